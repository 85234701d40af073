//! Symmetric sparse matrices (compressed sparse columns, both triangles stored) and their
//! products: the storage every assembled K and M of jointrom uses.

use faer::{Mat, MatRef};

use super::LinalgError;

/// The compressed-column pattern `(col_ptr, row_idx)` of `n` columns whose rows `fill(c, rows)`
/// pushes into the (cleared) `rows`, in any order and with repeats: each column's rows sorted
/// and deduplicated. One column is held at a time.
pub(crate) fn column_pattern(
    n: usize,
    mut fill: impl FnMut(usize, &mut Vec<usize>),
) -> (Vec<usize>, Vec<usize>) {
    let mut col_ptr = Vec::with_capacity(n + 1);
    col_ptr.push(0);
    let mut row_idx = Vec::new();
    let mut rows = Vec::new();
    for c in 0..n {
        rows.clear();
        fill(c, &mut rows);
        rows.sort_unstable();
        rows.dedup();
        row_idx.extend_from_slice(&rows);
        col_ptr.push(row_idx.len());
    }
    (col_ptr, row_idx)
}

/// A symmetric sparse matrix in compressed sparse columns with both triangles stored.
#[derive(Clone, Debug)]
pub struct SymCsc {
    /// Dimension.
    pub n: usize,
    /// Column pointers (length n + 1).
    pub col_ptr: Vec<usize>,
    /// Row indices, sorted within each column.
    pub row_idx: Vec<usize>,
    /// Values.
    pub values: Vec<f64>,
}

impl SymCsc {
    /// `y = A x`.
    pub fn mul_vec(&self, x: &[f64], y: &mut [f64]) {
        y.iter_mut().for_each(|v| *v = 0.0);
        for j in 0..self.n {
            let xj = x[j];
            for p in self.col_ptr[j]..self.col_ptr[j + 1] {
                y[self.row_idx[p]] += self.values[p] * xj;
            }
        }
    }

    /// `‖A‖∞`, the largest absolute row sum (= column sum, A being symmetric).
    pub fn inf_norm(&self) -> f64 {
        (0..self.n)
            .map(|j| {
                self.values[self.col_ptr[j]..self.col_ptr[j + 1]]
                    .iter()
                    .map(|v| v.abs())
                    .sum::<f64>()
            })
            .fold(0.0, f64::max)
    }

    /// Entry (i, j) (zero where not stored).
    pub fn get(&self, i: usize, j: usize) -> f64 {
        let rows = &self.row_idx[self.col_ptr[j]..self.col_ptr[j + 1]];
        rows.binary_search(&i)
            .map(|p| self.values[self.col_ptr[j] + p])
            .unwrap_or(0.0)
    }

    /// The leading principal submatrix of size `m` (e.g. the Craig–Bampton interior).
    pub fn leading(&self, m: usize) -> SymCsc {
        let mut col_ptr = Vec::with_capacity(m + 1);
        col_ptr.push(0);
        let stored = self.col_ptr[m.min(self.n)];
        let mut row_idx = Vec::with_capacity(stored);
        let mut values = Vec::with_capacity(stored);
        for j in 0..m {
            for p in self.col_ptr[j]..self.col_ptr[j + 1] {
                if self.row_idx[p] < m {
                    row_idx.push(self.row_idx[p]);
                    values.push(self.values[p]);
                }
            }
            col_ptr.push(row_idx.len());
        }
        SymCsc {
            n: m,
            col_ptr,
            row_idx,
            values,
        }
    }

    /// `A + s B` for matrices with the same pattern (e.g. the shifted `K − σ M`).
    pub fn add_scaled(&self, s: f64, other: &SymCsc) -> Result<SymCsc, LinalgError> {
        if self.col_ptr != other.col_ptr || self.row_idx != other.row_idx {
            return Err(LinalgError::PatternMismatch {
                operation: "add_scaled",
            });
        }
        let mut out = self.clone();
        for (v, o) in out.values.iter_mut().zip(&other.values) {
            *v += s * o;
        }
        Ok(out)
    }

