//! The benchmark models of `data/benchmarks/` run through the library exactly
//! as `flexmech run` runs them, and their result files are checked against
//! analytic solutions and published values.

use crate::common;
use flexmech::cli::benchmarks::reference::{numbers, ELASTICA, PRINCETON};
use flexmech::model::{load_model, parse_model, Model};
use flexmech::results::run_model;
use std::path::{Path, PathBuf};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../data/benchmarks")
        .join(name)
}

/// A time series of a result file, as rows of `width` values.
fn read(file: &Path, dataset: &str, width: usize) -> Vec<Vec<f64>> {
    let flat = common::read(file, dataset);
    flat.chunks(width).map(<[f64]>::to_vec).collect()
}

fn status(file: &Path) -> String {
    common::reader(file).status().unwrap()
}

/// The benchmark file `name` with its (single) beam re-meshed into `elements`
/// elements of `npe` nodes — edited in the text, so that node labels such as
/// `bend.end` resolve in the new mesh.
fn remeshed(name: &str, elements: usize, npe: usize) -> Model {
    let text = std::fs::read_to_string(data(name)).unwrap();
    let mut out = String::new();
    for line in text.lines() {
        if line.starts_with("elements = ") {
            out.push_str(&format!(
                "elements = {elements}\nnodes_per_element = {npe}\n"
            ));
        } else if !line.starts_with("nodes_per_element") {
            out.push_str(line);
            out.push('\n');
        }
    }
    parse_model(&out, &data(name)).unwrap()
}

/// Runs `model` into a fresh directory; returns the result file and the
/// directory guard.
fn solve(model: Model) -> (PathBuf, tempfile::TempDir) {
    let dir = tempfile::tempdir().unwrap();
    let summary = run_model(&model, dir.path()).unwrap();
    assert_eq!(status(&summary.file), "completed");
    (summary.file, dir)
}

/// Tip displacement at load factor `lambda` (which must be a stored step).
fn tip_at(file: &Path, label: &str, lambda: f64) -> [f64; 3] {
    let times = read(file, "/time", 1);
    let k = times
        .iter()
        .position(|t| (t[0] - lambda).abs() < 1e-12)
        .unwrap_or_else(|| panic!("no step at {lambda}: {times:?}"));
    let d = read(file, &format!("/nodes/{label}/displacement"), 3);
    [d[k][0], d[k][1], d[k][2]]
}

fn max_diff(a: [f64; 3], b: [f64; 3]) -> f64 {
    (0..3).map(|i| (a[i] - b[i]).abs()).fold(0.0, f64::max)
}

#[test]
fn rollup_returns_the_tip_to_the_clamp() {
    for file in ["rollup_linear.toml", "rollup_quadratic.toml"] {
        let model = load_model(&data(file)).unwrap();
        let (out, _dir) = solve(model);
        let pos = read(&out, "/nodes/strip.end/position", 3);
        let tip = pos.last().unwrap();
        let dist = (tip[0].powi(2) + tip[1].powi(2) + tip[2].powi(2)).sqrt();
        assert!(
            dist <= 1e-8 * 10.0,
            "{file}: tip {tip:?} is {dist:e} from the clamp"
        );
        // Strain energy of the closed circle: ½·EI·(2π/L)²·L.
        let e = read(&out, "/energy/strain", 1);
        let exact = 0.5 * 100.0 * (2.0 * std::f64::consts::PI / 10.0f64).powi(2) * 10.0;
        assert!((e.last().unwrap()[0] - exact).abs() <= 1e-8 * exact);
        // Every stored step converged below the model's tolerance.
        assert!(read(&out, "/solver/residual", 1)
            .iter()
            .all(|r| r[0] <= 1e-10));
    }
}

/// Converged rod solution of the 45° bend at P = 600 (tip displacement).
const BEND_CONVERGED: [f64; 3] = [-13.73, -23.81, 53.61];
/// Bathe and Bolourchi's published 8-element tip displacement at P = 600.
const BEND_PUBLISHED_8: [f64; 3] = [-13.4, -23.5, 53.4];

