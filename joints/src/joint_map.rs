//! The joint operations the solvers use ([`JointMap`]): object-safe, and
//! blanket-implemented for every [`JointKinematics`] by automatic
//! differentiation — the variation map `N`, its transfer of slave residuals
//! and the incremental map `Ñ` of a step.
//!
//! `N` and the transfer's derivative are closed form in the master's
//! increments, with AD over the released coordinates only. With the slave
//! `x_s = x_m + R_m r_R`, `R_s = R_m Λ_R`, `y = R_m r_R`, and the released
//! placement's derivatives `u = ∂r_R/∂a`, `v = ∂r_R/∂b` (increments applied
//! last and first) and spin `s` (`δΛ_R Λ_Rᵀ = (s δa)^`):
//!
//! ```text
//! N = [ I  −ŷ  R_m u ]        Nᵀg = ( g_x,  ŷ g_x + g_φ,  uᵀR_mᵀg_x + sᵀR_mᵀg_φ )
//!     [ 0   I  R_m s ]
//! ∂(Nᵀg)/∂(x, φ, q) = [ 0  0                            0           ]
//!                     [ 0  ĝ_x ŷ                        −ĝ_x R_m v  ]
//!                     [ 0  uᵀR_mᵀĝ_x + sᵀR_mᵀĝ_φ        ∂²w/∂a∂b    ]
//! ```
//!
//! with `w(a, b) = G_x·(r_R(a, b) − r_R(0, b)) + G_φ·spin(Λ_R(a, b)Λ_R(0, b)ᵀ)`,
//! `G = R_mᵀg`, by hyper-dual AD over the (at most four) released lanes
//! instead of all ten local ones. [`JointMap::variation_ad`] and
//! [`JointMap::transfer_ad`] keep the full AD as the oracle the tests compare
//! with.

