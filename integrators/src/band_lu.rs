//! Band LU with partial pivoting for tangents whose pattern has a narrow
//! band after a bandwidth-reducing ordering — the common case of beam
//! mechanisms, chains of elements whose unknowns couple only to their
//! neighbours'.
//!
//! The pattern is renumbered by reverse Cuthill–McKee (on the symmetric
//! pattern `A + Aᵀ`), the permuted matrix `P A Pᵀ` is stored as a dense band
//! in LAPACK's `gbtrf` layout (lower bandwidth `kl`, upper `ku`, `kl` extra
//! rows for the fill of row interchanges) and factorised column by column
//! with threshold partial pivoting within the band: `O(n kl (kl + ku))`
//! operations at most and no symbolic work per factorisation. The
//! elimination is left-looking: a column is loaded when it is reached and
//! takes the earlier steps' interchanges and multipliers then, so the
//! entries being updated stay one column (LAPACK's `gbtf2` is
//! right-looking; the factors are the same). For the
//! tangents of beam models this is several times faster than a general
//! sparse LU; wider patterns keep the general one
//! ([`crate::linsolve::SparseLu`] chooses).
//!
//! Pivots are chosen on the symmetrically equilibrated matrix `B = D A D`,
//! `dᵢ = |aᵢᵢ|^-½` ([`equilibrating_scale`]), so that the mixed units of
//! translations and rotations do not decide them, and a column keeps its
//! diagonal pivot unless an entry below it is more than `1/`[`PIVOT_THRESHOLD`]
//! times larger (threshold pivoting, as the general sparse LU codes do). The
//! elimination of `B` and of `A` differ only by the scales (`P B = L' U'` ⇔
//! `P A = (P D⁻¹ Pᵀ L' P D Pᵀ)(P D⁻¹ Pᵀ U' D⁻¹)`), so `A` itself is factorised
//! and only the comparison of candidates sees `dᵢ |aᵢⱼ|`. The tangents of beam
//! mechanisms then need almost no row interchanges, and without them the
//! factors keep the upper bandwidth `ku` instead of `kl + ku` — half the
//! work. Each interchange still bounds the growth of the (equilibrated)
//! entries by `1 + 1/τ`.

use faer::sparse::SymbolicSparseColMat;
use std::collections::VecDeque;

use crate::band_solve::{backward_window, forward_window};
use crate::sparsity::transposed;
use crate::tolerances::TOLERANCES;

/// A column keeps its diagonal pivot while `|bⱼⱼ| ≥ τ maxᵢ |bᵢⱼ|` on the
/// equilibrated matrix: `τ = 0.1`.
pub const PIVOT_THRESHOLD: f64 = TOLERANCES.pivot_threshold;

/// The symmetric equilibrating scale of a matrix with diagonal magnitudes
/// `diag`: `dᵢ = |aᵢᵢ|^-½`, the mean diagonal standing in for a zero (or
/// non-finite) one, and `1` where the whole diagonal vanishes.
pub fn equilibrating_scale(diag: &[f64]) -> Vec<f64> {
    let mut scale = diag.to_vec();
    equilibrate_in_place(&mut scale);
    scale
}

/// [`equilibrating_scale`] in place: the diagonal given in `v` becomes its
/// scale (no allocation: a band factorisation takes it every time).
fn equilibrate_in_place(v: &mut [f64]) {
    let finite = v.iter().filter(|a| a.is_finite());
    let (sum, count) = finite.fold((0.0, 0usize), |(s, c), &a| (s + a.abs(), c + 1));
    let mean = if count > 0 { sum / count as f64 } else { 0.0 };
    for x in v.iter_mut() {
        let a = x.abs();
        *x = if a > 0.0 && a.is_finite() {
            1.0 / a.sqrt()
        } else if mean > 0.0 && mean.is_finite() {
            1.0 / mean.sqrt()
        } else {
            1.0
        };
    }
}

/// The renumbering and band structure of a square pattern.
#[derive(Debug, Clone)]
pub struct BandStructure {
    /// `perm[i]`: the new index of unknown `i`.
    pub perm: Vec<usize>,
    /// Lower bandwidth of the permuted pattern.
    pub kl: usize,
    /// Upper bandwidth of the permuted pattern.
    pub ku: usize,
}

impl BandStructure {
    /// Reverse Cuthill–McKee renumbering of `pattern` and the resulting
    /// bandwidths. Every connected component starts from a node of least
    /// degree.
    pub fn of(pattern: &SymbolicSparseColMat<usize>) -> Self {
        let n = pattern.nrows();
        let (adj_ptr, adj) = symmetric_adjacency(pattern);
        let neighbours = |v: usize| &adj[adj_ptr[v]..adj_ptr[v + 1]];
        let degree: Vec<usize> = (0..n).map(|v| neighbours(v).len()).collect();
        let mut order = Vec::with_capacity(n);
        let mut seen = vec![false; n];
        let mut by_degree: Vec<usize> = (0..n).collect();
        // The keys are unique (ties go by index): the unstable sort gives
        // the stable one's order.
        by_degree.sort_unstable_by_key(|&i| (degree[i], i));
        let mut next = Vec::new();
        for &root in &by_degree {
            if seen[root] {
                continue;
            }
            seen[root] = true;
            let mut queue = VecDeque::from([root]);
            while let Some(v) = queue.pop_front() {
                order.push(v);
                next.clear();
                next.extend(neighbours(v).iter().copied().filter(|&w| !seen[w]));
                next.sort_unstable_by_key(|&w| (degree[w], w));
                for &w in &next {
                    seen[w] = true;
                    queue.push_back(w);
                }
            }
        }
        order.reverse();
        let mut perm = vec![0; n];
        for (new, &old) in order.iter().enumerate() {
            perm[old] = new;
        }
        Self::with_perm(pattern, perm)
    }

