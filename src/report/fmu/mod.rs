//! The reduced model as an FMI 2.0 co-simulation FMU (`jointrom export --fmu OUT.fmu`).
//!
//! ## What the FMU is
//!
//! A zip archive ([`package`]) holding
//!
//! ```text
//! modelDescription.xml                  the variables below, units, GUID (description.rs)
//! binaries/linux64/<modelIdentifier>.so the FMU binary: the `jointrom-fmu` crate (fmu/)
//! resources/rom.json                    the exported reduced model (jointrom-rom v1)
//! ```
//!
//! The binary is the same for every reduced model: it reads `resources/rom.json` at
//! `fmi2Instantiate` and integrates it with jointrom's own engine — the mechanical ODE of
//! [`crate::integrate::mechanical`] (penalty contact, viscoplastic slip memory) under CVODE with
//! the options of `jointrom transient` — through [`crate::integrate::Stepper`]. With the default
//! inputs and parameters and a communication step equal to the transient's output step it
//! returns the `transient --model file:rom.json` curves bit for bit (see the stepper's docs for
//! why no stop time is set).
//!
//! ## Variables
//!
//! [`VARIABLES`] is the one table both sides use: the model description is written from it and
//! the binary answers `fmi2GetReal`/`fmi2SetReal` by its value references ([`vr`]).
//!
//! | name | causality | variability | unit | meaning |
//! |---|---|---|---|---|
//! | `master_fx`, `master_fy`, `master_fz` | input | continuous | N | master-node force added to the model's load |
//! | `master_mx`, `master_my`, `master_mz` | input | continuous | N·mm | master-node moment added to the model's load |
//! | `load_scale` | parameter | tunable | 1 | factor on the model's own load history (start 1) |
//! | `mu` | parameter | fixed | 1 | friction coefficient μ (start: the ROM's) |
//! | `k_n` | parameter | fixed | N/mm | normal penalty stiffness (start: the ROM's) |
//! | `k_t` | parameter | fixed | N/mm | stick stiffness (start: the ROM's) |
//! | `master_ux`, `master_uy`, `master_uz` | output | continuous | mm | master-node displacement |
//! | `master_rx`, `master_ry`, `master_rz` | output | continuous | rad | master-node rotation |
//! | `contact_force_norm` | output | continuous | N | ‖f_c‖, Euclidean norm of all pair normal forces |
//! | `friction_force_norm` | output | continuous | N | ‖f_R‖, Euclidean norm of all tangential pair forces |
//!
//! The load the binary applies is `f(t) = load_scale · f_ROM(t) + Φ_mᵀ [fx, fy, fz, mx, my, mz]`
//! with the inputs held over each communication step; the outputs are computed as the
//! `transient` JSON curves of the same names ([`crate::integrate::EnergySample`]). Outputs do
//! not depend directly on the inputs (the load enters the accelerations only): the model
//! structure declares no direct feed-through.
//!
//! ## GUID
//!
//! The GUID is derived from the content of `resources/rom.json` ([`guid`]: SHA-256 of an
//! interface tag and the bytes, shown as a UUID), so the binary checks at instantiation that
//! the model description and the reduced model it finds belong together — an edited or
//! corrupted `rom.json` is refused with a message rather than simulated.

pub mod description;
pub mod package;

use sha2::{Digest, Sha256};

use crate::rom::file::RomFile;

pub use description::model_description;
pub use package::{write_fmu, FmuPackage};

/// The file name of the FMU binary cargo builds (`cargo build --release -p jointrom-fmu`).
pub const BINARY_FILE: &str = "libjointrom_fmu.so";

/// The environment variable that names the FMU binary explicitly (else `jointrom export`
/// looks beside its own executable).
pub const BINARY_ENV: &str = "JOINTROM_FMU_BINARY";

/// Where the FMU keeps the reduced model, relative to the archive's root.
pub const ROM_RESOURCE: &str = "resources/rom.json";

/// The FMI platform folder of the binary (the only platform built).
pub const PLATFORM: &str = "linux64";

/// Tag hashed with the reduced model into the GUID: changes with the variables' interface.
const INTERFACE_TAG: &[u8] = b"jointrom-fmu interface 1\0";

/// Causality of a variable (FMI 2.0 `causality`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Causality {
    /// Set by the importer between steps.
    Input,
    /// Computed by the FMU.
    Output,
    /// Set by the importer before (fixed) or also between steps (tunable).
    Parameter,
}

/// Variability of a variable (FMI 2.0 `variability`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Variability {
    /// Fixed after initialization.
    Fixed,
    /// May change between steps (a parameter: at communication points only).
    Tunable,
    /// Changes continuously in time.
    Continuous,
}

/// Where a parameter's start value comes from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Start {
    /// No start value (outputs: computed).
    None,
    /// A constant.
    Value(f64),
    /// The reduced model's friction coefficient μ.
    Mu,
    /// The reduced model's normal stiffness k_n, N/mm.
    NormalStiffness,
    /// The reduced model's stick stiffness k_t, N/mm.
    StickStiffness,
}

