//! Rust implementations of the serial vector's hot operations, installed into every
//! [`super::SerialVector`] (and inherited by CVODE's clones of it, `N_VCloneEmpty` copies the ops
//! table).
//!
//! Why: profiling the reduced-model transients showed ~45 % of the run inside Debian's
//! `libsundials_nvecserial` (N_VWrmsNorm, N_VLinearSum, N_VConst on ~10²-entry vectors), whose
//! loops are compiled without optimisation (every iteration stores its accumulator to the stack).
//! These replacements do the **same IEEE operations in the same order** as
//! `nvector_serial.c` of SUNDIALS 6.4 (sequential sums, `prod = x·w; sum += prod·prod`), so
//! results are bit-for-bit those of the library; only the speed changes. They read a vector's
//! length and data from the serial content struct directly (`N_VGetLength` and
//! `N_VGetArrayPointer` are two indirect calls each, per vector and operation — 4 % of a
//! TOL 1e-2 reduced run; the friction bar's ROM run 57.8 → 54.8 ms, the multilayer's 174 → 168
//! ms, same steps).
//!
//! The element-wise operations run on slices when the output is distinct from its inputs or
//! exactly one of them (every call CVODE makes), so that their loops vectorize: the same IEEE
//! operation per entry, the same bits (`map2`).
//!
//! Measured and not kept: summing the WRMS norm's squares in four interleaved partial sums (the
//! sequential sum's add latency makes the norm 8.6 % of that ROM run) saves another 6–8 %, but
//! the norm's last bits then differ from the library's, CVODE's step sequence moves, and the
//! stored references' short windows are no longer reproduced (the full friction bar's first
//! 0.01 s, whose forces ≤ 0.08 N sit at the tolerance's level, moves by 1.1 % in ‖f_c‖).
//!
//! # Safety
//! The operations are reached only through the ops table of a vector that [`install`] patched
//! (a [`super::SerialVector`]) or of one of its clones (`N_VClone_Serial`, which CVODE and its
//! solvers use, copies the table and allocates the clone's own data), and SUNDIALS dispatches an operation on the ops of its first vector
//! argument while requiring all vector arguments of one call to be of the same implementation.
//! So every `N_Vector` these functions receive is a live serial vector: its `content` is the
//! serial content struct, whose `data` is valid for `length` doubles (null only for length 0, when no
//! element is touched). CVODE and its solvers clone all their vectors from the one template `y`,
//! so the vectors of a call have the same length; the loops still run only to the *smallest*
//! length of their vectors, so no access can go out of bounds even if that ever changed (for
//! equal lengths, the only case that occurs, this is the library's loop).
//!
//! Aliasing: CVODE calls e.g. `N_VLinearSum(a, x, b, y, x)` with the output equal to an input,
//! as `nvector_serial.c` allows, so the loops work on raw pointers element by element, reading
//! the inputs of entry `i` before writing entry `i` of the output (never a `&mut` slice next to
//! a `&` slice of the same memory). No operation here can panic (no indexing, allocation or
//! unwrap); each still runs inside `catch_unwind`, and a panic would leave NaN in the output (a
//! norm of NaN), which CVODE treats as a failed step and jointrom reports as an error.

use std::panic::{catch_unwind, AssertUnwindSafe};

use sundials_sys::{_N_VectorContent_Serial, realtype, N_Vector};

/// Data pointer and length of a serial vector.
///
/// # Safety
/// `v` must be a live serial `N_Vector`.
unsafe fn raw(v: N_Vector) -> (*mut f64, usize) {
    // SAFETY: by this function's contract `v` is a live serial vector, whose `content` is the
    // serial content struct of `nvector_serial.h` (length, ownership flag, data pointer) —
    // what `N_VGetLength_Serial` and `N_VGetArrayPointer_Serial` read, without their two
    // indirect calls each.
    unsafe {
        let c = (*v).content as *const _N_VectorContent_Serial;
        ((*c).data, (*c).length.max(0) as usize)
    }
}

