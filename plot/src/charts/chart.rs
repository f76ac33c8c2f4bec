//! The chart as data: curves, labels and markers — what the PNG/SVG
//! drawing ([`super::line`]) and the editable copies ([`super::pgfplots`])
//! are made from.

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
    /// mistaken for lines through data.
    pub mark_every: usize,
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
        }
    }

    /// The series with a marker on every `k`-th point.
    pub fn with_markers(mut self, k: usize) -> Self {
        self.mark_every = k;
        self
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
