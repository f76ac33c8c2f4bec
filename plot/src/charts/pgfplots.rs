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

use std::fmt::Write as _;
use std::path::Path;

use super::chart::{LineChart, Series, AUTO_MARKERS};

/// The curves' colours (Okabe–Ito, as the PNG) and dash patterns.
const COLORS: [(&str, &str); 6] = [
    ("fmblue", "0,114,178"),
    ("fmvermilion", "213,94,0"),
    ("fmgreen", "0,158,115"),
    ("fmpurple", "204,121,167"),
    ("fmorange", "230,159,0"),
    ("fmsky", "86,180,233"),
];
const DASHES: [&str; 6] = [
    "solid",
    "dashed",
    "dotted",
    "dashdotted",
    "densely dashed",
    "loosely dotted",
];

fn number(v: f64) -> String {
    if v.is_finite() {
        format!("{v:e}")
    } else {
        "nan".to_owned()
    }
}

/// The chart's data, two columns per curve.
pub fn csv(chart: &LineChart) -> String {
    let mut out = String::new();
    let header: Vec<String> = (0..chart.series.len())
        .flat_map(|i| [format!("x{i}"), format!("y{i}")])
        .collect();
    out.push_str(&header.join(","));
    out.push('\n');
    let rows = chart
        .series
        .iter()
        .map(|s| s.x.len().min(s.y.len()))
        .max()
        .unwrap_or(0);
    for r in 0..rows {
        let cells: Vec<String> = chart
            .series
            .iter()
            .flat_map(|s: &Series| {
                if r < s.x.len().min(s.y.len()) {
                    // A logarithmic axis leaves non-positive values out, as the PNG does.
                    let y = if chart.log_y && s.y[r] <= 0.0 {
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
/// (relative to the `.tex` file).
pub fn tex(chart: &LineChart, csv_name: &str) -> String {
    let mut t = String::from(
        "% Made by flexmech: the chart's data are in the CSV file next to this one.\n\
         % Compile with pdflatex; copy the tikzpicture into a paper to restyle it.\n\
         \\documentclass{article}\n\
         \\usepackage[paperwidth=15cm,paperheight=11cm,margin=0.3cm]{geometry}\n\
         \\usepackage{pgfplots}\n\
         \\pgfplotsset{compat=1.16}\n\\pagestyle{empty}\n",
    );
    for (name, rgb) in COLORS {
        let _ = writeln!(t, "\\definecolor{{{name}}}{{RGB}}{{{rgb}}}");
    }
    t.push_str("\\begin{document}\n\\begin{tikzpicture}\n\\begin{axis}[\n");
    t.push_str("  width=13.5cm, height=8.5cm, grid=major, grid style={gray!25},\n");
    t.push_str("  unbounded coords=jump, legend cell align=left, legend columns=2,\n");
    t.push_str("  legend style={font=\\small, draw=gray!60, at={(0.5,-0.2)}, anchor=north},\n");
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
    t.push_str("]\n");
    for (i, s) in chart.series.iter().enumerate() {
        let (color, _) = COLORS[i % COLORS.len()];
        let points =
            s.x.iter()
                .zip(&s.y)
                .filter(|(x, y)| x.is_finite() && y.is_finite())
                .count();
        let marks = match s.mark_every {
            0 if points <= AUTO_MARKERS => "mark=*, mark size=1.5pt".to_owned(),
            0 => "no markers".to_owned(),
            k => format!("mark=*, mark size=1.5pt, mark repeat={k}"),
        };
        let _ = writeln!(
            t,
            "\\addplot[{color}, {}, thick, {marks}] table[x=x{i}, y=y{i}, col sep=comma] {{{csv_name}}};",
            DASHES[i % DASHES.len()]
        );
        if s.label.is_empty() {
            t.push_str("\\addlegendentry{}\n");
        } else {
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
    t.push_str("\\end{axis}\n\\end{tikzpicture}\n\\end{document}\n");
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
