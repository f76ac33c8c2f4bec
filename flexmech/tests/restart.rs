//! Restarts: a run continued from its result file equals the uninterrupted
//! run, and a result file that does not belong to the model is refused with
//! a message naming what differs.

use crate::common::{read, string_attr};
use flexmech::model::parse_model;
use flexmech::results::{restart_model, run_model, RunError};
use std::path::{Path, PathBuf};

fn data(p: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../data")
        .join(p)
}

fn text_of(p: &str) -> String {
    std::fs::read_to_string(data(p)).unwrap()
}

fn replaced(text: &str, from: &str, to: &str) -> String {
    assert!(text.contains(from), "{from}");
    text.replacen(from, to, 1)
}

/// Runs `short` (to t₁), continues it with `long` (to t₂), runs `long` from
/// t = 0, and compares the continuation with the last rows of the
/// uninterrupted run, dataset by dataset; returns the largest difference.
fn continued_vs_uninterrupted(short: &str, long: &str, datasets: &[&str]) -> f64 {
    let dir = tempfile::tempdir().unwrap();
    let (a, b, c) = (
        dir.path().join("a"),
        dir.path().join("b"),
        dir.path().join("c"),
    );
    let short = parse_model(short, Path::new("short.toml")).unwrap();
    let long = parse_model(long, Path::new("long.toml")).unwrap();
    let first = run_model(&short, &a).unwrap().file;
    let whole = run_model(&long, &b).unwrap().file;
    let continued = restart_model(&long, &first, &c).unwrap().file;
    let t_whole = read(&whole, "/time");
    let t_cont = read(&continued, "/time");
    let t_first = read(&first, "/time");
    assert_eq!(
        t_cont[0],
        *t_first.last().unwrap(),
        "starts where the first run stopped"
    );
    assert_eq!(t_cont.last(), t_whole.last());
    assert!(string_attr(&continued, "restarted_from").ends_with(".h5"));
    let mut worst = 0.0_f64;
    for ds in datasets {
        let w = read(&whole, ds);
        let k = read(&continued, ds);
        let per_row = w.len() / t_whole.len();
        let tail = &w[w.len() - k.len()..];
        assert_eq!(k.len(), t_cont.len() * per_row, "{ds}");
        let d = tail
            .iter()
            .zip(&k)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max);
        worst = worst.max(d);
    }
    worst
}

const STATE: [&str; 6] = [
    "/configuration/position",
    "/configuration/quaternion",
    "/configuration/velocity",
    "/configuration/angular_velocity",
    "/energy/total",
    "/energy/driver_work",
];

#[test]
fn every_integrator_continues_a_driven_cam_bit_for_bit() {
    // The paper's cam: a driven joint (Newmark carries the drivers'
    // reactions across steps), gravity, a flexible arm.
    let base = text_of("paper/cam.toml");
    for integrator in [
        "newmark",
        "generalized-alpha",
        "momentum",
        "energy-momentum",
        "energy-momentum-paper",
    ] {
        let base = replaced(
            &base,
            "integrator = \"energy-momentum\"",
            &format!("integrator = \"{integrator}\""),
        );
        let short = replaced(&base, "t_end = 3.0", "t_end = 0.6");
        let long = replaced(&base, "t_end = 3.0", "t_end = 1.2");
        let mut sets = STATE.to_vec();
        sets.push("/joints/cam/angle");
        let worst = continued_vs_uninterrupted(&short, &long, &sets);
        assert_eq!(worst, 0.0, "{integrator}");
    }
}

#[test]
fn a_free_chain_of_every_joint_kind_continues_bit_for_bit() {
    // Free joints: released rates (momentum schemes), a spherical joint's
    // multiplicative rotation, a cylindrical joint's two coordinates.
    let base = text_of("dynamics/free_chain.toml");
    for integrator in ["newmark", "energy-momentum"] {
        let base = replaced(
            &base,
            "integrator = \"energy-momentum\"",
            &format!("integrator = \"{integrator}\""),
        );
        let short = replaced(&base, "t_end = 1.0", "t_end = 0.1");
        let long = replaced(&base, "t_end = 1.0", "t_end = 0.25");
        let worst = continued_vs_uninterrupted(&short, &long, &STATE);
        assert_eq!(worst, 0.0, "{integrator}");
    }
}

#[test]
fn modified_newton_continues_to_the_newton_tolerance() {
    // Modified Newton keeps a factorised tangent across steps; the continued
    // run factorises afresh at its first step, so it agrees to the solve's
    // tolerance (1e-10 on the scaled residual: positions of this 1 m arm to
    // well below 1e-6 m), not bit for bit.
    let base = replaced(
        &text_of("paper/cam.toml"),
        "newton = \"exact\"",
        "newton = \"modified\"",
    );
    let short = replaced(&base, "t_end = 3.0", "t_end = 0.5");
    let long = replaced(&base, "t_end = 3.0", "t_end = 1.0");
    let worst = continued_vs_uninterrupted(&short, &long, &["/configuration/position"]);
    assert!(worst <= 1e-6, "{worst:e}");
}

