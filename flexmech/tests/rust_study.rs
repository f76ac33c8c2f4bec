//! Studies defined in Rust and models built in Rust: what is refused, with
//! which message, before anything runs.

use std::path::{Path, PathBuf};

use flexmech::model::{load_model, Analysis, Model, NodeRef, PrescribedSpec, TimeFunction};
use flexmech::studies::{
    execute::plans, run_study, sweep::model_for, Figure, SpecError, StudyOptions, StudySpec,
    SweepError,
};
use toml::Value;

fn data(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../data")
        .join(rel)
}

fn base() -> Model {
    load_model(&data("statics/screw_driven.toml")).unwrap()
}

fn grid(key: &str, values: &[f64]) -> Vec<(String, Vec<Value>)> {
    vec![(key.into(), values.iter().map(|&v| v.into()).collect())]
}

#[test]
fn a_study_defined_in_rust_is_checked_like_a_study_file() {
    let f = |_: &flexmech::studies::RunParams<'_>| Ok(base());
    let err = |r: Result<StudySpec, SpecError>| r.unwrap_err().to_string();
    let e = err(StudySpec::from_fn("a/b", grid("x", &[1.0]), vec![], f));
    assert!(e.contains("path separator"), "{e}");
    let e = err(StudySpec::from_fn(
        "s",
        vec![("x".into(), vec![])],
        vec![],
        f,
    ));
    assert!(e.contains("empty"), "{e}");
    let mut twice = grid("x", &[1.0]);
    twice.extend(grid("x", &[2.0]));
    let e = err(StudySpec::from_fn("s", twice, vec![], f));
    assert!(e.contains("given twice"), "{e}");
    let e = err(StudySpec::from_fn(
        "s",
        grid("x", &[1.0]),
        vec![Figure::WallTime, Figure::WallTime],
        f,
    ));
    assert!(e.contains("wall_time"), "{e}");
    // Over a base model, every key must name a value present in it.
    let text = std::fs::read_to_string(data("statics/screw_driven.toml")).unwrap();
    let file = data("statics/screw_driven.toml");
    let e = err(StudySpec::over_model(
        "s",
        &file,
        &text,
        grid("joint.drive.pich", &[0.1]),
        vec![],
    ));
    assert!(e.contains("joint.drive.pich"), "{e}");
    let spec = StudySpec::over_model("s", &file, &text, grid("joint.drive.pitch", &[0.1]), vec![])
        .unwrap();
    assert_eq!(spec.model_file(), Some(file.as_path()));
    let model = model_for(&spec, &plans(&spec)[0]).unwrap();
    assert_eq!(model.joints[0].kind.map().released_count(), 1);
}

#[test]
fn a_function_that_gives_no_model_stops_the_study_naming_the_run() {
    let spec = StudySpec::from_fn(
        "stiffness",
        grid("EI", &[1000.0, -1.0]),
        Figure::ALL.to_vec(),
        |p| {
            let mut m = base();
            let ei = p.f64("EI")?;
            m.sections[0].values.ei = [ei, ei];
            Ok(m)
        },
    )
    .unwrap();
    let all = plans(&spec);
    let first = model_for(&spec, &all[0]).unwrap();
    assert!(first
        .source_text
        .starts_with("# study `stiffness`, run-0000 (EI = 1000"));
    assert!(first.source_text.contains("name = \"screw-driven\""));
    // The stored text is the model that ran, with the run's EI.
    assert!(
        first.text().contains("EI = [1000.0, 1000.0]"),
        "{}",
        first.text()
    );
    // EI = −1 passes the function but not the model's checks.
    let e = model_for(&spec, &all[1]).unwrap_err();
    assert!(matches!(e, SweepError::Function { .. }));
    let e = e.to_string();
    assert!(e.contains("run-0001 (EI = -1"), "{e}");
    assert!(e.contains("section[0].EI"), "{e}");
    // The study refuses before anything runs: no run directory is written.
    let dir = tempfile::tempdir().unwrap();
    let options = StudyOptions {
        out: dir.path().into(),
        shard: None,
        progress: false,
    };
    assert!(run_study(&spec, &options).is_err());
    assert!(!dir.path().join("stiffness").exists());

    // A parameter the grid does not have, or of the wrong type, is named.
    let spec = StudySpec::from_fn("s", grid("EI", &[1.0]), vec![], |p| {
        p.f64("GA")?;
        Ok(base())
    })
    .unwrap();
    let e = model_for(&spec, &plans(&spec)[0]).unwrap_err().to_string();
    assert!(e.contains("`GA`") && e.contains("the grid has EI"), "{e}");
    let spec = StudySpec::from_fn("s", grid("EI", &[1.5]), vec![], |p| {
        p.usize("EI")?;
        Ok(base())
    })
    .unwrap();
    let e = model_for(&spec, &plans(&spec)[0]).unwrap_err().to_string();
    assert!(e.contains("not a non-negative integer"), "{e}");
}

