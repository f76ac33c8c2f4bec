//! The energy-consistent internal force of the energy–momentum scheme for the
//! 2-node element: a discrete gradient of the element's own strain energy
//! (FORMULATION §4.3).
//!
//! The paper's force `q_k(N̄, M̄)` (eq. 17, [`crate::conserving`]) does work
//! on the step's increments through the operator of the *continuum* strain
//! rates, `Λ̃ᵀ(θ₂ − θ₁)` for the curvature and `½(θ₁ + θ₂)` for the reference
//! rotation; the element's strains are functions of the nodal rotations
//! through the logarithm `φ = log(Λ₁ᵀΛ₂)` and the reference rotation
//! `Λ_r = Λ₁ exp(½φ̂)`, whose rates differ from those by `O(|φ|)` terms. So
//! `Σ p·q_k` misses the strain energy change by terms of order `|φ| Δt` per
//! step — a spatial inconsistency that does not vanish as `Δt → 0`, and the
//! paper's scalar correction `β q_k(N_d, 0)`, whose work is `O(Δt²)`, has to
//! make it up with `β = O(|φ|/Δt)`, growing as the step is refined.
//!
//! Here the strain increments are exact by construction. With `p = (uᵢ, θᵢ)`
//! the step's increments (Cayley `θᵢ`: `Λᵢ,ₙ₊₁ = cay(θᵢ)Λᵢ,ₙ`), `θ_r` the
//! Cayley increment of the reference rotation, `Λ̄_r` the algebraic mean of
//! `Λ_r,ₙ` and `Λ_r,ₙ₊₁` and `d̄ = ½(dₙ + dₙ₊₁)`, `d = x₂ − x₁`:
//!
//! ```text
//! L ΔΓ = Λ̄_rᵀ (Δd + d̄ × θ_r)          (exact: ΔΛ_r = θ̂_r Λ̄_r)
//! L ΔK = Δφ
//! θ_r  = ½(θ₁ + θ₂) + B Δθ,    Δφ = T Δθ,    Δθ = θ₂ − θ₁
//! ```
//!
//! `B` and `T` are smooth operators built from two exact relations of the
//! Cayley increments. The relative rotation advances as
//! `Λ₁ᵀΛ₂ ← cay(c) Λ₁ᵀΛ₂` with `c = Λ₁,ₙᵀ C Δθ`,
//! `C = (I − ½θ̄^)/(1 + ¼θ₁·θ₂)`, `θ̄ = ½(θ₁ + θ₂)` — exactly linear in `Δθ`,
//! however large the element's rigid rotation `θ̄`. So
//! `Δφ = log(cay(c) exp(φ̂ₙ)) − φₙ` and the reference rotation's relative
//! increment `g(c) = cay⁻¹(exp(½φ̂ₙ₊₁) exp(−½φ̂ₙ))` are functions of `c` alone,
//! and `θ_r = compose(θ₁, Λ₁,ₙ g)` (Cayley composition, FORMULATION §1), so
//! `θ_r − θ₁ = E Λ₁,ₙ g/(1 − ¼θ₁·Λ₁,ₙ g)`, `E = I + ½θ̂₁ + ¼θ₁⊗θ₁`. Their
//! Jacobians in `c`, taken at `½c` (midpoint rule of the mean-value
//! integral), `∂φ/∂c = H⁻¹(φ) Q(c)` and
//! `∂g/∂c = Q(g)⁻¹ H(½φ) ½ ∂φ/∂c` (`Q` the Cayley tangent), give
//! `T = ∂φ/∂c Λ₁,ₙᵀ C` and `B = E Λ₁,ₙ ∂g/∂c Λ₁,ₙᵀ C − ½I`, which miss the exact
//! relations only by `O(|c|³)` — third order in the element's *deformation*
//! increment, independent of its rigid rotation. The same operators seen
//! from the step's end (base `n+1`, increments `−θᵢ`) satisfy the same
//! relations; their average is symmetric in time, so the force is consistent
//! at second order. The rank-one (Gonzalez)
//! corrections `B += (δ − BΔθ) ⊗ Δθ/|Δθ|²`, `δ = θ_r − θ̄`, and
//! `T += (Δφ − TΔθ) ⊗ Δθ/|Δθ|²` (`|Δθ|²` regularised by [`RIGID_STEP`]) make
//! them exact for the step; being `O(|Δθ|²)`, they are smooth, and Newton's
//! tangent stays well behaved when an element barely deforms in a step. The
//! force
//!
//! ```text
//! f₁ = −n,  f₂ = n,   n = Λ̄_r N̄,   c = d̄ × n
//! m₁ = −(½I − B)ᵀ c − Tᵀ M̄,    m₂ = −(½I + B)ᵀ c + Tᵀ M̄
//! ```
//!
//! then does the work `Σ p·q = L (N̄·ΔΓ + M̄·ΔK)`, which for the averaged
//! resultants `N̄ = Nₙ₊½`, `M̄ = Mₙ₊½` of a linear elastic section is the strain
//! energy change *exactly*; it is self-equilibrated about the mid-step
//! configuration (forces sum to zero; the two `B` terms sum to `−c`, the `T`
//! terms to zero), so linear and angular momentum are conserved too; and as
//! `Δt → 0` it tends to the exact gradient of the static element
//! ([`BeamElement::internal_force`]) at second order. No
//! scalar β and no bordered Newton system are needed.

