//! The main job, `jointrom run`: build the model, choose the reduced model's size a priori, run
//! it against the full FE model and write a report a structural-dynamics engineer reads.
//!
//! One call of [`run_main_job`] measures everything the report shows, in the same process on
//! the same machine (steps 1–3; [`crate::report::main_job`] draws and writes steps 4–6):
//!
//! 1. the static convergence study ([`crate::studies::convergence`]: ‖f_c‖ of every basis kind against the
//!    number g of added vectors, and the POD energy ratios w(g) of eq. (26) — the paper's Figs.
//!    7, 8, 15, 16, 19);
//! 2. the full FE transient with friction (BDF + Newton with the structured sparse solve), the
//!    reference of every error below;
//! 3. reduced transients: TVD with g = 0, the paper's sizes (friction bar 10, 25; multilayer
//!    sheet 20, 60) and the a-priori g (smallest g with w(g) ≥ the threshold, eq. 26), plus the
//!    competitors (plain POD, the secant TVD, modes only, Joint Interface Modes, all joint DOF,
//!    and the POD of
//!    200 displacement snapshots of the job's own full run, paper Section 5.2) and functional
//!    (fixed-point) iteration next to Newton; every run under a wall-clock budget, so a method
//!    that does not finish is a measured failure, not a hang; every reduced run carries its own
//!    error estimate ([`crate::rom::estimate::run_estimated`]) beside its true error; and
//!    the tolerance-chosen models ([`crate::rom::tolerance`], TOL = 1e-1, 1e-2, 1e-3), the
//!    one for 1e-2 being the headline reduced model;
//! 4. charts: ‖f_c‖(t), ‖f_R‖(t), master u_y(t) (Figs. 9, 11, 12, 17, 18), and speed against
//!    accuracy — integration CPU time (log) against the relative L2 error of ‖f_c‖(t)
//!
//!    ```text
//!    e = sqrt( Σ_k (‖f_c‖_ROM(t_k) − ‖f_c‖_full(t_k))² / Σ_k ‖f_c‖_full(t_k)² )
//!    ```
//!
//!    over the output times t_k — with the full run's CPU time and the paper's CPU ratios (Sections
//!    4.1.5, 4.2.4) as vertical anchors and the Pareto front (points no other point beats in both
//!    time and error) drawn through;
//! 5. the first joint modes as VTU files and a picture (`shapes/`, [`crate::report::shapes`]);
//!    the stored stability map of the case (`results/stability/CASE`, made by
//!    `jointrom stability CASE`; 17 min, too long to repeat here), copied in when present;
//! 6. `report.md` (the charts as PNG, SVG alongside) and `results.json` with every number.
//!
//! `quick` shortens the transient window to 0.02 s and the study to g ≤ 20 (< 20 s in all).

use std::path::PathBuf;
use std::time::Instant;

use serde::Serialize;

use crate::error::{Error, StudyError};
use crate::integrate::problem::{Iteration, OdeOptions, OdeStats};
use crate::integrate::{
    integrate, ProblemOptions, Run, RunStatus, Scene, Trajectory, TransientOptions,
};
use crate::joint::{T1, T2};
use crate::model::Model;
use crate::reduction::{build_basis, snapshot_basis, BasisKind, BasisOptions, JointFlexibility};
use crate::rom::compare::JointCurves;
use crate::rom::estimate::{run_estimated, RunEstimate};
use crate::rom::tolerance::{tolerance_model, ToleranceOptions};
use crate::studies::convergence::{self as study, StudyOptions};
use crate::studies::stability::Outcome;
use crate::system::{FullSystem, ReducedSystem, SecondOrderSystem};

/// Options of the main job ([`run_main_job`], [`crate::report::main_job::run_report`]). Defaults: the full job (case end time, study g ≤ 60, functional
/// iteration runs included), budgets 60 s per reduced run and 600 s for the full run, progress
/// reported, the stored stability maps under `results/stability`.
#[derive(Clone, Debug)]
pub struct ReportOptions {
    /// Short variant: 0.02 s window, study g ≤ 20, fewer runs.
    pub quick: bool,
    /// Wall-clock budget of one reduced run, s.
    pub rom_budget_s: f64,
    /// Wall-clock budget of the full FE Newton run, s.
    pub full_budget_s: f64,
    /// Wall-clock budget of the full FE run with functional iteration, s (it is expected to fail:
    /// the budget bounds what that failure costs; at most 2 s when `quick`).
    pub full_functional_budget_s: f64,
    /// Report progress to the observer of [`crate::report::main_job::run_report_observed`] (`jointrom run` draws it as a
    /// bar when stderr is a terminal).
    pub progress: bool,
    /// Folder holding stored stability maps (`<dir>/<case>/stability_status.png`).
    pub stability_dir: PathBuf,
    /// Tolerances of the tolerance-chosen models run ([`crate::rom::tolerance`]; `quick`:
    /// the headline one only).
    pub tolerances: Vec<f64>,
    /// The tolerance of the headline reduced model (run whether or not in `tolerances`).
    pub headline_tolerance: f64,
}

