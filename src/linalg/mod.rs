//! Linear algebra under everything else: symmetric sparse storage and products ([`sparse`]), the
//! sparse SPD Cholesky factorization ([`cholesky`]) and its exact low-rank corrections
//! ([`lowrank`]), compensated double-double arithmetic for the ill-conditioned shell stiffness
//! ([`compensated`]) and the generalized symmetric eigenproblem ([`eigen`]), and the blocked
//! dense matrix–vector kernels of the reduced model's steps ([`kernels`]). Depends on nothing
//! of jointrom but its error type.

pub mod cholesky;
pub mod compensated;
pub mod eigen;
mod error;
pub mod kernels;
pub mod lowrank;
pub mod sparse;
pub mod subset_llt;

pub use cholesky::{solve_spd, SparseCholesky};
pub use eigen::{dense_modes, lowest_modes, Modes};
pub use error::LinalgError;
pub use lowrank::LowRankCholesky;
pub use sparse::SymCsc;
pub use subset_llt::SubsetLlt;