use crate::conserving::{Frames, Pose};
use crate::element::BeamElement;
use crate::rotation::{
    cayley_inverse, cayley_of_quaternion, cayley_quaternion, cayley_tangent_inverse,
    exp_quaternion, log_quaternion, mm, mmt, mtm, mv, quaternion_conjugate, quaternion_half,
    quaternion_product, skew, tangent, tangent_inverse,
};
use crate::scalar::{cst, Scalar};
use crate::secant_pair::{secant_operators_both, EndView};
use nalgebra::{Matrix3, SVector, Vector3, Vector4};

/// Width `ε` of the rank-one corrections' regularisation, relative to
/// `1 + |θ₁|² + |θ₂|²`: the corrections divide by `|Δθ|² + ε²` instead of
/// `|Δθ|²`, so they are smooth (and Newton's tangent bounded) when the step
/// is nearly a rigid rotation of the element (`Δθ → 0`), where a plain
/// quotient would switch direction abruptly. The energy identity then holds
/// up to the mismatch times `ε²/(|Δθ|² + ε²)`, and the mismatch is itself
/// `O(|Δθ| |θ|² |φ|)`: below `ε |θ|² |φ|` of the element's moment — at
/// round-off of the step's energy for any step of practical size.
pub const RIGID_STEP: f64 = 1e-7;

/// The pieces of one element's step the discrete gradient is built from.
pub(crate) struct Step<T: Scalar> {
    /// Algebraic mean of the reference rotations.
    pub(crate) lam_bar: Matrix3<T>,
    /// Mean chord `d̄`.
    pub(crate) dbar: Vector3<T>,
    /// The smooth operators `B`, `T` and the mismatches `δ − BΔθ`, `Δφ − TΔθ`.
    pub(crate) b: Matrix3<T>,
    pub(crate) t: Matrix3<T>,
    pub(crate) b_miss: Vector3<T>,
    pub(crate) t_miss: Vector3<T>,
    /// `Δθ/(|Δθ|² + ε²)`, the direction of the rank-one corrections.
    pub(crate) direction: Vector3<T>,
}

/// Spatial tangent of the Cayley map: `δcay(c) cay(c)ᵀ = (Q(c) δc)^`,
/// `Q(c) = (I + ½ĉ)/(1 + ¼|c|²)`.
fn cayley_tangent<T: Scalar>(c: &Vector3<T>) -> Matrix3<T> {
    (Matrix3::identity() + skew(c) * cst::<T>(0.5))
        * (T::one() / (T::one() + c.norm_squared() * cst::<T>(0.25)))
}

