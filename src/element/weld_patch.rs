//! The re-meshed neighbourhood of an area spot weld (a weld's `local_mesh`; by default,
//! `"auto"`, at d/16 wherever a welded sheet's shells have a side longer than d/2): small shells
//! around the nugget, condensed onto the sheets' own nodes.
//!
//! # Why
//!
//! The area weld (`super::weld`) converges under uniform refinement, but only once the shells
//! around the nugget are about 0.6 mm or smaller: on the friction bar the ratio of consecutive
//! changes of the frequencies is ≈ 2 up to 8× the paper's mesh (pre-asymptotic) and 3.6–4.1
//! from 8× to 16× (docs/validation/welds.md). On the paper's mesh (5 × 12.5 mm
//! shells around a 5 mm nugget) the local field of the sheets around the nugget is not
//! resolved. Refining the whole structured sheet for it multiplies the DOF by ~10–40; this
//! module resolves only the neighbourhood and keeps the sheets' DOF.
//!
//! # The patch
//!
//! On each welded sheet the rectangle of the sheet's shells that meet the square of half-width
//! 2d around the weld centre (`crate::mesh`'s `WeldPatch`) is cut into small `Shell4`s of at
//! most `local_mesh` per side, and the nugget is sampled on those (`crate::mesh`'s nugget
//! rule, on the small shells). The small shells' nodes are of three kinds:
//!
//! - on a node of the sheet: that node (its 6 DOF are the model's);
//! - on a side of the rectangle shared with the sheet's other shells, between two of its
//!   nodes `a`, `b`: the side's field as those shells have it — linear in the membrane
//!   translations and the other rotations, DKMQ's quadratic tangential rotation and the
//!   matching (thin: Hermite-cubic) deflection (`Side`), so the patch follows them;
//! - otherwise (inside, or on the sheet's free edge): internal, condensed.
//!
//! # The nugget: a bonded slab
//!
//! With the neighbourhood resolved, the nugget is what the converged solid model has: the two
//! sheets fused over the disc, the bonded slab of [`super::weld_slab`], integrated on the small
//! shells. On the sheets' own coarse shells this slab locks (+26 % on f10 at the paper's mesh: a
//! 5 mm disc inside 5 × 12.5 mm shells bonds whole shells), and the RBE3 + beam weld of
//! `super::weld` converges to a limit 4–5 % soft in f7–f10 (it ties only the disc's mean rigid
//! motion, not the fused disc's composite bending); on the re-meshed neighbourhood the slab
//! neither locks nor leaves that out (docs/validation/welds.md).
//!
//! # Condensation
//!
//! With the constraint written as `u_fine = A q_r + E q_i` (retained DOF `q_r`, internal `q_i`),
//! the small shells and the slab give `K_f`, `M_f` (the slab has no mass: its material is the
//! sheets'), and
//!
//! ```text
//! K̂ = Aᵀ K_f A,  …  (the blocks rr, ri, ii)
//! X = −K̂_ii⁻¹ K̂_ir                                  (one sparse Cholesky, nr right-hand sides)
//! K_patch = K̂_rr + K̂_ri X                           (static condensation: exact in statics)
//! M_patch = M̂_rr + M̂_ri X + Xᵀ M̂_ir + Xᵀ M̂_ii X     (Guyan: the internal field follows statically)
//! ```
//!
//! on the retained nodes; the sheets' own shells of the rectangles are left out of the assembly.
//! Guyan's mass is accurate while the patch's own (fixed-boundary) frequencies lie far above the
//! structure's (a 20 × 25 mm patch of 0.5 mm steel: above 10 kHz).

use faer::linalg::matmul::matmul;
use faer::reborrow::{Reborrow, ReborrowMut};
use faer::{Accum, Mat, Par};

use super::shell4::dkmq_phi;
use super::{Material, Shell4};
use crate::error::{ElementError, Error};
use crate::linalg::{SparseCholesky, SymCsc};
use crate::mesh::{line_cell, PatchLayer, WeldElem, WeldPatch};

