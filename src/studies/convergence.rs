//! The static convergence study of the paper (Witteveen & Pichler 2014, Sections 4.1.2, 4.2.2
//! and 5; Figs. 7, 15, 19 and 8, 16) and the reduced contact statics behind `jointrom basis`,
//! `jointrom static --basis` and `jointrom study`.
//!
//! ## What is compared
//!
//! The case's master load (times a scale) is applied with frictionless penalty contact in the
//! joint ([`crate::joint::statics`]). The measure is the paper's: `‖f_c‖₂`, the Euclidean norm of all
//! pair contact forces (N). The full-FE value is the reference; each reduction basis is
//! `Φ = [Φ_S Φ_V | first g enrichment vectors]`, M-orthonormalized by
//! [`final_basis`] (drop tolerance [`DEFAULT_DROP_TOL`]), and solved exactly by the
//! active-set Newton method on the reduced model (eq. 7). The relative error is
//! `|‖f_c‖_red − ‖f_c‖_full| / ‖f_c‖_full`; the relative error of the whole pair force vector,
//! `‖p_red − p_full‖ / ‖p_full‖`, is recorded too (it bounds the former).
//!
//! The enrichments, g = 0 ..= `max_g` vectors each (g = 0 is plain Craig–Bampton with ν modes for
//! every kind, so all curves start at the same point):
//!
//! - `tvd`: the leading POMs of the K-weighted POD (eqs. 24–25) of the TVD (Algorithm 2, eq. 16,
//!   normal stiffness `k_n` only) — the paper's method;
//! - `tvd-plain`: the plain POD (eqs. 20–22) of the same TVD;
//! - `tvd-kt`: K-weighted POD of the TVD with `k_n` and `k_t` (Algorithm 2, line 10);
//! - `tvd-secant`: K-weighted POD of the secant TVD `(K + ∂K)⁻¹ ∂K φ_i` (Algorithm 2 with line
//!   19 replaced; [`crate::reduction::tvd`], "The secant TVD");
//! - `modes`: ν + g fixed-interface normal modes instead of joint modes (the paper's Fig. 7
//!   comparison).
//!
//! A series ends early when its kind has fewer than `max_g` vectors (the TVD of `k_n` alone span
//! at most one direction per pair, so their POD has at most w modes); `available` says how many.
//! The energy ratios `w(g)` (eq. 26) of each POD are recorded for g = 1 ..= `max_g`.
//!
//! ## Cost
//!
//! The expensive parts run once: the full solution, Craig–Bampton, each TVD variant and its POD,
//! and the ν + `max_g` fixed-interface modes of `modes`. Per g and kind only the
//! M-orthonormalization of `6 + ν + g` columns, the projection (`ReducedSystem`) and the dense
//! reduced contact solve remain.
//!
//! Two references without a g axis are recorded too: `tvd_spans`, the basis with *all* nonzero
//! TVD of a variant and no POD (the limit of its POD series) plus `alldof` (Craig–Bampton + the
//! normal constraint mode of every pair, paper Section 5.1: exact by construction), and the
//! full-FE value. `jim` (paper Section 5.3) is a series: the first g Joint Interface Modes of
//! the normal and in-plane sets, by frequency.
//!
//! ## Reduced contact solves
//!
//! The active-set Newton method of [`crate::joint::statics`] can cycle on a coarse basis. The
//! contact energy is convex, so the damped Newton method
//! ([`crate::joint::statics::contact_static_reduced_damped`], the same Newton step with an Armijo
//! line search) takes over when it fails
//! ([`crate::rom::statics::reduced_contact_static_restarting`]); every such g is listed in
//! `restarts`, and a g where both fail is NaN and listed in `failures`.
//!
//! ## Why the TVD series converge late
//!
//! The weighted POD of the TVD is computed without forming `YᵀKY` ([`crate::reduction::pod_tvd`]):
//! the POMs that carry the last per cent of the contact force have POD eigenvalues of
//! 1e-12 … 1e-16 λ_max, below the round-off floor of the Gram route. The TVD series converge to
//! the full value, but late: w(g) reaches 0.999 long before the contact force converges, because
//! the POD ranks by global strain energy and the pairs that carry the load are small in energy.
//! k_n + k_t TVD span a three times larger space and converge more slowly per added vector;
//! without POD they stop short of the full value (the combined normal-tangential pseudoforces do
//! not contain the pure normal flexibility directions). The measured series are in
//! docs/validation (the static convergence study; `jointrom study CASE`).

