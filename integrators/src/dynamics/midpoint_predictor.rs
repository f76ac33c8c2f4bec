//! The midpoint schemes' predictor: the velocities that carry a step's
//! start pose to Newton's first iterate, `x ← xₙ + Δt v`, `R ← exp(Δt R W̃) R`
//! (see `Simulation::predict`).
//!
//! The unknown of a midpoint step is its mid-step velocity
//! `v_{n+½} = (xₙ₊₁ − xₙ)/Δt` (and `W_{n+½} = Rₙᵀθ/Δt`, `θ = cay⁻¹(Rₙ₊₁Rₙᵀ)`).
//! Two candidates predict it:
//!
//! - `A`, the end velocities `vₙ`: off by `½Δt a` on smooth motion; but the
//!   midpoint rule conserves what the stiff modes ring with, and a mode far
//!   above `1/Δt` rings in the end velocities — their sign alternates from
//!   step to step (`vₙ₊₁ = 2v_{n+½} − vₙ`) while the positions, and with
//!   them the mid-step velocities, hardly move;
//! - `B`, the mid-step velocity extrapolated from the last two steps,
//!   `2v_{n−½} − v_{n−3/2}`: off by `O(Δt²)` on smooth motion, blind to the
//!   end velocities' ringing, but off threefold on what alternates in the
//!   mid-step velocities themselves (modes near `1/Δt`).
//!
//! Which is nearer depends on the mechanism and on the stage of the motion
//! (a stiff four-bar rings, a cantilever under a sudden load is smooth at
//! first). So once a step has converged, the blend `(1 − λ)A + λB` nearest
//! to the mid-step velocities of the last steps is fitted by least squares
//! in the kinetic-energy norm `‖δ‖² = Σ mᵢ|δvᵢ|² + δWᵢᵀJᵢδWᵢ`,
//! `λ = Σ ρᵏ⟨v_{n+½} − A, B − A⟩ / Σ ρᵏ‖B − A‖²` clamped to `[0, 1]`, each
//! step weighted `ρ = ½` of the one after it, and the next step is predicted
//! with the same blend of its own candidates. `λ` is a
//! continuous function of the converged steps, so a run's results stay
//! smooth in the model's parameters (finite differences of runs agree with
//! the exact sensitivities); a choice of one candidate or the other would
//! move the converged steps by up to the Newton tolerance where it flips.
//! The predictor moves only Newton's starting point: the converged steps are
//! the scheme's, to the Newton tolerance. A change of the step size drops
//! the history (the extrapolation assumes equal steps).

use crate::dynamics::checkpoint::{CheckpointMismatch, Tape};
use flexmech_core::Inertia;
use nalgebra::Vector3;

/// Nodal translational and body angular velocities.
type Velocities = (Vec<Vector3<f64>>, Vec<Vector3<f64>>);

/// [`Velocities`] borrowed.
type Pair<'a> = (&'a [Vector3<f64>], &'a [Vector3<f64>]);

/// The weight of a step in the blend's least-squares fit relative to the
/// step after it: the fit follows the motion over the last few steps.
/// (On the stiff four-bar 0.5 made the fewest iterations of 0, 0.5, 0.8
/// and 0.95.)
const FIT_MEMORY: f64 = 0.5;

/// The predictor's memory between steps (see the module docs).
#[derive(Debug, Clone, Default)]
pub(crate) struct MidpointPredictor {
    /// The last converged step's size and mid-step velocities.
    last: Option<(f64, Velocities)>,
    /// The candidate `B` for the coming step, once two steps of the same
    /// size have converged.
    extrapolated: Option<Velocities>,
    /// The blend of the candidates the coming step is predicted with (none:
    /// the end velocities alone).
    blended: Option<Velocities>,
    /// The least-squares fit's sums `(Σ ρᵏ⟨v − A, B − A⟩, Σ ρᵏ‖B − A‖²)`
    /// over the steps since the history began (`ρ = FIT_MEMORY`).
    fit: (f64, f64),
}

