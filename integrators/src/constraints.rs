//! Joints in the solvers: the order in which slaves are placed, the reduced
//! unknowns (free nodal DOFs + released coordinates that are not driven), the
//! node maps `Tₙ` (slaves: `T_s = N [T_m; E]`, paper eqs 5–8), the exact
//! placement of every slave after an increment, and the configuration-dependent
//! part of the tangent, `∂(Nᵀ g)/∂q`.

use crate::dofs::{DofMap, NodeMap};
use crate::error::SolveError;
use crate::mechanism::Mechanism;
use crate::record::JointRecord;
use crate::step_maps::StepMaps;
use crate::threads::increment_poses;
use flexmech_core::rotation::{exp, log};
use flexmech_core::Configuration;
use flexmech_joints::{JointStep, ReleasedState, SeededStep, StepLanes, LOCAL, MAX_RELEASED};
use nalgebra::{DMatrix, Matrix3, SMatrix, SVector, Vector3, Vector6};
use smallvec::SmallVec;

/// Positions and rotations of every node and the released coordinates of
/// every joint: the complete state of a mechanism.
#[derive(Debug, PartialEq)]
pub struct MechanismState {
    /// Nodal positions and rotations.
    pub config: Configuration,
    /// Every joint's released coordinates (model order).
    pub released: Vec<ReleasedState>,
    /// Current value of every prescribed nodal DOF (same order as
    /// [`Mechanism::prescribed`]).
    pub prescribed: Vec<f64>,
}

impl Clone for MechanismState {
    fn clone(&self) -> Self {
        Self {
            config: self.config.clone(),
            released: self.released.clone(),
            prescribed: self.prescribed.clone(),
        }
    }

    /// Into the storage already there (every step's start and every retry
    /// are saved and restored this way).
    fn clone_from(&mut self, source: &Self) {
        self.config.clone_from(&source.config);
        self.released.clone_from(&source.released);
        self.prescribed.clone_from(&source.prescribed);
    }
}

