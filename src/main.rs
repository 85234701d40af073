//! `jointrom` command line: a thin layer over the library.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use clap::{Parser, Subcommand, ValueEnum};
use serde_json::{json, Value};

use jointrom::integrate::mechanical::{self as transient, TransientOptions};
use jointrom::integrate::problem::{Iteration, NewtonLinear};
use jointrom::joint::statics as contact;
use jointrom::reduction::rom_file as export;
use jointrom::reduction::{build_basis, snapshot_basis, BasisKind, BasisOptions, ReducedModel};
use jointrom::report::main_job as report;
use jointrom::studies::convergence as study;
use jointrom::system::{FullSystem, ReducedSystem};
use jointrom::{Error, Interface, Model};

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
        /// Case file, matrix map (`jointrom-matrices` JSON) or built-in name (friction_bar, multilayer_sheet).
        case: String,
        /// One JSON document on stdout.
        #[arg(long)]
        json: bool,
    },
    /// Lowest eigenfrequencies (joint open, no contact stiffness).
    Modes {
        /// Case file, matrix map (`jointrom-matrices` JSON) or built-in name.
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
        /// Case file, matrix map (`jointrom-matrices` JSON) or built-in name.
        case: String,
        /// Linear analysis without contact (the joint may interpenetrate); default: full FE
        /// model with frictionless penalty contact in the joint pairs.
        #[arg(long)]
        linear: bool,
        /// Factor on the case's load (e.g. -1 reverses it).
        #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
        scale: f64,
        /// Solve the reduced model on this basis instead of the full FE model: tvd, tvd-plain,
        /// modes, ... (see `jointrom::studies::convergence::BASIS_KINDS`).
        #[arg(long)]
        basis: Option<String>,
        /// Enrichment vectors of the basis (joint modes; extra modes for `modes`); default: the
        /// smallest g with w(g) >= 0.999. Larger than available is an error.
        #[arg(long)]
        g: Option<usize>,
        /// Fixed-interface modes ν of the basis.
        #[arg(long, default_value_t = 10)]
        nu: usize,
        /// One JSON document on stdout.
        #[arg(long)]
        json: bool,
    },
    /// The TVD basis (Algorithm 2): POD energy ratios w(g), chosen g, sizes, build time.
    Basis {
        /// Case file, matrix map (`jointrom-matrices` JSON) or built-in name.
        case: String,
        /// tvd (K-weighted POD) or tvd-plain (plain POD).
        #[arg(long, default_value = "tvd")]
        kind: String,
        /// Number of joint modes; default: the smallest g with w(g) >= --threshold.
        #[arg(long)]
        g: Option<usize>,
        /// Energy threshold for choosing g (eq. 26).
        #[arg(long, default_value_t = jointrom::reduction::DEFAULT_THRESHOLD)]
        threshold: f64,
        /// Fixed-interface modes ν.
        #[arg(long, default_value_t = 10)]
        nu: usize,
        /// One JSON document on stdout.
        #[arg(long)]
        json: bool,
    },
    /// Static convergence study: ‖f_c‖ of each reduced basis against the number of added
    /// vectors g, w(g); writes OUT/CASE/study.json and SVG/PNG charts.
    Study {
        /// Case file, matrix map (`jointrom-matrices` JSON) or built-in name.
        case: String,
        /// Output folder.
        #[arg(long, default_value = "out")]
        out: PathBuf,
        /// Largest number of added vectors g.
        #[arg(long, default_value_t = 60)]
        max_g: usize,
        /// Fixed-interface modes ν.
        #[arg(long, default_value_t = 10)]
        nu: usize,
        /// Factor on the case's load.
        #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
        scale: f64,
        /// Skip the charts (JSON only).
        #[arg(long)]
        no_charts: bool,
        /// Print study.json on stdout too.
        #[arg(long)]
        json: bool,
    },
    /// Stability map of the transient methods: model × iteration × k_n × friction × events ×
    /// max order → status (ok or the CVODE flag and time reached), cost, error; writes
    /// OUT/CASE/stability.json, stability.md and heat maps (SVG/PNG).
    Stability(jointrom::studies::stability::StabilityArgs),

    /// Transient run from rest (CVODE): contact force norm, friction force norm and master uy
    /// over time, solver statistics and wall time.
    Transient {
        /// Case file, matrix map (`jointrom-matrices` JSON) or built-in name.
        case: String,
        /// full (FE model) or a reduced basis: tvd, tvd-plain, modes, jim, alldof, pod (POD of
        /// the displacement snapshots of a full-FE training run, paper Section 5.2), or
        /// file:PATH (a reduced model written by `jointrom export`; CASE is still loaded).
        #[arg(long, default_value = "tvd")]
        model: String,
        /// Enrichment vectors of the basis; default: the smallest g with w(g) >= 0.999.
        #[arg(long)]
        g: Option<usize>,
        /// `--model pod`: end of the full-FE training run, s (default: the run's end time).
        #[arg(long)]
        train_end: Option<f64>,
        /// `--model pod`: about this many snapshots kept from the training run (every k-th output,
        /// k = outputs / N).
        #[arg(long, default_value_t = 200)]
        snapshots: usize,
        /// Fixed-interface modes ν of the basis.
        #[arg(long, default_value_t = 10)]
        nu: usize,
        /// Nonlinear iteration: newton (structured solve) or functional (fixed point).
        #[arg(long, default_value = "newton")]
        iteration: String,
        /// Friction on or off.
        #[arg(long, default_value = "on")]
        friction: String,
        /// Event location on gaps and stick/slip switches, on or off.
        #[arg(long, default_value = "off")]
        events: String,
        /// Relative tolerance.
        #[arg(long)]
        rtol: Option<f64>,
        /// Absolute tolerance, mm of the physical displacement field.
        #[arg(long)]
        atol: Option<f64>,
        /// Velocity tolerance per displacement tolerance, 1/s.
        #[arg(long)]
        velocity_scale: Option<f64>,
        /// Maximum BDF order (1–5).
        #[arg(long)]
        max_order: Option<usize>,
        /// BDF stability-limit detection, on or off.
        #[arg(long)]
        stab_lim_det: Option<String>,
        /// End time, s (default: the case's).
        #[arg(long)]
        end_time: Option<f64>,
        /// Output spacing, s.
        #[arg(long, default_value_t = 1e-4)]
        output_step: f64,
        /// One JSON document on stdout (with the curves).
        #[arg(long)]
        json: bool,
        /// Write curves.csv and transient.json into this folder.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Write the displacement field over time as VTU files plus a `.pvd` collection
        /// (ParaView plays it) into this folder: DIR/u_NNNN.vtu, DIR/u.pvd. Reduced runs are
        /// expanded with their basis, u = Φ q.
        #[arg(long)]
        vtu: Option<PathBuf>,
        /// `--vtu`: about this many frames (every k-th output, k = outputs / N).
        #[arg(long, default_value_t = 100)]
        vtu_frames: usize,
    },
    /// Writes the Craig–Bampton vectors, the first TVD and joint modes as VTU (ParaView) and a
    /// picture of the first joint modes (PNG + SVG) → DIR/CASE/.
    Shapes {
        /// Case file, matrix map (`jointrom-matrices` JSON) or built-in name.
        case: String,
        /// Output folder.
        #[arg(long, default_value = "out")]
        out: PathBuf,
        /// TVD and joint modes written.
        #[arg(long, default_value_t = 12)]
        count: usize,
        /// Fixed-interface modes ν.
        #[arg(long, default_value_t = 10)]
        nu: usize,
    },
    /// Runs a list of variants (load factor, μ, k_n, k_t) of one reduced model in parallel,
    /// sharing the basis → a table (or JSON with every run's curves).
    Sweep {
        /// Case file, matrix map (`jointrom-matrices` JSON) or built-in name.
        case: String,
        /// The variant file (`{"variants": [{"name", "load_scale", "friction_coefficient",
        /// "normal_stiffness", "stick_stiffness"}, ...]}`).
        #[arg(long)]
        variants: PathBuf,
        /// Basis kind: tvd, tvd-plain, modes, jim, alldof.
        #[arg(long, default_value = "tvd")]
        basis: String,
        /// Enrichment vectors g; default: the smallest g with w(g) >= 0.999.
        #[arg(long)]
        g: Option<usize>,
        /// End time, s (default: the case's).
        #[arg(long)]
        end_time: Option<f64>,
        /// Run the variants one after the other.
        #[arg(long)]
        sequential: bool,
        /// One JSON document on stdout (with the curves).
        #[arg(long)]
        json: bool,
    },
    /// Writes a reduced model as a versioned JSON file (schema `jointrom-rom` v1: M̃, K̃, BΦ,
    /// master rows, reduced loads, contact law, load ramp; see `jointrom::reduction::rom_file`).
    Export {
        /// Case file, matrix map (`jointrom-matrices` JSON) or built-in name.
        case: String,
        /// Basis kind: tvd, tvd-plain, modes, jim, alldof.
        #[arg(long, default_value = "tvd")]
        basis: String,
        /// Enrichment vectors g; default: the smallest g with w(g) >= 0.999.
        #[arg(long)]
        g: Option<usize>,
        /// Fixed-interface modes ν.
        #[arg(long, default_value_t = 10)]
        nu: usize,
        /// Output file.
        #[arg(long)]
        out: PathBuf,
    },
    /// Writes a model's K and M as MatrixMarket files plus the JSON map (`K.mtx`, `M.mtx`,
    /// `model.json`; see `jointrom::model::matrices`): the format a user's own model comes in. Any
    /// command takes `DIR/model.json` where it takes a case.
    ExportMatrices {
        /// Case file, matrix map or built-in name.
        case: String,
        /// Output folder.
        #[arg(long)]
        out: PathBuf,
        /// One JSON document on stdout.
        #[arg(long)]
        json: bool,
    },
    /// The main job on a case (default: the friction bar): static study, full FE and reduced
    /// transients, speed against accuracy → DIR/CASE/report.md, charts, results.json.
    Run {
        /// Case file, matrix map (`jointrom-matrices` JSON) or built-in name.
        #[arg(default_value = "friction_bar")]
        case: String,
        /// Output folder (the report is written to DIR/CASE).
        #[arg(long, default_value = "out")]
        out: PathBuf,
        /// Short variant: 0.02 s window, study g ≤ 20 (well under 20 s).
        #[arg(long)]
        quick: bool,
        /// Folder of stored stability maps copied into the report.
        #[arg(long, default_value = "results/stability")]
        stability_dir: PathBuf,
        /// One JSON document on stdout (results.json).
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
        "case": model.name,
        "dofs": model.dofs(),
        "joint_pairs": model.pair_count(),
        "joint_dofs": model.joint_dofs(),
        "origin": match model.origin {
            jointrom::model::Origin::Case { .. } => "case",
            jointrom::model::Origin::Matrices { .. } => "matrices",
        },
        "nodes": model.geometry.nodes.len(),
        "elements": model.geometry.cells.len(),
        "shells": cell_count(model, true),
        "beams": cell_count(model, false),
        "clamped_nodes": model
            .dof_map
            .nodes
            .iter()
            .filter(|d| d.iter().all(|c| c.terms().next().is_none()))
            .count(),
        "tied_nodes": model.geometry.followers.len(),
        "stiffness_nonzeros": model.stiffness.values.len(),
    })
}

