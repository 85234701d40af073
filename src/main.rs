//! `jointrom` command line: a thin layer over the library.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use clap::{Parser, Subcommand, ValueEnum};
use serde_json::{json, Value};

use jointrom::{contact, Error, Interface, Model};

#[derive(Parser)]
#[command(
    name = "jointrom",
    version,
    about = "Reduced-order transient dynamics of jointed sheet structures (trial vector derivatives)"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Clone, Copy, ValueEnum)]
enum InterfaceArg {
    /// Master node clamped (Craig–Bampton fixed-interface normal modes).
    Fixed,
    /// Master node free (the cantilever's own modes).
    Free,
}

#[derive(Subcommand)]
enum Command {
    /// Model summary: DOF, joint pairs, nodes, elements.
    Info {
        /// Case file path or built-in name (friction_bar, multilayer_sheet).
        case: String,
        /// One JSON document on stdout.
        #[arg(long)]
        json: bool,
    },
    /// Lowest eigenfrequencies (joint open, no contact stiffness).
    Modes {
        /// Case file path or built-in name.
        case: String,
        /// Number of modes.
        #[arg(long, default_value_t = 10)]
        count: usize,
        /// Boundary condition of the master node.
        #[arg(long, value_enum, default_value_t = InterfaceArg::Fixed)]
        interface: InterfaceArg,
        /// One JSON document on stdout.
        #[arg(long)]
        json: bool,
    },
    /// Static response to the case's master load.
    Static {
        /// Case file path or built-in name.
        case: String,
        /// Linear analysis without contact (the joint may interpenetrate); default: full FE
        /// model with frictionless penalty contact in the joint pairs.
        #[arg(long)]
        linear: bool,
        /// Factor on the case's load (e.g. -1 reverses it).
        #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
        scale: f64,
        /// One JSON document on stdout.
        #[arg(long)]
        json: bool,
    },
    /// The main job on a case (default: the friction bar): model, modes, statics, results.json.
    Run {
        /// Case file path or built-in name.
        #[arg(default_value = "friction_bar")]
        case: String,
        /// Output folder (results.json is written there).
        #[arg(long, default_value = "out")]
        out: PathBuf,
        /// One JSON document on stdout.
        #[arg(long)]
        json: bool,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli.command) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("jointrom: error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn info_json(model: &Model) -> Value {
    json!({
        "case": model.case.name,
        "dofs": model.dofs(),
        "joint_pairs": model.mesh.pairs.len(),
        "joint_dofs": model.joint_dofs(),
        "nodes": model.mesh.nodes.len(),
        "elements": model.mesh.shells.len() + model.mesh.beams.len(),
        "shells": model.mesh.shells.len(),
        "beams": model.mesh.beams.len(),
        "clamped_nodes": model.mesh.clamped.len(),
        "tied_nodes": model.mesh.tie.slaves.len(),
        "stiffness_nonzeros": model.stiffness.values.len(),
    })
}

fn print_json(v: &Value) {
    println!(
        "{}",
        serde_json::to_string_pretty(v).expect("JSON values serialise")
    );
}

fn static_json(model: &Model, scale: f64) -> Result<Value, Error> {
    let load = model.case.master_load().map(|v| v * scale);
    let sol = model.static_linear(&[load])?.remove(0);
    Ok(json!({
        "case": model.case.name,
        "linear": true,
        "load": load,
        "master_displacement": sol.master_displacement,
    }))
}

fn contact_json(model: &Model, scale: f64) -> Result<Value, Error> {
    let load = model.case.master_load().map(|v| v * scale);
    let sol = contact::contact_static_full(model, load, &contact::ContactOptions::default())?;
    Ok(json!({
        "case": model.case.name,
        "linear": false,
        "load": load,
        "master_displacement": sol.master_displacement,
        "contact_force_norm": sol.state.contact_force_norm,
        "pairs_in_contact": sol.state.pairs_in_contact,
        "iterations": sol.state.iterations,
    }))
}

fn run(command: Command) -> Result<(), Error> {
    match command {
        Command::Info { case, json } => {
            let model = Model::from_case_name(&case)?;
            let v = info_json(&model);
            if json {
                print_json(&v);
            } else {
                println!("case            {}", model.case.name);
                println!("DOF             {}", model.dofs());
                println!("joint pairs     {}", model.mesh.pairs.len());
                println!("joint DOF       {}", model.joint_dofs());
                println!("nodes           {}", model.mesh.nodes.len());
                println!(
                    "elements        {} ({} Shell4, {} Beam2)",
                    model.mesh.shells.len() + model.mesh.beams.len(),
                    model.mesh.shells.len(),
                    model.mesh.beams.len()
                );
            }
        }
        Command::Modes {
            case,
            count,
            interface,
            json,
        } => {
            let model = Model::from_case_name(&case)?;
            let iface = match interface {
                InterfaceArg::Fixed => Interface::Fixed,
                InterfaceArg::Free => Interface::Free,
            };
            let t0 = Instant::now();
            let modes = model.modes(count, iface)?;
            let secs = t0.elapsed().as_secs_f64();
            if json {
                print_json(&json!({
                    "case": model.case.name,
                    "interface": match iface { Interface::Fixed => "fixed", Interface::Free => "free" },
                    "frequencies_hz": modes.frequencies_hz,
                    "solve_s": secs,
                }));
            } else {
                println!(
                    "{} — {} lowest modes, master {} ({:.1} ms):",
                    model.case.name,
                    count,
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
        }
        Command::Static {
            case,
            linear,
            scale,
            json,
        } => {
            if !scale.is_finite() {
                return Err(Error::Invalid(format!(
                    "--scale must be finite, got {scale}"
                )));
            }
            let model = Model::from_case_name(&case)?;
            let v = if linear {
                static_json(&model, scale)?
            } else {
                contact_json(&model, scale)?
            };
            if json {
                print_json(&v);
            } else {
                let u = &v["master_displacement"];
                let kind = if linear {
                    "linear"
                } else {
                    "with contact (frictionless)"
                };
                println!("{} — static {kind}, load × {scale}:", model.case.name);
                for (k, name) in ["ux", "uy", "uz", "rx", "ry", "rz"].iter().enumerate() {
                    let unit = if k < 3 { "mm" } else { "rad" };
                    println!(
                        "  {name} = {:>14.6e} {unit}",
                        u[k].as_f64().unwrap_or(f64::NAN)
                    );
                }
                if !linear {
                    println!(
                        "  ‖f_c‖ = {:.6} N, {} of {} pairs in contact",
                        v["contact_force_norm"].as_f64().unwrap_or(f64::NAN),
                        v["pairs_in_contact"],
                        model.mesh.pairs.len()
                    );
                }
            }
        }
        Command::Run { case, out, json } => {
            let t0 = Instant::now();
            let model = Model::from_case_name(&case)?;
            let t_assembly = t0.elapsed().as_secs_f64();
            let t1 = Instant::now();
            let fixed = model.modes(10, Interface::Fixed)?;
            let free = model.modes(10, Interface::Free)?;
            let t_modes = t1.elapsed().as_secs_f64();
            let statics = static_json(&model, 1.0)?;
            let result = json!({
                "info": info_json(&model),
                "fixed_interface_frequencies_hz": fixed.frequencies_hz,
                "free_interface_frequencies_hz": free.frequencies_hz,
                "linear_static": statics,
                "timing_s": {"assembly": t_assembly, "modes": t_modes},
            });
            let dir = out.join(&model.case.name);
            std::fs::create_dir_all(&dir).map_err(|e| Error::Io {
                file: dir.clone(),
                source: e,
            })?;
            let file = dir.join("results.json");
            std::fs::write(
                &file,
                serde_json::to_string_pretty(&result).expect("JSON values serialise"),
            )
            .map_err(|e| Error::Io {
                file: file.clone(),
                source: e,
            })?;
            if json {
                print_json(&result);
            } else {
                println!(
                    "{}: {} DOF, {} joint pairs ({} joint DOF); assembly {:.1} ms, 20 modes {:.1} ms",
                    model.case.name,
                    model.dofs(),
                    model.mesh.pairs.len(),
                    model.joint_dofs(),
                    t_assembly * 1e3,
                    t_modes * 1e3
                );
                println!("fixed-interface modes (Hz):");
                for (i, f) in fixed.frequencies_hz.iter().enumerate() {
                    println!(
                        "  {:>3}  {:>10.2}   free: {:>10.2}",
                        i + 1,
                        f,
                        free.frequencies_hz[i]
                    );
                }
                let u = &statics["master_displacement"];
                println!(
                    "linear static master displacement: uy = {:.5e} mm, rx = {:.5e} rad",
                    u[1].as_f64().unwrap_or(f64::NAN),
                    u[3].as_f64().unwrap_or(f64::NAN)
                );
                println!("results written to {}", file.display());
            }
        }
    }
    Ok(())
}
