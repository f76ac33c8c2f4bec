//! Everything a [`Simulation`](super::Simulation) carries from one step to
//! the next, as plain numbers: saved with a run's results, it lets a later
//! process continue the run exactly where it stopped (restart).
//!
//! A continued run performs the same floating-point operations as the
//! uninterrupted one — same state, velocities, accelerations, joint rates,
//! drivers' reactions, step size and halving level — so its results are
//! equal to the last bit.

use crate::constraints::MechanismState;
use flexmech_joints::{ReleasedState, MAX_RELEASED};
use nalgebra::{Matrix3, Vector3};
use thiserror::Error;

/// The state of a simulation between two steps.
#[derive(Debug, Clone, PartialEq)]
pub struct Checkpoint {
    /// The integrator's name (`"newmark"`, `"momentum"`, `"energy-momentum"`,
    /// `"energy-momentum-paper"`).
    pub integrator: String,
    /// Time of the state.
    pub time: f64,
    /// Size of the last converged step (0 before the first).
    pub last_dt: f64,
    /// The drivers' work since t = 0.
    pub driver_work: f64,
    /// The follower loads' work since t = 0 (see
    /// [`follower_work`](crate::measure::follower_work)).
    pub follower_work: f64,
    /// Step control: the step in force and its halving level, and the easy
    /// steps counted towards growing it back.
    pub step: f64,
    /// Halvings below the nominal step in force.
    pub level: usize,
    /// Easy steps in a row.
    pub easy: usize,
    /// Nodal positions.
    pub positions: Vec<Vector3<f64>>,
    /// Nodal rotations (from the initial triads).
    pub rotations: Vec<Matrix3<f64>>,
    /// Every joint's released state.
    pub released: Vec<ReleasedState>,
    /// Current values of the prescribed nodal DOFs.
    pub prescribed: Vec<f64>,
    /// What the scheme carries (velocities, accelerations, joint rates,
    /// drivers' reactions), in the order the scheme writes them.
    pub scheme: Vec<f64>,
}

impl Checkpoint {
    /// The mechanism state it holds.
    pub fn state(&self) -> MechanismState {
        MechanismState {
            config: flexmech_core::Configuration {
                x: self.positions.clone(),
                rot: self.rotations.clone(),
            },
            released: self.released.clone(),
            prescribed: self.prescribed.clone(),
        }
    }

    /// Every joint's released state as `[q (MAX_RELEASED), q0 (MAX_RELEASED),
    /// rot (9, column-major)]` rows.
    pub fn released_rows(&self) -> Vec<[f64; 2 * MAX_RELEASED + 9]> {
        self.released
            .iter()
            .map(|r| {
                let mut row = [0.0; 2 * MAX_RELEASED + 9];
                row[..MAX_RELEASED].copy_from_slice(&r.q);
                row[MAX_RELEASED..2 * MAX_RELEASED].copy_from_slice(&r.q0);
                row[2 * MAX_RELEASED..].copy_from_slice(r.rot.as_slice());
                row
            })
            .collect()
    }

    /// Released states from rows of [`Checkpoint::released_rows`].
    pub fn released_from_rows(rows: &[[f64; 2 * MAX_RELEASED + 9]]) -> Vec<ReleasedState> {
        rows.iter()
            .map(|row| {
                let mut q = [0.0; MAX_RELEASED];
                let mut q0 = [0.0; MAX_RELEASED];
                q.copy_from_slice(&row[..MAX_RELEASED]);
                q0.copy_from_slice(&row[MAX_RELEASED..2 * MAX_RELEASED]);
                ReleasedState {
                    q,
                    q0,
                    rot: Matrix3::from_column_slice(&row[2 * MAX_RELEASED..]),
                }
            })
            .collect()
    }
}

/// Why a checkpoint does not fit a simulation.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("the saved state does not fit this mechanism and integrator: {0}")]
pub struct CheckpointMismatch(pub String);

/// A flat record of numbers written and read back in one order: what a
/// scheme saves in [`Checkpoint::scheme`].
#[derive(Debug, Default)]
pub(crate) struct Tape {
    data: Vec<f64>,
    at: usize,
}

impl Tape {
    /// A tape to read `data` from.
    pub(crate) fn reading(data: &[f64]) -> Self {
        Self {
            data: data.to_vec(),
            at: 0,
        }
    }

