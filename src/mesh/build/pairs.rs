//! The joints pass: the node pairs of every joint, checked for contact, overlap and support.

use std::collections::{HashMap, HashSet};

use super::{Grid, Rect, Sheets, Supports};
use crate::case::validate::Ctx;
use crate::case::{JointSpec, NODE_TOLERANCE};
use crate::error::Error;
use crate::mesh::JointPair;

/// Relative tolerance of the zero-clearance test of a joint.
const CLEARANCE_TOLERANCE: f64 = 1e-9;

/// The node pairs of a joint between sheets `[lower, upper]` in their overlap (the `None` case
/// of `points`): every coincident pair neither of whose nodes is clamped or tied and that no
/// area weld's nugget fuses, i-major over the lower sheet; the coincident pairs left out (fused,
/// clamped or tied) go to `excluded`.
fn coincident_pairs(
    [lower, upper]: [usize; 2],
    [gl, gu]: [&Grid; 2],
    overlap: &Rect,
    supports: &Supports,
    excluded: &mut Vec<JointPair>,
) -> Vec<JointPair> {
    let mut found = Vec::new();
    for (i, k) in gl.nodes_in(overlap) {
        let [x, z] = gl.xz(i, k);
        let l = gl.index(i, k);
        if let Some(u) = gu.node_at(x, z) {
            let welded = supports.welded(lower, upper, [x, z]).is_some();
            let pair = JointPair { lower: l, upper: u };
            if !supports.excluded(l) && !supports.excluded(u) && !welded {
                found.push(pair);
            } else {
                excluded.push(pair);
            }
        }
    }
    found
}

/// Checks that a joint's sheets touch: upper.y − lower.y equals the mean thickness, zero initial
/// clearance (within [`CLEARANCE_TOLERANCE`]).
fn check_clearance(ctx: &Ctx, p: &str, gl: &Grid, gu: &Grid) -> Result<(), Error> {
    let distance = gu.y - gl.y;
    let contact = 0.5 * (gl.thickness + gu.thickness);
    let scale = gl.y.abs().max(gu.y.abs()).max(2.0 * contact);
    if (distance - contact).abs() > CLEARANCE_TOLERANCE * scale {
        let hint = if distance <= 0.0 {
            "; is `upper` below `lower`?"
        } else {
            ""
        };
        return Err(ctx.err(
            p,
            format!(
                "sheets `{}` (y = {} mm, t = {} mm) and `{}` (y = {} mm, t = {} mm) do not \
                 touch: upper.y − lower.y = {distance} mm but (t_lower + t_upper)/2 = \
                 {contact} mm; a joint needs zero initial clearance{hint}",
                gl.name, gl.y, gl.thickness, gu.name, gu.y, gu.thickness
            ),
        ));
    }
    Ok(())
}

/// The (x, z) overlap of a joint's sheets; an error if they do not overlap or if a node of one
/// inside it is not a node of the other.
fn overlap(ctx: &Ctx, p: &str, gl: &Grid, gu: &Grid) -> Result<Rect, Error> {
    let overlap = Rect {
        lo: [gl.lo[0].max(gu.lo[0]), gl.lo[1].max(gu.lo[1])],
        hi: [gl.hi[0].min(gu.hi[0]), gl.hi[1].min(gu.hi[1])],
    };
    if overlap.hi[0] - overlap.lo[0] <= NODE_TOLERANCE
        || overlap.hi[1] - overlap.lo[1] <= NODE_TOLERANCE
    {
        return Err(ctx.err(
            p,
            format!(
                "sheets `{}` and `{}` do not overlap in (x, z): x ∈ [{}, {}] × z ∈ [{}, {}] \
                 and x ∈ [{}, {}] × z ∈ [{}, {}] mm",
                gl.name,
                gu.name,
                gl.lo[0],
                gl.hi[0],
                gl.lo[1],
                gl.hi[1],
                gu.lo[0],
                gu.hi[0],
                gu.lo[1],
                gu.hi[1]
            ),
        ));
    }
    for (a, b) in [(gl, gu), (gu, gl)] {
        for (i, k) in a.nodes_in(&overlap) {
            let [x, z] = a.xz(i, k);
            if b.node_at(x, z).is_none() {
                return Err(ctx.err(
                    p,
                    format!(
                        "overlapping sheets that do not coincide: `{}` and `{}` overlap, but \
                         node (x, z) = ({x}, {z}) mm of `{}` is not a node of `{}` ({})",
                        gl.name,
                        gu.name,
                        a.name,
                        b.name,
                        b.describe()
                    ),
                ));
            }
        }
    }
    Ok(overlap)
}