/// Runs `f`; on a panic fills `z` with NaN.
///
/// # Safety
/// `z` must be a live serial `N_Vector`, and `f` must be sound to call (the callers' closures
/// access only vectors that satisfy the module's contract).
unsafe fn guarded(z: N_Vector, f: impl FnOnce()) {
    if catch_unwind(AssertUnwindSafe(f)).is_err() {
        // SAFETY: `z` is a live serial vector (contract), so `zp` is valid for `n` writes;
        // no reference to its data exists.
        unsafe {
            let (zp, n) = raw(z);
            for i in 0..n {
                *zp.add(i) = f64::NAN;
            }
        }
    }
}

fn guarded_value(f: impl FnOnce() -> f64) -> f64 {
    catch_unwind(AssertUnwindSafe(f)).unwrap_or(f64::NAN)
}

/// How the output of an element-wise operation lies against its inputs: distinct memory, or
/// the very same vector as one or both of them (the only overlaps CVODE creates).
#[derive(Clone, Copy, PartialEq, Eq)]
enum Layout {
    /// `z` overlaps neither input (the inputs may be one vector).
    Distinct,
    /// `z` is `x`, and `y` overlaps neither.
    InX,
    /// `z` is `y`, and `x` overlaps neither.
    InY,
    /// `z`, `x` and `y` are one vector.
    All,
    /// Any other overlap: the element-by-element pointer loop.
    Other,
}

/// Whether `[a, a + n)` and `[b, b + n)` (doubles) share memory.
fn overlaps(a: *const f64, b: *const f64, n: usize) -> bool {
    let (a, b) = (a as usize, b as usize);
    let bytes = n * std::mem::size_of::<f64>();
    a < b + bytes && b < a + bytes
}

/// The [`Layout`] of `z` against `x` and `y`, all of length `n`.
fn layout(x: *const f64, y: *const f64, z: *const f64, n: usize) -> Layout {
    let (zx, zy) = (overlaps(z, x, n), overlaps(z, y, n));
    match (zx, zy) {
        (false, false) => Layout::Distinct,
        (true, false) if z == x => Layout::InX,
        (false, true) if z == y => Layout::InY,
        (true, true) if z == x && z == y => Layout::All,
        _ => Layout::Other,
    }
}

/// `z_i = f(x_i, y_i)` for `i < n`, on slices where the [`Layout`] allows (so that the loop
/// vectorizes; each entry is the same IEEE operation either way), element by element through
/// the pointers otherwise.
///
/// # Safety
/// `xp`, `yp` and `zp` are valid for `n` doubles each (reads of `x`, `y`, writes of `z`), and
/// no Rust reference to that memory is live.
#[inline(always)]
unsafe fn map2(
    xp: *const f64,
    yp: *const f64,
    zp: *mut f64,
    n: usize,
    f: impl Fn(f64, f64) -> f64,
) {
    if n == 0 {
        return;
    }
    // SAFETY: each pointer is valid for `n` doubles (contract). A `&mut` slice of `z` is made
    // only where `z` overlaps no input (`Distinct`) or is exactly one of them, which is then
    // read through that same slice; shared slices of the inputs may alias each other.
    unsafe {
        match layout(xp, yp, zp, n) {
            Layout::Distinct => {
                let x = std::slice::from_raw_parts(xp, n);
                let y = std::slice::from_raw_parts(yp, n);
                let z = std::slice::from_raw_parts_mut(zp, n);
                for ((zi, &xi), &yi) in z.iter_mut().zip(x).zip(y) {
                    *zi = f(xi, yi);
                }
            }
            Layout::InX => {
                let y = std::slice::from_raw_parts(yp, n);
                let z = std::slice::from_raw_parts_mut(zp, n);
                for (zi, &yi) in z.iter_mut().zip(y) {
                    *zi = f(*zi, yi);
                }
            }
            Layout::InY => {
                let x = std::slice::from_raw_parts(xp, n);
                let z = std::slice::from_raw_parts_mut(zp, n);
                for (zi, &xi) in z.iter_mut().zip(x) {
                    *zi = f(xi, *zi);
                }
            }
            Layout::All => {
                let z = std::slice::from_raw_parts_mut(zp, n);
                for zi in z.iter_mut() {
                    *zi = f(*zi, *zi);
                }
            }
            Layout::Other => {
                for i in 0..n {
                    *zp.add(i) = f(*xp.add(i), *yp.add(i));
                }
            }
        }
    }
}

