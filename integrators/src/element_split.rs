//! How an element loop is split over threads so that every sum keeps the
//! one-thread order.
//!
//! The elements are cut into contiguous chunks, one task each. Every tangent
//! value and every node is *owned* by the chunk of the first element (in
//! element order) that adds to it. A chunk adds its elements straight into
//! the values and nodal forces it owns, as it evaluates them, in element
//! order. An element that also adds to something an earlier chunk owns is
//! *late*: its kernel output is kept, and those additions are made after
//! all chunks are done, late elements in element order. Since the chunks
//! are contiguous, everything a chunk owns receives first all of that
//! chunk's additions (in order, during the parallel phase) and then the
//! later chunks' (in order, afterwards): each sum is formed in exactly the
//! order of the one-thread loop, so the result is bitwise the same for any
//! number of threads. In a chain only the first element of each chunk is
//! late.
//!
//! Compared with evaluating every element into a buffer of its own and
//! summing all buffers on one thread afterwards, nothing is summed on one
//! thread but the few late elements, and each buffer is summed by the core
//! that wrote it while it is still in its cache: on a 2-core machine that
//! older scheme made a 2 048-element cantilever *slower* with two threads
//! than with one (1.32 s against 1.10 s).

use std::marker::PhantomData;
use std::ops::Range;

/// No chunk owns this (no element adds to it).
const NO_OWNER: u32 = u32::MAX;

/// Chunks per thread: more than one, so that a thread that finishes early
/// (the other core busy with something else) takes over work.
const CHUNKS_PER_THREAD: usize = 4;

/// Fewest elements in a chunk: below this the late elements and the task
/// hand-offs cost more than the split saves.
const MIN_CHUNK_ELEMENTS: usize = 16;

/// The chunks of one element loop and who owns what.
pub(crate) struct Split {
    /// Contiguous element ranges, in element order.
    pub chunks: Vec<Range<usize>>,
    /// Owning chunk of each tangent value position.
    value_owner: Vec<u32>,
    /// Owning chunk of each node (its six nodal forces).
    node_owner: Vec<u32>,
    /// The late elements, ascending.
    pub late: Vec<usize>,
    /// Whether each element is late.
    is_late: Vec<bool>,
    /// The thread count this split was made for.
    threads: usize,
}

impl Split {
    /// The split of `n_elements` elements for `threads` threads, given each
    /// element's tangent value positions and nodes.
    pub fn new<'a>(
        threads: usize,
        n_values: usize,
        n_nodes: usize,
        elements: impl Iterator<Item = (&'a [usize], &'a [usize])>,
        n_elements: usize,
    ) -> Self {
        let count = if threads > 1 {
            (threads * CHUNKS_PER_THREAD)
                .min(n_elements / MIN_CHUNK_ELEMENTS)
                .max(1)
        } else {
            1
        };
        let chunks: Vec<Range<usize>> = (0..count)
            .map(|c| c * n_elements / count..(c + 1) * n_elements / count)
            .collect();
        Self::with_chunks(chunks, threads, n_values, n_nodes, elements)
    }

    /// The split into the given contiguous `chunks` (in element order,
    /// covering every element) made for `threads` threads, given each
    /// element's tangent value positions and nodes.
    pub fn with_chunks<'a>(
        chunks: Vec<Range<usize>>,
        threads: usize,
        n_values: usize,
        n_nodes: usize,
        elements: impl Iterator<Item = (&'a [usize], &'a [usize])>,
    ) -> Self {
        let n_elements = chunks.last().map_or(0, |r| r.end);
        let chunk_of = |e: usize| chunks.partition_point(|r| r.end <= e) as u32;
        let mut value_owner = vec![NO_OWNER; n_values];
        let mut node_owner = vec![NO_OWNER; n_nodes];
        let mut is_late = vec![false; n_elements];
        for (e, (positions, nodes)) in elements.enumerate() {
            let c = chunk_of(e);
            let mut late = false;
            for &p in positions {
                let o = &mut value_owner[p];
                if *o == NO_OWNER {
                    *o = c;
                }
                late |= *o != c;
            }
            for &nd in nodes {
                let o = &mut node_owner[nd];
                if *o == NO_OWNER {
                    *o = c;
                }
                late |= *o != c;
            }
            is_late[e] = late;
        }
        let late = (0..n_elements).filter(|&e| is_late[e]).collect();
        Self {
            chunks,
            value_owner,
            node_owner,
            late,
            is_late,
            threads,
        }
    }

    /// Whether this split was made for `threads` threads.
    pub fn is_for(&self, threads: usize) -> bool {
        self.threads == threads
    }

    /// Whether element `e` is late.
    pub fn is_late(&self, e: usize) -> bool {
        self.is_late[e]
    }

    /// Whether chunk `c` owns tangent value position `p`.
    pub fn owns_value(&self, c: usize, p: usize) -> bool {
        self.value_owner[p] == c as u32
    }

    /// Whether chunk `c` owns node `nd`.
    pub fn owns_node(&self, c: usize, nd: usize) -> bool {
        self.node_owner[nd] == c as u32
    }

    /// The chunk element `e` belongs to.
    pub fn chunk_of(&self, e: usize) -> usize {
        self.chunks.partition_point(|r| r.end <= e)
    }
}

