//! Parameter sweeps on one reduced model (`jointrom sweep`): a ROM is cheap, so engineers run
//! it for many loads and joint laws. The basis is built **once** (with the case's k_n — the TVD
//! depend on it through dK/dq, so a k_n far from the case's is an extrapolation of the basis) and
//! shared; each variant changes only the load factor and the pair law, and the variants run in
//! parallel across cores (rayon, one CVODE instance per variant).
//!
//! Variant file (JSON, unknown fields rejected with the file and the JSON path):
//!
//! ```text
//! { "variants": [ { "name": "mu 0.1", "load_scale": 1.0, "friction_coefficient": 0.1,
//!                   "normal_stiffness": 1e4, "stick_stiffness": 1e4 }, ... ] }
//! ```
//!
//! every field but `name` optional (default: the case's value, load factor 1).

use std::path::Path;
use std::time::Instant;

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::error::Error;
use crate::integrate::problem::OdeStats;
use crate::integrate::{Curves, TransientOptions};
use crate::model::Model;
use crate::reduction::JointFlexibility;
use crate::rom::estimate::{run_estimated, RunEstimate};
use crate::system::{ReducedSystem, Scene};

/// One variant of a sweep.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Variant {
    /// Name shown in the results.
    pub name: String,
    /// Factor on the case's master load (default 1).
    #[serde(default)]
    pub load_scale: Option<f64>,
    /// Coulomb μ (default: the case's).
    #[serde(default)]
    pub friction_coefficient: Option<f64>,
    /// Penalty k_n, N/mm (default: the case's).
    #[serde(default)]
    pub normal_stiffness: Option<f64>,
    /// Stick stiffness k_t, N/mm (default: the case's).
    #[serde(default)]
    pub stick_stiffness: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct VariantFile {
    variants: Vec<Variant>,
}

/// Reads and checks a variant file (errors name the file and the field).
pub fn read_variants(path: &Path) -> Result<Vec<Variant>, Error> {
    let text = crate::files::read_text(path)?;
    let bad = |field: String, msg: String| Error::Document {
        file: path.to_path_buf(),
        path: field,
        reason: msg,
        source: None,
    };
    let de = &mut serde_json::Deserializer::from_str(&text);
    let f: VariantFile = serde_path_to_error::deserialize(de).map_err(|e| Error::Document {
        file: path.to_path_buf(),
        path: e.path().to_string(),
        reason: e.inner().to_string(),
        source: Some(Box::new(e.into_inner())),
    })?;
    if f.variants.is_empty() {
        return Err(bad("variants".into(), "no variants".into()));
    }
    for (i, v) in f.variants.iter().enumerate() {
        let checks = [
            ("load_scale", v.load_scale, false),
            ("friction_coefficient", v.friction_coefficient, true),
            ("normal_stiffness", v.normal_stiffness, false),
            ("stick_stiffness", v.stick_stiffness, false),
        ];
        for (field, value, zero_ok) in checks {
            if let Some(x) = value {
                let ok = x.is_finite()
                    && if zero_ok {
                        x >= 0.0
                    } else {
                        x > 0.0 || field == "load_scale"
                    };
                if !ok {
                    return Err(bad(
                        format!("variants[{i}].{field}"),
                        format!(
                            "must be finite{}, got {x}",
                            if zero_ok {
                                " and ≥ 0"
                            } else {
                                " and positive"
                            }
                        ),
                    ));
                }
            }
        }
    }
    Ok(f.variants)
}

/// The result of one variant.
#[derive(Clone, Debug, Serialize)]
pub struct VariantRun {
    /// The variant.
    pub variant: Variant,
    /// `ok` or the error.
    pub status: String,
    /// Wall time of this run, s.
    pub wall_s: f64,
    /// Solver statistics.
    pub stats: OdeStats,
    /// Output curves.
    pub curves: Curves,
    /// The run's error estimate (`null` if none could be made, see `estimate_note`).
    pub error_estimate: Option<RunEstimate>,
    /// Why there is no estimate.
    pub estimate_note: Option<String>,
}

/// A whole sweep.
#[derive(Clone, Debug, Serialize)]
pub struct SweepResult {
    /// Runs in the variants' order.
    pub runs: Vec<VariantRun>,
    /// Wall time of the parallel sweep, s.
    pub wall_s: f64,
    /// Sum of the runs' wall times, s (÷ `wall_s` = the parallel speed-up).
    pub sum_wall_s: f64,
    /// Threads used.
    pub threads: usize,
}

/// The system and scene of one variant: the shared reduction with the variant's load factor and
/// law.
fn variant_system(base: &ReducedSystem, scene: &Scene, v: &Variant) -> (ReducedSystem, Scene) {
    let mut p = base.clone();
    let mut scene = *scene;
    if let Some(s) = v.load_scale {
        let m = &mut p.load.master;
        for x in [
            &mut m.fx, &mut m.fy, &mut m.fz, &mut m.mx, &mut m.my, &mut m.mz,
        ] {
            *x *= s;
        }
    }
    if let Some(mu) = v.friction_coefficient {
        scene.contact.friction_coefficient = mu;
    }
    if let Some(k) = v.normal_stiffness {
        scene.contact.normal_stiffness = k;
    }
    if let Some(k) = v.stick_stiffness {
        scene.contact.stick_stiffness = k;
    }
    (p, scene)
}

/// Runs every variant on the shared reduction `rom` of `model`, `parallel` across rayon's
/// threads or one after the other, each with its own error estimate
/// ([`crate::rom::estimate::run_estimated`]: a shared basis chosen for one variant need not
/// suit another, and the estimate says so). A variant that fails is recorded with its error;
/// `wall_s` is the run's own integration, the estimate's cost is not in it.
pub fn run_sweep(
    model: &Model,
    rom: &ReducedSystem,
    variants: &[Variant],
    opts: &TransientOptions,
    parallel: bool,
) -> Result<SweepResult, Error> {
    let base = Scene::of(model);
    let flex = JointFlexibility::new(model)?;
    let one = |v: &Variant| {
        let (system, scene) = variant_system(rom, &base, v);
        let failed = |status: String| VariantRun {
            variant: v.clone(),
            status,
            wall_s: 0.0,
            stats: OdeStats::default(),
            curves: Curves::default(),
            error_estimate: None,
            estimate_note: None,
        };
        let (r, est) = match run_estimated(model, &flex, system, &scene, opts, true, |_, _| {}) {
            Ok(x) => x,
            Err(e) => return failed(e.to_string()),
        };
        let wall_s = r.wall_s;
        match r.into_result() {
            Ok(r) => VariantRun {
                variant: v.clone(),
                status: "ok".into(),
                wall_s,
                stats: r.stats,
                curves: r.curves,
                estimate_note: est.as_ref().err().map(|e| e.to_string()),
                error_estimate: est.ok(),
            },
            Err(e) => VariantRun {
                wall_s,
                ..failed(e.to_string())
            },
        }
    };
    let t0 = Instant::now();
    let runs: Vec<VariantRun> = if parallel {
        variants.par_iter().map(one).collect()
    } else {
        variants.iter().map(one).collect()
    };
    let wall_s = t0.elapsed().as_secs_f64();
    Ok(SweepResult {
        sum_wall_s: runs.iter().map(|r| r.wall_s).sum(),
        runs,
        wall_s,
        threads: if parallel {
            rayon::current_num_threads()
        } else {
            1
        },
    })
}
