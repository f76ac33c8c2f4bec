//! Dynamics of an unsupported flexible beam: the momentum-conserving scheme
//! conserves linear and angular momentum to the Newton tolerance over
//! hundreds of steps (paper §4, FORMULATION §4).

use flexmech_core::{MassKind, Mesh, Section};
use flexmech_integrators::dynamics::{momentum, DynamicSettings, Motion};
use flexmech_integrators::{Mechanism, StepRecord};
use nalgebra::Vector3;

/// A free beam of length 10 with a rigid initial velocity field
/// `v = v₀ + ω × x`, `W = ω` (spin about an axis oblique to the beam, so it
/// wobbles, stretches and bends).
fn spinning_beam(mass: MassKind) -> (Mechanism, Motion, DynamicSettings) {
    spinning_beam_of(mass, 10, 2)
}

/// [`spinning_beam`] meshed with `elements` elements of `nodes` nodes.
fn spinning_beam_of(
    mass: MassKind,
    elements: usize,
    nodes: usize,
) -> (Mechanism, Motion, DynamicSettings) {
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
        nodes,
        sec,
    )
    .unwrap();
    let mech = Mechanism::new(mesh);
    let (v0, om) = (Vector3::new(0.5, -0.2, 0.3), Vector3::new(0.3, 0.2, 1.0));
    let motion = crate::common::rigid_motion(&mech.mesh.positions, v0, om);
    let settings = crate::common::settings(0.05, 15.0, 1e-12, 30, 6, mass);
    (mech, motion, settings)
}

fn rel_drift(series: &[[f64; 3]]) -> f64 {
    let first = nalgebra::Vector3::from(series[0]);
    series
        .iter()
        .map(|h| (Vector3::from(*h) - first).norm() / first.norm())
        .fold(0.0, f64::max)
}

#[test]
fn momentum_scheme_conserves_linear_and_angular_momentum() {
    for mass in [MassKind::Consistent, MassKind::Lumped] {
        let (mech, motion, settings) = spinning_beam(mass);
        let mut steps: Vec<StepRecord> = Vec::new();
        momentum::solve(&mech, &settings, &motion, |s| steps.push(s.clone())).unwrap();
        assert!(steps.len() >= 301, "{} records", steps.len());
        let lin: Vec<_> = steps.iter().map(|s| s.momentum_linear).collect();
        let ang: Vec<_> = steps.iter().map(|s| s.momentum_angular).collect();
        let (dl, dh) = (rel_drift(&lin), rel_drift(&ang));
        assert!(
            dl <= 1e-9 && dh <= 1e-9,
            "{mass:?}: linear drift {dl:e}, angular drift {dh:e}"
        );
        // The beam really deforms: strain energy appears from the spin.
        let strain = steps.iter().map(|s| s.energy.strain).fold(0.0, f64::max);
        assert!(strain > 1e-6, "strain {strain}");
        // Energy is not conserved exactly by this scheme, but stays bounded.
        let e0 = steps[0].energy.total;
        let de = steps
            .iter()
            .map(|s| (s.energy.total - e0).abs() / e0)
            .fold(0.0, f64::max);
        eprintln!(
            "{mass:?}: momentum drift {dl:.2e} / {dh:.2e}, energy drift {de:.2e}, {} steps",
            steps.len() - 1
        );
        assert!(de < 0.1);
    }
}

