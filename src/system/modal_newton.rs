//! The Newton matrix of a reduced model in its own eigenbasis, factored as a diagonal plus a
//! low-rank joint term.
//!
//! A basis rotated to the reduced eigenbasis (`M̃ = I`, `K̃ = Ω² = diag(ω_i²)`) makes the
//! structural part of the Newton matrix diagonal, `D = I + γ² Ω²`, and leaves one coupling: the
//! joint's tangent over the pairs with a non-zero block,
//!
//! ```text
//!   N = D + γ² (BΦ)_aᵀ K_c (BΦ)_a = D + Ãᵀ Ã,   Ã = γ Λ^{1/2} Vᵀ (BΦ)_a,
//! ```
//!
//! with each pair's symmetric 3 × 3 block `K_c,z = V Λ Vᵀ` (positive semi-definite: a stuck pair
//! `diag(k_n, k_t, k_t)`, a sliding one its normal and the slip law's tangent). Ã has one row
//! per positive eigenvalue, `p ≤ 3a` rows for a pairs, and by Woodbury
//!
//! ```text
//!   N⁻¹ x = D⁻¹ x − D⁻¹ Ãᵀ S⁻¹ Ã D⁻¹ x,   S = I + Ã D⁻¹ Ãᵀ   (p × p, eigenvalues ≥ 1),
//! ```
//!
//! so a setup costs `p² r / 2` (forming S) and `p³ / 3` (its Cholesky) instead of the dense
//! `r² · 3a + r³ / 3`, and a solve `2 p r + p²` instead of `2 r²`. S is at least as well
//! conditioned as N relative to D (its eigenvalues are 1 + those of `D^{-1/2} Ãᵀ Ã D^{-1/2}`).
//! A ring-down about a pressed joint has a few tens of closed pairs against a basis of hundreds
//! of columns that carries every pair's attachment modes: the setups, which a slipping joint
//! repeats at every stick–slip switch, then cost a few percent of the dense ones.
//!
//! The factor applies only where it is the dense factorization to its own rounding: `M̃` the
//! identity and `K̃`'s off-diagonal entries below `r · ε` of its largest diagonal entry (a
//! dense Cholesky of N has a backward error of that size), every block positive semi-definite
//! and `p` at most half of r (beyond that the dense factor is cheaper). Otherwise the caller
//! factors N densely, as for any basis. Only the Newton matrix drops those off-diagonal
//! entries: the right-hand side keeps the dense `K̃ q`, so the model the integrator solves is
//! unchanged and the Newton iteration converges to the same solution.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::{
    cholesky_in_place, cholesky_in_place_scratch, LltRegularization,
};
use faer::linalg::cholesky::llt::solve::solve_in_place_with_conj;
use faer::linalg::matmul::matmul;
use faer::{Accum, Conj, Mat, MatMut, Par};

/// Rows of Ã beyond this fraction of r: the dense factor is cheaper.
const MAX_RANK_FRACTION: f64 = 0.5;

/// The diagonal-plus-low-rank Newton factor of a reduced model in its eigenbasis (module
/// docs). Scratch for up to 3w rows.
pub(super) struct ModalNewton {
    /// `K̃`'s diagonal `ω_i²` (N/mm per unit coordinate²).
    omega2: Vec<f64>,
    /// `D⁻¹ = (1 + γ² ω_i²)⁻¹` of the last setup.
    d_inv: Vec<f64>,
    /// Ã (p rows of r; scratch of 3w rows), and `Ã D⁻¹` beside it.
    a: Mat<f64>,
    ad: Mat<f64>,
    /// The Cholesky factor of S (p × p in the leading block).
    s: Mat<f64>,
    p: usize,
    /// Scratch of the solve (p values) and of the Cholesky.
    t: Vec<f64>,
    mem: MemBuffer,
}

/// The modal factor's `K̃` diagonal when `k` is diagonal to the dense factorization's rounding
/// (module docs) and `m_identity`; `None` otherwise.
pub(super) fn modal_diagonal(k: &Mat<f64>, m_identity: bool) -> Option<Vec<f64>> {
    let r = k.nrows();
    if !m_identity || r == 0 {
        return None;
    }
    let diag: Vec<f64> = (0..r).map(|i| k[(i, i)]).collect();
    let top = diag.iter().fold(0.0f64, |a, &b| a.max(b.abs()));
    if diag.iter().any(|d| d.is_nan() || *d < 0.0) {
        return None;
    }
    let bound = r as f64 * f64::EPSILON * top;
    for j in 0..r {
        for i in 0..r {
            if i != j && k[(i, j)].abs() > bound {
                return None;
            }
        }
    }
    Some(diag)
}

