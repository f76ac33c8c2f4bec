//! Static solver checks on analytic solutions: the cantilever rolled into a
//! full circle by an end moment, Newton's quadratic convergence, determinism
//! of parallel assembly, and typed failures.

use flexmech_core::{Configuration, Mesh, Section};
use flexmech_integrators::assembly::Assembler;
use flexmech_integrators::dofs::DofMap;
use flexmech_integrators::linsolve::SparseLu;
use flexmech_integrators::{
    solve_static, Mechanism, NewtonSettings, NodalLoad, Schedule, SolveError, StaticSettings,
    StepRecord,
};
use nalgebra::Vector3;

const L: f64 = 10.0;
const EI: f64 = 100.0;

fn cantilever(elements: usize, npe: usize, moment: f64) -> Mechanism {
    let sec = Section::new([1.0e5, 5.0e4, 5.0e4], [80.0, EI, EI], 0.0, [0.0; 3]);
    let mut mesh = Mesh::default();
    let nodes = mesh
        .add_straight_beam(
            Vector3::zeros(),
            Vector3::new(L, 0.0, 0.0),
            Vector3::y(),
            elements,
            npe,
            sec,
        )
        .unwrap();
    let mut mech = Mechanism::new(mesh);
    mech.fixed[nodes[0]] = [true; 6];
    mech.loads.push(NodalLoad {
        node: *nodes.last().unwrap(),
        force: Vector3::zeros(),
        moment: Vector3::new(0.0, 0.0, moment),
        scale: Schedule::ramp(),
    });
    mech
}

fn settings(steps: usize) -> StaticSettings {
    StaticSettings {
        load_steps: steps,
        newton: NewtonSettings {
            tolerance: 1e-10,
            max_iterations: 25,
            modified: false,
            exact_tangent: false,
        },
        max_halvings: 10,
    }
}

fn run(mech: &Mechanism, s: &StaticSettings) -> (Vec<StepRecord>, Result<(), SolveError>) {
    let mut steps = Vec::new();
    let res = solve_static(mech, s, |r| steps.push(r.clone())).map(|_| ());
    (steps, res)
}

#[test]
fn end_moment_rolls_the_cantilever_into_a_circle() {
    // M = 2πEI/L bends the beam to constant curvature 2π/L: the tip returns to
    // the clamp, for any number of elements of this family.
    for (elements, npe) in [(10, 2), (16, 2), (5, 3)] {
        let mech = cantilever(elements, npe, 2.0 * std::f64::consts::PI * EI / L);
        let (steps, res) = run(&mech, &settings(10));
        res.unwrap();
        let last = steps.last().unwrap();
        let tip = Vector3::from(*last.positions.last().unwrap());
        assert!(tip.norm() <= 1e-8 * L, "{elements}x{npe}: tip at {tip}");
        // Half-way (λ = 0.5) the beam is a half circle: tip at (0, L/π, 0)
        // up to the chord/arc difference of the discretisation.
        let half = &steps[4];
        assert!((half.time - 0.5).abs() < 1e-12);
        // Strain energy of the full roll: ½ EI (2π/L)² L.
        let exact = 0.5 * EI * (2.0 * std::f64::consts::PI / L).powi(2) * L;
        assert!(
            (last.energy.strain - exact).abs() < 1e-8 * exact,
            "energy {}",
            last.energy.strain
        );
        // Tip rotation is a full turn: quaternion back to ±identity.
        let q = last.quaternions.last().unwrap();
        assert!((q[0].abs() - 1.0).abs() < 1e-10, "{q:?}");
    }
}

/// One Newton step from the converged configuration perturbed by `eps`;
/// returns the reduced residual norm after the step.
fn residual_after_one_step(mech: &Mechanism, converged: &Configuration, eps: f64) -> f64 {
    let dofs = DofMap::independent(&mech.fixed);
    let mut asm = Assembler::new(&mech.mesh, &dofs, &[]);
    let mut lu = SparseLu::new(asm.pattern().clone()).unwrap();
    let mut fext = vec![0.0; 6 * mech.mesh.node_count()];
    mech.external_forces(1.0, &mut fext);
    let mut c = converged.clone();
    for n in 1..c.x.len() {
        let k = n as f64;
        c.increment(
            n,
            &(Vector3::new(1.0, -2.0, 0.5 * k) * eps),
            &(Vector3::new(2.0, k, -1.0) * eps),
        );
    }
    let residual = |asm: &mut Assembler, c: &Configuration| {
        asm.assemble(&mech.mesh, &dofs, c);
        let g: Vec<f64> = asm.nodal.iter().zip(&fext).map(|(a, b)| a - b).collect();
        let mut r = vec![0.0; dofs.n_eq];
        dofs.reduce(&g, &mut r);
        r
    };
    let r = residual(&mut asm, &c);
    lu.factor(&asm.values).unwrap();
    let mut dq: Vec<f64> = r.iter().map(|v| -v).collect();
    lu.solve(&mut dq).unwrap();
    for n in 0..c.x.len() {
        let p = dofs.node_increment(n, &dq);
        c.increment(
            n,
            &p.fixed_rows::<3>(0).into_owned(),
            &p.fixed_rows::<3>(3).into_owned(),
        );
    }
    residual(&mut asm, &c)
        .iter()
        .map(|v| v * v)
        .sum::<f64>()
        .sqrt()
}

