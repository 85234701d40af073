//! The FMI 2.0 C interface (co-simulation): every `extern "C"` function of the standard's
//! `fmi2Functions.h`, and the crate's only `unsafe` code.
//!
//! ## The C types, as declared by FMI 2.0 (`fmi2TypesPlatform.h`, `fmi2FunctionTypes.h`)
//!
//! | FMI | here |
//! |---|---|
//! | `fmi2Component` (`void*`) | `*mut c_void`: a `Box<Instance>` turned into a raw pointer |
//! | `fmi2ComponentEnvironment`, `fmi2FMUstate` | `*mut c_void` |
//! | `fmi2ValueReference` (`unsigned int`) | `c_uint` |
//! | `fmi2Real`, `fmi2Integer`, `fmi2Boolean` | `f64`, `c_int`, `c_int` |
//! | `fmi2String` | `*const c_char` (NUL-terminated) |
//! | `fmi2Byte` | `c_char` |
//! | enums `fmi2Status`, `fmi2Type`, `fmi2StatusKind` | `c_int` |
//! | `fmi2CallbackFunctions` | [`CallbackFunctions`], copied at instantiation |
//!
//! The shared object exports the functions without a prefix (`fmi2Instantiate`, ...), as FMI
//! requires for binaries loaded dynamically.
//!
//! ## Safety at the boundary
//!
//! - Every exported function runs its body inside [`std::panic::catch_unwind`]: a panic (a bug)
//!   is reported through the logger and returns `fmi2Error` (`NULL` from `fmi2Instantiate`),
//!   never unwinds into the importer. The instance then goes to the error state.
//! - Pointers from the importer are checked for NULL before use; an instance pointer must be
//!   one that `fmi2Instantiate` returned and that was not freed (the standard's contract) — a
//!   magic number catches some violations (a pointer to something else) but cannot make a
//!   dangling pointer safe.
//! - Arrays (`vr[nvr]`, `value[nvr]`) are read as slices of the given length, as the standard
//!   defines them.
//! - The logger is a C variadic function whose message is a `printf` format: it is called
//!   without variadic arguments and with every `%` of the message doubled, so a `%` in a message
//!   (or a case name) is printed, never interpreted — and importers whose logger prints the
//!   message without formatting it still show the text (with `%%` for `%`).
//! - `fmi2FreeInstance` drops the `Box<Instance>`: the slave, its integrator (CVODE memory,
//!   vectors, solvers, SUNDIALS context — freed by their RAII owners) and the copied strings.
//!
//! Everything else — the state machine, argument checks, the model — is the safe
//! [`crate::slave::Slave`].

#![allow(non_snake_case)]
#![deny(unsafe_op_in_unsafe_fn, clippy::undocumented_unsafe_blocks)]

use std::ffi::{c_char, c_int, c_uint, c_void, CStr, CString};
use std::panic::{catch_unwind, AssertUnwindSafe};

use crate::slave::{Outcome, Slave};
use crate::uri::resource_dir;

type Component = *mut c_void;
type Status = c_int;

// fmi2Status: fmi2OK, fmi2Warning (1, never returned: every problem is an error), fmi2Discard,
// fmi2Error, fmi2Fatal (4, never returned: instances are independent), fmi2Pending (5, never:
// steps are synchronous).
const FMI2_OK: Status = 0;
const FMI2_DISCARD: Status = 2;
const FMI2_ERROR: Status = 3;

const FMI2_TRUE: c_int = 1;
const FMI2_FALSE: c_int = 0;

/// `fmi2Type`: `fmi2ModelExchange` = 0, `fmi2CoSimulation` = 1.
const FMI2_CO_SIMULATION: c_int = 1;

/// `fmi2StatusKind` values.
const FMI2_LAST_SUCCESSFUL_TIME: c_int = 2;
const FMI2_TERMINATED: c_int = 3;

/// The logger: `void logger(env, instanceName, status, category, message, ...)`.
type Logger =
    unsafe extern "C" fn(*mut c_void, *const c_char, Status, *const c_char, *const c_char, ...);

