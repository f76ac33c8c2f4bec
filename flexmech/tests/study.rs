//! `flexmech study`: parameter sweeps over a model file, run whole or in
//! shards and merged, with their summary files and their errors.

use crate::common::{read, read_counts, read_strings, reader, string_attr};
use flexmech::joints::Screw;
use flexmech::studies::merge::MergeError;
use flexmech::studies::{
    load_study, merge_study, parse_study, run_study, select_shard, Shard, ShardError, SlurmArray,
    StudyError, StudyOptions, StudyReport, StudySpec,
};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

fn data(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../data")
        .join(rel)
}

/// A 2×2 grid over the spinning free beam, two or four steps per run.
fn small_study_text() -> String {
    format!(
        r#"name = "small"
model = "{}"

[grid]
"solver.dt" = [0.2, 0.1]
"solver.integrator" = ["newmark", "energy-momentum"]
"solver.t_end" = [0.4]
"#,
        data("dynamics/spinning_beam.toml").display()
    )
}

/// A fresh directory below cargo's scratch space for integration tests.
fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("study-tests")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn small_spec(dir: &Path) -> StudySpec {
    let file = dir.join("small.toml");
    std::fs::write(&file, small_study_text()).unwrap();
    load_study(&file).unwrap()
}

fn options(out: &Path, shard: Option<Shard>) -> StudyOptions {
    StudyOptions {
        out: out.to_path_buf(),
        shard,
        progress: false,
    }
}

/// The small study run unsharded (once for all tests).
fn unsharded() -> &'static (StudySpec, StudyReport) {
    static RUN: OnceLock<(StudySpec, StudyReport)> = OnceLock::new();
    RUN.get_or_init(|| {
        let dir = scratch("unsharded");
        let spec = small_spec(&dir);
        let report = run_study(&spec, &options(&dir.join("out"), None)).unwrap();
        (spec, report)
    })
}

/// The small study run as shards 1/2 and 2/2 (once for all tests; not merged).
fn sharded() -> &'static (StudySpec, PathBuf, Vec<StudyReport>) {
    static RUN: OnceLock<(StudySpec, PathBuf, Vec<StudyReport>)> = OnceLock::new();
    RUN.get_or_init(|| {
        let dir = scratch("sharded");
        let spec = small_spec(&dir);
        let out = dir.join("out");
        let reports = (1..=2)
            .map(|k| run_study(&spec, &options(&out, Some(Shard::new(k, 2).unwrap()))).unwrap())
            .collect();
        (spec, out, reports)
    })
}

fn csv_rows(file: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let mut r = csv::Reader::from_path(file).unwrap();
    let header = r.headers().unwrap().iter().map(str::to_owned).collect();
    let rows = r
        .records()
        .map(|rec| rec.unwrap().iter().map(str::to_owned).collect())
        .collect();
    (header, rows)
}

fn column(header: &[String], name: &str) -> usize {
    header.iter().position(|h| h == name).unwrap()
}

#[test]
fn runs_follow_grid_order_with_the_last_key_fastest() {
    let (spec, report) = unsharded();
    assert_eq!((report.runs, report.failed), (4, 0));
    let (header, rows) = csv_rows(&report.csv);
    assert_eq!(
        header,
        [
            "run",
            "solver.dt",
            "solver.integrator",
            "solver.t_end",
            "status",
            "energy_drift",
            "max_displacement",
            "failure_time",
            "wall_time",
            "newton_iterations"
        ]
    );
    let firsts: Vec<[&str; 4]> = rows
        .iter()
        .map(|r| [r[0].as_str(), r[1].as_str(), r[2].as_str(), r[3].as_str()])
        .collect();
    assert_eq!(
        firsts,
        [
            ["run-0000", "0.2", "newmark", "0.4"],
            ["run-0001", "0.2", "energy-momentum", "0.4"],
            ["run-0002", "0.1", "newmark", "0.4"],
            ["run-0003", "0.1", "energy-momentum", "0.4"],
        ]
    );
    // Each run's result file really holds its values.
    for r in &rows {
        let file = report.dir.join("runs").join(format!("{}.h5", r[0]));
        assert_eq!(string_attr(&file, "integrator"), r[2]);
        let dt = read(&file, "/solver/dt");
        let want: f64 = r[1].parse().unwrap();
        assert!(dt[1..].iter().all(|&d| (d - want).abs() < 1e-12), "{dt:?}");
        let t = read(&file, "/time");
        assert!((t.last().unwrap() - 0.4).abs() < 1e-12, "{t:?}");
    }
    assert_eq!(spec.grid.len(), 3);
}

