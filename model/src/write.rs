//! The model written back as a model file: [`Model::to_toml`]. Reading the
//! text gives the same model (tested on every model file of `data/`), so a
//! model built or changed in Rust is stored in its result file, continued
//! and swept in studies like one read from a file.

use nalgebra::Vector3;
use toml::{Table, Value};

use crate::validate::DOFS as DOF_NAMES;
use crate::{
    Analysis, BeamGeometry, BeamSpec, IntegratorKind, MassKind, Model, NodeRef, PrescribedSpec,
    TimeFunction,
};

fn vec3(a: [f64; 3]) -> Value {
    Value::Array(a.iter().map(|&x| Value::Float(x)).collect())
}

fn vector(v: &Vector3<f64>) -> Value {
    vec3([v.x, v.y, v.z])
}

fn int(n: usize) -> Value {
    Value::Integer(i64::try_from(n).unwrap_or(i64::MAX))
}

/// A time function as model files write it: a number, `{ table = [...] }`
/// or `{ expr = "..." }`.
fn time_function(f: &TimeFunction) -> Value {
    let mut t = Table::new();
    match f {
        TimeFunction::Constant(c) => return Value::Float(*c),
        TimeFunction::Table(rows) => {
            let rows = rows.iter().map(|&(a, b)| vec3_2(a, b)).collect();
            t.insert("table".into(), Value::Array(rows));
        }
        TimeFunction::Expression(e) => {
            t.insert("expr".into(), Value::String(e.text().to_owned()));
        }
    }
    Value::Table(t)
}

fn vec3_2(a: f64, b: f64) -> Value {
    Value::Array(vec![Value::Float(a), Value::Float(b)])
}

/// Pushes `table` to the array of tables `key` of `root`.
fn push(root: &mut Table, key: &str, table: Table) {
    let entry = root.entry(key).or_insert_with(|| Value::Array(Vec::new()));
    if let Value::Array(a) = entry {
        a.push(Value::Table(table));
    }
}

/// A `[[beam]]` table: `b` made of the section named `section`.
pub(crate) fn beam_table(b: &BeamSpec, section: &str) -> Table {
    let mut t = Table::new();
    t.insert("name".into(), Value::String(b.name.clone()));
    t.insert("section".into(), Value::String(section.into()));
    match &b.geometry {
        BeamGeometry::Straight { start, end, e2 } => {
            t.insert("start".into(), vector(start));
            t.insert("end".into(), vector(end));
            t.insert("e2".into(), vector(e2));
        }
        BeamGeometry::Arc {
            start,
            center,
            normal,
            sweep,
            e2,
        } => {
            let mut arc = Table::new();
            arc.insert("start".into(), vector(start));
            arc.insert("center".into(), vector(center));
            arc.insert("normal".into(), vector(normal));
            arc.insert("sweep".into(), Value::Float(*sweep));
            t.insert("arc".into(), Value::Table(arc));
            if let Some(e2) = e2 {
                t.insert("e2".into(), vector(e2));
            }
        }
    }
    t.insert("elements".into(), int(b.elements));
    t.insert("nodes_per_element".into(), int(b.nodes_per_element));
    t
}

impl Model {
    /// The model as a model file (TOML, `MODEL_FORMAT.md`): parsing it with
    /// the same joint kinds gives this model back.
    pub fn to_toml(&self) -> String {
        let mut root = Table::new();
        root.insert("name".into(), Value::String(self.name.clone()));
        root.insert("gravity".into(), vec3(self.gravity));
        self.write_sections(&mut root);
        self.write_beams(&mut root);
        self.write_supports_and_joints(&mut root);
        self.write_loads(&mut root);
        self.write_motion(&mut root);
        root.insert("solver".into(), Value::Table(self.solver_table()));
        root.insert("output".into(), Value::Table(self.output_table()));
        let text = toml::to_string(&root).unwrap_or_default();
        if self.rust_loads.is_empty() {
            return text;
        }
        let names: Vec<&str> = self.rust_loads.iter().map(|l| l.name.as_str()).collect();
        format!(
            "# Load fields written in Rust: {}. This model runs and restarts only from\n\
             # a program that binds their functions (Model::bind_load).\n{text}",
            names.join(", ")
        )
    }

    /// The model text a result file stores: [`Model::source_text`] (the
    /// file's own words and comments) while the model still writes
    /// [`Model::source_written`] — it was not changed in Rust since it was
    /// read — and [`Model::to_toml`] otherwise, so the text always
    /// describes what ran.
    pub fn text(&self) -> String {
        let written = self.to_toml();
        if !self.source_text.is_empty() && written == self.source_written {
            self.source_text.clone()
        } else {
            written
        }
    }

    fn label(&self, node: NodeRef) -> Value {
        Value::String(self.node_label(node))
    }

