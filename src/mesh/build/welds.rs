//! The welds pass: point welds' beams, area welds' nuggets and their re-meshed neighbourhoods
//! (`local_mesh`).

use std::collections::HashMap;

use super::{Nugget, Rect, Sheets, Welds};
use crate::case::validate::Ctx;
use crate::case::{LocalMesh, WeldModel, WeldSpec};
use crate::error::Error;
use crate::mesh::nugget;
use crate::mesh::{BeamElem, OwnShellNugget, PatchLayer, WeldElem, WeldPatch};

/// A weld's re-meshed neighbourhood (`local_mesh`) may neither hold a clamped or tied node
/// (the small shells would not be held with it) nor overlap another weld's. An explicit size
/// that breaks this is an error; an automatic neighbourhood is left out (checked after every
/// explicit one, in file order) with a warning in `warnings`.
pub(super) fn check_patches(
    ctx: &Ctx,
    welds: &mut [WeldElem],
    clamp_of: &[Option<usize>],
    tied: &[bool],
    warnings: &mut Vec<String>,
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
                Some(reason) if automatic => {
                    weld.patch = None;
                    warnings.push(downgrade_warning(weld.index, weld.centre, &reason));
                }
                Some(reason) => {
                    return Err(ctx.err(format!("welds[{}].local_mesh", weld.index), reason))
                }
            }
        }
    }
    Ok(())
}

