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
/// elements' force, the weight at the step's load time and the held
/// translations), added to `g`; returns the paper's energy residual's
/// `∂e/∂p` (zero for the other schemes).
pub(super) fn forces(
    sys: &ReducedSystem<'_, MidpointTerms>,
    (stretch, spin): (&[(usize, f64)], &Vector3<f64>),
    held: &StartShift,
    g: &mut [f64],
) -> f64 {
    let (mech, terms) = (sys.mech, &sys.terms);
    let ends = (&sys.start.config, &sys.end.config);
    let scheme = (terms.scheme, terms.beta);
    crate::geometry::weight(mech, &sys.end.config, sys.load_time, stretch, g);
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