/// Number of 4-node (`quads`) or 2-node display cells.
fn cell_count(model: &Model, quads: bool) -> usize {
    use jointrom::model::CellNodes;
    model
        .geometry
        .cells
        .iter()
        .filter(|c| matches!(c.nodes, CellNodes::Quad4(_)) == quads)
        .count()
}

fn print_json(v: &Value) {
    println!(
        "{}",
        serde_json::to_string_pretty(v).expect("JSON values serialise")
    );
}

fn static_json(model: &Model, scale: f64) -> Result<Value, Error> {
    let load = model.master_load().map(|v| v * scale);
    let sol = model.static_linear(&[load])?.remove(0);
    Ok(json!({
        "case": model.name,
        "linear": true,
        "load": load,
        "master_displacement": sol.master_displacement,
    }))
}

fn contact_json(model: &Model, scale: f64) -> Result<Value, Error> {
    let load = model.master_load().map(|v| v * scale);
    let sol =
        jointrom::model::contact_static_full(model, load, &contact::ContactOptions::default())?;
    Ok(json!({
        "case": model.name,
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
                println!("case            {}", model.name);
                println!("DOF             {}", model.dofs());
                println!("joint pairs     {}", model.pair_count());
                println!("joint DOF       {}", model.joint_dofs());
                println!("nodes           {}", model.geometry.nodes.len());
                println!(
                    "elements        {} ({} Shell4, {} Beam2)",
                    model.geometry.cells.len(),
                    cell_count(&model, true),
                    cell_count(&model, false)
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
                    "case": model.name,
                    "interface": match iface { Interface::Fixed => "fixed", Interface::Free => "free" },
                    "frequencies_hz": modes.frequencies_hz,
                    "solve_s": secs,
                }));
            } else {
                println!(
                    "{} — {} lowest modes, master {} ({:.1} ms):",
                    model.name,
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
            basis,
            g,
            nu,
            json,
        } => {
            if !scale.is_finite() {
                return Err(Error::Invalid(format!(
                    "--scale must be finite, got {scale}"
                )));
            }
            if basis.is_none() && g.is_some() {
                return Err(Error::Invalid("--g needs --basis".into()));
            }
            if let Some(name) = basis {
                if linear {
                    return Err(Error::Invalid(
                        "--linear and --basis do not combine: --basis solves the reduced contact statics".into(),
                    ));
                }
                let kind = study::parse_basis(&name)?;
                let model = Model::from_case_name(&case)?;
                return reduced_static(&model, kind, g, nu, scale, json);
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
                println!("{} — static {kind}, load × {scale}:", model.name);
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
                        model.pair_count()
                    );
                }
            }
        }
        Command::Basis {
            case,
            kind,
            g,
            threshold,
            nu,
            json,
        } => {
            let kind = study::parse_basis(&kind)
                .map_err(|_| Error::Invalid(format!("--kind {kind:?}: valid: tvd, tvd-plain")))?;
            let model = Model::from_case_name(&case)?;
            let opts = BasisOptions {
                nu,
                g,
                threshold,
                ..BasisOptions::default()
            };
            let b = study::basis_summary(&model, kind, &opts)?;
            if json {
                print_json(&serde_json::to_value(&b).expect("JSON values serialise"));
            } else {
                println!(
                    "{} — {} basis, ν = {}: {} TVD ({} nonzero), g = {} (w = {:.6}, plain w = {:.6}; threshold {}), \
                     basis {} columns ({} dropped), built in {:.1} ms",
                    b.case,
                    b.kind,
                    b.nu,
                    b.tvd_count,
                    b.tvd_nonzero,
                    b.g_chosen,
                    b.w.get(b.g_chosen.wrapping_sub(1)).copied().unwrap_or(0.0),
                    b.w_plain.get(b.g_chosen.wrapping_sub(1)).copied().unwrap_or(0.0),
                    b.threshold,
                    b.basis_size,
                    b.dropped,
                    b.build_s * 1e3
                );
                println!("    g   w(g) K-weighted   w(g) plain");
                for i in 0..b.w.len().min(60) {
                    println!("  {:>3}   {:.8}        {:.8}", i + 1, b.w[i], b.w_plain[i]);
                }
            }
        }
        Command::Stability(args) => {
            let v = jointrom::studies::stability::stability_command(&args)?;
            println!(
                "{}",
                serde_json::to_string_pretty(&v)
                    .map_err(|e| Error::Invalid(format!("JSON output: {e}")))?
            );
        }
        Command::Study {
            case,
            out,
            max_g,
            nu,
            scale,
            no_charts,
            json,
        } => {
            let model = Model::from_case_name(&case)?;
            let opts = study::StudyOptions {
                nu,
                max_g,
                scale,
                ..study::StudyOptions::default()
            };
            let s = study::run_study(&model, &opts)?;
            let dir = out.join(&model.name);
            std::fs::create_dir_all(&dir).map_err(|e| Error::Io {
                file: dir.clone(),
                source: e,
            })?;
            let t0 = Instant::now();
            let charts = if no_charts {
                Vec::new()
            } else {
                study::write_charts(&s, &dir)?
            };
            let charts_s = t0.elapsed().as_secs_f64();
            let mut doc = serde_json::to_value(&s).expect("JSON values serialise");
            doc["command_line"] = json!(std::env::args().collect::<Vec<_>>());
            doc["charts"] = json!(charts
                .iter()
                .filter_map(|p| p.file_name().map(|f| f.to_string_lossy().into_owned()))
                .collect::<Vec<_>>());
            doc["charts_s"] = json!(charts_s);
            let file = dir.join("study.json");
            std::fs::write(
                &file,
                serde_json::to_string_pretty(&doc).expect("JSON values serialise"),
            )
            .map_err(|e| Error::Io {
                file: file.clone(),
                source: e,
            })?;
            if json {
                print_json(&doc);
            } else {
                print_study(&s);
                println!("charts {:.2} s; written to {}", charts_s, dir.display());
            }
        }
        Command::Transient {
            case,
            model: model_name,
            g,
            train_end,
            snapshots,
            nu,
            iteration,
            friction,
            events,
            rtol,
            atol,
            velocity_scale,
            max_order,
            stab_lim_det,
            end_time,
            output_step,
            json,
            out,
            vtu,
            vtu_frames,
        } => {
            let args = TransientArgs {
                model: model_name,
                g,
                train_end,
                snapshots,
                nu,
                iteration,
                friction,
                events,
                rtol,
                atol,
                velocity_scale,
                max_order,
                stab_lim_det,
                end_time,
                output_step,
                vtu,
                vtu_frames,
            };
            transient_command(&case, &args, json, out)?;
        }
        Command::Shapes {
            case,
            out,
            count,
            nu,
        } => {
            let model = Model::from_case_name(&case)?;
            let s = jointrom::report::shapes::shapes(&model, nu, count)?;
            let dir = out.join(&model.name);
            for f in jointrom::report::shapes::write_shapes(&model, &s, &dir)? {
                println!("{}", f.display());
            }
        }
        Command::Sweep {
            case,
            variants,
            basis,
            g,
            end_time,
            sequential,
            json,
        } => {
            let model = Model::from_case_name(&case)?;
            let list = jointrom::studies::sweep::read_variants(&variants)?;
            let kind = BasisKind::from_name(&basis)
                .map_err(|e| Error::Invalid(format!("--basis: {e}")))?;
            let t0 = Instant::now();
            let b = build_basis(
                &model,
                kind,
                &BasisOptions {
                    g,
                    ..BasisOptions::default()
                },
            )?;
            let g_used = b.g;
            let rom = ReducedModel::new(&model, b.phi)?;
            let build_s = t0.elapsed().as_secs_f64();
            let mut opts = TransientOptions::default();
            if let Some(t) = end_time {
                opts.end_time = Some(positive("end-time", t)?);
            }
            let res = jointrom::studies::sweep::run_sweep(&model, &rom, &list, &opts, !sequential)?;
            if json {
                print_json(&json!({
                    "case": model.name,
                    "basis": kind.name(),
                    "g": g_used,
                    "basis_size": rom.dim(),
                    "build_s": build_s,
                    "sweep": res,
                }));
            } else {
                println!(
                    "{} — {} basis, g = {g_used}, r = {} (built once, {:.3} s); {} variants on {} threads",
                    model.name,
                    kind.name(),
                    rom.dim(),
                    build_s,
                    res.runs.len(),
                    res.threads
                );
                for r in &res.runs {
                    let last = |v: &[f64]| v.last().copied().unwrap_or(f64::NAN);
                    println!(
                        "  {:<20} {:<6} {:>8.3} s {:>8} steps  final |f_c| {:.4e} N  |f_R| {:.4e} N  uy {:.4e} mm",
                        r.variant.name,
                        if r.status == "ok" { "ok" } else { "failed" },
                        r.wall_s,
                        r.stats.steps,
                        last(&r.curves.contact_force_norm),
                        last(&r.curves.friction_force_norm),
                        last(&r.curves.master_uy)
                    );
                    if r.status != "ok" {
                        println!("    {}", r.status);
                    }
                }
                println!(
                    "sweep wall {:.3} s, sum of runs {:.3} s",
                    res.wall_s, res.sum_wall_s
                );
            }
        }
        Command::ExportMatrices { case, out, json } => {
            let model = Model::from_case_name(&case)?;
            let files = jointrom::model::matrices::write(&model, &out)?;
            if json {
                print_json(&json!({
                    "case": model.name,
                    "dofs": model.dofs(),
                    "joint_pairs": model.pair_count(),
                    "files": files,
                }));
            } else {
                println!(
                    "{}: {} DOF, {} joint pairs → {}",
                    model.name,
                    model.dofs(),
                    model.pair_count(),
                    files
                        .iter()
                        .map(|f| f.display().to_string())
                        .collect::<Vec<_>>()
                        .join(", ")
                );
            }
        }
        Command::Export {
            case,
            basis,
            g,
            nu,
            out,
        } => {
            let model = Model::from_case_name(&case)?;
            let kind = BasisKind::from_name(&basis)
                .map_err(|e| Error::Invalid(format!("--basis: {e}")))?;
            let opts = BasisOptions {
                g,
                nu,
                ..BasisOptions::default()
            };
            let b = build_basis(&model, kind, &opts)?;
            let info = export::BasisInfo {
                kind: kind.name().into(),
                g: b.g,
                nu,
                threshold: opts.threshold,
                w: b.w.clone(),
            };
            let rom = ReducedModel::new(&model, b.phi)?;
            let file = export::RomFile::new(&model, &rom, info)?;
            file.write(&out)?;
            println!(
                "{}: {} basis, g = {}, r = {} → {}",
                model.name,
                kind.name(),
                file.basis.g,
                file.dimension,
                out.display()
            );
        }
        Command::Run {
            case,
            out,
            quick,
            stability_dir,
            json,
        } => {
            let t0 = Instant::now();
            let model = Model::from_case_name(&case)?;
            let t_assembly = t0.elapsed().as_secs_f64();
            let t1 = Instant::now();
            let fixed = model.modes(10, Interface::Fixed)?;
            let free = model.modes(10, Interface::Free)?;
            let t_modes = t1.elapsed().as_secs_f64();
            let statics = static_json(&model, 1.0)?;
            let mut extra = serde_json::Map::new();
            extra.insert("info".into(), info_json(&model));
            extra.insert(
                "fixed_interface_frequencies_hz".into(),
                json!(fixed.frequencies_hz),
            );
            extra.insert(
                "free_interface_frequencies_hz".into(),
                json!(free.frequencies_hz),
            );
            extra.insert("linear_static".into(), statics);
            extra.insert(
                "timing_s".into(),
                json!({"assembly": t_assembly, "modes": t_modes}),
            );
            let dir = out.join(&model.name);
            let opts = report::ReportOptions {
                quick,
                stability_dir,
                ..Default::default()
            };
            let rep = report::run_report(&model, &dir, &opts, extra)?;
            if json {
                print_json(&serde_json::to_value(&rep).expect("the report serialises"));
            } else {
                print_report(&rep, &dir);
            }
        }
    }
    Ok(())
}

