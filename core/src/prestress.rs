//! The prestress of linear buckling: the strains a small displacement field
//! produces, to first order, and elements that carry them as stress in their
//! initial configuration.
//!
//! Classical linear buckling (the issue's `K_material + λ K_geometric`)
//! needs the geometric stiffness of the stress state `σ₁ = C ε̇` of the
//! linear solution `u₁ = K₀⁻¹ f` taken *at the undeformed geometry*. The
//! element's tangent at its initial configuration is
//! `K(σ) = K_material + K_geometric(σ)`, affine in the stress; an element
//! whose stress-free strains are lowered by `ε̇` has exactly the stress `σ₁`
//! there, so its tangent minus the plain one is `K_geometric(σ₁)` with no
//! initial-displacement terms.

use crate::element::{BeamElement, Strains};
use crate::mesh::{gather, Element};
use nalgebra::{Matrix3, Vector3};
use num_dual::Dual64;

impl Element {
    /// The first-order change of the element's material strains at its Gauss
    /// points along the nodal increments `(dx, dθ)` (positions and spatial
    /// spins, every node of the mesh) from the configuration `(x, rot)`:
    /// `d/dε (Γ, K)(x + ε dx, exp(ε dθ̂) R)` at `ε = 0`, by dual numbers.
    pub fn strain_rates(
        &self,
        (x, rot): (&[Vector3<f64>], &[Matrix3<f64>]),
        (dx, dth): (&[Vector3<f64>], &[Vector3<f64>]),
    ) -> Vec<Strains<f64>> {
        match self {
            Element::Linear(e) => rates(e, (x, rot), (dx, dth)).to_vec(),
            Element::Quadratic(e) => rates(e, (x, rot), (dx, dth)).to_vec(),
        }
    }

    /// The element with its stress-free strains lowered by `delta` (see
    /// [`BeamElement::prestrained`]).
    pub fn prestrained(&self, delta: &[Strains<f64>]) -> Element {
        match self {
            Element::Linear(e) => Element::Linear(e.prestrained(delta)),
            Element::Quadratic(e) => Element::Quadratic(e.prestrained(delta)),
        }
    }
}

/// [`Element::strain_rates`] of an `N`-node element (`N − 1` Gauss points).
fn rates<const N: usize>(
    e: &BeamElement<N>,
    (x, rot): (&[Vector3<f64>], &[Matrix3<f64>]),
    (dx, dth): (&[Vector3<f64>], &[Vector3<f64>]),
) -> Vec<Strains<f64>> {
    let (xe, re) = gather(&e.nodes, x, rot);
    let (dxe, dre) = gather_vectors(&e.nodes, dx, dth);
    let eps = Dual64::from_re(0.0).derivative();
    let xd: [Vector3<Dual64>; N] =
        std::array::from_fn(|i| xe[i].map(Dual64::from_re) + dxe[i].map(|v| eps * v));
    let rd: [Matrix3<Dual64>; N] = std::array::from_fn(|i| {
        crate::rotation::exp(&dre[i].map(|v| eps * v)) * re[i].map(Dual64::from_re)
    });
    e.strains(&xd, &rd)
        .iter()
        .take(N - 1)
        .map(|(g, k)| (g.map(|v| v.eps), k.map(|v| v.eps)))
        .collect()
}

/// The increments of an element's nodes.
fn gather_vectors<const N: usize>(
    nodes: &[usize; N],
    dx: &[Vector3<f64>],
    dth: &[Vector3<f64>],
) -> ([Vector3<f64>; N], [Vector3<f64>; N]) {
    (
        std::array::from_fn(|i| dx.get(nodes[i]).copied().unwrap_or_default()),
        std::array::from_fn(|i| dth.get(nodes[i]).copied().unwrap_or_default()),
    )
}

#[cfg(test)]
mod tests {
    use crate::mesh::Mesh;
    use crate::section::Section;
    use nalgebra::{Matrix3, Vector3};

    /// A prestrained element's stress in its initial configuration equals the
    /// linearised stress of the displacement whose strain rates it carries,
    /// and an axial stretch `dx = ε x` gives the axial strain rate `ε`.
    #[test]
    fn prestrain_carries_the_linearised_stress() {
        let mut mesh = Mesh::default();
        let sec = Section::new([2e9, 8e8, 8e8], [1e6, 2e6, 3e6], 7.8, [0.1, 0.05, 0.05]);
        for nodes_per_element in [2, 3] {
            mesh.add_straight_beam(
                Vector3::zeros(),
                Vector3::new(2.0, 0.0, 0.0),
                Vector3::y(),
                2,
                nodes_per_element,
                sec,
            )
            .unwrap();
        }
        let n = mesh.node_count();
        let x = mesh.positions.clone();
        let rot = vec![Matrix3::identity(); n];
        let stretch = 1e-3;
        let dx: Vec<_> = x.iter().map(|p| p * stretch).collect();
        let dth = vec![Vector3::zeros(); n];
        for e in &mesh.elements {
            let rates = e.strain_rates((&x, &rot), (&dx, &dth));
            for (g, k) in &rates {
                assert!((g.x - stretch).abs() < 1e-15 && g.y.abs() < 1e-15 && k.norm() < 1e-15);
            }
            let pre = e.prestrained(&rates);
            for (_, n_res, m_res) in pre.stress_resultants(&x, &rot) {
                let ea = e.section().c_n.x;
                assert!((n_res.x - ea * stretch).abs() < 1e-9 * ea * stretch);
                assert!(m_res.norm() < 1e-9 * ea * stretch);
            }
        }
    }
}