    /// A sprs matrix (copies), e.g. for MatrixMarket export.
    pub(crate) fn to_sprs(&self) -> sprs::CsMat<f64> {
        sprs::CsMat::new_csc(
            (self.n, self.n),
            self.col_ptr.clone(),
            self.row_idx.clone(),
            self.values.clone(),
        )
    }

    /// Dense copy (tests and small problems only).
    pub fn to_dense(&self) -> Mat<f64> {
        let mut m = Mat::zeros(self.n, self.n);
        for j in 0..self.n {
            for p in self.col_ptr[j]..self.col_ptr[j + 1] {
                m[(self.row_idx[p], j)] = self.values[p];
            }
        }
        m
    }
}

/// `y = A x` for a [`SymCsc`] (both triangles stored) in gather form: by symmetry row j of A is
/// its column j, so `y_j = Σ_p a_p x_{row(p)}` over column j — sequential reads, one write per
/// row, no scattered updates. The same products as [`SymCsc::mul_vec`], summed in column order.
pub(crate) fn sym_mul_vec_into(a: &SymCsc, x: &[f64], y: &mut [f64]) {
    // From −0.0, as `Iterator::sum` of f64 starts (an empty or all −0.0 row stays −0.0).
    gather_into(a, x, y, -0.0);
}

/// `y_j = Σ_p a_p x_{row(p)}` over column j of A for every row j (the gather form of `A x`),
/// each sum sequential from `zero` (0.0 or −0.0) in column order. Four rows go
/// together: each row's sum is a chain of dependent adds, so one row at a time waits on the
/// add latency at every entry, while four independent chains overlap. Every row still gets the
/// same operations in the same order: the same bits as one row at a time.
fn gather_into(a: &SymCsc, x: &[f64], y: &mut [f64], zero: f64) {
    let n = a.n.min(y.len());
    let column = |j: usize| {
        let range = a.col_ptr[j]..a.col_ptr[j + 1];
        (&a.values[range.clone()], &a.row_idx[range])
    };
    let mut j = 0;
    while j + 4 <= n {
        let cols = [column(j), column(j + 1), column(j + 2), column(j + 3)];
        let common = cols.iter().map(|c| c.0.len()).min().unwrap_or(0);
        let mut acc = [zero; 4];
        for i in 0..common {
            for (s, (v, r)) in acc.iter_mut().zip(&cols) {
                *s += v[i] * x[r[i]];
            }
        }
        for (s, (v, r)) in acc.iter_mut().zip(&cols) {
            for (vi, &ri) in v[common..].iter().zip(&r[common..]) {
                *s += vi * x[ri];
            }
        }
        y[j..j + 4].copy_from_slice(&acc);
        j += 4;
    }
    for (jj, yj) in y.iter_mut().enumerate().take(n).skip(j) {
        let (v, r) = column(jj);
        let mut s = zero;
        for (vi, &ri) in v.iter().zip(r) {
            s += vi * x[ri];
        }
        *yj = s;
    }
}

/// Columns handled together by [`sym_mul_mat`].
const BLOCK: usize = 16;