/// `fmi2CallbackFunctions` (FMI 2.0, section 2.1.5).
#[repr(C)]
#[derive(Clone, Copy)]
pub struct CallbackFunctions {
    logger: Option<Logger>,
    allocate_memory: Option<unsafe extern "C" fn(usize, usize) -> *mut c_void>,
    free_memory: Option<unsafe extern "C" fn(*mut c_void)>,
    step_finished: Option<unsafe extern "C" fn(*mut c_void, Status)>,
    component_environment: *mut c_void,
}

/// Marks a live [`Instance`] (checked on every call; cleared when freed).
const MAGIC: u64 = 0x6a6f_696e_7472_6f6d; // "jointrom"

/// One FMU instance behind an `fmi2Component`.
struct Instance {
    magic: u64,
    name: CString,
    logger: Option<Logger>,
    environment: *mut c_void,
    /// Diagnostics (category `logAll`) on: `loggingOn` of `fmi2Instantiate`, then
    /// `fmi2SetDebugLogging`. Errors are always logged.
    debug: bool,
    slave: Slave,
}

/// A message as a C string (interior NULs become spaces).
fn c_message(text: &str) -> CString {
    CString::new(text.replace('\0', " ")).unwrap_or_default()
}

/// Sends `message` to `logger` (if any) with `status` and `category`.
fn log_to(
    logger: Option<Logger>,
    env: *mut c_void,
    name: &CStr,
    status: Status,
    category: &CStr,
    message: &str,
) {
    let Some(logger) = logger else { return };
    let format = c_message(&message.replace('%', "%%"));
    // SAFETY: `logger` is the importer's logger function (FMI: callable from any fmi2 function
    // with the environment it gave); every string passed is NUL-terminated and lives across
    // the call; the format has no conversion left (every `%` doubled), so no variadic argument
    // is read.
    unsafe {
        logger(
            env,
            name.as_ptr(),
            status,
            category.as_ptr(),
            format.as_ptr(),
        )
    };
}

impl Instance {
    fn error(&self, message: &str) {
        log_to(
            self.logger,
            self.environment,
            &self.name,
            FMI2_ERROR,
            c"logStatusError",
            message,
        );
    }

    fn debug(&self, message: &str) {
        if self.debug {
            log_to(
                self.logger,
                self.environment,
                &self.name,
                FMI2_OK,
                c"logAll",
                message,
            );
        }
    }
}

/// The message of a caught panic.
fn panic_message(p: &(dyn std::any::Any + Send)) -> String {
    p.downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| p.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "(no message)".into())
}

/// Runs `body` on the instance `c` behind `catch_unwind`: `Ok(status)` is returned as is, an
/// `Err` or a panic is logged, puts the instance into the error state and returns
/// `fmi2Error`. A NULL or foreign `c` returns `fmi2Error` (there is no logger to tell).
fn with_instance(
    c: Component,
    function: &str,
    body: impl FnOnce(&mut Instance) -> Outcome<Status>,
) -> Status {
    if c.is_null() {
        return FMI2_ERROR;
    }
    let ptr = c.cast::<Instance>();
    // SAFETY: by the FMI contract `c` is a pointer returned by fmi2Instantiate and not yet
    // passed to fmi2FreeInstance, i.e. a live, aligned Box<Instance>; the importer calls one
    // function of an instance at a time, so no other reference to it exists. The magic number
    // is read through the raw pointer first to refuse some foreign pointers.
    let inst = unsafe {
        if std::ptr::addr_of!((*ptr).magic).read() != MAGIC {
            return FMI2_ERROR;
        }
        &mut *ptr
    };
    match catch_unwind(AssertUnwindSafe(|| body(inst))) {
        Ok(Ok(status)) => status,
        Ok(Err(message)) => {
            inst.error(&message);
            inst.slave.fail();
            FMI2_ERROR
        }
        Err(p) => {
            // The instance is still a valid value (a panic unwinds through safe code only).
            let message = format!("{function}: internal error: {}", panic_message(&*p));
            let _ = catch_unwind(AssertUnwindSafe(|| {
                inst.error(&message);
                inst.slave.fail();
            }));
            FMI2_ERROR
        }
    }
}

/// A C string argument as UTF-8 text (lossy), or the error naming it.
///
/// # Safety
/// `s` is NULL or a NUL-terminated string valid for the call.
unsafe fn text(s: *const c_char, what: &str) -> Outcome<String> {
    if s.is_null() {
        return Err(format!("{what} is NULL"));
    }
    // SAFETY: non-NULL and NUL-terminated by this function's contract.
    Ok(unsafe { CStr::from_ptr(s) }.to_string_lossy().into_owned())
}

