//! All joint DOF kept: the static constraint modes of the joint pairs' relative normal DOF
//! (the competitor of Witteveen & Pichler 2014, Section 5.1).
//!
//! Section 5.1 discusses "preserving all the nodal FE DOF which are involved in nonlinearities"
//! (its refs. [19–24]): each joint DOF becomes a DOF of the reduced system — 628 additional DOF for
//! the paper's friction bar against 25 TVD. For the frictionless contact statics the relevant
//! joint DOF are the pairs' relative normal displacements `g_k = b_k q` (the rows `b_k` of
//! `B_n`, [`crate::joint`]), and the trial vectors that keep them are their static constraint
//! modes, with the master node fixed as in Craig–Bampton:
//!
//! ```text
//! ψ_k = [K_ii⁻¹ b_{k,i}ᵀ ; 0]      (mm/N: the response to a unit pair force, master clamped)
//! ```
//!
//! one column per pair, all from one sparse Cholesky of `K_ii` with `w` right-hand sides.
//!
//! ## Why Craig–Bampton + these span the exact contact solution
//!
//! The frictionless penalty equilibrium is `K q = f − B_nᵀ p` with the load `f` on the master DOF
//! only. Split `q = [q_i; q_m]`: `q_i = K_ii⁻¹ (f_i − (B_nᵀ p)_i) − K_ii⁻¹ K_im q_m`. With
//! `f_i = 0`, the last term is the constraint-mode part `Φ_S q_m` and the first is
//! `−Σ_k p_k ψ_k`. So every contact solution, for any load on the master and any active set,
//! lies in `span[Φ_S, ψ_1 … ψ_w]`, and a reduced model on this basis reproduces the full-FE
//! contact statics exactly (to round-off); the fixed-interface modes `Φ_V` are kept for the
//! dynamics.

use faer::{Mat, MatRef};

use crate::assembly::SymCsc;
use crate::error::Error;
use crate::joint::NORMAL;
use crate::model::Model;
use crate::statics::SparseCholesky;

use super::jim::interior_size;

/// The static constraint modes `ψ_k = [K_ii⁻¹ b_{k,i}ᵀ; 0]` of every joint pair's relative
/// normal DOF (n × w, column k for pair k, mm/N; zero on the master DOF): one sparse Cholesky of
/// `K_ii`, all pairs at once, refined twice with double-double residuals. Craig–Bampton plus
/// these columns span the exact frictionless contact solution (see the module docs). Entries of `b_k` on master DOF are dropped (the master is
/// fixed); a pair acting only on the master gives a zero column.
pub fn alldof_vectors(model: &Model) -> Result<Mat<f64>, Error> {
    let m = interior_size(model, "all-joint-DOF constraint modes")?;
    let w = model.joint.pairs();
    let mut x = Mat::<f64>::zeros(m, w);
    for k in 0..w {
        for (c, v) in model.joint.row(3 * k + NORMAL) {
            if c < m {
                x[(c, k)] += v;
            }
        }
    }
    if w > 0 {
        let kii_mat = model.stiffness.leading(m);
        let kii = SparseCholesky::new(&kii_mat)?;
        x = solve_refined(&kii_mat, &kii, &x);
    }
    if x.col_iter().any(|c| c.iter().any(|v| !v.is_finite())) {
        return Err(Error::LinearAlgebra(
            "all-joint-DOF constraint modes are not finite".into(),
        ));
    }
    let n = model.dofs();
    Ok(Mat::from_fn(
        n,
        w,
        |r, c| if r < m { x[(r, c)] } else { 0.0 },
    ))
}

/// Steps of iterative refinement of the constraint-mode solves, each with the residual
/// `b − K_ii x` accumulated in double-double ([`Dot2`]). A plain Cholesky solve is accurate only
/// to about cond(K_ii)·eps ≈ 1e-6 for the thin shells (cond ≈ 2e10); two refinement steps give
/// the solution of the assembled system to nearly working precision, which the alldof basis
/// needs to reproduce the full contact statics to 1e-8 (the same scheme as [`crate::contact`]).
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
        let p = a * b;
        let (ah, al) = split(a);
        let (bh, bl) = split(b);
        let p_err = ((ah * bh - p) + ah * bl + al * bh) + al * bl;
        let s = self.hi + p;
        let z = s - self.hi;
        let s_err = (self.hi - (s - z)) + (p - z);
        self.hi = s;
        self.lo += s_err + p_err;
    }

    pub(crate) fn value(self) -> f64 {
        self.hi + self.lo
    }
}

