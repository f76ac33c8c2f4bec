//! Joints in the conserving schemes (paper eqs 21–23): an unsupported
//! mechanism of two flexible beams tied by a joint of every kind, spinning,
//! translating and with its joint moving. With the exact incremental map `Ñ`
//! the momentum-conserving and energy–momentum schemes conserve linear and
//! angular momentum of the joined system to the Newton tolerance, the
//! energy–momentum scheme also its energy, and relation (1) holds to
//! round-off at every step of every integrator.

use flexmech_core::{MassKind, Mesh, Section};
use flexmech_integrators::dynamics::{energy_momentum, momentum, newmark, DynamicSettings, Motion};
use flexmech_integrators::{JointInstance, Mechanism, NewtonSettings, StepRecord};
use flexmech_joints::{
    Cam, Cylindrical, JointMap, Lift, Lobe, Prismatic, RackPinion, ReleasedState, Revolute, Rigid,
    Screw, Spherical, MAX_RELEASED,
};
use nalgebra::Vector3;
use std::sync::Arc;

const TOL: f64 = 1e-11;

fn kinds() -> Vec<(&'static str, Arc<dyn JointMap>)> {
    let z = Vector3::z();
    let y = Vector3::y();
    vec![
        ("rigid", Arc::new(Rigid)),
        ("revolute", Arc::new(Revolute { axis: z })),
        ("spherical", Arc::new(Spherical::default())),
        (
            "prismatic",
            Arc::new(Prismatic {
                slide: Vector3::x(),
            }),
        ),
        ("cylindrical", Arc::new(Cylindrical { axis: z, slide: z })),
        (
            "screw",
            Arc::new(Screw {
                axis: z,
                pitch: 0.05,
            }),
        ),
        (
            "rack_pinion",
            Arc::new(RackPinion {
                axis: z,
                slide: y,
                radius: 0.1,
            }),
        ),
        (
            "cam",
            Arc::new(Cam {
                axis: z,
                slide: y,
                radius: 0.05,
                offset: 0.02,
            }),
        ),
        (
            "lobe",
            Arc::new(Lobe::new(z, y, Lift::fourier(&[0.05, 0.01, 0.004]).unwrap()).unwrap()),
        ),
    ]
}

/// Beam A along x from the origin, beam B from A's tip + r_R(ψ₀) along y;
/// 3 flexible 2-node elements each, no supports, no loads.
fn free_pair(map: Arc<dyn JointMap>) -> (Mechanism, Motion) {
    free_pair_of(map, 3, 2)
}

/// [`free_pair`] with `elements` elements of `nodes` nodes per beam.
fn free_pair_of(map: Arc<dyn JointMap>, elements: usize, nodes: usize) -> (Mechanism, Motion) {
    let section = Section::new(
        [2.0e4, 1.0e4, 1.0e4],
        [60.0, 40.0, 40.0],
        1.0,
        [0.02, 0.01, 0.01],
    );
    let initial = ReleasedState::new([0.3, 0.0, 0.0, 0.0]);
    let (offset, _) = map.released_placement(&initial);
    let mut mesh = Mesh::default();
    let a = mesh
        .add_straight_beam(
            Vector3::zeros(),
            Vector3::x(),
            Vector3::z(),
            elements,
            nodes,
            section,
        )
        .unwrap();
    let start_b = Vector3::x() + offset;
    let b = mesh
        .add_straight_beam(
            start_b,
            start_b + Vector3::y() * 0.8,
            Vector3::z(),
            elements,
            nodes,
            section,
        )
        .unwrap();
    let nodes = mesh.node_count();
    let positions = mesh.positions.clone();
    let mut mech = Mechanism::new(mesh);
    let released = map.released_count();
    mech.joints.push(JointInstance {
        name: "joint".into(),
        master: *a.last().unwrap(),
        slave: b[0],
        map,
        initial,
        driven: vec![None; released],
    });
    // Spin about an oblique axis, a drift, and the joint moving.
    let omega = Vector3::new(0.3, -0.2, 2.0);
    let drift = Vector3::new(0.1, 0.4, -0.2);
    let mut motion = Motion::rest(nodes);
    for (i, x) in positions.iter().enumerate() {
        motion.v[i] = drift + omega.cross(x);
        motion.w[i] = omega;
    }
    motion.joint_rates = vec![1.5];
    assert!(MAX_RELEASED >= released);
    (mech, motion)
}

