//! Modes and buckling loads of beams against their closed forms, and the
//! sparse solver against the dense one.

use super::*;
use crate::builder::{BeamDef, BeamShape, Dof, MechanismBuilder, SectionValues};
use crate::mechanism::Schedule;
use crate::newton::NewtonSettings;

/// Euler–Bernoulli cantilever roots `β_i L`.
const CANTILEVER_BETA_L: [f64; 3] = [1.875_104_068_7, 4.694_091_132_9, 7.854_757_438_2];

fn slender() -> SectionValues {
    SectionValues {
        ea: 1e10,
        ga: [1e10; 2],
        gj: 1e3,
        ei: [1e3, 1e3],
        rho_a: 1.0,
        rho_j: [1e-9, 1e-9, 1e-9],
    }
}

fn cantilever(elements: usize, nodes_per_element: usize, tip_load: f64) -> Mechanism {
    let mut b = MechanismBuilder::new();
    let beam = b
        .beam(BeamDef {
            shape: BeamShape::Straight {
                start: Vector3::zeros(),
                end: Vector3::x(),
                e2: Vector3::y(),
            },
            elements,
            nodes_per_element,
            section: slender(),
        })
        .unwrap();
    b.fix(beam.start(), &Dof::ALL).unwrap();
    if tip_load != 0.0 {
        b.load(
            beam.end(),
            Vector3::new(-tip_load, 0.0, 0.0),
            Vector3::zeros(),
            Schedule::ramp(),
        )
        .unwrap();
    }
    b.build()
}

fn settings(modes: usize) -> ModalSettings {
    ModalSettings {
        request: ModeRequest {
            modes,
            mass: MassKind::Consistent,
            solver: None,
        },
        preload: StaticSettings {
            load_steps: 1,
            newton: NewtonSettings::default(),
            max_halvings: 4,
        },
    }
}

/// Relative errors of the first three bending frequencies (one per root:
/// the two planes give equal pairs) of a cantilever of `elements`.
fn bending_errors(elements: usize, nodes_per_element: usize) -> [f64; 3] {
    let mech = cantilever(elements, nodes_per_element, 0.0);
    let set = solve_modal(&mech, &settings(6), |_| {}).unwrap();
    assert_eq!(set.rigid, 0);
    let f = set.values();
    let scale = 1e3f64.sqrt() / std::f64::consts::TAU;
    std::array::from_fn(|i| {
        let exact = CANTILEVER_BETA_L[i].powi(2) * scale;
        assert!(
            (f[2 * i] - f[2 * i + 1]).abs() < 1e-7 * exact,
            "pair {i}: {f:?}"
        );
        f[2 * i] / exact - 1.0
    })
}

/// Euler–Bernoulli's cantilever frequencies `(β_i L)² √(EI/ρA L⁴)/2π`: the
/// 3-node element converges at fourth order, the 2-node one at second, to
/// within the shear and rotary-inertia corrections of this section
/// (`~½(βL)² EI/(GA L²) ≈ 2·10⁻⁷` for the first root).
#[test]
fn cantilever_bending_frequencies_converge_to_euler_bernoulli() {
    let (q8, q16, q32) = (
        bending_errors(8, 3),
        bending_errors(16, 3),
        bending_errors(32, 3),
    );
    for (i, e) in q32.iter().enumerate() {
        assert!(e.abs() < 5e-6, "3-node, 32 elements, root {i}: {e}");
    }
    for i in 1..3 {
        let order = (q8[i] / q16[i]).log2();
        assert!(
            (3.7..4.3).contains(&order),
            "3-node order, root {i}: {order}"
        );
    }
    let (l16, l32) = (bending_errors(16, 2), bending_errors(32, 2));
    for i in 0..3 {
        let order = (l16[i] / l32[i]).log2();
        assert!(
            (1.9..2.1).contains(&order),
            "2-node order, root {i}: {order}"
        );
    }
}

#[test]
fn sparse_solver_equals_the_dense_one() {
    let mech = cantilever(40, 2, 0.0);
    let state = initial_state(&mech);
    let mut lin = Linearisation::at(&mech, &state, Some(0.0)).unwrap();
    let mut k = lin.tangent();
    lin.pattern.symmetrize(&mut k);
    let m = lin.mass(MassKind::Consistent);
    let reference = diagonal_sum(&lin.pattern, &k) / diagonal_sum(&lin.pattern, &m);
    let omega2 = |solver| {
        let (s, (mu, _)) = shifted_modes(&lin.pattern, (&k, &m), 8, reference, solver).unwrap();
        mu.iter().map(|mu| 1.0 / mu - s).collect::<Vec<_>>()
    };
    let (d, s) = (omega2(EigenSolver::Dense), omega2(EigenSolver::Sparse));
    // Both solvers stop at the round-off floor of this very slender
    // section's conditioning (`EA L²/EI = 10⁷`), ~10⁻⁷ of `ω²`.
    for (x, y) in d.iter().zip(&s) {
        assert!((x - y).abs() < 1e-6 * x.abs(), "{x} vs {y}");
    }
}

#[test]
fn clamped_free_column_buckles_at_eulers_load() {
    let mech = cantilever(16, 3, 1.0);
    let set = buckling_modes(&mech, 4, None).unwrap();
    let exact = std::f64::consts::PI.powi(2) * 1e3 / 4.0;
    for k in 0..2 {
        let l = set.eigenvalues[k];
        assert!((l - exact).abs() < 1e-4 * exact, "mode {k}: {l} vs {exact}");
    }
}