#[test]
fn energy_momentum_scheme_conserves_energy_and_momenta_with_a_large_step() {
    use flexmech_integrators::dynamics::energy_momentum;
    for mass in [MassKind::Consistent, MassKind::Lumped] {
        let (mech, motion, mut settings) = spinning_beam(mass);
        // A step four times the momentum test's: about a fifth of a turn.
        settings.dt = 0.2;
        settings.t_end = 40.0;
        let mut steps: Vec<StepRecord> = Vec::new();
        energy_momentum::solve(&mech, &settings, &motion, |s| steps.push(s.clone())).unwrap();
        assert!(steps.len() >= 201);
        let e0 = steps[0].energy.total;
        let de = steps
            .iter()
            .map(|s| (s.energy.total - e0).abs() / e0)
            .fold(0.0, f64::max);
        let lin: Vec<_> = steps.iter().map(|s| s.momentum_linear).collect();
        let ang: Vec<_> = steps.iter().map(|s| s.momentum_angular).collect();
        let (dl, dh) = (rel_drift(&lin), rel_drift(&ang));
        let betas: Vec<f64> = steps[1..].iter().map(|s| s.beta).collect();
        let determined = betas.iter().filter(|b| b.is_finite()).count();
        eprintln!(
            "{mass:?}: energy drift {de:.2e}, momentum drift {dl:.2e} / {dh:.2e}, β determined in {determined} of {} steps, max |β| {:.3e}",
            betas.len(),
            betas.iter().filter(|b| b.is_finite()).fold(0.0f64, |m, b| m.max(b.abs()))
        );
        assert!(de <= 1e-9, "{mass:?}: energy drift {de:e}");
        assert!(
            dl <= 1e-9 && dh <= 1e-9,
            "{mass:?}: momentum drift {dl:e} / {dh:e}"
        );
        assert!(
            determined * 10 >= betas.len() * 9,
            "β undetermined too often"
        );
        let strain = steps.iter().map(|s| s.energy.strain).fold(0.0, f64::max);
        assert!(strain > 1e-6);
    }
}

#[test]
fn newmark_translates_exactly_and_reports_its_energy_error() {
    use flexmech_integrators::dynamics::newmark;
    // Uniform translation without forces: exact for the trapezoidal rule.
    let (mech, _, mut settings) = spinning_beam(MassKind::Consistent);
    settings.t_end = 2.0;
    let v0 = Vector3::new(0.3, -0.4, 1.2);
    let still = Motion {
        v: vec![v0; mech.mesh.node_count()],
        w: vec![Vector3::zeros(); mech.mesh.node_count()],
        joint_rates: Vec::new(),
    };
    let mut last = None;
    newmark::solve(&mech, &settings, &still, |s| last = Some(s.clone())).unwrap();
    let last = last.unwrap();
    for (p, x0) in last.positions.iter().zip(&mech.mesh.positions) {
        assert!((Vector3::from(*p) - (x0 + v0 * 2.0)).norm() < 1e-12);
    }
    // The spinning, deforming beam: linear momentum is conserved (Σ M a =
    // Σ f_int = 0), angular momentum and energy are not; the energy error is
    // reported.
    let (mech, motion, mut settings) = spinning_beam(MassKind::Consistent);
    settings.t_end = 5.0;
    let mut steps: Vec<StepRecord> = Vec::new();
    newmark::solve(&mech, &settings, &motion, |s| steps.push(s.clone())).unwrap();
    let lin: Vec<_> = steps.iter().map(|s| s.momentum_linear).collect();
    assert!(
        rel_drift(&lin) <= 1e-9,
        "linear momentum drift {:e}",
        rel_drift(&lin)
    );
    let e0 = steps[0].energy.total;
    let de = steps
        .iter()
        .map(|s| (s.energy.total - e0).abs() / e0)
        .fold(0.0, f64::max);
    let ang: Vec<_> = steps.iter().map(|s| s.momentum_angular).collect();
    eprintln!(
        "Newmark: energy error {de:.2e}, angular momentum drift {:.2e} over {} steps",
        rel_drift(&ang),
        steps.len() - 1
    );
    assert!(de.is_finite());
}

