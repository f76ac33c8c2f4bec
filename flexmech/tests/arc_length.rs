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
    // The limit loads, located by bisection between the bracketing steps:
    // p_max and, by the curve's odd symmetry about the flat position,
    // −p_max (the steps themselves grow where the path is smooth and need
    // not come near either).
    let located = r.values("/stability/critical_load_factor").unwrap();
    let kinds = r.strings("/stability/critical_kind").unwrap();
    assert_eq!(kinds, ["limit", "limit"]);
    for (l, sign) in located.iter().zip([1.0, -1.0]) {
        assert!(
            (l * P_REF - sign * p_max).abs() < 1e-6 * p_max,
            "limit {} vs {p_max}",
            l * P_REF
        );
    }
    assert!(bottom < 0.0, "minimum {bottom}");
    assert!(
        summary
            .to_string()
            .contains("critical point: limit at load factor 0.500000"),
        "{summary}"
    );
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

/// The Argyris frame of `data/benchmarks/argyris_frame.toml`, 40 elements a
/// leg, its load raised to `force`, with `analysis` for the file's
/// `analysis = "static"` and `load_steps`.
fn argyris(force: f64, analysis: &str) -> flexmech::model::Model {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/benchmarks/argyris_frame.toml");
    let text = std::fs::read_to_string(&path)
        .unwrap()
        .replace("analysis = \"static\"", analysis)
        .replace("load_steps = 220", "")
        .replace("elements = 10", "elements = 40")
        .replace(
            "force = [0.0, 1.1, 0.0]",
            &format!("force = [0.0, {force:?}, 0.0]"),
        );
    parse_model(&text, &path).unwrap()
}

/// The published lateral buckling load of the frame.
const P_CR: f64 = 1.088;

#[test]
fn the_argyris_frame_buckles_at_the_located_bifurcation_and_follows_its_branch() {
    // The frame bends in its plane until lateral buckling at the published
    // P_cr = 1.088; the count brackets it, bisection locates it, and the
    // critical mode (out of plane: the load does no work on it) takes the
    // path off the plane onto the stable post-buckled branch, followed until
    // the tip has moved sideways by a quarter of the leg (60).
    const FORCE: f64 = 1.5;
    let model = argyris(
        FORCE,
        "analysis = \"static\"\ncontrol = \"arc-length\"\nbranch_switch = true\nload_steps = 60\n\
         max_arc_steps = 500\nstop = { displacement = { node = \"b.end\", max = 100.0 } }",
    );
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("a.h5");
    let summary = run_model_to(&model, &out).unwrap();
    let r = ResultReader::open(&out).unwrap();
    assert_eq!(r.status().unwrap(), "completed");
    let reason = r.string_attr("end_reason").unwrap();
    assert!(
        reason.contains("b.end") && reason.contains("displacement"),
        "{reason}"
    );
    // Located: one bifurcation, within 0.5 % of the published load, and
    // within its bracket of the linearised buckling analysis of the same mesh.
    let located = r.values("/stability/critical_load_factor").unwrap();
    let kinds = r.strings("/stability/critical_kind").unwrap();
    eprintln!(
        "located {located:?} {kinds:?}; {}",
        summary.end_reason.as_deref().unwrap_or("")
    );
    assert_eq!(kinds.first().map(String::as_str), Some("bifurcation"));
    let p_located = located[0] * FORCE;
    assert!((p_located / P_CR - 1.0).abs() < 5e-3, "located {p_located}");
    let lambda = r.time().unwrap();
    let x = r.values("/nodes/b.end/position").unwrap();
    let steps = lambda.len();
    let lateral = |k: usize| x[3 * k + 2].abs();
    eprintln!(
        "{steps} steps, last P = {:.5}, tip lateral {:.2}",
        lambda[steps - 1] * FORCE,
        lateral(steps - 1)
    );
    assert!(steps <= 500, "{steps} steps");
    assert!(
        lateral(steps - 1) >= 60.0,
        "tip lateral {}",
        lateral(steps - 1)
    );
    // On the branch: stable (no negative eigenvalue), the load at or above
    // the bifurcation's, the lateral deflection growing step by step.
    let pivots = r.values("/solver/negative_pivots").unwrap();
    let first_off = (0..steps)
        .find(|&k| lateral(k) > 0.0)
        .expect("left the plane");
    for k in first_off..steps {
        assert_eq!(pivots[k], 0.0, "unstable at step {k}");
        assert!(
            lambda[k] * FORCE >= p_located * (1.0 - 1e-6),
            "the branch's load fell at step {k}"
        );
        if k > first_off {
            assert!(lateral(k) > lateral(k - 1), "step {k}");
        }
    }
    // The linearised buckling analysis of the same mesh (its loads, the
    // lowest λ): the located point differs from it by the prebuckling
    // nonlinearity only — the in-plane deflection at P_cr is small — here
    // 0.3 % at most.
    let buckling = argyris(FORCE, "analysis = \"buckling\"\nmodes = 1");
    let linear = run_model_to(&buckling, &dir.path().join("b.h5")).unwrap();
    let p_linear = ResultReader::open(&linear.file)
        .unwrap()
        .values("/buckling/load_factor")
        .unwrap()[0]
        * FORCE;
    eprintln!("linearised buckling load {p_linear:.5}, located {p_located:.5}");
    assert!(
        (p_located / p_linear - 1.0).abs() < 3e-3,
        "{p_located} vs {p_linear}"
    );
    // The summary line names the point.
    assert!(summary.to_string().contains("bifurcation"), "{summary}");
}

