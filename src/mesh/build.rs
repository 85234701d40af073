//! Validation of a [`Case`] and generation of its [`Mesh`], in one pass: the checks that need the
//! node grids (clamp lines, weld nodes, joint coincidence) run while the mesh is built, so the
//! validator and the mesh generator cannot disagree. The first problem found, in file order, is
//! returned.

use std::collections::{HashMap, HashSet};

use super::nugget;
use super::Material;
use super::{
    BeamElem, JointPair, Mesh, PatchLayer, RigidTie, SheetGrid, ShellElem, WeldElem, WeldPatch,
};
use crate::case::validate::{check_contact_and_load, check_material, check_sheets, Ctx};
use crate::case::{
    Case, ClampSpec, JointSpec, LocalMesh, RigidTieSpec, WeldModel, WeldSpec, NODE_TOLERANCE,
};
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
    let mut welds = sheets.welds(&case.welds)?;
    check_patches(&ctx, &mut welds.welds, &clamp_of, &tied)?;
    let supports = Supports {
        clamp_of,
        tied,
        nuggets: welds.nuggets,
    };
    let pairs = sheets.joints(&case.joints, &supports, &nodes)?;
    // After the joints' and welds' own checks, which name the field more precisely.
    crate::case::validate::check_stacking(case, &ctx)?;

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
        beams: welds.beams,
        welds: welds.welds,
        masses: Vec::new(),
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

/// A weld's re-meshed neighbourhood (`local_mesh`) may neither hold a clamped or tied node
/// (the small shells would not be held with it) nor overlap another weld's. An explicit size
/// that breaks this is an error; an automatic neighbourhood is left out (checked after every
/// explicit one, in file order).
fn check_patches(
    ctx: &Ctx,
    welds: &mut [WeldElem],
    clamp_of: &[Option<usize>],
    tied: &[bool],
) -> Result<(), Error> {
    let mut owner: HashMap<usize, usize> = HashMap::new();
    for automatic in [false, true] {
        for weld in welds.iter_mut() {
            let Some(patch) = &weld.patch else { continue };
            if patch.automatic != automatic {
                continue;
            }
            let conflict = patch_conflict(patch, weld.index, &owner, clamp_of, tied);
            match conflict {
                None => owner.extend(patch.replaced.iter().map(|&shell| (shell, weld.index))),
                Some(_) if automatic => weld.patch = None,
                Some(reason) => {
                    return Err(ctx.err(format!("welds[{}].local_mesh", weld.index), reason))
                }
            }
        }
    }
    Ok(())
}

/// Why `patch` (of `welds[index]`) is inadmissible given the shells `owner` already gives to
/// other welds' neighbourhoods, if it is.
fn patch_conflict(
    patch: &WeldPatch,
    index: usize,
    owner: &HashMap<usize, usize>,
    clamp_of: &[Option<usize>],
    tied: &[bool],
) -> Option<String> {
    for layer in &patch.layers {
        if let Some(&n) = layer
            .nodes
            .iter()
            .find(|&&n| clamp_of[n].is_some() || tied[n])
        {
            let what = if tied[n] { "rigid tie" } else { "clamp" };
            return Some(format!(
                "the re-meshed neighbourhood ({} ≤ x ≤ {}, {} ≤ z ≤ {} mm) reaches the {what} \
                 (node at x = {} mm): move the weld or set `\"local_mesh\": \"off\"`",
                layer.xs[0],
                layer.xs[layer.xs.len() - 1],
                layer.zs[0],
                layer.zs[layer.zs.len() - 1],
                layer.xs[layer.nodes.iter().position(|&m| m == n).unwrap_or(0) / layer.zs.len()]
            ));
        }
    }
    let other = patch.replaced.iter().find_map(|s| owner.get(s))?;
    debug_assert_ne!(*other, index);
    Some(format!(
        "the re-meshed neighbourhood overlaps that of welds[{other}] (they share shells): the \
         welds are too close for separate neighbourhoods"
    ))
}

/// Half-width of the square around a weld centre whose shells a `local_mesh` re-meshes, in
/// nugget diameters (`crate::element::weld_patch`: measured on the friction bar, a half-width
/// of one diameter leaves the patch's sides where the nugget's field is still strong).
const PATCH_REACH: f64 = 2.0;

/// Most nodes of a weld's re-meshed neighbourhood on one sheet (`local_mesh`).
const MAX_PATCH_NODES: usize = 100_000;

