//! Joints in the static solver: the reduced system's tangent is exact (Newton
//! converges quadratically, which needs the derivative of N), constraints hold
//! to round-off along driven paths, chains work and cycles are refused — and a
//! joint written outside the crates takes one small impl.

use flexmech_core::{Mesh, Scalar, Section};
use flexmech_integrators::assembly::Assembler;
use flexmech_integrators::constraints::{initial_state, joint_records, MechanismState, Topology};
use flexmech_integrators::linsolve::SparseLu;
use flexmech_integrators::{
    solve_static, JointInstance, Mechanism, NewtonSettings, NodalLoad, Schedule, SolveError,
    StaticSettings,
};
use flexmech_joints::{
    DependentJoint, JointMap, RackPinion, ReleasedState, Revolute, Screw, MAX_RELEASED,
};
use nalgebra::Vector3;
use std::sync::Arc;

/// The variable-pitch screw `f(ψ) = (cψ + d sin ψ) t`: a joint kind written
/// here, outside the library, in one small impl. Its `N`, tangent terms,
/// secant `G` and `Ñ` all follow from `translation`.
#[derive(Debug)]
struct VariablePitchScrew {
    c: f64,
    d: f64,
    axis: Vector3<f64>,
}

impl DependentJoint for VariablePitchScrew {
    fn axis(&self) -> Vector3<f64> {
        self.axis
    }
    fn translation<T: Scalar>(&self, psi: T) -> Vector3<T> {
        let s = psi * T::from_subset(&self.c) + psi.sin() * T::from_subset(&self.d);
        self.axis.map(|a| T::from_subset(&a)) * s
    }
}

fn rod() -> Section {
    Section::new(
        [1.0e6, 4.0e5, 4.0e5],
        [800.0, 1000.0, 1000.0],
        0.0,
        [0.0; 3],
    )
}

/// A soft rod: loads of order 10 on moment arms of order 0.5 then give load
/// stiffness comparable to the elastic one, so the derivative of N matters.
fn soft() -> Section {
    Section::new([1.0e4, 4.0e3, 4.0e3], [8.0, 10.0, 10.0], 0.0, [0.0; 3])
}

/// Two straight 4-element beams `a0 → a1` and `b0 → b1`; their node numbers.
fn two_beams(
    ends: [[f64; 3]; 4],
    e2: [Vector3<f64>; 2],
    sec: Section,
) -> (Mesh, Vec<usize>, Vec<usize>) {
    let mut mesh = Mesh::default();
    let v = Vector3::from;
    let a = mesh
        .add_straight_beam(v(ends[0]), v(ends[1]), e2[0], 4, 2, sec)
        .unwrap();
    let b = mesh
        .add_straight_beam(v(ends[2]), v(ends[3]), e2[1], 4, 2, sec)
        .unwrap();
    (mesh, a, b)
}

/// A clamped post with an arm on its top joined by `map`; arm tip loaded.
fn post_and_arm(map: Arc<dyn JointMap>, driven: Option<Schedule>) -> Mechanism {
    let (mesh, post, arm) = two_beams(
        [
            [0.0, 0.0, 0.0],
            [0.0, 0.0, 2.0],
            [0.0, 0.0, 2.0],
            [1.0, 0.0, 2.0],
        ],
        [Vector3::x(), Vector3::y()],
        rod(),
    );
    let mut mech = Mechanism::new(mesh);
    mech.fixed[post[0]] = [true; 6];
    mech.loads.push(NodalLoad {
        node: *arm.last().unwrap(),
        force: Vector3::new(0.0, 0.0, -10.0),
        moment: Vector3::zeros(),
        scale: Schedule::ramp(),
    });
    let mut driven_list = vec![None; map.released_count()];
    driven_list[0] = driven;
    mech.joints.push(JointInstance {
        name: "drive".into(),
        master: *post.last().unwrap(),
        slave: arm[0],
        map,
        initial: ReleasedState::new([0.0; MAX_RELEASED]),
        driven: driven_list,
    });
    mech
}

fn settings(steps: usize) -> StaticSettings {
    StaticSettings {
        load_steps: steps,
        newton: NewtonSettings {
            tolerance: 1e-10,
            max_iterations: 30,
            modified: false,
            exact_tangent: false,
        },
        max_halvings: 8,
    }
}

