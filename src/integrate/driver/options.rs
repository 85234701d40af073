//! The options of a run.

use std::sync::Arc;

use serde::Serialize;

use crate::integrate::mechanical::{ProblemOptions, DEFAULT_MAX_ORDER};
use crate::integrate::problem::OdeOptions;

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
