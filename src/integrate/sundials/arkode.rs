//! [`Arkode`]: ARKODE's ARKStep (SUNDIALS 6.4, ARKODE 5.4) as an implicit Runge–Kutta
//! integrator for any [`OdeProblem`], the alternative to CVODE's BDF.
//!
//! # The method
//! ARKStep with the whole right-hand side implicit (`fi = F`, `fe = NULL`) is a diagonally
//! implicit Runge–Kutta (DIRK) method with the Butcher table `(A, b, c)` of a [`DirkTable`]:
//! each step of size h solves, stage after stage,
//! `z_i = y_n + h Σ_{j<i} A_ij F(t_n + c_j h, z_j) + h A_ii F(t_n + c_i h, z_i)`,
//! whose Newton matrix is `I − γ J` with `γ = h A_ii` — CVODE's matrix with CVODE's sign, so
//! the problem's `newton_setup` / `newton_solve` serve both integrators unchanged (ARKODE's
//! preconditioner callbacks have CVODE's signatures). The tables offered are L-stable and
//! stiffly accurate: `R(∞) = 0` damps the unresolved stiff modes of an undamped structure,
//! and the last stage is the solution. The step is chosen by the embedded method's error
//! estimate (ARKODE's PID controller) in the same weighted RMS norm as CVODE's; the stages
//! start from the last solution (`PREDICTOR`), outputs and events use ARKODE's default Hermite
//! interpolant (its Lagrange interpolant was as accurate on the friction bar and far less
//! accurate on smooth motion at large steps).
//!
//! # Why it does not replace BDF2 here
//! Measured on the reduced friction bar and multilayer sheet (`docs/performance/speed.md`,
//! *What sets the step size*): the best third-order tables take fewer steps than BDF2 at equal
//! true accuracy, but each step costs ~12 right-hand sides, ~7 Newton iterations and ~0.5
//! Newton setups (every stage is a nonlinear solve across the contact law's kinks, and
//! convergence failures are frequent), so BDF2 stays 2–2.5× cheaper; the fourth-order tables'
//! steps collapse and they miss by up to 16 % (likely order reduction: their stage order is
//! below the method's, and on the stiff penalty and slip-relaxation components the embedded
//! estimate stops tracking the error).
//!
//! # What it shares with [`super::Cvode`]
//! The trampolines (`callbacks`: panics caught, NaN/Inf recoverable), the boxed problem as
//! `user_data`, the problem's Newton solver through the same custom `SUNLinearSolver`
//! (`problem_ls`, declared iterative so that ARKLS calls `newton_setup` on its own schedule),
//! or a dense LU with difference quotients. Counters map into [`OdeStats`] (ARKODE's implicit
//! right-hand sides are `rhs_evals`); `last_order` is the table's order.
//!
//! # Ownership
//! Field order = drop order: `ARKStepFree` → linear solver → matrix → vector → problem →
//! context, the order of the ARKODE guide.

use std::ffi::{c_int, c_long, c_void, CString};

use sundials_sys::{SUNDenseMatrix, SUNLinSol_Dense};

use super::callbacks::{self, Failure, Shared};
use super::cvode::{
    callback_error, check_flag, check_state, check_stop_time, poisoned_failure, read_counter,
    root_directions, SharedBox,
};
use super::ffi::{
    ARKStepCreate, ARKStepEvolve, ARKStepGetCurrentTime, ARKStepGetDky, ARKStepGetLastStep,
    ARKStepGetLinReturnFlagName, ARKStepGetNumErrTestFails, ARKStepGetNumGEvals,
    ARKStepGetNumJacEvals, ARKStepGetNumLinRhsEvals, ARKStepGetNumLinSolvSetups,
    ARKStepGetNumNonlinSolvConvFails, ARKStepGetNumNonlinSolvIters, ARKStepGetNumPrecEvals,
    ARKStepGetNumPrecSolves, ARKStepGetNumRhsEvals, ARKStepGetNumSteps, ARKStepGetReturnFlagName,
    ARKStepGetRootInfo, ARKStepReInit, ARKStepRootInit, ARKStepSStolerances, ARKStepSVtolerances,
    ARKStepSetEpsLin, ARKStepSetErrHandlerFn, ARKStepSetFixedStepBounds, ARKStepSetInitStep,
    ARKStepSetLinearSolver, ARKStepSetMaxNumSteps, ARKStepSetMaxStep, ARKStepSetNoInactiveRootWarn,
    ARKStepSetPreconditioner, ARKStepSetPredictorMethod, ARKStepSetRootDirection,
    ARKStepSetStopTime, ARKStepSetTableName, ARKStepSetUserData, ARK_NORMAL, ARK_ROOT_RETURN,
};
use super::owners::{ArkodeMemory, LinearSolver, Matrix, Owned};
use super::{cvode_flag, problem_ls, take_c_string, Context, SerialVector};
use crate::error::{CallbackOutcome, Error, IntegrationError};
use crate::integrate::problem::{
    DirkTable, Iteration, Method, NewtonLinear, OdeOptions, OdeProblem, OdeStats, Stop,
};

