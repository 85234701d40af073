//! The custom `SUNLinearSolver` that hands CVODE's Newton systems `(I − γJ) x = b` to the
//! problem's own solver ([`crate::integrate::problem::OdeProblem::newton_setup`] / `newton_solve`).
//!
//! # Why an "iterative" solver with a preconditioner
//! SUNDIALS 6.4 offers two ways to plug in a matrix-free solver (`shared/NOTES.md`):
//! - declared `MATRIX_EMBEDDED`, CVODE never calls its `setup`, so the problem would have to
//!   rebuild its factorization from `CVodeGetCurrentGamma` inside every solve without knowing
//!   whether the Jacobian may be reused (measured: ~40 % more Newton iterations);
//! - declared `ITERATIVE` with a no-op `setatimes`, CVODE's linear-solver interface (CVLS) calls
//!   `setup` on its own schedule (new step size ratio, convergence failure, every 20 steps) and
//!   forwards it to the preconditioner setup `psetup(t, y, f, jok, &jcur, γ)` registered with
//!   `CVodeSetPreconditioner` — exactly the information `newton_setup` needs.
//!
//! This solver takes the second way. Its `setup` calls CVLS's `pset` (which calls the problem's
//! `newton_setup` through the trampoline), its `solve` calls `psol` once, as a left
//! preconditioner solve `x = P⁻¹ b` with `P = I − γJ`, and reports success, one iteration and a
//! zero residual norm: CVLS then accepts `x` as the exact Newton correction (`cvLsSolve` returns
//! 0 on `SUNLS_SUCCESS` and only reads `resnorm`/`numiters` for its statistics). CVLS skips the
//! solve altogether when `‖b‖_WRMS ≤ ε_L · tq[4]` (ε_L = `CVodeSetEpsLin`, default 0.05); the
//! wrapper sets ε_L small so that, like a direct solver, every Newton iteration is solved.
//! Unlike CVODE's direct solvers, CVLS does not rescale the correction by 2/(1 + γ/γ_setup) for
//! iterative solvers: `newton_solve` receives the current γ and may use it.

use std::ffi::{c_int, c_void};

use sundials_sys::{
    realtype, sunindextype, N_VScale, N_Vector, SUNATimesFn, SUNLinSolFreeEmpty, SUNLinSolNewEmpty,
    SUNLinearSolver, SUNLinearSolver_ID, SUNLinearSolver_ID_SUNLINEARSOLVER_CUSTOM,
    SUNLinearSolver_Type, SUNLinearSolver_Type_SUNLINEARSOLVER_ITERATIVE, SUNMatrix, SUNPSetupFn,
    SUNPSolveFn, SUNLS_PSET_FAIL_REC, SUNLS_PSET_FAIL_UNREC, SUNLS_PSOLVE_FAIL_REC,
    SUNLS_PSOLVE_FAIL_UNREC, SUNLS_SUCCESS, SUN_PREC_LEFT,
};

use super::callbacks::ffi_guard;
use super::owners::{LinearSolver, Owned};
use super::Context;
use crate::Error;

/// The solver's content: what CVLS registers through `setpreconditioner`.
struct Content {
    p_data: *mut c_void,
    pset: SUNPSetupFn,
    psol: SUNPSolveFn,
    last_flag: c_int,
}

/// Creates the solver in `context` (ops set, content allocated; `ops.free` releases both).
pub(crate) fn new(context: &Context) -> Result<Owned<LinearSolver>, Error> {
    // SAFETY: the context is live; SUNLinSolNewEmpty returns a new solver with allocated,
    // zeroed ops and null content (freed by SUNLinSolFree through the ops' default path until
    // `free` is installed below), or null (turned into an error by Owned::new). Only `solver`
    // frees it.
    let solver = unsafe {
        let raw = SUNLinSolNewEmpty(context.as_raw());
        Owned::<LinearSolver>::new(raw, "SUNLinSolNewEmpty", context)
    }?;
    let content = Box::new(Content {
        p_data: std::ptr::null_mut(),
        pset: None,
        psol: None,
        last_flag: 0,
    });
    // SAFETY: `raw` is a live solver with a valid `ops` table owned by it. From here on
    // `ops.free` (set first, together with the content) releases the content, so dropping
    // `solver` on any later path frees everything.
    unsafe {
        let s = solver.as_raw();
        (*s).content = Box::into_raw(content).cast();
        let ops = &mut *(*s).ops;
        ops.free = Some(free);
        ops.gettype = Some(get_type);
        ops.getid = Some(get_id);
        ops.setatimes = Some(set_atimes);
        ops.setpreconditioner = Some(set_preconditioner);
        ops.setup = Some(setup);
        ops.solve = Some(solve);
        ops.numiters = Some(num_iters);
        ops.resnorm = Some(res_norm);
        ops.lastflag = Some(last_flag);
    }
    Ok(solver)
}

/// The content of `s`.
///
/// # Safety
/// `s` is a live solver made by [`new`] (its content is a `Content` not yet freed), and no
/// other reference to that content exists while the returned one is used.
unsafe fn content<'a>(s: SUNLinearSolver) -> &'a mut Content {
    // SAFETY: by this function's contract.
    unsafe { &mut *(*s).content.cast::<Content>() }
}

extern "C" fn get_type(_s: SUNLinearSolver) -> SUNLinearSolver_Type {
    SUNLinearSolver_Type_SUNLINEARSOLVER_ITERATIVE
}

