//! Line charts in a journal style, written as a 1600×1000 px PNG and an SVG of
//! the same layout.
//!
//! Plotters draws the axes, tick labels and grid; this module chooses the
//! ticks and their labels, lays the figure out (title, marker labels, axis
//! areas), draws the curves with their own dash patterns, and places the
//! legend in the corner where it hides the least data.

use std::ffi::OsString;
use std::path::{Path, PathBuf};

use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint};
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::clip::clip_polyline;
use super::font;

/// Width of the PNG (and of the SVG's canvas) in pixels.
pub const WIDTH: u32 = 1600;
/// Height of the PNG (and of the SVG's canvas) in pixels.
pub const HEIGHT: u32 = 1000;

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

/// Why a chart could not be drawn or written; every variant names the file.
#[derive(Debug, thiserror::Error)]
pub enum ChartError {
    /// The chart has no series at all.
    #[error("chart {}: no series to draw", .path.display())]
    NoSeries {
        /// The PNG that was to be written.
        path: PathBuf,
    },
    /// A series' `x` and `y` differ in length.
    #[error(
        "chart {}: series \"{label}\" has {x_len} x values but {y_len} y values",
        .path.display()
    )]
    LengthMismatch {
        /// The PNG that was to be written.
        path: PathBuf,
        /// The series.
        label: String,
        /// Length of `x`.
        x_len: usize,
        /// Length of `y`.
        y_len: usize,
    },
    /// A series has no points.
    #[error("chart {}: series \"{label}\" is empty", .path.display())]
    EmptySeries {
        /// The PNG that was to be written.
        path: PathBuf,
        /// The series.
        label: String,
    },
    /// Every point of a series has a NaN or infinite coordinate.
    #[error(
        "chart {}: series \"{label}\" has no finite point (all x or y are NaN or infinite)",
        .path.display()
    )]
    NoFinitePoints {
        /// The PNG that was to be written.
        path: PathBuf,
        /// The series.
        label: String,
    },
    /// On a logarithmic axis, no finite point of a series has `y > 0`.
    #[error(
        "chart {}: series \"{label}\" has no positive finite value for the logarithmic y axis",
        .path.display()
    )]
    NoPositivePoints {
        /// The PNG that was to be written.
        path: PathBuf,
        /// The series.
        label: String,
    },
    /// A marker's position is NaN or infinite.
    #[error(
        "chart {}: marker \"{label}\" is at x = {x}, which is not finite",
        .path.display()
    )]
    BadMarker {
        /// The PNG that was to be written.
        path: PathBuf,
        /// The marker's label.
        label: String,
        /// Its position.
        x: f64,
    },
    /// Plotters rejected the embedded font (a packaging bug).
    #[error("chart {}: the embedded font could not be registered", .path.display())]
    Font {
        /// The PNG that was to be written.
        path: PathBuf,
    },
    /// Drawing or encoding failed.
    #[error("chart {}: drawing failed: {message}", .path.display())]
    Draw {
        /// The file being drawn.
        path: PathBuf,
        /// The backend's message.
        message: String,
    },
    /// The output directory or file could not be written.
    #[error("chart {}: {source}", .path.display())]
    Io {
        /// The file or directory.
        path: PathBuf,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
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

    /// Draws the chart into `<stem>.png` (1600×1000 px) and `<stem>.svg`,
    /// writes its editable copies `<stem>.csv` and `<stem>.tex` (PGFPlots,
    /// [`super::pgfplots`]) and returns the PNG and SVG paths. The extensions are appended, so a stem may contain
    /// dots (`out/nodes_arm.end_position`). Missing parent directories are
    /// created. Nothing is written when the data are unusable.
    pub fn render(&self, stem: &Path) -> Result<(PathBuf, PathBuf), ChartError> {
        let png = with_suffix(stem, ".png");
        let svg = with_suffix(stem, ".svg");
        let figure = Figure::prepare(self, &png)?;
        if !font::ensure_registered() {
            return Err(ChartError::Font { path: png });
        }
        if let Some(dir) = stem.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(|source| ChartError::Io {
                path: dir.to_path_buf(),
                source,
            })?;
        }
        write_png(&figure, &png)?;
        write_svg(&figure, &svg)?;
        let csv = with_suffix(stem, ".csv");
        super::pgfplots::write(self, &csv, &with_suffix(stem, ".tex"))
            .map_err(|source| ChartError::Io { path: csv, source })?;
        Ok((png, svg))
    }
}

/// Plotters' bitmap backend does not anti-alias lines: the PNG is drawn at
/// this multiple of its size and averaged down.
const SUPERSAMPLE: u32 = 2;

fn write_png(figure: &Figure, png: &Path) -> Result<(), ChartError> {
    let (w, h) = (WIDTH * SUPERSAMPLE, HEIGHT * SUPERSAMPLE);
    let mut big = vec![0u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut big, (w, h)).into_drawing_area();
        figure
            .draw(&root, f64::from(SUPERSAMPLE))
            .and_then(|()| root.present())
            .map_err(|e| draw_error(png, e))?;
    }
    let small = downsample(&big, w as usize, SUPERSAMPLE as usize);
    let mut backend = BitMapBackend::new(png, (WIDTH, HEIGHT));
    backend
        .blit_bitmap((0, 0), (WIDTH, HEIGHT), &small)
        .and_then(|()| backend.present())
        .map_err(|e| ChartError::Draw {
            path: png.to_path_buf(),
            message: e.to_string(),
        })
}

/// Averages `factor`×`factor` blocks of an RGB image `width` pixels wide.
fn downsample(rgb: &[u8], width: usize, factor: usize) -> Vec<u8> {
    let height = rgb.len() / (3 * width);
    let (w, h) = (width / factor, height / factor);
    let mut out = vec![0u8; w * h * 3];
    let n = (factor * factor) as u32;
    for y in 0..h {
        for x in 0..w {
            for c in 0..3 {
                let mut sum = 0u32;
                for dy in 0..factor {
                    let row = (y * factor + dy) * width;
                    for dx in 0..factor {
                        sum += u32::from(rgb[3 * (row + x * factor + dx) + c]);
                    }
                }
                out[3 * (y * w + x) + c] = ((sum + n / 2) / n) as u8;
            }
        }
    }
    out
}

