//! Binding the functions of a model's `[[rust_load]]` entries: load fields
//! written in Rust, which a model file names but cannot hold.
//!
//! ```
//! use flexmech_model::{BeamGeometry, Model, SectionValues};
//! use flexmech_integrators::dynamics::Integrator;
//! use nalgebra::Vector3;
//!
//! let rod = SectionValues { ea: 1e7, ga: [1e6; 2], gj: 1e3, ei: [1e3; 2], rho_a: 1.0, rho_j: [1e-3; 3] };
//! let straight = BeamGeometry::Straight { start: Vector3::zeros(), end: Vector3::x(), e2: Vector3::y() };
//! let model = Model::new("gust")
//!     .section("rod", rod)
//!     .beam("arm", "rod", straight, 4)
//!     .support("arm.start", "all")
//!     // a force along z of 2 sin(t) at the tip
//!     .rust_load("gust", &["arm.end"], |t, out| out[0][2] = 2.0 * t.sin())
//!     .dynamic(Integrator::EnergyMomentum, 0.01, 0.1)
//!     .build()?;
//! // The model file names the load and its nodes, and says where its function lives.
//! let text = model.to_toml();
//! assert!(text.starts_with("# Load fields written in Rust: gust."));
//! assert!(text.contains("[[rust_load]]"));
//! // Read back from text, the load has no function until the program binds it.
//! let mut again = flexmech_model::parse_model(&text, "gust.toml".as_ref())?;
//! assert!(flexmech_model::build(&again).unwrap_err().to_string().contains("bind_load"));
//! again.bind_load("gust", |t, out| out[0][2] = 2.0 * t.sin())?;
//! assert!(flexmech_model::build(&again).is_ok());
//! # Ok::<(), flexmech_model::ModelError>(())
//! ```

use crate::{LoadFn, Model, ModelError};

impl Model {
    /// Gives the `[[rust_load]]` named `name` its function `f(t, out)`
    /// (see [`crate::NodeLoadFn`]: row `k` of `out` is the force and moment
    /// on the load's `k`-th node). A model read from a file with
    /// `[[rust_load]]` entries runs, and restarts, only once each is bound.
    ///
    /// # Errors
    /// No `[[rust_load]]` is named `name` (the error lists the names).
    pub fn bind_load(
        &mut self,
        name: &str,
        f: impl Fn(f64, &mut [[f64; 6]]) + Send + Sync + 'static,
    ) -> Result<(), ModelError> {
        self.bind_load_fn(name, LoadFn::new(f))
    }

    /// [`Model::bind_load`] with a shared function.
    ///
    /// # Errors
    /// No `[[rust_load]]` is named `name`.
    pub fn bind_load_fn(&mut self, name: &str, f: LoadFn) -> Result<(), ModelError> {
        match self.rust_loads.iter_mut().find(|l| l.name == name) {
            Some(l) => {
                l.field = Some(f);
                Ok(())
            }
            None => {
                let names: Vec<String> = self
                    .rust_loads
                    .iter()
                    .map(|l| format!("\"{}\"", l.name))
                    .collect();
                let valid = if names.is_empty() {
                    "the model has no [[rust_load]] entries; add one with \
                     name and nodes (or ModelBuilder::rust_load)"
                        .to_string()
                } else {
                    format!("its rust loads are {}", names.join(", "))
                };
                Err(ModelError::new(
                    &self.path,
                    "rust_load",
                    None,
                    format!("no [[rust_load]] is named \"{name}\"; {valid}"),
                ))
            }
        }
    }
}
