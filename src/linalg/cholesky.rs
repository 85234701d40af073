//! Linear statics: `K q = f` by sparse Cholesky (faer), factored once for many right-hand sides.

use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
use faer::{Mat, Side};

use crate::error::Error;
use crate::linalg::SymCsc;

/// A sparse Cholesky factorization `A = L Lᵀ` of a symmetric positive definite matrix.
pub struct SparseCholesky {
    n: usize,
    llt: Llt<usize, f64>,
}

impl SparseCholesky {
    /// Factors `a` (symbolic analysis with AMD ordering, then numeric). Errors if `a` is not
    /// positive definite (e.g. an unsupported, singular structure).
    pub fn new(a: &SymCsc) -> Result<SparseCholesky, Error> {
        let mat = a.to_faer();
        let symbolic = SymbolicLlt::try_new(mat.symbolic(), Side::Lower).map_err(|e| {
            Error::LinearAlgebra(format!("symbolic Cholesky of a {0}×{0} matrix: {e:?}", a.n))
        })?;
        let llt = Llt::try_new_with_symbolic(symbolic, mat.as_ref(), Side::Lower).map_err(|e| {
            Error::LinearAlgebra(format!(
                "the {0}×{0} matrix is not positive definite (singular or unsupported structure): {e:?}",
                a.n
            ))
        })?;
        Ok(SparseCholesky { n: a.n, llt })
    }

    /// Solves in place for all columns of `rhs`.
    pub fn solve_in_place(&self, rhs: &mut Mat<f64>) {
        self.llt.solve_in_place(rhs.as_mut());
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
