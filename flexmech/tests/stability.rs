//! Static load paths report their stability: `/solver/negative_pivots` holds
//! the number of negative eigenvalues of the converged tangent per step, and
//! a run that passes a bifurcation says so (summary, stderr, the file's
//! `warnings` attribute) instead of completing silently on the unstable
//! branch. Checked against a published buckling load and an analytic one.

use crate::common::{read, read_integers, read_strings, reader};
use flexmech::model::{load_model, parse_model};
use flexmech::results::run_model;
use std::path::{Path, PathBuf};

fn data(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../data")
        .join(path)
}

fn warnings_attr(file: &Path) -> String {
    reader(file).string_attr("warnings").unwrap_or_default()
}

/// The load at which the count first turns non-zero, bracketed by the last
/// stable and the first unstable step: `(stable, unstable, count)`.
fn bracket(loads: &[f64], counts: &[i64]) -> (f64, f64, i64) {
    let first = counts
        .iter()
        .position(|&c| c > 0)
        .expect("the path never became unstable");
    assert!(counts[..first].iter().all(|&c| c == 0), "{counts:?}");
    (loads[first - 1], loads[first], counts[first])
}

#[test]
fn the_argyris_frame_reports_lateral_buckling_at_the_published_load() {
    // Published P_cr = 1.088 (Argyris et al. 1979, Simo & Vu-Quoc 1986);
    // the file ramps P to 1.10 in steps of 0.005, so the bracket must hold
    // it — to the four digits published.
    let model = load_model(&data("benchmarks/argyris_frame.toml")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let summary = run_model(&model, dir.path()).unwrap();
    let p_max = 1.1;
    let loads: Vec<f64> = read(&summary.file, "/time")
        .iter()
        .map(|l| l * p_max)
        .collect();
    let counts: Vec<i64> = read_integers(&summary.file, "/solver/negative_pivots");
    assert_eq!(counts.len(), loads.len());
    let (stable, unstable, count) = bracket(&loads, &counts);
    const PUBLISHED: f64 = 1.088;
    assert!(
        stable < PUBLISHED && PUBLISHED <= unstable + 5e-4,
        "bracket [{stable}, {unstable}] misses {PUBLISHED}"
    );
    // One lateral mode; the path stays on the (unstable) plane branch.
    assert_eq!(count, 1);
    assert!(counts[counts.len() - 1] == 1, "{counts:?}");
    assert_eq!(summary.warnings.len(), 1, "{:?}", summary.warnings);
    assert!(summary.warnings[0].starts_with("stability"));
    assert!(warnings_attr(&summary.file).contains("unstable from load factor"));
    // Located by bisection inside that bracket: a bifurcation (the load
    // does no work on the lateral mode) within 0.5 % of the published load,
    // named with the nearest linear buckling load in the warning.
    let located = read(&summary.file, "/stability/critical_load_factor");
    let kinds = read_strings(&summary.file, "/stability/critical_kind");
    assert_eq!(kinds, ["bifurcation"]);
    let p = located[0] * p_max;
    assert!(
        (p / PUBLISHED - 1.0).abs() < 5e-3 && stable < p && p <= unstable,
        "located {p}"
    );
    let bracket = read(&summary.file, "/stability/critical_bracket")[0];
    assert!(bracket < 1e-5, "bracket {bracket}");
    assert!(
        summary.warnings[0].contains("bifurcation at"),
        "{:?}",
        summary.warnings
    );
    assert!(summary.warnings[0].contains("nearest linear buckling load factor"));
}

/// A column clamped at its base under a dead axial force ramped to `p`.
fn column(p: f64, steps: usize) -> String {
    format!(
        r#"name = "column"
[[section]]
name = "rod"
EA = 1.0e5
GA = [5.0e4, 5.0e4]
GJ = 80.0
EI = [100.0, 100.0]
[[beam]]
name = "rod"
section = "rod"
start = [0.0, 0.0, 0.0]
end = [10.0, 0.0, 0.0]
e2 = [0.0, 1.0, 0.0]
elements = 20
[[support]]
node = "rod.start"
fixed = "all"
[[load]]
node = "rod.end"
force = [{}, 0.0, 0.0]
[solver]
analysis = "static"
load_steps = {steps}
"#,
        -p
    )
}

#[test]
fn an_euler_column_turns_unstable_at_its_critical_load() {
    // P_cr = π²EI/(4L²) = 2.4674 for the clamped–free column. With equal
    // bending stiffnesses both planes buckle at once: two negative
    // eigenvalues. Twenty linear elements overestimate P_cr by O(h²)
    // (< 0.5 %); the steps are 0.05.
    let p_cr = std::f64::consts::PI.powi(2) * 100.0 / (4.0 * 100.0);
    let dir = tempfile::tempdir().unwrap();
    let model = parse_model(&column(3.0, 60), Path::new("column.toml")).unwrap();
    let summary = run_model(&model, dir.path()).unwrap();
    let loads: Vec<f64> = read(&summary.file, "/time")
        .iter()
        .map(|l| l * 3.0)
        .collect();
    let counts: Vec<i64> = read_integers(&summary.file, "/solver/negative_pivots");
    let (stable, unstable, count) = bracket(&loads, &counts);
    assert!(
        stable < p_cr * 1.005 && p_cr <= unstable,
        "bracket [{stable}, {unstable}] vs {p_cr}"
    );
    assert_eq!(count, 2);
    assert!(!summary.warnings.is_empty());
    // The located bifurcation equals the same mesh's linear buckling load:
    // the perfect column's prebuckling state is a uniform shortening by
    // P/EA = 2.5e-5, so the two differ by that order only.
    let located = read(&summary.file, "/stability/critical_load_factor")[0] * 3.0;
    assert_eq!(read(&summary.file, "/stability/negative_after"), [2.0]);
    let buckling = parse_model(
        &column(3.0, 60).replace(
            "analysis = \"static\"\nload_steps = 60",
            "analysis = \"buckling\"\nmodes = 2",
        ),
        Path::new("column.toml"),
    )
    .unwrap();
    let linear = read(
        &run_model(&buckling, dir.path()).unwrap().file,
        "/buckling/load_factor",
    )[0] * 3.0;
    assert!(
        (located / linear - 1.0).abs() < 2e-4,
        "located {located}, linear {linear}"
    );
    assert!(
        (located / p_cr - 1.0).abs() < 5e-3,
        "located {located} vs {p_cr}"
    );
    // Below P_cr: stable all the way, no warning.
    let model = parse_model(&column(2.3, 10), Path::new("column.toml")).unwrap();
    let summary = run_model(&model, dir.path()).unwrap();
    let counts: Vec<i64> = read_integers(&summary.file, "/solver/negative_pivots");
    assert!(counts.iter().all(|&c| c == 0), "{counts:?}");
    assert!(summary.warnings.is_empty(), "{:?}", summary.warnings);
    assert_eq!(warnings_attr(&summary.file), "");
}

#[test]
fn a_dead_end_moment_writes_the_count_without_a_stability_claim() {
    // A dead moment is not conservative for finite 3D rotations: the
    // tangent's symmetric part is not the second variation of a potential,
    // so the count is written but no stability warning is made from it.
    let model = load_model(&data("benchmarks/rollup_linear.toml")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let summary = run_model(&model, dir.path()).unwrap();
    let counts: Vec<i64> = read_integers(&summary.file, "/solver/negative_pivots");
    assert_eq!(counts.len(), summary.written);
    assert!(summary.warnings.is_empty(), "{:?}", summary.warnings);
}

#[test]
fn dynamic_runs_have_no_stability_count() {
    let model = load_model(&data("dynamics/spinning_beam.toml")).unwrap();
    let mut model = model;
    if let flexmech::model::Analysis::Dynamic { t_end, dt, .. } = &mut model.solver.analysis {
        *t_end = 5.0 * *dt;
    }
    let dir = tempfile::tempdir().unwrap();
    let summary = run_model(&model, dir.path()).unwrap();
    assert!(!reader(&summary.file).has("/solver/negative_pivots"));
}
