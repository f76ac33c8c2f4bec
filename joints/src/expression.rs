//! Expression joint: a dependent joint written in the model file, its
//! released translation `r_R = f(ψ)` (paper eq. 12 and §3) given as three
//! expressions of `psi`, so that a new kind needs no compiling.
//!
//! ```toml
//! [[joint]]
//! name = "cam"
//! type = "expression"
//! master = "post.end"
//! slave = "follower.start"
//! axis = [0.0, 0.0, 1.0]              # the released rotation's axis t
//! translation = ["R*cos(psi) - R - a", "0", "0"]   # f(ψ), global axes at t = 0
//! parameters = { R = 0.1, a = 0.02 }  # optional named constants
//! ```
//!
//! The components are along the global axes at t = 0 and turn with the
//! master, as `axis` and `slide` of the built-in kinds do (the built-in
//! screw with axis z is `translation = ["0", "0", "c*psi"]`). The
//! expressions are evaluated over any dual number, so `N`, its derivative,
//! `G` and `Ñ` come by the same automatic differentiation as for a Rust
//! kind ([`DependentJoint`]).

use std::collections::BTreeMap;

use crate::dependent::{parameter_slopes, DependentJoint};
use crate::model_joint::{direction, ModelJoint, ParamError};
use flexmech_core::expr::{reserved, Expression};
use flexmech_core::Scalar;
use nalgebra::Vector3;
use serde::Deserialize;

/// A dependent joint whose `f(ψ)` is three parsed expressions of `psi`.
#[derive(Debug, Clone, PartialEq)]
pub struct ExpressionJoint {
    /// Unit axis `t` of the released rotation.
    pub axis: Vector3<f64>,
    /// The components of `f(ψ)`, global axes at t = 0.
    pub translation: [Expression; 3],
}

impl DependentJoint for ExpressionJoint {
    fn axis(&self) -> Vector3<f64> {
        self.axis
    }

    fn translation<T: Scalar>(&self, psi: T) -> Vector3<T> {
        let [x, y, z] = &self.translation;
        Vector3::new(x.eval(psi), y.eval(psi), z.eval(psi))
    }

    /// By a named parameter: the expressions in hyper-dual numbers, `ψ`
    /// seeded in the first direction and the parameter in the second.
    fn translation_by(&self, name: &str, psi: f64) -> Option<[Vector3<f64>; 2]> {
        let k = self.translation[0].parameter(name)?;
        let value = self.translation[0].parameter_value(k);
        Some(parameter_slopes(psi, value, |psi, p| {
            let [x, y, z] = self
                .translation
                .each_ref()
                .map(|e| e.eval_seeded(psi, k, p));
            Vector3::new(x, y, z)
        }))
    }
}

/// Parameters of an `expression` joint in model files.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExpressionParams {
    /// Axis `t` of the released rotation (normalised).
    pub axis: [f64; 3],
    /// The three components of `f(ψ)` as expressions of `psi`.
    pub translation: [String; 3],
    /// Named constants the expressions may use.
    #[serde(default)]
    pub parameters: BTreeMap<String, f64>,
}

impl ModelJoint for ExpressionJoint {
    const NAME: &'static str = "expression";
    type Params = ExpressionParams;

    fn from_params(p: ExpressionParams) -> Result<Self, ParamError> {
        let axis = direction("axis", p.axis)?;
        let parameters = checked_parameters(&p.parameters)?;
        let parse = |i: usize| {
            Expression::parse_with(&p.translation[i], "psi", &parameters).map_err(|e| ParamError {
                key: "translation".into(),
                message: format!("[{i}] `{}`: {e}", p.translation[i]),
                item: Some(i),
            })
        };
        Ok(ExpressionJoint {
            axis,
            translation: [parse(0)?, parse(1)?, parse(2)?],
        })
    }

    fn key_help(key: &str) -> Option<&'static str> {
        match key {
            "translation" => Some(
                "f(ψ) as three expressions of psi (global axes at t = 0), e.g. \
                 translation = [\"0\", \"0\", \"c*psi\"]",
            ),
            _ => crate::model_joint::common_key_help(key),
        }
    }
}

/// The parameters as `(name, value)`: names that are identifiers and not
/// taken by the expression language, values finite.
fn checked_parameters(p: &BTreeMap<String, f64>) -> Result<Vec<(String, f64)>, ParamError> {
    let refuse = |name: &str, message: String| ParamError {
        key: format!("parameters.{name}"),
        message,
        item: None,
    };
    let mut out = Vec::with_capacity(p.len());
    for (name, &value) in p {
        let identifier = name
            .chars()
            .next()
            .is_some_and(|c| c.is_alphabetic() || c == '_')
            && name.chars().all(|c| c.is_alphanumeric() || c == '_');
        if !identifier {
            return Err(refuse(
                name,
                "is not a name an expression can use (letters, digits and `_`, not starting with a digit)".into(),
            ));
        }
        if reserved(name) {
            return Err(refuse(
                name,
                "shadows a name of the expression language (psi, t, lambda, pi, e or a function); rename it".into(),
            ));
        }
        if !value.is_finite() {
            return Err(refuse(
                name,
                format!("must be a finite number, found {value}"),
            ));
        }
        out.push((name.clone(), value));
    }
    Ok(out)
}