fn settings(dt: f64, t_end: f64) -> DynamicSettings {
    DynamicSettings {
        dt,
        t_end,
        newton: NewtonSettings {
            tolerance: TOL,
            max_iterations: 40,
            modified: false,
            exact_tangent: false,
        },
        max_halvings: 4,
        mass: MassKind::Consistent,
    }
}

/// Largest deviation of a vector series from its first value, relative to `scale`.
fn drift(series: impl Iterator<Item = [f64; 3]>, scale: f64) -> f64 {
    let v: Vec<Vector3<f64>> = series.map(Vector3::from).collect();
    v.iter().map(|x| (x - v[0]).norm()).fold(0.0, f64::max) / scale
}

#[test]
fn conserving_schemes_carry_momentum_and_energy_through_every_joint_kind() {
    for (name, map) in kinds() {
        let (mech, motion) = free_pair(map);
        let s = settings(0.02, 1.0);
        let mut mc: Vec<StepRecord> = Vec::new();
        momentum::solve(&mech, &s, &motion, |r| mc.push(r.clone()))
            .unwrap_or_else(|e| panic!("{name}: momentum scheme failed: {e}"));
        let mut em: Vec<StepRecord> = Vec::new();
        energy_momentum::solve(&mech, &s, &motion, |r| em.push(r.clone()))
            .unwrap_or_else(|e| panic!("{name}: energy–momentum scheme failed: {e}"));
        for (scheme, steps) in [("MC", &mc), ("EM", &em)] {
            assert!((steps.last().unwrap().time - 1.0).abs() < 1e-12);
            let l0 = Vector3::from(steps[0].momentum_linear).norm();
            let h0 = Vector3::from(steps[0].momentum_angular).norm();
            let dl = drift(steps.iter().map(|r| r.momentum_linear), l0);
            let dh = drift(steps.iter().map(|r| r.momentum_angular), h0);
            let worst_c = steps
                .iter()
                .map(|r| r.joints[0].constraint_error)
                .fold(0.0, f64::max);
            let iters: usize = steps.iter().map(|r| r.iterations).sum();
            let e0 = steps[0].energy.total;
            let de = steps
                .iter()
                .map(|r| (r.energy.total - e0).abs())
                .fold(0.0, f64::max)
                / e0;
            let travel = steps.last().unwrap().joints[0].angle - steps[0].joints[0].angle;
            eprintln!(
                "{name:12} {scheme}: momentum drift {dl:.1e} / {dh:.1e}, energy {de:.1e}, constraint {worst_c:.1e}, {:.1} iterations/step, joint angle moved {travel:.3}",
                iters as f64 / (steps.len() - 1) as f64
            );
            // Newton stops at a relative residual of 1e-11; summed over 50
            // steps the momenta may drift by ~50 × that.
            assert!(
                dl <= 1e-9 && dh <= 1e-9,
                "{name} {scheme}: momentum drift {dl:e} / {dh:e}"
            );
            assert!(worst_c <= 1e-12, "{name} {scheme}: constraint {worst_c:e}");
            if scheme == "EM" {
                assert!(de <= 1e-9, "{name} EM: energy drift {de:e}");
            }
        }
        let mut nm: Vec<StepRecord> = Vec::new();
        newmark::solve(&mech, &s, &motion, |r| nm.push(r.clone()))
            .unwrap_or_else(|e| panic!("{name}: Newmark failed: {e}"));
        let worst_c = nm
            .iter()
            .map(|r| r.joints[0].constraint_error)
            .fold(0.0, f64::max);
        assert!(worst_c <= 1e-12, "{name} Newmark: constraint {worst_c:e}");
    }
}

