//! The options of a run.

use std::sync::Arc;

use serde::Serialize;

use crate::error::{Error, FlagError};
use crate::integrate::mechanical::{ProblemOptions, DEFAULT_MAX_ORDER};
use crate::integrate::problem::{DirkTable, Iteration, OdeOptions, DIRK_TABLE_NAMES};

/// Options of [`integrate`](super::integrate). Defaults: the integrator's defaults ([`OdeOptions::default`]: BDF,
/// Newton with the structured solve, rtol 1e-8, atol 1e-6 — the paper's Table 1) except the
/// maximum order [`DEFAULT_MAX_ORDER`] = 2, velocity tolerance
/// [`crate::integrate::mechanical::DEFAULT_VELOCITY_SCALE`] × atol, friction on, events off, τ = 1e-6 s,
/// outputs every 1e-4 s, the scene's end time, no wall-clock budget.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TransientOptions {
    /// Integrator options.
    pub ode: OdeOptions,
    /// Friction, events, τ.
    pub problem: ProblemOptions,
    /// Spacing of the output times, s (> 0).
    pub output_step: f64,
    /// End of the run, s (`None`: the scene's `end_time`).
    pub end_time: Option<f64>,
    /// Wall-clock budget of the integration, s (`None`: unlimited), checked in every
    /// right-hand side; running out ends the run as [`RunStatus::Budget`](super::RunStatus::Budget).
    #[serde(skip)]
    pub budget_s: Option<f64>,
    /// Keep the coordinates, pair forces and slip memory at every output in
    /// [`Run::trajectory`](super::Run::trajectory) (for the a-posteriori error estimate of a reduced run,
    /// [`crate::reduction::estimate`]); `false` by default.
    #[serde(skip)]
    pub record: bool,
    /// Time every callback ([`Run::profile`](super::Run::profile)): costs two clock reads per callback; `false` by
    /// default.
    #[serde(skip)]
    pub profile: bool,
    /// Called with the time reached (s) at every right-hand side; returning `false` stops the
    /// run as if its wall-clock budget had run out. For embedding callers (progress, Ctrl-C);
    /// `None` by default. It sees the run, it does not change it.
    #[serde(skip)]
    pub hook: Option<RunHook>,
    /// Where the run starts (`None`: at rest, undeformed, no slip — the default). A free decay
    /// starts from a displaced state ([`InitialState`]).
    #[serde(skip)]
    pub start: Option<InitialState>,
    /// A master-node load `[Fx, Fy, Fz (N), Mx, My, Mz (N·mm)]` held constant from t = 0,
    /// replacing the system's own (ramped) load (`None`: the system's load — the default). A
    /// preload under which a structure rings down.
    #[serde(skip)]
    pub constant_load: Option<[f64; 6]>,
}

/// The state a run starts from instead of rest: coordinates, velocities and slip memory (the
/// energy states W and D start at zero, so the energy balance is counted from this state:
/// [`Curves::balance`](super::Curves::balance) subtracts its value at t = 0).
#[derive(Clone, Debug, PartialEq)]
pub struct InitialState {
    /// Coordinates q (n: mm and rad of the full model, generalized coordinates of a reduced
    /// one).
    pub q: Vec<f64>,
    /// Velocities q̇ (n), same units per s.
    pub v: Vec<f64>,
    /// Slip memory s (2 per pair: t1, t2; mm). Ignored with friction off.
    pub slip: Vec<f64>,
}

/// A caller's hook into a running integration: `f(t)` → keep going.
#[derive(Clone)]
pub struct RunHook(pub Arc<dyn Fn(f64) -> bool + Send + Sync>);

impl std::fmt::Debug for RunHook {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("RunHook")
    }
}

impl PartialEq for RunHook {
    /// The same hook (one `Arc`).
    fn eq(&self, other: &RunHook) -> bool {
        Arc::ptr_eq(&self.0, &other.0)
    }
}