impl MidpointPredictor {
    /// The velocities the coming step is predicted with, given the end
    /// velocities `(v, W)` of the last step.
    pub(crate) fn velocities<'a>(
        &'a self,
        end: (&'a [Vector3<f64>], &'a [Vector3<f64>]),
    ) -> (&'a [Vector3<f64>], &'a [Vector3<f64>]) {
        match &self.blended {
            Some((v, w)) => (v, w),
            None => end,
        }
    }

    /// Records a converged step of size `dt` with mid-step velocities `mid`
    /// whose start velocities were `start` and end velocities are `end`,
    /// and blends the next step's candidates.
    pub(crate) fn finish(
        &mut self,
        inertia: &Inertia,
        dt: f64,
        (start, end): (Pair<'_>, Pair<'_>),
        mid: Velocities,
    ) {
        let blend = match self.extrapolated.as_ref() {
            Some(b) => {
                let (along, norm) = fit_terms(inertia, start, (&b.0, &b.1), (&mid.0, &mid.1));
                self.fit = (
                    FIT_MEMORY * self.fit.0 + along,
                    FIT_MEMORY * self.fit.1 + norm,
                );
                blend_of(self.fit)
            }
            None => {
                self.fit = (0.0, 0.0);
                0.0
            }
        };
        self.extrapolated = match &self.last {
            Some((last_dt, (v0, w0))) if *last_dt == dt => {
                Some((extrapolate(v0, &mid.0), extrapolate(w0, &mid.1)))
            }
            _ => None,
        };
        self.blended = match &self.extrapolated {
            Some((v, w)) if blend > 0.0 => Some((mix(end.0, v, blend), mix(end.1, w, blend))),
            _ => None,
        };
        self.last = Some((dt, mid));
    }

    /// Writes the memory to `tape`: a flag for each part, then its values.
    pub(crate) fn save(&self, tape: &mut Tape) {
        match &self.last {
            None => tape.put(0.0),
            Some((dt, (v, w))) => {
                tape.put(1.0);
                tape.put(*dt);
                tape.put_vectors(v);
                tape.put_vectors(w);
            }
        }
        for part in [&self.extrapolated, &self.blended] {
            match part {
                None => tape.put(0.0),
                Some((v, w)) => {
                    tape.put(1.0);
                    tape.put_vectors(v);
                    tape.put_vectors(w);
                }
            }
        }
        tape.put(self.fit.0);
        tape.put(self.fit.1);
    }

    /// Reads what [`Self::save`] wrote for `nodes` nodes; a tape that ends
    /// before it (saved by a build without the predictor's memory) starts
    /// with none.
    pub(crate) fn restore(tape: &mut Tape, nodes: usize) -> Result<Self, CheckpointMismatch> {
        if tape.is_done() {
            return Ok(Self::default());
        }
        let velocities = |tape: &mut Tape| -> Result<Velocities, CheckpointMismatch> {
            Ok((
                tape.take_vectors("mid-step velocities", nodes)?,
                tape.take_vectors("mid-step angular velocities", nodes)?,
            ))
        };
        let last = if tape.take()? != 0.0 {
            let dt = tape.take()?;
            Some((dt, velocities(tape)?))
        } else {
            None
        };
        let part = |tape: &mut Tape| -> Result<Option<Velocities>, CheckpointMismatch> {
            if tape.take()? != 0.0 {
                velocities(tape).map(Some)
            } else {
                Ok(None)
            }
        };
        let extrapolated = part(tape)?;
        let blended = part(tape)?;
        let fit = (tape.take()?, tape.take()?);
        Ok(Self {
            last,
            extrapolated,
            blended,
            fit,
        })
    }
}

/// One step's terms of the least-squares blend: `⟨target − a, b − a⟩` and
/// `‖b − a‖²` in the kinetic-energy norm.
fn fit_terms(inertia: &Inertia, a: Pair<'_>, b: Pair<'_>, target: Pair<'_>) -> (f64, f64) {
    let ba = (difference(b.0, a.0), difference(b.1, a.1));
    let ta = (difference(target.0, a.0), difference(target.1, a.1));
    (
        kinetic_product(inertia, (&ta.0, &ta.1), (&ba.0, &ba.1)),
        kinetic_product(inertia, (&ba.0, &ba.1), (&ba.0, &ba.1)),
    )
}

