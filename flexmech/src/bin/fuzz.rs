//! `flexmech-fuzz`: a fuzzing campaign over the models in `data/` (see
//! `flexmech/fuzz/`). Prints the counts per outcome and keeps every
//! defect's mutant as a reproducer under `--out`; exits non-zero when a
//! defect was found.

use clap::Parser;
#[path = "../../fuzz/mod.rs"]
mod fuzz;

use fuzz::{run, FuzzOptions};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

#[derive(Parser)]
#[command(
    name = "flexmech-fuzz",
    about = "Mutate the model files and classify every outcome"
)]
struct Args {
    /// Mutants to run.
    #[arg(long, default_value_t = 5000)]
    mutants: usize,
    /// Seed of the campaign.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Mutants run at once.
    #[arg(long, default_value_t = 2)]
    threads: usize,
    /// Seconds a process may take before it counts as a hang.
    #[arg(long, default_value_t = 60)]
    timeout: u64,
    /// Models to mutate (a directory, searched recursively).
    #[arg(long, default_value = "data")]
    data: PathBuf,
    /// Work directory; defects' reproducers stay in it, with report.txt.
    #[arg(long, short, default_value = "fuzz")]
    out: PathBuf,
}

fn main() -> ExitCode {
    let args = Args::parse();
    let flexmech = match std::env::current_exe() {
        Ok(p) => p.with_file_name("flexmech"),
        Err(e) => {
            eprintln!("error: cannot find the flexmech executable: {e}");
            return ExitCode::FAILURE;
        }
    };
    let options = FuzzOptions {
        flexmech,
        data: args.data,
        work: args.out.clone(),
        seed: args.seed,
        mutants: args.mutants,
        budget: None,
        timeout: Duration::from_secs(args.timeout),
        threads: args.threads,
    };
    match run(&options) {
        Ok(report) => {
            let text = report.text();
            print!("{text}");
            let _ = std::fs::write(args.out.join("report.txt"), &text);
            if report.defects.is_empty() {
                ExitCode::SUCCESS
            } else {
                ExitCode::FAILURE
            }
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