/// Eigenvalues and eigenvectors (columns of the returned row-major 3 × 3) of a symmetric 3 × 3
/// `a` (row-major), by cyclic Jacobi rotations.
fn sym3_eigen(a: &[f64]) -> ([f64; 3], [f64; 9]) {
    let mut m = [0.0; 9];
    m.copy_from_slice(&a[..9]);
    for i in 0..3 {
        for j in 0..i {
            let s = 0.5 * (m[3 * i + j] + m[3 * j + i]);
            m[3 * i + j] = s;
            m[3 * j + i] = s;
        }
    }
    let mut v = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0];
    let scale = m.iter().fold(0.0f64, |s, x| s.max(x.abs()));
    for _ in 0..32 {
        let off = m[1].abs() + m[2].abs() + m[5].abs();
        if off <= 1e-17 * scale {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            let apq = m[3 * p + q];
            if apq == 0.0 {
                continue;
            }
            let theta = (m[3 * q + q] - m[3 * p + p]) / (2.0 * apq);
            let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
            let t = if theta == 0.0 { 1.0 } else { t };
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            for k in 0..3 {
                let (mkp, mkq) = (m[3 * k + p], m[3 * k + q]);
                m[3 * k + p] = c * mkp - s * mkq;
                m[3 * k + q] = s * mkp + c * mkq;
            }
            for k in 0..3 {
                let (mpk, mqk) = (m[3 * p + k], m[3 * q + k]);
                m[3 * p + k] = c * mpk - s * mqk;
                m[3 * q + k] = s * mpk + c * mqk;
            }
            for k in 0..3 {
                let (vkp, vkq) = (v[3 * k + p], v[3 * k + q]);
                v[3 * k + p] = c * vkp - s * vkq;
                v[3 * k + q] = s * vkp + c * vkq;
            }
        }
    }
    ([m[0], m[4], m[8]], v)
}

impl ModalNewton {
    /// The factor for `K̃ = diag(omega2)` and `rows` joint rows (3w).
    pub(super) fn new(omega2: Vec<f64>, rows: usize) -> ModalNewton {
        let r = omega2.len();
        let p_max = rows.min(r);
        ModalNewton {
            d_inv: vec![0.0; r],
            a: Mat::zeros(p_max, r),
            ad: Mat::zeros(p_max, r),
            s: Mat::zeros(p_max, p_max),
            p: 0,
            t: vec![0.0; p_max],
            mem: MemBuffer::new(cholesky_in_place_scratch::<f64>(
                p_max,
                Par::Seq,
                Default::default(),
            )),
            omega2,
        }
    }

    /// Sets up `N = D + Ãᵀ Ã` at `gamma` with the pair blocks `kc` (row-major 3 × 3 per pair,
    /// N/mm) and `BΦ` row by row (`b_rows`, 3w × r). `false` if the factor does not apply
    /// (module docs: a block not semi-definite, too many rows, S not positive definite): the
    /// caller then factors densely.
    pub(super) fn factor(&mut self, gamma: f64, kc: &[f64], b_rows: &[f64]) -> bool {
        let r = self.omega2.len();
        let g2 = gamma * gamma;
        for (d, w2) in self.d_inv.iter_mut().zip(&self.omega2) {
            *d = 1.0 / (1.0 + g2 * w2);
        }
        let p_cap = ((MAX_RANK_FRACTION * r as f64) as usize).min(self.a.nrows());
        let mut p = 0;
        for (z, block) in kc.chunks_exact(9).enumerate() {
            if block.iter().all(|&x| x == 0.0) {
                continue;
            }
            let (lambda, v) = sym3_eigen(block);
            let top = lambda.iter().fold(0.0f64, |a, &b| a.max(b.abs()));
            for (e, &l) in lambda.iter().enumerate() {
                if l < -1e-12 * top {
                    return false;
                }
                if l <= 1e-12 * top {
                    continue;
                }
                if p == p_cap {
                    return false;
                }
                let w = gamma * l.sqrt();
                let coef = [w * v[e], w * v[3 + e], w * v[6 + e]];
                let rows = &b_rows[3 * z * r..(3 * z + 3) * r];
                for c in 0..r {
                    let x = coef[0] * rows[c] + coef[1] * rows[r + c] + coef[2] * rows[2 * r + c];
                    self.a[(p, c)] = x;
                    self.ad[(p, c)] = x * self.d_inv[c];
                }
                p += 1;
            }
        }
        self.p = p;
        if p == 0 {
            return true;
        }
        let mut s = self.s.as_mut().submatrix_mut(0, 0, p, p);
        s.fill(0.0);
        for i in 0..p {
            s[(i, i)] = 1.0;
        }
        matmul(
            s.as_mut(),
            Accum::Add,
            self.a.as_ref().subrows(0, p),
            self.ad.as_ref().subrows(0, p).transpose(),
            1.0,
            Par::Seq,
        );
        cholesky_in_place(
            s,
            LltRegularization::default(),
            Par::Seq,
            MemStack::new(&mut self.mem),
            Default::default(),
        )
        .is_ok()
    }

