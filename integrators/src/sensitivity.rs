//! Exact parameter sensitivities of static equilibria, by direct
//! differentiation of the discrete equations.
//!
//! A converged static step satisfies the reduced equations `r(q(p), p) = 0`
//! at its load factor λ. Differentiating with respect to a parameter `p`,
//!
//! ```text
//! K · dq/dp = −∂r/∂p,     K = ∂r/∂q (the exact tangent at the converged state),
//! ```
//!
//! one solve per parameter with one factorisation of `K` per step. In
//! statics the equilibrium at λ depends on λ and `p` only (no history), so
//! each step's derivatives come from its own state. `dq/dp` maps to every
//! node's translation by the same linear map the Newton increments go
//! through (`DofMap::node_increment`, slaves by the joints' `N`).
//!
//! `∂r/∂p` is exact: the internal forces `Bᵀ C (ε − ε₀)` are linear in each
//! stiffness of `C = diag(EA, GA₂, GA₃, GJ, EI₂, EI₃)`, so their derivative
//! is the internal force of the same elements, in the same state, with that
//! stiffness 1 and the others 0; a dead load's component enters `r` as
//! `−s(λ) e`.
//!
//! The total energy `E = U − Σ fₑₓₜ·u` (strain energy and the dead loads'
//! potential, [`crate::measure::load_potential`]) has the total derivative
//!
//! ```text
//! dE/dp = Σₙ f_int,n · dxₙ/dp − Σₙ fₑₓₜ,n · duₙ/dp + ∂E/∂p
//! ```
//!
//! with `dxₙ/dp` the node's translation and spatial rotation increment per
//! unit `p` (the work-conjugates of the nodal forces and moments), `duₙ/dp`
//! its translation and `∂E/∂p` at fixed configuration: the unit-stiffness
//! elements' strain energy, or `−s(λ) uₙ·e` for a load component. Follower
//! loads make the total path-dependent; its derivative is then NaN.

use nalgebra::Vector3;
use std::ops::AddAssign;

use crate::error::SolveError;
use crate::joint_parameter::JointShift;
use crate::linsolve::SparseLu;
use crate::mechanism::{nodal_weights, Mechanism};
use crate::record::Sensitivity;
use crate::start_shift::StartShift;
use crate::system::{ReducedSystem, StepTerms};
use flexmech_core::{Configuration, Element, Section};

/// A real number of the mechanism a sensitivity is taken with respect to.
#[derive(Debug, Clone, PartialEq)]
pub enum Parameter {
    /// One stiffness of the sections of the elements `elements` (indices
    /// into the mesh): `component` 0–5 is EA, GA₂, GA₃, GJ, EI₂, EI₃.
    Stiffness {
        /// The elements whose section carries it.
        elements: Vec<usize>,
        /// Which stiffness, 0–5.
        component: usize,
    },
    /// Component `component` (0–2 force, 3–5 moment, global axes) of the
    /// dead nodal load `load` (index into [`Mechanism::loads`]).
    Load {
        /// The load.
        load: usize,
        /// Which component, 0–5.
        component: usize,
    },
    /// Component `component` of a load spread over several dead nodal
    /// loads, `(load, w)` with `w` the load's share of a unit value (a
    /// distributed load per unit length: each node's `∫ Nᵢ ds`).
    Loads {
        /// The nodal loads (indices into [`Mechanism::loads`]) and their
        /// shares.
        shares: Vec<(usize, f64)>,
        /// Which component, 0–5.
        component: usize,
    },
    /// The mass per unit length (`component` 0: ρA) or one rotational
    /// inertia per unit length (1–3: ρ(I₂+I₃), ρI₂, ρI₃) of the sections of
    /// the elements `elements`: the inertial forces and (ρA) gravity.
    Mass {
        /// The elements whose section carries it.
        elements: Vec<usize>,
        /// Which value, 0–3.
        component: usize,
    },
    /// The mass (`component` 0) or a principal inertia about the centre of
    /// mass (1–3: about the global axes at t = 0) of rigid body `body`
    /// (index into [`Mechanism::bodies`]): its inertial forces and weight.
    BodyMass {
        /// The body.
        body: usize,
        /// Which value, 0–3.
        component: usize,
    },
    /// The real parameter `name` of joint `joint` (index into
    /// [`Mechanism::joints`]) of a kind that can differentiate by it (an
    /// expression joint's `parameters`); see [`crate::joint_parameter`] —
    /// refused where it would move the slave at t = 0.
    Joint {
        /// The joint.
        joint: usize,
        /// The parameter's name.
        name: String,
    },
    /// A change of a straight beam's initial geometry (one coordinate of
    /// its end): its elements lengthen, `dL/dp = s_e L_e`, their initial
    /// triads turn, `dλ₀/dp = ω̂ λ₀`, and its nodes' initial positions move
    /// by `dX/dp`.
    Geometry {
        /// The beam's elements with their relative stretch `s_e`.
        stretch: Vec<(usize, f64)>,
        /// `ω`.
        spin: Vector3<f64>,
        /// The moved nodes' `dX/dp`.
        shifts: Vec<(usize, Vector3<f64>)>,
        /// The dead nodal loads the beam's distributed loads became: they
        /// scale with its elements' lengths (`dF/dp = s F`).
        loads: Vec<usize>,
    },
    /// A value of the initial motion (dynamics): `motion` is the
    /// derivative of the initial nodal velocities (and joint rates) by it;
    /// the slaves' follow through `N`.
    InitialMotion {
        /// `d(initial motion)/dp`.
        motion: crate::dynamics::Motion,
    },
}

