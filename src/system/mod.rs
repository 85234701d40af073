//! The narrow second-order-system boundary shared by the full and every reduced model, so one
//! integrator ([`crate::integrate::mechanical`]) runs both (AMfe's "mechanical system").
//!
//! A system is the undamped structure of the paper's eq. (6) (full) or eq. (7) (reduced):
//!
//! ```text
//! M q̈ + K q = f(t) − Bᵀ p(B q, s)
//! ```
//!
//! with `q` the n structural DOF (full: mm, rad) or r generalized coordinates (reduced, `x = Φ q`),
//! `f(t)` the master-node load of the case times its half-cosine ramp (reduced: `Φᵀ f`), `B` the
//! joint operator (3 rows per pair: normal, t1, t2; reduced: `B Φ`) and `p` the pair forces of
//! [`crate::joint::law`]. Besides the operators a system factors and solves the Newton matrix of a
//! second-order model (see `shared/NOTES.md` and [`crate::integrate::mechanical`])
//!
//! ```text
//! A = M + γ² (K + Bᵀ K_c B) ,
//! ```
//!
//! `K_c` block diagonal with one symmetric 3×3 block per pair. [`FullSystem`]: sparse, the
//! pattern of `M + K + Bᵀ B` and its symbolic Cholesky analysis (AMD) built once at construction,
//! a numeric refactorization per setup into preallocated storage. [`ReducedSystem`]: dense r × r,
//! dense Cholesky in place. Neither allocates after construction.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::linalg::cholesky::llt::factor::{cholesky_in_place, cholesky_in_place_scratch};
use faer::linalg::cholesky::llt::solve::solve_in_place_with_conj;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, LltRef, SymbolicCholesky,
    SymmetricOrdering,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::{Conj, Mat, MatMut, Par, Side};

use crate::case::{ContactSpec, LoadSpec};
use crate::error::Error;
use crate::joint::JointOperator;
use crate::linalg::SymCsc;
use crate::model::Model;
use crate::reduction::ReducedModel;

/// A linear undamped second-order system with joint pairs.
pub trait SecondOrderSystem {
    /// Number of coordinates (n full, r reduced).
    fn dim(&self) -> usize;
    /// Number of joint pairs w.
    fn pairs(&self) -> usize;
    /// The case's contact law (k_n, μ, k_t).
    fn contact(&self) -> ContactSpec;
    /// The case's end time, s.
    fn end_time(&self) -> f64;
    /// `out = K q`.
    fn mul_k_into(&self, q: &[f64], out: &mut [f64]);
    /// `out = M x`.
    fn mul_m_into(&self, x: &[f64], out: &mut [f64]);
    /// `x ← M⁻¹ x`.
    fn solve_m_in_place(&mut self, x: &mut [f64]);
    /// `out = f(t)` (N, N·mm; reduced: generalized forces).
    fn load_into(&self, t: f64, out: &mut [f64]);
    /// `out = B q` (3 per pair: gap, slip x, slip z; mm).
    fn joint_apply_into(&self, q: &[f64], out: &mut [f64]);
    /// `out += Bᵀ p`.
    fn joint_transpose_add(&self, p: &[f64], out: &mut [f64]);
    /// Factors `M + γ² (K + Bᵀ K_c B)`; `kc` holds one 3×3 row-major symmetric block per pair
    /// (N/mm). Errors if the matrix is not positive definite.
    fn newton_factor(&mut self, gamma: f64, kc: &[f64]) -> Result<(), Error>;
    /// `x ← A⁻¹ x` with the last [`SecondOrderSystem::newton_factor`].
    fn newton_solve_in_place(&mut self, x: &mut [f64]);
    /// The master node's `[ux, uy, uz (mm), rx, ry, rz (rad)]` at `q`.
    fn master_displacement(&self, q: &[f64]) -> [f64; 6];
    /// The physical size of a unit of each coordinate: the largest nodal displacement (mm) or
    /// rotation (rad) it produces. 1 for physical DOF (the default); for a reduced model the
    /// largest entry of the basis column, so that a tolerance stated in mm applies to the
    /// physical field whatever the basis normalization (a mass-normalized column of the friction
    /// bar moves nodes by ~10² mm per unit).
    fn coordinate_size_into(&self, out: &mut [f64]) {
        out.iter_mut().for_each(|x| *x = 1.0);
    }
}