use std::time::Instant;

use faer::{Mat, MatRef};
use serde::Serialize;

use crate::error::{Error, FlagError, ReductionError, StudyError};
use crate::joint::statics::{ContactOptions, ContactState};
use crate::model::{contact_static_full, Interface, Model};
use crate::reduction::{
    alldof_vectors, build_basis, build_tvd_basis_both_pods, craig_bampton, final_basis,
    jim_vectors, trial_vector_derivatives, BasisKind, BasisOptions, JimSet, JointFlexibility,
    TvdOptions, DEFAULT_DROP_TOL, DEFAULT_THRESHOLD,
};
use crate::rom::statics::{reduced_contact_static_restarting, scaled_load, ReducedStatic};
use crate::system::ReducedSystem;

/// What `jointrom static --basis` reports.
#[derive(Clone, Debug)]
pub struct BasisStatic {
    /// The kind's name ([`BasisKind::name`]).
    pub basis: &'static str,
    /// Enrichment vectors used (joint modes; extra modes for `modes`).
    pub g: usize,
    /// Columns of the final basis r.
    pub basis_size: usize,
    /// The reduced solution.
    pub solution: ReducedStatic,
    /// Whether the active-set iteration failed and the damped one solved it (see
    /// [`reduced_contact_static_restarting`]).
    pub restarted: bool,
    /// Basis build time (s).
    pub build_s: f64,
    /// Projection and contact solve time (s).
    pub solve_s: f64,
}

/// Builds the basis `kind` with `opts` ([`build_basis`]) and solves the reduced contact statics
/// under the case load times `scale`. An explicit `opts.g` larger than the kind has vectors is
/// an error naming `--g` (never clamped).
pub fn basis_static(
    model: &Model,
    kind: BasisKind,
    opts: &BasisOptions,
    scale: f64,
) -> Result<BasisStatic, Error> {
    scaled_load(model, scale)?;
    let t0 = Instant::now();
    let basis = build_basis(model, kind, opts)?;
    let build_s = t0.elapsed().as_secs_f64();
    if let Some(g) = opts.g {
        if basis.g < g {
            return Err(StudyError::Enrichment {
                g,
                basis: kind.name(),
                available: basis.g,
                model: model.name.clone(),
            }
            .into());
        }
    }
    let t1 = Instant::now();
    let basis_size = basis.phi.ncols();
    let rm = ReducedSystem::new(model, basis.phi)?;
    let (solution, first) =
        reduced_contact_static_restarting(model, &rm, scale, &ContactOptions::default())?;
    Ok(BasisStatic {
        restarted: first.is_some(),
        basis: kind.name(),
        g: basis.g,
        basis_size,
        solution,
        build_s,
        solve_s: t1.elapsed().as_secs_f64(),
    })
}

/// What `jointrom basis` reports.
#[derive(Clone, Debug, Serialize)]
pub struct BasisSummary {
    /// Case name.
    pub case: String,
    /// `tvd` or `tvd-plain`.
    pub kind: &'static str,
    /// Fixed-interface modes ν.
    pub nu: usize,
    /// K-weighted POD energy ratio `w[g − 1] = w(g)` (eq. 26), g = 1 ..= p.
    pub w: Vec<f64>,
    /// Plain POD energy ratio (eq. 26 with eqs. 20–22), g = 1 ..= p.
    pub w_plain: Vec<f64>,
    /// g used: the given one, or the smallest with `w(g) ≥ threshold` (of the kind's POD).
    pub g_chosen: usize,
    /// The threshold.
    pub threshold: f64,
    /// TVD candidates `2 (v + s)²`.
    pub tvd_count: usize,
    /// Kept (nonzero) TVD.
    pub tvd_nonzero: usize,
    /// Columns of the final basis.
    pub basis_size: usize,
    /// Directions dropped by the M-orthonormalization.
    pub dropped: usize,
    /// Time of the basis build with both POD curves ([`build_tvd_basis_both_pods`]) (s).
    pub build_s: f64,
}

