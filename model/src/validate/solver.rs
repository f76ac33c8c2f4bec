//! The `[solver]` and `[output]` tables.

use std::ops::Range;

use super::{limits, quoted_list, Ctx, Res};
use crate::raw::{RawOutput, RawSolver, S};
use crate::types::*;
use flexmech_integrators::dynamics::generalized_alpha::DEFAULT_RHO_INF;

/// `max_arc_steps` when the file gives none: this many per `load_steps`.
const DEFAULT_ARC_STEPS_PER_LOAD_STEP: usize = 100;

/// `modes` when the file gives none.
const DEFAULT_MODES: usize = 10;

impl Ctx<'_> {
    pub(super) fn solver(&self, raw: Option<&S<RawSolver>>, beams: &[BeamSpec]) -> Res<SolverSpec> {
        let Some(entry) = raw else {
            return Ok(SolverSpec::default());
        };
        let hs = entry.span();
        let s = entry.get_ref();
        let analysis = match self.analysis_name(s)? {
            "dynamic" => self.dynamic_analysis(s, &hs)?,
            "modal" | "buckling" => self.linearised_analysis(s)?,
            _ => self.static_analysis(s)?,
        };
        if let (Some(m), false) = (
            &s.modes,
            matches!(analysis, Analysis::Modal { .. } | Analysis::Buckling { .. }),
        ) {
            return Err(self.at(
                "solver.modes",
                m,
                format!(
                    "`modes` belongs to analysis = \"modal\" or \"buckling\", but this \
                     analysis is {}; remove `modes`, or set the analysis",
                    analysis.name()
                ),
            ));
        }
        let tolerance = match &s.tolerance {
            Some(t) => self.positive(t, "solver.tolerance")?,
            None => SolverSpec::default().tolerance,
        };
        let max_iterations = match &s.max_iterations {
            Some(m) => self.int_in(m, "solver.max_iterations", 1, limits::MAX_ITERATIONS)?,
            None => SolverSpec::default().max_iterations,
        };
        let max_halvings = match &s.max_halvings {
            Some(m) => self.int_in(m, "solver.max_halvings", 0, limits::MAX_HALVINGS)?,
            None => SolverSpec::default().max_halvings,
        };
        let mass = self.mass_kind(s)?;
        let (modified_newton, exact_tangent) = self.newton_kind(s, &analysis)?;
        let rotation = self.rotation(s, &analysis)?;
        let eigensolver = self.eigensolver(s, &analysis)?;
        let stop = self.stop(s, &analysis, beams)?;
        Ok(SolverSpec {
            stop,
            rotation,
            eigensolver,
            analysis,
            tolerance,
            max_iterations,
            max_halvings,
            mass,
            modified_newton,
            exact_tangent,
        })
    }

    /// `solver.analysis`: "static" (also when absent), "dynamic", "modal"
    /// or "buckling".
    fn analysis_name(&self, s: &RawSolver) -> Res<&'static str> {
        const NAMES: [&str; 4] = ["static", "dynamic", "modal", "buckling"];
        let Some(a) = &s.analysis else {
            return Ok("static");
        };
        match NAMES.iter().find(|n| **n == a.get_ref().as_str()) {
            Some(n) => Ok(n),
            None => Err(self.at(
                "solver.analysis",
                a,
                format!(
                    "expected one of {}, found \"{}\"",
                    quoted_list(NAMES.iter().copied()),
                    a.get_ref()
                ),
            )),
        }
    }

    /// A modal or buckling analysis: `modes` (default 10); a modal one
    /// also `load_steps` (its static preload path, default 10); neither
    /// takes the keys of dynamics or of arc-length control.
    fn linearised_analysis(&self, s: &RawSolver) -> Res<Analysis> {
        let name = s.analysis.as_ref().map_or("", |a| a.get_ref().as_str());
        let foreign = [
            ("dt", s.dt.as_ref().map(S::span)),
            ("t_end", s.t_end.as_ref().map(S::span)),
            ("integrator", s.integrator.as_ref().map(S::span)),
            ("rho_inf", s.rho_inf.as_ref().map(S::span)),
            ("control", s.control.as_ref().map(S::span)),
            ("max_arc_steps", s.max_arc_steps.as_ref().map(S::span)),
            ("branch_switch", s.branch_switch.as_ref().map(S::span)),
            ("stop", s.stop.as_ref().map(S::span)),
            (
                "load_steps",
                s.load_steps
                    .as_ref()
                    .map(S::span)
                    .filter(|_| name == "buckling"),
            ),
            (
                "mass",
                s.mass.as_ref().map(S::span).filter(|_| name == "buckling"),
            ),
        ];
        if let Some((key, span)) = foreign.iter().find(|(_, sp)| sp.is_some()) {
            return Err(self.err(
                format!("solver.{key}"),
                span.clone(),
                format!(
                    "`{key}` does not belong to analysis = \"{name}\" (it takes `modes`{}); \
                     remove `{key}`",
                    if name == "modal" {
                        ", `load_steps` for the static state it is about, and `mass`"
                    } else {
                        ": it multiplies the model's loads about the undeformed state"
                    }
                ),
            ));
        }
        let modes = match &s.modes {
            Some(m) => self.int_in(m, "solver.modes", 1, limits::MAX_MODES)?,
            None => DEFAULT_MODES,
        };
        Ok(if name == "buckling" {
            Analysis::Buckling { modes }
        } else {
            let load_steps = match &s.load_steps {
                Some(l) => self.int_in(l, "solver.load_steps", 1, limits::MAX_LOAD_STEPS)?,
                None => 10,
            };
            Analysis::Modal { modes, load_steps }
        })
    }

    /// The dynamic analysis of `[solver]` (spanning `hs`): no static keys,
    /// the integrator, and `dt` and `t_end`.
    fn dynamic_analysis(&self, s: &RawSolver, hs: &Range<usize>) -> Res<Analysis> {
        self.no_static_keys(s)?;
        let integrator = self.integrator(s, hs)?;
        let dt_s = self.need(
            &s.dt,
            "solver.dt",
            hs,
            "a dynamic analysis needs the time step, e.g. dt = 0.01",
        )?;
        let dt = self.positive(dt_s, "solver.dt")?;
        let t_end_s = self.need(
            &s.t_end,
            "solver.t_end",
            hs,
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
        if t_end / dt > limits::MAX_TIME_STEPS {
            return Err(self.at(
                "solver.dt",
                dt_s,
                format!(
                    "gives t_end/dt = {:.3e} steps, more than the {:.0e} a run may take \
                     (one stored record each); use a larger dt or a shorter t_end",
                    t_end / dt,
                    limits::MAX_TIME_STEPS
                ),
            ));
        }
        Ok(Analysis::Dynamic {
            integrator,
            dt,
            t_end,
        })
    }

    /// A dynamic analysis has none of the static keys: `load_steps`, then
    /// `control`, `max_arc_steps` and `branch_switch`.
    fn no_static_keys(&self, s: &RawSolver) -> Res<()> {
        if let Some(l) = &s.load_steps {
            return Err(self.at(
                "solver.load_steps",
                l,
                "`load_steps` belongs to a static analysis, but analysis = \"dynamic\"; a \
                 dynamic analysis steps with `dt` up to `t_end`: remove `load_steps`",
            ));
        }
        for (key, v) in [
            ("control", s.control.as_ref().map(S::span)),
            ("max_arc_steps", s.max_arc_steps.as_ref().map(S::span)),
            ("branch_switch", s.branch_switch.as_ref().map(S::span)),
        ] {
            if let Some(span) = v {
                return Err(self.err(
                    format!("solver.{key}"),
                    Some(span),
                    format!(
                        "`{key}` belongs to a static analysis (load or arc-length control), \
                         but analysis = \"dynamic\"; remove `{key}`"
                    ),
                ));
            }
        }
        Ok(())
    }

    /// `solver.integrator` of a dynamic analysis (`[solver]` spanning `hs`),
    /// with `rho_inf` for the generalized-alpha scheme only.
    fn integrator(&self, s: &RawSolver, hs: &Range<usize>) -> Res<IntegratorKind> {
        let integrators = [
            IntegratorKind::Newmark,
            IntegratorKind::GeneralizedAlpha {
                rho_inf: DEFAULT_RHO_INF,
            },
            IntegratorKind::Momentum,
            IntegratorKind::EnergyMomentum,
            IntegratorKind::EnergyMomentumPaper,
        ];
        let names = quoted_list(integrators.iter().map(|i| i.name()));
        let int_s = self.need(
            &s.integrator,
            "solver.integrator",
            hs,
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
        Ok(match (integrator, &s.rho_inf) {
            (IntegratorKind::GeneralizedAlpha { .. }, Some(r)) => {
                let rho_inf = r.get_ref().0;
                if !(0.0..=1.0).contains(&rho_inf) {
                    return Err(self.at(
                        "solver.rho_inf",
                        r,
                        format!(
                            "the spectral radius at infinite frequency must lie in [0, 1] \
                             (1: no numerical damping, 0: the most), found {rho_inf:?}"
                        ),
                    ));
                }
                IntegratorKind::GeneralizedAlpha { rho_inf }
            }
            (_, Some(r)) => {
                return Err(self.at(
                    "solver.rho_inf",
                    r,
                    format!(
                        "`rho_inf` belongs to integrator = \"generalized-alpha\", but this \
                         run uses \"{}\"; remove `rho_inf` or change the integrator",
                        integrator.name()
                    ),
                ))
            }
            (integrator, None) => integrator,
        })
    }

    /// The static analysis of `[solver]`: no dynamic keys, `load_steps`,
    /// and load or arc-length control with its keys.
    fn static_analysis(&self, s: &RawSolver) -> Res<Analysis> {
        let dynamic_only = [
            ("dt", s.dt.as_ref().map(S::span)),
            ("t_end", s.t_end.as_ref().map(S::span)),
            ("integrator", s.integrator.as_ref().map(S::span)),
            ("rho_inf", s.rho_inf.as_ref().map(S::span)),
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
            Some(l) => self.int_in(l, "solver.load_steps", 1, limits::MAX_LOAD_STEPS)?,
            None => 10,
        };
        let arc_length = self.is_arc_length(s)?;
        let branch_switch = match (&s.branch_switch, arc_length) {
            (Some(b), false) => {
                return Err(self.at(
                    "solver.branch_switch",
                    b,
                    "`branch_switch` belongs to control = \"arc-length\"; set it, or \
                     remove `branch_switch`",
                ))
            }
            (b, _) => b.as_ref().is_some_and(|b| *b.get_ref()),
        };
        Ok(match (&s.max_arc_steps, arc_length) {
            (Some(m), true) => Analysis::ArcLength {
                load_steps,
                max_steps: self.int_in(m, "solver.max_arc_steps", 1, limits::MAX_LOAD_STEPS)?,
                branch_switch,
            },
            (None, true) => Analysis::ArcLength {
                load_steps,
                max_steps: DEFAULT_ARC_STEPS_PER_LOAD_STEP * load_steps,
                branch_switch,
            },
            (Some(m), false) => {
                return Err(self.at(
                    "solver.max_arc_steps",
                    m,
                    "`max_arc_steps` belongs to control = \"arc-length\"; set it, or \
                     remove `max_arc_steps`",
                ))
            }
            (None, false) => Analysis::Static { load_steps },
        })
    }

    /// `solver.control`: whether it is "arc-length" (absent: load control).
    fn is_arc_length(&self, s: &RawSolver) -> Res<bool> {
        Ok(match &s.control {
            None => false,
            Some(c) => match c.get_ref().as_str() {
                "load" => false,
                "arc-length" => true,
                other => {
                    return Err(self.at(
                        "solver.control",
                        c,
                        format!("expected \"load\" or \"arc-length\", found \"{other}\""),
                    ))
                }
            },
        })
    }

    /// `solver.rotation = { axis, origin, rate }` of a static or modal
    /// analysis (`origin` defaults to the global origin).
    fn rotation(&self, s: &RawSolver, analysis: &Analysis) -> Res<Option<Rotation>> {
        let Some(r) = &s.rotation else {
            return Ok(None);
        };
        if matches!(
            analysis,
            Analysis::Dynamic { .. } | Analysis::Buckling { .. }
        ) {
            return Err(self.at(
                "solver.rotation",
                r,
                format!(
                    "a steady spin of the frame belongs to static and modal analyses, but this \
                     analysis is {}; remove `rotation`{}",
                    analysis.name(),
                    if analysis.name() == "dynamic" {
                        " (a dynamic run spins the structure itself: initial velocities, drivers)"
                    } else {
                        ""
                    }
                ),
            ));
        }
        let (raw, span) = (r.get_ref(), r.span());
        let axis = self.need(
            &raw.axis,
            "solver.rotation.axis",
            &span,
            "the spin axis, e.g. axis = [0.0, 0.0, 1.0]",
        )?;
        let axis = self.direction(axis, "solver.rotation.axis")?;
        let origin = raw
            .origin
            .as_ref()
            .map_or([0.0; 3], |o| super::v3(o.get_ref()));
        let rate = self.need(
            &raw.rate,
            "solver.rotation.rate",
            &span,
            "the spin rate in radians per unit of time, e.g. rate = 10.0",
        )?;
        Ok(Some(Rotation {
            axis,
            origin,
            rate: rate.get_ref().0,
        }))
    }

    /// `solver.stop` of an arc-length path: `load_factor` (positive) and
    /// `displacement = { node, max }` (a node of the mesh, `max` positive).
    fn stop(
        &self,
        s: &RawSolver,
        analysis: &Analysis,
        beams: &[BeamSpec],
    ) -> Res<Option<PathStopSpec>> {
        let Some(st) = &s.stop else {
            return Ok(None);
        };
        if !matches!(analysis, Analysis::ArcLength { .. }) {
            return Err(self.at(
                "solver.stop",
                st,
                format!(
                    "`stop` ends an arc-length path (control = \"arc-length\"), but this \
                     analysis is {}{}; set control = \"arc-length\", or remove `stop`",
                    analysis.name(),
                    if matches!(analysis, Analysis::Static { .. }) {
                        " with load control (it ends at load factor 1)"
                    } else {
                        ""
                    }
                ),
            ));
        }
        let raw = st.get_ref();
        let load_factor = match &raw.load_factor {
            Some(l) => Some(self.positive(l, "solver.stop.load_factor")?),
            None => None,
        };
        let displacement = match &raw.displacement {
            None => None,
            Some(d) => {
                let span = d.span();
                let node = self.need(
                    &d.get_ref().node,
                    "solver.stop.displacement.node",
                    &span,
                    "the node whose displacement ends the path, e.g. node = \"beam.end\"",
                )?;
                let max = self.need(
                    &d.get_ref().max,
                    "solver.stop.displacement.max",
                    &span,
                    "the displacement |x − X| at which the path ends, e.g. max = 0.5",
                )?;
                Some(DisplacementStop {
                    label: node.get_ref().clone(),
                    node: self.node(node, "solver.stop.displacement.node", beams)?,
                    max: self.positive(max, "solver.stop.displacement.max")?,
                })
            }
        };
        Ok(Some(PathStopSpec {
            load_factor,
            displacement,
        }))
    }

    /// `solver.eigensolver` of a modal or buckling analysis: "auto" (the
    /// default: dense up to 600 unknowns), "dense" or "sparse".
    fn eigensolver(&self, s: &RawSolver, analysis: &Analysis) -> Res<Option<EigenSolver>> {
        let Some(e) = &s.eigensolver else {
            return Ok(None);
        };
        if !matches!(analysis, Analysis::Modal { .. } | Analysis::Buckling { .. }) {
            return Err(self.at(
                "solver.eigensolver",
                e,
                format!(
                    "`eigensolver` belongs to analysis = \"modal\" or \"buckling\", but this \
                     analysis is {}; remove `eigensolver`",
                    analysis.name()
                ),
            ));
        }
        match e.get_ref().as_str() {
            "auto" => Ok(None),
            "dense" => Ok(Some(EigenSolver::Dense)),
            "sparse" => Ok(Some(EigenSolver::Sparse)),
            other => Err(self.at(
                "solver.eigensolver",
                e,
                format!("expected \"auto\", \"dense\" or \"sparse\", found \"{other}\""),
            )),
        }
    }

    /// `solver.mass`: consistent (the default) or lumped.
    fn mass_kind(&self, s: &RawSolver) -> Res<MassKind> {
        Ok(match &s.mass {
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
        })
    }

    /// `solver.newton` as `(modified_newton, exact_tangent)`: modified Newton
    /// only for a dynamic analysis whose integrator allows it.
    fn newton_kind(&self, s: &RawSolver, analysis: &Analysis) -> Res<(bool, bool)> {
        Ok(match &s.newton {
            None => (false, false),
            Some(m) => match m.get_ref().as_str() {
                "full" => (false, false),
                "exact" => (false, true),
                "modified" => match analysis {
                    Analysis::Static { .. }
                    | Analysis::ArcLength { .. }
                    | Analysis::Modal { .. }
                    | Analysis::Buckling { .. } => {
                        return Err(self.at(
                            "solver.newton",
                            m,
                            "modified Newton is for dynamic analyses (a static path checks \
                             the stability of every converged state with its exact tangent); \
                             remove `newton` or set it to \"full\"",
                        ))
                    }
                    Analysis::Dynamic {
                        integrator: IntegratorKind::EnergyMomentumPaper,
                        ..
                    } => {
                        return Err(self.at(
                            "solver.newton",
                            m,
                            "the paper's energy-momentum scheme solves a bordered system with \
                             the exact tangent at every iterate; use newton = \"full\", or \
                             integrator = \"energy-momentum\"",
                        ))
                    }
                    Analysis::Dynamic { .. } => (true, false),
                },
                other => {
                    return Err(self.at(
                        "solver.newton",
                        m,
                        format!("expected \"full\", \"exact\" or \"modified\", found \"{other}\""),
                    ))
                }
            },
        })
    }

    pub(super) fn output(&self, raw: Option<&S<RawOutput>>, beams: &[BeamSpec]) -> Res<OutputSpec> {
        let Some(entry) = raw else {
            return Ok(OutputSpec::default());
        };
        let o = entry.get_ref();
        let every = match &o.every {
            Some(e) => self.int_in(e, "output.every", 1, limits::MAX_EVERY)?,
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
        Ok(OutputSpec {
            every,
            track,
            resultants: o.resultants.as_ref().is_some_and(|r| *r.get_ref()),
            vtk: o.vtk.as_ref().is_some_and(|r| *r.get_ref()),
            // Checked against the whole model (validate/sensitivity.rs).
            sensitivity: Vec::new(),
        })
    }
}
