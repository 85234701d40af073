//! `libjointrom_fmu.so`: the binary of jointrom's FMI 2.0 co-simulation FMUs
//! (`jointrom export CASE --fmu OUT.fmu`, see `jointrom::report::fmu` for the archive and the
//! variables).
//!
//! One binary serves every exported reduced model: `fmi2Instantiate` reads the FMU's
//! `resources/rom.json` (schema `jointrom-rom` v1), checks it against the model description's
//! GUID, and `fmi2DoStep` integrates it with jointrom's own engine — the mechanical ODE with
//! penalty contact and viscoplastic Coulomb friction under CVODE, with the options of `jointrom
//! transient` — through the library's stepping API (`jointrom::integrate::Stepper`).
//!
//! ## Layout
//!
//! - [`ffi`] — the C ABI of FMI 2.0 (every `fmi2…` function the co-simulation interface
//!   defines), the crate's only `unsafe` code: pointer checks, `catch_unwind` around every
//!   body, the logger, the instance's allocation and release;
//! - [`slave`] — the state machine, the variables and the stepping, in safe Rust;
//! - [`uri`] — `fmuResourceLocation` (a `file:` URI) to a path.
//!
//! ## Shared libraries
//!
//! jointrom's Rust code (faer, serde, ...) is linked in statically; SUNDIALS is linked
//! dynamically, as in the `jointrom` executable (`sundials-sys` links Debian's
//! `libsundials_cvode.so.6`, `libsundials_nvecserial.so.6`, ...; package `libsundials-dev`, or
//! its runtime packages). `ldd` on the binary lists them (docs/guide/fmu.md).

#![deny(unsafe_code)]

#[allow(unsafe_code)]
pub mod ffi;
pub mod slave;
pub mod uri;
