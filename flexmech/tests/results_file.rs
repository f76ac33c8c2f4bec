// The HDF5 result writer against the result-file contract of MODEL_FORMAT.md:
// every dataset's shape and values, the root attributes, the rotation vector,
// and that a failed, dropped or killed run still leaves a readable file.
//
// Unlike the other tests this file reads with the raw `hdf5` library, not
// through `ResultReader`: its purpose is the on-disk HDF5 layout itself
// (dtypes, shapes, group attributes, a killed process's file), checked
// independently of the reader so that a mistake shared by the writer and the
// reader cannot hide. It is why `hdf5` stays a dev-dependency of flexmech.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::{Mutex, MutexGuard};

use flexmech::integrators::record::*;
use flexmech::results::*;
use hdf5::types::VarLenUnicode;

const MODEL_TEXT: &str = "# tiny test model\n[mechanism]\nname = \"ü-arm\"\n";
const N_NODES: usize = 4;

/// Serialises the tests that touch files. HDF5 opens files without
/// close-on-exec and locks them (flock), so the child process of
/// [`killed_process_leaves_the_flushed_steps`] would inherit, and keep locked,
/// a file another test happens to be writing at that moment.
fn serial() -> MutexGuard<'static, ()> {
    static SERIAL: Mutex<()> = Mutex::new(());
    SERIAL
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
}

fn tmp_path(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("results_file");
    std::fs::create_dir_all(&dir).expect("create the test directory");
    let path = dir.join(name);
    let _ = std::fs::remove_file(&path);
    path
}

fn unit(v: [f64; 3]) -> [f64; 3] {
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    [v[0] / n, v[1] / n, v[2] / n]
}

/// Quaternion (w, x, y, z) of a rotation by `angle` about the unit `axis`.
fn quat(angle: f64, axis: [f64; 3]) -> [f64; 4] {
    let (s, c) = (0.5 * angle).sin_cos();
    [c, s * axis[0], s * axis[1], s * axis[2]]
}

fn scaled(angle: f64, axis: [f64; 3]) -> [f64; 3] {
    [angle * axis[0], angle * axis[1], angle * axis[2]]
}

fn axis_a() -> [f64; 3] {
    unit([1.0, 2.0, 2.0])
}

fn axis_b() -> [f64; 3] {
    unit([0.0, 0.6, -0.8])
}

const NEAR_PI: f64 = std::f64::consts::PI - 1e-7;

/// Node 3 ("arm.end"): identity, 2 rad about a, exactly π about z.
/// Node 1 ("post.1"): the *negated* quaternion of 3 rad about b (w < 0),
/// π − 1e-7 about b, 1e-9 rad about a (series branch).
fn quaternion(step: usize, node: usize) -> [f64; 4] {
    match (node, step) {
        (3, 0) => [1.0, 0.0, 0.0, 0.0],
        (3, 1) => quat(2.0, axis_a()),
        (3, _) => [0.0, 0.0, 0.0, 1.0],
        (1, 0) => quat(3.0, axis_b()).map(|c| -c),
        (1, 1) => quat(NEAR_PI, axis_b()),
        (1, _) => quat(1e-9, axis_a()),
        _ => quat(0.1 * (step + node) as f64, [0.0, 0.0, 1.0]),
    }
}

fn expected_rotation(step: usize, node: usize) -> [f64; 3] {
    match (node, step) {
        (3, 0) => [0.0; 3],
        (3, 1) => scaled(2.0, axis_a()),
        (3, _) => [0.0, 0.0, std::f64::consts::PI],
        (1, 0) => scaled(3.0, axis_b()),
        (1, 1) => scaled(NEAR_PI, axis_b()),
        (1, _) => scaled(1e-9, axis_a()),
        _ => unreachable!("untracked node"),
    }
}

fn initial(node: usize) -> [f64; 3] {
    let i = node as f64;
    [i, 2.0 * i, 0.0]
}

fn position(step: usize, node: usize) -> [f64; 3] {
    let (k, i) = (step as f64, node as f64);
    [i + 0.1 * k, 2.0 * i - 0.5 * k, 0.25 * k * i]
}

