//! The joint operations the solvers use ([`JointMap`]): object-safe, and
//! blanket-implemented for every [`JointKinematics`] by automatic
//! differentiation — the variation map `N`, its transfer of slave residuals
//! and the incremental map `Ñ` of a step.

use crate::incremental::{JointStep, NodePose};
use crate::kinematics::{
    released_count, Increments, JointKinematics, ReleasedState, LOCAL, MAX_RELEASED,
};
use flexmech_core::rotation::exp;
use flexmech_core::{cst, Scalar};
use nalgebra::{Const, Matrix3, SMatrix, SVector, Vector3, Vector6, U1};
use num_dual::{DualSVec64, HyperDualSVec64};
use std::fmt::Debug;

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
    fn reported_angle(&self, state: &ReleasedState) -> Option<f64>;

    /// Whether the first released coordinate is a rotation angle (named
    /// `angle`): the kinds that take an initial angle and can be driven.
    fn has_angle(&self) -> bool {
        self.coordinate_names().first() == Some(&"angle")
    }
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
        let (rr, lr) = joint.released_at_state(
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
        released_count::<J>()
    }

    fn coordinate_names(&self) -> &'static [&'static str] {
        JointKinematics::coordinate_names(self)
    }

    fn released_placement(&self, state: &ReleasedState) -> (Vector3<f64>, Matrix3<f64>) {
        let z = [0.0; MAX_RELEASED];
        self.released_at_state(
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
        for c in 6 + released_count::<J>()..LOCAL {
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
        for c in 6 + released_count::<J>()..LOCAL {
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
        for c in 6 + released_count::<J>()..LOCAL {
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

    fn reported_angle(&self, state: &ReleasedState) -> Option<f64> {
        JointKinematics::reported_angle(self, state)
    }
}

impl JointStep<f64> {
    /// `Ñ` of joint `map` for the master's poses at both ends of the step and
    /// the released states at both ends.
    pub fn new(
        map: &dyn JointMap,
        master: [NodePose<'_>; 2],
        released: [&ReleasedState; 2],
    ) -> Self {
        map.incremental_step(master, released)
    }
}
