//! `[[distributed_load]]`: consistent nodal loads of a line load, against
//! linear beam theory on a cantilever (small loads).

use std::path::{Path, PathBuf};

use flexmech::model::parse_model;
use flexmech::results::run_model_to;
use flexmech::results::ResultReader;

fn file() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/statics/distributed_load.toml")
}

fn tip(text: &str, dataset: &str) -> [f64; 3] {
    let model = parse_model(text, &file()).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let out = run_model_to(&model, &dir.path().join("r.h5")).unwrap();
    *ResultReader::open(&out.file)
        .unwrap()
        .rows3(&format!("/nodes/beam.end/{dataset}"))
        .unwrap()
        .last()
        .unwrap()
}

/// `w(L) = qL⁴/8EI + qL²/2GA` to 1e-9 relative (2-node elements are exact
/// at the tip for a uniform load; the geometric nonlinearity is ~1e-12), and
/// 3-node elements (consistent weights ⅙, ⅔, ⅙) to 1e-6.
#[test]
fn a_line_load_bends_the_cantilever_as_beam_theory_says() {
    let text = std::fs::read_to_string(file()).unwrap();
    let (q, ei, ga) = (0.01, 1000.0, 4.0e5);
    let expected = q / (8.0 * ei) + q / (2.0 * ga);
    let w = -tip(&text, "displacement")[2];
    assert!((w / expected - 1.0).abs() < 1e-9, "{w} against {expected}");
    let quadratic = text.replace("elements = 10", "elements = 10\nnodes_per_element = 3");
    let w3 = -tip(&quadratic, "displacement")[2];
    assert!(
        (w3 / expected - 1.0).abs() < 1e-6,
        "3-node: {w3} against {expected}"
    );
}

/// A uniform distributed moment `m` about y turns the tip by `m L²/(2EI)`
/// (the element's midpoint rule is exact for the linear moment).
#[test]
fn a_distributed_moment_turns_the_tip_as_beam_theory_says() {
    let text = std::fs::read_to_string(file())
        .unwrap()
        .replace("force = [0.0, 0.0, -0.01]", "moment = [0.0, 0.01, 0.0]");
    let (m, ei) = (0.01, 1000.0);
    let expected = m / (2.0 * ei);
    let theta = tip(&text, "rotation")[1];
    assert!(
        (theta / expected - 1.0).abs() < 1e-9,
        "{theta} against {expected}"
    );
}

/// Mistakes name the key.
#[test]
fn distributed_load_mistakes_name_the_key() {
    let text = std::fs::read_to_string(file()).unwrap();
    let err = |t: String| parse_model(&t, &file()).unwrap_err().to_string();
    let e = err(text.replace("beam = \"beam\"\nforce", "beam = \"bem\"\nforce"));
    assert!(
        e.contains("distributed_load[0].beam") && e.contains("no beam named"),
        "{e}"
    );
    let e = err(text.replace("force = [0.0, 0.0, -0.01]        # per unit length", ""));
    assert!(
        e.contains("distributed_load[0]") && e.contains("`force` and/or `moment`"),
        "{e}"
    );
    // `follower = true` is a follower load now (data/statics/follower_tip_force.toml).
    let follower = parse_model(
        &text.replace("# per unit length", "\nfollower = true"),
        &file(),
    );
    assert!(follower.unwrap().distributed_loads[0].follower);
    let e = err(text.replace("# per unit length", "\nweight = 2.0"));
    assert!(e.contains("weight"), "{e}");
}
