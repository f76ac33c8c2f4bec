//! The one font every chart uses: DejaVu Sans, embedded in the binary from the
//! `dejavu` crate and registered with plotters under [`FAMILY`].
//!
//! Charts never look up system fonts, so they render identically on a
//! headless machine without fontconfig. The DejaVu fonts are free (Bitstream
//! Vera licence with public-domain DejaVu changes); the licence text travels
//! with the `dejavu` crate's sources and in the font file's own `name` table.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Once;

use plotters::style::{register_font, FontStyle, IntoFont, TextStyle};

/// The family name the embedded face is registered under. No other family is
/// ever asked for, so a missing system font can never break a chart.
pub const FAMILY: &str = "flexmech-sans";

/// `font-family` written into SVG files instead of [`FAMILY`] (a name only
/// this program knows): the embedded face first, then close relatives.
pub const SVG_FAMILY: &str = "'DejaVu Sans', 'Bitstream Vera Sans', Verdana, sans-serif";

static REGISTER: Once = Once::new();
static REGISTERED: AtomicBool = AtomicBool::new(false);

/// Registers the embedded face under [`FAMILY`] (once per process; later calls
/// only report the outcome). Returns `false` if plotters rejected the font
/// data, which would be a packaging bug.
pub fn ensure_registered() -> bool {
    REGISTER.call_once(|| {
        let ok = register_font(FAMILY, FontStyle::Normal, dejavu::sans::regular()).is_ok();
        REGISTERED.store(ok, Ordering::Release);
    });
    REGISTERED.load(Ordering::Acquire)
}

/// A text style of the embedded family, `size` in pixels.
pub fn text(size: f64) -> TextStyle<'static> {
    (FAMILY, size).into_font().into()
}