/// What a small shell node is ([`condense`]'s module docs).
#[derive(Clone, Copy, Debug)]
enum Role {
    /// A node of the sheet: retained DOF block `r`.
    Retained(usize),
    /// On a shared side between retained blocks `a` and `b`, at `t` ∈ (0, 1) from `a`: the
    /// side's field as the sheet's shells beyond have it ([`Side`]).
    Edge(usize, usize, f64, Side),
    /// Internal DOF block `i`.
    Internal(usize),
}

/// A side of the rectangle shared with the sheet's other shells, between its nodes `a` and
/// `b` (global x or z direction; the sheet's normal is y).
///
/// The shells beyond are [`Shell4`]s, whose bending field along an edge is DKMQ's: with
/// `w = u_y`, the tangential rotation `β_s = (θ × ŷ)·s` (`−θ_z` along x, `θ_x` along z),
/// `Δβ = c (w_b − w_a + L/2 (β_s,a + β_s,b))`, `c = −3 / (2 L (1 + φ))`:
///
/// ```text
/// β_s(t) = (1 − t) β_s,a + t β_s,b + 4 t (1 − t) Δβ
/// w(t)   = w_a + ∫₀^{tL} (γ − β_s) ds,   γ = −⅔ φ Δβ   (w(1) = w_b by Δβ's definition)
/// ```
///
/// — the Hermite cubic of the edge's end values when thin. The side's other DOF (in-plane
/// translations, the rotation about the side's normal in-plane direction, the drilling
/// rotation) are linear, as the shells' membrane and bending fields along an edge. Why: sides
/// that are linear in everything are stiffer than the shells they join, and on coarse sheets
/// that stiffness dominates the weld (the measured comparison of both side forms against a
/// converged solid is in docs/validation/welds.md).
#[derive(Clone, Copy, Debug)]
struct Side {
    /// Along global x (else z).
    along_x: bool,
    /// Side length L between `a` and `b`, mm.
    length: f64,
    /// DKMQ's φ of the side ([`dkmq_phi`]), dimensionless.
    phi: f64,
}

impl Side {
    /// For fine DOF `c` at `t`: the four terms `(DOF of a, coef), (DOF of b, coef), (DOF of a,
    /// coef), (DOF of b, coef)` of `w` (c = 1) or of the tangential rotation's DOF, `None` for
    /// the linear DOF.
    fn bending_terms(&self, t: f64, c: usize) -> Option<[(usize, f64); 4]> {
        // β_s = σ θ_rs.
        let (rs, sigma) = if self.along_x { (5, -1.0) } else { (3, 1.0) };
        let (l, phi) = (self.length, self.phi);
        let cc = -1.5 / (l * (1.0 + phi));
        if c == rs {
            let q = 4.0 * t * (1.0 - t);
            Some([
                (rs, 1.0 - t + 0.5 * q * cc * l),
                (rs, t + 0.5 * q * cc * l),
                (1, -q * sigma * cc),
                (1, q * sigma * cc),
            ])
        } else if c == 1 {
            // ∫₀^{tL} of the quadratic part and γ: h Δβ.
            let h = l * (2.0 / 3.0 * phi * t + 2.0 * t * t - 4.0 / 3.0 * t * t * t);
            Some([
                (1, 1.0 + h * cc),
                (1, -h * cc),
                (
                    rs,
                    -sigma * l * (t - 0.5 * t * t) - 0.5 * h * cc * l * sigma,
                ),
                (rs, -sigma * l * 0.5 * t * t - 0.5 * h * cc * l * sigma),
            ])
        } else {
            None
        }
    }
}

/// The index of each fine line that is one of `coarse` (by position), `None` otherwise.
fn coarse_index(fine: &[f64], coarse: &[f64]) -> Vec<Option<usize>> {
    let scale = (coarse[coarse.len() - 1] - coarse[0]).abs().max(1.0);
    fine.iter()
        .map(|&v| coarse.iter().position(|&c| (c - v).abs() <= 1e-9 * scale))
        .collect()
}

