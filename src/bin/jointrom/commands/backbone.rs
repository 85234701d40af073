//! `jointrom backbone`: the amplitude-dependent frequency and damping ratio of modes from free
//! decays of the reduced (or full FE) model about the preloaded equilibrium.

use std::path::PathBuf;

use clap::Args;
use serde_json::json;

use jointrom::integrate::RunChoices;
use jointrom::report::backbone as report;
use jointrom::rom::{ModelFlags, ModelSpec};
use jointrom::studies::backbone::{self, BackboneOptions};
use jointrom::Error;

use crate::args::OnOff;
use crate::common::{create_dir, print_json, write_file};

#[derive(Args)]
pub struct BackboneArgs {
    /// Case file, matrix map (`jointrom-matrices` JSON) or built-in name.
    case: String,
    /// The model (default: tvd, or adaptive with --tolerance; `--model full` for the FE check).
    /// With --tolerance the tolerance model is enriched for the backbone (the full model's
    /// equilibrium, linearised modes and every pair's attachment modes).
    #[command(flatten)]
    model: ModelFlags,
    /// Mode numbers of the model linearised about the preloaded equilibrium with its closed
    /// pairs stuck (1 = lowest), e.g. 1,2,3.
    #[arg(long, value_delimiter = ',', default_value = "1")]
    modes: Vec<usize>,
    /// Initial amplitudes, mm of the mode shape's largest nodal translation, e.g. 0.001,0.01,0.1.
    #[arg(
        long,
        value_delimiter = ',',
        allow_negative_numbers = true,
        conflicts_with = "range"
    )]
    amplitudes: Vec<f64>,
    /// N amplitudes spaced logarithmically from A_MIN to A_MAX (mm).
    #[arg(long, num_args = 3, value_names = ["A_MIN", "A_MAX", "N"], allow_negative_numbers = true)]
    range: Option<Vec<String>>,
    /// Preload: this factor times the case's static master load, held constant (0: none; the
    /// backbone of an unloaded joint is flat).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    preload: f64,
    /// Cycles of each ring-down.
    #[arg(long, default_value_t = 3)]
    cycles: usize,
    /// Friction on or off.
    #[arg(long, value_enum, default_value_t = OnOff::On)]
    friction: OnOff,
    /// Relative tolerance.
    #[arg(long)]
    rtol: Option<f64>,
    /// Absolute tolerance at 1 mm of amplitude, mm (a ring-down of amplitude A runs with
    /// atol · A / 1 mm; default 1e-7, a decade below the transient's: the damping ratio of a
    /// slipping joint needs it).
    #[arg(long)]
    atol: Option<f64>,
    /// Wall-clock budget of each ring-down, s.
    #[arg(long, default_value_t = jointrom::integrate::driver::DEFAULT_MAX_WALL_S)]
    max_wall: f64,
    /// One JSON document on stdout.
    #[arg(long)]
    json: bool,
    /// Write backbone.json, backbone.csv, backbone.md and the charts
    /// (backbone_frequency/_damping .svg/.png) into this folder.
    #[arg(long)]
    out: Option<PathBuf>,
}

/// The amplitudes of `--amplitudes` or `--range`.
fn amplitudes(a: &BackboneArgs) -> Result<Vec<f64>, Error> {
    match &a.range {
        Some(r) => {
            let bad = || jointrom::error::FlagError::Value {
                flag: "range",
                value: r.join(" "),
                need: "A_MIN A_MAX N: two amplitudes in mm and a count",
            };
            let lo: f64 = r[0].parse().map_err(|_| bad())?;
            let hi: f64 = r[1].parse().map_err(|_| bad())?;
            let n: usize = r[2].parse().map_err(|_| bad())?;
            backbone::log_range(lo, hi, n)
        }
        None => Ok(a.amplitudes.clone()),
    }
}

pub fn run(a: BackboneArgs) -> Result<(), Error> {
    let transient = RunChoices {
        iteration: jointrom::integrate::TransientOptions::default()
            .ode
            .iteration,
        friction: a.friction.is_on(),
        events: false,
        rtol: a.rtol,
        atol: Some(a.atol.unwrap_or(backbone::DEFAULT_ATOL)),
        max_order: None,
        end_time: None,
        output_step: 1e-4,
        max_wall: a.max_wall,
    }
    .options()?;
    let opts = BackboneOptions {
        modes: a.modes.clone(),
        amplitudes: amplitudes(&a)?,
        preload: a.preload,
        cycles: a.cycles,
        transient,
    };
    opts.check()?;
    let model = crate::common::load_model(&a.case)?;
    let spec = a.model.spec_or_tvd()?;
    if let ModelSpec::Pod { .. } | ModelSpec::File(_) = spec {
        return Err(jointrom::rom::spec::unsupported(
            "backbone",
            &spec,
            "the full model (--model full), a reduced basis or --tolerance TOL",
        ));
    }
    let b = backbone::compute(&model, &spec, &opts)?;
    for w in &b.warnings {
        eprintln!("warning: {}", jointrom::files::printable(w));
    }
    let doc = json!({"case": model.name, "backbone": b});
    if let Some(dir) = &a.out {
        create_dir(dir)?;
        write_file(
            &dir.join("backbone.json"),
            serde_json::to_string_pretty(&doc).unwrap_or_default(),
        )?;
        write_file(&dir.join("backbone.csv"), report::csv(&b))?;
        write_file(&dir.join("backbone.md"), report::markdown(&b))?;
        report::charts(&b, dir, "backbone")?;
    }
    if a.json {
        print_json(&doc);
    } else {
        println!("{}", jointrom::files::printable(&model.name));
        print!("{}", report::markdown(&b));
    }
    Ok(())
}
