//! Case files: the serde schema of a jointed sheet structure (units mm, N, t, s), its validation
//! with JSON paths (the mesh is generated from it by `crate::mesh::Mesh::from_case`).
//!
//! A case file describes flat sheets parallel to the x–z plane, the clamps that support them, one
//! rigid tie (NASTRAN RBE2) from the free end to a master node that carries the load, spot welds
//! through a stack of sheets, the joints (sheet interfaces with node-to-node contact and
//! friction, zero initial clearance) and the load history. Spot welds are area welds by default
//! (the nugget joins the sheets over its area, anywhere in their overlap: `crate::element::Weld`);
//! `"model": "point"` keeps the paper's beam between two nodes for comparison. The two structures of Witteveen &
//! Pichler (2014), Section 4, ship as built-in cases: [`Case::builtin`]`("friction_bar")`
//! (Section 4.1, 906 DOF; 624 in the joint's 52 pairs — the paper's 648 less the two node pairs
//! at the weld centres, which the area welds fuse) and `"multilayer_sheet"` (Section 4.2, 834 DOF;
//! 86 pairs).
//!
//! ```json
//! {
//!   "name": "friction_bar",
//!   "material": {"youngs_modulus": 210000.0, "poisson_ratio": 0.3, "density": 7.85e-9},
//!   "sheets": [
//!     {"name": "A", "x": [0.0, 125.0], "z": [0.0, 25.0], "y": 0.0, "thickness": 0.5, "elements": [25, 2]},
//!     {"name": "B", "x": [40.0, 165.0], "z": [0.0, 25.0], "y": 0.5, "thickness": 0.5, "elements": [25, 2]}
//!   ],
//!   "clamps": [{"x": 0.0, "sheets": ["A"]}],
//!   "rigid_tie": {"x": 165.0, "sheets": ["B"], "master": [165.0, 0.5, 12.5]},
//!   "welds": [{"x": 60.0, "z": 12.5, "sheets": ["A", "B"], "diameter": 5.0}],
//!   "joints": [{"lower": "A", "upper": "B"}],
//!   "contact": {"normal_stiffness": 1.0e4, "friction_coefficient": 0.25, "stick_stiffness": 1.0e4},
//!   "load": {"master": {"fy": -0.7, "mx": -20.0}, "ramp": {"shape": "half_cosine", "duration": 0.05}},
//!   "end_time": 0.2
//! }
//! ```
//!
//! The load's time function may instead be a table, NASTRAN's `TABLED1` rule (linear between
//! the points, the mean at a jump, the straight line through the end points beyond them):
//! `"ramp": {"shape": "table", "points": [[0.0, 0.0], [0.05, 1.0], [0.2, 1.0]]}` (s, factor).
//! A NASTRAN deck is read into the same model by [`nastran`].
//!
//! # Geometry and numbering
//!
//! Sheet `s` spans `x ∈ [x0, x1]`, `z ∈ [z0, z1]` at height `y` (its mid-surface) and is meshed
//! with `elements = [nx, nz]` 4-node shells. Its node `(i, k)`, `0 ≤ i ≤ nx`, `0 ≤ k ≤ nz`, lies at
//! `(x0 + i·(x1−x0)/nx, y, z0 + k·(z1−z0)/nz)` and has index `first_node + i·(nz+1) + k`; sheets
//! are numbered in file order and the master node comes last. Two points are the same node when
//! they agree within [`NODE_TOLERANCE`] (1e-6 mm) in each coordinate.
//!
//! # Validation
//!
//! [`Case::from_json_str`] (and so [`Case::from_file`], [`Case::builtin`], [`Case::load`])
//! rejects, as [`Error::Case`] with the file, the JSON path and the reason:
//!
//! - malformed JSON, unknown or missing fields and wrong types (path from `serde_path_to_error`;
//!   a missing field's path names the field itself, the document root is `$`);
//! - non-finite numbers; E, density, thickness, diameter, element counts, sheet lengths
//!   (`x[1] > x[0]`, `z[1] > z[0]`), contact stiffnesses, ramp duration and end time that are
//!   not positive; a negative friction coefficient; ν outside (−1, 0.5); a contact stiffness
//!   given both per pair and per area, or neither, and the normal and stick stiffness given
//!   different ways;
//! - empty or duplicate sheet names, an unknown sheet name anywhere, a sheet listed twice;
//! - a clamp or tie `x` that is not a node line of each listed sheet; no clamp at all; a node
//!   that is both clamped and tied;
//! - a weld with fewer than two sheets, with sheets not in strictly increasing y, whose diameter
//!   exceeds a listed sheet's width, whose nugget overlaps an earlier weld's on a shared sheet
//!   (centres closer than the mean diameter), whose centre lies outside a listed sheet (an area
//!   weld: outside the sheets' overlap) or, for a point weld, is not a node of each listed sheet;
//! - a joint whose sheets are the same, are declared twice, have a clearance
//!   (`upper.y − lower.y ≠ (t_lower + t_upper)/2` within 1e-9 of the scale), do not overlap in
//!   (x, z), or overlap without coinciding nodes; an explicit joint point that is not a node of
//!   both sheets, is listed twice, or is clamped or tied; a joint left without pairs; with the
//!   contact law per area, a pair on no face of the joint surface or pairs whose faces do not
//!   cover the joints' overlap (`crate::model::per_area`).
//!
//! [`Case::from_json_str`] checks the material and each sheet's own fields; the other checks above
//! need the node grids and run while `crate::mesh::Mesh::from_case` generates
//! the mesh, which re-runs the field checks too — so a `Case` edited in code cannot produce a
//! broken mesh either, and the validator and the generator cannot disagree.