impl Parameter {
    /// Whether it names elements, a load and a component that exist.
    pub fn check(&self, mech: &Mechanism) -> Result<(), SolveError> {
        if let Parameter::Geometry { shifts, .. } = self {
            crate::geometry::check_joints(mech, shifts)?;
        }
        let ok = match self {
            Parameter::Stiffness {
                elements,
                component,
            } => *component < 6 && elements.iter().all(|&e| e < mech.mesh.elements.len()),
            Parameter::Load { load, component } => *load < mech.loads.len() && *component < 6,
            Parameter::Loads { shares, component } => {
                *component < 6
                    && shares
                        .iter()
                        .all(|&(l, w)| l < mech.loads.len() && w.is_finite())
            }
            Parameter::InitialMotion { motion } => {
                let n = mech.mesh.node_count();
                motion.v.len() == n && motion.w.len() == n
            }
            Parameter::Mass {
                elements,
                component,
            } => *component < 4 && elements.iter().all(|&e| e < mech.mesh.elements.len()),
            Parameter::Joint { joint, .. } => *joint < mech.joints.len(),
            Parameter::Geometry {
                stretch,
                shifts,
                loads,
                ..
            } => {
                stretch
                    .iter()
                    .all(|&(e, s)| e < mech.mesh.elements.len() && s.is_finite())
                    && shifts.iter().all(|&(n, _)| n < mech.mesh.node_count())
                    && loads.iter().all(|&l| l < mech.loads.len())
            }
            Parameter::BodyMass { body, component } => *body < mech.bodies.len() && *component < 4,
        };
        if ok {
            Ok(())
        } else {
            Err(SolveError::InvalidMechanism(format!(
                "sensitivity parameter {self:?} names no element, load or component of this \
                 mechanism"
            )))
        }
    }

    /// A joint parameter's direct effect at the end state of `sys` (`None`
    /// for the other parameters).
    pub(crate) fn shift<T: StepTerms>(
        &self,
        sys: &ReducedSystem<'_, T>,
    ) -> Result<Option<JointShift>, SolveError> {
        match self {
            Parameter::Joint { joint, name } => {
                JointShift::at(sys.mech, &sys.topo, &sys.end, *joint, name).map(Some)
            }
            _ => Ok(None),
        }
    }

