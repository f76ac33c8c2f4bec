//! Meshes of beams: nodes (initial positions) and elements (initial geometry).
//! Straight beams and circular arcs are meshed into equal elements; node
//! numbering is global and contiguous per beam.

use crate::element::{BeamElement, Strains};
use crate::rotation::{exp, log};
use crate::section::Section;
use crate::Scalar;
use nalgebra::{Matrix3, SMatrixViewMut, SVectorViewMut, Vector3};
use thiserror::Error;

/// Degenerate beam geometry (the model loader reports these with file context;
/// the mesh still refuses them so that no library path can panic).
#[derive(Debug, Clone, PartialEq, Error)]
pub enum MeshError {
    /// Start and end coincide.
    #[error("beam has zero length")]
    ZeroLength,
    /// The section's `e2` has no component normal to the beam axis.
    #[error("the section axis e2 is parallel to the beam axis")]
    ParallelE2,
    /// An arc of zero radius.
    #[error("arc radius is zero")]
    ZeroRadius,
    /// An arc normal that is zero or not normal to the radius.
    #[error("arc normal must be non-zero and perpendicular to start − center")]
    BadNormal,
    /// No elements, or elements of other than 2 or 3 nodes.
    #[error("a beam needs at least one element with 2 or 3 nodes, got {elements} elements of {nodes_per_element} nodes")]
    BadElementCount {
        /// Elements asked for.
        elements: usize,
        /// Nodes per element asked for.
        nodes_per_element: usize,
    },
}

/// A beam element of either order.
#[derive(Debug, Clone, PartialEq)]
pub enum Element {
    /// 2-node element, closed-form residual.
    Linear(BeamElement<2>),
    /// 3-node element, AD residual and tangent.
    Quadratic(BeamElement<3>),
}

impl Element {
    /// Global node numbers.
    pub fn nodes(&self) -> &[usize] {
        match self {
            Element::Linear(e) => &e.nodes,
            Element::Quadratic(e) => &e.nodes,
        }
    }

    /// The initial triads `Λ₀ᵢ` at the element's nodes (columns: the
    /// directors `e₁` along the beam, `e₂`, `e₃` of the section).
    pub fn initial_triads(&self) -> &[Matrix3<f64>] {
        match self {
            Element::Linear(e) => &e.lambda0,
            Element::Quadratic(e) => &e.lambda0,
        }
    }

    /// Number of element unknowns `6N`.
    pub fn dofs(&self) -> usize {
        6 * self.nodes().len()
    }

    /// The element's section.
    pub fn section(&self) -> &Section {
        match self {
            Element::Linear(e) => &e.section,
            Element::Quadratic(e) => &e.section,
        }
    }

    /// Initial length.
    pub fn length(&self) -> f64 {
        match self {
            Element::Linear(e) => e.length,
            Element::Quadratic(e) => e.length,
        }
    }

    /// Scale of the rounding errors of the element's internal forces when its
    /// nodes lie within `radius` of the origin: the chord `x₂ − x₁` is rounded
    /// to `eps·radius`, so the axial and shear strains carry `eps·radius/L`
    /// (times `C_N`), and the curvature `eps/L` (times `C_M`). Multiplied by
    /// `eps`, this bounds how small the element's residual can be computed.
    pub fn force_scale(&self, radius: f64) -> f64 {
        let s = self.section();
        let l = self.length();
        s.c_n.max() * (1.0 + radius / l) + s.c_m.max() / l
    }

    /// The material stress resultants `(N, M) = (C_N Γ, C_M K)` (FORMULATION
    /// §2) at the element's Gauss points in a global configuration (`x`,
    /// `rot`: every node's position and rotation from the initial
    /// configuration), each with the point's place along the element as a
    /// fraction of its length: one point (the middle) for 2-node elements,
    /// two (`½ ∓ ½/√3`) for 3-node ones.
    pub fn stress_resultants(
        &self,
        x: &[Vector3<f64>],
        rot: &[Matrix3<f64>],
    ) -> Vec<(f64, Vector3<f64>, Vector3<f64>)> {
        let stresses: Vec<_> = match self {
            Element::Linear(e) => {
                let (xe, re) = gather(&e.nodes, x, rot);
                e.stresses(&xe, &re).into_iter().take(1).collect()
            }
            Element::Quadratic(e) => {
                let (xe, re) = gather(&e.nodes, x, rot);
                e.stresses(&xe, &re).to_vec()
            }
        };
        self.gauss_places()
            .into_iter()
            .zip(stresses)
            .map(|(u, (n, m))| (u, n, m))
            .collect()
    }

