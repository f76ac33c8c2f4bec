//! The mechanism: a mesh with supports, loads and gravity — everything a solver
//! is handed. Nothing here reads files; the model loader builds it.

use flexmech_core::{Inertia, MassKind, Mesh};
use flexmech_joints::{JointMap, ReleasedState};
use nalgebra::{Matrix3, Vector3};
use std::fmt;
use std::sync::Arc;

/// A scalar function of time (statics: of the load factor λ).
#[derive(Clone)]
pub struct Schedule(Arc<dyn Fn(f64) -> f64 + Send + Sync>);

impl Schedule {
    /// A schedule from any function.
    pub fn new(f: impl Fn(f64) -> f64 + Send + Sync + 'static) -> Self {
        Self(Arc::new(f))
    }
    /// The same value at every time.
    pub fn constant(v: f64) -> Self {
        Self::new(move |_| v)
    }
    /// `s(t) = t`: the proportional load ramp of a static analysis.
    pub fn ramp() -> Self {
        Self::new(|t| t)
    }
    /// Value at `t`.
    pub fn at(&self, t: f64) -> f64 {
        (self.0)(t)
    }
}

impl fmt::Debug for Schedule {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("Schedule(..)")
    }
}

/// The consistent nodal weights (fractions of the element length) of a
/// uniform load on an element of `n` nodes, `∫ Nᵢ ds / h`: ½, ½ for two
/// nodes; ⅙, ⅔, ⅙ for three.
pub(crate) fn nodal_weights(n: usize) -> &'static [f64] {
    match n {
        2 => &[0.5, 0.5],
        _ => &[1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0],
    }
}

/// A dead nodal force and a fixed-axis (spatial) moment, scaled by `scale(t)`.
#[derive(Debug, Clone)]
pub struct NodalLoad {
    /// The loaded node.
    pub node: usize,
    /// Force (global components).
    pub force: Vector3<f64>,
    /// Moment about fixed global axes.
    pub moment: Vector3<f64>,
    /// Time function scaling both (statics: of the load factor).
    pub scale: Schedule,
}

/// A user's dead load field: adds nodal forces and moments about fixed
/// global axes at time `t` (statics: at the load factor) to `out` (6 per
/// node: force, then moment). Any time dependence and any distribution over
/// the nodes a researcher writes — a line load lumped to nodes, a measured
/// force history — enters every solver exactly where the built-in loads do
/// ([`Mechanism::external_forces`]), so the schemes' load evaluation, work
/// and reactions treat it alike. It must not depend on the state (its
/// tangent would be missing).
#[derive(Clone)]
pub struct LoadField(Arc<LoadFn>);

/// The function of a [`LoadField`]: time, and the nodal forces to add to.
pub type LoadFn = dyn Fn(f64, &mut [f64]) + Send + Sync;

impl LoadField {
    /// A field from `f(t, out)`, which adds its forces into `out`.
    pub fn new(f: impl Fn(f64, &mut [f64]) + Send + Sync + 'static) -> Self {
        Self(Arc::new(f))
    }

    /// Adds the field's forces at `t` into `out`.
    pub fn add(&self, t: f64, out: &mut [f64]) {
        (self.0)(t, out)
    }
}

impl std::fmt::Debug for LoadField {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("LoadField(<fn>)")
    }
}

/// A joint of the mechanism: master–slave relation (1) between two nodes.
#[derive(Debug, Clone)]
pub struct JointInstance {
    /// The joint's name (results, messages).
    pub name: String,
    /// Master node: its pose carries the joint frame.
    pub master: usize,
    /// Slave node: placed by relation (1) from the master and the released
    /// coordinates; its DOFs are eliminated.
    pub slave: usize,
    /// The joint kind's kinematics and derived maps.
    pub map: Arc<dyn JointMap>,
    /// Released coordinates at t = 0.
    pub initial: ReleasedState,
    /// Per released coordinate: `Some(value(t))` when it is driven.
    pub driven: Vec<Option<Schedule>>,
}

