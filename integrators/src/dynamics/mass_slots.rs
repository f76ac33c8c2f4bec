//! Where the nodal mass and inertia blocks land in the tangent values,
//! found once per run (the tangent's pattern does not change), so that each
//! tangent assembly adds them without searching.

use crate::assembly::Assembler;
use crate::dofs::DofMap;
use flexmech_core::Inertia;
use nalgebra::{Const, Matrix3, Vector3, U1};
use num_dual::DualSVec64;

/// A nodal inertial moment `m(R)` at the end rotation `r_end` and its
/// derivative with respect to a spatial spin of it (`R ← exp(η̂)R`), by
/// three-lane forward AD; the value alone when `tangent` is false (the
/// derivative is then zero).
pub(crate) fn spin_derivative(
    r_end: &Matrix3<f64>,
    tangent: bool,
    moment: impl Fn(&Matrix3<DualSVec64<3>>) -> Vector3<DualSVec64<3>>,
    plain: impl Fn(&Matrix3<f64>) -> Vector3<f64>,
) -> (Vector3<f64>, Matrix3<f64>) {
    if !tangent {
        return (plain(r_end), Matrix3::zeros());
    }
    type D = DualSVec64<3>;
    let seed = |j: usize| D::from_re(0.0).derivative(j);
    let eta = Vector3::new(seed(0), seed(1), seed(2));
    let m = moment(&(flexmech_core::rotation::exp(&eta) * r_end.map(D::from_re)));
    let mut k = Matrix3::zeros();
    for c in 0..3 {
        k.set_row(c, &m[c].eps.unwrap_generic(Const::<3>, U1).transpose());
    }
    (m.map(|v| v.re), k)
}

/// Tangent positions per translational mass entry `(i, j, m)` (its block
/// is `c(m) I`: the diagonal's positions only) and per node's rotational
/// inertia (`None` where a slave is involved: its maps change with the
/// iterate, and the block goes through them).
pub(crate) struct MassSlots {
    translational: Vec<Option<Vec<usize>>>,
    rotational: Vec<Option<Vec<(usize, usize, usize)>>>,
}

impl MassSlots {
    pub(crate) fn new(asm: &Assembler, dofs: &DofMap, inertia: &Inertia) -> Self {
        Self {
            translational: inertia
                .mass
                .iter()
                .map(|&(i, j, _)| {
                    asm.node_block_slots(dofs, (i, 0), (j, 0)).map(|slots| {
                        slots
                            .into_iter()
                            .filter(|&(_, a, b)| a == b)
                            .map(|(p, _, _)| p)
                            .collect()
                    })
                })
                .collect(),
            rotational: (0..inertia.rotational.len())
                .map(|i| asm.node_block_slots(dofs, (i, 3), (i, 3)))
                .collect(),
        }
    }

    /// Adds `c I` for mass entry `k = (i, j, m)` (translations of `i`, `j`).
    pub(crate) fn add_translational(
        &self,
        asm: &mut Assembler,
        dofs: &DofMap,
        k: usize,
        (i, j): (usize, usize),
        c: f64,
    ) {
        match &self.translational[k] {
            Some(diagonal) => {
                if c != 0.0 {
                    for &p in diagonal {
                        asm.values[p] += c;
                    }
                }
            }
            None => asm.add_node_block(dofs, (i, 0), (j, 0), &(Matrix3::identity() * c)),
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
    /// `force(j, m)` is the force of mass entry `(i, j, m)` on node `i`,
    /// whose derivative with respect to node `j`'s translation is
    /// `coefficient(m)·I`; `moment(i, J₀, tangent)` is node `i`'s inertial
    /// moment and its derivative under a spin of its end rotation (nodes
    /// without rotary inertia are skipped).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn add_inertia(
        &self,
        inertia: &Inertia,
        g: &mut [f64],
        abs: &mut [f64],
        mut tangent: Option<(&mut Assembler, &DofMap)>,
        force: impl Fn(usize, f64) -> Vector3<f64>,
        coefficient: impl Fn(f64) -> f64,
        moment: impl Fn(usize, &Matrix3<f64>, bool) -> (Vector3<f64>, Matrix3<f64>),
    ) {
        for (k, &(i, j, m)) in inertia.mass.iter().enumerate() {
            let f = force(j, m);
            for c in 0..3 {
                g[6 * i + c] += f[c];
                abs[6 * i + c] += f[c].abs();
            }
            if let Some((asm, dofs)) = tangent.as_mut() {
                self.add_translational(asm, dofs, k, (i, j), coefficient(m));
            }
        }
        for (i, j0) in inertia.rotational.iter().enumerate() {
            if *j0 == Matrix3::zeros() {
                continue;
            }
            let (m, k) = moment(i, j0, tangent.is_some());
            for c in 0..3 {
                g[6 * i + 3 + c] += m[c];
                abs[6 * i + 3 + c] += m[c].abs();
            }
            if let Some((asm, dofs)) = tangent.as_mut() {
                self.add_rotational(asm, dofs, i, &k);
            }
        }
    }
}
