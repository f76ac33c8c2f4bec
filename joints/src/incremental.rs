//! Exact incremental relations of a joint over a time step, for the
//! momentum- and energy–momentum-conserving schemes (paper eqs 21–23,
//! FORMULATION §4.4 "Joints in the conserving schemes").
//!
//! Over a step `n → n+1` the slave's increments `p_s = (u_s, θ_s)` — the
//! displacement and the tangent-scaled rotation increment
//! `Λ_s,ₙ₊₁ = cay(θ_s) Λ_s,ₙ` — follow *exactly* from the master's `(u_m, θ_m)`
//! and the released increments `τ`:
//!
//! ```text
//! u_s = u_m + (I − ¼θ̂_m²) Λ̄_m u_R − d̂ θ_m,     d = x̄_s − x̄_m          (21)
//! θ_s = θ_m + A θ_R,   A = (I + ½θ̂_m + ¼θ_m⊗θ_m) Λ_m,ₙ / (1 − ¼ θ_m·θ_r)
//! ```
//!
//! with `Λ̄_m = ½(Λ_m,ₙ + Λ_m,ₙ₊₁)`, `u_R = r_R,ₙ₊₁ − r_R,ₙ`,
//! `θ_R = cay⁻¹(Λ_R,ₙ₊₁ Λ_R,ₙᵀ)` (master body frame) and `θ_r = Λ_m,ₙ θ_R`.
//! The released increments are linear in `τ`, `(u_R, θ_R) = B τ`
//! ([`crate::JointMap::step_map`]; for a dependent joint `u_R = G θ_R`, the
//! secant of eq. 22). Hence `p_s = Ñ (u_m, θ_m, τ)`, and the reduced equations
//! `Ñᵀ g = 0` make `Σ pᵢ·gᵢ` vanish over all nodes: the discrete energy balance
//! of the beams (eq. 23) carries over to the joined system.
//!
//! Compared with the paper's `D = −(Λ̄_m r̄_R)^`, the lever here is the
//! averaged slave offset `d = x̄_s − x̄_m = Λ̄_m r̄_R + ¼ θ_m × Λ̄_m u_R`, and the
//! `¼θ_m × (θ_m × ·)` term moves into the released column (the relation stays
//! exact). With `d` the master's moment equation receives `d × g_s,u`, so the
//! reaction's moment is taken about the mid-step positions, as the beams'
//! internal forces are: linear *and* angular momentum are conserved exactly.

use crate::kinematics::{
    released_at, released_count, JointKinematics, ReleasedState, LOCAL, MAX_RELEASED,
};
use flexmech_core::rotation::{cayley_inverse, exp, mm, mmt, mtv, mv, skew, skew_squared};
use flexmech_core::{cst, Scalar};
use nalgebra::{Const, Matrix3, SMatrix, SVector, Vector3, Vector6, U1};
use num_dual::{Derivative, DualSVec64};

/// The dual number of a step map seeded along the step's end state: one lane
/// per local increment `(δx, δφ, τ)` of [`JointStep::of`]'s seed.
pub type StepDual = DualSVec64<LOCAL>;

/// A node's pose: position and rotation.
pub type NodePose<'a> = (&'a Vector3<f64>, &'a Matrix3<f64>);

/// The incremental map `Ñ` of one joint over one step (see the module docs),
/// generic over the scalar so that its derivative with respect to the end
/// state comes by automatic differentiation.
#[derive(Debug, Clone, PartialEq)]
pub struct JointStep<T: Scalar = f64> {
    /// Mid-step slave offset `d = x̄_s − x̄_m`.
    pub offset: Vector3<T>,
    /// `(I − ¼θ̂_m²) Λ̄_m`: released translation increment → slave displacement.
    pub lever: Matrix3<T>,
    /// `A`: released rotation increment → slave rotation increment.
    pub a: Matrix3<T>,
    /// `B`: released increments `τ` → `(u_R, θ_R)`.
    pub b: SMatrix<T, 6, MAX_RELEASED>,
}

impl<T: Scalar> JointStep<T> {
    /// The map with `f` applied to every entry.
    pub fn map<U: Scalar>(&self, f: impl Fn(T) -> U) -> JointStep<U> {
        JointStep {
            offset: self.offset.map(&f),
            lever: self.lever.map(&f),
            a: self.a.map(&f),
            b: self.b.map(&f),
        }
    }

    /// The map whose entries are all zero.
    pub fn zeros() -> Self {
        Self {
            offset: Vector3::zeros(),
            lever: Matrix3::zeros(),
            a: Matrix3::zeros(),
            b: SMatrix::zeros(),
        }
    }

