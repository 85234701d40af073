//! The discretised structure: nodes, `Shell4` sheets, spot welds (area nuggets sampled on the
//! sheets, or point-weld `Beam2`s), clamps, the rigid tie to the master node, and the joint node
//! pairs. Built from a [`crate::case::Case`] by
//! [`Mesh::from_case`], which validates the case while it generates the mesh (`build`).
//!
//! Axes: x along the length, y normal to the sheets, z across the width (mm).

use crate::case::Case;
use crate::error::{ElementError, Error};

mod build;
pub mod deck;
mod deck_patch;
mod nugget;
pub mod tributary;

pub use deck::DeckModel;

/// A 4-node shell on a sheet's mid-surface. Nodes run counter-clockwise in the (x, z) plane:
/// `(i, k), (i+1, k), (i+1, k+1), (i, k+1)` of the sheet's grid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShellElem {
    /// Node indices into [`Mesh::nodes`].
    pub nodes: [usize; 4],
    /// Shell thickness, mm.
    pub thickness: f64,
    /// Index of the sheet (into [`Mesh::sheets`]).
    pub sheet: usize,
}

/// A 2-node weld beam with a circular section.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BeamElem {
    /// Node indices into [`Mesh::nodes`] (lower sheet first).
    pub nodes: [usize; 2],
    /// Section diameter, mm.
    pub diameter: f64,
}

/// An area spot weld (see `crate::element::Weld`): the nugget disc, clipped to the welded
/// sheets, sampled on each sheet of the stack.
#[derive(Clone, Debug, PartialEq)]
pub struct WeldElem {
    /// Index of the weld in the case file (`welds[i]`).
    pub index: usize,
    /// Centre (x, z), mm.
    pub centre: [f64; 2],
    /// Nugget diameter d, mm.
    pub diameter: f64,
    /// The welded sheets, lower to upper (strictly increasing y).
    pub layers: Vec<NuggetLayer>,
    /// The re-meshed neighbourhood of the nugget (a weld's `local_mesh`), if any.
    pub patch: Option<WeldPatch>,
    /// Without a neighbourhood: how the nugget acts on the sheets' own shells.
    pub own_shells: OwnShellNugget,
}

/// How an area weld without a re-meshed neighbourhood acts on the sheets' own shells
/// (`crate::element::Weld`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum OwnShellNugget {
    /// RBE3 interpolation on each sheet and a connector beam between the reference points:
    /// `"local_mesh": "off"`, and shells too coarse for the nugget whose neighbourhood cannot be
    /// re-meshed (where the bonded slab would lock).
    #[default]
    Rbe3,
    /// The sheets bonded over the disc (the slab of the re-meshed neighbourhood, on the sheets'
    /// own shells): `"auto"` where every welded sheet's shells resolve the nugget.
    BondedSlab,
}

/// The cell `[j, j + 1]` of the ascending node `lines` (at least two) containing `v` — the
/// first or last cell for a value outside — and the position `t ∈ [0, 1]` of `v` in it.
pub(crate) fn line_cell(lines: &[f64], v: f64) -> (usize, f64) {
    let j = lines.partition_point(|&l| l <= v).clamp(1, lines.len() - 1) - 1;
    let t = ((v - lines[j]) / (lines[j + 1] - lines[j])).clamp(0.0, 1.0);
    (j, t)
}

/// The neighbourhood of an area weld's nugget re-meshed with small shells and condensed onto
/// the sheets' own nodes (`crate::element::weld_patch`): the sheets' shells it replaces are
/// left out of the assembly.
#[derive(Clone, Debug, PartialEq)]
pub struct WeldPatch {
    /// Size of the small shells, mm.
    pub size: f64,
    /// Per welded sheet, lower to upper (as [`WeldElem::layers`]).
    pub layers: Vec<PatchLayer>,
    /// Indices into [`Mesh::shells`] of the shells the patch replaces.
    pub replaced: Vec<usize>,
    /// The nugget sampled on the small shells, per layer; its node indices number the small
    /// shells' nodes layer by layer, `(layer, I, K)` → `Σ_{l < layer} (its node count) + I ·
    /// fine_zs.len() + K`.
    pub nugget: Vec<NuggetLayer>,
    /// Chosen by `"local_mesh": "auto"`: left out (the nugget then acts on the sheets' own
    /// shells) where it would reach a clamp or tie or overlap another weld's, instead of an
    /// error.
    pub automatic: bool,
}