/// The TVD basis of `kind` (`Tvd` or `TvdPlain`) with both POD energy curves.
pub fn basis_summary(
    model: &Model,
    kind: BasisKind,
    opts: &BasisOptions,
) -> Result<BasisSummary, Error> {
    if !matches!(kind, BasisKind::Tvd | BasisKind::TvdPlain) {
        return Err(FlagError::Value {
            flag: "kind",
            value: kind.name().to_string(),
            need: "must be tvd or tvd-plain",
        }
        .into());
    }
    if !(opts.threshold > 0.0 && opts.threshold <= 1.0) {
        return Err(FlagError::Range {
            flag: "threshold",
            need: "in (0, 1]",
            got: opts.threshold.to_string(),
        }
        .into());
    }
    let t0 = Instant::now();
    // The other POD's energy curve comes from the same TVD.
    let (basis, w_other) = build_tvd_basis_both_pods(model, kind, opts)?;
    let build_s = t0.elapsed().as_secs_f64();
    if let Some(g) = opts.g {
        if basis.g < g {
            return Err(ReductionError::PodModes {
                g,
                available: basis.g,
                model: model.name.clone(),
            }
            .into());
        }
    }
    let (w, w_plain) = if kind == BasisKind::Tvd {
        (basis.w, w_other)
    } else {
        (w_other, basis.w)
    };
    Ok(BasisSummary {
        case: model.name.clone(),
        kind: kind.name(),
        nu: opts.nu,
        w,
        w_plain,
        g_chosen: basis.g,
        threshold: opts.threshold,
        tvd_count: basis.tvd_total,
        tvd_nonzero: basis.tvd_nonzero,
        basis_size: basis.phi.ncols(),
        dropped: basis.dropped,
        build_s,
    })
}

/// Options of [`run_study`]. Defaults: `nu = 10`, `max_g = 60`, `scale = 1`,
/// `threshold =` [`DEFAULT_THRESHOLD`], `drop_tol =` [`DEFAULT_DROP_TOL`], default contact
/// options.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StudyOptions {
    /// Fixed-interface modes ν of the Craig–Bampton part.
    pub nu: usize,
    /// Largest number of enrichment vectors g.
    pub max_g: usize,
    /// Factor on the case's master load.
    pub scale: f64,
    /// Threshold on w(g) reported as the a-priori choice of g (eq. 26).
    pub threshold: f64,
    /// Drop tolerance of [`final_basis`].
    pub drop_tol: f64,
    /// Active-set Newton options (full and reduced).
    pub contact: ContactOptions,
}

impl Default for StudyOptions {
    fn default() -> Self {
        StudyOptions {
            nu: 10,
            max_g: 60,
            scale: 1.0,
            threshold: DEFAULT_THRESHOLD,
            drop_tol: DEFAULT_DROP_TOL,
            contact: ContactOptions::default(),
        }
    }
}

/// The full-FE reference of the study.
#[derive(Clone, Debug, Serialize)]
pub struct FullReference {
    /// `‖f_c‖` (N).
    pub contact_force_norm: f64,
    /// Pairs in contact.
    pub pairs_in_contact: usize,
    /// Master displacement (mm, rad).
    pub master_displacement: [f64; 6],
    /// Solve time (s).
    pub solve_s: f64,
    /// The mesh-independent measures of the contact state (resultant, area, peak pressure,
    /// largest penetration; `crate::model::per_area`).
    pub measures: crate::model::per_area::ContactMeasures,
}

/// First g at which a series is within a relative tolerance of the full value.
#[derive(Clone, Debug, Serialize)]
pub struct Within {
    /// The relative tolerance on `‖f_c‖`.
    pub tol: f64,
    /// The first g with error ≤ tol (`None`: never within `max_g`).
    pub first: Option<usize>,
    /// The smallest g from which every later g of the series is within tol.
    pub stays: Option<usize>,
}

