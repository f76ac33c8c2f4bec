//! The element kernels of the midpoint schemes (paper eqs 16–20,
//! FORMULATION §4): the scheme's internal force of one element between the
//! step's start and end poses and its derivative with respect to spatial
//! increments of the end pose.

use super::Scheme;
use crate::mechanism::Mechanism;
use crate::threads;
use flexmech_core::conserving::{MidRotation, Pose, Pose3};
use flexmech_core::frames_pair::energy_momentum_force_pair_into;
use flexmech_core::rotation::exp;
use flexmech_core::step_start::StepStart;
use flexmech_core::{cst, BeamElement, Configuration, Element, Scalar};
use nalgebra::{Const, Matrix3, SVector, Vector3, U1};
use num_dual::DualSVec64;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

/// Dual numbers for derivatives with respect to an element's 12 increments.
pub(crate) type Dual12 = DualSVec64<12>;

/// An element's pose at the step's start, and its start and end poses as
/// [`Dual12`] numbers with the end seeded by spatial increments
/// (`x ← x + η`, `R ← exp(η̂)R`), so that any function of them carries its
/// derivative with respect to the end pose.
pub(crate) fn seeded_poses(
    e: &BeamElement<2>,
    start: &Configuration,
    end: &Configuration,
) -> (Pose<f64>, Pose<Dual12>, Pose<Dual12>) {
    type D = Dual12;
    let n = e.nodes;
    let s = pose_of(e, start);
    let seed = |j: usize| D::from_re(0.0).derivative(j);
    let v = |j: usize| Vector3::new(seed(j), seed(j + 1), seed(j + 2));
    let sd: Pose<D> = (
        s.0.map(|x| x.map(D::from_re)),
        s.1.map(|q| q.map(D::from_re)),
    );
    let ed: Pose<D> = (
        [
            end.x[n[0]].map(D::from_re) + v(0),
            end.x[n[1]].map(D::from_re) + v(6),
        ],
        [
            exp(&v(3)) * end.rot[n[0]].map(D::from_re),
            exp(&v(9)) * end.rot[n[1]].map(D::from_re),
        ],
    );
    (s, sd, ed)
}

/// `q_k(Nₙ₊½, Mₙ₊½)` and, when `correction` is asked for, the energy–momentum
/// correction's `q_k(N_d, 0)`, `N_d = Nₙ₊₁ − Nₙ`, of one element between its
/// start pose `s` and the seeded poses `sd`, `ed` (see [`seeded_poses`]), as
/// dual numbers.
pub(crate) fn midpoint_forces(
    e: &BeamElement<2>,
    s: &Pose<f64>,
    sd: &Pose<Dual12>,
    ed: &Pose<Dual12>,
    mid: MidRotation,
    correction: bool,
) -> (SVector<Dual12, 12>, Option<SVector<Dual12, 12>>) {
    type D = Dual12;
    let (nbar, mbar) = averaged_resultants(e, s, ed);
    let qk = e.midpoint_force(sd, ed, &nbar, &mbar, mid);
    // N_d = Nₙ₊₁ − Nₙ = 2(Nₙ₊½ − Nₙ).
    let n0 = e.resultants(&s.0, &s.1).0.map(D::from_re);
    let qd = correction.then(|| {
        e.midpoint_force(
            sd,
            ed,
            &((nbar - n0) * D::from_re(2.0)),
            &Vector3::zeros(),
            mid,
        )
    });
    (qk, qd)
}

