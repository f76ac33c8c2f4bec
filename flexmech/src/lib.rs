//! # flexmech
//!
//! Dynamics of flexible mechanisms: geometrically exact 3D beams
//! (Reissner–Simo) joined by joints that eliminate the slave's degrees of
//! freedom (the master–slave method), including joints whose released
//! translation depends on the released rotation, `r_R = f(ψ)` — screw,
//! rack-and-pinion, cam, and any profile you write. Statics, Newmark,
//! generalized-α, and the momentum-conserving and energy–momentum schemes;
//! HDF5 results, charts and parameter studies.
//!
//! This crate is the front door: `use flexmech::prelude::*;` brings what the
//! three jobs of a researcher need.
//!
//! ## 1. A new joint, used from a model file
//!
//! A joint kind is `f(ψ)` and its axis ([`DependentJoint`](prelude::DependentJoint));
//! automatic differentiation derives `N`, `G`, `Ñ` and the tangents. Its
//! model-file name and parameters make it a [`ModelJoint`](prelude::ModelJoint),
//! and an [`App`] that knows it reads model files naming it:
//!
//! ```
//! use flexmech::prelude::*;
//!
//! /// A screw whose pitch grows with the turn: f(ψ) = (c ψ + d ψ²) t.
//! #[derive(Debug)]
//! struct Auger { axis: Vector3<f64>, c: f64, d: f64 }
//!
//! impl DependentJoint for Auger {
//!     fn axis(&self) -> Vector3<f64> { self.axis }
//!     fn translation<T: Scalar>(&self, psi: T) -> Vector3<T> {
//!         self.axis.map(cst::<T>) * (psi * cst::<T>(self.c) + psi * psi * cst::<T>(self.d))
//!     }
//! }
//!
//! #[derive(Deserialize)]
//! struct AugerParams { axis: [f64; 3], c: f64, d: f64 }
//!
//! impl ModelJoint for Auger {
//!     const NAME: &'static str = "auger";
//!     type Params = AugerParams;
//!     fn from_params(p: AugerParams) -> Result<Self, ParamError> {
//!         Ok(Auger { axis: direction("axis", p.axis)?, c: p.c, d: p.d })
//!     }
//! }
//!
//! let app = App::new().joint::<Auger>();
//! let text = std::fs::read_to_string(flexmech::data("paper/screw_driven.toml")).unwrap()
//!     .replace("type = \"screw\"", "type = \"auger\"")
//!     .replace("pitch = 0.02", "c = 0.02\nd = 0.0");
//! let model = app.parse(&text, "auger.toml")?;
//! assert_eq!(model.joints[0].kind.type_name(), "auger");
//! // Without the kind, the error lists every kind the program knows.
//! let e = App::new().parse(&text, "auger.toml").unwrap_err().to_string();
//! assert!(e.contains("unknown joint type \"auger\"") && e.contains("rack_pinion"), "{e}");
//! // A misspelt kind: the list names every kind, the user's included.
//! let e = app.parse(&text.replace("\"auger\"", "\"augur\""), "a.toml").unwrap_err().to_string();
//! assert!(e.contains("did you mean \"auger\"?") && e.contains("\"expression\", \"auger\""), "{e}");
//! # Ok::<(), ModelError>(())
//! ```
//!
//! `flexmech/examples/joint.rs` is the whole job with an elliptical cam and
//! a shipped model file (`cargo run --release -p flexmech --example joint`);
//! with arguments the same binary is flexmech's command line with the cam
//! ([`App::main`]).
//!
//! ## A model in Rust, a run into memory
//!
//! [`Model::new`](prelude::Model::new) writes a model with a few calls and
//! reads it through the same checks as a model file; [`run`](fn@prelude::run)
//! hands its steps to a sink: the result file ([`run_model`](prelude::run_model)),
//! memory ([`Memory`](prelude::Memory)) or a closure ([`OnStep`](prelude::OnStep)).
//!
//! ```
//! use flexmech::prelude::*;
//!
//! let rod = SectionValues { ea: 1e7, ga: [1e6; 2], gj: 1e3, ei: [1e3; 2], rho_a: 0.0, rho_j: [0.0; 3] };
//! let arm = BeamGeometry::Straight { start: Vector3::zeros(), end: Vector3::x(), e2: Vector3::y() };
//! let model = Model::new("cantilever")
//!     .section("rod", rod)
//!     .beam("arm", "rod", arm, 10)
//!     .support("arm.start", "all")
//!     .load("arm.end", [0.0, 0.0, -0.1], [0.0; 3])
//!     .statics(1)
//!     .track("arm.end")
//!     .build()?;
//! let mut memory = Memory::default();
//! run(&model, &mut memory)?;
//! let tip = memory.positions("arm.end").unwrap();
//! // Timoshenko's F L³/(3EI) + F L/GA, less the 2-node element's
//! // trapezoidal-rule error F L³/(12 EI n²) (n = 10 elements).
//! let expected = 0.1 / 3e3 + 0.1 / 1e6 - 0.1 / (12.0 * 1e3 * 100.0);
//! assert!((tip.last().unwrap()[2] + expected).abs() < 1e-3 * expected);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! ## 2. A study over its parameter
//!
//! A [`Study`](prelude::Study) sweeps model keys (`joint.cam.b`,
//! `section.rod.EI[0]`, `solver.dt`) over a base model and runs every run in
//! parallel, one result file each, with a summary table and a chart per
//! figure; `flexmech/examples/study.rs`.
//!
//! ## 3. A chart for the paper
//!
//! [`StudyReport::overlay`](prelude::StudyReport::overlay) draws one result
//! across a study's runs, labelled by their swept values;
//! [`LineChart`](prelude::LineChart) writes PNG, SVG and an editable
//! PGFPlots copy; `flexmech/examples/plot.rs`.
//!
//! ## Features
//!
//! `hdf5` (result files), `plot` (charts), `studies` and `cli` (the command
//! line, the `flexmech` binary); all on by default. A crate that only
//! defines joints needs none of them: `flexmech = { default-features = false }`
//! brings the model, the joints and the solvers.
//!
//! The book (`docs/book/` in the repository) has the tutorials, the
//! formulation and the model and result formats.