#[test]
fn bathe_bolourchi_bend_converges_to_the_reference() {
    let mut errors = Vec::new();
    let mut tips = Vec::new();
    for n in [8, 16, 32] {
        let (out, _dir) = solve(remeshed("bathe_bolourchi.toml", n, 2));
        let tip = tip_at(&out, "bend.end", 1.0);
        errors.push(max_diff(tip, BEND_CONVERGED));
        tips.push(tip);
    }
    // 16 elements are within 0.1 per component of the converged solution.
    assert!(
        errors[1] <= 0.1,
        "16 elements: tip {:?}, error {}",
        tips[1],
        errors[1]
    );
    // Refinement approaches it (the two values' remaining gap, ~0.01, is the
    // rounding of the quoted reference).
    assert!(
        errors[0] > errors[1] && errors[2] <= errors[1] + 0.01,
        "errors {errors:?}"
    );
    // The published 8-element values lie about 0.3 from the converged ones;
    // ours with 8 elements are closer to the converged solution than that.
    assert!(
        max_diff(tips[0], BEND_PUBLISHED_8) <= 0.35,
        "8 elements: {:?}",
        tips[0]
    );
    assert!(errors[0] <= 0.3);
}

#[test]
fn bathe_bolourchi_bend_at_intermediate_loads() {
    // Load factors 0.5 and 0.75 are P = 300 and 450. Two different
    // discretisations — 64 linear and 16 quadratic elements — must agree on
    // the converged tip, and 16 linear elements lie within 0.1 of it.
    let (fine, _a) = solve(remeshed("bathe_bolourchi.toml", 64, 2));
    let (quad, _b) = solve(remeshed("bathe_bolourchi.toml", 16, 3));
    let (coarse, _c) = solve(remeshed("bathe_bolourchi.toml", 16, 2));
    for lambda in [0.5, 0.75] {
        let f = tip_at(&fine, "bend.end", lambda);
        let q = tip_at(&quad, "bend.end", lambda);
        let c = tip_at(&coarse, "bend.end", lambda);
        assert!(
            max_diff(f, q) <= 0.02,
            "P = {}: linear {f:?} vs quadratic {q:?}",
            600.0 * lambda
        );
        assert!(
            max_diff(c, f) <= 0.1,
            "P = {}: 16 elements {c:?} vs 64 {f:?}",
            600.0 * lambda
        );
        // The out-of-plane deflection grows monotonically with the load.
        assert!(f[2] > 0.0 && f[0] < 0.0 && f[1] < 0.0);
    }
    let z: Vec<f64> = [0.5, 0.75, 1.0]
        .iter()
        .map(|&l| tip_at(&fine, "bend.end", l)[2])
        .collect();
    assert!(z[0] < z[1] && z[1] < z[2]);
}

/// `∫₀^φ f(√(1 − k² sin² t)) dt` by composite Simpson's rule (the
/// integrands are smooth for k < 1: 4 000 intervals give round-off).
fn elliptic(phi: f64, k: f64, f: impl Fn(f64) -> f64) -> f64 {
    const INTERVALS: usize = 4000;
    let h = phi / INTERVALS as f64;
    let g = |t: f64| f((1.0 - k * k * t.sin().powi(2)).sqrt());
    let inner: f64 = (1..INTERVALS)
        .map(|i| g(i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 })
        .sum();
    (g(0.0) + inner + g(phi)) * h / 3.0
}

