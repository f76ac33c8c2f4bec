//! Series styles, panels and the PGFPlots copy's agreement with the PNG and
//! SVG, on files written to a scratch directory.

use std::path::PathBuf;

use super::pgfplots::{latex, tex};
use super::{Color, Dash, LineChart, Marker, Panels, Series};

/// A fresh scratch directory for one test.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("flexmech-plot-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Width and height of a PNG, from its header.
fn png_size(path: &std::path::Path) -> (u32, u32) {
    let bytes = std::fs::read(path).unwrap();
    let be = |i: usize| u32::from_be_bytes(bytes[i..i + 4].try_into().unwrap());
    (be(16), be(20))
}

fn wave(label: &str, phase: f64) -> Series {
    let x: Vec<f64> = (0..101).map(|i| f64::from(i) / 50.0).collect();
    let y = x.iter().map(|t| (3.0 * t + phase).sin()).collect();
    Series::new(label, x, y)
}

fn chart(title: &str, series: Vec<Series>) -> LineChart {
    let mut c = LineChart::new(title, "time (s)", "angle (rad)");
    c.series = series;
    c
}

#[test]
fn a_series_keeps_its_own_colour_dash_and_marker_in_the_svg_and_the_tex() {
    let dir = scratch("styles");
    let c = chart(
        "styled",
        vec![
            wave("automatic", 0.0),
            wave("own", 1.0)
                .color(Color::rgb(200, 30, 40))
                .dash(Dash::DashDot)
                .marker(Marker::Square),
            Series::new("short, no marks", vec![0.0, 1.0, 2.0], vec![0.1, 0.2, 0.1])
                .marker(Marker::None),
        ],
    );
    let (_, svg) = c.render(&dir.join("styled")).unwrap();
    let svg = std::fs::read_to_string(svg).unwrap();
    // The first series keeps the automatic cycle's blue; the second is drawn
    // in its own colour with filled squares (rectangles) and no circles.
    assert!(svg.contains("stroke=\"#0072B2\""));
    assert!(svg.contains("stroke=\"#C81E28\""));
    let squares = svg.matches("<rect").count();
    assert!(svg.contains("fill=\"#C81E28\""), "filled squares");
    assert!(
        squares > 12,
        "about a dozen squares and the legend's: {squares}"
    );
    let circles_in = |color: &str| {
        svg.split("<circle")
            .skip(1)
            .filter(|c| c.split('>').next().unwrap_or("").contains(color))
            .count()
    };
    assert_eq!(circles_in("#C81E28"), 0);
    assert_eq!(
        circles_in("#009E73"),
        0,
        "Marker::None: a short curve unmarked"
    );

    let tex = std::fs::read_to_string(dir.join("styled.tex")).unwrap();
    let plots: Vec<&str> = tex.lines().filter(|l| l.starts_with("\\addplot")).collect();
    assert!(
        plots[0].starts_with("\\addplot[fmblue, solid, thick, no markers]"),
        "{}",
        plots[0]
    );
    assert!(
        plots[1].contains("color={rgb,255:red,200;green,30;blue,40}, dashdotted")
            && plots[1].contains("mark=square*")
            && plots[1].contains("mark repeat=9"),
        "{}",
        plots[1]
    );
    assert!(
        plots[2].contains("fmgreen, dotted, thick, no markers"),
        "{}",
        plots[2]
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn every_dash_and_marker_has_a_pgfplots_style() {
    for (i, dash) in Dash::CYCLE.into_iter().enumerate() {
        assert_eq!(dash.pixels().is_empty(), i == 0);
        assert!(!dash.pgf().is_empty());
    }
    let marks = [
        Marker::Circle,
        Marker::Square,
        Marker::Triangle,
        Marker::Diamond,
        Marker::Cross,
        Marker::Plus,
    ];
    assert!(marks.iter().all(|m| m.pgf().is_some()));
    assert_eq!(Marker::None.pgf(), None);
}

#[test]
fn panels_are_one_png_svg_and_groupplot() {
    let dir = scratch("panels");
    let charts = vec![
        chart("first", vec![wave("a", 0.0)]),
        chart("second", vec![wave("b", 0.5), wave("c", 1.0)]),
        chart("third", vec![wave("d", 2.0)]),
    ];
    let (png, svg) = Panels::row(charts.clone())
        .render(&dir.join("row"))
        .unwrap();
    assert_eq!(png_size(&png), (3 * 1600, 1000));
    let svg = std::fs::read_to_string(svg).unwrap();
    for title in ["first", "second", "third"] {
        assert!(
            svg.contains(&format!(">\n{title}\n</text>"))
                || svg.contains(&format!(">{title}</text>"))
        );
    }
    let tex = std::fs::read_to_string(dir.join("row.tex")).unwrap();
    assert!(tex.contains("group size=3 by 1"), "{tex}");
    assert_eq!(tex.matches("\\nextgroupplot[").count(), 3);
    assert!(tex.contains("table[x=p2x1, y=p2y1, col sep=comma] {row.csv}"));
    let csv = std::fs::read_to_string(dir.join("row.csv")).unwrap();
    assert_eq!(
        csv.lines().next(),
        Some("p1x0,p1y0,p2x0,p2y0,p2x1,p2y1,p3x0,p3y0")
    );

    let grid = Panels::grid(2, charts);
    assert_eq!(grid.shape(), (2, 2));
    let (png, _) = grid.render(&dir.join("grid")).unwrap();
    assert_eq!(png_size(&png), (2 * 1600, 2 * 1000));
    let tex = std::fs::read_to_string(dir.join("grid.tex")).unwrap();
    assert!(tex.contains("group size=2 by 2"), "{tex}");
    if std::process::Command::new("pdflatex")
        .arg("--version")
        .output()
        .is_ok()
    {
        let (_, _, pdf) = Panels::row(vec![chart("alone", vec![wave("e", 0.0)])])
            .render_with_pdf(&dir.join("pdf"))
            .unwrap();
        assert!(std::fs::read(pdf).unwrap().starts_with(b"%PDF"));
        super::pgfplots::compile_pdf(&dir.join("grid.tex")).expect("the grid compiles");
    }
    let empty = Panels::row(Vec::new()).render(&dir.join("none"));
    assert!(empty.is_err());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_tex_has_the_pngs_labels_legend_entries_and_legend_corner() {
    // Rising curves fill the upper right: the legend goes upper left.
    let x: Vec<f64> = (0..50).map(f64::from).collect();
    let rising = |k: f64| x.iter().map(|x| k * x * x).collect::<Vec<f64>>();
    let mut c = chart(
        "Δ of the tip",
        vec![
            Series::new("k = 1", x.clone(), rising(1.0)),
            Series::new("", x.clone(), rising(0.9)),
            Series::new("k = 0.8", x.clone(), rising(0.8)),
        ],
    );
    c.y_label = "E_ref (J)".into();
    let figure = super::figure::Figure::prepare(&c, std::path::Path::new("x.png")).unwrap();
    assert_eq!(figure.legend, Some(super::figure::Corner::UpperLeft));
    let t = tex(&c, "c.csv");
    assert!(t.contains("legend pos=north west"), "{t}");
    assert!(t.contains(&format!("title={{{}}}", latex("Δ of the tip"))));
    assert!(t.contains("ylabel={E$_{\\mathrm{ref}}$ (J)}"), "{t}");
    let entries: Vec<&str> = t
        .lines()
        .filter_map(|l| l.strip_prefix("\\addlegendentry{")?.strip_suffix('}'))
        .collect();
    assert_eq!(
        entries,
        ["k = 1", "k = 0.8"],
        "no entry for the unlabelled curve"
    );
    assert!(t.contains("forget plot"));
}

/// A description longer than its axis is set smaller, to fit along it; one
/// that fits keeps the usual size.
#[test]
fn a_long_axis_description_is_set_to_fit_its_axis() {
    use super::figure::{Figure, DESC_FONT};
    use super::font::text_width;
    let dir = scratch("long-label");
    let long = "released translation r_R in the master frame, x (m), of the cam's follower";
    let mut c = LineChart::new("long", "time (s)", long);
    c.series = vec![wave("a", 0.0)];
    let figure = Figure::prepare(&c, &dir.join("long.png")).unwrap();
    let lay = figure.layout(1.0);
    let (_, top, _, bottom) = lay.plot;
    assert!(
        text_width(long, DESC_FONT) > bottom - top,
        "the label is longer than the axis"
    );
    assert!(lay.desc_font < DESC_FONT);
    assert!(text_width(long, lay.desc_font) <= bottom - top);
    let short = Figure::prepare(
        &chart("short", vec![wave("a", 0.0)]),
        &dir.join("short.png"),
    );
    assert_eq!(short.unwrap().layout(1.0).desc_font, DESC_FONT);
    c.render(&dir.join("long")).unwrap();
}