/// ARKLS's tolerance factor for the problem's solver: small, so that every Newton iteration is
/// solved (as for CVODE, see `problem_ls`).
const PROBLEM_EPS_LIN: f64 = 1e-10;

/// ARKODE's predictor of the stages' initial guesses: 0 = the last step's solution (ARKODE's
/// default). Measured on the friction bar's 1 % model (rtol 1e-7): the maximum-order
/// interpolant (1) took 2.8× the steps with KVAERNO_4_2_3 — the interpolant extrapolates the
/// unresolved stiff components, and the kinks of the contact law, into the guess.
const PREDICTOR: c_int = 0;

/// The ARKODE name of an ARKStep return flag (`ARKStepGetReturnFlagName`), e.g.
/// `ARK_TOO_MUCH_WORK` for −1.
pub fn arkode_flag_name(flag: i32) -> String {
    // SAFETY: ARKStepGetReturnFlagName accepts any value and returns a malloc'ed string (or
    // null), whose ownership passes to `take_c_string`.
    unsafe { take_c_string(ARKStepGetReturnFlagName(flag.into())) }
}

/// The name of a return flag of ARKODE's linear-solver interface
/// (`ARKStepGetLinReturnFlagName`), e.g. `ARKLS_SUNLS_FAIL`.
pub fn arkode_ls_flag_name(flag: i32) -> String {
    // SAFETY: as in `arkode_flag_name`.
    unsafe { take_c_string(ARKStepGetLinReturnFlagName(flag.into())) }
}

/// Which linear solver is attached (decides which counters [`Arkode::stats`] reads).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Linear {
    DenseDq,
    Problem,
}

/// An ARKStep DIRK integrator driving an [`OdeProblem`] (see the module docs). The same
/// interface as [`super::Cvode`].
pub struct Arkode<P: OdeProblem> {
    // Field order = drop order: ARKStepFree, linear solver, matrix, vector, problem, context.
    mem: Owned<ArkodeMemory>,
    ls: Option<Owned<LinearSolver>>,
    matrix: Option<Owned<Matrix>>,
    y: SerialVector,
    shared: SharedBox<P>,
    _context: Context,
    /// Time of `y`, s.
    t: f64,
    table: DirkTable,
    linear: Linear,
    /// Counters accumulated before the last `reinit` (ARKStepReInit resets ARKODE's).
    base: OdeStats,
    /// After `reinit`, ARKLS's counters are reset only by the next `ARKStepEvolve` call.
    ls_counters_stale: bool,
    roots_found: u64,
    /// `y` before the current `solve_to`.
    saved_y: Vec<f64>,
    /// Internal steps allowed over the whole run (as for [`super::Cvode`]).
    max_steps: u64,
}

