//! The stability map: where the integrator's methods fail on the jointed structures.
//!
//! ## The sweep
//!
//! Every combination of
//!
//! - model: the full FE model (eq. 6), the ROM with g = 0 (Craig–Bampton only) and the ROM with
//!   the g chosen by the POD energy ratio `w(g) ≥ 0.9994` (eq. 26), both `BasisKind::Tvd` bases of
//!   [`build_basis`] (eq. 7);
//! - nonlinear iteration: functional (fixed point, no Anderson acceleration) or modified Newton
//!   with the structured solve of `M + γ²(K + BᵀK_cB)` ([`NewtonLinear::Problem`]);
//! - penalty stiffness k_n ∈ {1e2, 1e4, 1e6} N/mm (the case's `contact.normal_stiffness` is
//!   overridden before the model is built, so the TVD see it too);
//! - friction off / on, events (root finding on gaps and stick/slip switches with
//!   re-initialisation) off / on, BDF max order 2 / 5,
//!
//! is integrated from rest over a short window ([`SweepOptions::end_time`], 0.01 s of the friction
//! bar by default; the full model over [`SweepOptions::full_end_time`]) at the paper's Table 1
//! tolerances, and each cell records its status (`ok`, the CVODE flag such as
//! `CV_TOO_MUCH_WORK`, `budget`, `chatter`, `stalled` or `error`) with the time reached, the solver
//! statistics, the wall time and the relative L2 error over the output times of `‖f_c‖(t)`
//!
//! ```text
//! e = ‖fc_cell − fc_ref‖₂ / ‖fc_ref‖₂      (over the cell's output times)
//! ```
//!
//! against the *reference* of its model, k_n and friction: Newton, max order 5, events off, at
//! tolerances [`SweepOptions::reference_factor`] (100) times tighter. ROM cells also get
//! `error_vs_full`, the same measure against the full model's reference over the full model's
//! (shorter) window when that reference ran — the model error rather than the integration error.
//!
//! ## Bounded cost
//!
//! A cell cannot run away: `max_steps` caps the steps of the cell's whole run (a cell over it
//! fails with `CV_TOO_MUCH_WORK`; 2·10⁶ by default, the 20 000 per output interval of the stored
//! map's 100 intervals), and a wall-clock budget per cell is enforced from inside the
//! right-hand side (a wrapper problem returns a fatal callback error once the budget is spent, so
//! CVODE stops at once; the cell is reported as `budget` with the time reached).
//!
//! ## Measured
//!
//! The measured map of the friction bar (which cells fail, with which flag, and why) is in
//! `docs/validation/transient.md` (section `studies::stability`); the stored run is `results/stability/`.
//!
//! ## Failure kinds
//!
//! - `budget` with **functional iteration** (full model): the fixed point converges only while
//!   `γ‖J‖ < 1` (γ = h β₀), so the step is bounded by the stiffest retained mode — the shells'
//!   in-plane and drilling modes in the full model, the closed pairs' penalty frequency
//!   `√(k_n/m)` in a ROM, and with friction the slip relaxation `1/τ` (τ = 1e-6 s) of sliding
//!   pairs — whatever the accuracy needs.
//! - `budget` with **BDF max order 5** where order 2 finishes (full model, k_n = 1e4): orders
//!   3–5 are not A-stable near the imaginary axis, where an undamped structure's eigenvalues
//!   ±iω lie; high-order steps over the fast modes fail the error test and the step shrinks.
//! - `budget` with **events**: gaps of nearly closed pairs and stick/slip switches change sign
//!   at nearly every step (penalty oscillation), each root restarts the integrator at order 1;
//!   a switch that fires repeatedly at the same time would end the cell as `chatter`, and a
//!   full-model cell whose roots fire every other step at a crawl ends as `stalled`
//!   ([`crate::integrate::Stall`]) within seconds instead of spending its budget.
//! - `budget` with **Newton at k_n = 1e6** (w(g) ROM, full model): the contact oscillation at
//!   `√(k_n/m)` must be resolved to the tolerance, an accuracy limit that a stable implicit
//!   method does not remove.
//! - `CV_TOO_MUCH_WORK`: more than `max_steps` steps in the run, the same step bounds as above
//!   met with a small cap.

