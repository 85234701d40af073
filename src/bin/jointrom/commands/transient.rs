//! `jointrom transient`: a transient run from rest (CVODE) of the full FE model or a reduced
//! one; curves, solver statistics, wall time, optionally files and VTU frames.

use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::Args;
use serde_json::{json, Value};

use jointrom::error::{FlagError, RomError};
use jointrom::integrate::driver::dirk_table_flag;
use jointrom::integrate::problem::{DirkTable, Method};
use jointrom::integrate::{Curves, RunChoices, TransientOptions};
use jointrom::rom::compare::{ReferenceCurves, ReferenceErrors};
use jointrom::rom::spec::DEFAULT_SNAPSHOTS;
use jointrom::rom::tolerance::{worst, IntegrationTolerances};
use jointrom::rom::{
    run_model, CompressJoint, ModelFlags, ModelRun, ModelSpec, RunEstimate, RunSettings,
};
use jointrom::{Error, Model};

use jointrom::studies::stability::IterKind;

use crate::args::{MethodKind, OnOff};
use crate::common::{create_dir, positive, print_json, write_file};

#[derive(Args)]
pub struct TransientArgs {
    /// Case file, matrix map (`jointrom-matrices` JSON) or built-in name.
    case: String,
    /// The model (default: tvd, or adaptive with --tolerance).
    #[command(flatten)]
    model: ModelFlags,
    /// With --tolerance: exit non-zero (after printing the best model's run) when the estimate
    /// does not meet the tolerance. Without it a miss is a warning.
    #[arg(long, requires = "tolerance")]
    strict: bool,
    /// With --tolerance: the joint columns of the model that meets it, per pair (off) or
    /// compressed to the POD of the deformation the corrected pair forces cause (on; kept only
    /// if the compressed model meets the tolerance with a smaller basis); auto runs a compressed
    /// model only where its basis is at most three quarters of the per-pair one. JSON
    /// `"tolerance"."compression"`.
    #[arg(long, value_enum, default_value = "auto", requires = "tolerance")]
    compress_joint: CompressJoint,
    /// `--model pod`: end of the full-FE training run, s (default: the run's end time).
    #[arg(long)]
    train_end: Option<f64>,
    /// `--model pod`: about this many snapshots kept from the training run (every k-th output,
    /// k = outputs / N).
    #[arg(long, default_value_t = DEFAULT_SNAPSHOTS)]
    snapshots: usize,
    /// Nonlinear iteration: newton (structured solve) or functional (fixed point).
    #[arg(long, value_enum, default_value_t = IterKind::Newton)]
    iteration: IterKind,
    /// Friction on or off.
    #[arg(long, value_enum, default_value_t = OnOff::On)]
    friction: OnOff,
    /// Event location on gaps and stick/slip switches, on or off.
    #[arg(long, value_enum, default_value_t = OnOff::Off)]
    events: OnOff,
    /// Relative tolerance.
    #[arg(long)]
    rtol: Option<f64>,
    /// Absolute tolerance, mm of the physical displacement field.
    #[arg(long)]
    atol: Option<f64>,
    /// Velocity tolerance per displacement tolerance, 1/s.
    #[arg(long)]
    velocity_scale: Option<f64>,
    /// Integration method: bdf (CVODE's BDF, the paper's) or dirk (an L-stable, stiffly
    /// accurate diagonally implicit Runge–Kutta method of ARKODE, table --dirk-table).
    #[arg(long, value_enum, default_value_t = MethodKind::Bdf)]
    method: MethodKind,
    /// `--method dirk`: ARKODE's Butcher table, e.g. ARK324L2SA_DIRK_4_2_3 (default: the cheapest
    /// measured), ESDIRK324L2SA_4_2_3, KVAERNO_4_2_3, SDIRK_5_3_4 (with or without `ARKODE_`).
    #[arg(long)]
    dirk_table: Option<String>,
    /// Maximum BDF order (1–5).
    #[arg(long)]
    max_order: Option<usize>,
    /// BDF stability-limit detection, on or off.
    #[arg(long, value_enum)]
    stab_lim_det: Option<OnOff>,
    /// Time every callback of the run: JSON `"profile"` (right-hand sides, Newton setups and
    /// solves, the rest = CVODE's own work), at two clock reads per callback.
    #[arg(long)]
    profile: bool,
    /// Active-set refresh inside Newton iterations: a margin in mm (a pair past its switch by
    /// more than this re-linearizes and refactors the Newton matrix), or `off`. Default 1e-8.
    #[arg(long)]
    refresh: Option<String>,
    /// Pair screening of reduced models: evaluate only the joint pairs that may be in contact
    /// within a step, the others proved open by a bound (on), or every pair at every
    /// right-hand side (off). The full model evaluates every pair. Default off
    #[arg(long, value_enum)]
    screen: Option<OnOff>,
    /// Slip memory of reduced models as elastic stretch `e = u_t − s` (on) or as the slip `s`
    /// (off); the same law and curves. The full model keeps `s`. Default off
    #[arg(long, value_enum)]
    stretch: Option<OnOff>,
    /// Reduced models: keep the slip memory of open pairs in the error test (on), or give it
    /// zero weight, its value being slaved to the pair's tangential motion (off: fewer steps,
    /// the same curves to the integration tolerance). The full model tests every state.
    /// Default off
    #[arg(long, value_enum)]
    open_slip_test: Option<OnOff>,
    /// `--model full`: capacity of the exact low-rank update of the Newton factor at active-set
    /// refreshes, columns (one per changed pair row; a refresh that would exceed it refactors);
    /// 0 refactors at every refresh. Default 96.
    #[arg(long)]
    low_rank: Option<usize>,
    /// Smallest step-size growth CVODE acts on after a successful step (≥ 1; CVODE's own
    /// default 1.5).
    #[arg(long)]
    step_growth: Option<f64>,
    /// End time, s (default: the case's).
    #[arg(long)]
    end_time: Option<f64>,
    /// Output spacing, s.
    #[arg(long, default_value_t = 1e-4)]
    output_step: f64,
    /// Wall-clock budget of the integration, s: a run that has not finished by then stops with
    /// an error (and the curves up to the time reached in --json/--out).
    #[arg(long, default_value_t = jointrom::integrate::driver::DEFAULT_MAX_WALL_S)]
    max_wall: f64,
    /// Compare the run with stored reference curves (CSV with columns t, contact_force_norm,
    /// friction_force_norm, master_uy — e.g. `cases/reference/scale/*.csv` or a run's
    /// curves.csv — or a compact JSON reference): relative L2 errors of ‖f_c‖, ‖f_R‖ and u_y
    /// over the shared output times, and of the dissipated energy D (over the run and at its
    /// end) where the reference holds it (column `dissipated`), JSON `"reference_error"`.
    #[arg(long)]
    reference: Option<PathBuf>,
    /// One JSON document on stdout (with the curves).
    #[arg(long)]
    json: bool,
    /// Write curves.csv and transient.json into this folder.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Write the displacement field over time as VTU files plus a `.pvd` collection
    /// (ParaView plays it) into this folder: DIR/u_NNNN.vtu, DIR/u.pvd. Reduced runs are
    /// expanded with their basis, u = Φ q.
    #[arg(long)]
    vtu: Option<PathBuf>,
    /// `--vtu`: about this many frames (every k-th output, k = outputs / N).
    #[arg(long, default_value_t = 100)]
    vtu_frames: usize,
}

