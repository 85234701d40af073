//! A reduced model (eq. 7) as a second-order system: `M̃ q̈ + K̃ q = Φᵀ f(t) − (BΦ)ᵀ p`, dense
//! r × r, the Newton matrix `M̃ + γ²(K̃ + (BΦ)ᵀ K_c BΦ)` factored in place per setup.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::{
    cholesky_in_place, cholesky_in_place_scratch, LltRegularization,
};
use faer::linalg::cholesky::llt::solve::solve_in_place_with_conj;
use faer::{Conj, Mat, MatMut, Par};

use super::SecondOrderSystem;
use crate::case::LoadSpec;
use crate::error::Error;
use crate::joint::JointOperator;
use crate::linalg::compensated::compensated_gram;
use crate::linalg::LinalgError;
use crate::linalg::SymCsc;
use crate::model::Model;

/// A reduced model (eq. 7) as a [`SecondOrderSystem`] (r generalized coordinates), dense.
pub struct ReducedSystem {
    r: usize,
    /// The basis Φ (n × r), mm or rad per unit coordinate; `None` for a reduced model read from
    /// a file (which carries the operators below, not Φ).
    pub phi: Option<Mat<f64>>,
    /// `K̃ = ΦᵀKΦ` (r × r), N/mm per unit coordinate².
    pub k: Mat<f64>,
    /// `M̃ = ΦᵀMΦ` (r × r), t per unit coordinate²; the identity for an M-orthonormal basis.
    pub m: Mat<f64>,
    /// `BΦ` (3w × r), rows normal, t1, t2 per pair (as [`crate::joint::JointOperator`]), mm per
    /// unit coordinate.
    pub b_phi: Mat<f64>,
    /// Rows of Φ at the six master DOF (6 × r: ux, uy, uz (mm), rx, ry, rz (rad) per unit).
    pub phi_master: Mat<f64>,
    /// Largest absolute entry of each basis column (mm or rad per unit coordinate): the
    /// coordinate scale of the absolute tolerance.
    pub column_size: Vec<f64>,
    /// Master load and its ramp (change it to run load variants on one basis).
    pub load: LoadSpec,
    /// `M̃ = I` to round-off (M-orthonormal basis): the M-solve is the identity.
    m_identity: bool,
    m_llt: Mat<f64>,
    newton: Mat<f64>,
    newton_ok: bool,
    /// Scratch: one pair's `K_c (BΦ)_pair` (3 × r).
    kcb: Mat<f64>,
    mem: MemBuffer,
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
            model.load,
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
            return Err(Error::Invalid(format!(
                "basis has {} rows, the model {} DOF",
                phi.nrows(),
                k.n
            )));
        }
        let r = phi.ncols();
        let phi_master = Mat::from_fn(6, r, |d, c| phi[(master[d], c)]);
        let column_size: Vec<f64> = (0..r)
            .map(|c| phi.col(c).iter().fold(0.0f64, |m, x| m.max(x.abs())))
            .collect();
        ReducedSystem::from_matrices(
            compensated_gram(k, phi.as_ref()),
            compensated_gram(m, phi.as_ref()),
            joint.reduce(phi.as_ref()),
            (phi_master, column_size),
            load,
            Some(phi),
        )
    }

    /// Builds the system from its matrices (e.g. read back from an exported reduced model,
    /// [`crate::reduction::rom_file`]), with the basis if known; checks the dimensions,
    /// finiteness and the coordinate sizes, factors M̃ unless it is the identity.
    ///
    /// `k` = K̃ (r × r, N/mm per unit coordinate²), `m` = M̃ (r × r, t per unit coordinate²),
    /// `b_phi` = BΦ (3w × r, mm per unit), `master` = (the rows of Φ at the six master DOF,
    /// 6 × r; the largest absolute entry of each basis column, r), `load` the master load and
    /// its ramp, `phi` the basis if known (n × r).
    pub fn from_matrices(
        k: Mat<f64>,
        m: Mat<f64>,
        b_phi: Mat<f64>,
        master: (Mat<f64>, Vec<f64>),
        load: LoadSpec,
        phi: Option<Mat<f64>>,
    ) -> Result<ReducedSystem, Error> {
        let (phi_master, column_size) = master;
        let r = k.nrows();
        if let Some(phi) = &phi {
            if phi.ncols() != r {
                return Err(Error::Invalid(format!(
                    "basis has {} columns, the reduced model dimension {r}",
                    phi.ncols()
                )));
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
            return Err(Error::Invalid(format!(
                "reduced model of dimension {r} has inconsistent K̃ ({}×{}), M̃ ({}×{}), BΦ ({}×{}, \
                 3 rows per pair), master rows ({}×{}) or coordinate sizes ({})",
                k.nrows(),
                k.ncols(),
                m.nrows(),
                m.ncols(),
                b_phi.nrows(),
                b_phi.ncols(),
                phi_master.nrows(),
                phi_master.ncols(),
                column_size.len()
            )));
        }
        for (name, a) in [
            ("K̃", &k),
            ("M̃", &m),
            ("BΦ", &b_phi),
            ("master rows", &phi_master),
        ] {
            if a.col_iter().any(|c| c.iter().any(|v| !v.is_finite())) {
                return Err(Error::Invalid(format!(
                    "reduced model: {name} has a non-finite entry"
                )));
            }
        }
        if let Some(c) = column_size
            .iter()
            .position(|s| !(s.is_finite() && *s > 0.0))
        {
            return Err(Error::Invalid(format!(
                "basis column {c} is zero or not finite"
            )));
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
                Error::LinearAlgebra(LinalgError::caused_by(
                    format!("reduced mass ({r}×{r}) not positive definite: {e:?}"),
                    e,
                ))
            })?;
        }
        Ok(ReducedSystem {
            r,
            phi,
            k,
            m,
            m_identity,
            m_llt,
            b_phi,
            phi_master,
            column_size,
            load,
            newton: Mat::zeros(r, r),
            newton_ok: false,
            kcb: Mat::zeros(3, r),
            mem,
        })
    }

    /// Reduced dimension r.
    pub fn dim(&self) -> usize {
        self.r
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
            phi_master: self.phi_master.clone(),
            column_size: self.column_size.clone(),
            load: self.load,
            m_identity: self.m_identity,
            m_llt: self.m_llt.clone(),
            newton: Mat::zeros(self.r, self.r),
            newton_ok: false,
            kcb: Mat::zeros(3, self.r),
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
        dense_mul(&self.k, q, out);
    }
    fn mul_m_into(&self, x: &[f64], out: &mut [f64]) {
        dense_mul(&self.m, x, out);
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
        let f = self.load.master_at(t);
        for (c, o) in out.iter_mut().enumerate() {
            *o = (0..6).map(|d| self.phi_master[(d, c)] * f[d]).sum();
        }
    }
    fn joint_apply_into(&self, q: &[f64], out: &mut [f64]) {
        dense_mul(&self.b_phi, q, out);
    }
    fn joint_transpose_add(&self, p: &[f64], out: &mut [f64]) {
        for (c, o) in out.iter_mut().enumerate() {
            *o += dot(col(&self.b_phi, c), p);
        }
    }
    fn newton_factor(&mut self, gamma: f64, kc: &[f64]) -> Result<(), Error> {
        let r = self.r;
        let g2 = gamma * gamma;
        self.newton_ok = false;
        for j in 0..r {
            for i in 0..r {
                self.newton[(i, j)] = self.m[(i, j)] + g2 * self.k[(i, j)];
            }
        }
        for pair in 0..self.pairs() {
            let block = &kc[9 * pair..9 * pair + 9];
            if block.iter().all(|&x| x == 0.0) {
                continue;
            }
            for a in 0..3 {
                for c in 0..r {
                    self.kcb[(a, c)] = (0..3)
                        .map(|b| block[3 * a + b] * self.b_phi[(3 * pair + b, c)])
                        .sum();
                }
            }
            for j in 0..r {
                for i in j..r {
                    let v: f64 = (0..3)
                        .map(|a| self.b_phi[(3 * pair + a, i)] * self.kcb[(a, j)])
                        .sum();
                    self.newton[(i, j)] += g2 * v;
                }
            }
        }
        cholesky_in_place(
            self.newton.as_mut(),
            LltRegularization::default(),
            Par::Seq,
            MemStack::new(&mut self.mem),
            Default::default(),
        )
        .map_err(|e| {
            Error::LinearAlgebra(LinalgError::caused_by(
                format!("reduced Newton matrix ({r}×{r}) not positive definite: {e:?}"),
                e,
            ))
        })?;
        self.newton_ok = true;
        Ok(())
    }
    fn newton_solve_in_place(&mut self, x: &mut [f64]) {
        if !self.newton_ok {
            x.fill(f64::NAN);
            return;
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
        out.copy_from_slice(&self.column_size);
    }
}

