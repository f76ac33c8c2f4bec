//! A joint parameter's effect on the Newmark family's state at t = 0, for
//! exact sensitivities by it ([`super::newmark_sensitivity`]).
//!
//! At t = 0 the slave's subtree sits at `x_m + R_m f(ψ₀; p)` and moves with
//! the master through `N(p)` (paper eqs 10–11): its velocity is
//! `N q̇ + R_m f′ ψ̇_driven`, its acceleration the scheme's `N q̈`, `q̈` from
//! `(Nᵀ M N) q̈ = −Nᵀ g₀` ([`super::newmark_terms::initial_accelerations`]).
//! With `δ = R_m ∂f/∂p` and `s = R_m ∂²f/∂ψ∂p` (the columns of `∂N/∂p`
//! for the master's rotation, `−δ̂`, and for `ψ`, `s`) differentiating gives,
//! on the subtree's nodes,
//!
//! ```text
//! dv/dp = ω_m × δ + s ψ̇₀,       da/dp = N dq̈/dp + α_m × δ + s ψ̈₀,
//! (Nᵀ M N) dq̈/dp = −Nᵀ (∂g/∂p + M (α_m × δ + s ψ̈₀)) − (∂N/∂p)ᵀ (g₀ + M a₀),
//! ```
//!
//! `(∂N/∂p)ᵀ h` being the moment `δ × F` on the master and `s · F` on the
//! equation of a free `ψ`, `F` the translational force of `h` on the subtree
//! (`ψ̈₀ = 0` for a driven angle, whose acceleration the scheme's `q̈` does
//! not hold). A carried body re-placed with the slave
//! ([`crate::start_shift::StartShift`]) moves rigidly, so `∂g/∂p = 0`
//! from its elements.

use nalgebra::Vector3;

use super::newmark_terms::{initial_accelerations, NewmarkTerms};
use crate::error::SolveError;
use crate::joint_parameter::JointShift;
use crate::linsolve::SparseLu;
use crate::system::ReducedSystem;

/// A joint parameter's terms at t = 0 (module docs).
pub(super) struct JointStart {
    shift: JointShift,
    /// `ω_m × δ + s ψ̇₀`.
    velocity: Vector3<f64>,
    /// `α_m × δ + s ψ̈₀`.
    acceleration: Vector3<f64>,
    /// `F`: the translational force of `g₀ + M a₀` on the subtree.
    force: Vector3<f64>,
}

impl JointStart {
    /// The terms of parameter `name` of joint `joint` for `sys` as set up
    /// at t = 0 (`lu` as scratch).
    pub(super) fn new(
        sys: &mut ReducedSystem<'_, NewmarkTerms>,
        lu: &mut SparseLu,
        joint: usize,
        name: &str,
    ) -> Result<Self, SolveError> {
        let mech = sys.mech;
        let shift = JointShift::at(mech, &sys.topo, &sys.end, joint, name)?;
        let nodes = mech.mesh.node_count();
        let mut g0 = vec![0.0; 6 * nodes];
        mech.external_forces(0.0, &mut g0);
        sys.asm
            .assemble(&mech.mesh, &sys.topo.dofs, &sys.end.config);
        for (g, f) in g0.iter_mut().zip(&sys.asm.nodal) {
            *g = f - *g;
        }
        let psi_acc = match shift.psi_eq {
            Some(eq) => {
                let terms = &sys.terms;
                let (.., q) = initial_accelerations(
                    mech,
                    &sys.topo,
                    &terms.inertia,
                    &mut sys.asm,
                    lu,
                    &sys.end,
                    &g0,
                    None,
                );
                q[eq]
            }
            None => 0.0,
        };
        let prev = &sys.terms.prev;
        let master = mech.joints[joint].master;
        let r_m = sys.end.config.rot[master];
        let (omega, alpha) = (r_m * prev.w[master], r_m * prev.ang_acc[master]);
        let rate = sys.terms.initial_rates.get(joint).copied().unwrap_or(0.0);
        let ma = sys.terms.inertia.apply_mass(&prev.acc);
        let force = (shift.nodes.iter())
            .map(|&n| Vector3::from_fn(|c, _| g0[6 * n + c] + ma[n][c]))
            .sum();
        Ok(Self {
            velocity: shift.velocity(&omega, rate),
            acceleration: alpha.cross(&shift.delta) + shift.slope * psi_acc,
            force,
            shift,
        })
    }

    /// Adds `M (α_m × δ + s ψ̈₀)` on the subtree and the moment `δ × F` on
    /// the master to the nodal `g`; returns the free angle's share `s · F`.
    pub(super) fn add_forces(
        &self,
        sys: &ReducedSystem<'_, NewmarkTerms>,
        g: &mut [f64],
    ) -> Option<(usize, f64)> {
        let nodes = sys.mech.mesh.node_count();
        let moved: Vec<Vector3<f64>> = (0..nodes)
            .map(|n| {
                if self.shift.nodes.contains(&n) {
                    self.acceleration
                } else {
                    Vector3::zeros()
                }
            })
            .collect();
        for (i, f) in sys.terms.inertia.apply_mass(&moved).iter().enumerate() {
            for c in 0..3 {
                g[6 * i + c] += f[c];
            }
        }
        self.shift.add_transfer_of(&self.force, g)
    }

    /// Adds the subtree's `dv/dp` and the fixed-`q̈` part of `da/dp` to the
    /// velocity and acceleration derivatives.
    pub(super) fn add_motion(&self, v: &mut [Vector3<f64>], a: &mut [Vector3<f64>]) {
        for &n in &self.shift.nodes {
            v[n] += self.velocity;
            a[n] += self.acceleration;
        }
    }

    /// The subtree's nodes.
    pub(super) fn nodes(&self) -> &[usize] {
        &self.shift.nodes
    }
}
