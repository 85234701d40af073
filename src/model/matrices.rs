//! Users' own models: K and M as MatrixMarket files plus a JSON map, read into a [`Model`] that
//! the whole pipeline (bases, statics, transient runs, reports, exports) accepts.
//!
//! NASTRAN (DMAP `OUTPUT4`/pyNastran), Abaqus (`*MATRIX GENERATE`) and ANSYS (`HBMAT`/APDL Math)
//! all export stiffness and mass matrices; converted to MatrixMarket (`%%MatrixMarket matrix
//! coordinate real symmetric|general`, 1-based indices) they are read here by the strict
//! reader of [`super::mtx`]. The map
//! says what the rows mean. Any command that takes a CASE takes the map's path instead:
//!
//! ```text
//! jointrom export-matrices friction_bar --out fb/      # K.mtx, M.mtx, model.json
//! jointrom run fb/model.json                           # the main job on the matrices
//! ```
//!
//! ## The map (`"schema": "jointrom-matrices"`, `"version": 1`)
//!
//! | field | type | meaning |
//! |---|---|---|
//! | `schema`, `version` | string, integer | `"jointrom-matrices"`, `1` |
//! | `name` | string | model name (reports, output folders) |
//! | `description` | string, optional | free text |
//! | `stiffness`, `mass` | string | MatrixMarket files, relative to the map's folder; K in N/mm (N·mm/rad), M in t (t·mm²) |
//! | `nodes` | array | `{ "id": u64, "xyz": [x, y, z] (mm), "rows": [ux, uy, uz, rx, ry, rz] }`; each entry a 1-based matrix row or `null` (no row: fixed, or not modelled) |
//! | `master_node` | u64 | the load-introduction node; its 6 rows are the Craig–Bampton boundary and the output DOF |
//! | `rigid_followers` | array of u64, optional | nodes tied rigidly (RBE2) to the master node; no rows of their own; shown in VTU as `u_m + θ_m × (x − x_m)` |
//! | `fixed_rows` | array of rows, optional | rows removed from K and M before use (SPC'd DOF left in the export) |
//! | `pair_frame` | object, optional | default `{ "normal", "t1", "t2" }` unit vectors for pairs that give none |
//! | `pairs` | array | `{ "lower": id, "upper": id, "normal"?, "t1"?, "t2"?, "area"? }`: node-to-node contact pairs, zero initial clearance, the normal pointing from lower to upper; `n, t1, t2` orthonormal; `area` the pair's tributary area (mm², every pair or none) |
//! | `cells` | array, optional | display cells `{ "type": "quad4" \| "line2", "nodes": [ids], "group"?: i32, "size"?: mm }` |
//! | `load` | object | as in a case file: `master` (`fx, fy, fz` N, `mx, my, mz` N·mm) and `ramp` |
//! | `contact` | object | as in a case file: `normal_stiffness`, `friction_coefficient`, `stick_stiffness`, or per area `normal_stiffness_per_area`, `stick_stiffness_per_area` (N/mm³; the pairs then need their `area`) |
//! | `end_time` | number | simulated span, s |
//! | `max_pair_distance` | number, optional | mm; a pair whose nodes lie farther apart is refused (default 10 × the median pair distance, at least 10⁻³ × the bounding-box diagonal) |
//! | `duplicates` | `"reject"` (default) \| `"sum"`, optional | an entry a MatrixMarket file gives twice: an error naming both lines, or added up |
//!
//! Rows that no node names stay in the model as internal DOF (e.g. scalar points). The kept
//! rows are renumbered in ascending order with the master node's six moved last (the convention
//! of [`Model`]); K and M are stored on the union of their patterns.
//!
//! ## Checks (each error names the file and the field, row or entry)
//! Unknown fields, wrong schema or version, unreadable or non-real MatrixMarket, non-square or
//! mismatched sizes, non-finite or non-symmetric entries (|a_ij − a_ji| > 1e-12 max|a|), a
//! non-positive diagonal (a DOF without stiffness or mass), duplicate node ids, a row named
//! twice, out of range or both named and fixed, a master node without six rows, a pair naming an
//! unknown node or without translation rows along its frame, a pair at the master node or a
//! rigid follower, a pair given twice, a pair whose nodes lie farther apart than
//! `max_pair_distance`, a frame that is not orthonormal
//! (tolerance 1e-6), cells with unknown nodes; the contact law, load and end time as in a case.
//! An indefinite K (unsupported structure) is reported by the first factorization.
//!
//! [`write()`] goes the other way: any model to `K.mtx`, `M.mtx` (symmetric, shortest round-trip
//! decimal, so the numbers come back bit for bit) and `model.json`. `tests/model/matrices.rs` exports
//! the friction bar, reads it back and gets identical matrices, bases, statics and transients.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::assembly::{DofDep, DofMap};
use crate::case::{ContactSpec, LoadSpec};
use crate::error::{Error, ModelError};
use crate::joint::JointOperator;
use crate::joint::PairFrame;
use crate::linalg::SymCsc;
use crate::model::{Cell, CellNodes, Geometry, Model, Origin};

