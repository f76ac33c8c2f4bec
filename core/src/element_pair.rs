//! The 2-node element's internal force of two elements at once, one element
//! in each lane of a pair of doubles ([`crate::rotation_pair`]): the
//! arithmetic of [`BeamElement::internal_force`] in the same order, with no
//! fused products and the series/`sin`/`cot` coefficients called lane by
//! lane, so each lane holds the bits of the one-element force (tested). The
//! residual-only evaluations of a mesh go through [`for_each_internal_force`].

use crate::element::BeamElement;
use crate::mesh::{gather_into, gather_rotations_into, Element, RelativeRotations};
use crate::rotation_pair::{
    cross, exp, lane, log_pair, mat_mat, mat_t_mat, mat_t_vec, mat_vec, matrices, pair, scale,
    splat, tangent, tangent_inverse, vectors, M2, V2,
};
use nalgebra::{Matrix3, SVector, Vector3};
use wide::f64x2;

/// The most unknowns of an element, the length of the largest element
/// force (a 3-node element's).
pub const MOST_DOFS: usize = 18;

/// Two elements' nodal triads `Λᵢ = Rᵢ Λ₀ᵢ` as pairs, node by node.
pub(crate) fn triads(e: [&BeamElement<2>; 2], rot: [&[Matrix3<f64>; 2]; 2]) -> [M2; 2] {
    [0, 1].map(|i| {
        let r = matrices([&rot[0][i], &rot[1][i]]);
        mat_mat(&r, &matrices([&e[0].lambda0[i], &e[1].lambda0[i]]))
    })
}

fn component_mul(v: &V2, w: [&Vector3<f64>; 2]) -> V2 {
    let w = vectors(w);
    std::array::from_fn(|i| v[i] * w[i])
}

/// [`BeamElement::internal_force`] of two elements with their nodes'
/// positions `x[k]` and rotations `rot[k]`, `k` the element.
pub fn internal_force_pair(
    e: [&BeamElement<2>; 2],
    x: &[[Vector3<f64>; 2]; 2],
    rot: &[[Matrix3<f64>; 2]; 2],
) -> [SVector<f64, 12>; 2] {
    let lam = triads(e, [&rot[0], &rot[1]]);
    let l = pair(e[0].length, e[1].length);
    let half = splat(0.5);
    let phi = log_pair(&mat_t_mat(&lam[0], &lam[1]));
    let lam_r = mat_mat(&lam[0], &exp(&scale(&phi, half)));
    let d = vectors([&(x[0][1] - x[0][0]), &(x[1][1] - x[1][0])]);
    let s0 = [0, 1].map(|k| e[k].initial_strains()[0]);
    let (g0, k0) = (vectors([&s0[0].0, &s0[1].0]), vectors([&s0[0].1, &s0[1].1]));
    let rd = mat_t_vec(&lam_r, &d);
    let gam: V2 = std::array::from_fn(|i| rd[i] / l - g0[i]);
    let kap: V2 = std::array::from_fn(|i| phi[i] / l - k0[i]);
    let n = mat_vec(
        &lam_r,
        &component_mul(&gam, [&e[0].section.c_n, &e[1].section.c_n]),
    );
    let c = cross(&n, &d);
    let minus_phi = phi.map(|v| -v);
    let hinv_t = tangent_inverse(&minus_phi);
    let km = component_mul(&kap, [&e[0].section.c_m, &e[1].section.c_m]);
    let m_tilde = mat_vec(&lam[0], &mat_vec(&hinv_t, &km));
    let h = tangent(&scale(&minus_phi, half));
    let inner = mat_vec(&h, &mat_t_vec(&lam[0], &c));
    let b = scale(&mat_vec(&lam[0], &mat_vec(&hinv_t, &inner)), half);
    let blocks: [V2; 4] = [
        n.map(|v| -v),
        std::array::from_fn(|i| c[i] - b[i] - m_tilde[i]),
        n,
        std::array::from_fn(|i| b[i] + m_tilde[i]),
    ];
    [0, 1].map(|k| SVector::<f64, 12>::from_fn(|r, _| lane_of(blocks[r / 3][r % 3], k)))
}

#[inline]
fn lane_of(v: f64x2, k: usize) -> f64 {
    v.to_array()[k]
}

/// `two(i, a, b)` for the 2-node elements `i` and `i + 1` next to each
/// other, `one(i, element)` for the others: every element once, in order.
fn in_pairs(
    elements: &[Element],
    mut two: impl FnMut(usize, &BeamElement<2>, &BeamElement<2>),
    mut one: impl FnMut(usize, &Element),
) {
    let mut i = 0;
    while i < elements.len() {
        if let (Element::Linear(a), Some(Element::Linear(b))) = (&elements[i], elements.get(i + 1))
        {
            two(i, a, b);
            i += 2;
        } else {
            one(i, &elements[i]);
            i += 1;
        }
    }
}

