//! The integrator-neutral boundary between a first-order ODE problem `y' = F(t, y)` and a time
//! integrator (CVODE or ARKODE's ARKStep in `crate::integrate::sundials`, wrapped by
//! [`crate::integrate::Cvode`] and [`crate::integrate::Arkode`]).
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

    /// Whether the problem changes the integrator's error weights
    /// ([`OdeProblem::adjust_error_weights`]). The default `false` leaves them
    /// `1 / (rtol |y_i| + atol_i)` without a callback.
    fn adjusts_error_weights(&self) -> bool {
        false
    }

    /// Changes the error weights of the step starting at `y`: on entry `ewt_i = 1 / (rtol
    /// |y_i| + atol_i)` (the integrator's own weights, bit for bit); a problem may lower
    /// entries, down to zero for a component whose error the step's test should not see.
    /// Called once per step (CVODE only, when [`OdeProblem::adjusts_error_weights`]).
    fn adjust_error_weights(&mut self, _y: &[f64], _ewt: &mut [f64]) -> Result<(), CallbackError> {
        Ok(())
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

/// Integration method: CVODE's linear multistep families or an implicit Runge–Kutta method of
/// ARKODE's ARKStep.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Method {
    /// Backward differentiation formulas, orders 1–5 (stiff problems; the paper's choice).
    Bdf,
    /// Adams–Moulton, orders 1–12.
    Adams,
    /// A diagonally implicit Runge–Kutta method (ARKODE's ARKStep, implicit only) with the
    /// given Butcher table; the table fixes the order ([`OdeOptions::max_order`] is unused).
    Dirk(DirkTable),
}

/// The DIRK Butcher tables of ARKODE 5.4 offered by [`Method::Dirk`]: all L-stable and stiffly
/// accurate (the last stage is the step's solution, so the unresolved stiff modes of an
/// undamped structure are damped as by BDF2 and the stage values satisfy the differential
/// equation). Named `ARKODE_<name>_<stages>_<embedding order>_<order>` as in ARKODE.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub enum DirkTable {
    /// TR-BDF2: 3 stages, order 2 (embedding 3).
    #[serde(rename = "ARKODE_TRBDF2_3_3_2")]
    Trbdf2,
    /// Kværnø's ESDIRK: 4 stages, order 3 (embedding 2).
    #[serde(rename = "ARKODE_KVAERNO_4_2_3")]
    Kvaerno423,
    /// The implicit part of Kennedy–Carpenter's `ARK3(2)4L[2]SA`: 4 stages, order 3.
    #[serde(rename = "ARKODE_ARK324L2SA_DIRK_4_2_3")]
    Ark324Dirk,
    /// Kennedy–Carpenter's `ESDIRK3(2)4L[2]SA`: 4 stages, order 3.
    #[serde(rename = "ARKODE_ESDIRK324L2SA_4_2_3")]
    Esdirk324,
    /// Hairer–Wanner's SDIRK: 5 stages, order 4 (embedding 3).
    #[serde(rename = "ARKODE_SDIRK_5_3_4")]
    Sdirk534,
    /// Kværnø's ESDIRK: 5 stages, order 4 (embedding 3).
    #[serde(rename = "ARKODE_KVAERNO_5_3_4")]
    Kvaerno534,
    /// The implicit part of Kennedy–Carpenter's `ARK4(3)6L[2]SA`: 6 stages, order 4.
    #[serde(rename = "ARKODE_ARK436L2SA_DIRK_6_3_4")]
    Ark436Dirk,
    /// Kennedy–Carpenter's `ESDIRK4(3)6L[2]SA`: 6 stages, order 4.
    #[serde(rename = "ARKODE_ESDIRK436L2SA_6_3_4")]
    Esdirk436,
    /// Kværnø's ESDIRK: 7 stages, order 5 (embedding 4).
    #[serde(rename = "ARKODE_KVAERNO_7_4_5")]
    Kvaerno745,
    /// The implicit part of Kennedy–Carpenter's `ARK5(4)8L[2]SA`: 8 stages, order 5.
    #[serde(rename = "ARKODE_ARK548L2SA_DIRK_8_4_5")]
    Ark548Dirk,
}

