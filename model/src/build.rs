//! From a validated [`Model`] to the [`Mechanism`] the solvers work on: mesh
//! the beams, number the nodes, apply supports, loads and gravity.

use crate::{
    Analysis, BeamSpec, IntegratorKind, Model, ModelError, NodeRef, PrescribedSpec, SensitivityKey,
    TimeFunction,
};
use flexmech_integrators::builder::{
    Beam, BeamDef, BuildError, Dof, JointDef, JointId, MechanismBuilder, NodeId,
};
use flexmech_integrators::dynamics::Motion;
use flexmech_integrators::frame_spin::FrameSpin;
use flexmech_integrators::{Mechanism, Names, Parameter, Schedule};
use nalgebra::{Matrix3, Vector3};

/// A mechanism with the numbering that relates it back to the model file.
#[derive(Debug, Clone)]
pub struct Built {
    /// What the solvers work on.
    pub mechanism: Mechanism,
    /// Global node numbers of every beam's nodes (`beam_nodes[b][k]`).
    pub beam_nodes: Vec<Vec<usize>>,
    /// Every beam's elements' range in the mesh.
    pub beam_elements: Vec<std::ops::Range<usize>>,
    /// Initial velocities (dynamic analyses).
    pub motion: Motion,
    /// The ground node of every joint to the ground: `(joint index, node)`
    /// (nodes of no element, after the beams' nodes; labelled
    /// `ground.<joint name>`).
    pub ground_nodes: Vec<(usize, usize)>,
    /// The centre-of-mass node of every rigid body with an offset:
    /// `(body index, node)` (labelled `body.<body name>`; its rigid joint to
    /// the carrying node is the joint `body.<body name>`, after the model's).
    pub body_nodes: Vec<(usize, usize)>,
    /// Every `[[load]]` and then every `[[distributed_load]]` of the model
    /// as the dead nodal loads it became: `(index into Mechanism::loads,
    /// share of a unit value)` (empty for a follower load).
    pub load_shares: Vec<Vec<(usize, f64)>>,
}

impl Built {
    /// Global node number of a model node.
    pub fn node(&self, r: NodeRef) -> usize {
        self.beam_nodes[r.beam][r.node]
    }

    /// `d(initial motion)/dp` for component `component` (0–2 `linear`, 3–5
    /// `angular`) of `[[initial_velocity]]` `field`: on the nodes whose
    /// velocity it sets (no later field overrides it there), `e_c` or
    /// `(e_c × (x₀ − origin), e_c)`.
    fn initial_motion_derivative(&self, model: &Model, field: usize, component: usize) -> Motion {
        let x0 = &self.mechanism.mesh.positions;
        let mut motion = Motion::rest(x0.len());
        let spec = &model.initial_velocities[field];
        let later = &model.initial_velocities[field + 1..];
        let e = Vector3::ith(component % 3, 1.0);
        for r in &spec.nodes {
            if later.iter().any(|f| f.nodes.contains(r)) {
                continue;
            }
            let n = self.node(*r);
            if component < 3 {
                motion.v[n] = e;
            } else {
                motion.v[n] = e.cross(&(x0[n] - v(spec.origin)));
                motion.w[n] = e;
            }
        }
        motion.joint_rates = vec![0.0; model.joints.len()];
        motion
    }

