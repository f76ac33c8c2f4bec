//! Reactions in result files, checked against the laws they must obey:
//! static equilibrium of the whole mechanism and of the part beyond a joint,
//! and the momentum scheme's discrete balance of linear momentum.

use flexmech::model::parse_model;
use flexmech::results::run_model;
use flexmech::results::ResultReader;
use nalgebra::Vector3;
use std::path::Path;

const FORCE: [f64; 3] = [0.3, -2.0, 1.0];
const MOMENT: [f64; 3] = [0.0, 0.2, 0.5];

/// Two beams welded by a rigid joint, clamped at one end, loaded at the
/// other by a dead force and a fixed-axis moment (large deflection).
fn welded_cantilever() -> String {
    format!(
        r#"
name = "welded"

[[section]]
name = "s"
EA = 1.0e4
GA = [5.0e3, 5.0e3]
GJ = 8.0
EI = [10.0, 10.0]
rhoA = 1.0
rhoJ = [0.02, 0.01, 0.01]

[[beam]]
name = "a"
section = "s"
start = [0.0, 0.0, 0.0]
end = [1.0, 0.0, 0.0]
e2 = [0.0, 1.0, 0.0]
elements = 6

[[beam]]
name = "b"
section = "s"
start = [1.0, 0.0, 0.0]
end = [2.0, 0.0, 0.0]
e2 = [0.0, 1.0, 0.0]
elements = 6

[[support]]
node = "a.start"
fixed = "all"

[[joint]]
name = "weld"
type = "rigid"
master = "a.end"
slave = "b.start"

[[load]]
node = "b.end"
force = {FORCE:?}
moment = {MOMENT:?}

[solver]
load_steps = 4
tolerance = 1e-12

[output]
track = ["a.start", "b.start", "b.end"]
"#
    )
}

fn v(rows: &[[f64; 3]], k: usize) -> Vector3<f64> {
    Vector3::from(rows[k])
}

#[test]
fn static_reactions_balance_the_loads() {
    let model = parse_model(&welded_cantilever(), Path::new("welded.toml")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let file = run_model(&model, dir.path()).unwrap().file;
    let r = ResultReader::open(&file).unwrap();
    let support_f = r.rows3("/supports/a.start/reaction_force").unwrap();
    let support_m = r.rows3("/supports/a.start/reaction_moment").unwrap();
    let joint_f = r.rows3("/joints/weld/reaction_force").unwrap();
    let joint_m = r.rows3("/joints/weld/reaction_moment").unwrap();
    let x_root = r.rows3("/nodes/a.start/position").unwrap();
    let x_slave = r.rows3("/nodes/b.start/position").unwrap();
    let x_tip = r.rows3("/nodes/b.end/position").unwrap();
    let lambda = r.time().unwrap();
    assert!(lambda[0] > 0.0, "statics stores the converged load steps");
    let (f, m) = (Vector3::from(FORCE), Vector3::from(MOMENT));
    // The Newton tolerance (1e-12 of the force scale) bounds the imbalance.
    let tol = 1e-8 * f.norm();
    let mut deflected = 0.0_f64;
    for (k, &l) in lambda.iter().enumerate() {
        let (fk, mk) = (f * l, m * l);
        deflected = deflected.max((v(&x_tip, k) - Vector3::new(2.0, 0.0, 0.0)).norm());
        // The whole mechanism: R + F = 0 and R_M + (x_tip − x_root) × F + M = 0.
        assert!((v(&support_f, k) + fk).norm() <= tol, "step {k}");
        let arm = v(&x_tip, k) - v(&x_root, k);
        assert!(
            (v(&support_m, k) + arm.cross(&fk) + mk).norm() <= tol,
            "step {k}"
        );
        // Beam b alone: the weld holds it against the same load.
        assert!((v(&joint_f, k) + fk).norm() <= tol, "step {k}");
        let arm = v(&x_tip, k) - v(&x_slave, k);
        assert!(
            (v(&joint_m, k) + arm.cross(&fk) + mk).norm() <= tol,
            "step {k}"
        );
    }
    assert!(deflected > 0.2, "a large deflection: {deflected}");
}

#[test]
fn the_momentum_scheme_balances_momentum_with_gravity_and_the_support() {
    // The paper's cam, driven, under gravity; the post is clamped at its
    // foot. The momentum scheme's steps satisfy
    // (p_{n+1} − p_n)/Δt = m g + R exactly (to the Newton tolerance).
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/paper/cam.toml");
    let text = std::fs::read_to_string(&path)
        .unwrap()
        .replace(
            "integrator = \"energy-momentum\"",
            "integrator = \"momentum\"",
        )
        .replace("t_end = 3.0", "t_end = 1.0");
    let model = parse_model(&text, &path).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let file = run_model(&model, dir.path()).unwrap().file;
    let r = ResultReader::open(&file).unwrap();
    let p = r.rows3("/momentum/linear").unwrap();
    let dt = r.values("/solver/dt").unwrap();
    let support = r.rows3("/supports/post.start/reaction_force").unwrap();
    // Two beams of 1 m at ρA = 1.
    let weight = Vector3::new(0.0, 0.0, -9.81) * 2.0;
    assert!(
        support[0].iter().all(|x| x.is_nan()),
        "no step before t = 0"
    );
    let mut largest = 0.0_f64;
    for (k, &h) in dt.iter().enumerate().skip(1) {
        let rate = (v(&p, k) - v(&p, k - 1)) / h;
        let imbalance = rate - weight - v(&support, k);
        assert!(
            imbalance.norm() <= 1e-6 * weight.norm(),
            "step {k}: {imbalance}"
        );
        largest = largest.max(rate.norm());
    }
    assert!(
        largest > 0.1 * weight.norm(),
        "the mechanism accelerates: {largest}"
    );
}
