//! [`Cvode`]: a safe CVODE (SUNDIALS 6.4) integrator for any [`OdeProblem`].
//!
//! # The method
//! CVODE integrates `y' = F(t, y)` with variable-order, variable-step linear multistep formulas
//! `y_n = Σ α_j y_{n−j} + h β_0 F(t_n, y_n) + …` — BDF of orders 1–5 (the paper's choice for the
//! stiff contact problems) or Adams–Moulton of orders 1–12. Each step solves the implicit
//! equation `G(y_n) = y_n − γ F(t_n, y_n) − a_n = 0` (γ = h β_0) by
//! - **functional iteration** (`SUNNonlinSol_FixedPoint`, optional Anderson acceleration of
//!   depth m): `y ← γ F(t_n, y) + a_n`; it converges only while `γ ‖J‖ ≲ 1`, i.e. the step is
//!   bounded by the stiffest mode, whatever the accuracy needs;
//! - **modified Newton**: `(I − γ J) δ = −G(y)`, with either a dense LU of `I − γJ` and J by
//!   CVODE's difference quotients ([`NewtonLinear::DenseDq`]) or the problem's own solver
//!   ([`NewtonLinear::Problem`], e.g. the structured `M + γ C + γ² K_t` of a second-order model,
//!   see `problem_ls`).
//!
//! Undamped structures have eigenvalues ±iω on the imaginary axis, where BDF of orders 3–5 are
//! not A-stable; [`OdeOptions::stab_lim_det`] switches on CVODE's stability-limit detection,
//! which lowers the order when it sees the instability.
//!
//! Events: with `problem.num_roots() > 0` CVODE locates sign changes of `g(t, y)` between steps
//! (to about `100 U (|t| + |h|)`, U = 2.2e-16: ~1e-13 s for t ≤ 1 s, well below the paper's
//! tolerance on time of 1e-10) and [`Cvode::solve_to`] stops there with [`Stop::Root`].
//!
//! # Ownership
//! Each `Cvode` creates its own [`Context`] (a `SUNContext` is not thread-safe; `Cvode` is
//! neither `Send` nor `Sync`) and owns, one RAII value per C object, the CVODE memory, the
//! nonlinear solver (functional iteration only; CVODE owns its default Newton solver), the
//! linear solver, the dense matrix, the state vector and the problem (boxed: its address is
//! CVODE's `user_data`). They are freed in the order of the CVODE guide: `CVodeFree` →
//! nonlinear solver → linear solver → matrix → vector → problem → context.
//!
//! # Errors
//! Every return code is checked: [`Error::Sundials`] names the C function, the flag (CVODE's
//! name, plus CVODE's own message where it gave one) and the time reached; a failing callback
//! gives [`Error::Callback`] with the callback's name, last message, time and the flag. See
//! `callbacks` for panics and NaN/Inf.

use std::ffi::{c_int, c_long, c_void};
use std::ptr::NonNull;

use sundials_sys::{
    CVode, CVodeCreate, CVodeGetCurrentTime, CVodeGetDky, CVodeGetLastOrder, CVodeGetLastStep,
    CVodeGetNumErrTestFails, CVodeGetNumGEvals, CVodeGetNumJacEvals, CVodeGetNumLinRhsEvals,
    CVodeGetNumLinSolvSetups, CVodeGetNumNonlinSolvConvFails, CVodeGetNumNonlinSolvIters,
    CVodeGetNumPrecEvals, CVodeGetNumPrecSolves, CVodeGetNumRhsEvals, CVodeGetNumStabLimOrderReds,
    CVodeGetNumSteps, CVodeGetRootInfo, CVodeInit, CVodeReInit, CVodeRootInit, CVodeSStolerances,
    CVodeSVtolerances, CVodeSetEpsLin, CVodeSetErrHandlerFn, CVodeSetEtaFixedStepBounds,
    CVodeSetInitStep, CVodeSetLinearSolver, CVodeSetMaxNumSteps, CVodeSetMaxOrd, CVodeSetMaxStep,
    CVodeSetNoInactiveRootWarn, CVodeSetNonlinearSolver, CVodeSetPreconditioner,
    CVodeSetRootDirection, CVodeSetStabLimDet, CVodeSetStopTime, CVodeSetUserData,
    CVodeWFtolerances, SUNDenseMatrix, SUNLinSol_Dense, SUNNonlinSol_FixedPoint, CV_ADAMS, CV_BDF,
    CV_NORMAL, CV_ROOT_RETURN,
};

use super::callbacks::{self, Failure, Shared};
use super::owners::{CvodeMemory, LinearSolver, Matrix, NonlinearSolver, Owned};
use super::{cvode_flag, cvode_flag_name, cvode_ls_flag_name, problem_ls, Context, SerialVector};
use crate::error::{CallbackOutcome, Error, IntegrationError};
use crate::integrate::problem::{
    Iteration, Method, NewtonLinear, OdeOptions, OdeProblem, OdeStats, Stop,
};

