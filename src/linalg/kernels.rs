//! Dense matrix–vector kernels for the reduced model's per-step work (right-hand side, Newton
//! solve): `y = A x` on a column-major and `y += Aᵀ p` on a row-major matrix. Both are one kernel,
//! `y += Σ_i s_i a_i` over the contiguous rows `a_i` of a row-major matrix (a column-major `A` is
//! the row-major `Aᵀ`), four rows per pass, rows with `s_i = 0` skipped.
//!
//! ## Why this shape
//! At the sizes of a reduced model (`BΦ`: 3w × r, 156 × 28 to 600 × 70; `K̃`: r × r) one product
//! is 4–40 k multiply–adds on a matrix that sits in L1/L2. Measured on this machine's core
//! (`examples/kernels.rs`, 156 × 68): a dot product per row, even four rows per pass with 4 × 8
//! register sums, reaches 11 GFlop/s; the linear combination of rows, four per pass (each chunk
//! of `y` loaded and stored once per four rows), 23 GFlop/s — the rate of faer's own
//! matrix–vector product on the same matrix (24 GFlop/s), i.e. the memory-bound rate of a
//! product that reads each matrix entry once. One dispatch per product instead of one per row or
//! column. Skipping zero factors makes `(BΦ)ᵀ p` cost in proportion to the pairs that carry
//! force (open pairs carry none).
//!
//! The summation order is fixed (rows in index order, four at a time, `(s₀a₀ + s₁a₁) + (s₂a₂ +
//! s₃a₃)` per block), so results do not depend on the machine's vector width; compiled for
//! AVX-512 and AVX2 + FMA as well and dispatched once per call. The groups are applied to 32
//! entries of `y` at a time held in registers (one load and store of `y` per product instead of
//! one per group; the same order per entry), and [`mul_rows_listed`] gives single rows of
//! `A x` with the same order, bit for bit: a caller that needs only some rows of a product
//! (the reduced model's Newton solve and outputs) gets the values the whole product would.
//! At the friction bar's sizes (156 × 38, ~47 kB) a product streams its matrix from L2: its
//! cost is the bytes it reads, so the rows not needed are the ones worth skipping.

/// `y = A x` for a column-major `A` (`x.len()` contiguous columns of `y.len()` entries).
///
/// # Panics
/// If `a.len() != x.len() · y.len()`.
pub fn mul_col_major(a: &[f64], x: &[f64], y: &mut [f64]) {
    assert_eq!(a.len(), x.len() * y.len(), "mul_col_major: matrix size");
    y.fill(0.0);
    lincomb_rows_add(a, x, y);
}

/// `y += Aᵀ p` for a row-major `A` (`p.len()` contiguous rows of `y.len()` entries), skipping
/// rows with `p_i = 0`.
///
/// # Panics
/// If `a.len() != p.len() · y.len()`.
pub fn mul_t_add_row_major(a: &[f64], p: &[f64], y: &mut [f64]) {
    assert_eq!(
        a.len(),
        p.len() * y.len(),
        "mul_t_add_row_major: matrix size"
    );
    lincomb_rows_add(a, p, y);
}

