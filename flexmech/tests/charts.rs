// Line charts (PNG + SVG with the embedded font) and `flexmech plot` on a
// small result file: files exist and decode, text is real SVG text, NaN gaps
// split curves, logarithmic axes, and every error names what went wrong.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::{Mutex, MutexGuard};

use flexmech::integrators::record::{Energies, StepRecord};
use flexmech::plot::charts::{
    plot_datasets, plot_with, ChartError, LineChart, PlotError, PlotOptions, Series,
};
use flexmech::results::{layout, ReadError, ResultWriter, RunMeta};

/// HDF5 opens files without close-on-exec and locks them: the CLI test's child
/// process must not inherit a file another test is writing. Serialise the
/// tests that touch result files.
fn serial() -> MutexGuard<'static, ()> {
    static SERIAL: Mutex<()> = Mutex::new(());
    SERIAL
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// Set `FLEXMECH_KEEP_CHARTS=<dir>` to keep copies of the charts drawn here
/// for a look.
fn keep(files: &[&Path]) {
    if let Some(dir) = std::env::var_os("FLEXMECH_KEEP_CHARTS") {
        let dir = PathBuf::from(dir);
        std::fs::create_dir_all(&dir).unwrap();
        for f in files {
            std::fs::copy(f, dir.join(f.file_name().unwrap())).unwrap();
        }
    }
}

fn linspace(a: f64, b: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| a + (b - a) * i as f64 / (n - 1) as f64)
        .collect()
}

fn three_series_chart() -> LineChart {
    let t = linspace(0.0, 2.0, 201);
    let series = vec![
        Series::new(
            "tip x",
            t.clone(),
            t.iter().map(|t| 0.8 * (3.0 * t).sin()).collect(),
        ),
        Series::new(
            "tip y",
            t.clone(),
            t.iter().map(|t| 0.5 * (2.0 * t).cos() - 0.2).collect(),
        ),
        Series::new(
            "tip z",
            t.clone(),
            t.iter().map(|t| 0.3 * t - 0.4).collect(),
        ),
    ];
    LineChart {
        title: "Cantilever tip displacement".into(),
        x_label: "time (s)".into(),
        y_label: "displacement (m)".into(),
        log_y: false,
        series,
        markers: vec![(1.37, "failure t = 1.37 s".into())],
    }
}

