//! From the raw file ([`RawModel`]) to the validated [`Model`]: every rule of
//! `MODEL_FORMAT.md` that serde cannot check by itself.

use std::collections::HashMap;
use std::f64::consts::TAU;
use std::ops::Range;
use std::path::Path;

use super::error::ModelError;
use super::labels::resolve_label;
use super::locate::line_of;
use super::raw::{
    v3, Num, RawArc, RawBeam, RawInitialVelocity, RawJoint, RawLift, RawLoad, RawModel, RawOutput,
    RawPrescribed, RawSection, RawSolver, RawSupport, RawTimeFn, StrOrList, Vec3, S,
};
use super::types::*;

type Res<T> = Result<T, ModelError>;

/// DOF names in index order.
const DOFS: [&str; 6] = ["ux", "uy", "uz", "rx", "ry", "rz"];
const DOF_LIST: &str = "\"ux\", \"uy\", \"uz\", \"rx\", \"ry\", \"rz\"";
/// |sin| or |cos| below which two directions count as parallel / perpendicular.
const ANGLE_TOL: f64 = 1e-8;

// ---------------------------------------------------------------------------
// Small vector helpers.

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

/// `a / |a|`, or `None` for the zero vector (robust against overflow).
fn unit(a: [f64; 3]) -> Option<[f64; 3]> {
    let m = a.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    if m == 0.0 || !m.is_finite() {
        return None;
    }
    let b = [a[0] / m, a[1] / m, a[2] / m];
    let n = norm(b);
    Some([b[0] / n, b[1] / n, b[2] / n])
}

fn fmt_v(a: [f64; 3]) -> String {
    format!("[{:?}, {:?}, {:?}]", a[0], a[1], a[2])
}

/// A global axis not parallel to unit `t`, to suggest in messages.
fn suggest_not_parallel(t: [f64; 3]) -> [f64; 3] {
    let mut best = 0;
    for i in 1..3 {
        if t[i].abs() < t[best].abs() {
            best = i;
        }
    }
    let mut e = [0.0; 3];
    e[best] = 1.0;
    e
}

fn quoted_list<'a>(names: impl Iterator<Item = &'a str>) -> String {
    names
        .map(|n| format!("\"{n}\""))
        .collect::<Vec<_>>()
        .join(", ")
}

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

struct Ctx<'a> {
    file: &'a Path,
    text: &'a str,
}