#[test]
fn figures_are_read_from_the_run_files() {
    let (_, report) = unsharded();
    let (header, rows) = csv_rows(&report.csv);
    for r in &rows {
        let file = report.dir.join("runs").join(format!("{}.h5", r[0]));
        let num = |name: &str| r[column(&header, name)].parse::<f64>().unwrap();
        assert_eq!(r[column(&header, "status")], "completed");

        // Newton iterations: the sum of the per-step counts.
        let its = read_counts(&file, "/solver/iterations");
        assert_eq!(num("newton_iterations"), its.iter().sum::<u64>() as f64);
        assert!(num("newton_iterations") > 0.0);

        // Energy drift relative to the energy the run starts with or is
        // given by its drivers (the model starts in motion: E(0) > 0).
        let e = read(&file, "/energy/total");
        let w = read(&file, "/energy/driver_work");
        let k = read(&file, "/energy/kinetic");
        let u = read(&file, "/energy/strain");
        let c: Vec<f64> = e.iter().zip(&w).map(|(e, w)| e - w).collect();
        let worst = c.iter().map(|v| (v - c[0]).abs()).fold(0.0, f64::max);
        let scale = w
            .iter()
            .map(|v| v.abs())
            .fold(e[0].abs().max(k[0] + u[0]), f64::max);
        assert!(scale > 0.0);
        let drift = num("energy_drift");
        assert!(
            (drift - worst / scale).abs() <= 1e-15 * (1.0 + drift),
            "{drift}"
        );
        if r[column(&header, "solver.integrator")] == "energy-momentum" {
            assert!(drift < 1e-9, "energy-momentum drift {drift}");
        }

        // Largest displacement of the three tracked nodes.
        let mut largest = 0.0f64;
        for label in ["rod.start", "rod.end", "rod.5"] {
            let d = read(&file, &format!("/nodes/{label}/displacement"));
            for p in d.chunks(3) {
                largest = largest.max((p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt());
            }
        }
        assert!(largest > 0.0);
        assert_eq!(num("max_displacement"), largest);

        assert!(num("failure_time").is_nan());
        let wall = reader(&file).f64_attr("wall_time_s").unwrap();
        assert_eq!(num("wall_time"), wall);
    }
}

#[test]
fn summary_h5_has_one_dataset_per_column() {
    let (spec, report) = unsharded();
    let (header, rows) = csv_rows(&report.csv);
    let h5 = reader(&report.h5);
    assert_eq!(string_attr(&report.h5, "study"), spec.text);
    let columns = h5.string_list_attr("columns").unwrap();
    assert_eq!(columns, header);
    for (j, name) in header.iter().enumerate() {
        assert_eq!(h5.shape(name).unwrap(), [rows.len()], "{name}");
        if ["run", "solver.integrator", "status"].contains(&name.as_str()) {
            let got = read_strings(&report.h5, name);
            let want: Vec<&str> = rows.iter().map(|r| r[j].as_str()).collect();
            assert_eq!(got, want);
        } else {
            let got = read(&report.h5, name);
            for (g, r) in got.iter().zip(&rows) {
                let want: f64 = r[j].parse().unwrap();
                assert!(g.to_bits() == want.to_bits() || (g.is_nan() && want.is_nan()));
            }
        }
    }
    // Charts of every figure with a finite value (failure_time has none).
    let charts: Vec<String> = report
        .charts
        .iter()
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    for figure in [
        "energy_drift",
        "max_displacement",
        "wall_time",
        "newton_iterations",
    ] {
        assert!(charts.contains(&format!("{figure}.png")), "{charts:?}");
        assert!(charts.contains(&format!("{figure}.svg")), "{charts:?}");
        assert!(report
            .dir
            .join("charts")
            .join(format!("{figure}.png"))
            .is_file());
    }
    assert!(!charts.iter().any(|c| c.starts_with("failure_time")));
}

#[test]
fn shards_then_merge_give_the_unsharded_summary() {
    let (_, whole) = unsharded();
    let (spec, out, shards) = sharded();
    let dir = out.join("small");

    // Shard K of 2 takes runs K-1, K+1, … and writes its own summary.
    for (k, report) in shards.iter().enumerate() {
        let k = k + 1;
        assert_eq!(report.csv, dir.join(format!("summary-shard-{k}-of-2.csv")));
        assert!(report.h5.is_file() && report.charts.is_empty());
        let (_, rows) = csv_rows(&report.csv);
        let ids: Vec<&str> = rows.iter().map(|r| r[0].as_str()).collect();
        let want = if k == 1 {
            ["run-0000", "run-0002"]
        } else {
            ["run-0001", "run-0003"]
        };
        assert_eq!(ids, want);
        assert_eq!(string_attr(&report.h5, "shard"), format!("{k}/2"));
    }
    assert!(!dir.join("summary.csv").exists());

    let merged = merge_study(spec, out).unwrap();
    assert_eq!(merged.csv, dir.join("summary.csv"));
    assert_eq!((merged.runs, merged.failed), (4, 0));
    let (h1, mut r1) = csv_rows(&whole.csv);
    let (h2, mut r2) = csv_rows(&merged.csv);
    assert_eq!(h1, h2);
    let wall = column(&h1, "wall_time");
    for r in r1.iter_mut().chain(r2.iter_mut()) {
        r.remove(wall);
    }
    assert_eq!(r1, r2);
    assert_eq!(
        read_strings(&merged.h5, "run"),
        ["run-0000", "run-0001", "run-0002", "run-0003"]
    );
    let mut a = whole.charts.clone();
    let mut b = merged.charts.clone();
    for p in a.iter_mut().chain(b.iter_mut()) {
        *p = PathBuf::from(p.file_name().unwrap());
    }
    assert_eq!(a, b);
}

/// Copies the shard CSVs `which` of the sharded fixture into a new output
/// directory and merges there.
fn merge_copies(name: &str, which: &[(&str, &str)]) -> StudyError {
    let (spec, out, _) = sharded();
    let dest = scratch(name);
    std::fs::create_dir_all(dest.join("small")).unwrap();
    for (from, to) in which {
        std::fs::copy(out.join("small").join(from), dest.join("small").join(to)).unwrap();
    }
    merge_study(spec, &dest).unwrap_err()
}

#[test]
fn merge_refuses_incomplete_or_inconsistent_shards() {
    let s1 = "summary-shard-1-of-2.csv";
    let s2 = "summary-shard-2-of-2.csv";

    let e = merge_copies("merge-none", &[]);
    assert!(
        matches!(e, StudyError::Merge(MergeError::NoShards { .. })),
        "{e}"
    );
    assert!(e.to_string().contains("--shard K/N"), "{e}");

    let e = merge_copies("merge-missing", &[(s1, s1)]);
    match &e {
        StudyError::Merge(MergeError::MissingShards { missing, .. }) => {
            assert_eq!(missing, &[Shard::new(2, 2).unwrap()]);
        }
        other => panic!("{other}"),
    }
    assert!(e.to_string().contains("summary-shard-2-of-2.csv"), "{e}");
    assert!(e.to_string().contains("--shard 2/2"), "{e}");

    let e = merge_copies(
        "merge-mixed",
        &[(s1, s1), (s2, s2), (s1, "summary-shard-1-of-3.csv")],
    );
    assert!(
        matches!(e, StudyError::Merge(MergeError::MixedCounts { .. })),
        "{e}"
    );
    assert!(e.to_string().contains("summary-shard-1-of-3.csv"), "{e}");

    // Shard 1's rows twice: a duplicate run.
    let e = merge_copies("merge-duplicate", &[(s1, s1), (s1, s2)]);
    match &e {
        StudyError::Merge(MergeError::DuplicateRun { run, .. }) => assert_eq!(run, "run-0000"),
        other => panic!("{other}"),
    }

    // A shard file with a row removed: a missing run.
    let (spec, out, _) = sharded();
    let dest = scratch("merge-lost-row");
    std::fs::create_dir_all(dest.join("small")).unwrap();
    std::fs::copy(out.join("small").join(s1), dest.join("small").join(s1)).unwrap();
    let text = std::fs::read_to_string(out.join("small").join(s2)).unwrap();
    let kept: Vec<&str> = text
        .lines()
        .filter(|l| !l.starts_with("run-0003"))
        .collect();
    std::fs::write(dest.join("small").join(s2), kept.join("\n") + "\n").unwrap();
    let e = merge_study(spec, &dest).unwrap_err();
    match &e {
        StudyError::Merge(MergeError::MissingRuns { runs, .. }) => assert_eq!(runs, &["run-0003"]),
        other => panic!("{other}"),
    }
}

#[test]
fn a_failed_solve_is_a_failed_row_not_an_error() {
    let dir = scratch("failing");
    let file = dir.join("failing.toml");
    // One Newton iteration cannot reach the tolerance and no halving is
    // allowed: the first step fails. Thirty iterations are plenty.
    std::fs::write(
        &file,
        format!(
            r#"name = "failing"
model = "{}"
[grid]
"solver.max_iterations" = [1, 30]
"solver.max_halvings" = [0]
"solver.t_end" = [0.4]
[output]
figures = ["failure_time", "newton_iterations"]
"#,
            data("dynamics/spinning_beam.toml").display()
        ),
    )
    .unwrap();
    let spec = load_study(&file).unwrap();
    let report = run_study(&spec, &options(&dir.join("out"), None)).unwrap();
    assert_eq!((report.runs, report.failed), (2, 1));
    let (header, rows) = csv_rows(&report.csv);
    let status = column(&header, "status");
    let failure = column(&header, "failure_time");
    assert!(rows[0][status].starts_with("failed: "), "{:?}", rows[0]);
    assert_eq!(rows[1][status], "completed");
    // The failed run's file is valid and ends at its last converged time.
    let run0 = report.dir.join("runs/run-0000.h5");
    let t = read(&run0, "/time");
    assert_eq!(rows[0][failure].parse::<f64>().unwrap(), *t.last().unwrap());
    assert!(rows[1][failure].parse::<f64>().unwrap().is_nan());
    assert_eq!(string_attr(&run0, "status"), rows[0][status]);
    // A chart for failure_time now exists: one run failed.
    assert!(report.dir.join("charts/failure_time.png").is_file());
}

fn study_error(name: &str, body: &str) -> String {
    let dir = scratch(name);
    let file = dir.join("bad.toml");
    let text = format!(
        "name = \"bad\"\nmodel = \"{}\"\n{body}",
        data("dynamics/free_chain.toml").display()
    );
    std::fs::write(&file, &text).unwrap();
    let e = parse_study(&text, &file).unwrap_err().to_string();
    assert!(
        e.contains("bad.toml"),
        "the message names the study file: {e}"
    );
    e
}

#[test]
fn a_grid_key_missing_from_the_model_is_an_error_naming_it() {
    let e = study_error("key-joint", "[grid]\n\"joint.scew.pitch\" = [0.1]\n");
    assert!(e.contains("`joint.scew.pitch`"), "{e}");
    assert!(
        e.contains("\"screw\"") && e.contains("\"lobe\""),
        "lists the joints: {e}"
    );
    assert!(e.contains("bad.toml:4:"), "names the line: {e}");

    let e = study_error("key-solver", "[grid]\n\"solver.dtt\" = [0.1]\n");
    assert!(e.contains("`solver.dtt`") && e.contains("dt, "), "{e}");

    let e = study_error("key-index", "[grid]\n\"beam[12].elements\" = [4]\n");
    assert!(
        e.contains("`beam[12].elements`") && e.contains("10 entries"),
        "{e}"
    );

    let e = study_error("key-optional", "[grid]\n\"output.every\" = [2]\n");
    assert!(e.contains("`output.every`") && e.contains("track"), "{e}");

    let e = study_error("key-table", "[grid]\n\"solver\" = [1]\n");
    assert!(e.contains("single value"), "{e}");

    let e = study_error("key-syntax", "[grid]\n\"joint[x].pitch\" = [1]\n");
    assert!(
        e.contains("`joint[x].pitch`") && e.contains("whole number"),
        "{e}"
    );

    // By index and by name both reach the screw.
    let dir = scratch("key-ok");
    let file = dir.join("ok.toml");
    let text = format!(
        "name = \"ok\"\nmodel = \"{}\"\n[grid]\n\"joint[5].pitch\" = [0.03]\n\"joint.screw.rate\" = [1.0]\n",
        data("dynamics/free_chain.toml").display()
    );
    let spec = parse_study(&text, &file).unwrap();
    let model =
        flexmech::studies::sweep::model_for(&spec, &flexmech::studies::execute::plans(&spec)[0])
            .unwrap();
    let screw = model.joints.iter().find(|j| j.name == "screw").unwrap();
    assert_eq!(screw.rate, 1.0);
    match screw.kind.downcast_ref::<Screw>() {
        Some(s) => assert_eq!(s.pitch, 0.03),
        None => panic!("{:?}", screw.kind),
    }
}

#[test]
fn study_file_mistakes_are_errors_naming_the_key() {
    let e = study_error("unknown-top", "grdi = 1\n");
    assert!(e.contains("unknown key `grdi`"), "{e}");
    let e = study_error("unknown-figure", "[output]\nfigures = [\"energy\"]\n");
    assert!(
        e.contains("\"energy\"") && e.contains("energy_drift"),
        "{e}"
    );
    let e = study_error("empty-list", "[grid]\n\"solver.dt\" = []\n");
    assert!(e.contains("solver.dt") && e.contains("empty"), "{e}");
    let e = study_error("unquoted", "[grid]\nsolver.dt = [0.1]\n");
    assert!(e.contains("quote dotted keys"), "{e}");

    let dir = scratch("no-model");
    let file = dir.join("s.toml");
    let e = parse_study("name = \"x\"\nmodel = \"nowhere.toml\"\n", &file)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("key `model`") && e.contains("nowhere.toml"),
        "{e}"
    );
    let e = parse_study("model = \"nowhere.toml\"\n", &file)
        .unwrap_err()
        .to_string();
    assert!(e.contains("missing key `name`"), "{e}");
    let e = parse_study("name = \"a/b\"\nmodel = \"m.toml\"\n", &file)
        .unwrap_err()
        .to_string();
    assert!(e.contains("key `name`"), "{e}");
}