pub fn run(a: TransientArgs) -> Result<(), Error> {
    let opts = transient_options(&a)?;
    let reference = match &a.reference {
        Some(path) => {
            let r = ReferenceCurves::read(path)?;
            crate::common::record_input(format!("reference curves {}", path.display()));
            Some(r)
        }
        None => None,
    };
    let model = crate::common::load_model(&a.case)?;
    let vtu_every = vtu_every(&a, &opts, &model)?;
    let spec = model_spec(&a)?;
    if let ModelSpec::File(path) = &spec {
        crate::common::record_input(format!("reduced model {}", path.display()));
    }
    let t0 = Instant::now();
    let mut o = run_model(
        &model,
        &spec,
        &opts,
        &RunSettings {
            keep_every: vtu_every,
            low_rank: a.low_rank,
            integration: if a.rtol.is_some() || a.atol.is_some() {
                IntegrationTolerances::Given
            } else {
                IntegrationTolerances::FromTolerance
            },
            compress_joint: a.compress_joint,
        },
    )?;
    // The largest estimated error of the quantities the tolerance holds for.
    let worst_estimate = o
        .tolerance
        .as_ref()
        .zip(o.estimate.as_ref().and_then(|e| e.as_ref().ok()))
        .map_or(f64::NAN, |(t, e)| worst(&e.total, t.quantities));
    warn_tolerance(&o, worst_estimate);
    let total_s = t0.elapsed().as_secs_f64();
    let name = spec_name(&a, &spec);
    let c = &o.run.curves;
    let reference_error = reference.as_ref().map(|r| {
        let e = r.errors(c);
        json!({
            "path": a.reference.as_ref().map(|p| p.display().to_string()),
            "contact_force": e.contact_force,
            "friction_force": e.friction_force,
            "master_uy": e.master_uy,
            "dissipated": e.dissipated,
            "dissipated_end": e.dissipated_end,
            "compared_outputs": e.compared_outputs,
            "compared_until": e.compared_until,
        })
    });
    let doc = json!({
        "case": model.name,
        "model": name,
        "basis": name,
        "basis_size": o.basis_size,
        "g": o.g,
        "offline_s": o.offline_s,
        "tolerance": o.tolerance,
        "options": opts,
        "stats": o.run.stats,
        "events": o.run.events,
        "wall_s": o.run.wall_s,
        "cpu_s": o.run.cpu_s,
        "total_s": total_s,
        "error_estimate": estimate_json(&o.estimate),
        "reference_error": reference_error,
        "curves": c,
        "energy_balance": c.balance(),
        "joint_dissipated_energy": c.dissipated.last().copied().unwrap_or(0.0),
        "contact": model.contact,
        "energy_check": c.energy_check(opts.energy_resolution()),
        "training": o.training,
        "profile": o.run.profile,
        "status": o.run.status,
        "warnings": model.warnings,
    });
    let check = c.energy_check(opts.energy_resolution());
    if !check.ok {
        eprintln!(
            "jointrom: warning: energy balance off by {:.3e} of the run's energy ({:.3e} N·mm \
             of {:.3e}; tolerance {:e}): the results are not trustworthy — check k_n and the \
             iteration (see `energy_check` in the JSON)",
            check.residual_ratio, check.max_residual, check.energy_scale, check.tolerance
        );
    }
    if let Some(dir) = &a.vtu {
        let (times, states): (Vec<f64>, Vec<Vec<f64>>) =
            std::mem::take(&mut o.frames).into_iter().unzip();
        let pvd = jointrom::report::vtu::write_series(&model, "u", &times, &states, dir)?;
        eprintln!("{} frames → {}", times.len(), pvd.display());
    }
    if let Some(dir) = &a.out {
        write_outputs(dir, &doc, c)?;
    }
    if a.json {
        print_json(&doc);
    } else {
        print_summary(&a, &name, &model, &o, total_s);
        if let Some(r) = &reference {
            print_reference_errors(&r.errors(c));
        }
    }
    let met = o.tolerance.as_ref().is_none_or(|t| t.met);
    if a.strict && !met {
        return Err(RomError::Strict {
            estimate: worst_estimate,
            tolerance: a.model.tolerance.unwrap_or(f64::NAN),
        }
        .into());
    }
    Ok(())
}

