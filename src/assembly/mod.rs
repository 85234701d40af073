//! Global assembly on the independent DOF.
//!
//! Every node carries 6 DOF `[ux, uy, uz, rx, ry, rz]`. The constraints are eliminated exactly
//! (no penalty): clamped DOF are dropped, and the DOF of a rigidly tied (RBE2) slave node are
//! linear combinations of the master's, `u_s = u_m + θ_m × (x_s − x_m)`, `θ_s = θ_m`. Writing
//! all node DOF as `u = T q` with `q` the independent DOF, the assembled matrices are
//! `K = Σ_e T_eᵀ K_e T_e`, `M = Σ_e T_eᵀ M_e T_e`.
//!
//! The independent DOF are numbered node by node in mesh order (free nodes' 6 DOF each), the
//! master node's 6 DOF last; so the first `n − 6` DOF are the Craig–Bampton interior and the
//! last 6 the boundary.
//!
//! The sparsity pattern (compressed sparse columns, full symmetric storage, sorted rows) and
//! each element's scatter positions are computed once by [`Assembler::new`]; values are filled
//! by [`Assembler::assemble`] as often as needed.

use faer::Mat;

use crate::element::{Beam2, Shell4, Weld};
use crate::error::Error;
use crate::linalg::sparse::column_pattern;
use crate::linalg::SymCsc;
use crate::mesh::Mesh;

/// The assembled linear structure: DOF map, stiffness and mass on the independent DOF.
#[derive(Clone, Debug)]
pub struct Structure {
    /// Node DOF → independent DOF.
    pub dof_map: DofMap,
    /// Stiffness, N/mm (N, N·mm/rad for rotational DOF).
    pub stiffness: SymCsc,
    /// Mass, t (t·mm, t·mm² for rotational DOF).
    pub mass: SymCsc,
}

/// Builds every `Shell4`, `Beam2`, area `Weld` and point mass of the mesh and assembles K and M on the
/// independent DOF.
pub fn assemble_structure(mesh: &Mesh) -> Result<Structure, Error> {
    let material = mesh.material;
    let shells = mesh
        .shells
        .iter()
        .map(|s| Shell4::new(s.nodes.map(|i| mesh.nodes[i]), s.thickness, material))
        .collect::<Result<Vec<_>, _>>()?;
    let beams = mesh
        .beams
        .iter()
        .map(|b| {
            Beam2::circular(
                mesh.nodes[b.nodes[0]],
                mesh.nodes[b.nodes[1]],
                b.diameter,
                material,
            )
        })
        .collect::<Result<Vec<_>, _>>()?;
    let welds = Weld::build_all(&mesh.welds, &mesh.nodes, material)?;
    let dof_map = DofMap::new(mesh);
    // Each weld's parts ([`Weld::parts`]) with the weld they belong to.
    let weld_parts = welds
        .iter()
        .enumerate()
        .flat_map(|(i, w)| w.parts().into_iter().map(move |(n, k)| (n, k, i)))
        .collect::<Vec<_>>();
    let element_nodes: Vec<&[usize]> = mesh
        .shells
        .iter()
        .map(|s| &s.nodes[..])
        .chain(mesh.beams.iter().map(|b| &b.nodes[..]))
        .chain(weld_parts.iter().map(|p| p.0))
        .chain(mesh.masses.iter().map(|m| std::slice::from_ref(&m.node)))
        .collect();
    let assembler = Assembler::new(&dof_map, element_nodes);
    let (ns, nb, nw) = (shells.len(), beams.len(), weld_parts.len());
    // The shells a weld's re-meshed neighbourhood replaces (its condensed matrices stand for them).
    let replaced: std::collections::HashSet<usize> = mesh
        .welds
        .iter()
        .filter_map(|w| w.patch.as_ref())
        .flat_map(|p| p.replaced.iter().copied())
        .collect();
    let stiffness = assembler.assemble(|e| match e {
        e if replaced.contains(&e) => Mat::zeros(24, 24),
        e if e < ns => shells[e].stiffness(),
        e if e < ns + nb => beams[e - ns].stiffness(),
        e if e < ns + nb + nw => match weld_parts[e - ns - nb] {
            (_, Some(k), _) => k.clone(),
            (_, None, i) => welds[i].stiffness(),
        },
        _ => Mat::zeros(6, 6),
    });
    let mass = assembler.assemble(|e| match e {
        e if replaced.contains(&e) => Mat::zeros(24, 24),
        e if e < ns => shells[e].mass(),
        e if e < ns + nb => beams[e - ns].mass(),
        e if e < ns + nb + nw => match weld_parts[e - ns - nb] {
            (_, Some(k), _) => Mat::zeros(k.nrows(), k.ncols()),
            (_, None, i) => welds[i].mass(),
        },
        e => {
            let m = mesh.masses[e - ns - nb - nw].matrix();
            Mat::from_fn(6, 6, |a, b| m[a][b])
        }
    });
    Ok(Structure {
        dof_map,
        stiffness,
        mass,
    })
}

