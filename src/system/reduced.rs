//! A reduced model (eq. 7) as a second-order system: `M̃ q̈ + K̃ q = Φᵀ f(t) − (BΦ)ᵀ p`, dense
//! r × r, the Newton matrix `M̃ + γ²(K̃ + (BΦ)ᵀ K_c BΦ)` factored in place per setup — as a
//! diagonal plus the joint's low-rank term when the basis is the reduced eigenbasis
//! ([`super::modal_newton`]).
//!
//! ## Active-set refreshes by a rank update
//!
//! A refresh of the mechanical problem ([`crate::integrate::mechanical`]) changes the `K_c`
//! blocks of the pairs that switched branch. The Newton matrix changes by
//! `γ_f² Σ_i (BΦ)_iᵀ ΔK_c,i (BΦ)_i`; each `ΔK_c,i` has no normal–tangential coupling (the
//! problem's blocks have none), so it is the normal entry and the tangential 2 × 2 block's two
//! eigenpairs `λ v vᵀ` — at most three columns `w = γ_f (BΦ)_iᵀ v` with weights `λ` per pair.
//! [`ReducedSystem::newton_update`](SecondOrderSystem::newton_update) applies them to the
//! dense Cholesky factor as a rank-k up/downdate (faer's `rank_r_update_clobber`, ~2kr² flops)
//! when that is cheaper than a factorization (r³/3 flops: k ≤ r/6), and declines otherwise, when
//! a downdate loses definiteness (the factor is then refactored) or when the setup used the
//! eigenbasis factor (whose setup already costs the joint's rank, not r³). A refactorization re-linearizes
//! every pair at the current γ, a better Newton matrix than the update at the factored γ, so
//! the update is taken only where it saves the factorization's cost.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::{
    cholesky_in_place, cholesky_in_place_scratch, LltRegularization,
};
use faer::linalg::cholesky::llt::solve::solve_in_place_with_conj;
use faer::linalg::cholesky::llt::update::rank_r_update_clobber;
use faer::linalg::matmul::matmul;
use faer::{Accum, Col, Conj, Mat, MatMut, Par};

use super::modal_newton::{modal_diagonal, ModalNewton};
use super::{JointRows, SecondOrderSystem};
use crate::case::LoadSpec;
use crate::error::{Error, SystemError};
use crate::joint::JointOperator;
use crate::linalg::compensated::compensated_gram;
use crate::linalg::kernels;
use crate::linalg::LinalgError;
use crate::linalg::SymCsc;
use crate::model::Model;

/// How the integrator's error test sees a reduced model's coordinates: as the physical field
/// they produce (`crate::integrate::mechanical`, *The error test of a reduced model*).
#[derive(Clone, Debug, PartialEq)]
pub struct ErrorScale {
    /// Per coordinate, the Euclidean norm over the full model's DOF of the field a unit of it
    /// produces, `‖Φ_j‖₂` (mm or rad per unit coordinate).
    pub column: Vec<f64>,
    /// The number of DOF n of that field (the full model's).
    pub field_dofs: usize,
}

