//! Geometrically exact (Reissner–Simo) beam element with the strain-invariant
//! interpolation of Crisfield & Jelenić (FORMULATION §2).
//!
//! Node `i` of an element carries its position `xᵢ` and its nodal rotation `Rᵢ`
//! (measured from the initial configuration); the element's triad at the node is
//! `Λᵢ = Rᵢ Λ₀ᵢ` with `Λ₀ᵢ` the initial triad, so beams with initial curvature
//! (arcs) are handled exactly like straight ones.
//!
//! Interpolation: reference rotation `Λ_r = Λ_I exp(½φ̂_IJ)`,
//! `φ_IJ = log(Λ_Iᵀ Λ_J)` from the two middle nodes; local rotations
//! `ψᵢ = log(Λ_rᵀ Λᵢ)`; `ψ(s) = Σ Iᵢ(s) ψᵢ`; `Λ(s) = Λ_r exp(ψ̂(s))`. Material
//! strains `Γ = Λᵀ r′ − Γ₀`, `K = Hᵀ(ψ) ψ′ − K₀` (`Λᵀ Λ′ = (Hᵀψ′)^`), with
//! `Γ₀`, `K₀` those of the interpolated initial configuration (so the initial
//! configuration is stress-free exactly). Reduced (n − 1 point) Gauss rule.
//!
//! Every kernel is generic over the [`Scalar`]: the strain energy is the single
//! source of truth, and num-dual differentiates it. The residual is the
//! gradient of the energy with respect to nodal position increments and
//! *spatial* spin increments (`Rᵢ ← exp(δφ̂ᵢ) Rᵢ`); the tangent is the
//! derivative of that residual under the same increments.

use crate::rotation::{exp, log, mm, tangent, tangent_inverse};
use crate::scalar::{cst, Scalar};
use crate::section::Section;
use crate::shape::{lagrange, reduced_gauss};
use nalgebra::{Const, Matrix3, SMatrix, SVector, Vector3, U1};
use num_dual::{DualSVec64, HyperDualSVec64};

/// Material strains `(Γ, K)` at a quadrature point.
pub type Strains<T> = (Vector3<T>, Vector3<T>);

/// An `N`-node beam element (`N` = 2 or 3): its nodes and its initial geometry.
#[derive(Debug, Clone, PartialEq)]
pub struct BeamElement<const N: usize> {
    /// Global node numbers, in order along the beam.
    pub nodes: [usize; N],
    /// Section and material.
    pub section: Section,
    /// Initial arc length `L`.
    pub length: f64,
    /// Initial triads `Λ₀ᵢ` at the nodes (columns: beam axis, section axes 2, 3).
    pub lambda0: [Matrix3<f64>; N],
    /// Strains of the initial configuration at the Gauss points (first `N − 1` used).
    strain0: [Strains<f64>; 2],
    /// For `N = 2`, the same strains through the invariant coordinates
    /// ([`BeamElement::energy_linear`]'s formula, so that its energy is
    /// exactly zero in the initial configuration); zero otherwise.
    linear0: Strains<f64>,
}

/// The two middle nodes `(I, J)` that define the reference rotation.
const fn reference_nodes(n: usize) -> (usize, usize) {
    (n.div_ceil(2) - 1, (n + 2) / 2 - 1)
}

impl<const N: usize> BeamElement<N> {
    /// Number of nodal unknowns, `6N`.
    pub const DOFS: usize = 6 * N;

    /// An element with initial nodal positions `x0` and triads `lambda0`.
    pub fn new(
        nodes: [usize; N],
        section: Section,
        length: f64,
        x0: &[Vector3<f64>; N],
        lambda0: [Matrix3<f64>; N],
    ) -> Self {
        let mut element = Self {
            nodes,
            section,
            length,
            lambda0,
            strain0: [(Vector3::zeros(), Vector3::zeros()); 2],
            linear0: (Vector3::zeros(), Vector3::zeros()),
        };
        element.strain0 = element.total_strains(x0, &[Matrix3::identity(); N]);
        if N == 2 {
            let lam = element.triads(&[Matrix3::identity(); N]);
            element.linear0 = crate::element_linear::invariant_strains(
                (&lam[0], &lam[1]),
                &(x0[N - 1] - x0[0]),
                length,
            );
        }
        element
    }