/// How one node DOF depends on the independent DOF: `u = Σ coef_k q[idx_k]` (at most 3 terms).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DofDep {
    idx: [usize; 3],
    coef: [f64; 3],
    len: u8,
}

impl DofDep {
    pub(crate) const FIXED: DofDep = DofDep {
        idx: [0; 3],
        coef: [0.0; 3],
        len: 0,
    };
    pub(crate) fn single(i: usize) -> DofDep {
        DofDep {
            idx: [i, 0, 0],
            coef: [1.0, 0.0, 0.0],
            len: 1,
        }
    }
    /// The 6 DOF of a node tied rigidly (RBE2) to a master node with independent DOF `master`
    /// `[ux, uy, uz, rx, ry, rz]`, at offset `r = x_s − x_m` (mm): `u_s = u_m + θ_m × r`,
    /// `θ_s = θ_m`.
    pub(crate) fn rigid_follower(master: [usize; 6], r: [f64; 3]) -> [DofDep; 6] {
        let [ux, uy, uz, rx, ry, rz] = master;
        let mut dep = [DofDep::FIXED; 6];
        dep[0].push(ux, 1.0);
        dep[0].push(ry, r[2]);
        dep[0].push(rz, -r[1]);
        dep[1].push(uy, 1.0);
        dep[1].push(rz, r[0]);
        dep[1].push(rx, -r[2]);
        dep[2].push(uz, 1.0);
        dep[2].push(rx, r[1]);
        dep[2].push(ry, -r[0]);
        dep[3].push(rx, 1.0);
        dep[4].push(ry, 1.0);
        dep[5].push(rz, 1.0);
        dep
    }
    fn push(&mut self, i: usize, c: f64) {
        if c != 0.0 {
            self.idx[self.len as usize] = i;
            self.coef[self.len as usize] = c;
            self.len += 1;
        }
    }
    /// The terms `(independent DOF, coefficient)`.
    pub fn terms(&self) -> impl Iterator<Item = (usize, f64)> + '_ {
        (0..self.len as usize).map(|k| (self.idx[k], self.coef[k]))
    }
    /// The independent DOF if this node DOF is itself independent.
    pub fn as_free(&self) -> Option<usize> {
        (self.len == 1 && self.coef[0] == 1.0).then_some(self.idx[0])
    }
}

/// Map from node DOF to independent DOF.
#[derive(Clone, Debug)]
pub struct DofMap {
    /// Per node, its 6 DOF.
    pub nodes: Vec<[DofDep; 6]>,
    /// Number of independent DOF.
    pub n: usize,
    /// The master node's independent DOF `[ux, uy, uz, rx, ry, rz]` (the last six).
    pub master: [usize; 6],
}

impl DofMap {
    /// Builds the map for a mesh: clamped nodes fixed, tie slaves dependent on the master.
    pub fn new(mesh: &Mesh) -> DofMap {
        let nn = mesh.nodes.len();
        let mut fixed = vec![false; nn];
        for &c in &mesh.clamped {
            fixed[c] = true;
        }
        let mut slave = vec![false; nn];
        for &s in &mesh.tie.slaves {
            slave[s] = true;
        }
        let master_node = mesh.tie.master;
        let mut nodes = vec![[DofDep::FIXED; 6]; nn];
        let mut next = 0;
        for (i, node) in nodes.iter_mut().enumerate() {
            if fixed[i] || slave[i] || i == master_node {
                continue;
            }
            for (d, dep) in node.iter_mut().enumerate() {
                *dep = DofDep::single(next + d);
            }
            next += 6;
        }
        let master = [0, 1, 2, 3, 4, 5].map(|d| next + d);
        for (d, dep) in nodes[master_node].iter_mut().enumerate() {
            *dep = DofDep::single(master[d]);
        }
        let xm = mesh.nodes[master_node];
        for &s in &mesh.tie.slaves {
            let xs = mesh.nodes[s];
            nodes[s] =
                DofDep::rigid_follower(master, [xs[0] - xm[0], xs[1] - xm[1], xs[2] - xm[2]]);
        }
        DofMap {
            nodes,
            n: next + 6,
            master,
        }
    }

    /// The independent DOF of a node's 6 DOF if the node is free (neither clamped nor tied).
    pub(crate) fn free_dofs(&self, node: usize) -> Option<[usize; 6]> {
        let d = &self.nodes[node];
        let mut out = [0; 6];
        for k in 0..6 {
            out[k] = d[k].as_free()?;
        }
        Some(out)
    }

    /// Expands independent DOF values `q` to all node DOF `u = T q` (6 per node).
    pub fn expand(&self, q: &[f64]) -> Vec<f64> {
        let mut u = vec![0.0; 6 * self.nodes.len()];
        for (i, node) in self.nodes.iter().enumerate() {
            for (d, dep) in node.iter().enumerate() {
                u[6 * i + d] = dep.terms().map(|(k, c)| c * q[k]).sum();
            }
        }
        u
    }
}

