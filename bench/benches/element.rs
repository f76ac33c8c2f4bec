//! Element kernel speed: residual + tangent of one element in a deformed state
//! (and of the conserving schemes' forces over a step), the solvers' kernels
//! next to the AD formulations they replaced (which stay the test oracles).
//! `cargo bench -p flexmech-benches --bench element`

use criterion::{criterion_group, criterion_main, Criterion};
use flexmech_core::rotation::exp;
use flexmech_core::{BeamElement, Section};
use nalgebra::{Matrix3, Vector3};
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let sec = Section::new(
        [1.0e7, 5.0e6, 5.0e6],
        [7.05e5, 8.3e5, 8.3e5],
        1.0,
        [0.2, 0.1, 0.1],
    );
    let x0 = [Vector3::zeros(), Vector3::new(1.0, 0.0, 0.0)];
    let e2 = BeamElement::new([0, 1], sec, 1.0, &x0, [Matrix3::identity(); 2]);
    let x = [Vector3::new(0.01, 0.02, 0.0), Vector3::new(0.9, 0.3, 0.1)];
    let rot = [
        exp(&Vector3::new(0.1, 0.2, 0.3)),
        exp(&Vector3::new(-0.2, 0.5, 0.9)),
    ];
    c.bench_function(
        "2-node residual+tangent (invariant coordinates, the solvers')",
        |b| b.iter(|| black_box(e2.residual_tangent_linear(black_box(&x), black_box(&rot)))),
    );
    c.bench_function(
        "2-node residual+tangent (closed form + 6-lane AD, objectivity)",
        |b| b.iter(|| black_box(e2.residual_tangent(black_box(&x), black_box(&rot)))),
    );
    c.bench_function("2-node residual+tangent (hyper-dual energy)", |b| {
        b.iter(|| black_box(e2.residual_tangent_ad::<12>(black_box(&x), black_box(&rot))))
    });
    c.bench_function("2-node residual only (closed form)", |b| {
        b.iter(|| black_box(e2.internal_force(black_box(&x), black_box(&rot))))
    });
    let x3 = [
        Vector3::zeros(),
        Vector3::new(0.5, 0.0, 0.0),
        Vector3::new(1.0, 0.0, 0.0),
    ];
    let e3 = BeamElement::new([0, 1, 2], sec, 1.0, &x3, [Matrix3::identity(); 3]);
    let xd = [
        Vector3::new(0.01, 0.02, 0.0),
        Vector3::new(0.45, 0.1, 0.05),
        Vector3::new(0.9, 0.3, 0.1),
    ];
    let rot3 = [rot[0], exp(&Vector3::new(0.0, 0.3, 0.5)), rot[1]];
    c.bench_function(
        "3-node residual+tangent (invariant coordinates, the solvers')",
        |b| b.iter(|| black_box(e3.residual_tangent_quadratic(black_box(&xd), black_box(&rot3)))),
    );
    c.bench_function("3-node residual+tangent (hyper-dual, objectivity)", |b| {
        b.iter(|| {
            black_box(e3.residual_tangent_invariant::<18, 12>(black_box(&xd), black_box(&rot3)))
        })
    });
    c.bench_function("3-node residual+tangent (hyper-dual energy)", |b| {
        b.iter(|| black_box(e3.residual_tangent_ad::<18>(black_box(&xd), black_box(&rot3))))
    });
    // The conserving schemes' element forces and tangents over a step.
    let start = (x, rot);
    let end = (
        [
            x[0] + Vector3::new(0.01, -0.02, 0.005),
            x[1] + Vector3::new(-0.01, 0.02, 0.01),
        ],
        [
            exp(&Vector3::new(0.02, -0.01, 0.03)) * rot[0],
            exp(&Vector3::new(-0.03, 0.01, 0.02)) * rot[1],
        ],
    );
    c.bench_function(
        "momentum step: force+tangent (closed form, the solvers')",
        |b| b.iter(|| black_box(e2.momentum_force_tangent(black_box(&start), black_box(&end)))),
    );
    c.bench_function("momentum step: force+tangent (12-lane AD)", |b| {
        b.iter(|| black_box(ad12(&e2, &start, &end, false)))
    });
    c.bench_function(
        "energy-momentum step: force+tangent (6-lane AD + closed form, the solvers')",
        |b| {
            b.iter(|| {
                black_box(e2.energy_momentum_force_tangent(black_box(&start), black_box(&end)))
            })
        },
    );
    c.bench_function("energy-momentum step: force only (the residual's)", |b| {
        b.iter(|| black_box(e2.energy_momentum_force_parts(black_box(&start), black_box(&end))))
    });
    let from = e2.step_start(&start);
    c.bench_function(
        "energy-momentum step: force only, from the step's start",
        |b| {
            b.iter(|| {
                black_box(e2.energy_momentum_force_parts_from(black_box(&from), black_box(&end)))
            })
        },
    );
    c.bench_function(
        "energy-momentum step: force+cheap tangent, from the step's start",
        |b| {
            b.iter(|| {
                black_box(
                    e2.energy_momentum_force_cheap_tangent_from(black_box(&from), black_box(&end)),
                )
            })
        },
    );
    c.bench_function("energy-momentum step: force+tangent (12-lane AD)", |b| {
        b.iter(|| black_box(ad12(&e2, &start, &end, true)))
    });
}

type Pose = ([Vector3<f64>; 2], [Matrix3<f64>; 2]);

/// The conserving force's Jacobian by forward AD over all twelve end
/// increments (the reference the solvers' kernels are measured against).
fn ad12(e: &BeamElement<2>, start: &Pose, end: &Pose, energy: bool) -> f64 {
    use flexmech_core::conserving::MidRotation;
    use num_dual::DualSVec64;
    type D = DualSVec64<12>;
    let seed = |k: usize| D::from_re(0.0).derivative(k);
    let v = |k: usize| Vector3::new(seed(k), seed(k + 1), seed(k + 2));
    let sd = (
        start.0.map(|x| x.map(D::from_re)),
        start.1.map(|r| r.map(D::from_re)),
    );
    let ed = (
        [
            end.0[0].map(D::from_re) + v(0),
            end.0[1].map(D::from_re) + v(6),
        ],
        [
            exp(&v(3)) * end.1[0].map(D::from_re),
            exp(&v(9)) * end.1[1].map(D::from_re),
        ],
    );
    let (n0, m0) = e.resultants(&start.0, &start.1);
    let (n1, m1) = e.resultants(&ed.0, &ed.1);
    let half = D::from_re(0.5);
    let nbar = (n0.map(D::from_re) + n1) * half;
    let mbar = (m0.map(D::from_re) + m1) * half;
    let q = if energy {
        e.discrete_gradient_force(&sd, &ed, &nbar, &mbar)
    } else {
        e.midpoint_force(&sd, &ed, &nbar, &mbar, MidRotation::Geodesic)
    };
    q[0].re
}

criterion_group!(benches, bench);
criterion_main!(benches);