/// A nodal DOF (0..6 = ux, uy, uz, rx, ry, rz) that follows `value(t)`:
/// displacement from the initial position, or rotation about the global axis.
#[derive(Debug, Clone)]
pub struct PrescribedDof {
    /// The node.
    pub node: usize,
    /// Which DOF: 0..3 translations, 3..6 rotations about global axes.
    pub dof: usize,
    /// Its value over time (statics: over the load factor).
    pub value: Schedule,
}

/// A follower load on a node: a force and a moment that turn with the
/// node's triad, `f = s(t) R f₀`, `m = s(t) R m₀` (`f₀`, `m₀` in the node's
/// initial frame, the global axes — every node starts at the identity).
/// Not conservative: it has no potential, and its load stiffness
/// `∂(−R f₀)/∂η = (R f₀)^` (for a spatial spin `η` of `R`) makes the tangent
/// unsymmetric.
#[derive(Debug, Clone)]
pub struct FollowerLoad {
    /// The loaded node.
    pub node: usize,
    /// Force in the node's initial frame.
    pub force: Vector3<f64>,
    /// Moment in the node's initial frame.
    pub moment: Vector3<f64>,
    /// Scale factor over time (statics: over the load factor).
    pub scale: Schedule,
}

/// A rigid body (or point mass) whose centre of mass is a node: the mass
/// on its translations, the inertia about the centre of mass on its
/// rotations. An offset centre of mass is a node of its own joined rigidly
/// to the carrying node (see
/// [`MechanismBuilder::rigid_body`](crate::builder::MechanismBuilder::rigid_body)).
#[derive(Debug, Clone, PartialEq)]
pub struct RigidBody {
    /// Its name (results, messages).
    pub name: String,
    /// The node at its centre of mass.
    pub node: usize,
    /// Mass.
    pub mass: f64,
    /// Inertia tensor about the centre of mass, global axes at t = 0.
    pub inertia: Matrix3<f64>,
}

/// What the model calls the mechanism's parts, so that a solver's error is
/// born in the model's words. Empty for a mechanism built without names
/// (nodes and elements are then numbered).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Names {
    /// Every node's label (`arm.3`, `ground.pin`, `body.mass`); an empty
    /// or missing entry: unnamed.
    pub nodes: Vec<String>,
    /// Every beam: its name and its elements' range in the mesh.
    pub beams: Vec<(String, std::ops::Range<usize>)>,
    /// Per prescribed DOF ([`Mechanism::prescribed`]), its entry in the
    /// model's `[[prescribed]]` list (missing: the DOF's own index).
    pub prescribed: Vec<usize>,
}

impl Names {
    /// Node `n`'s label, if it has one.
    pub fn node(&self, n: usize) -> Option<&str> {
        self.nodes
            .get(n)
            .map(String::as_str)
            .filter(|l| !l.is_empty())
    }

    /// Element `e` in its beam's words, ` (element k of beam "arm", which
    /// has m)`, or empty.
    pub fn element(&self, e: usize) -> String {
        self.beams
            .iter()
            .find(|(_, r)| r.contains(&e))
            .map(|(name, r)| {
                format!(
                    " (element {} of beam \"{name}\", which has {})",
                    e - r.start,
                    r.len()
                )
            })
            .unwrap_or_default()
    }

    /// The model's `[[prescribed]]` entry of prescribed DOF `index`.
    pub fn prescribed_entry(&self, index: usize) -> usize {
        self.prescribed.get(index).copied().unwrap_or(index)
    }
}

