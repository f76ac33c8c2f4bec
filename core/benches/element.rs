//! Element kernel speed: residual + tangent of one element in a deformed state.
//! `cargo bench -p flexmech-core --bench element`

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
    c.bench_function("2-node residual+tangent (closed form + AD Jacobian)", |b| {
        b.iter(|| black_box(e2.residual_tangent(black_box(&x), black_box(&rot))))
    });
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
    c.bench_function("3-node residual+tangent (hyper-dual energy)", |b| {
        b.iter(|| black_box(e3.residual_tangent_ad::<18>(black_box(&xd), black_box(&rot3))))
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
