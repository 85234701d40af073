//! Error-controlled reduction: a tolerance on the joint forces in, the smallest reduced model that
//! meets it out, with the estimate of [`super::estimate`] attached to every reduced run.
//!
//! The tolerance holds for the quantities of [`ToleranceOptions::quantities`] — by default
//! ‖f_c‖(t), ‖f_R‖(t), the master's u_y(t) and the dissipated energy D(t) (the last two need
//! friction): the rounds below run until the reduction estimate of each is within TOL. The
//! rules are written for ‖f_c‖; ‖f_R‖ and D add **tangential attachment modes**
//! `K⁻¹ B_{t,k}ᵀ d_k` by the same selection on the tangential shares
//! `e_{t,k} = Σ_t |p_{t,k} − p_{t,k}*|²` ([`Estimate::pair_tangential_error`]), first in the
//! pair's main direction of friction, later across it, and in rounds that add no normal modes
//! (the friction cone follows the normal force). A round that adds normal modes while the
//! normal part is already within TOL takes tangential modes too, selected by the shares of the
//! outputs at which the run sticks each pair ([`Estimate::pair_stick_error`]): a stick force
//! is an elastic stretch, set by the tangential compliance that only tangential modes add.
//! D, a sum of what each pair dissipates,
//! has its own rule when neither force rule adds anything: the pairs with the largest shares
//! `σ_k` of its error ([`Estimate::pair_dissipation_error`]; the shares bound it by their sum)
//! get their normal attachment mode, or their next tangential one if they hold it already.
//! With ‖f_R‖ or D controlled the integration starts ten times tighter
//! ([`integration_looseness_for`]). With ‖f_c‖ controlled the rounds' atol is capped by the
//! force floor ([`force_floor_atol`]): `k_n · atol ≤ θ·TOL·F`, F the first estimate's
//! `(Σ_t ‖f_c*‖²)^{1/2}`, so that the force resolution follows the forces asked for, not a
//! length fixed in mm (on a refined mesh more pairs share the load and F falls); with ‖f_R‖
//! controlled also by the sliding friction floor ([`sliding_friction_floor_atol`], the same
//! with `μ k_n` and ‖f_R*‖). A sticking pair's force is resolved through `k_t`, not `μ k_n`: the
//! stick floor ([`friction_floor_atol`]) is not a cap from the start but the first tightening of
//! a model that misses by its integration part. An a-priori stick floor put the refined meshes'
//! runs below the atol at which their ringing joints' curves stop converging (their runs at
//! tighter atol move further from each other, and from the full run), where the same models
//! meet at the force floor; the friction bar under a light load needs it, and gets it from its
//! integration check. A scene whose load is scaled gets floors scaled alike.
//!
//! ## Why not the paper's w(g)
//!
//! Every TVD column is a static response to loads on the pairs that close, so the TVD span is the
//! span of the pair attachment modes `K⁻¹ b_kᵀ`, and the POD ranks those directions by global
//! strain energy, not by how much they change the gaps of the pairs that carry force. The pairs
//! that carry the load are often small in energy (beside the welds, which hold the sheets nearly
//! shut), so they enter only the last POD modes, and no threshold of w(g) fixes that
//! (docs/validation: the a-priori g against the tolerance model).
//!
//! ## The basis
//!
//! `Φ = [Φ_S Φ_V K⁻¹ b_kᵀ (k ∈ S)]`, Craig–Bampton plus the attachment modes of a set S of pairs,
//! M-orthonormalized and rotated to the reduced eigenbasis ([`crate::reduction::final_basis`],
//! [`crate::reduction::modal_rotation`]). With S = all pairs this is the "all joint DOF" model
//! of the paper's Section 5.1; its contact statics are exact.
//!
//! ## Choosing S ([`tolerance_model`])
//!
//! Start with S = ∅ (Craig–Bampton), and repeat:
//!
//! 1. run the reduced model (the user's transient options) and estimate its error: the
//!    quasi-static joint correction gives the corrected normal forces `p_n*(t)` and the estimate
//!    `η = ‖ ‖p_n‖ − ‖p_n*‖ ‖_L2 / ‖ ‖p_n*‖ ‖_L2` (module docs of the estimator);
//! 2. if `η ≤ TOL`, stop: this run is the result;
//! 3. else rank the pairs outside S by their share `e_k = Σ_t (p_{n,k} − p_{n,k}*)²` and add the
//!    fewest, largest first, that leave `√(Σ_{k∉S} e_k) ≤ θ · TOL · ‖ ‖p_n*‖ ‖_L2` (θ =
//!    [`SELECTION_MARGIN`]) — but at most `max(|S|, dim Φ_CB)` of them: a round at most
//!    doubles the basis's joint part, starting from the Craig–Bampton size. Since
//!    `|‖a‖ − ‖b‖| ≤ ‖a − b‖`, the pairs left out can contribute at most θ·TOL to the next
//!    estimate if the added pairs become exact.
//!
//! Why the cap: a model far from the answer spreads its error over many pairs, so an uncapped
//! rule adds most of the interface after the Craig–Bampton round although the next estimate's
//! joint part would be far inside the tolerance with a fraction of them. Doubling per round costs
//! at most one round more and keeps the basis near the smallest that meets TOL.
//!
//! The first round's run, Craig–Bampton alone, only ranks the pairs — its joint forces are off by
//! O(1) and its integration error at [`RANKING_LOOSENING`]× looser tolerances is a small
//! fraction of that — so it runs at those looser tolerances; should it meet TOL, it is re-run at
//! the user's before it is the result. It is still estimated on every output: a thinned ranking
//! picks worse pairs on refined meshes. But only its joint part (the correction without the
//! truncated modes' dynamics): the pairs are ranked by that part, and ν grows only once it is
//! within its share, so the second correction per output and the truncated modes' setup against
//! its basis would buy nothing there.
//!
//! Pairs that never carry force in either the run or the correction have `e_k = 0` and are never
//! added: the model keeps only the joint directions the scene uses. The estimate's truncation
//! part (the dynamics of the fixed-interface modes beyond ν) is not removed by pairs: when it
//! exceeds θ·TOL once the joint part is within its share, ν grows by [`NU_STEP`] (up to
//! [`MAX_NU`]; the estimate then holds [`truncated_modes_for`]`(ν)` modes, so that the modes
//! beyond every ν are checked). The truncated modes are driven by the run's own contact forces,
//! so while those are wrong the truncation part is inflated by orders of magnitude: growing ν in
//! the same round as the pairs would make every model [`NU_STEP`] columns larger for nothing.
//! The rounds' e_k come from the joint part alone, so truncation does not masquerade as pair
//! error. A round whose correction meets TOL may be the result: it also gets the estimate's
//! truncation check ([`super::estimate::add_truncation_check`], a re-run with every truncated
//! fixed-interface mode the estimator holds, which sees their back-coupling into the global
//! motion), and ν grows when that part exceeds θ·TOL and the total misses.
//!
//! The last round's run is the result; its estimate then gains the integration part
//! ([`super::estimate::integration_errors`]: one more run at other tolerances, its difference
//! scaled to this run's error by the BDF2 error model), and `met` says whether the total meets
//! TOL. Both checks are re-runs that do not depend on the run they check, and they are made as
//! one first, the **combined check** ([`super::estimate::add_combined_check`]: the truncation
//! check's richer model at the integration check's tighter tolerances, its difference scaled
//! like the integration part). It estimates the sum of both errors without telling them apart:
//! if the total with it meets TOL the round is the result; if not, the two separate re-runs
//! replace it and their parts decide between ν and the integration. It is made only for runs
//! looser than the paper's tolerances and at most [`COMBINED_CHECK_MAX_LOOSENESS`]× them (where
//! two models' integration errors follow the BDF2 law and the integration check is the tighter
//! re-run), and it reads the truncation error 1.87× as large as the truncation check does, so a
//! round whose first-order truncation part read that large already misses makes the separate
//! ones at once (docs/theory/error-estimate.md, "The combined check"). A round makes the checks
//! only if it may be the result (its correction meets TOL, or nothing is left to change), the
//! two beside each other on a second core; a round *expected* to be the result starts them
//! beside its own run instead: one that repeats the previous model (the ranking round's at the
//! user's tolerances, or tighter ones), grows ν, or adds every attachment mode the previous
//! estimate asked for (no cap cut the selection and no tangential modes wait for the normal
//! ones). The expectation only moves work in time: a check made beside a run whose correction
//! then misses TOL is dropped, and every estimate and model is the one the sequential order
//! gives, bit for bit. When it does not — nothing left to add, or the integration error of the
//! user's tolerances above TOL — the best model is returned with `met = false` (the CLI warns;
//! tighter `--rtol/--atol` lower the integration floor). So is the last model that could be the
//! result when a richer round's run (or a check's re-run) stops before its end time — CVODE's
//! step limit, a convergence failure, a stall, the wall-clock budget: the offline work up to it
//! is a model with an estimate, and the stopped round is reported beside it (`stopped`); a
//! request or model error is still an error.
//!
//! **At the integration floor.** The selection leaves the model's error θ·TOL and so the
//! integration part the rest, but a round's model error is only held below TOL: at the
//! tolerances' floor (the user's or the paper's, or after a stall below TOL) a model error
//! between θ·TOL and TOL beside an integration part that cannot fall may still miss. Such a
//! round grows its model where its parts exceed their shares (the attachment modes the joint
//! parts ask for, else ν), as a round that misses by its model error does — but only while the
//! integration part leaves room, `e_int ≤ √(1 − θ²)·TOL` (the parts add in quadrature): with a
//! larger one no model meets TOL and the best is returned as above. Growth there is a trial: a
//! later round whose estimated total (with its checks) is no better than the model it grew from
//! ends the search with that model, not met, and the rounds after it are reported as
//! `discarded`. On a joint that rings, richer models can estimate worse — their truncation
//! check's richer run and their integration check both ring more — and the rounds' rules
//! would otherwise follow that into ever larger ν.
//!
//! **Tightening that does not converge.** A model that misses by its integration part is re-run
//! tighter (first at the stick floor, then tenfold). Where a joint rings — sheets that knock
//! together, a refined interface of stiff penalty pairs — the tighter run damps less of the
//! ringing, and its curves move *away* from the looser run's instead of towards a limit
//! (docs/performance/scale.md, "The friction floor and the ringing joint"). A re-run at least
//! [`STALL_TIGHTENING`] tighter whose integration part is no smaller is an
//! [`IntegrationStall`]: no round after it is tightened, and if that part alone is above TOL no
//! model the rounds can build meets it, so the search ends there with the re-run as the result
//! (`met = false`, the stall in the JSON and a CLI warning).

use std::collections::HashMap;
use std::sync::Arc;
use std::time::Instant;

use serde::Serialize;