#[test]
fn an_invalid_value_is_an_error_naming_the_run_before_anything_runs() {
    let dir = scratch("invalid-value");
    let file = dir.join("neg.toml");
    let text = format!(
        "name = \"neg\"\nmodel = \"{}\"\n[grid]\n\"solver.dt\" = [0.2, -0.1]\n",
        data("dynamics/spinning_beam.toml").display()
    );
    std::fs::write(&file, &text).unwrap();
    let spec = load_study(&file).unwrap();
    let out = dir.join("out");
    let e = run_study(&spec, &options(&out, None)).unwrap_err();
    let msg = e.to_string();
    assert!(matches!(e, StudyError::Sweep(_)), "{msg}");
    assert!(
        msg.contains("run-0001") && msg.contains("solver.dt = -0.1"),
        "{msg}"
    );
    assert!(msg.contains("key `solver.dt`"), "{msg}");
    assert!(!out.join("neg/runs/run-0000.h5").exists());
}

#[test]
fn a_value_that_moves_a_joints_slave_is_refused_before_anything_runs() {
    // The expression cam's f(0) = −a x: the slave was placed for a = 0.02,
    // so a = 0.03 puts relation (1) 0.01 away from it — a mistake in the
    // study, refused whole, not a failed row among completed ones.
    let dir = scratch("slave-moved");
    let file = dir.join("moved.toml");
    let text = format!(
        "name = \"moved\"\nmodel = \"{}\"\n[grid]\n\"joint.cam.parameters.a\" = [0.02, 0.03]\n",
        data("examples/expression_cam.toml").display()
    );
    std::fs::write(&file, &text).unwrap();
    let spec = load_study(&file).unwrap();
    let out = dir.join("out");
    let msg = run_study(&spec, &options(&out, None))
        .unwrap_err()
        .to_string();
    assert!(
        msg.contains("run-0001") && msg.contains("joint.cam.parameters.a = 0.03"),
        "{msg}"
    );
    assert!(
        msg.contains("off by 1.000e-2") && msg.contains("angle"),
        "{msg}"
    );
    assert!(!out.join("moved/runs/run-0000.h5").exists());
}

