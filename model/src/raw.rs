//! The model file as written: serde structs that mirror the TOML keys exactly
//! (see `MODEL_FORMAT.md`). Unknown keys are errors. Almost every field is an
//! `Option<Spanned<_>>` so that the validator can report missing keys itself and
//! give the line of any value it rejects.

use std::fmt;

use serde::de::{self, Deserializer, MapAccess, SeqAccess, Visitor};
use serde::Deserialize;
use toml::Spanned;

/// A value with its byte span in the file.
pub(crate) type S<T> = Spanned<T>;

/// A finite number (TOML integers are accepted too). NaN and infinities are
/// rejected while deserialising, so the error carries the value's position.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Num(pub f64);

impl<'de> Deserialize<'de> for Num {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let v = f64::deserialize(d)?;
        if v.is_finite() {
            Ok(Num(v))
        } else {
            Err(de::Error::custom(format!(
                "must be a finite number, found {v:?}"
            )))
        }
    }
}

/// A 3-vector of finite numbers.
pub(crate) type Vec3 = [Num; 3];

/// Converts a raw vector.
pub(crate) fn v3(a: &Vec3) -> [f64; 3] {
    [a[0].0, a[1].0, a[2].0]
}

/// The whole file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawModel {
    pub name: Option<S<String>>,
    pub gravity: Option<S<Vec3>>,
    #[serde(default)]
    pub section: Vec<S<RawSection>>,
    #[serde(default)]
    pub beam: Vec<S<RawBeam>>,
    #[serde(default)]
    pub support: Vec<S<RawSupport>>,
    #[serde(default)]
    pub joint: Vec<S<RawJoint>>,
    #[serde(default)]
    pub load: Vec<S<RawLoad>>,
    #[serde(default)]
    pub distributed_load: Vec<S<RawDistributedLoad>>,
    #[serde(default)]
    pub prescribed: Vec<S<RawPrescribed>>,
    #[serde(default)]
    pub initial_velocity: Vec<S<RawInitialVelocity>>,
    #[serde(default)]
    pub rigid_body: Vec<S<RawRigidBody>>,
    #[serde(default)]
    pub rust_load: Vec<S<RawRustLoad>>,
    pub solver: Option<S<RawSolver>>,
    pub output: Option<S<RawOutput>>,
}

/// The keys of [`RawModel`] that are arrays of tables (`[[name]]`).
pub(crate) const ARRAY_TABLES: [&str; 8] = [
    "section",
    "beam",
    "support",
    "joint",
    "load",
    "distributed_load",
    "prescribed",
    "initial_velocity",
];

/// `[[section]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawSection {
    pub name: Option<S<String>>,
    #[serde(rename = "EA")]
    pub ea: Option<S<Num>>,
    #[serde(rename = "GA")]
    pub ga: Option<S<[Num; 2]>>,
    #[serde(rename = "GJ")]
    pub gj: Option<S<Num>>,
    #[serde(rename = "EI")]
    pub ei: Option<S<[Num; 2]>>,
    #[serde(rename = "rhoA")]
    pub rho_a: Option<S<Num>>,
    #[serde(rename = "rhoJ")]
    pub rho_j: Option<S<Vec3>>,
    pub damping: Option<S<Num>>,
}

/// `[[beam]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawBeam {
    pub name: Option<S<String>>,
    pub section: Option<S<String>>,
    pub start: Option<S<Vec3>>,
    pub end: Option<S<Vec3>>,
    pub arc: Option<S<RawArc>>,
    pub elements: Option<S<i64>>,
    pub nodes_per_element: Option<S<i64>>,
    pub e2: Option<S<Vec3>>,
}

/// `arc = { start, center, normal, sweep }` of a beam.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawArc {
    pub start: Option<S<Vec3>>,
    pub center: Option<S<Vec3>>,
    pub normal: Option<S<Vec3>>,
    pub sweep: Option<S<Num>>,
}

/// `[[support]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawSupport {
    pub node: Option<S<String>>,
    pub fixed: Option<S<StrOrList>>,
}

/// `[[joint]]`: the keys every joint has; the kind's own parameters are read
/// from the same table by the joint registry (which refuses unknown keys).
#[derive(Debug, Deserialize)]
pub(crate) struct RawJoint {
    pub name: Option<S<String>>,
    #[serde(rename = "type")]
    pub kind: Option<S<String>>,
    pub master: Option<S<String>>,
    pub slave: Option<S<String>>,
    pub angle: Option<S<Num>>,
    pub rate: Option<S<Num>>,
}

/// `[[load]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawLoad {
    pub node: Option<S<String>>,
    pub force: Option<S<Vec3>>,
    pub moment: Option<S<Vec3>>,
    pub time: Option<S<RawTimeFn>>,
    pub follower: Option<S<bool>>,
}

/// `[[rust_load]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawRustLoad {
    pub name: Option<S<String>>,
    pub nodes: Option<S<Vec<S<String>>>>,
}

/// `[[distributed_load]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawDistributedLoad {
    pub beam: Option<S<String>>,
    pub force: Option<S<Vec3>>,
    pub moment: Option<S<Vec3>>,
    pub follower: Option<S<bool>>,
    pub time: Option<S<RawTimeFn>>,
}

/// `[[prescribed]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawPrescribed {
    pub joint: Option<S<String>>,
    pub angle: Option<S<RawTimeFn>>,
    pub node: Option<S<String>>,
    pub dof: Option<S<String>>,
    pub value: Option<S<RawTimeFn>>,
}

