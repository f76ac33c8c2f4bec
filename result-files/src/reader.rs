//! Reading result files back: the other half of the contract the
//! [`ResultWriter`](super::ResultWriter) writes (docs/MODEL_FORMAT.md). `plot`,
//! studies and `reproduce` read through it, so a quantity derived from a
//! result (the energy drift) has one definition. It hands out arrays, strings
//! and numbers — never HDF5 handles — so its callers need not name `hdf5`;
//! a [table](super::table) (`summary.h5`) reads through it too.
//!
//! ```no_run
//! use flexmech_results::ResultReader;
//!
//! let r = ResultReader::open("results/cam.h5".as_ref())?;
//! let t = r.time()?;
//! let tip = r.rows3("/nodes/arm.end/position")?;
//! println!("{} steps, status {}, drift {:.1e}", t.len(), r.status()?, r.energy_drift()?);
//! # let _ = tip;
//! # Ok::<(), flexmech_results::ReadError>(())
//! ```

use std::path::{Path, PathBuf};

use hdf5::types::VarLenUnicode;
use thiserror::Error;

use super::layout;

/// A result file could not be read as the contract says.
#[derive(Debug, Error)]
pub enum ReadError {
    /// The HDF5 library reported an error.
    #[error("{}: HDF5 error while {what}: {source}", .path.display())]
    Hdf5 {
        /// The result file.
        path: PathBuf,
        /// What was being read.
        what: String,
        /// The library's error.
        #[source]
        source: hdf5::Error,
    },
    /// The dataset does not exist (or is a group).
    #[error(
        "{}: no dataset {dataset}; datasets under {group}: {}",
        .path.display(),
        if .available.is_empty() { "(none)".to_owned() } else { .available.join(", ") }
    )]
    UnknownDataset {
        /// The result file.
        path: PathBuf,
        /// The dataset asked for.
        dataset: String,
        /// The nearest existing group above it.
        group: String,
        /// Every dataset below that group.
        available: Vec<String>,
    },
    /// A dataset does not have the shape the contract gives it.
    #[error("{}: dataset {dataset} has shape {shape:?}, expected {expected}", .path.display())]
    Shape {
        /// The result file.
        path: PathBuf,
        /// The dataset.
        dataset: String,
        /// Its shape.
        shape: Vec<usize>,
        /// What it should be.
        expected: &'static str,
    },
}

impl ReadError {
    /// The result file the error is about.
    pub fn path(&self) -> &Path {
        match self {
            ReadError::Hdf5 { path, .. }
            | ReadError::UnknownDataset { path, .. }
            | ReadError::Shape { path, .. } => path,
        }
    }
}

/// An open result file.
#[derive(Debug)]
pub struct ResultReader {
    path: PathBuf,
    file: hdf5::File,
}

impl ResultReader {
    /// Opens the result file at `path` for reading.
    pub fn open(path: &Path) -> Result<Self, ReadError> {
        let file = hdf5::File::open(path).map_err(|source| ReadError::Hdf5 {
            path: path.to_path_buf(),
            what: "opening the file".into(),
            source,
        })?;
        Ok(Self {
            path: path.to_path_buf(),
            file,
        })
    }