impl Ctx<'_> {
    fn err(
        &self,
        key: impl Into<String>,
        span: Option<Range<usize>>,
        message: impl Into<String>,
    ) -> ModelError {
        let line = span.map(|s| line_of(self.text, s.start));
        ModelError::new(self.file, key, line, message)
    }

    fn at<T>(
        &self,
        key: impl Into<String>,
        value: &S<T>,
        message: impl Into<String>,
    ) -> ModelError {
        self.err(key, Some(value.span()), message)
    }

    /// `value`, or an error ``missing key `<last part of key>`: <help>`` at the
    /// line of the enclosing table `table`.
    fn need<'v, T>(
        &self,
        value: &'v Option<S<T>>,
        key: &str,
        table: &Range<usize>,
        help: &str,
    ) -> Res<&'v S<T>> {
        value.as_ref().ok_or_else(|| {
            let field = key.rsplit('.').next().unwrap_or(key);
            self.err(
                key,
                Some(table.clone()),
                format!("missing key `{field}`: {help}"),
            )
        })
    }

    fn positive(&self, v: &S<Num>, key: &str) -> Res<f64> {
        let x = v.get_ref().0;
        if x > 0.0 {
            Ok(x)
        } else {
            Err(self.at(key, v, format!("must be > 0, found {x:?}")))
        }
    }

    fn positive_n<const N: usize>(&self, v: &S<[Num; N]>, key: &str) -> Res<[f64; N]> {
        let a = v.get_ref().map(|n| n.0);
        match a.iter().position(|&x| x <= 0.0) {
            None => Ok(a),
            Some(k) => Err(self.at(
                key,
                v,
                format!(
                    "every component must be > 0, found {a:?} (component {k} is {:?})",
                    a[k]
                ),
            )),
        }
    }

    fn non_negative(&self, v: &S<Num>, key: &str) -> Res<f64> {
        let x = v.get_ref().0;
        if x >= 0.0 {
            Ok(x)
        } else {
            Err(self.at(key, v, format!("must be >= 0, found {x:?}")))
        }
    }

    fn non_negative_n<const N: usize>(&self, v: &S<[Num; N]>, key: &str) -> Res<[f64; N]> {
        let a = v.get_ref().map(|n| n.0);
        match a.iter().position(|&x| x < 0.0) {
            None => Ok(a),
            Some(k) => Err(self.at(
                key,
                v,
                format!(
                    "every component must be >= 0, found {a:?} (component {k} is {:?})",
                    a[k]
                ),
            )),
        }
    }

    fn int_at_least(&self, v: &S<i64>, key: &str, min: i64) -> Res<usize> {
        let n = *v.get_ref();
        if n < min {
            return Err(self.at(key, v, format!("must be >= {min}, found {n}")));
        }
        usize::try_from(n).map_err(|_| self.at(key, v, format!("is too large, found {n}")))
    }

    /// A nonzero vector, normalised.
    fn direction(&self, v: &S<Vec3>, key: &str) -> Res<[f64; 3]> {
        let a = v3(v.get_ref());
        unit(a).ok_or_else(|| {
            self.at(
                key,
                v,
                format!(
                    "must be a nonzero vector (it gives a direction), found {}",
                    fmt_v(a)
                ),
            )
        })
    }

    fn node(&self, label: &S<String>, key: &str, beams: &[BeamSpec]) -> Res<NodeRef> {
        resolve_label(beams, label.get_ref()).map_err(|m| self.at(key, label, m))
    }

    /// The `name` of an array-of-tables entry: present and non-empty.
    fn entity_name<'v>(
        &self,
        name: &'v Option<S<String>>,
        tk: &str,
        table: &Range<usize>,
        what: &str,
    ) -> Res<&'v S<String>> {
        let key = format!("{tk}.name");
        let n = self.need(
            name,
            &key,
            table,
            &format!("every [[{what}]] needs a unique name, e.g. name = \"{what}-1\""),
        )?;
        if n.get_ref().trim().is_empty() {
            return Err(self.at(key, n, "must not be empty"));
        }
        Ok(n)
    }

    fn time_fn(&self, v: &S<RawTimeFn>, key: &str) -> Res<TimeFunction> {
        let f = match v.get_ref() {
            RawTimeFn::Constant(c) => TimeFunction::Constant(*c),
            RawTimeFn::Table(rows) => TimeFunction::Table(
                rows.iter()
                    .map(|r| (r.get_ref()[0].0, r.get_ref()[1].0))
                    .collect(),
            ),
        };
        if let Err(message) = f.validate() {
            // Point at the first row out of order when there is one.
            let span = match v.get_ref() {
                RawTimeFn::Table(rows) => rows
                    .windows(2)
                    .find(|w| w[1].get_ref()[0].0 <= w[0].get_ref()[0].0)
                    .map_or_else(|| v.span(), |w| w[1].span()),
                RawTimeFn::Constant(_) => v.span(),
            };
            return Err(self.err(key, Some(span), message));
        }
        Ok(f)
    }

    // -----------------------------------------------------------------------

    fn model_name(&self, name: &Option<S<String>>) -> Res<String> {
        let n = name.as_ref().ok_or_else(|| {
            self.err(
                "name",
                None,
                "missing key `name`: every model needs a name, e.g. name = \"my-mechanism\" \
                 (the results are written to <name>.h5)",
            )
        })?;
        let s = n.get_ref();
        let problem = if s.trim().is_empty() {
            Some("must not be empty")
        } else if s.contains('/') || s.contains('\\') {
            Some("must not contain '/' or '\\'")
        } else if s.starts_with('.') {
            Some("must not start with '.'")
        } else if s.chars().any(char::is_control) {
            Some("must not contain control characters")
        } else {
            None
        };
        match problem {
            Some(p) => Err(self.at(
                "name",
                n,
                format!("{p}, because the results are written to <name>.h5; found \"{s}\""),
            )),
            None => Ok(s.clone()),
        }
    }

    fn sections(&self, raw: &[S<RawSection>]) -> Res<Vec<SectionSpec>> {
        let mut out: Vec<SectionSpec> = Vec::new();
        for (i, entry) in raw.iter().enumerate() {
            let tk = format!("section[{i}]");
            let k = |f: &str| format!("{tk}.{f}");
            let hs = entry.span();
            let s = entry.get_ref();
            let name_s = self.entity_name(&s.name, &tk, &hs, "section")?;
            let name = name_s.get_ref().clone();
            if let Some(j) = out.iter().position(|o| o.name == name) {
                return Err(self.at(
                    k("name"),
                    name_s,
                    format!("duplicate section name \"{name}\" (section[{j}] has it too); section names must be unique"),
                ));
            }
            let ea = self.need(&s.ea, &k("EA"), &hs, "the axial stiffness, e.g. EA = 2.0e6")?;
            let ga = self.need(
                &s.ga,
                &k("GA"),
                &hs,
                "the shear stiffnesses [GA2, GA3], e.g. GA = [8.0e5, 8.0e5]",
            )?;
            let gj = self.need(
                &s.gj,
                &k("GJ"),
                &hs,
                "the torsional stiffness, e.g. GJ = 1.0e3",
            )?;
            let ei = self.need(
                &s.ei,
                &k("EI"),
                &hs,
                "the bending stiffnesses [EI2, EI3], e.g. EI = [1.5e3, 1.5e3]",
            )?;
            let rho_a = match &s.rho_a {
                Some(v) => self.non_negative(v, &k("rhoA"))?,
                None => 0.0,
            };
            let rho_j = match &s.rho_j {
                Some(v) => self.non_negative_n(v, &k("rhoJ"))?,
                None => [0.0; 3],
            };
            out.push(SectionSpec {
                name,
                ea: self.positive(ea, &k("EA"))?,
                ga: self.positive_n(ga, &k("GA"))?,
                gj: self.positive(gj, &k("GJ"))?,
                ei: self.positive_n(ei, &k("EI"))?,
                rho_a,
                rho_j,
            });
        }
        Ok(out)
    }

    fn beams(&self, raw: &[S<RawBeam>], sections: &[SectionSpec]) -> Res<Vec<BeamSpec>> {
        let mut out: Vec<BeamSpec> = Vec::new();
        for (i, entry) in raw.iter().enumerate() {
            let tk = format!("beam[{i}]");
            let k = |f: &str| format!("{tk}.{f}");
            let hs = entry.span();
            let b = entry.get_ref();
            let name_s = self.entity_name(&b.name, &tk, &hs, "beam")?;
            let name = name_s.get_ref().clone();
            if name.contains('.') || name.contains('/') {
                return Err(self.at(
                    k("name"),
                    name_s,
                    format!(
                        "beam names must not contain '.' or '/', because node labels are \
                         <beam>.<node> and name result groups /nodes/<label>; found \"{name}\""
                    ),
                ));
            }
            if let Some(j) = out.iter().position(|o| o.name == name) {
                return Err(self.at(
                    k("name"),
                    name_s,
                    format!("duplicate beam name \"{name}\" (beam[{j}] has it too); beam names must be unique"),
                ));
            }
            let sec_s = self.need(
                &b.section,
                &k("section"),
                &hs,
                "the name of a [[section]], e.g. section = \"steel-tube\"",
            )?;
            let section = sections
                .iter()
                .position(|s| s.name == *sec_s.get_ref())
                .ok_or_else(|| {
                    let known = if sections.is_empty() {
                        "the file defines no [[section]]".to_string()
                    } else {
                        format!(
                            "sections are {}",
                            quoted_list(sections.iter().map(|s| s.name.as_str()))
                        )
                    };
                    self.at(
                        k("section"),
                        sec_s,
                        format!("unknown section \"{}\"; {known}", sec_s.get_ref()),
                    )
                })?;
            let elements_s = self.need(
                &b.elements,
                &k("elements"),
                &hs,
                "the number of elements, e.g. elements = 4",
            )?;
            let elements = self.int_at_least(elements_s, &k("elements"), 1)?;
            let nodes_per_element = match &b.nodes_per_element {
                None => 2,
                Some(v) => match *v.get_ref() {
                    2 => 2,
                    3 => 3,
                    n => {
                        return Err(self.at(
                            k("nodes_per_element"),
                            v,
                            format!(
                                "must be 2 (linear elements) or 3 (quadratic elements), found {n}"
                            ),
                        ))
                    }
                },
            };
            let geometry = self.geometry(b, &tk, &hs)?;
            out.push(BeamSpec {
                name,
                section,
                geometry,
                elements,
                nodes_per_element,
            });
        }
        Ok(out)
    }

    fn geometry(&self, b: &RawBeam, tk: &str, hs: &Range<usize>) -> Res<BeamGeometry> {
        let k = |f: &str| format!("{tk}.{f}");
        if let Some(arc) = &b.arc {
            let straight = [("start", &b.start), ("end", &b.end)];
            if let Some((which, Some(v))) = straight.iter().find(|(_, v)| v.is_some()) {
                return Err(self.at(
                    k(which),
                    v,
                    format!(
                        "a beam is either straight (`start` and `end`) or an arc (`arc = {{ ... }}`), \
                         not both; remove `{which}` or `arc` (the arc has its own `start`)"
                    ),
                ));
            }
            return self.arc(arc, b.e2.as_ref(), tk);
        }
        let (start_s, end_s) = match (&b.start, &b.end) {
            (Some(s), Some(e)) => (s, e),
            (Some(_), None) | (None, Some(_)) => {
                let missing = if b.start.is_none() { "start" } else { "end" };
                return Err(self.err(
                    k(missing),
                    Some(hs.clone()),
                    format!(
                        "missing key `{missing}`: a straight beam needs both `start` and `end` \
                         (or give `arc = {{ start, center, normal, sweep }}` instead)"
                    ),
                ));
            }
            (None, None) => {
                return Err(self.err(
                    tk,
                    Some(hs.clone()),
                    "missing geometry: give `start` and `end` for a straight beam, or \
                     `arc = { start = [...], center = [...], normal = [...], sweep = ... }` \
                     for a circular arc",
                ))
            }
        };
        let start = v3(start_s.get_ref());
        let end = v3(end_s.get_ref());
        let Some(t) = unit(sub(end, start)) else {
            return Err(self.at(
                k("end"),
                end_s,
                format!(
                    "`end` equals `start` ({}); a beam needs a nonzero length",
                    fmt_v(start)
                ),
            ));
        };
        let e2_s = self.need(
            &b.e2,
            &k("e2"),
            hs,
            &format!(
                "a straight beam needs the section's second axis, a direction not parallel \
                 to the beam, e.g. e2 = {}",
                fmt_v(suggest_not_parallel(t))
            ),
        )?;
        let e2 = self.direction(e2_s, &k("e2"))?;
        if norm(cross(t, e2)) <= ANGLE_TOL {
            return Err(self.at(
                k("e2"),
                e2_s,
                format!(
                    "must not be parallel to the beam (end − start = {}), found {}; \
                     choose e.g. e2 = {}",
                    fmt_v(sub(end, start)),
                    fmt_v(v3(e2_s.get_ref())),
                    fmt_v(suggest_not_parallel(t))
                ),
            ));
        }
        Ok(BeamGeometry::Straight { start, end, e2 })
    }

    fn arc(&self, arc_s: &S<RawArc>, e2_s: Option<&S<Vec3>>, tk: &str) -> Res<BeamGeometry> {
        let k = |f: &str| format!("{tk}.arc.{f}");
        let hs = arc_s.span();
        let a = arc_s.get_ref();
        let start_s = self.need(
            &a.start,
            &k("start"),
            &hs,
            "the arc's first point, e.g. start = [0.0, 0.0, 0.0]",
        )?;
        let center_s = self.need(
            &a.center,
            &k("center"),
            &hs,
            "the arc's center, e.g. center = [1.0, 0.0, 0.0]",
        )?;
        let normal_s = self.need(
            &a.normal,
            &k("normal"),
            &hs,
            "the axis the arc turns about (right-hand rule), e.g. normal = [0.0, 0.0, 1.0]",
        )?;
        let sweep_s = self.need(
            &a.sweep,
            &k("sweep"),
            &hs,
            "the angle the arc turns through, in radians, e.g. sweep = 1.5707963",
        )?;
        let start = v3(start_s.get_ref());
        let center = v3(center_s.get_ref());
        let r = sub(start, center);
        let Some(r_hat) = unit(r) else {
            return Err(self.at(
                k("center"),
                center_s,
                format!(
                    "`center` equals `start` ({}): the radius |start − center| must be > 0",
                    fmt_v(start)
                ),
            ));
        };
        let normal = self.direction(normal_s, &k("normal"))?;
        let cos = dot(normal, r_hat);
        if cos.abs() >= ANGLE_TOL {
            return Err(self.at(
                k("normal"),
                normal_s,
                format!(
                    "must be perpendicular to start − center = {} (the arc lies in the plane \
                     through `start` perpendicular to `normal`), found {} with |cos(angle)| = {:.3e}",
                    fmt_v(r),
                    fmt_v(v3(normal_s.get_ref())),
                    cos.abs()
                ),
            ));
        }
        let sweep = sweep_s.get_ref().0;
        if sweep == 0.0 {
            return Err(self.at(
                k("sweep"),
                sweep_s,
                "must be nonzero (the angle the arc turns through, in radians), found 0.0",
            ));
        }
        if sweep.abs() > TAU * (1.0 + 1e-12) {
            return Err(self.at(
                k("sweep"),
                sweep_s,
                format!("must satisfy |sweep| <= 2π = {TAU:?} (one full turn), found {sweep:?}"),
            ));
        }
        let e2 = match e2_s {
            None => None,
            Some(v) => {
                let key = format!("{tk}.e2");
                let d = self.direction(v, &key)?;
                let tangent = cross(normal, r_hat);
                if norm(cross(tangent, d)) <= ANGLE_TOL {
                    return Err(self.at(
                        key,
                        v,
                        format!(
                            "must not be parallel to the arc's tangent at its start \
                             (normal × (start − center)/radius = {}), found {}",
                            fmt_v(tangent),
                            fmt_v(v3(v.get_ref()))
                        ),
                    ));
                }
                Some(d)
            }
        };
        Ok(BeamGeometry::Arc {
            start,
            center,
            normal,
            sweep,
            e2,
        })
    }

    fn supports(&self, raw: &[S<RawSupport>], beams: &[BeamSpec]) -> Res<Vec<SupportSpec>> {
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

    fn joints(&self, raw: &[S<RawJoint>], beams: &[BeamSpec]) -> Res<Vec<JointSpec>> {
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
    fn topology(
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

    fn loads(&self, raw: &[S<RawLoad>], beams: &[BeamSpec]) -> Res<Vec<LoadSpec>> {
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
            let time = match &l.time {
                Some(t) => Some(self.time_fn(t, &k("time"))?),
                None => None,
            };
            out.push(LoadSpec {
                node,
                force: l.force.as_ref().map_or([0.0; 3], |f| v3(f.get_ref())),
                moment: l.moment.as_ref().map_or([0.0; 3], |m| v3(m.get_ref())),
                time,
            });
        }
        Ok(out)
    }

    fn prescribed(
        &self,
        raw: &[S<RawPrescribed>],
        beams: &[BeamSpec],
        joints: &[JointSpec],
    ) -> Res<Vec<PrescribedSpec>> {
        let mut out: Vec<PrescribedSpec> = Vec::new();
        for (i, entry) in raw.iter().enumerate() {
            let tk = format!("prescribed[{i}]");
            let k = |f: &str| format!("{tk}.{f}");
            let hs = entry.span();
            let p = entry.get_ref();
            if let Some(joint_s) = &p.joint {
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
                let Some(ji) = joints.iter().position(|j| j.name == *jname) else {
                    let known = if joints.is_empty() {
                        "the file defines no [[joint]]".to_string()
                    } else {
                        format!(
                            "joints are {}",
                            quoted_list(joints.iter().map(|j| j.name.as_str()))
                        )
                    };
                    return Err(self.at(
                        k("joint"),
                        joint_s,
                        format!("unknown joint \"{jname}\"; {known}"),
                    ));
                };
                match joints[ji].kind {
                    JointKind::Rigid | JointKind::Prismatic { .. } => {
                        return Err(self.at(
                            k("joint"),
                            joint_s,
                            format!(
                                "joint \"{jname}\" is a {} joint: it has no released rotation, so \
                                 there is no angle to prescribe",
                                joints[ji].kind.type_name()
                            ),
                        ))
                    }
                    JointKind::Spherical => {
                        return Err(self.at(
                            k("joint"),
                            joint_s,
                            format!(
                                "joint \"{jname}\" is spherical: it releases three rotations, and \
                                 prescribing a spherical joint's rotation is not supported yet; use \
                                 a revolute joint, or prescribe node DOFs (node + dof + value)"
                            ),
                        ))
                    }
                    _ => {}
                }
                if let Some(o) = out.iter().position(
                    |q| matches!(q, PrescribedSpec::JointAngle { joint, .. } if *joint == ji),
                ) {
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
                out.push(PrescribedSpec::JointAngle { joint: ji, angle });
            } else {
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
                if let Some(j) = joints.iter().position(|j| j.slave == node) {
                    return Err(self.at(
                        k("node"),
                        node_s,
                        format!(
                            "node \"{}\" is the slave of joint \"{}\" (joint[{j}]): its motion follows \
                             the master; prescribe the master node or the joint angle instead",
                            node_s.get_ref(),
                            joints[j].name
                        ),
                    ));
                }
                if let Some(o) = out.iter().position(|q| {
                    matches!(q, PrescribedSpec::NodeDof { node: n, dof: d, .. } if *n == node && *d == dof)
                }) {
                    return Err(self.at(
                        k("dof"),
                        dof_s,
                        format!(
                            "DOF \"{dof_name}\" of node \"{}\" is already prescribed by prescribed[{o}]",
                            node_s.get_ref()
                        ),
                    ));
                }
                let value = self.time_fn(value_s, &k("value"))?;
                out.push(PrescribedSpec::NodeDof { node, dof, value });
            }
        }
        Ok(out)
    }

    fn initial_velocities(
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

    fn solver(&self, raw: Option<&S<RawSolver>>) -> Res<SolverSpec> {
        let Some(entry) = raw else {
            return Ok(SolverSpec {
                analysis: Analysis::Static { load_steps: 10 },
                tolerance: 1e-10,
                max_iterations: 25,
                max_halvings: 10,
                mass: MassKind::Consistent,
            });
        };
        let hs = entry.span();
        let s = entry.get_ref();
        let dynamic = match &s.analysis {
            None => false,
            Some(a) => match a.get_ref().as_str() {
                "static" => false,
                "dynamic" => true,
                other => {
                    return Err(self.at(
                        "solver.analysis",
                        a,
                        format!("expected \"static\" or \"dynamic\", found \"{other}\""),
                    ))
                }
            },
        };
        let analysis = if dynamic {
            if let Some(l) = &s.load_steps {
                return Err(self.at(
                    "solver.load_steps",
                    l,
                    "`load_steps` belongs to a static analysis, but analysis = \"dynamic\"; a \
                     dynamic analysis steps with `dt` up to `t_end`: remove `load_steps`",
                ));
            }
            let integrators = [
                IntegratorKind::Newmark,
                IntegratorKind::Momentum,
                IntegratorKind::EnergyMomentum,
            ];
            let names = quoted_list(integrators.iter().map(|i| i.name()));
            let int_s = self.need(
                &s.integrator,
                "solver.integrator",
                &hs,
                &format!("a dynamic analysis needs an integrator, one of {names}"),
            )?;
            let Some(&integrator) = integrators.iter().find(|i| i.name() == int_s.get_ref()) else {
                return Err(self.at(
                    "solver.integrator",
                    int_s,
                    format!(
                        "unknown integrator \"{}\"; expected one of {names}",
                        int_s.get_ref()
                    ),
                ));
            };
            let dt_s = self.need(
                &s.dt,
                "solver.dt",
                &hs,
                "a dynamic analysis needs the time step, e.g. dt = 0.01",
            )?;
            let dt = self.positive(dt_s, "solver.dt")?;
            let t_end_s = self.need(
                &s.t_end,
                "solver.t_end",
                &hs,
                "a dynamic analysis needs the end time, e.g. t_end = 1.0",
            )?;
            let t_end = self.positive(t_end_s, "solver.t_end")?;
            if dt > t_end {
                return Err(self.at(
                    "solver.dt",
                    dt_s,
                    format!("must be <= t_end = {t_end:?}, found {dt:?}"),
                ));
            }
            Analysis::Dynamic {
                integrator,
                dt,
                t_end,
            }
        } else {
            let dynamic_only = [
                ("dt", s.dt.as_ref().map(S::span)),
                ("t_end", s.t_end.as_ref().map(S::span)),
                ("integrator", s.integrator.as_ref().map(S::span)),
            ];
            if let Some((key, span)) = dynamic_only.iter().find(|(_, sp)| sp.is_some()) {
                let default = if s.analysis.is_none() {
                    " (the default)"
                } else {
                    ""
                };
                return Err(self.err(
                    format!("solver.{key}"),
                    span.clone(),
                    format!(
                        "`{key}` belongs to a dynamic analysis, but this analysis is static{default}; \
                         set analysis = \"dynamic\", or remove `{key}` (a static analysis takes `load_steps`)"
                    ),
                ));
            }
            let load_steps = match &s.load_steps {
                Some(l) => self.int_at_least(l, "solver.load_steps", 1)?,
                None => 10,
            };
            Analysis::Static { load_steps }
        };
        let tolerance = match &s.tolerance {
            Some(t) => self.positive(t, "solver.tolerance")?,
            None => 1e-10,
        };
        let max_iterations = match &s.max_iterations {
            Some(m) => self.int_at_least(m, "solver.max_iterations", 1)?,
            None => 25,
        };
        let max_halvings = match &s.max_halvings {
            Some(m) => self.int_at_least(m, "solver.max_halvings", 0)?,
            None => 10,
        };
        let mass = match &s.mass {
            None => MassKind::Consistent,
            Some(m) => match m.get_ref().as_str() {
                "consistent" => MassKind::Consistent,
                "lumped" => MassKind::Lumped,
                other => {
                    return Err(self.at(
                        "solver.mass",
                        m,
                        format!("expected \"consistent\" or \"lumped\", found \"{other}\""),
                    ))
                }
            },
        };
        Ok(SolverSpec {
            analysis,
            tolerance,
            max_iterations,
            max_halvings,
            mass,
        })
    }

    fn output(&self, raw: Option<&S<RawOutput>>, beams: &[BeamSpec]) -> Res<OutputSpec> {
        let Some(entry) = raw else {
            return Ok(OutputSpec {
                every: 1,
                track: Vec::new(),
            });
        };
        let o = entry.get_ref();
        let every = match &o.every {
            Some(e) => self.int_at_least(e, "output.every", 1)?,
            None => 1,
        };
        let mut track: Vec<(String, NodeRef)> = Vec::new();
        if let Some(list) = &o.track {
            for (n, item) in list.get_ref().iter().enumerate() {
                let key = format!("output.track[{n}]");
                let label = item.get_ref();
                if track.iter().any(|(l, _)| l == label) {
                    return Err(self.at(key, item, format!("node \"{label}\" is listed twice")));
                }
                track.push((label.clone(), self.node(item, &key, beams)?));
            }
        }
        Ok(OutputSpec { every, track })
    }
}

/// Validates the raw file `raw` (parsed from `text`, read from `file`).
pub(crate) fn validate(raw: RawModel, text: &str, file: &Path) -> Result<Model, ModelError> {
    let cx = Ctx { file, text };
    let name = cx.model_name(&raw.name)?;
    let gravity = raw.gravity.as_ref().map_or([0.0; 3], |g| v3(g.get_ref()));
    let sections = cx.sections(&raw.section)?;
    let beams = cx.beams(&raw.beam, &sections)?;
    let supports = cx.supports(&raw.support, &beams)?;
    let joints = cx.joints(&raw.joint, &beams)?;
    cx.topology(&raw.support, &supports, &raw.joint, &joints)?;
    let loads = cx.loads(&raw.load, &beams)?;
    let prescribed = cx.prescribed(&raw.prescribed, &beams, &joints)?;
    let initial_velocities = cx.initial_velocities(&raw.initial_velocity, &beams)?;
    let solver = cx.solver(raw.solver.as_ref())?;
    let output = cx.output(raw.output.as_ref(), &beams)?;
    Ok(Model {
        name,
        path: file.to_path_buf(),
        source_text: text.to_string(),
        gravity,
        sections,
        beams,
        supports,
        joints,
        loads,
        prescribed,
        initial_velocities,
        solver,
        output,
    })
}
