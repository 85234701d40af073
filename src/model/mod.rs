//! The full finite-element model: K and M on the independent DOF, the joint operator B, the
//! master node, the load and the contact law — from a case (mesh generated and assembled here)
//! or from a user's own matrices ([`crate::model::matrices`]: MatrixMarket K, M plus a JSON map).
//!
//! Everything downstream (bases, statics, transient runs, reports) sees only this type, so one
//! pipeline serves both origins. Conventions every model satisfies (checked where it is built):
//!
//! - the master (Craig–Bampton boundary) DOF are the **last six** independent DOF, in the order
//!   `[ux, uy, uz, rx, ry, rz]` of one master node, which carries the load (eq. 1's `f(t)`);
//! - each joint pair has three rows in B (eq. 2): `n · (u_upper − u_lower)` (normal gap, contact
//!   when negative, zero initial clearance), `t1 · (…)` and `t2 · (…)` (slips), with `n, t1, t2`
//!   orthonormal;
//! - K is symmetric positive definite (the structure is supported), M symmetric positive
//!   definite, both stored on one sparsity pattern.

mod contact;
mod load;
pub mod matrices;
pub mod mtx;
pub mod per_area;
pub mod petsc;
pub mod sampling;

pub use contact::contact_static_full;
pub use load::LoadOptions;

use std::path::PathBuf;

use crate::assembly::{assemble_structure, DofMap, Structure};
use crate::case::{Case, ContactSpec, LoadSpec};
use crate::error::{Error, ModelError};
use crate::joint::{JointOperator, PairFrame};
use crate::linalg::cholesky as statics;
use crate::linalg::eigen::{self as modes, Modes};
use crate::linalg::SymCsc;
use crate::mesh::Mesh;

/// The model data besides the mesh, for [`Model::assemble`].
struct Parts {
    name: String,
    source: String,
    load: LoadSpec,
    contact: ContactSpec,
    end_time: f64,
    warnings: Vec<String>,
}

/// Which boundary the master node has in an eigenproblem (the CLI's `--interface` values).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Interface {
    /// Master node free: the cantilever's own modes.
    #[value(name = "free")]
    Free,
    /// Master node clamped: Craig–Bampton fixed-interface normal modes.
    #[value(name = "fixed")]
    Fixed,
}

/// What a cell of the display geometry is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CellNodes {
    /// A 4-node shell (VTK quad).
    Quad4([usize; 4]),
    /// A 2-node beam (VTK line).
    Line2([usize; 2]),
}

impl CellNodes {
    /// The node indices, in cell order.
    pub fn as_slice(&self) -> &[usize] {
        match self {
            CellNodes::Quad4(n) => n,
            CellNodes::Line2(n) => n,
        }
    }
}

/// A cell of the display geometry (VTU output, pictures; not used by the mechanics).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cell {
    /// Node indices into [`Geometry::nodes`].
    pub nodes: CellNodes,
    /// Group (sheet index of a generated case; the map's `group`; −1 for none).
    pub group: i32,
    /// Shell thickness or beam diameter, mm (0 where unknown).
    pub size: f64,
}

/// Node positions, node ids and cells: what output needs to show a displacement field.
#[derive(Clone, Debug, PartialEq)]
pub struct Geometry {
    /// Node coordinates (x, y, z), mm.
    pub nodes: Vec<[f64; 3]>,
    /// The user's node ids (1-based node numbers for a generated case).
    pub node_ids: Vec<u64>,
    /// Cells for display.
    pub cells: Vec<Cell>,
    /// Nodes tied rigidly to the master node (RBE2): no DOF of their own.
    pub followers: Vec<usize>,
}

/// Where a model came from.
#[derive(Clone, Debug)]
pub enum Origin {
    /// Generated and assembled from a case.
    Case {
        /// The validated case.
        case: Box<Case>,
        /// Its discretisation.
        mesh: Box<Mesh>,
    },
    /// Read from a NASTRAN deck ([`crate::case::nastran`]).
    Deck {
        /// The deck file.
        deck: PathBuf,
        /// Its discretisation.
        mesh: Box<Mesh>,
    },
    /// Read from a user's MatrixMarket K and M plus a JSON map ([`crate::model::matrices`]).
    Matrices {
        /// The map file.
        map: PathBuf,
        /// The stiffness file.
        stiffness: PathBuf,
        /// The mass file.
        mass: PathBuf,
    },
}

