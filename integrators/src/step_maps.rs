//! The conserving schemes' joints: every joint's incremental map `Ñ` of a
//! step (paper eqs 21–23, [`JointStep`]) evaluated once per Newton
//! evaluation and shared by the three places that need it — the slaves'
//! tangent rows ([`Topology::refresh_rows`]), the reduced residual `Ñᵀ g`
//! ([`Topology::reduce_incremental`]) and the joints' tangent blocks
//! ([`Topology::incremental_blocks`]). With the tangent, one seeded map per
//! joint ([`SeededStep`], along the lanes that reach the unknowns) gives all
//! three: its value is the map and its lanes the derivative along the step's
//! end state.
//!
//! [`Topology::refresh_rows`]: crate::constraints::Topology::refresh_rows
//! [`Topology::reduce_incremental`]: crate::constraints::Topology::reduce_incremental
//! [`Topology::incremental_blocks`]: crate::constraints::Topology::incremental_blocks

use crate::constraints::MechanismState;
use crate::mechanism::Mechanism;
use flexmech_joints::incremental::NodePose;
use flexmech_joints::{JointStep, SeededStep, StepLanes};

/// Every joint's `Ñ` over the step `start → end` (model order), and, when
/// the tangent is wanted, the same maps seeded along the lanes of the end
/// state that reach the unknowns.
#[derive(Debug, Clone, Default)]
pub struct StepMaps {
    /// `Ñ` of each joint.
    pub values: Vec<JointStep>,
    /// `Ñ` of each joint with its derivative along the step's end state
    /// (empty without the tangent).
    pub seeded: Vec<SeededStep>,
}

impl StepMaps {
    /// The maps of every joint of `mech` over `start → end`; with `lanes`
    /// (one per joint, [`Topology::step_lanes`]) the seeded maps too, and
    /// the values from them.
    ///
    /// [`Topology::step_lanes`]: crate::constraints::Topology::step_lanes
    pub fn new(
        mech: &Mechanism,
        start: &MechanismState,
        end: &MechanismState,
        lanes: Option<&[StepLanes]>,
    ) -> Self {
        let mut maps = Self::default();
        maps.fill(mech, start, end, lanes);
        maps
    }

    /// [`Self::new`] in place: the vectors keep their storage from one
    /// Newton evaluation to the next (one allocation each an evaluation
    /// otherwise).
    pub fn fill(
        &mut self,
        mech: &Mechanism,
        start: &MechanismState,
        end: &MechanismState,
        lanes: Option<&[StepLanes]>,
    ) {
        let joints = 0..mech.joints.len();
        self.values.clear();
        self.seeded.clear();
        if let Some(lanes) = lanes {
            self.seeded.extend(joints.map(|j| {
                let (master, released) = ends(mech, j, start, end);
                mech.joints[j]
                    .map
                    .incremental_step_lanes(master, released, lanes[j])
            }));
            let values = self.seeded.iter().map(|s| s.value.clone());
            self.values.extend(values);
        } else {
            self.values.extend(joints.map(|j| {
                let (master, released) = ends(mech, j, start, end);
                mech.joints[j].map.incremental_step(master, released)
            }));
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