fn svg_text(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// `<text …>content</text>` elements of an SVG, in order.
fn text_elements(svg: &str) -> Vec<String> {
    svg.split("<text")
        .skip(1)
        .filter_map(|rest| {
            let start = rest.find('>')? + 1;
            let end = rest.find("</text>")?;
            Some(rest[start..end].trim().to_owned())
        })
        .collect()
}

/// Number of `<polyline>`s drawn in the given stroke colour.
fn polylines_in(svg: &str, color: &str) -> usize {
    svg.split("<polyline")
        .skip(1)
        .filter(|p| {
            p.split('>')
                .next()
                .unwrap_or("")
                .contains(&format!("stroke=\"{color}\""))
        })
        .count()
}

const BLUE: &str = "#0072B2";

#[test]
fn three_series_with_a_marker_give_a_png_and_an_svg() {
    let dir = tempfile::tempdir().unwrap();
    let stem = dir.path().join("tip_displacement");
    let (png, svg) = three_series_chart().render(&stem).expect("render");
    keep(&[&png, &svg]);
    assert_eq!(png, dir.path().join("tip_displacement.png"));
    assert_eq!(svg, dir.path().join("tip_displacement.svg"));
    assert!(png.is_file() && svg.is_file());

    let image = image::open(&png).expect("the PNG decodes").to_rgb8();
    assert_eq!(image.dimensions(), (1600, 1000));
    let corner = image.get_pixel(2, 2).0;
    assert_eq!(corner, [255, 255, 255], "white background");
    let count = |rgb: [u8; 3]| image.pixels().filter(|p| p.0 == rgb).count();
    assert!(count([0, 114, 178]) > 500, "first series (blue) is drawn");
    assert!(
        count([213, 94, 0]) > 300,
        "second series (vermilion) is drawn"
    );
    assert!(count([0, 158, 115]) > 100, "third series (green) is drawn");
    let dark = image
        .pixels()
        .filter(|p| p.0.iter().all(|&c| c < 60))
        .count();
    assert!(
        dark > 5_000,
        "axes, frame and text are drawn ({dark} dark pixels)"
    );

    let text = svg_text(&svg);
    assert!(text.contains("width=\"1600\"") && text.contains("height=\"1000\""));
    let texts = text_elements(&text);
    for wanted in [
        "Cantilever tip displacement",
        "time (s)",
        "displacement (m)",
        "tip x",
        "tip y",
        "tip z",
        "failure t = 1.37 s",
    ] {
        assert!(
            texts.iter().any(|t| t == wanted),
            "SVG text {wanted:?} missing; texts: {texts:?}"
        );
    }
    assert!(
        !text.contains("flexmech-sans"),
        "the SVG names real font families, not the internal one"
    );
    assert!(text.contains("DejaVu Sans"));
    // Tick labels use a typographic minus.
    assert!(texts.iter().any(|t| t.starts_with('\u{2212}')), "{texts:?}");
}

#[test]
fn six_series_get_distinct_colours_and_small_values_a_common_factor() {
    let dir = tempfile::tempdir().unwrap();
    let t = linspace(0.0, 10.0, 400);
    // Curves that fill every corner of the plot, so the legend needs room.
    let series = (0..6)
        .map(|k| {
            let phase = k as f64;
            let y = t
                .iter()
                .map(|t| 2.0e-4 * (1.3 * t + phase).sin() * (1.0 + 0.1 * phase))
                .collect();
            Series::new(format!("beam {}", k + 1), t.clone(), y)
        })
        .collect();
    let chart = LineChart {
        title: "Six beams".into(),
        x_label: "time (s)".into(),
        y_label: "axial strain (–)".into(),
        log_y: false,
        series,
        markers: vec![(2.5, "impact".into()), (2.6, "release".into())],
    };
    let (png, svg) = chart.render(&dir.path().join("six")).expect("render");
    keep(&[&png, &svg]);
    let text = svg_text(&svg);
    for color in [
        "#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9",
    ] {
        assert!(polylines_in(&text, color) >= 2, "{color}");
    }
    let texts = text_elements(&text);
    assert!(texts.iter().any(|t| t == "×10⁻⁴"), "{texts:?}");
    for wanted in ["beam 6", "impact", "release"] {
        assert!(texts.iter().any(|t| t == wanted), "{wanted}: {texts:?}");
    }
}

#[test]
fn stems_with_dots_keep_them() {
    let dir = tempfile::tempdir().unwrap();
    let stem = dir.path().join("nested/nodes_bend.end_displacement");
    let (png, svg) = three_series_chart().render(&stem).expect("render");
    assert_eq!(png.file_name().unwrap(), "nodes_bend.end_displacement.png");
    assert_eq!(svg.file_name().unwrap(), "nodes_bend.end_displacement.svg");
    assert!(png.is_file() && svg.is_file());
}

#[test]
fn log_axis_labels_decades_and_skips_non_positive_values() {
    let dir = tempfile::tempdir().unwrap();
    let k: Vec<f64> = (0..12).map(f64::from).collect();
    // A converging residual that hits exactly zero and goes negative at the end.
    let residual: Vec<f64> = k
        .iter()
        .map(|&k| if k < 10.0 { 10f64.powf(-k) } else { -k })
        .collect();
    let chart = LineChart {
        title: "Newton convergence".into(),
        x_label: "iteration".into(),
        y_label: "scaled residual".into(),
        log_y: true,
        series: vec![
            Series::new("residual", k.clone(), residual),
            Series::new("tolerance", vec![0.0, 11.0], vec![1e-8, 1e-8]),
        ],
        markers: vec![],
    };
    let (png, svg) = chart.render(&dir.path().join("log")).expect("render");
    keep(&[&png, &svg]);
    image::open(&png).expect("the PNG decodes");
    let texts = text_elements(&svg_text(&svg));
    for decade in ["10⁰", "10⁻⁴", "10⁻⁸"] {
        assert!(texts.iter().any(|t| t == decade), "{decade}: {texts:?}");
    }

    let all_negative = LineChart {
        log_y: true,
        series: vec![Series::new("bad", vec![0.0, 1.0], vec![0.0, -1.0])],
        ..chart
    };
    let err = all_negative
        .render(&dir.path().join("negative"))
        .unwrap_err();
    assert!(
        matches!(&err, ChartError::NoPositivePoints { label, .. } if label == "bad"),
        "{err}"
    );
    assert!(err.to_string().contains("negative.png"), "{err}");
    assert!(!dir.path().join("negative.png").exists());
}

#[test]
fn nan_and_infinite_points_split_the_line() {
    let dir = tempfile::tempdir().unwrap();
    let x = linspace(0.0, 1.0, 50);
    let whole: Vec<f64> = x.iter().map(|x| x * x).collect();
    let mut gappy = whole.clone();
    gappy[20] = f64::NAN;
    gappy[21] = f64::NAN;
    gappy[35] = f64::INFINITY;
    let mut x_gappy = x.clone();
    x_gappy[45] = f64::NAN;

    let solid = LineChart {
        series: vec![Series::new("whole", x.clone(), whole)],
        ..LineChart::new("", "x", "y")
    };
    let (_, svg) = solid.render(&dir.path().join("whole")).unwrap();
    assert_eq!(
        polylines_in(&svg_text(&svg), BLUE),
        2,
        "curve + legend sample"
    );

    let split = LineChart {
        series: vec![Series::new("gappy", x_gappy, gappy)],
        ..LineChart::new("", "x", "y")
    };
    let (png, svg) = split.render(&dir.path().join("gappy")).unwrap();
    keep(&[&png, &svg]);
    image::open(&png).expect("the PNG decodes");
    // Runs 0..20, 22..35, 36..45, 46..50, plus the legend sample.
    assert_eq!(polylines_in(&svg_text(&svg), BLUE), 5);
}

#[test]
fn unusable_data_are_typed_errors_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let stem = dir.path().join("bad");
    let base = three_series_chart();
    let with = |series: Vec<Series>| LineChart {
        series,
        ..base.clone()
    };

    let err = with(vec![]).render(&stem).unwrap_err();
    assert!(matches!(err, ChartError::NoSeries { .. }), "{err}");

    let err = with(vec![Series::new("empty", vec![], vec![])])
        .render(&stem)
        .unwrap_err();
    assert!(
        matches!(&err, ChartError::EmptySeries { label, .. } if label == "empty"),
        "{err}"
    );

    let err = with(vec![
        base.series[0].clone(),
        Series::new(
            "nan",
            vec![0.0, 1.0, f64::NAN],
            vec![f64::NAN, f64::NAN, 1.0],
        ),
    ])
    .render(&stem)
    .unwrap_err();
    assert!(
        matches!(&err, ChartError::NoFinitePoints { label, .. } if label == "nan"),
        "{err}"
    );

    let err = with(vec![Series::new("short", vec![0.0, 1.0], vec![1.0])])
        .render(&stem)
        .unwrap_err();
    assert!(
        matches!(
            &err,
            ChartError::LengthMismatch {
                x_len: 2,
                y_len: 1,
                ..
            }
        ),
        "{err}"
    );

    let err = LineChart {
        markers: vec![(f64::NAN, "never".into())],
        ..base.clone()
    }
    .render(&stem)
    .unwrap_err();
    assert!(matches!(err, ChartError::BadMarker { .. }), "{err}");

    let message = err.to_string();
    assert!(
        message.contains(&stem.with_extension("png").display().to_string()),
        "{message}"
    );
    assert!(!stem.with_extension("png").exists());
    assert!(!stem.with_extension("svg").exists());
}

