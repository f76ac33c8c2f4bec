//! The invariants of a [`Model`] that the model-file checks establish,
//! checked on the typed model itself: a model built or changed in Rust (a
//! study's function, a researcher's program) is refused with a message naming
//! the key, instead of reaching the mesher with an index out of range or a
//! stiffness of zero.
//!
//! A model loaded from a file always passes (the file checks are stricter:
//! they also locate the line); [`crate::build`] runs this check first.

use super::{Analysis, Model, ModelError, NodeRef, PrescribedSpec, SensitivityKey, TimeFunction};

/// Collects the first violation with its key.
struct Checker<'a> {
    model: &'a Model,
}

type Res = Result<(), ModelError>;

impl Checker<'_> {
    fn fail(&self, key: impl Into<String>, message: impl Into<String>) -> ModelError {
        ModelError::new(&self.model.path, key, None, message)
    }

    fn finite(&self, key: &str, values: &[f64]) -> Res {
        match values.iter().find(|v| !v.is_finite()) {
            Some(v) => Err(self.fail(key, format!("{v} is not a finite number"))),
            None => Ok(()),
        }
    }

    fn positive(&self, key: &str, values: &[f64]) -> Res {
        match values.iter().find(|v| !(v.is_finite() && **v > 0.0)) {
            Some(v) => Err(self.fail(key, format!("must be positive and finite, found {v}"))),
            None => Ok(()),
        }
    }

    fn node(&self, key: &str, r: NodeRef) -> Res {
        let Some(beam) = self.model.beams.get(r.beam) else {
            return Err(self.fail(
                key,
                format!(
                    "names beam {} but the model has {} beam(s)",
                    r.beam,
                    self.model.beams.len()
                ),
            ));
        };
        if r.node >= beam.node_count() {
            return Err(self.fail(
                key,
                format!(
                    "names node {} of beam `{}`, which has nodes 0..={}",
                    r.node,
                    beam.name,
                    beam.node_count() - 1
                ),
            ));
        }
        Ok(())
    }

    fn time(&self, key: &str, f: &TimeFunction) -> Res {
        match f {
            TimeFunction::Constant(c) => self.finite(key, &[*c]),
            TimeFunction::Expression(_) => f.validate().map_err(|m| self.fail(key, m)),
            TimeFunction::Table(rows) => {
                if rows.is_empty() {
                    return Err(self.fail(key, "the time table has no rows"));
                }
                for (i, (t, v)) in rows.iter().enumerate() {
                    self.finite(key, &[*t, *v])?;
                    if i > 0 && *t < rows[i - 1].0 {
                        return Err(self.fail(
                            key,
                            format!("the times must not decrease; row {i} has t = {t}"),
                        ));
                    }
                }
                Ok(())
            }
        }
    }

    fn sections_and_beams(&self) -> Res {
        for (i, s) in self.model.sections.iter().enumerate() {
            let key = format!("section[{i}].damping");
            self.finite(&key, &[s.damping])?;
            if s.damping < 0.0 {
                return Err(self.fail(key, format!("must be >= 0, found {}", s.damping)));
            }
            // The builder's own check of the values, named by the model key.
            if let Err((what, value)) = s.values.section() {
                let key = match what {
                    "GA2" | "GA3" => "GA",
                    "EI2" | "EI3" => "EI",
                    other => other,
                };
                let need = if key.starts_with("rho") {
                    "must be zero or positive and finite"
                } else {
                    "must be positive and finite"
                };
                return Err(self.fail(
                    format!("section[{i}].{key}"),
                    format!("{need}, found {value}"),
                ));
            }
        }
        for (b, beam) in self.model.beams.iter().enumerate() {
            let k = |name: &str| format!("beam[{b}].{name}");
            if beam.section >= self.model.sections.len() {
                return Err(self.fail(
                    k("section"),
                    format!(
                        "names section {} but the model has {} section(s)",
                        beam.section,
                        self.model.sections.len()
                    ),
                ));
            }
            if beam.elements == 0 {
                return Err(self.fail(k("elements"), "must be at least 1"));
            }
            if !matches!(beam.nodes_per_element, 2 | 3) {
                return Err(self.fail(
                    k("nodes_per_element"),
                    format!("must be 2 or 3, found {}", beam.nodes_per_element),
                ));
            }
        }
        Ok(())
    }

    fn loading(&self) -> Res {
        let m = self.model;
        self.finite("gravity", &m.gravity)?;
        for (i, s) in m.supports.iter().enumerate() {
            self.node(&format!("support[{i}].node"), s.node)?;
        }
        for (i, l) in m.loads.iter().enumerate() {
            let k = |name: &str| format!("load[{i}].{name}");
            self.node(&k("node"), l.node)?;
            self.finite(&k("force"), &l.force)?;
            self.finite(&k("moment"), &l.moment)?;
            if let Some(f) = &l.time {
                self.time(&k("time"), f)?;
            }
        }
        for (i, l) in m.distributed_loads.iter().enumerate() {
            let k = |name: &str| format!("distributed_load[{i}].{name}");
            if l.beam >= m.beams.len() {
                return Err(self.fail(
                    k("beam"),
                    format!(
                        "names beam {} but the model has {} beam(s)",
                        l.beam,
                        m.beams.len()
                    ),
                ));
            }
            self.finite(&k("force"), &l.force)?;
            self.finite(&k("moment"), &l.moment)?;
            if let Some(f) = &l.time {
                self.time(&k("time"), f)?;
            }
        }
        for (j, joint) in m.joints.iter().enumerate() {
            let k = |name: &str| format!("joint[{j}].{name}");
            if let Some(master) = joint.master {
                self.node(&k("master"), master)?;
            }
            self.node(&k("slave"), joint.slave)?;
            if joint.master == Some(joint.slave) {
                return Err(self.fail(k("slave"), "the slave is the master node"));
            }
            self.finite(&k("angle"), &[joint.angle])?;
            self.finite(&k("rate"), &[joint.rate])?;
        }
        for (i, p) in m.prescribed.iter().enumerate() {
            let k = |name: &str| format!("prescribed[{i}].{name}");
            match p {
                PrescribedSpec::JointAngle { joint, angle } => {
                    let Some(spec) = m.joints.get(*joint) else {
                        return Err(self.fail(
                            k("joint"),
                            format!(
                                "names joint {joint} but the model has {} joint(s)",
                                m.joints.len()
                            ),
                        ));
                    };
                    if !spec.kind.has_angle() {
                        return Err(self.fail(
                            k("joint"),
                            format!("joint `{}` has no released angle to drive", spec.name),
                        ));
                    }
                    self.time(&k("angle"), angle)?;
                }
                PrescribedSpec::NodeDof { node, dof, value } => {
                    self.node(&k("node"), *node)?;
                    if *dof >= 6 {
                        return Err(self.fail(
                            k("dof"),
                            format!("must be 0..6 (ux, uy, uz, rx, ry, rz), found {dof}"),
                        ));
                    }
                    self.time(&k("value"), value)?;
                }
            }
        }
        for (i, v) in m.initial_velocities.iter().enumerate() {
            let k = |name: &str| format!("initial_velocity[{i}].{name}");
            for r in &v.nodes {
                self.node(&k("nodes"), *r)?;
            }
            self.finite(&k("linear"), &v.linear)?;
            self.finite(&k("angular"), &v.angular)?;
            self.finite(&k("origin"), &v.origin)?;
        }
        for (i, b) in m.rigid_bodies.iter().enumerate() {
            let k = |name: &str| format!("rigid_body[{i}].{name}");
            self.node(&k("node"), b.node)?;
            self.finite(&k("mass"), &[b.mass])?;
            self.finite(&k("inertia"), b.inertia.as_flattened())?;
            self.finite(&k("offset"), &b.offset)?;
        }
        Ok(())
    }

    /// Every `[[rust_load]]` names nodes of the mesh, and has a function:
    /// one read from text without its program is refused here.
    fn rust_loads(&self) -> Res {
        for (i, l) in self.model.rust_loads.iter().enumerate() {
            for &r in &l.nodes {
                self.node(&format!("rust_load[{i}].nodes"), r)?;
            }
            if l.field.is_none() {
                return Err(self.fail(
                    format!("rust_load[{i}]"),
                    format!(
                        "\"{}\" is a load field written in Rust and its function is not in \
                         this model: a model with Rust load fields runs and restarts only from \
                         a program that binds them; call model.bind_load(\"{}\", f) before \
                         running it",
                        l.name, l.name
                    ),
                ));
            }
        }
        Ok(())
    }

    fn solver_and_output(&self) -> Res {
        let s = &self.model.solver;
        self.positive("solver.tolerance", &[s.tolerance])?;
        if s.max_iterations == 0 {
            return Err(self.fail("solver.max_iterations", "must be at least 1"));
        }
        match s.analysis {
            Analysis::Static { load_steps: 0 } => {
                return Err(self.fail("solver.load_steps", "must be at least 1"));
            }
            Analysis::Static { .. } => {}
            Analysis::ArcLength {
                load_steps,
                max_steps,
                ..
            } => {
                if load_steps == 0 || max_steps == 0 {
                    return Err(self.fail(
                        "solver.load_steps",
                        "arc-length control needs load_steps and max_arc_steps of at least 1",
                    ));
                }
            }
            Analysis::Modal { modes, load_steps } => {
                if modes == 0 || load_steps == 0 {
                    return Err(self.fail(
                        "solver.modes",
                        "a modal analysis needs modes and load_steps of at least 1",
                    ));
                }
            }
            Analysis::Buckling { modes: 0 } => {
                return Err(self.fail("solver.modes", "must be at least 1"));
            }
            Analysis::Buckling { .. } => {}
            Analysis::Dynamic { dt, t_end, .. } => {
                self.positive("solver.dt", &[dt])?;
                self.positive("solver.t_end", &[t_end])?;
            }
        }
        if let Some(r) = s.rotation {
            let v = [r.axis.as_slice(), &r.origin, &[r.rate]].concat();
            self.finite("solver.rotation", &v)?;
            if r.axis.iter().all(|v| *v == 0.0) {
                return Err(self.fail("solver.rotation.axis", "must be a nonzero vector"));
            }
        }
        if self.model.output.every == 0 {
            return Err(self.fail("output.every", "must be at least 1"));
        }
        for (label, r) in &self.model.output.track {
            self.node(&format!("output.track (\"{label}\")"), *r)?;
        }
        self.sensitivity()
    }

    /// Every sensitivity key names a section or a dead load of the model,
    /// and the model is one sensitivities are computed for.
    fn sensitivity(&self) -> Res {
        let m = self.model;
        for (i, (text, key)) in m.output.sensitivity.iter().enumerate() {
            let ok = match *key {
                SensitivityKey::JointParameter { joint, .. } => joint < m.joints.len(),
                SensitivityKey::BodyMass { body, component } => {
                    body < m.rigid_bodies.len() && component < 4
                }
                SensitivityKey::Section { section, component } => {
                    section < m.sections.len() && component < 10
                }
                SensitivityKey::Load { load, component } => {
                    m.loads.get(load).is_some_and(|l| !l.follower) && component < 6
                }
                SensitivityKey::DistributedLoad { load, component } => {
                    m.distributed_loads.get(load).is_some_and(|l| !l.follower) && component < 6
                }
                SensitivityKey::InitialVelocity { field, component } => {
                    field < m.initial_velocities.len() && component < 6
                }
                SensitivityKey::BeamEnd {
                    beam,
                    end,
                    component,
                } => {
                    let field = format!("{}[{component}]", ["start", "end"][end.min(1)]);
                    beam < m.beams.len()
                        && end < 2
                        && crate::validate::beam_end(m, beam, &field).is_some_and(|r| r.is_ok())
                }
            };
            if !ok {
                return Err(self.fail(
                    format!("output.sensitivity[{i}]"),
                    format!(
                        "\"{text}\" names no section stiffness, dead load component or initial \
                         velocity of the model ({key:?})"
                    ),
                ));
            }
        }
        match crate::validate::analysis_allows_sensitivity(m) {
            Err(why) if !m.output.sensitivity.is_empty() => {
                Err(self.fail("output.sensitivity", why))
            }
            _ => Ok(()),
        }
    }
}

impl Model {
    /// Asks the run for the exact derivatives of its results by the model
    /// values at `keys` too (key paths, as in `[output] sensitivity`; keys
    /// already asked for are kept once). Refused as in a model file: a key
    /// that names no differentiable value, or a model sensitivities are not
    /// computed for.
    pub fn add_sensitivity(&mut self, keys: &[String]) -> Result<(), ModelError> {
        crate::validate::add_sensitivity(self, keys)
    }

    /// Checks the invariants the model-file checks establish (indices in
    /// range, stiffnesses positive, numbers finite, time tables sorted,
    /// steps positive); the error names the model key and what to change.
    pub fn check(&self) -> Result<(), ModelError> {
        let c = Checker { model: self };
        c.sections_and_beams()?;
        c.loading()?;
        c.rust_loads()?;
        c.solver_and_output()
    }
}
