//! The example against the cam's geometry written out here, not the kind's
//! code: at every stored step the released translation is the ellipse's
//! rim, and the slave sits where relation (1) puts it.

use super::*;
use nalgebra::Rotation3;

/// Semi-axes of `data/examples/ellipse_cam.toml`.
const A: f64 = 0.02;
const B: f64 = 0.04;
/// Newton stops at 1e-10 of the force scale; the joint relation itself is
/// exact to round-off in positions of size 1.
const ROUND_OFF: f64 = 1e-12;

fn rim(psi: f64) -> f64 {
    A * B / ((B * psi.cos()).powi(2) + (A * psi.sin()).powi(2)).sqrt()
}

#[test]
fn the_follower_rides_the_ellipse_and_obeys_relation_1() {
    let out = tempfile::tempdir().unwrap();
    let summary = run(out.path()).unwrap();
    assert!(summary.warnings.is_empty(), "{:?}", summary.warnings);
    let file = ResultReader::open(&summary.file).unwrap();
    assert_eq!(file.status().unwrap(), "completed");
    let time = file.time().unwrap();
    let psi = file.values("/joints/cam/angle").unwrap();
    let released = file.rows3("/joints/cam/released_translation").unwrap();
    let slave = file.rows3("/nodes/arm.start/position").unwrap();
    let master = file.rows3("/nodes/post.end/position").unwrap();
    let turn = file.rows3("/nodes/post.end/rotation").unwrap();
    assert_eq!(time.len(), 101);
    for k in 0..time.len() {
        let expected = Vector3::new(-rim(psi[k]), 0.0, 0.0);
        let r = Vector3::from(released[k]);
        assert!((r - expected).norm() <= ROUND_OFF, "step {k}: {r:?}");
        let placed = Vector3::from(master[k]) + Rotation3::new(Vector3::from(turn[k])) * r;
        let gap = (Vector3::from(slave[k]) - placed).norm();
        assert!(gap <= ROUND_OFF, "step {k}: gap {gap:e}");
    }
    // Half-way, ψ = π/2: the follower is at the end of the b semi-axis.
    let half = time.iter().position(|&t| (t - 0.5).abs() < 1e-9).unwrap();
    assert!((psi[half] - std::f64::consts::FRAC_PI_2).abs() <= 1e-12);
    assert!((released[half][0] + B).abs() <= ROUND_OFF);
}

#[test]
fn the_same_cam_written_as_an_expression_joint_runs_alike() {
    // data/examples/expression_cam.toml: f(ψ) in the file, no Rust. The
    // expression evaluates the rim with other operations than the Rust
    // kind (a power for a product), so the runs agree to round-off of the
    // positions, not bit for bit.
    let rust = App::new()
        .joint::<EllipseCam>()
        .load(flexmech::data("examples/ellipse_cam.toml"))
        .unwrap();
    let expression = load_model(&flexmech::data("examples/expression_cam.toml")).unwrap();
    let (mut a, mut b) = (Memory::default(), Memory::default());
    flexmech::results::run(&rust, &mut a).unwrap();
    flexmech::results::run(&expression, &mut b).unwrap();
    assert_eq!(b.status(), "completed");
    for label in ["arm.start", "arm.end"] {
        let (pa, pb) = (a.positions(label).unwrap(), b.positions(label).unwrap());
        assert_eq!(pa.len(), 101);
        for (x, y) in pa.iter().zip(&pb) {
            let gap = (Vector3::from(*x) - Vector3::from(*y)).norm();
            assert!(gap <= ROUND_OFF, "{label}: {gap:e}");
        }
    }
    // Its study sweeps the parameter by key: every follower ends at −b.
    let out = tempfile::tempdir().unwrap();
    let report = App::new()
        .load_study(flexmech::data("examples/expression_cam_study.toml"))
        .unwrap()
        .run(out.path())
        .unwrap();
    let csv = std::fs::read_to_string(out.path().join("expression-cam/summary.csv")).unwrap();
    assert_eq!(report.study_runs().unwrap().len(), 3);
    for (line, b) in csv.lines().skip(1).zip([0.02, 0.03, 0.04]) {
        let x: f64 = line.rsplit(',').next().unwrap().parse().unwrap();
        assert!((x + b).abs() <= ROUND_OFF, "{line}");
    }
}
