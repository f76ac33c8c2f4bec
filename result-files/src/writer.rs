//! The incremental HDF5 writer. The layout it produces is documented on the
//! parent module ([`crate::results`]); the names live in [`super::layout`].

use std::collections::HashSet;
use std::path::{Path, PathBuf};

use flexmech_integrators::record::StepRecord;

use hdf5::{Dataset, Extent, File, H5Type, Location};

use super::layout as names;

mod sensitivity;
use sensitivity::SensitivitySets;

/// Appended steps are held in memory and written together (one resize and
/// one write per dataset, then one flush of the file) when the oldest held
/// step is this old...
const WRITE_INTERVAL: std::time::Duration = std::time::Duration::from_secs(1);
/// ... or the held steps reach this many values (32 MiB), whichever first;
/// [`ResultWriter::flush`] and [`ResultWriter::finish`] write them at once.
const HELD_VALUES: usize = 1 << 22;

/// Rows per chunk of the time series (`T`, `T×3`, `T×4`).
const SERIES_CHUNK_ROWS: usize = 256;
/// Elements per chunk of the flat Newton residual history and its offsets.
const NEWTON_CHUNK: usize = 1024;
/// Upper bound on the rows (steps) per chunk of `/configuration/*`.
const CONFIG_CHUNK_ROWS: usize = 16;
/// Upper bound on the nodes per chunk of `/configuration/*`.
const CONFIG_CHUNK_NODES: usize = 16_384;
/// Slots of the (empty) chunk cache of a written dataset: HDF5's default.
const WRITER_CACHE_SLOTS: usize = 521;
/// Target size of one `/configuration/*` chunk. The written datasets have
/// no chunk cache ([`WRITER_CACHE_SLOTS`]) and no compression, so a write
/// of a few rows goes to their place in the chunk, with no read of the rest.
const CONFIG_CHUNK_BYTES: usize = 512 * 1024;

/// What a run is: written once, when the file is created.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RunMeta {
    /// The model file text; root attribute `model`.
    pub model_text: String,
    /// Integrator name; root attribute `integrator` (`"static"` for statics).
    pub integrator: String,
    /// Initial position of every node. Its length is the node count every
    /// [`StepRecord`] must match; displacements are measured from it.
    pub initial_positions: Vec<[f64; 3]>,
    /// Tracked nodes as `(label, node index)`: the label, verbatim, names the
    /// group `/nodes/<label>` holding `position`, `displacement` and `rotation`.
    pub tracked: Vec<(String, usize)>,
    /// Joint names in model order: `/joints/<name>` holds `angle`,
    /// `released_translation` and `constraint_error`. Every [`StepRecord`]
    /// must carry exactly this many joint records.
    pub joint_names: Vec<String>,
    /// Per joint, whether it has a released angle (`/joints/<name>/angle`
    /// is written only then); joints past the end of the list have one.
    pub joint_angles: Vec<bool>,
    /// Per joint, its master and slave node (indices into
    /// `/configuration`): attributes `master_node`, `slave_node` of
    /// `/joints/<name>` (omitted for joints past the end of the list).
    pub joint_nodes: Vec<[usize; 2]>,
    /// The command line that made the run; root attribute `command_line`
    /// (omitted when empty).
    pub command_line: String,
    /// Labels of the supported nodes (`Mechanism::supported_nodes` order):
    /// `/supports/<label>/reaction_force` and `reaction_moment`; every
    /// [`StepRecord`] must then carry as many support reactions.
    pub supports: Vec<String>,
    /// The mesh: `/mesh` (omitted when `None`).
    pub mesh: Option<super::mesh::MeshMeta>,
    /// The stress resultants to write under `/resultants` (omitted when
    /// `None`; see [`super::resultants`]).
    pub resultants: Option<super::resultants::ResultantsMeta>,
    /// The `[output] sensitivity` key paths as written: `/sensitivity/<key>`
    /// holds the derivatives of the tracked nodes' displacements and of the
    /// total energy; every [`StepRecord`] must then carry as many
    /// [`StepRecord::sensitivities`].
    pub sensitivity: Vec<String>,
}

/// Everything that can go wrong while writing a result file.
#[derive(Debug, thiserror::Error)]
pub enum ResultError {
    /// Another process holds the result file's lock: creating the file
    /// would truncate a result being written (or just finished) there.
    #[error(
        "{}: another process is writing this result file (its lock {} is held); wait for it \
         to finish, or write to another --out directory",
        .path.display(),
        .lock.display()
    )]
    Busy {
        /// The result file.
        path: PathBuf,
        /// The lock file beside it.
        lock: PathBuf,
    },
    /// The lock file beside the result could not be locked.
    #[error("{}: cannot lock the result file: {source}", .lock.display())]
    Lock {
        /// The lock file.
        lock: PathBuf,
        /// The system's error.
        #[source]
        source: std::io::Error,
    },
    /// The HDF5 library reported an error.
    #[error("{}: HDF5 error while {what}: {source}", .path.display())]
    Hdf5 {
        /// The result file.
        path: PathBuf,
        /// What was being done, naming the dataset or attribute.
        what: String,
        /// The library's error.
        #[source]
        source: hdf5::Error,
    },
    /// A step record does not match the run's meta data; nothing of the step
    /// was written and the writer stays usable.
    #[error(
        "{}: step {step} (0-based) has {found} {field}, but the run has {expected}",
        .path.display()
    )]
    RecordLength {
        /// The result file.
        path: PathBuf,
        /// Index of the rejected step (= steps written before it).
        step: usize,
        /// `"positions"`, `"quaternions"`, `"joints"`, `"support_reactions"`,
        /// `"velocities"` or `"angular_velocities"` (dynamics).
        field: &'static str,
        /// Length given by [`RunMeta`].
        expected: usize,
        /// Length found in the record.
        found: usize,
    },
    /// A tracked node refers to a node the run does not have.
    #[error(
        "{}: tracked node {label:?} refers to node {index}, but the run has {nodes} nodes",
        .path.display()
    )]
    NodeIndex {
        /// The result file.
        path: PathBuf,
        /// The tracked node's label.
        label: String,
        /// The out-of-range index.
        index: usize,
        /// Number of nodes (`initial_positions.len()`).
        nodes: usize,
    },
    /// A label or joint name cannot be used verbatim as a group name, or is
    /// used twice.
    #[error("{}: {kind} name {name:?} cannot name an HDF5 group: {reason}", .path.display())]
    InvalidName {
        /// The result file.
        path: PathBuf,
        /// `"node label"` or `"joint"`.
        kind: &'static str,
        /// The offending name.
        name: String,
        /// Why it is rejected.
        reason: &'static str,
    },
}

/// Attaches the file path and a description of the operation to HDF5 errors.
trait Context<T> {
    fn ctx(self, path: &Path, what: impl FnOnce() -> String) -> Result<T, ResultError>;
}

impl<T> Context<T> for hdf5::Result<T> {
    fn ctx(self, path: &Path, what: impl FnOnce() -> String) -> Result<T, ResultError> {
        self.map_err(|source| ResultError::Hdf5 {
            path: path.to_path_buf(),
            what: what(),
            source,
        })
    }
}

