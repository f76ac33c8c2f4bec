//! The elastica: a cantilever under a perpendicular dead tip force, λ =
//! PL²/EI to 16, against Mattiasson's published table.

use super::princeton::reference_marks;
use super::reference::{column, numbers, ELASTICA};
use super::table::{difference, sig, Row};
use super::{rows3, solve, times, Outcome, ReproduceError};
use flexmech_plot::charts::{LineChart, Panels, Series};
use std::path::Path;

const MODEL: &str = include_str!("../../../data/benchmarks/elastica.toml");
const MESH: &str = "16 three-node elements";
const STEP: &str = "static, 160 load steps";
/// The model's load factor at t = 1.
const LAMBDA_END: f64 = 16.0;

/// Runs the elastica and sets its tip beside the published table.
pub fn run(dir: &Path, titles: bool) -> Result<Outcome, ReproduceError> {
    let r = solve(MODEL, "data/benchmarks/elastica.toml", dir, "elastica")?;
    let lambda: Vec<f64> = times(&r)?.iter().map(|t| LAMBDA_END * t).collect();
    let tip = rows3(&r, "/nodes/rod.end/displacement")?;
    let (w, u): (Vec<f64>, Vec<f64>) = tip.iter().map(|d| (-d[2], -d[0])).unzip();
    let published = numbers(ELASTICA);
    let mut rows = Vec::new();
    for p in &published {
        let k = super::nearest(&lambda, p[0]);
        for (name, ours, reference) in [("w/L", w[k], p[1]), ("u/L", u[k], p[2])] {
            if p[0] == 10.0 {
                rows.push(Row {
                    benchmark: "elastica (`elastica.toml`)".into(),
                    quantity: format!("tip {name} at PL²/EI = {}", p[0]),
                    reference: sig(reference),
                    source: "published",
                    ours: sig(ours),
                    difference: difference(ours, reference),
                    mesh: MESH,
                    step: STEP,
                });
            }
        }
    }
    let mut chart = LineChart::new("", "load PL²/EI", "tip displacement / L");
    if titles {
        chart.title = "Elastica: cantilever under a dead tip force".into();
    }
    chart.series = vec![
        Series::new("w/L, flexmech", lambda.clone(), w),
        Series::new("u/L, flexmech", lambda, u),
        reference_marks(
            "w/L, Mattiasson",
            column(&published, 0),
            column(&published, 1),
            0,
        ),
        reference_marks(
            "u/L, Mattiasson",
            column(&published, 0),
            column(&published, 2),
            1,
        ),
    ];
    Ok(Outcome {
        rows,
        chart: Panels::row(vec![chart]),
    })
}
