//! What moves freely when a tangent is singular, told in the model's terms
//! for the error message.
//!
//! A converged solve whose tangent is singular has no unique answer (a
//! support missing, a part that nothing connects, a released joint
//! coordinate with neither stiffness, load nor mass): Newton may well reach
//! a small residual, but the configuration it reports is one of infinitely
//! many. [`crate::newton`] refuses it; this module says what is free:
//!
//! * the rigid-body motions of the whole mechanism the tangent does not
//!   resist — the six motions `uₙ = a + ω × (xₙ − c)`, `φₙ = ω` (with
//!   released coordinates unchanged) are written in the unknowns, and the
//!   combinations whose equilibrated tangent product is round-off relative
//!   to their size are the free ones (a generalized 6×6 eigenproblem); they
//!   are reported as free translation directions and free rotation axes
//!   with a point on each;
//! * otherwise the nodes and joints that the null direction found by
//!   [`crate::linsolve::SparseLu::condition_estimate`] moves.

use crate::dofs::DofMap;
use crate::linsolve::TangentRef;
use crate::mechanism::Mechanism;
use nalgebra::{DMatrix, Matrix6, SymmetricEigen, Vector3, Vector6};
use std::fmt;

/// Relative size below which a node, a joint coordinate, a part of a motion
/// or a Gram eigenvalue takes no part.
const MOVES: f64 = 1e-3;
/// Relative tangent product (of the equilibrated tangent, against its norm)
/// below which a rigid-body motion is free: far above round-off (10⁻¹⁴),
/// far below what any support leaves (≳ 1/√(node count)).
const FREE: f64 = 1e-6;
/// How many nodes a message names.
const NAMED: usize = 3;

/// The free motion of a singular mechanism.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FreeMotion {
    /// Free translation directions of the whole mechanism (orthonormal).
    pub translations: Vec<Vector3<f64>>,
    /// Free rotations of the whole mechanism: unit axis and a point on it.
    pub rotations: Vec<(Vector3<f64>, Vector3<f64>)>,
    /// The global numbers of the nodes the null direction moves most,
    /// largest first.
    pub nodes: Vec<usize>,
    /// How many nodes it moves in all.
    pub moving: usize,
    /// Labels of `nodes` in the model's terms ([`Mechanism::names`];
    /// `node <n>` for an unnamed node).
    pub labels: Vec<String>,
    /// Names of the joints whose released coordinates it moves.
    pub joints: Vec<String>,
    /// Names of the beams ([`Mechanism::names`]) with a node it moves, in
    /// the model's order.
    pub beams: Vec<String>,
}

impl FreeMotion {
    /// Describes the singular tangent `tangent` of `mech` (reduced unknowns
    /// with node maps `dofs` and, per joint, the equations of its released
    /// coordinates `released_eqs`; nodes at `x`) with null direction `mode`.
    pub fn of(
        mech: &Mechanism,
        dofs: &DofMap,
        released_eqs: &[Vec<Option<usize>>],
        x: &[Vector3<f64>],
        mode: &[f64],
        tangent: TangentRef,
    ) -> Self {
        let count = x.len().max(1) as f64;
        let centre = x.iter().sum::<Vector3<f64>>() / count;
        let length = x
            .iter()
            .map(|xi| (xi - centre).norm())
            .fold(0.0f64, f64::max);
        let length = if length > 0.0 { length } else { 1.0 };
        let mut motion = Self::default();
        let free = free_rigid_motions(mech, dofs, x, centre, length, tangent);
        motion.describe_rigid(&free, centre, length);
        let p: Vec<Vector6<f64>> = (0..dofs.nodes.len())
            .map(|n| dofs.node_increment(n, mode))
            .collect();
        let size = |pn: &Vector6<f64>| {
            (pn.fixed_rows::<3>(0).norm() / length).max(pn.fixed_rows::<3>(3).norm())
        };
        let sizes: Vec<f64> = p.iter().map(size).collect();
        let top = sizes.iter().fold(0.0f64, |m, &s| m.max(s));
        let mut nodes: Vec<usize> = (0..p.len()).filter(|&n| sizes[n] > MOVES * top).collect();
        motion.moving = nodes.len();
        motion.beams = beams_moved(mech, &nodes);
        nodes.sort_by(|&a, &b| sizes[b].total_cmp(&sizes[a]).then(a.cmp(&b)));
        nodes.truncate(NAMED);
        if !mech.names.nodes.is_empty() {
            motion.labels = nodes
                .iter()
                .map(|&n| {
                    mech.names
                        .node(n)
                        .map_or_else(|| format!("node {n}"), str::to_owned)
                })
                .collect();
        }
        motion.nodes = nodes;
        let released = |eqs: &Vec<Option<usize>>| {
            eqs.iter()
                .flatten()
                .fold(0.0f64, |m, &e| m.max(mode[e].abs()))
        };
        let joint_top = released_eqs.iter().map(released).fold(0.0, f64::max);
        let scale = top.max(joint_top);
        motion.joints = released_eqs
            .iter()
            .zip(&mech.joints)
            .filter(|(eqs, _)| released(eqs) > MOVES * scale)
            .map(|(_, j)| j.name.clone())
            .collect();
        motion
    }