fn write_svg(figure: &Figure, svg: &Path) -> Result<(), ChartError> {
    let mut text = String::new();
    {
        let root = SVGBackend::with_string(&mut text, (WIDTH, HEIGHT)).into_drawing_area();
        figure
            .draw(&root, 1.0)
            .and_then(|()| root.present())
            .map_err(|e| draw_error(svg, e))?;
    }
    let mut text = text.replace(
        &format!("font-family=\"{}\"", font::FAMILY),
        &format!("font-family=\"{}\"", font::SVG_FAMILY),
    );
    // The face itself, right after the opening <svg ...> tag.
    if let Some(end) = text
        .find("<svg")
        .and_then(|s| text[s..].find('>').map(|e| s + e + 1))
    {
        text.insert_str(end, &font::svg_font_face());
    }
    std::fs::write(svg, text).map_err(|source| ChartError::Io {
        path: svg.to_path_buf(),
        source,
    })
}

fn with_suffix(stem: &Path, suffix: &str) -> PathBuf {
    let mut name = OsString::from(stem.as_os_str());
    name.push(suffix);
    PathBuf::from(name)
}

fn draw_error<E: std::error::Error + Send + Sync>(
    path: &Path,
    e: DrawingAreaErrorKind<E>,
) -> ChartError {
    ChartError::Draw {
        path: path.to_path_buf(),
        message: e.to_string(),
    }
}

// ---------------------------------------------------------------------------
// Style (pixel sizes at the output size; multiplied by the drawing scale)
// ---------------------------------------------------------------------------

const MARGIN: f64 = 28.0;
const TITLE_FONT: f64 = 52.0;
const DESC_FONT: f64 = 46.0;
const TICK_FONT: f64 = 44.0;
const LEGEND_FONT: f64 = 40.0;
const NOTE_FONT: f64 = 36.0;
const TICK_LEN: f64 = 12.0;
const LINE_WIDTH: f64 = 4.0;
/// Radius of the data markers ([`Series::mark_every`]).
const MARKER_RADIUS: f64 = 7.0;
const AXIS_WIDTH: f64 = 2.0;
const LEGEND_PAD: f64 = 16.0;
const LEGEND_SAMPLE: f64 = 84.0;
const LEGEND_GAP: f64 = 14.0;
const LEGEND_INSET: f64 = 18.0;
const LEGEND_COLUMN_GAP: f64 = 36.0;
const LEGEND_ROW: f64 = LEGEND_FONT * 1.3;
const NOTE_ROW: f64 = NOTE_FONT * 1.35;

/// Okabe–Ito colours (distinguishable with colour-vision deficiencies).
const PALETTE: [RGBColor; 6] = [
    RGBColor(0, 114, 178),   // blue
    RGBColor(213, 94, 0),    // vermilion
    RGBColor(0, 158, 115),   // bluish green
    RGBColor(204, 121, 167), // reddish purple
    RGBColor(230, 159, 0),   // orange
    RGBColor(86, 180, 233),  // sky blue
];

/// Dash patterns in pixels (on, off, on, off, …); empty = solid.
const DASHES: [&[f64]; 6] = [
    &[],
    &[24.0, 12.0],
    &[4.0, 10.0],
    &[26.0, 10.0, 4.0, 10.0],
    &[44.0, 14.0],
    &[22.0, 8.0, 4.0, 8.0, 4.0, 8.0],
];

const MARKER_COLOR: RGBColor = RGBColor(60, 60, 60);
const MARKER_DASH: &[f64] = &[14.0, 9.0];

fn series_style(index: usize) -> (RGBColor, &'static [f64]) {
    let n = PALETTE.len();
    (PALETTE[index % n], DASHES[(index + index / n) % n])
}

/// Width in pixels of `text` at font size `size`.
fn text_width(text: &str, size: f64) -> f64 {
    font::text(size)
        .font
        .box_size(text)
        .map(|(w, _)| f64::from(w))
        .unwrap_or(0.6 * size * text.chars().count() as f64)
}

fn px(v: f64) -> i32 {
    v.round() as i32
}

// ---------------------------------------------------------------------------
// Ticks
// ---------------------------------------------------------------------------

/// One axis: its range (in plotted coordinates: log10 of the value on a
/// logarithmic axis), labelled ticks, unlabelled minor grid lines and an
/// optional common factor such as `×10⁻³`.
#[derive(Debug, Clone)]
struct Axis {
    lo: f64,
    hi: f64,
    ticks: Vec<f64>,
    labels: Vec<String>,
    minor: Vec<f64>,
    factor: Option<String>,
}

impl Axis {
    fn linear(lo: f64, hi: f64, target: usize) -> Self {
        let (step, ticks) = nice_ticks(lo, hi, target);
        let (labels, factor) = linear_labels(&ticks, step);
        Self {
            lo,
            hi,
            ticks,
            labels,
            minor: Vec::new(),
            factor,
        }
    }