/// Rotation vector ψ (axis × angle, |ψ| ≤ π) of the unit quaternion
/// `q = (w, x, y, z)`.
///
/// The quaternion is normalised, its sign chosen so that `w ≥ 0` (q and −q
/// are the same rotation), and `ψ = 2·atan2(|v|, w)·v/|v|` with `v = (x, y, z)`;
/// for `|v| < 1e-4` the factor `2·atan2(|v|, w)/|v|` is replaced by its series
/// `(2/w)(1 − |v|²/(3w²))`, exact to rounding there. A zero or non-finite
/// quaternion gives NaNs.
pub fn rotation_vector(q: [f64; 4]) -> [f64; 3] {
    let norm = q.iter().map(|c| c * c).sum::<f64>().sqrt();
    if !(norm.is_finite() && norm > 0.0) {
        return [f64::NAN; 3];
    }
    let sign = if q[0] < 0.0 { -1.0 } else { 1.0 };
    let s = sign / norm;
    let (w, v) = (q[0] * s, [q[1] * s, q[2] * s, q[3] * s]);
    let sin_half = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    let factor = if sin_half < 1e-4 {
        // Here w = sqrt(1 − |v|²) > 0.99999999.
        2.0 / w * (1.0 - sin_half * sin_half / (3.0 * w * w))
    } else {
        2.0 * sin_half.atan2(w) / sin_half
    };
    [factor * v[0], factor * v[1], factor * v[2]]
}

use crate::table::{str_attr as create_str_attr, varlen};

fn set_str_attr(loc: &Location, name: &str, value: &str) -> hdf5::Result<()> {
    if loc.attr_names()?.iter().any(|n| n == name) {
        loc.attr(name)?.as_writer().write_scalar(&varlen(value))
    } else {
        create_str_attr(loc, name, value)
    }
}

fn create_group(
    file: &File,
    path: &Path,
    name: &str,
    description: &str,
) -> Result<(), ResultError> {
    let group = file
        .create_group(name)
        .ctx(path, || format!("creating group {name}"))?;
    create_str_attr(&group, names::ATTR_DESCRIPTION, description)
        .ctx(path, || format!("writing the description of {name}"))
}

/// Creates the scalar attribute `name` of `loc` holding `value`.
fn scalar_attr<T: H5Type>(loc: &Location, name: &str, value: T) -> hdf5::Result<()> {
    loc.new_attr::<T>()
        .shape(())
        .create(name)
        .and_then(|a| a.as_writer().write_scalar(&value))
}

/// The file being created, for making its groups and datasets (errors name
/// `path`).
#[derive(Clone, Copy)]
struct Creator<'a> {
    file: &'a File,
    path: &'a Path,
}

impl Creator<'_> {
    /// A group with its description (see [`create_group`]).
    fn group(self, name: &str, description: &str) -> Result<(), ResultError> {
        create_group(self.file, self.path, name, description)
    }

    /// A group with its description and the `u64` scalar attributes
    /// `attrs` (`(name, value)`, e.g. a node or joint index).
    fn indexed_group(
        self,
        group: &str,
        description: &str,
        attrs: &[(&str, usize)],
    ) -> Result<(), ResultError> {
        self.group(group, description)?;
        let g = self
            .file
            .group(group)
            .ctx(self.path, || format!("opening group {group}"))?;
        for &(attr, value) in attrs {
            scalar_attr(&g, attr, value as u64)
                .ctx(self.path, || format!("writing {group} attribute {attr}"))?;
        }
        Ok(())
    }

    /// A `T` or `T×n` series of `T`s ([`Series::time_series`]).
    fn series<T: H5Type>(
        self,
        name: &str,
        tail: &[usize],
        description: &str,
    ) -> Result<Series, ResultError> {
        Series::time_series::<T>(self.file, self.path, name, tail, description)
    }

    /// A `T` or `T×n` series of `f64`s.
    fn f64s(self, name: &str, tail: &[usize], description: &str) -> Result<Series, ResultError> {
        self.series::<f64>(name, tail, description)
    }

    /// A `T × count × width` series of `f64`s, chunked by rows of at most
    /// [`CONFIG_CHUNK_BYTES`].
    fn block(
        self,
        name: &str,
        count: usize,
        width: usize,
        description: &str,
    ) -> Result<Series, ResultError> {
        let count_chunk = count.clamp(1, CONFIG_CHUNK_NODES);
        let rows = (CONFIG_CHUNK_BYTES / (count_chunk * width * 8)).clamp(1, CONFIG_CHUNK_ROWS);
        let chunk = [rows, count_chunk, width];
        Series::create::<f64>(
            self.file,
            self.path,
            name,
            0,
            &[count, width],
            &chunk,
            description,
        )
    }
}

/// One extendable dataset: rows along the first (unlimited) dimension, fixed
/// trailing dimensions.
struct Series {
    ds: Dataset,
    name: String,
    tail: Vec<usize>,
}

impl Series {
    /// Creates `name` with `rows` rows of shape `tail`, chunked as `chunk`.
    fn create<T: H5Type>(
        file: &File,
        path: &Path,
        name: &str,
        rows: usize,
        tail: &[usize],
        chunk: &[usize],
        description: &str,
    ) -> Result<Self, ResultError> {
        let mut extents = Vec::with_capacity(1 + tail.len());
        extents.push(Extent::new(rows, None));
        // A zero-length fixed dimension cannot be chunked; leave it unlimited.
        extents.extend(tail.iter().map(|&d| Extent::new(d, (d > 0).then_some(d))));
        let ds = file
            .new_dataset::<T>()
            .shape(extents)
            .chunk(chunk.to_vec())
            // Every row is written before it is read (a failed write's rows
            // are trimmed by `finish`): no zero-filling of new chunks.
            .fill_time(hdf5::plist::dataset_create::FillTime::Never)
            // No chunk cache: the chunks are not compressed, so a write goes
            // straight to its place in the file. Through the cache, HDF5
            // allocated and zeroed every chunk a write covers before
            // copying the rows in (for the 512-element cantilever's 100
            // steps, 28 chunks of 200–260 kB: 1 500 page faults).
            .chunk_cache(WRITER_CACHE_SLOTS, 0, 1.0)
            .create(name)
            .ctx(path, || format!("creating dataset {name}"))?;
        create_str_attr(&ds, names::ATTR_DESCRIPTION, description)
            .ctx(path, || format!("writing the description of {name}"))?;
        Ok(Self {
            ds,
            name: name.to_owned(),
            tail: tail.to_vec(),
        })
    }

    /// A `T` or `T×n` series, chunked by [`SERIES_CHUNK_ROWS`].
    fn time_series<T: H5Type>(
        file: &File,
        path: &Path,
        name: &str,
        tail: &[usize],
        description: &str,
    ) -> Result<Self, ResultError> {
        let mut chunk = vec![SERIES_CHUNK_ROWS];
        chunk.extend(tail.iter().map(|&d| d.max(1)));
        Self::create::<T>(file, path, name, 0, tail, &chunk, description)
    }

    /// Sets the number of rows (grows or shrinks).
    fn set_rows(&self, rows: usize, path: &Path) -> Result<(), ResultError> {
        let mut shape = Vec::with_capacity(1 + self.tail.len());
        shape.push(rows);
        shape.extend_from_slice(&self.tail);
        self.ds
            .resize(shape)
            .ctx(path, || format!("resizing {} to {rows} rows", self.name))
    }