/// A reduced model (eq. 7) as a [`SecondOrderSystem`] (r generalized coordinates), dense.
pub struct ReducedSystem {
    r: usize,
    /// The basis Φ (n × r), mm or rad per unit coordinate; `None` for a reduced model read from
    /// a file (which carries the operators below, not Φ).
    pub phi: Option<Mat<f64>>,
    /// `K̃ = ΦᵀKΦ` (r × r), N/mm per unit coordinate² (read with [`ReducedSystem::k`]).
    k: Mat<f64>,
    /// `M̃ = ΦᵀMΦ` (r × r), t per unit coordinate²; the identity for an M-orthonormal basis.
    m: Mat<f64>,
    /// `BΦ` (3w × r), rows normal, t1, t2 per pair (as [`crate::joint::JointOperator`]), mm per
    /// unit coordinate.
    b_phi: Mat<f64>,
    /// `K̃`, `M̃` and `BΦ` column by column, and `BΦ` row by row: contiguous copies for
    /// [`kernels`] (`y = A x` on columns, `y += Aᵀ p` on rows).
    k_cols: Vec<f64>,
    m_cols: Vec<f64>,
    b_cols: Vec<f64>,
    b_rows: Vec<f64>,
    /// `BΦ`'s normal rows (w × r) and tangential rows (2w × r, t1 and t2 of each pair in
    /// turn), each column by column: the products of one kind of row
    /// ([`SecondOrderSystem::joint_apply_rows_into`]).
    bn_cols: Vec<f64>,
    bt_cols: Vec<f64>,
    /// Rows of Φ at the six master DOF (6 × r: ux, uy, uz (mm), rx, ry, rz (rad) per unit).
    pub phi_master: Mat<f64>,
    /// The Euclidean norm of each basis column over the full model's DOF (mm or rad per unit
    /// coordinate) and that number of DOF: the field the error test measures
    /// ([`SecondOrderSystem::coordinate_size_into`], [`SecondOrderSystem::field_dofs`]).
    pub error_scale: ErrorScale,
    /// Master load and its ramp (change it to run load variants on one basis).
    pub load: LoadSpec,
    /// `M̃ = I` to round-off (M-orthonormal basis): the M-solve is the identity.
    m_identity: bool,
    m_llt: Mat<f64>,
    newton: Mat<f64>,
    newton_ok: bool,
    /// γ and the pairs' `K_c` blocks (9 per pair, N/mm) of the factored Newton matrix, as
    /// [`SecondOrderSystem::newton_update`] changed them since the factorization.
    gamma_factored: f64,
    kc_factored: Vec<f64>,
    /// Scratch of [`SecondOrderSystem::newton_update`]: the update's columns `W` (r × k, k at
    /// most `update_columns`) and weights `α`, `A ← A + W diag(α) Wᵀ`.
    update_w: Mat<f64>,
    update_alpha: Col<f64>,
    /// The Newton factor as diagonal plus low rank when the basis is the reduced eigenbasis
    /// ([`super::modal_newton`]), and whether the last setup used it.
    modal: Option<ModalNewton>,
    modal_used: bool,
    /// Scratch of the Newton setup: the rows of `BΦ` of the pairs with a non-zero `K_c` block
    /// (`active`) and `K_c (BΦ)` on them (`kcb`), up to 3w × r.
    active: Mat<f64>,
    kcb: Mat<f64>,
    mem: MemBuffer,
}

/// A dense matrix's rows, concatenated.
fn row_major(a: &Mat<f64>) -> Vec<f64> {
    let mut out = Vec::with_capacity(a.nrows() * a.ncols());
    for i in 0..a.nrows() {
        out.extend((0..a.ncols()).map(|j| a[(i, j)]));
    }
    out
}

/// The rows `i` of a dense matrix with `keep(i)`, as one matrix, column by column.
fn col_major_rows(a: &Mat<f64>, keep: impl Fn(usize) -> bool) -> Vec<f64> {
    let rows: Vec<usize> = (0..a.nrows()).filter(|&i| keep(i)).collect();
    let mut out = Vec::with_capacity(rows.len() * a.ncols());
    for j in 0..a.ncols() {
        out.extend(rows.iter().map(|&i| a[(i, j)]));
    }
    out
}

/// A dense matrix's columns, concatenated.
fn col_major(a: &Mat<f64>) -> Vec<f64> {
    col_major_rows(a, |_| true)
}

/// The most columns a rank update of the dense Newton factor takes (module docs): k columns cost
/// ~2kr² flops against a factorization's r³/3, so k ≤ r/6, and a change has at most three per
/// pair (`rows` = 3w).
fn update_columns(r: usize, rows: usize) -> usize {
    (r / 6).min(rows)
}

