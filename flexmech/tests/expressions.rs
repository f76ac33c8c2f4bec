//! Time functions written as expressions (`{ expr = "…" }`): the parser's
//! precedence and functions against hand-computed values, its derivatives
//! (num-dual, exact) against analytic derivatives, refusals that point at
//! the character and the key, and the payoff in a run — a prescribed motion
//! written as an expression starts at its exact rate, so its velocity follows
//! `f′(t)` to O(Δt²), where the same motion as a table starts at rest and
//! carries an O(1) velocity error.

use flexmech::model::{parse_model, Expression, TimeFunction};
use flexmech::results::run_model_to;
use flexmech::results::ResultReader;
use std::f64::consts::PI;
use std::path::Path;

fn value(text: &str, t: f64) -> f64 {
    Expression::parse(text)
        .unwrap_or_else(|e| panic!("{text}: {e}"))
        .eval(t)
}

#[test]
fn precedence_functions_and_constants() {
    let cases: [(&str, f64); 22] = [
        ("1 + 2*3", 7.0),
        ("(1 + 2)*3", 9.0),
        ("-2^2", -4.0),
        ("2^3^2", 512.0),
        ("2^-1", 0.5),
        ("10 - 4 - 3", 3.0),
        ("12 / 3 / 2", 2.0),
        ("pi", PI),
        ("e", std::f64::consts::E),
        ("2.5e2 + 1E-1", 250.1),
        ("sin(pi/6)", 0.5),
        ("atan2(1, 1)", PI / 4.0),
        ("sqrt(16) + abs(-3)", 7.0),
        ("min(3, t) + max(3, t)", 3.0 + 5.0),
        ("pow(t, 2)", 25.0),
        ("ln(e^2) + log(1)", 2.0),
        ("if(t < 4, 1, 2)", 2.0),
        ("if(t >= 5 && t != 6, 10, 20)", 10.0),
        ("if(t < 1 || t == 5, 1, 0)", 1.0),
        ("!(t > 1)", 0.0),
        ("(t - 5)^2", 0.0),
        ("tanh(0) + cosh(0) + exp(0)", 2.0),
    ];
    for (text, expected) in cases {
        let got = value(text, 5.0);
        assert!(
            (got - expected).abs() <= 1e-12 * expected.abs().max(1.0),
            "{text}: {got}"
        );
    }
    // `lambda` names the argument too (a static analysis's load factor).
    assert_eq!(value("2*lambda", 0.25), 0.5);
    // Integer powers of negative values are defined.
    assert_eq!(value("t^2", -3.0), 9.0);
}

#[test]
fn derivatives_are_exact() {
    // f = sin(t²) e^(−t/2): f′ = (2t cos t² − ½ sin t²) e^(−t/2),
    // f″ = (2 cos t² − 4t² sin t² − 2t cos t² + ¼ sin t²) e^(−t/2).
    let e = Expression::parse("sin(t^2) * exp(-t/2)").unwrap();
    for t in [0.0f64, 0.3, 1.1, 2.7] {
        let (s, c, x) = ((t * t).sin(), (t * t).cos(), (-t / 2.0).exp());
        let f1 = (2.0 * t * c - 0.5 * s) * x;
        let f2 = (2.0 * c - 4.0 * t * t * s - 2.0 * t * c + 0.25 * s) * x;
        let (v, d1, d2) = e.derivatives(t);
        assert!((v - s * x).abs() < 1e-15);
        assert!((d1 - f1).abs() < 1e-13, "t = {t}: {d1} vs {f1}");
        assert!((d2 - f2).abs() < 1e-12, "t = {t}: {d2} vs {f2}");
    }
    // Branches: min, max, abs and if differentiate the branch they take.
    let cases = [
        ("min(t^2, 1)", 0.5, 1.0, 2.0),
        ("min(t^2, 1)", 2.0, 0.0, 0.0),
        ("max(t^3, 0)", 2.0, 12.0, 12.0),
        ("abs(t^3)", -2.0, -12.0, 12.0),
        ("if(t < 1, t^2, 2*t - 1)", 0.5, 1.0, 2.0),
        ("if(t < 1, t^2, 2*t - 1)", 3.0, 2.0, 0.0),
        ("pow(2, t)", 1.0, 2.0 * 2f64.ln(), 2.0 * 2f64.ln().powi(2)),
        ("t^t", 1.0, 1.0, 2.0),
    ];
    for (text, t, f1, f2) in cases {
        let (_, d1, d2) = Expression::parse(text).unwrap().derivatives(t);
        assert!(
            (d1 - f1).abs() < 1e-12,
            "{text} at {t}: f′ = {d1}, expected {f1}"
        );
        assert!(
            (d2 - f2).abs() < 1e-12,
            "{text} at {t}: f″ = {d2}, expected {f2}"
        );
    }
}