    /// Its re-placement of a carried body at the start state of `sys`
    /// ([`StartShift`]; none but for joint parameters).
    pub(crate) fn start_shift<T: StepTerms>(
        &self,
        sys: &ReducedSystem<'_, T>,
    ) -> Result<StartShift, SolveError> {
        match self {
            Parameter::Joint { joint, name } => {
                StartShift::for_joint(sys.mech, &sys.topo, &sys.end, *joint, name)
            }
            Parameter::Geometry { shifts, .. } => Ok(StartShift::of_nodes(shifts.clone())),
            _ => Ok(StartShift::default()),
        }
    }

    /// The held translations this parameter moves at every step, node by
    /// node ([`crate::geometry::held_shifts`]; none but for a geometry).
    pub(crate) fn held_shift(&self, mech: &Mechanism) -> StartShift {
        match self {
            Parameter::Geometry { shifts, .. } => {
                StartShift::of_nodes(crate::geometry::held_shifts(mech, shifts))
            }
            _ => StartShift::default(),
        }
    }

    /// The dead loads this parameter scales, with their shares (empty for
    /// a stiffness).
    fn load_shares(&self) -> (Vec<(usize, f64)>, usize) {
        match self {
            Parameter::Stiffness { .. }
            | Parameter::InitialMotion { .. }
            | Parameter::Mass { .. }
            | Parameter::Joint { .. }
            | Parameter::Geometry { .. }
            | Parameter::BodyMass { .. } => (Vec::new(), 0),
            Parameter::Load { load, component } => (vec![(*load, 1.0)], *component),
            Parameter::Loads { shares, component } => (shares.clone(), *component),
        }
    }

    /// `∂g/∂p`, the derivative of the nodal residual `g = f_int − f_ext`
    /// (6 per node) at `config` and load factor `lambda`, into `out`; returns
    /// `∂E/∂p`, the total energy's derivative at fixed configuration.
    pub(crate) fn nodal_derivative(
        &self,
        mech: &Mechanism,
        config: &Configuration,
        lambda: f64,
        out: &mut [f64],
    ) -> f64 {
        out.iter_mut().for_each(|v| *v = 0.0);
        if let Parameter::Stiffness {
            elements,
            component,
        } = self
        {
            let mut r = Vec::new();
            let mut energy = 0.0;
            for &e in elements {
                let unit = with_unit_stiffness(&mech.mesh.elements[e], *component);
                r.resize(unit.dofs(), 0.0);
                unit.internal_force_into(&config.x, &config.rot, &mut r);
                for (k, &n) in unit.nodes().iter().enumerate() {
                    for c in 0..6 {
                        out[6 * n + c] += r[6 * k + c];
                    }
                }
                energy += unit.energy(&config.x, &config.rot);
            }
            return energy;
        }
        if let Parameter::Mass {
            elements,
            component,
        } = self
        {
            return unit_gravity(mech, elements, *component, config, lambda, out);
        }
        if let Parameter::Geometry {
            stretch,
            spin,
            loads,
            ..
        } = self
        {
            let energy = crate::geometry::forces(mech, config, lambda, (stretch, spin), out);
            let lines = (stretch.as_slice(), loads.as_slice());
            return energy + crate::geometry::line_loads(mech, config, lambda, lines, out);
        }
        if let Parameter::BodyMass { body, component: 0 } = self {
            let n = mech.bodies[*body].node;
            let g = mech.gravity * mech.gravity_scale.at(lambda);
            for c in 0..3 {
                out[6 * n + c] -= g[c];
            }
            return -g.dot(&(config.x[n] - mech.mesh.positions[n]));
        }
        let (shares, component) = self.load_shares();
        let mut energy = 0.0;
        for (load, w) in shares {
            let l = &mech.loads[load];
            let f = w * l.scale.at(lambda);
            out[6 * l.node + component] -= f;
            if component < 3 {
                energy -=
                    f * (config.x[l.node][component] - mech.mesh.positions[l.node][component]);
            }
        }
        energy
    }
}

