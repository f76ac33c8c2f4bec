//! Axis ticks and their labels. Where the ticks go is plotters' choice (its
//! linear key points, and `LogCoord`'s decades and 2…9× lines); what is added
//! here is what plotters' formatters do not give: a common factor (`×10ⁿ`) or
//! an offset note when the labels would repeat, decade labels `10ⁿ` (and 2×,
//! 5× when few), the true minus sign and Unicode superscripts — and the
//! plotters coordinate whose grid lines are exactly these ticks.

use plotters::coord::combinators::LogCoord;
use plotters::coord::ranged1d::{BoldPoints, DefaultFormatting, KeyPointHint};
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

use super::font::text_width;

/// One axis: its range (in plotted coordinates: log10 of the value on a
/// logarithmic axis), labelled ticks, unlabelled minor grid lines and an
/// optional common factor such as `×10⁻³`.
#[derive(Debug, Clone)]
pub(super) struct Axis {
    pub(super) lo: f64,
    pub(super) hi: f64,
    pub(super) ticks: Vec<f64>,
    pub(super) labels: Vec<String>,
    pub(super) minor: Vec<f64>,
    pub(super) factor: Option<String>,
}

impl Axis {
    /// Ticks from plotters' own choice of "nice" key points (steps of 1, 2 or
    /// 5 × 10ᵏ, at most `target + 1` of them), labelled here.
    pub(super) fn linear(lo: f64, hi: f64, target: usize) -> Self {
        let (step, ticks) = nice_ticks(lo, hi, target);
        let (labels, factor) = linear_labels(&ticks, step);
        Self {
            lo,
            hi,
            ticks,
            labels,
            minor: Vec::new(),
            factor,
        }
    }

    /// `lo`, `hi` are the data's exponents (log10). The range gets a small
    /// margin, or is widened to whole decades when it would otherwise hold
    /// fewer than two of them. Decades and the 2…9× lines between them are
    /// plotters' logarithmic key points (`LogCoord`: bold and light points);
    /// at most about nine decades are labelled, always including 10⁰.
    pub(super) fn logarithmic(lo: f64, hi: f64) -> Self {
        let pad = LOG_MARGIN * (hi - lo);
        let (mut lo, mut hi) = (lo - pad, hi + pad);
        if hi.floor() - lo.ceil() < 1.0 {
            lo = (lo + EXPONENT_SLACK).floor();
            hi = (hi - EXPONENT_SLACK).ceil().max(lo + 1.0);
        }
        let (decades, between) = log_key_points(lo, hi);
        let every = (decades.len() as i64 + 7) / 9; // at most ~9 labelled decades
        let mut ticks = Vec::new();
        let mut minor = Vec::new();
        for &e in &decades {
            if (e.round() as i64).rem_euclid(every.max(1)) == 0 {
                ticks.push(e);
            } else {
                minor.push(e);
            }
        }
        if decades.len() <= 7 {
            minor.extend(between.iter().copied());
        }
        let mut labels: Vec<String> = ticks
            .iter()
            .map(|&e| format!("10{}", superscript(e.round() as i64)))
            .collect();
        // Fewer than three labelled decades: label 2× and 5× as well.
        if ticks.len() < 3 {
            for &v in &between {
                let e = (v + EXPONENT_SLACK).floor();
                let m = 10f64.powf(v - e).round() as u8;
                if m == 2 || m == 5 {
                    ticks.push(v);
                    labels.push(format!("{m}×10{}", superscript(e as i64)));
                    minor.retain(|&w| (w - v).abs() > EXPONENT_SLACK);
                }
            }
        }
        Self {
            lo,
            hi,
            ticks,
            labels,
            minor,
            factor: None,
        }
    }

    pub(super) fn label_of(&self, v: f64) -> String {
        self.ticks
            .iter()
            .position(|&t| t == v)
            .map(|i| self.labels[i].clone())
            .unwrap_or_default()
    }

    pub(super) fn widest_label(&self, size: f64) -> f64 {
        self.labels
            .iter()
            .map(|l| text_width(l, size))
            .fold(0.0, f64::max)
    }
}

/// A linear plotters coordinate whose grid lines are exactly an [`Axis`]'s
/// ticks (bold) and minor lines (light).
pub(super) struct TickRange {
    linear: RangedCoordf64,
    pub(super) ticks: Vec<f64>,
    pub(super) minor: Vec<f64>,
}

impl TickRange {
    pub(super) fn new(axis: &Axis) -> Self {
        Self {
            linear: (axis.lo..axis.hi).into(),
            ticks: axis.ticks.clone(),
            minor: axis.minor.clone(),
        }
    }
}

impl Ranged for TickRange {
    type FormatOption = DefaultFormatting;
    type ValueType = f64;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        self.linear.map(value, limit)
    }

    fn key_points<Hint: KeyPointHint>(&self, hint: Hint) -> Vec<f64> {
        if hint.weight().allow_light_points() {
            self.minor.clone()
        } else {
            self.ticks.clone()
        }
    }

    fn range(&self) -> std::ops::Range<f64> {
        self.linear.range()
    }
}