    /// The file's path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    fn hdf5(&self, what: impl Into<String>) -> impl FnOnce(hdf5::Error) -> ReadError + '_ {
        let what = what.into();
        move |source| ReadError::Hdf5 {
            path: self.path.clone(),
            what,
            source,
        }
    }

    /// A string attribute of the root, if present.
    pub fn string_attr(&self, name: &str) -> Option<String> {
        string_attr(&self.file, name)
    }

    /// The run's `status` (`"completed"`, `"failed: …"`, `"running"`).
    pub fn status(&self) -> Result<String, ReadError> {
        self.file
            .attr(layout::ATTR_STATUS)
            .and_then(|a| a.read_scalar::<VarLenUnicode>())
            .map(|s| s.as_str().to_owned())
            .map_err(self.hdf5(format!("reading root attribute {}", layout::ATTR_STATUS)))
    }

    /// Whether the run stopped on an error.
    pub fn failed(&self) -> Result<bool, ReadError> {
        Ok(self.status()?.starts_with(layout::STATUS_FAILED_PREFIX))
    }

    /// A root attribute holding a list of strings (a table's `columns`), if
    /// present; a scalar string attribute is a list of one.
    pub fn string_list_attr(&self, name: &str) -> Option<Vec<String>> {
        let list = self
            .file
            .attr(name)
            .and_then(|a| a.read_raw::<VarLenUnicode>())
            .ok()?;
        Some(list.iter().map(|s| s.as_str().to_owned()).collect())
    }

    /// A numeric root attribute, if the file has it.
    pub fn f64_attr(&self, name: &str) -> Option<f64> {
        self.file
            .attr(name)
            .and_then(|a| a.read_scalar::<f64>())
            .ok()
    }

    /// The root attribute `wall_time_s`, NaN while the run has not finished.
    pub fn wall_time_s(&self) -> f64 {
        self.file
            .attr(layout::ATTR_WALL_TIME)
            .and_then(|a| a.read_scalar::<f64>())
            .unwrap_or(f64::NAN)
    }

    /// The integrator's name (`"static"` for a static analysis).
    pub fn integrator(&self) -> Option<String> {
        self.string_attr(layout::ATTR_INTEGRATOR)
    }

    /// Whether a dataset (or group) exists at `name`.
    pub fn has(&self, name: &str) -> bool {
        self.file.link_exists(name)
    }

    /// The dataset at the absolute path `name`; if there is none, the error
    /// lists the datasets below the nearest existing group. Private: the
    /// reader hands out arrays, never HDF5 handles.
    fn dataset(&self, name: &str) -> Result<hdf5::Dataset, ReadError> {
        let parts: Vec<&str> = name.split('/').filter(|p| !p.is_empty()).collect();
        let mut group = self
            .file
            .group("/")
            .map_err(self.hdf5("opening the root group"))?;
        for (i, part) in parts.iter().enumerate() {
            if !group.link_exists(part) {
                break;
            }
            if i + 1 == parts.len() {
                if let Ok(ds) = group.dataset(part) {
                    return Ok(ds);
                }
            }
            match group.group(part) {
                Ok(g) => group = g,
                Err(_) => break,
            }
        }
        let mut available = Vec::new();
        datasets_under(&group, &mut available);
        available.sort();
        Err(ReadError::UnknownDataset {
            path: self.path.clone(),
            dataset: name.to_owned(),
            group: group.name(),
            available,
        })
    }

    /// The path of every dataset in the file (`/time`, `/nodes/tip/position`,
    /// ...), sorted.
    pub fn dataset_names(&self) -> Vec<String> {
        let mut names = Vec::new();
        if let Ok(root) = self.file.group("/") {
            datasets_under(&root, &mut names);
        }
        names.sort();
        names
    }

    /// The `description` attribute of dataset `name`.
    pub fn description(&self, name: &str) -> Option<String> {
        let ds = self.dataset(name).ok()?;
        string_attr(&ds, layout::ATTR_DESCRIPTION)
    }

    /// The shape of dataset `name`.
    pub fn shape(&self, name: &str) -> Result<Vec<usize>, ReadError> {
        Ok(self.dataset(name)?.shape())
    }

    /// Dataset `name` read as `T`, flattened in row-major order: the one
    /// read behind [`values`](Self::values), [`counts`](Self::counts),
    /// [`integers`](Self::integers) and [`strings`](Self::strings).
    fn read_raw<T: hdf5::H5Type>(&self, name: &str) -> Result<Vec<T>, ReadError> {
        self.dataset(name)?
            .read_raw::<T>()
            .map_err(self.hdf5(format!("reading {name}")))
    }

    /// Dataset `name` as `f64`, flattened in row-major order.
    pub fn values(&self, name: &str) -> Result<Vec<f64>, ReadError> {
        self.read_raw(name)
    }

    /// Dataset `name` as unsigned counts (`/solver/iterations`, ...).
    pub fn counts(&self, name: &str) -> Result<Vec<u64>, ReadError> {
        self.read_raw(name)
    }

    /// Dataset `name` as signed integers (`/solver/negative_pivots`, where
    /// −1 means undefined).
    pub fn integers(&self, name: &str) -> Result<Vec<i64>, ReadError> {
        self.read_raw(name)
    }

    /// A T×3 dataset as rows.
    pub fn rows3(&self, name: &str) -> Result<Vec<[f64; 3]>, ReadError> {
        let shape = self.shape(name)?;
        if shape.len() != 2 || shape[1] != 3 {
            return Err(ReadError::Shape {
                path: self.path.clone(),
                dataset: name.to_owned(),
                shape,
                expected: "T×3",
            });
        }
        Ok(self
            .values(name)?
            .chunks_exact(3)
            .map(|r| [r[0], r[1], r[2]])
            .collect())
    }

    /// `/time`: the stored times (load factors in statics).
    pub fn time(&self) -> Result<Vec<f64>, ReadError> {
        self.values(layout::TIME)
    }

    fn members(&self, group: &str) -> Result<Vec<String>, ReadError> {
        if !self.has(group) {
            return Ok(Vec::new());
        }
        self.file
            .group(group)
            .and_then(|g| g.member_names())
            .map_err(self.hdf5(format!("listing {group}")))
    }

    /// Every node's label in `/configuration` order (`/mesh/node_labels`:
    /// `<beam>.<k>`, `<beam>.start`, `<beam>.end`, and `ground.<joint>` for
    /// the ground node of a joint to the ground).
    pub fn mesh_node_labels(&self) -> Result<Vec<String>, ReadError> {
        self.strings(layout::MESH_NODE_LABELS)
    }

    /// A dataset of strings (`/mesh/beam_names`, ...).
    pub fn strings(&self, name: &str) -> Result<Vec<String>, ReadError> {
        Ok(self
            .read_raw::<VarLenUnicode>(name)?
            .into_iter()
            .map(|s| s.as_str().to_owned())
            .collect())
    }

    /// A scalar unsigned attribute of the group `group` (None when absent).
    pub fn group_u64_attr(&self, group: &str, attr: &str) -> Option<u64> {
        self.file
            .group(group)
            .ok()?
            .attr(attr)
            .ok()?
            .read_scalar::<u64>()
            .ok()
    }

    /// A scalar real attribute of the group `group` (None when absent).
    pub fn group_f64_attr(&self, group: &str, attr: &str) -> Option<f64> {
        self.file
            .group(group)
            .ok()?
            .attr(attr)
            .ok()?
            .read_scalar::<f64>()
            .ok()
    }

    /// The beams of `/resultants`: names and their Gauss points' offsets
    /// (beams + 1), from the attributes of `/resultants/force`.
    pub fn resultant_beams(&self) -> Result<(Vec<String>, Vec<u64>), ReadError> {
        let name = layout::RESULTANTS_FORCE;
        let ds = self.dataset(name)?;
        let names: Vec<VarLenUnicode> = ds
            .attr("beam_names")
            .and_then(|a| a.read_raw())
            .map_err(self.hdf5(format!("reading the attribute beam_names of {name}")))?;
        let offsets: Vec<u64> = ds
            .attr("beam_offsets")
            .and_then(|a| a.read_raw())
            .map_err(self.hdf5(format!("reading the attribute beam_offsets of {name}")))?;
        Ok((
            names.iter().map(|n| n.as_str().to_owned()).collect(),
            offsets,
        ))
    }

    /// The labels of the tracked nodes (the groups of `/nodes`).
    pub fn node_labels(&self) -> Result<Vec<String>, ReadError> {
        self.members(layout::NODES)
    }

    /// The joints' names (the groups of `/joints`).
    pub fn joint_names(&self) -> Result<Vec<String>, ReadError> {
        self.members(layout::JOINTS)
    }

    /// The energy balance `B = E − W`: `/energy/total` less
    /// `/energy/driver_work` (when the file has it).
    pub fn energy_balance(&self) -> Result<Vec<f64>, ReadError> {
        let mut e = self.values(layout::ENERGY_TOTAL)?;
        if self.has(layout::ENERGY_DRIVER_WORK) {
            for (e, w) in e.iter_mut().zip(self.values(layout::ENERGY_DRIVER_WORK)?) {
                *e -= w;
            }
        }
        Ok(e)
    }

    /// The run's energy drift, [`energy_drift`] of its energies.
    pub fn energy_drift(&self) -> Result<f64, ReadError> {
        let total = self.values(layout::ENERGY_TOTAL)?;
        let work = if self.has(layout::ENERGY_DRIVER_WORK) {
            self.values(layout::ENERGY_DRIVER_WORK)?
        } else {
            vec![0.0; total.len()]
        };
        let kinetic = self.values(layout::ENERGY_KINETIC)?;
        let strain = self.values(layout::ENERGY_STRAIN)?;
        Ok(energy_drift(&total, &work, &kinetic, &strain))
    }

    /// The energy scale `S` of [`energy_drift`] for this run.
    pub fn energy_scale(&self) -> Result<f64, ReadError> {
        let total = self.values(layout::ENERGY_TOTAL)?;
        let work = if self.has(layout::ENERGY_DRIVER_WORK) {
            self.values(layout::ENERGY_DRIVER_WORK)?
        } else {
            Vec::new()
        };
        let kinetic = self.values(layout::ENERGY_KINETIC)?;
        let strain = self.values(layout::ENERGY_STRAIN)?;
        Ok(energy_scale(&total, &work, &kinetic, &strain))
    }
}