    /// The element with its stress-free strains lowered by `delta` at its
    /// Gauss points (first `N − 1` used): in its initial configuration it
    /// then carries the stress resultants `(C_N Δ_Γ, C_M Δ_K)` — the
    /// prestress of linear buckling ([`crate::prestress`]).
    pub fn prestrained(&self, delta: &[Strains<f64>]) -> Self {
        let mut e = self.clone();
        for (s0, d) in e.strain0.iter_mut().zip(delta).take(N - 1) {
            s0.0 -= d.0;
            s0.1 -= d.1;
        }
        if let (2, Some(d)) = (N, delta.first()) {
            e.linear0.0 -= d.0;
            e.linear0.1 -= d.1;
        }
        e
    }

    /// Strains of the initial configuration at the Gauss points.
    pub fn initial_strains(&self) -> &[Strains<f64>] {
        &self.strain0[..N - 1]
    }

    /// [`Self::linear0`]: a 2-node element's initial strains through its
    /// invariant coordinates.
    pub(crate) fn initial_invariant_strains(&self) -> Strains<f64> {
        self.linear0
    }

    /// Nodal triads `Λᵢ = Rᵢ Λ₀ᵢ` (public form of the kernels' helper).
    pub fn nodal_triads(&self, rot: &[Matrix3<f64>; N]) -> [Matrix3<f64>; N] {
        self.triads(rot)
    }

    /// Nodal triads `Λᵢ = Rᵢ Λ₀ᵢ`.
    #[inline(always)]
    pub(crate) fn triads<T: Scalar>(&self, rot: &[Matrix3<T>; N]) -> [Matrix3<T>; N] {
        // Filled in place (`std::array::from_fn` copied them out with `memcpy`).
        let mut out = [Matrix3::zeros(); N];
        for (o, (r, l0)) in out.iter_mut().zip(rot.iter().zip(&self.lambda0)) {
            *o = mm(r, &l0.map(cst::<T>));
        }
        out
    }

    /// Total (not yet reduced by the initial values) material strains
    /// `(Λᵀr′, Hᵀ(ψ)ψ′)` at the Gauss points.
    fn total_strains<T: Scalar>(
        &self,
        x: &[Vector3<T>; N],
        rot: &[Matrix3<T>; N],
    ) -> [Strains<T>; 2] {
        let lam = self.triads(rot);
        let (i, j) = reference_nodes(N);
        let lam_r = if i == j {
            lam[i]
        } else {
            let phi = log(&(lam[i].transpose() * lam[j]));
            lam[i] * exp(&(phi * cst::<T>(0.5)))
        };
        let psi: [Vector3<T>; N] = std::array::from_fn(|k| log(&(lam_r.transpose() * lam[k])));
        let ds = 2.0 / self.length;
        let mut out = [(Vector3::zeros(), Vector3::zeros()); 2];
        for (g, &(xi, _)) in reduced_gauss(N).iter().enumerate() {
            let (v, d) = lagrange(N, xi);
            let mut p = Vector3::zeros();
            let mut dp = Vector3::zeros();
            let mut dr = Vector3::zeros();
            for k in 0..N {
                p += psi[k] * cst::<T>(v[k]);
                dp += psi[k] * cst::<T>(d[k] * ds);
                dr += x[k] * cst::<T>(d[k] * ds);
            }
            let lam_g = lam_r * exp(&p);
            out[g] = (lam_g.transpose() * dr, tangent(&p).transpose() * dp);
        }
        out
    }

    /// Material strains `(Γ, K)` at the Gauss points, measured from the initial
    /// configuration (zero for any rigid motion of it).
    pub fn strains<T: Scalar>(
        &self,
        x: &[Vector3<T>; N],
        rot: &[Matrix3<T>; N],
    ) -> [Strains<T>; 2] {
        let mut s = self.total_strains(x, rot);
        for (g, s0) in self.strain0.iter().enumerate().take(N - 1) {
            s[g].0 -= s0.0.map(cst::<T>);
            s[g].1 -= s0.1.map(cst::<T>);
        }
        s
    }

    /// Material stress resultants `(N, M) = (C_N Γ, C_M K)` at the Gauss points.
    pub fn stresses<T: Scalar>(
        &self,
        x: &[Vector3<T>; N],
        rot: &[Matrix3<T>; N],
    ) -> [Strains<T>; 2] {
        let cn = self.section.c_n.map(cst::<T>);
        let cm = self.section.c_m.map(cst::<T>);
        self.strains(x, rot)
            .map(|(g, k)| (g.component_mul(&cn), k.component_mul(&cm)))
    }

