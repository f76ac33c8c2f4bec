//! The conserving schemes' joint maps: a joint's incremental map `Ñ` over a
//! step (paper eqs 21–23), unseeded and seeded along the step's end state
//! (one Newton evaluation's rows, residual and tangent), and the seeded
//! transfer `Ñᵀ g` with its derivative.
//! `cargo bench -p flexmech-benches --bench joint_step`

use criterion::{criterion_group, criterion_main, Criterion};
use flexmech_core::rotation::exp;
use flexmech_joints::{
    JointKinematics, JointMap, JointStep, Prismatic, ReleasedState, Revolute, StepLanes,
};
use nalgebra::{Vector3, Vector6};
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let (x0, x1) = (Vector3::new(0.1, 0.2, 0.0), Vector3::new(0.11, 0.19, 0.01));
    let (r0, r1) = (
        exp(&Vector3::new(0.1, 0.2, 0.3)),
        exp(&Vector3::new(0.12, 0.19, 0.33)),
    );
    let master = [(&x0, &r0), (&x1, &r1)];
    let (s0, mut s1) = (
        ReleasedState::new([0.3, 0.0, 0.0, 0.0]),
        ReleasedState::new([0.3, 0.0, 0.0, 0.0]),
    );
    s1.q[0] = 0.35;
    let released = [&s0, &s1];
    let g = Vector6::new(1.0, -2.0, 0.5, 0.3, 0.2, -0.1);
    let revolute = Revolute { axis: Vector3::z() };
    let prismatic = Prismatic {
        slide: Vector3::x(),
    };
    c.bench_function("revolute Ñ", |b| {
        b.iter(|| black_box(revolute.incremental_step(black_box(master), released)))
    });
    c.bench_function("revolute Ñ seeded", |b| {
        b.iter(|| black_box(revolute.incremental_step_seeded(black_box(master), released)))
    });
    let seeded = revolute.incremental_step_seeded(master, released);
    c.bench_function("revolute seeded Ñᵀg and derivative", |b| {
        b.iter(|| black_box(black_box(&seeded).seeded_transfer(black_box(&g), 1)))
    });
    type D4 = num_dual::DualSVec64<4>;
    let e: [D4; 4] = std::array::from_fn(|i| D4::from_re(0.0).derivative(i));
    let z = D4::from_re(0.0);
    let seed = [z, z, z, e[0], e[1], e[2]];
    let inc = [e[3], z, z, z];
    c.bench_function("revolute Ñ in 4 lanes (no widening)", |b| {
        b.iter(|| {
            black_box(JointStep::of(
                &revolute,
                black_box(master),
                released,
                &seed,
                &inc,
            ))
        })
    });
    c.bench_function("revolute B in 4 lanes", |b| {
        b.iter(|| {
            black_box(JointKinematics::step_map(
                &revolute,
                black_box(&s0),
                &s1,
                &inc,
            ))
        })
    });
    let inc1 = [num_dual::DualSVec64::<1>::from_re(0.0).derivative(0); 4];
    c.bench_function("revolute B in 1 lane", |b| {
        b.iter(|| {
            black_box(JointKinematics::step_map(
                &revolute,
                black_box(&s0),
                &s1,
                &inc1,
            ))
        })
    });
    c.bench_function(
        "revolute Ñ along its lanes (spin closed form, angle AD)",
        |b| {
            b.iter(|| {
                black_box(revolute.incremental_step_lanes(
                    black_box(master),
                    released,
                    StepLanes::all(1),
                ))
            })
        },
    );
    c.bench_function("revolute Ñ along the angle alone (ground master)", |b| {
        let lanes = StepLanes {
            spin: false,
            released: 1,
        };
        b.iter(|| black_box(revolute.incremental_step_lanes(black_box(master), released, lanes)))
    });
    let lanes = revolute.incremental_step_lanes(master, released, StepLanes::all(1));
    c.bench_function("revolute Ñᵀg and derivative along its lanes", |b| {
        b.iter(|| black_box(black_box(&lanes).transfer(black_box(&g), 1)))
    });
    c.bench_function("prismatic Ñ seeded", |b| {
        b.iter(|| black_box(prismatic.incremental_step_seeded(black_box(master), released)))
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
