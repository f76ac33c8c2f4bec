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

/// Width in pixels of `text` at font size `size`.
pub(crate) fn text_width(content: &str, size: f64) -> f64 {
    text(size)
        .font
        .box_size(content)
        .map(|(w, _)| f64::from(w))
        .unwrap_or(0.6 * size * content.chars().count() as f64)
}

/// A text style of the embedded family, `size` in pixels.
pub fn text(size: f64) -> TextStyle<'static> {
    (FAMILY, size).into_font().into()
}

/// A `<style>` element embedding the face in an SVG file as a
/// base64 `@font-face` under [`SVG_FAMILY`]'s first name, so the file shows
/// (and converts to PDF) with the same text metrics on any machine.
pub fn svg_font_face() -> String {
    format!(
        "<style>@font-face {{ font-family: 'DejaVu Sans'; src: url(data:font/ttf;base64,{}) format('truetype'); }}</style>",
        base64(dejavu::sans::regular())
    )
}

/// Standard base64 (RFC 4648, with padding).
fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            *chunk.get(1).unwrap_or(&0),
            *chunk.get(2).unwrap_or(&0),
        ];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(ALPHABET[(n >> (18 - 6 * k)) as usize & 63] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::base64;

    #[test]
    fn base64_matches_rfc_4648_vectors() {
        for (plain, coded) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foobar", "Zm9vYmFy"),
        ] {
            assert_eq!(base64(plain.as_bytes()), coded);
        }
    }
}
