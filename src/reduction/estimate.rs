//! A-posteriori error estimate of a reduced run's joint forces: the quasi-static joint
//! correction, solved in the space of the joint pairs.
//!
//! ## What a reduced model misses
//!
//! The full model (eq. 6) is `M ẍ + K x = f(t) − Bᵀ p(B x, s)`. Solving it for `x` with the
//! inertia and pair forces taken as loads gives the identity (the "modal acceleration" form of
//! the displacement)
//!
//! ```text
//! x = K⁻¹ (f(t) − M ẍ − Bᵀ p) .
//! ```
//!
//! A reduced run `x ≈ Φ q(t)` (eq. 3) gets the global motion right long before it gets the local
//! deformation at the pairs: every direction that a pair force excites locally,
//! `K⁻¹ b_kᵀ`, is a static response of high frequency (the flexibility of one pair against the
//! sheet), and the basis holds it only if its pair was chosen. Its pair forces `p(BΦq)` then
//! follow the wrong gaps — the paper's a-priori `w(g)` rule misses ‖f_c‖ by 22–61 % while the tip
//! motion is within 0.5 %.
//!
//! ## The correction
//!
//! Take from the reduced run what it gets right — the accelerations `ẍ ≈ Φ q̈` (with
//! `M̃ q̈ = Φᵀ f − K̃ q − (BΦ)ᵀ p`) and the slip memory `s` — and recompute the pair kinematics
//! `u = B x` (3w: gap, slip t1, slip t2 per pair) from the identity above, with the pair forces
//! consistent with `u`:
//!
//! ```text
//! u = H f_m(t) − G q̈ − F p(u, s)
//! F = B K⁻¹ Bᵀ   (3w × 3w, mm/N: the joint flexibility)
//! H = B K⁻¹ E_m  (3w × 6: pair kinematics under unit master loads)
//! G = B K⁻¹ M Φ  (3w × r: under the inertia of a unit reduced acceleration)
//! ```
//!
//! `f = E_m f_m(t)` is the master load. All three matrices come from one sparse Cholesky of `K`
//! and `3w + 6` solves (`Z = K⁻¹ [Bᵀ E_m]`), `G = Zᵀ M Φ` per basis; each output time then costs
//! O(w² + w r). The normal part is the frictionless contact problem of the pairs alone — the
//! tangential forces enter as loads, `p_t` of the reduced run:
//!
//! ```text
//! g = ĝ − k_n F_{n,A} g_A ,   ĝ = (H f_m − G q̈ − F_{·,t} p_t)_n ,   A = {k : g_k < 0}
//! (I + k_n F_AA) g_A = ĝ_A
//! ```
//!
//! solved exactly by the active-set Newton method of [`crate::joint::statics`]; the corrected
//! normal forces are `p_n* = k_n min(g, 0)`. The corrected tangential forces are the law's at the
//! corrected slips with the run's slip memory, `p_t* = p_t(u_t*, s)`, and the master
//! displacement is `x_m* = C f_m − G_m q̈ − Hᵀ p*` (`C = E_mᵀ K⁻¹ E_m`, `G_m = E_mᵀ K⁻¹ M Φ`).
//!
//! The estimate of a curve's relative L2 error (the measure of [`crate::studies`], e.g.
//! ‖f_c‖(t) against the full run) is the same measure of the reduced curve against the
//! corrected one:
//!
//! ```text
//! η_fc = ‖ ‖p_n(t)‖ − ‖p_n*(t)‖ ‖_L2 / ‖ ‖p_n*(t)‖ ‖_L2      (likewise ‖f_R‖, u_y)
//! ```
//!
//! ## Friction
//!
//! A sticking pair's force `p_t = k_t (u_t − s)` is set by the structure's tangential compliance
//! at the pair, which a basis of normal attachment modes lacks. The correction solves the
//! sticking pairs' problem on the exact flexibility with the run's slip memory (a pair the run
//! slides keeps its direction on the corrected cone `μ|p_n*|`, set L):
//!
//! ```text
//! (I + k_t F_SS) p_S* = k_t (û_S − F_{S,n} p_n* − F_{S,L} p_L* − s_S)
//! ```
//!
//! a pair of S whose force leaves its cone slides on it and S is solved again without it. A pair
//! the run holds open has no slip memory of its own there (it follows the pair's tangential
//! motion): where the correction closes it, it slides on its cone in the direction of its
//! tangential motion over the last output interval if that motion exceeds its stick radius
//! `μ|p_n*|/k_t` (what the full model's pair does once closed), else it joins S. The
//! tangential rows of the tangential flexibility columns are kept beside their normal rows.
//!
//! The dissipated energy `D = ∫ p_t · ṡ dt` of the run and of the correction is summed over the
//! output states, each state with its own forces and its own slip, over the intervals its pair
//! is closed at both ends: the run's memory s, and for the correction the slip of the corrected
//! state `s* = u_t* − p_t*/k_t` at its kinematics `u_t* = û_t − F_{t,n} p_n* − F_{t,t} p_t*`
//! (equal to s for a pair that sticks, since `p_t* = k_t (u_t* − s)` there). Putting the
//! corrected forces on the run's slip instead counts a pair whose cone the correction raises
//! as sliding as far as before under the larger force; a joint that slides carries the load
//! through friction, so a pair that takes more of it moves the structure (and itself) less
//! and the others slide under what is left — the corrected kinematics see that, the run's slip
//! does not (measured: D over-estimated 18–37× where ‖f_c‖ is a few per cent off). The
//! estimate is the relative L2 of the two curves and their relative difference at the end.
//!
//! D* is summed from the **joint part** of the correction (below: without the truncated modes'
//! dynamic excess). The excess is driven by the run's pair forces sampled at the outputs and
//! taken as linear between them; it is undamped, so every change of slope of that sampled
//! force starts a free oscillation that stays. A run integrated loosely (the tolerance model's
//! runs, up to 100× the paper's tolerances) carries ringing stick forces, and their sampling
//! noise accumulates in the excess and shakes the gaps of lightly loaded pairs: such a pair
//! flickers open in the correction (intervals lost from D*) and slides under a lower mean cone.
//! A curve's L2 error averages that noise; D, an integral of cone force times slip, turns it
//! into a bias (the friction bar's 1 % model at rtol 1e-6: D* 0.95 % below the full model's D
//! with the excess, 0.08 % without; 0.07 % and 0.08 % at rtol 1e-8). What the truncated modes
//! do to D is the truncation check's to measure, which also sees their back-coupling into the
//! global motion (`crate::rom::estimate`), where the first-order excess does not.
//!
//! ## Truncation: the dynamics of the modes beyond the basis
//!
//! The quasi-static identity treats every direction outside Φ as static. The fixed-interface
//! modes just above the basis's ν are not: the load excites them dynamically, and on the
//! multilayer sheet the all-joint-DOF model with ν = 10 misses ‖f_c‖(t) by 0.5 % for that reason
//! alone (0.15 % with ν = 20). The estimate therefore adds their dynamic excess: the lowest
//! [`TRUNCATION_MODES`] fixed-interface modes, M-orthogonalized against Φ and rotated to their own
//! eigenbasis (`Ψ`, `ΨᵀMΨ = I`, `ΨᵀKΨ = diag(ω²)`), are driven by the reduced run's residual
//!
//! ```text
//! η̈ + ω² η = ρ(t) ,   ρ = Ψᵀ (f − M Φ q̈ − K Φ q − Bᵀ p) = Ψ_mᵀ f_m − (ΨᵀKΦ) q − (BΨ)ᵀ p
//! ```
//!
//! (the `MΦq̈` term vanishes by M-orthogonality), and the part of η that the quasi-static
//! identity does not already hold, `Δ = η − ρ/ω²`, moves the pairs by `BΨ Δ` and the master by
//! `Ψ_m Δ`. With ρ linear between outputs, Δ is a free oscillation within each interval whose
//! rate jumps by `−Δρ̇/ω²` where ρ's slope changes — integrated exactly. The two parts are
//! reported separately ([`Estimate::joint`], [`Estimate::truncation`]): more pair attachment
//! modes remove the first, more fixed-interface modes the second.
//!
//! ## Cost: only the columns of F the contact problems touch
//!
//! `F` is 3w × 3w and `K⁻¹ Bᵀ` is n × 3w: at 10⁵ DOF and 5 888 pairs, 2.5 GB and 15 GB, and
//! 17 664 sparse solves. Neither is formed. The correction reads `F` only through
//!
//! - `F_{n,A} g_A`: the normal flexibility columns of the pairs in the active set A (the
//!   semismooth Newton iteration and its projected Gauss–Seidel fallback), and
//! - `F_{n,t} p_t`: the tangential columns of the pairs that carry a friction force in the run,
//!
//! and only their normal rows (the problem is posed on the gaps). Each column `B_n K⁻¹ b_rᵀ`
//! (w values) is solved the first time a contact problem touches its row — blocked,
//! 256 right-hand sides per multi-column solve, refined once — and kept for every
//! later output, round and variant of the model (`H`, `C` take six solves, `G = B K⁻¹ M Φ` r per
//! basis). The cost is one solve per pair that is ever in contact or in friction, the memory
//! w × 8 bytes per such column. The semismooth iteration lets only the deepest penetrations
//! join the active set per iteration (`next_active_set`): the structure without contact forces
//! penetrates along most of a refined interface, while the forces of the deepest few open the
//! rest. Measured on the friction bar ×8 (40 806 DOF, 2 287 pairs, with friction): the
//! a-priori TVD run's estimate went from 130 s and 5.8 GB (dense `F` and `K⁻¹Bᵀ`) to 21 s and
//! 0.75 GB with the same figures to 1e-12.
//!
//! ## When it is exact, and what it neglects
//!
//! In statics (`q̈ = 0`, no friction) the correction *is* the full model's contact problem,
//! condensed to the pairs exactly: the estimate equals the true error. In a transient it
//! neglects the inertia of the correction's pair directions (quasi-static: their frequencies lie
//! far above the load's), the back-coupling of the error into the reduced coordinates, and takes
//! the slip memory from the reduced run — so ‖f_R‖ and the master u_y are estimated less well
//! than ‖f_c‖ (measured effectivities in docs/validation/error-control.md). The per-pair differences
//! `Σ_t (p_{n,k} − p_{n,k}*)²` say which pairs' attachment modes `K⁻¹ b_kᵀ` the basis needs
//! ([`Estimate::pair_error`]); `crate::rom::tolerance` enriches the basis with them (and ν)
//! until the estimate meets a tolerance, and adds the integration error of the run.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};

use faer::{Mat, MatRef};