/// `sink(index, element, force)` for every element of `elements`, in
/// order, with its internal force ([`Element::internal_force_into`]) at the
/// nodes' positions `x` and rotations `rot`: two 2-node elements next to
/// each other at a time ([`internal_force_pair`]), the same bits.
pub fn for_each_internal_force(
    elements: &[Element],
    x: &[Vector3<f64>],
    rot: &[Matrix3<f64>],
    sink: impl FnMut(usize, &Element, &[f64]),
) {
    let sink = std::cell::RefCell::new(sink);
    let mut buf = [0.0; MOST_DOFS];
    in_pairs(
        elements,
        |i, a, b| {
            let (mut xx, mut rr) = ([[Vector3::zeros(); 2]; 2], [[Matrix3::zeros(); 2]; 2]);
            gather_into(&a.nodes, x, rot, &mut xx[0], &mut rr[0]);
            gather_into(&b.nodes, x, rot, &mut xx[1], &mut rr[1]);
            let [fa, fb] = internal_force_pair([a, b], &xx, &rr);
            let mut sink = sink.borrow_mut();
            sink(i, &elements[i], fa.as_slice());
            sink(i + 1, &elements[i + 1], fb.as_slice());
        },
        |i, el| {
            let r = &mut buf[..el.dofs()];
            el.internal_force_into(x, rot, r);
            sink.borrow_mut()(i, el, r);
        },
    );
}

/// The relative rotations `log(Λ₁ᵀΛ₂)` of two 2-node elements' nodal
/// triads at the nodes' rotations `rot[k]`, `k` the element (the
/// logarithm of [`Element::relative_rotations`], two at a time).
pub fn relative_rotation_pair(e: [&BeamElement<2>; 2], rot: &[[Matrix3<f64>; 2]; 2]) -> V2 {
    let lam = triads(e, [&rot[0], &rot[1]]);
    log_pair(&mat_t_mat(&lam[0], &lam[1]))
}

/// Every element's [`Element::relative_rotations`] at the nodes' rotations
/// `rot`, two 2-node elements next to each other at a time: the same bits.
pub fn relative_rotations_of(elements: &[Element], rot: &[Matrix3<f64>]) -> Vec<RelativeRotations> {
    let mut all = Vec::with_capacity(elements.len());
    relative_rotations_into(elements, rot, &mut all);
    all
}

/// [`relative_rotations_of`] appended to `out` (whose allocation a caller
/// keeps from one state to the next).
pub fn relative_rotations_into(
    elements: &[Element],
    rot: &[Matrix3<f64>],
    out: &mut Vec<RelativeRotations>,
) {
    let all = std::cell::RefCell::new(out);
    in_pairs(
        elements,
        |_, a, b| {
            let mut rr = [[Matrix3::zeros(); 2]; 2];
            gather_rotations_into(&a.nodes, rot, &mut rr[0]);
            gather_rotations_into(&b.nodes, rot, &mut rr[1]);
            let phi = relative_rotation_pair([a, b], &rr);
            let mut all = all.borrow_mut();
            all.extend([0, 1].map(|k| RelativeRotations::one(lane(&phi, k))));
        },
        |_, el| all.borrow_mut().push(el.relative_rotations(rot)),
    );
}

#[cfg(test)]
pub(crate) mod tests {
    use super::{for_each_internal_force, internal_force_pair, relative_rotations_of};
    use crate::element::BeamElement;
    use crate::mesh::Element;
    use crate::rotation::exp;
    use crate::Section;
    use nalgebra::Vector3;
    use proptest::prelude::*;

    /// A curved (`tilt`), prestrained element of `length`.
    pub(crate) fn element(length: f64, tilt: [f64; 3], prestrain: f64) -> BeamElement<2> {
        let section = Section::new(
            [1.0e7, 5.0e6, 4.0e6],
            [7.0e5, 8.0e5, 8.3e5],
            1.0,
            [0.2, 0.1, 0.1],
        );
        let x0 = [Vector3::zeros(), Vector3::new(length, 0.0, 0.0)];
        let l0 = [
            exp(&Vector3::from(tilt)),
            exp(&(Vector3::from(tilt) * (1.0 + prestrain))),
        ];
        BeamElement::new([0, 1], section, length, &x0, l0)
    }

