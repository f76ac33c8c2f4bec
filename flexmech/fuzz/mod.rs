//! Fuzzing the model-file path: mutants of the models in `data/` go through
//! `flexmech check` (parse, validate, build: every derived quantity at
//! t = 0) and, when they pass and are small enough, a shortened
//! `flexmech run`; each outcome is classified. A mutant must be refused with
//! a located error (`error: <file>…`), fail to solve with an error naming
//! its file, or complete with finite results. A panic, an abort (a signal),
//! a hang (no exit within the timeout), an unlocated error or a non-finite
//! value in a completed result is a defect; its mutant is kept as a
//! reproducer.
//!
//! Every mutant runs in its own process (so an abort or a hang is seen, not
//! suffered), several at a time. The test suite runs a bounded campaign
//! (`flexmech/tests/fuzz.rs`); `flexmech-fuzz` runs any size
//! (`scripts/fuzz.sh`).

pub mod mutate;

use flexmech::results::ResultReader;
use mutate::{mutate, Kind, Rng};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// Largest model (elements in all) that a mutant is solved with; a larger
/// one is only checked (validated and built), to keep campaigns bounded.
const MAX_RUN_ELEMENTS: u64 = 5_000;
/// Steps a solved mutant takes at most (`t_end ≤ 3 dt`, `load_steps ≤ 3`).
const RUN_STEPS: f64 = 3.0;
/// Newton iterations and halvings a solved mutant may use at most.
const RUN_ITERATIONS: u64 = 50;
const RUN_HALVINGS: u64 = 8;
/// Datasets in which NaN is part of the contract (β of non-EM schemes).
const NAN_ALLOWED: &[&str] = &["/solver/beta"];

/// Dataset names whose first row (t = 0, before any step's equations) is
/// NaN by contract: the joint and support reactions.
const NAN_FIRST_ROW: &[&str] = &["reaction_force", "reaction_moment"];

/// What became of one mutant.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Outcome {
    /// Refused by `check` with a located error.
    Refused,
    /// Passed `check`; too large to be solved in a campaign.
    CheckedOnly,
    /// Solved to the end, every value finite.
    Completed,
    /// Solved to the end with a warning (energy balance, stability).
    CompletedWithWarning,
    /// The solver stopped with an error naming the file.
    SolveFailed,
    /// Defect: a panic.
    Panic,
    /// Defect: killed by a signal (an abort).
    Abort,
    /// Defect: no exit within the timeout.
    Hang,
    /// Defect: an error that does not name the file.
    Unlocated,
    /// Defect: a completed result with a non-finite value.
    NonFinite,
}

impl Outcome {
    /// Whether the outcome is a defect.
    pub fn is_defect(self) -> bool {
        self >= Outcome::Panic
    }

    /// Its name in reports.
    pub fn name(self) -> &'static str {
        match self {
            Outcome::Refused => "refused (located error)",
            Outcome::CheckedOnly => "valid, too large to solve here",
            Outcome::Completed => "completed",
            Outcome::CompletedWithWarning => "completed with a warning",
            Outcome::SolveFailed => "solve failed (located error)",
            Outcome::Panic => "DEFECT: panic",
            Outcome::Abort => "DEFECT: abort",
            Outcome::Hang => "DEFECT: hang",
            Outcome::Unlocated => "DEFECT: unlocated error",
            Outcome::NonFinite => "DEFECT: non-finite value in a completed result",
        }
    }
}

/// A campaign's settings.
#[derive(Debug, Clone)]
pub struct FuzzOptions {
    /// The `flexmech` executable.
    pub flexmech: PathBuf,
    /// The directory of the models to mutate (searched recursively; study
    /// files are left out).
    pub data: PathBuf,
    /// Work directory: one sub-directory per mutant, removed unless it is a
    /// defect's reproducer.
    pub work: PathBuf,
    /// Seed of the campaign.
    pub seed: u64,
    /// Mutants at most.
    pub mutants: usize,
    /// Wall time after which no new mutant is started.
    pub budget: Option<Duration>,
    /// Time a process may take before it counts as a hang.
    pub timeout: Duration,
    /// Mutants run at once.
    pub threads: usize,
}

