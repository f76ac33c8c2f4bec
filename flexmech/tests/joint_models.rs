//! The driven-joint models of `data/statics/` (screw, rack-and-pinion, cam,
//! lobe) through the same path as `flexmech run`: relation (1) and
//! `r_R = f(ψ)` hold to round-off at every stored step of several turns, the
//! driven angle follows its table, and the joint datasets are in the file.

use crate::common::read;
use flexmech::model::load_model;
use flexmech::results::run_model;
use std::path::{Path, PathBuf};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../data/statics")
        .join(name)
}

/// The joint histories of one run.
struct Run {
    t: Vec<f64>,
    angle: Vec<f64>,
    released: Vec<[f64; 3]>,
    error: Vec<f64>,
    file: PathBuf,
    _dir: tempfile::TempDir,
}

/// Runs a model and reads its joint datasets.
fn run(name: &str) -> Run {
    let model = load_model(&data(name)).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let file = run_model(&model, dir.path()).unwrap().file;
    Run {
        t: read(&file, "/time"),
        angle: read(&file, "/joints/drive/angle"),
        released: read(&file, "/joints/drive/released_translation")
            .chunks(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect(),
        error: read(&file, "/joints/drive/constraint_error"),
        file,
        _dir: dir,
    }
}

fn check(name: &str, turns: f64, f: impl Fn(f64) -> [f64; 3]) {
    let Run {
        t,
        angle,
        released: rr,
        error: err,
        file,
        _dir,
    } = run(name);
    assert!(t.len() >= 40, "{name}: {} steps", t.len());
    assert!((t.last().unwrap() - 1.0).abs() < 1e-12);
    let full = 2.0 * std::f64::consts::PI * turns;
    for k in 0..t.len() {
        // The driven angle follows its table exactly.
        assert!(
            (angle[k] - full * t[k]).abs() <= 1e-12 * full,
            "{name}: angle {} at t = {}",
            angle[k],
            t[k]
        );
        // r_R = f(ψ) to round-off (closed form of the paper's eqs 12 and 14).
        let expected = f(angle[k]);
        let d = (0..3)
            .map(|i| (rr[k][i] - expected[i]).abs())
            .fold(0.0, f64::max);
        assert!(
            d <= 1e-14 * (1.0 + full),
            "{name}: r_R {:?} vs f(ψ) {expected:?}",
            rr[k]
        );
        // Relation (1) to round-off.
        assert!(
            err[k] <= 1e-13,
            "{name}: constraint error {} at t = {}",
            err[k],
            t[k]
        );
    }
    // Every step converged: below the tolerance or at the round-off floor.
    let res = read(&file, "/solver/residual");
    assert!(res.iter().all(|r| *r <= 1e-8), "{name}: residuals {res:?}");
}

#[test]
fn driven_screw() {
    check("screw_driven.toml", 2.0, |p| [0.0, 0.0, 0.05 * p]);
}

#[test]
fn driven_rack_and_pinion() {
    // b (t_r × t) + b ψ t_r with t = y, t_r = x, b = 0.1: (bψ, 0, b).
    check("rack_pinion_driven.toml", 1.0, |p| [0.1 * p, 0.0, 0.1]);
}

#[test]
fn driven_cam() {
    check("cam_driven.toml", 2.0, |p| {
        [0.2 * p.cos() - 0.2 - 0.05, 0.0, 0.0]
    });
}

#[test]
fn driven_lobe() {
    check("lobe_driven.toml", 2.0, |p| {
        [-0.3 + 0.02 * p.sin() + 0.05 * (2.0 * p).cos(), 0.0, 0.0]
    });
}

#[test]
fn screw_arm_rises_by_pitch_times_angle() {
    // The arm's root rides up the post by c·ψ, less what the post's top
    // sinks: axial shortening 10·2/EA = 2e-5 and the shortening of its bent
    // shape under the arm's moment M = 10, ½∫θ² = M²L³/(6 EI²) = 1.33e-4, and
    // the tilt of the screw axis with the post's top (θ = ML/EI = 0.02 rad
    // takes cψ·θ²/2 ≤ 4.3e-5 off the rise): 2.0e-4 in all; allowed 1.5 times that.
    // And the arm turns with the joint: its tip's azimuth equals ψ up to the
    // post's twist (torque c·F = 0.5 over GJ/L = 400: 1.25e-3 rad).
    let Run {
        t,
        angle,
        file,
        _dir,
        ..
    } = run("screw_driven.toml");
    let root = read(&file, "/nodes/arm.start/position");
    let tip = read(&file, "/nodes/arm.end/position");
    let post = read(&file, "/nodes/post.end/position");
    for k in 0..t.len() {
        let rise = root[3 * k + 2] - 2.0;
        assert!(
            (rise - 0.05 * angle[k]).abs() <= 3e-4,
            "rise {rise} at ψ = {}",
            angle[k]
        );
        let (dx, dy) = (tip[3 * k] - post[3 * k], tip[3 * k + 1] - post[3 * k + 1]);
        let azimuth = dy.atan2(dx);
        let wrapped = (azimuth - angle[k] + std::f64::consts::PI)
            .rem_euclid(2.0 * std::f64::consts::PI)
            - std::f64::consts::PI;
        assert!(
            wrapped.abs() <= 5e-3,
            "azimuth {azimuth} vs ψ = {}",
            angle[k]
        );
    }
}

#[test]
fn slave_out_of_place_is_a_clear_error() {
    let text = std::fs::read_to_string(data("screw_driven.toml"))
        .unwrap()
        .replace(
            "start = [0.0, 0.0, 2.0]\nend = [1.0, 0.0, 2.0]",
            "start = [0.0, 0.0, 2.5]\nend = [1.0, 0.0, 2.5]",
        );
    let model = flexmech::model::parse_model(&text, Path::new("moved.toml")).unwrap();
    let err = flexmech::model::build(&model).unwrap_err().to_string();
    assert!(
        err.contains("moved.toml") && err.contains("joint[0].slave") && err.contains("drive"),
        "{err}"
    );
    assert!(
        err.contains("arm.start") && err.contains("post.end"),
        "{err}"
    );
}

#[test]
fn standard_joint_kinds_from_a_model_file() {
    let model = load_model(&data("joint_kinds.toml")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let file = run_model(&model, dir.path()).unwrap().file;
    for kind in ["rigid", "revolute", "spherical", "prismatic", "cylindrical"] {
        let err = read(&file, &format!("/joints/{kind}/constraint_error"));
        assert!(err.iter().all(|e| *e <= 1e-13), "{kind}: {err:?}");
    }
    // A rigid joint makes the pair one beam: same displacements as the
    // continuous beam of the same mesh under the same loads.
    let cont = read(&file, "/nodes/continuous.5/displacement");
    let rigid = read(&file, "/nodes/rigid_b.1/displacement");
    let scale = cont.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(
        cont.iter()
            .zip(&rigid)
            .all(|(a, b)| (a - b).abs() <= 1e-9 * scale),
        "{cont:?} vs {rigid:?}"
    );
    // Released coordinates open where they are released, and only there.
    let last = |d: &str, w: usize| read(&file, d).chunks(w).last().unwrap().to_vec();
    let prism = last("/joints/prismatic/released_translation", 3);
    assert!(
        prism[0].abs() > 1e-6 && prism[1] == 0.0 && prism[2] == 0.0,
        "{prism:?}"
    );
    let cyl = last("/joints/cylindrical/released_translation", 3);
    assert!(
        cyl[0].abs() > 1e-6 && cyl[1] == 0.0 && cyl[2] == 0.0,
        "{cyl:?}"
    );
    assert!(last("/joints/cylindrical/angle", 1)[0].abs() > 1e-6);
    assert!(last("/joints/revolute/angle", 1)[0].abs() > 1e-6);
    assert!(last("/joints/spherical/angle", 1)[0].abs() > 1e-6);
    assert_eq!(last("/joints/rigid/released_translation", 3), vec![0.0; 3]);
    // The hinge opens: master and slave rotate differently about y only.
    let ra = last("/nodes/revolute_a.end/rotation", 3);
    let rb = last("/nodes/revolute_b.start/rotation", 3);
    assert!((ra[1] - rb[1]).abs() > 1e-6, "{ra:?} {rb:?}");
}

#[test]
fn prescribed_end_rotation_rolls_the_strip_into_a_circle() {
    // Driving the end's rotation to 2π (end free to move) gives the same
    // circle as the end moment 2πEI/L: the tip returns to the clamp.
    let model = load_model(&data("rollup_prescribed.toml")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let file = run_model(&model, dir.path()).unwrap().file;
    let pos = read(&file, "/nodes/strip.end/position");
    let tip = &pos[pos.len() - 3..];
    let dist = (tip[0] * tip[0] + tip[1] * tip[1] + tip[2] * tip[2]).sqrt();
    assert!(dist <= 1e-8 * 10.0, "tip {tip:?}");
    let e = read(&file, "/energy/strain");
    let exact = 0.5 * 100.0 * (2.0 * std::f64::consts::PI / 10.0f64).powi(2) * 10.0;
    assert!((e.last().unwrap() - exact).abs() <= 1e-8 * exact);
}

#[test]
fn a_released_translation_that_is_not_finite_is_a_clear_error() {
    // A pitch of 1e308 at an initial angle of 10 rad puts the slave at
    // infinity; the comparison with the slave's position once let it pass.
    let text = std::fs::read_to_string(data("screw_driven.toml"))
        .unwrap()
        .replace("pitch = 0.05", "pitch = 1e308\nangle = 10.0");
    assert!(text.contains("pitch = 1e308"));
    let model = flexmech::model::parse_model(&text, Path::new("inf.toml")).unwrap();
    let err = flexmech::model::build(&model).unwrap_err().to_string();
    assert!(
        err.contains("inf.toml") && err.contains("joint[0]") && err.contains("not a finite"),
        "{err}"
    );
}

/// A cantilever (along x, clamped at the origin) whose tip carries a ball
/// joint on an arm `a = (0, 0.1, 0)`; the ball's slave is the top of a post
/// pinned at its foot (ux, uy, rz held), pulled down at the foot by `F`.
/// The ball passes the force at the arm's end: the cantilever's tip twists
/// by `φ = −a F L / GJ` and deflects by `−F L³ / 3EI` (linear theory; the
/// loads are small enough for it to hold to 1e-3).
const BALL_ON_ARM: &str = r#"
name = "ball-on-arm"
[[section]]
name = "s"
EA = 1.0e8
GA = [1.0e8, 1.0e8]
GJ = 100.0
EI = [1.0e4, 1.0e4]
[[beam]]
name = "cantilever"
section = "s"
start = [0.0, 0.0, 0.0]
end = [1.0, 0.0, 0.0]
e2 = [0.0, 1.0, 0.0]
elements = 4
nodes_per_element = 3
[[beam]]
name = "post"
section = "s"
start = [1.0, 0.1, 0.0]
end = [1.0, 0.1, -0.5]
e2 = [1.0, 0.0, 0.0]
elements = 2
[[support]]
node = "cantilever.start"
fixed = "all"
[[support]]
node = "post.end"
fixed = ["ux", "uy", "rz"]
[[joint]]
name = "ball"
type = "spherical"
master = "cantilever.end"
slave = "post.start"
arm = [0.0, 0.1, 0.0]
[[load]]
node = "post.end"
force = [0.0, 0.0, -1.0]
[solver]
analysis = "static"
load_steps = 1
[output]
track = ["cantilever.end"]
"#;

#[test]
fn a_ball_on_an_arm_passes_its_force_at_the_arm_s_end() {
    let model = flexmech::model::parse_model(BALL_ON_ARM, Path::new("arm.toml")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let file = run_model(&model, dir.path()).unwrap().file;
    let (f, a, l, gj, ei) = (1.0, 0.1, 1.0, 100.0, 1.0e4);
    let r = read(&file, "/nodes/cantilever.end/rotation");
    let twist = r[r.len() - 3];
    let expected = -a * f * l / gj;
    assert!(
        (twist - expected).abs() < 1e-3 * expected.abs(),
        "{twist} vs {expected}"
    );
    let u = read(&file, "/nodes/cantilever.end/displacement");
    let w = -f * l.powi(3) / (3.0 * ei);
    assert!(
        (u[u.len() - 1] - w).abs() < 1e-3 * w.abs(),
        "{} vs {w}",
        u[u.len() - 1]
    );
    // The slave starts at the master plus the arm; elsewhere it is refused.
    let moved = BALL_ON_ARM.replace("arm = [0.0, 0.1, 0.0]", "arm = [0.0, 0.2, 0.0]");
    let model = flexmech::model::parse_model(&moved, Path::new("arm.toml")).unwrap();
    let err = flexmech::model::build(&model).unwrap_err().to_string();
    assert!(
        err.contains("joint[0].slave") && err.contains("ball"),
        "{err}"
    );
    // Its fix is the arm that puts the ball where the slave is, not an angle
    // (a spherical joint has none).
    assert!(
        err.contains("`arm = [0.0, 0.1") && !err.contains("`angle`"),
        "{err}"
    );
}
