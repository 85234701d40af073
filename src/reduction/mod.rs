//! Model order reduction with trial vector derivatives (Witteveen & Pichler 2014, Sections 2–3,
//! Algorithm 2).
//!
//! The full model `M ẍ + K x = f(t) − f_NL(x)` (eq. 6; `f_NL` the joint contact and friction
//! pseudoforces) is projected on `x = Φ q` (eq. 3), giving `M̃ q̈ + K̃ q = Φᵀ f − Φᵀ f_NL(Φ q)`
//! with `M̃ = ΦᵀMΦ`, `K̃ = ΦᵀKΦ` (eq. 7). The basis (eq. 9, Algorithm 2) is
//! `Φ = [Φ_S Φ_V Φ̃_T]`:
//!
//! 1. [`craig_bampton()`]: `Φ_S`, the s = 6 constraint modes of the master node, and `Φ_V`, ν
//!    fixed-interface normal modes (Section 4: both at the undeformed state, no joint stiffness).
//! 2. [`trial_vector_derivatives`]: for each trial vector φ_j and each sign k = ±1 (eqs. 27–28:
//!    the contact stiffness is one-sided, so `∂K/∂q_j ≠ −∂K/∂(−q_j)`), the pairs whose normal
//!    gap under `k φ_j` is ≤ 0 get the penalty stiffness `k_n` (and optionally `k_t`):
//!    `∂K/∂q_{k,j} = Σ_active k_n b_nᵀ b_n`. The TVD `φ_{i,k,j} = K⁻¹ ∂K/∂q_{k,j} φ_i`
//!    (eqs. 16, 18: the static response to the pseudoforce of eq. 19; by default the inertia
//!    terms of eq. 15 are neglected, as in the paper's Algorithm 2, and [`TvdOptions::inertia`]
//!    includes them for the fixed-interface modes) — `2 (v + s)²` candidates, each normalized
//!    to `φᵀKφ = 1`. Gaps are compared with zero relative to φ_j's displacement scale (its
//!    largest translation, see [`active_pairs`]): a vector that opens no gap (an in-plane
//!    constraint mode) has round-off gaps, and their signs must not decide its active sets.
//! 3. [`pod()`]: the POD of the TVD (eqs. 20–25), K-weighted (the paper's choice: the POMs
//!    approximate the deformation energy of the TVD space) or plain, with the energy ratio
//!    `w(g)` (eq. 26) to choose the number g of joint modes `Φ̃_T` (eq. 23 scaling).
//!    For TVD, [`pod_tvd`] computes the same POD from the factor form `Y = K⁻¹ B_uᵀ C` as an
//!    SVD (no `Yᵀ K Y`), resolving eigenvalues far below the Gram's round-off, so that with all
//!    POMs the reduced contact force converges to the full one (the measured errors are in
//!    `docs/validation/static-convergence.md`, section `reduction`).
//! 4. [`final_basis`]: the parts concatenated and M-orthonormalized (so `M̃ = I`), dependent
//!    directions dropped; [`build_basis`] then rotates Φ to the reduced eigenbasis
//!    ([`modal_rotation`]: `K̃ = diag(ω²)`, same span) unless `BasisOptions::modal` is false.
//! 5. The reduced system on Φ ([`crate::system::ReducedSystem`], from
//!    [`crate::system::FullSystem::reduce`] or [`crate::system::ReducedSystem::new`]): `K̃`, `M̃`,
//!    the reduced joint operator `B Φ` and the reduced load.
//!
//! The competitors of the paper's Section 5, behind the same [`build_basis`] ([`BasisKind`]):
//! modes only (more fixed-interface modes), [`competitors::jim`] (Joint Interface Modes,
//! Section 5.3), [`competitors::alldof`] (constraint modes of all joint normal DOF,
//! Section 5.1) and, with its own builder because it needs full-FE results,
//! [`competitors::snapshots`] (POD of transient snapshots, Section 5.2).
//!
//! Without `k_t` every TVD lies in `span(K⁻¹ B_nᵀ)`, so the TVD space has at most one dimension
//! per pair and `w(g) = 1` by g = w (number of pairs).
//!
//! The inertia-corrected TVD of eq. (15) for the fixed-interface vibration modes is implemented:
//! [`TvdOptions::inertia`] (off by default, as in Algorithm 2) factors the indefinite
//! `K − Ω_i² M` of each mode by sparse LU (see [`tvd`]). The static convergence study runs it as
//! its `tvd-inertia` variant (`jointrom study`); the other commands' TVD bases use eq. (16), and
//! a library caller selects eq. (15) through `BasisOptions::tvd`.

pub mod basis;
mod build;
pub mod competitors;
pub mod craig_bampton;
pub mod distributed;
pub mod estimate;
pub mod joint_pod;
pub mod pod;
pub mod tvd;

pub use basis::{
    final_basis, modal_rotation, Basis, BasisOptions, JimSet, Orthonormalizer, DEFAULT_DROP_TOL,
};
pub use build::{build_basis, build_tvd_basis_both_pods, BasisKind};
pub use competitors::{
    alldof_vectors, jim_dofs, jim_vectors, joint_interface_modes, snapshot_basis, snapshot_pod,
    JointInterfaceModes,
};
pub use craig_bampton::{craig_bampton, craig_bampton_with, FixedInterface};
pub use estimate::{
    CurveErrors, ErrorEstimator, Estimate, JointFlexibility, Quantities, Quantity, RunStates,
};
pub use joint_pod::{joint_pod, JointPod};
pub use pod::{
    pod, pod_tvd, pod_tvd_leading, pod_tvd_ratios, sigma_zero, Pod, DEFAULT_THRESHOLD,
    ZERO_EIGENVALUE,
};
pub use tvd::{
    active_pairs, displacement_scales, static_right_hand_sides, trial_vector_derivatives,
    trial_vector_derivatives_factored, Tvd, TvdFactor, TvdIndex, TvdOptions,
};