impl<P: OdeProblem> Arkode<P> {
    /// Creates the integrator for `problem` with `y(t0) = y0` and the options `opts`, whose
    /// method must be [`Method::Dirk`]; creates its own SUNDIALS context.
    ///
    /// # Errors
    /// [`Error::Integration`] naming the field for a bad option (`method` not a DIRK table,
    /// functional iteration, tolerances, `max_steps` 0, negative `max_step`/`init_step`,
    /// `stab_lim_det` on, Newton with the problem's solver for a problem without one), a `y0` of
    /// the wrong length or with NaN/Inf; [`Error::Sundials`] naming the C function if SUNDIALS
    /// refuses something.
    pub fn new(problem: P, t0: f64, y0: &[f64], opts: &OdeOptions) -> Result<Self, Error> {
        let n = problem.dim();
        let nroots = problem.num_roots();
        let (table, linear) = validate(&problem, t0, y0, opts)?;
        let context = Context::new()?;
        let y = SerialVector::from_slice(&context, y0)?;
        // SAFETY: the context and `y` are live; ARKStepCreate copies `y0` into new memory (or
        // returns null), which only `mem` frees. fe = NULL: the whole right-hand side implicit.
        let mem = unsafe {
            let raw = ARKStepCreate(
                None,
                Some(callbacks::rhs::<P>),
                t0,
                y.as_raw(),
                context.as_raw(),
            );
            Owned::new(raw, "ARKStepCreate", &context)
        }?;
        let shared = SharedBox::new(Shared {
            problem,
            n,
            nroots,
            failure: None,
            poisoned: false,
            cvode_message: None,
            warnings: 0,
            ewt_rtol: 0.0,
            ewt_atol: Vec::new(),
        });
        let mut ark = Arkode {
            mem,
            ls: None,
            matrix: None,
            y,
            shared,
            _context: context.clone(),
            t: t0,
            table,
            linear,
            base: OdeStats::default(),
            ls_counters_stale: false,
            roots_found: 0,
            saved_y: Vec::with_capacity(n),
            max_steps: opts.max_steps as u64,
        };
        ark.init(&context, opts)?;
        match linear {
            Linear::DenseDq => ark.attach_dense_dq(&context)?,
            Linear::Problem => ark.attach_problem_solver(&context)?,
        }
        ark.set_step_options(opts)?;
        Ok(ark)
    }

    /// Error handler, tolerances (per component when the problem gives a scale), user data and
    /// the Butcher table.
    fn init(&mut self, context: &Context, opts: &OdeOptions) -> Result<(), Error> {
        let m = self.mem.as_raw();
        let user_data = self.shared.as_user_data();
        let mut scale = vec![0.0; self.shared.get().n];
        let atol_vector = if self.shared.get().problem.atol_scale(&mut scale) {
            if let Some((i, s)) = scale
                .iter()
                .enumerate()
                .find(|(_, s)| !(s.is_finite() && **s > 0.0))
            {
                return Err(IntegrationError::ToleranceScale {
                    index: i,
                    value: *s,
                }
                .into());
            }
            scale.iter_mut().for_each(|s| *s *= opts.atol);
            Some(SerialVector::from_slice(context, &scale)?)
        } else {
            None
        };
        // Table names are ASCII constants without NUL.
        let itable = CString::new(self.table.name()).unwrap_or_default();
        let etable = CString::new("ARKODE_ERK_NONE").unwrap_or_default();
        // SAFETY: (also for the blocks of the other attach/set methods called by `new` that say
        // "as in `init`") `m` is live ARKODE memory owned by `self`; `user_data` points to the
        // boxed Shared<P> that `self` frees only after ARKStepFree; vectors, matrices and
        // solvers passed are owned by `self` (or copied by ARKODE: the tolerance vector, the
        // table names) and outlive the memory. The trampolines' type parameter is this problem
        // type.
        unsafe {
            self.check(
                "ARKStepSetErrHandlerFn",
                ARKStepSetErrHandlerFn(m, Some(callbacks::error_handler::<P>), user_data),
            )?;
            match &atol_vector {
                Some(v) => self.check(
                    "ARKStepSVtolerances",
                    ARKStepSVtolerances(m, opts.rtol, v.as_raw()),
                )?,
                None => self.check(
                    "ARKStepSStolerances",
                    ARKStepSStolerances(m, opts.rtol, opts.atol),
                )?,
            }
            self.check("ARKStepSetUserData", ARKStepSetUserData(m, user_data))?;
            self.check(
                "ARKStepSetTableName",
                ARKStepSetTableName(m, itable.as_ptr(), etable.as_ptr()),
            )?;
            self.check(
                "ARKStepSetPredictorMethod",
                ARKStepSetPredictorMethod(m, PREDICTOR),
            )?;
        }
        Ok(())
    }