    /// Writes `values` into rows `start..start + values.len()` of a 1-D dataset.
    fn write_values<T: H5Type>(
        &self,
        start: usize,
        values: &[T],
        path: &Path,
    ) -> Result<(), ResultError> {
        self.ds
            .write_slice(values, start..start + values.len())
            .ctx(path, || format!("writing row {start} of {}", self.name))
    }

    /// Extends a 1-D series to `t + values.len()` rows and writes `values`
    /// from row `t`.
    fn push_scalars<T: H5Type>(
        &self,
        t: usize,
        values: &[T],
        path: &Path,
    ) -> Result<(), ResultError> {
        self.set_rows(t + values.len(), path)?;
        self.write_values(t, values, path)
    }

    /// Extends a `T×N` series to `t + rows.len()` rows and writes `rows` from
    /// row `t`.
    fn push_rows<const N: usize>(
        &self,
        t: usize,
        rows: &[[f64; N]],
        path: &Path,
    ) -> Result<(), ResultError> {
        self.set_rows(t + rows.len(), path)?;
        self.ds
            .write_slice::<_, f64, _, _>(rows, (t..t + rows.len(), ..))
            .ctx(path, || format!("writing rows {t}.. of {}", self.name))
    }

    /// Extends a `T×n×N` series by `blocks.len()` rows from row `t`, each
    /// block `n` rows of `N`, gathered in `flat` (scratch: one buffer for
    /// every series of a write, whose pages are then touched once).
    fn push_blocks<const N: usize>(
        &self,
        t: usize,
        blocks: &[&[[f64; N]]],
        flat: &mut Vec<f64>,
        path: &Path,
    ) -> Result<(), ResultError> {
        self.set_rows(t + blocks.len(), path)?;
        let Some(n) = blocks.first().map(|b| b.len()) else {
            return Ok(());
        };
        // One contiguous slab for all the rows: one write, not one per row.
        flat.clear();
        for b in blocks {
            flat.extend_from_slice(b.as_flattened());
        }
        let rows = || format!("writing rows {t}.. of {}", self.name);
        let view = ndarray::ArrayView3::from_shape((blocks.len(), n, N), &flat[..])
            .map_err(|e| hdf5::Error::from(e.to_string()))
            .ctx(path, rows)?;
        self.ds
            .write_slice(view, (t..t + blocks.len(), .., ..))
            .ctx(path, rows)
    }
}

/// A 1-D series and the value of a record that goes into it.
type Column<'a, T> = (&'a Series, fn(&StepRecord) -> T);

