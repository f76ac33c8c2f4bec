//! Lee's frame through snap-through and snap-back by arc length, against
//! the exact limit loads of the same planar rod.

use super::reference::{fields, LEE_FRAME};
use super::table::{difference_of, sig, Row};
use super::{read_error, rows3, solve, Outcome, ReproduceError};
use flexmech_plot::charts::{Dash, LineChart, Marker, Panels, Series};
use std::path::Path;

const MODEL: &str = include_str!("../../../data/benchmarks/lee_frame.toml");
const MESH: &str = "20 three-node elements per member";
const STEP: &str = "static, arc length";
/// `P L²/EI` per unit load factor (the model's P = 20 000, EI/L² = 1000).
const LOAD_SCALE: f64 = 20.0;
/// The members' length.
const LENGTH: f64 = 120.0;

/// Runs the frame and sets its located limit points beside the exact ones.
pub fn run(dir: &Path, titles: bool) -> Result<Outcome, ReproduceError> {
    let r = solve(MODEL, "data/benchmarks/lee_frame.toml", dir, "lee_frame")?;
    let lambda = r.time().map_err(|e| read_error(r.path(), e))?;
    let located = r
        .values("/stability/critical_load_factor")
        .map_err(|e| read_error(r.path(), e))?;
    let exact: Vec<(String, f64)> = fields(LEE_FRAME)
        .iter()
        .map(|f| (f[0].to_string(), f[1].parse().unwrap_or(f64::NAN)))
        .collect();
    let rows = exact
        .iter()
        .enumerate()
        .map(|(k, (point, load))| {
            let ours = located.get(k).map_or(f64::NAN, |l| LOAD_SCALE * l);
            Row {
                benchmark: "Lee's frame (`lee_frame.toml`)".into(),
                quantity: format!("limit load P L²/EI, {point}"),
                reference: sig(*load),
                source: "exact",
                ours: sig(ours),
                difference: difference_of(ours, *load, exact[0].1, "of the first"),
                mesh: MESH,
                step: STEP,
            }
        })
        .collect();
    let d = rows3(&r, "/nodes/beam.8/displacement")?;
    let load: Vec<f64> = lambda.iter().map(|l| LOAD_SCALE * l).collect();
    let mut chart = LineChart::new("", "load-point displacement / L", "load P L²/EI");
    if titles {
        chart.title = "Lee's frame".into();
    }
    let span = [-0.1, 1.0];
    chart.series = vec![
        Series::new(
            "−v/L, flexmech",
            d.iter().map(|p| -p[1] / LENGTH).collect(),
            load.clone(),
        ),
        Series::new(
            "u/L, flexmech",
            d.iter().map(|p| p[0] / LENGTH).collect(),
            load,
        ),
    ];
    for (point, value) in &exact {
        chart.series.push(
            Series::new(
                format!("exact limit load, {point}"),
                span.to_vec(),
                vec![*value; 2],
            )
            .dash(Dash::Dotted)
            .marker(Marker::None),
        );
    }
    Ok(Outcome {
        rows,
        chart: Panels::row(vec![chart]),
    })
}