    /// Strain energy `Π = Σ_g w_g (L/2) ½ (Γ·C_N Γ + K·C_M K)`.
    pub fn energy<T: Scalar>(&self, x: &[Vector3<T>; N], rot: &[Matrix3<T>; N]) -> T {
        let cn = self.section.c_n.map(cst::<T>);
        let cm = self.section.c_m.map(cst::<T>);
        let s = self.strains(x, rot);
        let mut e = T::zero();
        for (g, &(_, w)) in reduced_gauss(N).iter().enumerate() {
            let (gam, kap) = s[g];
            e += (gam.component_mul(&cn).dot(&gam) + kap.component_mul(&cm).dot(&kap))
                * cst::<T>(0.25 * w * self.length);
        }
        e
    }

    /// `∂Π/∂σ` at `σ = 1` for the element's initial length stretched to
    /// `σL` along its straight axis, the initial strains `(Γ₀, K₀) = (e₁, 0)`
    /// of a straight element unchanged: the strains from the initial
    /// configuration become `(Γ + Γ₀)/σ − Γ₀` and `K/σ`, the weights `σL`, so
    ///
    /// ```text
    /// ∂Π/∂σ = −Σ_g w_g (L/2) (½ Γ·C_N Γ + Γ₀·C_N Γ + ½ K·C_M K).
    /// ```
    ///
    /// For any scalar: its gradient is the internal force's derivative by
    /// the stretch (exact sensitivities by a beam's end coordinates).
    pub fn stretch_rate<T: Scalar>(&self, x: &[Vector3<T>; N], rot: &[Matrix3<T>; N]) -> T {
        let cn = self.section.c_n.map(cst::<T>);
        let cm = self.section.c_m.map(cst::<T>);
        let s = self.strains(x, rot);
        let mut e = T::zero();
        for (g, &(_, w)) in reduced_gauss(N).iter().enumerate() {
            let (gam, kap) = s[g];
            let gam0 = self.strain0[g].0.map(cst::<T>);
            let n = gam.component_mul(&cn);
            e -= (n.dot(&gam) * cst::<T>(0.5)
                + n.dot(&gam0)
                + kap.component_mul(&cm).dot(&kap) * cst::<T>(0.5))
                * cst::<T>(0.5 * w * self.length);
        }
        e
    }

    /// Gradient of [`Self::energy`] with respect to the nodal increments
    /// `(δx₀, δφ₀, δx₁, δφ₁, …)` (spatial spins), by forward-mode AD.
    /// `D` must equal `6N`.
    pub fn energy_gradient<const D: usize>(
        &self,
        x: &[Vector3<f64>; N],
        rot: &[Matrix3<f64>; N],
    ) -> SVector<f64, D> {
        assert_eq!(D, 6 * N, "energy_gradient: D must be 6N");
        let seed = |k: usize| DualSVec64::<D>::from_re(0.0).derivative(k);
        let xd: [Vector3<DualSVec64<D>>; N] = std::array::from_fn(|i| {
            x[i].map(DualSVec64::from_re)
                + Vector3::new(seed(6 * i), seed(6 * i + 1), seed(6 * i + 2))
        });
        let rd: [Matrix3<DualSVec64<D>>; N] = std::array::from_fn(|i| {
            let spin = Vector3::new(seed(6 * i + 3), seed(6 * i + 4), seed(6 * i + 5));
            exp(&spin) * rot[i].map(DualSVec64::from_re)
        });
        self.energy(&xd, &rd).eps.unwrap_generic(Const::<D>, U1)
    }

    /// Residual and consistent tangent from the energy alone, with hyper-dual
    /// numbers: `rᵢ = ∂E/∂εᵢ`, `K_ij = ∂²E/∂εᵢ∂η_j` of
    /// `E(x + ε + η, exp(ε̂) exp(η̂) R)` at zero. `K` is the exact derivative of
    /// the residual under spatial increments (not symmetric away from
    /// equilibrium: the spin parametrisation adds `−½ m̂` to the diagonal blocks).
    pub fn residual_tangent_ad<const D: usize>(
        &self,
        x: &[Vector3<f64>; N],
        rot: &[Matrix3<f64>; N],
    ) -> (SVector<f64, D>, SMatrix<f64, D, D>) {
        self.gradient_hessian_ad(x, rot, |xd, rd| self.energy(xd, rd))
    }

