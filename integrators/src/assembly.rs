//! Assembly of the reduced residual and tangent.
//!
//! Structure once, numbers every iteration: the sparsity pattern and every
//! element's positions in the value array are computed when the assembler is
//! built. Each call evaluates the element kernels, reduces them with the
//! node maps (`Gᵀ K G`, `Gᵀ r`) and sums them in element order. With more
//! than one thread, and kernels costly enough to gain from it
//! ([`crate::threads::LoopCost`]), the elements are cut into contiguous
//! chunks evaluated in parallel, each summing straight into the values it
//! owns (see the `element_split` module) — every sum is still formed in
//! element order, so the result is bitwise the same for any number of
//! threads.

use crate::dofs::DofMap;
use crate::sparsity::symmetric_pattern;
use faer::sparse::SymbolicSparseColMat;
use flexmech_core::element_pair::{for_each_internal_force, MOST_DOFS};
use flexmech_core::element_tangent_pair::residual_tangent_pair_at;
use flexmech_core::{BeamElement, Configuration, Element, Inertia, Mesh};
use nalgebra::{DMatrix, DVector, Matrix3, Vector6};

use crate::element_split::{Shared, Split};
use crate::threads::LoopCost;
use std::ops::Range;
use std::time::Instant;

mod pairs;

/// A kernel of two neighbouring 2-node elements, the mesh's `index` and
/// `index + 1`: their residuals and tangents (column-major) into the two
/// pairs of buffers.
pub(crate) type PairKernel<'a> =
    dyn Fn(usize, [&BeamElement<2>; 2], [&mut [f64]; 2], [&mut [f64]; 2]) + Sync + 'a;

struct Slots {
    /// Sorted, unique global equations the element touches.
    eqs: Vec<usize>,
    /// Position in the CSC value array of local pair (i, j), column-major `j·m + i`.
    pos: Vec<usize>,
    /// For an element whose nodes are all independent (no joint touches
    /// it: every node map column is a unit vector), its reduced tangent is a
    /// gather of the element tangent, with no products with node maps: runs
    /// `(first entry of the element tangent (column-major), first position
    /// in the CSC value array, length)` over which both advance by one, so
    /// that the tangent is summed into the values straight from the kernel's
    /// buffer, a run at a time (a chain's element has one run of 12 per
    /// column), one addition per position as through `pos` (so the sums are
    /// bitwise the same). The fourth member is whether the element writes
    /// the run's positions first ([`Slots::first`], the same for the whole
    /// run).
    direct: Option<Vec<DirectRun>>,
    /// Whether this element is the first, in element order, to add to each
    /// position of `pos`: it stores its value there instead of adding it
    /// to a zero (the same bits but for the sign of a zero), so the values
    /// need no zeroing before an assembly ([`Assembler::untouched`]).
    first: Vec<bool>,
}

/// A run of [`Slots::direct`]: `(first entry of the element tangent, first
/// position in the values, length, written first)`.
type DirectRun = (usize, usize, usize, bool);

/// An element's `(element dof, local index)` pairs, or `None` where a joint
/// touches it (see [`direct_pairs`]).
type DirectPairs = Option<Vec<(usize, usize)>>;

/// The `(element dof, local index)` pairs of an element whose nodes are all
/// independent (see [`Slots::direct`]; the local index is into the sorted
/// equation list `eqs`), or `None`.
fn direct_pairs(el: &Element, dofs: &DofMap, eqs: &[usize]) -> Option<Vec<(usize, usize)>> {
    let mut pairs = Vec::with_capacity(eqs.len());
    for (a, &nd) in el.nodes().iter().enumerate() {
        let map = &dofs.nodes[nd];
        for (eq, &d) in map.eqs.iter().zip(dofs.own_dofs(nd)?) {
            pairs.push((6 * a + usize::from(d), eqs.binary_search(eq).ok()?));
        }
    }
    (pairs.len() == eqs.len()).then_some(pairs)
}

/// Every element's slots (its sorted, unique equations; positions still to
/// be found) and its direct pairs ([`direct_pairs`]).
fn element_slots(mesh: &Mesh, dofs: &DofMap) -> (Vec<Slots>, Vec<DirectPairs>) {
    let mut slots = Vec::with_capacity(mesh.elements.len());
    let mut direct = Vec::with_capacity(mesh.elements.len());
    for el in &mesh.elements {
        let mut eqs: Vec<usize> = el
            .nodes()
            .iter()
            .flat_map(|&nd| dofs.nodes[nd].eqs.iter().copied())
            .collect();
        eqs.sort_unstable();
        eqs.dedup();
        direct.push(direct_pairs(el, dofs, &eqs));
        slots.push(Slots {
            eqs,
            pos: Vec::new(),
            direct: None,
            first: Vec::new(),
        });
    }
    (slots, direct)
}

/// The slots of the extra dense blocks over the equation lists `blocks`
/// (positions still to be found).
fn block_slots(blocks: &[Vec<usize>]) -> Vec<Slots> {
    blocks
        .iter()
        .map(|eqs| Slots {
            eqs: eqs.clone(),
            pos: Vec::new(),
            direct: None,
            first: Vec::new(),
        })
        .collect()
}

/// The positions in the CSC value array of the pattern `(col_ptr, row_idx)`
/// of every pair `(eqs[i], eqs[j])`, column-major `j·m + i` ([`Slots::pos`]):
/// `eqs` and each column's rows are sorted, so one walk down the column
/// finds them all (step by step: a column holds a few dozen rows, where a
/// binary search for each of the element's rows cost more than the walk).
fn value_positions(eqs: &[usize], col_ptr: &[usize], row_idx: &[usize]) -> Vec<usize> {
    let m = eqs.len();
    let mut pos = Vec::with_capacity(m * m);
    for &cj in eqs {
        let rows = &row_idx[col_ptr[cj]..col_ptr[cj + 1]];
        let mut p = 0;
        for &ri in eqs {
            while rows.get(p).is_some_and(|&r| r < ri) {
                p += 1;
            }
            assert!(
                rows.get(p) == Some(&ri),
                "pattern contains every element pair"
            );
            pos.push(col_ptr[cj] + p);
        }
    }
    pos
}