/// The energy drift of a run, the one definition every report uses:
///
/// ```text
/// drift = max_t |B(t) − B(0)| / S,    B = E − W
/// S = max(|E(0)|, max_t |W(t)|, K(0) + U(0))
/// ```
///
/// with `E` the total energy, `W` the drivers' work, `K` and `U` the kinetic
/// and strain energies. `S` is the energy the run starts with or is given —
/// not its current energies, so that a blow-up shows as a drift ≫ 1. A run
/// that starts at rest, unstrained, with no drivers (`S = 0`) is measured
/// against `max_t (K + U)`. 0 when `B` never changes; NaN for no steps.
pub fn energy_drift(total: &[f64], work: &[f64], kinetic: &[f64], strain: &[f64]) -> f64 {
    accumulate(total, work, kinetic, strain).drift()
}

/// `S` of [`energy_drift`].
pub fn energy_scale(total: &[f64], work: &[f64], kinetic: &[f64], strain: &[f64]) -> f64 {
    accumulate(total, work, kinetic, strain).scale()
}

fn accumulate(total: &[f64], work: &[f64], kinetic: &[f64], strain: &[f64]) -> EnergyDrift {
    let at = |v: &[f64], i: usize| v.get(i).copied().unwrap_or(0.0);
    let mut d = EnergyDrift::default();
    for (i, &e) in total.iter().enumerate() {
        d.push(e, at(work, i), at(kinetic, i), at(strain, i));
    }
    d
}

