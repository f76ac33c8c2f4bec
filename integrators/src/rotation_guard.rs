//! Guard against a silent wrap of the elements' interpolation: the
//! strain-invariant interpolation takes principal logarithms of the rotations
//! between an element's nodes (`|φ| ≤ π`), so an element turned past π
//! between its nodes would be read as turned the other way — a straight beam
//! "rolled" six times would report no strain at all. After every converged
//! step each element's relative rotations must stay below
//! [`Element::ROTATION_LIMIT`] and change by less than
//! [`Element::ROTATION_STEP_LIMIT`]; otherwise the analysis stops with
//! [`SolveError::ElementRotation`], whose fix is more elements (or smaller
//! steps). A prescribed nodal rotation is applied as a rotation by the
//! change of its value, which is ambiguous past π (a change of 2π is no
//! rotation at all): its change per step must stay below the same step
//! limit ([`SolveError::PrescribedRotationStep`]). A change too large for one
//! step is retried with a smaller step; a rotation beyond the limit stops
//! the analysis.

use crate::constraints::MechanismState;
use crate::error::{NewtonFailure, SolveError};
use crate::mechanism::Mechanism;
use flexmech_core::element_pair::{relative_rotations_into, relative_rotations_of};
use flexmech_core::mesh::RelativeRotations;
use flexmech_core::{Configuration, Element};

/// Whether a smaller step cures the guard's objection (a change too large
/// for one step, not a rotation beyond the limit): the solvers then retry
/// with a halved step ([`NewtonFailure::Rejected`]) instead of stopping.
pub(crate) fn cured_by_smaller_steps(error: &SolveError) -> bool {
    match error {
        SolveError::ElementRotation { angle, .. } => *angle <= Element::ROTATION_LIMIT,
        SolveError::PrescribedRotationStep { .. } => true,
        _ => false,
    }
}

/// The guard's objection as a step failure when smaller steps cure it.
pub(crate) fn as_step_failure(error: SolveError) -> Result<NewtonFailure, SolveError> {
    if cured_by_smaller_steps(&error) {
        Ok(NewtonFailure::Rejected(error.to_string()))
    } else {
        Err(error)
    }
}

/// The relative rotations of the last accepted state.
#[derive(Debug, Clone)]
pub(crate) struct RotationGuard {
    previous: Vec<RelativeRotations>,
    /// The state being checked's, kept for its allocation.
    now: Vec<RelativeRotations>,
    prescribed: Vec<f64>,
}

impl RotationGuard {
    /// The guard at the initial (or any accepted) state.
    pub(crate) fn new(mech: &Mechanism, state: &MechanismState) -> Self {
        let mut previous = Vec::new();
        rotations(mech, &state.config, &mut previous);
        Self {
            previous,
            now: Vec::new(),
            prescribed: state.prescribed.clone(),
        }
    }

    /// The elements' relative rotations in the last accepted state (the
    /// records' strain energy takes them, [`crate::measure::strain_energy_with`]).
    pub(crate) fn accepted(&self) -> &[RelativeRotations] {
        &self.previous
    }

    /// Checks the converged state at `time` and accepts it.
    pub(crate) fn accept(
        &mut self,
        mech: &Mechanism,
        state: &MechanismState,
        time: f64,
    ) -> Result<(), SolveError> {
        for (index, (p, (now, before))) in mech
            .prescribed
            .iter()
            .zip(state.prescribed.iter().zip(&self.prescribed))
            .enumerate()
        {
            let change = (now - before).abs();
            if p.dof >= 3 && change > Element::ROTATION_STEP_LIMIT {
                return Err(SolveError::PrescribedRotationStep {
                    index: mech.names.prescribed_entry(index),
                    time,
                    change,
                });
            }
        }
        rotations(mech, &state.config, &mut self.now);
        for (element, (a, b)) in self.now.iter().zip(&self.previous).enumerate() {
            for (phi, before) in a.iter().zip(b.iter()) {
                let (angle, change) = (phi.norm(), (phi - before).norm());
                if angle > Element::ROTATION_LIMIT || change > Element::ROTATION_STEP_LIMIT {
                    return Err(SolveError::ElementRotation {
                        element,
                        beam: mech.names.element(element),
                        time,
                        angle,
                        change,
                    });
                }
            }
        }
        std::mem::swap(&mut self.previous, &mut self.now);
        self.prescribed.clone_from(&state.prescribed);
        Ok(())
    }
}

/// Every element's relative rotations at `config` into `out` (cleared
/// first).
fn rotations(mech: &Mechanism, config: &Configuration, out: &mut Vec<RelativeRotations>) {
    let elements = &mech.mesh.elements;
    out.clear();
    if !crate::threads::split_nodes(elements.len()) {
        return relative_rotations_into(elements, &config.rot, out);
    }
    // On two threads for a large mesh, half the elements each (cut at an
    // even element), each element's on its own: the same either way.
    let mid = (elements.len() / 2) & !1;
    let halves = [&elements[..mid], &elements[mid..]];
    let outs = halves.map(|_| std::sync::Mutex::new(Vec::new()));
    crate::threads::for_each_item(vec![0, 1], |_, h| {
        let rotations = relative_rotations_of(halves[h], &config.rot);
        *outs[h].lock().unwrap_or_else(|e| e.into_inner()) = rotations;
    });
    for half in outs {
        out.append(&mut half.into_inner().unwrap_or_else(|e| e.into_inner()));
    }
}
