//! Linear algebra under everything else: symmetric sparse storage and products ([`sparse`]), the
//! sparse SPD Cholesky factorization ([`cholesky`]) and its exact low-rank corrections
//! ([`lowrank`]), compensated double-double arithmetic for the ill-conditioned shell stiffness
//! ([`compensated`]), the generalized symmetric eigenproblem ([`eigen`]) and the dense symmetric one
//! ([`symmetric`]: backward stable for any spectrum, unlike faer's divide and conquer), and the blocked
//! dense matrix–vector kernels of the reduced model's steps ([`kernels`]). Depends on nothing
//! of jointrom but its error type.

pub mod cholesky;
pub mod compensated;
pub mod eigen;
mod error;
pub mod kernels;
pub mod lowrank;
pub(crate) mod random;
pub mod sparse;
pub mod subset_llt;
pub mod symmetric;

pub use cholesky::{solve_spd, SparseCholesky};
pub use eigen::{dense_modes, lowest_modes, Modes};
pub use error::LinalgError;
pub use lowrank::LowRankCholesky;
pub use sparse::SymCsc;
pub use subset_llt::SubsetLlt;
pub use symmetric::{symmetric_eigen, symmetric_eigenvalues, SymmetricEigen};
