//! Craig–Bampton trial vectors `[Φ_S | Φ_V]` of the linear structure (Algorithm 2, lines 1–2).

use faer::Mat;

use crate::error::{Error, ReductionError};
use crate::linalg::cholesky::SparseCholesky;
use crate::linalg::eigen::lowest_modes_factored;
use crate::linalg::LinalgError;
use crate::model::Model;

/// The Craig–Bampton basis `[Φ_S | Φ_V]` (n × (6 + ν)) of a model whose master node's six DOF
/// are the last six independent DOF (the boundary set `b`, interior `i` = the leading n − 6).
///
/// - `Φ_S`: constraint modes. Column `c` has a unit displacement of master DOF `c` (mm or rad),
///   zero on the other master DOF, and the interior `x_i` from `K_ii x_i = −K_ib e_c` (one sparse
///   Cholesky of `K_ii`, six right-hand sides). So `K Φ_S` is zero on the interior rows.
/// - `Φ_V`: the ν lowest fixed-interface normal modes (`K_ii φ = ω² M_ii φ`, M-orthonormal),
///   padded with zeros on the master DOF. `ν = 0` gives `Φ_S` alone.
///
/// Because `K Φ_S` vanishes on the interior rows and `Φ_V` vanishes on the master rows,
/// `Φ_Sᵀ K Φ_V = 0` holds exactly (up to the solve's round-off).
pub fn craig_bampton(model: &Model, nu: usize) -> Result<Mat<f64>, Error> {
    let n = model.dofs();
    if n <= 6 {
        return Err(ReductionError::NoInteriorDofs {
            method: "Craig–Bampton",
            dofs: n,
        }
        .into());
    }
    let m = n - 6;
    if nu > m {
        return Err(ReductionError::FixedInterfaceModes { nu, interior: m }.into());
    }
    let master = model.master_dofs();
    for (c, &d) in master.iter().enumerate() {
        if d != m + c {
            return Err(ReductionError::MasterNotLast {
                method: "Craig–Bampton",
                master: c,
                dof: d,
                expected: m + c,
            }
            .into());
        }
    }
    let k = &model.stiffness;
    let k_ii = k.leading(m);
    let kii = SparseCholesky::new(&k_ii)?;
    // Right-hand sides −K_ib e_c: column m + c of K restricted to interior rows.
    let mut rhs = Mat::<f64>::zeros(m, 6);
    for c in 0..6 {
        let col = m + c;
        for p in k.col_ptr[col]..k.col_ptr[col + 1] {
            let r = k.row_idx[p];
            if r < m {
                rhs[(r, c)] = -k.values[p];
            }
        }
    }
    kii.solve_in_place(&mut rhs);
    let mut phi = Mat::<f64>::zeros(n, 6 + nu);
    for c in 0..6 {
        for r in 0..m {
            phi[(r, c)] = rhs[(r, c)];
        }
        phi[(m + c, c)] = 1.0;
    }
    if nu > 0 {
        // The fixed-interface modes reuse the factorization of K_ii (the same eigenproblem as
        // `model.modes(nu, Interface::Fixed)`).
        let modes = lowest_modes_factored(&k_ii, &model.mass.leading(m), &kii, nu)?;
        for c in 0..nu {
            for r in 0..m {
                phi[(r, 6 + c)] = modes.shapes[(r, c)];
            }
        }
    }
    if phi.col_iter().any(|c| c.iter().any(|v| !v.is_finite())) {
        return Err(Error::LinearAlgebra(LinalgError::not_finite(
            "Craig–Bampton basis",
        )));
    }
    Ok(phi)
}
