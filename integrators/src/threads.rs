//! When an element loop is worth handing to the thread pool.
//!
//! Handing a loop to rayon's pool wakes a worker (a system call and a
//! context switch each way, several µs) — more than a small mesh's element
//! kernels cost (about 1.5 µs per 2-node element): with two threads, a
//! 32-element cantilever ran in 0.23–0.27 s handing every loop over and in
//! 0.14 s without. And where there is one thread, or the solve is itself one
//! of many parallel tasks (a study's runs, [`one_thread_each`]), splitting
//! its loops again only adds hand-offs between the same threads.

use std::cell::Cell;

/// Below this many elements a loop stays on the calling thread.
pub const PARALLEL_MIN_ELEMENTS: usize = 64;

thread_local! {
    /// Set while this thread runs one of many parallel tasks.
    static ONE_THREAD_EACH: Cell<bool> = const { Cell::new(false) };
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
    /// Restores the flag also if `task` panics.
    struct Restore(bool);
    impl Drop for Restore {
        fn drop(&mut self) {
            ONE_THREAD_EACH.with(|f| f.set(self.0));
        }
    }
    let _restore = Restore(ONE_THREAD_EACH.with(|f| f.replace(true)));
    task()
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
}
