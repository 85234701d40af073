//! The mesh of a NASTRAN deck ([`crate::case::nastran`]): the references between cards
//! resolved, the sheets found, welds sampled on unstructured shells, pairs oriented.
//!
//! - **Nodes** are the grids an element, the RBE2, a CONM2 or a CGAP uses, in id order with the
//!   RBE2's independent grid last; a grid nothing uses (a CWELD's GS is a location, not a node)
//!   gets no DOF — unused grids other than weld locations are counted in a warning.
//! - **Sheets** are the connected sets of CQUAD4s (shells sharing a node); stacked sheets of a
//!   lap joint share none (their contact runs through CGAP pairs).
//! - **Area welds** (`CWELD` `PARTPAT`, `ELPAT`, `ELEMID`): the weld's two sheets are those of
//!   PIDA/PIDB (the sheet of that PSHELL whose shells contain the weld's location, projected
//!   along y, nearest in y) or of the shells SHIDA/SHIDB. Both must be flat and parallel to the
//!   x–z plane (jointrom's weld stacks along y). The nugget is sampled as for a case
//!   (`nugget`), clipped to where both sheets have shells, each point located in its shell by
//!   inverting the bilinear map in (x, z): the weld's footprint is its diameter, not the
//!   element. `ELEMID` is read as `ELPAT` for that reason. `ALIGN` is a point weld: a `Beam2` of
//!   the PWELD's diameter between GA and GB.
//! - **Pairs** (`CGAP`): lower = GA, upper = GB, normal along GB − GA (the gap opens when GB
//!   moves away from GA along it). A CGAP whose two grids lie inside an area weld's nugget on
//!   that weld's two sheets is fused by the weld, not in contact: it is left out, with a
//!   warning, as a case's joint leaves out the nodes inside a nugget.

use std::cell::RefCell;
use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::rc::Rc;

use super::nugget;
use super::{
    BeamElem, JointPair, Material, Mesh, OwnShellNugget, PointMass, RigidTie, ShellElem, WeldElem,
};
use crate::case::nastran::cards::Position;
use crate::case::nastran::deck::{Location, WeldAttach};
use crate::case::nastran::Deck;
use crate::case::{ContactSpec, LoadSpec, MasterLoadSpec, RampShape, RampSpec, NODE_TOLERANCE};
use crate::error::Error;

/// What a deck gives besides the mesh.
#[derive(Clone, Debug)]
pub struct DeckModel {
    /// The mesh.
    pub mesh: Mesh,
    /// The grid id of each mesh node.
    pub grid_ids: Vec<u64>,
    /// The master load and its time function (TLOAD1 + TABLED1).
    pub load: LoadSpec,
    /// The contact law (PGAP).
    pub contact: ContactSpec,
    /// End time (TSTEP/TSTEPNL), s.
    pub end_time: f64,
    /// Warnings: ignored and unknown cards, unused grids, pairs fused by welds.
    pub warnings: Vec<String>,
    /// Where each shell of [`Mesh::shells`] comes from: file, line and CQUAD4 id, for errors
    /// found when its element is built.
    pub shell_sources: Vec<(std::path::PathBuf, usize, i64)>,
}

/// Builds the mesh of a typed deck (see the module docs), the area welds' neighbourhoods
/// re-meshed by the rule `local_mesh` of a case file's welds (`crate::mesh::deck_patch`).
pub fn build(deck: &Deck, local_mesh: crate::case::LocalMesh) -> Result<DeckModel, Error> {
    let mut warnings = deck.warnings.clone();
    let (nodes, grid_ids, index) = nodes(deck, &mut warnings)?;
    let material = material(deck)?;
    units_warning(deck, &material, &mut warnings);
    let mut shells = shells(deck, &index)?;
    let sheets = Sheets::new(&shells, &nodes);
    for (shell, &sheet) in shells.iter_mut().zip(&sheets.of_shell) {
        shell.sheet = sheet;
    }
    let tie = rigid_tie(deck, &index)?;
    let clamped = clamps(deck, &index, &tie)?;
    let mut beams = beams(deck, &index)?;
    let (mut welds, align) = welds(deck, &index, &nodes, &shells, &sheets)?;
    beams.extend(align);
    super::deck_patch::weld_patches(
        &deck.cards.files[0].display().to_string(),
        &mut welds,
        (&nodes, &shells, &sheets.members),
        (&clamped, &tie),
        local_mesh,
        &mut warnings,
    )?;
    let (pairs, fused, contact) =
        pairs(deck, &index, &nodes, &welds, &clamped, &tie, &mut warnings)?;
    let masses = deck
        .masses
        .iter()
        .map(|m| PointMass {
            node: index[&m.grid],
            mass: m.mass * deck.wtmass,
            inertia: m.inertia.map(|i| i * deck.wtmass),
        })
        .collect();
    let load = load(deck, tie.master, &grid_ids)?;
    let end_time = end_time(deck)?;
    Ok(DeckModel {
        mesh: Mesh {
            nodes,
            sheets: Vec::new(),
            shells,
            beams,
            welds,
            masses,
            clamped,
            tie,
            pairs,
            excluded: fused,
            material,
            warnings: Vec::new(),
        },
        grid_ids,
        load,
        contact,
        end_time,
        warnings,
        shell_sources: deck
            .quads
            .iter()
            .map(|q| (deck.cards.files[q.at.file].clone(), q.at.line, q.id))
            .collect(),
    })
}