fn beta(step: usize) -> f64 {
    if step == 1 {
        0.5
    } else {
        f64::NAN
    }
}

fn history(step: usize) -> Vec<f64> {
    (0..step + 2)
        .map(|j| 10f64.powi(-(3 * j as i32)) * (step + 1) as f64)
        .collect()
}

fn record(step: usize) -> StepRecord {
    let k = step as f64;
    StepRecord {
        time: 0.1 * (k + 1.0),
        dt: 0.01 / (k + 1.0),
        iterations: 3 + step,
        factorizations: 1 + step,
        residual: 1e-10 * (k + 1.0),
        residual_history: history(step),
        beta: beta(step),
        energy: Energies {
            kinetic: 1.0 + k,
            strain: 10.0 + k,
            potential: -k,
            total: 11.0 + k,
            driver_work: 0.25 * k,
            dissipated: 0.0,
        },
        momentum_linear: [k, 2.0 * k, 3.0 * k],
        momentum_angular: [-k, 0.5, k * k],
        positions: (0..N_NODES).map(|i| position(step, i)).collect(),
        quaternions: (0..N_NODES).map(|i| quaternion(step, i)).collect(),
        joints: vec![JointRecord {
            angle: 0.1 * k,
            released_translation: [k, 0.0, -k],
            constraint_error: 1e-12 * k,
            reaction: [k, -k, 0.5 * k, 1.0, 2.0, 3.0],
        }],
        support_reactions: vec![],
        negative_pivots: None,
        velocities: (0..N_NODES).map(|i| velocity(step, i, 1.0)).collect(),
        angular_velocities: (0..N_NODES).map(|i| velocity(step, i, -2.0)).collect(),
        sensitivities: Vec::new(),
        critical: None,
    }
}

/// A made-up velocity of node `node` at `step`, distinct per node, step and `kind`.
fn velocity(step: usize, node: usize, kind: f64) -> [f64; 3] {
    let (k, n) = (step as f64, node as f64);
    [kind * (k + 0.5), n - k, kind * n * 0.25 + k]
}

fn meta() -> RunMeta {
    RunMeta {
        model_text: MODEL_TEXT.to_owned(),
        integrator: "energy-momentum".to_owned(),
        initial_positions: (0..N_NODES).map(initial).collect(),
        tracked: vec![("arm.end".to_owned(), 3), ("post.1".to_owned(), 1)],
        joint_names: vec!["hinge.a".to_owned()],
        ..Default::default()
    }
}

fn write_steps(path: &Path, steps: usize) -> ResultWriter {
    let mut writer = ResultWriter::create(path, &meta()).expect("create the writer");
    for k in 0..steps {
        writer.append(&record(k)).expect("append a step");
        assert_eq!(writer.steps_written(), k + 1);
    }
    writer
}

fn dataset(file: &hdf5::File, name: &str) -> hdf5::Dataset {
    file.dataset(name)
        .unwrap_or_else(|e| panic!("dataset {name}: {e}"))
}

fn read_f64(file: &hdf5::File, name: &str) -> (Vec<usize>, Vec<f64>) {
    let ds = dataset(file, name);
    let data = ds
        .read_raw::<f64>()
        .unwrap_or_else(|e| panic!("read {name}: {e}"));
    (ds.shape(), data)
}

fn read_u64(file: &hdf5::File, name: &str) -> (Vec<usize>, Vec<u64>) {
    let ds = dataset(file, name);
    let data = ds
        .read_raw::<u64>()
        .unwrap_or_else(|e| panic!("read {name}: {e}"));
    (ds.shape(), data)
}

fn str_attr(loc: &hdf5::Location, name: &str) -> String {
    let attr = loc
        .attr(name)
        .unwrap_or_else(|e| panic!("attribute {name}: {e}"));
    let value: VarLenUnicode = attr
        .read_scalar()
        .unwrap_or_else(|e| panic!("read {name}: {e}"));
    value.as_str().to_owned()
}

/// Bit-exact equality, except that NaN equals NaN.
fn assert_same(name: &str, got: &[f64], want: &[f64]) {
    assert_eq!(got.len(), want.len(), "{name}: length");
    for (i, (g, w)) in got.iter().zip(want).enumerate() {
        assert!(
            g == w || (g.is_nan() && w.is_nan()),
            "{name}[{i}]: got {g}, want {w}"
        );
    }
}

