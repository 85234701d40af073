//! The command line: subcommands, their enumerated flag values, and today's error texts for bad
//! values of those flags.

use clap::error::{ContextKind, ContextValue, ErrorKind};
use clap::{Parser, Subcommand};

use jointrom::error::FlagError;
use jointrom::reduction::BasisKind;
use jointrom::studies::stability::{IterKind, ModelKind};
use jointrom::Error;

use crate::commands::{
    backbone, basis, distributed, export, export_matrices, info, modes, run, shapes, stability,
    statics, study as study_cmd, sweep, transient,
};

#[derive(Parser)]
#[command(
    name = "jointrom",
    version,
    about = "Reduced-order transient dynamics of jointed sheet structures (trial vector derivatives)"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
    /// Contact stiffness per area `KN,KT` (N/mm³) for the model of any command: each joint
    /// pair's normal and stick stiffness become KN·A and KT·A with A its tributary area on the
    /// joint surface, in place of the per-pair values of the deck's PGAP (or the case's or the
    /// map's contact block).
    #[arg(long, global = true, value_name = "KN,KT")]
    pub contact_per_area: Option<String>,
    /// How a NASTRAN deck's CWELD area welds re-mesh their neighbourhood: `auto` (default, a
    /// case file's rule: re-meshed where the shells do not resolve the nugget), `off` (the
    /// nugget on the deck's own shells) or a shell size in mm.
    #[arg(long, global = true, value_name = "auto|off|SIZE")]
    pub deck_local_mesh: Option<String>,
    /// Contact points inside a case's joint faces `M[,hermite|bilinear]`: M × M points per face
    /// (1 ≤ M ≤ 8) with the gap interpolated from the shells' edge deflections (`hermite`,
    /// default) or bilinearly, in place of the case's `contact.sampling`; needs the contact
    /// stiffnesses per area (the case's or --contact-per-area).
    #[arg(long, global = true, value_name = "M[,GAP]")]
    pub contact_sampling: Option<String>,
}

impl Cli {
    /// The model-loading options of the global flags.
    pub fn load_options(&self) -> Result<jointrom::model::LoadOptions, Error> {
        use jointrom::case::LocalMesh;
        let deck_local_mesh = match self.deck_local_mesh.as_deref() {
            None | Some("auto") => LocalMesh::Auto,
            Some("off") => LocalMesh::Off,
            Some(text) => match text.parse::<f64>() {
                Ok(size) if size.is_finite() && size > 0.0 => LocalMesh::Size(size),
                _ => {
                    return Err(FlagError::Range {
                        flag: "deck-local-mesh",
                        need: "`auto`, `off` or a shell size in mm (finite and > 0)",
                        got: format!("`{text}`"),
                    }
                    .into())
                }
            },
        };
        Ok(jointrom::model::LoadOptions {
            contact_per_area: self.contact_per_area()?,
            deck_local_mesh,
            contact_sampling: self.contact_sampling()?,
        })
    }

    /// `--contact-sampling M[,GAP]`: M in 1..=8, GAP `hermite` (default) or `bilinear`.
    pub fn contact_sampling(&self) -> Result<Option<jointrom::case::ContactSampling>, Error> {
        use jointrom::case::{ContactSampling, GapInterpolation, MAX_POINTS_PER_EDGE};
        let Some(text) = &self.contact_sampling else {
            return Ok(None);
        };
        let bad = || FlagError::Range {
            flag: "contact-sampling",
            need: "`M` or `M,hermite` or `M,bilinear` with M points per face edge in 1..=8",
            got: format!("`{text}`"),
        };
        let mut parts = text.split(',').map(str::trim);
        let m: usize = parts.next().and_then(|m| m.parse().ok()).ok_or_else(bad)?;
        let gap = match parts.next() {
            None | Some("hermite") => GapInterpolation::Hermite,
            Some("bilinear") => GapInterpolation::Bilinear,
            Some(_) => return Err(bad().into()),
        };
        if parts.next().is_some() || !(1..=MAX_POINTS_PER_EDGE).contains(&m) {
            return Err(bad().into());
        }
        Ok(Some(ContactSampling {
            points_per_edge: m,
            gap,
        }))
    }

