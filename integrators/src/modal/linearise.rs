//! The linearisation of a mechanism at a state: its reduced tangent and mass
//! in the minimum coordinates of the master–slave method (no constraint
//! rows), and the expansion of a reduced vector to every node.

use super::pencil::Pattern;
use crate::constraints::MechanismState;
use crate::error::SolveError;
use crate::mechanism::Mechanism;
use crate::statics::{static_system, StaticTerms};
use crate::system::ReducedSystem;
use flexmech_core::MassKind;
use nalgebra::Vector3;

/// A mode expanded to the nodes: displacements, spatial rotation vectors
/// (both per node) and each joint's released coordinates.
pub(crate) type Expanded = (Vec<Vector3<f64>>, Vec<Vector3<f64>>, Vec<Vec<f64>>);

/// The reduced system of a mechanism at a state, with its pattern.
pub(crate) struct Linearisation<'m> {
    sys: ReducedSystem<'m, StaticTerms>,
    pub pattern: Pattern,
}

impl<'m> Linearisation<'m> {
    /// The system of `mech` at `state`, with the loads at `load_time` (the
    /// load factor of a static state, the time of a stored dynamic one;
    /// `None`: no loads).
    pub fn at(
        mech: &'m Mechanism,
        state: &MechanismState,
        load_time: Option<f64>,
    ) -> Result<Self, SolveError> {
        let (mut sys, _, _) = static_system(mech)?;
        sys.start.clone_from(state);
        sys.end.clone_from(state);
        if let Some(t) = load_time {
            mech.external_forces(t, &mut sys.fext);
            sys.load_time = t;
        }
        let pattern = Pattern::new(sys.asm.pattern().clone()).map_err(SolveError::Singular)?;
        Ok(Self { sys, pattern })
    }

    /// The reduced external loads `Nᵀ f` at `load_time`.
    pub fn reduced_load(&self, load_time: f64) -> Vec<f64> {
        let mech = self.sys.mech;
        let mut f = vec![0.0; 6 * mech.mesh.node_count()];
        mech.external_forces(load_time, &mut f);
        let mut out = vec![0.0; self.unknowns()];
        self.sys.topo.dofs.reduce(&f, &mut out);
        out
    }

    /// Unknowns of the reduced system.
    pub fn unknowns(&self) -> usize {
        self.pattern.n()
    }

    /// The exact reduced tangent `∂(Nᵀg)/∂q` at the state (elements, the
    /// joints' configuration-dependent blocks with the slaves' residuals,
    /// follower loads' stiffness) as compressed-column values.
    pub fn tangent(&mut self) -> Vec<f64> {
        let mut r = vec![0.0; self.unknowns()];
        self.sys.evaluate_with(&mut r, true);
        self.sys.asm.values.clone()
    }

    /// The reduced mass `NᵀMN` at the state (`kind` of translational mass,
    /// rigid bodies; rotational inertia `R J₀ Rᵀ` for spatial spins), as
    /// in the initial accelerations of dynamics.
    pub fn mass(&mut self, kind: MassKind) -> Vec<f64> {
        let mech = self.sys.mech;
        let inertia = mech.inertia(kind);
        let (asm, topo) = (&mut self.sys.asm, &self.sys.topo);
        asm.values.iter_mut().for_each(|v| *v = 0.0);
        asm.add_mass(&topo.dofs, &inertia, &self.sys.end.config.rot);
        asm.values.clone()
    }

    /// The gyroscopic matrix of the mechanism's spin at the state (zero
    /// without a spin; see [`crate::frame_spin`]).
    pub fn gyroscopic(&mut self) -> Vec<f64> {
        self.sys.asm.values.iter_mut().for_each(|v| *v = 0.0);
        self.sys.add_gyroscopic();
        self.sys.asm.values.clone()
    }

    /// The spin axis of the mechanism, if it spins.
    pub fn spin_axis(&self) -> Option<Vector3<f64>> {
        self.sys.mech.spin.as_ref().map(|s| s.axis)
    }

    /// The nodal displacements and spatial rotation vectors (`N q` at every
    /// node) and the joints' released coordinates (zero where driven) of
    /// the reduced vector `q`.
    pub fn expand(&self, q: &[f64]) -> Expanded {
        let topo = &self.sys.topo;
        let nodes = self.sys.mech.mesh.node_count();
        let (mut u, mut theta) = (Vec::with_capacity(nodes), Vec::with_capacity(nodes));
        for i in 0..nodes {
            let p = topo.dofs.node_increment(i, q);
            u.push(p.fixed_rows::<3>(0).into_owned());
            theta.push(p.fixed_rows::<3>(3).into_owned());
        }
        let released = topo
            .released_eqs
            .iter()
            .map(|eqs| eqs.iter().map(|e| e.map_or(0.0, |e| q[e])).collect())
            .collect();
        (u, theta, released)
    }
}