/// Sparse SPD matrix with a fixed pattern: symbolic Cholesky once, numeric refactorizations and
/// solves into preallocated storage.
struct SparseSpd {
    n: usize,
    pattern: SymbolicSparseColMat<usize>,
    symbolic: SymbolicCholesky<usize>,
    l_values: Vec<f64>,
    mem: MemBuffer,
    factored: bool,
}

impl SparseSpd {
    fn new(n: usize, col_ptr: Vec<usize>, row_idx: Vec<usize>) -> Result<SparseSpd, Error> {
        let pattern = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx);
        let symbolic = factorize_symbolic_cholesky(
            pattern.as_ref(),
            Side::Lower,
            SymmetricOrdering::Amd,
            CholeskySymbolicParams::default(),
        )
        .map_err(|e| Error::LinearAlgebra(format!("symbolic Cholesky ({n}×{n}): {e:?}")))?;
        let req = StackReq::any_of(&[
            symbolic.factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default()),
            symbolic.solve_in_place_scratch::<f64>(1, Par::Seq),
        ]);
        Ok(SparseSpd {
            n,
            l_values: vec![0.0; symbolic.len_val()],
            mem: MemBuffer::new(req),
            pattern,
            symbolic,
            factored: false,
        })
    }

    fn factor(&mut self, values: &[f64], what: &str) -> Result<(), Error> {
        self.factored = false;
        let a = SparseColMatRef::new(self.pattern.as_ref(), values);
        self.symbolic
            .factorize_numeric_llt(
                &mut self.l_values,
                a,
                Side::Lower,
                LltRegularization::default(),
                Par::Seq,
                MemStack::new(&mut self.mem),
                Default::default(),
            )
            .map_err(|e| {
                Error::LinearAlgebra(format!(
                    "{what} ({0}×{0}) is not positive definite: {e:?}",
                    self.n
                ))
            })?;
        self.factored = true;
        Ok(())
    }

    fn solve(&mut self, x: &mut [f64]) {
        if !self.factored {
            x.fill(f64::NAN);
            return;
        }
        let rhs = MatMut::from_column_major_slice_mut(x, self.n, 1);
        LltRef::new(&self.symbolic, &self.l_values).solve_in_place_with_conj(
            Conj::No,
            rhs,
            Par::Seq,
            MemStack::new(&mut self.mem),
        );
    }
}

/// The full FE model as a [`SecondOrderSystem`] (n = model DOF).
pub struct FullSystem {
    stiffness: SymCsc,
    mass: SymCsc,
    joint: JointOperator,
    master: [usize; 6],
    load: LoadSpec,
    contact: ContactSpec,
    end_time: f64,
    mass_llt: SparseSpd,
    /// Pattern of `M + K + BᵀB` (both triangles) and its factorization.
    newton: SparseSpd,
    newton_values: Vec<f64>,
    k_pos: Vec<usize>,
    m_pos: Vec<usize>,
    /// Per pair: (position, 3×3 block index a·3+b, weight b_a,i · b_b,j).
    pair_entries: Vec<Vec<(usize, u8, f64)>>,
}

