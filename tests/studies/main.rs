//! Studies (`jointrom::studies`): backbones, the static convergence study, the stability map,
//! parameter sweeps, the POD-snapshot ROM.

#[path = "../common/mod.rs"]
mod common;

mod backbone;
mod pod_snapshots;
mod stability;
mod study;
mod sweep;
