//! Element checks (FORMULATION §5): rigid motions give zero strain and force,
//! the closed-form residual is the gradient of the energy, and the tangent is
//! the derivative of the residual — each against an independent computation.

use super::*;
use crate::rotation::exp;
use proptest::prelude::*;

fn section() -> Section {
    Section::new(
        [2.0e4, 8.0e3, 9.0e3],
        [30.0, 45.0, 60.0],
        1.0,
        [0.2, 0.1, 0.1],
    )
}

/// Orthonormal triad with first column along `t`.
fn triad(t: Vector3<f64>, hint: Vector3<f64>) -> Matrix3<f64> {
    let t1 = t.normalize();
    let t2 = (hint - t1 * hint.dot(&t1)).normalize();
    Matrix3::from_columns(&[t1, t2, t1.cross(&t2)])
}

/// A straight 2-node element of length 1.3 along a tilted axis.
fn straight2() -> (BeamElement<2>, [Vector3<f64>; 2]) {
    let a = Vector3::new(0.2, -0.1, 0.3);
    let dir = Vector3::new(1.0, 0.4, -0.2).normalize();
    let x0 = [a, a + dir * 1.3];
    let l0 = triad(dir, Vector3::new(0.0, 0.0, 1.0));
    (BeamElement::new([0, 1], section(), 1.3, &x0, [l0, l0]), x0)
}

/// Nodes of a circular arc of radius 2 about e3, swept by `sweep`, `n` nodes.
fn arc<const N: usize>(sweep: f64) -> (BeamElement<N>, [Vector3<f64>; N]) {
    let r = 2.0;
    let x0: [Vector3<f64>; N] = std::array::from_fn(|i| {
        let a = sweep * i as f64 / (N - 1) as f64;
        Vector3::new(r * a.sin(), r * (1.0 - a.cos()), 0.0)
    });
    let l0: [Matrix3<f64>; N] = std::array::from_fn(|i| {
        let a = sweep * i as f64 / (N - 1) as f64;
        triad(
            Vector3::new(a.cos(), a.sin(), 0.0),
            Vector3::new(-a.sin(), a.cos(), 0.0),
        )
    });
    let nodes: [usize; N] = std::array::from_fn(|i| i);
    (BeamElement::new(nodes, section(), r * sweep, &x0, l0), x0)
}

fn vec3() -> impl Strategy<Value = Vector3<f64>> {
    (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64).prop_map(|(a, b, c)| Vector3::new(a, b, c))
}

/// A deformed state: positions moved by up to `du`, rotations up to `dr` rad.
fn deformed<const N: usize>(
    x0: &[Vector3<f64>; N],
    du: &[Vector3<f64>],
    dr: &[Vector3<f64>],
    scale_u: f64,
    scale_r: f64,
) -> ([Vector3<f64>; N], [Matrix3<f64>; N]) {
    (
        std::array::from_fn(|i| x0[i] + du[i] * scale_u),
        std::array::from_fn(|i| exp(&(dr[i] * scale_r))),
    )
}

fn rel(a: f64, scale: f64) -> f64 {
    a / scale.max(1e-300)
}

#[test]
fn initial_configuration_is_stress_free() {
    let (e, x0) = straight2();
    let id = [Matrix3::identity(); 2];
    assert!(e.energy(&x0, &id).abs() < 1e-20);
    // Round-off only: forces scale with the stiffness EA = 2e4.
    let f0 = e.internal_force(&x0, &id).norm();
    assert!(f0 < 1e-13 * 2.0e4, "{f0}");
    let (a, xa) = arc::<3>(0.7);
    let id3 = [Matrix3::identity(); 3];
    assert!(a.energy(&xa, &id3).abs() < 1e-20);
    let g0 = a.energy_gradient::<18>(&xa, &id3).norm();
    assert!(g0 < 1e-13 * 2.0e4, "{g0}");
    // The records' energy (invariant coordinates) is exactly zero there,
    // straight or curved: energy drifts are measured from it.
    assert_eq!(e.energy_linear(&x0, &id), 0.0);
    let (c2, xc) = arc::<2>(0.9);
    assert_eq!(c2.energy_linear(&xc, &id), 0.0);
    // The arc's initial curvature is 1/R about the section's third axis.
    let (a2, _) = arc::<2>(0.4);
    let k0 = a2.initial_strains()[0].1;
    assert!((k0 - Vector3::new(0.0, 0.0, 0.5)).norm() < 1e-14, "{k0}");
}

