//! The `flexmech` command line, as a library function so that a user's binary
//! can run it with its own joint kinds. Thin: it parses arguments, calls the
//! library and turns errors into messages that name the file, the key and
//! the fix.
//!
//! A crate that defines joint kinds gets the whole command line (`run`,
//! `check`, `study`, `reproduce`, `plot`, `bench`) for model files naming
//! them with a three-line binary:
//!
//! ```no_run
//! use flexmech_model::JointRegistry;
//!
//! fn main() -> std::process::ExitCode {
//!     let mut registry = JointRegistry::builtin();
//!     // registry.register::<MyJoint>().expect("a new name");
//!     flexmech_cli::main_with(registry)
//! }
//! ```

#![warn(missing_docs)]

use crate::reproduce::{reproduce, ReproduceOptions};
use clap::{Args, Parser, Subcommand};
use flexmech_model::build;
use flexmech_model::{load_model_with, JointRegistry};
use flexmech_plot::charts::{plot_with, PlotOptions};
use flexmech_results::{restart_model, run_model, RunError};

use std::path::{Path, PathBuf};
use std::process::ExitCode;

pub mod bench;
pub mod benchmarks;
mod modes;
mod plot_study;
pub mod reproduce;

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
    Run(RunArgs),
    /// Check model files without solving them: parse, validate every key and
    /// build the mechanism (every derived quantity at t = 0 must be finite).
    ///
    /// Prints `<file>: ok (…)` per valid model; errors name the file, line,
    /// key and fix, as `run` does.
    Check(CheckArgs),
    /// Reproduce the paper's examples (data/paper) with every integrator.
    ///
    /// Writes `<out>/<model>/<integrator>.h5` for every run with its
    /// ParaView series `<out>/<model>/<integrator>.pvd`, an animation per
    /// example in `<out>/animations/<model>.gif`, the charts
    /// (PNG and SVG) into `<out>/charts/`, and `<out>/summary.csv` and
    /// `<out>/summary.md` with each run's outcome, energy drift and step
    /// halvings. A run that fails (Newmark in `screw_free`) is a result, not
    /// an error.
    Reproduce(ReproduceArgs),
    /// Draw line charts (PNG and SVG) of result datasets over /time (or
    /// over another dataset with --x), overlaying other files with --with.
    ///
    /// Writes `<out>/<dataset path with / as _>.png` (1600x1000 px), `.svg`,
    /// and the editable `.csv` and PGFPlots `.tex` per dataset, e.g.
    /// `plots/nodes_arm.end_displacement.png`.
    Plot(PlotArgs),
    /// Write a result file as a ParaView time series.
    ///
    /// Writes `<vtk>/<stem>.pvd` (open it in ParaView) and one `.vtu` file
    /// per stored step under `<vtk>/<stem>/`: beams as ribbons whose width
    /// follows the section's e2 director (twist is visible), 3-node elements
    /// as quadratic cells, joints as points with their coordinates; times
    /// from /time.
    Export(ExportArgs),
    /// Vibration modes about a stored step of a result file: the mechanism
    /// held still in that pose with its stress state.
    ///
    /// Solves the stored model again up to the step (static load control
    /// or dynamics: the same state to the last bit), writes
    /// `<out>/<name>_modes.h5` with that step and `/modes` (see "Modes and
    /// buckling" in MODEL_FORMAT.md) and prints the frequencies.
    Modes(modes::ModesArgs),
    /// Draw the mechanism moving: an animated GIF (or MP4 with ffmpeg, or a
    /// PNG of one frame).
    Animate(AnimateArgs),
    /// Time steps of the yardstick cantilever (2 m, tip force, dt = 1e-3)
    /// at several mesh sizes with each integrator, modified Newton and
    /// 3-node elements; then the four-bar and slider-crank benchmarks with
    /// each integrator.
    ///
    /// Prints the machine, then µs per step, µs per element-step and the
    /// ratio to Newmark with full Newton at the same size (ratios carry over
    /// between machines; absolute times on a shared machine do not), all of
    /// the time steps alone; the set-up before the first step (patterns,
    /// orderings, initial accelerations) in its own column. Writes
    /// `<out>/bench.md` and the runs' result files under `<out>/`. Set
    /// RAYON_NUM_THREADS=1 for one-thread figures.
    Bench(BenchArgs),
    /// Run a parameter study: a base model over a grid of key values.
    ///
    /// Writes `<out>/<name>/runs/<run id>.h5` per run, `summary.csv`,
    /// `summary.h5` and `charts/<figure>.png/.svg` (see "Study files" in
    /// MODEL_FORMAT.md). Without --shard, a Slurm array task runs the shard
    /// that SLURM_ARRAY_TASK_ID, _MIN and _COUNT select.
    Study(StudyArgs),
}

