//! `jointrom basis`: the TVD basis and its POD energy ratios.

use clap::Args;

use jointrom::error::FlagError;
use jointrom::reduction::{BasisKind, BasisOptions};
use jointrom::studies::convergence as study;
use jointrom::Error;

use crate::common::print_json;

#[derive(Args)]
pub struct BasisArgs {
    /// Case file, matrix map (`jointrom-matrices` JSON) or built-in name.
    case: String,
    /// tvd (K-weighted POD) or tvd-plain (plain POD).
    #[arg(long, value_enum, default_value_t = BasisKind::Tvd)]
    kind: BasisKind,
    /// Number of joint modes; default: the smallest g with w(g) >= --threshold.
    #[arg(long)]
    g: Option<usize>,
    /// Energy threshold for choosing g (eq. 26).
    #[arg(long, default_value_t = jointrom::reduction::DEFAULT_THRESHOLD)]
    threshold: f64,
    /// Fixed-interface modes ν.
    #[arg(long, default_value_t = 10)]
    nu: usize,
    /// One JSON document on stdout.
    #[arg(long)]
    json: bool,
}

pub fn run(a: BasisArgs) -> Result<(), Error> {
    if !matches!(a.kind, BasisKind::Tvd | BasisKind::TvdPlain) {
        return Err(FlagError::Value {
            flag: "kind",
            value: a.kind.name().to_string(),
            need: "must be tvd or tvd-plain",
        }
        .into());
    }
    let model = crate::common::load_model(&a.case)?;
    let opts = BasisOptions {
        nu: a.nu,
        g: a.g,
        threshold: a.threshold,
        ..BasisOptions::default()
    };
    let b = study::basis_summary(&model, a.kind, &opts)?;
    if a.json {
        print_json(&serde_json::to_value(&b).expect("JSON values serialise"));
        return Ok(());
    }
    println!(
        "{} — {} basis, ν = {}: {} TVD ({} nonzero), g = {} (w = {:.6}, plain w = {:.6}; threshold {}), \
         basis {} columns ({} dropped), built in {:.1} ms",
        b.case,
        b.kind,
        b.nu,
        b.tvd_count,
        b.tvd_nonzero,
        b.g_chosen,
        b.w.get(b.g_chosen.wrapping_sub(1)).copied().unwrap_or(0.0),
        b.w_plain.get(b.g_chosen.wrapping_sub(1)).copied().unwrap_or(0.0),
        b.threshold,
        b.basis_size,
        b.dropped,
        b.build_s * 1e3
    );
    println!("    g   w(g) K-weighted   w(g) plain");
    for i in 0..b.w.len().min(60) {
        println!("  {:>3}   {:.8}        {:.8}", i + 1, b.w[i], b.w_plain[i]);
    }
    Ok(())
}
