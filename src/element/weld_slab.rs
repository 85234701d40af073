//! The nugget as a bonded slab: the two sheets fused over the nugget disc, as the converged
//! solid model has them. Used inside a re-meshed neighbourhood (`super::weld_patch`) and, where
//! the sheets' own shells resolve the nugget, directly on them ([`on_own_shells`]).
//!
//! # The slab
//!
//! Between consecutive sheets (mid-surfaces L apart, 0.5 mm on the built-in scenes) the nugget is
//! a slab of the sheets' material whose strains follow from the two mid-surfaces' interpolated
//! fields (lower `A`, upper `B`; `ū_y` their mean):
//!
//! ```text
//! γ_x = (u_x^B − u_x^A)/L + ∂ū_y/∂x,   γ_z = (u_z^B − u_z^A)/L + ∂ū_y/∂z,   ε_y = (u_y^B − u_y^A)/L
//! U   = ½ ∫_disc L (G γ_x² + E ε_y² + G γ_z²) dA            (the nugget's sampling points)
//! ```
//!
//! Rigid motions give no strain (a rotation θ about z: `(u_x^B − u_x^A)/L = −θ`, `∂ū_y/∂x = θ`),
//! so the six rigid-body modes stay. The slab has no mass: its material is the sheets', whose
//! shells already cover the disc.
//!
//! # On the sheets' own shells
//!
//! Each sampling point carries the bilinear shape functions `N_a` of the sheet's shell that
//! contains it (`crate::mesh`'s nugget rule); the derivatives `∂N_a/∂x`, `∂N_a/∂z` follow from
//! the shell's isoparametric map at the point's parametric coordinates, which the shape
//! functions themselves give (`ξ = N_1 + N_2`, `η = N_2 + N_3` in the node order of
//! [`crate::mesh::ShellElem`], corners at (0,0), (1,0), (1,1), (0,1)).
//!
//! Where it applies: a 5 mm disc inside 5 × 12.5 mm shells bonds whole shells and locks (+7 % on
//! the friction bar's first fixed-interface mode, +26 % on the tenth, against the converged
//! solid), so `"local_mesh": "auto"` puts the slab on the sheets' own shells only where they
//! resolve the nugget (every side at most d/2) and re-meshes the neighbourhood elsewhere. On
//! resolved shells the slab is what the solid has, where the RBE3 + beam weld of `super::weld`
//! (which ties only the disc's mean rigid motion) is softer: on the friction bar refined 8×
//! (0.625 × 1.56 mm shells) the slab's first ten fixed-interface modes are within +1.1 % of the
//! converged solid, the RBE3 weld's 1.4–4.4 % below it; and the bonded disc carries the prying
//! contact at the nugget's rim that the RBE3 weld lets pass (docs/validation/welds.md,
//! docs/validation/contact-refinement.md).

use faer::Mat;

use super::Material;
use crate::error::{ElementError, Error};
use crate::mesh::{NuggetPoint, WeldElem};

/// Shape-function derivatives `(∂N/∂x, ∂N/∂z)` (1/mm) of the four nodes of a shell at a point.
pub(super) type ShapeDerivatives = ([f64; 4], [f64; 4]);

/// Adds the slab's stiffness at one pair of sampling points (lower `pa`, upper `pb`, the same
/// position and weight) over the 8 nodes' 6 DOF (the lower sheet's four nodes first) to the
/// 48 × 48 `ke`; `da`, `db` the shape-function derivatives there, `gap` the mid-surfaces'
/// distance (mm).
pub(super) fn add_point(
    ke: &mut Mat<f64>,
    (pa, da): (&NuggetPoint, ShapeDerivatives),
    (pb, db): (&NuggetPoint, ShapeDerivatives),
    gap: f64,
    material: Material,
) {
    let e = material.youngs_modulus;
    let g = e / (2.0 * (1.0 + material.poisson_ratio));
    // Strain rows γ_x, ε_y, γ_z.
    let mut b = [[0.0f64; 48]; 3];
    for a in 0..4 {
        let (lo, up) = (6 * a, 6 * (a + 4));
        let (na, nb) = (pa.shape[a], pb.shape[a]);
        b[0][lo] -= na / gap;
        b[0][up] += nb / gap;
        b[0][lo + 1] += 0.5 * da.0[a];
        b[0][up + 1] += 0.5 * db.0[a];
        b[1][lo + 1] -= na / gap;
        b[1][up + 1] += nb / gap;
        b[2][lo + 2] -= na / gap;
        b[2][up + 2] += nb / gap;
        b[2][lo + 1] += 0.5 * da.1[a];
        b[2][up + 1] += 0.5 * db.1[a];
    }
    for (row, modulus) in b.iter().zip([g, e, g]) {
        let w = pa.weight * gap * modulus;
        for (x, &bx) in row.iter().enumerate() {
            if bx == 0.0 {
                continue;
            }
            for (y, &by) in row.iter().enumerate() {
                ke[(x, y)] += w * bx * by;
            }
        }
    }
}

