//! The `extern "C"` trampolines through which CVODE calls a [`crate::integrate::problem::OdeProblem`], and the
//! state they share with [`super::Cvode`].
//!
//! Every trampoline runs the Rust code inside `catch_unwind` (a panic escaping an `extern "C"`
//! function aborts the process) and maps the outcome to CVODE's convention:
//! - `Ok` → 0;
//! - [`CallbackError::Recoverable`], or a NaN/Inf in the callback's output (`ydot`, `z`) → +1,
//!   CVODE retries with a smaller step (not possible for the event functions: CVODE treats any
//!   nonzero return of a root function as fatal);
//! - [`CallbackError::Fatal`] or a panic → −1, CVODE stops.
//!
//! The last failure (callback name, message, time, fatal or not) is kept in [`Shared`] so that
//! `solve_to` can name it in its error. After a panic the problem may be in an inconsistent
//! state: the integrator is *poisoned* and every later callback returns −1 at once until
//! `reinit`.

use std::any::Any;
use std::ffi::{c_char, c_int, c_void, CStr};
use std::panic::{catch_unwind, AssertUnwindSafe};

use sundials_sys::{realtype, N_VGetArrayPointer, N_Vector};

use crate::integrate::problem::{CallbackError, OdeProblem};

/// A callback failure recorded for the error of `solve_to`.
#[derive(Clone, Debug)]
pub(crate) struct Failure {
    pub callback: &'static str,
    pub message: String,
    pub time: f64,
    /// Returned −1 (fatal error or panic) rather than +1.
    pub fatal: bool,
}

/// What CVODE's `user_data` points to: the problem and the trampolines' bookkeeping.
pub(crate) struct Shared<P> {
    pub problem: P,
    /// Dimension of `y`.
    pub n: usize,
    /// Number of event functions.
    pub nroots: usize,
    /// The last callback failure since it was last taken.
    pub failure: Option<Failure>,
    /// A callback panicked: refuse every callback until `reinit`.
    pub poisoned: bool,
    /// The last error message CVODE reported through its error handler.
    pub cvode_message: Option<String>,
    /// Warnings CVODE reported through its error handler (e.g. `t + h = t`).
    pub warnings: u64,
    /// With the problem's error weights ([`error_weights`]): `rtol` and the per-component
    /// `atol_i` the weights start from (empty otherwise).
    pub ewt_rtol: f64,
    pub ewt_atol: Vec<f64>,
}

/// Clears the upper halves of the AVX registers (`VZEROUPPER`) on CPUs that have them.
///
/// Measured: the full friction bar ran 0.02 s in 5.1 s in a fresh process but in 2.9 s after one
/// `VZEROUPPER` (and in 2.2 s after other work had run) — same steps, every kernel uniformly
/// slower. Some code in the process leaves the AVX upper state "dirty", and on recent x86 cores
/// every SSE instruction (all of this crate's code, compiled for baseline x86-64) then pays a
/// false dependency on the upper halves. One instruction at each entry from CVODE keeps the state
/// clean whatever dirtied it.
#[inline]
fn clean_upper_state() {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx") {
            // SAFETY: AVX is available (checked above); VZEROUPPER has no other effect.
            unsafe { zero_upper() }
        }
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
unsafe fn zero_upper() {
    std::arch::x86_64::_mm256_zeroupper();
}

/// Runs `f`, returning `fallback` if it panics (for the linear-solver ops, whose only failure
/// mode is a bug; the panic message is printed by the panic hook).
pub(crate) fn ffi_guard<R>(fallback: R, f: impl FnOnce() -> R) -> R {
    catch_unwind(AssertUnwindSafe(f)).unwrap_or(fallback)
}

/// The text of a panic payload.
fn panic_text(payload: &(dyn Any + Send)) -> String {
    if let Some(s) = payload.downcast_ref::<&str>() {
        (*s).to_string()
    } else if let Some(s) = payload.downcast_ref::<String>() {
        s.clone()
    } else {
        "(non-string panic payload)".to_string()
    }
}

