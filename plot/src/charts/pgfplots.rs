//! Editable copies of a chart for papers: its data as CSV and a PGFPlots
//! (`.tex`) document that draws the same figure from that CSV, so authors
//! restyle it with their paper's fonts and sizes.
//!
//! `<stem>.csv` has two columns per curve, `x<i>` and `y<i>` in legend order,
//! padded with `nan` where a curve is shorter (PGFPlots then breaks the line,
//! `unbounded coords=jump`; non-finite values, and non-positive ones on a
//! logarithmic axis, are written as `nan` too: the points the chart leaves out).
//! `<stem>.tex` compiles on its own with `pdflatex` (packages `pgfplots` and
//! `geometry` only) to one page holding the figure; the `tikzpicture` inside
//! is what a paper copies. Labels are the chart's, with Greek letters, sub-
//! and superscripts and the minus sign written as LaTeX math.
//!
//! The copy agrees with the PNG and SVG (the `line` module) on what a reader
//! compares: the title, axis labels and legend entries (a curve without a
//! label has none in either), the legend's corner (`legend pos`) or its
//! place below the plot with as many columns, the axis limits, and each
//! curve's colour, dash pattern and markers (solid, as in the PNG). A
//! [`super::Panels`] figure is one `groupplot` with an axis per chart.

use std::fmt::Write as _;
use std::path::Path;

use super::chart::{LineChart, Series};
use super::figure::{Corner, Figure};
use super::style::{Color, PGF_COLOR_NAMES};

fn number(v: f64) -> String {
    if v.is_finite() {
        format!("{v:e}")
    } else {
        "nan".to_owned()
    }
}

/// The chart's data, two columns per curve.
pub fn csv(chart: &LineChart) -> String {
    csv_of(&[("", chart)])
}

/// The data of several charts in one table: two columns per curve, named
/// `<prefix>x<i>`, `<prefix>y<i>`, each chart's after the other's.
pub(super) fn csv_of(charts: &[(&str, &LineChart)]) -> String {
    let mut out = String::new();
    let header: Vec<String> = charts
        .iter()
        .flat_map(|(prefix, chart)| {
            (0..chart.series.len())
                .flat_map(move |i| [format!("{prefix}x{i}"), format!("{prefix}y{i}")])
        })
        .collect();
    out.push_str(&header.join(","));
    out.push('\n');
    let rows = charts
        .iter()
        .flat_map(|(_, c)| c.series.iter().map(|s| s.x.len().min(s.y.len())))
        .max()
        .unwrap_or(0);
    for r in 0..rows {
        let cells: Vec<String> = charts
            .iter()
            .flat_map(|(_, chart)| chart.series.iter().map(move |s| (chart.log_y, s)))
            .flat_map(|(log_y, s): (bool, &Series)| {
                if r < s.x.len().min(s.y.len()) {
                    // A logarithmic axis leaves non-positive values out, as the PNG does.
                    let y = if log_y && s.y[r] <= 0.0 {
                        f64::NAN
                    } else {
                        s.y[r]
                    };
                    [number(s.x[r]), number(y)]
                } else {
                    ["nan".to_owned(), "nan".to_owned()]
                }
            })
            .collect();
        out.push_str(&cells.join(","));
        out.push('\n');
    }
    out
}

/// LaTeX for one character outside plain text, as math where it is math.
fn latex_char(c: char) -> Option<&'static str> {
    Some(match c {
        'α' => "$\\alpha$",
        'β' => "$\\beta$",
        'γ' => "$\\gamma$",
        'Δ' => "$\\Delta$",
        'δ' => "$\\delta$",
        'ε' => "$\\varepsilon$",
        'η' => "$\\eta$",
        'θ' => "$\\theta$",
        'λ' => "$\\lambda$",
        'ρ' => "$\\rho$",
        'ψ' => "$\\psi$",
        'φ' => "$\\varphi$",
        'ω' => "$\\omega$",
        'Ω' => "$\\Omega$",
        '∞' => "$\\infty$",
        '−' => "$-$",
        '–' => "--",
        '—' => "---",
        '×' => "$\\times$",
        '·' => "$\\cdot$",
        '…' => "\\dots{}",
        '≤' => "$\\leq$",
        '≥' => "$\\geq$",
        '|' => "$|$",
        '<' => "$<$",
        '>' => "$>$",
        '\\' => "\\textbackslash{}",
        '&' => "\\&",
        '%' => "\\%",
        '$' => "\\$",
        '#' => "\\#",
        '{' => "\\{",
        '}' => "\\}",
        '~' => "\\textasciitilde{}",
        '_' => "\\_",
        '^' => "\\textasciicircum{}",
        _ => return None,
    })
}

