//! Joints: types and their parameters, lift profiles, and the topology checks.

use std::collections::HashMap;
use std::ops::Range;

use super::{dot, fmt_v, Ctx, Res, ANGLE_TOL};
use crate::model::raw::{v3, RawJoint, RawLift, RawSupport, S};
use crate::model::types::*;

// ---------------------------------------------------------------------------
// Joint types.

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum JointType {
    Rigid,
    Revolute,
    Spherical,
    Prismatic,
    Cylindrical,
    Screw,
    RackPinion,
    Cam,
    Lobe,
}

const JOINT_TYPES: [(&str, JointType); 9] = [
    ("rigid", JointType::Rigid),
    ("revolute", JointType::Revolute),
    ("spherical", JointType::Spherical),
    ("prismatic", JointType::Prismatic),
    ("cylindrical", JointType::Cylindrical),
    ("screw", JointType::Screw),
    ("rack_pinion", JointType::RackPinion),
    ("cam", JointType::Cam),
    ("lobe", JointType::Lobe),
];

impl JointType {
    /// The type's parameter keys: required, then optional.
    fn keys(self) -> (&'static [&'static str], &'static [&'static str]) {
        const ANGLE: &[&str] = &["angle", "rate"];
        match self {
            JointType::Rigid | JointType::Spherical => (&[], &[]),
            JointType::Revolute => (&["axis"], ANGLE),
            JointType::Prismatic => (&["slide"], &[]),
            JointType::Cylindrical => (&["axis", "slide"], ANGLE),
            JointType::Screw => (&["axis", "pitch"], ANGLE),
            JointType::RackPinion => (&["axis", "radius", "slide"], ANGLE),
            JointType::Cam => (&["axis", "radius", "offset", "slide"], ANGLE),
            JointType::Lobe => (&["axis", "slide", "lift"], ANGLE),
        }
    }
}

impl JointKind {
    /// The joint's `type` as written in model files (`"rack_pinion"`, ...).
    pub fn type_name(&self) -> &'static str {
        match self {
            JointKind::Rigid => "rigid",
            JointKind::Revolute { .. } => "revolute",
            JointKind::Spherical => "spherical",
            JointKind::Prismatic { .. } => "prismatic",
            JointKind::Cylindrical { .. } => "cylindrical",
            JointKind::Screw { .. } => "screw",
            JointKind::RackPinion { .. } => "rack_pinion",
            JointKind::Cam { .. } => "cam",
            JointKind::Lobe { .. } => "lobe",
        }
    }
}

/// What a missing joint parameter is, for messages.
fn joint_key_help(key: &str) -> &'static str {
    match key {
        "axis" => "its released rotation axis, e.g. axis = [0.0, 0.0, 1.0]",
        "slide" => "its slide direction t_r, e.g. slide = [1.0, 0.0, 0.0]",
        "pitch" => "its pitch (translation per radian along the axis), e.g. pitch = 0.1",
        "radius" => "its radius (> 0), e.g. radius = 0.05",
        "offset" => "its offset a, e.g. offset = 0.0",
        "lift" => {
            "its lift profile: lift = { table = [[angle, lift], ...] } or \
             lift = { fourier = [a0, a1, b1, ...] }"
        }
        _ => "this key",
    }
}

// ---------------------------------------------------------------------------
// The validator.