/// Everything a solver needs about the mechanism.
#[derive(Debug, Clone)]
pub struct Mechanism {
    /// Beams: nodes and elements.
    pub mesh: Mesh,
    /// Per node `[ux, uy, uz, rx, ry, rz]`: true where held at the initial value.
    pub fixed: Vec<[bool; 6]>,
    /// Nodal loads.
    pub loads: Vec<NodalLoad>,
    /// Follower loads (turning with their nodes).
    pub follower_loads: Vec<FollowerLoad>,
    /// Users' load fields, added after the nodal loads.
    pub load_fields: Vec<LoadField>,
    /// Gravity acceleration (acts on `ρA`).
    pub gravity: Vector3<f64>,
    /// Scale of gravity over time (statics: ramped with the load factor).
    pub gravity_scale: Schedule,
    /// Joints (any order; chains allowed, cycles refused).
    pub joints: Vec<JointInstance>,
    /// Prescribed nodal DOFs.
    pub prescribed: Vec<PrescribedDof>,
    /// Rigid bodies and point masses.
    pub bodies: Vec<RigidBody>,
    /// Kelvin–Voigt damping time `η` of each element (resultants
    /// `C(ε + η ε̇)`; missing entries and 0: undamped). Newmark and
    /// generalized-α take it (FORMULATION §4.7).
    pub damping: Vec<f64>,
    /// What the model calls its nodes, beams and prescribed DOFs.
    pub names: Names,
    /// A steady spin of the whole structure: statics and modes are then in
    /// the frame turning with it (centrifugal loads, gyroscopic modes).
    pub spin: Option<crate::frame_spin::FrameSpin>,
}

impl Mechanism {
    /// A mechanism with no supports, loads or gravity.
    pub fn new(mesh: Mesh) -> Self {
        let n = mesh.node_count();
        Self {
            mesh,
            fixed: vec![[false; 6]; n],
            loads: Vec::new(),
            follower_loads: Vec::new(),
            load_fields: Vec::new(),
            gravity: Vector3::zeros(),
            gravity_scale: Schedule::constant(1.0),
            joints: Vec::new(),
            prescribed: Vec::new(),
            bodies: Vec::new(),
            damping: Vec::new(),
            names: Names::default(),
            spin: None,
        }
    }

    /// The damped elements: `(element index, η)` for every `η > 0`.
    pub fn damped_elements(&self) -> Vec<(usize, f64)> {
        self.damping
            .iter()
            .enumerate()
            .filter(|(e, &eta)| eta > 0.0 && *e < self.mesh.elements.len())
            .map(|(e, &eta)| (e, eta))
            .collect()
    }

    /// Whether anything drives the mechanism: a driven joint coordinate or
    /// a prescribed DOF (whose reactions do the drivers' work).
    pub fn has_drivers(&self) -> bool {
        !self.prescribed.is_empty()
            || self
                .joints
                .iter()
                .any(|j| j.driven.iter().any(Option::is_some))
    }

    /// The mass and inertia of the beams (with `kind` of translational
    /// mass) and of the rigid bodies.
    pub fn inertia(&self, kind: MassKind) -> Inertia {
        let mut inertia = Inertia::new(&self.mesh, kind);
        for b in &self.bodies {
            inertia.add_body(b.node, b.mass, &b.inertia);
        }
        inertia
    }

    /// The nodes held at one DOF at least (fixed or prescribed), ascending:
    /// the nodes whose reactions results report.
    pub fn supported_nodes(&self) -> Vec<usize> {
        (0..self.mesh.node_count())
            .filter(|&n| {
                self.fixed[n].iter().any(|&h| h) || self.prescribed.iter().any(|p| p.node == n)
            })
            .collect()
    }

    /// The round-off floor of a residual norm in the initial configuration
    /// (see [`Mechanism::round_off_floor_at`]).
    pub fn round_off_floor(&self) -> f64 {
        self.round_off_floor_at(&self.mesh.positions)
    }