pub mod nastran;
mod parse;

pub(crate) mod validate;
pub(crate) use parse::parse_object;
pub(crate) use validate::check_contact_load;

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::error::Error;

/// Two coordinates closer than this (mm) in each axis denote the same node.
pub const NODE_TOLERANCE: f64 = 1e-6;

/// A validated case: the structure, the contact law and the load history.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Case {
    /// Name of the case (free text, used in reports).
    pub name: String,
    /// Optional description (free text).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub description: Option<String>,
    /// Material of all sheets and welds.
    pub material: MaterialSpec,
    /// The sheets, in the order their nodes are numbered.
    pub sheets: Vec<SheetSpec>,
    /// Clamps (all 6 DOF fixed) along lines x = const; at least one node must be clamped.
    pub clamps: Vec<ClampSpec>,
    /// The rigid tie of one line x = const to the master node that carries the load.
    pub rigid_tie: RigidTieSpec,
    /// Spot welds through a stack of sheets.
    pub welds: Vec<WeldSpec>,
    /// Joints: interfaces between two sheets with node-to-node contact and friction.
    pub joints: Vec<JointSpec>,
    /// Contact and friction law of all joints.
    pub contact: ContactSpec,
    /// The load on the master node and its time history.
    pub load: LoadSpec,
    /// End of the simulated time span, s (> 0).
    pub end_time: f64,
    /// Where the case came from: the file path as given, or `builtin:<name>`. Not part of the
    /// file; set by the loaders and used as `file` in errors.
    #[serde(skip)]
    pub source: String,
}

/// Linear elastic isotropic material (see [`crate::mesh::Material`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    /// Young's modulus E, N/mm² (> 0).
    pub youngs_modulus: f64,
    /// Poisson's ratio ν, dimensionless (−1 < ν < 0.5).
    pub poisson_ratio: f64,
    /// Mass density ρ, t/mm³ (> 0).
    pub density: f64,
}

/// A flat rectangular sheet parallel to the x–z plane.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SheetSpec {
    /// Unique, non-empty name, used by clamps, ties, welds and joints.
    pub name: String,
    /// Extent along x, `[x0, x1]` with `x1 > x0`, mm.
    pub x: [f64; 2],
    /// Extent along z, `[z0, z1]` with `z1 > z0`, mm.
    pub z: [f64; 2],
    /// Height of the mid-surface, mm.
    pub y: f64,
    /// Thickness, mm (> 0).
    pub thickness: f64,
    /// Number of shell elements `[nx, nz]` along x and z (each ≥ 1; the whole mesh may have at
    /// most 10 000 000 nodes).
    pub elements: [usize; 2],
}

/// A clamp: all nodes of the listed sheets on the line `x` have all 6 DOF fixed.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClampSpec {
    /// The clamped node line, mm; must be a node line of every listed sheet.
    pub x: f64,
    /// Names of the clamped sheets (at least one).
    pub sheets: Vec<String>,
}