impl Ctx<'_> {
    pub(super) fn joints(&self, raw: &[S<RawJoint>], beams: &[BeamSpec]) -> Res<Vec<JointSpec>> {
        let mut out: Vec<JointSpec> = Vec::new();
        for (i, entry) in raw.iter().enumerate() {
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
            let all_types = JOINT_TYPES
                .iter()
                .map(|(n, _)| *n)
                .collect::<Vec<_>>()
                .join("|");
            let type_s = self.need(
                &j.kind,
                &k("type"),
                &hs,
                &format!("the joint type, one of {all_types}"),
            )?;
            let type_name = type_s.get_ref().as_str();
            let Some(&(_, jt)) = JOINT_TYPES.iter().find(|(n, _)| *n == type_name) else {
                return Err(self.at(
                    k("type"),
                    type_s,
                    format!("unknown joint type \"{type_name}\"; expected one of {all_types}"),
                ));
            };

            // Keys that do not belong to this type.
            let present: [(&str, Option<Range<usize>>); 8] = [
                ("axis", j.axis.as_ref().map(S::span)),
                ("slide", j.slide.as_ref().map(S::span)),
                ("pitch", j.pitch.as_ref().map(S::span)),
                ("radius", j.radius.as_ref().map(S::span)),
                ("offset", j.offset.as_ref().map(S::span)),
                ("lift", j.lift.as_ref().map(S::span)),
                ("angle", j.angle.as_ref().map(S::span)),
                ("rate", j.rate.as_ref().map(S::span)),
            ];
            let (required, optional) = jt.keys();
            for (key, span) in &present {
                if span.is_some() && !required.contains(key) && !optional.contains(key) {
                    let takes = if required.is_empty() && optional.is_empty() {
                        "no keys besides name, type, master and slave".to_string()
                    } else {
                        let mut parts: Vec<String> =
                            required.iter().map(|r| format!("`{r}`")).collect();
                        if !optional.is_empty() {
                            parts.push(format!(
                                "optionally {}",
                                optional
                                    .iter()
                                    .map(|r| format!("`{r}`"))
                                    .collect::<Vec<_>>()
                                    .join(", ")
                            ));
                        }
                        parts.join(", ")
                    };
                    let why = match (*key, jt) {
                        ("angle" | "rate", JointType::Spherical) => {
                            " (it releases three rotations, not one angle)"
                        }
                        ("angle" | "rate", _) => " (it has no released angle)",
                        _ => "",
                    };
                    return Err(self.err(
                        k(key),
                        span.clone(),
                        format!("`{key}` does not belong to a {type_name} joint{why}; a {type_name} joint takes {takes}"),
                    ));
                }
            }

            let master_s = self.need(
                &j.master,
                &k("master"),
                &hs,
                "the master node's label, e.g. master = \"post.end\"",
            )?;
            let slave_s = self.need(
                &j.slave,
                &k("slave"),
                &hs,
                "the slave node's label, e.g. slave = \"arm.start\"",
            )?;
            let master = self.node(master_s, &k("master"), beams)?;
            let slave = self.node(slave_s, &k("slave"), beams)?;
            if master == slave {
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

            let need = |key: &str| format!("a {type_name} joint needs {}", joint_key_help(key));
            let axis = || -> Res<[f64; 3]> {
                let v = self.need(&j.axis, &k("axis"), &hs, &need("axis"))?;
                self.direction(v, &k("axis"))
            };
            let slide = || -> Res<[f64; 3]> {
                let v = self.need(&j.slide, &k("slide"), &hs, &need("slide"))?;
                self.direction(v, &k("slide"))
            };
            let perpendicular_slide = |axis: [f64; 3]| -> Res<[f64; 3]> {
                let v = self.need(&j.slide, &k("slide"), &hs, &need("slide"))?;
                let s = self.direction(v, &k("slide"))?;
                let cos = dot(s, axis);
                if cos.abs() > ANGLE_TOL {
                    return Err(self.at(
                        k("slide"),
                        v,
                        format!(
                            "must be perpendicular to `axis` for a {type_name} joint, found slide = {} \
                             and axis = {} with |cos(angle)| = {:.3e}",
                            fmt_v(v3(v.get_ref())),
                            fmt_v(axis),
                            cos.abs()
                        ),
                    ));
                }
                Ok(s)
            };
            let radius = || -> Res<f64> {
                let v = self.need(&j.radius, &k("radius"), &hs, &need("radius"))?;
                self.positive(v, &k("radius"))
            };
            let kind = match jt {
                JointType::Rigid => JointKind::Rigid,
                JointType::Spherical => JointKind::Spherical,
                JointType::Revolute => JointKind::Revolute { axis: axis()? },
                JointType::Prismatic => JointKind::Prismatic { slide: slide()? },
                JointType::Cylindrical => JointKind::Cylindrical {
                    axis: axis()?,
                    slide: slide()?,
                },
                JointType::Screw => {
                    let axis = axis()?;
                    let pitch = self.need(&j.pitch, &k("pitch"), &hs, &need("pitch"))?;
                    JointKind::Screw {
                        axis,
                        pitch: pitch.get_ref().0,
                    }
                }
                JointType::RackPinion => {
                    let axis = axis()?;
                    let radius = radius()?;
                    JointKind::RackPinion {
                        axis,
                        radius,
                        slide: perpendicular_slide(axis)?,
                    }
                }
                JointType::Cam => {
                    let axis = axis()?;
                    let radius = radius()?;
                    let offset = self.need(&j.offset, &k("offset"), &hs, &need("offset"))?;
                    JointKind::Cam {
                        axis,
                        radius,
                        offset: offset.get_ref().0,
                        slide: perpendicular_slide(axis)?,
                    }
                }
                JointType::Lobe => {
                    let axis = axis()?;
                    let slide = perpendicular_slide(axis)?;
                    let lift = self.need(&j.lift, &k("lift"), &hs, &need("lift"))?;
                    JointKind::Lobe {
                        axis,
                        slide,
                        lift: self.lift(lift, &k("lift"))?,
                    }
                }
            };
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

    fn lift(&self, l: &S<RawLift>, key: &str) -> Res<LiftSpec> {
        let lift = l.get_ref();
        match (&lift.table, &lift.fourier) {
            (Some(_), Some(f)) => Err(self.at(
                format!("{key}.fourier"),
                f,
                "give either `table` or `fourier`, not both",
            )),
            (None, None) => Err(self.at(
                key,
                l,
                "expected lift = { table = [[angle, lift], ...] } or lift = { fourier = [a0, a1, b1, ...] }",
            )),
            (Some(t), None) => {
                let key = format!("{key}.table");
                let rows = t.get_ref();
                if rows.len() < 3 {
                    return Err(self.at(
                        key,
                        t,
                        format!(
                            "a periodic lift table needs at least 3 rows [angle, lift], found {}",
                            rows.len()
                        ),
                    ));
                }
                let pairs: Vec<(f64, f64)> = rows
                    .iter()
                    .map(|r| (r.get_ref()[0].0, r.get_ref()[1].0))
                    .collect();
                for (r, w) in pairs.windows(2).enumerate() {
                    if w[1].0 <= w[0].0 {
                        return Err(self.at(
                            key,
                            &rows[r + 1],
                            format!(
                                "angles must be strictly increasing, but row {} has angle {:?} \
                                 after {:?} in row {r}",
                                r + 1,
                                w[1].0,
                                w[0].0
                            ),
                        ));
                    }
                }
                let first = pairs[0];
                let last = pairs[pairs.len() - 1];
                let scale = pairs.iter().fold(0.0_f64, |m, p| m.max(p.1.abs()));
                if (last.1 - first.1).abs() > 1e-12 * scale {
                    return Err(self.at(
                        key,
                        &rows[rows.len() - 1],
                        format!(
                            "the lift profile is periodic (period = last angle − first angle = {:?}), \
                             so the last lift must equal the first: found {:?} at angle {:?} and \
                             {:?} at angle {:?}; end the table with [{:?}, {:?}]",
                            last.0 - first.0,
                            first.1,
                            first.0,
                            last.1,
                            last.0,
                            last.0,
                            first.1
                        ),
                    ));
                }
                Ok(LiftSpec::Table(pairs))
            }
            (None, Some(f)) => {
                let c: Vec<f64> = f.get_ref().iter().map(|n| n.0).collect();
                if c.len() % 2 != 1 {
                    return Err(self.at(
                        format!("{key}.fourier"),
                        f,
                        format!(
                            "expected [a0, a1, b1, a2, b2, ...], an odd number of coefficients \
                             (a0, then cos/sin pairs), found {}",
                            c.len()
                        ),
                    ));
                }
                Ok(LiftSpec::Fourier(c))
            }
        }
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
            while let Some(&next) = slave_of.get(&node) {
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