    /// The geometry parameter of coordinate `component` of straight beam
    /// `b`'s start (`end` 0) or end (1): with `t` the unit axis and `ℓ` the
    /// length, node `k` at `s_k ℓ` along the beam moves by `(1 − s_k) e_c`
    /// (start) or `s_k e_c` (end), every element stretches by
    /// `∓ t·e_c / ℓ`, and the triads `[t, t₂, t × t₂]` turn as `t` does,
    /// `dt = ±(e_c − t (t·e_c))/ℓ` (their derivative by a dual number through
    /// the mesher's own construction).
    fn beam_end_parameter(&self, model: &Model, b: usize, end: usize, c: usize) -> Parameter {
        let crate::types::BeamGeometry::Straight {
            start,
            end: tip,
            e2,
        } = model.beams[b].geometry
        else {
            unreachable!("the key was checked to name a straight beam's end")
        };
        let (axis, length) = ((tip - start).normalize(), (tip - start).norm());
        let sign = if end == 0 { -1.0 } else { 1.0 };
        let e_c = Vector3::ith(c, 1.0);
        let dt = (e_c - axis * axis.dot(&e_c)) * (sign / length);
        let dual = |v: &Vector3<f64>, d: &Vector3<f64>| {
            Vector3::from_fn(|i, _| num_dual::Dual64::new(v[i], d[i]))
        };
        let triad =
            flexmech_core::mesh::straight_triad(&dual(&axis, &dt), &dual(&e2, &Vector3::zeros()));
        let (l0, dl0) = (triad.map(|v| v.re), triad.map(|v| v.eps));
        let w = dl0 * l0.transpose();
        let spin = Vector3::new(
            w[(2, 1)] - w[(1, 2)],
            w[(0, 2)] - w[(2, 0)],
            w[(1, 0)] - w[(0, 1)],
        ) * 0.5;
        let x0 = &self.mechanism.mesh.positions;
        let shifts = (self.beam_nodes[b].iter())
            .map(|&n| {
                let s = (x0[n] - start).dot(&axis) / length;
                (n, e_c * if end == 0 { 1.0 - s } else { s })
            })
            .collect();
        let stretch = sign * axis.dot(&e_c) / length;
        let first = model.loads.len();
        let loads = (model.distributed_loads.iter().enumerate())
            .filter(|(_, d)| d.beam == b)
            .flat_map(|(d, _)| self.load_shares[first + d].iter().map(|&(l, _)| l))
            .collect();
        Parameter::Geometry {
            stretch: self.beam_elements[b]
                .clone()
                .map(|e| (e, stretch))
                .collect(),
            spin,
            shifts,
            loads,
        }
    }

    /// The mechanism's parameter of every `[output] sensitivity` key of
    /// `model` (the model this was built from), in order: a section's
    /// stiffness on the elements of every beam of that section; a load's
    /// component on the dead nodal loads it became, with their shares.
    pub fn sensitivity_parameters(&self, model: &Model) -> Vec<Parameter> {
        let loads = model.loads.len();
        let param = |key: &SensitivityKey| match *key {
            SensitivityKey::BodyMass { body, component } => Parameter::BodyMass { body, component },
            SensitivityKey::JointParameter { joint, ref name } => Parameter::Joint {
                joint,
                name: name.clone(),
            },
            SensitivityKey::Section { section, component } => {
                let elements = (model.beams.iter().zip(&self.beam_elements))
                    .filter(|(b, _)| b.section == section)
                    .flat_map(|(_, e)| e.clone())
                    .collect();
                match component {
                    0..=5 => Parameter::Stiffness {
                        elements,
                        component,
                    },
                    _ => Parameter::Mass {
                        elements,
                        component: component - 6,
                    },
                }
            }
            SensitivityKey::Load { load, component } => Parameter::Loads {
                shares: self.load_shares[load].clone(),
                component,
            },
            SensitivityKey::DistributedLoad { load, component } => Parameter::Loads {
                shares: self.load_shares[loads + load].clone(),
                component,
            },
            SensitivityKey::BeamEnd {
                beam,
                end,
                component,
            } => self.beam_end_parameter(model, beam, end, component),
            SensitivityKey::InitialVelocity { field, component } => Parameter::InitialMotion {
                motion: self.initial_motion_derivative(model, field, component),
            },
        };
        model
            .output
            .sensitivity
            .iter()
            .map(|(_, k)| param(k))
            .collect()
    }
}

fn v(a: [f64; 3]) -> Vector3<f64> {
    Vector3::from(a)
}

/// The schedule of a load: its time table if the file gives one; otherwise
/// the load factor itself in statics (proportional loading) and 1 in dynamics.
fn schedule(time: &Option<TimeFunction>, analysis: &Analysis) -> Schedule {
    match (time, analysis) {
        (Some(f), _) => schedule_of(f),
        (None, a) if a.is_load_path() => Schedule::ramp(),
        (None, _) => Schedule::constant(1.0),
    }
}

