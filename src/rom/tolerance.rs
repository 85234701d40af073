//! Error-controlled reduction: a tolerance on the joint forces in, the smallest reduced model that
//! meets it out, with the estimate of [`super::estimate`] attached to every reduced run.
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
//! picks worse pairs on refined meshes.
//!
//! Pairs that never carry force in either the run or the correction have `e_k = 0` and are never
//! added: the model keeps only the joint directions the scene uses. The estimate's truncation
//! part (the dynamics of the fixed-interface modes beyond ν) is not removed by pairs: when it
//! exceeds θ·TOL once the joint part is within its share, ν grows by [`NU_STEP`] (up to
//! `TRUNCATION_MODES − NU_STEP`). The truncated modes are driven by the run's own contact forces,
//! so while those are wrong the truncation part is inflated by orders of magnitude: growing ν in
//! the same round as the pairs would make every model [`NU_STEP`] columns larger for nothing.
//! The rounds' e_k come from the joint part alone, so truncation does not masquerade as pair
//! error.
//!
//! The last round's run is the result; its estimate then gains the integration part
//! ([`super::estimate::integration_errors`]: one more run at 2× looser tolerances, its difference scaled to this
//! run's error by the BDF2 error model — that run does not depend on the one it checks, so every
//! round at the user's tolerances starts it beside its own run on a second thread, and a round
//! that is not the last discards it), and `met` says whether the
//! total meets TOL. When it does not — nothing left to add, or the integration error of the
//! user's tolerances above TOL — the best model is returned with `met = false` (the CLI warns;
//! tighter `--rtol/--atol` lower the integration floor).

use std::time::Instant;

use serde::Serialize;

use crate::error::{Error, RomError};
use crate::integrate::{Run, TransientOptions};
use crate::joint::statics::ContactOptions;
use crate::model::Model;
use crate::reduction::estimate::TRUNCATION_MODES;
use crate::reduction::{
    craig_bampton, final_basis, modal_rotation, Estimate, JointFlexibility, DEFAULT_DROP_TOL,
};
use crate::rom::estimate::{beside, loosened, run_estimated, RunEstimate};
use crate::rom::statics::{reduced_contact_static_restarting, scaled_load, ReducedStatic};
use crate::system::{ReducedSystem, Scene};

/// θ of the pair selection (module docs): the pairs left out may carry at most this fraction of
/// the tolerance.
pub const SELECTION_MARGIN: f64 = 0.5;

/// Options of [`tolerance_model`].
#[derive(Clone, Debug)]
pub struct ToleranceOptions {
    /// The tolerance on the relative L2 error of ‖f_c‖(t), in (0, 1).
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
}

/// Where the tolerance model's rtol and atol come from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum IntegrationTolerances {
    /// From the tolerance: the paper's Table 1 values loosened by [`integration_looseness`],
    /// tightened tenfold while the estimate misses the tolerance.
    #[default]
    FromTolerance,
    /// The transient options' own rtol and atol (the user gave them).
    Given,
}

/// The factor `s` on the paper's Table 1 rtol and atol (1e-8, 1e-6 mm) at which the tolerance
/// model of tolerance `tol` starts: `s = clamp(tol / 1e-4, 1, 1e4)` — ten times looser per
/// decade of tolerance above 1e-4, the paper's tolerances from 1e-4 down. The estimate, whose
/// integration part is a re-run ten times tighter ([`super::estimate::integration_errors`]),
/// checks the choice: while its total misses TOL, `s` drops tenfold and the model is re-run,
/// down to `s = 1`.
pub fn integration_looseness(tol: f64) -> f64 {
    (tol / 1e-4).clamp(1.0, 1e4)
}

impl ToleranceOptions {
    /// ν = 10 (the paper), the default transient options, at most 8 rounds.
    pub fn new(tolerance: f64) -> ToleranceOptions {
        ToleranceOptions {
            tolerance,
            nu: 10,
            transient: TransientOptions::default(),
            max_rounds: 8,
            integration: IntegrationTolerances::FromTolerance,
        }
    }
}