    /// The round-off floor of a residual norm with the nodes at `positions`:
    /// `4·eps·‖(force scale of each element)‖₂` (see
    /// [`flexmech_core::Element::force_scale`]), with the model's size taken as
    /// twice its radius about the origin — the larger of the initial one and
    /// the current one, since rounding grows with the coordinates as a
    /// mechanism travels. Below it a residual is rounding noise, whatever the
    /// loads: long meshes of short, axially stiff elements far from the
    /// origin have the highest floors.
    pub fn round_off_floor_at(&self, positions: &[Vector3<f64>]) -> f64 {
        let radius = self.size_at(positions);
        let sum: f64 = self
            .mesh
            .elements
            .iter()
            .map(|e| e.force_scale(radius).powi(2))
            .sum();
        4.0 * f64::EPSILON * sum.sqrt()
    }

    /// The round-off floor the Kelvin–Voigt damping forces ([`Self::damping`])
    /// add over a step of `dt` with the nodes at `positions`:
    /// `4·eps·‖(η/Δt · force scale of each damped element)‖₂`. A damped
    /// element's force is `η/Δt` times that of the element whose strains are
    /// the step's change `ε − εₙ` (FORMULATION §4.7); the difference is
    /// small, but it carries the rounding of the strains themselves, so its
    /// noise is `η/Δt` times the elastic force's however little the element
    /// moves in the step (a 3-node cantilever with `η/Δt = 10` stalled at
    /// twice the undamped floor without it). Zero without damping.
    pub fn damping_round_off_floor_at(&self, positions: &[Vector3<f64>], dt: f64) -> f64 {
        let damped = self.damped_elements();
        if damped.is_empty() {
            return 0.0;
        }
        let radius = self.size_at(positions);
        let sum: f64 = damped
            .iter()
            .map(|&(e, eta)| (eta / dt * self.mesh.elements[e].force_scale(radius)).powi(2))
            .sum();
        4.0 * f64::EPSILON * sum.sqrt()
    }

    /// Adds `weight ×` the follower loads at time `t` with the nodes turned
    /// by `rot` to `out` (6 per node, force then spatial moment).
    pub fn add_follower_forces(&self, t: f64, rot: &[Matrix3<f64>], weight: f64, out: &mut [f64]) {
        for l in &self.follower_loads {
            let s = weight * l.scale.at(t);
            let (f, m) = (rot[l.node] * l.force * s, rot[l.node] * l.moment * s);
            for c in 0..3 {
                out[6 * l.node + c] += f[c];
                out[6 * l.node + 3 + c] += m[c];
            }
        }
    }

    /// The mechanism's size for round-off estimates: twice the largest
    /// distance from the origin of a node, initially or at `positions`.
    pub fn size_at(&self, positions: &[Vector3<f64>]) -> f64 {
        2.0 * self
            .mesh
            .positions
            .iter()
            .chain(positions)
            .map(|x| x.norm())
            .fold(0.0, f64::max)
    }

    /// External nodal forces and moments at time `t` (6 per node:
    /// force, then spatial moment): the nodal loads, the users' load fields
    /// and consistent nodal gravity forces `∫ρA g Iᵢ ds`, plus `m g` on each
    /// rigid body.
    pub fn external_forces(&self, t: f64, out: &mut [f64]) {
        out.iter_mut().for_each(|v| *v = 0.0);
        for load in &self.loads {
            let s = load.scale.at(t);
            for c in 0..3 {
                out[6 * load.node + c] += s * load.force[c];
                out[6 * load.node + 3 + c] += s * load.moment[c];
            }
        }
        for field in &self.load_fields {
            field.add(t, out);
        }
        if self.gravity != Vector3::zeros() {
            let g = self.gravity * self.gravity_scale.at(t);
            for e in &self.mesh.elements {
                let m = e.section().rho_a * e.length();
                for (&n, w) in e.nodes().iter().zip(nodal_weights(e.nodes().len())) {
                    for c in 0..3 {
                        out[6 * n + c] += m * w * g[c];
                    }
                }
            }
            for b in &self.bodies {
                for c in 0..3 {
                    out[6 * b.node + c] += b.mass * g[c];
                }
            }
        }
    }
}