fn print_report(rep: &report::Report, dir: &std::path::Path) {
    println!(
        "{} — {} DOF, {} joint pairs; a-priori g = {} (w ≥ {}); window {} s; job {:.1} s",
        rep.case, rep.dofs, rep.pairs, rep.g_chosen, rep.threshold, rep.end_time, rep.total_s
    );
    println!(
        "  {:<10} {:>4} {:>5} {:<10} {:<10} {:>10} {:>10} {:>9} {:>9}",
        "model", "g", "size", "iteration", "status", "err |f_c|", "err uy", "CPU s", "speed-up"
    );
    for r in &rep.runs {
        let e = |v: Option<f64>| v.map_or("-".to_string(), |x| format!("{x:.2e}"));
        println!(
            "  {:<10} {:>4} {:>5} {:<10} {:<10} {:>10} {:>10} {:>9.3} {:>9}",
            r.model,
            r.g.map_or("-".to_string(), |g| g.to_string()),
            r.size,
            r.iteration,
            r.status,
            e(r.error_fc),
            e(r.error_uy),
            r.cpu_s,
            r.speedup.map_or("-".to_string(), |x| format!("{x:.0}x"))
        );
    }
    println!("report: {}", dir.join("report.md").display());
}

fn reduced_static(
    model: &Model,
    kind: BasisKind,
    g: Option<usize>,
    nu: usize,
    scale: f64,
    json: bool,
) -> Result<(), Error> {
    let load = study::scaled_load(model, scale)?;
    let opts = BasisOptions {
        nu,
        g,
        ..BasisOptions::default()
    };
    let r = study::basis_static(model, kind, &opts, scale)?;
    let st = &r.solution.state;
    let v = json!({
        "case": model.name,
        "linear": false,
        "load": load,
        "master_displacement": r.solution.master_displacement,
        "contact_force_norm": st.contact_force_norm,
        "pairs_in_contact": st.pairs_in_contact,
        "iterations": st.iterations,
        "basis": r.basis,
        "g": r.g,
        "basis_size": r.basis_size,
        "restarted": r.restarted,
        "build_s": r.build_s,
        "solve_s": r.solve_s,
    });
    if json {
        print_json(&v);
    } else {
        println!(
            "{} — reduced static with contact (frictionless), basis {} (g = {}, {} columns), load × {scale}:",
            model.name, r.basis, r.g, r.basis_size
        );
        for (k, name) in ["ux", "uy", "uz", "rx", "ry", "rz"].iter().enumerate() {
            let unit = if k < 3 { "mm" } else { "rad" };
            println!(
                "  {name} = {:>14.6e} {unit}",
                r.solution.master_displacement[k]
            );
        }
        println!(
            "  ‖f_c‖ = {:.6} N, {} of {} pairs in contact; basis {:.1} ms, solve {:.1} ms",
            st.contact_force_norm,
            st.pairs_in_contact,
            model.pair_count(),
            r.build_s * 1e3,
            r.solve_s * 1e3
        );
    }
    Ok(())
}