/// One scalar variable of the FMU (all are `Real`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Variable {
    /// Its name (the contract with importers).
    pub name: &'static str,
    /// Its value reference.
    pub vr: u32,
    /// Causality.
    pub causality: Causality,
    /// Variability.
    pub variability: Variability,
    /// Unit name (one of [`UNITS`]), or `None` for a dimensionless value.
    pub unit: Option<&'static str>,
    /// Start value.
    pub start: Start,
    /// Its description in the model description.
    pub description: &'static str,
}

/// The value references of [`VARIABLES`], by name.
pub mod vr {
    /// Master-node force along x, N (input).
    pub const MASTER_FX: u32 = 0;
    /// Master-node force along y, N (input).
    pub const MASTER_FY: u32 = 1;
    /// Master-node force along z, N (input).
    pub const MASTER_FZ: u32 = 2;
    /// Master-node moment about x, N·mm (input).
    pub const MASTER_MX: u32 = 3;
    /// Master-node moment about y, N·mm (input).
    pub const MASTER_MY: u32 = 4;
    /// Master-node moment about z, N·mm (input).
    pub const MASTER_MZ: u32 = 5;
    /// Factor on the model's own load history (tunable parameter).
    pub const LOAD_SCALE: u32 = 6;
    /// Friction coefficient μ (fixed parameter).
    pub const MU: u32 = 7;
    /// Normal penalty stiffness k_n, N/mm (fixed parameter).
    pub const K_N: u32 = 8;
    /// Stick stiffness k_t, N/mm (fixed parameter).
    pub const K_T: u32 = 9;
    /// Master u_x, mm (output; the six master outputs are consecutive).
    pub const MASTER_UX: u32 = 10;
    /// Master u_y, mm (output).
    pub const MASTER_UY: u32 = 11;
    /// Master u_z, mm (output).
    pub const MASTER_UZ: u32 = 12;
    /// Master r_x, rad (output).
    pub const MASTER_RX: u32 = 13;
    /// Master r_y, rad (output).
    pub const MASTER_RY: u32 = 14;
    /// Master r_z, rad (output).
    pub const MASTER_RZ: u32 = 15;
    /// ‖f_c‖, N (output).
    pub const CONTACT_FORCE_NORM: u32 = 16;
    /// ‖f_R‖, N (output).
    pub const FRICTION_FORCE_NORM: u32 = 17;
    /// Number of variables; value references are `0..COUNT`, the index in
    /// [`super::VARIABLES`].
    pub const COUNT: u32 = 18;
}

const fn input(
    name: &'static str,
    vr: u32,
    unit: &'static str,
    description: &'static str,
) -> Variable {
    Variable {
        name,
        vr,
        causality: Causality::Input,
        variability: Variability::Continuous,
        unit: Some(unit),
        start: Start::Value(0.0),
        description,
    }
}

const fn output(
    name: &'static str,
    vr: u32,
    unit: &'static str,
    description: &'static str,
) -> Variable {
    Variable {
        name,
        vr,
        causality: Causality::Output,
        variability: Variability::Continuous,
        unit: Some(unit),
        start: Start::None,
        description,
    }
}

/// Every variable of the FMU, in value-reference order (see the module docs' table).
pub const VARIABLES: [Variable; vr::COUNT as usize] = [
    input(
        "master_fx",
        vr::MASTER_FX,
        "N",
        "Master-node force x added to the model's load",
    ),
    input(
        "master_fy",
        vr::MASTER_FY,
        "N",
        "Master-node force y added to the model's load",
    ),
    input(
        "master_fz",
        vr::MASTER_FZ,
        "N",
        "Master-node force z added to the model's load",
    ),
    input(
        "master_mx",
        vr::MASTER_MX,
        "N.mm",
        "Master-node moment x added to the model's load",
    ),
    input(
        "master_my",
        vr::MASTER_MY,
        "N.mm",
        "Master-node moment y added to the model's load",
    ),
    input(
        "master_mz",
        vr::MASTER_MZ,
        "N.mm",
        "Master-node moment z added to the model's load",
    ),
    Variable {
        name: "load_scale",
        vr: vr::LOAD_SCALE,
        causality: Causality::Parameter,
        variability: Variability::Tunable,
        unit: None,
        start: Start::Value(1.0),
        description: "Factor on the reduced model's own load history",
    },
    Variable {
        name: "mu",
        vr: vr::MU,
        causality: Causality::Parameter,
        variability: Variability::Fixed,
        unit: None,
        start: Start::Mu,
        description: "Friction coefficient (>= 0)",
    },
    Variable {
        name: "k_n",
        vr: vr::K_N,
        causality: Causality::Parameter,
        variability: Variability::Fixed,
        unit: Some("N/mm"),
        start: Start::NormalStiffness,
        description: "Normal penalty stiffness of a closed pair (> 0)",
    },
    Variable {
        name: "k_t",
        vr: vr::K_T,
        causality: Causality::Parameter,
        variability: Variability::Fixed,
        unit: Some("N/mm"),
        start: Start::StickStiffness,
        description: "Tangential stick stiffness of a closed pair (> 0)",
    },
    output(
        "master_ux",
        vr::MASTER_UX,
        "mm",
        "Master-node displacement x",
    ),
    output(
        "master_uy",
        vr::MASTER_UY,
        "mm",
        "Master-node displacement y",
    ),
    output(
        "master_uz",
        vr::MASTER_UZ,
        "mm",
        "Master-node displacement z",
    ),
    output("master_rx", vr::MASTER_RX, "rad", "Master-node rotation x"),
    output("master_ry", vr::MASTER_RY, "rad", "Master-node rotation y"),
    output("master_rz", vr::MASTER_RZ, "rad", "Master-node rotation z"),
    output(
        "contact_force_norm",
        vr::CONTACT_FORCE_NORM,
        "N",
        "Euclidean norm of all pair normal forces",
    ),
    output(
        "friction_force_norm",
        vr::FRICTION_FORCE_NORM,
        "N",
        "Euclidean norm of all tangential pair forces",
    ),
];

