//! Line charts in a journal style, written as a 1600×1000 px PNG and an SVG of
//! the same layout (with their CSV data and PGFPlots copy, [`super::pgfplots`]).
//!
//! Plotters draws the axes, tick labels, grid and text; this module lays the
//! figure out (title, marker labels, axis areas), draws the curves clipped
//! to the frame ([`super::clip`]) with their own dash patterns
//! ([`super::strokes`]) and markers. The ticks and their labels are
//! [`super::ticks`]'s, the legend's place [`super::legend`]'s — the parts
//! plotters does not provide (common `×10ⁿ` factors, superscript decades,
//! dash-dot patterns, a legend that avoids the data, supersampled PNGs).

use std::ffi::OsString;
use std::path::{Path, PathBuf};

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::chart::{LineChart, Series};
use super::clip::clip_polyline;
use super::figure::*;
use super::font::{self, text_width};
use super::marks::draw_mark;
use super::strokes::{dashed, pixels};
use super::ticks::{Axis, TickRange};

/// Why a chart could not be drawn or written; every variant names the file.
#[derive(Debug, thiserror::Error)]
pub enum ChartError {
    /// The chart has no series at all.
    #[error("chart {}: no series to draw", .path.display())]
    NoSeries {
        /// The PNG that was to be written.
        path: PathBuf,
    },
    /// A series' `x` and `y` differ in length.
    #[error(
        "chart {}: series \"{label}\" has {x_len} x values but {y_len} y values",
        .path.display()
    )]
    LengthMismatch {
        /// The PNG that was to be written.
        path: PathBuf,
        /// The series.
        label: String,
        /// Length of `x`.
        x_len: usize,
        /// Length of `y`.
        y_len: usize,
    },
    /// A series has no points.
    #[error("chart {}: series \"{label}\" is empty", .path.display())]
    EmptySeries {
        /// The PNG that was to be written.
        path: PathBuf,
        /// The series.
        label: String,
    },
    /// Every point of a series has a NaN or infinite coordinate.
    #[error(
        "chart {}: series \"{label}\" has no finite point (all x or y are NaN or infinite)",
        .path.display()
    )]
    NoFinitePoints {
        /// The PNG that was to be written.
        path: PathBuf,
        /// The series.
        label: String,
    },
    /// On a logarithmic axis, no finite point of a series has `y > 0`.
    #[error(
        "chart {}: series \"{label}\" has no positive finite value for the logarithmic y axis",
        .path.display()
    )]
    NoPositivePoints {
        /// The PNG that was to be written.
        path: PathBuf,
        /// The series.
        label: String,
    },
    /// A marker's position is NaN or infinite.
    #[error(
        "chart {}: marker \"{label}\" is at x = {x}, which is not finite",
        .path.display()
    )]
    BadMarker {
        /// The PNG that was to be written.
        path: PathBuf,
        /// The marker's label.
        label: String,
        /// Its position.
        x: f64,
    },
    /// Plotters rejected the embedded font (a packaging bug).
    #[error("chart {}: the embedded font could not be registered", .path.display())]
    Font {
        /// The PNG that was to be written.
        path: PathBuf,
    },
    /// Drawing or encoding failed.
    #[error("chart {}: drawing failed: {message}", .path.display())]
    Draw {
        /// The file being drawn.
        path: PathBuf,
        /// The backend's message.
        message: String,
    },
    /// The PDF could not be made from the chart's PGFPlots file.
    #[error("chart {}: {why}", .path.display())]
    Pdf {
        /// The `.tex` file.
        path: PathBuf,
        /// What went wrong and how to fix it.
        why: String,
    },
    /// The output directory or file could not be written.
    #[error("chart {}: {source}", .path.display())]
    Io {
        /// The file or directory.
        path: PathBuf,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
}

