//! The reproduction's figures of merit: one row per run in `DIR/summary.csv`
//! and a readable table in `DIR/summary.md`.

use super::{ReproduceError, RunRecord};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Writes `DIR/summary.csv` and `DIR/summary.md`; returns their paths.
pub fn write(runs: &[RunRecord], out: &Path) -> Result<(PathBuf, PathBuf), ReproduceError> {
    let csv_path = out.join("summary.csv");
    let md_path = out.join("summary.md");
    let mut csv = String::from(
        "model,integrator,status,t_reached,steps,energy_drift,reduced_steps,min_dt,newton_iterations,wall_time_s\n",
    );
    let mut md = String::from(
        "| model | integrator | outcome | energy drift | steps with Δt reduced | smallest Δt | Newton iterations / step |\n|---|---|---|---|---|---|---|\n",
    );
    for r in runs {
        let steps = r.time.len().saturating_sub(1);
        let t_reached = r.time.last().copied().unwrap_or(0.0);
        let iterations: f64 = r.iterations.iter().sum();
        let status = r.status.replace(',', ";").replace('\n', " ");
        // Writing into a String cannot fail.
        let _ = writeln!(
            csv,
            "{},{},{},{},{},{:e},{},{},{},{}",
            r.model,
            r.integrator,
            status,
            t_reached,
            steps,
            r.energy_drift(),
            r.reduced_steps(),
            r.min_dt(),
            iterations,
            r.wall_time_s
        );
        let outcome = match r.failure_time {
            Some(t) => format!("fails at t = {t:.4} s"),
            None => format!("completed (t = {t_reached:.3} s)"),
        };
        let _ = writeln!(
            md,
            "| {} | {} | {} | {:.2e} | {} | {} | {:.1} |",
            r.model,
            r.integrator,
            outcome,
            r.energy_drift(),
            r.reduced_steps(),
            r.min_dt(),
            iterations / steps.max(1) as f64
        );
    }
    md.push_str(
        "\nEnergy drift: largest |B(t) − B(0)| over the run, B = total energy − work of the drive, relative to the larger of |E(0)| and the largest |work of the drive|.\n",
    );
    for (path, text) in [(&csv_path, &csv), (&md_path, &md)] {
        std::fs::create_dir_all(out)
            .and_then(|_| std::fs::write(path, text))
            .map_err(|source| ReproduceError::Write {
                file: path.clone(),
                source,
            })?;
    }
    Ok((csv_path, md_path))
}
