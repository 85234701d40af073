//! One transient run of the model a [`ModelSpec`] names, from rest: the full FE model, a reduced
//! basis, the POD of a training run, the tolerance-chosen model or a reduced-model file. Every
//! reduced run built here carries its error estimate ([`super::estimate`]); the states can be
//! kept (expanded to physical DOF, `u = Φ q`) for VTU frames.

use std::path::Path;
use std::time::Instant;

use crate::error::{Error, RomError};
use crate::integrate::{self as driver, integrate, Run, TransientOptions};
use crate::model::Model;
use crate::reduction::{build_basis, BasisOptions, JointFlexibility, Quantities};
use crate::rom::estimate::{run_estimated, RunEstimate};
use crate::rom::file::RomFile;
use crate::rom::spec::ModelSpec;
use crate::rom::tolerance::{
    tolerance_model, CompressJoint, IntegrationTolerances, ToleranceChoice, ToleranceModel,
    ToleranceOptions,
};
use crate::rom::training::{train_snapshot_basis, Training};
use crate::system::{FullSystem, ReducedSystem, Scene, SecondOrderSystem};

/// Kept states: (time in s, displacement in physical DOF).
pub type Frames = Vec<(f64, Vec<f64>)>;

/// What a run needs beside the model and its spec.
#[derive(Clone, Debug, Default)]
pub struct RunSettings {
    /// Keep every k-th output state (expanded to physical DOF) as a frame.
    pub keep_every: Option<usize>,
    /// The full model's capacity for low-rank updates of its Newton factor (columns).
    pub low_rank: Option<usize>,
    /// Where the tolerance model's rtol and atol come from (the user's `--rtol/--atol` win).
    pub integration: IntegrationTolerances,
    /// When the tolerance model compresses its joint columns
    /// ([`ToleranceOptions::compress`]; default [`CompressJoint::Auto`]).
    pub compress_joint: CompressJoint,
}

/// A finished run of a spec's model.
pub struct ModelRun {
    /// The run.
    pub run: Run,
    /// The model's size: the DOF of the full model, the basis size r of a reduced one.
    pub basis_size: usize,
    /// Added vectors g (pairs for the tolerance model); `None` for the full model.
    pub g: Option<usize>,
    /// The POD training run ([`ModelSpec::Pod`]).
    pub training: Option<Training>,
    /// The kept states ([`RunSettings::keep_every`]), in physical DOF.
    pub frames: Frames,
    /// Wall time of building the reduced model (basis, enrichment, earlier rounds), s.
    pub offline_s: Option<f64>,
    /// The tolerance model's choice ([`ModelSpec::Tolerance`]).
    pub tolerance: Option<ToleranceChoice>,
    /// The error estimate of a reduced run (`None` for the full model), or why there is none.
    pub estimate: Option<Result<RunEstimate, String>>,
}

impl ModelRun {
    fn of(run: Run, basis_size: usize, g: Option<usize>) -> ModelRun {
        ModelRun {
            run,
            basis_size,
            g,
            training: None,
            frames: Vec::new(),
            offline_s: None,
            tolerance: None,
            estimate: None,
        }
    }
}

/// Runs the model `spec` names on `model` with `opts`.
///
/// # Errors
/// Settings that do not apply to the spec (naming the flag), a failing build, a run that does
/// not finish.
pub fn run_model(
    model: &Model,
    spec: &ModelSpec,
    opts: &TransientOptions,
    settings: &RunSettings,
) -> Result<ModelRun, Error> {
    if settings.low_rank.is_some() && spec.is_reduced() {
        return Err(RomError::LowRankReduced.into());
    }
    let every = settings.keep_every;
    match spec {
        ModelSpec::Full => {
            let mut sys = FullSystem::new(model)?;
            if let Some(cap) = settings.low_rank {
                sys.set_low_rank_capacity(cap);
            }
            let (run, frames) = run_keeping(sys, &Scene::of(model), opts, every)?;
            let mut out = ModelRun::of(run, model.dofs(), None);
            out.frames = frames;
            Ok(out)
        }
        &ModelSpec::Basis { kind, g, nu } => {
            let t0 = Instant::now();
            let opts_b = BasisOptions {
                g,
                nu,
                ..Default::default()
            };
            let basis = build_basis(model, kind, &opts_b)?;
            let offline_s = t0.elapsed().as_secs_f64();
            let mut o = run_reduced(model, basis.phi, basis.g, opts, every)?;
            o.offline_s = Some(offline_s);
            Ok(o)
        }
        &ModelSpec::Pod {
            g,
            nu,
            train_end,
            snapshots,
        } => {
            let train_end = train_end.unwrap_or(opts.end_time.unwrap_or(model.end_time));
            let (basis, training) = train_snapshot_basis(
                model,
                opts,
                train_end,
                snapshots,
                &BasisOptions {
                    g,
                    nu,
                    ..Default::default()
                },
            )?;
            let mut o = run_reduced(model, basis.phi, basis.g, opts, every)?;
            o.training = Some(training);
            Ok(o)
        }
        ModelSpec::File(path) => run_file(model, path, opts, every),
        &ModelSpec::Tolerance { tolerance, nu, on } => {
            run_tolerance(model, tolerance, nu, on, opts, settings)
        }
    }
}