impl LineChart {
    /// Draws the chart into `<stem>.png` (1600×1000 px) and `<stem>.svg`,
    /// writes its editable copies `<stem>.csv` and `<stem>.tex` (PGFPlots,
    /// [`super::pgfplots`]) and returns the PNG and SVG paths. The extensions are appended, so a stem may contain
    /// dots (`out/nodes_arm.end_position`). Missing parent directories are
    /// created. Nothing is written when the data are unusable.
    pub fn render(&self, stem: &Path) -> Result<(PathBuf, PathBuf), ChartError> {
        let png = with_suffix(stem, ".png");
        let figure = Figure::prepare(self, &png)?;
        let csv = with_suffix(stem, ".csv");
        render_files(&figure, stem, |tex| {
            super::pgfplots::write(self, &csv, tex).map_err(|source| ChartError::Io {
                path: csv.clone(),
                source,
            })
        })
    }

    /// [`Self::render`], or [`Self::render_with_pdf`] when `pdf`: every file
    /// written (PNG, SVG, the PGFPlots `.tex`, its data `.csv` and, with
    /// `pdf`, the PDF).
    pub fn render_all(&self, stem: &Path, pdf: bool) -> Result<Vec<PathBuf>, ChartError> {
        let mut files = if pdf {
            let (png, svg, pdf) = self.render_with_pdf(stem)?;
            vec![png, svg, pdf]
        } else {
            let (png, svg) = self.render(stem)?;
            vec![png, svg]
        };
        files.insert(2, with_suffix(stem, ".tex"));
        files.insert(3, with_suffix(stem, ".csv"));
        Ok(files)
    }

    /// [`Self::render`], then the PDF of the chart's PGFPlots copy
    /// (`<stem>.pdf`, by `pdflatex`: [`super::pgfplots::compile_pdf`]).
    pub fn render_with_pdf(&self, stem: &Path) -> Result<(PathBuf, PathBuf, PathBuf), ChartError> {
        let (png, svg) = self.render(stem)?;
        let tex = with_suffix(stem, ".tex");
        let pdf =
            super::pgfplots::compile_pdf(&tex).map_err(|why| ChartError::Pdf { path: tex, why })?;
        Ok((png, svg, pdf))
    }
}

/// What [`render_files`] draws: a canvas of some multiple of the chart size.
pub(super) trait Canvas {
    /// The output size in pixels.
    fn size(&self) -> (u32, u32);

    /// Draws on `root`, a canvas [`Self::size`] times `scale`.
    fn paint<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        scale: f64,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>>;
}

impl Canvas for Figure {
    fn size(&self) -> (u32, u32) {
        (WIDTH, HEIGHT)
    }

    fn paint<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        scale: f64,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        self.draw(root, scale)
    }
}

/// Writes `<stem>.png` and `<stem>.svg` of `canvas`, then the editable
/// copies by `copies` (given the `.tex` path); returns the PNG and SVG.
pub(super) fn render_files<C: Canvas>(
    canvas: &C,
    stem: &Path,
    copies: impl FnOnce(&Path) -> Result<(), ChartError>,
) -> Result<(PathBuf, PathBuf), ChartError> {
    let png = with_suffix(stem, ".png");
    let svg = with_suffix(stem, ".svg");
    if !font::ensure_registered() {
        return Err(ChartError::Font { path: png });
    }
    if let Some(dir) = stem.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|source| ChartError::Io {
            path: dir.to_path_buf(),
            source,
        })?;
    }
    write_png(canvas, &png)?;
    write_svg(canvas, &svg)?;
    copies(&with_suffix(stem, ".tex"))?;
    Ok((png, svg))
}

/// Plotters' bitmap backend does not anti-alias lines: the PNG is drawn at
/// this multiple of its size and averaged down.
const SUPERSAMPLE: u32 = 2;

fn write_png<C: Canvas>(canvas: &C, png: &Path) -> Result<(), ChartError> {
    let (width, height) = canvas.size();
    let (w, h) = (width * SUPERSAMPLE, height * SUPERSAMPLE);
    let mut big = vec![0u8; (w as usize) * (h as usize) * 3];
    {
        let root = BitMapBackend::with_buffer(&mut big, (w, h)).into_drawing_area();
        canvas
            .paint(&root, f64::from(SUPERSAMPLE))
            .and_then(|()| root.present())
            .map_err(|e| draw_error(png, e))?;
    }
    let small = downsample(&big, w as usize, SUPERSAMPLE as usize);
    let mut backend = BitMapBackend::new(png, (width, height));
    backend
        .blit_bitmap((0, 0), (width, height), &small)
        .and_then(|()| backend.present())
        .map_err(|e| ChartError::Draw {
            path: png.to_path_buf(),
            message: e.to_string(),
        })
}

