//! The four-bar with a misaligned joint (2016 problem 2) as its authors
//! define it, against one author's stored run.

use super::princeton::reference_marks;
use super::reference::{column, numbers, FOUR_BAR};
use super::table::{difference, sig, Row};
use super::{nearest, rows3, solve, times, Outcome, ReproduceError};
use flexmech_plot::charts::{LineChart, Panels, Series};
use std::path::Path;

const MODEL: &str = include_str!("../../../data/benchmarks/four_bar.toml");
const MESH: &str = "8 two-node elements per bar";
const STEP: &str = "generalized-α ρ∞ = 0, Δt = 4e-3";
/// z_C's out-of-plane minimum in the authors' run and its time (their
/// stored run; see the model file).
const AUTHORS_Z_MIN: (f64, f64) = (-4.1277e-3, 2.672);

fn row(quantity: String, reference: String, ours: String, difference: String) -> Row {
    Row {
        benchmark: "four-bar, 2016 problem 2 (`four_bar.toml`)".into(),
        quantity,
        reference,
        source: "authors' run",
        ours,
        difference,
        mesh: MESH,
        step: STEP,
    }
}

/// Runs the four-bar and sets C's motion beside the authors' run.
pub fn run(dir: &Path, titles: bool) -> Result<Outcome, ReproduceError> {
    let r = solve(MODEL, "data/benchmarks/four_bar.toml", dir, "four_bar")?;
    let t = times(&r)?;
    let c = rows3(&r, "/nodes/bar2.end/position")?;
    let authors = numbers(FOUR_BAR);
    let (mut in_plane, mut out_of_plane) = (0.0f64, 0.0f64);
    for a in &authors {
        let p = c[nearest(&t, a[0])];
        in_plane = in_plane.max((p[0] - a[1]).abs()).max((p[1] - a[2]).abs());
        out_of_plane = out_of_plane.max((p[2] - a[3]).abs());
    }
    let k = (0..t.len())
        .min_by(|&a, &b| c[a][2].total_cmp(&c[b][2]))
        .unwrap_or(0);
    let rows = vec![
        row(
            "C's out-of-plane minimum z_C (m)".into(),
            sig(AUTHORS_Z_MIN.0),
            sig(c[k][2]),
            difference(c[k][2], AUTHORS_Z_MIN.0),
        ),
        row(
            "its time (s)".into(),
            format!("{}", AUTHORS_Z_MIN.1),
            format!("{:.3}", t[k]),
            format!("{:.3}", t[k] - AUTHORS_Z_MIN.1),
        ),
        row(
            "C's position at 22 times: largest difference (m)".into(),
            "22 rows".into(),
            "in plane / out of plane".into(),
            format!("{in_plane:.1e} / {out_of_plane:.1e}"),
        ),
    ];
    let mut chart = LineChart::new("", "time (s)", "C's out-of-plane displacement z_C (m)");
    if titles {
        chart.title = "Four-bar with a misaligned joint".into();
    }
    chart.series = vec![
        Series::new("flexmech", t, c.iter().map(|p| p[2]).collect()),
        reference_marks("authors' run", column(&authors, 0), column(&authors, 3), 1),
    ];
    Ok(Outcome {
        rows,
        chart: Panels::row(vec![chart]),
    })
}
