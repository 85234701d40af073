//! `jointrom modes`: lowest eigenfrequencies.

use std::time::Instant;

use clap::Args;
use serde_json::json;

use jointrom::{Error, Interface};

use crate::common::print_json;

#[derive(Args)]
pub struct ModesArgs {
    /// Case file, matrix map (`jointrom-matrices` JSON) or built-in name.
    case: String,
    /// Number of modes.
    #[arg(long, default_value_t = 10)]
    count: usize,
    /// Boundary condition of the master node.
    #[arg(long, value_enum, default_value_t = Interface::Fixed)]
    interface: Interface,
    /// One JSON document on stdout.
    #[arg(long)]
    json: bool,
}

pub fn run(a: ModesArgs) -> Result<(), Error> {
    let model = crate::common::load_model(&a.case)?;
    let iface = a.interface;
    let t0 = Instant::now();
    let modes = model.modes(a.count, iface)?;
    let secs = t0.elapsed().as_secs_f64();
    if a.json {
        print_json(&json!({
            "case": model.name,
            "interface": match iface { Interface::Fixed => "fixed", Interface::Free => "free" },
            "frequencies_hz": modes.frequencies_hz,
            "solve_s": secs,
        }));
    } else {
        println!(
            "{} — {} lowest modes, master {} ({:.1} ms):",
            jointrom::files::printable(&model.name),
            a.count,
            match iface {
                Interface::Fixed => "clamped (fixed interface)",
                Interface::Free => "free",
            },
            secs * 1e3
        );
        for (i, f) in modes.frequencies_hz.iter().enumerate() {
            println!("  {:>3}  {:>12.3} Hz", i + 1, f);
        }
    }
    Ok(())
}
