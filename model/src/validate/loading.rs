//! Supports, loads, prescribed motions and initial velocities.

use super::{quoted_list, Ctx, Res, DOFS, DOF_LIST};
use crate::labels::resolve_label;
use crate::raw::{
    v3, RawDistributedLoad, RawInitialVelocity, RawLoad, RawPrescribed, RawSupport, RawTimeFn,
    StrOrList, Vec3, S,
};
use crate::types::*;

/// What a nodal and a distributed load share: force and moment (zero where
/// left out), time function, follower flag.
type LoadValues = ([f64; 3], [f64; 3], Option<TimeFunction>, bool);

/// Largest difference, relative to the angle's size (at least 1 rad),
/// between a joint's initial angle and its drive's value at t = 0: the
/// round-off of writing the same number twice (π/2 as 1.5707963267948966
/// or as an expression).
const DRIVE_START_TOLERANCE: f64 = 1e-12;

impl Ctx<'_> {
    /// The values a `[[load]]` and a `[[distributed_load]]` share; `time_key`
    /// names the time function in messages.
    fn load_values(
        &self,
        force: &Option<S<Vec3>>,
        moment: &Option<S<Vec3>>,
        time: &Option<S<RawTimeFn>>,
        follower: &Option<S<bool>>,
        time_key: &str,
    ) -> Res<LoadValues> {
        let time = match time {
            Some(t) => Some(self.time_fn(t, time_key)?),
            None => None,
        };
        Ok((
            force.as_ref().map_or([0.0; 3], |f| v3(f.get_ref())),
            moment.as_ref().map_or([0.0; 3], |m| v3(m.get_ref())),
            time,
            follower.as_ref().is_some_and(|f| *f.get_ref()),
        ))
    }

    pub(super) fn supports(
        &self,
        raw: &[S<RawSupport>],
        beams: &[BeamSpec],
    ) -> Res<Vec<SupportSpec>> {
        let mut out = Vec::new();
        for (i, entry) in raw.iter().enumerate() {
            let tk = format!("support[{i}]");
            let k = |f: &str| format!("{tk}.{f}");
            let hs = entry.span();
            let s = entry.get_ref();
            let node_s = self.need(
                &s.node,
                &k("node"),
                &hs,
                "the supported node's label, e.g. node = \"post.start\"",
            )?;
            let node = self.node(node_s, &k("node"), beams)?;
            let fixed_s = self.need(
                &s.fixed,
                &k("fixed"),
                &hs,
                &format!("\"all\" or a list of the held DOFs from {DOF_LIST}"),
            )?;
            let fixed = match fixed_s.get_ref() {
                StrOrList::One(s) if s == "all" => [true; 6],
                StrOrList::One(s) => {
                    let hint = if DOFS.contains(&s.as_str()) {
                        format!("; to hold one DOF write fixed = [\"{s}\"]")
                    } else {
                        String::new()
                    };
                    return Err(self.at(
                        k("fixed"),
                        fixed_s,
                        format!("expected \"all\" or a list of DOF names from {DOF_LIST}, found \"{s}\"{hint}"),
                    ));
                }
                StrOrList::List(items) => {
                    if items.is_empty() {
                        return Err(self.at(
                            k("fixed"),
                            fixed_s,
                            format!("the list is empty; list the held DOFs from {DOF_LIST}, or write fixed = \"all\""),
                        ));
                    }
                    let mut fixed = [false; 6];
                    for item in items {
                        let name = item.get_ref();
                        let Some(d) = DOFS.iter().position(|d| d == name) else {
                            return Err(self.at(
                                k("fixed"),
                                item,
                                format!("unknown DOF name \"{name}\"; expected one of {DOF_LIST}"),
                            ));
                        };
                        if fixed[d] {
                            return Err(self.at(
                                k("fixed"),
                                item,
                                format!("DOF \"{name}\" is listed twice"),
                            ));
                        }
                        fixed[d] = true;
                    }
                    fixed
                }
            };
            out.push(SupportSpec { node, fixed });
        }
        Ok(out)
    }

    pub(super) fn loads(&self, raw: &[S<RawLoad>], beams: &[BeamSpec]) -> Res<Vec<LoadSpec>> {
        let mut out = Vec::new();
        for (i, entry) in raw.iter().enumerate() {
            let tk = format!("load[{i}]");
            let k = |f: &str| format!("{tk}.{f}");
            let hs = entry.span();
            let l = entry.get_ref();
            let node_s = self.need(
                &l.node,
                &k("node"),
                &hs,
                "the loaded node's label, e.g. node = \"arm.end\"",
            )?;
            let node = self.node(node_s, &k("node"), beams)?;
            if l.force.is_none() && l.moment.is_none() {
                return Err(self.err(
                    tk.clone(),
                    Some(hs.clone()),
                    "a load needs `force` and/or `moment`, e.g. force = [0.0, 0.0, -1.0]",
                ));
            }
            let (force, moment, time, follower) =
                self.load_values(&l.force, &l.moment, &l.time, &l.follower, &k("time"))?;
            out.push(LoadSpec {
                node,
                force,
                moment,
                time,
                follower,
            });
        }
        Ok(out)
    }

    pub(super) fn distributed_loads(
        &self,
        raw: &[S<RawDistributedLoad>],
        beams: &[BeamSpec],
    ) -> Res<Vec<DistributedLoadSpec>> {
        let mut out = Vec::new();
        for (i, entry) in raw.iter().enumerate() {
            let tk = format!("distributed_load[{i}]");
            let k = |f: &str| format!("{tk}.{f}");
            let hs = entry.span();
            let l = entry.get_ref();
            let beam_s = self.need(
                &l.beam,
                &k("beam"),
                &hs,
                "the loaded beam's name, e.g. beam = \"arm\"",
            )?;
            let Some(beam) = beams.iter().position(|b| &b.name == beam_s.get_ref()) else {
                let names: Vec<String> = beams.iter().map(|b| format!("\"{}\"", b.name)).collect();
                return Err(self.at(
                    k("beam"),
                    beam_s,
                    format!(
                        "no beam named \"{}\"; the beams are {}",
                        beam_s.get_ref(),
                        names.join(", ")
                    ),
                ));
            };
            if l.force.is_none() && l.moment.is_none() {
                return Err(self.err(
                    tk.clone(),
                    Some(hs.clone()),
                    "a distributed load needs `force` and/or `moment` per unit length, e.g. \
                     force = [0.0, 0.0, -1.0]",
                ));
            }
            let (force, moment, time, follower) =
                self.load_values(&l.force, &l.moment, &l.time, &l.follower, &k("time"))?;
            out.push(DistributedLoadSpec {
                beam,
                force,
                moment,
                time,
                follower,
            });
        }
        Ok(out)
    }

    pub(super) fn prescribed(
        &self,
        raw: &[S<RawPrescribed>],
        beams: &[BeamSpec],
        joints: &[JointSpec],
        supports: &[SupportSpec],
    ) -> Res<Vec<PrescribedSpec>> {
        let mut out: Vec<PrescribedSpec> = Vec::new();
        for (i, entry) in raw.iter().enumerate() {
            let p = entry.get_ref();
            let spec = if let Some(joint_s) = &p.joint {
                self.prescribed_angle(i, entry, joint_s, joints, &out)?
            } else {
                self.prescribed_dof(i, entry, beams, joints, supports, &out)?
            };
            out.push(spec);
        }
        Ok(out)
    }

    /// `prescribed[i]` (`entry`) driving the angle of joint `joint_s`: no
    /// node-DOF keys, a joint with a released angle not driven before (by
    /// the entries `out`), and the angle's time function.
    fn prescribed_angle(
        &self,
        i: usize,
        entry: &S<RawPrescribed>,
        joint_s: &S<String>,
        joints: &[JointSpec],
        out: &[PrescribedSpec],
    ) -> Res<PrescribedSpec> {
        let tk = format!("prescribed[{i}]");
        let k = |f: &str| format!("{tk}.{f}");
        let hs = entry.span();
        let p = entry.get_ref();
        let node_keys = [
            ("node", p.node.as_ref().map(S::span)),
            ("dof", p.dof.as_ref().map(S::span)),
            ("value", p.value.as_ref().map(S::span)),
        ];
        if let Some((key, span)) = node_keys.iter().find(|(_, s)| s.is_some()) {
            return Err(self.err(
                k(key),
                span.clone(),
                format!(
                    "`{key}` belongs to a prescribed node DOF (node + dof + value), but this \
                     entry drives joint \"{}\" (joint + angle); use two [[prescribed]] entries",
                    joint_s.get_ref()
                ),
            ));
        }
        let jname = joint_s.get_ref();
        let ji = self.driven_joint(&k("joint"), joint_s, joints)?;
        if let Some(o) = out
            .iter()
            .position(|q| matches!(q, PrescribedSpec::JointAngle { joint, .. } if *joint == ji))
        {
            return Err(self.at(
                k("joint"),
                joint_s,
                format!("the angle of joint \"{jname}\" is already prescribed by prescribed[{o}]"),
            ));
        }
        let angle_s = self.need(
            &p.angle,
            &k("angle"),
            &hs,
            "the released angle as a function of time, e.g. angle = { table = [[0.0, 0.0], [1.0, 6.2832]] }",
        )?;
        let angle = self.time_fn(angle_s, &k("angle"))?;
        // In dynamics the drive must start where the joint does: a jump at
        // t = 0 is an impulsive start the discrete equations cannot follow.
        // (In statics the drive is a function of the load factor and the
        // path from the reference state is an equilibrium sequence.)
        let (start, psi0) = (angle.eval(0.0), joints[ji].angle);
        if self.dynamic && (start - psi0).abs() > DRIVE_START_TOLERANCE * psi0.abs().max(1.0) {
            return Err(self.at(
                k("angle"),
                angle_s,
                format!(
                    "the drive gives joint \"{jname}\" the angle {start} at t = 0, but the \
                     joint starts at angle = {psi0}; start the drive at {psi0} or set the \
                     joint's `angle` to {start}"
                ),
            ));
        }
        Ok(PrescribedSpec::JointAngle { joint: ji, angle })
    }

    /// The index of joint `joint_s` (at key `key`) in `joints`: a known
    /// joint with one released angle to drive.
    fn driven_joint(&self, key: &str, joint_s: &S<String>, joints: &[JointSpec]) -> Res<usize> {
        let jname = joint_s.get_ref();
        let Some(ji) = joints.iter().position(|j| j.name == *jname) else {
            let known = if joints.is_empty() {
                "the file defines no [[joint]]".to_string()
            } else {
                format!(
                    "joints are {}",
                    quoted_list(joints.iter().map(|j| j.name.as_str()))
                )
            };
            return Err(self.at(key, joint_s, format!("unknown joint \"{jname}\"; {known}")));
        };
        let kind = &joints[ji].kind;
        if !kind.has_angle() {
            let names = kind.map().coordinate_names();
            let message = if names.len() == 3 {
                format!(
                    "joint \"{jname}\" is {}: it releases three rotations, and \
                     prescribing its rotation is not supported yet; use a revolute \
                     joint, or prescribe node DOFs (node + dof + value)",
                    kind.type_name()
                )
            } else {
                format!(
                    "joint \"{jname}\" is a {} joint: it has no released rotation, so \
                     there is no angle to prescribe",
                    kind.type_name()
                )
            };
            return Err(self.at(key, joint_s, message));
        }
        Ok(ji)
    }

    /// `prescribed[i]` (`entry`) driving a node DOF: no `angle`, the node,
    /// the DOF and its time function, for a DOF that no joint, support or
    /// earlier entry (of `out`) constrains already.
    fn prescribed_dof(
        &self,
        i: usize,
        entry: &S<RawPrescribed>,
        beams: &[BeamSpec],
        joints: &[JointSpec],
        supports: &[SupportSpec],
        out: &[PrescribedSpec],
    ) -> Res<PrescribedSpec> {
        let tk = format!("prescribed[{i}]");
        let k = |f: &str| format!("{tk}.{f}");
        let hs = entry.span();
        let p = entry.get_ref();
        if let Some(a) = &p.angle {
            return Err(self.at(
                k("angle"),
                a,
                "`angle` drives a joint's released angle and needs `joint = \"<joint name>\"`; \
                 to drive a node DOF use node + dof + value",
            ));
        }
        if p.node.is_none() && p.dof.is_none() && p.value.is_none() {
            return Err(self.err(
                tk.clone(),
                Some(hs.clone()),
                "expected `joint` + `angle` (drive a joint's released angle) or `node` + \
                 `dof` + `value` (drive a node DOF)",
            ));
        }
        let node_s = self.need(
            &p.node,
            &k("node"),
            &hs,
            "the driven node's label, e.g. node = \"post.start\"",
        )?;
        let dof_s = self.need(
            &p.dof,
            &k("dof"),
            &hs,
            &format!("the driven DOF, one of {DOF_LIST}"),
        )?;
        let value_s = self.need(
            &p.value,
            &k("value"),
            &hs,
            "the DOF's value as a function of time, e.g. value = { table = [[0.0, 0.0], [1.0, 0.1]] }",
        )?;
        let node = self.node(node_s, &k("node"), beams)?;
        let dof_name = dof_s.get_ref();
        let Some(dof) = DOFS.iter().position(|d| d == dof_name) else {
            return Err(self.at(
                k("dof"),
                dof_s,
                format!("unknown DOF name \"{dof_name}\"; expected one of {DOF_LIST}"),
            ));
        };
        self.driven_node_not_slave(&k("node"), node_s, node, joints)?;
        self.driven_dof_not_supported(&k("dof"), node_s, node, dof_s, dof, supports)?;
        self.driven_dof_not_prescribed(&k("dof"), node_s, node, dof_s, dof, out)?;
        let value = self.time_fn(value_s, &k("value"))?;
        Ok(PrescribedSpec::NodeDof { node, dof, value })
    }

    /// The driven node `node_s` (`node`, at key `key`) is no joint's slave.
    fn driven_node_not_slave(
        &self,
        key: &str,
        node_s: &S<String>,
        node: NodeRef,
        joints: &[JointSpec],
    ) -> Res<()> {
        if let Some(j) = joints.iter().position(|j| j.slave == node) {
            return Err(self.at(
                key,
                node_s,
                format!(
                    "node \"{}\" is the slave of joint \"{}\" (joint[{j}]): its motion follows \
                     the master; prescribe the master node or the joint angle instead",
                    node_s.get_ref(),
                    joints[j].name
                ),
            ));
        }
        Ok(())
    }

    /// The driven DOF `dof_s` (`dof`, at key `key`) of node `node_s`
    /// (`node`) is held by none of the `supports`.
    fn driven_dof_not_supported(
        &self,
        key: &str,
        node_s: &S<String>,
        node: NodeRef,
        dof_s: &S<String>,
        dof: usize,
        supports: &[SupportSpec],
    ) -> Res<()> {
        let dof_name = dof_s.get_ref();
        // A support holds the DOF at zero; prescribing it too would
        // silently override one of the two.
        if let Some(s) = supports.iter().position(|s| s.node == node && s.fixed[dof]) {
            return Err(self.at(
                key,
                dof_s,
                format!(
                    "DOF \"{dof_name}\" of node \"{}\" is also held by support[{s}].fixed; a DOF is \
                     either supported or prescribed: remove \"{dof_name}\" from support[{s}].fixed, \
                     or remove this prescribed entry",
                    node_s.get_ref()
                ),
            ));
        }
        Ok(())
    }

    /// The driven DOF `dof_s` (`dof`, at key `key`) of node `node_s`
    /// (`node`) is driven by none of the earlier entries `out`.
    fn driven_dof_not_prescribed(
        &self,
        key: &str,
        node_s: &S<String>,
        node: NodeRef,
        dof_s: &S<String>,
        dof: usize,
        out: &[PrescribedSpec],
    ) -> Res<()> {
        let dof_name = dof_s.get_ref();
        if let Some(o) = out.iter().position(|q| {
            matches!(q, PrescribedSpec::NodeDof { node: n, dof: d, .. } if *n == node && *d == dof)
        }) {
            return Err(self.at(
                key,
                dof_s,
                format!(
                    "DOF \"{dof_name}\" of node \"{}\" is already prescribed by prescribed[{o}]",
                    node_s.get_ref()
                ),
            ));
        }
        Ok(())
    }

    pub(super) fn initial_velocities(
        &self,
        raw: &[S<RawInitialVelocity>],
        beams: &[BeamSpec],
    ) -> Res<Vec<InitialVelocitySpec>> {
        let mut out = Vec::new();
        for (i, entry) in raw.iter().enumerate() {
            let tk = format!("initial_velocity[{i}]");
            let k = |f: &str| format!("{tk}.{f}");
            let hs = entry.span();
            let v = entry.get_ref();
            let nodes_s = self.need(
                &v.nodes,
                &k("nodes"),
                &hs,
                "a beam name (all its nodes) or a list of node labels, e.g. nodes = \"arm\" or nodes = [\"arm.end\"]",
            )?;
            let nodes = match nodes_s.get_ref() {
                StrOrList::One(name) => match beams.iter().position(|b| b.name == *name) {
                    Some(b) => (0..beams[b].node_count())
                        .map(|node| NodeRef { beam: b, node })
                        .collect(),
                    None => {
                        let message = if resolve_label(beams, name).is_ok() {
                            format!(
                                "\"{name}\" is a node label, but a string here must be a beam name; \
                                 for node labels write a list: nodes = [\"{name}\"]"
                            )
                        } else {
                            format!(
                                "no beam named \"{name}\"; give a beam name ({}) or a list of node labels",
                                quoted_list(beams.iter().map(|b| b.name.as_str()))
                            )
                        };
                        return Err(self.at(k("nodes"), nodes_s, message));
                    }
                },
                StrOrList::List(items) => {
                    if items.is_empty() {
                        return Err(self.at(
                            k("nodes"),
                            nodes_s,
                            "the list is empty; give node labels or a beam name",
                        ));
                    }
                    items
                        .iter()
                        .enumerate()
                        .map(|(n, item)| self.node(item, &format!("{tk}.nodes[{n}]"), beams))
                        .collect::<Res<Vec<_>>>()?
                }
            };
            let vec_or_zero =
                |f: &Option<S<Vec3>>| f.as_ref().map_or([0.0; 3], |x| v3(x.get_ref()));
            out.push(InitialVelocitySpec {
                nodes,
                linear: vec_or_zero(&v.linear),
                angular: vec_or_zero(&v.angular),
                origin: vec_or_zero(&v.origin),
            });
        }
        Ok(out)
    }
}