    /// `lo`, `hi` are the data's exponents (log10). The range gets a small
    /// margin, or is widened to whole decades when it would otherwise hold
    /// fewer than two of them.
    fn logarithmic(lo: f64, hi: f64) -> Self {
        let pad = 0.04 * (hi - lo);
        let (mut lo, mut hi) = (lo - pad, hi + pad);
        if hi.floor() - lo.ceil() < 1.0 {
            lo = (lo + 1e-9).floor();
            hi = (hi - 1e-9).ceil().max(lo + 1.0);
        }
        let first = (lo - 1e-9).ceil() as i64;
        let last = (hi + 1e-9).floor() as i64;
        let decades = last - first;
        let every = (decades + 8) / 9; // at most ~9 labelled decades
        let mut ticks = Vec::new();
        let mut minor = Vec::new();
        for e in first..=last {
            if e.rem_euclid(every) == 0 {
                ticks.push(e as f64);
            } else {
                minor.push(e as f64);
            }
        }
        if decades <= 6 {
            for e in first - 1..=last {
                minor.extend(
                    (2..=9)
                        .map(|m| e as f64 + f64::from(m).log10())
                        .filter(|v| *v > lo && *v < hi),
                );
            }
        }
        let mut labels: Vec<String> = ticks
            .iter()
            .map(|&e| format!("10{}", superscript(e as i64)))
            .collect();
        // Fewer than three labelled decades: label 2× and 5× as well.
        if ticks.len() < 3 {
            for e in first - 1..=last {
                for m in [2u8, 5] {
                    let v = e as f64 + f64::from(m).log10();
                    if v > lo && v < hi {
                        ticks.push(v);
                        labels.push(format!("{m}×10{}", superscript(e)));
                        minor.retain(|&w| (w - v).abs() > 1e-9);
                    }
                }
            }
        }
        Self {
            lo,
            hi,
            ticks,
            labels,
            minor,
            factor: None,
        }
    }

    fn label_of(&self, v: f64) -> String {
        self.ticks
            .iter()
            .position(|&t| t == v)
            .map(|i| self.labels[i].clone())
            .unwrap_or_default()
    }

    fn widest_label(&self, size: f64) -> f64 {
        self.labels
            .iter()
            .map(|l| text_width(l, size))
            .fold(0.0, f64::max)
    }
}

/// A linear plotters coordinate whose grid lines are exactly an [`Axis`]'s
/// ticks (bold) and minor lines (light).
struct TickRange {
    linear: RangedCoordf64,
    ticks: Vec<f64>,
    minor: Vec<f64>,
}

impl TickRange {
    fn new(axis: &Axis) -> Self {
        Self {
            linear: (axis.lo..axis.hi).into(),
            ticks: axis.ticks.clone(),
            minor: axis.minor.clone(),
        }
    }
}

impl Ranged for TickRange {
    type FormatOption = DefaultFormatting;
    type ValueType = f64;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        self.linear.map(value, limit)
    }

    fn key_points<Hint: KeyPointHint>(&self, hint: Hint) -> Vec<f64> {
        if hint.weight().allow_light_points() {
            self.minor.clone()
        } else {
            self.ticks.clone()
        }
    }

    fn range(&self) -> std::ops::Range<f64> {
        self.linear.range()
    }
}

/// Ticks at multiples of 1, 2, 2.5 or 5 × 10ᵏ inside `[lo, hi]`, as close to
/// `target` ticks as possible (2.5 slightly disfavoured, then coarser steps
/// preferred). Returns the step and the ticks.
fn nice_ticks(lo: f64, hi: f64, target: usize) -> (f64, Vec<f64>) {
    let ticks_of = |step: f64| -> Vec<f64> {
        let first = (lo / step - 1e-9).ceil() as i64;
        let last = (hi / step + 1e-9).floor() as i64;
        (first..=last)
            .map(|k| {
                let t = k as f64 * step;
                if t.abs() < step * 1e-9 {
                    0.0
                } else {
                    t
                }
            })
            .collect()
    };
    let base = 10f64.powf(((hi - lo) / target.max(1) as f64).log10().floor());
    let mut best: Option<(usize, f64)> = None;
    for mag in [0.1 * base, base, 10.0 * base] {
        for m in [1.0, 2.0, 2.5, 5.0] {
            let step = m * mag;
            let n = ((hi / step + 1e-9).floor() - (lo / step - 1e-9).ceil() + 1.0).max(0.0);
            if n < 2.0 {
                continue;
            }
            let score = 2 * (n as usize).abs_diff(target) + usize::from(m == 2.5);
            if best.is_none_or(|(s, _)| score <= s) {
                best = Some((score, step));
            }
        }
    }
    let step = best.map_or(hi - lo, |(_, s)| s);
    (step, ticks_of(step))
}

/// Tick labels with as many decimals as the step needs; very large or small
/// values get a common factor `×10ᵏ` shown once beside the axis. When the
/// ticks differ only far behind their leading digits (a conserved energy, say),
/// they are labelled as deviations from a reference tick, and the note beside
/// the axis reads `×10ᵏ + offset`.
fn linear_labels(ticks: &[f64], step: f64) -> (Vec<String>, Option<String>) {
    let max_abs = ticks.iter().fold(0.0f64, |m, t| m.max(t.abs()));
    let offset = if max_abs > 0.0 && step < 1e-4 * max_abs && !ticks.is_empty() {
        ticks[ticks.len() / 2]
    } else {
        0.0
    };
    let shifted: Vec<f64> = ticks.iter().map(|t| t - offset).collect();
    let max_abs = shifted.iter().fold(0.0f64, |m, t| m.max(t.abs()));
    let exponent = if max_abs >= 1e4 || (max_abs > 0.0 && max_abs < 1e-2) {
        max_abs.log10().floor() as i32
    } else {
        0
    };
    let scale = 10f64.powi(-exponent);
    let scaled_step = step * scale;
    let decimals = (0..=12)
        .find(|&d| {
            let v = scaled_step * 10f64.powi(d);
            (v - v.round()).abs() < 1e-6 * v.max(1.0)
        })
        .unwrap_or(12) as usize;
    let labels = shifted
        .iter()
        .map(|t| minus_sign(&format!("{:.*}", decimals, t * scale)))
        .collect();
    let factor = (exponent != 0).then(|| format!("×10{}", superscript(i64::from(exponent))));
    if offset == 0.0 {
        return (labels, factor);
    }
    // Enough significant digits that the offset is exact to the tick step.
    let digits = ((offset.abs() / step).log10().ceil().max(1.0) as usize).min(16);
    let off = minus_sign(&format!("{:+.*e}", digits, offset));
    let note = match factor {
        Some(f) => format!("{f} {off}"),
        None => off,
    };
    (labels, Some(note))
}