/// Runs a problem callback for CVODE: checks poisoning, catches panics, records failures and
/// returns CVODE's code (0, +1 or −1).
///
/// # Safety
/// `data` is the `Shared<P>` registered as CVODE's user data, alive and not otherwise
/// referenced while CVODE calls back (the owning `Cvode` is inside a `&mut self` method that
/// holds no reference to it).
unsafe fn run<P: OdeProblem>(
    data: *mut c_void,
    callback: &'static str,
    time: f64,
    f: impl FnOnce(&mut Shared<P>) -> Result<(), CallbackError>,
) -> c_int {
    clean_upper_state();
    if data.is_null() {
        return -1;
    }
    // SAFETY: by this function's contract.
    let shared = unsafe { &mut *data.cast::<Shared<P>>() };
    if shared.poisoned {
        return -1;
    }
    let outcome = catch_unwind(AssertUnwindSafe(|| f(&mut *shared)));
    let (message, fatal) = match outcome {
        Ok(Ok(())) => return 0,
        Ok(Err(CallbackError::Recoverable(m))) => (m, false),
        Ok(Err(CallbackError::Fatal(m))) => (m, true),
        Err(payload) => {
            shared.poisoned = true;
            (format!("panicked: {}", panic_text(payload.as_ref())), true)
        }
    };
    shared.failure = Some(Failure {
        callback,
        message,
        time,
        fatal,
    });
    if fatal {
        -1
    } else {
        1
    }
}

/// The `n` entries of a serial vector.
///
/// # Safety
/// `v` is a live serial vector of length `n` whose data is not written through any other
/// pointer while the slice lives.
unsafe fn entries<'a>(v: N_Vector, n: usize) -> &'a [f64] {
    if n == 0 || v.is_null() {
        return &[];
    }
    // SAFETY: by this function's contract.
    unsafe { std::slice::from_raw_parts(N_VGetArrayPointer(v), n) }
}

/// The `n` entries of a serial vector, writable.
///
/// # Safety
/// As [`entries`], and no other reference to the data exists while the slice lives.
unsafe fn entries_mut<'a>(v: N_Vector, n: usize) -> &'a mut [f64] {
    if n == 0 || v.is_null() {
        return &mut [];
    }
    // SAFETY: by this function's contract.
    unsafe { std::slice::from_raw_parts_mut(N_VGetArrayPointer(v), n) }
}

/// A recoverable error naming the first non-finite entry of `out`, if any.
fn check_finite(name: &str, out: &[f64]) -> Result<(), CallbackError> {
    match out.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(i) => Err(CallbackError::Recoverable(format!(
            "{name}[{i}] = {} is not finite ({} non-finite of {})",
            out[i],
            out.iter().filter(|v| !v.is_finite()).count(),
            out.len()
        ))),
    }
}

/// Fatal error unless the vectors are distinct (CVODE always passes distinct ones).
fn check_distinct(a: N_Vector, b: N_Vector) -> Result<(), CallbackError> {
    if a == b {
        Err(CallbackError::Fatal(
            "input and output vectors alias (not supported)".into(),
        ))
    } else {
        Ok(())
    }
}

/// `CVRhsFn`: `ydot = F(t, y)`, non-finite output → recoverable.
///
/// # Safety
/// Called by CVODE only: `data` is the `Shared<P>` registered as user data (as for `run`), and
/// `y`, `ydot` are live serial vectors of length `n`.
pub(crate) unsafe extern "C" fn rhs<P: OdeProblem>(
    t: realtype,
    y: N_Vector,
    ydot: N_Vector,
    data: *mut c_void,
) -> c_int {
    // SAFETY: `data` is the registered Shared<P> (see `run`); CVODE passes live serial vectors
    // of length n; `y` and `ydot` are checked to be distinct before the slices are made.
    unsafe {
        run::<P>(data, "rhs", t, |s| {
            check_distinct(y, ydot)?;
            let (yv, out) = (entries(y, s.n), entries_mut(ydot, s.n));
            s.problem.rhs(t, yv, out)?;
            check_finite("ydot", out)
        })
    }
}

/// `CVRootFn`: the event functions (any failure is fatal for CVODE).
///
/// # Safety
/// As [`rhs`]; `gout` points to `nroots` writable doubles not aliasing `y`.
pub(crate) unsafe extern "C" fn roots<P: OdeProblem>(
    t: realtype,
    y: N_Vector,
    gout: *mut realtype,
    data: *mut c_void,
) -> c_int {
    // SAFETY: as in `rhs`; `gout` points to `nroots` doubles of CVODE, distinct from `y`.
    unsafe {
        run::<P>(data, "roots", t, |s| {
            let yv = entries(y, s.n);
            let g: &mut [f64] = if s.nroots == 0 || gout.is_null() {
                &mut []
            } else {
                std::slice::from_raw_parts_mut(gout, s.nroots)
            };
            s.problem
                .roots(t, yv, g)
                .and_then(|()| check_finite("g", g))
                .map_err(|e| match e {
                    CallbackError::Recoverable(m) | CallbackError::Fatal(m) => {
                        CallbackError::Fatal(m)
                    }
                })
        })
    }
}