/// Initial nodal velocities from the `[[initial_velocity]]` fields
/// (`v = v₀ + ω × (x − origin)`, body angular velocity `W = ω` since every
/// node starts at the identity); a later field overrides an earlier one on
/// the nodes they share; nodes in no field start at rest. Joints' `rate`s set
/// the released rates (slave velocities follow from them).
fn initial_motion(model: &Model, built: &Built) -> Motion {
    let x0 = &built.mechanism.mesh.positions;
    let mut motion = Motion::rest(x0.len());
    for field in &model.initial_velocities {
        let (v0, om, o) = (v(field.linear), v(field.angular), v(field.origin));
        for r in &field.nodes {
            let n = built.node(*r);
            motion.v[n] = v0 + om.cross(&(x0[n] - o));
            motion.w[n] = om;
        }
    }
    motion.joint_rates = model.joints.iter().map(|j| j.rate).collect();
    // Drivers written as expressions start at their exact rate f′(0): a
    // driven joint's released rate (unless `rate` is given) and a
    // prescribed DOF's velocity (a rotation DOF: the spin about its global
    // axis, = W at t = 0 where R = I).
    for p in &model.prescribed {
        match p {
            PrescribedSpec::JointAngle {
                joint,
                angle: f @ TimeFunction::Expression(_),
            } if model.joints[*joint].rate == 0.0 => {
                motion.joint_rates[*joint] = f.derivatives(0.0).1;
            }
            PrescribedSpec::NodeDof {
                node,
                dof,
                value: f @ TimeFunction::Expression(_),
            } => {
                let n = built.node(*node);
                let rate = f.derivatives(0.0).1;
                match *dof {
                    d @ 0..=2 => motion.v[n][d] = rate,
                    d => motion.w[n][d - 3] = rate,
                }
            }
            _ => {}
        }
    }
    motion
}

/// A time function as a schedule.
fn schedule_of(f: &TimeFunction) -> Schedule {
    let f = f.clone();
    Schedule::new(move |t| f.eval(t))
}

/// The builder's refusal as a model error: the key of the model entry it is
/// about (`key`), in the model's words.
fn refused(model: &Model, key: String, e: BuildError) -> ModelError {
    let message = match &e {
        BuildError::Mesh { beam, source } => {
            format!("beam `{}`: {source}", model.beams[*beam].name)
        }
        BuildError::NonFiniteRelease { joint, expected } => format!(
            "joint `{joint}`: its released translation at the initial angle is not a finite \
             number ({expected:?}); check the joint's parameters (pitch, radius, profile \
             coefficients or table, period) and its `angle`"
        ),
        BuildError::SlaveOff {
            joint,
            at,
            expected,
            gap,
        } => {
            let spec = model.joints.iter().find(|j| &j.name == joint);
            let label = |r: Option<NodeRef>| r.map(|r| model.node_label(r)).unwrap_or_default();
            let p = |x: &[f64; 3]| format!("({:.6}, {:.6}, {:.6})", x[0], x[1], x[2]);
            format!(
                "joint `{joint}`: the slave `{}` starts at {} but the master `{}` plus the \
                 released translation at the initial angle puts it at {} (off by {gap:.3e}); \
                 {}",
                label(spec.map(|s| s.slave)),
                p(at),
                spec.map_or_else(String::new, |s| match s.master {
                    Some(m) => model.node_label(m),
                    None => "ground".into(),
                }),
                p(expected),
                slave_off_fix(spec, at, expected)
            )
        }
        other => other.to_string(),
    };
    ModelError::new(&model.path, key, None, message)
}

/// The fix a misplaced slave's message offers for its joint's kind: the
/// `angle` of a kind that has one, the `arm` (with the value that puts the
/// ball where the slave is) of a spherical joint, else moving the beam.
fn slave_off_fix(spec: Option<&crate::JointSpec>, at: &[f64; 3], expected: &[f64; 3]) -> String {
    let Some(kind) = spec.map(|s| &s.kind) else {
        return "move the beam".into();
    };
    if kind.has_angle() {
        return "move the beam, or set the joint's `angle`".into();
    }
    if kind.type_name() != "spherical" {
        return "move the beam to where the joint places the slave".into();
    }
    let arm: Vec<f64> = match kind.params().get("arm").and_then(|v| v.as_array()) {
        Some(a) => a
            .iter()
            .map(|v| {
                v.as_float()
                    .or(v.as_integer().map(|i| i as f64))
                    .unwrap_or(0.0)
            })
            .collect(),
        None => vec![0.0; 3],
    };
    let needed: Vec<String> = (0..3)
        .map(|i| {
            format!(
                "{:?}",
                at[i] - expected[i] + arm.get(i).copied().unwrap_or(0.0)
            )
        })
        .collect();
    format!(
        "move the beam, or put the ball on an arm of the master: `arm = [{}]` (the slave's \
         offset from the master node)",
        needed.join(", ")
    )
}

