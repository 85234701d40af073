//! One module per subcommand: its flags (`…Args`) and `run`.

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

use jointrom::Error;

use crate::cli::Command;

/// Runs one subcommand.
pub fn run(command: Command) -> Result<(), Error> {
    match command {
        Command::Info(a) => info::run(a),
        Command::Modes(a) => modes::run(a),
        Command::Static(a) => statics::run(a),
        Command::Basis(a) => basis::run(a),
        Command::Study(a) => study::run(a),
        Command::Stability(a) => stability::run(a),
        Command::Transient(a) => transient::run(a),
        Command::Shapes(a) => shapes::run(a),
        Command::Sweep(a) => sweep::run(a),
        Command::Export(a) => export::run(a),
        Command::ExportMatrices(a) => export_matrices::run(a),
        Command::Run(a) => run::run(a),
        Command::Distributed(a) => distributed::run(a),
    }
}