/// CVLS's tolerance factor ε_L for jointrom's problem solver: small, so that CVLS skips the
/// Newton solve only when the residual is negligible (`‖b‖ ≤ ε_L · tq[4]`), as a direct solver
/// never does. (CVODE's default 0.05 would let the first Newton iteration take `x = b`.)
const PROBLEM_EPS_LIN: f64 = 1e-10;

/// Which linear solver is attached (decides which counters [`Cvode::stats`] reads).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Linear {
    /// Functional iteration: no linear solver.
    None,
    /// Dense LU with difference-quotient Jacobian.
    DenseDq,
    /// The problem's solver through [`problem_ls`].
    Problem,
}

/// Owns the boxed [`Shared`] state whose address CVODE holds as `user_data`.
pub(super) struct SharedBox<P> {
    ptr: NonNull<Shared<P>>,
}

impl<P> SharedBox<P> {
    pub(super) fn new(shared: Shared<P>) -> Self {
        Self {
            ptr: NonNull::from(Box::leak(Box::new(shared))),
        }
    }

    /// The shared state. Valid while no CVODE call is under way (callbacks only run inside
    /// methods taking `&mut Cvode`, which hold no reference from here across the call).
    pub(super) fn get(&self) -> &Shared<P> {
        // SAFETY: the pointer came from Box::leak and is freed only in Drop / into_inner.
        unsafe { self.ptr.as_ref() }
    }

    pub(super) fn get_mut(&mut self) -> &mut Shared<P> {
        // SAFETY: as in `get`; `&mut self` excludes other Rust references.
        unsafe { self.ptr.as_mut() }
    }

    pub(super) fn as_user_data(&self) -> *mut c_void {
        self.ptr.as_ptr().cast()
    }

    pub(super) fn into_inner(self) -> Shared<P> {
        let this = std::mem::ManuallyDrop::new(self);
        // SAFETY: the pointer came from Box::leak; `Drop` will not run for `this`.
        *unsafe { Box::from_raw(this.ptr.as_ptr()) }
    }
}

impl<P> Drop for SharedBox<P> {
    fn drop(&mut self) {
        // SAFETY: the pointer came from Box::leak and is freed only here (or in into_inner,
        // which suppresses this Drop). The CVODE memory holding it is freed before (field order).
        drop(unsafe { Box::from_raw(self.ptr.as_ptr()) });
    }
}

/// A CVODE integrator driving an [`OdeProblem`] (see the module docs).
///
/// ```
/// use jointrom::integrate::problem::{CallbackError, OdeOptions, OdeProblem, Stop};
/// use jointrom::integrate::Cvode;
///
/// struct Decay;
/// impl OdeProblem for Decay {
///     fn dim(&self) -> usize { 1 }
///     fn rhs(&mut self, _t: f64, y: &[f64], ydot: &mut [f64]) -> Result<(), CallbackError> {
///         ydot[0] = -y[0];
///         Ok(())
///     }
/// }
/// let opts = OdeOptions { iteration: jointrom::integrate::problem::Iteration::Functional { anderson: 0 },
///                         ..OdeOptions::default() };
/// let mut cvode = Cvode::new(Decay, 0.0, &[1.0], &opts)?;
/// assert_eq!(cvode.solve_to(1.0)?, Stop::Reached(1.0));
/// assert!((cvode.y()[0] - (-1.0f64).exp()).abs() < 1e-5); // atol = 1e-6 per step
/// # Ok::<(), jointrom::Error>(())
/// ```
pub struct Cvode<P: OdeProblem> {
    // Field order = drop order: CVodeFree, nonlinear solver, linear solver, matrix, vector,
    // problem, context.
    mem: Owned<CvodeMemory>,
    nls: Option<Owned<NonlinearSolver>>,
    ls: Option<Owned<LinearSolver>>,
    matrix: Option<Owned<Matrix>>,
    y: SerialVector,
    shared: SharedBox<P>,
    _context: Context,
    /// Time of `y`, s.
    t: f64,
    linear: Linear,
    /// Counters accumulated before the last `reinit` (CVodeReInit resets CVODE's).
    base: OdeStats,
    /// After `reinit`, CVLS's counters are reset only by the next `CVode` call.
    ls_counters_stale: bool,
    roots_found: u64,
    /// `y` before the current `solve_to` (restored if CVODE cannot report its state).
    saved_y: Vec<f64>,
    /// Internal steps allowed over the whole run (`OdeOptions::max_steps`), across `solve_to`
    /// calls and `reinit`: CVODE's own limit counts per call, so a run with many output
    /// intervals could take that many steps in each of them.
    max_steps: u64,
}