impl Default for ReportOptions {
    fn default() -> Self {
        ReportOptions {
            quick: false,
            rom_budget_s: 60.0,
            full_budget_s: 600.0,
            full_functional_budget_s: 5.0,
            progress: true,
            stability_dir: PathBuf::from("results/stability"),
            tolerances: vec![1e-1, 1e-2, 1e-3],
            headline_tolerance: 1e-2,
        }
    }
}

/// One transient run of the report.
#[derive(Clone, Debug, Serialize)]
pub struct RunRecord {
    /// `full` or a basis kind name (`tvd`, `tvd-plain`, `modes`, `jim`, `alldof`).
    pub model: String,
    /// Added vectors g (reduced models).
    pub g: Option<usize>,
    /// Coordinates (full: DOF; reduced: basis size r).
    pub size: usize,
    /// `newton` or `functional`.
    pub iteration: String,
    /// `ok`, `budget` or the CVODE flag.
    pub status: RunStatus,
    /// Failure message.
    pub message: Option<String>,
    /// Time reached, s.
    pub t_reached: f64,
    /// Basis (or model) construction time, s.
    pub build_s: f64,
    /// Integration wall time, s.
    pub wall_s: f64,
    /// Integration CPU time, s.
    pub cpu_s: f64,
    /// Solver statistics.
    pub stats: OdeStats,
    /// Relative L2 error of ‖f_c‖(t) against the full run (`None`: not comparable).
    pub error_fc: Option<f64>,
    /// Relative L2 error of master u_y(t).
    pub error_uy: Option<f64>,
    /// Relative L2 error of ‖f_R‖(t).
    pub error_fr: Option<f64>,
    /// Relative L2 error of the dissipated energy D(t).
    pub error_d: Option<f64>,
    /// Relative error of D at the end of the run.
    pub error_d_end: Option<f64>,
    /// The run's own error estimate (reduced runs; [`crate::rom::estimate::RunEstimate`]),
    /// to set beside the true errors above.
    pub estimate: Option<RunEstimate>,
    /// Why a reduced run has no estimate.
    pub estimate_note: Option<String>,
    /// `adaptive`: the tolerance it was built for and whether its estimate met it.
    pub tolerance: Option<(f64, bool)>,
    /// Full-run integration CPU time over this run's (speed-up).
    pub speedup: Option<f64>,
    /// This run's CPU time in % of the full run's (the paper's measure).
    pub cpu_percent: Option<f64>,
    /// On the Pareto front of (CPU time, error of ‖f_c‖).
    pub pareto: bool,
    /// ‖f_c‖(t), ‖f_R‖(t) and master u_y(t) at the output times.
    #[serde(skip)]
    pub curves: JointCurves,
}

/// The paper's CPU-time ratio of a reduced run to the full run.
#[derive(Clone, Debug, Serialize)]
pub struct PaperAnchor {
    /// g.
    pub g: usize,
    /// CPU time in % of the full FE model.
    pub cpu_percent: f64,
}

/// The joint's hysteresis at one pair: its tangential force against its relative tangential
/// displacement, both along the pair's main direction of friction (the principal direction of
/// `Σ_t p_t p_tᵀ` in the full run).
#[derive(Clone, Debug, Default, Serialize)]
pub struct Hysteresis {
    /// The pair (index into the model's joint pairs): the one that dissipates most in the full
    /// run.
    pub pair: usize,
    /// Its dissipated energy over the full run, `Σ ∫ p_t · ṡ dt` from the output states, N·mm.
    pub dissipated: f64,
    /// The direction, a unit vector in the pair's (t1, t2) plane.
    pub direction: [f64; 2],
    /// The full run: (relative tangential displacement (mm), tangential force (N)) per output.
    #[serde(skip)]
    pub full: Vec<(f64, f64)>,
    /// The headline reduced model, likewise.
    #[serde(skip)]
    pub reduced: Vec<(f64, f64)>,
}

