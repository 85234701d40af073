//! A minimal FMI 2.0 co-simulation importer over `libloading`: loads an FMU binary, resolves
//! its functions and wraps one instance in a value that frees it on drop. The test binary's only
//! `unsafe` code.
//!
//! The C declarations are written from the FMI 2.0 standard (`fmi2FunctionTypes.h`): statuses
//! and booleans are `int`, value references `unsigned int`, reals `double`, the component and
//! the environment `void*`.

use std::ffi::{c_char, c_int, c_uint, c_void, CStr, CString};
use std::path::Path;
use std::sync::Mutex;

use libloading::Library;

pub type Status = c_int;
pub const OK: Status = 0;
pub const ERROR: Status = 3;

type Component = *mut c_void;

/// The logger as this importer defines it: FMI declares it variadic; the FMU under test passes
/// no variadic argument (its messages come with `%` doubled), and on x86-64 System V a call
/// through the variadic type reaches a non-variadic function of the same fixed parameters
/// correctly.
type Logger =
    unsafe extern "C" fn(*mut c_void, *const c_char, Status, *const c_char, *const c_char);

/// `fmi2CallbackFunctions`.
#[repr(C)]
struct Callbacks {
    logger: Option<Logger>,
    allocate_memory: Option<unsafe extern "C" fn(usize, usize) -> *mut c_void>,
    free_memory: Option<unsafe extern "C" fn(*mut c_void)>,
    step_finished: Option<unsafe extern "C" fn(*mut c_void, Status)>,
    component_environment: *mut c_void,
}

/// The messages an instance logged: `(status, category, message)`.
type Log = Mutex<Vec<(Status, String, String)>>;

/// Appends a message to the [`Log`] behind `env`.
unsafe extern "C" fn logger(
    env: *mut c_void,
    _name: *const c_char,
    status: Status,
    category: *const c_char,
    message: *const c_char,
) {
    let text = |p: *const c_char| {
        if p.is_null() {
            String::new()
        } else {
            // SAFETY: the FMU passes NUL-terminated strings valid for the call.
            unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned()
        }
    };
    // SAFETY: `env` is the `Log` the instance's owner boxed and keeps alive while the
    // instance exists (see `Instance`); the FMU calls back on the caller's thread.
    let log = unsafe { &*env.cast::<Log>() };
    // The FMU doubles `%` for printf; undo it as a printf-style logger would.
    let message = text(message).replace("%%", "%");
    if let Ok(mut l) = log.lock() {
        l.push((status, text(category), message));
    }
}

type Instantiate = unsafe extern "C" fn(
    *const c_char,
    c_int,
    *const c_char,
    *const c_char,
    *const Callbacks,
    c_int,
    c_int,
) -> Component;
type Free = unsafe extern "C" fn(Component);
type Setup = unsafe extern "C" fn(Component, c_int, f64, f64, c_int, f64) -> Status;
type Unary = unsafe extern "C" fn(Component) -> Status;
type GetReal = unsafe extern "C" fn(Component, *const c_uint, usize, *mut f64) -> Status;
type SetReal = unsafe extern "C" fn(Component, *const c_uint, usize, *const f64) -> Status;
type DoStep = unsafe extern "C" fn(Component, f64, f64, c_int) -> Status;
type GetState = unsafe extern "C" fn(Component, *mut *mut c_void) -> Status;
type RealStatus = unsafe extern "C" fn(Component, c_int, *mut f64) -> Status;

/// Every function of the FMI 2.0 co-simulation interface (common and CS-specific).
pub const CS_FUNCTIONS: [&str; 34] = [
    "fmi2GetTypesPlatform",
    "fmi2GetVersion",
    "fmi2SetDebugLogging",
    "fmi2Instantiate",
    "fmi2FreeInstance",
    "fmi2SetupExperiment",
    "fmi2EnterInitializationMode",
    "fmi2ExitInitializationMode",
    "fmi2Terminate",
    "fmi2Reset",
    "fmi2GetReal",
    "fmi2GetInteger",
    "fmi2GetBoolean",
    "fmi2GetString",
    "fmi2SetReal",
    "fmi2SetInteger",
    "fmi2SetBoolean",
    "fmi2SetString",
    "fmi2GetFMUstate",
    "fmi2SetFMUstate",
    "fmi2FreeFMUstate",
    "fmi2SerializedFMUstateSize",
    "fmi2SerializeFMUstate",
    "fmi2DeSerializeFMUstate",
    "fmi2GetDirectionalDerivative",
    "fmi2SetRealInputDerivatives",
    "fmi2GetRealOutputDerivatives",
    "fmi2DoStep",
    "fmi2CancelStep",
    "fmi2GetStatus",
    "fmi2GetRealStatus",
    "fmi2GetIntegerStatus",
    "fmi2GetBooleanStatus",
    "fmi2GetStringStatus",
];

