//! Compressed joint columns: the tolerance model's attachment modes replaced by the POD of the
//! deformation the joint forces actually cause ([`crate::reduction::joint_pod()`]).
//!
//! The per-pair model holds one normal attachment mode `z_k = K⁻¹ b_kᵀ` per chosen pair (and
//! tangential ones), so its size grows with the pairs the joint needs. The joint's deformation
//! is `Z_S p_S(t)`: the kept pairs' attachment modes weighted by their forces. Where neighbouring
//! pairs carry forces that rise and fall together (a closing contact patch, a weld's prying
//! ring), few combinations of their modes hold that deformation.
//!
//! Once the per-pair model meets the tolerance, its estimate's corrected pair forces
//! ([`crate::reduction::Estimate::corrected_pair_forces`], the forces the full model would carry
//! under the run's motion) are the snapshots `P` (kept pairs × outputs), and the POD of `Z_S P`
//! in the strain-energy norm beyond the Craig–Bampton part ([`crate::reduction::joint_pod()`],
//! Gram `G_SS − (B_S Φ_CB) K̃_CB⁻¹ (B_S Φ_CB)ᵀ` with `G_SS = B_S K⁻¹ B_Sᵀ`) gives the compressed
//! normal columns `Z_S c_j`; the tangential columns likewise, with the corrected tangential
//! forces along each column's direction.
//!
//! ## The rank
//!
//! The POD bounds the deformation left out; the tolerance is on forces, and a contact force is
//! a penalty stiffness times a gap. In the energy norm of the structure with the pairs' springs
//! closed, `‖x‖²_c = xᵀKx + k ‖Bx‖²` (k = k_n for the normal columns, k_t for the tangential
//! ones), the force error is bounded by the deformation error, `‖δp‖² = k² ‖B δx‖² ≤ k ‖δx‖²_c`,
//! while the forces hold only the spring part of their own deformation's energy,
//! `‖p‖² = k · (k ‖Bx‖²)`. Relative:
//!
//! ```text
//! ‖δp‖ / ‖p‖ ≤ κ · ‖δx‖_c / ‖x‖_c ,   κ² = ‖x‖²_c / (k ‖Bx‖²) = 1 + k E / Σ_t ‖p(t)‖²
//! ```
//!
//! with `E = Σ_t x(t)ᵀ K x(t)` the snapshots' strain energy beyond the Craig–Bampton part (the
//! POD's total). κ is large where the springs are stiff against the structure (k·G ≫ 1, the
//! regime in which a reduced basis misses the joint forces), near 1 where they are soft. So the
//! rank is the fewest modes that leave the snapshots' part outside their span within
//! `θ · TOL / κ` of their K-norm (θ = [`SELECTION_MARGIN`], the share the pair selection leaves
//! to the pairs it does not add), κ computed from the snapshots of each set of columns. The
//! bound is a worst case (the error of a POD lies in the directions the forces excite least) and
//! in K rather than the closed-spring norm, so the estimate decides: the compressed model is
//! run and estimated like any round (reduction, truncation and integration parts), and it is
//! the result only if every controlled quantity's total estimate meets TOL with a smaller basis.
//! If it misses, the fractions are tightened by [`COMPRESSION_TIGHTENING`] (√10), at most
//! [`COMPRESSION_ATTEMPTS`] models in all (down to a tenth of the first fraction); if the last
//! misses too (or would not be smaller), the per-pair model stays the result.
//!
//! ## When to compress
//!
//! A compressed model costs one more run and estimate, so the command's own time grows by
//! roughly a round; what it buys is a smaller model for this run and for every later use of it
//! (an exported model, a sweep, a backbone, an FMU). The reduced step's dense work grows like
//! r² to r³ (the Newton matrix's products and refactorizations), so a basis three quarters the
//! size steps at 0.42–0.56 of the cost, which repays the extra run and estimate within a few reuses; a
//! basis 10–15 % smaller does not. [`CompressJoint::Auto`] (the default) therefore runs a
//! compressed model only where the POD's rank — known before its run, from the per-pair
//! model's estimate — gives a basis at most [`AUTO_COMPRESSION_SHRINK`] of the per-pair one: a
//! scene whose joint forces do not compress costs nothing but the POD, and a miss is followed
//! by a richer attempt only while that one is still small enough.
//! [`CompressJoint::On`] tries every attempt that is smaller at all, [`CompressJoint::Off`]
//! never.

