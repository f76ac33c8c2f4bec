//! A parameter study whose mechanism is built in Rust, not read from a file.
//!
//! A clamped cantilever of length `L` carries a tip force `F`; the study
//! sweeps the bending stiffness `EI` and the force, and its own figure of
//! merit `tip_deflection` is the tip's final transverse displacement. The
//! runs get everything a study file's runs get: parallel execution, one HDF5
//! file per run, the summary table and charts, shards (`--shard K/N` or a
//! Slurm array task) and `--merge`:
//!
//! ```text
//! cargo run --release -p flexmech --example rust_study -- studies
//! cargo run --release -p flexmech --example rust_study -- studies --shard 1/2
//! ```
//!
//! For small deflections the answer is Timoshenko's: `F L³/(3 EI) + F L/GA`.
//! Two-node elements of the Reissner–Simo beam with one-point quadrature get
//! the nodal rotations exactly (the element moment is the exact moment at
//! its midpoint, and the midpoint rule integrates the linear `M/EI`
//! exactly), but the deflection is the trapezoidal rule over the quadratic
//! rotation, `−h³θ''/12 = −h³F/(12 EI)` per element: `−F L³/(12 EI n²)` for
//! `n` elements. The test below holds the study to that analytic value of the
//! discrete model.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use nalgebra::Vector3;

use flexmech::model::{
    Analysis, BeamGeometry, BeamSpec, LoadSpec, Model, NodeRef, OutputSpec, SectionSpec,
    SectionValues, SolverSpec, SupportSpec,
};
use flexmech::studies::{
    merge_study, run_study, select_shard, Component, DatasetFigure, Figure, Reduce, SlurmArray,
    StudyOptions, StudyReport, StudySpec,
};

/// Beam length (m).
const LENGTH: f64 = 1.0;
/// Elements along the beam.
const ELEMENTS: usize = 10;
/// Shear stiffness GA (N).
const SHEAR: f64 = 1.0e6;

/// The cantilever with bending stiffness `ei` and tip force `force` (−z).
fn cantilever(ei: f64, force: f64) -> Model {
    let beam = NodeRef { beam: 0, node: 0 };
    let tip = NodeRef {
        beam: 0,
        node: ELEMENTS,
    };
    Model {
        name: "cantilever".into(),
        path: PathBuf::from("cantilever (built in Rust)"),
        sections: vec![SectionSpec {
            name: "rod".into(),
            values: SectionValues {
                ea: 1.0e7,
                ga: [SHEAR, SHEAR],
                gj: ei,
                ei: [ei, ei],
                rho_a: 0.0,
                rho_j: [0.0; 3],
            },
            damping: 0.0,
        }],
        beams: vec![BeamSpec {
            name: "beam".into(),
            section: 0,
            geometry: BeamGeometry::Straight {
                start: Vector3::zeros(),
                end: Vector3::new(LENGTH, 0.0, 0.0),
                e2: Vector3::y(),
            },
            elements: ELEMENTS,
            nodes_per_element: 2,
        }],
        supports: vec![SupportSpec {
            node: beam,
            fixed: [true; 6],
        }],
        loads: vec![LoadSpec {
            node: tip,
            force: [0.0, 0.0, -force],
            moment: [0.0; 3],
            time: None,
            follower: false,
        }],
        solver: SolverSpec {
            analysis: Analysis::Static { load_steps: 1 },
            ..SolverSpec::default()
        },
        output: OutputSpec {
            track: vec![("beam.end".into(), tip)],
            ..OutputSpec::default()
        },
        ..Model::default()
    }
}

/// The study: `EI` × `F`, summarised by the tip deflection and the solver's
/// own figures.
fn study() -> Result<StudySpec, Box<dyn std::error::Error>> {
    let tip = Figure::Dataset(DatasetFigure {
        name: "tip_deflection".into(),
        dataset: "/nodes/beam.end/displacement".into(),
        component: Component::Index(2),
        reduce: Reduce::Final,
        derivative: Vec::new(),
        mode: None,
    });
    Ok(StudySpec::from_fn(
        "cantilever-stiffness",
        vec![
            ("EI".into(), vec![50.0.into(), 100.0.into()]),
            ("F".into(), vec![0.01.into(), 0.02.into()]),
        ],
        vec![tip, Figure::NewtonIterations, Figure::WallTime],
        |p| Ok(cantilever(p.f64("EI")?, p.f64("F")?)),
    )?)
}

