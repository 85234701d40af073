//! Helpers the commands share: printing, flag checks, files.

use std::path::Path;

use jointrom::Error;
use serde_json::Value;

/// Prints one pretty JSON document on stdout.
pub fn print_json(v: &Value) {
    println!(
        "{}",
        serde_json::to_string_pretty(v).expect("JSON values serialise")
    );
}

/// Prints the six master displacements `u[k]`, one a line (mm, then rad).
pub fn print_master_displacement(u: impl Fn(usize) -> f64) {
    for (k, name) in ["ux", "uy", "uz", "rx", "ry", "rz"].iter().enumerate() {
        let unit = if k < 3 { "mm" } else { "rad" };
        println!("  {name} = {:>14.6e} {unit}", u(k));
    }
}

/// `v` if finite and positive, else an error naming `--flag`.
pub fn positive(flag: &str, v: f64) -> Result<f64, Error> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(Error::Invalid(format!(
            "--{flag} must be finite and positive, got {v}"
        )))
    }
}

/// Creates `dir` and its parents.
pub fn create_dir(dir: &Path) -> Result<(), Error> {
    jointrom::files::create_dir(dir)
}

/// Writes `text` to `file`.
pub fn write_file(file: &Path, text: impl AsRef<[u8]>) -> Result<(), Error> {
    jointrom::files::write_atomic(file, text)
}
