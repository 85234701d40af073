//! Contact sampled at points inside the joint's faces: a per-area contact law integrated with
//! more points than the nodes, and with a gap interpolated as richly as the shells bend.
//!
//! # Why
//!
//! Two sheets pressed together over a penalty layer κ (N/mm³) behave as a plate on an elastic
//! foundation: the pressure decays from a sheet's end or a weld's rim over
//! `ℓ = (4D/κ)^{1/4}` (2.8 mm for 0.5 mm steel at κ = 160 N/mm³). Node-to-node pairs sample
//! the pressure only at the nodes, so a face of side h ≈ ℓ carries a strip with one or two
//! samples and the contact edge jumps from node to node.
//!
//! # The points
//!
//! Every face of the joint surface (the lower side's faces of [`crate::mesh::tributary`]) is
//! split into m × m equal parametric sub-cells; the contact point of a sub-cell sits at its
//! centre `(r_p, s_p)` and stands for the share of the sub-cell that belongs to contact:
//!
//! ```text
//! A_p = Σ_{a paired} ∫_cell N_a dA      (2×2 Gauss on the sub-cell: exact for bilinear faces)
//! ```
//!
//! where the corners fused in a nugget or held by a support pass their share to the weld or the
//! support as in the nodal rule, so `Σ_p A_p = Σ_i A_i` (the pairs' tributary areas) on any
//! mesh and for any m. Sub-cell centres rather than Gauss points: every point has an area of its
//! own that adds up exactly, and the points cover the face evenly (a strip is met wherever it
//! lies). With [`SamplingPoints::Nodes`] the points are the pairs themselves (the node-pair
//! per-area law, reproduced bit for bit).
//!
//! The point's rows in B are the interpolation, on the upper face minus the lower face (each
//! face's corners ordered like the lower one's), of
//!
//! - the normal gap `g = w_upper − w_lower`, with `w` the deflection along the face normal
//!   either bilinear in the corner deflections or the face's own DKMQ edge cubics blended over
//!   the face ([`crate::element::Shell4::deflection_row`]: it uses the corners' rotations, so a
//!   face bends inside; on a thin rectangle it is the 12-term ACM interpolation);
//! - the slips `t1·(u_upper − u_lower)`, `t2·(…)` bilinear in the corner translations (and,
//!   with `"slip": "faces"`, in the corner rotations times the half thicknesses:
//!   `crate::joint::operator`).
//!
//! The frame of a point is the shape-weighted mean of its corners' pair normals (`+y` for the
//! generated sheets). A point is a pair of the per-area law ([`super::per_area`]): its rows are
//! weighted by `√(A_p/Ā)`, so everything downstream (statics, the TVD's `∂K/∂q`, the joint
//! flexibility, reduced `BΦ`) sees an operator of the same kind, with more rows. A point's
//! [`PairFrame`] names the node pair of its nearest paired corner (its sheets' thickness, the
//! joint's node set) and [`Model::point_positions`] where it sits.

use super::Model;
use crate::case::GapInterpolation;
use crate::element::Shell4;
use crate::error::{Error, ModelError};
use crate::joint::{JointOperator, PairFrame};
use crate::mesh::tributary::on_joint_surface;
use crate::mesh::Mesh;

/// Where the contact points sit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SamplingPoints {
    /// At the pairs' nodes (the node-to-node per-area law; the gap interpolation plays no part).
    Nodes,
    /// At the centres of m × m parametric sub-cells of every joint face (m ≥ 1).
    SubCells(usize),
}

/// One contact point under construction.
struct Point {
    /// Rows normal, t1, t2 over (node, node DOF 0..6) terms.
    rows: [Vec<(usize, usize, f64)>; 3],
    area: f64,
    frame: PairFrame,
    /// Where it sits, mm.
    position: [f64; 3],
}

/// A joint face: the lower shell, the upper nodes in the lower corners' order, the share of the
/// face (1 unless a lower node has several upper partners).
struct FacePair {
    lower: usize,
    upper: [usize; 4],
    upper_shell: usize,
    share: f64,
}