/// A reduced contact solve that failed at one g.
#[derive(Clone, Debug, Serialize)]
pub struct Failure {
    /// The g.
    pub g: usize,
    /// The error.
    pub error: String,
}

/// One basis kind's convergence curve.
#[derive(Clone, Debug, Serialize)]
pub struct ConvergenceSeries {
    /// Short name (`tvd`, `tvd-plain`, `tvd-kt`, `modes`, ...).
    pub name: String,
    /// Legend text.
    pub label: String,
    /// Enrichment vectors available (the series stops at `min(available, max_g)`).
    pub available: usize,
    /// g = 0, 1, ...
    pub g: Vec<usize>,
    /// Final basis size r at each g.
    pub basis_size: Vec<usize>,
    /// `‖f_c‖` (N) at each g.
    pub contact_force_norm: Vec<f64>,
    /// `|‖f_c‖ − ‖f_c‖_full| / ‖f_c‖_full`.
    pub relative_error: Vec<f64>,
    /// `‖p − p_full‖ / ‖p_full‖` (pair force vectors).
    pub force_vector_error: Vec<f64>,
    /// Pairs in contact at each g.
    pub pairs_in_contact: Vec<usize>,
    /// Where the series gets within 1e-2 and 1e-4.
    pub within: Vec<Within>,
    /// g where the active-set Newton method failed (cycled) and the damped one
    /// ([`crate::rom::statics::reduced_contact_static_damped`]) solved it.
    pub restarts: Vec<Failure>,
    /// g where both failed: the values are NaN (`null` in JSON) there.
    pub failures: Vec<Failure>,
    /// Time to prepare the enrichment vectors (TVD + POD, or modes) (s).
    pub prepare_s: f64,
    /// Time of the sweep over g (orthonormalization, projection, contact solves) (s).
    pub sweep_s: f64,
}

/// A POD energy-ratio curve.
#[derive(Clone, Debug, Serialize)]
pub struct EnergyCurve {
    /// Short name (`tvd`, `tvd-plain`, `tvd-kt`).
    pub name: String,
    /// Legend text.
    pub label: String,
    /// `w[g − 1] = w(g)`, g = 1 ..= max_g (or p if fewer).
    pub w: Vec<f64>,
    /// Smallest g with `w(g) ≥ threshold`.
    pub g_threshold: usize,
    /// Nonzero TVD columns p.
    pub tvd_nonzero: usize,
    /// Kept POD modes (eigenvalues above the zero threshold).
    pub pod_modes: usize,
}

/// The reduced solution on `[Φ_S Φ_V | all nonzero TVD]` (no POD): the limit the POD series
/// of this TVD variant can reach, up to the POD's numerical-zero cut and
/// the basis drop tolerance.
#[derive(Clone, Debug, Serialize)]
pub struct SpanReference {
    /// TVD variant (`tvd`: k_n only; `tvd-kt`: k_n and k_t).
    pub name: String,
    /// Columns kept by the M-orthonormalization.
    pub basis_size: usize,
    /// Columns dropped as dependent.
    pub dropped: usize,
    /// `‖f_c‖` (N); NaN if the solve failed.
    pub contact_force_norm: f64,
    /// Relative error of `‖f_c‖`.
    pub relative_error: f64,
    /// Time (s).
    pub solve_s: f64,
}

/// The tolerance rule's basis ([`crate::rom::tolerance`]) as a convergence series: the
/// attachment modes of the pairs ranked by their force in the pair-space solution (exact),
/// largest first.
fn adaptive_series(
    model: &Model,
    full: &ContactState,
    cb: MatRef<'_, f64>,
    opts: &StudyOptions,
) -> Result<ConvergenceSeries, Error> {
    let t0 = Instant::now();
    let flex = JointFlexibility::new(model)?;
    let load = model.master_load().map(|v| v * opts.scale);
    let forces = flex.static_contact_forces(load)?;
    let mut order: Vec<usize> = (0..forces.len()).collect();
    order.sort_by(|&a, &b| forces[a].abs().total_cmp(&forces[b].abs()).reverse());
    order.truncate(opts.max_g);
    let att = flex.attachment_modes(&order);
    let prepare_s = t0.elapsed().as_secs_f64();
    let s = sweep(
        model,
        full,
        cb,
        att.as_ref(),
        opts,
        (
            "adaptive",
            "Craig–Bampton + attachment modes of the g pairs with the largest force",
        ),
    )?;
    Ok(ConvergenceSeries { prepare_s, ..s })
}