//! ## Outputs
//!
//! [`crate::report::stability::write_outputs`]: `stability.json` (every cell, the options and the references),
//! `stability.md` (a markdown table) and three heat maps (SVG + PNG) — rows model × iteration ×
//! max order, columns k_n × friction × events — coloured by status, by log10 of the wall time and
//! by log10 of the error, the failure flag (and, on the status map, the time reached, s)
//! written in failed cells.

use std::time::Instant;

use serde::Serialize;

use crate::case::Case;
use crate::error::Error;
use crate::integrate::problem::{Iteration, NewtonLinear, OdeOptions, OdeStats};
use crate::integrate::{integrate, ProblemOptions, Run, RunStatus, Scene, TransientOptions};
use crate::model::Model;
use crate::reduction::{build_basis, BasisKind, BasisOptions};
use crate::rom::compare::{relative_l2, JointCurves};
use crate::system::{FullSystem, ReducedSystem};

/// The model of a cell (the CLI's `--models` values).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, clap::ValueEnum)]
pub enum ModelKind {
    /// The full FE model.
    #[serde(rename = "full")]
    #[value(name = "full")]
    Full,
    /// ROM, TVD basis with g = 0 (Craig–Bampton).
    #[serde(rename = "rom-g0")]
    #[value(name = "rom-g0")]
    RomG0,
    /// ROM, TVD basis with g chosen by w(g).
    #[serde(rename = "rom")]
    #[value(name = "rom")]
    Rom,
}

impl ModelKind {
    /// Every kind, in map order.
    pub const ALL: [ModelKind; 3] = [ModelKind::Full, ModelKind::RomG0, ModelKind::Rom];

    /// The CLI / JSON name.
    pub fn name(self) -> &'static str {
        match self {
            ModelKind::Full => "full",
            ModelKind::RomG0 => "rom-g0",
            ModelKind::Rom => "rom",
        }
    }

    /// Parses a CLI name.
    pub fn parse(s: &str) -> Result<ModelKind, Error> {
        ModelKind::ALL
            .into_iter()
            .find(|k| k.name() == s)
            .ok_or_else(|| {
                crate::error::FlagError::Unknown {
                    flag: "models",
                    what: "model",
                    value: s.to_string(),
                    valid: "full, rom-g0, rom",
                }
                .into()
            })
    }
}

/// The nonlinear iteration of a cell or a run (the CLI's `--iteration`/`--iterations` values).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum IterKind {
    /// Fixed point, no acceleration.
    #[value(name = "functional")]
    Functional,
    /// Modified Newton with the structured solve.
    #[value(name = "newton")]
    Newton,
}

impl IterKind {
    /// The CLI / JSON name.
    pub fn name(self) -> &'static str {
        match self {
            IterKind::Functional => "functional",
            IterKind::Newton => "newton",
        }
    }

    /// Parses a CLI name.
    pub fn parse(s: &str) -> Result<IterKind, Error> {
        match s {
            "functional" => Ok(IterKind::Functional),
            "newton" => Ok(IterKind::Newton),
            _ => Err(crate::error::FlagError::Unknown {
                flag: "iterations",
                what: "iteration",
                value: s.to_string(),
                valid: "functional, newton",
            }
            .into()),
        }
    }

    /// The integrator's iteration of this kind (no Anderson acceleration; Newton with the
    /// problem's structured solve).
    pub fn iteration(self) -> Iteration {
        match self {
            IterKind::Functional => Iteration::Functional { anderson: 0 },
            IterKind::Newton => Iteration::Newton {
                linear: NewtonLinear::Problem,
            },
        }
    }
}

