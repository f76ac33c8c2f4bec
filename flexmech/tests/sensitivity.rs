//! Exact static sensitivities (direct differentiation, `solve_static_with`)
//! against the linear cantilever's closed form and against central finite
//! differences of two perturbed solves, in the nonlinear range and through
//! every joint kind.

use flexmech::integrators::{
    solve_static_with, Mechanism, NewtonSettings, Parameter, StaticSettings, StepRecord,
};
use flexmech::model::{build, Built};
use flexmech::prelude::*;

use crate::common::data;

/// Newton to 1e-12 of the force scale: the finite differences below then
/// carry ~1e-12 / 1e-4 of error, far below the tolerances.
const NEWTON: f64 = 1e-12;
/// Relative step of the central differences (the issue's 1e-4).
const STEP: f64 = 1e-4;
/// Central differences of step h err by O(h²) ≈ 1e-8 plus the solves'
/// round-off over h; the derivative is exact, so 1e-6 of the largest
/// derivative is a safe bound in statics.
const AGREE: f64 = 1e-6;

fn settings(load_steps: usize) -> StaticSettings {
    StaticSettings {
        load_steps,
        newton: NewtonSettings {
            tolerance: NEWTON,
            max_iterations: 30,
            ..NewtonSettings::default()
        },
        max_halvings: 8,
    }
}

/// Every converged step's record.
fn solve(mech: &Mechanism, steps: usize, params: &[Parameter]) -> Vec<StepRecord> {
    let mut records = Vec::new();
    solve_static_with(mech, &settings(steps), params, |r| records.push(r.clone())).unwrap();
    records
}

/// A cantilever of length 2 along x, `n` elements, EI₂ = 1e3, EI₃ = 2e3,
/// a tip force `fz` along z.
fn cantilever(n: usize, fz: f64) -> Built {
    let rod = SectionValues {
        ea: 1e7,
        ga: [4e6, 4e6],
        gj: 800.0,
        ei: [1e3, 2e3],
        rho_a: 1.0,
        rho_j: [1e-3; 3],
    };
    let straight = BeamGeometry::Straight {
        start: Vector3::zeros(),
        end: Vector3::new(2.0, 0.0, 0.0),
        e2: Vector3::y(),
    };
    let model = Model::new("arm")
        .section("rod", rod)
        .beam("arm", "rod", straight, n)
        .support("arm.start", "all")
        .load("arm.end", [0.0, 0.0, fz], [0.0; 3])
        .statics(4)
        .build()
        .unwrap();
    build(&model).unwrap()
}

fn stiffness(built: &Built, beam: usize, component: usize) -> Parameter {
    Parameter::Stiffness {
        elements: built.beam_elements[beam].clone().collect(),
        component,
    }
}

/// `mech` with `p` scaled by `1 + h`.
fn perturbed(mech: &Mechanism, p: &Parameter, h: f64) -> Mechanism {
    let mut m = mech.clone();
    match p {
        Parameter::Stiffness {
            elements,
            component,
        } => {
            for &e in elements {
                let s = match &mut m.mesh.elements[e] {
                    flexmech::core::Element::Linear(e) => &mut e.section,
                    flexmech::core::Element::Quadratic(e) => &mut e.section,
                };
                match component {
                    0..=2 => s.c_n[*component] *= 1.0 + h,
                    _ => s.c_m[component - 3] *= 1.0 + h,
                }
            }
        }
        Parameter::Load { load, component } => {
            let l = &mut m.loads[*load];
            match component {
                0..=2 => l.force[*component] *= 1.0 + h,
                _ => l.moment[component - 3] *= 1.0 + h,
            }
        }
        _ => panic!("not used in these tests"),
    }
    m
}

/// The value of `p` in `mech` (the finite differences' scale).
fn value(mech: &Mechanism, p: &Parameter) -> f64 {
    match p {
        Parameter::Stiffness {
            elements,
            component,
        } => {
            let s = mech.mesh.elements[elements[0]].section();
            if *component < 3 {
                s.c_n[*component]
            } else {
                s.c_m[component - 3]
            }
        }
        Parameter::Load { load, component } => {
            let l = &mech.loads[*load];
            if *component < 3 {
                l.force[*component]
            } else {
                l.moment[component - 3]
            }
        }
        _ => panic!("not used in these tests"),
    }
}

/// Every node's final position and the final total energy by central
/// differences: `dx/dp`, `dE/dp`.
fn central_difference(mech: &Mechanism, p: &Parameter, steps: usize) -> (Vec<[f64; 3]>, f64) {
    let last = |h: f64| solve(&perturbed(mech, p, h), steps, &[]).pop().unwrap();
    let (plus, minus) = (last(STEP), last(-STEP));
    let dp = 2.0 * STEP * value(mech, p);
    let dx = plus
        .positions
        .iter()
        .zip(&minus.positions)
        .map(|(a, b)| [0, 1, 2].map(|c| (a[c] - b[c]) / dp))
        .collect();
    (dx, (plus.energy.total - minus.energy.total) / dp)
}

/// [`central_difference`] against the exact `dx/dp` and `dE/dp` of `last`.
fn assert_agrees(last: &StepRecord, k: usize, fd: (Vec<[f64; 3]>, f64), p: &Parameter) {
    let exact = &last.sensitivities[k];
    let e = mismatch(&exact.displacement, &fd.0);
    assert!(e < AGREE, "{p:?}: {e:e}");
    let e = (exact.energy - fd.1).abs() / exact.energy.abs().max(fd.1.abs());
    assert!(
        e < AGREE,
        "{p:?}: dE/dp {} vs {} ({e:e})",
        exact.energy,
        fd.1
    );
}

/// Largest difference between the exact and the difference derivatives,
/// over the largest exact one.
fn mismatch(exact: &[[f64; 3]], fd: &[[f64; 3]]) -> f64 {
    let scale = exact.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    let worst = exact
        .iter()
        .flatten()
        .zip(fd.iter().flatten())
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(scale > 0.0, "a derivative that vanishes everywhere");
    worst / scale
}

#[test]
fn the_tip_deflection_of_a_linear_cantilever_by_ei_ga_and_the_load() {
    // |F| L² / EI = 2e-3: linear to ~1e-6. The n reduced-integration
    // elements bend as the Timoshenko beam with L³ → L³ (1 − 1/(4n²)):
    // w = F L³/(3 EI₂) (1 − 1/(4n²)) + F L / GA₃, so
    // dw/dEI₂ = −F L³/(3 EI₂²)(1 − 1/(4n²)), dw/dGA₃ = −F L/GA₃², dw/dF = w/F.
    let (n, f, l, ei, ga): (usize, f64, f64, f64, f64) = (16, -0.5, 2.0, 1e3, 4e6);
    let built = cantilever(n, f);
    let tip = built.beam_nodes[0][n];
    let params = [
        stiffness(&built, 0, 4),
        stiffness(&built, 0, 5),
        stiffness(&built, 0, 2),
        Parameter::Load {
            load: 0,
            component: 2,
        },
    ];
    let last = solve(&built.mechanism, 4, &params).pop().unwrap();
    let d = |k: usize| last.sensitivities[k].displacement[tip][2];
    let bend = 1.0 - 1.0 / (4.0 * (n * n) as f64);
    let exact = -f * l.powi(3) / (3.0 * ei * ei) * bend;
    assert!((d(0) / exact - 1.0).abs() < 1e-5, "{} vs {exact}", d(0));
    // EI₃ bends the other way: no z deflection depends on it.
    assert!(d(1).abs() < 1e-9 * exact.abs(), "{}", d(1));
    let exact = -f * l / (ga * ga);
    assert!((d(2) / exact - 1.0).abs() < 1e-4, "{} vs {exact}", d(2));
    let w = last.positions[tip][2];
    assert!(
        (d(3) - w / f).abs() < 1e-5 * (w / f).abs(),
        "{} vs {}",
        d(3),
        w / f
    );
}