/// The `n` elements at `p` (an empty slice for `n == 0`, whatever `p`).
///
/// # Safety
/// For `n > 0`, `p` is NULL (refused) or points to `n` valid, initialized `T` that nothing
/// writes during the returned borrow.
unsafe fn slice<'a, T>(p: *const T, n: usize, what: &str) -> Outcome<&'a [T]> {
    if n == 0 {
        return Ok(&[]);
    }
    if p.is_null() {
        return Err(format!("{what} is NULL for {n} values"));
    }
    // SAFETY: by this function's contract.
    Ok(unsafe { std::slice::from_raw_parts(p, n) })
}

/// The `n` writable elements at `p`.
///
/// # Safety
/// For `n > 0`, `p` is NULL (refused) or points to `n` writable `T` not otherwise borrowed.
unsafe fn slice_mut<'a, T>(p: *mut T, n: usize, what: &str) -> Outcome<&'a mut [T]> {
    if n == 0 {
        return Ok(&mut []);
    }
    if p.is_null() {
        return Err(format!("{what} is NULL for {n} values"));
    }
    // SAFETY: by this function's contract.
    Ok(unsafe { std::slice::from_raw_parts_mut(p, n) })
}

// ---------------------------------------------------------------------------------------------
// Inquiry

/// `fmi2GetTypesPlatform`: `"default"`.
#[no_mangle]
pub extern "C" fn fmi2GetTypesPlatform() -> *const c_char {
    c"default".as_ptr()
}

/// `fmi2GetVersion`: `"2.0"`.
#[no_mangle]
pub extern "C" fn fmi2GetVersion() -> *const c_char {
    c"2.0".as_ptr()
}

// ---------------------------------------------------------------------------------------------
// Creation and destruction

/// `fmi2Instantiate`: reads `resources/rom.json`, checks it against the GUID; NULL on any
/// failure (logged through `functions->logger` when there is one).
///
/// # Safety
/// The string arguments are NULL or NUL-terminated; `functions` is NULL or points to an
/// `fmi2CallbackFunctions` (copied here).
#[no_mangle]
pub unsafe extern "C" fn fmi2Instantiate(
    instance_name: *const c_char,
    fmu_type: c_int,
    fmu_guid: *const c_char,
    fmu_resource_location: *const c_char,
    functions: *const CallbackFunctions,
    _visible: c_int,
    logging_on: c_int,
) -> Component {
    let result = catch_unwind(AssertUnwindSafe(|| {
        let callbacks = if functions.is_null() {
            None
        } else {
            // SAFETY: non-NULL, points to the importer's callback struct (FMI contract).
            Some(unsafe { *functions })
        };
        let logger = callbacks.and_then(|f| f.logger);
        let env = callbacks.map_or(std::ptr::null_mut(), |f| f.component_environment);
        // SAFETY: the importer passes NUL-terminated strings or NULL (FMI contract).
        let name = unsafe { text(instance_name, "instanceName") };
        let fail = |name: &str, message: &str| {
            log_to(
                logger,
                env,
                &c_message(name),
                FMI2_ERROR,
                c"logStatusError",
                &format!("fmi2Instantiate: {message}"),
            );
            std::ptr::null_mut::<c_void>()
        };
        let name = match name {
            Ok(n) => n,
            Err(e) => return fail("", &e),
        };
        if fmu_type != FMI2_CO_SIMULATION {
            return fail(
                &name,
                &format!("fmuType {fmu_type} is not fmi2CoSimulation (1): this FMU is co-simulation only"),
            );
        }
        // SAFETY: as above.
        let guid = match unsafe { text(fmu_guid, "fmuGUID") } {
            Ok(g) => g,
            Err(e) => return fail(&name, &e),
        };
        // SAFETY: as above.
        let location = match unsafe { text(fmu_resource_location, "fmuResourceLocation") } {
            Ok(l) => l,
            Err(e) => return fail(&name, &e),
        };
        let slave = match resource_dir(&location).and_then(|dir| Slave::new(&dir, &guid)) {
            Ok(s) => s,
            Err(e) => return fail(&name, &e),
        };
        let inst = Box::new(Instance {
            magic: MAGIC,
            name: c_message(&name),
            logger,
            environment: env,
            debug: logging_on == FMI2_TRUE,
            slave,
        });
        inst.debug(&format!(
            "instantiated: {} from {location}",
            inst.slave.describe()
        ));
        Box::into_raw(inst).cast::<c_void>()
    }));
    result.unwrap_or(std::ptr::null_mut())
}

