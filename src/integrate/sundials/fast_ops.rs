//! Rust implementations of the serial vector's hot operations, installed into every
//! [`super::SerialVector`] (and inherited by CVODE's clones of it, `N_VCloneEmpty` copies the ops
//! table).
//!
//! Why: profiling the reduced-model transients showed ~45 % of the run inside Debian's
//! `libsundials_nvecserial` (N_VWrmsNorm, N_VLinearSum, N_VConst on ~10²-entry vectors), whose
//! loops are compiled without optimisation (every iteration stores its accumulator to the stack).
//! These replacements do the **same IEEE operations in the same order** as
//! `nvector_serial.c` of SUNDIALS 6.4 (sequential sums, `prod = x·w; sum += prod·prod`), so
//! results are bit-for-bit those of the library; only the speed changes.
//!
//! Safety and aliasing: CVODE calls e.g. `N_VLinearSum(a, x, b, y, x)` with the output equal to
//! an input, so the loops work on raw pointers element by element (never a `&mut` slice next to
//! a `&` slice of the same memory). No operation here can panic (no indexing, allocation or
//! unwrap); each still runs inside `catch_unwind`, and a panic would leave NaN in the output (a
//! norm of NaN), which CVODE treats as a failed step and jointrom reports as an error.

use std::panic::{catch_unwind, AssertUnwindSafe};

use sundials_sys::{realtype, N_VGetArrayPointer, N_VGetLength, N_Vector};

/// Data pointer and length of a serial vector.
///
/// # Safety
/// `v` must be a valid serial `N_Vector`.
unsafe fn raw(v: N_Vector) -> (*mut f64, usize) {
    let n = N_VGetLength(v).max(0) as usize;
    (N_VGetArrayPointer(v), n)
}

/// Runs `f`; on a panic fills `z` with NaN.
///
/// # Safety
/// `z` must be a valid serial `N_Vector`.
unsafe fn guarded(z: N_Vector, f: impl FnOnce()) {
    if catch_unwind(AssertUnwindSafe(f)).is_err() {
        let (zp, n) = raw(z);
        for i in 0..n {
            *zp.add(i) = f64::NAN;
        }
    }
}

fn guarded_value(f: impl FnOnce() -> f64) -> f64 {
    catch_unwind(AssertUnwindSafe(f)).unwrap_or(f64::NAN)
}

/// `z = a x + b y` (z may be x or y). As `N_VLinearSum_Serial`, `a = b` is computed as
/// `a (x + y)` and `a = −b` as `a (x − y)`; its other special cases (a or b = ±1, in-place
/// updates) give the same numbers as `a x + b y`.
unsafe extern "C" fn linear_sum(a: realtype, x: N_Vector, b: realtype, y: N_Vector, z: N_Vector) {
    guarded(z, || {
        let (xp, n) = raw(x);
        let (yp, _) = raw(y);
        let (zp, _) = raw(z);
        let unit = a.abs() == 1.0 || b.abs() == 1.0;
        if !unit && a == b {
            for i in 0..n {
                *zp.add(i) = a * (*xp.add(i) + *yp.add(i));
            }
        } else if !unit && a == -b {
            for i in 0..n {
                *zp.add(i) = a * (*xp.add(i) - *yp.add(i));
            }
        } else {
            for i in 0..n {
                *zp.add(i) = a * *xp.add(i) + b * *yp.add(i);
            }
        }
    })
}

/// `z = c`.
unsafe extern "C" fn constant(c: realtype, z: N_Vector) {
    guarded(z, || {
        let (zp, n) = raw(z);
        for i in 0..n {
            *zp.add(i) = c;
        }
    })
}

/// `z = x ∘ y`.
unsafe extern "C" fn prod(x: N_Vector, y: N_Vector, z: N_Vector) {
    guarded(z, || {
        let (xp, n) = raw(x);
        let (yp, _) = raw(y);
        let (zp, _) = raw(z);
        for i in 0..n {
            *zp.add(i) = *xp.add(i) * *yp.add(i);
        }
    })
}

