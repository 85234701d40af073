//! Generalized symmetric eigenproblem `K φ = ω² M φ` for the lowest modes.
//!
//! [`lowest_modes`] uses faer's Krylov–Schur eigensolver (`faer::matrix_free::eigen`,
//! sequential, fixed start vector) on the inverse operator: with the sparse Cholesky
//! factorization `P K Pᵀ = L Lᵀ` (shared with Craig–Bampton through
//! `lowest_modes_factored`) the operator `C = L⁻¹ P M Pᵀ L⁻ᵀ` is symmetric positive definite
//! and its largest eigenvalues `μ = 1/ω²` belong to the lowest modes, `φ = Pᵀ L⁻ᵀ z`. The
//! converged vectors get one subspace-iteration step with Rayleigh–Ritz, every pair must meet
//! the true residual `‖C z − μ z‖ ≤ 1e-9 μ` (else a rerun with a tighter locking tolerance and a
//! larger search space), and every returned pair is checked against the backward error of
//! `K φ = ω² M φ`. The modes are M-orthonormal: `Φᵀ M Φ = I`, `Φᵀ K Φ = diag(ω²)`.
//!
//! [`dense_modes`] is the dense reference (Cholesky of M, symmetric eigensolver): O(n³), for
//! tests and small models.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::triangular_solve::{
    solve_lower_triangular_in_place, solve_upper_triangular_in_place,
};
use faer::matrix_free::eigen::{partial_eigen, partial_eigen_scratch, PartialEigenParams};
use faer::matrix_free::LinOp;
use faer::{c64, Col, ColRef, Mat, MatMut, MatRef, Par, Scale, Side};

use crate::linalg::cholesky::SparseCholesky;
use crate::linalg::sparse::sym_mul_mat;
use crate::linalg::symmetric_eigen;
use crate::linalg::LinalgError;
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

fn check_count(n: usize, count: usize) -> Result<(), LinalgError> {
    if count == 0 || count > n {
        return Err(LinalgError::ModeCount { count, dofs: n });
    }
    Ok(())
}

/// Deterministic pseudo-random start vector (SplitMix64 bits mapped to [−1, 1)).
fn start_vector(n: usize) -> Vec<f64> {
    let mut rng = super::random::SplitMix64::new(0);
    (0..n).map(|_| rng.next_signed()).collect()
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// The lowest `count` modes of `K φ = ω² M φ` (K and M symmetric positive definite).
pub fn lowest_modes(k: &SymCsc, m: &SymCsc, count: usize) -> Result<Modes, LinalgError> {
    let n = k.n;
    check_count(n, count)?;
    if n <= 64 || 3 * count > n {
        return dense_modes(k, m, count);
    }
    let chol = SparseCholesky::new(k).map_err(|e| LinalgError::EigenStiffness {
        source: Box::new(e),
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
) -> Result<Modes, LinalgError> {
    let n = k.n;
    check_count(n, count)?;
    if n <= 64 || 3 * count > n {
        return dense_modes(k, m, count);
    }
    let op = InverseOperator { chol, m };
    let start = start_vector(n);
    let v0 = Col::from_fn(n, |i| start[i]);
    // faer's locking tolerance is absolute; the wanted one is relative to the smallest
    // requested μ. Start from the Rayleigh quotient of the start vector; should the refined
    // pairs miss the residual bound, rerun with the tolerance of the computed μ_count and a
    // larger search space (same start vector: deterministic).
    let mut cv = Mat::<f64>::zeros(n, 1);
    op.apply(
        cv.as_mut(),
        v0.as_mat(),
        Par::Seq,
        MemStack::new(&mut MemBuffer::new(StackReq::EMPTY)),
    );
    let rq = (v0.transpose() * cv.col(0)) / (v0.transpose() * &v0);
    if !(rq.is_finite() && rq > 0.0) {
        return Err(LinalgError::RayleighQuotient { value: rq });
    }
    let mut tol = LOCK_TOL * rq;
    let mut max_dim = 2 * count + 20;
    let mut worst = f64::NAN;
    for _ in 0..3 {
        let z = krylov_schur(&op, v0.as_ref(), count, tol, max_dim)?;
        let (mu, z, residual) = refine(&op, z)?;
        if residual <= RESIDUAL_TOL {
            let modes = to_modes(chol, m, &mu, z)?;
            verify(k, m, &modes)?;
            return Ok(modes);
        }
        worst = residual;
        tol = LOCK_TOL * mu[count - 1];
        max_dim *= 2;
    }
    Err(LinalgError::KrylovSchurNotConverged {
        count,
        residual: worst,
        bound: RESIDUAL_TOL,
    })
}

/// Locking tolerance of the Krylov–Schur iteration relative to the smallest wanted μ.
const LOCK_TOL: f64 = 1e-10;

/// Bound on the true relative residual `‖C z − μ z‖ / μ` of every refined pair.
const RESIDUAL_TOL: f64 = 1e-9;

/// The symmetric operator `C = L⁻¹ P M Pᵀ L⁻ᵀ` for `P K Pᵀ = L Lᵀ`: `C z = μ z` with
/// `μ = 1/ω²` and `φ = Pᵀ L⁻ᵀ z`.
struct InverseOperator<'a> {
    chol: &'a SparseCholesky,
    m: &'a SymCsc,
}

impl std::fmt::Debug for InverseOperator<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("InverseOperator")
            .field("n", &self.m.n)
            .finish()
    }
}

