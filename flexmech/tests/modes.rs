//! Linearised analysis from model files: vibration modes (`analysis =
//! "modal"`) against the closed forms of beam theory, and linear buckling
//! (`analysis = "buckling"`) against Euler's column and the Argyris frame's
//! published lateral buckling load. Results are read back from `/modes` and
//! `/buckling`.

use crate::common::{data, read};
use flexmech::model::parse_model;
use flexmech::results::run_model;
use std::f64::consts::{PI, TAU};
use std::path::{Path, PathBuf};

/// A straight beam of length 1 along x with `elements` 3-node elements,
/// its `[solver]` and any extra tables.
fn beam_model(section: &str, supports: &str, solver: &str, elements: usize) -> String {
    format!(
        r#"name = "beam"
[[section]]
name = "s"
{section}
[[beam]]
name = "b"
section = "s"
start = [0.0, 0.0, 0.0]
end = [1.0, 0.0, 0.0]
e2 = [0.0, 1.0, 0.0]
elements = {elements}
nodes_per_element = 3
{supports}
[solver]
{solver}
"#
    )
}

/// A slender section: `EI = 1e3`, `ρA = 1`; shear, axial and rotary
/// inertia effects below 1e-6 of the bending frequencies.
const SLENDER: &str = "EA = 1e10\nGA = [1e10, 1e10]\nGJ = 1e3\nEI = [1e3, 1e3]\nrhoA = 1.0\nrhoJ = [1e-9, 1e-9, 1e-9]";

/// The 3-node element's discretisation error at these meshes: fourth order
/// in the element size (the integrators' convergence test), 2·10⁻⁵ for the
/// third bending root on 24 elements and 1.4·10⁻⁵ for the column's load on
/// 16; axial and torsional modes converge faster.
const DISCRETISATION: f64 = 3e-5;

