//! Where the legend goes and how it is drawn: in the corner of the plot
//! where it hides the least data (counted along the drawn lines), above the
//! curves when no corner is free and it is short, otherwise below the plot
//! in as many columns as fit — plotters' own series labels sit in a fixed
//! position.

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::figure::{
    px, Corner, Figure, Layout, AXIS_WIDTH, HEIGHT, LEGEND_COLUMN_GAP, LEGEND_FONT, LEGEND_GAP,
    LEGEND_INSET, LEGEND_PAD, LEGEND_ROW, LEGEND_SAMPLE, LINE_WIDTH, MARGIN,
};
use super::font::{self, text_width};
use super::marks::draw_mark;
use super::strokes::{dashed, pixels};

impl Figure {
    /// Chooses the legend's place (module docs); `d_hi` is the data's top.
    pub(super) fn place_legend(&mut self, d_hi: f64) {
        if self.legend_lines() == 0 {
            return;
        }

        // The legend goes upper right unless it would hide data there and a
        // free corner exists. If no corner is free, the top of the y range
        // is raised so that the legend sits above every curve, or, for a
        // legend too tall for that, it goes beside the plot.
        let layout = self.layout(1.0);
        let corners = [
            Corner::UpperRight,
            Corner::UpperLeft,
            Corner::LowerRight,
            Corner::LowerLeft,
        ];
        let hidden: Vec<usize> = corners
            .iter()
            .map(|&c| self.hidden_by(&layout, c))
            .collect();
        if let Some(i) = hidden.iter().position(|&n| n == 0) {
            self.legend = Some(corners[i]);
            return;
        }
        let (_, top, _, bottom) = layout.plot;
        let (_, legend_h) = self.legend_size(1.0);
        let f = (legend_h + LEGEND_INSET + 12.0) / (bottom - top);
        if f < 0.3 {
            let lo = layout.y.lo;
            self.y_range = (lo, d_hi + f / (1.0 - f) * (d_hi - lo));
            self.legend = Some(Corner::UpperRight);
        } else {
            // Below the plot: as many columns (up to three) as its width holds.
            self.legend = Some(Corner::Outside);
            let (l, _, r, _) = layout.plot;
            let entry = self.legend_entry_width(1.0) + LEGEND_COLUMN_GAP;
            let fit = ((r - l - 2.0 * LEGEND_PAD + LEGEND_COLUMN_GAP) / entry).floor() as usize;
            self.legend_columns = fit.clamp(1, 3).min(self.legend_lines());
        }
    }

    pub(super) fn legend_lines(&self) -> usize {
        self.curves.iter().filter(|c| !c.label.is_empty()).count()
    }

    /// Width of one legend entry (sample, gap, longest label).
    pub(super) fn legend_entry_width(&self, scale: f64) -> f64 {
        let text = self
            .curves
            .iter()
            .filter(|c| !c.label.is_empty())
            .map(|c| text_width(&c.label, LEGEND_FONT * scale))
            .fold(0.0, f64::max);
        (LEGEND_SAMPLE + LEGEND_GAP) * scale + text
    }

    pub(super) fn legend_size(&self, scale: f64) -> (f64, f64) {
        let cols = self.legend_columns.max(1);
        let rows = self.legend_lines().div_ceil(cols) as f64;
        let entry = self.legend_entry_width(scale);
        (
            2.0 * LEGEND_PAD * scale
                + cols as f64 * entry
                + (cols - 1) as f64 * LEGEND_COLUMN_GAP * scale,
            (2.0 * LEGEND_PAD + rows * LEGEND_ROW) * scale,
        )
    }

