//! When an element loop is worth handing to other threads.
//!
//! A solve's split loops run on [`crate::team`], whose helpers stay awake
//! between one loop and the next, so a hand-off costs about a µs rather
//! than the system call and context switches of waking a sleeping worker.
//! The thread count is rayon's (`RAYON_NUM_THREADS`, or the pool a solve
//! runs in). Where there is one thread, or the solve is itself one of many
//! parallel tasks (a study's runs, [`one_thread_each`]), splitting its
//! loops again would only add hand-offs between the same threads.
//!
//! A small mesh's loops stay on the calling thread: a 2-node element's
//! kernels cost about 1 µs, and a 64-element cantilever under Newmark ran
//! 1.3× *slower* with its loops split over two threads. From
//! [`PARALLEL_ALWAYS_ELEMENTS`] elements on, every element and node loop
//! is split (2-node cantilevers under Newmark, wall time on two threads
//! over one: 128 elements 0.89, 256 elements 0.81, 512 elements 0.77,
//! 1 024 elements 0.64, 2 048 elements 0.60 with its band LU in two halves
//! as well, [`crate::band_split`]).
//! Between the two, a loop is split when its kernels, timed on one thread
//! for the first few calls ([`LoopCost`]), cost at least
//! [`PARALLEL_MIN_NS_PER_ELEMENT`] each — the energy–momentum scheme's
//! exact tangent (≈ 24 µs), 3-node elements (≈ 5 µs). Either way the sums
//! are the same numbers.

use std::cell::Cell;
use std::ops::Range;
use std::sync::Mutex;
use std::thread::LocalKey;
use std::time::Duration;

/// Below this many elements a loop stays on the calling thread.
pub const PARALLEL_MIN_ELEMENTS: usize = 64;

/// Least time per element (ns) of an element loop's kernels, timed on one
/// thread, for the loop to be split over threads.
pub const PARALLEL_MIN_NS_PER_ELEMENT: f64 = 2000.0;

/// Fewest elements for which a loop is split whatever its kernels cost
/// (see the module docs for the measurements).
pub const PARALLEL_ALWAYS_ELEMENTS: usize = 128;

/// One-thread calls timed before a loop's cost is known.
const PROBE_CALLS: u32 = 3;

thread_local! {
    /// Set while this thread runs one of many parallel tasks.
    static ONE_THREAD_EACH: Cell<bool> = const { Cell::new(false) };
    /// Set while this thread's loops split whatever their cost.
    static ALWAYS_SPLIT: Cell<bool> = const { Cell::new(false) };
}

/// Whether a loop over `elements` element kernels runs on the calling
/// thread: a small loop, one thread asked for (`RAYON_NUM_THREADS=1` or a
/// one-thread pool), or a solve inside [`one_thread_each`].
pub fn sequential(elements: usize) -> bool {
    elements < PARALLEL_MIN_ELEMENTS
        || rayon::current_num_threads() == 1
        || ONE_THREAD_EACH.with(Cell::get)
}

/// Runs `task` with every element loop on the calling thread: for a solve
/// that is one of many tasks already spread over the threads (a study's
/// runs), where the threads are busy with the other tasks.
pub fn one_thread_each<R>(task: impl FnOnce() -> R) -> R {
    with_flag(&ONE_THREAD_EACH, task)
}