impl Default for TransientOptions {
    fn default() -> Self {
        TransientOptions {
            ode: OdeOptions {
                max_order: DEFAULT_MAX_ORDER,
                ..OdeOptions::default()
            },
            problem: ProblemOptions::default(),
            output_step: 1e-4,
            end_time: None,
            budget_s: None,
            record: false,
            profile: false,
            hook: None,
            start: None,
            constant_load: None,
        }
    }
}

impl TransientOptions {
    /// The absolute resolution of a run's energy balance, N·mm: 10 × the absolute tolerance
    /// CVODE holds the energy states W and D to (`atol` × [`ProblemOptions::energy_scale`],
    /// 1e-9 N·mm by default). A run whose energies are themselves at this level (the first
    /// millisecond of a ramp: 1e-7 N·mm) cannot balance better than it, relative to anything.
    pub fn energy_resolution(&self) -> f64 {
        10.0 * self.ode.atol * self.problem.energy_scale
    }
}

/// `v` if finite and positive, else the error naming the command-line flag `--{flag}`.
pub fn positive_flag(flag: &'static str, v: f64) -> Result<f64, Error> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(FlagError::NotPositive { flag, value: v }.into())
    }
}

/// The DIRK table named by the value of the command-line flag `--{flag}` (ARKODE's name, with
/// or without `ARKODE_`, any case), or the error naming the flag and listing the tables.
pub fn dirk_table_flag(flag: &'static str, name: &str) -> Result<DirkTable, Error> {
    DirkTable::from_name(name).ok_or_else(|| {
        FlagError::Unknown {
            flag,
            what: "DIRK table",
            value: name.to_string(),
            valid: DIRK_TABLE_NAMES,
        }
        .into()
    })
}

/// The choices of a run a user makes — `jointrom transient`'s flags and the Python package's
/// keyword arguments of the same names — checked into [`TransientOptions`] in one place (errors
/// name the flags). Callers add what only they have (the CLI's `--velocity-scale`,
/// `--refresh`, ...; Python's hook) to the options this returns.
#[derive(Clone, Debug, PartialEq)]
pub struct RunChoices {
    /// Newton or functional iteration.
    pub iteration: Iteration,
    /// Friction on.
    pub friction: bool,
    /// Event location on gaps and stick/slip switches.
    pub events: bool,
    /// CVODE's relative tolerance (`None`: the paper's 1e-8).
    pub rtol: Option<f64>,
    /// Absolute tolerance, mm (`None`: the paper's 1e-6).
    pub atol: Option<f64>,
    /// Maximum BDF order 1–5 (`None`: [`DEFAULT_MAX_ORDER`]).
    pub max_order: Option<usize>,
    /// End time, s (`None`: the scene's).
    pub end_time: Option<f64>,
    /// Output spacing, s.
    pub output_step: f64,
    /// Wall-clock budget of the integration, s.
    pub max_wall: f64,
}

impl RunChoices {
    /// The checked transient options of these choices.
    ///
    /// # Errors
    /// A tolerance, time, step or budget that is not finite and positive, a max order outside
    /// 1–5, more outputs than a run keeps — each naming its flag.
    pub fn options(&self) -> Result<TransientOptions, Error> {
        let mut o = TransientOptions::default();
        o.ode.iteration = self.iteration;
        o.problem.friction = self.friction;
        o.problem.events = self.events;
        if let Some(r) = self.rtol {
            o.ode.rtol = positive_flag("rtol", r)?;
        }
        if let Some(a) = self.atol {
            o.ode.atol = positive_flag("atol", a)?;
        }
        if let Some(k) = self.max_order {
            if !(1..=5).contains(&k) {
                return Err(FlagError::Range {
                    flag: "max-order",
                    need: "1..=5 (BDF)",
                    got: k.to_string(),
                }
                .into());
            }
            o.ode.max_order = k;
        }
        if let Some(t) = self.end_time {
            o.end_time = Some(positive_flag("end-time", t)?);
        }
        o.output_step = positive_flag("output-step", self.output_step)?;
        if let Some(t) = o.end_time {
            super::output_count(t, o.output_step)?;
        }
        o.budget_s = Some(positive_flag("max-wall", self.max_wall)?);
        Ok(o)
    }
}
