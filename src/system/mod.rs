//! The narrow second-order-system boundary shared by the full and every reduced model, so one
//! integrator ([`crate::integrate::mechanical`]) runs both (AMfe's "mechanical system").
//!
//! A system is the undamped structure of the paper's eq. (6) (full) or eq. (7) (reduced):
//!
//! ```text
//! M q̈ + K q = f(t) − Bᵀ p(B q, s)
//! ```
//!
//! with `q` the n structural DOF (full: mm, rad) or r generalized coordinates (reduced, `x = Φ q`),
//! `f(t)` the master-node load of the case times its half-cosine ramp (reduced: `Φᵀ f`), `B` the
//! joint operator (3 rows per pair: normal, t1, t2; reduced: `B Φ`) and `p` the pair forces of
//! [`crate::joint::law`]. Besides the operators a system factors and solves the Newton matrix of a
//! second-order model (see `shared/NOTES.md` and [`crate::integrate::mechanical`])
//!
//! ```text
//! A = M + γ² (K + Bᵀ K_c B) ,
//! ```
//!
//! `K_c` block diagonal with one symmetric 3×3 block per pair. [`FullSystem`]: sparse, the
//! pattern of `M + K + Bᵀ B` and its symbolic Cholesky analysis (AMD) built once at construction,
//! a numeric refactorization per setup into preallocated storage. [`ReducedSystem`]: dense r × r,
//! dense Cholesky in place. Neither allocates in a right-hand side or a Newton solve; the full
//! model's exact low-rank refresh ([`SecondOrderSystem::newton_update`]) allocates when it adds
//! columns (faer's blocked half solves).

//!
//! A system holds the structure and its load only: the contact law, the end time and the
//! integrator's options belong to a run ([`crate::integrate`]). [`FullSystem::reduce`] projects
//! the full system on a basis Φ and returns a [`ReducedSystem`] of the same interface, so one
//! integrator drives both.

mod full;
mod modal_newton;
mod reduced;

pub use full::FullSystem;
pub use reduced::{ErrorScale, ReducedSystem};

use serde::Serialize;

use crate::case::ContactSpec;
use crate::error::Error;
use crate::model::Model;

/// What a run simulates besides the structure and its load: the joint's contact law and the
/// span.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Scene {
    /// Contact and friction law (k_n, k_t in N/mm, μ).
    pub contact: ContactSpec,
    /// End of the simulated span, s.
    pub end_time: f64,
}

impl Scene {
    /// The scene of a model: its contact law and end time.
    pub fn of(model: &Model) -> Scene {
        Scene {
            contact: model.contact,
            end_time: model.end_time,
        }
    }
}

/// One kind of row of the joint operator `B` (rows normal, t1, t2 per pair):
/// [`SecondOrderSystem::joint_apply_rows_into`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum JointRows {
    /// The normal rows `3z` (the gaps).
    Normal,
    /// The tangential rows `3z + 1`, `3z + 2`.
    Tangential,
}