fn run(text: &str) -> (tempfile::TempDir, PathBuf) {
    let model = parse_model(text, Path::new("beam.toml")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let summary = run_model(&model, dir.path()).unwrap();
    (dir, summary.file)
}

fn assert_close(found: f64, exact: f64, tol: f64, what: &str) {
    assert!(
        (found - exact).abs() <= tol * exact.abs(),
        "{what}: {found} vs {exact} (relative {:.2e})",
        (found - exact).abs() / exact.abs()
    );
}

/// Euler–Bernoulli: `f = (βL)² √(EI/ρA L⁴) / 2π`.
fn bending(beta_l: f64) -> f64 {
    beta_l * beta_l * 1e3f64.sqrt() / TAU
}

#[test]
fn cantilever_modes_are_euler_bernoulli_with_unit_mass_norm() {
    let text = beam_model(
        SLENDER,
        "[[support]]\nnode = \"b.start\"\nfixed = \"all\"",
        "analysis = \"modal\"\nmodes = 6",
        24,
    );
    let (_dir, file) = run(&text);
    let f = read(&file, "/modes/frequency");
    assert_eq!(f.len(), 6);
    for (i, bl) in [1.875_104_068_7, 4.694_091_132_9, 7.854_757_438_2]
        .iter()
        .enumerate()
    {
        for k in [2 * i, 2 * i + 1] {
            assert_close(f[k], bending(*bl), DISCRETISATION, &format!("mode {k}"));
        }
    }
    // Unit mass norm: ∫ρA φ² = 1 puts the tip of the first mode at
    // 2/√(ρA L) (the cantilever's φ(L)/‖φ‖ = 2).
    let u = read(&file, "/modes/displacement");
    let nodes = u.len() / (6 * 3);
    let tip = 3 * (nodes - 1);
    let tip_norm = (u[tip].powi(2) + u[tip + 1].powi(2) + u[tip + 2].powi(2)).sqrt();
    assert_close(tip_norm, 2.0, 1e-5, "tip of mode 1");
    assert_eq!(read(&file, "/modes/rotation").len(), u.len());
}

#[test]
fn axial_and_torsional_cantilever_modes_are_exact_to_discretisation() {
    // Stiff in bending: the lowest modes are axial, f = (2n−1)/4 √(EA/ρA),
    // and torsional, f = (2n−1)/4 √(GJ/ρJ₁).
    let section = "EA = 4.0\nGA = [1e6, 1e6]\nGJ = 9.0\nEI = [1e6, 1e6]\nrhoA = 1.0\nrhoJ = [1.0, 1e-3, 1e-3]";
    let text = beam_model(
        section,
        "[[support]]\nnode = \"b.start\"\nfixed = \"all\"",
        "analysis = \"modal\"\nmodes = 4",
        24,
    );
    let (_dir, file) = run(&text);
    let f = read(&file, "/modes/frequency");
    let mut exact = [0.25 * 2.0, 0.75 * 2.0, 0.25 * 3.0, 0.75 * 3.0];
    exact.sort_by(f64::total_cmp);
    for (k, e) in exact.iter().enumerate() {
        assert_close(f[k], *e, 2e-6, &format!("mode {k}"));
    }
}

#[test]
fn free_free_beam_has_six_rigid_modes_then_euler_bernoulli() {
    let text = beam_model(SLENDER, "", "analysis = \"modal\"\nmodes = 8", 24);
    let (_dir, file) = run(&text);
    let f = read(&file, "/modes/frequency");
    assert!(f[..6].iter().all(|v| *v == 0.0), "{f:?}");
    assert_close(
        f[6],
        bending(4.730_040_744_9),
        DISCRETISATION,
        "first elastic",
    );
    assert_close(
        f[7],
        bending(4.730_040_744_9),
        DISCRETISATION,
        "first elastic, other plane",
    );
    assert_eq!(number_attr(&file, "/modes", "rigid_modes"), 6.0);
}

#[test]
fn pinned_pinned_beam_has_frequencies_n_squared_pi_squared() {
    let supports = "[[support]]\nnode = \"b.start\"\nfixed = [\"ux\", \"uy\", \"uz\", \"rx\"]\n\
                    [[support]]\nnode = \"b.end\"\nfixed = [\"uy\", \"uz\"]";
    let text = beam_model(SLENDER, supports, "analysis = \"modal\"\nmodes = 4", 24);
    let (_dir, file) = run(&text);
    let f = read(&file, "/modes/frequency");
    for (k, n) in [1.0, 1.0, 2.0, 2.0].iter().enumerate() {
        assert_close(f[k], bending(n * PI), DISCRETISATION, &format!("mode {k}"));
    }
}

/// A numeric attribute of a group.
fn number_attr(file: &Path, group: &str, name: &str) -> f64 {
    let f = hdf5::File::open(file).unwrap();
    f.group(group)
        .unwrap()
        .attr(name)
        .unwrap()
        .read_scalar::<f64>()
        .unwrap()
}

#[test]
fn clamped_free_column_buckles_at_euler_load_in_both_planes() {
    let supports = "[[support]]\nnode = \"b.start\"\nfixed = \"all\"\n\
                    [[load]]\nnode = \"b.end\"\nforce = [-1.0, 0.0, 0.0]";
    let section = "EA = 1e10\nGA = [1e10, 1e10]\nGJ = 1e3\nEI = [1e3, 2e3]\nrhoA = 1.0\nrhoJ = [1e-3, 1e-3, 1e-3]";
    let text = beam_model(section, supports, "analysis = \"buckling\"\nmodes = 2", 16);
    let (_dir, file) = run(&text);
    let l = read(&file, "/buckling/load_factor");
    assert_close(l[0], PI * PI * 1e3 / 4.0, DISCRETISATION, "weak plane");
    assert_close(l[1], PI * PI * 2e3 / 4.0, DISCRETISATION, "strong plane");
}

#[test]
fn argyris_frame_buckling_load_is_the_published_one() {
    // Published P_cr = 1.088 (Argyris et al. 1979; Simo & Vu-Quoc 1986); the
    // file's load is P = 1.1 at load factor 1.
    let path = data("benchmarks/argyris_frame.toml");
    let text = std::fs::read_to_string(&path)
        .unwrap()
        .replace(
            "analysis = \"static\"",
            "analysis = \"buckling\"\nmodes = 2",
        )
        .replace("load_steps = 220", "");
    let model = parse_model(&text, &path).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let summary = run_model(&model, dir.path()).unwrap();
    let p = read(&summary.file, "/buckling/load_factor")[0] * 1.1;
    assert_close(p, 1.088, 5e-3, "lateral buckling load");
}

#[test]
fn linearised_analyses_refuse_keys_that_are_not_theirs() {
    let cases = [
        ("analysis = \"static\"\nmodes = 3", "solver.modes"),
        (
            "analysis = \"buckling\"\nload_steps = 3",
            "solver.load_steps",
        ),
        ("analysis = \"modal\"\ndt = 0.1", "solver.dt"),
        (
            "analysis = \"buckling\"\nstop = { load_factor = 0.5 }",
            "solver.stop",
        ),
        ("analysis = \"modes\"", "solver.analysis"),
        ("analysis = \"modal\"\nmodes = 0", "solver.modes"),
        (
            "analysis = \"static\"\neigensolver = \"dense\"",
            "solver.eigensolver",
        ),
        (
            "analysis = \"modal\"\neigensolver = \"lanczos\"",
            "solver.eigensolver",
        ),
        (
            "analysis = \"modal\"\nrotation = { rate = 3.0 }",
            "solver.rotation.axis",
        ),
        (
            "analysis = \"buckling\"\nrotation = { axis = [0.0, 0.0, 1.0], rate = 3.0 }",
            "solver.rotation",
        ),
    ];
    for (solver, key) in cases {
        let text = beam_model(SLENDER, "", solver, 4);
        let err = parse_model(&text, Path::new("beam.toml"))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains(key) && err.contains("beam.toml"),
            "{solver}: {err}"
        );
    }
    // More modes than unknowns: refused when the run starts, with the count.
    let text = beam_model(SLENDER, "", "analysis = \"modal\"\nmodes = 500", 2);
    let model = parse_model(&text, Path::new("beam.toml")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let err = run_model(&model, dir.path()).unwrap_err().to_string();
    assert!(
        err.contains("solver.modes") && err.contains("30 unknowns"),
        "{err}"
    );
}

/// The slider-crank of `data/benchmarks/slider_crank.toml` held at the crank
/// angle `angle` (reached in `steps` static steps of equal angle), with the
/// `[solver]` given.
fn slider_crank_at(angle: f64, steps: usize, solver: &str) -> String {
    let text = std::fs::read_to_string(data("benchmarks/slider_crank.toml")).unwrap();
    let body = &text[..text.find("[[initial_velocity]]").unwrap()];
    let body = body.replace(
        "angle = { expr = \"2*pi*t\" }",
        &format!("angle = {{ expr = \"{angle}*lambda\" }}"),
    );
    format!("{body}\n[solver]\n{solver}\nload_steps = {steps}\ntolerance = 1e-12\n")
}

/// Node index of `label` in a result file.
fn node(file: &Path, label: &str) -> usize {
    crate::common::read_strings(file, "/mesh/node_labels")
        .iter()
        .position(|l| l == label)
        .unwrap()
}

#[test]
fn slider_crank_modes_about_a_pose_equal_those_of_a_stored_static_step() {
    let dir = tempfile::tempdir().unwrap();
    // The pose at crank angle 0.4: a modal analysis about it, and the
    // stored step at load factor 4/7 of a static run on to 0.7.
    let modal = slider_crank_at(0.4, 4, "analysis = \"modal\"\nmodes = 6");
    let (_d, modal_file) = run(&modal);
    let f_modal = read(&modal_file, "/modes/frequency");
    let stat = parse_model(
        &slider_crank_at(0.7, 7, "analysis = \"static\""),
        Path::new("sc.toml"),
    )
    .unwrap();
    let summary = run_model(&stat, dir.path()).unwrap();
    let t = read(&summary.file, "/time")[3];
    let times = read(&summary.file, "/time");
    assert!((t - 4.0 / 7.0).abs() < 1e-12, "{times:?}");
    let registry = flexmech::model::JointRegistry::builtin();
    let stored =
        flexmech::results::modes_of_result(&summary.file, t, 6, &registry, dir.path()).unwrap();
    let f_stored = read(&stored.file, "/modes/frequency");
    for (a, b) in f_modal.iter().zip(&f_stored) {
        assert_close(*b, *a, 1e-6, "stored step against the modal analysis");
    }
    assert!(
        f_modal[0] > 0.0,
        "the driven crank holds the mechanism: {f_modal:?}"
    );
    // Relation (1) in every mode: the revolutes' nodes move together and
    // turn apart about z only; the slider moves along x without turning.
    let u = read(&modal_file, "/modes/displacement");
    let r = read(&modal_file, "/modes/rotation");
    let nodes = u.len() / (6 * 3);
    let at = |v: &[f64], k: usize, n: usize| {
        [
            v[3 * (k * nodes + n)],
            v[3 * (k * nodes + n) + 1],
            v[3 * (k * nodes + n) + 2],
        ]
    };
    let scale = u.iter().chain(&r).fold(0.0f64, |m, v| m.max(v.abs()));
    let pairs = [("crank.end", "rod.start"), ("block.start", "rod.end")];
    for k in 0..6 {
        for (m, s) in pairs {
            let (um, us) = (
                at(&u, k, node(&modal_file, m)),
                at(&u, k, node(&modal_file, s)),
            );
            let (rm, rs) = (
                at(&r, k, node(&modal_file, m)),
                at(&r, k, node(&modal_file, s)),
            );
            for c in 0..3 {
                assert!((um[c] - us[c]).abs() < 1e-12 * scale, "mode {k}, {m}/{s}");
            }
            for c in 0..2 {
                assert!((rm[c] - rs[c]).abs() < 1e-12 * scale, "mode {k}, {m}/{s}");
            }
        }
        let (ub, rb) = (
            at(&u, k, node(&modal_file, "block.start")),
            at(&r, k, node(&modal_file, "block.start")),
        );
        assert!(
            ub[1].abs() < 1e-12 * scale && ub[2].abs() < 1e-12 * scale,
            "mode {k}: {ub:?}"
        );
        assert!(
            rb.iter().all(|v| v.abs() < 1e-12 * scale),
            "mode {k}: {rb:?}"
        );
    }
}

#[test]
fn modes_of_a_stored_step_are_refused_where_no_step_is_stored() {
    let dir = tempfile::tempdir().unwrap();
    let stat = parse_model(
        &slider_crank_at(0.7, 7, "analysis = \"static\""),
        Path::new("sc.toml"),
    )
    .unwrap();
    let summary = run_model(&stat, dir.path()).unwrap();
    let registry = flexmech::model::JointRegistry::builtin();
    let err = flexmech::results::modes_of_result(&summary.file, 0.5, 6, &registry, dir.path())
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("--time 0.5 is no stored step") && err.contains("nearest"),
        "{err}"
    );
}

