//! `flexmech bench`: every case's model is valid and runs, the steps are
//! the ones asked for, and the table's ratios are to Newmark at the same size.

use flexmech_studies::bench::{bench, model_text, table, CASES};
use flexmech_studies::model::parse_model;
use std::path::Path;

#[test]
fn every_case_builds_runs_and_is_tabulated() {
    for case in CASES {
        let model = parse_model(&model_text(&case, 8, 3), Path::new("bench.toml")).unwrap();
        assert_eq!(model.solver.modified_newton, case.newton == "modified");
    }
    let dir = tempfile::tempdir().unwrap();
    let mut seen = 0;
    let timings = bench(&[4, 8], 3, 2, dir.path(), |_| seen += 1).unwrap();
    // Two rounds, one kept timing per case and size, in the cases' order.
    assert_eq!((timings.len(), seen), (2 * CASES.len(), 2 * CASES.len()));
    for (t, case) in timings.iter().zip(CASES.iter().cycle()) {
        assert_eq!(t.case.label, case.label);
    }
    for t in &timings {
        // Three steps of dt = 1e-3.
        assert_eq!(t.steps, 3, "{}", t.case.label);
        assert!(t.seconds > 0.0 && t.per_element_step_us().is_finite());
        // The set-up (patterns, initial accelerations) is timed apart.
        assert!(t.setup_seconds > 0.0, "{}", t.case.label);
    }
    let md = table(&timings);
    assert_eq!(md.lines().count(), 2 + timings.len());
    assert!(md
        .lines()
        .filter(|l| l.contains("| newmark |"))
        .all(|l| l.contains("| 1.00 | ")));
}
