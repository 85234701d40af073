//! Solves with a sparse Cholesky factor corrected by a symmetric low-rank change, without
//! refactoring: the capacitance (Woodbury) form on the half-solved update columns.
//!
//! ## The maths
//!
//! [`SparseCholesky`] holds `A = Pᵀ L Lᵀ P`. The changed matrix is
//!
//! ```text
//! A' = A + U C Uᵀ          U: n × m (sparse columns), C: m × m symmetric (any sign)
//! ```
//!
//! With the half-solved columns `H = L⁻¹ P U` (n × m, dense) and `S = Hᵀ H`,
//! `A' = Pᵀ L (I + H C Hᵀ) Lᵀ P`, and by the push-through identity
//! `(I + H C Hᵀ)⁻¹ = I − H C (I + S C)⁻¹ Hᵀ`, so
//!
//! ```text
//! A'⁻¹ b = Pᵀ L⁻ᵀ (y − H C (I + S C)⁻¹ Hᵀ y),    y = L⁻¹ P b .
//! ```
//!
//! `det(I + S C) = det(A') / det(A)`: the m × m capacitance matrix `I + S C` is invertible
//! exactly when `A'` is, and it needs no inverse of C (a rank-deficient or indefinite change,
//! e.g. a contact pair that opens, is fine). The solve is exact up to round-off — not an
//! approximation of `A'⁻¹` — at the cost of one solve with the old factor, two products with
//! the n × m matrix H and an m × m LU solve.
//!
//! ## Cost
//!
//! Adding k columns costs k half solves (`L⁻¹ P u`, blocked) and the products `Hᵀ H_new`
//! (n · m · k); every later solve costs `4 n m` flops more than a plain solve. Measured on the
//! friction bar's Newton matrix at 10⁵ DOF (x13, this 2-core machine): a refactorization
//! 0.58–0.70 s, a solve 47 ms, 48 new columns 0.16 s (3.4 ms each), a solve with 96 columns
//! 79 ms. The owner chooses the capacity ([`LowRankCholesky::new`]) and refactors when it is
//! full.
//!
//! Adding columns allocates (faer's blocked half solve and product workspace); solves do not.

use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, Par};

use crate::linalg::SparseCholesky;

/// A low-rank correction `U C Uᵀ` of a [`SparseCholesky`] factor (module docs): columns are
/// added one block at a time, `C` set entry by entry, then [`LowRankCholesky::factor`] and
/// solves. The factor itself is passed to every call and must not be refactored while the
/// correction holds columns ([`LowRankCholesky::clear`] after a refactorization).
pub struct LowRankCholesky {
    n: usize,
    cap: usize,
    m: usize,
    /// `H = L⁻¹ P U`, n × cap (allocated at the first column).
    h: Mat<f64>,
    /// `S = Hᵀ H`, cap × cap (the leading m × m block in use).
    s: Mat<f64>,
    /// `C`, cap × cap symmetric.
    c: Mat<f64>,
    /// LU factors of `I + S C` (m × m, column-major with leading dimension cap) and pivots.
    lu: Vec<f64>,
    piv: Vec<usize>,
    factored: bool,
    /// Scratch of a solve (m values each).
    t: Vec<f64>,
    w: Vec<f64>,
}

impl LowRankCholesky {
    /// An empty correction of an n × n factor with room for `cap` columns (m ≤ cap). The
    /// n × cap block H is allocated when the first column is added.
    pub fn new(n: usize, cap: usize) -> LowRankCholesky {
        LowRankCholesky {
            n,
            cap,
            m: 0,
            h: Mat::zeros(0, 0),
            s: Mat::zeros(cap, cap),
            c: Mat::zeros(cap, cap),
            lu: vec![0.0; cap * cap],
            piv: vec![0; cap],
            factored: false,
            t: vec![0.0; cap],
            w: vec![0.0; cap],
        }
    }

    /// Columns in use, m.
    pub fn len(&self) -> usize {
        self.m
    }

    /// Whether no column is in use (solves are plain solves with the factor).
    pub fn is_empty(&self) -> bool {
        self.m == 0
    }

    /// The most columns the correction takes.
    pub fn capacity(&self) -> usize {
        self.cap
    }