/// Sub- and superscript digits and signs: `(script, its ASCII)`.
fn script(c: char) -> Option<(bool, char)> {
    const SUB: &str = "₀₁₂₃₄₅₆₇₈₉₊₋";
    const SUP: &str = "⁰¹²³⁴⁵⁶⁷⁸⁹⁺⁻";
    const PLAIN: &str = "0123456789+-";
    let plain = |i: usize| PLAIN.chars().nth(i);
    if let Some(i) = SUB.chars().position(|s| s == c) {
        return plain(i).map(|p| (false, p));
    }
    SUP.chars()
        .position(|s| s == c)
        .and_then(|i| plain(i).map(|p| (true, p)))
}

/// A chart label as LaTeX text: special characters escaped, Greek letters
/// and signs as math, runs of sub-/superscript characters as `$_{..}$` /
/// `$^{..}$`, an ASCII subscript of a one-letter symbol `E_ref` as
/// `E$_{\mathrm{ref}}$`, any other underscore (`screw_free`) as `\_`.
pub fn latex(text: &str) -> String {
    let chars: Vec<char> = text.chars().collect();
    let mut out = String::new();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        if let Some((sup, _)) = script(c) {
            let mut run = String::new();
            while let Some((s, p)) = chars.get(i).and_then(|&c| script(c)) {
                if s != sup {
                    break;
                }
                run.push(p);
                i += 1;
            }
            let _ = write!(out, "${}{{{run}}}$", if sup { "^" } else { "_" });
            continue;
        }
        let single_letter =
            i >= 1 && chars[i - 1].is_alphabetic() && (i < 2 || !chars[i - 2].is_alphanumeric());
        if c == '_' && single_letter {
            // An ASCII subscript of a one-letter symbol (`E_ref`, `u_z`).
            let mut run = String::new();
            i += 1;
            while let Some(&c) = chars.get(i).filter(|c| c.is_ascii_alphanumeric()) {
                run.push(c);
                i += 1;
            }
            let _ = write!(out, "$_{{\\mathrm{{{run}}}}}$");
            continue;
        }
        match latex_char(c) {
            Some(s) => out.push_str(s),
            None => out.push(c),
        }
        i += 1;
    }
    out
}

/// The PGFPlots document drawing `chart` from the CSV file `csv_name`
/// (relative to the `.tex` file). Title, axis labels, legend entries, the
/// legend's corner and columns, the axis limits and each curve's colour,
/// pattern and markers are those of the chart's PNG and SVG.
pub fn tex(chart: &LineChart, csv_name: &str) -> String {
    let figure = Figure::prepare(chart, Path::new(csv_name)).ok();
    let mut body = String::from("\\begin{axis}[\n");
    body.push_str(&axis_options(chart, figure.as_ref()));
    body.push_str("]\n");
    body.push_str(&axis_body(chart, csv_name, ""));
    body.push_str("\\end{axis}\n");
    let below = figure.as_ref().map_or(0, legend_rows_below);
    document((15.0, 11.0 + 0.6 * below as f64), false, &body)
}

/// Rows of a legend put below the plot (0 for one inside it).
pub(super) fn legend_rows_below(figure: &Figure) -> usize {
    if figure.legend == Some(Corner::Outside) {
        figure.legend_lines().div_ceil(figure.legend_columns.max(1))
    } else {
        0
    }
}