/// Timoshenko's simply supported beam, mode `n`: the lower root `ω²` of
/// `(ρI ρA/κGA) ω⁴ − (ρA + ρI k² + EI ρA k²/κGA) ω² + EI k⁴ = 0`, `k = nπ/L`
/// (shear and rotary inertia; `w = sin kx`, `ψ = cos kx` exactly).
fn timoshenko_pinned(n: f64, (ei, ga, rho_a, rho_i): (f64, f64, f64, f64)) -> f64 {
    let k = n * PI;
    let a = rho_i * rho_a / ga;
    let b = rho_a + rho_i * k * k + ei * rho_a * k * k / ga;
    let c = ei * k.powi(4);
    let w2 = (b - (b * b - 4.0 * a * c).sqrt()) / (2.0 * a);
    w2.sqrt() / TAU
}

#[test]
fn stubby_pinned_beam_has_timoshenko_frequencies() {
    // EI/(GA L²) = 0.01 and rotary inertia ρI/(ρA L²) = 0.01: the first
    // mode lies 9 % and the second 28 % below Euler–Bernoulli's.
    let section = "EA = 1e7\nGA = [1e5, 1e5]\nGJ = 1e6\nEI = [1e3, 1e3]\nrhoA = 1.0\nrhoJ = [2e-2, 1e-2, 1e-2]";
    let supports = "[[support]]\nnode = \"b.start\"\nfixed = [\"ux\", \"uy\", \"uz\", \"rx\"]\n\
                    [[support]]\nnode = \"b.end\"\nfixed = [\"uy\", \"uz\"]";
    let text = beam_model(section, supports, "analysis = \"modal\"\nmodes = 4", 24);
    let (_dir, file) = run(&text);
    let f = read(&file, "/modes/frequency");
    for (k, n) in [1.0, 1.0, 2.0, 2.0].iter().enumerate() {
        let exact = timoshenko_pinned(*n, (1e3, 1e5, 1.0, 1e-2));
        assert_close(f[k], exact, DISCRETISATION, &format!("mode {k}"));
        assert!(
            f[k] < 0.95 * bending(n * PI),
            "mode {k} is not Euler–Bernoulli's"
        );
    }
}

