//! JSON summaries of a model that more than one command prints: `info --json` (the library's,
//! shared with the Python package) and the linear statics (both also part of `run`'s
//! results.json).

use serde_json::{json, Value};

use jointrom::{Error, Model};

pub use jointrom::report::info::{area_welds, cell_count, info_json};

/// `doc` with the model's warnings as `warnings` (the JSON of every command that loads a model
/// carries what its standard error said about the model).
pub fn with_warnings(model: &Model, mut doc: Value) -> Value {
    doc["warnings"] = json!(model.warnings);
    doc
}

/// The linear static solution under `scale` × the master load (also part of `run`'s
/// results.json).
pub fn static_json(model: &Model, scale: f64) -> Result<Value, Error> {
    let load = model.master_load().map(|v| v * scale);
    let sol = model.static_linear(&[load])?.remove(0);
    Ok(json!({
        "case": model.name,
        "linear": true,
        "load": load,
        "master_displacement": sol.master_displacement,
    }))
}