impl FullSystem {
    /// Builds the system of a model: factors M once and analyses the pattern of the Newton
    /// matrix once.
    pub fn new(model: &Model) -> Result<FullSystem, Error> {
        let n = model.dofs();
        let k = &model.stiffness;
        let m = &model.mass;
        let joint = &model.joint;
        let mass_llt = {
            let mut spd = SparseSpd::new(n, m.col_ptr.clone(), m.row_idx.clone())?;
            spd.factor(&m.values, "the mass matrix")?;
            spd
        };
        let mut cols: Vec<Vec<usize>> = (0..n)
            .map(|j| {
                let mut c = k.row_idx[k.col_ptr[j]..k.col_ptr[j + 1]].to_vec();
                c.extend_from_slice(&m.row_idx[m.col_ptr[j]..m.col_ptr[j + 1]]);
                c
            })
            .collect();
        let pair_rows: Vec<[Vec<(usize, f64)>; 3]> = (0..joint.pairs())
            .map(|i| [0, 1, 2].map(|a| joint.row(3 * i + a).collect()))
            .collect();
        for rows in &pair_rows {
            for ra in rows {
                for rb in rows {
                    for &(cj, _) in rb {
                        cols[cj].extend(ra.iter().map(|&(ci, _)| ci));
                    }
                }
            }
        }
        let mut col_ptr = Vec::with_capacity(n + 1);
        col_ptr.push(0);
        let mut row_idx = Vec::new();
        for c in &mut cols {
            c.sort_unstable();
            c.dedup();
            row_idx.extend_from_slice(c);
            col_ptr.push(row_idx.len());
        }
        let pos = |i: usize, j: usize| -> Result<usize, Error> {
            let col = &row_idx[col_ptr[j]..col_ptr[j + 1]];
            col.binary_search(&i).map(|p| col_ptr[j] + p).map_err(|_| {
                Error::LinearAlgebra(format!("entry ({i}, {j}) missing from the Newton pattern"))
            })
        };
        let mut k_pos = Vec::with_capacity(k.values.len());
        for j in 0..n {
            for p in k.col_ptr[j]..k.col_ptr[j + 1] {
                k_pos.push(pos(k.row_idx[p], j)?);
            }
        }
        let mut m_pos = Vec::with_capacity(m.values.len());
        for j in 0..n {
            for p in m.col_ptr[j]..m.col_ptr[j + 1] {
                m_pos.push(pos(m.row_idx[p], j)?);
            }
        }
        let mut pair_entries = Vec::with_capacity(pair_rows.len());
        for rows in &pair_rows {
            let mut e = Vec::new();
            for (a, ra) in rows.iter().enumerate() {
                for (b, rb) in rows.iter().enumerate() {
                    for &(ci, vi) in ra {
                        for &(cj, vj) in rb {
                            e.push((pos(ci, cj)?, (3 * a + b) as u8, vi * vj));
                        }
                    }
                }
            }
            pair_entries.push(e);
        }
        let nnz = row_idx.len();
        let newton = SparseSpd::new(n, col_ptr, row_idx)?;
        Ok(FullSystem {
            stiffness: k.clone(),
            mass: m.clone(),
            joint: joint.clone(),
            master: model.master_dofs(),
            load: model.load,
            contact: model.contact,
            end_time: model.end_time,
            mass_llt,
            newton,
            newton_values: vec![0.0; nnz],
            k_pos,
            m_pos,
            pair_entries,
        })
    }

    /// Number of stored entries (both triangles) of the Newton matrix pattern.
    pub fn newton_nnz(&self) -> usize {
        self.newton_values.len()
    }
}