    /// Splits the free rigid motions `free` (columns `(a, ω)` about
    /// `centre`) into pure translations and rotations with their axes.
    fn describe_rigid(&mut self, free: &[Vector6<f64>], centre: Vector3<f64>, length: f64) {
        if free.is_empty() {
            return;
        }
        // Each motion scaled so that its larger part has unit size.
        let unit: Vec<Vector6<f64>> = free
            .iter()
            .map(|c| {
                let big = (c.fixed_rows::<3>(0).norm() / length).max(c.fixed_rows::<3>(3).norm());
                c / big
            })
            .collect();
        let w = DMatrix::from_fn(3, unit.len(), |i, j| unit[j][3 + i]);
        // Combinations e of the free motions: Wᵀ W e = σ² e; σ ≈ 0 are pure
        // translations, the others rotate.
        let eig = SymmetricEigen::new(w.transpose() * &w);
        let combine = |k: usize| -> Vector6<f64> {
            unit.iter()
                .enumerate()
                .map(|(j, c)| c * eig.eigenvectors[(j, k)])
                .sum()
        };
        let rotates = |k: usize| eig.eigenvalues[k] > MOVES * MOVES;
        for k in (0..unit.len()).filter(|&k| !rotates(k)) {
            let mut a = Vector3::from(combine(k).fixed_rows::<3>(0));
            for t in &self.translations {
                a -= t * t.dot(&a);
            }
            if a.norm() > MOVES * length {
                self.translations.push(a.normalize());
            }
        }
        for k in (0..unit.len()).filter(|&k| rotates(k)) {
            let g = combine(k);
            let mut a = Vector3::from(g.fixed_rows::<3>(0));
            for t in &self.translations {
                a -= t * t.dot(&a);
            }
            let w = Vector3::from(g.fixed_rows::<3>(3));
            let point = centre + w.cross(&a) / w.norm_squared();
            // The axis's sign: its largest component positive.
            let axis = w.normalize();
            let axis = if axis[axis.iamax()] < 0.0 {
                -axis
            } else {
                axis
            };
            self.rotations.push((axis, point));
        }
    }

    fn name(&self, k: usize) -> String {
        self.labels
            .get(k)
            .map(|l| format!("\"{l}\""))
            .unwrap_or_else(|| format!("node {}", self.nodes[k]))
    }
}

/// The names of the beams with an element on one of the `moving` nodes, in
/// the model's order.
fn beams_moved(mech: &Mechanism, moving: &[usize]) -> Vec<String> {
    let mut moved = vec![false; mech.mesh.node_count()];
    for &n in moving {
        if let Some(m) = moved.get_mut(n) {
            *m = true;
        }
    }
    let elements = &mech.mesh.elements;
    let moves = |e: usize| {
        elements
            .get(e)
            .is_some_and(|el| el.nodes().iter().any(|&n| moved.get(n) == Some(&true)))
    };
    mech.names
        .beams
        .iter()
        .filter(|(_, range)| range.clone().any(moves))
        .map(|(name, _)| name.clone())
        .collect()
}

