//! What a result file says about itself: when, by which build and command it
//! was made, and the mesh (labels, elements, beams) needed to draw the
//! mechanism without the model text; joint angles only where a joint has one.

use crate::common::{read, read_counts, read_strings, string_attr};
use flexmech::results::run_model;
use flexmech::results::ResultReader;
use std::path::Path;

fn counts(file: &Path, name: &str) -> Vec<usize> {
    read_counts(file, name)
        .into_iter()
        .map(|n| n as usize)
        .collect()
}

#[test]
fn the_file_is_enough_to_draw_the_mechanism() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/dynamics/free_chain.toml");
    let text = std::fs::read_to_string(&path)
        .unwrap()
        .replace("t_end = 1.0", "t_end = 0.02");
    let model = flexmech::model::parse_model(&text, &path).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let file = run_model(&model, dir.path()).unwrap().file;

    // Provenance.
    let attr = |name: &str| -> String { string_attr(&file, name) };
    let created = attr("created");
    assert_eq!(created.len(), 20, "{created}");
    assert!(
        created.starts_with("20") && created.ends_with('Z'),
        "{created}"
    );
    assert!(!attr("git_revision").is_empty());
    assert!(attr("units").contains("radians"));
    assert!(!attr("command_line").is_empty());

    // Labels in /configuration order: one per node, every beam's ends named.
    let labels = read_strings(&file, "/mesh/node_labels");
    let n = labels.len();
    let x0 = read(&file, "/configuration/position");
    assert_eq!(x0.len() % (3 * n), 0, "T×{n}×3");
    for beam in &model.beams {
        assert!(labels.contains(&format!("{}.start", beam.name)));
        assert!(labels.contains(&format!("{}.end", beam.name)));
    }

    // Beams: their nodes in order; at t = 0 consecutive nodes of a straight
    // beam are its length over its node intervals apart.
    let names = read_strings(&file, "/mesh/beam_names");
    let nodes = counts(&file, "/mesh/beam_nodes");
    let offsets = counts(&file, "/mesh/beam_offsets");
    assert_eq!(names.len(), model.beams.len());
    assert_eq!((offsets[0], *offsets.last().unwrap()), (0, nodes.len()));
    let at = |k: usize| nalgebra::Vector3::new(x0[3 * k], x0[3 * k + 1], x0[3 * k + 2]);
    for (b, beam) in model.beams.iter().enumerate() {
        assert_eq!(names[b], beam.name);
        let own = &nodes[offsets[b]..offsets[b + 1]];
        assert_eq!(labels[own[0]], format!("{}.start", beam.name));
        let span = (at(own[own.len() - 1]) - at(own[0])).norm();
        for w in own.windows(2) {
            let gap = (at(w[1]) - at(w[0])).norm();
            assert!((gap - span / (own.len() - 1) as f64).abs() <= 1e-12 * span.max(1.0));
        }
    }

    // Elements: 2 or 3 nodes each, all of one beam, covering every node.
    let element_nodes = counts(&file, "/mesh/element_nodes");
    let element_offsets = counts(&file, "/mesh/element_offsets");
    let elements: usize = model.beams.iter().map(|b| b.elements).sum();
    assert_eq!(element_offsets.len(), elements + 1);
    let mut seen = vec![false; n];
    for e in element_offsets.windows(2) {
        let own = &element_nodes[e[0]..e[1]];
        assert!((2..=3).contains(&own.len()));
        let beam = |k: usize| labels[k].split('.').next().unwrap().to_owned();
        assert!(own.iter().all(|&k| beam(k) == beam(own[0])));
        own.iter().for_each(|&k| seen[k] = true);
    }
    assert!(seen.iter().all(|&s| s));

    // Angles where a joint has one: not the rigid or prismatic joint.
    let r = ResultReader::open(&file).unwrap();
    for joint in [
        "revolute",
        "spherical",
        "cylindrical",
        "screw",
        "rack_pinion",
        "cam",
        "lobe",
    ] {
        assert!(r.has(&format!("/joints/{joint}/angle")), "{joint}");
    }
    for joint in ["rigid", "prismatic"] {
        assert!(!r.has(&format!("/joints/{joint}/angle")), "{joint}");
        assert!(
            r.has(&format!("/joints/{joint}/released_translation")),
            "{joint}"
        );
    }
}