    /// Drops every column and coupling (after a refactorization of the factor).
    pub fn clear(&mut self) {
        for j in 0..self.m {
            for i in 0..self.m {
                self.c[(i, j)] = 0.0;
            }
        }
        self.m = 0;
        self.factored = false;
    }

    /// Adds `k` columns of U: `fill(j, col)` writes column j (0..k) into a zeroed n-vector.
    /// Returns the index of the first new column, or `None` (nothing added) if m + k would
    /// exceed the capacity. The new columns couple to nothing until
    /// [`LowRankCholesky::set_coupling`]; call [`LowRankCholesky::factor`] before solving.
    pub(crate) fn add_columns(
        &mut self,
        chol: &SparseCholesky,
        k: usize,
        mut fill: impl FnMut(usize, &mut [f64]),
    ) -> Option<usize> {
        let (m0, m1) = (self.m, self.m + k);
        if m1 > self.cap || chol.dim() != self.n {
            return None;
        }
        if self.h.ncols() != self.cap {
            self.h = Mat::zeros(self.n, self.cap);
        }
        for j in 0..k {
            let col = self.h.col_as_slice_mut(m0 + j);
            col.fill(0.0);
            fill(j, col);
        }
        chol.half_solve(self.h.as_mut().subcols_mut(m0, k));
        let h = self.h.as_ref();
        matmul(
            self.s.as_mut().submatrix_mut(0, m0, m1, k),
            Accum::Replace,
            h.subcols(0, m1).transpose(),
            h.subcols(m0, k),
            1.0,
            Par::Seq,
        );
        for j in m0..m1 {
            for i in 0..m0 {
                self.s[(j, i)] = self.s[(i, j)];
            }
        }
        self.m = m1;
        self.factored = false;
        Some(m0)
    }

    /// Sets `C_ij = C_ji = v` (columns i, j < m).
    pub(crate) fn set_coupling(&mut self, i: usize, j: usize, v: f64) {
        debug_assert!(i < self.m && j < self.m);
        self.c[(i, j)] = v;
        self.c[(j, i)] = v;
        self.factored = false;
    }

    /// Factors the capacitance matrix `I + S C` (LU with partial pivoting). `false` if it is
    /// singular or not finite (the corrected matrix is singular: refactor instead).
    pub fn factor(&mut self) -> bool {
        let (m, ld) = (self.m, self.cap);
        self.factored = false;
        // T = I + S C, column by column over the nonzeros of C (a few per column).
        for j in 0..m {
            let tj = &mut self.lu[j * ld..j * ld + m];
            tj.fill(0.0);
            tj[j] = 1.0;
            for l in 0..m {
                let c = self.c[(l, j)];
                if c != 0.0 {
                    for (t, &s) in tj.iter_mut().zip(self.s.col_as_slice(l)) {
                        *t += s * c;
                    }
                }
            }
        }
        // The identity part sets the scale: a pivot far below 1 (or below the largest entry)
        // means a (numerically) singular corrected matrix.
        let mut scale = 1.0f64;
        for j in 0..m {
            for &x in &self.lu[j * ld..j * ld + m] {
                scale = scale.max(x.abs());
            }
        }
        for k in 0..m {
            let (mut p, mut best) = (k, 0.0f64);
            for i in k..m {
                let v = self.lu[k * ld + i].abs();
                if v > best {
                    (p, best) = (i, v);
                }
            }
            if !(best.is_finite() && best > 1e-14 * scale) {
                return false;
            }
            self.piv[k] = p;
            if p != k {
                for j in 0..m {
                    self.lu.swap(j * ld + k, j * ld + p);
                }
            }
            let d = self.lu[k * ld + k];
            for i in k + 1..m {
                self.lu[k * ld + i] /= d;
            }
            for j in k + 1..m {
                let f = self.lu[j * ld + k];
                if f != 0.0 {
                    for i in k + 1..m {
                        self.lu[j * ld + i] -= self.lu[k * ld + i] * f;
                    }
                }
            }
        }
        self.factored = true;
        true
    }

