//! Joints to the ground (`master = "ground"`), against analytic rigid-body
//! motions, with every integrator: a compound pendulum on a tilted revolute
//! and a nut falling down a screw.

use std::path::{Path, PathBuf};

use flexmech::model::{parse_model, Model};
use flexmech::results::run_model_to;
use flexmech::results::ResultReader;

use crate::common::INTEGRATORS;

fn model(file: &str, integrator: &str) -> Model {
    let path: PathBuf = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../data/dynamics")
        .join(file);
    let text = std::fs::read_to_string(&path).unwrap().replace(
        "integrator = \"energy-momentum\"",
        &format!("integrator = \"{integrator}\""),
    );
    parse_model(&text, &path).unwrap()
}

fn run(model: &Model, dir: &Path) -> ResultReader {
    let file = dir.join(format!("{}.h5", model.name));
    let summary = run_model_to(model, &file).unwrap();
    assert!(summary.warnings.is_empty(), "{:?}", summary.warnings);
    ResultReader::open(&file).unwrap()
}

/// The period of the pendulum in `data/dynamics/ground_pendulum.toml` from
/// its joint angle's zero crossings: `2π √(2L / (3 g cos 5°))` to 1e-3
/// (the schemes' period error, (ΩΔt)²/12 ≈ 1.2e-4, and the model's
/// neglected effects, ≤ 1e-5, are below it).
#[test]
fn a_pendulum_hinged_to_the_ground_swings_with_the_compound_period() {
    let expected =
        2.0 * std::f64::consts::PI * (2.0 / (3.0 * 9.81 * 5f64.to_radians().cos())).sqrt();
    let dir = tempfile::tempdir().unwrap();
    for integrator in INTEGRATORS {
        let r = run(&model("ground_pendulum.toml", integrator), dir.path());
        let t = r.time().unwrap();
        let psi = r.values("/joints/hinge/angle").unwrap();
        let crossings: Vec<f64> = (1..t.len())
            .filter(|&k| psi[k - 1] * psi[k] < 0.0)
            .map(|k| t[k - 1] + (t[k] - t[k - 1]) * psi[k - 1] / (psi[k - 1] - psi[k]))
            .collect();
        assert!(crossings.len() >= 3, "{integrator}: {crossings:?}");
        let n = crossings.len() - 1;
        let period = 2.0 * (crossings[n] - crossings[0]) / n as f64;
        eprintln!(
            "{integrator}: period {period}, relative error {:.2e}",
            period / expected - 1.0
        );
        assert!(
            (period / expected - 1.0).abs() < 1e-3,
            "{integrator}: period {period} against {expected}"
        );
        // The ground node holds: its label and its reaction are reported.
        let labels = r.mesh_node_labels().unwrap();
        assert_eq!(labels.last().map(String::as_str), Some("ground.hinge"));
        assert!(r.has("/supports/ground.hinge/reaction_force"));
    }
}

/// The nut of `data/dynamics/ground_screw.toml` turns as
/// `ψ(t) = −½ g c/(c² + 1/3) t²` and descends by `c ψ`: to 1e-3 of the
/// final angle (second-order schemes, 100 steps of a rigid motion).
#[test]
fn a_nut_on_a_screw_to_the_ground_falls_as_the_rigid_body_does() {
    let (g, c) = (9.81, 0.1);
    let dir = tempfile::tempdir().unwrap();
    for integrator in INTEGRATORS {
        let r = run(&model("ground_screw.toml", integrator), dir.path());
        let t = *r.time().unwrap().last().unwrap();
        let psi = *r.values("/joints/thread/angle").unwrap().last().unwrap();
        let expected = -0.5 * g * c / (c * c + 1.0 / 3.0) * t * t;
        eprintln!(
            "{integrator}: ψ relative error {:.2e}",
            psi / expected - 1.0
        );
        assert!(
            (psi / expected - 1.0).abs() < 1e-3,
            "{integrator}: ψ({t}) = {psi} against {expected}"
        );
        // The nut's start stays on the thread, c ψ below the origin.
        let start = r.rows3("/nodes/nut.start/position").unwrap();
        let z = start.last().unwrap()[2];
        assert!(
            (z - c * psi).abs() < 1e-9,
            "{integrator}: z = {z}, c ψ = {}",
            c * psi
        );
    }
}

/// The ground is a master only; a joint to the ground is still placed by
/// relation (1), so a kind whose `f(ψ₀)` is not finite is refused.
#[test]
fn the_ground_is_refused_as_a_slave_naming_the_key() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/dynamics/ground_screw.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let swapped = text
        .replace("master = \"ground\"", "master = \"nut.start\"")
        .replace("slave = \"nut.start\"", "slave = \"ground\"");
    let e = parse_model(&swapped, &path).unwrap_err().to_string();
    assert!(
        e.contains("joint[0].slave") && e.contains("ground cannot be a slave"),
        "{e}"
    );
    // f(ψ₀) = c ψ₀ t overflows: refused when the joint is placed.
    let huge = text.replace("pitch = 0.1", "pitch = 1e308").replace(
        "slave = \"nut.start\"",
        "slave = \"nut.start\"\nangle = 10.0",
    );
    let m = parse_model(&huge, &path).unwrap();
    let e = flexmech::model::build(&m).unwrap_err().to_string();
    assert!(e.contains("joint[0]") && e.contains("not a finite"), "{e}");
}