/// The options of a `transient` run from its flags (errors name the flag).
fn transient_options(a: &TransientArgs) -> Result<TransientOptions, Error> {
    let mut o = RunChoices {
        iteration: a.iteration.iteration(),
        friction: a.friction.is_on(),
        events: a.events.is_on(),
        rtol: a.rtol,
        atol: a.atol,
        max_order: a.max_order,
        end_time: a.end_time,
        output_step: a.output_step,
        max_wall: a.max_wall,
    }
    .options()?;
    if let Some(v) = a.velocity_scale {
        o.problem.velocity_scale = positive("velocity-scale", v)?;
    }
    if let Some(s) = a.stab_lim_det {
        o.ode.stab_lim_det = s.is_on();
    }
    o.ode.method = method(a)?;
    o.profile = a.profile;
    if let Some(s) = a.screen {
        o.problem.screen = s.is_on();
    }
    if let Some(s) = a.stretch {
        o.problem.stretch = s.is_on();
    }
    if let Some(s) = a.open_slip_test {
        o.problem.open_slip_test = s.is_on();
    }
    if let Some(r) = &a.refresh {
        o.problem.refresh = if r == "off" {
            None
        } else {
            match r.parse::<f64>() {
                Ok(m) if m.is_finite() && m >= 0.0 => Some(m),
                _ => {
                    return Err(FlagError::Range {
                        flag: "refresh",
                        need: "`off` or a margin in mm (finite, >= 0)",
                        got: format!("`{r}`"),
                    }
                    .into())
                }
            }
        };
    }
    if let Some(g) = a.step_growth {
        if !(g.is_finite() && g >= 1.0) {
            return Err(FlagError::Range {
                flag: "step-growth",
                need: "finite and >= 1",
                got: g.to_string(),
            }
            .into());
        }
        o.ode.step_growth = g;
    }
    Ok(o)
}