/// The roles of one layer's small-shell nodes (z fastest), numbering new retained nodes in
/// `retained` (sheet node ids) and internal nodes from `*internal`.
fn layer_roles(
    layer: &PatchLayer,
    retained: &[usize],
    internal: &mut usize,
    material: Material,
) -> Vec<Role> {
    let side = |along_x: bool, l: f64| Side {
        along_x,
        length: l,
        phi: dkmq_phi(layer.thickness, l, material.poisson_ratio),
    };
    let (cx, cz) = (
        coarse_index(&layer.fine_xs, &layer.xs),
        coarse_index(&layer.fine_zs, &layer.zs),
    );
    let (nfx, nfz, ncz) = (layer.fine_xs.len(), layer.fine_zs.len(), layer.zs.len());
    let block = |node: usize| {
        retained
            .binary_search(&node)
            .expect("every node of the rectangle is retained")
    };
    let coarse = |i: usize, k: usize| block(layer.nodes[i * ncz + k]);
    let mut roles = Vec::with_capacity(nfx * nfz);
    for ii in 0..nfx {
        for kk in 0..nfz {
            let x_side = (ii == 0 && !layer.free_side[0]) || (ii + 1 == nfx && !layer.free_side[1]);
            let z_side = (kk == 0 && !layer.free_side[2]) || (kk + 1 == nfz && !layer.free_side[3]);
            let role = match (cx[ii], cz[kk]) {
                (Some(i), Some(k)) => Role::Retained(coarse(i, k)),
                (Some(i), None) if x_side => {
                    let (k, t) = line_cell(&layer.zs, layer.fine_zs[kk]);
                    let l = layer.zs[k + 1] - layer.zs[k];
                    Role::Edge(coarse(i, k), coarse(i, k + 1), t, side(false, l))
                }
                (None, Some(k)) if z_side => {
                    let (i, t) = line_cell(&layer.xs, layer.fine_xs[ii]);
                    let l = layer.xs[i + 1] - layer.xs[i];
                    Role::Edge(coarse(i, k), coarse(i + 1, k), t, side(true, l))
                }
                _ => {
                    *internal += 1;
                    Role::Internal(*internal - 1)
                }
            };
            roles.push(role);
        }
    }
    roles
}

/// The `Aᵀ K A` terms of a small-shell node's fine DOF `c` on the retained DOF: `(index,
/// coefficient)` pairs, of which the first `.1` are used. Internal nodes have none.
fn retained_terms(role: Role, c: usize) -> ([(usize, f64); 4], usize) {
    const Z: (usize, f64) = (0, 0.0);
    match role {
        Role::Retained(r) => ([(6 * r + c, 1.0), Z, Z, Z], 1),
        Role::Edge(a, b, t, side) => match side.bending_terms(t, c) {
            Some([ta, tb, wa, wb]) => (
                [
                    (6 * a + ta.0, ta.1),
                    (6 * b + tb.0, tb.1),
                    (6 * a + wa.0, wa.1),
                    (6 * b + wb.0, wb.1),
                ],
                4,
            ),
            None => ([(6 * a + c, 1.0 - t), (6 * b + c, t), Z, Z], 2),
        },
        Role::Internal(_) => ([Z; 4], 0),
    }
}