/// The map's `schema` value.
pub const SCHEMA: &str = "jointrom-matrices";
/// The map version this build reads and writes.
pub const VERSION: u32 = 1;
pub use super::mtx::SYMMETRY_TOLERANCE;
/// Tolerance of the orthonormality check of pair frames.
pub const FRAME_TOLERANCE: f64 = 1e-6;

/// The JSON map (see the module docs for every field).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MatrixMap {
    /// Always [`SCHEMA`].
    pub schema: String,
    /// Always [`VERSION`].
    pub version: u32,
    /// Model name.
    pub name: String,
    /// Free text.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub description: Option<String>,
    /// Stiffness file (MatrixMarket), relative to the map's folder; N/mm, N·mm/rad.
    pub stiffness: String,
    /// Mass file (MatrixMarket), relative to the map's folder; t, t·mm².
    pub mass: String,
    /// Nodes with coordinates and rows.
    pub nodes: Vec<MapNode>,
    /// The master (load-introduction) node's id.
    pub master_node: u64,
    /// Nodes tied rigidly to the master node (display only; no rows).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub rigid_followers: Vec<u64>,
    /// 1-based rows removed before use.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub fixed_rows: Vec<usize>,
    /// Default pair frame.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pair_frame: Option<FrameSpec>,
    /// Joint pairs.
    pub pairs: Vec<MapPair>,
    /// Display cells.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub cells: Vec<MapCell>,
    /// Master load and ramp (as in a case file).
    pub load: LoadSpec,
    /// Contact and friction law (as in a case file).
    pub contact: ContactSpec,
    /// Simulated span, s.
    pub end_time: f64,
    /// The largest distance between the two nodes of a joint pair, mm (default: 10 × the
    /// median pair distance, at least 10⁻³ × the model's bounding-box diagonal).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_pair_distance: Option<f64>,
    /// What to do with an entry a MatrixMarket file gives twice: `"reject"` (default) or
    /// `"sum"` (exporters that write element contributions unassembled).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub duplicates: Option<DuplicatePolicy>,
}

/// The map's `duplicates` field.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DuplicatePolicy {
    /// An entry given twice is an error naming both lines.
    #[default]
    Reject,
    /// Entries given twice are added up.
    Sum,
}

impl From<DuplicatePolicy> for super::mtx::Duplicates {
    fn from(p: DuplicatePolicy) -> Self {
        match p {
            DuplicatePolicy::Reject => super::mtx::Duplicates::Reject,
            DuplicatePolicy::Sum => super::mtx::Duplicates::Sum,
        }
    }
}

/// A node of the map.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MapNode {
    /// The user's node id (unique).
    pub id: u64,
    /// Coordinates, mm.
    pub xyz: [f64; 3],
    /// 1-based matrix rows of `[ux, uy, uz, rx, ry, rz]`, `null` for none.
    pub rows: [Option<usize>; 6],
}

/// An orthonormal pair frame.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrameSpec {
    /// Unit normal, from the lower to the upper surface.
    pub normal: [f64; 3],
    /// First unit tangent.
    pub t1: [f64; 3],
    /// Second unit tangent.
    pub t2: [f64; 3],
}

/// A joint pair of the map.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MapPair {
    /// Lower node id.
    pub lower: u64,
    /// Upper node id.
    pub upper: u64,
    /// Unit normal (default: `pair_frame.normal`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub normal: Option<[f64; 3]>,
    /// First tangent (default: `pair_frame.t1`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub t1: Option<[f64; 3]>,
    /// Second tangent (default: `pair_frame.t2`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub t2: Option<[f64; 3]>,
    /// Tributary area of the pair on the joint surface, mm² (> 0; optional, but given for
    /// every pair or none): a contact law per area needs it, and with it the contact area and
    /// pressure are reported.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub area: Option<f64>,
}

/// Display cell kinds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MapCellKind {
    /// 4-node quadrilateral.
    Quad4,
    /// 2-node line.
    Line2,
}

/// A display cell of the map.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MapCell {
    /// Cell kind.
    #[serde(rename = "type")]
    pub kind: MapCellKind,
    /// Node ids (4 or 2).
    pub nodes: Vec<u64>,
    /// Group (e.g. property id), −1 for none.
    #[serde(default = "no_group")]
    pub group: i32,
    /// Thickness or diameter, mm (0 where unknown).
    #[serde(default)]
    pub size: f64,
}

fn no_group() -> i32 {
    -1
}

