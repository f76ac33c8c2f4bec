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

use flexmech_core::rotation::{cayley_inverse, exp, log, mmt, skew};
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

/// What a kind's released coordinates are: how many, their names, how a
/// state advanced by increments looks to the kind ([`Coordinates::At`]), how
/// a converged increment moves the state and how a step's released motion
/// depends on the coordinates' increments (`B`, paper eq. 22).
///
/// The solvers keep every joint's coordinates in one storage type,
/// [`ReleasedState`]; a kind never reads it: it sees its own typed
/// coordinates — an angle, a slide, both, a rotation, or none — through the
/// kind's associated type [`JointKinematics::Coordinates`], and automatic
/// differentiation seeds the increments inside [`Coordinates::at`].
pub trait Coordinates: Send + Sync + 'static {
    /// Number of released coordinates (≤ [`MAX_RELEASED`]).
    const COUNT: usize;
    /// Their names (messages and outputs); a first coordinate named
    /// `"angle"` is the released rotation angle ψ that model files set and
    /// drive.
    const NAMES: &'static [&'static str];
    /// The coordinates of `state ⊕ inc` as the kind sees them.
    type At<T: Scalar>;

    /// The coordinates of the state advanced by `inc`.
    fn at<T: Scalar>(state: &ReleasedState, inc: Increments<'_, T>) -> Self::At<T>;

    /// Advances the state by a converged (or Newton) increment `delta`:
    /// additive by default.
    fn advance(state: &mut ReleasedState, delta: &[f64]) {
        for (q, d) in state.q.iter_mut().zip(delta).take(Self::COUNT) {
            *q += d;
        }
    }

    /// `B` with `(u_R, θ_R) = B τ` over a step (see
    /// [`JointKinematics::step_map`]): [`additive_step_map`] by default.
    fn step_map<J: JointKinematics + ?Sized, T: Scalar>(
        joint: &J,
        start: &ReleasedState,
        end: &ReleasedState,
        inc: &[T; MAX_RELEASED],
    ) -> SMatrix<T, 6, MAX_RELEASED> {
        additive_step_map(joint, start, end, inc)
    }

    /// `B` for a step whose start is `start ⊕ from` (`from` seeded for the
    /// derivative along the start state: exact sensitivities through the
    /// conserving schemes); `None`, the default, where the coordinates do
    /// not provide it.
    fn step_map_from<J: JointKinematics + ?Sized, T: Scalar>(
        _joint: &J,
        _start: &ReleasedState,
        _end: &ReleasedState,
        _from: &[T; MAX_RELEASED],
        _inc: &[T; MAX_RELEASED],
    ) -> Option<SMatrix<T, 6, MAX_RELEASED>> {
        None
    }

    /// The angle reported as `/joints/<name>/angle`: the first coordinate
    /// when it is the angle, else none.
    fn reported_angle(state: &ReleasedState) -> Option<f64> {
        (Self::NAMES.first() == Some(&"angle")).then_some(state.q[0])
    }
}

/// [`Coordinates::step_map_from`] of additive coordinates.
macro_rules! additive_from {
    () => {
        fn step_map_from<J: JointKinematics + ?Sized, T: Scalar>(
            joint: &J,
            start: &ReleasedState,
            end: &ReleasedState,
            from: &[T; MAX_RELEASED],
            inc: &[T; MAX_RELEASED],
        ) -> Option<SMatrix<T, 6, MAX_RELEASED>> {
            Some(additive_step_map_from(joint, start, end, from, inc))
        }
    };
}

/// A released rotation angle ψ about a fixed axis, with its value at t = 0.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AngleAt<T> {
    /// ψ.
    pub angle: T,
    /// ψ₀.
    pub initial: f64,
}

impl<T: Scalar> AngleAt<T> {
    /// The turn since t = 0, `ψ − ψ₀` (the released rotation is
    /// `exp((ψ − ψ₀) t̂)`: the identity at the initial angle).
    pub fn turn(&self) -> T {
        self.angle - cst::<T>(self.initial)
    }
}

/// No released coordinate (rigid joints).
#[derive(Debug, Clone, Copy)]
pub struct NoCoordinates;

impl Coordinates for NoCoordinates {
    const COUNT: usize = 0;
    const NAMES: &'static [&'static str] = &[];
    type At<T: Scalar> = ();
    fn at<T: Scalar>(_: &ReleasedState, _: Increments<'_, T>) {}
    additive_from!();
}

/// One released angle ψ (revolute, screw, rack-and-pinion, cam, lobe).
#[derive(Debug, Clone, Copy)]
pub struct Angle;