/// [`energy_drift`] step by step: the one definition, for series read back
/// from a file and for a run's every converged step as it is computed
/// ([`super::merit::Merit`]).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct EnergyDrift {
    /// `B(0)` and `max |B − B(0)|`.
    first: Option<f64>,
    change: f64,
    /// `max(|E(0)|, K(0) + U(0), max |W|)`.
    given: f64,
    /// `max (K + U)`, the scale of a run given no energy.
    moving: f64,
}

impl EnergyDrift {
    /// Takes in one step's total energy `E`, drivers' work `W`, kinetic `K`
    /// and strain energy `U`.
    pub fn push(&mut self, total: f64, work: f64, kinetic: f64, strain: f64) {
        let b = total - work;
        let moving = kinetic + strain;
        if self.first.is_none() {
            self.first = Some(b);
            self.given = total.abs().max(moving);
        }
        let b0 = self.first.unwrap_or(b);
        self.change = self.change.max((b - b0).abs());
        self.given = self.given.max(work.abs());
        self.moving = self.moving.max(moving);
    }

    /// `S`: the energy the run starts with or is given, else `max (K + U)`.
    pub fn scale(&self) -> f64 {
        if self.given > 0.0 {
            self.given
        } else {
            self.moving
        }
    }

    /// The drift `max |B − B(0)| / S`: 0 when `B` never changed, NaN before
    /// the first step.
    pub fn drift(&self) -> f64 {
        if self.first.is_none() {
            f64::NAN
        } else if self.change == 0.0 {
            0.0
        } else {
            self.change / self.scale()
        }
    }
}

