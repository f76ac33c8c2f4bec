//! The conserving schemes' joint maps: a joint's incremental map `Ñ` over a
//! step (paper eqs 21–23), and seeded along the step's end state for one
//! Newton evaluation's rows, residual and tangent — along the lanes that
//! reach the unknowns (the solvers'), and along all ten local lanes (the
//! oracle) — with the seeded transfer `Ñᵀ g` and its derivative.
//! `cargo bench -p flexmech-benches --bench joint_step`

use criterion::{criterion_group, criterion_main, Criterion};
use flexmech_core::rotation::exp;
use flexmech_joints::{JointMap, ReleasedState, Revolute, StepLanes};
use nalgebra::{Vector3, Vector6};
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let (x0, x1) = (Vector3::new(0.1, 0.2, 0.0), Vector3::new(0.11, 0.19, 0.01));
    let (r0, r1) = (
        exp(&Vector3::new(0.1, 0.2, 0.3)),
        exp(&Vector3::new(0.12, 0.19, 0.33)),
    );
    let master = [(&x0, &r0), (&x1, &r1)];
    let s0 = ReleasedState::new([0.3, 0.0, 0.0, 0.0]);
    let mut s1 = s0;
    s1.q[0] = 0.35;
    let released = [&s0, &s1];
    let g = Vector6::new(1.0, -2.0, 0.5, 0.3, 0.2, -0.1);
    let revolute = Revolute { axis: Vector3::z() };
    c.bench_function("revolute Ñ", |b| {
        b.iter(|| black_box(revolute.incremental_step(black_box(master), released)))
    });
    c.bench_function("revolute Ñ seeded along its lanes (the solvers')", |b| {
        let lanes = StepLanes::all(1);
        b.iter(|| black_box(revolute.incremental_step_lanes(black_box(master), released, lanes)))
    });
    c.bench_function(
        "revolute Ñ seeded along the angle (a ground master)",
        |b| {
            let lanes = StepLanes {
                spin: false,
                released: 1,
            };
            b.iter(|| {
                black_box(revolute.incremental_step_lanes(black_box(master), released, lanes))
            })
        },
    );
    c.bench_function("revolute Ñ seeded along ten lanes (the oracle)", |b| {
        b.iter(|| black_box(revolute.incremental_step_seeded(black_box(master), released)))
    });
    let lanes = revolute.incremental_step_lanes(master, released, StepLanes::all(1));
    c.bench_function("revolute Ñᵀg and its derivative (the solvers')", |b| {
        b.iter(|| black_box(black_box(&lanes).transfer(black_box(&g), 1)))
    });
    let seeded = revolute.incremental_step_seeded(master, released);
    c.bench_function("revolute Ñᵀg and its derivative (ten lanes)", |b| {
        b.iter(|| black_box(black_box(&seeded).seeded_transfer(black_box(&g), 1)))
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