/// The rigid tie (RBE2, all 6 DOF): the nodes of the listed sheets on the line `x` move with
/// the master node as one rigid body.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RigidTieSpec {
    /// The tied node line, mm; must be a node line of every listed sheet.
    pub x: f64,
    /// Names of the tied sheets (at least one).
    pub sheets: Vec<String>,
    /// Position (x, y, z) of the master node, mm. It belongs to no sheet and carries the load.
    pub master: [f64; 3],
}

/// A spot weld at (x, z) through a stack of sheets `[s0, s1, s2, …]` (see `crate::element::Weld`
/// for the area model and [`WeldModel`] for the choice).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WeldSpec {
    /// Centre along x, mm; inside every listed sheet (a node of each for [`WeldModel::Point`]).
    pub x: f64,
    /// Centre along z, mm.
    pub z: f64,
    /// Names of the welded sheets in strictly increasing y (at least two).
    pub sheets: Vec<String>,
    /// Nugget diameter d, mm (> 0, no larger than a listed sheet's width).
    pub diameter: f64,
    /// How the weld attaches to the sheets; `"area"` when omitted.
    #[serde(default)]
    pub model: WeldModel,
    /// The nugget's neighbourhood (area welds): `"auto"` when omitted, `"off"`, or a shell size
    /// in mm (see [`LocalMesh`]).
    #[serde(default, skip_serializing_if = "LocalMesh::is_auto")]
    pub local_mesh: LocalMesh,
}

/// Whether an area weld's neighbourhood is re-meshed with small shells around the nugget and
/// condensed onto the sheets' own nodes (`crate::element::weld_patch`). JSON: `"auto"`,
/// `"off"` or a number (mm).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum LocalMesh {
    /// The default: re-meshed with shells of d/16 ([`LocalMesh::AUTO_SIZE_PER_DIAMETER`]) where
    /// the sheets' own shells do not resolve the nugget (a side longer than d/2 on a welded
    /// sheet) and the neighbourhood is admissible (no clamp or tie in it, no overlap with
    /// another weld's, within the size limits); otherwise the nugget acts on the sheets' own
    /// shells. Point welds: nothing to re-mesh.
    #[default]
    Auto,
    /// The nugget acts on the sheets' own shells (the RBE3 area weld of `crate::element::weld`).
    Off,
    /// Re-meshed with shells of at most this size, mm (> 0, below the sheets' element size);
    /// an inadmissible neighbourhood is an error.
    Size(f64),
}

impl LocalMesh {
    /// The automatic shell size as a fraction of the nugget diameter: 1/16 (0.3125 mm for a
    /// 5 mm nugget; docs/validation/welds.md).
    pub const AUTO_SIZE_PER_DIAMETER: f64 = 1.0 / 16.0;

    /// A sheet side longer than this fraction of d leaves the nugget unresolved, so `"auto"`
    /// re-meshes it.
    pub const AUTO_UNRESOLVED_PER_DIAMETER: f64 = 0.5;

    /// `true` for [`LocalMesh::Auto`] (omitted when written).
    pub(crate) fn is_auto(&self) -> bool {
        *self == LocalMesh::Auto
    }
}

impl Serialize for LocalMesh {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            LocalMesh::Auto => s.serialize_str("auto"),
            LocalMesh::Off => s.serialize_str("off"),
            LocalMesh::Size(v) => s.serialize_f64(*v),
        }
    }
}

impl<'de> Deserialize<'de> for LocalMesh {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Visitor;
        impl serde::de::Visitor<'_> for Visitor {
            type Value = LocalMesh;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("\"auto\", \"off\" or a shell size in mm")
            }
            fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<LocalMesh, E> {
                Ok(LocalMesh::Size(v))
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<LocalMesh, E> {
                Ok(LocalMesh::Size(v as f64))
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<LocalMesh, E> {
                Ok(LocalMesh::Size(v as f64))
            }
            fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<LocalMesh, E> {
                match v {
                    "auto" => Ok(LocalMesh::Auto),
                    "off" => Ok(LocalMesh::Off),
                    other => Err(E::invalid_value(serde::de::Unexpected::Str(other), &self)),
                }
            }
        }
        d.deserialize_any(Visitor)
    }
}

