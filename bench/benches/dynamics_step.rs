//! Time per step of the energy–momentum scheme on a free flexible beam, and
//! its scaling with the number of elements (250, 500, 1000).
//! `cargo bench -p flexmech-benches --bench dynamics_step`

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use flexmech_core::{MassKind, Mesh, Section};
use flexmech_integrators::dynamics::{energy_momentum, DynamicSettings, Motion};
use flexmech_integrators::{Mechanism, NewtonSettings};
use nalgebra::Vector3;
use std::hint::black_box;

fn free_beam(elements: usize) -> (Mechanism, Motion) {
    let sec = Section::new(
        [1.0e4, 4.0e3, 4.0e3],
        [50.0, 80.0, 80.0],
        1.0,
        [0.2, 0.1, 0.1],
    );
    let mut mesh = Mesh::default();
    mesh.add_straight_beam(
        Vector3::zeros(),
        Vector3::new(10.0, 0.0, 0.0),
        Vector3::y(),
        elements,
        2,
        sec,
    )
    .expect("valid beam");
    let mech = Mechanism::new(mesh);
    let om = Vector3::new(0.3, 0.2, 1.0);
    let motion = Motion {
        v: mech.mesh.positions.iter().map(|x| om.cross(x)).collect(),
        w: vec![om; mech.mesh.node_count()],
        joint_rates: Vec::new(),
    };
    (mech, motion)
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("energy-momentum step");
    group.sample_size(10);
    for elements in [250, 500, 1000] {
        let (mech, motion) = free_beam(elements);
        // Five steps per sample; the figure reported is per five steps.
        let settings = DynamicSettings {
            dt: 0.05,
            t_end: 0.25,
            newton: NewtonSettings {
                tolerance: 1e-10,
                max_iterations: 30,
                modified: false,
                exact_tangent: false,
            },
            max_halvings: 4,
            mass: MassKind::Consistent,
        };
        group.bench_with_input(BenchmarkId::from_parameter(elements), &elements, |b, _| {
            b.iter(|| {
                black_box(
                    energy_momentum::solve(&mech, &settings, &motion, |_| {}).expect("converges"),
                )
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