/// The node pairs at a joint's listed `points` (at `p.points`): each a node of both sheets, free,
/// and listed once.
fn pairs_at_points(
    ctx: &Ctx,
    p: &str,
    points: &[[f64; 2]],
    ([lower, upper], [gl, gu]): ([usize; 2], [&Grid; 2]),
    supports: &Supports,
) -> Result<Vec<JointPair>, Error> {
    if points.is_empty() {
        return Err(ctx.err(
            format!("{p}.points"),
            "empty list: give the pair locations, or omit `points` to pair every coincident node",
        ));
    }
    let mut found = Vec::new();
    let mut seen = HashSet::new();
    for (q, &[x, z]) in points.iter().enumerate() {
        let pq = format!("{p}.points[{q}]");
        ctx.finite(&format!("{pq}[0]"), x, " mm")?;
        ctx.finite(&format!("{pq}[1]"), z, " mm")?;
        let mut at = [0; 2];
        for (slot, g) in at.iter_mut().zip([gl, gu]) {
            *slot = g.node_at(x, z).ok_or_else(|| {
                ctx.err(
                    &pq,
                    format!(
                        "(x, z) = ({x}, {z}) mm is not a node of sheet `{}` ({})",
                        g.name,
                        g.describe()
                    ),
                )
            })?;
        }
        for n in at {
            if let Some(role) = supports.role(n) {
                return Err(ctx.err(
                    &pq,
                    format!(
                        "node {n} at (x, z) = ({x}, {z}) mm is {role}; a joint pair must be free"
                    ),
                ));
            }
        }
        if let Some(w) = supports.welded(lower, upper, [x, z]) {
            return Err(ctx.err(
                &pq,
                format!(
                    "(x, z) = ({x}, {z}) mm lies inside the nugget of welds[{w}]: the sheets are \
                     welded there, not in contact"
                ),
            ));
        }
        if !seen.insert(at[0]) {
            return Err(ctx.err(&pq, format!("(x, z) = ({x}, {z}) mm is listed twice")));
        }
        found.push(JointPair {
            lower: at[0],
            upper: at[1],
        });
    }
    Ok(found)
}

/// The joints pass of [`super::build`].
impl Sheets<'_> {
    /// The joint pairs, joint by joint in case-file order, within a joint sorted by (x, z) of the
    /// lower node in `nodes`; and the coincident pairs left out (fused by a weld, clamped or tied).
    pub(super) fn joints(
        &self,
        joints: &[JointSpec],
        supports: &Supports,
        nodes: &[[f64; 3]],
    ) -> Result<(Vec<JointPair>, Vec<JointPair>), Error> {
        let (grids, ctx) = (self.grids, self.ctx);
        let mut pairs = Vec::new();
        let mut excluded = Vec::new();
        let mut declared: HashMap<(usize, usize), usize> = HashMap::new();
        for (j, joint) in joints.iter().enumerate() {
            let p = format!("joints[{j}]");
            let lower = self.lookup(&joint.lower, &format!("{p}.lower"))?;
            let upper = self.lookup(&joint.upper, &format!("{p}.upper"))?;
            let (gl, gu) = (&grids[lower], &grids[upper]);
            if lower == upper {
                return Err(ctx.err(
                    format!("{p}.upper"),
                    format!("lower and upper are the same sheet `{}`", gl.name),
                ));
            }
            let key = (lower.min(upper), lower.max(upper));
            if let Some(prev) = declared.insert(key, j) {
                return Err(ctx.err(
                    &p,
                    format!(
                        "duplicate joint between `{}` and `{}` (also joints[{prev}])",
                        gl.name, gu.name
                    ),
                ));
            }
            check_clearance(ctx, &p, gl, gu)?;
            let overlap = overlap(ctx, &p, gl, gu)?;
            let mut found = match &joint.points {
                None => {
                    coincident_pairs([lower, upper], [gl, gu], &overlap, supports, &mut excluded)
                }
                Some(points) => {
                    pairs_at_points(ctx, &p, points, ([lower, upper], [gl, gu]), supports)?
                }
            };
            if found.is_empty() {
                return Err(ctx.err(
                    &p,
                    format!(
                        "the joint between `{}` and `{}` has no node pairs: every coincident \
                         node is clamped, tied or inside a weld nugget",
                        gl.name, gu.name
                    ),
                ));
            }
            found.sort_by(|a, b| {
                let (pa, pb) = (&nodes[a.lower], &nodes[b.lower]);
                pa[0].total_cmp(&pb[0]).then(pa[2].total_cmp(&pb[2]))
            });
            pairs.extend(found);
        }
        Ok((pairs, excluded))
    }
}