/// How a spot weld attaches to its sheets.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum WeldModel {
    /// Area weld (the default): the nugget disc of diameter d joins the sheets over its area,
    /// through interpolation constraints on the shells' own shape functions (like NASTRAN's
    /// CWELD ELPAT or an ACM2 weld); the centre may lie anywhere inside the sheets' overlap.
    /// Joint pairs inside the nugget are welded, not in contact, and leave the joint.
    #[default]
    Area,
    /// Point weld (the paper's wording, kept for comparison): a Timoshenko beam of diameter d
    /// between the sheets' nodes at (x, z), which must be a node of every listed sheet; its
    /// footprint on the sheets is set by the mesh, so it does not converge under refinement.
    Point,
}

/// A joint: the interface between two stacked sheets with zero initial clearance,
/// `upper.y − lower.y = (t_lower + t_upper)/2`, where the sheets' nodes pair up node to node.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JointSpec {
    /// Name of the lower sheet (smaller y).
    pub lower: String,
    /// Name of the upper sheet (larger y).
    pub upper: String,
    /// Optional (x, z) locations of the node pairs, mm; each must be a node of both sheets that
    /// is neither clamped nor tied. Without it, every node of the lower sheet that coincides in
    /// (x, z) with a node of the upper sheet forms a pair, except clamped or tied nodes (on
    /// either side).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub points: Option<Vec<[f64; 2]>>,
}

/// Penalty contact and elastic–slip friction of every node pair.
///
/// The penalty stiffnesses are given either **per pair** (`normal_stiffness`, `stick_stiffness`,
/// N/mm: the paper's node-to-node springs, whose interface stiffness grows with the pair count
/// when the mesh is refined) or **per area** (`normal_stiffness_per_area`,
/// `stick_stiffness_per_area`, N/mm³: a pressure per penetration, each pair's spring `κ·A_i`
/// with `A_i` its tributary area on the joint surface, so the interface's stiffness `κ·A_joint`
/// does not depend on the mesh; `crate::mesh::tributary`). Both stiffnesses are given the same
/// way. In a built model ([`crate::Model::contact`]) the per-area law is resolved:
/// `normal_stiffness = κ_n·Ā` and `stick_stiffness = κ_t·Ā` with Ā the mean tributary area of
/// the pairs (the stiffness of a pair of mean area), the per-area values kept beside them.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactSpec {
    /// Normal penalty stiffness of a closed pair, N/mm (> 0). Absent (NaN) in a file that gives
    /// `normal_stiffness_per_area` instead.
    #[serde(default = "absent", skip_serializing_if = "is_absent")]
    pub normal_stiffness: f64,
    /// Coulomb friction coefficient μ, dimensionless (≥ 0).
    pub friction_coefficient: f64,
    /// Tangential (stick) stiffness of a closed pair, N/mm (> 0). Absent (NaN) in a file that
    /// gives `stick_stiffness_per_area` instead.
    #[serde(default = "absent", skip_serializing_if = "is_absent")]
    pub stick_stiffness: f64,
    /// Normal penalty stiffness per unit contact area κ_n, N/mm³ (> 0): each pair's normal
    /// stiffness is κ_n·A_i. An alternative to `normal_stiffness`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub normal_stiffness_per_area: Option<f64>,
    /// Tangential (stick) stiffness per unit contact area κ_t, N/mm³ (> 0): each pair's stick
    /// stiffness is κ_t·A_i. An alternative to `stick_stiffness`, given together with
    /// `normal_stiffness_per_area`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stick_stiffness_per_area: Option<f64>,
    /// Where the contact is sampled with a law per area (absent: at the node pairs): points
    /// inside the joint's faces ([`ContactSampling`]). Only with the stiffnesses per area.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sampling: Option<ContactSampling>,
    /// Where the tangential slips are taken (default `mid_surface`, the paper's node-to-node
    /// kinematics): `faces` adds each sheet's rotation times its half thickness, the slip of
    /// the contacting faces of sheets that bend together ([`SlipSurface`]).
    #[serde(default, skip_serializing_if = "SlipSurface::is_mid_surface")]
    pub slip: SlipSurface,
}

