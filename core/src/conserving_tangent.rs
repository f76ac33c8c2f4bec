//! Newton tangents of the conserving schemes' 2-node element forces
//! (FORMULATION §4), under spatial increments of the step's end pose
//! (`x ← x + η`, `R ← exp(η̂)R`) — the start pose is fixed.
//!
//! * Momentum scheme ([`BeamElement::momentum_force_tangent`]): the force
//!   `q_k(Nₙ₊½, Mₙ₊½)` with the geodesic mid rotation (paper eq. 17) and its
//!   derivative in closed form, by the chain rule through the end pose's
//!   relative rotation `φ = log(Λ₁ᵀΛ₂)`, reference rotation `Λ_r` and chord
//!   `d = x₂ − x₁`:
//!
//!   ```text
//!   δφ  = S (ε₂ − ε₁),                     S = H⁻¹(φ) Λ₁ᵀ
//!   w_r = (I − P) ε₁ + P ε₂,                P = ½ Λ₁ H(½φ) S      (spin of Λ_r)
//!   δN̄ = ½ C_N Λ_rᵀ (δd + d̂ w_r)/L,        δM̄ = ½ C_M δφ/L
//!   w̃  = G w_r,                            G = ½ H(½ω) H⁻¹(ω),  ω = log(Λ_r Λ_r,ₙᵀ)
//!   δn  = −n̂ w̃ + Λ̃ δN̄,                    δm = −m̂ w̃ + Λ̃ δM̄
//!   δ(−½ d̄ × n) = ¼ n̂ δd − ½ d̄̂ δn
//!   ```
//!
//!   equal to the AD derivative of the generic kernel to round-off (tested).
//! * Energy–momentum scheme ([`BeamElement::energy_momentum_force_tangent`]):
//!   the discrete gradient's secant operators `B`, `T` and its rank-one
//!   corrections depend on the end *rotations* only, so forward AD runs over
//!   the six end spins (half the lanes of the full Jacobian) with the
//!   positions held; the force depends on the end positions only through the
//!   chord `d₂ = x₂ − x₁` — in `N̄` (`∂N̄/∂d₂ = ½ C_N Λ_rᵀ/L`) and in
//!   `d̄ = ½(dₙ + dₙ₊₁)` — whose columns are closed form:
//!
//!   ```text
//!   ∂n/∂d₂ = A = ½ Λ̄_r C_N Λ_rᵀ/L,   ∂c/∂d₂ = C = −½ n̂ + d̄̂ A,   (c = d̄ × n)
//!   ∂f₂ = −∂f₁ = A,   ∂m₁ = −½C + BᵀC + w ⊗ (b_missᵀ C),   ∂m₂ = −½C − BᵀC − w ⊗ (b_missᵀ C)
//!   ```
//!
//!   (`w = Δθ/(|Δθ|² + ε²)`, `b_miss = δ − BΔθ`), and
//!   `∂q/∂x₂ = −∂q/∂x₁ = ∂q/∂d₂`.

use crate::conserving::{Frames, Pose};
use crate::element::BeamElement;
use crate::rotation::{exp, log, tangent, tangent_inverse};
use nalgebra::{Const, Matrix3, SMatrix, SVector, Vector3, U1};
use num_dual::DualSVec64;

/// A 3 × 12 Jacobian with respect to `(η₁, ε₁, η₂, ε₂)`.
type Jac = SMatrix<f64, 3, 12>;

/// `[a, b, c, d]` side by side as a 3 × 12 Jacobian.
fn jac(blocks: [Matrix3<f64>; 4]) -> Jac {
    let mut j = Jac::zeros();
    for (k, b) in blocks.iter().enumerate() {
        j.fixed_view_mut::<3, 3>(0, 3 * k).copy_from(b);
    }
    j
}