/// How slaves' residuals fold into their masters'.
#[derive(Clone, Copy)]
enum Fold<'a> {
    /// Through `Nᵀ` at this state (the variational schemes and statics).
    Variation(&'a MechanismState),
    /// Through the step's `Ñᵀ`, one map per joint (the conserving schemes).
    Incremental(&'a [JointStep]),
}

/// The joint structure of a mechanism, fixed for a run.
#[derive(Debug, Clone)]
pub struct Topology {
    /// Joints in placement order: every joint after the joint (if any) whose
    /// slave is its master.
    pub order: Vec<usize>,
    /// For each node, the joint of which it is the slave.
    pub slave_of: Vec<Option<usize>>,
    /// For each joint and released coordinate, its equation (`None` if driven).
    pub released_eqs: Vec<Vec<Option<usize>>>,
    /// For each joint, its local equations: the master's, then its released ones.
    pub local_eqs: Vec<Vec<usize>>,
    /// The node maps (structure fixed; slave columns refreshed by [`Topology::refresh`]).
    pub dofs: DofMap,
}

impl Topology {
    /// Orders the joints, numbers the unknowns and builds the node maps at `state`.
    pub fn new(mech: &Mechanism, state: &MechanismState) -> Result<Self, SolveError> {
        let nodes = mech.mesh.node_count();
        let mut slave_of: Vec<Option<usize>> = vec![None; nodes];
        for (j, joint) in mech.joints.iter().enumerate() {
            if joint.slave >= nodes || joint.master >= nodes {
                return Err(SolveError::InvalidMechanism(format!(
                    "joint `{}` names a node that does not exist",
                    joint.name
                )));
            }
            if let Some(other) = slave_of[joint.slave] {
                return Err(SolveError::InvalidMechanism(format!(
                    "node {} is the slave of joints `{}` and `{}`",
                    joint.slave, mech.joints[other].name, joint.name
                )));
            }
            slave_of[joint.slave] = Some(j);
        }
        // Depth of each joint along its chain of masters; a cycle never ends.
        let mut depth = vec![0usize; mech.joints.len()];
        for (j, d) in depth.iter_mut().enumerate() {
            let mut node = mech.joints[j].master;
            while let Some(k) = slave_of[node] {
                *d += 1;
                if *d > mech.joints.len() {
                    return Err(SolveError::InvalidMechanism(format!(
                        "joint `{}` is part of a cycle of joints",
                        mech.joints[j].name
                    )));
                }
                node = mech.joints[k].master;
            }
        }
        let mut order: Vec<usize> = (0..mech.joints.len()).collect();
        order.sort_by_key(|&j| (depth[j], j));

        // Unknowns: free DOFs of independent nodes, then released coordinates.
        let mut held = mech.fixed.clone();
        for p in &mech.prescribed {
            held[p.node][p.dof] = true;
        }
        let mut n_eq = 0;
        let mut maps: Vec<NodeMap> = vec![NodeMap::default(); nodes];
        for ((map, held), slave) in maps.iter_mut().zip(&held).zip(&slave_of) {
            if slave.is_some() {
                continue;
            }
            for (d, &h) in held.iter().enumerate() {
                if !h {
                    map.eqs.push(n_eq);
                    map.cols.push(Vector6::ith(d, 1.0));
                    n_eq += 1;
                }
            }
        }
        let mut released_eqs: Vec<Vec<Option<usize>>> = Vec::with_capacity(mech.joints.len());
        for joint in &mech.joints {
            let eqs: Vec<Option<usize>> = (0..joint.map.released_count())
                .map(|c| {
                    if joint.driven.get(c).is_some_and(Option::is_some) {
                        None
                    } else {
                        n_eq += 1;
                        Some(n_eq - 1)
                    }
                })
                .collect();
            released_eqs.push(eqs);
        }
        let mut local_eqs = vec![Vec::new(); mech.joints.len()];
        for &j in &order {
            let joint = &mech.joints[j];
            let mut eqs = maps[joint.master].eqs.clone();
            eqs.extend(released_eqs[j].iter().flatten());
            maps[joint.slave].eqs = eqs.clone();
            maps[joint.slave].cols = vec![Vector6::zeros(); eqs.len()];
            maps[joint.slave].slave = true;
            local_eqs[j] = eqs;
        }
        let mut topo = Self {
            order,
            slave_of,
            released_eqs,
            local_eqs,
            dofs: DofMap::new(n_eq, maps),
        };
        topo.refresh(mech, state);
        Ok(topo)
    }

    /// Recomputes the slaves' node maps `T_s = N [T_m; E]` at `state`.
    pub fn refresh(&mut self, mech: &Mechanism, state: &MechanismState) {
        for &j in &self.order {
            let joint = &mech.joints[j];
            let m = joint.master;
            let n =
                joint
                    .map
                    .variation(&state.config.x[m], &state.config.rot[m], &state.released[j]);
            let nm = n.fixed_columns::<6>(0).into_owned();
            // The slave's own vector, refilled (no allocation per iteration).
            let mut cols = std::mem::take(&mut self.dofs.nodes[joint.slave].cols);
            cols.clear();
            cols.extend(self.dofs.nodes[m].cols.iter().map(|c| nm * c));
            for (c, eq) in self.released_eqs[j].iter().enumerate() {
                if eq.is_some() {
                    cols.push(n.column(6 + c).into_owned());
                }
            }
            self.dofs.nodes[joint.slave].cols = cols;
        }
    }

    /// Sets every slave's rows to those of its joint's incremental map `Ñ`
    /// of the step (`steps[j]`, [`StepMaps`]; `R_s = Ñ [R_m; E]`, masters
    /// first), so that the assembled tangent's rows are those of the
    /// conserving schemes' reduced residual `Ñᵀ g`
    /// ([`Topology::reduce_incremental`]).
    pub fn refresh_rows(&mut self, mech: &Mechanism, steps: &[JointStep]) {
        for &j in &self.order {
            let joint = &mech.joints[j];
            let n = steps[j].matrix();
            let nm = n.fixed_columns::<6>(0).into_owned();
            // The slave's own vector, refilled (no allocation per iteration).
            let mut rows = self.dofs.nodes[joint.slave].rows.take().unwrap_or_default();
            rows.clear();
            rows.extend(self.dofs.nodes[joint.master].rows().iter().map(|r| nm * r));
            for (c, eq) in self.released_eqs[j].iter().enumerate() {
                if eq.is_some() {
                    rows.push(n.column(6 + c).into_owned());
                }
            }
            self.dofs.nodes[joint.slave].rows = Some(rows);
        }
    }

    /// The lanes along which each joint's step map is differentiated for the
    /// conserving schemes' tangent ([`StepLanes`]): those of the columns
    /// [`Self::incremental_blocks`] keeps — the master's spin where a column
    /// of the master's map turns it (not for the ground or a node whose
    /// rotation is held), the released coordinates up to the last with an
    /// equation (a driven one has none).
    pub fn step_lanes(&self, mech: &Mechanism) -> Vec<StepLanes> {
        (0..mech.joints.len())
            .map(|j| {
                let master = &self.dofs.nodes[mech.joints[j].master];
                let spin = master
                    .cols
                    .iter()
                    .any(|c| c.fixed_rows::<3>(3).iter().any(|&v| v != 0.0));
                let eqs = &self.released_eqs[j];
                let released = eqs.iter().rposition(Option::is_some).map_or(0, |c| c + 1);
                StepLanes { spin, released }
            })
            .collect()
    }

    /// The local-to-global map of joint `j`, one entry per column (following
    /// `local_eqs[j]`): the master's node map (its rows when `rows`, else
    /// its columns) in local rows 0..6, then the released coordinates, each
    /// the unit vector of its local row `6 + c`.
    fn local_map<'a>(&'a self, mech: &Mechanism, j: usize, rows: bool) -> LocalMap<'a> {
        let master = &self.dofs.nodes[mech.joints[j].master];
        let map = if rows {
            master.rows()
        } else {
            &master.cols[..]
        };
        let released = self.released_eqs[j].iter().enumerate();
        map.iter()
            .map(LocalColumn::Node)
            .chain(
                released
                    .filter(|(_, eq)| eq.is_some())
                    .map(|(c, _)| LocalColumn::Released(6 + c)),
            )
            .collect()
    }

    /// The joints' contribution to the reduced tangent, `Σ_j L_jᵀ ∂(N_jᵀ g_s)/∂q L_j`,
    /// for nodal residuals `g` (internal − external, 6 per node). Slaves deepest
    /// in a chain go first and hand `N_{s,m}ᵀ g_s` to their master, whose own
    /// joint then carries it on. Returns one dense block per joint, over
    /// `local_eqs[j]`.
    pub fn geometric_blocks(
        &self,
        mech: &Mechanism,
        state: &MechanismState,
        g: &[f64],
    ) -> Vec<DMatrix<f64>> {
        self.joint_blocks(mech, g, false, |j, m, gs| {
            mech.joints[j].map.transfer(
                &state.config.x[m],
                &state.config.rot[m],
                &state.released[j],
                gs,
            )
        })
    }

    /// The joints' contribution to the conserving schemes' exact tangent,
    /// `Σ_j L_j,rowᵀ ∂(Ñ_jᵀ g_s)/∂q L_j,col` with the slaves' residuals held
    /// (deepest slaves first, each handing `Ñᵀ g_s` to its master, as
    /// [`Topology::reduce_incremental`] does): `Ñ` follows the step's end
    /// state (the seeded maps `seeded[j]` of [`StepMaps`] along the lanes of
    /// [`Self::step_lanes`], [`SeededStep::transfer`]); rows through the masters' rows,
    /// columns through their columns.
    pub fn incremental_blocks(
        &self,
        mech: &Mechanism,
        seeded: &[SeededStep],
        g: &[f64],
    ) -> Vec<DMatrix<f64>> {
        self.joint_blocks(mech, g, true, |j, _, gs| {
            seeded[j].transfer(gs, mech.joints[j].map.released_count())
        })
    }

    /// One dense block per joint from `transfer(j, master, g_s) = (Pᵀ g_s,
    /// ∂(Pᵀ g_s)/∂local)` of its slave's accumulated residual, deepest slaves
    /// first (each hands `Pᵀ g_s` to its master); rows through the masters'
    /// rows when `rows`, else their columns.
    fn joint_blocks(
        &self,
        mech: &Mechanism,
        g: &[f64],
        rows: bool,
        transfer: impl Fn(
            usize,
            usize,
            &Vector6<f64>,
        ) -> (SVector<f64, LOCAL>, SMatrix<f64, LOCAL, LOCAL>),
    ) -> Vec<DMatrix<f64>> {
        let mut acc = g.to_vec();
        let mut blocks = vec![DMatrix::zeros(0, 0); mech.joints.len()];
        for &j in self.order.iter().rev() {
            let (m, s) = (mech.joints[j].master, mech.joints[j].slave);
            let gs = Vector6::from_column_slice(&acc[6 * s..6 * s + 6]);
            let (t, h) = transfer(j, m, &gs);
            for d in 0..6 {
                acc[6 * m + d] += t[d];
            }
            let (lr, lc) = (
                self.local_map(mech, j, rows),
                self.local_map(mech, j, false),
            );
            blocks[j] = triple_product(&lr, &h, &lc);
        }
        blocks
    }

    /// The reduced residual of the conserving schemes, `Ñᵀ g` (paper eqs
    /// 21–23): every slave's nodal residual goes to its master and its
    /// released equations through the exact incremental map of the step
    /// (`steps[j]`, [`StepMaps`]), deepest slaves first; independent nodes
    /// reduce as usual. With these equations `Σ pᵢ·gᵢ = 0` over all nodes, so
    /// the beams' energy balance and momentum conservation hold for the
    /// joined system.
    pub fn reduce_incremental(
        &self,
        mech: &Mechanism,
        steps: &[JointStep],
        g: &[f64],
        out: &mut [f64],
    ) {
        out.iter_mut().for_each(|v| *v = 0.0);
        let acc = self.fold_slaves(mech, Fold::Incremental(steps), g, |j, _, t| {
            for (c, eq) in self.released_eqs[j].iter().enumerate() {
                if let Some(e) = eq {
                    out[*e] += t[6 + c];
                }
            }
        });
        self.dofs
            .add_reduced_except(&acc, out, |n| self.slave_of[n].is_some());
    }

    /// The derivative of the conserving schemes' reduced residual `Σ Ñᵀ g`
    /// along the step's start state with `g` held (exact sensitivities):
    /// for each joint, `∂(Ñⱼᵀ g_s)/∂start · d` of its accumulated slave
    /// residual `g_s`, with the master's start pose moved by `d`'s
    /// `(dx, θ)` of that node (`x ← x + dx`, `R ← exp(θ̂)R`) and the released
    /// start state by `released[j]`. The master part is added to the nodal
    /// `out` at the master (to be folded and reduced with the rest), the
    /// released part returned as `(equation, value)`. `Err(j)`: joint `j`'s
    /// kind does not provide the derivative.
    #[allow(clippy::too_many_arguments)]
    pub fn incremental_start_terms(
        &self,
        mech: &Mechanism,
        (start, end): (&MechanismState, &MechanismState),
        g: &[f64],
        (dx, theta): (&[Vector3<f64>], &[Vector3<f64>]),
        released: &[[f64; flexmech_joints::MAX_RELEASED]],
        out: &mut [f64],
    ) -> Result<Vec<(usize, f64)>, usize> {
        let mut extra = Vec::new();
        let mut missing = None;
        let maps = StepMaps::new(mech, start, end, None);
        self.fold_slaves(mech, Fold::Incremental(&maps.values), g, |j, gs, _| {
            let m = mech.joints[j].master;
            let from = [
                dx[m].x, dx[m].y, dx[m].z, theta[m].x, theta[m].y, theta[m].z,
            ];
            let t = mech.joints[j].map.incremental_transfer_start(
                [
                    (&start.config.x[m], &start.config.rot[m]),
                    (&end.config.x[m], &end.config.rot[m]),
                ],
                [&start.released[j], &end.released[j]],
                gs,
                (&from, &released[j]),
            );
            let Some(t) = t else {
                missing = Some(j);
                return;
            };
            for c in 0..6 {
                out[6 * m + c] += t[c];
            }
            for (c, eq) in self.released_eqs[j].iter().enumerate() {
                if let Some(e) = eq {
                    extra.push((*e, t[6 + c]));
                }
            }
        });
        match missing {
            Some(j) => Err(j),
            None => Ok(extra),
        }
    }

    /// Folds every slave's nodal residual into its master's, deepest slaves
    /// first — through `Nᵀ` at a state, or through the step's `Ñᵀ` (the
    /// conserving schemes) — calling `each(j, g_s, t)` with joint `j`'s slave
    /// residual `g_s` (its own slaves' already folded in) and its transfer
    /// `t` (master part, then released). Returns the nodal residuals with
    /// every slave's carried by the independent nodes.
    fn fold_slaves(
        &self,
        mech: &Mechanism,
        fold: Fold<'_>,
        g: &[f64],
        mut each: impl FnMut(usize, &Vector6<f64>, &SVector<f64, LOCAL>),
    ) -> Vec<f64> {
        let mut acc = g.to_vec();
        for &j in self.order.iter().rev() {
            let joint = &mech.joints[j];
            let (m, s) = (joint.master, joint.slave);
            let gs = Vector6::from_column_slice(&acc[6 * s..6 * s + 6]);
            let t = match fold {
                Fold::Incremental(steps) => steps[j].transfer(&gs),
                Fold::Variation(end) => {
                    joint
                        .map
                        .variation(&end.config.x[m], &end.config.rot[m], &end.released[j])
                        .transpose()
                        * gs
                }
            };
            for d in 0..6 {
                acc[6 * m + d] += t[d];
            }
            each(j, &gs, &t);
        }
        acc
    }

    /// The reactions of a converged step with nodal residuals `g` (internal
    /// and inertial minus external forces, 6 per node): what every joint
    /// exerts on its slave node (force, then moment, global components; the
    /// slave's residual with its own slaves' folded in) and what holds every
    /// node of [`Mechanism::supported_nodes`] (the folded residual at its
    /// fixed and prescribed DOFs, zero at its free ones). Slaves fold into
    /// masters as the scheme reduces (`start` given: through `Ñᵀ`).
    pub fn reactions(
        &self,
        mech: &Mechanism,
        start: Option<&MechanismState>,
        end: &MechanismState,
        g: &[f64],
    ) -> (Vec<[f64; 6]>, Vec<[f64; 6]>) {
        let mut joints = vec![[0.0; 6]; mech.joints.len()];
        let maps = start.map(|start| StepMaps::new(mech, start, end, None));
        let fold = match &maps {
            Some(maps) => Fold::Incremental(&maps.values),
            None => Fold::Variation(end),
        };
        let acc = self.fold_slaves(mech, fold, g, |j, gs, _| {
            joints[j].copy_from_slice(gs.as_slice());
        });
        let supports = mech
            .supported_nodes()
            .into_iter()
            .map(|n| {
                let mut held = mech.fixed[n];
                for p in mech.prescribed.iter().filter(|p| p.node == n) {
                    held[p.dof] = true;
                }
                std::array::from_fn(|d| if held[d] { acc[6 * n + d] } else { 0.0 })
            })
            .collect();
        (joints, supports)
    }

    /// The generalised reactions of the drivers for nodal residuals `g`
    /// (through `Nᵀ`, deepest slaves first): for every joint, one value per
    /// released coordinate (meaningful for the driven ones), and for every
    /// prescribed nodal DOF the residual component it carries. Their products
    /// with the drivers' increments are the drivers' work.
    pub fn driver_reactions(
        &self,
        mech: &Mechanism,
        state: &MechanismState,
        g: &[f64],
    ) -> (Vec<Vec<f64>>, Vec<f64>) {
        let mut joints = vec![Vec::new(); mech.joints.len()];
        let acc = self.fold_slaves(mech, Fold::Variation(state), g, |j, _, t| {
            joints[j] = (0..mech.joints[j].map.released_count())
                .map(|c| t[6 + c])
                .collect();
        });
        let prescribed = mech
            .prescribed
            .iter()
            .map(|p| acc[6 * p.node + p.dof])
            .collect();
        (joints, prescribed)
    }

    /// Applies a Newton increment: independent nodes, then released
    /// coordinates and the exact placement of every slave.
    pub fn apply(&self, mech: &Mechanism, state: &mut MechanismState, dq: &[f64]) {
        // Each node on its own: on two threads for a large mesh, the same
        // numbers either way.
        let config = &mut state.config;
        increment_poses(&mut config.x, &mut config.rot, |n| {
            let p = self.dofs.node_increment(n, dq);
            (self.slave_of[n].is_none() && p != Vector6::zeros()).then(|| {
                (
                    p.fixed_rows::<3>(0).into_owned(),
                    p.fixed_rows::<3>(3).into_owned(),
                )
            })
        });
        for &j in &self.order {
            let eqs = &self.released_eqs[j];
            let mut delta = [0.0; MAX_RELEASED];
            for (d, eq) in delta.iter_mut().zip(eqs) {
                *d = eq.map_or(0.0, |e| dq[e]);
            }
            let delta = &delta[..eqs.len()];
            if delta.iter().any(|&d| d != 0.0) {
                mech.joints[j].map.advance(&mut state.released[j], delta);
            }
        }
        self.place_slaves(mech, state);
    }

    /// Places every slave exactly by relation (1), masters first.
    pub fn place_slaves(&self, mech: &Mechanism, state: &mut MechanismState) {
        for &j in &self.order {
            let joint = &mech.joints[j];
            let (x, r) = joint.map.slave(
                &state.config.x[joint.master],
                &state.config.rot[joint.master],
                &state.released[j],
            );
            state.config.x[joint.slave] = x;
            state.config.rot[joint.slave] = r;
        }
    }

    /// Secant predictor: moves `state` on by `ratio` times the change from
    /// `previous` to `state`, and places the slaves. Each node continues its
    /// own screw motion: the rotation along the geodesic,
    /// `R ← exp(r·φ̂) R` with `φ = log(R Rₚᵀ)`, and the displacement increment
    /// turned with it, `Δx ← sin(rα/2)/sin(α/2) · exp(½(1+r)φ̂) Δx`
    /// (`α = |φ|`) — exact for a rigid rotation about any axis, so the motion
    /// downstream of a driven joint is predicted without chord errors.
    /// Released coordinates are extrapolated linearly.
    pub fn extrapolate(
        &self,
        mech: &Mechanism,
        state: &mut MechanismState,
        previous: &MechanismState,
        ratio: f64,
    ) {
        for n in 0..state.config.x.len() {
            if self.slave_of[n].is_none() {
                let phi = log(&(state.config.rot[n] * previous.config.rot[n].transpose()));
                let alpha = phi.norm();
                let factor = if alpha < 1e-8 {
                    ratio
                } else {
                    (0.5 * ratio * alpha).sin() / (0.5 * alpha).sin()
                };
                let u = exp(&(phi * (0.5 * (1.0 + ratio))))
                    * (state.config.x[n] - previous.config.x[n])
                    * factor;
                state.config.increment(n, &u, &(phi * ratio));
            }
        }
        // The prescribed values move with the nodes they belong to, so that
        // imposing the new values adds only what the prediction missed.
        for (now, before) in state.prescribed.iter_mut().zip(&previous.prescribed) {
            *now += (*now - before) * ratio;
        }
        for (j, joint) in mech.joints.iter().enumerate() {
            let k = joint.map.released_count();
            let (now, before) = (state.released[j], previous.released[j]);
            let mut delta = [0.0; MAX_RELEASED];
            for (c, d) in delta.iter_mut().enumerate().take(k) {
                *d = (now.q[c] - before.q[c]) * ratio;
            }
            let mut delta = &delta[..k];
            let spin;
            if now.rot != before.rot {
                // A multiplicative released rotation (spherical): the spin between the two.
                let w = log(&(now.rot * before.rot.transpose())) * ratio;
                spin = [w.x, w.y, w.z];
                delta = &spin;
            }
            joint.map.advance(&mut state.released[j], delta);
        }
        self.place_slaves(mech, state);
    }

    /// Moves driven coordinates and prescribed nodal DOFs to their values at
    /// time `t` and re-places the slaves. A prescribed rotation DOF `d` turns
    /// the node about the global axis `d` by the change of its value.
    pub fn impose(&self, mech: &Mechanism, state: &mut MechanismState, t: f64) {
        for (k, p) in mech.prescribed.iter().enumerate() {
            let v = p.value.at(t);
            if p.dof < 3 {
                state.config.x[p.node][p.dof] = mech.mesh.positions[p.node][p.dof] + v;
            } else {
                let dv = v - state.prescribed[k];
                if dv != 0.0 {
                    let axis = Vector3::ith(p.dof - 3, dv);
                    state.config.increment(p.node, &Vector3::zeros(), &axis);
                }
            }
            state.prescribed[k] = v;
        }
        for (j, joint) in mech.joints.iter().enumerate() {
            let mut delta = [0.0; MAX_RELEASED];
            let mut any = false;
            for (c, d) in joint.driven.iter().enumerate() {
                if let Some(s) = d {
                    delta[c] = s.at(t) - state.released[j].q[c];
                    any |= delta[c] != 0.0;
                }
            }
            if any {
                let k = joint.map.released_count();
                joint.map.advance(&mut state.released[j], &delta[..k]);
            }
        }
        self.place_slaves(mech, state);
    }
}

