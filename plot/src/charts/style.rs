//! How a curve looks: its colour, dash pattern and marker. A series that
//! sets none of them gets the automatic cycle ([`auto_style`]); the PNG/SVG
//! drawing and the PGFPlots copy read the same values from here, so both
//! show one curve alike.

use plotters::style::RGBColor;

/// An sRGB colour of a curve (`Color::rgb(0, 114, 178)`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Color {
    /// Red, 0–255.
    pub r: u8,
    /// Green, 0–255.
    pub g: u8,
    /// Blue, 0–255.
    pub b: u8,
}

impl Color {
    /// A colour from its red, green and blue components (0–255).
    pub const fn rgb(r: u8, g: u8, b: u8) -> Self {
        Self { r, g, b }
    }

    /// The automatic cycle's colours: the Okabe–Ito palette (distinguishable
    /// with colour-vision deficiencies), blue, vermilion, bluish green,
    /// reddish purple, orange, sky blue.
    pub const PALETTE: [Color; 6] = [
        Color::rgb(0, 114, 178),
        Color::rgb(213, 94, 0),
        Color::rgb(0, 158, 115),
        Color::rgb(204, 121, 167),
        Color::rgb(230, 159, 0),
        Color::rgb(86, 180, 233),
    ];

    pub(super) fn plotters(self) -> RGBColor {
        RGBColor(self.r, self.g, self.b)
    }

    /// The colour as a PGFPlots option: the named colour the `.tex`
    /// defines for a palette colour, else an inline `rgb,255:` expression.
    pub(super) fn pgf(self) -> String {
        match Self::PALETTE.iter().position(|&c| c == self) {
            Some(i) => PGF_COLOR_NAMES[i].to_owned(),
            None => format!(
                "color={{rgb,255:red,{};green,{};blue,{}}}",
                self.r, self.g, self.b
            ),
        }
    }
}

/// Names under which the `.tex` defines [`Color::PALETTE`].
pub(super) const PGF_COLOR_NAMES: [&str; 6] = [
    "fmblue",
    "fmvermilion",
    "fmgreen",
    "fmpurple",
    "fmorange",
    "fmsky",
];

/// A curve's line pattern.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Dash {
    /// An unbroken line.
    Solid,
    /// Dashes.
    Dashed,
    /// Dots.
    Dotted,
    /// Dash, dot, dash, …
    DashDot,
    /// Long dashes.
    LongDashed,
    /// Dash, dot, dot, dash, …
    DashDotDot,
    /// No line: a marker on every point (published values, sparse data);
    /// never in the automatic cycle.
    Markers,
}

impl Dash {
    /// The automatic cycle's patterns, in order.
    pub const CYCLE: [Dash; 6] = [
        Dash::Solid,
        Dash::Dashed,
        Dash::Dotted,
        Dash::DashDot,
        Dash::LongDashed,
        Dash::DashDotDot,
    ];

    /// The pattern in pixels at the chart's output size (on, off, on, off,
    /// …); empty for a solid line.
    pub(super) fn pixels(self) -> &'static [f64] {
        match self {
            Dash::Solid => &[],
            Dash::Dashed => &[24.0, 12.0],
            Dash::Dotted => &[4.0, 10.0],
            Dash::DashDot => &[26.0, 10.0, 4.0, 10.0],
            Dash::LongDashed => &[44.0, 14.0],
            Dash::DashDotDot => &[22.0, 8.0, 4.0, 8.0, 4.0, 8.0],
            Dash::Markers => &[],
        }
    }

    /// Whether the curve's points are joined by a line.
    pub(super) fn has_line(self) -> bool {
        self != Dash::Markers
    }

    /// The pattern as a TikZ line style: TikZ's own name where one matches,
    /// else the PNG's pattern in points (a 1600 px chart is about 400 pt
    /// wide in the `.tex`).
    pub(super) fn pgf(self) -> &'static str {
        match self {
            Dash::Solid => "solid",
            Dash::Dashed => "dashed",
            Dash::Dotted => "dotted",
            Dash::DashDot => "dashdotted",
            Dash::LongDashed => "dash pattern=on 11pt off 3.5pt",
            Dash::DashDotDot => "dashdotdotted",
            Dash::Markers => "only marks",
        }
    }
}

/// The shape drawn on a curve's data points.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Marker {
    /// No markers, even on a short curve.
    None,
    /// Filled circles (the automatic marker).
    Circle,
    /// Filled squares.
    Square,
    /// Filled triangles pointing up.
    Triangle,
    /// Filled diamonds.
    Diamond,
    /// Crosses `×`.
    Cross,
    /// Plus signs `+`.
    Plus,
}

impl Marker {
    /// The marker as PGFPlots `mark=` value (`None` for no marker).
    pub(super) fn pgf(self) -> Option<&'static str> {
        Some(match self {
            Marker::None => return None,
            Marker::Circle => "*",
            Marker::Square => "square*",
            Marker::Triangle => "triangle*",
            Marker::Diamond => "diamond*",
            Marker::Cross => "x",
            Marker::Plus => "+",
        })
    }
}

/// The automatic cycle: colour and dash pattern of the `index`-th series
/// (counting every series of the chart). Colours repeat after six series,
/// each time with the patterns shifted by one, so no two of the first 36
/// curves look alike.
pub fn auto_style(index: usize) -> (Color, Dash) {
    let n = Color::PALETTE.len();
    (
        Color::PALETTE[index % n],
        Dash::CYCLE[(index + index / n) % n],
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_cycle_is_distinct_for_36_series() {
        let styles: Vec<(Color, Dash)> = (0..36).map(auto_style).collect();
        for (i, a) in styles.iter().enumerate() {
            assert!(styles[i + 1..].iter().all(|b| b != a), "series {i}");
        }
        assert_eq!(auto_style(0), (Color::rgb(0, 114, 178), Dash::Solid));
        assert_eq!(auto_style(7), (Color::rgb(213, 94, 0), Dash::Dotted));
    }

    #[test]
    fn palette_colours_keep_their_names_in_the_tex() {
        assert_eq!(Color::PALETTE[2].pgf(), "fmgreen");
        assert_eq!(
            Color::rgb(1, 2, 3).pgf(),
            "color={rgb,255:red,1;green,2;blue,3}"
        );
    }
}