use crate::error::{Error, RomError};
use crate::integrate::problem::OdeOptions;
use crate::integrate::{Run, TransientOptions};
use crate::joint::statics::ContactOptions;
use crate::model::Model;
use crate::reduction::estimate::{truncated_modes_for, TRUNCATION_BEYOND};
use crate::reduction::Estimate;
use crate::reduction::{
    craig_bampton, craig_bampton_with, modal_rotation, CurveErrors, FixedInterface,
    JointFlexibility, Orthonormalizer, Quantities, Quantity, DEFAULT_DROP_TOL,
};
use crate::rom::estimate::{
    add_checks, add_combined_check, beside, check_factor, drop_combined, drop_truncation,
    integration_scale, loosened, run_estimated_parts, Checks, RunEstimate, PAPER_RTOL,
};
use crate::rom::statics::{reduced_contact_static_restarting, scaled_load, ReducedStatic};
use crate::system::{ReducedSystem, Scene};

mod compress;
pub use compress::{
    AttemptParts, Compression, CompressionAttempt, AUTO_COMPRESSION_SHRINK, COMPRESSION_ATTEMPTS,
    COMPRESSION_TIGHTENING,
};

/// θ of the pair selection (module docs): the pairs left out may carry at most this fraction of
/// the tolerance.
pub const SELECTION_MARGIN: f64 = 0.5;

/// Options of [`tolerance_model`].
#[derive(Clone, Debug)]
pub struct ToleranceOptions {
    /// The tolerance on the relative L2 errors of the controlled quantities, in (0, 1).
    pub tolerance: f64,
    /// Fixed-interface modes ν of the Craig–Bampton part.
    pub nu: usize,
    /// The transient runs (every round and the result).
    pub transient: TransientOptions,
    /// Rounds of enrichment at most (each one reduced run).
    pub max_rounds: usize,
    /// Whether the integration tolerances follow the tolerance ([`integration_looseness`]) or are
    /// `transient`'s as given.
    pub integration: IntegrationTolerances,
    /// The quantities the tolerance holds for (`None`: all the run produces,
    /// [`controlled_quantities`]).
    pub quantities: Option<Quantities>,
    /// Whether the per-pair model that meets the tolerance is then compressed (its joint
    /// columns replaced by their POD, `compress.rs`; kept only if it meets the tolerance with a
    /// smaller basis): always, never, or where the POD promises a basis small enough to pay for
    /// the compressed model's run and estimate ([`CompressJoint::Auto`]).
    pub compress: CompressJoint,
}

/// When the tolerance model compresses its joint columns ([`ToleranceOptions::compress`]; the
/// CLI's `--compress-joint` values).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum CompressJoint {
    /// Never: the per-pair model is the result.
    Off,
    /// Always try (up to [`COMPRESSION_ATTEMPTS`] compressed models).
    On,
    /// Try only where the first compressed basis is at most [`AUTO_COMPRESSION_SHRINK`] of the
    /// per-pair basis.
    #[default]
    Auto,
}

/// Where the tolerance model's rtol and atol come from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum IntegrationTolerances {
    /// From the tolerance: the paper's Table 1 values loosened by [`integration_looseness`],
    /// tightened while the estimate misses the tolerance (first to the stick floor,
    /// [`friction_floor_atol`], then tenfold).
    #[default]
    FromTolerance,
    /// The transient options' own rtol and atol (the user gave them).
    Given,
}

/// The factor `s` on the paper's Table 1 rtol and atol (1e-8, 1e-6 mm) at which the tolerance
/// model of tolerance `tol` starts: `s = clamp(tol / 1e-4, 1, 1e4)` — ten times looser per
/// decade of tolerance above 1e-4, the paper's tolerances from 1e-4 down. The estimate, whose
/// integration part is a re-run √10 times tighter ([`super::estimate::integration_errors`]),
/// checks the choice: while its total misses TOL, `s` drops tenfold and the model is re-run,
/// down to `s = 1`.
pub fn integration_looseness(tol: f64) -> f64 {
    (tol / PAPER_LEVEL).clamp(1.0, 1e4)
}

/// The tolerance at and below which [`integration_looseness`] is 1 (the paper's tolerances).
const PAPER_LEVEL: f64 = 1e-4;

/// The same with ‖f_R‖ or D controlled ([`integration_looseness_for`]): ten times higher.
const PAPER_LEVEL_FRICTION: f64 = 1e-3;

/// [`integration_looseness`] for the quantities `on`: ten times tighter when ‖f_R‖ or D is
/// controlled, `s = clamp(tol / 1e-3, 1, 1e4)`. The friction force is the quantity most
/// sensitive to the integration: a sticking pair's force is `k_t` times an elastic stretch of
/// 1e-6 mm, and at rtol 1e-6 the stick–slip transitions are resolved only to a few per cent of
/// ‖f_R‖ (friction bar: the 1 % model's ‖f_R‖(t) moves by 1–2 % between rtol 1e-6 and 1e-7).
/// A run that noisy would read its integration noise as reduction error — the quasi-static
/// correction is smooth where the run rings — and the rounds would add attachment modes and
/// fixed-interface modes that remove nothing.
pub fn integration_looseness_for(tol: f64, on: Quantities) -> f64 {
    (tol / paper_level(on)).clamp(1.0, 1e4)
}

/// The tolerance at and below which the rounds start at the paper's integration tolerances
/// (`s = 1` in [`integration_looseness_for`]): 1e-3 when ‖f_R‖ or D is controlled, else 1e-4.
fn paper_level(on: Quantities) -> f64 {
    let friction = on.contains(Quantity::FrictionForce) || on.contains(Quantity::Dissipation);
    if friction {
        PAPER_LEVEL_FRICTION
    } else {
        PAPER_LEVEL
    }
}

/// θ of the force-floor rule ([`force_floor_atol`]): one output's flicker at the force floor may
/// use at most this fraction of the tolerance on ‖f_c‖.
pub const FORCE_FLOOR_SHARE: f64 = SELECTION_MARGIN;

/// The absolute tolerance (mm) at which the force floor of the normal penalty law, `k_n · atol`,
/// is at most θ·TOL ([`FORCE_FLOOR_SHARE`]) of the run's force scale
/// `F = (Σ_t ‖f_c*(t)‖²)^{1/2}` — the denominator of the relative L2 error of ‖f_c‖(t) over the
/// outputs, taken from the first estimate's correction (`corrected_norm2`, N²):
///
/// ```text
/// atol_f = θ · TOL · F / k_n
/// ```
///
/// A gap is resolved to about atol, so a pair near its closure flickers by a force of about
/// `k_n · atol`; one output that reads it moves the relative L2 error of ‖f_c‖ by
/// `k_n · atol / F`. The rule keeps that within θ·TOL whatever the mesh: on a refined mesh more
/// pairs share the load and `F` falls, while an atol in mm holds the same force floor. `None`
/// where the scale is zero or not finite (no contact: nothing to resolve).
pub fn force_floor_atol(tol: f64, corrected_norm2: f64, k_n: f64) -> Option<f64> {
    let scale = corrected_norm2.sqrt();
    let atol = FORCE_FLOOR_SHARE * tol * scale / k_n;
    (atol.is_finite() && atol > 0.0).then_some(atol)
}

/// The same floor for the friction force of a sticking pair ([`force_floor_atol`] with the
/// stick law): its force is `k_t` times an elastic stretch resolved to about atol, so one
/// output's flicker moves the relative L2 error of ‖f_R‖(t) by `k_t · atol / F_R`, with
/// `F_R = (Σ_t ‖f_R*(t)‖²)^{1/2}` from the first estimate's correction
/// (`corrected_friction_norm2`, N²):
///
/// ```text
/// atol_R = θ · TOL · F_R / k_t
/// ```
///
/// The rounds start without it, at the sliding floor ([`sliding_friction_floor_atol`]); a
/// round that misses by its integration part is tightened to it first, where it is below the
/// rounds' atol ([`tolerance_model`], module docs). The floors are homogeneous of degree one in
/// the load, like the penalty and Coulomb laws: a scene whose load is scaled by λ (zero initial
/// gaps) gets them scaled by λ. `None` where nothing slides or sticks.
pub fn friction_floor_atol(tol: f64, corrected_friction_norm2: f64, k_t: f64) -> Option<f64> {
    force_floor_atol(tol, corrected_friction_norm2, k_t)
}

/// The friction floor of a sliding pair: its friction force `μ p_n` is resolved through its gap,
/// to `μ k_n · atol`, so
///
/// ```text
/// atol_S = θ · TOL · F_R / (μ k_n)
/// ```
///
/// (`mu_k_n` = μ·k_n, N/mm). On a joint that slides (`F_R ≈ μ F`) it is the force floor. It caps
/// every round's atol where ‖f_R‖ is controlled; the stick floor ([`friction_floor_atol`], `k_t`
/// for `μ k_n`) is the first tightening. `None` where nothing slides or sticks, or `μ = 0`.
pub fn sliding_friction_floor_atol(
    tol: f64,
    corrected_friction_norm2: f64,
    mu_k_n: f64,
) -> Option<f64> {
    force_floor_atol(tol, corrected_friction_norm2, mu_k_n)
}

/// How many times the ranking round is repeated at most because its own run was coarser than
/// [`RANKING_LOOSENING`]× the force floor it measured ([`force_floor_atol`]): a run whose force
/// floor exceeds the joint forces measures its own noise, not their scale. It is repeated at
/// that atol until the floor it measures agrees with the previous one within a factor 2.
pub const FORCE_FLOOR_REPEATS: usize = 3;

/// `opts` with its atol lowered to `cap` where that is tighter (the force floor,
/// [`force_floor_atol`]).
fn capped(mut opts: TransientOptions, cap: Option<f64>) -> TransientOptions {
    if let Some(cap) = cap {
        opts.ode.atol = opts.ode.atol.min(cap);
    }
    opts
}

/// The rounds' integration tolerances ([`tolerance_model`]): the user's, or the paper's times
/// the looseness `s` ([`integration_looseness_for`]), the atol capped by the force floor where
/// ‖f_c‖ is controlled ([`force_floor_atol`]).
struct RoundTolerances {
    /// The factor `s` on the user's (or the paper's) rtol and atol.
    looseness: f64,
    /// Whether the force floor applies (‖f_c‖ controlled, tolerances from the tolerance).
    force_rule: bool,
    /// Whether the friction floor applies (‖f_R‖ controlled, tolerances from the tolerance).
    friction_rule: bool,
    /// The tolerance the floors are taken at: TOL, but not below [`paper_level`] — where the
    /// looseness stops at the paper's tolerances, so does the force resolution asked of them.
    floor_tol: f64,
    /// The force floor's atol, once a ranking round has measured it.
    force_atol: Option<f64>,
    /// The sliding friction floor's atol ([`sliding_friction_floor_atol`]), once a ranking
    /// round has measured it.
    sliding_atol: Option<f64>,
    /// The stick friction floor's atol ([`friction_floor_atol`]), once a ranking round has
    /// measured it.
    friction_atol: Option<f64>,
    /// Whether a tightening has applied the stick floor ([`RoundTolerances::tighten`]).
    stick_applied: bool,
    /// Whether the next round re-runs the last one's model tighter.
    tightened: bool,
    /// A tightening that did not converge ([`IntegrationStall`]): no more tightening after it.
    stall: Option<IntegrationStall>,
    /// Ranking rounds repeated so far ([`FORCE_FLOOR_REPEATS`]).
    repeats: usize,
}