fn err(deck: &Deck, what: String, at: Position, reason: impl Into<String>) -> Error {
    deck.cards.error_at(what, at, reason)
}

/// The deck as a whole (no one card at fault): an error on the main file's first line.
fn deck_err(deck: &Deck, reason: impl Into<String>) -> Error {
    err(deck, "deck".into(), Position { file: 0, line: 1 }, reason)
}

/// At most this many of the smallest elements across a nugget (bounds the sampling points,
/// which grow with (d/h)²).
const MAX_NUGGET_ELEMENTS: f64 = 200.0;

type NodeIndex = HashMap<i64, usize>;

/// The used grids: node positions (mm), grid ids and the id → node index map.
type UsedGrids = (Vec<[f64; 3]>, Vec<u64>, NodeIndex);

/// The used grids: positions, ids and the id → node index map; the RBE2 master last.
fn nodes(deck: &Deck, warnings: &mut Vec<String>) -> Result<UsedGrids, Error> {
    let mut used: BTreeSet<i64> = BTreeSet::new();
    let mut refs: Vec<(i64, &str, Position)> = Vec::new();
    for q in &deck.quads {
        refs.extend(q.grids.iter().map(|&g| (g, "CQUAD4", q.at)));
    }
    for b in &deck.beams {
        refs.extend(b.grids.iter().map(|&g| (g, "CBAR/CBEAM", b.at)));
    }
    for w in &deck.welds {
        if let WeldAttach::Align { a, b } = w.attach {
            refs.extend([(a, "CWELD", w.at), (b, "CWELD", w.at)]);
        }
    }
    for r in &deck.rbe2 {
        refs.push((r.master, "RBE2", r.at));
        refs.extend(r.slaves.iter().map(|&g| (g, "RBE2", r.at)));
    }
    for m in &deck.masses {
        refs.push((m.grid, "CONM2", m.at));
    }
    for g in &deck.gaps {
        refs.extend(g.grids.iter().map(|&n| (n, "CGAP", g.at)));
    }
    for (g, card, at) in refs {
        if !deck.grids.contains_key(&g) {
            return Err(err(
                deck,
                card.into(),
                at,
                format!("grid {g} is not defined (no GRID {g})"),
            ));
        }
        used.insert(g);
    }
    let budget = crate::files::dof_budget();
    if used.len().saturating_mul(6) > budget {
        return Err(deck_err(
            deck,
            format!(
                "{} grids (up to {} DOF) exceed the model-size budget of {budget} DOF ({})",
                used.len(),
                6 * used.len(),
                crate::files::DOF_BUDGET_VAR
            ),
        ));
    }
    let locations: BTreeSet<i64> = deck
        .welds
        .iter()
        .filter_map(|w| match w.location {
            Some(Location::Grid(g)) => Some(g),
            _ => None,
        })
        .collect();
    let unused = deck
        .grids
        .keys()
        .filter(|g| !used.contains(g) && !locations.contains(g))
        .count();
    if unused > 0 {
        warnings.push(format!(
            "{}: {unused} grid(s) connect to no element, tie, mass or gap: left out (no DOF)",
            deck.cards.files[0].display()
        ));
    }
    let master = deck.rbe2.first().map(|r| r.master);
    let mut order: Vec<i64> = used
        .iter()
        .copied()
        .filter(|&g| Some(g) != master)
        .collect();
    order.extend(master);
    let index: NodeIndex = order.iter().enumerate().map(|(i, &g)| (g, i)).collect();
    let nodes = order.iter().map(|g| deck.grids[g].xyz).collect();
    Ok((nodes, order.iter().map(|&g| g as u64).collect(), index))
}

/// The one material of the shells, welds and beams (several MAT1 ids with equal values are one
/// material).
fn material(deck: &Deck) -> Result<Material, Error> {
    let mut used: Vec<(i64, String, Position)> = Vec::new();
    for p in deck.pshells.values() {
        used.push((p.mid, "PSHELL".into(), p.at));
    }
    for p in deck.pwelds.values() {
        used.push((p.mid, "PWELD".into(), p.at));
    }
    for p in deck.rods.values() {
        used.push((p.mid, "PBARL/PBEAML".into(), p.at));
    }
    let mut first: Option<(Material, i64)> = None;
    for (mid, card, at) in used {
        let Some(m) = deck.materials.get(&mid) else {
            return Err(err(
                deck,
                card,
                at,
                format!("material {mid} is not defined (no MAT1 {mid})"),
            ));
        };
        let mat = Material {
            youngs_modulus: m.youngs_modulus,
            poisson_ratio: m.poisson_ratio,
            density: m.density * deck.wtmass,
        };
        match first {
            None => first = Some((mat, mid)),
            Some((f, fid)) if f != mat => {
                return Err(err(
                    deck,
                    card,
                    at,
                    format!(
                        "MAT1 {mid} differs from MAT1 {fid}: jointrom's sheets, welds and beams \
                         share one material"
                    ),
                ))
            }
            Some(_) => {}
        }
    }
    first
        .map(|(m, _)| m)
        .ok_or_else(|| deck_err(deck, "no PSHELL: the deck has no sheets"))
}

