//! Follower loads in model files: the cantilever of
//! `data/statics/follower_tip_force.toml` against the elastica's tip (from
//! an independent integration, see the file), and a follower load's work in
//! the energy balance of a dynamic run with every integrator (the run's
//! check, and the result file's `energy_drift`, where minus the follower
//! work stands for the potential these loads do not have).

use std::path::{Path, PathBuf};

use flexmech::model::parse_model;
use flexmech::results::run_model_to;
use flexmech::results::ResultReader;

/// The elastica's tip under the normal tip force (see the model file).
const ELASTICA_TIP: [f64; 2] = [0.55166, 0.72668];

fn file() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/statics/follower_tip_force.toml")
}

#[test]
fn the_follower_cantilever_reaches_the_elastica() {
    let path = file();
    let text = std::fs::read_to_string(&path).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let model = parse_model(&text, &path).unwrap();
    let out = dir.path().join("f.h5");
    let summary = run_model_to(&model, &out).unwrap();
    assert!(summary.warnings.is_empty(), "{:?}", summary.warnings);
    let x = ResultReader::open(&out)
        .unwrap()
        .values("/nodes/arm.end/position")
        .unwrap();
    let tip = &x[x.len() - 3..];
    let err = ((tip[0] - ELASTICA_TIP[0]).powi(2) + (tip[1] - ELASTICA_TIP[1]).powi(2)).sqrt();
    // The reference carries 5 decimals; the beam's discretisation error is
    // ~2e-4 (see the file).
    assert!(err < 5e-4, "tip {tip:?}, elastica {ELASTICA_TIP:?}");
    // Not refused, and different from the dead load.
    let dead = parse_model(&text.replace("follower = true", "follower = false"), &path).unwrap();
    run_model_to(&dead, &out).unwrap();
    let x = ResultReader::open(&out)
        .unwrap()
        .values("/nodes/arm.end/position")
        .unwrap();
    assert!(
        (x[x.len() - 3] - tip[0]).abs() > 0.1,
        "dead {:?}",
        &x[x.len() - 3..]
    );
}

#[test]
fn a_follower_loads_work_enters_the_energy_balance() {
    // The same cantilever in motion under a follower tip force ramped in
    // over 0.2 s and held (and a follower line load along it): non-
    // conservative, so the balance holds only with the follower work
    // counted. Every integrator completes without an energy warning.
    let path = file();
    let text = std::fs::read_to_string(&path)
        .unwrap()
        .replace(
            "follower = true                      # turns with the tip",
            "follower = true\ntime = { expr = \"min(t/0.2, 1)\" }\n\n[[distributed_load]]\nbeam = \"arm\"\nforce = [0.0, 0.0, 0.5]\nfollower = true",
        )
        .replace(
            "analysis = \"static\"\nload_steps = 6",
            "analysis = \"dynamic\"\nintegrator = \"INTEGRATOR\"\ndt = 0.002\nt_end = 0.6",
        );
    let dir = tempfile::tempdir().unwrap();
    for integrator in [
        "newmark",
        "generalized-alpha",
        "momentum",
        "energy-momentum",
        "energy-momentum-paper",
    ] {
        let model = parse_model(&text.replace("INTEGRATOR", integrator), &path).unwrap();
        let out = dir.path().join(format!("{integrator}.h5"));
        let summary = run_model_to(&model, &out).unwrap();
        let r = ResultReader::open(&out).unwrap();
        let drift = r.energy_drift().unwrap();
        eprintln!("{integrator}: energy drift {drift:.2e}");
        // Kinetic + strain energy − the follower loads' work (the records'
        // total) is kept to the schemes' accuracy: measured 3.8e-6 (Newmark),
        // 3.6e-6 (generalized-α), 2.9e-6 (momentum), 6.7e-8 (energy–momentum)
        // of the energy.
        assert!(drift < 1e-4, "{integrator}: energy drift {drift:e}");
        assert!(
            summary.warnings.is_empty(),
            "{integrator}: {:?}",
            summary.warnings
        );
    }
}