/// Arguments of `jointrom transient` (besides the case and the output switches).
struct TransientArgs {
    model: String,
    g: Option<usize>,
    train_end: Option<f64>,
    snapshots: usize,
    nu: usize,
    iteration: String,
    friction: String,
    events: String,
    rtol: Option<f64>,
    atol: Option<f64>,
    velocity_scale: Option<f64>,
    max_order: Option<usize>,
    stab_lim_det: Option<String>,
    end_time: Option<f64>,
    output_step: f64,
    vtu: Option<PathBuf>,
    vtu_frames: usize,
}

/// Kept states: (time in s, state).
type Frames = Vec<(f64, Vec<f64>)>;

/// A transient run that keeps every `every`-th state (with its time) when `every` is given.
fn run_keeping<S: jointrom::system::SecondOrderSystem>(
    sys: S,
    opts: &TransientOptions,
    every: Option<usize>,
) -> Result<(transient::TransientResult, Frames), Error> {
    let Some(every) = every else {
        return Ok((transient::run(sys, opts)?, Vec::new()));
    };
    let mut frames = Vec::new();
    let mut k = 0usize;
    let res = transient::run_observed(sys, opts, |t, q| {
        if k % every == 0 {
            frames.push((t, q.to_vec()));
        }
        k += 1;
    })?;
    Ok((res, frames))
}

