//! Building a [`Mechanism`] from Rust with typed handles and validating
//! constructors.
//!
//! Beams return the [`NodeId`]s of their nodes; joints return a [`JointId`]
//! that a drive refers to; DOFs are a [`Dof`], not an index; sections take
//! named values ([`SectionValues`]). Every constructor checks what the
//! solvers rely on and says what is wrong: stiffnesses positive, numbers
//! finite, a node of this mechanism, a slave where relation (1) puts it
//! (FORMULATION §3: `x_S = x_M + Λ_M r_R(ψ₀)` with the joint's initial
//! released coordinates), an angle only for kinds that have one. The
//! model-file path (the studies crate's `build`) is a layer over this one.
//!
//! ```
//! use flexmech_integrators::builder::{BeamShape, BeamDef, Dof, MechanismBuilder, SectionValues};
//! use flexmech_integrators::Schedule;
//! use nalgebra::Vector3;
//!
//! let rod = SectionValues { ea: 1e6, ga: [1e6; 2], gj: 1e3, ei: [1e3; 2], rho_a: 1.0, rho_j: [1e-3; 3] };
//! let mut b = MechanismBuilder::new();
//! let beam = b.beam(BeamDef {
//!     shape: BeamShape::Straight { start: Vector3::zeros(), end: Vector3::x(), e2: Vector3::y() },
//!     elements: 8,
//!     nodes_per_element: 2,
//!     section: rod,
//! })?;
//! b.fix(beam.start(), &Dof::ALL)?;
//! b.load(beam.end(), Vector3::new(0.0, 0.0, -1.0), Vector3::zeros(), Schedule::ramp())?;
//! let mechanism = b.build();
//! assert_eq!(mechanism.mesh.node_count(), 9);
//! # Ok::<(), flexmech_integrators::builder::BuildError>(())
//! ```

use std::sync::Arc;

use flexmech_core::{Mesh, MeshError, Section};
use flexmech_joints::{JointMap, ReleasedState, MAX_RELEASED};
use nalgebra::{Matrix3, Vector3};

use crate::mechanism::{
    nodal_weights, FollowerLoad, JointInstance, LoadField, Mechanism, NodalLoad, PrescribedDof,
    RigidBody, Schedule,
};

/// Relative distance (to the mechanism's size, at least 1) within which a
/// slave node is where relation (1) puts it: round-off of a mesher's
/// coordinates.
pub const SLAVE_PLACEMENT_TOLERANCE: f64 = 1e-9;

/// A node of the mechanism being built.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct NodeId(usize);

impl NodeId {
    /// Its global node number (the index into the mesh's nodes and into
    /// every per-node result).
    pub fn index(self) -> usize {
        self.0
    }
}

/// A joint of the mechanism being built.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct JointId(usize);

impl JointId {
    /// Its index in [`Mechanism::joints`].
    pub fn index(self) -> usize {
        self.0
    }
}

/// A nodal degree of freedom: a displacement along, or a rotation about, a
/// global axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Dof {
    /// Displacement along x.
    Ux,
    /// Displacement along y.
    Uy,
    /// Displacement along z.
    Uz,
    /// Rotation about x.
    Rx,
    /// Rotation about y.
    Ry,
    /// Rotation about z.
    Rz,
}

impl Dof {
    /// All six, in order.
    pub const ALL: [Dof; 6] = [Dof::Ux, Dof::Uy, Dof::Uz, Dof::Rx, Dof::Ry, Dof::Rz];

    /// 0..6 = ux, uy, uz, rx, ry, rz (the column of a node's six DOFs).
    pub fn index(self) -> usize {
        self as usize
    }

    /// The DOF of column `i`, if `i < 6`.
    pub fn from_index(i: usize) -> Option<Dof> {
        Dof::ALL.get(i).copied()
    }
}

/// A section by name: stiffness and inertia per unit length
/// (FORMULATION §2: `C_N = diag(EA, GA₂, GA₃)`, `C_M = diag(GJ, EI₂, EI₃)`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SectionValues {
    /// Axial stiffness EA.
    pub ea: f64,
    /// Shear stiffnesses GA₂, GA₃.
    pub ga: [f64; 2],
    /// Torsional stiffness GJ.
    pub gj: f64,
    /// Bending stiffnesses EI₂, EI₃.
    pub ei: [f64; 2],
    /// Mass per unit length ρA (zero for statics).
    pub rho_a: f64,
    /// Rotational inertia per unit length `ρ(I₂+I₃), ρI₂, ρI₃`.
    pub rho_j: [f64; 3],
}