/// Residual norm after one Newton step from `converged` perturbed by ε in every unknown.
fn one_step_residual(mech: &Mechanism, converged: &MechanismState, eps: f64) -> f64 {
    let mut state = converged.clone();
    let mut topo = Topology::new(mech, &state).unwrap();
    let n = topo.dofs.n_eq;
    let pert: Vec<f64> = (0..n)
        .map(|i| eps * (1.0 + 0.37 * i as f64).sin())
        .collect();
    topo.apply(mech, &mut state, &pert);
    let mut asm = Assembler::new(&mech.mesh, &topo.dofs, &topo.local_eqs);
    let mut lu = SparseLu::new(asm.pattern().clone()).unwrap();
    let mut fext = vec![0.0; 6 * mech.mesh.node_count()];
    mech.external_forces(1.0, &mut fext);
    let residual = |topo: &mut Topology, asm: &mut Assembler, state: &MechanismState| {
        topo.refresh(mech, state);
        asm.assemble(&mech.mesh, &topo.dofs, &state.config);
        let g: Vec<f64> = asm.nodal.iter().zip(&fext).map(|(a, b)| a - b).collect();
        let mut r = vec![0.0; n];
        topo.dofs.reduce(&g, &mut r);
        for (b, block) in topo.geometric_blocks(mech, state, &g).iter().enumerate() {
            asm.add_block(b, block);
        }
        r
    };
    let r = residual(&mut topo, &mut asm, &state);
    lu.factor(&asm.values).unwrap();
    let mut dq: Vec<f64> = r.iter().map(|v| -v).collect();
    lu.solve(&mut dq).unwrap();
    topo.apply(mech, &mut state, &dq);
    residual(&mut topo, &mut asm, &state)
        .iter()
        .map(|v| v * v)
        .sum::<f64>()
        .sqrt()
}

/// Two beams along x, clamped at their far ends, joined in the middle by
/// `map` (axis x); loads near the joint. The released angle is then fixed by
/// the elasticity of both beams — no zero-stiffness mode (unlike a free
/// pendulum, whose unstressed tangent is singular in statics).
fn clamped_pair(map: Arc<dyn JointMap>) -> Mechanism {
    let (mesh, a, b) = two_beams(
        [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
        ],
        [Vector3::y(), Vector3::y()],
        soft(),
    );
    let mut mech = Mechanism::new(mesh);
    mech.fixed[a[0]] = [true; 6];
    mech.fixed[*b.last().unwrap()] = [true; 6];
    mech.loads.push(NodalLoad {
        node: b[1],
        force: Vector3::new(20.0, 3.0, -10.0),
        moment: Vector3::new(4.0, 0.0, 0.0),
        scale: Schedule::ramp(),
    });
    mech.joints.push(JointInstance {
        name: "coupling".into(),
        master: *a.last().unwrap(),
        slave: b[0],
        map,
        initial: ReleasedState::new([0.0; MAX_RELEASED]),
        driven: vec![None],
    });
    mech
}

#[test]
fn newton_is_quadratic_with_dependent_joints() {
    // (a) A free variable-pitch screw coupling two clamped beams: the released
    // angle is an unknown, set by torsion against the screw's axial coupling
    // (f′ and f″ both enter). (b) A driven screw with a lateral tip load, so
    // the joint transmits torque and bending to the post.
    // In both the derivative of N enters the tangent: without it one Newton
    // step would reduce the residual only in proportion to ε, not ε².
    let free = clamped_pair(Arc::new(VariablePitchScrew {
        c: 0.3,
        d: 0.2,
        axis: Vector3::x(),
    }));
    let mut driven = clamped_pair(Arc::new(RackPinion {
        axis: Vector3::x(),
        slide: Vector3::y(),
        radius: 0.5,
    }));
    driven.joints[0].driven = vec![Some(Schedule::new(|t| 0.8 * t))];
    // The rack-and-pinion's slave starts at b (t_r × t) from the master.
    let slave = driven.joints[0].slave;
    let offset = Vector3::y().cross(&Vector3::x()) * 0.5;
    let (mesh, a, b) = two_beams(
        [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, offset.y, offset.z],
            [2.0, offset.y, offset.z],
        ],
        [Vector3::y(), Vector3::y()],
        soft(),
    );
    assert_eq!((a.len(), b[0]), (5, slave));
    driven.mesh = mesh;
    for mech in [free, driven] {
        let mut last = None;
        let out = solve_static(&mech, &settings(8), |s| last = Some(s.clone())).unwrap();
        // The joint really turned.
        assert!(last.unwrap().joints[0].angle.abs() > 1e-6);
        let r: Vec<f64> = [1e-3, 1e-4, 1e-5]
            .iter()
            .map(|&e| one_step_residual(&mech, &out.state, e))
            .collect();
        for w in r.windows(2) {
            let ratio = w[0] / w[1];
            // ε² gives 100 per decade; a tangent missing the derivative of N
            // (linear convergence) would give 10.
            assert!(ratio >= 60.0, "one-step residuals {r:?}");
        }
    }
}