/// `Some(path)` if `arg` is an existing file whose top-level `schema` is [`SCHEMA`]; `None` for
/// anything else (a case file, a built-in name), which the case loader then reports on.
pub(crate) fn map_file(arg: &str) -> Result<Option<PathBuf>, Error> {
    #[derive(Deserialize)]
    struct Peek {
        schema: Option<String>,
    }
    let path = Path::new(arg);
    if !path.is_file() {
        return Ok(None);
    }
    let text = crate::files::read_text(path)?;
    if !text.contains(SCHEMA) {
        return Ok(None);
    }
    // A file that names the schema but does not parse is a broken map, reported by the map's
    // reader (not as a case file).
    Ok(match serde_json::from_str::<Peek>(&text) {
        Ok(Peek {
            schema: Some(s), ..
        }) if s == SCHEMA => Some(path.to_path_buf()),
        Ok(_) => None,
        Err(_) => Some(path.to_path_buf()),
    })
}

fn field_err(file: &str, path: impl Into<String>, reason: impl Into<String>) -> Error {
    Error::Case {
        file: file.to_string(),
        path: path.into(),
        reason: reason.into(),
        source: None,
    }
}

use super::mtx::Triplet;

fn frame_check(file: &str, path: &str, f: &FrameSpec) -> Result<(), Error> {
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    for (name, v) in [("normal", f.normal), ("t1", f.t1), ("t2", f.t2)] {
        if v.iter().any(|x| !x.is_finite()) || (dot(v, v).sqrt() - 1.0).abs() > FRAME_TOLERANCE {
            return Err(field_err(
                file,
                format!("{path}.{name}"),
                format!("must be a unit vector, got {v:?}"),
            ));
        }
    }
    for (a, b, va, vb) in [
        ("normal", "t1", f.normal, f.t1),
        ("normal", "t2", f.normal, f.t2),
        ("t1", "t2", f.t1, f.t2),
    ] {
        if dot(va, vb).abs() > FRAME_TOLERANCE {
            return Err(field_err(
                file,
                format!("{path}.{b}"),
                format!(
                    "{a} and {b} must be orthogonal, their dot product is {:e}",
                    dot(va, vb)
                ),
            ));
        }
    }
    Ok(())
}

/// Reads a map and its matrices into a [`Model`] (see the module docs).
pub fn load(map_path: &Path) -> Result<Model, Error> {
    let file = map_path.display().to_string();
    let map = read_map(map_path, &file)?;
    let dir = map_path.parent().unwrap_or(Path::new("."));
    let k_path = dir.join(&map.stiffness);
    let m_path = dir.join(&map.mass);
    let dup = map.duplicates.unwrap_or_default().into();
    let (nk, k_trip) = super::mtx::read(&k_path, dup)?;
    let (nm, m_trip) = super::mtx::read(&m_path, dup)?;
    if nk != nm {
        return Err(field_err(
            &file,
            "mass",
            format!("M is {nm} × {nm} but K is {nk} × {nk}"),
        ));
    }
    let rows = nk;

    // Nodes and rows.
    let fixed = fixed_rows(&file, &map, rows)?;
    let reader = MapReader {
        file: &file,
        map: &map,
        index_of: node_index(&file, &map, &fixed)?,
    };
    let master_node = reader.node(map.master_node, "master_node")?;
    let master_rows = reader.master_rows(master_node)?;

    // Renumbering: kept rows ascending, the master's six last.
    let Renumbering {
        new_index,
        n,
        master,
    } = Renumbering::new(&fixed, &master_rows);
    if n <= 6 {
        return Err(field_err(
            &file,
            "nodes",
            format!("the model has {n} DOF; it needs DOF besides the master node's six"),
        ));
    }
    let (stiffness, mass) = union_pattern(n, &new_index, &k_trip, &m_trip);
    check_diagonals(
        &new_index,
        [("K", &stiffness, &k_path), ("M", &mass, &m_path)],
    )?;

    let (dof_map, followers) = reader.dof_map(master_node, &new_index, n, master)?;
    let pairs = reader.pairs(&dof_map)?;
    let joint = JointOperator::new(&pairs, &dof_map)?;
    let geometry = Geometry {
        cells: reader.cells()?,
        nodes: map.nodes.iter().map(|nd| nd.xyz).collect(),
        node_ids: map.nodes.iter().map(|nd| nd.id).collect(),
        followers,
    };
    let pair_areas = reader.pair_areas()?;
    let per_area = map.contact.per_area();
    let mut model = Model {
        name: map.name,
        source: file,
        origin: Origin::Matrices {
            map: map_path.to_path_buf(),
            stiffness: k_path,
            mass: m_path,
        },
        geometry,
        pairs,
        dof_map,
        stiffness,
        mass,
        joint,
        load: map.load,
        warnings: Vec::new(),
        pair_areas,
        pair_weights: None,
        point_positions: None,
        contact: map.contact,
        end_time: map.end_time,
    };
    if model.contact.sampling.is_some() {
        return Err(field_err(
            &model.source,
            "contact.sampling",
            "contact points inside the joint's faces need the mesh's faces, which a matrix map \
             does not have: leave `sampling` out (the pairs are the contact points)",
        ));
    }
    if let Some(kappa) = per_area {
        if model.pair_areas.is_none() {
            return Err(field_err(
                &model.source,
                "pairs[0].area",
                "missing: a contact law per area needs each pair's tributary area (mm²)",
            ));
        }
        model.apply_contact_per_area(kappa, "contact.normal_stiffness_per_area")?;
    }
    Ok(model)
}