impl RoundTolerances {
    fn new(opts: &ToleranceOptions, on: Quantities) -> RoundTolerances {
        let from_tolerance = opts.integration == IntegrationTolerances::FromTolerance;
        RoundTolerances {
            looseness: if from_tolerance {
                integration_looseness_for(opts.tolerance, on)
            } else {
                1.0
            },
            force_rule: from_tolerance && on.contains(Quantity::ContactForce),
            friction_rule: from_tolerance && on.contains(Quantity::FrictionForce),
            floor_tol: opts.tolerance.max(paper_level(on)),
            force_atol: None,
            sliding_atol: None,
            friction_atol: None,
            stick_applied: false,
            tightened: false,
            stall: None,
            repeats: 0,
        }
    }

    /// The transient options of a round: `opts` times the looseness, the ranking round's
    /// [`RANKING_LOOSENING`]× that (and its force floor).
    fn transient(&self, opts: &TransientOptions, ranking: bool) -> TransientOptions {
        let factor = if ranking { RANKING_LOOSENING } else { 1.0 };
        capped(
            loosened(opts, self.looseness * factor),
            self.cap().map(|a| a * factor),
        )
    }

    /// The stick floor, once a tightening applied it.
    fn stick(&self) -> Option<f64> {
        self.friction_atol.filter(|_| self.stick_applied)
    }

    /// The cap on atol: the tightest of the floors measured so far (the stick floor once a
    /// tightening applied it).
    fn cap(&self) -> Option<f64> {
        [self.force_atol, self.sliding_atol, self.stick()]
            .into_iter()
            .flatten()
            .reduce(f64::min)
    }

    /// Measures the force and friction floors from a ranking round's estimate `d` (its run at
    /// `run_atol`) and returns whether the ranking round is to be repeated: its run was coarser
    /// than [`RANKING_LOOSENING`]× the floor, the floor moved by more than a factor 2 from the
    /// last measurement, and repeats (and, `room`, rounds) are left.
    fn measure(&mut self, model: &Model, d: &Estimate, run_atol: f64, room: bool) -> bool {
        if !self.force_rule && !self.friction_rule {
            return false;
        }
        let previous = self.cap();
        if self.force_rule {
            let k_n = model.contact.normal_stiffness;
            self.force_atol = force_floor_atol(self.floor_tol, d.corrected_joint_norm2, k_n);
        }
        if self.friction_rule {
            let c = &model.contact;
            let norm2 = d.corrected_joint_friction_norm2;
            let mu_k_n = c.friction_coefficient * c.normal_stiffness;
            self.sliding_atol = sliding_friction_floor_atol(self.floor_tol, norm2, mu_k_n);
            self.friction_atol = friction_floor_atol(self.floor_tol, norm2, c.stick_stiffness);
        }
        let cap = self.cap();
        let coarse = cap.is_some_and(|a| run_atol > a * RANKING_LOOSENING * (1.0 + 1e-9));
        let moved = match (previous, cap) {
            (Some(p), Some(a)) => (p / a).max(a / p) > 2.0,
            _ => true,
        };
        let repeat = coarse && moved && room && self.repeats < FORCE_FLOOR_REPEATS;
        self.repeats += usize::from(repeat);
        repeat
    }

    /// After a round (`rounds` so far): whether it re-ran the last model tighter and its
    /// integration part stalled ([`IntegrationStall`], kept) above TOL — the search ends.
    fn judge(&mut self, rounds: &[Round], tol: f64) -> bool {
        if !std::mem::take(&mut self.tightened) {
            return false;
        }
        let [.., before, after] = rounds else {
            return false;
        };
        self.stall = IntegrationStall::of(before, after, tol);
        self.stall.is_some_and(|s| s.ended)
    }

    /// Tighter, for a round that missed (`opts` the user's transient options): first the stick
    /// floor on atol where it is below the rounds' atol, then ten times tighter, down to the
    /// user's (or the paper's) tolerances; never after a stall. Whether it tightened.
    fn tighten(&mut self, opts: &TransientOptions) -> bool {
        if self.stall.is_some() {
            return false;
        }
        let atol = self.transient(opts, false).ode.atol;
        if !self.stick_applied && self.friction_atol.is_some_and(|a| a < atol) {
            self.stick_applied = true;
            return true;
        }
        let tightened = self.looseness > 1.0;
        self.looseness = (self.looseness / 10.0).max(1.0);
        tightened
    }
}

impl ToleranceOptions {
    /// ν = 10 (the paper), the default transient options, at most 8 rounds.
    pub fn new(tolerance: f64) -> ToleranceOptions {
        ToleranceOptions {
            tolerance,
            nu: 10,
            transient: TransientOptions::default(),
            max_rounds: 12,
            integration: IntegrationTolerances::FromTolerance,
            quantities: None,
            compress: CompressJoint::Auto,
        }
    }
}

/// One round of [`tolerance_model`].
#[derive(Clone, Debug, Serialize)]
pub struct Round {
    /// Pairs whose attachment modes the basis held.
    pub pairs: usize,
    /// Tangential attachment modes the basis held.
    pub tangential_pairs: usize,
    /// Fixed-interface modes ν of the basis.
    pub nu: usize,
    /// Basis size r.
    pub basis_size: usize,
    /// The estimated relative L2 error of ‖f_c‖(t) (reduction part; of the ranking round its
    /// joint part alone).
    pub estimate: Option<f64>,
    /// The estimated relative L2 error of ‖f_R‖(t) (reduction part; `None` without friction).
    pub friction_estimate: Option<f64>,
    /// Its joint part (what more pairs remove).
    pub joint: Option<f64>,
    /// The joint part of the ‖f_R‖(t) estimate (what more tangential attachment modes remove).
    pub joint_friction: Option<f64>,
    /// Its truncation part (what more fixed-interface modes remove; `None` in the ranking
    /// round, whose estimate is its joint part alone).
    pub truncation: Option<f64>,
    /// The truncation check's part of the estimate (the re-run with the next fixed-interface
    /// modes, [`super::estimate::truncation_check_run`]): the largest over the controlled
    /// quantities (`None` in the ranking round, which makes no re-runs).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub truncation_check: Option<f64>,
    /// The combined check's part of the estimate (one re-run both richer and tighter,
    /// [`super::estimate::add_combined_check`]): the largest over the controlled quantities, as
    /// made — also when it missed and the two separate checks replaced it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub combined_check: Option<f64>,
    /// Wall time of the round's run, s.
    pub wall_s: f64,
    /// The integration steps of the round's run.
    pub steps: u64,
    /// The relative tolerance of the round's run.
    pub rtol: f64,
    /// The absolute tolerance of the round's run (mm).
    pub atol: f64,
    /// The integration check's part of the estimate (the re-run at other tolerances,
    /// [`super::estimate::integration_errors`]): the largest over the controlled quantities
    /// (`None`: not made, or made as the combined check).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub integration_check: Option<f64>,
    /// Wall time of the round's basis and reduced system, s.
    pub basis_s: f64,
    /// Wall time of the round's estimate, s.
    pub estimate_s: f64,
    /// The round only ranked the pairs: its run at [`RANKING_LOOSENING`]× looser tolerances.
    pub ranking: bool,
    /// Where the round made its re-runs (the truncation and integration checks).
    pub checks: ReRuns,
}

impl Round {
    /// The record of a round with the joint part `chosen`, ν and basis size `(nu, r)`, its
    /// estimate (its parts' largest over the quantities `on`), its combined check's part, where
    /// it made its re-runs and whether it ranked, its run's steps and tolerances, and its
    /// timings (run, basis, estimate; s).
    fn of(
        chosen: &Chosen,
        (nu, basis_size): (usize, usize),
        estimate: &RunEstimate,
        on: Quantities,
        (combined_check, checks, ranking): (Option<f64>, ReRuns, bool),
        (steps, ode): (u64, &OdeOptions),
        (wall_s, basis_s, estimate_s): (f64, f64, f64),
    ) -> Round {
        let d = &estimate.detail;
        Round {
            pairs: chosen.pairs.len(),
            tangential_pairs: chosen.tangential.len(),
            nu,
            basis_size,
            estimate: estimate.reduction.contact_force,
            friction_estimate: estimate.reduction.friction_force,
            joint: d.joint,
            joint_friction: d.joint_friction,
            truncation: d.truncation,
            truncation_check: estimate.truncation.map(|t| worst(&t, on)),
            combined_check,
            wall_s,
            steps,
            rtol: ode.rtol,
            atol: ode.atol,
            integration_check: estimate.integration.map(|i| worst(&i, on)),
            basis_s,
            estimate_s,
            ranking,
            checks,
        }
    }
}

/// Where a round of [`tolerance_model`] made its re-runs, the truncation and integration checks
/// (module docs): `"checks"` of a round in the JSON.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ReRuns {
    /// None: its correction missed the tolerance and it was not the result (or it ranked).
    None,
    /// Beside its run: it was expected to be the result.
    BesideRun,
    /// Beside its run, and dropped: its correction missed the tolerance.
    Dropped,
    /// After its correction (which met the tolerance), or as the result.
    AfterCorrection,
    /// The combined check (beside its run or after its correction) missed the tolerance, and
    /// the two separate checks were made after it to tell its parts apart.
    Separated,
}