use crate::error::{Error, ReductionError};
use crate::joint::law::PairLaw;
use crate::joint::JointOperator;
use crate::joint::{NORMAL, T1, T2};
use crate::linalg::cholesky::SparseCholesky;
use crate::linalg::compensated::{
    compensated_gram, solve_refined, solve_refined_owned, solve_refined_steps_owned,
};
use crate::linalg::sparse::sym_mul_mat;
use crate::linalg::symmetric_eigen;
use crate::linalg::LinalgError;
use crate::linalg::{SubsetLlt, SymCsc};
use crate::model::{Interface, Model};
use crate::reduction::basis::orthonormal_beyond;
use crate::reduction::craig_bampton::FixedInterface;
use crate::system::{ReducedSystem, SecondOrderSystem};

/// The joint flexibility of a model: one sparse Cholesky of `K`, the static responses to unit
/// master loads, and the columns of the pair flexibility `F` that the contact problems touch,
/// solved on first use (module docs, "Cost").
pub struct JointFlexibility {
    /// `K` (for the refined solves) and its factorization.
    stiffness: SymCsc,
    chol: SparseCholesky,
    /// The joint operator B (3w × n).
    joint: JointOperator,
    /// The six master DOF.
    master: [usize; 6],
    /// `H = B K⁻¹ E_m` (3w × 6), mm per N (N·mm).
    h: Mat<f64>,
    /// `C = E_mᵀ K⁻¹ E_m` (6 × 6, symmetric).
    c: Mat<f64>,
    /// Normal penalty stiffness of the model's contact law, N/mm.
    k_n: f64,
    /// The lowest fixed-interface modes (n × count, M-orthonormal, zero at the master) for the
    /// truncation part of the estimate: computed on first use
    /// ([`JointFlexibility::truncation_modes`]), again with more when more are asked for.
    modes: Mutex<Option<Arc<Mat<f64>>>>,
    /// How many truncated modes the estimate holds: [`TRUNCATION_MODES`], or more once a
    /// basis's ν needs them ([`JointFlexibility::hold_truncation_modes`]).
    held: std::sync::atomic::AtomicUsize,
    /// The model's fixed-interface problem with its factorization, if shared
    /// ([`JointFlexibility::share_fixed_interface`]): the truncated modes are then solved with
    /// it instead of a factorization of their own.
    fixed: std::sync::OnceLock<Arc<FixedInterface>>,
    /// Per joint row r (3w: normal, t1, t2 of each pair), once solved: the normal rows of its
    /// flexibility column `B_n K⁻¹ b_rᵀ` (w values, mm/N). Shared by every estimate of the
    /// model (sweeps run in parallel), so behind a lock.
    columns: Mutex<Vec<Option<Arc<[f64]>>>>,
    /// Per tangential joint row r (`3k + T1`, `3k + T2`), once solved: the tangential rows of
    /// its flexibility column `B_t K⁻¹ b_rᵀ` (2w values, t1 and t2 of each pair in turn, mm/N),
    /// for the stick correction of the tangential forces (module docs, "Friction").
    tangential: Mutex<Vec<Option<Arc<[f64]>>>>,
}

/// Fixed-interface modes computed for the truncation part of the estimate (module docs): the
/// modes of these beyond a basis's span are the ones whose dynamics it checks. At least this
/// many; a basis of ν fixed-interface modes has [`truncated_modes_for`]`(ν)` held.
pub const TRUNCATION_MODES: usize = 40;

/// Fixed-interface modes the estimate checks beyond a basis's ν once ν is past
/// `TRUNCATION_MODES − TRUNCATION_BEYOND`.
pub const TRUNCATION_BEYOND: usize = 20;

/// The truncated modes held for a basis of `nu` fixed-interface modes: the lowest
/// [`TRUNCATION_MODES`], or `nu + TRUNCATION_BEYOND` when that is more — a scene whose motion
/// needs many fixed-interface modes (impacts in the joint ring up modes far above the load's)
/// keeps having the modes beyond its ν checked.
pub fn truncated_modes_for(nu: usize) -> usize {
    TRUNCATION_MODES.max(nu + TRUNCATION_BEYOND)
}

/// Refinement steps (double-double residuals) of the flexibility columns and the friction
/// term: one, where the basis vectors take two (the pair-space statics still equal the full
/// model's to 1e-9 of ‖f_c‖, tested); the columns are most of the estimate's cost on a
/// refined mesh.
const COLUMN_REFINEMENT: usize = 1;

/// Right-hand sides per blocked solve of the flexibility (bounds the n × block scratch).
const SOLVE_CHUNK: usize = 256;

/// Columns per solve of [`JointFlexibility::prefetch_normal_columns`]: how far it may run past
/// its stop signal.
pub const PREFETCH_BLOCK: usize = 8;

impl JointFlexibility {
    /// Factors the model's `K` once and solves for the six unit master loads (refined twice
    /// with double-double residuals, as the other static vectors of [`crate::reduction`]);
    /// pair columns and the truncation modes follow on demand.
    pub fn new(model: &Model) -> Result<JointFlexibility, Error> {
        let n = model.dofs();
        let master = model.master_dofs();
        let mut rhs = Mat::<f64>::zeros(n, 6);
        for (d, &m) in master.iter().enumerate() {
            rhs[(m, d)] = 1.0;
        }
        let chol = SparseCholesky::new(&model.stiffness)?;
        let z = solve_refined(&model.stiffness, &chol, &rhs);
        if z.col_iter().any(|c| c.iter().any(|v| !v.is_finite())) {
            return Err(Error::LinearAlgebra(LinalgError::not_finite(
                "joint flexibility K⁻¹ E_m",
            )));
        }
        let h = model.joint.reduce(z.as_ref());
        let c = Mat::from_fn(6, 6, |a, b| 0.5 * (z[(master[a], b)] + z[(master[b], a)]));
        Ok(JointFlexibility {
            stiffness: model.stiffness.clone(),
            chol,
            joint: model.joint.clone(),
            master,
            h,
            c,
            k_n: model.contact.normal_stiffness,
            modes: Mutex::new(None),
            held: std::sync::atomic::AtomicUsize::new(TRUNCATION_MODES),
            fixed: std::sync::OnceLock::new(),
            columns: Mutex::new(vec![None; model.joint.rows()]),
            tangential: Mutex::new(vec![None; model.joint.rows()]),
        })
    }

    /// Number of joint pairs w.
    pub fn pairs(&self) -> usize {
        self.joint.pairs()
    }

    /// Number of flexibility columns solved so far (normal and tangential; the estimate's
    /// memory beyond the factorization is this × w × 8 bytes).
    pub fn solved_columns(&self) -> usize {
        self.lock_columns().iter().filter(|c| c.is_some()).count()
    }

