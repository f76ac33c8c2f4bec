//! Expression joints (`type = "expression"`): the built-in screw, cam and
//! rack-and-pinion written as expressions of `psi` run as the built-in
//! kinds do — positions to 1e-12 of the mechanism's size at every stored
//! step, in every integrator — and bad expressions are refused at their key.

use flexmech::prelude::*;
use toml::{Table, Value};

use crate::common::data;

/// Agreement of two runs of the same discrete equations whose joint
/// functions differ only in evaluation order: round-off of the
/// positions' size, far below the Newton tolerance's effect (~1e-10).
const SAME_RUN: f64 = 1e-12;

use crate::common::INTEGRATORS;

/// `file`'s model with its first joint rewritten as an expression joint
/// (`translation`, `parameters`), run with `integrator` to `t_end`.
fn variants(file: &str, translation: [&str; 3], parameters: &[(&str, f64)]) -> (Table, Table) {
    let text = std::fs::read_to_string(data(file)).unwrap();
    let builtin: Table = toml::from_str(&text).unwrap();
    let mut expression = builtin.clone();
    let joint = expression["joint"].as_array_mut().unwrap()[0]
        .as_table_mut()
        .unwrap();
    let keep = ["name", "master", "slave", "axis", "angle", "rate"];
    joint.retain(|k, _| keep.contains(&k));
    joint.insert("type".into(), "expression".into());
    let f = translation.iter().map(|&e| Value::from(e)).collect();
    joint.insert("translation".into(), Value::Array(f));
    let p: Table = parameters
        .iter()
        .map(|&(n, v)| (n.to_string(), Value::from(v)))
        .collect();
    joint.insert("parameters".into(), Value::Table(p));
    (builtin, expression)
}

fn run_table(file: &str, mut model: Table, integrator: &str, t_end: f64) -> Memory {
    let solver = model["solver"].as_table_mut().unwrap();
    solver.insert("integrator".into(), integrator.into());
    solver.insert("t_end".into(), t_end.into());
    let text = toml::to_string(&model).unwrap();
    let model = parse_model(&text, &data(file)).unwrap_or_else(|e| panic!("{e}"));
    let mut memory = Memory::default();
    run(&model, &mut memory).unwrap_or_else(|e| panic!("{file} {integrator}: {e}"));
    assert_eq!(memory.status(), "completed", "{file} {integrator}");
    memory
}

/// Runs both variants in every integrator and compares every tracked
/// node's positions and the total energy at every stored step.
fn same_runs(file: &str, translation: [&str; 3], parameters: &[(&str, f64)], t_end: f64) {
    let (builtin, expression) = variants(file, translation, parameters);
    for integrator in INTEGRATORS {
        let a = run_table(file, builtin.clone(), integrator, t_end);
        let b = run_table(file, expression.clone(), integrator, t_end);
        let mut size: f64 = 0.0;
        let mut worst: f64 = 0.0;
        for (label, _) in &a.meta.tracked {
            let (pa, pb) = (a.positions(label).unwrap(), b.positions(label).unwrap());
            assert_eq!(pa.len(), pb.len(), "{file} {integrator} {label}");
            for (x, y) in pa.iter().zip(&pb) {
                for c in 0..3 {
                    size = size.max(x[c].abs());
                    worst = worst.max((x[c] - y[c]).abs());
                }
            }
        }
        assert!(size > 0.1, "{file}: tracked nodes");
        assert!(
            worst <= SAME_RUN * size,
            "{file} {integrator}: {worst:e} of {size}"
        );
        let (ea, eb) = (energies(&a), energies(&b));
        let scale = ea.iter().map(|e| e.abs()).fold(0.0, f64::max);
        for (x, y) in ea.iter().zip(&eb) {
            assert!(
                (x - y).abs() <= SAME_RUN * scale.max(1.0),
                "{file} {integrator}: energy"
            );
        }
    }
}

fn energies(m: &Memory) -> Vec<f64> {
    m.records.iter().map(|r| r.energy.total).collect()
}

#[test]
fn the_screw_as_an_expression_is_the_builtin_screw() {
    same_runs(
        "paper/screw_driven.toml",
        ["0", "0", "c*psi"],
        &[("c", 0.02)],
        0.5,
    );
    // Free: the arm spins on the screw (momentum and energy conserved by
    // the conserving schemes, for both kinds alike).
    same_runs(
        "paper/screw_free.toml",
        ["0", "0", "c*psi"],
        &[("c", -0.3)],
        0.6,
    );
}

#[test]
fn the_cam_as_an_expression_is_the_builtin_cam() {
    // f(ψ) = (R cos ψ − R − a) t_r with t_r = x.
    let f = ["R*cos(psi) - R - a", "0", "0"];
    same_runs("paper/cam.toml", f, &[("R", 0.05), ("a", 0.02)], 0.5);
}

#[test]
fn the_rack_and_pinion_as_an_expression_is_the_builtin_one() {
    // f(ψ) = b (t_r × t) + b ψ t_r with t = y, t_r = x: (b ψ, 0, b).
    same_runs(
        "paper/rack_pinion.toml",
        ["b*psi", "0", "b"],
        &[("b", 0.1)],
        0.5,
    );
}

/// The message of a model whose joint is `joint` (a TOML table's lines).
fn refusal(joint: &str) -> String {
    let text = std::fs::read_to_string(data("paper/screw_driven.toml"))
        .unwrap()
        .replace("type = \"screw\"", "type = \"expression\"")
        .replace("pitch = 0.02 ", &format!("{joint}\n#"));
    parse_model(&text, Path::new("bad.toml"))
        .and_then(|m| flexmech::model::build(&m).map(|_| ()))
        .unwrap_err()
        .to_string()
}

#[test]
fn bad_expressions_are_refused_at_their_key() {
    let e = refusal(r#"translation = ["0", "0", "c*psi +"]"#);
    assert!(
        e.contains("joint[0].translation") && e.contains("at character"),
        "{e}"
    );
    let e = refusal(r#"translation = ["0", "0", "k*psi"]"#);
    assert!(e.contains("unknown name `k`") && e.contains("psi"), "{e}");
    let e = refusal("translation = [\"0\", \"0\", \"c*psi\"]\nparameters = { pi = 3.0, c = 1.0 }");
    assert!(e.contains("parameters.pi") && e.contains("shadows"), "{e}");
    let e = refusal("translation = [\"0\", \"0\", \"c*psi\"]\nparameters = { t = 1.0 }");
    assert!(e.contains("parameters.t"), "{e}");
    // Non-finite at the initial angle: the value, then the derivative.
    let e = refusal(r#"translation = ["0", "0", "ln(psi)"]"#);
    assert!(e.contains("not a finite number"), "{e}");
    let e = refusal(r#"translation = ["0", "0", "sqrt(psi)"]"#);
    assert!(e.contains("derivative") && e.contains("not finite"), "{e}");
    let e = refusal(r#"translation = ["0", "0"]"#);
    assert!(e.contains("translation"), "{e}");
}
