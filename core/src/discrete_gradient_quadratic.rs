//! The energy-consistent internal force of the conserving schemes for the
//! 3-node element: a discrete gradient of the element's strain energy
//! (FORMULATION §4.3, "3-node elements").
//!
//! The 3-node element's reference rotation is its middle node's triad `Λ_r`,
//! so its strains at a Gauss point `g` are functions of *objective*
//! coordinates only — the end nodes' positions and rotation vectors relative
//! to the middle node, `aᵢ = Λ_rᵀ(xᵢ − x_r)`, `ψᵢ = log(Λ_rᵀΛᵢ)`:
//!
//! ```text
//! Γ_g = Q_g b_g − Γ₀,  Q_g = exp(−ψ̂_g),   b_g = Σ Iᵢ′ aᵢ
//! K_g = Hᵀ(ψ_g) k_g − K₀,                 k_g = Σ Iᵢ′ ψᵢ,   ψ_g = Σ Iᵢ ψᵢ
//! ```
//!
//! Over a step, with algebraic means `Q̄`, `H̄` and `N̄ = Nₙ₊½`, `M̄ = Mₙ₊½`:
//!
//! ```text
//! N̄·ΔΓ_g = (Q̄ᵀN̄)·Δb_g + (Q̄ b̄_g × N̄)·κ_g,     κ_g = cay⁻¹(Q_g,ₙ₊₁ Q_g,ₙᵀ)
//! M̄·ΔK_g = (H̄ M̄)·Δk_g + M̄·(ΔHᵀ) k̄_g
//! ```
//!
//! (exact: `ΔQ = κ̂ Q̄` for Cayley increments, FORMULATION §1). The two
//! non-linear pieces are written as operators on `Δψ_g`: `κ_g = K Δψ_g`,
//! `(ΔHᵀ)k̄ = D Δψ_g`, with `K = −Hᵀ(ψ̄_g)` and `D = ∂(Hᵀ(ψ)k̄)/∂ψ` at the
//! mid value `ψ̄_g` (second-order accurate by symmetry) plus rank-one
//! corrections `(exact − K Δψ_g) ⊗ Δψ_g/(|Δψ_g|² + ε²)` that make them
//! exact; `Δψ_g` is a pure deformation increment, so the corrections are
//! `O(|Δψ_g|²)` and smooth. The coordinates' increments are exactly linear in
//! the nodal increments: `Δaᵢ = Λ̄_rᵀ(Δdᵢ + d̄ᵢ × θ_r)` (`dᵢ = xᵢ − x_r`,
//! `θ_r` the middle node's Cayley increment) and `Δψᵢ = Tᵢ(θᵢ − θ_r)` with
//! the smooth secant operator of the 2-node element
//! ([`crate::discrete_gradient`]). The force conjugate to the nodal
//! increments therefore does the work `Πₙ₊₁ − Πₙ` exactly; it vanishes on
//! every rigid increment about the mid-step positions (`Δaᵢ = 0`, `Δψᵢ = 0`),
//! so it is self-equilibrated about them and conserves momenta; and as
//! `Δt → 0` it tends to the static element's gradient.

use crate::conserving::Pose3;
use crate::discrete_gradient::{secant_operators, RIGID_STEP};
use crate::element::BeamElement;
use crate::rotation::{cayley_inverse, exp, log, series, skew, tangent, SERIES_LIMIT};
use crate::scalar::{cst, Scalar};
use crate::shape::{lagrange, reduced_gauss};
use nalgebra::{Matrix3, SVector, Vector3};

/// The reference (frame) node of the 3-node element: its middle node.
const FRAME: usize = 1;
/// The end nodes, whose coordinates are taken relative to the frame node.
const ENDS: [usize; 2] = [0, 2];