/// A warning when the material does not look like mm, N, t, s (jointrom's units, and those of
/// most car-body decks): steel is E = 2.1e5 N/mm², ρ = 7.85e-9 t/mm³; in SI it is 2.1e11 Pa and
/// 7850 kg/m³.
fn units_warning(deck: &Deck, m: &Material, warnings: &mut Vec<String>) {
    if m.youngs_modulus > 1e8 || m.density > 1e-5 {
        warnings.push(format!(
            "{}: E = {} and ρ·WTMASS = {} do not look like N/mm² and t/mm³: jointrom reads decks \
             in mm, N, t, s (results in other units are not converted)",
            deck.cards.files[0].display(),
            m.youngs_modulus,
            m.density
        ));
    }
}

fn shells(deck: &Deck, index: &NodeIndex) -> Result<Vec<ShellElem>, Error> {
    let mut seen: HashMap<i64, Position> = HashMap::new();
    let mut out = Vec::with_capacity(deck.quads.len());
    for q in &deck.quads {
        let what = format!("CQUAD4 {}", q.id);
        if let Some(old) = seen.insert(q.id, q.at) {
            return Err(err(
                deck,
                what,
                q.at,
                format!(
                    "element id {} is defined twice (first at {})",
                    q.id,
                    deck.cards.locate(old)
                ),
            ));
        }
        let Some(p) = deck.pshells.get(&q.pid) else {
            return Err(err(
                deck,
                what,
                q.at,
                format!("PSHELL {} is not defined", q.pid),
            ));
        };
        let nodes = q.grids.map(|g| index[&g]);
        let distinct: BTreeSet<usize> = nodes.iter().copied().collect();
        if distinct.len() != 4 {
            return Err(err(
                deck,
                what,
                q.at,
                "a grid appears twice: degenerate quadrilateral",
            ));
        }
        out.push(ShellElem {
            nodes,
            thickness: p.thickness,
            sheet: q.pid as usize,
        });
    }
    if out.is_empty() {
        return Err(deck_err(deck, "no CQUAD4: the deck has no sheets"));
    }
    Ok(out)
}

/// The sheets: connected sets of shells, and a point locator on each.
struct Sheets {
    /// Sheet index of each shell.
    of_shell: Vec<usize>,
    /// The shells of each sheet.
    members: Vec<Vec<usize>>,
}

impl Sheets {
    fn new(shells: &[ShellElem], nodes: &[[f64; 3]]) -> Sheets {
        let mut parent: Vec<usize> = (0..nodes.len()).collect();
        fn find(p: &mut [usize], mut i: usize) -> usize {
            while p[i] != i {
                p[i] = p[p[i]];
                i = p[i];
            }
            i
        }
        for s in shells {
            let r0 = find(&mut parent, s.nodes[0]);
            for &n in &s.nodes[1..] {
                let r = find(&mut parent, n);
                parent[r] = r0;
            }
        }
        let mut label: HashMap<usize, usize> = HashMap::new();
        let mut members: Vec<Vec<usize>> = Vec::new();
        let mut of_shell = Vec::with_capacity(shells.len());
        for (e, s) in shells.iter().enumerate() {
            let root = find(&mut parent, s.nodes[0]);
            let next = label.len();
            let k = *label.entry(root).or_insert(next);
            if k == members.len() {
                members.push(Vec::new());
            }
            members[k].push(e);
            of_shell.push(k);
        }
        Sheets { of_shell, members }
    }
}

fn rigid_tie(deck: &Deck, index: &NodeIndex) -> Result<RigidTie, Error> {
    let Some(r) = deck.rbe2.first() else {
        return Err(deck_err(
            deck,
            "no RBE2: jointrom needs the rigid tie whose independent grid is the master node \
             that carries the load",
        ));
    };
    if let Some(second) = deck.rbe2.get(1) {
        return Err(err(
            deck,
            format!("RBE2 {}", second.id),
            second.at,
            format!(
                "a second RBE2: jointrom has one rigid tie (RBE2 {} at {})",
                r.id,
                deck.cards.locate(r.at)
            ),
        ));
    }
    let master = index[&r.master];
    let mut slaves: Vec<usize> = r.slaves.iter().map(|g| index[g]).collect();
    slaves.sort_unstable();
    let before = slaves.len();
    slaves.dedup();
    if slaves.len() != before || slaves.contains(&master) {
        return Err(err(
            deck,
            format!("RBE2 {}", r.id),
            r.at,
            "a dependent grid is listed twice or is the independent grid GN",
        ));
    }
    Ok(RigidTie { master, slaves })
}

