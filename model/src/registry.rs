//! The joint kinds model files can name: `type` → kind.
//!
//! Every kind, built-in or written in a user's crate, implements
//! [`ModelJoint`] (its `type` name and a serde parameter struct, declared once
//! in the kind's own file). A [`JointRegistry`] holds the kinds a program
//! knows; [`JointRegistry::builtin`] the ten of flexmech. A user's binary adds
//! its own and hands the registry to the command line
//! (`flexmech::cli::main_with`), so `run`, `check`, `study` and `reproduce` read
//! model files that name them:
//!
//! ```
//! use flexmech_joints::Screw;
//! use flexmech_model::JointRegistry;
//!
//! let mut registry = JointRegistry::builtin();
//! // A user's kind is registered the same way: registry.register::<MyJoint>()?
//! assert!(registry.register::<Screw>().is_err(), "names are unique");
//! assert!(registry.names().any(|n| n == "rack_pinion"));
//! ```

use std::any::Any;
use std::fmt;
use std::sync::Arc;

use flexmech_joints::model_joint::ParamError;
use flexmech_joints::{
    Cam, Cylindrical, ExpressionJoint, JointMap, Lobe, ModelJoint, Prismatic, RackPinion, Revolute,
    Rigid, Screw, Spherical,
};
use serde::de::{self, Deserializer, Visitor};
use thiserror::Error;

/// A joint built from a model file: its kind's maps and the kind itself (for
/// inspection by type, [`JointKind::downcast_ref`]).
#[derive(Clone)]
pub struct JointKind {
    type_name: String,
    params: toml::Table,
    map: Arc<dyn JointMap>,
    any: Arc<dyn Any + Send + Sync>,
}

impl JointKind {
    /// A joint of a registered kind, from its (already validated) value.
    pub fn new<J: ModelJoint>(joint: J, params: toml::Table) -> Self {
        let joint = Arc::new(joint);
        Self {
            type_name: J::NAME.to_string(),
            params,
            map: joint.clone(),
            any: joint,
        }
    }

    /// The joint's `type` as written in model files (`"rack_pinion"`, ...).
    pub fn type_name(&self) -> &str {
        &self.type_name
    }

    /// Its parameters as written in the model file (every key of the
    /// `[[joint]]` table besides name, type, master, slave, angle and rate).
    pub fn params(&self) -> &toml::Table {
        &self.params
    }

    /// The kinematics and derived maps the solvers use.
    pub fn map(&self) -> &Arc<dyn JointMap> {
        &self.map
    }

    /// The kind itself, if it is a `J`.
    pub fn downcast_ref<J: 'static>(&self) -> Option<&J> {
        self.any.downcast_ref::<J>()
    }

    /// Whether the first released coordinate is a rotation angle `angle`
    /// (the kinds that take the `angle` and `rate` keys and whose angle can
    /// be prescribed).
    pub fn has_angle(&self) -> bool {
        self.map.has_angle()
    }
}

impl PartialEq for JointKind {
    fn eq(&self, other: &Self) -> bool {
        self.type_name == other.type_name && self.params == other.params
    }
}

impl fmt::Debug for JointKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("JointKind")
            .field("type", &self.type_name)
            .field("params", &self.params)
            .field("joint", &self.map)
            .finish()
    }
}

/// Why a registration was refused.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum RegistryError {
    /// Two kinds with one name.
    #[error("a joint kind named \"{0}\" is already registered; model-file names must be unique")]
    Duplicate(&'static str),
    /// A name model files cannot hold.
    #[error("joint kind name \"{0}\" must be non-empty lower case letters, digits and '_'")]
    BadName(&'static str),
}

/// Why a joint table's parameters were refused (the model layer adds the
/// file, line and `joint[i]` prefix).
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum ParamsError {
    /// A key the kind does not take.
    Unknown {
        /// The key.
        key: String,
    },
    /// A key the kind needs.
    Missing {
        /// The key.
        key: String,
        /// What it is, if the kind says.
        help: Option<&'static str>,
    },
    /// The value of a key (path relative to the joint table) is of the wrong
    /// shape or refused by the kind.
    Value(ParamError),
}

/// Adds one kind to a registry.
type Register = fn(&mut JointRegistry) -> Result<&mut JointRegistry, RegistryError>;

type BuildFn = fn(&toml::Table) -> Result<JointKind, ParamsError>;

#[derive(Clone, Copy)]
struct Entry {
    name: &'static str,
    /// The parameter keys, when the kind's parameters are a struct.
    fields: Option<&'static [&'static str]>,
    build: BuildFn,
}