/// The tolerance-chosen reduced model and its run.
pub struct ToleranceModel {
    /// The chosen pairs (indices into the model's joint pairs), ascending.
    pub pairs: Vec<usize>,
    /// The pairs whose tangential attachment modes the basis holds, in the order added (a pair
    /// twice: both tangential directions).
    pub tangential: Vec<usize>,
    /// The quantities the tolerance held for.
    pub quantities: Quantities,
    /// The chosen number of fixed-interface modes ν.
    pub nu: usize,
    /// Wall time of the setup (the joint flexibility with its factorization and modes,
    /// Craig–Bampton), s.
    pub setup_s: f64,
    /// The reduced system of the result (a fresh copy, not the one that ran).
    pub rom: ReducedSystem,
    /// The result's run (the last round).
    pub run: Run,
    /// Its estimate (reduction and integration parts).
    pub estimate: RunEstimate,
    /// Whether the estimates (both parts) of every controlled quantity meet the tolerance.
    pub met: bool,
    /// Every round, the last one the result.
    pub rounds: Vec<Round>,
    /// Wall time of everything before the result's run (factorization, Craig–Bampton, the
    /// flexibility, the earlier rounds' runs and estimates, the result's basis), s.
    pub offline_s: f64,
    /// Wall time of the result's estimate after its run: the quasi-static joint correction and
    /// the truncation and integration checks (or the wait for them, when they ran beside the
    /// run), s.
    pub estimate_s: f64,
    /// The transient options of the result's run (the integration tolerances chosen).
    pub transient: TransientOptions,
    /// CPU time of the process over the whole tolerance model (setup, rounds, the result's
    /// run and estimate; every thread, including other work the process does meanwhile), s.
    pub cpu_s: f64,
    /// What the compression of the joint columns did (`None`: not tried).
    pub compression: Option<Compression>,
    /// The force floor's atol ([`force_floor_atol`], mm): a cap on the rounds' atol (`None`:
    /// no cap — ‖f_c‖ not controlled, `--rtol/--atol` given, or no contact).
    pub force_atol: Option<f64>,
    /// The sliding friction floor's atol ([`sliding_friction_floor_atol`], mm): the other cap
    /// (`None`: ‖f_R‖ not controlled, `--rtol/--atol` given, or no friction force).
    pub sliding_friction_atol: Option<f64>,
    /// The stick friction floor's atol ([`friction_floor_atol`], mm), where a tightening applied
    /// it (`None`: no round missed by its integration, or as for the sliding floor).
    pub friction_atol: Option<f64>,
    /// A richer round whose run stopped before its end time (`None`: none did): the result is
    /// then the model of the round before it, not met, its estimate as far as its round made
    /// it.
    pub stopped: Option<StoppedRound>,
    /// A tightening of the integration that did not converge (`None`: none did); no round
    /// after it was tightened again.
    pub integration_stall: Option<IntegrationStall>,
    /// The rounds grown at the integration floor whose estimate came out no better than the
    /// model they grew from, which is then the result (empty: none were dropped).
    pub discarded: Vec<Round>,
}

impl ToleranceModel {
    /// The model of a round with the joint part `chosen`, the quantities `on`, ν and the setup's
    /// wall time, with its system, run, estimate and transient options, and the floors of
    /// `tolerances`; not met, no rounds and no timings yet (the caller sets those).
    fn of(
        chosen: &Chosen,
        (on, nu, setup_s): (Quantities, usize, f64),
        (rom, run, estimate, transient): (ReducedSystem, Run, RunEstimate, TransientOptions),
        tolerances: &RoundTolerances,
    ) -> ToleranceModel {
        ToleranceModel {
            pairs: chosen.pairs.clone(),
            tangential: chosen.tangential.clone(),
            quantities: on,
            nu,
            setup_s,
            rom,
            transient,
            run,
            met: false,
            estimate,
            estimate_s: 0.0,
            rounds: Vec::new(),
            offline_s: 0.0,
            cpu_s: f64::NAN,
            compression: None,
            force_atol: tolerances.force_atol,
            sliding_friction_atol: tolerances.sliding_atol,
            friction_atol: tolerances.stick(),
            stopped: None,
            integration_stall: tolerances.stall,
            discarded: Vec::new(),
        }
    }
}

impl StoppedRound {
    /// The record of a round with the joint part `chosen`, ν, system `rom` and transient
    /// options `transient`, before it runs (no reason yet).
    fn of(chosen: &Chosen, nu: usize, rom: &ReducedSystem, transient: &TransientOptions) -> Self {
        StoppedRound {
            pairs: chosen.pairs.len(),
            tangential_pairs: chosen.tangential.len(),
            nu,
            basis_size: rom.dim(),
            rtol: transient.ode.rtol,
            atol: transient.ode.atol,
            reason: String::new(),
        }
    }
}

/// A tightening of the integration that did not converge ([`tolerance_model`], module docs):
/// the same model re-run at tighter rtol or atol read an integration part no smaller than before
/// (`"integration_stall"` of the tolerance JSON).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct IntegrationStall {
    /// rtol of the runs before and after the tightening.
    pub rtol: [f64; 2],
    /// atol of the runs before and after the tightening (mm).
    pub atol: [f64; 2],
    /// Their integration parts (the largest over the controlled quantities).
    pub part: [f64; 2],
    /// Whether the search ended on it: the integration part alone was above the tolerance, so
    /// no model the rounds can build meets it.
    pub ended: bool,
}

/// The smallest tightening `f` (the smaller of the rtol and atol ratios) that
/// [`IntegrationStall`] judges: a converging BDF run's error falls like `f^p`, `p` between 2/3
/// and 1, so by at least a fifth here — more than the integration part's own scatter between
/// runs. A smaller tightening (the stick floor a little below the rounds' atol) decides nothing.
pub const STALL_TIGHTENING: f64 = 0.7;

impl IntegrationStall {
    /// The stall between a round `before` and the same model re-run tighter, `after` (`None`:
    /// no stall, a tightening too small to judge, or a part not measured).
    fn of(before: &Round, after: &Round, tol: f64) -> Option<IntegrationStall> {
        let (b, a) = (before.integration_check?, after.integration_check?);
        let f = (after.rtol / before.rtol).min(after.atol / before.atol);
        (f <= STALL_TIGHTENING && a >= b).then_some(IntegrationStall {
            rtol: [before.rtol, after.rtol],
            atol: [before.atol, after.atol],
            part: [b, a],
            ended: a > tol,
        })
    }
}

/// A round of [`tolerance_model`] whose run (or a check's re-run) stopped before its end time
/// (`"stopped"` of the tolerance JSON).
#[derive(Clone, Debug, Serialize)]
pub struct StoppedRound {
    /// Pairs whose attachment modes its basis held.
    pub pairs: usize,
    /// Tangential attachment modes its basis held.
    pub tangential_pairs: usize,
    /// Fixed-interface modes ν of its basis.
    pub nu: usize,
    /// Its basis size r.
    pub basis_size: usize,
    /// Its integration tolerances: CVODE's rtol and atol (mm).
    pub rtol: f64,
    /// See `rtol`.
    pub atol: f64,
    /// What stopped it (the run's error: CVODE's flag and the time reached, a stall, ...).
    pub reason: String,
}

/// What the tolerance model chose, as the outputs report it (`"tolerance"` in a run's JSON).
#[derive(Clone, Debug, Serialize)]
pub struct ToleranceChoice {
    /// The tolerance asked for.
    pub tolerance: f64,
    /// Whether the estimate (both parts) meets it.
    pub met: bool,
    /// The chosen pairs (indices into the model's joint pairs), ascending.
    pub pairs: Vec<usize>,
    /// The pairs whose tangential attachment modes the basis holds, in the order added.
    pub tangential_pairs: Vec<usize>,
    /// The quantities the tolerance held for (`--tolerance-on`): names `fc`, `fr`, `uy`,
    /// `dissipation`.
    pub quantities: Quantities,
    /// The chosen number of fixed-interface modes ν.
    pub nu: usize,
    /// Wall time of the setup, s.
    pub setup_s: f64,
    /// Wall time of the result's estimate after its run, s.
    pub estimate_s: f64,
    /// CPU time of the process over the whole tolerance model (offline, online and the
    /// result's estimate; every thread), s.
    pub cpu_s: f64,
    /// Every round, the last one the result.
    pub rounds: Vec<Round>,
    /// The integration tolerances of the result's run: CVODE's rtol and atol (mm).
    pub rtol: f64,
    /// See `rtol`.
    pub atol: f64,
    /// The force floor's atol (mm) that capped the rounds' atol (absent: no cap;
    /// [`force_floor_atol`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub force_atol: Option<f64>,
    /// The sliding friction floor's atol (mm), the other cap (absent: no cap;
    /// [`sliding_friction_floor_atol`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sliding_friction_atol: Option<f64>,
    /// The stick friction floor's atol (mm), where a missed round's tightening applied it
    /// (absent: not applied; [`friction_floor_atol`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub friction_atol: Option<f64>,
    /// What the compression of the joint columns did (absent: not tried): how many compressed
    /// columns replaced how many per-pair ones, and whether that model is the result.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub compression: Option<Compression>,
    /// A richer round whose run stopped before its end time (absent: none did); the result is
    /// then the round's before it, not met.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stopped: Option<StoppedRound>,
    /// A tightening of the integration that did not converge (absent: none did).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub integration_stall: Option<IntegrationStall>,
    /// The rounds grown at the integration floor that estimated no better than the model they
    /// grew from — the result, not met (absent: none).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub discarded_rounds: Vec<Round>,
}

/// Builds the smallest Craig–Bampton + pair-attachment-mode model whose estimated errors of the
/// quantities `opts.quantities` meet `opts.tolerance` (module docs).
///
/// # Errors
/// A tolerance outside (0, 1) or not finite ([`RomError::Tolerance`] naming it), a quantity the
/// run cannot produce ([`RomError::ToleranceOnFriction`]), a failing basis, a run that does not
/// finish before a model that could be the result exists (later, the result is that model, not
/// met: [`ToleranceModel::stopped`]) or an estimate that cannot be made.
pub fn tolerance_model(model: &Model, opts: &ToleranceOptions) -> Result<ToleranceModel, Error> {
    let start = Instant::now();
    let cpu_start = process_cpu_s();
    let mut progress = Progress::default();
    let mut result = match search(model, opts, start, &mut progress) {
        Ok(result) => result,
        Err(e) => progress.fall_back(e, start)?,
    };
    result.cpu_s = process_cpu_s() - cpu_start;
    Ok(result)
}

/// What [`search`] leaves behind for a round that stops: the rounds so far, the last model
/// that could be the result and the round being made.
#[derive(Default)]
struct Progress {
    rounds: Vec<Round>,
    /// The last completed round's model at the user's tolerances (not a ranking round), with
    /// the number of rounds up to it.
    best: Option<(ToleranceModel, usize)>,
    /// The round being made: what [`StoppedRound`] reports if its runs stop.
    current: Option<StoppedRound>,
    /// The model a growth at the integration floor started from, with the number of rounds up
    /// to it and its estimated total (the largest over the controlled quantities).
    floor: Option<(ToleranceModel, usize, f64)>,
}

/// The model a growth at the integration floor started from (`floor`, with the number of rounds
/// up to it and its estimated total), as the result — not met, the rounds after it `discarded`
/// — if its total is at most `total`; `rounds` are the search's rounds so far.
fn floor_result(
    floor: &mut Option<(ToleranceModel, usize, f64)>,
    rounds: &mut Vec<Round>,
    total: f64,
    start: Instant,
) -> Option<ToleranceModel> {
    let (mut model, upto, _) = floor.take_if(|f| f.2 <= total)?;
    model.unmet_after(std::mem::take(rounds), upto, start);
    Some(model)
}

