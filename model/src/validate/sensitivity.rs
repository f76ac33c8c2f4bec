//! `[output] sensitivity`: key paths into the model naming the values the
//! run differentiates its results by, checked against the whole model.

use toml::{Table, Value};

use super::{Ctx, Res};
use crate::key_path::{lookup_mut, KeyPath, Segment};
use crate::raw::{RawOutput, S};
use crate::types::{Analysis, IntegratorKind, Model, SensitivityKey};

/// What the keys may name today, for the messages.
const AVAILABLE: &str = "section values (`section.<name>.EA`, `GA[0]`, `GA[1]`, `GJ`, \
                         `EI[0]`, `EI[1]`, `rhoA`, `rhoJ[0]`, `rhoJ[1]`, `rhoJ[2]`), rigid \
                         bodies' `rigid_body[i].mass` and principal `inertia[k]`, joints' \
                         `joint.<name>.pitch` (screw), `.radius` (rack_pinion, cam), \
                         `.offset` (cam) and `joint.<name>.parameters.<p>` (expression), straight beams' ends \
                         (`beam.<name>.start[c]`, `beam.<name>.end[c]`; statics and the \
                         Newmark family), dead load components \
                         (`load[i].force[c]`, `load[i].moment[c]`, \
                         `distributed_load[i].force[c]`, `distributed_load[i].moment[c]`) and, \
                         in dynamics, initial velocities (`initial_velocity[i].linear[c]`, \
                         `initial_velocity[i].angular[c]`)";

/// The value of a `[[section]]` field (its words after the section): the
/// component 0–5 of EA, GA₂, GA₃, GJ, EI₂, EI₃, 6 of ρA, 7–9 of ρJ.
fn stiffness(field: &str) -> Option<usize> {
    [
        "EA", "GA[0]", "GA[1]", "GJ", "EI[0]", "EI[1]", "rhoA", "rhoJ[0]", "rhoJ[1]", "rhoJ[2]",
    ]
    .iter()
    .position(|f| *f == field)
}

/// The component 0–5 of a load's `force[c]` or `moment[c]`.
fn load_component(field: &str) -> Option<usize> {
    [
        "force[0]",
        "force[1]",
        "force[2]",
        "moment[0]",
        "moment[1]",
        "moment[2]",
    ]
    .iter()
    .position(|f| *f == field)
}

/// The value 0–3 of a rigid body's `mass` (0) or principal inertia
/// `inertia[k]` / `inertia[k][k]` (1 + k).
fn body_component(field: &str) -> Option<usize> {
    match field {
        "mass" => Some(0),
        _ => (0..3)
            .find(|k| field == format!("inertia[{k}]") || field == format!("inertia[{k}][{k}]"))
            .map(|k| k + 1),
    }
}

/// The component 0–5 of an initial velocity's `linear[c]` or `angular[c]`.
fn velocity_component(field: &str) -> Option<usize> {
    [
        "linear[0]",
        "linear[1]",
        "linear[2]",
        "angular[0]",
        "angular[1]",
        "angular[2]",
    ]
    .iter()
    .position(|f| *f == field)
}

/// The parameter `field` (`parameters.<p>`, or a built-in kind's value
/// such as `offset`) of joint `j` at key `text`, where the joint's kind can
/// differentiate by it. A value that moves the slave at t = 0 re-places
/// the body the joint carries with it (checked when the run starts).
fn joint_parameter(
    model: &Model,
    j: usize,
    field: &str,
    text: &str,
) -> Result<SensitivityKey, String> {
    let spec = &model.joints[j];
    let refuse = |why: String| format!("cannot differentiate by \"{text}\": {why}");
    let name = field.strip_prefix("parameters.").unwrap_or(field);
    let mut q0 = [0.0; flexmech_joints::MAX_RELEASED];
    q0[0] = spec.angle;
    let state = flexmech_joints::ReleasedState::new(q0);
    if spec.kind.map().parameter_derivative(name, &state).is_none() {
        return Err(refuse(format!(
            "a joint of type {} cannot be differentiated by `{field}` ({JOINT_VALUES}); write \
             the joint as `type = \"expression\"` to differentiate by its parameters",
            spec.kind.type_name()
        )));
    }
    Ok(SensitivityKey::JointParameter {
        joint: j,
        name: name.to_owned(),
    })
}