/// The eigenpairs `(λ, v)` (v unit, in the pair's rows normal, t1, t2) of a change of a pair's
/// `K_c` block (row-major 3 × 3, symmetric) that couples the normal and tangential rows nowhere:
/// the normal entry, and the 2 × 2 tangential block's two eigenpairs (closed form).
fn block_eigen(d: [f64; 9]) -> [(f64, [f64; 3]); 3] {
    let normal = (d[0], [1.0, 0.0, 0.0]);
    let (a, b, c) = (d[4], 0.5 * (d[5] + d[7]), d[8]);
    if b == 0.0 {
        return [normal, (a, [0.0, 1.0, 0.0]), (c, [0.0, 0.0, 1.0])];
    }
    let mean = 0.5 * (a + c);
    let rad = (0.5 * (a - c)).hypot(b);
    let (l1, l2) = (mean + rad, mean - rad);
    // Eigenvector of l1: (b, l1 − a) or (l1 − c, b), whichever is longer (no cancellation);
    // that of l2 is its perpendicular.
    let (x, y) = if (l1 - a).abs() >= (l1 - c).abs() {
        (b, l1 - a)
    } else {
        (l1 - c, b)
    };
    let n = x.hypot(y);
    let (x, y) = (x / n, y / n);
    [normal, (l1, [0.0, x, y]), (l2, [0.0, -y, x])]
}

impl ReducedSystem {
    /// Projects a model on the basis `phi` (n × r) with the model's load (eq. 7): the same as
    /// [`crate::system::FullSystem::reduce`] without factoring the full model.
    pub fn new(model: &Model, phi: Mat<f64>) -> Result<ReducedSystem, Error> {
        ReducedSystem::project(
            &model.stiffness,
            &model.mass,
            &model.joint,
            model.master_dofs(),
            model.load.clone(),
            phi,
        )
    }

    /// `K̃ = ΦᵀKΦ` and `M̃ = ΦᵀMΦ` (compensated: exact projections of the assembled matrices to
    /// working precision, see [`compensated_gram`]), `BΦ`, the master rows and column sizes.
    pub(super) fn project(
        k: &SymCsc,
        m: &SymCsc,
        joint: &JointOperator,
        master: [usize; 6],
        load: LoadSpec,
        phi: Mat<f64>,
    ) -> Result<ReducedSystem, Error> {
        if phi.nrows() != k.n {
            return Err(SystemError::BasisRows {
                rows: phi.nrows(),
                dofs: k.n,
            }
            .into());
        }
        let r = phi.ncols();
        let phi_master = Mat::from_fn(6, r, |d, c| phi[(master[d], c)]);
        let error_scale = ErrorScale {
            column: (0..r)
                .map(|c| phi.col(c).iter().map(|x| x * x).sum::<f64>().sqrt())
                .collect(),
            field_dofs: k.n,
        };
        ReducedSystem::from_matrices(
            compensated_gram(k, phi.as_ref()),
            compensated_gram(m, phi.as_ref()),
            joint.reduce(phi.as_ref()),
            (phi_master, error_scale),
            load,
            Some(phi),
        )
    }