/// Everything the main job measured (written as `results.json`).
#[derive(Clone, Debug, Serialize)]
pub struct Report {
    /// Case name.
    pub case: String,
    /// The CASE argument that reproduces the model: a built-in name, a case file or a matrix map.
    pub source: String,
    /// The command line.
    pub command_line: Vec<String>,
    /// Quick variant.
    pub quick: bool,
    /// Model DOF.
    pub dofs: usize,
    /// Joint pairs.
    pub pairs: usize,
    /// Transient window, s.
    pub end_time: f64,
    /// w threshold of the a-priori choice.
    pub threshold: f64,
    /// The a-priori g (TVD, K-weighted POD).
    pub g_chosen: usize,
    /// w(g) of the K-weighted POD, g = 1, 2, ...
    pub w: Vec<f64>,
    /// w(g) of the plain POD.
    pub w_plain: Vec<f64>,
    /// The static study (summary per basis kind is in `study.json` as well).
    pub study: study::Study,
    /// The transient runs, full first.
    pub runs: Vec<RunRecord>,
    /// The headline reduced model: the tolerance-chosen one for
    /// [`ReportOptions::headline_tolerance`] (index into `runs`; `None` if it failed to build).
    pub headline: Option<usize>,
    /// Its tolerance.
    pub headline_tolerance: f64,
    /// The joint's hysteresis at the pair that dissipates most, full run and headline model
    /// (`None` without friction or a headline model).
    pub hysteresis: Option<Hysteresis>,
    /// The paper's CPU ratios for this case (empty for other cases).
    pub paper_anchors: Vec<PaperAnchor>,
    /// Files written (relative to the report folder).
    pub files: Vec<String>,
    /// Whole job, s.
    pub total_s: f64,
    /// A short backbone of mode 1 of the a-priori TVD model under the case's static load
    /// ([`report_backbone`]); `None` if it could not be computed (`backbone_error` says why).
    pub backbone: Option<crate::studies::backbone::Backbone>,
    /// Why the backbone is missing.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub backbone_error: Option<String>,
    /// Further fields given by the caller (model summary, modes, linear statics).
    #[serde(flatten)]
    pub extra: serde_json::Map<String, serde_json::Value>,
}

/// The paper's g values and CPU ratios (Sections 4.1.5 and 4.2.4).
fn paper_anchors(case: &str) -> Vec<PaperAnchor> {
    let a = |g, p| PaperAnchor { g, cpu_percent: p };
    match case {
        "friction_bar" => vec![a(0, 0.07), a(10, 0.12), a(25, 0.25)],
        "multilayer_sheet" => vec![a(0, 0.42), a(20, 0.44), a(60, 0.49)],
        _ => Vec::new(),
    }
}

/// One planned reduced run.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Plan {
    kind: BasisKind,
    g: usize,
    functional: bool,
}

fn plans(case: &str, g_chosen: usize, pairs: usize, quick: bool) -> Vec<Plan> {
    let paper: Vec<usize> = match case {
        "multilayer_sheet" => vec![20, 60],
        _ => vec![10, 25],
    };
    let mut tvd_g = vec![0, g_chosen];
    tvd_g.extend(&paper);
    if !quick {
        tvd_g.extend([5, 40, pairs.saturating_sub(6)]);
    }
    tvd_g.retain(|&g| g <= pairs);
    tvd_g.sort_unstable();
    tvd_g.dedup();
    let mut out: Vec<Plan> = tvd_g
        .iter()
        .map(|&g| Plan {
            kind: BasisKind::Tvd,
            g,
            functional: false,
        })
        .collect();
    let competitor_g: Vec<usize> = if quick { vec![paper[0]] } else { paper.clone() };
    for kind in [
        BasisKind::TvdPlain,
        BasisKind::TvdSecant,
        BasisKind::Modes,
        BasisKind::Jim,
    ] {
        for &g in &competitor_g {
            out.push(Plan {
                kind,
                g,
                functional: false,
            });
        }
    }
    out.push(Plan {
        kind: BasisKind::AllDof,
        g: pairs,
        functional: false,
    });
    let functional_g: Vec<usize> = if quick {
        vec![g_chosen]
    } else {
        vec![0, g_chosen]
    };
    for g in functional_g {
        out.push(Plan {
            kind: BasisKind::Tvd,
            g,
            functional: true,
        });
    }
    out
}