use faer::prelude::Solve;
use faer::{Mat, Side};
use serde::Serialize;

use super::{
    worst, BasisCache, Chosen, Column, CompressJoint, ToleranceModel, ToleranceOptions,
    SELECTION_MARGIN,
};
use crate::error::Error;
use crate::integrate::{Run, TransientOptions};
use crate::joint::{JointOperator, NORMAL, T1, T2};
use crate::linalg::sparse::sym_mul_mat;
use crate::model::Model;
use crate::reduction::{
    joint_pod, modal_rotation, CurveErrors, JointFlexibility, JointPod, Orthonormalizer,
    Quantities, DEFAULT_DROP_TOL,
};
use crate::rom::estimate::{run_estimated_parts, Checks, RunEstimate};
use crate::system::{ReducedSystem, Scene};

/// The POD fractions are divided by this when a compressed model misses the tolerance (√10:
/// half a decade per attempt).
pub const COMPRESSION_TIGHTENING: f64 = 3.162_277_660_168_379_5;

/// Compressed models tried at most (the last at a tenth of the first fraction).
pub const COMPRESSION_ATTEMPTS: usize = 3;

/// [`CompressJoint::Auto`] runs a compressed model only if its basis is at most this fraction
/// of the per-pair basis (module docs, "When to compress").
pub const AUTO_COMPRESSION_SHRINK: f64 = 0.75;

/// One compressed model tried (`"compression"."attempts"` of the tolerance JSON).
#[derive(Clone, Debug, Serialize)]
pub struct CompressionAttempt {
    /// Compressed normal columns.
    pub columns: usize,
    /// Compressed tangential columns.
    pub tangential_columns: usize,
    /// The POD fractions of the normal and tangential columns: the snapshots' part outside the
    /// compressed columns' span, relative to their K-norm beyond the Craig–Bampton part, at
    /// most this (module docs, "The rank").
    pub fraction: [f64; 2],
    /// Basis size r.
    pub basis_size: usize,
    /// The largest total estimate (reduction, truncation and integration parts) over the
    /// controlled quantities.
    pub estimate: f64,
    /// Wall time of its basis, run and estimate, s.
    pub wall_s: f64,
    /// CPU time of its integration (the run alone), s.
    pub run_cpu_s: f64,
    /// Its integration steps.
    pub steps: u64,
    /// Its estimate per quantity: the total and its reduction, truncation and integration
    /// parts (as `"estimate"` of the tolerance JSON), to see which part a miss comes from.
    pub parts: AttemptParts,
}

/// A compressed model's estimate per quantity and part (`"parts"` of an attempt): the parts of
/// its [`RunEstimate`] without the estimate's detail, which the attempt does not keep.
#[derive(Clone, Debug, Serialize)]
pub struct AttemptParts {
    /// The total estimate.
    pub total: CurveErrors,
    /// The reduction part.
    pub reduction: CurveErrors,
    /// The truncation part (`None`: not checked).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub truncation: Option<CurveErrors>,
    /// The integration part (`None`: not checked).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub integration: Option<CurveErrors>,
}

/// What the compression of the joint columns did (`"compression"` of the tolerance JSON).
#[derive(Clone, Debug, Serialize)]
pub struct Compression {
    /// When to compress: `"on"` (always tried) or `"auto"` ([`CompressJoint`]).
    pub mode: CompressJoint,
    /// The basis size r of the first compressed model the POD's rank gives (before any run).
    pub first_basis_size: usize,
    /// Whether compressed models were run (`false`: the POD gave no smaller basis, or — with
    /// `"auto"` — none small enough to pay for its run and estimate).
    pub tried: bool,
    /// Normal attachment modes (one per pair) of the per-pair model.
    pub pair_columns: usize,
    /// Tangential attachment modes of the per-pair model.
    pub tangential_pair_columns: usize,
    /// Basis size r of the per-pair model.
    pub pair_basis_size: usize,
    /// CPU time of the per-pair model's integration (its run alone), s.
    pub pair_run_cpu_s: f64,
    /// The per-pair model's integration steps.
    pub pair_steps: u64,
    /// The stiffness ratios κ of the normal and tangential snapshots (module docs, "The
    /// rank"), dimensionless.
    pub kappa: [f64; 2],
    /// Whether a compressed model is the result (the last attempt).
    pub accepted: bool,
    /// The compressed models tried, in order.
    pub attempts: Vec<CompressionAttempt>,
    /// What stopped the run of the attempt after the last one (its error; absent: none
    /// stopped): the attempts end there and the per-pair model stays the result.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stopped: Option<String>,
}