/// Typographic minus; no negative zero.
fn minus_sign(text: &str) -> String {
    let zero = text
        .trim_start_matches('-')
        .chars()
        .all(|c| c == '0' || c == '.');
    if zero {
        text.trim_start_matches('-').to_owned()
    } else {
        text.replace('-', "\u{2212}")
    }
}

fn superscript(n: i64) -> String {
    n.to_string()
        .chars()
        .map(|c| match c {
            '-' => '⁻',
            '0' => '⁰',
            '1' => '¹',
            '2' => '²',
            '3' => '³',
            '4' => '⁴',
            '5' => '⁵',
            '6' => '⁶',
            '7' => '⁷',
            '8' => '⁸',
            _ => '⁹',
        })
        .collect()
}

// ---------------------------------------------------------------------------
// Data and layout
// ---------------------------------------------------------------------------

/// A series reduced to drawable runs of points (plotted coordinates).
struct Curve {
    label: String,
    color: RGBColor,
    dash: &'static [f64],
    runs: Vec<Vec<(f64, f64)>>,
    /// Marker on every k-th drawn point (0: none).
    mark_every: usize,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Corner {
    UpperRight,
    UpperLeft,
    LowerRight,
    LowerLeft,
    /// Below the plot, left-aligned with it (the plot is shortened to make room).
    Outside,
}

/// Pixel geometry of the figure at one drawing scale (1 for the SVG, the
/// supersampling factor for the PNG).
#[derive(Debug, Clone)]
struct Layout {
    scale: f64,
    x: Axis,
    y: Axis,
    top: f64,
    right_margin: f64,
    /// Below the x axis' label: the margin, and the legend when it is
    /// outside the plot.
    bottom_margin: f64,
    x_area: f64,
    y_area: f64,
    /// Plot rectangle: left, top, right, bottom.
    plot: (f64, f64, f64, f64),
    /// Row (0 = nearest the plot) of each marker label.
    marker_rows: Vec<usize>,
}

/// Everything needed to draw, independent of the backend.
struct Figure {
    title: String,
    x_label: String,
    y_label: String,
    log_y: bool,
    curves: Vec<Curve>,
    markers: Vec<(f64, String)>,
    /// Plotted x and y ranges before ticks are chosen.
    x_range: (f64, f64),
    y_range: (f64, f64),
    legend: Option<Corner>,
    /// Legend columns (more than one only below the plot).
    legend_columns: usize,
}

impl Figure {
    fn prepare(chart: &LineChart, png: &Path) -> Result<Self, ChartError> {
        let path = || png.to_path_buf();
        if chart.series.is_empty() {
            return Err(ChartError::NoSeries { path: path() });
        }
        let mut curves = Vec::with_capacity(chart.series.len());
        for (i, s) in chart.series.iter().enumerate() {
            let label = || s.label.clone();
            if s.x.len() != s.y.len() {
                return Err(ChartError::LengthMismatch {
                    path: path(),
                    label: label(),
                    x_len: s.x.len(),
                    y_len: s.y.len(),
                });
            }
            if s.x.is_empty() {
                return Err(ChartError::EmptySeries {
                    path: path(),
                    label: label(),
                });
            }
            let finite = |x: f64, y: f64| x.is_finite() && y.is_finite();
            if !s.x.iter().zip(&s.y).any(|(&x, &y)| finite(x, y)) {
                return Err(ChartError::NoFinitePoints {
                    path: path(),
                    label: label(),
                });
            }
            let mut runs = Vec::new();
            let mut run = Vec::new();
            for (&x, &y) in s.x.iter().zip(&s.y) {
                if finite(x, y) && (!chart.log_y || y > 0.0) {
                    run.push((x, if chart.log_y { y.log10() } else { y }));
                } else if !run.is_empty() {
                    runs.push(std::mem::take(&mut run));
                }
            }
            if !run.is_empty() {
                runs.push(run);
            }
            if runs.is_empty() {
                return Err(ChartError::NoPositivePoints {
                    path: path(),
                    label: label(),
                });
            }
            let (color, dash) = series_style(i);
            let points: usize = runs.iter().map(Vec::len).sum();
            curves.push(Curve {
                label: s.label.clone(),
                color,
                dash,
                runs,
                mark_every: match s.mark_every {
                    0 if points <= AUTO_MARKERS => 1,
                    k => k,
                },
            });
        }
        for (x, label) in &chart.markers {
            if !x.is_finite() {
                return Err(ChartError::BadMarker {
                    path: path(),
                    label: label.clone(),
                    x: *x,
                });
            }
        }

        let points = || curves.iter().flat_map(|c| c.runs.iter().flatten());
        let (x_lo, x_hi) = min_max(points().map(|p| p.0));
        let (mut x_lo, mut x_hi) = widen_if_flat(x_lo, x_hi);
        // A marker at (or beyond) an end of the data: a little room so its
        // line is not hidden by the frame.
        let span = x_hi - x_lo;
        if chart.markers.iter().any(|m| m.0 <= x_lo) {
            x_lo = chart.markers.iter().fold(x_lo, |lo, m| lo.min(m.0)) - 0.02 * span;
        }
        if chart.markers.iter().any(|m| m.0 >= x_hi) {
            x_hi = chart.markers.iter().fold(x_hi, |hi, m| hi.max(m.0)) + 0.02 * span;
        }
        let (d_lo, d_hi) = min_max(points().map(|p| p.1));
        let y_range = if chart.log_y {
            (d_lo, d_hi)
        } else {
            let (lo, hi) = widen_if_flat(d_lo, d_hi);
            let pad = 0.05 * (hi - lo);
            (lo - pad, hi + pad)
        };

        let mut figure = Self {
            title: chart.title.clone(),
            x_label: chart.x_label.clone(),
            y_label: chart.y_label.clone(),
            log_y: chart.log_y,
            curves,
            markers: chart.markers.clone(),
            x_range: (x_lo, x_hi),
            y_range,
            legend: None,
            legend_columns: 1,
        };
        if figure.legend_lines() == 0 {
            return Ok(figure);
        }

        // The legend goes upper right unless it would hide data there and a
        // free corner exists. If no corner is free, the top of the y range
        // is raised so that the legend sits above every curve, or, for a
        // legend too tall for that, it goes beside the plot.
        let layout = figure.layout(1.0);
        let corners = [
            Corner::UpperRight,
            Corner::UpperLeft,
            Corner::LowerRight,
            Corner::LowerLeft,
        ];
        let hidden: Vec<usize> = corners
            .iter()
            .map(|&c| figure.hidden_by(&layout, c))
            .collect();
        if let Some(i) = hidden.iter().position(|&n| n == 0) {
            figure.legend = Some(corners[i]);
            return Ok(figure);
        }
        let (_, top, _, bottom) = layout.plot;
        let (_, legend_h) = figure.legend_size(1.0);
        let f = (legend_h + LEGEND_INSET + 12.0) / (bottom - top);
        if f < 0.3 {
            let lo = layout.y.lo;
            figure.y_range = (lo, d_hi + f / (1.0 - f) * (d_hi - lo));
            figure.legend = Some(Corner::UpperRight);
        } else {
            // Below the plot: as many columns (up to three) as its width holds.
            figure.legend = Some(Corner::Outside);
            let (l, _, r, _) = layout.plot;
            let entry = figure.legend_entry_width(1.0) + LEGEND_COLUMN_GAP;
            let fit = ((r - l - 2.0 * LEGEND_PAD + LEGEND_COLUMN_GAP) / entry).floor() as usize;
            figure.legend_columns = fit.clamp(1, 3).min(figure.legend_lines());
        }
        Ok(figure)
    }

