//! The reduced system every solver hands to Newton (FORMULATION §3–4): one
//! evaluation for statics, Newmark and the midpoint schemes.
//!
//! At the iterate `qₙ₊₁` (the end state, slaves placed exactly):
//!
//! 1. refresh the slaves' node maps `T_s = N [T_m; E]` (and, for the
//!    conserving schemes, their rows through the incremental map `Ñ`);
//! 2. the element forces of the scheme (and their tangents) — internal minus
//!    external gives the nodal residual `g`;
//! 3. the scheme's inertial forces (and their tangent blocks) are added to `g`;
//! 4. the reduction through `N` (`Tᵀ g`, statics and Newmark) or `Ñ`
//!    (`Ñᵀ g`, the conserving schemes, paper eqs 21–23);
//! 5. the joints' configuration-dependent tangent blocks `∂(Nᵀ g)/∂q`
//!    (or `∂(Ñᵀ g)/∂q`) with the slaves' full residuals;
//! 6. the force scale: the larger of the reduced external loads and the
//!    reduced magnitudes of the forces that cancel in `g`.
//!
//! A scheme supplies only steps 2 and 3 and the choice in step 4
//! ([`StepTerms`]); the rest is here, once.

use crate::assembly::Assembler;
use crate::constraints::{MechanismState, Topology};
use crate::dofs::DofMap;
use crate::frame_spin::FrameSpin;
use crate::free_motion::FreeMotion;
use crate::linsolve::TangentRef;
use crate::mechanism::Mechanism;
use crate::newton::NewtonSystem;
use crate::record::StepRecord;
use crate::step_maps::StepMaps;
use flexmech_core::rotation::skew;
use flexmech_core::{Configuration, Inertia};

/// How the joints reduce the nodal residuals to the unknowns.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reduction {
    /// Through the variation map `N` at the iterate (paper eqs 5–8): statics
    /// and Newmark.
    Variation,
    /// Through the exact incremental map `Ñ` of the step (paper eqs 21–23):
    /// the conserving schemes.
    Incremental,
}

/// A step's start and end configurations.
pub type Ends<'a> = (&'a Configuration, &'a Configuration);

/// What a scheme contributes to the reduced system at an iterate.
pub trait StepTerms {
    /// How the joints reduce this scheme's residual.
    fn reduction(&self) -> Reduction;

    /// Evaluates the scheme's element forces between `start` and `end` into
    /// `asm` ([`Assembler::nodal`], [`Assembler::nodal_abs`]) and, if
    /// `tangent`, their reduced tangents into [`Assembler::values`].
    /// Default: the beams' internal forces at `end` (the exact gradient of
    /// the strain energy, statics and Newmark).
    fn elements(
        &self,
        mech: &Mechanism,
        dofs: &DofMap,
        asm: &mut Assembler,
        _start: &Configuration,
        end: &Configuration,
        tangent: bool,
    ) {
        if tangent {
            asm.assemble(&mech.mesh, dofs, end);
        } else {
            asm.assemble_residual(&mech.mesh, end);
        }
    }

    /// Whether the scheme's [`Self::element_tangents`] leave the elements'
    /// forces out, so that a tangent at an iterate whose residual was just
    /// evaluated is computed alone
    /// ([`NewtonSystem::update_tangent_at_residual`]: the residual's nodal
    /// forces are kept for the joints' blocks). Default: `false`, a whole
    /// evaluation with the tangent.
    fn tangents_alone(&self) -> bool {
        false
    }

    /// [`Self::elements`] with the tangent where only the tangent is wanted
    /// (the forces at this iterate were evaluated just before and are
    /// kept, [`Self::tangents_alone`]): a scheme may leave its forces out of
    /// `asm`. Default: the whole [`Self::elements`].
    fn element_tangents(&self, mech: &Mechanism, dofs: &DofMap, asm: &mut Assembler, ends: Ends) {
        self.elements(mech, dofs, asm, ends.0, ends.1, true);
    }

    /// Adds the scheme's inertial forces at `end` to the nodal residual `g`
    /// and their magnitudes to `abs`; with `tangent`, their tangent blocks
    /// to the assembler. Default: none (statics).
    fn inertia(
        &self,
        _start: &Configuration,
        _end: &Configuration,
        _g: &mut [f64],
        _abs: &mut [f64],
        _tangent: Option<(&mut Assembler, &DofMap)>,
    ) {
    }