fn assert_close(name: &str, got: &[f64], want: &[f64], tol: f64) {
    assert_eq!(got.len(), want.len(), "{name}: length");
    for (i, (g, w)) in got.iter().zip(want).enumerate() {
        assert!((g - w).abs() <= tol, "{name}[{i}]: got {g:e}, want {w:e}");
    }
}

/// Reads one field of a step record.
type Getter<T> = fn(&StepRecord) -> T;

/// Breaks a valid [`RunMeta`].
type MetaEdit = fn(&mut RunMeta);

/// Checks the series of a file holding steps `0..t` of [`record`].
fn check_series(file: &hdf5::File, t: usize) {
    let steps: Vec<StepRecord> = (0..t).map(record).collect();
    let scalars: [(&str, Getter<f64>); 9] = [
        (layout::TIME, |s| s.time),
        (layout::ENERGY_KINETIC, |s| s.energy.kinetic),
        (layout::ENERGY_STRAIN, |s| s.energy.strain),
        (layout::ENERGY_POTENTIAL, |s| s.energy.potential),
        (layout::ENERGY_TOTAL, |s| s.energy.total),
        (layout::ENERGY_DRIVER_WORK, |s| s.energy.driver_work),
        (layout::SOLVER_DT, |s| s.dt),
        (layout::SOLVER_RESIDUAL, |s| s.residual),
        (layout::SOLVER_BETA, |s| s.beta),
    ];
    for (name, get) in scalars {
        let (shape, data) = read_f64(file, name);
        assert_eq!(shape, [t], "{name}");
        assert_same(name, &data, &steps.iter().map(get).collect::<Vec<_>>());
    }
    let rows: [(&str, Getter<[f64; 3]>); 2] = [
        (layout::MOMENTUM_LINEAR, |s| s.momentum_linear),
        (layout::MOMENTUM_ANGULAR, |s| s.momentum_angular),
    ];
    for (name, get) in rows {
        let (shape, data) = read_f64(file, name);
        assert_eq!(shape, [t, 3], "{name}");
        assert_same(name, &data, &steps.iter().flat_map(get).collect::<Vec<_>>());
    }

    let (shape, iterations) = read_u64(file, layout::SOLVER_ITERATIONS);
    assert_eq!(shape, [t]);
    assert_eq!(
        iterations,
        steps
            .iter()
            .map(|s| s.iterations as u64)
            .collect::<Vec<_>>()
    );

    let (shape, offsets) = read_u64(file, layout::SOLVER_NEWTON_OFFSETS);
    assert_eq!(shape, [t + 1]);
    let mut want_offsets = vec![0_u64];
    for s in &steps {
        want_offsets.push(want_offsets[want_offsets.len() - 1] + s.residual_history.len() as u64);
    }
    assert_eq!(offsets, want_offsets);
    let (shape, residuals) = read_f64(file, layout::SOLVER_NEWTON_RESIDUALS);
    assert_eq!(shape, [want_offsets[t] as usize]);
    for (k, s) in steps.iter().enumerate() {
        let slice = &residuals[offsets[k] as usize..offsets[k + 1] as usize];
        assert_same("newton_residuals", slice, &s.residual_history);
    }

    for (label, node) in [("arm.end", 3), ("post.1", 1)] {
        let name = layout::node_path(label, layout::NODE_POSITION);
        let (shape, data) = read_f64(file, &name);
        assert_eq!(shape, [t, 3], "{name}");
        assert_same(
            &name,
            &data,
            &(0..t).flat_map(|k| position(k, node)).collect::<Vec<_>>(),
        );

        let name = layout::node_path(label, layout::NODE_DISPLACEMENT);
        let (shape, data) = read_f64(file, &name);
        assert_eq!(shape, [t, 3], "{name}");
        let want: Vec<f64> = (0..t)
            .flat_map(|k| {
                let (p, p0) = (position(k, node), initial(node));
                [p[0] - p0[0], p[1] - p0[1], p[2] - p0[2]]
            })
            .collect();
        assert_same(&name, &data, &want);
        // Independently of the formula: known values.
        for k in 0..t {
            let (kf, i) = (k as f64, node as f64);
            assert_close(
                &name,
                &data[3 * k..3 * k + 3],
                &[0.1 * kf, -0.5 * kf, 0.25 * kf * i],
                1e-15,
            );
        }

        let name = layout::node_path(label, layout::NODE_ROTATION);
        let (shape, data) = read_f64(file, &name);
        assert_eq!(shape, [t, 3], "{name}");
        for k in 0..t {
            let row = &data[3 * k..3 * k + 3];
            assert_close(&name, row, &expected_rotation(k, node), 1e-12);
            let norm = row.iter().map(|c| c * c).sum::<f64>().sqrt();
            assert!(
                norm <= std::f64::consts::PI + 1e-15,
                "{name}[{k}]: |psi| = {norm}"
            );
        }
        let group = file.group(&layout::node_group(label)).expect("node group");
        let index: u64 = group
            .attr(layout::ATTR_NODE_INDEX)
            .unwrap()
            .read_scalar()
            .unwrap();
        assert_eq!(index, node as u64);
    }

    let joint = |leaf| layout::joint_path("hinge.a", leaf);
    let (shape, data) = read_f64(file, &joint(layout::JOINT_ANGLE));
    assert_eq!(shape, [t]);
    assert_same(
        "angle",
        &data,
        &steps.iter().map(|s| s.joints[0].angle).collect::<Vec<_>>(),
    );
    let (shape, data) = read_f64(file, &joint(layout::JOINT_RELEASED_TRANSLATION));
    assert_eq!(shape, [t, 3]);
    let want: Vec<f64> = steps
        .iter()
        .flat_map(|s| s.joints[0].released_translation)
        .collect();
    assert_same("released_translation", &data, &want);
    let (shape, data) = read_f64(file, &joint(layout::JOINT_CONSTRAINT_ERROR));
    assert_eq!(shape, [t]);
    let want: Vec<f64> = steps.iter().map(|s| s.joints[0].constraint_error).collect();
    assert_same("constraint_error", &data, &want);

    let (shape, data) = read_f64(file, layout::CONFIGURATION_POSITION);
    assert_eq!(shape, [t, N_NODES, 3]);
    let want: Vec<f64> = steps
        .iter()
        .flat_map(|s| s.positions.iter().flatten().copied())
        .collect();
    assert_same("configuration/position", &data, &want);
    let (shape, data) = read_f64(file, layout::CONFIGURATION_QUATERNION);
    assert_eq!(shape, [t, N_NODES, 4]);
    let want: Vec<f64> = steps
        .iter()
        .flat_map(|s| s.quaternions.iter().flatten().copied())
        .collect();
    assert_same("configuration/quaternion", &data, &want);
    for (name, field) in [
        (layout::CONFIGURATION_VELOCITY, 0),
        (layout::CONFIGURATION_ANGULAR_VELOCITY, 1),
    ] {
        let (shape, data) = read_f64(file, name);
        assert_eq!(shape, [t, N_NODES, 3]);
        let want: Vec<f64> = steps
            .iter()
            .flat_map(|s| {
                let v = if field == 0 {
                    &s.velocities
                } else {
                    &s.angular_velocities
                };
                v.iter().flatten().copied().collect::<Vec<_>>()
            })
            .collect();
        assert_same(name, &data, &want);
    }
}