/// The clamped nodes: the selected SPC set (case control `SPC = n`, else the deck's only set)
/// and the grids with PS = 123456.
fn clamps(deck: &Deck, index: &NodeIndex, tie: &RigidTie) -> Result<Vec<usize>, Error> {
    let sets: BTreeSet<i64> = deck
        .spcs
        .iter()
        .map(|s| s.sid)
        .chain(deck.spcadds.keys().copied())
        .collect();
    let selected = match deck.cards.control.spc {
        Some(sid) => Some(sid),
        None if sets.len() <= 1 => sets.first().copied(),
        None => {
            return Err(deck_err(
                deck,
                format!("several SPC sets ({sets:?}) and no case control `SPC = n` to choose one"),
            ))
        }
    };
    let mut wanted: BTreeSet<i64> = BTreeSet::new();
    if let Some(sid) = selected {
        let mut stack = vec![(sid, 0usize)];
        while let Some((s, depth)) = stack.pop() {
            if depth > 16 {
                return Err(deck_err(
                    deck,
                    format!("SPCADD {sid} nests too deep (a cycle?)"),
                ));
            }
            if let Some((members, _)) = deck.spcadds.get(&s) {
                stack.extend(members.iter().map(|&m| (m, depth + 1)));
            } else {
                wanted.insert(s);
            }
        }
    }
    let mut clamped: BTreeSet<usize> = BTreeSet::new();
    for spc in deck.spcs.iter().filter(|s| wanted.contains(&s.sid)) {
        for &(lo, hi) in &spc.grids {
            if lo == hi && !deck.grids.contains_key(&lo) {
                return Err(err(
                    deck,
                    format!("SPC {}", spc.sid),
                    spc.at,
                    format!("grid {lo} is not defined"),
                ));
            }
            for (g, _) in deck.grids.range(lo..=hi) {
                if let Some(&n) = index.get(g) {
                    clamped.insert(n);
                }
            }
        }
    }
    for g in deck.grids.values().filter(|g| g.clamped) {
        if let Some(&n) = index.get(&g.id) {
            clamped.insert(n);
        }
    }
    if clamped.is_empty() {
        return Err(deck_err(
            deck,
            "no clamped grid (SPC1 123456 or GRID PS 123456): jointrom's structures are supported",
        ));
    }
    if let Some(&n) = clamped
        .iter()
        .find(|&&n| n == tie.master || tie.slaves.binary_search(&n).is_ok())
    {
        let grid = index.iter().find(|(_, &i)| i == n).map_or(0, |(&g, _)| g);
        return Err(deck_err(
            deck,
            format!("grid {grid} is both clamped and rigidly tied (RBE2)"),
        ));
    }
    Ok(clamped.into_iter().collect())
}

fn beams(deck: &Deck, index: &NodeIndex) -> Result<Vec<BeamElem>, Error> {
    deck.beams
        .iter()
        .map(|b| {
            let what = format!("CBAR/CBEAM {}", b.id);
            let Some(rod) = deck.rods.get(&b.pid) else {
                return Err(err(
                    deck,
                    what,
                    b.at,
                    format!("PBARL/PBEAML {} is not defined", b.pid),
                ));
            };
            Ok(BeamElem {
                nodes: b.grids.map(|g| index[&g]),
                diameter: rod.diameter,
            })
        })
        .collect()
}

/// A sheet seen for weld sampling: its shells, height and a bucket grid for point location.
struct Layer<'a> {
    sheet: usize,
    shells: Vec<usize>,
    all: &'a [ShellElem],
    nodes: &'a [[f64; 3]],
    y: f64,
    h: f64,
    lo: [f64; 2],
    cell: f64,
    dims: [usize; 2],
    buckets: Vec<Vec<usize>>,
}

