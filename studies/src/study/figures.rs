//! The per-run scalar figures of a study, read back from a run's result file.

use std::path::{Path, PathBuf};

use hdf5::types::VarLenUnicode;

use super::spec::Figure;
use crate::results::layout;

/// What the summary records of one run: its status and every figure.
#[derive(Debug, Clone, PartialEq)]
pub struct RunFigures {
    /// `completed`, or `failed: <reason>`.
    pub status: String,
    /// See [`Figure::EnergyDrift`].
    pub energy_drift: f64,
    /// See [`Figure::MaxDisplacement`].
    pub max_displacement: f64,
    /// See [`Figure::FailureTime`].
    pub failure_time: f64,
    /// See [`Figure::WallTime`].
    pub wall_time: f64,
    /// See [`Figure::NewtonIterations`].
    pub newton_iterations: f64,
}

impl RunFigures {
    /// A run that left no result file (its model could not be built): every
    /// figure NaN.
    pub fn without_file(status: String) -> Self {
        Self {
            status,
            energy_drift: f64::NAN,
            max_displacement: f64::NAN,
            failure_time: f64::NAN,
            wall_time: f64::NAN,
            newton_iterations: f64::NAN,
        }
    }

    /// The value of `figure`.
    pub fn get(&self, figure: Figure) -> f64 {
        match figure {
            Figure::EnergyDrift => self.energy_drift,
            Figure::MaxDisplacement => self.max_displacement,
            Figure::FailureTime => self.failure_time,
            Figure::WallTime => self.wall_time,
            Figure::NewtonIterations => self.newton_iterations,
        }
    }

    /// Whether the run failed (status `failed: …`).
    pub fn failed(&self) -> bool {
        is_failed(&self.status)
    }
}

/// Whether a status text is that of a failed run.
pub fn is_failed(status: &str) -> bool {
    status.starts_with("failed")
}

/// A result file could not be read.
#[derive(Debug, thiserror::Error)]
#[error("{}: HDF5 error while {what}: {source}", .file.display())]
pub struct FigureError {
    /// The result file.
    pub file: PathBuf,
    /// What was being read.
    pub what: String,
    /// The library's error.
    #[source]
    pub source: hdf5::Error,
}

/// `max |e(t) − e(0)| / max(|e(0)|, max |e|)`; 0 for an identically zero
/// series, NaN for an empty one.
pub fn relative_drift(e: &[f64]) -> f64 {
    let Some(&e0) = e.first() else {
        return f64::NAN;
    };
    let num = e.iter().map(|v| (v - e0).abs()).fold(0.0, f64::max);
    let den = e.iter().map(|v| v.abs()).fold(e0.abs(), f64::max);
    if num == 0.0 {
        0.0
    } else {
        num / den
    }
}

/// Reads the status and figures of the run whose result file is `file`.
///
/// - `energy_drift`: [`relative_drift`] of `/energy/total`, less
///   `/energy/driver_work` when that dataset exists;
/// - `max_displacement`: largest `|/nodes/<label>/displacement|` over every
///   tracked node and stored step (NaN when no node is tracked);
/// - `failure_time`: last value of `/time` when the status starts with
///   `failed`, else NaN;
/// - `wall_time`: root attribute `wall_time_s` (NaN if absent);
/// - `newton_iterations`: sum of `/solver/iterations`.
pub fn read_figures(file: &Path) -> Result<RunFigures, FigureError> {
    let err = |what: &str| {
        let what = what.to_owned();
        move |source| FigureError {
            file: file.to_path_buf(),
            what,
            source,
        }
    };
    let h5 = hdf5::File::open(file).map_err(err("opening the file"))?;
    let read = |name: &str| -> Result<Vec<f64>, FigureError> {
        h5.dataset(name)
            .and_then(|d| d.read_raw::<f64>())
            .map_err(err(&format!("reading {name}")))
    };
    let status = h5
        .attr(layout::ATTR_STATUS)
        .and_then(|a| a.read_scalar::<VarLenUnicode>())
        .map(|s| s.as_str().to_owned())
        .map_err(err(&format!(
            "reading root attribute {}",
            layout::ATTR_STATUS
        )))?;
    let wall_time = match h5.attr(layout::ATTR_WALL_TIME) {
        Ok(a) => a.read_scalar::<f64>().map_err(err(&format!(
            "reading root attribute {}",
            layout::ATTR_WALL_TIME
        )))?,
        Err(_) => f64::NAN,
    };

    let mut energy = read(layout::ENERGY_TOTAL)?;
    if h5.link_exists(layout::ENERGY_DRIVER_WORK) {
        let work = read(layout::ENERGY_DRIVER_WORK)?;
        for (e, w) in energy.iter_mut().zip(work) {
            *e -= w;
        }
    }
    let energy_drift = relative_drift(&energy);

    let mut max_displacement = f64::NAN;
    if h5.link_exists(layout::NODES) {
        let nodes = h5.group(layout::NODES).map_err(err("opening /nodes"))?;
        let labels = nodes
            .member_names()
            .map_err(err("listing the groups of /nodes"))?;
        for label in labels {
            let d = read(&layout::node_path(&label, layout::NODE_DISPLACEMENT))?;
            for row in d.chunks_exact(3) {
                let norm = (row[0] * row[0] + row[1] * row[1] + row[2] * row[2]).sqrt();
                // NaN-aware: NaN.max(x) is x.
                max_displacement = max_displacement.max(norm);
            }
        }
    }

    let failure_time = if is_failed(&status) {
        read(layout::TIME)?.last().copied().unwrap_or(f64::NAN)
    } else {
        f64::NAN
    };

    let iterations = h5
        .dataset(layout::SOLVER_ITERATIONS)
        .and_then(|d| d.read_raw::<u64>())
        .map_err(err(&format!("reading {}", layout::SOLVER_ITERATIONS)))?;
    let newton_iterations = iterations.iter().sum::<u64>() as f64;

    Ok(RunFigures {
        status,
        energy_drift,
        max_displacement,
        failure_time,
        wall_time,
        newton_iterations,
    })
}
