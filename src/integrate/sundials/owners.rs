//! One RAII owner per SUNDIALS object used by [`super::Cvode`]: the CVODE memory, a nonlinear
//! solver, a linear solver and a dense matrix. Each frees its object in `Drop` and holds a
//! [`Context`] clone, so the `SUNContext` outlives every object created in it.
//!
//! The order in which they are freed is fixed by the field order of [`super::Cvode`] (Rust
//! drops fields in declaration order): `CVodeFree` → nonlinear solver → linear solver → matrix
//! → vectors → context, the order of the CVODE guide.

use std::ffi::c_void;
use std::ptr::NonNull;

use sundials_sys::{
    _generic_SUNLinearSolver, _generic_SUNMatrix, _generic_SUNNonlinearSolver, CVodeFree,
    SUNLinSolFree, SUNLinearSolver, SUNMatDestroy, SUNMatrix, SUNNonlinSolFree, SUNNonlinearSolver,
};

use super::{sundials_error, Context};
use crate::Error;

/// CVODE's integrator memory (`CVodeCreate`), freed with `CVodeFree`.
pub(crate) struct CvodeMem {
    raw: NonNull<c_void>,
    _context: Context,
}

impl CvodeMem {
    /// Takes ownership of `raw` (from `CVodeCreate`); an error naming `CVodeCreate` if null.
    pub(crate) fn new(raw: *mut c_void, context: &Context) -> Result<Self, Error> {
        let raw =
            NonNull::new(raw).ok_or_else(|| sundials_error("CVodeCreate", "NULL", f64::NAN))?;
        Ok(Self {
            raw,
            _context: context.clone(),
        })
    }

    pub(crate) fn as_raw(&self) -> *mut c_void {
        self.raw.as_ptr()
    }
}

impl Drop for CvodeMem {
    fn drop(&mut self) {
        let mut raw = self.raw.as_ptr();
        // SAFETY: `raw` came from CVodeCreate and is freed only here, once. The solvers, matrix
        // and vectors attached to it are owned by fields dropped after this one.
        unsafe { CVodeFree(&mut raw) };
    }
}

/// A `SUNNonlinearSolver` owned by jointrom (attached with `CVodeSetNonlinearSolver`, which
/// leaves freeing it to the caller), freed with `SUNNonlinSolFree`.
pub(crate) struct NonlinearSolver {
    raw: NonNull<_generic_SUNNonlinearSolver>,
    _context: Context,
}

impl NonlinearSolver {
    /// Takes ownership of `raw`; an error naming `function` if null.
    pub(crate) fn new(
        raw: SUNNonlinearSolver,
        function: &'static str,
        context: &Context,
    ) -> Result<Self, Error> {
        let raw = NonNull::new(raw).ok_or_else(|| sundials_error(function, "NULL", f64::NAN))?;
        Ok(Self {
            raw,
            _context: context.clone(),
        })
    }

    pub(crate) fn as_raw(&self) -> SUNNonlinearSolver {
        self.raw.as_ptr()
    }
}

impl Drop for NonlinearSolver {
    fn drop(&mut self) {
        // SAFETY: `raw` is owned by `self` alone and freed only here; the CVODE memory that
        // used it has been freed before (field order of `Cvode`).
        let flag = unsafe { SUNNonlinSolFree(self.as_raw()) };
        debug_assert_eq!(flag, 0, "SUNNonlinSolFree returned {flag}");
    }
}

/// A `SUNLinearSolver`, freed with `SUNLinSolFree` (which calls its `ops.free`: jointrom's own
/// solver frees its content there).
pub(crate) struct LinearSolver {
    raw: NonNull<_generic_SUNLinearSolver>,
    _context: Context,
}

impl LinearSolver {
    /// Takes ownership of `raw`; an error naming `function` if null.
    pub(crate) fn new(
        raw: SUNLinearSolver,
        function: &'static str,
        context: &Context,
    ) -> Result<Self, Error> {
        let raw = NonNull::new(raw).ok_or_else(|| sundials_error(function, "NULL", f64::NAN))?;
        Ok(Self {
            raw,
            _context: context.clone(),
        })
    }

    pub(crate) fn as_raw(&self) -> SUNLinearSolver {
        self.raw.as_ptr()
    }
}

impl Drop for LinearSolver {
    fn drop(&mut self) {
        // SAFETY: `raw` is owned by `self` alone and freed only here, after CVodeFree.
        let flag = unsafe { SUNLinSolFree(self.as_raw()) };
        debug_assert_eq!(flag, 0, "SUNLinSolFree returned {flag}");
    }
}

/// A `SUNMatrix` (dense here), freed with `SUNMatDestroy`.
pub(crate) struct Matrix {
    raw: NonNull<_generic_SUNMatrix>,
    _context: Context,
}

impl Matrix {
    /// Takes ownership of `raw`; an error naming `function` if null.
    pub(crate) fn new(
        raw: SUNMatrix,
        function: &'static str,
        context: &Context,
    ) -> Result<Self, Error> {
        let raw = NonNull::new(raw).ok_or_else(|| sundials_error(function, "NULL", f64::NAN))?;
        Ok(Self {
            raw,
            _context: context.clone(),
        })
    }

    pub(crate) fn as_raw(&self) -> SUNMatrix {
        self.raw.as_ptr()
    }
}

impl Drop for Matrix {
    fn drop(&mut self) {
        // SAFETY: `raw` is owned by `self` alone and destroyed only here, after the CVODE
        // memory and the linear solver that referenced it.
        unsafe { SUNMatDestroy(self.as_raw()) };
    }
}