    /// The bandwidths of `pattern` renumbered by `perm` (`perm[i]`: the new
    /// index of unknown `i`).
    pub fn with_perm(pattern: &SymbolicSparseColMat<usize>, perm: Vec<usize>) -> Self {
        let n = pattern.nrows();
        let (col_ptr, row_idx) = (pattern.col_ptr(), pattern.row_idx());
        let (mut kl, mut ku) = (0, 0);
        for j in 0..n {
            for &i in &row_idx[col_ptr[j]..col_ptr[j + 1]] {
                let (pi, pj) = (perm[i], perm[j]);
                if pi > pj {
                    kl = kl.max(pi - pj);
                } else {
                    ku = ku.max(pj - pi);
                }
            }
        }
        Self { perm, kl, ku }
    }

    /// Whether the band's storage rows can be numbered in 32 bits (the
    /// factorisation's scatter map is), as every band that fits in memory
    /// can.
    pub fn fits(&self) -> bool {
        2 * self.kl + self.ku < u32::MAX as usize
    }

    /// Storage of the band factorisation, in values.
    pub fn storage(&self) -> usize {
        (2 * self.kl + self.ku + 1) * self.perm.len()
    }
}

/// The neighbours of every unknown in the symmetric pattern `A + Aᵀ`
/// (the diagonal left out), sorted and unique, as compressed rows: those of
/// `v` at `adj[ptr[v]..ptr[v + 1]]` (in flat storage: a list per unknown
/// was most of the renumbering's time).
fn symmetric_adjacency(pattern: &SymbolicSparseColMat<usize>) -> (Vec<usize>, Vec<usize>) {
    let n = pattern.nrows();
    let (col_ptr, row_idx) = (pattern.col_ptr(), pattern.row_idx());
    // Aᵀ by columns: the columns of each row of A.
    let (t_ptr, t_idx) = transposed(col_ptr, row_idx);
    let mut ptr = Vec::with_capacity(n + 1);
    let mut adj = Vec::with_capacity(2 * row_idx.len());
    ptr.push(0);
    for v in 0..n {
        let column = &row_idx[col_ptr[v]..col_ptr[v + 1]];
        let row = &t_idx[t_ptr[v]..t_ptr[v + 1]];
        if column.windows(2).all(|w| w[0] < w[1]) {
            // Then the rows of A are sorted and unique too (gathered
            // column by column).
            merge_without(column, row, v, &mut adj);
        } else {
            let mut neighbours: Vec<usize> = column
                .iter()
                .chain(row)
                .copied()
                .filter(|&w| w != v)
                .collect();
            neighbours.sort_unstable();
            neighbours.dedup();
            adj.extend_from_slice(&neighbours);
        }
        ptr.push(adj.len());
    }
    (ptr, adj)
}

/// Appends to `out` the union of the sorted, duplicate-free lists `a` and
/// `b` without `v`, in ascending order (a column's rows and a row's
/// columns of a CSC pattern are both sorted).
fn merge_without(a: &[usize], b: &[usize], v: usize, out: &mut Vec<usize>) {
    let (mut i, mut j) = (0, 0);
    loop {
        let next = match (a.get(i), b.get(j)) {
            (Some(&x), Some(&y)) => {
                i += usize::from(x <= y);
                j += usize::from(y <= x);
                x.min(y)
            }
            (Some(&x), None) => {
                i += 1;
                x
            }
            (None, Some(&y)) => {
                j += 1;
                y
            }
            (None, None) => return,
        };
        if next != v {
            out.push(next);
        }
    }
}

/// A band LU factorisation bound to one pattern.
#[derive(Debug, Clone)]
pub struct BandLu {
    band: BandStructure,
    /// Rows of the band storage, `2 kl + ku + 1`.
    ld: usize,
    /// Column-major band storage: entry `(r, c)` of `P A Pᵀ` (and of its
    /// factors) at `c ld + kl + ku + r − c`.
    ab: Vec<f64>,
    /// Row interchanges: at step `j`, rows `j` and `piv[j]`.
    piv: Vec<usize>,
    /// Row in its band-storage column (`kl + ku + r − c`) of each stored
    /// entry of the CSC pattern: narrow, so that loading a column streams
    /// half the bytes.
    slot: Vec<u32>,
    /// For each column of the band storage, the range of its entries in the
    /// CSC values (the column it is renumbered from).
    columns: Vec<std::ops::Range<usize>>,
    /// The entries of each column of the band storage as runs whose band
    /// rows go up or down by one from entry to entry ([`SlotRun`]), so that
    /// a column is loaded by copies: its runs are `runs[run_of[c]..run_of[c + 1]]`.
    runs: Vec<SlotRun>,
    /// Where each column's runs start in `runs` (and where they end).
    run_of: Vec<usize>,
    /// Where each stored entry's value is: its position in the values a
    /// factorisation is given, or (`None`) the entry's own index — the CSC
    /// values of the pattern itself. A half of a split band
    /// ([`crate::band_split`]) reads the whole's values through it, with no
    /// copy of its own.
    sources: Option<Vec<usize>>,
    /// Position in the CSC values of each unknown's diagonal entry.
    diagonal: Vec<Option<usize>>,
    /// For each column of the band storage, its first row that is not zero
    /// in the pattern (the diagonal at the latest). Without interchanges the
    /// rows above it stay zero in `U` — `u(i, c) = a(i, c) − Σ_{k<i} l(i, k)
    /// u(k, c)`, zero above the top by induction — so the steps before it
    /// change nothing in the column and are skipped: the envelope inside the
    /// band (on a chain of 6-unknown nodes, the column of a node's first
    /// unknown starts 5 rows below the band's top).
    top: Vec<usize>,
    /// Equilibrating scale of each row of the band storage, following the
    /// row interchanges during a factorisation.
    row_scale: Vec<f64>,
    /// The equilibrating scale of each column (of each unknown, renumbered).
    col_scale: Vec<f64>,
    /// The smallest and largest equilibrated pivot `|uⱼⱼ| dᵣ dⱼ` of the last
    /// factorisation (`dᵣ` the scale of the pivot's row).
    pivot_range: (f64, f64),
    /// Upper bandwidth of the last factors: `ku` plus the farthest row
    /// interchange (beyond `ku`, the last factorisation wrote into the rows
    /// kept for the fill of interchanges, which the next must clear).
    u_width: usize,
    /// Scratch for the permuted right-hand side.
    work: Vec<f64>,
    /// `1/uⱼⱼ` of the last factorisation's pivots: the backward solve
    /// multiplies by them (each column's division was its solve's longest
    /// wait).
    pivot_inverse: Vec<f64>,
}