    /// The element's Gauss points as fractions of its length (`½(1 + ξ)`).
    pub fn gauss_places(&self) -> Vec<f64> {
        crate::shape::reduced_gauss(self.nodes().len())
            .iter()
            .map(|&(xi, _)| 0.5 * (1.0 + xi))
            .collect()
    }

    /// Strain energy in a global configuration.
    pub fn energy(&self, x: &[Vector3<f64>], rot: &[Matrix3<f64>]) -> f64 {
        match self {
            Element::Linear(e) => {
                let (xe, re) = gather(&e.nodes, x, rot);
                e.energy(&xe, &re)
            }
            Element::Quadratic(e) => {
                let (xe, re) = gather(&e.nodes, x, rot);
                e.energy(&xe, &re)
            }
        }
    }

    /// Strain energy in a global configuration as the step records give it:
    /// [`Element::energy`], for a 2-node element by its invariant
    /// coordinates ([`BeamElement::energy_linear`], equal to round-off).
    pub fn recorded_energy(&self, x: &[Vector3<f64>], rot: &[Matrix3<f64>]) -> f64 {
        match self {
            Element::Linear(e) => {
                let (xe, re) = gather(&e.nodes, x, rot);
                e.energy_linear(&xe, &re)
            }
            Element::Quadratic(_) => self.energy(x, rot),
        }
    }

    /// [`Element::recorded_energy`] given the element's
    /// [`Element::relative_rotations`] in the same configuration (as the
    /// solvers' rotation guard has them after a step): the same value to the
    /// bit, without computing a 2-node element's relative rotation again.
    pub fn recorded_energy_with(
        &self,
        relative: &RelativeRotations,
        x: &[Vector3<f64>],
        rot: &[Matrix3<f64>],
    ) -> f64 {
        match self {
            Element::Linear(e) => {
                let (mut xe, mut re) = ([Vector3::zeros(); 2], [Matrix3::zeros(); 2]);
                gather_into(&e.nodes, x, rot, &mut xe, &mut re);
                e.energy_linear_with(&relative.values[0], &xe, &re)
            }
            Element::Quadratic(_) => self.energy(x, rot),
        }
    }

    /// The rotation vectors between the element's nodal triads that its
    /// interpolation takes principal logarithms of: `log(Λ₁ᵀΛ₂)` (2-node), or
    /// `log(Λ_rᵀΛᵢ)` of the end nodes relative to the middle one (3-node). A
    /// logarithm is principal (`|·| ≤ π`): past π it wraps silently, so the
    /// solvers watch these ([`Element::ROTATION_LIMIT`]).
    pub fn relative_rotations(&self, rot: &[Matrix3<f64>]) -> RelativeRotations {
        match self {
            Element::Linear(e) => {
                let mut r = [Matrix3::zeros(); 2];
                gather_rotations_into(&e.nodes, rot, &mut r);
                let l = e.nodal_triads(&r);
                RelativeRotations {
                    values: [log(&(l[0].transpose() * l[1])), Vector3::zeros()],
                    len: 1,
                }
            }
            Element::Quadratic(e) => {
                let r = gather(&e.nodes, &[], rot).1;
                let l = e.nodal_triads(&r);
                RelativeRotations {
                    values: [
                        log(&(l[1].transpose() * l[0])),
                        log(&(l[1].transpose() * l[2])),
                    ],
                    len: 2,
                }
            }
        }
    }

    /// The largest rotation between an element's nodes that a solution may
    /// reach (3π/4): well short of the logarithm's branch cut at π, so a
    /// step that would cross it is caught before it can wrap.
    pub const ROTATION_LIMIT: f64 = 0.75 * std::f64::consts::PI;