/// An array that several chunks add into at once, each only at what it
/// owns (see [`Split`]).
#[derive(Clone, Copy)]
pub(crate) struct Shared<'a> {
    ptr: *mut f64,
    len: usize,
    /// The array stays borrowed, mutably, as long as this lives.
    array: PhantomData<&'a mut [f64]>,
}

// SAFETY: `Shared` is only a pointer and a length; the positions added to by
// `Shared::add` are disjoint between threads by the ownership of `Split`
// (the caller's obligation), and the array stays mutably borrowed as long
// as the `Shared` lives (its lifetime), so nothing else touches it.
unsafe impl Send for Shared<'_> {}
// SAFETY: as for `Send`.
unsafe impl Sync for Shared<'_> {}

impl<'a> Shared<'a> {
    /// Shares `values` (borrowed for as long as the result lives).
    pub fn new(values: &'a mut [f64]) -> Self {
        Self {
            ptr: values.as_mut_ptr(),
            len: values.len(),
            array: PhantomData,
        }
    }

    /// Adds `f(src[i])` to `values[p + i]` for every `i`.
    ///
    /// # Safety
    /// Meanwhile no other thread reads or writes any of these positions:
    /// the calling chunk owns all of them.
    pub unsafe fn add(&self, p: usize, src: &[f64], f: impl Fn(f64) -> f64) {
        assert!(p + src.len() <= self.len, "shared range within the array");
        for (i, &v) in src.iter().enumerate() {
            // SAFETY: in bounds (asserted); exclusive by the caller's contract.
            unsafe { *self.ptr.add(p + i) += f(v) };
        }
    }

    /// Stores (`store`) or adds `src[i]` at `values[p + i]` for every `i`.
    ///
    /// # Safety
    /// As for [`Shared::add`].
    pub unsafe fn add_or_store(&self, p: usize, src: &[f64], store: bool) {
        if !store {
            // SAFETY: by the caller's contract.
            return unsafe { self.add(p, src, |v| v) };
        }
        assert!(p + src.len() <= self.len, "shared range within the array");
        // SAFETY: in bounds (asserted); exclusive by the caller's contract.
        let target = unsafe { std::slice::from_raw_parts_mut(self.ptr.add(p), src.len()) };
        store_run(target, src);
    }
}