/// `fmi2FreeInstance`: frees the instance and everything it owns (NULL: nothing).
///
/// # Safety
/// `c` is NULL or an instance from `fmi2Instantiate` not freed before; it is invalid after.
#[no_mangle]
pub unsafe extern "C" fn fmi2FreeInstance(c: Component) {
    if c.is_null() {
        return;
    }
    let ptr = c.cast::<Instance>();
    // SAFETY: by the FMI contract `c` came from Box::into_raw in fmi2Instantiate and is freed
    // only here; the magic check refuses some foreign pointers before taking ownership.
    let _ = catch_unwind(AssertUnwindSafe(|| unsafe {
        if std::ptr::addr_of!((*ptr).magic).read() != MAGIC {
            return;
        }
        (*ptr).magic = 0;
        drop(Box::from_raw(ptr));
    }));
}

/// `fmi2SetDebugLogging`: switches the diagnostics (`logAll`) on or off; the categories must
/// be ones of the model description (none: all).
///
/// # Safety
/// `c` as for every function; `categories` holds `n` C strings (or is NULL for `n == 0`).
#[no_mangle]
pub unsafe extern "C" fn fmi2SetDebugLogging(
    c: Component,
    logging_on: c_int,
    n: usize,
    categories: *const *const c_char,
) -> Status {
    with_instance(c, "fmi2SetDebugLogging", |inst| {
        // SAFETY: the importer passes `n` category strings (FMI contract).
        let cats = unsafe { slice(categories, n, "categories") }?;
        let mut debug = n == 0;
        for &cat in cats {
            // SAFETY: each entry is a NUL-terminated string (FMI contract).
            let cat = unsafe { text(cat, "a category") }?;
            match cat.as_str() {
                "logAll" => debug = true,
                "logStatusError" => {}
                other => {
                    return Err(format!(
                        "fmi2SetDebugLogging: unknown log category `{other}` (logStatusError, \
                         logAll)"
                    ))
                }
            }
        }
        inst.debug = logging_on == FMI2_TRUE && debug;
        Ok(FMI2_OK)
    })
}

// ---------------------------------------------------------------------------------------------
// Initialization, termination, reset

/// `fmi2SetupExperiment`.
///
/// # Safety
/// `c` is an instance from `fmi2Instantiate`.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetupExperiment(
    c: Component,
    tolerance_defined: c_int,
    tolerance: f64,
    start_time: f64,
    stop_time_defined: c_int,
    stop_time: f64,
) -> Status {
    with_instance(c, "fmi2SetupExperiment", |inst| {
        let tol = (tolerance_defined == FMI2_TRUE).then_some(tolerance);
        let stop = (stop_time_defined == FMI2_TRUE).then_some(stop_time);
        inst.slave.setup_experiment(tol, start_time, stop)?;
        Ok(FMI2_OK)
    })
}

/// `fmi2EnterInitializationMode`.
///
/// # Safety
/// `c` is an instance from `fmi2Instantiate`.
#[no_mangle]
pub unsafe extern "C" fn fmi2EnterInitializationMode(c: Component) -> Status {
    with_instance(c, "fmi2EnterInitializationMode", |inst| {
        inst.slave.enter_initialization()?;
        Ok(FMI2_OK)
    })
}

/// `fmi2ExitInitializationMode`: builds the integrator.
///
/// # Safety
/// `c` is an instance from `fmi2Instantiate`.
#[no_mangle]
pub unsafe extern "C" fn fmi2ExitInitializationMode(c: Component) -> Status {
    with_instance(c, "fmi2ExitInitializationMode", |inst| {
        inst.slave.exit_initialization()?;
        inst.debug("initialized: the integrator is built");
        Ok(FMI2_OK)
    })
}

