//! The competitors of the paper's Section 5, built from the same core steps: all joint DOF kept
//! ([`alldof`], Section 5.1), POD of transient snapshots ([`snapshots`], Section 5.2) and Joint
//! Interface Modes ([`jim`], Section 5.3).

pub mod alldof;
pub mod jim;
pub mod snapshots;

pub use alldof::alldof_vectors;
pub use jim::{jim_dofs, jim_vectors, joint_interface_modes, JointInterfaceModes};
pub use snapshots::{snapshot_basis, snapshot_pod};