fn on_off(flag: &str, v: &str) -> Result<bool, Error> {
    match v {
        "on" => Ok(true),
        "off" => Ok(false),
        _ => Err(Error::Invalid(format!(
            "--{flag} must be `on` or `off`, got `{v}`"
        ))),
    }
}

fn positive(flag: &str, v: f64) -> Result<f64, Error> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(Error::Invalid(format!(
            "--{flag} must be finite and positive, got {v}"
        )))
    }
}

/// The options of a `transient` run from its flags (errors name the flag).
fn transient_options(a: &TransientArgs) -> Result<TransientOptions, Error> {
    let mut o = TransientOptions::default();
    o.ode.iteration = match a.iteration.as_str() {
        "newton" => Iteration::Newton {
            linear: NewtonLinear::Problem,
        },
        "functional" => Iteration::Functional { anderson: 0 },
        other => {
            return Err(Error::Invalid(format!(
                "--iteration must be `newton` or `functional`, got `{other}`"
            )))
        }
    };
    o.problem.friction = on_off("friction", &a.friction)?;
    o.problem.events = on_off("events", &a.events)?;
    if let Some(r) = a.rtol {
        o.ode.rtol = positive("rtol", r)?;
    }
    if let Some(r) = a.atol {
        o.ode.atol = positive("atol", r)?;
    }
    if let Some(v) = a.velocity_scale {
        o.problem.velocity_scale = positive("velocity-scale", v)?;
    }
    if let Some(k) = a.max_order {
        if !(1..=5).contains(&k) {
            return Err(Error::Invalid(format!(
                "--max-order must be 1..=5 (BDF), got {k}"
            )));
        }
        o.ode.max_order = k;
    }
    if let Some(s) = &a.stab_lim_det {
        o.ode.stab_lim_det = on_off("stab-lim-det", s)?;
    }
    if let Some(t) = a.end_time {
        o.end_time = Some(positive("end-time", t)?);
    }
    o.output_step = positive("output-step", a.output_step)?;
    Ok(o)
}

