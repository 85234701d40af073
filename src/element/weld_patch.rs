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

use faer::Mat;

use super::shell4::dkmq_phi;
use super::{Material, Shell4};
use crate::error::{ElementError, Error};
use crate::linalg::{SparseCholesky, SymCsc};
use crate::mesh::{line_cell, NuggetLayer, PatchLayer, WeldElem, WeldPatch};

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

/// Accumulates the blocks `rr` (dense), `ri` (dense, nr × ni) and `ii` (triplets) of
/// `Aᵀ K A` from element matrices.
struct Blocks {
    rr: Mat<f64>,
    ri: sprs::TriMat<f64>,
    ii: sprs::TriMat<f64>,
}

impl Blocks {
    fn new(nr: usize, ni: usize) -> Blocks {
        Blocks {
            rr: Mat::zeros(nr, nr),
            ri: sprs::TriMat::new((nr, ni)),
            ii: sprs::TriMat::new((ni, ni)),
        }
    }

    /// `K̂_ri X` (nr × nr) for `x` (ni × nr), `K̂_ri` sparse.
    fn ri_times(&self, x: &Mat<f64>) -> Mat<f64> {
        let ri: sprs::CsMat<f64> = self.ri.to_csr();
        let nr = x.ncols();
        let mut out = Mat::<f64>::zeros(ri.rows(), nr);
        // Column by column: X's columns are contiguous.
        for j in 0..nr {
            let xj = x.col(j);
            for (r, row) in ri.outer_iterator().enumerate() {
                out[(r, j)] = row.iter().map(|(i, &v)| v * xj[i]).sum::<f64>();
            }
        }
        out
    }

    /// The terms of fine DOF `c` of a node with `role`: (is retained, index, coefficient).
    fn terms(role: Role, c: usize) -> ([(bool, usize, f64); 4], usize) {
        const Z: (bool, usize, f64) = (true, 0, 0.0);
        match role {
            Role::Retained(r) => ([(true, 6 * r + c, 1.0), Z, Z, Z], 1),
            Role::Edge(a, b, t, side) => match side.bending_terms(t, c) {
                Some([ta, tb, wa, wb]) => (
                    [
                        (true, 6 * a + ta.0, ta.1),
                        (true, 6 * b + tb.0, tb.1),
                        (true, 6 * a + wa.0, wa.1),
                        (true, 6 * b + wb.0, wb.1),
                    ],
                    4,
                ),
                None => ([(true, 6 * a + c, 1.0 - t), (true, 6 * b + c, t), Z, Z], 2),
            },
            Role::Internal(i) => ([(false, 6 * i + c, 1.0), Z, Z, Z], 1),
        }
    }

    /// Adds element matrix `k` over nodes with `roles`.
    fn add(&mut self, roles: &[Role], k: &Mat<f64>) {
        let dofs = 6 * roles.len();
        // Each DOF's terms once (a side's are polynomials in t), not once per matrix entry.
        let terms: Vec<_> = (0..dofs)
            .map(|a| Blocks::terms(roles[a / 6], a % 6))
            .collect();
        for (a, &(ta, na)) in terms.iter().enumerate() {
            for (b, &(tb, nb)) in terms.iter().enumerate() {
                let v = k[(a, b)];
                if v == 0.0 {
                    continue;
                }
                for &(ra, ia, ca) in &ta[..na] {
                    for &(rb, ib, cb) in &tb[..nb] {
                        let w = v * ca * cb;
                        match (ra, rb) {
                            (true, true) => self.rr[(ia, ib)] += w,
                            (true, false) => self.ri.add_triplet(ia, ib, w),
                            (false, false) => self.ii.add_triplet(ia, ib, w),
                            (false, true) => {}
                        }
                    }
                }
            }
        }
    }

