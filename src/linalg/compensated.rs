//! Compensated (double-double) arithmetic for the ill-conditioned thin-shell stiffness
//! (cond(K) ≈ 2e10): Ogita–Rump–Oishi `Dot2` sums of products, a compensated sparse product,
//! iteratively refined Cholesky solves and the compensated Gram `Φᵀ A Φ`.

use faer::{Mat, MatRef};

use super::cholesky::SparseCholesky;
use super::sparse::SymCsc;

/// Steps of iterative refinement of the constraint-mode solves, each with the residual
/// `b − K_ii x` accumulated in double-double ([`Dot2`]). A plain Cholesky solve is accurate only
/// to about cond(K_ii)·eps ≈ 1e-6 for the thin shells (cond ≈ 2e10); two refinement steps give
/// the solution of the assembled system to nearly working precision, which the alldof basis
/// needs to reproduce the full contact statics to 1e-8 (the same scheme as [`crate::joint::statics`]).
pub(crate) const REFINEMENT_STEPS: usize = 2;

/// A compensated accumulator `hi + lo` of a sum of products, about twice the working precision
/// (TwoSum for the sums, Dekker's TwoProduct for the products; Ogita–Rump–Oishi `Dot2`).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Dot2 {
    hi: f64,
    lo: f64,
}

/// Veltkamp's split of `a` into two 26-bit halves.
pub(crate) fn split(a: f64) -> (f64, f64) {
    let c = 134_217_729.0 * a; // 2^27 + 1
    let hi = c - (c - a);
    (hi, a - hi)
}

impl Dot2 {
    pub(crate) fn new(start: f64) -> Dot2 {
        Dot2 { hi: start, lo: 0.0 }
    }

    /// `self += a·b`.
    pub(crate) fn add_product(&mut self, a: f64, b: f64) {
        product_sum(&mut self.hi, &mut self.lo, (a, split(a)), b, false);
    }

    pub(crate) fn value(self) -> f64 {
        self.hi + self.lo
    }
}

/// Columns of one block of [`sym_mul_compensated`].
const COMPENSATED_BLOCK: usize = 32;

/// `out[:, c] = start[:, c] + s · A x[:, c]` for every column, each entry accumulated in
/// double-double and rounded once (A symmetric sparse, both triangles stored).
///
/// Row-oriented: column i of the symmetric A is its row i, so `out[i, :]` is one pass over
/// column i with all right-hand sides of a block at once. `s·x` is stored row-major, the
/// accumulators are kept as separate `hi`/`lo` arrays over the columns, so the inner loop is
/// the same straight-line TwoProduct + TwoSum on contiguous data for every column
/// (vectorizable, [`product_sums`]). The summation order per entry is the column order of A, as
/// in [`Dot2`].
///
/// The columns go in blocks of 32, in parallel (rayon): the row-major copy of a block takes
/// `8 · 32 n` bytes (27 MB at 10⁵ DOF) instead of two more n × w matrices, and every entry
/// is computed by the same operations in the same order whatever the blocks or the threads, so
/// the result is bit-identical to a single pass.
pub(crate) fn sym_mul_compensated(
    a: &SymCsc,
    x: MatRef<'_, f64>,
    s: f64,
    start: Option<MatRef<'_, f64>>,
) -> Mat<f64> {
    use rayon::prelude::*;
    let mut out = Mat::<f64>::zeros(a.n, x.ncols());
    if x.ncols() == 0 {
        return out;
    }
    out.as_mut()
        .par_col_chunks_mut(COMPENSATED_BLOCK)
        .enumerate()
        .for_each(|(b, out_b)| {
            let c0 = b * COMPENSATED_BLOCK;
            let w = out_b.ncols();
            let x_b = x.subcols(c0, w);
            let start_b = start.map(|st| st.subcols(c0, w));
            sym_mul_compensated_block(a, x_b, s, start_b, out_b);
        });
    out
}