/// `--method` and `--dirk-table` (BDF's flags `--max-order`, `--stab-lim-det on` and
/// `--iteration functional` refused with a DIRK method, `--dirk-table` without one).
fn method(a: &TransientArgs) -> Result<Method, Error> {
    match a.method {
        MethodKind::Bdf => match &a.dirk_table {
            Some(t) => Err(FlagError::Value {
                flag: "dirk-table",
                value: t.clone(),
                need: "only with --method dirk",
            }
            .into()),
            None => Ok(Method::Bdf),
        },
        MethodKind::Dirk => {
            let refuse = |flag, value: String| {
                Err(FlagError::Value {
                    flag,
                    value,
                    need: "only with --method bdf (a DIRK table fixes its order and stability)",
                }
                .into())
            };
            if let Some(k) = a.max_order {
                return refuse("max-order", k.to_string());
            }
            if a.stab_lim_det == Some(OnOff::On) {
                return refuse("stab-lim-det", "on".into());
            }
            if a.iteration == IterKind::Functional {
                return Err(FlagError::Value {
                    flag: "iteration",
                    value: "functional".into(),
                    need: "newton with --method dirk",
                }
                .into());
            }
            let table = match &a.dirk_table {
                Some(name) => dirk_table_flag("dirk-table", name)?,
                None => DirkTable::Ark324Dirk,
            };
            Ok(Method::Dirk(table))
        }
    }
}

/// `--vtu`: every how many outputs a frame is kept (`None` without `--vtu`).
fn vtu_every(
    a: &TransientArgs,
    opts: &TransientOptions,
    model: &Model,
) -> Result<Option<usize>, Error> {
    match &a.vtu {
        None => Ok(None),
        Some(_) if a.vtu_frames == 0 => Err(FlagError::AtLeast {
            flag: "vtu-frames",
            min: 1,
        }
        .into()),
        Some(_) => {
            let end = opts.end_time.unwrap_or(model.end_time);
            let outputs = (end / opts.output_step).ceil().max(1.0) as usize + 1;
            Ok(Some((outputs / a.vtu_frames).max(1)))
        }
    }
}

/// The model the flags name (default `tvd`, `adaptive` with `--tolerance`), with the POD
/// training flags.
fn model_spec(a: &TransientArgs) -> Result<ModelSpec, Error> {
    let mut spec = a.model.spec_or_tvd()?;
    match &mut spec {
        ModelSpec::Pod {
            train_end,
            snapshots,
            ..
        } => {
            *train_end = a.train_end.map(|t| positive("train-end", t)).transpose()?;
            *snapshots = a.snapshots;
        }
        _ if a.train_end.is_some() => return Err(RomError::TrainEndNotPod.into()),
        _ => {}
    }
    Ok(spec)
}

/// The model's name in the outputs: `--model` as given, else the spec's (`tvd`, `adaptive`).
fn spec_name(a: &TransientArgs, spec: &ModelSpec) -> String {
    a.model.model.clone().unwrap_or_else(|| spec.name())
}

/// `"error_estimate"`: the estimated relative L2 errors, or `{"unavailable": why}`; `null` for
/// the full model.
fn estimate_json(e: &Option<Result<RunEstimate, String>>) -> Value {
    match e {
        None => Value::Null,
        Some(Ok(e)) => serde_json::to_value(e).expect("an estimate serialises"),
        Some(Err(why)) => json!({ "unavailable": why }),
    }
}

/// `--out DIR`: DIR/transient.json (the JSON document) and DIR/curves.csv.
fn write_outputs(dir: &Path, doc: &Value, c: &Curves) -> Result<(), Error> {
    create_dir(dir)?;
    write_file(
        &dir.join("transient.json"),
        serde_json::to_string(doc).expect("JSON values serialise"),
    )?;
    let csv = jointrom::report::curves::curves_csv(c)?;
    write_file(&dir.join("curves.csv"), csv)
}

