//! `flexmech.run`: one model run into its result file — the file the
//! command line writes, through the same engine and sink — read back whole.
//! Without an output directory the file lives in a temporary directory for
//! the time of the call.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use flexmech::integrators::dynamics::Checkpoint;
use flexmech::integrators::modal::ModeSet;
use flexmech::integrators::StepRecord;
use flexmech::model::Model;
use flexmech::results::{FileSink, RunEnd, RunError as RustRunError, RunMeta, Sink, SinkError};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::run_error;
use crate::h5read::read_file;
use crate::model::PyModel;
use flexmech::results::Contents;

/// How often a run looks for Ctrl-C (a pending signal of the interpreter).
const POLL: Duration = Duration::from_millis(200);

/// Watches for Ctrl-C while Rust works without the interpreter: at most
/// every [`POLL`], it attaches and asks the interpreter for pending
/// signals; the `KeyboardInterrupt` is kept to be raised when the work ends.
pub struct Interrupt {
    last: Instant,
    /// The interrupt, once seen.
    pub error: Option<PyErr>,
}

impl Default for Interrupt {
    fn default() -> Self {
        Self {
            last: Instant::now(),
            error: None,
        }
    }
}

impl Interrupt {
    /// Whether the user interrupted (checked at most every [`POLL`]).
    pub fn interrupted(&mut self) -> bool {
        if self.error.is_some() {
            return true;
        }
        if self.last.elapsed() < POLL {
            return false;
        }
        self.last = Instant::now();
        if let Err(e) = Python::attach(|py| py.check_signals()) {
            self.error = Some(e);
        }
        self.error.is_some()
    }
}

/// A sink that hands everything to `inner` and stops the run when the user
/// interrupts it (the file then ends `failed: interrupted …`).
pub struct Watched<S: Sink> {
    /// The sink written to.
    pub inner: S,
    /// The interrupt watch.
    pub interrupt: Interrupt,
}

impl<S: Sink> Watched<S> {
    /// The interrupt as the error that stops the run, if the user made it.
    fn watch(&mut self) -> Result<(), SinkError> {
        if self.interrupt.interrupted() {
            return Err(INTERRUPTED.into());
        }
        Ok(())
    }
}

/// The message a run stopped by Ctrl-C ends with.
pub const INTERRUPTED: &str = "interrupted by the user (KeyboardInterrupt)";

impl<S: Sink> Sink for Watched<S> {
    fn begin(&mut self, meta: &RunMeta) -> Result<(), SinkError> {
        self.inner.begin(meta)
    }

    fn step(&mut self, record: &StepRecord) -> Result<(), SinkError> {
        self.inner.step(record)?;
        self.watch()
    }

    fn take_step(&mut self, record: StepRecord) -> Result<(), SinkError> {
        self.inner.take_step(record)?;
        self.watch()
    }

    fn checkpoint(&mut self, state: &Checkpoint) -> Result<(), SinkError> {
        self.inner.checkpoint(state)
    }

    fn wants_checkpoint(&self) -> bool {
        self.inner.wants_checkpoint()
    }

    fn modes(&mut self, set: &ModeSet, joints: &[String]) -> Result<(), SinkError> {
        self.inner.modes(set, joints)
    }

    fn finish(&mut self, end: &RunEnd) -> Result<(), SinkError> {
        self.inner.finish(end)
    }

    fn file(&self) -> Option<&Path> {
        self.inner.file()
    }
}

/// What a run left: its file read back (when there is one), the error that
/// stopped it, and an interrupt.
pub struct Outcome {
    /// The result file's contents.
    pub contents: Option<Contents>,
    /// Why the run did not complete.
    pub error: Option<RustRunError>,
    /// Ctrl-C, to raise.
    pub interrupt: Option<PyErr>,
    /// A failure to read the file back.
    pub read_error: Option<String>,
}