impl SecondOrderSystem for FullSystem {
    fn dim(&self) -> usize {
        self.stiffness.n
    }
    fn pairs(&self) -> usize {
        self.joint.pairs()
    }
    fn contact(&self) -> ContactSpec {
        self.contact
    }
    fn end_time(&self) -> f64 {
        self.end_time
    }
    fn mul_k_into(&self, q: &[f64], out: &mut [f64]) {
        self.stiffness.mul_vec(q, out);
    }
    fn mul_m_into(&self, x: &[f64], out: &mut [f64]) {
        self.mass.mul_vec(x, out);
    }
    fn solve_m_in_place(&mut self, x: &mut [f64]) {
        self.mass_llt.solve(x);
    }
    fn load_into(&self, t: f64, out: &mut [f64]) {
        out.fill(0.0);
        let f = self.load.master_at(t);
        for d in 0..6 {
            out[self.master[d]] += f[d];
        }
    }
    fn joint_apply_into(&self, q: &[f64], out: &mut [f64]) {
        self.joint.apply(q, out);
    }
    fn joint_transpose_add(&self, p: &[f64], out: &mut [f64]) {
        self.joint.apply_transpose_add(p, out);
    }
    fn newton_factor(&mut self, gamma: f64, kc: &[f64]) -> Result<(), Error> {
        let g2 = gamma * gamma;
        let vals = &mut self.newton_values;
        vals.fill(0.0);
        for (&p, &v) in self.m_pos.iter().zip(&self.mass.values) {
            vals[p] += v;
        }
        for (&p, &v) in self.k_pos.iter().zip(&self.stiffness.values) {
            vals[p] += g2 * v;
        }
        for (i, entries) in self.pair_entries.iter().enumerate() {
            let block = &kc[9 * i..9 * i + 9];
            if block.iter().all(|&x| x == 0.0) {
                continue;
            }
            for &(p, ab, w) in entries {
                vals[p] += g2 * block[ab as usize] * w;
            }
        }
        self.newton
            .factor(&self.newton_values, "the Newton matrix M + γ²(K + BᵀK_cB)")
    }
    fn newton_solve_in_place(&mut self, x: &mut [f64]) {
        self.newton.solve(x);
    }
    fn master_displacement(&self, q: &[f64]) -> [f64; 6] {
        self.master.map(|d| q[d])
    }
}

/// A reduced model (eq. 7) as a [`SecondOrderSystem`] (r generalized coordinates), dense.
pub struct ReducedSystem {
    r: usize,
    k: Mat<f64>,
    m: Mat<f64>,
    /// `M̃ = I` to round-off (M-orthonormal basis): the M-solve is the identity.
    m_identity: bool,
    m_llt: Mat<f64>,
    b_phi: Mat<f64>,
    /// Rows of Φ at the master DOF (6 × r).
    phi_master: Mat<f64>,
    /// Largest absolute entry of each basis column (mm or rad per unit coordinate).
    column_size: Vec<f64>,
    load: LoadSpec,
    contact: ContactSpec,
    end_time: f64,
    newton: Mat<f64>,
    newton_ok: bool,
    /// Scratch: one pair's `K_c (BΦ)_pair` (3 × r).
    kcb: Mat<f64>,
    mem: MemBuffer,
}

/// Everything a [`ReducedSystem`] is made of, independent of the full model (e.g. read back from
/// an exported reduced model, [`crate::reduction::rom_file`]).
#[derive(Clone, Debug)]
pub struct ReducedParts {
    /// `K̃ = ΦᵀKΦ` (r × r), N/mm per unit coordinate².
    pub k: Mat<f64>,
    /// `M̃ = ΦᵀMΦ` (r × r), t per unit coordinate².
    pub m: Mat<f64>,
    /// `BΦ` (3w × r), rows normal, t1, t2 per pair, mm per unit coordinate.
    pub b_phi: Mat<f64>,
    /// Rows of Φ at the six master DOF (6 × r: ux, uy, uz (mm), rx, ry, rz (rad) per unit).
    pub phi_master: Mat<f64>,
    /// Largest absolute entry of each basis column (mm or rad per unit coordinate): the
    /// coordinate scale of the absolute tolerance.
    pub column_size: Vec<f64>,
    /// Master load and its ramp.
    pub load: LoadSpec,
    /// Contact and friction law.
    pub contact: ContactSpec,
    /// End of the simulated span, s.
    pub end_time: f64,
}

