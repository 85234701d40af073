//! The FMU archive: a zip (deflate, written with the `zip` crate) of the model description, the
//! binary and the reduced model, written atomically like every jointrom output.
//!
//! The archive is reproducible: entries in a fixed order, the zip format's earliest timestamp
//! (1980-01-01) on every entry, so the same reduced model and binary give the same bytes.

use std::io::{Cursor, Write};
use std::path::Path;

use zip::write::SimpleFileOptions;
use zip::{CompressionMethod, ZipWriter};

use super::{guid, model_description, model_identifier, PLATFORM, ROM_RESOURCE};
use crate::error::{Error, ReportError};
use crate::rom::file::RomFile;

/// What [`write_fmu`] wrote.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FmuPackage {
    /// The model identifier (the binary's name inside the archive without `.so`).
    pub model_identifier: String,
    /// The GUID of the model description.
    pub guid: String,
    /// Size of the archive, bytes.
    pub bytes: usize,
}

/// Whether `bytes` start like an ELF shared object (`\x7fELF`, 64-bit).
fn looks_like_elf64(bytes: &[u8]) -> bool {
    bytes.len() > 64 && bytes[..4] == *b"\x7fELF" && bytes[4] == 2
}

/// The archive's bytes for `rom` (serialized as `jointrom export --out` writes it) and the
/// binary's bytes.
fn archive(rom: &RomFile, binary: &[u8]) -> Result<(Vec<u8>, FmuPackage), Error> {
    let rom_json = serde_json::to_string_pretty(rom).expect("the reduced model serialises");
    let id = model_identifier(&rom.case);
    let description = model_description(rom, rom_json.as_bytes());
    let zip_err = |what: &str, source: zip::result::ZipError| ReportError::FmuArchive {
        what: what.to_string(),
        source,
    };
    let file = SimpleFileOptions::default()
        .compression_method(CompressionMethod::Deflated)
        .unix_permissions(0o644);
    let dir = SimpleFileOptions::default().unix_permissions(0o755);
    let mut z = ZipWriter::new(Cursor::new(Vec::new()));
    let so = format!("binaries/{PLATFORM}/{id}.so");
    let entries: [(&str, &[u8], SimpleFileOptions); 3] = [
        ("modelDescription.xml", description.as_bytes(), file),
        (&so, binary, file.unix_permissions(0o755)),
        (ROM_RESOURCE, rom_json.as_bytes(), file),
    ];
    for d in ["binaries/", &format!("binaries/{PLATFORM}/"), "resources/"] {
        z.add_directory(d, dir).map_err(|e| zip_err(d, e))?;
    }
    for (name, bytes, opts) in entries {
        z.start_file(name, opts).map_err(|e| zip_err(name, e))?;
        z.write_all(bytes)
            .map_err(|e| zip_err(name, zip::result::ZipError::Io(e)))?;
    }
    let bytes = z.finish().map_err(|e| zip_err("finish", e))?.into_inner();
    let info = FmuPackage {
        model_identifier: id,
        guid: guid(rom_json.as_bytes()),
        bytes: bytes.len(),
    };
    Ok((bytes, info))
}

/// Writes the FMU of `rom` with the FMU binary at `binary` (`libjointrom_fmu.so`) to `out`.
///
/// # Errors
/// [`Error::Io`] naming the binary if it cannot be read, [`Error::Report`] if it is not a
/// 64-bit ELF shared object, errors writing `out` (naming it).
pub fn write_fmu(rom: &RomFile, binary: &Path, out: &Path) -> Result<FmuPackage, Error> {
    let so = crate::files::read_bytes(binary)?;
    if !looks_like_elf64(&so) {
        return Err(ReportError::FmuBinary {
            binary: binary.to_path_buf(),
        }
        .into());
    }
    let (bytes, info) = archive(rom, &so)?;
    crate::files::write_atomic(out, bytes)?;
    Ok(info)
}