    fn lock_columns(&self) -> std::sync::MutexGuard<'_, Vec<Option<Arc<[f64]>>>> {
        // A panic elsewhere cannot leave a half-written column: entries are replaced whole.
        self.columns
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
    }

    fn lock_tangential(&self) -> std::sync::MutexGuard<'_, Vec<Option<Arc<[f64]>>>> {
        self.tangential
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
    }

    /// The flexibility columns of the tangential joint rows `rows`: per row its normal rows
    /// `B_n K⁻¹ b_rᵀ` (w values) and its tangential rows `B_t K⁻¹ b_rᵀ` (2w values), mm/N,
    /// solved on first use ([`JointFlexibility::columns`]).
    #[allow(clippy::type_complexity)]
    fn tangential_columns(&self, rows: &[usize]) -> Result<Vec<(Arc<[f64]>, Arc<[f64]>)>, Error> {
        let normal = self.columns(rows)?;
        let tang = self.lock_tangential();
        Ok(normal
            .into_iter()
            .zip(rows)
            .map(|(n, &r)| (n, tang[r].clone().expect("solved with its normal rows")))
            .collect())
    }

    /// The flexibility columns `B_n K⁻¹ b_rᵀ` (each w values, mm/N) of the joint rows `rows`
    /// (`3k + NORMAL` for pair k's normal force, `3k + T1`, `3k + T2` for its tangential ones),
    /// solving the missing ones in blocked multi-right-hand-side solves of [`SOLVE_CHUNK`]
    /// columns. Only the normal rows of the response are kept: the pair-space contact problem
    /// is posed on the gaps.
    fn columns(&self, rows: &[usize]) -> Result<Vec<Arc<[f64]>>, Error> {
        let missing: Vec<usize> = {
            let cols = self.lock_columns();
            let tang = self.lock_tangential();
            let mut m: Vec<usize> = rows
                .iter()
                .copied()
                .filter(|&r| cols[r].is_none() || (r % 3 != NORMAL && tang[r].is_none()))
                .collect();
            m.sort_unstable();
            m.dedup();
            m
        };
        let w = self.pairs();
        let n = self.stiffness.n;
        for chunk in missing.chunks(SOLVE_CHUNK) {
            let mut rhs = Mat::<f64>::zeros(n, chunk.len());
            for (j, &r) in chunk.iter().enumerate() {
                for (i, v) in self.joint.row(r) {
                    rhs[(i, j)] += v;
                }
            }
            // The solution overwrites the right-hand sides: one n × chunk matrix, not two.
            let x = solve_refined_steps_owned(&self.stiffness, &self.chol, rhs, COLUMN_REFINEMENT);
            let solved: Vec<Arc<[f64]>> = (0..chunk.len())
                .map(|j| {
                    (0..w)
                        .map(|k| {
                            self.joint
                                .row(3 * k + NORMAL)
                                .map(|(i, v)| v * x[(i, j)])
                                .sum::<f64>()
                        })
                        .collect()
                })
                .collect();
            // The tangential rows of the tangential columns (the stick correction's F_tt).
            let solved_t: Vec<Option<Arc<[f64]>>> = chunk
                .iter()
                .enumerate()
                .map(|(j, &r)| {
                    (r % 3 != NORMAL).then(|| {
                        (0..2 * w)
                            .map(|i| {
                                let row = 3 * (i / 2) + if i % 2 == 0 { T1 } else { T2 };
                                self.joint.row(row).map(|(c, v)| v * x[(c, j)]).sum::<f64>()
                            })
                            .collect()
                    })
                })
                .collect();
            let finite = |c: &[f64]| c.iter().all(|v| v.is_finite());
            if !solved.iter().all(|c| finite(c)) || !solved_t.iter().flatten().all(|c| finite(c)) {
                return Err(Error::LinearAlgebra(LinalgError::not_finite(
                    "joint flexibility K⁻¹ Bᵀ",
                )));
            }
            let mut cols = self.lock_columns();
            let mut tang = self.lock_tangential();
            for ((&r, col), t) in chunk.iter().zip(solved).zip(solved_t) {
                cols[r] = Some(col);
                if t.is_some() {
                    tang[r] = t;
                }
            }
        }
        let cols = self.lock_columns();
        Ok(rows
            .iter()
            .map(|&r| cols[r].clone().expect("solved above"))
            .collect())
    }

    /// Solves the normal flexibility columns not yet cached, [`PREFETCH_BLOCK`] at a time in
    /// pair order, until `stop` is set or all are cached; returns how many it solved. For a
    /// second core while a reduced run goes on: the estimate of a run whose contact is wrong
    /// (a Craig–Bampton ranking run) needs nearly every pair's column, and the columns are most
    /// of its cost on refined meshes. Stops within one block of `stop`.
    ///
    /// # Errors
    /// A column that is not finite.
    pub fn prefetch_normal_columns(&self, stop: &AtomicBool) -> Result<usize, Error> {
        let missing: Vec<usize> = {
            let cols = self.lock_columns();
            (0..self.pairs())
                .map(|k| 3 * k + NORMAL)
                .filter(|&r| cols[r].is_none())
                .collect()
        };
        let mut solved = 0;
        for block in missing.chunks(PREFETCH_BLOCK) {
            if stop.load(Ordering::Relaxed) {
                break;
            }
            self.columns(block)?;
            solved += block.len();
        }
        Ok(solved)
    }

    /// The normal flexibility columns `F_{n,k}` of `pairs` ([`JointFlexibility::columns`]).
    fn normal_columns(&self, pairs: &[usize]) -> Result<Vec<Arc<[f64]>>, Error> {
        let rows: Vec<usize> = pairs.iter().map(|&k| 3 * k + NORMAL).collect();
        self.columns(&rows)
    }

    /// `g_t = B_n K⁻¹ B_tᵀ p_t` (w × outputs): the gaps under the run's tangential forces, each
    /// column of `p` (3w × outputs) one output. Built from the tangential flexibility columns
    /// of the pairs that carry a tangential force at some output (solved once, cached).
    fn tangential_gaps(&self, p: MatRef<'_, f64>) -> Result<Mat<f64>, Error> {
        let w = self.pairs();
        let rows: Vec<usize> = (0..w)
            .flat_map(|k| [3 * k + T1, 3 * k + T2])
            .filter(|&r| (0..p.ncols()).any(|j| p[(r, j)] != 0.0))
            .collect();
        let cols = self.columns(&rows)?;
        let mut out = Mat::<f64>::zeros(w, p.ncols());
        for j in 0..p.ncols() {
            for (&r, col) in rows.iter().zip(&cols) {
                let pr = p[(r, j)];
                if pr != 0.0 {
                    for (o, f) in out.col_mut(j).iter_mut().zip(col.iter()) {
                        *o += f * pr;
                    }
                }
            }
        }
        Ok(out)
    }

    /// The attachment modes `K⁻¹ b_kᵀ` of the normal rows of `pairs` (n × |pairs|, mm/N): the
    /// static response of the structure to a unit normal force on each pair.
    pub(crate) fn attachment_modes(&self, pairs: &[usize]) -> Mat<f64> {
        let mut rhs = Mat::<f64>::zeros(self.stiffness.n, pairs.len());
        for (j, &k) in pairs.iter().enumerate() {
            for (i, v) in self.joint.row(3 * k + NORMAL) {
                rhs[(i, j)] += v;
            }
        }
        solve_refined_owned(&self.stiffness, &self.chol, rhs)
    }

    /// The tangential attachment modes `K⁻¹ B_{t,k}ᵀ d` of `pairs`, each with its direction `d`
    /// (a unit vector in the pair's (t1, t2) plane): n × |pairs|, mm/N — the static response of
    /// the structure to a unit friction force on the pair in that direction.
    pub fn tangential_attachment_modes(&self, pairs: &[(usize, [f64; 2])]) -> Mat<f64> {
        let mut rhs = Mat::<f64>::zeros(self.stiffness.n, pairs.len());
        for (j, &(k, d)) in pairs.iter().enumerate() {
            for (row, dk) in [(3 * k + T1, d[0]), (3 * k + T2, d[1])] {
                for (i, v) in self.joint.row(row) {
                    rhs[(i, j)] += dk * v;
                }
            }
        }
        solve_refined_owned(&self.stiffness, &self.chol, rhs)
    }

    /// The frictionless contact statics (the model's `k_n`) under the master load `load` (`[Fx, Fy, Fz (N), Mx, My,
    /// Mz (N·mm)]`) solved in the pair space, `g = H_n f_m − k_n F_{n,A} g_A`: the full model's
    /// solution condensed exactly to the pairs (module docs). Returns the normal pair forces
    /// `p_n = k_n min(g, 0)` (w values, N).
    pub fn static_contact_forces(&self, load: [f64; 6]) -> Result<Vec<f64>, Error> {
        let rows = 3 * self.pairs();
        let u: Vec<f64> = (0..rows)
            .map(|i| (0..6).map(|d| self.h[(i, d)] * load[d]).sum())
            .collect();
        let law = PairLaw {
            k_n: self.k_n,
            friction: false,
            mu: 0.0,
            k_t: 0.0,
            tau: 1.0,
        };
        let pc = Corrector::new(self, &law).correct(&u, &vec![0.0; rows], &[])?;
        Ok(pc.iter().step_by(3).copied().collect())
    }

    /// The estimator of a reduced model on the basis `phi` (n × r) of `model`: `G = B K⁻¹ M Φ`
    /// and `G_m = E_mᵀ K⁻¹ M Φ` from r refined solves, and the truncated modes beyond Φ.
    pub fn estimator<'a>(
        &'a self,
        model: &Model,
        rom: &ReducedSystem,
    ) -> Result<ErrorEstimator<'a>, Error> {
        self.estimator_with(model, rom, true)
    }

    /// [`JointFlexibility::estimator`], with the truncation part only if `truncation`: without
    /// it the estimate is the joint part alone ([`Estimate::truncation`] `None`), one correction
    /// per output instead of two and no truncated modes set up — for a run whose estimate only
    /// ranks the pairs (the tolerance model's first round).
    pub fn estimator_with<'a>(
        &'a self,
        model: &Model,
        rom: &ReducedSystem,
        truncation: bool,
    ) -> Result<ErrorEstimator<'a>, Error> {
        let phi = self.basis_of(rom)?;
        let m_phi = sym_mul_mat(&model.mass, phi.as_ref());
        let y = solve_refined_owned(&self.stiffness, &self.chol, m_phi);
        let truncation = if truncation {
            let modes = self.truncation_modes(model)?;
            Some(Truncation::new(
                model,
                phi.as_ref(),
                modes.as_ref().as_ref(),
            )?)
        } else {
            None
        };
        Ok(ErrorEstimator {
            flex: self,
            g: self.joint.reduce(y.as_ref()),
            g_m: Mat::from_fn(6, y.ncols(), |d, j| y[(self.master[d], j)]),
            truncation,
            rom: rom.clone(),
        })
    }

    /// Shares the model's fixed-interface problem (e.g. the one Craig–Bampton factored) for the
    /// truncated modes of the estimate: the same modes, bit for bit, without factoring `K_ii`
    /// again. A second call keeps the first.
    pub fn share_fixed_interface(&self, fixed: Arc<FixedInterface>) {
        let _ = self.fixed.set(fixed);
    }

    /// Holds at least `count` truncated modes from the next estimator on (the set only grows;
    /// [`truncated_modes_for`]).
    pub fn hold_truncation_modes(&self, count: usize) {
        self.held
            .fetch_max(count, std::sync::atomic::Ordering::Relaxed);
    }

    /// The lowest fixed-interface modes the estimate holds ([`TRUNCATION_MODES`], or more after
    /// [`JointFlexibility::hold_truncation_modes`]; n × m, zero at the master DOF), computed on
    /// first use: only the transient estimate needs them (not the pair-space statics), and its
    /// first use is on the second core beside a reduced run
    /// ([`crate::rom::estimate::run_estimated`]).
    pub(crate) fn truncation_modes(&self, model: &Model) -> Result<Arc<Mat<f64>>, Error> {
        // Not held while computing: the modes' solves may run on rayon's pool, and a worker
        // waiting there can take another estimator's job that wants this lock (the deadlock
        // class of `rom::estimate::beside`). Two estimators may both compute them: the
        // same bits, the first one kept.
        let slot = || {
            self.modes
                .lock()
                .unwrap_or_else(std::sync::PoisonError::into_inner)
        };
        let n = self.stiffness.n;
        let count = self
            .held
            .load(std::sync::atomic::Ordering::Relaxed)
            .min(n.saturating_sub(6) / 2);
        if let Some(m) = slot().as_ref().filter(|m| m.ncols() >= count) {
            return Ok(Arc::clone(m));
        }
        let modes = if count > 0 {
            let fixed = match self.fixed.get() {
                Some(shared) if shared.dofs() + 6 == n => shared.modes(count)?,
                _ => model.modes(count, Interface::Fixed)?,
            };
            let m = n - 6;
            Mat::from_fn(n, fixed.shapes.ncols(), |i, j| {
                if i < m {
                    fixed.shapes[(i, j)]
                } else {
                    0.0
                }
            })
        } else {
            Mat::zeros(n, 0)
        };
        let mut held = slot();
        match held.as_ref() {
            Some(m) if m.ncols() >= modes.ncols() => Ok(Arc::clone(m)),
            _ => Ok(Arc::clone(held.insert(Arc::new(modes)))),
        }
    }

    /// The basis Φ of `rom` if an estimator of it can be built on this flexibility: `rom`
    /// carries Φ, of this model's DOF and pairs.
    ///
    /// # Errors
    /// [`Error::Reduction`] saying which of these fails.
    pub(crate) fn basis_of<'r>(&self, rom: &'r ReducedSystem) -> Result<&'r Mat<f64>, Error> {
        let phi = rom
            .phi
            .as_ref()
            .ok_or_else(|| Error::Reduction(ReductionError::EstimateNoBasis))?;
        if phi.nrows() != self.stiffness.n || rom.pairs() != self.pairs() {
            return Err(ReductionError::EstimateBasis {
                basis: (phi.nrows(), phi.ncols()),
                basis_pairs: rom.pairs(),
                dofs: self.stiffness.n,
                pairs: self.pairs(),
            }
            .into());
        }
        Ok(phi)
    }
}

/// The estimator of one reduced model (module docs): the flexibility and `G`, `G_m`.
pub struct ErrorEstimator<'a> {
    flex: &'a JointFlexibility,
    /// `G = B K⁻¹ M Φ` (3w × r).
    g: Mat<f64>,
    /// `G_m = E_mᵀ K⁻¹ M Φ` (6 × r).
    g_m: Mat<f64>,
    /// The truncated modes (`None`: the estimate is the joint part alone).
    truncation: Option<Truncation>,
    rom: ReducedSystem,
}