impl LinOp<f64> for InverseOperator<'_> {
    fn apply_scratch(&self, _rhs_ncols: usize, _par: Par) -> StackReq {
        StackReq::EMPTY
    }

    fn nrows(&self) -> usize {
        self.m.n
    }

    fn ncols(&self) -> usize {
        self.m.n
    }

    fn apply(&self, mut out: MatMut<'_, f64>, rhs: MatRef<'_, f64>, _par: Par, _: &mut MemStack) {
        let mut w = rhs.to_owned();
        self.chol.half_solve_transpose(w.as_mut());
        let mut mw = sym_mul_mat(self.m, w.as_ref());
        self.chol.half_solve(mw.as_mut());
        out.copy_from(&mw);
    }

    fn conj_apply(
        &self,
        out: MatMut<'_, f64>,
        rhs: MatRef<'_, f64>,
        par: Par,
        stack: &mut MemStack,
    ) {
        self.apply(out, rhs, par, stack);
    }
}

/// faer's Krylov–Schur eigensolver (sequential) for the `count` largest μ: their vectors z.
///
/// faer's `partial_self_adjoint_eigen` (Lanczos) keeps only the tridiagonal coefficients, and
/// on these operators its residual estimates went below the tolerance while true residuals
/// stayed at 1e-6 (friction_bar, 60 modes); the Arnoldi variant `partial_eigen` keeps the whole
/// Hessenberg matrix and converges to the true residual. Its (real, up to round-off) vectors
/// are phase-aligned and taken real; [`refine`] restores symmetry.
fn krylov_schur(
    op: &InverseOperator<'_>,
    v0: ColRef<'_, f64>,
    count: usize,
    tol: f64,
    max_dim: usize,
) -> Result<Mat<f64>, LinalgError> {
    let n = op.m.n;
    // faer needs max_dim < n; the callers keep 3 count ≤ n and n > 64.
    let params = PartialEigenParams {
        max_dim: max_dim.clamp(64, n - 1),
        ..Default::default()
    };
    let mut zc = Mat::<c64>::zeros(n, count);
    let mut muc = vec![c64::new(0.0, 0.0); count];
    let scratch = partial_eigen_scratch(op, count, Par::Seq, params);
    let info = partial_eigen(
        zc.as_mut(),
        &mut muc,
        op,
        v0,
        tol,
        Par::Seq,
        MemStack::new(&mut MemBuffer::new(scratch)),
        params,
    );
    if info.n_converged_eigen < count {
        return Err(LinalgError::KrylovSchurIncomplete {
            converged: info.n_converged_eigen,
            count,
            restarts: params.max_restarts,
        });
    }
    let mut z = Mat::<f64>::zeros(n, count);
    for (j, col) in zc.col_iter().enumerate() {
        // Rotate the largest entry onto the positive real axis.
        let mut big = c64::new(0.0, 0.0);
        for v in col.iter() {
            if v.norm() > big.norm() {
                big = *v;
            }
        }
        let phase = if big.norm() > 0.0 {
            (big / big.norm()).conj()
        } else {
            c64::new(1.0, 0.0)
        };
        for (i, v) in col.iter().enumerate() {
            z[(i, j)] = (*v * phase).re;
        }
    }
    Ok(z)
}

/// Rayleigh–Ritz on one subspace-iteration step: `W = C Z` is orthonormalised (Q) and the
/// pairs of the symmetric `Qᵀ C Q` are the refined ones (largest μ first), orthonormal to
/// round-off. Also returns the largest true relative residual `‖C z − μ z‖ / μ`.
fn refine(op: &InverseOperator<'_>, z: Mat<f64>) -> Result<(Vec<f64>, Mat<f64>, f64), LinalgError> {
    let (n, count) = z.shape();
    let stack = &mut MemBuffer::new(StackReq::EMPTY);
    let mut w = Mat::<f64>::zeros(n, count);
    op.apply(w.as_mut(), z.as_ref(), Par::Seq, MemStack::new(stack));
    let q = w.qr().compute_thin_Q();
    op.apply(w.as_mut(), q.as_ref(), Par::Seq, MemStack::new(stack));
    let g = q.transpose() * &w;
    let g = Mat::from_fn(count, count, |i, j| 0.5 * (g[(i, j)] + g[(j, i)]));
    let evd = symmetric_eigen(g.as_ref(), "Rayleigh–Ritz")?;
    let s = &evd.values;
    let mu: Vec<f64> = (0..count).map(|c| s[count - 1 - c]).collect();
    if let Some(&bad) = mu.iter().find(|&&v| !(v.is_finite() && v > 0.0)) {
        return Err(LinalgError::RitzValue { value: bad });
    }
    let u = Mat::from_fn(count, count, |i, c| evd.vectors[(i, count - 1 - c)]);
    let z = &q * &u;
    let cz = &w * &u;
    let residual = (0..count)
        .map(|c| (cz.col(c) - Scale(mu[c]) * z.col(c)).norm_l2() / mu[c])
        .fold(0.0, f64::max);
    Ok((mu, z, residual))
}