/// A loaded FMU binary and the functions the tests call.
pub struct Fmu {
    instantiate: Instantiate,
    free: Free,
    setup: Setup,
    enter: Unary,
    exit: Unary,
    terminate: Unary,
    reset: Unary,
    get_real: GetReal,
    set_real: SetReal,
    do_step: DoStep,
    get_state: GetState,
    real_status: RealStatus,
    version: unsafe extern "C" fn() -> *const c_char,
    /// Kept last: the function pointers above are valid while the library is loaded.
    lib: Library,
}

/// The function `name` of `lib` as a plain function pointer of type `T`.
///
/// # Safety
/// `T` is the function's true C type.
unsafe fn function<T: Copy>(lib: &Library, name: &str) -> T {
    let c = CString::new(name).unwrap();
    // SAFETY: by this function's contract; the pointer is used only while `lib` is loaded.
    unsafe {
        *lib.get::<T>(c.as_bytes_with_nul())
            .unwrap_or_else(|e| panic!("{name}: {e}"))
    }
}

impl Fmu {
    /// Loads the binary at `path`.
    pub fn load(path: &Path) -> Fmu {
        // SAFETY: loading the FMU binary runs no initialisation code of its own beyond Rust's
        // and the SUNDIALS libraries' (none with side effects on this process's state).
        let lib =
            unsafe { Library::new(path) }.unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        // SAFETY: each type is the FMI 2.0 declaration of the function named.
        unsafe {
            Fmu {
                instantiate: function(&lib, "fmi2Instantiate"),
                free: function(&lib, "fmi2FreeInstance"),
                setup: function(&lib, "fmi2SetupExperiment"),
                enter: function(&lib, "fmi2EnterInitializationMode"),
                exit: function(&lib, "fmi2ExitInitializationMode"),
                terminate: function(&lib, "fmi2Terminate"),
                reset: function(&lib, "fmi2Reset"),
                get_real: function(&lib, "fmi2GetReal"),
                set_real: function(&lib, "fmi2SetReal"),
                do_step: function(&lib, "fmi2DoStep"),
                get_state: function(&lib, "fmi2GetFMUstate"),
                real_status: function(&lib, "fmi2GetRealStatus"),
                version: function(&lib, "fmi2GetVersion"),
                lib,
            }
        }
    }

    /// Whether the binary exports the C symbol `name`.
    pub fn exports(&self, name: &str) -> bool {
        let c = CString::new(name).unwrap();
        // SAFETY: only the symbol's address is looked up, never called.
        unsafe { self.lib.get::<*const c_void>(c.as_bytes_with_nul()).is_ok() }
    }

    /// `fmi2GetVersion`.
    pub fn version(&self) -> String {
        // SAFETY: returns a static NUL-terminated string.
        unsafe { CStr::from_ptr((self.version)()) }
            .to_string_lossy()
            .into_owned()
    }

    /// `fmi2FreeInstance(NULL)` and the status of `fmi2DoStep(NULL, ...)`.
    pub fn null_component_calls(&self) -> Status {
        // SAFETY: FMI functions must accept a NULL component without touching memory (this
        // FMU's do: it checks before use).
        unsafe {
            (self.free)(std::ptr::null_mut());
            (self.do_step)(std::ptr::null_mut(), 0.0, 1e-4, 1)
        }
    }
}

/// One FMU instance; freed on drop.
pub struct Instance<'a> {
    fmu: &'a Fmu,
    c: Component,
    log: Box<Log>,
    // Kept alive while the instance may call back (FMI lets the FMU keep the pointer).
    _callbacks: Box<Callbacks>,
}

