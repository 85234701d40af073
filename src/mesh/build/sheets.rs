//! The sheets' passes: node grids, nodes and shells, clamps and the rigid tie.

use super::{Grid, Sheets};
use crate::case::validate::{check_sheets, Ctx};
use crate::case::{Case, ClampSpec, RigidTieSpec};
use crate::error::Error;
use crate::mesh::{RigidTie, ShellElem};

/// The sheet nodes (sheet by sheet, i-major) and the shells of every grid; the master node is
/// appended later, by the rigid tie.
pub(super) fn nodes_and_shells(grids: &[Grid]) -> (Vec<[f64; 3]>, Vec<ShellElem>) {
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

/// Checks every sheet's own fields and numbers the nodes.
pub(super) fn sheet_grids<'a>(case: &'a Case, ctx: &Ctx) -> Result<Vec<Grid<'a>>, Error> {
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

/// The passes of [`super::build`] that resolve sheet references: clamps and the rigid tie.
impl Sheets<'_> {
    /// The clamp holding each sheet node (the first one listed, for messages); an error if no
    /// node is clamped.
    pub(super) fn clamps(&self, clamps: &[ClampSpec]) -> Result<Vec<Option<usize>>, Error> {
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
    pub(super) fn rigid_tie(
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
}
