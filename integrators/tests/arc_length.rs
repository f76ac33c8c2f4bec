//! Arc-length control traces a snap-through: the shallow two-bar truss
//! (von Mises truss) loaded at its apex, whose exact load–deflection curve
//! for bars with the Reissner axial strain `ε = L/L₀ − 1` is
//!
//! ```text
//! P(w) = 2 EA (L₀ − L)/L₀ · (h − w)/L,   L = √(a² + (h − w)²)
//! ```
//!
//! (`w` the apex's downward deflection): the load rises to a limit point,
//! falls through zero to a negative minimum (the truss snaps through) and
//! rises again once inverted. Load control stops at the limit point; the
//! arc-length path follows the whole curve.

use flexmech_integrators::arc_length::{solve_arc_length, ArcLengthSettings, PathStop};
use flexmech_integrators::builder::{
    BeamDef, BeamShape, Dof, JointDef, MechanismBuilder, SectionValues,
};
use flexmech_integrators::critical::CriticalKind;
use flexmech_integrators::{solve_static, Mechanism, NewtonSettings, Schedule, StaticSettings};
use flexmech_joints::Revolute;
use nalgebra::Vector3;
use std::sync::Arc;

const A: f64 = 1.0;
const H: f64 = 0.2;
const EA: f64 = 1e4;

fn truss(p_ref: f64) -> (Mechanism, usize) {
    let section = SectionValues {
        ea: EA,
        ga: [1e4; 2],
        gj: 1e3,
        ei: [1e3; 2],
        rho_a: 0.0,
        rho_j: [0.0; 3],
    };
    let mut b = MechanismBuilder::new();
    let apex = Vector3::new(0.0, H, 0.0);
    let bar = |b: &mut MechanismBuilder, start: Vector3<f64>| {
        b.beam(BeamDef {
            shape: BeamShape::Straight {
                start,
                end: apex,
                e2: Vector3::z(),
            },
            elements: 4,
            nodes_per_element: 2,
            section,
        })
        .unwrap()
    };
    let left = bar(&mut b, Vector3::new(-A, 0.0, 0.0));
    let right = bar(&mut b, Vector3::new(A, 0.0, 0.0));
    let pinned = [Dof::Ux, Dof::Uy, Dof::Uz, Dof::Rx, Dof::Ry];
    b.fix(left.start(), &pinned).unwrap();
    b.fix(right.start(), &pinned).unwrap();
    b.joint(JointDef {
        name: "apex".into(),
        map: Arc::new(Revolute { axis: Vector3::z() }),
        master: left.end(),
        slave: right.end(),
        angle: 0.0,
    })
    .unwrap();
    b.load(
        left.end(),
        Vector3::new(0.0, -p_ref, 0.0),
        Vector3::zeros(),
        Schedule::ramp(),
    )
    .unwrap();
    (b.build(), left.end().index())
}

/// The exact load at apex deflection `w`.
fn exact(w: f64) -> f64 {
    let l0 = (A * A + H * H).sqrt();
    let l = (A * A + (H - w) * (H - w)).sqrt();
    2.0 * EA * (l0 - l) / l0 * (H - w) / l
}

fn newton() -> NewtonSettings {
    NewtonSettings {
        tolerance: 1e-10,
        max_iterations: 25,
        modified: false,
        exact_tangent: false,
    }
}

