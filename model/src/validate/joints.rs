//! Joints: the common keys, the kinds' parameters (through the joint
//! registry), and the topology checks.

use std::collections::HashMap;
use std::ops::Range;

use super::{quoted_list, Ctx, Res};
use crate::locate::span_at;
use crate::raw::{RawJoint, RawSupport, S};
use crate::registry::{JointKind, ParamsError};
use crate::types::*;

// ---------------------------------------------------------------------------
// The validator.

/// The keys of a `[[joint]]` table that every kind has; the rest are the
/// kind's parameters.
const COMMON_KEYS: [&str; 6] = ["name", "type", "master", "slave", "angle", "rate"];

/// The `master` of a joint to the ground.
pub(crate) const GROUND: &str = "ground";

impl Ctx<'_> {
    pub(super) fn joints(&self, raw: &[S<RawJoint>], beams: &[BeamSpec]) -> Res<Vec<JointSpec>> {
        let tables = self.joint_tables();
        let mut out: Vec<JointSpec> = Vec::new();
        for (i, entry) in raw.iter().enumerate() {
            let j = entry.get_ref();
            let name = self.joint_name(i, entry, &out)?;
            let (type_name, kind) = self.joint_type(i, entry, &tables)?;
            self.angle_keys(i, j, type_name, &kind)?;
            let (master, slave) = self.joint_nodes(i, entry, &name, beams, &out)?;
            out.push(JointSpec {
                name,
                kind,
                master,
                slave,
                angle: j.angle.as_ref().map_or(0.0, |a| a.get_ref().0),
                rate: j.rate.as_ref().map_or(0.0, |a| a.get_ref().0),
            });
        }
        Ok(out)
    }

    /// The joint tables of the file as plain TOML values: the kinds'
    /// parameters.
    fn joint_tables(&self) -> Vec<toml::Table> {
        toml::from_str::<toml::Table>(self.text)
            .ok()
            .and_then(|mut doc| doc.remove("joint"))
            .and_then(|v| match v {
                toml::Value::Array(items) => Some(items),
                _ => None,
            })
            .unwrap_or_default()
            .into_iter()
            .map(|v| match v {
                toml::Value::Table(t) => t,
                _ => toml::Table::new(),
            })
            .collect()
    }

    /// The name of `joint[i]` (`entry`): present, non-empty, without '/',
    /// and none of the earlier joints `out` has it.
    fn joint_name(&self, i: usize, entry: &S<RawJoint>, out: &[JointSpec]) -> Res<String> {
        let tk = format!("joint[{i}]");
        let k = |f: &str| format!("{tk}.{f}");
        let hs = entry.span();
        let j = entry.get_ref();
        let name_s = self.entity_name(&j.name, &tk, &hs, "joint")?;
        let name = name_s.get_ref().clone();
        if name.contains('/') {
            return Err(self.at(
                k("name"),
                name_s,
                format!("must not contain '/' (joint names become group names /joints/<name> in the result file), found \"{name}\""),
            ));
        }
        if let Some(o) = out.iter().position(|o| o.name == name) {
            return Err(self.at(
                k("name"),
                name_s,
                format!("duplicate joint name \"{name}\" (joint[{o}] has it too); joint names must be unique"),
            ));
        }
        Ok(name)
    }

    /// The type name of `joint[i]` (`entry`), a registered kind, and the
    /// joint of that kind from its parameters (its table in `tables`).
    fn joint_type<'e>(
        &self,
        i: usize,
        entry: &'e S<RawJoint>,
        tables: &[toml::Table],
    ) -> Res<(&'e str, JointKind)> {
        let tk = format!("joint[{i}]");
        let k = |f: &str| format!("{tk}.{f}");
        let hs = entry.span();
        let j = entry.get_ref();
        // Quoted and comma-separated: every name stays whole however many
        // kinds a program registers (a message cuts only over-long words).
        let all_types = quoted_list(self.registry.names());
        let type_s = self.need(
            &j.kind,
            &k("type"),
            &hs,
            &format!("the joint type, one of {all_types}"),
        )?;
        let type_name = type_s.get_ref().as_str();
        if !self.registry.contains(type_name) {
            let guess = super::closest(type_name, self.registry.names())
                .map(|n| format!("did you mean \"{n}\"? "))
                .unwrap_or_default();
            return Err(self.at(
                k("type"),
                type_s,
                format!(
                    "unknown joint type \"{type_name}\"; {guess}expected one of {all_types} \
                     (a kind written in Rust is known once registered with the program that \
                     reads the model: `App::new().joint::<MyJoint>()`)"
                ),
            ));
        }
        let mut params = tables.get(i).cloned().unwrap_or_default();
        params.retain(|key, _| !COMMON_KEYS.contains(&key));
        let kind = self.joint_kind(type_name, &params, i, &hs)?;
        Ok((type_name, kind))
    }

    /// `angle` and `rate` of `joint[i]` (`j`, of type `type_name`, `kind`)
    /// belong to kinds whose first released coordinate is an angle.
    fn angle_keys(&self, i: usize, j: &RawJoint, type_name: &str, kind: &JointKind) -> Res<()> {
        let tk = format!("joint[{i}]");
        let k = |f: &str| format!("{tk}.{f}");
        for (key, value) in [("angle", &j.angle), ("rate", &j.rate)] {
            if let (Some(v), false) = (value, kind.has_angle()) {
                let names = kind.map().coordinate_names();
                let why = if names.is_empty() {
                    " (it has no released angle)".to_string()
                } else if names.len() == 3 {
                    " (it releases three rotations, not one angle)".to_string()
                } else {
                    format!(
                        " (its released coordinates are {}, not an angle)",
                        names.join(", ")
                    )
                };
                return Err(self.at(
                    k(key),
                    v,
                    format!(
                        "`{key}` does not belong to a joint of type {type_name}{why}; a joint of type {type_name} takes {}",
                        self.takes(type_name)
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The master (`None`: the ground) and slave nodes of `joint[i]`
    /// (`entry`, named `name`): two different nodes, the slave not the
    /// ground and the slave of none of the earlier joints `out`.
    fn joint_nodes(
        &self,
        i: usize,
        entry: &S<RawJoint>,
        name: &str,
        beams: &[BeamSpec],
        out: &[JointSpec],
    ) -> Res<(Option<NodeRef>, NodeRef)> {
        let tk = format!("joint[{i}]");
        let k = |f: &str| format!("{tk}.{f}");
        let hs = entry.span();
        let j = entry.get_ref();
        let master_s = self.need(
            &j.master,
            &k("master"),
            &hs,
            "the master node's label, e.g. master = \"post.end\", or master = \"ground\"",
        )?;
        let slave_s = self.need(
            &j.slave,
            &k("slave"),
            &hs,
            "the slave node's label, e.g. slave = \"arm.start\"",
        )?;
        let master = if master_s.get_ref() == GROUND {
            None
        } else {
            Some(self.node(master_s, &k("master"), beams)?)
        };
        if slave_s.get_ref() == GROUND {
            return Err(self.at(
                k("slave"),
                slave_s,
                "the ground cannot be a slave (its DOFs are not unknowns); make it the \
                 master, master = \"ground\", and the node the slave",
            ));
        }
        let slave = self.node(slave_s, &k("slave"), beams)?;
        if master == Some(slave) {
            return Err(self.at(
                k("slave"),
                slave_s,
                format!(
                    "the slave \"{}\" is the master node (\"{}\"); a joint connects two different nodes",
                    slave_s.get_ref(),
                    master_s.get_ref()
                ),
            ));
        }
        if let Some(o) = out.iter().position(|o| o.slave == slave) {
            return Err(self.at(
                k("slave"),
                slave_s,
                format!(
                    "node \"{}\" is the slave of two joints: \"{}\" (joint[{o}]) and \"{name}\" \
                     (joint[{i}]); a node can be the slave of one joint only (chains, where a \
                     slave is the master of another joint, are allowed)",
                    slave_s.get_ref(),
                    out[o].name
                ),
            ));
        }
        Ok((master, slave))
    }

    /// "`axis`, `pitch`": the parameter keys of a kind.
    fn takes(&self, type_name: &str) -> String {
        let parts: Vec<String> = self
            .registry
            .keys(type_name)
            .unwrap_or(&[])
            .iter()
            .map(|r| format!("`{r}`"))
            .collect();
        if parts.is_empty() {
            "no keys besides name, type, master and slave".to_string()
        } else {
            parts.join(", ")
        }
    }

    /// The joint of registered kind `type_name` from its parameter table
    /// (`joint[i]`, spanning `table`): unknown, missing and refused keys
    /// are errors at their line.
    fn joint_kind(
        &self,
        type_name: &str,
        params: &toml::Table,
        i: usize,
        table: &Range<usize>,
    ) -> Res<JointKind> {
        let tk = format!("joint[{i}]");
        if let Some((key, value)) = non_finite(params) {
            return Err(self.err(
                format!("{tk}.{key}"),
                span_at(self.text, &format!("{tk}.{key}")),
                format!("must be a finite number, found {value:?}"),
            ));
        }
        let Some(result) = self.registry.build(type_name, params) else {
            return Err(self.err(
                format!("{tk}.type"),
                Some(table.clone()),
                format!("unknown joint type \"{type_name}\""),
            ));
        };
        result.map_err(|e| match e {
            ParamsError::Unknown { key } => self.err(
                format!("{tk}.{key}"),
                span_at(self.text, &format!("{tk}.{key}")),
                format!(
                    "`{key}` does not belong to a joint of type {type_name}; a joint of type {type_name} takes {} \
                     (besides name, type, master, slave, and angle and rate where it has a \
                     released angle)",
                    self.takes(type_name)
                ),
            ),
            ParamsError::Missing { key, help } => self.err(
                format!("{tk}.{key}"),
                Some(table.clone()),
                format!(
                    "missing key `{key}`: a joint of type {type_name} needs {}",
                    help.map_or_else(|| format!("`{key}`"), str::to_string)
                ),
            ),
            ParamsError::Value(p) => {
                let key = if p.key.is_empty() {
                    tk.clone()
                } else {
                    format!("{tk}.{}", p.key)
                };
                let at = match p.item {
                    Some(n) => format!("{key}[{n}]"),
                    None => key.clone(),
                };
                let span = span_at(self.text, &at)
                    .or_else(|| span_at(self.text, &key))
                    .or(Some(table.clone()));
                self.err(key, span, p.message)
            }
        })
    }

    /// Supports vs slaves, and cycles of joints.
    pub(super) fn topology(
        &self,
        raw_supports: &[S<RawSupport>],
        supports: &[SupportSpec],
        raw_joints: &[S<RawJoint>],
        joints: &[JointSpec],
    ) -> Res<()> {
        let slave_of: HashMap<NodeRef, usize> = joints
            .iter()
            .enumerate()
            .map(|(i, j)| (j.slave, i))
            .collect();
        for (i, s) in supports.iter().enumerate() {
            if let Some(&j) = slave_of.get(&s.node) {
                let node_s = raw_supports[i].get_ref().node.as_ref();
                let label = node_s.map_or(String::new(), |n| n.get_ref().clone());
                return Err(self.err(
                    format!("support[{i}].node"),
                    node_s.map(S::span),
                    format!(
                        "node \"{label}\" is supported and is also the slave of joint \"{}\" \
                         (joint[{j}]); a slave's motion follows its master, so support the \
                         master instead",
                        joints[j].name
                    ),
                ));
            }
        }
        for start in 0..joints.len() {
            let mut chain = vec![start];
            let mut node = joints[start].master;
            while let Some(&next) = node.as_ref().and_then(|n| slave_of.get(n)) {
                if next == start {
                    let mut names: Vec<String> = chain
                        .iter()
                        .map(|&c| format!("\"{}\"", joints[c].name))
                        .collect();
                    let list = names.join(", ");
                    names.push(format!("\"{}\"", joints[start].name));
                    return Err(self.err(
                        format!("joint[{start}]"),
                        Some(raw_joints[start].span()),
                        format!(
                            "joints {list} form a cycle: the master node of each is the slave of \
                             the next ({}); a chain of joints must end at a master node that is \
                             not a slave",
                            names.join(" → ")
                        ),
                    ));
                }
                if chain.contains(&next) {
                    break; // a cycle not through `start`: reported from one of its joints
                }
                chain.push(next);
                node = joints[next].master;
            }
        }
        Ok(())
    }
}

/// The first non-finite number in a parameter table (path relative to it).
fn non_finite(table: &toml::Table) -> Option<(String, f64)> {
    fn walk(v: &toml::Value, path: String) -> Option<(String, f64)> {
        match v {
            toml::Value::Float(x) if !x.is_finite() => Some((path, *x)),
            toml::Value::Array(items) => items
                .iter()
                .enumerate()
                .find_map(|(i, item)| walk(item, format!("{path}[{i}]"))),
            toml::Value::Table(t) => t
                .iter()
                .find_map(|(k, item)| walk(item, format!("{path}.{k}"))),
            _ => None,
        }
    }
    table.iter().find_map(|(k, v)| walk(v, k.clone()))
}