/// Where a joint's tangential slips are measured.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SlipSurface {
    /// At the shells' mid-surface nodes, from their translations (the paper's node-to-node
    /// pairs, NASTRAN's CGAP between grid points).
    #[default]
    MidSurface,
    /// At the contacting faces, half a thickness from each mid-surface: the translations plus
    /// each sheet's rotation times its half thickness (`crate::joint::operator`).
    Faces,
}

impl SlipSurface {
    /// True for the default (kept out of written files).
    pub fn is_mid_surface(&self) -> bool {
        *self == SlipSurface::MidSurface
    }
}

/// Contact points inside the joint's faces (`crate::model::sampling`): each face of the joint
/// surface split into `points_per_edge`² parametric sub-cells, a contact point at each centre
/// with the sub-cell's share of the joint area, its gap interpolated by `gap`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactSampling {
    /// Contact points along each edge of a face, m (1 ≤ m ≤ [`MAX_POINTS_PER_EDGE`]); a face
    /// gets m × m points.
    pub points_per_edge: usize,
    /// How the normal gap varies inside a face (default `hermite`).
    #[serde(default)]
    pub gap: GapInterpolation,
}

/// The largest `points_per_edge` of a contact sampling.
pub const MAX_POINTS_PER_EDGE: usize = 8;

/// The interpolation of the normal gap inside a joint face.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum GapInterpolation {
    /// The shells' own edge deflections (cubic along each edge from the corners' deflections
    /// and rotations: the Hermite cubic for thin shells, DKMQ's edge field in general) blended
    /// over the face.
    #[default]
    Hermite,
    /// Bilinear in the corners' deflections.
    Bilinear,
}

/// A per-pair stiffness the file leaves out (it gives the per-area one).
fn absent() -> f64 {
    f64::NAN
}

fn is_absent(v: &f64) -> bool {
    v.is_nan()
}

impl ContactSpec {
    /// The paper's law with per-pair stiffnesses `k_n`, `k_t` (N/mm) and friction coefficient
    /// `mu`.
    pub fn per_pair(k_n: f64, mu: f64, k_t: f64) -> ContactSpec {
        ContactSpec {
            normal_stiffness: k_n,
            friction_coefficient: mu,
            stick_stiffness: k_t,
            normal_stiffness_per_area: None,
            stick_stiffness_per_area: None,
            sampling: None,
            slip: SlipSurface::MidSurface,
        }
    }

    /// The per-area stiffnesses `[κ_n, κ_t]` (N/mm³) if the law is given per area.
    pub fn per_area(&self) -> Option<[f64; 2]> {
        match (
            self.normal_stiffness_per_area,
            self.stick_stiffness_per_area,
        ) {
            (Some(n), Some(t)) => Some([n, t]),
            _ => None,
        }
    }
}

/// The load on the master node: constant components times a ramp in time.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LoadSpec {
    /// Final values of the master-node load.
    pub master: MasterLoadSpec,
    /// How the load rises from zero to its final values.
    pub ramp: RampSpec,
}

impl LoadSpec {
    /// The master-node load at time `t` (s): `[Fx, Fy, Fz (N), Mx, My, Mz (N·mm)]` times
    /// [`RampSpec::factor`].
    pub fn master_at(&self, t: f64) -> [f64; 6] {
        let f = self.ramp.factor(t);
        self.master.to_array().map(|v| v * f)
    }
}

/// Final master-node load components; a missing key means zero.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MasterLoadSpec {
    /// Force along x, N.
    #[serde(default)]
    pub fx: f64,
    /// Force along y, N.
    #[serde(default)]
    pub fy: f64,
    /// Force along z, N.
    #[serde(default)]
    pub fz: f64,
    /// Moment about x, N·mm.
    #[serde(default)]
    pub mx: f64,
    /// Moment about y, N·mm.
    #[serde(default)]
    pub my: f64,
    /// Moment about z, N·mm.
    #[serde(default)]
    pub mz: f64,
}

impl MasterLoadSpec {
    /// `[fx, fy, fz, mx, my, mz]` (N, N·mm).
    pub fn to_array(&self) -> [f64; 6] {
        [self.fx, self.fy, self.fz, self.mx, self.my, self.mz]
    }
}