    /// Kelvin–Voigt damping of a step, as a pseudo-potential of the end
    /// configuration: `ψ = Σ_g w_g (L/2) ½ c (ΔΓ·C_N ΔΓ + ΔK·C_M ΔK)` with
    /// `Δ` the change of the strains from `start` (the step's first
    /// configuration) and `c = η/Δt` (`η` the section's damping time). Its
    /// gradient is the damping force `Bᵀ η C (Δε/Δt)` — the resultants
    /// `η C ε̇` with the step's strain rate `Δε/Δt` — and `2ψ` the energy
    /// the damping dissipates over the step (FORMULATION §4.7).
    pub fn damping_potential<T: Scalar>(
        &self,
        x: &[Vector3<T>; N],
        rot: &[Matrix3<T>; N],
        start: &[Strains<f64>; 2],
        c: f64,
    ) -> T {
        let cn = self.section.c_n.map(cst::<T>);
        let cm = self.section.c_m.map(cst::<T>);
        let s = self.strains(x, rot);
        let mut e = T::zero();
        for (g, &(_, w)) in reduced_gauss(N).iter().enumerate() {
            let dg = s[g].0 - start[g].0.map(cst::<T>);
            let dk = s[g].1 - start[g].1.map(cst::<T>);
            e += (dg.component_mul(&cn).dot(&dg) + dk.component_mul(&cm).dot(&dk))
                * cst::<T>(0.25 * w * self.length * c);
        }
        e
    }

    /// Gradient and Hessian of a scalar function `f` of the element's nodes
    /// under spatial increments, with hyper-dual numbers (see
    /// [`Self::residual_tangent_ad`]).
    pub fn gradient_hessian_ad<const D: usize>(
        &self,
        x: &[Vector3<f64>; N],
        rot: &[Matrix3<f64>; N],
        f: impl Fn(
            &[Vector3<HyperDualSVec64<D, D>>; N],
            &[Matrix3<HyperDualSVec64<D, D>>; N],
        ) -> HyperDualSVec64<D, D>,
    ) -> (SVector<f64, D>, SMatrix<f64, D, D>) {
        assert_eq!(D, 6 * N, "gradient_hessian_ad: D must be 6N");
        type H<const D: usize> = HyperDualSVec64<D, D>;
        let e1 = |k: usize| H::<D>::from_re(0.0).derivative1(k);
        let e2 = |k: usize| H::<D>::from_re(0.0).derivative2(k);
        let v = |f: &dyn Fn(usize) -> H<D>, k: usize| Vector3::new(f(k), f(k + 1), f(k + 2));
        let xd: [Vector3<H<D>>; N] =
            std::array::from_fn(|i| x[i].map(H::<D>::from_re) + v(&e1, 6 * i) + v(&e2, 6 * i));
        let rd: [Matrix3<H<D>>; N] = std::array::from_fn(|i| {
            exp(&v(&e1, 6 * i + 3)) * exp(&v(&e2, 6 * i + 3)) * rot[i].map(H::<D>::from_re)
        });
        let e = f(&xd, &rd);
        (
            e.eps1.unwrap_generic(Const::<D>, U1),
            e.eps1eps2.unwrap_generic(Const::<D>, Const::<D>),
        )
    }
}

