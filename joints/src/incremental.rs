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
    Increments, JointKinematics, JointMap, ReleasedState, LOCAL, MAX_RELEASED,
};
use flexmech_core::rotation::{cayley_inverse, skew};
use flexmech_core::Scalar;
use nalgebra::{Const, Matrix3, SMatrix, SVector, Vector3, Vector6, U1};
use num_dual::HyperDualSVec64;

/// A node's pose: position and rotation.
pub type NodePose<'a> = (&'a Vector3<f64>, &'a Matrix3<f64>);

/// The incremental map `Ñ` of one joint over one step (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct JointStep {
    /// Mid-step slave offset `d = x̄_s − x̄_m`.
    pub offset: Vector3<f64>,
    /// `(I − ¼θ̂_m²) Λ̄_m`: released translation increment → slave displacement.
    pub lever: Matrix3<f64>,
    /// `A`: released rotation increment → slave rotation increment.
    pub a: Matrix3<f64>,
    /// `B`: released increments `τ` → `(u_R, θ_R)`.
    pub b: SMatrix<f64, 6, MAX_RELEASED>,
}

impl JointStep {
    /// `Ñ` of joint `map` for the master's poses at both ends of the step and
    /// the released states at both ends.
    pub fn new(
        map: &dyn JointMap,
        master: [NodePose<'_>; 2],
        released: [&ReleasedState; 2],
    ) -> Self {
        let [(x0, r0), (x1, r1)] = master;
        let theta_m = cayley_inverse(&(r1 * r0.transpose()));
        let (xs0, _) = map.slave(x0, r0, released[0]);
        let (xs1, _) = map.slave(x1, r1, released[1]);
        let offset = (xs0 + xs1 - x0 - x1) * 0.5;
        let tm = skew(&theta_m);
        let lever = (Matrix3::identity() - tm * tm * 0.25) * ((r0 + r1) * 0.5);
        let (_, l0) = map.released_placement(released[0]);
        let (_, l1) = map.released_placement(released[1]);
        let theta_r = r0 * cayley_inverse(&(l1 * l0.transpose()));
        let a = (Matrix3::identity() + tm * 0.5 + theta_m * theta_m.transpose() * 0.25) * r0
            / (1.0 - 0.25 * theta_m.dot(&theta_r));
        Self {
            offset,
            lever,
            a,
            b: map.step_map(released[0], released[1]),
        }
    }

    /// `Ñ` as a matrix over the local increments `(u_m, θ_m, τ)` (the column
    /// layout of [`crate::JointMap::variation`]).
    pub fn matrix(&self) -> SMatrix<f64, 6, LOCAL> {
        let mut n = SMatrix::<f64, 6, LOCAL>::zeros();
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
    pub fn transfer(&self, g: &Vector6<f64>) -> SVector<f64, LOCAL> {
        let f = g.fixed_rows::<3>(0).into_owned();
        let m = g.fixed_rows::<3>(3).into_owned();
        let mut out = SVector::<f64, LOCAL>::zeros();
        out.fixed_rows_mut::<3>(0).copy_from(&f);
        out.fixed_rows_mut::<3>(3)
            .copy_from(&(self.offset.cross(&f) + m));
        let mut h = Vector6::zeros();
        h.fixed_rows_mut::<3>(0)
            .copy_from(&(self.lever.transpose() * f));
        h.fixed_rows_mut::<3>(3)
            .copy_from(&(self.a.transpose() * m));
        out.fixed_rows_mut::<MAX_RELEASED>(6)
            .copy_from(&(self.b.transpose() * h));
        out
    }
}

/// Below this size a coordinate increment's column of `B` comes from a
/// second-order Taylor expansion instead of the difference quotient: the
/// quotient's cancellation error is then ≤ eps/1e-6 ≈ 2e-10 relative, and the
/// expansion's `f‴τ³/6` misses the increment by < 2e-19·f‴, below round-off.
const TAYLOR_BELOW: f64 = 1e-6;

/// `B` for kinds with additive coordinates (the default of
/// [`JointKinematics::step_map`]): along the path that changes one coordinate
/// after the other, `F(q) = (r_R(q) − r_R(qₙ), cay⁻¹(Λ_R(q) Λ_R(qₙ)ᵀ))`,
/// column `k` is the divided difference `(F(Pₖ) − F(Pₖ₋₁))/τₖ` with
/// `τₖ = qₖ,ₙ₊₁ − qₖ,ₙ`. The columns telescope, so `B τ = F(qₙ₊₁)` exactly;
/// increments below `1e-6` use `F′ + ½F″τₖ` (hyper-dual numbers) so the
/// column stays accurate as `τₖ → 0` and tends to `N`'s column.
pub fn additive_step_map<J: JointKinematics + ?Sized>(
    joint: &J,
    start: &ReleasedState,
    end: &ReleasedState,
) -> SMatrix<f64, 6, MAX_RELEASED> {
    type H = HyperDualSVec64<1, 1>;
    let (r_n, l_n) = released_at(joint, start, &[0.0; MAX_RELEASED]);
    let mut b = SMatrix::<f64, 6, MAX_RELEASED>::zeros();
    let mut point = *start;
    for k in 0..J::RELEASED {
        let tau = end.q[k] - start.q[k];
        let column: Vector6<f64> = if tau.abs() >= TAYLOR_BELOW {
            let f = |p: &ReleasedState| {
                let (r, l) = released_at(joint, p, &[0.0; MAX_RELEASED]);
                stack(&(r - r_n), &cayley_inverse(&(l * l_n.transpose())))
            };
            let mut next = point;
            next.q[k] = end.q[k];
            (f(&next) - f(&point)) / tau
        } else {
            let mut inc = [H::from_re(0.0); MAX_RELEASED];
            inc[k] = H::from_re(0.0).derivative1(0).derivative2(0);
            let (r, l) = released_at(joint, &point, &inc);
            let dr = r - r_n.map(H::from_re);
            let th = cayley_inverse(&(l * l_n.map(H::from_re).transpose()));
            let d1 = |v: H| v.eps1.unwrap_generic(Const::<1>, U1)[0];
            let d2 = |v: H| v.eps1eps2.unwrap_generic(Const::<1>, Const::<1>)[0];
            let taylor = |v: H| d1(v) + 0.5 * d2(v) * tau;
            stack(&dr.map(taylor), &th.map(taylor))
        };
        b.set_column(k, &column);
        point.q[k] = end.q[k];
    }
    b
}

fn released_at<J: JointKinematics + ?Sized, T: Scalar>(
    joint: &J,
    state: &ReleasedState,
    first: &[T; MAX_RELEASED],
) -> (Vector3<T>, Matrix3<T>) {
    let zero = [T::zero(); MAX_RELEASED];
    joint.released(
        state,
        Increments {
            first,
            second: &zero,
        },
    )
}

fn stack(a: &Vector3<f64>, b: &Vector3<f64>) -> Vector6<f64> {
    Vector6::new(a.x, a.y, a.z, b.x, b.y, b.z)
}