    /// `--contact-per-area KN,KT`: two positive finite numbers.
    pub fn contact_per_area(&self) -> Result<Option<[f64; 2]>, Error> {
        let Some(text) = &self.contact_per_area else {
            return Ok(None);
        };
        let bad = || FlagError::Range {
            flag: "contact-per-area",
            need: "two positive stiffnesses per area `KN,KT` in N/mm³ (finite and > 0)",
            got: format!("`{text}`"),
        };
        let values: Vec<f64> = text
            .split(',')
            .map(|v| v.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|_| bad())?;
        match values[..] {
            [n, t] if n.is_finite() && n > 0.0 && t.is_finite() && t > 0.0 => Ok(Some([n, t])),
            _ => Err(bad().into()),
        }
    }
}

#[derive(Subcommand)]
pub enum Command {
    /// Model summary: DOF, joint pairs, nodes, elements.
    Info(info::InfoArgs),
    /// Lowest eigenfrequencies (joint open, no contact stiffness).
    Modes(modes::ModesArgs),
    /// Static response to the case's master load.
    Static(statics::StaticArgs),
    /// The TVD basis (Algorithm 2): POD energy ratios w(g), chosen g, sizes, build time.
    Basis(basis::BasisArgs),
    /// Static convergence study: ‖f_c‖ of each reduced basis against the number of added
    /// vectors g, w(g); writes OUT/CASE/study.json and SVG/PNG charts.
    Study(study_cmd::StudyArgs),
    /// Stability map of the transient methods: model × iteration × k_n × friction × events ×
    /// max order → status (ok or the CVODE flag and time reached), cost, error; writes
    /// OUT/CASE/stability.json, stability.md and heat maps (SVG/PNG).
    Stability(stability::StabilityArgs),

    /// Transient run from rest (CVODE): contact force norm, friction force norm and master uy
    /// over time, solver statistics and wall time.
    Transient(transient::TransientArgs),
    /// Writes the Craig–Bampton vectors, the first TVD and joint modes as VTU (ParaView) and a
    /// picture of the first joint modes (PNG + SVG) → DIR/CASE/.
    Shapes(shapes::ShapesArgs),
    /// Runs a list of variants (load factor, μ, k_n, k_t) of one reduced model in parallel,
    /// sharing the basis → a table (or JSON with every run's curves).
    Sweep(sweep::SweepArgs),
    /// Backbones: frequency and damping ratio of modes against amplitude, from free decays of
    /// the reduced (or full FE) model about the equilibrium under a preload → table, JSON, CSV,
    /// charts.
    Backbone(backbone::BackboneArgs),
    /// Writes a reduced model as a versioned JSON file (schema `jointrom-rom` v1: M̃, K̃, BΦ,
    /// master rows, reduced loads, contact law, load ramp; see `jointrom::rom::file`).
    Export(export::ExportArgs),
    /// Writes a model's K and M as MatrixMarket files plus the JSON map (`K.mtx`, `M.mtx`,
    /// `model.json`; see `jointrom::model::matrices`): the format a user's own model comes in. Any
    /// command takes `DIR/model.json` where it takes a case.
    ExportMatrices(export_matrices::ExportMatricesArgs),
    /// The main job on a case (default: the friction bar): static study, full FE and reduced
    /// transients, speed against accuracy → DIR/CASE/report.md, charts, results.json.
    Run(run::RunArgs),
    /// The Craig–Bampton eigen solve and the TVD multi-right-hand-side solve on PETSc/SLEPc
    /// (+ MUMPS) under `mpirun -n R`, compared with the native path: frequencies, span of the
    /// modes, the solve's difference and backward error, timings (opt-in: docs/distributed.md).
    Distributed(distributed::DistributedArgs),
}

