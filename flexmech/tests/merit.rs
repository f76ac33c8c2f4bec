//! A run's figures of merit are computed over every converged step while it
//! runs, so a study's figures do not depend on how many steps are stored.

use std::path::Path;

use flexmech::model::parse_model;
use flexmech::results::run_model_to;
use flexmech::results::{layout, ResultReader};
use flexmech::studies::figures::read_figures;
use flexmech::studies::Figure;

fn free_chain(every: usize) -> flexmech::model::Model {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/dynamics/free_chain.toml");
    let text = std::fs::read_to_string(&path)
        .unwrap()
        .replace("t_end = 1.0", "t_end = 0.2")
        .replace("[output]\n", &format!("[output]\nevery = {every}\n"));
    parse_model(&text, &path).unwrap()
}

#[test]
fn figures_cover_every_step_whatever_is_stored() {
    let dir = tempfile::tempdir().unwrap();
    let all = dir.path().join("all.h5");
    let sparse = dir.path().join("sparse.h5");
    let run_all = run_model_to(&free_chain(1), &all).unwrap();
    let run_sparse = run_model_to(&free_chain(7), &sparse).unwrap();
    assert!(run_sparse.written < run_all.written);

    // With every step stored, the streamed figures equal the figures of the
    // stored series (one definition), bit for bit.
    let r = ResultReader::open(&all).unwrap();
    let attr = |r: &ResultReader, name| r.f64_attr(name).unwrap();
    assert_eq!(
        attr(&r, layout::ATTR_ENERGY_DRIFT),
        r.energy_drift().unwrap()
    );
    let stored_iterations: u64 = r.counts(layout::SOLVER_ITERATIONS).unwrap().iter().sum();
    assert_eq!(
        attr(&r, layout::ATTR_NEWTON_ITERATIONS),
        stored_iterations as f64
    );
    assert_eq!(
        attr(&r, layout::ATTR_NEWTON_ITERATIONS),
        run_all.iterations as f64
    );
    assert_eq!(attr(&r, layout::ATTR_STEPS), run_all.steps as f64);

    // Storing every 7th step changes none of them: the same run, observed
    // at every step.
    let a = read_figures(&all, &Figure::ALL).unwrap();
    let b = read_figures(&sparse, &Figure::ALL).unwrap();
    for figure in [
        Figure::EnergyDrift,
        Figure::MaxDisplacement,
        Figure::NewtonIterations,
    ] {
        assert_eq!(a.get(&figure), b.get(&figure), "{figure}");
    }
    assert!(
        a.energy_drift > 0.0 && a.energy_drift < 1e-6,
        "{}",
        a.energy_drift
    );
    // The stored steps of the sparse file alone would undercount.
    let s = ResultReader::open(&sparse).unwrap();
    let sparse_sum: u64 = s.counts(layout::SOLVER_ITERATIONS).unwrap().iter().sum();
    assert!((sparse_sum as f64) < b.newton_iterations);
}