    /// `w ← (I + S C)⁻¹ w` (the first m values) with the LU factors.
    fn capacitance_solve(&mut self) {
        let (m, ld) = (self.m, self.cap);
        let w = &mut self.w[..m];
        // The row swaps of the factorization, in order, before the unit lower solve: the
        // stored multipliers of column k have been permuted by the later swaps.
        for k in 0..m {
            w.swap(k, self.piv[k]);
        }
        for k in 0..m {
            let wk = w[k];
            for i in k + 1..m {
                w[i] -= self.lu[k * ld + i] * wk;
            }
        }
        for k in (0..m).rev() {
            w[k] /= self.lu[k * ld + k];
            let wk = w[k];
            for i in 0..k {
                w[i] -= self.lu[k * ld + i] * wk;
            }
        }
    }

    /// `x ← (A + U C Uᵀ)⁻¹ x` with the factor of A (a plain solve when empty); NaN if the
    /// correction is not factored. No allocation.
    pub fn solve_in_place(&mut self, chol: &mut SparseCholesky, x: &mut [f64]) {
        let m = self.m;
        if m == 0 {
            chol.solve_vec_in_place(x);
            return;
        }
        if !self.factored {
            x.fill(f64::NAN);
            return;
        }
        chol.half_solve_vec_in_place(x);
        // t = Hᵀ y
        for j in 0..m {
            self.t[j] = dot(self.h.col_as_slice(j), x);
        }
        // (I + S C) w = t
        self.w[..m].copy_from_slice(&self.t[..m]);
        self.capacitance_solve();
        let w = &self.w[..m];
        // y ← y − H (C w)
        for j in 0..m {
            let mut v = 0.0;
            for (l, &wl) in w.iter().enumerate() {
                v += self.c[(j, l)] * wl;
            }
            self.t[j] = v;
        }
        for j in 0..m {
            let v = self.t[j];
            if v != 0.0 {
                for (xi, &hi) in x.iter_mut().zip(self.h.col_as_slice(j)) {
                    *xi -= hi * v;
                }
            }
        }
        chol.half_solve_transpose_vec_in_place(x);
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::SymCsc;

    /// A 2-D five-point Laplacian plus a diagonal shift on an nx × nx grid (SPD), as
    /// (col_ptr, row_idx, values) with both triangles.
    fn grid(nx: usize, shift: f64) -> (usize, Vec<usize>, Vec<usize>, Vec<f64>) {
        let n = nx * nx;
        let mut col_ptr = vec![0];
        let (mut rows, mut vals) = (Vec::new(), Vec::new());
        for j in 0..n {
            let (x, y) = (j % nx, j / nx);
            let mut col = vec![(j, 4.0 + shift)];
            if x > 0 {
                col.push((j - 1, -1.0));
            }
            if x + 1 < nx {
                col.push((j + 1, -1.0));
            }
            if y > 0 {
                col.push((j - nx, -1.0));
            }
            if y + 1 < nx {
                col.push((j + nx, -1.0));
            }
            push_column(col, &mut col_ptr, &mut rows, &mut vals);
        }
        (n, col_ptr, rows, vals)
    }

    /// The matrix of a test pattern and its factorization: `(n, A, chol)`.
    fn factored(
        pattern: (usize, Vec<usize>, Vec<usize>, Vec<f64>),
    ) -> (usize, SymCsc, SparseCholesky) {
        let (n, cp, ri, v) = pattern;
        let mut chol = SparseCholesky::analyze(n, cp.clone(), ri.clone()).unwrap();
        chol.factor(&v, "grid").unwrap();
        let a = SymCsc {
            n,
            col_ptr: cp,
            row_idx: ri,
            values: v,
        };
        (n, a, chol)
    }

    /// Appends one column (entries in any order) to a CSC pattern being built.
    fn push_column(
        mut col: Vec<(usize, f64)>,
        col_ptr: &mut Vec<usize>,
        rows: &mut Vec<usize>,
        vals: &mut Vec<f64>,
    ) {
        col.sort_by_key(|e| e.0);
        for (i, v) in col {
            rows.push(i);
            vals.push(v);
        }
        col_ptr.push(rows.len());
    }

    /// A shell-mesh-like SPD pattern: 3 DOF per node on a g × g grid, each node coupled to its
    /// 8 neighbours (large enough for faer's supernodal factor), as in [`grid`].
    fn shell_grid(g: usize) -> (usize, Vec<usize>, Vec<usize>, Vec<f64>) {
        let n = 3 * g * g;
        let (mut col_ptr, mut rows, mut vals) = (vec![0], Vec::new(), Vec::new());
        for j in 0..n {
            let (jy, jx) = (j / 3 / g, j / 3 % g);
            let mut col = Vec::new();
            for iy in jy.saturating_sub(1)..(jy + 2).min(g) {
                for ix in jx.saturating_sub(1)..(jx + 2).min(g) {
                    for d in 0..3 {
                        let i = 3 * (iy * g + ix) + d;
                        if i != j {
                            col.push((i, -0.1));
                        }
                    }
                }
            }
            col.push((j, 0.1 * col.len() as f64 + 1.0));
            push_column(col, &mut col_ptr, &mut rows, &mut vals);
        }
        (n, col_ptr, rows, vals)
    }

    /// A seeded generator in [−1, 1).
    fn rng(seed: u64) -> impl FnMut() -> f64 {
        let mut s = seed;
        move || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 52) as f64 - 1.0
        }
    }

    /// `A + U C Uᵀ` of sparse columns `u` (row, value) and dense symmetric C, densified.
    /// `max_i |(A x − b)_i|` for the dense `a`.
    fn max_residual(a: &Mat<f64>, x: &[f64], b: &[f64]) -> f64 {
        let res = a * Mat::from_fn(x.len(), 1, |i, _| x[i]);
        (0..b.len())
            .map(|i| (res[(i, 0)] - b[i]).abs())
            .fold(0.0, f64::max)
    }

    fn corrected(a: &SymCsc, u: &[Vec<(usize, f64)>], c: &[Vec<f64>]) -> Mat<f64> {
        let n = a.n;
        let mut d = Mat::<f64>::zeros(n, n);
        for j in 0..n {
            for p in a.col_ptr[j]..a.col_ptr[j + 1] {
                d[(a.row_idx[p], j)] += a.values[p];
            }
        }
        for (i, ui) in u.iter().enumerate() {
            for (j, uj) in u.iter().enumerate() {
                for &(r, x) in ui {
                    for &(q, y) in uj {
                        d[(r, q)] += x * c[i][j] * y;
                    }
                }
            }
        }
        d
    }

    #[test]
    fn corrected_solves_match_the_refactored_matrix() {
        for (nx, m, seed) in [(6, 1, 1), (12, 7, 2), (30, 24, 3)] {
            let (n, a, mut chol) = factored(grid(nx, 0.1));
            let mut r = rng(seed);
            // Sparse columns (3 entries each) and a block-diagonal C of 3×3 blocks with mixed
            // signs, small enough to keep A' positive definite.
            let u: Vec<Vec<(usize, f64)>> = (0..m)
                .map(|j| {
                    (0..3)
                        .map(|k| ((7 * j + 13 * k + seed as usize) % n, r()))
                        .collect()
                })
                .collect();
            // 3×3 blocks R Rᵀ (positive semidefinite, so A' stays positive definite), large
            // against A: I + S C is far from the identity and its LU must pivot.
            let mut c = vec![vec![0.0; m]; m];
            for b0 in (0..m).step_by(3) {
                let b1 = (b0 + 3).min(m);
                let rr: Vec<Vec<f64>> = (b0..b1).map(|_| (0..3).map(|_| r()).collect()).collect();
                for i in b0..b1 {
                    for j in b0..b1 {
                        let x: f64 = (0..3).map(|q| rr[i - b0][q] * rr[j - b0][q]).sum();
                        c[i][j] = 50.0 * x;
                    }
                }
            }
            let mut lr = LowRankCholesky::new(n, 32);
            // In two blocks, as refreshes add them.
            let half = m / 2;
            assert_eq!(
                lr.add_columns(&chol, half, |j, col| {
                    for &(i, x) in &u[j] {
                        col[i] += x;
                    }
                }),
                Some(0)
            );
            assert_eq!(
                lr.add_columns(&chol, m - half, |j, col| {
                    for &(i, x) in &u[half + j] {
                        col[i] += x;
                    }
                }),
                Some(half)
            );
            for i in 0..m {
                for j in 0..m {
                    lr.set_coupling(i, j, c[i][j]);
                }
            }
            assert!(lr.factor());
            if m > 3 {
                assert!(
                    (0..m).any(|k| lr.piv[k] != k),
                    "m = {m}: the capacitance LU pivots"
                );
            }
            let dense = corrected(&a, &u, &c);
            let b: Vec<f64> = (0..n).map(|_| r()).collect();
            let mut x = b.clone();
            lr.solve_in_place(&mut chol, &mut x);
            let err = max_residual(&dense, &x, &b);
            let xn = x.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            assert!(
                err <= 1e3 * n as f64 * f64::EPSILON * (1.0 + xn),
                "n = {n}, m = {m}: residual {err:e}"
            );
            // Without columns the solve is the plain one.
            lr.clear();
            assert!(lr.is_empty());
            let mut y = b.clone();
            lr.solve_in_place(&mut chol, &mut y);
            let mut z = b.clone();
            chol.solve_vec_in_place(&mut z);
            assert_eq!(y, z);
        }
    }

    #[test]
    fn many_batches_with_changing_couplings() {
        let (n, a, mut chol) = factored(shell_grid(40));
        assert!(chol.is_supernodal(), "the supernodal half solves");
        let mut r = rng(9);
        let mut lr = LowRankCholesky::new(n, 96);
        let mut u: Vec<Vec<(usize, f64)>> = Vec::new();
        let mut c: Vec<Vec<f64>> = Vec::new();
        for batch in 0..12 {
            let k = 1 + (batch * 5) % 9;
            if u.len() + k > 96 {
                break;
            }
            let first = u.len();
            for j in 0..k {
                let base = ((first + j) * 37) % n;
                u.push((0..4).map(|q| ((base + q * 30) % n, r())).collect());
            }
            let m = u.len();
            for row in c.iter_mut() {
                row.resize(m, 0.0);
            }
            c.resize(m, vec![0.0; m]);
            assert_eq!(
                lr.add_columns(&chol, k, |j, col| {
                    for &(i, x) in &u[first + j] {
                        col[i] += x;
                    }
                }),
                Some(first)
            );
            // Change some old couplings too, positive only on the diagonal blocks to stay SPD.
            for i in 0..m {
                if i % 3 == batch % 3 || i >= first {
                    let x = 2.0 * r().abs();
                    c[i][i] = x;
                    lr.set_coupling(i, i, x);
                    // and a coupling to a neighbouring column, of either sign
                    if i > 0 {
                        let y = 0.3 * r();
                        c[i][i - 1] = y;
                        c[i - 1][i] = y;
                        lr.set_coupling(i, i - 1, y);
                    }
                }
            }
            assert!(lr.factor());
            let dense = corrected(&a, &u, &c);
            let b: Vec<f64> = (0..n).map(|_| r()).collect();
            let mut x = b.clone();
            lr.solve_in_place(&mut chol, &mut x);
            let err = max_residual(&dense, &x, &b);
            assert!(err < 1e-9, "batch {batch}, m = {m}: residual {err:e}");
        }
    }

    #[test]
    fn capacity_and_singular_corrections_are_refused() {
        let (n, _, mut chol) = factored(grid(5, 0.0));
        let mut lr = LowRankCholesky::new(n, 2);
        assert_eq!(lr.add_columns(&chol, 3, |_, _| {}), None);
        assert!(lr.is_empty());
        // u = e_0, C = −A_00 · (1/(A⁻¹)_00) makes A' singular: c = −1/(A⁻¹)_00.
        let mut e0 = vec![0.0; n];
        e0[0] = 1.0;
        chol.solve_vec_in_place(&mut e0);
        assert_eq!(lr.add_columns(&chol, 1, |_, col| col[0] = 1.0), Some(0));
        lr.set_coupling(0, 0, -1.0 / e0[0]);
        assert!(!lr.factor(), "a singular A' is refused");
        let mut x = vec![1.0; n];
        lr.solve_in_place(&mut chol, &mut x);
        assert!(x.iter().all(|v| v.is_nan()), "no solve without a factor");
        lr.set_coupling(0, 0, 2.0);
        assert!(lr.factor());
    }
}
