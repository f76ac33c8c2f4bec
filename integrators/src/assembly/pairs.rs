//! The one-thread tangent assembly of [`Assembler::assemble`] with two
//! neighbouring 2-node elements whose nodes are all independent evaluated
//! at once ([`residual_tangent_pair_at`], each lane the one-element bits),
//! every element's forces and tangent summed in element order as the
//! element-by-element loop sums them.

use super::{
    add_forces, add_run, add_tangent, reduce_tangent, scratch_for, Assembler, PairKernel, Sinks,
    Slots,
};
use crate::dofs::DofMap;
use flexmech_core::element_tangent_pair::residual_tangent_pair_at;
use flexmech_core::{BeamElement, Configuration, Element, Mesh};
use std::time::Instant;

/// The unknowns of a 2-node element.
const DOFS: usize = 12;

/// Elements `i` and `i + 1` when both are 2-node elements whose tangents
/// go straight into the values ([`Slots::direct`]).
pub(super) fn direct_pair<'a>(
    elements: &'a [Element],
    slots: &[Slots],
    i: usize,
) -> Option<[&'a BeamElement<2>; 2]> {
    let (Element::Linear(a), Some(Element::Linear(b))) = (&elements[i], elements.get(i + 1)) else {
        return None;
    };
    (slots[i].direct.is_some() && slots[i + 1].direct.is_some()).then_some([a, b])
}

/// Evaluates two neighbouring direct 2-node elements `els` (the mesh's
/// `elements`, slots `s`) by `pair` and adds them to `sinks`, the first
/// first.
///
/// # Safety
/// As for [`Sinks::add`]: the caller's chunk owns everything both add to.
pub(super) unsafe fn add_pair(
    sinks: &Sinks<'_>,
    pair: &PairKernel,
    (els, elements): ([&BeamElement<2>; 2], [&Element; 2]),
    s: [&Slots; 2],
) {
    let (mut r, mut k) = ([[0.0; DOFS]; 2], [[0.0; DOFS * DOFS]; 2]);
    let ([r0, r1], [k0, k1]) = (&mut r, &mut k);
    pair(els, [r0, r1], [k0, k1]);
    for j in 0..2 {
        // SAFETY: by the caller's contract.
        unsafe { sinks.add_direct(elements[j], &r[j], &k[j], s[j]) };
    }
}

/// Adds the tangent `k` of an element with direct runs `s` to `values`.
fn add_direct_tangent(values: &mut [f64], k: &[f64], s: &Slots) {
    for &(e, p, len, first) in s.direct.iter().flatten() {
        add_run(&mut values[p..p + len], &k[e..e + len], first);
    }
}

impl Assembler {
    /// [`Assembler::assemble`] on one thread, two neighbouring direct
    /// 2-node elements at a time; each element is summed as soon as it is
    /// evaluated, from buffers that stay in cache.
    pub(super) fn assemble_in_pairs(&mut self, mesh: &Mesh, dofs: &DofMap, config: &Configuration) {
        let n = mesh.elements.len();
        let start = self.tangent_cost.probing(n).then(Instant::now);
        if self.any_reduced {
            self.own_work(mesh);
        }
        self.clear();
        let Self {
            slots,
            scratch,
            work,
            values,
            nodal,
            nodal_abs,
            ..
        } = self;
        let (x, rot) = (&config.x[..], &config.rot[..]);
        let (mut r, mut k) = ([[0.0; DOFS]; 2], [[0.0; DOFS * DOFS]; 2]);
        let mut i = 0;
        while i < n {
            if let Some(pair) = direct_pair(&mesh.elements, slots, i) {
                let ([r0, r1], [k0, k1]) = (&mut r, &mut k);
                residual_tangent_pair_at(pair, x, rot, [r0, r1], [k0, k1]);
                for j in 0..2 {
                    add_forces(nodal, nodal_abs, &mesh.elements[i + j], &r[j]);
                    add_direct_tangent(values, &k[j], &slots[i + j]);
                }
                i += 2;
                continue;
            }
            let (el, s) = (&mesh.elements[i], &slots[i]);
            let w = match &s.direct {
                Some(_) => scratch_for(scratch, el.dofs()),
                None => &mut work[i],
            };
            el.residual_tangent(x, rot, w.r.as_mut_slice(), w.k.as_mut_slice());
            if s.direct.is_none() {
                reduce_tangent(w, el, dofs, s);
            }
            add_forces(nodal, nodal_abs, el, w.r.as_slice());
            add_tangent(values, w, s);
            i += 1;
        }
        if let Some(start) = start {
            self.tangent_cost.record(start.elapsed(), n);
        }
    }
}