/// `φ = Pᵀ L⁻ᵀ z`, scaled to `φᵀ M φ = 1`; `ω² = 1/μ`.
fn to_modes(
    chol: &SparseCholesky,
    m: &SymCsc,
    mu: &[f64],
    mut z: Mat<f64>,
) -> Result<Modes, LinalgError> {
    chol.half_solve_transpose(z.as_mut());
    // M z for every column at once (blocked): each entry the same sum as a product per column.
    let mz = sym_mul_mat(m, z.as_ref());
    for c in 0..z.ncols() {
        let norm = dot(z.col_as_slice(c), mz.col_as_slice(c)).sqrt();
        if !(norm.is_finite() && norm > 0.0) {
            return Err(LinalgError::Indefinite {
                what: "mass matrix".to_string(),
                hint: " (mode M-norm vanished)",
            });
        }
        let inv = 1.0 / norm;
        z.col_mut(c).iter_mut().for_each(|v| *v *= inv);
    }
    Ok(Modes::from_pairs(mu.iter().map(|&v| 1.0 / v).collect(), z))
}

/// Checks the normwise backward error of every pair,
/// `‖K φ − ω² M φ‖∞ / ((‖K‖∞ + ω² ‖M‖∞) ‖φ‖∞) ≤ 1e-10`.
fn verify(k: &SymCsc, m: &SymCsc, modes: &Modes) -> Result<(), LinalgError> {
    let (kn, mn) = (k.inf_norm(), m.inf_norm());
    // K Φ and M Φ blocked (the matrices read once per 16 modes, not twice per mode).
    let k_phi = sym_mul_mat(k, modes.shapes.as_ref());
    let m_phi = sym_mul_mat(m, modes.shapes.as_ref());
    for (c, &lam) in modes.eigenvalues.iter().enumerate() {
        let phi = modes.shapes.col_as_slice(c);
        let (kphi, mphi) = (k_phi.col_as_slice(c), m_phi.col_as_slice(c));
        let res = kphi
            .iter()
            .zip(mphi)
            .map(|(a, b)| (a - lam * b).abs())
            .fold(0.0, f64::max);
        let phi_norm = phi.iter().map(|v| v.abs()).fold(0.0, f64::max);
        let backward = res / ((kn + lam * mn) * phi_norm);
        if backward.is_nan() || backward > 1e-10 {
            return Err(LinalgError::ModeBackwardError {
                mode: c + 1,
                frequency_hz: modes.frequencies_hz[c],
                backward,
            });
        }
    }
    Ok(())
}

/// Dense reference solver in the inverse form that keeps the lowest modes accurate:
/// `K = L Lᵀ`, `L⁻¹ M L⁻ᵀ y = μ y` with `μ = 1/ω²` (the largest μ are the lowest modes),
/// `φ = L⁻ᵀ y / sqrt(μ)` (M-normalised). Factoring M instead would mix the drilling and
/// membrane eigenvalues (~1e16) into the low ones and lose them to round-off.
pub fn dense_modes(k: &SymCsc, m: &SymCsc, count: usize) -> Result<Modes, LinalgError> {
    let n = k.n;
    check_count(n, count)?;
    let kd = k.to_dense();
    let llt = kd
        .llt(Side::Lower)
        .map_err(|e| LinalgError::NotPositiveDefinite {
            what: "stiffness matrix".to_string(),
            hint: " (is the structure supported?)",
            source: Box::new(e),
        })?;
    let l = llt.L();
    let mut c = m.to_dense();
    // C = L⁻¹ M L⁻ᵀ: solve L X = M, then L Cᵀ = Xᵀ.
    solve_lower_triangular_in_place(l, c.as_mut(), Par::Seq);
    let mut ct = c.transpose().to_owned();
    solve_lower_triangular_in_place(l, ct.as_mut(), Par::Seq);
    let sym = Mat::from_fn(n, n, |i, j| 0.5 * (ct[(i, j)] + ct[(j, i)]));
    let evd = symmetric_eigen(sym.as_ref(), "dense modes")?;
    let s = &evd.values;
    let mut eigenvalues = Vec::with_capacity(count);
    let mut shapes = Mat::<f64>::zeros(n, count);
    for c in 0..count {
        let idx = n - 1 - c;
        let mu = s[idx];
        if mu <= 0.0 {
            return Err(LinalgError::Indefinite {
                what: "mass matrix".to_string(),
                hint: "",
            });
        }
        eigenvalues.push(1.0 / mu);
        let inv = 1.0 / mu.sqrt();
        for i in 0..n {
            shapes[(i, c)] = evd.vectors[(i, idx)] * inv;
        }
    }
    solve_upper_triangular_in_place(l.transpose(), shapes.as_mut(), Par::Seq);
    Ok(Modes::from_pairs(eigenvalues, shapes))
}