/// Rayleigh–Ritz for a uniform cantilever of length 1 spinning about an
/// axis through its root, perpendicular to it: bending stiffness `ei`,
/// `ρA = 1`, the centrifugal tension `T(x) = Ω²(1 − x²)/2`, and `−Ω²` of
/// in-plane softening for the lead-lag motion (`in_plane`). Basis `xᵖ`,
/// `p = 2..=7`: `K = ei ∫φ″φ″ + ∫T φ′φ′ (− Ω² ∫φφ)`, `M = ∫φφ`; the lowest
/// `ω²`.
fn rayleigh_ritz_spinning(ei: f64, omega: f64, in_plane: bool) -> f64 {
    use nalgebra::DMatrix;
    let powers: Vec<f64> = (2..=7).map(f64::from).collect();
    let n = powers.len();
    let k = DMatrix::from_fn(n, n, |i, j| {
        let (p, q) = (powers[i], powers[j]);
        let bending = ei * p * (p - 1.0) * q * (q - 1.0) / (p + q - 3.0);
        let tension = omega * omega * p * q / 2.0 * (1.0 / (p + q - 1.0) - 1.0 / (p + q + 1.0));
        let soft = if in_plane {
            omega * omega / (p + q + 1.0)
        } else {
            0.0
        };
        bending + tension - soft
    });
    let m = DMatrix::from_fn(n, n, |i, j| 1.0 / (powers[i] + powers[j] + 1.0));
    let l = m.cholesky().unwrap().l();
    let li = l.clone().try_inverse().unwrap();
    let c = &li * k * li.transpose();
    let c = (&c + c.transpose()) * 0.5;
    c.symmetric_eigenvalues().min()
}

