//! The fuzzing campaign of the model-file path, bounded for the test suite:
//! mutants of every model in `data/` for about 20 s of wall time, each in
//! its own `flexmech` process. No panic, abort, hang, unlocated error or
//! non-finite completed result may appear (see `flexmech/fuzz/`;
//! `scripts/fuzz.sh` runs larger campaigns). A fake `flexmech` that
//! misbehaves in each way shows the harness sees every kind of defect.

use crate::fuzz_engine::{run, FuzzOptions, Outcome};
use flexmech::results::table::{write_table, TableColumn, TableValues};
use std::os::unix::fs::PermissionsExt;
use std::path::{Path, PathBuf};
use std::time::Duration;

fn data() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../data")
}

/// Wall time of the suite's campaign (about 750 mutants alone on 2 cores;
/// `scripts/fuzz.sh` runs the long campaigns).
const BUDGET: Duration = Duration::from_secs(12);
/// Fewest mutants it must have run (a slow machine still runs this many).
const FEWEST: usize = 200;

#[test]
fn a_bounded_campaign_finds_no_defect() {
    let work = tempfile::tempdir().unwrap();
    // A fixed seed keeps the suite's verdict reproducible (the mutants run
    // are a prefix of one sequence); FLEXMECH_FUZZ_SEED explores others, as
    // scripts/fuzz.sh does.
    let seed = std::env::var("FLEXMECH_FUZZ_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(20_261_130);
    let options = FuzzOptions {
        flexmech: PathBuf::from(env!("CARGO_BIN_EXE_flexmech")),
        data: data(),
        work: work.path().to_path_buf(),
        seed,
        mutants: 100_000,
        budget: Some(BUDGET),
        timeout: Duration::from_secs(60),
        threads: 2,
    };
    let report = run(&options).unwrap();
    eprintln!("seed {seed}\n{}", report.text());
    assert!(report.defects.is_empty(), "seed {seed}:\n{}", report.text());
    let solved: usize = [
        Outcome::Completed,
        Outcome::CompletedWithWarning,
        Outcome::SolveFailed,
    ]
    .iter()
    .map(|o| report.counts.get(o).copied().unwrap_or(0))
    .sum();
    assert!(report.mutants >= FEWEST, "{} mutants", report.mutants);
    // Most mutants are refused; a fair share must reach the solver.
    assert!(solved * 10 >= report.mutants, "{}", report.text());
}

/// A stand-in for `flexmech` that behaves as `script` says for `run` and
/// passes `check`.
fn fake(dir: &Path, script: &str) -> PathBuf {
    let path = dir.join("flexmech");
    let body =
        format!("#!/bin/sh\nif [ \"$1\" = check ]; then exit 0; fi\nmkdir -p \"$3\"\n{script}\n");
    std::fs::write(&path, body).unwrap();
    std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o755)).unwrap();
    path
}

#[test]
fn the_harness_sees_every_kind_of_defect() {
    // A result file with a NaN where none belongs.
    let tmp = tempfile::tempdir().unwrap();
    let h5 = tmp.path().join("nan.h5");
    write_table(
        &h5,
        &[TableColumn {
            name: "time".into(),
            description: "a NaN where none belongs".into(),
            values: TableValues::Numbers(vec![0.0, f64::NAN]),
        }],
        &[],
    )
    .unwrap();
    let copy_nan = format!("cp '{}' \"$3/r.h5\"; echo completed", h5.display());
    let cases = [
        (
            "echo \"thread 'main' panicked at x\" >&2; exit 101",
            Outcome::Panic,
        ),
        ("kill -ABRT $$", Outcome::Abort),
        ("sleep 5", Outcome::Hang),
        ("echo 'error: somewhere' >&2; exit 1", Outcome::Unlocated),
        (copy_nan.as_str(), Outcome::NonFinite),
    ];
    for (script, expected) in cases {
        let dir = tempfile::tempdir().unwrap();
        let options = FuzzOptions {
            flexmech: fake(dir.path(), script),
            data: data(),
            work: dir.path().join("work"),
            seed: 3,
            mutants: 4,
            budget: None,
            timeout: Duration::from_secs(1),
            threads: 2,
        };
        let report = run(&options).unwrap();
        // Mutants that the fake "checks" are all solved by the script.
        assert!(
            report.defects.iter().all(|(_, o, _)| *o == expected) && !report.defects.is_empty(),
            "{script}: {}",
            report.text()
        );
        for (dir, _, _) in &report.defects {
            assert!(dir.join("mutant.toml").exists(), "reproducer kept");
        }
    }
}
