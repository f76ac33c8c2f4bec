//! Load fields written in Rust (`[[rust_load]]`): the same forces as a
//! model-file load give the same run bit for bit; a static tip force
//! meets the linear cantilever's deflection; the result file's model says
//! that the model runs only with its functions, and a restart from it
//! needs them bound.

use flexmech::prelude::*;
use flexmech::results::ResultReader;

/// Steel-like rod section: EA, GA, GJ, EI, ρA, ρJ.
const EA: f64 = 1e7;
const GA: f64 = 4e6;
const EI: f64 = 1e3;
/// The cantilever's tip force (along z) and length.
const F: f64 = -0.5;
const L: f64 = 2.0;

fn rod() -> SectionValues {
    SectionValues {
        ea: EA,
        ga: [GA; 2],
        gj: 800.0,
        ei: [EI; 2],
        rho_a: 1.0,
        rho_j: [1e-3; 3],
    }
}

fn cantilever(name: &str) -> ModelBuilder {
    let straight = BeamGeometry::Straight {
        start: Vector3::zeros(),
        end: Vector3::new(L, 0.0, 0.0),
        e2: Vector3::y(),
    };
    Model::new(name)
        .section("rod", rod())
        .beam("arm", "rod", straight, 16)
        .support("arm.start", "all")
        .track("arm.end")
}

fn tip(memory: &Memory) -> Vec<[f64; 3]> {
    memory.positions("arm.end").unwrap()
}

#[test]
fn a_rust_load_equals_the_model_file_load_bit_for_bit() {
    let dynamic = |b: ModelBuilder| b.dynamic(Integrator::EnergyMomentum, 0.01, 0.3);
    let file_load = dynamic(cantilever("arm").load("arm.end", [0.0, 0.0, F], [0.0; 3]))
        .build()
        .unwrap();
    let rust_load =
        dynamic(cantilever("arm").rust_load("tip", &["arm.end"], |_, out| out[0][2] = F))
            .build()
            .unwrap();
    let (mut a, mut b) = (Memory::default(), Memory::default());
    run(&file_load, &mut a).unwrap();
    run(&rust_load, &mut b).unwrap();
    assert_eq!(b.status(), "completed");
    assert_eq!(tip(&a), tip(&b));
}

#[test]
fn a_static_rust_load_meets_the_linear_cantilever() {
    // The field sees the load factor λ as its time: F λ at the tip. A tip
    // load of |F| L² / EI = 2e-3 is linear to ~1e-6. The n two-node
    // elements with one-point shear/bending quadrature hold a constant
    // curvature per element; their tip deflection is the Timoshenko beam's
    // with the bending part times (1 − 1/(4n²)):
    // w = F L³ / (3 EI) (1 − 1/(4n²)) + F L / GA.
    let model = cantilever("arm")
        .rust_load("tip", &["arm.end"], |lambda, out| out[0][2] = F * lambda)
        .statics(4)
        .build()
        .unwrap();
    let mut memory = Memory::default();
    run(&model, &mut memory).unwrap();
    let w = tip(&memory).last().unwrap()[2];
    let n = 16.0;
    let exact = F * L.powi(3) / (3.0 * EI) * (1.0 - 1.0 / (4.0 * n * n)) + F * L / GA;
    assert!(((w - exact) / exact).abs() < 1e-5, "{w} vs {exact}");
}

#[test]
fn a_result_file_says_its_model_needs_the_rust_functions() {
    let field = |t: f64, out: &mut [[f64; 6]]| out[0][2] = F * (3.0 * t).sin();
    let model = cantilever("gust")
        .rust_load("gust", &["arm.end"], field)
        .dynamic(Integrator::EnergyMomentum, 0.01, 0.2)
        .build()
        .unwrap();
    let dir = tempfile::tempdir().unwrap();
    let first = run_model(&model, dir.path()).unwrap().file;
    let stored = ResultReader::open(&first)
        .unwrap()
        .string_attr("model")
        .unwrap();
    assert!(
        stored.starts_with("# Load fields written in Rust: gust."),
        "{stored}"
    );

    // Continued from the stored text alone: refused, naming the fix.
    let longer = stored.replace("t_end = 0.2", "t_end = 0.3");
    let mut again = parse_model(&longer, Path::new("gust.toml")).unwrap();
    let e = restart_model(&again, &first, &dir.path().join("a")).unwrap_err();
    assert!(
        e.to_string().contains("model.bind_load(\"gust\", f)"),
        "{e}"
    );
    let e = again.bind_load("wind", field).unwrap_err();
    assert!(e.to_string().contains("\"gust\""), "{e}");

    // With the function bound, the continuation equals the whole run.
    again.bind_load("gust", field).unwrap();
    let continued = restart_model(&again, &first, &dir.path().join("b")).unwrap();
    let mut whole = again.clone();
    whole.source_text.clear();
    let whole = run_model(&whole, &dir.path().join("c")).unwrap().file;
    let last = |f: &Path| {
        let rows = ResultReader::open(f)
            .unwrap()
            .rows3("/nodes/arm.end/position")
            .unwrap();
        *rows.last().unwrap()
    };
    assert_eq!(last(&continued.file), last(&whole));
}