/// Runs `model` into `file` (as `flexmech run` does, the ParaView series of
/// `[output] vtk = true` included when `vtk`) and reads the file back.
pub fn run_into(model: &Model, file: &Path, vtk: bool) -> Outcome {
    let mut sink = Watched {
        inner: FileSink::new(file),
        interrupt: Interrupt::default(),
    };
    let mut error = flexmech::results::run(model, &mut sink).err();
    if error.is_none() && vtk && model.output.vtk {
        let dir = file
            .parent()
            .filter(|d| !d.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        if let Err(e) = flexmech::results::export::export_vtk(file, dir, None) {
            error = Some(RustRunError::Export(e));
        }
    }
    let (contents, read_error) = if file.exists() {
        match read_file(file) {
            Ok(c) => (Some(c), None),
            Err(e) => (None, Some(e)),
        }
    } else {
        (None, None)
    };
    Outcome {
        contents,
        error,
        interrupt: sink.interrupt.error,
        read_error,
    }
}

/// The file of a run of `name` below `out`, or in a fresh temporary
/// directory (kept alive by the returned guard).
fn target(name: &str, out: Option<&Path>) -> std::io::Result<(PathBuf, Option<tempfile::TempDir>)> {
    match out {
        Some(dir) => Ok((dir.join(format!("{name}.h5")), None)),
        None => {
            let tmp = tempfile::Builder::new().prefix("flexmech-run-").tempdir()?;
            Ok((tmp.path().join(format!("{name}.h5")), Some(tmp)))
        }
    }
}

/// `(file, datasets, attributes, error)` of a run, for Python.
type RunOutput<'py> = (
    Option<String>,
    Bound<'py, PyDict>,
    Bound<'py, PyDict>,
    Option<String>,
);

/// Runs `model` (into `out/<name>.h5` when `out` is given) and returns
/// `(file, datasets, attributes, error)`: the result file's path (None
/// without `out`), its datasets and attributes, and the message of a solve
/// that stopped part-way (its partial result is the rest). Raises
/// `ModelError` for a model that cannot be built, `RunError` when the file
/// cannot be written or read, `KeyboardInterrupt` on Ctrl-C.
#[pyfunction]
#[pyo3(signature = (model, out = None))]
pub fn run_model<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyModel>,
    out: Option<PathBuf>,
) -> PyResult<RunOutput<'py>> {
    let rust_model = model.borrow_mut().checked(py)?;
    let (file, tmp) = target(&rust_model.name, out.as_deref())
        .map_err(|e| run_error(format!("cannot create a temporary directory: {e}")))?;
    let outcome = py.detach(|| {
        let outcome = run_into(&rust_model, &file, out.is_some());
        drop(tmp);
        outcome
    });
    let message = outcome_error(py, model, outcome.error, outcome.interrupt, out.is_some())?;
    if let Some(e) = outcome.read_error {
        return Err(run_error(e));
    }
    let Some(contents) = outcome.contents else {
        return Err(run_error(
            message.unwrap_or_else(|| "the run left no result file".into()),
        ));
    };
    let (datasets, attrs) = crate::h5read::into_py(contents, py)?;
    let file = out.map(|_| file.display().to_string());
    Ok((file, datasets, attrs, message))
}

/// The exception of a run's error, or the message of a solve failure
/// (which is a result, not an exception; `kept` says whether its file is
/// kept, which the message then names).
pub fn outcome_error(
    py: Python<'_>,
    model: &Bound<'_, PyModel>,
    error: Option<RustRunError>,
    interrupt: Option<PyErr>,
    kept: bool,
) -> PyResult<Option<String>> {
    if let Some(e) = interrupt {
        return Err(e);
    }
    match error {
        None => Ok(None),
        Some(e @ RustRunError::Solve { .. }) if kept => Ok(Some(e.to_string())),
        Some(RustRunError::Solve {
            model: name,
            path,
            error,
            ..
        }) => Ok(Some(format!(
            "{}: model \"{name}\": {error}",
            path.display()
        ))),
        Some(RustRunError::Model(e)) => Err(model.borrow().model_error(py, &e)),
        Some(e) => Err(run_error(e)),
    }
}