    /// What the tangent's form depends on besides the iterate (the step
    /// size of a dynamic step; see [`NewtonSystem::tangent_key`]).
    fn tangent_key(&self) -> f64 {
        f64::NAN
    }

    /// See [`NewtonSystem::tangent_is_exact`]. Default: `true`.
    fn tangent_is_exact(&self) -> bool {
        true
    }

    /// See [`NewtonSystem::set_exact_tangent`]. Default: nothing to switch.
    fn set_exact_tangent(&mut self, _exact: bool) {}

    /// See [`NewtonSystem::closes_converged`]. Default: `false`.
    fn closes_converged(&self) -> bool {
        false
    }

    /// Whether the scheme conserves energy, so that its drivers' work
    /// balances the energy exactly (see
    /// [`NewtonSystem::evaluates_closing`]). Default: `false`.
    fn conserves_energy(&self) -> bool {
        false
    }
}

/// The reduced system of one step: the mechanism's structure and the
/// workspace of its evaluation (kept for the whole run: no allocation per
/// step or iteration), the step's start state and the iterate at its end,
/// and the scheme's terms.
pub struct ReducedSystem<'m, T> {
    /// The mechanism.
    pub mech: &'m Mechanism,
    /// Unknowns and node maps (refreshed at the iterate).
    pub topo: Topology,
    /// Element assembly and the tangent values.
    pub asm: Assembler,
    /// The state at the start of the step.
    pub start: MechanismState,
    /// The current iterate of the state at the end of the step.
    pub end: MechanismState,
    /// External nodal forces of the step (6 per node).
    pub fext: Vec<f64>,
    /// The time at which the step takes its loads (`fext` and the follower
    /// loads; statics: the load factor).
    pub load_time: f64,
    /// Nodal residuals `g` (internal + inertial − external) at the last
    /// evaluation.
    pub nodal: Vec<f64>,
    abs: Vec<f64>,
    scratch: Vec<f64>,
    /// Absolute residual norm below which the residual is round-off.
    pub floor: f64,
    /// The mechanism's steady spin with the inertia it acts on.
    spin: Option<(FrameSpin, Inertia)>,
    /// The joints' incremental maps of the last evaluation (their storage
    /// reused by the next).
    maps: StepMaps,
    /// Where a tangent-only evaluation puts the nodal residual and scale it
    /// computes alongside, so that those of the residual it follows stay.
    spare: (Vec<f64>, Vec<f64>),
    /// `‖r‖₂` of the residual the last evaluation wrote, where it was
    /// summed alongside the force scale (taken by
    /// [`NewtonSystem::residual_norm`]).
    formed_norm: Option<f64>,
    /// The scheme's terms.
    pub terms: T,
}

impl<'m, T: StepTerms> ReducedSystem<'m, T> {
    /// A system over `topo` and `asm` starting (and ending) at `state`.
    pub fn new(
        mech: &'m Mechanism,
        topo: Topology,
        asm: Assembler,
        state: MechanismState,
        terms: T,
    ) -> Self {
        let nodes = mech.mesh.node_count();
        let n_eq = topo.dofs.n_eq;
        Self {
            mech,
            topo,
            asm,
            start: state.clone(),
            end: state,
            fext: vec![0.0; 6 * nodes],
            load_time: 0.0,
            nodal: vec![0.0; 6 * nodes],
            abs: vec![0.0; 6 * nodes],
            scratch: vec![0.0; n_eq],
            floor: mech.round_off_floor(),
            spin: (mech.spin.clone()).map(|s| {
                let inertia = mech.inertia(s.mass);
                (s, inertia)
            }),
            maps: StepMaps::default(),
            spare: (vec![0.0; 6 * nodes], vec![0.0; 6 * nodes]),
            formed_norm: None,
            terms,
        }
    }

    /// The reduced residual of nodal residuals `g` into `out`, through the
    /// scheme's [`Reduction`].
    pub fn reduce(&self, g: &[f64], out: &mut [f64]) {
        let mut maps = StepMaps::default();
        let incremental = self.fill_step_maps(false, &mut maps);
        self.reduce_with(incremental.then_some(&maps), g, out);
    }