/// Averages `factor`×`factor` blocks of an RGB image `width` pixels wide.
fn downsample(rgb: &[u8], width: usize, factor: usize) -> Vec<u8> {
    let height = rgb.len() / (3 * width);
    let (w, h) = (width / factor, height / factor);
    let mut out = vec![0u8; w * h * 3];
    let n = (factor * factor) as u32;
    for y in 0..h {
        for x in 0..w {
            for c in 0..3 {
                let mut sum = 0u32;
                for dy in 0..factor {
                    let row = (y * factor + dy) * width;
                    for dx in 0..factor {
                        sum += u32::from(rgb[3 * (row + x * factor + dx) + c]);
                    }
                }
                out[3 * (y * w + x) + c] = ((sum + n / 2) / n) as u8;
            }
        }
    }
    out
}

fn write_svg<C: Canvas>(canvas: &C, svg: &Path) -> Result<(), ChartError> {
    let mut text = String::new();
    {
        let root = SVGBackend::with_string(&mut text, canvas.size()).into_drawing_area();
        canvas
            .paint(&root, 1.0)
            .and_then(|()| root.present())
            .map_err(|e| draw_error(svg, e))?;
    }
    let mut text = text.replace(
        &format!("font-family=\"{}\"", font::FAMILY),
        &format!("font-family=\"{}\"", font::SVG_FAMILY),
    );
    // The face itself, right after the opening <svg ...> tag.
    if let Some(end) = text
        .find("<svg")
        .and_then(|s| text[s..].find('>').map(|e| s + e + 1))
    {
        text.insert_str(end, &font::svg_font_face());
    }
    std::fs::write(svg, text).map_err(|source| ChartError::Io {
        path: svg.to_path_buf(),
        source,
    })
}

pub(super) fn with_suffix(stem: &Path, suffix: &str) -> PathBuf {
    let mut name = OsString::from(stem.as_os_str());
    name.push(suffix);
    PathBuf::from(name)
}

fn draw_error<E: std::error::Error + Send + Sync>(
    path: &Path,
    e: DrawingAreaErrorKind<E>,
) -> ChartError {
    ChartError::Draw {
        path: path.to_path_buf(),
        message: e.to_string(),
    }
}

/// The plot frame in pixels of the drawing area: plotters' own mapping of
/// the axes' ends, and the plotting area's pixel ranges.
struct Frame {
    x0: i32,
    y0: i32,
    x1: i32,
    y1: i32,
    area: (std::ops::Range<i32>, std::ops::Range<i32>),
}

impl Frame {
    /// The exact pixel position of a plotted point.
    fn to_px(&self, lay: &Layout, (x, y): (f64, f64)) -> (f64, f64) {
        let (x0, y0) = (f64::from(self.x0), f64::from(self.y0));
        (
            x0 + (x - lay.x.lo) / (lay.x.hi - lay.x.lo) * f64::from(self.x1 - self.x0),
            y0 + (y - lay.y.lo) / (lay.y.hi - lay.y.lo) * f64::from(self.y1 - self.y0),
        )
    }

    /// Left, top, right, bottom, the rectangle curves are clipped to.
    fn rect(&self) -> (f64, f64, f64, f64) {
        (
            f64::from(self.x0),
            f64::from(self.y1),
            f64::from(self.x1),
            f64::from(self.y0),
        )
    }
}