/// See [`SpanReference`].
fn span_reference(
    model: &Model,
    full: &ContactState,
    cb: MatRef<'_, f64>,
    tvd: MatRef<'_, f64>,
    opts: &StudyOptions,
    name: &str,
) -> Result<SpanReference, Error> {
    let t0 = Instant::now();
    let (phi, dropped) = final_basis(&[cb, tvd], &model.mass, opts.drop_tol)?;
    let basis_size = phi.ncols();
    let rm = ReducedSystem::new(model, phi)?;
    let norm = reduced_contact_static_restarting(model, &rm, opts.scale, &opts.contact)
        .map(|(s, _)| s.state.contact_force_norm)
        .unwrap_or(f64::NAN);
    Ok(SpanReference {
        name: name.into(),
        basis_size,
        dropped,
        contact_force_norm: norm,
        relative_error: (norm - full.contact_force_norm).abs() / full.contact_force_norm,
        solve_s: t0.elapsed().as_secs_f64(),
    })
}

/// The whole study of one case.
#[derive(Clone, Debug, Serialize)]
pub struct Study {
    /// Case name.
    pub case: String,
    /// Model DOF.
    pub dofs: usize,
    /// Joint pairs.
    pub pairs: usize,
    /// ν.
    pub nu: usize,
    /// Largest g.
    pub max_g: usize,
    /// Load factor.
    pub scale: f64,
    /// The w threshold of `g_threshold`.
    pub threshold: f64,
    /// The full-FE value.
    pub full: FullReference,
    /// Convergence curves, one per basis kind.
    pub series: Vec<ConvergenceSeries>,
    /// POD energy curves.
    pub energy: Vec<EnergyCurve>,
    /// The limit of each TVD variant without POD truncation, `[Φ_S Φ_V | all TVD]`, and
    /// `alldof`, `[Φ_S Φ_V | K⁻¹ b_nᵀ of every pair]`.
    pub tvd_spans: Vec<SpanReference>,
    /// Craig–Bampton time (s).
    pub craig_bampton_s: f64,
    /// Whole study time (s), charts excluded.
    pub total_s: f64,
}

/// One TVD variant of the study: name, legend, TVD options, K-weighted POD?
struct TvdVariant {
    name: &'static str,
    label: &'static str,
    tvd: TvdOptions,
    weighted: bool,
}

/// The TVD variants of the study (the one list; POD variants of one TVD share its computation).
fn tvd_variants() -> Vec<TvdVariant> {
    let kn = TvdOptions::default();
    let knkt = TvdOptions {
        tangential: true,
        ..kn
    };
    vec![
        TvdVariant {
            name: "tvd",
            label: "TVD, K-weighted POD (eq. 16)",
            tvd: kn,
            weighted: true,
        },
        TvdVariant {
            name: "tvd-plain",
            label: "TVD, plain POD",
            tvd: kn,
            weighted: false,
        },
        TvdVariant {
            name: "tvd-inertia",
            label: "TVD with inertia (eq. 15), K-weighted POD",
            tvd: TvdOptions {
                inertia: true,
                ..kn
            },
            weighted: true,
        },
        TvdVariant {
            name: "tvd-kt",
            label: "TVD with k_n + k_t, K-weighted POD",
            tvd: knkt,
            weighted: true,
        },
        TvdVariant {
            name: "tvd-secant",
            label: "secant TVD, K-weighted POD",
            tvd: TvdOptions { secant: true, ..kn },
            weighted: true,
        },
    ]
}

