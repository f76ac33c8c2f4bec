//! What the three jobs need, in one `use flexmech::prelude::*;`.

pub use crate::{data, App};

pub use flexmech_core::{cst, Scalar};
pub use flexmech_integrators::critical::{CriticalKind, CriticalPoint};
pub use flexmech_integrators::dynamics::{Integrator, Simulation};
pub use flexmech_integrators::modal::{ModeKind, ModeSet};
pub use flexmech_joints::model_joint::{direction, perpendicular_slide, positive};
pub use flexmech_joints::{DependentJoint, ModelJoint, ParamError};
pub use flexmech_model::{
    load_model, parse_model, BeamGeometry, JointRegistry, Model, ModelBuilder, ModelError,
    SectionValues,
};
pub use nalgebra::{Rotation3, Vector3};
pub use serde::Deserialize;
pub use std::path::Path;

#[cfg(feature = "plot")]
pub use flexmech_plot::charts::{Color, Dash, LineChart, Marker, Panels, Series};
#[cfg(feature = "hdf5")]
pub use flexmech_results::{
    restart_model, run, run_model, FileSink, Memory, OnStep, ResultReader, RunError, RunSummary,
    Sink,
};
#[cfg(feature = "studies")]
pub use flexmech_studies::{Component, DatasetFigure, Figure, Reduce, Study, StudyReport};
