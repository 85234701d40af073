//! Sparse SPD Cholesky (faer): one symbolic analysis per pattern, numeric factorizations per
//! value set, solves for one or many right-hand sides; `K q = f` with a residual check.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::linalg::solvers::LltError;
use faer::reborrow::ReborrowMut;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, supernodal::SupernodalLltRef, CholeskySymbolicParams, LltRef,
    SymbolicCholesky, SymbolicCholeskyRaw, SymmetricOrdering,
};
use faer::sparse::linalg::triangular_solve::{
    solve_lower_triangular_in_place, solve_lower_triangular_transpose_in_place,
};
use faer::sparse::linalg::LltError as SparseLltError;
use faer::sparse::FaerError;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::{get_global_parallelism, Conj, Mat, MatMut, Par, Side};

use crate::linalg::LinalgError;
use crate::linalg::SymCsc;

/// A sparse Cholesky factorization `P A Pᵀ = L Lᵀ` (fill-reducing permutation P, AMD) of a
/// symmetric positive definite matrix with a fixed pattern: the symbolic analysis (AMD ordering) once, numeric factorizations as often as
/// the values change, solves for one column into preallocated scratch (no allocation: the
/// Newton solve of a transient) or for many columns at once.
///
/// The one SPD factorization of jointrom: statics, constraint modes, shift-invert eigen solves,
/// the mass and Newton matrices of the full model.
pub struct SparseCholesky {
    n: usize,
    pattern: SymbolicSparseColMat<usize>,
    symbolic: SymbolicCholesky<usize>,
    l_values: Vec<f64>,
    /// Parallelism of the numeric factorization and of many-column solves.
    par: Par,
    /// Scratch of the numeric factorization and of a one-column solve or half solve.
    mem: MemBuffer,
    /// n values: the permutation of a one-column half solve.
    tmp: Vec<f64>,
    factored: bool,
}

impl SparseCholesky {
    /// Factors `a` (symbolic analysis with AMD ordering, then numeric, with faer's global
    /// parallelism). Errors if `a` is not positive definite (e.g. an unsupported, singular
    /// structure).
    pub fn new(a: &SymCsc) -> Result<SparseCholesky, LinalgError> {
        SparseCholesky::new_with(a, get_global_parallelism())
    }

    /// [`SparseCholesky::new`] with the parallelism `par` of the numeric factorization and of
    /// many-column solves.
    pub fn new_with(a: &SymCsc, par: Par) -> Result<SparseCholesky, LinalgError> {
        let mut chol = SparseCholesky::analyze_with(a.n, a.col_ptr.clone(), a.row_idx.clone(), par)
            .map_err(|e| LinalgError::Symbolic {
                what: format!("Cholesky of a {0}×{0} matrix", a.n),
                source: Box::new(e),
            })?;
        chol.factor_with(&a.values, |e| {
            let e = SparseLltError::Numeric(e);
            LinalgError::NotPositiveDefinite {
                what: format!("the {0}×{0} matrix", a.n),
                hint: " (singular or unsupported structure)",
                source: Box::new(e),
            }
        })?;
        Ok(chol)
    }

    /// The symbolic analysis of the pattern `col_ptr`/`row_idx` (n × n, both triangles,
    /// sorted rows), for sequential numeric factorizations with [`SparseCholesky::factor`].
    pub(crate) fn analyze(
        n: usize,
        col_ptr: Vec<usize>,
        row_idx: Vec<usize>,
    ) -> Result<SparseCholesky, LinalgError> {
        SparseCholesky::analyze_with(n, col_ptr, row_idx, Par::Seq).map_err(|e| {
            LinalgError::Symbolic {
                what: format!("Cholesky ({n}×{n})"),
                source: Box::new(e),
            }
        })
    }

