//! Inertia of a mesh (FORMULATION §2): translational mass, consistent
//! (`m_ij = ∫ρA Iᵢ Iⱼ ds`, exact Gauss rule) or lumped (row sums), and
//! rotational inertia lumped at the nodes (nodal quadrature of `J_ρ`).
//!
//! Lumping the rotational inertia keeps the conserving schemes exact node by
//! node; it converges to the same continuum. A node's inertia is expressed in
//! the global frame of the initial configuration, `J₀ = Σₑ wₑ Λ₀ₑ J_ρ Λ₀ₑᵀ`,
//! so that with the nodal rotation `R` (from the initial configuration) and
//! the body angular velocity `W` (`Ṙ = R Ŵ`): kinetic energy `½ W·J₀W`,
//! spatial angular momentum `π = R J₀ W`.

use crate::mesh::{Element, Mesh};
use nalgebra::{Matrix3, Vector3};

/// How translational mass is distributed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MassKind {
    /// `m_ij = ∫ρA Iᵢ Iⱼ ds`: exact for the interpolated velocity field.
    Consistent,
    /// Row sums of the consistent matrix on the diagonal.
    Lumped,
}

/// Nodal quadrature weights (fractions of the element length) of an element.
fn nodal_weights(n: usize) -> &'static [f64] {
    match n {
        2 => &[0.5, 0.5],
        _ => &[1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0],
    }
}

/// Consistent mass coefficients `∫ Iᵢ Iⱼ ds / L` of the 2- and 3-node elements.
fn consistent_fractions(n: usize) -> [[f64; 3]; 3] {
    match n {
        2 => [
            [1.0 / 3.0, 1.0 / 6.0, 0.0],
            [1.0 / 6.0, 1.0 / 3.0, 0.0],
            [0.0; 3],
        ],
        _ => [
            [4.0 / 30.0, 2.0 / 30.0, -1.0 / 30.0],
            [2.0 / 30.0, 16.0 / 30.0, 2.0 / 30.0],
            [-1.0 / 30.0, 2.0 / 30.0, 4.0 / 30.0],
        ],
    }
}

/// The inertia of a whole mesh.
#[derive(Debug, Clone, PartialEq)]
pub struct Inertia {
    /// Translational mass as node pairs `(i, j, m_ij)` (both orders stored
    /// for `i ≠ j`); multiply by the 3×3 identity.
    pub mass: Vec<(usize, usize, f64)>,
    /// Total translational mass of each node's row, `Σⱼ m_ij`.
    pub row_mass: Vec<f64>,
    /// Rotational inertia of each node, global frame of the initial configuration.
    pub rotational: Vec<Matrix3<f64>>,
}

impl Inertia {
    /// Assembles the inertia of `mesh`.
    pub fn new(mesh: &Mesh, kind: MassKind) -> Self {
        let n = mesh.node_count();
        let mut mass = Vec::new();
        let mut row_mass = vec![0.0; n];
        let mut rotational = vec![Matrix3::zeros(); n];
        for e in &mesh.elements {
            let nodes = e.nodes();
            let k = nodes.len();
            let s = e.section();
            let l = e.length();
            let frac = consistent_fractions(k);
            for a in 0..k {
                for b in 0..k {
                    let m = s.rho_a * l * frac[a][b];
                    match kind {
                        MassKind::Consistent => mass.push((nodes[a], nodes[b], m)),
                        MassKind::Lumped => mass.push((nodes[a], nodes[a], m)),
                    }
                    row_mass[nodes[a]] += m;
                }
            }
            let j_rho = Matrix3::from_diagonal(&s.rho_j);
            for (a, w) in nodal_weights(k).iter().enumerate() {
                let l0 = triad0(e, a);
                rotational[nodes[a]] += l0 * j_rho * l0.transpose() * (w * l);
            }
        }
        // Merge duplicate pairs so that products are cheap and deterministic.
        mass.sort_by_key(|&(i, j, _)| (i, j));
        let mut merged: Vec<(usize, usize, f64)> = Vec::with_capacity(mass.len());
        for (i, j, m) in mass {
            match merged.last_mut() {
                Some(last) if last.0 == i && last.1 == j => last.2 += m,
                _ => merged.push((i, j, m)),
            }
        }
        Self {
            mass: merged,
            row_mass,
            rotational,
        }
    }

