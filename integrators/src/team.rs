//! The threads that share one solve's loops, kept awake between them.
//!
//! A Newmark step of a long chain hands work to a second thread six to
//! eight times per Newton iteration (the element loop, the inertia's nodes,
//! the two halves of the band LU and of every solve, the pose update), each
//! time for 0.1–0.5 ms of work, with sequential work of the same order in
//! between. A thread pool whose idle workers go to sleep after a few µs
//! (rayon's) wakes them for every one of those hand-offs through the
//! kernel; on a shared machine the wake-up often came so late that the
//! calling thread had done most of the work alone (a 2 048-element
//! cantilever's calling thread did 1.6 × the other's share of the
//! parallel work). So a solve's loops go to a team of its own: helpers
//! that, after a job, spin for [`SPIN_BEFORE_SLEEP`] waiting for the next
//! one before they sleep — what OpenMP runtimes do between parallel
//! regions.
//!
//! A job is a number of tasks `f(0) … f(n−1)` taken in turn by whichever
//! member of the team is free, the calling thread included; each task
//! computes the same numbers whoever runs it, so the results do not depend
//! on the thread count or on who ran what. One solve uses the team at a
//! time: a job from another thread while it is busy, or from within one of
//! its tasks, runs its tasks on the calling thread, in order.

use std::any::Any;
use std::cell::Cell;
use std::panic::{catch_unwind, resume_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicPtr, AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Condvar, Mutex, OnceLock, TryLockError};
use std::time::{Duration, Instant};

/// How long a helper waits, spinning, for the next job before it sleeps.
/// Longer than the sequential stretches of a solve between its parallel
/// loops (tens to hundreds of µs), short next to a human's wait.
pub const SPIN_BEFORE_SLEEP: Duration = Duration::from_millis(1);

/// A ticket's low bits: the helpers a job engages.
const TICKET_SHIFT: u32 = 16;
const ENGAGED_MASK: u64 = (1 << TICKET_SHIFT) - 1;

/// Spins between two looks at the clock (or at a sleeping helper).
const SPINS_PER_CHECK: u32 = 64;

/// One job: its tasks, the next one to take, and what went wrong.
struct Job<'a> {
    task: &'a (dyn Fn(usize) + Sync),
    tasks: usize,
    next: AtomicUsize,
    panic: Mutex<Option<Box<dyn Any + Send>>>,
}

impl Job<'_> {
    /// Takes and runs tasks until none is left; keeps the first panic.
    fn work(&self) {
        loop {
            let i = self.next.fetch_add(1, Ordering::Relaxed);
            if i >= self.tasks {
                return;
            }
            if let Err(p) = catch_unwind(AssertUnwindSafe(|| (self.task)(i))) {
                let mut slot = self.panic.lock().unwrap_or_else(|e| e.into_inner());
                slot.get_or_insert(p);
                // The remaining tasks are skipped.
                self.next.store(self.tasks, Ordering::Relaxed);
            }
        }
    }
}

/// What the members share.
struct Shared {
    /// The current job's ticket: a count bumped for every job, times
    /// [`TICKET_SHIFT`], plus the number of helpers it engages (the first
    /// ones). Read as one value, so that a helper never pairs one job's
    /// count with another's engagement.
    ticket: AtomicU64,
    /// The current job, type-erased (valid until every engaged helper has
    /// signed off).
    job: AtomicPtr<Job<'static>>,
    /// Engaged helpers done with the current job.
    done: AtomicUsize,
    /// Helpers asleep, and where they sleep.
    sleeping: Mutex<usize>,
    wake: Condvar,
}

/// The team: its helpers (started as jobs ask for them) and the lock that
/// gives it to one caller at a time.
struct Team {
    shared: Arc<Shared>,
    helpers: usize,
}

thread_local! {
    /// Set on the team's members while they run a job's tasks.
    static IN_JOB: Cell<bool> = const { Cell::new(false) };
}

/// The process's team, behind the lock that gives it to one job at a time.
fn team() -> &'static Mutex<Team> {
    static TEAM: OnceLock<Mutex<Team>> = OnceLock::new();
    TEAM.get_or_init(|| {
        Mutex::new(Team {
            shared: Arc::new(Shared {
                ticket: AtomicU64::new(0),
                job: AtomicPtr::new(std::ptr::null_mut()),
                done: AtomicUsize::new(0),
                sleeping: Mutex::new(0),
                wake: Condvar::new(),
            }),
            helpers: 0,
        })
    })
}

