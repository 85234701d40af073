//! [`SerialVector`]: an owned `N_Vector` of the serial implementation (`nvector_serial`).

use std::ptr::NonNull;

use sundials_sys::{
    _generic_N_Vector, sunindextype, N_VConst, N_VDestroy, N_VGetArrayPointer, N_VNew_Serial,
    N_Vector,
};

use super::{sundials_error, Context, CvodeFlag};
use crate::error::{Error, IntegrationError};

/// A serial SUNDIALS vector (`N_VNew_Serial`) owning its `f64` data, destroyed (`N_VDestroy`) on
/// drop. Read and write it as a slice; it keeps its [`Context`] alive.
pub struct SerialVector {
    raw: NonNull<_generic_N_Vector>,
    len: usize,
    // Kept alive (not read): dropped after `Drop::drop` has destroyed the vector.
    _context: Context,
}

impl SerialVector {
    /// A vector of `len` zeros in `context`.
    ///
    /// # Errors
    /// [`Error::Integration`] if `len` does not fit SUNDIALS's 64-bit index type;
    /// [`Error::Sundials`] naming `N_VNew_Serial` if the allocation failed.
    pub fn zeros(context: &Context, len: usize) -> Result<Self, Error> {
        let n = sunindextype::try_from(len)
            .map_err(|_| Error::Integration(IntegrationError::VectorLength { len }))?;
        // SAFETY: the context pointer is valid while `context` lives, and the vector keeps a
        // clone of it. N_VNew_Serial returns a new vector owning `n` doubles, or null.
        let raw = unsafe { N_VNew_Serial(n, context.as_raw()) };
        let raw = NonNull::new(raw).ok_or_else(|| {
            sundials_error("N_VNew_Serial", CvodeFlag::condition("NULL"), f64::NAN)
        })?;
        let vector = Self {
            raw,
            len,
            _context: context.clone(),
        };
        // SAFETY: `raw` is a valid serial vector whose ops table N_VNew_Serial allocated for it
        // alone; the replacements compute what the library's do (see `fast_ops`), and CVODE's
        // clones copy the table. N_VNew_Serial leaves the data uninitialised, N_VConst writes all
        // `len` entries (none if `len` is 0).
        unsafe {
            super::fast_ops::install(vector.as_raw());
            N_VConst(0.0, vector.as_raw());
        }
        Ok(vector)
    }

    /// A vector in `context` holding a copy of `values`.
    ///
    /// # Errors
    /// As [`SerialVector::zeros`].
    pub fn from_slice(context: &Context, values: &[f64]) -> Result<Self, Error> {
        let mut vector = Self::zeros(context, values.len())?;
        vector.as_mut_slice().copy_from_slice(values);
        Ok(vector)
    }

    /// Number of entries.
    #[cfg(test)]
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether the vector has no entries.
    #[cfg(test)]
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The entries.
    pub fn as_slice(&self) -> &[f64] {
        // SAFETY: `as_raw` is a live serial vector owning its data.
        let data = unsafe { N_VGetArrayPointer(self.as_raw()) };
        if data.is_null() || self.len == 0 {
            // N_VNew_Serial allocates no data for a zero length.
            return &[];
        }
        // SAFETY: `data` points to `len` initialised doubles owned by the vector, which lives
        // as long as `&self`; no mutable access exists while `&self` is borrowed.
        unsafe { std::slice::from_raw_parts(data, self.len) }
    }

    /// The entries, writable.
    pub fn as_mut_slice(&mut self) -> &mut [f64] {
        // SAFETY: `as_raw` is a live serial vector owning its data.
        let data = unsafe { N_VGetArrayPointer(self.as_raw()) };
        if data.is_null() || self.len == 0 {
            return &mut [];
        }
        // SAFETY: as in `as_slice`; `&mut self` makes this the only access to the data.
        unsafe { std::slice::from_raw_parts_mut(data, self.len) }
    }

    /// The raw `N_Vector`, valid as long as `self` lives.
    pub(crate) fn as_raw(&self) -> N_Vector {
        self.raw.as_ptr()
    }
}

impl std::fmt::Debug for SerialVector {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_tuple("SerialVector")
            .field(&self.as_slice())
            .finish()
    }
}

impl Drop for SerialVector {
    fn drop(&mut self) {
        // SAFETY: `raw` came from N_VNew_Serial and is destroyed only here, once; its context
        // is still alive because `self.context` is dropped after this body runs.
        unsafe { N_VDestroy(self.as_raw()) };
    }
}