/// One block of [`sym_mul_compensated`], written to `out` (n × x.ncols(), at most
/// [`COMPENSATED_BLOCK`] columns).
///
/// `s·x` (and `start`) are copied row-major, each row padded with zeros to whole chunks of
/// [`LANES`], and every row's sums are held in registers over the row's stored entries
/// ([`compensated_rows`]), instead of being loaded and stored around a call per stored entry:
/// each entry gets the operations of [`product_sums`] in the column order of A, the same bits.
fn sym_mul_compensated_block(
    a: &SymCsc,
    x: MatRef<'_, f64>,
    s: f64,
    start: Option<MatRef<'_, f64>>,
    out: faer::MatMut<'_, f64>,
) {
    let n = a.n;
    let w = x.ncols();
    let chunks = w.div_ceil(LANES);
    assert!(
        chunks * LANES <= COMPENSATED_BLOCK,
        "a block of at most 32 columns"
    );
    let stride = chunks * LANES;
    let mut sx = vec![0.0; n * stride];
    to_rows(x, s, &mut sx, stride);
    let mut init = vec![0.0; n * stride];
    if let Some(b) = start {
        to_rows(b, 1.0, &mut init, stride);
    }
    let mut y = vec![0.0; n * stride];
    compensated_rows_of(a, &sx, &init, &mut y, stride);
    from_rows(&y, stride, out);
}

/// Rows of a tile of [`to_rows`] and [`from_rows`]: 64 rows of up to 32 columns are 16 KB on
/// each side, so a tile's strided side stays in the L1 cache while its columns stream.
const TILE_ROWS: usize = 64;

/// `rows[j · stride + c] = s · x[j, c]`: the columns of `x` into rows of `stride` values, tile
/// by tile of [`TILE_ROWS`] rows (a row-major copy that touches each row's cache lines once
/// per tile instead of once per column).
fn to_rows(x: MatRef<'_, f64>, s: f64, rows: &mut [f64], stride: usize) {
    let n = x.nrows();
    for j0 in (0..n).step_by(TILE_ROWS) {
        let j1 = (j0 + TILE_ROWS).min(n);
        for c in 0..x.ncols() {
            for (j, v) in (j0..j1).zip(x.col(c).subrows(j0, j1 - j0).iter()) {
                rows[j * stride + c] = s * v;
            }
        }
    }
}

/// `out[j, c] = rows[j · stride + c]`: [`to_rows`] back, tile by tile.
fn from_rows(rows: &[f64], stride: usize, mut out: faer::MatMut<'_, f64>) {
    use faer::reborrow::ReborrowMut;
    let n = out.nrows();
    for j0 in (0..n).step_by(TILE_ROWS) {
        let j1 = (j0 + TILE_ROWS).min(n);
        for c in 0..out.ncols() {
            let col = out.rb_mut().col_mut(c).subrows_mut(j0, j1 - j0);
            for (j, o) in (j0..j1).zip(col.iter_mut()) {
                *o = rows[j * stride + c];
            }
        }
    }
}

/// [`compensated_rows`] for rows of `sx`, `init` and `y` of 8 to 32 values (whole chunks),
/// compiled for AVX-512 / AVX2 as well as the baseline and dispatched at run time.
#[multiversion::multiversion(targets(
    "x86_64+avx512f+avx512vl+fma",
    "x86_64+avx2+fma",
    "x86_64+avx2"
))]
fn compensated_rows_of(a: &SymCsc, sx: &[f64], init: &[f64], y: &mut [f64], stride: usize) {
    let fma = multiversion::target::target_cfg_f!(target_feature = "fma");
    let args = (a, sx, init, y);
    match stride {
        0 => {}
        8 => compensated_rows::<8>(args, fma),
        16 => compensated_rows::<16>(args, fma),
        24 => compensated_rows::<24>(args, fma),
        _ => compensated_rows::<32>(args, fma),
    }
}

/// Lanes of one chunk of accumulators in [`sym_mul_compensated_block`].
const LANES: usize = 8;

/// `y[i] = init[i] + Σ_p a_p sx[row(p)]` over column i of A for every row i (rows of W
/// values), each lane accumulated in double-double ([`two_sum_product`]) in the column order of
/// A and rounded once, the row's W lanes held in registers over its stored entries.
#[inline(always)]
fn compensated_rows<const W: usize>(
    (a, sx, init, y): (&SymCsc, &[f64], &[f64], &mut [f64]),
    fma: bool,
) {
    for i in 0..a.n {
        let mut hi: [f64; W] = *lanes(init, i);
        let mut lo = [0.0; W];
        for p in a.col_ptr[i]..a.col_ptr[i + 1] {
            two_sum_product(&mut hi, &mut lo, a.values[p], lanes(sx, a.row_idx[p]), fma);
        }
        let out = &mut y[i * W..(i + 1) * W];
        for k in 0..W {
            out[k] = hi[k] + lo[k];
        }
    }
}

