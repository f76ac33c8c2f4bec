//! Publication-quality line charts (PNG and SVG) of result files.
//!
//! [`LineChart`] draws curves with a journal look: white background, framed
//! plot with a thin grid, axis labels as given (with their units), a framed
//! legend, colour-blind-safe colours with distinct dash patterns, and tick
//! labels with a common `×10ⁿ` factor or decades `10ⁿ` on a logarithmic axis.
//! Text uses only the DejaVu Sans face embedded through [`font`], never a
//! system font. [`plot_datasets`] is the `flexmech plot` command: charts of
//! HDF5 result datasets over `/time`.
//!
//! A [`Series`] may set its own [`Color`], [`Dash`] and [`Marker`]; unset,
//! it keeps the automatic cycle ([`auto_style`]). [`Panels`] lays several
//! charts out in a row or a grid, as one PNG, SVG and PGFPlots copy.

mod chart;
mod clip;
mod figure;
pub mod font;
mod legend;
mod line;
mod marks;
mod panels;
pub mod pgfplots;
mod plot;
mod strokes;
mod style;
#[cfg(test)]
mod tests;
mod ticks;

pub use chart::{LineChart, Series, AUTO_MARKERS};
pub use figure::{HEIGHT, WIDTH};
pub use line::ChartError;
pub use panels::Panels;
pub use plot::{plot_datasets, plot_with, unit_of, PlotError, PlotOptions};
pub use style::{auto_style, Color, Dash, Marker};
