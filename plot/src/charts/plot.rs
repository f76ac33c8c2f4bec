//! `flexmech plot`: one line chart per result-file dataset, over `/time`.
//! `/resultants/force` and `/resultants/moment` are drawn instead over the
//! Gauss points' arc length at the last stored step (three curves per beam).
//!
//! A dataset of shape T (one value per stored step) gives one curve, a T×3
//! dataset three (its x, y and z components). The y axis is labelled with the
//! dataset's description and its unit ([`unit_of`]: SI names of the model's
//! consistent units), the x axis "time (s)", or "load factor" in statics.
//! [`PlotOptions`] give other labels, no title, an x–y plot against another
//! dataset (`--x /joints/screw/angle`, or a component `DATASET[k]`), and
//! other result files whose same datasets are overlaid (curves named by
//! file). A run that stopped early (`status` `"failed: …"` or still
//! `"running"`) gets a marker line at its last stored time.

use std::path::{Path, PathBuf};

use super::chart::{LineChart, Series};
use super::line::ChartError;
use flexmech_results::{layout, ReadError, ResultReader};

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

/// What `flexmech plot` can change about its charts.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PlotOptions {
    /// Logarithmic y axis.
    pub log_y: bool,
    /// The x axis: another dataset (T, or `DATASET[k]` for component `k`
    /// of a T×3 one) instead of `/time`.
    pub x: Option<String>,
    /// Label of the x axis (default: `/time`'s or the x dataset's).
    pub x_label: Option<String>,
    /// Label of the y axis (default: the dataset's description and unit).
    pub y_label: Option<String>,
    /// Title (default: file and description; `Some("")`: none).
    pub title: Option<String>,
    /// Other result files whose same datasets are drawn in the same charts.
    pub overlay: Vec<PathBuf>,
    /// Also a PDF of each chart (its PGFPlots copy through `pdflatex`).
    pub pdf: bool,
}

/// The unit of a dataset's values by its name (SI names for the model's
/// consistent units: a model in mm, t, s gives mm where this says m).
pub fn unit_of(dataset: &str) -> Option<&'static str> {
    let leaf = dataset.rsplit('/').next().unwrap_or(dataset);
    Some(match leaf {
        "position" | "displacement" | "released_translation" | "arc_length" => "m",
        "rotation" | "angle" | "rotation_vector" => "rad",
        "velocity" => "m/s",
        "angular_velocity" => "rad/s",
        "reaction_force" | "force" => "N",
        "reaction_moment" | "moment" => "N·m",
        "dt" | "time" => "s",
        "linear" if dataset.starts_with("/momentum") => "N·s",
        "angular" if dataset.starts_with("/momentum") => "N·m·s",
        _ if dataset.starts_with("/energy") => "J",
        _ => return None,
    })
}

/// A label from a dataset's description (or its last path element) and unit.
fn label_of(r: &ResultReader, name: &str) -> String {
    let text = match r.description(name) {
        Some(d) if !d.is_empty() => d,
        _ => name.rsplit('/').next().unwrap_or(name).replace('_', " "),
    };
    match unit_of(name) {
        Some(u) => format!("{text} ({u})"),
        None => text,
    }
}

/// `DATASET` or `DATASET[k]`: the path (leading `/` added) and component.
fn split_component(spec: &str) -> (String, Option<usize>) {
    let spec = spec.trim();
    let name = |s: &str| format!("/{}", s.trim_start_matches('/'));
    if let Some(open) = spec.rfind('[') {
        if let Some(k) = spec[open + 1..]
            .strip_suffix(']')
            .and_then(|k| k.trim().parse().ok())
        {
            return (name(&spec[..open]), Some(k));
        }
    }
    (name(spec), None)
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
    let options = PlotOptions {
        log_y,
        ..PlotOptions::default()
    };
    plot_with(file, datasets, out_dir, &options)
}

/// One file's curves of dataset `name` (shape T or T×3) over `x`.
fn curves(
    r: &ResultReader,
    file: &Path,
    name: &str,
    x: &[f64],
    prefix: &str,
) -> Result<Vec<Series>, PlotError> {
    let steps = x.len();
    let shape = r.shape(name)?;
    let values = match shape.as_slice() {
        [n] | [n, 3] if *n == steps => r.values(name)?,
        _ => {
            return Err(PlotError::BadShape {
                path: file.to_path_buf(),
                dataset: name.to_owned(),
                shape,
                steps,
            })
        }
    };
    let named = |label: &str| {
        if prefix.is_empty() {
            label.to_owned()
        } else if label.is_empty() {
            prefix.to_owned()
        } else {
            format!("{prefix}: {label}")
        }
    };
    Ok(if shape.len() == 1 {
        let label = if prefix.is_empty() {
            name.rsplit('/').next().unwrap_or(name).replace('_', " ")
        } else {
            String::new()
        };
        vec![Series::new(named(&label), x.to_vec(), values)]
    } else {
        ["x", "y", "z"]
            .iter()
            .enumerate()
            .map(|(c, label)| {
                let y = values.iter().skip(c).step_by(3).copied().collect();
                Series::new(named(label), x.to_vec(), y)
            })
            .collect()
    })
}