/// The element force vector `(−n, a − m, n, a + m)` and its Jacobian rows
/// from those of `n`, `a` and `m`.
fn stack(
    (n, a, m): (&Vector3<f64>, &Vector3<f64>, &Vector3<f64>),
    (jn, ja, jm): (&Jac, &Jac, &Jac),
) -> (SVector<f64, 12>, SMatrix<f64, 12, 12>) {
    let mut q = SVector::<f64, 12>::zeros();
    q.fixed_rows_mut::<3>(0).copy_from(&(-n));
    q.fixed_rows_mut::<3>(3).copy_from(&(a - m));
    q.fixed_rows_mut::<3>(6).copy_from(n);
    q.fixed_rows_mut::<3>(9).copy_from(&(a + m));
    let mut k = SMatrix::<f64, 12, 12>::zeros();
    k.fixed_rows_mut::<3>(0).copy_from(&(-jn));
    k.fixed_rows_mut::<3>(3).copy_from(&(ja - jm));
    k.fixed_rows_mut::<3>(6).copy_from(jn);
    k.fixed_rows_mut::<3>(9).copy_from(&(ja + jm));
    (q, k)
}

impl BeamElement<2> {
    /// The momentum scheme's element force `q_k(Nₙ₊½, Mₙ₊½)` with the
    /// geodesic mid rotation (equal to [`Self::midpoint_force`] with the
    /// averaged resultants) and its closed-form derivative under spatial
    /// increments of the end pose (module docs), ordered `(f₁, m₁, f₂, m₂)`.
    pub fn momentum_force_tangent(
        &self,
        start: &Pose<f64>,
        end: &Pose<f64>,
    ) -> (SVector<f64, 12>, SMatrix<f64, 12, 12>) {
        self.momentum_tangent_of(&self.frames(start), &self.frames(end))
    }

    /// The energy–momentum scheme's element force (the discrete gradient,
    /// [`Self::energy_momentum_force`]) with the cheap tangent: the momentum
    /// scheme's closed-form derivative ([`Self::momentum_force_tangent`]),
    /// which differs from the exact one by terms that vanish with the
    /// step's rotation increment. Both from one set of the poses' rotation
    /// pieces.
    pub fn energy_momentum_force_cheap_tangent(
        &self,
        start: &Pose<f64>,
        end: &Pose<f64>,
    ) -> (SVector<f64, 12>, SMatrix<f64, 12, 12>) {
        self.energy_momentum_force_cheap_tangent_from(&self.step_start(start), end)
    }

    /// [`Self::momentum_force_tangent`] from the poses' [`Frames`]: the chain
    /// rule of the module docs block by block. Only the increments' blocks
    /// `(η₁, ε₁, η₂, ε₂)` that a term depends on are formed — `δd` on the
    /// `η`, `w_r` and `δφ` on the `ε` — and the `η₁` blocks are the negated
    /// `η₂` ones.
    pub(crate) fn momentum_tangent_of(
        &self,
        s0: &Frames<f64>,
        s1: &Frames<f64>,
    ) -> (SVector<f64, 12>, SMatrix<f64, 12, 12>) {
        let l = self.length;
        let (n0, m0) = self.frame_resultants(s0);
        let (n1, m1) = self.frame_resultants(s1);
        let (nbar, mbar) = ((n0 + n1) * 0.5, (m0 + m1) * 0.5);
        let omega = log(&(s1.lam_r * s0.lam_r.transpose()));
        let lt = exp(&(omega * 0.5)) * s0.lam_r;
        let (n, m) = (lt * nbar, lt * mbar);
        let dbar = (s0.d + s1.d) * 0.5;
        let arm = -dbar.cross(&n) * 0.5;
        // S, P, G of the module docs; δd = η₂ − η₁, w_r = (I − P)ε₁ + Pε₂,
        // δφ = S(ε₂ − ε₁), w̃ = G w_r.
        let s = tangent_inverse(&s1.phi) * s1.lam[0].transpose();
        let p = s1.lam[0] * tangent(&(s1.phi * 0.5)) * s * 0.5;
        let g = tangent(&(omega * 0.5)) * tangent_inverse(&omega) * 0.5;
        // δN̄ = A (δd + d̂ w_r), δM̄ = D δφ; Λ̃ A on δd, Λ̃ A d̂ on w_r.
        let lta =
            lt * Matrix3::from_diagonal(&(self.section.c_n * (0.5 / l))) * s1.lam_r.transpose();
        let ltad = lta * s1.d.cross_matrix();
        let ltds = lt * Matrix3::from_diagonal(&(self.section.c_m * (0.5 / l))) * s;
        let (ng, mg) = (n.cross_matrix() * g, m.cross_matrix() * g);
        // The ε₂ blocks (through P and S); the ε₁ blocks through I − P and −S.
        let jn_e2 = (ltad - ng) * p;
        let jn_e1 = ltad - ng - jn_e2;
        let jm_e2 = ltds - mg * p;
        let jm_e1 = -mg - jm_e2;
        // δ(−½ d̄ × n) = ¼ n̂ δd − ½ d̄̂ δn.
        let half_dbar = dbar.cross_matrix() * 0.5;
        let ja_x2 = n.cross_matrix() * 0.25 - half_dbar * lta;
        let z = Matrix3::zeros();
        stack(
            (&n, &arm, &m),
            (
                &jac([-lta, jn_e1, lta, jn_e2]),
                &jac([-ja_x2, -half_dbar * jn_e1, ja_x2, -half_dbar * jn_e2]),
                &jac([z, jm_e1, z, jm_e2]),
            ),
        )
    }

