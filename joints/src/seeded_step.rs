//! A joint's incremental map `Ñ` of a step (paper eqs 21–23,
//! [`JointStep`]) with its derivative along the step's end state, lane by
//! lane and only along the local increments that reach the unknowns
//! ([`StepLanes`]): the conserving schemes' Newton tangent.
//!
//! The released coordinates' lanes come by forward-mode AD through the
//! kind's `B` and released placement (any kind, a user's too); the master's
//! spin `δφ` (`Λ_m,ₙ₊₁ ← exp(δφ̂) Λ_m,ₙ₊₁`) enters `Ñ` only through
//! `Λ_m,ₙ₊₁`, and its lanes are closed form. With `y = Λ_m,ₙ₊₁ r_R,ₙ₊₁`,
//! `θ = θ_m`, `M = ½(Λ_m,ₙ + Λ_m,ₙ₊₁)`, `P = I + ½θ̂ + ¼θθᵀ`,
//! `s = 1 − ¼ θ·θ_r` and a spin `e` (a unit vector):
//!
//! ```text
//! ∂θ      = C e,   C = I − ½θ̂ + ¼θθᵀ     (θ = cay⁻¹(Λ_m,ₙ₊₁Λ_m,ₙᵀ) = 2v/w, q ← (1, ½e) ⊗ q)
//! ∂d      = ½ e × y
//! ∂lever  = −¼(∂θ̂ θ̂ + θ̂ ∂θ̂) M + ½(I − ¼θ̂²) ê Λ_m,ₙ₊₁
//! ∂A      = (∂P Λ_m,ₙ)/s + A (¼ ∂θ·θ_r)/s,   ∂P = ½∂θ̂ + ¼(∂θ θᵀ + θ ∂θᵀ)
//! ∂B      = 0
//! ```
//!
//! [`JointMap::incremental_step_seeded`](crate::JointMap::incremental_step_seeded)
//! (AD over all ten local lanes) stays the oracle the tests compare with.

use crate::incremental::{JointStep, NodePose, StepDual};
use crate::kinematics::{released_at, JointKinematics, ReleasedState, LOCAL, MAX_RELEASED};
use flexmech_core::rotation::{cayley_inverse, cayley_tangent_inverse, mmt, skew, vee};
use nalgebra::{Matrix3, SMatrix, SVector, Vector3, Vector6};
use num_dual::DualSVec64;

/// The local increments of a step's end state along which a joint's `Ñ`
/// is differentiated: those that reach the unknowns. A master whose
/// rotation is held (the ground, a clamped node) needs no spin lanes; a
/// released coordinate without an equation (driven) needs no lane. The
/// master's translation never needs one (`Ñ` does not depend on it).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StepLanes {
    /// The master's spin `δφ` (three lanes).
    pub spin: bool,
    /// The first `released` released coordinates (one lane each).
    pub released: usize,
}

impl StepLanes {
    /// Every lane of a kind with `released` coordinates.
    pub fn all(released: usize) -> Self {
        Self {
            spin: true,
            released,
        }
    }
}

/// `Ñ` with its derivatives along the lanes of [`StepLanes`].
#[derive(Debug, Clone, PartialEq)]
pub struct SeededStep {
    /// `Ñ` itself.
    pub value: JointStep,
    /// `(c, ∂Ñ/∂q_c)` for each seeded lane, `c` the local increment
    /// (`3..6` the master's spin, `6 + k` released coordinate `k`).
    pub slopes: Vec<(usize, JointStep)>,
}

