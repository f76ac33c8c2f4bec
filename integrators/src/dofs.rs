//! Numbering of the unknowns and the map from them to nodal increments.
//!
//! Every node's increment `pₙ = (uₙ, φₙ)` is a linear combination of global
//! unknowns: `pₙ = Σₖ cₖ q[eqₖ]`. For an independent node the columns are unit
//! vectors of its free DOFs; the master–slave joints (paper eqs 5–6) make a
//! slave's columns those of `N` applied to its master's and the released
//! unknowns. Residuals are carried back by the transpose (paper eqs 7–8).

use nalgebra::Vector6;

/// How node `n`'s increment depends on the unknowns.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct NodeMap {
    /// Global equation numbers.
    pub eqs: Vec<usize>,
    /// The column of each equation: `pₙ = Σₖ cols[k]·q[eqs[k]]`.
    pub cols: Vec<Vector6<f64>>,
    /// The row of each equation through which the node's residual reaches
    /// the reduced equations, when it differs from the column: a slave in
    /// the conserving schemes (rows of the incremental map `Ñ`, columns of
    /// the variational map `N`). `None`: the columns.
    pub rows: Option<Vec<Vector6<f64>>>,
    /// Whether the node is a joint's slave (its columns and rows change with
    /// the configuration); an independent node's columns are unit vectors
    /// for good.
    pub slave: bool,
}

impl NodeMap {
    /// The rows of the node's equations (the columns unless set apart).
    pub fn rows(&self) -> &[Vector6<f64>] {
        self.rows.as_deref().unwrap_or(&self.cols)
    }

    /// For an independent node (not a slave, rows equal to columns, every
    /// column a unit vector), the nodal DOF (0..6) of each of its equations;
    /// `None` otherwise. Such a node's map never changes.
    pub fn own_dofs(&self) -> Option<Vec<usize>> {
        if self.slave || self.rows.is_some() {
            return None;
        }
        self.cols
            .iter()
            .map(|c| {
                let d = c.iter().position(|&v| v == 1.0)?;
                (c.iter().filter(|&&v| v != 0.0).count() == 1).then_some(d)
            })
            .collect()
    }
}

/// The unknowns of a mechanism and every node's map.
#[derive(Debug, Clone, PartialEq)]
pub struct DofMap {
    /// Number of unknowns.
    pub n_eq: usize,
    /// One map per node.
    pub nodes: Vec<NodeMap>,
    /// Per node, the nodal DOF of each of its equations when the node is
    /// independent ([`NodeMap::own_dofs`]; such a map never changes): its
    /// reduced residual is a gather, not a product with unit columns.
    own: Vec<Option<OwnDofs>>,
    /// Whether every node is independent and every unknown is one node's
    /// (each receives one term in [`DofMap::reduce`]): then the reduction
    /// is a gather with no zeroing first.
    gather: bool,
    /// Where [`Self::gather`] holds: the gather as runs of consecutive
    /// unknowns taken from consecutive nodal DOFs, in the unknowns' order
    /// (a chain of free 6-DOF nodes is one run).
    runs: Vec<Run>,
}

/// Unknowns `eq..eq + len` of a gather take nodal DOFs `from..from + len`.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Run {
    eq: usize,
    from: usize,
    len: usize,
}

/// The runs of a gather: unknown `e` takes nodal DOF `6n + d` for each
/// independent node `n`'s equation `e` of DOF `d`; every unknown is taken
/// once (checked by the caller).
fn gather_runs(nodes: &[NodeMap], own: &[Option<OwnDofs>]) -> Vec<Run> {
    let mut pairs: Vec<(usize, usize)> = Vec::new();
    for (n, (m, own)) in nodes.iter().zip(own).enumerate() {
        let Some(own) = own else { continue };
        for (&e, &d) in m.eqs.iter().zip(&own.dofs[..own.len as usize]) {
            pairs.push((e, 6 * n + d as usize));
        }
    }
    pairs.sort_unstable();
    let mut runs: Vec<Run> = Vec::new();
    for (eq, from) in pairs {
        match runs.last_mut() {
            Some(r) if r.eq + r.len == eq && r.from + r.len == from => r.len += 1,
            _ => runs.push(Run { eq, from, len: 1 }),
        }
    }
    runs
}

