//! A straight beam's end coordinate as a parameter of the midpoint schemes'
//! sensitivities ([`super::midpoint_sensitivity`], [`crate::geometry`]).
//!
//! The scheme's element force `q(start, end)` sees the initial geometry
//! through the element length `L`, the triads `λ₀` and the initial strains.
//! Turning `λ₀` by `ω` is turning both ends' rotations by the spatial spins
//! `Rω` (the force sees `Λ = Rλ₀` only), one dual number through the force.
//! Stretching `L` to `σL` leaves the strain–displacement operators times
//! the weights unchanged (`B ∝ 1/L`, weights `∝ L`) and turns the strains
//! into `(Γ + Γ₀)/σ − Γ₀` and `K/σ`, so every scheme's force — affine in the
//! resultants, or a discrete gradient linear in an energy quadratic in the
//! strains — has
//!
//! ```text
//! ∂q/∂σ = q[Γ₀ → 2Γ₀] − 2 q,
//! ```
//!
//! the force of the element whose initial axial strain is doubled (built with
//! its initial nodes twice as far apart) less twice its own: exact, since
//! `q` is affine in the initial strain. The paper's energy residual (eq. 18)
//! likewise. Moved nodes' held translations follow `dX/dp` through the
//! scheme's tangent and the inertia `2M/Δt²`.

use flexmech_core::{BeamElement, Element};

use super::midpoint::MidpointTerms;
use super::midpoint_history::{element_seeded, element_value};
use super::midpoint_kernels::element_kernel;
use crate::joint_parameter::add_moved_stiffness;
use crate::start_shift::StartShift;
use crate::system::ReducedSystem;
use nalgebra::Vector3;

/// `∂g/∂p` of a geometry parameter at the converged step of `sys` (the
/// elements' force, the weight and line loads at the step's load time and
/// the held translations), added to `g`; returns the paper's energy residual's
/// `∂e/∂p` (zero for the other schemes).
pub(super) fn forces(
    sys: &ReducedSystem<'_, MidpointTerms>,
    (stretch, spin, loads): (&[(usize, f64)], &Vector3<f64>, &[usize]),
    held: &StartShift,
    g: &mut [f64],
) -> f64 {
    let (mech, terms) = (sys.mech, &sys.terms);
    let ends = (&sys.start.config, &sys.end.config);
    let scheme = (terms.scheme, terms.beta);
    crate::geometry::weight(mech, &sys.end.config, sys.load_time, stretch, g);
    let lines = (stretch, loads);
    crate::geometry::line_loads(mech, &sys.end.config, sys.load_time, lines, g);
    let from = |i: usize| (Vector3::zeros(), ends.0.rot[i] * spin);
    let to = |i: usize| (Vector3::zeros(), ends.1.rot[i] * spin);
    let mut energy = 0.0;
    for &(e, s) in stretch {
        let el = &mech.mesh.elements[e];
        let (q0, e0) = element_value(el, scheme, ends);
        let (q1, e1) = element_value(&doubled(el, &mech.mesh.positions), scheme, ends);
        let (qt, et) = element_seeded(el, scheme, ends, (&from, &to));
        for (k, &n) in el.nodes().iter().enumerate() {
            for c in 0..6 {
                let i = 6 * k + c;
                g[6 * n + c] += (q1[i] - 2.0 * q0[i]) * s + qt[i];
            }
        }
        energy += (e1 - 2.0 * e0) * s + et;
    }
    let tangent = |e: &Element, r: &mut [f64], k: &mut [f64]| {
        element_kernel(e, ends.0, ends.1, terms.scheme, terms.beta, true, r, k)
    };
    let inertia = Some((&terms.inertia, 2.0 / (terms.dt * terms.dt)));
    add_moved_stiffness(mech, tangent, inertia, held.shifts(), g);
    energy
}

/// The element with its initial axial strain doubled: its initial nodes
/// twice as far from its first, its length and triads as they are.
fn doubled(el: &Element, x0: &[Vector3<f64>]) -> Element {
    fn of<const N: usize>(e: &BeamElement<N>, x0: &[Vector3<f64>]) -> BeamElement<N> {
        let a = x0[e.nodes[0]];
        let x: [Vector3<f64>; N] = std::array::from_fn(|k| a + (x0[e.nodes[k]] - a) * 2.0);
        BeamElement::new(e.nodes, e.section, e.length, &x, e.lambda0)
    }
    match el {
        Element::Linear(e) => Element::Linear(of(e, x0)),
        Element::Quadratic(e) => Element::Quadratic(of(e, x0)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::Scheme;
    use flexmech_core::rotation::exp;
    use flexmech_core::{Configuration, Section};
    use nalgebra::Matrix3;

    /// A 2-node element of length `l` along x and a deformed step's ends.
    fn element(l: f64) -> (Element, Vec<Vector3<f64>>) {
        let x0 = vec![Vector3::zeros(), Vector3::new(l, 0.0, 0.0)];
        let section = Section::new(
            [2.0e4, 8.0e3, 9.0e3],
            [30.0, 45.0, 60.0],
            1.0,
            [0.2, 0.1, 0.1],
        );
        let e = BeamElement::new(
            [0, 1],
            section,
            l,
            &[x0[0], x0[1]],
            [Matrix3::identity(); 2],
        );
        (Element::Linear(e), x0)
    }

    fn ends() -> (Configuration, Configuration) {
        let config = |x: [Vector3<f64>; 2], r: [Vector3<f64>; 2]| Configuration {
            x: x.to_vec(),
            rot: r.iter().map(exp).collect(),
        };
        (
            config(
                [
                    Vector3::new(0.01, 0.0, 0.02),
                    Vector3::new(1.32, 0.05, -0.03),
                ],
                [
                    Vector3::new(0.1, -0.05, 0.02),
                    Vector3::new(-0.03, 0.2, 0.1),
                ],
            ),
            config(
                [
                    Vector3::new(0.02, 0.01, 0.03),
                    Vector3::new(1.29, 0.09, -0.01),
                ],
                [
                    Vector3::new(0.15, -0.02, 0.05),
                    Vector3::new(0.02, 0.25, 0.12),
                ],
            ),
        )
    }

    #[test]
    fn the_doubled_strain_gives_each_schemes_stretch_derivative() {
        // ∂q/∂σ and the paper's ∂e/∂σ by q[Γ₀ → 2Γ₀] − 2q against central
        // differences of the element re-built σ = 1 ± h times as long.
        let (start, end) = ends();
        let (l, h) = (1.3, 1e-6);
        for scheme in [
            Scheme::Momentum,
            Scheme::EnergyMomentum,
            Scheme::EnergyMomentumPaper,
        ] {
            let s = (scheme, 0.37);
            let (el, x0) = element(l);
            let (q0, e0) = element_value(&el, s, (&start, &end));
            let (q1, e1) = element_value(&doubled(&el, &x0), s, (&start, &end));
            let at = |f: f64| element_value(&element(l * f).0, s, (&start, &end));
            let ((qp, ep), (qm, em)) = (at(1.0 + h), at(1.0 - h));
            for i in 0..12 {
                let fd = (qp[i] - qm[i]) / (2.0 * h);
                let exact = q1[i] - 2.0 * q0[i];
                assert!(
                    (exact - fd).abs() <= 1e-6 * (1.0 + fd.abs()),
                    "{scheme:?} {i}: {exact} vs {fd}"
                );
            }
            let fd = (ep - em) / (2.0 * h);
            assert!(
                (e1 - 2.0 * e0 - fd).abs() <= 1e-6 * (1.0 + fd.abs()),
                "{scheme:?} e"
            );
        }
    }
}
