//! The linear-algebra layer's error: what failed, in words, with faer's own error kept as the
//! source where faer gives one (a non-positive pivot, a failed symbolic analysis, a singular LU).

use std::error::Error as StdError;
use std::fmt;

/// A failed factorization, solve or eigen decomposition.
#[derive(Debug)]
pub struct LinalgError {
    message: String,
    source: Option<Box<dyn StdError + Send + Sync + 'static>>,
}

impl LinalgError {
    /// A failure described by `message` (no underlying library error).
    pub fn new(message: impl Into<String>) -> LinalgError {
        LinalgError {
            message: message.into(),
            source: None,
        }
    }

    /// A failure described by `message`, caused by the library error `source`.
    pub fn caused_by(
        message: impl Into<String>,
        source: impl StdError + Send + Sync + 'static,
    ) -> LinalgError {
        LinalgError {
            message: message.into(),
            source: Some(Box::new(source)),
        }
    }

    /// The description.
    pub fn message(&self) -> &str {
        &self.message
    }
}

impl fmt::Display for LinalgError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl StdError for LinalgError {
    fn source(&self) -> Option<&(dyn StdError + 'static)> {
        self.source
            .as_deref()
            .map(|s| s as &(dyn StdError + 'static))
    }
}

impl From<String> for LinalgError {
    fn from(message: String) -> LinalgError {
        LinalgError::new(message)
    }
}

impl From<&str> for LinalgError {
    fn from(message: &str) -> LinalgError {
        LinalgError::new(message)
    }
}
