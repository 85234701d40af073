//! Validation of a [`Case`] and generation of its [`Mesh`], in one pass: the checks that need the
//! node grids (clamp lines, weld nodes, joint coincidence) run while the mesh is built, so the
//! validator and the mesh generator cannot disagree. The first problem found, in file order, is
//! returned.

use std::collections::{HashMap, HashSet};

use super::Material;
use super::{BeamElem, JointPair, Mesh, RigidTie, SheetGrid, ShellElem};
use crate::case::validate::{check_contact_and_load, check_material, check_sheets, Ctx};
use crate::case::{Case, ClampSpec, JointSpec, RigidTieSpec, WeldSpec, NODE_TOLERANCE};
use crate::error::Error;

/// Relative tolerance of the zero-clearance test of a joint.
const CLEARANCE_TOLERANCE: f64 = 1e-9;

/// Validates `case` and builds its mesh, pass by pass: the material, the sheets' grids, nodes and
/// shells, clamps, the rigid tie, welds, joints, then the contact law and the load.
pub(super) fn build(case: &Case) -> Result<Mesh, Error> {
    let file = if case.source.is_empty() {
        "(case built in code)"
    } else {
        case.source.as_str()
    };
    let ctx = Ctx { file };

    check_material(case, &ctx)?;
    let grids = sheet_grids(case, &ctx)?;
    let names: HashMap<&str, usize> = grids.iter().enumerate().map(|(s, g)| (g.name, s)).collect();
    let sheets = Sheets {
        grids: &grids,
        names: &names,
        ctx: &ctx,
    };

    let (mut nodes, shells) = nodes_and_shells(&grids);
    let clamp_of = sheets.clamps(&case.clamps)?;
    let clamped: Vec<usize> = (0..clamp_of.len())
        .filter(|&n| clamp_of[n].is_some())
        .collect();
    let (tied, tie) = sheets.rigid_tie(&case.rigid_tie, &clamp_of, &mut nodes)?;
    let beams = sheets.welds(&case.welds)?;
    let supports = Supports { clamp_of, tied };
    let pairs = sheets.joints(&case.joints, &supports, &nodes)?;

    check_contact_and_load(case, &ctx)?;

    Ok(Mesh {
        nodes,
        sheets: grids
            .iter()
            .map(|g| SheetGrid {
                name: g.name.to_string(),
                first_node: g.first,
                elements: g.n,
            })
            .collect(),
        shells,
        beams,
        clamped,
        tie,
        pairs,
        material: Material {
            youngs_modulus: case.material.youngs_modulus,
            poisson_ratio: case.material.poisson_ratio,
            density: case.material.density,
        },
    })
}

/// The sheet nodes (sheet by sheet, i-major) and the shells of every grid; the master node is
/// appended later, by the rigid tie.
fn nodes_and_shells(grids: &[Grid]) -> (Vec<[f64; 3]>, Vec<ShellElem>) {
    let sheet_nodes: usize = grids.iter().map(Grid::node_count).sum();
    let mut nodes = Vec::with_capacity(sheet_nodes + 1);
    let mut shells = Vec::new();
    for (s, g) in grids.iter().enumerate() {
        for i in 0..=g.n[0] {
            for k in 0..=g.n[1] {
                let [x, z] = g.xz(i, k);
                nodes.push([x, g.y, z]);
            }
        }
        for i in 0..g.n[0] {
            for k in 0..g.n[1] {
                shells.push(ShellElem {
                    nodes: [
                        g.index(i, k),
                        g.index(i + 1, k),
                        g.index(i + 1, k + 1),
                        g.index(i, k + 1),
                    ],
                    thickness: g.thickness,
                    sheet: s,
                });
            }
        }
    }
    (nodes, shells)
}

/// Which sheet nodes are held, for excluding them from joints and for messages.
struct Supports {
    /// The clamp (index into `Case::clamps`) holding each sheet node, if any.
    clamp_of: Vec<Option<usize>>,
    /// Whether each sheet node is rigidly tied to the master node.
    tied: Vec<bool>,
}

impl Supports {
    fn excluded(&self, n: usize) -> bool {
        self.clamp_of[n].is_some() || self.tied[n]
    }

    /// What holds node `n`, in words, if anything does.
    fn role(&self, n: usize) -> Option<String> {
        match (self.clamp_of[n], self.tied[n]) {
            (Some(c), _) => Some(format!("clamped (clamps[{c}])")),
            (None, true) => Some("rigidly tied (rigid_tie)".to_string()),
            (None, false) => None,
        }
    }
}

