//! `Weld`: an area spot weld joining a stack of sheets over its nugget disc (NASTRAN CWELD with
//! ELPAT, or ACM2, in spirit).
//!
//! A point weld — a beam between two single nodes — loads each sheet at one node, so its
//! footprint is set by the mesh: the local flexibility of a shell under a point load grows
//! without bound as the mesh is refined (logarithmically for membrane shear, like the
//! displacement under a point load in plane stress), and the point-weld model has no converged
//! answer. The area weld spreads the connection over the nugget's real area.
//!
//! # Interpolation constraint (RBE3) on each sheet
//!
//! The nugget disc (diameter d, clipped to the sheets: see `crate::mesh`'s nugget sampling) is
//! represented on sheet ℓ by points `p_k` with area weights `w_k`, each inside a shell whose
//! bilinear shape functions give the sheet's mid-surface translations and rotations there,
//! `u_k = Σ_a N_a(p_k) u_a`, `θ_k = Σ_a N_a(p_k) θ_a`. A reference point `c_ℓ` on the sheet's
//! mid-surface at the weld centre carries six DOF `[u_c, θ_c]`, defined as the weighted
//! least-squares rigid-body fit of the sampled motion (NASTRAN's RBE3 with translations and the
//! bending rotations of the independent points, rotations weighted by the square of the
//! characteristic length `L_c`, the mean distance of the points from the centre):
//!
//! ```text
//! [u_c; θ_c] = argmin Σ_k w_k ( |u_k − u_c − θ_c × r_k|² + L_c² |P (θ_k − θ_c)|² ),  r_k = p_k − c_ℓ
//!            = A⁻¹ Σ_k w_k (G_kᵀ u_k + L_c² Pᵀ P θ_k),
//!   G_k = [I  S(r_k)],  S(r) θ = θ × r,   A = Σ_k w_k (G_kᵀ G_k + L_c² Pᵀ P)
//! ```
//!
//! with P selecting the rotations about the sheet's in-plane axes x and z (the drilling rotation
//! about the normal has only a penalty stiffness in `Shell4` and is not used; the rotation about
//! the normal comes from the in-plane translations). A is positive definite unless the points
//! are collinear. The relation spreads a force on the reference point over the disc as
//! `w_k`-weighted tractions and moments, adds no stiffness to the sheet and does not depend on
//! where the nodes are. The reference DOF are not DOF of the model: they are eliminated exactly,
//! `[u_c; θ_c] = T_ℓ u`, with `T_ℓ` (6 × 6N over the N shell nodes the disc touches). A rigid
//! motion of the sheet is reproduced exactly (bilinear shape functions interpolate a rigid
//! motion's linear field exactly, and its fit is that rigid motion), so welds keep the
//! structure's six rigid-body modes.
//!
//! Both kinds of observation matter on the coarse meshes the paper uses (5 × 12.5 mm shells,
//! larger than the 5 mm nugget): the out-of-plane translations alone see only an element's mean
//! slope across the disc, the rotations carry the nodes' own bending rotations. Measured on the
//! friction bar against a converged solid model (20-node bricks, `scripts/solid_reference.py`),
//! translations only were 2–10 % stiff on the default mesh, translations and rotations within
//! 4 % (docs/validation/welds.md).
//!
//! An edge weld (centre on a free edge, as on the multilayer sheet) keeps the part of the disc
//! inside the sheets; the fit is the same, about the weld centre, over the half disc.
//!
//! # Connector between the sheets
//!
//! Consecutive reference points of the stack (bottom–middle, middle–top) are joined by a
//! Timoshenko `Beam2` of diameter d and length the distance between the mid-surfaces (0.5 mm):
//! `K = Σ_beams [T_ℓ; T_ℓ₊₁]ᵀ K_beam [T_ℓ; T_ℓ₊₁]` on the shell nodes' DOF. Its shear stiffness
//! κGA/L ≈ 3·10⁶ N/mm is two to three orders above the sheets' local stiffness around the nugget,
//! so the connector is nearly rigid and the weld's compliance is the sheets'. A beam (not an
//! exact rigid link) is used because a rigid link between two RBE3 reference points is a
//! constraint among combinations of independent DOF, which the node-by-node elimination of the
//! assembly does not express.
//!
//! # Which weld where
//!
//! The solid-like connector — the nugget as a bonded slab between the mid-surfaces
//! ([`super::weld_slab`]: the sheets fused over the disc, like the solid model) — converges to
//! the solid model but locks on coarse meshes, where a 5 mm disc inside 5 × 12.5 mm shells bonds
//! whole elements (+7 % on the first mode, +26 % on the tenth at the default mesh). The RBE3 +
//! beam weld does not lock; what it leaves out is the fused disc's composite stiffness, which
//! makes its converged limit 1–5 % softer than the solid in the modes where the sheets move
//! against each other, and the bonded disc's prying contact at the nugget's rim
//! (docs/validation/welds.md). So `"local_mesh": "auto"` (the default) re-meshes the
//! neighbourhood with the slab inside ([`super::weld_patch`]) where the sheets' shells do not
//! resolve the nugget, and puts the slab on the sheets' own shells where they do; this module's
//! RBE3 + beam weld is what `"off"` gets, and shells too coarse for the nugget whose
//! neighbourhood cannot be re-meshed.
//!
//! # Mass
//!
//! None of its own: the nugget's material is the sheets' material, whose shells already cover
//! the disc (the point weld's beam mass counted that volume twice).

