//! `/restart`: the exact state of a dynamic run at its last stored step
//! ([`Checkpoint`]), rewritten in place with each write of stored steps, so that
//! `flexmech run MODEL --restart RESULT.h5` can continue it.
//!
//! | path | shape | content |
//! |---|---|---|
//! | `/restart` attributes | scalars | `integrator`, `time`, `last_dt`, `driver_work`, `follower_work`, `step`, `level`, `easy` |
//! | `/restart/initial_positions` | nodes×3 | the mechanism's nodes at t = 0 (to check MODEL describes the same mechanism) |
//! | `/restart/positions` | nodes×3 | positions |
//! | `/restart/rotations` | nodes×3×3 | rotation matrices `R[i][row][col]` |
//! | `/restart/released` | joints×17 | per joint `q` (4), `q₀` (4), released rotation (9, column-major) |
//! | `/restart/prescribed` | P | current values of the prescribed nodal DOFs |
//! | `/restart/scheme` | K | the integrator's own values (velocities, accelerations, joint rates, drivers' reactions) |

use std::path::{Path, PathBuf};

use flexmech_integrators::dynamics::Checkpoint;
use flexmech_joints::MAX_RELEASED;
use hdf5::types::VarLenUnicode;
use hdf5::{File, Group, H5Type};
use nalgebra::{Matrix3, Vector3};
use thiserror::Error;

/// The group holding the checkpoint.
pub const RESTART: &str = "restart";

const ROW: usize = 2 * MAX_RELEASED + 9;

/// Why a result file cannot be continued.
#[derive(Debug, Error)]
pub enum RestartError {
    /// The file cannot be read.
    #[error("{}: cannot read the result file to restart from: {source}", .path.display())]
    Open {
        /// The result file.
        path: PathBuf,
        /// HDF5's reason.
        #[source]
        source: hdf5::Error,
    },
    /// The file holds no restart state.
    #[error(
        "{}: no /restart group: the file was written by a static analysis or by a flexmech \
         version without restarts; run the model again from t = 0",
        .path.display()
    )]
    Missing {
        /// The result file.
        path: PathBuf,
    },
    /// A dataset or attribute is missing or of the wrong shape.
    #[error("{}: /restart/{what}: {why}", .path.display())]
    Malformed {
        /// The result file.
        path: PathBuf,
        /// The dataset or attribute.
        what: String,
        /// What is wrong.
        why: String,
    },
}

/// Writes (or rewrites in place) `/restart` of `file` with `checkpoint` and the
/// mechanism's `initial_positions`.
pub(crate) fn write(
    file: &File,
    checkpoint: &Checkpoint,
    initial_positions: &[[f64; 3]],
) -> hdf5::Result<()> {
    let group = match file.group(RESTART) {
        Ok(g) => g,
        Err(_) => file.create_group(RESTART)?,
    };
    let c = checkpoint;
    for (name, value) in [
        ("time", c.time),
        ("last_dt", c.last_dt),
        ("driver_work", c.driver_work),
        ("follower_work", c.follower_work),
        ("step", c.step),
        ("level", c.level as f64),
        ("easy", c.easy as f64),
    ] {
        set_attr(&group, name, value)?;
    }
    let integrator: VarLenUnicode = c.integrator.parse().unwrap_or_default();
    if group.attr("integrator").is_err() {
        group
            .new_attr::<VarLenUnicode>()
            .shape(())
            .create("integrator")?;
    }
    group.attr("integrator")?.write_scalar(&integrator)?;
    let n = c.positions.len();
    let initial: Vec<f64> = initial_positions.iter().flatten().copied().collect();
    put(
        &group,
        "initial_positions",
        &[initial_positions.len(), 3],
        &initial,
    )?;
    let x: Vec<f64> = c.positions.iter().flat_map(|v| v.iter().copied()).collect();
    put(&group, "positions", &[n, 3], &x)?;
    let r: Vec<f64> = c
        .rotations
        .iter()
        .flat_map(|m| (0..3).flat_map(move |i| (0..3).map(move |j| m[(i, j)])))
        .collect();
    put(&group, "rotations", &[n, 3, 3], &r)?;
    let rows: Vec<f64> = c.released_rows().into_iter().flatten().collect();
    put(&group, "released", &[c.released.len(), ROW], &rows)?;
    put(&group, "prescribed", &[c.prescribed.len()], &c.prescribed)?;
    put(&group, "scheme", &[c.scheme.len()], &c.scheme)?;
    file.flush()
}

