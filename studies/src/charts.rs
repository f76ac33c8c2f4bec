//! One summary chart per figure: the figure over a swept numeric key, one
//! series per combination of the other swept keys.
//!
//! The x axis is the first numeric grid key with at least two distinct
//! values; failing that the first numeric grid key; failing that the run
//! index. Keys with a single value split nothing and are left out of the
//! series labels, which name a key by its last segment (`pitch = 0.05`)
//! unless two keys share it. Points where a figure is NaN are left out; a series with
//! no finite point is dropped, and a figure with no series left (e.g.
//! `failure_time` when nothing failed) gets no chart. `energy_drift` is drawn
//! on a logarithmic axis when all its values are positive.

use std::path::{Path, PathBuf};

use super::spec::{Figure, StudySpec};
use super::summary::Summary;
use flexmech_plot::charts::{auto_style, ChartError, Color, Dash, LineChart, Marker, Series};

/// The model tables whose name a key's words leave out (`joint.cam.b` reads
/// `cam b`: the entry's name says what it is).
const TABLE_NAMES: [&str; 11] = [
    "joint",
    "section",
    "beam",
    "solver",
    "output",
    "load",
    "distributed_load",
    "support",
    "prescribed",
    "rigid_body",
    "initial_velocity",
];

/// A grid key as words for an axis label or a legend: dots become spaces
/// and a leading table name is left out (`joint.cam.b` → `cam b`,
/// `solver.dt` → `dt`, `section.rod.EI[0]` → `rod EI[0]`); quotes around a
/// segment are dropped.
pub fn key_words(key: &str) -> String {
    let segments: Vec<String> = super::key_path::KeyPath::parse(key)
        .map(|p| p.words())
        .unwrap_or_else(|_| key.split('.').map(str::to_owned).collect());
    let skip = usize::from(segments.len() > 1 && TABLE_NAMES.contains(&segments[0].as_str()));
    segments[skip..].join(" ")
}

fn distinct(cells: impl Iterator<Item = String>) -> usize {
    let mut seen: Vec<String> = Vec::new();
    for c in cells {
        if !seen.contains(&c) {
            seen.push(c);
        }
    }
    seen.len()
}

/// How the summary's rows are drawn: the x axis and the series.
struct Layout {
    /// The swept key on the x axis (`None`: the run index).
    x_key: Option<usize>,
    x_label: String,
    /// Each row's abscissa.
    x: Vec<f64>,
    /// The series: a label and its rows.
    groups: Vec<(String, Vec<usize>)>,
}

impl Layout {
    fn of(spec: &StudySpec, summary: &Summary) -> Self {
        let key_col = |i: usize| 1 + i;
        let varying: Vec<usize> = (0..spec.grid.len())
            .filter(|&i| distinct(summary.rows.iter().map(|r| r[key_col(i)].csv_text())) > 1)
            .collect();
        let x_key = varying
            .iter()
            .copied()
            .find(|&i| spec.grid[i].is_numeric())
            .or_else(|| (0..spec.grid.len()).find(|&i| spec.grid[i].is_numeric()));
        let x_label = match x_key {
            Some(i) => key_words(&spec.grid[i].key),
            None => "run index".into(),
        };
        let others: Vec<usize> = varying
            .iter()
            .copied()
            .filter(|&i| Some(i) != x_key)
            .collect();
        // Legend labels name a key by its last segment (`pitch`) unless two
        // of the keys share it.
        let short = |i: usize| -> String {
            let last = |k: &str| k.rsplit('.').next().unwrap_or(k).to_owned();
            let mine = last(&spec.grid[i].key);
            let clash = others
                .iter()
                .any(|&j| j != i && last(&spec.grid[j].key) == mine);
            if clash {
                key_words(&spec.grid[i].key)
            } else {
                mine
            }
        };
        // Group the rows by the values of the other varying keys, in order
        // of first appearance.
        let mut groups: Vec<(String, Vec<usize>)> = Vec::new();
        for (r, cells) in summary.rows.iter().enumerate() {
            let label = others
                .iter()
                .map(|&i| format!("{} = {}", short(i), cells[key_col(i)].csv_text()))
                .collect::<Vec<_>>()
                .join(", ");
            match groups.iter_mut().find(|(l, _)| *l == label) {
                Some((_, rows)) => rows.push(r),
                None => groups.push((label, vec![r])),
            }
        }
        let x = (0..summary.rows.len())
            .map(|r| match x_key {
                Some(i) => summary.rows[r][key_col(i)].number(),
                None => r as f64,
            })
            .collect();
        Self {
            x_key,
            x_label,
            x,
            groups,
        }
    }
}

/// Draws `<dir>/<figure>.png` and `.svg` for each figure of `spec` from
/// `summary` (whose columns are those of [`super::summary::columns`]) and
/// returns the files written.
pub fn summary_charts(
    spec: &StudySpec,
    summary: &Summary,
    dir: &Path,
) -> Result<Vec<PathBuf>, ChartError> {
    let layout = Layout::of(spec, summary);
    let mut written = Vec::new();
    let mut col = 2 + spec.grid.len();
    for figure in &spec.figures {
        let columns = Columns {
            value: col,
            derivatives: figure.derivative_columns(),
        };
        col += 1 + columns.derivatives.len();
        let chart = figure_chart(spec, summary, &layout, figure, &columns);
        let stem = dir.join(figure.name());
        if chart.series.is_empty() {
            // Leave no chart of an earlier run of the study behind.
            for ext in ["png", "svg"] {
                let _ = std::fs::remove_file(stem.with_extension(ext));
            }
            continue;
        }
        let (png, svg) = chart.render(&stem)?;
        written.push(png);
        written.push(svg);
    }
    Ok(written)
}