impl Model {
    fn sampling_error(&self, field: &str, reason: String) -> Error {
        ModelError::PerArea {
            model: self.source.clone(),
            field: field.to_string(),
            reason,
        }
        .into()
    }

    /// Replaces the node pairs by the contact points `points` with the gap interpolation `gap`
    /// and resolves the per-area law
    /// `kappa` (N/mm³) on them. `field` names the field that asked for it in errors: a model
    /// without a mesh, a joint face whose upper face is not found.
    pub fn apply_contact_sampling(
        &mut self,
        kappa: [f64; 2],
        points: SamplingPoints,
        gap: GapInterpolation,
        field: &str,
    ) -> Result<(), Error> {
        let Some(mesh) = self.mesh() else {
            return Err(self.sampling_error(
                field,
                "contact points inside the faces need the model's mesh (a case or a deck)".into(),
            ));
        };
        let faces = joint_faces(mesh).map_err(|node| {
            let [x, y, z] = mesh.nodes[node];
            self.sampling_error(
                field,
                format!(
                    "the joint face at node {} ({x}, {y}, {z}) mm has no upper face through its \
                     partner nodes",
                    self.geometry.node_ids[node]
                ),
            )
        })?;
        let points = match points {
            SamplingPoints::Nodes => self.node_points(mesh, &faces)?,
            SamplingPoints::SubCells(m) => {
                if m == 0 {
                    return Err(
                        self.sampling_error(field, "points_per_edge must be at least 1".into())
                    );
                }
                self.cell_points(mesh, &faces, m, gap == GapInterpolation::Hermite)?
            }
        };
        if points.is_empty() {
            return Err(self.sampling_error(field, "the joints have no contact point".into()));
        }
        let mut rows = Vec::with_capacity(3 * points.len());
        for p in &points {
            for row in &p.rows {
                let mut out = Vec::with_capacity(row.len());
                for &(node, k, c) in row {
                    out.extend(self.dof_map.nodes[node][k].terms().map(|(i, d)| (i, c * d)));
                }
                rows.push(out);
            }
        }
        self.joint = JointOperator::from_rows(&rows, self.dof_map.n);
        self.pairs = points.iter().map(|p| p.frame).collect();
        self.point_positions = Some(points.iter().map(|p| p.position).collect());
        let areas = points.iter().map(|p| p.area).collect();
        self.pair_weights = None;
        self.resolve_per_area(kappa, areas, field)
    }

    /// The pairs as points (`"points": "nodes"`): their own rows and frames, the areas summed
    /// over the faces.
    fn node_points(&self, mesh: &Mesh, faces: &[FacePair]) -> Result<Vec<Point>, Error> {
        let mut index = std::collections::HashMap::new();
        for (i, p) in self.pairs.iter().enumerate() {
            index.insert((p.lower, p.upper), i);
        }
        let mut area = vec![0.0; self.pairs.len()];
        for f in faces {
            let corners = mesh.shells[f.lower].nodes;
            let shares = crate::mesh::tributary::corner_areas(corners.map(|n| mesh.nodes[n]));
            for a in 0..4 {
                if let Some(&i) = index.get(&(corners[a], f.upper[a])) {
                    area[i] += f.share * shares[a];
                }
            }
        }
        Ok(self
            .pairs
            .iter()
            .zip(area)
            .map(|(p, a)| {
                let rows = p.directions().map(|d| {
                    let mut r = Vec::new();
                    let sides = [
                        (p.upper, 1.0, p.face_offsets[1]),
                        (p.lower, -1.0, p.face_offsets[0]),
                    ];
                    for (node, sign, offset) in sides {
                        for k in 0..3 {
                            if d[k] != 0.0 {
                                r.push((node, k, sign * d[k]));
                            }
                        }
                        let rot = p.face_rotation_row(d, offset);
                        for (k, &c) in rot.iter().enumerate() {
                            if c != 0.0 {
                                r.push((node, 3 + k, c));
                            }
                        }
                    }
                    r
                });
                Point {
                    rows,
                    area: a,
                    frame: *p,
                    position: mesh.nodes[p.lower],
                }
            })
            .collect())
    }