/// The blend `λ = along/norm` of the fit's sums, clamped to `[0, 1]` (0
/// where the candidates have not differed).
fn blend_of((along, norm): (f64, f64)) -> f64 {
    if norm > 0.0 {
        (along / norm).clamp(0.0, 1.0)
    } else {
        0.0
    }
}

/// `a − b` of each node.
fn difference(a: &[Vector3<f64>], b: &[Vector3<f64>]) -> Vec<Vector3<f64>> {
    a.iter().zip(b).map(|(a, b)| a - b).collect()
}

/// `(1 − λ)a + λb` of each node.
fn mix(a: &[Vector3<f64>], b: &[Vector3<f64>], lambda: f64) -> Vec<Vector3<f64>> {
    a.iter()
        .zip(b)
        .map(|(a, b)| a * (1.0 - lambda) + b * lambda)
        .collect()
}

/// `2b − a` of each node.
fn extrapolate(a: &[Vector3<f64>], b: &[Vector3<f64>]) -> Vec<Vector3<f64>> {
    a.iter().zip(b).map(|(a, b)| b * 2.0 - a).collect()
}

/// `Σ mᵢ vᵢ·uᵢ + WᵢᵀJᵢSᵢ`: the kinetic-energy inner product of two sets
/// of velocities (lumped masses, the nodes' material rotational inertia).
fn kinetic_product(inertia: &Inertia, (v, w): Pair<'_>, (u, s): Pair<'_>) -> f64 {
    let translational: f64 = (v.iter().zip(u).zip(&inertia.row_mass))
        .map(|((v, u), m)| m * v.dot(u))
        .sum();
    let rotational: f64 = (w.iter().zip(s).zip(&inertia.rotational))
        .map(|((w, s), j)| w.dot(&(j * s)))
        .sum();
    translational + rotational
}

#[cfg(test)]
mod tests {
    use super::*;

    fn inertia(n: usize) -> Inertia {
        Inertia {
            mass: (0..n).map(|i| (i, i, 1.0)).collect(),
            row_mass: vec![1.0; n],
            rotational: vec![nalgebra::Matrix3::identity(); n],
        }
    }

    fn uniform(v: f64) -> Velocities {
        (vec![Vector3::new(v, 0.0, 0.0)], vec![Vector3::zeros()])
    }

    /// Steps of `Δt = 1` with mid-step velocities `mid(k)` and end
    /// velocities `end(k)` (from rest); the velocity predicted after each.
    fn predicted(mid: impl Fn(usize) -> f64, end: impl Fn(usize) -> f64, n: usize) -> Vec<f64> {
        let (m, mut p) = (inertia(1), MidpointPredictor::default());
        let mut out = Vec::new();
        for k in 0..n {
            let start = if k == 0 { 0.0 } else { end(k - 1) };
            let (a, b) = (uniform(start), uniform(end(k)));
            p.finish(&m, 1.0, ((&a.0, &a.1), (&b.0, &b.1)), uniform(mid(k)));
            out.push(p.velocities((&b.0, &b.1)).0[0].x);
        }
        out
    }

    /// Uniform acceleration `a = 1` from rest: mid-step velocities ½, 3/2,
    /// 5/2, … — the extrapolation is exact and the end velocities half a
    /// step behind, so from the third step on the blend is the
    /// extrapolation: the next mid-step velocity exactly.
    #[test]
    fn smooth_motion_is_predicted_by_the_extrapolation() {
        let v = predicted(|k| k as f64 + 0.5, |k| k as f64 + 1.0, 5);
        assert_eq!(&v[..2], &[1.0, 2.0]);
        assert_eq!(&v[2..], &[3.5, 4.5, 5.5]);
    }

    /// A stiff mode ringing in the end velocities (±1 about a smooth
    /// motion whose mid-step velocities rise by 0.1 a step): the end
    /// velocities miss by 1, the blend predicts the next mid-step velocity.
    #[test]
    fn ringing_end_velocities_are_left_out() {
        let mid = |k: usize| 0.1 * k as f64;
        let ring = |k: usize| if k.is_multiple_of(2) { 1.0 } else { -1.0 };
        let v = predicted(mid, |k| mid(k) + 0.05 + ring(k), 8);
        for (k, v) in v.iter().enumerate().skip(2) {
            assert!((v - mid(k + 1)).abs() < 1e-12, "after step {k}: {v}");
        }
    }