fn record(
    model: &str,
    g: Option<usize>,
    size: usize,
    functional: bool,
    build_s: f64,
    o: Outcome,
) -> RunRecord {
    RunRecord {
        model: model.into(),
        g,
        size,
        iteration: if functional { "functional" } else { "newton" }.into(),
        status: o.status,
        message: o.message,
        t_reached: o.t_reached,
        build_s,
        wall_s: o.wall_s,
        cpu_s: o.cpu_s,
        stats: o.stats,
        error_fc: None,
        error_uy: None,
        error_fr: None,
        error_d: None,
        error_d_end: None,
        estimate: None,
        estimate_note: None,
        tolerance: None,
        speedup: None,
        cpu_percent: None,
        pareto: false,
        curves: o.curves,
    }
}

/// One run of the report through the driver, from rest over `span` = (end, output step) s,
/// under a wall-clock budget (s); a system that could not be built is the run's status.
fn budgeted<S: SecondOrderSystem>(
    sys: Result<S, Error>,
    model: &Model,
    problem: &ProblemOptions,
    ode: OdeOptions,
    span: (f64, f64),
    budget_s: f64,
) -> Outcome {
    let opts = transient_options(problem, ode, span, budget_s);
    Outcome::of_run(match sys {
        Ok(s) => integrate(s, &Scene::of(model), &opts, |_, _| {}),
        Err(e) => Run::failed(e),
    })
}

/// The options of one run of the report over `span` = (end, output step) s under a wall-clock
/// budget (s).
fn transient_options(
    problem: &ProblemOptions,
    ode: OdeOptions,
    span: (f64, f64),
    budget_s: f64,
) -> TransientOptions {
    TransientOptions {
        ode,
        problem: *problem,
        output_step: span.1,
        end_time: Some(span.0),
        budget_s: Some(budget_s),
        record: false,
        profile: false,
        hook: None,
        ..TransientOptions::default()
    }
}

fn ode_options(functional: bool) -> OdeOptions {
    let mut ode = TransientOptions::default().ode;
    if functional {
        ode.iteration = Iteration::Functional { anderson: 0 };
    }
    ode
}

/// Where the main job stands, as [`run_main_job`] reports it: the stage now running, the
/// steps done and the steps in all (known once the static study has chosen g; 1 before).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Progress {
    /// What runs now (e.g. `full FE model, Newton`).
    pub stage: String,
    /// Steps done.
    pub position: u64,
    /// Steps in all.
    pub total: u64,
    /// The runs are over (a progress bar is cleared).
    pub finished: bool,
}

/// Sends every change of a [`Progress`] to an observer (nothing when `on` is false).
struct Tracker<'a> {
    on: bool,
    state: Progress,
    observer: &'a mut dyn FnMut(&Progress),
}

impl Tracker<'_> {
    fn notify(&mut self) {
        if self.on {
            (self.observer)(&self.state);
        }
    }

    fn set_message(&mut self, stage: impl Into<String>) {
        self.state.stage = stage.into();
        self.notify();
    }

    fn set_length(&mut self, total: u64) {
        self.state.total = total;
        self.notify();
    }

    fn inc(&mut self, steps: u64) {
        self.state.position += steps;
        self.notify();
    }

    fn finish_and_clear(&mut self) {
        self.state.finished = true;
        self.notify();
    }
}