/// `fmi2Terminate`.
///
/// # Safety
/// `c` is an instance from `fmi2Instantiate`.
#[no_mangle]
pub unsafe extern "C" fn fmi2Terminate(c: Component) -> Status {
    with_instance(c, "fmi2Terminate", |inst| {
        inst.slave.terminate()?;
        if let Some(s) = inst.slave.statistics() {
            inst.debug(&format!("terminated at {s}"));
        }
        Ok(FMI2_OK)
    })
}

/// `fmi2Reset`: back to the instantiated state with the start values.
///
/// # Safety
/// `c` is an instance from `fmi2Instantiate`.
#[no_mangle]
pub unsafe extern "C" fn fmi2Reset(c: Component) -> Status {
    with_instance(c, "fmi2Reset", |inst| {
        inst.slave.reset();
        Ok(FMI2_OK)
    })
}

// ---------------------------------------------------------------------------------------------
// Values

/// `fmi2GetReal`.
///
/// # Safety
/// `c` is an instance; `vr` and `value` hold `nvr` elements.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetReal(
    c: Component,
    vr: *const c_uint,
    nvr: usize,
    value: *mut f64,
) -> Status {
    with_instance(c, "fmi2GetReal", |inst| {
        // SAFETY: the importer passes `nvr` value references and room for `nvr` values.
        let (vrs, out) = unsafe { (slice(vr, nvr, "vr")?, slice_mut(value, nvr, "value")?) };
        inst.slave.get_real(vrs, out)?;
        Ok(FMI2_OK)
    })
}

/// `fmi2SetReal`.
///
/// # Safety
/// `c` is an instance; `vr` and `value` hold `nvr` elements.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetReal(
    c: Component,
    vr: *const c_uint,
    nvr: usize,
    value: *const f64,
) -> Status {
    with_instance(c, "fmi2SetReal", |inst| {
        // SAFETY: the importer passes `nvr` value references and `nvr` values.
        let (vrs, vals) = unsafe { (slice(vr, nvr, "vr")?, slice(value, nvr, "value")?) };
        inst.slave.set_real(vrs, vals)?;
        Ok(FMI2_OK)
    })
}

/// The answer to a get/set of a type the FMU has no variables of: fine for no variables, an
/// error naming the first value reference otherwise.
///
/// # Safety
/// `vr` holds `nvr` elements.
unsafe fn no_variables_of(
    c: Component,
    function: &'static str,
    kind: &'static str,
    vr: *const c_uint,
    nvr: usize,
) -> Status {
    with_instance(c, function, |_| {
        // SAFETY: the importer passes `nvr` value references.
        let vrs = unsafe { slice(vr, nvr, "vr") }?;
        match vrs.first() {
            None => Ok(FMI2_OK),
            Some(r) => Err(format!(
                "{function}: this FMU has no {kind} variables (value reference {r})"
            )),
        }
    })
}

/// `fmi2GetInteger`: there are no Integer variables.
///
/// # Safety
/// `c` is an instance; `vr` holds `nvr` elements.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetInteger(
    c: Component,
    vr: *const c_uint,
    nvr: usize,
    _value: *mut c_int,
) -> Status {
    // SAFETY: forwarded contract.
    unsafe { no_variables_of(c, "fmi2GetInteger", "Integer", vr, nvr) }
}

/// `fmi2GetBoolean`: there are no Boolean variables.
///
/// # Safety
/// `c` is an instance; `vr` holds `nvr` elements.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetBoolean(
    c: Component,
    vr: *const c_uint,
    nvr: usize,
    _value: *mut c_int,
) -> Status {
    // SAFETY: forwarded contract.
    unsafe { no_variables_of(c, "fmi2GetBoolean", "Boolean", vr, nvr) }
}

/// `fmi2GetString`: there are no String variables.
///
/// # Safety
/// `c` is an instance; `vr` holds `nvr` elements.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetString(
    c: Component,
    vr: *const c_uint,
    nvr: usize,
    _value: *mut *const c_char,
) -> Status {
    // SAFETY: forwarded contract.
    unsafe { no_variables_of(c, "fmi2GetString", "String", vr, nvr) }
}

/// `fmi2SetInteger`: there are no Integer variables.
///
/// # Safety
/// `c` is an instance; `vr` holds `nvr` elements.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetInteger(
    c: Component,
    vr: *const c_uint,
    nvr: usize,
    _value: *const c_int,
) -> Status {
    // SAFETY: forwarded contract.
    unsafe { no_variables_of(c, "fmi2SetInteger", "Integer", vr, nvr) }
}