/// A whole `.tex` document: page size in cm, whether it needs the
/// `groupplots` library, and the `tikzpicture`'s body.
pub(super) fn document((width, height): (f64, f64), groups: bool, body: &str) -> String {
    let mut t = String::from(
        "% Made by flexmech: the chart's data are in the CSV file next to this one.\n\
         % Compile with pdflatex; copy the tikzpicture into a paper to restyle it.\n\
         \\documentclass{article}\n",
    );
    let _ = writeln!(
        t,
        "\\usepackage[paperwidth={width}cm,paperheight={height}cm,margin=0.3cm]{{geometry}}"
    );
    t.push_str("\\usepackage{pgfplots}\n");
    if groups {
        t.push_str("\\usepgfplotslibrary{groupplots}\n");
    }
    t.push_str("\\pgfplotsset{compat=1.16}\n\\pagestyle{empty}\n");
    for (name, c) in PGF_COLOR_NAMES.iter().zip(Color::PALETTE) {
        let _ = writeln!(
            t,
            "\\definecolor{{{name}}}{{RGB}}{{{},{},{}}}",
            c.r, c.g, c.b
        );
    }
    t.push_str("\\begin{document}\n\\begin{tikzpicture}\n");
    t.push_str(body);
    t.push_str("\\end{tikzpicture}\n\\end{document}\n");
    t
}

/// The options of one chart's axis (one per line, inside `[…]`): the
/// look, the PNG's limits and legend place (when the chart can be drawn),
/// labels and title.
pub(super) fn axis_options(chart: &LineChart, figure: Option<&Figure>) -> String {
    let mut t = String::from("  width=13.5cm, height=8.5cm, grid=major, grid style={gray!25},\n");
    let columns = figure.map_or(1, |f| f.legend_columns.max(1));
    let _ = writeln!(
        t,
        "  unbounded coords=jump, legend cell align=left, legend columns={columns},"
    );
    let place = match figure.and_then(|f| f.legend.map(|c| (f, c))) {
        Some((f, Corner::Outside)) => {
            // As far below the plot, in its heights, as the PNG's legend.
            let lay = f.layout(1.0);
            let (_, top, _, bottom) = lay.plot;
            let (_, legend_top, _, _) = f.legend_box(&lay, Corner::Outside);
            format!(
                "at={{(0,{:.3})}}, anchor=north west",
                -(legend_top - bottom) / (bottom - top)
            )
        }
        Some((_, corner)) => format!("legend pos={}", pgf_corner(corner)),
        None => "legend pos=north east".to_owned(),
    };
    if place.starts_with("legend pos") {
        let _ = writeln!(t, "  {place},");
        t.push_str("  legend style={font=\\small, draw=gray!60, fill=white},\n");
    } else {
        let _ = writeln!(
            t,
            "  legend style={{font=\\small, draw=gray!60, fill=white, {place}}},"
        );
    }
    if let Some(f) = figure {
        let lay = f.layout(1.0);
        let y = |v: f64| number(if f.log_y { 10f64.powf(v) } else { v });
        let _ = writeln!(
            t,
            "  xmin={}, xmax={}, ymin={}, ymax={},",
            number(lay.x.lo),
            number(lay.x.hi),
            y(lay.y.lo),
            y(lay.y.hi)
        );
    }
    let _ = writeln!(t, "  xlabel={{{}}},", latex(&chart.x_label));
    let _ = writeln!(t, "  ylabel={{{}}},", latex(&chart.y_label));
    if !chart.title.is_empty() {
        let _ = writeln!(t, "  title={{{}}},", latex(&chart.title));
    }
    if chart.log_y {
        t.push_str("  ymode=log, log basis y=10,\n");
    }
    if !chart.markers.is_empty() {
        t.push_str("  clip=false,\n");
    }
    t
}

/// The PGFPlots legend position of a corner inside the plot.
fn pgf_corner(corner: Corner) -> &'static str {
    match corner {
        Corner::UpperRight | Corner::Outside => "north east",
        Corner::UpperLeft => "north west",
        Corner::LowerRight => "south east",
        Corner::LowerLeft => "south west",
    }
}

