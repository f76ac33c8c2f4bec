//! The `flexmech` command line. Thin: it parses arguments, calls the library
//! and turns errors into messages that name the file, the key and the fix.

use clap::{Parser, Subcommand};
use flexmech_studies::charts::plot_datasets;
use flexmech_studies::model::load_model;
use flexmech_studies::run_model;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "flexmech",
    version,
    about = "Dynamics of flexible mechanisms: geometrically exact beams joined by master-slave joints"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Solve model files and write `<out>/<name>.h5` for each.
    Run {
        /// Model files (TOML, see MODEL_FORMAT.md).
        #[arg(required = true)]
        models: Vec<PathBuf>,
        /// Output directory for the result files.
        #[arg(long, short, default_value = "results")]
        out: PathBuf,
    },
    /// Draw line charts (PNG and SVG) of result datasets over /time.
    ///
    /// Writes `<out>/<dataset path with / as _>.png` (1600x1000 px) and `.svg`
    /// per dataset, e.g. `plots/nodes_arm.end_displacement.png`.
    Plot {
        /// Result file written by `flexmech run`.
        result: PathBuf,
        /// Dataset paths, e.g. /energy/total or /nodes/<label>/displacement
        /// (shape T: one curve; T x 3: x, y and z curves).
        #[arg(required = true)]
        datasets: Vec<String>,
        /// Output directory for the charts.
        #[arg(long, short, default_value = "plots")]
        out: PathBuf,
        /// Logarithmic y axis (non-positive values are left out).
        #[arg(long)]
        log: bool,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::Run { models, out } => {
            let mut failed = 0;
            for path in &models {
                let outcome = load_model(path)
                    .map_err(Into::into)
                    .and_then(|m| run_model(&m, &out));
                match outcome {
                    Ok(s) => println!(
                        "{}: completed, {} steps ({} written, {} Newton iterations) in {:.2} s -> {}",
                        path.display(),
                        s.steps,
                        s.written,
                        s.iterations,
                        s.wall_time_s,
                        s.file.display()
                    ),
                    Err(e) => {
                        failed += 1;
                        eprintln!("error: {e}");
                    }
                }
            }
            if failed > 0 {
                eprintln!("{failed} of {} model(s) failed", models.len());
                ExitCode::FAILURE
            } else {
                ExitCode::SUCCESS
            }
        }
        Command::Plot {
            result,
            datasets,
            out,
            log,
        } => match plot_datasets(&result, &datasets, &out, log) {
            Ok(files) => {
                for f in files {
                    println!("{}", f.display());
                }
                ExitCode::SUCCESS
            }
            Err(e) => {
                eprintln!("error: {e}");
                ExitCode::FAILURE
            }
        },
    }
}