/// Element kernel of the midpoint schemes: the scheme's internal force
/// (`q_k(Nₙ₊½, Mₙ₊½)` with the geodesic mid rotation for the momentum
/// scheme; the energy-consistent discrete gradient for the energy–momentum
/// scheme; `q_k(Nₙ₊½, Mₙ₊½) + β q_k(N_d, 0)` with the algebraic mid rotation
/// for the paper's energy–momentum scheme) and its derivative with respect
/// to spatial increments of the end pose (`x ← x + η`, `R ← exp(η̂)R`):
/// closed form for the momentum scheme, AD over the end spins with
/// closed-form chord columns for the energy–momentum scheme
/// ([`flexmech_core::conserving_tangent`]), forward-mode AD over all twelve
/// increments for the paper's scheme.
///
/// `exact = false` asks for the energy–momentum scheme's cheap tangent
/// (the force stays the exact discrete gradient): the momentum scheme's
/// closed-form derivative of `q_k(Nₙ₊½, Mₙ₊½)`. The discrete gradient is
/// that force with secant operators in place of the geodesic mid rotation
/// plus rank-one corrections of size `O(|Δθ|²)` ([`correction_size`]), so
/// the two derivatives differ by terms that vanish with the step's rotation
/// increment, and Newton with the cheap one contracts linearly at a rate of
/// that order; [`crate::newton`] switches to the exact tangent when it does
/// not. Other schemes and 3-node elements ignore the flag.
#[allow(clippy::too_many_arguments)]
pub(crate) fn element_kernel(
    el: &Element,
    start: &Configuration,
    end: &Configuration,
    scheme: Scheme,
    beta: f64,
    exact: bool,
    r: &mut [f64],
    k: &mut [f64],
) {
    let e = match el {
        Element::Linear(e) => e,
        Element::Quadratic(e) => return quadratic_kernel(e, start, end, r, k),
    };
    let pose = |c: &Configuration| pose_of(e, c);
    let (q, jac) = match scheme {
        Scheme::Momentum => e.momentum_force_tangent(&pose(start), &pose(end)),
        Scheme::EnergyMomentum if exact => {
            e.energy_momentum_force_tangent(&pose(start), &pose(end))
        }
        Scheme::EnergyMomentum => e.energy_momentum_force_cheap_tangent(&pose(start), &pose(end)),
        Scheme::EnergyMomentumPaper => {
            type D = Dual12;
            let (s, sd, ed) = seeded_poses(e, start, end);
            let (mut q, qd) = midpoint_forces(e, &s, &sd, &ed, scheme.mid_rotation(), beta != 0.0);
            if let Some(qd) = qd {
                q += qd * D::from_re(beta);
            }
            for i in 0..12 {
                r[i] = q[i].re;
                let row = q[i].eps.unwrap_generic(Const::<12>, U1);
                for j in 0..12 {
                    k[j * 12 + i] = row[j];
                }
            }
            return;
        }
    };
    r.copy_from_slice(q.as_slice());
    k.copy_from_slice(jac.as_slice());
}

/// The element force of [`element_kernel`] alone (no derivative): for
/// residual checks that no factorisation follows. The energy–momentum
/// scheme's 2-node elements add the sizes of their force and of its
/// rank-one corrections to `tally`.
pub(crate) fn element_force(
    el: &Element,
    start: &Configuration,
    end: &Configuration,
    scheme: Scheme,
    beta: f64,
    tally: &CorrectionTally,
    r: &mut [f64],
) {
    let q = match (el, scheme) {
        (Element::Linear(e), Scheme::Momentum | Scheme::EnergyMomentum) => {
            let (s, t) = (pose_of(e, start), pose_of(e, end));
            if scheme == Scheme::Momentum {
                let (nbar, mbar) = averaged_resultants(e, &s, &t);
                e.midpoint_force(&s, &t, &nbar, &mbar, MidRotation::Geodesic)
            } else {
                let (q, c) = e.energy_momentum_force_parts(&s, &t);
                tally.add(c.norm(), q.norm());
                q
            }
        }
        (Element::Quadratic(e), _) => {
            let n = e.nodes;
            let s: Pose3<f64> = (n.map(|i| start.x[i]), n.map(|i| start.rot[i]));
            let t: Pose3<f64> = (n.map(|i| end.x[i]), n.map(|i| end.rot[i]));
            r.copy_from_slice(e.discrete_gradient_force(&s, &t).as_slice());
            return;
        }
        (Element::Linear(_), Scheme::EnergyMomentumPaper) => {
            let mut k = [0.0; 144];
            return element_kernel(el, start, end, scheme, beta, true, r, &mut k);
        }
    };
    r.copy_from_slice(q.as_slice());
}

