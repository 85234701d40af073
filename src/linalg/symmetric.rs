//! The dense symmetric eigen decomposition `A = U diag(λ) Uᵀ` that every stage uses (POD Gram
//! matrices, the reduced eigenbasis, Rayleigh–Ritz, the dense reference modes).
//!
//! faer reduces `A` to tridiagonal form by Householder reflections and then, from dimension 128
//! on, solves the tridiagonal problem by divide and conquer. That last step is not backward
//! stable on matrices whose spectrum holds a large cluster far above the rest — exactly the
//! reduced stiffness `ΦᵀKΦ` of an M-orthonormal basis with many pair attachment modes (ω² from
//! 8e3 to 2.8e14 /s², a hundred of them within 20 % of the top). Measured on the friction bar
//! ×8's tolerance model (r = 203): `‖UᵀAU − diag‖ / ‖A‖ = 3.9e-4` and a lowest eigenvalue of
//! −2.3e7 (true 8.0e3), where a backward-stable solver leaves 1e-15; a synthetic matrix
//! `Q diag(λ) Qᵀ` with 60 of 150 eigenvalues near 1e14 reproduces it (the unit test below). The
//! implicit QR iteration on the tridiagonal matrix is backward stable for any spectrum and, with
//! eigenvectors, no slower than divide and conquer at the sizes used here (r ≤ 10³: 1.4 ms at
//! 200, 15 ms at 512, 77 ms at 906 on this machine), so this module always takes it.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::evd::{
    self_adjoint_evd, self_adjoint_evd_scratch, ComputeEigenvectors, SelfAdjointEvdParams,
};
use faer::{Auto, Mat, MatRef, Par};

use super::LinalgError;

/// Eigenvalues (ascending) and orthonormal eigenvectors (columns, in the same order) of a
/// symmetric matrix.
#[derive(Clone, Debug)]
pub struct SymmetricEigen {
    /// Eigenvalues λ, ascending (the unit of the matrix).
    pub values: Vec<f64>,
    /// Orthonormal eigenvectors, column `j` for `values[j]`.
    pub vectors: Mat<f64>,
}

/// The tridiagonal QR iteration for every size (module docs).
fn params() -> SelfAdjointEvdParams {
    let mut p = <SelfAdjointEvdParams as Auto<f64>>::auto();
    p.recursion_threshold = usize::MAX;
    p
}

fn decompose(
    a: MatRef<'_, f64>,
    vectors: bool,
    what: &str,
) -> Result<(Vec<f64>, Option<Mat<f64>>), LinalgError> {
    let n = a.nrows();
    if a.ncols() != n {
        return Err(LinalgError::NotSquare {
            what: what.to_string(),
            rows: n,
            cols: a.ncols(),
        });
    }
    if a.col_iter().any(|c| c.iter().any(|v| !v.is_finite())) {
        return Err(LinalgError::NonFiniteEntry {
            what: what.to_string(),
            n,
        });
    }
    let compute = if vectors {
        ComputeEigenvectors::Yes
    } else {
        ComputeEigenvectors::No
    };
    let mut s = faer::diag::Diag::<f64>::zeros(n);
    let mut u = vectors.then(|| Mat::<f64>::zeros(n, n));
    let mut mem = MemBuffer::new(self_adjoint_evd_scratch::<f64>(
        n,
        compute,
        Par::Seq,
        params().into(),
    ));
    self_adjoint_evd(
        a,
        s.as_mut(),
        u.as_mut().map(|u| u.as_mut()),
        Par::Seq,
        MemStack::new(&mut mem),
        params().into(),
    )
    .map_err(|error| LinalgError::EigenNotConverged {
        what: what.to_string(),
        n,
        error,
    })?;
    Ok((s.column_vector().iter().copied().collect(), u))
}

/// Eigenvalues and eigenvectors of the symmetric `a` (its lower triangle is read); `what` names
/// the matrix in errors.
///
/// # Errors
/// A non-square or non-finite matrix, or a QR iteration that does not converge.
pub fn symmetric_eigen(a: MatRef<'_, f64>, what: &str) -> Result<SymmetricEigen, LinalgError> {
    let (values, vectors) = decompose(a, true, what)?;
    Ok(SymmetricEigen {
        values,
        vectors: vectors.unwrap_or_else(|| Mat::zeros(0, 0)),
    })
}