/// One round of [`tolerance_model`].
#[derive(Clone, Debug, Serialize)]
pub struct Round {
    /// Pairs whose attachment modes the basis held.
    pub pairs: usize,
    /// Fixed-interface modes ν of the basis.
    pub nu: usize,
    /// Basis size r.
    pub basis_size: usize,
    /// The estimated relative L2 error of ‖f_c‖(t) (reduction part).
    pub estimate: Option<f64>,
    /// Its joint part (what more pairs remove).
    pub joint: Option<f64>,
    /// Its truncation part (what more fixed-interface modes remove).
    pub truncation: Option<f64>,
    /// Wall time of the round's run, s.
    pub wall_s: f64,
    /// Wall time of the round's basis and reduced system, s.
    pub basis_s: f64,
    /// Wall time of the round's estimate, s.
    pub estimate_s: f64,
    /// The round only ranked the pairs: its run at [`RANKING_LOOSENING`]× looser tolerances.
    pub ranking: bool,
}

/// The tolerance-chosen reduced model and its run.
pub struct ToleranceModel {
    /// The chosen pairs (indices into the model's joint pairs), ascending.
    pub pairs: Vec<usize>,
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
    /// Whether the estimate (both parts) meets the tolerance.
    pub met: bool,
    /// Every round, the last one the result.
    pub rounds: Vec<Round>,
    /// Wall time of everything before the result's run (factorization, Craig–Bampton, the
    /// flexibility, the earlier rounds' runs and estimates, the result's basis), s.
    pub offline_s: f64,
    /// Wall time of the result's estimate after its run: the quasi-static joint correction and
    /// the wait for the integration check (which runs beside the run on a second thread), s.
    pub estimate_s: f64,
    /// The transient options of the result's run (the integration tolerances chosen).
    pub transient: TransientOptions,
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
    /// The chosen number of fixed-interface modes ν.
    pub nu: usize,
    /// Wall time of the setup, s.
    pub setup_s: f64,
    /// Wall time of the result's estimate after its run, s.
    pub estimate_s: f64,
    /// Every round, the last one the result.
    pub rounds: Vec<Round>,
    /// The integration tolerances of the result's run: CVODE's rtol and atol (mm).
    pub rtol: f64,
    /// See `rtol`.
    pub atol: f64,
}

/// Builds the smallest Craig–Bampton + pair-attachment-mode model whose estimated ‖f_c‖(t)
/// error meets `opts.tolerance` (module docs).
///
/// # Errors
/// A tolerance outside (0, 1) or not finite ([`RomError::Tolerance`] naming it), a failing basis, a
/// run that does not finish or an estimate that cannot be made.
pub fn tolerance_model(model: &Model, opts: &ToleranceOptions) -> Result<ToleranceModel, Error> {
    let tol = opts.tolerance;
    check_tolerance(tol)?;
    let start = Instant::now();
    let mut nu = opts.nu;
    let (flex, cb) = beside(|| JointFlexibility::new(model), || craig_bampton(model, nu));
    let (flex, mut cb) = (flex?, cb?);
    let setup_s = start.elapsed().as_secs_f64();
    let mut pairs: Vec<usize> = Vec::new();
    let mut rounds = Vec::new();
    // The Craig–Bampton round only ranks the pairs: looser tolerances (module docs).
    let mut ranking = true;
    // The integration tolerances: the user's, or the paper's times s (integration_looseness).
    let mut looseness = match opts.integration {
        IntegrationTolerances::FromTolerance => integration_looseness(tol),
        IntegrationTolerances::Given => 1.0,
    };
    loop {
        let round_start = Instant::now();
        let rom = reduced_on_pairs(model, &cb, &flex, &pairs)?;
        let basis_s = round_start.elapsed().as_secs_f64();
        let transient = loosened(
            &opts.transient,
            looseness * if ranking { RANKING_LOOSENING } else { 1.0 },
        );
        // Any round at the user's tolerances may be the result: its integration check runs
        // beside it (on a second core; unused when the round is not the last).
        let (run, estimate) = run_estimated(
            model,
            &flex,
            rom.clone(),
            &Scene::of(model),
            &transient,
            !ranking,
            |_, _| {},
        )?;
        let run = run.into_result()?;
        let estimate = estimate?;
        let eta = estimate.reduction.contact_force.unwrap_or(0.0);
        let d = &estimate.detail;
        rounds.push(Round {
            pairs: pairs.len(),
            nu,
            basis_size: rom.dim(),
            estimate: estimate.reduction.contact_force,
            joint: d.joint,
            truncation: d.truncation,
            wall_s: run.wall_s,
            basis_s,
            estimate_s: round_start.elapsed().as_secs_f64() - basis_s - run.wall_s,
            ranking,
        });
        let mut changed = false;
        if eta > tol && rounds.len() < opts.max_rounds {
            let part = SELECTION_MARGIN * tol;
            if d.joint.unwrap_or(0.0) > part {
                if let Some(add) = more_pairs(d, &pairs, tol, cb.ncols()) {
                    pairs.extend(add);
                    pairs.sort_unstable();
                    changed = true;
                }
            }
            // The truncated modes are driven by the run's contact forces: while those are wrong
            // the truncation part is too, so ν grows only once the joint part is within its share.
            if !changed && d.truncation.unwrap_or(0.0) > part && nu + NU_STEP <= max_nu(model) {
                nu += NU_STEP;
                cb = craig_bampton(model, nu)?;
                changed = true;
            }
        }
        let was_ranking = std::mem::replace(&mut ranking, false);
        if !changed && was_ranking {
            // A ranking run is never the result: the same model again at the user's tolerances.
            continue;
        }
        // The estimate misses the tolerance at loosened integration tolerances: the same model
        // again, ten times tighter (the reduction part is within its share, or the loop would
        // have added pairs).
        let total = estimate.total.contact_force.unwrap_or(0.0);
        if !changed && looseness > 1.0 && estimate.integration.is_some() && total > tol {
            looseness = (looseness / 10.0).max(1.0);
            continue;
        }
        if !changed {
            let offline_s = (round_start - start).as_secs_f64() + basis_s;
            let estimate_s = rounds.last().map_or(0.0, |r| r.estimate_s);
            return Ok(ToleranceModel {
                pairs,
                nu,
                setup_s,
                rom,
                run,
                met: estimate.total.contact_force.unwrap_or(0.0) <= tol,
                estimate,
                rounds,
                offline_s,
                estimate_s,
                transient,
            });
        }
    }
}

