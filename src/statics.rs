//! Linear statics: `K q = f` by sparse Cholesky (faer), factored once for many right-hand sides.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::reborrow::ReborrowMut;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, supernodal::SupernodalLltRef, LltRef, SymbolicCholesky,
    SymbolicCholeskyRaw,
};
use faer::sparse::linalg::triangular_solve::{
    solve_lower_triangular_in_place, solve_lower_triangular_transpose_in_place,
};
use faer::sparse::SparseColMatRef;
use faer::{Conj, Mat, MatMut, MatRef, Par, Side};

use crate::assembly::SymCsc;
use crate::error::Error;

/// A static solution.
#[derive(Clone, Debug, PartialEq)]
pub struct StaticSolution {
    /// All independent DOF, mm and rad.
    pub displacement: Vec<f64>,
    /// The master node `[ux, uy, uz (mm), rx, ry, rz (rad)]`.
    pub master_displacement: [f64; 6],
}

/// A sparse Cholesky factorization `P A Pᵀ = L Lᵀ` (fill-reducing permutation P) of a symmetric
/// positive definite matrix.
pub struct SparseCholesky {
    n: usize,
    symbolic: SymbolicCholesky<usize>,
    values: Vec<f64>,
}

impl std::fmt::Debug for SparseCholesky {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SparseCholesky")
            .field("n", &self.n)
            .field("nnz_l", &self.values.len())
            .finish()
    }
}

impl SparseCholesky {
    /// Factors `a` (symbolic analysis with AMD ordering, then numeric). Errors if `a` is not
    /// positive definite (e.g. an unsupported, singular structure).
    pub fn new(a: &SymCsc) -> Result<SparseCholesky, Error> {
        let mat = a.to_faer();
        let symbolic = factorize_symbolic_cholesky(
            mat.symbolic(),
            Side::Lower,
            Default::default(),
            Default::default(),
        )
        .map_err(|e| {
            Error::LinearAlgebra(format!("symbolic Cholesky of a {0}×{0} matrix: {e:?}", a.n))
        })?;
        let mut values = vec![0.0; symbolic.len_val()];
        let par = faer::get_global_parallelism();
        let scratch = symbolic.factorize_numeric_llt_scratch::<f64>(par, Default::default());
        symbolic
            .factorize_numeric_llt(
                &mut values,
                mat.as_ref(),
                Side::Lower,
                Default::default(),
                par,
                MemStack::new(&mut MemBuffer::new(scratch)),
                Default::default(),
            )
            .map_err(|e| {
                Error::LinearAlgebra(format!(
                    "the {0}×{0} matrix is not positive definite (singular or unsupported structure): {e:?}",
                    a.n
                ))
            })?;
        Ok(SparseCholesky {
            n: a.n,
            symbolic,
            values,
        })
    }

    /// Solves in place for all columns of `rhs`.
    pub fn solve_in_place(&self, rhs: &mut Mat<f64>) {
        let par = faer::get_global_parallelism();
        let scratch = self
            .symbolic
            .solve_in_place_scratch::<f64>(rhs.ncols(), par);
        LltRef::new(&self.symbolic, &self.values).solve_in_place_with_conj(
            Conj::No,
            rhs.as_mut(),
            par,
            MemStack::new(&mut MemBuffer::new(scratch)),
        );
    }

    /// Half solve `x ← L⁻¹ P x` for all columns (sequential): with [`Self::half_solve_transpose`],
    /// `A⁻¹ = (Pᵀ L⁻ᵀ)(L⁻¹ P)`.
    pub(crate) fn half_solve(&self, mut x: MatMut<'_, f64>) {
        self.permute(x.rb_mut(), false);
        self.triangular(x, false);
    }

    /// Half solve `x ← Pᵀ L⁻ᵀ x` for all columns (sequential).
    pub(crate) fn half_solve_transpose(&self, mut x: MatMut<'_, f64>) {
        self.triangular(x.rb_mut(), true);
        self.permute(x, true);
    }