impl Figure {
    pub(super) fn prepare(chart: &LineChart, png: &Path) -> Result<Self, ChartError> {
        // Legend widths are measured with the embedded face: register it
        // first, so the legend's place never depends on what was drawn before.
        font::ensure_registered();
        let path = || png.to_path_buf();
        if chart.series.is_empty() {
            return Err(ChartError::NoSeries { path: path() });
        }
        let curves = chart
            .series
            .iter()
            .enumerate()
            .map(|(i, s)| Curve::of(s, i, chart.log_y, png))
            .collect::<Result<Vec<_>, _>>()?;
        for (x, label) in &chart.markers {
            if !x.is_finite() {
                return Err(ChartError::BadMarker {
                    path: path(),
                    label: label.clone(),
                    x: *x,
                });
            }
        }

        let points = || curves.iter().flat_map(|c| c.runs.iter().flatten());
        let x_range = x_range(min_max(points().map(|p| p.0)), &chart.markers);
        let (d_lo, d_hi) = min_max(points().map(|p| p.1));
        let y_range = if chart.log_y {
            (d_lo, d_hi)
        } else {
            let (lo, hi) = widen_if_flat(d_lo, d_hi);
            let pad = 0.05 * (hi - lo);
            (lo - pad, hi + pad)
        };

        let mut figure = Self {
            title: chart.title.clone(),
            x_label: chart.x_label.clone(),
            y_label: chart.y_label.clone(),
            log_y: chart.log_y,
            curves,
            markers: chart.markers.clone(),
            x_range,
            y_range,
            legend: None,
            legend_columns: 1,
        };
        figure.place_legend(d_hi);
        Ok(figure)
    }

    pub(super) fn layout(&self, scale: f64) -> Layout {
        Layout::compute(self, scale)
    }

    /// Draws the figure on a canvas `scale` times the output size (a whole
    /// drawing area of [`WIDTH`] × [`HEIGHT`] times `scale`).
    pub(super) fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        scale: f64,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        let lay = self.layout(scale);
        let s = scale;
        root.fill(&WHITE)?;
        let frame = self.draw_mesh(root, &lay)?;

        // Markers under the curves.
        let marker_style = MARKER_COLOR.stroke_width(px(1.5 * AXIS_WIDTH * s) as u32);
        let marker_dash: Vec<f64> = MARKER_DASH.iter().map(|d| d * s).collect();
        for (x, _) in &self.markers {
            let line = [
                frame.to_px(&lay, (*x, lay.y.lo)),
                frame.to_px(&lay, (*x, lay.y.hi)),
            ];
            for piece in dashed(&line, &marker_dash) {
                root.draw(&PathElement::new(pixels(&piece), marker_style))?;
            }
        }
        for curve in &self.curves {
            curve.draw(root, &lay, &frame)?;
        }

        // Frame around the plot.
        let (xr, yr) = &frame.area;
        root.draw(&Rectangle::new(
            [(xr.start, yr.start), (xr.end - 1, yr.end - 1)],
            BLACK.stroke_width(px(AXIS_WIDTH * s) as u32),
        ))?;