impl<P: OdeProblem> Cvode<P> {
    /// Creates the integrator for `problem` with `y(t0) = y0` and the options `opts`; creates
    /// its own SUNDIALS context.
    ///
    /// # Errors
    /// [`Error::Integration`] naming the field for a bad option (`rtol`/`atol` negative or not
    /// finite, `max_order` outside 1–5 (BDF) or 1–12 (Adams), `max_steps` 0, negative
    /// `max_step`/`init_step`, `stab_lim_det` with Adams, Newton with the problem's solver for
    /// a problem without one), a `y0` of the wrong length or with NaN/Inf, a zero dimension;
    /// [`Error::Sundials`] naming the C function if SUNDIALS refuses something.
    pub fn new(problem: P, t0: f64, y0: &[f64], opts: &OdeOptions) -> Result<Self, Error> {
        let n = problem.dim();
        let nroots = problem.num_roots();
        validate(&problem, t0, y0, opts)?;
        let context = Context::new()?;
        let y = SerialVector::from_slice(&context, y0)?;
        let lmm = match opts.method {
            Method::Bdf => CV_BDF,
            // `validate` refused a DIRK method.
            Method::Adams | Method::Dirk(_) => CV_ADAMS,
        };
        // SAFETY: the context is live; CVodeCreate returns new memory created in it, or null,
        // which only `mem` frees.
        let mem =
            unsafe { Owned::new(CVodeCreate(lmm, context.as_raw()), "CVodeCreate", &context) }?;
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
        let mut cvode = Cvode {
            mem,
            nls: None,
            ls: None,
            matrix: None,
            y,
            shared,
            _context: context.clone(),
            t: t0,
            linear: Linear::None,
            base: OdeStats::default(),
            ls_counters_stale: false,
            roots_found: 0,
            saved_y: Vec::with_capacity(n),
            max_steps: opts.max_steps as u64,
        };
        let atol_vector = cvode.atol_vector(&context, opts.atol)?;
        if let Some(v) = &atol_vector {
            let shared = cvode.shared.get_mut();
            shared.ewt_rtol = opts.rtol;
            shared.ewt_atol = v.as_slice().to_vec();
        }
        cvode.init(t0, opts, atol_vector.as_ref())?;
        match opts.iteration {
            Iteration::Functional { anderson } => cvode.attach_fixed_point(&context, anderson)?,
            Iteration::Newton {
                linear: NewtonLinear::DenseDq,
            } => cvode.attach_dense_dq(&context)?,
            Iteration::Newton {
                linear: NewtonLinear::Problem,
            } => cvode.attach_problem_solver(&context)?,
        }
        cvode.set_step_options(opts)?;
        Ok(cvode)
    }

    /// Per-component absolute tolerances `atol · scale` if the problem gives a scale
    /// ([`OdeProblem::atol_scale`]), checked finite and positive; `None` for a scalar `atol`.
    fn atol_vector(&self, context: &Context, atol: f64) -> Result<Option<SerialVector>, Error> {
        let mut scale = vec![0.0; self.shared.get().n];
        if !self.shared.get().problem.atol_scale(&mut scale) {
            return Ok(None);
        }
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
        scale.iter_mut().for_each(|s| *s *= atol);
        Ok(Some(SerialVector::from_slice(context, &scale)?))
    }

    /// Initializes the CVODE memory: error handler, right-hand side and `y(t0)`, tolerances
    /// (per component with `atol_vector`, which CVODE copies), user data.
    fn init(
        &mut self,
        t0: f64,
        opts: &OdeOptions,
        atol_vector: Option<&SerialVector>,
    ) -> Result<(), Error> {
        let m = self.mem.as_raw();
        let user_data = self.shared.as_user_data();
        // SAFETY: (also for the blocks of the other attach/set methods called by `new` that say
        // "as in `init`") `m` is live CVODE memory owned by `self`; `user_data` points to the
        // boxed Shared<P> that `self` frees only after CVodeFree; vectors, matrices and solvers
        // passed are owned by `self` and outlive the memory (field order). The trampolines'
        // type parameter is this problem type.
        unsafe {
            self.check_cv(
                "CVodeSetErrHandlerFn",
                CVodeSetErrHandlerFn(m, Some(callbacks::error_handler::<P>), user_data),
            )?;
            self.check_cv(
                "CVodeInit",
                CVodeInit(m, Some(callbacks::rhs::<P>), t0, self.y.as_raw()),
            )?;
            match atol_vector {
                Some(_) if self.shared.get().problem.adjusts_error_weights() => self.check_cv(
                    "CVodeWFtolerances",
                    CVodeWFtolerances(m, Some(callbacks::error_weights::<P>)),
                )?,
                Some(v) => self.check_cv(
                    "CVodeSVtolerances",
                    CVodeSVtolerances(m, opts.rtol, v.as_raw()),
                )?,
                None => self.check_cv(
                    "CVodeSStolerances",
                    CVodeSStolerances(m, opts.rtol, opts.atol),
                )?,
            }
            // Before the linear solver: CVLS copies user_data as the preconditioner's data.
            self.check_cv("CVodeSetUserData", CVodeSetUserData(m, user_data))?;
        }
        Ok(())
    }