/// The arguments of `flexmech run`.
#[derive(Args)]
struct RunArgs {
    /// Model files (TOML, see MODEL_FORMAT.md).
    #[arg(required = true)]
    models: Vec<PathBuf>,
    /// Output directory for the result files.
    #[arg(long, short, default_value = "results")]
    out: PathBuf,
    /// Continue the dynamic run stored in this result file from its last
    /// stored step to the model's `t_end` (one model, describing the same
    /// mechanism with the same integrator and `dt`).
    #[arg(long, value_name = "RESULT.h5")]
    restart: Option<PathBuf>,
}

/// The arguments of `flexmech check`.
#[derive(Args)]
struct CheckArgs {
    /// Model files (TOML, see MODEL_FORMAT.md).
    #[arg(required = true)]
    models: Vec<PathBuf>,
}

/// The arguments of `flexmech reproduce`.
#[derive(Args)]
struct ReproduceArgs {
    /// Output directory.
    #[arg(long, short, default_value = "results")]
    out: PathBuf,
    /// Only these models (screw_free, screw_driven, rack_pinion, cam, lobe).
    #[arg(long = "model")]
    models: Vec<String>,
    /// Factor on every model's end time (e.g. 0.2 for a quick look).
    #[arg(long, default_value_t = 1.0)]
    time_scale: f64,
    /// Charts without titles (for papers whose captions carry them).
    #[arg(long)]
    no_titles: bool,
    /// Also a PDF of every chart, from its PGFPlots copy (needs pdflatex).
    #[arg(long)]
    pdf: bool,
    /// The benchmark set of data/benchmarks/ instead of the paper's
    /// examples: a chart per benchmark beside its reference and the table
    /// (DIR/benchmarks/).
    #[arg(long, conflicts_with_all = ["models", "time_scale"])]
    benchmarks: bool,
}

/// The arguments of `flexmech plot`.
#[derive(Args)]
struct PlotArgs {
    /// Result file written by `flexmech run`.
    result: PathBuf,
    /// Dataset paths, e.g. /energy/total or /nodes/<label>/displacement
    /// (shape T: one curve; T x 3: x, y and z curves).
    #[arg(required_unless_present = "study")]
    datasets: Vec<String>,
    /// Output directory for the charts.
    #[arg(long, short, default_value = "plots")]
    out: PathBuf,
    /// Logarithmic y axis (non-positive values are left out).
    #[arg(long)]
    log: bool,
    /// Plot against this dataset instead of /time (T, or DATASET[k] for
    /// component k of a T x 3 one), e.g. --x /joints/screw/angle.
    #[arg(long, value_name = "DATASET")]
    x: Option<String>,
    /// Label of the x axis.
    #[arg(long)]
    xlabel: Option<String>,
    /// Label of the y axis (default: the dataset's description and unit).
    #[arg(long)]
    ylabel: Option<String>,
    /// Title ("" for none; default: file and description).
    #[arg(long)]
    title: Option<String>,
    /// Another result file whose same datasets are drawn in the same
    /// charts (repeat for more); curves are named by file.
    #[arg(long = "with", value_name = "RESULT.h5")]
    with: Vec<PathBuf>,
    /// Also a PDF of each chart, from its PGFPlots copy (needs pdflatex).
    #[arg(long)]
    pdf: bool,
    /// A study's output directory (`<out>/<name>`, with summary.csv and
    /// runs/): every positional argument is then a dataset (DATASET[k] for
    /// column k, or x, y, z), drawn across the runs, one curve per run
    /// named by its swept values.
    #[arg(long, value_name = "DIR", conflicts_with_all = ["x", "with"])]
    study: Option<PathBuf>,
}