/// `(∂N/∂x, ∂N/∂z)` of the shell containing `p` (node positions `coords`, mm), from its
/// isoparametric map at the point (module docs); `None` for a degenerate or inverted shell.
fn own_shell_derivatives(p: &NuggetPoint, coords: &[[f64; 3]]) -> Option<ShapeDerivatives> {
    let (xi, eta) = (p.shape[1] + p.shape[2], p.shape[2] + p.shape[3]);
    let d_xi = [-(1.0 - eta), 1.0 - eta, eta, -eta];
    let d_eta = [-(1.0 - xi), -xi, xi, 1.0 - xi];
    let mut j = [[0.0f64; 2]; 2];
    for a in 0..4 {
        let [x, _, z] = coords[p.nodes[a]];
        j[0][0] += d_xi[a] * x;
        j[0][1] += d_xi[a] * z;
        j[1][0] += d_eta[a] * x;
        j[1][1] += d_eta[a] * z;
    }
    let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
    if !det.is_finite() || det.abs() <= f64::EPSILON * (j[0][0].abs() + j[1][1].abs()).powi(2) {
        return None;
    }
    let mut dx = [0.0; 4];
    let mut dz = [0.0; 4];
    for a in 0..4 {
        dx[a] = (j[1][1] * d_xi[a] - j[0][1] * d_eta[a]) / det;
        dz[a] = (-j[1][0] * d_xi[a] + j[0][0] * d_eta[a]) / det;
    }
    Some((dx, dz))
}

/// One part of the bonded slab on the sheets' own shells: the eight nodes of a lower and an
/// upper shell (lower first, as [`add_point`] orders them) and the slab's stiffness (48 × 48) of
/// the sampling points that join those two shells.
pub(crate) type SlabPart = ([usize; 8], Mat<f64>);

/// The bonded slab of `weld` on the sheets' own shells (module docs): the nodes it couples
/// (sorted) and its stiffness as one part per pair of shells its sampling points join (6 DOF
/// per node; N/mm, N, N·mm/rad), in the order the points first reach them. A point couples only
/// its two shells' eight nodes, so the slab is sparse over the disc: as one dense block over all
/// its nodes it was (6N)² entries (N ≈ 1 050 nodes under a 5 mm nugget of 0.12 mm shells, two
/// thirds of a 10⁶-DOF model's stiffness entries). Errors naming the weld if two consecutive
/// layers are not sampled alike or a shell is degenerate.
pub(super) fn on_own_shells(
    weld: &WeldElem,
    coords: &[[f64; 3]],
    material: Material,
) -> Result<(Vec<usize>, Vec<SlabPart>), Error> {
    let mut nodes: Vec<usize> = weld
        .layers
        .iter()
        .flat_map(|l| l.points.iter().flat_map(|p| p.nodes))
        .collect();
    nodes.sort_unstable();
    nodes.dedup();
    let mut parts: Vec<SlabPart> = Vec::new();
    let mut part_of: std::collections::HashMap<[usize; 8], usize> =
        std::collections::HashMap::new();
    for pair in weld.layers.windows(2) {
        let (lower, upper) = (&pair[0], &pair[1]);
        let gap = upper.y - lower.y;
        check_layers(weld.index, lower, upper)?;
        for (pa, pb) in lower.points.iter().zip(&upper.points) {
            let derivatives = |p: &NuggetPoint, sheet: usize| {
                own_shell_derivatives(p, coords).ok_or_else(|| {
                    Error::from(ElementError::InWeld {
                        index: weld.index,
                        source: Box::new(ElementError::DegenerateNuggetShell {
                            sheet,
                            x: p.xz[0],
                            z: p.xz[1],
                        }),
                    })
                })
            };
            let mut key = [0usize; 8];
            key[..4].copy_from_slice(&pa.nodes);
            key[4..].copy_from_slice(&pb.nodes);
            let at = *part_of.entry(key).or_insert_with(|| {
                parts.push((key, Mat::zeros(48, 48)));
                parts.len() - 1
            });
            add_point(
                &mut parts[at].1,
                (pa, derivatives(pa, lower.sheet)?),
                (pb, derivatives(pb, upper.sheet)?),
                gap,
                material,
            );
        }
    }
    // Exact symmetry (the point matrices are symmetric up to round-off).
    for (_, k) in &mut parts {
        for i in 0..48 {
            for j in 0..i {
                let v = 0.5 * (k[(i, j)] + k[(j, i)]);
                k[(i, j)] = v;
                k[(j, i)] = v;
            }
        }
    }
    Ok((nodes, parts))
}

/// Errors unless `lower` and `upper` (consecutive layers of weld `index`) carry the same
/// sampling points (positions and weights) and `upper` lies above `lower`.
pub(super) fn check_layers(
    index: usize,
    lower: &crate::mesh::NuggetLayer,
    upper: &crate::mesh::NuggetLayer,
) -> Result<(), Error> {
    let same = lower.points.len() == upper.points.len()
        && lower
            .points
            .iter()
            .zip(&upper.points)
            .all(|(a, b)| a.xz == b.xz && a.weight == b.weight);
    let gap = upper.y - lower.y;
    if !same || gap.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        return Err(ElementError::InWeld {
            index,
            source: Box::new(ElementError::NuggetSampling {
                lower: lower.sheet,
                upper: upper.sheet,
            }),
        }
        .into());
    }
    Ok(())
}