/// The replaced rectangle of shells on one welded sheet.
#[derive(Clone, Debug, PartialEq)]
pub struct PatchLayer {
    /// Index of the sheet (into [`Mesh::sheets`]).
    pub sheet: usize,
    /// Height of the sheet's mid-surface, mm.
    pub y: f64,
    /// Sheet thickness, mm.
    pub thickness: f64,
    /// The sheet's node lines bounding and crossing the rectangle, along x and z (mm, ascending).
    pub xs: Vec<f64>,
    /// As `xs`, along z.
    pub zs: Vec<f64>,
    /// The sheet's node at `(xs[i], zs[k])`: `nodes[i * zs.len() + k]`.
    pub nodes: Vec<usize>,
    /// The small shells' node lines along x and z (mm, ascending; every line of `xs`, `zs` is
    /// one of them).
    pub fine_xs: Vec<f64>,
    /// As `fine_xs`, along z.
    pub fine_zs: Vec<f64>,
    /// Whether each side of the rectangle (x low, x high, z low, z high) is the sheet's free
    /// edge (no shell beyond it).
    pub free_side: [bool; 4],
}

/// The nugget on one welded sheet: its sampling points on the sheet's mid-surface.
#[derive(Clone, Debug, PartialEq)]
pub struct NuggetLayer {
    /// Index of the sheet (into [`Mesh::sheets`]).
    pub sheet: usize,
    /// Height of the sheet's mid-surface, mm.
    pub y: f64,
    /// Sampling points of the (clipped) nugget disc, with their area weights.
    pub points: Vec<NuggetPoint>,
}

/// A point of a nugget disc and how the sheet's displacement there is interpolated.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NuggetPoint {
    /// Position (x, z), mm.
    pub xz: [f64; 2],
    /// Area weight, mm² (the weights of a layer sum to the clipped disc's area).
    pub weight: f64,
    /// The nodes of the shell containing the point, in [`ShellElem`] order.
    pub nodes: [usize; 4],
    /// The bilinear shape functions of those nodes at the point (they sum to 1).
    pub shape: [f64; 4],
}

/// A point mass with rotary inertia at a node (NASTRAN CONM2, no offset).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointMass {
    /// Node index into [`Mesh::nodes`].
    pub node: usize,
    /// Mass, t.
    pub mass: f64,
    /// Inertia `[I11, I21, I22, I31, I32, I33]` about the node, t·mm²: the rotational block of
    /// the mass matrix is `[[I11, −I21, −I31], [−I21, I22, −I32], [−I31, −I32, I33]]`.
    pub inertia: [f64; 6],
}

impl PointMass {
    /// The 6 × 6 mass matrix on the node's `[ux, uy, uz, rx, ry, rz]`.
    pub fn matrix(&self) -> [[f64; 6]; 6] {
        let [i11, i21, i22, i31, i32, i33] = self.inertia;
        let mut m = [[0.0; 6]; 6];
        for (k, row) in m.iter_mut().enumerate().take(3) {
            row[k] = self.mass;
        }
        let rot = [[i11, -i21, -i31], [-i21, i22, -i32], [-i31, -i32, i33]];
        for a in 0..3 {
            for b in 0..3 {
                m[3 + a][3 + b] = rot[a][b];
            }
        }
        m
    }
}

/// Rigid-body tie (NASTRAN RBE2, all 6 DOF): every slave node moves as
/// `u_s = u_m + θ_m × (x_s − x_m)`, `θ_s = θ_m`.
#[derive(Clone, Debug, PartialEq)]
pub struct RigidTie {
    /// The master node (index into [`Mesh::nodes`]); it belongs to no sheet.
    pub master: usize,
    /// The tied nodes, in increasing order.
    pub slaves: Vec<usize>,
}

/// A node-to-node joint pair: the gap is `g = u_y(upper) − u_y(lower)`, zero initial clearance.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct JointPair {
    /// Node on the lower sheet (smaller y).
    pub lower: usize,
    /// Node on the upper sheet (larger y), coincident in (x, z).
    pub upper: usize,
}