/// The node pairs of a joint's overlap (the `None` case of `points`): every coincident pair
/// neither of whose nodes is clamped or tied, i-major over the lower sheet.
fn coincident_pairs(gl: &Grid, gu: &Grid, overlap: &Rect, supports: &Supports) -> Vec<JointPair> {
    let mut found = Vec::new();
    for (i, k) in gl.nodes_in(overlap) {
        let [x, z] = gl.xz(i, k);
        let l = gl.index(i, k);
        if let Some(u) = gu.node_at(x, z) {
            if !supports.excluded(l) && !supports.excluded(u) {
                found.push(JointPair { lower: l, upper: u });
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
    [gl, gu]: [&Grid; 2],
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

/// Checks every sheet's own fields and numbers the nodes.
fn sheet_grids<'a>(case: &'a Case, ctx: &Ctx) -> Result<Vec<Grid<'a>>, Error> {
    check_sheets(case, ctx)?;
    let mut grids = Vec::with_capacity(case.sheets.len());
    let mut first = 0usize;
    for sheet in &case.sheets {
        let [nx, nz] = sheet.elements;
        let grid = Grid {
            name: &sheet.name,
            lo: [sheet.x[0], sheet.z[0]],
            hi: [sheet.x[1], sheet.z[1]],
            step: [
                (sheet.x[1] - sheet.x[0]) / nx as f64,
                (sheet.z[1] - sheet.z[0]) / nz as f64,
            ],
            n: [nx, nz],
            y: sheet.y,
            thickness: sheet.thickness,
            first,
        };
        first += grid.node_count();
        grids.push(grid);
    }
    Ok(grids)
}

/// The sheets by name, for resolving references.
struct Sheets<'a> {
    grids: &'a [Grid<'a>],
    names: &'a HashMap<&'a str, usize>,
    ctx: &'a Ctx<'a>,
}

impl Sheets<'_> {
    fn lookup(&self, name: &str, path: &str) -> Result<usize, Error> {
        self.names.get(name).copied().ok_or_else(|| {
            let known: Vec<String> = self.grids.iter().map(|g| format!("`{}`", g.name)).collect();
            self.ctx.err(
                path,
                format!(
                    "unknown sheet `{name}` (the sheets are {})",
                    known.join(", ")
                ),
            )
        })
    }

    /// Resolves a list of at least `min` distinct sheet names at `path`.
    fn resolve(&self, list: &[String], path: &str, min: usize) -> Result<Vec<usize>, Error> {
        if list.len() < min {
            let reason = match min {
                1 => "lists no sheets; at least one is needed".to_string(),
                _ => format!("lists {} sheet(s); at least {min} are needed", list.len()),
            };
            return Err(self.ctx.err(path, reason));
        }
        let mut out: Vec<usize> = Vec::with_capacity(list.len());
        for (j, name) in list.iter().enumerate() {
            let s = self.lookup(name, &format!("{path}[{j}]"))?;
            if out.contains(&s) {
                return Err(self.ctx.err(
                    format!("{path}[{j}]"),
                    format!("sheet `{name}` is listed twice"),
                ));
            }
            out.push(s);
        }
        Ok(out)
    }

    /// The index i of the node line `x` of sheet `s`, or an error at `path`.
    fn x_line(&self, s: usize, x: f64, path: &str) -> Result<usize, Error> {
        let g = &self.grids[s];
        g.line(0, x).ok_or_else(|| {
            self.ctx.err(
                path,
                format!(
                    "x = {x} mm is not a node line of sheet `{}` ({})",
                    g.name,
                    g.describe()
                ),
            )
        })
    }
}