/// The arguments of `flexmech export`.
#[derive(Args)]
struct ExportArgs {
    /// Result file written by `flexmech run`.
    result: PathBuf,
    /// Output directory of the ParaView series.
    #[arg(long, value_name = "DIR")]
    vtk: PathBuf,
    /// Ribbon width in model units (default: 2 % of the mechanism's
    /// initial bounding-box diagonal).
    #[arg(long)]
    width: Option<f64>,
    /// Write mode k (from 1) of a modal or buckling result as one cycle
    /// about its stored state (`<stem>_mode<k>.pvd`; the phase 0 to 1 as
    /// time) instead of the stored steps.
    #[arg(long, value_name = "K")]
    mode: Option<usize>,
}

/// The arguments of `flexmech animate`.
#[derive(Args)]
struct AnimateArgs {
    /// Result file written by `flexmech run`.
    result: PathBuf,
    /// Output file: .gif, .mp4 (needs ffmpeg) or .png (one frame).
    #[arg(long, short)]
    out: PathBuf,
    /// Camera: auto (normal to the plane of the motion), xy, xz, yz or
    /// iso; or give --azimuth and --elevation.
    #[arg(long, default_value = "auto")]
    view: String,
    /// Camera azimuth about z from x, degrees (with --elevation).
    #[arg(long, requires = "elevation")]
    azimuth: Option<f64>,
    /// Camera elevation above the xy plane, degrees (with --azimuth).
    #[arg(long, requires = "azimuth")]
    elevation: Option<f64>,
    /// Image size in pixels, WIDTHxHEIGHT.
    #[arg(long, default_value = "800x600")]
    size: String,
    /// Frames per second.
    #[arg(long, default_value_t = 25.0)]
    fps: f64,
    /// At most this many frames (stored steps are thinned evenly).
    #[arg(long, default_value_t = 250)]
    max_frames: usize,
    /// Nodes drawn with the trail of their positions (labels, e.g. arm.end).
    #[arg(long)]
    track: Vec<String>,
    /// For a .png: the time of the frame (default: the last step).
    #[arg(long)]
    time: Option<f64>,
    /// Draw mode k (from 1) of a modal or buckling result, one cycle about
    /// its stored state, instead of the stored steps.
    #[arg(long, value_name = "K")]
    mode: Option<usize>,
}

/// The arguments of `flexmech bench`.
#[derive(Args)]
struct BenchArgs {
    /// Element counts (2-node; 3-node runs use half as many elements).
    #[arg(long, value_delimiter = ',', default_values_t = [32, 128, 512, 2048, 8192])]
    elements: Vec<usize>,
    /// Time steps per run.
    #[arg(long, default_value_t = 20)]
    steps: usize,
    /// Rounds per size: the cases run this many times, interleaved,
    /// and each keeps its fastest run (other work on a shared machine
    /// only adds time).
    #[arg(long, default_value_t = 3)]
    rounds: usize,
    /// Mechanisms of data/benchmarks timed after the cantilever, each a
    /// whole run of the benchmark with each 2-node case (`none` for
    /// none).
    #[arg(long, value_delimiter = ',', default_values_t = ["four-bar".to_string(), "slider-crank".to_string()])]
    mechanisms: Vec<String>,
    /// Output directory.
    #[arg(long, short, default_value = "bench")]
    out: PathBuf,
}

/// The arguments of `flexmech study`.
#[derive(Args)]
struct StudyArgs {
    /// Study file (TOML).
    study: PathBuf,
    /// Output directory; the study writes to `<out>/<name>/`.
    #[arg(long, short, default_value = "studies")]
    out: PathBuf,
    /// Run only shard K of N (runs with index % N == K-1) and write
    /// summary-shard-K-of-N.csv/.h5.
    #[arg(long, value_name = "K/N", conflicts_with = "merge")]
    shard: Option<String>,
    /// Merge the shard summaries into summary.csv/.h5 and the charts.
    #[arg(long)]
    merge: bool,
}

/// Runs the command line of this process's arguments with the joint kinds
/// of `registry`.
pub fn main_with(registry: JointRegistry) -> ExitCode {
    run_with(registry, std::env::args_os())
}