/// Runs `task(i)` for every `i < tasks` on `threads` threads (the calling
/// one and `threads − 1` helpers), each task once; returns when all are
/// done. With one thread, inside another job, or while the team serves
/// another caller, the tasks run here in order. A panicking task's panic
/// is resumed here once all have stopped.
pub fn run(threads: usize, tasks: usize, task: &(dyn Fn(usize) + Sync)) {
    let inline = || (0..tasks).for_each(task);
    if threads < 2 || tasks < 2 || IN_JOB.with(Cell::get) {
        return inline();
    }
    let mut team = match team().try_lock() {
        Ok(t) => t,
        Err(TryLockError::Poisoned(p)) => p.into_inner(),
        Err(TryLockError::WouldBlock) => return inline(),
    };
    let wanted = (threads - 1).min(tasks - 1).min(ENGAGED_MASK as usize);
    let engaged = team.hire(wanted);
    let job = Job {
        task,
        tasks,
        next: AtomicUsize::new(0),
        panic: Mutex::new(None),
    };
    let shared = &team.shared;
    // SAFETY: the lifetime is erased only while engaged helpers may look at
    // the job: this function waits below until all of them have signed off,
    // and helpers that are not engaged never read the pointer.
    let erased = (&job as *const Job<'_>).cast::<Job<'static>>().cast_mut();
    shared.job.store(erased, Ordering::Relaxed);
    shared.done.store(0, Ordering::Relaxed);
    let count = shared.ticket.load(Ordering::Relaxed) >> TICKET_SHIFT;
    let ticket = ((count + 1) << TICKET_SHIFT) | engaged as u64;
    shared.ticket.store(ticket, Ordering::Release);
    if *shared.sleeping.lock().unwrap_or_else(|e| e.into_inner()) > 0 {
        shared.wake.notify_all();
    }
    IN_JOB.with(|f| f.set(true));
    job.work();
    IN_JOB.with(|f| f.set(false));
    let mut spins = 0u32;
    while shared.done.load(Ordering::Acquire) < engaged {
        spins += 1;
        if spins.is_multiple_of(SPINS_PER_CHECK) {
            // A helper descheduled by the system: let it run.
            std::thread::yield_now();
        } else {
            std::hint::spin_loop();
        }
    }
    shared.job.store(std::ptr::null_mut(), Ordering::Relaxed);
    drop(team);
    let panic = job.panic.into_inner().unwrap_or_else(|e| e.into_inner());
    if let Some(p) = panic {
        resume_unwind(p);
    }
}

impl Team {
    /// Starts helpers until there are at least `n`; returns how many of
    /// them a job can engage (fewer if the system gives no more threads).
    fn hire(&mut self, n: usize) -> usize {
        while self.helpers < n {
            let (shared, index) = (Arc::clone(&self.shared), self.helpers);
            let seen = shared.ticket.load(Ordering::Acquire);
            let started = std::thread::Builder::new()
                .name(format!("flexmech-team-{}", index + 1))
                .spawn(move || helper(&shared, index, seen));
            if started.is_err() {
                // No more threads to be had: the team stays as it is, and
                // a job engages only the helpers there are.
                return self.helpers;
            }
            self.helpers += 1;
        }
        n
    }
}

/// A helper's life: wait for a job (spinning, then asleep), work on it if
/// engaged, sign off, repeat.
fn helper(shared: &Shared, index: usize, mut seen: u64) {
    loop {
        seen = next_ticket(shared, seen);
        if index as u64 >= seen & ENGAGED_MASK {
            continue;
        }
        // An engaged helper's job is this ticket's: the next job cannot be
        // posted before it signs off.
        let job = shared.job.load(Ordering::Relaxed);
        // SAFETY: an engaged helper's job stays valid until it signs off.
        if let Some(job) = unsafe { job.as_ref() } {
            IN_JOB.with(|f| f.set(true));
            job.work();
            IN_JOB.with(|f| f.set(false));
        }
        shared.done.fetch_add(1, Ordering::Release);
    }
}

/// Waits until the team's ticket moves past `seen` and returns it: spins
/// for [`SPIN_BEFORE_SLEEP`], then sleeps until a job wakes it.
fn next_ticket(shared: &Shared, seen: u64) -> u64 {
    let start = Instant::now();
    let mut spins = 0u32;
    loop {
        let now = shared.ticket.load(Ordering::Acquire);
        if now != seen {
            return now;
        }
        spins += 1;
        if !spins.is_multiple_of(SPINS_PER_CHECK) {
            std::hint::spin_loop();
            continue;
        }
        if start.elapsed() < SPIN_BEFORE_SLEEP {
            continue;
        }
        let mut asleep = shared.sleeping.lock().unwrap_or_else(|e| e.into_inner());
        *asleep += 1;
        while shared.ticket.load(Ordering::Acquire) == seen {
            asleep = shared.wake.wait(asleep).unwrap_or_else(|e| e.into_inner());
        }
        *asleep -= 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::AtomicU32;

    #[test]
    fn every_task_runs_once_whatever_the_thread_count() {
        for threads in [1, 2, 3] {
            for tasks in [0, 1, 2, 7, 64] {
                let counts: Vec<AtomicU32> = (0..tasks).map(|_| AtomicU32::new(0)).collect();
                run(threads, tasks, &|i| {
                    counts[i].fetch_add(1, Ordering::Relaxed);
                });
                assert!(counts.iter().all(|c| c.load(Ordering::Relaxed) == 1));
            }
        }
    }

    #[test]
    fn nested_and_concurrent_jobs_run_their_tasks_inline() {
        let total = AtomicU32::new(0);
        std::thread::scope(|s| {
            for _ in 0..3 {
                s.spawn(|| {
                    for _ in 0..50 {
                        run(2, 4, &|_| {
                            run(2, 3, &|_| {
                                total.fetch_add(1, Ordering::Relaxed);
                            });
                        });
                    }
                });
            }
        });
        assert_eq!(total.load(Ordering::Relaxed), 3 * 50 * 4 * 3);
    }

    #[test]
    fn a_panicking_task_panics_in_the_caller_and_the_team_goes_on() {
        let caught = catch_unwind(|| run(2, 8, &|i| assert!(i != 5, "task five")));
        assert!(caught.is_err());
        let done = AtomicU32::new(0);
        run(2, 8, &|_| {
            done.fetch_add(1, Ordering::Relaxed);
        });
        assert_eq!(done.load(Ordering::Relaxed), 8);
    }

    #[test]
    fn a_helper_asleep_is_woken_by_the_next_job() {
        run(2, 2, &|_| {});
        std::thread::sleep(SPIN_BEFORE_SLEEP * 5);
        let done = AtomicU32::new(0);
        run(2, 16, &|_| {
            done.fetch_add(1, Ordering::Relaxed);
        });
        assert_eq!(done.load(Ordering::Relaxed), 16);
    }
}