/// Extends each 1-D series of `columns` by one value per record: the
/// value its function takes from the record.
fn push_columns<T: H5Type>(
    t0: usize,
    recs: &[StepRecord],
    path: &Path,
    columns: &[Column<'_, T>],
) -> Result<(), ResultError> {
    for &(series, value) in columns {
        let values: Vec<T> = recs.iter().map(value).collect();
        series.push_scalars(t0, &values, path)?;
    }
    Ok(())
}

/// Extends a force and a moment series by the rows of `reactions`
/// (`(force, moment)` each).
fn push_reactions(
    [force, moment]: [&Series; 2],
    t0: usize,
    reactions: impl Iterator<Item = [f64; 6]>,
    path: &Path,
) -> Result<(), ResultError> {
    let (f, m) = force_moment(reactions);
    force.push_rows(t0, &f, path)?;
    moment.push_rows(t0, &m, path)
}

/// `/energy/*`.
struct EnergySets {
    kinetic: Series,
    strain: Series,
    potential: Series,
    total: Series,
    driver_work: Series,
    dissipated: Series,
}

impl EnergySets {
    /// Creates the energy datasets (the group exists).
    fn create(c: Creator<'_>) -> Result<Self, ResultError> {
        Ok(Self {
            kinetic: c.f64s(names::ENERGY_KINETIC, &[], "kinetic energy")?,
            strain: c.f64s(names::ENERGY_STRAIN, &[], "strain energy")?,
            potential: c.f64s(
                names::ENERGY_POTENTIAL,
                &[],
                "potential of gravity and dead external loads",
            )?,
            total: c.f64s(names::ENERGY_TOTAL, &[], "kinetic + strain + potential")?,
            driver_work: c.f64s(
                names::ENERGY_DRIVER_WORK,
                &[],
                "work done by driven joint coordinates and prescribed DOFs since t = 0",
            )?,
            dissipated: c.f64s(
                names::ENERGY_DISSIPATED,
                &[],
                "energy dissipated by structural damping since t = 0 (in potential and total)",
            )?,
        })
    }
}

/// `/solver/*`.
struct SolverSets {
    iterations: Series,
    factorizations: Series,
    dt: Series,
    residual: Series,
    beta: Series,
    /// Statics only.
    negative_pivots: Option<Series>,
    newton_residuals: Series,
    newton_offsets: Series,
}

impl SolverSets {
    /// Creates the solver datasets (the group exists), `negative_pivots`
    /// for `statics` only, and writes the first Newton offset (0).
    fn create(c: Creator<'_>, statics: bool) -> Result<Self, ResultError> {
        let sets = Self {
            iterations: c.series::<u64>(
                names::SOLVER_ITERATIONS,
                &[],
                "Newton iterations of the step",
            )?,
            factorizations: c.series::<u64>(
                names::SOLVER_FACTORIZATIONS,
                &[],
                "tangent factorisations of the step",
            )?,
            dt: c.f64s(
                names::SOLVER_DT,
                &[],
                "step size actually used (after halvings)",
            )?,
            residual: c.f64s(names::SOLVER_RESIDUAL, &[], "final scaled residual norm")?,
            beta: c.f64s(
                names::SOLVER_BETA,
                &[],
                "energy-momentum beta of the step (NaN for other integrators)",
            )?,
            negative_pivots: statics
                .then(|| {
                    c.series::<i64>(
                        names::SOLVER_NEGATIVE_PIVOTS,
                        &[],
                        "number of negative eigenvalues of the converged reduced tangent (negative \
                         pivots of its LDLT factorisation); > 0: the equilibrium is unstable; -1: \
                         undefined (a zero pivot)",
                    )
                })
                .transpose()?,
            newton_residuals: Series::create::<f64>(
                c.file,
                c.path,
                names::SOLVER_NEWTON_RESIDUALS,
                0,
                &[],
                &[NEWTON_CHUNK],
                "scaled residual after each Newton iteration (first: before the first solve), \
                 all steps concatenated; see newton_offsets",
            )?,
            newton_offsets: Series::create::<u64>(
                c.file,
                c.path,
                names::SOLVER_NEWTON_OFFSETS,
                1,
                &[],
                &[NEWTON_CHUNK],
                "T+1 offsets: step k's residuals are newton_residuals[offsets[k]..offsets[k+1]]",
            )?,
        };
        sets.newton_offsets.write_values(0, &[0_u64], c.path)?;
        Ok(sets)
    }

    /// Writes the step statistics of `recs` from row `t0`.
    fn write(&self, t0: usize, recs: &[StepRecord], path: &Path) -> Result<(), ResultError> {
        push_columns::<u64>(
            t0,
            recs,
            path,
            &[
                (&self.iterations, |r| r.iterations as u64),
                (&self.factorizations, |r| r.factorizations as u64),
            ],
        )?;
        push_columns::<f64>(
            t0,
            recs,
            path,
            &[
                (&self.dt, |r| r.dt),
                (&self.residual, |r| r.residual),
                (&self.beta, |r| r.beta),
            ],
        )?;
        if let Some(set) = &self.negative_pivots {
            push_columns::<i64>(
                t0,
                recs,
                path,
                &[(set, |r| r.negative_pivots.map_or(-1, |n| n as i64))],
            )?;
        }
        Ok(())
    }

    /// Appends the Newton residual histories of `recs` (steps `t0..`) after
    /// the `newton_len` residuals in the file, and their offsets.
    fn write_newton(
        &self,
        t0: usize,
        newton_len: usize,
        recs: &[StepRecord],
        path: &Path,
    ) -> Result<(), ResultError> {
        let history: Vec<f64> = recs
            .iter()
            .flat_map(|r| r.residual_history.iter().copied())
            .collect();
        let mut end = newton_len;
        let offsets: Vec<u64> = recs
            .iter()
            .map(|r| {
                end += r.residual_history.len();
                end as u64
            })
            .collect();
        self.newton_residuals.set_rows(end, path)?;
        self.newton_residuals
            .write_values(newton_len, &history, path)?;
        self.newton_offsets.set_rows(t0 + recs.len() + 1, path)?;
        self.newton_offsets.write_values(t0 + 1, &offsets, path)
    }
}

/// `/nodes/<label>/*` of one tracked node.
struct NodeSets {
    index: usize,
    position: Series,
    displacement: Series,
    rotation: Series,
}

impl NodeSets {
    /// Creates `/nodes/<label>` for node `index`: the group, its
    /// `node_index` attribute and its datasets.
    fn create(c: Creator<'_>, label: &str, index: usize) -> Result<Self, ResultError> {
        c.indexed_group(
            &names::node_group(label),
            "tracked node",
            &[(names::ATTR_NODE_INDEX, index)],
        )?;
        Ok(Self {
            index,
            position: c.f64s(
                &names::node_path(label, names::NODE_POSITION),
                &[3],
                "position of the node",
            )?,
            displacement: c.f64s(
                &names::node_path(label, names::NODE_DISPLACEMENT),
                &[3],
                "position minus initial position",
            )?,
            rotation: c.f64s(
                &names::node_path(label, names::NODE_ROTATION),
                &[3],
                "rotation vector (axis times angle, |psi| <= pi) of the node's triad",
            )?,
        })
    }

    /// Writes the node's rows of `recs` from row `t0`; `initial_positions`
    /// are the run's.
    fn write(
        &self,
        t0: usize,
        recs: &[StepRecord],
        initial_positions: &[[f64; 3]],
        path: &Path,
    ) -> Result<(), ResultError> {
        let p0 = initial_positions[self.index];
        let p: Vec<[f64; 3]> = recs.iter().map(|r| r.positions[self.index]).collect();
        let u: Vec<[f64; 3]> = p
            .iter()
            .map(|p| [p[0] - p0[0], p[1] - p0[1], p[2] - p0[2]])
            .collect();
        let rot: Vec<[f64; 3]> = recs
            .iter()
            .map(|r| rotation_vector(r.quaternions[self.index]))
            .collect();
        self.position.push_rows(t0, &p, path)?;
        self.displacement.push_rows(t0, &u, path)?;
        self.rotation.push_rows(t0, &rot, path)
    }
}

/// `/joints/<name>/*` of one joint.
struct JointSets {
    /// Absent for a joint without a released angle.
    angle: Option<Series>,
    reaction_force: Series,
    reaction_moment: Series,
    released_translation: Series,
    constraint_error: Series,
}

impl JointSets {
    /// Creates `/joints/<name>` for joint `index` of `meta`: the group, its
    /// index and (where known) master and slave node attributes, and its
    /// datasets (`angle` only for a joint with a released angle).
    fn create(
        c: Creator<'_>,
        meta: &RunMeta,
        index: usize,
        name: &str,
    ) -> Result<Self, ResultError> {
        let mut attrs = vec![(names::ATTR_JOINT_INDEX, index)];
        if let Some(nodes) = meta.joint_nodes.get(index) {
            attrs.push((names::ATTR_JOINT_MASTER_NODE, nodes[0]));
            attrs.push((names::ATTR_JOINT_SLAVE_NODE, nodes[1]));
        }
        c.indexed_group(&names::joint_group(name), "joint", &attrs)?;
        let has_angle = meta.joint_angles.get(index).copied().unwrap_or(true);
        Ok(Self {
            angle: if has_angle {
                Some(c.f64s(
                    &names::joint_path(name, names::JOINT_ANGLE),
                    &[],
                    "released angle psi",
                )?)
            } else {
                None
            },
            released_translation: c.f64s(
                &names::joint_path(name, names::JOINT_RELEASED_TRANSLATION),
                &[3],
                "released translation r_R in the master frame",
            )?,
            reaction_force: c.f64s(
                &names::joint_path(name, names::JOINT_REACTION_FORCE),
                &[3],
                "force the joint exerts on its slave node in the step's equations (NaN at t = 0)",
            )?,
            reaction_moment: c.f64s(
                &names::joint_path(name, names::JOINT_REACTION_MOMENT),
                &[3],
                "moment the joint exerts on its slave node in the step's equations (NaN at t = 0)",
            )?,
            constraint_error: c.f64s(
                &names::joint_path(name, names::JOINT_CONSTRAINT_ERROR),
                &[],
                "|r_s - r_m - L_m f(psi)| + |L_m^T L_s - exp(psi t^)|_F",
            )?,
        })
    }

    /// Writes joint `j`'s rows of `recs` from row `t0`.
    fn write(
        &self,
        j: usize,
        t0: usize,
        recs: &[StepRecord],
        path: &Path,
    ) -> Result<(), ResultError> {
        let of = |r: &StepRecord| r.joints[j];
        if let Some(angle) = &self.angle {
            let a: Vec<f64> = recs.iter().map(|r| of(r).angle).collect();
            angle.push_scalars(t0, &a, path)?;
        }
        let released: Vec<[f64; 3]> = recs.iter().map(|r| of(r).released_translation).collect();
        self.released_translation.push_rows(t0, &released, path)?;
        let error: Vec<f64> = recs.iter().map(|r| of(r).constraint_error).collect();
        self.constraint_error.push_scalars(t0, &error, path)?;
        push_reactions(
            [&self.reaction_force, &self.reaction_moment],
            t0,
            recs.iter().map(|r| of(r).reaction),
            path,
        )
    }
}

/// Creates `/supports/<label>` and its reaction force and moment datasets.
fn support_sets(c: Creator<'_>, label: &str) -> Result<[Series; 2], ResultError> {
    c.group(&format!("{}/{label}", names::SUPPORTS), "supported node")?;
    Ok([
        c.f64s(
            &names::support_path(label, names::JOINT_REACTION_FORCE),
            &[3],
            "force the supports exert on the node at its held DOFs (zero at free ones; \
             NaN at t = 0)",
        )?,
        c.f64s(
            &names::support_path(label, names::JOINT_REACTION_MOMENT),
            &[3],
            "moment the supports exert on the node at its held DOFs (zero at free ones; \
             NaN at t = 0)",
        )?,
    ])
}

/// `/configuration/*`: every node at every stored step.
struct ConfigurationSets {
    position: Series,
    quaternion: Series,
    /// Dynamics only: translational and angular velocities of every node.
    velocity: Option<[Series; 2]>,
}

impl ConfigurationSets {
    /// Creates the configuration datasets of `nodes` nodes (the group
    /// exists), the velocities for `dynamic` runs only.
    fn create(c: Creator<'_>, nodes: usize, dynamic: bool) -> Result<Self, ResultError> {
        Ok(Self {
            position: c.block(
                names::CONFIGURATION_POSITION,
                nodes,
                3,
                "position of every node at every stored step (T x nodes x 3)",
            )?,
            quaternion: c.block(
                names::CONFIGURATION_QUATERNION,
                nodes,
                4,
                "rotation of every node's triad from its initial configuration as a unit \
                 quaternion (w, x, y, z) (T x nodes x 4)",
            )?,
            velocity: if dynamic {
                Some([
                    c.block(
                        names::CONFIGURATION_VELOCITY,
                        nodes,
                        3,
                        "translational velocity of every node at every stored step (T x nodes x 3)",
                    )?,
                    c.block(
                        names::CONFIGURATION_ANGULAR_VELOCITY,
                        nodes,
                        3,
                        "angular velocity w = R W of every node's triad in spatial components \
                         (T x nodes x 3)",
                    )?,
                ])
            } else {
                None
            },
        })
    }

    /// Writes every node's rows of `recs` from row `t0`.
    fn write(&self, t0: usize, recs: &[StepRecord], path: &Path) -> Result<(), ResultError> {
        let blocks3 = |f: fn(&StepRecord) -> &[[f64; 3]]| recs.iter().map(f).collect::<Vec<_>>();
        let mut flat = Vec::new();
        self.position
            .push_blocks(t0, &blocks3(|r| &r.positions), &mut flat, path)?;
        let quaternions: Vec<&[[f64; 4]]> = recs.iter().map(|r| &r.quaternions[..]).collect();
        self.quaternion
            .push_blocks(t0, &quaternions, &mut flat, path)?;
        if let Some([v, w]) = &self.velocity {
            v.push_blocks(t0, &blocks3(|r| &r.velocities), &mut flat, path)?;
            w.push_blocks(t0, &blocks3(|r| &r.angular_velocities), &mut flat, path)?;
        }
        Ok(())
    }
}

/// Creates `/resultants`: the force and moment at every Gauss point of
/// `meta` (with the beams' ranges) and the points' arc lengths.
fn resultant_sets(
    c: Creator<'_>,
    meta: &super::resultants::ResultantsMeta,
) -> Result<[Series; 2], ResultError> {
    let (arc, offsets) = meta.points();
    let (file, path) = (c.file, c.path);
    let group = names::RESULTANTS;
    file.create_group(group)
        .ctx(path, || format!("creating group {group}"))?;
    let points = arc.len();
    let force = c.block(
        names::RESULTANTS_FORCE,
        points,
        3,
        "material stress resultant N = C_N Gamma (axial, shear 2, shear 3) at every \
         Gauss point, element order (T x G x 3)",
    )?;
    let moment = c.block(
        names::RESULTANTS_MOMENT,
        points,
        3,
        "material stress resultant M = C_M K (torsion, bending 2, bending 3) at every \
         Gauss point, element order (T x G x 3)",
    )?;
    super::resultants::write_ranges(&force.ds, meta, &offsets).ctx(path, || {
        "writing the beams' ranges of /resultants".to_owned()
    })?;
    file.new_dataset::<f64>()
        .shape([points])
        .create(names::RESULTANTS_ARC_LENGTH)
        .and_then(|ds| ds.write_raw(&arc))
        .ctx(path, || format!("writing {}", names::RESULTANTS_ARC_LENGTH))?;
    Ok([force, moment])
}

/// Writes the resultants of `recs` (by `meta`) into `[force, moment]` from
/// row `t0`.
fn write_resultants(
    [n, m]: &[Series; 2],
    meta: &super::resultants::ResultantsMeta,
    t0: usize,
    recs: &[StepRecord],
    path: &Path,
) -> Result<(), ResultError> {
    let (force, moment): (Vec<_>, Vec<_>) = recs.iter().map(|r| meta.of(r)).unzip();
    let force: Vec<&[[f64; 3]]> = force.iter().map(Vec::as_slice).collect();
    let moment: Vec<&[[f64; 3]]> = moment.iter().map(Vec::as_slice).collect();
    let mut flat = Vec::new();
    n.push_blocks(t0, &force, &mut flat, path)?;
    m.push_blocks(t0, &moment, &mut flat, path)
}

/// Every dataset handle of the file, kept open for the whole run.
struct Datasets {
    time: Series,
    energy: EnergySets,
    momentum_linear: Series,
    momentum_angular: Series,
    solver: SolverSets,
    nodes: Vec<NodeSets>,
    /// Per supported node: reaction force and moment.
    supports: Vec<[Series; 2]>,
    joints: Vec<JointSets>,
    configuration: ConfigurationSets,
    /// `[output] resultants = true`: force and moment at every Gauss point.
    resultants: Option<[Series; 2]>,
    /// `[output] sensitivity`: the derivatives, per key.
    sensitivity: SensitivitySets,
}

impl Datasets {
    /// Creates every dataset of the run `meta` with zero rows (the groups
    /// exist), in the file's order: `/time`, `/energy`, `/momentum`,
    /// `/solver`, `/nodes`, `/joints`, `/supports`, `/configuration`,
    /// `/resultants`.
    fn create(c: Creator<'_>, meta: &RunMeta) -> Result<Self, ResultError> {
        let time = c.f64s(
            names::TIME,
            &[],
            "time of each stored step (statics: load factor)",
        )?;
        let energy = EnergySets::create(c)?;
        let momentum_linear = c.f64s(names::MOMENTUM_LINEAR, &[3], "total linear momentum")?;
        let momentum_angular = c.f64s(
            names::MOMENTUM_ANGULAR,
            &[3],
            "total angular momentum about the origin",
        )?;
        let solver = SolverSets::create(c, meta.integrator == "static")?;
        let nodes = (meta.tracked.iter())
            .map(|(label, node)| NodeSets::create(c, label, *node))
            .collect::<Result<_, _>>()?;
        let joints = (meta.joint_names.iter().enumerate())
            .map(|(index, name)| JointSets::create(c, meta, index, name))
            .collect::<Result<_, _>>()?;
        let supports = (meta.supports.iter())
            .map(|label| support_sets(c, label))
            .collect::<Result<_, _>>()?;
        let configuration = ConfigurationSets::create(
            c,
            meta.initial_positions.len(),
            meta.integrator != "static",
        )?;
        let resultants = (meta.resultants.as_ref())
            .map(|r| resultant_sets(c, r))
            .transpose()?;
        let sensitivity = SensitivitySets::create(c, meta)?;
        Ok(Self {
            time,
            energy,
            momentum_linear,
            momentum_angular,
            solver,
            nodes,
            supports,
            joints,
            configuration,
            resultants,
            sensitivity,
        })
    }

    /// Every dataset with one row per step.
    fn per_step(&self) -> impl Iterator<Item = &Series> {
        let (e, s, c) = (&self.energy, &self.solver, &self.configuration);
        [
            &self.time,
            &e.kinetic,
            &e.strain,
            &e.potential,
            &e.total,
            &e.driver_work,
            &e.dissipated,
            &self.momentum_linear,
            &self.momentum_angular,
            &s.iterations,
            &s.factorizations,
            &s.dt,
            &s.residual,
            &s.beta,
            &c.position,
            &c.quaternion,
        ]
        .into_iter()
        .chain(c.velocity.iter().flatten())
        .chain(self.resultants.iter().flatten())
        .chain(s.negative_pivots.iter())
        .chain(
            self.nodes
                .iter()
                .flat_map(|n| [&n.position, &n.displacement, &n.rotation]),
        )
        .chain(self.joints.iter().flat_map(|j| {
            j.angle.iter().chain([
                &j.released_translation,
                &j.constraint_error,
                &j.reaction_force,
                &j.reaction_moment,
            ])
        }))
        .chain(self.supports.iter().flatten())
        .chain(self.sensitivity.series())
    }

    /// Writes `/time`, the energies and the momenta of `recs` from row `t0`.
    fn write_globals(
        &self,
        t0: usize,
        recs: &[StepRecord],
        path: &Path,
    ) -> Result<(), ResultError> {
        let e = &self.energy;
        push_columns::<f64>(
            t0,
            recs,
            path,
            &[
                (&self.time, |r| r.time),
                (&e.kinetic, |r| r.energy.kinetic),
                (&e.strain, |r| r.energy.strain),
                (&e.potential, |r| r.energy.potential),
                (&e.total, |r| r.energy.total),
                (&e.driver_work, |r| r.energy.driver_work),
                (&e.dissipated, |r| r.energy.dissipated),
            ],
        )?;
        let rows = |f: fn(&StepRecord) -> [f64; 3]| recs.iter().map(f).collect::<Vec<_>>();
        self.momentum_linear
            .push_rows(t0, &rows(|r| r.momentum_linear), path)?;
        self.momentum_angular
            .push_rows(t0, &rows(|r| r.momentum_angular), path)
    }
}

/// Writes a result file step by step (layout: see the [crate docs](crate)
/// documentation).
///
/// [`create`](Self::create) writes the root attributes with `status =
/// "running"` and empty datasets; every [`append`](Self::append) extends each
/// dataset by one row and flushes the file, so a run that dies leaves a valid
/// file holding every step appended so far; [`finish`](Self::finish) records
/// the final status and wall time and closes the file. Dropping the writer
/// without `finish` closes the file with `status = "running"`.
pub struct ResultWriter {
    path: PathBuf,
    file: File,
    /// The lock file beside the result, held (exclusively) while writing
    /// (`None` where no file can be made there: creating the result fails
    /// then anyway, with HDF5's reason).
    lock: Option<(std::fs::File, PathBuf)>,
    sets: Datasets,
    initial_positions: Vec<[f64; 3]>,
    resultants: Option<super::resultants::ResultantsMeta>,
    /// Steps in the file.
    steps: usize,
    newton_len: usize,
    /// An append failed part-way: some datasets may hold an extra row.
    inconsistent: bool,
    /// Appended steps not yet in the file, and their size in values.
    held: Vec<StepRecord>,
    held_values: usize,
    /// The restart state at the last appended step, written after the
    /// steps it belongs to.
    held_checkpoint: Option<flexmech_integrators::dynamics::Checkpoint>,
    /// When the file was last written.
    last_write: std::time::Instant,
    /// The held steps were due to be written when the last was appended
    /// (decided once per append, so that [`Self::wants_checkpoint`] and the
    /// write it announces agree).
    due: bool,
}

impl std::fmt::Debug for ResultWriter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ResultWriter")
            .field("path", &self.path)
            .field("nodes", &self.initial_positions.len())
            .field("tracked", &self.sets.nodes.len())
            .field("joints", &self.sets.joints.len())
            .field("steps", &self.steps)
            .finish_non_exhaustive()
    }
}