#[test]
fn sensitivities_equal_central_differences_in_the_nonlinear_range() {
    // F L² / EI₂ = 4: the tip turns by about 1.4 rad.
    let built = cantilever(10, -1e3);
    let params = [
        stiffness(&built, 0, 4),
        stiffness(&built, 0, 0),
        Parameter::Load {
            load: 0,
            component: 2,
        },
    ];
    let last = solve(&built.mechanism, 10, &params).pop().unwrap();
    let tip = built.beam_nodes[0][10];
    assert!(
        last.positions[tip][0] < 1.5,
        "large deflection: {:?}",
        last.positions[tip]
    );
    for (k, p) in params.iter().enumerate() {
        let fd = central_difference(&built.mechanism, p, 10);
        assert_agrees(&last, k, fd, p);
    }
}

#[test]
fn sensitivities_through_every_joint_kind_equal_central_differences() {
    // data/statics/joint_kinds.toml: a loaded pair of beams per joint kind.
    let model = load_model(&data("statics/joint_kinds.toml")).unwrap();
    let built = build(&model).unwrap();
    let steps = match model.solver.analysis {
        flexmech::model::Analysis::Static { load_steps } => load_steps,
        _ => panic!("a static model"),
    };
    let mut params: Vec<Parameter> = (0..built.beam_elements.len())
        .step_by(3)
        .map(|b| stiffness(&built, b, 4))
        .collect();
    params.push(Parameter::Load {
        load: 1,
        component: 2,
    });
    let last = solve(&built.mechanism, steps, &params).pop().unwrap();
    for (k, p) in params.iter().enumerate() {
        let fd = central_difference(&built.mechanism, p, steps);
        assert_agrees(&last, k, fd, p);
    }
}

/// `model` with the value at `key` scaled by `1 + h` (through the model
/// file's text, so the key's meaning is the file's, not the solver's).
fn perturbed_model(model: &Model, key: &str, h: f64) -> (Model, f64) {
    use flexmech::model::key_path::{lookup_mut, KeyPath};
    let mut table: toml::Table = toml::from_str(&model.to_toml()).unwrap();
    let value = lookup_mut(&mut table, &KeyPath::parse(key).unwrap()).unwrap();
    let v = value
        .as_float()
        .or(value.as_integer().map(|i| i as f64))
        .unwrap();
    *value = toml::Value::Float(v * (1.0 + h));
    let text = toml::to_string(&table).unwrap();
    (parse_model(&text, &model.path).unwrap(), v)
}

/// The last kept step of `model` run into memory.
fn last_step(model: &Model) -> StepRecord {
    let mut memory = Memory::default();
    run(model, &mut memory).unwrap();
    assert_eq!(memory.status(), "completed");
    memory.records.pop().unwrap()
}

#[test]
fn model_file_sensitivities_equal_central_differences_of_perturbed_files() {
    // data/statics/sensitivity_frame.toml: an L-frame turned ~0.5 rad, five
    // keys (two sections by name and by position, a tip force and moment, a
    // distributed load). The result file's /sensitivity against central
    // differences of the model run with each key's value scaled by 1 ± 1e-4.
    let model = load_model(&data("statics/sensitivity_frame.toml")).unwrap();
    let out = tempfile::tempdir().unwrap();
    let file = flexmech::results::run_model_to(&model, &out.path().join("frame.h5")).unwrap();
    let result = crate::common::reader(&file.file);
    let built = build(&model).unwrap();
    let nodes = [
        ("arm.end", built.beam_nodes[1][8]),
        ("post.end", built.beam_nodes[0][8]),
    ];
    let mut quiet = model.clone();
    quiet.output.sensitivity.clear();
    for (key, _) in &model.output.sensitivity {
        let (plus, v) = perturbed_model(&quiet, key, STEP);
        let (minus, _) = perturbed_model(&quiet, key, -STEP);
        let (plus, minus) = (last_step(&plus), last_step(&minus));
        let dp = 2.0 * STEP * v;
        for (label, node) in nodes {
            let name = format!("/sensitivity/{key}/nodes/{label}/displacement");
            let exact = *result.rows3(&name).unwrap().last().unwrap();
            let fd: [f64; 3] =
                [0, 1, 2].map(|c| (plus.positions[node][c] - minus.positions[node][c]) / dp);
            let e = mismatch(&[exact], &[fd]);
            assert!(e < AGREE, "{name}: {exact:?} vs {fd:?} ({e:e})");
        }
        let name = format!("/sensitivity/{key}/energy/total");
        let exact = *result.values(&name).unwrap().last().unwrap();
        let fd = (plus.energy.total - minus.energy.total) / dp;
        let e = (exact - fd).abs() / fd.abs();
        assert!(e < AGREE, "{name}: {exact} vs {fd} ({e:e})");
    }
}