    /// The largest change of those rotations in one step (π/2): a wrap
    /// turns the vector by almost 2π, far beyond it.
    pub const ROTATION_STEP_LIMIT: f64 = 0.5 * std::f64::consts::PI;

    /// Internal force only (`6N`), written into `r`: the closed form for
    /// 2-node elements, the forward-AD energy gradient for 3-node ones —
    /// what a converged-residual check needs, at a small fraction of
    /// [`Element::residual_tangent`]'s cost.
    pub fn internal_force_into(&self, x: &[Vector3<f64>], rot: &[Matrix3<f64>], r: &mut [f64]) {
        match self {
            Element::Linear(e) => {
                let (xe, re) = gather(&e.nodes, x, rot);
                r.copy_from_slice(e.internal_force(&xe, &re).as_slice());
            }
            Element::Quadratic(e) => {
                let (xe, re) = gather(&e.nodes, x, rot);
                r.copy_from_slice(e.internal_force_quadratic(&xe, &re).as_slice());
            }
        }
    }

    /// Kelvin–Voigt damping over a step from `start` to `end` (global
    /// configurations) with `c = η/Δt`: the damping force (`6N`) into `r`,
    /// its tangent under the end configuration's increments (`6N × 6N`,
    /// column-major) into `k`; returns the energy dissipated over the step,
    /// `2ψ` (see [`BeamElement::damping_potential`]).
    pub fn damping_residual_tangent(
        &self,
        start: (&[Vector3<f64>], &[Matrix3<f64>]),
        end: (&[Vector3<f64>], &[Matrix3<f64>]),
        c: f64,
        r: &mut [f64],
        k: &mut [f64],
    ) -> f64 {
        // ψ is c times the strain energy of the element whose stress-free
        // strains are the step start's (its strains are then the change
        // Δε): the damping force and tangent are c times that element's
        // internal force and tangent, in closed form (the hyper-dual
        // Hessian of ψ is their oracle in the tests).
        let strains0 = self.strains_at(start);
        let psi = match self {
            Element::Linear(e) => damping_value(e, &strains0, end, c),
            Element::Quadratic(e) => damping_value(e, &strains0, end, c),
        };
        self.step_element(&strains0)
            .residual_tangent(end.0, end.1, r, k);
        r.iter_mut().chain(k.iter_mut()).for_each(|v| *v *= c);
        2.0 * psi
    }

    /// The Kelvin–Voigt damping force alone (`6N`, into `r`) over a step from
    /// `start` to `end` with `c = η/Δt`: the force of
    /// [`Self::damping_residual_tangent`] without its tangent.
    pub fn damping_force(
        &self,
        start: (&[Vector3<f64>], &[Matrix3<f64>]),
        end: (&[Vector3<f64>], &[Matrix3<f64>]),
        c: f64,
        r: &mut [f64],
    ) {
        self.step_element(&self.strains_at(start))
            .internal_force_into(end.0, end.1, r);
        r.iter_mut().for_each(|v| *v *= c);
    }

    /// The element's strains at its Gauss points in the configuration `at`.
    fn strains_at(&self, at: (&[Vector3<f64>], &[Matrix3<f64>])) -> [Strains<f64>; 2] {
        match self {
            Element::Linear(e) => {
                let (x, rot) = gather(&e.nodes, at.0, at.1);
                e.strains(&x, &rot)
            }
            Element::Quadratic(e) => {
                let (x, rot) = gather(&e.nodes, at.0, at.1);
                e.strains(&x, &rot)
            }
        }
    }

    /// The element whose stress-free strains are `strains0` (a step
    /// start's): its strains are the change since then, and `c` times its
    /// force and tangent are the damping's.
    fn step_element(&self, strains0: &[Strains<f64>]) -> Element {
        let lowered: Vec<Strains<f64>> = strains0.iter().map(|s| (-s.0, -s.1)).collect();
        self.prestrained(&lowered)
    }

