//! Contact statics of a reduced model: the case's load on `Φᵀ K Φ` with frictionless penalty
//! contact on the pairs' normal rows of `B Φ`, solved by the active-set Newton method of
//! [`crate::joint::statics`] (eq. 7 of the paper on the reduced coordinates) and, where that
//! cycles on a coarse basis, by its damped variant, which converges for any basis because the
//! contact energy is convex.

use faer::Mat;

use crate::error::{Error, FlagError};
use crate::joint::statics::{
    contact_static_reduced, contact_static_reduced_damped, ContactOptions, ContactState,
};
use crate::joint::NORMAL;
use crate::linalg::LinalgError;
use crate::model::Model;
use crate::system::ReducedSystem;

/// The case's master load `[Fx, Fy, Fz (N), Mx, My, Mz (N·mm)]` times `scale`.
pub fn scaled_load(model: &Model, scale: f64) -> Result<[f64; 6], Error> {
    if !scale.is_finite() {
        return Err(FlagError::NotFinite {
            flag: "scale",
            value: scale,
        }
        .into());
    }
    Ok(model.master_load().map(|v| v * scale))
}

/// A reduced contact static solution.
#[derive(Clone, Debug)]
pub struct ReducedStatic {
    /// Reduced coordinates η (r); the displacement is `Φ η`.
    pub eta: Vec<f64>,
    /// The master node `[ux, uy, uz (mm), rx, ry, rz (rad)]` of `Φ η`.
    pub master_displacement: [f64; 6],
    /// Gaps (mm), pair forces (N), active set, `‖f_c‖` (N).
    pub state: ContactState,
}

/// The dense contact problem of a reduced model under its load `Φᵀ f` times `scale`: `K̃`, the
/// normal rows of `B Φ`, `f̃`, `k_n`.
type DenseContactSolver = fn(
    faer::MatRef<'_, f64>,
    faer::MatRef<'_, f64>,
    &[f64],
    f64,
    &ContactOptions,
) -> Result<(Vec<f64>, ContactState), Error>;

/// `solve` on the reduced contact problem of `rm` under `scale` × its load, with the master
/// displacement of the solution.
fn solve_reduced(
    model: &Model,
    rm: &ReducedSystem,
    scale: f64,
    opts: &ContactOptions,
    solve: DenseContactSolver,
) -> Result<ReducedStatic, Error> {
    let w = model.joint.pairs();
    let r = rm.dim();
    let b_n = Mat::from_fn(w, r, |i, j| rm.b_phi()[(3 * i + NORMAL, j)]);
    let f: Vec<f64> = rm.reduced_load().iter().map(|v| v * scale).collect();
    let (eta, state) = solve(
        rm.k().as_ref(),
        b_n.as_ref(),
        &f,
        model.contact.normal_stiffness,
        opts,
    )?;
    let master_displacement: [f64; 6] =
        std::array::from_fn(|k| (0..r).map(|c| rm.phi_master[(k, c)] * eta[c]).sum::<f64>());
    Ok(ReducedStatic {
        eta,
        master_displacement,
        state,
    })
}

/// Frictionless contact statics of a reduced model under its load `Φᵀ f` times `scale`
/// ([`contact_static_reduced`] on `K̃` and the normal rows of `B Φ`).
pub fn reduced_contact_static(
    model: &Model,
    rm: &ReducedSystem,
    scale: f64,
    opts: &ContactOptions,
) -> Result<ReducedStatic, Error> {
    solve_reduced(model, rm, scale, opts, contact_static_reduced)
}

/// [`reduced_contact_static`] (the active-set Newton method of [`crate::joint::statics`]) from
/// `opts.start`; if that fails — it can cycle on a coarse basis, whose contact problem is still
/// convex but poorly resolved — [`reduced_contact_static_damped`], which converges for any
/// basis. Returns the solution and the first attempt's error if the fallback was needed.
pub fn reduced_contact_static_restarting(
    model: &Model,
    rm: &ReducedSystem,
    scale: f64,
    opts: &ContactOptions,
) -> Result<(ReducedStatic, Option<Error>), Error> {
    match reduced_contact_static(model, rm, scale, opts) {
        Ok(sol) => Ok((sol, None)),
        Err(first) => match reduced_contact_static_damped(model, rm, scale, opts) {
            Ok(sol) => Ok((sol, Some(first))),
            Err(second) => Err(Error::LinearAlgebra(LinalgError::ContactFallback {
                first: Box::new(first),
                second: Box::new(second),
            })),
        },
    }
}

/// [`contact_static_reduced_damped`] on a reduced model under its load `Φᵀ f` times `scale`:
/// converges from any start where the undamped method can cycle.
pub fn reduced_contact_static_damped(
    model: &Model,
    rm: &ReducedSystem,
    scale: f64,
    opts: &ContactOptions,
) -> Result<ReducedStatic, Error> {
    solve_reduced(model, rm, scale, opts, contact_static_reduced_damped)
}