#[test]
fn spinning_cantilever_flap_and_lag_frequencies_match_rayleigh_ritz() {
    // Flap (out of the plane of rotation, z) with EI = 1e3; lead-lag (y)
    // with EI = 4e3; the blade along x spins about z through its root.
    let section = "EA = 1e9\nGA = [1e9, 1e9]\nGJ = 1e3\nEI = [1e3, 4e3]\nrhoA = 1.0\nrhoJ = [1e-6, 1e-9, 1e-9]";
    let supports = "[[support]]\nnode = \"b.start\"\nfixed = \"all\"";
    for omega in [0.0, 20.0, 60.0] {
        let solver = format!(
            "analysis = \"modal\"\nmodes = 2\nrotation = {{ axis = [0.0, 0.0, 1.0], rate = {omega} }}"
        );
        let (_dir, file) = run(&beam_model(section, supports, &solver, 24));
        let f = read(&file, "/modes/frequency");
        let flap = rayleigh_ritz_spinning(1e3, omega, false).sqrt() / TAU;
        let lag = rayleigh_ritz_spinning(4e3, omega, true).sqrt() / TAU;
        assert_close(f[0], flap, 1e-4, &format!("flap at Ω = {omega}"));
        assert_close(f[1], lag, 1e-4, &format!("lead-lag at Ω = {omega}"));
    }
    // Southwell at small Ω: ω² = ω₀² + K Ω², K ≈ 1.193 for the first flap mode.
    let (w0, w1) = (
        rayleigh_ritz_spinning(1e3, 0.0, false),
        rayleigh_ritz_spinning(1e3, 1.0, false),
    );
    assert!(
        (w1 - w0 - 1.193).abs() < 2e-3,
        "Southwell coefficient {}",
        w1 - w0
    );
}

