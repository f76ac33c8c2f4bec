//! `[output] resultants = true`: the stress resultants at every Gauss point
//! against a tip-loaded cantilever's statics, `n(s) = F`, `m(s) = (L − s) x̂ × F`.

use std::path::Path;

use flexmech::model::parse_model;
use flexmech::results::run_model_to;
use flexmech::results::{layout, ResultReader};

const F: f64 = 0.01;

/// The cantilever of `data/statics/distributed_load.toml` with a tip force
/// `−F ẑ` instead of the line load, writing resultants.
fn run(nodes_per_element: usize, dir: &Path) -> ResultReader {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/statics/distributed_load.toml");
    let text = std::fs::read_to_string(&path)
        .unwrap()
        .replace(
            "[[distributed_load]]\nbeam = \"beam\"\nforce = [0.0, 0.0, -0.01]        # per unit length",
            &format!("[[load]]\nnode = \"beam.end\"\nforce = [0.0, 0.0, {}]", -F),
        )
        .replace(
            "elements = 10",
            &format!("elements = 10\nnodes_per_element = {nodes_per_element}"),
        )
        .replace("[output]\n", "[output]\nresultants = true\n");
    let model = parse_model(&text, &path).unwrap();
    let file = dir.join(format!("r{nodes_per_element}.h5"));
    run_model_to(&model, &file).unwrap();
    ResultReader::open(&file).unwrap()
}

/// Shear `N₃ = −F` and bending `M₂ = F (L − s)` at every Gauss point, axial
/// force, torsion and the other components zero — to 1e-4 of `F` and `FL`
/// (the material frame turns by `FL²/2EI = 5e-6` under the load); one point
/// per 2-node element, two per 3-node one, in element order with their arc
/// lengths and the beam's range.
#[test]
fn resultants_are_the_statics_of_a_tip_loaded_cantilever() {
    let dir = tempfile::tempdir().unwrap();
    for npe in [2, 3] {
        let r = run(npe, dir.path());
        let s = r.values(layout::RESULTANTS_ARC_LENGTH).unwrap();
        assert_eq!(s.len(), 10 * (npe - 1));
        assert!(s.windows(2).all(|w| w[1] > w[0]) && s[s.len() - 1] < 1.0);
        let shape = r.shape(layout::RESULTANTS_FORCE).unwrap();
        assert_eq!(shape[1..], [s.len(), 3]);
        let n = r.values(layout::RESULTANTS_FORCE).unwrap();
        let m = r.values(layout::RESULTANTS_MOMENT).unwrap();
        // The last stored step (the full load).
        let row = (shape[0] - 1) * 3 * s.len();
        for (g, &sg) in s.iter().enumerate() {
            let at = |v: &[f64], c: usize| v[row + 3 * g + c];
            let expected_n = [0.0, 0.0, -F];
            let expected_m = [0.0, F * (1.0 - sg), 0.0];
            for c in 0..3 {
                assert!(
                    (at(&n, c) - expected_n[c]).abs() < 1e-4 * F,
                    "npe {npe}, s = {sg}: N{} = {} against {}",
                    c + 1,
                    at(&n, c),
                    expected_n[c]
                );
                assert!(
                    (at(&m, c) - expected_m[c]).abs() < 1e-4 * F,
                    "npe {npe}, s = {sg}: M{} = {} against {}",
                    c + 1,
                    at(&m, c),
                    expected_m[c]
                );
            }
        }
        let (_, offsets) = r.resultant_beams().unwrap();
        assert_eq!(offsets, vec![0, s.len() as u64]);
    }
}

/// Without the key the file has no `/resultants`.
#[test]
fn resultants_are_written_only_when_asked() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/statics/distributed_load.toml");
    let model = parse_model(&std::fs::read_to_string(&path).unwrap(), &path).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let out = run_model_to(&model, &dir.path().join("r.h5")).unwrap();
    assert!(!ResultReader::open(&out.file)
        .unwrap()
        .has(layout::RESULTANTS));
}

/// `flexmech plot` draws a resultant over the Gauss points' arc length.
#[test]
fn resultants_are_charted_over_the_arc_length() {
    let dir = tempfile::tempdir().unwrap();
    let r = run(3, dir.path());
    let charts = flexmech::plot::charts::plot_datasets(
        r.path(),
        &["/resultants/moment".to_owned()],
        &dir.path().join("plots"),
        false,
    )
    .unwrap();
    assert_eq!(charts.len(), 4, "png, svg, tex, csv");
    assert!(std::fs::metadata(&charts[0]).unwrap().len() > 10_000);
    let svg = std::fs::read_to_string(&charts[1]).unwrap();
    assert!(
        svg.contains("M2 bending") && svg.contains("arc length"),
        "{}",
        &svg[..200]
    );
}