/// The truss file with `old` replaced by `new`, parsed.
fn truss_with(old: &str, new: &str) -> Result<flexmech::model::Model, String> {
    let text = std::fs::read_to_string(file()).unwrap();
    assert!(text.contains(old), "{old}");
    parse_model(&text.replace(old, new), &file()).map_err(|e| e.to_string())
}

const BUDGET_LINE: &str =
    "max_arc_steps = 400                  # optional; default 100 x load_steps";

#[test]
fn a_path_ends_at_its_budget_or_its_stop_as_completed() {
    let dir = tempfile::tempdir().unwrap();
    let run = |model: flexmech::model::Model, name: &str| {
        let out = dir.path().join(name);
        let summary = run_model_to(&model, &out).unwrap();
        let r = ResultReader::open(&out).unwrap();
        assert_eq!(r.status().unwrap(), "completed");
        let reason = r.string_attr("end_reason").unwrap();
        assert_eq!(summary.end_reason.as_deref(), Some(reason.as_str()));
        (
            r.time().unwrap(),
            r.values("/nodes/left.end/displacement").unwrap(),
            reason,
        )
    };
    // The budget: three steps, the path short of λ = 1, completed.
    let (lambda, _, reason) = run(
        truss_with(BUDGET_LINE, "max_arc_steps = 3").unwrap(),
        "b.h5",
    );
    assert_eq!(lambda.len(), 3);
    assert!(lambda[2] < 0.5, "{lambda:?}");
    assert!(
        reason.contains("3 steps") && reason.contains("max_arc_steps"),
        "{reason}"
    );
    // A load factor: the path ends exactly there, the first time it reaches it.
    let (lambda, _, reason) = run(
        truss_with(BUDGET_LINE, "stop = { load_factor = 0.25 }").unwrap(),
        "l.h5",
    );
    assert_eq!(*lambda.last().unwrap(), 0.25);
    assert!(lambda[..lambda.len() - 1].iter().all(|&l| l < 0.25));
    assert!(reason.contains("reached load factor 0.25"), "{reason}");
    // A displacement: after the first step at which |u| of the apex
    // reaches 0.3 (on the falling branch, past the limit point).
    let (lambda, u, reason) = run(
        truss_with(
            BUDGET_LINE,
            "stop = { displacement = { node = \"left.end\", max = 0.3 } }",
        )
        .unwrap(),
        "d.h5",
    );
    let norm = |k: usize| (u[3 * k].powi(2) + u[3 * k + 1].powi(2) + u[3 * k + 2].powi(2)).sqrt();
    let last = lambda.len() - 1;
    assert!(
        norm(last) >= 0.3 && norm(last - 1) < 0.3,
        "{} {}",
        norm(last - 1),
        norm(last)
    );
    assert!(lambda[last] < 0.5 && lambda[last] > -0.5, "{lambda:?}");
    assert!(
        reason.contains("left.end") && reason.contains("solver.stop.displacement"),
        "{reason}"
    );
}

