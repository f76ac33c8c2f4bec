//! Rigid bodies and point masses (`[[rigid_body]]`) against analytic
//! mechanics: a physical pendulum's period with every integrator, the
//! weight of an offset body equal to the force and moment it hangs on its
//! node, and refusals that name the key.

use std::path::{Path, PathBuf};

use flexmech::model::build;
use flexmech::model::{parse_model, Model};
use flexmech::results::run_model_to;
use flexmech::results::ResultReader;

use crate::common::INTEGRATORS;

fn path(file: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../data")
        .join(file)
}

fn model_with(file: &str, from: &str, to: &str) -> Model {
    let p = path(file);
    let text = std::fs::read_to_string(&p).unwrap();
    assert!(text.contains(from), "{from}");
    parse_model(&text.replace(from, to), &p).unwrap()
}

/// The period of `data/dynamics/body_pendulum.toml` from the joint angle's
/// zero crossings: `2π √(I_O / (g S))` (see the file) to 5e-4 — the
/// schemes' (ωΔt)²/12 ≈ 8e-5 and the finite amplitude's θ₀²/16 ≈ 7e-5 lie
/// below it.
#[test]
fn a_body_on_a_hinged_rod_swings_as_a_physical_pendulum() {
    let (m, d, jc, rho_a, l, g) = (2.0, 1.0, 0.1, 1e-4, 0.5f64, 9.81);
    let i_o = jc + m * d * d + rho_a * l.powi(3) / 3.0;
    let s = m * d + rho_a * l * l / 2.0;
    let expected = 2.0 * std::f64::consts::PI * (i_o / (g * s)).sqrt();
    let dir = tempfile::tempdir().unwrap();
    for integrator in INTEGRATORS {
        let model = model_with(
            "dynamics/body_pendulum.toml",
            "integrator = \"energy-momentum\"",
            &format!("integrator = \"{integrator}\""),
        );
        let file = dir.path().join(format!("{integrator}.h5"));
        let summary = run_model_to(&model, &file).unwrap();
        assert!(summary.warnings.is_empty(), "{:?}", summary.warnings);
        let r = ResultReader::open(&file).unwrap();
        let t = r.time().unwrap();
        let psi = r.values("/joints/hinge/angle").unwrap();
        let crossings: Vec<f64> = (1..t.len())
            .filter(|&k| psi[k - 1] * psi[k] < 0.0)
            .map(|k| t[k - 1] + (t[k] - t[k - 1]) * psi[k - 1] / (psi[k - 1] - psi[k]))
            .collect();
        assert!(crossings.len() >= 3, "{integrator}: {crossings:?}");
        let n = crossings.len() - 1;
        let period = 2.0 * (crossings[n] - crossings[0]) / n as f64;
        eprintln!(
            "{integrator}: period {period:.6}, relative error {:.2e}",
            period / expected - 1.0
        );
        assert!(
            (period / expected - 1.0).abs() < 5e-4,
            "{integrator}: period {period} against {expected}"
        );
        // The centre of mass is a node of its own, held by the rigid link
        // `body.bob` at d = 1 from the hinge (the rod stretches by ~1e-7).
        let labels = r.mesh_node_labels().unwrap();
        let com = labels.iter().position(|l| l == "body.bob").expect("label");
        let x = r.values("/configuration/position").unwrap();
        let nodes = labels.len();
        for k in 0..t.len() {
            let p = &x[3 * (k * nodes + com)..3 * (k * nodes + com) + 3];
            let dist = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
            assert!((dist - d).abs() < 1e-6, "{integrator}: |x_c| = {dist}");
        }
        assert!(r.has("/joints/body.bob/constraint_error"));
    }
}