/// Runs the main job's studies and transient runs on `model` (steps 1–3 of the module docs),
/// reporting progress to `observer` when [`ReportOptions::progress`] is set; writes nothing
/// ([`crate::report::main_job::write_report`] does). `extra` fields are carried into the report.
///
/// # Errors
/// Building the model's bases or the full reference run failing. Reduced runs that fail are
/// recorded with their status, not errors.
pub fn run_main_job(
    model: &Model,
    opts: &ReportOptions,
    extra: serde_json::Map<String, serde_json::Value>,
    observer: &mut dyn FnMut(&Progress),
) -> Result<Report, Error> {
    let t_all = Instant::now();
    let case = model.name.clone();
    let end_time = if opts.quick {
        model.end_time.min(0.02)
    } else {
        model.end_time
    };
    let output_step = 1e-4;

    let mut bar = Tracker {
        on: opts.progress,
        state: Progress {
            total: 1,
            ..Progress::default()
        },
        observer,
    };

    // 1. Static study and the a-priori g.
    bar.set_message("static convergence study");
    let study_opts = StudyOptions {
        max_g: if opts.quick { 20 } else { 60 },
        ..StudyOptions::default()
    };
    let st = study::run_study(model, &study_opts)?;
    let energy = |name: &str| st.energy.iter().find(|e| e.name == name);
    let tvd_energy = energy("tvd").ok_or(StudyError::NoTvdEnergy)?;
    let g_chosen = tvd_energy.g_threshold;
    let w = tvd_energy.w.clone();
    let w_plain = energy("tvd-plain").map(|e| e.w.clone()).unwrap_or_default();

    let pairs = model.joint.pairs();
    let plan = plans(&case, g_chosen, pairs, opts.quick);
    bar.set_length(
        (plan.len() + run_tolerances(opts).len() + snapshot_sizes(&case).len()) as u64 + 3,
    );
    bar.inc(1);

    // 2. The full reference and 3. the reduced runs.
    let span = (end_time, output_step);
    let mut snapshots = Vec::new();
    let mut full_states = None;
    let mut runs = full_runs(
        model,
        opts,
        span,
        &mut bar,
        &mut snapshots,
        &mut full_states,
    )?;
    let flex = JointFlexibility::new(model)?;
    reduced_runs(model, &flex, opts, &plan, span, &mut bar, &mut runs)?;
    snapshot_runs(model, &flex, opts, &snapshots, span, &mut bar, &mut runs);
    let mut headline_states = None;
    let headline = tolerance_runs(model, opts, span, &mut bar, &mut runs, &mut headline_states);
    bar.set_message("backbone of mode 1");
    let backbone = report_backbone(model, g_chosen, opts.quick);
    bar.finish_and_clear();
    let hysteresis = full_states
        .zip(headline_states)
        .and_then(|(full, (rom, reduced))| hysteresis(model, &full, &rom, &reduced));

    // Errors, speed-ups, Pareto front.
    compare_to_full(&mut runs);
    mark_pareto(&mut runs);

    let anchors = paper_anchors(&case);
    let mut report = Report {
        case: case.clone(),
        source: model
            .source
            .strip_prefix("builtin:")
            .unwrap_or(&model.source)
            .to_string(),
        command_line: std::env::args().collect(),
        quick: opts.quick,
        dofs: model.dofs(),
        pairs,
        end_time,
        threshold: st.threshold,
        g_chosen,
        w,
        w_plain,
        study: st,
        runs,
        headline,
        headline_tolerance: opts.headline_tolerance,
        hysteresis,
        paper_anchors: anchors,
        files: Vec::new(),
        total_s: 0.0,
        backbone_error: backbone.as_ref().err().map(|e| e.to_string()),
        backbone: backbone.ok(),
        extra,
    };

    report.total_s = t_all.elapsed().as_secs_f64();
    Ok(report)
}

/// The main job's backbone: mode 1 of the a-priori TVD model (g reduced vectors) under the
/// case's static load, two cycles per ring-down at 5 amplitudes (3 when `quick`) spaced
/// logarithmically from 1e-8 to 1e-4 of the master's static linear translation (1 mm if the
/// load does not move it): four decades, over which the built-in scenes' joints go from stick
/// to slip. A few seconds of reduced runs.
pub fn report_backbone(
    model: &Model,
    g: usize,
    quick: bool,
) -> Result<crate::studies::backbone::Backbone, Error> {
    use crate::studies::backbone::{compute, log_range, BackboneOptions};
    let u = model
        .static_linear(&[model.master_load()])?
        .first()
        .map(|s| {
            let m = s.master_displacement;
            (m[0] * m[0] + m[1] * m[1] + m[2] * m[2]).sqrt()
        })
        .unwrap_or(0.0);
    let base = if u.is_finite() && u > 0.0 { u } else { 1.0 };
    let opts = BackboneOptions {
        modes: vec![1],
        amplitudes: log_range(1e-8 * base, 1e-4 * base, if quick { 3 } else { 5 })?,
        preload: 1.0,
        cycles: 2,
        transient: {
            let mut t = TransientOptions {
                budget_s: Some(60.0),
                ..TransientOptions::default()
            };
            t.ode.atol = crate::studies::backbone::DEFAULT_ATOL;
            t
        },
    };
    let spec = crate::rom::ModelSpec::Basis {
        kind: crate::reduction::BasisKind::Tvd,
        g: Some(g),
        nu: BasisOptions::default().nu,
    };
    compute(model, &spec, &opts)
}