/// The joint values that can be differentiated by, for the messages.
const JOINT_VALUES: &str = "joints can be differentiated by `pitch` of a screw, `radius` of a \
                            rack_pinion, `radius` and `offset` of a cam and the parameters of \
                            an expression joint, `joint.<name>.parameters.<p>`";

/// The coordinate `field` (`start[c]`, `end[c]`) of beam `b`'s end, where
/// the beam is straight and nothing on it depends on its nodes' places but
/// what the derivative follows: refused where an initial velocity with an angular part covers it (`ω × (x − origin)` changes) or
/// a joint or an offset rigid body ties a node it moves.
/// `None`: `field` is no end coordinate.
pub(crate) fn beam_end(
    model: &Model,
    b: usize,
    field: &str,
) -> Option<Result<SensitivityKey, String>> {
    let (end, component) = (0..2)
        .flat_map(|end| (0..3).map(move |c| (end, c)))
        .find(|&(end, c)| field == format!("{}[{c}]", ["start", "end"][end]))?;
    let spec = &model.beams[b];
    let refuse = |why: String| Some(Err(why));
    if !matches!(spec.geometry, crate::types::BeamGeometry::Straight { .. }) {
        return refuse(format!(
            "beam `{}` is not straight; the end coordinates of straight beams can be \
             differentiated by",
            spec.name
        ));
    }
    let spinning = (model.initial_velocities.iter())
        .any(|v| v.angular != [0.0; 3] && v.nodes.iter().any(|n| n.beam == b));
    if spinning {
        return refuse(format!(
            "an [[initial_velocity]] with an angular part covers beam `{}`: its velocity \
             field `ω × (x − origin)` depends on where the nodes are; differentiate from a \
             start without spin",
            spec.name
        ));
    }
    // Moved: every node but the other end's.
    let last = spec.node_count() - 1;
    let moved = |n: &crate::types::NodeRef| n.beam == b && n.node != [last, 0][end];
    let tied = (model.joints.iter())
        .find(|j| moved(&j.slave) || j.master.as_ref().is_some_and(moved))
        .map(|j| format!("joint `{}`", j.name))
        .or_else(|| {
            (model.rigid_bodies.iter())
                .find(|r| r.offset != [0.0; 3] && moved(&r.node))
                .map(|r| format!("rigid body `{}` (its offset is a link)", r.name))
        });
    if let Some(what) = tied {
        return refuse(format!(
            "moving that end moves a node of beam `{}` that {what} ties, which the joint \
             would no longer place; differentiate by the other end, or by a beam whose moved \
             nodes carry no joint",
            spec.name
        ));
    }
    Some(Ok(SensitivityKey::BeamEnd {
        beam: b,
        end,
        component,
    }))
}

/// What kind of value `v` is, when it is no real number.
fn not_real(v: &Value) -> Option<&'static str> {
    match v {
        Value::String(_) => Some("a string"),
        Value::Boolean(_) => Some("a boolean"),
        Value::Integer(_) => Some("an integer"),
        Value::Datetime(_) => Some("a date"),
        Value::Array(_) => Some("a list (name one component, e.g. `[0]`)"),
        Value::Table(_) => Some("a table (name one of its values)"),
        Value::Float(_) => None,
    }
}

/// Adds the key paths `keys` that `model`'s `[output] sensitivity` does not
/// hold yet, checked as in a model file (errors name the model's path and
/// the key, without a line: the text is the model's as written back).
pub(crate) fn add_sensitivity(model: &mut Model, keys: &[String]) -> Res<()> {
    let text = model.to_toml();
    let registry = crate::registry::JointRegistry::builtin();
    let cx = Ctx {
        file: &model.path,
        text: &text,
        registry: &registry,
        dynamic: !matches!(model.solver.analysis, Analysis::Static { .. }),
    };
    let mut table: Table = toml::from_str(&text).unwrap_or_default();
    let mut added = Vec::new();
    for key in keys {
        if model.output.sensitivity.iter().any(|(k, _)| k == key) {
            continue;
        }
        let at = format!("output.sensitivity (\"{key}\")");
        let resolved = cx.sensitivity_key(key, &mut table, model);
        added.push((key.clone(), resolved.map_err(|m| cx.err(&at, None, m))?));
    }
    if !added.is_empty() {
        analysis_allows_sensitivity(model).map_err(|m| cx.err("output.sensitivity", None, m))?;
    }
    model.output.sensitivity.extend(added);
    Ok(())
}