#[test]
fn constraints_hold_to_round_off_along_driven_turns() {
    // Three turns of the custom variable-pitch screw, quasi-statically.
    let screw = VariablePitchScrew {
        c: 0.05,
        d: 0.03,
        axis: Vector3::z(),
    };
    let turns = 3.0 * 2.0 * std::f64::consts::PI;
    let mech = post_and_arm(Arc::new(screw), Some(Schedule::new(move |t| turns * t)));
    let mut steps = Vec::new();
    solve_static(&mech, &settings(60), |s| steps.push(s.clone())).unwrap();
    assert!(steps.len() >= 60);
    let check = VariablePitchScrew {
        c: 0.05,
        d: 0.03,
        axis: Vector3::z(),
    };
    for s in &steps {
        let j = s.joints[0];
        assert!(
            j.constraint_error <= 1e-13,
            "t = {}: {}",
            s.time,
            j.constraint_error
        );
        assert!((j.angle - turns * s.time).abs() <= 1e-12 * turns);
        let f = check.translation(j.angle);
        let rr = Vector3::from(j.released_translation);
        assert!((rr - f).norm() <= 1e-14, "r_R {rr} vs f(ψ) {f}");
        // Converged: below the tolerance or at the round-off floor of EA = 1e6.
        assert!(
            s.residual <= 1e-8,
            "t = {}: residual {}",
            s.time,
            s.residual
        );
    }
}

#[test]
fn chains_of_joints_and_refused_topologies() {
    // A revolute joint whose master is the slave of a screw: a chain.
    let mut mech = post_and_arm(
        Arc::new(Screw {
            axis: Vector3::z(),
            pitch: 0.05,
        }),
        Some(Schedule::new(|t| 2.0 * t)),
    );
    let hub = mech.mesh.positions.len();
    let arm_end = mech.joints[0].slave + 4;
    let x = mech.mesh.positions[arm_end];
    let extra = mech
        .mesh
        .add_straight_beam(
            x,
            x + Vector3::new(0.5, 0.0, 0.0),
            Vector3::y(),
            2,
            2,
            rod(),
        )
        .unwrap();
    assert_eq!(extra[0], hub);
    mech.fixed.resize(mech.mesh.node_count(), [false; 6]);
    mech.joints.push(JointInstance {
        name: "elbow".into(),
        master: arm_end,
        slave: extra[0],
        map: Arc::new(Revolute { axis: Vector3::y() }),
        initial: ReleasedState::new([0.0; MAX_RELEASED]),
        driven: vec![Some(Schedule::new(|t| 0.5 * t))],
    });
    let mut last = None;
    solve_static(&mech, &settings(10), |s| last = Some(s.clone())).unwrap();
    let last = last.unwrap();
    assert!(last.joints.iter().all(|j| j.constraint_error <= 1e-13));
    assert!((last.joints[1].angle - 0.5).abs() < 1e-12);

    // A cycle: the screw's master made the slave of the elbow's slave.
    let mut cyc = mech.clone();
    cyc.joints[1].slave = cyc.joints[0].master;
    cyc.joints[1].master = cyc.joints[0].slave;
    let state = initial_state(&cyc);
    match Topology::new(&cyc, &state) {
        Err(SolveError::InvalidMechanism(m)) => assert!(m.contains("cycle"), "{m}"),
        other => panic!("expected a cycle error, got {other:?}"),
    }
    // Two joints with the same slave.
    let mut double = mech.clone();
    double.joints[1].slave = double.joints[0].slave;
    match Topology::new(&double, &initial_state(&double)) {
        Err(SolveError::InvalidMechanism(m)) => {
            assert!(m.contains("drive") && m.contains("elbow"), "{m}")
        }
        other => panic!("expected a double-slave error, got {other:?}"),
    }
    let records = joint_records(&mech, &initial_state(&mech));
    assert_eq!(records.len(), 2);
}