/// `A Y` for a [`SymCsc`] A (n × n, both triangles stored) and a dense Y (n × p), in blocks of
/// 16 columns: each block is copied row-major, so every stored entry of A multiplies 16
/// contiguous values (two cache lines, independent accumulators) — `nnz(A) · p` multiply-adds,
/// A read `p / 16` times.
///
/// One column (the Krylov–Schur operator's apply) goes without the block: the same
/// multiply-adds in the same order from 0.0 as a block lane (bit-identical), without copying the
/// column to an n × 16 row-major block and computing 15 zero lanes.
pub(crate) fn sym_mul_mat(a: &SymCsc, y: MatRef<'_, f64>) -> Mat<f64> {
    let n = a.n;
    let p = y.ncols();
    let mut out = Mat::<f64>::zeros(n, p);
    if p == 1 {
        let col = y.col(0);
        let x: std::borrow::Cow<'_, [f64]> = match col.try_as_col_major() {
            Some(c) => c.as_slice().into(),
            None => col.iter().copied().collect::<Vec<f64>>().into(),
        };
        gather_into(a, &x, out.col_as_slice_mut(0), 0.0);
        return out;
    }
    let mut block = vec![[0.0f64; BLOCK]; n];
    for c0 in (0..p).step_by(BLOCK) {
        let bw = BLOCK.min(p - c0);
        for t in 0..BLOCK {
            if t < bw {
                for (r, v) in y.col(c0 + t).iter().enumerate() {
                    block[r][t] = *v;
                }
            } else {
                block.iter_mut().for_each(|row| row[t] = 0.0);
            }
        }
        for j in 0..n {
            let range = a.col_ptr[j]..a.col_ptr[j + 1];
            let mut acc = [0.0f64; BLOCK];
            for (v, &r) in a.values[range.clone()].iter().zip(&a.row_idx[range]) {
                let row = &block[r];
                for t in 0..BLOCK {
                    acc[t] += v * row[t];
                }
            }
            for (t, &s) in acc.iter().enumerate().take(bw) {
                out[(j, c0 + t)] = s;
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::random::SplitMix64;

    /// A symmetric pattern whose columns have different lengths (so the four rows of a group
    /// end at different entries), with values that make the order of a sum matter.
    fn uneven(n: usize) -> SymCsc {
        let mut rng = SplitMix64::new(7);
        let mut dense = vec![vec![None; n]; n];
        for j in 0..n {
            dense[j][j] = Some(1.0 + rng.next_signed().abs());
            for i in 0..j {
                if rng.next_u64() % (1 + j as u64 % 5) == 0 {
                    let v = rng.next_signed() * 10f64.powi((rng.next_u64() % 9) as i32 - 4);
                    dense[i][j] = Some(v);
                    dense[j][i] = Some(v);
                }
            }
        }
        let (mut col_ptr, mut row_idx, mut values) = (vec![0], Vec::new(), Vec::new());
        for j in 0..n {
            for (i, row) in dense.iter().enumerate() {
                if let Some(v) = row[j] {
                    row_idx.push(i);
                    values.push(v);
                }
            }
            col_ptr.push(row_idx.len());
        }
        SymCsc {
            n,
            col_ptr,
            row_idx,
            values,
        }
    }

    #[test]
    fn gathered_rows_are_the_sequential_sums_bit_for_bit() {
        for n in [1, 3, 4, 7, 33] {
            let a = uneven(n);
            let mut rng = SplitMix64::new(11);
            let x: Vec<f64> = (0..n).map(|_| rng.next_signed()).collect();
            for zero in [0.0, -0.0] {
                let mut y = vec![f64::NAN; n];
                gather_into(&a, &x, &mut y, zero);
                for (j, got) in y.iter().enumerate() {
                    let mut want = zero;
                    for p in a.col_ptr[j]..a.col_ptr[j + 1] {
                        want += a.values[p] * x[a.row_idx[p]];
                    }
                    assert_eq!(got.to_bits(), want.to_bits(), "n = {n}, row {j}");
                }
            }
            let mut y = vec![f64::NAN; n];
            sym_mul_vec_into(&a, &x, &mut y);
            for (j, got) in y.iter().enumerate() {
                let want: f64 = (a.col_ptr[j]..a.col_ptr[j + 1])
                    .map(|p| a.values[p] * x[a.row_idx[p]])
                    .sum();
                assert_eq!(got.to_bits(), want.to_bits(), "n = {n}, row {j}");
            }
            // One column alone has the bits of the same column in a block.
            let one = sym_mul_mat(&a, Mat::from_fn(n, 1, |i, _| x[i]).as_ref());
            let two = sym_mul_mat(
                &a,
                Mat::from_fn(n, 2, |i, j| x[i] * (j + 1) as f64).as_ref(),
            );
            for j in 0..n {
                assert_eq!(one[(j, 0)].to_bits(), two[(j, 0)].to_bits(), "n = {n}");
            }
        }
    }
}
