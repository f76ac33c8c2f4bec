//! Axis ticks and their labels: "nice" linear steps with a common factor
//! (`×10ⁿ`) or an offset note when the labels would repeat, decades `10ⁿ`
//! (and 2×, 5× when few) on a logarithmic axis, the true minus sign and
//! Unicode superscripts — what plotters' own formatters do not give — and
//! the plotters coordinate whose grid lines are exactly these ticks.

use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint};
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
    /// fewer than two of them.
    pub(super) fn logarithmic(lo: f64, hi: f64) -> Self {
        let pad = 0.04 * (hi - lo);
        let (mut lo, mut hi) = (lo - pad, hi + pad);
        if hi.floor() - lo.ceil() < 1.0 {
            lo = (lo + 1e-9).floor();
            hi = (hi - 1e-9).ceil().max(lo + 1.0);
        }
        let first = (lo - 1e-9).ceil() as i64;
        let last = (hi + 1e-9).floor() as i64;
        let decades = last - first;
        let every = (decades + 8) / 9; // at most ~9 labelled decades
        let mut ticks = Vec::new();
        let mut minor = Vec::new();
        for e in first..=last {
            if e.rem_euclid(every) == 0 {
                ticks.push(e as f64);
            } else {
                minor.push(e as f64);
            }
        }
        if decades <= 6 {
            for e in first - 1..=last {
                minor.extend(
                    (2..=9)
                        .map(|m| e as f64 + f64::from(m).log10())
                        .filter(|v| *v > lo && *v < hi),
                );
            }
        }
        let mut labels: Vec<String> = ticks
            .iter()
            .map(|&e| format!("10{}", superscript(e as i64)))
            .collect();
        // Fewer than three labelled decades: label 2× and 5× as well.
        if ticks.len() < 3 {
            for e in first - 1..=last {
                for m in [2u8, 5] {
                    let v = e as f64 + f64::from(m).log10();
                    if v > lo && v < hi {
                        ticks.push(v);
                        labels.push(format!("{m}×10{}", superscript(e)));
                        minor.retain(|&w| (w - v).abs() > 1e-9);
                    }
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

/// Ticks at multiples of 1, 2, 2.5 or 5 × 10ᵏ inside `[lo, hi]`, as close to
/// `target` ticks as possible (2.5 slightly disfavoured, then coarser steps
/// preferred). Returns the step and the ticks.
fn nice_ticks(lo: f64, hi: f64, target: usize) -> (f64, Vec<f64>) {
    let ticks_of = |step: f64| -> Vec<f64> {
        let first = (lo / step - 1e-9).ceil() as i64;
        let last = (hi / step + 1e-9).floor() as i64;
        (first..=last)
            .map(|k| {
                let t = k as f64 * step;
                if t.abs() < step * 1e-9 {
                    0.0
                } else {
                    t
                }
            })
            .collect()
    };
    let base = 10f64.powf(((hi - lo) / target.max(1) as f64).log10().floor());
    let mut best: Option<(usize, f64)> = None;
    for mag in [0.1 * base, base, 10.0 * base] {
        for m in [1.0, 2.0, 2.5, 5.0] {
            let step = m * mag;
            let n = ((hi / step + 1e-9).floor() - (lo / step - 1e-9).ceil() + 1.0).max(0.0);
            if n < 2.0 {
                continue;
            }
            let score = 2 * (n as usize).abs_diff(target) + usize::from(m == 2.5);
            if best.is_none_or(|(s, _)| score <= s) {
                best = Some((score, step));
            }
        }
    }
    let step = best.map_or(hi - lo, |(_, s)| s);
    (step, ticks_of(step))
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
}
