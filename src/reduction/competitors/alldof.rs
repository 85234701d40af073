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

use faer::Mat;

use crate::error::Error;
use crate::joint::NORMAL;
use crate::linalg::cholesky::SparseCholesky;
use crate::linalg::compensated::solve_refined;
use crate::linalg::LinalgError;
use crate::model::Model;

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
        return Err(Error::LinearAlgebra(LinalgError::NotFinite {
            what: "all-joint-DOF constraint modes".to_string(),
            plural: true,
        }));
    }
    let n = model.dofs();
    Ok(Mat::from_fn(
        n,
        w,
        |r, c| if r < m { x[(r, c)] } else { 0.0 },
    ))
}