/// The load's time function: a half-cosine rise (`{"shape": "half_cosine", "duration": T}`)
/// or a table (`{"shape": "table", "points": [[t0, f0], [t1, f1], ...]}`, NASTRAN's `TABLED1`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RampSpec {
    /// Shape of the time function.
    pub shape: RampShape,
    /// Rise time T of `half_cosine`, s (> 0; required there, not allowed for `table`): the
    /// load is at its final value from `t = T` on.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub duration: Option<f64>,
    /// The `table` shape's points `[t (s), factor]`, at least two, t non-decreasing (a repeated
    /// t is a jump); empty for `half_cosine`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub points: Vec<[f64; 2]>,
}

impl RampSpec {
    /// The half-cosine rise over `duration` s.
    pub fn half_cosine(duration: f64) -> RampSpec {
        RampSpec {
            shape: RampShape::HalfCosine,
            duration: Some(duration),
            points: Vec::new(),
        }
    }

    /// The load factor at time `t` (s). [`RampShape::HalfCosine`]: 0 for `t ≤ 0`, 1 for
    /// `t ≥ T`, `½(1 − cos(π t / T))` in between. [`RampShape::Table`]: linear interpolation
    /// between the points, the mean of the two sides at a jump, and beyond the first or last
    /// point the straight line through the two end points (NASTRAN's `TABLED1` rule).
    pub fn factor(&self, t: f64) -> f64 {
        match self.shape {
            RampShape::HalfCosine => {
                let duration = self.duration.unwrap_or(f64::NAN);
                if t <= 0.0 {
                    0.0
                } else if t >= duration {
                    1.0
                } else {
                    0.5 * (1.0 - (std::f64::consts::PI * t / duration).cos())
                }
            }
            RampShape::Table => table_value(&self.points, t),
        }
    }

    /// Checks the fields of the shape (`path` is the JSON path of the ramp, for messages):
    /// `Err((field path, reason))`.
    pub fn check(&self, path: &str) -> Result<(), (String, String)> {
        match self.shape {
            RampShape::HalfCosine => {
                if !self.points.is_empty() {
                    return Err((
                        format!("{path}.points"),
                        "only the `table` shape has points".into(),
                    ));
                }
                match self.duration {
                    Some(d) if d.is_finite() && d > 0.0 => Ok(()),
                    Some(d) => Err((
                        format!("{path}.duration"),
                        format!("must be positive (finite and > 0), got {d} s"),
                    )),
                    None => Err((
                        format!("{path}.duration"),
                        "missing field `duration` (the half-cosine rise time, s)".into(),
                    )),
                }
            }
            RampShape::Table => {
                if self.duration.is_some() {
                    return Err((
                        format!("{path}.duration"),
                        "a `table` has no duration: its points give the time function".into(),
                    ));
                }
                if self.points.len() < 2 {
                    return Err((
                        format!("{path}.points"),
                        format!(
                            "a table needs at least two points, got {}",
                            self.points.len()
                        ),
                    ));
                }
                for (i, p) in self.points.iter().enumerate() {
                    if !(p[0].is_finite() && p[1].is_finite()) {
                        return Err((
                            format!("{path}.points[{i}]"),
                            format!("must be finite, got [{}, {}]", p[0], p[1]),
                        ));
                    }
                    if i > 0 && p[0] < self.points[i - 1][0] {
                        return Err((
                            format!("{path}.points[{i}]"),
                            format!(
                                "times must not decrease: {} s after {} s",
                                p[0],
                                self.points[i - 1][0]
                            ),
                        ));
                    }
                    if i > 1 && p[0] == self.points[i - 1][0] && p[0] == self.points[i - 2][0] {
                        return Err((
                            format!("{path}.points[{i}]"),
                            format!("three points at t = {} s (a jump has two)", p[0]),
                        ));
                    }
                }
                let (first, last) = (self.points[0], self.points[self.points.len() - 1]);
                if first[0] == self.points[1][0] || last[0] == self.points[self.points.len() - 2][0]
                {
                    return Err((
                        format!("{path}.points"),
                        "the first two and the last two points need distinct times (the \
                         straight line beyond the ends runs through them)"
                            .into(),
                    ));
                }
                Ok(())
            }
        }
    }
}

