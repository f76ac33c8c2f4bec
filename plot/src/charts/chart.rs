//! The chart as data: curves, labels and markers — what the PNG/SVG
//! drawing ([`super::line`]) and the editable copies ([`super::pgfplots`])
//! are made from.

use super::style::{Color, Dash, Marker};

/// One curve: `y[i]` over `x[i]`. Points where either value is NaN or
/// infinite (or, on a logarithmic axis, where `y ≤ 0`) are left out and split
/// the curve.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend entry; an empty label keeps the series out of the legend.
    pub label: String,
    /// Abscissae.
    pub x: Vec<f64>,
    /// Ordinates, as many as `x`.
    pub y: Vec<f64>,
    /// A marker on every `mark_every`-th point (0: none, unless the curve
    /// has at most [`AUTO_MARKERS`] points, which are then all marked), so
    /// curves that lie on each other stay visible and short ones are not
    /// mistaken for lines through data. With a [`Self::marker`] set and
    /// `mark_every` 0, a curve of more than [`AUTO_MARKERS`] points is marked
    /// on every `⌈points / AUTO_MARKERS⌉`-th point.
    pub mark_every: usize,
    /// Line colour; `None`: the automatic cycle's colour for the series'
    /// place in the chart ([`super::auto_style`]).
    pub color: Option<Color>,
    /// Line pattern; `None`: the automatic cycle's.
    pub dash: Option<Dash>,
    /// Marker shape; `None`: filled circles where [`Self::mark_every`] puts
    /// them, `Some(Marker::None)`: no markers at all.
    pub marker: Option<Marker>,
}

/// Curves with at most this many points get a marker on every point.
pub const AUTO_MARKERS: usize = 12;

impl Series {
    /// A series from its label and values.
    pub fn new(label: impl Into<String>, x: Vec<f64>, y: Vec<f64>) -> Self {
        Self {
            label: label.into(),
            x,
            y,
            mark_every: 0,
            color: None,
            dash: None,
            marker: None,
        }
    }

    /// The series with a marker on every `k`-th point.
    pub fn with_markers(mut self, k: usize) -> Self {
        self.mark_every = k;
        self
    }

    /// The series drawn in `color` instead of the automatic cycle's.
    pub fn color(mut self, color: Color) -> Self {
        self.color = Some(color);
        self
    }

    /// The series drawn with the line pattern `dash`.
    pub fn dash(mut self, dash: Dash) -> Self {
        self.dash = Some(dash);
        self
    }

    /// The series marked with `marker` ([`Marker::None`]: never marked).
    pub fn marker(mut self, marker: Marker) -> Self {
        self.marker = Some(marker);
        self
    }

    /// The colour, pattern and marker (shape and spacing, 0 for none) this
    /// series is drawn with as the `index`-th of a chart, `points` being
    /// the number of its points that are drawn.
    pub(super) fn resolved_style(
        &self,
        index: usize,
        points: usize,
    ) -> (Color, Dash, Marker, usize) {
        let (color, dash) = super::style::auto_style(index);
        let every = match (self.marker, self.mark_every) {
            (_, 0) if self.dash == Some(Dash::Markers) => 1,
            (Some(Marker::None), _) => 0,
            (_, 0) if points <= AUTO_MARKERS => 1,
            (None, k) => k,
            (Some(_), 0) => points.div_ceil(AUTO_MARKERS),
            (Some(_), k) => k,
        };
        let marker = match self.marker {
            Some(m) if every > 0 => m,
            _ if every > 0 => Marker::Circle,
            _ => Marker::None,
        };
        (
            self.color.unwrap_or(color),
            self.dash.unwrap_or(dash),
            marker,
            every,
        )
    }
}

/// A line chart: curves, axis labels (with units, written as given) and
/// vertical marker lines such as a failure time.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LineChart {
    /// Text above the plot; may be empty.
    pub title: String,
    /// Label of the horizontal axis, e.g. `"time (s)"`.
    pub x_label: String,
    /// Label of the vertical axis, e.g. `"strain energy (J)"`.
    pub y_label: String,
    /// Logarithmic vertical axis (decades, labels `10ⁿ`).
    pub log_y: bool,
    /// The curves; colours and line styles are distinct for up to six.
    pub series: Vec<Series>,
    /// Vertical lines at `x` with a label shown above the plot.
    pub markers: Vec<(f64, String)>,
}

impl LineChart {
    /// An empty chart with a title and axis labels.
    pub fn new(
        title: impl Into<String>,
        x_label: impl Into<String>,
        y_label: impl Into<String>,
    ) -> Self {
        Self {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            ..Self::default()
        }
    }
}
