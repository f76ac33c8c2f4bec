//! `flexmech bench`: the cost per time step of the yardstick cantilever
//! (`benches/cantilever512.toml`: a 2 m cantilever under a tip force,
//! `dt = 1e-3`) at several mesh sizes, with each integrator and Newton
//! variant and with 3-node elements, as microseconds per step and per
//! element-step — and as ratios to Newmark with full Newton measured in the
//! same run, which is what carries over between machines on a shared one.
//! Then the mechanisms of `data/benchmarks/` (the four-bar with a misaligned
//! joint and the slider-crank), each a whole run of the published benchmark
//! with each integrator that applies.

use flexmech_model::parse_model;
use flexmech_results::run::{run_model, RunError};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// One configuration of the yardstick.
#[derive(Debug, Clone, Copy)]
pub struct Case {
    /// Short label, e.g. `newmark/modified`.
    pub label: &'static str,
    /// The integrator's model-file name.
    pub integrator: &'static str,
    /// `"full"` or `"modified"` Newton.
    pub newton: &'static str,
    /// Nodes per element (3-node elements run with half as many elements,
    /// so the unknowns are the same).
    pub nodes_per_element: usize,
}

/// The configurations `flexmech bench` times; the first is the reference.
pub const CASES: [Case; 7] = [
    Case {
        label: "newmark",
        integrator: "newmark",
        newton: "full",
        nodes_per_element: 2,
    },
    Case {
        label: "newmark/modified",
        integrator: "newmark",
        newton: "modified",
        nodes_per_element: 2,
    },
    Case {
        label: "generalized-alpha",
        integrator: "generalized-alpha",
        newton: "full",
        nodes_per_element: 2,
    },
    Case {
        label: "momentum",
        integrator: "momentum",
        newton: "full",
        nodes_per_element: 2,
    },
    Case {
        label: "energy-momentum",
        integrator: "energy-momentum",
        newton: "full",
        nodes_per_element: 2,
    },
    Case {
        label: "energy-momentum/modified",
        integrator: "energy-momentum",
        newton: "modified",
        nodes_per_element: 2,
    },
    Case {
        label: "newmark/3-node",
        integrator: "newmark",
        newton: "full",
        nodes_per_element: 3,
    },
];

/// One timed run.
#[derive(Debug, Clone)]
pub struct Timing {
    /// The model: `cantilever` (the yardstick) or a [`Mechanism`]'s name.
    pub model: &'static str,
    /// What ran.
    pub case: Case,
    /// Elements of 2 nodes (or the 3-node mesh with the same unknowns).
    pub elements: usize,
    /// Time steps taken.
    pub steps: usize,
    /// Newton iterations in all.
    pub iterations: usize,
    /// Wall time of the time steps, seconds (the run's set-up — patterns,
    /// orderings, initial accelerations — left out).
    pub seconds: f64,
    /// Wall time of the set-up, seconds.
    pub setup_seconds: f64,
}

impl Timing {
    /// Microseconds per time step.
    pub fn per_step_us(&self) -> f64 {
        1e6 * self.seconds / self.steps as f64
    }
    /// Microseconds per step and per 2-node-equivalent element.
    pub fn per_element_step_us(&self) -> f64 {
        self.per_step_us() / self.elements as f64
    }
}

/// The yardstick's model text for a case, `elements` (2-node equivalent)
/// and `steps` steps of `dt = 1e-3`.
pub fn model_text(case: &Case, elements: usize, steps: usize) -> String {
    let mesh = if case.nodes_per_element == 3 {
        format!(
            "elements = {}\nnodes_per_element = 3",
            (elements / 2).max(1)
        )
    } else {
        format!("elements = {elements}")
    };
    format!(
        r#"name = "bench"
[[section]]
name = "s"
EA = 1.0e6
GA = [1.0e6, 1.0e6]
GJ = 1.0e3
EI = [1.0e3, 1.0e3]
rhoA = 1.0
rhoJ = [1.0e-3, 5.0e-4, 5.0e-4]
[[beam]]
name = "b"
section = "s"
start = [0.0, 0.0, 0.0]
end = [2.0, 0.0, 0.0]
e2 = [0.0, 1.0, 0.0]
{mesh}
[[support]]
node = "b.start"
fixed = "all"
[[load]]
node = "b.end"
force = [0.0, 0.0, 50.0]
[solver]
analysis = "dynamic"
integrator = "{}"
newton = "{}"
dt = 1.0e-3
t_end = {}
[output]
every = {steps}
"#,
        case.integrator,
        case.newton,
        steps as f64 * 1e-3
    )
}