/// The nodal DOFs (0..6) of an independent node's equations, in order.
#[derive(Debug, Clone, Copy, PartialEq)]
struct OwnDofs {
    dofs: [u8; 6],
    len: u8,
}

impl OwnDofs {
    fn of(map: &NodeMap) -> Option<Self> {
        let own = map.own_dofs()?;
        let mut dofs = [0; 6];
        for (d, &o) in dofs.iter_mut().zip(&own) {
            *d = o as u8;
        }
        Some(Self {
            dofs,
            len: own.len() as u8,
        })
    }
}

impl DofMap {
    /// The map of `n_eq` unknowns with these node maps.
    pub fn new(n_eq: usize, nodes: Vec<NodeMap>) -> Self {
        let own: Vec<Option<OwnDofs>> = nodes.iter().map(OwnDofs::of).collect();
        let mut hits = vec![0u32; n_eq];
        for m in &nodes {
            for &e in &m.eqs {
                if let Some(h) = hits.get_mut(e) {
                    *h += 1;
                }
            }
        }
        let gather = own.iter().all(Option::is_some) && hits.iter().all(|&h| h == 1);
        let runs = if gather {
            gather_runs(&nodes, &own)
        } else {
            Vec::new()
        };
        Self {
            n_eq,
            nodes,
            own,
            gather,
            runs,
        }
    }

    /// Independent nodes only: each free DOF is an unknown, numbered node by node.
    pub fn independent(fixed: &[[bool; 6]]) -> Self {
        let mut n_eq = 0;
        let nodes = fixed
            .iter()
            .map(|f| {
                let mut m = NodeMap::default();
                for (d, &held) in f.iter().enumerate() {
                    if !held {
                        m.eqs.push(n_eq);
                        m.cols.push(Vector6::ith(d, 1.0));
                        n_eq += 1;
                    }
                }
                m
            })
            .collect();
        Self::new(n_eq, nodes)
    }

    /// [`NodeMap::own_dofs`] of node `n`, found once when the map was made:
    /// the nodal DOF (0..6) of each of its equations where the node is
    /// independent, `None` otherwise.
    pub fn own_dofs(&self, n: usize) -> Option<&[u8]> {
        self.own[n].as_ref().map(|o| &o.dofs[..o.len as usize])
    }

    /// Nodal increment of node `n` for the global increment `dq`.
    pub fn node_increment(&self, n: usize, dq: &[f64]) -> Vector6<f64> {
        let m = &self.nodes[n];
        m.eqs.iter().zip(&m.cols).map(|(&e, c)| c * dq[e]).sum()
    }

    /// `‖Σₙ Tₙᵀ gₙ‖`, reduced into `scratch` (length `n_eq`): the size of
    /// nodal forces `g` as the unknowns see them (residual scales).
    pub fn reduced_norm(&self, g: &[f64], scratch: &mut [f64]) -> f64 {
        self.reduce(g, scratch);
        scratch.iter().map(|x| x * x).sum::<f64>().sqrt()
    }

    /// [`Self::reduced_norm`] of each of `g`, the same numbers: where the
    /// reduction is a gather, read from the nodal values in the unknowns'
    /// order with the sums side by side (each sum waits on its last
    /// addition; several in one loop wait once).
    pub fn reduced_norms<const K: usize>(&self, g: [&[f64]; K], scratch: &mut [f64]) -> [f64; K] {
        if !self.gather {
            return g.map(|g| self.reduced_norm(g, scratch));
        }
        let mut sums = [0.0f64; K];
        for r in &self.runs {
            for j in r.from..r.from + r.len {
                for (s, g) in sums.iter_mut().zip(&g) {
                    // `0 + g` as the gather forms it: its square is `g²`.
                    *s += g[j] * g[j];
                }
            }
        }
        sums.map(f64::sqrt)
    }

    /// Whether the reduction is a gather ([`Self::reduce`]): each unknown
    /// one node's DOF.
    pub fn is_gather(&self) -> bool {
        self.gather
    }