/// Runs the study (see the module docs).
pub fn run_study(model: &Model, opts: &StudyOptions) -> Result<Study, Error> {
    let t_all = Instant::now();
    let load = scaled_load(model, opts.scale)?;
    if !(opts.threshold > 0.0 && opts.threshold <= 1.0) {
        return Err(StudyError::Threshold {
            threshold: opts.threshold,
        }
        .into());
    }
    let t0 = Instant::now();
    let full = contact_static_full(model, load, &opts.contact)?;
    let full_ref = FullReference {
        contact_force_norm: full.state.contact_force_norm,
        pairs_in_contact: full.state.pairs_in_contact,
        master_displacement: full.master_displacement,
        solve_s: t0.elapsed().as_secs_f64(),
        measures: model.contact_measures(&full.state.forces, &full.state.gaps),
    };
    if full_ref.contact_force_norm.is_nan() || full_ref.contact_force_norm <= 0.0 {
        return Err(StudyError::NoContact {
            model: model.name.clone(),
        }
        .into());
    }

    let t0 = Instant::now();
    let cb = craig_bampton(model, opts.nu)?;
    let craig_bampton_s = t0.elapsed().as_secs_f64();

    let mut series = Vec::new();
    let mut energy = Vec::new();
    // TVD variants: each distinct TvdOptions computed once.
    let mut tvd_cache: Vec<(TvdOptions, crate::reduction::Tvd, f64)> = Vec::new();
    let mut spans = Vec::new();
    for v in tvd_variants() {
        let t0 = Instant::now();
        let idx = match tvd_cache.iter().position(|(o, _, _)| *o == v.tvd) {
            Some(i) => i,
            None => {
                let tvd = trial_vector_derivatives(model, cb.as_ref(), &v.tvd)?;
                tvd_cache.push((v.tvd, tvd, t0.elapsed().as_secs_f64()));
                tvd_cache.len() - 1
            }
        };
        let (_, tvd, tvd_s) = &tvd_cache[idx];
        if v.weighted && !spans.iter().any(|x: &SpanReference| x.name == v.name) {
            spans.push(span_reference(
                model,
                &full.state,
                cb.as_ref(),
                tvd.vectors.as_ref(),
                opts,
                v.name,
            )?);
        }
        let p = crate::reduction::pod_tvd(model, tvd, v.weighted)?;
        let prepare_s = tvd_s + t0.elapsed().as_secs_f64();
        energy.push(EnergyCurve {
            name: v.name.into(),
            label: v.label.into(),
            w: p.w.iter().copied().take(opts.max_g).collect(),
            g_threshold: p.choose_g(opts.threshold),
            tvd_nonzero: tvd.nonzero(),
            pod_modes: p.lambda.len(),
        });
        let s = sweep(
            model,
            &full.state,
            cb.as_ref(),
            p.poms.as_ref(),
            opts,
            (v.name, v.label),
        )?;
        series.push(ConvergenceSeries { prepare_s, ..s });
    }

    // Modes only: fixed-interface modes ν+1 ..= ν+max_g once (sparse, zero on the master DOF);
    // g extra modes = their leading columns.
    {
        let t0 = Instant::now();
        let modes = model.modes(opts.nu + opts.max_g, Interface::Fixed)?;
        let m = modes.shapes.nrows();
        let extra = Mat::from_fn(model.dofs(), opts.max_g, |r, c| {
            if r < m {
                modes.shapes[(r, opts.nu + c)]
            } else {
                0.0
            }
        });
        let prepare_s = t0.elapsed().as_secs_f64();
        let s = sweep(
            model,
            &full.state,
            cb.as_ref(),
            extra.as_ref(),
            opts,
            ("modes", "Craig–Bampton, ν + g modes"),
        )?;
        series.push(ConvergenceSeries { prepare_s, ..s });
    }

    // Joint Interface Modes (paper Section 5.3): max_g of them once, g = leading columns.
    {
        let t0 = Instant::now();
        let jim = jim_vectors(model, opts.max_g, JimSet::Both)?;
        let prepare_s = t0.elapsed().as_secs_f64();
        let s = sweep(
            model,
            &full.state,
            cb.as_ref(),
            jim.as_ref(),
            opts,
            ("jim", "Craig–Bampton + g Joint Interface Modes"),
        )?;
        series.push(ConvergenceSeries { prepare_s, ..s });
    }
    series.push(adaptive_series(model, &full.state, cb.as_ref(), opts)?);
    // All joint DOF (paper Section 5.1): the exact limit, one column per pair.
    spans.push(span_reference(
        model,
        &full.state,
        cb.as_ref(),
        alldof_vectors(model)?.as_ref(),
        opts,
        "alldof",
    )?);

    Ok(Study {
        case: model.name.clone(),
        dofs: model.dofs(),
        pairs: model.joint.pairs(),
        nu: opts.nu,
        max_g: opts.max_g,
        scale: opts.scale,
        threshold: opts.threshold,
        full: full_ref,
        series,
        energy,
        tvd_spans: spans,
        craig_bampton_s,
        total_s: t_all.elapsed().as_secs_f64(),
    })
}