fn check_names<'a>(
    path: &Path,
    kind: &'static str,
    list: impl Iterator<Item = &'a str>,
) -> Result<(), ResultError> {
    let mut seen = HashSet::new();
    for name in list {
        let reason = names::invalid_name_reason(name)
            .or_else(|| (!seen.insert(name)).then_some("used twice"));
        if let Some(reason) = reason {
            return Err(ResultError::InvalidName {
                path: path.to_path_buf(),
                kind,
                name: name.to_owned(),
                reason,
            });
        }
    }
    Ok(())
}

/// Refuses a run whose labels or joint names cannot name groups, or whose
/// tracked node is out of range, before the file is touched.
fn check_meta(path: &Path, meta: &RunMeta) -> Result<(), ResultError> {
    let n_nodes = meta.initial_positions.len();
    check_names(
        path,
        "node label",
        meta.tracked.iter().map(|(l, _)| l.as_str()),
    )?;
    check_names(path, "joint", meta.joint_names.iter().map(String::as_str))?;
    check_names(
        path,
        "sensitivity key",
        meta.sensitivity.iter().map(String::as_str),
    )?;
    if let Some((label, index)) = meta.tracked.iter().find(|(_, i)| *i >= n_nodes) {
        return Err(ResultError::NodeIndex {
            path: path.to_path_buf(),
            label: label.clone(),
            index: *index,
            nodes: n_nodes,
        });
    }
    Ok(())
}

