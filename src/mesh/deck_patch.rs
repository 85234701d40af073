//! The re-meshed neighbourhood of a deck's area welds: where the CQUAD4 of a welded sheet form
//! a regular grid (equal shells over a rectangle, as a pre-processor writes a case's sheet),
//! the neighbourhood is built by the rule of a case file's `local_mesh`
//! (`crate::case::LocalMesh`, default `auto`: re-meshed where the shells do not resolve the
//! nugget), so that a deck of a built-in scene is the scene's case. A sheet that is not a
//! regular grid keeps the nugget on its own shells (`auto`, with a warning) or is an error
//! (an explicit size).

use std::collections::HashMap;

use super::build::{check_deck_patches, regular_weld_patch, RegularSheet};
use super::{OwnShellNugget, RigidTie, ShellElem, WeldElem};
use crate::case::{LocalMesh, NODE_TOLERANCE};
use crate::error::Error;

/// A regular sheet with the deck's node and shell of each grid position.
struct Regular {
    sheet: RegularSheet,
    /// Node of grid position (i, k) at `i (nz+1) + k`.
    nodes: Vec<usize>,
    /// Shell of grid cell (i, k) at `i nz + k`.
    shells: Vec<usize>,
}

/// The distinct values of `v` (sorted, merged within [`NODE_TOLERANCE`]) if they are equally
/// spaced.
fn uniform_lines(mut v: Vec<f64>) -> Option<Vec<f64>> {
    v.sort_by(f64::total_cmp);
    let mut lines: Vec<f64> = Vec::new();
    for x in v {
        if lines.last().is_none_or(|&l| x - l > NODE_TOLERANCE) {
            lines.push(x);
        }
    }
    let n = lines.len().checked_sub(1).filter(|&n| n > 0)?;
    let step = (lines[n] - lines[0]) / n as f64;
    lines
        .iter()
        .enumerate()
        .all(|(i, &x)| (x - (lines[0] + i as f64 * step)).abs() <= NODE_TOLERANCE)
        .then_some(lines)
}

/// Sheet `members` (shell indices) as a regular grid, if it is one (`name` for messages).
fn regular(
    name: String,
    members: &[usize],
    shells: &[ShellElem],
    nodes: &[[f64; 3]],
) -> Option<Regular> {
    let mut own: Vec<usize> = members.iter().flat_map(|&e| shells[e].nodes).collect();
    own.sort_unstable();
    own.dedup();
    let y = nodes[own[0]][1];
    if own
        .iter()
        .any(|&n| (nodes[n][1] - y).abs() > NODE_TOLERANCE)
    {
        return None;
    }
    let xs = uniform_lines(own.iter().map(|&n| nodes[n][0]).collect())?;
    let zs = uniform_lines(own.iter().map(|&n| nodes[n][2]).collect())?;
    let (nx, nz) = (xs.len() - 1, zs.len() - 1);
    if own.len() != (nx + 1) * (nz + 1) || members.len() != nx * nz {
        return None;
    }
    let at = |lines: &[f64], v: f64| {
        let i = lines.partition_point(|&l| l < v - NODE_TOLERANCE);
        (i < lines.len() && (lines[i] - v).abs() <= NODE_TOLERANCE).then_some(i)
    };
    let mut grid_nodes = vec![usize::MAX; own.len()];
    let mut position: HashMap<usize, (usize, usize)> = HashMap::with_capacity(own.len());
    for &n in &own {
        let (i, k) = (at(&xs, nodes[n][0])?, at(&zs, nodes[n][2])?);
        let slot = &mut grid_nodes[i * (nz + 1) + k];
        if *slot != usize::MAX {
            return None;
        }
        *slot = n;
        position.insert(n, (i, k));
    }
    let mut grid_shells = vec![usize::MAX; members.len()];
    let mut thickness = None;
    for &e in members {
        let corners = shells[e].nodes.map(|n| position[&n]);
        let (i, k) = corners.iter().copied().min()?;
        let mut want = [(i, k), (i + 1, k), (i + 1, k + 1), (i, k + 1)];
        let mut got = corners;
        want.sort_unstable();
        got.sort_unstable();
        if want != got || i >= nx || k >= nz || grid_shells[i * nz + k] != usize::MAX {
            return None;
        }
        grid_shells[i * nz + k] = e;
        match thickness {
            None => thickness = Some(shells[e].thickness),
            Some(t) if t != shells[e].thickness => return None,
            Some(_) => {}
        }
    }
    Some(Regular {
        sheet: RegularSheet {
            name,
            lo: [xs[0], zs[0]],
            hi: [xs[nx], zs[nz]],
            n: [nx, nz],
            y,
            thickness: thickness?,
        },
        nodes: grid_nodes,
        shells: grid_shells,
    })
}