/// A campaign's result.
#[derive(Debug, Clone, Default)]
pub struct FuzzReport {
    /// Mutants run.
    pub mutants: usize,
    /// Mutants per outcome.
    pub counts: BTreeMap<Outcome, usize>,
    /// Mutants per mutation kind.
    pub kinds: BTreeMap<&'static str, usize>,
    /// Every defect: the reproducer's directory, its outcome, the message.
    pub defects: Vec<(PathBuf, Outcome, String)>,
}

impl FuzzReport {
    /// The report as text: counts per outcome and per kind, and the defects.
    pub fn text(&self) -> String {
        let mut s = format!("{} mutants\n", self.mutants);
        for (o, n) in &self.counts {
            s.push_str(&format!("  {:48} {n}\n", o.name()));
        }
        s.push_str("by mutation kind:\n");
        for (k, n) in &self.kinds {
            s.push_str(&format!("  {k:48} {n}\n"));
        }
        for (dir, o, m) in &self.defects {
            s.push_str(&format!("{}: {}: {m}\n", dir.display(), o.name()));
        }
        s
    }
}

/// The model files under `dir` (recursively), sorted; study files (which
/// name a `model`) are left out.
pub fn model_files(dir: &Path) -> std::io::Result<Vec<PathBuf>> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d)? {
            let path = entry?.path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "toml") {
                let text = std::fs::read_to_string(&path)?;
                if !text.lines().any(|l| l.starts_with("model =")) {
                    out.push(path);
                }
            }
        }
    }
    out.sort();
    Ok(out)
}

/// Runs a campaign.
pub fn run(options: &FuzzOptions) -> std::io::Result<FuzzReport> {
    let bases: Vec<String> = model_files(&options.data)?
        .iter()
        .map(std::fs::read_to_string)
        .collect::<Result<_, _>>()?;
    if bases.is_empty() {
        return Err(std::io::Error::other("no model files to mutate"));
    }
    std::fs::create_dir_all(&options.work)?;
    let next = AtomicUsize::new(0);
    let report = Mutex::new(FuzzReport::default());
    let start = Instant::now();
    std::thread::scope(|scope| {
        for _ in 0..options.threads.max(1) {
            scope.spawn(|| loop {
                let id = next.fetch_add(1, Ordering::Relaxed);
                let late = options.budget.is_some_and(|b| start.elapsed() > b);
                if id >= options.mutants || late {
                    break;
                }
                let (kind, outcome, message, dir) = one(options, &bases, id);
                let mut r = report.lock().unwrap_or_else(|e| e.into_inner());
                r.mutants += 1;
                *r.counts.entry(outcome).or_default() += 1;
                *r.kinds.entry(kind_name(kind)).or_default() += 1;
                if outcome.is_defect() {
                    r.defects.push((dir, outcome, message));
                } else {
                    let _ = std::fs::remove_dir_all(&dir);
                }
            });
        }
    });
    Ok(report.into_inner().unwrap_or_else(|e| e.into_inner()))
}

fn kind_name(kind: Kind) -> &'static str {
    match kind {
        Kind::Numeric => "numeric",
        Kind::Structural => "structural",
        Kind::Bytes => "byte-level",
    }
}

/// Mutant `id`: made, checked, perhaps solved, classified.
fn one(options: &FuzzOptions, bases: &[String], id: usize) -> (Kind, Outcome, String, PathBuf) {
    let mut rng = Rng::new(options.seed ^ (id as u64).wrapping_mul(0x2545_f491_4f6c_dd1d));
    let base = &bases[id % bases.len()];
    let kind = [Kind::Numeric, Kind::Structural, Kind::Bytes][rng.below(3)];
    let mut text = base.clone();
    for _ in 0..1 + rng.below(3) {
        text = mutate(&text, kind, &mut rng);
    }
    let dir = options.work.join(format!("m{id:06}"));
    let write = |name: &str, text: &str| -> Result<PathBuf, String> {
        std::fs::create_dir_all(&dir).map_err(|e| e.to_string())?;
        let path = dir.join(name);
        std::fs::write(&path, text).map_err(|e| e.to_string())?;
        Ok(path)
    };
    let mutant = match write("mutant.toml", &text) {
        Ok(p) => p,
        Err(e) => return (kind, Outcome::Unlocated, e, dir),
    };
    let check = execute(options, &dir, &["check"], &mutant);
    let (outcome, message) = match check {
        Exit::Code(0, _, _) => {
            let short = shorten(&text);
            if elements(&short) > MAX_RUN_ELEMENTS {
                (Outcome::CheckedOnly, String::new())
            } else {
                match write("run.toml", &short) {
                    Ok(p) => solve(options, &dir, &p),
                    Err(e) => (Outcome::Unlocated, e),
                }
            }
        }
        other => classify_error(other, &mutant, Outcome::Refused),
    };
    (kind, outcome, message, dir)
}