/// The runs of [`Slots::direct`] for an element of `d` unknowns whose nodes
/// are all independent, from its direct `pairs`, positions `s.pos` and
/// first writes `s.first`.
fn direct_runs(pairs: &[(usize, usize)], d: usize, s: &Slots) -> Vec<DirectRun> {
    let m = s.eqs.len();
    let mut runs: Vec<DirectRun> = Vec::new();
    for &(ec, lc) in pairs {
        for &(er, lr) in pairs {
            let (e, p, first) = (ec * d + er, s.pos[lc * m + lr], s.first[lc * m + lr]);
            match runs.last_mut() {
                Some((e0, p0, len, f0)) if *e0 + *len == e && *p0 + *len == p && *f0 == first => {
                    *len += 1
                }
                _ => runs.push((e, p, 1, first)),
            }
        }
    }
    runs
}

/// Marks each element's first writes ([`Slots::first`]), in element order,
/// and returns the ranges of the `n` values no element writes.
fn first_writes(slots: &mut [Slots], n: usize) -> Vec<Range<usize>> {
    let mut written = vec![false; n];
    for s in slots.iter_mut() {
        s.first = s
            .pos
            .iter()
            .map(|&p| !std::mem::replace(&mut written[p], true))
            .collect();
    }
    let mut untouched: Vec<Range<usize>> = Vec::new();
    for (p, _) in written.iter().enumerate().filter(|(_, &w)| !w) {
        match untouched.last_mut() {
            Some(r) if r.end == p => r.end += 1,
            _ => untouched.push(p..p + 1),
        }
    }
    untouched
}

/// One scratch buffer per element kind (number of unknowns) of `mesh`, for
/// the one-thread path ([`scratch_for`]).
fn kind_scratch(mesh: &Mesh) -> Vec<Work> {
    let mut scratch: Vec<Work> = Vec::new();
    for el in &mesh.elements {
        let d = el.dofs();
        if scratch.iter().all(|w| w.r.len() != d) {
            scratch.push(Work::new(d, 0));
        }
    }
    scratch
}

struct Work {
    r: DVector<f64>,
    k: DMatrix<f64>,
    tmp: DMatrix<f64>,
    k_red: DMatrix<f64>,
}

impl Work {
    /// Buffers for an element of `d` unknowns over `m` equations.
    fn new(d: usize, m: usize) -> Self {
        Self {
            r: DVector::zeros(d),
            k: DMatrix::zeros(d, d),
            tmp: DMatrix::zeros(d, m),
            k_red: DMatrix::zeros(m, m),
        }
    }
}

/// Assembler bound to one mesh and one DOF map topology.
pub struct Assembler {
    pattern: SymbolicSparseColMat<usize>,
    slots: Vec<Slots>,
    /// Extra dense blocks (joints' configuration-dependent terms).
    blocks: Vec<Slots>,
    /// Every element's own buffers, made when first needed
    /// ([`Self::own_work`]): by an element a joint touches (its tangent is
    /// reduced through the node maps) and by the split loop.
    work: Vec<Work>,
    /// Whether a joint touches some element (its tangent is reduced
    /// through the node maps, in its own buffers).
    any_reduced: bool,
    /// One buffer per element kind (its number of unknowns) for the
    /// one-thread path, which sums each element as soon as it is evaluated.
    scratch: Vec<Work>,
    /// The split of the element loop over threads, made when first needed.
    split: Option<Split>,
    /// The split of the residual-only loop into two halves
    /// ([`Self::residual_in_halves`]; nodes only), made when first needed.
    halves: Option<Split>,
    /// One set of [`Self::scratch`] buffers per chunk of `split`.
    chunk_scratch: Vec<Vec<Work>>,
    /// Whether the residual-and-tangent loop is worth splitting.
    tangent_cost: LoopCost,
    /// Whether the residual-only loop is worth splitting.
    residual_cost: LoopCost,
    /// The ranges of [`Self::values`] no element writes, zeroed before an
    /// assembly (the others take their first element's value as it is,
    /// [`Slots::first`]).
    untouched: Vec<Range<usize>>,
    /// CSC values of the reduced tangent after [`Assembler::assemble`].
    pub values: Vec<f64>,
    /// Internal nodal forces, 6 per node (force, spatial moment).
    pub nodal: Vec<f64>,
    /// Sum of the absolute element contributions per nodal DOF — the scale of
    /// the internal forces, used to measure the residual relative to round-off.
    /// Every assembly zeroes it first, so a caller may take it (swap it out)
    /// after one.
    pub nodal_abs: Vec<f64>,
}