impl Ctx<'_> {
    /// The validated `[output] sensitivity` of `model` (its other parts
    /// validated).
    pub(super) fn sensitivity(
        &self,
        raw: Option<&S<RawOutput>>,
        model: &Model,
    ) -> Res<Vec<(String, SensitivityKey)>> {
        let Some(list) = raw.and_then(|o| o.get_ref().sensitivity.as_ref()) else {
            return Ok(Vec::new());
        };
        let mut table: Table = toml::from_str(self.text).unwrap_or_default();
        let mut keys: Vec<(String, SensitivityKey)> = Vec::new();
        for (i, item) in list.get_ref().iter().enumerate() {
            let at = format!("output.sensitivity[{i}]");
            let text = item.get_ref();
            if keys.iter().any(|(k, _)| k == text) {
                return Err(self.at(at, item, format!("\"{text}\" is listed twice")));
            }
            let key = self.sensitivity_key(text, &mut table, model);
            keys.push((text.clone(), key.map_err(|m| self.at(&at, item, m))?));
        }
        if !keys.is_empty() {
            self.sensitivity_analysis(list, model)?;
        }
        Ok(keys)
    }

    /// The model value `text` names, or why it names none that can be
    /// differentiated by.
    fn sensitivity_key(
        &self,
        text: &str,
        table: &mut Table,
        model: &Model,
    ) -> Result<SensitivityKey, String> {
        let path = KeyPath::parse(text).map_err(|why| format!("\"{text}\" {why}"))?;
        let value = lookup_mut(table, &path).map_err(|why| format!("\"{text}\": {why}"))?;
        // The table and entry (`section.rod`, `load[0]`), then the field.
        let (table_name, entry, field) = match path.segments.as_slice() {
            [Segment::Key(t), entry, rest @ ..] if !rest.is_empty() => {
                let field = KeyPath {
                    segments: rest.to_vec(),
                };
                (t.as_str(), Some(entry), field.to_string())
            }
            _ => ("", None, String::new()),
        };
        let index = |count: usize| match entry {
            Some(Segment::Index(i)) if *i < count => Some(*i),
            _ => None,
        };
        let found = match table_name {
            "section" => {
                let section = match entry {
                    Some(Segment::Key(name)) => model.sections.iter().position(|s| &s.name == name),
                    _ => index(model.sections.len()),
                };
                section
                    .zip(stiffness(&field))
                    .map(|(section, component)| SensitivityKey::Section { section, component })
            }
            "load" => index(model.loads.len())
                .zip(load_component(&field))
                .map(|(load, component)| SensitivityKey::Load { load, component }),
            "distributed_load" => index(model.distributed_loads.len())
                .zip(load_component(&field))
                .map(|(load, component)| SensitivityKey::DistributedLoad { load, component }),
            "joint" => {
                let joint = match entry {
                    Some(Segment::Key(name)) => model.joints.iter().position(|j| &j.name == name),
                    _ => index(model.joints.len()),
                };
                if let Some(j) = joint {
                    return joint_parameter(model, j, &field, text);
                }
                None
            }
            "rigid_body" => {
                let body = match entry {
                    Some(Segment::Key(name)) => {
                        model.rigid_bodies.iter().position(|b| &b.name == name)
                    }
                    _ => index(model.rigid_bodies.len()),
                };
                body.zip(body_component(&field))
                    .map(|(body, component)| SensitivityKey::BodyMass { body, component })
            }
            "initial_velocity" => index(model.initial_velocities.len())
                .zip(velocity_component(&field))
                .map(|(field, component)| SensitivityKey::InitialVelocity { field, component }),
            _ => None,
        };
        if let Some(key) = found {
            return self.dead(key, model, text);
        }
        if table_name == "beam" {
            let beam = match entry {
                Some(Segment::Key(name)) => model.beams.iter().position(|b| &b.name == name),
                _ => index(model.beams.len()),
            };
            if let Some(key) = beam.and_then(|b| beam_end(model, b, &field)) {
                return key.map_err(|why| format!("cannot differentiate by \"{text}\": {why}"));
            }
        }

        let why = if matches!(text, "solver.dt" | "solver.t_end") {
            "the step size and the end time are no parameters of the solution".to_string()
        } else if matches!(table_name, "solver" | "output") {
            "it is a setting of the solver or the output, no parameter of the solution".to_string()
        } else if let Some(kind) = not_real(value) {
            format!("it is {kind}, not a real number")
        } else {
            "sensitivities to it are not available yet".to_string()
        };
        Err(format!(
            "cannot differentiate by \"{text}\": {why}; available: {AVAILABLE}"
        ))
    }

    /// `key`, if it is not a component of a follower load.
    fn dead(
        &self,
        key: SensitivityKey,
        model: &Model,
        text: &str,
    ) -> Result<SensitivityKey, String> {
        let follower = match key {
            SensitivityKey::Load { load, .. } => model.loads[load].follower,
            SensitivityKey::DistributedLoad { load, .. } => model.distributed_loads[load].follower,
            SensitivityKey::Section { .. }
            | SensitivityKey::JointParameter { .. }
            | SensitivityKey::BeamEnd { .. }
            | SensitivityKey::BodyMass { .. } => false,
            SensitivityKey::InitialVelocity { .. } => {
                if !matches!(model.solver.analysis, Analysis::Dynamic { .. }) {
                    return Err(format!(
                        "cannot differentiate by \"{text}\": initial velocities act in dynamic \
                         analyses only"
                    ));
                }
                false
            }
        };
        if follower {
            Err(format!(
                "cannot differentiate by \"{text}\": a follower load's components are not \
                 available yet; available: {AVAILABLE}"
            ))
        } else {
            Ok(key)
        }
    }

    /// Refuses the analyses and loads sensitivities are not computed for.
    fn sensitivity_analysis(&self, list: &S<Vec<S<String>>>, model: &Model) -> Res<()> {
        analysis_allows_sensitivity(model).map_err(|m| self.at("output.sensitivity", list, m))
    }
}