/// The fixed-interface modes beyond a basis, M-orthogonalized against it and rotated to their
/// own eigenbasis: `Ψ` (n × m, `ΨᵀMΦ = 0`, `ΨᵀMΨ = I`, `ΨᵀKΨ = diag(ω²)`), kept as the
/// products the estimate needs.
struct Truncation {
    /// ω² per mode, (rad/s)².
    omega2: Vec<f64>,
    /// `B Ψ` (3w × m).
    b_psi: Mat<f64>,
    /// `Ψ` at the master DOF (6 × m).
    psi_m: Mat<f64>,
    /// `Ψᵀ K Φ` (m × r).
    psi_k_phi: Mat<f64>,
    /// The columns of `Ψ` by increasing frequency (n × m), for the truncation check's re-run.
    ordered: Mat<f64>,
}

impl Truncation {
    fn new(
        model: &Model,
        phi: MatRef<'_, f64>,
        modes: MatRef<'_, f64>,
    ) -> Result<Truncation, Error> {
        // Φ is M-orthonormal already: the modes are orthonormalized against it as it is.
        let (w, _) = orthonormal_beyond(phi, modes, &model.mass, 1e-6)?;
        let (psi, omega2) = if w.ncols() > 0 {
            let k2 = compensated_gram(&model.stiffness, w.as_ref());
            let evd = symmetric_eigen(k2.as_ref(), "truncation modes' eigenproblem")
                .map_err(Error::LinearAlgebra)?;
            (&w * &evd.vectors, evd.values)
        } else {
            (w, Vec::new())
        };
        if let Some(o) = omega2.iter().find(|o| !(o.is_finite() && **o > 0.0)) {
            return Err(Error::LinearAlgebra(LinalgError::EigenvalueNotPositive {
                what: "truncation modes",
                value: *o,
            }));
        }
        let master = model.master_dofs();
        let k_phi = sym_mul_mat(&model.stiffness, phi);
        let mut by_frequency: Vec<usize> = (0..omega2.len()).collect();
        by_frequency.sort_by(|&a, &b| omega2[a].total_cmp(&omega2[b]));
        Ok(Truncation {
            ordered: Mat::from_fn(psi.nrows(), by_frequency.len(), |i, j| {
                psi[(i, by_frequency[j])]
            }),
            b_psi: model.joint.reduce(psi.as_ref()),
            psi_m: Mat::from_fn(6, psi.ncols(), |d, j| psi[(master[d], j)]),
            psi_k_phi: psi.transpose() * &k_phi,
            omega2,
        })
    }

    /// The dynamic excess `Δ = η − ρ/ω²` of every truncated mode at every output (m × outputs):
    /// `η̈ + ω² η = ρ(t)` from rest, `ρ = Ψᵀ (f − M Φ q̈ − K Φ q − Bᵀ p)`, with ρ linear between
    /// outputs (then Δ is a free oscillation within each interval, and its rate jumps by
    /// `−Δρ̇/ω²` where the slope of ρ changes: exact for piecewise-linear ρ).
    fn excess(
        &self,
        t: &[f64],
        load: &Mat<f64>,
        q: MatRef<'_, f64>,
        p: MatRef<'_, f64>,
    ) -> Mat<f64> {
        let m = self.omega2.len();
        let outputs = t.len();
        let rho = self.psi_m.transpose() * load - &self.psi_k_phi * q - self.b_psi.transpose() * p;
        let mut out = Mat::<f64>::zeros(m, outputs);
        // The outputs are nearly equally spaced: their steps take a few distinct values (in
        // the last bits), so each mode's rotation is computed once per distinct step.
        let mut distinct: Vec<f64> = Vec::new();
        let mut index = std::collections::HashMap::new();
        let step_of: Vec<usize> = (0..outputs.saturating_sub(1))
            .map(|j| {
                let h = t[j + 1] - t[j];
                *index.entry(h.to_bits()).or_insert_with(|| {
                    distinct.push(h);
                    distinct.len() - 1
                })
            })
            .collect();
        let mut rotation = vec![(0.0, 1.0); distinct.len()];
        for i in 0..m {
            let w2 = self.omega2[i];
            let w = w2.sqrt();
            for (r, h) in rotation.iter_mut().zip(&distinct) {
                *r = (w * h).sin_cos();
            }
            let mut d = -rho[(i, 0)] / w2;
            let mut slope_prev = 0.0;
            let mut rate = 0.0;
            out[(i, 0)] = d;
            for j in 0..outputs.saturating_sub(1) {
                let h = t[j + 1] - t[j];
                let (sn, cs) = rotation[step_of[j]];
                let slope = if h > 0.0 {
                    (rho[(i, j + 1)] - rho[(i, j)]) / h
                } else {
                    0.0
                };
                rate -= (slope - slope_prev) / w2;
                slope_prev = slope;
                let d_next = d * cs + rate / w * sn;
                rate = -d * w * sn + rate * cs;
                d = d_next;
                out[(i, j + 1)] = d;
            }
        }
        out
    }
}

/// The states of a reduced run at its output times, each block stored output after output
/// (as [`crate::integrate::Trajectory`] records them).
#[derive(Clone, Copy, Debug)]
pub struct RunStates<'a> {
    /// Output times, s.
    pub t: &'a [f64],
    /// Reduced coordinates (r per output).
    pub q: &'a [f64],
    /// Pair forces (3w per output: normal, t1, t2), N.
    pub p: &'a [f64],
    /// Slip memory (2w per output with friction, else empty), mm.
    pub s: &'a [f64],
}

/// A quantity a run reports and `--tolerance` can control: ‖f_c‖(t), ‖f_R‖(t), the master's
/// u_y(t) or the joint's dissipated energy D(t).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Quantity {
    /// ‖f_c‖(t), the norm of the normal contact forces (`fc`).
    ContactForce,
    /// ‖f_R‖(t), the norm of the tangential (friction) forces (`fr`).
    FrictionForce,
    /// The master node's u_y(t) (`uy`).
    MasterUy,
    /// The joint's dissipated energy D(t) (`dissipation`): relative L2 over the run and
    /// relative error at its end.
    Dissipation,
}

impl Quantity {
    /// Every quantity, in the order of the outputs.
    pub const ALL: [Quantity; 4] = [
        Quantity::ContactForce,
        Quantity::FrictionForce,
        Quantity::MasterUy,
        Quantity::Dissipation,
    ];

    /// The short name of `--tolerance-on`: `fc`, `fr`, `uy`, `dissipation`.
    pub fn name(self) -> &'static str {
        match self {
            Quantity::ContactForce => "fc",
            Quantity::FrictionForce => "fr",
            Quantity::MasterUy => "uy",
            Quantity::Dissipation => "dissipation",
        }
    }

    /// The quantity of a short name ([`Quantity::name`]).
    pub fn from_name(name: &str) -> Option<Quantity> {
        Quantity::ALL.into_iter().find(|q| q.name() == name)
    }

    /// Whether a run produces it: ‖f_R‖ and D need friction.
    pub fn needs_friction(self) -> bool {
        matches!(self, Quantity::FrictionForce | Quantity::Dissipation)
    }
}

/// A set of [`Quantity`]s: what `--tolerance` controls (`--tolerance-on`). Serialized as the
/// list of their names.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Quantities(u8);

impl Quantities {
    /// All four quantities (the default of `--tolerance`).
    pub const ALL: Quantities = Quantities(0b1111);

    /// The set of `list`.
    pub fn of(list: &[Quantity]) -> Quantities {
        Quantities(list.iter().fold(0, |m, &q| m | 1 << q as u8))
    }

    /// Whether `q` is in the set.
    pub fn contains(self, q: Quantity) -> bool {
        self.0 & 1 << q as u8 != 0
    }

    /// The quantities of the set, in [`Quantity::ALL`]'s order.
    pub fn iter(self) -> impl Iterator<Item = Quantity> {
        Quantity::ALL.into_iter().filter(move |&q| self.contains(q))
    }

    /// The set without the quantities that need friction.
    pub fn without_friction(self) -> Quantities {
        Quantities::of(
            &self
                .iter()
                .filter(|q| !q.needs_friction())
                .collect::<Vec<_>>(),
        )
    }

    /// Whether the set is empty.
    pub fn is_empty(self) -> bool {
        self.0 == 0
    }
}

impl serde::Serialize for Quantities {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq(self.iter().map(Quantity::name))
    }
}

/// Relative L2 errors over a run's output times of its headline curves (and the error of the
/// dissipated energy at the end).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct CurveErrors {
    /// ‖f_c‖(t) (`None`: no contact force in the reference curve).
    pub contact_force: Option<f64>,
    /// ‖f_R‖(t) (`None`: friction off or no friction force).
    pub friction_force: Option<f64>,
    /// Master u_y(t).
    pub master_uy: Option<f64>,
    /// The joint's dissipated energy D(t) (`None`: friction off or nothing dissipated).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub dissipated: Option<f64>,
    /// D at the end of the run: `|D(T) − D_ref(T)| / |D_ref(T)|` (`None` as for `dissipated`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub dissipated_end: Option<f64>,
}

impl CurveErrors {
    /// The error of `quantity` (its relative L2 over the run; for D the larger of that and the
    /// error at the end).
    pub fn of(&self, quantity: Quantity) -> Option<f64> {
        match quantity {
            Quantity::ContactForce => self.contact_force,
            Quantity::FrictionForce => self.friction_force,
            Quantity::MasterUy => self.master_uy,
            Quantity::Dissipation => match (self.dissipated, self.dissipated_end) {
                (None, None) => None,
                (a, b) => Some(a.unwrap_or(0.0).max(b.unwrap_or(0.0))),
            },
        }
    }

    /// The root sum of squares of two independent error estimates, per curve (a missing one
    /// counts as zero; both missing stays `None`).
    pub fn combine(&self, other: &CurveErrors) -> CurveErrors {
        let rss = |a: Option<f64>, b: Option<f64>| match (a, b) {
            (None, None) => None,
            (a, b) => Some(a.unwrap_or(0.0).hypot(b.unwrap_or(0.0))),
        };
        CurveErrors {
            contact_force: rss(self.contact_force, other.contact_force),
            friction_force: rss(self.friction_force, other.friction_force),
            master_uy: rss(self.master_uy, other.master_uy),
            dissipated: rss(self.dissipated, other.dissipated),
            dissipated_end: rss(self.dissipated_end, other.dissipated_end),
        }
    }
}

