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
/// Relative step of the central differences (the 1e-4).
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
    }
}

/// Every node's final position by central differences: `dx/dp`.
fn central_difference(mech: &Mechanism, p: &Parameter, steps: usize) -> Vec<[f64; 3]> {
    let last = |h: f64| {
        solve(&perturbed(mech, p, h), steps, &[])
            .pop()
            .unwrap()
            .positions
    };
    let (plus, minus) = (last(STEP), last(-STEP));
    let dp = 2.0 * STEP * value(mech, p);
    plus.iter()
        .zip(&minus)
        .map(|(a, b)| [0, 1, 2].map(|c| (a[c] - b[c]) / dp))
        .collect()
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
    let d = |k: usize| last.sensitivities[k][tip][2];
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
        let e = mismatch(&last.sensitivities[k], &fd);
        assert!(e < AGREE, "{p:?}: {e:e}");
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
        let e = mismatch(&last.sensitivities[k], &fd);
        assert!(e < AGREE, "{p:?}: {e:e}");
    }
}
