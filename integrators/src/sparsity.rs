//! Sparsity patterns built from lists of coupled equations (an element's,
//! a joint block's): compressed columns with sorted rows, in linear time.

/// The compressed columns `(col_ptr, row_idx)` of the `n × n` pattern with
/// the diagonal and every pair of equations of each list, each
/// column's rows sorted. In linear time: the lists holding each equation
/// (counted first, so nothing grows), then each column's rows once each (a
/// marker per row) in any order, then the transpose, which gathers every
/// column's rows in order — and is the pattern itself, which is symmetric.
pub(crate) fn symmetric_pattern(n: usize, lists: &[&[usize]]) -> (Vec<usize>, Vec<usize>) {
    let mut at = vec![0; n + 1];
    for list in lists {
        for &j in *list {
            at[j + 1] += 1;
        }
    }
    for j in 0..n {
        at[j + 1] += at[j];
    }
    let mut fill = at.clone();
    let mut holding = vec![0; at[n]];
    for (l, list) in lists.iter().enumerate() {
        for &j in *list {
            holding[fill[j]] = l;
            fill[j] += 1;
        }
    }
    let mut mark = vec![usize::MAX; n];
    let mut ptr = Vec::with_capacity(n + 1);
    let mut rows = Vec::new();
    ptr.push(0);
    for j in 0..n {
        mark[j] = j;
        rows.push(j);
        for &l in &holding[at[j]..at[j + 1]] {
            for &r in lists[l] {
                if mark[r] != j {
                    mark[r] = j;
                    rows.push(r);
                }
            }
        }
        ptr.push(rows.len());
    }
    transposed(&ptr, &rows)
}

/// The transpose `(col_ptr, row_idx)` of the square CSC pattern `(ptr,
/// rows)`, each column's rows in ascending order.
pub(crate) fn transposed(ptr: &[usize], rows: &[usize]) -> (Vec<usize>, Vec<usize>) {
    let n = ptr.len() - 1;
    let mut col_ptr = vec![0; n + 1];
    for &r in rows {
        col_ptr[r + 1] += 1;
    }
    for j in 0..n {
        col_ptr[j + 1] += col_ptr[j];
    }
    let mut fill = col_ptr.clone();
    let mut row_idx = vec![0; rows.len()];
    for (j, w) in ptr.windows(2).enumerate() {
        for &r in &rows[w[0]..w[1]] {
            row_idx[fill[r]] = j;
            fill[r] += 1;
        }
    }
    (col_ptr, row_idx)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_pattern_is_every_lists_pairs_sorted() {
        // Lists out of order, with a repeat and an equation in none.
        let lists: [&[usize]; 4] = [&[4, 1, 2], &[2, 6], &[0, 4, 4], &[6, 1]];
        let n = 8;
        let (col_ptr, row_idx) = symmetric_pattern(n, &lists);
        for j in 0..n {
            let mut expected = vec![j];
            for l in lists.iter().filter(|l| l.contains(&j)) {
                expected.extend_from_slice(l);
            }
            expected.sort_unstable();
            expected.dedup();
            assert_eq!(
                &row_idx[col_ptr[j]..col_ptr[j + 1]],
                &expected[..],
                "column {j}"
            );
        }
    }
}