/// Solves the shortened mutant and classifies the outcome.
fn solve(options: &FuzzOptions, dir: &Path, model: &Path) -> (Outcome, String) {
    let out = dir.join("out");
    let out_arg = out.to_string_lossy().into_owned();
    match execute(options, dir, &["run", "--out", &out_arg], model) {
        Exit::Code(0, stdout, _) => match non_finite(&out) {
            Some(where_) => (Outcome::NonFinite, where_),
            None if stdout.contains("with a warning") => {
                (Outcome::CompletedWithWarning, String::new())
            }
            None => (Outcome::Completed, String::new()),
        },
        other => classify_error(other, model, Outcome::SolveFailed),
    }
}

/// How a process ended: exit code with stdout and stderr, a signal, or
/// the timeout.
enum Exit {
    Code(i32, String, String),
    Signal(i32),
    Timeout,
    Spawn(String),
}

fn execute(options: &FuzzOptions, dir: &Path, args: &[&str], model: &Path) -> Exit {
    let (out, err) = (dir.join("stdout.txt"), dir.join("stderr.txt"));
    let files = std::fs::File::create(&out).and_then(|o| Ok((o, std::fs::File::create(&err)?)));
    let (o, e) = match files {
        Ok(f) => f,
        Err(e) => return Exit::Spawn(e.to_string()),
    };
    let child = Command::new(&options.flexmech)
        .args(args)
        .arg(model)
        .env("RAYON_NUM_THREADS", "1")
        .stdin(Stdio::null())
        .stdout(o)
        .stderr(e)
        .spawn();
    let mut child = match child {
        Ok(c) => c,
        Err(e) => return Exit::Spawn(e.to_string()),
    };
    let deadline = Instant::now() + options.timeout;
    let status = loop {
        match child.try_wait() {
            Ok(Some(s)) => break s,
            Ok(None) if Instant::now() > deadline => {
                let _ = child.kill();
                let _ = child.wait();
                return Exit::Timeout;
            }
            Ok(None) => std::thread::sleep(Duration::from_millis(5)),
            Err(e) => return Exit::Spawn(e.to_string()),
        }
    };
    let read = |p: &Path| {
        std::fs::read(p)
            .map(|b| String::from_utf8_lossy(&b).into_owned())
            .unwrap_or_default()
    };
    match status.code() {
        Some(code) => Exit::Code(code, read(&out), read(&err)),
        None => {
            use std::os::unix::process::ExitStatusExt;
            Exit::Signal(status.signal().unwrap_or(0))
        }
    }
}

/// A failed process: `expected` when it exited 1 with an error that names
/// `model`, a defect otherwise.
fn classify_error(exit: Exit, model: &Path, expected: Outcome) -> (Outcome, String) {
    match exit {
        Exit::Code(1, _, stderr) => {
            let first = stderr.lines().next().unwrap_or("").to_string();
            if stderr.contains("panicked at") {
                (Outcome::Panic, first)
            } else if first.starts_with(&format!("error: {}", model.display())) {
                (expected, String::new())
            } else {
                (Outcome::Unlocated, first)
            }
        }
        Exit::Code(101, _, stderr) => (Outcome::Panic, stderr.lines().take(3).collect()),
        Exit::Code(code, _, stderr) => (
            Outcome::Unlocated,
            format!("exit {code}: {}", stderr.lines().next().unwrap_or("")),
        ),
        Exit::Signal(s) => (Outcome::Abort, format!("signal {s}")),
        Exit::Timeout => (Outcome::Hang, "no exit within the timeout".into()),
        Exit::Spawn(e) => (Outcome::Unlocated, format!("could not run: {e}")),
    }
}