        self.draw_notes(root, &lay, (frame.x0, frame.y1, frame.x1))?;
        if !self.title.is_empty() {
            root.draw(&Text::new(
                self.title.clone(),
                (px(f64::from(WIDTH) * s / 2.0), px(MARGIN * s)),
                font::text(TITLE_FONT * s).pos(Pos::new(HPos::Center, VPos::Top)),
            ))?;
        }
        if let Some(corner) = self.legend {
            self.draw_legend(root, &lay, corner)?;
        }
        Ok(())
    }

    /// Axes, tick labels, grid and axis labels (plotters'); returns where
    /// the plot frame is, in pixels of `root`.
    fn draw_mesh<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        lay: &Layout,
    ) -> Result<Frame, DrawingAreaErrorKind<DB::ErrorType>> {
        let s = lay.scale;
        let mut chart = ChartBuilder::on(root)
            .margin_top(px(lay.top))
            .margin_bottom(px(lay.bottom_margin))
            .margin_left(px(MARGIN * s))
            .margin_right(px(lay.right_margin))
            .x_label_area_size(px(lay.x_area))
            .y_label_area_size(px(lay.y_area))
            .build_cartesian_2d(TickRange::new(&lay.x), TickRange::new(&lay.y))?;
        let x_fmt = |v: &f64| lay.x.label_of(*v);
        let y_fmt = |v: &f64| lay.y.label_of(*v);
        chart
            .configure_mesh()
            .x_desc(self.x_label.as_str())
            .y_desc(self.y_label.as_str())
            .axis_desc_style(font::text(lay.desc_font))
            .label_style(font::text(TICK_FONT * s))
            .x_label_formatter(&x_fmt)
            .y_label_formatter(&y_fmt)
            .bold_line_style(BLACK.mix(0.14).stroke_width(px(s) as u32))
            .light_line_style(BLACK.mix(0.06).stroke_width(px(s) as u32))
            .axis_style(BLACK.stroke_width(px(AXIS_WIDTH * s) as u32))
            .set_all_tick_mark_size(px(TICK_LEN * s))
            .x_labels(lay.x.ticks.len().max(1))
            .y_labels(lay.y.ticks.len().max(1))
            .max_light_lines(10)
            .draw()?;
        // Plotters maps to the backend's pixels; `root` may be one panel of
        // a larger canvas, whose own pixels start at its base.
        let (bx, by) = root.get_base_pixel();
        let (x0, y0) = chart.backend_coord(&(lay.x.lo, lay.y.lo));
        let (x1, y1) = chart.backend_coord(&(lay.x.hi, lay.y.hi));
        let (xr, yr) = chart.plotting_area().get_pixel_range();
        Ok(Frame {
            x0: x0 - bx,
            y0: y0 - by,
            x1: x1 - bx,
            y1: y1 - by,
            area: (xr.start - bx..xr.end - bx, yr.start - by..yr.end - by),
        })
    }

    /// Marker labels and the axes' common factors, outside the plot.
    fn draw_notes<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        lay: &Layout,
        (left, top, right): (i32, i32, i32),
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        let s = lay.scale;
        let row_y = |row: usize| top - px((10.0 + row as f64 * NOTE_ROW) * s);
        let tick_font = font::text(TICK_FONT * s);
        if let Some(factor) = &lay.y.factor {
            root.draw(&Text::new(
                factor.clone(),
                (left, row_y(0)),
                tick_font.pos(Pos::new(HPos::Left, VPos::Bottom)),
            ))?;
        }
        if let Some(factor) = &lay.x.factor {
            root.draw(&Text::new(
                factor.clone(),
                (right, px((f64::from(HEIGHT) - MARGIN) * s)),
                tick_font.pos(Pos::new(HPos::Right, VPos::Bottom)),
            ))?;
        }
        let note = font::text(NOTE_FONT * s).color(&MARKER_COLOR);
        for ((x, label), &row) in self.markers.iter().zip(&lay.marker_rows) {
            if label.is_empty() {
                continue;
            }
            let (cx, _) = lay.to_px((*x, lay.y.lo));
            let w = text_width(label, NOTE_FONT * s);
            let start =
                (cx - w / 2.0).clamp(f64::from(left), (f64::from(right) - w).max(f64::from(left)));
            root.draw(&Text::new(
                label.clone(),
                (px(start), row_y(row)),
                note.pos(Pos::new(HPos::Left, VPos::Bottom)),
            ))?;
        }
        Ok(())
    }
}

impl Curve {
    /// The `index`-th series of a chart, checked and cut into runs of
    /// drawable points (log10 of `y` on a logarithmic axis).
    fn of(s: &Series, index: usize, log_y: bool, png: &Path) -> Result<Self, ChartError> {
        let path = || png.to_path_buf();
        let label = || s.label.clone();
        if s.x.len() != s.y.len() {
            return Err(ChartError::LengthMismatch {
                path: path(),
                label: label(),
                x_len: s.x.len(),
                y_len: s.y.len(),
            });
        }
        if s.x.is_empty() {
            return Err(ChartError::EmptySeries {
                path: path(),
                label: label(),
            });
        }
        let finite = |x: f64, y: f64| x.is_finite() && y.is_finite();
        if !s.x.iter().zip(&s.y).any(|(&x, &y)| finite(x, y)) {
            return Err(ChartError::NoFinitePoints {
                path: path(),
                label: label(),
            });
        }
        let mut runs = Vec::new();
        let mut run = Vec::new();
        for (&x, &y) in s.x.iter().zip(&s.y) {
            if finite(x, y) && (!log_y || y > 0.0) {
                run.push((x, if log_y { y.log10() } else { y }));
            } else if !run.is_empty() {
                runs.push(std::mem::take(&mut run));
            }
        }
        if !run.is_empty() {
            runs.push(run);
        }
        if runs.is_empty() {
            return Err(ChartError::NoPositivePoints {
                path: path(),
                label: label(),
            });
        }
        let points: usize = runs.iter().map(Vec::len).sum();
        let (color, style, marker, mark_every) = s.resolved_style(index, points);
        Ok(Self {
            label: s.label.clone(),
            color: color.plotters(),
            dash: style.pixels(),
            line: style.has_line(),
            runs,
            mark_every,
            marker,
        })
    }