    /// The blend is the least-squares one in the kinetic-energy norm: a
    /// target on the segment gives its own `λ`, whatever the masses; one
    /// beyond either end is clamped to it.
    #[test]
    fn the_blend_is_the_nearest_point_of_the_segment() {
        let mut m = inertia(2);
        m.row_mass = vec![2.0, 0.5];
        m.rotational[1] = nalgebra::Matrix3::from_diagonal(&Vector3::new(3.0, 1.0, 0.2));
        let a = (
            vec![Vector3::new(1.0, 0.0, 2.0), Vector3::new(0.0, -1.0, 0.5)],
            vec![Vector3::new(0.3, 0.1, 0.0), Vector3::new(0.0, 0.2, -0.4)],
        );
        let b = (
            vec![Vector3::new(-1.0, 2.0, 0.0), Vector3::new(1.0, 1.0, 1.0)],
            vec![Vector3::new(0.0, 0.5, 0.2), Vector3::new(1.0, -0.2, 0.3)],
        );
        let at = |l: f64| (mix(&a.0, &b.0, l), mix(&a.1, &b.1, l));
        for (l, expected) in [(0.7, 0.7), (0.25, 0.25), (1.6, 1.0), (-0.4, 0.0)] {
            let t = at(l);
            let got = blend_of(fit_terms(&m, (&a.0, &a.1), (&b.0, &b.1), (&t.0, &t.1)));
            assert!((got - expected).abs() < 1e-14, "{l}: {got}");
        }
        // A target off the segment's line: the residual is orthogonal to it.
        let mut t = at(0.4);
        t.0[1] += Vector3::new(0.3, -0.2, 0.1);
        let l = blend_of(fit_terms(&m, (&a.0, &a.1), (&b.0, &b.1), (&t.0, &t.1)));
        let near = at(l);
        let r = (difference(&t.0, &near.0), difference(&t.1, &near.1));
        let d = (difference(&b.0, &a.0), difference(&b.1, &a.1));
        let cos = kinetic_product(&m, (&r.0, &r.1), (&d.0, &d.1));
        assert!(cos.abs() < 1e-14, "{cos}");
    }

    /// A change of step size drops the extrapolation.
    #[test]
    fn a_new_step_size_drops_the_history() {
        let (m, mut p) = (inertia(1), MidpointPredictor::default());
        for k in 0..4 {
            let (a, b) = (uniform(k as f64), uniform(k as f64 + 1.0));
            let dt = if k == 3 { 0.5 } else { 1.0 };
            p.finish(
                &m,
                dt,
                ((&a.0, &a.1), (&b.0, &b.1)),
                uniform(k as f64 + 0.5),
            );
            assert_eq!(p.blended.is_some(), k == 2, "after step {k}");
        }
    }

    /// Saved and restored, the memory is the same; an older tape that ends
    /// before it restores to none.
    #[test]
    fn the_memory_survives_a_restart() {
        let (m, mut p) = (inertia(2), MidpointPredictor::default());
        for k in 0..3 {
            let v = |x: f64| {
                (
                    vec![Vector3::new(x, 1.0, 2.0); 2],
                    vec![Vector3::new(0.1, 0.2, x); 2],
                )
            };
            let (a, b) = (v(k as f64), v(k as f64 + 1.0));
            p.finish(&m, 0.25, ((&a.0, &a.1), (&b.0, &b.1)), v(k as f64 + 0.5));
        }
        assert!(p.blended.is_some());
        let mut tape = Tape::default();
        p.save(&mut tape);
        let mut read = Tape::reading(&tape.into_data());
        let q = MidpointPredictor::restore(&mut read, 2).expect("restores");
        assert!(read.is_done());
        assert_eq!(format!("{p:?}"), format!("{q:?}"));
        let empty = MidpointPredictor::restore(&mut Tape::reading(&[]), 2).expect("restores");
        assert!(empty.last.is_none() && empty.blended.is_none());
    }
}
