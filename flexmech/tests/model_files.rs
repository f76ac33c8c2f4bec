//! Model-file loader: good files parse to the right values, bad files give
//! errors that name the key, the line and the problem.

use std::path::Path;

use flexmech::joints::{
    Cam, Cylindrical, Lift, Lobe, Prismatic, RackPinion, Revolute, Rigid, Screw, Spherical,
};
use flexmech::model::*;

/// A full model in the style of MODEL_FORMAT.md (with the `arm` beam it refers to).
const FULL: &str = r#"name = "screw-free"                  # required; the result file is <name>.h5

gravity = [0.0, 0.0, -9.81]

[[section]]
name = "steel-tube"
EA = 2.0e6
GA = [8.0e5, 8.0e5]
GJ = 1.0e3
EI = [1.5e3, 1.5e3]
rhoA = 1.0
rhoJ = [0.02, 0.01, 0.01]

[[section]]
name = "light"
EA = 1000
GA = [500, 500]
GJ = 10
EI = [20, 30]
rhoA = 0.5

[[beam]]
name = "post"
section = "steel-tube"
start = [0.0, 0.0, 0.0]
end = [0.0, 0.0, 10.0]
elements = 4
nodes_per_element = 2
e2 = [2.0, 0.0, 0.0]

[[beam]]
name = "arm"
section = "light"
start = [0.0, 0.0, 10.0]
end = [5.0, 0.0, 10.0]
elements = 3
nodes_per_element = 3
e2 = [0.0, 1.0, 0.0]

[[beam]]
name = "bend"
section = "steel-tube"
arc = { start = [0.0, 0.0, 0.0], center = [100.0, 0.0, 0.0], normal = [0.0, 0.0, -1.0], sweep = 0.7853981634 }
elements = 8

[[support]]
node = "post.start"
fixed = "all"

[[support]]
node = "bend.0"
fixed = ["ux", "uy", "rz"]

[[joint]]
name = "screw"
type = "screw"
master = "post.end"
slave = "arm.start"
axis = [0.0, 0.0, 2.0]
pitch = 0.1
angle = 0.25
rate = 0.0

[[joint]]
name = "weld"
type = "rigid"
master = "arm.end"
slave = "bend.end"

[[load]]
node = "arm.end"
force = [0.0, 0.0, -1.0]
time = { table = [[0.0, 0.0], [1.0, 1.0]] }

[[load]]
node = "arm.3"
moment = [0.0, 1.0, 0.0]

[[prescribed]]
joint = "screw"
angle = { table = [[0.0, 0.25], [2.0, 6.2832]] }

[[prescribed]]
node = "bend.2"
dof = "rz"
value = 0.5

[[initial_velocity]]
nodes = "arm"
linear = [1.0, 0.0, 0.0]
angular = [0.0, 0.0, 2.0]
origin = [0.0, 0.0, 0.0]

[[initial_velocity]]
nodes = ["post.end", "post.2"]
angular = [0.0, 0.0, 1.0]

[solver]
analysis = "dynamic"
integrator = "energy-momentum"
dt = 0.02
t_end = 5.0
tolerance = 1e-10
max_iterations = 25
max_halvings = 10
mass = "consistent"

[output]
every = 2
track = ["post.end", "arm.end", "arm.2"]
"#;

/// A small valid file that the bad inputs below modify.
const BASE: &str = r#"name = "base"

[[section]]
name = "s"
EA = 1.0
GA = [1.0, 1.0]
GJ = 1.0
EI = [1.0, 1.0]

[[beam]]
name = "a"
section = "s"
start = [0.0, 0.0, 0.0]
end = [1.0, 0.0, 0.0]
elements = 2
e2 = [0.0, 1.0, 0.0]

[[beam]]
name = "b"
section = "s"
start = [1.0, 0.0, 0.0]
end = [2.0, 0.0, 0.0]
elements = 2
e2 = [0.0, 1.0, 0.0]

[[beam]]
name = "c"
section = "s"
start = [2.0, 0.0, 0.0]
end = [3.0, 0.0, 0.0]
elements = 2
e2 = [0.0, 1.0, 0.0]
"#;

fn parse(text: &str) -> Result<Model, ModelError> {
    parse_model(text, Path::new("data/test.toml"))
}

/// `BASE` followed by `extra`.
fn with(extra: &str) -> String {
    format!("{BASE}\n{extra}")
}

/// The 1-based line of the first line of `text` that contains `needle`.
fn line_of(text: &str, needle: &str) -> usize {
    text.lines()
        .position(|l| l.contains(needle))
        .unwrap_or_else(|| panic!("{needle:?} not in the text"))
        + 1
}

/// Parses `text`, expects an error with key `key` whose message contains every
/// one of `words`, and returns it.
fn expect_err(text: &str, key: &str, words: &[&str]) -> ModelError {
    let e = match parse(text) {
        Ok(_) => panic!("expected an error at `{key}`, but the file parsed"),
        Err(e) => e,
    };
    assert_eq!(e.key(), key, "wrong key in: {e}");
    for w in words {
        assert!(e.message().contains(w), "message lacks {w:?}: {e}");
    }
    assert_eq!(e.file(), Path::new("data/test.toml"));
    let shown = e.to_string();
    assert!(shown.starts_with("data/test.toml"), "{shown}");
    assert!(shown.contains(e.message()), "{shown}");
    e
}

const EPS: f64 = 1e-12;

fn close(a: [f64; 3], b: [f64; 3]) -> bool {
    (0..3).all(|i| (a[i] - b[i]).abs() < EPS)
}

// ---------------------------------------------------------------------------
// Good files.

#[test]
fn base_file_parses_with_defaults() {
    let m = parse(BASE).unwrap();
    assert_eq!(m.name, "base");
    assert_eq!(m.gravity, [0.0; 3]);
    assert_eq!(m.sections[0].values.rho_a, 0.0);
    assert_eq!(m.sections[0].values.rho_j, [0.0; 3]);
    assert_eq!(m.beams.len(), 3);
    assert_eq!(m.beams[0].nodes_per_element, 2);
    assert_eq!(m.beams[0].node_count(), 3);
    assert!(m.supports.is_empty() && m.joints.is_empty() && m.loads.is_empty());
    assert_eq!(
        m.solver,
        SolverSpec {
            analysis: Analysis::Static { load_steps: 10 },
            tolerance: 1e-10,
            max_iterations: 25,
            max_halvings: 10,
            mass: MassKind::Consistent,
            modified_newton: false,
            exact_tangent: false,
            rotation: None,
            eigensolver: None,
            stop: None,
        }
    );
    assert_eq!(m.output.every, 1);
    assert!(m.output.track.is_empty());
    assert_eq!(m.source_text, BASE);
    assert_eq!(m.path, Path::new("data/test.toml"));
}