/// `fmi2SetBoolean`: there are no Boolean variables.
///
/// # Safety
/// `c` is an instance; `vr` holds `nvr` elements.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetBoolean(
    c: Component,
    vr: *const c_uint,
    nvr: usize,
    _value: *const c_int,
) -> Status {
    // SAFETY: forwarded contract.
    unsafe { no_variables_of(c, "fmi2SetBoolean", "Boolean", vr, nvr) }
}

/// `fmi2SetString`: there are no String variables.
///
/// # Safety
/// `c` is an instance; `vr` holds `nvr` elements.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetString(
    c: Component,
    vr: *const c_uint,
    nvr: usize,
    _value: *const *const c_char,
) -> Status {
    // SAFETY: forwarded contract.
    unsafe { no_variables_of(c, "fmi2SetString", "String", vr, nvr) }
}

// ---------------------------------------------------------------------------------------------
// Capabilities the model description declares absent: each answers fmi2Error with a message.

/// Logs that `function` is not provided (the capability flag says so) and returns
/// `fmi2Error`.
fn unsupported(c: Component, function: &'static str, flag: &'static str) -> Status {
    with_instance(c, function, |_| {
        Err(format!(
            "{function} is not supported by this FMU (modelDescription.xml: {flag})"
        ))
    })
}

/// `fmi2GetFMUstate`: not supported.
#[no_mangle]
pub extern "C" fn fmi2GetFMUstate(c: Component, _state: *mut *mut c_void) -> Status {
    unsupported(c, "fmi2GetFMUstate", "canGetAndSetFMUstate=\"false\"")
}

/// `fmi2SetFMUstate`: not supported.
#[no_mangle]
pub extern "C" fn fmi2SetFMUstate(c: Component, _state: *mut c_void) -> Status {
    unsupported(c, "fmi2SetFMUstate", "canGetAndSetFMUstate=\"false\"")
}

/// `fmi2FreeFMUstate`: not supported.
#[no_mangle]
pub extern "C" fn fmi2FreeFMUstate(c: Component, _state: *mut *mut c_void) -> Status {
    unsupported(c, "fmi2FreeFMUstate", "canGetAndSetFMUstate=\"false\"")
}

/// `fmi2SerializedFMUstateSize`: not supported.
#[no_mangle]
pub extern "C" fn fmi2SerializedFMUstateSize(
    c: Component,
    _state: *mut c_void,
    _size: *mut usize,
) -> Status {
    unsupported(
        c,
        "fmi2SerializedFMUstateSize",
        "canSerializeFMUstate=\"false\"",
    )
}

/// `fmi2SerializeFMUstate`: not supported.
#[no_mangle]
pub extern "C" fn fmi2SerializeFMUstate(
    c: Component,
    _state: *mut c_void,
    _bytes: *mut c_char,
    _size: usize,
) -> Status {
    unsupported(c, "fmi2SerializeFMUstate", "canSerializeFMUstate=\"false\"")
}

/// `fmi2DeSerializeFMUstate`: not supported.
#[no_mangle]
pub extern "C" fn fmi2DeSerializeFMUstate(
    c: Component,
    _bytes: *const c_char,
    _size: usize,
    _state: *mut *mut c_void,
) -> Status {
    unsupported(
        c,
        "fmi2DeSerializeFMUstate",
        "canSerializeFMUstate=\"false\"",
    )
}

/// `fmi2GetDirectionalDerivative`: not supported.
#[no_mangle]
pub extern "C" fn fmi2GetDirectionalDerivative(
    c: Component,
    _unknown: *const c_uint,
    _n_unknown: usize,
    _known: *const c_uint,
    _n_known: usize,
    _dv_known: *const f64,
    _dv_unknown: *mut f64,
) -> Status {
    unsupported(
        c,
        "fmi2GetDirectionalDerivative",
        "providesDirectionalDerivative=\"false\"",
    )
}

/// `fmi2SetRealInputDerivatives`: not supported.
#[no_mangle]
pub extern "C" fn fmi2SetRealInputDerivatives(
    c: Component,
    _vr: *const c_uint,
    _nvr: usize,
    _order: *const c_int,
    _value: *const f64,
) -> Status {
    unsupported(
        c,
        "fmi2SetRealInputDerivatives",
        "canInterpolateInputs=\"false\"",
    )
}