/// `∂g/∂p = −∂f_ext/∂p` of a mass parameter: the gravity forces of the
/// elements `elements` with unit ρA (nothing for a rotational inertia),
/// into `out`; returns `∂E/∂p`, their potential `−Σ ∂f·u`.
fn unit_gravity(
    mech: &Mechanism,
    elements: &[usize],
    component: usize,
    config: &Configuration,
    t: f64,
    out: &mut [f64],
) -> f64 {
    if component != 0 || mech.gravity == Vector3::zeros() {
        return 0.0;
    }
    let g = mech.gravity * mech.gravity_scale.at(t);
    let mut energy = 0.0;
    for &e in elements {
        let element = &mech.mesh.elements[e];
        let nodes = element.nodes();
        for (&n, w) in nodes.iter().zip(nodal_weights(nodes.len())) {
            let f = g * (w * element.length());
            let u = config.x[n] - mech.mesh.positions[n];
            for c in 0..3 {
                out[6 * n + c] -= f[c];
            }
            energy -= f.dot(&u);
        }
    }
    energy
}

/// `∂M/∂p` and `∂J/∂p` of a mass parameter ([`Parameter::Mass`],
/// [`Parameter::BodyMass`]; `None` for the others).
pub(crate) fn mass_derivative(
    mech: &Mechanism,
    p: &Parameter,
    kind: flexmech_core::MassKind,
) -> Option<flexmech_core::Inertia> {
    match p {
        Parameter::Geometry { stretch, spin, .. } => Some(
            flexmech_core::Inertia::geometry_derivative(&mech.mesh, kind, stretch, spin),
        ),
        Parameter::Mass {
            elements,
            component,
        } => Some(unit_inertia(mech, elements, *component, kind)),
        Parameter::BodyMass { body, component } => {
            let mut unit = unit_inertia(mech, &[], 0, kind);
            let node = mech.bodies[*body].node;
            let (m, mut j) = (f64::from(*component == 0), nalgebra::Matrix3::zeros());
            if *component > 0 {
                j[(component - 1, component - 1)] = 1.0;
            }
            unit.add_body(node, m, &j);
            Some(unit)
        }
        _ => None,
    }
}

/// The inertia of the elements `elements` with a unit mass parameter
/// `component` (0: ρA, 1–3: ρJ) and every other element massless.
fn unit_inertia(
    mech: &Mechanism,
    elements: &[usize],
    component: usize,
    kind: flexmech_core::MassKind,
) -> flexmech_core::Inertia {
    let mut mesh = mech.mesh.clone();
    for (k, e) in mesh.elements.iter_mut().enumerate() {
        let unit = elements.contains(&k);
        let section = match e {
            Element::Linear(e) => &mut e.section,
            Element::Quadratic(e) => &mut e.section,
        };
        section.rho_a = if unit && component == 0 { 1.0 } else { 0.0 };
        section.rho_j = Vector3::zeros();
        if unit && component > 0 {
            section.rho_j[component - 1] = 1.0;
        }
    }
    flexmech_core::Inertia::new(&mesh, kind)
}

/// `element` with a section whose stiffness `component` is 1 and every
/// other stiffness 0.
pub(crate) fn with_unit_stiffness(element: &Element, component: usize) -> Element {
    let mut stiffness = [0.0; 6];
    stiffness[component] = 1.0;
    let section = |s: &Section| Section {
        c_n: Vector3::new(stiffness[0], stiffness[1], stiffness[2]),
        c_m: Vector3::new(stiffness[3], stiffness[4], stiffness[5]),
        ..*s
    };
    let mut unit = element.clone();
    match &mut unit {
        Element::Linear(e) => e.section = section(&e.section),
        Element::Quadratic(e) => e.section = section(&e.section),
    }
    unit
}

/// The sensitivities of a static solve: its parameters and the
/// factorisation of the converged tangent.
pub(crate) struct StaticSensitivities {
    params: Vec<Parameter>,
    /// Per parameter, its re-placement of a carried body at the start.
    starts: Vec<StartShift>,
    lu: SparseLu,
    nodal: Vec<f64>,
}