impl BandLu {
    /// Storage and scatter map for `pattern` renumbered by `band`, which
    /// [`BandStructure::fits`].
    pub fn new(pattern: &SymbolicSparseColMat<usize>, band: BandStructure) -> Self {
        let n = pattern.nrows();
        let ld = 2 * band.kl + band.ku + 1;
        let kv = band.kl + band.ku;
        let (col_ptr, row_idx) = (pattern.col_ptr(), pattern.row_idx());
        let mut slot = Vec::with_capacity(row_idx.len());
        let mut diagonal = vec![None; n];
        let mut columns = vec![0..0; n];
        let mut top: Vec<usize> = (0..n).collect();
        for j in 0..n {
            columns[band.perm[j]] = col_ptr[j]..col_ptr[j + 1];
            for (k, &i) in row_idx[col_ptr[j]..col_ptr[j + 1]].iter().enumerate() {
                let (r, c) = (band.perm[i], band.perm[j]);
                top[c] = top[c].min(r);
                // Below `ld`, which `fits` bounds by 2³².
                slot.push((kv + r - c) as u32);
                if i == j {
                    diagonal[j] = Some(col_ptr[j] + k);
                }
            }
        }
        let (runs, run_of) = slot_runs(&slot, &columns);
        Self {
            ld,
            ab: vec![0.0; ld * n],
            piv: vec![0; n],
            slot,
            columns,
            runs,
            run_of,
            sources: None,
            diagonal,
            top,
            row_scale: vec![1.0; n],
            col_scale: vec![1.0; n],
            pivot_range: (0.0, 0.0),
            u_width: band.ku,
            work: vec![0.0; n],
            pivot_inverse: vec![0.0; n],
            band,
        }
    }

    /// The same factorisation reading the value of stored entry `k` of the
    /// pattern at `values[sources[k]]` of the values it is given.
    pub(crate) fn with_sources(mut self, sources: Vec<usize>) -> Self {
        debug_assert_eq!(sources.len(), self.slot.len());
        for k in self.diagonal.iter_mut().flatten() {
            *k = sources[*k];
        }
        self.sources = Some(sources);
        self
    }

    /// The equilibrating scale of the rows of `A` (renumbered).
    fn scale_rows(&mut self, values: &[f64]) {
        // The diagonal, then its scale, in the original numbering in
        // `col_scale` (as scratch).
        let scale = &mut self.col_scale;
        for (v, k) in scale.iter_mut().zip(&self.diagonal) {
            *v = k.map_or(0.0, |k| values[k]);
        }
        equilibrate_in_place(scale);
        for (&p, &d) in self.band.perm.iter().zip(scale.iter()) {
            self.row_scale[p] = d;
        }
        self.col_scale.copy_from_slice(&self.row_scale);
    }

    /// Factorises the matrix with the pattern's `values` (CSC order):
    /// `P A = L U` after the renumbering. A zero pivot leaves its column
    /// unfactorised; the solves then give non-finite values, which the
    /// caller reports.
    pub fn factor(&mut self, values: &[f64]) {
        self.scale_rows(values);
        let n = self.piv.len();
        let (kl, ku, ld) = (self.band.kl, self.band.ku, self.ld);
        let kv = kl + ku;
        // Rows kept for the fill of interchanges are still zero unless the
        // last factorisation interchanged rows.
        let from = if self.u_width > ku { 0 } else { kl };
        let (ab, d, piv) = (&mut self.ab, &mut self.row_scale, &mut self.piv);
        let inverse = &mut self.pivot_inverse;
        let mut farthest = 0usize;
        let (mut smallest, mut largest_pivot) = (f64::INFINITY, 0.0f64);
        let entries = Entries {
            slot: &self.slot,
            columns: &self.columns,
            runs: (&self.runs, &self.run_of),
            sources: self.sources.as_deref(),
            values,
        };
        for c in 0..LOAD_AHEAD.min(n) {
            entries.load(c, &mut ab[c * ld..(c + 1) * ld], from);
        }
        for c in 0..n {
            // Row r of column c at kv + r − c of its storage.
            let (done, rest) = ab.split_at_mut(c * ld);
            if c + LOAD_AHEAD < n {
                let ahead = (c + LOAD_AHEAD) * ld - c * ld;
                entries.load(c + LOAD_AHEAD, &mut rest[ahead..ahead + ld], from);
            }
            let column = &mut rest[..ld];
            update_column(
                (kl, ku, ld, n),
                (c, self.top[c], farthest),
                column,
                done,
                piv,
            );
            let km = kl.min(n - 1 - c);
            // Pivot: the diagonal unless an equilibrated entry below it is
            // more than 1/τ times larger, then the largest.
            let diagonal = column[kv].abs() * d[c];
            let below = &column[kv + 1..=kv + km];
            let scales = &d[c + 1..=c + km];
            let largest = largest_scaled(below, scales);
            let mut jp = 0;
            let mut best = diagonal;
            if diagonal < PIVOT_THRESHOLD * largest {
                for (i, (a, di)) in below.iter().zip(scales).enumerate() {
                    if a.abs() * di > best {
                        best = a.abs() * di;
                        jp = i + 1;
                    }
                }
            }
            piv[c] = c + jp;
            if best == 0.0 || !best.is_finite() {
                // Not finite: the solves give non-finite values.
                inverse[c] = 1.0 / column[kv];
                smallest = 0.0;
                continue;
            }
            if jp != 0 {
                // The later columns take the interchange when they are
                // reached; the multipliers of the earlier ones stay (the
                // solve interchanges in the same order).
                column.swap(kv, kv + jp);
                d.swap(c, c + jp);
                farthest = farthest.max(jp);
            }
            let pivot = column[kv].abs() * d[c] * self.col_scale[c];
            smallest = smallest.min(pivot);
            largest_pivot = largest_pivot.max(pivot);
            let reciprocal = 1.0 / column[kv];
            inverse[c] = reciprocal;
            column[kv + 1..=kv + km]
                .iter_mut()
                .for_each(|v| *v *= reciprocal);
        }
        self.u_width = ku + farthest;
        self.pivot_range = (smallest, largest_pivot);
    }

