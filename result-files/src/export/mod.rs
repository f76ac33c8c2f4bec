//! Views of a result file beyond line charts: the ParaView time series
//! ([`paraview`], `flexmech export --vtk`) and animations (`flexmech_plot::animation`,
//! `flexmech animate`), both drawn from the same [`Frames`].

pub mod frames;
pub mod mode_frames;
pub mod paraview;
pub mod vtu;

pub use frames::Frames;
pub use mode_frames::mode_frames;
pub use paraview::{export_mode_vtk, export_vtk, ExportError};