#[test]
fn linear_stiffness_of_the_two_node_element() {
    // At the undeformed state the tangent is the linear Timoshenko stiffness:
    // axial EA/L and torsional GJ/L along the element axis.
    let (e, x0) = straight2();
    let (_, k) = e.residual_tangent(&x0, &[Matrix3::identity(); 2]);
    let t1 = e.lambda0[0].column(0).into_owned();
    let axial = t1.dot(&(k.fixed_view::<3, 3>(6, 6) * t1));
    let torsion = t1.dot(&(k.fixed_view::<3, 3>(9, 9) * t1));
    assert!((axial - 2.0e4 / 1.3).abs() < 1e-9 * axial);
    assert!((torsion - 30.0 / 1.3).abs() < 1e-9 * torsion);
}

#[test]
fn pure_bending_energy_is_exact() {
    // Rotating the end node by φ about the section's axis 3, with the chord
    // kept along the mid-triad, stores ½·EI₃·φ²/L exactly.
    let (e, x0) = straight2();
    let t3 = e.lambda0[0].column(2).into_owned();
    let phi = 0.9;
    let rot = [Matrix3::identity(), exp(&(t3 * phi))];
    let mid = exp(&(t3 * (0.5 * phi)));
    let x = [x0[0], x0[0] + mid * (x0[1] - x0[0])];
    let expected = 0.5 * 60.0 * phi * phi / 1.3;
    assert!((e.energy(&x, &rot) - expected).abs() < 1e-12 * expected);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn rigid_motion_gives_zero_strain_and_force(
        du in prop::collection::vec(vec3(), 3), dr in prop::collection::vec(vec3(), 3),
        q in vec3(), c in vec3(), big in 0.0..3.0f64,
    ) {
        // Any rotation (up to |q|·3 ≈ 5 rad, wrapped) and translation of the initial state.
        let qm = exp(&(q * big));
        let (e, x0) = straight2();
        let x: [Vector3<f64>; 2] = std::array::from_fn(|i| qm * x0[i] + c * 10.0);
        let rot = [qm; 2];
        let s = e.strains(&x, &rot)[0];
        prop_assert!(s.0.norm() < 1e-13 && s.1.norm() < 1e-13);
        prop_assert!(e.internal_force(&x, &rot).norm() < 1e-8);
        let (a, xa) = arc::<3>(0.9);
        let xr: [Vector3<f64>; 3] = std::array::from_fn(|i| qm * xa[i] + c);
        for s in &a.strains(&xr, &[qm; 3])[..2] {
            prop_assert!(s.0.norm() < 1e-13 && s.1.norm() < 1e-13);
        }
        prop_assert!(a.energy_gradient::<18>(&xr, &[qm; 3]).norm() < 1e-8);
        // Objectivity of a deformed state: energy invariant, forces rotate.
        let (xd, rd) = deformed(&x0, &du, &dr, 0.2, 0.5);
        let xq: [Vector3<f64>; 2] = std::array::from_fn(|i| qm * xd[i] + c);
        let rq: [Matrix3<f64>; 2] = std::array::from_fn(|i| qm * rd[i]);
        let e0 = e.energy(&xd, &rd);
        prop_assert!((e.energy(&xq, &rq) - e0).abs() <= 1e-11 * e0.abs().max(1.0));
        let f0 = e.internal_force(&xd, &rd);
        let fq = e.internal_force(&xq, &rq);
        for b in 0..4 {
            let rotated = qm * f0.fixed_rows::<3>(3 * b);
            // Moments about the nodes rotate; forces rotate.
            prop_assert!((fq.fixed_rows::<3>(3 * b) - rotated).norm() <= 1e-9 * f0.norm().max(1.0));
        }
    }

    #[test]
    fn closed_form_residual_is_the_energy_gradient(
        du in prop::collection::vec(vec3(), 2), dr in prop::collection::vec(vec3(), 2),
        su in 0.0..0.5f64, sr in 0.0..1.2f64, curved in any::<bool>(),
    ) {
        let (e, x0) = if curved { arc::<2>(0.8) } else { straight2() };
        let (x, rot) = deformed(&x0, &du, &dr, su, sr);
        let closed = e.internal_force(&x, &rot);
        let ad = e.energy_gradient::<12>(&x, &rot);
        prop_assert!(rel((closed - ad).norm(), ad.norm()) <= 1e-8,
            "closed {closed} ad {ad}");
    }

    #[test]
    fn the_records_energy_is_the_interpolations(
        du in prop::collection::vec(vec3(), 2), dr in prop::collection::vec(vec3(), 2),
        su in 0.0..0.5f64, sr in 0.0..1.2f64, curved in any::<bool>(),
    ) {
        // One logarithm and one exponential (the mid triad's rotation
        // vectors to the nodes are ∓½φ) against the general interpolation's
        // three and two: the same energy to round-off of its terms.
        let (e, x0) = if curved { arc::<2>(0.8) } else { straight2() };
        let (x, rot) = deformed(&x0, &du, &dr, su, sr);
        let (general, linear) = (e.energy(&x, &rot), e.energy_linear(&x, &rot));
        let scale = e.section.c_n.norm() * e.length;
        prop_assert!((general - linear).abs() <= 1e-13 * scale.max(general),
            "general {general} linear {linear}");
    }

    #[test]
    fn tangent_is_the_derivative_of_the_residual(
        du in prop::collection::vec(vec3(), 2), dr in prop::collection::vec(vec3(), 2),
        su in 0.0..0.5f64, sr in 0.0..1.2f64, curved in any::<bool>(),
    ) {
        let (e, x0) = if curved { arc::<2>(0.8) } else { straight2() };
        let (x, rot) = deformed(&x0, &du, &dr, su, sr);
        let (r, k) = e.residual_tangent(&x, &rot);
        // Independent path: mixed second derivative of the energy (hyper-duals).
        let (r2, k2) = e.residual_tangent_ad::<12>(&x, &rot);
        prop_assert!(rel((r - r2).norm(), r2.norm()) <= 1e-8);
        prop_assert!(rel((k - k2).norm(), k2.norm()) <= 1e-8, "k {k} k2 {k2}");
        // And central finite differences of the residual under the same increments.
        let h = 1e-6;
        for j in 0..12 {
            let mut xp = x; let mut xm = x; let mut rp = rot; let mut rm = rot;
            let node = j / 6; let c = j % 6;
            let mut unit = Vector3::zeros(); unit[c % 3] = 1.0;
            if c < 3 { xp[node] += unit * h; xm[node] -= unit * h; }
            else { rp[node] = exp(&(unit * h)) * rot[node]; rm[node] = exp(&(-unit * h)) * rot[node]; }
            let col = (e.internal_force(&xp, &rp) - e.internal_force(&xm, &rm)) / (2.0 * h);
            prop_assert!(rel((col - k.column(j)).norm(), k.norm()) <= 1e-6, "column {j}");
        }
    }

    #[test]
    fn three_node_residual_and_tangent(
        du in prop::collection::vec(vec3(), 3), dr in prop::collection::vec(vec3(), 3),
        su in 0.0..0.4f64, sr in 0.0..1.0f64,
    ) {
        let (e, x0) = arc::<3>(0.9);
        let (x, rot) = deformed(&x0, &du, &dr, su, sr);
        let (r, k) = e.residual_tangent_ad::<18>(&x, &rot);
        // Residual = gradient of the energy (first-order duals, other code path).
        let g = e.energy_gradient::<18>(&x, &rot);
        prop_assert!(rel((r - g).norm(), g.norm()) <= 1e-10);
        // Tangent = derivative of the residual (central differences of the AD gradient).
        let h = 1e-6;
        for j in 0..18 {
            let mut xp = x; let mut xm = x; let mut rp = rot; let mut rm = rot;
            let node = j / 6; let c = j % 6;
            let mut unit = Vector3::zeros(); unit[c % 3] = 1.0;
            if c < 3 { xp[node] += unit * h; xm[node] -= unit * h; }
            else { rp[node] = exp(&(unit * h)) * rot[node]; rm[node] = exp(&(-unit * h)) * rot[node]; }
            let col = (e.energy_gradient::<18>(&xp, &rp) - e.energy_gradient::<18>(&xm, &rm)) / (2.0 * h);
            prop_assert!(rel((col - k.column(j)).norm(), k.norm()) <= 1e-6, "column {j}");
        }
        // The kernel the solvers use (node 0's columns from objectivity)
        // equals the full hyper-dual tangent to round-off, for 2 and 3 nodes.
        let (r3, k3) = e.residual_tangent_invariant::<18, 12>(&x, &rot);
        prop_assert!(rel((r3 - r).norm(), r.norm()) <= 1e-12);
        prop_assert!(rel((k3 - k).norm(), k.norm()) <= 1e-10, "k3 {k3} k {k}");
        let (e2, x02) = arc::<2>(0.9);
        let (x2, rot2) = deformed(&x02, &du[..2], &dr[..2], su, sr);
        let (_, k2) = e2.residual_tangent_ad::<12>(&x2, &rot2);
        let (_, k2i) = e2.residual_tangent_invariant::<12, 6>(&x2, &rot2);
        prop_assert!(rel((k2i - k2).norm(), k2.norm()) <= 1e-10);
    }
}