/// Options of [`run_sweep`]. Defaults: the whole map of the module docs, ROM window 0.01 s,
/// full window 2e-4 s, outputs every 1e-4 s (ROM) / 1e-5 s (full), paper tolerances
/// (rtol 1e-8, atol 1e-6), 20 000 steps per output interval, 20 s per cell, references 100×
/// tighter with 3× the budget.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SweepOptions {
    /// Models.
    pub models: Vec<ModelKind>,
    /// Nonlinear iterations.
    pub iterations: Vec<IterKind>,
    /// Penalty stiffnesses k_n, N/mm.
    pub normal_stiffness: Vec<f64>,
    /// Friction off/on values.
    pub friction: Vec<bool>,
    /// Events off/on values.
    pub events: Vec<bool>,
    /// BDF maximum orders.
    pub max_orders: Vec<usize>,
    /// ROM window, s.
    pub end_time: f64,
    /// Full-model window, s.
    pub full_end_time: f64,
    /// ROM output spacing, s.
    pub output_step: f64,
    /// Full-model (and reference) output spacing, s.
    pub full_output_step: f64,
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance (mm of the physical field; see [`crate::integrate::mechanical`]).
    pub atol: f64,
    /// Velocity tolerance per displacement tolerance, 1/s
    /// ([`crate::integrate::mechanical::ProblemOptions::velocity_scale`]).
    pub velocity_scale: f64,
    /// Maximum internal steps of a cell's run (all output intervals together).
    pub max_steps: usize,
    /// Wall-clock budget per cell, s.
    pub budget_s: f64,
    /// Tolerance factor of the references (> 1).
    pub reference_factor: f64,
    /// The Newton iteration's active-set refresh margin of every run, mm (`None`: off; see
    /// [`ProblemOptions::refresh`]).
    pub refresh: Option<f64>,
    /// Budget of a reference run, s.
    pub reference_budget_s: f64,
    /// Run the references (errors are `None` without).
    pub references: bool,
    /// Basis options of the ROMs (g is set to 0 for `rom-g0`).
    #[serde(skip)]
    pub basis: BasisOptions,
    /// Print one line per cell to stderr.
    pub progress: bool,
}

impl Default for SweepOptions {
    fn default() -> Self {
        SweepOptions {
            models: ModelKind::ALL.to_vec(),
            iterations: vec![IterKind::Functional, IterKind::Newton],
            normal_stiffness: vec![1e2, 1e4, 1e6],
            friction: vec![false, true],
            events: vec![false, true],
            max_orders: vec![2, 5],
            end_time: 0.01,
            full_end_time: 2e-4,
            output_step: 1e-4,
            full_output_step: 1e-5,
            rtol: 1e-8,
            atol: 1e-6,
            velocity_scale: crate::integrate::mechanical::DEFAULT_VELOCITY_SCALE,
            max_steps: 2_000_000,
            budget_s: 20.0,
            reference_factor: 100.0,
            refresh: ProblemOptions::default().refresh,
            reference_budget_s: 60.0,
            references: true,
            basis: BasisOptions::default(),
            progress: false,
        }
    }
}

/// One cell of the map.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Cell {
    /// Model.
    pub model: ModelKind,
    /// Number of reduced coordinates (full: DOF).
    pub dim: usize,
    /// Nonlinear iteration.
    pub iteration: IterKind,
    /// k_n, N/mm.
    pub normal_stiffness: f64,
    /// Friction on.
    pub friction: bool,
    /// Events on.
    pub events: bool,
    /// BDF max order.
    pub max_order: usize,
    /// Window, s.
    pub end_time: f64,
    /// Outcome of the integration (see [`Outcome`]).
    #[serde(flatten)]
    pub outcome: Outcome,
    /// Relative L2 error of ‖f_c‖(t) against the same model's reference (`None`: the cell or
    /// the reference failed).
    pub error: Option<f64>,
    /// The same against the full model's reference over its window (ROM cells).
    pub error_vs_full: Option<f64>,
}

