//! `flexmech bench`: every case's model is valid and runs, the steps are
//! the ones asked for, and the table's ratios are to Newmark at the same size.

use flexmech::cli::bench::{bench, model_text, table, CASES};
use flexmech::model::parse_model;
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

/// Every mechanism runs with each 2-node case's integrator and Newton, its
/// `rho_inf` kept for generalized-α alone, the rest of the file unchanged.
#[test]
fn mechanisms_run_with_each_case() {
    use flexmech::cli::bench::{bench_mechanisms, mechanism_cases, mechanism_text, MECHANISMS};
    use flexmech::model::{Analysis, IntegratorKind};
    for mechanism in MECHANISMS {
        let published = parse_model(mechanism.text, Path::new("m.toml")).unwrap();
        for case in mechanism_cases() {
            let text = mechanism_text(&mechanism, case);
            let model = parse_model(&text, Path::new("m.toml")).unwrap();
            let Analysis::Dynamic {
                integrator,
                dt,
                t_end,
            } = model.solver.analysis
            else {
                panic!("{} is not dynamic", mechanism.name);
            };
            assert_eq!(integrator.name(), case.integrator, "{}", mechanism.name);
            if let IntegratorKind::GeneralizedAlpha { rho_inf } = integrator {
                assert_eq!(rho_inf, 0.5, "the file's rho_inf");
            }
            assert_eq!(model.solver.modified_newton, case.newton == "modified");
            let Analysis::Dynamic {
                dt: dt0, t_end: t0, ..
            } = published.solver.analysis
            else {
                unreachable!()
            };
            assert_eq!((dt, t_end), (dt0, t0), "the published run");
            assert_eq!(model.beams, published.beams);
            assert_eq!(model.joints, published.joints);
        }
    }
    // A short four-bar through the timing loop: one kept timing per case.
    let short: &'static str = Box::leak(
        MECHANISMS[0]
            .text
            .replace("t_end = 12.0", "t_end = 0.03")
            .into_boxed_str(),
    );
    let four_bar = flexmech::cli::bench::Mechanism {
        name: "four-bar",
        text: short,
    };
    let dir = tempfile::tempdir().unwrap();
    let timings = bench_mechanisms(&[four_bar], 2, dir.path(), |_| {}).unwrap();
    assert_eq!(timings.len(), mechanism_cases().count());
    for t in &timings {
        assert_eq!(
            (t.model, t.elements, t.steps),
            ("four-bar", 32, 3),
            "{}",
            t.case.label
        );
    }
    let md = table(&timings);
    assert!(md
        .lines()
        .filter(|l| l.contains("| four-bar | 32 | newmark |"))
        .all(|l| l.contains("| 1.00 | ")));
}