#[test]
fn completed_run_matches_the_contract() {
    let _serial = serial();
    let path = tmp_path("completed.h5");
    let writer = write_steps(&path, 3);
    let returned = writer
        .finish(layout::STATUS_COMPLETED, 12.5)
        .expect("finish");
    assert_eq!(returned, path);

    let file = hdf5::File::open(&path).expect("reopen");
    check_series(&file, 3);

    assert_eq!(str_attr(&file, "status"), "completed");
    assert_eq!(str_attr(&file, "integrator"), "energy-momentum");
    assert_eq!(str_attr(&file, "model"), MODEL_TEXT);
    assert_eq!(str_attr(&file, "version"), env!("CARGO_PKG_VERSION"));
    let wall: f64 = file.attr("wall_time_s").unwrap().read_scalar().unwrap();
    assert_eq!(wall, 12.5);

    // NaN β survives (steps 0 and 2), the finite one too.
    let (_, beta) = read_f64(&file, "/solver/beta");
    assert!(beta[0].is_nan() && beta[2].is_nan());
    assert_eq!(beta[1], 0.5);

    // Extendable, chunked, described.
    let time = dataset(&file, "/time");
    assert!(time.is_resizable() && time.is_chunked());
    assert_eq!(time.chunk(), Some(vec![256]));
    assert_eq!(
        dataset(&file, layout::CONFIGURATION_POSITION).chunk(),
        Some(vec![16, N_NODES, 3])
    );
    assert!(!str_attr(&dataset(&file, "/energy/total"), "description").is_empty());
    assert!(!str_attr(&dataset(&file, "/nodes/arm.end/rotation"), "description").is_empty());
}