/// Marks the runs no other run beats in both CPU time and ‖f_c‖ error (finished runs with an
/// error only).
fn mark_pareto(runs: &mut [RunRecord]) {
    let pts: Vec<Option<(f64, f64)>> = runs
        .iter()
        .map(|r| match (r.status.finished(), r.error_fc) {
            (true, Some(e)) if r.cpu_s.is_finite() && e.is_finite() => Some((r.cpu_s, e)),
            _ => None,
        })
        .collect();
    for i in 0..runs.len() {
        let Some((ci, ei)) = pts[i] else { continue };
        let dominated = pts.iter().enumerate().any(|(j, p)| {
            j != i && p.is_some_and(|(cj, ej)| cj <= ci && ej <= ei && (cj < ci || ej < ei))
        });
        runs[i].pareto = !dominated;
    }
}

/// The full FE runs (step 2): Newton, the reference of every error (its failure is an error),
/// and functional iteration (expected to fail: recorded).
fn full_runs(
    model: &Model,
    opts: &ReportOptions,
    span: (f64, f64),
    bar: &mut Tracker<'_>,
    snapshots: &mut Vec<Vec<f64>>,
    states: &mut Option<Trajectory>,
) -> Result<Vec<RunRecord>, Error> {
    let problem = ProblemOptions::default();
    bar.set_message("full FE model, Newton");
    let t0 = Instant::now();
    let full_sys = FullSystem::new(model);
    let build_full = t0.elapsed().as_secs_f64();
    // Every k-th displacement state (about SNAPSHOTS) for the POD-snapshot competitor.
    let every = ((span.0 / span.1).ceil() as usize / SNAPSHOTS).max(1);
    let mut k = 0usize;
    // The full run's states are kept for the joint's hysteresis.
    let recorded = TransientOptions {
        record: true,
        ..transient_options(&problem, ode_options(false), span, opts.full_budget_s)
    };
    let mut full_run = match full_sys {
        Ok(s) => integrate(s, &Scene::of(model), &recorded, |_, q| {
            if k % every == 0 {
                snapshots.push(q.to_vec());
            }
            k += 1;
        }),
        Err(e) => Run::failed(e),
    };
    *states = full_run.trajectory.take();
    let full = Outcome::of_run(full_run);
    if !full.ok() {
        return Err(StudyError::ReferenceFailed {
            t: full.t_reached,
            status: full.status.to_string(),
            message: full.message.clone().unwrap_or_default(),
        }
        .into());
    }
    let mut runs = vec![record("full", None, model.dofs(), false, build_full, full)];
    bar.inc(1);
    bar.set_message("full FE model, functional iteration");
    let full_fun = budgeted(
        FullSystem::new(model),
        model,
        &problem,
        ode_options(true),
        span,
        if opts.quick {
            opts.full_functional_budget_s.min(2.0)
        } else {
            opts.full_functional_budget_s
        },
    );
    runs.push(record(
        "full",
        None,
        model.dofs(),
        true,
        build_full,
        full_fun,
    ));
    bar.inc(1);

    Ok(runs)
}

/// The reduced runs of the plan (step 3), each on its own basis and under its budget.
fn reduced_runs(
    model: &Model,
    flex: &JointFlexibility,
    opts: &ReportOptions,
    plan: &[Plan],
    span: (f64, f64),
    bar: &mut Tracker<'_>,
    runs: &mut Vec<RunRecord>,
) -> Result<(), Error> {
    let problem = ProblemOptions::default();
    for p in plan {
        bar.set_message(format!(
            "{} g = {} ({})",
            p.kind.name(),
            p.g,
            if p.functional { "functional" } else { "Newton" }
        ));
        let t0 = Instant::now();
        let basis = build_basis(
            model,
            p.kind,
            &BasisOptions {
                g: Some(p.g),
                ..BasisOptions::default()
            },
        )?;
        let g_used = basis.g;
        let rm = ReducedSystem::new(model, basis.phi)?;
        let build_s = t0.elapsed().as_secs_f64();
        let t_opts =
            transient_options(&problem, ode_options(p.functional), span, opts.rom_budget_s);
        let rec = estimated_record(
            model,
            flex,
            rm,
            &t_opts,
            (p.kind.name(), g_used, p.functional, build_s),
        );
        runs.push(rec);
        bar.inc(1);
    }
    Ok(())
}

/// The record of a reduced run with its error estimate; `(model, g, functional, build_s)` label
/// it. A run that cannot start is recorded with its status.
fn estimated_record(
    model: &Model,
    flex: &JointFlexibility,
    rm: ReducedSystem,
    t_opts: &TransientOptions,
    (name, g, functional, build_s): (&str, usize, bool, f64),
) -> RunRecord {
    let dim = rm.dim();
    match run_estimated(model, flex, rm, &Scene::of(model), t_opts, true, |_, _| {}) {
        Ok((run, est)) => {
            let mut rec = record(
                name,
                Some(g),
                dim,
                functional,
                build_s,
                Outcome::of_run(run),
            );
            match est {
                Ok(e) => rec.estimate = Some(e),
                Err(e) => rec.estimate_note = Some(e.to_string()),
            }
            rec
        }
        Err(e) => record(
            name,
            Some(g),
            dim,
            functional,
            build_s,
            Outcome::of_run(Run::failed(e)),
        ),
    }
}