/// Eigenvalues (ascending) of the symmetric `a` (lower triangle read).
///
/// # Errors
/// As [`symmetric_eigen`].
pub fn symmetric_eigenvalues(a: MatRef<'_, f64>, what: &str) -> Result<Vec<f64>, LinalgError> {
    Ok(decompose(a, false, what)?.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::Side;

    /// `Q diag(λ) Qᵀ`, Q orthogonal from a fixed pseudo-random matrix, λ: `n − big` values
    /// log-spaced over 1e4 … 1e12 and `big` values within 20 % of `top`.
    fn clustered(n: usize, big: usize, top: f64) -> (Mat<f64>, Vec<f64>) {
        let mut state: u64 = 7;
        let mut rnd = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut lambda: Vec<f64> = (0..n)
            .map(|i| {
                if i + big >= n {
                    top * (0.9 + 0.2 * rnd())
                } else {
                    1e4 * 10f64.powf(8.0 * i as f64 / (n - big) as f64)
                }
            })
            .collect();
        let q = Mat::from_fn(n, n, |_, _| rnd() - 0.5).qr().compute_Q();
        let a =
            &q * Mat::from_fn(n, n, |i, j| if i == j { lambda[i] } else { 0.0 }) * q.transpose();
        lambda.sort_by(f64::total_cmp);
        (
            Mat::from_fn(n, n, |i, j| 0.5 * (a[(i, j)] + a[(j, i)])),
            lambda,
        )
    }

    /// Largest off-diagonal of `Uᵀ A U` relative to the largest diagonal.
    fn off_diagonal(a: &Mat<f64>, u: MatRef<'_, f64>) -> f64 {
        let b = u.transpose() * a * u;
        let n = a.nrows();
        let diag = (0..n).map(|i| b[(i, i)].abs()).fold(0.0, f64::max);
        let off = (0..n)
            .flat_map(|i| (0..n).filter(move |&j| j != i).map(move |j| (i, j)))
            .map(|(i, j)| b[(i, j)].abs())
            .fold(0.0, f64::max);
        off / diag
    }

    #[test]
    fn clustered_spectrum_is_backward_stable() {
        let (a, lambda) = clustered(150, 60, 1e14);
        let evd = symmetric_eigen(a.as_ref(), "test").unwrap();
        assert!(off_diagonal(&a, evd.vectors.as_ref()) < 1e-14);
        for (got, want) in evd.values.iter().zip(&lambda) {
            // Absolute error eps·‖A‖ at most (backward stability).
            assert!((got - want).abs() < 1e-13 * 1.1e14, "{got:e} vs {want:e}");
        }
        assert!(
            (evd.values[0] - 1e4).abs() < 1.0,
            "lowest {:e}",
            evd.values[0]
        );
        let only = symmetric_eigenvalues(a.as_ref(), "test").unwrap();
        for (x, y) in only.iter().zip(&evd.values) {
            assert!((x - y).abs() <= 1e-13 * 1.1e14);
        }
    }

    /// The reason for the module: faer's default (divide and conquer from 128 on) on the same
    /// matrix. If a faer release fixes it this test fails, and the module docs need updating.
    #[test]
    fn faer_divide_and_conquer_fails_on_the_clustered_spectrum() {
        let (a, _) = clustered(150, 60, 1e14);
        let evd = a.self_adjoint_eigen(Side::Lower).unwrap();
        assert!(off_diagonal(&a, evd.U()) > 1e-8);
    }

    #[test]
    fn rejects_non_finite_and_non_square() {
        let mut a = Mat::<f64>::identity(3, 3);
        a[(1, 0)] = f64::NAN;
        let e = symmetric_eigen(a.as_ref(), "the Gram matrix").unwrap_err();
        assert!(
            matches!(&e, LinalgError::NonFiniteEntry { what, n: 3 } if what == "the Gram matrix"),
            "{e:?}"
        );
        assert_eq!(
            e.to_string(),
            "the Gram matrix: the 3×3 matrix has a non-finite entry"
        );
        let b = Mat::<f64>::zeros(2, 3);
        let e = symmetric_eigenvalues(b.as_ref(), "x").unwrap_err();
        assert!(
            matches!(
                e,
                LinalgError::NotSquare {
                    rows: 2,
                    cols: 3,
                    ..
                }
            ),
            "{e:?}"
        );
        assert!(e.to_string().contains("not square"));
    }
}
