//! The band LU of a long chain in two halves at once: the renumbered band
//! (see [`crate::band_lu`]) is cut at its middle by a separator of
//! `w = max(kl, ku)` unknowns, which decouples the unknowns before it
//! (block 1) from those after it (block 2). In the order (block 1, block
//! 2, separator) the matrix is a bordered block diagonal,
//!
//! ```text
//! [ A₁₁   0    A₁ₛ ]
//! [ 0     A₂₂  A₂ₛ ]
//! [ Aₛ₁   Aₛ₂  Aₛₛ ]
//! ```
//!
//! and its LU is that of the two blocks — each a band LU, factorised at the
//! same time on two threads — and of the Schur complement
//! `S = Aₛₛ − Σₖ Yₖ Zₖ`, `Zₖ = Lₖ⁻¹ Pₖ Aₖₛ`, `Yₖ = Aₛₖ Uₖ⁻¹`, a dense `w × w`
//! matrix. Block 2 is numbered backwards, so that both blocks meet the
//! separator in their last rows and columns: `Zₖ` and `Yₖ` are zero but for
//! their last `kl + ku` entries and cost `O(w (kl + ku)²)` — the halves'
//! factorisations are all the work. A solve is the same in two halves:
//! `zₖ = Lₖ⁻¹ Pₖ bₖ` at once, `S xₛ = bₛ − Σₖ Yₖ zₖ`, then
//! `xₖ = Uₖ⁻¹ (zₖ − Zₖ xₛ)` at once ("burn at both ends").
//!
//! The operations and their order do not depend on the number of threads,
//! so neither do the results, to the bit. Pivots stay inside each block and
//! inside the separator; a block that is singular on its own (its
//! separator held — possible where the whole is regular, though not for
//! the tangents of supported chains) makes the factorisation fall back to
//! the one band LU of the whole, so a regular matrix is never refused.

use faer::sparse::SymbolicSparseColMat;

use crate::band_lu::{BandLu, BandStructure};

/// Fewest unknowns for which a band is factorised in two halves: below it
/// the halves' work is too small to hand to a second thread (a rayon
/// hand-off costs several µs; a band LU of 4 096 unknowns of a 2-node chain
/// about 0.5 ms).
pub const SPLIT_MIN_UNKNOWNS: usize = 4096;

/// One half of a split band: its band LU, where its values come from, and
/// its couplings to the separator.
#[derive(Debug, Clone)]
struct Half {
    /// Its band LU, reading the whole pattern's values
    /// ([`BandLu::with_sources`]).
    lu: BandLu,
    /// The entries coupling the half to the separator: `(row in the half,
    /// separator column, position in the values)` of `Aₖₛ`, and
    /// `(separator row, column in the half, position)` of `Aₛₖ`.
    to_sep: Vec<(usize, usize, usize)>,
    from_sep: Vec<(usize, usize, usize)>,
    /// Where the couplings live: rows/columns of the half from `tail` on.
    tail: usize,
    /// `Zₖ`, one column (the half's length) per separator unknown.
    z: Vec<Vec<f64>>,
    /// `Yₖ`, one row (the half's length) per separator unknown.
    y: Vec<Vec<f64>>,
    /// Scratch: the half's part of a right-hand side.
    b: Vec<f64>,
}

impl Half {
    /// Factorises the half with the whole's `values` and forms its `Zₖ`,
    /// `Yₖ`; returns its part `Yₖ Zₖ` of the Schur complement (row-major
    /// `w × w`), or `None` when the half is singular on its own.
    fn factor(&mut self, values: &[f64], w: usize) -> Option<Vec<f64>> {
        self.lu.factor(values);
        if !self.lu.pivots_regular() {
            return None;
        }
        let (kl, ku) = (self.lu.structure().kl, self.lu.structure().ku);
        let n = self.lu.len();
        let from = self.tail.saturating_sub(kl + ku);
        for col in self.z.iter_mut().chain(self.y.iter_mut()) {
            col[from..].iter_mut().for_each(|v| *v = 0.0);
        }
        for &(r, s, k) in &self.to_sep {
            self.z[s][r] = values[k];
        }
        for &(s, c, k) in &self.from_sep {
            self.y[s][c] = values[k];
        }
        for s in 0..w {
            self.lu.forward(&mut self.z[s], from);
            self.lu.row_backward(&mut self.y[s], self.tail);
        }
        let mut schur = vec![0.0; w * w];
        for (i, y) in self.y.iter().enumerate() {
            for (j, z) in self.z.iter().enumerate() {
                schur[i * w + j] = y[from..n].iter().zip(&z[from..n]).map(|(a, b)| a * b).sum();
            }
        }
        schur.iter().all(|v| v.is_finite()).then_some(schur)
    }

