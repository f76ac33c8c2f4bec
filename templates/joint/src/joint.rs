//! The joint kind: its axis and `f(ψ)`, its model-file name and parameters.
//! Here a screw whose pitch changes along the turn, `f(ψ) = (c ψ + d sin ψ) t`;
//! replace `translation` with your profile.

use flexmech::prelude::*;

/// The joint.
#[derive(Debug)]
pub struct MyJoint {
    axis: Vector3<f64>,
    c: f64,
    d: f64,
}

impl DependentJoint for MyJoint {
    fn axis(&self) -> Vector3<f64> {
        self.axis
    }

    fn translation<T: Scalar>(&self, psi: T) -> Vector3<T> {
        self.axis.map(cst::<T>) * (psi * cst::<T>(self.c) + psi.sin() * cst::<T>(self.d))
    }
}

/// Its keys in a `[[joint]]` table (besides name, type, master, slave,
/// angle and rate).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MyJointParams {
    axis: [f64; 3],
    c: f64,
    d: f64,
}

impl ModelJoint for MyJoint {
    const NAME: &'static str = "my_joint";
    type Params = MyJointParams;

    fn from_params(p: MyJointParams) -> Result<Self, ParamError> {
        Ok(MyJoint {
            axis: direction("axis", p.axis)?,
            c: p.c,
            d: p.d,
        })
    }
}