impl SectionValues {
    /// The section, if every stiffness is positive and finite and every
    /// inertia zero or positive and finite; otherwise which value is not.
    pub fn section(&self) -> Result<Section, (&'static str, f64)> {
        let positive = [
            ("EA", self.ea),
            ("GA2", self.ga[0]),
            ("GA3", self.ga[1]),
            ("GJ", self.gj),
            ("EI2", self.ei[0]),
            ("EI3", self.ei[1]),
        ];
        if let Some(&bad) = positive.iter().find(|(_, v)| !(v.is_finite() && *v > 0.0)) {
            return Err(bad);
        }
        let inertia = [
            ("rhoA", self.rho_a),
            ("rhoJ", self.rho_j[0]),
            ("rhoJ", self.rho_j[1]),
            ("rhoJ", self.rho_j[2]),
        ];
        if let Some(&bad) = inertia.iter().find(|(_, v)| !(v.is_finite() && *v >= 0.0)) {
            return Err(bad);
        }
        Ok(Section::new(
            [self.ea, self.ga[0], self.ga[1]],
            [self.gj, self.ei[0], self.ei[1]],
            self.rho_a,
            self.rho_j,
        ))
    }
}

/// The initial geometry of a beam.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BeamShape {
    /// Straight from `start` to `end`; `e2` is the section's second axis
    /// (not parallel to the beam; orthogonalised against its axis).
    Straight {
        /// The first end.
        start: Vector3<f64>,
        /// The second end.
        end: Vector3<f64>,
        /// The section's second axis.
        e2: Vector3<f64>,
    },
    /// A circular arc from `start` about `center`, turning about `normal`
    /// (perpendicular to `start − center`) through `sweep` radians; `e2` is
    /// carried along the arc, or points to the center when `None`.
    Arc {
        /// The first point.
        start: Vector3<f64>,
        /// The centre of the circle.
        center: Vector3<f64>,
        /// The turning axis.
        normal: Vector3<f64>,
        /// The angle swept (radians, non-zero).
        sweep: f64,
        /// The section's second axis at the start.
        e2: Option<Vector3<f64>>,
    },
}

/// A beam: its shape, its mesh and its section.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BeamDef {
    /// The initial geometry.
    pub shape: BeamShape,
    /// Number of equal elements (at least 1).
    pub elements: usize,
    /// 2 (linear) or 3 (quadratic).
    pub nodes_per_element: usize,
    /// The section.
    pub section: SectionValues,
}

/// The nodes of a beam, first to last.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Beam {
    nodes: Vec<NodeId>,
    elements: std::ops::Range<usize>,
}

impl Beam {
    /// The first node.
    pub fn start(&self) -> NodeId {
        self.nodes[0]
    }

    /// The last node.
    pub fn end(&self) -> NodeId {
        self.nodes[self.nodes.len() - 1]
    }

    /// Node `k` along the beam (0 = start), if it has one.
    pub fn node(&self, k: usize) -> Option<NodeId> {
        self.nodes.get(k).copied()
    }

    /// Every node, first to last.
    pub fn nodes(&self) -> &[NodeId] {
        &self.nodes
    }

    /// Its elements' indices in the mesh, first to last.
    pub fn elements(&self) -> std::ops::Range<usize> {
        self.elements.clone()
    }
}

/// A joint: a master–slave relation (1) between two nodes of the
/// mechanism, of the kind `map`, at the released angle `angle` at t = 0
/// (kinds whose first released coordinate is an angle; 0 for the others).
#[derive(Debug, Clone)]
pub struct JointDef {
    /// Its name (results, messages).
    pub name: String,
    /// The kind's kinematics.
    pub map: Arc<dyn JointMap>,
    /// The master node (carries the joint frame).
    pub master: NodeId,
    /// The slave node (its DOFs are eliminated).
    pub slave: NodeId,
    /// The initial released angle ψ₀.
    pub angle: f64,
}

