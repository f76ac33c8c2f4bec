//! The rotating shaft with an unbalanced disc spun up through its critical
//! speed (2016 problem 4), against the same model run in an independent
//! code.

use super::reference::{column, numbers, ROTATING_SHAFT};
use super::table::{difference, sig, Row};
use super::{against_twin, nearest, rows3, solve, times, Outcome, ReproduceError};
use std::path::Path;

const MODEL: &str = include_str!("../../../data/benchmarks/rotating_shaft.toml");
const MESH: &str = "16 two-node elements";
const STEP: &str = "generalized-α ρ∞ = 0, Δt = 1e-4";

fn row(quantity: &str, reference: f64, ours: f64) -> Row {
    Row {
        benchmark: "rotating shaft, 2016 problem 4 (`rotating_shaft.toml`)".into(),
        quantity: quantity.into(),
        reference: sig(reference),
        source: "independent run",
        ours: sig(ours),
        difference: difference(ours, reference),
        mesh: MESH,
        step: STEP,
    }
}

/// The largest whirl radius `√(u_y² + u_z²)` over `(a, b]`.
fn radius(t: &[f64], uy: &[f64], uz: &[f64], (a, b): (f64, f64)) -> f64 {
    (0..t.len())
        .filter(|&k| t[k] > a && t[k] <= b + 1e-9)
        .fold(0.0f64, |m, k| m.max(uy[k].hypot(uz[k])))
}

/// Runs the shaft and sets its mid-span whirl beside the independent run.
pub fn run(dir: &Path, titles: bool) -> Result<Outcome, ReproduceError> {
    let r = solve(
        MODEL,
        "data/benchmarks/rotating_shaft.toml",
        dir,
        "rotating_shaft",
    )?;
    let t = times(&r)?;
    let u = rows3(&r, "/nodes/shaft.8/displacement")?;
    let twin = numbers(ROTATING_SHAFT);
    let (tt, ty, tz) = (column(&twin, 0), column(&twin, 2), column(&twin, 3));
    let at = |c: usize| -> Vec<f64> { tt.iter().map(|&s| u[nearest(&t, s)][c]).collect() };
    let (oy, oz) = (at(1), at(2));
    let rows = vec![
        row(
            "largest whirl radius before the critical speed, 0–1 s (m)",
            radius(&tt, &ty, &tz, (0.0, 1.0)),
            radius(&tt, &oy, &oz, (0.0, 1.0)),
        ),
        row(
            "largest whirl radius past it, 1.5–2.5 s (m)",
            radius(&tt, &ty, &tz, (1.5, 2.5)),
            radius(&tt, &oy, &oz, (1.5, 2.5)),
        ),
    ];
    let title = titles.then(|| "Rotating shaft through its critical speed".to_string());
    Ok(Outcome {
        rows,
        chart: against_twin(title, &t, &u, &twin, ["horizontal u_y", "vertical u_z"]),
    })
}