/// The chart of `figure` (summary columns `columns`): one series per group,
/// the tangents from its derivative by the swept key when it has one.
fn figure_chart(
    spec: &StudySpec,
    summary: &Summary,
    layout: &Layout,
    figure: &Figure,
    columns: &Columns<'_>,
) -> LineChart {
    let title = if spec.titles {
        format!("{}: {}", spec.name, figure.name())
    } else {
        String::new()
    };
    let mut chart = LineChart::new(title, layout.x_label.clone(), figure.axis_label());
    // The derivative by the swept key gives each point's tangent.
    let slope = (layout.x_key.map(|i| spec.grid[i].key.as_str()))
        .and_then(|key| columns.derivatives.iter().position(|(_, k)| *k == key))
        .map(|d| columns.value + 1 + d);
    for (group, (label, rows)) in layout.groups.iter().enumerate() {
        let cell = |r: usize, c: Option<usize>| c.map_or(f64::NAN, |c| summary.rows[r][c].number());
        let mut points: Vec<(f64, f64, f64)> = rows
            .iter()
            .map(|&r| (layout.x[r], cell(r, Some(columns.value)), cell(r, slope)))
            .filter(|(x, y, _)| x.is_finite() && y.is_finite())
            .collect();
        if points.is_empty() {
            continue;
        }
        points.sort_by(|a, b| a.0.total_cmp(&b.0));
        let (x, y) = points.iter().map(|p| (p.0, p.1)).unzip();
        let mut series = Series::new(label.clone(), x, y);
        // The groups' styles, whatever tangent lines come between them.
        let (color, dash) = auto_style(group);
        (series.color, series.dash) = (Some(color), Some(dash));
        chart.series.push(series);
        if slope.is_some() {
            let first = !chart.series.iter().any(|s| s.label == TANGENT_LABEL);
            chart.series.extend(tangents(&points, first));
        }
    }
    let swept = layout.x_key.map(|i| spec.grid[i].key.as_str());
    chart
        .series
        .extend(speed_lines(figure, swept, &chart.series));
    // Drifts span decades: a logarithmic axis when every value allows it.
    chart.log_y =
        *figure == Figure::EnergyDrift && chart.series.iter().flat_map(|s| &s.y).all(|&y| y > 0.0);
    chart
}

/// A figure's summary columns: its value and its derivatives (column name
/// and key).
struct Columns<'a> {
    value: usize,
    derivatives: Vec<(String, &'a str)>,
}

/// The legend entry of the tangent lines.
const TANGENT_LABEL: &str = "tangents (exact derivatives)";
/// A tangent line reaches this fraction of the spacing of the swept values
/// on either side of its point.
const TANGENT_REACH: f64 = 0.3;

/// Short tangent lines through `points` (`x`, `y`, `dy/dx`; sorted by x),
/// grey, the first labelled when `labelled`.
fn tangents(points: &[(f64, f64, f64)], labelled: bool) -> Vec<Series> {
    let spacing = (points.windows(2))
        .map(|w| w[1].0 - w[0].0)
        .filter(|d| *d > 0.0)
        .fold(f64::INFINITY, f64::min);
    let reach = if spacing.is_finite() {
        TANGENT_REACH * spacing
    } else {
        TANGENT_REACH * points[0].0.abs().max(1.0) * 0.1
    };
    let mut out = Vec::new();
    for &(x, y, slope) in points.iter().filter(|p| p.2.is_finite()) {
        let label = if labelled && out.is_empty() {
            TANGENT_LABEL.to_string()
        } else {
            String::new()
        };
        let mut s = Series::new(
            label,
            vec![x - reach, x + reach],
            vec![y - reach * slope, y + reach * slope],
        );
        s.color = Some(Color {
            r: 110,
            g: 110,
            b: 110,
        });
        s.marker = Some(Marker::None);
        s.dash = Some(Dash::Solid);
        out.push(s);
    }
    out
}

/// The swept key of a Campbell diagram: the spin rate of the frame.
const SPIN_RATE_KEY: &str = "solver.rotation.rate";
/// Multiples of the spin rate drawn on a Campbell diagram.
const SPEED_MULTIPLES: [f64; 3] = [1.0, 2.0, 3.0];

/// A Campbell diagram's speed lines `f = nΩ/2π` (n = 1, 2, 3) over the swept
/// rates of `series`, grey and dashed: when `figure` is a mode of
/// `/modes/frequency` swept over `solver.rotation.rate` (their crossings
/// with the frequencies are the critical speeds).
fn speed_lines(figure: &Figure, swept: Option<&str>, series: &[Series]) -> Vec<Series> {
    let Figure::Dataset(d) = figure else {
        return Vec::new();
    };
    if d.mode.is_none() || d.dataset != "/modes/frequency" || swept != Some(SPIN_RATE_KEY) {
        return Vec::new();
    }
    let xs = series.iter().flat_map(|s| s.x.iter().copied());
    let (lo, hi) = xs.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
        (a.min(x), b.max(x))
    });
    if !(lo.is_finite() && hi.is_finite()) {
        return Vec::new();
    }
    SPEED_MULTIPLES
        .iter()
        .map(|n| {
            let f = |omega: f64| n * omega / std::f64::consts::TAU;
            let mut s = Series::new(format!("{n}× speed"), vec![lo, hi], vec![f(lo), f(hi)]);
            s.color = Some(Color {
                r: 150,
                g: 150,
                b: 150,
            });
            s.marker = Some(Marker::None);
            s.dash = Some(Dash::Dashed);
            s
        })
        .collect()
}