    /// Functional iteration: attaches a fixed-point solver with Anderson depth `anderson`.
    fn attach_fixed_point(&mut self, context: &Context, anderson: usize) -> Result<(), Error> {
        let m = self.mem.as_raw();
        let depth = c_int::try_from(anderson).map_err(|_| IntegrationError::TooLarge {
            what: "iteration.anderson",
            value: anderson,
        })?;
        // SAFETY: `y` is a live template vector and the context is live; the new solver
        // (or null) is owned by `nls` alone.
        let nls = unsafe {
            let raw = SUNNonlinSol_FixedPoint(self.y.as_raw(), depth, context.as_raw());
            Owned::<NonlinearSolver>::new(raw, "SUNNonlinSol_FixedPoint", context)
        }?;
        let raw = nls.as_raw();
        self.nls = Some(nls);
        // SAFETY: as in `init`; `self.nls` owns the solver and frees it after CVodeFree.
        unsafe {
            self.check_cv("CVodeSetNonlinearSolver", CVodeSetNonlinearSolver(m, raw))?;
        }
        Ok(())
    }

    /// Newton with a dense LU and CVODE's difference-quotient Jacobian.
    fn attach_dense_dq(&mut self, context: &Context) -> Result<(), Error> {
        let m = self.mem.as_raw();
        // n ≤ i64::MAX: SerialVector::from_slice checked it.
        let nn = self.shared.get().n as i64;
        // SAFETY: the context is live; SUNDenseMatrix returns a new matrix (or null),
        // owned by `a` alone.
        let a = unsafe {
            let raw = SUNDenseMatrix(nn, nn, context.as_raw());
            Owned::<Matrix>::new(raw, "SUNDenseMatrix", context)
        }?;
        // SAFETY: `y` and `a` are live and compatible (n × n, length n); the new solver
        // (or null) is owned by `ls` alone.
        let ls = unsafe {
            let raw = SUNLinSol_Dense(self.y.as_raw(), a.as_raw(), context.as_raw());
            Owned::<LinearSolver>::new(raw, "SUNLinSol_Dense", context)
        }?;
        let (ls_raw, a_raw) = (ls.as_raw(), a.as_raw());
        self.matrix = Some(a);
        self.ls = Some(ls);
        self.linear = Linear::DenseDq;
        // SAFETY: as in `init`. No Jacobian function: CVODE's difference quotients.
        unsafe {
            self.check_ls(
                "CVodeSetLinearSolver",
                CVodeSetLinearSolver(m, ls_raw, a_raw),
            )?;
        }
        Ok(())
    }

    /// Newton with the problem's own solver through [`problem_ls`] (matrix-free, as a
    /// preconditioner).
    fn attach_problem_solver(&mut self, context: &Context) -> Result<(), Error> {
        let m = self.mem.as_raw();
        let ls = problem_ls::new(context)?;
        let ls_raw = ls.as_raw();
        self.ls = Some(ls);
        self.linear = Linear::Problem;
        // SAFETY: as in `init`; the solver is matrix-free (NULL matrix).
        unsafe {
            self.check_ls(
                "CVodeSetLinearSolver",
                CVodeSetLinearSolver(m, ls_raw, std::ptr::null_mut()),
            )?;
            self.check_ls(
                "CVodeSetPreconditioner",
                CVodeSetPreconditioner(
                    m,
                    Some(callbacks::newton_setup::<P>),
                    Some(callbacks::newton_solve::<P>),
                ),
            )?;
            self.check_ls("CVodeSetEpsLin", CVodeSetEpsLin(m, PROBLEM_EPS_LIN))?;
        }
        Ok(())
    }

    /// The step options (maximum order, steps and step size, initial step, stability-limit
    /// detection) and the event functions.
    fn set_step_options(&mut self, opts: &OdeOptions) -> Result<(), Error> {
        let m = self.mem.as_raw();
        let nroots = self.shared.get().nroots;
        let max_order = opts.max_order as c_int; // validated ≤ 12
        let max_steps = c_long::try_from(opts.max_steps).unwrap_or(c_long::MAX);
        // SAFETY: as in `init`.
        unsafe {
            self.check_cv("CVodeSetMaxOrd", CVodeSetMaxOrd(m, max_order))?;
            self.check_cv("CVodeSetMaxNumSteps", CVodeSetMaxNumSteps(m, max_steps))?;
            if opts.max_step > 0.0 {
                self.check_cv("CVodeSetMaxStep", CVodeSetMaxStep(m, opts.max_step))?;
            }
            if opts.init_step > 0.0 {
                self.check_cv("CVodeSetInitStep", CVodeSetInitStep(m, opts.init_step))?;
            }
            self.check_cv(
                "CVodeSetEtaFixedStepBounds",
                CVodeSetEtaFixedStepBounds(m, 0.0, opts.step_growth),
            )?;
            if opts.stab_lim_det {
                self.check_cv("CVodeSetStabLimDet", CVodeSetStabLimDet(m, 1))?;
            }
            if nroots > 0 {
                let nr = c_int::try_from(nroots).map_err(|_| IntegrationError::TooLarge {
                    what: "num_roots()",
                    value: nroots,
                })?;
                self.check_cv(
                    "CVodeRootInit",
                    CVodeRootInit(m, nr, Some(callbacks::roots::<P>)),
                )?;
                // Event functions that are identically zero at the start (e.g. the gap of an
                // open contact at rest) are legitimate: no warning.
                self.check_cv("CVodeSetNoInactiveRootWarn", CVodeSetNoInactiveRootWarn(m))?;
            }
        }
        Ok(())
    }