#[test]
fn a_study_over_the_spin_rate_gives_the_campbell_diagram() {
    use flexmech::studies::{load_study, run_study, StudyOptions};
    let dir = tempfile::tempdir().unwrap();
    let section = "EA = 1e9\nGA = [1e9, 1e9]\nGJ = 1e3\nEI = [1e3, 4e3]\nrhoA = 1.0\nrhoJ = [1e-6, 1e-9, 1e-9]";
    let solver =
        "analysis = \"modal\"\nmodes = 2\nrotation = { axis = [0.0, 0.0, 1.0], rate = 0.0 }";
    let model = beam_model(
        section,
        "[[support]]\nnode = \"b.start\"\nfixed = \"all\"",
        solver,
        12,
    );
    std::fs::write(dir.path().join("blade.toml"), model).unwrap();
    let study = "name = \"campbell\"\nmodel = \"blade.toml\"\n[grid]\n\
                 \"solver.rotation.rate\" = [0.0, 30.0, 60.0]\n[output]\nfigures = [\n\
                 { name = \"flap\", dataset = \"/modes/frequency\", mode = 1 },\n\
                 { name = \"lag\", dataset = \"/modes/frequency\", mode = 2 },\n]\n";
    let file = dir.path().join("campbell.toml");
    std::fs::write(&file, study).unwrap();
    let spec = load_study(&file).unwrap();
    let options = StudyOptions {
        out: dir.path().join("out"),
        shard: None,
        progress: false,
    };
    let report = run_study(&spec, &options).unwrap();
    assert_eq!((report.runs, report.failed), (3, 0));
    let text = std::fs::read_to_string(&report.csv).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    for (row, omega) in lines.zip([0.0, 30.0, 60.0]) {
        let cells: Vec<&str> = row.split(',').collect();
        let value = |name: &str| cells[col(name)].parse::<f64>().unwrap();
        // The 12-element blade is within 1e-4 of Rayleigh–Ritz.
        let flap = rayleigh_ritz_spinning(1e3, omega, false).sqrt() / TAU;
        let lag = rayleigh_ritz_spinning(4e3, omega, true).sqrt() / TAU;
        assert_close(value("flap"), flap, 1e-4, &format!("flap at Ω = {omega}"));
        assert_close(value("lag"), lag, 1e-4, &format!("lag at Ω = {omega}"));
    }
    assert!(
        report.charts.iter().any(|c| c.ends_with("flap.png")),
        "{:?}",
        report.charts
    );
}