    fn layout(&self, scale: f64) -> Layout {
        Layout::compute(self, scale)
    }

    fn legend_lines(&self) -> usize {
        self.curves.iter().filter(|c| !c.label.is_empty()).count()
    }

    /// Width of one legend entry (sample, gap, longest label).
    fn legend_entry_width(&self, scale: f64) -> f64 {
        let text = self
            .curves
            .iter()
            .filter(|c| !c.label.is_empty())
            .map(|c| text_width(&c.label, LEGEND_FONT * scale))
            .fold(0.0, f64::max);
        (LEGEND_SAMPLE + LEGEND_GAP) * scale + text
    }

    fn legend_size(&self, scale: f64) -> (f64, f64) {
        let cols = self.legend_columns.max(1);
        let rows = self.legend_lines().div_ceil(cols) as f64;
        let entry = self.legend_entry_width(scale);
        (
            2.0 * LEGEND_PAD * scale
                + cols as f64 * entry
                + (cols - 1) as f64 * LEGEND_COLUMN_GAP * scale,
            (2.0 * LEGEND_PAD + rows * LEGEND_ROW) * scale,
        )
    }

    /// Legend box (left, top, right, bottom) in a corner of the plot.
    fn legend_box(&self, layout: &Layout, corner: Corner) -> (f64, f64, f64, f64) {
        let s = layout.scale;
        let (l, t, r, b) = layout.plot;
        let (w, h) = self.legend_size(s);
        let left = match corner {
            Corner::UpperLeft | Corner::LowerLeft => l + LEGEND_INSET * s,
            Corner::UpperRight | Corner::LowerRight => r - LEGEND_INSET * s - w,
            Corner::Outside => l,
        };
        let top = match corner {
            Corner::UpperLeft | Corner::UpperRight => t + LEGEND_INSET * s,
            Corner::Outside => f64::from(HEIGHT) * s - MARGIN * s - h,
            Corner::LowerLeft | Corner::LowerRight => b - LEGEND_INSET * s - h,
        };
        (left, top, left + w, top + h)
    }

    /// How many sampled points of the curves and marker lines (every ~6 px
    /// along each line) the legend would hide in `corner`.
    fn hidden_by(&self, layout: &Layout, corner: Corner) -> usize {
        let (l, t, r, b) = self.legend_box(layout, corner);
        let (l, t, r, b) = (l - 6.0, t - 6.0, r + 6.0, b + 6.0);
        let inside = |(x, y): (f64, f64)| x >= l && x <= r && y >= t && y <= b;
        let mut count = 0;
        // Marker lines count as data too.
        let (_, top, _, bottom) = layout.plot;
        for (x, _) in &self.markers {
            let (mx, _) = layout.to_px((*x, layout.y.lo));
            let n = ((bottom - top) / 6.0).ceil() as usize;
            count += (0..=n)
                .filter(|k| inside((mx, top + (bottom - top) * *k as f64 / n as f64)))
                .count();
        }
        for run in self.curves.iter().flat_map(|c| &c.runs) {
            let pts: Vec<(f64, f64)> = run.iter().map(|&p| layout.to_px(p)).collect();
            count += usize::from(inside(pts[0]));
            for w in pts.windows(2) {
                let n = ((w[1].0 - w[0].0).hypot(w[1].1 - w[0].1) / 6.0)
                    .ceil()
                    .max(1.0);
                for k in 1..=n as usize {
                    let f = k as f64 / n;
                    let p = (
                        w[0].0 + f * (w[1].0 - w[0].0),
                        w[0].1 + f * (w[1].1 - w[0].1),
                    );
                    count += usize::from(inside(p));
                }
            }
        }
        count
    }