impl<const N: usize> BeamElement<N> {
    /// [`Self::residual_tangent_ad`] with the tangent's second derivative
    /// taken along the increments of nodes `1..N` only (`E = 6N − 6`
    /// hyper-dual lanes instead of `6N`); node 0's columns follow from
    /// objectivity. The residual `r` turns with the element and does not see
    /// a translation: `Σₙ ∂r/∂xₙ = 0` and
    /// `Σₙ (∂r/∂εₙ − (∂r/∂xₙ) x̂ₙ) = −r̂` (each 3-block `f` of `r`
    /// contributing `f̂`), so `∂r/∂x₀ = −Σ_{n≥1} ∂r/∂xₙ` and
    /// `∂r/∂ε₀ = −r̂ + Σₙ (∂r/∂xₙ) x̂ₙ − Σ_{n≥1} ∂r/∂εₙ`.
    pub fn residual_tangent_invariant<const D: usize, const E: usize>(
        &self,
        x: &[Vector3<f64>; N],
        rot: &[Matrix3<f64>; N],
    ) -> (SVector<f64, D>, SMatrix<f64, D, D>) {
        assert!(
            D == 6 * N && E + 6 == D,
            "residual_tangent_invariant: D = 6N, E = D - 6"
        );
        type H<const D: usize, const E: usize> = HyperDualSVec64<D, E>;
        let e1 = |k: usize| H::<D, E>::from_re(0.0).derivative1(k);
        let e2 = |k: usize| H::<D, E>::from_re(0.0).derivative2(k);
        let v = |f: &dyn Fn(usize) -> H<D, E>, k: usize| Vector3::new(f(k), f(k + 1), f(k + 2));
        let zero = Vector3::from_element(H::<D, E>::from_re(0.0));
        let lane2 = |i: usize, k: usize| {
            if i == 0 {
                zero
            } else {
                v(&e2, 6 * (i - 1) + k)
            }
        };
        let xd: [Vector3<H<D, E>>; N] =
            std::array::from_fn(|i| x[i].map(H::<D, E>::from_re) + v(&e1, 6 * i) + lane2(i, 0));
        let rd: [Matrix3<H<D, E>>; N] = std::array::from_fn(|i| {
            exp(&v(&e1, 6 * i + 3)) * exp(&lane2(i, 3)) * rot[i].map(H::<D, E>::from_re)
        });
        let e = self.energy(&xd, &rd);
        let r: SVector<f64, D> = e.eps1.unwrap_generic(Const::<D>, U1);
        let partial: SMatrix<f64, D, E> = e.eps1eps2.unwrap_generic(Const::<D>, Const::<E>);
        let mut k = SMatrix::<f64, D, D>::zeros();
        k.columns_mut(6, E).copy_from(&partial);
        let mut jx0 = SMatrix::<f64, D, 3>::zeros();
        let mut je0 = SMatrix::<f64, D, 3>::zeros();
        // Σₙ (∂r/∂xₙ) x̂ₙ, node 0's block included once it is known.
        let mut moment = SMatrix::<f64, D, 3>::zeros();
        for (n, xn) in x.iter().enumerate().skip(1) {
            let jx = k.fixed_columns::<3>(6 * n).into_owned();
            jx0 -= jx;
            je0 -= k.fixed_columns::<3>(6 * n + 3);
            moment += jx * xn.cross_matrix();
        }
        moment += jx0 * x[0].cross_matrix();
        je0 += moment;
        for block in 0..2 * N {
            let f = Vector3::new(r[3 * block], r[3 * block + 1], r[3 * block + 2]);
            let mut rows = je0.fixed_view_mut::<3, 3>(3 * block, 0);
            rows -= f.cross_matrix();
        }
        k.fixed_columns_mut::<3>(0).copy_from(&jx0);
        k.fixed_columns_mut::<3>(3).copy_from(&je0);
        (r, k)
    }
}

impl BeamElement<2> {
    /// Closed-form internal force of the 2-node element (one-point rule), the
    /// exact gradient of its energy:
    /// with `φ = log(Λ₁ᵀΛ₂)`, `Λ_r = Λ₁ exp(½φ̂)`, `d = x₂ − x₁`,
    /// `Γ = Λ_rᵀd/L − Γ₀`, `K = φ/L − K₀`, `n = Λ_r C_N Γ`, `c = n × d`,
    /// `m̃ = Λ₁ H⁻ᵀ(φ) C_M K`, `b = ½ Λ₁ H⁻ᵀ(φ) Hᵀ(½φ) Λ₁ᵀ c`:
    /// `f₁ = −n`, `f₂ = n`, `m₁ = c − b − m̃`, `m₂ = b + m̃`
    /// (ordered `(f₁, m₁, f₂, m₂)`; self-equilibrated).
    pub fn internal_force<T: Scalar>(
        &self,
        x: &[Vector3<T>; 2],
        rot: &[Matrix3<T>; 2],
    ) -> SVector<T, 12> {
        let lam = self.triads(rot);
        let l = cst::<T>(self.length);
        let half = cst::<T>(0.5);
        let phi = log(&(lam[0].transpose() * lam[1]));
        let lam_r = lam[0] * exp(&(phi * half));
        let d = x[1] - x[0];
        let (g0, k0) = self.strain0[0];
        let gam = lam_r.transpose() * d / l - g0.map(cst::<T>);
        let kap = phi / l - k0.map(cst::<T>);
        let n = lam_r * gam.component_mul(&self.section.c_n.map(cst::<T>));
        let c = n.cross(&d);
        let hinv_t = tangent_inverse(&(-phi));
        let m_tilde = lam[0] * (hinv_t * kap.component_mul(&self.section.c_m.map(cst::<T>)));
        let b = lam[0] * (hinv_t * (tangent(&(-phi * half)) * (lam[0].transpose() * c))) * half;
        let mut r = SVector::<T, 12>::zeros();
        r.fixed_rows_mut::<3>(0).copy_from(&(-n));
        r.fixed_rows_mut::<3>(3).copy_from(&(c - b - m_tilde));
        r.fixed_rows_mut::<3>(6).copy_from(&n);
        r.fixed_rows_mut::<3>(9).copy_from(&(b + m_tilde));
        r
    }