    /// Newton with a dense LU and ARKODE's difference-quotient Jacobian.
    fn attach_dense_dq(&mut self, context: &Context) -> Result<(), Error> {
        let m = self.mem.as_raw();
        let nn = self.shared.get().n as i64;
        // SAFETY: the context is live; the new matrix (or null) is owned by `a` alone.
        let a = unsafe {
            Owned::<Matrix>::new(
                SUNDenseMatrix(nn, nn, context.as_raw()),
                "SUNDenseMatrix",
                context,
            )
        }?;
        // SAFETY: `y` and `a` are live and compatible; the new solver is owned by `ls` alone.
        let ls = unsafe {
            let raw = SUNLinSol_Dense(self.y.as_raw(), a.as_raw(), context.as_raw());
            Owned::<LinearSolver>::new(raw, "SUNLinSol_Dense", context)
        }?;
        let (ls_raw, a_raw) = (ls.as_raw(), a.as_raw());
        self.matrix = Some(a);
        self.ls = Some(ls);
        // SAFETY: as in `init`. No Jacobian function: ARKODE's difference quotients.
        unsafe {
            self.check_ls(
                "ARKStepSetLinearSolver",
                ARKStepSetLinearSolver(m, ls_raw, a_raw),
            )
        }
    }

    /// Newton with the problem's own solver through `problem_ls` (matrix-free).
    fn attach_problem_solver(&mut self, context: &Context) -> Result<(), Error> {
        let m = self.mem.as_raw();
        let ls = problem_ls::new(context)?;
        let ls_raw = ls.as_raw();
        self.ls = Some(ls);
        // SAFETY: as in `init`; the solver is matrix-free (NULL matrix).
        unsafe {
            self.check_ls(
                "ARKStepSetLinearSolver",
                ARKStepSetLinearSolver(m, ls_raw, std::ptr::null_mut()),
            )?;
            self.check_ls(
                "ARKStepSetPreconditioner",
                ARKStepSetPreconditioner(
                    m,
                    Some(callbacks::newton_setup::<P>),
                    Some(callbacks::newton_solve::<P>),
                ),
            )?;
            self.check_ls("ARKStepSetEpsLin", ARKStepSetEpsLin(m, PROBLEM_EPS_LIN))
        }
    }

    /// Steps, step sizes, the step-growth threshold, and the event functions.
    fn set_step_options(&mut self, opts: &OdeOptions) -> Result<(), Error> {
        let m = self.mem.as_raw();
        let nroots = self.shared.get().nroots;
        let max_steps = c_long::try_from(opts.max_steps).unwrap_or(c_long::MAX);
        // SAFETY: as in `init`.
        unsafe {
            self.check("ARKStepSetMaxNumSteps", ARKStepSetMaxNumSteps(m, max_steps))?;
            if opts.max_step > 0.0 {
                self.check("ARKStepSetMaxStep", ARKStepSetMaxStep(m, opts.max_step))?;
            }
            if opts.init_step > 0.0 {
                self.check("ARKStepSetInitStep", ARKStepSetInitStep(m, opts.init_step))?;
            }
            self.check(
                "ARKStepSetFixedStepBounds",
                ARKStepSetFixedStepBounds(m, 1.0, opts.step_growth),
            )?;
            if nroots > 0 {
                let nr = c_int::try_from(nroots).map_err(|_| IntegrationError::TooLarge {
                    what: "num_roots()",
                    value: nroots,
                })?;
                self.check(
                    "ARKStepRootInit",
                    ARKStepRootInit(m, nr, Some(callbacks::roots::<P>)),
                )?;
                self.check(
                    "ARKStepSetNoInactiveRootWarn",
                    ARKStepSetNoInactiveRootWarn(m),
                )?;
            }
        }
        Ok(())
    }