/// What a builder refuses.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BuildError {
    /// A section value is not usable.
    #[error(
        "beam {beam}: section value {what} = {value}: stiffnesses must be positive and \
         finite, inertias zero or positive and finite"
    )]
    Section {
        /// The beam (0-based, in the order added).
        beam: usize,
        /// Which value.
        what: &'static str,
        /// The value.
        value: f64,
    },
    /// The mesher refused the beam's geometry or element count.
    #[error("beam {beam}: {source}")]
    Mesh {
        /// The beam (0-based, in the order added).
        beam: usize,
        /// The mesher's reason.
        source: MeshError,
    },
    /// A node that is not one of this mechanism's.
    #[error("node {node} is not a node of this mechanism (it has {count})")]
    UnknownNode {
        /// The node's index.
        node: usize,
        /// Nodes of the mechanism.
        count: usize,
    },
    /// A joint that is not one of this mechanism's.
    #[error("joint {joint} is not a joint of this mechanism (it has {count})")]
    UnknownJoint {
        /// The joint's index.
        joint: usize,
        /// Joints of the mechanism.
        count: usize,
    },
    /// A value that must be a finite number is not.
    #[error("{what}: {value} is not a finite number")]
    NotFinite {
        /// What it is.
        what: String,
        /// The value.
        value: f64,
    },
    /// A joint between a node and itself.
    #[error("joint `{joint}`: the slave is the master node")]
    SameNode {
        /// The joint's name.
        joint: String,
    },
    /// An angle given to a kind without one, or a drive of such a kind.
    #[error("joint `{joint}`: its kind has no released angle ({what})")]
    NoAngle {
        /// The joint's name.
        joint: String,
        /// What asked for one.
        what: &'static str,
    },
    /// The kind's released translation at ψ₀ is not a finite number.
    #[error(
        "joint `{joint}`: its released translation at the initial angle is not a finite \
         number ({expected:?}); check the kind's parameters and the angle"
    )]
    NonFiniteRelease {
        /// The joint's name.
        joint: String,
        /// Where relation (1) puts the slave.
        expected: [f64; 3],
    },
    /// The derivative of the kind's released translation or rotation at ψ₀
    /// (the variational map `N` of paper eqs 5–6) is not finite.
    #[error(
        "joint `{joint}`: the derivative of its released translation at the initial angle is \
         not finite (the map N of paper eqs 5-6 holds {bad}); a function such as sqrt(psi) \
         at psi = 0 has no derivative there: change the function or the joint's `angle`"
    )]
    NonFiniteDerivative {
        /// The joint's name.
        joint: String,
        /// The first non-finite entry.
        bad: f64,
    },
    /// A rigid body's mass or inertia is not physical.
    #[error("rigid body `{body}`: {why}")]
    Body {
        /// The body's name.
        body: String,
        /// What is wrong, with the values.
        why: String,
    },
    /// The slave is not where relation (1) puts it at ψ₀.
    #[error(
        "joint `{joint}`: the slave starts at {at:?} but the master plus the released \
         translation at the initial angle puts it at {expected:?} (off by {gap:.3e})"
    )]
    SlaveOff {
        /// The joint's name.
        joint: String,
        /// The slave's initial position.
        at: [f64; 3],
        /// Where relation (1) puts it.
        expected: [f64; 3],
        /// The distance between the two.
        gap: f64,
    },
}

/// The released coordinates of a joint at t = 0: the angle `angle` for a
/// kind whose first coordinate is an angle, every coordinate zero otherwise
/// (where an angle other than zero is refused).
fn initial_state(name: &str, map: &dyn JointMap, angle: f64) -> Result<ReleasedState, BuildError> {
    finite(|| format!("joint `{name}`: angle"), &[angle])?;
    let mut q0 = [0.0; MAX_RELEASED];
    if map.has_angle() {
        q0[0] = angle;
    } else if angle != 0.0 {
        return Err(BuildError::NoAngle {
            joint: name.to_owned(),
            what: "an initial angle was given",
        });
    }
    Ok(ReleasedState::new(q0))
}

/// Builds a [`Mechanism`] step by step; see the module docs.
#[derive(Debug, Clone)]
pub struct MechanismBuilder {
    mech: Mechanism,
    beams: usize,
}

impl Default for MechanismBuilder {
    fn default() -> Self {
        Self::new()
    }
}

/// Relative asymmetry (and negative part) of an inertia tensor taken for
/// round-off, against its largest entry.
pub const BODY_SYMMETRY_TOLERANCE: f64 = 1e-12;