impl<'a> Layer<'a> {
    /// The layer of `shells` (indices into `all`), if they are flat at one height y (within
    /// 1e-6 of the sheet's size): `Err(reason)` otherwise.
    fn new(
        sheet: usize,
        shells: Vec<usize>,
        all: &'a [ShellElem],
        nodes: &'a [[f64; 3]],
    ) -> Result<Layer<'a>, String> {
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        let (mut ymin, mut ymax) = (f64::INFINITY, f64::NEG_INFINITY);
        let mut h = f64::INFINITY;
        let mut longest: f64 = 0.0;
        for &e in &shells {
            let p = all[e].nodes.map(|n| nodes[n]);
            for a in 0..4 {
                let b = (a + 1) % 4;
                let edge = (p[b][0] - p[a][0]).hypot(p[b][2] - p[a][2]);
                h = h.min(edge);
                longest = longest.max(edge);
                ymin = ymin.min(p[a][1]);
                ymax = ymax.max(p[a][1]);
                lo = [lo[0].min(p[a][0]), lo[1].min(p[a][2])];
                hi = [hi[0].max(p[a][0]), hi[1].max(p[a][2])];
            }
        }
        let size = (hi[0] - lo[0]).max(hi[1] - lo[1]);
        if ymax - ymin > 1e-6 * size.max(1.0) {
            return Err(format!(
                "its sheet is not flat in an x–z plane (y from {ymin} to {ymax} mm): jointrom's \
                 area weld joins sheets stacked along y"
            ));
        }
        // About as many buckets as shells, no more than the shells need.
        let cell = longest
            .max(size / (shells.len() as f64).sqrt().max(1.0))
            .max(1e-9);
        let dims = [
            (((hi[0] - lo[0]) / cell).floor() as usize + 1).min(shells.len() + 1),
            (((hi[1] - lo[1]) / cell).floor() as usize + 1).min(shells.len() + 1),
        ];
        let mut layer = Layer {
            sheet,
            shells: Vec::new(),
            all,
            nodes,
            y: 0.5 * (ymin + ymax),
            h,
            lo,
            cell,
            dims,
            buckets: vec![Vec::new(); dims[0] * dims[1]],
        };
        for &e in &shells {
            let p = all[e].nodes.map(|n| nodes[n]);
            let (mut a, mut b) = ([usize::MAX; 2], [0usize; 2]);
            for q in p {
                let c = layer.bucket_of([q[0], q[2]]);
                a = [a[0].min(c[0]), a[1].min(c[1])];
                b = [b[0].max(c[0]), b[1].max(c[1])];
            }
            for i in a[0]..=b[0] {
                for k in a[1]..=b[1] {
                    layer.buckets[i * dims[1] + k].push(e);
                }
            }
        }
        layer.shells = shells;
        Ok(layer)
    }

    fn bucket_of(&self, p: [f64; 2]) -> [usize; 2] {
        let mut c = [0; 2];
        for a in 0..2 {
            let s = ((p[a] - self.lo[a]) / self.cell).floor();
            c[a] = if s.is_finite() && s > 0.0 {
                (s as usize).min(self.dims[a] - 1)
            } else {
                0
            };
        }
        c
    }

    /// The shell containing (x, z) (boundary included, within 1e-9 in the natural coordinates)
    /// and its bilinear shape functions there.
    fn locate(&self, p: [f64; 2]) -> Option<nugget::Interpolation> {
        let c = self.bucket_of(p);
        self.buckets[c[0] * self.dims[1] + c[1]]
            .iter()
            .find_map(|&e| {
                let nodes = self.all[e].nodes;
                let xz = nodes.map(|n| [self.nodes[n][0], self.nodes[n][2]]);
                natural(&xz, p).map(|rs| (nodes, shape(rs)))
            })
    }
}

/// The natural coordinates (r, s) ∈ [−1, 1]² of `p` in the bilinear quadrilateral `xz` (corners
/// at r, s = (−1, −1), (1, −1), (1, 1), (−1, 1)), by Newton's method; `None` if outside.
fn natural(xz: &[[f64; 2]; 4], p: [f64; 2]) -> Option<[f64; 2]> {
    const R: [f64; 4] = [-1.0, 1.0, 1.0, -1.0];
    const S: [f64; 4] = [-1.0, -1.0, 1.0, 1.0];
    let (mut r, mut s) = (0.0, 0.0);
    for _ in 0..25 {
        let (mut f, mut j) = ([-p[0], -p[1]], [[0.0; 2]; 2]);
        for a in 0..4 {
            let n = 0.25 * (1.0 + R[a] * r) * (1.0 + S[a] * s);
            let dr = 0.25 * R[a] * (1.0 + S[a] * s);
            let ds = 0.25 * S[a] * (1.0 + R[a] * r);
            for d in 0..2 {
                f[d] += n * xz[a][d];
                j[d][0] += dr * xz[a][d];
                j[d][1] += ds * xz[a][d];
            }
        }
        let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
        if !det.is_finite() || det == 0.0 {
            return None;
        }
        let dr = (j[1][1] * f[0] - j[0][1] * f[1]) / det;
        let ds = (-j[1][0] * f[0] + j[0][0] * f[1]) / det;
        r -= dr;
        s -= ds;
        if dr.abs() + ds.abs() < 1e-14 {
            break;
        }
        if !(r.is_finite() && s.is_finite()) || r.abs() > 10.0 || s.abs() > 10.0 {
            return None;
        }
    }
    const TOL: f64 = 1e-9;
    (r.abs() <= 1.0 + TOL && s.abs() <= 1.0 + TOL).then(|| [r.clamp(-1.0, 1.0), s.clamp(-1.0, 1.0)])
}

/// The bilinear shape functions at (r, s), in corner order.
fn shape([r, s]: [f64; 2]) -> [f64; 4] {
    [
        0.25 * (1.0 - r) * (1.0 - s),
        0.25 * (1.0 + r) * (1.0 - s),
        0.25 * (1.0 + r) * (1.0 + s),
        0.25 * (1.0 - r) * (1.0 + s),
    ]
}

/// Layers by (sheet, PSHELL filter), each built once.
type LayerCache<'a> = HashMap<(usize, Option<i64>), Rc<Layer<'a>>>;

/// The two sides of the area welds: candidate sheets per PSHELL and per shell id, and the layers
/// built so far by (sheet, PSHELL filter) — each built once however many welds it carries.
struct WeldSides<'a> {
    deck: &'a Deck,
    shells: &'a [ShellElem],
    nodes: &'a [[f64; 3]],
    sheets: &'a Sheets,
    shell_of_id: HashMap<i64, usize>,
    sheets_of_part: HashMap<i64, BTreeSet<usize>>,
    cache: RefCell<LayerCache<'a>>,
}

