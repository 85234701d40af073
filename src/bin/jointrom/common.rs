//! Helpers the commands share: printing, flag checks, files.

use std::path::Path;
use std::sync::{LazyLock, Mutex};
use std::time::Instant;

use jointrom::model::LoadOptions;
use jointrom::{Error, Model};
use serde_json::Value;

/// Prints one pretty JSON document on stdout. A document of a command that loaded a model gains
/// `"model_s"`: the wall time of reading and building the model (s), and every document
/// `"total_s"` (where the command did not set its own): the wall time of the command up to this
/// print (s), so that the end-to-end time of a command is visible beside its `offline_s` and
/// `wall_s`.
pub fn print_json(v: &Value) {
    let mut v = v.clone();
    if let Value::Object(map) = &mut v {
        if let Some(s) = model_seconds() {
            map.entry("model_s").or_insert(Value::from(s));
        }
        map.entry("total_s")
            .or_insert(Value::from(COMMAND_START.elapsed().as_secs_f64()));
    }
    println!(
        "{}",
        serde_json::to_string_pretty(&v).expect("JSON values serialise")
    );
}

/// When the command started (the first use: `main` touches it before parsing the command line).
pub static COMMAND_START: LazyLock<Instant> = LazyLock::new(Instant::now);

/// Wall time of the model loads of this command, s (`None` before one).
static MODEL_S: Mutex<Option<f64>> = Mutex::new(None);

fn model_seconds() -> Option<f64> {
    MODEL_S.lock().ok().and_then(|g| *g)
}

/// Prints the six master displacements `u[k]`, one a line (mm, then rad).
pub fn print_master_displacement(u: impl Fn(usize) -> f64) {
    for (k, name) in ["ux", "uy", "uz", "rx", "ry", "rz"].iter().enumerate() {
        let unit = if k < 3 { "mm" } else { "rad" };
        println!("  {name} = {:>14.6e} {unit}", u(k));
    }
}

/// `v` if finite and positive, else an error naming `--flag`.
pub fn positive(flag: &'static str, v: f64) -> Result<f64, Error> {
    jointrom::integrate::positive_flag(flag, v)
}

/// Creates `dir` and its parents.
pub fn create_dir(dir: &Path) -> Result<(), Error> {
    jointrom::files::create_dir(dir)
}

/// Writes `text` to `file`.
pub fn write_file(file: &Path, text: impl AsRef<[u8]>) -> Result<(), Error> {
    jointrom::files::write_atomic(file, text)
}

/// The inputs the command has read, for errors that cannot name one themselves (a matrix that
/// is not positive definite, a CVODE failure): the main function names them.
static INPUTS: Mutex<Vec<String>> = Mutex::new(Vec::new());

/// Records an input the command read (a model's files, a reduced-model file).
pub fn record_input(what: String) {
    if let Ok(mut v) = INPUTS.lock() {
        if !v.contains(&what) {
            v.push(what);
        }
    }
}

/// The inputs recorded so far.
pub fn inputs() -> Vec<String> {
    INPUTS.lock().map(|v| v.clone()).unwrap_or_default()
}

/// `--contact-per-area` and `--deck-local-mesh`, parsed once by the main function.
static LOAD_OPTIONS: Mutex<Option<LoadOptions>> = Mutex::new(None);

/// Sets the options every [`load_model`] applies.
pub fn set_load_options(opts: LoadOptions) {
    if let Ok(mut g) = LOAD_OPTIONS.lock() {
        *g = Some(opts);
    }
}

/// Loads a case file, deck, built-in scene or matrix map ([`Model::from_case_name_with`], with
/// `--contact-per-area` and `--deck-local-mesh`) and records where its matrices came from.
pub fn load_model(arg: &str) -> Result<Model, Error> {
    let start = std::time::Instant::now();
    let opts = LOAD_OPTIONS
        .lock()
        .ok()
        .and_then(|g| *g)
        .unwrap_or_default();
    let model = Model::from_case_name_with(arg, &opts)?;
    if let Ok(mut g) = MODEL_S.lock() {
        *g = Some(g.unwrap_or(0.0) + start.elapsed().as_secs_f64());
    }
    record_input(format!("model {}", model.describe_source()));
    for w in &model.warnings {
        eprintln!("warning: {}", jointrom::files::printable(w));
    }
    Ok(model)
}