    /// The smallest equilibrated pivot of the last factorisation over its
    /// largest (0 for a zero or non-finite pivot, 1 for no unknowns).
    pub fn pivot_ratio(&self) -> f64 {
        let (smallest, largest) = self.pivot_range;
        if smallest == f64::INFINITY {
            1.0
        } else if largest > 0.0 && largest.is_finite() {
            smallest / largest
        } else {
            0.0
        }
    }

    /// Solves `A x = rhs` in place with the last factorisation.
    pub fn solve(&mut self, rhs: &mut [f64]) {
        let mut b = std::mem::take(&mut self.work);
        for (i, &p) in self.band.perm.iter().enumerate() {
            b[p] = rhs[i];
        }
        self.forward(&mut b, 0);
        self.backward(&mut b);
        for (i, &p) in self.band.perm.iter().enumerate() {
            rhs[i] = b[p];
        }
        self.work = b;
    }

    /// `b ← L⁻¹ P b` in the renumbered unknowns (the interchanges and the
    /// unit lower factor), for a `b` that is zero above row `from + kl`:
    /// the steps before `from` neither move nor change it.
    pub(crate) fn forward(&self, b: &mut [f64], from: usize) {
        let n = self.piv.len();
        let (kl, kv, ld) = (self.band.kl, self.band.kl + self.band.ku, self.ld);
        // Without interchanges, the columns with a full band in registers.
        let to = n.saturating_sub(kl).max(from);
        let windowed =
            self.u_width == self.band.ku && forward_window((kl, kv, ld), &self.ab, b, (from, to));
        for j in if windowed { to } else { from }..n {
            let l = self.piv[j];
            if l != j {
                b.swap(l, j);
            }
            let km = kl.min(n - 1 - j);
            let col = j * ld + kv;
            let bj = b[j];
            subtract_multiple(&mut b[j + 1..=j + km], &self.ab[col + 1..=col + km], bj);
        }
    }

    /// `b ← U⁻¹ b` in the renumbered unknowns: upper bandwidth `ku` plus the
    /// farthest interchange (≤ `kl + ku`), each `bⱼ` times its pivot's
    /// inverse.
    pub(crate) fn backward(&self, b: &mut [f64]) {
        let (ku, kv, ld) = (self.band.ku, self.band.kl + self.band.ku, self.ld);
        let n = self.piv.len();
        // Without interchanges, the columns with a full band in registers.
        let to = ku.min(n);
        let (ab, inverse) = (&self.ab[..], &self.pivot_inverse[..]);
        let windowed =
            self.u_width == ku && backward_window((ku, kv, ld), (ab, inverse), b, (to, n));
        for j in (0..if windowed { to } else { n }).rev() {
            let col = j * ld + kv;
            b[j] *= self.pivot_inverse[j];
            let bj = b[j];
            let top = j.saturating_sub(self.u_width);
            subtract_multiple(&mut b[top..j], &self.ab[col + top - j..col], bj);
        }
    }

    /// `y ← y U⁻¹` (the row vector `y` solving `y U = a`, `a` given in `y`)
    /// in the renumbered unknowns, for an `a` that is zero before column
    /// `from` (so is `y`).
    pub(crate) fn row_backward(&self, y: &mut [f64], from: usize) {
        let (kv, ld) = (self.band.kl + self.band.ku, self.ld);
        for j in from..self.piv.len() {
            let col = j * ld + kv;
            let top = j.saturating_sub(self.u_width).max(from);
            let u = &self.ab[col + top - j..col];
            let t: f64 = y[top..j].iter().zip(u).map(|(a, b)| a * b).sum();
            y[j] = (y[j] - t) / self.ab[col];
        }
    }

    /// Whether every pivot of the last factorisation is finite and
    /// nonzero (else a solve gives non-finite values).
    pub(crate) fn pivots_regular(&self) -> bool {
        let kv = self.band.kl + self.band.ku;
        (0..self.piv.len()).all(|j| {
            let p = self.ab[j * self.ld + kv];
            p != 0.0 && p.is_finite()
        })
    }

    /// The unknowns' count.
    pub(crate) fn len(&self) -> usize {
        self.piv.len()
    }

    /// The renumbering and bandwidths the factorisation works in.
    pub(crate) fn structure(&self) -> &BandStructure {
        &self.band
    }
}

/// The earlier steps that reach column `c` of a left-looking band LU, in
/// order: each step's interchange, then its multipliers times the entry of
/// its pivot row (`column`: the column's storage; `done`: the columns
/// before it; `piv`: their interchanges). Rows above `c − ku` are reached
/// only through interchanges (`farthest`, the farthest so far). Without
/// any, the steps before the column's `top` change nothing in it, and
/// columns past the first `ku` whose band lies inside the matrix take the
/// unrolled update of the common bandwidths.
fn update_column(
    (kl, ku, ld, n): (usize, usize, usize, usize),
    (c, top, farthest): (usize, usize, usize),
    column: &mut [f64],
    done: &[f64],
    piv: &[usize],
) {
    let kv = kl + ku;
    if farthest == 0
        && c >= ku
        && c + kl < n
        && eliminate_unrolled(
            (kl, ku, ld),
            top - (c - ku),
            &mut column[kl..],
            &done[(c - ku) * ld..],
        )
    {
        return;
    }
    let first = match farthest {
        0 => top.max(c.saturating_sub(ku)),
        _ => c.saturating_sub(ku + farthest),
    };
    for j in first..c {
        let rj = kv + j - c;
        let jp = piv[j] - j;
        if jp != 0 {
            column.swap(rj, rj + jp);
        }
        // No test for a zero `u`: on these bands it is rare, and a
        // mispredicted branch costs more than the update.
        let u = column[rj];
        let km = kl.min(n - 1 - j);
        let multipliers = &done[j * ld + kv + 1..=j * ld + kv + km];
        subtract_multiple(&mut column[rj + 1..=rj + km], multipliers, u);
    }
}

