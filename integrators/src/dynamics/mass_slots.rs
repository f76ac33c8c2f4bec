//! Where the nodal mass and inertia blocks land in the tangent values,
//! found once per run (the tangent's pattern does not change), so that each
//! tangent assembly adds them without searching.

use crate::assembly::Assembler;
use crate::dofs::DofMap;
use crate::element_split::Shared;
use flexmech_core::Inertia;
use nalgebra::{Matrix3, Vector3};
/// Where the mass and inertia blocks land in the tangent values. The
/// translational mass `Σ m_ij I` is constant: the diagonal positions of the
/// blocks whose nodes are independent, with their masses, are listed once,
/// in the order of the values, so that each tangent assembly adds
/// `c m_ij` along them in one sweep; entries involving a slave (whose maps
/// change with the iterate) go through the maps. Rotational inertia: per
/// node, its block's positions (`None` where the node is a slave).
pub(crate) struct MassSlots {
    /// `(position in the tangent values, m_ij)`, sorted by position.
    translational: Vec<(usize, f64)>,
    /// Mass entries (indices into [`Inertia::mass`]) that involve a slave.
    through_maps: Vec<usize>,
    rotational: Vec<Option<Vec<(usize, usize, usize)>>>,
    /// Where no node is a slave: each node's translational mass entries
    /// (`by_node[i]` into `entries`, in the order of [`Inertia::mass`]),
    /// so that a node's translational forces and tangent diagonal are added
    /// with its rotational terms, by the thread that takes the node.
    own: Option<NodeMass>,
}

/// The translational mass entries `(i, j, m)` of every node `i`, with the
/// positions of their blocks' diagonals in the tangent values.
struct NodeMass {
    by_node: Vec<std::ops::Range<usize>>,
    entries: Vec<MassEntry>,
}

/// A translational mass entry `(i, j, m)` of node `i`: `(j, m, positions of
/// its block's diagonal, how many)`.
type MassEntry = (usize, f64, [usize; 3], usize);

impl NodeMass {
    /// Every entry's node `i` and diagonal, or `None` where one involves a
    /// slave.
    fn new(asm: &Assembler, dofs: &DofMap, inertia: &Inertia) -> Option<Self> {
        let nodes = inertia.rotational.len();
        let mut rows: Vec<Vec<MassEntry>> = vec![Vec::new(); nodes];
        for &(i, j, m) in &inertia.mass {
            let (at, len) = asm.node_block_diagonal(dofs, i, j)?;
            rows.get_mut(i)?.push((j, m, at, len));
        }
        let mut by_node = Vec::with_capacity(nodes);
        let mut entries = Vec::with_capacity(inertia.mass.len());
        for row in rows {
            by_node.push(entries.len()..entries.len() + row.len());
            entries.extend(row);
        }
        Some(Self { by_node, entries })
    }
}

impl MassSlots {
    pub(crate) fn new(asm: &Assembler, dofs: &DofMap, inertia: &Inertia) -> Self {
        let mut translational = Vec::new();
        let mut through_maps = Vec::new();
        for (k, &(i, j, m)) in inertia.mass.iter().enumerate() {
            match asm.node_block_diagonal(dofs, i, j) {
                Some((at, len)) => translational.extend(at[..len].iter().map(|&p| (p, m))),
                None => through_maps.push(k),
            }
        }
        translational.sort_by_key(|&(p, _)| p);
        let rotational: Vec<_> = (0..inertia.rotational.len())
            .map(|i| asm.node_block_slots(dofs, (i, 3), (i, 3)))
            .collect();
        let own = rotational
            .iter()
            .all(Option::is_some)
            .then(|| NodeMass::new(asm, dofs, inertia))
            .flatten();
        Self {
            translational,
            through_maps,
            rotational,
            own,
        }
    }

    /// Adds `c M` for the translational mass `M = Σ m_ij I`.
    fn add_translational(&self, asm: &mut Assembler, dofs: &DofMap, inertia: &Inertia, c: f64) {
        if c == 0.0 {
            return;
        }
        for &(p, m) in &self.translational {
            asm.values[p] += c * m;
        }
        for &k in &self.through_maps {
            let (i, j, m) = inertia.mass[k];
            asm.add_node_block(dofs, (i, 0), (j, 0), &(Matrix3::identity() * (c * m)));
        }
    }

    /// Adds `block` for the rotations of node `i`.
    pub(crate) fn add_rotational(
        &self,
        asm: &mut Assembler,
        dofs: &DofMap,
        i: usize,
        block: &Matrix3<f64>,
    ) {
        match &self.rotational[i] {
            Some(at) => asm.add_node_block_at(at, block),
            None => asm.add_node_block(dofs, (i, 3), (i, 3), block),
        }
    }