/// Calls `add(nodes, k, m)` for every element of the neighbourhood: each small shell (4 nodes,
/// stiffness and consistent mass) and each sampling point of the bonded slab between two
/// consecutive sheets (8 nodes, stiffness only); `nodes` in the small shells' node numbering
/// (layer by layer, z fastest). With `matrices` false, `k` and `m` are empty (the pattern pass).
fn for_each_element(
    patch: &WeldPatch,
    material: Material,
    index: usize,
    matrices: bool,
    mut add: impl FnMut(&[usize], &Mat<f64>, Option<&Mat<f64>>),
) -> Result<(), Error> {
    let empty = Mat::<f64>::zeros(0, 0);
    let mut offset = 0usize;
    for layer in &patch.layers {
        let nz = layer.fine_zs.len();
        let node = |i: usize, kk: usize| offset + i * nz + kk;
        for i in 0..layer.fine_xs.len() - 1 {
            for kk in 0..nz - 1 {
                let ids = [
                    node(i, kk),
                    node(i + 1, kk),
                    node(i + 1, kk + 1),
                    node(i, kk + 1),
                ];
                if !matrices {
                    add(&ids, &empty, Some(&empty));
                    continue;
                }
                let xyz = |n: usize| {
                    let (a, b) = ((n - offset) / nz, (n - offset) % nz);
                    [layer.fine_xs[a], layer.y, layer.fine_zs[b]]
                };
                let shell = Shell4::new(ids.map(xyz), layer.thickness, material)?;
                add(&ids, &shell.stiffness(), Some(&shell.mass()));
            }
        }
        offset += layer.fine_xs.len() * nz;
    }
    for (l, pair) in patch.nugget.windows(2).enumerate() {
        let (layers, (lower, upper)) = (&patch.layers[l..l + 2], (&pair[0], &pair[1]));
        super::weld_slab::check_layers(index, lower, upper)?;
        let gap = upper.y - lower.y;
        let mut ke = Mat::<f64>::zeros(48, 48);
        for (pa, pb) in lower.points.iter().zip(&upper.points) {
            let mut ids = [0usize; 8];
            ids[..4].copy_from_slice(&pa.nodes);
            ids[4..].copy_from_slice(&pb.nodes);
            if !matrices {
                add(&ids, &empty, None);
                continue;
            }
            ke.fill(0.0);
            super::weld_slab::add_point(
                &mut ke,
                (pa, shape_derivatives(&layers[0], pa.xz)),
                (pb, shape_derivatives(&layers[1], pb.xz)),
                gap,
                material,
            );
            add(&ids, &ke, None);
        }
    }
    Ok(())
}

/// Where `Aᵀ K A`'s entries go: the small-shell nodes' roles, the sparsity pattern of the
/// internal block (node by node: every internal node's 6 columns hold the same rows, the 6 DOF
/// of each internal node it shares an element with) and the internal nodes that share an element
/// with a retained or side node (the only rows of the `ir` block, "slots").
struct Layout {
    roles: Vec<Role>,
    /// Per internal node, the internal nodes it couples with (itself included), ascending.
    couples: Vec<Vec<usize>>,
    /// Per internal node, the offset of its first column's values; the last entry is the count.
    base: Vec<usize>,
    /// Per internal node, its slot (position in `slots`), or `usize::MAX`.
    slot: Vec<usize>,
    /// The internal nodes with a slot, ascending.
    slots: Vec<usize>,
}

impl Layout {
    fn new(
        patch: &WeldPatch,
        roles: Vec<Role>,
        internal: usize,
        material: Material,
        index: usize,
    ) -> Result<Layout, Error> {
        let mut couples: Vec<Vec<usize>> = vec![Vec::new(); internal];
        let mut slot = vec![usize::MAX; internal];
        for_each_element(patch, material, index, false, |nodes, _, _| {
            let mut inner = [0usize; 8];
            let mut n = 0;
            let mut outer = false;
            for &v in nodes {
                match roles[v] {
                    Role::Internal(i) => {
                        inner[n] = i;
                        n += 1;
                    }
                    _ => outer = true,
                }
            }
            for &i in &inner[..n] {
                couples[i].extend_from_slice(&inner[..n]);
                if outer {
                    slot[i] = 0;
                }
            }
        })?;
        let mut base = Vec::with_capacity(internal + 1);
        let mut at = 0usize;
        for c in &mut couples {
            c.sort_unstable();
            c.dedup();
            base.push(at);
            at += 36 * c.len();
        }
        base.push(at);
        let slots: Vec<usize> = (0..internal).filter(|&i| slot[i] == 0).collect();
        for (s, &i) in slots.iter().enumerate() {
            slot[i] = s;
        }
        Ok(Layout {
            roles,
            couples,
            base,
            slot,
            slots,
        })
    }