    /// The curve clipped to the plot frame, then its markers.
    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        lay: &Layout,
        frame: &Frame,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        let s = lay.scale;
        let rect = frame.rect();
        let line_width = px(LINE_WIDTH * s);
        let style = self.color.stroke_width(line_width as u32);
        let dash: Vec<f64> = self.dash.iter().map(|d| d * s).collect();
        let inside =
            |c: (f64, f64)| c.0 >= rect.0 && c.0 <= rect.2 && c.1 >= rect.1 && c.1 <= rect.3;
        let mut index = 0usize;
        for run in &self.runs {
            let pts: Vec<(f64, f64)> = run.iter().map(|&p| frame.to_px(lay, p)).collect();
            for piece in clip_polyline(&pts, rect).into_iter().filter(|_| self.line) {
                if piece.len() == 1 {
                    let c = pixels(&piece)[0];
                    root.draw(&Circle::new(c, line_width, self.color.filled()))?;
                    continue;
                }
                for dash in dashed(&piece, &dash) {
                    root.draw(&PathElement::new(pixels(&dash), style))?;
                }
            }
            if self.mark_every > 0 {
                for &p in &pts {
                    if index.is_multiple_of(self.mark_every) && inside(p) {
                        draw_mark(root, p, self.marker, self.color, s)?;
                    }
                    index += 1;
                }
            }
        }
        Ok(())
    }
}

/// The axis descriptions' font size at `scale`: [`DESC_FONT`], scaled down
/// where a description `(label, room)` is longer than its axis (a long y
/// label ran past both ends of the plot), to [`DESC_FIT`] of the axis.
fn desc_font_fitting(axes: &[(&String, f64)], scale: f64) -> f64 {
    let size = DESC_FONT * scale;
    let shrink = axes
        .iter()
        .map(|(label, room)| {
            let width = text_width(label, size);
            if width <= *room {
                1.0
            } else {
                DESC_FIT * room.max(0.0) / width
            }
        })
        .fold(1.0, f64::min);
    size * shrink
}

/// The share of its axis a description scaled down to fit takes: glyph
/// widths do not scale exactly with the size.
const DESC_FIT: f64 = 0.95;

