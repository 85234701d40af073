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

/// `--method`: CVODE's BDF (the default) or an ARKODE DIRK method (`--dirk-table`).
#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum MethodKind {
    #[value(name = "bdf")]
    Bdf,
    #[value(name = "dirk")]
    Dirk,
}