/// One element's scatter information.
#[derive(Clone, Debug)]
struct Scatter {
    /// Independent DOF touched by the element (sorted).
    dofs: Vec<usize>,
    /// `T_e`: element DOF × `dofs` (None when it is the identity map onto `dofs` in order).
    te: Option<Mat<f64>>,
    /// Position in `values` of entry `(dofs[a], dofs[b])` at `a * len + b`.
    positions: Vec<usize>,
}

/// Pattern-once, values-many assembler for elements given by their node lists.
#[derive(Clone, Debug)]
pub struct Assembler {
    n: usize,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    elements: Vec<Scatter>,
}

impl Assembler {
    /// Builds the sparsity pattern for elements with the given node lists (6 DOF per node).
    pub fn new<'a>(map: &DofMap, element_nodes: impl IntoIterator<Item = &'a [usize]>) -> Self {
        let n = map.n;
        let mut elements = Vec::new();
        for nodes in element_nodes {
            let deps: Vec<DofDep> = nodes.iter().flat_map(|&i| map.nodes[i]).collect();
            let mut dofs: Vec<usize> = deps.iter().flat_map(|d| d.terms().map(|t| t.0)).collect();
            dofs.sort_unstable();
            dofs.dedup();
            let identity = deps.len() == dofs.len()
                && deps.iter().zip(&dofs).all(|(d, &k)| d.as_free() == Some(k));
            let te = (!identity).then(|| {
                let mut t = Mat::zeros(deps.len(), dofs.len());
                for (a, d) in deps.iter().enumerate() {
                    for (k, c) in d.terms() {
                        let b = dofs.binary_search(&k).expect("dof listed");
                        t[(a, b)] += c;
                    }
                }
                t
            });
            elements.push(Scatter {
                dofs,
                te,
                positions: Vec::new(),
            });
        }
        // The pattern column by column from the DOF → element incidence: each column's rows are
        // the DOF of its elements, sorted locally (no global list of all element DOF pairs: at
        // 10⁶ DOF that was 10⁸ pairs to sort).
        let mut inc_ptr = vec![0usize; n + 1];
        for e in &elements {
            for &d in &e.dofs {
                inc_ptr[d + 1] += 1;
            }
        }
        for j in 0..n {
            inc_ptr[j + 1] += inc_ptr[j];
        }
        let mut cursor = inc_ptr.clone();
        let mut inc = vec![0usize; inc_ptr[n]];
        for (k, e) in elements.iter().enumerate() {
            for &d in &e.dofs {
                inc[cursor[d]] = k;
                cursor[d] += 1;
            }
        }
        let (col_ptr, row_idx) = column_pattern(n, |c, rows| {
            for &k in &inc[inc_ptr[c]..inc_ptr[c + 1]] {
                rows.extend_from_slice(&elements[k].dofs);
            }
        });
        drop(inc);
        // Positions: the element's sorted DOF walk each of its columns' sorted rows once.
        for e in &mut elements {
            let len = e.dofs.len();
            e.positions = vec![0; len * len];
            for (b, &c) in e.dofs.iter().enumerate() {
                let rows = &row_idx[col_ptr[c]..col_ptr[c + 1]];
                let mut p = 0;
                for (a, &r) in e.dofs.iter().enumerate() {
                    while rows[p] < r {
                        p += 1;
                    }
                    debug_assert_eq!(rows[p], r, "pattern holds the pair");
                    e.positions[a * len + b] = col_ptr[c] + p;
                }
            }
        }
        Assembler {
            n,
            col_ptr,
            row_idx,
            elements,
        }
    }

    /// Number of stored entries.
    pub fn nnz(&self) -> usize {
        self.row_idx.len()
    }

    /// Assembles `Σ T_eᵀ A_e T_e` from the element matrices (in node-DOF order) into a new
    /// matrix with the shared pattern.
    pub fn assemble(&self, element_matrix: impl Fn(usize) -> Mat<f64>) -> SymCsc {
        let mut values = vec![0.0; self.row_idx.len()];
        self.assemble_into(element_matrix, &mut values);
        SymCsc {
            n: self.n,
            col_ptr: self.col_ptr.clone(),
            row_idx: self.row_idx.clone(),
            values,
        }
    }

    /// Like [`Assembler::assemble`] but into an existing value array (same pattern).
    pub(crate) fn assemble_into(
        &self,
        element_matrix: impl Fn(usize) -> Mat<f64>,
        values: &mut [f64],
    ) {
        values.iter_mut().for_each(|v| *v = 0.0);
        for (e, sc) in self.elements.iter().enumerate() {
            let ae = element_matrix(e);
            let reduced;
            let a = match &sc.te {
                None => &ae,
                Some(t) => {
                    reduced = t.transpose() * &ae * t;
                    &reduced
                }
            };
            let len = sc.dofs.len();
            for i in 0..len {
                for j in 0..len {
                    // Both triangles from the same bits: `Tᵀ A T` (and a rotated element's
                    // `Tᵀ A T`) is symmetric only up to round-off.
                    values[sc.positions[i * len + j]] += 0.5 * (a[(i, j)] + a[(j, i)]);
                }
            }
        }
    }
}