/// The abscissae of a file: `/time`, or the `--x` dataset (a component of
/// a T×3 one), with its label.
fn abscissae(
    r: &ResultReader,
    file: &Path,
    x: Option<&str>,
) -> Result<(Vec<f64>, String), PlotError> {
    let time = r.time()?;
    let Some(spec) = x else {
        let label = if r.integrator().as_deref() == Some("static") {
            "load factor"
        } else {
            "time (s)"
        };
        return Ok((time, label.to_owned()));
    };
    let (name, component) = split_component(spec);
    let shape = r.shape(&name)?;
    let values = r.values(&name)?;
    let bad = || PlotError::BadShape {
        path: file.to_path_buf(),
        dataset: format!("{name} (--x; a T×3 dataset needs a component, e.g. {name}[0])"),
        shape: shape.clone(),
        steps: time.len(),
    };
    let xs = match (shape.as_slice(), component) {
        ([n], None) if *n == time.len() => values,
        ([n, 3], Some(k)) if *n == time.len() && k < 3 => {
            values.iter().skip(k).step_by(3).copied().collect()
        }
        _ => return Err(bad()),
    };
    let mut label = label_of(r, &name);
    if let Some(k) = component {
        label = format!("{label}, component {k}");
    }
    Ok((xs, label))
}

fn stem_of(file: &Path) -> String {
    file.file_stem()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| file.display().to_string())
}

/// [`plot_datasets`] with [`PlotOptions`].
pub fn plot_with(
    file: &Path,
    datasets: &[String],
    out_dir: &Path,
    options: &PlotOptions,
) -> Result<Vec<PathBuf>, PlotError> {
    let r = ResultReader::open(file)?;
    let time = r.time()?;
    let (x, x_label) = abscissae(&r, file, options.x.as_deref())?;
    let x_label = options.x_label.clone().unwrap_or(x_label);
    let markers = if options.x.is_none() {
        stop_marker(r.string_attr(layout::ATTR_STATUS), &time)
    } else {
        Vec::new()
    };
    let file_name = file
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| file.display().to_string());
    let others: Vec<(PathBuf, ResultReader)> = options
        .overlay
        .iter()
        .map(|p| ResultReader::open(p).map(|r| (p.clone(), r)))
        .collect::<Result<_, _>>()?;
    let overlaid = !others.is_empty();

    let mut charts = Vec::with_capacity(datasets.len());
    for requested in datasets {
        let name = format!("/{}", requested.trim_start_matches('/'));
        let shape = r.shape(&name)?;
        let stem = out_dir.join(name.trim_start_matches('/').replace('/', "_"));
        if let [n, _, 3] = shape.as_slice() {
            if *n == time.len() && name.starts_with(layout::RESULTANTS) {
                let mut chart = resultants_chart(&r, &name, &file_name, &time)?;
                if let Some(t) = &options.title {
                    chart.title.clone_from(t);
                }
                charts.push((name, chart, stem));
                continue;
            }
        }
        let own = if overlaid {
            stem_of(file)
        } else {
            String::new()
        };
        let mut series = curves(&r, file, &name, &x, &own)?;
        for (path, other) in &others {
            let (ox, _) = abscissae(other, path, options.x.as_deref())?;
            series.extend(curves(other, path, &name, &ox, &stem_of(path))?);
        }
        let title = match (&options.title, r.description(&name)) {
            (Some(t), _) => t.clone(),
            (None, Some(d)) if !d.is_empty() => format!("{file_name}: {d}"),
            (None, _) => file_name.clone(),
        };
        let chart = LineChart {
            title,
            x_label: x_label.clone(),
            y_label: options
                .y_label
                .clone()
                .unwrap_or_else(|| label_of(&r, &name)),
            log_y: options.log_y,
            series,
            markers: markers.clone(),
        };
        charts.push((name, chart, stem));
    }

    std::fs::create_dir_all(out_dir).map_err(|source| PlotError::Io {
        path: out_dir.to_path_buf(),
        source,
    })?;
    let mut written = Vec::with_capacity(2 * charts.len());
    for (name, chart, stem) in charts {
        let error = |source| PlotError::Chart {
            path: file.to_path_buf(),
            dataset: name.clone(),
            source,
        };
        written.extend(chart.render_all(&stem, options.pdf).map_err(error)?);
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
        x_label: "arc length from the beam's start (m)".to_owned(),
        y_label: label_of(r, name),
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