    /// The `ii` block as a [`SymCsc`] (duplicates summed).
    fn ii_matrix(&self) -> SymCsc {
        let csc: sprs::CsMat<f64> = self.ii.to_csc();
        SymCsc {
            n: csc.rows(),
            col_ptr: csc.indptr().raw_storage().to_vec(),
            row_idx: csc.indices().to_vec(),
            values: csc.data().to_vec(),
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

/// The nugget between two consecutive sheets as a bonded slab ([`super::weld_slab`]),
/// integrated by the nugget's sampling points on the small shells, added to `k`.
fn add_slab(
    k: &mut Blocks,
    roles: &[Role],
    layers: &[PatchLayer],
    nugget: &[NuggetLayer],
    material: Material,
    index: usize,
) -> Result<(), Error> {
    let (lower, upper) = (&nugget[0], &nugget[1]);
    super::weld_slab::check_layers(index, lower, upper)?;
    let gap = upper.y - lower.y;
    let mut ke = Mat::<f64>::zeros(48, 48);
    for (pa, pb) in lower.points.iter().zip(&upper.points) {
        ke.fill(0.0);
        super::weld_slab::add_point(
            &mut ke,
            (pa, shape_derivatives(&layers[0], pa.xz)),
            (pb, shape_derivatives(&layers[1], pb.xz)),
            gap,
            material,
        );
        let r: Vec<Role> = pa
            .nodes
            .iter()
            .chain(&pb.nodes)
            .map(|&n| roles[n])
            .collect();
        k.add(&r, &ke);
    }
    Ok(())
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
pub(super) fn condense(
    weld: &WeldElem,
    patch: &WeldPatch,
    material: Material,
) -> Result<Condensed, Error> {
    let retained = retained_nodes(patch);
    let mut internal = 0usize;
    let roles: Vec<Role> = patch
        .layers
        .iter()
        .flat_map(|l| layer_roles(l, &retained, &mut internal, material))
        .collect();
    let (nr, ni) = (6 * retained.len(), 6 * internal);
    let mut k = Blocks::new(nr, ni);
    let mut m = Blocks::new(nr, ni);
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
                let xyz = |n: usize| {
                    let (a, b) = ((n - offset) / nz, (n - offset) % nz);
                    [layer.fine_xs[a], layer.y, layer.fine_zs[b]]
                };
                let shell = Shell4::new(ids.map(xyz), layer.thickness, material)?;
                let r = ids.map(|n| roles[n]);
                k.add(&r, &shell.stiffness());
                m.add(&r, &shell.mass());
            }
        }
        offset += layer.fine_xs.len() * nz;
    }
    for (l, pair) in patch.nugget.windows(2).enumerate() {
        add_slab(
            &mut k,
            &roles,
            &patch.layers[l..l + 2],
            pair,
            material,
            weld.index,
        )?;
    }
    let what = |source| ElementError::InWeld {
        index: weld.index,
        source: Box::new(ElementError::NeighbourhoodStiffness { source }),
    };
    let kii = k.ii_matrix();
    let chol = SparseCholesky::new(&kii).map_err(what)?;
    // X = −K_ii⁻¹ K_ir.
    let mut x = Mat::<f64>::zeros(ni, nr);
    for (&v, (r, i)) in k.ri.triplet_iter() {
        x[(i, r)] -= v;
    }
    chol.solve_in_place(&mut x);
    let mut kc = k.rr.clone() + k.ri_times(&x);
    let mii = m.ii_matrix();
    // M̂_ii X column by column (X and the product are column-major: contiguous columns).
    let mut mx = Mat::<f64>::zeros(ni, nr);
    for j in 0..nr {
        let (xj, mut out) = (x.col(j), mx.col_mut(j));
        for col in 0..ni {
            let xv = xj[col];
            if xv == 0.0 {
                continue;
            }
            for p in mii.col_ptr[col]..mii.col_ptr[col + 1] {
                out[mii.row_idx[p]] += mii.values[p] * xv;
            }
        }
    }
    let mri_x = m.ri_times(&x);
    let mut mc = m.rr.clone() + &mri_x + mri_x.transpose() + x.transpose() * &mx;
    for a in [&mut kc, &mut mc] {
        for i in 0..nr {
            for j in 0..i {
                let v = 0.5 * (a[(i, j)] + a[(j, i)]);
                a[(i, j)] = v;
                a[(j, i)] = v;
            }
        }
    }
    Ok(Condensed {
        nodes: retained,
        stiffness: kc,
        mass: mc,
    })
}