    /// A mesh of 2-node elements (an odd count, so one goes alone) at
    /// large rotations: the paired loops give every element's force and
    /// relative rotation as the element alone does.
    #[test]
    fn the_paired_loops_equal_the_elements_one_at_a_time() {
        let n = 5;
        let elements: Vec<Element> = (0..n)
            .map(|i| {
                let mut e = element(0.3 + 0.1 * i as f64, [0.1 * i as f64, -0.2, 0.3], 0.05);
                e.nodes = [i, i + 1];
                Element::Linear(e)
            })
            .collect();
        let x: Vec<Vector3<f64>> = (0..=n)
            .map(|i| Vector3::new(0.4 * i as f64, 0.01 * (i * i) as f64, 0.0))
            .collect();
        let rot: Vec<_> = (0..=n)
            .map(|i| exp(&Vector3::new(0.7 * i as f64, 0.2, -0.4 * i as f64)))
            .collect();
        let mut seen = 0;
        for_each_internal_force(&elements, &x, &rot, |i, el, f| {
            let mut one = vec![0.0; el.dofs()];
            el.internal_force_into(&x, &rot, &mut one);
            assert!(
                one.iter().zip(f).all(|(a, b)| a.to_bits() == b.to_bits()),
                "element {i}"
            );
            assert_eq!(i, seen);
            seen += 1;
        });
        assert_eq!(seen, n);
        let all = relative_rotations_of(&elements, &rot);
        assert_eq!(all.len(), n);
        for (el, r) in elements.iter().zip(&all) {
            let one = el.relative_rotations(&rot);
            assert!(one.iter().zip(r.iter()).all(|(a, b)| a
                .iter()
                .zip(b.iter())
                .all(|(p, q)| p.to_bits() == q.to_bits())));
        }
    }

    /// Two elements (`tilt`, `lengths`, the second prestrained) and their
    /// nodes' positions (moved by `moves`) and rotations (turned from
    /// `dirs[2k]` by `dirs[2k + 1]` scaled by `10^scales[k]`): the property
    /// tests' pairs.
    pub(crate) fn two_elements(
        dirs: [[f64; 3]; 4],
        scales: [f64; 2],
        tilt: [[f64; 3]; 2],
        moves: [[f64; 3]; 4],
        lengths: [f64; 2],
    ) -> Pair {
        let e = [0, 1].map(|k| element(lengths[k], tilt[k], 0.1 * k as f64));
        let rot = [0, 1].map(|k| {
            let base = exp(&Vector3::from(dirs[2 * k]));
            [
                base,
                exp(&(Vector3::from(dirs[2 * k + 1]) * 10f64.powf(scales[k]))) * base,
            ]
        });
        let x = [0, 1].map(|k| {
            let end = Vector3::new(lengths[k], 0.0, 0.0) + Vector3::from(moves[2 * k + 1]);
            [Vector3::from(moves[2 * k]), end]
        });
        (e, x, rot)
    }

    /// [`two_elements`] over the property tests' ranges: relative rotations
    /// from 10⁻⁵ rad to past 120°, curved elements of 0.1 to 2 length units.
    pub(crate) fn pairs() -> impl Strategy<Value = Pair> {
        (
            prop::array::uniform4(prop::array::uniform3(-1.0..1.0f64)),
            prop::array::uniform2(-5.0..0.4f64),
            prop::array::uniform2(prop::array::uniform3(-0.5..0.5f64)),
            prop::array::uniform4(prop::array::uniform3(-0.3..0.3f64)),
            prop::array::uniform2(0.1..2.0f64),
        )
            .prop_map(|(d, s, t, m, l)| two_elements(d, s, t, m, l))
    }

    /// Two elements with their nodes' positions and rotations.
    pub(crate) type Pair = (
        [BeamElement<2>; 2],
        [[Vector3<f64>; 2]; 2],
        [[nalgebra::Matrix3<f64>; 2]; 2],
    );

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(512))]

        /// Each lane holds the bits of the one-element force, on every
        /// branch: relative rotations from 10⁻⁵ rad (series of `exp`, `H`
        /// and `H⁻¹`, of the logarithm) to past 120° (the logarithm's
        /// quaternion not read from the trace), lanes on different branches,
        /// curved and prestrained elements.
        #[test]
        fn a_pair_gives_the_bits_of_one_element_at_a_time((e, x, rot) in pairs()) {
            let both = internal_force_pair([&e[0], &e[1]], &x, &rot);
            for k in 0..2 {
                let one = e[k].internal_force(&x[k], &rot[k]);
                prop_assert!(one.iter().zip(both[k].iter()).all(|(a, b)| a.to_bits() == b.to_bits()), "lane {k}");
            }
        }
    }
}
