//! An elliptical cam: the follower rests on the rim of an ellipse of
//! semi-axes `a` (along the follower direction `t_r` at ψ = 0) and `b`,
//! turning with the released angle ψ about `t`:
//! `f(ψ) = −r(ψ) t_r`, `r(ψ) = a b / √((b cos ψ)² + (a sin ψ)²)`.
//! The whole kind is `f` and its axis; num-dual derives the rest.

use flexmech::prelude::*;

/// The cam.
#[derive(Debug)]
pub struct EllipseCam {
    axis: Vector3<f64>,
    slide: Vector3<f64>,
    a: f64,
    b: f64,
}

impl DependentJoint for EllipseCam {
    fn axis(&self) -> Vector3<f64> {
        self.axis
    }

    fn translation<T: Scalar>(&self, psi: T) -> Vector3<T> {
        let (a, b) = (cst::<T>(self.a), cst::<T>(self.b));
        let (bc, as_) = (b * psi.cos(), a * psi.sin());
        let r = a * b / (bc * bc + as_ * as_).sqrt();
        self.slide.map(cst::<T>) * -r
    }
}

/// Its keys in a `[[joint]]` table.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EllipseCamParams {
    axis: [f64; 3],
    slide: [f64; 3],
    a: f64,
    b: f64,
}

impl ModelJoint for EllipseCam {
    const NAME: &'static str = "ellipse_cam";
    type Params = EllipseCamParams;

    fn from_params(p: EllipseCamParams) -> Result<Self, ParamError> {
        let axis = direction("axis", p.axis)?;
        let slide = perpendicular_slide(Self::NAME, p.slide, &axis)?;
        let (a, b) = (positive("a", p.a)?, positive("b", p.b)?);
        Ok(EllipseCam { axis, slide, a, b })
    }
}