/// `y_i = (A x)_i` for the listed rows `i` only (other entries of `y` untouched), `A` (`y.len()`
/// × `x.len()`) given row-major: the same value, bit for bit, as [`mul_col_major`] gives that
/// entry from the column-major copy of `A` — the same terms, grouped four at a time in the
/// same order (`(x₀a₀ + x₁a₁) + (x₂a₂ + x₃a₃)` per group of non-zero `x`, the rest one by one).
/// For products of which only a few rows are needed.
///
/// # Panics
/// If `a_rows.len() != y.len() · x.len()` or a listed row is out of range.
pub fn mul_rows_listed(a_rows: &[f64], x: &[f64], rows: &[usize], y: &mut [f64]) {
    let n = x.len();
    assert_eq!(a_rows.len(), n * y.len(), "mul_rows_listed: matrix size");
    if x.iter().all(|&v| v != 0.0) {
        // Every term present: the groups are the consecutive fours.
        rows_listed_dense(a_rows, x, rows, y);
        return;
    }
    for &i in rows {
        let a = &a_rows[i * n..i * n + n];
        let mut acc = 0.0;
        let mut idx = [0usize; 4];
        let mut len = 0;
        for (j, &xj) in x.iter().enumerate() {
            if xj == 0.0 {
                continue;
            }
            idx[len] = j;
            len += 1;
            if len == 4 {
                let [j0, j1, j2, j3] = idx;
                acc += (x[j0] * a[j0] + x[j1] * a[j1]) + (x[j2] * a[j2] + x[j3] * a[j3]);
                len = 0;
            }
        }
        for &j in &idx[..len] {
            acc += x[j] * a[j];
        }
        y[i] = acc;
    }
}

/// [`mul_rows_listed`] for an `x` without zeros.
#[multiversion::multiversion(targets("x86_64+avx512f+avx512vl", "x86_64+avx2+fma"))]
fn rows_listed_dense(a_rows: &[f64], x: &[f64], rows: &[usize], y: &mut [f64]) {
    let n = x.len();
    let (xc, xr) = x.split_at(n - n % 4);
    for &i in rows {
        let a = &a_rows[i * n..i * n + n];
        let (ac, ar) = a.split_at(xc.len());
        let mut acc = 0.0;
        for (xs, as_) in xc.chunks_exact(4).zip(ac.chunks_exact(4)) {
            acc += (xs[0] * as_[0] + xs[1] * as_[1]) + (xs[2] * as_[2] + xs[3] * as_[3]);
        }
        for (xj, aj) in xr.iter().zip(ar) {
            acc += xj * aj;
        }
        y[i] = acc;
    }
}

/// `y += Σ_i s_i a_i` over the rows `a_i` (length `y.len()`) of the row-major `a`, `s_i ≠ 0`.
///
/// The non-zero factors are taken four at a time in index order (a *group*), the last one to
/// three one by one; each entry of `y` gets `(s₀a₀ + s₁a₁) + (s₂a₂ + s₃a₃)` per group in that
/// order. The groups are collected first (up to [`GROUPS`] at a time) and applied to blocks of
/// [`BLOCK`] entries of `y` held in registers across all of them, so that `y` is read and
/// written once per block instead of once per group: the same operations per entry, in the
/// same order, as one pass per group.
#[multiversion::multiversion(targets("x86_64+avx512f+avx512vl", "x86_64+avx2+fma"))]
fn lincomb_rows_add(a: &[f64], p: &[f64], y: &mut [f64]) {
    let n = y.len();
    if n == 0 {
        return;
    }
    // Indices written in place (copying a group of four written one by one would stall on
    // store forwarding).
    let mut groups = [[0usize; 4]; GROUPS];
    let mut ng = 0;
    let mut len = 0;
    for (i, &pi) in p.iter().enumerate() {
        if pi == 0.0 {
            continue;
        }
        groups[ng][len] = i;
        len += 1;
        if len == 4 {
            ng += 1;
            len = 0;
            if ng == GROUPS {
                apply_groups(a, p, &groups, y);
                ng = 0;
            }
        }
    }
    apply_groups(a, p, &groups[..ng], y);
    let rest = groups[ng];
    for &i in &rest[..len] {
        let s = p[i];
        for (o, v) in y.iter_mut().zip(&a[i * n..i * n + n]) {
            *o += s * v;
        }
    }
}

/// Groups collected before they are applied ([`lincomb_rows_add`]).
const GROUPS: usize = 16;

/// Entries of `y` held in registers while the groups are applied ([`lincomb_rows_add`]).
const BLOCK: usize = 32;

