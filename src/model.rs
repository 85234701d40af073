//! The full finite-element model of a case: mesh, DOF map, assembled K and M, joint pairs.

use crate::assembly::{assemble_structure, DofMap, Structure, SymCsc};
use crate::case::Case;
use crate::error::Error;
use crate::joint::JointOperator;
use crate::mesh::Mesh;
use crate::modes::{self, Modes};
use crate::statics::{self, StaticSolution};

/// Which boundary the master node has in an eigenproblem.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Interface {
    /// Master node free: the cantilever's own modes.
    Free,
    /// Master node clamped: Craig–Bampton fixed-interface normal modes.
    Fixed,
}

/// The assembled full FE model of a case.
#[derive(Clone, Debug)]
pub struct Model {
    /// The validated case.
    pub case: Case,
    /// The discretisation.
    pub mesh: Mesh,
    /// Node DOF → independent DOF.
    pub dof_map: DofMap,
    /// Stiffness on the independent DOF, N/mm (N, N·mm/rad for rotations).
    pub stiffness: SymCsc,
    /// Mass on the independent DOF, t (t·mm² for rotations).
    pub mass: SymCsc,
    /// The joint operator B (3 rows per pair: normal gap, slip x, slip z).
    pub joint: JointOperator,
}

impl Model {
    /// Loads a case (path or built-in name) and assembles it.
    pub fn from_case_name(arg: &str) -> Result<Model, Error> {
        Model::from_case(Case::load(arg)?)
    }

    /// Builds the mesh and assembles K and M.
    pub fn from_case(case: Case) -> Result<Model, Error> {
        let mesh = case.build_mesh()?;
        let Structure {
            dof_map,
            stiffness,
            mass,
        } = assemble_structure(&mesh)?;
        let joint = JointOperator::new(&mesh, &dof_map)?;
        Ok(Model {
            case,
            mesh,
            dof_map,
            stiffness,
            mass,
            joint,
        })
    }

    /// Number of independent DOF (after eliminating clamp and rigid tie).
    pub fn dofs(&self) -> usize {
        self.dof_map.n
    }

    /// Number of distinct independent DOF on nodes of joint pairs.
    pub fn joint_dofs(&self) -> usize {
        let mut nodes: Vec<usize> = self
            .mesh
            .pairs
            .iter()
            .flat_map(|p| [p.lower, p.upper])
            .collect();
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

    /// The lowest `count` eigenmodes with the master node free or clamped.
    pub fn modes(&self, count: usize, interface: Interface) -> Result<Modes, Error> {
        match interface {
            Interface::Free => modes::lowest_modes(&self.stiffness, &self.mass, count),
            Interface::Fixed => {
                let m = self.dofs() - 6;
                modes::lowest_modes(&self.stiffness.leading(m), &self.mass.leading(m), count)
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