/// Every 2-node element's [`StepStart`] at the step's start, written into
/// `starts` (one entry per element; a 3-node element's is
/// [`StepStart::unset`]): the energy–momentum scheme's kernels look the
/// start pose's rotation pieces up instead of recomputing them at every
/// Newton evaluation of the step. Neighbouring 2-node elements take their
/// pieces two at a time ([`BeamElement::step_start_pair_into`]): the same
/// bits.
pub(crate) fn step_starts_into(
    mech: &Mechanism,
    start: &Configuration,
    starts: &mut Vec<StepStart>,
) {
    let elements = &mech.mesh.elements;
    starts.truncate(elements.len());
    starts.resize_with(elements.len(), StepStart::unset);
    threads::for_each_chunk_mut(starts, |first, chunk| {
        for (p, slots) in chunk.chunks_mut(2).enumerate() {
            let i = first + 2 * p;
            match (slots, &elements[i..]) {
                ([a, b], [Element::Linear(ea), Element::Linear(eb), ..]) => {
                    let poses = [pose_of(ea, start), pose_of(eb, start)];
                    BeamElement::step_start_pair_into([ea, eb], [&poses[0], &poses[1]], [a, b]);
                }
                (slots, els) => {
                    for (slot, el) in slots.iter_mut().zip(els) {
                        match el {
                            Element::Linear(e) => e.step_start_into(&pose_of(e, start), slot),
                            Element::Quadratic(_) => *slot = StepStart::unset(),
                        }
                    }
                }
            }
        }
    });
}

/// Element `index`'s entry of `starts` when `el` is a 2-node element and the
/// entry is the start of a step from `start` (else `None`: the kernel
/// computes its own).
pub(crate) fn start_of<'a>(
    starts: &'a [StepStart],
    el: &'a Element,
    index: usize,
    start: &Configuration,
) -> Option<(&'a BeamElement<2>, &'a StepStart)> {
    match (el, starts.get(index)) {
        (Element::Linear(e), Some(s)) if is_pose_in(e, s.pose(), start) => Some((e, s)),
        _ => None,
    }
}

/// The energy–momentum scheme's force with its cheap tangent
/// ([`element_kernel`] with `exact = false`) from the element's step start.
pub(crate) fn started_kernel(
    (e, s): (&BeamElement<2>, &StepStart),
    end: &Configuration,
    r: &mut [f64],
    k: &mut [f64],
) {
    let (q, jac) = e.energy_momentum_force_cheap_tangent_from(s, &pose_of(e, end));
    r.copy_from_slice(q.as_slice());
    k.copy_from_slice(jac.as_slice());
}

/// [`started_kernel`]'s cheap tangent alone, the force left out (`r`
/// zeroed): for a tangent at an iterate whose residual was just evaluated.
pub(crate) fn started_tangent(
    (e, s): (&BeamElement<2>, &StepStart),
    end: &Configuration,
    r: &mut [f64],
    k: &mut [f64],
) {
    r.fill(0.0);
    k.copy_from_slice(
        e.energy_momentum_cheap_tangent_from(s, &pose_of(e, end))
            .as_slice(),
    );
}

/// [`started_kernel`] of two neighbouring elements, their end poses' pieces
/// and cheap tangents two at a time
/// ([`BeamElement::energy_momentum_cheap_tangent_pair_into`]): the same
/// bits.
pub(crate) fn started_kernel_pair(
    starts: [(&BeamElement<2>, &StepStart); 2],
    end: &Configuration,
    r: [&mut [f64]; 2],
    k: [&mut [f64]; 2],
) {
    started_pair(starts, end, (r, k), true);
}

/// [`started_tangent`] of two neighbouring elements, their cheap tangents
/// two at a time ([`BeamElement::energy_momentum_cheap_tangent_pair_into`]): the
/// same bits.
pub(crate) fn started_tangent_pair(
    starts: [(&BeamElement<2>, &StepStart); 2],
    end: &Configuration,
    r: [&mut [f64]; 2],
    k: [&mut [f64]; 2],
) {
    started_pair(starts, end, (r, k), false);
}

/// Two neighbouring elements' cheap tangents into `k`, with their forces
/// into `r` (`force`) or `r` zeroed.
fn started_pair(
    starts: [(&BeamElement<2>, &StepStart); 2],
    end: &Configuration,
    (r, k): ([&mut [f64]; 2], [&mut [f64]; 2]),
    force: bool,
) {
    let [(ea, sa), (eb, sb)] = starts;
    let poses = [pose_of(ea, end), pose_of(eb, end)];
    let (e, s, p) = ([ea, eb], [sa, sb], [&poses[0], &poses[1]]);
    let forces = if force {
        Some(r)
    } else {
        r.into_iter().for_each(|r| r.fill(0.0));
        None
    };
    BeamElement::energy_momentum_cheap_tangent_pair_into(e, s, p, forces, k);
}

/// The energy–momentum scheme's force ([`element_force`]) from the
/// element's step start.
pub(crate) fn started_force(
    (e, s): (&BeamElement<2>, &StepStart),
    end: &Configuration,
    tally: &CorrectionTally,
    r: &mut [f64],
) {
    let (q, c) = e.energy_momentum_force_parts_from(s, &pose_of(e, end));
    tally.add(c.norm(), q.norm());
    r.copy_from_slice(q.as_slice());
}

