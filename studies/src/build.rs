//! From a validated [`Model`] to the [`Mechanism`] the solvers work on: mesh
//! the beams, number the nodes, apply supports, loads and gravity.

use crate::model::{Analysis, BeamGeometry, Model, ModelError, NodeRef, TimeFunction};
use flexmech_core::{Mesh, Section};
use flexmech_integrators::{Mechanism, NodalLoad, Schedule};
use nalgebra::Vector3;

/// A mechanism with the numbering that relates it back to the model file.
#[derive(Debug, Clone)]
pub struct Built {
    /// What the solvers work on.
    pub mechanism: Mechanism,
    /// Global node numbers of every beam's nodes (`beam_nodes[b][k]`).
    pub beam_nodes: Vec<Vec<usize>>,
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
        (Some(f), _) => {
            let f = f.clone();
            Schedule::new(move |t| f.eval(t))
        }
        (None, Analysis::Static { .. }) => Schedule::ramp(),
        (None, Analysis::Dynamic { .. }) => Schedule::constant(1.0),
    }
}

/// Features of the model format that this version cannot run yet are reported
/// as errors naming the key, never silently ignored.
fn unsupported(model: &Model) -> Result<(), ModelError> {
    let err = |key: &str, what: &str| {
        Err(ModelError::new(
            &model.path,
            key,
            None,
            format!("{what} cannot be solved by this version of flexmech yet; remove it to run the rest"),
        ))
    };
    if !model.joints.is_empty() {
        return err("joint[0]", "joints");
    }
    if !model.prescribed.is_empty() {
        return err("prescribed[0]", "prescribed motion");
    }
    if let Analysis::Dynamic { .. } = model.solver.analysis {
        return err("solver.analysis", "dynamic analysis");
    }
    if !model.initial_velocities.is_empty() {
        return err("initial_velocity[0]", "initial velocities");
    }
    Ok(())
}

/// Builds the mechanism of `model`.
pub fn build(model: &Model) -> Result<Built, ModelError> {
    unsupported(model)?;
    let mut mesh = Mesh::default();
    let mut beam_nodes = Vec::with_capacity(model.beams.len());
    for (b, beam) in model.beams.iter().enumerate() {
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
    Ok(Built {
        mechanism,
        beam_nodes,
    })
}