    /// The joints' incremental maps of the step `start → end` into `maps`
    /// for the conserving schemes' [`Reduction::Incremental`] (seeded along
    /// the end state with `seeded`); `false` (and `maps` untouched) for
    /// [`Reduction::Variation`].
    fn fill_step_maps(&self, seeded: bool, maps: &mut StepMaps) -> bool {
        let incremental = self.terms.reduction() == Reduction::Incremental;
        if incremental {
            let lanes = seeded.then(|| self.topo.step_lanes(self.mech));
            maps.fill(self.mech, &self.start, &self.end, lanes.as_deref());
        }
        incremental
    }

    /// [`Self::reduce`] with the step's maps (given for
    /// [`Reduction::Incremental`]).
    fn reduce_with(&self, maps: Option<&StepMaps>, g: &[f64], out: &mut [f64]) {
        match maps {
            None => self.topo.dofs.reduce(g, out),
            Some(maps) => self
                .topo
                .reduce_incremental(self.mech, &maps.values, g, out),
        }
    }

    /// The reactions of the last evaluated residual (see
    /// [`Topology::reactions`]) into `record`: slaves fold into masters as the
    /// scheme reduces.
    pub fn record_reactions(&self, record: &mut StepRecord) {
        let start = (self.terms.reduction() == Reduction::Incremental).then_some(&self.start);
        let (joints, supports) = self
            .topo
            .reactions(self.mech, start, &self.end, &self.nodal);
        for (rec, r) in record.joints.iter_mut().zip(joints) {
            rec.reaction = r;
        }
        record.support_reactions = supports;
    }

    /// The residual into `r` (returns the force scale) and, if `tangent`,
    /// the tangent values (see the module docs for the steps).
    pub fn evaluate_with(&mut self, r: &mut [f64], tangent: bool) -> f64 {
        let mut kept = std::mem::take(&mut self.maps);
        let maps = self.refreshed_maps(tangent, &mut kept);
        let gathered = maps.is_none() && self.topo.dofs.is_gather();
        self.nodal_residual(tangent, false);
        self.reduce_with(maps, &self.nodal, r);
        if tangent {
            self.joint_blocks(maps);
        }
        self.maps = kept;
        let dofs = &self.topo.dofs;
        // Where `r` is the gather of the nodal residual, its norm is summed
        // with the force scale's ([`NewtonSystem::residual_norm`]).
        let (g, fext, abs) = (&self.nodal[..], &self.fext[..], &self.abs[..]);
        let (norm, f_ext, abs) = if gathered {
            let [norm, f_ext, abs] = dofs.reduced_norms([g, fext, abs], &mut self.scratch);
            (Some(norm), f_ext, abs)
        } else {
            let [f_ext, abs] = dofs.reduced_norms([fext, abs], &mut self.scratch);
            (None, f_ext, abs)
        };
        self.formed_norm = norm;
        f_ext.max(abs)
    }

    /// The tangent values alone at an iterate whose residual
    /// ([`Self::evaluate_with`]) was just evaluated: the same values as an
    /// evaluation with the tangent, whose nodal residual would be that
    /// residual's again (`nodal` and `abs` keep it; the joints' tangent
    /// blocks are formed from it). The elements may leave their forces out
    /// ([`StepTerms::element_tangents`]); the other terms' forces go to
    /// spare buffers.
    fn tangent_at_residual(&mut self) {
        let mut kept = std::mem::take(&mut self.maps);
        let maps = self.refreshed_maps(true, &mut kept);
        std::mem::swap(&mut self.nodal, &mut self.spare.0);
        std::mem::swap(&mut self.abs, &mut self.spare.1);
        self.nodal_residual(true, true);
        std::mem::swap(&mut self.nodal, &mut self.spare.0);
        std::mem::swap(&mut self.abs, &mut self.spare.1);
        self.joint_blocks(maps);
        self.maps = kept;
    }