    /// The position in the internal block's values of row DOF `6 i + c`, column DOF `6 j + d`.
    fn at(&self, i: usize, c: usize, j: usize, d: usize) -> usize {
        let pos = self.couples[j]
            .binary_search(&i)
            .expect("coupled nodes share an element");
        self.base[j] + d * 6 * self.couples[j].len() + 6 * pos + c
    }

    /// The internal block with `values` (both triangles, rows ascending).
    fn matrix(&self, values: Vec<f64>) -> SymCsc {
        let ni = 6 * self.couples.len();
        let mut col_ptr = Vec::with_capacity(ni + 1);
        let mut row_idx = Vec::with_capacity(values.len());
        col_ptr.push(0);
        for c in &self.couples {
            for _ in 0..6 {
                row_idx.extend(c.iter().flat_map(|&i| (0..6).map(move |d| 6 * i + d)));
                col_ptr.push(row_idx.len());
            }
        }
        SymCsc {
            n: ni,
            col_ptr,
            row_idx,
            values,
        }
    }
}

/// The blocks of `Aᵀ K A`: `rr` (dense, nr × nr), `ri` on the slots' DOF (dense,
/// nr × 6·slots) and `ii`'s values on the [`Layout`]'s pattern.
struct Blocks {
    rr: Mat<f64>,
    ri: Mat<f64>,
    ii: Vec<f64>,
}

impl Blocks {
    fn new(nr: usize, layout: &Layout) -> Blocks {
        Blocks {
            rr: Mat::zeros(nr, nr),
            ri: Mat::zeros(nr, 6 * layout.slots.len()),
            ii: vec![0.0; layout.base[layout.couples.len()]],
        }
    }

    /// Adds element matrix `k` over the small-shell nodes `nodes`.
    fn add(&mut self, layout: &Layout, nodes: &[usize], k: &Mat<f64>) {
        let roles: Vec<Role> = nodes.iter().map(|&v| layout.roles[v]).collect();
        // Each DOF's terms once (a side's are polynomials in t), not once per matrix entry.
        let terms: Vec<_> = (0..6 * nodes.len())
            .map(|a| retained_terms(roles[a / 6], a % 6))
            .collect();
        for (q, &rq) in roles.iter().enumerate() {
            for (p, &rp) in roles.iter().enumerate() {
                match (rp, rq) {
                    (Role::Internal(i), Role::Internal(j)) => {
                        for d in 0..6 {
                            let at = self::Layout::at(layout, i, 0, j, d);
                            for c in 0..6 {
                                self.ii[at + c] += k[(6 * p + c, 6 * q + d)];
                            }
                        }
                    }
                    // The transpose of `ri`.
                    (Role::Internal(_), _) => {}
                    (_, Role::Internal(j)) => {
                        let col = 6 * layout.slot[j];
                        for d in 0..6 {
                            for c in 0..6 {
                                let v = k[(6 * p + c, 6 * q + d)];
                                if v == 0.0 {
                                    continue;
                                }
                                let (t, n) = terms[6 * p + c];
                                for &(r, coef) in &t[..n] {
                                    self.ri[(r, col + d)] += coef * v;
                                }
                            }
                        }
                    }
                    _ => {
                        for d in 0..6 {
                            let (tb, nb) = terms[6 * q + d];
                            for c in 0..6 {
                                let v = k[(6 * p + c, 6 * q + d)];
                                if v == 0.0 {
                                    continue;
                                }
                                let (ta, na) = terms[6 * p + c];
                                for &(ra, ca) in &ta[..na] {
                                    for &(rb, cb) in &tb[..nb] {
                                        self.rr[(ra, rb)] += v * ca * cb;
                                    }
                                }
                            }
                        }
                    }
                }
            }
        }
    }
}

