//! Helpers the integration tests share: model paths, result datasets and
//! the drift of a conserved series. (Each test crate uses a subset.)

use std::path::{Path, PathBuf};

/// A path under the repository's `data/`.
pub fn data(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../data")
        .join(rel)
}

/// A whole dataset of a result file, flattened.
pub fn read<T: hdf5::H5Type>(file: &Path, dataset: &str) -> Vec<T> {
    hdf5::File::open(file)
        .unwrap()
        .dataset(dataset)
        .unwrap()
        .read_raw()
        .unwrap()
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
