//! `newton = "modified"`: a factorised tangent is kept across iterations and
//! steps while each iteration at least halves the residual. The solution
//! satisfies the same tolerance, so a modified run must follow the full
//! Newton run to within the accumulated Newton tolerance and keep every
//! conservation law the scheme promises — with fewer factorisations than
//! steps. Refused where it cannot hold (statics, the paper's bordered scheme).
//! `newton = "exact"` (the exact tangent at every iterate) and `"full"` (the
//! energy–momentum scheme's cheaper tangent first) reach the same solution.

use flexmech::model::parse_model;
use flexmech::results::run_model;
use std::path::{Path, PathBuf};

use crate::common;
use common::{data, drift, read, read_counts};

/// Runs `model` (a data/ path) with `integrator` and `newton`.
fn run(model: &str, integrator: &str, newton: &str) -> (PathBuf, tempfile::TempDir) {
    let path = data(model);
    let text = std::fs::read_to_string(&path).unwrap().replace(
        "integrator = \"energy-momentum\"",
        &format!("integrator = \"{integrator}\"\nnewton = \"{newton}\""),
    );
    let model = parse_model(&text, &path).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let file = run_model(&model, dir.path())
        .unwrap_or_else(|e| panic!("{integrator}, {newton}: {e}"))
        .file;
    (file, dir)
}

/// The largest difference of any stored position between two result files
/// of the same model (which must have the same steps).
fn largest_position_difference(a: &Path, b: &Path) -> f64 {
    let (a, b) = (
        read(a, "/configuration/position"),
        read(b, "/configuration/position"),
    );
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(&b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// Newton's tolerance (1e-11 in the chain's file) accumulated over 100
/// steps, on positions of size 1: well below this; an approximate
/// solution (a step accepted before convergence) would be far above.
const SAME_SOLUTION: f64 = 1e-7;

#[test]
fn the_free_chain_follows_full_newton_with_every_joint_kind() {
    for integrator in ["newmark", "momentum", "energy-momentum"] {
        let (full, _d1) = run("dynamics/free_chain.toml", integrator, "full");
        let (modified, _d2) = run("dynamics/free_chain.toml", integrator, "modified");
        let worst = largest_position_difference(&full, &modified);
        let steps = read_counts(&modified, "/solver/iterations").len() - 1;
        let factorizations: u64 = read_counts(&modified, "/solver/factorizations")
            .iter()
            .sum();
        let iterations: u64 = read_counts(&modified, "/solver/iterations").iter().sum();
        let full_factorizations: u64 = read_counts(&full, "/solver/factorizations").iter().sum();
        let full_iterations: u64 = read_counts(&full, "/solver/iterations").iter().sum();
        eprintln!(
            "{integrator}: positions differ by {worst:.1e}; modified {factorizations} \
             factorisations / {iterations} iterations over {steps} steps, full \
             {full_factorizations} / {full_iterations}"
        );
        assert!(worst <= SAME_SOLUTION, "{integrator}: {worst:e}");
        // Full Newton factorises at the start of every step and at every
        // iteration but its chord steps and round-off corrections at the
        // floor, which reuse the step's factorisation.
        assert!(
            full_factorizations <= full_iterations && full_factorizations >= steps as u64,
            "{integrator}: full Newton {full_factorizations} factorisations / {full_iterations} iterations"
        );
        assert!(
            (factorizations as usize) < steps,
            "{integrator}: {factorizations} factorisations for {steps} steps"
        );
        for joint in ["revolute", "screw", "cam", "lobe"] {
            let c = read(&modified, &format!("/joints/{joint}/constraint_error"));
            assert!(c.iter().all(|&v| v <= 1e-12), "{integrator}, {joint}");
        }
        if integrator != "newmark" {
            let (dl, dh) = (
                drift(&read(&modified, "/momentum/linear"), 3),
                drift(&read(&modified, "/momentum/angular"), 3),
            );
            assert!(dl <= 1e-9 && dh <= 1e-9, "{integrator}: {dl:e} {dh:e}");
        }
        if integrator == "energy-momentum" {
            let de = drift(&read(&modified, "/energy/total"), 1);
            assert!(de <= 1e-9, "energy drift {de:e}");
        }
    }
}

#[test]
fn the_spinning_beam_keeps_its_energy_with_modified_newton() {
    let (file, _dir) = run("dynamics/spinning_beam.toml", "energy-momentum", "modified");
    assert!((read(&file, "/time").last().unwrap() - 20.0).abs() < 1e-9);
    let de = drift(&read(&file, "/energy/total"), 1);
    assert!(de <= 1e-9, "energy drift {de:e}");
    assert!(drift(&read(&file, "/momentum/angular"), 3) <= 1e-9);
}

#[test]
fn modified_newton_is_refused_where_it_cannot_hold() {
    // The model error of `text` names `solver.newton` and says `why`.
    let refused = |text: &str, why: &str| {
        let err = parse_model(text, Path::new("m.toml"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("solver.newton") && err.contains(why), "{err}");
    };
    let static_model = std::fs::read_to_string(data("statics/screw_driven.toml")).unwrap();
    assert!(static_model.contains("[solver]"));
    refused(
        &static_model.replace("[solver]", "[solver]\nnewton = \"modified\""),
        "dynamic",
    );
    let chain = std::fs::read_to_string(data("dynamics/free_chain.toml")).unwrap();
    let with = |integrator: &str, newton: &str| {
        chain.replace(
            "integrator = \"energy-momentum\"",
            &format!("integrator = \"{integrator}\"\nnewton = \"{newton}\""),
        )
    };
    refused(&with("energy-momentum-paper", "modified"), "bordered");
    refused(&with("energy-momentum", "quasi"), "\"modified\"");
    refused(&with("energy-momentum", "quasi"), "\"exact\"");
}

#[test]
fn exact_and_full_newton_reach_the_same_energy_momentum_solution() {
    // The chain's links are joined by every joint kind; the energy–momentum
    // scheme's "full" Newton starts each step with the momentum scheme's
    // closed-form tangent, "exact" uses the discrete gradient's own.
    let (full, _d1) = run("dynamics/free_chain.toml", "energy-momentum", "full");
    let (exact, _d2) = run("dynamics/free_chain.toml", "energy-momentum", "exact");
    let worst = largest_position_difference(&full, &exact);
    let iterations = |f: &Path| read_counts(f, "/solver/iterations").iter().sum::<u64>();
    eprintln!(
        "positions differ by {worst:.1e}; iterations full {} / exact {}",
        iterations(&full),
        iterations(&exact)
    );
    assert!(worst <= SAME_SOLUTION, "{worst:e}");
    for file in [&full, &exact] {
        let de = drift(&read(file, "/energy/total"), 1);
        assert!(de <= 1e-9, "energy drift {de:e}");
        assert!(drift(&read(file, "/momentum/angular"), 3) <= 1e-9);
    }
}