/// `(b, c) = ((1 − cos t)/t², (t − sin t)/t³)` and their derivatives with
/// respect to `s = t²`, as functions of `s` (series near 0).
fn tangent_coefficients<T: Scalar>(s: T) -> (T, T, T, T) {
    if s.value() < SERIES_LIMIT {
        (
            series(
                s,
                &[
                    0.5,
                    -1.0 / 24.0,
                    1.0 / 720.0,
                    -1.0 / 40320.0,
                    1.0 / 3628800.0,
                ],
            ),
            series(
                s,
                &[
                    1.0 / 6.0,
                    -1.0 / 120.0,
                    1.0 / 5040.0,
                    -1.0 / 362880.0,
                    1.0 / 39916800.0,
                ],
            ),
            series(
                s,
                &[-1.0 / 24.0, 2.0 / 720.0, -3.0 / 40320.0, 4.0 / 3628800.0],
            ),
            series(
                s,
                &[
                    -1.0 / 120.0,
                    2.0 / 5040.0,
                    -3.0 / 362880.0,
                    4.0 / 39916800.0,
                ],
            ),
        )
    } else {
        let t = s.sqrt();
        let (sin, cos) = (t.sin(), t.cos());
        let one = T::one();
        let b = (one - cos) / s;
        let c = (t - sin) / (s * t);
        // d/ds = (d/dt)/(2t).
        let db_dt = sin / s - (one - cos) * cst::<T>(2.0) / (s * t);
        let dc_dt = (one - cos) / (s * t) - (t - sin) * cst::<T>(3.0) / (s * s);
        let two_t = t * cst::<T>(2.0);
        (b, c, db_dt / two_t, dc_dt / two_t)
    }
}

/// `∂(Hᵀ(ψ) w)/∂ψ` for `Hᵀ(ψ)w = w − b ψ×w + c ψ×(ψ×w)`.
pub fn tangent_transpose_derivative<T: Scalar>(psi: &Vector3<T>, w: &Vector3<T>) -> Matrix3<T> {
    let (b, c, b_s, c_s) = tangent_coefficients(psi.norm_squared());
    let two = cst::<T>(2.0);
    let pxw = psi.cross(w);
    let ppw = psi.cross(&pxw);
    -(pxw * psi.transpose()) * (b_s * two)
        + skew(w) * b
        + ppw * psi.transpose() * (c_s * two)
        + (Matrix3::identity() * psi.dot(w) + psi * w.transpose() - w * psi.transpose() * two) * c
}

/// A rank-one correction making `op` map `d` to `exact`:
/// `op + (exact − op d) ⊗ d/(|d|² + ε²)`.
fn corrected<T: Scalar>(op: Matrix3<T>, exact: Vector3<T>, d: &Vector3<T>, eps: T) -> Matrix3<T> {
    op + (exact - op * d) * (d / (d.norm_squared() + eps * eps)).transpose()
}

/// Coordinates of the end nodes at both ends of the step, `[k][i]` for node
/// `i` at `n` (`k = 0`) and `n+1` (`k = 1`); zero at the frame node.
type Coordinates<T> = [[Vector3<T>; 3]; 2];

/// The step's frame of a 3-node element: the frame node's triads `Λ_r` at
/// `n` and `n+1` and their mean `Λ̄_r`, the nodes' Cayley increments `θᵢ`
/// (`Rᵢ,ₙ₊₁ = cay(θᵢ) Rᵢ,ₙ`), and the regularisation `ε` of the rank-one
/// corrections.
struct StepFrame<T: Scalar> {
    lam_r: [Matrix3<T>; 2],
    lam_bar: Matrix3<T>,
    theta: [Vector3<T>; 3],
    eps: T,
}

impl BeamElement<3> {
    /// The energy-consistent internal force between the poses at `n` and
    /// `n+1`, ordered `(f₀, m₀, f₁, m₁, f₂, m₂)`; see the module docs. The
    /// resultants are the step averages of the element's own.
    pub fn discrete_gradient_force<T: Scalar>(
        &self,
        start: &Pose3<T>,
        end: &Pose3<T>,
    ) -> SVector<T, 18> {
        let half = cst::<T>(0.5);
        let ends = [self.triads(&start.1), self.triads(&end.1)];
        let lam_r = [ends[0][FRAME], ends[1][FRAME]];
        let lam_bar = (lam_r[0] + lam_r[1]) * half;
        let theta: [Vector3<T>; 3] =
            std::array::from_fn(|i| cayley_inverse(&(end.1[i] * start.1[i].transpose())));
        let eps = (T::one()
            + theta
                .iter()
                .map(|t| t.norm_squared())
                .fold(T::zero(), |a, b| a + b))
            * cst::<T>(RIGID_STEP);
        let (a, psi) = objective_coordinates(start, end, &ends, &lam_r);
        let (g_a, g_psi) = self.coordinate_forces(start, end, &a, &psi, eps);
        let frame = StepFrame {
            lam_r,
            lam_bar,
            theta,
            eps,
        };
        nodal_forces(start, end, &frame, &psi, &g_a, &g_psi)
    }

