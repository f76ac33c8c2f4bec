//! From a validated [`Model`] to the [`Mechanism`] the solvers work on: mesh
//! the beams, number the nodes, apply supports, loads and gravity.

use crate::model::{
    Analysis, BeamGeometry, IntegratorKind, JointSpec, Model, ModelError, NodeRef, PrescribedSpec,
    TimeFunction,
};
use flexmech_core::{Mesh, Section};
use flexmech_integrators::dynamics::Motion;
use flexmech_integrators::{JointInstance, Mechanism, NodalLoad, PrescribedDof, Schedule};
use flexmech_joints::{JointMap, ReleasedState, MAX_RELEASED};
use nalgebra::Vector3;
use std::sync::Arc;

/// A mechanism with the numbering that relates it back to the model file.
#[derive(Debug, Clone)]
pub struct Built {
    /// What the solvers work on.
    pub mechanism: Mechanism,
    /// Global node numbers of every beam's nodes (`beam_nodes[b][k]`).
    pub beam_nodes: Vec<Vec<usize>>,
    /// Initial velocities (dynamic analyses).
    pub motion: Motion,
}

impl Built {
    /// Global node number of a model node.
    pub fn node(&self, r: NodeRef) -> usize {
        self.beam_nodes[r.beam][r.node]
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
        (None, Analysis::Static { .. }) => Schedule::ramp(),
        (None, Analysis::Dynamic { .. }) => Schedule::constant(1.0),
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
    motion
}

/// A time function as a schedule.
fn schedule_of(f: &TimeFunction) -> Schedule {
    let f = f.clone();
    Schedule::new(move |t| f.eval(t))
}

/// The kinematics of a joint and its initial released coordinates: `angle`
/// starts the first coordinate of kinds whose first coordinate is an angle.
fn joint_map(spec: &JointSpec) -> (Arc<dyn JointMap>, ReleasedState) {
    let mut q0 = [0.0; MAX_RELEASED];
    if spec.kind.has_angle() {
        q0[0] = spec.angle;
    }
    (spec.kind.map().clone(), ReleasedState::new(q0))
}

/// Builds the mechanism of `model`.
///
/// The model's invariants are checked first ([`Model::check`]), so a model
/// built or changed in Rust is refused with a message naming the key rather
/// than meshed with an index out of range.
pub fn build(model: &Model) -> Result<Built, ModelError> {
    model.check()?;
    let mut mesh = Mesh::default();
    let mut beam_nodes = Vec::with_capacity(model.beams.len());
    for (b, beam) in model.beams.iter().enumerate() {
        if let Analysis::Dynamic { integrator, .. } = model.solver.analysis {
            if integrator == IntegratorKind::EnergyMomentumPaper && beam.nodes_per_element != 2 {
                return Err(ModelError::new(
                    &model.path,
                    format!("beam[{b}].nodes_per_element"),
                    None,
                    format!(
                        "integrator = \"{}\" runs on 2-node elements (the paper's internal force is the midpoint form of the linear element); use nodes_per_element = 2 with more elements, or integrator = \"energy-momentum\"",
                        integrator.name()
                    ),
                ));
            }
        }
        let s = &model.sections[beam.section];
        let section = Section::new(
            [s.ea, s.ga[0], s.ga[1]],
            [s.gj, s.ei[0], s.ei[1]],
            s.rho_a,
            s.rho_j,
        );
        let nodes = match &beam.geometry {
            BeamGeometry::Straight { start, end, e2 } => mesh.add_straight_beam(
                v(*start),
                v(*end),
                v(*e2),
                beam.elements,
                beam.nodes_per_element,
                section,
            ),
            BeamGeometry::Arc {
                start,
                center,
                normal,
                sweep,
                e2,
            } => mesh.add_arc_beam(
                v(*start),
                v(*center),
                v(*normal),
                *sweep,
                e2.map(v),
                beam.elements,
                beam.nodes_per_element,
                section,
            ),
        }
        .map_err(|e| {
            ModelError::new(
                &model.path,
                format!("beam[{b}]"),
                None,
                format!("beam `{}`: {e}", beam.name),
            )
        })?;
        beam_nodes.push(nodes);
    }
    let mut mechanism = Mechanism::new(mesh);
    let node = |r: NodeRef| beam_nodes[r.beam][r.node];
    for s in &model.supports {
        let f = &mut mechanism.fixed[node(s.node)];
        for (d, held) in s.fixed.iter().enumerate() {
            f[d] |= *held;
        }
    }
    for l in &model.loads {
        mechanism.loads.push(NodalLoad {
            node: node(l.node),
            force: v(l.force),
            moment: v(l.moment),
            scale: schedule(&l.time, &model.solver.analysis),
        });
    }
    mechanism.gravity = v(model.gravity);
    mechanism.gravity_scale = schedule(&None, &model.solver.analysis);
    let scale = mechanism
        .mesh
        .positions
        .iter()
        .map(|x| x.norm())
        .fold(1.0, f64::max);
    for (j, spec) in model.joints.iter().enumerate() {
        let (map, initial) = joint_map(spec);
        let (master, slave) = (node(spec.master), node(spec.slave));
        // The slave must start where relation (1) puts it.
        let x0 = &mechanism.mesh.positions;
        let (expected, _) = map.slave(&x0[master], &nalgebra::Matrix3::identity(), &initial);
        let gap = (x0[slave] - expected).norm();
        if !gap.is_finite() {
            // A profile that evaluates to NaN or ∞ (a tiny period, huge
            // coefficients, a pitch of 1e308) would pass a plain comparison.
            return Err(ModelError::new(
                &model.path,
                format!("joint[{j}]"),
                None,
                format!(
                    "joint `{}`: its released translation at the initial angle is not a finite \
                     number ({expected:?}); check the joint's parameters (pitch, radius, \
                     profile coefficients or table, period) and its `angle`",
                    spec.name
                ),
            ));
        }
        if gap > 1e-9 * scale {
            let p = |x: &Vector3<f64>| format!("({:.6}, {:.6}, {:.6})", x.x, x.y, x.z);
            return Err(ModelError::new(
                &model.path,
                format!("joint[{j}].slave"),
                None,
                format!(
                    "joint `{}`: the slave `{}` starts at {} but the master `{}` plus the released translation at the initial angle puts it at {} (off by {gap:.3e}); move the beam, or set the joint's `angle`",
                    spec.name,
                    model.node_label(spec.slave),
                    p(&x0[slave]),
                    model.node_label(spec.master),
                    p(&expected)
                ),
            ));
        }
        let driven = vec![None; map.released_count()];
        mechanism.joints.push(JointInstance {
            name: spec.name.clone(),
            master,
            slave,
            map,
            initial,
            driven,
        });
    }
    for p in &model.prescribed {
        match p {
            PrescribedSpec::JointAngle { joint, angle } => {
                mechanism.joints[*joint].driven[0] = Some(schedule_of(angle));
            }
            PrescribedSpec::NodeDof {
                node: r,
                dof,
                value,
            } => {
                mechanism.prescribed.push(PrescribedDof {
                    node: node(*r),
                    dof: *dof,
                    value: schedule_of(value),
                });
            }
        }
    }
    let mut built = Built {
        mechanism,
        beam_nodes,
        motion: Motion::rest(0),
    };
    built.motion = initial_motion(model, &built);
    crate::initial_check::check(model, &built.mechanism, &built.beam_nodes, &built.motion)?;
    Ok(built)
}