/// `OUT [--shard K/N | --merge]`: runs (a shard of) the study below `OUT`,
/// or merges its shards.
fn run(args: &[String]) -> Result<StudyReport, Box<dyn std::error::Error>> {
    let (out, rest) = args
        .split_first()
        .ok_or("usage: rust_study OUT_DIR [--shard K/N | --merge]")?;
    let spec = study()?;
    let out = Path::new(out);
    match rest {
        [] => Ok(run_with_shard(&spec, out, None)?),
        [flag, k] if flag == "--shard" => Ok(run_with_shard(&spec, out, Some(k))?),
        [flag] if flag == "--merge" => Ok(merge_study(&spec, out)?),
        _ => Err("usage: rust_study OUT_DIR [--shard K/N | --merge]".into()),
    }
}

fn run_with_shard(
    spec: &StudySpec,
    out: &Path,
    shard: Option<&String>,
) -> Result<StudyReport, Box<dyn std::error::Error>> {
    let shard = select_shard(shard.map(String::as_str), &SlurmArray::from_env())?;
    let options = StudyOptions {
        out: out.to_path_buf(),
        shard,
        progress: true,
    };
    Ok(run_study(spec, &options)?)
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match run(&args) {
        Ok(report) => {
            println!(
                "{} runs ({} failed): {}",
                report.runs,
                report.failed,
                report.csv.display()
            );
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use flexmech::results::ResultReader;

    /// Tip deflection of the discrete cantilever: Timoshenko's
    /// `F L³/(3EI) + F L/GA` less the trapezoidal-rule error
    /// `F L³/(12 EI n²)` of two-node elements (module docs).
    fn analytic(ei: f64, force: f64) -> f64 {
        let n = ELEMENTS as f64;
        force * LENGTH.powi(3) / (3.0 * ei) + force * LENGTH / SHEAR
            - force * LENGTH.powi(3) / (12.0 * ei * n * n)
    }

    #[test]
    fn the_rust_study_matches_the_beam_theory_and_shards_merge() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().to_string_lossy().into_owned();
        for k in ["1/2", "2/2"] {
            run(&[out.clone(), "--shard".into(), k.into()]).unwrap();
        }
        let report = run(&[out.clone(), "--merge".into()]).unwrap();
        assert_eq!((report.runs, report.failed), (4, 0));
        assert_eq!(report.charts.len(), 6);
        let csv = std::fs::read_to_string(&report.csv).unwrap();
        let mut lines = csv.lines();
        assert_eq!(
            lines.next().unwrap(),
            "run,EI,F,status,tip_deflection,newton_iterations,wall_time"
        );
        let mut rows = 0;
        for line in lines {
            let cells: Vec<&str> = line.split(',').collect();
            let (ei, force): (f64, f64) = (cells[1].parse().unwrap(), cells[2].parse().unwrap());
            let w: f64 = cells[4].parse().unwrap();
            let expected = analytic(ei, force);
            // The geometric nonlinearity changes a deflection of relative
            // size d = w/L by O(d²) ≤ 1e-6 of it here.
            let d = expected / LENGTH;
            assert!(
                (-w - expected).abs() <= 2.0 * d * d * expected,
                "EI = {ei}, F = {force}: {w} against -{expected}"
            );
            rows += 1;
        }
        assert_eq!(rows, 4);
        // Each run's file says which run it was and with which values.
        let file = report.dir.join("runs/run-0003.h5");
        let text = ResultReader::open(&file)
            .unwrap()
            .string_attr("model")
            .unwrap();
        assert!(text.contains("run-0003"), "{text}");
        assert!(text.contains("EI = 100"), "{text}");
        assert!(text.contains("F = 0.02"), "{text}");
    }
}