    /// The forces `(g_a, g_ψ)` conjugate to the increments of the objective
    /// coordinates `a`, `psi` of the step (`Σ g_aᵢ·Δaᵢ + g_ψᵢ·Δψᵢ = ΔΠ`),
    /// summed over the Gauss points with the step means `N̄`, `M̄`, `Q̄`, `H̄`
    /// and the exact operators `K`, `D` (regularised by `eps`) of the module
    /// docs.
    fn coordinate_forces<T: Scalar>(
        &self,
        start: &Pose3<T>,
        end: &Pose3<T>,
        a: &Coordinates<T>,
        psi: &Coordinates<T>,
        eps: T,
    ) -> ([Vector3<T>; 3], [Vector3<T>; 3]) {
        let half = cst::<T>(0.5);
        // Forces conjugate to the coordinates' increments: Σ g_aᵢ·Δaᵢ + g_ψᵢ·Δψᵢ = ΔΠ.
        let mut g_a = [Vector3::zeros(); 3];
        let mut g_psi = [Vector3::zeros(); 3];
        let strains = [
            self.strains(&start.0, &start.1),
            self.strains(&end.0, &end.1),
        ];
        let cn = self.section.c_n.map(cst::<T>);
        let cm = self.section.c_m.map(cst::<T>);
        let ds = 2.0 / self.length;
        for (g, &(xi, w)) in reduced_gauss(3).iter().enumerate() {
            let (v, d) = lagrange(3, xi);
            let weight = cst::<T>(0.5 * w * self.length);
            let at = |k: usize| {
                let (mut pg, mut kg, mut bg) =
                    (Vector3::zeros(), Vector3::zeros(), Vector3::zeros());
                for i in ENDS {
                    pg += psi[k][i] * cst::<T>(v[i]);
                    kg += psi[k][i] * cst::<T>(d[i] * ds);
                    bg += a[k][i] * cst::<T>(d[i] * ds);
                }
                (pg, kg, bg)
            };
            let (p0, k0, b0) = at(0);
            let (p1, k1, b1) = at(1);
            let (dpsi, pbar, kbar, bbar) = (
                p1 - p0,
                (p0 + p1) * half,
                (k0 + k1) * half,
                (b0 + b1) * half,
            );
            let q = [exp(&(-p0)), exp(&(-p1))];
            let qbar = (q[0] + q[1]) * half;
            let hbar = (tangent(&p0) + tangent(&p1)) * half;
            let nbar = (strains[0][g].0 + strains[1][g].0).component_mul(&cn) * half;
            let mbar = (strains[0][g].1 + strains[1][g].1).component_mul(&cm) * half;
            // κ = K Δψ_g and (ΔHᵀ)k̄ = D Δψ_g, made exact.
            let kappa = cayley_inverse(&(q[1] * q[0].transpose()));
            let kop = corrected(-tangent(&pbar).transpose(), kappa, &dpsi, eps);
            let dh = tangent(&p1).transpose() * kbar - tangent(&p0).transpose() * kbar;
            let dop = corrected(tangent_transpose_derivative(&pbar, &kbar), dh, &dpsi, eps);
            let on_b = qbar.transpose() * nbar * weight;
            let on_k = hbar * mbar * weight;
            let on_pg =
                (kop.transpose() * (qbar * bbar).cross(&nbar) + dop.transpose() * mbar) * weight;
            for i in ENDS {
                g_a[i] += on_b * cst::<T>(d[i] * ds);
                g_psi[i] += on_k * cst::<T>(d[i] * ds) + on_pg * cst::<T>(v[i]);
            }
        }
        (g_a, g_psi)
    }
}

