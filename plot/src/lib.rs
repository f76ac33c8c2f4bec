//! flexmech-plot: publication charts of result files (PNG, SVG and their
//! PGFPlots copies) and animations of a run's motion (GIF). The only crate of
//! flexmech that draws.

#![warn(missing_docs)]

pub mod animation;
pub mod charts;