fn restart_error(first: &str, second: &str) -> String {
    let dir = tempfile::tempdir().unwrap();
    let first = parse_model(first, Path::new("first.toml")).unwrap();
    let result = run_model(&first, dir.path()).unwrap().file;
    let second = parse_model(second, Path::new("second.toml")).unwrap();
    match restart_model(&second, &result, &dir.path().join("next")) {
        Err(e) => e.to_string(),
        Ok(_) => panic!("expected a refusal"),
    }
}

#[test]
fn a_result_of_another_run_is_refused_naming_what_differs() {
    let base = replaced(&text_of("paper/cam.toml"), "t_end = 3.0", "t_end = 0.1");
    let later = replaced(&base, "t_end = 0.1", "t_end = 0.2");
    // Another mechanism: a longer post (its nodes moved).
    let moved = replaced(
        &later,
        "start = [0.0, 0.0, 0.0]",
        "start = [0.0, 0.0, -0.5]",
    );
    let e = restart_error(&base, &moved);
    assert!(
        e.contains("second.toml") && e.contains("not the same mechanism"),
        "{e}"
    );
    // More elements.
    let finer = replaced(
        &later,
        "elements = 4\n\n[[joint]]",
        "elements = 5\n\n[[joint]]",
    );
    let e = restart_error(&base, &finer);
    assert!(e.contains("nodes"), "{e}");
    // Another integrator.
    let other = replaced(&later, "\"energy-momentum\"", "\"momentum\"");
    let e = restart_error(&base, &other);
    assert!(
        e.contains("energy-momentum") && e.contains("momentum"),
        "{e}"
    );
    // Generalized-α with another ρ∞.
    let alpha = |t: &str, rho: f64| {
        replaced(
            t,
            "integrator = \"energy-momentum\"",
            &format!("integrator = \"generalized-alpha\"\nrho_inf = {rho:?}"),
        )
    };
    let e = restart_error(&alpha(&base, 0.9), &alpha(&later, 0.5));
    assert!(e.contains("rho_inf = 0.9") && e.contains("0.5"), "{e}");
    // Another time step.
    let other = replaced(&later, "dt = 0.01", "dt = 0.02");
    let e = restart_error(&base, &other);
    assert!(e.contains("restart") && e.contains("nominal step"), "{e}");
    // Nothing left to do.
    let e = restart_error(&base, &base);
    assert!(
        e.contains("solver.t_end") && e.contains("later t_end"),
        "{e}"
    );
}

#[test]
fn a_static_result_cannot_be_continued() {
    let dir = tempfile::tempdir().unwrap();
    let path = data("statics/rack_pinion_driven.toml");
    let model = flexmech::model::load_model(&path).unwrap();
    let result = run_model(&model, dir.path()).unwrap().file;
    let dynamic = parse_model(&text_of("paper/cam.toml"), Path::new("cam.toml")).unwrap();
    let e = restart_model(&dynamic, &result, &dir.path().join("next")).unwrap_err();
    assert!(
        matches!(e, RunError::Restart(_)) && e.to_string().contains("no /restart group"),
        "{e}"
    );
    // Nor can a run continue into its own file.
    let first = parse_model(
        &replaced(&text_of("paper/cam.toml"), "t_end = 3.0", "t_end = 0.05"),
        Path::new("cam.toml"),
    )
    .unwrap();
    let file = run_model(&first, dir.path()).unwrap().file;
    let later = parse_model(&text_of("paper/cam.toml"), Path::new("cam.toml")).unwrap();
    let e = restart_model(&later, &file, dir.path()).unwrap_err();
    assert!(e.to_string().contains("overwrite"), "{e}");
}

#[test]
fn a_follower_loaded_run_continues_bit_for_bit_with_its_load_work() {
    // The follower loads' work since t = 0 stands in the records' total
    // energy; the restart carries it (`/restart` attribute follower_work).
    let base = replaced(
        &replaced(
            &text_of("statics/follower_tip_force.toml"),
            "analysis = \"static\"\nload_steps = 6",
            "analysis = \"dynamic\"\nintegrator = \"energy-momentum\"\ndt = 0.005\nt_end = T_END",
        ),
        "follower = true                      # turns with the tip",
        "follower = true\ntime = { expr = \"min(t/0.05, 1)\" }",
    );
    let short = replaced(&base, "T_END", "0.05");
    let long = replaced(&base, "T_END", "0.1");
    let worst = continued_vs_uninterrupted(&short, &long, &STATE);
    assert_eq!(worst, 0.0);
}

#[test]
fn a_damped_run_continues_bit_for_bit_with_its_dissipation() {
    // The energy dissipated so far is part of the generalized-α scheme's
    // saved values and of the records' total energy.
    let base = replaced(
        &replaced(
            &text_of("dynamics/damped_oscillator.toml"),
            "integrator = \"newmark\"",
            "integrator = \"generalized-alpha\"",
        ),
        "t_end = 1.0",
        "t_end = T_END",
    );
    let short = replaced(&base, "T_END", "0.05");
    let long = replaced(&base, "T_END", "0.1");
    let mut sets = STATE.to_vec();
    sets.push("/energy/dissipated");
    assert_eq!(continued_vs_uninterrupted(&short, &long, &sets), 0.0);
}