/// Reads the map at `map_path` (named `file` in messages) and checks its schema, version, name,
/// contact law, load and end time.
fn read_map(map_path: &Path, file: &str) -> Result<MatrixMap, Error> {
    let text = crate::files::read_text(map_path)?;
    let map: MatrixMap = crate::case::parse_object(&text, file, "a matrix map")?;
    if map.schema != SCHEMA {
        return Err(field_err(
            file,
            "schema",
            format!("must be \"{SCHEMA}\", got \"{}\"", map.schema),
        ));
    }
    if map.version != VERSION {
        return Err(field_err(
            file,
            "version",
            format!("this build reads version {VERSION}, got {}", map.version),
        ));
    }
    if map.name.trim().is_empty() {
        return Err(field_err(file, "name", "must not be empty"));
    }
    crate::case::check_contact_load(&map.contact, &map.load, map.end_time, file)?;
    Ok(map)
}

/// Which of the `rows` matrix rows are fixed (`fixed_rows`, each in range and listed once).
fn fixed_rows(file: &str, map: &MatrixMap, rows: usize) -> Result<Vec<bool>, Error> {
    let mut fixed = vec![false; rows];
    for (k, &r) in map.fixed_rows.iter().enumerate() {
        if r == 0 || r > rows {
            return Err(field_err(
                file,
                format!("fixed_rows[{k}]"),
                format!("row {r} is outside 1..={rows}"),
            ));
        }
        if std::mem::replace(&mut fixed[r - 1], true) {
            return Err(field_err(
                file,
                format!("fixed_rows[{k}]"),
                format!("row {r} is listed twice"),
            ));
        }
    }
    Ok(fixed)
}

/// The index of each node id into `map.nodes`, checking the nodes: ids used once, finite
/// coordinates, and rows in range, not fixed and named by one node DOF only.
fn node_index(file: &str, map: &MatrixMap, fixed: &[bool]) -> Result<HashMap<u64, usize>, Error> {
    let rows = fixed.len();
    let mut index_of: HashMap<u64, usize> = HashMap::with_capacity(map.nodes.len());
    let mut owner: Vec<Option<(usize, usize)>> = vec![None; rows];
    for (i, node) in map.nodes.iter().enumerate() {
        if index_of.insert(node.id, i).is_some() {
            return Err(field_err(
                file,
                format!("nodes[{i}].id"),
                format!("node id {} is used twice", node.id),
            ));
        }
        if node.xyz.iter().any(|x| !x.is_finite()) {
            return Err(field_err(
                file,
                format!("nodes[{i}].xyz"),
                "coordinates must be finite numbers",
            ));
        }
        for (c, r) in node.rows.iter().enumerate() {
            let Some(r) = *r else { continue };
            let path = format!("nodes[{i}].rows[{c}]");
            if r == 0 || r > rows {
                return Err(field_err(
                    file,
                    path,
                    format!("row {r} is outside 1..={rows} (K and M are {rows} × {rows})"),
                ));
            }
            if fixed[r - 1] {
                return Err(field_err(
                    file,
                    path,
                    format!("row {r} is also in fixed_rows"),
                ));
            }
            if let Some((j, d)) = owner[r - 1] {
                return Err(field_err(
                    file,
                    path,
                    format!("row {r} is already nodes[{j}].rows[{d}]"),
                ));
            }
            owner[r - 1] = Some((i, c));
        }
    }
    Ok(index_of)
}

/// The model's DOF numbering: the kept rows ascending, the master node's six last.
struct Renumbering {
    /// The new index of each matrix row (0-based); `None` for a fixed row.
    new_index: Vec<Option<usize>>,
    /// DOF count.
    n: usize,
    /// The master node's DOF, the last six.
    master: [usize; 6],
}

impl Renumbering {
    /// Numbers the rows not `fixed`, with the 0-based `master_rows` last.
    fn new(fixed: &[bool], master_rows: &[usize; 6]) -> Self {
        let rows = fixed.len();
        let mut is_master = vec![false; rows];
        for &r in master_rows {
            is_master[r] = true;
        }
        let mut new_index: Vec<Option<usize>> = vec![None; rows];
        let mut next = 0;
        for r in 0..rows {
            if !fixed[r] && !is_master[r] {
                new_index[r] = Some(next);
                next += 1;
            }
        }
        let n = next + 6;
        for (c, &r) in master_rows.iter().enumerate() {
            new_index[r] = Some(next + c);
        }
        let master = [0, 1, 2, 3, 4, 5].map(|c| next + c);
        Renumbering {
            new_index,
            n,
            master,
        }
    }
}