impl<'a> WeldSides<'a> {
    fn new(
        deck: &'a Deck,
        shells: &'a [ShellElem],
        nodes: &'a [[f64; 3]],
        sheets: &'a Sheets,
    ) -> WeldSides<'a> {
        let mut sheets_of_part: HashMap<i64, BTreeSet<usize>> = HashMap::new();
        for (e, q) in deck.quads.iter().enumerate() {
            sheets_of_part
                .entry(q.pid)
                .or_default()
                .insert(sheets.of_shell[e]);
        }
        WeldSides {
            deck,
            shells,
            nodes,
            sheets,
            shell_of_id: deck
                .quads
                .iter()
                .enumerate()
                .map(|(e, q)| (q.id, e))
                .collect(),
            sheets_of_part,
            cache: RefCell::new(HashMap::new()),
        }
    }

    /// The layer of side `side` (`id`: PIDA/PIDB with `by_part`, else SHIDA/SHIDB): among the
    /// candidate sheets, the nearest in y to `location` whose shells contain its (x, z).
    fn pick(
        &self,
        side: &str,
        id: i64,
        by_part: bool,
        location: [f64; 3],
        e: &dyn Fn(String) -> Error,
    ) -> Result<Rc<Layer<'a>>, Error> {
        let (deck, shells, nodes, sheets) = (self.deck, self.shells, self.nodes, self.sheets);
        let centre = [location[0], location[2]];
        let candidates: Vec<usize> = if by_part {
            match self.sheets_of_part.get(&id) {
                Some(set) => set.iter().copied().collect(),
                None => return Err(e(format!("PID{side} {id}: no CQUAD4 has this PSHELL"))),
            }
        } else {
            match self.shell_of_id.get(&id) {
                Some(&s) => vec![sheets.of_shell[s]],
                None => return Err(e(format!("SHID{side} {id}: no such CQUAD4"))),
            }
        };
        // The candidate sheets, nearest in y first, that contain the centre.
        let mut found: Vec<(f64, usize)> = candidates
            .into_iter()
            .map(|k| {
                let y = nodes[shells[sheets.members[k][0]].nodes[0]][1];
                ((y - location[1]).abs(), k)
            })
            .collect();
        found.sort_by(|a, b| a.0.total_cmp(&b.0));
        for (_, k) in found {
            let part = by_part.then_some(id);
            let layer = match self.cache.borrow().get(&(k, part)) {
                Some(l) => Some(Rc::clone(l)),
                None => None,
            };
            let layer = match layer {
                Some(l) => l,
                None => {
                    let members: Vec<usize> = sheets.members[k]
                        .iter()
                        .copied()
                        .filter(|&s| part.is_none_or(|p| deck.quads[s].pid == p))
                        .collect();
                    let l = Rc::new(
                        Layer::new(k, members, shells, nodes)
                            .map_err(|why| e(format!("side {side}: {why}")))?,
                    );
                    self.cache.borrow_mut().insert((k, part), Rc::clone(&l));
                    l
                }
            };
            if layer.locate(centre).is_some() {
                return Ok(layer);
            }
        }
        Err(e(format!(
            "the weld's location (x, z) = ({}, {}) mm lies outside the shells of side {side}",
            centre[0], centre[1]
        )))
    }
}

/// Area welds (and the beams of ALIGN point welds).
fn welds(
    deck: &Deck,
    index: &NodeIndex,
    nodes: &[[f64; 3]],
    shells: &[ShellElem],
    sheets: &Sheets,
) -> Result<(Vec<WeldElem>, Vec<BeamElem>), Error> {
    let sides = WeldSides::new(deck, shells, nodes, sheets);
    let mut out = Vec::new();
    let mut beams = Vec::new();
    for (w, card) in deck.welds.iter().enumerate() {
        let what = format!("CWELD {}", card.id);
        let e = |reason: String| err(deck, what.clone(), card.at, reason);
        let Some(prop) = deck.pwelds.get(&card.pid) else {
            return Err(e(format!("PWELD {} is not defined", card.pid)));
        };
        let d = prop.diameter;
        let location = match &card.location {
            None => {
                let WeldAttach::Align { a, b } = card.attach else {
                    return Err(e("no location".into()));
                };
                if a == b {
                    return Err(e("GA and GB are the same grid".into()));
                }
                beams.push(BeamElem {
                    nodes: [index[&a], index[&b]],
                    diameter: d,
                });
                continue;
            }
            Some(Location::Grid(g)) => match deck.grids.get(g) {
                Some(grid) => grid.xyz,
                None => return Err(e(format!("GS: grid {g} is not defined"))),
            },
            Some(Location::Point(p)) => *p,
        };
        let centre = [location[0], location[2]];
        let (a, b, by_part) = match card.attach {
            WeldAttach::Parts { a, b } => (a, b, true),
            WeldAttach::Elements { a, b } => (a, b, false),
            WeldAttach::Align { .. } => unreachable!("handled above"),
        };
        let (la, lb) = (
            sides.pick("A", a, by_part, location, &e)?,
            sides.pick("B", b, by_part, location, &e)?,
        );
        if la.sheet == lb.sheet {
            return Err(e("both sides are the same sheet".into()));
        }
        let (lower, upper) = if la.y <= lb.y { (la, lb) } else { (lb, la) };
        let h = lower.h.min(upper.h);
        if (d / h).is_nan() || d / h > MAX_NUGGET_ELEMENTS {
            return Err(e(format!(
                "PWELD {}: the nugget diameter D = {d} mm spans {:.0} of the smallest elements \
                 around it ({h} mm; at most {MAX_NUGGET_ELEMENTS})",
                card.pid,
                d / h
            )));
        }
        if upper.y - lower.y <= NODE_TOLERANCE {
            return Err(e("the two sheets are at the same height".into()));
        }
        let inside = |p: [f64; 2]| lower.locate(p).is_some() && upper.locate(p).is_some();
        // One sampling rule for both sheets (the finer one's): the same points on each.
        let h = lower.h.min(upper.h);
        let layers = [&*lower, &*upper]
            .map(|l| {
                let interpolation = |p: [f64; 2]| {
                    l.locate(p)
                        .expect("sampled points lie inside the sheet (checked by `inside`)")
                };
                let view = nugget::SheetView {
                    sheet: l.sheet,
                    y: l.y,
                    h,
                    interpolation: &interpolation,
                };
                nugget::sample(centre, d, &inside, &view)
            })
            .to_vec();
        out.push(WeldElem {
            index: w,
            centre,
            diameter: d,
            layers,
            patch: None,
            own_shells: OwnShellNugget::Rbe3,
        });
    }
    Ok((out, beams))
}