/// `z = a x + b y` (z may be x or y). As `N_VLinearSum_Serial`, `a = b` is computed as
/// `a (x + y)` and `a = −b` as `a (x − y)`; its other special cases (a or b = ±1, in-place
/// updates) give the same numbers as `a x + b y`.
///
/// # Safety
/// `x`, `y`, `z` are live serial vectors (module docs); `z` may be `x` or `y`.
unsafe extern "C" fn linear_sum(a: realtype, x: N_Vector, b: realtype, y: N_Vector, z: N_Vector) {
    // SAFETY: `x`, `y` and `z` are live serial vectors (contract), each pointer valid for its
    // vector's length, and `n` is the smallest of them; `map2` reads entry `i` of the inputs
    // before it writes entry `i` of `z`, so `z` aliasing an input is fine.
    unsafe {
        guarded(z, || {
            let (xp, nx) = raw(x);
            let (yp, ny) = raw(y);
            let (zp, nz) = raw(z);
            let n = nx.min(ny).min(nz);
            let unit = a.abs() == 1.0 || b.abs() == 1.0;
            if !unit && a == b {
                map2(xp, yp, zp, n, |xi, yi| a * (xi + yi));
            } else if !unit && a == -b {
                map2(xp, yp, zp, n, |xi, yi| a * (xi - yi));
            } else {
                map2(xp, yp, zp, n, |xi, yi| a * xi + b * yi);
            }
        })
    }
}

/// `z = c`.
///
/// # Safety
/// `z` is a live serial vector (module docs).
unsafe extern "C" fn constant(c: realtype, z: N_Vector) {
    // SAFETY: `z` is a live serial vector (contract): `zp` is valid for its `n` entries.
    unsafe {
        guarded(z, || {
            let (zp, n) = raw(z);
            for i in 0..n {
                *zp.add(i) = c;
            }
        })
    }
}

/// `z = x ∘ y`.
///
/// # Safety
/// `x`, `y`, `z` are live serial vectors (module docs); `z` may be `x` or `y`.
unsafe extern "C" fn prod(x: N_Vector, y: N_Vector, z: N_Vector) {
    // SAFETY: as in `linear_sum`.
    unsafe {
        guarded(z, || {
            let (xp, nx) = raw(x);
            let (yp, ny) = raw(y);
            let (zp, nz) = raw(z);
            map2(xp, yp, zp, nx.min(ny).min(nz), |xi, yi| xi * yi);
        })
    }
}

/// `z = x / y` elementwise.
///
/// # Safety
/// `x`, `y`, `z` are live serial vectors (module docs); `z` may be `x` or `y`.
unsafe extern "C" fn div(x: N_Vector, y: N_Vector, z: N_Vector) {
    // SAFETY: as in `linear_sum`.
    unsafe {
        guarded(z, || {
            let (xp, nx) = raw(x);
            let (yp, ny) = raw(y);
            let (zp, nz) = raw(z);
            map2(xp, yp, zp, nx.min(ny).min(nz), |xi, yi| xi / yi);
        })
    }
}

/// `z = c x`.
///
/// # Safety
/// `x` and `z` are live serial vectors (module docs); `z` may be `x`.
unsafe extern "C" fn scale(c: realtype, x: N_Vector, z: N_Vector) {
    // SAFETY: `x` and `z` are live serial vectors (contract), each pointer valid for its
    // vector's length, and `map2` runs to the smaller one (with `x` as both inputs). It reads
    // entry `i` of `x` before it writes entry `i` of `z`, so `z` may be `x`.
    unsafe {
        guarded(z, || {
            let (xp, nx) = raw(x);
            let (zp, nz) = raw(z);
            map2(xp, xp, zp, nx.min(nz), |xi, _| c * xi);
        })
    }
}

