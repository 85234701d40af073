//! POD of full-FE transient snapshots (the competitor of Witteveen & Pichler 2014, Section 5.2).
//!
//! The snapshot matrix `Y = [x(t_0) x(t_1) … x(t_{z−1})]` (n × z, mm and rad) holds displacement
//! states of a time integration of the full nonlinear system (eq. 2). Its POD is the same
//! computation as the POD of the TVD (eqs. 20–26, [`crate::reduction::pod()`]): the eigenproblem
//! `Yᵀ A Y û_i = λ_i û_i` of the z × z correlation matrix (the "method of snapshots"), the
//! proper orthogonal modes `u_i = Y û_i / √λ_i`, A-orthonormal, and the captured-energy ratio
//! `w(g) = Σ_{i≤g} λ_i / Σ_i λ_i` (eq. 26). The paper's Section 5.2 uses the Euclidean
//! inner product (`A = I`, "a minimal Euclidean distance"); a weight `A` (e.g. K or M) is
//! optional. The snapshots are **not** centred: the POMs approximate the states themselves, as
//! in the paper's eqs. 20–23, not their fluctuation about the mean. Cost `O(n z² + z³)`.
//!
//! [`snapshot_basis`] builds the reduction basis `[Φ_S Φ_V U_g]`: Craig–Bampton plus the first g
//! POMs, M-orthonormalized by [`final_basis`] (Craig–Bampton first, so a POM lying in its span is
//! dropped and counted in [`Basis::dropped`]).

use faer::MatRef;

use crate::error::{Error, ReductionError};
use crate::linalg::SymCsc;
use crate::model::Model;

use crate::reduction::basis::{final_basis, modal_rotation, Basis, BasisOptions};
use crate::reduction::craig_bampton::craig_bampton;
use crate::reduction::pod::{pod, Pod};

/// POD of the snapshot columns of `snapshots` (n × z) with the inner product of `weight`
/// (`None`: Euclidean, the paper's Section 5.2). Errors on non-finite entries, a weight of the
/// wrong size or an all-zero snapshot set. See the module docs.
pub fn snapshot_pod(snapshots: MatRef<'_, f64>, weight: Option<&SymCsc>) -> Result<Pod, Error> {
    if snapshots.ncols() == 0 {
        return Err(ReductionError::NoSnapshots.into());
    }
    if let Some((r, c)) = (0..snapshots.ncols())
        .flat_map(|c| (0..snapshots.nrows()).map(move |r| (r, c)))
        .find(|&(r, c)| !snapshots[(r, c)].is_finite())
    {
        return Err(ReductionError::SnapshotNotFinite {
            snapshot: c,
            dof: r,
        }
        .into());
    }
    pod(snapshots, weight)
}

/// The basis `[Φ_S Φ_V U_g]` of Craig–Bampton (`opts.nu` modes) and the first g snapshot POMs
/// (`opts.g`, or the smallest g with `w(g) ≥ opts.threshold`), M-orthonormalized with
/// `opts.drop_tol` (and rotated to the reduced eigenbasis if `opts.modal`). `weight` as in [`snapshot_pod`]. The returned [`Basis::w`] is the snapshot
/// POD's energy ratio; `tvd_total = tvd_nonzero = 0`. Errors if the snapshots do not have
/// `model.dofs()` rows.
pub fn snapshot_basis(
    model: &Model,
    snapshots: MatRef<'_, f64>,
    weight: Option<&SymCsc>,
    opts: &BasisOptions,
) -> Result<Basis, Error> {
    if snapshots.nrows() != model.dofs() {
        return Err(ReductionError::Rows {
            what: "snapshots have",
            rows: snapshots.nrows(),
            dofs: model.dofs(),
        }
        .into());
    }
    let p = snapshot_pod(snapshots, weight)?;
    let g = opts
        .g
        .unwrap_or_else(|| p.choose_g(opts.threshold))
        .min(p.lambda.len());
    let cb = craig_bampton(model, opts.nu)?;
    let (phi, dropped) = final_basis(&[cb.as_ref(), p.leading(g)], &model.mass, opts.drop_tol)?;
    let (phi, eigenvalues) = if opts.modal {
        modal_rotation(model, phi)?
    } else {
        (phi, Vec::new())
    };
    Ok(Basis {
        phi,
        w: p.w,
        g,
        tvd_total: 0,
        tvd_nonzero: 0,
        dropped,
        eigenvalues,
    })
}