/// Stores `src` in `target` as `0 + v`: the bits of a sum into zeroed
/// values (a `−0` stored as `+0`, as it was added), and a loop the compiler
/// keeps inline — a plain copy of a run of a few entries (an element
/// tangent's 6 or 12 per column) became a call to `memmove`, 5 % of a
/// cantilever's time.
pub(crate) fn store_run(target: &mut [f64], src: &[f64]) {
    for (t, &v) in target.iter_mut().zip(src) {
        *t = 0.0 + v;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A chain of `n` 2-node elements: element `e` has nodes `e, e + 1`
    /// and adds to "values" `2e, 2e + 1, 2e + 2` (the middle one its own).
    fn chain(n: usize, threads: usize) -> Split {
        let nodes: Vec<[usize; 2]> = (0..n).map(|e| [e, e + 1]).collect();
        let values: Vec<[usize; 3]> = (0..n).map(|e| [2 * e, 2 * e + 1, 2 * e + 2]).collect();
        Split::new(
            threads,
            2 * n + 1,
            n + 1,
            values.iter().zip(&nodes).map(|(v, nd)| (&v[..], &nd[..])),
            n,
        )
    }

    #[test]
    fn in_a_chain_only_the_first_element_of_each_later_chunk_is_late() {
        let s = chain(256, 2);
        assert_eq!(s.chunks.len(), 8);
        assert_eq!(s.chunks.first().map(|r| r.start), Some(0));
        assert_eq!(s.chunks.last().map(|r| r.end), Some(256));
        let firsts: Vec<usize> = s.chunks[1..].iter().map(|r| r.start).collect();
        assert_eq!(s.late, firsts);
        // The shared value and node at a boundary belong to the earlier chunk.
        let b = s.chunks[1].start;
        assert!(s.owns_value(0, 2 * b) && !s.owns_value(1, 2 * b));
        assert!(s.owns_value(1, 2 * b + 1) && s.owns_node(1, b + 1));
        assert!(s.owns_node(0, b) && s.chunk_of(b) == 1);
        assert!(s.is_for(2) && !s.is_for(1));
    }

    #[test]
    fn split_sums_equal_the_one_thread_sums_to_the_bit() {
        // Elements adding to random positions of a small array (many
        // contributors to each, across chunks, as at joints), values of
        // magnitudes 1e-8..1e8 so that the order of the additions shows.
        let mut seed = 0x9e37_79b9_7f4a_7c15_u64;
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed
        };
        let (n, n_values) = (200, 60);
        let positions: Vec<Vec<usize>> = (0..n)
            .map(|e| {
                let mut p: Vec<usize> = (0..6).map(|_| next() as usize % n_values).collect();
                p.push(e * n_values / n);
                p.sort_unstable();
                p.dedup();
                p
            })
            .collect();
        let value = |v: u64| (v % 1000) as f64 * 10f64.powi((v >> 20) as i32 % 17 - 8);
        let values: Vec<Vec<f64>> = positions
            .iter()
            .map(|p| p.iter().map(|_| value(next())).collect())
            .collect();
        let nodes: Vec<[usize; 1]> = (0..n).map(|e| [e]).collect();
        let split = Split::new(
            3,
            n_values,
            n,
            positions
                .iter()
                .zip(&nodes)
                .map(|(p, nd)| (&p[..], &nd[..])),
            n,
        );
        assert!(split.chunks.len() > 1 && !split.late.is_empty());
        let mut one = vec![0.0; n_values];
        for (p, v) in positions.iter().zip(&values) {
            p.iter().zip(v).for_each(|(&p, v)| one[p] += v);
        }
        // The chunks in any order (here backwards), then the late elements.
        let mut split_sum = vec![0.0; n_values];
        let mut touched = vec![None; n_values];
        for c in (0..split.chunks.len()).rev() {
            for e in split.chunks[c].clone() {
                for (&p, v) in positions[e].iter().zip(&values[e]) {
                    if split.owns_value(c, p) {
                        split_sum[p] += v;
                        // Only one chunk ever writes a position in phase 1.
                        assert!(*touched[p].get_or_insert(c) == c);
                    } else {
                        assert!(split.is_late(e));
                    }
                }
            }
        }
        for &e in &split.late {
            let c = split.chunk_of(e);
            for (&p, v) in positions[e].iter().zip(&values[e]) {
                if !split.owns_value(c, p) {
                    split_sum[p] += v;
                }
            }
        }
        let bits = |x: &[f64]| x.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&split_sum), bits(&one));
        // The data do show the order: chunks adding all their elements'
        // values, in another order than the elements', give other sums.
        let mut unordered = vec![0.0; n_values];
        for c in (0..split.chunks.len()).rev() {
            for e in split.chunks[c].clone() {
                positions[e]
                    .iter()
                    .zip(&values[e])
                    .for_each(|(&p, v)| unordered[p] += v);
            }
        }
        assert_ne!(bits(&unordered), bits(&one));
    }

    #[test]
    fn small_loops_and_one_thread_have_one_chunk_and_nothing_late() {
        for s in [chain(20, 2), chain(256, 1)] {
            assert!(s.late.is_empty());
            assert!((0..s.value_owner.len()).all(|p| s.owns_value(0, p)));
        }
        assert_eq!(chain(20, 2).chunks.len(), 1);
        assert_eq!(chain(256, 1).chunks.len(), 1);
    }
}