impl Assembler {
    /// Builds the pattern for `mesh` with the unknowns of `dofs`, plus one
    /// dense block over each equation list of `blocks` (added later with
    /// [`Assembler::add_block`]).
    pub fn new(mesh: &Mesh, dofs: &DofMap, blocks: &[Vec<usize>]) -> Self {
        let n = dofs.n_eq;
        let (mut slots, direct) = element_slots(mesh, dofs);
        let mut extra = block_slots(blocks);
        let lists: Vec<&[usize]> = slots.iter().chain(&extra).map(|s| &s.eqs[..]).collect();
        let (col_ptr, row_idx) = symmetric_pattern(n, &lists);
        for s in slots.iter_mut().chain(extra.iter_mut()) {
            s.pos = value_positions(&s.eqs, &col_ptr, &row_idx);
        }
        let untouched = first_writes(&mut slots, row_idx.len());
        for ((s, el), pairs) in slots.iter_mut().zip(&mesh.elements).zip(&direct) {
            if let Some(pairs) = pairs {
                s.direct = Some(direct_runs(pairs, el.dofs(), s));
            }
        }
        let nnz = row_idx.len();
        let pattern = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx);
        Self {
            pattern,
            slots,
            blocks: extra,
            work: Vec::new(),
            any_reduced: direct.iter().any(Option::is_none),
            scratch: kind_scratch(mesh),
            split: None,
            halves: None,
            chunk_scratch: Vec::new(),
            tangent_cost: LoopCost::default(),
            residual_cost: LoopCost::default(),
            untouched,
            values: vec![0.0; nnz],
            nodal: vec![0.0; 6 * mesh.node_count()],
            nodal_abs: vec![0.0; 6 * mesh.node_count()],
        }
    }

    /// The sparsity pattern of the reduced tangent.
    pub fn pattern(&self) -> &SymbolicSparseColMat<usize> {
        &self.pattern
    }

    /// Evaluates every element at `config`: fills [`Self::nodal`],
    /// [`Self::nodal_abs`] and the tangent [`Self::values`].
    /// Two neighbouring 2-node elements whose nodes are all independent
    /// are evaluated at once (`assembly/pairs.rs`), on one thread and in the
    /// chunks of a split loop: the same bits.
    pub fn assemble(&mut self, mesh: &Mesh, dofs: &DofMap, config: &Configuration) {
        let (x, rot) = (&config.x[..], &config.rot[..]);
        let pair = |_, e: [&BeamElement<2>; 2], r: [&mut [f64]; 2], k: [&mut [f64]; 2]| {
            residual_tangent_pair_at(e, x, rot, r, k)
        };
        let kernel = |el: &Element, _: usize, r: &mut [f64], k: &mut [f64]| {
            el.residual_tangent(x, rot, r, k)
        };
        self.assemble_paired(mesh, dofs, kernel, Some(&pair));
    }

    /// As [`Assembler::assemble`], with any element kernel: `kernel(element,
    /// index, r, k)` writes the element's residual (`6N`) and tangent
    /// (`6N × 6N`, column-major) with respect to its nodal increments.
    pub fn assemble_with<F>(&mut self, mesh: &Mesh, dofs: &DofMap, kernel: F)
    where
        F: Fn(&Element, usize, &mut [f64], &mut [f64]) + Sync,
    {
        self.assemble_paired(mesh, dofs, kernel, None);
    }

    /// [`Assembler::assemble_with`], two neighbouring direct 2-node elements
    /// at a time through `pair` where it is given (see [`Self::split_loop`]).
    pub(crate) fn assemble_paired<F>(
        &mut self,
        mesh: &Mesh,
        dofs: &DofMap,
        kernel: F,
        pair: Option<&PairKernel>,
    ) where
        F: Fn(&Element, usize, &mut [f64], &mut [f64]) + Sync,
    {
        let element = |w: &mut Work, index: usize, el: &Element, s: &Slots| {
            kernel(el, index, w.r.as_mut_slice(), w.k.as_mut_slice());
            if s.direct.is_none() {
                reduce_tangent(w, el, dofs, s);
            }
        };
        let n = mesh.elements.len();
        if !self.tangent_cost.split(n) {
            // One thread: each element is summed as soon as it is evaluated,
            // from a buffer that stays in cache (the same sums in the same
            // order as below).
            let start = self.tangent_cost.probing(n).then(Instant::now);
            if self.any_reduced {
                self.own_work(mesh);
            }
            self.clear();
            let mut index = 0;
            while index < n {
                let slots = &self.slots;
                if let Some((pair, els)) =
                    pair.zip(pairs::direct_pair(&mesh.elements, slots, index))
                {
                    let elements = [&mesh.elements[index], &mesh.elements[index + 1]];
                    let sinks = Sinks::new(&mut self.values, &mut self.nodal, &mut self.nodal_abs);
                    // SAFETY: one thread: nothing else touches the sinks.
                    unsafe {
                        pairs::add_pair(
                            &sinks,
                            pair,
                            (index, els, elements),
                            [&slots[index], &slots[index + 1]],
                        )
                    };
                    index += 2;
                    continue;
                }
                let (el, s) = (&mesh.elements[index], &slots[index]);
                let w = match &s.direct {
                    Some(_) => scratch_for(&mut self.scratch, el.dofs()),
                    None => &mut self.work[index],
                };
                element(w, index, el, s);
                add_forces(&mut self.nodal, &mut self.nodal_abs, el, w.r.as_slice());
                add_tangent(&mut self.values, w, s);
                index += 1;
            }
            if let Some(start) = start {
                self.tangent_cost.record(start.elapsed(), n);
            }
            return;
        }
        self.split_loop(mesh, true, pair, element);
    }

    /// The element loop over the chunks of [`Self::split`]: `evaluate(w,
    /// index, element, slots)` fills `w` (with `tangent`, the residual and
    /// the reduced tangent; otherwise the residual `w.r`), which is added to
    /// the nodal forces (and the tangent values) as [`crate::element_split`]
    /// says.
    /// `pair`: with the tangent, a kernel of two neighbouring 2-node
    /// elements ([`residual_tangent_pair_at`], the one-element bits), which
    /// two such elements of a chunk whose tangents go straight into the
    /// values and that are not late take instead of `evaluate`.
    fn split_loop<F>(&mut self, mesh: &Mesh, tangent: bool, pair: Option<&PairKernel>, evaluate: F)
    where
        F: Fn(&mut Work, usize, &Element, &Slots) + Sync,
    {
        self.split_for(mesh);
        if tangent {
            self.clear();
        } else {
            self.clear_forces();
        }
        let Self {
            slots,
            work,
            split: Some(split),
            chunk_scratch,
            values,
            nodal,
            nodal_abs,
            ..
        } = self
        else {
            return;
        };
        let sinks = Sinks::new(values, nodal, nodal_abs);
        let items = chunk_parts(work, split)
            .into_iter()
            .zip(chunk_scratch.iter_mut());
        crate::threads::for_each_item(items.collect(), |c, (part, scratch)| {
            let mut skip = false;
            for (w_own, index) in part.iter_mut().zip(split.chunks[c].clone()) {
                if std::mem::take(&mut skip) {
                    continue;
                }
                let in_chunk = split.chunks[c].contains(&(index + 1));
                let is_late = |i| split.is_late(i);
                if let Some((pair, els)) = pair
                    .filter(|_| tangent && in_chunk && !is_late(index) && !is_late(index + 1))
                    .zip(pairs::direct_pair(&mesh.elements, slots, index))
                {
                    // SAFETY: chunk `c` owns both elements' values and
                    // nodes (neither is late).
                    let elements = [&mesh.elements[index], &mesh.elements[index + 1]];
                    let s = [&slots[index], &slots[index + 1]];
                    unsafe { pairs::add_pair(&sinks, pair, (index, els, elements), s) };
                    skip = true;
                    continue;
                }
                let (el, s) = (&mesh.elements[index], &slots[index]);
                let late = split.is_late(index);
                // Late elements keep their output for the second phase;
                // reduced tangents need the element's own buffers.
                let w = if late || (tangent && s.direct.is_none()) {
                    w_own
                } else {
                    scratch_for(scratch, el.dofs())
                };
                evaluate(w, index, el, s);
                let s = tangent.then_some(s);
                // SAFETY: chunk `c` adds only what it owns (all of it
                // for an element that is not late).
                unsafe { sinks.add(el, w, s, late.then_some((split, c, true))) };
            }
        });
        for &index in &split.late {
            let c = split.chunk_of(index);
            let (el, s) = (&mesh.elements[index], tangent.then_some(&slots[index]));
            // SAFETY: the parallel phase is over.
            unsafe { sinks.add(el, &work[index], s, Some((split, c, false))) };
        }
    }

    /// Makes every element's own buffers ([`Self::work`]) if they are not.
    fn own_work(&mut self, mesh: &Mesh) {
        if self.work.is_empty() {
            self.work = (mesh.elements.iter().zip(&self.slots))
                .map(|(el, s)| Work::new(el.dofs(), s.eqs.len()))
                .collect();
        }
    }

    /// Makes [`Self::split`] for the current thread count if it is not.
    fn split_for(&mut self, mesh: &Mesh) {
        self.own_work(mesh);
        let threads = rayon::current_num_threads();
        if self.split.as_ref().is_some_and(|s| s.is_for(threads)) {
            return;
        }
        let split = Split::new(
            threads,
            self.values.len(),
            mesh.node_count(),
            self.slots
                .iter()
                .zip(&mesh.elements)
                .map(|(s, el)| (&s.pos[..], el.nodes())),
            mesh.elements.len(),
        );
        self.chunk_scratch = split
            .chunks
            .iter()
            .map(|_| {
                self.scratch
                    .iter()
                    .map(|w| Work::new(w.r.len(), 0))
                    .collect()
            })
            .collect();
        self.split = Some(split);
    }

    /// Zeroes the tangent values no element writes and the nodal forces
    /// (the elements' first writes store, [`Slots::first`]).
    fn clear(&mut self) {
        for r in &self.untouched {
            self.values[r.clone()].fill(0.0);
        }
        self.clear_forces();
    }

    /// Zeroes the nodal forces and their scale.
    fn clear_forces(&mut self) {
        self.nodal.iter_mut().for_each(|v| *v = 0.0);
        self.nodal_abs.iter_mut().for_each(|v| *v = 0.0);
    }

    /// The internal nodal forces only ([`Self::nodal`], [`Self::nodal_abs`];
    /// the tangent values are left as they were): for a residual check that
    /// no factorisation follows.
    /// On one thread, the 2-node elements' forces are computed two at a
    /// time ([`for_each_internal_force`]): the same bits.
    pub fn assemble_residual(&mut self, mesh: &Mesh, config: &Configuration) {
        let n = mesh.elements.len();
        if self.residual_cost.split(n) {
            return self.residual_in_halves(mesh, config);
        }
        let start = self.residual_cost.probing(n).then(Instant::now);
        self.clear_forces();
        let (nodal, nodal_abs) = (&mut self.nodal, &mut self.nodal_abs);
        for_each_internal_force(&mesh.elements, &config.x, &config.rot, |_, el, r| {
            add_forces(nodal, nodal_abs, el, r)
        });
        if let Some(start) = start {
            self.residual_cost.record(start.elapsed(), n);
        }
    }

    /// [`Self::assemble_residual`] on two threads: each half of the
    /// elements (cut at an even element) computes its forces two elements
    /// at a time and adds them to the nodes it owns as [`Split`] says (a
    /// late element keeps its forces in its own buffer for the nodes the
    /// first half owns, added afterwards): every sum in element order, as
    /// on one thread — the same bits.
    fn residual_in_halves(&mut self, mesh: &Mesh, config: &Configuration) {
        self.own_work(mesh);
        self.clear_forces();
        let els = &mesh.elements;
        let mid = (els.len() / 2) & !1;
        let halves = self.halves.get_or_insert_with(|| {
            let nodes = els.iter().map(|el| (&[][..], el.nodes()));
            let chunks = vec![0..mid, mid..els.len()];
            Split::with_chunks(chunks, 2, 0, mesh.node_count(), nodes)
        });
        let (first, second) = self.work.split_at_mut(mid);
        let sinks = Sinks::new(&mut [], &mut self.nodal, &mut self.nodal_abs);
        let items = vec![(&els[..mid], first), (&els[mid..], second)];
        crate::threads::for_each_item(items, |c, (part, work)| {
            let offset = halves.chunks[c].start;
            for_each_internal_force(part, &config.x, &config.rot, |i, el, r| {
                let late = halves.is_late(offset + i);
                if late {
                    work[i].r.as_mut_slice().copy_from_slice(r);
                }
                // SAFETY: half `c` adds only what it owns (all of it for an
                // element that is not late).
                unsafe { sinks.add_forces(el, r, late.then_some((&*halves, c, true))) };
            });
        });
        for &index in &halves.late {
            let only = Some((&*halves, halves.chunk_of(index), false));
            // SAFETY: the parallel phase is over.
            unsafe { sinks.add_forces(&els[index], self.work[index].r.as_slice(), only) };
        }
    }

    /// [`Self::assemble_residual`] with the element forces of `kernel`
    /// (element, its force out, ordered as the element's nodes).
    pub fn assemble_residual_with<F>(&mut self, mesh: &Mesh, kernel: F)
    where
        F: Fn(&Element, usize, &mut [f64]) + Sync,
    {
        self.assemble_residual_paired(mesh, |_, _, _| false, kernel);
    }

    /// [`Self::assemble_residual_with`] with a kernel for two neighbouring
    /// elements at once: `pair(index, [a, b], [ra, rb])` writes the forces
    /// of elements `index` and `index + 1` and returns `true`, or returns
    /// `false` (then `kernel` takes element `index` alone). On one thread
    /// only (a split loop takes `kernel`); the forces are summed in element
    /// order either way.
    pub fn assemble_residual_paired<P, F>(&mut self, mesh: &Mesh, pair: P, kernel: F)
    where
        P: Fn(usize, [&Element; 2], [&mut [f64]; 2]) -> bool,
        F: Fn(&Element, usize, &mut [f64]) + Sync,
    {
        let n = mesh.elements.len();
        if self.residual_cost.split(n) {
            return self.split_loop(mesh, false, None, |w, index, el, _| {
                kernel(el, index, w.r.as_mut_slice())
            });
        }
        let start = self.residual_cost.probing(n).then(Instant::now);
        self.clear_forces();
        let (els, nodal, abs) = (&mesh.elements, &mut self.nodal, &mut self.nodal_abs);
        let (mut a, mut b) = ([0.0; MOST_DOFS], [0.0; MOST_DOFS]);
        let mut i = 0;
        while i < n {
            let ra = &mut a[..els[i].dofs()];
            if let Some(next) = els.get(i + 1) {
                let rb = &mut b[..next.dofs()];
                if pair(i, [&els[i], next], [&mut *ra, &mut *rb]) {
                    add_forces(nodal, abs, &els[i], ra);
                    add_forces(nodal, abs, next, rb);
                    i += 2;
                    continue;
                }
            }
            kernel(&els[i], i, ra);
            add_forces(nodal, abs, &els[i], ra);
            i += 1;
        }
        if let Some(start) = start {
            self.residual_cost.record(start.elapsed(), n);
        }
    }

    /// Adds the dense matrix `m` (column-major over block `b`'s equations) to
    /// the tangent values.
    pub fn add_block(&mut self, b: usize, m: &DMatrix<f64>) {
        for (&p, &v) in self.blocks[b].pos.iter().zip(m.as_slice()) {
            self.values[p] += v;
        }
    }

    /// Adds the mass `inertia` at the nodal rotations `rot` through the node
    /// maps: `m_ij I` on the translations, `R J₀ Rᵀ` on the spatial spins
    /// (the reduced `NᵀMN` of the initial accelerations and of the modes).
    pub fn add_mass(&mut self, dofs: &DofMap, inertia: &Inertia, rot: &[Matrix3<f64>]) {
        for &(i, j, m) in &inertia.mass {
            self.add_node_block(dofs, (i, 0), (j, 0), &(Matrix3::identity() * m));
        }
        for (i, j0) in inertia.rotational.iter().enumerate() {
            let r = rot[i];
            self.add_node_block(dofs, (i, 3), (i, 3), &(r * j0 * r.transpose()));
        }
    }

    /// Adds the 3×3 block `k` — rows: components `ri..ri+3` of node `i`'s
    /// increment, columns: `cj..cj+3` of node `j`'s — to the tangent through
    /// the node maps (`T_iᵀ k T_j`, e.g. a mass or inertia block).
    pub fn add_node_block(
        &mut self,
        dofs: &DofMap,
        (i, ri): (usize, usize),
        (j, cj): (usize, usize),
        k: &Matrix3<f64>,
    ) {
        let (mi, mj) = (&dofs.nodes[i], &dofs.nodes[j]);
        for (ei, ci) in mi.eqs.iter().zip(mi.rows()) {
            for (ej, cjv) in mj.eqs.iter().zip(&mj.cols) {
                let v = ci.fixed_rows::<3>(ri).dot(&(k * cjv.fixed_rows::<3>(cj)));
                if v != 0.0 {
                    self.add_entry(*ei, *ej, v);
                }
            }
        }
    }

    /// Where [`Self::add_node_block`] of two independent nodes lands:
    /// `(value position, a, b)` triples such that the block `k` adds
    /// `k[(a, b)]` at each position — found once, so that a constant block
    /// (a mass) is added every iteration without searching the pattern.
    /// `None` when either node is a slave (its maps change with the
    /// configuration).
    pub fn node_block_slots(
        &self,
        dofs: &DofMap,
        (i, ri): (usize, usize),
        (j, cj): (usize, usize),
    ) -> Option<Vec<(usize, usize, usize)>> {
        let (mi, mj) = (&dofs.nodes[i], &dofs.nodes[j]);
        let (di, dj) = (dofs.own_dofs(i)?, dofs.own_dofs(j)?);
        let (cp, ri_idx) = (self.pattern.col_ptr(), self.pattern.row_idx());
        let mut out = Vec::new();
        for (ei, a) in mi.eqs.iter().zip(di.iter().map(|&a| usize::from(a))) {
            if !(ri..ri + 3).contains(&a) {
                continue;
            }
            for (ej, b) in mj.eqs.iter().zip(dj.iter().map(|&b| usize::from(b))) {
                if !(cj..cj + 3).contains(&b) {
                    continue;
                }
                let rows = &ri_idx[cp[*ej]..cp[*ej + 1]];
                let p = rows.binary_search(ei).ok()?;
                out.push((cp[*ej] + p, a - ri, b - cj));
            }
        }
        Some(out)
    }

    /// The diagonal of [`Self::node_block_slots`]' translational block
    /// (`ri = cj = 0`): the positions of the triples with `a = b`, in the
    /// same order, found without the others (a mass block is `m I`). `None`
    /// under the same conditions.
    pub fn node_block_diagonal(
        &self,
        dofs: &DofMap,
        i: usize,
        j: usize,
    ) -> Option<([usize; 3], usize)> {
        let (mi, mj) = (&dofs.nodes[i], &dofs.nodes[j]);
        let (di, dj) = (dofs.own_dofs(i)?, dofs.own_dofs(j)?);
        let (cp, ri_idx) = (self.pattern.col_ptr(), self.pattern.row_idx());
        let (mut out, mut len) = ([0; 3], 0);
        for (ei, &a) in mi.eqs.iter().zip(di) {
            if a >= 3 {
                continue;
            }
            for (ej, _) in mj.eqs.iter().zip(dj).filter(|&(_, &b)| b == a) {
                let rows = &ri_idx[cp[*ej]..cp[*ej + 1]];
                out[len] = cp[*ej] + rows.binary_search(ei).ok()?;
                len += 1;
            }
        }
        Some((out, len))
    }

    /// Adds the node block `k` at the positions of
    /// [`Self::node_block_slots`] (the same sums as
    /// [`Self::add_node_block`]).
    pub fn add_node_block_at(&mut self, slots: &[(usize, usize, usize)], k: &Matrix3<f64>) {
        for &(p, a, b) in slots {
            let v = k[(a, b)];
            if v != 0.0 {
                self.values[p] += v;
            }
        }
    }

    /// Adds `v` to the tangent entry (`row`, `col`), which must be in the
    /// pattern (any two equations of one element, or of one joint block).
    pub fn add_entry(&mut self, row: usize, col: usize, v: f64) {
        let (cp, ri) = (self.pattern.col_ptr(), self.pattern.row_idx());
        let rows = &ri[cp[col]..cp[col + 1]];
        let p = rows
            .binary_search(&row)
            .expect("entry in the sparsity pattern");
        self.values[cp[col] + p] += v;
    }
}