/// The initial state: nodes as meshed, joints at their initial coordinates,
/// prescribed values at their `t = 0` values (not yet imposed).
pub fn initial_state(mech: &Mechanism) -> MechanismState {
    MechanismState {
        config: Configuration::initial(&mech.mesh.positions),
        released: mech.joints.iter().map(|j| j.initial).collect(),
        prescribed: vec![0.0; mech.prescribed.len()],
    }
}

/// Joint outputs: released angle and translation, and the constraint error
/// `‖r_s − r_m − Λ_m r_R‖ + ‖Λ_mᵀΛ_s − Λ_R‖_F` of relation (1).
pub fn joint_records(mech: &Mechanism, state: &MechanismState) -> Vec<JointRecord> {
    mech.joints
        .iter()
        .enumerate()
        .map(|(j, joint)| {
            let (m, s) = (joint.master, joint.slave);
            let (rr, lr) = joint.map.released_placement(&state.released[j]);
            let c = &state.config;
            let pos = (c.x[s] - c.x[m] - c.rot[m] * rr).norm();
            let rot: Matrix3<f64> = c.rot[m].transpose() * c.rot[s] - lr;
            JointRecord {
                reaction: [f64::NAN; 6],
                angle: joint
                    .map
                    .reported_angle(&state.released[j])
                    .unwrap_or(f64::NAN),
                released_translation: [rr.x, rr.y, rr.z],
                constraint_error: pos + rot.norm(),
            }
        })
        .collect()
}