    /// Integrates to `tout` (`ARK_NORMAL`: internal steps past `tout`, then interpolation); as
    /// [`super::Cvode::solve_to`].
    ///
    /// # Errors
    /// As [`super::Cvode::solve_to`], naming `ARKStepEvolve` and ARKODE's flags.
    pub fn solve_to(&mut self, tout: f64) -> Result<Stop, Error> {
        if !tout.is_finite() {
            return Err(IntegrationError::TimeNotFinite {
                function: "solve_to",
                name: "tout",
                value: tout,
            }
            .into());
        }
        if let Some(failure) = self.poisoned_failure() {
            return Err(callback_error(failure, CallbackOutcome::NotRun));
        }
        if tout == self.t {
            return Ok(Stop::Reached(self.t));
        }
        {
            let shared = self.shared.get_mut();
            shared.failure = None;
            shared.cvode_message = None;
        }
        self.saved_y.clear();
        self.saved_y.extend_from_slice(self.y.as_slice());
        let left = self
            .max_steps
            .saturating_sub(self.current_stats().steps)
            .max(1);
        let left = c_long::try_from(left).unwrap_or(c_long::MAX);
        // SAFETY: memory live and owned by `self`.
        let f = unsafe { ARKStepSetMaxNumSteps(self.mem.as_raw(), left) };
        self.check("ARKStepSetMaxNumSteps", f)?;
        let mut t = self.t;
        // SAFETY: the memory and `y` are live and owned by `self`; no Rust reference to the
        // shared state or to `y`'s data is held across the call.
        let flag =
            unsafe { ARKStepEvolve(self.mem.as_raw(), tout, self.y.as_raw(), &mut t, ARK_NORMAL) };
        let t_before = self.t;
        if t.is_finite() {
            self.t = t;
        }
        if flag >= 0 || self.raw_counter(ARKStepGetNumSteps) > 0 {
            self.ls_counters_stale = false;
        }
        if flag == ARK_ROOT_RETURN {
            let nroots = self.shared.get().nroots;
            let mut info = vec![0 as c_int; nroots];
            // SAFETY: `info` holds `nroots` writable ints, the number given to ARKStepRootInit.
            let f = unsafe { ARKStepGetRootInfo(self.mem.as_raw(), info.as_mut_ptr()) };
            self.check("ARKStepGetRootInfo", f)?;
            self.roots_found += 1;
            return Ok(Stop::Root {
                t: self.t,
                roots: info,
            });
        }
        if flag >= 0 {
            return Ok(Stop::Reached(self.t));
        }
        Err(self.evolve_error(flag, t_before))
    }

    /// The error of a failed `ARKStepEvolve` (flag < 0), with `t`/`y` made consistent.
    fn evolve_error(&mut self, flag: c_int, t_before: f64) -> Error {
        let shared = self.shared.get_mut();
        let failure = shared.failure.take();
        let message = shared.cvode_message.take();
        let flag = cvode_flag(flag, arkode_flag_name, message);
        let mut reached = self.t;
        // SAFETY: memory live; valid out-pointer.
        if unsafe { ARKStepGetCurrentTime(self.mem.as_raw(), &mut reached) } != 0 {
            reached = self.t;
        }
        // SAFETY: memory and `y` live; ARKStepGetDky writes n entries into `y`.
        if unsafe { ARKStepGetDky(self.mem.as_raw(), reached, 0, self.y.as_raw()) } == 0 {
            self.t = reached;
        } else {
            let saved = std::mem::take(&mut self.saved_y);
            self.y.as_mut_slice().copy_from_slice(&saved);
            self.saved_y = saved;
            self.t = t_before;
            reached = t_before;
        }
        match failure {
            Some(f) if f.fatal || f.time >= reached => {
                callback_error(f, CallbackOutcome::Returned { flag, t: reached })
            }
            _ => Error::Sundials {
                function: "ARKStepEvolve",
                flag,
                time: reached,
            },
        }
    }

    /// Current time, s.
    pub fn t(&self) -> f64 {
        self.t
    }

    /// Current state.
    pub fn y(&self) -> &[f64] {
        self.y.as_slice()
    }

    /// Restarts the integration at `(t, y)` (`ARKStepReInit`): history discarded, options,
    /// solvers and event functions kept; statistics stay cumulative.
    ///
    /// # Errors
    /// As [`super::Cvode::reinit`], naming `ARKStepReInit`.
    pub fn reinit(&mut self, t: f64, y: &[f64]) -> Result<(), Error> {
        check_state("reinit", t, y, self.shared.get().n)?;
        let accumulated = self.current_stats();
        self.y.as_mut_slice().copy_from_slice(y);
        // SAFETY: memory and vector live and owned by `self`; ARKStepReInit copies `y`.
        let flag = unsafe {
            ARKStepReInit(
                self.mem.as_raw(),
                None,
                Some(callbacks::rhs::<P>),
                t,
                self.y.as_raw(),
            )
        };
        self.check("ARKStepReInit", flag)?;
        self.base = accumulated;
        self.ls_counters_stale = true;
        self.t = t;
        let shared = self.shared.get_mut();
        shared.poisoned = false;
        shared.failure = None;
        Ok(())
    }