/// Builds the mechanism of `model` through the [`MechanismBuilder`], whose
/// checks (sections, geometry, joints placed by relation (1)) apply.
///
/// The model's invariants are checked first ([`Model::check`]), so a model
/// built or changed in Rust is refused with a message naming the key rather
/// than meshed with an index out of range.
pub fn build(model: &Model) -> Result<Built, ModelError> {
    model.check()?;
    let mut b = MechanismBuilder::new();
    let (beam_nodes, beams) = add_beams(model, &mut b)?;
    add_supports(model, &mut b, &beam_nodes)?;
    let load_shares = add_loads(model, &mut b, &beam_nodes, &beams)?;
    let (joints, ground_nodes) = add_joints(model, &mut b, &beam_nodes)?;
    let body_nodes = add_rigid_bodies(model, &mut b, &beam_nodes)?;
    add_prescribed(model, &mut b, &beam_nodes, &joints)?;
    let mut mechanism = b.build();
    mechanism.spin = model.solver.rotation.map(|r| FrameSpin {
        axis: v(r.axis),
        origin: v(r.origin),
        rate: r.rate,
        mass: model.solver.mass,
    });
    let beam_nodes = beam_nodes
        .into_iter()
        .map(|nodes| nodes.into_iter().map(NodeId::index).collect())
        .collect();
    let beam_elements = beams.iter().map(|b| b.elements()).collect();
    let mut built = Built {
        mechanism,
        beam_nodes,
        beam_elements,
        motion: Motion::rest(0),
        ground_nodes,
        body_nodes,
        load_shares,
    };
    built.motion = initial_motion(model, &built);
    built.mechanism.names = names(model, &built);
    crate::initial_check::check(model, &built.mechanism, &built.beam_nodes, &built.motion)?;
    Ok(built)
}

/// The model's names of the built mechanism's parts: every node's label
/// (beam nodes `arm.3`, ground nodes `ground.<joint>`, offset bodies'
/// centres `body.<name>`), the beams' element ranges, and the
/// `[[prescribed]]` entry of every prescribed nodal DOF (the mechanism
/// numbers only those, not the driven joints).
fn names(model: &Model, built: &Built) -> Names {
    let mut nodes = vec![String::new(); built.mechanism.mesh.node_count()];
    for (b, beam) in built.beam_nodes.iter().enumerate() {
        for (k, &n) in beam.iter().enumerate() {
            nodes[n] = model.node_label(NodeRef { beam: b, node: k });
        }
    }
    for &(j, n) in &built.ground_nodes {
        nodes[n] = format!("ground.{}", model.joints[j].name);
    }
    for &(b, n) in &built.body_nodes {
        nodes[n] = format!("body.{}", model.rigid_bodies[b].name);
    }
    Names {
        nodes,
        beams: model
            .beams
            .iter()
            .zip(&built.beam_elements)
            .map(|(b, r)| (b.name.clone(), r.clone()))
            .collect(),
        prescribed: model
            .prescribed
            .iter()
            .enumerate()
            .filter(|(_, p)| matches!(p, PrescribedSpec::NodeDof { .. }))
            .map(|(i, _)| i)
            .collect(),
    }
}

/// Meshes the beams of `model` in `b`, with their sections' structural
/// damping: every beam's node ids (`[b][k]`) and the beams.
fn add_beams(
    model: &Model,
    b: &mut MechanismBuilder,
) -> Result<(Vec<Vec<NodeId>>, Vec<Beam>), ModelError> {
    let mut beam_nodes: Vec<Vec<NodeId>> = Vec::with_capacity(model.beams.len());
    let mut beams = Vec::with_capacity(model.beams.len());
    for (i, beam) in model.beams.iter().enumerate() {
        check_paper_elements(model, i, beam)?;
        let s = &model.sections[beam.section];
        let nodes = b
            .beam(BeamDef {
                shape: beam.geometry,
                elements: beam.elements,
                nodes_per_element: beam.nodes_per_element,
                section: s.values,
            })
            .map_err(|e| refused(model, format!("beam[{i}]"), e))?;
        if s.damping > 0.0 {
            check_damping_integrator(model, beam)?;
            b.damping(&nodes, s.damping)
                .map_err(|e| refused(model, format!("section[{}].damping", beam.section), e))?;
        }
        beam_nodes.push(nodes.nodes().to_vec());
        beams.push(nodes);
    }
    Ok((beam_nodes, beams))
}