    /// The energy–momentum scheme's element force (the discrete gradient
    /// [`Self::discrete_gradient_force`] with the averaged resultants) and its
    /// derivative under spatial increments of the end pose: AD over the six
    /// end spins, closed-form chord columns (module docs).
    pub fn energy_momentum_force_tangent(
        &self,
        start: &Pose<f64>,
        end: &Pose<f64>,
    ) -> (SVector<f64, 12>, SMatrix<f64, 12, 12>) {
        type D = DualSVec64<6>;
        let seed = |k: usize| D::from_re(0.0).derivative(k);
        let spin = |k: usize| Vector3::new(seed(k), seed(k + 1), seed(k + 2));
        let lift = |p: &Pose<f64>| -> Pose<D> {
            (
                p.0.map(|x| x.map(D::from_re)),
                p.1.map(|r| r.map(D::from_re)),
            )
        };
        let sd = lift(start);
        let mut ed = lift(end);
        ed.1 = [exp(&spin(0)) * ed.1[0], exp(&spin(3)) * ed.1[1]];
        let (n0, m0) = self.resultants(&start.0, &start.1);
        let (n1, m1) = self.resultants(&ed.0, &ed.1);
        let half = D::from_re(0.5);
        let nbar = (n0.map(D::from_re) + n1) * half;
        let mbar = (m0.map(D::from_re) + m1) * half;
        let qd = self.discrete_gradient_force(&sd, &ed, &nbar, &mbar);
        let mut q = SVector::<f64, 12>::zeros();
        let mut k = SMatrix::<f64, 12, 12>::zeros();
        for i in 0..12 {
            q[i] = qd[i].re;
            let row = qd[i].eps.unwrap_generic(Const::<6>, U1);
            for c in 0..3 {
                k[(i, 3 + c)] = row[c];
                k[(i, 9 + c)] = row[3 + c];
            }
        }
        let jd2 = self.discrete_gradient_chord_jacobian(start, end, &nbar.map(|v| v.re));
        k.fixed_view_mut::<12, 3>(0, 0).copy_from(&(-jd2));
        k.fixed_view_mut::<12, 3>(0, 6).copy_from(&jd2);
        (q, k)
    }

    /// `∂q/∂d₂` of the discrete gradient force with the averaged resultants
    /// `N̄` (module docs): the end chord enters `N̄` and `d̄` only.
    fn discrete_gradient_chord_jacobian(
        &self,
        start: &Pose<f64>,
        end: &Pose<f64>,
        nbar: &Vector3<f64>,
    ) -> SMatrix<f64, 12, 3> {
        let st = self.dg_step(start, end);
        let lam_r1 = self.frames(end).lam_r;
        let a = st.lam_bar
            * Matrix3::from_diagonal(&(self.section.c_n * (0.5 / self.length)))
            * lam_r1.transpose();
        let n = st.lam_bar * nbar;
        let c = -n.cross_matrix() * 0.5 + st.dbar.cross_matrix() * a;
        let bc = st.b.transpose() * c;
        let extra = st.direction * (st.b_miss.transpose() * c);
        let mut j = SMatrix::<f64, 12, 3>::zeros();
        j.fixed_rows_mut::<3>(0).copy_from(&(-a));
        j.fixed_rows_mut::<3>(3).copy_from(&(-c * 0.5 + bc + extra));
        j.fixed_rows_mut::<3>(6).copy_from(&a);
        j.fixed_rows_mut::<3>(9).copy_from(&(-c * 0.5 - bc - extra));
        j
    }
}

#[cfg(test)]
#[path = "conserving_tangent_tests.rs"]
mod tests;
