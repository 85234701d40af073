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
//! AVX-512 and AVX2 + FMA as well and dispatched once per call.

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

/// `y += Σ_i s_i a_i` over the rows `a_i` (length `y.len()`) of the row-major `a`, `s_i ≠ 0`.
#[multiversion::multiversion(targets("x86_64+avx512f+avx512vl", "x86_64+avx2+fma"))]
fn lincomb_rows_add(a: &[f64], p: &[f64], y: &mut [f64]) {
    let n = y.len();
    if n == 0 {
        return;
    }
    let mut idx = [0usize; 4];
    let mut len = 0;
    for (i, &pi) in p.iter().enumerate() {
        if pi == 0.0 {
            continue;
        }
        idx[len] = i;
        len += 1;
        if len == 4 {
            let row = |k: usize| &a[idx[k] * n..idx[k] * n + n];
            let (r0, r1, r2, r3) = (row(0), row(1), row(2), row(3));
            let s = [p[idx[0]], p[idx[1]], p[idx[2]], p[idx[3]]];
            for ((((o, a0), a1), a2), a3) in y.iter_mut().zip(r0).zip(r1).zip(r2).zip(r3) {
                *o += (s[0] * a0 + s[1] * a1) + (s[2] * a2 + s[3] * a3);
            }
            len = 0;
        }
    }
    for &i in &idx[..len] {
        let s = p[i];
        for (o, v) in y.iter_mut().zip(&a[i * n..i * n + n]) {
            *o += s * v;
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
