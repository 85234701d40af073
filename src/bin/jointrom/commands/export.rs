//! `jointrom export`: a reduced model as a versioned JSON file (`jointrom-rom` v1).

use std::path::PathBuf;

use clap::Args;

use jointrom::reduction::rom_file as export;
use jointrom::reduction::{build_basis, BasisKind, BasisOptions};
use jointrom::system::ReducedSystem;
use jointrom::{Error, Model};

use crate::cli::BasisArg;

#[derive(Args)]
pub struct ExportArgs {
    /// Case file, matrix map (`jointrom-matrices` JSON) or built-in name.
    case: String,
    /// Basis kind: tvd, tvd-plain, modes, jim, alldof.
    #[arg(long, value_enum, default_value_t = BasisArg::Tvd)]
    basis: BasisArg,
    /// Enrichment vectors g; default: the smallest g with w(g) >= 0.999.
    #[arg(long)]
    g: Option<usize>,
    /// Fixed-interface modes ν.
    #[arg(long, default_value_t = 10)]
    nu: usize,
    /// Output file.
    #[arg(long)]
    out: PathBuf,
}

pub fn run(a: ExportArgs) -> Result<(), Error> {
    let model = Model::from_case_name(&a.case)?;
    let kind = BasisKind::from(a.basis);
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
    };
    let rom = ReducedSystem::new(&model, b.phi)?;
    let file = export::RomFile::new(&model, &rom, info)?;
    file.write(&a.out)?;
    println!(
        "{}: {} basis, g = {}, r = {} → {}",
        model.name,
        kind.name(),
        file.basis.g,
        file.dimension,
        a.out.display()
    );
    Ok(())
}