/// Runs `task` with this thread's `flag` set, and restores it afterwards
/// (also if `task` panics).
fn with_flag<R>(flag: &'static LocalKey<Cell<bool>>, task: impl FnOnce() -> R) -> R {
    struct Restore(&'static LocalKey<Cell<bool>>, bool);
    impl Drop for Restore {
        fn drop(&mut self) {
            self.0.with(|f| f.set(self.1));
        }
    }
    let _restore = Restore(flag, flag.with(|f| f.replace(true)));
    task()
}

/// Runs `a` and `b`, on two threads where there are two to use (not
/// inside [`one_thread_each`], not on a one-thread pool), else one after
/// the other — the same computations either way: for the two halves of a
/// factorisation ([`crate::band_split`]), each far costlier than a hand-off.
pub fn join<A: Send, B: Send>(
    a: impl FnOnce() -> A + Send,
    b: impl FnOnce() -> B + Send,
) -> (A, B) {
    if sequential(usize::MAX) {
        let ra = a();
        return (ra, b());
    }
    let (ra, rb) = (Mutex::new(None), Mutex::new(None));
    let (a, b) = (Mutex::new(Some(a)), Mutex::new(Some(b)));
    crate::team::run(rayon::current_num_threads(), 2, &|i| {
        if i == 0 {
            if let Some(a) = take(&a) {
                *lock(&ra) = Some(a());
            }
        } else if let Some(b) = take(&b) {
            *lock(&rb) = Some(b());
        }
    });
    match (take(&ra), take(&rb)) {
        (Some(ra), Some(rb)) => (ra, rb),
        // `team::run` runs every task or resumes a task's panic.
        _ => unreachable!("both halves of a join ran"),
    }
}

/// `task(i, item)` for every item, each on whichever of the threads is free
/// ([`crate::team`]): for chunks of a loop whose results do not depend on
/// who computes them.
pub fn for_each_item<T: Send>(items: Vec<T>, task: impl Fn(usize, T) + Sync) {
    let slots: Vec<Mutex<Option<T>>> = items.into_iter().map(|t| Mutex::new(Some(t))).collect();
    crate::team::run(rayon::current_num_threads(), slots.len(), &|i| {
        if let Some(item) = take(&slots[i]) {
            task(i, item);
        }
    });
}

/// Chunks a per-node loop is cut into, per thread (a little more than one,
/// so that a thread held up elsewhere does not hold the loop up).
const NODE_CHUNKS_PER_THREAD: usize = 4;

/// The ranges of `n` nodes' chunks.
fn node_chunks(n: usize) -> impl Iterator<Item = Range<usize>> {
    let count = (rayon::current_num_threads() * NODE_CHUNKS_PER_THREAD).clamp(1, n.max(1));
    (0..count).map(move |c| c * n / count..(c + 1) * n / count)
}

/// The item of a slot, taken (a poisoned lock's too: its task panicked,
/// which the team resumes).
fn take<T>(slot: &Mutex<Option<T>>) -> Option<T> {
    lock(slot).take()
}

/// A lock's guard, a poisoned one's too (its holder panicked, which the
/// team resumes): also for the scratch buffers terms keep behind a lock.
pub(crate) fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

/// Whether a per-node loop over `nodes` nodes goes to two threads: a mesh
/// large enough that its element loops are split whatever they cost
/// ([`PARALLEL_ALWAYS_ELEMENTS`]) or any loop under [`always_split`],
/// threads to use.
pub fn split_nodes(nodes: usize) -> bool {
    (nodes >= PARALLEL_ALWAYS_ELEMENTS || ALWAYS_SPLIT.with(Cell::get)) && !sequential(nodes)
}

/// `f(i)` for every node `i < nodes`, in order — on two threads where
/// [`split_nodes`]; each value computed on its own, so the same either way.
pub fn map_nodes<T: Send>(nodes: usize, f: impl Fn(usize) -> T + Sync + Send) -> Vec<T> {
    map_split(nodes, split_nodes(nodes), f)
}

/// [`map_nodes`] into `out`, cleared first: a loop run at every
/// evaluation keeps its buffer's allocation from one call to the next.
pub fn map_nodes_into<T: Send>(
    nodes: usize,
    out: &mut Vec<T>,
    f: impl Fn(usize) -> T + Sync + Send,
) {
    out.clear();
    if split_nodes(nodes) {
        out.append(&mut map_split(nodes, true, f));
    } else {
        out.extend((0..nodes).map(f));
    }
}

/// `f(i)` for every `i < n`, in order — on two threads unless
/// [`sequential`]: for loops whose every item is costly (an element's
/// energy terms), split from [`PARALLEL_MIN_ELEMENTS`] items on.
pub fn map_each<T: Send>(n: usize, f: impl Fn(usize) -> T + Sync + Send) -> Vec<T> {
    map_split(n, !sequential(n), f)
}

/// `f(i)` for every `i < n`, in order, in chunks on the team's threads if
/// `split`; each value computed on its own, so the same either way.
fn map_split<T: Send>(n: usize, split: bool, f: impl Fn(usize) -> T + Sync + Send) -> Vec<T> {
    if !split {
        return (0..n).map(f).collect();
    }
    let chunks: Vec<_> = node_chunks(n).collect();
    let outs: Vec<Mutex<Vec<T>>> = chunks.iter().map(|_| Mutex::new(Vec::new())).collect();
    for_each_chunk(&chunks, |c, range| {
        *lock(&outs[c]) = range.map(&f).collect()
    });
    let mut all = Vec::with_capacity(n);
    for out in outs {
        all.append(&mut out.into_inner().unwrap_or_else(|e| e.into_inner()));
    }
    all
}

/// `f(i)` for every node `i < nodes` — on the team's threads where
/// [`split_nodes`], each node once: for node loops that write only what
/// belongs to their node.
pub fn for_each_node(nodes: usize, f: impl Fn(usize) + Sync) {
    if !split_nodes(nodes) {
        return (0..nodes).for_each(f);
    }
    let chunks: Vec<_> = node_chunks(nodes).collect();
    for_each_chunk(&chunks, |_, range| range.for_each(&f));
}

/// `f(c, chunks[c])` for every chunk, on the team's threads.
fn for_each_chunk(chunks: &[Range<usize>], f: impl Fn(usize, Range<usize>) + Sync) {
    crate::team::run(rayon::current_num_threads(), chunks.len(), &|c| {
        f(c, chunks[c].clone())
    });
}

/// `f(first, chunk)` on consecutive chunks of `items`, `first` the chunk's
/// first index — on the team's threads unless [`sequential`] (one chunk
/// then), as [`map_each`] splits: for loops that write each item in place
/// from what belongs to it alone, so the same either way.
pub fn for_each_chunk_mut<T: Send>(items: &mut [T], f: impl Fn(usize, &mut [T]) + Sync + Send) {
    if sequential(items.len()) {
        return f(0, items);
    }
    let mut parts = Vec::new();
    let ranges: Vec<_> = node_chunks(items.len()).collect();
    let mut rest = items;
    for range in ranges {
        let (chunk, tail) = std::mem::take(&mut rest).split_at_mut(range.len());
        parts.push((range.start, chunk));
        rest = tail;
    }
    for_each_item(parts, |_, (first, chunk)| f(first, chunk));
}

/// `f(i, xᵢ, Rᵢ)` on every node's pose — on two threads where
/// [`split_nodes`]; each node on its own, so the same either way.
pub fn for_each_pose(
    x: &mut [nalgebra::Vector3<f64>],
    rot: &mut [nalgebra::Matrix3<f64>],
    f: impl Fn(usize, &mut nalgebra::Vector3<f64>, &mut nalgebra::Matrix3<f64>) + Sync + Send,
) {
    for_each_pose_chunk(x, rot, |first, xs, rs| {
        for (k, (x, r)) in xs.iter_mut().zip(rs.iter_mut()).enumerate() {
            f(first + k, x, r);
        }
    });
}

/// `f(first, xs, rs)` on consecutive chunks of the nodes' poses, `first`
/// the chunk's first node — on two threads where [`split_nodes`] (one
/// chunk otherwise); each node in one chunk.
pub fn for_each_pose_chunk(
    x: &mut [nalgebra::Vector3<f64>],
    rot: &mut [nalgebra::Matrix3<f64>],
    f: impl Fn(usize, &mut [nalgebra::Vector3<f64>], &mut [nalgebra::Matrix3<f64>]) + Sync + Send,
) {
    if !split_nodes(x.len()) {
        return f(0, x, rot);
    }
    let mut items = Vec::new();
    let (mut x, mut rot) = (x, rot);
    for range in node_chunks(x.len().min(rot.len())) {
        let (xs, x_rest) = std::mem::take(&mut x).split_at_mut(range.len());
        let (rs, rot_rest) = std::mem::take(&mut rot).split_at_mut(range.len());
        items.push((range.start, xs, rs));
        (x, rot) = (x_rest, rot_rest);
    }
    for_each_item(items, |_, (first, xs, rs)| f(first, xs, rs));
}

/// The increments `inc(i)` of the nodes' poses (translation, spatial
/// rotation vector; `None`: node `i` stays), applied as
/// [`flexmech_core::state::increment_pose`] would — two nodes at a time
/// ([`flexmech_core::pose_pair::increment_poses`]), on two threads where
/// [`split_nodes`]; each node on its own, so the same bits either way.
pub fn increment_poses(
    x: &mut [nalgebra::Vector3<f64>],
    rot: &mut [nalgebra::Matrix3<f64>],
    inc: impl Fn(usize) -> Option<(nalgebra::Vector3<f64>, nalgebra::Vector3<f64>)> + Sync + Send,
) {
    for_each_pose_chunk(x, rot, |first, xs, rs| {
        flexmech_core::pose_pair::increment_poses(first, xs, rs, &inc)
    });
}

/// Runs `task` with every element and node loop that may be split
/// ([`sequential`] false) split over the threads whatever its kernels cost:
/// for tests of the parallel paths with cheap kernels and small meshes.
pub fn always_split<R>(task: impl FnOnce() -> R) -> R {
    with_flag(&ALWAYS_SPLIT, task)
}

/// The measured cost of one element loop (one assembler's kernel), which
/// decides whether the loop is split over threads.
#[derive(Debug, Clone, Default)]
pub struct LoopCost {
    /// One-thread calls timed so far.
    probes: u32,
    /// The fastest of them, ns per element.
    best: f64,
}

impl LoopCost {
    /// Whether this call of a loop over `elements` elements is split: not
    /// when [`sequential`], nor before its cost is known, nor when its
    /// kernels cost less than [`PARALLEL_MIN_NS_PER_ELEMENT`] (unless
    /// [`always_split`]).
    pub fn split(&self, elements: usize) -> bool {
        !sequential(elements)
            && (ALWAYS_SPLIT.with(Cell::get)
                || elements >= PARALLEL_ALWAYS_ELEMENTS
                || (self.probes >= PROBE_CALLS && self.best >= PARALLEL_MIN_NS_PER_ELEMENT))
    }

    /// Whether this one-thread call should be timed (the loop could be
    /// split and its cost is not known yet).
    pub fn probing(&self, elements: usize) -> bool {
        !sequential(elements) && elements < PARALLEL_ALWAYS_ELEMENTS && self.probes < PROBE_CALLS
    }

    /// Records a timed one-thread call over `elements` elements.
    pub fn record(&mut self, elapsed: Duration, elements: usize) {
        let ns = elapsed.as_secs_f64() * 1e9 / elements.max(1) as f64;
        self.best = if self.probes == 0 {
            ns
        } else {
            self.best.min(ns)
        };
        self.probes += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_loops_one_thread_and_tasks_of_a_study_stay_sequential() {
        let pool = |n| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .expect("a thread pool")
        };
        let big = PARALLEL_MIN_ELEMENTS;
        pool(2).install(|| {
            assert!(!sequential(big));
            assert!(sequential(big - 1));
            assert!(one_thread_each(|| sequential(big)));
            // Restored after the task, nested or not.
            assert!(one_thread_each(
                || one_thread_each(|| true) && sequential(big)
            ));
            assert!(!sequential(big));
        });
        pool(1).install(|| assert!(sequential(big)));
    }

    #[test]
    fn a_loop_is_split_once_timed_as_costly_enough() {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .expect("a thread pool");
        let big = PARALLEL_MIN_ELEMENTS;
        let per = |ns: f64| Duration::from_secs_f64(ns * big as f64 * 1e-9);
        pool.install(|| {
            let (mut cheap, mut costly) = (LoopCost::default(), LoopCost::default());
            for _ in 0..PROBE_CALLS {
                assert!(!costly.split(big) && costly.probing(big));
                cheap.record(per(0.5 * PARALLEL_MIN_NS_PER_ELEMENT), big);
                // The fastest probe counts: one slow (cold) call does not.
                costly.record(per(1.5 * PARALLEL_MIN_NS_PER_ELEMENT), big);
            }
            assert!(costly.split(big) && !costly.probing(big));
            assert!(!cheap.split(big) && !cheap.probing(big));
            assert!(always_split(|| cheap.split(big)));
            assert!(!always_split(|| cheap.split(big - 1)));
            // Inside a study's run, nothing is split or timed.
            assert!(one_thread_each(
                || !costly.split(big) && !costly.probing(big)
            ));
            let mut slow_first = LoopCost::default();
            slow_first.record(per(10.0 * PARALLEL_MIN_NS_PER_ELEMENT), big);
            for _ in 1..PROBE_CALLS {
                slow_first.record(per(0.1 * PARALLEL_MIN_NS_PER_ELEMENT), big);
            }
            assert!(!slow_first.split(big));
        });
    }
}