/// The joint kinds a program knows, by model-file name.
#[derive(Clone, Default)]
pub struct JointRegistry {
    entries: Vec<Entry>,
}

/// Two registries are equal when they hold the same names in the same order.
impl PartialEq for JointRegistry {
    fn eq(&self, other: &Self) -> bool {
        self.names().eq(other.names())
    }
}

impl fmt::Debug for JointRegistry {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_list().entries(self.names()).finish()
    }
}

impl JointRegistry {
    /// No kinds at all.
    pub fn empty() -> Self {
        Self::default()
    }

    /// flexmech's ten kinds: rigid, revolute, spherical, prismatic,
    /// cylindrical, screw, rack_pinion, cam, lobe, expression.
    pub fn builtin() -> Self {
        let mut r = Self::empty();
        let all: [Register; 10] = [
            Self::register::<Rigid>,
            Self::register::<Revolute>,
            Self::register::<Spherical>,
            Self::register::<Prismatic>,
            Self::register::<Cylindrical>,
            Self::register::<Screw>,
            Self::register::<RackPinion>,
            Self::register::<Cam>,
            Self::register::<Lobe>,
            Self::register::<ExpressionJoint>,
        ];
        for add in all {
            // The built-in names are distinct and well formed (tested).
            let _ = add(&mut r);
        }
        r
    }

    /// Adds the kind `J` under [`ModelJoint::NAME`].
    pub fn register<J: ModelJoint>(&mut self) -> Result<&mut Self, RegistryError> {
        let name = J::NAME;
        let well_formed = !name.is_empty()
            && name
                .chars()
                .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_');
        if !well_formed {
            return Err(RegistryError::BadName(name));
        }
        if self.entries.iter().any(|e| e.name == name) {
            return Err(RegistryError::Duplicate(name));
        }
        self.entries.push(Entry {
            name,
            fields: struct_fields::<J::Params>(),
            build: build_kind::<J>,
        });
        Ok(self)
    }

    /// The registered names, in registration order.
    pub fn names(&self) -> impl Iterator<Item = &'static str> + '_ {
        self.entries.iter().map(|e| e.name)
    }

    /// Whether `name` is registered.
    pub fn contains(&self, name: &str) -> bool {
        self.entries.iter().any(|e| e.name == name)
    }

    /// The parameter keys of kind `name` (when its parameters are a struct).
    pub fn keys(&self, name: &str) -> Option<&'static [&'static str]> {
        self.entries.iter().find(|e| e.name == name)?.fields
    }

    /// Builds a joint of kind `name` from its parameter table.
    pub(crate) fn build(
        &self,
        name: &str,
        params: &toml::Table,
    ) -> Option<Result<JointKind, ParamsError>> {
        let e = self.entries.iter().find(|e| e.name == name)?;
        if let Some(fields) = e.fields {
            if let Some(key) = params.keys().find(|k| !fields.contains(&k.as_str())) {
                return Some(Err(ParamsError::Unknown { key: key.clone() }));
            }
        }
        Some((e.build)(params))
    }
}

fn build_kind<J: ModelJoint>(table: &toml::Table) -> Result<JointKind, ParamsError> {
    // Through TOML text, so that a refused value's position names its key
    // path (`lift.table[2]`), whatever the shape of the kind's parameters.
    let text = toml::to_string(table).map_err(|e| {
        ParamsError::Value(ParamError::new(
            "",
            format!("cannot be written back as TOML: {e}"),
        ))
    })?;
    let params: J::Params = toml::from_str(&text).map_err(|e| {
        let message = e.message().to_string();
        if let Some(key) = quoted_after(&message, "missing field `") {
            return ParamsError::Missing {
                help: J::key_help(&key),
                key,
            };
        }
        let key = e
            .span()
            .map(|s| super::locate::key_path_at(&text, s.start))
            .unwrap_or_default();
        ParamsError::Value(ParamError::new(key, message))
    })?;
    J::from_params(params)
        .map(|j| JointKind::new(j, table.clone()))
        .map_err(ParamsError::Value)
}

