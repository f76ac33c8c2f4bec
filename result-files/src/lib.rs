//! flexmech-results: HDF5 result files, written incrementally from a stream of
//! [`StepRecord`](flexmech_integrators::record::StepRecord)s.
//!
//! [`ResultWriter::create`] writes the root attributes and empty datasets,
//! [`ResultWriter::append`] takes one converged step (one row of every
//! dataset), and [`ResultWriter::finish`] writes the steps still held and
//! records the outcome. Steps are written in batches — at least once a second
//! of the run, each dataset extended once per batch, then the file flushed —
//! so a run that fails part-way leaves a valid file holding every step, and a
//! process that dies one holding every step up to its last write.
//!
//! # Layout
//!
//! This is the contract of `MODEL_FORMAT.md`, "Result file (HDF5)"; names are
//! never renamed (constants in [`layout`]). `T` is the number of appended
//! steps; datasets are `f64` unless noted, extendable along their first
//! dimension, and carry a `description` attribute.
//!
//! | path | shape | meaning |
//! |---|---|---|
//! | `/time` | T | time of each step (statics: load factor) |
//! | `/energy/kinetic`, `/energy/strain`, `/energy/potential`, `/energy/total` | T | energies |
//! | `/energy/driver_work` | T | work done by driven joint coordinates and prescribed DOFs since t = 0 (extension) |
//! | `/energy/dissipated` | T | energy dissipated by structural damping since t = 0, included in potential and total (extension) |
//! | `/momentum/linear`, `/momentum/angular` | T×3 | total momenta (angular about the origin) |
//! | `/solver/iterations` | T, `u64` | Newton iterations of the step |
//! | `/solver/factorizations` | T, `u64` | *extension:* tangent factorisations of the step (fewer than the iterations with `newton = "modified"`) |
//! | `/solver/dt` | T | step size actually used (after halvings) |
//! | `/solver/residual` | T | final scaled residual norm |
//! | `/solver/beta` | T | energy–momentum β (NaN for other integrators) |
//! | `/solver/negative_pivots` | T, `i64` | *extension, statics only:* negative eigenvalues of the converged reduced tangent (> 0: unstable equilibrium; −1: undefined) |
//! | `/solver/newton_residuals` | Σ iterations | *extension:* every step's scaled residual history, concatenated |
//! | `/solver/newton_offsets` | T+1, `u64` | *extension:* step k's history is `newton_residuals[offsets[k]..offsets[k+1]]`; `offsets[0] = 0` |
//! | `/nodes/<label>/position` | T×3 | tracked node's position |
//! | `/nodes/<label>/displacement` | T×3 | position − initial position |
//! | `/nodes/<label>/rotation` | T×3 | rotation vector of the node's triad, ‖ψ‖ ≤ π (see [`rotation_vector`]) |
//! | `/joints/<name>/angle` | T | released angle ψ |
//! | `/joints/<name>/released_translation` | T×3 | r_R in the master frame |
//! | `/joints/<name>/constraint_error` | T | ‖r_s − r_m − Λ_m f(ψ)‖ + ‖Λ_mᵀΛ_s − exp(ψ t̂)‖ |
//! | `/configuration/position` | T×nodes×3 | every node's position |
//! | `/configuration/quaternion` | T×nodes×4 | every node's triad as (w, x, y, z) |
//! | `/configuration/velocity` | T×nodes×3 | dynamics: every node's translational velocity |
//! | `/configuration/angular_velocity` | T×nodes×3 | dynamics: every node's angular velocity `ω = R W` (spatial) |
//! | `/sensitivity/<key>/nodes/<label>/displacement` | T×3 | `[output] sensitivity`: d(displacement)/dp of a tracked node, exact |
//! | `/sensitivity/<key>/energy/total` | T | d(total energy)/dp, exact |
//!
//! `<label>` and `<name>` are the tracked-node labels and joint names of
//! [`RunMeta`], used verbatim as group names (`arm.end`, `post.3`); they must
//! not be empty, be `.`, or contain `/`; `<key>` is an `[output]
//! sensitivity` key path as written (`section.rod.EI[0]`). Group `/nodes/<label>` has a `u64`
//! attribute `node_index`, group `/joints/<name>` a `u64` attribute
//! `joint_index` (extensions).
//!
//! Root attributes (UTF-8 strings unless noted):
//!
//! | attribute | value |
//! |---|---|
//! | `model` | the model file text (TOML) |
//! | `integrator` | integrator name (`"static"` for statics) |
//! | `version` | version of flexmech that wrote the file |
//! | `status` | `"running"` until [`ResultWriter::finish`], then `"completed"` or `"failed: <reason>"` |
//! | `wall_time_s` | `f64`, written by [`ResultWriter::finish`] |
//! | `energy_drift`, `max_displacement`, `newton_iterations`, `steps` | `f64`, the run's figures of merit over every converged step ([`merit`]) |
//!
//! A file whose `status` is still `"running"` comes from a process that
//! stopped without calling `finish`; it holds every step appended before.
//!
//! # Example
//!
//! ```no_run
//! use flexmech_results::{ResultWriter, RunMeta, layout};
//! # fn steps() -> Vec<flexmech_integrators::record::StepRecord> { Vec::new() }
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let meta = RunMeta {
//!     model_text: "# the TOML model".into(),
//!     integrator: "energy-momentum".into(),
//!     initial_positions: vec![[0.0; 3], [1.0, 0.0, 0.0]],
//!     tracked: vec![("arm.end".into(), 1)],
//!     joint_names: vec![],
//!     ..Default::default()
//! };
//! let mut writer = ResultWriter::create("run.h5".as_ref(), &meta)?;
//! for step in steps() {
//!     writer.append(&step)?;
//! }
//! writer.finish(layout::STATUS_COMPLETED, 1.5)?;
//! # Ok(())
//! # }
//! ```

pub mod checks;
pub mod contents;
mod critical;
pub mod export;
pub mod layout;
pub mod merit;
mod mesh;
mod modes;
pub mod reader;
pub mod restart;
pub mod resultants;
pub mod run;
pub mod sink;
pub mod stored_modes;
pub mod table;
mod writer;

pub use checks::RunChecks;
pub use contents::{read_contents, Array, Contents, Values};
pub use merit::Merit;
pub use mesh::MeshMeta;
pub use reader::{EnergyDrift, ReadError, ResultReader};
pub use restart::{read_checkpoint, RestartError};
pub use resultants::ResultantsMeta;
pub use run::{restart_model, restart_state, run, run_model, run_model_to, RunError, RunSummary};
pub use sink::{FileSink, Memory, OnStep, RunEnd, Sink, SinkError};
pub use stored_modes::{modes_of_result, StoredModes};
pub use writer::{rotation_vector, ResultError, ResultWriter, RunMeta};
