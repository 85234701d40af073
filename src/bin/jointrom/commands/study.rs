//! `jointrom study`: static convergence study → OUT/CASE/study.json and charts.

use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use serde_json::json;

use jointrom::studies::convergence as study;
use jointrom::Error;

use crate::common::{create_dir, print_json, write_file};

#[derive(Args)]
pub struct StudyArgs {
    /// Case file, matrix map (`jointrom-matrices` JSON) or built-in name.
    case: String,
    /// Output folder.
    #[arg(long, default_value = "out")]
    out: PathBuf,
    /// Largest number of added vectors g.
    #[arg(long, default_value_t = 60)]
    max_g: usize,
    /// Fixed-interface modes ν.
    #[arg(long, default_value_t = 10)]
    nu: usize,
    /// Factor on the case's load.
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    scale: f64,
    /// Skip the charts (JSON only).
    #[arg(long)]
    no_charts: bool,
    /// Print study.json on stdout too.
    #[arg(long)]
    json: bool,
}

pub fn run(a: StudyArgs) -> Result<(), Error> {
    let model = crate::common::load_model(&a.case)?;
    let opts = study::StudyOptions {
        nu: a.nu,
        max_g: a.max_g,
        scale: a.scale,
        ..study::StudyOptions::default()
    };
    let s = study::run_study(&model, &opts)?;
    let dir = a.out.join(jointrom::files::safe_name(&model.name));
    create_dir(&dir)?;
    let t0 = Instant::now();
    let charts = if a.no_charts {
        Vec::new()
    } else {
        jointrom::report::convergence::write_charts(&s, &dir)?
    };
    let charts_s = t0.elapsed().as_secs_f64();
    let mut doc = serde_json::to_value(&s).expect("JSON values serialise");
    doc["command_line"] = json!(std::env::args().collect::<Vec<_>>());
    doc["charts"] = json!(charts
        .iter()
        .filter_map(|p| p.file_name().map(|f| f.to_string_lossy().into_owned()))
        .collect::<Vec<_>>());
    doc["charts_s"] = json!(charts_s);
    write_file(
        &dir.join("study.json"),
        serde_json::to_string_pretty(&doc).expect("JSON values serialise"),
    )?;
    if a.json {
        print_json(&doc);
    } else {
        print_study(&s);
        println!("charts {:.2} s; written to {}", charts_s, dir.display());
    }
    Ok(())
}

fn print_study(s: &study::Study) {
    println!(
        "{} — static convergence study: {} DOF, {} pairs, ν = {}, g = 0..={}, load × {}",
        s.case, s.dofs, s.pairs, s.nu, s.max_g, s.scale
    );
    println!(
        "full FE: ‖f_c‖ = {:.9} N, {} pairs in contact ({:.1} ms)",
        s.full.contact_force_norm,
        s.full.pairs_in_contact,
        s.full.solve_s * 1e3
    );
    let show = |o: Option<usize>| o.map_or("—".to_string(), |g| g.to_string());
    println!(
        "  {:<10} {:>5} {:>13} {:>13} {:>13} {:>13} {:>9} {:>9}",
        "basis", "avail", "err(g=0)", "err(g=max)", "1e-2 first/stays", "", "prep s", "sweep s"
    );
    for x in &s.series {
        let last = x.relative_error.last().copied().unwrap_or(f64::NAN);
        let w2 = &x.within[0];
        let w4 = &x.within[1];
        println!(
            "  {:<10} {:>5} {:>13.3e} {:>13.3e}   1e-2: {:>3}/{:<3}  1e-4: {:>3}/{:<3} {:>9.3} {:>9.3}",
            x.name,
            x.available,
            x.relative_error[0],
            last,
            show(w2.first),
            show(w2.stays),
            show(w4.first),
            show(w4.stays),
            x.prepare_s,
            x.sweep_s
        );
    }
    for e in &s.energy {
        println!(
            "  w(g) {:<10}: g(w >= {}) = {}, {} nonzero TVD, {} POD modes",
            e.name, s.threshold, e.g_threshold, e.tvd_nonzero, e.pod_modes
        );
    }
    for t in &s.tvd_spans {
        let what = if t.name == "alldof" {
            "alldof: CB + every pair's normal constraint mode".to_string()
        } else {
            format!("all {} TVD without POD", t.name)
        };
        println!(
            "  {what}: {} columns ({} dropped), error {:.3e} ({:.2} s)",
            t.basis_size, t.dropped, t.relative_error, t.solve_s
        );
    }
    println!(
        "study {:.2} s (Craig–Bampton {:.3} s)",
        s.total_s, s.craig_bampton_s
    );
}