impl Coordinates for Angle {
    const COUNT: usize = 1;
    const NAMES: &'static [&'static str] = &["angle"];
    type At<T: Scalar> = AngleAt<T>;
    fn at<T: Scalar>(state: &ReleasedState, inc: Increments<'_, T>) -> AngleAt<T> {
        AngleAt {
            angle: inc.coordinate(state, 0),
            initial: state.q0[0],
        }
    }
    additive_from!();
}

/// One released translation `s` (prismatic).
#[derive(Debug, Clone, Copy)]
pub struct Slide;

impl Coordinates for Slide {
    const COUNT: usize = 1;
    const NAMES: &'static [&'static str] = &["slide"];
    type At<T: Scalar> = T;
    fn at<T: Scalar>(state: &ReleasedState, inc: Increments<'_, T>) -> T {
        inc.coordinate(state, 0)
    }
    additive_from!();
}

/// A released angle and a released translation (cylindrical).
#[derive(Debug, Clone, Copy)]
pub struct AngleSlide;

impl Coordinates for AngleSlide {
    const COUNT: usize = 2;
    const NAMES: &'static [&'static str] = &["angle", "slide"];
    type At<T: Scalar> = (AngleAt<T>, T);
    fn at<T: Scalar>(state: &ReleasedState, inc: Increments<'_, T>) -> (AngleAt<T>, T) {
        (
            AngleAt {
                angle: inc.coordinate(state, 0),
                initial: state.q0[0],
            },
            inc.coordinate(state, 1),
        )
    }
    additive_from!();
}

/// A released rotation of three axes (spherical), kept as a matrix and
/// updated multiplicatively, `Λ_R ← exp(ω̂) Λ_R` with `ω` in the master
/// body frame: the kind sees `Λ_R ⊕ inc = exp(first^) exp(second^) Λ_R`.
#[derive(Debug, Clone, Copy)]
pub struct BallRotation;

impl Coordinates for BallRotation {
    const COUNT: usize = 3;
    const NAMES: &'static [&'static str] = &["rx", "ry", "rz"];
    type At<T: Scalar> = Matrix3<T>;
    fn at<T: Scalar>(state: &ReleasedState, inc: Increments<'_, T>) -> Matrix3<T> {
        let a = Vector3::new(inc.first[0], inc.first[1], inc.first[2]);
        let b = Vector3::new(inc.second[0], inc.second[1], inc.second[2]);
        exp(&a) * exp(&b) * state.rot.map(cst::<T>)
    }

    fn advance(state: &mut ReleasedState, delta: &[f64]) {
        state.rot = exp(&Vector3::new(delta[0], delta[1], delta[2])) * state.rot;
    }

    /// The released increment is the rotation increment itself: `τ = θ_R`,
    /// `B = [0; I]`.
    fn step_map<J: JointKinematics + ?Sized, T: Scalar>(
        _joint: &J,
        _start: &ReleasedState,
        _end: &ReleasedState,
        _inc: &[T; MAX_RELEASED],
    ) -> SMatrix<T, 6, MAX_RELEASED> {
        let mut b = SMatrix::<T, 6, MAX_RELEASED>::zeros();
        b.fixed_view_mut::<3, 3>(3, 0)
            .copy_from(&Matrix3::identity());
        b
    }

    /// `B = [0; I]` whatever the start.
    fn step_map_from<J: JointKinematics + ?Sized, T: Scalar>(
        joint: &J,
        start: &ReleasedState,
        end: &ReleasedState,
        _from: &[T; MAX_RELEASED],
        inc: &[T; MAX_RELEASED],
    ) -> Option<SMatrix<T, 6, MAX_RELEASED>> {
        Some(Self::step_map(joint, start, end, inc))
    }

    /// The magnitude of the released rotation.
    fn reported_angle(state: &ReleasedState) -> Option<f64> {
        Some(log(&state.rot).norm())
    }
}

/// The coordinates of kind `J` as it sees them.
pub type CoordinatesOf<J, T> = <<J as JointKinematics>::Coordinates as Coordinates>::At<T>;

/// What a joint kind provides: its coordinates' type and the released
/// translation `r_R` and rotation `Λ_R` (master body frame) as functions of
/// them, for any scalar. Everything else has a default from the coordinates'
/// type.
pub trait JointKinematics: Send + Sync + Debug {
    /// The kind's released coordinates ([`Angle`], [`Slide`],
    /// [`AngleSlide`], [`BallRotation`], [`NoCoordinates`], or a type of
    /// the author's).
    type Coordinates: Coordinates;

    /// `(r_R, Λ_R)` at the coordinates `q`.
    fn released<T: Scalar>(&self, q: &CoordinatesOf<Self, T>) -> (Vector3<T>, Matrix3<T>);