    /// Builds the system from its matrices (e.g. read back from an exported reduced model,
    /// [`crate::rom::file`]), with the basis if known; checks the dimensions,
    /// finiteness and the coordinate sizes, factors M̃ unless it is the identity.
    ///
    /// `k` = K̃ (r × r, N/mm per unit coordinate²), `m` = M̃ (r × r, t per unit coordinate²),
    /// `b_phi` = BΦ (3w × r, mm per unit), `master` = (the rows of Φ at the six master DOF,
    /// 6 × r; the error test's scale of each coordinate and the full model's DOF count,
    /// [`ErrorScale`]), `load` the master load and its ramp, `phi` the basis if known (n × r).
    pub(crate) fn from_matrices(
        k: Mat<f64>,
        m: Mat<f64>,
        b_phi: Mat<f64>,
        master: (Mat<f64>, ErrorScale),
        load: LoadSpec,
        phi: Option<Mat<f64>>,
    ) -> Result<ReducedSystem, Error> {
        let (phi_master, error_scale) = master;
        let column_size = &error_scale.column;
        let r = k.nrows();
        if let Some(phi) = &phi {
            if phi.ncols() != r {
                return Err(SystemError::BasisColumns {
                    columns: phi.ncols(),
                    r,
                }
                .into());
            }
        }
        if k.ncols() != r
            || m.nrows() != r
            || m.ncols() != r
            || b_phi.ncols() != r
            || b_phi.nrows() % 3 != 0
            || phi_master.nrows() != 6
            || phi_master.ncols() != r
            || column_size.len() != r
        {
            return Err(SystemError::Sizes {
                r,
                k: (k.nrows(), k.ncols()),
                m: (m.nrows(), m.ncols()),
                b_phi: (b_phi.nrows(), b_phi.ncols()),
                master: (phi_master.nrows(), phi_master.ncols()),
                coordinates: column_size.len(),
            }
            .into());
        }
        for (name, a) in [
            ("K̃", &k),
            ("M̃", &m),
            ("BΦ", &b_phi),
            ("master rows", &phi_master),
        ] {
            if a.col_iter().any(|c| c.iter().any(|v| !v.is_finite())) {
                return Err(SystemError::NotFinite { name }.into());
            }
        }
        if let Some(c) = column_size
            .iter()
            .position(|s| !(s.is_finite() && *s > 0.0))
        {
            return Err(SystemError::ZeroColumn { column: c }.into());
        }
        if error_scale.field_dofs < r {
            return Err(SystemError::FieldTooSmall {
                r,
                field_dofs: error_scale.field_dofs,
            }
            .into());
        }
        let mut dev = 0.0f64;
        for i in 0..r {
            for j in 0..r {
                let id = if i == j { 1.0 } else { 0.0 };
                dev = dev.max((m[(i, j)] - id).abs());
            }
        }
        let m_identity = dev <= 1e-12;
        let req = cholesky_in_place_scratch::<f64>(r, Par::Seq, Default::default());
        let mut mem = MemBuffer::new(req);
        let mut m_llt = m.clone();
        if !m_identity {
            cholesky_in_place(
                m_llt.as_mut(),
                LltRegularization::default(),
                Par::Seq,
                MemStack::new(&mut mem),
                Default::default(),
            )
            .map_err(|e| {
                Error::LinearAlgebra(LinalgError::ReducedNotPositiveDefinite {
                    matrix: "reduced mass",
                    r,
                    source: Box::new(e),
                })
            })?;
        }
        let w3 = b_phi.nrows();
        let modal = modal_diagonal(&k, m_identity).map(|d| ModalNewton::new(d, w3));
        Ok(ReducedSystem {
            r,
            phi,
            k_cols: col_major(&k),
            m_cols: col_major(&m),
            b_cols: col_major(&b_phi),
            b_rows: row_major(&b_phi),
            bn_cols: col_major_rows(&b_phi, |i| i % 3 == 0),
            bt_cols: col_major_rows(&b_phi, |i| i % 3 != 0),
            k,
            m,
            m_identity,
            m_llt,
            b_phi,
            phi_master,
            error_scale,
            load,
            newton: Mat::zeros(r, r),
            newton_ok: false,
            gamma_factored: 0.0,
            kc_factored: vec![0.0; 3 * w3],
            update_w: Mat::zeros(r, update_columns(r, w3)),
            update_alpha: Col::zeros(update_columns(r, w3)),
            modal,
            modal_used: false,
            active: Mat::zeros(w3, r),
            kcb: Mat::zeros(w3, r),
            mem,
        })
    }

    /// Reduced dimension r.
    pub fn dim(&self) -> usize {
        self.r
    }

    /// `K̃ = ΦᵀKΦ` (r × r), N/mm per unit coordinate².
    pub fn k(&self) -> &Mat<f64> {
        &self.k
    }

    /// `M̃ = ΦᵀMΦ` (r × r), t per unit coordinate² (the identity for an M-orthonormal basis).
    pub fn m(&self) -> &Mat<f64> {
        &self.m
    }

    /// `BΦ` (3w × r), rows normal, t1, t2 per pair (as [`crate::joint::JointOperator`]), mm per
    /// unit coordinate.
    pub fn b_phi(&self) -> &Mat<f64> {
        &self.b_phi
    }