use crate::incremental::{JointStep, NodePose, StepDual};
use crate::kinematics::{
    released_count, Increments, JointKinematics, ReleasedState, LOCAL, MAX_RELEASED, TAYLOR_BELOW,
};
use crate::seeded_step::{SeededStep, StepLanes};
use flexmech_core::rotation::exp;
use flexmech_core::{cst, Scalar};
use nalgebra::{Const, Matrix3, SMatrix, SVector, Vector3, Vector6, U1};
use num_dual::{Dual64, DualSVec64, HyperDualSVec64};
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
    /// [`Self::variation`] by forward-mode AD over every local coordinate
    /// (the oracle the closed form is tested against).
    fn variation_ad(
        &self,
        x_m: &Vector3<f64>,
        r_m: &Matrix3<f64>,
        state: &ReleasedState,
    ) -> SMatrix<f64, 6, LOCAL>;
    /// [`Self::transfer`] by hyper-dual AD over every pair of local
    /// coordinates (the oracle the closed form is tested against).
    fn transfer_ad(
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

    /// `Ñ` seeded along the local increments of the step's end state — the
    /// master's end pose (`x ← x + δx`, `R ← exp(δφ̂)R`) and the released
    /// coordinates — one forward-AD lane each ([`JointStep::seeded`]). Its
    /// real parts are [`Self::incremental_step`]'s map
    /// ([`JointStep::value`]); one seeded map serves a Newton evaluation's
    /// rows, residual and tangent.
    fn incremental_step_seeded(
        &self,
        master: [NodePose<'_>; 2],
        released: [&ReleasedState; 2],
    ) -> JointStep<StepDual>;

    /// [`Self::incremental_step_seeded`] along `lanes` only, the lanes that
    /// reach the unknowns ([`SeededStep`]): what a Newton evaluation of the
    /// conserving schemes uses. The default takes the ten-lane map; the
    /// kinds of [`JointKinematics`] seed the released coordinates alone and
    /// take the master's spin in closed form ([`SeededStep::of`]).
    fn incremental_step_lanes(
        &self,
        master: [NodePose<'_>; 2],
        released: [&ReleasedState; 2],
        lanes: StepLanes,
    ) -> SeededStep {
        SeededStep::from_seeded(&self.incremental_step_seeded(master, released), lanes)
    }

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
    ) -> (SVector<f64, LOCAL>, SMatrix<f64, LOCAL, LOCAL>) {
        self.incremental_step_seeded(master, released)
            .seeded_transfer(g, self.released_count())
    }

    /// The derivative of `Ñᵀ g` (slave residual `g` held, the step's end
    /// held) along the step's start state: the master's start pose moved by
    /// `from.0 = (δx, δφ)` (`x ← x + δx`, `R ← exp(δφ̂)R`) and the released
    /// start state by the increments `from.1` — for exact sensitivities
    /// through the conserving schemes. `None` where the kind's coordinates
    /// do not provide it ([`crate::Coordinates::step_map_from`]).
    fn incremental_transfer_start(
        &self,
        master: [NodePose<'_>; 2],
        released: [&ReleasedState; 2],
        g: &Vector6<f64>,
        from: (&[f64; 6], &[f64; MAX_RELEASED]),
    ) -> Option<SVector<f64, LOCAL>>;

    /// `(∂Ñ/∂p)ᵀ g` for the kind's real parameter `name` (slave residual
    /// `g`, both ends of the step held): `Ñ` depends on `r_R` through the
    /// mid-step offset `d = ½(Λ_m,ₙ r_R,ₙ + Λ_m,ₙ₊₁ r_R,ₙ₊₁) + …` and the
    /// secant column of `B`, `(r_R,ₙ₊₁ − r_R,ₙ)/τ` (`∂r_R/∂q₁` below the
    /// Taylor threshold, leaving out `O(τ ∂³r_R/∂q₁²∂p)`), so the master's
    /// moment gains `∂d × g_u` and the released equation
    /// `(lever ∂B_u)·g_u`. `None` where the kind cannot differentiate by
    /// `name` or has more than one released coordinate.
    fn incremental_transfer_by(
        &self,
        name: &str,
        master: [NodePose<'_>; 2],
        released: [&ReleasedState; 2],
        g: &Vector6<f64>,
    ) -> Option<SVector<f64, LOCAL>>;

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

    /// `∂r_R/∂p` and `∂²r_R/∂q₁∂p` at `state` for the real parameter `name`
    /// of the kind, where it can differentiate by it.
    fn parameter_derivative(&self, name: &str, state: &ReleasedState) -> Option<[Vector3<f64>; 2]>;
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

/// The released placement `(r_R, Λ_R)` at a state and its first
/// derivatives in the released increments: `u = ∂r_R/∂a` (increment applied
/// last), `v = ∂r_R/∂b` (applied first) and the spin Jacobian `s`,
/// `δΛ_R Λ_Rᵀ = (s δa)^` — by forward AD over the released lanes only
/// (columns past the kind's count are zero).
struct ReleasedDerivatives {
    r: Vector3<f64>,
    u: SMatrix<f64, 3, MAX_RELEASED>,
    v: SMatrix<f64, 3, MAX_RELEASED>,
    s: SMatrix<f64, 3, MAX_RELEASED>,
}

impl ReleasedDerivatives {
    /// The derivatives of the joint's `r_R` and `Λ_R` at `state`, by dual
    /// numbers with as many lanes as the joint releases coordinates (twice:
    /// the first and the second increments), not [`MAX_RELEASED`]'s.
    fn of<J: JointKinematics>(joint: &J, state: &ReleasedState) -> Self {
        match released_count::<J>() {
            0 => Self::of_in::<J, 0, 0>(joint, state),
            1 => Self::of_in::<J, 1, 2>(joint, state),
            2 => Self::of_in::<J, 2, 4>(joint, state),
            3 => Self::of_in::<J, 3, 6>(joint, state),
            _ => Self::of_in::<J, MAX_RELEASED, { 2 * MAX_RELEASED }>(joint, state),
        }
    }

    /// [`Self::of`] over `N` released coordinates, `L = 2N` dual lanes: lane
    /// `i` the first increment of coordinate `i`, lane `N + i` its second.
    fn of_in<J: JointKinematics, const N: usize, const L: usize>(
        joint: &J,
        state: &ReleasedState,
    ) -> Self {
        type D<const L: usize> = DualSVec64<L>;
        let lane = |i: usize| {
            let x = D::<L>::from_re(0.0);
            if i < L {
                x.derivative(i)
            } else {
                x
            }
        };
        let a: [D<L>; MAX_RELEASED] =
            std::array::from_fn(|i| if i < N { lane(i) } else { lane(L) });
        let b: [D<L>; MAX_RELEASED] =
            std::array::from_fn(|i| if i < N { lane(N + i) } else { lane(L) });
        let (rr, lr) = joint.released_at_state(
            state,
            Increments {
                first: &a,
                second: &b,
            },
        );
        let lanes = |x: &D<L>| x.eps.unwrap_generic(Const::<L>, U1);
        let lr0 = lr.map(|x| x.re);
        let mut d = Self {
            r: rr.map(|x| x.re),
            u: SMatrix::zeros(),
            v: SMatrix::zeros(),
            s: SMatrix::zeros(),
        };
        for k in 0..N {
            let dl = lr.map(|x| lanes(&x)[k]) * lr0.transpose();
            d.s.set_column(
                k,
                &Vector3::new(
                    0.5 * (dl[(2, 1)] - dl[(1, 2)]),
                    0.5 * (dl[(0, 2)] - dl[(2, 0)]),
                    0.5 * (dl[(1, 0)] - dl[(0, 1)]),
                ),
            );
            d.u.set_column(k, &rr.map(|x| lanes(&x)[k]));
            d.v.set_column(k, &rr.map(|x| lanes(&x)[N + k]));
        }
        d
    }
}

/// `(∂w/∂a, ∂²w/∂a∂b)` of [`released_transfer`].
type ReleasedTransfer = (
    SVector<f64, MAX_RELEASED>,
    SMatrix<f64, MAX_RELEASED, MAX_RELEASED>,
);

/// The released block of the transfer in the master's frame: with
/// `G_x = R_mᵀ g_x`, `G_φ = R_mᵀ g_φ` and
/// `w(a, b) = G_x·(r_R(a, b) − r_R(0, b)) + G_φ·spin(Λ_R(a, b) Λ_R(0, b)ᵀ)`,
/// `(∂w/∂a, ∂²w/∂a∂b)` at zero — hyper-dual AD over the released lanes only,
/// as many as the joint releases (a revolute's hyper-duals carry 4 numbers,
/// not the 25 of [`MAX_RELEASED`] lanes).
fn released_transfer<J: JointKinematics>(
    joint: &J,
    state: &ReleasedState,
    gx: &Vector3<f64>,
    gp: &Vector3<f64>,
) -> ReleasedTransfer {
    match released_count::<J>() {
        0 => (SVector::zeros(), SMatrix::zeros()),
        1 => released_transfer_in::<J, 1>(joint, state, gx, gp),
        2 => released_transfer_in::<J, 2>(joint, state, gx, gp),
        3 => released_transfer_in::<J, 3>(joint, state, gx, gp),
        _ => released_transfer_in::<J, MAX_RELEASED>(joint, state, gx, gp),
    }
}

/// [`released_transfer`] over `N` released lanes (the rest of the result
/// zero).
fn released_transfer_in<J: JointKinematics, const N: usize>(
    joint: &J,
    state: &ReleasedState,
    gx: &Vector3<f64>,
    gp: &Vector3<f64>,
) -> ReleasedTransfer {
    let lane = |i: usize, first: bool| {
        let x = HyperDualSVec64::<N, N>::from_re(0.0);
        match (i < N, first) {
            (true, true) => x.derivative1(i),
            (true, false) => x.derivative2(i),
            (false, _) => x,
        }
    };
    let a: [HyperDualSVec64<N, N>; MAX_RELEASED] = std::array::from_fn(|i| lane(i, true));
    let b: [HyperDualSVec64<N, N>; MAX_RELEASED] = std::array::from_fn(|i| lane(i, false));
    let zero = [HyperDualSVec64::<N, N>::from_re(0.0); MAX_RELEASED];
    let (r1, l1) = joint.released_at_state(
        state,
        Increments {
            first: &a,
            second: &b,
        },
    );
    let (r0, l0) = joint.released_at_state(
        state,
        Increments {
            first: &zero,
            second: &b,
        },
    );
    // The axial part of `m = l1 l0ᵀ`, `m_ij = l1_i· · l0_j·`: its six
    // off-diagonal entries only (a general product of hyper-duals would
    // form all nine through nalgebra's generic kernel).
    let m = |i: usize, j: usize| {
        l1[(i, 0)] * l0[(j, 0)] + l1[(i, 1)] * l0[(j, 1)] + l1[(i, 2)] * l0[(j, 2)]
    };
    let half = HyperDualSVec64::<N, N>::from_re(0.5);
    let spin = Vector3::new(
        (m(2, 1) - m(1, 2)) * half,
        (m(0, 2) - m(2, 0)) * half,
        (m(1, 0) - m(0, 1)) * half,
    );
    let w = (r1 - r0).dot(&gx.map(HyperDualSVec64::<N, N>::from_re))
        + spin.dot(&gp.map(HyperDualSVec64::<N, N>::from_re));
    let first = w.eps1.unwrap_generic(Const::<N>, U1);
    let second = w.eps1eps2.unwrap_generic(Const::<N>, Const::<N>);
    let mut d1 = SVector::<f64, MAX_RELEASED>::zeros();
    let mut d2 = SMatrix::<f64, MAX_RELEASED, MAX_RELEASED>::zeros();
    d1.fixed_rows_mut::<N>(0).copy_from(&first);
    d2.fixed_view_mut::<N, N>(0, 0).copy_from(&second);
    (d1, d2)
}

impl<J: JointKinematics> JointMap for J {
    fn released_count(&self) -> usize {
        released_count::<J>()
    }

    fn parameter_derivative(&self, name: &str, state: &ReleasedState) -> Option<[Vector3<f64>; 2]> {
        JointKinematics::parameter_derivative(self, name, state)
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
        let _ = x_m;
        let d = ReleasedDerivatives::of(self, state);
        let y = r_m * d.r;
        let mut n = SMatrix::<f64, 6, LOCAL>::zeros();
        n.fixed_view_mut::<3, 3>(0, 0).fill_with_identity();
        n.fixed_view_mut::<3, 3>(0, 3)
            .copy_from(&(-y.cross_matrix()));
        n.fixed_view_mut::<3, 3>(3, 3).fill_with_identity();
        n.fixed_view_mut::<3, MAX_RELEASED>(0, 6)
            .copy_from(&(r_m * d.u));
        n.fixed_view_mut::<3, MAX_RELEASED>(3, 6)
            .copy_from(&(r_m * d.s));
        n
    }

    fn transfer(
        &self,
        x_m: &Vector3<f64>,
        r_m: &Matrix3<f64>,
        state: &ReleasedState,
        g: &Vector6<f64>,
    ) -> (SVector<f64, LOCAL>, SMatrix<f64, LOCAL, LOCAL>) {
        let _ = x_m;
        let (gx, gp) = (
            g.fixed_rows::<3>(0).into_owned(),
            g.fixed_rows::<3>(3).into_owned(),
        );
        let (gx_m, gp_m) = (r_m.transpose() * gx, r_m.transpose() * gp);
        let d = ReleasedDerivatives::of(self, state);
        let (ntg_q, k_qq) = released_transfer(self, state, &gx_m, &gp_m);
        let y = r_m * d.r;
        let (gxh, gph) = (gx.cross_matrix(), gp.cross_matrix());
        let mut ntg = SVector::<f64, LOCAL>::zeros();
        ntg.fixed_rows_mut::<3>(0).copy_from(&gx);
        ntg.fixed_rows_mut::<3>(3).copy_from(&(y.cross(&gx) + gp));
        ntg.fixed_rows_mut::<MAX_RELEASED>(6).copy_from(&ntg_q);
        let mut k = SMatrix::<f64, LOCAL, LOCAL>::zeros();
        k.fixed_view_mut::<3, 3>(3, 3)
            .copy_from(&(gxh * y.cross_matrix()));
        k.fixed_view_mut::<3, MAX_RELEASED>(3, 6)
            .copy_from(&(-gxh * r_m * d.v));
        k.fixed_view_mut::<MAX_RELEASED, 3>(6, 3).copy_from(
            &(d.u.transpose() * r_m.transpose() * gxh + d.s.transpose() * r_m.transpose() * gph),
        );
        k.fixed_view_mut::<MAX_RELEASED, MAX_RELEASED>(6, 6)
            .copy_from(&k_qq);
        for c in 6 + released_count::<J>()..LOCAL {
            ntg[c] = 0.0;
            k.row_mut(c).fill(0.0);
            k.column_mut(c).fill(0.0);
        }
        (ntg, k)
    }

    fn variation_ad(
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

    fn transfer_ad(
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

    fn incremental_step_seeded(
        &self,
        master: [NodePose<'_>; 2],
        released: [&ReleasedState; 2],
    ) -> JointStep<StepDual> {
        JointStep::seeded(self, master, released)
    }

    fn incremental_step_lanes(
        &self,
        master: [NodePose<'_>; 2],
        released: [&ReleasedState; 2],
        lanes: StepLanes,
    ) -> SeededStep {
        SeededStep::of(self, master, released, lanes)
    }

    fn incremental_transfer_start(
        &self,
        master: [NodePose<'_>; 2],
        released: [&ReleasedState; 2],
        g: &Vector6<f64>,
        from: (&[f64; 6], &[f64; MAX_RELEASED]),
    ) -> Option<SVector<f64, LOCAL>> {
        let seeded = |v: &f64| Dual64::new(0.0, *v);
        let from = (from.0.each_ref().map(seeded), from.1.each_ref().map(seeded));
        let zero = Dual64::from(0.0);
        let step = JointStep::of_from(
            self,
            master,
            released,
            (&from.0, &from.1),
            &[zero; 6],
            &[zero; MAX_RELEASED],
        )?;
        let mut t = step.transfer(&g.map(Dual64::from)).map(|v| v.eps);
        for c in 6 + released_count::<J>()..LOCAL {
            t[c] = 0.0;
        }
        Some(t)
    }

    fn incremental_transfer_by(
        &self,
        name: &str,
        master: [NodePose<'_>; 2],
        released: [&ReleasedState; 2],
        g: &Vector6<f64>,
    ) -> Option<SVector<f64, LOCAL>> {
        if released_count::<J>() != 1 {
            return None;
        }
        let [fp0, slope0] = self.parameter_derivative(name, released[0])?;
        let [fp1, _] = self.parameter_derivative(name, released[1])?;
        let [(_, r0), (_, r1)] = master;
        let zero = [0.0; MAX_RELEASED];
        let step = JointStep::of(self, master, released, &[0.0; 6], &zero);
        let tau = released[1].q[0] - released[0].q[0];
        let column = if tau.abs() >= TAYLOR_BELOW {
            (fp1 - fp0) / tau
        } else {
            slope0
        };
        let force = g.fixed_rows::<3>(0).into_owned();
        let offset = (r0 * fp0 + r1 * fp1) * 0.5;
        let mut t = SVector::<f64, LOCAL>::zeros();
        t.fixed_rows_mut::<3>(3).copy_from(&offset.cross(&force));
        t[6] = (step.lever * column).dot(&force);
        Some(t)
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