/// A static solution.
#[derive(Clone, Debug, PartialEq)]
pub struct StaticSolution {
    /// All independent DOF, mm and rad.
    pub displacement: Vec<f64>,
    /// The master node `[ux, uy, uz (mm), rx, ry, rz (rad)]`.
    pub master_displacement: [f64; 6],
}

/// The full FE model (see the module docs for its conventions).
#[derive(Clone, Debug)]
pub struct Model {
    /// Name (used in reports and output folders).
    pub name: String,
    /// Where it came from, for errors: a file path or `builtin:<name>`.
    pub source: String,
    /// Case and mesh, or the matrix files.
    pub origin: Origin,
    /// Nodes and cells for output.
    pub geometry: Geometry,
    /// The joint pairs with their frames, in the row order of [`Model::joint`].
    pub pairs: Vec<PairFrame>,
    /// Node DOF → independent DOF.
    pub dof_map: DofMap,
    /// Stiffness on the independent DOF, N/mm (N, N·mm/rad for rotations).
    pub stiffness: SymCsc,
    /// Mass on the independent DOF, t (t·mm² for rotations).
    pub mass: SymCsc,
    /// The joint operator B (3 rows per pair: normal, t1, t2).
    pub joint: JointOperator,
    /// The master-node load and its ramp.
    pub load: LoadSpec,
    /// Contact and friction law of all pairs.
    pub contact: ContactSpec,
    /// End of the simulated time span, s.
    pub end_time: f64,
    /// What the reader noticed but did not refuse (a deck's ignored and unknown cards, unused
    /// grids, pairs fused by welds); empty for cases and matrices.
    pub warnings: Vec<String>,
    /// Tributary area `A_i` of each pair on the joint surface, mm² (`crate::mesh::tributary`;
    /// a matrix map's per-pair `area`): `None` where the model has none (a map without areas,
    /// pairs that do not cover faces). With them the mesh-independent contact outputs (contact
    /// area, pressure) are reported.
    pub pair_areas: Option<Vec<f64>>,
    /// The pair weights `w_i = √(A_i/Ā)` of a per-area contact law (`None`: the per-pair law,
    /// all weights 1). [`Model::joint`]'s three rows of pair i carry `w_i`, so the scalar law
    /// `k = κ·Ā` on the weighted kinematics `w_i·(g, u_t)` returns the force `w_i² κ Ā g =
    /// κ A_i g` to the structure (module [`per_area`]).
    pub pair_weights: Option<Vec<f64>>,
    /// Where each pair sits, mm, for contact points inside the joint's faces
    /// ([`sampling`]; their [`Model::pairs`] name the nearest node pair). `None`: the pairs are
    /// node pairs, at their lower nodes.
    pub point_positions: Option<Vec<[f64; 3]>>,
}

impl Model {
    /// Where the model's matrices came from, for error messages: the case file (or
    /// `builtin:<name>`), or the map with its stiffness and mass files.
    pub fn describe_source(&self) -> String {
        match &self.origin {
            Origin::Case { .. } | Origin::Deck { .. } => self.source.clone(),
            Origin::Matrices {
                map,
                stiffness,
                mass,
            } => format!(
                "{} (stiffness {}, mass {})",
                map.display(),
                stiffness.display(),
                mass.display()
            ),
        }
    }

    /// Builds the mesh and assembles K and M.
    pub fn from_case(case: Case) -> Result<Model, Error> {
        let mesh = Mesh::from_case(&case)?;
        let (normal, t1, t2) = PairFrame::SHEET_AXES;
        let half = node_half_thickness(&mesh, case.contact.slip);
        let pairs: Vec<PairFrame> = mesh
            .pairs
            .iter()
            .map(|p| PairFrame {
                lower: p.lower,
                upper: p.upper,
                normal,
                t1,
                t2,
                face_offsets: [half[p.lower], half[p.upper]],
            })
            .collect();
        let node_ids = (1..=mesh.nodes.len() as u64).collect();
        let (per_area, overlap) = (case.contact.per_area(), per_area::joints_overlap(&case));
        let sampling = case.contact.sampling;
        let parts = Parts {
            name: case.name.clone(),
            source: case.source.clone(),
            load: case.load.clone(),
            contact: case.contact,
            end_time: case.end_time,
            warnings: mesh.warnings.clone(),
        };
        let mut model = Model::assemble(mesh, pairs, node_ids, parts, |mesh| Origin::Case {
            case: Box::new(case),
            mesh: Box::new(mesh),
        })?;
        model.set_mesh_areas();
        if let Some(kappa) = per_area {
            model.apply_case_per_area(kappa, overlap)?;
            if let Some(s) = sampling {
                model.apply_contact_sampling(
                    kappa,
                    sampling::SamplingPoints::SubCells(s.points_per_edge),
                    s.gap,
                    "contact.sampling",
                )?;
            }
        }
        Ok(model)
    }