#[test]
fn contract_names_are_literal() {
    // The constants are the contract; a rename would break readers.
    let expected = [
        (layout::TIME, "/time"),
        (layout::ENERGY_KINETIC, "/energy/kinetic"),
        (layout::ENERGY_STRAIN, "/energy/strain"),
        (layout::ENERGY_POTENTIAL, "/energy/potential"),
        (layout::ENERGY_TOTAL, "/energy/total"),
        (layout::MOMENTUM_LINEAR, "/momentum/linear"),
        (layout::MOMENTUM_ANGULAR, "/momentum/angular"),
        (layout::SOLVER_ITERATIONS, "/solver/iterations"),
        (layout::SOLVER_DT, "/solver/dt"),
        (layout::SOLVER_RESIDUAL, "/solver/residual"),
        (layout::SOLVER_BETA, "/solver/beta"),
        (layout::CONFIGURATION_POSITION, "/configuration/position"),
        (
            layout::CONFIGURATION_QUATERNION,
            "/configuration/quaternion",
        ),
        (layout::CONFIGURATION_VELOCITY, "/configuration/velocity"),
        (
            layout::CONFIGURATION_ANGULAR_VELOCITY,
            "/configuration/angular_velocity",
        ),
    ];
    for (constant, literal) in expected {
        assert_eq!(constant, literal);
    }
    assert_eq!(
        layout::node_path("arm.end", layout::NODE_DISPLACEMENT),
        "/nodes/arm.end/displacement"
    );
    assert_eq!(
        layout::joint_path("j", layout::JOINT_RELEASED_TRANSLATION),
        "/joints/j/released_translation"
    );
    assert_eq!(layout::failed_status("x"), "failed: x");
}

#[test]
fn failed_run_keeps_its_steps_and_status() {
    let _serial = serial();
    let path = tmp_path("failed.h5");
    let writer = write_steps(&path, 2);
    let status = "failed: no convergence at t = 0.3";
    writer.finish(status, 0.75).expect("finish");

    let file = hdf5::File::open(&path).expect("reopen");
    check_series(&file, 2);
    assert_eq!(str_attr(&file, "status"), status);
    let wall: f64 = file.attr("wall_time_s").unwrap().read_scalar().unwrap();
    assert_eq!(wall, 0.75);
}

#[test]
fn dropped_writer_leaves_a_readable_running_file() {
    let _serial = serial();
    let path = tmp_path("dropped.h5");
    let mut writer = write_steps(&path, 2);
    writer.flush().expect("write the held steps");
    drop(writer);

    let file = hdf5::File::open(&path).expect("reopen");
    check_series(&file, 2);
    assert_eq!(str_attr(&file, "status"), "running");
    assert!(
        file.attr("wall_time_s").is_err(),
        "wall time is written by finish only"
    );
}

const CHILD_ENV: &str = "FLEXMECH_RESULTS_TEST_CHILD_PATH";
const CHILD_READY: &str = "flexmech-results-child-ready";

