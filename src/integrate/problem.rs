//! The integrator-neutral boundary between a first-order ODE problem `y' = F(t, y)` and a time
//! integrator (CVODE in `crate::integrate::sundials`, wrapped by [`crate::integrate::Cvode`]).
//!
//! A problem is data plus pure functions of `(t, y)`: the right-hand side, optional event
//! (root) functions, and optionally its own Newton linear solver for the matrix `I − γ J`
//! (J = ∂F/∂y), which lets a second-order mechanical model solve the Newton system through the
//! symmetric `M + γ C + γ² K_t` (see `shared/NOTES.md`) instead of a dense `2n × 2n` matrix.
//! The integrator's options, its statistics and the reason it stopped are plain data here so
//! that models, tests and reports never touch the FFI layer.

/// A failure inside a problem callback.
#[derive(Clone, Debug, PartialEq)]
pub enum CallbackError {
    /// The integrator may retry with a smaller step (e.g. a NaN/Inf from a too large step).
    Recoverable(String),
    /// Stop the integration; the message is returned in the run's error.
    Fatal(String),
}

impl std::fmt::Display for CallbackError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            CallbackError::Recoverable(m) => write!(f, "recoverable: {m}"),
            CallbackError::Fatal(m) => write!(f, "{m}"),
        }
    }
}

/// A first-order ODE problem `y' = F(t, y)` of fixed dimension.
///
/// The callbacks must be pure functions of their arguments (an implicit integrator evaluates
/// them at trial states that are thrown away) and must not allocate on the hot path.
pub trait OdeProblem {
    /// Dimension of `y`.
    fn dim(&self) -> usize;

    /// `ydot = F(t, y)`.
    fn rhs(&mut self, t: f64, y: &[f64], ydot: &mut [f64]) -> Result<(), CallbackError>;

    /// Number of event functions (0: no root finding).
    fn num_roots(&self) -> usize {
        0
    }

    /// Event functions `g(t, y)` (length [`OdeProblem::num_roots`]); the integrator locates
    /// their sign changes.
    fn roots(&mut self, _t: f64, _y: &[f64], _g: &mut [f64]) -> Result<(), CallbackError> {
        Ok(())
    }

    /// Per-component scale of the absolute tolerance: the integrator uses
    /// `atol_i = atol · scale_i` when this fills `scale` (length [`OdeProblem::dim`]) and returns
    /// `true`; the default returns `false` (one scalar `atol` for every component). Problems
    /// whose states have different units (displacements, velocities, generalized coordinates)
    /// use it to state the tolerance in one physical unit.
    fn atol_scale(&self, _scale: &mut [f64]) -> bool {
        false
    }

    /// Whether [`OdeProblem::newton_setup`] / [`OdeProblem::newton_solve`] are implemented.
    fn has_newton_solver(&self) -> bool {
        false
    }

    /// Prepares solves with `I − γ J(t, y)` (`fy = F(t, y)`). `jok`: the integrator allows
    /// reusing Jacobian data from an earlier call (only γ changed). Returns whether the
    /// Jacobian data were recomputed (`jcur`).
    fn newton_setup(
        &mut self,
        _t: f64,
        _y: &[f64],
        _fy: &[f64],
        _jok: bool,
        _gamma: f64,
    ) -> Result<bool, CallbackError> {
        Err(CallbackError::Fatal(
            "this problem has no Newton linear solver".into(),
        ))
    }

    /// Solves `(I − γ J) z = r` (approximately: the integrator's Newton iteration corrects
    /// for an inexact matrix) with the data of the last [`OdeProblem::newton_setup`].
    fn newton_solve(
        &mut self,
        _t: f64,
        _y: &[f64],
        _r: &[f64],
        _z: &mut [f64],
        _gamma: f64,
    ) -> Result<(), CallbackError> {
        Err(CallbackError::Fatal(
            "this problem has no Newton linear solver".into(),
        ))
    }
}

/// Linear multistep family.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Method {
    /// Backward differentiation formulas, orders 1–5 (stiff problems; the paper's choice).
    Bdf,
    /// Adams–Moulton, orders 1–12.
    Adams,
}

/// Linear solver inside Newton's iteration.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum NewtonLinear {
    /// Dense LU of `I − γ J`, J by CVODE's difference quotients (small reduced models).
    DenseDq,
    /// The problem's own solver ([`OdeProblem::newton_setup`] / `newton_solve`).
    Problem,
}

/// Nonlinear iteration of the implicit multistep formula.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case", tag = "kind")]
pub enum Iteration {
    /// Fixed-point ("functional") iteration, with Anderson acceleration of depth `anderson`
    /// (0: plain fixed point, the paper's functional iteration).
    Functional { anderson: usize },
    /// Modified Newton iteration.
    Newton { linear: NewtonLinear },
}