/// `CVEwtFn`: the error weights of the step starting at `y`, `ewt_i = 1 / (rtol |y_i| +
/// atol_i)` (what CVODE's own per-component tolerances give, the same operations) changed by
/// the problem's [`OdeProblem::adjust_error_weights`]. A non-positive `rtol |y_i| + atol_i` or
/// a failure of the problem → nonzero (CVODE stops with `CV_ILL_INPUT`).
///
/// # Safety
/// As [`rhs`]; `ewt` is a live serial vector of length `n` distinct from `y`.
pub(crate) unsafe extern "C" fn error_weights<P: OdeProblem>(
    y: N_Vector,
    ewt: N_Vector,
    data: *mut c_void,
) -> c_int {
    // SAFETY: as in `rhs`; CVODE passes its own distinct weight vector.
    unsafe {
        run::<P>(data, "error_weights", f64::NAN, |s| {
            check_distinct(y, ewt)?;
            let (yv, w) = (entries(y, s.n), entries_mut(ewt, s.n));
            let rtol = s.ewt_rtol;
            for ((wi, &yi), &ai) in w.iter_mut().zip(yv).zip(&s.ewt_atol) {
                let d = rtol * yi.abs() + ai;
                if d.is_nan() || d <= 0.0 {
                    return Err(CallbackError::Fatal(format!(
                        "rtol |y| + atol = {d} is not positive"
                    )));
                }
                *wi = 1.0 / d;
            }
            s.problem.adjust_error_weights(yv, w)
        })
    }
}

/// `CVLsPrecSetupFn`: the problem's `newton_setup(t, y, fy, jok, γ)` → `jcur`.
///
/// # Safety
/// As [`rhs`] for `data`, `y`, `fy`; `jcur` is null or CVLS's writable flag.
pub(crate) unsafe extern "C" fn newton_setup<P: OdeProblem>(
    t: realtype,
    y: N_Vector,
    fy: N_Vector,
    jok: c_int,
    jcur: *mut c_int,
    gamma: realtype,
    data: *mut c_void,
) -> c_int {
    // SAFETY: as in `rhs`; `jcur` is CVODE's writable flag.
    unsafe {
        run::<P>(data, "newton_setup", t, |s| {
            let (yv, fv) = (entries(y, s.n), entries(fy, s.n));
            let recomputed = s.problem.newton_setup(t, yv, fv, jok != 0, gamma)?;
            if !jcur.is_null() {
                *jcur = c_int::from(recomputed);
            }
            Ok(())
        })
    }
}

/// `CVLsPrecSolveFn`: the problem's `newton_solve`, `z ≈ (I − γJ)⁻¹ r`; non-finite `z` →
/// recoverable.
///
/// # Safety
/// As [`rhs`] for `data`, `y`, `r`, `z`; `z` is not written through any other pointer while
/// the call runs.
#[allow(clippy::too_many_arguments)]
pub(crate) unsafe extern "C" fn newton_solve<P: OdeProblem>(
    t: realtype,
    y: N_Vector,
    _fy: N_Vector,
    r: N_Vector,
    z: N_Vector,
    gamma: realtype,
    _delta: realtype,
    _lr: c_int,
    data: *mut c_void,
) -> c_int {
    // SAFETY: as in `rhs`; `r` and `z` are checked to be distinct, `y` is another CVLS vector.
    unsafe {
        run::<P>(data, "newton_solve", t, |s| {
            check_distinct(r, z)?;
            let (yv, rv, zv) = (entries(y, s.n), entries(r, s.n), entries_mut(z, s.n));
            s.problem.newton_solve(t, yv, rv, zv, gamma)?;
            check_finite("z", zv)
        })
    }
}

/// `CVErrHandlerFn`: keeps CVODE's messages (errors for the `Error`, warnings counted) instead
/// of printing them to stderr.
///
/// # Safety
/// Called by CVODE only: `data` is null or the registered `Shared<P>`, not otherwise
/// referenced during the call; `function` and `msg` are null or NUL-terminated strings valid
/// for the call.
pub(crate) unsafe extern "C" fn error_handler<P: OdeProblem>(
    error_code: c_int,
    _module: *const c_char,
    function: *const c_char,
    msg: *mut c_char,
    data: *mut c_void,
) {
    ffi_guard((), || {
        if data.is_null() {
            return;
        }
        // SAFETY: `data` is the registered Shared<P>; CVODE calls the handler only between
        // callbacks, when no other reference to it exists. `function` and `msg` are null or
        // NUL-terminated strings valid for the call.
        let shared = unsafe { &mut *data.cast::<Shared<P>>() };
        let text = |p: *const c_char| {
            if p.is_null() {
                String::new()
            } else {
                // SAFETY: see above.
                unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned()
            }
        };
        if error_code < 0 {
            shared.cvode_message = Some(format!("{}: {}", text(function), text(msg)));
        } else {
            shared.warnings += 1;
        }
    })
}
