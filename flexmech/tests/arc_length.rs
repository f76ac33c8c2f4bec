//! `control = "arc-length"` in a model file: the snap-through truss of
//! `data/statics/snap_through_truss.toml` against its exact load–deflection
//! curve (see the file), and the keys' refusals.

use std::path::{Path, PathBuf};

use flexmech::model::parse_model;
use flexmech::results::run_model_to;
use flexmech::results::ResultReader;

const A: f64 = 1.0;
const H: f64 = 0.2;
const EA: f64 = 1e4;
const P_REF: f64 = 59.210352;

fn exact(w: f64) -> f64 {
    let l0 = (A * A + H * H).sqrt();
    let l = (A * A + (H - w) * (H - w)).sqrt();
    2.0 * EA * (l0 - l) / l0 * (H - w) / l
}

fn file() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/statics/snap_through_truss.toml")
}

#[test]
fn the_truss_snaps_through_on_its_exact_curve() {
    let path = file();
    let model = parse_model(&std::fs::read_to_string(&path).unwrap(), &path).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("t.h5");
    let summary = run_model_to(&model, &out).unwrap();
    // The falling branch is unstable under load: the run says so.
    assert!(
        summary.warnings.iter().any(|w| w.contains("unstable")),
        "{:?}",
        summary.warnings
    );
    let r = ResultReader::open(&out).unwrap();
    let lambda = r.time().unwrap();
    let x = r.values("/nodes/left.end/position").unwrap();
    let pivots = r.values("/solver/negative_pivots").unwrap();
    let p_max = (0..=100_000)
        .map(|k| exact(H * k as f64 / 100_000.0))
        .fold(0.0, f64::max);
    let mut bottom = 0.0f64;
    for k in 0..lambda.len() {
        let (w, p) = (H - x[3 * k + 1], lambda[k] * P_REF);
        assert!((p - exact(w)).abs() < 1e-6 * p_max, "w = {w}: P = {p}");
        bottom = bottom.min(p);
    }
    // The limit load: the largest load before the path first turns down.
    let rising = lambda.windows(2).take_while(|w| w[1] >= w[0]).count();
    let top = lambda[rising] * P_REF;
    assert!((top - p_max).abs() < 1e-3 * p_max, "limit {top} vs {p_max}");
    assert!(bottom < -0.99 * p_max, "minimum {bottom}");
    assert_eq!(*lambda.last().unwrap(), 1.0);
    assert!(H - x[x.len() - 2] > 2.0 * H, "ends on the inverted branch");
    assert!(
        pivots.iter().any(|&n| n >= 1.0),
        "no unstable step reported"
    );
}

#[test]
fn arc_length_keys_are_checked() {
    let text = std::fs::read_to_string(file()).unwrap();
    let err = |t: String| parse_model(&t, &file()).unwrap_err().to_string();
    let e = err(text.replace("control = \"arc-length\"", "control = \"arc\""));
    assert!(
        e.contains("solver.control") && e.contains("arc-length"),
        "{e}"
    );
    let e = err(text.replace("control = \"arc-length\"", "control = \"load\""));
    assert!(e.contains("solver.max_arc_steps"), "{e}");
    let dynamic = text
        .replace(
            "analysis = \"static\"",
            "analysis = \"dynamic\"\nintegrator = \"newmark\"\ndt = 0.1\nt_end = 1.0",
        )
        .replace(
            "load_steps = 10                      # the first step's load increment: 1/10\n",
            "",
        );
    let e = err(dynamic);
    assert!(
        e.contains("solver.") && e.contains("static analysis"),
        "{e}"
    );
}

#[test]
fn the_argyris_frame_leaves_its_plane_at_the_bifurcation() {
    // data/benchmarks/argyris_frame.toml with arc-length control and branch
    // switching, its load raised to 1.5 so the bifurcation lies inside the
    // path: the frame bends in its plane until lateral buckling at the
    // published P_cr = 1.088; there the critical mode (out of plane, the
    // load does no work on it) takes the path off the plane, onto the
    // stable post-buckled branch whose load stays at P_cr and then rises.
    // The path's budget (600 steps) ends the run before λ = 1 — refused
    // with the reason, the steps so far in the file.
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/benchmarks/argyris_frame.toml");
    let text = std::fs::read_to_string(&path)
        .unwrap()
        .replace(
            "analysis = \"static\"",
            "analysis = \"static\"\ncontrol = \"arc-length\"\nbranch_switch = true\nmax_arc_steps = 600",
        )
        .replace("load_steps = 220", "load_steps = 30")
        .replace("force = [0.0, 1.1, 0.0]", "force = [0.0, 1.5, 0.0]");
    let model = parse_model(&text, &path).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("a.h5");
    let Err(refused) = run_model_to(&model, &out) else {
        panic!("the budget ends the run");
    };
    assert!(refused.to_string().contains("600 steps"), "{refused}");
    let r = ResultReader::open(&out).unwrap();
    let lambda = r.time().unwrap();
    let x = r.values("/configuration/position").unwrap();
    let pivots = r.values("/solver/negative_pivots").unwrap();
    let nodes = x.len() / 3 / lambda.len();
    let lateral = |k: usize| {
        (0..nodes)
            .map(|n| x[3 * (k * nodes + n) + 2].abs())
            .fold(0.0, f64::max)
    };
    const PUBLISHED: f64 = 1.088;
    let p = |k: usize| lambda[k] * 1.5;
    let first_off = (0..lambda.len())
        .find(|&k| lateral(k) > 0.0)
        .expect("left the plane");
    // In the plane up to the bifurcation, which the count brackets.
    assert!(pivots[first_off - 1] >= 1.0 && pivots[first_off - 2] == 0.0);
    assert!(p(first_off - 2) < PUBLISHED && PUBLISHED < p(first_off - 1));
    // On the branch: the load at P_cr (within 0.5 %), stable, the lateral
    // displacement growing step by step to tens of millimetres.
    let branch = p(first_off);
    eprintln!(
        "branch at P = {branch:.5} ({:.2e} from {PUBLISHED}); {} steps, last P = {:.5}, lateral {:.2} mm",
        branch / PUBLISHED - 1.0,
        lambda.len(),
        p(lambda.len() - 1),
        lateral(lambda.len() - 1)
    );
    assert!(
        (branch / PUBLISHED - 1.0).abs() < 5e-3,
        "branch load {branch}"
    );
    for (k, &count) in pivots.iter().enumerate().skip(first_off) {
        assert_eq!(count, 0.0, "unstable at step {k}");
        assert!(
            p(k) >= branch * (1.0 - 1e-9),
            "the branch's load fell at step {k}"
        );
        if k > first_off {
            assert!(lateral(k) > lateral(k - 1), "step {k}");
        }
    }
    assert!(
        lateral(lambda.len() - 1) > 5.0,
        "{}",
        lateral(lambda.len() - 1)
    );
}