    /// Legend box (left, top, right, bottom) in a corner of the plot.
    pub(super) fn legend_box(&self, layout: &Layout, corner: Corner) -> (f64, f64, f64, f64) {
        let s = layout.scale;
        let (l, t, r, b) = layout.plot;
        let (w, h) = self.legend_size(s);
        let left = match corner {
            Corner::UpperLeft | Corner::LowerLeft => l + LEGEND_INSET * s,
            Corner::UpperRight | Corner::LowerRight => r - LEGEND_INSET * s - w,
            Corner::Outside => l,
        };
        let top = match corner {
            Corner::UpperLeft | Corner::UpperRight => t + LEGEND_INSET * s,
            Corner::Outside => f64::from(HEIGHT) * s - MARGIN * s - h,
            Corner::LowerLeft | Corner::LowerRight => b - LEGEND_INSET * s - h,
        };
        (left, top, left + w, top + h)
    }

    /// How many sampled points of the curves and marker lines (every ~6 px
    /// along each line) the legend would hide in `corner`.
    pub(super) fn hidden_by(&self, layout: &Layout, corner: Corner) -> usize {
        let (l, t, r, b) = self.legend_box(layout, corner);
        let (l, t, r, b) = (l - 6.0, t - 6.0, r + 6.0, b + 6.0);
        let inside = |(x, y): (f64, f64)| x >= l && x <= r && y >= t && y <= b;
        let mut count = 0;
        // Marker lines count as data too.
        let (_, top, _, bottom) = layout.plot;
        for (x, _) in &self.markers {
            let (mx, _) = layout.to_px((*x, layout.y.lo));
            let n = ((bottom - top) / 6.0).ceil() as usize;
            count += (0..=n)
                .filter(|k| inside((mx, top + (bottom - top) * *k as f64 / n as f64)))
                .count();
        }
        for run in self.curves.iter().flat_map(|c| &c.runs) {
            let pts: Vec<(f64, f64)> = run.iter().map(|&p| layout.to_px(p)).collect();
            count += usize::from(inside(pts[0]));
            for w in pts.windows(2) {
                let n = ((w[1].0 - w[0].0).hypot(w[1].1 - w[0].1) / 6.0)
                    .ceil()
                    .max(1.0);
                for k in 1..=n as usize {
                    let f = k as f64 / n;
                    let p = (
                        w[0].0 + f * (w[1].0 - w[0].0),
                        w[0].1 + f * (w[1].1 - w[0].1),
                    );
                    count += usize::from(inside(p));
                }
            }
        }
        count
    }

    pub(super) fn draw_legend<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        lay: &Layout,
        corner: Corner,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        let s = lay.scale;
        let (l, t, r, b) = self.legend_box(lay, corner);
        let corners = [(px(l), px(t)), (px(r), px(b))];
        root.draw(&Rectangle::new(corners, WHITE.filled()))?;
        root.draw(&Rectangle::new(
            corners,
            BLACK.mix(0.6).stroke_width(px(AXIS_WIDTH * s) as u32),
        ))?;
        let labelled = self.curves.iter().filter(|c| !c.label.is_empty());
        let cols = self.legend_columns.max(1);
        let column_step = self.legend_entry_width(s) + LEGEND_COLUMN_GAP * s;
        for (i, curve) in labelled.enumerate() {
            let (row, col) = (i / cols, i % cols);
            let y = t + (LEGEND_PAD + (row as f64 + 0.5) * LEGEND_ROW) * s;
            let x0 = l + LEGEND_PAD * s + col as f64 * column_step;
            let sample = [(x0, y), (x0 + LEGEND_SAMPLE * s, y)];
            let dash: Vec<f64> = curve.dash.iter().map(|d| d * s).collect();
            for piece in dashed(&sample, &dash).into_iter().filter(|_| curve.line) {
                root.draw(&PathElement::new(
                    pixels(&piece),
                    curve.color.stroke_width(px(LINE_WIDTH * s) as u32),
                ))?;
            }
            if curve.mark_every > 0 {
                let c = (x0 + 0.5 * LEGEND_SAMPLE * s, y);
                draw_mark(root, c, curve.marker, curve.color, s)?;
            }
            root.draw(&Text::new(
                curve.label.clone(),
                (px(x0 + (LEGEND_SAMPLE + LEGEND_GAP) * s), px(y)),
                font::text(LEGEND_FONT * s).pos(Pos::new(HPos::Left, VPos::Center)),
            ))?;
        }
        Ok(())
    }
}