fn finite<'a>(
    what: impl FnOnce() -> String,
    values: impl IntoIterator<Item = &'a f64>,
) -> Result<(), BuildError> {
    match values.into_iter().find(|v| !v.is_finite()) {
        Some(&value) => Err(BuildError::NotFinite {
            what: what(),
            value,
        }),
        None => Ok(()),
    }
}

impl MechanismBuilder {
    /// An empty mechanism: no nodes, no gravity.
    pub fn new() -> Self {
        Self {
            mech: Mechanism::new(Mesh::default()),
            beams: 0,
        }
    }

    fn check(&self, node: NodeId) -> Result<usize, BuildError> {
        let count = self.mech.mesh.node_count();
        if node.0 < count {
            Ok(node.0)
        } else {
            Err(BuildError::UnknownNode {
                node: node.0,
                count,
            })
        }
    }

    /// The initial position of `node`.
    pub fn position(&self, node: NodeId) -> Result<Vector3<f64>, BuildError> {
        Ok(self.mech.mesh.positions[self.check(node)?])
    }

    /// Meshes a beam; returns its nodes.
    pub fn beam(&mut self, def: BeamDef) -> Result<Beam, BuildError> {
        let beam = self.beams;
        let section = def
            .section
            .section()
            .map_err(|(what, value)| BuildError::Section { beam, what, value })?;
        let mesh = &mut self.mech.mesh;
        let first_element = mesh.elements.len();
        let nodes = match def.shape {
            BeamShape::Straight { start, end, e2 } => {
                finite(
                    || format!("beam {beam}: start, end, e2"),
                    start.iter().chain(&end).chain(&e2),
                )?;
                mesh.add_straight_beam(start, end, e2, def.elements, def.nodes_per_element, section)
            }
            BeamShape::Arc {
                start,
                center,
                normal,
                sweep,
                e2,
            } => {
                let e2v = e2.unwrap_or_default();
                finite(
                    || format!("beam {beam}: start, center, normal, sweep, e2"),
                    start
                        .iter()
                        .chain(&center)
                        .chain(&normal)
                        .chain(&e2v)
                        .chain(std::iter::once(&sweep)),
                )?;
                mesh.add_arc_beam(
                    start,
                    center,
                    normal,
                    sweep,
                    e2,
                    def.elements,
                    def.nodes_per_element,
                    section,
                )
            }
        }
        .map_err(|source| BuildError::Mesh { beam, source })?;
        self.mech
            .fixed
            .resize(self.mech.mesh.node_count(), [false; 6]);
        self.beams += 1;
        Ok(Beam {
            nodes: nodes.into_iter().map(NodeId).collect(),
            elements: first_element..self.mech.mesh.elements.len(),
        })
    }

    /// Holds `dofs` of `node` at their initial values.
    pub fn fix(&mut self, node: NodeId, dofs: &[Dof]) -> Result<(), BuildError> {
        let n = self.check(node)?;
        for d in dofs {
            self.mech.fixed[n][d.index()] = true;
        }
        Ok(())
    }

    /// A dead force and a moment about fixed global axes on `node`, both
    /// scaled by `scale(t)` (statics: by the load factor).
    pub fn load(
        &mut self,
        node: NodeId,
        force: Vector3<f64>,
        moment: Vector3<f64>,
        scale: Schedule,
    ) -> Result<(), BuildError> {
        let n = self.checked_load(node, "load", &force, &moment)?;
        self.mech.loads.push(NodalLoad {
            node: n,
            force,
            moment,
            scale,
        });
        Ok(())
    }

    /// The node of a `what` load, after checking it and the load's numbers.
    fn checked_load(
        &self,
        node: NodeId,
        what: &str,
        force: &Vector3<f64>,
        moment: &Vector3<f64>,
    ) -> Result<usize, BuildError> {
        let n = self.check(node)?;
        finite(
            || format!("{what} on node {n}: force, moment"),
            force.iter().chain(moment),
        )?;
        Ok(n)
    }

    /// A load field of the user's: `f(t, out)` adds nodal forces and
    /// moments (6 per node of [`MechanismBuilder::build`]'s mechanism) at
    /// time `t` (see [`LoadField`]).
    pub fn load_field(&mut self, f: impl Fn(f64, &mut [f64]) + Send + Sync + 'static) {
        self.mech.load_fields.push(LoadField::new(f));
    }

