//! The driven paper examples spin up smoothly: the sampled drive follows its
//! documented formula `ψ(t) = (W/2)(t − sin(πt)/π)` (t ≤ 1 s), `W(t − ½)`
//! after, and its rate has no jump — the secant slopes of consecutive table
//! intervals differ by at most the interval times the largest acceleration
//! `W π/2`, which is what a C¹ function sampled at that spacing allows.
//! (A rate jump at t = 1 s, as the drive once had, fails the slope bound by
//! two orders of magnitude.)

use flexmech::model::{load_model, PrescribedSpec, TimeFunction};
use std::f64::consts::PI;
use std::path::Path;

const W: f64 = 2.0 * PI;
/// Largest |ψ''| of the drive: `(W π/2) sin(πt)`.
const MAX_ACCELERATION: f64 = W * PI / 2.0;
/// The tables are printed with ten decimals.
const TABLE_ROUNDING: f64 = 1e-10;

fn drive(t: f64) -> f64 {
    if t <= 1.0 {
        0.5 * W * (t - (PI * t).sin() / PI)
    } else {
        W * (t - 0.5)
    }
}

fn drive_rows(model: &str) -> Vec<(f64, f64)> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../data/paper")
        .join(format!("{model}.toml"));
    let m = load_model(&path).unwrap();
    let angle = m
        .prescribed
        .iter()
        .find_map(|p| match p {
            PrescribedSpec::JointAngle { angle, .. } => Some(angle.clone()),
            _ => None,
        })
        .expect("a driven joint");
    match angle {
        TimeFunction::Table(rows) => rows,
        other => panic!("{model}: expected a table, found {other:?}"),
    }
}

#[test]
fn the_drive_of_every_driven_example_is_smooth() {
    for model in ["cam", "lobe", "rack_pinion", "screw_driven"] {
        let rows = drive_rows(model);
        for &(t, v) in &rows {
            assert!(
                (v - drive(t)).abs() <= TABLE_ROUNDING,
                "{model}: ψ({t}) = {v}, formula {}",
                drive(t)
            );
        }
        let slopes: Vec<(f64, f64)> = rows
            .windows(2)
            .map(|w| (w[1].0 - w[0].0, (w[1].1 - w[0].1) / (w[1].0 - w[0].0)))
            .collect();
        for pair in slopes.windows(2) {
            let ((h0, s0), (h1, s1)) = (pair[0], pair[1]);
            // Secant slopes are rates at the intervals' midpoints, ½(h0 + h1) apart.
            let bound = 0.5 * (h0 + h1) * MAX_ACCELERATION + 4.0 * TABLE_ROUNDING / h0.min(h1);
            assert!(
                (s1 - s0).abs() <= bound,
                "{model}: rate jumps from {s0} to {s1} (bound {bound})"
            );
        }
        // Full speed is reached with zero acceleration: the constant-rate part has rate W.
        let last = slopes.last().unwrap().1;
        assert!((last - W).abs() < 1e-9, "{model}: final rate {last}");
    }
}