/// Why `model` is no model sensitivities are computed for, if it is not.
pub(crate) fn analysis_allows_sensitivity(model: &Model) -> Result<(), &'static str> {
    match model.solver.analysis {
        Analysis::Static { .. } | Analysis::ArcLength { .. } => {}
        Analysis::Modal { .. } | Analysis::Buckling { .. } => {
            return Err(
                "sensitivities of modes and buckling loads are not computed; remove \
                 `sensitivity` from [output], or run a static or dynamic analysis",
            )
        }
        Analysis::Dynamic {
            integrator: IntegratorKind::Newmark | IntegratorKind::GeneralizedAlpha { .. },
            ..
        } => {
            if model.sections.iter().any(|s| s.damping > 0.0) {
                return Err(
                    "sensitivities of a run with structural damping (`damping` in a \
                     [[section]]) are not available yet; remove `sensitivity` from [output], \
                     or the damping",
                );
            }
        }
        Analysis::Dynamic {
            integrator:
                IntegratorKind::Momentum
                | IntegratorKind::EnergyMomentum
                | IntegratorKind::EnergyMomentumPaper,
            ..
        } => {}
    }
    let follower = model.loads.iter().any(|l| l.follower)
        || model.distributed_loads.iter().any(|l| l.follower);
    if follower {
        return Err(
            "sensitivities of a model with follower loads are not available yet (their \
             work makes the total energy path-dependent); remove `sensitivity` from \
             [output], or make the loads dead (`follower = false`)",
        );
    }
    Ok(())
}
