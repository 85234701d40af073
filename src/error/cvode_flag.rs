//! A SUNDIALS return flag as data: its code, SUNDIALS' name for it and CVODE's message.

use std::fmt;

use serde::Serialize;

/// A SUNDIALS return flag: the numeric code with SUNDIALS' own name (`CV_TOO_MUCH_WORK` for
/// −1), or a condition without a code (a constructor that returned `NULL`, a library version
/// mismatch), and CVODE's error message when it printed one. Displayed as `NAME (message)`.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct CvodeFlag {
    /// The return code (`None`: a condition without one, e.g. a `NULL` return).
    pub code: Option<i32>,
    /// SUNDIALS' name of the code (`CV_TOO_MUCH_WORK`, `CVLS_SUNLS_FAIL`, ...) or the condition
    /// (`NULL`).
    pub name: String,
    /// CVODE's own message about it, if any.
    pub message: Option<String>,
}

impl CvodeFlag {
    /// A condition without a return code, named `name` (e.g. `NULL`).
    pub fn condition(name: impl Into<String>) -> CvodeFlag {
        CvodeFlag {
            code: None,
            name: name.into(),
            message: None,
        }
    }
}

impl fmt::Display for CvodeFlag {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.message {
            Some(m) => write!(f, "{} ({m})", self.name),
            None => write!(f, "{}", self.name),
        }
    }
}
