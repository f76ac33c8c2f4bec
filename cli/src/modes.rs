//! `flexmech modes RESULT.h5 --time T`: the vibration modes about a stored
//! step (see `flexmech_results::stored_modes`).

use clap::Args;
use flexmech_model::JointRegistry;
use flexmech_results::modes_of_result;
use std::path::PathBuf;
use std::process::ExitCode;

/// The arguments of `flexmech modes`.
#[derive(Args)]
pub(crate) struct ModesArgs {
    /// Result file of a static (load control) or dynamic run.
    result: PathBuf,
    /// The stored time (static: load factor) to linearise at.
    #[arg(long)]
    time: f64,
    /// How many of the lowest modes.
    #[arg(long, default_value_t = 10)]
    modes: usize,
    /// Output directory of `<name>_modes.h5`.
    #[arg(long, short, default_value = "results")]
    out: PathBuf,
}

/// Writes the modes about the stored step and prints their frequencies.
pub(crate) fn modes_command(args: ModesArgs, registry: &JointRegistry) -> ExitCode {
    let ModesArgs {
        result,
        time,
        modes,
        out,
    } = args;
    match modes_of_result(&result, time, modes, registry, &out) {
        Ok(found) => {
            let f: Vec<String> = found
                .modes
                .values()
                .iter()
                .map(|v| format!("{v:.6e}"))
                .collect();
            println!(
                "{}: {} modes about t = {} ({} rigid): frequencies {} -> {}",
                result.display(),
                f.len(),
                found.time,
                found.modes.rigid,
                f.join(", "),
                found.file.display()
            );
            ExitCode::SUCCESS
        }
        Err(e) => super::fail(e),
    }
}
