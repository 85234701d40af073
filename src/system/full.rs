//! The full FE model as a second-order system: sparse K and M, the joint operator B, the Newton
//! matrix `M + γ²(K + BᵀK_cB)` on a pattern analysed once and refactored per setup.
//!
//! ## Active-set refreshes without refactoring
//!
//! Between two factorizations the mechanical problem's active-set refresh
//! ([`crate::integrate::mechanical`]) changes the blocks `K_c,i` of the few pairs `i` that
//! switched branch (open, stick, slip). The change of the Newton matrix,
//! `γ_f² Σ_i B_iᵀ ΔK_c,i B_i`, has rank ≤ 3 per pair: [`FullSystem::newton_update`] applies it
//! as an exact low-rank correction of the existing factor ([`crate::linalg::lowrank`]), one
//! column per pair row `a` whose block row changed (`u = B_{3i+a}ᵀ`, sparse) and
//! `C_(ia),(jb) = γ_f² ΔK_c,i[a][b]` (i = j; the blocks are per pair). A pair that switches again
//! before the next factorization reuses its columns (its `ΔK_c` is always against the factored
//! block). When the correction would exceed its capacity
//! ([`FullSystem::set_low_rank_capacity`], [`DEFAULT_LOW_RANK_COLUMNS`] columns) the caller
//! refactors. At 10⁵ DOF a refactorization costs ~13 solves and a new column ~0.07 solve
//! (blocked half solves), each later solve `4 n m` flops more (measured: `linalg::lowrank`). A
//! refresh switches ~3 pairs on the built-in friction bar and ~30 on its 4× refinement
//! (`newton_refresh_pairs / newton_refreshes`), and a switching pair's columns serve all its
//! later switches until the next factorization.

use faer::Mat;

use super::{ReducedSystem, SecondOrderSystem};
use crate::case::LoadSpec;
use crate::error::Error;
use crate::joint::JointOperator;
use crate::linalg::sparse::column_pattern;
use crate::linalg::LinalgError;
use crate::linalg::{LowRankCholesky, SparseCholesky, SymCsc};
use crate::model::Model;

/// Default capacity of the low-rank correction of the Newton factor, columns (module docs):
/// measured on the refined friction bars, see docs/performance/scale.md.
pub const DEFAULT_LOW_RANK_COLUMNS: usize = 96;

/// No column of the low-rank correction.
const NO_SLOT: usize = usize::MAX;