/// The rigid-body motions (columns `(a, ω)` about `centre`) that the
/// tangent does not resist.
fn free_rigid_motions(
    mech: &Mechanism,
    dofs: &DofMap,
    x: &[Vector3<f64>],
    centre: Vector3<f64>,
    length: f64,
    tangent: TangentRef,
) -> Vec<Vector6<f64>> {
    let n = dofs.n_eq;
    let d = tangent.equilibration();
    let norm = tangent.scaled_norm(&d);
    let mut slave = vec![false; x.len()];
    for j in &mech.joints {
        slave[j.slave] = true;
    }
    // The six motions in the unknowns (released coordinates unchanged):
    // scaled unknowns vᵢ = D⁻¹qᵢ and equilibrated products yᵢ = D K qᵢ.
    let mut v = Vec::with_capacity(6);
    let mut y = Vec::with_capacity(6);
    for i in 0..6 {
        let mut q = vec![0.0; n];
        for (node, map) in dofs.nodes.iter().enumerate() {
            if slave[node] {
                continue;
            }
            let r = x[node] - centre;
            let mut rigid = Vector6::<f64>::zeros();
            if i < 3 {
                rigid[i] = length;
            } else {
                let w = Vector3::ith(i - 3, 1.0);
                rigid.fixed_rows_mut::<3>(0).copy_from(&w.cross(&r));
                rigid[i] = 1.0;
            }
            for (&eq, col) in map.eqs.iter().zip(&map.cols) {
                q[eq] = col.dot(&rigid);
            }
        }
        let kq = tangent.product(&q);
        v.push(q.iter().zip(&d).map(|(a, s)| a / s).collect::<Vec<f64>>());
        y.push(kq.iter().zip(&d).map(|(a, s)| a * s).collect::<Vec<f64>>());
    }
    let gram =
        |a: &[Vec<f64>]| Matrix6::from_fn(|i, j| a[i].iter().zip(&a[j]).map(|(p, q)| p * q).sum());
    let (gv, gy) = (gram(&v), gram(&y));
    // Gy c = λ Gv c on the range of Gv (a motion every support holds has
    // no unknowns: it is not free).
    let eig = SymmetricEigen::new(gv);
    let top = eig.eigenvalues.iter().fold(0.0f64, |m, &s| m.max(s));
    let keep: Vec<usize> = (0..6)
        .filter(|&k| eig.eigenvalues[k] > MOVES * MOVES * top)
        .collect();
    if keep.is_empty() {
        return Vec::new();
    }
    let t: DMatrix<f64> = DMatrix::from_fn(6, keep.len(), |i, j| {
        let value: f64 = eig.eigenvalues[keep[j]];
        eig.eigenvectors[(i, keep[j])] / value.sqrt()
    });
    let gy = DMatrix::from_fn(6, 6, |i, j| gy[(i, j)]);
    let reduced: DMatrix<f64> = t.transpose() * gy * &t;
    let inner = SymmetricEigen::new(reduced);
    (0..keep.len())
        .filter(|&k| inner.eigenvalues[k] <= (FREE * norm).powi(2))
        .map(|k| {
            let c = &t * inner.eigenvectors.column(k);
            let mut motion = Vector6::from_iterator(c.iter().copied());
            motion.fixed_rows_mut::<3>(0).scale_mut(length);
            motion
        })
        .collect()
}

impl fmt::Display for FreeMotion {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let v = |a: &Vector3<f64>| {
            let c = a.map(|c| {
                if c.abs() < 1e-9 * a.norm().max(1.0) {
                    0.0
                } else {
                    c
                }
            });
            format!("[{:.4}, {:.4}, {:.4}]", c.x, c.y, c.z)
        };
        if !self.translations.is_empty() || !self.rotations.is_empty() {
            let mut parts = Vec::new();
            match self.translations.len() {
                0 => {}
                1 => parts.push(format!("translation along {}", v(&self.translations[0]))),
                2 => {
                    let normal = self.translations[0].cross(&self.translations[1]);
                    parts.push(format!("translation in the plane normal to {}", v(&normal)))
                }
                _ => parts.push("translation in any direction".into()),
            }
            // With every translation free, an axis has no particular point.
            let through = |point: &Vector3<f64>| {
                if self.translations.len() == 3 {
                    String::new()
                } else {
                    format!(" through {}", v(point))
                }
            };
            match self.rotations.len() {
                0 => {}
                2 => {
                    let normal = self.rotations[0].0.cross(&self.rotations[1].0);
                    parts.push(format!(
                        "rotation about any axis normal to {}{}",
                        v(&normal.normalize()),
                        through(&self.rotations[0].1)
                    ))
                }
                3 => parts.push(format!(
                    "rotation about any axis{}",
                    through(&self.rotations[0].1)
                )),
                _ => {
                    for (axis, point) in &self.rotations {
                        parts.push(format!("rotation about {}{}", v(axis), through(point)));
                    }
                }
            }
            return write!(
                f,
                "the whole mechanism can move as a rigid body with no force ({}): add a \
                 [[support]] (or a joint to a supported part) that holds it",
                parts.join("; ")
            );
        }
        let names: Vec<String> = (0..self.nodes.len()).map(|k| self.name(k)).collect();
        let more = self.moving.saturating_sub(self.nodes.len());
        write!(f, "a motion with no force moves ")?;
        if names.is_empty() {
            write!(f, "no node")?;
        } else {
            write!(f, "{}", names.join(", "))?;
            if more > 0 {
                write!(f, " and {more} more node(s)")?;
            }
        }
        if !self.beams.is_empty() {
            let b: Vec<String> = self.beams.iter().map(|b| format!("\"{b}\"")).collect();
            write!(f, " of beam(s) {}", b.join(", "))?;
        }
        if !self.joints.is_empty() {
            let j: Vec<String> = self.joints.iter().map(|j| format!("\"{j}\"")).collect();
            write!(
                f,
                " through the released coordinates of joint(s) {}",
                j.join(", ")
            )?;
        }
        write!(
            f,
            ": support it, connect it to a supported part, or give it stiffness or mass"
        )
    }
}