/// The estimated reduction errors of a reduced run and the corrected curves they come from.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Estimate {
    /// Estimated relative L2 errors of the reduced curves against the corrected ones.
    pub errors: CurveErrors,
    /// The joint part of the ‖f_c‖(t) estimate: the run against the correction without the
    /// truncated modes' dynamics (what more pair attachment modes can remove).
    pub joint: Option<f64>,
    /// The truncation part: the correction with the truncated modes' dynamics against the one
    /// without, relative L2 of ‖f_c‖(t) (what more fixed-interface modes can remove).
    pub truncation: Option<f64>,
    /// `Σ_t ‖p_n*(t)‖²` of the joint-only correction, N² (the scale of [`Estimate::pair_error`]).
    pub corrected_joint_norm2: f64,
    /// `Σ_t ‖p_t*‖²` of the joint-only correction, N² (the scale of
    /// [`Estimate::pair_tangential_error`]).
    pub corrected_joint_friction_norm2: f64,
    /// The corrected ‖f_c*‖(t), N.
    pub corrected_contact_force: Vec<f64>,
    /// The corrected ‖f_R*‖(t), N.
    pub corrected_friction_force: Vec<f64>,
    /// The corrected master u_y*(t), mm.
    pub corrected_master_uy: Vec<f64>,
    /// Per pair, `Σ_t (p_{n,k}(t) − p_{n,k}*(t))²` (N²) with the joint-only correction: where
    /// the reduced run's normal forces differ from the corrected ones.
    pub pair_error: Vec<f64>,
    /// The joint part of the ‖f_R‖(t) estimate (the run against the joint-only correction;
    /// `None` without friction).
    pub joint_friction: Option<f64>,
    /// Per pair, `Σ_t |p_{t,k}(t) − p_{t,k}*(t)|²` (N²) with the joint-only correction: where
    /// the reduced run's tangential forces differ from the corrected ones.
    pub pair_tangential_error: Vec<f64>,
    /// Per pair, the part of [`Estimate::pair_tangential_error`] from the outputs at which the
    /// run sticks the pair (closed, its friction force inside its cone), N²: the error of its
    /// stick force, an elastic stretch that the structure's tangential compliance at the pair
    /// sets. At the other outputs the correction puts the pair on its corrected cone
    /// `μ|p_n*|` in the run's direction (or opens or closes it), so the error there is its
    /// normal force's.
    pub pair_stick_error: Vec<f64>,
    /// Per pair, the moments `Σ_t [p_1², p_1 p_2, p_2²]` (N²) of the tangential forces of the
    /// run and of the joint-only correction: their principal direction is the pair's main
    /// direction of friction.
    pub pair_tangential_moment: Vec<[f64; 3]>,
    /// The corrected dissipated energy D*(t) from the joint-only correction's output states
    /// (module docs, "Friction"), N·mm (empty without friction).
    pub corrected_dissipated: Vec<f64>,
    /// Per pair, `Σ_t (D_k(t) − D_k*(t))²` (N²·mm²): where the run's dissipated energy differs
    /// from the joint-only correction's, pair by pair (empty without friction). `D − D* = Σ_k (D_k − D_k*)`,
    /// so the pairs' shares bound the error of D by their sum (not in quadrature).
    pub pair_dissipation_error: Vec<f64>,
    /// Per pair, `D_k(T) − D_k*(T)` at the last output (N·mm; empty without friction).
    pub pair_dissipation_end: Vec<f64>,
    /// The corrected pair forces of every output, sparse: per output the pairs with a nonzero
    /// corrected force and their `[p_n*, p_t1*, p_t2*]`, N (the snapshots of the joint's
    /// deformation patterns, [`crate::reduction::joint_pod()`]).
    pub corrected_pair_forces: Vec<Vec<(usize, [f64; 3])>>,
}

impl Estimate {
    /// Adds one output's per-pair shares (the run's forces `p`, the correction's `pc`, the
    /// joint-only correction's `pj`; `mu` the friction coefficient, which tells the pairs the
    /// run sticks) and returns its squared norms `[‖p_n*‖², ‖p_t*‖², ‖p_n‖², ‖p_t‖², ‖p_n^j‖²,
    /// ‖p_t^j‖²]`.
    fn add_output(&mut self, p: &[f64], pc: &[f64], pj: &[f64], mu: f64) -> [f64; 6] {
        let mut sums = [0.0; 6];
        let sq = |v: &[f64], k: usize| {
            [
                v[3 * k + NORMAL].powi(2),
                v[3 * k + T1].powi(2) + v[3 * k + T2].powi(2),
            ]
        };
        let forces = (0..self.pair_error.len())
            .filter_map(|k| {
                let f = [pc[3 * k + NORMAL], pc[3 * k + T1], pc[3 * k + T2]];
                (f != [0.0; 3]).then_some((k, f))
            })
            .collect();
        self.corrected_pair_forces.push(forces);
        for k in 0..self.pair_error.len() {
            let (a1, a2) = (pj[3 * k + T1], pj[3 * k + T2]);
            let e = (a1 - p[3 * k + T1]).powi(2) + (a2 - p[3 * k + T2]).powi(2);
            self.pair_tangential_error[k] += e;
            // Stuck in the run: closed, inside its cone (the correction's sliding test).
            let cone = mu * p[3 * k + NORMAL].abs();
            if cone > 0.0 && p[3 * k + T1].hypot(p[3 * k + T2]) < (1.0 - 1e-9) * cone {
                self.pair_stick_error[k] += e;
            }
            let m = &mut self.pair_tangential_moment[k];
            for (b1, b2) in [(a1, a2), (p[3 * k + T1], p[3 * k + T2])] {
                m[0] += b1 * b1;
                m[1] += b1 * b2;
                m[2] += b2 * b2;
            }
            self.pair_error[k] += (pj[3 * k + NORMAL] - p[3 * k + NORMAL]).powi(2);
            for (i, v) in [sq(pc, k), sq(p, k), sq(pj, k)]
                .iter()
                .flatten()
                .enumerate()
            {
                sums[i] += v;
            }
        }
        sums
    }
}

/// One output's run forces `p` (3w), corrected forces `pc` (3w), the run's slip memory `s` (2w)
/// and the corrected state's slip (2w), mm and N.
struct OutputState {
    p: Vec<f64>,
    pc: Vec<f64>,
    s: Vec<f64>,
    slip: Vec<f64>,
}

/// The joint's dissipated energy `D(t) = ∫ p_t · ṡ dt` of the run and of the joint-only
/// correction, by the trapezoidal rule over the output states, each with its own forces and slip
/// (the run's memory, the corrected state's `s*`; module docs, "Friction").
#[derive(Default)]
struct Dissipation {
    /// The run's D at each output so far, N·mm.
    run: Vec<f64>,
    /// The correction's D*, N·mm.
    corrected: Vec<f64>,
    /// The last output's forces and slips.
    last: Option<OutputState>,
    /// Per pair, the run's and the correction's D so far, N·mm.
    pair_run: Vec<f64>,
    pair_corrected: Vec<f64>,
    /// Per pair, `Σ_t (D_k − D_k*)²` over the outputs so far, N²·mm².
    pair_error: Vec<f64>,
}

impl Dissipation {
    fn push(&mut self, p: &[f64], pc: &[f64], s: &[f64], slip: &[f64]) {
        let (mut d, mut dc) = (
            self.run.last().copied().unwrap_or(0.0),
            self.corrected.last().copied().unwrap_or(0.0),
        );
        if let Some(OutputState {
            p: p0,
            pc: pc0,
            s: s0,
            slip: slip0,
        }) = &self.last
        {
            for i in 0..s.len() {
                let r = 3 * (i / 2) + 1 + i % 2;
                let n = 3 * (i / 2) + NORMAL;
                // Each state over the intervals its own pair is closed at both ends (an open
                // pair's memory relaxes to its tangential displacement without dissipating),
                // each with its own slip: the run's memory, the corrected state's.
                let ds = s[i] - s0[i];
                if ds != 0.0 && p[n] != 0.0 && p0[n] != 0.0 {
                    let e = 0.5 * (p[r] + p0[r]) * ds;
                    d += e;
                    self.pair_run[i / 2] += e;
                }
                let ds = slip[i] - slip0[i];
                if ds != 0.0 && pc[n] != 0.0 && pc0[n] != 0.0 && ds.is_finite() {
                    let e = 0.5 * (pc[r] + pc0[r]) * ds;
                    dc += e;
                    self.pair_corrected[i / 2] += e;
                }
            }
        } else {
            let w = s.len() / 2;
            self.pair_run = vec![0.0; w];
            self.pair_corrected = vec![0.0; w];
            self.pair_error = vec![0.0; w];
        }
        for ((e, a), b) in self
            .pair_error
            .iter_mut()
            .zip(&self.pair_run)
            .zip(&self.pair_corrected)
        {
            *e += (a - b).powi(2);
        }
        self.run.push(d);
        self.corrected.push(dc);
        // The last state's buffers are reused: four copies per output, no allocation.
        let last = self.last.get_or_insert_with(|| OutputState {
            p: Vec::new(),
            pc: Vec::new(),
            s: Vec::new(),
            slip: Vec::new(),
        });
        for (to, from) in [
            (&mut last.p, p),
            (&mut last.pc, pc),
            (&mut last.s, s),
            (&mut last.slip, slip),
        ] {
            to.clear();
            to.extend_from_slice(from);
        }
    }

    /// `|D(T) − D*(T)| / |D*(T)|` (`None` when nothing is dissipated).
    fn end_error(&self) -> Option<f64> {
        let (d, dc) = (*self.run.last()?, *self.corrected.last()?);
        (dc != 0.0).then(|| (d - dc).abs() / dc.abs())
    }
}