#[test]
fn newton_converges_quadratically() {
    // From the converged roll-up perturbed by ε, one Newton step leaves a
    // residual O(ε²): dividing ε by 10 must divide it by about 100 (a linearly
    // convergent method would give 10). This is the exact-tangent property the
    // residual histories rely on, measured without the pre-asymptotic phase
    // (slender beams have a large nonlinearity constant GA·L²/EI).
    let mech = cantilever(10, 2, 2.0 * std::f64::consts::PI * EI / L);
    let converged = solve_static(&mech, &settings(10), |_| {}).unwrap().config;
    let r: Vec<f64> = [1e-4, 1e-5, 1e-6]
        .iter()
        .map(|&e| residual_after_one_step(&mech, &converged, e))
        .collect();
    for w in r.windows(2) {
        let ratio = w[0] / w[1];
        assert!(
            (60.0..170.0).contains(&ratio),
            "residuals after one step {r:?}: ratio {ratio}"
        );
    }
    // And every converged step of the run ends below the tolerance.
    let (steps, res) = run(&mech, &settings(10));
    res.unwrap();
    assert!(steps
        .iter()
        .all(|s| s.residual <= 1e-10 && *s.residual_history.last().unwrap() == s.residual));
}

#[test]
fn assembly_is_bitwise_deterministic_across_thread_counts() {
    // Enough elements for the parallel assembly (threads::PARALLEL_MIN_ELEMENTS).
    let elements = flexmech_integrators::threads::PARALLEL_MIN_ELEMENTS;
    let mech = cantilever(elements, 3, 1.3 * std::f64::consts::PI * EI / L);
    let solve_with = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        // Split whatever the kernels cost (a cheap 2-node loop is otherwise
        // kept on one thread).
        pool.install(|| flexmech_integrators::threads::always_split(|| run(&mech, &settings(3)).0))
    };
    let one = solve_with(1);
    let two = solve_with(2);
    assert_eq!(one.len(), two.len());
    for (a, b) in one.iter().zip(&two) {
        for (p, q) in a.positions.iter().zip(&b.positions) {
            assert_eq!(p.map(f64::to_bits), q.map(f64::to_bits));
        }
        assert_eq!(a.residual_history, b.residual_history);
    }
}

#[test]
fn unsupported_beam_is_a_typed_error() {
    let mut mech = cantilever(4, 2, 1.0);
    mech.fixed[0] = [false; 6];
    let (_, res) = run(&mech, &settings(2));
    assert!(
        matches!(res, Err(SolveError::Unrestrained { .. })),
        "{res:?}"
    );
}

#[test]
fn step_halving_rescues_a_large_step_and_failure_keeps_steps() {
    // One load step of 2.5 turns is too far for Newton from the straight beam;
    // halving brings it home.
    let mech = cantilever(20, 2, 2.5 * 2.0 * std::f64::consts::PI * EI / L);
    let (steps, res) = run(&mech, &settings(1));
    res.unwrap();
    assert!(
        steps.len() > 1,
        "expected halvings, got {} step",
        steps.len()
    );
    assert!((steps.last().unwrap().time - 1.0).abs() < 1e-12);
    // With no halvings allowed and one iteration, the first step fails and says so.
    let mut s = settings(1);
    s.max_halvings = 0;
    s.newton.max_iterations = 1;
    let (steps, res) = run(&mech, &s);
    assert!(steps.is_empty());
    match res {
        Err(SolveError::NoConvergence { time, .. }) => assert_eq!(time, 1.0),
        other => panic!("expected NoConvergence, got {other:?}"),
    }
}