/// Columns a factorisation loads ahead of the one it eliminates: each
/// column's entries are stored one by one and then read by the update in
/// pairs, which waits where the stores are still in flight.
const LOAD_AHEAD: usize = 4;

/// A run of a band column's entries: the `len` values from `at` in the CSC
/// values go to the band rows from `row` on, down the column (`up`
/// false: rows `row, row + 1, …`) or up it (`row, row − 1, …`).
#[derive(Debug, Clone, Copy)]
struct SlotRun {
    row: u32,
    len: u32,
    up: bool,
    at: usize,
}

/// The runs of every band column's entries ([`BandLu::runs`]): maximal
/// stretches of a column's CSC entries whose band rows step by one in one
/// direction.
fn slot_runs(slot: &[u32], columns: &[std::ops::Range<usize>]) -> (Vec<SlotRun>, Vec<usize>) {
    let mut runs: Vec<SlotRun> = Vec::new();
    let mut run_of = Vec::with_capacity(columns.len() + 1);
    for entries in columns {
        run_of.push(runs.len());
        let first = runs.len();
        for k in entries.clone() {
            let row = slot[k];
            if let Some(r) = runs[first..].last_mut() {
                let next = |up: bool| {
                    if up {
                        r.row.checked_sub(r.len)
                    } else {
                        r.row.checked_add(r.len)
                    }
                };
                if r.len == 1 && (row + 1 == r.row || r.row + 1 == row) {
                    r.up = row + 1 == r.row;
                    r.len = 2;
                    continue;
                }
                if r.len > 1 && next(r.up) == Some(row) {
                    r.len += 1;
                    continue;
                }
            }
            runs.push(SlotRun {
                row,
                len: 1,
                up: false,
                at: k,
            });
        }
    }
    run_of.push(runs.len());
    (runs, run_of)
}

/// The pattern's values as the band storage's columns take them.
struct Entries<'a> {
    slot: &'a [u32],
    columns: &'a [std::ops::Range<usize>],
    runs: (&'a [SlotRun], &'a [usize]),
    sources: Option<&'a [usize]>,
    values: &'a [f64],
}

impl Entries<'_> {
    /// Column `c` of the band storage (`column`, zero from row `from`) with
    /// its entries.
    fn load(&self, c: usize, column: &mut [f64], from: usize) {
        column[from..].iter_mut().for_each(|v| *v = 0.0);
        let entries = self.columns[c].clone();
        let slots = &self.slot[entries.clone()];
        match self.sources {
            None => {
                let (runs, run_of) = self.runs;
                for r in &runs[run_of[c]..run_of[c + 1]] {
                    let (row, len) = (r.row as usize, r.len as usize);
                    let src = &self.values[r.at..r.at + len];
                    if r.up {
                        let dst = &mut column[row + 1 - len..=row];
                        for (d, &v) in dst.iter_mut().rev().zip(src) {
                            *d = v;
                        }
                    } else {
                        column[row..row + len].copy_from_slice(src);
                    }
                }
            }
            Some(src) => {
                for (&row, &k) in slots.iter().zip(&src[entries]) {
                    column[row as usize] = self.values[k];
                }
            }
        }
    }
}

/// The left-looking update of one column with no interchanges among the
/// `ku` steps before it, for the bandwidths of the common beam chains
/// (`kl = ku` = 11 for 2-node elements, 17 for 3-node ones, 12 for the
/// mechanisms of 2-node links closed by joints: the slider-crank's and the
/// four-bar's of `data/benchmarks`); `false` (and
/// nothing done) for others. `lead`: the rows of the window that stay
/// zero (the column's top is `c − ku + lead`), whose steps are skipped;
/// `window`: the column's storage from row `c − ku` on; `earlier`: the
/// storage from column `c − ku` on. The same operations in the same order
/// as the general loop.
fn eliminate_unrolled(
    (kl, ku, ld): (usize, usize, usize),
    lead: usize,
    window: &mut [f64],
    earlier: &[f64],
) -> bool {
    match (kl, ku) {
        (11, 11) => eliminate_led::<11, 11, 23>(ld, lead, window, earlier),
        (12, 12) => eliminate_led::<12, 12, 25>(ld, lead, window, earlier),
        (17, 17) => eliminate_led::<17, 17, 35>(ld, lead, window, earlier),
        _ => false,
    }
}

/// [`eliminate_fixed`] with the zero rows it skips fixed at compile time:
/// up to [`MOST_LEAD`] (a column of a 6-unknown node has at most 5), fewer
/// than there are for a longer lead (skipping fewer is always right).
#[inline(always)]
fn eliminate_led<const KL: usize, const KU: usize, const W: usize>(
    ld: usize,
    lead: usize,
    window: &mut [f64],
    earlier: &[f64],
) -> bool {
    match lead {
        0 => eliminate_fixed::<KL, KU, W, 0>(ld, window, earlier),
        1 => eliminate_fixed::<KL, KU, W, 1>(ld, window, earlier),
        2 => eliminate_fixed::<KL, KU, W, 2>(ld, window, earlier),
        3 => eliminate_fixed::<KL, KU, W, 3>(ld, window, earlier),
        4 => eliminate_fixed::<KL, KU, W, 4>(ld, window, earlier),
        _ => eliminate_fixed::<KL, KU, W, MOST_LEAD>(ld, window, earlier),
    }
}