#[test]
fn three_node_elements_carry_momentum_and_energy_through_every_joint_kind() {
    // The same free pair meshed with two 3-node elements per beam, in the
    // energy–momentum scheme: energy and momenta to the Newton tolerance,
    // constraints at round-off, for every joint kind.
    for (name, map) in kinds() {
        let (mech, motion) = free_pair_of(map, 2, 3);
        let mut em: Vec<StepRecord> = Vec::new();
        energy_momentum::solve(&mech, &settings(0.02, 0.3), &motion, |r| em.push(r.clone()))
            .unwrap_or_else(|e| panic!("{name}: energy–momentum scheme failed: {e}"));
        assert_eq!(em.len(), 16, "{name}: a step was halved");
        let l0 = Vector3::from(em[0].momentum_linear).norm();
        let h0 = Vector3::from(em[0].momentum_angular).norm();
        let dl = drift(em.iter().map(|r| r.momentum_linear), l0);
        let dh = drift(em.iter().map(|r| r.momentum_angular), h0);
        let e0 = em[0].energy.total;
        let de = em
            .iter()
            .map(|r| (r.energy.total - e0).abs())
            .fold(0.0, f64::max)
            / e0;
        let worst_c = em
            .iter()
            .map(|r| r.joints[0].constraint_error)
            .fold(0.0, f64::max);
        eprintln!("{name:12} 3-node EM: momentum {dl:.1e} / {dh:.1e}, energy {de:.1e}, constraint {worst_c:.1e}");
        assert!(
            dl <= 1e-9 && dh <= 1e-9,
            "{name}: momentum drift {dl:e} / {dh:e}"
        );
        assert!(de <= 1e-9, "{name}: energy drift {de:e}");
        assert!(worst_c <= 1e-12, "{name}: constraint {worst_c:e}");
    }
}

/// Residuals above this are far from round-off (scaled residual).
const ABOVE_ROUND_OFF: f64 = 1e-11;
/// Quadratic convergence: `rₖ₊₁ ≤ C rₖ²` over the iterations above round-off.
const QUADRATIC: f64 = 50.0;

#[test]
fn newton_converges_quadratically_with_joints_in_the_conserving_schemes() {
    // Newton's tangent is the exact derivative of Ñᵀg: every pair of
    // successive residuals above round-off satisfies rₖ₊₁ ≤ 50 rₖ². (With the
    // end-point tangent of Nᵀg the convergence is linear, rₖ₊₁ ≈ 0.01–0.1 rₖ,
    // and this fails.)
    for (name, map) in kinds() {
        let (mech, motion) = free_pair(map);
        let mut s = settings(0.05, 0.5);
        s.newton.tolerance = 1e-13;
        // The exact tangent at every iterate (the energy–momentum scheme
        // otherwise starts with its cheaper one).
        s.newton.exact_tangent = true;
        for scheme in ["MC", "EM"] {
            let mut steps: Vec<StepRecord> = Vec::new();
            let push = |r: &StepRecord| steps.push(r.clone());
            if scheme == "MC" {
                momentum::solve(&mech, &s, &motion, push)
            } else {
                energy_momentum::solve(&mech, &s, &motion, push)
            }
            .unwrap_or_else(|e| panic!("{name} {scheme}: {e}"));
            let mut worst = 0.0f64;
            for r in &steps[1..] {
                for w in r.residual_history.windows(2) {
                    if w[1] > ABOVE_ROUND_OFF {
                        worst = worst.max(w[1] / (w[0] * w[0]));
                    }
                }
            }
            eprintln!(
                "{name:12} {scheme}: max r(k+1)/r(k)² = {worst:.2e}; history of step 5: {:?}",
                steps[5].residual_history
            );
            assert!(
                worst <= QUADRATIC,
                "{name} {scheme}: r(k+1)/r(k)² up to {worst:e}"
            );
        }
    }
}