/// A static cantilever under gravity carrying a body whose centre of mass
/// lies beyond its tip: the same tip pose as the body's weight applied at
/// the tip as a dead force `m g` and moment `c × m g` (the weight's moment
/// about the node for a small rotation of the arm: to the rotation's order,
/// ~1e-4 of the deflection here).
#[test]
fn an_offset_body_weighs_on_its_node_with_force_and_moment() {
    let text = r#"name = "tip-body"
gravity = [0.0, 0.0, -9.81]

[[section]]
name = "s"
EA = 1.0e7
GA = [1.0e7, 1.0e7]
GJ = 1.0e4
EI = [1.0e4, 1.0e4]

[[beam]]
name = "arm"
section = "s"
start = [0.0, 0.0, 0.0]
end = [2.0, 0.0, 0.0]
e2 = [0.0, 1.0, 0.0]
elements = 8

[[support]]
node = "arm.start"
fixed = "all"

BODY

[solver]
analysis = "static"
load_steps = 4

[output]
track = ["arm.end"]
"#;
    let body = "[[rigid_body]]\nnode = \"arm.end\"\nmass = 3.0\noffset = [0.5, 0.0, 0.0]\n";
    let load =
        "[[load]]\nnode = \"arm.end\"\nforce = [0.0, 0.0, -29.43]\nmoment = [0.0, 14.715, 0.0]\n";
    let dir = tempfile::tempdir().unwrap();
    let tip = |body_text: &str, name: &str| {
        let model = parse_model(&text.replace("BODY", body_text), Path::new("tip.toml")).unwrap();
        let file = dir.path().join(name);
        run_model_to(&model, &file).unwrap();
        let r = ResultReader::open(&file).unwrap();
        let x = r.values("/nodes/arm.end/position").unwrap();
        x[x.len() - 3..].to_vec()
    };
    let (with_body, with_load) = (tip(body, "body.h5"), tip(load, "load.h5"));
    let deflection = with_load[2].abs();
    // Tip deflection of the equivalent loads: F L³/3EI + M L²/2EI ≈ 0.092.
    let (f, m, l, ei) = (29.43, 14.715, 2.0f64, 1.0e4);
    let beam_theory = f * l.powi(3) / (3.0 * ei) + m * l * l / (2.0 * ei);
    assert!(
        (deflection / beam_theory - 1.0).abs() < 0.02,
        "{deflection} vs {beam_theory}"
    );
    for c in 0..3 {
        assert!(
            (with_body[c] - with_load[c]).abs() < 2e-4 * deflection,
            "component {c}: {with_body:?} vs {with_load:?}"
        );
    }
}

#[test]
fn unphysical_bodies_are_refused_at_their_key() {
    let base = std::fs::read_to_string(path("dynamics/body_pendulum.toml")).unwrap();
    let parse_err = |from: &str, to: &str| {
        assert!(base.contains(from), "{from}");
        parse_model(&base.replace(from, to), Path::new("bp.toml"))
            .expect_err("refused")
            .to_string()
    };
    let e = parse_err("mass = 2.0", "mass = -2.0");
    assert!(
        e.contains("rigid_body[0].mass") && e.contains(">= 0"),
        "{e}"
    );
    let e = parse_err("inertia = [0.1, 0.1, 0.1]", "inertia = [0.1, 0.1]");
    assert!(
        e.contains("rigid_body[0].inertia") && e.contains("3×3"),
        "{e}"
    );
    let e = parse_err("node = \"rod.end\"", "node = \"rod.99\"");
    assert!(e.contains("rigid_body[0].node"), "{e}");
    let e = parse_err("mass = 2.0\n", "");
    assert!(
        e.contains("rigid_body[0].mass") && e.contains("missing"),
        "{e}"
    );
    let e = parse_err(
        "offset = [0.0, -0.5, 0.0]",
        "offset = [0.0, -0.5, 0.0]\ncolour = 1",
    );
    assert!(e.contains("colour"), "{e}");
    // Physics is the builder's check, named by the entry.
    let build_err = |from: &str, to: &str| {
        let model = parse_model(&base.replace(from, to), Path::new("bp.toml")).unwrap();
        match build(&model) {
            Err(e) => e.to_string(),
            Ok(_) => panic!("expected a refusal"),
        }
    };
    let e = build_err("inertia = [0.1, 0.1, 0.1]", "inertia = [0.1, 0.1, 0.5]");
    assert!(
        e.contains("rigid_body[0]") && e.contains("J₁ ≤ J₂ + J₃"),
        "{e}"
    );
    let e = build_err(
        "inertia = [0.1, 0.1, 0.1]",
        "inertia = [[0.1, 0.01, 0.0], [0.0, 0.1, 0.0], [0.0, 0.0, 0.1]]",
    );
    assert!(e.contains("symmetric"), "{e}");
    let e = build_err(
        "inertia = [0.1, 0.1, 0.1]",
        "inertia = [[0.1, 0.2, 0.0], [0.2, 0.1, 0.0], [0.0, 0.0, 0.1]]",
    );
    assert!(e.contains(">= 0"), "{e}");
}