    /// `∂Π/∂σ` and its gradient `∂f/∂σ` (`6N`) for the element's length
    /// stretched to `σL` ([`BeamElement::stretch_rate`]; straight elements).
    pub fn stretch_force(&self, x: &[Vector3<f64>], rot: &[Matrix3<f64>]) -> (f64, Vec<f64>) {
        match self {
            Element::Linear(e) => {
                let (xe, re) = gather(&e.nodes, x, rot);
                let (g, _) = e.gradient_hessian_ad::<12>(&xe, &re, |x, q| e.stretch_rate(x, q));
                (e.stretch_rate(&xe, &re), g.as_slice().to_vec())
            }
            Element::Quadratic(e) => {
                let (xe, re) = gather(&e.nodes, x, rot);
                let (g, _) = e.gradient_hessian_ad::<18>(&xe, &re, |x, q| e.stretch_rate(x, q));
                (e.stretch_rate(&xe, &re), g.as_slice().to_vec())
            }
        }
    }

    /// Residual (internal force, `6N`) and tangent (`6N × 6N`, column-major)
    /// in a global configuration, written into `r` and `k`.
    pub fn residual_tangent(
        &self,
        x: &[Vector3<f64>],
        rot: &[Matrix3<f64>],
        r: &mut [f64],
        k: &mut [f64],
    ) {
        match self {
            Element::Linear(e) => {
                let (mut xe, mut re) = ([Vector3::zeros(); 2], [Matrix3::zeros(); 2]);
                gather_into(&e.nodes, x, rot, &mut xe, &mut re);
                let rv = SVectorViewMut::<f64, 12>::from_slice(r);
                e.residual_tangent_linear_into(&xe, &re, rv, SMatrixViewMut::from_slice(k));
            }
            Element::Quadratic(e) => {
                let (xe, re) = gather(&e.nodes, x, rot);
                let (rv, km) = e.residual_tangent_quadratic(&xe, &re);
                r.copy_from_slice(rv.as_slice());
                k.copy_from_slice(km.as_slice());
            }
        }
    }
}

/// The damping pseudo-potential `ψ` of an `N`-node element over a step from
/// the strains `strains0` to the configuration `end` (see
/// [`BeamElement::damping_potential`]).
fn damping_value<const N: usize>(
    e: &BeamElement<N>,
    strains0: &[Strains<f64>; 2],
    end: (&[Vector3<f64>], &[Matrix3<f64>]),
    c: f64,
) -> f64 {
    let (xe, re) = gather(&e.nodes, end.0, end.1);
    e.damping_potential(&xe, &re, strains0, c)
}

/// [`Element::damping_residual_tangent`]'s force and tangent by the
/// hyper-dual gradient and Hessian of the damping
/// pseudo-potential `ψ` (the oracle of the closed form).
#[cfg(test)]
fn damping_of_ad<const N: usize>(
    e: &BeamElement<N>,
    start: (&[Vector3<f64>], &[Matrix3<f64>]),
    end: (&[Vector3<f64>], &[Matrix3<f64>]),
    c: f64,
    r: &mut [f64],
    k: &mut [f64],
) {
    let (xs, rs) = gather(&e.nodes, start.0, start.1);
    let strains0 = e.strains(&xs, &rs);
    let (xe, re) = gather(&e.nodes, end.0, end.1);
    if N == 2 {
        let (g, h) =
            e.gradient_hessian_ad::<12>(&xe, &re, |x, q| e.damping_potential(x, q, &strains0, c));
        r.copy_from_slice(g.as_slice());
        k.copy_from_slice(h.as_slice());
    } else {
        let (g, h) =
            e.gradient_hessian_ad::<18>(&xe, &re, |x, q| e.damping_potential(x, q, &strains0, c));
        r.copy_from_slice(g.as_slice());
        k.copy_from_slice(h.as_slice());
    }
}

#[inline(always)]
pub(crate) fn gather<const N: usize>(
    nodes: &[usize; N],
    x: &[Vector3<f64>],
    rot: &[Matrix3<f64>],
) -> ([Vector3<f64>; N], [Matrix3<f64>; N]) {
    let mut out = ([Vector3::zeros(); N], [Matrix3::zeros(); N]);
    gather_into(nodes, x, rot, &mut out.0, &mut out.1);
    out
}