/// With [`ToleranceOptions::compress`], compresses the joint columns of the per-pair `result`
/// if it met the tolerance (module docs), given the per-pair model's joint part, basis cache and
/// Craig–Bampton basis: if a compressed model meets the tolerance with a smaller basis, it becomes the result (its system, run and
/// estimate; the per-pair run, its estimate and the compression before the compressed run count
/// as offline time). `result.compression` says what was tried.
///
/// # Errors
/// A failing eigenproblem, basis or run.
pub(super) fn compress_result(
    model: &Model,
    flex: &JointFlexibility,
    (chosen, cache, cb): (&Chosen, &BasisCache<'_>, &Mat<f64>),
    opts: &ToleranceOptions,
    result: &mut ToleranceModel,
) -> Result<(), Error> {
    let columns = chosen.pairs.len() + chosen.tangential.len();
    if opts.compress == CompressJoint::Off || !result.met || columns == 0 {
        return Ok(());
    }
    let tol = opts.tolerance;
    let start = std::time::Instant::now();
    let per_pair = PerPair {
        chosen,
        cache,
        cb,
        estimate: &result.estimate,
        run: &result.run,
        basis_size: result.rom.dim(),
    };
    let on = result.quantities;
    let (better, report) = compress(
        model,
        flex,
        per_pair,
        (on, tol, opts.compress),
        &result.transient,
    )?;
    if let Some(c) = better {
        let last = report.attempts.last().map_or(0.0, |a| a.wall_s);
        let before = start.elapsed().as_secs_f64() - last + c.basis_s;
        result.offline_s += result.run.wall_s + result.estimate_s + before;
        result.estimate_s = last - c.basis_s - c.run.wall_s;
        result.rom = c.rom;
        result.run = c.run;
        result.estimate = c.estimate;
        result.met = worst(&result.estimate.total, on) <= tol;
    }
    result.compression = Some(report);
    Ok(())
}

/// A compressed model that met the tolerance: its system, run, estimate.
pub(super) struct Compressed {
    pub rom: ReducedSystem,
    pub run: Run,
    pub estimate: RunEstimate,
    /// Wall time of its basis and reduced system, s.
    pub basis_s: f64,
}

/// The inputs of [`compress`]: the per-pair result and what built it.
pub(super) struct PerPair<'a> {
    pub chosen: &'a Chosen,
    pub cache: &'a BasisCache<'a>,
    pub cb: &'a Mat<f64>,
    pub estimate: &'a RunEstimate,
    pub run: &'a Run,
    pub basis_size: usize,
}