    /// The slaves' node maps refreshed at the iterate and the joints' maps
    /// of the step filled into `kept` (seeded with `tangent`; `None` for
    /// [`Reduction::Variation`]), the slaves' rows set from them with the
    /// tangent: one map per joint serves the rows, the residual and the
    /// tangent.
    fn refreshed_maps<'k>(
        &mut self,
        tangent: bool,
        kept: &'k mut StepMaps,
    ) -> Option<&'k StepMaps> {
        let mech = self.mech;
        let joints = !mech.joints.is_empty();
        self.topo.refresh(mech, &self.end);
        let maps = self
            .fill_step_maps(tangent && joints, kept)
            .then_some(&*kept);
        if let Some(maps) = maps.filter(|_| tangent && joints) {
            self.topo.refresh_rows(mech, &maps.values);
        }
        maps
    }

    /// The joints' tangent blocks (from the nodal residual) added to the
    /// tangent values: through the step's seeded maps, or the variation
    /// map's geometric blocks at the iterate.
    fn joint_blocks(&mut self, maps: Option<&StepMaps>) {
        let mech = self.mech;
        if mech.joints.is_empty() {
            return;
        }
        let blocks = match maps {
            None => self.topo.geometric_blocks(mech, &self.end, &self.nodal),
            Some(maps) => self
                .topo
                .incremental_blocks(mech, &maps.seeded, &self.nodal),
        };
        for (b, block) in blocks.iter().enumerate() {
            self.asm.add_block(b, block);
        }
    }

    /// The nodal residual at the iterate (internal and inertial minus
    /// external forces, 6 per node) into `nodal`, the sums of their
    /// magnitudes into `abs`, and, if `tangent`, the elements', inertia's,
    /// follower loads' and spin's tangent values (the slaves' maps and rows
    /// set by the caller); `tangent_only`: the elements' tangents alone
    /// where the scheme leaves their forces out
    /// ([`StepTerms::element_tangents`]).
    fn nodal_residual(&mut self, tangent: bool, tangent_only: bool) {
        let mech = self.mech;
        let (start, end) = (&self.start.config, &self.end.config);
        let (dofs, asm) = (&self.topo.dofs, &mut self.asm);
        if tangent_only {
            self.terms.element_tangents(mech, dofs, asm, (start, end));
        } else {
            self.terms.elements(mech, dofs, asm, start, end, tangent);
        }
        for (g, (fi, fe)) in self
            .nodal
            .iter_mut()
            .zip(self.asm.nodal.iter().zip(&self.fext))
        {
            *g = fi - fe;
        }
        // The assembler's scale, taken as it is: the next assembly zeroes
        // what is left in its place.
        std::mem::swap(&mut self.abs, &mut self.asm.nodal_abs);
        let blocks = tangent.then_some((&mut self.asm, &self.topo.dofs));
        self.terms
            .inertia(start, end, &mut self.nodal, &mut self.abs, blocks);
        if !mech.follower_loads.is_empty() {
            self.follower_terms(self.terms.reduction(), tangent);
        }
        if let Some((spin, inertia)) = &self.spin {
            let blocks = tangent.then_some((&mut self.asm, &self.topo.dofs));
            let residual = (&mut self.nodal[..], &mut self.abs[..]);
            spin.add_steady(inertia, &self.end.config, self.load_time, residual, blocks);
        }
    }
}

impl<T: StepTerms> ReducedSystem<'_, T> {
    /// Adds the gyroscopic matrix of the mechanism's spin at the end state to
    /// the tangent values (zeroed by the caller); nothing without a spin.
    pub(crate) fn add_gyroscopic(&mut self) {
        if let Some((spin, inertia)) = &self.spin {
            spin.add_gyroscopic(inertia, &self.end.config, &mut self.asm, &self.topo.dofs);
        }
    }

    /// The follower loads in the nodal residual (`g −= f`) and, with
    /// `tangent`, their load stiffness: at the end of the step
    /// (`f = s R₁ f₀`, [`Reduction::Variation`]) or as the mean of both ends
    /// (`½ s (R₀ + R₁) f₀`, the midpoint schemes' [`Reduction::Incremental`]);
    /// `∂(−R₁ f₀)/∂η = (R₁ f₀)^` for a spatial spin `η` of the end rotation.
    fn follower_terms(&mut self, reduction: Reduction, tangent: bool) {
        let (start, end) = (&self.start.config.rot, &self.end.config.rot);
        let w_end = match reduction {
            Reduction::Variation => 1.0,
            Reduction::Incremental => 0.5,
        };
        for l in &self.mech.follower_loads {
            let (n, s) = (l.node, l.scale.at(self.load_time));
            let (f1, m1) = (
                end[n] * l.force * (s * w_end),
                end[n] * l.moment * (s * w_end),
            );
            let (mut f, mut m) = (f1, m1);
            if reduction == Reduction::Incremental {
                f += start[n] * l.force * (0.5 * s);
                m += start[n] * l.moment * (0.5 * s);
            }
            for c in 0..3 {
                self.nodal[6 * n + c] -= f[c];
                self.nodal[6 * n + 3 + c] -= m[c];
                self.abs[6 * n + c] += f[c].abs();
                self.abs[6 * n + 3 + c] += m[c].abs();
            }
            if tangent {
                let dofs = &self.topo.dofs;
                self.asm.add_node_block(dofs, (n, 0), (n, 3), &skew(&f1));
                self.asm.add_node_block(dofs, (n, 3), (n, 3), &skew(&m1));
            }
        }
    }
}

