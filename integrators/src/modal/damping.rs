//! Structural (Kelvin–Voigt) damping of vibration modes.
//!
//! The damped elements' resultants `C(ε + η ε̇)` add `D q̇` to the
//! linearised equations, `NᵀMN δq̈ + D δq̇ + K δq = 0`, with the damping
//! matrix `D = Σₑ ηₑ Bₑᵀ Cₑ Bₑ`: each element's material stiffness times
//! its damping time — the Hessian of the step's damping pseudo-potential
//! (FORMULATION §4.7) at a zero strain change, `c = η`. Projected on the
//! undamped modes `φₖ` (unit mass norm), `cᵢⱼ = φᵢᵀ D φⱼ`, each mode's
//! damping ratio is `ζₖ = cₖₖ / (2ωₖ)`. Where `D` is a combination of `K`
//! and `M` — one `η` for every element of an unstressed structure,
//! `D = ηK` — the undamped modes are the damped ones (classical normal
//! modes, `cᵢⱼ = 0` for `i ≠ j`) and `ζₖ = ηωₖ/2` exactly; otherwise the
//! projection neglects the coupling between modes, whose size
//! `maxᵢ≠ⱼ |cᵢⱼ|/√(cᵢᵢcⱼⱼ)` is reported with the ratios.

use super::ModeSet;
use crate::constraints::MechanismState;
use crate::mechanism::Mechanism;

/// The damping of a set of vibration modes.
#[derive(Debug, Clone, PartialEq)]
pub struct ModalDamping {
    /// Per mode, `ζₖ = φₖᵀDφₖ / (2ωₖ)` (0 for a rigid mode).
    pub ratio: Vec<f64>,
    /// `maxᵢ≠ⱼ |φᵢᵀDφⱼ| / √(φᵢᵀDφᵢ · φⱼᵀDφⱼ)` over the elastic modes: 0 for
    /// classical normal modes, where the ratios are exact.
    pub coupling: f64,
}

/// The damping of the vibration modes `set` of `mech` about `state`, or
/// `None` when no element is damped.
pub(super) fn modal_damping(
    mech: &Mechanism,
    state: &MechanismState,
    set: &ModeSet,
) -> Option<ModalDamping> {
    let damped = mech.damped_elements();
    if damped.is_empty() {
        return None;
    }
    let count = set.eigenvalues.len();
    let c = projected(mech, state, set, &damped);
    let ratio = (0..count)
        .map(|k| {
            let w2 = set.eigenvalues[k];
            if w2 > 0.0 {
                c[k * count + k] / (2.0 * w2.sqrt())
            } else {
                0.0
            }
        })
        .collect();
    let elastic: Vec<usize> = (0..count).filter(|&k| set.eigenvalues[k] > 0.0).collect();
    let mut coupling = 0.0f64;
    for &i in &elastic {
        for &j in elastic.iter().filter(|&&j| j != i) {
            let scale = (c[i * count + i] * c[j * count + j]).abs().sqrt();
            if scale > 0.0 {
                coupling = coupling.max(c[i * count + j].abs() / scale);
            }
        }
    }
    Some(ModalDamping { ratio, coupling })
}

/// `cᵢⱼ = φᵢᵀ D φⱼ` (row-major, modes × modes), element by element.
fn projected(
    mech: &Mechanism,
    state: &MechanismState,
    set: &ModeSet,
    damped: &[(usize, f64)],
) -> Vec<f64> {
    let count = set.eigenvalues.len();
    let config = (&state.config.x[..], &state.config.rot[..]);
    let mut c = vec![0.0; count * count];
    for &(e, eta) in damped {
        let element = &mech.mesh.elements[e];
        let nodes = element.nodes();
        let n = 6 * nodes.len();
        let (mut r, mut k) = (vec![0.0; n], vec![0.0; n * n]);
        element.damping_residual_tangent(config, config, eta, &mut r, &mut k);
        // Each mode's element vector (u, θ per node) and D_e times it.
        let v: Vec<Vec<f64>> = (0..count)
            .map(|m| {
                nodes
                    .iter()
                    .flat_map(|&a| {
                        let (u, t) = (set.displacement[m][a], set.rotation[m][a]);
                        [u.x, u.y, u.z, t.x, t.y, t.z]
                    })
                    .collect()
            })
            .collect();
        let dv: Vec<Vec<f64>> = v
            .iter()
            .map(|x| {
                (0..n)
                    .map(|row| (0..n).map(|col| k[col * n + row] * x[col]).sum())
                    .collect()
            })
            .collect();
        for i in 0..count {
            for j in 0..count {
                c[i * count + j] += v[i].iter().zip(&dv[j]).map(|(a, b)| a * b).sum::<f64>();
            }
        }
    }
    c
}