    /// Adds a scheme's inertial forces to the nodal residual `g` (their
    /// magnitudes to `abs`) and, with `tangent`, their tangent blocks:
    /// `force(m, &node_term(j))` is the force of mass entry `(i, j, m)` on
    /// node `i` (`node_term` computed once per node), whose derivative with
    /// respect to node `j`'s translation is `coefficient·m·I`;
    /// `moment(i, J₀, tangent)` is node `i`'s inertial moment and its
    /// derivative under a spin of its end rotation (nodes without rotary
    /// inertia are skipped).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn add_inertia(
        &self,
        inertia: &Inertia,
        g: &mut [f64],
        abs: &mut [f64],
        mut tangent: Option<(&mut Assembler, &DofMap)>,
        node_term: impl Fn(usize) -> Vector3<f64> + Sync + Send,
        force: impl Fn(f64, &Vector3<f64>) -> Vector3<f64> + Sync,
        coefficient: f64,
        moment: impl Fn(usize, &Matrix3<f64>, bool) -> (Vector3<f64>, Matrix3<f64>) + Sync,
    ) {
        let terms = crate::threads::map_nodes(g.len() / 6, node_term);
        if let Some(own) = &self.own {
            let values = tangent.map(|(asm, _)| &mut asm.values[..]);
            let translational: Translational<'_> = (own, &terms[..], &force, coefficient);
            return self.add_rotational_own(inertia, g, abs, values, &moment, Some(translational));
        }
        for &(i, j, m) in &inertia.mass {
            let f = force(m, &terms[j]);
            for c in 0..3 {
                g[6 * i + c] += f[c];
                abs[6 * i + c] += f[c].abs();
            }
        }
        if let Some((asm, dofs)) = tangent.as_mut() {
            self.add_translational(asm, dofs, inertia, coefficient);
        }
        if self.rotational.iter().all(Option::is_some) {
            let values = tangent.map(|(asm, _)| &mut asm.values[..]);
            return self.add_rotational_own(inertia, g, abs, values, &moment, None);
        }
        let moments = rotational_moments(inertia, tangent.is_some(), &moment);
        for (i, (m, k)) in moments.into_iter().enumerate() {
            if inertia.rotational[i] == Matrix3::zeros() {
                continue;
            }
            for c in 0..3 {
                g[6 * i + 3 + c] += m[c];
                abs[6 * i + 3 + c] += m[c].abs();
            }
            if let Some((asm, dofs)) = tangent.as_mut() {
                self.add_rotational(asm, dofs, i, &k);
            }
        }
    }

    /// The inertial moments' part of [`Self::add_inertia`] where no node is
    /// a slave (every inertia block has its own positions), node by node —
    /// on the team's threads for a large mesh
    /// ([`crate::threads::for_each_node`]): each node's moment, and its
    /// tangent block into `values` (given a tangent), is added by the thread
    /// that computes it; so are, given `translational`, its translational
    /// forces and tangent diagonal ([`Self::own`]: the forces of node `i`'s
    /// mass entries in their order, then `c m` along their diagonals). The
    /// entries of `g`, `abs` and the values each node adds to are its own,
    /// and each receives its terms in the order of the one-thread loops, so
    /// the sums do not depend on the thread count.
    fn add_rotational_own(
        &self,
        inertia: &Inertia,
        g: &mut [f64],
        abs: &mut [f64],
        values: Option<&mut [f64]>,
        moment: &(impl Fn(usize, &Matrix3<f64>, bool) -> (Vector3<f64>, Matrix3<f64>) + Sync),
        translational: Option<Translational<'_>>,
    ) {
        let tangent = values.is_some();
        let (g, abs) = (Shared::new(g), Shared::new(abs));
        let values = values.map(Shared::new);
        crate::threads::for_each_node(inertia.rotational.len(), |i| {
            if let Some((own, terms, force, c)) = translational {
                let entries = &own.entries[own.by_node[i].clone()];
                for &(j, m, _, _) in entries {
                    let f = force(m, &terms[j]);
                    // SAFETY: node `i`'s translational entries of `g` and
                    // `abs` are touched by this node only.
                    unsafe {
                        g.add(6 * i, f.as_slice(), |v| v);
                        abs.add(6 * i, f.as_slice(), f64::abs);
                    }
                }
                if let Some(values) = values.as_ref().filter(|_| c != 0.0) {
                    for &(_, m, at, len) in entries {
                        for &p in &at[..len] {
                            // SAFETY: the diagonals of node `i`'s row blocks
                            // are touched by this node only.
                            unsafe { values.add(p, &[c * m], |v| v) };
                        }
                    }
                }
            }
            let j0 = &inertia.rotational[i];
            if *j0 == Matrix3::zeros() {
                return;
            }
            let (m, k) = moment(i, j0, tangent);
            // SAFETY: node `i`'s rotational entries of `g` and `abs`, and the
            // positions of its own inertia block, are touched by this node
            // only (see above); `for_each_node` visits each node once.
            unsafe {
                g.add(6 * i + 3, m.as_slice(), |v| v);
                abs.add(6 * i + 3, m.as_slice(), f64::abs);
            }
            let (Some(values), Some(at)) = (&values, &self.rotational[i]) else {
                return;
            };
            for &(p, a, b) in at {
                let v = k[(a, b)];
                if v != 0.0 {
                    // SAFETY: as above.
                    unsafe { values.add(p, &[v], |v| v) };
                }
            }
        });
    }
}