/// Helper for [`killed_process_leaves_the_flushed_steps`]: does nothing in a
/// normal run. In the child process it appends two steps, reports, and waits
/// to be killed (no destructor, no library shutdown runs).
#[test]
fn child_appends_then_waits_to_be_killed() {
    let Some(path) = std::env::var_os(CHILD_ENV) else {
        return;
    };
    let mut writer = write_steps(Path::new(&path), 2);
    writer.flush().expect("write the held steps");
    println!("{CHILD_READY}");
    std::thread::sleep(std::time::Duration::from_secs(120));
    drop(writer);
}

/// The harness's name of [`child_appends_then_waits_to_be_killed`]: its
/// module path within the test binary, then its own name.
fn child_test_name() -> String {
    let module = module_path!().split_once("::").map_or("", |(_, m)| m);
    format!("{module}::child_appends_then_waits_to_be_killed")
}

#[test]
fn killed_process_leaves_the_flushed_steps() {
    let _serial = serial();
    let path = tmp_path("killed.h5");
    let exe = std::env::current_exe().expect("test executable");
    let mut child = Command::new(exe)
        .args(["--exact", &child_test_name(), "--nocapture"])
        .args(["--test-threads=1"])
        .env(CHILD_ENV, &path)
        .stdout(Stdio::piped())
        .spawn()
        .expect("spawn the child test process");
    let stdout = child.stdout.take().expect("child stdout");
    let ready = BufReader::new(stdout)
        .lines()
        .map_while(Result::ok)
        .any(|line| line.contains(CHILD_READY));
    child.kill().expect("kill the child");
    let _ = child.wait();
    assert!(ready, "the child did not report its steps");

    let file = hdf5::File::open(&path).expect("reopen the file of the killed process");
    check_series(&file, 2);
    assert_eq!(str_attr(&file, "status"), "running");
}

#[test]
fn steps_written_in_several_batches_make_the_same_file() {
    // Appends are held and written in batches; writes at uneven points
    // (one step, none, five, the rest at finish) must give every row and
    // the Newton history's offsets across the batches.
    let _serial = serial();
    let path = tmp_path("batches.h5");
    let mut writer = ResultWriter::create(&path, &meta()).expect("create the writer");
    for k in 0..9 {
        writer.append(&record(k)).expect("append a step");
        if matches!(k, 0 | 5) {
            writer.flush().expect("write the held steps");
            writer.flush().expect("an empty write");
        }
    }
    assert_eq!(writer.steps_written(), 9);
    writer
        .finish(layout::STATUS_COMPLETED, 1.0)
        .expect("finish");
    let file = hdf5::File::open(&path).expect("reopen");
    check_series(&file, 9);
}

#[test]
fn mismatched_records_are_errors_and_write_nothing() {
    let _serial = serial();
    let path = tmp_path("mismatch.h5");
    let mut writer = ResultWriter::create(&path, &meta()).expect("create");

    let mut short = record(0);
    short.positions.pop();
    match writer.append(&short) {
        Err(ResultError::RecordLength {
            field: "positions",
            expected: 4,
            found: 3,
            step: 0,
            ..
        }) => {}
        other => panic!("expected a positions length error, got {other:?}"),
    }
    let mut no_joints = record(0);
    no_joints.joints.clear();
    let err = writer.append(&no_joints).expect_err("joint count mismatch");
    assert!(matches!(
        err,
        ResultError::RecordLength {
            field: "joints",
            expected: 1,
            found: 0,
            ..
        }
    ));
    assert!(
        err.to_string().contains("mismatch.h5"),
        "message names the file: {err}"
    );
    let mut extra_quaternion = record(0);
    extra_quaternion.quaternions.push([1.0, 0.0, 0.0, 0.0]);
    let err = writer
        .append(&extra_quaternion)
        .expect_err("quaternion count mismatch");
    assert!(matches!(
        err,
        ResultError::RecordLength {
            field: "quaternions",
            found: 5,
            ..
        }
    ));
    assert_eq!(writer.steps_written(), 0);

    // The writer stays usable and the rejected records left no trace.
    writer
        .append(&record(0))
        .expect("a good record after bad ones");
    assert_eq!(writer.steps_written(), 1);
    writer.finish("completed", 0.0).expect("finish");
    let file = hdf5::File::open(&path).expect("reopen");
    check_series(&file, 1);
}

