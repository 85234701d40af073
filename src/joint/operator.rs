//! The joint operator: pair kinematics from the structure's DOF.
//!
//! For `w` joint pairs the sparse operator `B` (3w × n) maps the independent DOF `q` to three
//! rows per pair, in the order **normal, t1, t2**:
//!
//! - normal gap `g = n · (u(upper) − u(lower))` (mm; zero initial clearance, contact when g < 0),
//! - tangential slips `s1 = t1 · (u(upper) − u(lower))`, `s2 = t2 · (…)` (mm),
//!
//! with the pair's orthonormal frame `n, t1, t2` ([`PairFrame`]; for generated sheets `n = +y`,
//! `t1 = +x`, `t2 = +z`, so the rows are `u_y`, `u_x`, `u_z` differences).
//!
//! These are node-to-node quantities at the shell mid-surface nodes, as in the paper's
//! NASTRAN model (Section 4, "node-to-node contact and friction model"). With the slips taken
//! at the contacting faces (`"slip": "faces"`, [`PairFrame::face_offsets`] `[t_l/2, t_u/2]`),
//! the tangential rows add each sheet's rotation: the face point `x ∓ (t/2) n` moves by
//! `u ∓ (t/2) θ × n`, so `s = t·(u_upper − u_lower) − (t_u/2)(n × t)·θ_upper −
//! (t_l/2)(n × t)·θ_lower` — the interleaf slip of sheets that bend together about their own
//! mid-surfaces, which the mid-surface translations miss. The normal row is unchanged. Pair forces
//! `p` (N, same row order, positive pulls the upper node along +n/+t1/+t2) return to the structure as
//! `f = Bᵀ p`. For a reduced model `q = Φ η` the operator [`JointOperator::reduce`] gives the dense
//! `B Φ` (3w × r) once, so a pseudoforce costs O(w r), never O(n).

use faer::{Mat, MatRef};

use crate::assembly::DofMap;
use crate::error::{Error, JointError};
use crate::joint::PairFrame;

/// Row kinds within a pair's three rows.
pub const NORMAL: usize = 0;
/// First tangential row (t1; x for generated sheets).
pub const T1: usize = 1;
/// Second tangential row (t2; z for generated sheets).
pub const T2: usize = 2;

/// Sparse joint operator B in compressed rows.
#[derive(Clone, Debug)]
pub struct JointOperator {
    /// Number of pairs w.
    pairs: usize,
    /// Number of independent DOF n.
    n: usize,
    row_ptr: Vec<usize>,
    col_idx: Vec<usize>,
    values: Vec<f64>,
}

impl JointOperator {
    /// Builds B for joint pairs with their frames. Errors if a pair node does not exist or has
    /// a translation that is not an independent DOF (clamped or without a matrix row).
    pub fn new(pairs: &[PairFrame], map: &DofMap) -> Result<JointOperator, Error> {
        let mut row_ptr = vec![0];
        let mut col_idx = Vec::new();
        let mut values = Vec::new();
        for (k, pair) in pairs.iter().enumerate() {
            for dir in pair.directions() {
                let mut entries: Vec<(usize, f64)> = Vec::new();
                let sides = [
                    (pair.upper, 1.0, pair.face_offsets[1]),
                    (pair.lower, -1.0, pair.face_offsets[0]),
                ];
                for (node, sign, offset) in sides {
                    let dep = map
                        .nodes
                        .get(node)
                        .ok_or_else(|| Error::Joint(JointError::UnknownNode { pair: k, node }))?;
                    // The slips at the faces: the rotations carry the faces along (a fixed
                    // rotation contributes nothing).
                    if offset != 0.0 {
                        let rot = pair.face_rotation_row(dir, offset);
                        for (axis, &w) in rot.iter().enumerate() {
                            if w != 0.0 {
                                entries.extend(dep[3 + axis].terms().map(|(i, c)| (i, w * c)));
                            }
                        }
                    }
                    for (axis, &w) in dir.iter().enumerate() {
                        if w == 0.0 {
                            continue;
                        }
                        let terms: Vec<(usize, f64)> = dep[axis].terms().collect();
                        if terms.is_empty() {
                            return Err(JointError::FixedNode {
                                pair: k,
                                node,
                                axis: ["x", "y", "z"][axis],
                            }
                            .into());
                        }
                        for (i, c) in terms {
                            entries.push((i, sign * w * c));
                        }
                    }
                }
                push_row(entries, &mut col_idx, &mut values);
                row_ptr.push(col_idx.len());
            }
        }
        Ok(JointOperator {
            pairs: pairs.len(),
            n: map.n,
            row_ptr,
            col_idx,
            values,
        })
    }