/// `max_t |B(t) − B(0)| / scale` of [`energy_drift`]: 0 when `B` never
/// changes, NaN for no steps.
pub fn drift_of(balance: &[f64], scale: f64) -> f64 {
    let Some(&b0) = balance.first() else {
        return f64::NAN;
    };
    let change = balance.iter().map(|b| (b - b0).abs()).fold(0.0, f64::max);
    if change == 0.0 {
        0.0
    } else {
        change / scale
    }
}

fn string_attr(loc: &hdf5::Location, name: &str) -> Option<String> {
    let attr = loc.attr(name).ok()?;
    let value = attr.read_scalar::<VarLenUnicode>().ok()?;
    Some(value.as_str().to_owned())
}

fn datasets_under(group: &hdf5::Group, out: &mut Vec<String>) {
    if let Ok(datasets) = group.datasets() {
        out.extend(datasets.iter().map(|d| d.name()));
    }
    if let Ok(groups) = group.groups() {
        for g in &groups {
            datasets_under(g, out);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::energy_drift;

    #[test]
    fn drift_is_relative_to_the_energy_a_run_starts_with_or_is_given() {
        // Conserved: no drift.
        assert_eq!(
            energy_drift(&[2.0, 2.0], &[], &[1.0, 1.5], &[1.0, 0.5]),
            0.0
        );
        // Free run: relative to E(0).
        assert_eq!(
            energy_drift(&[2.0, 2.5], &[], &[2.0, 2.5], &[0.0, 0.0]),
            0.25
        );
        // A drive that puts in 10 and the energy follows: no drift.
        assert_eq!(
            energy_drift(&[0.0, 10.0], &[0.0, 10.0], &[0.0, 10.0], &[0.0, 0.0]),
            0.0
        );
        // ... and one that loses 1 of the 10: relative to the work.
        assert_eq!(
            energy_drift(&[0.0, 9.0], &[0.0, 10.0], &[0.0, 9.0], &[0.0, 0.0]),
            0.1
        );
        // A blow-up is ≫ 1, not saturated by its own growth.
        assert!(energy_drift(&[1.0, 1e3], &[], &[1.0, 1e3], &[0.0, 0.0]) > 900.0);
        // From rest under a dead load (E(0) = 0, no drive): against K + U.
        let d = energy_drift(&[0.0, 1e-9], &[], &[0.0, 2.0], &[0.0, 2.0]);
        assert!((d - 0.25e-9).abs() < 1e-24, "{d}");
        assert!(energy_drift(&[], &[], &[], &[]).is_nan());
    }
}