    /// The sub-cell centres of every joint face (module docs).
    fn cell_points(
        &self,
        mesh: &Mesh,
        faces: &[FacePair],
        m: usize,
        edges: bool,
    ) -> Result<Vec<Point>, Error> {
        let frame_of: std::collections::HashMap<(usize, usize), PairFrame> = self
            .pairs
            .iter()
            .map(|p| ((p.lower, p.upper), *p))
            .collect();
        let faces_slip = self.contact.slip == crate::case::SlipSurface::Faces;
        let mut out = Vec::new();
        for f in faces {
            let lower = mesh.shells[f.lower];
            let upper_elem = mesh.shells[f.upper_shell];
            let corners = lower.nodes;
            let shell = |nodes: [usize; 4], t: f64| {
                Shell4::new(nodes.map(|n| mesh.nodes[n]), t, mesh.material)
            };
            let (sl, su) = (
                shell(corners, lower.thickness)?,
                shell(f.upper, upper_elem.thickness)?,
            );
            let frames: [Option<PairFrame>; 4] =
                std::array::from_fn(|a| frame_of.get(&(corners[a], f.upper[a])).copied());
            let h = 2.0 / m as f64;
            for i in 0..m {
                for j in 0..m {
                    let (r0, s0) = (-1.0 + h * i as f64, -1.0 + h * j as f64);
                    let (r, s) = (r0 + 0.5 * h, s0 + 0.5 * h);
                    let area = f.share * cell_area(&sl, [r0, r0 + h], [s0, s0 + h], &frames);
                    if area <= 0.0 {
                        continue;
                    }
                    let (n, _) = sl.shape(r, s);
                    let mut normal = [0.0; 3];
                    // The nearest paired corner names the point's nodes (for its thickness,
                    // the joint's node set); its position is the sub-cell centre.
                    let mut nearest = (-1.0, 0usize);
                    for a in 0..4 {
                        if let Some(fr) = frames[a] {
                            (0..3).for_each(|k| normal[k] += n[a] * fr.normal[k]);
                            if n[a] > nearest.0 {
                                nearest = (n[a], a);
                            }
                        }
                    }
                    let position = std::array::from_fn(|k| {
                        (0..4)
                            .map(|b| n[b] * mesh.nodes[corners[b]][k])
                            .sum::<f64>()
                    });
                    let a = nearest.1;
                    let Some(frame) = PairFrame::along(corners[a], f.upper[a], normal) else {
                        continue;
                    };
                    let mut rows: [Vec<(usize, usize, f64)>; 3] = Default::default();
                    let sides = [
                        (&su, f.upper, 1.0, upper_elem.thickness),
                        (&sl, corners, -1.0, lower.thickness),
                    ];
                    for (sh, nodes, sign, thickness) in sides {
                        let wrow = sh.deflection_row(r, s, edges);
                        let sn: f64 = (0..3).map(|k| sh.normal()[k] * frame.normal[k]).sum();
                        let orient = sign * sn.signum();
                        for (d, &v) in wrow.iter().enumerate() {
                            if v != 0.0 {
                                rows[0].push((nodes[d / 6], d % 6, orient * v));
                            }
                        }
                        let offset = if faces_slip { 0.5 * thickness } else { 0.0 };
                        for (row, t) in rows[1..].iter_mut().zip([frame.t1, frame.t2]) {
                            let rot = frame.face_rotation_row(t, offset);
                            for b in 0..4 {
                                for k in 0..3 {
                                    if t[k] != 0.0 && n[b] != 0.0 {
                                        row.push((nodes[b], k, sign * n[b] * t[k]));
                                    }
                                    if rot[k] != 0.0 && n[b] != 0.0 {
                                        row.push((nodes[b], 3 + k, n[b] * rot[k]));
                                    }
                                }
                            }
                        }
                    }
                    out.push(Point {
                        rows,
                        area,
                        frame,
                        position,
                    });
                }
            }
        }
        Ok(out)
    }
}