/// [`started_force`] of two neighbouring elements, their end poses' pieces
/// two at a time ([`energy_momentum_force_pair_into`]): the same bits.
pub(crate) fn started_force_pair(
    starts: [(&BeamElement<2>, &StepStart); 2],
    end: &Configuration,
    tally: &CorrectionTally,
    forces: [&mut [f64]; 2],
) {
    let [(ea, sa), (eb, sb)] = starts;
    let poses = [pose_of(ea, end), pose_of(eb, end)];
    let norms = energy_momentum_force_pair_into([ea, eb], [sa, sb], [&poses[0], &poses[1]], forces);
    for (correction, force) in norms {
        tally.add(correction, force);
    }
}

/// Element kernel for 3-node elements, in both conserving schemes: the
/// energy-consistent discrete gradient (FORMULATION §4.3; there is no
/// paper form for them, so the momentum scheme uses it too and conserves
/// energy as well) and its AD derivative under spatial increments of the
/// end pose.
fn quadratic_kernel(
    e: &BeamElement<3>,
    start: &Configuration,
    end: &Configuration,
    r: &mut [f64],
    k: &mut [f64],
) {
    type D = DualSVec64<18>;
    let n = e.nodes;
    let seed = |j: usize| D::from_re(0.0).derivative(j);
    let v = |j: usize| Vector3::new(seed(j), seed(j + 1), seed(j + 2));
    let sd: Pose3<D> = (
        std::array::from_fn(|i| start.x[n[i]].map(D::from_re)),
        std::array::from_fn(|i| start.rot[n[i]].map(D::from_re)),
    );
    let ed: Pose3<D> = (
        std::array::from_fn(|i| end.x[n[i]].map(D::from_re) + v(6 * i)),
        std::array::from_fn(|i| exp(&v(6 * i + 3)) * end.rot[n[i]].map(D::from_re)),
    );
    let q = e.discrete_gradient_force(&sd, &ed);
    for i in 0..18 {
        r[i] = q[i].re;
        let row = q[i].eps.unwrap_generic(Const::<18>, U1);
        for j in 0..18 {
            k[j * 18 + i] = row[j];
        }
    }
}

/// The step averages `(Nₙ₊½, Mₙ₊½)` of an element's material resultants
/// between the start pose `s` and the end pose `ed` (plain, or seeded for
/// AD: see [`seeded_poses`]).
fn averaged_resultants<T: Scalar>(
    e: &BeamElement<2>,
    s: &Pose<f64>,
    ed: &Pose<T>,
) -> (Vector3<T>, Vector3<T>) {
    let (n0, m0) = e.resultants(&s.0, &s.1);
    let (n1, m1) = e.resultants(&ed.0, &ed.1);
    let half = cst::<T>(0.5);
    (
        (n0.map(cst::<T>) + n1) * half,
        (m0.map(cst::<T>) + m1) * half,
    )
}

/// A 2-node element's nodal positions and rotations in a configuration.
/// Filled in place: a pose is 192 bytes, and one built as an expression was
/// moved into its place with a call to `memcpy`, for every element of every
/// evaluation.
pub(crate) fn pose_of(e: &BeamElement<2>, c: &Configuration) -> Pose<f64> {
    let mut pose = ([Vector3::zeros(); 2], [Matrix3::zeros(); 2]);
    for (k, &n) in e.nodes.iter().enumerate() {
        pose.0[k] = c.x[n];
        pose.1[k] = c.rot[n];
    }
    pose
}

/// Whether `pose` is the element's pose in `c` (compared in place,
/// [`StepStart::is_of`] without building the pose).
fn is_pose_in(e: &BeamElement<2>, pose: &Pose<f64>, c: &Configuration) -> bool {
    e.nodes
        .iter()
        .enumerate()
        .all(|(k, &n)| pose.0[k] == c.x[n] && pose.1[k] == c.rot[n])
}

/// The energy–momentum scheme's consistency measure of a converged step:
/// the largest size, over the 2-node elements, of the rank-one corrections
/// of the discrete gradient relative to the largest element force, `O(Δt²)`
/// (NaN for a mesh without 2-node elements).
pub fn correction_size(mech: &Mechanism, start: &Configuration, end: &Configuration) -> f64 {
    let (mut corr, mut size) = (0.0f64, 0.0f64);
    for el in &mech.mesh.elements {
        let Element::Linear(e) = el else { continue };
        let (q, c) = e.energy_momentum_force_parts(&pose_of(e, start), &pose_of(e, end));
        corr = corr.max(c.norm());
        size = size.max(q.norm());
    }
    correction_ratio(mech, corr, size)
}

