//! How a parameter moves the initial positions: `dX/dp` per node, for
//! exact sensitivities whose model places its nodes differently as the
//! parameter changes — a joint's value that moves its slave at t = 0 (the
//! body the joint carries moves rigidly with it,
//! [`crate::joint_parameter`]) or a beam's end coordinate (its nodes move
//! along their places on the beam). The nodes' positions then start at
//! `dx₀/dp = dX/dp`, and the reported displacements are `dx/dp − dX/dp`.

use nalgebra::Vector3;

use crate::constraints::{MechanismState, Topology};
use crate::error::SolveError;
use crate::joint_parameter::{add_moved_stiffness, carried_body, JointShift, START_SHIFT};
use crate::mechanism::Mechanism;

/// The initial positions' `dX/dp`, node by node (none listed: none moves).
#[derive(Debug, Clone, Default)]
pub(crate) struct StartShift {
    shifts: Vec<(usize, Vector3<f64>)>,
}

impl StartShift {
    /// The moved nodes and their `dX/dp`.
    pub(crate) fn of_nodes(shifts: Vec<(usize, Vector3<f64>)>) -> Self {
        Self { shifts }
    }

    /// The re-placement by parameter `name` of joint `joint` at the initial
    /// `state`: the body the joint carries moves by `δ₀ = R_m ∂f/∂p(ψ₀)`;
    /// refused where that body is held otherwise.
    pub(crate) fn for_joint(
        mech: &Mechanism,
        topo: &Topology,
        state: &MechanismState,
        joint: usize,
        name: &str,
    ) -> Result<Self, SolveError> {
        let shift = JointShift::at(mech, topo, state, joint, name)?;
        if shift.delta.norm() <= START_SHIFT * mech.size_at(&mech.mesh.positions).max(1.0) {
            return Ok(Self::default());
        }
        let body = carried_body(mech, joint, name)?;
        Ok(Self::of_nodes(
            body.into_iter().map(|n| (n, shift.delta)).collect(),
        ))
    }

    /// `dX/dp` of node `n`'s initial position.
    pub(crate) fn of(&self, n: usize) -> Vector3<f64> {
        (self.shifts.iter())
            .find(|(m, _)| *m == n)
            .map_or(Vector3::zeros(), |(_, d)| *d)
    }

    /// The displacements' derivatives `dx/dp − dX/dp` from the positions'
    /// `dx/dp`, node by node.
    pub(crate) fn displacements(&self, dx: &[Vector3<f64>]) -> Vec<[f64; 3]> {
        (dx.iter().enumerate())
            .map(|(n, d)| {
                let d = d - self.of(n);
                [d.x, d.y, d.z]
            })
            .collect()
    }

    /// The moved nodes and their `dX/dp`.
    pub(crate) fn shifts(&self) -> &[(usize, Vector3<f64>)] {
        &self.shifts
    }

    /// The moved nodes.
    pub(crate) fn nodes(&self) -> impl Iterator<Item = usize> + '_ {
        self.shifts.iter().map(|(n, _)| *n)
    }

    /// Adds `∂g/∂x · dX/dp` of the elements at `config` and, with
    /// `inertia = (M, c)`, `c M dX/dp` to the nodal `g` (the held nodes'
    /// motion as the free equations see it).
    pub(crate) fn add_stiffness(
        &self,
        mech: &Mechanism,
        config: &flexmech_core::Configuration,
        inertia: Option<(&flexmech_core::Inertia, f64)>,
        g: &mut [f64],
    ) {
        if self.shifts.is_empty() {
            return;
        }
        let tangent = |e: &flexmech_core::Element, r: &mut [f64], k: &mut [f64]| {
            e.residual_tangent(&config.x, &config.rot, r, k)
        };
        add_moved_stiffness(mech, tangent, inertia, &self.shifts, g);
    }

    /// `Σ f·dX/dp` over the moved nodes' translations of the nodal `f`.
    pub(crate) fn work(&self, f: &[f64]) -> f64 {
        (self.shifts.iter())
            .map(|(n, d)| Vector3::new(f[6 * n], f[6 * n + 1], f[6 * n + 2]).dot(d))
            .sum()
    }
}