/// `Σ_{a paired} ∫ N_a dA` over the parametric cell `[r0, r1] × [s0, s1]` of `shell` (2×2
/// Gauss points, exact for the bilinear `N_a det J`), the corners with a pair frame counted.
fn cell_area(shell: &Shell4, r: [f64; 2], s: [f64; 2], frames: &[Option<PairFrame>; 4]) -> f64 {
    let g = 0.5 / 3f64.sqrt();
    let (rc, sc) = (0.5 * (r[0] + r[1]), 0.5 * (s[0] + s[1]));
    let (hr, hs) = (r[1] - r[0], s[1] - s[0]);
    let mut total = 0.0;
    for (dr, ds) in [(-g, -g), (g, -g), (g, g), (-g, g)] {
        let (n, det) = shell.shape(rc + dr * hr, sc + ds * hs);
        let paired: f64 = (0..4).filter(|&a| frames[a].is_some()).map(|a| n[a]).sum();
        total += 0.25 * hr * hs * det * paired;
    }
    total
}

/// The joint surface's faces with their upper faces: the lower shells of
/// [`crate::mesh::tributary`]'s rule (all corners joint nodes, one a pair's or a left-out
/// pair's), each with every upper shell through its corners' partners (a held corner without
/// partner takes the upper shell's remaining node nearest to it). `Err(node)`: a face's corner
/// node whose partners lie on no common upper shell.
fn joint_faces(mesh: &Mesh) -> Result<Vec<FacePair>, usize> {
    let nn = mesh.nodes.len();
    let mut partners: Vec<Vec<usize>> = vec![Vec::new(); nn];
    for p in mesh.pairs.iter().chain(&mesh.excluded) {
        partners[p.lower].push(p.upper);
    }
    let mut support = vec![false; nn];
    for &n in mesh.clamped.iter().chain(&mesh.tie.slaves) {
        support[n] = true;
    }
    let mut shells_of: Vec<Vec<usize>> = vec![Vec::new(); nn];
    for (e, s) in mesh.shells.iter().enumerate() {
        for &n in &s.nodes {
            shells_of[n].push(e);
        }
    }
    let dist2 = |a: usize, b: usize| -> f64 {
        (0..3)
            .map(|k| (mesh.nodes[a][k] - mesh.nodes[b][k]).powi(2))
            .sum()
    };
    let mut out = Vec::new();
    for (e, shell) in mesh.shells.iter().enumerate() {
        let c = shell.nodes;
        if !on_joint_surface(c, |n| !partners[n].is_empty(), |n| support[n]) {
            continue;
        }
        let first = c.iter().position(|&n| !partners[n].is_empty()).unwrap_or(0);
        let mut found: Vec<(usize, [usize; 4])> = Vec::new();
        for &u0 in &partners[c[first]] {
            for &cand in &shells_of[u0] {
                if cand == e || found.iter().any(|f| f.0 == cand) {
                    continue;
                }
                let un = mesh.shells[cand].nodes;
                let mut upper = [usize::MAX; 4];
                let mut ok = true;
                for a in 0..4 {
                    if partners[c[a]].is_empty() {
                        continue;
                    }
                    match partners[c[a]].iter().find(|u| un.contains(u)) {
                        Some(&u) => upper[a] = u,
                        None => ok = false,
                    }
                }
                if !ok {
                    continue;
                }
                for a in 0..4 {
                    if upper[a] == usize::MAX {
                        let rest = un.iter().filter(|n| !upper.contains(n));
                        upper[a] = *rest
                            .min_by(|&&x, &&y| dist2(x, c[a]).total_cmp(&dist2(y, c[a])))
                            .unwrap_or(&un[0]);
                    }
                }
                found.push((cand, upper));
            }
        }
        if found.is_empty() {
            return Err(c[first]);
        }
        let share = 1.0 / found.len() as f64;
        for (cand, upper) in found {
            out.push(FacePair {
                lower: e,
                upper,
                upper_shell: cand,
                share,
            });
        }
    }
    Ok(out)
}