/// `z = |x|`.
///
/// # Safety
/// `x` and `z` are live serial vectors (module docs); `z` may be `x`.
unsafe extern "C" fn abs(x: N_Vector, z: N_Vector) {
    // SAFETY: as in `scale`.
    unsafe {
        guarded(z, || {
            let (xp, nx) = raw(x);
            let (zp, nz) = raw(z);
            map2(xp, xp, zp, nx.min(nz), |xi, _| xi.abs());
        })
    }
}

/// `z = 1 / x`.
///
/// # Safety
/// `x` and `z` are live serial vectors (module docs); `z` may be `x`.
unsafe extern "C" fn inv(x: N_Vector, z: N_Vector) {
    // SAFETY: as in `scale`.
    unsafe {
        guarded(z, || {
            let (xp, nx) = raw(x);
            let (zp, nz) = raw(z);
            map2(xp, xp, zp, nx.min(nz), |xi, _| 1.0 / xi);
        })
    }
}

/// `z = x + b`.
///
/// # Safety
/// `x` and `z` are live serial vectors (module docs); `z` may be `x`.
unsafe extern "C" fn add_const(x: N_Vector, b: realtype, z: N_Vector) {
    // SAFETY: as in `scale`.
    unsafe {
        guarded(z, || {
            let (xp, nx) = raw(x);
            let (zp, nz) = raw(z);
            map2(xp, xp, zp, nx.min(nz), |xi, _| xi + b);
        })
    }
}

/// `Σ (x_i w_i)²`, summed in order (as `N_VWSqrSumLocal_Serial`).
///
/// # Safety
/// `x` and `w` are live serial vectors (module docs); they may be the same vector.
unsafe fn wsqrsum(x: N_Vector, w: N_Vector) -> f64 {
    // SAFETY: `x` and `w` are live serial vectors (contract), each pointer valid for its
    // vector's length, and the loop runs to the smaller one; both are only read.
    unsafe {
        let (xp, nx) = raw(x);
        let (wp, nw) = raw(w);
        let mut sum = 0.0;
        for i in 0..nx.min(nw) {
            let p = *xp.add(i) * *wp.add(i);
            sum += p * p;
        }
        sum
    }
}

/// `sqrt(Σ (x_i w_i)² / n)`.
///
/// # Safety
/// `x` and `w` are live serial vectors (module docs).
unsafe extern "C" fn wrms_norm(x: N_Vector, w: N_Vector) -> realtype {
    guarded_value(|| {
        // SAFETY: `x` and `w` are live serial vectors (contract).
        let n = unsafe { raw(x) }.1;
        // SAFETY: as above.
        (unsafe { wsqrsum(x, w) } / n as f64).sqrt()
    })
}

/// `Σ (x_i w_i)²` (the local part of the norm).
///
/// # Safety
/// `x` and `w` are live serial vectors (module docs).
unsafe extern "C" fn wsqrsum_local(x: N_Vector, w: N_Vector) -> realtype {
    // SAFETY: `x` and `w` are live serial vectors (contract).
    guarded_value(|| unsafe { wsqrsum(x, w) })
}

/// `max |x_i|` (0 for an empty vector).
///
/// # Safety
/// `x` is a live serial vector (module docs).
unsafe extern "C" fn max_norm(x: N_Vector) -> realtype {
    guarded_value(|| {
        // SAFETY: `x` is a live serial vector (contract): `xp` is valid for `n` reads.
        unsafe {
            let (xp, n) = raw(x);
            let mut m = 0.0f64;
            for i in 0..n {
                let a = (*xp.add(i)).abs();
                if a > m {
                    m = a;
                }
            }
            m
        }
    })
}

/// Installs the operations above into the ops table of `v`.
///
/// # Safety
/// `v` must be a live serial `N_Vector` (from `N_VNew_Serial`) with a valid ops table that no
/// other vector shares.
pub(crate) unsafe fn install(v: N_Vector) {
    // SAFETY: by this function's contract `v` points to a live vector; reading its `ops`
    // pointer is a plain field read.
    let ops = unsafe { (*v).ops };
    if ops.is_null() {
        return;
    }
    // SAFETY: `ops` is the vector's own, valid table (contract), written only here while no
    // SUNDIALS call is under way. The replacements have the serial operations' signatures and
    // results, and `v` is serial, as they require.
    unsafe {
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
}