    /// Reduced residual `Σₙ Tₙᵀ gₙ` from nodal residuals `g` (6 per node).
    pub fn reduce(&self, g: &[f64], out: &mut [f64]) {
        if self.gather {
            for r in &self.runs {
                let to = &mut out[r.eq..r.eq + r.len];
                for (o, &v) in to.iter_mut().zip(&g[r.from..r.from + r.len]) {
                    // `0 + g` as the sum below forms it (a zero's sign too).
                    *o = 0.0 + v;
                }
            }
            return;
        }
        out.iter_mut().for_each(|v| *v = 0.0);
        self.add_reduced_except(g, out, |_| false);
    }

    /// `Tₙᵀ gₙ` of every node `skip` does not name added into `out`: an
    /// independent node's own DOFs taken as they are (the dot product with a
    /// unit column gives the same sum, zero signs included, for finite
    /// forces), any other through its columns.
    pub fn add_reduced_except(&self, g: &[f64], out: &mut [f64], skip: impl Fn(usize) -> bool) {
        for (n, (m, own)) in self.nodes.iter().zip(&self.own).enumerate() {
            if skip(n) {
                continue;
            }
            let gn = &g[6 * n..6 * n + 6];
            match own {
                Some(own) => {
                    for (&e, &d) in m.eqs.iter().zip(&own.dofs[..own.len as usize]) {
                        out[e] += gn[d as usize];
                    }
                }
                None => {
                    let gn = Vector6::from_column_slice(gn);
                    for (&e, c) in m.eqs.iter().zip(&m.cols) {
                        out[e] += c.dot(&gn);
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_gather_gives_the_bits_of_the_sum_through_the_columns() {
        // Independent nodes with held DOFs: the reduction is a gather; the
        // same map with one node made a slave-like product (its columns
        // scaled by one, so no gather) sums through the columns. Both give
        // `0 + g` per unknown, a zero's sign included.
        let mut fixed = vec![[false; 6]; 4];
        fixed[0] = [true; 6];
        fixed[2] = [false, true, false, false, true, false];
        let map = DofMap::independent(&fixed);
        assert!(map.gather);
        let general = DofMap {
            gather: false,
            ..map.clone()
        };
        let g: Vec<f64> = (0..24)
            .map(|i| {
                if i % 5 == 0 {
                    -0.0
                } else {
                    (i as f64 * 0.37).sin()
                }
            })
            .collect();
        let (mut a, mut b) = (vec![1.0; map.n_eq], vec![2.0; map.n_eq]);
        map.reduce(&g, &mut a);
        general.reduce(&g, &mut b);
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&a), bits(&b));
        // Both norms in one loop: the bits of each alone.
        let h: Vec<f64> = g.iter().map(|v| 3.0 * v - 1e-3).collect();
        let mut scratch = vec![0.0; map.n_eq];
        let norms = |m: &DofMap, s: &mut [f64]| {
            let [x, y] = m.reduced_norms([&g, &h], s);
            [x, y, m.reduced_norm(&g, s), m.reduced_norm(&h, s)].map(f64::to_bits)
        };
        let [x, y, xa, ya] = norms(&map, &mut scratch);
        assert_eq!((x, y), (xa, ya));
        assert_eq!(norms(&general, &mut scratch)[..2], [x, y]);
        // Unknowns numbered against the nodes' order: the runs follow the
        // unknowns (the sums' order), not the nodes.
        let mut shuffled = map.nodes.clone();
        for m in &mut shuffled {
            for e in &mut m.eqs {
                *e = map.n_eq - 1 - *e;
            }
        }
        let shuffled = DofMap::new(map.n_eq, shuffled);
        assert!(shuffled.gather && shuffled.runs.len() > 1);
        let plain = DofMap {
            gather: false,
            ..shuffled.clone()
        };
        let (mut a, mut b) = (vec![1.0; map.n_eq], vec![2.0; map.n_eq]);
        shuffled.reduce(&g, &mut a);
        plain.reduce(&g, &mut b);
        assert_eq!(bits(&a), bits(&b));
        assert_eq!(norms(&shuffled, &mut scratch), norms(&plain, &mut scratch));
        // A map whose unknowns are not each one node's sums.
        let mut nodes = map.nodes.clone();
        nodes[3].eqs[0] = nodes[1].eqs[0];
        assert!(!DofMap::new(map.n_eq, nodes).gather);
    }
}