#[test]
fn malformed_expressions_point_at_the_character() {
    let cases = [
        ("sin(t", 5, "expected `,` or `)`"),
        ("2 * foo(t)", 4, "unknown function `foo`"),
        ("2 * omega", 4, "unknown name `omega`"),
        ("max(1)", 0, "`max` takes 2 arguments, found 1"),
        ("if(t, 1)", 0, "`if` takes 3 arguments"),
        ("1 +", 3, "ends where a value is expected"),
        ("t t", 2, "unexpected `t` after a complete expression"),
        ("3 # 4", 2, "unexpected `#`"),
        ("1e999", 0, "not a finite number"),
    ];
    for (text, position, words) in cases {
        let e = Expression::parse(text).expect_err(text);
        assert_eq!(e.position, position, "{text}: {e}");
        assert!(e.message.contains(words), "{text}: {e}");
    }
}

/// A cantilever whose clamp moves along x as `prescribed`.
fn shaken(prescribed: &str) -> String {
    format!(
        r#"name = "shaken"

[[section]]
name = "s"
EA = 1.0e4
GA = [5.0e3, 5.0e3]
GJ = 20.0
EI = [10.0, 10.0]
rhoA = 1.0
rhoJ = [0.02, 0.01, 0.01]

[[beam]]
name = "rod"
section = "s"
start = [0.0, 0.0, 0.0]
end = [1.0, 0.0, 0.0]
e2 = [0.0, 1.0, 0.0]
elements = 4

[[support]]
node = "rod.start"
fixed = ["uy", "uz", "rx", "ry", "rz"]

[[prescribed]]
node = "rod.start"
dof = "ux"
value = {prescribed}

[solver]
analysis = "dynamic"
integrator = "newmark"
dt = 0.005
t_end = 1.0

[output]
track = ["rod.start"]
"#
    )
}

#[test]
fn a_prescribed_expression_starts_at_its_exact_rate() {
    // u(t) = 0.01 sin(10 t): the clamp starts at 0.1 m/s. The trapezoidal
    // rule's velocity of a prescribed coordinate is the secant recursion
    // vₙ₊₁ = 2(uₙ₊₁ − uₙ)/Δt − vₙ: from the exact v₀ it follows u′ to
    // O((ωΔt)²) ≈ 2.5e-3 relative; from rest it oscillates by ±u′(0).
    let dir = tempfile::tempdir().unwrap();
    let expr = "{ expr = \"0.01*sin(10*t)\" }";
    let rows: Vec<String> = (0..=200)
        .map(|k| {
            let t = 0.005 * k as f64;
            format!("[{t:?}, {:?}]", 0.01 * (10.0 * t).sin())
        })
        .collect();
    let table = format!("{{ table = [{}] }}", rows.join(", "));
    let worst = |text: &str| {
        let model = parse_model(text, Path::new("shaken.toml")).unwrap();
        let file = dir.path().join("shaken.h5");
        run_model_to(&model, &file).unwrap();
        let r = ResultReader::open(&file).unwrap();
        let t = r.time().unwrap();
        // T × nodes × 3; the clamp is node 0 of 5.
        let v = r.values("/configuration/velocity").unwrap();
        t.iter()
            .enumerate()
            .map(|(k, t)| (v[15 * k] - 0.1 * (10.0 * t).cos()).abs())
            .fold(0.0, f64::max)
    };
    let (from_expr, from_table) = (worst(&shaken(expr)), worst(&shaken(&table)));
    eprintln!("clamp velocity error: expression {from_expr:.2e}, table {from_table:.2e}");
    assert!(from_expr <= 0.1 * 5e-3, "expression: {from_expr}");
    assert!(from_table >= 0.1 * 0.9, "table: {from_table}");
}