/// `fmi2GetRealOutputDerivatives`: not supported.
#[no_mangle]
pub extern "C" fn fmi2GetRealOutputDerivatives(
    c: Component,
    _vr: *const c_uint,
    _nvr: usize,
    _order: *const c_int,
    _value: *mut f64,
) -> Status {
    unsupported(
        c,
        "fmi2GetRealOutputDerivatives",
        "maxOutputDerivativeOrder=\"0\"",
    )
}

/// `fmi2CancelStep`: not supported (steps are synchronous).
#[no_mangle]
pub extern "C" fn fmi2CancelStep(c: Component) -> Status {
    unsupported(c, "fmi2CancelStep", "canRunAsynchronuously=\"false\"")
}

// ---------------------------------------------------------------------------------------------
// Stepping and status

/// `fmi2DoStep`: integrates from `current` to `current + step` (synchronously: never
/// `fmi2Pending`).
///
/// # Safety
/// `c` is an instance from `fmi2Instantiate`.
#[no_mangle]
pub unsafe extern "C" fn fmi2DoStep(
    c: Component,
    current: f64,
    step: f64,
    _no_set_fmu_state_prior: c_int,
) -> Status {
    with_instance(c, "fmi2DoStep", |inst| {
        inst.slave.do_step(current, step)?;
        Ok(FMI2_OK)
    })
}

/// `fmi2GetStatus`: steps are synchronous, so there is no pending step to report.
///
/// # Safety
/// `c` is an instance from `fmi2Instantiate`.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetStatus(c: Component, kind: c_int, _value: *mut Status) -> Status {
    status_discard(c, "fmi2GetStatus", kind)
}

/// `fmi2GetIntegerStatus`: no integer status is defined.
///
/// # Safety
/// `c` is an instance from `fmi2Instantiate`.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetIntegerStatus(
    c: Component,
    kind: c_int,
    _value: *mut c_int,
) -> Status {
    status_discard(c, "fmi2GetIntegerStatus", kind)
}

/// `fmi2GetStringStatus`: no pending step, so no status message.
///
/// # Safety
/// `c` is an instance from `fmi2Instantiate`.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetStringStatus(
    c: Component,
    kind: c_int,
    _value: *mut *const c_char,
) -> Status {
    status_discard(c, "fmi2GetStringStatus", kind)
}

/// `fmi2Discard` (the status is not available), with a diagnostic.
fn status_discard(c: Component, function: &'static str, kind: c_int) -> Status {
    with_instance(c, function, |inst| {
        inst.debug(&format!(
            "{function}: status kind {kind} is not available (steps are synchronous)"
        ));
        Ok(FMI2_DISCARD)
    })
}

/// `fmi2GetRealStatus`: `fmi2LastSuccessfulTime` is the time reached.
///
/// # Safety
/// `c` is an instance; `value` is a writable `fmi2Real`.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetRealStatus(c: Component, kind: c_int, value: *mut f64) -> Status {
    with_instance(c, "fmi2GetRealStatus", |inst| {
        // SAFETY: the importer passes room for one value.
        let out = unsafe { slice_mut(value, 1, "value") }?;
        if kind == FMI2_LAST_SUCCESSFUL_TIME {
            out[0] = inst.slave.last_successful_time();
            Ok(FMI2_OK)
        } else {
            Ok(FMI2_DISCARD)
        }
    })
}

/// `fmi2GetBooleanStatus`: `fmi2Terminated` is always false (the FMU never ends a
/// simulation by itself).
///
/// # Safety
/// `c` is an instance; `value` is a writable `fmi2Boolean`.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetBooleanStatus(
    c: Component,
    kind: c_int,
    value: *mut c_int,
) -> Status {
    with_instance(c, "fmi2GetBooleanStatus", |inst| {
        // SAFETY: the importer passes room for one value.
        let out = unsafe { slice_mut(value, 1, "value") }?;
        let _ = inst;
        if kind == FMI2_TERMINATED {
            out[0] = FMI2_FALSE;
            Ok(FMI2_OK)
        } else {
            Ok(FMI2_DISCARD)
        }
    })
}
