//! [`Owned`]: the RAII owner of one SUNDIALS object used by [`super::Cvode`] and
//! [`super::Arkode`] — the CVODE or ARKStep memory, a nonlinear solver, a linear solver or a
//! matrix. It frees its object in `Drop` with the free
//! function of the object's kind ([`SundialsObject`]) and holds a [`Context`] clone, so the
//! `SUNContext` outlives every object created in it.
//!
//! The order in which they are freed is fixed by the field order of [`super::Cvode`] (Rust
//! drops fields in declaration order): `CVodeFree` → nonlinear solver → linear solver → matrix
//! → vectors → context, the order of the CVODE guide.
//!
//! The context itself is not an `Owned` (it cannot hold a clone of itself, and is created
//! through an out-pointer): see [`super::context`].

use std::ffi::{c_int, c_void};
use std::ptr::NonNull;

use sundials_sys::{
    _generic_SUNLinearSolver, _generic_SUNMatrix, _generic_SUNNonlinearSolver, CVodeFree,
    SUNLinSolFree, SUNMatDestroy, SUNNonlinSolFree,
};

use super::ffi::ARKStepFree;

use super::{sundials_error, Context, CvodeFlag};
use crate::Error;

mod sealed {
    /// Only the kinds below are [`super::SundialsObject`]s.
    pub trait Sealed {}
}

/// A kind of SUNDIALS object an [`Owned`] can own: the C type its handle points to and the
/// function that frees it. Sealed: implemented only by the marker types of this module.
pub(crate) trait SundialsObject: sealed::Sealed {
    /// What the C handle points to (`void` for the CVODE memory).
    type Raw;

    /// Frees the object, returning the C function's flag (0 for functions returning `void`).
    ///
    /// # Safety
    /// `raw` is a live object of this kind that the caller owns; it must not be used (or freed)
    /// again afterwards, and every object referring to it must already have been freed.
    unsafe fn free(raw: *mut Self::Raw) -> c_int;
}

/// CVODE's integrator memory (`CVodeCreate`), freed with `CVodeFree`.
pub(crate) enum CvodeMemory {}

/// ARKODE's ARKStep memory (`ARKStepCreate`), freed with `ARKStepFree`.
pub(crate) enum ArkodeMemory {}

/// A `SUNNonlinearSolver` owned by jointrom (attached with `CVodeSetNonlinearSolver`, which
/// leaves freeing it to the caller), freed with `SUNNonlinSolFree`.
pub(crate) enum NonlinearSolver {}

/// A `SUNLinearSolver`, freed with `SUNLinSolFree` (which calls its `ops.free`: jointrom's own
/// solver frees its content there).
pub(crate) enum LinearSolver {}

/// A `SUNMatrix` (dense here), freed with `SUNMatDestroy`.
pub(crate) enum Matrix {}

impl sealed::Sealed for CvodeMemory {}
impl sealed::Sealed for ArkodeMemory {}
impl sealed::Sealed for NonlinearSolver {}
impl sealed::Sealed for LinearSolver {}
impl sealed::Sealed for Matrix {}

impl SundialsObject for CvodeMemory {
    type Raw = c_void;

    unsafe fn free(raw: *mut c_void) -> c_int {
        let mut raw = raw;
        // SAFETY: by the trait's contract `raw` is live CVODE memory owned by the caller.
        // CVodeFree frees it and only nulls our local copy of the pointer.
        unsafe { CVodeFree(&mut raw) };
        0
    }
}

impl SundialsObject for ArkodeMemory {
    type Raw = c_void;

    unsafe fn free(raw: *mut c_void) -> c_int {
        let mut raw = raw;
        // SAFETY: by the trait's contract `raw` is live ARKStep memory owned by the caller.
        // ARKStepFree frees it (with its nonlinear solver, which ARKStep created) and only
        // nulls our local copy of the pointer.
        unsafe { ARKStepFree(&mut raw) };
        0
    }
}

impl SundialsObject for NonlinearSolver {
    type Raw = _generic_SUNNonlinearSolver;

    unsafe fn free(raw: *mut Self::Raw) -> c_int {
        // SAFETY: by the trait's contract `raw` is a live solver owned by the caller and no
        // CVODE memory still uses it.
        unsafe { SUNNonlinSolFree(raw) }
    }
}

impl SundialsObject for LinearSolver {
    type Raw = _generic_SUNLinearSolver;

    unsafe fn free(raw: *mut Self::Raw) -> c_int {
        // SAFETY: by the trait's contract `raw` is a live solver owned by the caller and no
        // CVODE memory still uses it.
        unsafe { SUNLinSolFree(raw) }
    }
}

impl SundialsObject for Matrix {
    type Raw = _generic_SUNMatrix;

    unsafe fn free(raw: *mut Self::Raw) -> c_int {
        // SAFETY: by the trait's contract `raw` is a live matrix owned by the caller, and the
        // CVODE memory and linear solver that referenced it are gone.
        unsafe { SUNMatDestroy(raw) };
        0
    }
}

/// Owns one SUNDIALS object of kind `T` and frees it (`T::free`) on drop; keeps the object's
/// [`Context`] alive until then.
pub(crate) struct Owned<T: SundialsObject> {
    raw: NonNull<T::Raw>,
    // Dropped after `Drop::drop` has freed the object.
    _context: Context,
}

impl<T: SundialsObject> Owned<T> {
    /// Takes ownership of `raw`, just returned by the C constructor `function`; an
    /// [`Error::Sundials`] naming `function` (flag `NULL`) if `raw` is null.
    ///
    /// # Safety
    /// `raw` is null or a live object of kind `T`, created in `context`, that nothing else
    /// frees: from now on only the returned owner frees it, once.
    pub(crate) unsafe fn new(
        raw: *mut T::Raw,
        function: &'static str,
        context: &Context,
    ) -> Result<Self, Error> {
        let raw = NonNull::new(raw)
            .ok_or_else(|| sundials_error(function, CvodeFlag::condition("NULL"), f64::NAN))?;
        Ok(Self {
            raw,
            _context: context.clone(),
        })
    }

    /// The raw handle, valid as long as `self` lives.
    pub(crate) fn as_raw(&self) -> *mut T::Raw {
        self.raw.as_ptr()
    }
}

impl<T: SundialsObject> Drop for Owned<T> {
    fn drop(&mut self) {
        // SAFETY: `raw` was handed over by `Owned::new` (a live object of kind `T` freed by
        // nothing else) and is freed only here, once. The objects that refer to it are owned by
        // fields of `Cvode` declared, hence dropped, before this owner; its context is alive
        // because `self._context` is dropped after this body runs.
        let flag = unsafe { T::free(self.as_raw()) };
        // The flag is ignored on purpose. Only the solvers' free functions return one, namely
        // their `ops.free`'s (always success for SUNDIALS's fixed-point and dense solvers and
        // for jointrom's own); whatever it says, the handle is gone and there is nothing to
        // recover or retry, and `drop` has no caller to report to. (A panic here would abort
        // the process if the owner is dropped while unwinding.)
        let _ = flag;
    }
}
