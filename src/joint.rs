//! The joint operator: pair kinematics from the structure's DOF.
//!
//! For `w` joint pairs the sparse operator `B` (3w × n) maps the independent DOF `q` to three
//! rows per pair, in the order **normal, t1, t2**:
//!
//! - normal gap `g = u_y(upper) − u_y(lower)` (mm; zero initial clearance, contact when g < 0),
//! - tangential slips `s1 = u_x(upper) − u_x(lower)`, `s2 = u_z(upper) − u_z(lower)` (mm).
//!
//! These are node-to-node quantities at the shell mid-surface nodes, as in the paper's
//! NASTRAN model (Section 4, "node-to-node contact and friction model"). Pair forces
//! `p` (N, same row order, positive pulls the upper node in +y/+x/+z) return to the structure as
//! `f = Bᵀ p`. For a reduced model `q = Φ η` the operator [`JointOperator::reduce`] gives the dense
//! `B Φ` (3w × r) once, so a pseudoforce costs O(w r), never O(n).

use faer::{Mat, MatRef};

use crate::assembly::DofMap;
use crate::error::Error;
use crate::mesh::Mesh;

/// Row kinds within a pair's three rows.
pub const NORMAL: usize = 0;
/// First tangential row (x).
pub const T1: usize = 1;
/// Second tangential row (z).
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
    /// Builds B for the mesh's joint pairs. Errors if a pair node is not an independent node
    /// (clamped or tied pair nodes are rejected by case validation already).
    pub fn new(mesh: &Mesh, map: &DofMap) -> Result<JointOperator, Error> {
        let mut row_ptr = vec![0];
        let mut col_idx = Vec::new();
        let mut values = Vec::new();
        for (k, pair) in mesh.pairs.iter().enumerate() {
            for dir in [1usize, 0, 2] {
                // normal = y (1), t1 = x (0), t2 = z (2)
                let mut entries: Vec<(usize, f64)> = Vec::new();
                for (node, sign) in [(pair.upper, 1.0), (pair.lower, -1.0)] {
                    let dep = map.nodes.get(node).ok_or_else(|| {
                        Error::Invalid(format!(
                            "joint pair {k} names node {node}, which does not exist"
                        ))
                    })?;
                    let terms: Vec<(usize, f64)> = dep[dir].terms().collect();
                    if terms.is_empty() {
                        return Err(Error::Invalid(format!(
                            "joint pair {k}: node {node} is clamped; a clamped node cannot be in a joint pair"
                        )));
                    }
                    for (i, c) in terms {
                        entries.push((i, sign * c));
                    }
                }
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
                row_ptr.push(col_idx.len());
            }
        }
        Ok(JointOperator {
            pairs: mesh.pairs.len(),
            n: map.n,
            row_ptr,
            col_idx,
            values,
        })
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

    /// The normal gaps `g = B_n q` of all pairs (w values).
    pub fn gaps(&self, q: &[f64], out: &mut [f64]) {
        for (k, o) in out.iter_mut().enumerate().take(self.pairs) {
            *o = self.row(3 * k + NORMAL).map(|(c, v)| v * q[c]).sum();
        }
    }

    /// Dense `B Φ` (3w × r) for a basis Φ (n × r).
    pub fn reduce(&self, phi: MatRef<'_, f64>) -> Mat<f64> {
        Mat::from_fn(self.rows(), phi.ncols(), |r, j| {
            self.row(r).map(|(c, v)| v * phi[(c, j)]).sum()
        })
    }
}