/// The most leading zero rows of a column the unrolled update skips.
const MOST_LEAD: usize = 5;

/// [`eliminate_unrolled`] for `kl = KL`, `ku = KU`, `W = KL + KU + 1`,
/// the first `T` rows of the window zero (`T < KU`).
#[inline(always)]
fn eliminate_fixed<const KL: usize, const KU: usize, const W: usize, const T: usize>(
    ld: usize,
    window: &mut [f64],
    earlier: &[f64],
) -> bool {
    let kv = KL + KU;
    // Step jj's multiplier of row i at jj·ld + kv + i − jj (row i − jj − 1
    // below its diagonal).
    let Some(Ok(x)) = window.get_mut(..W).map(<&mut [f64; W]>::try_from) else {
        return false;
    };
    if earlier.len() < (KU - 1) * ld + kv + 1 + KL {
        return false;
    }
    // Each row takes the steps jj that reach it (i − kl ≤ jj < i) in order,
    // as step by step. The rows of U (i < ku) first, each as one running
    // sum; then the rows from the diagonal down, step by step over the same
    // positions — so that no update loads entries the previous one has just
    // stored at an offset of one, which the processor cannot forward from
    // the stores.
    for i in (T + 1)..KU {
        let mut t = x[i];
        for jj in i.saturating_sub(KL).max(T)..i {
            t -= earlier[jj * ld + kv + i - jj] * x[jj];
        }
        x[i] = t;
    }
    for jj in T..KU {
        let (u, lo, hi) = (x[jj], KU.max(jj + 1), jj + KL);
        let m = &earlier[jj * ld + kv + lo - jj..=jj * ld + kv + hi - jj];
        for (t, &l) in x[lo..=hi].iter_mut().zip(m) {
            *t -= l * u;
        }
    }
    true
}

/// The largest `|aᵢ| dᵢ` (0 for none; a NaN counts as nothing, as in
/// `f64::max`), in four running maxima: a column's pivot waited on one
/// chain of comparisons. The maximum of the same numbers in any order is
/// the same number.
fn largest_scaled(a: &[f64], d: &[f64]) -> f64 {
    let bigger = |m: f64, v: f64| if v > m { v } else { m };
    let mut lanes = [0.0f64; 4];
    for (ac, dc) in a.chunks_exact(4).zip(d.chunks_exact(4)) {
        for k in 0..4 {
            lanes[k] = bigger(lanes[k], ac[k].abs() * dc[k]);
        }
    }
    let tail = a.len() - a.len() % 4;
    for (&x, &s) in a[tail..].iter().zip(&d[tail..]) {
        lanes[0] = bigger(lanes[0], x.abs() * s);
    }
    bigger(bigger(lanes[0], lanes[1]), bigger(lanes[2], lanes[3]))
}

