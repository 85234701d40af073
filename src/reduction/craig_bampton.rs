//! Craig–Bampton trial vectors `[Φ_S | Φ_V]` of the linear structure (Algorithm 2, lines 1–2).

use faer::Mat;

use crate::error::{Error, ReductionError};
use crate::linalg::cholesky::SparseCholesky;
use crate::linalg::eigen::{lowest_modes_factored, Modes};
use crate::linalg::LinalgError;
use crate::linalg::SymCsc;
use crate::model::Model;

/// The fixed-interface problem of a model (the master node clamped): `K_ii`, `M_ii` (the
/// leading n − 6 rows and columns) and the Cholesky factor of `K_ii`. Craig–Bampton's
/// constraint modes and fixed-interface modes and the error estimate's truncated modes
/// ([`crate::reduction::JointFlexibility::share_fixed_interface`]) are all solves with it: one
/// factorization instead of one per use, and the same bits as each use factoring on its own
/// (the factorization is deterministic).
pub struct FixedInterface {
    k_ii: SymCsc,
    m_ii: SymCsc,
    chol: SparseCholesky,
}

impl FixedInterface {
    /// Extracts `K_ii`, `M_ii` of `model` and factors `K_ii`.
    ///
    /// # Errors
    /// The model's checks of [`craig_bampton`] (interior DOF, master DOF last) and a failing
    /// factorization.
    pub fn new(model: &Model) -> Result<FixedInterface, Error> {
        let m = interior_dofs(model)?;
        let k_ii = model.stiffness.leading(m);
        let chol = SparseCholesky::new(&k_ii)?;
        Ok(FixedInterface {
            m_ii: model.mass.leading(m),
            k_ii,
            chol,
        })
    }

    /// Number of interior DOF (n − 6).
    pub fn dofs(&self) -> usize {
        self.k_ii.n
    }

    /// The lowest `count` fixed-interface modes (interior DOF only, M-orthonormal): the same
    /// eigenproblem and bits as `model.modes(count, Interface::Fixed)`.
    ///
    /// # Errors
    /// A failing eigensolve.
    pub fn modes(&self, count: usize) -> Result<Modes, Error> {
        Ok(lowest_modes_factored(
            &self.k_ii, &self.m_ii, &self.chol, count,
        )?)
    }
}

/// The interior DOF count n − 6 of a model whose master node's six DOF are the last six.
fn interior_dofs(model: &Model) -> Result<usize, Error> {
    let n = model.dofs();
    if n <= 6 {
        return Err(ReductionError::NoInteriorDofs {
            method: "Craig–Bampton",
            dofs: n,
        }
        .into());
    }
    let m = n - 6;
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
    Ok(m)
}

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
    let m = interior_dofs(model)?;
    if nu > m {
        return Err(ReductionError::FixedInterfaceModes { nu, interior: m }.into());
    }
    craig_bampton_with(model, nu, &FixedInterface::new(model)?)
}

/// [`craig_bampton`] on the model's fixed-interface problem `fixed` (its factorization shared
/// with other uses): the same bits.
///
/// # Errors
/// As [`craig_bampton`]; `fixed` of another model ([`ReductionError::FixedInterfaceModes`] if
/// its size differs).
pub fn craig_bampton_with(
    model: &Model,
    nu: usize,
    fixed: &FixedInterface,
) -> Result<Mat<f64>, Error> {
    let m = interior_dofs(model)?;
    if nu > m || fixed.dofs() != m {
        return Err(ReductionError::FixedInterfaceModes { nu, interior: m }.into());
    }
    let n = model.dofs();
    let k = &model.stiffness;
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
    fixed.chol.solve_in_place(&mut rhs);
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
        let modes = fixed.modes(nu)?;
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