/// The passes of [`build`] that resolve sheet references.
impl Sheets<'_> {
    /// The clamp holding each sheet node (the first one listed, for messages); an error if no
    /// node is clamped.
    fn clamps(&self, clamps: &[ClampSpec]) -> Result<Vec<Option<usize>>, Error> {
        let (grids, ctx) = (self.grids, self.ctx);
        let sheet_nodes: usize = grids.iter().map(Grid::node_count).sum();
        let mut clamp_of: Vec<Option<usize>> = vec![None; sheet_nodes];
        for (c, clamp) in clamps.iter().enumerate() {
            let p = format!("clamps[{c}]");
            ctx.finite(&format!("{p}.x"), clamp.x, " mm")?;
            for s in self.resolve(&clamp.sheets, &format!("{p}.sheets"), 1)? {
                let g = &grids[s];
                let i = self.x_line(s, clamp.x, &format!("{p}.x"))?;
                for k in 0..=g.n[1] {
                    clamp_of[g.index(i, k)].get_or_insert(c);
                }
            }
        }
        if clamp_of.iter().all(Option::is_none) {
            return Err(ctx.err(
                "clamps",
                "no node is clamped: the structure must be supported by at least one clamp",
            ));
        }
        Ok(clamp_of)
    }

    /// The rigid tie: which sheet nodes are tied, and the tie to the master node, which is
    /// appended to `nodes`. A node cannot be both clamped and tied.
    fn rigid_tie(
        &self,
        tie: &RigidTieSpec,
        clamp_of: &[Option<usize>],
        nodes: &mut Vec<[f64; 3]>,
    ) -> Result<(Vec<bool>, RigidTie), Error> {
        let (grids, ctx) = (self.grids, self.ctx);
        ctx.finite("rigid_tie.x", tie.x, " mm")?;
        for (j, &v) in tie.master.iter().enumerate() {
            ctx.finite(&format!("rigid_tie.master[{j}]"), v, " mm")?;
        }
        let mut tied = vec![false; clamp_of.len()];
        let mut slaves = Vec::new();
        for s in self.resolve(&tie.sheets, "rigid_tie.sheets", 1)? {
            let g = &grids[s];
            let i = self.x_line(s, tie.x, "rigid_tie.x")?;
            for k in 0..=g.n[1] {
                let n = g.index(i, k);
                if let Some(c) = clamp_of[n] {
                    let [x, z] = g.xz(i, k);
                    return Err(ctx.err(
                        "rigid_tie",
                        format!(
                            "node {n} of sheet `{}` at (x, z) = ({x}, {z}) mm is both clamped \
                             (clamps[{c}]) and rigidly tied; a node can be only one of them",
                            g.name
                        ),
                    ));
                }
                tied[n] = true;
                slaves.push(n);
            }
        }
        slaves.sort_unstable();
        let master = nodes.len();
        nodes.push(tie.master);
        Ok((tied, RigidTie { master, slaves }))
    }

    /// The weld beams: one between each two consecutive sheets of a weld's stack.
    fn welds(&self, welds: &[WeldSpec]) -> Result<Vec<BeamElem>, Error> {
        let (grids, ctx) = (self.grids, self.ctx);
        let mut beams = Vec::new();
        for (w, weld) in welds.iter().enumerate() {
            let p = format!("welds[{w}]");
            ctx.finite(&format!("{p}.x"), weld.x, " mm")?;
            ctx.finite(&format!("{p}.z"), weld.z, " mm")?;
            ctx.positive(&format!("{p}.diameter"), weld.diameter, " mm")?;
            let stack = self.resolve(&weld.sheets, &format!("{p}.sheets"), 2)?;
            self.check_nugget(welds, w, &stack)?;
            let mut weld_nodes = Vec::with_capacity(stack.len());
            for &s in &stack {
                let g = &grids[s];
                let n = g.node_at(weld.x, weld.z).ok_or_else(|| {
                    ctx.err(
                        &p,
                        format!(
                            "(x, z) = ({}, {}) mm is not a node of sheet `{}` ({})",
                            weld.x,
                            weld.z,
                            g.name,
                            g.describe()
                        ),
                    )
                })?;
                weld_nodes.push(n);
            }
            for (pair, nodes_pair) in stack.windows(2).zip(weld_nodes.windows(2)) {
                let (lo, hi) = (&grids[pair[0]], &grids[pair[1]]);
                if hi.y <= lo.y {
                    return Err(ctx.err(
                        format!("{p}.sheets"),
                        format!(
                            "sheets must be listed in strictly increasing y: `{}` (y = {} mm) \
                             comes before `{}` (y = {} mm)",
                            lo.name, lo.y, hi.name, hi.y
                        ),
                    ));
                }
                beams.push(BeamElem {
                    nodes: [nodes_pair[0], nodes_pair[1]],
                    diameter: weld.diameter,
                });
            }
        }
        Ok(beams)
    }

    /// The nugget of weld `w` (diameter d, on the sheets `stack`) fits each sheet (d no larger
    /// than the sheet's width, its smaller extent) and does not overlap the nugget of an earlier
    /// weld that shares a sheet (centre distance ≥ (d₁ + d₂)/2).
    fn check_nugget(&self, welds: &[WeldSpec], w: usize, stack: &[usize]) -> Result<(), Error> {
        let (grids, ctx) = (self.grids, self.ctx);
        let weld = &welds[w];
        for &s in stack {
            let g = &grids[s];
            let width = (g.hi[0] - g.lo[0]).min(g.hi[1] - g.lo[1]);
            if weld.diameter > width {
                return Err(ctx.err(
                    format!("welds[{w}].diameter"),
                    format!(
                        "{} mm is larger than the width of sheet `{}` ({width} mm)",
                        weld.diameter, g.name
                    ),
                ));
            }
        }
        for (v, other) in welds[..w].iter().enumerate() {
            if !other.sheets.iter().any(|s| weld.sheets.contains(s)) {
                continue;
            }
            let distance = (weld.x - other.x).hypot(weld.z - other.z);
            let reach = 0.5 * (weld.diameter + other.diameter);
            if distance < reach {
                return Err(ctx.err(
                    format!("welds[{w}]"),
                    format!(
                        "its nugget overlaps that of welds[{v}]: centres {distance} mm apart, \
                         closer than the mean diameter {reach} mm"
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The joint pairs, joint by joint in case-file order, within a joint sorted by (x, z) of the
    /// lower node in `nodes`.
    fn joints(
        &self,
        joints: &[JointSpec],
        supports: &Supports,
        nodes: &[[f64; 3]],
    ) -> Result<Vec<JointPair>, Error> {
        let (grids, ctx) = (self.grids, self.ctx);
        let mut pairs = Vec::new();
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
                None => coincident_pairs(gl, gu, &overlap, supports),
                Some(points) => pairs_at_points(ctx, &p, points, [gl, gu], supports)?,
            };
            if found.is_empty() {
                return Err(ctx.err(
                    &p,
                    format!(
                        "the joint between `{}` and `{}` has no node pairs: every coincident \
                         node is clamped or tied",
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
        Ok(pairs)
    }
}

/// An axis-parallel rectangle in (x, z), mm.
struct Rect {
    lo: [f64; 2],
    hi: [f64; 2],
}

/// One sheet's node grid in (x, z); axis 0 is x, axis 1 is z.
struct Grid<'a> {
    name: &'a str,
    lo: [f64; 2],
    hi: [f64; 2],
    step: [f64; 2],
    n: [usize; 2],
    y: f64,
    thickness: f64,
    first: usize,
}

impl Grid<'_> {
    fn node_count(&self) -> usize {
        (self.n[0] + 1) * (self.n[1] + 1)
    }

    fn index(&self, i: usize, k: usize) -> usize {
        self.first + i * (self.n[1] + 1) + k
    }

    fn coord(&self, axis: usize, i: usize) -> f64 {
        self.lo[axis] + i as f64 * self.step[axis]
    }

    fn xz(&self, i: usize, k: usize) -> [f64; 2] {
        [self.coord(0, i), self.coord(1, k)]
    }

    /// The grid line along `axis` at `v` (within [`NODE_TOLERANCE`]).
    fn line(&self, axis: usize, v: f64) -> Option<usize> {
        let r = ((v - self.lo[axis]) / self.step[axis]).round();
        if !(r >= 0.0 && r <= self.n[axis] as f64) {
            return None;
        }
        let i = r as usize;
        ((self.coord(axis, i) - v).abs() <= NODE_TOLERANCE).then_some(i)
    }

    /// The global index of the node at (x, z), if there is one.
    fn node_at(&self, x: f64, z: f64) -> Option<usize> {
        Some(self.index(self.line(0, x)?, self.line(1, z)?))
    }

    /// The grid nodes (i, k) inside `r` (closed, widened by [`NODE_TOLERANCE`]), i-major.
    fn nodes_in<'r>(&'r self, r: &'r Rect) -> impl Iterator<Item = (usize, usize)> + 'r {
        let inside = |axis: usize, i: usize| {
            let v = self.coord(axis, i);
            v >= r.lo[axis] - NODE_TOLERANCE && v <= r.hi[axis] + NODE_TOLERANCE
        };
        (0..=self.n[0])
            .filter(move |&i| inside(0, i))
            .flat_map(move |i| {
                (0..=self.n[1])
                    .filter(move |&k| inside(1, k))
                    .map(move |k| (i, k))
            })
    }

    /// The grid in words, for messages.
    fn describe(&self) -> String {
        format!(
            "its nodes are at x = {} + i·{} mm, i = 0…{}, and z = {} + k·{} mm, k = 0…{}",
            self.lo[0], self.step[0], self.n[0], self.lo[1], self.step[1], self.n[1]
        )
    }
}