    /// Integrates to `tout` (CVODE's `CV_NORMAL` task: internal steps past `tout`, then
    /// interpolation). Returns [`Stop::Reached`] with the time reached (`tout`, or the stop
    /// time of [`Cvode::set_stop_time`] if that came first) or [`Stop::Root`] at an event; `y`
    /// and `t` then hold the state there.
    ///
    /// # Errors
    /// [`Error::Callback`] if a callback failed (error, panic, persistent NaN/Inf), naming it,
    /// its last message and the CVODE flag; [`Error::Sundials`] naming `CVode`, the flag (e.g.
    /// `CV_TOO_MUCH_WORK`, `CV_CONV_FAILURE`, `CV_ERR_FAILURE`) and the time reached;
    /// [`Error::Integration`] for a non-finite `tout`. After an error `t`/`y` hold the last state
    /// CVODE reached.
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
        // The run's remaining steps (at least one, so that CVODE itself reports
        // CV_TOO_MUCH_WORK when the budget is spent).
        let left = self
            .max_steps
            .saturating_sub(self.current_stats().steps)
            .max(1);
        let left = c_long::try_from(left).unwrap_or(c_long::MAX);
        // SAFETY: memory live and owned by `self`.
        let f = unsafe { CVodeSetMaxNumSteps(self.mem.as_raw(), left) };
        self.check_cv("CVodeSetMaxNumSteps", f)?;
        let mut t = self.t;
        // SAFETY: the memory and `y` are live and owned by `self`; no Rust reference to the
        // shared state or to `y`'s data is held across the call (callbacks reach them through
        // `user_data` and CVODE's own vectors).
        let flag = unsafe { CVode(self.mem.as_raw(), tout, self.y.as_raw(), &mut t, CV_NORMAL) };
        let t_before = self.t;
        if t.is_finite() {
            self.t = t;
        }
        if flag >= 0 || self.raw_counter(CVodeGetNumSteps) > 0 {
            self.ls_counters_stale = false;
        }
        if flag == CV_ROOT_RETURN {
            let nroots = self.shared.get().nroots;
            let mut info = vec![0 as c_int; nroots];
            // SAFETY: `info` holds `nroots` writable ints, the number given to CVodeRootInit.
            let f = unsafe { CVodeGetRootInfo(self.mem.as_raw(), info.as_mut_ptr()) };
            self.check_cv("CVodeGetRootInfo", f)?;
            self.roots_found += 1;
            return Ok(Stop::Root {
                t: self.t,
                roots: info,
            });
        }
        if flag >= 0 {
            return Ok(Stop::Reached(self.t));
        }
        let shared = self.shared.get_mut();
        let failure = shared.failure.take();
        let message = shared.cvode_message.take();
        let flag = cvode_flag(flag, cvode_flag_name, message);
        // The time CVODE reached (CVode leaves `t` unset on some failures, e.g. of the roots).
        let mut reached = self.t;
        // SAFETY: memory live; valid out-pointer.
        if unsafe { CVodeGetCurrentTime(self.mem.as_raw(), &mut reached) } != 0 {
            reached = self.t;
        }
        // Make `t`/`y` consistent: CVODE may have left interpolated trial values in `y` (e.g.
        // after a root-function failure). Take the solution at the time reached, or restore
        // the state before the call if CVODE cannot give it.
        // SAFETY: memory and `y` live; CVodeGetDky writes n entries into `y`.
        if unsafe { CVodeGetDky(self.mem.as_raw(), reached, 0, self.y.as_raw()) } == 0 {
            self.t = reached;
        } else {
            let saved = std::mem::take(&mut self.saved_y);
            self.y.as_mut_slice().copy_from_slice(&saved);
            self.saved_y = saved;
            self.t = t_before;
            reached = t_before;
        }
        // A callback failure explains the CVODE failure if it was fatal, or if it happened at
        // or after the time reached (during the attempts of the step that failed).
        match failure {
            Some(f) if f.fatal || f.time >= reached => Err(callback_error(
                f,
                CallbackOutcome::Returned { flag, t: reached },
            )),
            _ => Err(Error::Sundials {
                function: "CVode",
                flag,
                time: reached,
            }),
        }
    }

    /// Current time, s (the time of [`Cvode::y`]).
    pub fn t(&self) -> f64 {
        self.t
    }

    /// Current state.
    pub fn y(&self) -> &[f64] {
        self.y.as_slice()
    }

    /// Restarts the integration at `(t, y)` (`CVodeReInit`, e.g. after an event changed the
    /// problem): order 1, new initial step, history discarded; options, solvers and event
    /// functions are kept. Statistics stay cumulative. Clears the poisoning left by a panic.
    ///
    /// # Errors
    /// [`Error::Integration`] for a `y` of the wrong length or with NaN/Inf, or a non-finite `t`;
    /// [`Error::Sundials`] naming `CVodeReInit`.
    pub fn reinit(&mut self, t: f64, y: &[f64]) -> Result<(), Error> {
        check_state("reinit", t, y, self.shared.get().n)?;
        let accumulated = self.current_stats();
        self.y.as_mut_slice().copy_from_slice(y);
        // SAFETY: memory and vector live and owned by `self`; CVodeReInit copies `y`.
        let flag = unsafe { CVodeReInit(self.mem.as_raw(), t, self.y.as_raw()) };
        self.check_cv("CVodeReInit", flag)?;
        self.base = accumulated;
        self.ls_counters_stale = true;
        self.t = t;
        let shared = self.shared.get_mut();
        shared.poisoned = false;
        shared.failure = None;
        Ok(())
    }

    /// Makes the integration stop exactly at `tstop` (`CVodeSetStopTime`): no step goes past
    /// it, which matters when F is not smooth beyond it. `solve_to` returns
    /// `Stop::Reached(tstop)` when it gets there first; CVODE then forgets the stop time.
    ///
    /// # Errors
    /// [`Error::Integration`] for a non-finite `tstop`; [`Error::Sundials`] naming
    /// `CVodeSetStopTime` (e.g. `tstop` behind the current time).
    pub fn set_stop_time(&mut self, tstop: f64) -> Result<(), Error> {
        check_stop_time(tstop)?;
        // SAFETY: memory live and owned by `self`.
        let flag = unsafe { CVodeSetStopTime(self.mem.as_raw(), tstop) };
        self.check_cv("CVodeSetStopTime", flag)
    }

    /// Restricts event detection by direction (`CVodeSetRootDirection`): `+1` only rising
    /// (g from negative to positive), `−1` only falling, `0` both (the default), one entry per
    /// event function.
    ///
    /// There is no root *tolerance* to set: CVODE locates roots to `100 U (|t| + |h|)` in time
    /// (module docs), far tighter than the paper's 1e-10 s.
    ///
    /// # Errors
    /// [`Error::Integration`] if `directions` does not have `num_roots()` entries of −1, 0, +1;
    /// [`Error::Sundials`] naming `CVodeSetRootDirection`.
    pub fn set_root_direction(&mut self, directions: &[i32]) -> Result<(), Error> {
        let Some(mut dirs) = root_directions(self.shared.get().nroots, directions)? else {
            return Ok(());
        };
        // SAFETY: memory live; `dirs` holds `nroots` ints, read (copied) by CVODE.
        let flag = unsafe { CVodeSetRootDirection(self.mem.as_raw(), dirs.as_mut_ptr()) };
        self.check_cv("CVodeSetRootDirection", flag)
    }

    /// Solver statistics, cumulative since creation (across `reinit`). `last_order` and
    /// `last_step` are those of the last step. `linear_solves` counts the problem solver's
    /// solves (`CVodeGetNumPrecSolves`) for [`NewtonLinear::Problem`], and the Newton
    /// iterations (one dense back-substitution each) for [`NewtonLinear::DenseDq`];
    /// `jacobian_evals` counts difference-quotient Jacobians (`CVodeGetNumJacEvals`) or the
    /// problem setups that recomputed the Jacobian (`CVodeGetNumPrecEvals`).
    pub fn stats(&self) -> OdeStats {
        self.current_stats()
    }

    /// Raises (or lowers) the run's step budget: `solve_to` fails with `CV_TOO_MUCH_WORK` once
    /// the internal steps since creation (across `reinit`) reach `total` (at least one more
    /// step is always allowed). A caller that advances a run for an open-ended time (a
    /// co-simulation, [`crate::integrate::Stepper`]) gives each advance its own budget this way.
    pub fn set_max_steps(&mut self, total: u64) {
        self.max_steps = total;
    }

    /// Number of warnings CVODE reported (e.g. `t + h = t`), which are not printed.
    pub fn warnings(&self) -> u64 {
        self.shared.get().warnings
    }

    /// The problem.
    pub fn problem(&self) -> &P {
        &self.shared.get().problem
    }

    /// The problem, writable (e.g. to switch a contact state after an event, then `reinit`).
    pub fn problem_mut(&mut self) -> &mut P {
        &mut self.shared.get_mut().problem
    }

    /// Frees the integrator (in the guide's order) and returns the problem.
    pub fn into_problem(self) -> P {
        let Cvode {
            mem,
            nls,
            ls,
            matrix,
            y,
            shared,
            _context,
            ..
        } = self;
        drop(mem);
        drop(nls);
        drop(ls);
        drop(matrix);
        drop(y);
        shared.into_inner().problem
    }

    /// The failure that poisoned the integrator, if a callback panicked.
    fn poisoned_failure(&self) -> Option<Failure> {
        poisoned_failure(self.shared.get(), self.t)
    }

    /// A CVODE counter (0 if CVODE refuses, which it does only without the module the counter
    /// belongs to — never for the counters read here).
    fn raw_counter(&self, get: unsafe extern "C" fn(*mut c_void, *mut c_long) -> c_int) -> u64 {
        read_counter(self.mem.as_raw(), get)
    }

    /// `base` plus CVODE's current counters.
    fn current_stats(&self) -> OdeStats {
        let c = |get| self.raw_counter(get);
        let ls = |get| {
            if self.ls_counters_stale {
                0
            } else {
                self.raw_counter(get)
            }
        };
        let nni = c(CVodeGetNumNonlinSolvIters);
        let (rhs_jac, jac, solves) = match self.linear {
            Linear::None => (0, 0, 0),
            Linear::DenseDq => (ls(CVodeGetNumLinRhsEvals), ls(CVodeGetNumJacEvals), nni),
            Linear::Problem => (
                ls(CVodeGetNumLinRhsEvals),
                ls(CVodeGetNumPrecEvals),
                ls(CVodeGetNumPrecSolves),
            ),
        };
        let mut order: c_int = 0;
        let mut step = 0.0;
        // SAFETY: memory live; valid out-pointers.
        unsafe {
            if CVodeGetLastOrder(self.mem.as_raw(), &mut order) != 0 {
                order = 0;
            }
            if CVodeGetLastStep(self.mem.as_raw(), &mut step) != 0 {
                step = 0.0;
            }
        }
        let b = &self.base;
        OdeStats {
            steps: b.steps + c(CVodeGetNumSteps),
            rhs_evals: b.rhs_evals + c(CVodeGetNumRhsEvals),
            rhs_evals_jac: b.rhs_evals_jac + rhs_jac,
            nonlinear_iterations: b.nonlinear_iterations + nni,
            nonlinear_conv_failures: b.nonlinear_conv_failures + c(CVodeGetNumNonlinSolvConvFails),
            error_test_failures: b.error_test_failures + c(CVodeGetNumErrTestFails),
            linear_setups: b.linear_setups + c(CVodeGetNumLinSolvSetups),
            jacobian_evals: b.jacobian_evals + jac,
            linear_solves: b.linear_solves + solves,
            root_evals: b.root_evals
                + if self.shared.get().nroots > 0 {
                    c(CVodeGetNumGEvals)
                } else {
                    0
                },
            roots_found: self.roots_found,
            last_order: if order > 0 { order } else { b.last_order },
            last_step: if step != 0.0 { step } else { b.last_step },
            stab_lim_order_reductions: b.stab_lim_order_reductions + c(CVodeGetNumStabLimOrderReds),
            newton_refreshes: 0,
            newton_low_rank: 0,
            newton_refresh_pairs: 0,
            screen_builds: 0,
            screen_tracked_sum: 0,
            screen_tracked_max: 0,
            screen_violations: 0,
            screen_entries: 0,
            screen_exact_checks: 0,
            screen_exits: 0,
        }
    }

    /// Checks a CVODE return code.
    fn check_cv(&mut self, function: &'static str, flag: c_int) -> Result<(), Error> {
        self.check(function, flag, cvode_flag_name)
    }

    /// Checks a CVLS (linear-solver interface) return code.
    fn check_ls(&mut self, function: &'static str, flag: c_int) -> Result<(), Error> {
        self.check(function, flag, cvode_ls_flag_name)
    }

    fn check(
        &mut self,
        function: &'static str,
        flag: c_int,
        name: fn(i32) -> String,
    ) -> Result<(), Error> {
        check_flag(self.shared.get_mut(), function, flag, name, self.t)
    }
}

