//! Sections and beams: stiffnesses, straight and arc geometry.

use std::f64::consts::TAU;
use std::ops::Range;

use super::limits;
use super::{
    cross, dot, fmt_v, norm, quoted_list, sub, suggest_not_parallel, unit, Ctx, Res, ANGLE_TOL,
};
use crate::raw::{v3, RawArc, RawBeam, RawSection, Vec3, S};
use crate::types::*;

impl Ctx<'_> {
    pub(super) fn sections(&self, raw: &[S<RawSection>]) -> Res<Vec<SectionSpec>> {
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
                values: SectionValues {
                    ea: self.positive(ea, &k("EA"))?,
                    ga: self.positive_n(ga, &k("GA"))?,
                    gj: self.positive(gj, &k("GJ"))?,
                    ei: self.positive_n(ei, &k("EI"))?,
                    rho_a,
                    rho_j,
                },
                damping: match &s.damping {
                    Some(v) => self.non_negative(v, &k("damping"))?,
                    None => 0.0,
                },
            });
        }
        Ok(out)
    }

    /// A dynamic analysis needs mass: every section a beam uses must have
    /// `rhoA > 0` (without it the mass matrix is singular and no integrator
    /// can give a meaningful answer).
    pub(super) fn massive(
        &self,
        raw: &[S<RawSection>],
        sections: &[SectionSpec],
        beams: &[BeamSpec],
        solver: &SolverSpec,
    ) -> Res<()> {
        if !solver.analysis.needs_mass() {
            return Ok(());
        }
        for beam in beams {
            let (i, sec) = (beam.section, &sections[beam.section]);
            if sec.values.rho_a > 0.0 {
                continue;
            }
            let key = format!("section[{i}].rhoA");
            let given = raw[i].get_ref().rho_a.as_ref();
            let what =
                format!(
                "a dynamic analysis needs mass, but section \"{}\" (used by beam \"{}\") has {}; \
                 give its mass per unit length, e.g. rhoA = 7.85, or make the analysis static",
                sec.name,
                beam.name,
                if given.is_some() { "rhoA = 0" } else { "no rhoA" }
            );
            return Err(match given {
                Some(v) => self.at(key, v, what),
                None => self.err(key, Some(raw[i].span()), what),
            });
        }
        Ok(())
    }

    pub(super) fn beams(&self, raw: &[S<RawBeam>], sections: &[SectionSpec]) -> Res<Vec<BeamSpec>> {
        let mut out: Vec<BeamSpec> = Vec::new();
        let mut total_elements = 0usize;
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
            let elements = self.int_in(elements_s, &k("elements"), 1, limits::MAX_ELEMENTS)?;
            total_elements += elements;
            if total_elements > limits::MAX_ELEMENTS.0 as usize {
                return Err(self.at(
                    k("elements"),
                    elements_s,
                    format!(
                        "brings the model to {total_elements} elements, more than {} ({})",
                        limits::MAX_ELEMENTS.0,
                        limits::MAX_ELEMENTS.1
                    ),
                ));
            }
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
        Ok(BeamGeometry::Straight {
            start: start.into(),
            end: end.into(),
            e2: e2.into(),
        })
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
            start: start.into(),
            center: center.into(),
            normal: normal.into(),
            sweep,
            e2: e2.map(Into::into),
        })
    }
}