impl SeededStep {
    /// `Ñ` of `joint` over the step and its derivatives along `lanes`, closed
    /// form from `B`'s and the released end placement's derivatives (AD in
    /// the released lanes only, module docs).
    pub fn of<J: JointKinematics + ?Sized>(
        joint: &J,
        master: [NodePose<'_>; 2],
        released: [&ReleasedState; 2],
        lanes: StepLanes,
    ) -> Self {
        match lanes.released.min(MAX_RELEASED) {
            0 => {
                let b = joint.step_map(released[0], released[1], &[0.0; MAX_RELEASED]);
                let (value, ends) = value_and_ends(joint, master, released, b);
                let slopes = spin_slopes(&ends, &value, lanes.spin).collect();
                Self { value, slopes }
            }
            1 => of_in::<J, 1>(joint, master, released, lanes.spin),
            2 => of_in::<J, 2>(joint, master, released, lanes.spin),
            3 => of_in::<J, 3>(joint, master, released, lanes.spin),
            _ => of_in::<J, MAX_RELEASED>(joint, master, released, lanes.spin),
        }
    }

    /// The same from a map seeded along all ten local lanes
    /// ([`JointStep::seeded`]): its real parts and the lanes' derivatives.
    pub fn from_seeded(seeded: &JointStep<StepDual>, lanes: StepLanes) -> Self {
        let spin = if lanes.spin { 3..6 } else { 3..3 };
        let slopes = spin
            .chain(6..6 + lanes.released.min(MAX_RELEASED))
            .map(|c| (c, seeded.map(|v| v.eps.0.as_ref().map_or(0.0, |e| e[c]))))
            .collect();
        Self {
            value: seeded.value(),
            slopes,
        }
    }

    /// `Ñᵀ g` for a slave residual `g` held fixed, and its derivative with
    /// respect to the local increments `(δx, δφ, τ)` of the step's end state
    /// (the columns of lanes not seeded are zero; the rows and columns of
    /// the released coordinates past `released` too), as
    /// [`JointStep::seeded_transfer`] gives it over all lanes.
    pub fn transfer(
        &self,
        g: &Vector6<f64>,
        released: usize,
    ) -> (SVector<f64, LOCAL>, SMatrix<f64, LOCAL, LOCAL>) {
        let mut value = self.value.transfer(g);
        let (f, m) = (g.fixed_rows::<3>(0).into_owned(), g.fixed_rows::<3>(3));
        let (lf, am) = (self.value.lever.tr_mul(&f), self.value.a.tr_mul(&m));
        let h = [lf.x, lf.y, lf.z, am.x, am.y, am.z];
        let mut k = SMatrix::<f64, LOCAL, LOCAL>::zeros();
        for (c, d) in self.slopes.iter().filter(|(c, _)| *c < 6 + released) {
            k.set_column(*c, &self.lane_column(d, g, &h));
        }
        for c in 6 + released..LOCAL {
            value[c] = 0.0;
            k.row_mut(c).fill(0.0);
        }
        (value, k)
    }

    /// The derivative of `Ñᵀ g` along one lane, `d = ∂Ñ`: the master's
    /// moment `∂d × f`, the released equations `∂Bᵀ h + Bᵀ ∂h` with
    /// `h = (leverᵀ f, Aᵀ m)`.
    fn lane_column(&self, d: &JointStep, g: &Vector6<f64>, h: &[f64; 6]) -> SVector<f64, LOCAL> {
        let (f, m) = (g.fixed_rows::<3>(0).into_owned(), g.fixed_rows::<3>(3));
        let mut col = SVector::<f64, LOCAL>::zeros();
        col.fixed_rows_mut::<3>(3).copy_from(&d.offset.cross(&f));
        let (dlf, dam) = (d.lever.tr_mul(&f), d.a.tr_mul(&m));
        let dh = [dlf.x, dlf.y, dlf.z, dam.x, dam.y, dam.z];
        let b = &self.value.b;
        for j in 0..MAX_RELEASED {
            col[6 + j] = (0..6).fold(0.0, |acc, i| acc + d.b[(i, j)] * h[i] + b[(i, j)] * dh[i]);
        }
        col
    }
}

/// `Ñ` (with the step's `B`) and the pieces its derivatives are formed from.
fn value_and_ends<J: JointKinematics + ?Sized>(
    joint: &J,
    master: [NodePose<'_>; 2],
    released: [&ReleasedState; 2],
    b: SMatrix<f64, 6, MAX_RELEASED>,
) -> (JointStep, StepEnds) {
    let (zero, none) = ([0.0; 6], [0.0; MAX_RELEASED]);
    let value = JointStep::with_map(joint, master, released, (&zero, &none), (&zero, &none), b);
    (value, StepEnds::of(joint, master, released))
}

/// The spin lanes `(3 + i, ∂Ñ/∂δφᵢ)` when `spin`.
fn spin_slopes<'a>(
    ends: &'a StepEnds,
    value: &'a JointStep,
    spin: bool,
) -> impl Iterator<Item = (usize, JointStep)> + 'a {
    let lanes = if spin { 0..3 } else { 0..0 };
    lanes.map(move |i| (3 + i, ends.spin_lane(value, i)))
}

