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
use flexmech_plot::charts::{ChartError, LineChart, Series};

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

/// Draws `<dir>/<figure>.png` and `.svg` for each figure of `spec` from
/// `summary` (whose columns are those of [`super::summary::columns`]) and
/// returns the files written.
pub fn summary_charts(
    spec: &StudySpec,
    summary: &Summary,
    dir: &Path,
) -> Result<Vec<PathBuf>, ChartError> {
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

    // Legend labels name a key by its last segment (`pitch`) unless two of
    // the keys share it.
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

    // Group the rows by the values of the other varying keys, in order of
    // first appearance.
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
    let x_of = |r: usize| match x_key {
        Some(i) => summary.rows[r][key_col(i)].number(),
        None => r as f64,
    };

    let mut written = Vec::new();
    let first_figure = 2 + spec.grid.len();
    for (f, figure) in spec.figures.iter().enumerate() {
        let col = first_figure + f;
        let title = if spec.titles {
            format!("{}: {}", spec.name, figure.name())
        } else {
            String::new()
        };
        let mut chart = LineChart::new(title, x_label.clone(), figure.axis_label());
        for (label, rows) in &groups {
            let mut points: Vec<(f64, f64)> = rows
                .iter()
                .map(|&r| (x_of(r), summary.rows[r][col].number()))
                .filter(|(x, y)| x.is_finite() && y.is_finite())
                .collect();
            if points.is_empty() {
                continue;
            }
            points.sort_by(|a, b| a.0.total_cmp(&b.0));
            let (x, y) = points.into_iter().unzip();
            chart.series.push(Series::new(label.clone(), x, y));
        }
        let stem = dir.join(figure.name());
        if chart.series.is_empty() {
            // Leave no chart of an earlier run of the study behind.
            for ext in ["png", "svg"] {
                let _ = std::fs::remove_file(stem.with_extension(ext));
            }
            continue;
        }
        // Drifts span decades: a logarithmic axis when every value allows it.
        chart.log_y = *figure == Figure::EnergyDrift
            && chart.series.iter().flat_map(|s| &s.y).all(|&y| y > 0.0);
        let (png, svg) = chart.render(&stem)?;
        written.push(png);
        written.push(svg);
    }
    Ok(written)
}
