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
    for (j, yj) in y.iter_mut().enumerate().take(a.n) {
        let range = a.col_ptr[j]..a.col_ptr[j + 1];
        *yj = a.values[range.clone()]
            .iter()
            .zip(&a.row_idx[range])
            .map(|(v, &r)| v * x[r])
            .sum();
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
        let x = y.col(0);
        for (j, o) in out.col_mut(0).iter_mut().enumerate() {
            let mut acc = 0.0f64;
            for p in a.col_ptr[j]..a.col_ptr[j + 1] {
                acc += a.values[p] * x[a.row_idx[p]];
            }
            *o = acc;
        }
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