    /// Whether the Newton matrix is factored as a diagonal plus the joint's low-rank term when
    /// it can be: a basis in the reduced eigenbasis (`M̃ = I`, `K̃` diagonal to rounding; by
    /// Woodbury through the joint's rows, see the module `system::modal_newton`). A setup with
    /// too many joint rows still factors densely.
    pub fn modal_newton(&self) -> bool {
        self.modal.is_some()
    }

    /// `Φᵀ f_master` (r): the generalized forces of the final master load (N, N·mm per unit
    /// coordinate), before the ramp.
    pub fn reduced_load(&self) -> Vec<f64> {
        let f = self.load.master.to_array();
        (0..self.r)
            .map(|c| (0..6).map(|d| self.phi_master[(d, c)] * f[d]).sum())
            .collect()
    }
}

impl Clone for ReducedSystem {
    /// The same system with its own scratch (the factor of M̃ is copied, not recomputed).
    fn clone(&self) -> ReducedSystem {
        ReducedSystem {
            r: self.r,
            phi: self.phi.clone(),
            k: self.k.clone(),
            m: self.m.clone(),
            b_phi: self.b_phi.clone(),
            k_cols: self.k_cols.clone(),
            m_cols: self.m_cols.clone(),
            b_cols: self.b_cols.clone(),
            b_rows: self.b_rows.clone(),
            bn_cols: self.bn_cols.clone(),
            bt_cols: self.bt_cols.clone(),
            phi_master: self.phi_master.clone(),
            error_scale: self.error_scale.clone(),
            load: self.load.clone(),
            m_identity: self.m_identity,
            m_llt: self.m_llt.clone(),
            newton: Mat::zeros(self.r, self.r),
            newton_ok: false,
            gamma_factored: 0.0,
            kc_factored: vec![0.0; 3 * self.b_phi.nrows()],
            update_w: Mat::zeros(self.r, update_columns(self.r, self.b_phi.nrows())),
            update_alpha: Col::zeros(update_columns(self.r, self.b_phi.nrows())),
            modal: self.modal.clone(),
            modal_used: false,
            active: Mat::zeros(self.b_phi.nrows(), self.r),
            kcb: Mat::zeros(self.b_phi.nrows(), self.r),
            mem: MemBuffer::new(cholesky_in_place_scratch::<f64>(
                self.r,
                Par::Seq,
                Default::default(),
            )),
        }
    }
}