/// The first round's run (Craig–Bampton alone) is at this many times looser rtol and atol: its
/// estimate only ranks the pairs (module docs, "Choosing S").
pub const RANKING_LOOSENING: f64 = 10.0;

/// Fixed-interface modes added to ν when the truncation part of the estimate exceeds its share.
pub const NU_STEP: usize = 10;

/// The largest ν the enrichment uses: [`TRUNCATION_MODES`] − [`NU_STEP`], so that the estimate
/// still checks [`NU_STEP`] modes beyond the basis.
fn max_nu(model: &Model) -> usize {
    TRUNCATION_MODES
        .saturating_sub(NU_STEP)
        .min(model.dofs().saturating_sub(6) / 2)
}

/// The reduced system on Craig–Bampton plus the attachment modes of `pairs`.
pub fn reduced_on_pairs(
    model: &Model,
    cb: &faer::Mat<f64>,
    flex: &JointFlexibility,
    pairs: &[usize],
) -> Result<ReducedSystem, Error> {
    let att = flex.attachment_modes(pairs);
    let (phi, _) = final_basis(&[cb.as_ref(), att.as_ref()], &model.mass, DEFAULT_DROP_TOL)?;
    let (phi, _) = modal_rotation(model, phi)?;
    ReducedSystem::new(model, phi)
}

/// The pairs to add after a round whose estimate missed `tol` (module docs, step 3), at most
/// `max(|S|, cb_size)` of them; `None` when no pair outside `pairs` carries any of the error.
fn more_pairs(est: &Estimate, pairs: &[usize], tol: f64, cb_size: usize) -> Option<Vec<usize>> {
    let mut cand: Vec<(usize, f64)> = est
        .pair_error
        .iter()
        .enumerate()
        .filter(|(k, e)| **e > 0.0 && !pairs.contains(k))
        .map(|(k, e)| (k, *e))
        .collect();
    if cand.is_empty() {
        return None;
    }
    cand.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
    let allowed = (SELECTION_MARGIN * tol).powi(2) * est.corrected_joint_norm2;
    let mut left: f64 = cand.iter().map(|c| c.1).sum();
    let mut add = Vec::new();
    // At most double the joint part per round, starting from the Craig–Bampton size.
    let cap = pairs.len().max(cb_size);
    for (k, e) in cand {
        if left <= allowed || add.len() >= cap {
            break;
        }
        add.push(k);
        left -= e;
    }
    (!add.is_empty()).then_some(add)
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
    let mut m = 0;
    loop {
        let rom = reduced_on_pairs(model, &cb, &flex, &ranked[..m])?;
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
