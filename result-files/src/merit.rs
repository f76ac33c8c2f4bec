//! A run's figures of merit, computed once, while it runs, over every
//! converged step (not only the stored ones), and written as root
//! attributes of its result file; studies read them back from there
//! (`flexmech_studies::figures`).
//!
//! | attribute | value |
//! |---|---|
//! | `energy_drift` | [`super::reader::energy_drift`] over every converged step |
//! | `max_displacement` | largest `|x − x₀|` of any tracked node over every converged step (NaN when none is tracked) |
//! | `newton_iterations` | Newton iterations of every converged step |
//! | `steps` | converged steps (the initial record of a dynamic run included) |

use flexmech_integrators::StepRecord;

use super::layout;
use super::reader::EnergyDrift;

/// The streaming observer of a run's figures of merit.
#[derive(Debug, Clone)]
pub struct Merit {
    drift: EnergyDrift,
    /// Tracked nodes: global index and initial position.
    tracked: Vec<(usize, [f64; 3])>,
    max_displacement: f64,
    iterations: u64,
    steps: u64,
}

impl Merit {
    /// An observer of the tracked nodes `(global index, initial position)`.
    pub fn new(tracked: Vec<(usize, [f64; 3])>) -> Self {
        Self {
            drift: EnergyDrift::default(),
            tracked,
            max_displacement: f64::NAN,
            iterations: 0,
            steps: 0,
        }
    }

    /// Takes in a converged step.
    pub fn push(&mut self, step: &StepRecord) {
        let e = &step.energy;
        self.drift.push(e.total, e.driver_work, e.kinetic, e.strain);
        for &(node, x0) in &self.tracked {
            if let Some(x) = step.positions.get(node) {
                let d = (0..3).map(|c| (x[c] - x0[c]).powi(2)).sum::<f64>().sqrt();
                // NaN-aware: NaN.max(d) is d.
                self.max_displacement = self.max_displacement.max(d);
            }
        }
        self.iterations += step.iterations as u64;
        self.steps += 1;
    }

    /// `(attribute, value)` of every figure, in the order of the module docs.
    pub fn figures(&self) -> [(&'static str, f64); 4] {
        [
            (layout::ATTR_ENERGY_DRIFT, self.drift.drift()),
            (layout::ATTR_MAX_DISPLACEMENT, self.max_displacement),
            (layout::ATTR_NEWTON_ITERATIONS, self.iterations as f64),
            (layout::ATTR_STEPS, self.steps as f64),
        ]
    }
}