    /// The derivative of the beams' inertia by a change of their initial
    /// geometry in which element `e` of `stretch` lengthens by `s_e L_e`
    /// (`dL/dp = s_e L_e`) and every listed element's initial triads turn by
    /// `spin` (`dλ₀/dp = ω̂ λ₀`): the translational masses `ρA L` scale with
    /// `s_e`, the rotational `λ₀ J_ρ λ₀ᵀ w L` gains
    /// `(ω̂ A − A ω̂) w L + A w L s_e` (`A = λ₀ J_ρ λ₀ᵀ`). Elements not listed
    /// contribute nothing.
    pub fn geometry_derivative(
        mesh: &Mesh,
        kind: MassKind,
        stretch: &[(usize, f64)],
        spin: &Vector3<f64>,
    ) -> Self {
        let n = mesh.node_count();
        let mut out = Self {
            mass: Vec::new(),
            row_mass: vec![0.0; n],
            rotational: vec![Matrix3::zeros(); n],
        };
        let omega = crate::rotation::skew(spin);
        for &(k, s) in stretch {
            let e = &mesh.elements[k];
            let (nodes, sec, l) = (e.nodes(), e.section(), e.length());
            let frac = consistent_fractions(nodes.len());
            for a in 0..nodes.len() {
                for b in 0..nodes.len() {
                    let m = sec.rho_a * l * s * frac[a][b];
                    let (i, j) = match kind {
                        MassKind::Consistent => (nodes[a], nodes[b]),
                        MassKind::Lumped => (nodes[a], nodes[a]),
                    };
                    out.add_pair(i, j, m);
                    out.row_mass[nodes[a]] += m;
                }
            }
            let j_rho = Matrix3::from_diagonal(&sec.rho_j);
            for (a, w) in nodal_weights(nodes.len()).iter().enumerate() {
                let l0 = triad0(e, a);
                let big_a = l0 * j_rho * l0.transpose();
                out.rotational[nodes[a]] += (omega * big_a - big_a * omega + big_a * s) * (w * l);
            }
        }
        out
    }

    /// Adds `m` to the pair `(i, j)` (kept sorted).
    fn add_pair(&mut self, i: usize, j: usize, m: f64) {
        match self.mass.binary_search_by_key(&(i, j), |&(a, b, _)| (a, b)) {
            Ok(k) => self.mass[k].2 += m,
            Err(k) => self.mass.insert(k, (i, j, m)),
        }
    }

    /// Adds a rigid body whose centre of mass is `node`: mass `m` on the
    /// node's translations and inertia `j` about its centre of mass (global
    /// axes of the initial configuration, where every node's frame is the
    /// identity) to its rotations — a point mass when `j = 0`.
    pub fn add_body(&mut self, node: usize, m: f64, j: &Matrix3<f64>) {
        match self
            .mass
            .binary_search_by_key(&(node, node), |&(a, b, _)| (a, b))
        {
            Ok(k) => self.mass[k].2 += m,
            Err(k) => self.mass.insert(k, (node, node, m)),
        }
        self.row_mass[node] += m;
        self.rotational[node] += j;
    }

    /// `Σⱼ m_ij vⱼ` for every node (the mass matrix applied to velocities).
    pub fn apply_mass(&self, v: &[Vector3<f64>]) -> Vec<Vector3<f64>> {
        let mut out = vec![Vector3::zeros(); v.len()];
        for &(i, j, m) in &self.mass {
            out[i] += v[j] * m;
        }
        out
    }

    /// Kinetic energy `½ Σ m_ij vᵢ·vⱼ + ½ Σ Wᵢ·J₀ᵢWᵢ`.
    pub fn kinetic_energy(&self, v: &[Vector3<f64>], w: &[Vector3<f64>]) -> f64 {
        let mv = self.apply_mass(v);
        let trans: f64 = v.iter().zip(&mv).map(|(a, b)| a.dot(b)).sum();
        let rot: f64 = w
            .iter()
            .zip(&self.rotational)
            .map(|(wi, j)| wi.dot(&(j * wi)))
            .sum();
        0.5 * (trans + rot)
    }

    /// Total linear momentum `Σ m_ij vⱼ`.
    pub fn linear_momentum(&self, v: &[Vector3<f64>]) -> Vector3<f64> {
        self.apply_mass(v).iter().sum()
    }

    /// Total angular momentum about the origin,
    /// `Σ m_ij xᵢ × vⱼ + Σ Rᵢ J₀ᵢ Wᵢ`.
    pub fn angular_momentum(
        &self,
        x: &[Vector3<f64>],
        rot: &[Matrix3<f64>],
        v: &[Vector3<f64>],
        w: &[Vector3<f64>],
    ) -> Vector3<f64> {
        let mv = self.apply_mass(v);
        let orbital: Vector3<f64> = x.iter().zip(&mv).map(|(xi, p)| xi.cross(p)).sum();
        let spin: Vector3<f64> = (0..x.len())
            .map(|i| rot[i] * (self.rotational[i] * w[i]))
            .sum();
        orbital + spin
    }

    /// Potential of gravity `g`: `−g·Σᵢ (Σⱼ m_ij) xᵢ = −∫ρA g·r ds`
    /// (exact for the interpolated positions, consistent or lumped).
    pub fn gravity_potential(&self, g: &Vector3<f64>, x: &[Vector3<f64>]) -> f64 {
        -x.iter()
            .zip(&self.row_mass)
            .map(|(xi, m)| g.dot(xi) * m)
            .sum::<f64>()
    }
}

