//! The per-run scalar figures of a study, read back from a run's result file.

use std::path::Path;

use super::spec::Figure;
use flexmech_results::{layout, ReadError, ResultReader};

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
    /// The values of the study's [`Figure::Dataset`] figures, by name.
    pub datasets: Vec<(String, f64)>,
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
            datasets: Vec::new(),
        }
    }

    /// The value of the dataset figure or derivative column `name` (NaN
    /// when the run has none).
    pub fn named(&self, name: &str) -> f64 {
        self.datasets
            .iter()
            .find(|(n, _)| n == name)
            .map_or(f64::NAN, |(_, v)| *v)
    }

    /// The value of `figure`.
    pub fn get(&self, figure: &Figure) -> f64 {
        match figure {
            Figure::Dataset(d) => self.named(&d.name),
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
#[error(transparent)]
pub struct FigureError(#[from] pub ReadError);

/// Reads the status and figures of the run whose result file is `file`.
///
/// `energy_drift`, `max_displacement` and `newton_iterations` are the run's
/// figures of merit, computed while it ran over every converged step
/// ([`flexmech_results::merit`]) and stored as root attributes. A file
/// written before they were recorded is summarised from its stored steps
/// with the same definitions:
///
/// - `energy_drift`: [`ResultReader::energy_drift`] (the definition of
///   [`flexmech_results::reader::energy_drift`]);
/// - `max_displacement`: largest `|/nodes/<label>/displacement|` over every
///   tracked node and stored step (NaN when no node is tracked);
/// - `newton_iterations`: sum of `/solver/iterations`.
///
/// The others:
///
/// - `failure_time`: last value of `/time` (the last converged step, always
///   stored) when the status starts with `failed`, else NaN;
/// - `wall_time`: root attribute `wall_time_s` (NaN if absent);
/// - every [`Figure::Dataset`] of `figures`: its reduction of its dataset.
pub fn read_figures(file: &Path, figures: &[Figure]) -> Result<RunFigures, FigureError> {
    let r = ResultReader::open(file)?;
    let status = r.status()?;
    let stored = |name: &str| r.f64_attr(name);
    let energy_drift = match stored(layout::ATTR_ENERGY_DRIFT) {
        Some(v) => v,
        None => r.energy_drift()?,
    };
    let max_displacement = match stored(layout::ATTR_MAX_DISPLACEMENT) {
        Some(v) => v,
        None => stored_max_displacement(&r)?,
    };
    let newton_iterations = match stored(layout::ATTR_NEWTON_ITERATIONS) {
        Some(v) => v,
        None => r.counts(layout::SOLVER_ITERATIONS)?.iter().sum::<u64>() as f64,
    };
    let failure_time = if is_failed(&status) {
        r.time()?.last().copied().unwrap_or(f64::NAN)
    } else {
        f64::NAN
    };
    Ok(RunFigures {
        energy_drift,
        max_displacement,
        failure_time,
        wall_time: r.wall_time_s(),
        newton_iterations,
        datasets: dataset_figures(&r, figures)?,
        status,
    })
}

/// Every [`Figure::Dataset`] of `figures` for the run in `r`, by name,
/// each followed by its derivatives (by their column names).
fn dataset_figures(r: &ResultReader, figures: &[Figure]) -> Result<Vec<(String, f64)>, ReadError> {
    let mut out = Vec::new();
    for f in figures {
        if let Figure::Dataset(d) = f {
            out.push((d.name.clone(), d.value(r)?));
            out.extend(d.derivative_values(r)?);
        }
    }
    Ok(out)
}

/// Largest tracked-node displacement over the stored steps.
fn stored_max_displacement(r: &ResultReader) -> Result<f64, ReadError> {
    let mut max_displacement = f64::NAN;
    for label in r.node_labels()? {
        for row in r.rows3(&layout::node_path(&label, layout::NODE_DISPLACEMENT))? {
            let norm = (row[0] * row[0] + row[1] * row[1] + row[2] * row[2]).sqrt();
            // NaN-aware: NaN.max(x) is x.
            max_displacement = max_displacement.max(norm);
        }
    }
    Ok(max_displacement)
}