#[test]
fn arc_length_traces_the_snap_through_of_a_two_bar_truss() {
    // The limit load, from the exact curve (fine scan, then the maximum).
    let (mut p_max, mut w_max) = (0.0, 0.0);
    for k in 0..=200_000 {
        let w = H * k as f64 / 200_000.0;
        if exact(w) > p_max {
            (p_max, w_max) = (exact(w), w);
        }
    }
    let p_ref = 2.0 * p_max;
    let (mech, apex) = truss(p_ref);
    let settings = ArcLengthSettings {
        load_steps: 10,
        newton: newton(),
        max_halvings: 8,
        max_steps: 400,
        branch_switch: false,
        stop: PathStop::default(),
    };
    let mut path: Vec<(f64, f64, Option<usize>)> = Vec::new();
    let mut critical = Vec::new();
    solve_arc_length(&mech, &settings, |r| {
        path.push((H - r.positions[apex][1], r.time * p_ref, r.negative_pivots));
        critical.extend(r.critical);
    })
    .unwrap();
    let last = path.last().unwrap();
    assert_eq!(last.1, p_ref, "ends at λ = 1");
    // Every point on the exact curve (the bars' strain is the Reissner
    // one; their bending is released by the pins).
    for &(w, p, _) in &path {
        assert!(
            (p - exact(w)).abs() < 1e-6 * p_max,
            "w = {w}: P = {p}, exact {}",
            exact(w)
        );
    }
    // Past the limit point, through the snap, onto the inverted branch
    // (the steps grow where the path is smooth, so the extremes of the
    // path are the located points below, not the steps themselves).
    let bottom = path.iter().map(|p| p.1).fold(f64::MAX, f64::min);
    eprintln!(
        "{} steps; limit load {p_max:.6} at w = {w_max:.5}; lowest step {bottom:.6}; final w = {:.4}",
        path.len(),
        last.0
    );
    assert!(bottom < 0.0, "the path did not snap through: min {bottom}");
    assert!(last.0 > 2.0 * H, "final deflection {}", last.0);
    // Both limit points located: the maximum p_max and, by the curve's
    // odd symmetry about the flat position (w = h), the minimum −p_max.
    // Bisection to 1e-6 of a step leaves the load factor within the
    // curve's quadratic flatness there — far below 1e-8 of p_max.
    eprintln!("located: {critical:?}");
    assert_eq!(critical.len(), 2, "{critical:?}");
    for (point, sign) in critical.iter().zip([1.0, -1.0]) {
        assert_eq!(point.kind, CriticalKind::Limit, "{point:?}");
        let p = point.load_factor * p_ref;
        assert!(
            (p - sign * p_max).abs() < 1e-8 * p_max,
            "{p} vs {}",
            sign * p_max
        );
        assert!(point.bracket * p_ref < 1e-4 * p_max, "{point:?}");
    }
    assert_eq!(
        (critical[0].negative_before, critical[0].negative_after),
        (0, 1)
    );
    // The stability report: stable before the limit point, unstable on the
    // falling branch.
    let falling = path
        .windows(2)
        .find(|w| w[1].1 < w[0].1)
        .expect("a falling branch");
    assert!(falling[1].2.unwrap_or(0) >= 1, "{:?}", falling[1]);
    assert_eq!(path[0].2, Some(0));
}

#[test]
fn load_control_stops_at_the_limit_point() {
    let (mut p_max, mut w) = (0.0f64, 0.0);
    while w < H {
        p_max = p_max.max(exact(w));
        w += 1e-5;
    }
    let (mech, _) = truss(2.0 * p_max);
    let settings = StaticSettings {
        load_steps: 10,
        newton: newton(),
        max_halvings: 4,
    };
    let mut reached = 0.0;
    let outcome = solve_static(&mech, &settings, |r| reached = r.time);
    // Load control either fails near λ = ½ or jumps to the far branch; it
    // cannot follow the falling branch.
    eprintln!(
        "load control: {:?}, reached λ = {reached}",
        outcome.as_ref().err()
    );
    assert!(outcome.is_err() || reached == 1.0);
}

#[test]
fn non_proportional_loads_are_refused() {
    let (mut mech, _) = truss(1.0);
    mech.loads[0].scale = Schedule::constant(1.0);
    let settings = ArcLengthSettings {
        load_steps: 10,
        newton: newton(),
        max_halvings: 4,
        max_steps: 100,
        branch_switch: false,
        stop: PathStop::default(),
    };
    let e = solve_arc_length(&mech, &settings, |_| {}).unwrap_err();
    assert!(e.to_string().contains("proportional"), "{e}");
}
