//! Finite elements, named by node count.
//!
//! Every element returns its stiffness and mass in **global** axes, with 6 DOF per node in the
//! order `[ux, uy, uz, rx, ry, rz]` (mm and rad), nodes in the order given to the constructor.
//! Matrices are dense `faer::Mat<f64>` (24×24 for [`Shell4`], 12×12 for [`Beam2`], 6N×6N over the
//! N shell nodes an area [`Weld`]'s nugget touches); units are
//! N/mm, N, N·mm/rad for stiffness and t, t·mm, t·mm² for mass.

mod beam2;
mod shell4;
mod weld;
mod weld_cache;
mod weld_patch;
mod weld_slab;

pub use beam2::Beam2;
pub use shell4::Shell4;
pub use weld::Weld;

pub use crate::error::{ElementError, WeldLayerProblem};
pub use crate::mesh::Material;