/// A deck writes a weld through a stack of sheets as one CWELD per two consecutive sheets at the
/// same location: their nuggets (equal centre and diameter, sharing a sheet) become one weld
/// through the whole stack, as a case file's weld is, so that one neighbourhood is re-meshed
/// for it (each rigid disc ties its two sheets; two discs sharing a sheet tie all three, the
/// same constraint).
fn merge_stacks(welds: &mut Vec<WeldElem>) {
    let mut i = 0;
    while i < welds.len() {
        let mut j = i + 1;
        while j < welds.len() {
            let (a, b) = (&welds[i], &welds[j]);
            let same_place = (a.centre[0] - b.centre[0]).abs() <= NODE_TOLERANCE
                && (a.centre[1] - b.centre[1]).abs() <= NODE_TOLERANCE
                && a.diameter == b.diameter;
            let shared = a
                .layers
                .iter()
                .any(|l| b.layers.iter().any(|m| m.sheet == l.sheet));
            if same_place && shared && a.patch.is_none() && b.patch.is_none() {
                let other = welds.remove(j);
                let target = &mut welds[i];
                for layer in other.layers {
                    if !target.layers.iter().any(|l| l.sheet == layer.sheet) {
                        target.layers.push(layer);
                    }
                }
                target.layers.sort_by(|a, b| a.y.total_cmp(&b.y));
                j = i + 1;
            } else {
                j += 1;
            }
        }
        i += 1;
    }
}

/// Gives the deck's area welds the re-meshed neighbourhood `local_mesh` asks for (module docs).
/// `members` are the shells of each sheet; `file` names the deck in errors and warnings.
pub(super) fn weld_patches(
    file: &str,
    welds: &mut Vec<WeldElem>,
    (nodes, shells, members): (&[[f64; 3]], &[ShellElem], &[Vec<usize>]),
    (clamped, tie): (&[usize], &RigidTie),
    local_mesh: LocalMesh,
    warnings: &mut Vec<String>,
) -> Result<(), Error> {
    if local_mesh == LocalMesh::Off {
        return Ok(());
    }
    merge_stacks(welds);
    for weld in welds.iter_mut() {
        let mut stack: Vec<(f64, usize)> = weld.layers.iter().map(|l| (l.y, l.sheet)).collect();
        stack.sort_by(|a, b| a.0.total_cmp(&b.0));
        let grids: Option<Vec<Regular>> = stack
            .iter()
            .map(|&(_, s)| regular(format!("sheet {s}"), &members[s], shells, nodes))
            .collect();
        let Some(grids) = grids else {
            let reason = format!(
                "{file}: the area weld at (x, z) = ({}, {}) mm: a welded sheet's CQUAD4 are not a \
                 regular grid, so its neighbourhood is not re-meshed (the nugget acts on the \
                 sheets' own shells)",
                weld.centre[0], weld.centre[1]
            );
            if let LocalMesh::Size(_) = local_mesh {
                return Err(crate::error::ModelError::PerArea {
                    model: file.to_string(),
                    field: "--deck-local-mesh".into(),
                    reason,
                }
                .into());
            }
            warnings.push(reason);
            continue;
        };
        let sheets: Vec<RegularSheet> = grids.iter().map(|g| g.sheet.clone()).collect();
        let (patch, own_shells) = regular_weld_patch(
            file,
            &sheets,
            weld.index,
            (weld.centre, weld.diameter),
            local_mesh,
            warnings,
        )?;
        weld.own_shells = own_shells;
        if own_shells == OwnShellNugget::BondedSlab && !sampled_alike(weld) {
            // CWELDs merged through a stack of sheets meshed unequally carry different points
            // per pair of sheets; the slab pairs points across the sheets, the RBE3 weld does
            // not need to.
            weld.own_shells = OwnShellNugget::Rbe3;
            warnings.push(format!(
                "{file}: the area weld at (x, z) = ({}, {}) mm: its sheets are sampled unequally \
                 through the stack, so the nugget acts on them through the RBE3 weld instead \
                 of the bonded slab",
                weld.centre[0], weld.centre[1]
            ));
        }
        let Some(mut patch) = patch else {
            continue;
        };
        // The synthetic numbering back to the deck's nodes and shells.
        let (mut first, mut base) = (Vec::new(), Vec::new());
        let (mut f, mut b) = (0, 0);
        for g in &grids {
            first.push(f);
            base.push(b);
            f += g.nodes.len();
            b += g.shells.len();
        }
        for (j, layer) in patch.layers.iter_mut().enumerate() {
            layer.sheet = stack[j].1;
            for n in &mut layer.nodes {
                *n = grids[j].nodes[*n - first[j]];
            }
        }
        for layer in &mut patch.nugget {
            layer.sheet = stack[layer.sheet].1;
        }
        for e in &mut patch.replaced {
            let j = base.iter().rposition(|&b0| b0 <= *e).unwrap_or(0);
            *e = grids[j].shells[*e - base[j]];
        }
        weld.patch = Some(patch);
    }
    let tied: Vec<usize> = tie.slaves.iter().copied().chain([tie.master]).collect();
    check_deck_patches(file, welds, (nodes.len(), clamped, &tied), warnings)
}

/// Whether consecutive layers of `weld` carry the same sampling points (positions and weights):
/// what the bonded slab needs.
fn sampled_alike(weld: &WeldElem) -> bool {
    let mut layers: Vec<&super::NuggetLayer> = weld.layers.iter().collect();
    layers.sort_by(|a, b| a.y.total_cmp(&b.y));
    layers.windows(2).all(|p| {
        p[0].points.len() == p[1].points.len()
            && p[0]
                .points
                .iter()
                .zip(&p[1].points)
                .all(|(a, b)| a.xz == b.xz && a.weight == b.weight)
    })
}