/// Runs the command line `args` (the first is the program name) with the
/// joint kinds of `registry`: model and study files may name them, and an
/// unknown kind is refused with the list of every registered one.
pub fn run_with<I, T>(registry: JointRegistry, args: I) -> ExitCode
where
    I: IntoIterator<Item = T>,
    T: Into<std::ffi::OsString> + Clone,
{
    let cli = match Cli::try_parse_from(args) {
        Ok(cli) => cli,
        Err(e) => {
            let _ = e.print();
            return if e.use_stderr() {
                ExitCode::from(2)
            } else {
                ExitCode::SUCCESS
            };
        }
    };
    execute(cli, &registry)
}

/// Runs the parsed command line: each subcommand is its own function.
fn execute(cli: Cli, registry: &JointRegistry) -> ExitCode {
    match cli.command {
        Command::Run(args) => run_command(args, registry),
        Command::Check(args) => check_command(args, registry),
        Command::Reproduce(args) => reproduce_command(args),
        Command::Plot(args) => plot_command(args),
        Command::Export(args) => export_command(args),
        Command::Modes(args) => modes::modes_command(args, registry),
        Command::Animate(args) => animate_command(args),
        Command::Bench(args) => bench_command(args),
        Command::Study(args) => study_command(args, registry),
    }
}

/// Prints `error: <e>` and returns failure: the end of every subcommand
/// whose library call failed.
fn fail(e: impl std::fmt::Display) -> ExitCode {
    eprintln!("error: {e}");
    ExitCode::FAILURE
}