/// The warning for area weld `welds[index]` at `centre` (x, z, mm) whose automatic re-meshed
/// neighbourhood was wanted (its sheets' shells are coarser than the nugget) but cannot be built
/// for `reason`.
fn downgrade_warning(index: usize, centre: [f64; 2], reason: &str) -> String {
    format!(
        "welds[{index}] at (x, z) = ({}, {}) mm: its re-meshed neighbourhood \
         (`\"local_mesh\": \"auto\"`) cannot be built — {reason}; the weld acts on the sheets' \
         own shells, coarser than its nugget (a stiffer, less accurate weld): move it, set \
         `local_mesh` to a size or `\"off\"`, or refine the sheets",
        centre[0], centre[1]
    )
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
/// [`ShellElem`](crate::mesh::ShellElem) node order.
fn fine_interpolation(
    xs: &[f64],
    zs: &[f64],
    offset: usize,
    p: [f64; 2],
) -> ([usize; 4], [f64; 4]) {
    let ((i, xi), (k, eta)) = (
        crate::mesh::line_cell(xs, p[0]),
        crate::mesh::line_cell(zs, p[1]),
    );
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

/// The welds pass of [`super::build`].
impl Sheets<'_> {
    /// The welds: for a point weld one beam between each two consecutive sheets of its stack
    /// at their nodes there, for an area weld its nugget sampled on every sheet of the stack.
    pub(super) fn welds(&self, welds: &[WeldSpec]) -> Result<Welds, Error> {
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
                    (elem.patch, elem.own_shells) =
                        self.neighbourhood(w, weld, &stack, &mut out.warnings)?;
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
        // One sampling rule for the whole stack (the finest sheet's), so that every layer
        // carries the same points: the bonded slab pairs them across the sheets.
        let h = stack
            .iter()
            .map(|&s| grids[s].step[0].min(grids[s].step[1]))
            .fold(f64::INFINITY, f64::min);
        nugget::check_points(weld.diameter, h)
            .map_err(|reason| ctx.err(format!("welds[{w}].diameter"), reason))?;
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
                    h,
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
            own_shells: OwnShellNugget::Rbe3,
        })
    }

    /// How area weld `welds[w]` meets the sheets of `stack` under its `local_mesh`: the
    /// re-meshed neighbourhood, if any, and otherwise how the nugget acts on the sheets' own
    /// shells — the bonded slab under `"auto"` where every welded sheet's shells resolve the
    /// nugget ([`Sheets::resolves_nugget`]), else the RBE3 weld.
    pub(super) fn neighbourhood(
        &self,
        w: usize,
        weld: &WeldSpec,
        stack: &[usize],
        warnings: &mut Vec<String>,
    ) -> Result<(Option<WeldPatch>, OwnShellNugget), Error> {
        Ok(match weld.local_mesh {
            LocalMesh::Off => (None, OwnShellNugget::Rbe3),
            LocalMesh::Size(size) => (
                Some(self.weld_patch(w, weld, stack, size)?),
                OwnShellNugget::Rbe3,
            ),
            LocalMesh::Auto if self.resolves_nugget(weld.diameter, stack) => {
                (None, OwnShellNugget::BondedSlab)
            }
            LocalMesh::Auto => (
                self.auto_patch(w, weld, stack, warnings),
                OwnShellNugget::Rbe3,
            ),
        })
    }

    /// Whether the shells of every sheet of `stack` resolve a nugget of `diameter` (mm): no side
    /// longer than d · [`LocalMesh::AUTO_UNRESOLVED_PER_DIAMETER`].
    fn resolves_nugget(&self, diameter: f64, stack: &[usize]) -> bool {
        stack.iter().all(|&s| {
            let step = self.grids[s].step;
            step[0].max(step[1]) <= LocalMesh::AUTO_UNRESOLVED_PER_DIAMETER * diameter
        })
    }

    /// The neighbourhood `"local_mesh": "auto"` gives area weld `welds[w]`: re-meshed at
    /// d · [`LocalMesh::AUTO_SIZE_PER_DIAMETER`] when a welded sheet's shells have a side longer
    /// than d · [`LocalMesh::AUTO_UNRESOLVED_PER_DIAMETER`] and the neighbourhood is within the
    /// size limits; `None` otherwise (the nugget acts on the sheets' own shells), with a warning
    /// in `warnings` when the neighbourhood was wanted but cannot be built.
    pub(super) fn auto_patch(
        &self,
        w: usize,
        weld: &WeldSpec,
        stack: &[usize],
        warnings: &mut Vec<String>,
    ) -> Option<WeldPatch> {
        if self.resolves_nugget(weld.diameter, stack) {
            return None;
        }
        let size = LocalMesh::AUTO_SIZE_PER_DIAMETER * weld.diameter;
        match self.weld_patch(w, weld, stack, size) {
            Ok(mut patch) => {
                patch.automatic = true;
                Some(patch)
            }
            Err(e) => {
                let reason = match e {
                    Error::Case { reason, .. } => reason,
                    other => other.to_string(),
                };
                warnings.push(downgrade_warning(w, [weld.x, weld.z], &reason));
                None
            }
        }
    }

    /// The re-meshed neighbourhood of area weld `welds[w]` (`local_mesh` = `size`, mm): on each
    /// sheet of the stack the rectangle of its shells that meet the square of half-width
    /// [`PATCH_REACH`] · d around the centre, every shell cut into shells of at most `size`
    /// along each side, and the nugget sampled on those (`crate::element::weld_patch`
    /// condenses them).
    pub(super) fn weld_patch(
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
            // The fine grid's size, counted in floating point before anything is allocated (a
            // sheet spanning 1e308 mm or a `local_mesh` of 1e-300 mm would overflow an index).
            let lines_of = |lines: &[f64]| -> f64 {
                1.0 + lines
                    .windows(2)
                    .map(|pair| ((pair[1] - pair[0]) / size - 1e-9).ceil().max(1.0))
                    .sum::<f64>()
            };
            let planned = lines_of(&xs) * lines_of(&zs);
            if planned.is_nan() || planned > MAX_PATCH_NODES as f64 {
                return Err(ctx.err(
                    path.as_str(),
                    format!(
                        "{size:e} mm shells over the {:e} × {:e} mm around the nugget on sheet \
                         `{}` would be {planned:.3e} nodes (at most {MAX_PATCH_NODES} per sheet)",
                        xs[xs.len() - 1] - xs[0],
                        zs[zs.len() - 1] - zs[0],
                        g.name
                    ),
                ));
            }
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
            nugget::check_points(weld.diameter, size)
                .map_err(|reason| ctx.err(path.as_str(), reason))?;
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

    /// Index into the mesh's shells of sheet `s`'s first shell ([`nodes_and_shells`](super::sheets::nodes_and_shells) order).
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
}
