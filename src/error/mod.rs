//! The crate's error type: one enum, a variant per layer, each naming what was wrong and where.
//! The layers' own typed reasons live here too, so that every layer can use them and this
//! module imports nothing from the layers but [`LinalgError`]: [`ElementError`] (elements and
//! materials), the request errors of `request.rs` ([`ModelError`], [`JointError`],
//! [`SystemError`], [`ReductionError`], [`IntegrationError`], [`ReportError`], [`FlagError`],
//! [`RomError`], [`StudyError`]), and SUNDIALS' return flag [`CvodeFlag`].

use std::path::PathBuf;

mod cvode_flag;
mod element;
mod request;

pub use crate::linalg::LinalgError;
pub use cvode_flag::CvodeFlag;
pub use element::{ElementError, WeldLayerProblem};
pub use request::{
    FlagError, FontError, IntegrationError, JointError, ModelError, ReductionError,
    ReferenceProblem, ReportError, RomError, StudyError, SystemError,
};

/// Everything that can go wrong in jointrom. Bad input is an error, never a panic.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// An input file could not be read: the file and the OS error; the message says which kind
    /// (no such file, a folder, a link loop, a name too long, over the input budget, ...).
    #[error("{}: cannot read: {}", file.display(), crate::files::describe(source))]
    Io {
        file: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// An output could not be written: the file or folder, what failed (`write`, `create
    /// folder`, `rename into place`) and the OS error, named by kind as for [`Error::Io`].
    #[error("{}: cannot {action}: {}", file.display(), crate::files::describe(source))]
    Write {
        file: PathBuf,
        action: &'static str,
        #[source]
        source: std::io::Error,
    },
    /// A case file (or a matrix map) is malformed or violates the schema; `path` is the JSON path
    /// (e.g. `sheets[1].thickness`); `source` is serde's error when the JSON did not parse into
    /// the schema.
    #[error("{file}: at `{path}`: {reason}")]
    Case {
        file: String,
        path: String,
        reason: String,
        #[source]
        source: Option<Box<serde_json::Error>>,
    },
    /// A JSON document jointrom reads besides case files and maps (an exported reduced model, a
    /// sweep's variants) is malformed: the file, the JSON path, the reason, and serde's error as
    /// the source when the JSON did not parse into the schema.
    #[error("{}: at `{path}`: {reason}", file.display())]
    Document {
        file: PathBuf,
        path: String,
        reason: String,
        #[source]
        source: Option<Box<serde_json::Error>>,
    },
    /// A NASTRAN deck is malformed or asks for what jointrom does not model: the file and line
    /// of the card, the card (name and id) and the reason.
    #[error("{}:{line}: {card}: {reason}", file.display())]
    Deck {
        file: PathBuf,
        line: usize,
        card: String,
        reason: String,
    },
    /// An element could not be built (degenerate geometry, bad material).
    #[error("element: {0}")]
    Element(#[from] ElementError),
    /// A linear-algebra failure: singular or indefinite matrix, failed factorization, a
    /// numerical check that failed. `From<LinalgError>` puts requests the matrices cannot serve
    /// ([`LinalgError::is_request`]) in [`Error::MatrixRequest`] instead.
    #[error("linear algebra: {0}")]
    LinearAlgebra(#[source] LinalgError),
    /// A request the matrices cannot serve (a mode count out of range, mismatched patterns).
    #[error("invalid request: {0}")]
    MatrixRequest(#[source] LinalgError),
    /// A model request that does not fit (an export the map cannot express, a degenerate gap).
    #[error("invalid request: {0}")]
    Model(#[from] ModelError),
    /// A joint or contact-statics request that does not fit (bad options, sizes, nodes).
    #[error("invalid request: {0}")]
    Joint(#[from] JointError),
    /// A reduced model that does not fit its basis or model.
    #[error("invalid request: {0}")]
    System(#[from] SystemError),
    /// A reduction request that does not fit the model (sizes, counts, missing DOF).
    #[error("invalid request: {0}")]
    Reduction(#[from] ReductionError),
    /// A time-integration request that does not fit (times, states, options).
    #[error("invalid request: {0}")]
    Integration(#[from] IntegrationError),
    /// A report that cannot be written as asked (shapes, series, archives, charts).
    #[error("invalid request: {0}")]
    Report(#[from] ReportError),
    /// A command-line flag with a value it cannot take.
    #[error("invalid request: {0}")]
    Flag(#[from] FlagError),
    /// A model choice or reduced-model request that does not fit (flags that conflict, a
    /// tolerance out of range, a reference file, a reduced model of another case).
    #[error("invalid request: {0}")]
    Rom(#[from] RomError),
    /// A study request that does not fit, or a study that cannot go on.
    #[error("invalid request: {0}")]
    Study(#[from] StudyError),
    /// A failure reported by SUNDIALS: the C function, the flag's name and the time reached
    /// (NaN outside a time integration, e.g. when creating a context).
    #[error("SUNDIALS: {function} returned {flag}{}", time_suffix(*time))]
    Sundials {
        function: &'static str,
        flag: CvodeFlag,
        time: f64,
    },
    /// A problem callback failed during a time integration: it returned an error, panicked, or
    /// produced a NaN/Inf that persisted through the integrator's retries. `callback` names it
    /// (`rhs`, `roots`, `newton_setup`, `newton_solve`), `message` is its last message (the
    /// panic text for a panic), `time` the time it was evaluated at (s), and `flag` what the
    /// integrator reported (e.g. `CVode returned CV_REPTD_RHSFUNC_ERR at t = 0.01 s`).
    #[error("ODE callback `{callback}` failed at t = {time} s: {message} ({outcome})")]
    Callback {
        callback: &'static str,
        message: String,
        time: f64,
        outcome: CallbackOutcome,
    },
    /// Events: `roots` roots in a row without progress in time at `time` (s), a chattering
    /// stick/slip or gap switch.
    #[error(
        "invalid request: events: {roots} roots without progress at t = {time} s \
         (chattering switch); run with events off"
    )]
    Chatter { roots: usize, time: f64 },
}

impl From<LinalgError> for Error {
    fn from(e: LinalgError) -> Error {
        if e.is_request() {
            Error::MatrixRequest(e)
        } else {
            Error::LinearAlgebra(e)
        }
    }
}

/// What the integrator did about a failed callback.
#[derive(Clone, Debug, PartialEq)]
pub enum CallbackOutcome {
    /// CVODE returned `flag` at `t` (s).
    Returned { flag: CvodeFlag, t: f64 },
    /// The integration was not run: a callback had panicked before.
    NotRun,
}

impl std::fmt::Display for CallbackOutcome {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            CallbackOutcome::Returned { flag, t } => {
                write!(f, "CVode returned {flag} at t = {t} s")
            }
            CallbackOutcome::NotRun => {
                write!(
                    f,
                    "not run: a callback panicked earlier (call reinit to continue)"
                )
            }
        }
    }
}

fn time_suffix(time: f64) -> String {
    if time.is_finite() {
        format!(" at t = {time} s")
    } else {
        String::new()
    }
}