/// The joint pairs (CGAP) and their one contact law (PGAP).
#[allow(clippy::too_many_arguments)]
fn pairs(
    deck: &Deck,
    index: &NodeIndex,
    nodes: &[[f64; 3]],
    welds: &[WeldElem],
    clamped: &[usize],
    tie: &RigidTie,
    warnings: &mut Vec<String>,
) -> Result<(Vec<JointPair>, Vec<JointPair>, ContactSpec), Error> {
    let mut law: Option<(ContactSpec, i64)> = None;
    let mut fused_pairs = Vec::new();
    let mut out = Vec::with_capacity(deck.gaps.len());
    let mut seen: BTreeMap<(usize, usize), i64> = BTreeMap::new();
    let mut fused = Vec::new();
    for g in &deck.gaps {
        let what = format!("CGAP {}", g.id);
        let e = |reason: String| err(deck, what.clone(), g.at, reason);
        let Some(p) = deck.pgaps.get(&g.pid) else {
            return Err(e(format!("PGAP {} is not defined", g.pid)));
        };
        let spec = ContactSpec::per_pair(
            p.normal_stiffness,
            p.friction_coefficient,
            p.stick_stiffness,
        );
        match &law {
            None => law = Some((spec, g.pid)),
            Some((l, pid)) if *l != spec => {
                return Err(e(format!(
                    "PGAP {} differs from PGAP {pid}: jointrom's pairs share one contact law",
                    g.pid
                )))
            }
            Some(_) => {}
        }
        let [a, b] = g.grids.map(|n| index[&n]);
        let (xa, xb) = (nodes[a], nodes[b]);
        let length =
            ((xb[0] - xa[0]).powi(2) + (xb[1] - xa[1]).powi(2) + (xb[2] - xa[2]).powi(2)).sqrt();
        if length.is_nan() || length <= NODE_TOLERANCE {
            return Err(e(
                "GA and GB coincide: the gap direction is read from GA to GB, so they need \
                 distinct positions (a gap coordinate system is not read)"
                    .into(),
            ));
        }
        for (i, n) in [a, b].into_iter().enumerate() {
            let held = clamped.binary_search(&n).is_ok()
                || n == tie.master
                || tie.slaves.binary_search(&n).is_ok();
            if held {
                return Err(e(format!(
                    "grid {} is clamped or rigidly tied: a joint pair needs free nodes",
                    g.grids[i]
                )));
            }
        }
        if let Some(old) = seen.insert((a.min(b), a.max(b)), g.id) {
            return Err(e(format!("the same grids as CGAP {old}")));
        }
        let in_nugget = welds.iter().any(|w| {
            let r = 0.5 * w.diameter;
            let near =
                |x: [f64; 3]| (x[0] - w.centre[0]).hypot(x[2] - w.centre[1]) < r - NODE_TOLERANCE;
            let on = |n: usize| {
                w.layers
                    .iter()
                    .any(|l| (nodes[n][1] - l.y).abs() <= 1e-6 * (1.0 + l.y.abs()))
            };
            near(xa) && near(xb) && on(a) && on(b)
        });
        if in_nugget {
            fused.push(g.id);
            fused_pairs.push(JointPair { lower: a, upper: b });
            continue;
        }
        out.push(JointPair { lower: a, upper: b });
    }
    if !fused.is_empty() {
        warnings.push(format!(
            "{}: CGAP {fused:?} lie inside an area weld's nugget: fused by the weld, not in \
             contact (left out of the joint)",
            deck.cards.files[0].display()
        ));
    }
    match law {
        Some((spec, _)) if !out.is_empty() => Ok((out, fused_pairs, spec)),
        _ => Err(deck_err(
            deck,
            "no CGAP pairs: jointrom's joints are node-to-node CGAP + PGAP pairs",
        )),
    }
}

