//! The band LU's triangular solves over the columns that carry a full band
//! and no row interchange, for the common bandwidths, with the entries
//! still being updated kept in registers.
//!
//! Column by column, the forward solve `b ← L⁻¹ b` subtracts `lᵢⱼ bⱼ` from
//! the `kl` entries below `bⱼ`, and the backward solve `b ← U⁻¹ b` divides
//! `bⱼ` by its pivot (multiplies by its inverse) and subtracts `uᵢⱼ bⱼ` from the `ku` entries above it.
//! Done in memory, every column waits for the entry the previous column
//! has just stored (a store forwarded to a load, about five cycles) before
//! its own chain of a product and a difference; here the `kl` (or `ku + 1`)
//! entries in flight are a window of registers that slides by one entry
//! per column. The same operations in the same order as the general loops
//! of [`crate::band_lu::BandLu`], so the same bits.

/// Columns a solve asks the processor to fetch ahead of the one it works
/// on: a column's entries are a few cache lines at a stride of the band's
/// height, which the residual's evaluation between two solves has pushed
/// out of the nearer caches.
const PREFETCH_COLUMNS: usize = 12;

/// Asks for the first and last cache lines of `ab[at..at + len]` (nothing
/// where they lie outside `ab`): a hint, which changes no value.
#[inline(always)]
fn prefetch(ab: &[f64], at: usize, len: usize) {
    #[cfg(target_arch = "x86_64")]
    if at.checked_add(len).is_some_and(|end| end <= ab.len()) {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        // SAFETY: both addresses lie inside `ab`; a prefetch reads nothing.
        unsafe {
            let p = ab.as_ptr().add(at);
            _mm_prefetch(p.cast(), _MM_HINT_T0);
            _mm_prefetch(p.add(len - 1).cast(), _MM_HINT_T0);
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (ab, at, len);
}

/// The forward solve's columns `from..to` with `kl` multipliers each
/// (`to + kl ≤ n`) and no interchange, for `kl` ∈ {11, 12, 17}; `false`
/// (and nothing done) for other bandwidths. `ab`: the band storage
/// (`ld` rows, the diagonal at row `kv`).
pub(crate) fn forward_window(
    (kl, kv, ld): (usize, usize, usize),
    ab: &[f64],
    b: &mut [f64],
    (from, to): (usize, usize),
) -> bool {
    match kl {
        11 => forward_fixed::<11>((kv, ld), ab, b, (from, to)),
        12 => forward_fixed::<12>((kv, ld), ab, b, (from, to)),
        17 => forward_fixed::<17>((kv, ld), ab, b, (from, to)),
        _ => return false,
    }
    true
}

/// [`forward_window`] for `kl = KL`. The window `w` holds `b[j..j + KL]`
/// as column `j` starts.
#[inline(always)]
fn forward_fixed<const KL: usize>(
    (kv, ld): (usize, usize),
    ab: &[f64],
    b: &mut [f64],
    (from, to): (usize, usize),
) {
    if from >= to {
        return;
    }
    let mut w: [f64; KL] = std::array::from_fn(|i| b[from + i]);
    for j in from..to {
        prefetch(ab, (j + PREFETCH_COLUMNS) * ld + kv + 1, KL);
        let bj = w[0];
        b[j] = bj;
        let l: &[f64; KL] = ab[j * ld + kv + 1..][..KL].try_into().expect("KL entries");
        for i in 0..KL - 1 {
            w[i] = w[i + 1] - l[i] * bj;
        }
        w[KL - 1] = b[j + KL] - l[KL - 1] * bj;
    }
    b[to..to + KL].copy_from_slice(&w);
}

/// The backward solve's columns `to..from`, last first, with `ku` entries
/// above the diagonal each (`to ≥ ku`) and no interchange, for `ku` ∈
/// {11, 12, 17}; `false` (and nothing done) for other bandwidths.
/// `inverse`: the pivots' inverses.
pub(crate) fn backward_window(
    (ku, kv, ld): (usize, usize, usize),
    factors: (&[f64], &[f64]),
    b: &mut [f64],
    (to, from): (usize, usize),
) -> bool {
    match ku {
        11 => backward_fixed::<11, 12>((kv, ld), factors, b, (to, from)),
        12 => backward_fixed::<12, 13>((kv, ld), factors, b, (to, from)),
        17 => backward_fixed::<17, 18>((kv, ld), factors, b, (to, from)),
        _ => return false,
    }
    true
}

/// [`backward_window`] for `ku = KU`, `W = KU + 1`. The window `w` holds
/// `b[j − KU..=j]` as column `j` starts.
#[inline(always)]
fn backward_fixed<const KU: usize, const W: usize>(
    (kv, ld): (usize, usize),
    (ab, inverse): (&[f64], &[f64]),
    b: &mut [f64],
    (to, from): (usize, usize),
) {
    if from <= to {
        return;
    }
    let top = from - 1 - KU;
    let mut w: [f64; W] = std::array::from_fn(|i| b[top + i]);
    for j in (to..from).rev() {
        let col = j * ld + kv;
        prefetch(ab, col.wrapping_sub(PREFETCH_COLUMNS * ld + KU), KU);
        let bj = w[KU] * inverse[j];
        b[j] = bj;
        let u: &[f64; KU] = ab[col - KU..col].try_into().expect("KU entries");
        for k in (1..=KU).rev() {
            w[k] = w[k - 1] - u[k - 1] * bj;
        }
        // Row j − 1 − KU enters the window (in the matrix while j > KU).
        w[0] = if j > KU { b[j - 1 - KU] } else { 0.0 };
    }
    b[to - KU..to].copy_from_slice(&w[1..]);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A pseudo-random number in (−1, 1).
    fn noise(k: usize) -> f64 {
        ((k as f64 * 12.9898).sin() * 43_758.547).fract()
    }

    /// The general loops' column steps, in memory.
    fn forward_in_memory((kl, kv, ld): (usize, usize, usize), ab: &[f64], b: &mut [f64]) {
        for j in 0..b.len() - kl {
            let bj = b[j];
            for i in 1..=kl {
                b[j + i] -= ab[j * ld + kv + i] * bj;
            }
        }
    }

    fn backward_in_memory(
        (ku, kv, ld): (usize, usize, usize),
        (ab, inverse): (&[f64], &[f64]),
        b: &mut [f64],
    ) {
        for j in (ku..b.len()).rev() {
            b[j] *= inverse[j];
            let bj = b[j];
            for i in 1..=ku {
                b[j - i] -= ab[j * ld + kv - i] * bj;
            }
        }
    }

    #[test]
    fn the_windows_give_the_bits_of_the_loops_in_memory() {
        for width in [11, 12, 17] {
            let n = 5 * width + 3;
            let (kv, ld) = (2 * width, 3 * width + 1);
            let ab: Vec<f64> = (0..ld * n).map(|k| 2.0 + noise(k)).collect();
            let b: Vec<f64> = (0..n).map(|k| noise(k + 7)).collect();
            let (mut fast, mut slow) = (b.clone(), b.clone());
            assert!(forward_window(
                (width, kv, ld),
                &ab,
                &mut fast,
                (0, n - width)
            ));
            forward_in_memory((width, kv, ld), &ab, &mut slow);
            assert_eq!(fast, slow, "forward, width {width}");
            let inverse: Vec<f64> = (0..n).map(|j| 1.0 / ab[j * ld + kv]).collect();
            assert!(backward_window(
                (width, kv, ld),
                (&ab, &inverse),
                &mut fast,
                (width, n)
            ));
            backward_in_memory((width, kv, ld), (&ab, &inverse), &mut slow);
            assert_eq!(fast, slow, "backward, width {width}");
        }
        assert!(!forward_window((10, 20, 31), &[], &mut [], (0, 0)));
        assert!(!backward_window((10, 20, 31), (&[], &[]), &mut [], (0, 0)));
    }
}