/// `flexmech run`: solves each model file (or continues one run with
/// `--restart`), printing one line per model.
fn run_command(args: RunArgs, registry: &JointRegistry) -> ExitCode {
    let RunArgs {
        models,
        out,
        restart,
    } = args;
    if restart.is_some() && models.len() != 1 {
        eprintln!(
            "error: --restart continues one run: give one model file, found {}",
            models.len()
        );
        return ExitCode::FAILURE;
    }
    let mut failed = 0;
    let mut names: Vec<(String, PathBuf)> = Vec::new();
    for path in &models {
        let outcome = load_model_with(path, registry)
            .map_err(Into::into)
            .and_then(|m| {
                if let Some((_, first)) = names.iter().find(|(n, _)| *n == m.name) {
                    return Err(RunError::DuplicateName {
                        name: m.name.clone(),
                        file: path.clone(),
                        first: first.clone(),
                    });
                }
                names.push((m.name.clone(), path.clone()));
                match &restart {
                    Some(result) => restart_model(&m, result, &out),
                    None => run_model(&m, &out),
                }
            });
        match outcome {
            Ok(s) => print_run(path, &s),
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

/// The line `flexmech run` prints for a model that ran, and its warnings.
fn print_run(path: &Path, s: &flexmech_results::RunSummary) {
    let warned = if s.warnings.is_empty() {
        ""
    } else {
        " with a warning"
    };
    println!(
        "{}: completed{warned}, {} steps ({} written, {} Newton iterations) in {:.2} s -> {}",
        path.display(),
        s.steps,
        s.written,
        s.iterations,
        s.wall_time_s,
        s.file.display()
    );
    for line in s.details() {
        println!("  {line}");
    }
    for w in &s.warnings {
        eprintln!("warning: {}: {w}", path.display());
    }
}

/// `flexmech check`: loads and builds each model file without solving it.
fn check_command(args: CheckArgs, registry: &JointRegistry) -> ExitCode {
    let CheckArgs { models } = args;
    let mut failed = 0;
    for path in &models {
        match load_model_with(path, registry).and_then(|m| build(&m).map(|b| (m, b))) {
            Ok((m, b)) => println!(
                "{}: ok (model \"{}\": {} beams, {} elements, {} joints, {} nodes)",
                path.display(),
                m.name,
                m.beams.len(),
                b.mechanism.mesh.elements.len(),
                m.joints.len(),
                b.mechanism.mesh.node_count()
            ),
            Err(e) => {
                failed += 1;
                eprintln!("error: {e}");
            }
        }
    }
    if failed > 0 {
        eprintln!("{failed} of {} model(s) refused", models.len());
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    }
}

/// `flexmech reproduce`: the paper's examples, one line per run and where
/// the charts, summary and views went.
fn reproduce_command(args: ReproduceArgs) -> ExitCode {
    let ReproduceArgs {
        out,
        models,
        time_scale,
        no_titles,
        pdf,
        benchmarks,
    } = args;
    if benchmarks {
        return benchmarks_command(&out, !no_titles, pdf);
    }
    let options = ReproduceOptions {
        out,
        models,
        time_scale,
        titles: !no_titles,
        pdf,
    };
    let rep = match reproduce(&options) {
        Ok(rep) => rep,
        Err(e) => return fail(e),
    };
    for r in &rep.runs {
        let outcome = match r.failure_time {
            Some(t) => format!("failed at t = {t:.4} s"),
            None => "completed".to_string(),
        };
        println!(
            "{:13} {:21} {:28} energy drift {:.2e}, {} reduced steps -> {}",
            r.model,
            r.integrator,
            outcome,
            r.energy_drift(),
            r.reduced_steps(),
            r.file.display()
        );
    }
    println!(
        "{} charts in {}; summary in {} and {}",
        rep.charts.len(),
        options.out.join("charts").display(),
        rep.summary.0.display(),
        rep.summary.1.display()
    );
    println!(
        "ParaView series (open the .pvd): {}/<model>/<integrator>.pvd; animations: {}",
        options.out.display(),
        options.out.join("animations").display()
    );
    ExitCode::SUCCESS
}

/// `flexmech reproduce --benchmarks`: the benchmark table's rows and where
/// the charts and the table went.
fn benchmarks_command(out: &Path, titles: bool, pdf: bool) -> ExitCode {
    let report = match benchmarks::reproduce_benchmarks(out, titles, pdf) {
        Ok(report) => report,
        Err(e) => return fail(e),
    };
    for r in &report.rows {
        println!(
            "{}: {}: reference {} ({}), flexmech {}, difference {}",
            r.benchmark, r.quantity, r.reference, r.source, r.ours, r.difference
        );
    }
    println!(
        "{} charts in {}; table in {} and {}",
        report.charts.len(),
        out.join("benchmarks").display(),
        report.table.0.display(),
        report.table.1.display()
    );
    ExitCode::SUCCESS
}

/// `flexmech plot`: line charts of result datasets; prints each file written.
fn plot_command(args: PlotArgs) -> ExitCode {
    let PlotArgs {
        result,
        datasets,
        out,
        log,
        x,
        xlabel,
        ylabel,
        title,
        with,
        pdf,
        study,
    } = args;
    let options = PlotOptions {
        log_y: log,
        x,
        x_label: xlabel,
        y_label: ylabel,
        title,
        overlay: with,
        pdf,
    };
    if let Some(dir) = study {
        return plot_study::command(&dir, &result, &datasets, &out, &options);
    }
    match plot_with(&result, &datasets, &out, &options) {
        Ok(files) => {
            for f in files {
                println!("{}", f.display());
            }
            ExitCode::SUCCESS
        }
        Err(e) => fail(e),
    }
}

/// `flexmech export`: a result file as a ParaView series; prints the `.pvd`.
fn export_command(args: ExportArgs) -> ExitCode {
    let ExportArgs {
        result,
        vtk,
        width,
        mode,
    } = args;
    let written = match mode {
        Some(k) => flexmech_results::export::export_mode_vtk(&result, &vtk, width, k),
        None => flexmech_results::export::export_vtk(&result, &vtk, width),
    };
    match written {
        Ok(pvd) => {
            println!("{}", pvd.display());
            ExitCode::SUCCESS
        }
        Err(e) => fail(e),
    }
}

/// `flexmech animate`: the mechanism moving; prints the file written.
fn animate_command(args: AnimateArgs) -> ExitCode {
    use flexmech_plot::animation::{animate, AnimationOptions, View};
    let AnimateArgs {
        result,
        out,
        view,
        azimuth,
        elevation,
        size,
        fps,
        max_frames,
        track,
        time,
        mode,
    } = args;
    let view = match (azimuth, elevation) {
        (Some(azimuth), Some(elevation)) => Some(View::Angles { azimuth, elevation }),
        _ => View::parse(&view),
    };
    let Some(view) = view else {
        eprintln!("error: --view: use auto, xy, xz, yz or iso (or --azimuth and --elevation)");
        return ExitCode::FAILURE;
    };
    let size = size
        .split_once(['x', 'X'])
        .and_then(|(w, h)| Some((w.trim().parse().ok()?, h.trim().parse().ok()?)));
    let Some(size) = size else {
        eprintln!("error: --size: give WIDTHxHEIGHT in pixels, e.g. 800x600");
        return ExitCode::FAILURE;
    };
    let opts = AnimationOptions {
        view,
        size,
        fps,
        max_frames,
        track,
        time,
        mode,
    };
    match animate(&result, &out, &opts) {
        Ok(file) => {
            println!("{}", file.display());
            ExitCode::SUCCESS
        }
        Err(e) => fail(e),
    }
}

/// `flexmech bench`: times the cantilever and the chosen mechanisms, prints
/// each timing and the table, and writes `<out>/bench.md`.
fn bench_command(args: BenchArgs) -> ExitCode {
    let BenchArgs {
        elements,
        steps,
        rounds,
        mechanisms,
        out,
    } = args;
    let Some(chosen) = bench_mechanisms(&mechanisms) else {
        return ExitCode::FAILURE;
    };
    println!("{}", bench::machine());
    let show = |t: &bench::Timing| {
        println!(
            "{:<12} {:>6} elements  {:<26} {:>9.0} µs/step  {:>7.2} µs/(element·step)",
            t.model,
            t.elements,
            t.case.label,
            t.per_step_us(),
            t.per_element_step_us()
        );
    };
    let outcome = bench::bench(&elements, steps, rounds, &out, show).and_then(|mut all| {
        all.extend(bench::bench_mechanisms(&chosen, rounds, &out, show)?);
        Ok(all)
    });
    let timings = match outcome {
        Ok(timings) => timings,
        Err(e) => return fail(e),
    };
    let table = bench::table(&timings);
    println!("\n{table}");
    let file = out.join("bench.md");
    let text = format!("{}\n\n{table}", bench::machine());
    if let Err(e) = std::fs::write(&file, text) {
        eprintln!("error: cannot write {}: {e}", file.display());
        return ExitCode::FAILURE;
    }
    println!("table: {}", file.display());
    ExitCode::SUCCESS
}

/// The mechanisms `--mechanisms` names (`none` left out), or `None` after
/// printing the error for a name that is not one of [`bench::MECHANISMS`].
fn bench_mechanisms(names: &[String]) -> Option<Vec<bench::Mechanism>> {
    let mut chosen = Vec::new();
    for name in names.iter().filter(|n| n.as_str() != "none") {
        match bench::MECHANISMS.iter().find(|m| m.name == name.as_str()) {
            Some(m) => chosen.push(*m),
            None => {
                let known: Vec<&str> = bench::MECHANISMS.iter().map(|m| m.name).collect();
                eprintln!(
                    "error: --mechanisms: no mechanism `{name}`; fix: one of {} or `none`",
                    known.join(", ")
                );
                return None;
            }
        }
    }
    Some(chosen)
}

/// `flexmech study`: a parameter study (or one shard of it, or the merge of
/// its shards); prints what ran and where its files are.
fn study_command(args: StudyArgs, registry: &JointRegistry) -> ExitCode {
    let StudyArgs {
        study,
        out,
        shard,
        merge,
    } = args;
    let slurm = flexmech_studies::SlurmArray::from_env();
    let outcome = flexmech_studies::study_command(
        registry,
        &study,
        &out,
        shard.as_deref(),
        merge,
        &slurm,
        true,
    );
    let r = match outcome {
        Ok(r) => r,
        Err(e) => return fail(e),
    };
    let what = match r.shard {
        Some(s) => format!("shard {s}"),
        None if merge => "merged".to_owned(),
        None => "all runs".to_owned(),
    };
    println!(
        "{}: {what}: {} run(s), {} failed -> {} and {}",
        study.display(),
        r.runs,
        r.failed,
        r.csv.display(),
        r.h5.display()
    );
    println!(
        "runs: {} (<run id>.h5; the summary's `run` column and its column per \
         swept key give each run's values)",
        r.dir.join("runs").display()
    );
    if !r.charts.is_empty() {
        println!("charts: {}", r.dir.join("charts").display());
    }
    ExitCode::SUCCESS
}
