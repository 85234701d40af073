//! The reduced model's home: choose it, build it, run it with its error estimate, compare it.
//!
//! ```text
//!  ModelSpec (spec)  ──►  build_rom (build) / run_model (run)  ──►  ModelRun { run, estimate }
//!  full | basis kind + g, ν | pod | tolerance | file      │
//!                                                         ├─ tolerance: the smallest model
//!                                                         │  whose estimate meets TOL
//!                                                         └─ estimate: every reduced run's
//!                                                            a-posteriori error
//! ```
//!
//! - [`spec`]: [`ModelSpec`], the model choice parsed once, and [`ModelFlags`], the one clap group
//!   of model flags every command flattens.
//! - [`build`]: a reduced model from a spec, with the record the reduced-model file keeps.
//! - [`run`]: one transient run of a spec's model (the `transient` command's engine).
//! - [`estimate`]: the estimated reduced run — the reduction part (quasi-static joint correction,
//!   [`crate::reduction::estimate`]) and the integration part (a re-run at looser tolerances).
//! - [`tolerance`]: the error-controlled reduction (Craig–Bampton plus the attachment modes of
//!   the pairs the estimate selects), transient and static.
//! - [`statics`]: contact statics of a reduced model.
//! - [`training`]: the POD of a full-FE training run (the paper's Section 5.2 competitor).
//! - [`mod@file`]: the reduced model as a versioned JSON file (`jointrom-rom`).
//! - [`compare`]: curves against curves — the relative L2 error every estimate and reference
//!   check uses, and stored reference curves.
//!
//! In the dependency rule (ARCHITECTURE.md) `rom` sits between `integrate` (it runs models) and
//! `studies` (which run many models): nothing in `studies` is needed to run one reduced model.

pub mod build;
pub mod compare;
pub mod estimate;
pub mod file;
pub mod run;
pub mod spec;
pub mod statics;
pub mod tolerance;
pub mod training;

pub use build::{build_rom, BuiltRom};
pub use compare::{relative_l2, JointCurves, ReferenceCurves, ReferenceErrors};
pub use estimate::{run_estimated, RunEstimate};
pub use run::{run_model, run_rom, Frames, ModelRun, RunSettings};
pub use spec::{ModelFlags, ModelSpec};
pub use tolerance::{
    tolerance_model, CompressJoint, StoppedRound, ToleranceModel, ToleranceOptions,
};
