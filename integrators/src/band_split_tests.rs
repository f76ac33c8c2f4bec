use super::*;

use crate::band_lu::tests::{product, scrambled_with};

/// A random unsymmetric matrix on a banded pattern of `n` unknowns and
/// half-width `width`, scrambled (so the renumbering has work to do), its
/// diagonal `diag` times its off-diagonal size.
fn banded(n: usize, width: usize, diag: f64, seed: u64) -> (SymbolicSparseColMat<usize>, Vec<f64>) {
    scrambled_with(n, width, seed, |r| diag * (1.0 + r))
}

/// `x` and the split solve of `A x̃ = A x`.
fn solve(
    split: &mut SplitBandLu,
    pattern: &SymbolicSparseColMat<usize>,
    values: &[f64],
) -> (Vec<f64>, Vec<f64>) {
    let n = pattern.nrows();
    let x: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
    let mut b = product(pattern, values, &x);
    split.factor(values);
    split.solve(&mut b);
    (x, b)
}

fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("a thread pool")
}

/// Diagonally dominant (no interchanges) and with small diagonals (many):
/// the split solves `A x = b` to round-off and agrees with the one band LU
/// of the whole.
#[test]
fn the_split_solves_like_the_whole_band() {
    for (n, width, diag, seed) in [
        (300, 11, 40.0, 1),
        (1000, 17, 0.2, 3),
        (257, 5, 0.05, 2),
        (257, 5, 1e-3, 2),
    ] {
        let (pattern, values) = banded(n, width, diag, seed);
        let band = BandStructure::of(&pattern);
        let mut split = SplitBandLu::new(&pattern, band.clone()).expect("long enough to split");
        let (x, got) = solve(&mut split, &pattern, &values);
        assert!(!split.fell_back(), "n = {n}");
        let err = max_diff(&x, &got);
        assert!(err < 1e-9, "n = {n}, width {width}: error {err:e}");
        let mut whole = BandLu::new(&pattern, band);
        whole.factor(&values);
        let mut b = product(&pattern, &values, &x);
        whole.solve(&mut b);
        assert!(max_diff(&b, &got) < 1e-9, "n = {n}: split and whole differ");
    }
}

/// The same bits on one thread and on two.
#[test]
fn the_split_gives_the_same_bits_on_one_thread_and_two() {
    let (pattern, values) = banded(600, 11, 0.5, 4);
    let run = |threads| {
        pool(threads).install(|| {
            let mut split =
                SplitBandLu::new(&pattern, BandStructure::of(&pattern)).expect("a split");
            solve(&mut split, &pattern, &values).1
        })
    };
    let (one, two) = (run(1), run(2));
    assert!(one
        .iter()
        .zip(&two)
        .all(|(a, b)| a.to_bits() == b.to_bits()));
}

/// A half singular on its own (one of its columns nonzero only in the
/// separator's rows) while the whole is regular: the whole's band LU takes
/// over, and the solve is right.
#[test]
fn a_half_singular_alone_falls_back_to_the_whole() {
    let (pattern, mut values) = banded(300, 4, 10.0, 5);
    let band = BandStructure::of(&pattern);
    let split = SplitBandLu::new(&pattern, band.clone()).expect("a split");
    let (sep, w) = (split.sep, split.w);
    // The unknown renumbered last before the separator.
    let col = band
        .perm
        .iter()
        .position(|&p| p == sep - 1)
        .expect("a column");
    let (cp, ri) = (pattern.col_ptr(), pattern.row_idx());
    let mut kept = 0;
    for k in cp[col]..cp[col + 1] {
        let p = band.perm[ri[k]];
        if p < sep {
            values[k] = 0.0;
        } else if p < sep + w {
            kept += 1;
        }
    }
    assert!(kept > 0, "the column reaches the separator");
    let mut split = split;
    let (x, got) = solve(&mut split, &pattern, &values);
    assert!(split.fell_back());
    let err = max_diff(&x, &got);
    assert!(err < 1e-8, "error {err:e}");
}

/// Patterns too short for two halves wider than the separator are not
/// split.
#[test]
fn a_short_band_is_not_split() {
    let (pattern, _) = banded(30, 11, 1.0, 6);
    assert!(SplitBandLu::new(&pattern, BandStructure::of(&pattern)).is_none());
}