    /// `(r_R, Λ_R)` at `state ⊕ inc` (what the derived maps evaluate; the
    /// increments are where automatic differentiation seeds).
    fn released_at_state<T: Scalar>(
        &self,
        state: &ReleasedState,
        inc: Increments<'_, T>,
    ) -> (Vector3<T>, Matrix3<T>) {
        self.released(&<Self::Coordinates as Coordinates>::at(state, inc))
    }

    /// Advances the state by a converged (or Newton) increment `delta`.
    fn advance(&self, state: &mut ReleasedState, delta: &[f64]) {
        <Self::Coordinates as Coordinates>::advance(state, delta)
    }

    /// `∂r_R/∂p` and `∂²r_R/∂q₁∂p` at `state` for the kind's real parameter
    /// `name` (see [`crate::DependentJoint::translation_by`]). Default:
    /// `None`.
    fn parameter_derivative(
        &self,
        _name: &str,
        _state: &ReleasedState,
    ) -> Option<[Vector3<f64>; 2]> {
        None
    }

    /// Names of the released coordinates (for messages and outputs).
    fn coordinate_names(&self) -> &'static [&'static str] {
        <Self::Coordinates as Coordinates>::NAMES
    }

    /// The released increments of a step as linear functions of the
    /// coordinates' increments `τ`: `(u_R, θ_R) = B τ` exactly, with
    /// `u_R = r_R,ₙ₊₁ − r_R,ₙ` and `θ_R = cay⁻¹(Λ_R,ₙ₊₁ Λ_R,ₙᵀ)` (paper eq. 22;
    /// see [`crate::incremental`]). The coordinates' type gives it: for
    /// additive coordinates (`τ = qₙ₊₁ − qₙ`) [`additive_step_map`], for a
    /// multiplicative rotation `[0; I]`. The end state is `end ⊕ inc` (`inc`
    /// as in [`JointKinematics::released_at_state`]), so that automatic
    /// differentiation can follow `B` as the end state moves.
    fn step_map<T: Scalar>(
        &self,
        start: &ReleasedState,
        end: &ReleasedState,
        inc: &[T; MAX_RELEASED],
    ) -> SMatrix<T, 6, MAX_RELEASED> {
        <Self::Coordinates as Coordinates>::step_map(self, start, end, inc)
    }

    /// `B` for a step from `start ⊕ from` (see [`Coordinates::step_map_from`]).
    fn step_map_from<T: Scalar>(
        &self,
        start: &ReleasedState,
        end: &ReleasedState,
        from: &[T; MAX_RELEASED],
        inc: &[T; MAX_RELEASED],
    ) -> Option<SMatrix<T, 6, MAX_RELEASED>> {
        <Self::Coordinates as Coordinates>::step_map_from(self, start, end, from, inc)
    }

    /// The released rotation angle reported as `/joints/<name>/angle`, or
    /// `None` for a kind without one (the dataset is then absent).
    fn reported_angle(&self, state: &ReleasedState) -> Option<f64> {
        <Self::Coordinates as Coordinates>::reported_angle(state)
    }
}

/// Number of released coordinates of kind `J`.
pub fn released_count<J: JointKinematics + ?Sized>() -> usize {
    <J::Coordinates as Coordinates>::COUNT
}

/// `exp(φ t̂)` for a unit axis `t` and an angle `φ` (one-axis released
/// rotation), by Rodrigues' formula `I + sin φ t̂ + (1 − cos φ) t̂²`: one sine
/// and one cosine of the (dual) angle times constant matrices, where the
/// general `exp` of the vector `φt` would take its norm and series in duals.
pub fn axis_rotation<T: Scalar>(axis: &Vector3<f64>, angle: T) -> Matrix3<T> {
    let t = skew(axis);
    let t2 = t * t;
    let (s, c) = (angle.sin(), T::one() - angle.cos());
    Matrix3::from_fn(|i, j| {
        let id = if i == j { T::one() } else { T::zero() };
        id + s * cst::<T>(t[(i, j)]) + c * cst::<T>(t2[(i, j)])
    })
}

/// `â` for an `f64` vector (re-exported for the joint kinds' closed forms).
pub fn hat(a: &Vector3<f64>) -> Matrix3<f64> {
    skew(a)
}

/// Below this size a coordinate increment's column of `B` comes from a
/// second-order Taylor expansion instead of the difference quotient: the
/// quotient's cancellation error is then ≤ eps/1e-6 ≈ 2e-10 relative, and the
/// expansion's `f‴τ³/6` misses the increment by < 2e-19·f‴, below round-off.
pub(crate) const TAYLOR_BELOW: f64 = 1e-6;

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
    additive_step_map_from(joint, start, end, &[T::zero(); MAX_RELEASED], inc)
}

