//! Every dynamic result file stores the velocities of every node at every
//! stored step (`/configuration/velocity`, `/configuration/angular_velocity`,
//! spatial components), so a file is enough to restart or animate a run;
//! static files do not have them. Checked against the model's initial
//! velocity field (`v = v₀ + ω × x`, `ω` for every triad) and against each
//! scheme's own velocity relation between stored steps.

use crate::common;

use common::{data, read, reader};
use flexmech::model::{load_model, parse_model};
use flexmech::results::run_model;
use std::path::Path;

/// The spinning beam of `data/dynamics`, shortened to `steps` steps of the
/// model's Δt with `integrator`.
fn spinning_beam(integrator: &str, steps: usize) -> flexmech::model::Model {
    let text = std::fs::read_to_string(data("dynamics/spinning_beam.toml")).unwrap();
    let text = text
        .replace(
            "integrator = \"energy-momentum\"",
            &format!("integrator = \"{integrator}\""),
        )
        .replace("t_end = 20.0", &format!("t_end = {}", 0.2 * steps as f64));
    parse_model(&text, Path::new("spinning_beam.toml")).unwrap()
}

#[test]
fn the_first_row_is_the_models_initial_velocity_field() {
    let (v0, om) = ([0.5, -0.2, 0.3], [0.3, 0.2, 1.0]);
    for integrator in ["newmark", "momentum", "energy-momentum"] {
        let dir = tempfile::tempdir().unwrap();
        let summary = run_model(&spinning_beam(integrator, 3), dir.path()).unwrap();
        let x: Vec<f64> = read(&summary.file, "/configuration/position");
        let v: Vec<f64> = read(&summary.file, "/configuration/velocity");
        let w: Vec<f64> = read(&summary.file, "/configuration/angular_velocity");
        let nodes = 11;
        assert_eq!(v.len(), 4 * nodes * 3, "{integrator}: T x nodes x 3");
        assert_eq!(w.len(), v.len());
        for n in 0..nodes {
            let p = &x[3 * n..3 * n + 3];
            let cross = [
                om[1] * p[2] - om[2] * p[1],
                om[2] * p[0] - om[0] * p[2],
                om[0] * p[1] - om[1] * p[0],
            ];
            for c in 0..3 {
                assert!(
                    (v[3 * n + c] - (v0[c] + cross[c])).abs() < 1e-14,
                    "{integrator}"
                );
                assert!((w[3 * n + c] - om[c]).abs() < 1e-14, "{integrator}");
            }
        }
    }
}

#[test]
fn the_midpoint_schemes_velocities_average_to_the_position_increment() {
    // (xₙ₊₁ − xₙ)/Δt = ½(vₙ + vₙ₊₁) holds exactly in the midpoint schemes
    // (and in Newmark's trapezoidal rule): the stored velocities are the
    // scheme's, not a difference quotient of the stored positions.
    for integrator in ["newmark", "momentum", "energy-momentum"] {
        let dir = tempfile::tempdir().unwrap();
        let summary = run_model(&spinning_beam(integrator, 5), dir.path()).unwrap();
        let t: Vec<f64> = read(&summary.file, "/time");
        let x: Vec<f64> = read(&summary.file, "/configuration/position");
        let v: Vec<f64> = read(&summary.file, "/configuration/velocity");
        let row = 11 * 3;
        let mut worst = 0.0f64;
        for k in 1..t.len() {
            let dt = t[k] - t[k - 1];
            for i in 0..row {
                let (a, b) = (k * row + i, (k - 1) * row + i);
                let lhs = (x[a] - x[b]) / dt;
                worst = worst.max((lhs - 0.5 * (v[a] + v[b])).abs());
            }
        }
        // Positions of size 10 differenced over Δt = 0.2: round-off 1e-13.
        assert!(worst < 1e-12, "{integrator}: off by {worst:e}");
    }
}

#[test]
fn static_files_have_no_velocities() {
    let model = load_model(&data("statics/joint_kinds.toml")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let summary = run_model(&model, dir.path()).unwrap();
    let file = reader(&summary.file);
    assert!(file.has("/configuration/position"));
    assert!(!file.has("/configuration/velocity"));
    assert!(!file.has("/configuration/angular_velocity"));
}
