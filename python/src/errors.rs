//! `jointrom.Error` and its subclasses. Each carries the CLI's message for the same failure
//! (the file, the JSON path or line, the flag, the C function and time).

use pyo3::create_exception;
use pyo3::exceptions::PyException;
use pyo3::prelude::*;

create_exception!(
    jointrom,
    Error,
    PyException,
    "Every failure jointrom reports; the message is the command line's."
);
create_exception!(
    jointrom,
    InputError,
    Error,
    "Bad input: a case, deck, matrix map or reduced-model file (file and field), or an option \
     (named as the command line's flag)."
);
create_exception!(
    jointrom,
    SolverError,
    Error,
    "A numerical failure: linear algebra, SUNDIALS (function, flag, time), a failed callback, \
     chattering events."
);
create_exception!(
    jointrom,
    IoError,
    Error,
    "A file could not be read or written (the file and the OS error)."
);

/// Adds the exception types to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("Error", py.get_type::<Error>())?;
    m.add("InputError", py.get_type::<InputError>())?;
    m.add("SolverError", py.get_type::<SolverError>())?;
    m.add("IoError", py.get_type::<IoError>())?;
    Ok(())
}

/// The Python exception of a jointrom error.
pub fn to_py(e: jointrom::Error) -> PyErr {
    use jointrom::Error as E;
    let msg = e.to_string();
    match e {
        E::Io { .. } | E::Write { .. } => IoError::new_err(msg),
        E::Case { .. }
        | E::Document { .. }
        | E::Deck { .. }
        | E::Element(_)
        | E::MatrixRequest(_)
        | E::Model(_)
        | E::Joint(_)
        | E::System(_)
        | E::Reduction(_)
        | E::Integration(_)
        | E::Report(_)
        | E::Flag(_)
        | E::Rom(_)
        | E::Study(_) => InputError::new_err(msg),
        E::LinearAlgebra(_) | E::Sundials { .. } | E::Callback { .. } | E::Chatter { .. } => {
            SolverError::new_err(msg)
        }
        _ => Error::new_err(msg),
    }
}

/// An [`InputError`] with `msg`.
pub fn input(msg: impl Into<String>) -> PyErr {
    InputError::new_err(msg.into())
}

/// `Result<T, jointrom::Error>` → `PyResult<T>`.
pub trait IntoPy<T> {
    fn py_err(self) -> PyResult<T>;
}

impl<T> IntoPy<T> for Result<T, jointrom::Error> {
    fn py_err(self) -> PyResult<T> {
        self.map_err(to_py)
    }
}
