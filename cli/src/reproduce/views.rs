//! The reproduction's views of the motion: a ParaView series per run
//! (`DIR/<model>/<integrator>.pvd`) and an animation per example
//! (`DIR/animations/<model>.gif`, from the energy–momentum run, the arm's
//! tip drawn with its trail).

use std::path::{Path, PathBuf};

use super::runs::RunRecord;
use super::ReproduceError;
use flexmech_plot::animation::{animate, AnimationOptions};
use flexmech_results::export::export_vtk;

/// The integrator whose run each example's animation shows.
pub const ANIMATED_INTEGRATOR: &str = "energy-momentum";

/// The node every paper example's animation traces: the arm's free end.
pub const TRACKED_NODE: &str = "arm.end";

fn view_error(
    file: &Path,
) -> impl FnOnce(flexmech_results::export::ExportError) -> ReproduceError + '_ {
    move |e| ReproduceError::Read {
        file: file.to_path_buf(),
        message: e.to_string(),
    }
}

/// Writes the ParaView series of every run and one animation per example;
/// returns the files (`.pvd` and `.gif`).
pub fn write_all(runs: &[RunRecord], out: &Path) -> Result<Vec<PathBuf>, ReproduceError> {
    let mut files = Vec::new();
    for run in runs {
        let dir = run.file.parent().unwrap_or(out);
        files.push(export_vtk(&run.file, dir, None).map_err(view_error(&run.file))?);
    }
    for run in runs.iter().filter(|r| r.integrator == ANIMATED_INTEGRATOR) {
        let gif = out.join("animations").join(format!("{}.gif", run.model));
        let opts = AnimationOptions {
            track: vec![TRACKED_NODE.to_owned()],
            ..Default::default()
        };
        files.push(animate(&run.file, &gif, &opts).map_err(view_error(&run.file))?);
    }
    Ok(files)
}