impl Command {
    /// Runs the subcommand.
    pub fn run(self) -> Result<(), Error> {
        match self {
            Command::Info(a) => info::run(a),
            Command::Modes(a) => modes::run(a),
            Command::Static(a) => statics::run(a),
            Command::Basis(a) => basis::run(a),
            Command::Study(a) => study_cmd::run(a),
            Command::Stability(a) => stability::run(a),
            Command::Transient(a) => transient::run(a),
            Command::Shapes(a) => shapes::run(a),
            Command::Sweep(a) => sweep::run(a),
            Command::Backbone(a) => backbone::run(a),
            Command::Export(a) => export::run(a),
            Command::ExportMatrices(a) => export_matrices::run(a),
            Command::Run(a) => run::run(a),
            Command::Distributed(a) => distributed::run(a),
        }
    }
}

/// The error `jointrom` reported for a bad value of an enumerated flag before the flags were
/// typed (they were parsed by the commands then); `None` for every other parse error, which
/// clap reports itself. `args` is the command line (program name first).
pub fn legacy_value_error(e: &clap::Error, args: &[String]) -> Option<Error> {
    if e.kind() != ErrorKind::InvalidValue {
        return None;
    }
    let text = |k| match e.get(k) {
        Some(ContextValue::String(s)) => Some(s.clone()),
        _ => None,
    };
    let arg = text(ContextKind::InvalidArg)?;
    let value = text(ContextKind::InvalidValue)?;
    let flag = arg.split([' ', '=']).next().unwrap_or_default();
    // clap reports a missing value as an empty one; only a given empty value went to the
    // command before.
    if value.is_empty() && !has_value(args, flag) {
        return None;
    }
    value_error(args.get(1)?, flag, &value)
}

/// Whether `flag` is given a value on the command line (`--flag=…` or `--flag …`).
fn has_value(args: &[String], flag: &str) -> bool {
    args.iter().enumerate().any(|(i, a)| {
        a.strip_prefix(flag).is_some_and(|r| r.starts_with('='))
            || (a == flag && args.get(i + 1).is_some_and(|v| !v.starts_with('-')))
    })
}

/// Today's error for `value` given to `flag` of `subcommand`.
fn value_error(subcommand: &str, flag: &str, v: &str) -> Option<Error> {
    let value = v.to_string();
    let e = match (subcommand, flag) {
        ("static", "--basis") => FlagError::UnknownBasis {
            flag: "basis",
            value,
            valid: &BasisKind::NAMES,
        },
        ("sweep" | "export" | "transient", "--basis") => FlagError::Basis {
            flag: "basis",
            source: BasisKind::from_name(v).err()?,
        },
        ("basis", "--kind") => FlagError::Value {
            flag: "kind",
            value: format!("{v:?}"),
            need: "valid: tvd, tvd-plain",
        },
        ("transient", "--iteration") => FlagError::Range {
            flag: "iteration",
            need: "`newton` or `functional`",
            got: format!("`{v}`"),
        },
        ("transient", "--friction" | "--events" | "--stab-lim-det") => FlagError::Range {
            flag: switch(flag)?,
            need: "`on` or `off`",
            got: format!("`{v}`"),
        },
        ("stability", "--models") => return ModelKind::parse(v).err(),
        ("stability", "--iterations") => return IterKind::parse(v).err(),
        ("stability", "--friction" | "--events") => FlagError::OnOff {
            flag: switch(flag)?,
            value,
        },
        _ => return None,
    };
    Some(e.into())
}

/// The name of the on/off switch `flag` (`--friction`, `--events`, `--stab-lim-det`).
fn switch(flag: &str) -> Option<&'static str> {
    let name = flag.strip_prefix("--")?;
    ["friction", "events", "stab-lim-det"]
        .into_iter()
        .find(|&s| s == name)
}