impl ToleranceModel {
    /// This model of an earlier round as the result of a search that went on: not met, its
    /// `rounds` the search's up to it (the first `upto`), the rest `discarded`, and its offline
    /// time everything since `start` but its own run and estimate.
    fn unmet_after(&mut self, mut rounds: Vec<Round>, upto: usize, start: Instant) {
        self.discarded = rounds.split_off(upto.min(rounds.len()));
        self.rounds = rounds;
        self.met = false;
        self.offline_s = start.elapsed().as_secs_f64() - self.run.wall_s - self.estimate_s;
    }
}

impl Progress {
    /// The result after [`search`] failed with `e`: when `e` is a run that stopped before its
    /// end time (CVODE's step limit or a convergence failure, a stall, the wall-clock budget, an
    /// overflow) in a round after a model that could be the result, that model, not met, with
    /// the stopped round; any other error, or no such model, is `e`.
    fn fall_back(self, e: Error, start: Instant) -> Result<ToleranceModel, Error> {
        let best = self.floor.map(|(m, upto, _)| (m, upto)).or(self.best);
        let (Some((mut best, upto)), Some(mut stopped)) = (best, self.current) else {
            return Err(e);
        };
        if !stopped_in_time(&e) {
            return Err(e);
        }
        stopped.reason = e.to_string();
        best.unmet_after(self.rounds, upto, start);
        best.stopped = Some(stopped);
        Ok(best)
    }
}

/// Whether `e` is a time integration that stopped before its end time (as opposed to a
/// request or model error): a SUNDIALS failure, a callback failure CVODE returned (the
/// wall-clock budget among them), chattering events, a stall or an overflowing output.
pub(super) fn stopped_in_time(e: &Error) -> bool {
    use crate::error::{CallbackOutcome, IntegrationError};
    matches!(
        e,
        Error::Sundials { .. }
            | Error::Callback {
                outcome: CallbackOutcome::Returned { .. },
                ..
            }
            | Error::Chatter { .. }
            | Error::Integration(
                IntegrationError::Stalled { .. } | IntegrationError::OutputNotFinite { .. }
            )
    )
}

/// The rounds of [`tolerance_model`] from `start`, recording them in `progress`.
fn search(
    model: &Model,
    opts: &ToleranceOptions,
    start: Instant,
    progress: &mut Progress,
) -> Result<ToleranceModel, Error> {
    let tol = opts.tolerance;
    check_tolerance(tol)?;
    let on = controlled_quantities(opts.quantities, opts.transient.problem.friction)?;
    let mut nu = opts.nu;
    let (flex, fixed, mut cb) = setup(model, nu)?;
    // A start ν given above the held set's default keeps modes beyond it checked too.
    flex.hold_truncation_modes(truncated_modes_for(nu));
    let setup_s = start.elapsed().as_secs_f64();
    let mut chosen = Chosen::default();
    let mut bases = BasisCache::new(model);
    let rounds = &mut progress.rounds;
    // The Craig–Bampton round only ranks the pairs: looser tolerances (module docs).
    let mut ranking = true;
    // Whether the round is expected to be the result (its checks then go beside its run).
    let mut expect_result = false;
    // Whether the last estimate says a combined check would miss (combined_may_meet).
    let mut separate = false;
    // The integration tolerances: the user's, or the paper's times s, capped by the force floor.
    let mut tolerances = RoundTolerances::new(opts, on);
    let search = Search {
        model,
        fixed: &fixed,
        flex: &flex,
        on,
        tol,
    };
    loop {
        let round_start = Instant::now();
        let rom = reduced_on(model, &cb, &flex, &chosen, &mut bases)?;
        let basis_s = round_start.elapsed().as_secs_f64();
        let transient = tolerances.transient(&opts.transient, ranking);
        progress.current = (!ranking).then(|| StoppedRound::of(&chosen, nu, &rom, &transient));
        let speculate = !ranking && expect_result;
        let flags = (ranking, speculate, separate);
        let (scene, run, mut estimate, made, combined) =
            search.run_round(&rom, &transient, flags)?;
        let recheck = (&rom, &run, &scene, &transient);
        // A next round expected to be the result: expected with its reduction part in its share.
        let expected = SELECTION_MARGIN * tol;
        separate = !combined_may_meet(expected, &estimate, tol, &transient);
        let eta = worst(&estimate.model_error(), on);
        let d = &estimate.detail;
        let estimate_s = round_start.elapsed().as_secs_f64() - basis_s - run.wall_s;
        rounds.push(Round::of(
            &chosen,
            (nu, rom.dim()),
            &estimate,
            on,
            (combined, made, ranking),
            (run.stats.steps, &transient.ode),
            (run.wall_s, basis_s, estimate_s),
        ));
        // The force floor from the ranking round's correction, the ranking round again if
        // its own run was too coarse to measure it (RoundTolerances::measure).
        let room = rounds.len() < opts.max_rounds;
        if ranking && tolerances.measure(model, d, transient.ode.atol, room) {
            continue;
        }
        // A tightened re-run whose integration part did not converge: no more tightening, and
        // no more rounds if that part alone misses (IntegrationStall).
        let ended = tolerances.judge(rounds, tol);
        // This round's own model (the result, or the fall-back of later rounds).
        let own = (chosen.clone(), nu);
        let mut changed = false;
        // The next round repeats this model or adds all the estimate asked for: the result?
        expect_result = true;
        if eta > tol && !ended && room {
            let grown = search.grow(&mut chosen, (&mut nu, &mut cb), &estimate)?;
            changed = grown.changed;
            expect_result = grown.complete;
        }
        if std::mem::replace(&mut ranking, false) {
            // A ranking run is never the result: the same model again at the user's tolerances
            // (or the one it enriched).
            continue;
        }
        if !changed && estimate.integration.is_none() && estimate.combined.is_none() {
            // The result, or the same model again if its integration misses: its integration
            // check (when the correction missed, no round made it).
            let last = rounds.last_mut();
            result_integration_check(model, recheck, &mut estimate, on, last)?;
        }
        // After a growth at the integration floor, a round whose estimate is no better than
        // that of the model it grew from ends the search with that model.
        let total = worst(&estimate.total, on);
        let checked = estimate.integration.is_some() || estimate.combined.is_some();
        if let Some(floor) = checked
            .then(|| floor_result(&mut progress.floor, rounds, total, start))
            .flatten()
        {
            progress.current = None;
            return Ok(floor);
        }
        // The estimate misses the tolerance at loosened integration tolerances: the same model
        // again, ten times tighter (the reduction part is within its share, or the loop would
        // have enriched the basis).
        let misses = !ended && estimate.integration.is_some() && total > tol;
        let mut again = changed || (misses && tolerances.tighten(&opts.transient));
        let mut at_floor = false;
        if !again && misses && room && room_for_the_model(&estimate, on, tol) {
            // At the integration floor (the tolerances can tighten no further): the model's
            // error into its share, where the integration part leaves room for it.
            let grown = search.grow(&mut chosen, (&mut nu, &mut cb), &estimate)?;
            (changed, again, expect_result) = (grown.changed, grown.changed, grown.complete);
            at_floor = grown.changed;
        }
        let parts = (rom, run, estimate, transient);
        let mut result = ToleranceModel::of(&own.0, (on, own.1, setup_s), parts, &tolerances);
        result.met = total <= tol;
        result.estimate_s = rounds.last().map_or(0.0, |r| r.estimate_s);
        result.offline_s = (round_start - start).as_secs_f64() + basis_s;
        if again {
            tolerances.tightened = !changed;
            // The model the next rounds fall back to if their runs stop (Progress::fall_back),
            // or are read against if they grew at the floor.
            if at_floor {
                progress.floor = Some((result, rounds.len(), total));
            } else {
                progress.best = Some((result, rounds.len()));
            }
            continue;
        }
        // The result: what the compression does is its own (a failed attempt is no round's).
        progress.current = None;
        result.rounds = std::mem::take(rounds);
        compress::compress_result(model, &flex, (&chosen, &bases, &cb), opts, &mut result)?;
        return Ok(result);
    }
}

/// Whether a model whose error is within its share θ·TOL would meet `tol` beside the integration
/// part of `estimate` (largest over the quantities `on`): the parts add in quadrature, so the
/// integration part must be at most `√(1 − θ²)·TOL`. A round at the integration floor — its
/// tolerances can tighten no further — that misses grows its model only then
/// ([`tolerance_model`]); with a larger integration part no model the rounds can build meets TOL.
fn room_for_the_model(estimate: &RunEstimate, on: Quantities, tol: f64) -> bool {
    let share = (1.0 - SELECTION_MARGIN * SELECTION_MARGIN).sqrt() * tol;
    estimate.integration.is_some_and(|i| worst(&i, on) <= share)
}

/// The fixed parts of a [`tolerance_model`] search: the model, its fixed-interface problem and
/// joint flexibility, the controlled quantities and the tolerance.
struct Search<'a> {
    model: &'a Model,
    fixed: &'a FixedInterface,
    flex: &'a JointFlexibility,
    on: Quantities,
    tol: f64,
}

impl Search<'_> {
    /// A round's run of `rom` at `transient` and its estimate with the re-runs it makes (module
    /// docs), given whether it ranks (its estimate then its joint part alone), speculates (its
    /// checks beside its run) and makes the two separate checks rather than the combined one.
    /// Returns the scene, the run, the estimate, where the re-runs were made and the combined
    /// part as made ([`round_checks`]).
    fn run_round(
        &self,
        rom: &ReducedSystem,
        transient: &TransientOptions,
        (ranking, speculate, separate): (bool, bool, bool),
    ) -> Result<(Scene, Run, RunEstimate, ReRuns, Option<f64>), Error> {
        let (model, on, tol) = (self.model, self.on, self.tol);
        let scene = Scene::of(model);
        // A round expected to be the result makes its two checks beside its run (on a second
        // core); any other round makes them after its correction, only if it may be the result.
        let checks = match (speculate, separate) {
            (false, _) => Checks::NONE,
            (true, true) => Checks::BOTH,
            (true, false) => Checks::COMBINED,
        };
        let (run, estimate) = run_estimated_parts(
            model,
            self.flex,
            rom.clone(),
            &scene,
            transient,
            checks,
            !ranking,
            |_, _| {},
        )?;
        let run = run.into_result()?;
        let mut estimate = estimate?;
        let candidate = !ranking && worst(&estimate.reduction, on) <= tol;
        let recheck = (rom, &run, &scene, transient);
        let flags = (speculate, candidate);
        let (made, combined) = round_checks(model, recheck, &mut estimate, flags, on, tol)?;
        Ok((scene, run, estimate, made, combined))
    }

    /// Grows a round's model where its estimate's parts exceed their shares: the attachment
    /// modes the joint parts ask for ([`Chosen::enrich`]), else ν by [`NU_STEP`] where the
    /// truncation part (the correction's, or the truncation check's over the controlled
    /// quantities) exceeds θ·TOL. The truncated modes are driven by the run's contact forces:
    /// while those are wrong the truncation part is too, so ν grows only once the joint parts
    /// are within their shares. `nu` and the Craig–Bampton base `cb` grow together, and the
    /// estimator then holds the modes beyond the new ν.
    fn grow(
        &self,
        chosen: &mut Chosen,
        (nu, cb): (&mut usize, &mut faer::Mat<f64>),
        estimate: &RunEstimate,
    ) -> Result<Enriched, Error> {
        let (on, tol) = (self.on, self.tol);
        let enriched = chosen.enrich(estimate, on, tol, cb.ncols());
        if enriched.changed {
            return Ok(enriched);
        }
        let part = SELECTION_MARGIN * tol;
        let truncated = estimate
            .detail
            .truncation
            .unwrap_or(0.0)
            .max(estimate.truncation.map_or(0.0, |t| worst(&t, on)));
        if truncated > part && *nu + NU_STEP <= max_nu(self.model) {
            *nu += NU_STEP;
            *cb = craig_bampton_with(self.model, *nu, self.fixed)?;
            self.flex.hold_truncation_modes(truncated_modes_for(*nu));
            return Ok(Enriched {
                changed: true,
                complete: true,
            });
        }
        Ok(enriched)
    }
}

