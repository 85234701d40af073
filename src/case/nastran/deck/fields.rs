//! Reading a card's fields: typed access with errors naming the card and the field, NASTRAN
//! reals, component lists.

use std::collections::BTreeSet;

use crate::case::nastran::cards::{Card, Cards};
use crate::error::Error;

/// Field access with errors naming the card and the field.
pub(crate) struct Fields<'a> {
    pub(crate) cards: &'a Cards,
    pub(crate) card: &'a Card,
}

impl Fields<'_> {
    pub(crate) fn error(&self, reason: impl Into<String>) -> Error {
        self.cards.error(self.card, reason)
    }

    /// Data field `k` (1 = the first after the name), trimmed, "" when blank or absent.
    pub(crate) fn raw(&self, k: usize) -> &str {
        self.card.fields.get(k - 1).map_or("", |s| s.as_str())
    }

    pub(super) fn bad(&self, name: &str, expected: &str, found: &str) -> Error {
        self.error(format!(
            "{name}: expected {expected}, found `{}`",
            crate::files::printable(found)
        ))
    }

    pub(crate) fn int_opt(&self, k: usize, name: &str) -> Result<Option<i64>, Error> {
        let s = self.raw(k);
        if s.is_empty() {
            return Ok(None);
        }
        let digits = s.strip_prefix(['+', '-']).unwrap_or(s);
        if digits.is_empty() || digits.len() > 15 || !digits.bytes().all(|b| b.is_ascii_digit()) {
            return Err(self.bad(name, "an integer", s));
        }
        s.parse::<i64>()
            .map(Some)
            .map_err(|_| self.bad(name, "an integer", s))
    }

    pub(crate) fn int(&self, k: usize, name: &str) -> Result<i64, Error> {
        self.int_opt(k, name)?
            .ok_or_else(|| self.error(format!("{name}: required, found a blank field")))
    }

    /// A positive id.
    pub(crate) fn id(&self, k: usize, name: &str) -> Result<i64, Error> {
        let v = self.int(k, name)?;
        if v <= 0 {
            return Err(self.error(format!("{name}: an id must be > 0, found {v}")));
        }
        Ok(v)
    }

    pub(crate) fn real_opt(&self, k: usize, name: &str) -> Result<Option<f64>, Error> {
        let s = self.raw(k);
        if s.is_empty() {
            return Ok(None);
        }
        parse_real(s)
            .map(Some)
            .ok_or_else(|| self.bad(name, "a finite real number", s))
    }

    pub(crate) fn real(&self, k: usize, name: &str) -> Result<f64, Error> {
        self.real_opt(k, name)?
            .ok_or_else(|| self.error(format!("{name}: required, found a blank field")))
    }

    pub(super) fn real_or(&self, k: usize, name: &str, default: f64) -> Result<f64, Error> {
        Ok(self.real_opt(k, name)?.unwrap_or(default))
    }

    pub(super) fn word(&self, k: usize) -> String {
        self.raw(k).to_ascii_uppercase()
    }

    /// Fields from `k` on must be blank (`what` names them in the error).
    pub(super) fn blank_from(&self, k: usize, what: &str) -> Result<(), Error> {
        if let Some(j) = (k..=self.card.fields.len()).find(|&j| !self.raw(j).is_empty()) {
            return Err(self.error(format!(
                "{what}: unexpected `{}` in data field {j}",
                crate::files::printable(self.raw(j))
            )));
        }
        Ok(())
    }
}

/// A NASTRAN real: `1.5`, `-.5`, `1.E4`, `1.5D-3`, `7.85-9` (exponent without E), `2` (an
/// integer, read as a real). `None` for anything else, and for non-finite values.
pub fn parse_real(s: &str) -> Option<f64> {
    let upper = s.trim().to_ascii_uppercase().replace('D', "E");
    if upper.is_empty()
        || !upper
            .bytes()
            .all(|b| b.is_ascii_digit() || matches!(b, b'.' | b'+' | b'-' | b'E'))
    {
        return None;
    }
    let text = if upper.contains('E') {
        upper
    } else {
        // An exponent sign after the mantissa: 7.85-9 → 7.85E-9.
        match upper[1..].find(['+', '-']) {
            Some(i) => format!("{}E{}", &upper[..=i], &upper[i + 1..]),
            None => upper,
        }
    };
    let v: f64 = text.parse().ok()?;
    v.is_finite().then_some(v)
}

/// Whether a component field lists all six components (`123456` in any order).
pub(super) fn is_all_six(s: &str) -> bool {
    let set: BTreeSet<u8> = s.bytes().collect();
    s.len() == 6 && set.len() == 6 && set.iter().all(|d| (b'1'..=b'6').contains(d))
}

#[cfg(test)]
mod tests {
    use super::parse_real;

    #[test]
    fn nastran_reals() {
        assert_eq!(parse_real("1.5"), Some(1.5));
        assert_eq!(parse_real("-.5"), Some(-0.5));
        assert_eq!(parse_real("1.E4"), Some(1e4));
        assert_eq!(parse_real("7.85-9"), Some(7.85e-9));
        assert_eq!(parse_real("2.1+5"), Some(2.1e5));
        assert_eq!(parse_real("1.5D-3"), Some(1.5e-3));
        assert_eq!(parse_real("-1.-3"), Some(-1e-3));
        assert_eq!(parse_real("3"), Some(3.0));
        assert_eq!(parse_real("nan"), None);
        assert_eq!(parse_real("inf"), None);
        assert_eq!(parse_real("1.e999"), None);
        assert_eq!(parse_real("1..2"), None);
        assert_eq!(parse_real("+"), None);
    }
}