/// Column `j` of a dense matrix as a slice (faer's `Mat` stores columns contiguously).
fn col(a: &Mat<f64>, j: usize) -> &[f64] {
    a.col(j)
        .try_as_col_major()
        .expect("columns of an owned Mat are contiguous")
        .as_slice()
}

/// `a · b` with eight independent partial sums (so the loop vectorizes), compiled for
/// AVX-512 / AVX2 as well and dispatched at run time.
#[multiversion::multiversion(targets("x86_64+avx512f+avx512vl", "x86_64+avx2"))]
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let mut acc = [0.0f64; 8];
    let ca = a.chunks_exact(8);
    let cb = b.chunks_exact(8);
    let (ra, rb) = (ca.remainder(), cb.remainder());
    for (x, y) in ca.zip(cb) {
        for k in 0..8 {
            acc[k] += x[k] * y[k];
        }
    }
    let mut tail = 0.0;
    for (x, y) in ra.iter().zip(rb) {
        tail += x * y;
    }
    ((acc[0] + acc[4]) + (acc[1] + acc[5])) + ((acc[2] + acc[6]) + (acc[3] + acc[7])) + tail
}

/// `out += s · a` (vectorized; see [`dot`]).
#[multiversion::multiversion(targets("x86_64+avx512f+avx512vl", "x86_64+avx2"))]
fn axpy(s: f64, a: &[f64], out: &mut [f64]) {
    for (o, &v) in out.iter_mut().zip(a) {
        *o += v * s;
    }
}

/// `out = A x` for a dense matrix, column by column.
fn dense_mul(a: &Mat<f64>, x: &[f64], out: &mut [f64]) {
    out.fill(0.0);
    for (j, &xj) in x.iter().enumerate().take(a.ncols()) {
        if xj != 0.0 {
            axpy(xj, col(a, j), out);
        }
    }
}