/// The integration check of a round that may be the result and made none (`recheck` its
/// system, run, scene and transient options), added to its `estimate` and its record `last`.
fn result_integration_check(
    model: &Model,
    (rom, run, scene, opts): (&ReducedSystem, &Run, &Scene, &TransientOptions),
    estimate: &mut RunEstimate,
    on: Quantities,
    last: Option<&mut Round>,
) -> Result<(), Error> {
    let start = Instant::now();
    add_checks(
        model,
        estimate,
        run,
        rom.clone(),
        scene,
        opts,
        Checks::INTEGRATION,
    )?;
    if let Some(last) = last {
        last.estimate_s += start.elapsed().as_secs_f64();
        last.checks = ReRuns::AfterCorrection;
        last.integration_check = estimate.integration.map(|i| worst(&i, on));
    }
    Ok(())
}

/// The joint flexibility, the fixed-interface problem and Craig–Bampton with ν modes, the first
/// beside the other two; Craig–Bampton's factorization serves the estimate's truncated modes.
fn setup(
    model: &Model,
    nu: usize,
) -> Result<(JointFlexibility, Arc<FixedInterface>, faer::Mat<f64>), Error> {
    let (flex, cb) = beside(
        || JointFlexibility::new(model),
        || -> Result<_, Error> {
            let fixed = FixedInterface::new(model)?;
            let cb = craig_bampton_with(model, nu, &fixed)?;
            Ok((Arc::new(fixed), cb))
        },
    );
    let (flex, (fixed, cb)) = (flex?, cb?);
    flex.share_fixed_interface(Arc::clone(&fixed));
    Ok((flex, fixed, cb))
}

/// The re-runs of a round (module docs), given as its system, run, scene and transient options:
/// a round whose correction meets the tolerance (`candidate`) may be the result, so it gets the
/// combined check (one re-run both richer and tighter) — already made beside the run when
/// `speculate`. If the total with it meets `tol` on the quantities `on`, that is the result's
/// estimate; if not, the two separate checks replace it, and their parts decide between more
/// fixed-interface modes and tighter integration. A round whose own estimate says the combined
/// check would miss ([`combined_may_meet`]) makes the two separate checks at once (beside its
/// run, if the last estimate said so). Checks made beside the run of a round that is no
/// candidate are dropped, all but the integration part. Returns where the re-runs were made,
/// and the combined part as made.
fn round_checks(
    model: &Model,
    (rom, run, scene, opts): (&ReducedSystem, &Run, &Scene, &TransientOptions),
    estimate: &mut RunEstimate,
    (speculate, candidate): (bool, bool),
    on: Quantities,
    tol: f64,
) -> Result<(ReRuns, Option<f64>), Error> {
    if !candidate {
        let made = if speculate {
            drop_truncation(estimate);
            drop_combined(estimate);
            ReRuns::Dropped
        } else {
            ReRuns::None
        };
        return Ok((made, None));
    }
    if !speculate {
        if !combined_may_meet(worst(&estimate.reduction, on), estimate, tol, opts) {
            add_checks(model, estimate, run, rom.clone(), scene, opts, Checks::BOTH)?;
            return Ok((ReRuns::AfterCorrection, None));
        }
        add_combined_check(model, estimate, run, rom.clone(), scene, opts)?;
    }
    let combined = estimate.combined.map(|c| worst(&c, on));
    let made = if speculate {
        ReRuns::BesideRun
    } else {
        ReRuns::AfterCorrection
    };
    if combined.is_none() || worst(&estimate.total, on) <= tol {
        return Ok((made, combined));
    }
    drop_combined(estimate);
    add_checks(model, estimate, run, rom.clone(), scene, opts, Checks::BOTH)?;
    Ok((ReRuns::Separated, combined))
}

/// Whether a run at `opts` with the reduction part `reduction` and the first-order truncation
/// part of `estimate` (its correction's, of ‖f_c‖) gets the combined check:
///
/// - only at rtol above the paper's and up to [`COMBINED_CHECK_MAX_LOOSENESS`]× it, where the
///   integration check is a tighter re-run ([`super::estimate::check_factor`] < 1): the
///   combined check reads the integration error from two *different* models' runs (the run and
///   the richer model √10 tighter), which holds only where each model's error follows the BDF2
///   law in its tolerance. Looser, both runs' errors are dominated by the same stick–slip
///   transitions shifted alike, and the re-run's own error no longer shrinks with its tolerance
///   (the lap joint at TOL 1e-1, rtol 1e-6: the combined check read ‖f_R‖ at 6.5e-3 against a
///   true 1.4e-2, the separate checks 1.6e-2). At the paper's tolerances the integration check
///   is 2× looser and would read the richer model's looser error, and there the integration
///   part is what decides whether a tolerance is met at all (the 1e-3 models: the combined
///   check missed on the friction bar and the lap joint, a third re-run for nothing);
/// - only where it may accept: it reads the truncation error [`integration_scale`] times as
///   large as the truncation check does (1.87 at the tolerance model's √10 tighter re-run), so
///   where the reduction part with the truncation part read that large already exceeds `tol`,
///   it would miss and the two separate re-runs would follow it.
///
/// A round's own estimate decides for checks made after its correction; the last round's, with
/// the reduction part expected within its share, for checks made beside the run.
fn combined_may_meet(
    reduction: f64,
    estimate: &RunEstimate,
    tol: f64,
    opts: &TransientOptions,
) -> bool {
    if check_factor(opts) >= 1.0
        || opts.ode.rtol > COMBINED_CHECK_MAX_LOOSENESS * PAPER_RTOL * (1.0 + 1e-9)
    {
        return false;
    }
    let truncation = estimate.detail.truncation.unwrap_or(0.0) * integration_scale(opts);
    reduction.hypot(truncation) <= tol
}

/// The loosest integration at which the tolerance model makes the combined check: rtol (and
/// atol) at most this many times the paper's (module docs) — with friction, the
/// tolerances of TOL 1e-2 (and those of TOL 1e-2 to 1e-3 without).
pub const COMBINED_CHECK_MAX_LOOSENESS: f64 = 10.0;

/// CPU time of the process (every thread), s (NaN where unavailable).
fn process_cpu_s() -> f64 {
    cpu_time::ProcessTime::try_now()
        .map(|t| t.as_duration().as_secs_f64())
        .unwrap_or(f64::NAN)
}

/// The quantities a tolerance model controls: `asked` (`None`: all the run produces), checked
/// against the run (‖f_R‖ and D need friction).
///
/// # Errors
/// [`RomError::ToleranceOnFriction`] for ‖f_R‖ or D asked of a run without friction.
pub fn controlled_quantities(
    asked: Option<Quantities>,
    friction: bool,
) -> Result<Quantities, Error> {
    match asked {
        None if friction => Ok(Quantities::ALL),
        None => Ok(Quantities::ALL.without_friction()),
        Some(q) if q.is_empty() => Err(RomError::ToleranceOnEmpty.into()),
        Some(q) => match q.iter().find(|q| q.needs_friction() && !friction) {
            Some(bad) => Err(RomError::ToleranceOnFriction {
                name: bad.name(),
                what: match bad {
                    Quantity::FrictionForce => "friction force |f_R|",
                    _ => "dissipated energy D",
                },
            }
            .into()),
            None => Ok(q),
        },
    }
}

/// The largest of the errors of the quantities `on` (0 for those not estimated).
pub fn worst(errors: &CurveErrors, on: Quantities) -> f64 {
    on.iter()
        .map(|q| errors.of(q).unwrap_or(0.0))
        .fold(0.0, f64::max)
}

/// The joint part of a tolerance model's basis: the pairs whose normal attachment modes it
/// holds, and the tangential attachment modes (pair, direction) it holds.
#[derive(Clone, Debug, Default)]
struct Chosen {
    /// Pairs with their normal attachment mode, ascending.
    pairs: Vec<usize>,
    /// Pairs with tangential attachment modes, in the order added (a pair at most twice: its
    /// main direction of friction, then the one across it).
    tangential: Vec<usize>,
    /// The directions of `tangential`, unit vectors in the pairs' (t1, t2) planes.
    directions: Vec<[f64; 2]>,
}