    /// `x ← N⁻¹ x` with the last setup's factor.
    pub(super) fn solve_in_place(&mut self, x: &mut [f64]) {
        let p = self.p;
        for (xi, d) in x.iter_mut().zip(&self.d_inv) {
            *xi *= d;
        }
        if p == 0 {
            return;
        }
        let t = &mut self.t[..p];
        for (i, ti) in t.iter_mut().enumerate() {
            *ti = self.a.row(i).iter().zip(x.iter()).map(|(a, b)| a * b).sum();
        }
        solve_in_place_with_conj(
            self.s.as_ref().submatrix(0, 0, p, p),
            Conj::No,
            MatMut::from_column_major_slice_mut(t, p, 1),
            Par::Seq,
            MemStack::new(&mut self.mem),
        );
        for (i, &ti) in t.iter().enumerate() {
            for (xc, adc) in x.iter_mut().zip(self.ad.row(i).iter()) {
                *xc -= ti * adc;
            }
        }
    }
}

impl Clone for ModalNewton {
    fn clone(&self) -> ModalNewton {
        ModalNewton::new(self.omega2.clone(), self.a.nrows())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn jacobi_diagonalizes_a_symmetric_block() {
        let a = [4.0, 1.0, -2.0, 1.0, 3.0, 0.5, -2.0, 0.5, 1.0];
        let (l, v) = sym3_eigen(&a);
        for e in 0..3 {
            for i in 0..3 {
                let av: f64 = (0..3).map(|k| a[3 * i + k] * v[3 * k + e]).sum();
                assert!((av - l[e] * v[3 * i + e]).abs() < 1e-13, "{e} {i}");
            }
        }
    }

    #[test]
    fn woodbury_solve_equals_the_dense_newton_matrix() {
        // r = 12, two pairs (6 rows): one stuck (diagonal), one sliding (full symmetric PSD).
        let r = 12;
        let omega2: Vec<f64> = (0..r).map(|i| 10.0 * (i as f64 + 1.0).powi(3)).collect();
        let b = Mat::from_fn(6, r, |i, j| ((i * 7 + j * 3) % 11) as f64 / 5.0 - 1.0);
        let b_rows: Vec<f64> = (0..6)
            .flat_map(|i| (0..r).map(move |j| (i, j)))
            .map(|(i, j)| b[(i, j)])
            .collect();
        let slide = {
            // u uᵀ + 0.5 w wᵀ: symmetric, rank 2.
            let u = [1.0, 0.3, -0.2];
            let w = [0.0, 1.0, 0.4];
            let mut c = [0.0; 9];
            for i in 0..3 {
                for j in 0..3 {
                    c[3 * i + j] = 30.0 * u[i] * u[j] + 15.0 * w[i] * w[j];
                }
            }
            c
        };
        let mut kc = vec![50.0, 0.0, 0.0, 0.0, 20.0, 0.0, 0.0, 0.0, 20.0];
        kc.extend_from_slice(&slide);
        let gamma = 0.07;
        let mut f = ModalNewton::new(omega2.clone(), 6);
        assert!(f.factor(gamma, &kc, &b_rows));
        let dense = Mat::from_fn(r, r, |i, j| {
            let mut x = if i == j {
                1.0 + gamma * gamma * omega2[i]
            } else {
                0.0
            };
            for z in 0..2 {
                for a in 0..3 {
                    for c in 0..3 {
                        x += gamma
                            * gamma
                            * b[(3 * z + a, i)]
                            * kc[9 * z + 3 * a + c]
                            * b[(3 * z + c, j)];
                    }
                }
            }
            x
        });
        let rhs: Vec<f64> = (0..r).map(|i| (i as f64 - 2.5) * 0.3).collect();
        let mut x = rhs.clone();
        f.solve_in_place(&mut x);
        for i in 0..r {
            let nx: f64 = (0..r).map(|j| dense[(i, j)] * x[j]).sum();
            assert!((nx - rhs[i]).abs() < 1e-12, "{i}: {nx} vs {}", rhs[i]);
        }
    }
}