    /// As [`super::Cvode::set_stop_time`] (`ARKStepSetStopTime`).
    ///
    /// # Errors
    /// [`Error::Integration`] for a non-finite `tstop`; [`Error::Sundials`] naming
    /// `ARKStepSetStopTime`.
    pub fn set_stop_time(&mut self, tstop: f64) -> Result<(), Error> {
        check_stop_time(tstop)?;
        // SAFETY: memory live and owned by `self`.
        let flag = unsafe { ARKStepSetStopTime(self.mem.as_raw(), tstop) };
        self.check("ARKStepSetStopTime", flag)
    }

    /// As [`super::Cvode::set_root_direction`] (`ARKStepSetRootDirection`).
    ///
    /// # Errors
    /// As [`super::Cvode::set_root_direction`].
    pub fn set_root_direction(&mut self, directions: &[i32]) -> Result<(), Error> {
        let Some(mut dirs) = root_directions(self.shared.get().nroots, directions)? else {
            return Ok(());
        };
        // SAFETY: memory live; `dirs` holds `nroots` ints, copied by ARKODE.
        let flag = unsafe { ARKStepSetRootDirection(self.mem.as_raw(), dirs.as_mut_ptr()) };
        self.check("ARKStepSetRootDirection", flag)
    }

    /// Solver statistics, cumulative since creation (across `reinit`): `rhs_evals` counts the
    /// implicit right-hand sides, `nonlinear_iterations` the Newton iterations of all stages,
    /// `last_order` is the table's order.
    pub fn stats(&self) -> OdeStats {
        self.current_stats()
    }

    /// As [`super::Cvode::set_max_steps`].
    pub fn set_max_steps(&mut self, total: u64) {
        self.max_steps = total;
    }

    /// Number of warnings ARKODE reported (not printed).
    pub fn warnings(&self) -> u64 {
        self.shared.get().warnings
    }

    /// The Butcher table.
    pub fn table(&self) -> DirkTable {
        self.table
    }

    /// The problem.
    pub fn problem(&self) -> &P {
        &self.shared.get().problem
    }

    /// The problem, writable.
    pub fn problem_mut(&mut self) -> &mut P {
        &mut self.shared.get_mut().problem
    }

    /// Frees the integrator (in the guide's order) and returns the problem.
    pub fn into_problem(self) -> P {
        let Arkode {
            mem,
            ls,
            matrix,
            y,
            shared,
            _context,
            ..
        } = self;
        drop(mem);
        drop(ls);
        drop(matrix);
        drop(y);
        shared.into_inner().problem
    }

    fn poisoned_failure(&self) -> Option<Failure> {
        poisoned_failure(self.shared.get(), self.t)
    }

    /// An ARKODE counter (0 if ARKODE refuses).
    fn raw_counter(&self, get: unsafe extern "C" fn(*mut c_void, *mut c_long) -> c_int) -> u64 {
        read_counter(self.mem.as_raw(), get)
    }

    fn current_stats(&self) -> OdeStats {
        let c = |get| self.raw_counter(get);
        let ls = |get| {
            if self.ls_counters_stale {
                0
            } else {
                self.raw_counter(get)
            }
        };
        let nni = c(ARKStepGetNumNonlinSolvIters);
        let (rhs_jac, jac, solves) = match self.linear {
            Linear::DenseDq => (ls(ARKStepGetNumLinRhsEvals), ls(ARKStepGetNumJacEvals), nni),
            Linear::Problem => (
                ls(ARKStepGetNumLinRhsEvals),
                ls(ARKStepGetNumPrecEvals),
                ls(ARKStepGetNumPrecSolves),
            ),
        };
        let (mut nfe, mut nfi): (c_long, c_long) = (0, 0);
        let mut step = 0.0;
        // SAFETY: memory live; valid out-pointers.
        unsafe {
            if ARKStepGetNumRhsEvals(self.mem.as_raw(), &mut nfe, &mut nfi) != 0 {
                nfi = 0;
            }
            if ARKStepGetLastStep(self.mem.as_raw(), &mut step) != 0 {
                step = 0.0;
            }
        }
        let b = &self.base;
        OdeStats {
            steps: b.steps + c(ARKStepGetNumSteps),
            rhs_evals: b.rhs_evals + u64::try_from(nfi).unwrap_or(0),
            rhs_evals_jac: b.rhs_evals_jac + rhs_jac,
            nonlinear_iterations: b.nonlinear_iterations + nni,
            nonlinear_conv_failures: b.nonlinear_conv_failures
                + c(ARKStepGetNumNonlinSolvConvFails),
            error_test_failures: b.error_test_failures + c(ARKStepGetNumErrTestFails),
            linear_setups: b.linear_setups + c(ARKStepGetNumLinSolvSetups),
            jacobian_evals: b.jacobian_evals + jac,
            linear_solves: b.linear_solves + solves,
            root_evals: b.root_evals
                + if self.shared.get().nroots > 0 {
                    c(ARKStepGetNumGEvals)
                } else {
                    0
                },
            roots_found: self.roots_found,
            last_order: self.table.order() as i32,
            last_step: if step != 0.0 { step } else { b.last_step },
            ..OdeStats::default()
        }
    }