/// [`gather`] into arrays the caller holds. The element loops that run on
/// every evaluation take this one: two 3 × 3 rotations are 144 bytes, and an
/// array of them returned by value was moved with a call to `memcpy`.
#[inline(always)]
pub(crate) fn gather_into<const N: usize>(
    nodes: &[usize; N],
    x: &[Vector3<f64>],
    rot: &[Matrix3<f64>],
    xs: &mut [Vector3<f64>; N],
    rs: &mut [Matrix3<f64>; N],
) {
    for (xi, &n) in xs.iter_mut().zip(nodes) {
        *xi = x.get(n).copied().unwrap_or_default();
    }
    gather_rotations_into(nodes, rot, rs);
}

/// The element's nodal rotations alone ([`gather_into`] without positions).
#[inline(always)]
pub(crate) fn gather_rotations_into<const N: usize>(
    nodes: &[usize; N],
    rot: &[Matrix3<f64>],
    rs: &mut [Matrix3<f64>; N],
) {
    for (r, &n) in rs.iter_mut().zip(nodes) {
        *r = rot[n];
    }
}

/// An element's relative rotations ([`Element::relative_rotations`]): one
/// for a 2-node element, two for a 3-node one, as a slice (no allocation:
/// the solvers check them after every step).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RelativeRotations {
    values: [Vector3<f64>; 2],
    len: usize,
}

impl RelativeRotations {
    /// A 2-node element's relative rotation.
    pub(crate) fn one(phi: Vector3<f64>) -> Self {
        Self {
            values: [phi, Vector3::zeros()],
            len: 1,
        }
    }
}

impl std::ops::Deref for RelativeRotations {
    type Target = [Vector3<f64>];

    fn deref(&self) -> &[Vector3<f64>] {
        &self.values[..self.len]
    }
}

/// Nodes and elements of a mechanism's beams.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Mesh {
    /// Initial position of every node.
    pub positions: Vec<Vector3<f64>>,
    /// All elements.
    pub elements: Vec<Element>,
}

/// Orthonormal triad with first column `t1` (unit) and second column the part
/// of `e2` orthogonal to it.
fn triad(t1: &Vector3<f64>, e2: &Vector3<f64>) -> Result<Matrix3<f64>, MeshError> {
    let t2 = e2 - t1 * e2.dot(t1);
    if t2.norm() <= 1e-8 * e2.norm() || e2.norm() == 0.0 {
        return Err(MeshError::ParallelE2);
    }
    Ok(straight_triad(t1, e2))
}

/// The initial triad of a straight beam along the unit `t1` with the
/// section axis `e2` (not parallel to `t1`): `[t1, t2, t1 × t2]`, `t2` the
/// normalised part of `e2` orthogonal to `t1`. For any scalar (the triad's
/// derivative by the beam's end coordinates).
pub fn straight_triad<T: Scalar>(t1: &Vector3<T>, e2: &Vector3<T>) -> Matrix3<T> {
    let t2 = e2 - t1 * e2.dot(t1);
    let t2 = t2 / t2.norm();
    Matrix3::from_columns(&[*t1, t2, t1.cross(&t2)])
}

impl Mesh {
    /// Number of nodes.
    pub fn node_count(&self) -> usize {
        self.positions.len()
    }

    /// A node of no element at `x` (a point of the ground a joint hangs
    /// from); returns its number.
    pub fn add_node(&mut self, x: Vector3<f64>) -> usize {
        self.positions.push(x);
        self.positions.len() - 1
    }