/// `Gᵀ K G` of an element some joint touches, from the kernel's `K` in
/// `w.k`, into `w.k_red` (`G` its node maps over the element's equations:
/// column `j` of `G` is, in each node block `a` whose map has equation `j`,
/// that map's column; the rows' map likewise with the maps' rows).
fn reduce_tangent(w: &mut Work, el: &Element, dofs: &DofMap, s: &Slots) {
    let entries = |rows: bool| {
        el.nodes().iter().enumerate().flat_map(move |(a, &nd)| {
            let map = &dofs.nodes[nd];
            let vectors = if rows { map.rows() } else { &map.cols[..] };
            map.eqs.iter().zip(vectors).map(move |(eq, v)| {
                let j = s
                    .eqs
                    .binary_search(eq)
                    .expect("element equation list is complete");
                (a, j, v)
            })
        })
    };
    map_columns(&w.k, entries(false), &mut w.tmp);
    map_rows(&w.tmp, entries(true), &mut w.k_red);
}

/// `t = K G` for `G` given by its entries `(node block a, column j, v)`
/// (column `j` holds `v` in rows `6a..6a + 6`): each entry's six columns of
/// `K` times `v`, its zeros skipped — no product over the zeros of `G`.
fn map_columns<'a>(
    k: &DMatrix<f64>,
    entries: impl Iterator<Item = (usize, usize, &'a Vector6<f64>)>,
    t: &mut DMatrix<f64>,
) {
    t.fill(0.0);
    for (a, j, v) in entries {
        for (c, &vc) in v.iter().enumerate() {
            if vc != 0.0 {
                t.column_mut(j).axpy(vc, &k.column(6 * a + c), 1.0);
            }
        }
    }
}

