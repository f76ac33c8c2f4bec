//! `flexmech plot`: one line chart per result-file dataset, over `/time`.
//! `/resultants/force` and `/resultants/moment` are drawn instead over the
//! Gauss points' arc length at the last stored step (three curves per beam).
//!
//! A dataset of shape T (one value per stored step) gives one curve, a T×3
//! dataset three (its x, y and z components). The y axis is labelled with the
//! dataset's path, the x axis "time", or "time (load factor in statics)" when
//! the root attribute `integrator` is `"static"`. A run that stopped early
//! (`status` `"failed: …"` or still `"running"`) gets a marker line at its
//! last stored time.

use std::path::{Path, PathBuf};

use super::line::{ChartError, LineChart, Series};
use crate::results::{layout, ReadError, ResultReader};

/// Why `plot_datasets` could not draw the charts; every variant names the
/// result file (and the dataset where one is involved).
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// The result file could not be read (an HDF5 error, or no such dataset:
    /// the message lists the datasets under the nearest existing group).
    #[error(transparent)]
    Read(#[from] ReadError),
    /// The dataset is neither T nor T×3 (T = length of `/time`).
    #[error(
        "{}: dataset {dataset} has shape {}, but a chart needs {steps} (one value per step) \
         or {steps}×3 (T = {steps} steps in /time)",
        .path.display(),
        shape_text(.shape)
    )]
    BadShape {
        /// The result file.
        path: PathBuf,
        /// The dataset.
        dataset: String,
        /// Its shape.
        shape: Vec<usize>,
        /// Length of `/time`.
        steps: usize,
    },
    /// The output directory could not be created.
    #[error("{}: {source}", .path.display())]
    Io {
        /// The directory.
        path: PathBuf,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// The chart could not be drawn or written (e.g. every value is NaN).
    #[error("{}: dataset {dataset}: {source}", .path.display())]
    Chart {
        /// The result file.
        path: PathBuf,
        /// The dataset.
        dataset: String,
        /// The chart's error, naming the output file.
        #[source]
        source: ChartError,
    },
}

fn shape_text(shape: &[usize]) -> String {
    if shape.is_empty() {
        return "scalar".to_owned();
    }
    let dims: Vec<String> = shape.iter().map(ToString::to_string).collect();
    dims.join("×")
}

/// Draws `<out_dir>/<stem>.png` and `.svg` for each dataset path in
/// `datasets` (leading `/` optional), where the stem is the path with `/`
/// replaced by `_` (`/nodes/arm.end/displacement` →
/// `nodes_arm.end_displacement`). Returns the written files, PNG then SVG
/// for each dataset, in argument order. Every dataset is read and checked
/// before the first chart is written.
pub fn plot_datasets(
    file: &Path,
    datasets: &[String],
    out_dir: &Path,
    log_y: bool,
) -> Result<Vec<PathBuf>, PlotError> {
    let r = ResultReader::open(file)?;
    let time = r.time()?;
    let steps = time.len();

    let x_label = if r.integrator().as_deref() == Some("static") {
        "time (load factor in statics)"
    } else {
        "time"
    };
    let markers = stop_marker(r.string_attr(layout::ATTR_STATUS), &time);
    let file_name = file
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| file.display().to_string());

    let mut charts = Vec::with_capacity(datasets.len());
    for requested in datasets {
        let name = format!("/{}", requested.trim_start_matches('/'));
        let shape = r.shape(&name)?;
        let bad_shape = || PlotError::BadShape {
            path: file.to_path_buf(),
            dataset: name.clone(),
            shape: shape.clone(),
            steps,
        };
        if let [n, _, 3] = shape.as_slice() {
            if *n == steps && name.starts_with(layout::RESULTANTS) {
                let chart = resultants_chart(&r, &name, &file_name, &time)?;
                let stem = out_dir.join(name.trim_start_matches('/').replace('/', "_"));
                charts.push((name, chart, stem));
                continue;
            }
        }
        let values = match shape.as_slice() {
            [n] | [n, 3] if *n == steps => r.values(&name)?,
            _ => return Err(bad_shape()),
        };
        let series = if shape.len() == 1 {
            let label = name.rsplit('/').next().unwrap_or(&name).to_owned();
            vec![Series::new(label, time.clone(), values)]
        } else {
            ["x", "y", "z"]
                .iter()
                .enumerate()
                .map(|(c, label)| {
                    let y = values.iter().skip(c).step_by(3).copied().collect();
                    Series::new(*label, time.clone(), y)
                })
                .collect()
        };
        let title = match r.description(&name) {
            Some(d) if !d.is_empty() => format!("{file_name}: {d}"),
            _ => file_name.clone(),
        };
        let chart = LineChart {
            title,
            x_label: x_label.to_owned(),
            y_label: name.clone(),
            log_y,
            series,
            markers: markers.clone(),
        };
        let stem = out_dir.join(name.trim_start_matches('/').replace('/', "_"));
        charts.push((name, chart, stem));
    }

    std::fs::create_dir_all(out_dir).map_err(|source| PlotError::Io {
        path: out_dir.to_path_buf(),
        source,
    })?;
    let mut written = Vec::with_capacity(2 * charts.len());
    for (name, chart, stem) in charts {
        let (png, svg) = chart.render(&stem).map_err(|source| PlotError::Chart {
            path: file.to_path_buf(),
            dataset: name,
            source,
        })?;
        written.push(png);
        written.push(svg);
    }
    Ok(written)
}

