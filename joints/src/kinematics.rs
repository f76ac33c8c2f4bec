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
//! The blanket implementation of [`JointMap`] derives, with num-dual, the
//! variational map `N` of paper eqs 5–6 (`p_s = N p_Rm`) and the derivative of
//! `Nᵀ g` that Newton's tangent needs. No kind writes a derivative by hand.

use crate::incremental::{JointStep, NodePose};
use flexmech_core::rotation::{exp, skew};
use flexmech_core::{cst, Scalar};
use nalgebra::{Const, Matrix3, SMatrix, SVector, Vector3, Vector6, U1};
use num_dual::{DualSVec64, HyperDualSVec64};
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
    pub first: &'a [T],
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
    /// (`τ = qₙ₊₁ − qₙ`), is [`crate::incremental::additive_step_map`]; a kind
    /// with a multiplicative rotation overrides it. The end state is
    /// `end ⊕ inc` (`inc` as in [`JointKinematics::released`]), so that
    /// automatic differentiation can follow `B` as the end state moves.
    fn step_map<T: Scalar>(
        &self,
        start: &ReleasedState,
        end: &ReleasedState,
        inc: &[T; MAX_RELEASED],
    ) -> SMatrix<T, 6, MAX_RELEASED> {
        crate::incremental::additive_step_map(self, start, end, inc)
    }

    /// The released rotation angle reported as `/joints/<name>/angle`.
    fn reported_angle(&self, state: &ReleasedState) -> f64 {
        if Self::RELEASED > 0 {
            state.q[0]
        } else {
            0.0
        }
    }
}

