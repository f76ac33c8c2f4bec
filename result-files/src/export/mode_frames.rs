//! A mode of a modal or buckling result drawn as a motion: one cycle of
//! `x = x₀ + a sin(2πs) u`, `R = exp(a sin(2πs) θ̂) R₀` about the stored
//! state (`s` the phase, 0 to 1, as the series' time), for the ParaView
//! series (`flexmech export --mode k`) and the animations (`flexmech
//! animate --mode k`).

use std::path::Path;

use nalgebra::{UnitQuaternion, Vector3};

use super::frames::Frames;
use super::paraview::ExportError;
use crate::layout as names;
use crate::reader::ResultReader;

/// Frames of one cycle (the first and last are the stored state).
pub const MODE_FRAMES: usize = 40;

/// The largest nodal displacement of a drawn mode, as a part of the
/// mechanism's initial bounding-box diagonal.
pub const MODE_AMPLITUDE: f64 = 0.1;

/// The largest rotation (radians) of a drawn mode in which no node moves.
const MODE_ROTATION: f64 = 0.3;

/// Mode `mode` (from 1) of the result file `path` (`/modes` or `/buckling`)
/// as a motion about its last stored step.
///
/// # Errors
/// A file without modes, or a mode it does not hold.
pub fn mode_frames(path: &Path, mode: usize) -> Result<Frames, ExportError> {
    let base = Frames::read(path)?;
    let r = ResultReader::open(path)?;
    let group = [names::MODES, names::BUCKLING]
        .into_iter()
        .find(|g| r.has(&format!("{g}/displacement")))
        .ok_or_else(|| ExportError::Option {
            option: "--mode",
            why: format!(
                "{} holds no modes (/modes or /buckling): run a model with analysis = \
                 \"modal\" or \"buckling\", or `flexmech modes`",
                path.display()
            ),
        })?;
    let shape = r.shape(&format!("{group}/displacement"))?;
    let count = shape.first().copied().unwrap_or(0);
    if mode == 0 || mode > count || base.steps() == 0 {
        return Err(ExportError::Option {
            option: "--mode",
            why: format!("{} holds modes 1 to {count}, not {mode}", path.display()),
        });
    }
    let nodes = base.labels.len();
    let pick = |name: &str| -> Result<Vec<Vector3<f64>>, ExportError> {
        let v = r.values(&format!("{group}/{name}"))?;
        Ok(v[(mode - 1) * nodes * 3..mode * nodes * 3]
            .chunks_exact(3)
            .map(Vector3::from_column_slice)
            .collect())
    };
    let (u, theta) = (pick("displacement")?, pick("rotation")?);
    Ok(cycle(base, &u, &theta))
}

/// One cycle of the mode `(u, θ)` about the last step of `base`.
fn cycle(base: Frames, u: &[Vector3<f64>], theta: &[Vector3<f64>]) -> Frames {
    let last = base.steps() - 1;
    let (x0, r0) = (base.positions[last].clone(), base.rotations[last].clone());
    let largest = |v: &[Vector3<f64>]| v.iter().fold(0.0f64, |m, x| m.max(x.norm()));
    let (lo, hi) = base.initial.iter().fold(
        (
            Vector3::repeat(f64::INFINITY),
            Vector3::repeat(f64::NEG_INFINITY),
        ),
        |(lo, hi), x| (lo.inf(x), hi.sup(x)),
    );
    let diagonal = (hi - lo).norm().max(f64::MIN_POSITIVE);
    let amplitude = if largest(u) > 0.0 {
        MODE_AMPLITUDE * diagonal / largest(u)
    } else if largest(theta) > 0.0 {
        MODE_ROTATION / largest(theta)
    } else {
        0.0
    };
    let phases: Vec<f64> = (0..=MODE_FRAMES)
        .map(|j| j as f64 / MODE_FRAMES as f64)
        .collect();
    let mut frames = base;
    frames.positions = phases
        .iter()
        .map(|s| {
            let w = amplitude * (std::f64::consts::TAU * s).sin();
            x0.iter().zip(u).map(|(x, d)| x + d * w).collect()
        })
        .collect();
    frames.rotations = phases
        .iter()
        .map(|s| {
            let w = amplitude * (std::f64::consts::TAU * s).sin();
            r0.iter()
                .zip(theta)
                .map(|(q, t)| UnitQuaternion::from_scaled_axis(t * w) * q)
                .collect()
        })
        .collect();
    for j in &mut frames.joints {
        let at = |v: &[f64]| v.get(last).copied().unwrap_or(f64::NAN);
        let (angle, error) = (at(&j.angle), at(&j.constraint_error));
        let translation = j
            .released_translation
            .get(last)
            .copied()
            .unwrap_or([f64::NAN; 3]);
        j.angle = vec![angle; phases.len()];
        j.constraint_error = vec![error; phases.len()];
        j.released_translation = vec![translation; phases.len()];
    }
    frames.time = phases;
    frames.velocities = None;
    frames.angular_velocities = None;
    frames.resultants = None;
    frames
}