/// Most memory of a weld's condensation (`local_mesh`), bytes.
const MAX_PATCH_BYTES: f64 = 4e9;

/// The small shell of a weld patch's grid (`xs` × `zs`, nodes numbered from `offset`, z
/// fastest) containing `p` and the bilinear shape functions of its nodes there, in
/// [`ShellElem`] node order.
fn fine_interpolation(
    xs: &[f64],
    zs: &[f64],
    offset: usize,
    p: [f64; 2],
) -> ([usize; 4], [f64; 4]) {
    let ((i, xi), (k, eta)) = (super::line_cell(xs, p[0]), super::line_cell(zs, p[1]));
    let nz = zs.len();
    let id = |i: usize, k: usize| offset + i * nz + k;
    (
        [id(i, k), id(i + 1, k), id(i + 1, k + 1), id(i, k + 1)],
        [
            (1.0 - xi) * (1.0 - eta),
            xi * (1.0 - eta),
            xi * eta,
            (1.0 - xi) * eta,
        ],
    )
}

/// Which sheet nodes are held, for excluding them from joints and for messages.
struct Supports {
    /// The clamp (index into `Case::clamps`) holding each sheet node, if any.
    clamp_of: Vec<Option<usize>>,
    /// Whether each sheet node is rigidly tied to the master node.
    tied: Vec<bool>,
    /// The area welds' nuggets: node pairs inside one are welded, not in contact.
    nuggets: Vec<Nugget>,
}

impl Supports {
    fn excluded(&self, n: usize) -> bool {
        self.clamp_of[n].is_some() || self.tied[n]
    }