/// Writes the root attributes of a new file: what the run is, where and
/// when it was made, and `status = "running"`.
fn write_root_attributes(file: &File, path: &Path, meta: &RunMeta) -> Result<(), ResultError> {
    let created = super::mesh::utc_now();
    let mut attrs = vec![
        (names::ATTR_MODEL, meta.model_text.as_str()),
        (names::ATTR_INTEGRATOR, meta.integrator.as_str()),
        (names::ATTR_VERSION, env!("CARGO_PKG_VERSION")),
        (names::ATTR_GIT_REVISION, env!("FLEXMECH_GIT_REVISION")),
        (names::ATTR_CREATED, created.as_str()),
        (names::ATTR_UNITS, names::UNITS_NOTE),
        (names::ATTR_STATUS, names::STATUS_RUNNING),
    ];
    if !meta.command_line.is_empty() {
        attrs.push((names::ATTR_COMMAND_LINE, meta.command_line.as_str()));
    }
    for (name, value) in attrs {
        create_str_attr(file, name, value)
            .ctx(path, || format!("writing root attribute {name}"))?;
    }
    Ok(())
}

/// Creates the top-level groups with their descriptions, `/supports` only
/// when some node is supported.
fn create_groups(c: Creator<'_>, supports: bool) -> Result<(), ResultError> {
    let groups = [
        (
            names::ENERGY,
            "energies of the whole mechanism at the end of each step",
        ),
        (names::MOMENTUM, "total momenta at the end of each step"),
        (names::SOLVER, "solver statistics of each step"),
        (names::NODES, "tracked nodes, one group per label"),
        (names::JOINTS, "joints, one group per name, in model order"),
        (names::CONFIGURATION, "every node at every stored step"),
    ];
    for (name, description) in groups {
        c.group(name, description)?;
    }
    if supports {
        c.group(
            names::SUPPORTS,
            "supported nodes (a fixed or prescribed DOF), one group per label",
        )?;
    }
    Ok(())
}