/// [`additive_step_map`] for a step from `start ⊕ from` (`from` seeded for
/// the derivative along the start state). A Taylor column (increment below
/// `1e-6`) follows its own coordinate's `from` to first order, through `τₖ`
/// and the base point (`F′ + F″ δ`); it leaves out `F‴ τₖ δ/6`, below `1e-6`
/// relative, and other coordinates' `from` (as [`additive_step_map`] leaves
/// out their end values).
pub fn additive_step_map_from<J: JointKinematics + ?Sized, T: Scalar>(
    joint: &J,
    start: &ReleasedState,
    end: &ReleasedState,
    from: &[T; MAX_RELEASED],
    inc: &[T; MAX_RELEASED],
) -> SMatrix<T, 6, MAX_RELEASED> {
    type H = HyperDualSVec64<1, 1>;
    let (r_n, l_n) = released_at(joint, start, from);
    let tau: [T; MAX_RELEASED] =
        std::array::from_fn(|k| cst::<T>(end.q[k] - start.q[k]) + inc[k] - from[k]);
    // F at the path point with the first `upto` coordinates at their end values.
    let f = |upto: usize| -> Vector6<T> {
        let d: [T; MAX_RELEASED] =
            std::array::from_fn(|i| if i < upto { from[i] + tau[i] } else { from[i] });
        let (r, l) = released_at(joint, start, &d);
        stack(&(r - r_n), &cayley_inverse(&mmt(&l, &l_n)))
    };
    let mut b = SMatrix::<T, 6, MAX_RELEASED>::zeros();
    for k in 0..released_count::<J>() {
        let column: Vector6<T> = if tau[k].value().abs() >= TAYLOR_BELOW {
            (f(k + 1) - f(k)) / tau[k]
        } else {
            let mut d: [H; MAX_RELEASED] = std::array::from_fn(|i| H::from_re(from[i].value()));
            for (i, di) in d.iter_mut().enumerate().take(k) {
                *di = H::from_re(from[i].value() + tau[i].value());
            }
            d[k] = H::from_re(from[k].value()).derivative1(0).derivative2(0);
            let (r, l) = released_at(joint, start, &d);
            let base: [H; MAX_RELEASED] = std::array::from_fn(|i| H::from_re(from[i].value()));
            let (r0, l0) = released_at(joint, start, &base);
            let dr = r - r0;
            let th = cayley_inverse(&(l * l0.transpose()));
            let d1 = |v: H| v.eps1.unwrap_generic(Const::<1>, U1)[0];
            let d2 = |v: H| v.eps1eps2.unwrap_generic(Const::<1>, Const::<1>)[0];
            // The base point moves with `from`: `F′(Pₖ₋₁ + δ) ≈ F′ + F″ δ`.
            let shift = (from[k] - cst::<T>(from[k].value())) * cst::<T>(2.0);
            let taylor = |v: H| cst::<T>(d1(v)) + (tau[k] + shift) * cst::<T>(0.5 * d2(v));
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
    joint.released_at_state(
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axis_rotation_is_the_exponential_with_its_derivatives() {
        // Rodrigues' formula against the general exponential of `φt`, in
        // value and in the first and second derivatives in the angle
        // (hyper-dual), from zero through a small angle to beyond a turn.
        type H = HyperDualSVec64<1, 1>;
        let axes = [
            Vector3::z(),
            Vector3::new(1.0, -2.0, 0.5).normalize(),
            Vector3::new(0.0, 0.6, 0.8),
        ];
        for axis in axes {
            for phi in [0.0, 1e-9, 0.3, 2.0, 3.1, 7.0, -4.5] {
                let angle = H::from_re(phi).derivative1(0).derivative2(0);
                let ours = axis_rotation(&axis, angle);
                let general = exp(&(axis.map(cst::<H>) * angle));
                for (a, b) in ours.iter().zip(general.iter()) {
                    let parts = |x: &H| {
                        let e1 = x.eps1.unwrap_generic(Const::<1>, U1);
                        let e2 = x.eps2.unwrap_generic(U1, Const::<1>);
                        let e12 = x.eps1eps2.unwrap_generic(Const::<1>, Const::<1>);
                        [x.re, e1[0], e2[0], e12[(0, 0)]]
                    };
                    for (p, q) in parts(a).iter().zip(parts(b)) {
                        assert!((p - q).abs() <= 1e-14, "{axis:?} {phi}: {p} vs {q}");
                    }
                }
            }
        }
    }
}
