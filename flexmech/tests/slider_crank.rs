//! The slider-crank of `data/benchmarks/slider_crank.toml` against rigid-body
//! mechanics: the slider follows `x_C(θ) = r cos θ + √(l² − r² sin² θ)` and
//! the ground's normal force on it is the slider mass's inertia force turned
//! by the rod, `N = M ẍ_C tan φ` (the light rod is a two-force member: its
//! pull on the slider, along the rod, has `x` part `M ẍ_C`, so its `y` part
//! is `−M ẍ_C tan φ`, which the guide balances).

use std::f64::consts::PI;
use std::path::Path;

use flexmech::model::load_model;
use flexmech::results::run_model_to;
use flexmech::results::ResultReader;

const R: f64 = 0.15;
const L: f64 = 0.30;
const M: f64 = 2.0;
const OMEGA: f64 = 2.0 * PI;
/// The start transient is gone by then (measured: 50 steps).
const SETTLED: f64 = 0.05;

/// `x_C`, `dx_C/dθ`, `d²x_C/dθ²` and `tan φ` at crank angle `θ`.
fn kinematics(th: f64) -> (f64, f64, f64, f64) {
    let (s, c) = th.sin_cos();
    let q = (L * L - R * R * s * s).sqrt();
    let x = R * c + q;
    let dx = -R * s - R * R * s * c / q;
    let d2x = -R * c - R * R * (c * c - s * s) / q - R.powi(4) * s * s * c * c / q.powi(3);
    let sin_phi = R * s / L;
    (x, dx, d2x, sin_phi / (1.0 - sin_phi * sin_phi).sqrt())
}

#[test]
fn the_slider_follows_the_crank_and_pushes_on_its_guide() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/benchmarks/slider_crank.toml");
    let model = load_model(&path).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("slider-crank.h5");
    let summary = run_model_to(&model, &file).unwrap();
    assert!(summary.warnings.is_empty(), "{:?}", summary.warnings);
    let r = ResultReader::open(&file).unwrap();
    let t = r.time().unwrap();
    let x = r.values("/nodes/block.start/position").unwrap();
    let reaction = r.values("/supports/ground.slide/reaction_force").unwrap();
    let (mut worst_x, mut worst_n, mut scale_n): (f64, f64, f64) = (0.0, 0.0, 0.0);
    for k in 1..t.len() {
        let th = OMEGA * t[k];
        let (xc, _, d2x, tan_phi) = kinematics(th);
        worst_x = worst_x.max((x[3 * k] - xc).abs());
        let normal = M * OMEGA * OMEGA * d2x * tan_phi;
        // The start: the solver's initial accelerations leave out the
        // velocity terms (the slider's centripetal ẍ), and the stiff links
        // ring for a few steps until generalized-α's damping removes it.
        if t[k] >= SETTLED {
            worst_n = worst_n.max((reaction[3 * k + 1] - normal).abs());
        }
        scale_n = scale_n.max(normal.abs());
    }
    eprintln!("slider: |Δx| ≤ {worst_x:.2e}, |ΔN| ≤ {worst_n:.3e} of max |N| {scale_n:.3}");
    // The links stretch by ~1e-7 under these forces (EA = 1e8); their mass
    // (1e-3 per metre) and vibration ride on the slider's force.
    assert!(worst_x < 1e-6, "slider position off by {worst_x:e}");
    assert!(
        worst_n < 1e-3 * scale_n,
        "normal force off by {worst_n:e} (max {scale_n})"
    );
}