    /// Residual (closed form) and tangent under spatial increments
    /// `x ← x + η`, `R ← exp(η̂)R`, by forward-mode AD over six directions
    /// only. The force depends on the positions through `d = x₂ − x₁`, so
    /// `∂F/∂x₂ = −∂F/∂x₁ = ∂F/∂d`; and it turns with the element
    /// (objectivity: `F(Qd, QR₁, QR₂) = Q F`), which differentiated along
    /// `Q = exp(ε̂)` gives `∂F/∂ε₁ + ∂F/∂ε₂ − (∂F/∂d) d̂ = −F̂` (each 3-block
    /// `f` of `F` contributes `f̂ = [f]ₓ`). So the AD lanes are `d` and the
    /// spin of node 2, and `∂F/∂ε₁ = −F̂ + (∂F/∂d) d̂ − ∂F/∂ε₂` — half the
    /// lanes of the plain Jacobian, equal to it to round-off (tested against
    /// the hyper-dual second derivative of the energy).
    pub fn residual_tangent(
        &self,
        x: &[Vector3<f64>; 2],
        rot: &[Matrix3<f64>; 2],
    ) -> (SVector<f64, 12>, SMatrix<f64, 12, 12>) {
        type D = DualSVec64<6>;
        let seed = |k: usize| D::from_re(0.0).derivative(k);
        let v = |k: usize| Vector3::new(seed(k), seed(k + 1), seed(k + 2));
        let xd: [Vector3<D>; 2] = [x[0].map(D::from_re), x[1].map(D::from_re) + v(0)];
        let rd: [Matrix3<D>; 2] = [rot[0].map(D::from_re), exp(&v(3)) * rot[1].map(D::from_re)];
        let rf = self.internal_force(&xd, &rd);
        let mut r = SVector::<f64, 12>::zeros();
        let mut jd = SMatrix::<f64, 12, 3>::zeros();
        let mut j2 = SMatrix::<f64, 12, 3>::zeros();
        for i in 0..12 {
            r[i] = rf[i].re;
            let eps = rf[i].eps.unwrap_generic(Const::<6>, U1);
            for c in 0..3 {
                jd[(i, c)] = eps[c];
                j2[(i, c)] = eps[3 + c];
            }
        }
        let d_hat = (x[1] - x[0]).cross_matrix();
        let mut j1 = jd * d_hat - j2;
        for block in 0..4 {
            let f = Vector3::new(r[3 * block], r[3 * block + 1], r[3 * block + 2]);
            let mut rows = j1.fixed_view_mut::<3, 3>(3 * block, 0);
            rows -= f.cross_matrix();
        }
        let mut k = SMatrix::<f64, 12, 12>::zeros();
        k.fixed_view_mut::<12, 3>(0, 0).copy_from(&(-jd));
        k.fixed_view_mut::<12, 3>(0, 3).copy_from(&j1);
        k.fixed_view_mut::<12, 3>(0, 6).copy_from(&jd);
        k.fixed_view_mut::<12, 3>(0, 9).copy_from(&j2);
        (r, k)
    }
}

#[cfg(test)]
#[path = "element_tests.rs"]
mod tests;