/// `hi[k] + lo[k] += a · b[k]` for the lanes of one row: [`product_sums`]'s operations,
/// inlined into its caller's target features.
#[inline(always)]
fn two_sum_product<const W: usize>(
    hi: &mut [f64; W],
    lo: &mut [f64; W],
    a: f64,
    b: &[f64; W],
    fma: bool,
) {
    let halves = split(a);
    for k in 0..W {
        product_sum(&mut hi[k], &mut lo[k], (a, halves), b[k], fma);
    }
}

/// Row `j` of a row-major array of rows of W values.
#[inline(always)]
fn lanes<const W: usize>(rows: &[f64], j: usize) -> &[f64; W] {
    rows[j * W..(j + 1) * W]
        .try_into()
        .expect("rows of W values")
}

/// `hi[c] + lo[c] += a · b[c]` for every c: the error-free product and Knuth's TwoSum, the
/// error terms summed into `lo` — the inner loop of the M-orthonormalization, and the
/// operations [`two_sum_product`] does on the lanes of [`sym_mul_compensated`] and
/// [`compensated_gram`] held in registers. Compiled for AVX-512 / AVX2 as well as
/// the baseline and dispatched at run time (`multiversion`).
///
/// The product's rounding error `a·b − fl(a·b)` is exactly representable, and both ways of
/// computing it here are exact: Dekker's TwoProduct from Veltkamp splits of `a` and `b`
/// (every partial product and sum exact) and, where the CPU has FMA, `fma(a, b, −fl(a·b))`
/// (one rounding of the exact value). So the two paths give the same bits — barring products
/// within 2⁵³ of the underflow threshold, far below any entry of K, M or a basis here — and
/// the FMA path does one operation in place of the splits and seven. No other operation is
/// contracted (Rust does not fuse `a * b + c`).
#[multiversion::multiversion(targets(
    "x86_64+avx512f+avx512vl+fma",
    "x86_64+avx2+fma",
    "x86_64+avx2"
))]
pub(crate) fn product_sums(hi: &mut [f64], lo: &mut [f64], a: f64, b: &[f64]) {
    let fma = multiversion::target::target_cfg_f!(target_feature = "fma");
    let halves = split(a);
    for ((h, l), &b) in hi.iter_mut().zip(lo.iter_mut()).zip(b) {
        product_sum(h, l, (a, halves), b, fma);
    }
}

/// `h + l += a · b` for one entry: TwoProduct (FMA or Dekker's from the Veltkamp halves of
/// `a` and `b`) and TwoSum, the errors summed into `l` ([`product_sums`]).
#[inline(always)]
fn product_sum(h: &mut f64, l: &mut f64, (a, (ah, al)): (f64, (f64, f64)), b: f64, fma: bool) {
    let prod = a * b;
    let p_err = if fma {
        a.mul_add(b, -prod)
    } else {
        let (bh, bl) = split(b);
        ((ah * bh - prod) + ah * bl + al * bh) + al * bl
    };
    let sum = *h + prod;
    let z = sum - *h;
    let s_err = (*h - (sum - z)) + (prod - z);
    *h = sum;
    *l += s_err + p_err;
}

/// Solves `A X = B` for all columns of `b` with the factorization `chol` of `a`, refined
/// [`REFINEMENT_STEPS`] times with double-double residuals.
pub(crate) fn solve_refined(a: &SymCsc, chol: &SparseCholesky, b: &Mat<f64>) -> Mat<f64> {
    solve_refined_steps(a, chol, b, REFINEMENT_STEPS)
}

/// [`solve_refined`] on right-hand sides the caller gives up ([`solve_refined_steps_owned`]):
/// the same bits, without a second n × columns matrix.
pub(crate) fn solve_refined_owned(a: &SymCsc, chol: &SparseCholesky, b: Mat<f64>) -> Mat<f64> {
    solve_refined_steps_owned(a, chol, b, REFINEMENT_STEPS)
}

/// Columns of one block of [`solve_refined_steps`].
const SOLVE_BLOCK: usize = 32;

/// [`solve_refined`] with `steps` refinement steps.
///
/// The columns go in blocks of 32, in parallel (rayon), each block solved and refined on its
/// own: the residual of one block (n × 32) instead of an n × w residual, and the right-hand
/// sides' solves spread over the cores (the 496 TVD solves of a 10⁵-DOF model). The blocks
/// are fixed (not by thread count), so the result does not depend on the threads; and faer's
/// supernodal solve gives a column the same bits in a block as alone (tested).
pub(crate) fn solve_refined_steps(
    a: &SymCsc,
    chol: &SparseCholesky,
    b: &Mat<f64>,
    steps: usize,
) -> Mat<f64> {
    solve_refined_steps_owned(a, chol, b.clone(), steps)
}

