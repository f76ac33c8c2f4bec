//! A model written in Rust with a few calls, read through the same checks
//! as a model file: [`Model::new`] starts a [`ModelBuilder`] that collects
//! the model-file tables, and [`ModelBuilder::build`] reads them with
//! [`crate::parse_model_with`] — one validation pass for files and Rust
//! alike, and the result file stores the model as text.
//!
//! ```
//! use flexmech_model::{BeamGeometry, Model, SectionValues};
//! use flexmech_integrators::dynamics::Integrator;
//! use nalgebra::Vector3;
//!
//! let rod = SectionValues { ea: 1e7, ga: [1e6; 2], gj: 1e3, ei: [1e3; 2], rho_a: 1.0, rho_j: [1e-3; 3] };
//! let model = Model::new("arm")
//!     .section("rod", rod)
//!     .beam("arm", "rod", BeamGeometry::Straight { start: Vector3::zeros(), end: Vector3::x(), e2: Vector3::y() }, 8)
//!     .support("arm.start", "all")
//!     .load("arm.end", [0.0, 0.0, -1.0], [0.0; 3])
//!     .dynamic(Integrator::EnergyMomentum, 0.01, 1.0)
//!     .track("arm.end")
//!     .build()?;
//! assert_eq!(model.beams[0].elements, 8);
//! # Ok::<(), flexmech_model::ModelError>(())
//! ```

use std::path::PathBuf;

use flexmech_integrators::dynamics::Integrator;
use toml::{Table, Value};

use crate::{
    parse_model_with, BeamGeometry, JointRegistry, LoadFn, Model, ModelError, SectionValues,
};

/// The model-file tables of a model being written in Rust (see the module
/// docs). Node names are the labels of model files (`arm.start`,
/// `arm.end`, `arm.3`).
#[derive(Debug, Clone)]
pub struct ModelBuilder {
    root: Table,
    /// A table that could not be read (its text), reported by `build`.
    refused: Option<(String, String)>,
    /// The functions of the `[[rust_load]]` tables, by name.
    fields: Vec<(String, LoadFn)>,
}

fn floats(values: &[f64]) -> Value {
    Value::Array(values.iter().map(|&x| Value::Float(x)).collect())
}

impl Model {
    /// A model named `name` (its result file is `<name>.h5`), built with
    /// [`ModelBuilder`]'s calls. (It returns the builder, not a model: a
    /// model exists only once checked, by [`ModelBuilder::build`].)
    #[allow(clippy::new_ret_no_self)]
    pub fn new(name: &str) -> ModelBuilder {
        let mut root = Table::new();
        root.insert("name".into(), Value::String(name.into()));
        ModelBuilder {
            root,
            refused: None,
            fields: Vec::new(),
        }
    }
}

impl ModelBuilder {
    fn push(mut self, array: &str, table: Table) -> Self {
        let entry = self
            .root
            .entry(array)
            .or_insert_with(|| Value::Array(Vec::new()));
        if let Value::Array(a) = entry {
            a.push(Value::Table(table));
        }
        self
    }

    fn set(mut self, table: &str, key: &str, value: Value) -> Self {
        let entry = self
            .root
            .entry(table)
            .or_insert_with(|| Value::Table(Table::new()));
        if let Value::Table(t) = entry {
            t.insert(key.into(), value);
        }
        self
    }

    /// Gravity's acceleration (it acts on ρA and the rigid bodies).
    pub fn gravity(mut self, g: [f64; 3]) -> Self {
        self.root.insert("gravity".into(), floats(&g));
        self
    }

    /// A `[[section]]` named `name`.
    pub fn section(self, name: &str, v: SectionValues) -> Self {
        let mut t = Table::new();
        t.insert("name".into(), Value::String(name.into()));
        t.insert("EA".into(), Value::Float(v.ea));
        t.insert("GA".into(), floats(&v.ga));
        t.insert("GJ".into(), Value::Float(v.gj));
        t.insert("EI".into(), floats(&v.ei));
        t.insert("rhoA".into(), Value::Float(v.rho_a));
        t.insert("rhoJ".into(), floats(&v.rho_j));
        self.push("section", t)
    }

    /// A `[[beam]]` of 2-node elements (its nodes are `name.start`,
    /// `name.1`, …, `name.end`).
    pub fn beam(self, name: &str, section: &str, geometry: BeamGeometry, elements: usize) -> Self {
        let beam = crate::BeamSpec {
            name: name.into(),
            section: 0,
            geometry,
            elements,
            nodes_per_element: 2,
        };
        self.push("beam", crate::write::beam_table(&beam, section))
    }

    /// A `[[support]]`: `fixed` is `"all"` or DOF names (`"ux"`, …, `"rz"`)
    /// separated by commas.
    pub fn support(self, node: &str, fixed: &str) -> Self {
        let mut t = Table::new();
        t.insert("node".into(), Value::String(node.into()));
        let fixed = if fixed.trim() == "all" {
            Value::String("all".into())
        } else {
            let names = fixed.split(',').map(|d| Value::String(d.trim().into()));
            Value::Array(names.collect())
        };
        t.insert("fixed".into(), fixed);
        self.push("support", t)
    }

    /// A `[[joint]]` of kind `kind` between `master` (a node or `"ground"`)
    /// and `slave`; `params` are its other keys as model-file text, e.g.
    /// `"axis = [0, 0, 1]\npitch = 0.1"`.
    pub fn joint(
        mut self,
        name: &str,
        kind: &str,
        master: &str,
        slave: &str,
        params: &str,
    ) -> Self {
        let mut t = match toml::from_str::<Table>(params) {
            Ok(t) => t,
            Err(e) => {
                let why = e.message().trim().to_owned();
                self.refused
                    .get_or_insert((format!("joint `{name}`: `{params}`"), why));
                Table::new()
            }
        };
        t.insert("name".into(), Value::String(name.into()));
        t.insert("type".into(), Value::String(kind.into()));
        t.insert("master".into(), Value::String(master.into()));
        t.insert("slave".into(), Value::String(slave.into()));
        self.push("joint", t)
    }