#[test]
fn a_mode_is_written_as_a_paraview_cycle_and_drawn_as_a_gif() {
    use flexmech::plot::animation::{animate, AnimationOptions};
    use flexmech::results::export::export_mode_vtk;
    let text = beam_model(
        SLENDER,
        "[[support]]\nnode = \"b.start\"\nfixed = \"all\"",
        "analysis = \"modal\"\nmodes = 3",
        6,
    );
    let (dir, file) = run(&text);
    let pvd = export_mode_vtk(&file, &dir.path().join("vtk"), None, 2).unwrap();
    let collection = std::fs::read_to_string(&pvd).unwrap();
    assert_eq!(collection.matches("timestep=").count(), 41, "{collection}");
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scripts/check_vtk_mode.py");
    let out = std::process::Command::new("python3")
        .arg(&script)
        .arg(&file)
        .arg(&pvd)
        .arg("2")
        .output();
    let required = std::env::var_os("FLEXMECH_REQUIRE_VTK").is_some();
    match out {
        Ok(o) if o.status.code() == Some(3) && !required => {
            eprintln!("skipped: the VTK read-back of the mode needs vtk and h5py")
        }
        Ok(o) => assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr)),
        Err(e) => assert!(!required, "python3 is required: {e}"),
    }
    let gif = dir.path().join("mode2.gif");
    let opts = AnimationOptions {
        mode: Some(2),
        size: (200, 150),
        ..Default::default()
    };
    animate(&file, &gif, &opts).unwrap();
    let mut decoder = gif::DecodeOptions::new()
        .read_info(std::fs::File::open(&gif).unwrap())
        .unwrap();
    let mut frames = 0;
    while decoder.read_next_frame().unwrap().is_some() {
        frames += 1;
    }
    assert_eq!(frames, 41);
    let err = export_mode_vtk(&file, &dir.path().join("vtk"), None, 4).unwrap_err();
    assert!(err.to_string().contains("modes 1 to 3, not 4"), "{err}");
}

#[test]
fn the_sparse_eigensolver_gives_the_dense_ones_frequencies() {
    let model = |solver: &str| {
        beam_model(
            SLENDER,
            "[[support]]\nnode = \"b.start\"\nfixed = \"all\"",
            &format!("analysis = \"modal\"\nmodes = 10\neigensolver = \"{solver}\""),
            24,
        )
    };
    let (_a, dense) = run(&model("dense"));
    let (_b, sparse) = run(&model("sparse"));
    let (d, s) = (
        read(&dense, "/modes/frequency"),
        read(&sparse, "/modes/frequency"),
    );
    for (k, (x, y)) in d.iter().zip(&s).enumerate() {
        assert_close(*y, *x, 1e-7, &format!("mode {k}"));
    }
    assert_eq!(
        crate::common::reader(&sparse)
            .string_attr("integrator")
            .as_deref(),
        Some("static")
    );
}

/// A cantilever of two beams joined rigidly at x = 1 ("a" at the root,
/// "b" at the tip), sections damped with `η_a`, `η_b`; `solver` lines.
fn damped_cantilever((eta_a, eta_b): (f64, f64), solver: &str) -> String {
    let section = |name: &str, eta: f64| {
        format!(
            "[[section]]\nname = \"{name}\"\nEA = 1e7\nGA = [1e7, 1e7]\nGJ = 1e3\nEI = [50.0, 50.0]\n\
             rhoA = 0.3\nrhoJ = [1e-4, 1e-4, 1e-4]\ndamping = {eta:?}\n"
        )
    };
    let beam = |name: &str, x0: f64| {
        format!(
            "[[beam]]\nname = \"{name}\"\nsection = \"{name}\"\nstart = [{x0:?}, 0.0, 0.0]\n\
             end = [{:?}, 0.0, 0.0]\ne2 = [0.0, 1.0, 0.0]\nelements = 8\n",
            x0 + 1.0
        )
    };
    format!(
        "name = \"damped\"\n{}{}{}{}[[joint]]\nname = \"middle\"\ntype = \"rigid\"\nmaster = \"a.end\"\n\
         slave = \"b.start\"\n[[support]]\nnode = \"a.start\"\nfixed = \"all\"\n[solver]\n{solver}\n",
        section("a", eta_a),
        section("b", eta_b),
        beam("a", 0.0),
        beam("b", 1.0)
    )
}

