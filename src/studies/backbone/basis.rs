//! The backbone's reduced model: the case's tolerance model enriched with what ring-downs about
//! the preloaded equilibrium need.
//!
//! A tolerance model ([`crate::rom::tolerance`]) is chosen on the case's own transient: its error
//! control holds for the contact forces, the master's motion and the dissipation of that load
//! history, not for small vibrations about a pressed joint. There the closed pairs stick, and the
//! modes of the stuck joint bend the stick springs: a basis without the pairs' tangential
//! compliance is too stiff (the friction bar's 1 % model linearised 1.1 % high), and its
//! stick–slip onset follows the wrong tangential forces. The backbone's model therefore adds to
//! the tolerance model's basis Φ_TOL, from the full model:
//!
//! 1. **The equilibrium** `x_eq`, the full model's frictionless contact statics under the
//!    preload. The statics minimise a strictly convex energy, so a basis holding `x_eq` has it
//!    as its own (Galerkin) solution: the reduced equilibrium and its set of closed pairs are the
//!    full model's.
//! 2. **The linearised modes** ψ_1…ψ_m about `x_eq` with the closed pairs stuck (the modes the
//!    backbone is asked for, [`super::linear`]). Rayleigh–Ritz on a basis holding them returns
//!    their frequencies exactly (Courant–Fischer: the reduced k-th eigenvalue is an upper bound
//!    and ψ_1…ψ_k are in the span), so the small-amplitude end of the backbone is the full
//!    model's linearisation. They cost one sparse shift-invert eigensolve of the stiffened `K`.
//! 3. **The slipped modes** ψ̂_1…ψ̂_m: the same with the closed pairs' normal springs only (their
//!    tangential stick released) — the large-amplitude limit towards which the slipping joint
//!    softens.
//! 4. **Static attachment modes** `K⁻¹ b_zᵀ` of every pair of the joint, in the normal and both
//!    tangential directions (`3w` columns before the drop of dependent ones). For the pairs
//!    closed at the equilibrium they are the local compliance that decides how far a pair slides
//!    once its friction force changes; by Woodbury `(K + B_zᵀ k B_z)⁻¹ B_zᵀ = K⁻¹ B_zᵀ (I + k
//!    B_z K⁻¹ B_zᵀ)⁻¹` they also span the stiffened structure's responses to the pair forces.
//!    The open pairs' columns add no static response the closed pairs' do not, but shapes of
//!    the joint region between them: measured on the friction bar and the multilayer sheet, a
//!    basis with the closed pairs' columns alone dissipated up to 13 % more per cycle than the
//!    full model, with every pair's up to 7 % (docs/validation/backbone.md) — the slipping
//!    joint's local dynamics need them. They are what makes the model large (r ≈ Φ_TOL + 2–3 w).
//! 5. **Dynamic attachment modes** `K⁻¹ M K⁻¹ b_zᵀ` of the same rows. A ring-down at ω sees the
//!    dynamic compliance `(K − ω²M)⁻¹ b_zᵀ = K⁻¹ b_zᵀ + ω² K⁻¹ M K⁻¹ b_zᵀ + O(ω⁴)`, not the static
//!    one: the pair forces of a slipping joint accelerate the structure around the pair, and
//!    with the static columns alone the reduced model dissipated up to 9 % more per cycle than
//!    the full one (docs/validation/backbone.md). These columns are the first dynamic term;
//!    most of them lie in the span already (to the drop tolerance), so they add few columns (34 on the friction bar, 90 on the
//!    multilayer sheet). Further Krylov blocks `(K⁻¹M)ʲ K⁻¹ b_zᵀ` add none.
//!
//! The columns are M-orthonormalised after Φ_TOL (dependent ones dropped,
//! [`crate::reduction::final_basis`]) and rotated to the reduced eigenbasis.

use faer::{Mat, MatRef};

