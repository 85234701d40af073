//! `jointrom export`: a reduced model as a versioned JSON file (`jointrom-rom` v1).

use std::path::PathBuf;

use clap::Args;

use jointrom::reduction::rom_file as export;
use jointrom::reduction::{build_basis, BasisKind, BasisOptions};
use jointrom::system::ReducedSystem;
use jointrom::Error;

use jointrom::studies::tolerance::{tolerance_model, ToleranceOptions};

use crate::cli::BasisArg;

#[derive(Args)]
pub struct ExportArgs {
    /// Case file, matrix map (`jointrom-matrices` JSON) or built-in name.
    case: String,
    /// Basis kind: tvd, tvd-plain, modes, jim, alldof (default tvd).
    #[arg(long, value_enum)]
    basis: Option<BasisArg>,
    /// Enrichment vectors g; default: the smallest g with w(g) >= 0.999.
    #[arg(long)]
    g: Option<usize>,
    /// Fixed-interface modes ν.
    #[arg(long, default_value_t = 10)]
    nu: usize,
    /// Export the tolerance-chosen model instead (the `transient --tolerance TOL` model: the
    /// smallest Craig–Bampton + pair-attachment-mode basis whose estimated relative L2 error of
    /// |f_c|(t) over the case's transient with friction is at most TOL, in (0, 1)).
    #[arg(long, allow_negative_numbers = true)]
    tolerance: Option<f64>,
    /// Output file.
    #[arg(long)]
    out: PathBuf,
}

pub fn run(a: ExportArgs) -> Result<(), Error> {
    let model = crate::common::load_model(&a.case)?;
    if let Some(tol) = a.tolerance {
        if a.basis.is_some() || a.g.is_some() {
            return Err(Error::Invalid(
                "--tolerance chooses its own basis: drop --basis and --g".into(),
            ));
        }
        let mut opts = ToleranceOptions::new(tol);
        opts.nu = a.nu;
        let t = tolerance_model(&model, &opts)?;
        let info = export::BasisInfo {
            kind: "adaptive".into(),
            g: t.pairs.len(),
            nu: t.nu,
            threshold: 0.0,
            w: Vec::new(),
            tolerance: Some(export::ToleranceInfo {
                tolerance: tol,
                met: t.met,
                pairs: t.pairs.clone(),
                error_estimate: t.estimate.total.contact_force,
            }),
        };
        let file = export::RomFile::new(&model, &t.rom, info)?;
        file.write(&a.out)?;
        println!(
            "{}: adaptive basis for tolerance {tol:e} ({} pairs, nu = {}), r = {}, estimated |f_c| error {:.2e}{} → {}",
            jointrom::files::printable(&model.name),
            t.pairs.len(),
            t.nu,
            file.dimension,
            t.estimate.total.contact_force.unwrap_or(0.0),
            if t.met { "" } else { " (tolerance NOT met)" },
            a.out.display()
        );
        return Ok(());
    }
    let kind = BasisKind::from(a.basis.unwrap_or(BasisArg::Tvd));
    let opts = BasisOptions {
        g: a.g,
        nu: a.nu,
        ..BasisOptions::default()
    };
    let b = build_basis(&model, kind, &opts)?;
    let info = export::BasisInfo {
        kind: kind.name().into(),
        g: b.g,
        nu: a.nu,
        threshold: opts.threshold,
        w: b.w.clone(),
        tolerance: None,
    };
    let rom = ReducedSystem::new(&model, b.phi)?;
    let file = export::RomFile::new(&model, &rom, info)?;
    file.write(&a.out)?;
    println!(
        "{}: {} basis, g = {}, r = {} → {}",
        jointrom::files::printable(&model.name),
        kind.name(),
        file.basis.g,
        file.dimension,
        a.out.display()
    );
    Ok(())
}