// --- flexmech plot ----------------------------------------------------------

const STEPS: usize = 12;

fn record(step: usize) -> StepRecord {
    let t = 0.1 * (step + 1) as f64;
    StepRecord {
        time: t,
        dt: 0.1,
        iterations: 3,
        factorizations: 3,
        residual: 1e-11,
        residual_history: vec![1.0, 1e-5, 1e-11],
        beta: f64::NAN,
        energy: Energies {
            kinetic: 0.0,
            strain: 50.0 * t * t,
            potential: -10.0 * t,
            total: 50.0 * t * t - 10.0 * t,
            driver_work: 0.0,
            dissipated: 0.0,
        },
        momentum_linear: [0.0; 3],
        momentum_angular: [0.0; 3],
        positions: vec![[0.0; 3], [1.0 - 0.1 * t * t, 0.0, 0.4 * t]],
        quaternions: vec![[1.0, 0.0, 0.0, 0.0]; 2],
        joints: vec![],
        support_reactions: vec![],
        negative_pivots: None,
        velocities: Vec::new(),
        angular_velocities: Vec::new(),
        sensitivities: Vec::new(),
        critical: None,
    }
}

/// A static run of a two-node "bend" model tracking node 1 as `bend.end`.
fn write_result(path: &Path, status: &str) {
    let meta = RunMeta {
        model_text: "# chart test\n".into(),
        integrator: "static".into(),
        initial_positions: vec![[0.0; 3], [1.0, 0.0, 0.0]],
        tracked: vec![("bend.end".into(), 1)],
        joint_names: vec![],
        ..Default::default()
    };
    let mut writer = ResultWriter::create(path, &meta).expect("create the result file");
    for k in 0..STEPS {
        writer.append(&record(k)).expect("append");
    }
    writer.finish(status, 0.5).expect("finish");
}