    pub(crate) fn into_data(self) -> Vec<f64> {
        self.data
    }

    pub(crate) fn put(&mut self, x: f64) {
        self.data.push(x);
    }

    /// A list of numbers, preceded by its length.
    pub(crate) fn put_list(&mut self, xs: &[f64]) {
        self.put(xs.len() as f64);
        self.data.extend_from_slice(xs);
    }

    /// A list of vectors, preceded by its length.
    pub(crate) fn put_vectors(&mut self, vs: &[Vector3<f64>]) {
        self.put(vs.len() as f64);
        for v in vs {
            self.data.extend_from_slice(v.as_slice());
        }
    }

    pub(crate) fn take(&mut self) -> Result<f64, CheckpointMismatch> {
        let x = self
            .data
            .get(self.at)
            .copied()
            .ok_or_else(|| CheckpointMismatch("the scheme's saved values end early".into()))?;
        self.at += 1;
        Ok(x)
    }

    /// A count written with [`Tape::put`], checked against `expected`.
    pub(crate) fn take_count(
        &mut self,
        what: &str,
        expected: Option<usize>,
    ) -> Result<usize, CheckpointMismatch> {
        let n = self.take()?;
        if n < 0.0 || n.fract() != 0.0 || n > self.data.len() as f64 {
            return Err(CheckpointMismatch(format!("{what}: not a length ({n})")));
        }
        let n = n as usize;
        match expected {
            Some(e) if e != n => Err(CheckpointMismatch(format!(
                "{what}: {n} saved, the mechanism has {e}"
            ))),
            _ => Ok(n),
        }
    }

    pub(crate) fn take_list(
        &mut self,
        what: &str,
        expected: Option<usize>,
    ) -> Result<Vec<f64>, CheckpointMismatch> {
        let n = self.take_count(what, expected)?;
        (0..n).map(|_| self.take()).collect()
    }

    pub(crate) fn take_vectors(
        &mut self,
        what: &str,
        expected: usize,
    ) -> Result<Vec<Vector3<f64>>, CheckpointMismatch> {
        let n = self.take_count(what, Some(expected))?;
        (0..n)
            .map(|_| Ok(Vector3::new(self.take()?, self.take()?, self.take()?)))
            .collect()
    }

    /// Whether every saved value has been read.
    pub(crate) fn is_done(&self) -> bool {
        self.at == self.data.len()
    }

    /// Refuses values left over.
    pub(crate) fn done(&self) -> Result<(), CheckpointMismatch> {
        if self.at == self.data.len() {
            Ok(())
        } else {
            Err(CheckpointMismatch(format!(
                "{} saved values of the scheme were not used",
                self.data.len() - self.at
            )))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_tape_reads_back_what_was_written_and_refuses_other_shapes() {
        let mut t = Tape::default();
        t.put(0.5);
        t.put_list(&[1.0, 2.0]);
        t.put_vectors(&[Vector3::new(3.0, 4.0, 5.0)]);
        let data = t.into_data();
        let mut r = Tape::reading(&data);
        assert_eq!(r.take().unwrap(), 0.5);
        assert_eq!(r.take_list("x", Some(2)).unwrap(), [1.0, 2.0]);
        assert_eq!(
            r.take_vectors("v", 1).unwrap(),
            [Vector3::new(3.0, 4.0, 5.0)]
        );
        r.done().unwrap();
        let mut r = Tape::reading(&data);
        r.take().unwrap();
        assert!(r.take_list("x", Some(3)).is_err());
        let r = Tape::reading(&data);
        assert!(r.done().is_err());
    }

    #[test]
    fn released_rows_round_trip() {
        let mut s = ReleasedState::new([0.1, 0.2, 0.0, 0.0]);
        s.q[0] = 1.5;
        s.rot = flexmech_core::rotation::exp(&Vector3::new(0.1, -0.2, 0.3));
        let cp = Checkpoint {
            integrator: "newmark".into(),
            time: 0.0,
            last_dt: 0.0,
            driver_work: 0.0,
            follower_work: 0.0,
            step: 0.1,
            level: 0,
            easy: 0,
            positions: vec![],
            rotations: vec![],
            released: vec![s],
            prescribed: vec![],
            scheme: vec![],
        };
        assert_eq!(Checkpoint::released_from_rows(&cp.released_rows()), [s]);
    }
}