/// Status, statistics and wall time of one integration.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Outcome {
    /// `ok`, the CVODE flag (`CV_TOO_MUCH_WORK`, `CV_CONV_FAILURE`, `CV_ERR_FAILURE`, ...),
    /// `budget`, `chatter`, `stalled` or `error` (serialized as [`RunStatus::name`]).
    pub status: RunStatus,
    /// The failure's message (`None` when ok).
    pub message: Option<String>,
    /// Time reached, s.
    pub t_reached: f64,
    /// Solver statistics.
    pub stats: OdeStats,
    /// Events located (re-initialisations).
    pub events_found: u64,
    /// Wall time of the integration (excluding building the system), s.
    pub wall_s: f64,
    /// Process CPU time of the integration, s (10 ms resolution; NaN where unavailable).
    pub cpu_s: f64,
    /// ‖f_c‖, ‖f_R‖ and master u_y at the output times.
    #[serde(skip)]
    pub curves: JointCurves,
}

impl Outcome {
    /// Whether the integration reached its end.
    pub fn ok(&self) -> bool {
        self.status.finished()
    }

    /// The record of a run of the driver.
    pub fn of_run(run: Run) -> Outcome {
        Outcome {
            status: run.status,
            message: run.failure.map(|e| e.to_string()),
            t_reached: run.t_reached,
            stats: run.stats,
            events_found: run.events,
            wall_s: run.wall_s,
            cpu_s: run.cpu_s,
            curves: run.curves.into(),
        }
    }
}

/// A reference run.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Reference {
    /// Model.
    pub model: ModelKind,
    /// k_n, N/mm.
    pub normal_stiffness: f64,
    /// Friction on.
    pub friction: bool,
    /// rtol used.
    pub rtol: f64,
    /// atol used.
    pub atol: f64,
    /// Outcome.
    #[serde(flatten)]
    pub outcome: Outcome,
    /// Relative L2 error of this reference's ‖f_c‖ against the full model's reference over the
    /// full window (ROM references).
    pub error_vs_full: Option<f64>,
}

/// A built model kind of one k_n.
#[derive(Clone, Debug, Serialize)]
pub struct Built {
    /// Model kind.
    pub model: ModelKind,
    /// k_n, N/mm.
    pub normal_stiffness: f64,
    /// Coordinates.
    pub dim: usize,
    /// Joint modes g (ROMs).
    pub g: Option<usize>,
    /// Largest reduced eigenfrequency ω_max/2π without contact, Hz (ROMs).
    pub max_frequency_hz: Option<f64>,
    /// Build time (model or basis), s.
    pub build_s: f64,
}

/// The result of [`run_sweep`].
#[derive(Clone, Debug, Serialize)]
pub struct Sweep {
    /// Case name.
    pub case: String,
    /// Options.
    pub options: SweepOptions,
    /// The models built.
    pub models: Vec<Built>,
    /// The references.
    pub references: Vec<Reference>,
    /// Every cell.
    pub cells: Vec<Cell>,
    /// Total wall time, s.
    pub wall_s: f64,
}

/// A model of one k_n, ready to build systems.
enum Prepared {
    Full,
    Rom(Box<ReducedSystem>),
}

/// Integrates a prepared model through the one driver; a system that cannot be built becomes
/// the outcome's status.
fn system_run(model: &Model, prep: &Prepared, opts: &TransientOptions) -> Outcome {
    let scene = Scene::of(model);
    let run = match prep {
        Prepared::Full => match FullSystem::new(model) {
            Ok(s) => integrate(s, &scene, opts, |_, _| {}),
            Err(e) => Run::failed(e),
        },
        Prepared::Rom(rm) => integrate(rm.as_ref().clone(), &scene, opts, |_, _| {}),
    };
    Outcome::of_run(run)
}