/// The smooth secant operators `(B, T)` of a step seen from one end, from
/// that end's relative rotations: [`secant_operators_at`] with the
/// quaternions computed here (for callers that hold rotation vectors only).
pub(crate) fn secant_operators<T: Scalar>(
    lam1: &Matrix3<T>,
    phi0: &Vector3<T>,
    phi1: &Vector3<T>,
    th: &[Vector3<T>; 2],
) -> (Matrix3<T>, Matrix3<T>) {
    let half = cst::<T>(0.5);
    let half0 = exp_quaternion(&(phi0 * half));
    let g = relative_cayley(&exp_quaternion(&(phi1 * half)), &half0);
    secant_operators_at(lam1, &exp_quaternion(phi0), &half0, &g, th)
}

/// The Cayley vector of `Λ(a) Λ(b)ᵀ` from the quaternions `a`, `b`:
/// `cay⁻¹(Λ(a) Λ(b)ᵀ)`.
fn relative_cayley<T: Scalar>(a: &Vector4<T>, b: &Vector4<T>) -> Vector3<T> {
    cayley_of_quaternion(&quaternion_product(a, &quaternion_conjugate(b)))
}

/// The smooth secant operators `(B, T)` of a step seen from one end: node
/// 1's triad `lam1`, the unit quaternions (`w ≥ 0`) of that end's relative
/// rotation `rel0 = exp(φ̂₀)` and of its half `half0 = exp(½φ̂₀)`, the
/// reference rotation's relative increment
/// `g = cay⁻¹(exp(½φ̂₁) exp(−½φ̂₀))` towards the other end, and the Cayley
/// increments `th` of the nodes towards the other end. The rotations of the
/// midpoint rule (`cay(½c) exp(φ̂₀)`, its half, and the increment `g` at ½c)
/// are composed as quaternions, so no logarithm of a matrix and no
/// exponential series is taken; with `T = ∂φ/∂c Λ₁ᵀC` and
/// `∂g/∂c = ½ Q(g)⁻¹ H(½φ) ∂φ/∂c` (module docs),
/// `B = ½ E Λ₁ Q(g)⁻¹ H(½φ) T − ½I`.
pub(crate) fn secant_operators_at<T: Scalar>(
    lam1: &Matrix3<T>,
    rel0: &Vector4<T>,
    half0: &Vector4<T>,
    g: &Vector3<T>,
    th: &[Vector3<T>; 2],
) -> (Matrix3<T>, Matrix3<T>) {
    let half = cst::<T>(0.5);
    let quarter = cst::<T>(0.25);
    let id = Matrix3::identity();
    let dtheta = th[1] - th[0];
    let tbar = (th[0] + th[1]) * half;
    // Λ₁ᵀΛ₂ advances by cay(c), c = Λ₁ᵀ C Δθ exactly.
    let to_rel = mtm(lam1, &(id - skew(&tbar) * half))
        * (T::one() / (T::one() + th[0].dot(&th[1]) * quarter));
    let c_half = mv(&to_rel, &dtheta) * half;
    // φ(c) = log(cay(c) exp(φ̂₀)) and g(c) at ½c (midpoint rule).
    let mut q = quaternion_product(&cayley_quaternion(&c_half), rel0);
    if q.x.value() < 0.0 {
        q = -q;
    }
    let phi_h = log_quaternion(&q);
    let g_h = relative_cayley(&quaternion_half(&q), half0);
    let t = mm(
        &mm(&tangent_inverse(&phi_h), &cayley_tangent(&c_half)),
        &to_rel,
    );
    // θ_r − θ₁ = E b/(1 − ¼θ₁·b), b = Λ₁ g (Cayley composition).
    let b = mv(lam1, g);
    let e = (id + skew(&th[0]) * half + th[0] * th[0].transpose() * quarter)
        * (T::one() / (T::one() - th[0].dot(&b) * quarter));
    let dg = mm(&cayley_tangent_inverse(&g_h), &tangent(&(phi_h * half)));
    (mm(&mm(&mm(&e, lam1), &dg), &t) * half - id * half, t)
}