impl ErrorEstimator<'_> {
    /// The basis of the truncation check (module docs, "Truncation"): this estimator's Φ and
    /// every truncated mode it holds — the [`TRUNCATION_MODES`] lowest fixed-interface modes
    /// beyond Φ, M-orthogonal to it, by increasing frequency (n × (r + m); `None` when no mode
    /// is beyond Φ). A re-run on it shows what those modes change of the run, the back-coupling
    /// through the pair forces into the global motion included, which the quasi-static
    /// correction does not see. All of them, not only the next step of ν: the modes that carry
    /// a scene's error need not be the next ones (the lap joint's dissipated energy at ν = 10
    /// is changed little by modes 11–20 and mostly by 21–30).
    pub fn truncation_check_basis(&self) -> Option<Mat<f64>> {
        let extra = &self.truncation.as_ref()?.ordered;
        let phi = self.rom.phi.as_ref()?;
        (extra.ncols() > 0).then(|| {
            Mat::from_fn(phi.nrows(), phi.ncols() + extra.ncols(), |i, j| {
                if j < phi.ncols() {
                    phi[(i, j)]
                } else {
                    extra[(i, j - phi.ncols())]
                }
            })
        })
    }

    /// The estimate of a run of this estimator's reduced model under the law `law` (its
    /// friction switch says whether `states.s` holds a slip memory).
    pub fn estimate(&self, law: &PairLaw, states: RunStates<'_>) -> Result<Estimate, Error> {
        let r = self.rom.dim();
        let w = self.flex.pairs();
        let outputs = states.t.len();
        let ns = if law.friction { 2 * w } else { 0 };
        if states.q.len() != outputs * r
            || states.p.len() != outputs * 3 * w
            || states.s.len() != outputs * ns
        {
            return Err(ReductionError::EstimateStates { outputs, r, w }.into());
        }
        let qdd = self.accelerations(states)?;
        let load = Mat::from_fn(6, outputs, |d, j| self.rom.load.master_at(states.t[j])[d]);
        // The dynamic excess of the truncated modes (module docs, "Truncation") and the master
        // kinematics for every output at once (small: modes × outputs, 6 × outputs).
        let q_all = MatRef::from_column_major_slice(states.q, r, outputs);
        let p_all = MatRef::from_column_major_slice(states.p, 3 * w, outputs);
        let mut x_hat = &self.flex.c * &load - &self.g_m * &qdd;
        let excess = self.truncation.as_ref().map(|tr| {
            let excess = tr.excess(states.t, &load, q_all, p_all);
            x_hat += &tr.psi_m * &excess;
            excess
        });
        let mut out = Estimate {
            pair_error: vec![0.0; w],
            ..Default::default()
        };
        // ‖p_n*‖, ‖p_t*‖, u_y* and the run's ‖p_n‖, ‖p_t‖, u_y per output.
        let mut curves: [Vec<f64>; 6] = Default::default();
        let mut fc_joint = Vec::with_capacity(outputs);
        let mut fr_joint = Vec::with_capacity(outputs);
        out.pair_tangential_error = vec![0.0; w];
        out.pair_stick_error = vec![0.0; w];
        out.pair_tangential_moment = vec![[0.0; 3]; w];
        let mut dissipation = Dissipation::default();
        let mut corr = Corrector::new(self.flex, law);
        let mut corr_joint = Corrector::new(self.flex, law);
        // D is summed from the joint part's states (module docs, "Friction"): the full
        // correction's slip is not wanted.
        corr.want_slip = false;
        let at = |j: usize| {
            move |e: Error| match e {
                Error::LinearAlgebra(source) => Error::LinearAlgebra(LinalgError::EstimateAt {
                    time: states.t[j],
                    source: Box::new(source),
                }),
                e => e,
            }
        };
        // The pair kinematics go chunk by chunk of outputs (3w × chunk at a time): û = H f_m −
        // G q̈ − F_{·,t} p_t, plus the truncated modes' excess for the full correction.
        for first in (0..outputs).step_by(SOLVE_CHUNK) {
            let cols = SOLVE_CHUNK.min(outputs - first);
            let mut u_joint =
                &self.flex.h * load.subcols(first, cols) - &self.g * qdd.subcols(first, cols);
            if law.friction {
                let g_t = self.flex.tangential_gaps(p_all.subcols(first, cols))?;
                for c in 0..cols {
                    for k in 0..w {
                        u_joint[(3 * k + NORMAL, c)] -= g_t[(k, c)];
                    }
                }
            }
            // The two corrections are independent sequences over the outputs (each warm-starts
            // from its own previous active set): one per core, the same bits as one after the
            // other.
            #[allow(clippy::type_complexity)]
            let series = |corr: &mut Corrector<'_>,
                          u: &Mat<f64>|
             -> Result<Vec<(Vec<f64>, Vec<f64>)>, Error> {
                (0..cols)
                    .map(|c| {
                        let j = first + c;
                        let u: Vec<f64> = u.col(c).iter().copied().collect();
                        let pc = corr
                            .correct(
                                &u,
                                &states.p[3 * w * j..3 * w * (j + 1)],
                                &states.s[ns * j..ns * (j + 1)],
                            )
                            .map_err(at(j))?;
                        Ok((pc, std::mem::take(&mut corr.slip)))
                    })
                    .collect()
            };
            // The joint part alone (no truncated-mode dynamics) ranks the pairs; without
            // truncated modes it is the whole correction.
            let (full, joint) = match (&self.truncation, &excess) {
                (Some(tr), Some(excess)) => {
                    let u_hat = &u_joint + &tr.b_psi * excess.subcols(first, cols);
                    let (full, joint) = rayon::join(
                        || series(&mut corr, &u_hat),
                        || series(&mut corr_joint, &u_joint),
                    );
                    (Some(full?), joint?)
                }
                _ => (None, series(&mut corr_joint, &u_joint)?),
            };
            for (c, (pj, slip_j)) in joint.iter().enumerate() {
                let j = first + c;
                let pc = full.as_ref().map_or(pj, |f| &f[c].0);
                let p = &states.p[3 * w * j..3 * w * (j + 1)];
                if law.friction {
                    dissipation.push(p, pj, &states.s[ns * j..ns * (j + 1)], slip_j);
                }
                let [fc, fr, fc_rom, fr_rom, fcj, frj] = out.add_output(p, pc, pj, law.mu);
                fc_joint.push(fcj.sqrt());
                fr_joint.push(frj.sqrt());
                // x_m* = C f_m − G_m q̈ − Hᵀ p* (the tangential part of p* as in the gaps: the
                // run's).
                let mut uy = x_hat[(1, j)];
                for (i, pi) in pc.iter().enumerate() {
                    let load = if i % 3 == NORMAL { *pi } else { p[i] };
                    uy -= self.flex.h[(i, 1)] * load;
                }
                let q = &states.q[r * j..r * (j + 1)];
                let uy_rom = self.rom.master_displacement(q)[1];
                let values = [
                    fc.sqrt(),
                    fr.sqrt(),
                    uy,
                    fc_rom.sqrt(),
                    fr_rom.sqrt(),
                    uy_rom,
                ];
                for (c, v) in curves.iter_mut().zip(values) {
                    c.push(v);
                }
            }
        }
        Ok(finish_estimate(
            out,
            curves,
            [fc_joint, fr_joint],
            dissipation,
            law.friction,
            self.truncation.is_some(),
        ))
    }

    /// `q̈ = M̃⁻¹ (Φᵀ f(t) − K̃ q − (BΦ)ᵀ p)` at every output (r × outputs).
    fn accelerations(&self, states: RunStates<'_>) -> Result<Mat<f64>, Error> {
        let r = self.rom.dim();
        let rows = 3 * self.flex.pairs();
        let mut rom = self.rom.clone();
        let mut acc = Mat::<f64>::zeros(r, states.t.len());
        let mut rhs = vec![0.0; r];
        let mut kq = vec![0.0; r];
        let mut neg_p = vec![0.0; rows];
        for (j, &t) in states.t.iter().enumerate() {
            let q = &states.q[r * j..r * (j + 1)];
            rom.load_into(t, &mut rhs);
            rom.mul_k_into(q, &mut kq);
            for (o, pv) in neg_p.iter_mut().zip(&states.p[rows * j..rows * (j + 1)]) {
                *o = -pv;
            }
            for (o, k) in rhs.iter_mut().zip(&kq) {
                *o -= k;
            }
            rom.joint_transpose_add(&neg_p, &mut rhs);
            rom.solve_m_in_place(&mut rhs);
            if let Some(v) = rhs.iter().find(|v| !v.is_finite()) {
                return Err(ReductionError::EstimateAcceleration { t, value: *v }.into());
            }
            for (i, v) in rhs.iter().enumerate() {
                acc[(i, j)] = *v;
            }
        }
        Ok(acc)
    }
}

/// The estimate's curve errors from its per-output curves (`[‖p_n*‖, ‖p_t*‖, u_y*, ‖p_n‖, ‖p_t‖,
/// u_y]`, the joint-only correction's `[‖p_n‖, ‖p_t‖]` and the dissipated energies), written into
/// `out` with the per-pair shares it holds; the truncation part only if the estimate has one.
fn finish_estimate(
    mut out: Estimate,
    curves: [Vec<f64>; 6],
    [fc_joint, fr_joint]: [Vec<f64>; 2],
    dissipation: Dissipation,
    friction: bool,
    truncation: bool,
) -> Estimate {
    let [fc, fr, uy, fc_rom, fr_rom, uy_rom] = curves;
    out.joint = relative_l2(&fc_rom, &fc_joint);
    out.joint_friction = if friction {
        relative_l2(&fr_rom, &fr_joint)
    } else {
        None
    };
    out.truncation = truncation.then(|| relative_l2(&fc_joint, &fc)).flatten();
    out.corrected_joint_norm2 = fc_joint.iter().map(|v| v * v).sum();
    out.corrected_joint_friction_norm2 = fr_joint.iter().map(|v| v * v).sum();
    out.errors = CurveErrors {
        contact_force: relative_l2(&fc_rom, &fc),
        friction_force: if friction {
            relative_l2(&fr_rom, &fr)
        } else {
            None
        },
        master_uy: relative_l2(&uy_rom, &uy),
        dissipated: friction
            .then(|| relative_l2(&dissipation.run, &dissipation.corrected))
            .flatten(),
        dissipated_end: friction.then(|| dissipation.end_error()).flatten(),
    };
    out.pair_dissipation_end = dissipation
        .pair_run
        .iter()
        .zip(&dissipation.pair_corrected)
        .map(|(a, b)| a - b)
        .collect();
    out.pair_dissipation_error = dissipation.pair_error;
    out.corrected_dissipated = dissipation.corrected;
    out.corrected_contact_force = fc;
    out.corrected_friction_force = fr;
    out.corrected_master_uy = uy;
    out
}

/// The per-output pair-space correction (module docs). Consecutive outputs mostly share their
/// active set, so each solve starts from the previous output's set and reuses its factor of
/// `I + k_n F_AA` while the set is unchanged.
struct Corrector<'a> {
    flex: &'a JointFlexibility,
    law: &'a PairLaw,
    w: usize,
    /// The converged active set of the last output.
    active: Vec<bool>,
    /// The Cholesky factor of `I + k_n F_AA` for the set last solved, updated as the set
    /// changes ([`SubsetLlt`]: a few pairs in or out cost O(|A|²) each, not |A|³/3).
    factor: SubsetLlt,
    /// The Cholesky factor of `I + k_t F_SS` for the tangential rows of the sticking pairs S
    /// last solved ([`Corrector::tangential`]).
    stick_factor: SubsetLlt,
    /// The flexibility columns of the pairs met so far (w entries, `None` before).
    cols: Vec<Option<Arc<[f64]>>>,
    /// The tangential flexibility columns met so far, per joint row (3w entries, `None` before
    /// and for normal rows): the column's normal rows and tangential rows
    /// ([`JointFlexibility::tangential_columns`]), fetched once per correction sequence instead
    /// of from the shared cache (its lock) at every output.
    tcols: Vec<Option<TangentialColumn>>,
    /// Working arrays of one output, kept between outputs (no allocation per output).
    scratch: Scratch,
    /// The run's slip memory at the previous output (2w, mm; empty before the first).
    last_s: Vec<f64>,
    /// The slip memory of the last corrected state (2w, mm; NaN for open pairs; empty
    /// without friction or without `want_slip`): [`Corrector::corrected_slip`].
    slip: Vec<f64>,
    /// Whether the corrected slip is wanted (the dissipated energy is summed from this
    /// correction's states).
    want_slip: bool,
}

