//! Generalized symmetric eigenproblem `K φ = ω² M φ` for the lowest modes.
//!
//! [`lowest_modes`] uses shift-invert Lanczos in the M-inner product: with one sparse Cholesky
//! factorization of `K − σM` the operator `S = (K − σM)⁻¹ M` is self-adjoint in `⟨x, y⟩_M`,
//! and its largest eigenvalues `θ = 1 / (ω² − σ)` belong to the lowest modes. The Lanczos basis
//! `Q` is kept M-orthonormal by full reorthogonalization (twice, "twice is enough"), the
//! projected tridiagonal matrix is solved densely, and a Ritz pair is accepted when its
//! residual bound `|β_m y_m| / θ` is below 1e-10; the Krylov space grows until all requested
//! pairs converge. Every returned pair is then checked against the true residual
//! `‖K φ − ω² M φ‖ / ‖K φ‖`. The modes are M-orthonormal: `Φᵀ M Φ = I`, `Φᵀ K Φ = diag(ω²)`.
//!
//! [`dense_modes`] is the dense reference (Cholesky of M, symmetric eigensolver): O(n³), for
//! tests and small models.

use faer::linalg::triangular_solve::{
    solve_lower_triangular_in_place, solve_upper_triangular_in_place,
};
use faer::{Mat, Par, Side};

use crate::error::Error;
use crate::linalg::cholesky::SparseCholesky;
use crate::linalg::sparse::sym_mul_vec_into;
use crate::linalg::SymCsc;

/// Eigenmodes, lowest first.
#[derive(Clone, Debug)]
pub struct Modes {
    /// Eigenvalues ω², (rad/s)².
    pub eigenvalues: Vec<f64>,
    /// Frequencies f = ω / 2π, Hz.
    pub frequencies_hz: Vec<f64>,
    /// Mode shapes as columns (n × count), M-orthonormal.
    pub shapes: Mat<f64>,
}

impl Modes {
    fn from_pairs(eigenvalues: Vec<f64>, shapes: Mat<f64>) -> Modes {
        let frequencies_hz = eigenvalues
            .iter()
            .map(|&l| l.max(0.0).sqrt() / (2.0 * std::f64::consts::PI))
            .collect();
        Modes {
            eigenvalues,
            frequencies_hz,
            shapes,
        }
    }
}

fn check_count(n: usize, count: usize) -> Result<(), Error> {
    if count == 0 || count > n {
        return Err(Error::Invalid(format!(
            "cannot compute {count} modes of a model with {n} DOF (need 1 ≤ count ≤ {n})"
        )));
    }
    Ok(())
}