use crate::error::Error;
use crate::linalg::cholesky::SparseCholesky;
use crate::linalg::compensated::solve_refined;
use crate::linalg::sparse::sym_mul_mat;
use crate::model::Model;
use crate::reduction::estimate::JointFlexibility;
use crate::reduction::{final_basis, modal_rotation, DEFAULT_DROP_TOL};
use crate::system::ReducedSystem;

use super::linear::{full_equilibrium, full_modes, LinearMode};

/// The backbone's model and what went into it.
pub struct BackboneModel {
    /// The enriched reduced system (with its basis Φ).
    pub rom: ReducedSystem,
    /// The full model's linearised frequencies of modes 1…m, Hz (the reference of the reduced
    /// model's linearisation).
    pub full_frequencies_hz: Vec<f64>,
    /// Pairs whose attachment modes were added (every pair of the joint).
    pub attachment_pairs: usize,
}

/// The backbone's model (module docs): Φ_TOL `phi` enriched for ring-downs of the lowest
/// `count` modes about the equilibrium under `preload` × the master load, the closed pairs
/// stuck when `friction`.
///
/// # Errors
/// A failing contact solve, eigensolve, factorization or basis.
pub fn backbone_model(
    model: &Model,
    phi: &Mat<f64>,
    preload: f64,
    count: usize,
    friction: bool,
) -> Result<BackboneModel, Error> {
    let n = model.dofs();
    let eq = full_equilibrium(model, preload)?;
    let stuck = full_modes(model, &eq, count, friction)?;
    let slipped = if friction {
        full_modes(model, &eq, count, false)?
    } else {
        Vec::new()
    };
    let shapes = |m: &[LinearMode]| Mat::from_fn(n, m.len(), |i, j| m[j].shape[i]);
    let x = Mat::from_fn(n, 1, |i, _| eq.q[i]);
    let pairs: Vec<usize> = (0..model.joint.pairs()).collect();
    let flex = JointFlexibility::new(model)?;
    let normal = flex.attachment_modes(&pairs);
    let tangential = if friction {
        let dirs: Vec<(usize, [f64; 2])> = pairs
            .iter()
            .flat_map(|&k| [(k, [1.0, 0.0]), (k, [0.0, 1.0])])
            .collect();
        flex.tangential_attachment_modes(&dirs)
    } else {
        Mat::zeros(n, 0)
    };
    let (psi, psi_slipped) = (shapes(&stuck), shapes(&slipped));
    let dynamic = dynamic_attachment_modes(model, &[normal.as_ref(), tangential.as_ref()])?;
    let (basis, _) = final_basis(
        &[
            phi.as_ref(),
            x.as_ref(),
            psi.as_ref(),
            psi_slipped.as_ref(),
            normal.as_ref(),
            tangential.as_ref(),
            dynamic.as_ref(),
        ],
        &model.mass,
        DEFAULT_DROP_TOL,
    )?;
    let (basis, _) = modal_rotation(model, basis)?;
    Ok(BackboneModel {
        rom: ReducedSystem::new(model, basis)?,
        full_frequencies_hz: stuck.iter().map(|m| m.frequency_hz).collect(),
        attachment_pairs: pairs.len(),
    })
}

/// `K⁻¹ M X` for the columns of the blocks `xs` (n × Σ cols; mm/N · s² for attachment modes X
/// in mm/N): the dynamic term of the attachment modes (module docs, item 5).
///
/// # Errors
/// A stiffness that does not factor.
fn dynamic_attachment_modes(model: &Model, xs: &[MatRef<'_, f64>]) -> Result<Mat<f64>, Error> {
    let n = model.dofs();
    let cols: usize = xs.iter().map(|x| x.ncols()).sum();
    let mut x = Mat::<f64>::zeros(n, cols);
    let mut j = 0;
    for block in xs {
        for c in 0..block.ncols() {
            x.col_mut(j).copy_from(block.col(c));
            j += 1;
        }
    }
    let mx = sym_mul_mat(&model.mass, x.as_ref());
    let chol = SparseCholesky::new(&model.stiffness)?;
    Ok(solve_refined(&model.stiffness, &chol, &mx))
}