/// [`SeededStep::of`] with the first `K` released coordinates seeded: `B`,
/// the released end placement `(r_R, Λ_R)` by forward-mode AD in `K`
/// lanes, `∂r_R/∂τₖ` and the spin `sₖ` (`∂Λ_R = ŝₖ Λ_R`) from them.
fn of_in<J: JointKinematics + ?Sized, const K: usize>(
    joint: &J,
    master: [NodePose<'_>; 2],
    released: [&ReleasedState; 2],
    spin: bool,
) -> SeededStep {
    type D<const K: usize> = DualSVec64<K>;
    let zero = D::<K>::from_re(0.0);
    let inc: [D<K>; MAX_RELEASED] =
        std::array::from_fn(|k| if k < K { zero.derivative(k) } else { zero });
    let b = joint.step_map(released[0], released[1], &inc);
    let (r, l) = released_at(joint, released[1], &inc);
    let lane = |v: &D<K>, k: usize| v.eps.0.as_ref().map_or(0.0, |e| e[k]);
    let (value, ends) = value_and_ends(joint, master, released, b.map(|v| v.re));
    let l1 = l.map(|v| v.re);
    let mut slopes: Vec<_> = spin_slopes(&ends, &value, spin).collect();
    slopes.extend((0..K).map(|k| {
        let turn = vee(&(l.map(|v| lane(&v, k)) * l1.transpose()));
        let dr = r.map(|v| lane(&v, k));
        let d = ends.released_lane(&value, &dr, &turn, b.map(|v| lane(&v, k)));
        (6 + k, d)
    }));
    SeededStep { value, slopes }
}

/// The pieces of `Ñ` its derivatives are formed from (module docs).
struct StepEnds {
    r0: Matrix3<f64>,
    r1: Matrix3<f64>,
    /// `Λ_m,ₙ₊₁ r_R,ₙ₊₁`.
    y: Vector3<f64>,
    /// `θ_m`, its skew matrix and `C(θ_m)`.
    theta_m: Vector3<f64>,
    theta: Matrix3<f64>,
    c: Matrix3<f64>,
    /// `I − ¼θ̂_m²` and `M = ½(Λ_m,ₙ + Λ_m,ₙ₊₁)`: the lever's factors.
    squeeze: Matrix3<f64>,
    mid: Matrix3<f64>,
    /// `θ_R = cay⁻¹(Λ_R,ₙ₊₁Λ_R,ₙᵀ)` and `θ_r = Λ_m,ₙ θ_R`.
    theta_rel: Vector3<f64>,
    theta_r: Vector3<f64>,
    /// `s = 1 − ¼ θ_m·θ_r`.
    s: f64,
}

impl StepEnds {
    fn of<J: JointKinematics + ?Sized>(
        joint: &J,
        master: [NodePose<'_>; 2],
        released: [&ReleasedState; 2],
    ) -> Self {
        let [(_, r0), (_, r1)] = master;
        let zero = [0.0; MAX_RELEASED];
        let (_, l0) = released_at(joint, released[0], &zero);
        let (rr1, l1) = released_at(joint, released[1], &zero);
        let theta_m = cayley_inverse(&mmt(r1, r0));
        let theta_rel = cayley_inverse(&mmt(&l1, &l0));
        let theta_r = r0 * theta_rel;
        let theta = skew(&theta_m);
        Self {
            r0: *r0,
            r1: *r1,
            y: r1 * rr1,
            theta_m,
            theta,
            c: cayley_tangent_inverse(&theta_m),
            squeeze: Matrix3::identity() - theta * theta * 0.25,
            mid: (r0 + r1) * 0.5,
            theta_rel,
            theta_r,
            s: 1.0 - 0.25 * theta_m.dot(&theta_r),
        }
    }

    /// `∂Ñ/∂δφᵢ`, the master's end spin (module docs); `value` is `Ñ`.
    fn spin_lane(&self, value: &JointStep, i: usize) -> JointStep {
        let (t, theta) = (&self.theta, &self.theta_m);
        let e = Vector3::ith(i, 1.0);
        let dt = self.c.column(i).into_owned();
        let dth = skew(&dt);
        let dp = dth * 0.5 + (dt * theta.transpose() + theta * dt.transpose()) * 0.25;
        JointStep {
            offset: e.cross(&self.y) * 0.5,
            lever: -(dth * t + t * dth) * self.mid * 0.25 + self.squeeze * skew(&e) * self.r1 * 0.5,
            a: (dp * self.r0 + value.a * (0.25 * dt.dot(&self.theta_r))) / self.s,
            b: SMatrix::zeros(),
        }
    }

    /// `∂Ñ/∂τₖ`, released coordinate `k` of the end state (`dr = ∂r_R`, `turn`
    /// the spin `sₖ`, `db = ∂B`): `∂d = ½ Λ_m,ₙ₊₁
    /// ∂r_R`, `∂θ_r = Λ_m,ₙ C(θ_R) sₖ`, `∂A = A (¼ θ_m·∂θ_r)/s`, `∂B` as
    /// given; the lever does not depend on it.
    fn released_lane(
        &self,
        value: &JointStep,
        dr: &Vector3<f64>,
        turn: &Vector3<f64>,
        db: SMatrix<f64, 6, MAX_RELEASED>,
    ) -> JointStep {
        let d_theta_r = self.r0 * (cayley_tangent_inverse(&self.theta_rel) * turn);
        JointStep {
            offset: self.r1 * dr * 0.5,
            lever: Matrix3::zeros(),
            a: value.a * (0.25 * self.theta_m.dot(&d_theta_r) / self.s),
            b: db,
        }
    }
}
