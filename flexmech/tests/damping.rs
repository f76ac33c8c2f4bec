//! `damping` in a `[[section]]`: the damped oscillator of
//! `data/dynamics/damped_oscillator.toml` against `x(t)`, its dissipated
//! energy in the result file and the balance, and the midpoint schemes'
//! refusal at the key.

use std::path::{Path, PathBuf};

use flexmech::model::build;
use flexmech::model::parse_model;
use flexmech::results::run_model_to;
use flexmech::results::ResultReader;

fn file() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/dynamics/damped_oscillator.toml")
}

#[test]
fn the_damped_oscillator_decays_and_reports_its_dissipation() {
    let path = file();
    let text = std::fs::read_to_string(&path).unwrap();
    let dir = tempfile::tempdir().unwrap();
    for integrator in ["newmark", "generalized-alpha"] {
        let model = parse_model(
            &text.replace(
                "integrator = \"newmark\"",
                &format!("integrator = \"{integrator}\""),
            ),
            &path,
        )
        .unwrap();
        let out = dir.path().join(format!("{integrator}.h5"));
        let summary = run_model_to(&model, &out).unwrap();
        assert!(summary.warnings.is_empty(), "{:?}", summary.warnings);
        let r = ResultReader::open(&out).unwrap();
        let (t, x) = (
            r.time().unwrap(),
            r.values("/nodes/bar.end/position").unwrap(),
        );
        let (omega, zeta, v0) = (10.0f64, 0.05f64, 0.5);
        let wd = omega * (1.0 - zeta * zeta).sqrt();
        let worst = t
            .iter()
            .enumerate()
            .map(|(k, &t)| {
                let exact = v0 / wd * (-zeta * omega * t).exp() * (wd * t).sin();
                (x[3 * k] - 1.0 - exact).abs()
            })
            .fold(0.0, f64::max);
        let dissipated = r.values("/energy/dissipated").unwrap();
        let e0 = 0.5 * 4.0 * v0 * v0;
        eprintln!(
            "{integrator}: |x − x_exact| ≤ {worst:.2e}, dissipated {:.4} of {e0}",
            dissipated.last().unwrap()
        );
        // First order in the damping (Δt ωζ ~ 5e-4 per unit of ωt).
        assert!(worst < 4e-3 * v0 / omega, "{integrator}: {worst:e}");
        // e^{−2ζωt} over 1 s leaves e^{−1} of the energy: most dissipated.
        assert!(*dissipated.last().unwrap() > 0.6 * e0, "{dissipated:?}");
        // The work of the damping forces in the scheme's own balance (the
        // trapezoidal rule on both ends of each step): what the motion
        // lost. Each step's share is the physical `η ε̇ C ε̇ Δt ≥ 0` up to the
        // rule's O(Δt³), which shows only at the velocity's reversals
        // (−5e-9 where a step's share reaches 1e-3).
        let (k, s) = (
            r.values("/energy/kinetic").unwrap(),
            r.values("/energy/strain").unwrap(),
        );
        let lost = e0 - k.last().unwrap() - s.last().unwrap();
        let last = *dissipated.last().unwrap();
        assert!(
            (last - lost).abs() < 1e-4 * e0,
            "{integrator}: {last} against {lost}"
        );
        let largest = dissipated
            .windows(2)
            .map(|w| w[1] - w[0])
            .fold(0.0, f64::max);
        assert!(dissipated.windows(2).all(|w| w[1] >= w[0] - 1e-5 * largest));
        let drift = r.energy_drift().unwrap();
        assert!(drift < 2e-3, "{integrator}: energy drift {drift:e}");
    }
    // The midpoint schemes refuse it at the section's key.
    let model = parse_model(
        &text.replace("integrator = \"newmark\"", "integrator = \"momentum\""),
        &path,
    )
    .unwrap();
    let Err(e) = build(&model) else {
        panic!("expected a refusal")
    };
    let e = e.to_string();
    assert!(
        e.contains("section[0].damping") && e.contains("newmark"),
        "{e}"
    );
    let e = parse_model(&text.replace("damping = 0.01", "damping = -0.01"), &path)
        .unwrap_err()
        .to_string();
    assert!(e.contains("section[0].damping"), "{e}");
}