/// The `\addplot`s of one chart (columns `<prefix>x<i>`, `<prefix>y<i>`
/// of `csv_name`), their legend entries and the marker lines. A curve
/// without a label is left out of the legend (`forget plot`), as in the PNG.
pub(super) fn axis_body(chart: &LineChart, csv_name: &str, prefix: &str) -> String {
    let mut t = String::new();
    for (i, s) in chart.series.iter().enumerate() {
        let points =
            s.x.iter()
                .zip(&s.y)
                .filter(|&(x, &y)| x.is_finite() && y.is_finite() && (!chart.log_y || y > 0.0))
                .count();
        let (color, dash, marker, every) = s.resolved_style(i, points);
        let marks = match (marker.pgf(), every) {
            (None, _) | (_, 0) => "no markers".to_owned(),
            (Some(m), 1) => format!("mark={m}, mark size=1.5pt, mark options={{solid}}"),
            (Some(m), k) => {
                format!("mark={m}, mark size=1.5pt, mark options={{solid}}, mark repeat={k}")
            }
        };
        let forget = if s.label.is_empty() {
            ", forget plot"
        } else {
            ""
        };
        let _ = writeln!(
            t,
            "\\addplot[{}, {}, thick, {marks}{forget}] table[x={prefix}x{i}, y={prefix}y{i}, col sep=comma] {{{csv_name}}};",
            color.pgf(),
            dash.pgf()
        );
        if !s.label.is_empty() {
            let _ = writeln!(t, "\\addlegendentry{{{}}}", latex(&s.label));
        }
    }
    for (x, label) in &chart.markers {
        let _ = writeln!(
            t,
            "\\draw[gray, dashed] ({{axis cs:{0},0}} |- {{rel axis cs:0,0}}) -- ({{axis cs:{0},0}} |- {{rel axis cs:0,1}}) \
             node[above, font=\\small] {{{1}}};",
            number(*x),
            latex(label)
        );
    }
    t
}

/// Compiles `tex` (a file [`write()`] made) with `pdflatex` into the PDF next
/// to it — vector graphics with the paper's own LaTeX fonts — and removes
/// the run's `.aux` and `.log`. Fails naming `pdflatex` when it is not
/// installed, or with the end of its log when the document does not compile.
pub fn compile_pdf(tex: &Path) -> Result<std::path::PathBuf, String> {
    let dir = tex
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let name = tex.file_name().ok_or("no file name")?;
    let out = std::process::Command::new("pdflatex")
        .args(["-interaction=nonstopmode", "-halt-on-error"])
        .arg(name)
        .current_dir(dir)
        .output()
        .map_err(|e| {
            format!(
                "PDF output needs pdflatex with pgfplots (Debian/Ubuntu: apt-get install \
                 texlive-latex-base texlive-pictures texlive-latex-recommended): {e}"
            )
        })?;
    for ext in ["aux", "log"] {
        let _ = std::fs::remove_file(tex.with_extension(ext));
    }
    if !out.status.success() {
        let log = String::from_utf8_lossy(&out.stdout);
        let tail: Vec<&str> = log.lines().rev().take(12).collect();
        return Err(format!(
            "pdflatex failed on {}:\n{}",
            tex.display(),
            tail.into_iter().rev().collect::<Vec<_>>().join("\n")
        ));
    }
    Ok(tex.with_extension("pdf"))
}

/// Writes `<stem>.csv` and `<stem>.tex` for `chart`.
pub fn write(chart: &LineChart, csv_path: &Path, tex_path: &Path) -> std::io::Result<()> {
    std::fs::write(csv_path, csv(chart))?;
    let name = csv_path
        .file_name()
        .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
    std::fs::write(tex_path, tex(chart, &name))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_become_latex() {
        assert_eq!(latex("Δt (s)"), "$\\Delta$t (s)");
        assert_eq!(
            latex("|E − E₀| / E_ref"),
            "$|$E $-$ E$_{0}$$|$ / E$_{\\mathrm{ref}}$"
        );
        assert_eq!(latex("×10⁻³"), "$\\times$10$^{-3}$");
        assert_eq!(latex("50% & $"), "50\\% \\& \\$");
        assert_eq!(latex("screw_free: u_z"), "screw\\_free: u$_{\\mathrm{z}}$");
    }

    #[test]
    fn csv_pads_short_curves_with_nan() {
        let mut c = LineChart::new("", "x", "y");
        c.series.push(Series::new(
            "a",
            vec![0.0, 1.0, 2.0],
            vec![1.0, f64::NAN, 3.0],
        ));
        c.series.push(Series::new("b", vec![0.5], vec![-1.0]));
        assert_eq!(
            csv(&c),
            "x0,y0,x1,y1\n0e0,1e0,5e-1,-1e0\n1e0,nan,nan,nan\n2e0,3e0,nan,nan\n"
        );
    }
}