    /// `zₖ = Lₖ⁻¹ Pₖ bₖ` of the half's right-hand side (in `self.b`) and
    /// `Yₖ zₖ` (one value per separator unknown).
    fn forward(&mut self) -> Vec<f64> {
        self.lu.forward(&mut self.b, 0);
        let from = self
            .tail
            .saturating_sub(self.lu.structure().kl + self.lu.structure().ku);
        let b = &self.b;
        self.y
            .iter()
            .map(|y| y[from..].iter().zip(&b[from..]).map(|(a, c)| a * c).sum())
            .collect()
    }

    /// `xₖ = Uₖ⁻¹ (zₖ − Zₖ xₛ)` into `self.b`.
    fn backward(&mut self, xs: &[f64]) {
        let from = self
            .tail
            .saturating_sub(self.lu.structure().kl + self.lu.structure().ku);
        for (z, &x) in self.z.iter().zip(xs) {
            for (b, &zi) in self.b[from..].iter_mut().zip(&z[from..]) {
                *b -= zi * x;
            }
        }
        self.lu.backward(&mut self.b);
    }
}

/// A band LU factorised in two halves and a separator (see the module).
#[derive(Debug, Clone)]
pub struct SplitBandLu {
    /// The whole's renumbering and bandwidths.
    band: BandStructure,
    /// First unknown of the separator and its size, in the renumbering.
    sep: usize,
    w: usize,
    halves: [Half; 2],
    /// `(row, column, position in the values)` of `Aₛₛ`.
    sep_entries: Vec<(usize, usize, usize)>,
    /// The dense LU of the Schur complement (row-major) and its row
    /// interchanges.
    schur: Vec<f64>,
    schur_piv: Vec<usize>,
    /// The separator's diagonal entries of the last factorised matrix.
    sep_diag: Vec<f64>,
    /// The one band LU of the whole, used when a half is singular alone.
    whole: BandLu,
    fallback: bool,
    /// Scratch for the renumbered right-hand side.
    work: Vec<f64>,
}

impl SplitBandLu {
    /// The split of `pattern` renumbered by `band` (which
    /// [`BandStructure::fits`]), or `None` when the band is too short to
    /// leave two halves wider than the separator.
    pub fn new(pattern: &SymbolicSparseColMat<usize>, band: BandStructure) -> Option<Self> {
        let n = pattern.nrows();
        let w = band.kl.max(band.ku).max(1);
        if n < 4 * w + 4 {
            return None;
        }
        let sep = (n - w) / 2;
        // Renumbered index → (half, index in the half) or the separator.
        let place = |g: usize| -> (usize, usize) {
            if g < sep {
                (0, g)
            } else if g < sep + w {
                (2, g - sep)
            } else {
                (1, n - 1 - g)
            }
        };
        let sizes = [sep, n - sep - w];
        let mut entries: [Vec<(usize, usize, usize)>; 2] = [Vec::new(), Vec::new()];
        let (mut to_sep, mut from_sep) = ([Vec::new(), Vec::new()], [Vec::new(), Vec::new()]);
        let mut sep_entries = Vec::new();
        let (col_ptr, row_idx) = (pattern.col_ptr(), pattern.row_idx());
        for j in 0..n {
            let (hj, lj) = place(band.perm[j]);
            for (k, &i) in row_idx
                .iter()
                .enumerate()
                .take(col_ptr[j + 1])
                .skip(col_ptr[j])
            {
                let (hi, li) = place(band.perm[i]);
                match (hi, hj) {
                    (2, 2) => sep_entries.push((li, lj, k)),
                    (h, 2) => to_sep[h].push((li, lj, k)),
                    (2, h) => from_sep[h].push((li, lj, k)),
                    (a, b) if a == b => entries[a].push((li, lj, k)),
                    _ => return None,
                }
            }
        }
        let halves = [0, 1].map(|h| {
            let sub = std::mem::take(&mut entries[h]);
            half(
                sizes[h],
                sub,
                std::mem::take(&mut to_sep[h]),
                std::mem::take(&mut from_sep[h]),
                w,
            )
        });
        let [h0, h1] = halves;
        Some(Self {
            whole: BandLu::new(pattern, band.clone()),
            band,
            sep,
            w,
            halves: [h0?, h1?],
            sep_entries,
            schur: vec![0.0; w * w],
            schur_piv: vec![0; w],
            sep_diag: vec![0.0; w],
            fallback: false,
            work: vec![0.0; n],
        })
    }