/// `out[:, c] = start[:, c] + s · A x[:, c]` for every column, each entry accumulated in
/// double-double and rounded once (A symmetric sparse, both triangles stored).
///
/// Row-oriented: column i of the symmetric A is its row i, so `out[i, :]` is one pass over
/// column i with all right-hand sides at once. `s·x` is stored row-major and pre-split
/// (Veltkamp), the accumulators are kept as separate `hi`/`lo` arrays over the columns, so the
/// inner loop is the same straight-line TwoProduct + TwoSum on contiguous data for every column
/// (vectorizable). The summation order per entry is the column order of A, as in [`Dot2`].
pub(crate) fn sym_mul_compensated(
    a: &SymCsc,
    x: MatRef<'_, f64>,
    s: f64,
    start: Option<MatRef<'_, f64>>,
) -> Mat<f64> {
    let n = a.n;
    let w = x.ncols();
    let mut out = Mat::<f64>::zeros(n, w);
    if w == 0 {
        return out;
    }
    // Row-major s·x, split into halves.
    let mut xh = vec![0.0; n * w];
    let mut xl = vec![0.0; n * w];
    for c in 0..w {
        for j in 0..n {
            let (h, l) = split(s * x[(j, c)]);
            xh[j * w + c] = h;
            xl[j * w + c] = l;
        }
    }
    let mut hi = vec![0.0; w];
    let mut lo = vec![0.0; w];
    for i in 0..n {
        for c in 0..w {
            hi[c] = start.map_or(0.0, |b| b[(i, c)]);
            lo[c] = 0.0;
        }
        for p in a.col_ptr[i]..a.col_ptr[i + 1] {
            let av = a.values[p];
            let (ah, al) = split(av);
            let j = a.row_idx[p];
            two_product_sums(
                &mut hi,
                &mut lo,
                av,
                ah,
                al,
                &xh[j * w..(j + 1) * w],
                &xl[j * w..(j + 1) * w],
            );
        }
        for c in 0..w {
            out[(i, c)] = hi[c] + lo[c];
        }
    }
    out
}

/// `hi[c] + lo[c] += a · (bh[c] + bl[c])` for every c: Dekker's TwoProduct (`a = ah + al` and
/// `b = bh + bl` are Veltkamp splits) and Knuth's TwoSum, the error terms summed into `lo` — the
/// inner loop of [`sym_mul_compensated`]. Compiled for AVX-512 / AVX2 as well as the baseline
/// and dispatched at run time (`multiversion`); the same IEEE operations on every path (no FMA
/// contraction in Rust), so the result does not depend on the CPU.
#[multiversion::multiversion(targets("x86_64+avx512f+avx512vl", "x86_64+avx2"))]
pub(crate) fn two_product_sums(
    hi: &mut [f64],
    lo: &mut [f64],
    a: f64,
    ah: f64,
    al: f64,
    bh: &[f64],
    bl: &[f64],
) {
    for ((h, l), (&bh, &bl)) in hi.iter_mut().zip(lo.iter_mut()).zip(bh.iter().zip(bl)) {
        let b = bh + bl;
        let prod = a * b;
        let p_err = ((ah * bh - prod) + ah * bl + al * bh) + al * bl;
        let sum = *h + prod;
        let z = sum - *h;
        let s_err = (*h - (sum - z)) + (prod - z);
        *h = sum;
        *l += s_err + p_err;
    }
}

/// Solves `A X = B` for all columns of `b` with the factorization `chol` of `a`, refined
/// [`REFINEMENT_STEPS`] times with double-double residuals.
pub(crate) fn solve_refined(a: &SymCsc, chol: &SparseCholesky, b: &Mat<f64>) -> Mat<f64> {
    solve_refined_steps(a, chol, b, REFINEMENT_STEPS)
}

/// [`solve_refined`] with `steps` refinement steps.
pub(crate) fn solve_refined_steps(
    a: &SymCsc,
    chol: &SparseCholesky,
    b: &Mat<f64>,
    steps: usize,
) -> Mat<f64> {
    let mut x = b.clone();
    chol.solve_in_place(&mut x);
    for _ in 0..steps {
        let mut r = sym_mul_compensated(a, x.as_ref(), -1.0, Some(b.as_ref()));
        chol.solve_in_place(&mut r);
        x += &r;
    }
    x
}