    fn write_sections(&self, root: &mut Table) {
        for s in &self.sections {
            let v = &s.values;
            let mut t = Table::new();
            t.insert("name".into(), Value::String(s.name.clone()));
            t.insert("EA".into(), Value::Float(v.ea));
            t.insert("GA".into(), vec3_2(v.ga[0], v.ga[1]));
            t.insert("GJ".into(), Value::Float(v.gj));
            t.insert("EI".into(), vec3_2(v.ei[0], v.ei[1]));
            t.insert("rhoA".into(), Value::Float(v.rho_a));
            t.insert("rhoJ".into(), vec3(v.rho_j));
            if s.damping != 0.0 {
                t.insert("damping".into(), Value::Float(s.damping));
            }
            push(root, "section", t);
        }
    }

    fn write_beams(&self, root: &mut Table) {
        for b in &self.beams {
            let section = self.sections.get(b.section).map(|s| s.name.as_str());
            push(root, "beam", beam_table(b, section.unwrap_or_default()));
        }
    }

    fn write_supports_and_joints(&self, root: &mut Table) {
        for s in &self.supports {
            let mut t = Table::new();
            t.insert("node".into(), self.label(s.node));
            let fixed = if s.fixed == [true; 6] {
                Value::String("all".into())
            } else {
                let held = (0..6).filter(|&d| s.fixed[d]);
                Value::Array(held.map(|d| Value::String(DOF_NAMES[d].into())).collect())
            };
            t.insert("fixed".into(), fixed);
            push(root, "support", t);
        }
        for j in &self.joints {
            let mut t = Table::new();
            t.insert("name".into(), Value::String(j.name.clone()));
            t.insert("type".into(), Value::String(j.kind.type_name().into()));
            let master = j
                .master
                .map_or(Value::String("ground".into()), |m| self.label(m));
            t.insert("master".into(), master);
            t.insert("slave".into(), self.label(j.slave));
            if j.kind.has_angle() {
                t.insert("angle".into(), Value::Float(j.angle));
                t.insert("rate".into(), Value::Float(j.rate));
            }
            t.extend(j.kind.params().clone());
            push(root, "joint", t);
        }
    }

    fn write_loads(&self, root: &mut Table) {
        let common = |t: &mut Table, force, moment, time: &Option<TimeFunction>, follower| {
            t.insert("force".into(), vec3(force));
            t.insert("moment".into(), vec3(moment));
            if let Some(f) = time {
                t.insert("time".into(), time_function(f));
            }
            if follower {
                t.insert("follower".into(), Value::Boolean(true));
            }
        };
        for l in &self.loads {
            let mut t = Table::new();
            t.insert("node".into(), self.label(l.node));
            common(&mut t, l.force, l.moment, &l.time, l.follower);
            push(root, "load", t);
        }
        for l in &self.distributed_loads {
            let mut t = Table::new();
            let beam = self.beams.get(l.beam).map(|b| b.name.clone());
            t.insert("beam".into(), Value::String(beam.unwrap_or_default()));
            common(&mut t, l.force, l.moment, &l.time, l.follower);
            push(root, "distributed_load", t);
        }
        for l in &self.rust_loads {
            let mut t = Table::new();
            t.insert("name".into(), Value::String(l.name.clone()));
            let nodes = l.nodes.iter().map(|&n| self.label(n)).collect();
            t.insert("nodes".into(), Value::Array(nodes));
            push(root, "rust_load", t);
        }
    }

    fn write_motion(&self, root: &mut Table) {
        for p in &self.prescribed {
            let mut t = Table::new();
            match p {
                PrescribedSpec::JointAngle { joint, angle } => {
                    let name = self.joints.get(*joint).map(|j| j.name.clone());
                    t.insert("joint".into(), Value::String(name.unwrap_or_default()));
                    t.insert("angle".into(), time_function(angle));
                }
                PrescribedSpec::NodeDof { node, dof, value } => {
                    t.insert("node".into(), self.label(*node));
                    let name = DOF_NAMES.get(*dof).copied().unwrap_or("?");
                    t.insert("dof".into(), Value::String(name.into()));
                    t.insert("value".into(), time_function(value));
                }
            }
            push(root, "prescribed", t);
        }
        for v in &self.initial_velocities {
            let mut t = Table::new();
            let nodes = v.nodes.iter().map(|&n| self.label(n)).collect();
            t.insert("nodes".into(), Value::Array(nodes));
            t.insert("linear".into(), vec3(v.linear));
            t.insert("angular".into(), vec3(v.angular));
            t.insert("origin".into(), vec3(v.origin));
            push(root, "initial_velocity", t);
        }
        for b in &self.rigid_bodies {
            let mut t = Table::new();
            t.insert("name".into(), Value::String(b.name.clone()));
            t.insert("node".into(), self.label(b.node));
            t.insert("mass".into(), Value::Float(b.mass));
            let rows = b.inertia.iter().map(|&r| vec3(r)).collect();
            t.insert("inertia".into(), Value::Array(rows));
            t.insert("offset".into(), vec3(b.offset));
            push(root, "rigid_body", t);
        }
    }