/// Checks that every kept DOF has a positive diagonal in each of the `(name, matrix, file)`.
fn check_diagonals(
    new_index: &[Option<usize>],
    matrices: [(&str, &SymCsc, &PathBuf); 2],
) -> Result<(), Error> {
    for (name, a, path) in matrices {
        for (r, idx) in new_index.iter().enumerate() {
            let Some(j) = *idx else { continue };
            let d = a.get(j, j);
            if d.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
                return Err(field_err(
                    &path.display().to_string(),
                    format!("entry ({0}, {0})", r + 1),
                    format!(
                        "{name} has diagonal {d:e} at row {}: every kept DOF needs positive \
                         stiffness and mass (unsupported DOF? put it in fixed_rows)",
                        r + 1
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// A map being read, its nodes checked: the parts of [`load`] that refer to nodes by id.
struct MapReader<'a> {
    /// The map's file, for messages.
    file: &'a str,
    map: &'a MatrixMap,
    /// The index of each node id into `map.nodes`.
    index_of: HashMap<u64, usize>,
}

impl MapReader<'_> {
    /// The index of node `id`, or an error at `path`.
    fn node(&self, id: u64, path: &str) -> Result<usize, Error> {
        self.index_of
            .get(&id)
            .copied()
            .ok_or_else(|| field_err(self.file, path, format!("no node has id {id}")))
    }

    /// The master node's six rows, 0-based; an error if one is missing.
    fn master_rows(&self, master_node: usize) -> Result<[usize; 6], Error> {
        let map = self.map;
        let mut master_rows = [0usize; 6];
        for (c, r) in map.nodes[master_node].rows.iter().enumerate() {
            master_rows[c] = r.ok_or_else(|| {
                field_err(
                    self.file,
                    "master_node",
                    format!(
                        "node {} has no row for {}; the master node needs all six DOF \
                         (ux, uy, uz, rx, ry, rz) in the matrices",
                        map.master_node,
                        ["ux", "uy", "uz", "rx", "ry", "rz"][c]
                    ),
                )
            })? - 1;
        }
        Ok(master_rows)
    }

    /// The DOF map (own rows, rigid followers, fixed) and the followers' node indices.
    fn dof_map(
        &self,
        master_node: usize,
        new_index: &[Option<usize>],
        n: usize,
        master: [usize; 6],
    ) -> Result<(DofMap, Vec<usize>), Error> {
        let map = self.map;
        let mut nodes_dep: Vec<[DofDep; 6]> = map
            .nodes
            .iter()
            .map(|nd| {
                nd.rows.map(|r| match r {
                    Some(r) => DofDep::single(new_index[r - 1].expect("named rows are kept")),
                    None => DofDep::FIXED,
                })
            })
            .collect();
        let mut followers = Vec::with_capacity(map.rigid_followers.len());
        let xm = map.nodes[master_node].xyz;
        for (k, &id) in map.rigid_followers.iter().enumerate() {
            let path = format!("rigid_followers[{k}]");
            let i = self.node(id, &path)?;
            if i == master_node || map.nodes[i].rows.iter().any(Option::is_some) {
                return Err(field_err(
                    self.file,
                    path,
                    format!(
                        "node {id} has rows of its own (or is the master); a rigid follower has \
                         none"
                    ),
                ));
            }
            let xs = map.nodes[i].xyz;
            nodes_dep[i] =
                DofDep::rigid_follower(master, [xs[0] - xm[0], xs[1] - xm[1], xs[2] - xm[2]]);
            followers.push(i);
        }
        let dof_map = DofMap {
            nodes: nodes_dep,
            n,
            master,
        };
        Ok((dof_map, followers))
    }

    /// The joint pairs with their frames.
    /// The pairs' `area` values (mm²): all given, positive and finite, or none.
    fn pair_areas(&self) -> Result<Option<Vec<f64>>, Error> {
        let pairs = &self.map.pairs;
        if pairs.iter().all(|p| p.area.is_none()) {
            return Ok(None);
        }
        let mut areas = Vec::with_capacity(pairs.len());
        for (k, p) in pairs.iter().enumerate() {
            let path = format!("pairs[{k}].area");
            match p.area {
                Some(a) if a.is_finite() && a > 0.0 => areas.push(a),
                Some(a) => {
                    return Err(field_err(
                        self.file,
                        &path,
                        format!("must be positive (finite and > 0), got {a} mm²"),
                    ))
                }
                None => {
                    return Err(field_err(
                        self.file,
                        &path,
                        "missing: give every pair's tributary area (mm²) or none",
                    ))
                }
            }
        }
        Ok(Some(areas))
    }

    fn pairs(&self, dof_map: &DofMap) -> Result<Vec<PairFrame>, Error> {
        let map = self.map;
        if map.pairs.is_empty() {
            return Err(field_err(
                self.file,
                "pairs",
                "no joint pairs: the model needs at least one",
            ));
        }
        if let Some(f) = &map.pair_frame {
            frame_check(self.file, "pair_frame", f)?;
        }
        let mut pairs = Vec::with_capacity(map.pairs.len());
        let mut seen = HashMap::with_capacity(map.pairs.len());
        for (k, p) in map.pairs.iter().enumerate() {
            let path = format!("pairs[{k}]");
            for id in [p.lower, p.upper] {
                if id == map.master_node || map.rigid_followers.contains(&id) {
                    return Err(field_err(
                        self.file,
                        &path,
                        format!(
                            "node {id} is the master node or tied rigidly to it: the master \
                             introduces the load and is not a joint node"
                        ),
                    ));
                }
            }
            let key = (p.lower.min(p.upper), p.lower.max(p.upper));
            if let Some(first) = seen.insert(key, k) {
                return Err(field_err(
                    self.file,
                    &path,
                    format!(
                        "the pair ({}, {}) is pairs[{first}] again",
                        p.lower, p.upper
                    ),
                ));
            }
            pairs.push(self.pair(&path, p, dof_map)?);
        }
        self.check_pair_distances(&pairs)?;
        Ok(pairs)
    }

    /// Joint pairs join nodes that face each other across a thin gap: a pair whose nodes are
    /// farther apart than `max_pair_distance` (default: 10 × the median pair distance, at least
    /// 10⁻³ × the model's bounding-box diagonal) is a mistake in the map, not a joint.
    fn check_pair_distances(&self, pairs: &[PairFrame]) -> Result<(), Error> {
        if pairs.is_empty() {
            return Ok(());
        }
        let xyz = |i: usize| self.map.nodes[i].xyz;
        let dist = |p: &PairFrame| {
            let (a, b) = (xyz(p.lower), xyz(p.upper));
            ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
        };
        let limit = match self.map.max_pair_distance {
            Some(l) if l.is_finite() && l > 0.0 => l,
            Some(l) => {
                return Err(field_err(
                    self.file,
                    "max_pair_distance",
                    format!("must be finite and positive (mm), got {l}"),
                ))
            }
            None => {
                let mut d: Vec<f64> = pairs.iter().map(dist).collect();
                d.sort_by(f64::total_cmp);
                let median = d[d.len() / 2];
                let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
                for n in &self.map.nodes {
                    for a in 0..3 {
                        lo[a] = lo[a].min(n.xyz[a]);
                        hi[a] = hi[a].max(n.xyz[a]);
                    }
                }
                let diag = (0..3).map(|a| (hi[a] - lo[a]).powi(2)).sum::<f64>().sqrt();
                (10.0 * median).max(1e-3 * diag)
            }
        };
        for (k, p) in pairs.iter().enumerate() {
            let d = dist(p);
            if d > limit {
                return Err(field_err(
                    self.file,
                    format!("pairs[{k}]"),
                    format!(
                        "nodes {} and {} are {d:.4} mm apart, more than the {limit:.4} mm a \
                         joint pair may span (10 × the median pair distance; set \
                         `max_pair_distance` (mm) if the joint really has such gaps)",
                        self.map.nodes[p.lower].id, self.map.nodes[p.upper].id
                    ),
                ));
            }
        }
        Ok(())
    }

    /// One joint pair (at `path`): two distinct nodes, an orthonormal frame (its own or the
    /// default), and rows along the frame at both nodes.
    fn pair(&self, path: &str, p: &MapPair, dof_map: &DofMap) -> Result<PairFrame, Error> {
        let file = self.file;
        let lower = self.node(p.lower, &format!("{path}.lower"))?;
        let upper = self.node(p.upper, &format!("{path}.upper"))?;
        if lower == upper {
            return Err(field_err(file, path, "lower and upper are the same node"));
        }
        let default = self.map.pair_frame;
        let pick = |own: Option<[f64; 3]>, d: Option<[f64; 3]>, name: &str| {
            own.or(d).ok_or_else(|| {
                field_err(
                    file,
                    format!("{path}.{name}"),
                    "missing, and the map has no `pair_frame` default",
                )
            })
        };
        let frame = FrameSpec {
            normal: pick(p.normal, default.map(|f| f.normal), "normal")?,
            t1: pick(p.t1, default.map(|f| f.t1), "t1")?,
            t2: pick(p.t2, default.map(|f| f.t2), "t2")?,
        };
        if p.normal.is_some() || p.t1.is_some() || p.t2.is_some() {
            frame_check(file, path, &frame)?;
        }
        for (which, i, id) in [("lower", lower, p.lower), ("upper", upper, p.upper)] {
            for (axis, _) in [frame.normal, frame.t1, frame.t2]
                .iter()
                .flat_map(|d| d.iter().enumerate())
                .filter(|(_, w)| **w != 0.0)
            {
                if dof_map.nodes[i][axis].terms().next().is_none() {
                    return Err(field_err(
                        file,
                        format!("{path}.{which}"),
                        format!(
                            "node {id} has no row for u{}; a joint node must move along its \
                             pair frame",
                            ["x", "y", "z"][axis]
                        ),
                    ));
                }
            }
        }
        Ok(PairFrame {
            lower,
            upper,
            normal: frame.normal,
            t1: frame.t1,
            t2: frame.t2,
            face_offsets: [0.0; 2],
        })
    }

    /// The display cells.
    fn cells(&self) -> Result<Vec<Cell>, Error> {
        let map = self.map;
        let mut cells = Vec::with_capacity(map.cells.len());
        for (k, c) in map.cells.iter().enumerate() {
            let path = format!("cells[{k}].nodes");
            let want = match c.kind {
                MapCellKind::Quad4 => 4,
                MapCellKind::Line2 => 2,
            };
            if c.nodes.len() != want {
                return Err(field_err(
                    self.file,
                    path,
                    format!(
                        "a {:?} cell has {want} nodes, got {}",
                        c.kind,
                        c.nodes.len()
                    ),
                ));
            }
            let idx: Vec<usize> = c
                .nodes
                .iter()
                .map(|&id| self.node(id, &path))
                .collect::<Result<_, _>>()?;
            if !c.size.is_finite() || c.size < 0.0 {
                return Err(field_err(
                    self.file,
                    format!("cells[{k}].size"),
                    format!("must be finite and ≥ 0 mm, got {}", c.size),
                ));
            }
            cells.push(Cell {
                nodes: match c.kind {
                    MapCellKind::Quad4 => CellNodes::Quad4([idx[0], idx[1], idx[2], idx[3]]),
                    MapCellKind::Line2 => CellNodes::Line2([idx[0], idx[1]]),
                },
                group: c.group,
                size: c.size,
            });
        }
        Ok(cells)
    }
}

/// K and M renumbered by `new_index` (dropped rows: `None`) on the union of their patterns
/// (both triangles, rows sorted), so both share one symbolic structure.
fn union_pattern(
    n: usize,
    new_index: &[Option<usize>],
    k: &[Triplet],
    m: &[Triplet],
) -> (SymCsc, SymCsc) {
    // Per new column: (new row, K value, M value).
    let mut cols: Vec<Vec<(usize, f64, f64)>> = vec![Vec::new(); n];
    for (trip, is_k) in [(k, true), (m, false)] {
        for &(i, j, v) in trip {
            if let (Some(ni), Some(nj)) = (new_index[i], new_index[j]) {
                cols[nj].push(if is_k { (ni, v, 0.0) } else { (ni, 0.0, v) });
            }
        }
    }
    let mut col_ptr = Vec::with_capacity(n + 1);
    col_ptr.push(0);
    let mut row_idx = Vec::new();
    let mut kv = Vec::new();
    let mut mv = Vec::new();
    for c in &mut cols {
        c.sort_by_key(|e| e.0);
        let mut last = usize::MAX;
        for &(r, a, b) in c.iter() {
            if r == last {
                *kv.last_mut().expect("an entry") += a;
                *mv.last_mut().expect("an entry") += b;
            } else {
                row_idx.push(r);
                kv.push(a);
                mv.push(b);
                last = r;
            }
        }
        col_ptr.push(row_idx.len());
    }
    (
        SymCsc {
            n,
            col_ptr: col_ptr.clone(),
            row_idx: row_idx.clone(),
            values: kv,
        },
        SymCsc {
            n,
            col_ptr,
            row_idx,
            values: mv,
        },
    )
}

/// Writes any model as `K.mtx`, `M.mtx` and `model.json` in `dir` (created if missing): node
/// ids and coordinates, the rows of each node DOF, master node, rigid followers, pairs with
/// their frames, cells, load, contact law and end time. Returns the three paths.
pub fn write(model: &Model, dir: &Path) -> Result<Vec<PathBuf>, Error> {
    crate::files::create_dir(dir)?;
    if model.point_positions.is_some() {
        return Err(ModelError::ExportContactPoints.into());
    }
    let k_path = dir.join("K.mtx");
    let m_path = dir.join("M.mtx");
    let map_path = dir.join("model.json");
    for (a, path) in [(&model.stiffness, &k_path), (&model.mass, &m_path)] {
        crate::files::write_atomic_with(path, |tmp| {
            sprs::io::write_matrix_market_sym(tmp, &a.to_sprs(), sprs::io::SymmetryMode::Symmetric)
        })?;
    }
    let geo = &model.geometry;
    let mut follower = vec![false; geo.nodes.len()];
    for &f in &geo.followers {
        follower[f] = true;
    }
    let mut nodes = Vec::with_capacity(geo.nodes.len());
    for (i, x) in geo.nodes.iter().enumerate() {
        let mut rows = [None; 6];
        if !follower[i] {
            for (c, dep) in model.dof_map.nodes[i].iter().enumerate() {
                rows[c] = match (dep.as_free(), dep.terms().count()) {
                    (Some(r), _) => Some(r + 1),
                    (None, 0) => None,
                    (None, _) => {
                        return Err(ModelError::ExportDependentDof {
                            node: geo.node_ids[i],
                            dof: c,
                        }
                        .into())
                    }
                };
            }
        }
        nodes.push(MapNode {
            id: geo.node_ids[i],
            xyz: *x,
            rows,
        });
    }
    let master = model.master_dofs();
    let master_node = (0..geo.nodes.len())
        .find(|&i| {
            !follower[i] && (0..6).all(|c| model.dof_map.nodes[i][c].as_free() == Some(master[c]))
        })
        .ok_or_else(|| Error::Model(ModelError::ExportNoMasterNode))?;
    let cells = geo
        .cells
        .iter()
        .map(|c| MapCell {
            kind: match c.nodes {
                CellNodes::Quad4(_) => MapCellKind::Quad4,
                CellNodes::Line2(_) => MapCellKind::Line2,
            },
            nodes: c
                .nodes
                .as_slice()
                .iter()
                .map(|&i| geo.node_ids[i])
                .collect(),
            group: c.group,
            size: c.size,
        })
        .collect();
    // A per-area law is written as the file gives it: κ_n, κ_t and the pairs' areas (the
    // resolved per-pair values of a pair of mean area are not repeated).
    let per_area = model.pair_weights.as_ref().and(model.contact.per_area());
    let mut contact = model.contact;
    if per_area.is_some() {
        contact.normal_stiffness = f64::NAN;
        contact.stick_stiffness = f64::NAN;
    }
    let map = MatrixMap {
        schema: SCHEMA.to_string(),
        version: VERSION,
        name: model.name.clone(),
        description: Some(format!(
            "exported by jointrom {} from {}",
            env!("CARGO_PKG_VERSION"),
            model.source
        )),
        stiffness: "K.mtx".to_string(),
        mass: "M.mtx".to_string(),
        nodes,
        master_node: geo.node_ids[master_node],
        rigid_followers: geo.followers.iter().map(|&i| geo.node_ids[i]).collect(),
        fixed_rows: Vec::new(),
        pair_frame: None,
        pairs: model
            .pairs
            .iter()
            .enumerate()
            .map(|(i, p)| MapPair {
                lower: geo.node_ids[p.lower],
                upper: geo.node_ids[p.upper],
                normal: Some(p.normal),
                t1: Some(p.t1),
                t2: Some(p.t2),
                area: per_area.and(model.pair_areas.as_ref().map(|a| a[i])),
            })
            .collect(),
        cells,
        load: model.load.clone(),
        contact,
        end_time: model.end_time,
        duplicates: None,
        max_pair_distance: None,
    };
    crate::files::write_atomic(&map_path, map_text(&map))?;
    Ok(vec![k_path, m_path, map_path])
}

/// The map as JSON text a person can read: the scalar fields first, then one node, pair or
/// cell per line.
fn map_text(map: &MatrixMap) -> String {
    const ORDER: [&str; 16] = [
        "schema",
        "version",
        "name",
        "description",
        "stiffness",
        "mass",
        "master_node",
        "rigid_followers",
        "fixed_rows",
        "pair_frame",
        "load",
        "contact",
        "end_time",
        "nodes",
        "pairs",
        "cells",
    ];
    let value = serde_json::to_value(map).expect("the map serialises");
    let compact = |v: &serde_json::Value| serde_json::to_string(v).expect("JSON serialises");
    let obj = value.as_object().expect("the map is an object");
    let mut keys: Vec<&str> = ORDER
        .iter()
        .copied()
        .filter(|k| obj.contains_key(*k))
        .collect();
    keys.extend(
        obj.keys()
            .map(String::as_str)
            .filter(|k| !ORDER.contains(k)),
    );
    let mut out = String::from("{\n");
    for (i, key) in keys.iter().enumerate() {
        let v = &obj[*key];
        out += &format!("  \"{key}\": ");
        match v.as_array() {
            Some(items) if !items.is_empty() && items[0].is_object() => {
                out += "[\n";
                for (j, item) in items.iter().enumerate() {
                    out += "    ";
                    out += &compact(item);
                    out += if j + 1 < items.len() { ",\n" } else { "\n" };
                }
                out += "  ]";
            }
            _ => out += &compact(v),
        }
        out += if i + 1 < keys.len() { ",\n" } else { "\n" };
    }
    out += "}\n";
    out
}