/// `out = Hᵀ t` for `H` given by its entries as in [`map_columns`].
fn map_rows<'a>(
    t: &DMatrix<f64>,
    entries: impl Iterator<Item = (usize, usize, &'a Vector6<f64>)>,
    out: &mut DMatrix<f64>,
) {
    out.fill(0.0);
    for (a, i, v) in entries {
        for (c, &vc) in v.iter().enumerate() {
            if vc != 0.0 {
                for j in 0..t.ncols() {
                    out[(i, j)] += vc * t[(6 * a + c, j)];
                }
            }
        }
    }
}

/// An element's forces `r` (6 per node, ordered as its nodes) as
/// `(node, its six forces)`.
fn force_blocks<'a>(el: &'a Element, r: &'a [f64]) -> impl Iterator<Item = (usize, &'a [f64])> {
    el.nodes()
        .iter()
        .enumerate()
        .map(move |(a, &nd)| (nd, &r[6 * a..6 * a + 6]))
}

/// Adds a node's six forces to its nodal forces and their absolute values
/// to the scale.
fn add_force_block(nodal: &mut [f64], nodal_abs: &mut [f64], f: &[f64]) {
    for ((n, a), v) in nodal.iter_mut().zip(nodal_abs.iter_mut()).zip(f) {
        *n += v;
        *a += v.abs();
    }
}

