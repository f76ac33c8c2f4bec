//! flexmech-joints: master–slave joints (paper §2–3).
//!
//! Every joint kind is one small file implementing either
//! [`DependentJoint`] (one released rotation `ψ` about `t` and a released
//! translation `r_R = f(ψ)`: revolute, screw, rack-and-pinion, cam, lobe, and
//! any profile a user writes) or [`JointKinematics`] (rigid, spherical,
//! prismatic, cylindrical, and the rigid link that carries a rigid body's
//! centre of mass). The shared mechanism in [`kinematics`] derives the
//! variational map `N`, its derivative and the exact placement of the slave by
//! automatic differentiation; [`dependent`] derives `f′`, the secant `G` and
//! the paper's incremental map `Ñ`; [`incremental`] gives every kind its exact
//! step map for the conserving schemes.

#![warn(missing_docs)]

pub mod cam;
pub mod cylindrical;
pub mod dependent;
pub mod expression;
pub mod incremental;
pub mod joint_map;
pub mod kinematics;
pub mod lobe;
pub mod model_joint;
pub mod prismatic;
pub mod rack_pinion;
pub mod revolute;
pub mod rigid;
pub mod rigid_link;
pub mod screw;
pub mod seeded_step;
pub mod spherical;

pub use cam::Cam;
pub use cylindrical::Cylindrical;
pub use dependent::{parameter_slopes, DependentJoint, DependentJointMaps};
pub use expression::ExpressionJoint;
pub use incremental::{JointStep, StepDual};
pub use joint_map::JointMap;
pub use kinematics::{
    Angle, AngleAt, AngleSlide, BallRotation, Coordinates, CoordinatesOf, JointKinematics,
    NoCoordinates, ReleasedState, Slide, LOCAL, MAX_RELEASED,
};
pub use lobe::{Lift, Lobe, PeriodicSpline};
pub use model_joint::{ModelJoint, ParamError};
pub use prismatic::Prismatic;
pub use rack_pinion::RackPinion;
pub use revolute::Revolute;
pub use rigid::Rigid;
pub use rigid_link::RigidLink;
pub use screw::Screw;
pub use seeded_step::{SeededStep, StepLanes};
pub use spherical::{Spherical, SphericalParams};