    /// Meshes a beam given node positions and triads along its length
    /// (`count` nodes, parameter `u ∈ [0, 1]`), returning its node numbers.
    fn add_beam(
        &mut self,
        elements: usize,
        npe: usize,
        section: Section,
        length: f64,
        frame: impl Fn(f64) -> Result<(Vector3<f64>, Matrix3<f64>), MeshError>,
    ) -> Result<Vec<usize>, MeshError> {
        if elements == 0 || !(2..=3).contains(&npe) {
            return Err(MeshError::BadElementCount {
                elements,
                nodes_per_element: npe,
            });
        }
        let count = elements * (npe - 1) + 1;
        let first = self.positions.len();
        let mut triads = Vec::with_capacity(count);
        for k in 0..count {
            let (x, t) = frame(k as f64 / (count - 1) as f64)?;
            self.positions.push(x);
            triads.push(t);
        }
        let le = length / elements as f64;
        for e in 0..elements {
            let base = e * (npe - 1);
            if npe == 2 {
                let nodes = [first + base, first + base + 1];
                let x0 = nodes.map(|n| self.positions[n]);
                let l0 = [triads[base], triads[base + 1]];
                self.elements.push(Element::Linear(BeamElement::new(
                    nodes, section, le, &x0, l0,
                )));
            } else {
                let nodes = [first + base, first + base + 1, first + base + 2];
                let x0 = nodes.map(|n| self.positions[n]);
                let l0 = [triads[base], triads[base + 1], triads[base + 2]];
                self.elements.push(Element::Quadratic(BeamElement::new(
                    nodes, section, le, &x0, l0,
                )));
            }
        }
        Ok((first..first + count).collect())
    }

    /// A straight beam from `start` to `end` with section axis `e2`.
    pub fn add_straight_beam(
        &mut self,
        start: Vector3<f64>,
        end: Vector3<f64>,
        e2: Vector3<f64>,
        elements: usize,
        nodes_per_element: usize,
        section: Section,
    ) -> Result<Vec<usize>, MeshError> {
        let d = end - start;
        let length = d.norm();
        if length == 0.0 || !length.is_finite() {
            return Err(MeshError::ZeroLength);
        }
        let t = triad(&(d / length), &e2)?;
        self.add_beam(elements, nodes_per_element, section, length, |u| {
            Ok((start + d * u, t))
        })
    }

