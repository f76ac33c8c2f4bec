//! The master–slave relation (paper eq. 1) and everything derived from it.
//!
//! A joint ties a slave node to a master node:
//!
//! ```text
//! r_s = r_m + Λ_m r_R(q)        Λ_s = Λ_m Λ_R(q)                         (1)
//! ```
//!
//! where `q` are the joint's *released* coordinates (an angle about an axis, a
//! slide, a spherical rotation), `r_R` and `Λ_R` are the released translation
//! and rotation in the master's body frame, and `Λ_m` is the master's nodal
//! rotation (identity at t = 0, so body-frame components are the global ones
//! of the initial configuration).
//!
//! A joint kind implements [`JointKinematics`] — the released translation and
//! rotation as functions of the released coordinates, generic over the scalar.
//! The blanket implementation of [`JointMap`](crate::JointMap) derives, with num-dual, the
//! variational map `N` of paper eqs 5–6 (`p_s = N p_Rm`) and the derivative of
//! `Nᵀ g` that Newton's tangent needs. No kind writes a derivative by hand.

use flexmech_core::rotation::{cayley_inverse, exp, skew};
use flexmech_core::{cst, Scalar};
use nalgebra::{Const, Matrix3, SMatrix, Vector3, Vector6, U1};
use num_dual::HyperDualSVec64;
use std::fmt::Debug;

/// Largest number of released coordinates of a joint (cylindrical: 2,
/// spherical: 3; four leaves room for user kinds).
pub const MAX_RELEASED: usize = 4;
/// Local coordinates of a joint: master increment (6) + released (≤ 4).
pub const LOCAL: usize = 6 + MAX_RELEASED;

/// The released coordinates of one joint.
///
/// Additive coordinates (angles, slides) live in `q`; their values at t = 0 in
/// `q0`. A kind with a released *rotation* of several axes (spherical) keeps
/// it in `rot`, updated multiplicatively (`rot ← exp(ω̂) rot`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReleasedState {
    /// Current released coordinates.
    pub q: [f64; MAX_RELEASED],
    /// Released coordinates of the initial configuration.
    pub q0: [f64; MAX_RELEASED],
    /// Accumulated released rotation (kinds with a multiplicative rotation).
    pub rot: Matrix3<f64>,
}

impl ReleasedState {
    /// A state whose coordinates start at `q0`.
    pub fn new(q0: [f64; MAX_RELEASED]) -> Self {
        Self {
            q: q0,
            q0,
            rot: Matrix3::identity(),
        }
    }
}

/// Increments of the released coordinates, as seen by a kind: `first` is
/// applied after `second` (for rotations: `exp(first^) exp(second^) rot`; for
/// additive coordinates the two simply add). Automatic differentiation seeds
/// them separately to obtain mixed second derivatives.
#[derive(Debug, Clone, Copy)]
pub struct Increments<'a, T> {
    /// The increment applied last (outermost).
    pub first: &'a [T],
    /// The increment applied first.
    pub second: &'a [T],
}

impl<T: Scalar> Increments<'_, T> {
    /// Coordinate `i` of the state advanced by both increments (additive kinds).
    pub fn coordinate(&self, state: &ReleasedState, i: usize) -> T {
        cst::<T>(state.q[i]) + self.first[i] + self.second[i]
    }
}

/// What a joint kind provides: the released translation `r_R` and rotation
/// `Λ_R` (master body frame) of the state advanced by the increments.
pub trait JointKinematics: Send + Sync + Debug {
    /// Number of released coordinates (≤ [`MAX_RELEASED`]).
    const RELEASED: usize;

    /// `(r_R, Λ_R)` at `state ⊕ inc`.
    fn released<T: Scalar>(
        &self,
        state: &ReleasedState,
        inc: Increments<'_, T>,
    ) -> (Vector3<T>, Matrix3<T>);

    /// Advances the state by a converged (or Newton) increment `delta`.
    /// Additive coordinates by default; kinds with a multiplicative rotation override.
    fn advance(&self, state: &mut ReleasedState, delta: &[f64]) {
        for (q, d) in state.q.iter_mut().zip(delta).take(Self::RELEASED) {
            *q += d;
        }
    }

