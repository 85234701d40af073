//! `jointrom export`: a reduced model as a versioned JSON file (`jointrom-rom` v1) and/or as an
//! FMI 2.0 co-simulation FMU (`jointrom::report::fmu`).

use std::path::{Path, PathBuf};

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
    /// Output file: the reduced model as JSON (`jointrom-rom` v1).
    #[arg(long, required_unless_present = "fmu")]
    out: Option<PathBuf>,
    /// Also (or instead) write the reduced model as an FMI 2.0 co-simulation FMU: the archive
    /// holds modelDescription.xml, the FMU binary (libjointrom_fmu.so, taken from
    /// $JOINTROM_FMU_BINARY or beside this executable; build it with `cargo build --release
    /// -p jointrom-fmu`) and the reduced model as resources/rom.json.
    #[arg(long)]
    fmu: Option<PathBuf>,
}

/// The FMU binary to package: `$JOINTROM_FMU_BINARY`, else `libjointrom_fmu.so` beside the
/// running executable (cargo builds both into `target/release/`).
fn fmu_binary() -> Result<PathBuf, Error> {
    use jointrom::report::fmu::{BINARY_ENV, BINARY_FILE};
    if let Some(p) = std::env::var_os(BINARY_ENV) {
        let p = PathBuf::from(p);
        if !p.is_file() {
            return Err(Error::Invalid(format!(
                "{BINARY_ENV}={} is not a file (point it at the {BINARY_FILE} built by `cargo \
                 build --release -p jointrom-fmu`, or unset it)",
                p.display()
            )));
        }
        return Ok(p);
    }
    let exe = std::env::current_exe().map_err(|e| {
        Error::Invalid(format!(
            "--fmu: cannot locate this executable to find {BINARY_FILE} beside it ({e}); set \
             {BINARY_ENV}"
        ))
    })?;
    let dir = exe.parent().unwrap_or(Path::new("."));
    let p = dir.join(BINARY_FILE);
    if p.is_file() {
        Ok(p)
    } else {
        Err(Error::Invalid(format!(
            "--fmu: the FMU binary {} does not exist: build it with `cargo build --release -p \
             jointrom-fmu` (it lands beside the jointrom executable), or set {BINARY_ENV} to it",
            p.display()
        )))
    }
}

/// Writes `file` to `--out` and/or `--fmu`; the paths written, for the summary line.
fn write_outputs(a: &ExportArgs, file: &export::RomFile) -> Result<String, Error> {
    // Find the binary first: a missing binary must not leave a half-done export behind.
    let binary = a.fmu.as_ref().map(|_| fmu_binary()).transpose()?;
    let mut written = Vec::new();
    if let Some(out) = &a.out {
        file.write(out)?;
        written.push(out.display().to_string());
    }
    if let (Some(out), Some(binary)) = (&a.fmu, binary) {
        let p = jointrom::report::fmu::write_fmu(file, &binary, out)?;
        written.push(format!(
            "{} (FMI 2.0 co-simulation, {}, {} bytes)",
            out.display(),
            p.model_identifier,
            p.bytes
        ));
    }
    Ok(written.join(" and "))
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
        let written = write_outputs(&a, &file)?;
        println!(
            "{}: adaptive basis for tolerance {tol:e} ({} pairs, nu = {}), r = {}, estimated |f_c| error {:.2e}{} → {}",
            jointrom::files::printable(&model.name),
            t.pairs.len(),
            t.nu,
            file.dimension,
            t.estimate.total.contact_force.unwrap_or(0.0),
            if t.met { "" } else { " (tolerance NOT met)" },
            written
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
    let written = write_outputs(&a, &file)?;
    println!(
        "{}: {} basis, g = {}, r = {} → {}",
        jointrom::files::printable(&model.name),
        kind.name(),
        file.basis.g,
        file.dimension,
        written
    );
    Ok(())
}