/// The translational part of [`MassSlots::add_rotational_own`]: every
/// node's mass entries, the nodes' terms, the force of an entry and the
/// tangent's coefficient.
type Translational<'a> = (
    &'a NodeMass,
    &'a [Vector3<f64>],
    &'a (dyn Fn(f64, &Vector3<f64>) -> Vector3<f64> + Sync),
    f64,
);

/// Every node's inertial moment and its tangent (zero for nodes without
/// rotary inertia), on two threads for a large mesh
/// ([`crate::threads::map_nodes`]: each node's on its own, summed afterwards
/// in node order, the same for any thread count).
fn rotational_moments(
    inertia: &Inertia,
    tangent: bool,
    moment: &(impl Fn(usize, &Matrix3<f64>, bool) -> (Vector3<f64>, Matrix3<f64>) + Sync),
) -> Vec<(Vector3<f64>, Matrix3<f64>)> {
    crate::threads::map_nodes(inertia.rotational.len(), |i| {
        let j0 = &inertia.rotational[i];
        if *j0 == Matrix3::zeros() {
            (Vector3::zeros(), Matrix3::zeros())
        } else {
            moment(i, j0, tangent)
        }
    })
}

/// Test support: forward AD of an inertial moment under a spatial spin of
/// the end rotation, the oracle of the schemes' closed-form inertial
/// tangents, with the fixtures both schemes' tests share.
#[cfg(test)]
pub(crate) mod inertia_oracle {
    use flexmech_core::rotation::exp;
    use nalgebra::{Const, Matrix3, Vector3, U1};
    use num_dual::DualSVec64;

    /// A number of the oracle's kind.
    pub(crate) type D = DualSVec64<3>;

    /// Both sides are exact: only round-off separates them.
    const ORACLE_TOL: f64 = 1e-10;

    /// A rotary inertia with products of inertia.
    pub(crate) fn inertia() -> Matrix3<f64> {
        Matrix3::new(2.0, 0.1, -0.2, 0.1, 1.5, 0.05, -0.2, 0.05, 0.8)
    }

    /// A start rotation and end rotations a small, a moderate and a large
    /// spin from it (the last beyond 120°).
    pub(crate) fn rotations() -> (Matrix3<f64>, [Matrix3<f64>; 3]) {
        let r_n = exp(&Vector3::new(0.4, -1.1, 2.0));
        let spins = [
            Vector3::new(1e-4, 2e-4, -1e-4),
            Vector3::new(0.3, -0.5, 0.2),
            Vector3::new(-1.2, 0.9, 1.4),
        ];
        (r_n, spins.map(|s| exp(&s) * r_n))
    }

    /// Asserts that `closed` — a moment and its derivative under a spatial
    /// spin of `r1` — equals three-lane forward AD of `moment` at `r1`.
    pub(crate) fn assert_equals_ad(
        r1: &Matrix3<f64>,
        (m, k): (Vector3<f64>, Matrix3<f64>),
        moment: impl Fn(&Matrix3<D>) -> Vector3<D>,
        what: &str,
    ) {
        let seed = |j: usize| D::from_re(0.0).derivative(j);
        let eta = Vector3::new(seed(0), seed(1), seed(2));
        let m_ad = moment(&(exp(&eta) * r1.map(D::from_re)));
        let mut k_ad = Matrix3::zeros();
        for c in 0..3 {
            k_ad.set_row(c, &m_ad[c].eps.unwrap_generic(Const::<3>, U1).transpose());
        }
        let m_ad = m_ad.map(|v| v.re);
        let size = k_ad.norm().max(1.0);
        assert!(
            (m - m_ad).norm() <= ORACLE_TOL * m_ad.norm().max(1.0),
            "{what}: moment"
        );
        assert!(
            (k - k_ad).norm() <= ORACLE_TOL * size,
            "{what}: {:e}",
            (k - k_ad).norm() / size
        );
    }
}
