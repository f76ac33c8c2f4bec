//! The benchmark table: benchmark, quantity, reference (and what it is),
//! ours, difference, mesh and step — as Markdown and CSV.

use crate::reproduce::ReproduceError;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// One row of the table.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    /// The benchmark (and its model file).
    pub benchmark: String,
    /// The quantity, exactly as defined.
    pub quantity: String,
    /// The reference value, as text.
    pub reference: String,
    /// What the reference is: published, exact, an independent run.
    pub source: &'static str,
    /// Ours, as text.
    pub ours: String,
    /// The difference, as text (absolute, and relative where it helps).
    pub difference: String,
    /// The mesh.
    pub mesh: &'static str,
    /// The integrator and step, or the load stepping.
    pub step: &'static str,
}

/// A number with six significant digits.
pub fn sig(x: f64) -> String {
    if x == 0.0 || (1e-3..1e4).contains(&x.abs()) {
        let digits = (5 - x.abs().log10().floor() as i32).clamp(0, 9) as usize;
        format!("{x:.digits$}")
    } else {
        format!("{x:.5e}")
    }
}

/// `ours − reference`, and its size relative to the reference.
pub fn difference(ours: f64, reference: f64) -> String {
    difference_of(ours, reference, reference, "relative")
}

/// `ours − reference`, and its size as a fraction of `scale` (`what` it is).
pub fn difference_of(ours: f64, reference: f64, scale: f64, what: &str) -> String {
    format!(
        "{:.1e} ({:.1e} {what})",
        ours - reference,
        (ours - reference).abs() / scale.abs()
    )
}

/// Writes `dir/table.md` and `dir/table.csv`.
pub fn write(rows: &[Row], dir: &Path) -> Result<(PathBuf, PathBuf), ReproduceError> {
    let mut md = String::from(
        "| benchmark | quantity | reference | ours | difference | mesh | step |\n|---|---|---|---|---|---|---|\n",
    );
    let mut csv = String::from("benchmark,quantity,reference,source,ours,difference,mesh,step\n");
    for r in rows {
        let cell = |s: &str| s.replace('|', "\\|");
        let _ = writeln!(
            md,
            "| {} | {} | {} ({}) | {} | {} | {} | {} |",
            cell(&r.benchmark),
            cell(&r.quantity),
            cell(&r.reference),
            r.source,
            cell(&r.ours),
            cell(&r.difference),
            r.mesh,
            r.step
        );
        let quote = |s: &str| format!("\"{}\"", s.replace('"', "\"\""));
        let fields = [
            &r.benchmark,
            &r.quantity,
            &r.reference,
            r.source,
            &r.ours,
            &r.difference,
            r.mesh,
            r.step,
        ];
        let line: Vec<String> = fields.iter().map(|f| quote(f)).collect();
        let _ = writeln!(csv, "{}", line.join(","));
    }
    let (md_path, csv_path) = (dir.join("table.md"), dir.join("table.csv"));
    for (path, text) in [(&md_path, md), (&csv_path, csv)] {
        std::fs::write(path, text).map_err(|source| ReproduceError::Write {
            file: path.clone(),
            source,
        })?;
    }
    Ok((md_path, csv_path))
}