#[test]
fn plot_draws_scalar_and_vector_datasets_over_time() {
    let _guard = serial();
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("bend.h5");
    write_result(&file, layout::STATUS_COMPLETED);
    let out = dir.path().join("plots");

    let written = plot_datasets(
        &file,
        &[
            layout::ENERGY_STRAIN.to_owned(),
            "nodes/bend.end/displacement".to_owned(),
        ],
        &out,
        false,
    )
    .expect("plot");
    keep(&written.iter().map(PathBuf::as_path).collect::<Vec<_>>());
    let names: Vec<PathBuf> = ["energy_strain", "nodes_bend.end_displacement"]
        .iter()
        .flat_map(|n| ["png", "svg", "tex", "csv"].map(|e| out.join(format!("{n}.{e}"))))
        .collect();
    assert_eq!(written, names);
    assert!(written.iter().all(|f| f.is_file()), "{written:?}");
    for png in written.iter().step_by(4) {
        let image = image::open(png).expect("the PNG decodes");
        assert_eq!((image.width(), image.height()), (1600, 1000));
    }

    let strain = text_elements(&svg_text(&names[1]));
    // Axis labels in words with units, not dataset paths.
    assert!(strain.iter().any(|t| t == "load factor"), "{strain:?}");
    assert!(
        strain.iter().any(|t| t == "strain energy (J)"),
        "{strain:?}"
    );
    assert!(strain.iter().any(|t| t == "strain"), "legend: {strain:?}");
    assert!(
        strain.iter().any(|t| t.starts_with("bend.h5")),
        "title: {strain:?}"
    );

    let displacement = svg_text(&names[5]);
    let texts = text_elements(&displacement);
    for wanted in ["x", "y", "z"] {
        assert!(texts.iter().any(|t| t == wanted), "{wanted}: {texts:?}");
    }
    assert!(texts.iter().any(|t| t.ends_with("(m)")), "unit: {texts:?}");
    // y (all zero) and z components are drawn: three colours of curves.
    for color in ["#0072B2", "#D55E00", "#009E73"] {
        assert!(polylines_in(&displacement, color) >= 2, "{color}");
    }

    // Logarithmic strain energy.
    let written = plot_datasets(&file, &["/energy/strain".to_owned()], &out, true).unwrap();
    let texts = text_elements(&svg_text(&written[1]));
    assert!(texts.iter().any(|t| t.starts_with("10")), "{texts:?}");
}

#[test]
fn plot_errors_name_the_dataset_and_what_exists() {
    let _guard = serial();
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("bend.h5");
    write_result(&file, layout::STATUS_COMPLETED);
    let out = dir.path().join("plots");

    let err =
        plot_datasets(&file, &["/nodes/bend.end/displacment".into()], &out, false).unwrap_err();
    let message = err.to_string();
    assert!(
        matches!(err, PlotError::Read(ReadError::UnknownDataset { .. })),
        "{message}"
    );
    assert!(message.contains("bend.h5"), "{message}");
    assert!(message.contains("/nodes/bend.end/displacment"), "{message}");
    assert!(
        message.contains("/nodes/bend.end/displacement"),
        "{message}"
    );
    assert!(message.contains("/nodes/bend.end/rotation"), "{message}");
    assert!(
        !message.contains("/energy/strain"),
        "only that group: {message}"
    );

    // A missing group: the listing comes from the nearest existing one.
    let err = plot_datasets(&file, &["/energy/elastic".into()], &out, false).unwrap_err();
    let message = err.to_string();
    assert!(message.contains("/energy/kinetic"), "{message}");

    // A group is not a dataset.
    let err = plot_datasets(&file, &["/energy".into()], &out, false).unwrap_err();
    assert!(
        matches!(err, PlotError::Read(ReadError::UnknownDataset { .. })),
        "{err}"
    );

    // T × nodes × 3 and Σ iterations are not chartable shapes.
    let err = plot_datasets(&file, &["/configuration/position".into()], &out, false).unwrap_err();
    let message = err.to_string();
    assert!(
        matches!(&err, PlotError::BadShape { shape, .. } if shape == &[STEPS, 2, 3]),
        "{message}"
    );
    assert!(message.contains("/configuration/position"), "{message}");
    assert!(message.contains("12×2×3"), "{message}");
    let err = plot_datasets(&file, &["/solver/newton_residuals".into()], &out, false).unwrap_err();
    assert!(matches!(err, PlotError::BadShape { .. }), "{err}");

    // Nothing was written for a request with a bad dataset in it.
    let err = plot_datasets(
        &file,
        &["/energy/strain".into(), "/nope".into()],
        &out,
        false,
    )
    .unwrap_err();
    assert!(
        matches!(err, PlotError::Read(ReadError::UnknownDataset { .. })),
        "{err}"
    );
    assert!(!out.join("energy_strain.png").exists());
}