/// The initial triad of an element at its local node `a`.
fn triad0(e: &Element, a: usize) -> Matrix3<f64> {
    match e {
        Element::Linear(b) => b.lambda0[a],
        Element::Quadratic(b) => b.lambda0[a],
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rotation::exp;
    use crate::section::Section;

    const RHO_A: f64 = 2.5;
    const L: f64 = 3.0;

    fn bar(kind: MassKind, elements: usize, npe: usize) -> (Mesh, Inertia) {
        let sec = Section::new([1.0; 3], [1.0; 3], RHO_A, [0.6, 0.2, 0.4]);
        let mut mesh = Mesh::default();
        // A bar along x centred at the origin.
        mesh.add_straight_beam(
            Vector3::new(-0.5 * L, 0.0, 0.0),
            Vector3::new(0.5 * L, 0.0, 0.0),
            Vector3::y(),
            elements,
            npe,
            sec,
        )
        .unwrap();
        let inertia = Inertia::new(&mesh, kind);
        (mesh, inertia)
    }

    #[test]
    fn total_mass_and_translation() {
        for kind in [MassKind::Consistent, MassKind::Lumped] {
            for npe in [2, 3] {
                let (mesh, i) = bar(kind, 5, npe);
                let v0 = Vector3::new(1.0, -2.0, 0.5);
                let v = vec![v0; mesh.node_count()];
                let w = vec![Vector3::zeros(); mesh.node_count()];
                let m = RHO_A * L;
                assert!((i.linear_momentum(&v) - v0 * m).norm() < 1e-12);
                assert!((i.kinetic_energy(&v, &w) - 0.5 * m * v0.norm_squared()).abs() < 1e-12);
                assert!((i.row_mass.iter().sum::<f64>() - m).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn rigid_spin_is_exact_with_consistent_mass() {
        // Spin ω about z through the centre: v = ω × x, W = ω (triads rotate
        // with the body). Kinetic energy of the bar, exact for linear velocity
        // fields with the consistent mass: ½ω²(ρA L³/12) + ½ ω·(ρI₃ L) ω.
        for npe in [2, 3] {
            let (mesh, i) = bar(MassKind::Consistent, 4, npe);
            let om = Vector3::new(0.0, 0.0, 1.7);
            let v: Vec<_> = mesh.positions.iter().map(|x| om.cross(x)).collect();
            let w = vec![om; mesh.node_count()];
            let exact = 0.5 * om.z * om.z * (RHO_A * L.powi(3) / 12.0 + 0.4 * L);
            assert!(
                (i.kinetic_energy(&v, &w) - exact).abs() < 1e-12 * exact,
                "npe {npe}"
            );
            let rot = vec![Matrix3::identity(); mesh.node_count()];
            let h = i.angular_momentum(&mesh.positions, &rot, &v, &w);
            assert!((h - om * (RHO_A * L.powi(3) / 12.0 + 0.4 * L)).norm() < 1e-12);
        }
        // Lumped mass converges to it with refinement (error ∝ 1/n²).
        let om = Vector3::new(0.0, 0.0, 1.0);
        let err = |n: usize| {
            let (mesh, i) = bar(MassKind::Lumped, n, 2);
            let v: Vec<_> = mesh.positions.iter().map(|x| om.cross(x)).collect();
            let w = vec![om; mesh.node_count()];
            (i.kinetic_energy(&v, &w) - 0.5 * (RHO_A * L.powi(3) / 12.0 + 0.4 * L)).abs()
        };
        let (e4, e8) = (err(4), err(8));
        assert!(e4 > 0.0 && (e4 / e8 - 4.0).abs() < 0.1, "{e4} {e8}");
    }

    #[test]
    fn rotated_triads_carry_their_inertia() {
        // A rotated configuration: π = R J₀ W and ½W·J₀W do not depend on where
        // the body is, only on its body angular velocity.
        let (mesh, i) = bar(MassKind::Consistent, 2, 2);
        let n = mesh.node_count();
        let r = exp(&Vector3::new(0.3, -1.1, 0.7));
        let w = vec![Vector3::new(0.2, 0.5, -0.3); n];
        let v = vec![Vector3::zeros(); n];
        let x: Vec<_> = mesh.positions.iter().map(|p| r * p).collect();
        let rot = vec![r; n];
        let h = i.angular_momentum(&x, &rot, &v, &w);
        let h0 = i.angular_momentum(&mesh.positions, &vec![Matrix3::identity(); n], &v, &w);
        assert!((h - r * h0).norm() < 1e-14);
        // Rotational inertia of the bar, ρJ·L about its axes (x axis: ρ(I₂+I₃)).
        let total: Matrix3<f64> = i.rotational.iter().sum();
        assert!((total - Matrix3::from_diagonal(&Vector3::new(0.6, 0.2, 0.4)) * L).norm() < 1e-14);
    }

    #[test]
    fn gravity_potential_is_the_integral() {
        for kind in [MassKind::Consistent, MassKind::Lumped] {
            let (mesh, i) = bar(kind, 3, 3);
            let g = Vector3::new(0.0, 0.0, -9.81);
            // Lift the bar by 2: potential drops by −m g·Δz.
            let x: Vec<_> = mesh
                .positions
                .iter()
                .map(|p| p + Vector3::new(0.0, 0.0, 2.0))
                .collect();
            let dv = i.gravity_potential(&g, &x) - i.gravity_potential(&g, &mesh.positions);
            assert!((dv - RHO_A * L * 9.81 * 2.0).abs() < 1e-12);
        }
    }
}