fn set_attr(group: &Group, name: &str, value: f64) -> hdf5::Result<()> {
    if group.attr(name).is_err() {
        group.new_attr::<f64>().shape(()).create(name)?;
    }
    group.attr(name)?.write_scalar(&value)
}

/// Writes `data` as dataset `name` of `shape`, in place when it exists with
/// that shape (the usual case: every stored step rewrites the same sizes).
fn put<T: H5Type>(group: &Group, name: &str, shape: &[usize], data: &[T]) -> hdf5::Result<()> {
    if let Ok(ds) = group.dataset(name) {
        if ds.shape() == shape {
            return ds.write_raw(data);
        }
        group.unlink(name)?;
    }
    group
        .new_dataset::<T>()
        .shape(shape)
        .create(name)?
        .write_raw(data)
}

/// The checkpoint stored in the result file `path`, and the initial node
/// positions of its mechanism.
pub fn read_checkpoint(path: &Path) -> Result<(Checkpoint, Vec<[f64; 3]>), RestartError> {
    let file = File::open(path).map_err(|source| RestartError::Open {
        path: path.to_path_buf(),
        source,
    })?;
    let Ok(group) = file.group(RESTART) else {
        return Err(RestartError::Missing {
            path: path.to_path_buf(),
        });
    };
    let bad = |what: &str, why: String| RestartError::Malformed {
        path: path.to_path_buf(),
        what: what.to_string(),
        why,
    };
    let attr = |name: &str| -> Result<f64, RestartError> {
        group
            .attr(name)
            .and_then(|a| a.read_scalar::<f64>())
            .map_err(|e| bad(name, e.to_string()))
    };
    let count = |name: &str| -> Result<usize, RestartError> {
        let x = attr(name)?;
        if x >= 0.0 && x.fract() == 0.0 && x < 1e9 {
            Ok(x as usize)
        } else {
            Err(bad(name, format!("not a count: {x}")))
        }
    };
    let data = |name: &str, width: &[usize]| -> Result<(usize, Vec<f64>), RestartError> {
        let ds = group.dataset(name).map_err(|e| bad(name, e.to_string()))?;
        let shape = ds.shape();
        if shape.len() != width.len() + 1 || shape[1..] != *width {
            return Err(bad(
                name,
                format!("shape {shape:?}, expected [_, {width:?}]"),
            ));
        }
        let values = ds.read_raw::<f64>().map_err(|e| bad(name, e.to_string()))?;
        if let Some(x) = values.iter().find(|x| !x.is_finite()) {
            return Err(bad(name, format!("holds {x}")));
        }
        Ok((shape[0], values))
    };
    let integrator = group
        .attr("integrator")
        .and_then(|a| a.read_scalar::<VarLenUnicode>())
        .map_err(|e| bad("integrator", e.to_string()))?
        .to_string();
    let (_, initial) = data("initial_positions", &[3])?;
    let (_, x) = data("positions", &[3])?;
    let (_, r) = data("rotations", &[3, 3])?;
    let (_, released) = data("released", &[ROW])?;
    let (_, prescribed) = data("prescribed", &[])?;
    let (_, scheme) = data("scheme", &[])?;
    let rows: Vec<[f64; ROW]> = released
        .chunks_exact(ROW)
        .map(|c| {
            let mut row = [0.0; ROW];
            row.copy_from_slice(c);
            row
        })
        .collect();
    let checkpoint = Checkpoint {
        integrator,
        time: attr("time")?,
        last_dt: attr("last_dt")?,
        driver_work: attr("driver_work")?,
        // Absent from files written before follower loads existed.
        follower_work: if group.attr("follower_work").is_ok() {
            attr("follower_work")?
        } else {
            0.0
        },
        step: attr("step")?,
        level: count("level")?,
        easy: count("easy")?,
        positions: x
            .chunks_exact(3)
            .map(|c| Vector3::new(c[0], c[1], c[2]))
            .collect(),
        rotations: r.chunks_exact(9).map(Matrix3::from_row_slice).collect(),
        released: Checkpoint::released_from_rows(&rows),
        prescribed,
        scheme,
    };
    let initial = initial
        .chunks_exact(3)
        .map(|c| [c[0], c[1], c[2]])
        .collect();
    Ok((checkpoint, initial))
}
