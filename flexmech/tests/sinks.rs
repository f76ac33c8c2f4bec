//! A run's sink: memory, a closure or the result file see the same run —
//! the same kept steps, bit for bit, and the same status.

use flexmech::prelude::*;

use crate::common::data;

/// The paper's cam example, 0.2 s of it.
fn short_cam() -> Model {
    let text = std::fs::read_to_string(data("paper/cam.toml"))
        .unwrap()
        .replace("t_end = 3.0", "t_end = 0.2");
    parse_model(&text, &data("paper/cam.toml")).unwrap()
}

#[test]
fn memory_closure_and_file_sinks_see_the_same_steps() {
    let model = short_cam();
    let mut memory = Memory::default();
    let summary = run(&model, &mut memory).unwrap();
    assert_eq!(memory.status(), "completed");
    assert_eq!(summary.file, Path::new(""));
    assert_eq!(memory.records.len(), summary.written);
    assert!(memory.checkpoint.is_some(), "a dynamic run's restart state");

    let mut times = Vec::new();
    run(
        &model,
        &mut OnStep(|r: &flexmech::integrators::StepRecord| times.push(r.time)),
    )
    .unwrap();
    assert_eq!(times, memory.time());

    let out = tempfile::tempdir().unwrap();
    let file = run_model(&model, out.path()).unwrap().file;
    let reader = ResultReader::open(&file).unwrap();
    assert_eq!(reader.time().unwrap(), memory.time());
    for (label, _) in &memory.meta.tracked {
        let stored = reader.rows3(&format!("/nodes/{label}/position")).unwrap();
        assert_eq!(stored, memory.positions(label).unwrap(), "{label}");
    }
}

#[test]
fn a_failed_run_leaves_its_steps_and_status_in_memory() {
    // A load far past the arm's strength in one step: Newton fails, the
    // memory holds the initial state and the failure.
    let text = std::fs::read_to_string(data("paper/screw_driven.toml"))
        .unwrap()
        .replace("max_halvings = 8", "max_halvings = 0")
        .replace("max_iterations = 30", "max_iterations = 1");
    let model = parse_model(&text, &data("paper/screw_driven.toml")).unwrap();
    let mut memory = Memory::default();
    match run(&model, &mut memory) {
        Err(RunError::Solve { file, .. }) => assert_eq!(file, Path::new("")),
        other => panic!("expected a failed solve, got {other:?}"),
    }
    assert!(
        memory.status().starts_with("failed: "),
        "{}",
        memory.status()
    );
    assert!(!memory.records.is_empty());
}

#[test]
fn a_file_read_whole_holds_what_the_reader_reads() {
    use flexmech::results::{read_contents, Values};
    let model = load_model(&data("paper/screw_driven.toml")).unwrap();
    let mut short = model.clone();
    if let flexmech::model::Analysis::Dynamic { t_end, .. } = &mut short.solver.analysis {
        *t_end = 0.1;
    }
    let out = tempfile::tempdir().unwrap();
    let file = run_model(&short, out.path()).unwrap().file;
    let reader = ResultReader::open(&file).unwrap();
    let contents = read_contents(&file).unwrap();
    let names: Vec<&str> = contents.datasets.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names.len(), reader.dataset_names().len());
    for (name, array) in &contents.datasets {
        if let Values::Float(v) = &array.values {
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(v), bits(&reader.values(name).unwrap()), "{name}");
            assert_eq!(array.shape, reader.shape(name).unwrap(), "{name}");
        }
    }
    let root = &contents.attrs.iter().find(|(p, _)| p == "/").unwrap().1;
    let status = root.iter().find(|(k, _)| k == "status").unwrap();
    assert_eq!(status.1.values, Values::Text(vec!["completed".into()]));
    assert!(read_contents(Path::new("no/such.h5"))
        .unwrap_err()
        .to_string()
        .contains("no/such.h5"));
}

/// A memory sink that takes the restart state only when asked for at every
/// third kept step, as the result file takes it only at its writes.
struct EveryThird {
    memory: Memory,
    /// The kept steps' indices after which a restart state came.
    saved_after: Vec<usize>,
}

impl Sink for EveryThird {
    fn begin(
        &mut self,
        meta: &flexmech::results::RunMeta,
    ) -> Result<(), flexmech::results::SinkError> {
        self.memory.begin(meta)
    }

    fn step(
        &mut self,
        record: &flexmech::integrators::StepRecord,
    ) -> Result<(), flexmech::results::SinkError> {
        self.memory.step(record)
    }

    fn checkpoint(
        &mut self,
        state: &flexmech::integrators::dynamics::Checkpoint,
    ) -> Result<(), flexmech::results::SinkError> {
        self.saved_after.push(self.memory.records.len() - 1);
        self.memory.checkpoint(state)
    }

    fn wants_checkpoint(&self) -> bool {
        self.memory.records.len().is_multiple_of(3)
    }

    fn finish(
        &mut self,
        end: &flexmech::results::RunEnd,
    ) -> Result<(), flexmech::results::SinkError> {
        self.memory.finish(end)
    }
}

#[test]
fn the_restart_state_is_built_when_the_sink_wants_it_and_at_the_end() {
    let model = short_cam();
    let mut sink = EveryThird {
        memory: Memory::default(),
        saved_after: Vec::new(),
    };
    run(&model, &mut sink).unwrap();
    let kept = sink.memory.records.len();
    assert!(kept > 6, "{kept} kept steps");
    let mut expected: Vec<usize> = (2..kept).step_by(3).collect();
    if expected.last() != Some(&(kept - 1)) {
        expected.push(kept - 1);
    }
    assert_eq!(sink.saved_after, expected);
    let last = sink.memory.checkpoint.as_ref().unwrap();
    assert_eq!(
        last.time,
        sink.memory.records[kept - 1].time,
        "the state at the last step"
    );
}