use std::sync::{Arc, Mutex};

use faer::linalg::solvers::Solve;
use faer::{Mat, Side};
use rayon::prelude::*;

use super::weld_slab::SlabPart;
use super::{Beam2, Material};
use crate::error::{ElementError, Error, WeldLayerProblem};
use crate::mesh::{NuggetLayer, OwnShellNugget, WeldElem, WeldPatch};

/// An area spot weld through a stack of sheets (see the module docs). Its matrices are on the
/// DOF of [`Weld::nodes`], 6 per node `[ux, uy, uz, rx, ry, rz]`.
#[derive(Clone, Debug)]
pub struct Weld {
    /// The shell nodes the nugget touches, sorted.
    nodes: Vec<usize>,
    /// Per layer (lower to upper): `T_ℓ`, the reference point's 6 DOF from the node DOF.
    maps: Vec<Mat<f64>>,
    /// Connector beams between consecutive reference points.
    beams: Vec<Beam2>,
    /// With a re-meshed neighbourhood ([`super::weld_patch`]) the condensed stiffness and mass,
    /// with the bonded slab on the sheets' own shells ([`super::weld_slab`]) its stiffness and
    /// no mass, on the DOF of `nodes` (and no maps or beams of its own).
    condensed: Option<Arc<(Mat<f64>, Mat<f64>)>>,
    /// The bonded slab on the sheets' own shells ([`super::weld_slab`]): its parts, each on the
    /// eight nodes of two shells; empty for the other weld models.
    slab: Vec<SlabPart>,
}