#[test]
fn a_model_changed_in_rust_records_what_runs() {
    // Unchanged, the stored text is the file's own (comments and all);
    // changed in Rust, it is the model writer's text of the changed model.
    let text = format!("# my notes\n{BASE}");
    let mut m = parse(&text).unwrap();
    assert_eq!(m.text(), text);
    m.beams[0].elements = 7;
    let stored = m.text();
    assert!(!stored.contains("# my notes"), "{stored}");
    let again = parse(&stored).unwrap();
    assert_eq!(again.beams[0].elements, 7);
}

#[test]
#[allow(clippy::approx_constant)] // the numbers of MODEL_FORMAT.md's example
fn full_file_parses_with_the_right_values() {
    let m = parse(FULL).unwrap();
    assert_eq!(m.name, "screw-free");
    assert_eq!(m.gravity, [0.0, 0.0, -9.81]);

    // Sections, integers accepted as numbers, defaults.
    assert_eq!(m.sections.len(), 2);
    let s = &m.sections[0].values;
    assert_eq!(
        (s.ea, s.ga, s.gj, s.ei),
        (2.0e6, [8.0e5, 8.0e5], 1.0e3, [1.5e3, 1.5e3])
    );
    assert_eq!((s.rho_a, s.rho_j), (1.0, [0.02, 0.01, 0.01]));
    assert_eq!(m.sections[1].values.ea, 1000.0);
    assert_eq!(m.sections[1].values.rho_a, 0.5);

    // Beams.
    let post = &m.beams[0];
    assert_eq!(
        (post.name.as_str(), post.section, post.elements),
        ("post", 0, 4)
    );
    match &post.geometry {
        BeamGeometry::Straight { start, end, e2 } => {
            assert_eq!(<[f64; 3]>::from(*start), [0.0, 0.0, 0.0]);
            assert_eq!(<[f64; 3]>::from(*end), [0.0, 0.0, 10.0]);
            assert!(
                close((*e2).into(), [1.0, 0.0, 0.0]),
                "e2 normalised: {e2:?}"
            );
        }
        g => panic!("post should be straight: {g:?}"),
    }
    let arm = &m.beams[1];
    assert_eq!(
        (arm.section, arm.nodes_per_element, arm.node_count()),
        (1, 3, 7)
    );
    let bend = &m.beams[2];
    assert_eq!(bend.nodes_per_element, 2);
    match &bend.geometry {
        BeamGeometry::Arc {
            start,
            center,
            normal,
            sweep,
            e2,
        } => {
            assert_eq!(<[f64; 3]>::from(*start), [0.0; 3]);
            assert_eq!(<[f64; 3]>::from(*center), [100.0, 0.0, 0.0]);
            assert!(close((*normal).into(), [0.0, 0.0, -1.0]));
            assert_eq!(*sweep, 0.7853981634);
            assert_eq!(*e2, None);
        }
        g => panic!("bend should be an arc: {g:?}"),
    }

    // Supports.
    assert_eq!(m.supports[0].node, NodeRef { beam: 0, node: 0 });
    assert_eq!(m.supports[0].fixed, [true; 6]);
    assert_eq!(m.supports[1].node, NodeRef { beam: 2, node: 0 });
    assert_eq!(m.supports[1].fixed, [true, true, false, false, false, true]);

    // Joints: labels resolved, axis normalised.
    let screw = &m.joints[0];
    assert_eq!(screw.name, "screw");
    assert_eq!(screw.master, Some(NodeRef { beam: 0, node: 4 }));
    assert_eq!(screw.slave, NodeRef { beam: 1, node: 0 });
    match screw.kind.downcast_ref::<Screw>() {
        Some(s) => {
            assert!(
                close(s.axis.into(), [0.0, 0.0, 1.0]),
                "axis normalised: {s:?}"
            );
            assert_eq!(s.pitch, 0.1);
        }
        None => panic!("wrong kind {:?}", screw.kind),
    }
    assert_eq!((screw.angle, screw.rate), (0.25, 0.0));
    assert_eq!(screw.kind.type_name(), "screw");
    let weld = &m.joints[1];
    assert!(
        weld.kind.downcast_ref::<Rigid>().is_some(),
        "{:?}",
        weld.kind
    );
    assert_eq!(weld.master, Some(NodeRef { beam: 1, node: 6 }));
    assert_eq!(weld.slave, NodeRef { beam: 2, node: 8 });
    assert_eq!((weld.angle, weld.rate), (0.0, 0.0));

    // Loads.
    assert_eq!(m.loads[0].node, NodeRef { beam: 1, node: 6 });
    assert_eq!(m.loads[0].force, [0.0, 0.0, -1.0]);
    assert_eq!(m.loads[0].moment, [0.0; 3]);
    assert_eq!(
        m.loads[0].time,
        Some(TimeFunction::Table(vec![(0.0, 0.0), (1.0, 1.0)]))
    );
    assert_eq!(m.loads[1].node, NodeRef { beam: 1, node: 3 });
    assert_eq!(m.loads[1].force, [0.0; 3]);
    assert_eq!(m.loads[1].time, None);

    // Prescribed motion.
    assert_eq!(
        m.prescribed[0],
        PrescribedSpec::JointAngle {
            joint: 0,
            angle: TimeFunction::Table(vec![(0.0, 0.25), (2.0, 6.2832)]),
        }
    );
    assert_eq!(
        m.prescribed[1],
        PrescribedSpec::NodeDof {
            node: NodeRef { beam: 2, node: 2 },
            dof: 5,
            value: TimeFunction::Constant(0.5),
        }
    );

    // Initial velocities: a beam name means all its nodes.
    let v = &m.initial_velocities[0];
    assert_eq!(
        v.nodes,
        (0..7)
            .map(|node| NodeRef { beam: 1, node })
            .collect::<Vec<_>>()
    );
    assert_eq!(
        (v.linear, v.angular, v.origin),
        ([1.0, 0.0, 0.0], [0.0, 0.0, 2.0], [0.0; 3])
    );
    let v = &m.initial_velocities[1];
    assert_eq!(
        v.nodes,
        vec![NodeRef { beam: 0, node: 4 }, NodeRef { beam: 0, node: 2 }]
    );
    assert_eq!((v.linear, v.origin), ([0.0; 3], [0.0; 3]));

    // Solver and output.
    assert_eq!(
        m.solver.analysis,
        Analysis::Dynamic {
            integrator: IntegratorKind::EnergyMomentum,
            dt: 0.02,
            t_end: 5.0
        }
    );
    assert_eq!(m.solver.mass, MassKind::Consistent);
    assert_eq!(m.output.every, 2);
    assert_eq!(
        m.output.track,
        vec![
            ("post.end".to_string(), NodeRef { beam: 0, node: 4 }),
            ("arm.end".to_string(), NodeRef { beam: 1, node: 6 }),
            ("arm.2".to_string(), NodeRef { beam: 1, node: 2 }),
        ]
    );
    assert_eq!(m.node_label(NodeRef { beam: 1, node: 2 }), "arm.2");
    assert_eq!(m.find_node("bend.end"), Ok(NodeRef { beam: 2, node: 8 }));
}

