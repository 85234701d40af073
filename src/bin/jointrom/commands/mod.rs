//! One module per subcommand: its flags (`…Args`) and `run`. Commands use the shared modules
//! ([`crate::args`], [`crate::common`]) and the library, never each other or [`crate::cli`].

pub mod backbone;
pub mod basis;
pub mod distributed;
pub mod export;
pub mod export_matrices;
pub mod info;
pub mod modes;
pub mod run;
pub mod shapes;
pub mod stability;
pub mod statics;
pub mod study;
pub mod sweep;
pub mod transient;
