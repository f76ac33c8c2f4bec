//! Several charts in one figure: panels side by side in a row, or in rows
//! and columns, each drawn exactly as the chart alone ([`WIDTH`] ×
//! [`HEIGHT`] px per panel), written as one PNG, one SVG, and one PGFPlots
//! copy (a `groupplot` with an axis per panel, the data of every panel in
//! one CSV).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use plotters::coord::Shift;
use plotters::prelude::*;

use super::chart::LineChart;
use super::figure::{Figure, HEIGHT, WIDTH};
use super::line::{render_files, with_suffix, Canvas, ChartError};
use super::pgfplots::{axis_body, axis_options, compile_pdf, csv_of, document, legend_rows_below};

/// A figure of several [`LineChart`]s laid out in rows of `columns` panels,
/// filled row by row (a last row may be short). Each panel keeps its own
/// title, labels and legend.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Panels {
    /// The charts, in reading order.
    pub charts: Vec<LineChart>,
    /// Panels per row (0: all in one row).
    pub columns: usize,
}

impl Panels {
    /// The charts side by side in one row.
    pub fn row(charts: Vec<LineChart>) -> Self {
        Self { charts, columns: 0 }
    }

    /// The charts in rows of `columns` panels.
    pub fn grid(columns: usize, charts: Vec<LineChart>) -> Self {
        Self { charts, columns }
    }

    /// `(columns, rows)` of the layout.
    pub fn shape(&self) -> (usize, usize) {
        let n = self.charts.len().max(1);
        let columns = match self.columns {
            0 => n,
            c => c.min(n),
        };
        (columns, n.div_ceil(columns))
    }

    /// Draws the figure into `<stem>.png` (1600×1000 px per panel) and
    /// `<stem>.svg`, writes its editable copies `<stem>.csv` (columns
    /// `p<k>x<i>`, `p<k>y<i>` for curve `i` of panel `k`, from 1) and
    /// `<stem>.tex` (PGFPlots `groupplots`), and returns the PNG and SVG
    /// paths. A chart that cannot be drawn alone is an error naming the
    /// PNG; nothing is written then.
    pub fn render(&self, stem: &Path) -> Result<(PathBuf, PathBuf), ChartError> {
        let png = with_suffix(stem, ".png");
        if self.charts.is_empty() {
            return Err(ChartError::NoSeries { path: png });
        }
        let figures = self
            .charts
            .iter()
            .map(|c| Figure::prepare(c, &png))
            .collect::<Result<Vec<_>, _>>()?;
        let canvas = PanelCanvas {
            figures,
            shape: self.shape(),
        };
        let csv = with_suffix(stem, ".csv");
        render_files(&canvas, stem, |tex| {
            let name = csv
                .file_name()
                .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
            let io = |path: &Path| {
                let path = path.to_path_buf();
                move |source| ChartError::Io { path, source }
            };
            std::fs::write(&csv, self.csv()).map_err(io(&csv))?;
            std::fs::write(tex, self.tex(&canvas.figures, &name)).map_err(io(tex))
        })
    }

    /// [`Self::render`], then the PDF of the PGFPlots copy (`<stem>.pdf`, by
    /// `pdflatex`).
    pub fn render_with_pdf(&self, stem: &Path) -> Result<(PathBuf, PathBuf, PathBuf), ChartError> {
        let (png, svg) = self.render(stem)?;
        let tex = with_suffix(stem, ".tex");
        let pdf = compile_pdf(&tex).map_err(|why| ChartError::Pdf { path: tex, why })?;
        Ok((png, svg, pdf))
    }

    fn prefixes(&self) -> Vec<String> {
        (1..=self.charts.len()).map(|k| format!("p{k}")).collect()
    }

    fn csv(&self) -> String {
        let prefixes = self.prefixes();
        let tables: Vec<(&str, &LineChart)> = prefixes
            .iter()
            .map(String::as_str)
            .zip(&self.charts)
            .collect();
        csv_of(&tables)
    }

    /// One `groupplot` of an axis per chart. The gaps between the axes hold
    /// their labels, and below a row the tallest legend put under a plot.
    fn tex(&self, figures: &[Figure], csv_name: &str) -> String {
        let (columns, rows) = self.shape();
        let below = figures.iter().map(legend_rows_below).max().unwrap_or(0);
        let v_sep = 3.0 + 0.6 * below as f64;
        let mut body = String::new();
        let _ = writeln!(
            body,
            "\\begin{{groupplot}}[group style={{group size={columns} by {rows}, \
             horizontal sep=2.5cm, vertical sep={v_sep}cm}}]"
        );
        for ((chart, figure), prefix) in self.charts.iter().zip(figures).zip(self.prefixes()) {
            body.push_str("\\nextgroupplot[\n");
            body.push_str(&axis_options(chart, Some(figure)));
            body.push_str("]\n");
            body.push_str(&axis_body(chart, csv_name, &prefix));
        }
        body.push_str("\\end{groupplot}\n");
        let size = (
            15.0 * columns as f64,
            11.0 * rows as f64 + (v_sep - 2.5) * (rows - 1) as f64 + 0.6 * below as f64,
        );
        document(size, true, &body)
    }
}

/// The prepared panels and their `(columns, rows)`.
struct PanelCanvas {
    figures: Vec<Figure>,
    shape: (usize, usize),
}

impl Canvas for PanelCanvas {
    fn size(&self) -> (u32, u32) {
        let (columns, rows) = self.shape;
        (WIDTH * columns as u32, HEIGHT * rows as u32)
    }

    fn paint<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        scale: f64,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        root.fill(&WHITE)?;
        let (columns, rows) = self.shape;
        let areas = root.split_evenly((rows, columns));
        for (area, figure) in areas.iter().zip(&self.figures) {
            figure.draw(area, scale)?;
        }
        Ok(())
    }
}