    /// Builds B from explicit rows: `rows[3k + d]` lists `(independent DOF, coefficient)` of
    /// contact point k's row d (normal, t1, t2) over `n` DOF — the kinematics of a contact point
    /// that is an interpolation of several nodes' DOF rather than a node pair. Entries of one
    /// DOF are summed, zeros dropped. `rows.len()` must be a multiple of 3 and every column
    /// below `n` (checked by the caller that built them; a violation panics in debug builds).
    pub fn from_rows(rows: &[Vec<(usize, f64)>], n: usize) -> JointOperator {
        debug_assert!(rows.len() % 3 == 0);
        let mut row_ptr = vec![0];
        let mut col_idx = Vec::new();
        let mut values = Vec::new();
        for row in rows {
            debug_assert!(row.iter().all(|e| e.0 < n));
            push_row(row.clone(), &mut col_idx, &mut values);
            row_ptr.push(col_idx.len());
        }
        JointOperator {
            pairs: rows.len() / 3,
            n,
            row_ptr,
            col_idx,
            values,
        }
    }

    /// Number of joint pairs w.
    pub fn pairs(&self) -> usize {
        self.pairs
    }

    /// Number of rows, 3w.
    pub fn rows(&self) -> usize {
        3 * self.pairs
    }

    /// Number of structural DOF n.
    pub fn dofs(&self) -> usize {
        self.n
    }

    /// The (column, value) entries of row `r`.
    pub fn row(&self, r: usize) -> impl Iterator<Item = (usize, f64)> + '_ {
        (self.row_ptr[r]..self.row_ptr[r + 1]).map(|p| (self.col_idx[p], self.values[p]))
    }

    /// `out = B q` (3w values).
    pub fn apply(&self, q: &[f64], out: &mut [f64]) {
        for (r, o) in out.iter_mut().enumerate().take(self.rows()) {
            *o = self.row(r).map(|(c, v)| v * q[c]).sum();
        }
    }

    /// `f += Bᵀ p`.
    pub fn apply_transpose_add(&self, p: &[f64], f: &mut [f64]) {
        for r in 0..self.rows() {
            let pr = p[r];
            if pr != 0.0 {
                for (c, v) in self.row(r) {
                    f[c] += v * pr;
                }
            }
        }
    }

    /// `(B q)_r`: row r's product with q.
    pub fn row_dot(&self, r: usize, q: &[f64]) -> f64 {
        self.row(r).map(|(c, v)| v * q[c]).sum()
    }

    /// `f += Σ_{k ∈ pairs} B_kᵀ p_k` over the three rows of each listed pair.
    pub fn apply_transpose_add_rows(&self, p: &[f64], pairs: &[usize], f: &mut [f64]) {
        for &k in pairs {
            for r in 3 * k..3 * k + 3 {
                let pr = p[r];
                if pr != 0.0 {
                    for (c, v) in self.row(r) {
                        f[c] += v * pr;
                    }
                }
            }
        }
    }

    /// The normal gaps `g = B_n q` of all pairs (w values).
    pub fn gaps(&self, q: &[f64], out: &mut [f64]) {
        for (k, o) in out.iter_mut().enumerate().take(self.pairs) {
            *o = self.row(3 * k + NORMAL).map(|(c, v)| v * q[c]).sum();
        }
    }

    /// Multiplies the three rows of pair k by `weights[k]` (w values, > 0): the weighted pair
    /// kinematics of a contact law per area (`crate::model::per_area`).
    pub fn weight_pairs(&mut self, weights: &[f64]) {
        for (k, &w) in weights.iter().enumerate().take(self.pairs) {
            let (a, b) = (self.row_ptr[3 * k], self.row_ptr[3 * k + 3]);
            self.values[a..b].iter_mut().for_each(|v| *v *= w);
        }
    }

    /// Dense `B Φ` (3w × r) for a basis Φ (n × r).
    pub fn reduce(&self, phi: MatRef<'_, f64>) -> Mat<f64> {
        Mat::from_fn(self.rows(), phi.ncols(), |r, j| {
            self.row(r).map(|(c, v)| v * phi[(c, j)]).sum()
        })
    }
}

/// Appends one CSR row from unsorted `(column, coefficient)` entries: sorted by column, the
/// entries of one column summed in their order, zeros dropped.
fn push_row(mut entries: Vec<(usize, f64)>, col_idx: &mut Vec<usize>, values: &mut Vec<f64>) {
    entries.sort_by_key(|e| e.0);
    let mut merged: Vec<(usize, f64)> = Vec::new();
    for (i, c) in entries {
        match merged.last_mut() {
            Some(last) if last.0 == i => last.1 += c,
            _ => merged.push((i, c)),
        }
    }
    for (i, c) in merged {
        if c != 0.0 {
            col_idx.push(i);
            values.push(c);
        }
    }
}
