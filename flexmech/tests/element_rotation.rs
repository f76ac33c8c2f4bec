//! An element turned past π between its nodes would be read as turned the
//! other way (principal logarithms): a strip rolled six times by a prescribed
//! end rotation once "completed" as a straight beam (strain energy 4.8e-18
//! instead of 7 106), one element rolled once gave 8e-29 instead of 197.4.
//! Such runs now stop with an error naming the beam, the element, the load
//! factor and the fix; the run's file keeps the steps before and says so.

use crate::common::{read, string_attr};
use flexmech::model::parse_model;
use flexmech::results::{run_model, RunError};
use std::path::Path;

fn rolled(turns: f64, elements: usize, load_steps: usize) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/statics/rollup_prescribed.toml");
    let text = std::fs::read_to_string(path).unwrap();
    let out = text
        .replace(
            "[1.0, 6.283185307179586]",
            &format!("[1.0, {:?}]", turns * std::f64::consts::TAU),
        )
        .replace("elements = 10", &format!("elements = {elements}"))
        .replace("load_steps = 10", &format!("load_steps = {load_steps}"));
    assert!(out.contains(&format!("load_steps = {load_steps}")));
    out
}

fn refused(text: &str) -> (String, String) {
    let model = parse_model(text, Path::new("rolled.toml")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    match run_model(&model, dir.path()) {
        Err(RunError::Solve { error, file, .. }) => {
            let status = string_attr(&file, "status");
            (error.to_string(), status)
        }
        other => panic!("expected a refusal, got {other:?}"),
    }
}

#[test]
fn six_turns_on_ten_elements_are_refused_with_the_beam_named() {
    let (message, status) = refused(&rolled(6.0, 10, 60));
    for words in [
        "beam \"strip\"",
        "between its nodes",
        "use more elements",
        "2.356 rad",
    ] {
        assert!(message.contains(words), "{message}");
    }
    assert!(
        status.starts_with("failed") && status.contains("beam \"strip\""),
        "{status}"
    );
}

#[test]
fn one_turn_on_one_element_is_refused() {
    let (message, _) = refused(&rolled(1.0, 1, 10));
    assert!(message.contains("element 0 of beam \"strip\""), "{message}");
}

#[test]
fn a_prescribed_turn_too_large_for_one_step_is_retried_smaller_or_refused() {
    // Two turns in one load step: the end node's prescribed rotation changes
    // by 4π, which as one rotation is none at all — the strip stayed straight
    // and the run "completed". Now the step is halved until the change is
    // below π/2 (three halvings), and the strip rolls up twice exactly…
    let model = parse_model(&rolled(2.0, 20, 1), Path::new("rolled.toml")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let file = run_model(&model, dir.path()).unwrap().file;
    let strain = read(&file, "/energy/strain");
    let kappa = 2.0 * std::f64::consts::TAU / 10.0;
    let exact = 0.5 * 100.0 * kappa * kappa * 10.0;
    let last = *strain.last().unwrap();
    assert!(
        (last - exact).abs() <= 1e-6 * exact,
        "strain energy {last} vs {exact}"
    );
    // … and without halvings allowed it is refused, naming the entry and the fix.
    let text = rolled(2.0, 20, 1).replace(
        "max_iterations = 30",
        "max_iterations = 30\nmax_halvings = 0",
    );
    let (message, _) = refused(&text);
    assert!(
        message.contains("prescribed[0]") && message.contains("more load steps"),
        "{message}"
    );
}

#[test]
fn many_turns_on_enough_elements_still_roll_up_exactly() {
    // Six turns on 60 elements (0.63 rad each): the strip is a six-fold circle,
    // the tip back at the clamp, the strain energy that of pure bending,
    // EI κ² L/2 with κ = 6·2π/L.
    let model = parse_model(&rolled(6.0, 60, 60), Path::new("rolled.toml")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let file = run_model(&model, dir.path()).unwrap().file;
    let strain = read(&file, "/energy/strain");
    let kappa = 6.0 * std::f64::consts::TAU / 10.0;
    let exact = 0.5 * 100.0 * kappa * kappa * 10.0;
    let last = *strain.last().unwrap();
    assert!(
        (last - exact).abs() <= 1e-6 * exact,
        "strain energy {last} vs {exact}"
    );
}