impl StaticSensitivities {
    /// Sensitivities to `params` of the solve whose system is `sys`.
    pub(crate) fn new<T: StepTerms>(
        sys: &ReducedSystem<'_, T>,
        params: &[Parameter],
    ) -> Result<Self, SolveError> {
        let mut starts = Vec::with_capacity(params.len());
        for p in params {
            p.check(sys.mech)?;
            if let Parameter::InitialMotion { .. } = p {
                return Err(SolveError::InvalidMechanism(
                    "a static analysis has no initial motion to differentiate by".into(),
                ));
            }
            starts.push(p.start_shift(sys)?);
        }
        let lu = SparseLu::new(sys.asm.pattern().clone()).map_err(SolveError::Singular)?;
        Ok(Self {
            params: params.to_vec(),
            starts,
            lu,
            nodal: vec![0.0; 6 * sys.mech.mesh.node_count()],
        })
    }

    /// The sensitivities of the converged step to `lambda` for every
    /// parameter; `sys` holds its exact tangent, its nodal residual and
    /// external forces (as the converged record leaves them).
    pub(crate) fn at<T: StepTerms>(
        &mut self,
        sys: &ReducedSystem<'_, T>,
        lambda: f64,
    ) -> Result<Vec<Sensitivity>, SolveError> {
        if self.params.is_empty() {
            return Ok(Vec::new());
        }
        let failed =
            |why| SolveError::InvalidMechanism(format!("sensitivities at λ = {lambda}: {why}"));
        self.lu.factor(&sys.asm.values).map_err(failed)?;
        let mut out = Vec::with_capacity(self.params.len());
        for (p, start) in self.params.iter().zip(&self.starts) {
            let partial = p.nodal_derivative(sys.mech, &sys.end.config, lambda, &mut self.nodal);
            let shift = p.shift(sys)?;
            let psi = shift.as_ref().and_then(|s| {
                s.add_stiffness(sys.mech, &sys.end.config, None, &mut self.nodal);
                s.add_transfer(&sys.nodal, &mut self.nodal)
            });
            let held = p.held_shift(sys.mech);
            held.add_stiffness(sys.mech, &sys.end.config, None, &mut self.nodal);
            let mut dq = vec![0.0; sys.topo.dofs.n_eq];
            sys.reduce(&self.nodal, &mut dq);
            if let Some((eq, share)) = psi {
                dq[eq] += share;
            }
            dq.iter_mut().for_each(|v| *v = -*v);
            self.lu.solve(&mut dq).map_err(failed)?;
            let partial = partial + start.work(&sys.fext);
            out.push(sensitivity_of(
                sys,
                &dq,
                (shift.as_ref(), &held),
                start,
                partial,
            ));
        }
        Ok(out)
    }
}

/// The nodes' `d(x − X)/dp` and the total energy's `dE/dp` (module docs)
/// for the reduced `dq = dq/dp`, with `partial = ∂E/∂p` (`start`: the
/// initial positions' `dX/dp`).
fn sensitivity_of<T: StepTerms>(
    sys: &ReducedSystem<'_, T>,
    dq: &[f64],
    (shift, held): (Option<&JointShift>, &StartShift),
    start: &StartShift,
    partial: f64,
) -> Sensitivity {
    let mut energy = partial;
    let displacement = (0..sys.mech.mesh.node_count())
        .map(|n| {
            let mut d = sys.topo.dofs.node_increment(n, dq);
            if let Some(s) = shift {
                d.fixed_rows_mut::<3>(0).add_assign(&s.of(n));
            }
            d.fixed_rows_mut::<3>(0).add_assign(&held.of(n));
            for c in 0..6 {
                // f_int = g + f_ext; the dead loads' potential sees translations only.
                let f = sys.nodal[6 * n + c] + sys.fext[6 * n + c];
                energy += f * d[c];
                if c < 3 {
                    energy -= sys.fext[6 * n + c] * d[c];
                }
            }
            let d = d.fixed_rows::<3>(0) - start.of(n);
            [d[0], d[1], d[2]]
        })
        .collect();
    if !sys.mech.follower_loads.is_empty() {
        energy = f64::NAN;
    }
    Sensitivity {
        displacement,
        energy,
    }
}
