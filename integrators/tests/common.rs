//! Fixtures the solver tests share.

use flexmech_core::MassKind;
use flexmech_integrators::dynamics::{DynamicSettings, Motion};
use flexmech_integrators::NewtonSettings;
use nalgebra::Vector3;

/// Dynamic settings with full Newton to `tolerance` in at most
/// `max_iterations`, `max_halvings` step halvings and `mass`.
pub fn settings(
    dt: f64,
    t_end: f64,
    tolerance: f64,
    max_iterations: usize,
    max_halvings: usize,
    mass: MassKind,
) -> DynamicSettings {
    DynamicSettings {
        dt,
        t_end,
        newton: NewtonSettings {
            tolerance,
            max_iterations,
            ..NewtonSettings::default()
        },
        max_halvings,
        mass,
    }
}

/// The rigid velocity field `v = v₀ + ω × x`, `W = ω` on nodes at `x`
/// (no joints).
pub fn rigid_motion(x: &[Vector3<f64>], v0: Vector3<f64>, om: Vector3<f64>) -> Motion {
    Motion {
        v: x.iter().map(|x| v0 + om.cross(x)).collect(),
        w: vec![om; x.len()],
        joint_rates: Vec::new(),
    }
}
