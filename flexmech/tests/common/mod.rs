//! Helpers the integration tests share: model paths, result datasets and
//! attributes (read through [`ResultReader`], not the HDF5 library) and
//! the drift of a conserved series. (Each test crate uses a subset.)

use std::path::{Path, PathBuf};

use flexmech::results::ResultReader;

/// A path under the repository's `data/`.
pub fn data(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../data")
        .join(rel)
}

/// A result file (or study summary) opened for reading.
pub fn reader(file: &Path) -> ResultReader {
    ResultReader::open(file).unwrap_or_else(|e| panic!("{e}"))
}

/// A whole `f64` dataset of a result file, flattened.
pub fn read(file: &Path, dataset: &str) -> Vec<f64> {
    reader(file)
        .values(dataset)
        .unwrap_or_else(|e| panic!("{e}"))
}

/// A whole `u64` dataset of a result file (`/solver/iterations`, ...).
pub fn read_counts(file: &Path, dataset: &str) -> Vec<u64> {
    reader(file)
        .counts(dataset)
        .unwrap_or_else(|e| panic!("{e}"))
}

/// A whole `i64` dataset of a result file (`/solver/negative_pivots`).
pub fn read_integers(file: &Path, dataset: &str) -> Vec<i64> {
    reader(file)
        .integers(dataset)
        .unwrap_or_else(|e| panic!("{e}"))
}

/// A whole string dataset of a result file or summary.
pub fn read_strings(file: &Path, dataset: &str) -> Vec<String> {
    reader(file)
        .strings(dataset)
        .unwrap_or_else(|e| panic!("{e}"))
}

/// A string root attribute of a result file or summary (panics when absent).
pub fn string_attr(file: &Path, name: &str) -> String {
    reader(file)
        .string_attr(name)
        .unwrap_or_else(|| panic!("{}: no string attribute {name}", file.display()))
}

/// Largest change of a conserved series (rows of `width`) from its first
/// row, relative to the first row's size.
pub fn drift(series: &[f64], width: usize) -> f64 {
    let rows: Vec<&[f64]> = series.chunks(width).collect();
    let norm = |r: &[f64]| r.iter().map(|v| v * v).sum::<f64>().sqrt();
    rows.iter()
        .map(|r| {
            let d: Vec<f64> = r.iter().zip(rows[0]).map(|(a, b)| a - b).collect();
            norm(&d) / norm(rows[0])
        })
        .fold(0.0, f64::max)
}

/// Every time integrator of the model format.
pub const INTEGRATORS: [&str; 5] = [
    "newmark",
    "generalized-alpha",
    "momentum",
    "energy-momentum",
    "energy-momentum-paper",
];