#[test]
fn every_joint_type_parses_and_normalises() {
    let text = with(
        r#"
[[joint]]
name = "rev"
type = "revolute"
master = "a.end"
slave = "b.start"
axis = [0.0, 3.0, 4.0]

[[joint]]
name = "sph"
type = "spherical"
master = "a.0"
slave = "b.1"

[[joint]]
name = "pri"
type = "prismatic"
master = "a.1"
slave = "b.end"
slide = [0.0, 0.0, -5.0]

[[joint]]
name = "cyl"
type = "cylindrical"
master = "b.end"
slave = "c.start"
axis = [1.0, 0.0, 0.0]
slide = [2.0, 0.0, 0.0]

[[joint]]
name = "rp"
type = "rack_pinion"
master = "c.0"
slave = "c.1"
axis = [0.0, 0.0, 1.0]
radius = 0.5
slide = [3.0, 0.0, 0.0]

[[joint]]
name = "cam"
type = "cam"
master = "c.1"
slave = "c.2"
axis = [0.0, 0.0, 1.0]
radius = 0.2
offset = -0.05
slide = [0.0, 1.0, 0.0]

[[joint]]
name = "lobe"
type = "lobe"
master = "c.0"
slave = "a.start"
axis = [0.0, 0.0, 1.0]
slide = [1.0, 1.0, 0.0]
lift = { table = [[0.0, 0.1], [3.0, 0.3], [6.283185307179586, 0.1]] }

[[joint]]
name = "lobe2"
type = "lobe"
master = "c.2"
slave = "a.end"
axis = [0.0, 0.0, 1.0]
slide = [1.0, 0.0, 0.0]
lift = { fourier = [0.1, 0.02, 0.0] }
"#,
    );
    let m = parse(&text).unwrap();
    let h = std::f64::consts::FRAC_1_SQRT_2;
    assert_eq!(m.joints.len(), 8);
    let kind = |i: usize| &m.joints[i].kind;
    let revolute = kind(0).downcast_ref::<Revolute>().expect("revolute");
    assert!(close(revolute.axis.into(), [0.0, 0.6, 0.8]));
    assert!(
        kind(1).downcast_ref::<Spherical>().is_some(),
        "{:?}",
        kind(1)
    );
    let prismatic = kind(2).downcast_ref::<Prismatic>().expect("prismatic");
    assert!(close(prismatic.slide.into(), [0.0, 0.0, -1.0]));
    let cylindrical = kind(3).downcast_ref::<Cylindrical>().expect("cylindrical");
    assert!(close(cylindrical.axis.into(), [1.0, 0.0, 0.0]));
    assert!(close(cylindrical.slide.into(), [1.0, 0.0, 0.0]));
    let rack = kind(4).downcast_ref::<RackPinion>().expect("rack_pinion");
    assert_eq!(rack.radius, 0.5);
    assert!(close(rack.slide.into(), [1.0, 0.0, 0.0]));
    let cam = kind(5).downcast_ref::<Cam>().expect("cam");
    assert_eq!((cam.radius, cam.offset), (0.2, -0.05));
    let lobe = kind(6).downcast_ref::<Lobe>().expect("lobe");
    assert!(close(lobe.slide.into(), [h, h, 0.0]));
    // The table as written, and the spline through it.
    assert_eq!(
        kind(6).params()["lift"]["table"],
        toml::Value::try_from(vec![[0.0, 0.1], [3.0, 0.3], [std::f64::consts::TAU, 0.1]]).unwrap()
    );
    assert!(matches!(&lobe.lift, Lift::Table(s) if s.knots() == [0.0, 3.0, std::f64::consts::TAU]));
    let lobe = kind(7).downcast_ref::<Lobe>().expect("lobe");
    assert_eq!(lobe.lift, Lift::Fourier(vec![0.1, 0.02, 0.0]));
}

#[test]
fn chains_of_joints_are_allowed() {
    let text = with(
        r#"
[[joint]]
name = "j1"
type = "rigid"
master = "a.end"
slave = "b.start"

[[joint]]
name = "j2"
type = "revolute"
master = "b.start"
slave = "c.start"
axis = [0.0, 0.0, 1.0]
"#,
    );
    let m = parse(&text).unwrap();
    assert_eq!(m.joints[1].master, Some(m.joints[0].slave));
}

#[test]
fn static_solver_settings() {
    let text = with(
        "[solver]\nanalysis = \"static\"\nload_steps = 4\nmax_iterations = 7\nmax_halvings = 0\nmass = \"lumped\"\ntolerance = 1e-8\n",
    );
    let m = parse(&text).unwrap();
    assert_eq!(m.solver.analysis, Analysis::Static { load_steps: 4 });
    assert_eq!(
        (
            m.solver.max_iterations,
            m.solver.max_halvings,
            m.solver.tolerance
        ),
        (7, 0, 1e-8)
    );
    assert_eq!(m.solver.mass, MassKind::Lumped);
}

#[test]
fn arc_with_e2_and_quadratic_elements() {
    let text = with(
        r#"
[[beam]]
name = "ring"
section = "s"
arc = { start = [1.0, 0.0, 0.0], center = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 5.0], sweep = -6.283185307179586 }
elements = 5
nodes_per_element = 3
e2 = [0.0, 0.0, 2.0]
"#,
    );
    let m = parse(&text).unwrap();
    let ring = &m.beams[3];
    assert_eq!(ring.node_count(), 11);
    match &ring.geometry {
        BeamGeometry::Arc {
            normal, e2, sweep, ..
        } => {
            assert!(close((*normal).into(), [0.0, 0.0, 1.0]));
            assert_eq!(e2.map(<[f64; 3]>::from), Some([0.0, 0.0, 1.0]));
            assert_eq!(*sweep, -std::f64::consts::TAU);
        }
        g => panic!("{g:?}"),
    }
}

