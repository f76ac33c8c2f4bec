//! Minimal reproducers of hostile or extreme model files: each is refused
//! with a located, readable error (the key, and what to change), never run
//! into a non-finite first record, a runaway step control or a megabyte of
//! echoed input.

use flexmech::model::build;
use flexmech::model::parse_model;
use flexmech::results::{run_model, RunError};
use std::path::Path;

fn chain() -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/dynamics/free_chain.toml");
    std::fs::read_to_string(path)
        .unwrap()
        .replace("t_end = 1.0", "t_end = 0.02")
}

/// The build error of `text` (it must parse and validate).
fn build_error(text: &str) -> String {
    let model = parse_model(text, Path::new("mutant.toml")).expect("the mutant validates");
    match build(&model) {
        Err(e) => e.to_string(),
        Ok(_) => panic!("expected a refusal"),
    }
}

fn once(text: &str, from: &str, to: &str) -> String {
    assert!(text.contains(from), "{from}");
    text.replacen(from, to, 1)
}

#[test]
fn overflowing_derived_quantities_are_refused_at_their_key() {
    // Each value is finite, but a product formed at t = 0 is not; once each
    // failed at its first step with "residual is not finite at iteration 0"
    // (or wrote inf into the first record).
    let base = chain();
    let cases = [
        (
            once(
                &base,
                "linear = [0.1, 0.3, -0.2]",
                "linear = [1e308, 0.3, -0.2]",
            ),
            "initial_velocity[0]",
        ),
        (
            once(
                &base,
                "angular = [0.4, -0.3, 1.5]",
                "angular = [0.4, -0.3, 1e200]",
            ),
            "initial_velocity[0]",
        ),
        (once(&base, "rhoA = 1.0", "rhoA = 1e308"), "section[0]"),
        (
            once(
                &base,
                "rhoJ = [0.02, 0.01, 0.01]",
                "rhoJ = [1e308, 0.01, 0.01]",
            ),
            "section[0]",
        ),
        (once(&base, "GJ = 60.0", "GJ = 1e308"), "section[0]"),
        (once(&base, "pitch = 0.02", "pitch = 1e308"), "joint[5]"),
        // A finite map N times a finite rate, squared in the kinetic energy:
        // once it completed with an infinite kinetic energy and NaN
        // velocities in the file.
        (once(&base, "rate = 1.0", "rate = 1e200"), "joint[1].rate"),
        (once(&base, "rate = 1.0", "rate = 1e308"), "joint[1].rate"),
        (
            once(
                &base,
                "lift = { fourier = [0.0, 0.0, 0.02] }",
                "lift = { fourier = [0.0, 0.0, 1e308, 1e308, 1e308] }",
            ),
            "joint[8]",
        ),
    ];
    for (text, key) in cases {
        let message = build_error(&text);
        assert!(
            message.starts_with(&format!("mutant.toml: key `{key}`")) && message.contains("finite"),
            "{key}: {message}"
        );
    }
}

#[test]
fn a_megabyte_key_is_quoted_by_its_head_and_length() {
    // Once echoed twice in full: a 2 MB error message.
    let text = once(
        &chain(),
        "[solver]",
        &format!("[solver]\n{} = 1", "k".repeat(1 << 20)),
    );
    let message = parse_model(&text, Path::new("mutant.toml"))
        .unwrap_err()
        .to_string();
    assert!(message.len() < 2000, "{} bytes", message.len());
    assert!(message.contains(" bytes)"), "{message}");
    assert!(message.starts_with("mutant.toml:"), "{message}");
}

#[test]
fn messages_name_what_the_file_should_hold_not_internal_types() {
    // Once: "invalid type: integer `1`, expected struct RawBeam".
    for text in [
        "name = \"x\"\nbeam = [1, 2]\n",
        "name = \"x\"\n[[section]]\nname = 1\n[[beam]]\nsection = [1]\n",
        "name = \"x\"\nsupport = [[1, 2]]\n",
    ] {
        let message = parse_model(text, Path::new("mutant.toml"))
            .unwrap_err()
            .to_string();
        assert!(
            !message.contains("Raw") && !message.contains("struct"),
            "{message}"
        );
    }
    let message = parse_model("name = \"x\"\nbeam = [1, 2]\n", Path::new("m.toml"))
        .unwrap_err()
        .to_string();
    assert!(message.contains("expected a table"), "{message}");
}