/// [`solve_refined_steps`] on right-hand sides the caller gives up: the solution overwrites
/// them, and only each block's right-hand sides are copied (n × 32 per block in flight instead
/// of a second n × columns matrix: 4.9 GB less for the 496 TVD solves at 1.2·10⁶ DOF). The
/// same bits as [`solve_refined_steps`].
pub(crate) fn solve_refined_steps_owned(
    a: &SymCsc,
    chol: &SparseCholesky,
    mut x: Mat<f64>,
    steps: usize,
) -> Mat<f64> {
    use faer::reborrow::{Reborrow, ReborrowMut};
    use rayon::prelude::*;
    x.as_mut()
        .par_col_chunks_mut(SOLVE_BLOCK)
        .for_each(|mut xb| {
            let bb = (steps > 0).then(|| xb.to_owned());
            chol.solve_in_place_mut(xb.rb_mut());
            if let Some(bb) = bb {
                for _ in 0..steps {
                    let mut r = sym_mul_compensated(a, xb.rb(), -1.0, Some(bb.as_ref()));
                    chol.solve_in_place(&mut r);
                    xb += &r;
                }
            }
        });
    x
}

/// Rows of `A Φ` split per block of [`compensated_gram`].
const GRAM_ROWS: usize = 2048;

/// `Φᵀ A Φ` (symmetrized) with `A Φ` and every inner product accumulated in double-double and
/// rounded once. The thin-shell K is ill-conditioned (cond ≈ 2e10): `K φ` for a smooth φ is a
/// small difference of large terms, so a plain product loses up to cond·eps of `K̃`'s smallest
/// eigenvalues' accuracy; the compensated product keeps `K̃` the exact projection of the
/// assembled K to working precision (measured: the alldof basis then reproduces the full contact
/// statics to ≤ 1e-8, against ≈ 5e-7 with plain products on the multilayer sheet).
///
/// Entry `(i, j)`, `i ≤ j`, is the [`Dot2`] sum of `φ_i[k] · (Aφ_j)[k]` over k ascending. The
/// sums run row block by row block ([`GRAM_ROWS`] rows of `A Φ`, row-major), and for
/// each `i` over all `j ≥ i` at once ([`product_sums`]: the same operations as
/// `Dot2::add_product(φ_i[k], (Aφ_j)[k])`, vectorized across j), the rows `i` in parallel — the
/// same bits as the entry-by-entry sums for any thread count (tested), ~1/10 of their time: one
/// Gram of r = 216 columns at 40 806 DOF took 3–10 s entry by entry, latency-bound.
pub(crate) fn compensated_gram(a: &SymCsc, phi: faer::MatRef<'_, f64>) -> Mat<f64> {
    use rayon::prelude::*;
    let aphi = sym_mul_compensated(a, phi, 1.0, None);
    let r = phi.ncols();
    let n = phi.nrows();
    // Row i of the upper triangle: hi and lo of the entries (i, j ≥ i), padded to whole
    // chunks of LANES (the padding's sums are of zeros, and dropped).
    let mut rows: Vec<(Vec<f64>, Vec<f64>)> = (0..r)
        .map(|i| {
            let len = (r - i).div_ceil(LANES) * LANES;
            (vec![0.0; len], vec![0.0; len])
        })
        .collect();
    // Rows of A Φ padded with zeros, so that every row's last chunk reads within its row.
    let stride = r + LANES;
    let mut b = vec![0.0; GRAM_ROWS.min(n) * stride];
    let mut phi_b = vec![vec![0.0; GRAM_ROWS.min(n)]; r];
    let mut k0 = 0;
    while k0 < n {
        let rows_b = GRAM_ROWS.min(n - k0);
        for j in 0..r {
            let col = aphi.col(j);
            for k in 0..rows_b {
                b[k * stride + j] = col[k0 + k];
            }
            for (k, v) in phi_b[j][..rows_b].iter_mut().enumerate() {
                *v = phi[(k0 + k, j)];
            }
        }
        let (b, phi_b) = (&b[..rows_b * stride], &phi_b);
        rows.par_iter_mut().enumerate().for_each(|(i, (hi, lo))| {
            gram_row_sums(hi, lo, &phi_b[i][..rows_b], b, (stride, i));
        });
        k0 += rows_b;
    }
    let mut g = Mat::<f64>::zeros(r, r);
    for (i, (hi, lo)) in rows.iter().enumerate() {
        for (d, (h, l)) in hi.iter().zip(lo).take(r - i).enumerate() {
            g[(i, i + d)] = h + l;
            g[(i + d, i)] = h + l;
        }
    }
    g
}