/// The discrete gradient's [`Step`] between two poses' [`Frames`].
pub(crate) fn dg_step_of<T: Scalar>(s: &Frames<T>, e: &Frames<T>) -> Step<T> {
    dg_step_with(s, e, |s, e, g, theta| {
        [
            secant_operators_at(&s.lam[0], &s.rel, &s.half, g, theta),
            secant_operators_at(&e.lam[0], &e.rel, &e.half, &(-g), &theta.map(|t| -t)),
        ]
    })
}

/// [`dg_step_of`] with the operators of both ends computed two at once
/// ([`crate::secant_pair`]): the same bits.
pub(crate) fn dg_step_in_pairs(s: &Frames<f64>, e: &Frames<f64>) -> Step<f64> {
    dg_step_with(s, e, |s, e, g, theta| {
        secant_operators_both([
            EndView {
                lam1: &s.lam[0],
                rel0: &s.rel,
                half0: &s.half,
                g: *g,
                th: *theta,
            },
            EndView {
                lam1: &e.lam[0],
                rel0: &e.rel,
                half0: &e.half,
                g: -g,
                th: theta.map(|t| -t),
            },
        ])
    })
}

/// The discrete gradient's [`Step`] with the secant operators `(B, T)` of
/// the step seen from its start and from its end, `[start, end]`, from
/// `both` of the two poses' [`Frames`], the reference rotation's relative
/// increment `g` and the nodes' increments `θᵢ`.
fn dg_step_with<T: Scalar, F>(s: &Frames<T>, e: &Frames<T>, both: F) -> Step<T>
where
    F: Fn(&Frames<T>, &Frames<T>, &Vector3<T>, &[Vector3<T>; 2]) -> [(Matrix3<T>, Matrix3<T>); 2],
{
    let half = cst::<T>(0.5);
    let theta = [0, 1].map(|i| cayley_inverse(&mmt(&e.lam[i], &s.lam[i])));
    let dtheta = theta[1] - theta[0];
    let delta = cayley_inverse(&mmt(&e.lam_r, &s.lam_r)) - (theta[0] + theta[1]) * half;
    // The average of the operators seen from both ends is symmetric in
    // time, hence consistent at second order; seen from the end, the
    // reference rotation's relative increment is the start's reversed.
    let g = relative_cayley(&e.half, &s.half);
    let [(bf, tf), (bb, tb)] = both(s, e, &g, &theta);
    let (b, t) = ((bf + bb) * half, (tf + tb) * half);
    let eps = (T::one() + theta[0].norm_squared() + theta[1].norm_squared()) * cst::<T>(RIGID_STEP);
    Step {
        lam_bar: (s.lam_r + e.lam_r) * half,
        dbar: (e.d + s.d) * half,
        b_miss: delta - b * dtheta,
        t_miss: (e.phi - s.phi) - t * dtheta,
        b,
        t,
        direction: dtheta / (dtheta.norm_squared() + eps * eps),
    }
}

impl BeamElement<2> {
    pub(crate) fn dg_step<T: Scalar>(&self, start: &Pose<T>, end: &Pose<T>) -> Step<T> {
        dg_step_of(&self.frames(start), &self.frames(end))
    }

    /// The energy-consistent internal force between the poses at `n` and
    /// `n+1` for the material resultants `(nbar, mbar)` (the step averages
    /// in the scheme), ordered `(f₁, m₁, f₂, m₂)`; see the module docs.
    pub fn discrete_gradient_force<T: Scalar>(
        &self,
        start: &Pose<T>,
        end: &Pose<T>,
        nbar: &Vector3<T>,
        mbar: &Vector3<T>,
    ) -> SVector<T, 12> {
        self.discrete_gradient_parts(start, end, nbar, mbar).0
    }