/// The paper's energy-momentum integrator runs on 2-node elements only:
/// checks beam `beam` (`beam[i]`) of `model`.
fn check_paper_elements(model: &Model, i: usize, beam: &BeamSpec) -> Result<(), ModelError> {
    if let Analysis::Dynamic { integrator, .. } = model.solver.analysis {
        if integrator == IntegratorKind::EnergyMomentumPaper && beam.nodes_per_element != 2 {
            return Err(ModelError::new(
                &model.path,
                format!("beam[{i}].nodes_per_element"),
                None,
                format!(
                    "integrator = \"{}\" runs on 2-node elements (the paper's internal force is the midpoint form of the linear element); use nodes_per_element = 2 with more elements, or integrator = \"energy-momentum\"",
                    integrator.name()
                ),
            ));
        }
    }
    Ok(())
}

/// Structural damping runs with the Newmark and generalized-alpha
/// integrators only: checks the damped section of beam `beam` of `model`.
fn check_damping_integrator(model: &Model, beam: &BeamSpec) -> Result<(), ModelError> {
    if let Analysis::Dynamic { integrator, .. } = model.solver.analysis {
        if !matches!(
            integrator,
            IntegratorKind::Newmark | IntegratorKind::GeneralizedAlpha { .. }
        ) {
            return Err(ModelError::new(
                &model.path,
                format!("section[{}].damping", beam.section),
                None,
                format!(
                    "structural damping runs with integrator = \"newmark\" or \
                     \"generalized-alpha\", not \"{}\" (the midpoint schemes' \
                     conservation statements have no place for it); change the \
                     integrator or remove `damping`",
                    integrator.name()
                ),
            ));
        }
    }
    Ok(())
}

/// Fixes the supported DOFs of `model` in `b` (beam node ids `beam_nodes`).
fn add_supports(
    model: &Model,
    b: &mut MechanismBuilder,
    beam_nodes: &[Vec<NodeId>],
) -> Result<(), ModelError> {
    let node = |r: NodeRef| beam_nodes[r.beam][r.node];
    for (i, s) in model.supports.iter().enumerate() {
        let dofs: Vec<Dof> = (0..6)
            .filter(|&d| s.fixed[d])
            .filter_map(Dof::from_index)
            .collect();
        b.fix(node(s.node), &dofs)
            .map_err(|e| refused(model, format!("support[{i}]"), e))?;
    }
    Ok(())
}

/// Applies the concentrated and distributed loads of `model` and its
/// gravity in `b` (beam node ids `beam_nodes`, meshed beams `beams`);
/// returns [`Built::load_shares`].
fn add_loads(
    model: &Model,
    b: &mut MechanismBuilder,
    beam_nodes: &[Vec<NodeId>],
    beams: &[Beam],
) -> Result<Vec<Vec<(usize, f64)>>, ModelError> {
    let node = |r: NodeRef| beam_nodes[r.beam][r.node];
    let mut shares = Vec::new();
    for (i, l) in model.loads.iter().enumerate() {
        let scale = schedule(&l.time, &model.solver.analysis);
        let first = b.load_count();
        if l.follower {
            b.follower_load(node(l.node), v(l.force), v(l.moment), scale)
        } else {
            b.load(node(l.node), v(l.force), v(l.moment), scale)
        }
        .map_err(|e| refused(model, format!("load[{i}]"), e))?;
        shares.push(if l.follower {
            vec![]
        } else {
            vec![(first, 1.0)]
        });
    }
    for (i, l) in model.distributed_loads.iter().enumerate() {
        let scale = schedule(&l.time, &model.solver.analysis);
        let beam = &beams[l.beam];
        let first = b.load_count();
        let refuse = |e| refused(model, format!("distributed_load[{i}]"), e);
        let split = b.distributed_shares(beam).map_err(refuse)?;
        if l.follower {
            b.follower_distributed_load(beam, v(l.force), v(l.moment), scale)
        } else {
            b.distributed_load(beam, v(l.force), v(l.moment), scale)
        }
        .map_err(refuse)?;
        let dead = split.iter().enumerate().map(|(k, &(_, w))| (first + k, w));
        shares.push(if l.follower { vec![] } else { dead.collect() });
    }
    b.gravity(v(model.gravity), schedule(&None, &model.solver.analysis))
        .map_err(|e| refused(model, "gravity".into(), e))?;
    add_rust_loads(model, b, beam_nodes);
    Ok(shares)
}