/// A linear undamped second-order system with joint pairs.
pub trait SecondOrderSystem {
    /// Number of coordinates (n full, r reduced).
    fn dim(&self) -> usize;
    /// Number of joint pairs w.
    fn pairs(&self) -> usize;
    /// `out = K q`.
    fn mul_k_into(&self, q: &[f64], out: &mut [f64]);
    /// `out = M x`.
    fn mul_m_into(&self, x: &[f64], out: &mut [f64]);
    /// `x ← M⁻¹ x`.
    fn solve_m_in_place(&mut self, x: &mut [f64]);
    /// `out = f(t)` (N, N·mm; reduced: generalized forces).
    fn load_into(&self, t: f64, out: &mut [f64]);
    /// `out` = the (generalized) forces of the master-node load `f = [Fx, Fy, Fz (N), Mx, My,
    /// Mz (N·mm)]`: the load vector with `f` on the six master DOF (full), `Φ_mᵀ f` (reduced).
    /// [`SecondOrderSystem::load_into`] is this of the case's load at `t`; a co-simulation adds
    /// its own master load through it ([`crate::integrate::Stepper`]).
    fn master_load_into(&self, f: &[f64; 6], out: &mut [f64]);
    /// `out = B q` (3 per pair: gap, slip x, slip z; mm).
    fn joint_apply_into(&self, q: &[f64], out: &mut [f64]);
    /// `out += Bᵀ p`.
    fn joint_transpose_add(&self, p: &[f64], out: &mut [f64]);
    /// The Euclidean norm of each pair's normal row of `B` in these coordinates (w values; mm
    /// per unit coordinate) if the system screens its pairs
    /// ([`crate::integrate::mechanical`], *Pair screening*): a reduced model, whose dense
    /// `B q` costs 3w·r per product. `None` (the default): every pair is evaluated at every
    /// right-hand side (the full model, whose sparse `B q` costs a few entries per pair).
    fn joint_normal_row_norms(&self) -> Option<Vec<f64>> {
        None
    }
    /// `out = B_n q`: the normal gaps of all pairs (w values, mm). The default goes through
    /// [`SecondOrderSystem::joint_apply_into`] with a scratch vector; a system that screens its
    /// pairs overrides this and the next three methods with direct row products.
    fn joint_normal_apply_into(&self, q: &[f64], out: &mut [f64]) {
        let mut u = vec![0.0; 3 * self.pairs()];
        self.joint_apply_into(q, &mut u);
        for (o, g) in out.iter_mut().zip(u.iter().step_by(3)) {
            *o = *g;
        }
    }
    /// Pair z's normal gap `(B q)_{3z}`, mm.
    fn joint_normal_gap(&self, q: &[f64], z: usize) -> f64 {
        self.joint_pair(q, z)[0]
    }
    /// Pair z's kinematics `[(B q)_{3z}, (B q)_{3z+1}, (B q)_{3z+2}]` (gap, slip x, slip z; mm).
    fn joint_pair(&self, q: &[f64], z: usize) -> [f64; 3] {
        let mut u = vec![0.0; 3 * self.pairs()];
        self.joint_apply_into(q, &mut u);
        [u[3 * z], u[3 * z + 1], u[3 * z + 2]]
    }
    /// Pair z's tangential kinematics `[(B q)_{3z+1}, (B q)_{3z+2}]` (slip x, slip z; mm), the
    /// same values as those entries of [`SecondOrderSystem::joint_pair`].
    fn joint_pair_tangential(&self, q: &[f64], z: usize) -> [f64; 2] {
        let [_, t1, t2] = self.joint_pair(q, z);
        [t1, t2]
    }
    /// `out[3z..3z+3] = (B q)_{3z..3z+3}` for the pairs z in `pairs` (other entries untouched).
    fn joint_apply_pairs_into(&self, q: &[f64], pairs: &[usize], out: &mut [f64]) {
        for &z in pairs {
            out[3 * z..3 * z + 3].copy_from_slice(&self.joint_pair(q, z));
        }
    }
    /// Parts of `out = B q` where only some rows are needed, with the same values, bit for
    /// bit, as [`SecondOrderSystem::joint_apply_into`] gives those entries: the rows of one
    /// kind for every pair if `all` names one ([`JointRows`]), written through `scratch` (2w
    /// entries), then the listed rows `extra` (indices into `out`). The other entries of `out`
    /// are left as they are. `false` (the default) if the system does not offer it: nothing is
    /// written, and the caller takes the whole product. A reduced model offers it: its dense
    /// `B q` costs 3w·r per product.
    fn joint_apply_rows_into(
        &self,
        _q: &[f64],
        _all: Option<JointRows>,
        _extra: &[usize],
        _scratch: &mut [f64],
        _out: &mut [f64],
    ) -> bool {
        false
    }
    /// `out += Σ_{z ∈ pairs} B_zᵀ p_z` (the rows of the other pairs are skipped).
    fn joint_transpose_add_pairs(&self, p: &[f64], pairs: &[usize], out: &mut [f64]) {
        let mut masked = vec![0.0; p.len()];
        for &z in pairs {
            masked[3 * z..3 * z + 3].copy_from_slice(&p[3 * z..3 * z + 3]);
        }
        self.joint_transpose_add(&masked, out);
    }
    /// Factors `M + γ² (K + Bᵀ K_c B)`; `kc` holds one 3×3 row-major symmetric block per pair
    /// (N/mm). Errors if the matrix is not positive definite.
    fn newton_factor(&mut self, gamma: f64, kc: &[f64]) -> Result<(), Error>;
    /// `x ← A⁻¹ x` with the last [`SecondOrderSystem::newton_factor`] (and the
    /// [`SecondOrderSystem::newton_update`]s since).
    fn newton_solve_in_place(&mut self, x: &mut [f64]);
    /// Changes the factored Newton matrix in the blocks of the pairs `changed` only, to their
    /// blocks in `kc` (every other pair's block must be the one factored), at the γ of the last
    /// [`SecondOrderSystem::newton_factor`] `γ_f`:
    /// `A ← A + γ_f² Σ_{i ∈ changed} B_iᵀ (K_c,i − K_c,i^factored) B_i`, exactly, without
    /// refactoring. `false` if the system does not do this (the default) or cannot now (its
    /// correction is full, or would cost more than a factorization): the caller then refactors
    /// with [`SecondOrderSystem::newton_factor`].
    fn newton_update(&mut self, kc: &[f64], changed: &[usize]) -> bool {
        let _ = (kc, changed);
        false
    }
    /// The master node's `[ux, uy, uz (mm), rx, ry, rz (rad)]` at `q`.
    fn master_displacement(&self, q: &[f64]) -> [f64; 6];
    /// The physical size of a unit of each coordinate: the Euclidean norm, over the physical
    /// field's [`SecondOrderSystem::field_dofs`] DOF, of the nodal displacements (mm) and
    /// rotations (rad) it produces. 1 for physical DOF (the default); for a reduced model the
    /// norm of the basis column, so that a tolerance stated in mm applies to the physical field
    /// whatever the basis normalization (`crate::integrate::mechanical`, *The error test of a
    /// reduced model*).
    fn coordinate_size_into(&self, out: &mut [f64]) {
        out.iter_mut().for_each(|x| *x = 1.0);
    }
    /// The number of physical DOF the coordinates describe: [`SecondOrderSystem::dim`] for
    /// physical DOF (the default), the full model's n for a reduced model.
    fn field_dofs(&self) -> usize {
        self.dim()
    }
}