/// `t ← t − u l`.
fn subtract_multiple(t: &mut [f64], l: &[f64], u: f64) {
    t.iter_mut().zip(l).for_each(|(t, &l)| *t -= l * u);
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A random unsymmetric matrix on a banded pattern, scrambled by a
    /// permutation (so RCM has work to do) and with small diagonal entries
    /// (so pivoting has work to do).
    fn scrambled(n: usize, width: usize, seed: u64) -> (SymbolicSparseColMat<usize>, Vec<f64>) {
        scrambled_with(n, width, seed, |r| 1e-3 * r)
    }

    /// [`scrambled`] with the diagonal `diag(r)` of a random `r` in
    /// `[-½, ½)`.
    pub(crate) fn scrambled_with(
        n: usize,
        width: usize,
        seed: u64,
        diag: impl Fn(f64) -> f64,
    ) -> (SymbolicSparseColMat<usize>, Vec<f64>) {
        let mut s = seed;
        let mut rand = || {
            s = s
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let shuffle: Vec<usize> = (0..n).map(|i| (i * 7 + 3) % n).collect();
        let mut entries = Vec::new();
        for i in 0..n {
            for j in i.saturating_sub(width)..(i + width + 1).min(n) {
                let v = if i == j { diag(rand()) } else { rand() };
                entries.push((shuffle[i], shuffle[j], v));
            }
        }
        entries.sort_by_key(|&(i, j, _)| (j, i));
        let mut col_ptr = vec![0usize; n + 1];
        for &(_, j, _) in &entries {
            col_ptr[j + 1] += 1;
        }
        for j in 0..n {
            col_ptr[j + 1] += col_ptr[j];
        }
        let row_idx = entries.iter().map(|e| e.0).collect();
        let pattern = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx);
        (pattern, entries.iter().map(|e| e.2).collect())
    }

    /// `A + Aᵀ`'s neighbour lists built the plain way: a list per unknown.
    fn adjacency_by_lists(pattern: &SymbolicSparseColMat<usize>) -> Vec<Vec<usize>> {
        let (col_ptr, row_idx) = (pattern.col_ptr(), pattern.row_idx());
        let mut adj = vec![Vec::new(); pattern.nrows()];
        for j in 0..pattern.nrows() {
            for &i in &row_idx[col_ptr[j]..col_ptr[j + 1]] {
                if i != j {
                    adj[i].push(j);
                    adj[j].push(i);
                }
            }
        }
        for a in adj.iter_mut() {
            a.sort_unstable();
            a.dedup();
        }
        adj
    }

    #[test]
    fn the_flat_adjacency_is_the_symmetric_patterns() {
        // An unsymmetric pattern (entries (i, j) by columns) and scrambled bands.
        let columns: [&[usize]; 6] = [&[0, 1, 3], &[1, 2], &[2, 5], &[3], &[0, 4], &[4, 5]];
        let mut col_ptr = vec![0];
        let mut row_idx = Vec::new();
        for c in columns {
            row_idx.extend_from_slice(c);
            col_ptr.push(row_idx.len());
        }
        // The same columns with their rows out of order (merged only when
        // sorted).
        let unsorted: Vec<usize> = columns
            .iter()
            .flat_map(|c| c.iter().rev().copied())
            .collect();
        let mut patterns = vec![
            SymbolicSparseColMat::new_unsorted_checked(6, 6, col_ptr.clone(), None, unsorted),
            SymbolicSparseColMat::new_checked(6, 6, col_ptr, None, row_idx),
        ];
        patterns.extend([(40, 3, 1), (61, 6, 2)].map(|(n, w, seed)| scrambled(n, w, seed).0));
        for pattern in &patterns {
            let (ptr, adj) = symmetric_adjacency(pattern);
            let flat: Vec<Vec<usize>> = ptr.windows(2).map(|w| adj[w[0]..w[1]].to_vec()).collect();
            assert_eq!(flat, adjacency_by_lists(pattern));
        }
    }

    #[test]
    fn solves_agree_with_the_product_to_round_off() {
        for (n, width, seed) in [(40, 3, 1), (97, 5, 2), (300, 11, 3), (11, 6, 4)] {
            let (pattern, values) = scrambled(n, width, seed);
            let band = BandStructure::of(&pattern);
            // RCM recovers a band no wider than the original.
            assert!(
                band.kl <= width && band.ku <= width,
                "{n}: {} {}",
                band.kl,
                band.ku
            );
            let err = solve_error(&pattern, &values, band);
            assert!(err < 1e-9, "n = {n}: error {err:e}");
        }
    }

    /// Without interchanges, at the bandwidths of the unrolled column
    /// update (11, 12, 17) and one beside them (13): the row-by-row solves and
    /// the unrolled update give the product's `x` back.
    #[test]
    fn solves_without_interchanges_agree_with_the_product() {
        for (n, width, seed) in [
            (300, 11, 5),
            (200, 17, 6),
            (150, 12, 7),
            (143, 13, 9),
            (30, 11, 8),
        ] {
            let (pattern, mut values) = scrambled(n, width, seed);
            // Diagonally dominant: the diagonal pivots all stay.
            let (cp, ri) = (pattern.col_ptr(), pattern.row_idx());
            for j in 0..n {
                for k in cp[j]..cp[j + 1] {
                    if ri[k] == j {
                        values[k] = 4.0 * width as f64;
                    }
                }
            }
            let band = BandStructure::of(&pattern);
            assert_eq!((band.kl, band.ku), (width, width), "n = {n}");
            let mut lu = BandLu::new(&pattern, band.clone());
            lu.factor(&values);
            assert_eq!(lu.u_width, width, "an interchange");
            let err = solve_error(&pattern, &values, band);
            assert!(err < 1e-12, "n = {n}, width {width}: error {err:e}");
        }
    }

    /// A chain of `nodes` nodes of `per` unknowns, each node coupled to the
    /// next (a 2-node element's `2·per` square block), with pseudo-random
    /// entries and a dominant diagonal (no interchanges).
    fn node_chain(nodes: usize, per: usize) -> (SymbolicSparseColMat<usize>, Vec<f64>) {
        let n = nodes * per;
        let (mut col_ptr, mut row_idx, mut values) = (vec![0], Vec::new(), Vec::new());
        for j in 0..n {
            let node = j / per;
            let rows = node.saturating_sub(1) * per..((node + 2) * per).min(n);
            for i in rows {
                let k = values.len();
                values.push(if i == j {
                    8.0 * per as f64
                } else {
                    (k as f64 * 0.618).sin()
                });
                row_idx.push(i);
            }
            col_ptr.push(row_idx.len());
        }
        let pattern = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx);
        (pattern, values)
    }

    /// A column loaded by its runs holds the values the entries' slots
    /// scatter, on a node chain (long runs, up or down the column as the
    /// renumbering goes) and on a scrambled pattern (short ones).
    #[test]
    fn a_column_loaded_by_runs_holds_what_its_slots_scatter() {
        let (chain, chain_values) = node_chain(7, 6);
        let (scrambled, scrambled_values) = scrambled(40, 5, 3);
        let mut longest = 0;
        for (pattern, values) in [(chain, chain_values), (scrambled, scrambled_values)] {
            let lu = BandLu::new(&pattern, BandStructure::of(&pattern));
            let entries = Entries {
                slot: &lu.slot,
                columns: &lu.columns,
                runs: (&lu.runs, &lu.run_of),
                sources: None,
                values: &values,
            };
            for c in 0..lu.columns.len() {
                let mut column = vec![f64::NAN; lu.ld];
                entries.load(c, &mut column, 0);
                let mut expected = vec![0.0; lu.ld];
                for k in lu.columns[c].clone() {
                    expected[lu.slot[k] as usize] = values[k];
                }
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(&column), bits(&expected), "column {c}");
            }
            longest = longest.max(lu.runs.iter().map(|r| r.len).max().unwrap_or(0));
        }
        assert!(longest >= 12, "a chain's column is a few runs: {longest}");
    }

    /// The steps skipped above each column's top (its first row of the
    /// pattern) change nothing: factors and solutions are bitwise those of
    /// the whole band, through the unrolled updates (nodes of 6 and 9
    /// unknowns: bandwidths 11 and 17) and the general loop (5: 9).
    #[test]
    fn skipping_the_steps_above_a_columns_top_gives_the_bits_of_the_whole_band() {
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        for per in [6, 9, 5] {
            let (pattern, values) = node_chain(40, per);
            let n = pattern.nrows();
            let band = BandStructure::of(&pattern);
            assert_eq!((band.kl, band.ku), (2 * per - 1, 2 * per - 1));
            let mut skipping = BandLu::new(&pattern, band.clone());
            let mut whole = skipping.clone();
            whole.top = (0..n).map(|c| c.saturating_sub(band.ku)).collect();
            assert!(skipping.top != whole.top, "{per}: no column to skip in");
            skipping.factor(&values);
            whole.factor(&values);
            assert_eq!(skipping.u_width, band.ku, "{per}: an interchange");
            assert_eq!(bits(&skipping.ab), bits(&whole.ab), "{per}: factors");
            assert_eq!(bits(&skipping.pivot_inverse), bits(&whole.pivot_inverse));
            let rhs: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).cos()).collect();
            let (mut a, mut b) = (rhs.clone(), rhs);
            skipping.solve(&mut a);
            whole.solve(&mut b);
            assert_eq!(bits(&a), bits(&b), "{per}: solutions");
        }
    }

    /// `max |x̃ − x|` where `x̃` solves `A x̃ = A x` by the band LU.
    fn solve_error(
        pattern: &SymbolicSparseColMat<usize>,
        values: &[f64],
        band: BandStructure,
    ) -> f64 {
        let n = pattern.nrows();
        let mut lu = BandLu::new(pattern, band);
        lu.factor(values);
        let x: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
        // b = A x
        let mut b = vec![0.0; n];
        let (cp, ri) = (pattern.col_ptr(), pattern.row_idx());
        for j in 0..n {
            for k in cp[j]..cp[j + 1] {
                b[ri[k]] += values[k] * x[j];
            }
        }
        lu.solve(&mut b);
        b.iter()
            .zip(&x)
            .map(|(a, e)| (a - e).abs())
            .fold(0.0, f64::max)
    }

    #[test]
    fn the_solver_picks_the_band_only_for_narrow_patterns_and_both_agree() {
        use crate::linsolve::SparseLu;
        let (pattern, values) = scrambled(120, 4, 6);
        let mut band = SparseLu::new(pattern.clone()).unwrap();
        let mut general = SparseLu::general(pattern).unwrap();
        assert!(band.is_band() && !general.is_band());
        band.factor(&values).unwrap();
        general.factor(&values).unwrap();
        let mut a: Vec<f64> = (0..120).map(|i| (i as f64).cos()).collect();
        let mut b = a.clone();
        band.solve(&mut a).unwrap();
        general.solve(&mut b).unwrap();
        let diff = a
            .iter()
            .zip(&b)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max);
        let size = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(diff <= 1e-10 * size, "{diff:e} of {size:e}");
        // An arrow (diagonal plus a full first row and column: no ordering
        // narrows its band) keeps the general LU.
        let n = 200;
        let mut col_ptr = vec![0usize];
        let mut row_idx = Vec::new();
        for j in 0..n {
            if j == 0 {
                row_idx.extend(0..n);
            } else {
                row_idx.extend([0, j]);
            }
            col_ptr.push(row_idx.len());
        }
        let arrow = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx);
        assert!(!SparseLu::new(arrow).unwrap().is_band());
    }

    /// `A x` for a CSC matrix.
    pub(crate) fn product(
        pattern: &SymbolicSparseColMat<usize>,
        values: &[f64],
        x: &[f64],
    ) -> Vec<f64> {
        let mut b = vec![0.0; x.len()];
        let (cp, ri) = (pattern.col_ptr(), pattern.row_idx());
        for j in 0..x.len() {
            for k in cp[j]..cp[j + 1] {
                b[ri[k]] += values[k] * x[j];
            }
        }
        b
    }

    #[test]
    fn mixed_units_keep_the_diagonal_pivots_and_small_diagonals_interchange() {
        // A symmetric positive definite band matrix (diagonally dominant)
        // whose odd unknowns are in units a million times larger: partial
        // pivoting on the raw entries would interchange rows at every odd
        // column, the equilibrated comparison none.
        let (pattern, raw) = scrambled(120, 5, 7);
        let (cp, ri) = (pattern.col_ptr(), pattern.row_idx());
        let unit = |i: usize| if i % 2 == 1 { 1e3 } else { 1e-3 };
        let mut values = vec![0.0; raw.len()];
        for j in 0..120 {
            for k in cp[j]..cp[j + 1] {
                let i = ri[k];
                // Symmetric part of the random entries, a dominant diagonal.
                let v = if i == j {
                    20.0
                } else {
                    0.5 + 0.25 * ((i + j) % 3) as f64
                };
                values[k] = v * unit(i) * unit(j);
            }
        }
        let band = BandStructure::of(&pattern);
        let ku = band.ku;
        let mut lu = BandLu::new(&pattern, band);
        lu.factor(&values);
        assert_eq!(lu.u_width, ku, "no interchange");
        let x: Vec<f64> = (0..120)
            .map(|i| (i as f64 * 0.37).sin() / unit(i))
            .collect();
        let solves_right = |lu: &mut BandLu| {
            let mut b = product(&pattern, &values, &x);
            lu.solve(&mut b);
            for (got, want) in b.iter().zip(&x) {
                assert!(
                    (got - want).abs() <= 1e-10 * want.abs().max(1e-3),
                    "{got} {want}"
                );
            }
        };
        solves_right(&mut lu);
        // Tiny diagonals (the scrambled matrix as it is) still interchange.
        let band = BandStructure::of(&pattern);
        let ku = band.ku;
        let mut lu = BandLu::new(&pattern, band);
        lu.factor(&raw);
        assert!(lu.u_width > ku, "interchanges where the diagonal is small");
        // And a matrix factorised after one with interchanges is right too
        // (the fill rows are cleared).
        lu.factor(&values);
        solves_right(&mut lu);
    }

    #[test]
    fn a_singular_matrix_gives_non_finite_solutions() {
        let (pattern, mut values) = scrambled(20, 2, 5);
        // Zero every entry of one column: rank deficient.
        let (cp, _) = (pattern.col_ptr(), pattern.row_idx());
        for v in &mut values[cp[4]..cp[5]] {
            *v = 0.0;
        }
        let band = BandStructure::of(&pattern);
        let mut lu = BandLu::new(&pattern, band);
        lu.factor(&values);
        let mut b = vec![1.0; 20];
        lu.solve(&mut b);
        assert!(b.iter().any(|v| !v.is_finite()));
    }
}