/// Linear interpolation in a checked table (see [`RampSpec::factor`]); no allocation.
fn table_value(points: &[[f64; 2]], t: f64) -> f64 {
    let n = points.len();
    if n < 2 {
        return f64::NAN;
    }
    let line = |a: [f64; 2], b: [f64; 2]| a[1] + (b[1] - a[1]) * (t - a[0]) / (b[0] - a[0]);
    if t <= points[0][0] {
        return line(points[0], points[1]);
    }
    if t >= points[n - 1][0] {
        return line(points[n - 2], points[n - 1]);
    }
    // The first point with time > t; 1 ≤ k ≤ n - 1.
    let k = points.partition_point(|p| p[0] <= t);
    let (a, b) = (points[k - 1], points[k]);
    if a[0] == t && k >= 2 && points[k - 2][0] == t {
        // At a jump: the mean of the two sides.
        return 0.5 * (points[k - 2][1] + a[1]);
    }
    line(a, b)
}

/// Ramp shapes, spelled in snake case in the file (`"half_cosine"`, `"table"`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RampShape {
    /// `F(t) = F·½(1 − cos(π t / T))` for `t < T`, then `F`: smooth start, zero rate at `T`.
    HalfCosine,
    /// `F(t) = F·f(t)` with `f` interpolated in [`RampSpec::points`].
    Table,
}

impl Case {
    /// Names of the built-in cases (files `cases/<name>.json` compiled into the crate).
    pub const BUILTIN: &'static [&'static str] = &["friction_bar", "multilayer_sheet"];

    /// Parses a case from JSON text (unknown fields rejected) and validates the material and
    /// every sheet's own fields; what needs the node grids (clamps, ties, welds, joints) and the
    /// contact law, load and end time are validated, in the file's order, when the mesh is
    /// generated ([`crate::mesh::Mesh::from_case`]), which every command does. `file` labels the text in
    /// errors and becomes [`Case::source`].
    pub fn from_json_str(text: &str, file: &str) -> Result<Case, Error> {
        let mut case = parse::parse(text, file)?;
        case.source = file.to_string();
        let ctx = validate::Ctx { file };
        validate::check_material(&case, &ctx)?;
        validate::check_sheets(&case, &ctx)?;
        Ok(case)
    }

    /// Reads, parses and validates a case file; [`Error::Io`] if it cannot be read.
    pub fn from_file(path: &Path) -> Result<Case, Error> {
        let text = crate::files::read_text(path)?;
        Case::from_json_str(&text, &path.display().to_string())
    }

    /// The built-in case `name` (one of [`Case::BUILTIN`]), or `None` for an unknown name. Its
    /// errors, if any, name the file `builtin:<name>`.
    pub fn builtin(name: &str) -> Option<Result<Case, Error>> {
        let text = match name {
            "friction_bar" => include_str!("../../cases/friction_bar.json"),
            "multilayer_sheet" => include_str!("../../cases/multilayer_sheet.json"),
            _ => return None,
        };
        Some(Case::from_json_str(text, &format!("builtin:{name}")))
    }

    /// Loads `arg` as a file if such a path exists, else as a built-in name. Anything else is an
    /// [`Error::Io`] (not found) whose message lists the built-in cases.
    pub fn load(arg: &str) -> Result<Case, Error> {
        let path = Path::new(arg);
        // Anything at that path (even a dangling or looping link), or a path the OS refuses for
        // another reason than "not found" (a name too long, a parent that is a file), is read as
        // a file, so the error says what is wrong with it.
        let not_found = matches!(
            std::fs::symlink_metadata(path),
            Err(ref e) if e.kind() == std::io::ErrorKind::NotFound
        );
        if !not_found {
            return Case::from_file(path);
        }
        if let Some(case) = Case::builtin(arg) {
            return case;
        }
        Err(Error::Io {
            file: path.to_path_buf(),
            source: std::io::Error::new(
                std::io::ErrorKind::NotFound,
                format!(
                    "no such file, and not a built-in case (built-in cases: {})",
                    Case::BUILTIN.join(", ")
                ),
            ),
        })
    }

    /// The final master-node load `[Fx, Fy, Fz (N), Mx, My, Mz (N·mm)]`, before the ramp.
    pub fn master_load(&self) -> [f64; 6] {
        self.load.master.to_array()
    }
}