/// The exact elastica of a cantilever under a perpendicular dead tip force,
/// `λ = PL²/EI`: `(w/L, u/L)` (Bisshopp & Drucker 1945; see
/// `data/benchmarks/elastica.toml`), the tip rotation found by bisection.
fn elastica(lambda: f64) -> (f64, f64) {
    let parts = |theta0: f64| {
        let k = ((1.0 + theta0.sin()) / 2.0).sqrt();
        let phi1 = (1.0 / (2f64.sqrt() * k)).asin();
        let half = std::f64::consts::FRAC_PI_2;
        let f = elliptic(half, k, |d| 1.0 / d) - elliptic(phi1, k, |d| 1.0 / d);
        let e = elliptic(half, k, |d| d) - elliptic(phi1, k, |d| d);
        (f, e)
    };
    let (mut lo, mut hi) = (0.0, std::f64::consts::FRAC_PI_2 - 1e-12);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if parts(mid).0 < lambda.sqrt() {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let theta0 = 0.5 * (lo + hi);
    let (_, e) = parts(theta0);
    let w = 1.0 - 2.0 / lambda.sqrt() * e;
    let u = 1.0 - (2.0 * theta0.sin() / lambda).sqrt();
    (w, u)
}

#[test]
fn the_elastica_follows_the_exact_solution_to_lambda_16() {
    // The exact solution as evaluated here, against Mattiasson's published
    // table (five digits: half a unit of the last digit).
    let published = numbers(ELASTICA);
    assert_eq!(published.len(), 4);
    for &[lambda, w, u] in published
        .iter()
        .map(|r| <&[f64; 3]>::try_from(&r[..]).unwrap())
    {
        let (we, ue) = elastica(lambda);
        assert!(
            (we - w).abs() <= 5e-6 && (ue - u).abs() <= 5e-6,
            "λ = {lambda}: ({we}, {ue})"
        );
    }
    // The run at every stored load factor. Sixteen 3-node elements: the
    // discretisation error of the tip is ~1e-6 of L (fourth order in the
    // element size); the stiff axial and shear terms add 1e-7.
    let (file, _dir) = solve(load_model(&data("elastica.toml")).unwrap());
    assert_eq!(status(&file), "completed");
    let lambda: Vec<f64> = common::read(&file, "/time")
        .iter()
        .map(|t| 16.0 * t)
        .collect();
    let d = read(&file, "/nodes/rod.end/displacement", 3);
    let mut worst = 0.0f64;
    for (l, d) in lambda.iter().zip(&d).filter(|(l, _)| **l > 0.0) {
        let (w, u) = elastica(*l);
        worst = worst.max((-d[2] - w).abs()).max((-d[0] - u).abs());
    }
    eprintln!("elastica: largest tip error over λ ∈ (0, 16]: {worst:.2e} L");
    assert!(worst < 1e-5, "{worst}");
    assert_eq!(lambda.last(), Some(&16.0));
}

#[test]
fn the_princeton_beam_meets_the_reference_tip_deflections() {
    // Tolerance from the reference: its section's torsion constant and
    // shear correction are idealised (0.198 G(I_y + I_z), none) and its
    // element is another code's; the independent code whose suite quotes it,
    // given the same data, differs from it by 1.3e-3 of the tip deflection
    // |u| at F = 8.896, β = 45° (as flexmech does: 1.3e-3). 1 % of |u| per
    // component (observed at most 5.7e-3, at F = 13.345, β = 15°, where
    // the twist couples the two bending planes most).
    let text = std::fs::read_to_string(data("princeton_beam.toml")).unwrap();
    let line = "force = [0.0, -6.290421925435528, 6.290421925435528]";
    assert!(text.contains(line));
    // The reference table (`data/benchmarks/reference/princeton_reference.csv`):
    // force, β in degrees, the tip's −y and z.
    let table = numbers(PRINCETON);
    assert_eq!(table.len(), 14);
    let mut worst = 0.0f64;
    for row in &table {
        let (force, beta, y, z) = (row[0], row[1].to_radians(), row[2], row[3]);
        let f = format!(
            "force = [0.0, {:?}, {:?}]",
            -force * beta.cos(),
            force * beta.sin()
        );
        let model = parse_model(&text.replace(line, &f), &data("princeton_beam.toml")).unwrap();
        let (file, _dir) = solve(model);
        let u = tip_at(&file, "strip.end", 1.0);
        let scale = (y * y + z * z).sqrt();
        let error = (-u[1] - y).abs().max((u[2] - z).abs()) / scale;
        worst = worst.max(error);
    }
    assert!(worst < 1e-2, "{worst}");
}

/// An independent run stored in `data/benchmarks/reference/<name>`: rows
/// `[t, ux, uy, uz]`.
fn twin_rows(name: &str) -> Vec<[f64; 4]> {
    let text = std::fs::read_to_string(data(&format!("reference/{name}"))).unwrap();
    text.lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("t,"))
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
            [v[0], v[1], v[2], v[3]]
        })
        .collect()
}

