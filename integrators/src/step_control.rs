//! Step-size control shared by statics (load steps) and dynamics (time
//! steps).

use crate::error::{NewtonFailure, SolveError};
use crate::tolerances::TOLERANCES;

/// Step-size control shared by statics and the integrators: halve on
/// failure, grow back (doubling) towards the nominal step after a number of
/// easy steps in a row. The step never goes below `nominal / 2^max_halvings`
/// — the level of halving in force is kept across successes — so a step that
/// fails at that size ends the analysis with a typed error, and a run whose
/// solution blows up (or a load path that stalls) stops instead of creeping
/// on with ever smaller steps.
#[derive(Debug, Clone, Copy)]
pub(crate) struct StepControl {
    nominal: f64,
    step: f64,
    /// Halvings below the nominal step now in force.
    level: usize,
    easy: usize,
    /// Easy steps in a row before the step doubles.
    grow_after: usize,
    max_halvings: usize,
}

impl StepControl {
    /// A controller of nominal step `nominal` that allows `max_halvings`
    /// halvings and doubles after `grow_after` easy steps.
    pub(crate) fn with(nominal: f64, max_halvings: usize, grow_after: usize) -> Self {
        Self {
            nominal,
            step: nominal,
            level: 0,
            easy: 0,
            grow_after,
            max_halvings,
        }
    }

    /// `(step, level, easy)`: what a restart needs to continue identically.
    pub(crate) fn saved(&self) -> (f64, usize, usize) {
        (self.step, self.level, self.easy)
    }

    /// Continues from a [`StepControl::saved`] triple; refused unless the step
    /// is the nominal one halved `level` times, within the allowed halvings.
    pub(crate) fn restore(&mut self, step: f64, level: usize, easy: usize) -> Result<(), String> {
        if level > self.max_halvings || step != self.nominal / f64::powi(2.0, level as i32) {
            return Err(format!(
                "saved step {step:e} at halving level {level} is not the nominal step {:e} \
                 halved at most {} times",
                self.nominal, self.max_halvings
            ));
        }
        (self.step, self.level, self.easy) = (step, level, easy);
        Ok(())
    }

    /// The step now in force (at most the nominal one).
    pub(crate) fn step(&self) -> f64 {
        self.step
    }

    /// Halvings below the nominal step now in force.
    pub(crate) fn level(&self) -> usize {
        self.level
    }

    /// The step to try from time `t` (never past `t_end`).
    pub(crate) fn next(&self, t: f64, t_end: f64) -> f64 {
        self.step.min(t_end - t)
    }

    /// The time after a converged step of `dt` from `t`: snapped to the
    /// nearest multiple of the nominal step when it is one up to round-off,
    /// so that stored times are `n·Δt` (not `0.9999999999999999`) however
    /// many steps were summed.
    pub(crate) fn advance(&self, t: f64, dt: f64) -> f64 {
        let next = t + dt;
        let n = (next / self.nominal).round();
        if (next - n * self.nominal).abs() <= TOLERANCES.level_snap * self.nominal {
            n * self.nominal
        } else {
            next
        }
    }

    /// A step converged.
    pub(crate) fn succeeded(&mut self) {
        self.easy += 1;
        if self.easy >= self.grow_after && self.level > 0 {
            self.level -= 1;
            self.step = self.nominal / f64::powi(2.0, self.level as i32);
            self.easy = 0;
        }
    }

    /// A step to `time` failed: halve, or give up with the reason.
    /// A converged state with a singular tangent ends the analysis at once
    /// (no step size makes a non-unique answer unique); a singular tangent at
    /// the start of a step (which a wild predictor can give) is retried
    /// smaller, and told as what it is when the smallest step meets it too.
    pub(crate) fn failed(&mut self, time: f64, reason: NewtonFailure) -> Result<(), SolveError> {
        if let NewtonFailure::Singular {
            condition,
            motion,
            converged,
        } = reason
        {
            if converged || self.level >= self.max_halvings {
                return Err(SolveError::Unrestrained {
                    time,
                    condition,
                    motion,
                });
            }
            return self.failed(
                time,
                NewtonFailure::Rejected(format!(
                    "singular tangent at the start of the step (condition number {condition:.1e})"
                )),
            );
        }
        if self.level >= self.max_halvings {
            return Err(SolveError::NoConvergence {
                time,
                halvings: self.level,
                reason,
            });
        }
        self.level += 1;
        self.easy = 0;
        self.step = self.nominal / f64::powi(2.0, self.level as i32);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn failure() -> NewtonFailure {
        NewtonFailure::NotFinite { iteration: 0 }
    }

    #[test]
    fn the_step_never_goes_below_the_floor() {
        // Failures interleaved with successes: the level is kept, so the
        // third failure after two successes ends the analysis (before, a
        // counter reset by every success let the step shrink without end).
        let mut c = StepControl::with(0.1, 2, 3);
        c.failed(0.1, failure()).unwrap();
        c.succeeded();
        c.failed(0.1, failure()).unwrap();
        assert_eq!((c.level(), c.step()), (2, 0.025));
        c.succeeded();
        let end = c.failed(0.1, failure());
        assert!(
            matches!(end, Err(SolveError::NoConvergence { halvings: 2, .. })),
            "{end:?}"
        );
    }

    #[test]
    fn the_step_grows_back_after_easy_steps() {
        let mut c = StepControl::with(0.1, 4, 3);
        c.failed(0.1, failure()).unwrap();
        c.failed(0.1, failure()).unwrap();
        for _ in 0..3 {
            c.succeeded();
        }
        assert_eq!((c.level(), c.step()), (1, 0.05));
        for _ in 0..3 {
            c.succeeded();
        }
        assert_eq!((c.level(), c.step()), (0, 0.1));
    }
}