    /// A circular arc starting at `start`, turning about the unit `normal`
    /// through `sweep` radians around `center`. The tangent at the start is
    /// `sign(sweep)·normal × (start − center)/radius`; the section axis `e2` is
    /// the given one carried along the arc, or the direction to the center.
    #[allow(clippy::too_many_arguments)]
    pub fn add_arc_beam(
        &mut self,
        start: Vector3<f64>,
        center: Vector3<f64>,
        normal: Vector3<f64>,
        sweep: f64,
        e2: Option<Vector3<f64>>,
        elements: usize,
        nodes_per_element: usize,
        section: Section,
    ) -> Result<Vec<usize>, MeshError> {
        let radial = start - center;
        let radius = radial.norm();
        if radius == 0.0 || !radius.is_finite() {
            return Err(MeshError::ZeroRadius);
        }
        if normal.norm() == 0.0
            || normal.normalize().dot(&(radial / radius)).abs() > 1e-8
            || sweep == 0.0
        {
            return Err(MeshError::BadNormal);
        }
        let n = normal.normalize();
        let sign = sweep.signum();
        let length = radius * sweep.abs();
        self.add_beam(elements, nodes_per_element, section, length, |u| {
            let q = exp(&(n * (sweep * u)));
            let r = q * radial;
            let t1 = n.cross(&r).normalize() * sign;
            let e2u = match e2 {
                Some(v) => q * v,
                None => -r / radius,
            };
            Ok((center + r, triad(&t1, &e2u)?))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sec() -> Section {
        Section::new([1.0, 1.0, 1.0], [1.0, 1.0, 1.0], 0.0, [0.0; 3])
    }

    #[test]
    fn arc_nodes_lie_on_the_circle_with_tangent_triads() {
        let mut m = Mesh::default();
        let sweep = std::f64::consts::FRAC_PI_4;
        let nodes = m
            .add_arc_beam(
                Vector3::zeros(),
                Vector3::new(100.0, 0.0, 0.0),
                Vector3::new(0.0, 0.0, -1.0),
                sweep,
                None,
                8,
                3,
                sec(),
            )
            .unwrap();
        assert_eq!(nodes.len(), 17);
        let tip = m.positions[*nodes.last().unwrap()];
        let expected = Vector3::new(100.0 - 100.0 * sweep.cos(), 100.0 * sweep.sin(), 0.0);
        assert!((tip - expected).norm() < 1e-12);
        // Tangent at the start is normal × (start − center)/radius = +y.
        if let Element::Quadratic(e) = &m.elements[0] {
            assert!((e.lambda0[0].column(0) - Vector3::y()).norm() < 1e-15);
            assert!((e.length - 100.0 * sweep / 8.0).abs() < 1e-12);
        } else {
            panic!("expected quadratic elements");
        }
    }

    #[test]
    fn closed_form_damping_equals_the_hyper_dual_hessian() {
        // A bent, twisted state and a step from a nearby one, for 2- and
        // 3-node elements: force and tangent against the AD oracle.
        for nodes_per_element in [2, 3] {
            let mut m = Mesh::default();
            let section = Section::new([3.0, 2.0, 1.5], [0.7, 1.1, 0.9], 0.0, [0.0; 3]);
            m.add_straight_beam(
                Vector3::zeros(),
                Vector3::new(1.0, 0.2, 0.1),
                Vector3::z(),
                1,
                nodes_per_element,
                section,
            )
            .unwrap();
            let n = m.node_count();
            let moved = |scale: f64| -> (Vec<Vector3<f64>>, Vec<Matrix3<f64>>) {
                let x = (0..n)
                    .map(|i| {
                        m.positions[i]
                            + scale * Vector3::new(0.01 * i as f64, 0.03 * (i * i) as f64, -0.02)
                    })
                    .collect();
                let rot = (0..n)
                    .map(|i| {
                        let v = scale * Vector3::new(0.1 * i as f64, -0.05, 0.07 * i as f64);
                        *nalgebra::Rotation3::new(v).matrix()
                    })
                    .collect();
                (x, rot)
            };
            let (xs, rs) = moved(0.8);
            let (xe, re) = moved(1.0);
            let d = 6 * n;
            let (mut r, mut k) = (vec![0.0; d], vec![0.0; d * d]);
            let (mut r_ad, mut k_ad) = (vec![0.0; d], vec![0.0; d * d]);
            let c = 2.5;
            m.elements[0].damping_residual_tangent((&xs, &rs), (&xe, &re), c, &mut r, &mut k);
            match &m.elements[0] {
                Element::Linear(e) => {
                    damping_of_ad(e, (&xs, &rs), (&xe, &re), c, &mut r_ad, &mut k_ad)
                }
                Element::Quadratic(e) => {
                    damping_of_ad(e, (&xs, &rs), (&xe, &re), c, &mut r_ad, &mut k_ad)
                }
            }
            let scale = |v: &[f64]| v.iter().fold(0.0f64, |a, b| a.max(b.abs()));
            let diff = |a: &[f64], b: &[f64]| {
                a.iter()
                    .zip(b)
                    .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
            };
            assert!(scale(&r) > 1e-3 && scale(&k) > 1e-3);
            assert!(
                diff(&r, &r_ad) <= 1e-12 * scale(&r_ad),
                "force {nodes_per_element}: {}",
                diff(&r, &r_ad)
            );
            assert!(
                diff(&k, &k_ad) <= 1e-12 * scale(&k_ad),
                "tangent {nodes_per_element}: {}",
                diff(&k, &k_ad)
            );
        }
    }

    #[test]
    fn degenerate_beams_are_errors() {
        let mut m = Mesh::default();
        let z = Vector3::zeros();
        assert_eq!(
            m.add_straight_beam(z, z, Vector3::x(), 2, 2, sec()),
            Err(MeshError::ZeroLength)
        );
        assert_eq!(
            m.add_straight_beam(z, Vector3::x(), Vector3::x() * 2.0, 2, 2, sec()),
            Err(MeshError::ParallelE2)
        );
        assert!(matches!(
            m.add_straight_beam(z, Vector3::x(), Vector3::y(), 0, 2, sec()),
            Err(MeshError::BadElementCount { .. })
        ));
        assert_eq!(m.node_count(), 0);
    }
}