/// Largest excursion, root mean square and mean of component `c` of the
/// rows of `u` (times `t`) in the window `(a, b]`.
fn window_stats(t: &[f64], u: &[[f64; 3]], c: usize, (a, b): (f64, f64)) -> [f64; 3] {
    let w: Vec<f64> = t
        .iter()
        .zip(u)
        .filter(|(&t, _)| t > a + 1e-9 && t <= b + 1e-9)
        .map(|(_, u)| u[c])
        .collect();
    let n = w.len() as f64;
    [
        w.iter().fold(0.0, |m, x| f64::max(m, x.abs())),
        (w.iter().map(|x| x * x).sum::<f64>() / n).sqrt(),
        w.iter().sum::<f64>() / n,
    ]
}

/// The 2016 benchmark's authors' stored run (mid-span node): before
/// buckling `[t, ux, uz]`; after it, per window `[a, b, max |uy|, rms uy,
/// mean uz]`.
const AUTHORS_PRE_BUCKLING: [[f64; 3]; 7] = [
    [0.02, -1.19209e-07, 3.01772e-04],
    [0.04, -1.78814e-06, 1.20089e-03],
    [0.06, -8.85129e-06, 2.66515e-03],
    [0.08, -2.64943e-05, 4.62014e-03],
    [0.10, -5.94556e-05, 6.93259e-03],
    [0.12, -1.08510e-04, 9.38388e-03],
    [0.14, -1.67012e-04, 1.16712e-02],
];
const AUTHORS_WINDOWS: [[f64; 5]; 3] = [
    [0.2, 0.3, 4.52560e-02, 2.57674e-02, 6.90286e-03],
    [0.3, 0.4, 3.60291e-02, 2.42904e-02, -3.01020e-03],
    [0.4, 0.5, 3.42274e-02, 2.27687e-02, -5.22945e-03],
];

/// Problem 3 of the 2016 benchmark set (lateral buckling of a strip driven
/// through a link and crank), against an independent code's run of the
/// same model (step by step) and the authors' stored run (before buckling
/// step by step, after it by windowed statistics). Tolerances: before
/// buckling the two codes' formulations differ at 1e-7 m (their log is
/// single precision); through the buckling and the first swings (to
/// 0.25 s) 2.5e-3 m laterally and 5e-4 m otherwise, what the independent
/// code's own result moves when its strip mesh is refined (2.6e-3, 4.4e-4);
/// after 0.25 s the swings drift in phase, so the windows' largest and rms
/// lateral excursions and mean vertical displacement are compared, within
/// 5 % of the swing (observed 2 %). The authors' run seeds its buckling by
/// its Newton residuals (see the model file): 0.2 % before buckling (its
/// tolerance), 10 % for the windows' statistics (observed 8 %).
#[test]
fn the_lateral_buckling_of_the_strip_follows_an_independent_code() {
    let (file, _dir) = solve(load_model(&data("lateral_buckling.toml")).unwrap());
    let t: Vec<f64> = read(&file, "/time", 1).iter().map(|r| r[0]).collect();
    let u: Vec<[f64; 3]> = read(&file, "/nodes/strip.10/displacement", 3)
        .iter()
        .map(|r| [r[0], r[1], r[2]])
        .collect();
    let at = |time: f64| u[t.iter().position(|&s| (s - time).abs() < 1e-9).unwrap()];
    let twin = twin_rows("lateral_buckling_twin.csv");
    assert_eq!(twin.len(), 251);
    for row in &twin {
        let ours = at(row[0]);
        let bounds = match row[0] {
            s if s <= 0.14 + 1e-9 => [1e-7, 1e-7, 1e-6],
            s if s <= 0.25 + 1e-9 => [5e-4, 2.5e-3, 5e-4],
            _ => continue,
        };
        for c in 0..3 {
            assert!(
                (ours[c] - row[c + 1]).abs() <= bounds[c],
                "t = {}: u[{c}] = {} vs the independent run's {}",
                row[0],
                ours[c],
                row[c + 1]
            );
        }
    }
    let twin_t: Vec<f64> = twin.iter().map(|r| r[0]).collect();
    let twin_u: Vec<[f64; 3]> = twin.iter().map(|r| [r[1], r[2], r[3]]).collect();
    for w in [(0.25, 0.35), (0.35, 0.5)] {
        let (o, r) = (
            window_stats(&t, &u, 1, w),
            window_stats(&twin_t, &twin_u, 1, w),
        );
        let (oz, rz) = (
            window_stats(&t, &u, 2, w),
            window_stats(&twin_t, &twin_u, 2, w),
        );
        assert!(
            (o[0] - r[0]).abs() < 0.05 * r[0],
            "{w:?}: max |uy| {o:?} vs {r:?}"
        );
        assert!(
            (o[1] - r[1]).abs() < 0.05 * r[0],
            "{w:?}: rms uy {o:?} vs {r:?}"
        );
        assert!(
            (oz[2] - rz[2]).abs() < 0.05 * r[0],
            "{w:?}: mean uz {oz:?} vs {rz:?}"
        );
    }
    for [time, ux, uz] in AUTHORS_PRE_BUCKLING {
        let ours = at(time);
        assert!(
            (ours[0] - ux).abs() < 2e-3 * uz.abs(),
            "t = {time}: ux {ours:?}"
        );
        assert!(
            (ours[2] - uz).abs() < 2e-3 * uz.abs(),
            "t = {time}: uz {ours:?}"
        );
    }
    for [a, b, max_y, rms_y, mean_z] in AUTHORS_WINDOWS {
        let y = window_stats(&t, &u, 1, (a, b));
        let z = window_stats(&t, &u, 2, (a, b));
        assert!(
            (y[0] - max_y).abs() < 0.1 * max_y,
            "({a}, {b}]: max |uy| {y:?}"
        );
        assert!(
            (y[1] - rms_y).abs() < 0.1 * rms_y,
            "({a}, {b}]: rms uy {y:?}"
        );
        assert!(
            (z[2] - mean_z).abs() < 0.1 * max_y,
            "({a}, {b}]: mean uz {z:?}"
        );
    }
}