/// The master load and its time function: the DLOAD (or TLOAD1) set selected by the case
/// control, or the deck's only one.
fn load(deck: &Deck, master: usize, grid_ids: &[u64]) -> Result<LoadSpec, Error> {
    let sets: BTreeSet<i64> = deck
        .dloads
        .keys()
        .chain(deck.tloads.keys())
        .copied()
        .collect();
    let sid = match deck.cards.control.dload {
        Some(sid) => sid,
        None if deck.dloads.len() == 1 => *deck.dloads.keys().next().expect("one"),
        None if deck.dloads.is_empty() && deck.tloads.len() == 1 => {
            *deck.tloads.keys().next().expect("one")
        }
        None if sets.is_empty() => {
            return Err(deck_err(
                deck,
                "no load history: jointrom needs a TLOAD1 (with a TABLED1) of FORCE/MOMENT at \
                 the RBE2's independent grid",
            ))
        }
        None => {
            return Err(deck_err(
                deck,
                format!("several load sets ({sets:?}) and no case control `DLOAD = n`"),
            ))
        }
    };
    let terms: Vec<(f64, i64)> = match deck.dloads.get(&sid) {
        Some(d) => d.terms.iter().map(|&(s, l)| (d.scale * s, l)).collect(),
        None => vec![(1.0, sid)],
    };
    let master_grid = grid_ids[master] as i64;
    let mut components = [0.0; 6];
    let mut time: Option<(i64, f64, Position)> = None;
    for (scale, l) in terms {
        let Some(t) = deck.tloads.get(&l) else {
            return Err(deck_err(
                deck,
                format!("load set {l} (DLOAD {sid}) has no TLOAD1"),
            ));
        };
        match time {
            None => time = Some((t.table, t.delay, t.at)),
            Some((table, delay, _)) if table != t.table || delay != t.delay => {
                return Err(err(
                    deck,
                    format!("TLOAD1 {l}"),
                    t.at,
                    "a second time function: jointrom's load is one table times constant \
                     components (give all TLOAD1s the same TID and delay)",
                ))
            }
            Some(_) => {}
        }
        let mut any = false;
        for entry in deck.loads.iter().filter(|e| e.sid == t.excite) {
            if entry.grid != master_grid {
                return Err(err(
                    deck,
                    format!("load set {}", entry.sid),
                    entry.at,
                    format!(
                        "grid {}: jointrom loads the RBE2's independent grid {master_grid} only",
                        entry.grid
                    ),
                ));
            }
            for k in 0..6 {
                components[k] += scale * entry.components[k];
            }
            any = true;
        }
        if !any {
            return Err(err(
                deck,
                format!("TLOAD1 {l}"),
                t.at,
                format!(
                    "EXCITEID {}: no FORCE, MOMENT or DAREA with this set id",
                    t.excite
                ),
            ));
        }
    }
    let (tid, delay, at) = time.expect("at least one term");
    let Some(table) = deck.tables.get(&tid) else {
        return Err(err(
            deck,
            "TLOAD1".into(),
            at,
            format!("TABLED1 {tid} is not defined"),
        ));
    };
    let mut points: Vec<[f64; 2]> = table.points.iter().map(|p| [p[0] + delay, p[1]]).collect();
    if table.flat {
        let (first, last) = (points[0], points[points.len() - 1]);
        let span = (last[0] - first[0]).abs().max(1.0);
        points.insert(0, [first[0] - span, first[1]]);
        points.push([last[0] + span, last[1]]);
    }
    let ramp = RampSpec {
        shape: RampShape::Table,
        duration: None,
        points,
    };
    ramp.check("TABLED1")
        .map_err(|(_, reason)| err(deck, format!("TABLED1 {tid}"), table.at, reason))?;
    let [fx, fy, fz, mx, my, mz] = components;
    Ok(LoadSpec {
        master: MasterLoadSpec {
            fx,
            fy,
            fz,
            mx,
            my,
            mz,
        },
        ramp,
    })
}

fn end_time(deck: &Deck) -> Result<f64, Error> {
    match deck.cards.control.tstep {
        Some(sid) => deck.tsteps.get(&sid).map(|t| t.0).ok_or_else(|| {
            deck_err(
                deck,
                format!("case control TSTEP = {sid}: no TSTEP/TSTEPNL {sid}"),
            )
        }),
        None if deck.tsteps.len() == 1 => Ok(deck.tsteps.values().next().expect("one").0),
        None if deck.tsteps.is_empty() => Err(deck_err(
            deck,
            "no TSTEP or TSTEPNL: the end time of the transient is Σ N·DT of one",
        )),
        None => Err(deck_err(
            deck,
            "several TSTEP/TSTEPNL sets and no case control `TSTEP = n`",
        )),
    }
}