#[test]
fn shard_strings() {
    assert_eq!("2/4".parse::<Shard>(), Ok(Shard { k: 2, n: 4 }));
    assert_eq!(" 1/1 ".parse::<Shard>(), Ok(Shard { k: 1, n: 1 }));
    for bad in ["0/2", "3/2", "1/0", "0/0"] {
        let e = bad.parse::<Shard>().unwrap_err();
        assert!(matches!(e, ShardError::OutOfRange { .. }), "{bad}: {e}");
        assert!(e.to_string().contains("between 1 and N"), "{e}");
    }
    for bad in ["", "2", "a/b", "1/2/3", "-1/2", "1.5/2", "1/ 2x"] {
        let e = bad.parse::<Shard>().unwrap_err();
        assert!(matches!(e, ShardError::Syntax { .. }), "{bad}: {e}");
        assert!(e.to_string().contains("expected K/N"), "{e}");
    }
    // Shards partition the runs.
    let n = 3;
    for i in 0..10 {
        let owners = (1..=n)
            .filter(|&k| Shard::new(k, n).unwrap().includes(i))
            .count();
        assert_eq!(owners, 1);
    }
    assert!(Shard::new(2, 3).unwrap().includes(4));
}

fn slurm(id: Option<&str>, count: Option<&str>, min: Option<&str>) -> SlurmArray {
    SlurmArray {
        task_id: id.map(Into::into),
        task_count: count.map(Into::into),
        task_min: min.map(Into::into),
        task_step: None,
    }
}

