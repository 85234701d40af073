//! `jointrom run`: the main job on a case → DIR/CASE/report.md, charts, results.json.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use serde_json::json;

use jointrom::report::main_job as report;
use jointrom::rom::tolerance::check_tolerance;
use jointrom::studies::main_job::{Progress, Report, ReportOptions};
use jointrom::{Error, Interface};

use crate::common::print_json;
use crate::summary::{info_json, static_json};

#[derive(Args)]
pub struct RunArgs {
    /// Case file, matrix map (`jointrom-matrices` JSON) or built-in name.
    #[arg(default_value = "friction_bar")]
    case: String,
    /// Output folder (the report is written to DIR/CASE).
    #[arg(long, default_value = "out")]
    out: PathBuf,
    /// Short variant: 0.02 s window, study g ≤ 20 (well under 20 s).
    #[arg(long)]
    quick: bool,
    /// Folder of stored stability maps copied into the report.
    #[arg(long, default_value = "results/stability")]
    stability_dir: PathBuf,
    /// One JSON document on stdout (results.json).
    #[arg(long)]
    json: bool,
    /// Tolerance of the headline reduced model: the relative L2 error of |f_c|(t) it is built
    /// for (in (0, 1)); see `transient --tolerance`.
    #[arg(long, default_value_t = 1e-2, allow_negative_numbers = true)]
    tolerance: f64,
}

pub fn run(a: RunArgs) -> Result<(), Error> {
    check_tolerance(a.tolerance)?;
    let t0 = Instant::now();
    let model = crate::common::load_model(&a.case)?;
    let t_assembly = t0.elapsed().as_secs_f64();
    let t1 = Instant::now();
    let fixed = model.modes(10, Interface::Fixed)?;
    let free = model.modes(10, Interface::Free)?;
    let t_modes = t1.elapsed().as_secs_f64();
    let statics = static_json(&model, 1.0)?;
    let mut extra = serde_json::Map::new();
    extra.insert("info".into(), info_json(&model));
    extra.insert(
        "fixed_interface_frequencies_hz".into(),
        json!(fixed.frequencies_hz),
    );
    extra.insert(
        "free_interface_frequencies_hz".into(),
        json!(free.frequencies_hz),
    );
    extra.insert("linear_static".into(), statics);
    extra.insert(
        "timing_s".into(),
        json!({"assembly": t_assembly, "modes": t_modes}),
    );
    let dir = a.out.join(jointrom::files::safe_name(&model.name));
    let opts = ReportOptions {
        quick: a.quick,
        stability_dir: a.stability_dir,
        headline_tolerance: a.tolerance,
        ..Default::default()
    };
    let bar = progress_bar(opts.progress);
    let rep = report::run_report_observed(&model, &dir, &opts, extra, &mut |p: &Progress| {
        show_progress(&bar, p)
    })?;
    if a.json {
        print_json(&serde_json::to_value(&rep).expect("the report serialises"));
    } else {
        print_report(&rep, &dir);
    }
    Ok(())
}

/// The job's progress bar on stderr: drawn on a terminal only, hidden otherwise.
fn progress_bar(wanted: bool) -> ProgressBar {
    if !(wanted && std::io::stderr().is_terminal()) {
        return ProgressBar::hidden();
    }
    let b = ProgressBar::new(1);
    b.set_style(
        ProgressStyle::with_template("{elapsed_precise} [{bar:30}] {pos}/{len} {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> "),
    );
    b
}

fn show_progress(bar: &ProgressBar, p: &Progress) {
    if p.finished {
        bar.finish_and_clear();
        return;
    }
    bar.set_message(p.stage.clone());
    bar.set_length(p.total);
    bar.set_position(p.position);
}

fn print_report(rep: &Report, dir: &Path) {
    println!(
        "{} — {} DOF, {} joint pairs; a-priori g = {} (w ≥ {}); window {} s; job {:.1} s",
        rep.case, rep.dofs, rep.pairs, rep.g_chosen, rep.threshold, rep.end_time, rep.total_s
    );
    println!(
        "  {:<16} {:>4} {:>5} {:<10} {:<10} {:>10} {:>10} {:>10} {:>9} {:>9}",
        "model",
        "g",
        "size",
        "iteration",
        "status",
        "err |f_c|",
        "est |f_c|",
        "err uy",
        "CPU s",
        "speed-up"
    );
    for (i, r) in rep.runs.iter().enumerate() {
        let e = |v: Option<f64>| v.map_or("-".to_string(), |x| format!("{x:.2e}"));
        let name = match r.tolerance {
            Some((tol, _)) => format!("adaptive {tol:.0e}"),
            None => r.model.clone(),
        };
        println!(
            "{} {:<16} {:>4} {:>5} {:<10} {:<10} {:>10} {:>10} {:>10} {:>9.3} {:>9}",
            if rep.headline == Some(i) { "*" } else { " " },
            name,
            r.g.map_or("-".to_string(), |g| g.to_string()),
            r.size,
            r.iteration,
            r.status,
            e(r.error_fc),
            e(r.estimate.as_ref().and_then(|x| x.total.contact_force)),
            e(r.error_uy),
            r.cpu_s,
            r.speedup.map_or("-".to_string(), |x| format!("{x:.0}x"))
        );
    }
    println!(
        "* headline reduced model (tolerance {:.0e} on |f_c|, |f_R|, u_y and D)",
        rep.headline_tolerance
    );
    println!("report: {}", dir.join("report.md").display());
}