/// Snapshots of the full run kept for the POD-snapshot competitor.
const SNAPSHOTS: usize = 200;

/// The POD-snapshot competitor's sizes: the paper's (friction bar 10, 25; multilayer 20, 60).
fn snapshot_sizes(case: &str) -> Vec<usize> {
    match case {
        "multilayer_sheet" => vec![20, 60],
        _ => vec![10, 25],
    }
}

/// The POD-snapshot competitor (paper Section 5.2, [`crate::reduction::snapshot_basis`]):
/// Craig–Bampton plus the leading POD modes of [`SNAPSHOTS`] displacement states of the job's own
/// full run — trained on the very run it is compared with, its best case. Each run carries its
/// estimate; the basis build time excludes the full run it needs.
fn snapshot_runs(
    model: &Model,
    flex: &JointFlexibility,
    opts: &ReportOptions,
    snapshots: &[Vec<f64>],
    span: (f64, f64),
    bar: &mut Tracker<'_>,
    runs: &mut Vec<RunRecord>,
) {
    let y = faer::Mat::from_fn(model.dofs(), snapshots.len(), |r, c| snapshots[c][r]);
    let t_opts = transient_options(
        &ProblemOptions::default(),
        ode_options(false),
        span,
        opts.rom_budget_s,
    );
    for g in snapshot_sizes(&model.name) {
        bar.set_message(format!("pod g = {g} (Newton)"));
        let t0 = Instant::now();
        let built = snapshot_basis(
            model,
            y.as_ref(),
            None,
            &BasisOptions {
                g: Some(g),
                ..BasisOptions::default()
            },
        )
        .and_then(|b| Ok((b.g, ReducedSystem::new(model, b.phi)?)));
        let build_s = t0.elapsed().as_secs_f64();
        let rec = match built {
            Ok((g_used, rm)) => {
                estimated_record(model, flex, rm, &t_opts, ("pod", g_used, false, build_s))
            }
            Err(e) => record(
                "pod",
                Some(g),
                0,
                false,
                build_s,
                Outcome::of_run(Run::failed(e)),
            ),
        };
        runs.push(rec);
        bar.inc(1);
    }
}

/// The tolerances the job runs: [`ReportOptions::tolerances`] (only the headline one when
/// `quick`) and the headline one, ascending, without repeats.
fn run_tolerances(opts: &ReportOptions) -> Vec<f64> {
    let mut tols: Vec<f64> = if opts.quick {
        Vec::new()
    } else {
        opts.tolerances.clone()
    };
    tols.push(opts.headline_tolerance);
    tols.sort_by(|a, b| b.total_cmp(a));
    tols.dedup();
    tols
}

/// The tolerance-chosen models (step 3, [`crate::rom::tolerance`]): one run each, its
/// offline time as the build time; returns the index of the headline model's run. A model
/// that cannot be built or run is recorded with its status.
fn tolerance_runs(
    model: &Model,
    opts: &ReportOptions,
    span: (f64, f64),
    bar: &mut Tracker<'_>,
    runs: &mut Vec<RunRecord>,
    headline_states: &mut Option<(ReducedSystem, Trajectory)>,
) -> Option<usize> {
    let mut headline = None;
    for tol in run_tolerances(opts) {
        bar.set_message(format!("adaptive, tolerance {tol:e}"));
        let mut t_opts = ToleranceOptions::new(tol);
        t_opts.transient = transient_options(
            &ProblemOptions::default(),
            ode_options(false),
            span,
            opts.rom_budget_s,
        );
        let rec = match tolerance_model(model, &t_opts) {
            Ok(t) => {
                if tol == opts.headline_tolerance {
                    // The headline model's states for the joint's hysteresis: its run again,
                    // recorded (the estimate consumed the first run's states).
                    let again = TransientOptions {
                        record: true,
                        ..t.transient.clone()
                    };
                    let mut run = integrate(t.rom.clone(), &Scene::of(model), &again, |_, _| {});
                    *headline_states = run.trajectory.take().map(|tr| (t.rom.clone(), tr));
                }
                let mut rec = record(
                    "adaptive",
                    Some(t.pairs.len()),
                    t.rom.dim(),
                    false,
                    t.offline_s,
                    Outcome::of_run(t.run),
                );
                rec.tolerance = Some((tol, t.met));
                rec.estimate = Some(t.estimate);
                rec
            }
            Err(e) => {
                let mut rec = record(
                    "adaptive",
                    None,
                    0,
                    false,
                    0.0,
                    Outcome::of_run(Run::failed(e)),
                );
                rec.tolerance = Some((tol, false));
                rec
            }
        };
        if tol == opts.headline_tolerance && rec.status.finished() {
            headline = Some(runs.len());
        }
        runs.push(rec);
        bar.inc(1);
    }
    headline
}

