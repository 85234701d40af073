//! The reduced model as an FMI 2.0 co-simulation FMU (`jointrom export --fmu`,
//! `jointrom::report::fmu`, the `jointrom-fmu` binary): the archive, a host driving the binary
//! through `libloading` against `jointrom transient`, and the error paths of the C interface.

#[path = "../common/mod.rs"]
mod common;

mod cosim;
mod errors;
mod host;