#[test]
fn residual_is_equilibrated() {
    // Σ f = 0 and Σ (x × f + m) = 0 for any state (no external load on an element).
    let (e, x0) = arc::<2>(0.6);
    let du = [Vector3::new(0.1, -0.2, 0.05), Vector3::new(-0.3, 0.1, 0.2)];
    let dr = [Vector3::new(0.2, 0.5, -0.1), Vector3::new(-0.4, 0.3, 0.6)];
    let (x, rot) = deformed(&x0, &du, &dr, 1.0, 1.0);
    let r = e.internal_force(&x, &rot);
    let f = r.fixed_rows::<3>(0) + r.fixed_rows::<3>(6);
    let m = x[0].cross(&r.fixed_rows::<3>(0).into_owned())
        + r.fixed_rows::<3>(3)
        + x[1].cross(&r.fixed_rows::<3>(6).into_owned())
        + r.fixed_rows::<3>(9);
    assert!(f.norm() < 1e-10 * r.norm() && m.norm() < 1e-10 * r.norm());
}

#[test]
fn the_stretch_rate_is_the_energys_derivative_by_the_initial_length() {
    // ∂Π/∂σ in closed form against central differences of the energy of
    // the same element built σ = 1 ± h times as long (its initial nodes
    // moved along its axis), in a deformed state; 2- and 3-node elements.
    let (e, x0) = straight2();
    let dir = (x0[1] - x0[0]).normalize();
    let l0 = e.lambda0[0];
    let x = [
        x0[0] + Vector3::new(0.01, -0.03, 0.02),
        x0[1] + Vector3::new(-0.05, 0.04, 0.1),
    ];
    let rot = [
        exp(&Vector3::new(0.1, -0.2, 0.05)),
        exp(&Vector3::new(-0.15, 0.1, 0.3)),
    ];
    let h = 1e-5;
    let energy = |s: f64| {
        let x0s = [x0[0], x0[0] + dir * (1.3 * s)];
        BeamElement::new([0, 1], section(), 1.3 * s, &x0s, [l0, l0]).energy(&x, &rot)
    };
    let fd = (energy(1.0 + h) - energy(1.0 - h)) / (2.0 * h);
    let exact: f64 = e.stretch_rate(&x, &rot);
    assert!((exact - fd).abs() <= 1e-8 * fd.abs(), "{exact} vs {fd}");
    let x3 = [x0[0], (x0[0] + x0[1]) * 0.5, x0[1]];
    let e3 = BeamElement::new([0, 1, 2], section(), 1.3, &x3, [l0, l0, l0]);
    let xd = [
        x3[0] + Vector3::new(0.01, 0.0, -0.02),
        x3[1] + Vector3::new(0.0, 0.05, 0.01),
        x3[2],
    ];
    let rd = [rot[0], exp(&Vector3::new(0.05, 0.05, 0.0)), rot[1]];
    let energy3 = |s: f64| {
        let xs = [x3[0], x3[0] + dir * (0.65 * s), x3[0] + dir * (1.3 * s)];
        BeamElement::new([0, 1, 2], section(), 1.3 * s, &xs, [l0, l0, l0]).energy(&xd, &rd)
    };
    let fd = (energy3(1.0 + h) - energy3(1.0 - h)) / (2.0 * h);
    let exact: f64 = e3.stretch_rate(&xd, &rd);
    assert!((exact - fd).abs() <= 1e-8 * fd.abs(), "{exact} vs {fd}");
}