/// The mutant cut down to a short solve: at most [`RUN_STEPS`] steps, few
/// iterations and halvings (values that do not parse are left alone:
/// `check` has accepted the text).
fn shorten(text: &str) -> String {
    let number = |line: &str, key: &str| -> Option<f64> {
        let (k, v) = line.split_once('=')?;
        (k.trim() == key).then_some(())?;
        v.split('#').next()?.trim().parse().ok()
    };
    let dt = text.lines().find_map(|l| number(l, "dt"));
    let mut out = String::with_capacity(text.len());
    for line in text.lines() {
        let clamp = |key: &str, most: f64| {
            number(line, key)
                .filter(|v| v.is_finite() && *v > most)
                .map(|_| format!("{key} = {most:?}"))
        };
        let integer = |key: &str, most: u64| {
            number(line, key)
                .filter(|v| *v > most as f64)
                .map(|_| format!("{key} = {most}"))
        };
        let replaced = dt
            .filter(|dt| dt.is_finite() && *dt > 0.0)
            .and_then(|dt| clamp("t_end", RUN_STEPS * dt))
            .or_else(|| integer("load_steps", RUN_STEPS as u64))
            .or_else(|| integer("max_iterations", RUN_ITERATIONS))
            .or_else(|| integer("max_halvings", RUN_HALVINGS));
        out.push_str(replaced.as_deref().unwrap_or(line));
        out.push('\n');
    }
    out
}

/// Elements in all (`elements = n` lines).
fn elements(text: &str) -> u64 {
    text.lines()
        .filter_map(|l| {
            let (k, v) = l.split_once('=')?;
            (k.trim() == "elements").then_some(())?;
            v.split('#').next()?.trim().parse::<u64>().ok()
        })
        .fold(0u64, u64::saturating_add)
}

/// The first non-finite value in the result files under `dir`, as
/// `file:dataset`.
fn non_finite(dir: &Path) -> Option<String> {
    let entries = std::fs::read_dir(dir).ok()?;
    for entry in entries.flatten() {
        let path = entry.path();
        if path.extension().is_some_and(|e| e == "h5") {
            let file = match ResultReader::open(&path) {
                Ok(f) => f,
                Err(e) => return Some(format!("{}: unreadable: {e}", path.display())),
            };
            if let Some(name) = non_finite_in(&file) {
                return Some(format!("{}:{name}", path.display()));
            }
        }
    }
    None
}

/// The first dataset of `file` with a non-finite value where none may be.
fn non_finite_in(file: &ResultReader) -> Option<String> {
    for path in file.dataset_names() {
        if NAN_ALLOWED.contains(&path.as_str()) {
            continue;
        }
        let name = path.rsplit('/').next().unwrap_or_default();
        let first_row = if NAN_FIRST_ROW.contains(&name) {
            let shape = file.shape(&path).unwrap_or_default();
            shape.iter().skip(1).product::<usize>()
        } else {
            0
        };
        // Datasets of strings or integers are not read as numbers.
        if let Ok(values) = file.values(&path) {
            if values.iter().skip(first_row).any(|v| !v.is_finite()) {
                return Some(path);
            }
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shorten_clamps_the_run_length_only() {
        let text = "name = \"x\"\n[solver]\ndt = 0.01\nt_end = 6.0 # s\nmax_iterations = 900\n";
        let short = shorten(text);
        assert!(short.contains("t_end = 0.03"), "{short}");
        assert!(short.contains("max_iterations = 50"), "{short}");
        assert!(short.contains("dt = 0.01"), "{short}");
        assert_eq!(shorten("load_steps = 2\n"), "load_steps = 2\n");
        assert_eq!(shorten("load_steps = 200\n"), "load_steps = 3\n");
    }

    #[test]
    fn elements_are_summed() {
        assert_eq!(elements("elements = 4\nx = 1\nelements = 10 # c\n"), 14);
    }

    #[test]
    fn outcomes_order_defects_last() {
        assert!(!Outcome::SolveFailed.is_defect());
        assert!(Outcome::Panic.is_defect() && Outcome::NonFinite.is_defect());
    }
}
