//! Flag values only the command line has (the library's value enums — basis kinds, iterations,
//! interfaces, map models — live with the types they parse into).

use clap::ValueEnum;

/// A switch: `on` or `off`.
#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum OnOff {
    #[value(name = "on")]
    On,
    #[value(name = "off")]
    Off,
}

impl OnOff {
    pub fn is_on(self) -> bool {
        self == OnOff::On
    }

    pub fn name(self) -> &'static str {
        match self {
            OnOff::On => "on",
            OnOff::Off => "off",
        }
    }
}

/// `--compress-joint`: when the tolerance model compresses its joint columns.
#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum CompressArg {
    #[value(name = "auto")]
    Auto,
    #[value(name = "on")]
    On,
    #[value(name = "off")]
    Off,
}

impl CompressArg {
    pub fn mode(self) -> jointrom::rom::CompressJoint {
        use jointrom::rom::CompressJoint;
        match self {
            CompressArg::Auto => CompressJoint::Auto,
            CompressArg::On => CompressJoint::On,
            CompressArg::Off => CompressJoint::Off,
        }
    }
}

/// `--method`: CVODE's BDF (the default) or an ARKODE DIRK method (`--dirk-table`).
#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum MethodKind {
    #[value(name = "bdf")]
    Bdf,
    #[value(name = "dirk")]
    Dirk,
}