#[test]
fn load_model_reads_a_file_and_names_a_missing_one() {
    let dir = std::env::temp_dir().join(format!("flexmech-model-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("full.toml");
    std::fs::write(&path, FULL).unwrap();
    let m = load_model(&path).unwrap();
    assert_eq!(m.name, "screw-free");
    assert_eq!(m.path, path);
    std::fs::remove_dir_all(&dir).unwrap();

    let missing = Path::new("/nonexistent/dir/model.toml");
    let e = load_model(missing).unwrap_err();
    assert_eq!(e.file(), missing);
    assert_eq!(e.key(), "");
    assert!(e.message().contains("cannot read"), "{e}");
    assert!(
        e.to_string().starts_with("/nonexistent/dir/model.toml: "),
        "{e}"
    );
}

// ---------------------------------------------------------------------------
// TimeFunction.

#[test]
fn time_function_eval() {
    let f = TimeFunction::Table(vec![(0.0, 0.0), (1.0, 2.0), (3.0, -2.0)]);
    // At the table points.
    assert_eq!(f.eval(0.0), 0.0);
    assert_eq!(f.eval(1.0), 2.0);
    assert_eq!(f.eval(3.0), -2.0);
    // Between them.
    assert!((f.eval(0.25) - 0.5).abs() < EPS);
    assert!((f.eval(2.0) - 0.0).abs() < EPS);
    assert!((f.eval(2.5) + 1.0).abs() < EPS);
    // Outside: constant extrapolation.
    assert_eq!(f.eval(-10.0), 0.0);
    assert_eq!(f.eval(1e9), -2.0);
    // One row and constants.
    assert_eq!(TimeFunction::Table(vec![(1.0, 3.0)]).eval(0.0), 3.0);
    assert_eq!(TimeFunction::Table(vec![(1.0, 3.0)]).eval(5.0), 3.0);
    assert_eq!(TimeFunction::Constant(1.5).eval(42.0), 1.5);
}

#[test]
fn time_function_validate() {
    assert!(TimeFunction::table(vec![(0.0, 1.0), (1.0, 1.0)]).is_ok());
    assert!(TimeFunction::table(vec![]).unwrap_err().contains("empty"));
    assert!(TimeFunction::table(vec![(0.0, 1.0), (0.0, 2.0)])
        .unwrap_err()
        .contains("strictly increasing"));
    assert!(TimeFunction::table(vec![(0.0, f64::NAN)])
        .unwrap_err()
        .contains("finite"));
    assert!(TimeFunction::Constant(f64::INFINITY).validate().is_err());
}

// ---------------------------------------------------------------------------
// Bad files.

#[test]
fn unknown_top_level_key() {
    let text = BASE.replace("name = \"base\"", "name = \"base\"\ncolour = 1");
    let e = expect_err(
        &text,
        "colour",
        &["unknown key `colour`", "expected one of", "`name`"],
    );
    assert_eq!(e.line(), Some(2));
    assert!(
        e.to_string()
            .starts_with("data/test.toml:2: key `colour`: unknown key"),
        "{e}"
    );
}

#[test]
fn unknown_key_in_a_section() {
    let text = BASE.replace("GJ = 1.0\n", "GJ = 1.0\nEJ = 3.0\n");
    let e = expect_err(&text, "section[0].EJ", &["unknown key `EJ`", "`GJ`"]);
    assert_eq!(e.line(), Some(line_of(&text, "EJ = 3.0")));
}

#[test]
fn unknown_key_in_an_inline_table() {
    let text = with(
        "[[beam]]\nname = \"r\"\nsection = \"s\"\nelements = 2\narc = { start = [1.0, 0.0, 0.0], center = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0], sweep = 1.0, radius = 1.0 }\n",
    );
    let e = expect_err(&text, "beam[3].arc.radius", &["unknown key `radius`"]);
    assert_eq!(e.line(), Some(line_of(&text, "radius = 1.0")));
}

#[test]
fn missing_name() {
    let text = BASE.replace("name = \"base\"\n", "");
    expect_err(&text, "name", &["missing key `name`"]);
}

#[test]
fn name_unusable_as_file_name() {
    let text = BASE.replace("name = \"base\"", "name = \"../x\"");
    let e = expect_err(&text, "name", &["must not contain '/'", "\"../x\""]);
    assert_eq!(e.line(), Some(1));
    let text = BASE.replace("name = \"base\"", "name = \".hidden\"");
    expect_err(&text, "name", &["must not start with '.'"]);
}

#[test]
fn negative_dt() {
    let text = with(
        "[solver]\nanalysis = \"dynamic\"\nintegrator = \"newmark\"\ndt = -0.01\nt_end = 1.0\n",
    );
    let e = expect_err(&text, "solver.dt", &["must be > 0", "found -0.01"]);
    let line = line_of(&text, "dt = -0.01");
    assert_eq!(e.line(), Some(line));
    assert_eq!(
        e.to_string(),
        format!("data/test.toml:{line}: key `solver.dt`: must be > 0, found -0.01")
    );
}

#[test]
fn dt_larger_than_t_end() {
    let text = with(
        "[solver]\nanalysis = \"dynamic\"\nintegrator = \"momentum\"\ndt = 2.0\nt_end = 1.0\n",
    );
    expect_err(&text, "solver.dt", &["t_end", "found 2.0"]);
}

#[test]
fn dynamic_needs_an_integrator() {
    let text = with("[solver]\nanalysis = \"dynamic\"\ndt = 0.1\nt_end = 1.0\n");
    let e = expect_err(
        &text,
        "solver.integrator",
        &["missing key `integrator`", "energy-momentum"],
    );
    assert_eq!(e.line(), Some(line_of(&text, "[solver]")));
    let text =
        with("[solver]\nanalysis = \"dynamic\"\nintegrator = \"euler\"\ndt = 0.1\nt_end = 1.0\n");
    expect_err(
        &text,
        "solver.integrator",
        &["unknown integrator \"euler\"", "newmark"],
    );
}

#[test]
fn generalized_alpha_takes_rho_inf_in_zero_one() {
    use flexmech::model::{Analysis, IntegratorKind};
    let solver = |int: &str, extra: &str| {
        with(&format!(
            "[solver]\nanalysis = \"dynamic\"\nintegrator = \"{int}\"\ndt = 0.1\nt_end = 1.0\n{extra}"
        ))
    };
    let rho =
        |text: &str| match parse(&text.replace("EI = [1.0, 1.0]", "EI = [1.0, 1.0]\nrhoA = 1.0"))
            .unwrap()
            .solver
            .analysis
        {
            Analysis::Dynamic {
                integrator: IntegratorKind::GeneralizedAlpha { rho_inf },
                ..
            } => rho_inf,
            other => panic!("{other:?}"),
        };
    assert_eq!(rho(&solver("generalized-alpha", "")), 0.9);
    assert_eq!(rho(&solver("generalized-alpha", "rho_inf = 0.0\n")), 0.0);
    assert_eq!(rho(&solver("generalized-alpha", "rho_inf = 1\n")), 1.0);
    for bad in ["1.5", "-0.1"] {
        let text = solver("generalized-alpha", &format!("rho_inf = {bad}\n"));
        let e = expect_err(&text, "solver.rho_inf", &["[0, 1]", bad]);
        assert_eq!(e.line(), Some(line_of(&text, "rho_inf")));
    }
    let text = solver("newmark", "rho_inf = 0.5\n");
    expect_err(&text, "solver.rho_inf", &["generalized-alpha", "newmark"]);
    let text = with("[solver]\nrho_inf = 0.5\n");
    expect_err(&text, "solver.rho_inf", &["dynamic"]);
}

#[test]
fn non_positive_ea() {
    let text = BASE.replace("EA = 1.0", "EA = 0.0");
    let e = expect_err(&text, "section[0].EA", &["must be > 0", "found 0.0"]);
    assert_eq!(e.line(), Some(line_of(&text, "EA = 0.0")));
    let text = BASE.replace("GA = [1.0, 1.0]", "GA = [1.0, -2.0]");
    expect_err(&text, "section[0].GA", &["must be > 0", "-2.0"]);
}

#[test]
fn negative_mass() {
    let text = BASE.replace(
        "EI = [1.0, 1.0]",
        "EI = [1.0, 1.0]\nrhoJ = [0.1, -0.1, 0.0]",
    );
    expect_err(&text, "section[0].rhoJ", &["must be >= 0", "-0.1"]);
}

#[test]
fn non_finite_number() {
    let text = BASE.replace("GJ = 1.0", "GJ = nan");
    let e = expect_err(&text, "section[0].GJ", &["finite", "NaN"]);
    assert_eq!(e.line(), Some(line_of(&text, "GJ = nan")));
    let text =
        with("gravity = [0.0, 0.0, -inf]\n").replace("\ngravity", "\n[output]\nevery = 1\n#");
    assert!(parse(&text).is_ok(), "commented-out inf is fine");
    let text = BASE.replace(
        "name = \"base\"",
        "name = \"base\"\ngravity = [0.0, 0.0, -inf]",
    );
    let e = expect_err(&text, "gravity", &["finite", "-inf"]);
    assert_eq!(e.line(), Some(2));
}

#[test]
fn wrong_value_type() {
    let text = BASE.replace(
        "elements = 2\ne2 = [0.0, 1.0, 0.0]\n\n[[beam]]\nname = \"b\"",
        "elements = 2.5\ne2 = [0.0, 1.0, 0.0]\n\n[[beam]]\nname = \"b\"",
    );
    let e = expect_err(&text, "beam[0].elements", &["expected an integer"]);
    assert_eq!(e.line(), Some(line_of(&text, "elements = 2.5")));
    let text = BASE.replace("end = [1.0, 0.0, 0.0]", "end = [1.0, 0.0]");
    expect_err(&text, "beam[0].end", &["length 2", "length 3"]);
}

#[test]
fn single_brackets_for_an_array_table() {
    let text = "name = \"x\"\n[solver]\nload_steps = 2\n[support]\nnode = \"a.start\"\n";
    let e = expect_err(text, "support", &["[[support]]"]);
    assert_eq!(e.line(), Some(4));
}

#[test]
fn unknown_node_label() {
    let text = with("[[support]]\nnode = \"arm.start\"\nfixed = \"all\"\n");
    let e = expect_err(
        &text,
        "support[0].node",
        &[
            "unknown node label \"arm.start\"",
            "no beam named \"arm\"",
            "<beam>.start",
            "\"a\", \"b\", \"c\"",
        ],
    );
    assert_eq!(e.line(), Some(line_of(&text, "node = \"arm.start\"")));
    let text = with("[[load]]\nnode = \"a.middle\"\nforce = [1.0, 0.0, 0.0]\n");
    expect_err(
        &text,
        "load[0].node",
        &["\"a.middle\"", "`start`, `end` or a node index in 0..=2"],
    );
    let text = with("[[load]]\nnode = \"a\"\nforce = [1.0, 0.0, 0.0]\n");
    expect_err(&text, "load[0].node", &["not a node label", "\"a.start\""]);
    let text = with("[[load]]\nnode = \"a.+1\"\nforce = [1.0, 0.0, 0.0]\n");
    expect_err(&text, "load[0].node", &["unknown node label \"a.+1\""]);
}

#[test]
fn node_index_out_of_range() {
    let text = with("[output]\ntrack = [\"a.end\", \"b.3\"]\n");
    let e = expect_err(
        &text,
        "output.track[1]",
        &["node index 3", "out of range", "3 nodes", "0..=2"],
    );
    assert_eq!(e.line(), Some(line_of(&text, "track = ")));
}

#[test]
fn slave_of_two_joints() {
    let text = with(
        r#"
[[joint]]
name = "first"
type = "rigid"
master = "a.end"
slave = "b.start"

[[joint]]
name = "second"
type = "revolute"
master = "c.start"
slave = "b.0"
axis = [0.0, 0.0, 1.0]
"#,
    );
    let e = expect_err(
        &text,
        "joint[1].slave",
        &["slave of two joints", "\"first\"", "\"second\""],
    );
    assert_eq!(e.line(), Some(line_of(&text, "slave = \"b.0\"")));
}

#[test]
fn master_equals_slave() {
    let text =
        with("[[joint]]\nname = \"j\"\ntype = \"rigid\"\nmaster = \"a.end\"\nslave = \"a.2\"\n");
    expect_err(
        &text,
        "joint[0].slave",
        &["is the master node", "two different nodes"],
    );
}

#[test]
fn supported_slave() {
    let text = with(
        "[[support]]\nnode = \"b.start\"\nfixed = [\"uz\"]\n\n[[joint]]\nname = \"j\"\ntype = \"rigid\"\nmaster = \"a.end\"\nslave = \"b.start\"\n",
    );
    let e = expect_err(
        &text,
        "support[0].node",
        &["supported", "slave of joint \"j\""],
    );
    assert_eq!(e.line(), Some(line_of(&text, "node = \"b.start\"")));
}

#[test]
fn zero_axis() {
    let text = with("[[joint]]\nname = \"hinge\"\ntype = \"revolute\"\nmaster = \"a.end\"\nslave = \"b.start\"\naxis = [0.0, 0.0, 0.0]\n");
    let e = expect_err(&text, "joint[0].axis", &["nonzero", "[0.0, 0.0, 0.0]"]);
    assert_eq!(e.line(), Some(line_of(&text, "axis = [0.0, 0.0, 0.0]")));
}

#[test]
fn missing_axis() {
    let text = with("[[joint]]\nname = \"hinge\"\ntype = \"cylindrical\"\nmaster = \"a.end\"\nslave = \"b.start\"\nslide = [1.0, 0.0, 0.0]\n");
    let e = expect_err(
        &text,
        "joint[0].axis",
        &["missing key `axis`", "cylindrical"],
    );
    assert_eq!(e.line(), Some(line_of(&text, "[[joint]]")));
}

#[test]
fn slide_not_perpendicular() {
    let text = with(
        "[[joint]]\nname = \"rp\"\ntype = \"rack_pinion\"\nmaster = \"a.end\"\nslave = \"b.start\"\naxis = [0.0, 0.0, 1.0]\nradius = 0.5\nslide = [1.0, 0.0, 1.0]\n",
    );
    let e = expect_err(&text, "joint[0].slide", &["perpendicular", "rack_pinion"]);
    assert_eq!(e.line(), Some(line_of(&text, "slide = [1.0, 0.0, 1.0]")));
}

#[test]
fn non_positive_radius() {
    let text = with(
        "[[joint]]\nname = \"c\"\ntype = \"cam\"\nmaster = \"a.end\"\nslave = \"b.start\"\naxis = [0.0, 0.0, 1.0]\nradius = -0.5\noffset = 0.0\nslide = [1.0, 0.0, 0.0]\n",
    );
    expect_err(&text, "joint[0].radius", &["must be > 0", "-0.5"]);
}

#[test]
fn cycle_of_joints() {
    let text = with(
        r#"
[[joint]]
name = "ab"
type = "rigid"
master = "a.end"
slave = "b.start"

[[joint]]
name = "bc"
type = "revolute"
master = "b.start"
slave = "c.start"
axis = [0.0, 0.0, 1.0]

[[joint]]
name = "ca"
type = "rigid"
master = "c.start"
slave = "a.end"
"#,
    );
    let e = expect_err(&text, "joint[0]", &["cycle", "\"ab\"", "\"bc\"", "\"ca\""]);
    assert_eq!(e.line(), Some(line_of(&text, "[[joint]]")));
}

#[test]
fn dt_in_a_static_analysis() {
    let text = with("[solver]\nload_steps = 5\ndt = 0.1\n");
    let e = expect_err(
        &text,
        "solver.dt",
        &["dynamic", "static", "analysis = \"dynamic\""],
    );
    assert_eq!(e.line(), Some(line_of(&text, "dt = 0.1")));
    let text = with("[solver]\nanalysis = \"dynamic\"\nintegrator = \"newmark\"\ndt = 0.1\nt_end = 1.0\nload_steps = 3\n");
    expect_err(&text, "solver.load_steps", &["static"]);
}

#[test]
fn pitch_on_a_revolute_joint() {
    let text = with("[[joint]]\nname = \"hinge\"\ntype = \"revolute\"\nmaster = \"a.end\"\nslave = \"b.start\"\naxis = [0.0, 0.0, 1.0]\npitch = 0.1\n");
    let e = expect_err(
        &text,
        "joint[0].pitch",
        &[
            "`pitch` does not belong to a joint of type revolute",
            "`axis`",
        ],
    );
    assert_eq!(e.line(), Some(line_of(&text, "pitch = 0.1")));
}

#[test]
fn unknown_joint_type() {
    let text = with(
        "[[joint]]\nname = \"hinge\"\ntype = \"hinge\"\nmaster = \"a.end\"\nslave = \"b.start\"\n",
    );
    let e = expect_err(
        &text,
        "joint[0].type",
        &["unknown joint type \"hinge\"", "revolute", "rack_pinion"],
    );
    assert_eq!(e.line(), Some(line_of(&text, "type = \"hinge\"")));
}

#[test]
fn toml_syntax_error_with_line() {
    let text = with("[solver]\nload_steps = 3\ntolerance = 1e-8.5\n");
    let e = parse(&text).unwrap_err();
    assert_eq!(e.line(), Some(line_of(&text, "tolerance = 1e-8.5")), "{e}");
    assert!(e.message().contains("TOML syntax error"), "{e}");
    assert_eq!(e.key(), "solver.tolerance", "{e}");

    let text = "name = \"x\"\n\n[solver\nload_steps = 3\n";
    let e = parse(text).unwrap_err();
    assert_eq!(e.line(), Some(3), "{e}");
    assert!(e.message().contains("TOML syntax error"), "{e}");
}

#[test]
fn duplicate_key_is_a_syntax_error() {
    let text = with("[solver]\nload_steps = 3\nload_steps = 4\n");
    let e = parse(&text).unwrap_err();
    assert_eq!(e.line(), Some(line_of(&text, "load_steps = 4")), "{e}");
    assert!(e.message().contains("duplicate key"), "{e}");
}

#[test]
fn unknown_support_dof_name() {
    let text = with("[[support]]\nnode = \"a.start\"\nfixed = [\"ux\", \"uw\"]\n");
    let e = expect_err(
        &text,
        "support[0].fixed",
        &["unknown DOF name \"uw\"", "\"rz\""],
    );
    assert_eq!(e.line(), Some(line_of(&text, "fixed = ")));
    let text = with("[[support]]\nnode = \"a.start\"\nfixed = [\"ux\", \"ux\"]\n");
    expect_err(&text, "support[0].fixed", &["listed twice"]);
    let text = with("[[support]]\nnode = \"a.start\"\nfixed = \"ux\"\n");
    expect_err(&text, "support[0].fixed", &["fixed = [\"ux\"]"]);
}

#[test]
fn lobe_table_not_periodic() {
    let text = with(
        "[[joint]]\nname = \"lobe\"\ntype = \"lobe\"\nmaster = \"a.end\"\nslave = \"b.start\"\naxis = [0.0, 0.0, 1.0]\nslide = [1.0, 0.0, 0.0]\nlift = { table = [\n  [0.0, 0.1],\n  [3.0, 0.3],\n  [6.0, 0.2],\n] }\n",
    );
    let e = expect_err(&text, "joint[0].lift.table", &["periodic", "0.1", "0.2"]);
    assert_eq!(e.line(), Some(line_of(&text, "[6.0, 0.2]")));
}

#[test]
fn lobe_lift_shape() {
    let joint = "[[joint]]\nname = \"lobe\"\ntype = \"lobe\"\nmaster = \"a.end\"\nslave = \"b.start\"\naxis = [0.0, 0.0, 1.0]\nslide = [1.0, 0.0, 0.0]\n";
    let text = with(&format!(
        "{joint}lift = {{ table = [[0.0, 0.1], [6.0, 0.1]] }}\n"
    ));
    expect_err(
        &text,
        "joint[0].lift.table",
        &["at least 3 rows", "found 2"],
    );
    let text = with(&format!("{joint}lift = {{ fourier = [0.1, 0.2] }}\n"));
    expect_err(&text, "joint[0].lift.fourier", &["odd number", "found 2"]);
    let text = with(&format!(
        "{joint}lift = {{ table = [[0.0, 0.1], [2.0, 0.2], [1.0, 0.1]] }}\n"
    ));
    expect_err(&text, "joint[0].lift.table", &["strictly increasing"]);
    let text = with(joint);
    expect_err(&text, "joint[0].lift", &["missing key `lift`"]);
}

#[test]
fn unknown_section_name() {
    let text = BASE.replace(
        "section = \"s\"\nstart = [1.0",
        "section = \"steel\"\nstart = [1.0",
    );
    let e = expect_err(
        &text,
        "beam[1].section",
        &["unknown section \"steel\"", "sections are \"s\""],
    );
    assert_eq!(e.line(), Some(line_of(&text, "section = \"steel\"")));
}

#[test]
fn duplicate_names() {
    let text = BASE.replace("name = \"b\"", "name = \"a\"");
    expect_err(
        &text,
        "beam[1].name",
        &["duplicate beam name \"a\"", "beam[0]"],
    );
    let text = BASE.replace("name = \"b\"", "name = \"b.x\"");
    expect_err(&text, "beam[1].name", &["must not contain '.'"]);
    let text = BASE.replace("name = \"b\"", "name = \"b/x\"");
    expect_err(&text, "beam[1].name", &["'/'"]);
}

#[test]
fn beam_geometry_errors() {
    let text = BASE.replace("end = [1.0, 0.0, 0.0]", "end = [0.0, 0.0, 0.0]");
    expect_err(&text, "beam[0].end", &["equals `start`"]);
    let text = BASE.replace(
        "end = [1.0, 0.0, 0.0]\nelements = 2\ne2 = [0.0, 1.0, 0.0]",
        "end = [1.0, 0.0, 0.0]\nelements = 2\ne2 = [-3.0, 0.0, 0.0]",
    );
    expect_err(&text, "beam[0].e2", &["parallel"]);
    let text = BASE.replace(
        "end = [1.0, 0.0, 0.0]\nelements = 2\ne2 = [0.0, 1.0, 0.0]\n",
        "end = [1.0, 0.0, 0.0]\nelements = 2\n",
    );
    expect_err(&text, "beam[0].e2", &["missing key `e2`"]);
    let text = BASE.replace(
        "elements = 2\ne2 = [0.0, 1.0, 0.0]\n\n[[beam]]\nname = \"b\"",
        "elements = 0\ne2 = [0.0, 1.0, 0.0]\n\n[[beam]]\nname = \"b\"",
    );
    expect_err(&text, "beam[0].elements", &["must be >= 1", "found 0"]);
    let text = BASE.replace(
        "name = \"c\"\nsection = \"s\"",
        "name = \"c\"\nsection = \"s\"\nnodes_per_element = 4",
    );
    expect_err(
        &text,
        "beam[2].nodes_per_element",
        &["2 (linear", "3 (quadratic", "found 4"],
    );
    let text = BASE.replace("start = [2.0, 0.0, 0.0]", "arc = { start = [1.0, 0.0, 0.0], center = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0], sweep = 1.0 }");
    expect_err(&text, "beam[2].end", &["not both"]);
}

#[test]
fn arc_errors() {
    let arc = |a: &str| {
        with(&format!(
            "[[beam]]\nname = \"r\"\nsection = \"s\"\nelements = 2\narc = {{ {a} }}\n"
        ))
    };
    let text = arc(
        "start = [1.0, 0.0, 0.0], center = [0.0, 0.0, 0.0], normal = [1.0, 0.0, 1.0], sweep = 1.0",
    );
    let e = expect_err(&text, "beam[3].arc.normal", &["perpendicular"]);
    assert_eq!(e.line(), Some(line_of(&text, "arc = ")));
    let text = arc(
        "start = [1.0, 0.0, 0.0], center = [1.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0], sweep = 1.0",
    );
    expect_err(&text, "beam[3].arc.center", &["radius"]);
    let text = arc(
        "start = [1.0, 0.0, 0.0], center = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0], sweep = 7.0",
    );
    expect_err(&text, "beam[3].arc.sweep", &["2π", "found 7.0"]);
    let text = arc(
        "start = [1.0, 0.0, 0.0], center = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0], sweep = 0",
    );
    expect_err(&text, "beam[3].arc.sweep", &["nonzero"]);
    let text = arc("start = [1.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0], sweep = 1.0");
    expect_err(&text, "beam[3].arc.center", &["missing key `center`"]);
}

#[test]
fn load_errors() {
    let text = with("[[load]]\nnode = \"a.end\"\n");
    let e = expect_err(&text, "load[0]", &["`force` and/or `moment`"]);
    assert_eq!(e.line(), Some(line_of(&text, "[[load]]")));
    let text = with("[[load]]\nnode = \"a.end\"\nforce = [1.0, 0.0, 0.0]\ntime = { table = [[0.0, 0.0], [1.0, 1.0], [1.0, 2.0]] }\n");
    expect_err(&text, "load[0].time", &["strictly increasing", "row 2"]);
    let text = with("[[load]]\nnode = \"a.end\"\nforce = [1.0, 0.0, 0.0]\ntime = { table = [] }\n");
    expect_err(&text, "load[0].time", &["empty"]);
    let text = with(
        "[[load]]\nnode = \"a.end\"\nforce = [1.0, 0.0, 0.0]\ntime = { tabel = [[0.0, 1.0]] }\n",
    );
    expect_err(&text, "load[0].time", &["unknown key `tabel`", "`table`"]);
}

#[test]
fn prescribed_errors() {
    let joints = "[[joint]]\nname = \"w\"\ntype = \"rigid\"\nmaster = \"a.end\"\nslave = \"b.start\"\n\n[[joint]]\nname = \"ball\"\ntype = \"spherical\"\nmaster = \"b.end\"\nslave = \"c.start\"\n\n";
    let table = "{ table = [[0.0, 0.0], [1.0, 1.0]] }";
    let text = with(&format!(
        "{joints}[[prescribed]]\njoint = \"w\"\nangle = {table}\n"
    ));
    expect_err(
        &text,
        "prescribed[0].joint",
        &["rigid", "no released rotation"],
    );
    let text = with(&format!(
        "{joints}[[prescribed]]\njoint = \"ball\"\nangle = {table}\n"
    ));
    expect_err(
        &text,
        "prescribed[0].joint",
        &["spherical", "not supported yet"],
    );
    let text = with(&format!(
        "{joints}[[prescribed]]\njoint = \"nope\"\nangle = {table}\n"
    ));
    expect_err(
        &text,
        "prescribed[0].joint",
        &["unknown joint \"nope\"", "\"w\", \"ball\""],
    );
    let text = with(&format!(
        "{joints}[[prescribed]]\nnode = \"b.start\"\ndof = \"ux\"\nvalue = {table}\n"
    ));
    expect_err(&text, "prescribed[0].node", &["slave of joint \"w\""]);
    let text = with(&format!(
        "{joints}[[prescribed]]\nnode = \"a.start\"\ndof = \"uq\"\nvalue = {table}\n"
    ));
    expect_err(&text, "prescribed[0].dof", &["unknown DOF name \"uq\""]);
    let text = with(&format!(
        "{joints}[[prescribed]]\nnode = \"a.start\"\ndof = \"ux\"\n"
    ));
    expect_err(&text, "prescribed[0].value", &["missing key `value`"]);
    let text = with(&format!(
        "{joints}[[prescribed]]\njoint = \"w\"\nnode = \"a.start\"\n"
    ));
    expect_err(&text, "prescribed[0].node", &["two [[prescribed]] entries"]);
    let text = with(&format!("{joints}[[prescribed]]\nangle = {table}\n"));
    expect_err(&text, "prescribed[0].angle", &["needs `joint"]);
}

#[test]
fn initial_velocity_errors() {
    let text = with("[[initial_velocity]]\nnodes = \"a.end\"\nlinear = [1.0, 0.0, 0.0]\n");
    expect_err(&text, "initial_velocity[0].nodes", &["nodes = [\"a.end\"]"]);
    let text = with("[[initial_velocity]]\nnodes = [\"a.end\", \"z.0\"]\n");
    expect_err(
        &text,
        "initial_velocity[0].nodes[1]",
        &["no beam named \"z\""],
    );
}

#[test]
fn angle_on_a_rigid_joint() {
    let text = with("[[joint]]\nname = \"w\"\ntype = \"rigid\"\nmaster = \"a.end\"\nslave = \"b.start\"\nangle = 0.5\n");
    expect_err(
        &text,
        "joint[0].angle",
        &["does not belong to a joint of type rigid"],
    );
}

#[test]
fn bad_enumerations() {
    expect_err(
        &with("[solver]\nanalysis = \"quasi\"\n"),
        "solver.analysis",
        &[
            "\"static\", \"dynamic\", \"modal\", \"buckling\"",
            "\"quasi\"",
        ],
    );
    expect_err(
        &with("[solver]\nmass = \"heavy\"\n"),
        "solver.mass",
        &["\"consistent\" or \"lumped\""],
    );
    expect_err(
        &with("[output]\nevery = 0\n"),
        "output.every",
        &["must be >= 1"],
    );
    expect_err(
        &with("[output]\ntrack = [\"a.end\", \"a.end\"]\n"),
        "output.track[1]",
        &["listed twice"],
    );
}

#[test]
fn unknown_key_in_solver() {
    let text = with("[solver]\nanalysis = \"static\"\nsteps = 3\n");
    let e = expect_err(
        &text,
        "solver.steps",
        &["unknown key `steps`", "`load_steps`"],
    );
    assert_eq!(e.line(), Some(line_of(&text, "steps = 3")));
}

#[test]
fn dynamics_without_mass_is_refused() {
    // Omitted rhoA (the default, 0) and an explicit 0: both named by key.
    let dynamic =
        "[solver]\nanalysis = \"dynamic\"\nintegrator = \"newmark\"\ndt = 0.1\nt_end = 1.0\n";
    let text = with(dynamic);
    let e = expect_err(
        &text,
        "section[0].rhoA",
        &["needs mass", "section \"s\"", "no rhoA", "rhoA = 7.85"],
    );
    assert_eq!(e.line(), Some(line_of(&text, "[[section]]")));
    let text = with(dynamic).replace("EI = [1.0, 1.0]\n", "EI = [1.0, 1.0]\nrhoA = 0.0\n");
    let e = expect_err(&text, "section[0].rhoA", &["needs mass", "rhoA = 0;"]);
    assert_eq!(e.line(), Some(line_of(&text, "rhoA = 0.0")));
    // Statics needs no mass.
    assert!(parse(BASE).is_ok());
}

#[test]
fn a_prescribed_dof_that_is_also_supported_is_refused() {
    let text = format!(
        "{BASE}\n[[support]]\nnode = \"a.start\"\nfixed = [\"ux\", \"rz\"]\n\n[[prescribed]]\nnode = \"a.start\"\ndof = \"rz\"\nvalue = 0.5\n"
    );
    let e = expect_err(
        &text,
        "prescribed[0].dof",
        &[
            "also held by support[0].fixed",
            "remove \"rz\" from support[0].fixed",
        ],
    );
    assert_eq!(e.line(), Some(line_of(&text, "dof = \"rz\"")));
    // Another DOF of the same node may be prescribed.
    let ok = text.replace("dof = \"rz\"", "dof = \"ry\"");
    assert!(parse(&ok).is_ok(), "{:?}", parse(&ok).err());
}

#[test]
fn huge_sizes_are_refused_by_key_not_by_a_panic() {
    // Sizes near i64::MAX once panicked with "capacity overflow" or aborted
    // on a failed allocation; they are refused at validation, naming the key
    // and the limit's reason.
    let big = i64::MAX;
    let text = BASE.replacen("elements = 2", &format!("elements = {big}"), 1);
    expect_err(
        &text,
        "beam[0].elements",
        &["must be <= 200000", "assembly memory"],
    );
    let text = with(&format!("[solver]\nload_steps = {big}\n"));
    expect_err(&text, "solver.load_steps", &["must be <= 1000000"]);
    let text = with("[solver]\nmax_iterations = 100000000000\n");
    expect_err(&text, "solver.max_iterations", &["must be <= 1000"]);
    let text = with("[solver]\nmax_halvings = 1000\n");
    expect_err(&text, "solver.max_halvings", &["must be <= 50"]);
    let text = with(&format!("[output]\nevery = {big}\n"));
    expect_err(&text, "output.every", &["must be <= 1000000000"]);
    // Many beams together: the total is limited too, at the beam that passes it.
    let text = BASE
        .replacen("elements = 2", "elements = 150000", 1)
        .replacen("elements = 2", "elements = 60000", 1);
    expect_err(
        &text,
        "beam[1].elements",
        &["brings the model to 210000 elements"],
    );
    // A dynamic run of more than 1e7 steps.
    let text = with(
        "[solver]\nanalysis = \"dynamic\"\nintegrator = \"newmark\"\ndt = 1e-9\nt_end = 1.0\n",
    );
    expect_err(
        &text,
        "solver.dt",
        &["t_end/dt = 1.000e9 steps", "larger dt"],
    );
}

#[test]
fn a_name_too_long_for_a_file_name_is_refused_by_key() {
    // A 300-character name once gave an HDF5 error about the output path.
    let long = "a".repeat(300);
    let text = BASE.replace("name = \"base\"", &format!("name = \"{long}\""));
    expect_err(&text, "name", &["at most 200 bytes"]);
}