extern "C" fn get_id(_s: SUNLinearSolver) -> SUNLinearSolver_ID {
    SUNLinearSolver_ID_SUNLINEARSOLVER_CUSTOM
}

/// No-op: the product `A v` is never needed (one exact preconditioner solve per system).
extern "C" fn set_atimes(_s: SUNLinearSolver, _data: *mut c_void, _f: SUNATimesFn) -> c_int {
    SUNLS_SUCCESS as c_int
}

/// `ops.setpreconditioner`: keeps CVLS's preconditioner data and functions.
///
/// # Safety
/// `s` is a live solver made by [`new`] (SUNDIALS calls this through the solver's own ops),
/// and no other call on `s` is under way.
unsafe extern "C" fn set_preconditioner(
    s: SUNLinearSolver,
    p_data: *mut c_void,
    pset: SUNPSetupFn,
    psol: SUNPSolveFn,
) -> c_int {
    ffi_guard(SUNLS_PSET_FAIL_UNREC, || {
        // SAFETY: CVLS passes the solver it was given, made by `new`.
        let c = unsafe { content(s) };
        c.p_data = p_data;
        c.pset = pset;
        c.psol = psol;
        SUNLS_SUCCESS as c_int
    })
}

/// Calls CVLS's preconditioner setup (the problem's `newton_setup`).
///
/// # Safety
/// As [`set_preconditioner`]; CVLS, which registered the preconditioner, calls it while its
/// CVODE memory is alive.
unsafe extern "C" fn setup(s: SUNLinearSolver, _a: SUNMatrix) -> c_int {
    ffi_guard(SUNLS_PSET_FAIL_UNREC, || {
        // SAFETY: CVLS passes the solver it was given, made by `new`.
        let c = unsafe { content(s) };
        let flag = match c.pset {
            // SAFETY: `pset` and `p_data` were registered together by CVLS (cvLsPSetup with
            // the CVODE memory), which is alive while it calls this solver.
            Some(pset) => match unsafe { pset(c.p_data) } {
                0 => SUNLS_SUCCESS as c_int,
                f if f > 0 => SUNLS_PSET_FAIL_REC as c_int,
                _ => SUNLS_PSET_FAIL_UNREC,
            },
            None => SUNLS_SUCCESS as c_int,
        };
        c.last_flag = flag;
        flag
    })
}

/// `x = P⁻¹ b` by one call of CVLS's preconditioner solve (the problem's `newton_solve`).
///
/// # Safety
/// As [`setup`]; `x` and `b` are distinct live vectors of the problem's length.
unsafe extern "C" fn solve(
    s: SUNLinearSolver,
    _a: SUNMatrix,
    x: N_Vector,
    b: N_Vector,
    tol: realtype,
) -> c_int {
    ffi_guard(SUNLS_PSOLVE_FAIL_UNREC, || {
        // SAFETY: CVLS passes the solver it was given, made by `new`.
        let c = unsafe { content(s) };
        let flag = match c.psol {
            // SAFETY: as in `setup`; `b` and `x` are distinct live vectors of CVLS.
            Some(psol) => match unsafe { psol(c.p_data, b, x, tol, SUN_PREC_LEFT as c_int) } {
                0 => SUNLS_SUCCESS as c_int,
                f if f > 0 => SUNLS_PSOLVE_FAIL_REC as c_int,
                _ => SUNLS_PSOLVE_FAIL_UNREC,
            },
            None => {
                // No preconditioner registered: the identity (never the case in jointrom).
                // SAFETY: `b` and `x` are live vectors of the same length.
                unsafe { N_VScale(1.0, b, x) };
                SUNLS_SUCCESS as c_int
            }
        };
        c.last_flag = flag;
        flag
    })
}

/// One "iteration" per solve (so `CVodeGetNumLinIters` counts the solves).
extern "C" fn num_iters(_s: SUNLinearSolver) -> c_int {
    1
}

/// The solve is exact: zero residual.
extern "C" fn res_norm(_s: SUNLinearSolver) -> realtype {
    0.0
}

/// The flag of the last `setup` or `solve`.
///
/// # Safety
/// As [`set_preconditioner`].
unsafe extern "C" fn last_flag(s: SUNLinearSolver) -> sunindextype {
    ffi_guard(0, || {
        // SAFETY: CVODE passes the solver it was given, made by `new`.
        sunindextype::from(unsafe { content(s) }.last_flag)
    })
}

/// `ops.free`: releases the content, then the solver and its ops (`SUNLinSolFreeEmpty`).
///
/// # Safety
/// `s` is null or a solver made by [`new`] that nothing uses afterwards (SUNLinSolFree calls
/// this once, from the owner's `Drop`).
unsafe extern "C" fn free(s: SUNLinearSolver) -> c_int {
    if s.is_null() {
        return SUNLS_SUCCESS as c_int;
    }
    // SAFETY: `s` was made by `new`; its content came from Box::into_raw and is released only
    // here (SUNLinSolFree calls ops.free once), then the empty solver is freed.
    unsafe {
        let content = (*s).content.cast::<Content>();
        if !content.is_null() {
            drop(Box::from_raw(content));
            (*s).content = std::ptr::null_mut();
        }
        SUNLinSolFreeEmpty(s);
    }
    SUNLS_SUCCESS as c_int
}