    /// A follower force and moment on `node`, given in the node's initial
    /// frame (the global axes) and turning with the node's triad:
    /// `f = s(t) R f₀`, `m = s(t) R m₀` (see [`FollowerLoad`]).
    pub fn follower_load(
        &mut self,
        node: NodeId,
        force: Vector3<f64>,
        moment: Vector3<f64>,
        scale: Schedule,
    ) -> Result<(), BuildError> {
        let n = self.checked_load(node, "follower load", &force, &moment)?;
        self.mech.follower_loads.push(FollowerLoad {
            node: n,
            force,
            moment,
            scale,
        });
        Ok(())
    }

    /// A dead force and a moment about fixed global axes per unit length on
    /// every element of `beam`, scaled by `scale(t)`: the consistent nodal
    /// loads `∫ q Nᵢ ds` — `qh/2` at each end of a 2-node element,
    /// `qh/6, 2qh/3, qh/6` on a 3-node one — the weights gravity uses.
    pub fn distributed_load(
        &mut self,
        beam: &Beam,
        force: Vector3<f64>,
        moment: Vector3<f64>,
        scale: Schedule,
    ) -> Result<(), BuildError> {
        for (node, share) in self.shares(beam, &force, &moment)? {
            self.mech.loads.push(NodalLoad {
                node,
                force: force * share,
                moment: moment * share,
                scale: scale.clone(),
            });
        }
        Ok(())
    }

    /// A follower force and moment per unit length on every element of
    /// `beam` (given in the initial frame, turning with the beam): the
    /// nodal shares of [`MechanismBuilder::distributed_load`], each turning
    /// with its node's triad — the nodal quadrature of `∫ R(s) q₀ Nᵢ ds`.
    pub fn follower_distributed_load(
        &mut self,
        beam: &Beam,
        force: Vector3<f64>,
        moment: Vector3<f64>,
        scale: Schedule,
    ) -> Result<(), BuildError> {
        for (node, share) in self.shares(beam, &force, &moment)? {
            self.mech.follower_loads.push(FollowerLoad {
                node,
                force: force * share,
                moment: moment * share,
                scale: scale.clone(),
            });
        }
        Ok(())
    }

    /// The number of dead nodal loads so far: the index in
    /// [`Mechanism::loads`] of the next one.
    pub fn load_count(&self) -> usize {
        self.mech.loads.len()
    }

    /// Each node of `beam` with its share `∫ Nᵢ ds` of a unit load per unit
    /// length, in the order [`MechanismBuilder::distributed_load`] adds
    /// the nodal loads.
    pub fn distributed_shares(&self, beam: &Beam) -> Result<Vec<(usize, f64)>, BuildError> {
        self.shares(beam, &Vector3::zeros(), &Vector3::zeros())
    }

    /// Each node's share `Σ w h` of a uniform load per unit length on
    /// `beam` (the weights of gravity), after checking the load's numbers.
    fn shares(
        &self,
        beam: &Beam,
        force: &Vector3<f64>,
        moment: &Vector3<f64>,
    ) -> Result<Vec<(usize, f64)>, BuildError> {
        finite(
            || "distributed load: force, moment".into(),
            force.iter().chain(moment),
        )?;
        let count = self.mech.mesh.elements.len();
        if beam.elements.end > count {
            return Err(BuildError::UnknownNode {
                node: beam.nodes.last().map_or(0, |n| n.0),
                count: self.mech.mesh.node_count(),
            });
        }
        let mut shares: Vec<(usize, f64)> = Vec::new();
        for e in &self.mech.mesh.elements[beam.elements.clone()] {
            let length = e.length();
            for (&node, w) in e.nodes().iter().zip(nodal_weights(e.nodes().len())) {
                match shares.iter_mut().find(|(n, _)| *n == node) {
                    Some((_, s)) => *s += w * length,
                    None => shares.push((node, w * length)),
                }
            }
        }
        Ok(shares)
    }