    /// `Ñ` of `joint` over a step whose end is seeded: the master's end pose
    /// `(x₁ + δx, exp(δφ̂) R₁)` and the released end state `end ⊕ inc`, with
    /// `δ = (δx, δφ)` given as `seed`.
    pub fn of<J: JointKinematics + ?Sized>(
        joint: &J,
        master: [NodePose<'_>; 2],
        released: [&ReleasedState; 2],
        seed: &[T; 6],
        inc: &[T; MAX_RELEASED],
    ) -> Self {
        let b = joint.step_map(released[0], released[1], inc);
        let from = ([T::zero(); 6], [T::zero(); MAX_RELEASED]);
        Self::with_map(joint, master, released, (&from.0, &from.1), (seed, inc), b)
    }

    /// [`Self::of`] with the step's start seeded too: the master's start pose
    /// `(x₀ + δx₀, exp(δφ̂₀) R₀)` with `from.0 = (δx₀, δφ₀)` and the released
    /// start state `start ⊕ from.1` — the derivative of `Ñ` along the start
    /// state (exact sensitivities through the conserving schemes). `None`
    /// where the kind's coordinates do not provide `B` from a seeded start.
    pub fn of_from<J: JointKinematics + ?Sized>(
        joint: &J,
        master: [NodePose<'_>; 2],
        released: [&ReleasedState; 2],
        from: (&[T; 6], &[T; MAX_RELEASED]),
        seed: &[T; 6],
        inc: &[T; MAX_RELEASED],
    ) -> Option<Self> {
        let b = joint.step_map_from(released[0], released[1], from.1, inc)?;
        Some(Self::with_map(
            joint,
            master,
            released,
            from,
            (seed, inc),
            b,
        ))
    }

    /// `Ñ` from the seeded ends and the step's `B`.
    pub(crate) fn with_map<J: JointKinematics + ?Sized>(
        joint: &J,
        master: [NodePose<'_>; 2],
        released: [&ReleasedState; 2],
        from: (&[T; 6], &[T; MAX_RELEASED]),
        (seed, inc): (&[T; 6], &[T; MAX_RELEASED]),
        b: SMatrix<T, 6, MAX_RELEASED>,
    ) -> Self {
        let [(x0, r0), (x1, r1)] = master;
        let x0 = x0.map(cst::<T>) + Vector3::new(from.0[0], from.0[1], from.0[2]);
        // Products written out (`mm`, `mmt`, `mv`): nalgebra's general
        // product multiplies every term by a unit dual number besides.
        let r0 = spun(&Vector3::new(from.0[3], from.0[4], from.0[5]), r0);
        let x1 = x1.map(cst::<T>) + Vector3::new(seed[0], seed[1], seed[2]);
        let r1 = spun(&Vector3::new(seed[3], seed[4], seed[5]), r1);
        let theta_m = cayley_inverse(&mmt(&r1, &r0));
        let (rr0, l0) = released_at(joint, released[0], from.1);
        let (rr1, l1) = released_at(joint, released[1], inc);
        let (xs0, xs1) = (x0 + mv(&r0, &rr0), x1 + mv(&r1, &rr1));
        let half = cst::<T>(0.5);
        let quarter = cst::<T>(0.25);
        let offset = (xs0 + xs1 - x0 - x1) * half;
        let tm = skew(&theta_m);
        let lever = mm(
            &(Matrix3::identity() - mm(&tm, &tm) * quarter),
            &((r0 + r1) * half),
        );
        let theta_r = mv(&r0, &cayley_inverse(&mmt(&l1, &l0)));
        let outer = Matrix3::from_fn(|i, j| theta_m[i] * theta_m[j]);
        let a = mm(&(Matrix3::identity() + tm * half + outer * quarter), &r0)
            / (T::one() - theta_m.dot(&theta_r) * quarter);
        Self {
            offset,
            lever,
            a,
            b,
        }
    }

    /// `Ñ` as a matrix over the local increments `(u_m, θ_m, τ)` (the column
    /// layout of [`crate::JointMap::variation`]).
    pub fn matrix(&self) -> SMatrix<T, 6, LOCAL> {
        let mut n = SMatrix::<T, 6, LOCAL>::zeros();
        n.fixed_view_mut::<3, 3>(0, 0)
            .copy_from(&Matrix3::identity());
        n.fixed_view_mut::<3, 3>(0, 3)
            .copy_from(&(-skew(&self.offset)));
        n.fixed_view_mut::<3, 3>(3, 3)
            .copy_from(&Matrix3::identity());
        let bu = self.b.fixed_rows::<3>(0);
        let bt = self.b.fixed_rows::<3>(3);
        n.fixed_view_mut::<3, MAX_RELEASED>(0, 6)
            .copy_from(&(self.lever * bu));
        n.fixed_view_mut::<3, MAX_RELEASED>(3, 6)
            .copy_from(&(self.a * bt));
        n
    }

    /// `Ñᵀ g` for the slave's nodal residual `g = (force, moment)`: the
    /// master receives the force and the moment `d × force + moment`; the
    /// released equations `Bᵀ (leverᵀ force, Aᵀ moment)`.
    pub fn transfer(&self, g: &Vector6<T>) -> SVector<T, LOCAL> {
        let f = g.fixed_rows::<3>(0).into_owned();
        let m = g.fixed_rows::<3>(3).into_owned();
        let mut out = SVector::<T, LOCAL>::zeros();
        out.fixed_rows_mut::<3>(0).copy_from(&f);
        out.fixed_rows_mut::<3>(3)
            .copy_from(&(self.offset.cross(&f) + m));
        // Written out (see `with_map`).
        let (lf, am) = (mtv(&self.lever, &f), mtv(&self.a, &m));
        let h = [lf.x, lf.y, lf.z, am.x, am.y, am.z];
        for j in 0..MAX_RELEASED {
            out[6 + j] = (0..6).fold(T::zero(), |acc, i| acc + self.b[(i, j)] * h[i]);
        }
        out
    }
}

/// `exp(ŝ) R`. A seed `s` with no real part (a pure derivative direction)
/// takes `exp(ŝ) = I + ŝ + ½ŝ²`, exact through second derivatives, instead
/// of the exponential's series in dual numbers.
fn spun<T: Scalar>(s: &Vector3<T>, r: &Matrix3<f64>) -> Matrix3<T> {
    let rotation = if s.iter().all(|v| v.value() == 0.0) {
        Matrix3::identity() + skew(s) + skew_squared(s) * cst::<T>(0.5)
    } else {
        exp(s)
    };
    mm(&rotation, &r.map(cst::<T>))
}

impl JointStep<StepDual> {
    /// The seeded map `Ñ(δx, δφ, τ)` of `joint` over a step: the master's end
    /// pose and the released end state moved along the local increments, one
    /// AD lane each (see [`Self::of`]).
    ///
    /// `Ñ` does not depend on the master's end position: it enters the
    /// offset as `x_s,ₙ₊₁ − x_m,ₙ₊₁ = Λ_m,ₙ₊₁ r_R,ₙ₊₁` and nowhere else. So
    /// the map is computed over the lanes of `δφ` and of the kind's released
    /// coordinates only (4 for a one-coordinate kind instead of 10) and
    /// widened; the lanes of `δx` are zero.
    pub fn seeded<J: JointKinematics + ?Sized>(
        joint: &J,
        master: [NodePose<'_>; 2],
        released: [&ReleasedState; 2],
    ) -> Self {
        match released_count::<J>() {
            0 => seeded_over::<J, 3>(joint, master, released),
            1 => seeded_over::<J, 4>(joint, master, released),
            2 => seeded_over::<J, 5>(joint, master, released),
            3 => seeded_over::<J, 6>(joint, master, released),
            _ => seeded_over::<J, { 3 + MAX_RELEASED }>(joint, master, released),
        }
    }

    /// The real parts: `Ñ` itself, equal to the unseeded map to round-off
    /// (a dual division multiplies by the reciprocal).
    pub fn value(&self) -> JointStep<f64> {
        self.map(|v| v.re)
    }

    /// `Ñᵀ g` for a slave residual `g` held fixed and its derivative with
    /// respect to the step's end state, from the seeded map; the columns and
    /// rows of the released coordinates past `released` are zero.
    pub fn seeded_transfer(
        &self,
        g: &Vector6<f64>,
        released: usize,
    ) -> (SVector<f64, LOCAL>, SMatrix<f64, LOCAL, LOCAL>) {
        let t = self.transfer(&g.map(StepDual::from_re));
        let mut value = t.map(|v| v.re);
        let mut k = SMatrix::<f64, LOCAL, LOCAL>::zeros();
        for r in 0..LOCAL {
            k.set_row(r, &t[r].eps.unwrap_generic(Const::<LOCAL>, U1).transpose());
        }
        for c in 6 + released..LOCAL {
            value[c] = 0.0;
            k.row_mut(c).fill(0.0);
            k.column_mut(c).fill(0.0);
        }
        (value, k)
    }
}

/// [`JointStep::seeded`] over `L` lanes: `δφ` in lanes 0–2, the first
/// `L − 3` released coordinates after them.
fn seeded_over<J: JointKinematics + ?Sized, const L: usize>(
    joint: &J,
    master: [NodePose<'_>; 2],
    released: [&ReleasedState; 2],
) -> JointStep<StepDual> {
    type D<const L: usize> = DualSVec64<L>;
    let e: [D<L>; L] = std::array::from_fn(|i| D::<L>::from_re(0.0).derivative(i));
    let seed: [D<L>; 6] = std::array::from_fn(|i| {
        if i < 3 {
            D::<L>::from_re(0.0)
        } else {
            e[i - 3]
        }
    });
    let inc: [D<L>; MAX_RELEASED] = std::array::from_fn(|k| {
        if 3 + k < L {
            e[3 + k]
        } else {
            D::<L>::from_re(0.0)
        }
    });
    let step = JointStep::of(joint, master, released, &seed, &inc);
    // Lane `i` of `L` is local lane `3 + i`.
    let widen = |v: D<L>| {
        let eps = v.eps.0.map(|eps| {
            let mut out = SVector::<f64, LOCAL>::zeros();
            out.fixed_rows_mut::<L>(3).copy_from(&eps);
            out
        });
        StepDual::new(v.re, Derivative::new(eps))
    };
    JointStep {
        offset: step.offset.map(widen),
        lever: step.lever.map(widen),
        a: step.a.map(widen),
        b: step.b.map(widen),
    }
}