    fn solver_table(&self) -> Table {
        let s = &self.solver;
        let mut t = Table::new();
        let mut put = |k: &str, v: Value| {
            t.insert(k.into(), v);
        };
        match s.analysis {
            Analysis::Static { load_steps } => {
                put("analysis", Value::String("static".into()));
                put("load_steps", int(load_steps));
            }
            Analysis::ArcLength {
                load_steps,
                max_steps,
                branch_switch,
            } => {
                put("analysis", Value::String("static".into()));
                put("control", Value::String("arc-length".into()));
                put("load_steps", int(load_steps));
                put("max_arc_steps", int(max_steps));
                put("branch_switch", Value::Boolean(branch_switch));
            }
            Analysis::Modal { modes, load_steps } => {
                put("analysis", Value::String("modal".into()));
                put("modes", int(modes));
                put("load_steps", int(load_steps));
                if s.mass == MassKind::Lumped {
                    put("mass", Value::String("lumped".into()));
                }
            }
            Analysis::Buckling { modes } => {
                put("analysis", Value::String("buckling".into()));
                put("modes", int(modes));
            }
            Analysis::Dynamic {
                integrator,
                dt,
                t_end,
            } => {
                put("analysis", Value::String("dynamic".into()));
                put("integrator", Value::String(integrator.name().into()));
                if let IntegratorKind::GeneralizedAlpha { rho_inf } = integrator {
                    put("rho_inf", Value::Float(rho_inf));
                }
                put("dt", Value::Float(dt));
                put("t_end", Value::Float(t_end));
                if s.mass == MassKind::Lumped {
                    put("mass", Value::String("lumped".into()));
                }
                if s.modified_newton {
                    put("newton", Value::String("modified".into()));
                } else if s.exact_tangent {
                    put("newton", Value::String("exact".into()));
                }
            }
        }
        put("tolerance", Value::Float(s.tolerance));
        put("max_iterations", int(s.max_iterations));
        put("max_halvings", int(s.max_halvings));
        if let Some(e) = s.eigensolver {
            put("eigensolver", Value::String(e.name().into()));
        }
        if let Some(stop) = &s.stop {
            let mut st = Table::new();
            if let Some(l) = stop.load_factor {
                st.insert("load_factor".into(), Value::Float(l));
            }
            if let Some(d) = &stop.displacement {
                let mut dt = Table::new();
                dt.insert("node".into(), Value::String(d.label.clone()));
                dt.insert("max".into(), Value::Float(d.max));
                st.insert("displacement".into(), Value::Table(dt));
            }
            put("stop", Value::Table(st));
        }
        if let Some(r) = s.rotation {
            let mut rot = Table::new();
            rot.insert("axis".into(), vec3(r.axis));
            rot.insert("origin".into(), vec3(r.origin));
            rot.insert("rate".into(), Value::Float(r.rate));
            put("rotation", Value::Table(rot));
        }
        t
    }

    fn output_table(&self) -> Table {
        let o = &self.output;
        let mut t = Table::new();
        t.insert("every".into(), int(o.every));
        let track = o
            .track
            .iter()
            .map(|(l, _)| Value::String(l.clone()))
            .collect();
        t.insert("track".into(), Value::Array(track));
        t.insert("resultants".into(), Value::Boolean(o.resultants));
        t.insert("vtk".into(), Value::Boolean(o.vtk));
        if !o.sensitivity.is_empty() {
            let keys = o.sensitivity.iter();
            let keys = keys.map(|(k, _)| Value::String(k.clone())).collect();
            t.insert("sensitivity".into(), Value::Array(keys));
        }
        t
    }
}

#[cfg(test)]
mod tests {
    use crate::{load_model, parse_model};
    use std::path::Path;

    /// Every model file of `data/` written back and read again is the same
    /// model (path and text aside).
    #[test]
    fn every_model_file_round_trips() {
        let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("../data");
        let mut count = 0;
        for dir in ["paper", "benchmarks", "statics", "dynamics"] {
            for entry in std::fs::read_dir(data.join(dir)).unwrap() {
                let path = entry.unwrap().path();
                if path.extension().is_none_or(|e| e != "toml") {
                    continue;
                }
                let Ok(model) = load_model(&path) else {
                    continue; // study files and deliberately invalid models
                };
                let text = model.to_toml();
                let mut again = parse_model(&text, &path)
                    .unwrap_or_else(|e| panic!("{}: {e}\n{text}", path.display()));
                again.source_text.clone_from(&model.source_text);
                again.source_written.clone_from(&model.source_written);
                assert_eq!(again, model, "{}:\n{text}", path.display());
                count += 1;
            }
        }
        assert!(count >= 20, "{count} model files");
    }
}
