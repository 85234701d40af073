//! Validation of a [`Case`] and generation of its [`Mesh`], in one pass: the checks that need the
//! node grids (clamp lines, weld nodes, joint coincidence) run while the mesh is built, so the
//! validator and the mesh generator cannot disagree. The first problem found, in file order, is
//! returned.
//!
//! The passes live in their own files: the sheets' nodes, shells, clamps and rigid tie
//! ([`sheets`]), the welds and their re-meshed neighbourhoods ([`welds`]), the joint pairs
//! ([`pairs`]). This file holds the pass order and the types the passes share.

use std::collections::HashMap;

use super::Material;
use super::{BeamElem, Mesh, SheetGrid, WeldElem};
use crate::case::validate::{check_contact_and_load, check_material, Ctx};
use crate::case::{Case, NODE_TOLERANCE};
use crate::error::Error;

mod pairs;
mod sheets;
mod welds;

use sheets::{nodes_and_shells, sheet_grids};
use welds::check_patches;

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
    check_patches(
        &ctx,
        &mut welds.welds,
        &clamp_of,
        &tied,
        &mut welds.warnings,
    )?;
    let supports = Supports {
        clamp_of,
        tied,
        nuggets: welds.nuggets,
    };
    let (pairs, excluded) = sheets.joints(&case.joints, &supports, &nodes)?;
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
        excluded,
        material: Material {
            youngs_modulus: case.material.youngs_modulus,
            poisson_ratio: case.material.poisson_ratio,
            density: case.material.density,
        },
        warnings: welds.warnings,
    })
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

/// What the welds pass produces.
#[derive(Default)]
struct Welds {
    /// Beams of point welds.
    beams: Vec<BeamElem>,
    /// Area welds.
    welds: Vec<WeldElem>,
    /// The area welds' nuggets, for taking welded node pairs out of the joints.
    nuggets: Vec<Nugget>,
    /// Welds whose automatic neighbourhood could not be built.
    warnings: Vec<String>,
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
    /// [`ShellElem`](crate::mesh::ShellElem) node order.
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

/// A deck's sheet whose shells form a regular grid: `n = [nx, nz]` shells of equal size over
/// `[lo, hi]` (x, z; mm) at height `y` (mm), thickness mm.
#[derive(Clone, Debug)]
pub(crate) struct RegularSheet {
    /// The sheet's name in messages.
    pub name: String,
    /// Lower corner (x, z), mm.
    pub lo: [f64; 2],
    /// Upper corner (x, z), mm.
    pub hi: [f64; 2],
    /// Shells along x and z.
    pub n: [usize; 2],
    /// Mid-surface height, mm.
    pub y: f64,
    /// Thickness, mm.
    pub thickness: f64,
}

/// The re-meshed neighbourhood of a deck's area weld (`index`: its place among the deck's
/// welds, centre (x, z) and diameter d in mm) on the regular sheets `stack` (in increasing y),
/// by the rule of a case file's `local_mesh` (`crate::case::LocalMesh`): the same shells, the
/// same nugget sampling. Numbering of the result: node (i, k) of `stack[j]` is
/// `Σ_{l<j} (nx_l+1)(nz_l+1) + i (nz_j+1) + k`, shell (i, k) is `Σ_{l<j} nx_l nz_l + i nz_j + k`
/// (the caller maps both to its own). Without a neighbourhood, how the nugget acts on the
/// sheets' own shells (the case file's rule). An automatic neighbourhood that cannot be built is
/// `None` with a warning; an explicit size that cannot be is an error naming `file`.
pub(crate) fn regular_weld_patch(
    file: &str,
    stack: &[RegularSheet],
    index: usize,
    (centre, diameter): ([f64; 2], f64),
    local_mesh: crate::case::LocalMesh,
    warnings: &mut Vec<String>,
) -> Result<(Option<super::WeldPatch>, super::OwnShellNugget), Error> {
    use crate::case::{WeldModel, WeldSpec};
    let ctx = Ctx { file };
    let mut first = 0;
    let grids: Vec<Grid> = stack
        .iter()
        .map(|s| {
            let grid = Grid {
                name: &s.name,
                lo: s.lo,
                hi: s.hi,
                step: [
                    (s.hi[0] - s.lo[0]) / s.n[0] as f64,
                    (s.hi[1] - s.lo[1]) / s.n[1] as f64,
                ],
                n: s.n,
                y: s.y,
                thickness: s.thickness,
                first,
            };
            first += grid.node_count();
            grid
        })
        .collect();
    let names: HashMap<&str, usize> = grids.iter().enumerate().map(|(s, g)| (g.name, s)).collect();
    let sheets = Sheets {
        grids: &grids,
        names: &names,
        ctx: &ctx,
    };
    let weld = WeldSpec {
        x: centre[0],
        z: centre[1],
        sheets: stack.iter().map(|s| s.name.clone()).collect(),
        diameter,
        model: WeldModel::Area,
        local_mesh,
    };
    let all: Vec<usize> = (0..stack.len()).collect();
    sheets.neighbourhood(index, &weld, &all, warnings)
}

/// [`welds::check_patches`] for a deck's welds: a re-meshed neighbourhood may hold no clamped
/// (`clamped`) or tied (`tied`) node of the `nodes` nodes and overlap no other weld's; an
/// automatic one that does is dropped with a warning, an explicit one is an error naming `file`.
pub(crate) fn check_deck_patches(
    file: &str,
    welds: &mut [WeldElem],
    (nodes, clamped, tied): (usize, &[usize], &[usize]),
    warnings: &mut Vec<String>,
) -> Result<(), Error> {
    let mut clamp_of = vec![None; nodes];
    for &n in clamped {
        clamp_of[n] = Some(0);
    }
    let mut held = vec![false; nodes];
    for &n in tied {
        held[n] = true;
    }
    check_patches(&Ctx { file }, welds, &clamp_of, &held, warnings)
}