    /// Factorises the matrix with the pattern's `values` (CSC order); a
    /// zero pivot of the whole leaves non-finite solves, as
    /// [`BandLu::factor`].
    pub fn factor(&mut self, values: &[f64]) {
        let w = self.w;
        let [h0, h1] = &mut self.halves;
        let (s0, s1) = crate::threads::join(|| h0.factor(values, w), || h1.factor(values, w));
        self.fallback = match (s0, s1) {
            (Some(s0), Some(s1)) => {
                self.schur.iter_mut().for_each(|v| *v = 0.0);
                for &(r, c, k) in &self.sep_entries {
                    self.schur[r * w + c] = values[k];
                    if r == c {
                        self.sep_diag[r] = values[k];
                    }
                }
                for ((s, a), b) in self.schur.iter_mut().zip(&s0).zip(&s1) {
                    *s -= a + b;
                }
                !dense_lu(&mut self.schur, &mut self.schur_piv, w)
            }
            _ => true,
        };
        if self.fallback {
            self.whole.factor(values);
        }
    }

    /// Solves `A x = rhs` in place with the last factorisation.
    pub fn solve(&mut self, rhs: &mut [f64]) {
        if self.fallback {
            return self.whole.solve(rhs);
        }
        let n = rhs.len();
        let (sep, w) = (self.sep, self.w);
        for (i, &p) in self.band.perm.iter().enumerate() {
            self.work[p] = rhs[i];
        }
        self.halves[0].b.copy_from_slice(&self.work[..sep]);
        for (q, b) in self.halves[1].b.iter_mut().enumerate() {
            *b = self.work[n - 1 - q];
        }
        let [h0, h1] = &mut self.halves;
        let (t0, t1) = crate::threads::join(|| h0.forward(), || h1.forward());
        let mut xs: Vec<f64> = (0..w)
            .map(|s| self.work[sep + s] - (t0[s] + t1[s]))
            .collect();
        dense_solve(&self.schur, &self.schur_piv, w, &mut xs);
        let [h0, h1] = &mut self.halves;
        crate::threads::join(|| h0.backward(&xs), || h1.backward(&xs));
        self.work[..sep].copy_from_slice(&self.halves[0].b);
        for (q, &b) in self.halves[1].b.iter().enumerate() {
            self.work[n - 1 - q] = b;
        }
        self.work[sep..sep + w].copy_from_slice(&xs);
        for (i, &p) in self.band.perm.iter().enumerate() {
            rhs[i] = self.work[p];
        }
    }