/// Times every case at every size, writing the result files under `out`.
/// Each size runs its cases `rounds` times, interleaved (all cases, then
/// all again), and keeps each case's fastest run: on a shared machine other
/// work only ever adds time, so the minimum is the figure that repeats, and
/// interleaving exposes every case to the same spells of load. `progress`
/// is called with each case's kept timing once its size is done.
pub fn bench(
    sizes: &[usize],
    steps: usize,
    rounds: usize,
    out: &Path,
    mut progress: impl FnMut(&Timing),
) -> Result<Vec<Timing>, RunError> {
    let cases: Vec<&Case> = CASES.iter().collect();
    let mut timings = Vec::new();
    for &elements in sizes {
        let kept = fastest_of(&cases, rounds, |case| time_case(case, elements, steps, out))?;
        kept.iter().for_each(&mut progress);
        timings.extend(kept);
    }
    Ok(timings)
}

/// Runs `cases` `rounds` times, interleaved (all cases, then all again),
/// and keeps each case's fastest run, in the cases' order.
fn fastest_of(
    cases: &[&Case],
    rounds: usize,
    mut run: impl FnMut(&Case) -> Result<Timing, RunError>,
) -> Result<Vec<Timing>, RunError> {
    let mut fastest: Vec<Option<Timing>> = vec![None; cases.len()];
    for _ in 0..rounds.max(1) {
        for (case, kept) in cases.iter().zip(fastest.iter_mut()) {
            let t = run(case)?;
            if kept.as_ref().is_none_or(|k| t.seconds < k.seconds) {
                *kept = Some(t);
            }
        }
    }
    Ok(fastest.into_iter().flatten().collect())
}

/// The yardstick's name in the timings.
pub const CANTILEVER: &str = "cantilever";

/// A mechanism of `data/benchmarks/` timed by `flexmech bench` (the file's
/// text is built into the binary, so the command runs anywhere).
#[derive(Debug, Clone, Copy)]
pub struct Mechanism {
    /// The name `--mechanisms` takes and the tables show.
    pub name: &'static str,
    /// The model file's text (generalized-α as published).
    pub text: &'static str,
}

/// The mechanisms `flexmech bench` times after the cantilever.
pub const MECHANISMS: [Mechanism; 2] = [
    Mechanism {
        name: "four-bar",
        text: include_str!("../../data/benchmarks/four_bar_tacs.toml"),
    },
    Mechanism {
        name: "slider-crank",
        text: include_str!("../../data/benchmarks/slider_crank.toml"),
    },
];

/// The cases a mechanism runs with: the 2-node cases (its mesh is the
/// file's).
pub fn mechanism_cases() -> impl Iterator<Item = &'static Case> {
    CASES.iter().filter(|c| c.nodes_per_element == 2)
}

/// A mechanism's model text run with `case`'s integrator and Newton: the
/// file's `integrator` line replaced, its `rho_inf` kept for
/// generalized-α only.
pub fn mechanism_text(mechanism: &Mechanism, case: &Case) -> String {
    let mut text = String::with_capacity(mechanism.text.len() + 64);
    for line in mechanism.text.lines() {
        let key = line.split('=').next().unwrap_or("").trim();
        match key {
            "integrator" => {
                let _ = writeln!(
                    text,
                    "integrator = \"{}\"\nnewton = \"{}\"",
                    case.integrator, case.newton
                );
            }
            // Replaced with the integrator line.
            "newton" => {}
            "rho_inf" if case.integrator != "generalized-alpha" => {}
            _ => {
                text.push_str(line);
                text.push('\n');
            }
        }
    }
    text
}