#[test]
fn sensitivity_keys_that_name_no_differentiable_value_are_refused_where_written() {
    let path = data("statics/sensitivity_frame.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let start = text.find("sensitivity = [").unwrap();
    let with = |keys: &str, more: &str| {
        let t = format!("{}sensitivity = [{keys}]\n{more}", &text[..start]);
        parse_model(&t, &path).unwrap_err().to_string()
    };
    let cases = [
        ("\"section.rod.EA\"", "no [[section]] entry named \"rod\""),
        (
            "\"beam[0].e2[0]\"",
            "not available yet; available: section values",
        ),
        ("\"section.post.EI\"", "a list (name one component"),
        ("\"beam[0].elements\"", "an integer, not a real number"),
        ("\"section.post.name\"", "a string, not a real number"),
        ("\"load[0].force[3]\"", "has 3 entries"),
        ("\"load[0].force[2]\", \"load[0].force[2]\"", "listed twice"),
        ("\"load[0.force\"", "unclosed '['"),
    ];
    for (keys, expected) in cases {
        let message = with(keys, "");
        assert!(message.contains(expected), "{keys}: {message}");
        assert!(message.contains("key `output.sensitivity["), "{message}");
        assert!(message.contains("sensitivity_frame.toml:"), "{message}");
    }
}

#[test]
fn a_study_figure_with_derivatives_agrees_with_its_own_neighbouring_runs() {
    // The frame without [output] sensitivity: the study asks the runs for
    // the figure's derivatives. EI[0] of the post at 1000 (1 ∓ 1e-4): the
    // middle run's d(tip_z)|d(EI) is the central difference of the outer
    // two runs' tip_z.
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(data("statics/sensitivity_frame.toml")).unwrap();
    let base = &text[..text.find("sensitivity = [").unwrap()];
    std::fs::write(dir.path().join("frame.toml"), base).unwrap();
    let ei = [1000.0 * (1.0 - STEP), 1000.0, 1000.0 * (1.0 + STEP)];
    let study = format!(
        "name = \"frame-ei\"\nmodel = \"frame.toml\"\n[grid]\n\"section.post.EI[0]\" = \
         [{:?}, {:?}, {:?}]\n[output]\nfigures = [{{ name = \"tip_z\", dataset = \
         \"/nodes/arm.end/displacement\", component = \"z\", reduce = \"final\", derivative = \
         [\"section.post.EI[0]\", \"load[0].force[2]\"] }}]\n",
        ei[0], ei[1], ei[2]
    );
    let file = dir.path().join("study.toml");
    std::fs::write(&file, study).unwrap();
    let spec = flexmech::studies::load_study(&file).unwrap();
    let report = spec.run(dir.path().join("out")).unwrap();
    let summary = crate::common::reader(&report.dir.join("summary.h5"));
    let column = |name: &str| summary.values(&format!("/{name}")).unwrap();
    let (tip, by_ei) = (column("tip_z"), column("d(tip_z)|d(section.post.EI[0])"));
    let fd = (tip[2] - tip[0]) / (ei[2] - ei[0]);
    assert!(
        (by_ei[1] - fd).abs() < AGREE * fd.abs(),
        "{} vs {fd}",
        by_ei[1]
    );
    // The column is the run file's /sensitivity at the last step.
    let run = crate::common::reader(&report.dir.join("runs/run-0001.h5"));
    let stored = run
        .rows3("/sensitivity/load[0].force[2]/nodes/arm.end/displacement")
        .unwrap();
    assert_eq!(
        column("d(tip_z)|d(load[0].force[2])")[1],
        stored.last().unwrap()[2]
    );
    // The chart over EI draws the tangents from the derivatives.
    let svg = std::fs::read_to_string(report.dir.join("charts/tip_z.svg")).unwrap();
    assert!(
        svg.contains("tangents (exact derivatives)"),
        "no tangent legend"
    );
}

/// Dynamics: central differences err by O(h²) of the derivative's own
/// variation and by the Newton tolerance over h; the issue's bound.
const AGREE_DYNAMICS: f64 = 1e-4;

/// `file` shortened to `t_end`, Newton to 1e-12, run with `integrator`
/// (model-file text), asking for the derivatives by `keys`.
fn dynamic_model(file: &str, t_end: f64, integrator: &str, keys: &[&str]) -> Model {
    let text = std::fs::read_to_string(data(file)).unwrap();
    let mut table: toml::Table = toml::from_str(&text).unwrap();
    let solver = table["solver"].as_table_mut().unwrap();
    solver.insert("t_end".into(), toml::Value::Float(t_end));
    solver.insert("tolerance".into(), toml::Value::Float(NEWTON));
    solver.insert("integrator".into(), toml::Value::String(integrator.into()));
    if integrator != "generalized-alpha" {
        solver.remove("rho_inf");
    }
    solver.insert("max_halvings".into(), toml::Value::Integer(0));
    let mut model = parse_model(&toml::to_string(&table).unwrap(), &data(file)).unwrap();
    let keys: Vec<String> = keys.iter().map(|k| k.to_string()).collect();
    model.add_sensitivity(&keys).unwrap();
    model
}

/// Every kept step's exact derivatives of the tracked nodes and the total
/// energy against central differences of two perturbed runs: the largest
/// difference over the largest derivative, per key.
fn dynamic_mismatch(model: &Model, step: f64) -> Vec<(String, f64, f64)> {
    let built = build(model).unwrap();
    let tracked: Vec<usize> = (model.output.track.iter())
        .map(|(_, r)| built.node(*r))
        .collect();
    let mut memory = Memory::default();
    run(model, &mut memory).unwrap();
    assert_eq!(memory.status(), "completed");
    let mut quiet = model.clone();
    quiet.output.sensitivity.clear();
    let mut out = Vec::new();
    for (k, (key, _)) in model.output.sensitivity.iter().enumerate() {
        let (plus, v) = perturbed_model(&quiet, key, step);
        let (minus, _) = perturbed_model(&quiet, key, -step);
        let records = |m: &Model| {
            let mut memory = Memory::default();
            run(m, &mut memory).unwrap();
            memory.records
        };
        let (plus, minus) = (records(&plus), records(&minus));
        assert_eq!(plus.len(), memory.records.len(), "{key}: the same steps");
        let dp = 2.0 * step * v;
        let (mut exact, mut fd) = (Vec::new(), Vec::new());
        let (mut e_exact, mut e_fd) = (Vec::new(), Vec::new());
        for ((rec, p), m) in memory.records.iter().zip(&plus).zip(&minus) {
            for &n in &tracked {
                exact.push(rec.sensitivities[k].displacement[n]);
                fd.push([0, 1, 2].map(|c| (p.positions[n][c] - m.positions[n][c]) / dp));
            }
            e_exact.push([rec.sensitivities[k].energy, 0.0, 0.0]);
            e_fd.push([(p.energy.total - m.energy.total) / dp, 0.0, 0.0]);
        }
        out.push((
            key.clone(),
            mismatch(&exact, &fd),
            mismatch(&e_exact, &e_fd),
        ));
    }
    out
}

/// The integrators that compute sensitivities.
const NEWMARK_FAMILY: [&str; 2] = ["newmark", "generalized-alpha"];

/// `file` shortened to `t_end` and differentiated by `keys`, with each of
/// [`NEWMARK_FAMILY`], within the dynamics' bound.
fn both_integrators_agree(file: &str, t_end: f64, keys: &[&str]) {
    for integrator in NEWMARK_FAMILY {
        let model = dynamic_model(file, t_end, integrator, keys);
        assert_dynamic_agrees(&model, integrator);
    }
}

/// [`dynamic_mismatch`] of `model` (run with `integrator`) within the
/// dynamics' bound, displacements and energy.
fn assert_dynamic_agrees(model: &Model, integrator: &str) {
    assert_dynamic_agrees_at(model, integrator, STEP);
}

/// [`assert_dynamic_agrees`] with the differences' relative step `step`.
fn assert_dynamic_agrees_at(model: &Model, integrator: &str, step: f64) {
    for (key, displacement, energy) in dynamic_mismatch(model, step) {
        assert!(
            displacement < AGREE_DYNAMICS,
            "{integrator} {key}: {displacement:e}"
        );
        assert!(
            energy < AGREE_DYNAMICS,
            "{integrator} {key}: energy {energy:e}"
        );
    }
}

#[test]
fn dynamic_sensitivities_of_the_spin_up_equal_central_differences() {
    // The spin-up's first 2 s (the root driven from rest): d(tip)/d(EI₃),
    // the in-plane bending stiffness, for both Newmark-family integrators.
    // (EA moves the tip by ~1e-15 per unit, 1e-11 over the differences'
    // step: at the runs' round-off, no test of anything.)
    both_integrators_agree("benchmarks/spin_up.toml", 2.0, &["section.blade.EI[1]"]);
}

#[test]
fn dynamic_sensitivities_of_the_four_bar_equal_central_differences() {
    // The four-bar's first 1.5 s through its revolutes and the drive:
    // d(out-of-plane displacement)/d(section stiffness).
    both_integrators_agree(
        "benchmarks/four_bar_tacs.toml",
        1.5,
        &["section.bar8.EI[0]", "section.bar16.GJ"],
    );
}

/// The L-frame of data/statics given mass (and, with `gravity`, weight)
/// and run in dynamics with `integrator` for 0.3 s.
fn frame_in_dynamics(integrator: &str, gravity: bool) -> String {
    let mut text = std::fs::read_to_string(data("statics/sensitivity_frame.toml")).unwrap();
    if gravity {
        let weight = "\ngravity = [0.0, 0.0, -9.81]\n\n[[section]]";
        text = text.replacen("\n[[section]]", weight, 1);
    }
    let mass = "\nrhoA = 2.0\nrhoJ = [0.02, 0.01, 0.01]";
    let solver =
        format!("analysis = \"dynamic\"\nintegrator = \"{integrator}\"\ndt = 0.005\nt_end = 0.3");
    (text.replace(
        "EI = [1000.0, 1000.0]",
        &format!("EI = [1000.0, 1000.0]{mass}"),
    ))
    .replace("EI = [400.0, 600.0]", &format!("EI = [400.0, 600.0]{mass}"))
    .replace("analysis = \"static\"\nload_steps = 5", &solver)
}

#[test]
fn dynamic_sensitivities_by_loads_through_a_joint_equal_central_differences() {
    // The L-frame of the static tests given mass and gravity and released
    // at once under its loads: its arm swings through the rigid corner
    // joint; derivatives by the tip force, the distributed load, the
    // sections' stiffnesses, the arm's mass (inertia and weight) and the
    // post's rotational inertia.
    for integrator in NEWMARK_FAMILY {
        let text = frame_in_dynamics(integrator, true);
        let mut model = parse_model(&text, &data("statics/sensitivity_frame.toml")).unwrap();
        let masses = [
            "section.arm.rhoA".to_string(),
            "section.post.rhoJ[1]".to_string(),
        ];
        model.add_sensitivity(&masses).unwrap();
        assert_dynamic_agrees(&model, integrator);
    }
}

#[test]
fn arc_length_sensitivities_at_the_final_load_factor_equal_central_differences() {
    // Derivatives at fixed load factor: the path's steps sit at other λ in
    // a perturbed run, its last at λ = 1 in every run. The frame, and the
    // truss past its snap (the apex through its revolute).
    let frame = std::fs::read_to_string(data("statics/sensitivity_frame.toml")).unwrap();
    let frame = frame.replace(
        "analysis = \"static\"\n",
        "analysis = \"static\"\ncontrol = \"arc-length\"\n",
    );
    let frame = parse_model(&frame, &data("statics/sensitivity_frame.toml")).unwrap();
    let mut truss = load_model(&data("statics/snap_through_truss.toml")).unwrap();
    truss
        .add_sensitivity(&["section.bar.EA".into(), "load[0].force[1]".into()])
        .unwrap();
    truss.solver.tolerance = NEWTON;
    for model in [frame, truss] {
        let file = tempfile::tempdir().unwrap();
        let file = flexmech::results::run_model_to(&model, &file.path().join("r.h5")).unwrap();
        let result = crate::common::reader(&file.file);
        assert_eq!(*result.time().unwrap().last().unwrap(), 1.0);
        let mut quiet = model.clone();
        quiet.output.sensitivity.clear();
        for (key, _) in &model.output.sensitivity {
            let (plus, v) = perturbed_model(&quiet, key, STEP);
            let (minus, _) = perturbed_model(&quiet, key, -STEP);
            let (plus, minus) = (last_step(&plus), last_step(&minus));
            assert_eq!((plus.time, minus.time), (1.0, 1.0));
            let dp = 2.0 * STEP * v;
            for (label, r) in &model.output.track {
                let node = build(&model).unwrap().node(*r);
                let name = format!("/sensitivity/{key}/nodes/{label}/displacement");
                let exact = *result.rows3(&name).unwrap().last().unwrap();
                let fd =
                    [0, 1, 2].map(|c| (plus.positions[node][c] - minus.positions[node][c]) / dp);
                let e = mismatch(&[exact], &[fd]);
                assert!(
                    e < AGREE,
                    "{}: {name}: {exact:?} vs {fd:?} ({e:e})",
                    model.name
                );
            }
        }
    }
}

#[test]
fn dynamic_sensitivities_by_initial_velocities_through_every_joint_kind() {
    // The free chain: ten links joined by every joint kind, thrown with a
    // rigid velocity field per link. Derivatives by the first link's spin,
    // a middle link's velocity (its slave's follows through N) and the
    // links' bending stiffness.
    both_integrators_agree(
        "dynamics/free_chain.toml",
        0.3,
        &[
            "initial_velocity[0].angular[2]",
            "initial_velocity[4].linear[1]",
            "section.link.EI[0]",
        ],
    );
}

#[test]
fn sensitivities_by_an_expression_joints_parameters_equal_central_differences() {
    // The ellipse cam of data/examples (semi-axes a, b: the follower starts
    // at −a x whatever b is), its angle driven through a quarter turn under
    // gravity: d/db in dynamics with both Newmark-family integrators, and in
    // statics (the angle driven by the load factor).
    both_integrators_agree(
        "examples/expression_cam.toml",
        0.5,
        &["joint.cam.parameters.b", "section.arm.EI[0]"],
    );
    let path = data("examples/expression_cam.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let solver = text.find("[solver]").unwrap();
    let statics = format!(
        "{}[solver]\nanalysis = \"static\"\nload_steps = 6\ntolerance = 1e-12\n\n[output]\n\
         track = [\"arm.end\", \"arm.start\"]\nsensitivity = [\"joint.cam.parameters.b\"]\n",
        &text[..solver]
    )
    .replace("pi*(t - sin(2*pi*t)/(2*pi))", "pi/2*lambda");
    assert_static_agrees(&parse_model(&statics, &path).unwrap());
    // `a` moves the follower at t = 0, and with it the arm it carries: the
    // arm re-placed along −x. Held by a support as well, the arm could not
    // move rigidly: refused, naming the support.
    let by_a = statics.replace("parameters.b\"]", "parameters.a\"]");
    let by_a = parse_model(&by_a, &path).unwrap();
    for (displacement, energy) in replaced_mismatch(&by_a, &["arm"], |_| [-1.0, 0.0, 0.0]) {
        assert!(
            displacement < AGREE && energy < AGREE,
            "{displacement:e} {energy:e}"
        );
    }
    let held = statics.replace("parameters.b\"]", "parameters.a\"]")
        + "[[support]]\nnode = \"arm.end\"\nfixed = [\"uz\"]\n";
    let mut memory = Memory::default();
    let message = run(&parse_model(&held, &path).unwrap(), &mut memory)
        .unwrap_err()
        .to_string();
    assert!(
        message.contains("moves the slave at t = 0") && message.contains("support of `arm.end`"),
        "{message}"
    );
}

#[test]
fn sensitivities_by_the_parameter_of_a_free_joint_in_statics_and_dynamics() {
    // A screw written as an expression, f(ψ) = (0, 0, c ψ), between a
    // clamped post and an arm whose far end is held sideways: the twist
    // of the joint is found by equilibrium (its ψ is an unknown), so the
    // derivative by the pitch c goes through the ψ equation.
    let text = r#"name = "free-screw"
[[section]]
name = "rod"
EA = 1.0e6
GA = [4.0e5, 4.0e5]
GJ = 800.0
EI = [1000.0, 1000.0]
[[beam]]
name = "post"
section = "rod"
start = [0.0, 0.0, 0.0]
end = [0.0, 0.0, 1.0]
e2 = [1.0, 0.0, 0.0]
elements = 4
[[beam]]
name = "arm"
section = "rod"
start = [0.0, 0.0, 1.0]
end = [1.0, 0.0, 1.0]
e2 = [0.0, 1.0, 0.0]
elements = 4
[[support]]
node = "post.start"
fixed = "all"
[[support]]
node = "arm.end"
fixed = ["uy"]
[[joint]]
name = "screw"
type = "expression"
master = "post.end"
slave = "arm.start"
axis = [0.0, 0.0, 1.0]
translation = ["0", "0", "c*psi"]
parameters = { c = 0.3 }
[[load]]
node = "arm.end"
force = [0.0, 40.0, -30.0]
moment = [0.0, 0.0, 0.0]
[solver]
analysis = "static"
load_steps = 4
tolerance = 1e-12
[output]
track = ["arm.end", "arm.start"]
sensitivity = ["joint.screw.parameters.c", "section.rod.GJ"]
"#;
    assert_static_agrees(&parse_model(text, std::path::Path::new("free_screw.toml")).unwrap());
    // The same in dynamics as the built-in screw, the load applied at once
    // to the arm given mass, with the pitch (through the free angle's
    // equation and its initial acceleration) and the rack-and-pinion's
    // radius (which re-places the arm at t = 0 along t_r × t = −y).
    let dynamic = |joint: &str, key: &str, integrator: &str| {
        let text = text
            .replace(
                "start = [0.0, 0.0, 1.0]\nend = [1.0, 0.0, 1.0]",
                if joint.contains("rack") {
                    // The pinion's centre sits b (t_r × t) = −0.1 y off the rack.
                    "start = [0.0, -0.1, 1.0]\nend = [1.0, -0.1, 1.0]"
                } else {
                    "start = [0.0, 0.0, 1.0]\nend = [1.0, 0.0, 1.0]"
                },
            )
            .replace(
                "[[support]]\nnode = \"arm.end\"\nfixed = [\"uy\"]\n",
                // The radius re-places the arm, which a support would hold.
                if joint.contains("rack") {
                    ""
                } else {
                    "[[support]]\nnode = \"arm.end\"\nfixed = [\"uy\"]\n"
                },
            )
            .replace(
                "GJ = 800.0",
                "GJ = 800.0\nrhoA = 2.0\nrhoJ = [0.02, 0.01, 0.01]",
            )
            .replace("type = \"expression\"", joint)
            .replace(
                "translation = [\"0\", \"0\", \"c*psi\"]\nparameters = { c = 0.3 }\n",
                "",
            )
            .replace("force = [0.0, 40.0, -30.0]", "force = [0.0, 4.0, -3.0]")
            .replace(
                "analysis = \"static\"\nload_steps = 4",
                &format!(
                    "analysis = \"dynamic\"\nintegrator = \"{integrator}\"\ndt = 0.01\n\
                     t_end = 0.3\nmax_halvings = 0"
                ),
            )
            .replace("[\"joint.screw.parameters.c\", \"section.rod.GJ\"]", key);
        parse_model(&text, std::path::Path::new("free_screw.toml")).unwrap()
    };
    for integrator in NEWMARK_FAMILY.into_iter().chain(MIDPOINT_SCHEMES) {
        // The midpoint schemes keep this free system's energy nearly
        // constant: its derivatives (≤ 1e-6) sit at the differences'
        // resolution of the energy (~4e-10 absolute), so only the Newmark
        // family's are compared.
        let energy_bound = if NEWMARK_FAMILY.contains(&integrator) {
            AGREE_DYNAMICS
        } else {
            f64::INFINITY
        };
        let screw = dynamic(
            "type = \"screw\"\npitch = 0.3",
            "[\"joint.screw.pitch\"]",
            integrator,
        );
        let rack = dynamic(
            "type = \"rack_pinion\"\nradius = 0.1\nslide = [1.0, 0.0, 0.0]",
            "[\"joint.screw.radius\"]",
            integrator,
        );
        for (model, dx) in [(screw, [0.0; 3]), (rack, [0.0, -1.0, 0.0])] {
            for (d, e) in replaced_mismatch(&model, &["arm"], |_| dx) {
                assert!(d < AGREE_DYNAMICS, "{integrator}: {d:e}");
                assert!(e < energy_bound, "{integrator}: energy {e:e}");
            }
        }
    }
}

/// The last step's exact derivatives of the tracked nodes against central
/// differences of two perturbed runs, within the statics' bound.
fn assert_static_agrees(model: &Model) {
    let built = build(model).unwrap();
    let last = last_step(model);
    let mut quiet = model.clone();
    quiet.output.sensitivity.clear();
    for (k, (key, _)) in model.output.sensitivity.iter().enumerate() {
        let (plus, v) = perturbed_model(&quiet, key, STEP);
        let (minus, _) = perturbed_model(&quiet, key, -STEP);
        let (plus, minus) = (last_step(&plus), last_step(&minus));
        let dp = 2.0 * STEP * v;
        let (mut exact, mut fd) = (Vec::new(), Vec::new());
        for (_, r) in &model.output.track {
            let n = built.node(*r);
            exact.push(last.sensitivities[k].displacement[n]);
            fd.push([0, 1, 2].map(|c| (plus.positions[n][c] - minus.positions[n][c]) / dp));
        }
        let e = mismatch(&exact, &fd);
        assert!(
            e < AGREE,
            "{}: {key}: {exact:?} vs {fd:?} ({e:e})",
            model.name
        );
        let fd_energy = (plus.energy.total - minus.energy.total) / dp;
        let e = (last.sensitivities[k].energy - fd_energy).abs() / fd_energy.abs();
        assert!(e < AGREE, "{}: {key}: energy {e:e}", model.name);
    }
}

#[test]
fn dynamic_sensitivities_by_a_rigid_bodys_mass_and_inertia() {
    // The body pendulum: a rod on a hinge carrying an offset bob, swinging
    // under gravity; derivatives by the bob's mass and its inertia about
    // the hinge's axis, and the rod's initial spin.
    both_integrators_agree(
        "dynamics/body_pendulum.toml",
        0.5,
        &[
            "rigid_body.bob.mass",
            "rigid_body[0].inertia[2][2]",
            "initial_velocity[0].angular[2]",
        ],
    );
}

#[test]
fn a_figures_derivative_key_the_model_cannot_take_is_refused_as_the_figures() {
    let dir = tempfile::tempdir().unwrap();
    let model = data("statics/sensitivity_frame.toml");
    let study = format!(
        "name = \"bad-derivative\"\nmodel = \"{}\"\n[grid]\n\"section.post.EI[0]\" = [1000.0]\n\
         [output]\nfigures = [{{ name = \"tip\", dataset = \"/nodes/arm.end/displacement\", \
         reduce = \"final\", derivative = [\"section.post.EI[3]\"] }}]\n",
        model.display()
    );
    let file = dir.path().join("study.toml");
    std::fs::write(&file, study).unwrap();
    let spec = flexmech::studies::load_study(&file).unwrap();
    let message = spec.run(dir.path().join("out")).unwrap_err().to_string();
    assert!(message.contains("a figure's `derivative`"), "{message}");
    assert!(message.contains("section.post.EI[3]"), "{message}");
    assert!(!message.contains("[grid]"), "{message}");
}

/// `model` with the value at `key` scaled by `1 + h` and the beams
/// `carried` translated by `direction` times the value's change: the model a
/// researcher writes by hand to change a value that moves a joint's slave
/// at t = 0 (e.g. a cam's offset moves the follower and the arm on it).
fn replaced_model(
    model: &Model,
    key: &str,
    h: f64,
    carried: &[&str],
    direction: [f64; 3],
) -> Model {
    let (moved, v) = perturbed_model(model, key, h);
    let mut table: toml::Table = toml::from_str(&moved.to_toml()).unwrap();
    for beam in table["beam"].as_array_mut().unwrap() {
        let beam = beam.as_table_mut().unwrap();
        if !carried.contains(&beam["name"].as_str().unwrap()) {
            continue;
        }
        for end in ["start", "end"] {
            for (c, x) in beam[end].as_array_mut().unwrap().iter_mut().enumerate() {
                *x = toml::Value::Float(x.as_float().unwrap() + direction[c] * v * h);
            }
        }
    }
    parse_model(&toml::to_string(&table).unwrap(), &model.path).unwrap()
}

/// Every kept step's exact displacement derivatives of the tracked nodes
/// against central differences of [`replaced_model`]'s displacements (each
/// run's positions less its own initial ones), and the energy's: the
/// largest differences over the largest derivatives. `direction` gives each
/// key's `dX/dp` of the carried beams (zero for a key that moves no slave).
fn replaced_mismatch(
    model: &Model,
    carried: &[&str],
    direction: impl Fn(&str) -> [f64; 3],
) -> Vec<(f64, f64)> {
    replaced_mismatch_at(model, carried, direction, STEP)
}

/// [`replaced_mismatch`] with the relative step `step`.
fn replaced_mismatch_at(
    model: &Model,
    carried: &[&str],
    direction: impl Fn(&str) -> [f64; 3],
    step: f64,
) -> Vec<(f64, f64)> {
    moved_mismatch(model, |quiet, key, sign| {
        let (_, v) = perturbed_model(quiet, key, 0.0);
        let moved = replaced_model(quiet, key, sign * step, carried, direction(key));
        (moved, step * v)
    })
}

/// [`replaced_mismatch`] for models `make(quiet, key, ±1)` moved by `±Δp`
/// (it returns the model and `Δp`).
fn moved_mismatch(
    model: &Model,
    make: impl Fn(&Model, &str, f64) -> (Model, f64),
) -> Vec<(f64, f64)> {
    let built = build(model).unwrap();
    let tracked: Vec<usize> = (model.output.track.iter())
        .map(|(_, r)| built.node(*r))
        .collect();
    let records = |m: &Model| {
        let mut memory = Memory::default();
        run(m, &mut memory).unwrap();
        assert_eq!(memory.status(), "completed");
        let x0 = build(m).unwrap().mechanism.mesh.positions;
        (memory.records, x0)
    };
    let (exact, _) = records(model);
    let mut quiet = model.clone();
    quiet.output.sensitivity.clear();
    let mut out = Vec::new();
    for (k, (key, _)) in model.output.sensitivity.iter().enumerate() {
        let ((up, step), (down, _)) = (make(&quiet, key, 1.0), make(&quiet, key, -1.0));
        let ((plus, x_plus), (minus, x_minus)) = (records(&up), records(&down));
        assert_eq!(plus.len(), exact.len(), "{key}: the same steps");
        let dp = 2.0 * step;
        let (mut d_exact, mut d_fd, mut e_exact, mut e_fd) = (vec![], vec![], vec![], vec![]);
        for ((rec, p), m) in exact.iter().zip(&plus).zip(&minus) {
            for &n in &tracked {
                d_exact.push(rec.sensitivities[k].displacement[n]);
                d_fd.push([0, 1, 2].map(|c| {
                    let (up, down) = (
                        p.positions[n][c] - x_plus[n][c],
                        m.positions[n][c] - x_minus[n][c],
                    );
                    (up - down) / dp
                }));
            }
            e_exact.push([rec.sensitivities[k].energy, 0.0, 0.0]);
            e_fd.push([(p.energy.total - m.energy.total) / dp, 0.0, 0.0]);
        }
        out.push((mismatch(&d_exact, &d_fd), mismatch(&e_exact, &e_fd)));
    }
    out
}

#[test]
fn the_driven_cams_lift_by_its_offset_and_radius_in_dynamics() {
    // The paper's eccentric cam (data/paper/cam.toml) spun up from rest for
    // 0.4 s: d/d(offset a) — which moves the follower at t = 0, so the arm
    // riding on it is re-placed with it along −t_r = −x — and d/d(radius R),
    // which does not (f(ψ₀) = −a t_r), with every integrator (the paper's
    // scheme at its differences' step, see PAPER_STEP).
    let paper = ["energy-momentum-paper"];
    let all = NEWMARK_FAMILY
        .into_iter()
        .chain(MIDPOINT_SCHEMES)
        .chain(paper);
    for integrator in all {
        let model = dynamic_model(
            "paper/cam.toml",
            0.4,
            integrator,
            &["joint.cam.offset", "joint.cam.radius"],
        );
        let step = if paper.contains(&integrator) {
            PAPER_STEP
        } else {
            STEP
        };
        for (k, (displacement, energy)) in
            replaced_mismatch_at(&model, &["arm"], offset_moves_x, step)
                .into_iter()
                .enumerate()
        {
            assert!(
                displacement < AGREE_DYNAMICS,
                "{integrator} {k}: {displacement:e}"
            );
            assert!(
                energy < AGREE_DYNAMICS,
                "{integrator} {k}: energy {energy:e}"
            );
        }
    }
}

#[test]
fn the_driven_cam_in_statics_by_its_offset_and_radius() {
    // data/statics/cam_driven.toml (two turns of a driven cam with a dead
    // tip load on the arm it carries), shortened to 10 steps: d/d(offset)
    // with the arm re-placed along −x, d/d(radius), within the statics' bound.
    let path = data("statics/cam_driven.toml");
    let text = std::fs::read_to_string(&path)
        .unwrap()
        .replace("load_steps = 80", "load_steps = 10")
        .replace("tolerance = 1e-10", "tolerance = 1e-12");
    let text = format!("{text}sensitivity = [\"joint.drive.offset\", \"joint.drive.radius\"]\n");
    let model = parse_model(&text, &path).unwrap();
    for (displacement, energy) in replaced_mismatch(&model, &["arm"], offset_moves_x) {
        assert!(displacement < AGREE, "{displacement:e}");
        assert!(energy < AGREE, "energy {energy:e}");
    }
}

/// The cams' `dX/dp` of the carried arm: `−t_r = −x` by the offset, none by
/// the radius (`f(ψ₀) = −a t_r` at ψ₀ = 0).
fn offset_moves_x(key: &str) -> [f64; 3] {
    if key.ends_with("offset") {
        [-1.0, 0.0, 0.0]
    } else {
        [0.0; 3]
    }
}

/// The conserving schemes that compute sensitivities.
const MIDPOINT_SCHEMES: [&str; 2] = ["momentum", "energy-momentum"];

/// The central differences' step for the paper's scheme, ten times
/// [`STEP`]: the scheme accepts its energy equation at that equation's
/// round-off floor, and the noise this leaves in its runs, over a step of
/// 1e-4, is of the order of the bound. At 1e-3 the spin-up's energy
/// derivative (to [`PAPER_SPIN_UP_END`]) differs by 3.3e-6 of its largest
/// value: truncation, 1.3e-5 at 2e-3 and 5.5e-5 at 4e-3.
const PAPER_STEP: f64 = 1e-3;

/// The end of the spin-up the paper's scheme is differentiated over. Past
/// 1.85 s its β falls from −0.13 to −0.013 within a tenth of a second, its
/// steps take 5–7 iterations, and its solutions, accepted at a round-off
/// floor of 1e-9–1e-8 of the force scale, differ between the perturbed runs
/// by up to 6e-4 of the energy derivative times `2h` at `h` = 5e-4,
/// alternating in sign from step to step: noise, not the derivative (which
/// agrees to 6.8e-5 at 1e-3 to 2 s, the differences' truncation and noise
/// together). To 2 s the mismatch at 1e-3 sat at 6.8e-5 against the bound
/// of 1e-4 and any change of round-off could cross it; to 1.8 s the
/// differences converge as h² (3.3e-6, 1.3e-5, 5.5e-5 at 1e-3, 2e-3, 4e-3)
/// with noise below 2e-6 at 5e-4.
const PAPER_SPIN_UP_END: f64 = 1.8;

// The bordered step on (q, β): dβ/dp from the energy equation's row (eq. 18)
// with its derivative along p and the history. One test per model (the
// suite runs them side by side): the spin-up's first 1.8 s, the four-bar's
// first 1.5 s, the paper's cam (0.4 s) and the frame released through its
// rigid corner under its loads and weight.

/// The paper's scheme on `file` to `t_end`, d/d `keys`, against central
/// differences of step [`PAPER_STEP`].
fn papers_energy_momentum_agrees(file: &str, t_end: f64, keys: &[&str]) {
    let paper = "energy-momentum-paper";
    let model = dynamic_model(file, t_end, paper, keys);
    assert_dynamic_agrees_at(&model, paper, PAPER_STEP);
}

#[test]
fn sensitivities_with_the_papers_energy_momentum_scheme_on_the_spin_up() {
    let keys = ["section.blade.EI[1]"];
    papers_energy_momentum_agrees("benchmarks/spin_up.toml", PAPER_SPIN_UP_END, &keys);
}

#[test]
fn sensitivities_with_the_papers_energy_momentum_scheme_on_the_four_bar() {
    let keys = ["section.bar8.EI[0]", "section.bar16.GJ"];
    papers_energy_momentum_agrees("benchmarks/four_bar_tacs.toml", 1.5, &keys);
}

#[test]
fn sensitivities_with_the_papers_energy_momentum_scheme_on_the_cam() {
    papers_energy_momentum_agrees(
        "paper/cam.toml",
        0.4,
        &["section.arm.EI[0]", "section.arm.rhoA"],
    );
}

#[test]
fn sensitivities_with_the_papers_energy_momentum_scheme_on_the_released_frame() {
    // Stiffnesses, a mass, the tip force and moment, the distributed load.
    let paper = "energy-momentum-paper";
    let text = frame_in_dynamics(paper, true);
    let mut model = parse_model(&text, &data("statics/sensitivity_frame.toml")).unwrap();
    model.add_sensitivity(&["section.arm.rhoA".into()]).unwrap();
    assert_dynamic_agrees_at(&model, paper, PAPER_STEP);
}

#[test]
fn sensitivities_with_the_conserving_schemes_equal_central_differences() {
    // The momentum and energy-momentum schemes (history through the element
    // force's start pose and the midpoint inertia): the spin-up's first 2 s
    // (d tip / d EI₃), the flying spaghetti's first 3 s as its load rises
    // (d/d bending and torsional stiffness, ρA, ρJ, the load's moment) and
    // the free spinning beam of 3-node elements (d/d its initial spin, d/d ρA:
    // its energy is the initial kinetic one, which a stiffness leaves alone).
    let cases: [(&str, f64, &[&str]); 3] = [
        ("benchmarks/spin_up.toml", 2.0, &["section.blade.EI[1]"]),
        (
            "benchmarks/flying_spaghetti.toml",
            3.0,
            &[
                "section.rod.EI[0]",
                "section.rod.GJ",
                "section.rod.rhoA",
                "section.rod.rhoJ[0]",
                "load[0].moment[2]",
            ],
        ),
        (
            "dynamics/spinning_beam.toml",
            4.0,
            &["initial_velocity[0].angular[2]", "section.rod.rhoA"],
        ),
    ];
    for (file, t_end, keys) in cases {
        for integrator in MIDPOINT_SCHEMES {
            let model = dynamic_model(file, t_end, integrator, keys);
            assert_dynamic_agrees(&model, integrator);
        }
    }
}

#[test]
fn sensitivities_with_the_conserving_schemes_through_joints() {
    // Joints through the incremental map Ñ of each step's start: the
    // four-bar's first 1.5 s (revolutes and drive; d/d EI₂ of the links,
    // d/d GJ of the crank and coupler), the free chain of every joint kind
    // (0.3 s; d/d a link's spin and a middle link's velocity — not d/d EI₂:
    // the free chain's energy is conserved, its derivative by a stiffness
    // ~1e-8 is the differences' round-off),
    // the paper's driven cam (0.4 s; d/d the arm's EI₂ and ρA) and the
    // frame released through its rigid corner under its loads and weight
    // (the tip force, the distributed load, both sections' EI₂, the arm's ρA).
    let cases: [(&str, f64, &[&str]); 3] = [
        (
            "benchmarks/four_bar_tacs.toml",
            1.5,
            &["section.bar8.EI[0]", "section.bar16.GJ"],
        ),
        (
            "dynamics/free_chain.toml",
            0.3,
            &[
                "initial_velocity[0].angular[2]",
                "initial_velocity[4].linear[1]",
            ],
        ),
        (
            "paper/cam.toml",
            0.4,
            &["section.arm.EI[0]", "section.arm.rhoA"],
        ),
    ];
    for integrator in MIDPOINT_SCHEMES {
        for (file, t_end, keys) in cases {
            let model = dynamic_model(file, t_end, integrator, keys);
            assert_dynamic_agrees(&model, integrator);
        }
        let text = frame_in_dynamics(integrator, true);
        let mut model = parse_model(&text, &data("statics/sensitivity_frame.toml")).unwrap();
        model.add_sensitivity(&["section.arm.rhoA".into()]).unwrap();
        assert_dynamic_agrees(&model, integrator);
    }
}

/// `model` with the coordinate at `key` (a beam's end) moved by `delta`.
fn shifted_model(model: &Model, key: &str, delta: f64) -> Model {
    use flexmech::model::key_path::{lookup_mut, KeyPath};
    let mut table: toml::Table = toml::from_str(&model.to_toml()).unwrap();
    let value = lookup_mut(&mut table, &KeyPath::parse(key).unwrap()).unwrap();
    *value = toml::Value::Float(value.as_float().unwrap() + delta);
    parse_model(&toml::to_string(&table).unwrap(), &model.path).unwrap()
}

/// Central differences of models whose beam end is moved by `±h`.
fn shifted_mismatch(model: &Model, h: f64) -> Vec<(f64, f64)> {
    moved_mismatch(model, |quiet, key, sign| {
        (shifted_model(quiet, key, sign * h), h)
    })
}

#[test]
fn the_linear_cantilevers_tip_by_its_length() {
    // w = F L³/(3EI)(1 − 1/(4n²)) + F L/GA for n 2-node elements (reduced
    // integration; the closed forms of the stiffness test above): moving the
    // end along the axis, dw/dL = F L²/EI (1 − 1/(4n²)) + F/GA, in the
    // linear range (w/L ~ 1e-5).
    let (n, l, ei, ga, f) = (8.0, 2.0, 1000.0, 4.0e6, 0.01);
    let text = format!(
        "name = \"arm\"\n[[section]]\nname = \"rod\"\nEA = 1.0e7\nGA = [{ga}, {ga}]\n\
         GJ = 800.0\nEI = [{ei}, {ei}]\n[[beam]]\nname = \"arm\"\nsection = \"rod\"\n\
         start = [0.0, 0.0, 0.0]\nend = [{l}, 0.0, 0.0]\ne2 = [0.0, 1.0, 0.0]\nelements = {n}\n\
         [[support]]\nnode = \"arm.start\"\nfixed = \"all\"\n[[load]]\nnode = \"arm.end\"\n\
         force = [0.0, 0.0, {f}]\n[solver]\nanalysis = \"static\"\nload_steps = 1\n\
         tolerance = 1e-12\n[output]\ntrack = [\"arm.end\"]\nsensitivity = [\"beam.arm.end[0]\"]\n"
    );
    let model = parse_model(&text, std::path::Path::new("cantilever.toml")).unwrap();
    let built = build(&model).unwrap();
    let tip = built.node(model.output.track[0].1);
    let exact = last_step(&model).sensitivities[0].displacement[tip][2];
    let closed = f * l * l / ei * (1.0 - 1.0 / (4.0 * n * n)) + f / ga;
    assert!(
        (exact - closed).abs() <= 1e-6 * closed,
        "{exact} vs {closed}"
    );
}

#[test]
fn sensitivities_by_a_beams_end_equal_central_differences() {
    // Moving a beam's end moves its nodes, lengthens and turns its elements:
    // the L-frame's post tilted and lengthened at its clamped foot and its
    // arm lengthened and tilted at its tip, under its distributed load
    // (statics, nonlinear), and the spin-up's blade lengthened (its tip's deflection,
    // 2 s, every integrator), against models with the end
    // moved by ±1e-4 of the beam's length.
    let path = data("statics/sensitivity_frame.toml");
    let mut frame = load_model(&path).unwrap();
    frame.output.sensitivity.clear();
    let keys = [
        "beam.post.start[0]".to_string(),
        "beam.post.start[2]".to_string(),
        "beam.arm.end[0]".to_string(),
        "beam.arm.end[2]".to_string(),
    ];
    frame.add_sensitivity(&keys).unwrap();
    frame.solver.tolerance = NEWTON;
    for (d, e) in shifted_mismatch(&frame, STEP * 2.0) {
        assert!(d < AGREE && e < AGREE, "frame: {d:e} {e:e}");
    }
    for integrator in NEWMARK_FAMILY.into_iter().chain(MIDPOINT_SCHEMES) {
        // The frame released under its loads and weight with its foot moved
        // (the support held at the moved place: a prescribed motion the
        // free equations see through the tangent and the inertia).
        let text = frame_in_dynamics(integrator, true);
        let mut model = parse_model(&text, &path).unwrap();
        model.output.sensitivity.clear();
        model.add_sensitivity(&keys).unwrap();
        model.solver.tolerance = NEWTON;
        for (d, e) in shifted_mismatch(&model, STEP * 2.0) {
            assert!(
                d < AGREE_DYNAMICS && e < AGREE_DYNAMICS,
                "{integrator}: {d:e} {e:e}"
            );
        }
        let blade = dynamic_model(
            "benchmarks/spin_up.toml",
            2.0,
            integrator,
            &["beam.blade.end[0]"],
        );
        for (d, e) in shifted_mismatch(&blade, STEP * 10.0) {
            assert!(
                d < AGREE_DYNAMICS && e < AGREE_DYNAMICS,
                "{integrator}: {d:e} {e:e}"
            );
        }
    }
    // Refused: the post's top carries the corner joint (at the key), and
    // the paper's energy-momentum scheme does not differentiate by geometry.
    let message = (frame.clone())
        .add_sensitivity(&["beam.post.end[0]".into()])
        .unwrap_err()
        .to_string();
    assert!(message.contains("joint `corner` ties"), "{message}");
    let blade = dynamic_model(
        "benchmarks/spin_up.toml",
        0.1,
        "energy-momentum-paper",
        &["beam.blade.end[0]"],
    );
    let message = run(&blade, &mut Memory::default()).unwrap_err().to_string();
    assert!(
        message.contains("paper's energy-momentum scheme"),
        "{message}"
    );
}
