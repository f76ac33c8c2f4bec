//! Static solve of a 1000-element cantilever bent through a half turn by an
//! end moment (10 load steps), one assembly of it, and one factorisation and
//! one solve of its tangent by the band LU the solvers choose for it.
//! `cargo bench -p flexmech-benches --bench static_solve`

use criterion::{criterion_group, criterion_main, Criterion};
use flexmech_core::{Configuration, Mesh, Section};
use flexmech_integrators::assembly::Assembler;
use flexmech_integrators::dofs::DofMap;
use flexmech_integrators::linsolve::SparseLu;
use flexmech_integrators::{
    solve_static, Mechanism, NewtonSettings, NodalLoad, Schedule, StaticSettings,
};
use nalgebra::Vector3;
use std::hint::black_box;

fn cantilever(elements: usize) -> Mechanism {
    let sec = Section::new([1.0e5, 5.0e4, 5.0e4], [80.0, 100.0, 100.0], 0.0, [0.0; 3]);
    let mut mesh = Mesh::default();
    let nodes = mesh
        .add_straight_beam(
            Vector3::zeros(),
            Vector3::new(10.0, 0.0, 0.0),
            Vector3::y(),
            elements,
            2,
            sec,
        )
        .expect("valid beam");
    let mut mech = Mechanism::new(mesh);
    mech.fixed[nodes[0]] = [true; 6];
    mech.loads.push(NodalLoad {
        node: *nodes.last().expect("nodes"),
        force: Vector3::zeros(),
        moment: Vector3::new(0.0, 0.0, std::f64::consts::PI * 100.0 / 10.0),
        scale: Schedule::ramp(),
    });
    mech
}

fn bench(c: &mut Criterion) {
    let mech = cantilever(1000);
    let settings = StaticSettings {
        load_steps: 10,
        newton: NewtonSettings {
            tolerance: 1e-10,
            max_iterations: 30,
            modified: false,
            exact_tangent: false,
        },
        max_halvings: 10,
    };
    let mut group = c.benchmark_group("cantilever-1000");
    group.sample_size(10);
    group.bench_function("static solve, half turn, 10 load steps", |b| {
        b.iter(|| black_box(solve_static(&mech, &settings, |_| {}).expect("converges")))
    });
    let dofs = DofMap::independent(&mech.fixed);
    let mut asm = Assembler::new(&mech.mesh, &dofs, &[]);
    let config = Configuration::initial(&mech.mesh.positions);
    group.bench_function("one assembly (residual + tangent)", |b| {
        b.iter(|| asm.assemble(&mech.mesh, &dofs, black_box(&config)))
    });
    let mut lu = SparseLu::new(asm.pattern().clone()).expect("pattern");
    assert!(lu.is_band(), "a chain's tangent takes the band LU");
    // The tangent at the initial configuration (whether or not the
    // assembly bench ran).
    asm.assemble(&mech.mesh, &dofs, &config);
    group.bench_function("band LU factorisation of the tangent", |b| {
        b.iter(|| lu.factor(black_box(&asm.values)).expect("factorises"))
    });
    lu.factor(&asm.values).expect("factorises");
    let rhs: Vec<f64> = (0..asm.pattern().nrows())
        .map(|i| (i as f64).sin())
        .collect();
    group.bench_function("band LU solve", |b| {
        b.iter(|| {
            let mut x = rhs.clone();
            lu.solve(black_box(&mut x)).expect("solves");
            x
        })
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
