//! The lateral buckling of a strip driven through a link and crank (2016
//! problem 3), against the same model run in an independent code.

use super::reference::{column, numbers, LATERAL_BUCKLING};
use super::table::{difference, sig, Row};
use super::{against_twin, nearest, rows3, solve, times, Outcome, ReproduceError};
use std::path::Path;

const MODEL: &str = include_str!("../../../data/benchmarks/lateral_buckling.toml");
const MESH: &str = "20/10/5 two-node elements (strip/link/crank)";
const STEP: &str = "generalized-α ρ∞ = 0.9, Δt = 1e-3";
/// The lateral displacement that marks the buckling (m).
const BUCKLED: f64 = 1e-3;

fn row(quantity: &str, reference: String, ours: String, diff: String) -> Row {
    Row {
        benchmark: "lateral buckling, 2016 problem 3 (`lateral_buckling.toml`)".into(),
        quantity: quantity.into(),
        reference,
        source: "independent run",
        ours,
        difference: diff,
        mesh: MESH,
        step: STEP,
    }
}

/// The first time `|u_y|` exceeds [`BUCKLED`], and the largest `|u_y|` in
/// (0.2, 0.3] s.
fn measures(t: &[f64], uy: &[f64]) -> (f64, f64) {
    let onset = t
        .iter()
        .zip(uy)
        .find(|(_, y)| y.abs() > BUCKLED)
        .map_or(f64::NAN, |(t, _)| *t);
    let swing = t
        .iter()
        .zip(uy)
        .filter(|(t, _)| **t > 0.2 && **t <= 0.3 + 1e-9)
        .fold(0.0f64, |m, (_, y)| m.max(y.abs()));
    (onset, swing)
}

/// Runs the strip and sets its mid-span beside the independent run.
pub fn run(dir: &Path, titles: bool) -> Result<Outcome, ReproduceError> {
    let r = solve(
        MODEL,
        "data/benchmarks/lateral_buckling.toml",
        dir,
        "lateral_buckling",
    )?;
    let t = times(&r)?;
    let u = rows3(&r, "/nodes/strip.10/displacement")?;
    let twin = numbers(LATERAL_BUCKLING);
    let (tt, ty) = (column(&twin, 0), column(&twin, 2));
    let ours_y: Vec<f64> = tt.iter().map(|&s| u[nearest(&t, s)][1]).collect();
    let (onset, swing) = measures(&tt, &ours_y);
    let (twin_onset, twin_swing) = measures(&tt, &ty);
    let rows = vec![
        row(
            "time |u_y| first exceeds 1 mm (s)",
            format!("{twin_onset:.3}"),
            format!("{onset:.3}"),
            format!("{:.3}", onset - twin_onset),
        ),
        row(
            "largest |u_y| in 0.2–0.3 s (m)",
            sig(twin_swing),
            sig(swing),
            difference(swing, twin_swing),
        ),
    ];
    let title = titles.then(|| "Lateral buckling of a strip".to_string());
    Ok(Outcome {
        rows,
        chart: against_twin(title, &t, &u, &twin, ["lateral u_y", "vertical u_z"]),
    })
}
