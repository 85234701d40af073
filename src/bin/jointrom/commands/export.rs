//! `jointrom export`: a reduced model as a versioned JSON file (`jointrom-rom` v1) and/or as an
//! FMI 2.0 co-simulation FMU (`jointrom::report::fmu`).

use std::path::{Path, PathBuf};

use clap::Args;

use jointrom::error::ReportError;
use jointrom::integrate::TransientOptions;
use jointrom::rom::file as export;
use jointrom::rom::{build_rom, ModelFlags};
use jointrom::Error;

#[derive(Args)]
pub struct ExportArgs {
    /// Case file, matrix map (`jointrom-matrices` JSON) or built-in name.
    case: String,
    /// The reduced model (default: tvd); --tolerance TOL exports the tolerance-chosen model
    /// (the `transient --tolerance TOL` model over the case's transient with friction).
    #[command(flatten)]
    model: ModelFlags,
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
            return Err(ReportError::FmuBinaryEnv {
                var: BINARY_ENV,
                path: p,
                file: BINARY_FILE,
            }
            .into());
        }
        return Ok(p);
    }
    let exe = std::env::current_exe().map_err(|source| ReportError::FmuNoExecutable {
        file: BINARY_FILE,
        var: BINARY_ENV,
        source,
    })?;
    let dir = exe.parent().unwrap_or(Path::new("."));
    let p = dir.join(BINARY_FILE);
    if p.is_file() {
        Ok(p)
    } else {
        Err(ReportError::FmuBinaryMissing {
            path: p,
            var: BINARY_ENV,
        }
        .into())
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
    let spec = a.model.spec_or_tvd()?;
    let built = build_rom(&model, &spec, &TransientOptions::default(), "export")?;
    let file = export::RomFile::new(&model, &built.rom, built.info)?;
    let written = write_outputs(&a, &file)?;
    match &file.basis.tolerance {
        Some(t) => println!(
            "{}: adaptive basis for tolerance {:e} ({} pairs, nu = {}), r = {}, estimated |f_c| error {:.2e}{} → {}",
            jointrom::files::printable(&model.name),
            t.tolerance,
            t.pairs.len(),
            file.basis.nu,
            file.dimension,
            t.error_estimate.unwrap_or(0.0),
            if t.met { "" } else { " (tolerance NOT met)" },
            written
        ),
        None => println!(
            "{}: {} basis, g = {}, r = {} → {}",
            jointrom::files::printable(&model.name),
            file.basis.kind,
            file.basis.g,
            file.dimension,
            written
        ),
    }
    Ok(())
}