/// The text between `prefix` and the next backquote in `message`.
fn quoted_after(message: &str, prefix: &str) -> Option<String> {
    let rest = &message[message.find(prefix)? + prefix.len()..];
    Some(rest[..rest.find('`')?].to_string())
}

/// The field names of a struct deserialised with serde's derive, read from the
/// `deserialize_struct` call it makes (no value is built).
fn struct_fields<P: de::DeserializeOwned>() -> Option<&'static [&'static str]> {
    let mut fields = None;
    let _ = P::deserialize(Probe(&mut fields));
    fields
}

struct Probe<'a>(&'a mut Option<&'static [&'static str]>);

#[derive(Debug)]
struct Stop;

impl fmt::Display for Stop {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("probe")
    }
}

impl std::error::Error for Stop {}

impl de::Error for Stop {
    fn custom<T: fmt::Display>(_: T) -> Self {
        Stop
    }
}

impl<'de> Deserializer<'de> for Probe<'_> {
    type Error = Stop;

    fn deserialize_any<V: Visitor<'de>>(self, _: V) -> Result<V::Value, Stop> {
        Err(Stop)
    }

    fn deserialize_struct<V: Visitor<'de>>(
        self,
        _: &'static str,
        fields: &'static [&'static str],
        _: V,
    ) -> Result<V::Value, Stop> {
        *self.0 = Some(fields);
        Err(Stop)
    }

    serde::forward_to_deserialize_any! {
        bool i8 i16 i32 i64 i128 u8 u16 u32 u64 u128 f32 f64 char str string
        bytes byte_buf option unit unit_struct newtype_struct seq tuple
        tuple_struct map enum identifier ignored_any
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_builtin_kinds_are_all_registered_with_their_keys() {
        let r = JointRegistry::builtin();
        let names: Vec<_> = r.names().collect();
        assert_eq!(
            names,
            [
                "rigid",
                "revolute",
                "spherical",
                "prismatic",
                "cylindrical",
                "screw",
                "rack_pinion",
                "cam",
                "lobe",
                "expression"
            ]
        );
        assert_eq!(r.keys("rigid"), Some(&[][..]));
        assert_eq!(r.keys("screw"), Some(&["axis", "pitch"][..]));
        assert_eq!(r.keys("lobe"), Some(&["axis", "slide", "lift"][..]));
        assert_eq!(
            r.keys("expression"),
            Some(&["axis", "translation", "parameters"][..])
        );
    }

    #[test]
    fn names_are_unique_and_well_formed() {
        let mut r = JointRegistry::builtin();
        assert_eq!(
            r.register::<Cam>().err(),
            Some(RegistryError::Duplicate("cam"))
        );
    }

    #[test]
    fn parameters_are_checked_by_key() {
        let r = JointRegistry::builtin();
        let table = |s: &str| -> toml::Table { toml::from_str(s).unwrap() };
        let j = r
            .build("screw", &table("axis = [0, 0, 2]\npitch = 0.1"))
            .unwrap()
            .unwrap();
        let screw = j.downcast_ref::<Screw>().unwrap();
        assert_eq!(screw.axis, nalgebra::Vector3::z());
        assert!(j.has_angle());
        assert_eq!(
            r.build("screw", &table("axis = [0, 0, 1]")).unwrap().err(),
            Some(ParamsError::Missing {
                key: "pitch".into(),
                help: flexmech_joints::model_joint::common_key_help("pitch")
            })
        );
        assert_eq!(
            r.build("revolute", &table("axis = [0, 0, 1]\npitch = 1.0"))
                .unwrap()
                .err(),
            Some(ParamsError::Unknown {
                key: "pitch".into()
            })
        );
        let Some(Err(ParamsError::Value(e))) = r.build(
            "lobe",
            &table("axis = [0, 0, 1]\nslide = [1, 0, 0]\nlift = { table = [[0, 1], [1, \"x\"]] }"),
        ) else {
            panic!("a string in a lift table is refused")
        };
        assert!(e.key.starts_with("lift.table"), "{e:?}");
        assert!(r.build("hinge", &table("")).is_none());
    }
}