/// The damping ratio of the tip's free decay in a Newmark run of the same
/// cantilever: the logarithmic decrement of its positive peaks after the
/// higher modes (damped ∝ ω) have died out.
fn decay_ratio(etas: (f64, f64)) -> f64 {
    let text = damped_cantilever(
        etas,
        "analysis = \"dynamic\"\nintegrator = \"newmark\"\ndt = 0.001\nt_end = 4.0\n\
         [[initial_velocity]]\nnodes = \"a\"\nangular = [0.0, -0.05, 0.0]\n\
         [[initial_velocity]]\nnodes = \"b\"\nangular = [0.0, -0.05, 0.0]\n[output]\ntrack = [\"b.end\"]",
    );
    // [[initial_velocity]] and [output] after [solver]: move them before it.
    let (head, solver) = text.split_once("[solver]").unwrap();
    let (solver, rest) = solver.split_once("[[initial_velocity]]").unwrap();
    let text = format!("{head}[[initial_velocity]]{rest}\n[solver]{solver}");
    let (_dir, file) = run(&text);
    let t = read(&file, "/time");
    let u = read(&file, "/nodes/b.end/displacement");
    let z: Vec<f64> = (0..t.len()).map(|k| u[3 * k + 2]).collect();
    let peaks: Vec<f64> = (1..z.len() - 1)
        .filter(|&k| t[k] > 1.5 && z[k] > z[k - 1] && z[k] >= z[k + 1] && z[k] > 0.0)
        .map(|k| z[k])
        .collect();
    assert!(peaks.len() >= 4, "{peaks:?}");
    let delta = (peaks[0] / peaks[peaks.len() - 1]).ln() / (peaks.len() - 1) as f64;
    delta / (4.0 * PI * PI + delta * delta).sqrt()
}

#[test]
fn structural_damping_gives_each_mode_its_damping_ratio() {
    // One η everywhere on an unstressed beam: D = ηK, classical normal
    // modes with ζ = ηω/2 exactly and no coupling — to the agreement of the
    // mode's Rayleigh quotient φᵀKφ with its eigenvalue ω² (the eigen-solve's
    // accuracy: 1e-7 here, a spectrum widened by the small ρJ).
    let eta = 0.004;
    let (_dir, file) = run(&damped_cantilever(
        (eta, eta),
        "analysis = \"modal\"\nmodes = 4",
    ));
    let f = read(&file, "/modes/frequency");
    let zeta = read(&file, "/modes/damping_ratio");
    for (fk, zk) in f.iter().zip(&zeta) {
        assert_close(*zk, eta * TAU * fk / 2.0, 1e-7, "ζ = ηω/2");
    }
    let coupling = crate::common::reader(&file).group_f64_attr("/modes", "damping_coupling");
    assert!(coupling.unwrap() < 1e-8, "{coupling:?}");
    // The free decay of the same beam stepped by Newmark (its damping
    // forces from the strain rate of each step, first order in Δt: ζωΔt ~
    // 1e-4 here) against mode 1's ratio, within 2e-3 (observed 6e-5).
    // Damping only the root half couples the modes (coupling 0.2); the
    // projection neglects that coupling, an error second order in the
    // damping (ζ² ~ 2e-3), and still matches the decay (observed 3e-4).
    let measured = decay_ratio((eta, eta));
    eprintln!("uniform: ζ₁ = {}, free decay {measured}", zeta[0]);
    assert_close(measured, zeta[0], 2e-3, "free decay, uniform η");
    let (_dir, file) = run(&damped_cantilever(
        (2.0 * eta, 0.0),
        "analysis = \"modal\"\nmodes = 4",
    ));
    let zeta = read(&file, "/modes/damping_ratio");
    let coupling = crate::common::reader(&file).group_f64_attr("/modes", "damping_coupling");
    eprintln!("root-damped: ζ = {zeta:?}, coupling {coupling:?}");
    assert!(coupling.unwrap() > 1e-3);
    let measured = decay_ratio((2.0 * eta, 0.0));
    eprintln!("root-damped: free decay {measured}");
    assert_close(measured, zeta[0], 2e-3, "free decay, root half damped");
}