/// Reduced states `q` (r) to physical DOF `Φ q` (n): one product `Φ [q_1 … q_f]`.
fn expand_frames(rom: &ReducedModel, kept: Frames) -> Frames {
    let q = faer::Mat::from_fn(rom.dim(), kept.len(), |i, j| kept[j].1[i]);
    let u = &rom.phi * &q;
    kept.iter()
        .enumerate()
        .map(|(j, &(t, _))| (t, u.col(j).iter().copied().collect()))
        .collect()
}

fn transient_command(
    case: &str,
    a: &TransientArgs,
    json_out: bool,
    out: Option<PathBuf>,
) -> Result<(), Error> {
    let opts = transient_options(a)?;
    let model = Model::from_case_name(case)?;
    let vtu_every = match &a.vtu {
        None => None,
        Some(_) if a.vtu_frames == 0 => {
            return Err(Error::Invalid("--vtu-frames must be at least 1".into()))
        }
        Some(_) => {
            let end = opts.end_time.unwrap_or(model.end_time);
            let outputs = (end / opts.output_step).ceil().max(1.0) as usize + 1;
            Some((outputs / a.vtu_frames).max(1))
        }
    };
    // Kept states in physical DOF (reduced states are expanded with Φ).
    let mut frames: Frames = Vec::new();
    let t0 = Instant::now();
    let (res, basis_size, g_used, training) = match a.model.as_str() {
        "full" => {
            if a.g.is_some() {
                return Err(Error::Invalid(
                    "--g applies to reduced models, not --model full".into(),
                ));
            }
            if a.train_end.is_some() {
                return Err(Error::Invalid(
                    "--train-end applies to --model pod only".into(),
                ));
            }
            let sys = FullSystem::new(&model)?;
            let (res, kept) = run_keeping(sys, &opts, vtu_every)?;
            frames = kept;
            (res, model.dofs(), None, None)
        }
        "pod" => {
            // Paper Section 5.2: the POD of displacement snapshots of a full-FE run (here over
            // [0, train_end] with the same options), Euclidean, added to Craig–Bampton.
            let train_end = match a.train_end {
                Some(t) => positive("train-end", t)?,
                None => opts.end_time.unwrap_or(model.end_time),
            };
            if a.snapshots < 2 {
                return Err(Error::Invalid(format!(
                    "--snapshots must be at least 2, got {}",
                    a.snapshots
                )));
            }
            let train_opts = TransientOptions {
                end_time: Some(train_end),
                ..opts.clone()
            };
            let outputs = (train_end / opts.output_step).ceil().max(1.0) as usize + 1;
            let every = (outputs / a.snapshots).max(1);
            let mut states: Vec<Vec<f64>> = Vec::new();
            let mut k = 0usize;
            let train = transient::run_observed(FullSystem::new(&model)?, &train_opts, |_, q| {
                if k % every == 0 {
                    states.push(q.to_vec());
                }
                k += 1;
            })?;
            let n = model.dofs();
            let y = faer::Mat::from_fn(n, states.len(), |r, c| states[c][r]);
            let basis = snapshot_basis(
                &model,
                y.as_ref(),
                None,
                &BasisOptions {
                    g: a.g,
                    nu: a.nu,
                    ..Default::default()
                },
            )?;
            let g_used = basis.g;
            let training = json!({
                "end_time": train_end,
                "snapshots": states.len(),
                "wall_s": train.wall_s,
                "cpu_s": train.cpu_s,
                "steps": train.stats.steps,
                "w": basis.w,
            });
            let rom = ReducedModel::new(&model, basis.phi)?;
            let r = rom.dim();
            let sys = ReducedSystem::new(&model, &rom)?;
            let (res, kept) = run_keeping(sys, &opts, vtu_every)?;
            frames = expand_frames(&rom, kept);
            (res, r, Some(g_used), Some(training))
        }
        name if name.starts_with("file:") => {
            // A reduced model exported by `jointrom export` (schema jointrom-rom v1).
            if a.g.is_some() || a.train_end.is_some() {
                return Err(Error::Invalid(
                    "--g and --train-end do not apply to --model file:PATH".into(),
                ));
            }
            if a.vtu.is_some() {
                return Err(Error::Invalid(
                    "--vtu needs the basis Φ, which an exported reduced model does not carry; \
                     run the basis by name instead (e.g. --model tvd)"
                        .into(),
                ));
            }
            let f = export::RomFile::read(std::path::Path::new(&name["file:".len()..]))?;
            let r = f.dimension;
            let g = f.basis.g;
            (transient::run(f.system()?, &opts)?, r, Some(g), None)
        }
        name => {
            if a.train_end.is_some() {
                return Err(Error::Invalid(
                    "--train-end applies to --model pod only".into(),
                ));
            }
            let kind = BasisKind::from_name(name)
                .map_err(|e| Error::Invalid(format!("--model: {e} (or full, pod)")))?;
            let basis = build_basis(
                &model,
                kind,
                &BasisOptions {
                    g: a.g,
                    nu: a.nu,
                    ..Default::default()
                },
            )?;
            let g_used = basis.g;
            let rom = ReducedModel::new(&model, basis.phi)?;
            let r = rom.dim();
            let sys = ReducedSystem::new(&model, &rom)?;
            let (res, kept) = run_keeping(sys, &opts, vtu_every)?;
            frames = expand_frames(&rom, kept);
            (res, r, Some(g_used), None)
        }
    };
    let total_s = t0.elapsed().as_secs_f64();
    let c = &res.curves;
    let doc = json!({
        "case": model.name,
        "model": a.model,
        "basis_size": basis_size,
        "g": g_used,
        "options": opts,
        "stats": res.stats,
        "events": res.events,
        "wall_s": res.wall_s,
        "cpu_s": res.cpu_s,
        "total_s": total_s,
        "curves": c,
        "energy_balance": c.balance(),
        "training": training,
    });
    if let Some(dir) = &a.vtu {
        let (times, states): (Vec<f64>, Vec<Vec<f64>>) = frames.into_iter().unzip();
        let pvd = jointrom::report::vtu::write_series(&model, "u", &times, &states, dir)?;
        eprintln!("{} frames → {}", times.len(), pvd.display());
    }
    if let Some(dir) = out {
        std::fs::create_dir_all(&dir).map_err(|e| Error::Io {
            file: dir.clone(),
            source: e,
        })?;
        let file = dir.join("transient.json");
        std::fs::write(
            &file,
            serde_json::to_string(&doc).expect("JSON values serialise"),
        )
        .map_err(|e| Error::Io {
            file: file.clone(),
            source: e,
        })?;
        let mut csv = String::from(
            "t_s,contact_force_norm_N,friction_force_norm_N,master_uy_mm,kinetic_Nmm,strain_Nmm,pair_Nmm,external_work_Nmm,dissipated_Nmm\n",
        );
        for i in 0..c.t.len() {
            csv.push_str(&format!(
                "{:.8e},{:.10e},{:.10e},{:.10e},{:.10e},{:.10e},{:.10e},{:.10e},{:.10e}\n",
                c.t[i],
                c.contact_force_norm[i],
                c.friction_force_norm[i],
                c.master_uy[i],
                c.kinetic[i],
                c.strain[i],
                c.pair[i],
                c.external_work[i],
                c.dissipated[i]
            ));
        }
        let file = dir.join("curves.csv");
        std::fs::write(&file, csv).map_err(|e| Error::Io {
            file: file.clone(),
            source: e,
        })?;
    }
    if json_out {
        print_json(&doc);
    } else {
        let s = &res.stats;
        println!(
            "{} — model {} (n = {}{}), friction {}, events {}",
            model.name,
            a.model,
            basis_size,
            g_used.map(|g| format!(", g = {g}")).unwrap_or_default(),
            a.friction,
            a.events
        );
        println!(
            "t_end {:.4e} s: {} steps, {} RHS, {} nonlinear iterations ({} conv. failures), {} error-test failures, {} setups, last order {}, last h {:.2e} s",
            c.t.last().copied().unwrap_or(0.0),
            s.steps,
            s.rhs_evals,
            s.nonlinear_iterations,
            s.nonlinear_conv_failures,
            s.error_test_failures,
            s.linear_setups,
            s.last_order,
            s.last_step
        );
        println!(
            "wall {:.3} s, cpu {:.2} s (total incl. model {:.3} s)",
            res.wall_s, res.cpu_s, total_s
        );
        if let Some(i) = c.t.len().checked_sub(1) {
            println!(
                "final: |f_c| {:.6e} N, |f_R| {:.6e} N, master uy {:.6e} mm",
                c.contact_force_norm[i], c.friction_force_norm[i], c.master_uy[i]
            );
        }
    }
    Ok(())
}