    fn analyze_with(
        n: usize,
        col_ptr: Vec<usize>,
        row_idx: Vec<usize>,
        par: Par,
    ) -> Result<SparseCholesky, FaerError> {
        let pattern = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx);
        let symbolic = factorize_symbolic_cholesky(
            pattern.as_ref(),
            Side::Lower,
            SymmetricOrdering::Amd,
            CholeskySymbolicParams::default(),
        )?;
        let req = StackReq::any_of(&[
            symbolic.factorize_numeric_llt_scratch::<f64>(par, Default::default()),
            symbolic.solve_in_place_scratch::<f64>(1, Par::Seq),
        ]);
        Ok(SparseCholesky {
            n,
            l_values: vec![0.0; symbolic.len_val()],
            mem: MemBuffer::new(req),
            tmp: vec![0.0; n],
            pattern,
            symbolic,
            par,
            factored: false,
        })
    }

    /// Factors the values of the analysed pattern; `what` names the matrix in the error if it
    /// is not positive definite.
    pub fn factor(&mut self, values: &[f64], what: &str) -> Result<(), LinalgError> {
        let n = self.n;
        self.factor_with(values, |e| LinalgError::NotPositiveDefinite {
            what: format!("{what} ({n}×{n})"),
            hint: "",
            source: Box::new(e),
        })
    }

    fn factor_with(
        &mut self,
        values: &[f64],
        error: impl FnOnce(LltError) -> LinalgError,
    ) -> Result<(), LinalgError> {
        self.factored = false;
        let a = SparseColMatRef::new(self.pattern.as_ref(), values);
        self.symbolic
            .factorize_numeric_llt(
                &mut self.l_values,
                a,
                Side::Lower,
                LltRegularization::default(),
                self.par,
                MemStack::new(&mut self.mem),
                Default::default(),
            )
            .map_err(error)?;
        self.factored = true;
        Ok(())
    }

    /// `x ← A⁻¹ x` for one column, sequential, in preallocated scratch (NaN if the last
    /// factorization failed).
    pub(crate) fn solve_vec_in_place(&mut self, x: &mut [f64]) {
        if !self.factored {
            x.fill(f64::NAN);
            return;
        }
        let rhs = MatMut::from_column_major_slice_mut(x, self.n, 1);
        LltRef::new(&self.symbolic, &self.l_values).solve_in_place_with_conj(
            Conj::No,
            rhs,
            Par::Seq,
            MemStack::new(&mut self.mem),
        );
    }

    /// Solves in place for all columns of `rhs` (NaN if the last factorization failed).
    pub fn solve_in_place(&self, rhs: &mut Mat<f64>) {
        self.solve_in_place_mut(rhs.as_mut());
    }

    /// [`Self::solve_in_place`] on a matrix view (e.g. a block of columns).
    pub(crate) fn solve_in_place_mut(&self, mut rhs: MatMut<'_, f64>) {
        if !self.factored {
            rhs.fill(f64::NAN);
            return;
        }
        let mut mem = MemBuffer::new(
            self.symbolic
                .solve_in_place_scratch::<f64>(rhs.ncols(), self.par),
        );
        LltRef::new(&self.symbolic, &self.l_values).solve_in_place_with_conj(
            Conj::No,
            rhs,
            self.par,
            MemStack::new(&mut mem),
        );
    }

    /// Half solve `x ← L⁻¹ P x` for all columns (sequential): with [`Self::half_solve_transpose`],
    /// `A⁻¹ = (Pᵀ L⁻ᵀ)(L⁻¹ P)`.
    pub(crate) fn half_solve(&self, mut x: MatMut<'_, f64>) {
        let mut tmp = vec![0.0; self.n];
        let mut mem = MemBuffer::new(self.triangular_scratch(x.ncols()));
        permute(&self.symbolic, x.rb_mut(), false, &mut tmp);
        triangular(
            &self.symbolic,
            &self.l_values,
            x,
            false,
            MemStack::new(&mut mem),
        );
    }

    /// Half solve `x ← Pᵀ L⁻ᵀ x` for all columns (sequential).
    pub(crate) fn half_solve_transpose(&self, mut x: MatMut<'_, f64>) {
        let mut tmp = vec![0.0; self.n];
        let mut mem = MemBuffer::new(self.triangular_scratch(x.ncols()));
        triangular(
            &self.symbolic,
            &self.l_values,
            x.rb_mut(),
            true,
            MemStack::new(&mut mem),
        );
        permute(&self.symbolic, x, true, &mut tmp);
    }

    /// [`Self::half_solve`] of one column in preallocated scratch (no allocation: the Newton
    /// solve of a low-rank corrected factor, [`crate::linalg::lowrank`]). NaN if the last
    /// factorization failed.
    pub(crate) fn half_solve_vec_in_place(&mut self, x: &mut [f64]) {
        if !self.factored {
            x.fill(f64::NAN);
            return;
        }
        let mut x = MatMut::from_column_major_slice_mut(x, self.n, 1);
        permute(&self.symbolic, x.rb_mut(), false, &mut self.tmp);
        triangular(
            &self.symbolic,
            &self.l_values,
            x,
            false,
            MemStack::new(&mut self.mem),
        );
    }

    /// [`Self::half_solve_transpose`] of one column in preallocated scratch.
    pub(crate) fn half_solve_transpose_vec_in_place(&mut self, x: &mut [f64]) {
        if !self.factored {
            x.fill(f64::NAN);
            return;
        }
        let mut x = MatMut::from_column_major_slice_mut(x, self.n, 1);
        triangular(
            &self.symbolic,
            &self.l_values,
            x.rb_mut(),
            true,
            MemStack::new(&mut self.mem),
        );
        permute(&self.symbolic, x, true, &mut self.tmp);
    }

    /// Scratch of a triangular half solve with `ncols` columns.
    fn triangular_scratch(&self, ncols: usize) -> StackReq {
        match self.symbolic.raw() {
            SymbolicCholeskyRaw::Simplicial(_) => StackReq::EMPTY,
            SymbolicCholeskyRaw::Supernodal(s) => s.solve_in_place_scratch::<f64>(ncols, Par::Seq),
        }
    }

    /// Whether the last numeric factorization succeeded.
    pub(crate) fn is_factored(&self) -> bool {
        self.factored
    }

    /// Whether faer chose the supernodal factor (tests: which solve path is exercised).
    #[cfg(test)]
    pub(crate) fn is_supernodal(&self) -> bool {
        matches!(self.symbolic.raw(), SymbolicCholeskyRaw::Supernodal(_))
    }

    /// Dimension.
    pub fn dim(&self) -> usize {
        self.n
    }
}