/// The `[[rust_load]]` functions as load fields of the mechanism: row `k`
/// of a function's output goes to the 6 generalised forces of its `k`-th
/// node. (Unbound functions were refused by [`Model::check`].)
fn add_rust_loads(model: &Model, b: &mut MechanismBuilder, beam_nodes: &[Vec<NodeId>]) {
    for l in &model.rust_loads {
        let Some(f) = l.field.clone() else { continue };
        let dofs: Vec<usize> = l
            .nodes
            .iter()
            .map(|r| 6 * beam_nodes[r.beam][r.node].index())
            .collect();
        b.load_field(move |t, out| {
            let mut rows = vec![[0.0; 6]; dofs.len()];
            (f.0)(t, &mut rows);
            for (row, &d) in rows.iter().zip(&dofs) {
                for (c, x) in row.iter().enumerate() {
                    out[d + c] += x;
                }
            }
        });
    }
}

/// The ids of placed joints, and the ground node of every joint to the
/// ground as `(joint index, node)`.
type PlacedJoints = (Vec<JointId>, Vec<(usize, usize)>);

/// Places the joints of `model` in `b` (beam node ids `beam_nodes`): their
/// ids, and the ground node of every joint to the ground as
/// `(joint index, node)`.
fn add_joints(
    model: &Model,
    b: &mut MechanismBuilder,
    beam_nodes: &[Vec<NodeId>],
) -> Result<PlacedJoints, ModelError> {
    let node = |r: NodeRef| beam_nodes[r.beam][r.node];
    let mut joints = Vec::with_capacity(model.joints.len());
    let mut ground_nodes = Vec::new();
    for (j, spec) in model.joints.iter().enumerate() {
        let angle = if spec.kind.has_angle() {
            spec.angle
        } else {
            0.0
        };
        let placed = match spec.master {
            Some(master) => b.joint(JointDef {
                name: spec.name.clone(),
                map: spec.kind.map().clone(),
                master: node(master),
                slave: node(spec.slave),
                angle,
            }),
            None => b
                .ground_joint(
                    spec.name.clone(),
                    spec.kind.map().clone(),
                    node(spec.slave),
                    angle,
                )
                .map(|(id, ground)| {
                    ground_nodes.push((j, ground.index()));
                    id
                }),
        };
        let id = placed.map_err(|e| {
            let key = match e {
                BuildError::SlaveOff { .. } => format!("joint[{j}].slave"),
                _ => format!("joint[{j}]"),
            };
            refused(model, key, e)
        })?;
        joints.push(id);
    }
    Ok((joints, ground_nodes))
}

/// Attaches the rigid bodies of `model` in `b` (beam node ids
/// `beam_nodes`): the centre-of-mass node of every body with an offset as
/// `(body index, node)`.
fn add_rigid_bodies(
    model: &Model,
    b: &mut MechanismBuilder,
    beam_nodes: &[Vec<NodeId>],
) -> Result<Vec<(usize, usize)>, ModelError> {
    let node = |r: NodeRef| beam_nodes[r.beam][r.node];
    let mut body_nodes = Vec::new();
    for (i, body) in model.rigid_bodies.iter().enumerate() {
        let carrier = node(body.node);
        let inertia = Matrix3::from_fn(|r, c| body.inertia[r][c]);
        let centre = b
            .rigid_body(
                body.name.clone(),
                carrier,
                body.mass,
                inertia,
                v(body.offset),
            )
            .map_err(|e| refused(model, format!("rigid_body[{i}]"), e))?;
        if centre != carrier {
            body_nodes.push((i, centre.index()));
        }
    }
    Ok(body_nodes)
}

/// Drives the prescribed joint angles and node DOFs of `model` in `b` (beam
/// node ids `beam_nodes`, joint ids `joints`).
fn add_prescribed(
    model: &Model,
    b: &mut MechanismBuilder,
    beam_nodes: &[Vec<NodeId>],
    joints: &[JointId],
) -> Result<(), ModelError> {
    let node = |r: NodeRef| beam_nodes[r.beam][r.node];
    for (i, p) in model.prescribed.iter().enumerate() {
        match p {
            PrescribedSpec::JointAngle { joint, angle } => {
                b.drive(joints[*joint], schedule_of(angle))
            }
            PrescribedSpec::NodeDof {
                node: r,
                dof,
                value,
            } => match Dof::from_index(*dof) {
                Some(d) => b.prescribe(node(*r), d, schedule_of(value)),
                None => Err(BuildError::NotFinite {
                    what: format!("dof index {dof} (0..6)"),
                    value: *dof as f64,
                }),
            },
        }
        .map_err(|e| refused(model, format!("prescribed[{i}]"), e))?;
    }
    Ok(())
}