/// A tangential flexibility column: its normal rows (w) and tangential rows (2w), mm/N.
type TangentialColumn = (Arc<[f64]>, Arc<[f64]>);

/// Fills the entries of `cache` at `keys` that are still empty by one `solve` of those keys
/// (blocked: one call for all of them).
fn fetch_missing<T>(
    cache: &mut [Option<T>],
    keys: &[usize],
    solve: impl FnOnce(&[usize]) -> Result<Vec<T>, Error>,
) -> Result<(), Error> {
    let missing: Vec<usize> = keys
        .iter()
        .copied()
        .filter(|&k| cache[k].is_none())
        .collect();
    if !missing.is_empty() {
        for (&k, c) in missing.iter().zip(solve(&missing)?) {
            cache[k] = Some(c);
        }
    }
    Ok(())
}

/// The working arrays of [`Corrector::correct`] (their contents do not outlive one output).
#[derive(Default)]
struct Scratch {
    /// ĝ (w), the gaps (w), the active set as a list and the next active set (w).
    g_hat: Vec<f64>,
    gaps: Vec<f64>,
    set: Vec<usize>,
    next: Vec<bool>,
    /// The stuck pairs (w), the tangential rows of the closed pairs, those of them that move
    /// and the closed pairs.
    is_stuck: Vec<bool>,
    rows: Vec<usize>,
    moving: Vec<usize>,
    closed: Vec<usize>,
}

/// Active-set iterations per output before the projected Gauss–Seidel fallback.
const MAX_ACTIVE_SET_ITERATIONS: usize = 100;

/// A pair outside the active set joins it in one iteration only if its penetration is at least
/// this fraction of the deepest one outside ([`next_active_set`]).
const JOIN_FRACTION: f64 = 0.5;

/// The next active set of the semismooth Newton iteration: the pairs of `active` whose gap is
/// still negative, and of the penetrating pairs outside it only the deepest (gap ≤
/// [`JOIN_FRACTION`] × the most negative gap outside). The plain rule `{g < 0}` would take
/// every pair that the structure without contact forces penetrates — on a refined mesh most of
/// the interface, each pair a flexibility column (a sparse solve) — while the contact forces of
/// the deepest few open most of the others. The fixed point is the same (no pair outside with
/// `g < 0`, none inside with `g ≥ 0`), so the solution is; it takes a few more, cheap, iterations.
fn next_active_set(active: &[bool], gaps: &[f64]) -> Vec<bool> {
    let mut next = Vec::with_capacity(active.len());
    next_active_set_into(active, gaps, &mut next);
    next
}

/// [`next_active_set`] written into `next`.
fn next_active_set_into(active: &[bool], gaps: &[f64], next: &mut Vec<bool>) {
    let deepest = gaps
        .iter()
        .zip(active)
        .filter(|(_, &a)| !a)
        .map(|(&g, _)| g)
        .fold(0.0f64, f64::min);
    next.clear();
    next.extend(
        gaps.iter()
            .zip(active)
            .map(|(&g, &a)| g < 0.0 && (a || g <= JOIN_FRACTION * deepest)),
    );
}

impl<'a> Corrector<'a> {
    fn new(flex: &'a JointFlexibility, law: &'a PairLaw) -> Corrector<'a> {
        Corrector {
            flex,
            law,
            w: flex.pairs(),
            active: vec![false; flex.pairs()],
            factor: SubsetLlt::new(),
            stick_factor: SubsetLlt::new(),
            cols: vec![None; flex.pairs()],
            tcols: vec![None; 3 * flex.pairs()],
            scratch: Scratch::default(),
            last_s: Vec::new(),
            slip: Vec::new(),
            want_slip: true,
        }
    }

    /// The gaps `g = ĝ − k_n F_{n,A} g_A` with `(I + k_n F_AA) g_A = ĝ_A` for the active set
    /// `set`.
    fn gaps(&mut self, set: &[usize], g_hat: &[f64], gaps: &mut [f64]) -> Result<(), Error> {
        let k_n = self.law.k_n;
        gaps.copy_from_slice(g_hat);
        if set.is_empty() {
            return Ok(());
        }
        let flex = self.flex;
        fetch_missing(&mut self.cols, set, |keys| flex.normal_columns(keys))?;
        let cols = &self.cols;
        let col = |k: usize| cols[k].as_deref().expect("fetched above");
        self.factor
            .update(set, |i, j| {
                let d = if i == j { 1.0 } else { 0.0 };
                d + k_n * 0.5 * (col(j)[i] + col(i)[j])
            })
            .map_err(|e| {
                Error::LinearAlgebra(LinalgError::ContactMatrix {
                    pairs: set.len(),
                    source: Box::new(e),
                })
            })?;
        let order = self.factor.order();
        let mut g_a: Vec<f64> = order.iter().map(|&k| g_hat[k]).collect();
        self.factor.solve_in_place(&mut g_a);
        for (&k, ga) in order.iter().zip(&g_a) {
            let s = k_n * ga;
            for (gk, fk) in gaps.iter_mut().zip(col(k).iter()) {
                *gk -= s * fk;
            }
        }
        Ok(())
    }

    /// Fetches the tangential flexibility columns of the joint rows `rows` not met yet into
    /// `tcols`.
    fn fetch_tangential(&mut self, rows: &[usize]) -> Result<(), Error> {
        let flex = self.flex;
        fetch_missing(&mut self.tcols, rows, |keys| flex.tangential_columns(keys))
    }

    /// The corrected pair forces `p*` (3w) from the pair kinematics `u0 = û − F_{·,t} p_t`
    /// (with the run's tangential forces as loads) and the run's forces `p`.
    fn correct(&mut self, u0: &[f64], p: &[f64], s: &[f64]) -> Result<Vec<f64>, Error> {
        let w = self.w;
        let k_n = self.law.k_n;
        let mut g_hat = std::mem::take(&mut self.scratch.g_hat);
        g_hat.clear();
        g_hat.extend((0..w).map(|k| u0[3 * k + NORMAL]));
        let nrm = |k: usize| 3 * k + NORMAL;
        // Semismooth Newton on the active set (see `crate::joint::statics`), warm-started.
        let mut active = std::mem::take(&mut self.active);
        let mut gaps = std::mem::take(&mut self.scratch.gaps);
        gaps.resize(w, 0.0);
        let mut set = std::mem::take(&mut self.scratch.set);
        let mut next = std::mem::take(&mut self.scratch.next);
        let mut converged = false;
        for _ in 0..MAX_ACTIVE_SET_ITERATIONS {
            set.clear();
            set.extend((0..w).filter(|&k| active[k]));
            self.gaps(&set, &g_hat, &mut gaps)?;
            if let Some(k) = gaps.iter().position(|g| !g.is_finite()) {
                return Err(Error::LinearAlgebra(LinalgError::GapNotFinite {
                    context: "pair-space contact".to_string(),
                    pair: k,
                    value: None,
                }));
            }
            next_active_set_into(&active, &gaps, &mut next);
            if next == active {
                converged = true;
                break;
            }
            std::mem::swap(&mut active, &mut next);
        }
        let forces: Vec<f64> = if converged {
            gaps.iter()
                .zip(&active)
                .map(|(&g, &a)| if a { k_n * g } else { 0.0 })
                .collect()
        } else {
            // The semismooth iteration can cycle between active sets; the problem is a strictly
            // convex QP, which projected Gauss–Seidel solves without fail.
            let forces = projected_gauss_seidel(self.flex, k_n, &g_hat, &active)?;
            active = forces.iter().map(|&p| p < 0.0).collect();
            forces
        };
        self.active = active;
        self.scratch.g_hat = g_hat;
        self.scratch.gaps = gaps;
        self.scratch.set = set;
        self.scratch.next = next;
        let mut pc = vec![0.0; 3 * w];
        for (k, &pk) in forces.iter().enumerate() {
            pc[nrm(k)] = pk;
        }
        if self.law.friction {
            self.tangential(u0, p, s, &mut pc)?;
            self.last_s.clear();
            self.last_s.extend_from_slice(s);
        }
        Ok(pc)
    }

    /// The corrected tangential forces (module docs, "Friction"), written into the tangential
    /// rows of `pc` whose normal rows hold the corrected normal forces: a pair the run slides
    /// keeps its direction on the corrected cone `μ|p_n*|`, and so does a pair the run holds
    /// open that moved tangentially by more than its stick radius over the last output
    /// interval (in the direction of that motion); the other closed pairs S stick with
    /// the run's slip memory `s` (2w, mm), `p_t* = k_t (u_t* − s)` at the corrected tangential
    /// kinematics `u_t* = û_t − F_{t,n} p_n* − F_{t,t} p_t*` — one linear pair-space solve
    /// `(I + k_t F_SS) p_S = k_t (û_S − F_{S,n} p_n* − F_{S,L} p_L − s_S)`; a sticking pair whose
    /// force leaves its cone slides on it, and S is solved again without it. Then the slip of
    /// the corrected state ([`Corrector::corrected_slip`]).
    fn tangential(
        &mut self,
        u0: &[f64],
        p: &[f64],
        s: &[f64],
        pc: &mut [f64],
    ) -> Result<(), Error> {
        let (w, mu, k_t) = (self.w, self.law.mu, self.law.k_t);
        let nrm = |k: usize| 3 * k + NORMAL;
        // Sliding in the run: on the corrected cone in the run's direction.
        let mut stick: Vec<usize> = Vec::new();
        for k in 0..w {
            let (pt1, pt2) = (p[3 * k + T1], p[3 * k + T2]);
            let pt = pt1.hypot(pt2);
            let cone = mu * pc[nrm(k)].abs();
            let sliding = pt > 0.0 && pt >= (1.0 - 1e-9) * mu * p[nrm(k)].abs();
            let scale = if cone == 0.0 || pt == 0.0 {
                0.0
            } else {
                cone / pt
            };
            // A pair the run holds open has no slip memory of its own (it follows the pair's
            // tangential motion), so sticking with it would give such a pair next to no friction
            // force. The full model's pair, once closed, reaches its cone after a tangential
            // motion of its stick radius μ|p_n*|/k_t: if the pair moved that far over the last
            // output interval, it slides on its cone in that direction.
            let moved = match (p[nrm(k)] == 0.0, self.last_s.is_empty()) {
                (true, false) => [
                    s[2 * k] - self.last_s[2 * k],
                    s[2 * k + 1] - self.last_s[2 * k + 1],
                ],
                _ => [0.0; 2],
            };
            let travel = moved[0].hypot(moved[1]);
            if cone > 0.0 && !sliding && travel > 0.0 && k_t * travel >= cone {
                pc[3 * k + T1] = cone * moved[0] / travel;
                pc[3 * k + T2] = cone * moved[1] / travel;
            } else if cone > 0.0 && !sliding {
                stick.push(k);
            } else {
                pc[3 * k + T1] = scale * pt1;
                pc[3 * k + T2] = scale * pt2;
            }
        }
        let stuck = self.stick(u0, s, pc, stick)?;
        if !self.want_slip {
            return Ok(());
        }
        self.corrected_slip(u0, s, pc, &stuck)
    }

    /// The stick problem of the closed pairs `stick` that do not slide (module docs,
    /// "Friction"): writes their forces into `pc` and returns the pairs whose force stays
    /// within the cone (they keep the run's slip memory).
    fn stick(
        &mut self,
        u0: &[f64],
        s: &[f64],
        pc: &mut [f64],
        mut stick: Vec<usize>,
    ) -> Result<Vec<usize>, Error> {
        let (w, mu, k_t) = (self.w, self.law.mu, self.law.k_t);
        let nrm = |k: usize| 3 * k + NORMAL;
        if stick.is_empty() || k_t <= 0.0 {
            return Ok(Vec::new());
        }
        for _ in 0..=w {
            for &k in &stick {
                pc[3 * k + T1] = 0.0;
                pc[3 * k + T2] = 0.0;
            }
            let rows: Vec<usize> = stick
                .iter()
                .flat_map(|&k| [3 * k + T1, 3 * k + T2])
                .collect();
            let loaded: Vec<usize> = (0..3 * w)
                .filter(|&r| r % 3 != NORMAL && pc[r] != 0.0)
                .collect();
            self.fetch_tangential(&rows)?;
            self.fetch_tangential(&loaded)?;
            let tcols = &self.tcols;
            let col = |r: usize| tcols[r].as_ref().expect("fetched above");
            // Tangential row r of pair k sits at 2k (t1) or 2k + 1 (t2) of a column's
            // tangential rows and of the slip memory.
            let t_at = |r: usize| 2 * (r / 3) + (r % 3 - 1);
            // The pairs with a normal force, ascending: the others would add only zeros.
            let closed: Vec<usize> = (0..w).filter(|&k| pc[nrm(k)] != 0.0).collect();
            let mut rhs: Vec<f64> = rows
                .iter()
                .map(|&r| {
                    let normal = &col(r).0;
                    let from_normal: f64 = closed.iter().map(|&k| normal[k] * pc[nrm(k)]).sum();
                    let from_sliding: f64 = loaded.iter().map(|&l| col(l).1[t_at(r)] * pc[l]).sum();
                    k_t * (u0[r] - from_normal - from_sliding - s[t_at(r)])
                })
                .collect();
            // The factor's indices are the positions t_at(r) (2w of them).
            let index: Vec<usize> = rows.iter().map(|&r| t_at(r)).collect();
            let mut col_of = vec![usize::MAX; 2 * w];
            for (c, &i) in index.iter().enumerate() {
                col_of[i] = c;
            }
            self.stick_factor
                .update(&index, |i, j| {
                    let d = if i == j { 1.0 } else { 0.0 };
                    d + k_t * 0.5 * (col(rows[col_of[j]]).1[i] + col(rows[col_of[i]]).1[j])
                })
                .map_err(|e| {
                    Error::LinearAlgebra(LinalgError::ContactMatrix {
                        pairs: stick.len(),
                        source: Box::new(e),
                    })
                })?;
            let order = self.stick_factor.order().to_vec();
            let mut x: Vec<f64> = order.iter().map(|&i| rhs[col_of[i]]).collect();
            self.stick_factor.solve_in_place(&mut x);
            for (&i, v) in order.iter().zip(&x) {
                rhs[col_of[i]] = *v;
            }
            let mut left = Vec::with_capacity(stick.len());
            for (c, &k) in stick.iter().enumerate() {
                let (f1, f2) = (rhs[2 * c], rhs[2 * c + 1]);
                let (f, cone) = (f1.hypot(f2), mu * pc[nrm(k)].abs());
                let scale = if f > cone { cone / f } else { 1.0 };
                pc[3 * k + T1] = scale * f1;
                pc[3 * k + T2] = scale * f2;
                if f <= cone {
                    left.push(k);
                }
            }
            let done = left.len() == stick.len();
            stick = left;
            if done || stick.is_empty() {
                break;
            }
        }
        Ok(stick)
    }

    /// The slip memory of the corrected state, `s* = u_t* − p_t*/k_t` at the corrected
    /// tangential kinematics `u_t* = û_t − F_{t,n} p_n* − F_{t,t} p_t*` of every pair the
    /// correction closes (module docs, "Friction"); the pairs of `stuck` keep the run's memory
    /// `s`, which their stick solve satisfies exactly. Open pairs get NaN: they dissipate nothing.
    fn corrected_slip(
        &mut self,
        u0: &[f64],
        s: &[f64],
        pc: &[f64],
        stuck: &[usize],
    ) -> Result<(), Error> {
        let (w, k_t) = (self.w, self.law.k_t);
        let nrm = |k: usize| 3 * k + NORMAL;
        let t_at = |r: usize| 2 * (r / 3) + (r % 3 - 1);
        self.slip.clear();
        self.slip.resize(2 * w, f64::NAN);
        let Scratch {
            is_stuck,
            rows,
            moving,
            closed,
            ..
        } = &mut self.scratch;
        is_stuck.clear();
        is_stuck.resize(w, false);
        for &k in stuck {
            is_stuck[k] = true;
            self.slip[2 * k] = s[2 * k];
            self.slip[2 * k + 1] = s[2 * k + 1];
        }
        // The pairs with a normal force, ascending (the others would add only zeros), and
        // their tangential rows.
        closed.clear();
        closed.extend((0..w).filter(|&k| pc[nrm(k)] != 0.0));
        rows.clear();
        rows.extend(closed.iter().flat_map(|&k| [3 * k + T1, 3 * k + T2]));
        moving.clear();
        moving.extend(rows.iter().copied().filter(|&r| !is_stuck[r / 3]));
        if moving.is_empty() {
            return Ok(());
        }
        let (rows, moving, closed) = (
            std::mem::take(rows),
            std::mem::take(moving),
            std::mem::take(closed),
        );
        self.fetch_tangential(&moving)?;
        for &r in &moving {
            let (normal, tangential) = self.tcols[r].as_ref().expect("fetched above");
            // F is symmetric: row r of F is column r.
            let from_normal: f64 = closed.iter().map(|&k| normal[k] * pc[nrm(k)]).sum();
            let from_tangential: f64 = rows.iter().map(|&l| tangential[t_at(l)] * pc[l]).sum();
            let u = u0[r] - from_normal - from_tangential;
            self.slip[t_at(r)] = if k_t > 0.0 { u - pc[r] / k_t } else { u };
        }
        (self.scratch.rows, self.scratch.moving, self.scratch.closed) = (rows, moving, closed);
        Ok(())
    }
}