fn print_study(s: &study::Study) {
    println!(
        "{} — static convergence study: {} DOF, {} pairs, ν = {}, g = 0..={}, load × {}",
        s.case, s.dofs, s.pairs, s.nu, s.max_g, s.scale
    );
    println!(
        "full FE: ‖f_c‖ = {:.9} N, {} pairs in contact ({:.1} ms)",
        s.full.contact_force_norm,
        s.full.pairs_in_contact,
        s.full.solve_s * 1e3
    );
    let show = |o: Option<usize>| o.map_or("—".to_string(), |g| g.to_string());
    println!(
        "  {:<10} {:>5} {:>13} {:>13} {:>13} {:>13} {:>9} {:>9}",
        "basis", "avail", "err(g=0)", "err(g=max)", "1e-2 first/stays", "", "prep s", "sweep s"
    );
    for x in &s.series {
        let last = x.relative_error.last().copied().unwrap_or(f64::NAN);
        let w2 = &x.within[0];
        let w4 = &x.within[1];
        println!(
            "  {:<10} {:>5} {:>13.3e} {:>13.3e}   1e-2: {:>3}/{:<3}  1e-4: {:>3}/{:<3} {:>9.3} {:>9.3}",
            x.name,
            x.available,
            x.relative_error[0],
            last,
            show(w2.first),
            show(w2.stays),
            show(w4.first),
            show(w4.stays),
            x.prepare_s,
            x.sweep_s
        );
    }
    for e in &s.energy {
        println!(
            "  w(g) {:<10}: g(w >= {}) = {}, {} nonzero TVD, {} POD modes",
            e.name, s.threshold, e.g_threshold, e.tvd_nonzero, e.pod_modes
        );
    }
    for t in &s.tvd_spans {
        let what = if t.name == "alldof" {
            "alldof: CB + every pair's normal constraint mode".to_string()
        } else {
            format!("all {} TVD without POD", t.name)
        };
        println!(
            "  {what}: {} columns ({} dropped), error {:.3e} ({:.2} s)",
            t.basis_size, t.dropped, t.relative_error, t.solve_s
        );
    }
    println!(
        "study {:.2} s (Craig–Bampton {:.3} s)",
        s.total_s, s.craig_bampton_s
    );
}
