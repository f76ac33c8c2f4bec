//! Branch switching: the stability count of the path's last step, and the
//! critical mode to leave the fundamental path along (once) after a
//! bifurcation.

use crate::critical::{critical_mode, load_cosine, BIFURCATION_COSINE};
use crate::linsolve::SparseLu;
use crate::statics::StaticTerms;
use crate::system::ReducedSystem;

/// The count of the last step and the mode to leave along.
pub(super) struct BranchSwitch {
    /// Negative eigenvalues of the last converged step's tangent.
    last_count: Option<usize>,
    /// The critical mode found at a bifurcation, not yet left along.
    switch: Option<Vec<f64>>,
    /// Whether the path has left along a critical mode.
    switched: bool,
}

impl Default for BranchSwitch {
    /// The count of the unloaded state (none negative), no mode.
    fn default() -> Self {
        Self {
            last_count: Some(0),
            switch: None,
            switched: false,
        }
    }
}

impl BranchSwitch {
    /// Before the first step, whose start has `count` negative eigenvalues.
    pub(super) fn starting_with(count: Option<usize>) -> Self {
        Self {
            last_count: count,
            ..Self::default()
        }
    }

    /// The direction the next step leaves along: the critical mode, taken
    /// once (the path switches branches at most once).
    pub(super) fn direction(&mut self) -> Option<Vec<f64>> {
        let direction = if self.switched {
            None
        } else {
            self.switch.take()
        };
        if direction.is_some() {
            self.switched = true;
        }
        direction
    }

    /// The count of the last converged step (of the unloaded state before
    /// the first).
    pub(super) fn last_count(&self) -> Option<usize> {
        self.last_count
    }

    /// Whether the path has left along a critical mode.
    pub(super) fn switched(&self) -> bool {
        self.switched
    }

    /// Takes a converged step's count of negative eigenvalues; whether it
    /// grew since the last step (both known).
    pub(super) fn count(&mut self, negative_pivots: Option<usize>) -> bool {
        let grew = match (self.last_count, negative_pivots) {
            (Some(a), Some(b)) => b > a,
            _ => false,
        };
        self.last_count = negative_pivots;
        grew
    }

    /// At a step past which the count grew: the critical mode of the
    /// converged tangent now in `sys`, kept to leave along when the load
    /// does no work on it (a bifurcation, not a limit point).
    pub(super) fn found(
        &mut self,
        sys: &ReducedSystem<'_, StaticTerms>,
        lu: &mut SparseLu,
        f_ref: &[f64],
    ) {
        self.switch = critical_mode(sys, lu)
            .filter(|mode| load_cosine(sys, mode, f_ref) < BIFURCATION_COSINE);
    }
}