#[test]
fn tumbling_rigid_body_keeps_its_exact_energy_and_momentum() {
    use flexmech_integrators::dynamics::{energy_momentum, momentum};
    // One short, very stiff element with unequal principal inertias, spun
    // about a non-principal axis through its centre: a free rigid body
    // (Simo & Wong's test). Its exact energy ½ω·I_cω and momentum I_cω
    // (I_c: ρA L³/12 about the transverse axes plus the nodal inertias ρJ·L)
    // are constants of the motion.
    let (rho_a, l) = (3.0, 0.2);
    let rho_j = [0.05, 0.02, 0.08];
    let sec = Section::new([1.0e9, 4.0e8, 4.0e8], [1.0e7, 1.0e7, 1.0e7], rho_a, rho_j);
    let mut mesh = Mesh::default();
    mesh.add_straight_beam(
        Vector3::new(-0.5 * l, 0.0, 0.0),
        Vector3::new(0.5 * l, 0.0, 0.0),
        Vector3::y(),
        1,
        2,
        sec,
    )
    .unwrap();
    let mech = Mechanism::new(mesh);
    let om = Vector3::new(1.5, 2.0, -0.7);
    let motion = Motion {
        v: mech.mesh.positions.iter().map(|x| om.cross(x)).collect(),
        w: vec![om; 2],
        joint_rates: Vec::new(),
    };
    let rod = rho_a * l.powi(3) / 12.0;
    let i_c = nalgebra::Matrix3::from_diagonal(&Vector3::new(
        rho_j[0] * l,
        rho_j[1] * l + rod,
        rho_j[2] * l + rod,
    ));
    let (t_exact, h_exact) = (0.5 * om.dot(&(i_c * om)), i_c * om);
    let settings = crate::common::settings(0.05, 10.0, 1e-12, 30, 6, MassKind::Consistent);
    let mut em: Vec<StepRecord> = Vec::new();
    energy_momentum::solve(&mech, &settings, &motion, |s| em.push(s.clone())).unwrap();
    let mut mc: Vec<StepRecord> = Vec::new();
    momentum::solve(&mech, &settings, &motion, |s| mc.push(s.clone())).unwrap();
    let dev = |r: &[StepRecord]| {
        r.iter()
            .map(|s| (Vector3::from(s.momentum_angular) - h_exact).norm() / h_exact.norm())
            .fold(0.0, f64::max)
    };
    let dev_e = em
        .iter()
        .map(|s| (s.energy.total - t_exact).abs() / t_exact)
        .fold(0.0, f64::max);
    eprintln!("tumbling body: EM energy {dev_e:.2e}, EM momentum {:.2e}, MC momentum {:.2e}, {} / {} steps", dev(&em), dev(&mc), em.len() - 1, mc.len() - 1);
    for s in &em {
        assert!(
            (s.energy.total - t_exact).abs() <= 1e-9 * t_exact,
            "EM energy {} vs {t_exact}",
            s.energy.total
        );
        assert!((Vector3::from(s.momentum_angular) - h_exact).norm() <= 1e-9 * h_exact.norm());
    }
    for s in &mc {
        assert!((Vector3::from(s.momentum_angular) - h_exact).norm() <= 1e-9 * h_exact.norm());
    }
    // It really tumbles: the body axis moves around.
    let q_end = em.last().unwrap().quaternions[0];
    assert!(q_end[0].abs() < 0.999, "{q_end:?}");
}

/// The records of `solve` on a pool of `threads` threads.
fn records_on(
    threads: usize,
    solve: impl FnOnce(&mut dyn FnMut(&StepRecord)) + Send,
) -> Vec<StepRecord> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    let mut steps: Vec<StepRecord> = Vec::new();
    pool.install(|| solve(&mut |s| steps.push(s.clone())));
    steps
}

/// Whether two runs' records are the same to the bit (energy, β, positions).
fn assert_same_bits(one: &[StepRecord], two: &[StepRecord]) {
    assert_eq!(one.len(), two.len());
    for (a, b) in one.iter().zip(two) {
        assert_eq!(a.beta.to_bits(), b.beta.to_bits());
        assert_eq!(a.energy.total.to_bits(), b.energy.total.to_bits());
        for (p, q) in a.positions.iter().zip(&b.positions) {
            assert_eq!(p.map(f64::to_bits), q.map(f64::to_bits));
        }
    }
}

#[test]
fn energy_momentum_is_bitwise_deterministic_across_thread_counts() {
    use flexmech_integrators::dynamics::energy_momentum;
    // Enough elements for the parallel loops (threads::PARALLEL_MIN_ELEMENTS).
    let elements = flexmech_integrators::threads::PARALLEL_MIN_ELEMENTS;
    let (mech, motion, mut settings) = spinning_beam_of(MassKind::Consistent, elements, 2);
    settings.dt = 0.2;
    settings.t_end = 2.0;
    let run = |threads: usize| {
        records_on(threads, |push| {
            flexmech_integrators::threads::always_split(|| {
                energy_momentum::solve(&mech, &settings, &motion, push).unwrap()
            });
        })
    };
    assert_same_bits(&run(1), &run(2));
}