#[test]
fn invalid_meta_is_rejected_before_touching_the_file() {
    let _serial = serial();
    let path = tmp_path("invalid-meta.h5");
    let cases: [(MetaEdit, &str); 5] = [
        (|m| m.tracked[0].0 = "arm/end".into(), "node label"),
        (|m| m.tracked[1].0 = String::new(), "node label"),
        (|m| m.tracked[1].0 = "arm.end".into(), "node label"),
        (|m| m.joint_names.push("hinge.a".into()), "joint"),
        (|m| m.joint_names[0] = ".".into(), "joint"),
    ];
    for (edit, want_kind) in cases {
        let mut m = meta();
        edit(&mut m);
        match ResultWriter::create(&path, &m) {
            Err(ResultError::InvalidName { kind, .. }) => assert_eq!(kind, want_kind),
            other => panic!("expected InvalidName, got {other:?}"),
        }
    }
    let mut m = meta();
    m.tracked.push(("ghost".into(), N_NODES));
    match ResultWriter::create(&path, &m) {
        Err(ResultError::NodeIndex { index, nodes, .. }) => {
            assert_eq!((index, nodes), (N_NODES, N_NODES))
        }
        other => panic!("expected NodeIndex, got {other:?}"),
    }
    assert!(!path.exists(), "no file for a rejected meta");
}

#[test]
fn unwritable_path_is_an_hdf5_error_with_context() {
    let _serial = serial();
    let path = tmp_path("no-such-dir").join("run.h5");
    let err = ResultWriter::create(&path, &meta()).expect_err("missing directory");
    assert!(matches!(err, ResultError::Hdf5 { .. }), "{err:?}");
    assert!(err.to_string().contains("creating the file"), "{err}");
}

#[test]
fn rotation_vector_known_values_and_round_trip() {
    let pi = std::f64::consts::PI;
    assert_eq!(rotation_vector([1.0, 0.0, 0.0, 0.0]), [0.0; 3]);
    assert_eq!(rotation_vector([-1.0, 0.0, 0.0, 0.0]), [0.0; 3]);
    assert_close(
        "2 rad",
        &rotation_vector(quat(2.0, axis_a())),
        &scaled(2.0, axis_a()),
        1e-14,
    );
    assert_close(
        "pi",
        &rotation_vector([0.0, 1.0, 0.0, 0.0]),
        &[pi, 0.0, 0.0],
        1e-15,
    );
    // Rotations beyond π come back as the equivalent one below π.
    let beyond = rotation_vector(quat(pi + 0.5, axis_b()));
    assert_close("beyond pi", &beyond, &scaled(-(pi - 0.5), axis_b()), 1e-13);
    // Not normalised: the same rotation.
    let q = quat(1.2, axis_a()).map(|c| 3.0 * c);
    assert_close(
        "scaled q",
        &rotation_vector(q),
        &scaled(1.2, axis_a()),
        1e-14,
    );
    // Degenerate input gives NaN, not a panic.
    assert!(rotation_vector([0.0; 4]).iter().all(|c| c.is_nan()));
    assert!(rotation_vector([f64::NAN, 0.0, 0.0, 1.0])
        .iter()
        .all(|c| c.is_nan()));

    // Round trip over a spread of angles (including the series branch) and axes.
    let mut seed = 0x2545_f491_4f6c_dd1d_u64;
    let mut next = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    for j in 0..2000 {
        let angle = match j % 4 {
            0 => next() * 1e-5,
            1 => pi - next() * 1e-6,
            _ => next() * pi,
        };
        let axis = unit([next() - 0.5, next() - 0.5, next() - 0.5]);
        let sign = if j % 3 == 0 { -1.0 } else { 1.0 };
        let psi = rotation_vector(quat(angle, axis).map(|c| sign * c));
        assert_close(
            "round trip",
            &psi,
            &scaled(angle, axis),
            4e-15 * (1.0 + angle),
        );
    }
}