/// The tolerance-chosen model and its run (the last round's).
fn run_tolerance(
    model: &Model,
    tolerance: f64,
    nu: usize,
    on: Option<Quantities>,
    opts: &TransientOptions,
    settings: &RunSettings,
) -> Result<ModelRun, Error> {
    let every = settings.keep_every;
    let mut topts = ToleranceOptions::new(tolerance);
    topts.nu = nu;
    topts.quantities = on;
    topts.transient = opts.clone();
    topts.integration = settings.integration;
    topts.compress = settings.compress_joint;
    let ToleranceModel {
        pairs,
        tangential,
        quantities,
        nu,
        setup_s,
        rom,
        run,
        estimate,
        met,
        rounds,
        offline_s,
        estimate_s,
        transient,
        cpu_s,
        compression,
        force_atol,
        sliding_friction_atol,
        friction_atol,
        stopped,
        integration_stall,
        discarded,
    } = tolerance_model(model, &topts)?;
    let frames = match (every, &rom.phi) {
        (Some(every), Some(phi)) => {
            // The result's states again, expanded: one more run of the (small) chosen model.
            let (_, kept) = run_keeping(rom.clone(), &Scene::of(model), &transient, Some(every))?;
            expand_frames(phi, kept)
        }
        _ => Vec::new(),
    };
    Ok(ModelRun {
        basis_size: rom.dim(),
        g: Some(pairs.len()),
        run,
        training: None,
        frames,
        offline_s: Some(offline_s),
        estimate: Some(Ok(estimate)),
        tolerance: Some(ToleranceChoice {
            tolerance,
            met,
            pairs,
            tangential_pairs: tangential,
            quantities,
            nu,
            setup_s,
            estimate_s,
            cpu_s,
            rounds,
            rtol: transient.ode.rtol,
            atol: transient.ode.atol,
            force_atol,
            sliding_friction_atol,
            friction_atol,
            compression,
            stopped,
            integration_stall,
            discarded_rounds: discarded,
        }),
    })
}

/// A reduced model exported by `jointrom export` from `model` (checked: a run is labelled with
/// its model's name), with the file's slip relaxation time τ: it carries no basis Φ, so neither
/// frames nor an error estimate.
fn run_file(
    model: &Model,
    path: &Path,
    opts: &TransientOptions,
    every: Option<usize>,
) -> Result<ModelRun, Error> {
    if every.is_some() {
        return Err(RomError::VtuFromFile.into());
    }
    let f = RomFile::read(path)?;
    f.check_source(model, path)?;
    let opts = TransientOptions {
        problem: crate::integrate::ProblemOptions {
            tau: f.friction_relaxation_time,
            ..opts.problem
        },
        ..opts.clone()
    };
    let mut out = ModelRun::of(
        driver::run(f.system()?, &f.scene(), &opts)?,
        f.dimension,
        Some(f.basis.g),
    );
    out.estimate = Some(Err(
        "an exported reduced model carries no basis Φ to correct its joint forces with".into(),
    ));
    Ok(out)
}

/// The run of the reduced model on the basis `phi` (g added vectors), with its estimate.
fn run_reduced(
    model: &Model,
    phi: faer::Mat<f64>,
    g: usize,
    opts: &TransientOptions,
    every: Option<usize>,
) -> Result<ModelRun, Error> {
    run_rom(model, ReducedSystem::new(model, phi)?, g, opts, every)
}

/// The run of a reduced model `rom` of `model` (built with its basis Φ, g added vectors; e.g.
/// [`super::build_rom`]'s), with its error estimate: what [`run_model`] does after building a
/// basis, for callers that keep a built reduced model and run it more than once.
///
/// # Errors
/// A reduced model without its basis or not of `model`, a run that does not finish.
pub fn run_rom(
    model: &Model,
    rom: ReducedSystem,
    g: usize,
    opts: &TransientOptions,
    every: Option<usize>,
) -> Result<ModelRun, Error> {
    let basis_size = rom.dim();
    let phi = rom.phi.clone();
    let flex = JointFlexibility::new(model)?;
    let mut kept = Vec::new();
    let mut k = 0usize;
    let (run, estimate) =
        run_estimated(model, &flex, rom, &Scene::of(model), opts, true, |t, q| {
            if every.is_some_and(|every| k % every == 0) {
                kept.push((t, q.to_vec()));
            }
            k += 1;
        })?;
    let mut out = ModelRun::of(run.into_result()?, basis_size, Some(g));
    out.estimate = Some(estimate.map_err(|e| e.to_string()));
    out.frames = match phi {
        Some(phi) if !kept.is_empty() => expand_frames(&phi, kept),
        _ => kept,
    };
    Ok(out)
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