/// The error for a callback failure.
pub(super) fn callback_error(f: Failure, outcome: CallbackOutcome) -> Error {
    Error::Callback {
        callback: f.callback,
        message: f.message,
        time: f.time,
        outcome,
    }
}

/// The failure of a poisoned integrator (a callback panicked): the recorded one, or an unknown
/// panic at `t`.
pub(super) fn poisoned_failure<P>(shared: &Shared<P>, t: f64) -> Option<Failure> {
    shared.poisoned.then(|| {
        shared.failure.clone().unwrap_or(Failure {
            callback: "unknown",
            message: "panicked".into(),
            time: t,
            fatal: true,
        })
    })
}

/// A SUNDIALS counter read by `get` from the integrator memory `mem` (0 if it refuses).
pub(super) fn read_counter(
    mem: *mut c_void,
    get: unsafe extern "C" fn(*mut c_void, *mut c_long) -> c_int,
) -> u64 {
    let mut value: c_long = 0;
    // SAFETY: the callers pass their live integrator memory; `value` is a valid out-pointer.
    let flag = unsafe { get(mem, &mut value) };
    if flag == 0 {
        u64::try_from(value).unwrap_or(0)
    } else {
        0
    }
}

/// Checks a SUNDIALS return code of `function` at time `t`: the error names the flag (`name`)
/// with the message the error handler left in `shared` (taken in any case).
pub(super) fn check_flag<P>(
    shared: &mut Shared<P>,
    function: &'static str,
    flag: c_int,
    name: fn(i32) -> String,
    t: f64,
) -> Result<(), Error> {
    let message = shared.cvode_message.take();
    if flag >= 0 {
        return Ok(());
    }
    Err(Error::Sundials {
        function,
        flag: cvode_flag(flag, name, message),
        time: t,
    })
}