#[test]
fn the_energy_momentum_schemes_cheap_tangent_reaches_the_exact_tangents_solution() {
    // The cheap tangent (the momentum scheme's closed form) changes Newton's
    // path, not its solution: every step's positions agree with the run
    // using the exact tangent throughout to what the Newton tolerance
    // leaves, and a step has at most one iteration after the first
    // contracting the residual by less than INEXACT_CONTRACTION: after it
    // Newton uses the exact one (the first correction, from the predictor,
    // is not judged: INEXACT_JUDGED_FROM).
    use flexmech_integrators::newton::{INEXACT_CONTRACTION, INEXACT_JUDGED_FROM};
    for (name, map) in kinds() {
        let (mech, motion) = free_pair(map);
        let mut runs = Vec::new();
        for exact in [true, false] {
            let mut s = settings(0.02, 1.0);
            s.newton.exact_tangent = exact;
            let mut steps: Vec<StepRecord> = Vec::new();
            energy_momentum::solve(&mech, &s, &motion, |r| steps.push(r.clone()))
                .unwrap_or_else(|e| panic!("{name} (exact tangent {exact}): {e}"));
            runs.push(steps);
        }
        let (exact, cheap) = (&runs[0], &runs[1]);
        assert_eq!(exact.len(), cheap.len(), "{name}");
        let size = exact[0]
            .positions
            .iter()
            .map(|p| Vector3::from(*p).norm())
            .fold(0.0, f64::max);
        let mut worst = 0.0f64;
        for (a, b) in exact.iter().zip(cheap) {
            for (p, q) in a.positions.iter().zip(&b.positions) {
                worst = worst.max((Vector3::from(*p) - Vector3::from(*q)).norm() / size);
            }
        }
        let slow = cheap
            .iter()
            .flat_map(|r| r.residual_history.windows(2).skip(INEXACT_JUDGED_FROM - 1))
            .filter(|w| w[1] > TOL && w[1] > INEXACT_CONTRACTION * w[0])
            .count();
        let iterations = |steps: &[StepRecord]| steps.iter().map(|r| r.iterations).sum::<usize>();
        eprintln!(
            "{name:12} cheap vs exact tangent: positions within {worst:.1e}, iterations {} vs {}, {slow} slow iterations",
            iterations(cheap),
            iterations(exact)
        );
        // 50 steps, each converged to a scaled residual of TOL.
        assert!(worst <= 1e3 * TOL, "{name}: positions differ by {worst:e}");
        assert!(slow < cheap.len(), "{name}: {slow} slow iterations");
    }
}

#[test]
fn the_recorded_correction_size_is_that_of_the_converged_step() {
    // The energy–momentum record's `beta` (the discrete gradient's
    // corrections relative to its force) is tallied during Newton's last
    // residual evaluation; recomputed from the stored end configurations of
    // each step it is the same number, to the round-off of the stored
    // rotations (quaternions) in a size measured relative to the force:
    // 1e3 ε, where an evaluation at another iterate would differ by the
    // order of `beta` itself (~4e-9 here).
    use flexmech_integrators::dynamics::midpoint_kernels::correction_size;
    use nalgebra::{Matrix3, Quaternion, UnitQuaternion};
    let (mech, motion) = free_pair(Arc::new(Revolute { axis: Vector3::z() }));
    let mut steps: Vec<StepRecord> = Vec::new();
    energy_momentum::solve(&mech, &settings(0.02, 0.4), &motion, |r| {
        steps.push(r.clone())
    })
    .unwrap();
    let config = |r: &StepRecord| flexmech_core::Configuration {
        x: r.positions.iter().map(|p| Vector3::from(*p)).collect(),
        rot: r
            .quaternions
            .iter()
            .map(|q| -> Matrix3<f64> {
                UnitQuaternion::from_quaternion(Quaternion::new(q[0], q[1], q[2], q[3]))
                    .to_rotation_matrix()
                    .into_inner()
            })
            .collect(),
    };
    let mut checked = 0;
    for w in steps.windows(2) {
        let recomputed = correction_size(&mech, &config(&w[0]), &config(&w[1]));
        assert!(w[1].beta > 0.0, "a turning pair has corrections");
        assert!(
            (w[1].beta - recomputed).abs() <= 1e3 * f64::EPSILON,
            "t = {}: recorded {:e}, recomputed {recomputed:e}",
            w[1].time,
            w[1].beta
        );
        checked += 1;
    }
    assert_eq!(checked, 20);
}