#[test]
fn plot_marks_where_a_failed_run_stopped() {
    let _guard = serial();
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("broken.h5");
    write_result(&file, &layout::failed_status("Newton did not converge"));
    let written = plot_datasets(&file, &["/solver/iterations".into()], dir.path(), false)
        .expect("u64 datasets plot too");
    keep(&[&written[0]]);
    let texts = text_elements(&svg_text(&written[1]));
    assert!(
        texts.iter().any(|t| t == "failed: Newton did not converge"),
        "{texts:?}"
    );
}

#[test]
fn flexmech_plot_command() {
    let _guard = serial();
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("bend.h5");
    write_result(&file, layout::STATUS_COMPLETED);
    let out = dir.path().join("figures");
    let run = Command::new(env!("CARGO_BIN_EXE_flexmech"))
        .arg("plot")
        .arg(&file)
        .args(["/energy/total", "/momentum/linear", "--log", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    // Total energy is negative at first: left out on the log axis, the
    // rest is drawn. Linear momentum is all zero: nothing is left, an error.
    assert!(!run.status.success());
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(stderr.contains("/momentum/linear"), "{stderr}");
    assert!(stderr.contains("logarithmic"), "{stderr}");

    let run = Command::new(env!("CARGO_BIN_EXE_flexmech"))
        .arg("plot")
        .arg(&file)
        .args(["/energy/total", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(stdout.contains("energy_total.png"), "{stdout}");
    assert!(out.join("energy_total.png").is_file());
    assert!(out.join("energy_total.svg").is_file());
}

/// The CSV next to a chart: `x<i>`, `y<i>` columns, `nan` for missing values.
fn read_csv(path: &Path) -> Vec<Vec<f64>> {
    let text = std::fs::read_to_string(path).expect("the CSV exists");
    let mut lines = text.lines();
    let columns = lines.next().expect("a header").split(',').count();
    let mut cols = vec![Vec::new(); columns];
    for line in lines {
        for (c, v) in line.split(',').enumerate() {
            cols[c].push(v.parse::<f64>().expect("a number or nan"));
        }
    }
    cols
}

/// `pdflatex` on `tex` in its directory: Ok(false) when it is not installed
/// and the environment does not require it.
fn compiles(tex: &Path) -> bool {
    let required = std::env::var_os("FLEXMECH_REQUIRE_PDFLATEX").is_some();
    let out = Command::new("pdflatex")
        .args(["-interaction=nonstopmode", "-halt-on-error"])
        .arg(tex.file_name().expect("a file"))
        .current_dir(tex.parent().expect("a directory"))
        .output();
    let Ok(out) = out else {
        assert!(
            !required,
            "pdflatex is required (FLEXMECH_REQUIRE_PDFLATEX is set)"
        );
        eprintln!("skipped: pdflatex is not installed; the PGFPlots files were not compiled");
        return false;
    };
    assert!(
        out.status.success(),
        "{} does not compile:\n{}",
        tex.display(),
        String::from_utf8_lossy(&out.stdout)
    );
    let pdf = tex.with_extension("pdf");
    assert!(
        std::fs::metadata(&pdf)
            .map(|m| m.len() > 1000)
            .unwrap_or(false),
        "no PDF"
    );
    true
}

#[test]
fn every_chart_gets_its_data_as_csv_and_a_pgfplots_file_that_compiles() {
    let dir = tempfile::tempdir().unwrap();
    let k: Vec<f64> = (0..8).map(f64::from).collect();
    let log = LineChart {
        title: String::new(),
        x_label: "Δt (s)".into(),
        y_label: "|E − E₀| / E_ref".into(),
        log_y: true,
        series: vec![
            Series::new(
                "energy–momentum (β)",
                k.clone(),
                k.iter().map(|k| 10f64.powf(-k)).collect(),
            ),
            Series::new("two points", vec![0.0, 7.0], vec![1e-3, -1.0]),
        ],
        markers: vec![],
    };
    for (chart, stem) in [(three_series_chart(), "linear"), (log, "log")] {
        let (png, _) = chart.render(&dir.path().join(stem)).expect("render");
        let csv = read_csv(&png.with_extension("csv"));
        assert_eq!(csv.len(), 2 * chart.series.len());
        for (i, s) in chart.series.iter().enumerate() {
            for (r, (&x, &y)) in s.x.iter().zip(&s.y).enumerate() {
                assert_eq!(csv[2 * i][r], x, "{stem}: x{i} row {r}");
                let drawn = if chart.log_y && y <= 0.0 { f64::NAN } else { y };
                let same =
                    csv[2 * i + 1][r] == drawn || (drawn.is_nan() && csv[2 * i + 1][r].is_nan());
                assert!(
                    same,
                    "{stem}: y{i} row {r}: {} vs {drawn}",
                    csv[2 * i + 1][r]
                );
            }
            assert!(
                csv[2 * i][s.x.len()..].iter().all(|v| v.is_nan()),
                "padding"
            );
        }
        let tex = png.with_extension("tex");
        let text = std::fs::read_to_string(&tex).expect("the .tex exists");
        assert_eq!(text.matches("\\addplot[").count(), chart.series.len());
        if compiles(&tex) {
            // The PDF output of `plot --pdf` / `reproduce --pdf`.
            let stem = dir.path().join(format!("{stem}-pdf"));
            let (_, _, pdf) = chart.render_with_pdf(&stem).expect("a PDF");
            let bytes = std::fs::read(&pdf).expect("the PDF exists");
            assert!(bytes.starts_with(b"%PDF") && bytes.len() > 1000);
            assert!(
                !stem.with_extension("log").exists(),
                "pdflatex's log is removed"
            );
        }
    }
}

#[test]
fn plot_labels_units_draws_x_y_plots_and_overlays_files() {
    let _guard = serial();
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("first.h5"), dir.path().join("second.h5"));
    write_result(&a, layout::STATUS_COMPLETED);
    write_result(&b, layout::STATUS_COMPLETED);
    let out = dir.path().join("plots");
    // Default labels: the description with its unit, and the load factor.
    plot_datasets(
        &a,
        &["/nodes/bend.end/displacement".to_owned()],
        &out,
        false,
    )
    .expect("plot");
    let tex = std::fs::read_to_string(out.join("nodes_bend.end_displacement.tex")).unwrap();
    assert!(
        tex.contains("(m)}") && tex.contains("xlabel={load factor}"),
        "{tex}"
    );
    // x–y: the tip's z displacement over its x position, two files, no title.
    let options = PlotOptions {
        x: Some("/nodes/bend.end/position[0]".into()),
        y_label: Some("tip deflection (m)".into()),
        title: Some(String::new()),
        overlay: vec![b.clone()],
        ..PlotOptions::default()
    };
    let written = plot_with(
        &a,
        &["/nodes/bend.end/displacement".to_owned()],
        &out,
        &options,
    )
    .expect("x-y plot");
    let csv = read_csv(&written[0].with_extension("csv"));
    assert_eq!(csv.len(), 2 * 6, "three components of two files");
    assert_eq!(csv[0].len(), STEPS);
    for (k, ((&x, &z), &z2)) in csv[0].iter().zip(&csv[5]).zip(&csv[11]).enumerate() {
        let t = 0.1 * (k + 1) as f64;
        assert_eq!(x, 1.0 - 0.1 * t * t, "x is the position's first component");
        assert_eq!(z, 0.4 * t, "z displacement of the first file");
        assert_eq!(z2, z, "the second file's z");
    }
    let tex = std::fs::read_to_string(written[0].with_extension("tex")).unwrap();
    assert!(
        tex.contains("addlegendentry{second: z}") && !tex.contains("title="),
        "{tex}"
    );
    assert!(tex.contains("ylabel={tip deflection (m)}"), "{tex}");
    // A T×3 abscissa needs its component.
    let bad = PlotOptions {
        x: Some("/nodes/bend.end/position".into()),
        ..PlotOptions::default()
    };
    let err = plot_with(&a, &[layout::ENERGY_STRAIN.to_owned()], &out, &bad).unwrap_err();
    assert!(err.to_string().contains("[0]"), "{err}");
}

/// `(x, y)` of the SVG `<text>` element whose content is `content`.
fn text_position(svg: &str, content: &str) -> Option<(f64, f64)> {
    svg.split("<text").skip(1).find_map(|rest| {
        let start = rest.find('>')? + 1;
        let end = rest.find("</text>")?;
        if rest[start..end].trim() != content {
            return None;
        }
        let attr = |name: &str| -> Option<f64> {
            let at = rest.find(&format!(" {name}=\""))? + name.len() + 3;
            rest[at..].split('"').next()?.parse().ok()
        };
        Some((attr("x")?, attr("y")?))
    })
}

/// The `{…}` of every `key={…}` (one level of braces inside) in a `.tex`.
fn tex_values(tex: &str, key: &str) -> Vec<String> {
    tex.split(key)
        .skip(1)
        .filter_map(|rest| {
            let mut depth = 0usize;
            for (i, c) in rest.char_indices() {
                match c {
                    '{' => depth += 1,
                    '}' if depth == 1 => return Some(rest[1..i].to_owned()),
                    '}' => depth = depth.saturating_sub(1),
                    _ => {}
                }
            }
            None
        })
        .collect()
}

#[test]
fn the_svg_and_the_tex_agree_on_labels_legend_entries_and_the_legend_corner() {
    use flexmech::plot::charts::pgfplots::latex;
    let dir = tempfile::tempdir().unwrap();
    // Rising curves fill the upper right: the legend goes upper left. An
    // unlabelled curve has no legend entry in either file.
    let x = linspace(0.0, 1.0, 60);
    let rising = |k: f64| x.iter().map(|x| k * x * x).collect::<Vec<f64>>();
    let upper_left = LineChart {
        title: "Tip of the arm".into(),
        x_label: "time (s)".into(),
        y_label: "Δz (m)".into(),
        log_y: false,
        series: vec![
            Series::new("run 1", x.clone(), rising(1.0)),
            Series::new("", x.clone(), rising(0.9)),
            Series::new("run 3", x.clone(), rising(0.8)),
        ],
        markers: vec![],
    };
    // Eight crossing curves leave no corner free: the legend goes below the
    // plot, left-aligned, in three columns.
    let t = linspace(0.0, 2.0, 201);
    let below = LineChart {
        series: (0..8)
            .map(|k| {
                let y = t.iter().map(|t| ((k + 1) as f64 * t).sin()).collect();
                Series::new(format!("mode {k}"), t.clone(), y)
            })
            .collect(),
        ..LineChart::new("Modes", "time (s)", "amplitude (m)")
    };
    for (chart, stem, corner) in [
        (&upper_left, "upper_left", "legend pos=north west"),
        (&below, "below", "anchor=north west"),
    ] {
        let (_, svg) = chart.render(&dir.path().join(stem)).expect("render");
        let svg = svg_text(&svg);
        let texts = text_elements(&svg);
        let tex = std::fs::read_to_string(dir.path().join(format!("{stem}.tex"))).unwrap();
        for (key, label) in [
            ("title=", &chart.title),
            ("xlabel=", &chart.x_label),
            ("ylabel=", &chart.y_label),
        ] {
            assert_eq!(texts.iter().filter(|t| *t == label).count(), 1, "{label}");
            assert_eq!(tex_values(&tex, key), [latex(label)], "{stem}: {key}");
        }
        let labelled: Vec<&String> = chart
            .series
            .iter()
            .map(|s| &s.label)
            .filter(|l| !l.is_empty())
            .collect();
        let in_tex = tex_values(&tex, "\\addlegendentry");
        assert_eq!(in_tex.len(), labelled.len(), "{stem}: {in_tex:?}");
        for (label, entry) in labelled.iter().zip(&in_tex) {
            assert_eq!(texts.iter().filter(|t| t == label).count(), 1, "{label}");
            assert_eq!(entry, &latex(label));
        }
        assert!(tex.contains(corner), "{stem}: {tex}");
        let (lx, ly) = text_position(&svg, labelled[0]).expect("the legend's first entry");
        match stem {
            "upper_left" => assert!(lx < 800.0 && ly < 500.0, "upper left: {lx}, {ly}"),
            _ => {
                assert!(tex.contains("legend columns=3"), "{tex}");
                assert!(lx < 400.0 && ly > 800.0, "below, at the left: {lx}, {ly}");
            }
        }
    }
}

#[test]
fn panels_draw_each_chart_as_it_is_alone() {
    use flexmech::plot::charts::{Color, Dash, Marker, Panels};
    let dir = tempfile::tempdir().unwrap();
    let first = three_series_chart();
    let mut second = three_series_chart();
    second.title = "Styled".into();
    second.series[0] = second.series[0]
        .clone()
        .color(Color::rgb(120, 0, 0))
        .dash(Dash::LongDashed)
        .marker(Marker::Triangle);
    second.series[2] = second.series[2].clone().marker(Marker::Cross);
    let (a, _) = first.render(&dir.path().join("first")).unwrap();
    let (b, _) = second.render(&dir.path().join("second")).unwrap();
    let (row, svg) = Panels::row(vec![first, second])
        .render(&dir.path().join("row"))
        .unwrap();
    keep(&[&row, &svg]);
    let row = image::open(&row).unwrap().to_rgb8();
    assert_eq!(row.dimensions(), (3200, 1000));
    for (k, alone) in [a, b].iter().enumerate() {
        let alone = image::open(alone).unwrap().to_rgb8();
        let panel = image::imageops::crop_imm(&row, 1600 * k as u32, 0, 1600, 1000).to_image();
        assert!(panel == alone, "panel {k} is drawn as the chart alone");
    }
    let texts = text_elements(&svg_text(&svg));
    assert!(texts.iter().any(|t| t == "Styled"));
    let tex = std::fs::read_to_string(dir.path().join("row.tex")).unwrap();
    assert!(
        tex.contains("mark=triangle*") && tex.contains("mark=x"),
        "{tex}"
    );
    compiles(&dir.path().join("row.tex"));
}

/// A two-run study of the driven screw (its pitch swept, five steps), run
/// by the `flexmech` binary below `dir`; returns its output directory.
fn screw_pitch_study(dir: &Path) -> PathBuf {
    let model = Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/paper/screw_driven.toml");
    let study = dir.join("pitch.toml");
    std::fs::write(
        &study,
        format!(
            "name = \"pitch\"\nmodel = \"{}\"\n\n[grid]\n\"joint.screw.pitch\" = [0.01, 0.03]\n\
             \"solver.t_end\" = [0.05]\n",
            model.display()
        ),
    )
    .unwrap();
    let run = Command::new(env!("CARGO_BIN_EXE_flexmech"))
        .arg("study")
        .arg(&study)
        .arg("--out")
        .arg(dir.join("studies"))
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    dir.join("studies").join("pitch")
}

#[test]
fn flexmech_plot_over_a_study_overlays_its_runs_named_by_their_values() {
    let _guard = serial();
    let dir = tempfile::tempdir().unwrap();
    let study = screw_pitch_study(dir.path());
    let out = dir.path().join("plots");
    let run = Command::new(env!("CARGO_BIN_EXE_flexmech"))
        .args(["plot", "--study"])
        .arg(&study)
        .arg("/joints/screw/released_translation[z]")
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let stem = out.join("joints_screw_released_translation_z");
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(
        stdout.contains("joints_screw_released_translation_z.png"),
        "{stdout}"
    );
    let tex = std::fs::read_to_string(stem.with_extension("tex")).expect("the .tex");
    let entries = tex_values(&tex, "\\addlegendentry");
    assert_eq!(entries, ["screw pitch = 0.01", "screw pitch = 0.03"]);
    let texts = text_elements(&svg_text(&stem.with_extension("svg")));
    for entry in &entries {
        assert!(texts.contains(entry), "{entry} in {texts:?}");
    }
    assert!(
        texts.iter().any(|t| t.ends_with(", z (m)")),
        "the y label names the column and unit: {texts:?}"
    );
    // The lift is the pitch times the same prescribed angle: three times
    // as much in the second run.
    let csv = read_csv(&stem.with_extension("csv"));
    assert_eq!(csv.len(), 4, "two runs");
    let (lift_1, lift_3) = (csv[1].last().unwrap(), csv[3].last().unwrap());
    assert!(*lift_1 > 0.0, "{lift_1}");
    assert!((lift_3 / lift_1 - 3.0).abs() < 1e-3, "{lift_1} {lift_3}");

    // A T×3 dataset needs its column; a directory that is no study is
    // refused naming what it should hold; --x has no meaning here.
    let refused = |args: &[&str], dir: &Path| {
        let run = Command::new(env!("CARGO_BIN_EXE_flexmech"))
            .args(["plot", "--study"])
            .arg(dir)
            .args(args)
            .output()
            .unwrap();
        assert!(!run.status.success());
        String::from_utf8_lossy(&run.stderr).into_owned()
    };
    let err = refused(&["/joints/screw/released_translation"], &study);
    assert!(err.contains("released_translation[x]"), "{err}");
    let err = refused(&["/energy/total"], dir.path());
    assert!(err.contains("summary.csv"), "{err}");
    let err = refused(&["/energy/total", "--x", "/time"], &study);
    assert!(err.contains("--x"), "{err}");
}