fn check_options(o: &SweepOptions) -> Result<(), Error> {
    let pos = |name: &str, v: f64| {
        if v.is_finite() && v > 0.0 {
            Ok(())
        } else {
            Err(Error::Study(crate::error::StudyError::NotPositive {
                option: name.to_string(),
                value: v,
            }))
        }
    };
    pos("end_time", o.end_time)?;
    pos("full_end_time", o.full_end_time)?;
    pos("output_step", o.output_step)?;
    pos("full_output_step", o.full_output_step)?;
    pos("rtol", o.rtol)?;
    pos("atol", o.atol)?;
    pos("budget_s", o.budget_s)?;
    pos("reference_budget_s", o.reference_budget_s)?;
    if !(o.reference_factor.is_finite() && o.reference_factor >= 1.0) {
        return Err(crate::error::StudyError::ReferenceFactor {
            factor: o.reference_factor,
        }
        .into());
    }
    for &k in &o.normal_stiffness {
        pos("normal_stiffness", k)?;
    }
    if let Some(m) = o.max_orders.iter().find(|m| !(1..=5).contains(*m)) {
        return Err(crate::error::StudyError::MaxOrder { order: *m }.into());
    }
    if o.max_steps == 0 {
        return Err(crate::error::StudyError::MaxSteps.into());
    }
    if o.models.is_empty()
        || o.iterations.is_empty()
        || o.normal_stiffness.is_empty()
        || o.friction.is_empty()
        || o.events.is_empty()
        || o.max_orders.is_empty()
    {
        return Err(crate::error::StudyError::EmptyAxis.into());
    }
    Ok(())
}

/// Runs the map on a case (see the module docs). Only bad options and failures to build a
/// model or basis are errors; every integration failure is a cell's status.
pub fn run_sweep(case: &Case, opts: &SweepOptions) -> Result<Sweep, Error> {
    check_options(opts)?;
    let t0 = Instant::now();
    let model = Model::from_case(case.clone())?;
    let model_s = t0.elapsed().as_secs_f64();
    run_sweep_model(&model, model_s, opts)
}

/// [`run_sweep`] on a built model (a case's or a user's matrices, [`crate::model::matrices`]);
/// `model_s` is the time it took to build, reported with the full model's cells. Each k_n
/// value only changes the contact law: K, M and B are shared.
pub fn run_sweep_model(base: &Model, model_s: f64, opts: &SweepOptions) -> Result<Sweep, Error> {
    check_options(opts)?;
    let t_all = Instant::now();
    let mut built = Vec::new();
    let mut references = Vec::new();
    let mut cells = Vec::new();
    for &kn in &opts.normal_stiffness {
        let mut model = base.clone();
        model.contact.normal_stiffness = kn;
        let pass = Pass {
            model: &model,
            kn,
            opts,
        };
        let prepared = pass.prepare(model_s, &mut built)?;
        for &friction in &opts.friction {
            let refs = pass.references(&prepared, friction, &mut references);
            pass.cells(&prepared, friction, &refs, &mut cells);
        }
    }
    Ok(Sweep {
        case: base.name.clone(),
        options: opts.clone(),
        models: built,
        references,
        cells,
        wall_s: t_all.elapsed().as_secs_f64(),
    })
}

/// A prepared model kind: the kind, what to integrate, the number of coordinates.
type PreparedKind = (ModelKind, Prepared, usize);

/// The references of one k_n and friction setting: the full model's ‖f_c‖ curve (t, ‖f_c‖) if
/// it finished, and every model's reference outcome.
struct References {
    full: Option<(Vec<f64>, Vec<f64>)>,
    by_model: Vec<(ModelKind, Outcome)>,
}

/// The sweep's passes over one k_n.
struct Pass<'a> {
    model: &'a Model,
    kn: f64,
    opts: &'a SweepOptions,
}