/// The units the variables use: `(name, SI exponents kg, m, s, rad, factor)` with
/// `value_SI = factor · value` (FMI 2.0 `BaseUnit`).
pub const UNITS: [(&str, [i32; 4], f64); 5] = [
    ("N", [1, 1, -2, 0], 1.0),
    ("N.mm", [1, 2, -2, 0], 1e-3),
    ("N/mm", [1, 0, -2, 0], 1e3),
    ("mm", [0, 1, 0, 0], 1e-3),
    ("rad", [0, 0, 0, 1], 1.0),
];

impl Variable {
    /// The start value for the reduced model `rom` (`None` for outputs).
    pub fn start_value(&self, rom: &RomFile) -> Option<f64> {
        match self.start {
            Start::None => None,
            Start::Value(v) => Some(v),
            Start::Mu => Some(rom.contact.friction_coefficient),
            Start::NormalStiffness => Some(rom.contact.normal_stiffness),
            Start::StickStiffness => Some(rom.contact.stick_stiffness),
        }
    }
}

/// The variable with value reference `vr`, if any.
pub fn variable(vr: u32) -> Option<&'static Variable> {
    VARIABLES.get(vr as usize)
}

/// The GUID of an FMU whose `resources/rom.json` holds `rom_json`: the first 16 bytes of
/// SHA-256(interface tag ‖ rom_json) as a UUID-shaped string `{8-4-4-4-12}`.
pub fn guid(rom_json: &[u8]) -> String {
    let mut h = Sha256::new();
    h.update(INTERFACE_TAG);
    h.update(rom_json);
    let d = h.finalize();
    let hex: String = d[..16].iter().map(|b| format!("{b:02x}")).collect();
    format!(
        "{{{}-{}-{}-{}-{}}}",
        &hex[0..8],
        &hex[8..12],
        &hex[12..16],
        &hex[16..20],
        &hex[20..32]
    )
}

/// The model identifier of the FMU of the case `case`: `jointrom_` and the case name with
/// every character outside `[A-Za-z0-9_]` replaced by `_`, cut to 64 characters — a C
/// identifier and a file name on every platform.
pub fn model_identifier(case: &str) -> String {
    let mut id = String::from("jointrom_");
    id.extend(case.chars().map(|c| {
        if c.is_ascii_alphanumeric() || c == '_' {
            c
        } else {
            '_'
        }
    }));
    id.truncate(64);
    id
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn value_references_are_the_indices_and_names_are_unique() {
        for (i, v) in VARIABLES.iter().enumerate() {
            assert_eq!(v.vr as usize, i, "{}", v.name);
            assert_eq!(variable(v.vr), Some(v));
            if let Some(u) = v.unit {
                assert!(UNITS.iter().any(|(n, _, _)| *n == u), "unit {u}");
            }
        }
        let mut names: Vec<_> = VARIABLES.iter().map(|v| v.name).collect();
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), VARIABLES.len());
        assert_eq!(variable(vr::COUNT), None);
        assert_eq!(VARIABLES[vr::MASTER_UY as usize].name, "master_uy");
        assert_eq!(
            VARIABLES[vr::FRICTION_FORCE_NORM as usize].name,
            "friction_force_norm"
        );
    }

    #[test]
    fn guid_depends_on_every_byte_and_has_the_uuid_shape() {
        let a = guid(b"{\"x\": 1}");
        assert_eq!(a, guid(b"{\"x\": 1}"));
        assert_ne!(a, guid(b"{\"x\": 2}"));
        assert_eq!(a.len(), 38);
        let parts: Vec<usize> = a[1..37].split('-').map(str::len).collect();
        assert_eq!(parts, [8, 4, 4, 4, 12]);
    }

    #[test]
    fn model_identifiers_are_c_identifiers() {
        assert_eq!(model_identifier("friction_bar"), "jointrom_friction_bar");
        assert_eq!(model_identifier("my case/../x"), "jointrom_my_case____x");
        assert_eq!(model_identifier(&"é".repeat(100)).len(), 64);
    }
}