/// Problem 4 of the 2016 benchmark set (the unbalanced shaft spun up
/// through its critical speed), against the same model in an independent
/// code, at every stored 2 ms. Tolerances: the two codes at the same mesh
/// against what the reference itself moves when the shaft's mesh is
/// doubled (2.2e-3 m to 0.5 s, 1.4e-2 m to 1.25 s, 8e-2 m to 2.5 s: the
/// free whirl's phase) — bounds 1e-3 m, 5e-3 m and 3e-2 m of whirl radii
/// up to 0.28 m (observed 2.4e-4, 2.4e-3, 1.7e-2); the steady whirl's
/// largest radius after 1.5 s within 2 % (observed 0.9 %).
#[test]
fn the_rotating_shaft_follows_an_independent_code() {
    let (file, _dir) = solve(load_model(&data("rotating_shaft.toml")).unwrap());
    let t: Vec<f64> = read(&file, "/time", 1).iter().map(|r| r[0]).collect();
    let u = read(&file, "/nodes/shaft.8/displacement", 3);
    let twin = twin_rows("rotating_shaft_twin.csv");
    assert_eq!(twin.len(), 1251);
    let (mut radius, mut twin_radius) = (0.0f64, 0.0f64);
    for row in &twin {
        let k = t.iter().position(|&s| (s - row[0]).abs() < 1e-9).unwrap();
        let bound = match row[0] {
            s if s <= 0.5 + 1e-9 => 1e-3,
            s if s <= 1.25 + 1e-9 => 5e-3,
            _ => 3e-2,
        };
        for c in 0..3 {
            assert!(
                (u[k][c] - row[c + 1]).abs() <= bound,
                "t = {}: u[{c}] = {} vs the independent run's {}",
                row[0],
                u[k][c],
                row[c + 1]
            );
        }
        if row[0] > 1.5 {
            radius = radius.max(u[k][1].hypot(u[k][2]));
            twin_radius = twin_radius.max(row[2].hypot(row[3]));
        }
    }
    assert!(
        (radius - twin_radius).abs() < 0.02 * twin_radius,
        "steady whirl radius {radius} vs {twin_radius}"
    );
}