impl Layout {
    fn compute(figure: &Figure, scale: f64) -> Self {
        let s = scale;
        let x = Axis::linear(figure.x_range.0, figure.x_range.1, 7);
        let y = if figure.log_y {
            Axis::logarithmic(figure.y_range.0, figure.y_range.1)
        } else {
            Axis::linear(figure.y_range.0, figure.y_range.1, 6)
        };
        let label_dist = 2.0 * TICK_LEN;
        let y_area = y.widest_label(TICK_FONT * s) + (label_dist + 18.0 + DESC_FONT) * s;
        let x_area = (TICK_FONT + label_dist + 18.0 + DESC_FONT) * s;
        let last_x_label = x
            .labels
            .last()
            .map(|l| text_width(l, TICK_FONT * s))
            .unwrap_or(0.0);
        let right_margin = (MARGIN * s).max(last_x_label / 2.0 + 8.0 * s);
        // A legend that fits no corner goes below the plot, across its width
        // (beside it, it would take half the figure's width).
        let mut bottom_margin = MARGIN * s;
        if figure.legend == Some(Corner::Outside) {
            let (_, legend_h) = figure.legend_size(s);
            bottom_margin += legend_h + LEGEND_INSET * s;
        }
        let left = MARGIN * s + y_area;
        let right = f64::from(WIDTH) * s - right_margin;

        // Marker labels: greedy rows so that no two overlap; the y factor
        // (if any) occupies the left end of row 0.
        let mut rows: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
        if let Some(f) = &y.factor {
            rows[0].push((left, left + text_width(f, TICK_FONT * s)));
        }
        let markers = &figure.markers;
        let mut order: Vec<usize> = (0..markers.len()).collect();
        order.sort_by(|&a, &b| markers[a].0.total_cmp(&markers[b].0));
        let mut marker_rows = vec![0; markers.len()];
        for i in order {
            let (mx, label) = &markers[i];
            if label.is_empty() {
                continue;
            }
            let cx = left + (mx - x.lo) / (x.hi - x.lo) * (right - left);
            let w = text_width(label, NOTE_FONT * s);
            let start = (cx - w / 2.0).clamp(left, (right - w).max(left));
            let span = (start - 12.0 * s, start + w + 12.0 * s);
            let free = |row: &Vec<(f64, f64)>| row.iter().all(|&(a, b)| span.1 <= a || b <= span.0);
            let row = match rows.iter().position(free) {
                Some(r) => r,
                None => {
                    rows.push(Vec::new());
                    rows.len() - 1
                }
            };
            rows[row].push(span);
            marker_rows[i] = row;
        }
        let used_rows = if y.factor.is_some() || markers.iter().any(|m| !m.1.is_empty()) {
            rows.len() as f64
        } else {
            0.0
        };
        let title_h = if figure.title.is_empty() {
            0.0
        } else {
            TITLE_FONT + 18.0
        };
        let top = (MARGIN + title_h + used_rows * NOTE_ROW + TICK_FONT / 2.0 + 6.0) * s;
        let bottom = f64::from(HEIGHT) * s - bottom_margin - x_area;
        let axes = [
            (&figure.x_label, right - left),
            (&figure.y_label, bottom - top),
        ];
        Self {
            desc_font: desc_font_fitting(&axes, s),
            scale,
            x,
            y,
            top,
            right_margin,
            bottom_margin,
            x_area,
            y_area,
            plot: (left, top, right, bottom),
            marker_rows,
        }
    }

    /// Predicted pixel position of a plotted point.
    pub(super) fn to_px(&self, (x, y): (f64, f64)) -> (f64, f64) {
        let (l, t, r, b) = self.plot;
        (
            l + (x - self.x.lo) / (self.x.hi - self.x.lo) * (r - l),
            b - (y - self.y.lo) / (self.y.hi - self.y.lo) * (b - t),
        )
    }
}

/// The plotted x range: the data's, with a little room for a marker line at
/// (or beyond) an end of the data, so that the frame does not hide it.
fn x_range((lo, hi): (f64, f64), markers: &[(f64, String)]) -> (f64, f64) {
    let (mut x_lo, mut x_hi) = widen_if_flat(lo, hi);
    let span = x_hi - x_lo;
    if markers.iter().any(|m| m.0 <= x_lo) {
        x_lo = markers.iter().fold(x_lo, |lo, m| lo.min(m.0)) - 0.02 * span;
    }
    if markers.iter().any(|m| m.0 >= x_hi) {
        x_hi = markers.iter().fold(x_hi, |hi, m| hi.max(m.0)) + 0.02 * span;
    }
    (x_lo, x_hi)
}

fn min_max(values: impl Iterator<Item = f64>) -> (f64, f64) {
    values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
        (lo.min(v), hi.max(v))
    })
}

/// A range of zero width becomes one around the value.
fn widen_if_flat(lo: f64, hi: f64) -> (f64, f64) {
    if hi > lo {
        return (lo, hi);
    }
    let pad = if lo == 0.0 { 1.0 } else { 0.1 * lo.abs() };
    (lo - pad, hi + pad)
}
#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn downsampling_averages_blocks() {
        let rgb = [0, 0, 0, 255, 255, 255, 255, 255, 255, 255, 255, 255];
        assert_eq!(downsample(&rgb, 2, 2), [191, 191, 191]);
    }
}