    /// Names of the released coordinates (for messages and outputs).
    fn coordinate_names(&self) -> &'static [&'static str];

    /// The released increments of a step as linear functions of the
    /// coordinates' increments `τ`: `(u_R, θ_R) = B τ` exactly, with
    /// `u_R = r_R,ₙ₊₁ − r_R,ₙ` and `θ_R = cay⁻¹(Λ_R,ₙ₊₁ Λ_R,ₙᵀ)` (paper eq. 22;
    /// see [`crate::incremental`]). The default, for additive coordinates
    /// (`τ = qₙ₊₁ − qₙ`), is [`additive_step_map`]; a kind
    /// with a multiplicative rotation overrides it. The end state is
    /// `end ⊕ inc` (`inc` as in [`JointKinematics::released`]), so that
    /// automatic differentiation can follow `B` as the end state moves.
    fn step_map<T: Scalar>(
        &self,
        start: &ReleasedState,
        end: &ReleasedState,
        inc: &[T; MAX_RELEASED],
    ) -> SMatrix<T, 6, MAX_RELEASED> {
        additive_step_map(self, start, end, inc)
    }

    /// The released rotation angle reported as `/joints/<name>/angle`, or
    /// `None` for a kind without one (the dataset is then absent). By
    /// default the first coordinate when it is named `"angle"`.
    fn reported_angle(&self, state: &ReleasedState) -> Option<f64> {
        (self.coordinate_names().first() == Some(&"angle")).then_some(state.q[0])
    }
}

/// `exp(φ t̂)` for a unit axis `t` and an angle `φ` (one-axis released rotation).
pub fn axis_rotation<T: Scalar>(axis: &Vector3<f64>, angle: T) -> Matrix3<T> {
    exp(&(axis.map(cst::<T>) * angle))
}

/// `â` for an `f64` vector (re-exported for the joint kinds' closed forms).
pub fn hat(a: &Vector3<f64>) -> Matrix3<f64> {
    skew(a)
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
/// `τₖ = qₖ,ₙ₊₁ − qₖ,ₙ` (the end state is `end ⊕ inc`). The columns
/// telescope, so `B τ = F(qₙ₊₁)` exactly; increments below `1e-6` use
/// `F′(Pₖ₋₁) + ½F″(Pₖ₋₁)τₖ` (hyper-dual numbers) so the column stays accurate
/// as `τₖ → 0` and tends to `N`'s column. The Taylor column follows `τₖ`
/// exactly under automatic differentiation; for `k ≥ 1` its dependence on the
/// earlier coordinates' end values (through `Pₖ₋₁`) is not followed.
pub fn additive_step_map<J: JointKinematics + ?Sized, T: Scalar>(
    joint: &J,
    start: &ReleasedState,
    end: &ReleasedState,
    inc: &[T; MAX_RELEASED],
) -> SMatrix<T, 6, MAX_RELEASED> {
    type H = HyperDualSVec64<1, 1>;
    let (r_n, l_n) = released_at(joint, start, &[0.0; MAX_RELEASED]);
    let tau: [T; MAX_RELEASED] = std::array::from_fn(|k| cst::<T>(end.q[k] - start.q[k]) + inc[k]);
    // F at the path point with the first `upto` coordinates at their end values.
    let f = |upto: usize| -> Vector6<T> {
        let d: [T; MAX_RELEASED] =
            std::array::from_fn(|i| if i < upto { tau[i] } else { T::zero() });
        let (r, l) = released_at(joint, start, &d);
        stack(
            &(r - r_n.map(cst::<T>)),
            &cayley_inverse(&(l * l_n.map(cst::<T>).transpose())),
        )
    };
    let mut b = SMatrix::<T, 6, MAX_RELEASED>::zeros();
    for k in 0..J::RELEASED {
        let column: Vector6<T> = if tau[k].value().abs() >= TAYLOR_BELOW {
            (f(k + 1) - f(k)) / tau[k]
        } else {
            let mut d = [H::from_re(0.0); MAX_RELEASED];
            for (i, di) in d.iter_mut().enumerate().take(k) {
                *di = H::from_re(tau[i].value());
            }
            d[k] = H::from_re(0.0).derivative1(0).derivative2(0);
            let (r, l) = released_at(joint, start, &d);
            let dr = r - r_n.map(H::from_re);
            let th = cayley_inverse(&(l * l_n.map(H::from_re).transpose()));
            let d1 = |v: H| v.eps1.unwrap_generic(Const::<1>, U1)[0];
            let d2 = |v: H| v.eps1eps2.unwrap_generic(Const::<1>, Const::<1>)[0];
            let taylor = |v: H| cst::<T>(d1(v)) + tau[k] * cst::<T>(0.5 * d2(v));
            stack(&dr.map(taylor), &th.map(taylor))
        };
        b.set_column(k, &column);
    }
    b
}

pub(crate) fn released_at<J: JointKinematics + ?Sized, T: Scalar>(
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

fn stack<T: Scalar>(a: &Vector3<T>, b: &Vector3<T>) -> Vector6<T> {
    Vector6::new(a.x, a.y, a.z, b.x, b.y, b.z)
}