/// Deterministic pseudo-random start vector (SplitMix64 bits mapped to [−1, 1)).
fn start_vector(n: usize) -> Vec<f64> {
    let mut state: u64 = 0x9E37_79B9_7F4A_7C15;
    (0..n)
        .map(|_| {
            state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = state;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^= z >> 31;
            (z >> 11) as f64 / (1u64 << 52) as f64 - 1.0
        })
        .collect()
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// The lowest `count` modes of `K φ = ω² M φ` (K and M symmetric positive definite).
pub fn lowest_modes(k: &SymCsc, m: &SymCsc, count: usize) -> Result<Modes, Error> {
    let n = k.n;
    check_count(n, count)?;
    if n <= 64 || 3 * count > n {
        return dense_modes(k, m, count);
    }
    let chol = SparseCholesky::new(k).map_err(|e| {
        Error::LinearAlgebra(format!(
            "eigenproblem: K must be positive definite (is the structure supported?): {e}"
        ))
    })?;
    lowest_modes_factored(k, m, &chol, count)
}

/// [`lowest_modes`] with the Cholesky factorization of K given (e.g. shared with the
/// Craig–Bampton constraint modes); small problems still go to [`dense_modes`].
pub(crate) fn lowest_modes_factored(
    k: &SymCsc,
    m: &SymCsc,
    chol: &SparseCholesky,
    count: usize,
) -> Result<Modes, Error> {
    let n = k.n;
    check_count(n, count)?;
    if n <= 64 || 3 * count > n {
        return dense_modes(k, m, count);
    }
    let mut steps = (2 * count + 20).max(40).min(n);
    loop {
        match lanczos(chol, m, count, steps)? {
            Some(modes) => {
                verify(k, m, &modes)?;
                return Ok(modes);
            }
            None if steps == n => {
                return Err(Error::LinearAlgebra(format!(
                    "Lanczos did not converge {count} modes in {n} steps"
                )))
            }
            None => steps = (2 * steps).min(n),
        }
    }
}

/// One Lanczos run of `steps` steps; `None` if not all `count` pairs converged.
fn lanczos(
    chol: &SparseCholesky,
    m: &SymCsc,
    count: usize,
    steps: usize,
) -> Result<Option<Modes>, Error> {
    let n = m.n;
    let mut q = Mat::<f64>::zeros(n, steps);
    let mut mq = Mat::<f64>::zeros(n, steps);
    let mut alpha = vec![0.0; steps];
    let mut beta = vec![0.0; steps];
    let mut w = start_vector(n);
    let mut mw = vec![0.0; n];
    let mut rhs = Mat::<f64>::zeros(n, 1);
    let mut restarts = 0u64;
    let mut j = 0;
    // Normalise the start vector in the M-norm.
    sym_mul_vec_into(m, &w, &mut mw);
    let mut norm = dot(&w, &mw).sqrt();
    while j < steps {
        if !(norm.is_finite() && norm > 0.0) {
            return Err(Error::LinearAlgebra(
                "mass matrix is not positive definite (Lanczos M-norm vanished)".into(),
            ));
        }
        for i in 0..n {
            q[(i, j)] = w[i] / norm;
            mq[(i, j)] = mw[i] / norm;
        }
        // w = S q_j = K⁻¹ M q_j
        for i in 0..n {
            rhs[(i, 0)] = mq[(i, j)];
        }
        chol.solve_in_place(&mut rhs);
        for i in 0..n {
            w[i] = rhs[(i, 0)];
        }
        alpha[j] = dot(mq.col_as_slice(j), &w);
        // Full reorthogonalization against all previous vectors, twice.
        for _ in 0..2 {
            for p in 0..=j {
                let c = dot(mq.col_as_slice(p), &w);
                let qp = q.col_as_slice(p);
                for i in 0..n {
                    w[i] -= c * qp[i];
                }
            }
        }
        sym_mul_vec_into(m, &w, &mut mw);
        norm = dot(&w, &mw).sqrt();
        if j + 1 < steps {
            beta[j] = norm;
            let qnorm = dot(q.col_as_slice(j), mq.col_as_slice(j)).sqrt();
            if norm <= 1e-12 * alpha[j].abs().max(f64::MIN_POSITIVE) * qnorm {
                // Invariant subspace found: continue with a fresh direction.
                beta[j] = 0.0;
                restarts += 1;
                let fresh = start_vector(n + restarts as usize);
                w.copy_from_slice(&fresh[restarts as usize..]);
                for _ in 0..2 {
                    sym_mul_vec_into(m, &w, &mut mw);
                    for p in 0..=j {
                        let c = dot(mq.col_as_slice(p), &w);
                        let qp = q.col_as_slice(p);
                        for i in 0..n {
                            w[i] -= c * qp[i];
                        }
                    }
                }
                sym_mul_vec_into(m, &w, &mut mw);
                norm = dot(&w, &mw).sqrt();
            }
        } else {
            beta[j] = norm;
        }
        j += 1;
    }
    // Projected tridiagonal T (steps × steps).
    let t = Mat::from_fn(steps, steps, |a, b| {
        if a == b {
            alpha[a]
        } else if a + 1 == b {
            beta[a]
        } else if b + 1 == a {
            beta[b]
        } else {
            0.0
        }
    });
    let evd = t
        .self_adjoint_eigen(Side::Lower)
        .map_err(|e| Error::LinearAlgebra(format!("tridiagonal eigensolver: {e:?}")))?;
    let theta = evd.S().column_vector();
    let y = evd.U();
    // Largest θ first.
    let last_beta = beta[steps - 1];
    let mut eigenvalues = Vec::with_capacity(count);
    let mut shapes = Mat::<f64>::zeros(n, count);
    for c in 0..count {
        let idx = steps - 1 - c;
        let th = theta[idx];
        if th <= 0.0 {
            return Err(Error::LinearAlgebra(format!(
                "non-positive Ritz value {th:e}: K or M is not positive definite"
            )));
        }
        let bound = (last_beta * y[(steps - 1, idx)]).abs() / th;
        if steps < n && bound > 1e-10 {
            return Ok(None);
        }
        eigenvalues.push(1.0 / th);
        let mut col = shapes.col_mut(c);
        for p in 0..steps {
            let yp = y[(p, idx)];
            let qp = q.col(p);
            col += yp * qp;
        }
    }
    Ok(Some(Modes::from_pairs(eigenvalues, shapes)))
}

/// Checks the normwise backward error of every pair,
/// `‖K φ − ω² M φ‖∞ / ((‖K‖∞ + ω² ‖M‖∞) ‖φ‖∞) ≤ 1e-10`.
fn verify(k: &SymCsc, m: &SymCsc, modes: &Modes) -> Result<(), Error> {
    let n = k.n;
    let (kn, mn) = (k.inf_norm(), m.inf_norm());
    let mut kphi = vec![0.0; n];
    let mut mphi = vec![0.0; n];
    for (c, &lam) in modes.eigenvalues.iter().enumerate() {
        let phi = modes.shapes.col_as_slice(c);
        sym_mul_vec_into(k, phi, &mut kphi);
        sym_mul_vec_into(m, phi, &mut mphi);
        let res = kphi
            .iter()
            .zip(&mphi)
            .map(|(a, b)| (a - lam * b).abs())
            .fold(0.0, f64::max);
        let phi_norm = phi.iter().map(|v| v.abs()).fold(0.0, f64::max);
        let backward = res / ((kn + lam * mn) * phi_norm);
        if backward.is_nan() || backward > 1e-10 {
            return Err(Error::LinearAlgebra(format!(
                "mode {} ({:.4} Hz) has backward error {:.2e} > 1e-10",
                c + 1,
                modes.frequencies_hz[c],
                backward
            )));
        }
    }
    Ok(())
}

/// Dense reference solver in the inverse form that keeps the lowest modes accurate:
/// `K = L Lᵀ`, `L⁻¹ M L⁻ᵀ y = μ y` with `μ = 1/ω²` (the largest μ are the lowest modes),
/// `φ = L⁻ᵀ y / sqrt(μ)` (M-normalised). Factoring M instead would mix the drilling and
/// membrane eigenvalues (~1e16) into the low ones and lose them to round-off.
pub fn dense_modes(k: &SymCsc, m: &SymCsc, count: usize) -> Result<Modes, Error> {
    let n = k.n;
    check_count(n, count)?;
    let kd = k.to_dense();
    let llt = kd.llt(Side::Lower).map_err(|e| {
        Error::LinearAlgebra(format!(
            "stiffness matrix is not positive definite (is the structure supported?): {e:?}"
        ))
    })?;
    let l = llt.L();
    let mut c = m.to_dense();
    // C = L⁻¹ M L⁻ᵀ: solve L X = M, then L Cᵀ = Xᵀ.
    solve_lower_triangular_in_place(l, c.as_mut(), Par::Seq);
    let mut ct = c.transpose().to_owned();
    solve_lower_triangular_in_place(l, ct.as_mut(), Par::Seq);
    let sym = Mat::from_fn(n, n, |i, j| 0.5 * (ct[(i, j)] + ct[(j, i)]));
    let evd = sym
        .self_adjoint_eigen(Side::Lower)
        .map_err(|e| Error::LinearAlgebra(format!("dense eigensolver: {e:?}")))?;
    let s = evd.S().column_vector();
    let mut eigenvalues = Vec::with_capacity(count);
    let mut shapes = Mat::<f64>::zeros(n, count);
    for c in 0..count {
        let idx = n - 1 - c;
        let mu = s[idx];
        if mu <= 0.0 {
            return Err(Error::LinearAlgebra(
                "mass matrix is not positive definite".into(),
            ));
        }
        eigenvalues.push(1.0 / mu);
        let inv = 1.0 / mu.sqrt();
        for i in 0..n {
            shapes[(i, c)] = evd.U()[(i, idx)] * inv;
        }
    }
    solve_upper_triangular_in_place(l.transpose(), shapes.as_mut(), Par::Seq);
    Ok(Modes::from_pairs(eigenvalues, shapes))
}
