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

use crate::kinematics::{released_at, JointKinematics, ReleasedState, LOCAL, MAX_RELEASED};
use flexmech_core::rotation::{cayley_inverse, exp, mm, mmt, mtv, mv, skew};
use flexmech_core::{cst, Scalar};
use nalgebra::{Matrix3, SMatrix, SVector, Vector3, Vector6};

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
    fn with_map<J: JointKinematics + ?Sized>(
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
        let r0 = mm(
            &exp(&Vector3::new(from.0[3], from.0[4], from.0[5])),
            &r0.map(cst::<T>),
        );
        let x1 = x1.map(cst::<T>) + Vector3::new(seed[0], seed[1], seed[2]);
        let r1 = mm(
            &exp(&Vector3::new(seed[3], seed[4], seed[5])),
            &r1.map(cst::<T>),
        );
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