/// [`correction_size`] from the largest correction and force sizes.
fn correction_ratio(mech: &Mechanism, corr: f64, size: f64) -> f64 {
    let linear = mech
        .mesh
        .elements
        .iter()
        .any(|e| matches!(e, Element::Linear(_)));
    if !linear {
        f64::NAN
    } else if size > 0.0 {
        corr / size
    } else {
        0.0
    }
}

/// The largest correction and force sizes of the energy–momentum scheme's
/// 2-node elements over one residual evaluation ([`element_force`]), so
/// that a converged step's [`correction_size`] comes from Newton's last
/// evaluation — at the accepted iterate — instead of another pass over the
/// elements. The maxima are of non-negative numbers (compared through their
/// bits), so they do not depend on the order the element loop's threads
/// add them in.
#[derive(Debug, Default)]
pub(crate) struct CorrectionTally {
    corr: AtomicU64,
    size: AtomicU64,
    /// Whether the last evaluation was a residual alone (which tallies);
    /// a tangent evaluation does not.
    complete: AtomicBool,
}

impl CorrectionTally {
    /// Starts an evaluation: one that tallies (`complete`) or not.
    pub(crate) fn start(&self, complete: bool) {
        self.corr.store(0, Ordering::Relaxed);
        self.size.store(0, Ordering::Relaxed);
        self.complete.store(complete, Ordering::Relaxed);
    }

    /// Adds one element's correction and force sizes (both `≥ 0`, so their
    /// bits order as they do). A plain load first: the locked maximum only
    /// where the tally grows, which after the first elements is rare.
    fn add(&self, corr: f64, size: f64) {
        for (tally, v) in [(&self.corr, corr), (&self.size, size)] {
            let bits = v.to_bits();
            if bits > tally.load(Ordering::Relaxed) {
                tally.fetch_max(bits, Ordering::Relaxed);
            }
        }
    }

    /// [`correction_size`] at the configuration the last evaluation was
    /// at, if that evaluation tallied.
    pub(crate) fn correction_size(&self, mech: &Mechanism) -> Option<f64> {
        self.complete.load(Ordering::Relaxed).then(|| {
            let get = |a: &AtomicU64| f64::from_bits(a.load(Ordering::Relaxed));
            correction_ratio(mech, get(&self.corr), get(&self.size))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use flexmech_core::Section;

    /// A step start is found for the configuration it was made at (compared
    /// in place, node by node) and refused for any other: a moved node or a
    /// turned one.
    #[test]
    fn a_step_start_is_used_only_from_its_own_start() {
        let sec = Section::new([1e6; 3], [1e3; 3], 1.0, [1e-3; 3]);
        let x: Vec<_> = (0..4)
            .map(|i| Vector3::new(f64::from(i), 0.0, 0.0))
            .collect();
        let els: Vec<_> = (0..3)
            .map(|i| {
                let ends = [x[i], x[i + 1]];
                Element::Linear(BeamElement::new(
                    [i, i + 1],
                    sec,
                    1.0,
                    &ends,
                    [Matrix3::identity(); 2],
                ))
            })
            .collect();
        let start = Configuration {
            x,
            rot: vec![Matrix3::identity(); 4],
        };
        let starts: Vec<_> = els
            .iter()
            .map(|el| match el {
                Element::Linear(e) => e.step_start(&pose_of(e, &start)),
                Element::Quadratic(_) => StepStart::unset(),
            })
            .collect();
        // An unset start is the start of nothing.
        assert!(start_of(&[StepStart::unset()], &els[0], 0, &start).is_none());
        let found = |c: &Configuration| -> Vec<bool> {
            (0..3)
                .map(|i| start_of(&starts, &els[i], i, c).is_some())
                .collect()
        };
        assert_eq!(found(&start), [true; 3]);
        let mut moved = start.clone();
        moved.x[1].y += 1e-12;
        assert_eq!(found(&moved), [false, false, true]);
        let mut turned = start.clone();
        turned.rot[3] = exp(&Vector3::new(0.0, 0.0, 1e-9)) * turned.rot[3];
        assert_eq!(found(&turned), [true, true, false]);
    }
}
