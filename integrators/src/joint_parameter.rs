//! How a joint's parameter enters the discrete equations, for exact
//! sensitivities by it.
//!
//! A dependent joint places its slave at `x_s = x_m + R_m f(ψ; p)` (paper
//! eq. 1, `f` in the master's frame). At fixed unknowns `q` a change of `p`
//! moves the slave — and every node placed from it through further joints —
//! by `δ = R_m ∂f/∂p` (rotations do not change), and changes the slave's
//! map `T_s` (paper eqs 5–8) in its columns for the master's rotation and
//! for `ψ`. So
//!
//! ```text
//! ∂r/∂p = Tᵀ (∂g/∂x · δ) + (∂T/∂p)ᵀ g,
//! (∂T/∂p)ᵀ g:  master moment += (R_m ∂f/∂p) × F,   ψ equation += (R_m ∂²f/∂ψ∂p) · F,
//! ```
//!
//! with `F` the force on the slave and the nodes placed from it. `∂g/∂x · δ`
//! is the elements' exact tangent (and, in dynamics, the inertia's) applied
//! to the shift; the nodes' positions change by `T dq/dp + δ`.
//!
//! A parameter with `∂f/∂p(ψ₀) ≠ 0` also moves the slave at t = 0, where
//! the model places it. The derivative is then that of the model whose
//! **carried body** — the slave and every node joined to it by elements and
//! other joints, this joint cut — is re-placed rigidly with it by
//! `δ₀ = R_m ∂f/∂p(ψ₀)` (`StartShift`): what a researcher does by hand to
//! change a cam's offset (move the follower's beams with it). A rigid
//! translation leaves the carried elements' strains, masses and dead loads
//! as they were, so the body's positions start at `dx₀/dp = δ₀` and its
//! displacements are `dx/dp − δ₀`. A carried body that also reaches the
//! master, a support or a prescribed motion cannot move rigidly; such a
//! parameter is refused.

use nalgebra::Vector3;

use crate::constraints::{MechanismState, Topology};
use crate::error::SolveError;
use crate::mechanism::Mechanism;

/// Below this size (relative to the mechanism) a joint parameter's shift of
/// the slave at t = 0 counts as none.
pub(crate) const START_SHIFT: f64 = 1e-12;

/// A joint parameter's direct effect at one state.
pub(crate) struct JointShift {
    /// Every node the shift moves (the slave and the nodes placed from it)
    /// and `δ = R_m ∂f/∂p`.
    pub(crate) nodes: Vec<usize>,
    pub(crate) delta: Vector3<f64>,
    /// `R_m ∂²f/∂ψ∂p`.
    pub(crate) slope: Vector3<f64>,
    master: usize,
    /// The equation of `ψ` (`None` when driven).
    pub(crate) psi_eq: Option<usize>,
}

impl JointShift {
    /// The effect of parameter `name` of joint `joint` at `state`.
    pub(crate) fn at(
        mech: &Mechanism,
        topo: &Topology,
        state: &MechanismState,
        joint: usize,
        name: &str,
    ) -> Result<Self, SolveError> {
        let j = &mech.joints[joint];
        let [f_p, slope] = j
            .map
            .parameter_derivative(name, &state.released[joint])
            .ok_or_else(|| {
                SolveError::InvalidMechanism(format!(
                    "joint `{}` cannot differentiate by a parameter `{name}` (parameters of \
                     expression joints can be differentiated by)",
                    j.name
                ))
            })?;
        let r_m = state.config.rot[j.master];
        Ok(Self {
            nodes: placed_from(mech, topo, j.slave),
            delta: r_m * f_p,
            slope: r_m * slope,
            master: j.master,
            psi_eq: topo.released_eqs[joint].first().copied().flatten(),
        })
    }

    /// Adds `∂g/∂x · δ` of the elements at `config` to the nodal `g`
    /// (and `c M δ` when `inertia` gives the mass and `∂q̈/∂x`).
    pub(crate) fn add_stiffness(
        &self,
        mech: &Mechanism,
        config: &flexmech_core::Configuration,
        inertia: Option<(&flexmech_core::Inertia, f64)>,
        g: &mut [f64],
    ) {
        let tangent = |e: &flexmech_core::Element, r: &mut [f64], k: &mut [f64]| {
            e.residual_tangent(&config.x, &config.rot, r, k)
        };
        self.add_stiffness_with(mech, tangent, inertia, g);
    }

    /// [`Self::add_stiffness`] with the elements' force and tangent with
    /// respect to the moved end pose from `tangent(element, r, k)` (a time
    /// scheme's kernel).
    pub(crate) fn add_stiffness_with(
        &self,
        mech: &Mechanism,
        tangent: impl Fn(&flexmech_core::Element, &mut [f64], &mut [f64]),
        inertia: Option<(&flexmech_core::Inertia, f64)>,
        g: &mut [f64],
    ) {
        let moved: Vec<(usize, Vector3<f64>)> =
            self.nodes.iter().map(|&n| (n, self.delta)).collect();
        add_moved_stiffness(mech, tangent, inertia, &moved, g);
    }

    /// Adds `(∂T/∂p)ᵀ g` for the nodal residual `g`: the master's moment into
    /// the nodal `out`; returns the `ψ` equation's share, if `ψ` is free.
    pub(crate) fn add_transfer(&self, g: &[f64], out: &mut [f64]) -> Option<(usize, f64)> {
        let force: Vector3<f64> = (self.nodes.iter())
            .map(|&n| Vector3::new(g[6 * n], g[6 * n + 1], g[6 * n + 2]))
            .sum();
        self.add_transfer_of(&force, out)
    }

