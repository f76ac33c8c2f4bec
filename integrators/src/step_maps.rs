//! The conserving schemes' joints: every joint's incremental map `Ñ` of a
//! step (paper eqs 21–23, [`JointStep`]) evaluated once per Newton
//! evaluation and shared by the three places that need it — the slaves'
//! tangent rows ([`Topology::refresh_rows`]), the reduced residual `Ñᵀ g`
//! ([`Topology::reduce_incremental`]) and the joints' tangent blocks
//! ([`Topology::incremental_blocks`]). With the tangent, one seeded map per
//! joint ([`JointStep::seeded`]) gives all three: its real parts are the map
//! and its lanes the derivative along the step's end state.
//!
//! [`Topology::refresh_rows`]: crate::constraints::Topology::refresh_rows
//! [`Topology::reduce_incremental`]: crate::constraints::Topology::reduce_incremental
//! [`Topology::incremental_blocks`]: crate::constraints::Topology::incremental_blocks

use crate::constraints::MechanismState;
use crate::mechanism::Mechanism;
use flexmech_joints::incremental::NodePose;
use flexmech_joints::{JointStep, StepDual};

/// Every joint's `Ñ` over the step `start → end` (model order), and, when
/// the tangent is wanted, the same maps seeded along the end state.
#[derive(Debug, Clone, Default)]
pub struct StepMaps {
    /// `Ñ` of each joint.
    pub values: Vec<JointStep>,
    /// `Ñ` of each joint seeded along the step's end state (empty without the
    /// tangent).
    pub seeded: Vec<JointStep<StepDual>>,
}

impl StepMaps {
    /// The maps of every joint of `mech` over `start → end`; `seeded` adds
    /// the seeded maps and takes the values from their real parts (equal to
    /// the unseeded maps to round-off: a dual division multiplies by the
    /// reciprocal).
    pub fn new(
        mech: &Mechanism,
        start: &MechanismState,
        end: &MechanismState,
        seeded: bool,
    ) -> Self {
        let joints = 0..mech.joints.len();
        if seeded {
            let seeded: Vec<_> = joints
                .map(|j| {
                    let (master, released) = ends(mech, j, start, end);
                    mech.joints[j].map.incremental_step_seeded(master, released)
                })
                .collect();
            let values = seeded.iter().map(JointStep::value).collect();
            Self { values, seeded }
        } else {
            let values = joints
                .map(|j| {
                    let (master, released) = ends(mech, j, start, end);
                    mech.joints[j].map.incremental_step(master, released)
                })
                .collect();
            Self {
                values,
                seeded: Vec::new(),
            }
        }
    }
}

/// Joint `j`'s master poses and released states at both ends of the step.
fn ends<'a>(
    mech: &Mechanism,
    j: usize,
    start: &'a MechanismState,
    end: &'a MechanismState,
) -> ([NodePose<'a>; 2], [&'a flexmech_joints::ReleasedState; 2]) {
    let m = mech.joints[j].master;
    (
        [
            (&start.config.x[m], &start.config.rot[m]),
            (&end.config.x[m], &end.config.rot[m]),
        ],
        [&start.released[j], &end.released[j]],
    )
}
