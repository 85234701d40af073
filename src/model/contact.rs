//! Contact statics of a whole model: the master load applied to the full FE model and solved by
//! the active-set Newton iteration of [`crate::joint::statics`].

use super::Model;
use crate::error::Error;
use crate::joint::statics::{contact_static_sparse, ContactOptions, ContactSolution};

/// Frictionless penalty contact statics of the full model under master loads
/// `[Fx, Fy, Fz (N), Mx, My, Mz (N·mm)]`, with `k_n = case.contact.normal_stiffness`.
pub fn contact_static_full(
    model: &Model,
    load: [f64; 6],
    opts: &ContactOptions,
) -> Result<ContactSolution, Error> {
    let master = model.master_dofs();
    let mut f = vec![0.0; model.dofs()];
    for k in 0..6 {
        f[master[k]] = load[k];
    }
    let (displacement, state) = contact_static_sparse(
        &model.stiffness,
        &model.joint,
        &f,
        model.contact.normal_stiffness,
        opts,
    )?;
    Ok(ContactSolution {
        master_displacement: master.map(|k| displacement[k]),
        displacement,
        state,
    })
}