/// Each finished reduced run's relative L2 errors of ‖f_c‖, ‖f_R‖, u_y and D against the full run
/// (`runs[0]`) and its CPU speed-up.
fn compare_to_full(runs: &mut [RunRecord]) {
    let (full, cpu_ref) = (runs[0].curves.clone(), runs[0].cpu_s);
    for r in runs.iter_mut().skip(1) {
        if !r.status.finished() {
            continue;
        }
        let e = r.curves.errors_against(&full);
        r.error_fc = e.contact_force;
        r.error_uy = e.master_uy;
        r.error_fr = e.friction_force;
        r.error_d = e.dissipated;
        r.error_d_end = e.dissipated_end;
        if r.cpu_s > 0.0 && cpu_ref.is_finite() {
            r.speedup = Some(cpu_ref / r.cpu_s);
            r.cpu_percent = Some(100.0 * r.cpu_s / cpu_ref);
        }
    }
}

/// The joint's hysteresis ([`Hysteresis`]) at the pair that dissipates most in the full run,
/// from the full run's recorded states and the headline model's; `None` without friction.
fn hysteresis(
    model: &Model,
    full: &Trajectory,
    rom: &ReducedSystem,
    reduced: &Trajectory,
) -> Option<Hysteresis> {
    let w = model.joint.pairs();
    let outputs = full.p.len() / (3 * w).max(1);
    if w == 0 || full.s.len() != 2 * w * outputs || outputs < 2 {
        return None;
    }
    let force = |p: &[f64], j: usize, k: usize| {
        let o = 3 * w * j + 3 * k;
        [p[o + 1], p[o + 2]]
    };
    let mut dissipated = vec![0.0; w];
    let mut moment = vec![[0.0; 3]; w];
    for j in 0..outputs {
        for k in 0..w {
            let f = force(&full.p, j, k);
            moment[k][0] += f[0] * f[0];
            moment[k][1] += f[0] * f[1];
            moment[k][2] += f[1] * f[1];
            if j + 1 < outputs {
                let f1 = force(&full.p, j + 1, k);
                for c in 0..2 {
                    let ds = full.s[2 * w * (j + 1) + 2 * k + c] - full.s[2 * w * j + 2 * k + c];
                    dissipated[k] += 0.5 * (f[c] + f1[c]) * ds;
                }
            }
        }
    }
    let pair = (0..w).max_by(|&a, &b| dissipated[a].total_cmp(&dissipated[b]))?;
    if dissipated[pair] <= 0.0 {
        return None;
    }
    let m = moment[pair];
    let angle = 0.5 * (2.0 * m[1]).atan2(m[0] - m[2]);
    let d = [angle.cos(), angle.sin()];
    let along = |v: [f64; 2]| d[0] * v[0] + d[1] * v[1];
    let n = model.dofs();
    let slip =
        |q: &[f64], c: usize| -> f64 { model.joint.row(3 * pair + c).map(|(i, v)| v * q[i]).sum() };
    let full_curve = (0..outputs)
        .map(|j| {
            let q = &full.q[n * j..n * (j + 1)];
            (
                along([slip(q, T1), slip(q, T2)]),
                along(force(&full.p, j, pair)),
            )
        })
        .collect();
    let r = rom.dim();
    let mut u = vec![0.0; 3 * w];
    let reduced_curve = (0..reduced.p.len() / (3 * w))
        .map(|j| {
            rom.joint_apply_into(&reduced.q[r * j..r * (j + 1)], &mut u);
            (
                along([u[3 * pair + T1], u[3 * pair + T2]]),
                along(force(&reduced.p, j, pair)),
            )
        })
        .collect();
    Some(Hysteresis {
        pair,
        dissipated: dissipated[pair],
        direction: d,
        full: full_curve,
        reduced: reduced_curve,
    })
}
