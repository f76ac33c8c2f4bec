//! Two neighbouring 2-node elements whose nodes are all independent,
//! evaluated at once by a pair kernel (each lane the one-element bits) in
//! the tangent assembly's loops, their forces and tangents summed in element
//! order as the element-by-element loop sums them.

use super::{PairKernel, Sinks, Slots};
use flexmech_core::{BeamElement, Element};

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
/// `elements` `index` and `index + 1`, slots `s`) by `pair` and adds them
/// to `sinks`, the first first.
///
/// # Safety
/// As for [`Sinks::add`]: the caller's chunk owns everything both add to.
pub(super) unsafe fn add_pair(
    sinks: &Sinks<'_>,
    pair: &PairKernel,
    (index, els, elements): (usize, [&BeamElement<2>; 2], [&Element; 2]),
    s: [&Slots; 2],
) {
    let (mut r, mut k) = ([[0.0; DOFS]; 2], [[0.0; DOFS * DOFS]; 2]);
    let ([r0, r1], [k0, k1]) = (&mut r, &mut k);
    pair(index, els, [r0, r1], [k0, k1]);
    for j in 0..2 {
        // SAFETY: by the caller's contract.
        unsafe { sinks.add_direct(elements[j], &r[j], &k[j], s[j]) };
    }
}