impl Weld {
    /// Builds `weld` on the mesh's node positions `coords` (mm): its re-meshed neighbourhood's
    /// condensation, the bonded slab on the sheets' own shells, or the interpolation constraints
    /// and connector beams (the weld's [`OwnShellNugget`]). Errors ([`Error::Element`]) if a
    /// layer has too few points for a rigid fit (collinear or fewer than three), a connector beam
    /// is invalid, or a shell under the slab is degenerate.
    pub fn new(weld: &WeldElem, coords: &[[f64; 3]], material: Material) -> Result<Weld, Error> {
        if let Some(patch) = &weld.patch {
            let c =
                super::weld_patch::condense(weld, patch, material, faer::get_global_parallelism())?;
            return Ok(Weld {
                nodes: c.nodes,
                maps: Vec::new(),
                beams: Vec::new(),
                condensed: Some(Arc::new((c.stiffness, c.mass))),
                slab: Vec::new(),
            });
        }
        if weld.own_shells == OwnShellNugget::BondedSlab {
            let (nodes, slab) = super::weld_slab::on_own_shells(weld, coords, material)?;
            return Ok(Weld {
                nodes,
                maps: Vec::new(),
                beams: Vec::new(),
                condensed: None,
                slab,
            });
        }
        let mut touched: Vec<usize> = weld
            .layers
            .iter()
            .flat_map(|l| l.points.iter().flat_map(|p| p.nodes))
            .collect();
        touched.sort_unstable();
        touched.dedup();
        let maps = weld
            .layers
            .iter()
            .map(|layer| reference_map(weld, layer, &touched))
            .collect::<Result<Vec<_>, _>>()?;
        let centre = |l: &NuggetLayer| [weld.centre[0], l.y, weld.centre[1]];
        let beams = weld
            .layers
            .windows(2)
            .map(|pair| {
                Beam2::circular(centre(&pair[0]), centre(&pair[1]), weld.diameter, material)
            })
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| match e {
                Error::Element(source) => Error::Element(ElementError::InWeld {
                    index: weld.index,
                    source: Box::new(source),
                }),
                other => other,
            })?;
        Ok(Weld {
            nodes: touched,
            maps,
            beams,
            condensed: None,
            slab: Vec::new(),
        })
    }

    /// The area welds of a mesh (node coordinates `nodes`, mm), each as [`Weld::new`], except
    /// that a re-meshed neighbourhood equal to an earlier weld's up to a translation (the same
    /// geometry relative to the weld centre, to 1e-9 mm, and the same material) reuses that
    /// weld's condensed matrices — within the scene (the friction bar's two welds are one
    /// condensation), across scenes built by this process (a cache bounded at 512 MB) and across
    /// commands (the disk cache of `element::weld_cache`). The neighbourhoods left to condense
    /// are condensed one at a time (with faer's global parallelism).
    pub fn build_all(
        welds: &[WeldElem],
        nodes: &[[f64; 3]],
        material: Material,
    ) -> Result<Vec<Weld>, Error> {
        // Each neighbourhood's retained nodes and key.
        let keys: Vec<Option<(Vec<usize>, Vec<i64>)>> = welds
            .iter()
            .map(|w| {
                w.patch.as_ref().map(|p| {
                    let retained = super::weld_patch::retained_nodes(p);
                    let key = condensation_key(w, p, &retained, nodes, material);
                    (retained, key)
                })
            })
            .collect();
        let key_of = |i: usize| keys[i].as_ref().map(|(_, k)| k.as_slice());
        // The distinct keys: found in this process or on disk, or to be condensed (the first
        // weld of each).
        let mut found: Vec<(&[i64], CondensedMatrices)> = Vec::new();
        let mut todo: Vec<usize> = Vec::new();
        for i in 0..welds.len() {
            let Some(key) = key_of(i) else { continue };
            if found.iter().any(|(k, _)| *k == key) || todo.iter().any(|&j| key_of(j) == Some(key))
            {
                continue;
            }
            match CONDENSED
                .get(key)
                .or_else(|| super::weld_cache::load(key).map(Arc::new))
            {
                Some(c) => {
                    CONDENSED.insert(key.to_vec(), c.clone());
                    found.push((key, c));
                }
                None => todo.push(i),
            }
        }
        // The distinct neighbourhoods side by side, one per core, each condensed sequentially
        // inside: the same bits as one after the other (a condensation does not depend on what
        // runs beside it), the wall time divided by the cores where there are several, at the
        // peak memory of as many neighbourhoods as cores.
        let condensed: Vec<Result<CondensedMatrices, Error>> = todo
            .par_iter()
            .map(|&i| {
                let w = &welds[i];
                let patch = w
                    .patch
                    .as_ref()
                    .expect("a weld with a key has a neighbourhood");
                let par = match todo.len() {
                    1 => faer::get_global_parallelism(),
                    _ => faer::Par::Seq,
                };
                super::weld_patch::condense(w, patch, material, par)
                    .map(|c| Arc::new((c.stiffness, c.mass)))
            })
            .collect();
        for (&i, c) in todo.iter().zip(condensed) {
            let c = c?;
            let key = key_of(i).expect("a condensed weld has a key");
            super::weld_cache::store(key, &c.0, &c.1);
            CONDENSED.insert(key.to_vec(), c.clone());
            found.push((key, c));
        }
        welds
            .iter()
            .zip(&keys)
            .map(|(w, entry)| match entry {
                None => Weld::new(w, nodes, material),
                Some((retained, key)) => Ok(Weld {
                    nodes: retained.clone(),
                    maps: Vec::new(),
                    beams: Vec::new(),
                    condensed: found
                        .iter()
                        .find(|(k, _)| *k == key.as_slice())
                        .map(|(_, c)| c.clone()),
                    slab: Vec::new(),
                }),
            })
            .collect()
    }

    /// The shell nodes the weld couples, in the order of its matrices' DOF.
    pub fn nodes(&self) -> &[usize] {
        &self.nodes
    }

    /// `T_ℓ` of layer `layer` (lower to upper): the reference point's `[u_c, θ_c]` (mm, rad) as a
    /// 6 × 6N map of the nodes' DOF; `None` for a weld with a re-meshed neighbourhood (its
    /// reference points live on the small shells) or a bonded slab (none), or past the last
    /// layer.
    pub fn reference_map(&self, layer: usize) -> Option<&Mat<f64>> {
        self.maps.get(layer)
    }

    /// The parts the assembly scatters, each with its nodes (6 DOF each) and, for a part of the
    /// bonded slab on the sheets' own shells, its stiffness (48 × 48, no mass): one part per
    /// pair of shells the slab's points join (sparse over the disc). Every other weld is one
    /// part over [`Weld::nodes`] (`None`: its matrices are [`Weld::stiffness`], [`Weld::mass`]).
    pub fn parts(&self) -> Vec<(&[usize], Option<&Mat<f64>>)> {
        if self.slab.is_empty() {
            return vec![(&self.nodes, None)];
        }
        self.slab.iter().map(|(n, k)| (&n[..], Some(k))).collect()
    }

    /// Stiffness on the DOF of [`Weld::nodes`], N/mm, N, N·mm/rad (dense; the assembly takes
    /// the bonded slab's [`Weld::parts`] instead).
    pub fn stiffness(&self) -> Mat<f64> {
        if let Some(c) = &self.condensed {
            return c.0.clone();
        }
        let dofs = 6 * self.nodes.len();
        let mut k = Mat::<f64>::zeros(dofs, dofs);
        for (part, kp) in &self.slab {
            let at = |n: usize| {
                self.nodes
                    .binary_search(&n)
                    .expect("a slab node is the weld's")
            };
            let dof: Vec<usize> = part
                .iter()
                .flat_map(|&n| (0..6).map(move |d| 6 * at(n) + d))
                .collect();
            for (x, &gx) in dof.iter().enumerate() {
                for (y, &gy) in dof.iter().enumerate() {
                    k[(gx, gy)] += kp[(x, y)];
                }
            }
        }
        for (l, beam) in self.beams.iter().enumerate() {
            let mut t = Mat::<f64>::zeros(12, dofs);
            t.as_mut()
                .subrows_mut(0, 6)
                .copy_from(self.maps[l].as_ref());
            t.as_mut()
                .subrows_mut(6, 6)
                .copy_from(self.maps[l + 1].as_ref());
            let kt = beam.stiffness() * &t;
            k += t.transpose() * kt;
        }
        // Exact symmetry (the products above are symmetric up to round-off).
        for i in 0..dofs {
            for j in 0..i {
                let v = 0.5 * (k[(i, j)] + k[(j, i)]);
                k[(i, j)] = v;
                k[(j, i)] = v;
            }
        }
        k
    }

    /// Mass on the DOF of [`Weld::nodes`]: zero (the nugget's material belongs to the sheets),
    /// or with a re-meshed neighbourhood the condensed mass of its small shells.
    pub fn mass(&self) -> Mat<f64> {
        if let Some(c) = &self.condensed {
            return c.1.clone();
        }
        let dofs = 6 * self.nodes.len();
        Mat::zeros(dofs, dofs)
    }
}