/// The convergence tolerances reported in [`ConvergenceSeries::within`].
pub const WITHIN_TOLS: [f64; 2] = [1e-2, 1e-4];

/// `‖f_c‖` of `[base | extra[:, ..g]]` for g = 0 ..= min(max_g, extra.ncols()).
fn sweep(
    model: &Model,
    full: &ContactState,
    base: MatRef<'_, f64>,
    extra: MatRef<'_, f64>,
    opts: &StudyOptions,
    (name, label): (&str, &str),
) -> Result<ConvergenceSeries, Error> {
    let t0 = Instant::now();
    let available = extra.ncols();
    let top = opts.max_g.min(available);
    let fnorm = full.contact_force_norm;
    let mut s = ConvergenceSeries {
        name: name.into(),
        label: label.into(),
        available,
        g: Vec::new(),
        basis_size: Vec::new(),
        contact_force_norm: Vec::new(),
        relative_error: Vec::new(),
        force_vector_error: Vec::new(),
        pairs_in_contact: Vec::new(),
        within: Vec::new(),
        restarts: Vec::new(),
        failures: Vec::new(),
        prepare_s: 0.0,
        sweep_s: 0.0,
    };
    for g in 0..=top {
        let (phi, _) = final_basis(&[base, extra.subcols(0, g)], &model.mass, opts.drop_tol)?;
        let r = phi.ncols();
        let rm = ReducedSystem::new(model, phi)?;
        let sol = match reduced_contact_static_restarting(model, &rm, opts.scale, &opts.contact) {
            Ok((sol, None)) => sol,
            Ok((sol, Some(first))) => {
                s.restarts.push(Failure {
                    g,
                    error: first.to_string(),
                });
                sol
            }
            Err(e) => {
                s.failures.push(Failure {
                    g,
                    error: e.to_string(),
                });
                s.g.push(g);
                s.basis_size.push(r);
                s.contact_force_norm.push(f64::NAN);
                s.relative_error.push(f64::NAN);
                s.force_vector_error.push(f64::NAN);
                s.pairs_in_contact.push(0);
                continue;
            }
        };
        let st = &sol.state;
        let dp: f64 = st
            .forces
            .iter()
            .zip(&full.forces)
            .map(|(a, b)| (a - b) * (a - b))
            .sum::<f64>()
            .sqrt();
        s.g.push(g);
        s.basis_size.push(r);
        s.contact_force_norm.push(st.contact_force_norm);
        s.relative_error
            .push((st.contact_force_norm - fnorm).abs() / fnorm);
        s.force_vector_error.push(dp / fnorm);
        s.pairs_in_contact.push(st.pairs_in_contact);
    }
    s.within = WITHIN_TOLS
        .iter()
        .map(|&tol| within(&s.g, &s.relative_error, tol))
        .collect();
    s.sweep_s = t0.elapsed().as_secs_f64();
    Ok(s)
}

/// First g, and the g from which all later ones are, with `err ≤ tol`.
pub fn within(g: &[usize], err: &[f64], tol: f64) -> Within {
    let first = err.iter().position(|&e| e <= tol).map(|i| g[i]);
    let stays = match err.iter().rposition(|&e| e.is_nan() || e > tol) {
        None => g.first().copied(),
        Some(i) if i + 1 < g.len() => Some(g[i + 1]),
        Some(_) => None,
    };
    Within { tol, first, stays }
}

/// Floor for drawing a zero relative error on a log axis.
pub const ERROR_FLOOR: f64 = 1e-16;