    /// The area weld (`welds[i]`) whose nugget fuses sheets `lower` and `upper` at `xz`, if any.
    fn welded(&self, lower: usize, upper: usize, xz: [f64; 2]) -> Option<usize> {
        self.nuggets
            .iter()
            .find(|n| n.welds(lower, upper, xz))
            .map(|n| n.index)
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

/// The node pairs of a joint between sheets `[lower, upper]` in their overlap (the `None` case
/// of `points`): every coincident pair neither of whose nodes is clamped or tied and that no
/// area weld's nugget fuses, i-major over the lower sheet.
fn coincident_pairs(
    [lower, upper]: [usize; 2],
    [gl, gu]: [&Grid; 2],
    overlap: &Rect,
    supports: &Supports,
) -> Vec<JointPair> {
    let mut found = Vec::new();
    for (i, k) in gl.nodes_in(overlap) {
        let [x, z] = gl.xz(i, k);
        let l = gl.index(i, k);
        if let Some(u) = gu.node_at(x, z) {
            let welded = supports.welded(lower, upper, [x, z]).is_some();
            if !supports.excluded(l) && !supports.excluded(u) && !welded {
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

    /// The welds: for a point weld one beam between each two consecutive sheets of its stack
    /// at their nodes there, for an area weld its nugget sampled on every sheet of the stack.
    fn welds(&self, welds: &[WeldSpec]) -> Result<Welds, Error> {
        let (grids, ctx) = (self.grids, self.ctx);
        let mut out = Welds::default();
        for (w, weld) in welds.iter().enumerate() {
            let p = format!("welds[{w}]");
            ctx.finite(&format!("{p}.x"), weld.x, " mm")?;
            ctx.finite(&format!("{p}.z"), weld.z, " mm")?;
            ctx.positive(&format!("{p}.diameter"), weld.diameter, " mm")?;
            let stack = self.resolve(&weld.sheets, &format!("{p}.sheets"), 2)?;
            for pair in stack.windows(2) {
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
            }
            self.check_nugget(welds, w, &stack)?;
            if let LocalMesh::Size(size) = weld.local_mesh {
                ctx.positive(&format!("{p}.local_mesh"), size, " mm")?;
                if weld.model == WeldModel::Point {
                    return Err(ctx.err(
                        format!("{p}.local_mesh"),
                        "applies to area welds; a point weld (\"model\": \"point\") joins two \
                         nodes and has no neighbourhood to re-mesh",
                    ));
                }
            }
            match weld.model {
                WeldModel::Point => out.beams.extend(self.point_weld(weld, &p, &stack)?),
                WeldModel::Area => {
                    let mut elem = self.area_weld(w, weld, &stack)?;
                    elem.patch = match weld.local_mesh {
                        LocalMesh::Off => None,
                        LocalMesh::Size(size) => Some(self.weld_patch(w, weld, &stack, size)?),
                        LocalMesh::Auto => self.auto_patch(w, weld, &stack),
                    };
                    out.nuggets.push(Nugget {
                        index: w,
                        centre: elem.centre,
                        radius: 0.5 * elem.diameter,
                        sheets: stack,
                    });
                    out.welds.push(elem);
                }
            }
        }
        Ok(out)
    }

    /// The beams of a point weld: (x, z) must be a node of every sheet of the stack.
    fn point_weld(
        &self,
        weld: &WeldSpec,
        p: &str,
        stack: &[usize],
    ) -> Result<Vec<BeamElem>, Error> {
        let (grids, ctx) = (self.grids, self.ctx);
        let mut weld_nodes = Vec::with_capacity(stack.len());
        for &s in stack {
            let g = &grids[s];
            let n = g.node_at(weld.x, weld.z).ok_or_else(|| {
                ctx.err(
                    p,
                    format!(
                        "(x, z) = ({}, {}) mm is not a node of sheet `{}` ({}); a point weld \
                         (\"model\": \"point\") joins nodes — the area weld (the default) does not \
                         need one",
                        weld.x,
                        weld.z,
                        g.name,
                        g.describe()
                    ),
                )
            })?;
            weld_nodes.push(n);
        }
        Ok(weld_nodes
            .windows(2)
            .map(|pair| BeamElem {
                nodes: [pair[0], pair[1]],
                diameter: weld.diameter,
            })
            .collect())
    }

    /// An area weld (`welds[w]`): its centre must lie inside every sheet of the stack; the
    /// nugget is clipped to the sheets' common rectangle and sampled on each.
    fn area_weld(&self, w: usize, weld: &WeldSpec, stack: &[usize]) -> Result<WeldElem, Error> {
        let (grids, ctx) = (self.grids, self.ctx);
        let centre = [weld.x, weld.z];
        for &s in stack {
            let g = &grids[s];
            let own = Rect { lo: g.lo, hi: g.hi };
            if !own.contains(centre) {
                return Err(ctx.err(
                    format!("welds[{w}]"),
                    format!(
                        "the centre (x, z) = ({}, {}) mm lies outside sheet `{}` (x ∈ [{}, {}], \
                         z ∈ [{}, {}] mm): a weld must lie where all its sheets overlap",
                        weld.x, weld.z, g.name, g.lo[0], g.hi[0], g.lo[1], g.hi[1]
                    ),
                ));
            }
        }
        let clip = Rect::common(stack.iter().map(|&s| &grids[s]));
        let inside = |p: [f64; 2]| clip.contains(p);
        let layers = stack
            .iter()
            .map(|&s| {
                let g = &grids[s];
                let interpolation = |p: [f64; 2]| g.interpolation(p);
                let view = nugget::SheetView {
                    sheet: s,
                    y: g.y,
                    h: g.step[0].min(g.step[1]),
                    interpolation: &interpolation,
                };
                nugget::sample(centre, weld.diameter, &inside, &view)
            })
            .collect();
        Ok(WeldElem {
            index: w,
            centre,
            diameter: weld.diameter,
            layers,
            patch: None,
        })
    }

    /// The neighbourhood `"local_mesh": "auto"` gives area weld `welds[w]`: re-meshed at
    /// d · [`LocalMesh::AUTO_SIZE_PER_DIAMETER`] when a welded sheet's shells have a side longer
    /// than d · [`LocalMesh::AUTO_UNRESOLVED_PER_DIAMETER`] and the neighbourhood is within the
    /// size limits; `None` otherwise (the nugget acts on the sheets' own shells).
    fn auto_patch(&self, w: usize, weld: &WeldSpec, stack: &[usize]) -> Option<WeldPatch> {
        let d = weld.diameter;
        let unresolved = stack.iter().any(|&s| {
            let step = self.grids[s].step;
            step[0].max(step[1]) > LocalMesh::AUTO_UNRESOLVED_PER_DIAMETER * d
        });
        if !unresolved {
            return None;
        }
        let size = LocalMesh::AUTO_SIZE_PER_DIAMETER * d;
        let mut patch = self.weld_patch(w, weld, stack, size).ok()?;
        patch.automatic = true;
        Some(patch)
    }

    /// The re-meshed neighbourhood of area weld `welds[w]` (`local_mesh` = `size`, mm): on each
    /// sheet of the stack the rectangle of its shells that meet the square of half-width
    /// [`PATCH_REACH`] · d around the centre, every shell cut into shells of at most `size`
    /// along each side, and the nugget sampled on those (`crate::element::weld_patch`
    /// condenses them).
    fn weld_patch(
        &self,
        w: usize,
        weld: &WeldSpec,
        stack: &[usize],
        size: f64,
    ) -> Result<WeldPatch, Error> {
        let (grids, ctx) = (self.grids, self.ctx);
        let path = format!("welds[{w}].local_mesh");
        let centre = [weld.x, weld.z];
        let reach = PATCH_REACH * weld.diameter;
        let mut layers = Vec::with_capacity(stack.len());
        let mut replaced = Vec::new();
        let mut nugget = Vec::with_capacity(stack.len());
        let mut offset = 0usize;
        let clip = Rect::common(stack.iter().map(|&s| &grids[s]));
        let inside = |p: [f64; 2]| clip.contains(p);
        for &s in stack {
            let g = &grids[s];
            let h = g.step[0].min(g.step[1]);
            if size >= h {
                return Err(ctx.err(
                    path.as_str(),
                    format!(
                        "{size} mm is not smaller than the elements of sheet `{}` ({h} mm): \
                         nothing to re-mesh",
                        g.name
                    ),
                ));
            }
            let range = |a: usize| {
                let lo = (centre[a] - reach - g.lo[a]) / g.step[a];
                let hi = (centre[a] + reach - g.lo[a]) / g.step[a];
                let i0 = (lo + 1e-9).floor().clamp(0.0, g.n[a] as f64 - 1.0) as usize;
                let i1 = ((hi - 1e-9).ceil().clamp(1.0, g.n[a] as f64) as usize).max(i0 + 1);
                (i0, i1)
            };
            let ((i0, i1), (k0, k1)) = (range(0), range(1));
            let xs: Vec<f64> = (i0..=i1).map(|i| g.coord(0, i)).collect();
            let zs: Vec<f64> = (k0..=k1).map(|k| g.coord(1, k)).collect();
            let nodes = (i0..=i1)
                .flat_map(|i| (k0..=k1).map(move |k| g.index(i, k)))
                .collect();
            let fine = |lines: &[f64]| -> Vec<f64> {
                let mut out = vec![lines[0]];
                for pair in lines.windows(2) {
                    let m = ((pair[1] - pair[0]) / size - 1e-9).ceil().max(1.0) as usize;
                    out.extend(
                        (1..=m).map(|j| pair[0] + (pair[1] - pair[0]) * j as f64 / m as f64),
                    );
                }
                out
            };
            let (fine_xs, fine_zs) = (fine(&xs), fine(&zs));
            let count = fine_xs.len() * fine_zs.len();
            if count > MAX_PATCH_NODES {
                return Err(ctx.err(
                    path.as_str(),
                    format!(
                        "{size} mm shells over the {} × {} mm around the nugget on sheet `{}` \
                         would be {count} nodes (at most {MAX_PATCH_NODES} per sheet)",
                        xs[xs.len() - 1] - xs[0],
                        zs[zs.len() - 1] - zs[0],
                        g.name
                    ),
                ));
            }
            let base = self.shell_base(s);
            replaced.extend((i0..i1).flat_map(|i| (k0..k1).map(move |k| base + i * g.n[1] + k)));
            let interpolation = |p: [f64; 2]| fine_interpolation(&fine_xs, &fine_zs, offset, p);
            let view = nugget::SheetView {
                sheet: s,
                y: g.y,
                h: size,
                interpolation: &interpolation,
            };
            nugget.push(nugget::sample(centre, weld.diameter, &inside, &view));
            offset += count;
            layers.push(PatchLayer {
                sheet: s,
                y: g.y,
                thickness: g.thickness,
                xs,
                zs,
                nodes,
                fine_xs,
                fine_zs,
                free_side: [i0 == 0, i1 == g.n[0], k0 == 0, k1 == g.n[1]],
            });
        }
        // The condensation keeps two dense (internal DOF × retained DOF) matrices.
        let internal = 6 * offset;
        let retained = 6 * layers.iter().map(|l| l.nodes.len()).sum::<usize>();
        let bytes = 2.0 * 8.0 * internal as f64 * retained as f64;
        if bytes > MAX_PATCH_BYTES {
            return Err(ctx.err(
                path.as_str(),
                format!(
                    "condensing {internal} DOF of {size} mm shells onto the {retained} DOF of the \
                     sheets' nodes around the nugget would take {:.1} GB (at most {:.0} GB): \
                     use larger `local_mesh` shells or a coarser sheet mesh",
                    bytes / 1e9,
                    MAX_PATCH_BYTES / 1e9
                ),
            ));
        }
        Ok(WeldPatch {
            size,
            layers,
            replaced,
            nugget,
            automatic: false,
        })
    }

    /// Index into the mesh's shells of sheet `s`'s first shell ([`nodes_and_shells`] order).
    fn shell_base(&self, s: usize) -> usize {
        self.grids[..s].iter().map(|g| g.n[0] * g.n[1]).sum()
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
                None => coincident_pairs([lower, upper], [gl, gu], &overlap, supports),
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
        Ok(pairs)
    }
}

/// What the welds pass produces.
#[derive(Default)]
struct Welds {
    /// Beams of point welds.
    beams: Vec<BeamElem>,
    /// Area welds.
    welds: Vec<WeldElem>,
    /// The area welds' nuggets, for taking welded node pairs out of the joints.
    nuggets: Vec<Nugget>,
}

/// An area weld's nugget as the joints pass sees it.
struct Nugget {
    /// `welds[index]` in the case file.
    index: usize,
    /// Centre (x, z), mm.
    centre: [f64; 2],
    /// d/2, mm.
    radius: f64,
    /// The welded sheets.
    sheets: Vec<usize>,
}

impl Nugget {
    /// Whether a node pair of sheets `lower`, `upper` at `xz` lies strictly inside the nugget
    /// (farther than [`NODE_TOLERANCE`] from its rim): the sheets are fused there.
    fn welds(&self, lower: usize, upper: usize, xz: [f64; 2]) -> bool {
        self.sheets.contains(&lower)
            && self.sheets.contains(&upper)
            && (xz[0] - self.centre[0]).hypot(xz[1] - self.centre[1]) < self.radius - NODE_TOLERANCE
    }
}

/// An axis-parallel rectangle in (x, z), mm.
pub(super) struct Rect {
    lo: [f64; 2],
    hi: [f64; 2],
}

impl Rect {
    /// Whether `p` lies in the closed rectangle (widened by [`NODE_TOLERANCE`]).
    pub(super) fn contains(&self, p: [f64; 2]) -> bool {
        (0..2).all(|a| p[a] >= self.lo[a] - NODE_TOLERANCE && p[a] <= self.hi[a] + NODE_TOLERANCE)
    }

    /// The intersection of the rectangles of `grids` (empty when `hi < lo` on an axis).
    fn common<'g>(grids: impl IntoIterator<Item = &'g Grid<'g>>) -> Rect {
        let mut r = Rect {
            lo: [f64::NEG_INFINITY; 2],
            hi: [f64::INFINITY; 2],
        };
        for g in grids {
            for a in 0..2 {
                r.lo[a] = r.lo[a].max(g.lo[a]);
                r.hi[a] = r.hi[a].min(g.hi[a]);
            }
        }
        r
    }
}

/// One sheet's node grid in (x, z); axis 0 is x, axis 1 is z.
pub(super) struct Grid<'a> {
    name: &'a str,
    lo: [f64; 2],
    hi: [f64; 2],
    pub(super) step: [f64; 2],
    n: [usize; 2],
    pub(super) y: f64,
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

    /// The shell containing the point `p` = (x, z) of the sheet (the last one along an axis for a
    /// point on the sheet's far edge) and the bilinear shape functions of its nodes at `p`, in
    /// [`ShellElem`] node order.
    pub(super) fn interpolation(&self, p: [f64; 2]) -> ([usize; 4], [f64; 4]) {
        let mut cell = [0usize; 2];
        let mut local = [0.0; 2];
        for a in 0..2 {
            let s = ((p[a] - self.lo[a]) / self.step[a]).clamp(0.0, self.n[a] as f64);
            cell[a] = (s.floor() as usize).min(self.n[a] - 1);
            local[a] = (s - cell[a] as f64).clamp(0.0, 1.0);
        }
        let [i, k] = cell;
        let [xi, eta] = local;
        (
            [
                self.index(i, k),
                self.index(i + 1, k),
                self.index(i + 1, k + 1),
                self.index(i, k + 1),
            ],
            [
                (1.0 - xi) * (1.0 - eta),
                xi * (1.0 - eta),
                xi * eta,
                (1.0 - xi) * eta,
            ],
        )
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