/// Derivatives `(∂N/∂x, ∂N/∂z)` (1/mm) of the bilinear shape functions of the small shell of
/// `layer` containing `p`, in [`ShellElem`](crate::mesh::ShellElem) node order.
fn shape_derivatives(layer: &PatchLayer, p: [f64; 2]) -> ([f64; 4], [f64; 4]) {
    let cell = |lines: &[f64], v: f64| {
        let (j, t) = line_cell(lines, v);
        (t, lines[j + 1] - lines[j])
    };
    let ((xi, hx), (eta, hz)) = (cell(&layer.fine_xs, p[0]), cell(&layer.fine_zs, p[1]));
    (
        [-(1.0 - eta) / hx, (1.0 - eta) / hx, eta / hx, -eta / hx],
        [-(1.0 - xi) / hz, -xi / hz, xi / hz, (1.0 - xi) / hz],
    )
}

/// The patch's retained sheet nodes (sorted), every small-shell node's role (layer by layer)
/// and the number of internal nodes.
fn patch_roles(patch: &WeldPatch, material: Material) -> (Vec<usize>, Vec<Role>, usize) {
    let retained = retained_nodes(patch);
    let mut internal = 0usize;
    let roles: Vec<Role> = patch
        .layers
        .iter()
        .flat_map(|l| layer_roles(l, &retained, &mut internal, material))
        .collect();
    (retained, roles, internal)
}

/// A condensed patch: its retained sheet nodes (sorted) and the stiffness and mass on their DOF.
pub(super) struct Condensed {
    pub(super) nodes: Vec<usize>,
    pub(super) stiffness: Mat<f64>,
    pub(super) mass: Mat<f64>,
}

/// The sheet nodes a re-meshed neighbourhood stands on, sorted (the order of its condensed
/// matrices' DOF).
pub(super) fn retained_nodes(patch: &WeldPatch) -> Vec<usize> {
    let mut nodes: Vec<usize> = patch
        .layers
        .iter()
        .flat_map(|l| l.nodes.iter().copied())
        .collect();
    nodes.sort_unstable();
    nodes.dedup();
    nodes
}

/// The condensed patch of `weld` (module docs).
///
/// Nothing of the internal size is dense but `X` (ni × nr, which the Guyan mass needs whole):
/// `K̂_ii`, `M̂_ii` are assembled straight into their pattern, `K̂_ri`, `M̂_ri` are kept only on the
/// internal DOF that share an element with a retained or side node, `X` comes from one sparse
/// Cholesky with nr right-hand sides, and the mass's `Xᵀ (M̂_ir + M̂_ii X)` is formed a block of
/// columns at a time, lower block triangle only (the product is symmetric).
pub(super) fn condense(
    weld: &WeldElem,
    patch: &WeldPatch,
    material: Material,
    par: Par,
) -> Result<Condensed, Error> {
    let (retained, roles, internal) = patch_roles(patch, material);
    let layout = Layout::new(patch, roles, internal, material, weld.index)?;
    let (nr, ni) = (6 * retained.len(), 6 * internal);
    let mut k = Blocks::new(nr, &layout);
    let mut m = Blocks::new(nr, &layout);
    for_each_element(patch, material, weld.index, true, |nodes, ke, me| {
        k.add(&layout, nodes, ke);
        if let Some(me) = me {
            m.add(&layout, nodes, me);
        }
    })?;
    let what = |source| ElementError::InWeld {
        index: weld.index,
        source: Box::new(ElementError::NeighbourhoodStiffness { source }),
    };
    // The pattern without the element matrices' structural zeros (less fill in the factor).
    let kii = without_zeros(layout.matrix(std::mem::take(&mut k.ii)));
    let chol = SparseCholesky::new_with(&kii, par).map_err(what)?;
    drop(kii);
    // X = −K̂_ii⁻¹ K̂_ir; K̂_ir is nonzero on the slots' rows only.
    let slot_dofs: Vec<usize> = layout
        .slots
        .iter()
        .flat_map(|&i| (0..6).map(move |d| 6 * i + d))
        .collect();
    let mut x = Mat::<f64>::zeros(ni, nr);
    for (s, &row) in slot_dofs.iter().enumerate() {
        for r in 0..nr {
            x[(row, r)] = -k.ri[(r, s)];
        }
    }
    chol.solve_in_place(&mut x);
    drop(chol);
    let xs = Mat::from_fn(slot_dofs.len(), nr, |s, j| x[(slot_dofs[s], j)]);
    let mut kc = k.rr;
    matmul(&mut kc, Accum::Add, &k.ri, &xs, 1.0, par);
    let mut mc = m.rr;
    matmul(&mut mc, Accum::Add, &m.ri, &xs, 1.0, par);
    // The consistent mass couples only like DOF: most of its pattern's entries are zero.
    let mii = without_zeros(layout.matrix(m.ii));
    guyan_inner(&mut mc, &mii, &m.ri, &slot_dofs, &x, par);
    for i in 0..nr {
        for j in 0..i {
            let v = 0.5 * (kc[(i, j)] + kc[(j, i)]);
            kc[(i, j)] = v;
            kc[(j, i)] = v;
            // `guyan_inner` completed the lower triangle.
            mc[(j, i)] = mc[(i, j)];
        }
    }
    Ok(Condensed {
        nodes: retained,
        stiffness: kc,
        mass: mc,
    })
}