    /// Kelvin–Voigt structural damping on every element of `beam`: stress
    /// resultants `C(ε + η ε̇)` with the damping time `eta` (seconds; 0:
    /// undamped). Newmark and generalized-α take it; the midpoint schemes
    /// refuse it.
    pub fn damping(&mut self, beam: &Beam, eta: f64) -> Result<(), BuildError> {
        finite(|| "damping time".into(), &[eta])?;
        if eta < 0.0 {
            return Err(BuildError::NotFinite {
                what: "damping time (must be >= 0)".into(),
                value: eta,
            });
        }
        let count = self.mech.mesh.elements.len();
        if self.mech.damping.len() < count {
            self.mech.damping.resize(count, 0.0);
        }
        for e in beam.elements.clone() {
            if let Some(d) = self.mech.damping.get_mut(e) {
                *d = eta;
            }
        }
        Ok(())
    }

    /// Gravity acceleration `g` (acting on ρA), scaled by `scale(t)`.
    pub fn gravity(&mut self, g: Vector3<f64>, scale: Schedule) -> Result<(), BuildError> {
        finite(|| "gravity".into(), &g)?;
        self.mech.gravity = g;
        self.mech.gravity_scale = scale;
        Ok(())
    }

    /// A rigid body carried by `node`: mass `mass`, inertia `inertia` about
    /// its centre of mass, which lies at `offset` from the node — both in the
    /// node's initial frame, which is the global one (every node starts at
    /// the identity). A point mass has zero inertia and offset. With an offset
    /// the centre of mass becomes a node of no element joined rigidly to
    /// `node` (master–slave, eliminated exactly; its joint is named
    /// `body.<name>`), so the body's kinetic energy, momenta and weight are
    /// exact in every scheme. Returns the node at the centre of mass.
    ///
    /// Refused: a negative or non-finite mass; an inertia that is not
    /// symmetric, has a negative principal value or breaks the triangle
    /// inequality `J₁ ≤ J₂ + J₃` of a physical body.
    pub fn rigid_body(
        &mut self,
        name: String,
        node: NodeId,
        mass: f64,
        inertia: Matrix3<f64>,
        offset: Vector3<f64>,
    ) -> Result<NodeId, BuildError> {
        let n = self.check(node)?;
        finite(|| format!("rigid body `{name}`: mass"), &[mass])?;
        finite(|| format!("rigid body `{name}`: inertia"), inertia.iter())?;
        finite(|| format!("rigid body `{name}`: offset"), offset.iter())?;
        let refuse = |why: String| BuildError::Body {
            body: name.clone(),
            why,
        };
        if mass < 0.0 {
            return Err(refuse(format!("the mass must be >= 0, found {mass}")));
        }
        let scale = inertia.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        if (inertia - inertia.transpose()).amax() > BODY_SYMMETRY_TOLERANCE * scale {
            return Err(refuse(format!(
                "the inertia tensor must be symmetric, found {:?}",
                inertia.as_slice()
            )));
        }
        let mut j = inertia.symmetric_eigenvalues().as_slice().to_vec();
        j.sort_by(f64::total_cmp);
        if j[0] < -BODY_SYMMETRY_TOLERANCE * scale {
            return Err(refuse(format!(
                "the principal moments of inertia must be >= 0, found {j:?}"
            )));
        }
        if j[2] > (j[0] + j[1]) * (1.0 + BODY_SYMMETRY_TOLERANCE) + BODY_SYMMETRY_TOLERANCE * scale
        {
            return Err(refuse(format!(
                "the principal moments of inertia {j:?} break J₁ ≤ J₂ + J₃, which every \
                 body's do"
            )));
        }
        let centre = if offset == Vector3::zeros() {
            node
        } else {
            let x = self.mech.mesh.positions[n] + offset;
            let c = NodeId(self.mech.mesh.add_node(x));
            self.mech.fixed.push([false; 6]);
            let joint = self.joint(JointDef {
                name: format!("body.{name}"),
                map: Arc::new(flexmech_joints::RigidLink { offset }),
                master: node,
                slave: c,
                angle: 0.0,
            });
            if let Err(e) = joint {
                self.mech.mesh.positions.pop();
                self.mech.fixed.pop();
                return Err(e);
            }
            c
        };
        self.mech.bodies.push(RigidBody {
            name,
            node: centre.0,
            mass,
            inertia,
        });
        Ok(centre)
    }