/// `y += (s₀a₀ + s₁a₁) + (s₂a₂ + s₃a₃)` for each group of four rows in turn, block by block.
#[inline(always)]
fn apply_groups(a: &[f64], p: &[f64], groups: &[[usize; 4]], y: &mut [f64]) {
    let n = y.len();
    if groups.is_empty() {
        return;
    }
    let mut start = 0;
    while start + BLOCK <= n {
        let mut acc = [0.0f64; BLOCK];
        acc.copy_from_slice(&y[start..start + BLOCK]);
        for g in groups {
            let row = |k: usize| &a[g[k] * n + start..g[k] * n + start + BLOCK];
            let (r0, r1, r2, r3) = (row(0), row(1), row(2), row(3));
            let s = [p[g[0]], p[g[1]], p[g[2]], p[g[3]]];
            for k in 0..BLOCK {
                acc[k] += (s[0] * r0[k] + s[1] * r1[k]) + (s[2] * r2[k] + s[3] * r3[k]);
            }
        }
        y[start..start + BLOCK].copy_from_slice(&acc);
        start += BLOCK;
    }
    if start < n {
        let tail = &mut y[start..];
        for g in groups {
            let row = |k: usize| &a[g[k] * n + start..g[k] * n + n];
            let (r0, r1, r2, r3) = (row(0), row(1), row(2), row(3));
            let s = [p[g[0]], p[g[1]], p[g[2]], p[g[3]]];
            for ((((o, a0), a1), a2), a3) in tail.iter_mut().zip(r0).zip(r1).zip(r2).zip(r3) {
                *o += (s[0] * a0 + s[1] * a1) + (s[2] * a2 + s[3] * a3);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn data(m: usize, n: usize) -> (Vec<f64>, Vec<f64>) {
        let a = (0..m * n)
            .map(|k| ((k * 7919 % 1013) as f64 - 506.0) / 97.0)
            .collect();
        let x = (0..n).map(|k| ((k * 31 % 17) as f64 - 8.0) / 3.0).collect();
        (a, x)
    }

    #[test]
    fn products_match_naive_for_every_remainder() {
        for m in [0, 1, 3, 4, 5, 9, 156] {
            for n in [0, 1, 7, 8, 9, 28, 70] {
                // A (m × n) column-major: entry (i, j) at a[j m + i].
                let (a, x) = data(m, n);
                let mut y = vec![f64::NAN; m];
                mul_col_major(&a, &x, &mut y);
                for (i, got) in y.iter().enumerate() {
                    let want: f64 = (0..n).map(|j| a[j * m + i] * x[j]).sum();
                    assert!((got - want).abs() <= 1e-11 * (1.0 + want.abs()), "{m}x{n}");
                }
                // A (m × n) row-major, every third factor zero (skipped rows).
                let p: Vec<f64> = (0..m)
                    .map(|i| if i % 3 == 1 { 0.0 } else { i as f64 - 2.5 })
                    .collect();
                let mut t = vec![1.0; n];
                mul_t_add_row_major(&a, &p, &mut t);
                for (j, got) in t.iter().enumerate() {
                    let want = 1.0 + (0..m).map(|i| a[i * n + j] * p[i]).sum::<f64>();
                    assert!(
                        (got - want).abs() <= 1e-11 * (1.0 + want.abs()),
                        "{m}x{n} t"
                    );
                }
            }
        }
    }

    /// One pass over `y` per group of four non-zero factors: the order every entry's terms
    /// must keep.
    fn one_pass_per_group(a: &[f64], p: &[f64], y: &mut [f64]) {
        let n = y.len();
        let nz: Vec<usize> = (0..p.len()).filter(|&i| p[i] != 0.0).collect();
        let mut chunks = nz.chunks_exact(4);
        for g in &mut chunks {
            for (j, o) in y.iter_mut().enumerate() {
                let t = |k: usize| p[g[k]] * a[g[k] * n + j];
                *o += (t(0) + t(1)) + (t(2) + t(3));
            }
        }
        for &i in chunks.remainder() {
            for (j, o) in y.iter_mut().enumerate() {
                *o += p[i] * a[i * n + j];
            }
        }
    }

    #[test]
    fn blocked_sum_keeps_the_order_of_one_pass_per_group() {
        // Up to 300 factors (more groups than are collected at once), y shorter and longer
        // than a block.
        for m in [3, 4, 9, 300] {
            for n in [1, 7, 31, 32, 33, 70, 156] {
                let (a, _) = data(m, n);
                let p: Vec<f64> = (0..m)
                    .map(|i| {
                        if i % 7 == 3 {
                            0.0
                        } else {
                            (i as f64 - 4.5) / 3.0
                        }
                    })
                    .collect();
                let y0: Vec<f64> = (0..n).map(|j| (j as f64).sin()).collect();
                let (mut got, mut want) = (y0.clone(), y0);
                mul_t_add_row_major(&a, &p, &mut got);
                one_pass_per_group(&a, &p, &mut want);
                for j in 0..n {
                    assert_eq!(got[j].to_bits(), want[j].to_bits(), "{m}x{n} entry {j}");
                }
            }
        }
    }

    #[test]
    fn listed_rows_are_bit_identical_to_the_full_product() {
        for m in [1, 5, 156] {
            for n in [1, 3, 4, 9, 38] {
                for zeros in [false, true] {
                    let (a, mut x) = data(m, n);
                    x.iter_mut().for_each(|v| {
                        if *v == 0.0 {
                            *v = 0.5
                        }
                    });
                    // Zeros in x change the grouping: every fifth one.
                    if zeros {
                        x.iter_mut().step_by(5).for_each(|v| *v = 0.0);
                    }
                    let mut full = vec![0.0; m];
                    mul_col_major(&a, &x, &mut full);
                    let rows_major: Vec<f64> = (0..m)
                        .flat_map(|i| (0..n).map(move |j| (i, j)))
                        .map(|(i, j)| a[j * m + i])
                        .collect();
                    let rows: Vec<usize> = (0..m).filter(|i| i % 3 != 1).collect();
                    let mut got = vec![f64::NAN; m];
                    mul_rows_listed(&rows_major, &x, &rows, &mut got);
                    for i in 0..m {
                        if rows.contains(&i) {
                            assert_eq!(got[i].to_bits(), full[i].to_bits(), "{m}x{n} row {i}");
                        } else {
                            assert!(got[i].is_nan(), "{m}x{n} row {i} touched");
                        }
                    }
                }
            }
        }
    }

    #[test]
    #[should_panic(expected = "mul_col_major: matrix size")]
    fn wrong_size_is_refused() {
        mul_col_major(&[1.0; 5], &[1.0; 2], &mut [0.0; 2]);
    }
}

/// `a · b` with four partial sums (vectorizable; the summation order is fixed, so the result is
/// the same on every call).
///
/// # Panics
/// If the lengths differ.
#[multiversion::multiversion(targets("x86_64+avx512f+avx512vl", "x86_64+avx2+fma"))]
pub fn dot(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len(), "dot: lengths");
    let mut acc = [0.0f64; 4];
    let (ca, ra) = a.split_at(a.len() - a.len() % 4);
    let (cb, rb) = b.split_at(ca.len());
    for (x, y) in ca.chunks_exact(4).zip(cb.chunks_exact(4)) {
        for i in 0..4 {
            acc[i] += x[i] * y[i];
        }
    }
    let mut s = (acc[0] + acc[2]) + (acc[1] + acc[3]);
    for (x, y) in ra.iter().zip(rb) {
        s += x * y;
    }
    s
}

/// `y += α x`.
///
/// # Panics
/// If the lengths differ.
#[multiversion::multiversion(targets("x86_64+avx512f+avx512vl", "x86_64+avx2+fma"))]
pub fn axpy(alpha: f64, x: &[f64], y: &mut [f64]) {
    assert_eq!(x.len(), y.len(), "axpy: lengths");
    for (yi, xi) in y.iter_mut().zip(x) {
        *yi += alpha * xi;
    }
}