/// Tries compressed joint columns for the per-pair model `per_pair` that met `tol` on the
/// quantities `on` (module docs), at the result's transient options — with `mode`
/// [`CompressJoint::Auto`] only if the first compressed basis is at most
/// [`AUTO_COMPRESSION_SHRINK`] of the per-pair one; returns the compressed model if one met
/// `tol` with a smaller basis, and what was tried.
///
/// # Errors
/// A failing eigenproblem, basis or run.
pub(super) fn compress(
    model: &Model,
    flex: &JointFlexibility,
    per_pair: PerPair<'_>,
    (on, tol, mode): (Quantities, f64, CompressJoint),
    transient: &TransientOptions,
) -> Result<(Option<Compressed>, Compression), Error> {
    let chosen = per_pair.chosen;
    let mut report = Compression {
        mode,
        first_basis_size: per_pair.basis_size,
        tried: false,
        pair_columns: chosen.pairs.len(),
        tangential_pair_columns: chosen.tangential.len(),
        pair_basis_size: per_pair.basis_size,
        pair_run_cpu_s: per_pair.run.cpu_s,
        pair_steps: per_pair.run.stats.steps,
        kappa: [1.0; 2],
        accepted: false,
        attempts: Vec::new(),
        stopped: None,
    };
    let normal = normal_columns(chosen);
    let tangential = tangential_columns(chosen);
    let forces = &per_pair.estimate.detail.corrected_pair_forces;
    let scene = Scene::of(model);
    let stiffness = [
        scene.contact.normal_stiffness,
        scene.contact.stick_stiffness,
    ];
    let pod_n = columns_pod(model, &per_pair, &normal, forces, stiffness[0])?;
    let pod_t = columns_pod(model, &per_pair, &tangential, forces, stiffness[1])?;
    report.kappa = [pod_n.kappa, pod_t.kappa];
    let mut fraction = [pod_n.kappa, pod_t.kappa].map(|k| SELECTION_MARGIN * tol / k);
    for attempt in 0..COMPRESSION_ATTEMPTS {
        let (rn, rt) = (
            pod_n.pod.rank_for(fraction[0]),
            pod_t.pod.rank_for(fraction[1]),
        );
        let size = per_pair.cb.ncols() + rn + rt;
        if attempt == 0 {
            report.first_basis_size = size;
        }
        let shrink = size as f64 / per_pair.basis_size as f64;
        if size >= per_pair.basis_size
            || (mode == CompressJoint::Auto && shrink > AUTO_COMPRESSION_SHRINK)
        {
            break;
        }
        report.tried = true;
        let start = std::time::Instant::now();
        let rom = compressed_system(
            model,
            per_pair.cb,
            per_pair.cache,
            [(&normal, &pod_n.pod, rn), (&tangential, &pod_t.pod, rt)],
        )?;
        let basis_s = start.elapsed().as_secs_f64();
        let (run, estimate) = run_estimated_parts(
            model,
            flex,
            rom.clone(),
            &scene,
            transient,
            Checks::BOTH,
            true,
            |_, _| {},
        )?;
        // An attempt whose run (or a check's re-run) stops is no model: the per-pair one stays.
        let (run, estimate) = match run.into_result().and_then(|r| estimate.map(|e| (r, e))) {
            Ok(done) => done,
            Err(e) if super::stopped_in_time(&e) => {
                report.stopped = Some(e.to_string());
                break;
            }
            Err(e) => return Err(e),
        };
        let total = worst(&estimate.total, on);
        report.attempts.push(CompressionAttempt {
            columns: rn,
            tangential_columns: rt,
            fraction,
            basis_size: rom.dim(),
            estimate: total,
            wall_s: start.elapsed().as_secs_f64(),
            run_cpu_s: run.cpu_s,
            steps: run.stats.steps,
            parts: AttemptParts {
                total: estimate.total,
                reduction: estimate.reduction,
                truncation: estimate.truncation,
                integration: estimate.integration,
            },
        });
        if total <= tol && rom.dim() < per_pair.basis_size {
            report.accepted = true;
            let compressed = Compressed {
                rom,
                run,
                estimate,
                basis_s,
            };
            return Ok((Some(compressed), report));
        }
        fraction = fraction.map(|f| f / COMPRESSION_TIGHTENING);
    }
    Ok((None, report))
}

/// A joint column: its pair and its direction in the pair's frame (normal, or a unit vector in
/// the (t1, t2) plane), and its key in the basis cache.
struct JointColumn {
    pair: usize,
    /// Weights of the pair's (normal, t1, t2) rows.
    weights: [f64; 3],
    key: Column,
}

fn normal_columns(chosen: &Chosen) -> Vec<JointColumn> {
    chosen
        .pairs
        .iter()
        .map(|&k| JointColumn {
            pair: k,
            weights: [1.0, 0.0, 0.0],
            key: Column::Normal(k),
        })
        .collect()
}

fn tangential_columns(chosen: &Chosen) -> Vec<JointColumn> {
    chosen
        .tangential
        .iter()
        .zip(&chosen.directions)
        .map(|(&k, d)| JointColumn {
            pair: k,
            weights: [0.0, d[0], d[1]],
            key: Column::Tangential(k, d.map(f64::to_bits)),
        })
        .collect()
}

/// `b · v` for the column's weighted joint rows `b`.
fn row_dot(joint: &JointOperator, col: &JointColumn, v: &[f64]) -> f64 {
    [NORMAL, T1, T2]
        .iter()
        .zip(col.weights)
        .filter(|(_, w)| *w != 0.0)
        .map(|(&row, w)| w * joint.row_dot(3 * col.pair + row, v))
        .sum()
}