/// Adds an element's forces `r` to the nodal forces and scale.
fn add_forces(nodal: &mut [f64], nodal_abs: &mut [f64], el: &Element, r: &[f64]) {
    for (nd, f) in force_blocks(el, r) {
        add_force_block(
            &mut nodal[6 * nd..6 * nd + 6],
            &mut nodal_abs[6 * nd..6 * nd + 6],
            f,
        );
    }
}

/// An element's tangent as runs `(first position, values, written first)`:
/// straight from the kernel's buffer along the direct runs, or its reduced
/// tangent through `pos`, one entry a run.
fn tangent_runs<'a>(w: &'a Work, s: &'a Slots) -> impl Iterator<Item = (usize, &'a [f64], bool)> {
    let k = w.k.as_slice();
    let k_red = w.k_red.as_slice();
    let direct = s
        .direct
        .iter()
        .flatten()
        .map(move |&(e, p, len, first)| (p, &k[e..e + len], first));
    let reduced = if s.direct.is_some() {
        &[][..]
    } else {
        &s.pos[..]
    };
    let reduced = reduced
        .iter()
        .zip(&s.first)
        .enumerate()
        .map(move |(i, (&p, &first))| (p, &k_red[i..i + 1], first));
    direct.chain(reduced)
}

/// Stores (`first`) or adds `src` into `target` entry by entry.
fn add_run(target: &mut [f64], src: &[f64], first: bool) {
    if first {
        crate::element_split::store_run(target, src);
    } else {
        for (t, v) in target.iter_mut().zip(src) {
            *t += v;
        }
    }
}