/// Checks a stop time before it goes to SUNDIALS: finite.
pub(super) fn check_stop_time(tstop: f64) -> Result<(), Error> {
    if tstop.is_finite() {
        return Ok(());
    }
    Err(IntegrationError::TimeNotFinite {
        function: "set_stop_time",
        name: "tstop",
        value: tstop,
    }
    .into())
}

/// The event directions for SUNDIALS' `SetRootDirection`: one of −1, 0, +1 per event function
/// (`nroots`); `None` without event functions (nothing to set).
pub(super) fn root_directions(
    nroots: usize,
    directions: &[i32],
) -> Result<Option<Vec<c_int>>, Error> {
    if directions.len() != nroots || directions.iter().any(|d| d.abs() > 1) {
        return Err(IntegrationError::RootDirections {
            roots: nroots,
            directions: directions.to_vec(),
        }
        .into());
    }
    Ok((nroots > 0).then(|| directions.to_vec()))
}

/// Checks a state: finite `t`, `y` of length `n` with finite entries.
pub(super) fn check_state(what: &'static str, t: f64, y: &[f64], n: usize) -> Result<(), Error> {
    if !t.is_finite() {
        return Err(IntegrationError::TimeNotFinite {
            function: what,
            name: "t",
            value: t,
        }
        .into());
    }
    if y.len() != n {
        return Err(IntegrationError::StateLength {
            function: what,
            len: y.len(),
            n,
        }
        .into());
    }
    if let Some(i) = y.iter().position(|v| !v.is_finite()) {
        return Err(IntegrationError::StateNotFinite {
            function: what,
            index: i,
            value: y[i],
        }
        .into());
    }
    Ok(())
}