/// Relative margin added to a logarithmic axis's data range.
const LOG_MARGIN: f64 = 0.04;
/// Slack on exponents (log10) when deciding whether a value is a decade.
const EXPONENT_SLACK: f64 = 1e-9;

/// Plotters' linear key points inside `[lo, hi]` — multiples of 1, 2 or
/// 5 × 10ᵏ, the finest such step giving at most `target + 1` points —
/// snapped to exact multiples of that step. Returns the step and the ticks.
fn nice_ticks(lo: f64, hi: f64, target: usize) -> (f64, Vec<f64>) {
    if !(lo.is_finite() && hi.is_finite() && hi > lo) {
        return (0.0, Vec::new());
    }
    let range: RangedCoordf64 = (lo..hi).into();
    let points = range.key_points(target + 1);
    let step = match points.as_slice() {
        [a, b, ..] => round_to_nice(b - a),
        _ => hi - lo,
    };
    let ticks = points
        .iter()
        .map(|&t| (t / step).round() * step)
        .map(|t| if t == 0.0 { 0.0 } else { t })
        .collect();
    (step, ticks)
}

/// The number of the form {1, 2, 5} × 10ᵏ nearest to `step` (the spacing of
/// plotters' key points, measured with rounding error).
fn round_to_nice(step: f64) -> f64 {
    let k = step.log10().floor();
    let base = 10f64.powf(k);
    [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * base)
        .min_by(|a, b| (a - step).abs().total_cmp(&(b - step).abs()))
        .unwrap_or(step)
}

/// Plotters' key points of a logarithmic axis over `[10^lo, 10^hi]`: the
/// decades (bold points) and the 2…9 × 10ᵏ lines (light points), both as
/// exponents (log10).
fn log_key_points(lo: f64, hi: f64) -> (Vec<f64>, Vec<f64>) {
    if !(lo.is_finite() && hi.is_finite() && hi > lo) {
        return (Vec::new(), Vec::new());
    }
    // Half a decade more on both sides, so that rounding in plotters' own
    // powers of ten cannot drop an end decade; the filters below trim it.
    // Plotters treats values below f64::EPSILON as zero and skips them, so the
    // key points are taken on the range shifted to start near 10⁰ (decades
    // map to decades) and shifted back.
    let shift = lo.floor();
    let (from, to) = (-0.5, hi - shift + 0.5);
    let axis: LogCoord<f64> = (10f64.powf(from)..10f64.powf(to)).log_scale().into();
    // Plotters adds light points once more than ten points per decade are
    // allowed: one point per decade gives the decades, ten the 2…9× lines.
    let decade_count = (to - from).ceil() as usize;
    let exponents = |points_per_decade: usize| -> Vec<f64> {
        axis.key_points(BoldPoints(points_per_decade * decade_count))
            .iter()
            .map(|v| v.log10() + shift)
            .collect()
    };
    let decades: Vec<f64> = exponents(1)
        .into_iter()
        .map(f64::round)
        .filter(|e| *e >= lo - EXPONENT_SLACK && *e <= hi + EXPONENT_SLACK)
        .collect();
    let between = exponents(10)
        .into_iter()
        .filter(|v| *v > lo && *v < hi)
        .filter(|v| (v - v.round()).abs() > EXPONENT_SLACK)
        .collect();
    (decades, between)
}

/// Tick labels with as many decimals as the step needs; very large or small
/// values get a common factor `×10ᵏ` shown once beside the axis. When the
/// ticks differ only far behind their leading digits (a conserved energy, say),
/// they are labelled as deviations from a reference tick, and the note beside
/// the axis reads `×10ᵏ + offset`.
fn linear_labels(ticks: &[f64], step: f64) -> (Vec<String>, Option<String>) {
    let max_abs = ticks.iter().fold(0.0f64, |m, t| m.max(t.abs()));
    let offset = if max_abs > 0.0 && step < 1e-4 * max_abs && !ticks.is_empty() {
        ticks[ticks.len() / 2]
    } else {
        0.0
    };
    let shifted: Vec<f64> = ticks.iter().map(|t| t - offset).collect();
    let max_abs = shifted.iter().fold(0.0f64, |m, t| m.max(t.abs()));
    let exponent = if max_abs >= 1e4 || (max_abs > 0.0 && max_abs < 1e-2) {
        max_abs.log10().floor() as i32
    } else {
        0
    };
    let scale = 10f64.powi(-exponent);
    let scaled_step = step * scale;
    let decimals = (0..=12)
        .find(|&d| {
            let v = scaled_step * 10f64.powi(d);
            (v - v.round()).abs() < 1e-6 * v.max(1.0)
        })
        .unwrap_or(12) as usize;
    let labels = shifted
        .iter()
        .map(|t| minus_sign(&format!("{:.*}", decimals, t * scale)))
        .collect();
    let factor = (exponent != 0).then(|| format!("×10{}", superscript(i64::from(exponent))));
    if offset == 0.0 {
        return (labels, factor);
    }
    // Enough significant digits that the offset is exact to the tick step.
    let digits = ((offset.abs() / step).log10().ceil().max(1.0) as usize).min(16);
    let off = minus_sign(&format!("{:+.*e}", digits, offset));
    let note = match factor {
        Some(f) => format!("{f} {off}"),
        None => off,
    };
    (labels, Some(note))
}

