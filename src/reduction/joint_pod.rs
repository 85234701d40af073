//! The POD of the joint's deformation patterns, computed in the space of the joint pairs.
//!
//! An error-controlled basis holds one attachment mode `z_k = K⁻¹ b_kᵀ` per chosen pair k
//! ([`crate::rom::tolerance`]), so its size follows the number of pairs the joint needs, not the
//! number of ways the joint deforms. The deformation the pair forces cause is, at an output t,
//! `x_J(t) = Z_S p_S(t)` (`Z_S = K⁻¹ B_Sᵀ`, n × c, and `p_S` the forces of the chosen pairs): the
//! snapshots `X = Z_S P` (P: c × m, one column per output). Their K-weighted POD — the modes that
//! hold the most strain energy of the snapshots, as the TVD's POD ranks its vectors
//! ([`super::pod()`], eq. 25) — needs no n-size work, because every product it needs is in the pair
//! space:
//!
//! ```text
//! Xᵀ K X = Pᵀ Z_Sᵀ K Z_S P = Pᵀ G P ,    G = B_S K⁻¹ B_Sᵀ   (c × c, mm/N)
//! ```
//!
//! With `L = G^{1/2}` (symmetric) and `Y = L P`, `Xᵀ K X = Yᵀ Y`, so the POD's energies are the
//! eigenvalues `σ_j²` of `Y Yᵀ = L (P Pᵀ) L` (c × c, whatever the number of outputs m) with
//! eigenvectors `v_j`; the snapshot-space vectors are `a_j = Yᵀ v_j / σ_j` and the modes
//!
//! ```text
//! u_j = X a_j / σ_j = Z_S c_j ,    c_j = (P Pᵀ) L v_j / σ_j²
//! ```
//!
//! — combinations of the attachment modes already solved, K-orthonormal (`c_iᵀ G c_j = δ_ij`).
//! The energy left out by the first k modes is `Σ_{j>k} σ_j²`, the squared K-norm of the
//! snapshots' part outside their span ([`JointPod::rank_for`]).
//!
//! `G` may be any positive semidefinite pair-space Gram of the columns: the tolerance model uses
//! the part of `G` that the Craig–Bampton basis does not already hold,
//! `G − (B_S Φ_CB) K̃_CB⁻¹ (B_S Φ_CB)ᵀ` (`K̃_CB = Φ_CBᵀ K Φ_CB`): the energy of the snapshots
//! beyond the K-orthogonal projection on Φ_CB, which is what the compressed columns must add.

use faer::{Mat, MatRef};

use crate::error::Error;
use crate::linalg::symmetric_eigen;

/// Energies below this fraction of the largest are numerically zero: their modes are not formed
/// (the K-norm of a mode with `σ_j² ≈ 0` is round-off).
pub const JOINT_POD_ZERO: f64 = 1e-14;

/// The pair-space POD of the snapshots `Z P` (module docs).
#[derive(Clone, Debug)]
pub struct JointPod {
    /// The energies `σ_j²` of the modes, descending (N·mm when `G` is in mm/N and `P` in N).
    pub energies: Vec<f64>,
    /// The total energy of the snapshots `Σ_j σ_j² = tr(Pᵀ G P)` (N·mm), the modes dropped as
    /// numerically zero included.
    pub total: f64,
    /// The modes' coefficients on the columns of `Z`: `c_j` in column j (c × energies.len()).
    pub coefficients: Mat<f64>,
}

impl JointPod {
    /// The fewest modes whose span leaves at most `fraction²` of the snapshots' energy outside:
    /// `Σ_{j>k} σ_j² ≤ fraction² · total`, i.e. the snapshots' part outside the span is within
    /// `fraction` of their K-norm (relative, over all outputs together).
    pub fn rank_for(&self, fraction: f64) -> usize {
        let allowed = fraction * fraction * self.total;
        let mut left = self.total;
        for (k, e) in self.energies.iter().enumerate() {
            if left <= allowed {
                return k;
            }
            left -= e;
        }
        self.energies.len()
    }
}