/// A joint's local-to-global map ([`Topology::local_map`]): on the stack
/// for a master with up to six columns.
type LocalMap<'a> = SmallVec<[LocalColumn<'a>; LOCAL]>;

/// One column of a joint's local-to-global map ([`Topology::local_map`]).
#[derive(Debug, Clone, Copy)]
enum LocalColumn<'a> {
    /// A column of the master's node map, in local rows 0..6.
    Node(&'a Vector6<f64>),
    /// The unit vector of one local row (a released coordinate's).
    Released(usize),
}

impl LocalColumn<'_> {
    /// `h · self` for a local `h` (`LOCAL` rows and columns).
    fn times(&self, h: &SMatrix<f64, LOCAL, LOCAL>) -> SVector<f64, LOCAL> {
        match *self {
            LocalColumn::Node(col) => h.fixed_columns::<6>(0) * col,
            LocalColumn::Released(r) => h.column(r).into_owned(),
        }
    }

    /// `selfᵀ · v` for a local `v`.
    fn dot(&self, v: &SVector<f64, LOCAL>) -> f64 {
        match *self {
            LocalColumn::Node(col) => col.dot(&v.fixed_rows::<6>(0)),
            LocalColumn::Released(r) => v[r],
        }
    }
}

/// `Lᵣᵀ h L_c` of a joint's local block `h` through its maps (dense, as
/// many rows as `lr` and columns as `lc`): each column of `h L_c` once, then
/// its dot products — a few hundred flops, where general matrix products
/// cost their packing and dispatch.
fn triple_product(
    lr: &[LocalColumn<'_>],
    h: &SMatrix<f64, LOCAL, LOCAL>,
    lc: &[LocalColumn<'_>],
) -> DMatrix<f64> {
    let mut out = DMatrix::zeros(lr.len(), lc.len());
    for (b, col) in lc.iter().enumerate() {
        let hc = col.times(h);
        for (a, row) in lr.iter().enumerate() {
            out[(a, b)] = row.dot(&hc);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_joint_block_product_equals_the_dense_one() {
        let h = SMatrix::<f64, LOCAL, LOCAL>::from_fn(|r, c| ((r * 7 + c * 3) % 13) as f64 - 6.0);
        let (c1, c2) = (
            Vector6::new(1.0, 0.0, -2.0, 0.5, 0.0, 3.0),
            Vector6::new(0.0, 1.5, 0.0, 0.0, -1.0, 0.0),
        );
        let dense = |cols: &[LocalColumn<'_>]| {
            DMatrix::from_fn(LOCAL, cols.len(), |r, k| match cols[k] {
                LocalColumn::Node(v) if r < 6 => v[r],
                LocalColumn::Released(row) if r == row => 1.0,
                _ => 0.0,
            })
        };
        let lr = [LocalColumn::Node(&c1), LocalColumn::Released(6)];
        let lc = [
            LocalColumn::Node(&c2),
            LocalColumn::Node(&c1),
            LocalColumn::Released(LOCAL - 1),
        ];
        let hd = DMatrix::from_column_slice(LOCAL, LOCAL, h.as_slice());
        let expected = dense(&lr).transpose() * hd * dense(&lc);
        assert!((triple_product(&lr, &h, &lc) - expected).amax() < 1e-12);
    }
}