/// `a` without its stored zeros.
fn without_zeros(a: SymCsc) -> SymCsc {
    let mut col_ptr = Vec::with_capacity(a.n + 1);
    let (mut row_idx, mut values) = (Vec::new(), Vec::new());
    col_ptr.push(0);
    for j in 0..a.n {
        for p in a.col_ptr[j]..a.col_ptr[j + 1] {
            if a.values[p] != 0.0 {
                row_idx.push(a.row_idx[p]);
                values.push(a.values[p]);
            }
        }
        col_ptr.push(row_idx.len());
    }
    SymCsc {
        n: a.n,
        col_ptr,
        row_idx,
        values,
    }
}

/// Adds `Xᵀ (M̂_ir + M̂_ii X)` to the lower triangle of `mc` (and to some entries above it), a
/// block of columns J at a time: `Z_J = M̂_iJ + M̂_ii X_J` (ni × |J|), then rows from J's first
/// on, `X[:, J₀..]ᵀ Z_J`. `mri` holds `M̂_ri` on the DOF `slot_dofs`.
fn guyan_inner(
    mc: &mut Mat<f64>,
    mii: &SymCsc,
    mri: &Mat<f64>,
    slot_dofs: &[usize],
    x: &Mat<f64>,
    par: Par,
) {
    const BLOCK: usize = 64;
    let (ni, nr) = (x.nrows(), x.ncols());
    let mut z = Mat::<f64>::zeros(ni, BLOCK.min(nr));
    for j0 in (0..nr).step_by(BLOCK) {
        let w = BLOCK.min(nr - j0);
        let mut zj = z.as_mut().subcols_mut(0, w);
        for j in 0..w {
            let xj = x
                .col(j0 + j)
                .try_as_col_major()
                .expect("a matrix's columns are contiguous")
                .as_slice();
            let mut zc = zj.rb_mut().col_mut(j);
            let out = zc
                .rb_mut()
                .try_as_col_major_mut()
                .expect("a matrix's columns are contiguous")
                .as_slice_mut();
            // Row i of the symmetric M̂_ii is its column i: a gather, one store per row.
            for (i, o) in out.iter_mut().enumerate() {
                let (a, b) = (mii.col_ptr[i], mii.col_ptr[i + 1]);
                *o = mii.row_idx[a..b]
                    .iter()
                    .zip(&mii.values[a..b])
                    .map(|(&r, &v)| v * xj[r])
                    .sum::<f64>();
            }
            for (s, &row) in slot_dofs.iter().enumerate() {
                out[row] += mri[(j0 + j, s)];
            }
        }
        matmul(
            mc.as_mut().submatrix_mut(j0, j0, nr - j0, w),
            Accum::Add,
            x.as_ref().subcols(j0, nr - j0).transpose(),
            zj.rb(),
            1.0,
            par,
        );
    }
}

#[cfg(test)]
mod tests;