    /// Adds a joint after checking that its nodes differ, that an angle is
    /// given only to a kind that has one, and that the slave starts where
    /// relation (1) puts it at the initial angle (to
    /// [`SLAVE_PLACEMENT_TOLERANCE`] of the mechanism's size).
    pub fn joint(&mut self, def: JointDef) -> Result<JointId, BuildError> {
        let (master, slave) = (self.check(def.master)?, self.check(def.slave)?);
        if master == slave {
            return Err(BuildError::SameNode { joint: def.name });
        }
        let initial = initial_state(&def.name, def.map.as_ref(), def.angle)?;
        let x0 = &self.mech.mesh.positions;
        let (expected, _) = def.map.slave(&x0[master], &Matrix3::identity(), &initial);
        let arr = |x: &Vector3<f64>| [x.x, x.y, x.z];
        let gap = (x0[slave] - expected).norm();
        if !gap.is_finite() {
            return Err(BuildError::NonFiniteRelease {
                joint: def.name,
                expected: arr(&expected),
            });
        }
        let n = def
            .map
            .variation(&x0[master], &Matrix3::identity(), &initial);
        if let Some(&bad) = n.iter().find(|v| !v.is_finite()) {
            return Err(BuildError::NonFiniteDerivative {
                joint: def.name,
                bad,
            });
        }
        let scale = x0.iter().map(|x| x.norm()).fold(1.0, f64::max);
        if gap > SLAVE_PLACEMENT_TOLERANCE * scale {
            return Err(BuildError::SlaveOff {
                joint: def.name,
                at: arr(&x0[slave]),
                expected: arr(&expected),
                gap,
            });
        }
        let driven = vec![None; def.map.released_count()];
        self.mech.joints.push(JointInstance {
            name: def.name,
            master,
            slave,
            map: def.map,
            initial,
            driven,
        });
        Ok(JointId(self.mech.joints.len() - 1))
    }

    /// A joint whose master is the ground: the slave's initial pose is the
    /// joint frame, fixed in space (global axes). A node of no element is
    /// added where relation (1) puts the master at the initial angle,
    /// `x_M = x_S − r_R(ψ₀)` (`Λ_M = I`), with all six DOFs held; it is
    /// returned with the joint. Every joint kind and every scheme apply,
    /// and the ground node's support reaction is what the joint transmits to
    /// the ground.
    pub fn ground_joint(
        &mut self,
        name: String,
        map: Arc<dyn JointMap>,
        slave: NodeId,
        angle: f64,
    ) -> Result<(JointId, NodeId), BuildError> {
        let s = self.check(slave)?;
        let (r_r, _) = map.released_placement(&initial_state(&name, map.as_ref(), angle)?);
        let master = self.mech.mesh.positions[s] - r_r;
        if !master.iter().all(|c| c.is_finite()) {
            return Err(BuildError::NonFiniteRelease {
                joint: name,
                expected: [master.x, master.y, master.z],
            });
        }
        let ground = NodeId(self.mech.mesh.add_node(master));
        self.mech.fixed.push([true; 6]);
        let joint = self.joint(JointDef {
            name,
            map,
            master: ground,
            slave,
            angle,
        });
        if joint.is_err() {
            // Leave no ground node behind a refused joint.
            self.mech.mesh.positions.pop();
            self.mech.fixed.pop();
        }
        Ok((joint?, ground))
    }

    /// Drives the released angle of `joint` by `angle(t)` (statics: of the
    /// load factor).
    pub fn drive(&mut self, joint: JointId, angle: Schedule) -> Result<(), BuildError> {
        let count = self.mech.joints.len();
        let j = self
            .mech
            .joints
            .get_mut(joint.0)
            .ok_or(BuildError::UnknownJoint {
                joint: joint.0,
                count,
            })?;
        if !j.map.has_angle() {
            return Err(BuildError::NoAngle {
                joint: j.name.clone(),
                what: "it was asked to be driven",
            });
        }
        j.driven[0] = Some(angle);
        Ok(())
    }

    /// Prescribes `dof` of `node` by `value(t)`: a displacement from the
    /// initial position, or a rotation about the global axis.
    pub fn prescribe(&mut self, node: NodeId, dof: Dof, value: Schedule) -> Result<(), BuildError> {
        let n = self.check(node)?;
        self.mech.prescribed.push(PrescribedDof {
            node: n,
            dof: dof.index(),
            value,
        });
        Ok(())
    }

    /// The mechanism.
    pub fn build(self) -> Mechanism {
        self.mech
    }
}