#[test]
fn stop_keys_are_checked() {
    let cases = [
        ("stop = { load_factor = -1.0 }", "solver.stop.load_factor"),
        ("stop = { load_factor = 0.5, at = 2 }", "at"),
        (
            "stop = { displacement = { node = \"left.middle\", max = 0.1 } }",
            "left.middle",
        ),
        (
            "stop = { displacement = { node = \"left.end\" } }",
            "solver.stop.displacement.max",
        ),
        (
            "stop = { displacement = { node = \"left.end\", max = 0.0 } }",
            "solver.stop.displacement.max",
        ),
    ];
    for (line, key) in cases {
        let e = truss_with(BUDGET_LINE, line).unwrap_err();
        assert!(
            e.contains(key) && e.contains("snap_through_truss.toml"),
            "{line}: {e}"
        );
    }
    // Load control ends at load factor 1: `stop` belongs to arc-length.
    let text = std::fs::read_to_string(file())
        .unwrap()
        .replace("control = \"arc-length\"", "control = \"load\"")
        .replace(BUDGET_LINE, "stop = { load_factor = 0.5 }");
    let e = parse_model(&text, &file()).unwrap_err().to_string();
    assert!(
        e.contains("solver.stop") && e.contains("control = \"arc-length\""),
        "{e}"
    );
}

#[test]
fn a_study_reads_the_located_limit_point_of_each_run() {
    // The truss's load–deflection curve scales with EA, so its limit load
    // does: with the file's reference load (2 P_max at EA = 1e4) the limit
    // point is at λ = EA/2e4. Runs whose budget ends the path before it
    // complete with NaN for the point (and NaN failure_time).
    let dir = tempfile::tempdir().unwrap();
    let study = dir.path().join("limit.toml");
    std::fs::write(
        &study,
        format!(
            "name = \"limit\"\nmodel = \"{}\"\n[grid]\n\"section.bar.EA\" = [1.0e4, 1.5e4]\n\
             \"solver.max_arc_steps\" = [2, 400]\n[output]\nfigures = [\"failure_time\", \
             {{ name = \"limit\", dataset = \"/stability/critical_load_factor\", mode = 1 }}]\n",
            file().display()
        ),
    )
    .unwrap();
    let spec = flexmech::studies::load_study(&study).unwrap();
    let options = flexmech::studies::StudyOptions {
        out: dir.path().join("out"),
        shard: None,
        progress: false,
    };
    let report = flexmech::studies::run_study(&spec, &options).unwrap();
    assert_eq!((report.runs, report.failed), (4, 0));
    let mut csv = csv::Reader::from_path(&report.csv).unwrap();
    let header: Vec<String> = csv.headers().unwrap().iter().map(str::to_owned).collect();
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    let p_max = (0..=100_000)
        .map(|k| exact(H * k as f64 / 100_000.0))
        .fold(0.0, f64::max);
    for row in csv.records() {
        let row = row.unwrap();
        let value = |name: &str| row[col(name)].parse::<f64>().unwrap();
        assert_eq!(&row[col("status")], "completed");
        assert!(value("failure_time").is_nan());
        let (ea, budget) = (value("section.bar.EA"), value("solver.max_arc_steps"));
        if budget == 2.0 {
            assert!(value("limit").is_nan(), "{row:?}");
        } else {
            let expected = p_max * ea / EA / P_REF;
            assert!(
                (value("limit") - expected).abs() < 1e-6 * expected,
                "{row:?} vs {expected}"
            );
        }
    }
}
