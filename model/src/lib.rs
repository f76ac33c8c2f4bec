//! flexmech-model: model files: parse and validate a mechanism described in TOML (see
//! `MODEL_FORMAT.md`) into a [`Model`].
//!
//! ```no_run
//! use std::path::Path;
//! use flexmech_model::load_model;
//!
//! match load_model(Path::new("data/screw.toml")) {
//!     Ok(model) => println!("{} beams", model.beams.len()),
//!     // e.g. `data/screw.toml:12: key `solver.dt`: must be > 0, found -0.01`
//!     Err(e) => eprintln!("{e}"),
//! }
//! ```
//!
//! Every problem is reported as a [`ModelError`] naming the file, the key path
//! (`solver.dt`, `beam[2].elements`, `joint[0].slave`; array-of-tables entries
//! counted from 0), the line where known, and what was expected.

use std::path::Path;

pub mod build;
mod check;
pub mod error;
pub use flexmech_core::expr;
mod fluent;
mod initial_check;
pub mod key_path;
mod labels;
mod locate;
mod raw;
pub mod registry;
mod rust_loads;
pub mod time_function;
pub mod types;
mod validate;
mod write;

pub use build::{build, Built};
pub use error::ModelError;
pub use expr::{ExprError, Expression};
pub use fluent::ModelBuilder;
pub use registry::{JointKind, JointRegistry, RegistryError};
pub use types::*;

/// Reads and validates the model file at `path` with flexmech's own joint
/// kinds ([`JointRegistry::builtin`]). An unreadable file is a
/// [`ModelError`] naming the file.
pub fn load_model(path: &Path) -> Result<Model, ModelError> {
    load_model_with(path, &JointRegistry::builtin())
}

/// [`load_model`] with the joint kinds of `registry`.
pub fn load_model_with(path: &Path, registry: &JointRegistry) -> Result<Model, ModelError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| ModelError::new(path, "", None, format!("cannot read the model file: {e}")))?;
    parse_model_with(&text, path, registry)
}

/// Parses and validates model-file `text`; `path` is used only in error
/// messages and stored in [`Model::path`].
/// Joint types are flexmech's own ([`JointRegistry::builtin`]).
pub fn parse_model(text: &str, path: &Path) -> Result<Model, ModelError> {
    parse_model_with(text, path, &JointRegistry::builtin())
}

/// [`parse_model`] with the joint kinds of `registry`.
pub fn parse_model_with(
    text: &str,
    path: &Path,
    registry: &JointRegistry,
) -> Result<Model, ModelError> {
    if let Err(e) = toml::de::DeTable::parse(text) {
        return Err(locate::syntax_error(text, path, &e));
    }
    let raw: raw::RawModel =
        toml::from_str(text).map_err(|e| locate::deserialize_error(text, path, &e))?;
    validate::validate(raw, text, path, registry)
}