/// `T_ℓ` (6 × 6N over `touched`) of one layer: the RBE3 fit of the module docs.
fn reference_map(
    weld: &WeldElem,
    layer: &NuggetLayer,
    touched: &[usize],
) -> Result<Mat<f64>, Error> {
    let fail = |problem: WeldLayerProblem| {
        Error::Element(ElementError::WeldLayer {
            index: weld.index,
            centre: weld.centre,
            sheet: layer.sheet,
            problem,
        })
    };
    if layer.points.len() < 3 {
        return Err(fail(WeldLayerProblem::TooFewPoints));
    }
    let offset = |p: [f64; 2]| [p[0] - weld.centre[0], 0.0, p[1] - weld.centre[1]];
    let area: f64 = layer.points.iter().map(|p| p.weight).sum();
    let mean_distance = layer
        .points
        .iter()
        .map(|p| p.weight * (p.xz[0] - weld.centre[0]).hypot(p.xz[1] - weld.centre[1]))
        .sum::<f64>()
        / area;
    let rotation_weight = mean_distance * mean_distance;
    // A = Σ w (Gᵀ G + L_c² Pᵀ P), P selecting the in-plane rotations θx, θz.
    let mut a = Mat::<f64>::zeros(6, 6);
    for p in &layer.points {
        let g = fit_row_block(offset(p.xz));
        for i in 0..6 {
            for j in 0..6 {
                a[(i, j)] += p.weight * (0..3).map(|m| g[m][i] * g[m][j]).sum::<f64>();
            }
        }
        for r in IN_PLANE_ROTATIONS {
            a[(r, r)] += p.weight * rotation_weight;
        }
    }
    let llt = a
        .llt(Side::Lower)
        .map_err(|_| fail(WeldLayerProblem::Collinear))?;
    let dofs = 6 * touched.len();
    let mut rhs = Mat::<f64>::zeros(6, dofs);
    for p in &layer.points {
        let g = fit_row_block(offset(p.xz));
        for (a_node, &n) in p.nodes.iter().enumerate() {
            let col = 6 * touched.binary_search(&n).expect("node listed");
            let s = p.weight * p.shape[a_node];
            for i in 0..6 {
                for m in 0..3 {
                    rhs[(i, col + m)] += s * g[m][i];
                }
            }
            for r in IN_PLANE_ROTATIONS {
                rhs[(r, col + r)] += s * rotation_weight;
            }
        }
    }
    Ok(llt.solve(&rhs))
}