impl ReducedParts {
    /// The parts of a model's reduction, with the case's load and contact law (change them to
    /// run variants on one basis, e.g. `jointrom sweep`).
    pub fn new(model: &Model, rom: &ReducedModel) -> Result<ReducedParts, Error> {
        let r = rom.dim();
        if rom.phi.nrows() != model.dofs() {
            return Err(Error::Invalid(format!(
                "basis has {} rows, the model {} DOF",
                rom.phi.nrows(),
                model.dofs()
            )));
        }
        let master = model.master_dofs();
        let phi_master = Mat::from_fn(6, r, |d, c| rom.phi[(master[d], c)]);
        let column_size: Vec<f64> = (0..r)
            .map(|c| rom.phi.col(c).iter().fold(0.0f64, |m, x| m.max(x.abs())))
            .collect();
        Ok(ReducedParts {
            k: rom.k.clone(),
            m: rom.m.clone(),
            b_phi: rom.b_phi.clone(),
            phi_master,
            column_size,
            load: model.load,
            contact: model.contact,
            end_time: model.end_time,
        })
    }
}

impl ReducedSystem {
    /// Builds the system from a model and its reduction (the load direction is the case's
    /// master load; `rom.load` is not used because the master rows of Φ carry it for any t).
    pub fn new(model: &Model, rom: &ReducedModel) -> Result<ReducedSystem, Error> {
        ReducedSystem::from_parts(ReducedParts::new(model, rom)?)
    }

    /// Builds the system from its parts; checks the dimensions, finiteness and the coordinate
    /// sizes, factors M̃ unless it is the identity.
    pub fn from_parts(p: ReducedParts) -> Result<ReducedSystem, Error> {
        let r = p.k.nrows();
        if p.k.ncols() != r
            || p.m.nrows() != r
            || p.m.ncols() != r
            || p.b_phi.ncols() != r
            || p.b_phi.nrows() % 3 != 0
            || p.phi_master.nrows() != 6
            || p.phi_master.ncols() != r
            || p.column_size.len() != r
        {
            return Err(Error::Invalid(format!(
                "reduced model of dimension {r} has inconsistent K̃ ({}×{}), M̃ ({}×{}), BΦ ({}×{}, \
                 3 rows per pair), master rows ({}×{}) or coordinate sizes ({})",
                p.k.nrows(),
                p.k.ncols(),
                p.m.nrows(),
                p.m.ncols(),
                p.b_phi.nrows(),
                p.b_phi.ncols(),
                p.phi_master.nrows(),
                p.phi_master.ncols(),
                p.column_size.len()
            )));
        }
        for (name, a) in [
            ("K̃", &p.k),
            ("M̃", &p.m),
            ("BΦ", &p.b_phi),
            ("master rows", &p.phi_master),
        ] {
            if a.col_iter().any(|c| c.iter().any(|v| !v.is_finite())) {
                return Err(Error::Invalid(format!(
                    "reduced model: {name} has a non-finite entry"
                )));
            }
        }
        let ReducedParts {
            k,
            m,
            b_phi,
            phi_master,
            column_size,
            load,
            contact,
            end_time,
        } = p;
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
                Error::LinearAlgebra(format!(
                    "reduced mass ({r}×{r}) not positive definite: {e:?}"
                ))
            })?;
        }
        Ok(ReducedSystem {
            r,
            k,
            m,
            m_identity,
            m_llt,
            b_phi,
            phi_master,
            column_size,
            load,
            contact,
            end_time,
            newton: Mat::zeros(r, r),
            newton_ok: false,
            kcb: Mat::zeros(3, r),
            mem,
        })
    }
}

impl SecondOrderSystem for ReducedSystem {
    fn dim(&self) -> usize {
        self.r
    }
    fn pairs(&self) -> usize {
        self.b_phi.nrows() / 3
    }
    fn contact(&self) -> ContactSpec {
        self.contact
    }
    fn end_time(&self) -> f64 {
        self.end_time
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
            Error::LinearAlgebra(format!(
                "reduced Newton matrix ({r}×{r}) not positive definite: {e:?}"
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