/// The pair-space contact problem as the strictly convex QP it is: with compressive forces
/// `c = −p_n ≥ 0` and gaps `g = ĝ + F_nn c`, the law `c = k_n (−g)₊` is the optimality condition
/// of `min ½ cᵀ (F_nn + I/k_n) c + ĝᵀ c` subject to `c ≥ 0` (KKT multiplier = g). Projected
/// Gauss–Seidel converges for any SPD matrix; it runs until no force moves by more than 1e-13
/// of the largest (at most 100 000 sweeps, else an error).
///
/// Only the pairs that can carry force enter the sweeps: the candidates S start as the last
/// active set `hint`; once PGS has converged on S, the deepest pairs outside S with a negative
/// gap `ĝ + F_{n,S} c_S` join S as in [`next_active_set`] and PGS resumes (S only grows, so
/// this ends, with no pair outside S penetrating).
/// Returns `p_n = −c` (w values, N).
fn projected_gauss_seidel(
    flex: &JointFlexibility,
    k_n: f64,
    g_hat: &[f64],
    hint: &[bool],
) -> Result<Vec<f64>, Error> {
    let w = g_hat.len();
    let mut set: Vec<usize> = (0..w).filter(|&k| hint[k]).collect();
    let mut c_all = vec![0.0; w];
    loop {
        let cols = flex.normal_columns(&set)?;
        let c: Vec<f64> = set.iter().map(|&k| c_all[k]).collect();
        let c = pgs_on(&set, &cols, k_n, g_hat, c)?;
        for (&k, &ck) in set.iter().zip(&c) {
            c_all[k] = ck;
        }
        // Gaps of every pair under the forces found on S.
        let mut gaps = g_hat.to_vec();
        for (col, ck) in cols.iter().zip(&c) {
            if *ck != 0.0 {
                for (g, f) in gaps.iter_mut().zip(col.iter()) {
                    *g += f * ck;
                }
            }
        }
        let mut in_set = vec![false; w];
        for &k in &set {
            in_set[k] = true;
        }
        let outside: Vec<bool> = in_set.iter().map(|i| !i).collect();
        let joins = next_active_set(&in_set, &gaps);
        let more: Vec<usize> = (0..w).filter(|&k| outside[k] && joins[k]).collect();
        if more.is_empty() {
            return Ok(c_all.iter().map(|v| -v).collect());
        }
        set.extend(more);
        set.sort_unstable();
    }
}

/// Projected Gauss–Seidel on the candidate pairs `set` (their flexibility columns `cols`),
/// from the compressive forces `c`; see [`projected_gauss_seidel`].
fn pgs_on(
    set: &[usize],
    cols: &[Arc<[f64]>],
    k_n: f64,
    g_hat: &[f64],
    mut c: Vec<f64>,
) -> Result<Vec<f64>, Error> {
    let diag: Vec<f64> = (0..set.len())
        .map(|i| cols[i][set[i]] + 1.0 / k_n)
        .collect();
    for _ in 0..100_000 {
        let (mut moved, mut largest) = (0.0f64, 0.0f64);
        for i in 0..set.len() {
            let k = set[i];
            let mut grad = g_hat[k] + c[i] / k_n;
            for (j, cj) in c.iter().enumerate() {
                grad += 0.5 * (cols[j][k] + cols[i][set[j]]) * cj;
            }
            let next = (c[i] - grad / diag[i]).max(0.0);
            moved = moved.max((next - c[i]).abs());
            largest = largest.max(next);
            c[i] = next;
        }
        if moved <= 1e-13 * largest || largest == 0.0 {
            return Ok(c);
        }
    }
    Err(Error::LinearAlgebra(LinalgError::GaussSeidelNotConverged))
}

/// `‖a − b‖ / ‖b‖` over all entries (`None` if `b` is zero).
fn relative_l2(a: &[f64], b: &[f64]) -> Option<f64> {
    let den: f64 = b.iter().map(|v| v * v).sum();
    let num: f64 = a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum();
    (den > 0.0).then(|| (num / den).sqrt())
}