#![warn(missing_docs)]

mod app;
pub mod prelude;

pub use app::App;

pub use flexmech_core as core;
pub use flexmech_integrators as integrators;
pub use flexmech_joints as joints;
pub use flexmech_model as model;

#[cfg(feature = "cli")]
pub use flexmech_cli as cli;
#[cfg(feature = "plot")]
pub use flexmech_plot as plot;
#[cfg(feature = "hdf5")]
pub use flexmech_results as results;
#[cfg(feature = "studies")]
pub use flexmech_studies as studies;

/// The book (`docs/book/` in the repository): tutorials, the model and
/// result formats, validation and performance. Built into the crate docs so
/// that `cargo test --doc` compiles and runs every code block it holds.
#[doc = include_str!("../../docs/book/README.md")]
pub mod book {
    #[doc = include_str!("../../docs/book/benchmarks.md")]
    pub mod benchmarks {}
    #[doc = include_str!("../../docs/book/getting-started.md")]
    pub mod getting_started {}
    #[doc = include_str!("../../docs/book/joints.md")]
    pub mod joints {}
    #[doc = include_str!("../../docs/book/linearised.md")]
    pub mod linearised {}
    #[doc = include_str!("../../docs/book/layout.md")]
    pub mod layout {}
    #[doc = include_str!("../../docs/book/model-files.md")]
    pub mod model_files {}
    #[doc = include_str!("../../docs/book/overview.md")]
    pub mod overview {}
    #[doc = include_str!("../../docs/book/paper-examples.md")]
    pub mod paper_examples {}
    #[doc = include_str!("../../docs/book/performance.md")]
    pub mod performance {}
    #[doc = include_str!("../../docs/book/python.md")]
    pub mod python {}
    #[doc = include_str!("../../docs/book/results.md")]
    pub mod results {}
    #[doc = include_str!("../../docs/book/stepping.md")]
    pub mod stepping {}
    #[doc = include_str!("../../docs/book/studies.md")]
    pub mod studies {}
    #[doc = include_str!("../../docs/book/validation.md")]
    pub mod validation {}
    #[doc = include_str!("../../docs/book/without-root.md")]
    pub mod without_root {}
}

/// A path under the `data/` folder of the flexmech source tree this crate
/// was built from: the paper's examples, benchmarks and example models
/// (`flexmech::data("paper/cam.toml")`).
pub fn data(relative: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../data")
        .join(relative)
}
