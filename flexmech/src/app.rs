//! [`App`]: the joint kinds a program knows, handed to every door that
//! reads a model — loading, studies and the command line. A value, not
//! process-wide state: two `App`s in one process may know different kinds.

use std::path::Path;

use flexmech_joints::ModelJoint;
use flexmech_model::{load_model_with, parse_model_with, JointRegistry, Model, ModelError};

/// The program's joint kinds: flexmech's nine, and those a researcher adds
/// with [`App::joint`].
///
/// ```
/// use flexmech::prelude::*;
///
/// let app = App::new();
/// let model = app.load(flexmech::data("paper/screw_free.toml"))?;
/// assert_eq!(model.joints[0].kind.type_name(), "screw");
/// # Ok::<(), ModelError>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct App {
    joints: JointRegistry,
}

impl Default for App {
    fn default() -> Self {
        Self::new()
    }
}

impl App {
    /// flexmech's own joint kinds ([`JointRegistry::builtin`]).
    pub fn new() -> Self {
        Self {
            joints: JointRegistry::builtin(),
        }
    }

    /// Adds the joint kind `J` under its model-file name
    /// ([`ModelJoint::NAME`]).
    ///
    /// # Panics
    /// If a kind of that name is already known, or the name is not lower
    /// case letters, digits and `_` — a mistake in the program, not in a
    /// model: [`App::try_joint`] returns it as an error instead.
    pub fn joint<J: ModelJoint>(self) -> Self {
        match self.try_joint::<J>() {
            Ok(app) => app,
            Err(e) => panic!("App::joint::<{}>(): {e}", std::any::type_name::<J>()),
        }
    }

    /// [`App::joint`], with a name that is taken or malformed as an error.
    pub fn try_joint<J: ModelJoint>(mut self) -> Result<Self, flexmech_model::RegistryError> {
        self.joints.register::<J>()?;
        Ok(self)
    }

    /// The joint kinds, for the crates' `*_with` functions.
    pub fn joints(&self) -> &JointRegistry {
        &self.joints
    }

    /// Reads and validates the model file at `path`.
    pub fn load(&self, path: impl AsRef<Path>) -> Result<Model, ModelError> {
        load_model_with(path.as_ref(), &self.joints)
    }

    /// Reads and validates model-file `text`; `path` names it in messages.
    pub fn parse(&self, text: &str, path: impl AsRef<Path>) -> Result<Model, ModelError> {
        parse_model_with(text, path.as_ref(), &self.joints)
    }

    /// A study over `base` whose runs read these joint kinds
    /// ([`flexmech_studies::Study::over`]).
    #[cfg(feature = "studies")]
    pub fn study(&self, name: &str, base: &Model) -> flexmech_studies::Study {
        flexmech_studies::Study::over(name, base).joints(&self.joints)
    }

    /// Reads and checks the study file at `path` (its base model with these
    /// joint kinds).
    #[cfg(feature = "studies")]
    pub fn load_study(
        &self,
        path: impl AsRef<Path>,
    ) -> Result<flexmech_studies::StudySpec, flexmech_studies::SpecError> {
        flexmech_studies::load_study_with(path.as_ref(), &self.joints)
    }

    /// The `flexmech` command line (`run`, `check`, `study`, `plot`,
    /// `export`, `animate`, `reproduce`, `bench`) of this process's
    /// arguments, reading model files with these joint kinds.
    #[cfg(feature = "cli")]
    pub fn main(self) -> std::process::ExitCode {
        flexmech_cli::main_with(self.joints)
    }

    /// The command line of `args` (the first is the program's name).
    #[cfg(feature = "cli")]
    pub fn main_with<I, T>(self, args: I) -> std::process::ExitCode
    where
        I: IntoIterator<Item = T>,
        T: Into<std::ffi::OsString> + Clone,
    {
        flexmech_cli::run_with(self.joints, args)
    }
}