    /// Draws the figure on a canvas `scale` times the output size.
    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        scale: f64,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        let lay = self.layout(scale);
        let s = scale;
        root.fill(&WHITE)?;
        let mut chart = ChartBuilder::on(root)
            .margin_top(px(lay.top))
            .margin_bottom(px(lay.bottom_margin))
            .margin_left(px(MARGIN * s))
            .margin_right(px(lay.right_margin))
            .x_label_area_size(px(lay.x_area))
            .y_label_area_size(px(lay.y_area))
            .build_cartesian_2d(TickRange::new(&lay.x), TickRange::new(&lay.y))?;
        let x_fmt = |v: &f64| lay.x.label_of(*v);
        let y_fmt = |v: &f64| lay.y.label_of(*v);
        chart
            .configure_mesh()
            .x_desc(self.x_label.as_str())
            .y_desc(self.y_label.as_str())
            .axis_desc_style(font::text(DESC_FONT * s))
            .label_style(font::text(TICK_FONT * s))
            .x_label_formatter(&x_fmt)
            .y_label_formatter(&y_fmt)
            .bold_line_style(BLACK.mix(0.14).stroke_width(px(s) as u32))
            .light_line_style(BLACK.mix(0.06).stroke_width(px(s) as u32))
            .axis_style(BLACK.stroke_width(px(AXIS_WIDTH * s) as u32))
            .set_all_tick_mark_size(px(TICK_LEN * s))
            .x_labels(lay.x.ticks.len().max(1))
            .y_labels(lay.y.ticks.len().max(1))
            .max_light_lines(10)
            .draw()?;

        // Exact pixel mapping of the plot, taken from plotters' own.
        let (px0, py0) = chart.backend_coord(&(lay.x.lo, lay.y.lo));
        let (px1, py1) = chart.backend_coord(&(lay.x.hi, lay.y.hi));
        let to_px = |(x, y): (f64, f64)| {
            (
                f64::from(px0) + (x - lay.x.lo) / (lay.x.hi - lay.x.lo) * f64::from(px1 - px0),
                f64::from(py0) + (y - lay.y.lo) / (lay.y.hi - lay.y.lo) * f64::from(py1 - py0),
            )
        };
        let scaled = |pattern: &[f64]| -> Vec<f64> { pattern.iter().map(|d| d * s).collect() };

        // Markers under the curves.
        let marker_style = MARKER_COLOR.stroke_width(px(1.5 * AXIS_WIDTH * s) as u32);
        for (x, _) in &self.markers {
            let line = [to_px((*x, lay.y.lo)), to_px((*x, lay.y.hi))];
            for piece in dashed(&line, &scaled(MARKER_DASH)) {
                root.draw(&PathElement::new(pixels(&piece), marker_style))?;
            }
        }

        // Curves clipped to the plot frame.
        let frame = (
            f64::from(px0),
            f64::from(py1),
            f64::from(px1),
            f64::from(py0),
        );
        let line_width = px(LINE_WIDTH * s);
        let mark =
            |c: (f64, f64)| c.0 >= frame.0 && c.0 <= frame.2 && c.1 >= frame.1 && c.1 <= frame.3;
        for curve in &self.curves {
            let style = curve.color.stroke_width(line_width as u32);
            let dash = scaled(curve.dash);
            let mut index = 0usize;
            for run in &curve.runs {
                let pts: Vec<(f64, f64)> = run.iter().map(|&p| to_px(p)).collect();
                for inside in clip_polyline(&pts, frame) {
                    if inside.len() == 1 {
                        let c = pixels(&inside)[0];
                        root.draw(&Circle::new(c, line_width, curve.color.filled()))?;
                        continue;
                    }
                    for piece in dashed(&inside, &dash) {
                        root.draw(&PathElement::new(pixels(&piece), style))?;
                    }
                }
                if curve.mark_every > 0 {
                    for &p in &pts {
                        if index.is_multiple_of(curve.mark_every) && mark(p) {
                            let c = (px(p.0), px(p.1));
                            root.draw(&Circle::new(
                                c,
                                px(MARKER_RADIUS * s),
                                curve.color.filled(),
                            ))?;
                        }
                        index += 1;
                    }
                }
            }
        }

        // Frame around the plot.
        let (xr, yr) = chart.plotting_area().get_pixel_range();
        root.draw(&Rectangle::new(
            [(xr.start, yr.start), (xr.end - 1, yr.end - 1)],
            BLACK.stroke_width(px(AXIS_WIDTH * s) as u32),
        ))?;

        self.draw_notes(root, &lay, (px0, py1, px1))?;
        if !self.title.is_empty() {
            root.draw(&Text::new(
                self.title.clone(),
                (px(f64::from(WIDTH) * s / 2.0), px(MARGIN * s)),
                font::text(TITLE_FONT * s).pos(Pos::new(HPos::Center, VPos::Top)),
            ))?;
        }
        if let Some(corner) = self.legend {
            self.draw_legend(root, &lay, corner)?;
        }
        Ok(())
    }