/// Times the named mechanisms with each of their cases, `rounds` times
/// interleaved, keeping each case's fastest run (as [`bench()`]).
/// `progress` is called with each kept timing once its mechanism is done.
pub fn bench_mechanisms(
    mechanisms: &[Mechanism],
    rounds: usize,
    out: &Path,
    mut progress: impl FnMut(&Timing),
) -> Result<Vec<Timing>, RunError> {
    let cases: Vec<&Case> = mechanism_cases().collect();
    let mut timings = Vec::new();
    for mechanism in mechanisms {
        let kept = fastest_of(&cases, rounds, |case| {
            let path = PathBuf::from(format!(
                "bench-{}-{}.toml",
                mechanism.name,
                case.label.replace('/', "-")
            ));
            let text = mechanism_text(mechanism, case);
            timed_run(mechanism.name, case, &text, &path, None, out)
        })?;
        kept.iter().for_each(&mut progress);
        timings.extend(kept);
    }
    Ok(timings)
}

/// One run of `case` at `elements`, its result file under `out`.
fn time_case(case: &Case, elements: usize, steps: usize, out: &Path) -> Result<Timing, RunError> {
    let text = model_text(case, elements, steps);
    let path = PathBuf::from(format!(
        "bench-{}-{elements}.toml",
        case.label.replace('/', "-")
    ));
    timed_run(CANTILEVER, case, &text, &path, Some(elements), out)
}

/// Parses and runs `text` (read as if from `path`), timing its steps;
/// `elements` is the count the timing reports (default: the model's).
fn timed_run(
    model: &'static str,
    case: &Case,
    text: &str,
    path: &Path,
    elements: Option<usize>,
    out: &Path,
) -> Result<Timing, RunError> {
    let parsed = parse_model(text, path).map_err(RunError::from)?;
    let elements = elements.unwrap_or_else(|| parsed.beams.iter().map(|b| b.elements).sum());
    let dir = out.join(path.with_extension(""));
    let summary = run_model(&parsed, &dir)?;
    Ok(Timing {
        model,
        case: *case,
        elements,
        // The summary counts the initial record too.
        steps: summary.steps.saturating_sub(1).max(1),
        iterations: summary.iterations,
        seconds: summary.wall_time_s - summary.setup_time_s,
        setup_seconds: summary.setup_time_s,
    })
}

/// The machine the figures come from: CPU model, logical CPUs, threads used.
pub fn machine() -> String {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|m| m.trim().to_owned())
        })
        .unwrap_or_else(|| "unknown CPU".into());
    let cpus = std::thread::available_parallelism().map_or(1, |n| n.get());
    format!(
        "{cpu}, {cpus} logical CPUs, {} assembly thread(s) (RAYON_NUM_THREADS), flexmech {}",
        rayon::current_num_threads(),
        env!("CARGO_PKG_VERSION")
    )
}

/// A Markdown table of the timings, with each run's ratio to the reference
/// case (Newmark, full Newton) of the same model and size.
pub fn table(timings: &[Timing]) -> String {
    let mut s = String::from(
        "| model | elements | case | steps | iterations | µs/step | µs/(element·step) | / newmark | set-up ms |\n\
         |---|---|---|---|---|---|---|---|---|\n",
    );
    for t in timings {
        let reference = timings
            .iter()
            .find(|r| {
                r.model == t.model && r.elements == t.elements && r.case.label == CASES[0].label
            })
            .map_or(f64::NAN, |r| t.seconds / r.seconds);
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {:.0} | {:.2} | {:.2} | {:.1} |",
            t.model,
            t.elements,
            t.case.label,
            t.steps,
            t.iterations,
            t.per_step_us(),
            t.per_element_step_us(),
            reference,
            1e3 * t.setup_seconds
        );
    }
    s
}