impl Pass<'_> {
    fn progress(&self, s: &str) {
        if self.opts.progress {
            eprintln!("{s}");
        }
    }

    /// Builds every model kind of the options, full first so that its reference is there for
    /// the ROMs; records each in `built`.
    fn prepare(&self, model_s: f64, built: &mut Vec<Built>) -> Result<Vec<PreparedKind>, Error> {
        let (model, kn, opts) = (self.model, self.kn, self.opts);
        let mut order = opts.models.clone();
        order.sort_by_key(|m| ModelKind::ALL.iter().position(|k| k == m));
        order.dedup();
        let mut prepared = Vec::new();
        for &kind in &order {
            let t0 = Instant::now();
            let (prep, dim, g, fmax) = match kind {
                ModelKind::Full => (Prepared::Full, model.dofs(), None, None),
                ModelKind::RomG0 | ModelKind::Rom => {
                    let mut bo = opts.basis;
                    if kind == ModelKind::RomG0 {
                        bo.g = Some(0);
                    }
                    let basis = build_basis(model, BasisKind::Tvd, &bo)?;
                    let fmax = basis
                        .eigenvalues
                        .iter()
                        .cloned()
                        .fold(f64::NAN, f64::max)
                        .sqrt()
                        / (2.0 * std::f64::consts::PI);
                    let rm = ReducedSystem::new(model, basis.phi)?;
                    let dim = rm.dim();
                    (Prepared::Rom(Box::new(rm)), dim, Some(basis.g), Some(fmax))
                }
            };
            let build_s = t0.elapsed().as_secs_f64()
                + if kind == ModelKind::Full {
                    model_s
                } else {
                    0.0
                };
            self.progress(&format!(
                "k_n = {kn:e}: {} built, {dim} coordinates ({build_s:.2} s)",
                kind.name()
            ));
            built.push(Built {
                model: kind,
                normal_stiffness: kn,
                dim,
                g,
                max_frequency_hz: fmax.filter(|f: &f64| f.is_finite()),
                build_s,
            });
            prepared.push((kind, prep, dim));
        }
        Ok(prepared)
    }

    /// The references (Newton, order 5, events off, tighter tolerances) of every prepared
    /// model, recorded in `references`.
    fn references(
        &self,
        prepared: &[PreparedKind],
        friction: bool,
        references: &mut Vec<Reference>,
    ) -> References {
        let (kn, opts) = (self.kn, self.opts);
        let mut refs = References {
            full: None,
            by_model: Vec::new(),
        };
        if !opts.references {
            return refs;
        }
        for (kind, prep, _) in prepared {
            let end = if *kind == ModelKind::Full {
                opts.full_end_time
            } else {
                opts.end_time
            };
            let spec = TransientOptions {
                problem: ProblemOptions {
                    friction,
                    events: false,
                    velocity_scale: opts.velocity_scale,
                    refresh: opts.refresh,
                    ..ProblemOptions::default()
                },
                ode: OdeOptions {
                    iteration: IterKind::Newton.iteration(),
                    rtol: opts.rtol / opts.reference_factor,
                    atol: opts.atol / opts.reference_factor,
                    max_order: 5,
                    max_steps: opts.max_steps.max(10_000_000),
                    ..OdeOptions::default()
                },
                end_time: Some(end),
                output_step: opts.full_output_step.min(end),
                budget_s: Some(opts.reference_budget_s),
                record: false,
                profile: false,
                hook: None,
                ..TransientOptions::default()
            };
            let o = system_run(self.model, prep, &spec);
            self.progress(&format!(
                "reference {} k_n = {kn:e} friction {}: {} t = {:.3e} s, {} steps, {:.2} s",
                kind.name(),
                on_off(friction),
                o.status.name(),
                o.t_reached,
                o.stats.steps,
                o.wall_s
            ));
            let vs_full = vs_full(&refs.full, *kind, &o);
            if *kind == ModelKind::Full && o.ok() {
                refs.full = Some((o.curves.t.clone(), o.curves.contact_force_norm.clone()));
            }
            references.push(Reference {
                model: *kind,
                normal_stiffness: kn,
                friction,
                rtol: spec.ode.rtol,
                atol: spec.ode.atol,
                outcome: o.clone(),
                error_vs_full: vs_full,
            });
            refs.by_model.push((*kind, o));
        }
        refs
    }

    /// Every cell (iteration × max order × events) of every prepared model, recorded in
    /// `cells`.
    fn cells(
        &self,
        prepared: &[PreparedKind],
        friction: bool,
        refs: &References,
        cells: &mut Vec<Cell>,
    ) {
        let opts = self.opts;
        for (kind, prep, dim) in prepared {
            let (end, dt) = if *kind == ModelKind::Full {
                (opts.full_end_time, opts.full_output_step)
            } else {
                (opts.end_time, opts.output_step)
            };
            for &iteration in &opts.iterations {
                for &max_order in &opts.max_orders {
                    for &events in &opts.events {
                        let spec = TransientOptions {
                            problem: ProblemOptions {
                                friction,
                                events,
                                velocity_scale: opts.velocity_scale,
                                refresh: opts.refresh,
                                ..ProblemOptions::default()
                            },
                            ode: OdeOptions {
                                iteration: iteration.iteration(),
                                rtol: opts.rtol,
                                atol: opts.atol,
                                max_order,
                                max_steps: opts.max_steps,
                                ..OdeOptions::default()
                            },
                            end_time: Some(end),
                            output_step: dt.min(end),
                            budget_s: Some(opts.budget_s),
                            record: false,
                            profile: false,
                            hook: None,
                            ..TransientOptions::default()
                        };
                        let o = system_run(self.model, prep, &spec);
                        let cell = Cell {
                            model: *kind,
                            dim: *dim,
                            iteration,
                            normal_stiffness: self.kn,
                            friction,
                            events,
                            max_order,
                            end_time: end,
                            error: None,
                            error_vs_full: vs_full(&refs.full, *kind, &o),
                            outcome: o,
                        };
                        cells.push(self.finish_cell(cell, refs));
                    }
                }
            }
        }
    }

    /// A cell's error against its model's reference, and its progress line.
    fn finish_cell(&self, mut cell: Cell, refs: &References) -> Cell {
        let o = &cell.outcome;
        let reference = refs
            .by_model
            .iter()
            .find(|(k, r)| *k == cell.model && r.ok())
            .map(|(_, r)| r);
        cell.error = match reference {
            Some(r) if o.ok() => relative_l2(
                &o.curves.t,
                &o.curves.contact_force_norm,
                &r.curves.t,
                &r.curves.contact_force_norm,
            ),
            _ => None,
        };
        self.progress(&format!(
            "{:<6} {:<10} order {} k_n {:7.0e} friction {:<3} events {:<3}: {:<18} t {:.3e} s \
             steps {:>7} rhs {:>8} {:7.2} s error {}",
            cell.model.name(),
            cell.iteration.name(),
            cell.max_order,
            self.kn,
            on_off(cell.friction),
            on_off(cell.events),
            o.status.name(),
            o.t_reached,
            o.stats.steps,
            o.stats.rhs_evals,
            o.wall_s,
            cell.error.map_or("-".into(), |e| format!("{e:.2e}"))
        ));
        cell
    }
}

/// A ROM outcome's ‖f_c‖ error against the full model's reference over the full model's
/// (shorter) window, compared where the times match; `None` for the full model or without a
/// finished reference.
fn vs_full(full: &Option<(Vec<f64>, Vec<f64>)>, kind: ModelKind, o: &Outcome) -> Option<f64> {
    match (full, kind) {
        (Some((t, f)), ModelKind::RomG0 | ModelKind::Rom) if o.ok() => {
            relative_l2(&o.curves.t, &o.curves.contact_force_norm, t, f)
        }
        _ => None,
    }
}

pub(crate) fn on_off(b: bool) -> &'static str {
    if b {
        "on"
    } else {
        "off"
    }
}