    /// `x ← P x` (`inverse` false) or `x ← Pᵀ x`, in faer's convention `(P x)_i = x_{fwd(i)}`.
    fn permute(&self, mut x: MatMut<'_, f64>, inverse: bool) {
        let Some(perm) = self.symbolic.perm() else {
            return;
        };
        let (fwd, inv) = perm.arrays();
        let map = if inverse { inv } else { fwd };
        let mut tmp = vec![0.0; self.n];
        for j in 0..x.ncols() {
            for (t, &src) in tmp.iter_mut().zip(map) {
                *t = x[(src, j)];
            }
            for (i, &t) in tmp.iter().enumerate() {
                x[(i, j)] = t;
            }
        }
    }

    /// `x ← L⁻¹ x` or (`transpose`) `x ← L⁻ᵀ x` with the (permuted) factor L.
    fn triangular(&self, x: MatMut<'_, f64>, transpose: bool) {
        let par = Par::Seq;
        match self.symbolic.raw() {
            SymbolicCholeskyRaw::Simplicial(s) => {
                let l = SparseColMatRef::<'_, usize, f64>::new(s.factor(), &self.values);
                if transpose {
                    solve_lower_triangular_transpose_in_place(l, Conj::No, x, par);
                } else {
                    solve_lower_triangular_in_place(l, Conj::No, x, par);
                }
            }
            SymbolicCholeskyRaw::Supernodal(s) => {
                let scratch = s.solve_in_place_scratch::<f64>(x.ncols(), par);
                let stack = &mut MemBuffer::new(scratch);
                let l = SupernodalLltRef::new(s, &self.values);
                if transpose {
                    l.l_transpose_solve_with_conj(Conj::No, x, par, MemStack::new(stack));
                } else {
                    l.l_solve_with_conj(Conj::No, x, par, MemStack::new(stack));
                }
            }
        }
    }

    /// Dimension.
    pub fn dim(&self) -> usize {
        self.n
    }
}

/// Solves `A x = b` for every `b` in `rhs` with one factorization; checks the residual.
pub fn solve_spd(a: &SymCsc, rhs: &[Vec<f64>]) -> Result<Vec<Vec<f64>>, Error> {
    let chol = SparseCholesky::new(a)?;
    let n = a.n;
    let mut b = Mat::from_fn(n, rhs.len(), |i, j| rhs[j][i]);
    chol.solve_in_place(&mut b);
    let mut out = Vec::with_capacity(rhs.len());
    let mut ax = vec![0.0; n];
    let a_norm = a.inf_norm();
    for (j, r) in rhs.iter().enumerate() {
        let x: Vec<f64> = (0..n).map(|i| b[(i, j)]).collect();
        if x.iter().any(|v| !v.is_finite()) {
            return Err(Error::LinearAlgebra("static solution is not finite".into()));
        }
        a.mul_vec(&x, &mut ax);
        let res = ax
            .iter()
            .zip(r)
            .map(|(p, q)| (p - q).abs())
            .fold(0.0, f64::max);
        let x_norm = x.iter().map(|v| v.abs()).fold(0.0, f64::max);
        let b_norm = r.iter().map(|v| v.abs()).fold(0.0, f64::max);
        // Normwise backward error; a stable Cholesky gives ~1e-16.
        let backward = res / (a_norm * x_norm + b_norm).max(f64::MIN_POSITIVE);
        if backward > 1e-10 {
            return Err(Error::LinearAlgebra(format!(
                "static solve backward error {backward:.3e} exceeds 1e-10 (singular or ill-conditioned stiffness)"
            )));
        }
        out.push(x);
    }
    Ok(out)
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
/// 32 columns: each block is copied row-major, so every stored entry of A multiplies 32
/// contiguous values (four cache lines, independent accumulators) — `nnz(A) · p` multiply-adds,
/// A read `p / 32` times.
pub(crate) fn sym_mul_mat(a: &SymCsc, y: MatRef<'_, f64>) -> Mat<f64> {
    let n = a.n;
    let p = y.ncols();
    let mut out = Mat::<f64>::zeros(n, p);
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