    /// A dead `[[load]]`: force and moment (global components) at `node`,
    /// ramped with the load factor in statics, constant in dynamics.
    pub fn load(self, node: &str, force: [f64; 3], moment: [f64; 3]) -> Self {
        let mut t = Table::new();
        t.insert("node".into(), Value::String(node.into()));
        t.insert("force".into(), floats(&force));
        t.insert("moment".into(), floats(&moment));
        self.push("load", t)
    }

    /// A load field written in Rust, `[[rust_load]]` named `name` on the
    /// nodes `nodes`: `f(t, out)` adds to row `k` of `out` the force and
    /// moment `[f₁, f₂, f₃, m₁, m₂, m₃]` (global axes) on `nodes[k]` at time
    /// `t` (statics: the load factor). The model's text names the load and
    /// says that the model runs and restarts only from a program that binds
    /// it ([`Model::bind_load`]).
    pub fn rust_load(
        mut self,
        name: &str,
        nodes: &[&str],
        f: impl Fn(f64, &mut [[f64; 6]]) + Send + Sync + 'static,
    ) -> Self {
        let mut t = Table::new();
        t.insert("name".into(), Value::String(name.into()));
        let labels = nodes.iter().map(|&n| Value::String(n.into())).collect();
        t.insert("nodes".into(), Value::Array(labels));
        self.fields.push((name.into(), LoadFn::new(f)));
        self.push("rust_load", t)
    }

    /// A `[[prescribed]]` released angle of joint `joint`: the expression
    /// `expr` of `t`.
    pub fn drive(self, joint: &str, expr: &str) -> Self {
        let mut t = Table::new();
        let mut f = Table::new();
        f.insert("expr".into(), Value::String(expr.into()));
        t.insert("joint".into(), Value::String(joint.into()));
        t.insert("angle".into(), Value::Table(f));
        self.push("prescribed", t)
    }

    /// Statics in `load_steps` equal load steps.
    pub fn statics(self, load_steps: usize) -> Self {
        let steps = Value::Integer(i64::try_from(load_steps).unwrap_or(i64::MAX));
        self.set("solver", "analysis", Value::String("static".into()))
            .set("solver", "load_steps", steps)
    }

    /// Time integration with `integrator`, steps of `dt` to `t_end`.
    pub fn dynamic(self, integrator: Integrator, dt: f64, t_end: f64) -> Self {
        let mut b = self
            .set("solver", "analysis", Value::String("dynamic".into()))
            .set(
                "solver",
                "integrator",
                Value::String(integrator.name().into()),
            )
            .set("solver", "dt", Value::Float(dt))
            .set("solver", "t_end", Value::Float(t_end));
        if let Integrator::GeneralizedAlpha { rho_inf } = integrator {
            b = b.set("solver", "rho_inf", Value::Float(rho_inf));
        }
        b
    }

    /// Any other `[solver]` key, as in model files (`tolerance`, `newton`,
    /// `mass`, …).
    pub fn solver(self, key: &str, value: impl Into<Value>) -> Self {
        self.set("solver", key, value.into())
    }

    /// Records the node `node` under `/nodes/<node>` of the result file.
    pub fn track(self, node: &str) -> Self {
        self.push_output("track", node)
    }

    /// Writes the exact derivatives of the results with respect to the
    /// model value at `key` (a key path such as `section.rod.EI[0]` or
    /// `load[0].force[2]`): `[output] sensitivity` of model files.
    pub fn sensitivity(self, key: &str) -> Self {
        self.push_output("sensitivity", key)
    }

    /// Appends `item` to the list `list` of `[output]`.
    fn push_output(mut self, list: &str, item: &str) -> Self {
        let output = self
            .root
            .entry("output")
            .or_insert_with(|| Value::Table(Table::new()));
        if let Value::Table(o) = output {
            let entries = o.entry(list).or_insert_with(|| Value::Array(Vec::new()));
            if let Value::Array(a) = entries {
                a.push(Value::String(item.into()));
            }
        }
        self
    }

    /// The model as model-file text.
    pub fn to_toml(&self) -> String {
        toml::to_string(&self.root).unwrap_or_default()
    }

    /// The model with flexmech's joint kinds, checked as a model file is.
    pub fn build(self) -> Result<Model, ModelError> {
        self.build_with(&JointRegistry::builtin())
    }

    /// The model with the joint kinds of `joints`, checked as a model file
    /// is; errors name the key (`joint[0].axis`) in the model's text.
    pub fn build_with(self, joints: &JointRegistry) -> Result<Model, ModelError> {
        let name = self.root.get("name").and_then(Value::as_str).unwrap_or("");
        let path = PathBuf::from(format!("{name} (built in Rust)"));
        if let Some((what, why)) = self.refused {
            return Err(ModelError::new(
                &path,
                "joint",
                None,
                format!("{what}: {why}"),
            ));
        }
        let mut model = parse_model_with(&self.to_toml(), &path, joints)?;
        for (name, f) in self.fields {
            model.bind_load_fn(&name, f)?;
        }
        if !model.rust_loads.is_empty() {
            model.source_text = model.to_toml();
        }
        model.source_written = model.to_toml();
        Ok(model)
    }
}
