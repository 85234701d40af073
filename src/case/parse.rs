//! JSON text to [`Case`], with serde errors turned into [`Error::Case`] that name the JSON path
//! (serde's error kept as the source).

use super::Case;
use crate::error::Error;

/// Parses `text` (the whole text must be one JSON object; unknown fields are rejected).
pub(super) fn parse(text: &str, file: &str) -> Result<Case, Error> {
    parse_object(text, file, "a case file")
}

/// Parses `text` as one JSON object of type `T`; errors are [`Error::Case`] naming `file` and
/// the JSON path. `what` names the kind of file in the error for a non-object.
pub(crate) fn parse_object<T: serde::de::DeserializeOwned>(
    text: &str,
    file: &str,
    what: &str,
) -> Result<T, Error> {
    // serde's derived structs also accept a JSON array (fields by position); these files are
    // objects.
    let first = text.trim_start().chars().next();
    if first.is_some_and(|c| c != '{') {
        return Err(Error::Case {
            file: file.to_string(),
            path: "$".to_string(),
            reason: format!("{what} must be one JSON object `{{ ... }}`"),
            source: None,
        });
    }
    let mut de = serde_json::Deserializer::from_str(text);
    let value: T = serde_path_to_error::deserialize(&mut de).map_err(|e| {
        let path = e.path().to_string();
        let e = e.into_inner();
        let typed = typed_reason::<T>(text, &path, &e);
        serde_error(file, &path, e, typed)
    })?;
    de.end().map_err(|e| serde_error(file, ".", e, None))?;
    Ok(value)
}

/// The reason for a "syntax" error of serde_json's typed reader that is not one: an enum field
/// (a name among fixed choices) given a number, `null`, `true` or an array makes the reader
/// report `expected value`, as for text that is no JSON at all. If the whole text is valid JSON,
/// the value is read again from its parsed form, whose reader says what it found and what it
/// expected (`invalid type: integer `1`, expected string or map`); taken only where that reader
/// stops at the same path (`path`).
fn typed_reason<T: serde::de::DeserializeOwned>(
    text: &str,
    path: &str,
    e: &serde_json::Error,
) -> Option<String> {
    if e.classify() != serde_json::error::Category::Syntax {
        return None;
    }
    let parsed: serde_json::Value = serde_json::from_str(text).ok()?;
    let typed = serde_path_to_error::deserialize::<_, T>(parsed).err()?;
    (typed.path().to_string() == path).then(|| typed.into_inner().to_string())
}

/// One serde_json error as [`Error::Case`]: the path as `serde_path_to_error` renders it (its
/// root `.` and an unknown top-level segment `?` are shown as `$`), extended by the field's name
/// for a missing field; the reason is the message (or `typed`, [`typed_reason`]) with its line
/// and column.
fn serde_error(file: &str, path: &str, e: serde_json::Error, typed: Option<String>) -> Error {
    let full = e.to_string();
    let position = format!(" at line {} column {}", e.line(), e.column());
    let is_typed = typed.is_some();
    let full = typed.unwrap_or(full);
    let message = full.strip_suffix(&position).unwrap_or(&full);
    let missing = message
        .strip_prefix("missing field `")
        .and_then(|rest| rest.strip_suffix('`'));
    let path = match (path, missing) {
        (".", Some(field)) => field.to_string(),
        (_, Some(field)) => format!("{path}.{field}"),
        (".", None) | ("?", None) => "$".to_string(),
        (_, None) => path.to_string(),
    };
    let message = if e.line() == 0 {
        message.to_string()
    } else {
        format!("{message} (line {}, column {})", e.line(), e.column())
    };
    let reason = match e.classify() {
        _ if message.starts_with("number out of range") => {
            format!("not a finite number: {message}")
        }
        serde_json::error::Category::Syntax | serde_json::error::Category::Eof if !is_typed => {
            format!("invalid JSON: {message}")
        }
        _ => message,
    };
    Error::Case {
        file: file.to_string(),
        path,
        reason,
        source: Some(Box::new(e)),
    }
}