/// `hi[d] + lo[d] += Σ_k phi[k] · b[k · stride + i + d]` for every lane d of `hi` and `lo`
/// (whole chunks of [`LANES`]), k ascending: row i of [`compensated_gram`] over one block of
/// rows of `A Φ`. The lanes go 32 at a time (the last group 8, 16 or 24), held in registers
/// over the block's rows; each entry gets [`product_sums`]'s operations in the same order.
#[multiversion::multiversion(targets(
    "x86_64+avx512f+avx512vl+fma",
    "x86_64+avx2+fma",
    "x86_64+avx2"
))]
fn gram_row_sums(
    hi: &mut [f64],
    lo: &mut [f64],
    phi: &[f64],
    b: &[f64],
    (stride, i): (usize, usize),
) {
    let fma = multiversion::target::target_cfg_f!(target_feature = "fma");
    let mut d = 0;
    while d < hi.len() {
        let left = hi.len() - d;
        let (h, l, j0) = (&mut hi[d..], &mut lo[d..], i + d);
        match left {
            8 => gram_lanes::<8>(h, l, phi, b, (stride, j0), fma),
            16 => gram_lanes::<16>(h, l, phi, b, (stride, j0), fma),
            24 => gram_lanes::<24>(h, l, phi, b, (stride, j0), fma),
            _ => gram_lanes::<32>(h, l, phi, b, (stride, j0), fma),
        }
        d += 32;
    }
}

/// W lanes of [`gram_row_sums`] from `hi[0]`, entry `j0` of the rows of `b` on.
#[inline(always)]
fn gram_lanes<const W: usize>(
    hi: &mut [f64],
    lo: &mut [f64],
    phi: &[f64],
    b: &[f64],
    (stride, j0): (usize, usize),
    fma: bool,
) {
    let mut h: [f64; W] = *lanes(hi, 0);
    let mut l: [f64; W] = *lanes(lo, 0);
    for (k, &a) in phi.iter().enumerate() {
        let row: &[f64; W] = b[k * stride + j0..k * stride + j0 + W]
            .try_into()
            .expect("W entries");
        two_sum_product(&mut h, &mut l, a, row, fma);
    }
    hi[..W].copy_from_slice(&h);
    lo[..W].copy_from_slice(&l);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The blocked, vectorized Gram equals the entry-by-entry [`Dot2`] sums bit for bit, across
    /// the row-block boundary.
    #[test]
    fn blocked_gram_is_the_dot2_sum() {
        let n = GRAM_ROWS + 37;
        let (mut col_ptr, mut row_idx, mut values) = (vec![0], Vec::new(), Vec::new());
        for j in 0..n {
            for i in j.saturating_sub(1)..(j + 2).min(n) {
                row_idx.push(i);
                values.push(if i == j {
                    2.0 + 1e5 * (j % 7) as f64
                } else {
                    -1.0 - 1e-3 * j as f64
                });
            }
            col_ptr.push(row_idx.len());
        }
        let a = SymCsc {
            n,
            col_ptr,
            row_idx,
            values,
        };
        // Rows of the triangle of one to three chunks of lanes, one past a group of 32.
        for r in [9, 41] {
            let phi = Mat::from_fn(n, r, |k, c| {
                ((k * (c + 3)) as f64 * 0.37).sin() * 10f64.powi(c as i32 % 9 - 4)
            });
            let g = compensated_gram(&a, phi.as_ref());
            let aphi = sym_mul_compensated(&a, phi.as_ref(), 1.0, None);
            for j in 0..r {
                for i in 0..=j {
                    let mut acc = Dot2::new(0.0);
                    for k in 0..n {
                        acc.add_product(phi[(k, i)], aphi[(k, j)]);
                    }
                    assert_eq!(
                        g[(i, j)].to_bits(),
                        acc.value().to_bits(),
                        "r {r} ({i}, {j})"
                    );
                    assert_eq!(
                        g[(j, i)].to_bits(),
                        acc.value().to_bits(),
                        "r {r} ({j}, {i})"
                    );
                }
            }
        }
    }

    /// The blocked, parallel product equals the entry-by-entry [`Dot2`] sums bit for bit, for
    /// column counts below, at and across the block width (ragged last block).
    #[test]
    fn blocked_product_is_the_dot2_sum() {
        // A 1-D Laplacian-like symmetric pattern with spread values, both triangles stored.
        let n: usize = 50;
        let (mut col_ptr, mut row_idx, mut values) = (vec![0], Vec::new(), Vec::new());
        for j in 0..n {
            for i in j.saturating_sub(2)..(j + 3).min(n) {
                row_idx.push(i);
                let (lo, hi) = (i.min(j) as f64, i.max(j) as f64);
                values.push(if i == j {
                    4.0 + 1e6 * lo
                } else {
                    -1.0 / (1.0 + lo * hi)
                });
            }
            col_ptr.push(row_idx.len());
        }
        let a = SymCsc {
            n,
            col_ptr,
            row_idx,
            values,
        };
        for w in [1, 5, 8, 9, 17, 24, 31, 32, 33, 70] {
            let x = Mat::from_fn(n, w, |i, c| ((i * 7 + c * 13) as f64).sin() * 1e3);
            let b = Mat::from_fn(n, w, |i, c| ((i + 3 * c) as f64).cos());
            let s = -0.7;
            let out = sym_mul_compensated(&a, x.as_ref(), s, Some(b.as_ref()));
            for c in 0..w {
                for i in 0..n {
                    let mut acc = Dot2::new(b[(i, c)]);
                    for p in a.col_ptr[i]..a.col_ptr[i + 1] {
                        acc.add_product(a.values[p], s * x[(a.row_idx[p], c)]);
                    }
                    assert_eq!(
                        out[(i, c)].to_bits(),
                        acc.value().to_bits(),
                        "w {w}, ({i}, {c})"
                    );
                }
            }
        }
    }
}