/// Summary of one sheet's node grid: node `(i, k)` (i along x, k along z) has index
/// `first_node + i * (elements[1] + 1) + k`.
#[derive(Clone, Debug, PartialEq)]
pub struct SheetGrid {
    /// Name from the case file.
    pub name: String,
    /// Index of the sheet's first node.
    pub first_node: usize,
    /// Elements along x and along z.
    pub elements: [usize; 2],
}

/// The whole discretised structure.
#[derive(Clone, Debug, PartialEq)]
pub struct Mesh {
    /// Node coordinates (x, y, z), mm. Sheet nodes first (sheet by sheet), the master node last.
    pub nodes: Vec<[f64; 3]>,
    /// The sheets' node grids, in case-file order (empty for a deck: its sheets are
    /// unstructured).
    pub sheets: Vec<SheetGrid>,
    /// Shell elements.
    pub shells: Vec<ShellElem>,
    /// Beams of point welds (`"model": "point"`).
    pub beams: Vec<BeamElem>,
    /// Area welds (`"model": "area"`, the default).
    pub welds: Vec<WeldElem>,
    /// Point masses (a deck's CONM2; none in a case).
    pub masses: Vec<PointMass>,
    /// Nodes with all 6 DOF clamped, in increasing order.
    pub clamped: Vec<usize>,
    /// The rigid tie to the master node.
    pub tie: RigidTie,
    /// Joint pairs, interface by interface in case-file order, within an interface sorted by
    /// (x, z).
    pub pairs: Vec<JointPair>,
    /// Coincident node pairs of the joints left out of [`Mesh::pairs`]: fused by an area weld's
    /// nugget, clamped or tied (a deck's: the CGAPs inside a nugget). Their share of the joint
    /// surface is carried by the weld or the support, not by contact.
    pub excluded: Vec<JointPair>,
    /// Material of all sheets and welds.
    pub material: Material,
    /// What the build could not do as asked and did otherwise (a weld whose automatic
    /// re-meshed neighbourhood could not be built), one sentence each.
    pub warnings: Vec<String>,
}

/// Linear elastic isotropic material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    /// Young's modulus E, N/mm².
    pub youngs_modulus: f64,
    /// Poisson's ratio ν, dimensionless.
    pub poisson_ratio: f64,
    /// Mass density ρ, t/mm³.
    pub density: f64,
}

impl Material {
    /// Structural steel as used in the paper: E = 210000 N/mm², ν = 0.3, ρ = 7.85e-9 t/mm³.
    pub const STEEL: Material = Material {
        youngs_modulus: 210_000.0,
        poisson_ratio: 0.3,
        density: 7.85e-9,
    };

    /// Shear modulus G = E / (2 (1 + ν)), N/mm².
    pub fn shear_modulus(&self) -> f64 {
        self.youngs_modulus / (2.0 * (1.0 + self.poisson_ratio))
    }

    /// Checks E > 0, -1 < ν < 0.5, ρ > 0.
    pub fn validate(&self) -> Result<(), Error> {
        let ok = self.youngs_modulus.is_finite()
            && self.youngs_modulus > 0.0
            && self.poisson_ratio > -1.0
            && self.poisson_ratio < 0.5
            && self.density.is_finite()
            && self.density > 0.0;
        if ok {
            Ok(())
        } else {
            Err(ElementError::Material {
                youngs_modulus: self.youngs_modulus,
                poisson_ratio: self.poisson_ratio,
                density: self.density,
            }
            .into())
        }
    }
}

impl Mesh {
    /// Validates a case and generates its mesh (see the numbering in [`crate::case`]). Errors are
    /// the checks listed in [`crate::case`] (those of [`Case::from_json_str`] and those that need
    /// the node grids), labelled with [`Case::source`].
    pub fn from_case(case: &Case) -> Result<Mesh, Error> {
        build::build(case)
    }

    /// Builds the mesh of a NASTRAN deck with its load, contact law and end time (see
    /// [`deck`]).
    pub fn from_deck(
        deck: &crate::case::nastran::Deck,
        local_mesh: crate::case::LocalMesh,
    ) -> Result<DeckModel, Error> {
        deck::build(deck, local_mesh)
    }
}