impl<'a> Instance<'a> {
    /// `fmi2Instantiate` (co-simulation when `cs`); on NULL the messages logged.
    pub fn new(
        fmu: &'a Fmu,
        guid: &str,
        resources_uri: &str,
        cs: bool,
    ) -> Result<Instance<'a>, Vec<String>> {
        let log: Box<Log> = Box::new(Mutex::new(Vec::new()));
        let callbacks = Box::new(Callbacks {
            logger: Some(logger),
            allocate_memory: None,
            free_memory: None,
            step_finished: None,
            component_environment: (&*log as *const Log).cast_mut().cast(),
        });
        let name = CString::new("test instance").unwrap();
        let guid = CString::new(guid).unwrap();
        let uri = CString::new(resources_uri).unwrap();
        // SAFETY: NUL-terminated strings and a callback struct that outlive the call; the
        // struct and the log outlive the instance (fields of the returned value).
        let c = unsafe {
            (fmu.instantiate)(
                name.as_ptr(),
                c_int::from(cs),
                guid.as_ptr(),
                uri.as_ptr(),
                &*callbacks,
                0,
                0,
            )
        };
        if c.is_null() {
            return Err(log.lock().unwrap().iter().map(|m| m.2.clone()).collect());
        }
        Ok(Instance {
            fmu,
            c,
            log,
            _callbacks: callbacks,
        })
    }

    /// The messages logged so far (`status: message`), and clears them.
    pub fn take_log(&self) -> Vec<String> {
        std::mem::take(&mut *self.log.lock().unwrap())
            .into_iter()
            .map(|(s, cat, m)| format!("{s} [{cat}] {m}"))
            .collect()
    }

    /// `fmi2SetupExperiment`.
    pub fn setup(&self, tolerance: Option<f64>, start: f64, stop: Option<f64>) -> Status {
        // SAFETY: a live instance of this FMU.
        unsafe {
            (self.fmu.setup)(
                self.c,
                c_int::from(tolerance.is_some()),
                tolerance.unwrap_or(0.0),
                start,
                c_int::from(stop.is_some()),
                stop.unwrap_or(0.0),
            )
        }
    }

    /// `fmi2EnterInitializationMode`.
    pub fn enter(&self) -> Status {
        // SAFETY: a live instance of this FMU.
        unsafe { (self.fmu.enter)(self.c) }
    }

    /// `fmi2ExitInitializationMode`.
    pub fn exit(&self) -> Status {
        // SAFETY: a live instance of this FMU.
        unsafe { (self.fmu.exit)(self.c) }
    }

    /// `fmi2Terminate`.
    pub fn terminate(&self) -> Status {
        // SAFETY: a live instance of this FMU.
        unsafe { (self.fmu.terminate)(self.c) }
    }

    /// `fmi2Reset`.
    pub fn reset(&self) -> Status {
        // SAFETY: a live instance of this FMU.
        unsafe { (self.fmu.reset)(self.c) }
    }

    /// `fmi2DoStep(t, h)`.
    pub fn do_step(&self, t: f64, h: f64) -> Status {
        // SAFETY: a live instance of this FMU.
        unsafe { (self.fmu.do_step)(self.c, t, h, 1) }
    }

    /// `fmi2SetReal`.
    pub fn set_real(&self, vr: &[u32], values: &[f64]) -> Status {
        assert_eq!(vr.len(), values.len());
        // SAFETY: both arrays hold `vr.len()` elements.
        unsafe { (self.fmu.set_real)(self.c, vr.as_ptr(), vr.len(), values.as_ptr()) }
    }

    /// `fmi2GetReal`: the status and the values.
    pub fn get_real(&self, vr: &[u32]) -> (Status, Vec<f64>) {
        let mut out = vec![f64::NAN; vr.len()];
        // SAFETY: both arrays hold `vr.len()` elements.
        let s = unsafe { (self.fmu.get_real)(self.c, vr.as_ptr(), vr.len(), out.as_mut_ptr()) };
        (s, out)
    }

    /// `fmi2GetFMUstate` (not supported by the FMU).
    pub fn get_fmu_state(&self) -> Status {
        let mut state = std::ptr::null_mut();
        // SAFETY: a live instance and a writable state pointer.
        unsafe { (self.fmu.get_state)(self.c, &mut state) }
    }

    /// `fmi2GetRealStatus(fmi2LastSuccessfulTime)`.
    pub fn last_successful_time(&self) -> (Status, f64) {
        let mut t = f64::NAN;
        // SAFETY: a live instance and a writable real.
        let s = unsafe { (self.fmu.real_status)(self.c, 2, &mut t) };
        (s, t)
    }
}

impl Drop for Instance<'_> {
    fn drop(&mut self) {
        // SAFETY: the instance is live and freed only here.
        unsafe { (self.fmu.free)(self.c) };
    }
}
