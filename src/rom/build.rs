//! A reduced model from its [`ModelSpec`]: the reduced system and the record of how it was made
//! (the basis kind, g, ν, the w(g) ratios, the tolerance and its estimate), as the reduced-model
//! file, the FMU, sweeps and reports keep it.

use std::time::Instant;

use crate::error::Error;
use crate::integrate::TransientOptions;
use crate::model::Model;
use crate::reduction::{build_basis, BasisOptions};
use crate::rom::file::{BasisInfo, ToleranceInfo};
use crate::rom::spec::{unsupported, ModelSpec};
use crate::rom::tolerance::{tolerance_model, ToleranceModel, ToleranceOptions};
use crate::system::ReducedSystem;

/// A reduced model built from a spec.
pub struct BuiltRom {
    /// The reduced system (with its basis Φ).
    pub rom: ReducedSystem,
    /// How it was made (the reduced-model file's `basis` record).
    pub info: BasisInfo,
    /// Wall time of the build, s (for the tolerance model: everything up to its result's run,
    /// the earlier rounds included).
    pub offline_s: f64,
    /// The tolerance model's rounds, result run and estimate ([`ModelSpec::Tolerance`] only).
    pub tolerance: Option<ToleranceModel>,
}

/// Builds the reduced model of a [`ModelSpec::Basis`] or [`ModelSpec::Tolerance`]; the
/// tolerance model is chosen with the transient options `transient` (its rounds are runs).
///
/// # Errors
/// A spec that is not one of those two (naming `command`), a failing basis or tolerance model.
pub fn build_rom(
    model: &Model,
    spec: &ModelSpec,
    transient: &TransientOptions,
    command: &str,
) -> Result<BuiltRom, Error> {
    let start = Instant::now();
    match spec {
        &ModelSpec::Basis { kind, g, nu } => {
            let opts = BasisOptions {
                g,
                nu,
                ..BasisOptions::default()
            };
            let b = build_basis(model, kind, &opts)?;
            let info = BasisInfo {
                kind: kind.name().into(),
                g: b.g,
                nu,
                threshold: opts.threshold,
                w: b.w.clone(),
                tolerance: None,
            };
            let rom = ReducedSystem::new(model, b.phi)?;
            Ok(BuiltRom {
                rom,
                info,
                offline_s: start.elapsed().as_secs_f64(),
                tolerance: None,
            })
        }
        &ModelSpec::Tolerance { tolerance, nu, on } => {
            let mut opts = ToleranceOptions::new(tolerance);
            opts.nu = nu;
            opts.quantities = on;
            opts.transient = transient.clone();
            let t = tolerance_model(model, &opts)?;
            let info = BasisInfo {
                kind: "adaptive".into(),
                g: t.pairs.len(),
                nu: t.nu,
                threshold: 0.0,
                w: Vec::new(),
                tolerance: Some(ToleranceInfo {
                    tolerance,
                    met: t.met,
                    pairs: t.pairs.clone(),
                    error_estimate: t.estimate.total.contact_force,
                }),
            };
            Ok(BuiltRom {
                rom: t.rom.clone(),
                info,
                offline_s: t.offline_s,
                tolerance: Some(t),
            })
        }
        other => Err(unsupported(
            command,
            other,
            "a reduced basis (--basis KIND or --model KIND) or --tolerance TOL",
        )),
    }
}