impl Chosen {
    /// Adds the attachment modes the estimate of a round that missed `tol` asks for (module
    /// docs, "Choosing S"): normal ones while the joint part of the ‖f_c‖ estimate (or of u_y)
    /// exceeds its share and a controlled quantity depends on the normal forces, tangential ones
    /// while the joint part of the ‖f_R‖ estimate exceeds its share and ‖f_R‖ or D is
    /// controlled — in a round that adds normal ones only those the stick shares ask for, and
    /// only once the normal part is within `tol`. Returns whether anything was added, and
    /// whether that is all the estimate asked for (no cap cut the selection, no tangential
    /// modes wait for the normal ones).
    fn enrich(
        &mut self,
        estimate: &RunEstimate,
        on: Quantities,
        tol: f64,
        cb_size: usize,
    ) -> Enriched {
        let d = &estimate.detail;
        let part = SELECTION_MARGIN * tol;
        let normal_matters = [
            Quantity::ContactForce,
            Quantity::FrictionForce,
            Quantity::Dissipation,
        ]
        .into_iter()
        .any(|q| on.contains(q));
        let wants_normal = (normal_matters && d.joint.unwrap_or(0.0) > part)
            || (on.contains(Quantity::MasterUy)
                && estimate.reduction.master_uy.unwrap_or(0.0) > part);
        let mut changed = false;
        let mut complete = false;
        let friction_matters =
            on.contains(Quantity::FrictionForce) || on.contains(Quantity::Dissipation);
        let wants_tangential = friction_matters && d.joint_friction.unwrap_or(0.0) > part;
        if wants_normal {
            if let Some((add, all)) = more_pairs(
                &d.pair_error,
                d.corrected_joint_norm2,
                |k| self.pairs.contains(&k),
                tol,
                self.pairs.len().max(cb_size),
            ) {
                self.pairs.extend(add);
                self.pairs.sort_unstable();
                changed = true;
                complete = all && !wants_tangential;
            }
        }
        // The cone of a sliding pair's friction force is μ|p_n|: while the normal forces are
        // being corrected, the errors of the sliding friction forces are theirs, so tangential
        // modes wait for them. A sticking pair's force is its elastic stretch, which the
        // tangential compliance at the pair sets and normal modes do not add: once the normal
        // forces are within the tolerance (and so their coupling into the stick forces), the
        // stick part of the tangential shares joins the round.
        if changed && wants_tangential && d.joint.unwrap_or(f64::INFINITY) <= tol {
            self.add_tangential(d, &d.pair_stick_error, tol, cb_size);
        }
        if !changed && wants_tangential {
            if let Some(all) = self.add_tangential(d, &d.pair_tangential_error, tol, cb_size) {
                changed = true;
                complete = all;
            }
        }
        // D is a sum over the pairs of what each dissipates: where its estimate misses while
        // the forces are within their shares, the pairs that dissipate wrongly get their normal
        // attachment mode first (their friction limit μ|p_n| and so their share of the slip),
        // then tangential ones (the structure's tangential compliance at the pair).
        let dissipation = [
            estimate.reduction.dissipated,
            estimate.reduction.dissipated_end,
        ]
        .into_iter()
        .flatten()
        .fold(0.0, f64::max);
        if !changed && on.contains(Quantity::Dissipation) && dissipation > part {
            let scores = dissipation_shares(d);
            let tangential = &self.tangential;
            let held = |k: usize| tangential.iter().filter(|&&j| j == k).count();
            let pairs = &self.pairs;
            if let Some((add, all)) = more_pairs_summed(
                &scores,
                |k| pairs.contains(&k) && held(k) >= 2,
                tol,
                (self.pairs.len() + self.tangential.len()).max(cb_size),
            ) {
                for k in add {
                    if !self.pairs.contains(&k) {
                        self.pairs.push(k);
                        continue;
                    }
                    let main = main_direction(d.pair_tangential_moment[k]);
                    let first = !self.tangential.contains(&k);
                    self.directions
                        .push(if first { main } else { [-main[1], main[0]] });
                    self.tangential.push(k);
                }
                self.pairs.sort_unstable();
                changed = true;
                complete = all;
            }
        }
        Enriched { changed, complete }
    }

    /// Adds the tangential attachment modes that the tangential shares `shares` (per pair, N²,
    /// against the joint-only correction's `Σ_t ‖p_t*‖²`) ask for, by the rule of the normal
    /// ones: a pair's main direction of friction first, the direction across it in a later
    /// round. Returns whether anything was added and whether that is all the shares ask for.
    fn add_tangential(
        &mut self,
        d: &crate::reduction::Estimate,
        shares: &[f64],
        tol: f64,
        cb_size: usize,
    ) -> Option<bool> {
        let tangential = &self.tangential;
        let held = |k: usize| tangential.iter().filter(|&&j| j == k).count();
        let (add, all) = more_pairs(
            shares,
            d.corrected_joint_friction_norm2,
            |k| held(k) >= 2,
            tol,
            self.tangential.len().max(cb_size),
        )?;
        let first: Vec<bool> = add.iter().map(|&k| held(k) == 0).collect();
        for (k, first) in add.into_iter().zip(first) {
            let main = main_direction(d.pair_tangential_moment[k]);
            self.directions
                .push(if first { main } else { [-main[1], main[0]] });
            self.tangential.push(k);
        }
        Some(all)
    }
}

/// Each pair's relative share of the error of D: the larger of `‖D_k − D_k*‖_L2 / ‖D*‖_L2`
/// and `|D_k(T) − D_k*(T)| / |D*(T)|` ([`Estimate::pair_dissipation_error`]). Their sum over
/// any set of pairs bounds what those pairs contribute to either measure of D's error.
fn dissipation_shares(d: &crate::reduction::Estimate) -> Vec<f64> {
    let norm = d
        .corrected_dissipated
        .iter()
        .map(|v| v * v)
        .sum::<f64>()
        .sqrt();
    let end = d.corrected_dissipated.last().map_or(0.0, |v| v.abs());
    d.pair_dissipation_error
        .iter()
        .zip(&d.pair_dissipation_end)
        .map(|(e2, e_end)| {
            let over = if norm > 0.0 { e2.sqrt() / norm } else { 0.0 };
            let at_end = if end > 0.0 { e_end.abs() / end } else { 0.0 };
            over.max(at_end)
        })
        .collect()
}

/// The pairs to add by shares that bound the error by their sum: the fewest, largest first, that
/// leave `Σ_{k left} share_k ≤ θ · TOL`, at most `cap` of them, and whether that is all of them.
/// `None` when no pair outside the `held` ones has a share.
fn more_pairs_summed(
    shares: &[f64],
    held: impl Fn(usize) -> bool,
    tol: f64,
    cap: usize,
) -> Option<(Vec<usize>, bool)> {
    select_largest(shares, held, SELECTION_MARGIN * tol, cap)
}

/// What [`Chosen::enrich`] did.
#[derive(Clone, Copy, Debug)]
struct Enriched {
    /// Attachment modes were added.
    changed: bool,
    /// They are all the estimate asked for: the next round is expected to meet the tolerance.
    complete: bool,
}

/// The principal direction of the moments `[Σ p_1², Σ p_1 p_2, Σ p_2²]` of a pair's tangential
/// force (t1 when they vanish).
fn main_direction(m: [f64; 3]) -> [f64; 2] {
    let angle = 0.5 * (2.0 * m[1]).atan2(m[0] - m[2]);
    [angle.cos(), angle.sin()]
}

/// The first round's run (Craig–Bampton alone) is at this many times looser rtol and atol: its
/// estimate only ranks the pairs (module docs, "Choosing S").
pub const RANKING_LOOSENING: f64 = 10.0;

/// Fixed-interface modes added to ν when the truncation part of the estimate exceeds its share
/// (the paper's ν = 10 at a time; the truncation check then measures the modes beyond the new
/// ν again).
pub const NU_STEP: usize = 10;

/// The largest ν the enrichment uses: [`MAX_NU`], and no more than leaves the estimate
/// [`TRUNCATION_BEYOND`] modes to check beyond the basis.
fn max_nu(model: &Model) -> usize {
    MAX_NU.min((model.dofs().saturating_sub(6) / 2).saturating_sub(TRUNCATION_BEYOND))
}

/// The most fixed-interface modes a tolerance model grows to (the estimate then holds
/// [`truncated_modes_for`]`(ν)` of them): beyond it, the scene's motion is not one a
/// Craig–Bampton base of the joint's interface reduces well.
pub const MAX_NU: usize = 100;

/// The reduced system on Craig–Bampton plus the attachment modes of `pairs`.
pub fn reduced_on_pairs(
    model: &Model,
    cb: &faer::Mat<f64>,
    flex: &JointFlexibility,
    pairs: &[usize],
) -> Result<ReducedSystem, Error> {
    let chosen = Chosen {
        pairs: pairs.to_vec(),
        ..Chosen::default()
    };
    reduced_on(model, cb, flex, &chosen, &mut BasisCache::new(model))
}

/// A column of a tolerance model's basis before its M-orthonormalization.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Column {
    /// Column `j` of the Craig–Bampton basis with `cols` columns (6 + ν).
    CraigBampton { cols: usize, j: usize },
    /// The normal attachment mode of a pair.
    Normal(usize),
    /// The tangential attachment mode of a pair in a direction (its bits).
    Tangential(usize, [u64; 2]),
}

/// What successive rounds' bases share: their leading columns (Craig–Bampton, and the
/// attachment modes while only later ones change), orthonormalized once — the modified
/// Gram–Schmidt's state after a column does not depend on the columns after it — and the
/// attachment modes solved so far (a column's refined solve has the same bits alone as in a
/// block). Every basis is the one [`crate::reduction::final_basis`] gives of all its columns,
/// bit for bit.
struct BasisCache<'m> {
    /// The orthonormalization of the last basis's columns `keys`, in order.
    gs: Orthonormalizer<'m>,
    keys: Vec<Column>,
    /// Attachment modes solved so far (n values each).
    solved: HashMap<Column, Vec<f64>>,
}