/// The full FE model as a [`SecondOrderSystem`] (n = model DOF).
pub struct FullSystem {
    stiffness: SymCsc,
    mass: SymCsc,
    joint: JointOperator,
    master: [usize; 6],
    load: LoadSpec,
    mass_llt: SparseCholesky,
    /// Pattern of `M + K + BᵀB` (both triangles) and its factorization.
    newton: SparseCholesky,
    newton_values: Vec<f64>,
    k_pos: Vec<usize>,
    m_pos: Vec<usize>,
    /// Per pair: (position, 3×3 block index a·3+b, weight b_a,i · b_b,j).
    pair_entries: Vec<Vec<(usize, u8, f64)>>,
    /// The pair blocks and γ of the last factorization.
    kc_factored: Vec<f64>,
    gamma_factored: f64,
    /// The low-rank correction of the factor since ([`FullSystem::newton_update`]).
    low_rank: LowRankCholesky,
    /// Column of the correction of each pair row (3w; [`NO_SLOT`]: none) and the pair rows
    /// in column order.
    slot: Vec<usize>,
    slot_rows: Vec<usize>,
    /// Pair rows that need a new column (scratch of an update).
    new_rows: Vec<usize>,
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
            let mut spd = SparseCholesky::analyze(n, m.col_ptr.clone(), m.row_idx.clone())?;
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
        let (col_ptr, row_idx) = column_pattern(n, |c, rows| rows.append(&mut cols[c]));
        let pos = |i: usize, j: usize| -> Result<usize, Error> {
            let col = &row_idx[col_ptr[j]..col_ptr[j + 1]];
            col.binary_search(&i).map(|p| col_ptr[j] + p).map_err(|_| {
                Error::LinearAlgebra(LinalgError::MissingEntry {
                    i,
                    j,
                    what: "Newton pattern",
                })
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
        let newton = SparseCholesky::analyze(n, col_ptr, row_idx)?;
        Ok(FullSystem {
            stiffness: k.clone(),
            mass: m.clone(),
            joint: joint.clone(),
            master: model.master_dofs(),
            load: model.load.clone(),
            mass_llt,
            newton,
            newton_values: vec![0.0; nnz],
            k_pos,
            m_pos,
            pair_entries,
            kc_factored: vec![0.0; 9 * joint.pairs()],
            gamma_factored: f64::NAN,
            low_rank: LowRankCholesky::new(n, DEFAULT_LOW_RANK_COLUMNS),
            slot: vec![NO_SLOT; 3 * joint.pairs()],
            slot_rows: Vec::new(),
            new_rows: Vec::new(),
        })
    }

    /// Sets the capacity of the low-rank correction of refreshes (module docs), columns;
    /// 0 refactors at every refresh.
    pub fn set_low_rank_capacity(&mut self, columns: usize) {
        self.clear_low_rank();
        self.low_rank = LowRankCholesky::new(self.stiffness.n, columns);
    }

    /// Drops the low-rank correction (after a refactorization).
    fn clear_low_rank(&mut self) {
        self.low_rank.clear();
        for &r in &self.slot_rows {
            self.slot[r] = NO_SLOT;
        }
        self.slot_rows.clear();
    }

    /// The reduced system on the basis `phi` (n × r): `K̃ = ΦᵀKΦ`, `M̃ = ΦᵀMΦ` (compensated),
    /// `BΦ`, the master rows of Φ and the same load (eq. 7).
    pub fn reduce(&self, phi: Mat<f64>) -> Result<ReducedSystem, Error> {
        ReducedSystem::project(
            &self.stiffness,
            &self.mass,
            &self.joint,
            self.master,
            self.load.clone(),
            phi,
        )
    }
}

impl SecondOrderSystem for FullSystem {
    fn dim(&self) -> usize {
        self.stiffness.n
    }
    fn pairs(&self) -> usize {
        self.joint.pairs()
    }
    fn mul_k_into(&self, q: &[f64], out: &mut [f64]) {
        self.stiffness.mul_vec(q, out);
    }
    fn mul_m_into(&self, x: &[f64], out: &mut [f64]) {
        self.mass.mul_vec(x, out);
    }
    fn solve_m_in_place(&mut self, x: &mut [f64]) {
        self.mass_llt.solve_vec_in_place(x);
    }
    fn load_into(&self, t: f64, out: &mut [f64]) {
        self.master_load_into(&self.load.master_at(t), out);
    }
    fn master_load_into(&self, f: &[f64; 6], out: &mut [f64]) {
        out.fill(0.0);
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
    fn joint_normal_apply_into(&self, q: &[f64], out: &mut [f64]) {
        self.joint.gaps(q, out);
    }
    fn joint_normal_gap(&self, q: &[f64], z: usize) -> f64 {
        self.joint.row_dot(3 * z, q)
    }
    fn joint_pair(&self, q: &[f64], z: usize) -> [f64; 3] {
        [0, 1, 2].map(|i| self.joint.row_dot(3 * z + i, q))
    }
    fn joint_transpose_add_pairs(&self, p: &[f64], pairs: &[usize], out: &mut [f64]) {
        self.joint.apply_transpose_add_rows(p, pairs, out);
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
        self.clear_low_rank();
        self.kc_factored.copy_from_slice(kc);
        self.gamma_factored = gamma;
        Ok(self
            .newton
            .factor(&self.newton_values, "the Newton matrix M + γ²(K + BᵀK_cB)")?)
    }
    fn newton_solve_in_place(&mut self, x: &mut [f64]) {
        self.low_rank.solve_in_place(&mut self.newton, x);
    }
    fn newton_update(&mut self, kc: &[f64], changed: &[usize]) -> bool {
        if !self.newton.is_factored() || self.low_rank.capacity() == 0 {
            return false;
        }
        let delta = |i: usize, ab: usize| kc[9 * i + ab] - self.kc_factored[9 * i + ab];
        self.new_rows.clear();
        for &i in changed {
            for a in 0..3 {
                let row_changed = (0..3).any(|b| delta(i, 3 * a + b) != 0.0);
                if row_changed && self.slot[3 * i + a] == NO_SLOT {
                    self.new_rows.push(3 * i + a);
                }
            }
        }
        if self.low_rank.len() + self.new_rows.len() > self.low_rank.capacity() {
            return false;
        }
        let joint = &self.joint;
        let rows = &self.new_rows;
        let Some(first) = self
            .low_rank
            .add_columns(&self.newton, rows.len(), |j, col| {
                for (c, v) in joint.row(rows[j]) {
                    col[c] += v;
                }
            })
        else {
            return false;
        };
        for (j, &r) in self.new_rows.iter().enumerate() {
            self.slot[r] = first + j;
            self.slot_rows.push(r);
        }
        let g2 = self.gamma_factored * self.gamma_factored;
        for &i in changed {
            for a in 0..3 {
                for b in 0..3 {
                    let (sa, sb) = (self.slot[3 * i + a], self.slot[3 * i + b]);
                    if sa != NO_SLOT && sb != NO_SLOT {
                        self.low_rank.set_coupling(sa, sb, g2 * delta(i, 3 * a + b));
                    }
                }
            }
        }
        self.low_rank.factor()
    }
    fn master_displacement(&self, q: &[f64]) -> [f64; 6] {
        self.master.map(|d| q[d])
    }
}