/// `z = x / y` elementwise.
unsafe extern "C" fn div(x: N_Vector, y: N_Vector, z: N_Vector) {
    guarded(z, || {
        let (xp, n) = raw(x);
        let (yp, _) = raw(y);
        let (zp, _) = raw(z);
        for i in 0..n {
            *zp.add(i) = *xp.add(i) / *yp.add(i);
        }
    })
}

/// `z = c x`.
unsafe extern "C" fn scale(c: realtype, x: N_Vector, z: N_Vector) {
    guarded(z, || {
        let (xp, n) = raw(x);
        let (zp, _) = raw(z);
        for i in 0..n {
            *zp.add(i) = c * *xp.add(i);
        }
    })
}

/// `z = |x|`.
unsafe extern "C" fn abs(x: N_Vector, z: N_Vector) {
    guarded(z, || {
        let (xp, n) = raw(x);
        let (zp, _) = raw(z);
        for i in 0..n {
            *zp.add(i) = (*xp.add(i)).abs();
        }
    })
}

/// `z = 1 / x`.
unsafe extern "C" fn inv(x: N_Vector, z: N_Vector) {
    guarded(z, || {
        let (xp, n) = raw(x);
        let (zp, _) = raw(z);
        for i in 0..n {
            *zp.add(i) = 1.0 / *xp.add(i);
        }
    })
}

/// `z = x + b`.
unsafe extern "C" fn add_const(x: N_Vector, b: realtype, z: N_Vector) {
    guarded(z, || {
        let (xp, n) = raw(x);
        let (zp, _) = raw(z);
        for i in 0..n {
            *zp.add(i) = *xp.add(i) + b;
        }
    })
}

/// `Σ (x_i w_i)²`, summed in order (as `N_VWSqrSumLocal_Serial`).
unsafe fn wsqrsum(x: N_Vector, w: N_Vector) -> f64 {
    let (xp, n) = raw(x);
    let (wp, _) = raw(w);
    let mut sum = 0.0;
    for i in 0..n {
        let p = *xp.add(i) * *wp.add(i);
        sum += p * p;
    }
    sum
}

/// `sqrt(Σ (x_i w_i)² / n)`.
unsafe extern "C" fn wrms_norm(x: N_Vector, w: N_Vector) -> realtype {
    guarded_value(|| {
        let n = N_VGetLength(x);
        (wsqrsum(x, w) / n as f64).sqrt()
    })
}

/// `Σ (x_i w_i)²` (the local part of the norm).
unsafe extern "C" fn wsqrsum_local(x: N_Vector, w: N_Vector) -> realtype {
    guarded_value(|| wsqrsum(x, w))
}

/// `max |x_i|` (0 for an empty vector).
unsafe extern "C" fn max_norm(x: N_Vector) -> realtype {
    guarded_value(|| {
        let (xp, n) = raw(x);
        let mut m = 0.0f64;
        for i in 0..n {
            let a = (*xp.add(i)).abs();
            if a > m {
                m = a;
            }
        }
        m
    })
}

/// Installs the operations above into the ops table of `v`.
///
/// # Safety
/// `v` must be a valid serial `N_Vector` with a valid, exclusively owned ops table.
pub(crate) unsafe fn install(v: N_Vector) {
    let ops = (*v).ops;
    if ops.is_null() {
        return;
    }
    (*ops).nvlinearsum = Some(linear_sum);
    (*ops).nvconst = Some(constant);
    (*ops).nvprod = Some(prod);
    (*ops).nvdiv = Some(div);
    (*ops).nvscale = Some(scale);
    (*ops).nvabs = Some(abs);
    (*ops).nvinv = Some(inv);
    (*ops).nvaddconst = Some(add_const);
    (*ops).nvwrmsnorm = Some(wrms_norm);
    (*ops).nvwsqrsumlocal = Some(wsqrsum_local);
    (*ops).nvmaxnorm = Some(max_norm);
}