/// The text summary of a run.
fn print_summary(a: &TransientArgs, name: &str, model: &Model, o: &ModelRun, total_s: f64) {
    let (res, c) = (&o.run, &o.run.curves);
    let s = &res.stats;
    println!(
        "{} — model {} (n = {}{}), friction {}, events {}",
        jointrom::files::printable(&model.name),
        name,
        o.basis_size,
        o.g.map(|g| format!(", g = {g}")).unwrap_or_default(),
        a.friction.name(),
        a.events.name()
    );
    println!(
        "t_end {:.4e} s: {} steps, {} RHS, {} nonlinear iterations ({} conv. failures), {} error-test failures, {} setups, last order {}, last h {:.2e} s",
        c.t.last().copied().unwrap_or(0.0),
        s.steps,
        s.rhs_evals,
        s.nonlinear_iterations,
        s.nonlinear_conv_failures,
        s.error_test_failures,
        s.linear_setups,
        s.last_order,
        s.last_step
    );
    println!(
        "wall {:.3} s, cpu {:.2} s (total incl. model {:.3} s)",
        res.wall_s, res.cpu_s, total_s
    );
    if let Some(i) = c.t.len().checked_sub(1) {
        println!(
            "final: |f_c| {:.6e} N, |f_R| {:.6e} N, master uy {:.6e} mm",
            c.contact_force_norm[i], c.friction_force_norm[i], c.master_uy[i]
        );
        println!("joint dissipated energy {:.6e} N·mm", c.dissipated[i]);
    }
    let pct = |v: Option<f64>| v.map_or("–".to_string(), |v| format!("{:.3} %", 100.0 * v));
    match &o.estimate {
        Some(Ok(e)) => {
            let line = |what: &str, c: &jointrom::reduction::CurveErrors| {
                println!(
                    "{what}: |f_c| {}, |f_R| {}, uy {}, D {} (end {})",
                    pct(c.contact_force),
                    pct(c.friction_force),
                    pct(c.master_uy),
                    pct(c.dissipated),
                    pct(c.dissipated_end)
                )
            };
            line("error estimate (relative L2 vs full)", &e.total);
            line(
                "  reduction (vs quasi-static joint correction)",
                &e.reduction,
            );
            if let Some(t) = &e.truncation {
                line("  truncation (vs the next fixed-interface modes)", t);
            }
            if let Some(i) = &e.integration {
                line("  integration (vs a re-run at other tolerances, scaled)", i);
            }
            if let Some(c) = &e.combined {
                line(
                    "  truncation + integration (vs one re-run richer and tighter, scaled)",
                    c,
                );
            }
        }
        Some(Err(why)) => println!("error estimate unavailable: {why}"),
        None => {}
    }
}

/// `--reference`: the relative L2 errors against the stored curves.
fn print_reference_errors(e: &ReferenceErrors) {
    let pct = |v: Option<f64>| v.map_or("–".to_string(), |v| format!("{:.3} %", 100.0 * v));
    println!(
        "against the reference ({} outputs to {:.4e} s, relative L2): |f_c| {}, |f_R| {}, uy {}, \
         D {} (end {})",
        e.compared_outputs,
        e.compared_until,
        pct(e.contact_force),
        pct(e.friction_force),
        pct(e.master_uy),
        pct(e.dissipated),
        pct(e.dissipated_end)
    );
}

/// The warnings of a tolerance model that misses (`worst_estimate` its largest estimate): the
/// best model, the richer round that stopped, the tightening that did not converge.
fn warn_tolerance(o: &ModelRun, worst_estimate: f64) {
    if let Some(t) = o.tolerance.as_ref().filter(|t| !t.met) {
        eprintln!(
            "warning: --tolerance {:e} not met: the best model ({} pairs, r = {}) estimates {:e} \
             (the largest of {})",
            t.tolerance,
            t.pairs.len(),
            o.basis_size,
            worst_estimate,
            t.quantities
                .iter()
                .map(|q| q.name())
                .collect::<Vec<_>>()
                .join(", ")
        );
        if let Some(s) = &t.stopped {
            eprintln!(
                "warning: the richer model after it ({} pairs, r = {}, rtol {:e}, atol {:e}) \
                 stopped: {}",
                s.pairs, s.basis_size, s.rtol, s.atol, s.reason
            );
        }
    }
    if let Some(s) = o.tolerance.as_ref().and_then(|t| t.integration_stall) {
        eprintln!(
            "warning: the curves do not converge as the integration tightens: integration part \
             {:.2e} at rtol {:.2e}, atol {:.2e} mm, {:.2e} at rtol {:.2e}, atol {:.2e} mm{}",
            s.part[0],
            s.rtol[0],
            s.atol[0],
            s.part[1],
            s.rtol[1],
            s.atol[1],
            if s.ended {
                " — above the tolerance by itself: no model meets it"
            } else {
                "; no tighter run was made"
            }
        );
    }
}