/// Typographic minus; no negative zero.
fn minus_sign(text: &str) -> String {
    let zero = text
        .trim_start_matches('-')
        .chars()
        .all(|c| c == '0' || c == '.');
    if zero {
        text.trim_start_matches('-').to_owned()
    } else {
        text.replace('-', "\u{2212}")
    }
}

fn superscript(n: i64) -> String {
    n.to_string()
        .chars()
        .map(|c| match c {
            '-' => '⁻',
            '0' => '⁰',
            '1' => '¹',
            '2' => '²',
            '3' => '³',
            '4' => '⁴',
            '5' => '⁵',
            '6' => '⁶',
            '7' => '⁷',
            '8' => '⁸',
            _ => '⁹',
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearly_constant_values_get_offset_labels() {
        // Ticks 1e-12 apart on a value of 163: every label must differ, and
        // the note beside the axis carries the factor and the offset.
        let (step, ticks) = nice_ticks(163.0 - 2.5e-12, 163.0 + 2.5e-12, 6);
        let (labels, note) = linear_labels(&ticks, step);
        let mut unique = labels.clone();
        unique.dedup();
        assert_eq!(unique.len(), labels.len(), "{labels:?}");
        let note = note.expect("offset note");
        assert!(note.contains("×10") && note.contains("e2"), "{note}");
        // Ordinary ranges keep plain labels.
        let (step, ticks) = nice_ticks(0.0, 10.0, 6);
        assert_eq!(linear_labels(&ticks, step).1, None);
    }

    #[test]
    fn ticks_come_close_to_the_target_count() {
        assert_eq!(nice_ticks(0.0, 2.0, 7).0, 0.5);
        assert_eq!(nice_ticks(0.1, 1.2, 7).0, 0.2);
        assert_eq!(nice_ticks(-0.17, 0.5, 6).0, 0.1);
        assert_eq!(nice_ticks(0.0, 11.0, 7).0, 2.0);
    }

    #[test]
    fn linear_labels_use_the_steps_decimals_and_a_common_factor() {
        let a = Axis::linear(-0.05, 1.05, 6);
        assert_eq!(a.labels, ["0.0", "0.2", "0.4", "0.6", "0.8", "1.0"]);
        let b = Axis::linear(-1.0e-4, 3.0e-4, 5);
        assert_eq!(b.factor.as_deref(), Some("×10⁻⁴"));
        assert_eq!(b.labels, ["\u{2212}1", "0", "1", "2", "3"]);
        let c = Axis::linear(0.0, 2.5e5, 6);
        assert_eq!(c.factor.as_deref(), Some("×10⁵"));
        assert_eq!(c.labels[1], "0.5");
    }

    #[test]
    fn log_axis_labels_decades() {
        let a = Axis::logarithmic(-3.2, 0.4);
        assert_eq!(a.labels, ["10⁻³", "10⁻²", "10⁻¹", "10⁰"]);
        assert!(a.lo < -3.2 && a.hi > 0.4);
        // Less than a decade of data: widened to whole decades, with 2× and
        // 5× labelled too.
        let b = Axis::logarithmic(-2.9, -2.6);
        assert_eq!((b.lo, b.hi), (-3.0, -2.0));
        assert_eq!(b.labels, ["10⁻³", "10⁻²", "2×10⁻³", "5×10⁻³"]);
        let c = Axis::logarithmic(-16.0, 4.0);
        assert!(c.ticks.len() <= 10, "{:?}", c.ticks);
        assert!(c.ticks.contains(&0.0));
    }

    #[test]
    fn log_axis_keeps_decades_below_machine_epsilon() {
        // Conserving schemes' energy errors live near 1e-16; plotters alone
        // would drop those decades as zero.
        let a = Axis::logarithmic(-17.5, -14.2);
        assert_eq!(a.labels, ["10⁻¹⁷", "10⁻¹⁶", "10⁻¹⁵"]);
        assert!(a
            .minor
            .iter()
            .any(|&m| (m - (-17.0 + 2f64.log10())).abs() < 1e-12));
    }

    #[test]
    fn degenerate_ranges_give_no_ticks_instead_of_panicking() {
        assert!(nice_ticks(f64::NAN, 1.0, 6).1.is_empty());
        assert!(nice_ticks(1.0, 1.0, 6).1.is_empty());
        assert!(log_key_points(f64::NAN, 2.0).0.is_empty());
    }
}