    /// Marker labels and the axes' common factors, outside the plot.
    fn draw_notes<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        lay: &Layout,
        (left, top, right): (i32, i32, i32),
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        let s = lay.scale;
        let row_y = |row: usize| top - px((10.0 + row as f64 * NOTE_ROW) * s);
        let tick_font = font::text(TICK_FONT * s);
        if let Some(factor) = &lay.y.factor {
            root.draw(&Text::new(
                factor.clone(),
                (left, row_y(0)),
                tick_font.pos(Pos::new(HPos::Left, VPos::Bottom)),
            ))?;
        }
        if let Some(factor) = &lay.x.factor {
            root.draw(&Text::new(
                factor.clone(),
                (right, px((f64::from(HEIGHT) - MARGIN) * s)),
                tick_font.pos(Pos::new(HPos::Right, VPos::Bottom)),
            ))?;
        }
        let note = font::text(NOTE_FONT * s).color(&MARKER_COLOR);
        for ((x, label), &row) in self.markers.iter().zip(&lay.marker_rows) {
            if label.is_empty() {
                continue;
            }
            let (cx, _) = lay.to_px((*x, lay.y.lo));
            let w = text_width(label, NOTE_FONT * s);
            let start =
                (cx - w / 2.0).clamp(f64::from(left), (f64::from(right) - w).max(f64::from(left)));
            root.draw(&Text::new(
                label.clone(),
                (px(start), row_y(row)),
                note.pos(Pos::new(HPos::Left, VPos::Bottom)),
            ))?;
        }
        Ok(())
    }

    fn draw_legend<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        lay: &Layout,
        corner: Corner,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        let s = lay.scale;
        let (l, t, r, b) = self.legend_box(lay, corner);
        let corners = [(px(l), px(t)), (px(r), px(b))];
        root.draw(&Rectangle::new(corners, WHITE.filled()))?;
        root.draw(&Rectangle::new(
            corners,
            BLACK.mix(0.6).stroke_width(px(AXIS_WIDTH * s) as u32),
        ))?;
        let labelled = self.curves.iter().filter(|c| !c.label.is_empty());
        let cols = self.legend_columns.max(1);
        let column_step = self.legend_entry_width(s) + LEGEND_COLUMN_GAP * s;
        for (i, curve) in labelled.enumerate() {
            let (row, col) = (i / cols, i % cols);
            let y = t + (LEGEND_PAD + (row as f64 + 0.5) * LEGEND_ROW) * s;
            let x0 = l + LEGEND_PAD * s + col as f64 * column_step;
            let sample = [(x0, y), (x0 + LEGEND_SAMPLE * s, y)];
            let dash: Vec<f64> = curve.dash.iter().map(|d| d * s).collect();
            for piece in dashed(&sample, &dash) {
                root.draw(&PathElement::new(
                    pixels(&piece),
                    curve.color.stroke_width(px(LINE_WIDTH * s) as u32),
                ))?;
            }
            if curve.mark_every > 0 {
                let c = (px(x0 + 0.5 * LEGEND_SAMPLE * s), px(y));
                root.draw(&Circle::new(c, px(MARKER_RADIUS * s), curve.color.filled()))?;
            }
            root.draw(&Text::new(
                curve.label.clone(),
                (px(x0 + (LEGEND_SAMPLE + LEGEND_GAP) * s), px(y)),
                font::text(LEGEND_FONT * s).pos(Pos::new(HPos::Left, VPos::Center)),
            ))?;
        }
        Ok(())
    }
}

impl Layout {
    fn compute(figure: &Figure, scale: f64) -> Self {
        let s = scale;
        let x = Axis::linear(figure.x_range.0, figure.x_range.1, 7);
        let y = if figure.log_y {
            Axis::logarithmic(figure.y_range.0, figure.y_range.1)
        } else {
            Axis::linear(figure.y_range.0, figure.y_range.1, 6)
        };
        let label_dist = 2.0 * TICK_LEN;
        let y_area = y.widest_label(TICK_FONT * s) + (label_dist + 18.0 + DESC_FONT) * s;
        let x_area = (TICK_FONT + label_dist + 18.0 + DESC_FONT) * s;
        let last_x_label = x
            .labels
            .last()
            .map(|l| text_width(l, TICK_FONT * s))
            .unwrap_or(0.0);
        let right_margin = (MARGIN * s).max(last_x_label / 2.0 + 8.0 * s);
        // A legend that fits no corner goes below the plot, across its width
        // (beside it, it would take half the figure's width).
        let mut bottom_margin = MARGIN * s;
        if figure.legend == Some(Corner::Outside) {
            let (_, legend_h) = figure.legend_size(s);
            bottom_margin += legend_h + LEGEND_INSET * s;
        }
        let left = MARGIN * s + y_area;
        let right = f64::from(WIDTH) * s - right_margin;

        // Marker labels: greedy rows so that no two overlap; the y factor
        // (if any) occupies the left end of row 0.
        let mut rows: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
        if let Some(f) = &y.factor {
            rows[0].push((left, left + text_width(f, TICK_FONT * s)));
        }
        let markers = &figure.markers;
        let mut order: Vec<usize> = (0..markers.len()).collect();
        order.sort_by(|&a, &b| markers[a].0.total_cmp(&markers[b].0));
        let mut marker_rows = vec![0; markers.len()];
        for i in order {
            let (mx, label) = &markers[i];
            if label.is_empty() {
                continue;
            }
            let cx = left + (mx - x.lo) / (x.hi - x.lo) * (right - left);
            let w = text_width(label, NOTE_FONT * s);
            let start = (cx - w / 2.0).clamp(left, (right - w).max(left));
            let span = (start - 12.0 * s, start + w + 12.0 * s);
            let free = |row: &Vec<(f64, f64)>| row.iter().all(|&(a, b)| span.1 <= a || b <= span.0);
            let row = match rows.iter().position(free) {
                Some(r) => r,
                None => {
                    rows.push(Vec::new());
                    rows.len() - 1
                }
            };
            rows[row].push(span);
            marker_rows[i] = row;
        }
        let used_rows = if y.factor.is_some() || markers.iter().any(|m| !m.1.is_empty()) {
            rows.len() as f64
        } else {
            0.0
        };
        let title_h = if figure.title.is_empty() {
            0.0
        } else {
            TITLE_FONT + 18.0
        };
        let top = (MARGIN + title_h + used_rows * NOTE_ROW + TICK_FONT / 2.0 + 6.0) * s;
        let bottom = f64::from(HEIGHT) * s - bottom_margin - x_area;
        Self {
            scale,
            x,
            y,
            top,
            right_margin,
            bottom_margin,
            x_area,
            y_area,
            plot: (left, top, right, bottom),
            marker_rows,
        }
    }