/// Adds an element's tangent to the values (stores its first writes).
fn add_tangent(values: &mut [f64], w: &Work, s: &Slots) {
    for (p, run, first) in tangent_runs(w, s) {
        add_run(&mut values[p..p + run.len()], run, first);
    }
}

/// The arrays the chunks of a parallel loop add into.
struct Sinks<'a> {
    values: Shared<'a>,
    nodal: Shared<'a>,
    nodal_abs: Shared<'a>,
}

impl<'a> Sinks<'a> {
    fn new(values: &'a mut [f64], nodal: &'a mut [f64], nodal_abs: &'a mut [f64]) -> Self {
        Self {
            values: Shared::new(values),
            nodal: Shared::new(nodal),
            nodal_abs: Shared::new(nodal_abs),
        }
    }

    /// Adds element `el`'s forces (and, with its slots `s`, its tangent)
    /// from `w`: everything, or with `Some((split, c, owned))` only the
    /// values and nodes that chunk `c` owns (`owned`) or does not own.
    ///
    /// # Safety
    /// No other thread touches what this adds to meanwhile: in a parallel
    /// phase, chunk `c` adds only what it owns.
    unsafe fn add(
        &self,
        el: &Element,
        w: &Work,
        s: Option<&Slots>,
        only: Option<(&Split, usize, bool)>,
    ) {
        // SAFETY: by the caller's contract.
        unsafe { self.add_forces(el, w.r.as_slice(), only) };
        let Some(s) = s else { return };
        for (p, run, first) in tangent_runs(w, s) {
            match only {
                // SAFETY: by the caller's contract.
                None => unsafe { self.values.add_or_store(p, run, first) },
                Some((split, c, owned)) => {
                    for (i, v) in run.iter().enumerate() {
                        if split.owns_value(c, p + i) == owned {
                            // SAFETY: by the caller's contract.
                            unsafe { self.values.add_or_store(p + i, &[*v], first) };
                        }
                    }
                }
            }
        }
    }

    /// Adds the forces `r` and tangent `k` (its kernel's buffer) of an
    /// element `el` whose tangent goes straight into the values
    /// ([`Slots::direct`]) — all of them, as [`Sinks::add`] without `only`.
    ///
    /// # Safety
    /// As for [`Sinks::add`].
    unsafe fn add_direct(&self, el: &Element, r: &[f64], k: &[f64], s: &Slots) {
        // SAFETY: by the caller's contract.
        unsafe { self.add_forces(el, r, None) };
        for &(e, p, len, first) in s.direct.iter().flatten() {
            // SAFETY: by the caller's contract.
            unsafe { self.values.add_or_store(p, &k[e..e + len], first) };
        }
    }

    /// Adds element `el`'s forces `r` to the nodes (all, or as
    /// [`Sinks::add`] says with `only`).
    ///
    /// # Safety
    /// As for [`Sinks::add`].
    unsafe fn add_forces(&self, el: &Element, r: &[f64], only: Option<(&Split, usize, bool)>) {
        for (nd, f) in force_blocks(el, r) {
            if only.is_none_or(|(split, c, owned)| split.owns_node(c, nd) == owned) {
                // SAFETY: by the caller's contract.
                unsafe {
                    self.nodal.add(6 * nd, f, |v| v);
                    self.nodal_abs.add(6 * nd, f, f64::abs);
                }
            }
        }
    }
}

/// `work` cut at the chunks of `split`.
fn chunk_parts<'a>(mut work: &'a mut [Work], split: &Split) -> Vec<&'a mut [Work]> {
    let mut parts = Vec::with_capacity(split.chunks.len());
    for r in &split.chunks {
        let (part, rest) = std::mem::take(&mut work).split_at_mut(r.len());
        parts.push(part);
        work = rest;
    }
    parts
}