#[test]
fn slurm_array_variables_select_the_shard() {
    // --array=0-3: task ids 0..3, MIN unset or 0.
    assert_eq!(
        slurm(Some("0"), Some("4"), None).shard(),
        Ok(Some(Shard { k: 1, n: 4 }))
    );
    assert_eq!(
        slurm(Some("3"), Some("4"), Some("0")).shard(),
        Ok(Some(Shard { k: 4, n: 4 }))
    );
    // --array=1-4.
    assert_eq!(
        slurm(Some("1"), Some("4"), Some("1")).shard(),
        Ok(Some(Shard { k: 1, n: 4 }))
    );
    assert_eq!(
        slurm(Some("4"), Some("4"), Some("1")).shard(),
        Ok(Some(Shard { k: 4, n: 4 }))
    );
    // --array=0-6:2.
    let mut stepped = slurm(Some("4"), Some("4"), Some("0"));
    stepped.task_step = Some("2".into());
    assert_eq!(stepped.shard(), Ok(Some(Shard { k: 3, n: 4 })));
    // Not an array job.
    assert_eq!(slurm(None, None, None).shard(), Ok(None));
    // Broken environments.
    assert!(matches!(
        slurm(Some("1"), None, None).shard(),
        Err(ShardError::SlurmIncomplete { .. })
    ));
    assert!(matches!(
        slurm(Some("x"), Some("4"), None).shard(),
        Err(ShardError::SlurmNotNumber {
            var: "SLURM_ARRAY_TASK_ID",
            ..
        })
    ));
    // An id near 2⁶⁴ − 1 (once wrapped to "shard 0/4", 0 runs, exit 0).
    let huge = slurm(Some("18446744073709551615"), Some("4"), None).shard();
    assert!(
        matches!(huge, Err(ShardError::SlurmOutOfRange { .. })),
        "{huge:?}"
    );
    let e = slurm(Some("4"), Some("4"), None).shard().unwrap_err();
    assert!(matches!(e, ShardError::SlurmOutOfRange { .. }));
    assert!(e.to_string().contains("--array=0-3"), "{e}");
    // --shard wins over the environment; without it the environment counts.
    let env = slurm(Some("2"), Some("3"), None);
    assert_eq!(
        select_shard(Some("1/2"), &env),
        Ok(Some(Shard { k: 1, n: 2 }))
    );
    assert_eq!(select_shard(None, &env), Ok(Some(Shard { k: 3, n: 3 })));
    assert_eq!(select_shard(None, &SlurmArray::default()), Ok(None));
}

#[test]
fn the_shipped_study_file_loads() {
    let spec = load_study(&data("studies/pitch_dt.toml")).unwrap();
    assert_eq!(spec.name, "pitch-dt");
    assert!(spec
        .model_file()
        .unwrap()
        .ends_with("dynamics/free_chain.toml"));
    let runs: usize = spec.grid.iter().map(|g| g.values.len()).product();
    assert_eq!(runs, 8);
    for plan in flexmech::studies::execute::plans(&spec) {
        flexmech::studies::sweep::model_for(&spec, &plan).unwrap();
    }
}

#[test]
fn titles_are_optional_and_a_wrong_value_is_refused_by_key() {
    let dir = scratch("titles");
    assert!(small_spec(&dir).titles, "titles by default");
    let file = dir.join("untitled.toml");
    std::fs::write(&file, small_study_text() + "\n[output]\ntitles = false\n").unwrap();
    assert!(!load_study(&file).unwrap().titles);
    std::fs::write(&file, small_study_text() + "\n[output]\ntitles = \"no\"\n").unwrap();
    let err = load_study(&file).unwrap_err().to_string();
    assert!(
        err.contains("output.titles") && err.contains("true or false"),
        "{err}"
    );
}
