//! From the raw file ([`RawModel`]) to the validated [`Model`]: every rule of
//! `MODEL_FORMAT.md` that serde cannot check by itself.

use std::ops::Range;
use std::path::Path;

use super::error::ModelError;
use super::expr::Expression;
use super::labels::resolve_label;
use super::locate::line_of;
use super::raw::{v3, Num, RawModel, RawTimeFn, Vec3, S};
use super::registry::JointRegistry;
use super::types::*;

mod geometry;
mod joints;
pub mod limits;
mod loading;
mod rigid_bodies;
mod rust_loads;
mod sensitivity;
pub(crate) use sensitivity::{add_sensitivity, analysis_allows_sensitivity, beam_end};
mod solver;

type Res<T> = Result<T, ModelError>;

/// DOF names in index order.
pub(crate) const DOFS: [&str; 6] = ["ux", "uy", "uz", "rx", "ry", "rz"];
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

/// The name of `names` closest to `word` by edit distance, when it is
/// near enough to be a misspelling (at most 2 edits, and fewer than half
/// the word's letters).
fn closest<'a>(word: &str, names: impl Iterator<Item = &'a str>) -> Option<&'a str> {
    let limit = (word.chars().count() / 2).clamp(1, 2);
    names
        .map(|n| (edit_distance(word, n), n))
        .filter(|&(d, _)| d <= limit)
        .min_by_key(|&(d, _)| d)
        .map(|(_, n)| n)
}

/// Levenshtein distance (insertions, deletions, substitutions).
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut diagonal = row[0];
        row[0] = i + 1;
        for (j, &cb) in b.iter().enumerate() {
            let next = (diagonal + usize::from(ca != cb))
                .min(row[j] + 1)
                .min(row[j + 1] + 1);
            diagonal = row[j + 1];
            row[j + 1] = next;
        }
    }
    row[b.len()]
}

fn quoted_list<'a>(names: impl Iterator<Item = &'a str>) -> String {
    names
        .map(|n| format!("\"{n}\""))
        .collect::<Vec<_>>()
        .join(", ")
}

// ---------------------------------------------------------------------------
// The validator.

struct Ctx<'a> {
    file: &'a Path,
    text: &'a str,
    /// The joint kinds the file may name.
    registry: &'a JointRegistry,
    /// Whether `[solver] analysis = "dynamic"` (time functions of `t`, not
    /// of the load factor `lambda`).
    dynamic: bool,
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

    /// An integer in `[min, max]`; `max` is one of the documented [`limits`]
    /// and the message says why it is there.
    fn int_in(&self, v: &S<i64>, key: &str, min: i64, max: (i64, &str)) -> Res<usize> {
        let n = *v.get_ref();
        if n < min {
            return Err(self.at(key, v, format!("must be >= {min}, found {n}")));
        }
        if n > max.0 {
            return Err(self.at(
                key,
                v,
                format!("must be <= {} ({}), found {n}", max.0, max.1),
            ));
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
            RawTimeFn::Expr(text) => {
                let e = Expression::parse(text).map_err(|e| {
                    self.at(
                        key,
                        v,
                        format!("the expression \"{text}\" is not valid {e}"),
                    )
                })?;
                if self.dynamic && e.uses_lambda() {
                    return Err(self.at(
                        key,
                        v,
                        format!(
                            "the expression \"{text}\" names `lambda`, the load factor of a \
                             static analysis; in a dynamic analysis write `t` (the time)"
                        ),
                    ));
                }
                TimeFunction::Expression(e)
            }
        };
        if let Err(message) = f.validate() {
            // Point at the first row out of order when there is one.
            let span = match v.get_ref() {
                RawTimeFn::Table(rows) => rows
                    .windows(2)
                    .find(|w| w[1].get_ref()[0].0 <= w[0].get_ref()[0].0)
                    .map_or_else(|| v.span(), |w| w[1].span()),
                RawTimeFn::Constant(_) | RawTimeFn::Expr(_) => v.span(),
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
        } else if s.len() > limits::MAX_NAME_BYTES {
            Some("must be at most 200 bytes long (file systems allow 255 per file name)")
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
}

/// Validates the raw file `raw` (parsed from `text`, read from `file`).
pub(crate) fn validate(
    raw: RawModel,
    text: &str,
    file: &Path,
    registry: &JointRegistry,
) -> Result<Model, ModelError> {
    let dynamic = raw
        .solver
        .as_ref()
        .and_then(|s| s.get_ref().analysis.as_ref())
        .is_some_and(|a| a.get_ref() == "dynamic");
    let cx = Ctx {
        file,
        text,
        registry,
        dynamic,
    };
    let name = cx.model_name(&raw.name)?;
    let gravity = raw.gravity.as_ref().map_or([0.0; 3], |g| v3(g.get_ref()));
    let sections = cx.sections(&raw.section)?;
    let beams = cx.beams(&raw.beam, &sections)?;
    let supports = cx.supports(&raw.support, &beams)?;
    let joints = cx.joints(&raw.joint, &beams)?;
    cx.topology(&raw.support, &supports, &raw.joint, &joints)?;
    let loads = cx.loads(&raw.load, &beams)?;
    let distributed_loads = cx.distributed_loads(&raw.distributed_load, &beams)?;
    let prescribed = cx.prescribed(&raw.prescribed, &beams, &joints, &supports)?;
    let initial_velocities = cx.initial_velocities(&raw.initial_velocity, &beams)?;
    let rigid_bodies = cx.rigid_bodies(&raw.rigid_body, &beams)?;
    let rust_loads = cx.rust_loads(&raw.rust_load, &beams)?;
    let solver = cx.solver(raw.solver.as_ref(), &beams)?;
    cx.massive(&raw.section, &sections, &beams, &solver)?;
    let output = cx.output(raw.output.as_ref(), &beams)?;
    let mut model = Model {
        name,
        path: file.to_path_buf(),
        source_text: text.to_string(),
        gravity,
        sections,
        beams,
        supports,
        joints,
        loads,
        distributed_loads,
        prescribed,
        initial_velocities,
        rigid_bodies,
        rust_loads,
        solver,
        output,
        source_written: String::new(),
    };
    model.output.sensitivity = cx.sensitivity(raw.output.as_ref(), &model)?;
    model.source_written = model.to_toml();
    Ok(model)
}