/// The scratch buffer for elements of `dofs` unknowns (one per element
/// kind, made with the assembler).
fn scratch_for(scratch: &mut [Work], dofs: usize) -> &mut Work {
    let i = scratch
        .iter()
        .position(|w| w.r.len() == dofs)
        .unwrap_or_default();
    &mut scratch[i]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_map_products_equal_the_dense_ones() {
        let k = DMatrix::from_fn(12, 12, |r, c| ((r * 13 + c * 5) % 17) as f64 - 8.0);
        let v = |s: usize| {
            Vector6::from_fn(|r, _| {
                if (r + s) % 4 == 1 {
                    0.0
                } else {
                    (r * 7 + s * 3) as f64 % 11.0 - 5.0
                }
            })
        };
        let vs: Vec<Vector6<f64>> = (0..8).map(v).collect();
        // Columns with one node's block, or two (a slave's and its master's).
        let cols = [
            (0, 0, &vs[0]),
            (1, 1, &vs[1]),
            (0, 2, &vs[2]),
            (1, 2, &vs[3]),
            (1, 3, &vs[4]),
        ];
        let rows = [
            (0, 0, &vs[5]),
            (1, 1, &vs[6]),
            (0, 2, &vs[7]),
            (1, 2, &vs[3]),
            (1, 3, &vs[4]),
        ];
        let dense = |entries: &[(usize, usize, &Vector6<f64>)]| {
            let mut g = DMatrix::zeros(12, 4);
            for &(a, j, v) in entries {
                for c in 0..6 {
                    g[(6 * a + c, j)] += v[c];
                }
            }
            g
        };
        let (mut t, mut out) = (DMatrix::zeros(12, 4), DMatrix::zeros(4, 4));
        map_columns(&k, cols.iter().copied(), &mut t);
        map_rows(&t, rows.iter().copied(), &mut out);
        let expected = dense(&rows).transpose() * &k * dense(&cols);
        assert!((out - expected).amax() < 1e-9);
    }
    /// A beam of 2-node elements and one of 3-node elements, with some
    /// DOFs held.
    fn two_beams() -> (Mesh, DofMap) {
        let section =
            flexmech_core::Section::new([1e4, 5e3, 5e3], [10.0, 20.0, 30.0], 1.0, [0.1; 3]);
        let mut mesh = Mesh::default();
        let (o, e2) = (nalgebra::Vector3::zeros(), nalgebra::Vector3::y());
        mesh.add_straight_beam(o, nalgebra::Vector3::x(), e2, 3, 2, section)
            .unwrap();
        mesh.add_straight_beam(
            o,
            nalgebra::Vector3::z(),
            nalgebra::Vector3::x(),
            2,
            3,
            section,
        )
        .unwrap();
        let mut fixed = vec![[false; 6]; mesh.node_count()];
        fixed[1] = [true, false, true, false, false, true];
        fixed[5] = [false, true, false, true, true, false];
        (mesh, DofMap::independent(&fixed))
    }

    #[test]
    fn the_counted_pattern_is_the_one_of_sorted_lists() {
        let (mesh, dofs) = two_beams();
        let blocks = vec![vec![2, 7, 30], vec![0, 31]];
        let asm = Assembler::new(&mesh, &dofs, &blocks);
        let n = dofs.n_eq;
        let mut cols: Vec<Vec<usize>> = (0..n).map(|j| vec![j]).collect();
        let lists = mesh.elements.iter().map(|el| {
            el.nodes()
                .iter()
                .flat_map(|&nd| dofs.nodes[nd].eqs.clone())
                .collect::<Vec<_>>()
        });
        for eqs in lists.chain(blocks) {
            for &j in &eqs {
                cols[j].extend(&eqs);
            }
        }
        let (col_ptr, row_idx) = (asm.pattern().col_ptr(), asm.pattern().row_idx());
        for (j, c) in cols.iter_mut().enumerate() {
            c.sort_unstable();
            c.dedup();
            assert_eq!(&row_idx[col_ptr[j]..col_ptr[j + 1]], &c[..], "column {j}");
        }
    }

    #[test]
    fn an_assembly_leaves_nothing_of_the_last_one_in_the_values() {
        // Each element's first writes store, so the values need no zeroing:
        // stale values (NaN) must leave no trace. The reference sums every
        // element's tangent into zeros, in element order, entry by entry.
        let (mesh, dofs) = two_beams();
        let blocks = vec![vec![2, 7, 30], vec![0, 31]];
        let mut asm = Assembler::new(&mesh, &dofs, &blocks);
        let mut config = flexmech_core::Configuration::initial(&mesh.positions);
        for (i, x) in config.x.iter_mut().enumerate() {
            // A bent, twisted state: tangents with no zero pattern of their own.
            let phi = nalgebra::Vector3::new(0.3, -0.2, 0.1) * i as f64;
            *x += phi * 0.05;
            config.rot[i] = flexmech_core::rotation::exp(&phi);
        }
        let n = dofs.n_eq;
        let mut dense = vec![0.0; n * n];
        let mut nodal = vec![0.0; 6 * mesh.node_count()];
        for el in &mesh.elements {
            let d = el.dofs();
            let (mut r, mut k) = (vec![0.0; d], vec![0.0; d * d]);
            el.residual_tangent(&config.x, &config.rot, &mut r, &mut k);
            for (a, &nd) in el.nodes().iter().enumerate() {
                for c in 0..6 {
                    nodal[6 * nd + c] += r[6 * a + c];
                }
            }
            let eqs: Vec<(usize, usize)> = el
                .nodes()
                .iter()
                .enumerate()
                .flat_map(|(a, &nd)| {
                    let own = dofs.own_dofs(nd).unwrap();
                    dofs.nodes[nd]
                        .eqs
                        .iter()
                        .zip(own)
                        .map(move |(&eq, &o)| (6 * a + usize::from(o), eq))
                })
                .collect();
            for &(b, col) in &eqs {
                for &(a, row) in &eqs {
                    dense[col * n + row] += k[b * d + a];
                }
            }
        }
        asm.values.fill(f64::NAN);
        asm.assemble(&mesh, &dofs, &config);
        let (col_ptr, row_idx) = (asm.pattern().col_ptr(), asm.pattern().row_idx());
        for j in 0..n {
            let (rows, values) = (col_ptr[j]..col_ptr[j + 1], col_ptr[j]..col_ptr[j + 1]);
            for (&i, &v) in row_idx[rows].iter().zip(&asm.values[values]) {
                // Bitwise, but for the sign of a zero.
                assert!(v == dense[j * n + i], "entry ({i}, {j})");
            }
        }
        // The nodal forces to the bit (the first two 2-node elements are
        // evaluated as a pair, `assembly/pairs.rs`).
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&asm.nodal), bits(&nodal));
        // Block 0's entry (2, 30) is no element's: zeroed.
        assert!(!asm.untouched.is_empty());
    }

    #[test]
    fn the_mass_diagonal_is_the_node_blocks_diagonal() {
        let (mesh, dofs) = two_beams();
        let asm = Assembler::new(&mesh, &dofs, &[]);
        let mut checked = 0;
        for el in &mesh.elements {
            for &i in el.nodes() {
                for &j in el.nodes() {
                    let full = asm.node_block_slots(&dofs, (i, 0), (j, 0)).unwrap();
                    let diagonal: Vec<usize> =
                        full.iter().filter(|s| s.1 == s.2).map(|s| s.0).collect();
                    let (at, len) = asm.node_block_diagonal(&dofs, i, j).unwrap();
                    assert_eq!(&at[..len], &diagonal[..], "nodes {i}, {j}");
                    checked += usize::from(len < 3);
                }
            }
        }
        // Blocks of the nodes with held DOFs were among them.
        assert!(checked > 0);
    }
}