#[test]
fn newmark_on_a_band_in_two_halves_is_bitwise_the_same_on_one_and_two_threads() {
    use flexmech_integrators::band_split::SPLIT_MIN_UNKNOWNS;
    use flexmech_integrators::threads::PARALLEL_ALWAYS_ELEMENTS;
    // Six unknowns a node: the band LU goes in two halves at once, and the
    // element loops are split whatever their kernels cost.
    let elements = PARALLEL_ALWAYS_ELEMENTS.max(SPLIT_MIN_UNKNOWNS / 6 + 1);
    let (mech, motion, mut settings) = spinning_beam_of(MassKind::Lumped, elements, 2);
    settings.dt = 0.01;
    settings.t_end = 0.03;
    let run = |threads: usize| {
        records_on(threads, |push| {
            flexmech_integrators::dynamics::newmark::solve(&mech, &settings, &motion, push)
                .unwrap();
        })
    };
    let one = run(1);
    assert_eq!(one.len(), 4);
    assert_same_bits(&one, &run(2));
}

#[test]
fn stored_times_are_multiples_of_the_step() {
    // Summing 0.1 ten times gives 0.9999999999999999; the stored times are
    // n·Δt exactly, in every integrator.
    let (mech, motion, mut settings) = spinning_beam(MassKind::Lumped);
    settings.dt = 0.1;
    settings.t_end = 1.0;
    let (mut nm, mut mc) = (Vec::new(), Vec::new());
    flexmech_integrators::dynamics::newmark::solve(&mech, &settings, &motion, |s| nm.push(s.time))
        .unwrap();
    momentum::solve(&mech, &settings, &motion, |s| mc.push(s.time)).unwrap();
    let times = [nm, mc];
    for t in &times {
        assert_eq!(t.len(), 11);
        for (k, &tk) in t.iter().enumerate() {
            assert_eq!(tk, k as f64 * 0.1, "{t:?}");
        }
    }
}

#[test]
fn three_node_elements_conserve_energy_and_momenta_in_both_conserving_schemes() {
    // 5 quadratic elements, a fifth of a turn per step, 60 steps: the
    // discrete gradient of the 3-node element (used by both conserving
    // schemes) conserves energy and both momenta to the Newton tolerance.
    use flexmech_integrators::dynamics::energy_momentum;
    let (mech, motion, mut settings) = spinning_beam_of(MassKind::Consistent, 5, 3);
    settings.dt = 0.2;
    settings.t_end = 12.0;
    for scheme in ["momentum", "energy-momentum"] {
        let mut steps: Vec<StepRecord> = Vec::new();
        let push = |s: &StepRecord| steps.push(s.clone());
        if scheme == "momentum" {
            momentum::solve(&mech, &settings, &motion, push).unwrap();
        } else {
            energy_momentum::solve(&mech, &settings, &motion, push).unwrap();
        }
        assert_eq!(steps.len(), 61, "{scheme}: a step was halved");
        let e0 = steps[0].energy.total;
        let de = steps
            .iter()
            .map(|s| (s.energy.total - e0).abs() / e0)
            .fold(0.0, f64::max);
        let lin: Vec<_> = steps.iter().map(|s| s.momentum_linear).collect();
        let ang: Vec<_> = steps.iter().map(|s| s.momentum_angular).collect();
        let (dl, dh) = (rel_drift(&lin), rel_drift(&ang));
        let strain = steps.iter().map(|s| s.energy.strain).fold(0.0, f64::max);
        eprintln!(
            "3-node, {scheme}: energy {de:.2e}, momenta {dl:.2e} / {dh:.2e}, strain {strain:.2e}"
        );
        assert!(de <= 1e-9, "{scheme}: energy drift {de:e}");
        assert!(
            dl <= 1e-9 && dh <= 1e-9,
            "{scheme}: momentum drift {dl:e} / {dh:e}"
        );
        assert!(strain > 1e-6);
    }
}