#[test]
fn the_spin_up_hub_angle_is_one_line() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/benchmarks/spin_up.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.len() < 4_000, "{} bytes", text.len());
    let model = parse_model(&text, &path).unwrap();
    let TimeFunction::Expression(e) = (match &model.prescribed[0] {
        flexmech::model::PrescribedSpec::NodeDof { value, .. } => value.clone(),
        other => panic!("{other:?}"),
    }) else {
        panic!("not an expression")
    };
    // Simo & Vu-Quoc's θ(t), with θ′ and θ″ (C² at T_s = 15 s).
    let (ws, ts) = (6.0, 15.0);
    let w = 2.0 * PI / ts;
    for k in 0..=300 {
        let t = 0.1 * k as f64;
        let (v, d1, d2) = e.derivatives(t);
        let (f, f1, f2) = if t <= ts {
            (
                ws / ts * (t * t / 2.0 + ((w * t).cos() - 1.0) / (w * w)),
                ws / ts * (t - (w * t).sin() / w),
                ws / ts * (1.0 - (w * t).cos()),
            )
        } else {
            (ws * (t - ts / 2.0), ws, 0.0)
        };
        assert!((v - f).abs() <= 1e-12 * f.abs().max(1.0), "θ({t})");
        assert!((d1 - f1).abs() <= 1e-12 * ws, "θ′({t})");
        assert!((d2 - f2).abs() <= 1e-11, "θ″({t})");
    }
}

#[test]
fn expressions_in_model_files_are_checked_at_their_key() {
    let base = shaken("{ expr = \"0.01*sin(10*t)\" }");
    let error = |text: &str| {
        parse_model(text, Path::new("shaken.toml"))
            .expect_err("refused")
            .to_string()
    };
    let e = error(&base.replace("0.01*sin(10*t)", "0.01*sin(10*t"));
    assert!(
        e.contains("prescribed[0].value") && e.contains("at character 14"),
        "{e}"
    );
    let e = error(&base.replace("0.01*sin(10*t)", "lambda"));
    assert!(
        e.contains("prescribed[0].value") && e.contains("`t`"),
        "{e}"
    );
    let e = error(&base.replace("0.01*sin(10*t)", "1/t"));
    assert!(e.contains("inf") && e.contains("t = 0"), "{e}");
    let e = error(&base.replace(
        "{ expr = \"0.01*sin(10*t)\" }",
        "{ expr = \"t\", table = [[0.0, 0.0]] }",
    ));
    assert!(e.contains("either `table` or `expr`"), "{e}");
    // In statics, `lambda` is the load factor.
    let statics = base
        .replace("analysis = \"dynamic\"", "analysis = \"static\"")
        .replace("integrator = \"newmark\"\ndt = 0.005\nt_end = 1.0\n", "")
        .replace("0.01*sin(10*t)", "0.01*lambda^2");
    parse_model(&statics, Path::new("shaken.toml")).unwrap();
}

#[test]
fn no_input_makes_the_parser_or_the_evaluator_panic() {
    // 20 000 strings over the expression alphabet (a fixed-seed LCG): each
    // parses or is refused with a position inside the text, and whatever
    // parses evaluates (possibly to NaN — refused later at its key).
    let alphabet: Vec<char> = "t1.e5+-*/^(),<>=!&|pi sincoxmaqrtbfl".chars().collect();
    let mut state: u64 = 0x2545_f491_4f6c_dd1d;
    let mut next = || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (state >> 33) as usize
    };
    let mut parsed = 0;
    for _ in 0..20_000 {
        let len = 1 + next() % 24;
        let text: String = (0..len)
            .map(|_| alphabet[next() % alphabet.len()])
            .collect();
        match Expression::parse(&text) {
            Ok(e) => {
                parsed += 1;
                let _ = e.derivatives(0.7);
            }
            Err(err) => assert!(err.position <= text.chars().count(), "{text:?}: {err}"),
        }
    }
    assert!(
        parsed > 100,
        "only {parsed} parsed: the alphabet should make many valid"
    );
    // Deep nesting is refused, not followed into a stack overflow.
    for deep in [
        "(".repeat(100_000),
        "-".repeat(100_000) + "t",
        "sin(".repeat(50_000),
    ] {
        let e = Expression::parse(&deep).expect_err("too deep");
        assert!(e.message.contains("nested"), "{e}");
    }
    let long = vec!["t"; 100_000].join("+");
    let e = Expression::parse(&long).expect_err("too long");
    assert!(e.message.contains("operators"), "{e}");
}