#[test]
fn h5dump_lists_the_contract_names() {
    let _serial = serial();
    let path = tmp_path("h5dump.h5");
    write_steps(&path, 2)
        .finish("completed", 1.0)
        .expect("finish");
    let output = match Command::new("h5dump").arg("-H").arg(&path).output() {
        Ok(output) => output,
        Err(e) => {
            println!("note: h5dump not available ({e}); skipping the h5dump check");
            return;
        }
    };
    assert!(
        output.status.success(),
        "h5dump failed: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    let header = String::from_utf8_lossy(&output.stdout);
    let names = [
        "DATASET \"time\"",
        "GROUP \"energy\"",
        "DATASET \"kinetic\"",
        "DATASET \"strain\"",
        "DATASET \"potential\"",
        "DATASET \"total\"",
        "GROUP \"momentum\"",
        "DATASET \"linear\"",
        "DATASET \"angular\"",
        "GROUP \"solver\"",
        "DATASET \"iterations\"",
        "DATASET \"dt\"",
        "DATASET \"residual\"",
        "DATASET \"beta\"",
        "DATASET \"newton_residuals\"",
        "DATASET \"newton_offsets\"",
        "GROUP \"nodes\"",
        "GROUP \"arm.end\"",
        "GROUP \"post.1\"",
        "DATASET \"position\"",
        "DATASET \"displacement\"",
        "DATASET \"rotation\"",
        "GROUP \"joints\"",
        "GROUP \"hinge.a\"",
        "DATASET \"angle\"",
        "DATASET \"released_translation\"",
        "DATASET \"constraint_error\"",
        "GROUP \"configuration\"",
        "DATASET \"quaternion\"",
        "ATTRIBUTE \"model\"",
        "ATTRIBUTE \"integrator\"",
        "ATTRIBUTE \"version\"",
        "ATTRIBUTE \"status\"",
        "ATTRIBUTE \"wall_time_s\"",
        "( 2, 4, 3 ) / ( H5S_UNLIMITED, 4, 3 )",
    ];
    for name in names {
        assert!(header.contains(name), "h5dump -H lacks {name}:\n{header}");
    }
}

#[test]
fn a_second_writer_of_the_same_file_is_refused_and_the_first_result_survives() {
    // Two processes writing one result file: the second once truncated the
    // file before failing, and the first reported "completed" over an
    // unreadable file. The second now fails before touching it.
    let _serial = serial();
    let path = tmp_path("locked.h5");
    let first = write_steps(&path, 2);
    match ResultWriter::create(&path, &meta()) {
        Err(e @ ResultError::Busy { .. }) => {
            let m = e.to_string();
            assert!(
                m.contains("another process is writing") && m.contains("locked.h5"),
                "{m}"
            );
        }
        other => panic!("expected Busy, got {other:?}"),
    }
    first.finish(layout::STATUS_COMPLETED, 1.0).expect("finish");
    let file = hdf5::File::open(&path).expect("the first result is intact");
    check_series(&file, 2);
    assert_eq!(str_attr(&file, "status"), "completed");
    drop(file);
    // Finished: the lock is gone, and the file can be written again.
    let mut lock = path.as_os_str().to_owned();
    lock.push(".lock");
    assert!(!std::path::Path::new(&lock).exists());
    let again = ResultWriter::create(&path, &meta()).expect("free again");
    again.finish(layout::STATUS_COMPLETED, 1.0).expect("finish");
}

#[test]
fn held_steps_fall_due_after_a_second_and_are_written_by_the_next_append() {
    // The writer asks for a restart state only when its held steps are due
    // (the file last written a second ago): a dynamic run builds it only
    // then. Without one, the next append writes the held steps first.
    let _serial = serial();
    let path = tmp_path("due.h5");
    let mut writer = ResultWriter::create(&path, &meta()).expect("create the writer");
    writer.append(&record(0)).expect("append a step");
    assert!(!writer.wants_checkpoint(), "a step just held is not due");
    std::thread::sleep(std::time::Duration::from_millis(1100));
    writer.append(&record(1)).expect("append a step");
    assert!(writer.wants_checkpoint(), "held for more than a second");
    writer.append(&record(2)).expect("append a step");
    // Written: the file's clock restarted, so the new step is not due.
    assert!(!writer.wants_checkpoint(), "the due steps written first");
    writer
        .finish(layout::STATUS_COMPLETED, 1.0)
        .expect("finish");
    let file = hdf5::File::open(&path).expect("reopen");
    check_series(&file, 3);
}