/// Checks the problem, initial state and options before any C call.
fn validate<P: OdeProblem>(problem: &P, t0: f64, y0: &[f64], o: &OdeOptions) -> Result<(), Error> {
    let n = problem.dim();
    if n == 0 {
        return Err(IntegrationError::EmptyProblem.into());
    }
    check_state("Cvode::new", t0, y0, n)?;
    let bad = |field: &'static str, value: String, need: &str| -> Result<(), Error> {
        Err(IntegrationError::Option {
            field,
            value,
            need: need.to_string(),
        }
        .into())
    };
    if !(o.rtol.is_finite() && o.rtol >= 0.0) {
        return bad("rtol", o.rtol.to_string(), "finite and ≥ 0");
    }
    if !(o.atol.is_finite() && o.atol >= 0.0) {
        return bad("atol", o.atol.to_string(), "finite and ≥ 0");
    }
    if o.rtol == 0.0 && o.atol == 0.0 {
        return bad("rtol", "0 (with atol = 0)".into(), "positive if atol is 0");
    }
    let max = match o.method {
        Method::Bdf => 5,
        Method::Adams => 12,
        Method::Dirk(t) => {
            return bad(
                "method",
                t.name().into(),
                "BDF or Adams for CVODE (a DIRK method runs on ARKODE: Arkode / Integrator)",
            )
        }
    };
    if o.max_order == 0 || o.max_order > max {
        return bad(
            "max_order",
            o.max_order.to_string(),
            &format!("in 1..={max} for {:?}", o.method),
        );
    }
    if o.max_steps == 0 {
        return bad("max_steps", "0".into(), "≥ 1");
    }
    if !(o.max_step.is_finite() && o.max_step >= 0.0) {
        return bad(
            "max_step",
            o.max_step.to_string(),
            "finite and ≥ 0 (0: no limit)",
        );
    }
    if !(o.init_step.is_finite() && o.init_step >= 0.0) {
        return bad(
            "init_step",
            o.init_step.to_string(),
            "finite and ≥ 0 (0: estimated)",
        );
    }
    if !(o.step_growth.is_finite() && o.step_growth >= 1.0) {
        return bad("step_growth", o.step_growth.to_string(), "finite and ≥ 1");
    }
    if o.stab_lim_det && o.method != Method::Bdf {
        return bad("stab_lim_det", "true".into(), "false with Adams (BDF only)");
    }
    if o.iteration
        == (Iteration::Newton {
            linear: NewtonLinear::Problem,
        })
        && !problem.has_newton_solver()
    {
        return bad(
            "iteration",
            "Newton { linear: Problem }".into(),
            "DenseDq or Functional: the problem has no Newton solver (has_newton_solver() is false)",
        );
    }
    Ok(())
}