/// The POD of one set of joint columns' snapshots and its stiffness ratio κ.
struct ColumnsPod {
    pod: JointPod,
    /// `κ = sqrt(1 + k E / Σ_t ‖p(t)‖²)` (module docs, "The rank"); 1 without snapshots.
    kappa: f64,
}

/// The POD of the joint deformation `Z P` of the columns `cols` (their attachment modes solved
/// in the per-pair model's cache) under the corrected pair forces `forces` (per output), beyond
/// the span of its Craig–Bampton basis (module docs), and its κ with the contact stiffness `k`
/// of the columns' direction (N/mm).
fn columns_pod(
    model: &Model,
    per_pair: &PerPair<'_>,
    cols: &[JointColumn],
    forces: &[Vec<(usize, [f64; 3])>],
    k: f64,
) -> Result<ColumnsPod, Error> {
    let c = cols.len();
    let cb = per_pair.cb;
    let joint = &model.joint;
    let z: Vec<&[f64]> = cols
        .iter()
        .map(|col| &per_pair.cache.solved[&col.key][..])
        .collect();
    // G = Zᵀ K Z = B_c K⁻¹ B_cᵀ from the solved modes and the sparse joint rows.
    let mut gram = Mat::from_fn(c, c, |i, j| row_dot(joint, &cols[i], z[j]));
    // Less what Φ_CB holds: (B_c Φ_CB) K̃_CB⁻¹ (B_c Φ_CB)ᵀ.
    if cb.ncols() > 0 && c > 0 {
        let k_cb = cb.transpose() * sym_mul_mat(&model.stiffness, cb.as_ref());
        let b_cb = Mat::from_fn(c, cb.ncols(), |i, j| {
            let v: Vec<f64> = cb.col(j).iter().copied().collect();
            row_dot(joint, &cols[i], &v)
        });
        if let Ok(llt) = k_cb.llt(Side::Lower) {
            gram -= &b_cb * llt.solve(b_cb.transpose());
        }
    }
    // P: each column's force (its rows' weights on the pair's corrected force) per output.
    let mut p = Mat::<f64>::zeros(c, forces.len());
    let mut index = vec![Vec::new(); joint.pairs()];
    for (i, col) in cols.iter().enumerate() {
        index[col.pair].push(i);
    }
    for (t, out) in forces.iter().enumerate() {
        for &(pair, f) in out {
            for &i in &index[pair] {
                p[(i, t)] = cols[i].weights.iter().zip(f).map(|(w, f)| w * f).sum();
            }
        }
    }
    let pod = joint_pod(gram.as_ref(), p.as_ref())?;
    let force2: f64 = p.col_iter().map(|c| c.squared_norm_l2()).sum();
    let ratio = k * pod.total / force2;
    let kappa = if ratio.is_finite() && ratio > 0.0 {
        (1.0 + ratio).sqrt()
    } else {
        1.0
    };
    Ok(ColumnsPod { pod, kappa })
}

/// The reduced system on the Craig–Bampton basis `cb` and the leading `rank` POD modes of each
/// set of joint columns (their attachment modes in `cache`), M-orthonormalized and rotated to
/// the reduced eigenbasis.
fn compressed_system(
    model: &Model,
    cb: &Mat<f64>,
    cache: &BasisCache<'_>,
    parts: [(&Vec<JointColumn>, &JointPod, usize); 2],
) -> Result<ReducedSystem, Error> {
    let mut gs = Orthonormalizer::new(&model.mass, DEFAULT_DROP_TOL);
    for j in 0..cb.ncols() {
        gs.push(cb.col(j).iter().copied().collect())?;
    }
    let n = model.dofs();
    for (cols, pod, rank) in parts {
        for j in 0..rank {
            let mut v = vec![0.0; n];
            for (i, col) in cols.iter().enumerate() {
                let c = pod.coefficients[(i, j)];
                if c != 0.0 {
                    for (o, z) in v.iter_mut().zip(&cache.solved[&col.key]) {
                        *o += c * z;
                    }
                }
            }
            gs.push(v)?;
        }
    }
    let (phi, _) = modal_rotation(model, gs.basis())?;
    ReducedSystem::new(model, phi)
}