impl<T: StepTerms> NewtonSystem for ReducedSystem<'_, T> {
    fn evaluate(&mut self, r: &mut [f64]) -> f64 {
        self.evaluate_with(r, true)
    }

    fn residual(&mut self, r: &mut [f64]) -> f64 {
        self.evaluate_with(r, false)
    }

    fn update_tangent(&mut self, scratch: &mut [f64]) {
        self.evaluate_with(scratch, true);
        self.formed_norm = None;
    }

    fn update_tangent_at_residual(&mut self, scratch: &mut [f64]) {
        if self.terms.tangents_alone() {
            self.tangent_at_residual();
        } else {
            self.evaluate_with(scratch, true);
        }
        self.formed_norm = None;
    }

    fn residual_norm(&mut self, r: &[f64]) -> f64 {
        self.formed_norm
            .take()
            .unwrap_or_else(|| crate::newton::residual_norm(r))
    }

    fn tangent_key(&self) -> f64 {
        self.terms.tangent_key()
    }

    fn tangent_is_exact(&self) -> bool {
        self.terms.tangent_is_exact()
    }

    fn set_exact_tangent(&mut self, exact: bool) {
        self.terms.set_exact_tangent(exact);
    }

    /// Not with drivers: their work over the step is summed from the last
    /// evaluated residual's forces on the driven coordinates, which a
    /// closing correction at the tolerance would leave behind the state by
    /// that tolerance (the energy balance of the paper's driven screw grew
    /// from 2e-15 to 2.5e-12 of its energy).
    fn closes_converged(&self) -> bool {
        self.terms.closes_converged() && !self.mech.has_drivers()
    }

    /// The energy-conserving scheme with drivers: the drivers' work is
    /// summed from the last evaluated residual's forces on the driven
    /// coordinates, and balances the energy exactly only at the state they
    /// were evaluated at (a closing at the floor not evaluated left the
    /// paper's rack-and-pinion's balance at 1.6e-11 of its energy instead
    /// of 1.6e-15).
    fn evaluates_closing(&self) -> bool {
        self.terms.conserves_energy() && self.mech.has_drivers()
    }

    /// The nodal residual alone: the drivers' work and the reactions are
    /// taken from it. The reduced residual would cost the joints' maps of
    /// the step, the slaves' node maps and the reduction besides (3 % of the
    /// CPU of the energy–momentum slider-crank of `data/benchmarks`) for a
    /// number that only ends the history. A non-finite nodal residual is
    /// `NaN`.
    fn evaluate_closing(&mut self, _r: &mut [f64]) -> Option<f64> {
        self.nodal_residual(false, false);
        (!self.nodal.iter().all(|v| v.is_finite())).then_some(f64::NAN)
    }

    fn tangent_values(&self) -> &[f64] {
        &self.asm.values
    }

    fn apply(&mut self, dq: &[f64]) {
        self.topo.apply(self.mech, &mut self.end, dq);
    }

    fn floor(&self) -> f64 {
        self.floor
    }

    fn free_motion(&self, mode: &[f64], tangent: TangentRef) -> FreeMotion {
        FreeMotion::of(
            self.mech,
            &self.topo.dofs,
            &self.topo.released_eqs,
            &self.end.config.x,
            mode,
            tangent,
        )
    }
}
