//! `jointrom stability`: the stability map of the transient methods (see
//! `jointrom::studies::stability`).

use std::io::IsTerminal;
use std::path::PathBuf;

use clap::Args;

use jointrom::error::StudyError;
use jointrom::report::stability::stability_study;
use jointrom::studies::stability::SweepOptions;
use jointrom::Error;

use jointrom::studies::stability::{IterKind, ModelKind};

use crate::args::OnOff;

#[derive(Args)]
pub struct StabilityArgs {
    /// Case file, matrix map (`jointrom-matrices` JSON) or built-in name.
    pub case: String,
    /// Output folder (OUT/CASE/stability.json, .md and heat maps).
    #[arg(long, default_value = "out")]
    pub out: PathBuf,
    /// Models: full, rom-g0, rom (comma-separated).
    #[arg(
        long,
        value_enum,
        value_delimiter = ',',
        default_value = "full,rom-g0,rom"
    )]
    pub models: Vec<ModelKind>,
    /// Iterations: functional, newton.
    #[arg(
        long,
        value_enum,
        value_delimiter = ',',
        default_value = "functional,newton"
    )]
    pub iterations: Vec<IterKind>,
    /// Penalty stiffnesses k_n, N/mm.
    #[arg(long, value_delimiter = ',', default_value = "1e2,1e4,1e6")]
    pub kn: Vec<f64>,
    /// Friction values: off, on.
    #[arg(long, value_enum, value_delimiter = ',', default_value = "off,on")]
    pub friction: Vec<OnOff>,
    /// Events values: off, on.
    #[arg(long, value_enum, value_delimiter = ',', default_value = "off,on")]
    pub events: Vec<OnOff>,
    /// BDF maximum orders.
    #[arg(long, value_delimiter = ',', default_value = "2,5")]
    pub max_order: Vec<usize>,
    /// ROM window, s.
    #[arg(long, default_value_t = 0.01)]
    pub end_time: f64,
    /// Full-model window, s.
    #[arg(long, default_value_t = 2e-4)]
    pub full_end_time: f64,
    /// ROM output spacing, s.
    #[arg(long, default_value_t = 1e-4)]
    pub output_step: f64,
    /// Full-model and reference output spacing, s.
    #[arg(long, default_value_t = 1e-5)]
    pub full_output_step: f64,
    /// Relative tolerance.
    #[arg(long, default_value_t = 1e-8)]
    pub rtol: f64,
    /// Absolute tolerance.
    #[arg(long, default_value_t = 1e-6)]
    pub atol: f64,
    /// Velocity tolerance per displacement tolerance, 1/s (1: the paper's one number).
    #[arg(long, default_value_t = jointrom::integrate::mechanical::DEFAULT_VELOCITY_SCALE)]
    pub velocity_scale: f64,
    /// Maximum internal steps of a cell's whole run.
    #[arg(long, default_value_t = 2_000_000)]
    pub max_steps: usize,
    /// Wall-clock budget per cell, s.
    #[arg(long, default_value_t = 20.0)]
    pub budget: f64,
    /// Wall-clock budget per reference run, s.
    #[arg(long, default_value_t = 60.0)]
    pub reference_budget: f64,
    /// Tolerance factor of the references.
    #[arg(long, default_value_t = 100.0)]
    pub reference_factor: f64,
    /// Skip the reference runs (no errors).
    #[arg(long)]
    pub no_reference: bool,
    /// Skip the heat maps.
    #[arg(long)]
    pub no_charts: bool,
}

impl StabilityArgs {
    /// The sweep options these arguments ask for (progress lines on a terminal only; the
    /// default basis options).
    pub fn options(&self) -> SweepOptions {
        let on = |v: &[OnOff]| v.iter().map(|s| s.is_on()).collect();
        SweepOptions {
            models: self.models.clone(),
            iterations: self.iterations.clone(),
            normal_stiffness: self.kn.clone(),
            friction: on(&self.friction),
            events: on(&self.events),
            max_orders: self.max_order.clone(),
            end_time: self.end_time,
            full_end_time: self.full_end_time,
            output_step: self.output_step,
            full_output_step: self.full_output_step,
            rtol: self.rtol,
            atol: self.atol,
            velocity_scale: self.velocity_scale,
            max_steps: self.max_steps,
            budget_s: self.budget,
            reference_factor: self.reference_factor,
            reference_budget_s: self.reference_budget,
            references: !self.no_reference,
            progress: std::io::stderr().is_terminal(),
            ..SweepOptions::default()
        }
    }
}

/// Runs the sweep, writes `OUT/CASE/stability.{json,md}` and the heat maps, prints the summary.
pub fn run(a: StabilityArgs) -> Result<(), Error> {
    let opts = a.options();
    let v = stability_study(&a.case, &a.out, !a.no_charts, &opts)?;
    println!(
        "{}",
        serde_json::to_string_pretty(&v).map_err(StudyError::JsonOutput)?
    );
    Ok(())
}
