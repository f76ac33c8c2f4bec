//! Data markers ([`Marker`]) drawn on curves and in the legend's samples.

use plotters::coord::Shift;
use plotters::prelude::*;

use super::figure::{px, LINE_WIDTH, MARKER_RADIUS};
use super::style::Marker;

/// Draws `marker` centred on `(x, y)` (pixels of `root`) at drawing scale
/// `scale`. A circle is the automatic marker, so its pixels are those every
/// chart has always had.
pub(super) fn draw_mark<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    (x, y): (f64, f64),
    marker: Marker,
    color: RGBColor,
    scale: f64,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let r = MARKER_RADIUS * scale;
    let at = |dx: f64, dy: f64| (px(x + dx * r), px(y + dy * r));
    match marker {
        Marker::None => Ok(()),
        Marker::Circle => root.draw(&Circle::new((px(x), px(y)), px(r), color.filled())),
        Marker::Square => root.draw(&Rectangle::new(
            [at(-0.9, -0.9), at(0.9, 0.9)],
            color.filled(),
        )),
        Marker::Triangle => root.draw(&Polygon::new(
            vec![at(0.0, -1.3), at(1.15, 0.75), at(-1.15, 0.75)],
            color.filled(),
        )),
        Marker::Diamond => root.draw(&Polygon::new(
            vec![at(0.0, -1.3), at(1.1, 0.0), at(0.0, 1.3), at(-1.1, 0.0)],
            color.filled(),
        )),
        Marker::Cross | Marker::Plus => {
            let stroke = color.stroke_width(px(0.75 * LINE_WIDTH * scale).max(1) as u32);
            let arms = if marker == Marker::Cross {
                [
                    [at(-1.0, -1.0), at(1.0, 1.0)],
                    [at(-1.0, 1.0), at(1.0, -1.0)],
                ]
            } else {
                [[at(-1.2, 0.0), at(1.2, 0.0)], [at(0.0, -1.2), at(0.0, 1.2)]]
            };
            for arm in arms {
                root.draw(&PathElement::new(arm.to_vec(), stroke))?;
            }
            Ok(())
        }
    }
}