/// The K-weighted POD of the snapshots `X = Z P` from the Gram `G = Zᵀ K Z` of the columns
/// (c × c, positive semidefinite; its lower triangle is read after symmetrizing) and the
/// coefficients `P` (c × m): module docs. No n-size product.
///
/// # Errors
/// An eigenproblem that fails (not finite input).
pub fn joint_pod(gram: MatRef<'_, f64>, p: MatRef<'_, f64>) -> Result<JointPod, Error> {
    let c = gram.nrows();
    let sym = Mat::from_fn(c, c, |i, j| 0.5 * (gram[(i, j)] + gram[(j, i)]));
    let g = symmetric_eigen(sym.as_ref(), "joint POD: pair-space Gram")
        .map_err(Error::LinearAlgebra)?;
    // L = U Λ^{1/2} Uᵀ, negative round-off eigenvalues clipped.
    let scaled = Mat::from_fn(c, c, |i, j| g.vectors[(i, j)] * g.values[j].max(0.0).sqrt());
    let l = &scaled * g.vectors.transpose();
    let s = p * p.transpose();
    let ls = &l * &s;
    let w = &ls * &l;
    let w = Mat::from_fn(c, c, |i, j| 0.5 * (w[(i, j)] + w[(j, i)]));
    let evd = symmetric_eigen(w.as_ref(), "joint POD: snapshot energies")
        .map_err(Error::LinearAlgebra)?;
    let total: f64 = evd.values.iter().map(|v| v.max(0.0)).sum();
    let top = evd.values.last().copied().unwrap_or(0.0).max(0.0);
    let kept: Vec<usize> = (0..c)
        .rev()
        .filter(|&j| evd.values[j] > JOINT_POD_ZERO * top && evd.values[j] > 0.0)
        .collect();
    // c_j = S L v_j / σ_j² (S = P Pᵀ, symmetric: (L S)ᵀ = S L).
    let sl = ls.transpose();
    let mut coefficients = Mat::<f64>::zeros(c, kept.len());
    for (col, &j) in kept.iter().enumerate() {
        let v = evd.vectors.col(j);
        let cj = sl * v;
        let e = evd.values[j];
        for i in 0..c {
            coefficients[(i, col)] = cj[i] / e;
        }
    }
    Ok(JointPod {
        energies: kept.iter().map(|&j| evd.values[j]).collect(),
        total,
        coefficients,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::prelude::Solve;

    fn rnd(state: &mut u64) -> f64 {
        *state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (*state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    }

    /// A small SPD "stiffness" K (n × n), a sparse-ish joint operator B (c × n) and forces
    /// P (c × m) whose outputs follow three patterns plus a little noise.
    fn problem(n: usize, c: usize, m: usize) -> (Mat<f64>, Mat<f64>, Mat<f64>) {
        let mut st = 11;
        let a = Mat::from_fn(n, n, |_, _| rnd(&mut st));
        let k = &a * a.transpose() + Mat::from_fn(n, n, |i, j| if i == j { n as f64 } else { 0.0 });
        let b = Mat::from_fn(c, n, |i, j| {
            if j % c == i || (j + 1) % c == i {
                1.0 + rnd(&mut st)
            } else {
                0.0
            }
        });
        let patterns = Mat::from_fn(c, 3, |_, _| rnd(&mut st));
        let time = Mat::from_fn(3, m, |i, t| ((i + 1) as f64 * 0.3 * t as f64).sin());
        let noise = Mat::from_fn(c, m, |_, _| 1e-3 * rnd(&mut st));
        (k, b, &patterns * &time + noise)
    }

    /// The direct n-space K-weighted POD of the snapshots X (method of snapshots on XᵀKX):
    /// energies descending and the modes (n × count).
    fn direct_pod(k: &Mat<f64>, x: &Mat<f64>) -> (Vec<f64>, Mat<f64>) {
        let gram = x.transpose() * k * x;
        let gram = Mat::from_fn(gram.nrows(), gram.ncols(), |i, j| {
            0.5 * (gram[(i, j)] + gram[(j, i)])
        });
        let evd = symmetric_eigen(gram.as_ref(), "test").unwrap();
        let m = gram.nrows();
        let top = evd.values[m - 1];
        let order: Vec<usize> = (0..m)
            .rev()
            .filter(|&j| evd.values[j] > 1e-12 * top)
            .collect();
        let modes = Mat::from_fn(x.nrows(), order.len(), |i, col| {
            let j = order[col];
            let s = evd.values[j].sqrt();
            (0..m).map(|t| x[(i, t)] * evd.vectors[(t, j)]).sum::<f64>() / s
        });
        (order.iter().map(|&j| evd.values[j]).collect(), modes)
    }

    /// The test problem's K, `Z = K⁻¹ Bᵀ`, the snapshots `X = Z P` and their pair-space POD
    /// (`c` columns, 40 DOF, 25 outputs).
    fn fixture(c: usize) -> (Mat<f64>, Mat<f64>, Mat<f64>, JointPod) {
        let (k, b, p) = problem(40, c, 25);
        let z = k.llt(faer::Side::Lower).unwrap().solve(b.transpose());
        let x = &z * &p;
        let gram = b.as_ref() * &z;
        let pod = joint_pod(gram.as_ref(), p.as_ref()).unwrap();
        (k, z, x, pod)
    }

    #[test]
    fn pair_space_pod_equals_the_direct_k_weighted_pod() {
        let c = 9;
        let (k, z, x, pod) = fixture(c);
        let (energies, direct) = direct_pod(&k, &x);
        // Energies: every one the direct POD resolves, to round-off of the largest.
        let top = energies[0];
        for (a, b) in pod.energies.iter().zip(&energies) {
            assert!((a - b).abs() <= 1e-9 * top, "energy {a} vs direct {b}");
        }
        let total: f64 = energies.iter().sum();
        assert!((pod.total - total).abs() <= 1e-9 * total);
        // Modes: Z c_j equals the direct mode j up to sign, and is K-orthonormal.
        let modes = &z * &pod.coefficients;
        for j in 0..5 {
            let dot: f64 = (modes.col(j).transpose() * &k * direct.col(j)).abs();
            assert!((dot - 1.0).abs() < 1e-8, "mode {j}: |u_jᵀ K u_j'| = {dot}");
        }
        let ortho = modes.transpose() * &k * &modes;
        for i in 0..pod.energies.len().min(6) {
            for j in 0..pod.energies.len().min(6) {
                let want = if i == j { 1.0 } else { 0.0 };
                assert!(
                    (ortho[(i, j)] - want).abs() < 1e-8,
                    "({i},{j}) {}",
                    ortho[(i, j)]
                );
            }
        }
    }

    #[test]
    fn kept_modes_span_the_snapshots_to_the_energy_rule() {
        let c = 9;
        let (k, z, x, pod) = fixture(c);
        // The energy of X outside the K-orthogonal projection on the leading `rank` modes.
        let left_outside = |rank: usize| -> f64 {
            let u = &z * pod.coefficients.subcols(0, rank);
            let coords = u.transpose() * &k * &x;
            let rest = &x - &u * &coords;
            (rest.transpose() * &k * &rest)
                .diagonal()
                .column_vector()
                .sum()
        };
        for fraction in [1e-1, 1e-2, 1e-4] {
            let rank = pod.rank_for(fraction);
            assert!(rank < c, "fraction {fraction}: rank {rank} of {c}");
            // The K-orthogonal projection of X on the kept modes leaves at most fraction² of
            // its energy outside.
            let left = left_outside(rank);
            assert!(
                left <= fraction * fraction * pod.total * (1.0 + 1e-8),
                "fraction {fraction}: rank {rank} leaves {left} of {}",
                pod.total
            );
            // One mode fewer leaves more than that (the rank is the fewest).
            if rank > 0 {
                assert!(left_outside(rank - 1) > fraction * fraction * pod.total);
            }
        }
        // Three patterns carry the forces: 1e-2 of the norm needs three modes.
        assert_eq!(pod.rank_for(1e-2), 3);
    }
}
