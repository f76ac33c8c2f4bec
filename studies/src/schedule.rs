//! The order in which a study's runs go to the threads.
//!
//! Runs of one study can differ in cost several-fold (a grid over the time
//! step, the mesh or the scheme). Splitting them into contiguous halves
//! leaves one thread idle while the other finishes its half: with 8 runs
//! whose one-thread times were 0.8–2.1 s, the halves took 4.2 and 6.3 s. So
//! the runs are handed out one at a time from a shared queue, longest first
//! (Graham's LPT rule: the makespan is within 4/3 of the optimum), by an
//! estimate of their cost — the estimate only orders the queue; a poor one
//! costs balance, never a result.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

use flexmech_integrators::threads::one_thread_each;
use flexmech_model::{Analysis, IntegratorKind, Model};

/// Cost of a step relative to a Newmark step at the same size, by scheme
/// (`flexmech bench`: generalized-α 0.94–1.16, momentum 0.94–1.44,
/// energy–momentum 1.5–2.2, its paper form 3.4–5.4 × Newmark).
fn step_weight(integrator: IntegratorKind) -> f64 {
    match integrator {
        IntegratorKind::Newmark | IntegratorKind::GeneralizedAlpha { .. } => 1.0,
        IntegratorKind::Momentum => 1.2,
        IntegratorKind::EnergyMomentum => 1.8,
        IntegratorKind::EnergyMomentumPaper => 4.0,
    }
}

/// The cost of one linearisation (an eigen-solve) in steps, for the
/// schedule's ordering only.
const LINEARISATION_STEPS: f64 = 100.0;

/// An estimate of a run's cost in node-steps: nodes × steps × the scheme's
/// [`step_weight`] (a static path counts its most steps).
pub(crate) fn estimated_cost(model: &Model) -> f64 {
    let nodes: usize = model.beams.iter().map(|b| b.node_count()).sum();
    let steps = match model.solver.analysis {
        Analysis::Static { load_steps } => load_steps as f64,
        Analysis::ArcLength { max_steps, .. } => max_steps as f64,
        // A dense eigen-solve costs about as much as a few hundred steps.
        Analysis::Modal { load_steps, .. } => load_steps as f64 + LINEARISATION_STEPS,
        Analysis::Buckling { .. } => LINEARISATION_STEPS,
        Analysis::Dynamic {
            integrator,
            dt,
            t_end,
        } => t_end / dt * step_weight(integrator),
    };
    let cost = steps * nodes.max(1) as f64;
    if cost.is_finite() {
        cost
    } else {
        0.0
    }
}

/// The indices `0..costs.len()` longest first (ties in index order).
pub(crate) fn longest_first(costs: &[f64]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..costs.len()).collect();
    order.sort_by(|&a, &b| costs[b].total_cmp(&costs[a]).then(a.cmp(&b)));
    order
}

/// `job(i)` for every index of `order`, on the threads of the current rayon
/// pool: each thread takes the next index of `order` when it is free. The
/// results come back in index order (`order` is a permutation of
/// `0..order.len()`; an index it lacks has no result).
pub(crate) fn run_queue<R: Send>(order: &[usize], job: impl Fn(usize) -> R + Sync) -> Vec<R> {
    let next = AtomicUsize::new(0);
    let done = Mutex::new(Vec::with_capacity(order.len()));
    let worker = || {
        while let Some(&i) = order.get(next.fetch_add(1, Ordering::Relaxed)) {
            // The threads are busy with the other runs: each run's element
            // loops stay on its thread.
            let result = one_thread_each(|| job(i));
            // A poisoned lock can only come from a panic elsewhere, which
            // rayon re-raises when the scope ends.
            if let Ok(mut done) = done.lock() {
                done.push((i, result));
            }
        }
    };
    rayon::scope(|s| {
        for _ in 0..rayon::current_num_threads().min(order.len()) {
            s.spawn(|_| worker());
        }
    });
    let mut done = done.into_inner().unwrap_or_else(|e| e.into_inner());
    done.sort_by_key(|(i, _)| *i);
    done.into_iter().map(|(_, r)| r).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_queue_is_longest_first_and_the_results_in_index_order() {
        let costs = [0.8, 1.2, 0.9, 1.3, 1.4, 2.1, 1.4, 0.0];
        assert_eq!(longest_first(&costs), vec![5, 4, 6, 3, 1, 2, 0, 7]);
        let order = longest_first(&costs);
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .expect("a pool of two threads");
        let started = Mutex::new(Vec::new());
        // The first two runs wait for each other: neither thread can take a
        // third before both have started theirs, so the first two recorded
        // are the first two taken, however the threads are scheduled.
        let both_started = std::sync::Barrier::new(2);
        let out = pool.install(|| {
            run_queue(&order, |i| {
                let count = {
                    let mut started = started.lock().expect("not poisoned");
                    started.push(i);
                    started.len()
                };
                if count <= 2 {
                    both_started.wait();
                }
                // The assembly of a run stays on its thread.
                assert!(flexmech_integrators::threads::sequential(usize::MAX));
                i * 10
            })
        });
        assert_eq!(out, (0..8).map(|i| i * 10).collect::<Vec<_>>());
        let started = started.into_inner().expect("not poisoned");
        let mut sorted = started.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, (0..8).collect::<Vec<_>>());
        // Taken from the queue in its order: the two threads start with the
        // two longest runs.
        let mut first_two = started[..2].to_vec();
        first_two.sort_unstable();
        assert_eq!(first_two, vec![4, 5]);
    }

    #[test]
    fn with_two_threads_the_longest_first_queue_balances_a_skewed_study() {
        // Greedy list scheduling, as the queue does: a thread takes the
        // next run when it is free.
        fn makespan(costs: &[f64], order: &[usize]) -> f64 {
            let mut free = [0.0f64; 2];
            for &i in order {
                let t = if free[0] <= free[1] { 0 } else { 1 };
                free[t] += costs[i];
            }
            free[0].max(free[1])
        }
        // One-thread run times (s) of the free-chain study at t_end = 4.
        let costs = [0.83, 1.15, 0.9, 1.27, 1.42, 2.1, 1.37, 1.39];
        let total: f64 = costs.iter().sum();
        let halves = costs[..4].iter().sum::<f64>().max(costs[4..].iter().sum());
        let lpt = makespan(&costs, &longest_first(&costs));
        assert!(
            total / halves < 1.7,
            "contiguous halves: {}",
            total / halves
        );
        assert!(total / lpt > 1.9, "longest first: {}", total / lpt);
        // Graham's bound for two machines: within 7/6 of the optimum, which
        // is at least half the total.
        assert!(lpt <= 7.0 / 6.0 * total / 2.0 + 1e-12);
    }
}