/// Integrator options. Defaults: BDF, Newton with the problem's solver, the paper's Table 1
/// tolerances (rtol 1e-8, atol 1e-6), max order 5, max 10⁶ steps, stability-limit detection
/// off, no maximum step, event tolerance decided by the integrator.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct OdeOptions {
    /// Multistep family.
    pub method: Method,
    /// Nonlinear iteration.
    pub iteration: Iteration,
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance, in the units of y (mm, mm/s, ...).
    pub atol: f64,
    /// Maximum order (BDF ≤ 5, Adams ≤ 12).
    pub max_order: usize,
    /// Maximum number of internal steps of the whole run (all `solve_to` calls together,
    /// across `reinit`); CVODE then returns `CV_TOO_MUCH_WORK`.
    pub max_steps: usize,
    /// BDF stability-limit detection (`CVodeSetStabLimDet`).
    pub stab_lim_det: bool,
    /// Maximum step size, s (0: none).
    pub max_step: f64,
    /// Initial step size, s (0: the integrator's estimate).
    pub init_step: f64,
    /// Smallest step-size growth CVODE acts on after a successful step (its `eta_max_fx` of
    /// `CVodeSetEtaFixedStepBounds`; ≥ 1). CVODE's default 1.5 keeps `h` until it could grow by
    /// 50 %; smaller values let `h` follow the error estimate more closely.
    pub step_growth: f64,
}

/// CVODE's own [`OdeOptions::step_growth`] (`eta_max_fx` = 1.5).
pub const CVODE_STEP_GROWTH: f64 = 1.5;

impl Default for OdeOptions {
    fn default() -> Self {
        OdeOptions {
            method: Method::Bdf,
            iteration: Iteration::Newton {
                linear: NewtonLinear::Problem,
            },
            rtol: 1e-8,
            atol: 1e-6,
            max_order: 5,
            max_steps: 1_000_000,
            stab_lim_det: false,
            max_step: 0.0,
            init_step: 0.0,
            step_growth: CVODE_STEP_GROWTH,
        }
    }
}

/// Why a `solve_to` call returned.
#[derive(Clone, Debug, PartialEq)]
pub enum Stop {
    /// The requested output time was reached.
    Reached(f64),
    /// Event functions changed sign at `t`; `roots[i]` is +1 / −1 for a rising / falling root of
    /// `g_i`, 0 where `g_i` did not change sign.
    Root { t: f64, roots: Vec<i32> },
}

/// Integrator statistics (cumulative since creation).
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct OdeStats {
    /// Internal steps.
    pub steps: u64,
    /// Right-hand-side evaluations by the integrator (not counting difference quotients).
    pub rhs_evals: u64,
    /// Right-hand-side evaluations for difference-quotient Jacobians.
    pub rhs_evals_jac: u64,
    /// Nonlinear iterations.
    pub nonlinear_iterations: u64,
    /// Nonlinear convergence failures.
    pub nonlinear_conv_failures: u64,
    /// Local error test failures.
    pub error_test_failures: u64,
    /// Linear solver setups (Newton matrix rebuilds requested by the integrator).
    pub linear_setups: u64,
    /// Jacobian evaluations (dense) or problem solver setups that recomputed the Jacobian.
    pub jacobian_evals: u64,
    /// Linear solves.
    pub linear_solves: u64,
    /// Event-function evaluations.
    pub root_evals: u64,
    /// Roots found (stops of kind [`Stop::Root`]).
    pub roots_found: u64,
    /// Order of the last step.
    pub last_order: i32,
    /// Size of the last step, s.
    pub last_step: f64,
    /// Stability-limit order reductions.
    pub stab_lim_order_reductions: u64,
    /// Newton matrices refactored inside a Newton iteration by the problem itself (the
    /// mechanical problem's active-set refresh; not counted in `linear_setups`).
    pub newton_refreshes: u64,
    /// Of the `newton_refreshes`, those done by an exact low-rank update of the factor instead
    /// of a refactorization (the full model, [`crate::system::FullSystem`]).
    pub newton_low_rank: u64,
    /// Pairs that had switched branch at the refreshes, summed.
    pub newton_refresh_pairs: u64,
    /// Pair screening ([`crate::integrate::mechanical`], *Pair screening*): builds of the
    /// tracked set (0 without screening).
    pub screen_builds: u64,
    /// Tracked pairs summed over the builds (mean = this / `screen_builds`).
    pub screen_tracked_sum: u64,
    /// The most pairs tracked at once.
    pub screen_tracked_max: u64,
    /// Untracked pairs found closed by a right-hand side (late entries into the set).
    pub screen_violations: u64,
    /// Pairs that joined the tracked set, summed.
    pub screen_entries: u64,
    /// Untracked pairs whose gap was computed exactly (their bound was not positive), summed.
    pub screen_exact_checks: u64,
    /// Pairs that left it, summed.
    pub screen_exits: u64,
}