impl SecondOrderSystem for ReducedSystem {
    fn dim(&self) -> usize {
        self.r
    }
    fn pairs(&self) -> usize {
        self.b_phi.nrows() / 3
    }
    fn mul_k_into(&self, q: &[f64], out: &mut [f64]) {
        kernels::mul_col_major(&self.k_cols, q, out);
    }
    fn mul_m_into(&self, x: &[f64], out: &mut [f64]) {
        if self.m_identity {
            out.copy_from_slice(x);
        } else {
            kernels::mul_col_major(&self.m_cols, x, out);
        }
    }
    fn solve_m_in_place(&mut self, x: &mut [f64]) {
        if self.m_identity {
            return;
        }
        let rhs = MatMut::from_column_major_slice_mut(x, self.r, 1);
        solve_in_place_with_conj(
            self.m_llt.as_ref(),
            Conj::No,
            rhs,
            Par::Seq,
            MemStack::new(&mut self.mem),
        );
    }
    fn load_into(&self, t: f64, out: &mut [f64]) {
        self.master_load_into(&self.load.master_at(t), out);
    }
    fn master_load_into(&self, f: &[f64; 6], out: &mut [f64]) {
        for (c, o) in out.iter_mut().enumerate() {
            *o = (0..6).map(|d| self.phi_master[(d, c)] * f[d]).sum();
        }
    }
    fn joint_apply_into(&self, q: &[f64], out: &mut [f64]) {
        kernels::mul_col_major(&self.b_cols, q, out);
    }
    fn joint_transpose_add(&self, p: &[f64], out: &mut [f64]) {
        kernels::mul_t_add_row_major(&self.b_rows, p, out);
    }
    fn joint_apply_rows_into(
        &self,
        q: &[f64],
        all: Option<JointRows>,
        extra: &[usize],
        scratch: &mut [f64],
        out: &mut [f64],
    ) -> bool {
        let w = self.pairs();
        // The same column grouping per entry as the whole product (`kernels`): same bits.
        if all == Some(JointRows::Normal) {
            let g = &mut scratch[..w];
            kernels::mul_col_major(&self.bn_cols, q, g);
            for (z, &v) in g.iter().enumerate() {
                out[3 * z] = v;
            }
        } else if all == Some(JointRows::Tangential) {
            let t = &mut scratch[..2 * w];
            kernels::mul_col_major(&self.bt_cols, q, t);
            for z in 0..w {
                out[3 * z + 1] = t[2 * z];
                out[3 * z + 2] = t[2 * z + 1];
            }
        }
        kernels::mul_rows_listed(&self.b_rows, q, extra, out);
        true
    }
    fn joint_normal_row_norms(&self) -> Option<Vec<f64>> {
        let r = self.r;
        Some(
            (0..self.pairs())
                .map(|z| {
                    let row = &self.b_rows[3 * z * r..3 * z * r + r];
                    row.iter().map(|x| x * x).sum::<f64>().sqrt()
                })
                .collect(),
        )
    }
    fn joint_normal_apply_into(&self, q: &[f64], out: &mut [f64]) {
        let r = self.r;
        for (z, o) in out.iter_mut().enumerate() {
            *o = kernels::dot(&self.b_rows[3 * z * r..3 * z * r + r], q);
        }
    }
    fn joint_normal_gap(&self, q: &[f64], z: usize) -> f64 {
        let r = self.r;
        kernels::dot(&self.b_rows[3 * z * r..3 * z * r + r], q)
    }
    fn joint_pair(&self, q: &[f64], z: usize) -> [f64; 3] {
        let r = self.r;
        [0, 1, 2].map(|i| kernels::dot(&self.b_rows[(3 * z + i) * r..(3 * z + i + 1) * r], q))
    }
    fn joint_pair_tangential(&self, q: &[f64], z: usize) -> [f64; 2] {
        let r = self.r;
        [1, 2].map(|i| kernels::dot(&self.b_rows[(3 * z + i) * r..(3 * z + i + 1) * r], q))
    }
    fn joint_transpose_add_pairs(&self, p: &[f64], pairs: &[usize], out: &mut [f64]) {
        let r = self.r;
        for &z in pairs {
            for i in 3 * z..3 * z + 3 {
                let pi = p[i];
                if pi != 0.0 {
                    kernels::axpy(pi, &self.b_rows[i * r..(i + 1) * r], out);
                }
            }
        }
    }
    fn newton_factor(&mut self, gamma: f64, kc: &[f64]) -> Result<(), Error> {
        let r = self.r;
        let g2 = gamma * gamma;
        self.newton_ok = false;
        self.modal_used = false;
        if let Some(modal) = &mut self.modal {
            if modal.factor(gamma, kc, &self.b_rows) {
                self.modal_used = true;
                self.newton_ok = true;
                return Ok(());
            }
        }
        // M̃ + γ² K̃ column by column from the contiguous copies.
        for j in 0..r {
            let (m, k) = (
                &self.m_cols[j * r..j * r + r],
                &self.k_cols[j * r..j * r + r],
            );
            for ((o, mi), ki) in self.newton.col_mut(j).iter_mut().zip(m).zip(k) {
                *o = mi + g2 * ki;
            }
        }
        // γ² (BΦ)ᵀ K_c (BΦ) over the pairs with a non-zero block, as one matrix product of the
        // gathered rows A (3a × r) and K_c A.
        let mut rows = 0;
        for pair in 0..self.pairs() {
            let block = &kc[9 * pair..9 * pair + 9];
            if block.iter().all(|&x| x == 0.0) {
                continue;
            }
            for c in 0..r {
                let b = [
                    self.b_phi[(3 * pair, c)],
                    self.b_phi[(3 * pair + 1, c)],
                    self.b_phi[(3 * pair + 2, c)],
                ];
                for a in 0..3 {
                    self.active[(rows + a, c)] = b[a];
                    self.kcb[(rows + a, c)] =
                        block[3 * a] * b[0] + block[3 * a + 1] * b[1] + block[3 * a + 2] * b[2];
                }
            }
            rows += 3;
        }
        if rows > 0 {
            matmul(
                self.newton.as_mut(),
                Accum::Add,
                self.active.as_ref().subrows(0, rows).transpose(),
                self.kcb.as_ref().subrows(0, rows),
                g2,
                Par::Seq,
            );
        }
        cholesky_in_place(
            self.newton.as_mut(),
            LltRegularization::default(),
            Par::Seq,
            MemStack::new(&mut self.mem),
            Default::default(),
        )
        .map_err(|e| {
            Error::LinearAlgebra(LinalgError::ReducedNotPositiveDefinite {
                matrix: "reduced Newton matrix",
                r,
                source: Box::new(e),
            })
        })?;
        self.newton_ok = true;
        self.gamma_factored = gamma;
        self.kc_factored.copy_from_slice(kc);
        Ok(())
    }
    fn newton_update(&mut self, kc: &[f64], changed: &[usize]) -> bool {
        // The eigenbasis factor's setup is already of the joint's rank: it refactors.
        if !self.newton_ok || self.modal_used {
            return false;
        }
        let r = self.r;
        let gf = self.gamma_factored;
        let mut cols = 0;
        for &i in changed {
            let (new, old) = (&kc[9 * i..9 * i + 9], &self.kc_factored[9 * i..9 * i + 9]);
            let d: [f64; 9] = std::array::from_fn(|ab| new[ab] - old[ab]);
            // The blocks couple the normal and tangential rows nowhere (module docs of
            // `crate::integrate::mechanical`); a block that did is left to a refactorization.
            if [1, 2, 3, 6].iter().any(|&ab| d[ab] != 0.0) {
                return false;
            }
            for (lambda, v) in block_eigen(d) {
                if lambda == 0.0 {
                    continue;
                }
                // The scratch holds the most columns worth an update (`update_columns`).
                if cols == self.update_alpha.nrows() {
                    return false;
                }
                let row = |a: usize| &self.b_rows[(3 * i + a) * r..(3 * i + a + 1) * r];
                let (b0, b1, b2) = (row(0), row(1), row(2));
                for (c, o) in self.update_w.col_mut(cols).iter_mut().enumerate() {
                    *o = gf * (v[0] * b0[c] + v[1] * b1[c] + v[2] * b2[c]);
                }
                self.update_alpha[cols] = lambda;
                cols += 1;
            }
        }
        if cols > 0 {
            let updated = rank_r_update_clobber(
                self.newton.as_mut(),
                self.update_w.as_mut().subcols_mut(0, cols),
                self.update_alpha
                    .as_mut()
                    .subrows_mut(0, cols)
                    .as_diagonal_mut(),
            );
            if updated.is_err() {
                // The factor is clobbered: the caller refactors.
                self.newton_ok = false;
                return false;
            }
        }
        for &i in changed {
            self.kc_factored[9 * i..9 * i + 9].copy_from_slice(&kc[9 * i..9 * i + 9]);
        }
        true
    }
    fn newton_solve_in_place(&mut self, x: &mut [f64]) {
        if !self.newton_ok {
            x.fill(f64::NAN);
            return;
        }
        if self.modal_used {
            if let Some(modal) = &mut self.modal {
                modal.solve_in_place(x);
                return;
            }
        }
        let rhs = MatMut::from_column_major_slice_mut(x, self.r, 1);
        solve_in_place_with_conj(
            self.newton.as_ref(),
            Conj::No,
            rhs,
            Par::Seq,
            MemStack::new(&mut self.mem),
        );
    }
    fn master_displacement(&self, q: &[f64]) -> [f64; 6] {
        std::array::from_fn(|d| (0..self.r).map(|c| self.phi_master[(d, c)] * q[c]).sum())
    }
    fn coordinate_size_into(&self, out: &mut [f64]) {
        out.copy_from_slice(&self.error_scale.column);
    }
    fn field_dofs(&self) -> usize {
        self.error_scale.field_dofs
    }
}