/// Condensed neighbourhoods (stiffness, mass) by [`condensation_key`].
type CondensedMatrices = Arc<(Mat<f64>, Mat<f64>)>;

/// The condensations of this process, by [`condensation_key`]: a neighbourhood equal to an
/// earlier one up to a translation — the other weld of the same scene, or the same scene built
/// again (a sweep, a study, the test suite) — is condensed once. Bounded by
/// [`CondensationCache::MAX_BYTES`], oldest first out.
struct CondensationCache {
    entries: Mutex<Vec<(Vec<i64>, CondensedMatrices)>>,
}

impl CondensationCache {
    /// The cache's bound on its matrices, bytes.
    const MAX_BYTES: usize = 512 << 20;

    fn lock(&self) -> std::sync::MutexGuard<'_, Vec<(Vec<i64>, CondensedMatrices)>> {
        // A panic elsewhere cannot leave an entry half-written (entries are pushed whole).
        self.entries.lock().unwrap_or_else(|e| e.into_inner())
    }

    fn get(&self, key: &[i64]) -> Option<CondensedMatrices> {
        let entries = self.lock();
        entries
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, c)| c.clone())
    }

    fn insert(&self, key: Vec<i64>, c: CondensedMatrices) {
        let bytes =
            |c: &CondensedMatrices| 8 * (c.0.nrows() * c.0.ncols() + c.1.nrows() * c.1.ncols());
        let mut entries = self.lock();
        let mut total: usize = bytes(&c) + entries.iter().map(|(_, e)| bytes(e)).sum::<usize>();
        while total > Self::MAX_BYTES && !entries.is_empty() {
            total -= bytes(&entries.remove(0).1);
        }
        if total <= Self::MAX_BYTES {
            entries.push((key, c));
        }
    }
}

static CONDENSED: CondensationCache = CondensationCache {
    entries: Mutex::new(Vec::new()),
};

/// Everything a re-meshed neighbourhood's condensation depends on, relative to the weld centre
/// and rounded to 1e-9 mm, with the positions of its `retained` nodes (sorted: matrix order).
fn condensation_key(
    weld: &WeldElem,
    patch: &WeldPatch,
    retained: &[usize],
    nodes: &[[f64; 3]],
    material: Material,
) -> Vec<i64> {
    let q = |v: f64| (v * 1e9).round() as i64;
    let [cx, cz] = weld.centre;
    let bits = |v: f64| v.to_bits() as i64;
    let mut key = vec![
        q(patch.size),
        q(weld.diameter),
        bits(material.youngs_modulus),
        bits(material.poisson_ratio),
        bits(material.density),
    ];
    for l in &patch.layers {
        key.extend([q(l.y), q(l.thickness), l.nodes.len() as i64]);
        key.extend(l.free_side.map(i64::from));
        for (lines, c) in [(&l.xs, cx), (&l.zs, cz), (&l.fine_xs, cx), (&l.fine_zs, cz)] {
            key.push(lines.len() as i64);
            key.extend(lines.iter().map(|&v| q(v - c)));
        }
    }
    for &n in retained {
        let [x, y, z] = nodes[n];
        key.extend([q(x - cx), q(y), q(z - cz)]);
    }
    for layer in &patch.nugget {
        key.push(layer.points.len() as i64);
        for p in &layer.points {
            key.extend([q(p.xz[0] - cx), q(p.xz[1] - cz), q(p.weight)]);
            key.extend(p.nodes.map(|n| n as i64));
        }
    }
    key
}

/// The rotations about the sheets' in-plane axes x and z (the sheets lie in x–z planes).
const IN_PLANE_ROTATIONS: [usize; 2] = [3, 5];

/// The 3 × 6 block `G = [I S(r)]` with `S(r) θ = θ × r`: the translation at offset `r` of the
/// rigid motion `[u_c, θ_c]`.
fn fit_row_block(r: [f64; 3]) -> [[f64; 6]; 3] {
    [
        [1.0, 0.0, 0.0, 0.0, r[2], -r[1]],
        [0.0, 1.0, 0.0, -r[2], 0.0, r[0]],
        [0.0, 0.0, 1.0, r[1], -r[0], 0.0],
    ]
}