    /// Reads a NASTRAN deck ([`crate::case::nastran`]), builds its mesh and assembles K and M.
    /// Pair frames follow each CGAP's GA → GB direction ([`PairFrame::along`]).
    pub fn from_deck(path: &std::path::Path) -> Result<Model, Error> {
        Model::from_deck_with(path, crate::case::LocalMesh::Auto)
    }

    /// [`Model::from_deck`] with the rule `local_mesh` for the area welds' neighbourhoods
    /// (`auto`: a case file's default; `off`: the nugget on the deck's own shells).
    pub fn from_deck_with(
        path: &std::path::Path,
        local_mesh: crate::case::LocalMesh,
    ) -> Result<Model, Error> {
        let deck = crate::case::nastran::deck::read(path)?;
        let built = Mesh::from_deck(&deck, local_mesh)?;
        let mesh = built.mesh;
        // Each CQUAD4's element first, so that a degenerate or warped one is named by its line.
        for (shell, (file, line, id)) in mesh.shells.iter().zip(&built.shell_sources) {
            let corners = shell.nodes.map(|n| mesh.nodes[n]);
            crate::element::Shell4::new(corners, shell.thickness, mesh.material).map_err(|e| {
                Error::Deck {
                    file: file.clone(),
                    line: *line,
                    card: format!("CQUAD4 {id}"),
                    reason: e.to_string(),
                }
            })?;
        }
        let pairs = mesh
            .pairs
            .iter()
            .map(|p| {
                let (a, b) = (mesh.nodes[p.lower], mesh.nodes[p.upper]);
                PairFrame::along(p.lower, p.upper, [b[0] - a[0], b[1] - a[1], b[2] - a[2]])
                    .ok_or_else(|| {
                        Error::Model(ModelError::DegenerateGap {
                            file: path.to_path_buf(),
                        })
                    })
            })
            .collect::<Result<Vec<_>, _>>()?;
        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "deck".into());
        let parts = Parts {
            name,
            source: path.display().to_string(),
            load: built.load,
            contact: built.contact,
            end_time: built.end_time,
            warnings: built.warnings,
        };
        let deck_path = path.to_path_buf();
        let mut model = Model::assemble(mesh, pairs, built.grid_ids, parts, |mesh| Origin::Deck {
            deck: deck_path,
            mesh: Box::new(mesh),
        })?;
        model.set_mesh_areas();
        Ok(model)
    }

    /// Assembles a mesh into a model.
    fn assemble(
        mesh: Mesh,
        pairs: Vec<PairFrame>,
        node_ids: Vec<u64>,
        parts: Parts,
        origin: impl FnOnce(Mesh) -> Origin,
    ) -> Result<Model, Error> {
        let Structure {
            dof_map,
            stiffness,
            mass,
        } = assemble_structure(&mesh)?;
        let joint = JointOperator::new(&pairs, &dof_map)?;
        let mut cells: Vec<Cell> = mesh
            .shells
            .iter()
            .map(|e| Cell {
                nodes: CellNodes::Quad4(e.nodes),
                group: e.sheet as i32,
                size: e.thickness,
            })
            .collect();
        cells.extend(mesh.beams.iter().map(|b| Cell {
            nodes: CellNodes::Line2(b.nodes),
            group: -1,
            size: b.diameter,
        }));
        let geometry = Geometry {
            nodes: mesh.nodes.clone(),
            node_ids,
            cells,
            followers: mesh.tie.slaves.clone(),
        };
        Ok(Model {
            name: parts.name,
            source: parts.source,
            load: parts.load,
            contact: parts.contact,
            end_time: parts.end_time,
            warnings: parts.warnings,
            pair_areas: None,
            pair_weights: None,
            point_positions: None,
            origin: origin(mesh),
            geometry,
            pairs,
            dof_map,
            stiffness,
            mass,
            joint,
        })
    }

    /// Where pair `i` sits, mm: its contact point, or its lower node.
    pub fn pair_position(&self, i: usize) -> [f64; 3] {
        self.point_positions
            .as_ref()
            .map_or(self.geometry.nodes[self.pairs[i].lower], |p| p[i])
    }

    /// The case, for a model generated from one.
    pub fn case(&self) -> Option<&Case> {
        match &self.origin {
            Origin::Case { case, .. } => Some(case),
            Origin::Deck { .. } | Origin::Matrices { .. } => None,
        }
    }

    /// The mesh, for a model generated from a case or read from a deck.
    pub fn mesh(&self) -> Option<&Mesh> {
        match &self.origin {
            Origin::Case { mesh, .. } | Origin::Deck { mesh, .. } => Some(mesh),
            Origin::Matrices { .. } => None,
        }
    }

    /// The final master load `[Fx, Fy, Fz (N), Mx, My, Mz (N·mm)]`, before the ramp.
    pub fn master_load(&self) -> [f64; 6] {
        self.load.master.to_array()
    }

    /// Number of independent DOF (after eliminating clamp and rigid tie).
    pub fn dofs(&self) -> usize {
        self.dof_map.n
    }

    /// Number of joint pairs.
    pub fn pair_count(&self) -> usize {
        self.pairs.len()
    }

    /// Number of distinct independent DOF on nodes of joint pairs.
    pub fn joint_dofs(&self) -> usize {
        let mut nodes: Vec<usize> = self.pairs.iter().flat_map(|p| [p.lower, p.upper]).collect();
        nodes.sort_unstable();
        nodes.dedup();
        nodes
            .iter()
            .filter_map(|&n| self.dof_map.free_dofs(n))
            .count()
            * 6
    }

    /// The master node's independent DOF `[ux, uy, uz, rx, ry, rz]`.
    pub fn master_dofs(&self) -> [usize; 6] {
        self.dof_map.master
    }

    /// The independent DOF that are a node's own translation `x, y, z` (mm), the master's
    /// included, ascending: not the rotations (rad), not the rigid followers' dependent DOF.
    pub fn translation_dofs(&self) -> Vec<usize> {
        let mut out: Vec<usize> = self
            .dof_map
            .nodes
            .iter()
            .flat_map(|node| node[..3].iter().filter_map(|d| d.as_free()))
            .collect();
        out.sort_unstable();
        out.dedup();
        out
    }

    /// The lowest `count` eigenmodes with the master node free or clamped.
    pub fn modes(&self, count: usize, interface: Interface) -> Result<Modes, Error> {
        match interface {
            Interface::Free => Ok(modes::lowest_modes(&self.stiffness, &self.mass, count)?),
            Interface::Fixed => {
                let m = self.dofs() - 6;
                Ok(modes::lowest_modes(
                    &self.stiffness.leading(m),
                    &self.mass.leading(m),
                    count,
                )?)
            }
        }
    }

    /// Linear static response (no contact) to master loads `[Fx, Fy, Fz, Mx, My, Mz]`
    /// (N, N·mm), each column of `loads` one load case.
    pub fn static_linear(&self, loads: &[[f64; 6]]) -> Result<Vec<StaticSolution>, Error> {
        let master = self.master_dofs();
        let rhs: Vec<Vec<f64>> = loads
            .iter()
            .map(|l| {
                let mut f = vec![0.0; self.dofs()];
                for k in 0..6 {
                    f[master[k]] = l[k];
                }
                f
            })
            .collect();
        let sols = statics::solve_spd(&self.stiffness, &rhs)?;
        Ok(sols
            .into_iter()
            .map(|q| StaticSolution {
                master_displacement: master.map(|k| q[k]),
                displacement: q,
            })
            .collect())
    }
}

/// Per node, the distance (mm) from its mid-surface to its contacting face: half the largest
/// thickness of the shells at the node where the slips are taken at the faces, else 0.
fn node_half_thickness(mesh: &Mesh, slip: crate::case::SlipSurface) -> Vec<f64> {
    let mut half = vec![0.0; mesh.nodes.len()];
    if slip == crate::case::SlipSurface::Faces {
        for s in &mesh.shells {
            for &n in &s.nodes {
                half[n] = f64::max(half[n], 0.5 * s.thickness);
            }
        }
    }
    half
}