impl ResultWriter {
    /// Creates (or truncates) the file at `path`, writes the root attributes
    /// `model`, `integrator`, `version` (this crate's version) and `status =
    /// "running"`, creates every dataset with zero rows, and flushes.
    ///
    /// Fails before touching the file if a label or joint name is empty,
    /// contains `/`, is `.` or is used twice, or if a tracked node index is
    /// out of range.
    pub fn create(path: &Path, meta: &RunMeta) -> Result<Self, ResultError> {
        check_meta(path, meta)?;
        // Lock before truncating: a second writer of the same file fails here
        // and leaves the first one's result intact.
        let lock = lock_result(path)?;
        // The default (earliest) file format on purpose: from the 1.10 format on,
        // a file left open by a killed writer cannot be reopened without
        // `h5clear`, and a killed run's file must stay readable.
        let file = File::create(path).ctx(path, || "creating the file".to_owned())?;
        write_root_attributes(&file, path, meta)?;
        if let Some(mesh) = &meta.mesh {
            super::mesh::write(&file, mesh, &meta.initial_positions)
                .ctx(path, || "writing /mesh".to_owned())?;
        }
        let c = Creator { file: &file, path };
        create_groups(c, !meta.supports.is_empty())?;
        let sets = Datasets::create(c, meta)?;
        file.flush().ctx(path, || "flushing the file".to_owned())?;
        Ok(Self {
            path: path.to_path_buf(),
            file,
            lock,
            sets,
            initial_positions: meta.initial_positions.clone(),
            resultants: meta.resultants.clone(),
            steps: 0,
            newton_len: 0,
            inconsistent: false,
            held: Vec::new(),
            held_values: 0,
            held_checkpoint: None,
            last_write: std::time::Instant::now(),
            due: false,
        })
    }

    /// Appends one step. Steps are written in batches: held in memory and
    /// written together (each dataset extended once, then the file flushed)
    /// when an append finds the file last written `WRITE_INTERVAL` (1 s) ago
    /// or the held steps at `HELD_VALUES` values — by the
    /// [`Self::checkpoint`] that follows it, or else by the next append —
    /// and by [`Self::flush`] and [`Self::finish`]. A process that dies therefore leaves a valid file
    /// holding every step up to the last write — at most about a second of
    /// the run is lost — and its restart state at the last of them.
    ///
    /// A record whose `positions`, `quaternions`, `joints` or (dynamics)
    /// velocities length differs
    /// from the [`RunMeta`] is rejected with [`ResultError::RecordLength`]
    /// before anything is held or written. If HDF5 fails part-way through a
    /// write, the steps stay held (the next write rewrites the same rows) and
    /// `finish` trims the file back to the steps written successfully.
    pub fn append(&mut self, step: &StepRecord) -> Result<(), ResultError> {
        self.check_record(step)?;
        self.hold(step.clone())
    }

    /// [`Self::append`] of a step handed over: held without a copy.
    pub fn append_owned(&mut self, step: StepRecord) -> Result<(), ResultError> {
        self.check_record(&step)?;
        self.hold(step)
    }

    /// [`ResultError::RecordLength`] where a field of `step` has a length
    /// other than the [`RunMeta`]'s.
    fn check_record(&self, step: &StepRecord) -> Result<(), ResultError> {
        let t = self.steps + self.held.len();
        let n_nodes = self.initial_positions.len();
        let lengths = [
            ("positions", n_nodes, step.positions.len()),
            ("quaternions", n_nodes, step.quaternions.len()),
            ("joints", self.sets.joints.len(), step.joints.len()),
            (
                "sensitivities",
                self.sets.sensitivity.keys(),
                step.sensitivities.len(),
            ),
        ];
        let supports = self.sets.supports.len();
        let found_supports = if supports == 0 {
            0
        } else {
            step.support_reactions.len()
        };
        let velocities = (self.sets.configuration.velocity.as_ref()).map_or(0, |_| n_nodes);
        let lengths = lengths.into_iter().chain([
            ("support_reactions", supports, found_supports),
            ("velocities", velocities, step.velocities.len()),
            (
                "angular_velocities",
                velocities,
                step.angular_velocities.len(),
            ),
        ]);
        for (field, expected, found) in lengths {
            if expected != found {
                return Err(ResultError::RecordLength {
                    path: self.path.clone(),
                    step: t,
                    field,
                    expected,
                    found,
                });
            }
        }
        Ok(())
    }

    /// Holds `step`, after writing the held steps first if they are due.
    fn hold(&mut self, step: StepRecord) -> Result<(), ResultError> {
        if self.due {
            self.flush()?;
        }
        self.held_values += record_values(&step);
        self.held.push(step);
        self.due = self.held_values >= HELD_VALUES || self.last_write.elapsed() >= WRITE_INTERVAL;
        Ok(())
    }

    /// Whether the held steps are due to be written: a
    /// [`Self::checkpoint`] now writes them with it; otherwise the next
    /// [`Self::append`] writes them first. A dynamic run builds its restart
    /// state only when this says so (and at its end), since only the state
    /// at the last step of a write is kept.
    pub fn wants_checkpoint(&self) -> bool {
        self.due || self.held.is_empty()
    }

    /// Writes the held steps and the restart state, and flushes the file:
    /// after it, the file holds every step appended so far.
    pub fn flush(&mut self) -> Result<(), ResultError> {
        if !self.held.is_empty() {
            match self.write_steps(self.steps, &self.held) {
                Ok(()) => {
                    self.steps += self.held.len();
                    self.newton_len += self
                        .held
                        .iter()
                        .map(|r| r.residual_history.len())
                        .sum::<usize>();
                    self.inconsistent = false;
                    self.held.clear();
                    self.held_values = 0;
                }
                Err(e) => {
                    self.inconsistent = true;
                    return Err(e);
                }
            }
        }
        if let Some(checkpoint) = self.held_checkpoint.take() {
            super::restart::write(&self.file, &checkpoint, &self.initial_positions)
                .ctx(&self.path, || {
                    "writing the restart state /restart".to_owned()
                })?;
        }
        self.last_write = std::time::Instant::now();
        self.due = false;
        self.file.flush().ctx(&self.path, || {
            format!("flushing after step {}", self.steps.saturating_sub(1))
        })
    }

    /// Writes `recs` as rows `t0..t0 + recs.len()` of every dataset.
    fn write_steps(&self, t0: usize, recs: &[StepRecord]) -> Result<(), ResultError> {
        let path = self.path.as_path();
        let s = &self.sets;
        s.write_globals(t0, recs, path)?;
        s.solver.write(t0, recs, path)?;
        s.solver.write_newton(t0, self.newton_len, recs, path)?;
        for node in &s.nodes {
            node.write(t0, recs, &self.initial_positions, path)?;
        }
        for (j, joint) in s.joints.iter().enumerate() {
            joint.write(j, t0, recs, path)?;
        }
        for (k, [force, moment]) in s.supports.iter().enumerate() {
            let reactions = recs.iter().map(|r| r.support_reactions[k]);
            push_reactions([force, moment], t0, reactions, path)?;
        }
        s.configuration.write(t0, recs, path)?;
        if let (Some(sets), Some(meta)) = (&s.resultants, &self.resultants) {
            write_resultants(sets, meta, t0, recs, path)?;
        }
        s.sensitivity.write(t0, recs, path)
    }