/// Every way a model built in Rust can break an index or a number is
/// refused by the build with the key, never a panic.
#[test]
fn models_built_in_rust_are_checked_before_meshing() {
    type Edit = fn(&mut Model);
    let cases: [(Edit, &str); 14] = [
        (|m| m.sections[0].values.ea = 0.0, "section[0].EA"),
        (
            |m| m.sections[0].values.rho_j[1] = f64::NAN,
            "section[0].rhoJ",
        ),
        (|m| m.beams[1].section = 7, "beam[1].section"),
        (|m| m.beams[0].elements = 0, "beam[0].elements"),
        (
            |m| m.beams[0].nodes_per_element = 4,
            "beam[0].nodes_per_element",
        ),
        (
            |m| m.supports[0].node = NodeRef { beam: 9, node: 0 },
            "support[0].node",
        ),
        (|m| m.loads[0].node.node = 99, "load[0].node"),
        (|m| m.loads[0].force[2] = f64::INFINITY, "load[0].force"),
        (
            |m| m.joints[0].slave = m.joints[0].master.unwrap(),
            "joint[0].slave",
        ),
        (
            |m| {
                m.prescribed = vec![PrescribedSpec::JointAngle {
                    joint: 3,
                    angle: TimeFunction::Constant(0.0),
                }]
            },
            "prescribed[0].joint",
        ),
        (
            |m| {
                m.prescribed = vec![PrescribedSpec::NodeDof {
                    node: NodeRef { beam: 0, node: 1 },
                    dof: 6,
                    value: TimeFunction::Table(vec![(1.0, 0.0), (0.0, 1.0)]),
                }]
            },
            "prescribed[0].dof",
        ),
        (
            |m| {
                m.prescribed = vec![PrescribedSpec::NodeDof {
                    node: NodeRef { beam: 0, node: 1 },
                    dof: 2,
                    value: TimeFunction::Table(vec![(1.0, 0.0), (0.0, 1.0)]),
                }]
            },
            "prescribed[0].value",
        ),
        (
            |m| m.solver.analysis = Analysis::Static { load_steps: 0 },
            "solver.load_steps",
        ),
        (|m| m.output.every = 0, "output.every"),
    ];
    base().check().unwrap();
    for (edit, key) in cases {
        let mut m = base();
        edit(&mut m);
        let e = flexmech::model::build(&m).unwrap_err();
        assert_eq!(e.key(), key, "{e}");
        assert!(e.to_string().contains("screw_driven.toml"), "{e}");
    }
}

/// Every shipped model file passes the typed check (it is no stricter than
/// the file checks).
#[test]
fn every_shipped_model_passes_the_typed_check() {
    let mut count = 0;
    for dir in ["benchmarks", "dynamics", "paper", "statics"] {
        for entry in std::fs::read_dir(data(dir)).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_some_and(|e| e == "toml") {
                load_model(&path).unwrap().check().unwrap();
                count += 1;
            }
        }
    }
    assert!(count >= 20, "{count}");
}