    /// [`Self::add_transfer`] for the total translational force `force` on
    /// the moved nodes.
    pub(crate) fn add_transfer_of(
        &self,
        force: &Vector3<f64>,
        out: &mut [f64],
    ) -> Option<(usize, f64)> {
        let moment = self.delta.cross(force);
        for c in 0..3 {
            out[6 * self.master + 3 + c] += moment[c];
        }
        self.psi_eq.map(|eq| (eq, self.slope.dot(force)))
    }

    /// `ω_m × δ + s ψ̇₀`: the moved nodes' initial velocity's derivative for
    /// the master's spatial angular velocity `omega` and the joint's rate.
    pub(crate) fn velocity(&self, omega: &Vector3<f64>, rate: f64) -> Vector3<f64> {
        omega.cross(&self.delta) + self.slope * rate
    }

    /// The joint's master.
    pub(crate) fn master(&self) -> usize {
        self.master
    }

    /// The shift of node `n` (zero off the moved nodes).
    pub(crate) fn of(&self, n: usize) -> Vector3<f64> {
        if self.nodes.contains(&n) {
            self.delta
        } else {
            Vector3::zeros()
        }
    }
}

/// `slave` and every node placed from it through joints, in placement
/// order.
fn placed_from(mech: &Mechanism, topo: &Topology, slave: usize) -> Vec<usize> {
    let mut nodes = vec![slave];
    for &j in &topo.order {
        let joint = &mech.joints[j];
        if nodes.contains(&joint.master) && !nodes.contains(&joint.slave) {
            nodes.push(joint.slave);
        }
    }
    nodes
}

/// The body joint `joint` carries: the nodes reached from its slave through
/// elements and the other joints. Refused with `name` where it reaches the
/// master, a support or a prescribed motion (it could not move rigidly).
pub(crate) fn carried_body(
    mech: &Mechanism,
    joint: usize,
    name: &str,
) -> Result<Vec<usize>, SolveError> {
    let n = mech.mesh.node_count();
    let mut links: Vec<Vec<usize>> = vec![Vec::new(); n];
    let mut link = |a: usize, b: usize| {
        links[a].push(b);
        links[b].push(a);
    };
    for e in &mech.mesh.elements {
        let nodes = e.nodes();
        for w in nodes.windows(2) {
            link(w[0], w[1]);
        }
    }
    for (k, j) in mech.joints.iter().enumerate() {
        if k != joint {
            link(j.master, j.slave);
        }
    }
    let j = &mech.joints[joint];
    let (mut body, mut next) = (vec![j.slave], 0);
    while next < body.len() {
        for &m in &links[body[next]] {
            if !body.contains(&m) {
                body.push(m);
            }
        }
        next += 1;
    }
    let held = (body.iter().copied()).find_map(|m| {
        let label = || match mech.names.nodes.get(m) {
            Some(l) if !l.is_empty() => l.clone(),
            _ => format!("node {m}"),
        };
        if m == j.master {
            Some(format!("the joint's master `{}`", label()))
        } else if mech.fixed[m].iter().any(|&f| f) {
            Some(format!("the support of `{}`", label()))
        } else if mech.prescribed.iter().any(|p| p.node == m) {
            Some(format!("the prescribed motion of `{}`", label()))
        } else {
            None
        }
    });
    match held {
        None => Ok(body),
        Some(what) => Err(SolveError::InvalidMechanism(format!(
            "joint `{}`: changing `{name}` moves the slave at t = 0, and the body it carries \
             would move rigidly with it, but that body is also held by {what}: differentiate \
             by a parameter that leaves f(ψ₀) unchanged, or free the body",
            j.name
        ))),
    }
}

/// Adds `∂g/∂x · δ` of the elements (force and tangent from
/// `tangent(element, r, k)`, the tangent with respect to the end pose) and,
/// with `inertia = (M, c)`, `c M δ`, for nodes moved by `moved` (node, `δ`),
/// to the nodal `g`.
pub(crate) fn add_moved_stiffness(
    mech: &Mechanism,
    tangent: impl Fn(&flexmech_core::Element, &mut [f64], &mut [f64]),
    inertia: Option<(&flexmech_core::Inertia, f64)>,
    moved: &[(usize, Vector3<f64>)],
    g: &mut [f64],
) {
    let shift = |n: usize| moved.iter().find(|(m, _)| *m == n).map(|(_, d)| *d);
    for e in &mech.mesh.elements {
        let nodes = e.nodes();
        if !nodes.iter().any(|&n| shift(n).is_some()) {
            continue;
        }
        let n = 6 * nodes.len();
        let (mut r, mut k) = (vec![0.0; n], vec![0.0; n * n]);
        tangent(e, &mut r, &mut k);
        for (b, &nb) in nodes.iter().enumerate() {
            let Some(delta) = shift(nb) else { continue };
            for c in 0..3 {
                let column = &k[(6 * b + c) * n..(6 * b + c + 1) * n];
                for (a, &na) in nodes.iter().enumerate() {
                    for i in 0..6 {
                        g[6 * na + i] += column[6 * a + i] * delta[c];
                    }
                }
            }
        }
    }
    if let Some((inertia, c)) = inertia {
        for &(i, j, m) in &inertia.mass {
            if let Some(delta) = shift(j) {
                for comp in 0..3 {
                    g[6 * i + comp] += c * m * delta[comp];
                }
            }
        }
    }
}