    /// Sets the root attributes `status` (`"completed"` or `"failed:
    /// <reason>"`, see [`layout::failed_status`](super::layout::failed_status))
    /// and `wall_time_s`, and closes the file. Returns its path.
    pub fn finish(mut self, status: &str, wall_time_s: f64) -> Result<PathBuf, ResultError> {
        // A write that fails here leaves the file trimmed to the steps
        // written before, with this status, and the error returned.
        let flushed = self.flush();
        let Self {
            path,
            file,
            lock,
            sets,
            steps,
            newton_len,
            inconsistent,
            ..
        } = self;
        if inconsistent {
            // Trim rows a failed append may have added.
            for series in sets.per_step() {
                series.set_rows(steps, &path)?;
            }
            sets.solver.newton_residuals.set_rows(newton_len, &path)?;
            sets.solver.newton_offsets.set_rows(steps + 1, &path)?;
        }
        set_str_attr(&file, names::ATTR_STATUS, status).ctx(&path, || {
            format!("writing root attribute {}", names::ATTR_STATUS)
        })?;
        scalar_attr(&file, names::ATTR_WALL_TIME, wall_time_s).ctx(&path, || {
            format!("writing root attribute {}", names::ATTR_WALL_TIME)
        })?;
        drop(sets);
        file.close().ctx(&path, || "closing the file".to_owned())?;
        flushed?;
        // The result is complete: release the lock and remove its file.
        if let Some((handle, lock_path)) = lock {
            drop(handle);
            let _ = std::fs::remove_file(lock_path);
        }
        Ok(path)
    }

    /// Writes the modes of a modal or buckling analysis (`/modes` or
    /// `/buckling`, see [`flexmech_integrators::modal::ModeSet`]); `joints`
    /// names the model's joints.
    pub fn modes(
        &mut self,
        set: &flexmech_integrators::modal::ModeSet,
        joints: &[String],
    ) -> Result<(), ResultError> {
        self.flush()?;
        super::modes::write(&self.file, set, joints)
            .ctx(&self.path, || "writing the modes".to_owned())
    }

    /// Writes how a static path ended: the root attribute `end_reason`
    /// (when given) and `/stability` with the located critical points.
    pub fn path_end(
        &mut self,
        reason: Option<&str>,
        critical: &[flexmech_integrators::critical::CriticalPoint],
    ) -> Result<(), ResultError> {
        self.flush()?;
        if let Some(reason) = reason {
            set_str_attr(&self.file, names::ATTR_END_REASON, reason).ctx(&self.path, || {
                format!("writing root attribute {}", names::ATTR_END_REASON)
            })?;
        }
        super::critical::write(&self.file, critical)
            .ctx(&self.path, || "writing /stability".to_owned())
    }

    /// Sets the root attribute `warnings`: what the run's checks found
    /// doubtful in a result that completed (e.g. an energy balance off by more
    /// than its threshold). Absent when there is nothing to say.
    pub fn warn(&mut self, text: &str) -> Result<(), ResultError> {
        set_str_attr(&self.file, names::ATTR_WARNINGS, text).ctx(&self.path, || {
            format!("writing root attribute {}", names::ATTR_WARNINGS)
        })
    }

    /// Writes the run's figures of merit as root attributes (see
    /// [`super::merit`]); called once, when the run ends.
    pub fn figures(&mut self, merit: &super::merit::Merit) -> Result<(), ResultError> {
        for (name, value) in merit.figures() {
            scalar_attr(&self.file, name, value)
                .ctx(&self.path, || format!("writing root attribute {name}"))?;
        }
        Ok(())
    }

    /// Sets the run's state at the step appended last as the restart state
    /// `/restart` (see [`super::restart`]), written with that step.
    pub fn checkpoint(
        &mut self,
        checkpoint: &flexmech_integrators::dynamics::Checkpoint,
    ) -> Result<(), ResultError> {
        self.held_checkpoint = Some(checkpoint.clone());
        if self.held.is_empty() || self.due {
            // Its step is in the file already, or the held steps are due.
            return self.flush();
        }
        Ok(())
    }

    /// Sets the root attributes `restarted_from` (the result file this run
    /// continues) and `restart_time` (the time it continues from).
    pub fn restarted_from(&mut self, result: &Path, time: f64) -> Result<(), ResultError> {
        set_str_attr(
            &self.file,
            names::ATTR_RESTARTED_FROM,
            &result.display().to_string(),
        )
        .ctx(&self.path, || {
            format!("writing root attribute {}", names::ATTR_RESTARTED_FROM)
        })?;
        scalar_attr(&self.file, names::ATTR_RESTART_TIME, time).ctx(&self.path, || {
            format!("writing root attribute {}", names::ATTR_RESTART_TIME)
        })
    }

    /// Number of steps appended (`T` once they are written; see
    /// [`Self::append`]).
    pub fn steps_written(&self) -> usize {
        self.steps + self.held.len()
    }

    /// Path of the file being written.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

/// Reactions `(force, moment)` split into the force rows and the moment rows.
fn force_moment(reactions: impl Iterator<Item = [f64; 6]>) -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
    reactions
        .map(|r| ([r[0], r[1], r[2]], [r[3], r[4], r[5]]))
        .unzip()
}

/// Values a record holds, for the bound on held steps ([`HELD_VALUES`]).
fn record_values(r: &StepRecord) -> usize {
    32 + r.residual_history.len()
        + 3 * r.positions.len()
        + 4 * r.quaternions.len()
        + 3 * (r.velocities.len() + r.angular_velocities.len())
        + 6 * r.support_reactions.len()
        + 11 * r.joints.len()
}

/// Takes the exclusive lock `<result>.lock` (an advisory lock the system
/// releases when the process ends, so a killed run leaves no stale lock).
fn lock_result(path: &Path) -> Result<Option<(std::fs::File, PathBuf)>, ResultError> {
    let mut name = path.as_os_str().to_owned();
    name.push(".lock");
    let lock = PathBuf::from(name);
    let Ok(handle) = std::fs::OpenOptions::new()
        .create(true)
        .truncate(false)
        .write(true)
        .open(&lock)
    else {
        return Ok(None);
    };
    match handle.try_lock() {
        Ok(()) => Ok(Some((handle, lock))),
        Err(std::fs::TryLockError::WouldBlock) => Err(ResultError::Busy {
            path: path.to_path_buf(),
            lock,
        }),
        Err(std::fs::TryLockError::Error(source)) => Err(ResultError::Lock { lock, source }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A written dataset has no chunk cache: through one, HDF5 allocates and
    /// zeroes every chunk a write covers before copying the rows in.
    #[test]
    fn written_datasets_have_no_chunk_cache() {
        let name = format!("flexmech-writer-cache-{}.h5", std::process::id());
        let path = std::env::temp_dir().join(name);
        let file = File::create(&path).expect("a scratch file");
        let series = Series::create::<f64>(&file, &path, "s", 0, &[3], &[16, 3], "a series")
            .expect("the series");
        let dapl = series.ds.access_plist().expect("its access list");
        assert_eq!(dapl.chunk_cache().nbytes, 0);
        drop((series, file));
        std::fs::remove_file(&path).expect("the scratch file removed");
    }
}
