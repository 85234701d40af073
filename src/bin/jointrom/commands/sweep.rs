//! `jointrom sweep`: variants of one reduced model, in parallel, sharing the basis.

use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use serde_json::json;

use crate::common::{positive, print_json};
use jointrom::error::StudyError;
use jointrom::integrate::TransientOptions;
use jointrom::rom::{build_rom, ModelFlags};
use jointrom::studies::sweep::{self, SweepResult};
use jointrom::Error;

#[derive(Args)]
pub struct SweepArgs {
    /// Case file, matrix map (`jointrom-matrices` JSON) or built-in name.
    case: String,
    /// The variant file (`{"variants": [{"name", "load_scale", "friction_coefficient",
    /// "normal_stiffness", "stick_stiffness"}, ...]}`).
    #[arg(long)]
    variants: PathBuf,
    /// The shared reduced model (default: tvd); --tolerance TOL shares the tolerance-chosen
    /// model (see `transient --tolerance`), chosen on the case itself: each variant's own error
    /// estimate says whether it suits the variant.
    #[command(flatten)]
    model: ModelFlags,
    /// End time, s (default: the case's).
    #[arg(long)]
    end_time: Option<f64>,
    /// Run the variants one after the other.
    #[arg(long)]
    sequential: bool,
    /// One JSON document on stdout (with the curves).
    #[arg(long)]
    json: bool,
    /// Wall-clock budget of each variant's integration, s.
    #[arg(long, default_value_t = jointrom::integrate::driver::DEFAULT_MAX_WALL_S)]
    max_wall: f64,
}

pub fn run(a: SweepArgs) -> Result<(), Error> {
    let model = crate::common::load_model(&a.case)?;
    let list = sweep::read_variants(&a.variants)?;
    let mut opts = TransientOptions::default();
    if let Some(t) = a.end_time {
        opts.end_time = Some(positive("end-time", t)?);
        jointrom::integrate::driver::output_count(t, opts.output_step)?;
    }
    opts.budget_s = Some(positive("max-wall", a.max_wall)?);
    let t0 = Instant::now();
    let spec = a.model.spec_or_tvd()?;
    let built = build_rom(&model, &spec, &opts, "sweep")?;
    let (kind, g_used, rom) = (built.info.kind, built.info.g, built.rom);
    let build_s = t0.elapsed().as_secs_f64();
    let res = sweep::run_sweep(&model, &rom, &list, &opts, !a.sequential)?;
    if a.json {
        print_json(&json!({
            "case": model.name,
            "basis": kind,
            "g": g_used,
            "basis_size": rom.dim(),
            "build_s": build_s,
            "offline_s": build_s,
            "sweep": res,
        }));
    } else {
        println!(
            "{} — {} basis, g = {g_used}, r = {} (built once, {:.3} s); {} variants on {} threads",
            jointrom::files::printable(&model.name),
            kind,
            rom.dim(),
            build_s,
            res.runs.len(),
            res.threads
        );
        print_runs(&res);
    }
    for r in &res.runs {
        let check = r.curves.energy_check(opts.energy_resolution());
        if r.status == "ok" && !check.ok {
            eprintln!(
                "jointrom: warning: variant `{}`: energy balance off by {:.3e} of its energy \
                 (tolerance {:e}): not trustworthy",
                jointrom::files::printable(&r.variant.name),
                check.residual_ratio,
                check.tolerance
            );
        }
    }
    // The table (or JSON) above shows every variant; a failed one fails the command.
    let failed: Vec<String> = res
        .runs
        .iter()
        .filter(|r| r.status != "ok")
        .map(|r| jointrom::files::printable(&r.variant.name).to_string())
        .collect();
    if !failed.is_empty() {
        return Err(StudyError::SweepFailed {
            failed,
            total: res.runs.len(),
        }
        .into());
    }
    Ok(())
}

/// One line per run (plus its status when it failed), then the wall times.
fn print_runs(res: &SweepResult) {
    for r in &res.runs {
        let last = |v: &[f64]| v.last().copied().unwrap_or(f64::NAN);
        let est = r
            .error_estimate
            .as_ref()
            .and_then(|e| e.total.contact_force)
            .map_or("-".to_string(), |e| format!("{e:.1e}"));
        println!(
            "  {:<20} {:<6} {:>8.3} s {:>8} steps  final |f_c| {:.4e} N  |f_R| {:.4e} N  uy {:.4e} mm  est. |f_c| error {est}",
            jointrom::files::printable(&r.variant.name),
            if r.status == "ok" { "ok" } else { "failed" },
            r.wall_s,
            r.stats.steps,
            last(&r.curves.contact_force_norm),
            last(&r.curves.friction_force_norm),
            last(&r.curves.master_uy)
        );
        if r.status != "ok" {
            println!("    {}", r.status);
        }
    }
    println!(
        "sweep wall {:.3} s, sum of runs {:.3} s",
        res.wall_s, res.sum_wall_s
    );
}