/// The objective coordinates `(a, ψ)` at both ends of the step:
/// `aᵢ = Λ_rᵀ(xᵢ − x_r)`, `ψᵢ = log(Λ_rᵀΛᵢ)` of the end nodes, from the
/// nodes' triads `ends` and the frame node's `lam_r` (`a_r = 0`, `ψ_r = 0`).
fn objective_coordinates<T: Scalar>(
    start: &Pose3<T>,
    end: &Pose3<T>,
    ends: &[[Matrix3<T>; 3]; 2],
    lam_r: &[Matrix3<T>; 2],
) -> (Coordinates<T>, Coordinates<T>) {
    // Objective coordinates at both ends: aᵢ, ψᵢ (ψ_r = 0, a_r = 0).
    let rel = |k: usize, i: usize| -> (Vector3<T>, Vector3<T>) {
        let (x, l) = (if k == 0 { &start.0 } else { &end.0 }, &ends[k]);
        (
            lam_r[k].transpose() * (x[i] - x[FRAME]),
            log(&(lam_r[k].transpose() * l[i])),
        )
    };
    let mut a = [[Vector3::zeros(); 3]; 2];
    let mut psi = [[Vector3::zeros(); 3]; 2];
    for k in 0..2 {
        for i in ENDS {
            (a[k][i], psi[k][i]) = rel(k, i);
        }
    }
    (a, psi)
}

/// The nodal forces, ordered `(f₀, m₀, f₁, m₁, f₂, m₂)`, conjugate to the
/// nodal increments through `Δaᵢ = Λ̄_rᵀ(Δdᵢ + d̄ᵢ × θ_r)` and
/// `Δψᵢ = Tᵢ(θᵢ − θ_r)` (`Tᵢ` the mean of the 2-node element's secant
/// operators both ways, corrected to map `θᵢ − θ_r` to `Δψᵢ` exactly), from
/// the coordinates' forces `g_a`, `g_psi`.
fn nodal_forces<T: Scalar>(
    start: &Pose3<T>,
    end: &Pose3<T>,
    frame: &StepFrame<T>,
    psi: &Coordinates<T>,
    g_a: &[Vector3<T>; 3],
    g_psi: &[Vector3<T>; 3],
) -> SVector<T, 18> {
    let half = cst::<T>(0.5);
    let StepFrame {
        lam_r,
        lam_bar,
        theta,
        eps,
    } = frame;
    // Nodal forces: Δaᵢ = Λ̄_rᵀ(Δdᵢ + d̄ᵢ × θ_r), Δψᵢ = Tᵢ(θᵢ − θ_r).
    let mut out = SVector::<T, 18>::zeros();
    let mut add = |node: usize, row: usize, v: Vector3<T>| {
        let mut r = out.fixed_rows_mut::<3>(6 * node + row);
        r += v;
    };
    for i in ENDS {
        let f = lam_bar * g_a[i];
        let dbar = (end.0[i] - end.0[FRAME] + start.0[i] - start.0[FRAME]) * half;
        add(i, 0, f);
        add(FRAME, 0, -f);
        add(FRAME, 3, f.cross(&dbar));
        let pair = [theta[FRAME], theta[i]];
        let (_, tf) = secant_operators(&lam_r[0], &psi[0][i], &psi[1][i], &pair);
        let (_, tb) = secant_operators(&lam_r[1], &psi[1][i], &psi[0][i], &pair.map(|t| -t));
        let dtheta = theta[i] - theta[FRAME];
        let t = corrected((tf + tb) * half, psi[1][i] - psi[0][i], &dtheta, *eps);
        let m = t.transpose() * g_psi[i];
        add(i, 3, m);
        add(FRAME, 3, -m);
    }
    out
}

#[cfg(test)]
#[path = "discrete_gradient_quadratic_tests.rs"]
mod tests;