    /// [`Self::discrete_gradient_force`] and, separately, the part of it due
    /// to the rank-one corrections. The ratio of their sizes, `O(|Δθ|²)`,
    /// measures how far the smooth operators are from exact for the step.
    pub fn discrete_gradient_parts<T: Scalar>(
        &self,
        start: &Pose<T>,
        end: &Pose<T>,
        nbar: &Vector3<T>,
        mbar: &Vector3<T>,
    ) -> (SVector<T, 12>, SVector<T, 12>) {
        step_force(&self.dg_step(start, end), nbar, mbar)
    }

    /// The energy–momentum scheme's element force: the discrete gradient
    /// with the step averages `N̄ = ½(Nₙ + Nₙ₊₁)`, `M̄ = ½(Mₙ + Mₙ₊₁)` of the
    /// element's own resultants ([`Self::resultants`]), every rotation
    /// piece of the two poses computed once.
    pub fn energy_momentum_force<T: Scalar>(
        &self,
        start: &Pose<T>,
        end: &Pose<T>,
    ) -> SVector<T, 12> {
        self.energy_momentum_force_parts(start, end).0
    }

    /// [`Self::energy_momentum_force`] and, separately, the part of it due
    /// to the rank-one corrections (as [`Self::discrete_gradient_parts`]).
    pub fn energy_momentum_force_parts<T: Scalar>(
        &self,
        start: &Pose<T>,
        end: &Pose<T>,
    ) -> (SVector<T, 12>, SVector<T, 12>) {
        let (s, e) = (self.frames(start), self.frames(end));
        let (nbar, mbar) = self.averaged_resultants(&s, &e);
        step_force(&dg_step_of(&s, &e), &nbar, &mbar)
    }

    /// The step averages `(N̄, M̄)` of the resultants of two poses.
    pub(crate) fn averaged_resultants<T: Scalar>(
        &self,
        s: &Frames<T>,
        e: &Frames<T>,
    ) -> (Vector3<T>, Vector3<T>) {
        let half = cst::<T>(0.5);
        let ((n0, m0), (n1, m1)) = (self.frame_resultants(s), self.frame_resultants(e));
        ((n0 + n1) * half, (m0 + m1) * half)
    }
}

/// The discrete gradient force of a [`Step`] for the resultants
/// `(nbar, mbar)` and, separately, its rank-one corrections' part.
pub(crate) fn step_force<T: Scalar>(
    st: &Step<T>,
    nbar: &Vector3<T>,
    mbar: &Vector3<T>,
) -> (SVector<T, 12>, SVector<T, 12>) {
    let half = cst::<T>(0.5);
    let n = st.lam_bar * nbar;
    let c = st.dbar.cross(&n);
    // Moments of the smooth operators B, T.
    let arm = c * (-half);
    let bc = st.b.transpose() * c;
    let tm = st.t.transpose() * mbar;
    let mut q = SVector::<T, 12>::zeros();
    q.fixed_rows_mut::<3>(0).copy_from(&(-n));
    q.fixed_rows_mut::<3>(3).copy_from(&(arm + bc - tm));
    q.fixed_rows_mut::<3>(6).copy_from(&n);
    q.fixed_rows_mut::<3>(9).copy_from(&(arm - bc + tm));
    // (v ⊗ w)ᵀ x = w (v·x), w = Δθ/(|Δθ|² + ε²).
    let extra = st.direction * (mbar.dot(&st.t_miss) - c.dot(&st.b_miss));
    let mut corr = SVector::<T, 12>::zeros();
    corr.fixed_rows_mut::<3>(3).copy_from(&(-extra));
    corr.fixed_rows_mut::<3>(9).copy_from(&extra);
    q += corr;
    (q, corr)
}

#[cfg(test)]
#[path = "discrete_gradient_tests.rs"]
mod tests;