/// The joint operations the solvers use: object-safe, blanket-implemented for
/// every [`JointKinematics`] by automatic differentiation.
pub trait JointMap: Send + Sync + Debug {
    /// Number of released coordinates.
    fn released_count(&self) -> usize;
    /// Names of the released coordinates.
    fn coordinate_names(&self) -> &'static [&'static str];
    /// `(r_R, Λ_R)` of a state.
    fn released_placement(&self, state: &ReleasedState) -> (Vector3<f64>, Matrix3<f64>);
    /// Slave position and rotation from the master's, relation (1) — exact.
    fn slave(
        &self,
        x_m: &Vector3<f64>,
        r_m: &Matrix3<f64>,
        state: &ReleasedState,
    ) -> (Vector3<f64>, Matrix3<f64>);
    /// The variational map `N` (6 × (6 + released), paper eqs 5–6): slave
    /// increment `(δx_s, δφ_s)` from master `(δx_m, δφ_m)` and released `δq`.
    /// Columns past `6 + released` are zero.
    fn variation(
        &self,
        x_m: &Vector3<f64>,
        r_m: &Matrix3<f64>,
        state: &ReleasedState,
    ) -> SMatrix<f64, 6, LOCAL>;
    /// `Nᵀ g` for the slave's nodal residual `g`, and its derivative with
    /// respect to the local increments at fixed `g` (the configuration-dependent
    /// part of the reduced tangent, paper §2: "the linearisation must include
    /// the derivative of N").
    fn transfer(
        &self,
        x_m: &Vector3<f64>,
        r_m: &Matrix3<f64>,
        state: &ReleasedState,
        g: &Vector6<f64>,
    ) -> (SVector<f64, LOCAL>, SMatrix<f64, LOCAL, LOCAL>);
    /// The incremental map `Ñ` over a step (paper eqs 21–23, [`JointStep`]),
    /// for the master's poses and the released states at both ends.
    fn incremental_step(
        &self,
        master: [NodePose<'_>; 2],
        released: [&ReleasedState; 2],
    ) -> JointStep;

    /// `Ñᵀ g` for a slave residual `g` held fixed, and its exact derivative
    /// with respect to the local increments of the step's end state —
    /// the master's end pose (`x ← x + δx`, `R ← exp(δφ̂)R`) and the released
    /// coordinates — by forward-mode AD through `Ñ` (the conserving schemes'
    /// Newton tangent; unused released columns are zero).
    fn incremental_transfer(
        &self,
        master: [NodePose<'_>; 2],
        released: [&ReleasedState; 2],
        g: &Vector6<f64>,
    ) -> (SVector<f64, LOCAL>, SMatrix<f64, LOCAL, LOCAL>);

    /// `B` with `(u_R, θ_R) = B τ` over a step (see [`JointKinematics::step_map`]).
    fn step_map(&self, start: &ReleasedState, end: &ReleasedState)
        -> SMatrix<f64, 6, MAX_RELEASED>;
    /// Advances the released state by `delta` (length `released_count`).
    fn advance(&self, state: &mut ReleasedState, delta: &[f64]);
    /// The angle reported in results.
    fn reported_angle(&self, state: &ReleasedState) -> f64;
}

/// Slave increment `(Δx, spin)` for the local increment `e` applied after `h`,
/// relative to the pose after `h` alone. The spin is the axial vector of the
/// skew part of `R_s(e,h) R_s(0,h)ᵀ`, exact to first order in `e` — all that
/// the first derivative in `e` (and mixed derivatives in `e`, `h`) need.
fn slave_increment<J: JointKinematics, T: Scalar>(
    joint: &J,
    x_m: &Vector3<f64>,
    r_m: &Matrix3<f64>,
    state: &ReleasedState,
    e: &[T; LOCAL],
    h: &[T; LOCAL],
) -> (Vector3<T>, Vector3<T>) {
    let zero = [T::zero(); LOCAL];
    let pose = |a: &[T; LOCAL], b: &[T; LOCAL]| {
        let xm = x_m.map(cst::<T>) + Vector3::new(a[0] + b[0], a[1] + b[1], a[2] + b[2]);
        let rm = exp(&Vector3::new(a[3], a[4], a[5]))
            * exp(&Vector3::new(b[3], b[4], b[5]))
            * r_m.map(cst::<T>);
        let (rr, lr) = joint.released(
            state,
            Increments {
                first: &a[6..],
                second: &b[6..],
            },
        );
        (xm + rm * rr, rm * lr)
    };
    let (x1, r1) = pose(e, h);
    let (x0, r0) = pose(&zero, h);
    let a = r1 * r0.transpose();
    let half = cst::<T>(0.5);
    let spin = Vector3::new(
        (a[(2, 1)] - a[(1, 2)]) * half,
        (a[(0, 2)] - a[(2, 0)]) * half,
        (a[(1, 0)] - a[(0, 1)]) * half,
    );
    (x1 - x0, spin)
}

impl<J: JointKinematics> JointMap for J {
    fn released_count(&self) -> usize {
        J::RELEASED
    }

    fn coordinate_names(&self) -> &'static [&'static str] {
        JointKinematics::coordinate_names(self)
    }

    fn released_placement(&self, state: &ReleasedState) -> (Vector3<f64>, Matrix3<f64>) {
        let z = [0.0; MAX_RELEASED];
        self.released(
            state,
            Increments {
                first: &z,
                second: &z,
            },
        )
    }

    fn slave(
        &self,
        x_m: &Vector3<f64>,
        r_m: &Matrix3<f64>,
        state: &ReleasedState,
    ) -> (Vector3<f64>, Matrix3<f64>) {
        let (rr, lr) = self.released_placement(state);
        (x_m + r_m * rr, r_m * lr)
    }

    fn variation(
        &self,
        x_m: &Vector3<f64>,
        r_m: &Matrix3<f64>,
        state: &ReleasedState,
    ) -> SMatrix<f64, 6, LOCAL> {
        type D = DualSVec64<LOCAL>;
        let e: [D; LOCAL] = std::array::from_fn(|i| D::from_re(0.0).derivative(i));
        let h = [D::from_re(0.0); LOCAL];
        let (dx, spin) = slave_increment(self, x_m, r_m, state, &e, &h);
        let mut n = SMatrix::<f64, 6, LOCAL>::zeros();
        for r in 0..3 {
            n.set_row(r, &dx[r].eps.unwrap_generic(Const::<LOCAL>, U1).transpose());
            n.set_row(
                3 + r,
                &spin[r].eps.unwrap_generic(Const::<LOCAL>, U1).transpose(),
            );
        }
        for c in 6 + J::RELEASED..LOCAL {
            n.column_mut(c).fill(0.0);
        }
        n
    }

    fn transfer(
        &self,
        x_m: &Vector3<f64>,
        r_m: &Matrix3<f64>,
        state: &ReleasedState,
        g: &Vector6<f64>,
    ) -> (SVector<f64, LOCAL>, SMatrix<f64, LOCAL, LOCAL>) {
        type H = HyperDualSVec64<LOCAL, LOCAL>;
        let e: [H; LOCAL] = std::array::from_fn(|i| H::from_re(0.0).derivative1(i));
        let h: [H; LOCAL] = std::array::from_fn(|i| H::from_re(0.0).derivative2(i));
        let (dx, spin) = slave_increment(self, x_m, r_m, state, &e, &h);
        let gh = g.map(H::from_re);
        let w = dx.dot(&gh.fixed_rows::<3>(0)) + spin.dot(&gh.fixed_rows::<3>(3));
        let mut ntg = w.eps1.unwrap_generic(Const::<LOCAL>, U1);
        let mut k = w.eps1eps2.unwrap_generic(Const::<LOCAL>, Const::<LOCAL>);
        for c in 6 + J::RELEASED..LOCAL {
            ntg[c] = 0.0;
            k.row_mut(c).fill(0.0);
            k.column_mut(c).fill(0.0);
        }
        (ntg, k)
    }

    fn incremental_step(
        &self,
        master: [NodePose<'_>; 2],
        released: [&ReleasedState; 2],
    ) -> JointStep {
        JointStep::of(self, master, released, &[0.0; 6], &[0.0; MAX_RELEASED])
    }

    fn incremental_transfer(
        &self,
        master: [NodePose<'_>; 2],
        released: [&ReleasedState; 2],
        g: &Vector6<f64>,
    ) -> (SVector<f64, LOCAL>, SMatrix<f64, LOCAL, LOCAL>) {
        type D = DualSVec64<LOCAL>;
        let e: [D; LOCAL] = std::array::from_fn(|i| D::from_re(0.0).derivative(i));
        let seed: [D; 6] = std::array::from_fn(|i| e[i]);
        let inc: [D; MAX_RELEASED] = std::array::from_fn(|i| e[6 + i]);
        let step = JointStep::of(self, master, released, &seed, &inc);
        let t = step.transfer(&g.map(D::from_re));
        let mut value = t.map(|v| v.re);
        let mut k = SMatrix::<f64, LOCAL, LOCAL>::zeros();
        for r in 0..LOCAL {
            k.set_row(r, &t[r].eps.unwrap_generic(Const::<LOCAL>, U1).transpose());
        }
        for c in 6 + J::RELEASED..LOCAL {
            value[c] = 0.0;
            k.row_mut(c).fill(0.0);
            k.column_mut(c).fill(0.0);
        }
        (value, k)
    }

    fn step_map(
        &self,
        start: &ReleasedState,
        end: &ReleasedState,
    ) -> SMatrix<f64, 6, MAX_RELEASED> {
        JointKinematics::step_map(self, start, end, &[0.0; MAX_RELEASED])
    }

    fn advance(&self, state: &mut ReleasedState, delta: &[f64]) {
        JointKinematics::advance(self, state, delta)
    }

    fn reported_angle(&self, state: &ReleasedState) -> f64 {
        JointKinematics::reported_angle(self, state)
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