/// A `/resultants` dataset (T × G × 3) at the last stored step over each
/// Gauss point's arc length, three curves per beam (the material
/// components: axial and shear forces, or torsion and bending moments).
fn resultants_chart(
    r: &ResultReader,
    name: &str,
    file_name: &str,
    time: &[f64],
) -> Result<LineChart, PlotError> {
    let values = r.values(name)?;
    let arc = r.values(layout::RESULTANTS_ARC_LENGTH)?;
    let points = arc.len();
    let last = values.len() / (3 * points.max(1));
    let row = &values[(last.saturating_sub(1)) * 3 * points..];
    let (beams, offsets) = r.resultant_beams()?;
    let consistent = offsets.len() == beams.len() + 1
        && offsets.windows(2).all(|w| w[0] <= w[1])
        && offsets.last().is_some_and(|&o| o as usize == points);
    if !consistent {
        return Err(PlotError::BadShape {
            path: r.path().to_path_buf(),
            dataset: format!("{name} (attributes beam_names, beam_offsets: {offsets:?})"),
            shape: vec![last, points, 3],
            steps: time.len(),
        });
    }
    let labels: [&str; 3] = if name == layout::RESULTANTS_MOMENT {
        ["M1 torsion", "M2 bending", "M3 bending"]
    } else {
        ["N1 axial", "N2 shear", "N3 shear"]
    };
    let mut series = Vec::new();
    for (b, beam) in beams.iter().enumerate() {
        let range = offsets[b] as usize..offsets[b + 1] as usize;
        for (c, label) in labels.iter().enumerate() {
            let label = if beams.len() > 1 {
                format!("{beam}: {label}")
            } else {
                (*label).to_owned()
            };
            let y = range.clone().map(|g| row[3 * g + c]).collect();
            series.push(Series::new(label, arc[range.clone()].to_vec(), y));
        }
    }
    let t = time.last().copied().unwrap_or(f64::NAN);
    Ok(LineChart {
        title: format!("{file_name}: {name} at t = {t}"),
        x_label: "arc length from the beam's start".to_owned(),
        y_label: name.to_owned(),
        log_y: false,
        series,
        markers: Vec::new(),
    })
}

/// A marker at the last stored time of a run that did not complete.
fn stop_marker(status: Option<String>, time: &[f64]) -> Vec<(f64, String)> {
    let Some(status) = status else {
        return Vec::new();
    };
    let Some(&last) = time.iter().rev().find(|t| t.is_finite()) else {
        return Vec::new();
    };
    let label = if status.starts_with(layout::STATUS_FAILED_PREFIX) {
        const MAX: usize = 60;
        if status.chars().count() > MAX {
            let cut: String = status.chars().take(MAX - 1).collect();
            format!("{cut}…")
        } else {
            status
        }
    } else if status == layout::STATUS_RUNNING {
        "run stopped (status \"running\")".to_owned()
    } else {
        return Vec::new();
    };
    vec![(last, label)]
}