    /// Checks an ARKStep return code.
    fn check(&mut self, function: &'static str, flag: c_int) -> Result<(), Error> {
        self.check_with(function, flag, arkode_flag_name)
    }

    /// Checks an ARKLS (linear-solver interface) return code.
    fn check_ls(&mut self, function: &'static str, flag: c_int) -> Result<(), Error> {
        self.check_with(function, flag, arkode_ls_flag_name)
    }

    fn check_with(
        &mut self,
        function: &'static str,
        flag: c_int,
        name: fn(i32) -> String,
    ) -> Result<(), Error> {
        check_flag(self.shared.get_mut(), function, flag, name, self.t)
    }
}

/// Checks the problem, initial state and options before any C call; the table and the linear
/// solver to attach.
fn validate<P: OdeProblem>(
    problem: &P,
    t0: f64,
    y0: &[f64],
    o: &OdeOptions,
) -> Result<(DirkTable, Linear), Error> {
    let n = problem.dim();
    if n == 0 {
        return Err(IntegrationError::EmptyProblem.into());
    }
    check_state("Arkode::new", t0, y0, n)?;
    let bad = |field: &'static str, value: String, need: &str| -> Error {
        IntegrationError::Option {
            field,
            value,
            need: need.to_string(),
        }
        .into()
    };
    let table = match o.method {
        Method::Dirk(t) => t,
        m => return Err(bad("method", format!("{m:?}"), "a DIRK table for ARKODE")),
    };
    if !(o.rtol.is_finite() && o.rtol >= 0.0) {
        return Err(bad("rtol", o.rtol.to_string(), "finite and ≥ 0"));
    }
    if !(o.atol.is_finite() && o.atol >= 0.0) {
        return Err(bad("atol", o.atol.to_string(), "finite and ≥ 0"));
    }
    if o.rtol == 0.0 && o.atol == 0.0 {
        return Err(bad(
            "rtol",
            "0 (with atol = 0)".into(),
            "positive if atol is 0",
        ));
    }
    if o.max_steps == 0 {
        return Err(bad("max_steps", "0".into(), "≥ 1"));
    }
    if !(o.max_step.is_finite() && o.max_step >= 0.0) {
        return Err(bad(
            "max_step",
            o.max_step.to_string(),
            "finite and ≥ 0 (0: no limit)",
        ));
    }
    if !(o.init_step.is_finite() && o.init_step >= 0.0) {
        return Err(bad(
            "init_step",
            o.init_step.to_string(),
            "finite and ≥ 0 (0: estimated)",
        ));
    }
    if !(o.step_growth.is_finite() && o.step_growth >= 1.0) {
        return Err(bad(
            "step_growth",
            o.step_growth.to_string(),
            "finite and ≥ 1",
        ));
    }
    if o.stab_lim_det {
        return Err(bad(
            "stab_lim_det",
            "true".into(),
            "false with a DIRK method (BDF only)",
        ));
    }
    match o.iteration {
        Iteration::Functional { .. } => Err(bad(
            "iteration",
            "Functional".into(),
            "Newton with a DIRK method (ARKODE's fixed-point iteration is not offered)",
        )),
        Iteration::Newton {
            linear: NewtonLinear::DenseDq,
        } => Ok((table, Linear::DenseDq)),
        Iteration::Newton {
            linear: NewtonLinear::Problem,
        } if !problem.has_newton_solver() => Err(bad(
            "iteration",
            "Newton { linear: Problem }".into(),
            "DenseDq: the problem has no Newton solver (has_newton_solver() is false)",
        )),
        Iteration::Newton {
            linear: NewtonLinear::Problem,
        } => Ok((table, Linear::Problem)),
    }
}
