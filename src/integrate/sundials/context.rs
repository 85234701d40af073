//! [`Context`]: the `SUNContext` every SUNDIALS 6 object is created in.

use std::ptr::{self, NonNull};
use std::rc::Rc;

use sundials_sys::{_SUNContext, SUNContext, SUNContext_Create, SUNContext_Free};

use super::{check_library_version, sundials_error, CvodeFlag};
use crate::Error;

/// A SUNDIALS context (`SUNContext`): the handle every vector, matrix, solver and integrator is
/// created in.
///
/// `Context` is a cheap, clonable handle to one reference-counted `SUNContext`. Every object
/// created in the context keeps a clone, so `SUNContext_Free` runs only after the last of them is
/// destroyed, whatever order the Rust values are dropped in.
///
/// A `SUNContext` is not thread-safe: `Context` and the objects holding it are neither `Send` nor
/// `Sync`. Create one context per thread.
#[derive(Clone)]
pub struct Context {
    raw: Rc<RawContext>,
}

/// Owns the `SUNContext` pointer and frees it on drop.
struct RawContext(NonNull<_SUNContext>);

impl Context {
    /// Creates a context (`SUNContext_Create`, no MPI communicator).
    ///
    /// Also checks, once per context, that the SUNDIALS library loaded at run time is a 6.x
    /// release, like the headers the crate was compiled against.
    ///
    /// # Errors
    /// [`Error::Sundials`] naming `SUNDIALSGetVersionNumber` if the loaded library is not 6.x, or
    /// `SUNContext_Create` with its return code if the context could not be created. The `time`
    /// of these errors is NaN (no integration is under way).
    pub fn new() -> Result<Self, Error> {
        check_library_version()?;
        let mut raw: SUNContext = ptr::null_mut();
        // SAFETY: SUNDIALS 6 takes a `void*` communicator, null without MPI; `raw` is a valid
        // out-pointer for the duration of the call. On success SUNContext_Create stores a newly
        // allocated context in `raw`, which RawContext then owns.
        let flag = unsafe { SUNContext_Create(ptr::null_mut(), &mut raw) };
        match NonNull::new(raw) {
            Some(raw) if flag == 0 => Ok(Self {
                raw: Rc::new(RawContext(raw)),
            }),
            _ => Err(sundials_error(
                "SUNContext_Create",
                CvodeFlag {
                    code: Some(flag),
                    name: flag.to_string(),
                    message: None,
                },
                f64::NAN,
            )),
        }
    }

    /// The raw `SUNContext`, valid as long as `self` (or any clone) lives.
    pub(crate) fn as_raw(&self) -> SUNContext {
        self.raw.0.as_ptr()
    }
}

impl std::fmt::Debug for Context {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_tuple("Context").field(&self.raw.0).finish()
    }
}

impl Drop for RawContext {
    fn drop(&mut self) {
        let mut raw = self.0.as_ptr();
        // SAFETY: `raw` came from a successful SUNContext_Create and is freed only here, once.
        // Every SUNDIALS object created in it holds a `Context` clone and so has been destroyed
        // before the last `Rc<RawContext>` is dropped.
        let flag = unsafe { SUNContext_Free(&mut raw) };
        // The flag is ignored on purpose: SUNContext_Free (6.4) returns nonzero only when a
        // profiling build fails to free the context's profiler, and then there is nothing to
        // recover or retry either; `drop` has no caller to report to (and a panic here would
        // abort the process if the context is dropped while unwinding).
        let _ = flag;
    }
}