#[cfg(test)]
mod solve_tests {
    use super::*;

    /// An SPD stiffness-like matrix: 3 DOF per node on a g × g grid, every node coupled to its
    /// 8 neighbours (a shell mesh's pattern), diagonally dominant with spread diagonal scales.
    fn grid_matrix(g: usize) -> SymCsc {
        let n = 3 * g * g;
        let node = |i: usize| (i / 3 / g, i / 3 % g);
        let (mut col_ptr, mut row_idx, mut values) = (vec![0], Vec::new(), Vec::new());
        for j in 0..n {
            let (jy, jx) = node(j);
            let mut col: Vec<(usize, f64)> = Vec::new();
            for iy in jy.saturating_sub(1)..(jy + 2).min(g) {
                for ix in jx.saturating_sub(1)..(jx + 2).min(g) {
                    for d in 0..3 {
                        let i = 3 * (iy * g + ix) + d;
                        if i != j {
                            col.push((i, -1.0 / (1.0 + ((i + j) % 7) as f64)));
                        }
                    }
                }
            }
            let off: f64 = col.iter().map(|(_, v)| v.abs()).sum();
            col.push((j, off * (1.0 + 1e-3) + 1e3 * (j % 5) as f64));
            col.sort_by_key(|e| e.0);
            for (i, v) in col {
                row_idx.push(i);
                values.push(v);
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

    /// The blocked refined solve gives every column bit for bit as solving it alone does (a
    /// 4 800-DOF supernodal factor, 70 columns: blocks of 32, 32 and 6): the blocks do not
    /// change the result.
    #[test]
    fn blocked_refined_solve_is_columnwise() {
        let k = grid_matrix(40);
        let chol = SparseCholesky::new(&k).unwrap();
        assert!(
            chol.is_supernodal(),
            "the 10⁵-DOF models' factor is supernodal"
        );
        let n = k.n;
        let b = Mat::from_fn(n, 70, |i, c| ((i * 31 + c * 17) as f64).sin());
        let x = solve_refined_steps(&k, &chol, &b, 1);
        for c in [0, 31, 32, 33, 69] {
            let bc = Mat::from_fn(n, 1, |i, _| b[(i, c)]);
            let xc = solve_refined_steps(&k, &chol, &bc, 1);
            for i in 0..n {
                assert_eq!(x[(i, c)].to_bits(), xc[(i, 0)].to_bits(), "({i}, {c})");
            }
        }
    }
}
