//! The full FE model as a second-order system: sparse K and M, the joint operator B, the Newton
//! matrix `M + γ²(K + BᵀK_cB)` on a pattern analysed once and refactored per setup.

use faer::Mat;

use super::{ReducedSystem, SecondOrderSystem};
use crate::case::LoadSpec;
use crate::error::Error;
use crate::joint::JointOperator;
use crate::linalg::{SparseCholesky, SymCsc};
use crate::model::Model;

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
                Error::LinearAlgebra(
                    format!("entry ({i}, {j}) missing from the Newton pattern").into(),
                )
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
        })
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
        self.newton.solve_vec_in_place(x);
    }
    fn master_displacement(&self, q: &[f64]) -> [f64; 6] {
        self.master.map(|d| q[d])
    }
}