    /// Predicted pixel position of a plotted point.
    fn to_px(&self, (x, y): (f64, f64)) -> (f64, f64) {
        let (l, t, r, b) = self.plot;
        (
            l + (x - self.x.lo) / (self.x.hi - self.x.lo) * (r - l),
            b - (y - self.y.lo) / (self.y.hi - self.y.lo) * (b - t),
        )
    }
}

fn min_max(values: impl Iterator<Item = f64>) -> (f64, f64) {
    values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
        (lo.min(v), hi.max(v))
    })
}

/// A range of zero width becomes one around the value.
fn widen_if_flat(lo: f64, hi: f64) -> (f64, f64) {
    if hi > lo {
        return (lo, hi);
    }
    let pad = if lo == 0.0 { 1.0 } else { 0.1 * lo.abs() };
    (lo - pad, hi + pad)
}

fn pixels(points: &[(f64, f64)]) -> Vec<(i32, i32)> {
    let mut out: Vec<(i32, i32)> = Vec::with_capacity(points.len());
    for &(x, y) in points {
        let p = (px(x), px(y));
        if out.last() != Some(&p) {
            out.push(p);
        }
    }
    if out.len() == 1 {
        out.push(out[0]);
    }
    out
}

/// Cuts a polyline into the "on" pieces of a dash pattern (pixel lengths,
/// alternating on and off), keeping the pattern's phase across vertices.
fn dashed(points: &[(f64, f64)], pattern: &[f64]) -> Vec<Vec<(f64, f64)>> {
    if pattern.is_empty() || points.len() < 2 {
        return vec![points.to_vec()];
    }
    let mut pieces = Vec::new();
    let mut current = vec![points[0]];
    let mut index = 0;
    let mut left = pattern[0];
    for w in points.windows(2) {
        let (mut a, b) = (w[0], w[1]);
        let mut d = (b.0 - a.0).hypot(b.1 - a.1);
        while d > left {
            let f = left / d;
            let p = (a.0 + f * (b.0 - a.0), a.1 + f * (b.1 - a.1));
            if index % 2 == 0 {
                current.push(p);
                pieces.push(std::mem::take(&mut current));
            } else {
                current = vec![p];
            }
            a = p;
            d -= left;
            index = (index + 1) % pattern.len();
            left = pattern[index];
        }
        left -= d;
        if index % 2 == 0 {
            current.push(b);
        }
    }
    if index % 2 == 0 && current.len() > 1 {
        pieces.push(current);
    }
    pieces
}

#[cfg(test)]
mod tests {

    #[test]
    fn nearly_constant_values_get_offset_labels() {
        // Ticks 1e-12 apart on a value of 163: every label must differ, and
        // the note beside the axis carries the factor and the offset.
        let (step, ticks) = nice_ticks(163.0 - 2.5e-12, 163.0 + 2.5e-12, 6);
        let (labels, note) = linear_labels(&ticks, step);
        let mut unique = labels.clone();
        unique.dedup();
        assert_eq!(unique.len(), labels.len(), "{labels:?}");
        let note = note.expect("offset note");
        assert!(note.contains("×10") && note.contains("e2"), "{note}");
        // Ordinary ranges keep plain labels.
        let (step, ticks) = nice_ticks(0.0, 10.0, 6);
        assert_eq!(linear_labels(&ticks, step).1, None);
    }

    use super::*;

    #[test]
    fn ticks_come_close_to_the_target_count() {
        assert_eq!(nice_ticks(0.0, 2.0, 7).0, 0.5);
        assert_eq!(nice_ticks(0.1, 1.2, 7).0, 0.2);
        assert_eq!(nice_ticks(-0.17, 0.5, 6).0, 0.1);
        assert_eq!(nice_ticks(0.0, 11.0, 7).0, 2.0);
    }

    #[test]
    fn linear_labels_use_the_steps_decimals_and_a_common_factor() {
        let a = Axis::linear(-0.05, 1.05, 6);
        assert_eq!(a.labels, ["0.0", "0.2", "0.4", "0.6", "0.8", "1.0"]);
        let b = Axis::linear(-1.0e-4, 3.0e-4, 5);
        assert_eq!(b.factor.as_deref(), Some("×10⁻⁴"));
        assert_eq!(b.labels, ["\u{2212}1", "0", "1", "2", "3"]);
        let c = Axis::linear(0.0, 2.5e5, 6);
        assert_eq!(c.factor.as_deref(), Some("×10⁵"));
        assert_eq!(c.labels[1], "0.5");
    }

    #[test]
    fn log_axis_labels_decades() {
        let a = Axis::logarithmic(-3.2, 0.4);
        assert_eq!(a.labels, ["10⁻³", "10⁻²", "10⁻¹", "10⁰"]);
        assert!(a.lo < -3.2 && a.hi > 0.4);
        // Less than a decade of data: widened to whole decades, with 2× and
        // 5× labelled too.
        let b = Axis::logarithmic(-2.9, -2.6);
        assert_eq!((b.lo, b.hi), (-3.0, -2.0));
        assert_eq!(b.labels, ["10⁻³", "10⁻²", "2×10⁻³", "5×10⁻³"]);
        let c = Axis::logarithmic(-16.0, 4.0);
        assert!(c.ticks.len() <= 10, "{:?}", c.ticks);
        assert!(c.ticks.contains(&0.0));
    }

    #[test]
    fn dashes_keep_their_phase() {
        let line = [(0.0, 0.0), (5.0, 0.0), (30.0, 0.0)];
        let pieces = dashed(&line, &[10.0, 5.0]);
        let spans: Vec<(f64, f64)> = pieces
            .iter()
            .map(|p| (p[0].0, p.last().unwrap().0))
            .collect();
        assert_eq!(spans, [(0.0, 10.0), (15.0, 25.0)]);
    }

    #[test]
    fn downsampling_averages_blocks() {
        let rgb = [0, 0, 0, 255, 255, 255, 255, 255, 255, 255, 255, 255];
        assert_eq!(downsample(&rgb, 2, 2), [191, 191, 191]);
    }
}