    /// The smallest equilibrated pivot of the last factorisation over its
    /// largest, as [`BandLu::pivot_ratio`]: the halves' and the Schur
    /// complement's (its pivots scaled by the separator's diagonal).
    pub fn pivot_ratio(&self) -> f64 {
        if self.fallback {
            return self.whole.pivot_ratio();
        }
        let w = self.w;
        let scale = |i: usize| {
            let d = self.sep_diag[i].abs();
            if d > 0.0 && d.is_finite() {
                1.0 / d.sqrt()
            } else {
                0.0
            }
        };
        // The Schur pivots against the halves' largest, which the
        // equilibration makes about 1 (each half's ratio is to its own).
        let schur = (0..w)
            .map(|i| self.schur[i * w + i].abs() * scale(i) * scale(i))
            .fold(f64::INFINITY, f64::min);
        let halves = self
            .halves
            .iter()
            .map(|h| h.lu.pivot_ratio())
            .fold(1.0, f64::min);
        halves.min(schur)
    }

    /// Whether the last factorisation fell back to the whole's band LU.
    pub fn fell_back(&self) -> bool {
        self.fallback
    }
}

/// A half of `size` unknowns with its own `entries` `(row, column,
/// position)` and its couplings: its band LU in its own (already banded)
/// numbering; `None` if that band does not fit.
fn half(
    size: usize,
    mut entries: Vec<(usize, usize, usize)>,
    to_sep: Vec<(usize, usize, usize)>,
    from_sep: Vec<(usize, usize, usize)>,
    w: usize,
) -> Option<Half> {
    entries.sort_unstable_by_key(|&(r, c, _)| (c, r));
    let mut col_ptr = vec![0usize; size + 1];
    for &(_, c, _) in &entries {
        col_ptr[c + 1] += 1;
    }
    for c in 0..size {
        col_ptr[c + 1] += col_ptr[c];
    }
    let row_idx = entries.iter().map(|e| e.0).collect();
    let pattern = SymbolicSparseColMat::new_checked(size, size, col_ptr, None, row_idx);
    let band = BandStructure::with_perm(&pattern, (0..size).collect());
    if !band.fits() {
        return None;
    }
    let tail = to_sep
        .iter()
        .map(|e| e.0)
        .chain(from_sep.iter().map(|e| e.1))
        .min()
        .unwrap_or(size);
    Some(Half {
        lu: BandLu::new(&pattern, band).with_sources(entries.iter().map(|e| e.2).collect()),
        to_sep,
        from_sep,
        tail,
        z: vec![vec![0.0; size]; w],
        y: vec![vec![0.0; size]; w],
        b: vec![0.0; size],
    })
}

/// LU with partial pivoting of the dense row-major `a` (`n × n`) in place,
/// the interchanges in `piv`; `false` for a zero or non-finite pivot.
fn dense_lu(a: &mut [f64], piv: &mut [usize], n: usize) -> bool {
    for k in 0..n {
        let p = (k..n).fold(k, |p, i| {
            if a[i * n + k].abs() > a[p * n + k].abs() {
                i
            } else {
                p
            }
        });
        piv[k] = p;
        if p != k {
            for c in 0..n {
                a.swap(k * n + c, p * n + c);
            }
        }
        let pivot = a[k * n + k];
        if pivot == 0.0 || !pivot.is_finite() {
            return false;
        }
        for i in k + 1..n {
            let l = a[i * n + k] / pivot;
            a[i * n + k] = l;
            for c in k + 1..n {
                a[i * n + c] -= l * a[k * n + c];
            }
        }
    }
    true
}

/// Solves with the factors of [`dense_lu`] in place (its interchanges
/// moved whole rows, the multipliers too: all of them first).
fn dense_solve(a: &[f64], piv: &[usize], n: usize, x: &mut [f64]) {
    for (k, &p) in piv.iter().enumerate().take(n) {
        x.swap(k, p);
    }
    for k in 0..n {
        for i in k + 1..n {
            x[i] -= a[i * n + k] * x[k];
        }
    }
    for k in (0..n).rev() {
        let t: f64 = (k + 1..n).map(|c| a[k * n + c] * x[c]).sum();
        x[k] = (x[k] - t) / a[k * n + k];
    }
}

#[cfg(test)]
#[path = "band_split_tests.rs"]
mod tests;
