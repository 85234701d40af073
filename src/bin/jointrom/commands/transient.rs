//! `jointrom transient`: a transient run from rest (CVODE) of the full FE model or a reduced
//! one; curves, solver statistics, wall time, optionally files and VTU frames.

use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::Args;
use serde_json::{json, Value};

use jointrom::integrate::problem::{Iteration, NewtonLinear};
use jointrom::integrate::{self as driver, integrate, Curves, Run, TransientOptions};
use jointrom::reduction::rom_file as export;
use jointrom::reduction::{build_basis, BasisKind, BasisOptions, JointFlexibility};
use jointrom::studies::reference::{ReferenceCurves, ReferenceErrors};
use jointrom::studies::tolerance::{run_estimated, tolerance_model, RunEstimate, ToleranceOptions};
use jointrom::studies::training::train_snapshot_basis;
use jointrom::system::{FullSystem, ReducedSystem, Scene, SecondOrderSystem};
use jointrom::{Error, Model};

use crate::cli::{IterationArg, OnOff};
use crate::common::{create_dir, positive, print_json, write_file};

#[derive(Args)]
pub struct TransientArgs {
    /// Case file, matrix map (`jointrom-matrices` JSON) or built-in name.
    case: String,
    /// full (FE model) or a reduced basis: tvd, tvd-plain, modes, jim, alldof, pod (POD of
    /// the displacement snapshots of a full-FE training run, paper Section 5.2), or
    /// file:PATH (a reduced model written by `jointrom export`; CASE is still loaded), or
    /// adaptive (Craig–Bampton plus the attachment modes of the pairs the error estimate
    /// selects, see --tolerance). Default: tvd, or adaptive with --tolerance.
    #[arg(long)]
    model: Option<String>,
    /// Enrichment vectors of the basis; default: the smallest g with w(g) >= 0.999.
    #[arg(long)]
    g: Option<usize>,
    /// Build the smallest reduced model whose estimated relative L2 error of |f_c|(t) is at most
    /// TOL (in (0, 1); e.g. 1e-2), with --model adaptive (the default with this flag).
    #[arg(long, allow_negative_numbers = true)]
    tolerance: Option<f64>,
    /// With --tolerance: exit non-zero (after printing the best model's run) when the estimate
    /// does not meet the tolerance. Without it a miss is a warning.
    #[arg(long, requires = "tolerance")]
    strict: bool,
    /// `--model pod`: end of the full-FE training run, s (default: the run's end time).
    #[arg(long)]
    train_end: Option<f64>,
    /// `--model pod`: about this many snapshots kept from the training run (every k-th output,
    /// k = outputs / N).
    #[arg(long, default_value_t = 200)]
    snapshots: usize,
    /// Fixed-interface modes ν of the basis.
    #[arg(long, default_value_t = 10)]
    nu: usize,
    /// Nonlinear iteration: newton (structured solve) or functional (fixed point).
    #[arg(long, value_enum, default_value_t = IterationArg::Newton)]
    iteration: IterationArg,
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
    /// over the shared output times, JSON `"reference_error"`.
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

/// What `--model` names: the full FE model, the POD of a full-FE training run, a reduced model
/// exported by `jointrom export`, or a basis kind.
enum ModelChoice {
    Full,
    Pod,
    File(PathBuf),
    Basis(BasisKind),
}

impl ModelChoice {
    fn parse(name: &str) -> Result<ModelChoice, Error> {
        Ok(match name {
            "full" => ModelChoice::Full,
            "adaptive" => {
                return Err(Error::Invalid(
                    "--model adaptive is chosen by --tolerance TOL: give the tolerance".into(),
                ))
            }
            "pod" => ModelChoice::Pod,
            _ if name.starts_with("file:") => {
                ModelChoice::File(PathBuf::from(&name["file:".len()..]))
            }
            _ => ModelChoice::Basis(
                BasisKind::from_name(name)
                    .map_err(|e| Error::Invalid(format!("--model: {e} (or full, pod)")))?,
            ),
        })
    }
}

/// Kept states: (time in s, state).
type Frames = Vec<(f64, Vec<f64>)>;

/// A finished run: the result, its size, g, the POD training run (`--model pod`) and the kept
/// states in physical DOF (reduced states are expanded with Φ).
struct Outcome {
    res: Run,
    basis_size: usize,
    g: Option<usize>,
    training: Option<Value>,
    frames: Frames,
    /// Wall time of building the reduced model (basis, enrichment, earlier rounds), s.
    offline_s: Option<f64>,
    /// `--tolerance`: the tolerance, whether it was met, the rounds and the chosen pairs.
    tolerance: Option<Value>,
    /// The a-posteriori error estimate of a reduced run (`None` for the full model), or why
    /// there is none.
    estimate: Option<Result<RunEstimate, String>>,
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
    let t0 = Instant::now();
    let mut o = run_model(&a, &model, &opts, vtu_every)?;
    let total_s = t0.elapsed().as_secs_f64();
    let c = &o.res.curves;
    let reference_error = reference.as_ref().map(|r| {
        let e = r.errors(c);
        json!({
            "path": a.reference.as_ref().map(|p| p.display().to_string()),
            "contact_force": e.contact_force,
            "friction_force": e.friction_force,
            "master_uy": e.master_uy,
            "compared_outputs": e.compared_outputs,
            "compared_until": e.compared_until,
        })
    });
    let doc = json!({
        "case": model.name,
        "model": model_name(&a),
        "basis": model_name(&a),
        "basis_size": o.basis_size,
        "g": o.g,
        "offline_s": o.offline_s,
        "tolerance": o.tolerance,
        "options": opts,
        "stats": o.res.stats,
        "events": o.res.events,
        "wall_s": o.res.wall_s,
        "cpu_s": o.res.cpu_s,
        "total_s": total_s,
        "error_estimate": estimate_json(&o.estimate),
        "reference_error": reference_error,
        "curves": c,
        "energy_balance": c.balance(),
        "energy_check": c.energy_check(opts.energy_resolution()),
        "training": o.training,
        "profile": o.res.profile,
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
        print_summary(&a, &model, &o, total_s);
        if let Some(r) = &reference {
            print_reference_errors(&r.errors(c));
        }
    }
    let met = o
        .tolerance
        .as_ref()
        .and_then(|t| t["met"].as_bool())
        .unwrap_or(true);
    if a.strict && !met {
        return Err(Error::Invalid(format!(
            "--strict: the estimated |f_c| error {:e} of the best model exceeds --tolerance {:e} \
             (the result above is that model's)",
            o.estimate
                .as_ref()
                .and_then(|e| e.as_ref().ok())
                .and_then(|e| e.total.contact_force)
                .unwrap_or(f64::NAN),
            a.tolerance.unwrap_or(f64::NAN)
        )));
    }
    Ok(())
}

/// The options of a `transient` run from its flags (errors name the flag).
fn transient_options(a: &TransientArgs) -> Result<TransientOptions, Error> {
    let mut o = TransientOptions::default();
    o.ode.iteration = match a.iteration {
        IterationArg::Newton => Iteration::Newton {
            linear: NewtonLinear::Problem,
        },
        IterationArg::Functional => Iteration::Functional { anderson: 0 },
    };
    o.problem.friction = a.friction.is_on();
    o.problem.events = a.events.is_on();
    if let Some(r) = a.rtol {
        o.ode.rtol = positive("rtol", r)?;
    }
    if let Some(r) = a.atol {
        o.ode.atol = positive("atol", r)?;
    }
    if let Some(v) = a.velocity_scale {
        o.problem.velocity_scale = positive("velocity-scale", v)?;
    }
    if let Some(k) = a.max_order {
        if !(1..=5).contains(&k) {
            return Err(Error::Invalid(format!(
                "--max-order must be 1..=5 (BDF), got {k}"
            )));
        }
        o.ode.max_order = k;
    }
    if let Some(s) = a.stab_lim_det {
        o.ode.stab_lim_det = s.is_on();
    }
    o.profile = a.profile;
    if let Some(r) = &a.refresh {
        o.problem.refresh = if r == "off" {
            None
        } else {
            match r.parse::<f64>() {
                Ok(m) if m.is_finite() && m >= 0.0 => Some(m),
                _ => {
                    return Err(Error::Invalid(format!(
                        "--refresh must be `off` or a margin in mm (finite, >= 0), got `{r}`"
                    )))
                }
            }
        };
    }
    if let Some(g) = a.step_growth {
        if !(g.is_finite() && g >= 1.0) {
            return Err(Error::Invalid(format!(
                "--step-growth must be finite and >= 1, got {g}"
            )));
        }
        o.ode.step_growth = g;
    }
    if let Some(t) = a.end_time {
        o.end_time = Some(positive("end-time", t)?);
    }
    o.output_step = positive("output-step", a.output_step)?;
    if let Some(t) = o.end_time {
        jointrom::integrate::driver::output_count(t, o.output_step)?;
    }
    o.budget_s = Some(positive("max-wall", a.max_wall)?);
    Ok(o)
}

/// `--vtu`: every how many outputs a frame is kept (`None` without `--vtu`).
fn vtu_every(
    a: &TransientArgs,
    opts: &TransientOptions,
    model: &Model,
) -> Result<Option<usize>, Error> {
    match &a.vtu {
        None => Ok(None),
        Some(_) if a.vtu_frames == 0 => {
            Err(Error::Invalid("--vtu-frames must be at least 1".into()))
        }
        Some(_) => {
            let end = opts.end_time.unwrap_or(model.end_time);
            let outputs = (end / opts.output_step).ceil().max(1.0) as usize + 1;
            Ok(Some((outputs / a.vtu_frames).max(1)))
        }
    }
}

/// The model `--model` names, or its default: `adaptive` with `--tolerance`, else `tvd`.
fn model_name(a: &TransientArgs) -> String {
    match (&a.model, a.tolerance) {
        (Some(m), _) => m.clone(),
        (None, Some(_)) => "adaptive".into(),
        (None, None) => "tvd".into(),
    }
}

/// `--tolerance TOL`: the tolerance-chosen model (`--model adaptive`) and its run.
fn run_tolerance(
    a: &TransientArgs,
    name: &str,
    tol: f64,
    model: &Model,
    opts: &TransientOptions,
    vtu_every: Option<usize>,
) -> Result<Outcome, Error> {
    if name != "adaptive" {
        return Err(Error::Invalid(format!(
            "--tolerance builds its own model (--model adaptive); it does not apply to --model {name} \
             (use --g to size that one)"
        )));
    }
    if a.g.is_some() {
        return Err(Error::Invalid(
            "--tolerance and --g both size the model: give one of them".into(),
        ));
    }
    if a.train_end.is_some() {
        return Err(train_end_error());
    }
    let mut topts = ToleranceOptions::new(tol);
    topts.nu = a.nu;
    topts.transient = opts.clone();
    let t = tolerance_model(model, &topts)?;
    let frames = match (vtu_every, &t.rom.phi) {
        (Some(every), Some(phi)) => {
            // The result's states again, expanded: one more run of the (small) chosen model.
            let (_, kept) = run_keeping(t.rom.clone(), &Scene::of(model), opts, Some(every))?;
            expand_frames(phi, kept)
        }
        _ => Vec::new(),
    };
    let info = json!({
        "tolerance": tol,
        "met": t.met,
        "pairs": t.pairs,
        "nu": t.nu,
        "setup_s": t.setup_s,
        "estimate_s": t.estimate_s,
        "rounds": t.rounds,
    });
    if !t.met {
        eprintln!(
            "warning: --tolerance {tol:e} not met: the best model ({} pairs, r = {}) estimates {:e}",
            t.pairs.len(),
            t.rom.dim(),
            t.estimate.total.contact_force.unwrap_or(f64::NAN)
        );
    }
    Ok(Outcome {
        basis_size: t.rom.dim(),
        g: Some(t.pairs.len()),
        res: t.run,
        training: None,
        frames,
        offline_s: Some(t.offline_s),
        tolerance: Some(info),
        estimate: Some(Ok(t.estimate)),
    })
}

fn train_end_error() -> Error {
    Error::Invalid("--train-end applies to --model pod only".into())
}

/// Runs the model `--model` names.
fn run_model(
    a: &TransientArgs,
    model: &Model,
    opts: &TransientOptions,
    vtu_every: Option<usize>,
) -> Result<Outcome, Error> {
    let name = model_name(a);
    if a.low_rank.is_some() && name != "full" {
        return Err(Error::Invalid(
            "--low-rank applies to --model full (the reduced model refactors its dense matrix)"
                .into(),
        ));
    }
    if let Some(tol) = a.tolerance {
        return run_tolerance(a, &name, tol, model, opts, vtu_every);
    }
    let choice = match ModelChoice::parse(&name) {
        Err(_) | Ok(ModelChoice::Basis(_)) if a.train_end.is_some() => {
            return Err(train_end_error())
        }
        c => c?,
    };
    match choice {
        ModelChoice::Full => {
            if a.g.is_some() {
                return Err(Error::Invalid(
                    "--g applies to reduced models, not --model full".into(),
                ));
            }
            if a.train_end.is_some() {
                return Err(train_end_error());
            }
            let mut sys = FullSystem::new(model)?;
            if let Some(cap) = a.low_rank {
                sys.set_low_rank_capacity(cap);
            }
            let (res, frames) = run_keeping(sys, &Scene::of(model), opts, vtu_every)?;
            Ok(Outcome {
                res,
                basis_size: model.dofs(),
                g: None,
                training: None,
                frames,
                offline_s: None,
                tolerance: None,
                estimate: None,
            })
        }
        ModelChoice::Pod => run_pod(a, model, opts, vtu_every),
        ModelChoice::File(path) => run_file(a, &path, opts),
        ModelChoice::Basis(kind) => {
            let t0 = Instant::now();
            let basis = build_basis(
                model,
                kind,
                &BasisOptions {
                    g: a.g,
                    nu: a.nu,
                    ..Default::default()
                },
            )?;
            let offline_s = t0.elapsed().as_secs_f64();
            let mut o = run_reduced(model, basis.phi, basis.g, None, opts, vtu_every)?;
            o.offline_s = Some(offline_s);
            Ok(o)
        }
    }
}

/// Paper Section 5.2: the POD of displacement snapshots of a full-FE run (here over
/// [0, train_end] with the same options), Euclidean, added to Craig–Bampton.
fn run_pod(
    a: &TransientArgs,
    model: &Model,
    opts: &TransientOptions,
    vtu_every: Option<usize>,
) -> Result<Outcome, Error> {
    let train_end = match a.train_end {
        Some(t) => positive("train-end", t)?,
        None => opts.end_time.unwrap_or(model.end_time),
    };
    let (basis, training) = train_snapshot_basis(
        model,
        opts,
        train_end,
        a.snapshots,
        &BasisOptions {
            g: a.g,
            nu: a.nu,
            ..Default::default()
        },
    )?;
    let training = serde_json::to_value(&training).expect("the training record serialises");
    run_reduced(model, basis.phi, basis.g, Some(training), opts, vtu_every)
}

/// A reduced model exported by `jointrom export` (schema jointrom-rom v1).
fn run_file(a: &TransientArgs, path: &Path, opts: &TransientOptions) -> Result<Outcome, Error> {
    if a.g.is_some() || a.train_end.is_some() {
        return Err(Error::Invalid(
            "--g and --train-end do not apply to --model file:PATH".into(),
        ));
    }
    if a.vtu.is_some() {
        return Err(Error::Invalid(
            "--vtu needs the basis Φ, which an exported reduced model does not carry; \
             run the basis by name instead (e.g. --model tvd)"
                .into(),
        ));
    }
    let f = export::RomFile::read(path)?;
    crate::common::record_input(format!("reduced model {}", path.display()));
    Ok(Outcome {
        res: driver::run(f.system()?, &f.scene(), opts)?,
        basis_size: f.dimension,
        g: Some(f.basis.g),
        training: None,
        frames: Vec::new(),
        offline_s: None,
        tolerance: None,
        estimate: Some(Err(
            "an exported reduced model carries no basis Φ to correct its joint forces with".into(),
        )),
    })
}

/// The run of the reduced model on the basis `phi` (g added vectors).
fn run_reduced(
    model: &Model,
    phi: faer::Mat<f64>,
    g: usize,
    training: Option<Value>,
    opts: &TransientOptions,
    vtu_every: Option<usize>,
) -> Result<Outcome, Error> {
    let rom = ReducedSystem::new(model, phi)?;
    let basis_size = rom.dim();
    let phi = rom.phi.clone();
    let flex = JointFlexibility::new(model)?;
    let mut kept = Vec::new();
    let mut k = 0usize;
    let (res, estimate) =
        run_estimated(model, &flex, rom, &Scene::of(model), opts, true, |t, q| {
            if vtu_every.is_some_and(|every| k % every == 0) {
                kept.push((t, q.to_vec()));
            }
            k += 1;
        })?;
    let res = res.into_result()?;
    Ok(Outcome {
        res,
        basis_size,
        g: Some(g),
        training,
        offline_s: None,
        tolerance: None,
        estimate: Some(estimate.map_err(|e| e.to_string())),
        frames: match phi {
            Some(phi) if !kept.is_empty() => expand_frames(&phi, kept),
            _ => kept,
        },
    })
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

/// A transient run that keeps every `every`-th state (with its time) when `every` is given.
fn run_keeping<S: SecondOrderSystem>(
    sys: S,
    scene: &Scene,
    opts: &TransientOptions,
    every: Option<usize>,
) -> Result<(Run, Frames), Error> {
    let Some(every) = every else {
        return Ok((driver::run(sys, scene, opts)?, Vec::new()));
    };
    let mut frames = Vec::new();
    let mut k = 0usize;
    let res = integrate(sys, scene, opts, |t, q| {
        if k % every == 0 {
            frames.push((t, q.to_vec()));
        }
        k += 1;
    })
    .into_result()?;
    Ok((res, frames))
}

/// Reduced states `q` (r) to physical DOF `Φ q` (n): one product `Φ [q_1 … q_f]`.
fn expand_frames(phi: &faer::Mat<f64>, kept: Frames) -> Frames {
    let q = faer::Mat::from_fn(phi.ncols(), kept.len(), |i, j| kept[j].1[i]);
    let u = phi * &q;
    kept.iter()
        .enumerate()
        .map(|(j, &(t, _))| (t, u.col(j).iter().copied().collect()))
        .collect()
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
fn print_summary(a: &TransientArgs, model: &Model, o: &Outcome, total_s: f64) {
    let (res, c) = (&o.res, &o.res.curves);
    let s = &res.stats;
    println!(
        "{} — model {} (n = {}{}), friction {}, events {}",
        jointrom::files::printable(&model.name),
        model_name(a),
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
    }
    let pct = |v: Option<f64>| v.map_or("–".to_string(), |v| format!("{:.3} %", 100.0 * v));
    match &o.estimate {
        Some(Ok(e)) => {
            let line = |what: &str, c: &jointrom::reduction::CurveErrors| {
                println!(
                    "{what}: |f_c| {}, |f_R| {}, uy {}",
                    pct(c.contact_force),
                    pct(c.friction_force),
                    pct(c.master_uy)
                )
            };
            line("error estimate (relative L2 vs full)", &e.total);
            line(
                "  reduction (vs quasi-static joint correction)",
                &e.reduction,
            );
            if let Some(i) = &e.integration {
                line("  integration (vs 2x looser tolerances, scaled)", i);
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
        "against the reference ({} outputs to {:.4e} s, relative L2): |f_c| {}, |f_R| {}, uy {}",
        e.compared_outputs,
        e.compared_until,
        pct(e.contact_force),
        pct(e.friction_force),
        pct(e.master_uy)
    );
}