/// `[[initial_velocity]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawInitialVelocity {
    pub nodes: Option<S<StrOrList>>,
    pub linear: Option<S<Vec3>>,
    pub angular: Option<S<Vec3>>,
    pub origin: Option<S<Vec3>>,
}

/// `[[rigid_body]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawRigidBody {
    pub name: Option<S<String>>,
    pub node: Option<S<String>>,
    pub mass: Option<S<Num>>,
    pub inertia: Option<S<Vec<NumOrRow>>>,
    pub offset: Option<S<Vec3>>,
}

/// An entry of `inertia`: a principal value or a row of the 3×3 tensor.
#[derive(Debug, Deserialize)]
#[serde(untagged)]
pub(crate) enum NumOrRow {
    Num(Num),
    Row([Num; 3]),
}

/// `[solver]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawSolver {
    pub analysis: Option<S<String>>,
    pub integrator: Option<S<String>>,
    pub dt: Option<S<Num>>,
    pub t_end: Option<S<Num>>,
    pub load_steps: Option<S<i64>>,
    pub tolerance: Option<S<Num>>,
    pub max_iterations: Option<S<i64>>,
    pub max_halvings: Option<S<i64>>,
    pub mass: Option<S<String>>,
    pub newton: Option<S<String>>,
    pub rho_inf: Option<S<Num>>,
    pub control: Option<S<String>>,
    pub max_arc_steps: Option<S<i64>>,
    pub branch_switch: Option<S<bool>>,
    pub modes: Option<S<i64>>,
    pub rotation: Option<S<RawRotation>>,
    pub eigensolver: Option<S<String>>,
    pub stop: Option<S<RawStop>>,
}

/// `[solver] stop`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawStop {
    pub load_factor: Option<S<Num>>,
    pub displacement: Option<S<RawDisplacementStop>>,
}

/// `[solver] stop.displacement`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawDisplacementStop {
    pub node: Option<S<String>>,
    pub max: Option<S<Num>>,
}

/// `[solver] rotation`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawRotation {
    pub axis: Option<S<Vec3>>,
    pub origin: Option<S<Vec3>>,
    pub rate: Option<S<Num>>,
}

/// `[output]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawOutput {
    pub every: Option<S<i64>>,
    pub track: Option<S<Vec<S<String>>>>,
    pub resultants: Option<S<bool>>,
    pub vtk: Option<S<bool>>,
    pub sensitivity: Option<S<Vec<S<String>>>>,
}

/// A string or a list of strings (`fixed`, `nodes`).
#[derive(Debug)]
pub(crate) enum StrOrList {
    One(String),
    List(Vec<S<String>>),
}

impl<'de> Deserialize<'de> for StrOrList {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = StrOrList;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a string or a list of strings")
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<StrOrList, E> {
                Ok(StrOrList::One(v.to_string()))
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<StrOrList, A::Error> {
                let mut items = Vec::new();
                while let Some(item) = seq.next_element::<S<String>>()? {
                    items.push(item);
                }
                Ok(StrOrList::List(items))
            }
        }
        d.deserialize_any(V)
    }
}

/// A time function as written: a number (constant) or `{ table = [[t, v], ...] }`.
#[derive(Debug)]
pub(crate) enum RawTimeFn {
    Constant(f64),
    Table(Vec<S<[Num; 2]>>),
    Expr(String),
}

impl<'de> Deserialize<'de> for RawTimeFn {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl V {
            fn constant<E: de::Error>(v: f64) -> Result<RawTimeFn, E> {
                if v.is_finite() {
                    Ok(RawTimeFn::Constant(v))
                } else {
                    Err(E::custom(format!("must be a finite number, found {v:?}")))
                }
            }
        }
        impl<'de> Visitor<'de> for V {
            type Value = RawTimeFn;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str(
                    "a number, a table { table = [[t, value], ...] } or an expression \
                     { expr = \"...\" }",
                )
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<RawTimeFn, E> {
                V::constant(v)
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<RawTimeFn, E> {
                V::constant(v as f64)
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<RawTimeFn, E> {
                V::constant(v as f64)
            }
            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<RawTimeFn, A::Error> {
                let (mut table, mut expr) = (None, None);
                while let Some(key) = map.next_key::<String>()? {
                    match key.as_str() {
                        "table" if table.is_some() => {
                            return Err(de::Error::duplicate_field("table"))
                        }
                        "table" => table = Some(map.next_value::<Vec<S<[Num; 2]>>>()?),
                        "expr" if expr.is_some() => return Err(de::Error::duplicate_field("expr")),
                        "expr" => expr = Some(map.next_value::<String>()?),
                        _ => return Err(de::Error::unknown_field(&key, &["table", "expr"])),
                    }
                }
                match (table, expr) {
                    (Some(rows), None) => Ok(RawTimeFn::Table(rows)),
                    (None, Some(text)) => Ok(RawTimeFn::Expr(text)),
                    (Some(_), Some(_)) => {
                        Err(de::Error::custom("give either `table` or `expr`, not both"))
                    }
                    (None, None) => Err(de::Error::custom(
                        "missing key `table` or `expr`: write { table = [[t, value], ...] }, \
                         { expr = \"...\" } or a number",
                    )),
                }
            }
        }
        d.deserialize_any(V)
    }
}
