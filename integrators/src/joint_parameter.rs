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

use nalgebra::Vector3;

use crate::constraints::{MechanismState, Topology};
use crate::error::SolveError;
use crate::mechanism::Mechanism;

/// Below this size (relative to the mechanism) a joint parameter's shift of
/// the slave at t = 0 counts as none.
const START_SHIFT: f64 = 1e-12;

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

    /// Refuses a parameter that moves the slave at the start: a model file
    /// places its slaves once, at t = 0, so such a change has no run to
    /// differentiate.
    pub(crate) fn check_start(
        &self,
        mech: &Mechanism,
        joint: usize,
        name: &str,
    ) -> Result<(), SolveError> {
        if self.delta.norm() > START_SHIFT * mech.size_at(&mech.mesh.positions).max(1.0) {
            return Err(SolveError::InvalidMechanism(format!(
                "joint `{}`: changing `{name}` moves the slave at t = 0 (∂f/∂{name} = {:?} at \
                 the initial angle), which a model cannot follow (its slave is placed in the \
                 file); differentiate by a parameter that leaves f(ψ₀) unchanged",
                mech.joints[joint].name,
                [self.delta.x, self.delta.y, self.delta.z]
            )));
        }
        Ok(())
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
        let moved = |n: usize| self.nodes.contains(&n);
        for e in &mech.mesh.elements {
            let nodes = e.nodes();
            if !nodes.iter().any(|&n| moved(n)) {
                continue;
            }
            let n = 6 * nodes.len();
            let (mut r, mut k) = (vec![0.0; n], vec![0.0; n * n]);
            e.residual_tangent(&config.x, &config.rot, &mut r, &mut k);
            for (b, &nb) in nodes.iter().enumerate() {
                if !moved(nb) {
                    continue;
                }
                for c in 0..3 {
                    let column = &k[(6 * b + c) * n..(6 * b + c + 1) * n];
                    for (a, &na) in nodes.iter().enumerate() {
                        for i in 0..6 {
                            g[6 * na + i] += column[6 * a + i] * self.delta[c];
                        }
                    }
                }
            }
        }
        if let Some((inertia, c)) = inertia {
            for &(i, j, m) in &inertia.mass {
                if moved(j) {
                    for comp in 0..3 {
                        g[6 * i + comp] += c * m * self.delta[comp];
                    }
                }
            }
        }
    }

    /// Adds `(∂T/∂p)ᵀ g` for the nodal residual `g`: the master's moment into
    /// the nodal `out`; returns the `ψ` equation's share, if `ψ` is free.
    pub(crate) fn add_transfer(&self, g: &[f64], out: &mut [f64]) -> Option<(usize, f64)> {
        let force: Vector3<f64> = (self.nodes.iter())
            .map(|&n| Vector3::new(g[6 * n], g[6 * n + 1], g[6 * n + 2]))
            .sum();
        let moment = self.delta.cross(&force);
        for c in 0..3 {
            out[6 * self.master + 3 + c] += moment[c];
        }
        self.psi_eq.map(|eq| (eq, self.slope.dot(&force)))
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
