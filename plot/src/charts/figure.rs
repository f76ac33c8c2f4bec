//! The chart as the backends draw it: the pixel style, the legend corner,
//! curves reduced to drawable runs and the figure's layout — shared by the
//! PNG/SVG drawing ([`super::line`]), its legend and markers, the panels and
//! the PGFPlots copy, which all read the same prepared [`Figure`].

use plotters::style::RGBColor;

use super::style::Marker;
use super::ticks::Axis;

/// Width of the PNG (and of the SVG's canvas) in pixels.
pub const WIDTH: u32 = 1600;
/// Height of the PNG (and of the SVG's canvas) in pixels.
pub const HEIGHT: u32 = 1000;

// ---------------------------------------------------------------------------
// Style (pixel sizes at the output size; multiplied by the drawing scale)
// ---------------------------------------------------------------------------

pub(super) const MARGIN: f64 = 28.0;
pub(super) const TITLE_FONT: f64 = 52.0;
pub(super) const DESC_FONT: f64 = 46.0;
pub(super) const TICK_FONT: f64 = 44.0;
pub(super) const NOTE_FONT: f64 = 36.0;
pub(super) const TICK_LEN: f64 = 12.0;
pub(super) const LINE_WIDTH: f64 = 4.0;
/// Radius of the data markers ([`Series::mark_every`]).
pub(super) const MARKER_RADIUS: f64 = 7.0;
pub(super) const AXIS_WIDTH: f64 = 2.0;
pub(super) const NOTE_ROW: f64 = NOTE_FONT * 1.35;

// Legend (drawn and placed by [`super::legend`]).
pub(super) const LEGEND_FONT: f64 = 40.0;
pub(super) const LEGEND_PAD: f64 = 16.0;
pub(super) const LEGEND_SAMPLE: f64 = 84.0;
pub(super) const LEGEND_GAP: f64 = 14.0;
pub(super) const LEGEND_INSET: f64 = 18.0;
pub(super) const LEGEND_COLUMN_GAP: f64 = 36.0;
pub(super) const LEGEND_ROW: f64 = LEGEND_FONT * 1.3;

#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Corner {
    UpperRight,
    UpperLeft,
    LowerRight,
    LowerLeft,
    /// Below the plot, left-aligned with it (the plot is shortened to make room).
    Outside,
}

pub(super) const MARKER_COLOR: RGBColor = RGBColor(60, 60, 60);
pub(super) const MARKER_DASH: &[f64] = &[14.0, 9.0];

pub(super) fn px(v: f64) -> i32 {
    v.round() as i32
}

// ---------------------------------------------------------------------------
// Data and layout
// ---------------------------------------------------------------------------

/// A series reduced to drawable runs of points (plotted coordinates).
pub(super) struct Curve {
    pub(super) label: String,
    pub(super) color: RGBColor,
    pub(super) dash: &'static [f64],
    /// Whether its points are joined by a line (else markers only).
    pub(super) line: bool,
    pub(super) runs: Vec<Vec<(f64, f64)>>,
    /// Marker on every k-th drawn point (0: none).
    pub(super) mark_every: usize,
    /// Its shape ([`Marker::None`] when `mark_every` is 0).
    pub(super) marker: Marker,
}

/// Pixel geometry of the figure at one drawing scale (1 for the SVG, the
/// supersampling factor for the PNG).
#[derive(Debug, Clone)]
pub(super) struct Layout {
    pub(super) scale: f64,
    pub(super) x: Axis,
    pub(super) y: Axis,
    pub(super) top: f64,
    pub(super) right_margin: f64,
    /// Below the x axis' label: the margin, and the legend when it is
    /// outside the plot.
    pub(super) bottom_margin: f64,
    pub(super) x_area: f64,
    pub(super) y_area: f64,
    /// Plot rectangle: left, top, right, bottom.
    pub(super) plot: (f64, f64, f64, f64),
    /// The axis descriptions' font size in pixels: [`DESC_FONT`], smaller
    /// where a description would not fit along its axis.
    pub(super) desc_font: f64,
    /// Row (0 = nearest the plot) of each marker label.
    pub(super) marker_rows: Vec<usize>,
}

/// Everything needed to draw, independent of the backend.
pub(super) struct Figure {
    pub(super) title: String,
    pub(super) x_label: String,
    pub(super) y_label: String,
    pub(super) log_y: bool,
    pub(super) curves: Vec<Curve>,
    pub(super) markers: Vec<(f64, String)>,
    /// Plotted x and y ranges before ticks are chosen.
    pub(super) x_range: (f64, f64),
    pub(super) y_range: (f64, f64),
    pub(super) legend: Option<Corner>,
    /// Legend columns (more than one only below the plot).
    pub(super) legend_columns: usize,
}