/// The names [`DirkTable::from_name`] accepts (without ARKODE's `ARKODE_` prefix), for
/// messages.
pub const DIRK_TABLE_NAMES: &str = "TRBDF2_3_3_2, KVAERNO_4_2_3, ARK324L2SA_DIRK_4_2_3, \
     SDIRK_5_3_4, KVAERNO_5_3_4, ARK436L2SA_DIRK_6_3_4, KVAERNO_7_4_5, ARK548L2SA_DIRK_8_4_5, \
     ESDIRK324L2SA_4_2_3, ESDIRK436L2SA_6_3_4";

impl DirkTable {
    /// Every table, in the order of ARKODE's table numbers.
    pub const ALL: [DirkTable; 10] = [
        DirkTable::Trbdf2,
        DirkTable::Kvaerno423,
        DirkTable::Ark324Dirk,
        DirkTable::Sdirk534,
        DirkTable::Kvaerno534,
        DirkTable::Ark436Dirk,
        DirkTable::Kvaerno745,
        DirkTable::Ark548Dirk,
        DirkTable::Esdirk324,
        DirkTable::Esdirk436,
    ];

    /// ARKODE's name of the table (`ARKStepSetTableName`), e.g. `ARKODE_SDIRK_5_3_4`.
    pub fn name(self) -> &'static str {
        match self {
            DirkTable::Trbdf2 => "ARKODE_TRBDF2_3_3_2",
            DirkTable::Kvaerno423 => "ARKODE_KVAERNO_4_2_3",
            DirkTable::Ark324Dirk => "ARKODE_ARK324L2SA_DIRK_4_2_3",
            DirkTable::Esdirk324 => "ARKODE_ESDIRK324L2SA_4_2_3",
            DirkTable::Sdirk534 => "ARKODE_SDIRK_5_3_4",
            DirkTable::Kvaerno534 => "ARKODE_KVAERNO_5_3_4",
            DirkTable::Ark436Dirk => "ARKODE_ARK436L2SA_DIRK_6_3_4",
            DirkTable::Esdirk436 => "ARKODE_ESDIRK436L2SA_6_3_4",
            DirkTable::Kvaerno745 => "ARKODE_KVAERNO_7_4_5",
            DirkTable::Ark548Dirk => "ARKODE_ARK548L2SA_DIRK_8_4_5",
        }
    }

    /// The method's order of accuracy (the last number of the name).
    pub fn order(self) -> usize {
        match self {
            DirkTable::Trbdf2 => 2,
            DirkTable::Kvaerno423 | DirkTable::Ark324Dirk | DirkTable::Esdirk324 => 3,
            DirkTable::Sdirk534
            | DirkTable::Kvaerno534
            | DirkTable::Ark436Dirk
            | DirkTable::Esdirk436 => 4,
            DirkTable::Kvaerno745 | DirkTable::Ark548Dirk => 5,
        }
    }

    /// The table named `name`: ARKODE's name, with or without its `ARKODE_` prefix, in any
    /// case (`sdirk_5_3_4`, `ARKODE_SDIRK_5_3_4`); `None` for any other name.
    pub fn from_name(name: &str) -> Option<DirkTable> {
        let upper = name.trim().to_ascii_uppercase();
        let full = if upper.starts_with("ARKODE_") {
            upper
        } else {
            format!("ARKODE_{upper}")
        };
        DirkTable::ALL.into_iter().find(|t| t.name() == full)
    }
}

impl Method {
    /// The method's order for error laws: BDF's and Adams' `max_order`, a DIRK table's own.
    pub fn order(self, max_order: usize) -> usize {
        match self {
            Method::Bdf | Method::Adams => max_order,
            Method::Dirk(t) => t.order(),
        }
    }
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
    /// Integration method (CVODE's BDF or Adams, or an ARKODE DIRK table).
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