impl<'m> BasisCache<'m> {
    fn new(model: &'m Model) -> BasisCache<'m> {
        BasisCache {
            gs: Orthonormalizer::new(&model.mass, DEFAULT_DROP_TOL),
            keys: Vec::new(),
            solved: HashMap::new(),
        }
    }

    /// The M-orthonormal basis of the columns `keys` (before the rotation), orthonormalizing
    /// only those after the prefix it shares with the last basis, and solving only the
    /// attachment modes not solved before.
    fn basis(
        &mut self,
        cb: &faer::Mat<f64>,
        flex: &JointFlexibility,
        keys: Vec<Column>,
    ) -> Result<faer::Mat<f64>, Error> {
        let common = self
            .keys
            .iter()
            .zip(&keys)
            .take_while(|(a, b)| a == b)
            .count();
        self.gs.truncate(common);
        self.keys.truncate(common);
        let missing = |want: fn(&Column) -> bool| -> Vec<Column> {
            let mut out: Vec<Column> = keys[common..]
                .iter()
                .filter(|c| want(c) && !self.solved.contains_key(c))
                .copied()
                .collect();
            out.dedup();
            out
        };
        let normal = missing(|c| matches!(c, Column::Normal(_)));
        let tangential = missing(|c| matches!(c, Column::Tangential(..)));
        let pairs: Vec<usize> = normal
            .iter()
            .filter_map(|c| match c {
                Column::Normal(k) => Some(*k),
                _ => None,
            })
            .collect();
        let directions: Vec<(usize, [f64; 2])> = tangential
            .iter()
            .filter_map(|c| match c {
                Column::Tangential(k, d) => Some((*k, d.map(f64::from_bits))),
                _ => None,
            })
            .collect();
        let att = flex.attachment_modes(&pairs);
        let tan = flex.tangential_attachment_modes(&directions);
        for (cols, modes) in [(&normal, &att), (&tangential, &tan)] {
            for (j, c) in cols.iter().enumerate() {
                self.solved
                    .insert(*c, modes.col(j).iter().copied().collect());
            }
        }
        for key in &keys[common..] {
            let v = match key {
                Column::CraigBampton { j, .. } => cb.col(*j).iter().copied().collect(),
                other => self.solved[other].clone(),
            };
            self.gs.push(v)?;
            self.keys.push(*key);
        }
        Ok(self.gs.basis())
    }
}

/// The reduced system on Craig–Bampton plus the normal and tangential attachment modes of
/// `chosen` ([`BasisCache`]: the columns it shares with the last basis are not orthonormalized
/// again).
fn reduced_on(
    model: &Model,
    cb: &faer::Mat<f64>,
    flex: &JointFlexibility,
    chosen: &Chosen,
    cache: &mut BasisCache<'_>,
) -> Result<ReducedSystem, Error> {
    let cols = cb.ncols();
    let keys: Vec<Column> = (0..cols)
        .map(|j| Column::CraigBampton { cols, j })
        .chain(chosen.pairs.iter().map(|&k| Column::Normal(k)))
        .chain(
            chosen
                .tangential
                .iter()
                .zip(&chosen.directions)
                .map(|(&k, d)| Column::Tangential(k, d.map(f64::to_bits))),
        )
        .collect();
    let phi = cache.basis(cb, flex, keys)?;
    let (phi, _) = modal_rotation(model, phi)?;
    ReducedSystem::new(model, phi)
}

/// The pairs to add after a round whose estimate missed `tol` (module docs, step 3): ranked by
/// their shares `errors` of the estimate (N², against the corrected curve's `norm2`), those not
/// `held` already, at most `cap` of them; `None` when no pair outside carries any of the error.
/// The flag says whether the pairs left out are within their share (the cap did not cut).
fn more_pairs(
    errors: &[f64],
    norm2: f64,
    held: impl Fn(usize) -> bool,
    tol: f64,
    cap: usize,
) -> Option<(Vec<usize>, bool)> {
    select_largest(errors, held, (SELECTION_MARGIN * tol).powi(2) * norm2, cap)
}

/// The pairs outside the `held` ones with a positive share, largest first, until the sum of the
/// shares left is within `allowed` or `cap` are taken, and whether that is all of them (the cap
/// did not cut); `None` when nothing is taken. The one greedy rule of [`more_pairs`] (squared
/// shares of a norm) and [`more_pairs_summed`] (shares that add).
fn select_largest(
    shares: &[f64],
    held: impl Fn(usize) -> bool,
    allowed: f64,
    cap: usize,
) -> Option<(Vec<usize>, bool)> {
    let mut cand: Vec<(usize, f64)> = shares
        .iter()
        .enumerate()
        .filter(|(k, e)| **e > 0.0 && !held(*k))
        .map(|(k, e)| (k, *e))
        .collect();
    cand.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
    let mut left: f64 = cand.iter().map(|c| c.1).sum();
    let mut add = Vec::new();
    for (k, e) in cand {
        if left <= allowed || add.len() >= cap {
            break;
        }
        add.push(k);
        left -= e;
    }
    let all = left <= allowed;
    (!add.is_empty()).then_some((add, all))
}

/// The tolerance-chosen model of the contact statics ([`static_tolerance_model`]).
pub struct StaticTolerance {
    /// The chosen pairs, by decreasing force in the exact solution.
    pub pairs: Vec<usize>,
    /// Basis size r.
    pub basis_size: usize,
    /// The reduced solution.
    pub solution: ReducedStatic,
    /// The relative error of its ‖f_c‖ against the pair-space solution (exact: the full
    /// model's, see [`crate::reduction::estimate`]).
    pub error: f64,
    /// ‖f_c‖ of the pair-space (full) solution, N.
    pub exact_norm: f64,
    /// Wall time, s.
    pub wall_s: f64,
}

/// The smallest Craig–Bampton (ν) + attachment-mode model whose static ‖f_c‖ under the case
/// load × `scale` is within `tol` (relative) of the full model's: the pair-space solution
/// ([`JointFlexibility::static_contact_forces`], exact) ranks the pairs in contact by force, and
/// the largest are added one at a time until the reduced ‖f_c‖ meets `tol` (with all of them
/// the reduced statics are exact). The error reported is exact, not estimated.
pub fn static_tolerance_model(
    model: &Model,
    tol: f64,
    nu: usize,
    scale: f64,
) -> Result<StaticTolerance, Error> {
    check_tolerance(tol)?;
    let start = Instant::now();
    let load = scaled_load(model, scale)?;
    let flex = JointFlexibility::new(model)?;
    let exact = flex.static_contact_forces(load)?;
    let exact_norm = exact.iter().map(|p| p * p).sum::<f64>().sqrt();
    let mut ranked: Vec<usize> = (0..exact.len()).filter(|&k| exact[k] != 0.0).collect();
    ranked.sort_by(|&a, &b| exact[a].abs().total_cmp(&exact[b].abs()).reverse());
    let cb = craig_bampton(model, nu)?;
    let mut bases = BasisCache::new(model);
    let mut m = 0;
    loop {
        let chosen = Chosen {
            pairs: ranked[..m].to_vec(),
            ..Chosen::default()
        };
        let rom = reduced_on(model, &cb, &flex, &chosen, &mut bases)?;
        let (solution, _) =
            reduced_contact_static_restarting(model, &rom, scale, &ContactOptions::default())?;
        let got = solution.state.contact_force_norm;
        let error = if exact_norm > 0.0 {
            (got - exact_norm).abs() / exact_norm
        } else {
            got
        };
        if error <= tol || m == ranked.len() {
            return Ok(StaticTolerance {
                pairs: ranked[..m].to_vec(),
                basis_size: rom.dim(),
                solution,
                error,
                exact_norm,
                wall_s: start.elapsed().as_secs_f64(),
            });
        }
        m += 1;
    }
}

/// A tolerance must be a relative error in (0, 1).
pub fn check_tolerance(tol: f64) -> Result<(), Error> {
    if tol.is_finite() && tol > 0.0 && tol < 1.0 {
        Ok(())
    } else {
        Err(RomError::Tolerance { tolerance: tol }.into())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn force_floor_follows_the_force_scale() {
        let k_n = 1e4;
        // The friction bar's corrected ‖f_c*‖ over its 2 001 outputs, F ≈ 69 N: k_n·atol =
        // θ·TOL·F at 3.45e-5 mm, looser than TOL 1e-2's atol with friction (1e-5): no cap.
        let bar = force_floor_atol(1e-2, 69.0_f64.powi(2), k_n).unwrap();
        assert!((bar - 3.45e-5).abs() < 1e-15, "{bar}");
        let opts = loosened(&TransientOptions::default(), 10.0);
        let kept = capped(opts.clone(), Some(bar));
        assert_eq!(kept.ode.atol, opts.ode.atol);
        assert_eq!(kept.ode.rtol, opts.ode.rtol);
        // Forces 100× smaller: the floor 100× tighter, and it caps the atol (not the rtol).
        let small = force_floor_atol(1e-2, 0.69_f64.powi(2), k_n).unwrap();
        assert!((bar / small - 100.0).abs() < 1e-9, "{small}");
        let tight = capped(opts.clone(), Some(small));
        assert_eq!(tight.ode.atol, small);
        assert_eq!(tight.ode.rtol, opts.ode.rtol);
        // Linear in TOL, inverse in k_n; no contact, no floor.
        let half = force_floor_atol(5e-3, 69.0_f64.powi(2), 2.0 * k_n).unwrap();
        assert!((bar / half - 4.0).abs() < 1e-12);
        assert!(force_floor_atol(1e-2, 0.0, k_n).is_none());
        assert!(force_floor_atol(1e-2, f64::NAN, k_n).is_none());
        assert_eq!(capped(opts.clone(), None).ode.atol, opts.ode.atol);
    }

    /// A round of the same model at `rtol`, `atol` with integration part `part`.
    fn round_at(rtol: f64, atol: f64, part: Option<f64>) -> Round {
        Round {
            pairs: 13,
            tangential_pairs: 9,
            nu: 10,
            basis_size: 38,
            estimate: None,
            friction_estimate: None,
            joint: None,
            joint_friction: None,
            truncation: None,
            truncation_check: None,
            combined_check: None,
            wall_s: 0.0,
            steps: 1,
            rtol,
            atol,
            integration_check: part,
            basis_s: 0.0,
            estimate_s: 0.0,
            ranking: false,
            checks: ReRuns::BesideRun,
        }
    }

    #[test]
    fn a_tightening_stalls_only_where_its_part_does_not_fall() {
        let before = round_at(1e-7, 1e-5, Some(4.1e-2));
        // The ringing joint: atol halved, the part grew — above the tolerance by itself.
        let s = IntegrationStall::of(&before, &round_at(1e-7, 5.2e-6, Some(5.1e-2)), 1e-2);
        let s = s.expect("a stall");
        assert!(s.ended && s.part == [4.1e-2, 5.1e-2] && s.atol == [1e-5, 5.2e-6]);
        // The same within the tolerance: a stall that does not end the search.
        let low = round_at(1e-7, 1e-5, Some(4.1e-3));
        let s = IntegrationStall::of(&low, &round_at(1e-8, 1e-6, Some(4.1e-3)), 1e-2);
        assert!(!s.expect("a stall").ended);
        // A part that fell, even by less than the tightening: converging.
        let fell = round_at(1e-7, 2.5e-6, Some(1.0e-2));
        assert!(IntegrationStall::of(&round_at(1e-7, 1e-5, Some(1.5e-2)), &fell, 1e-2).is_none());
        // A tightening too small to judge (the stick floor just below the atol), or a part
        // not measured (the combined check): no decision.
        let small = round_at(1e-7, 8.6e-6, Some(5e-2));
        assert!(IntegrationStall::of(&before, &small, 1e-2).is_none());
        let combined = round_at(1e-8, 1e-6, None);
        assert!(IntegrationStall::of(&before, &combined, 1e-2).is_none());
    }

    #[test]
    fn summed_selection_adds_the_largest_shares_until_the_rest_fits() {
        // θ·TOL = 0.5e-2: the rest after adding 0 (4e-3 + 2e-3 + 1e-3 = 7e-3) misses, after
        // adding 0 and 3 (3e-3) it fits; pair 1 is held.
        let shares = [6e-3, 9e-3, 1e-3, 4e-3, 2e-3, 0.0];
        let (add, all) = more_pairs_summed(&shares, |k| k == 1, 1e-2, 10).unwrap();
        assert_eq!(add, vec![0, 3]);
        assert!(all);
        // The cap stops it short, and says so.
        let (add, all) = more_pairs_summed(&shares, |k| k == 1, 1e-2, 1).unwrap();
        assert_eq!(add, vec![0]);
        assert!(!all);
        // Nothing outside the held pairs carries a share: nothing to add.
        assert!(more_pairs_summed(&shares, |k| k != 5, 1e-2, 10).is_none());
        // Already within its share: nothing to add.
        assert!(more_pairs_summed(&[1e-3, 2e-3], |_| false, 1e-2, 10).is_none());
    }
}