#[test]
fn static_step_control_stops_instead_of_creeping() {
    // Newton allowed two iterations on a strip rolled by an end moment:
    // only small steps converge. With the halving level once reset after
    // every success the load factor crept on in ever more sub-steps; now the
    // step never goes below 1/(load_steps·2^max_halvings), so the run has at
    // most load_steps·2^max_halvings steps, or stops saying what stalled.
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/benchmarks/rollup_linear.toml");
    let text = std::fs::read_to_string(path).unwrap().replace(
        "max_iterations = 30",
        "max_iterations = 2\nmax_halvings = 3",
    );
    assert!(text.contains("max_halvings = 3"));
    let model = parse_model(&text, Path::new("creep.toml")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    match run_model(&model, dir.path()) {
        Ok(summary) => assert!(summary.steps <= 10 * 8, "{} steps", summary.steps),
        Err(RunError::Solve { error, .. }) => {
            let message = error.to_string();
            assert!(
                message.contains("after 3 step halvings") && message.contains("above tolerance"),
                "{message}"
            );
        }
        Err(other) => panic!("{other}"),
    }
}

/// A stiff rod's section without mass (statics).
fn massless_rod() -> flexmech::model::SectionValues {
    flexmech::model::SectionValues {
        ea: 1e7,
        ga: [1e6; 2],
        gj: 1e3,
        ei: [1e3; 2],
        rho_a: 0.0,
        rho_j: [0.0; 3],
    }
}

/// A static run whose loads vanish — a beam turned rigidly by a driven
/// joint, no load, no gravity — converges at round-off; its recorded
/// residual must read as converged (the force scale is round-off itself,
/// which once recorded ≈ 0.8 per step).
#[test]
fn a_static_run_without_loads_records_a_converged_residual() {
    use flexmech::model::{BeamGeometry, Model};
    use flexmech::results::Memory;
    use nalgebra::Vector3;
    let rod = massless_rod();
    let arm = BeamGeometry::Straight {
        start: Vector3::zeros(),
        end: Vector3::x(),
        e2: Vector3::y(),
    };
    let model = Model::new("turned")
        .section("rod", rod)
        .beam("arm", "rod", arm, 4)
        .joint("pin", "revolute", "ground", "arm.start", "axis = [0, 0, 1]")
        .drive("pin", "t")
        .statics(4)
        .track("arm.end")
        .build()
        .unwrap();
    let mut memory = Memory::default();
    flexmech::results::run(&model, &mut memory).unwrap();
    let times: Vec<f64> = memory.time();
    assert_eq!(times.last(), Some(&1.0), "{times:?}");
    for r in &memory.records {
        assert!(
            r.residual <= model.solver.tolerance,
            "t = {}: {:e}",
            r.time,
            r.residual
        );
    }
    // The arm turned by the driven angle, 1 rad at the last load step.
    let tip = *memory.positions("arm.end").unwrap().last().unwrap();
    assert!(
        (tip[0] - 1f64.cos()).abs() < 1e-12 && (tip[1] - 1f64.sin()).abs() < 1e-12,
        "{tip:?}"
    );
}

#[test]
fn a_drive_that_does_not_start_at_the_joints_angle_is_refused() {
    // angle = 1.0 with a drive from 0: an impulsive jump of the angle at
    // t = 0 that no integrator can follow (it ended in an element "turning
    // by 2.4 rad" far from the cause).
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/paper/cam.toml");
    let text = std::fs::read_to_string(path)
        .unwrap()
        .replace("offset = 0.02 ", "angle = 1.0\noffset = 0.02 ");
    let e = parse_model(&text, Path::new("jump.toml"))
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("jump.toml:") && e.contains("key `prescribed[0].angle`"),
        "{e}"
    );
    assert!(
        e.contains("angle 0 at t = 0") && e.contains("angle = 1"),
        "{e}"
    );
}

/// An arm hinged to a post about its own axis spins freely: the refusal
/// names the arm (the beam whose nodes move), the hinge and the fix, not
/// only node labels.
#[test]
fn a_beam_free_to_spin_about_its_axis_is_refused_naming_the_beam() {
    use flexmech::model::{BeamGeometry, Model};
    use flexmech::results::Memory;
    use nalgebra::Vector3;
    let rod = massless_rod();
    let straight = |start: Vector3<f64>, end: Vector3<f64>| BeamGeometry::Straight {
        start,
        end,
        e2: Vector3::y(),
    };
    let top = Vector3::new(0.0, 0.0, 1.0);
    let model = Model::new("spinning-arm")
        .section("rod", rod)
        .beam("post", "rod", straight(Vector3::zeros(), top), 2)
        .beam("arm", "rod", straight(top, top + Vector3::x()), 4)
        .support("post.start", "all")
        .joint(
            "hinge",
            "revolute",
            "post.end",
            "arm.start",
            "axis = [1, 0, 0]",
        )
        .load("arm.end", [0.0, 0.0, -1.0], [0.0; 3])
        .statics(2)
        .build()
        .unwrap();
    let err = flexmech::results::run(&model, &mut Memory::default())
        .unwrap_err()
        .to_string();
    assert!(err.contains("not held"), "{err}");
    assert!(err.contains("of beam(s) \"arm\""), "{err}");
    assert!(!err.contains("\"post\""), "the post is held: {err}");
    assert!(err.contains("\"hinge\""), "{err}");
    // A run kept in memory has no result file to point to.
    assert!(!err.contains("steps computed so far"), "{err}");
}