/// `x ← P x` (`inverse` false) or `x ← Pᵀ x`, in faer's convention `(P x)_i = x_{fwd(i)}`;
/// `tmp` holds n values.
fn permute(
    symbolic: &SymbolicCholesky<usize>,
    mut x: MatMut<'_, f64>,
    inverse: bool,
    tmp: &mut [f64],
) {
    let Some(perm) = symbolic.perm() else {
        return;
    };
    let (fwd, inv) = perm.arrays();
    let map = if inverse { inv } else { fwd };
    for j in 0..x.ncols() {
        for (t, &src) in tmp.iter_mut().zip(map) {
            *t = x[(src, j)];
        }
        for (i, &t) in tmp.iter().enumerate() {
            x[(i, j)] = t;
        }
    }
}

/// `x ← L⁻¹ x` or (`transpose`) `x ← L⁻ᵀ x` with the (permuted) factor L (sequential).
fn triangular(
    symbolic: &SymbolicCholesky<usize>,
    l_values: &[f64],
    x: MatMut<'_, f64>,
    transpose: bool,
    stack: &mut MemStack,
) {
    let par = Par::Seq;
    match symbolic.raw() {
        SymbolicCholeskyRaw::Simplicial(s) => {
            let l = SparseColMatRef::<'_, usize, f64>::new(s.factor(), l_values);
            if transpose {
                solve_lower_triangular_transpose_in_place(l, Conj::No, x, par);
            } else {
                solve_lower_triangular_in_place(l, Conj::No, x, par);
            }
        }
        SymbolicCholeskyRaw::Supernodal(s) => {
            let l = SupernodalLltRef::new(s, l_values);
            if transpose {
                l.l_transpose_solve_with_conj(Conj::No, x, par, stack);
            } else {
                l.l_solve_with_conj(Conj::No, x, par, stack);
            }
        }
    }
}

/// Solves `A x = b` for every `b` in `rhs` with one factorization; checks the residual.
pub fn solve_spd(a: &SymCsc, rhs: &[Vec<f64>]) -> Result<Vec<Vec<f64>>, LinalgError> {
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
            return Err(LinalgError::not_finite("static solution"));
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
            return Err(LinalgError::StaticBackwardError { backward });
        }
        out.push(x);
    }
    Ok(out)
}
