//! A strict MatrixMarket reader for a user's K and M.
//!
//! `sprs::io::read_matrix_market` is lenient where a structural model must not be: it trusts
//! the size line (a file holding more entries than declared is cut short without a word, a
//! declared size of 10¹² rows is allocated before anything else is read, an index beyond it
//! panics), sums duplicate entries, and mirrors every entry of a `symmetric` file, so a file that
//! stores both triangles doubles every off-diagonal. Each of these gives a model that is silently
//! wrong (the friction bar's tip moved −4e-6 mm instead of −15.7 mm). This reader streams the
//! file once and accepts only what the format says:
//!
//! - the header `%%MatrixMarket matrix coordinate real|integer symmetric|general` (anything else
//!   — `array`, `pattern`, `complex`, `skew-symmetric`, `hermitian` — is named and refused);
//! - comment lines (`%`) and blank lines anywhere before or between entries;
//! - a size line `rows cols entries`, square, at least one row, at most
//!   [`crate::files::dof_budget`] rows (checked before anything is allocated);
//! - exactly `entries` lines `row col value`, 1-based indices within the size, finite values;
//!   a `symmetric` file stores one triangle (the standard's lower one, or the upper one as
//!   some writers — sprs among them — do): an entry stored together with its mirror image is an
//!   error naming both lines, since a lenient reader counts that off-diagonal twice;
//! - no entry twice (both lines are named), unless the caller sums duplicates on request (the
//!   map's `"duplicates": "sum"`, for exporters that write element contributions unassembled);
//! - more rows than stored entries is refused: every kept row needs at least its diagonal, and
//!   memory stays proportional to what the file holds, not to what it declares.
//!
//! The result is the full (both triangles) list of entries, sorted by column, then row.

/// Tolerance of the symmetry check, relative to the largest entry.
pub const SYMMETRY_TOLERANCE: f64 = 1e-12;

use std::io::BufRead;
use std::path::Path;

use crate::error::Error;

/// One stored entry (row, column, value), 0-based.
pub type Triplet = (usize, usize, f64);

/// What to do with an entry given twice.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Duplicates {
    /// An error naming both lines (the default).
    #[default]
    Reject,
    /// Summed (an exporter that writes element contributions without assembling them).
    Sum,
}

fn err(file: &Path, at: impl Into<String>, reason: impl Into<String>) -> Error {
    Error::Case {
        file: file.display().to_string(),
        path: at.into(),
        reason: format!("MatrixMarket: {}", reason.into()),
        source: None,
    }
}

/// The `symmetric` or `general` flag of the header.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Symmetry {
    Symmetric,
    General,
}

fn header(file: &Path, line: &str) -> Result<Symmetry, Error> {
    let expected = "expected `%%MatrixMarket matrix coordinate real symmetric` (or `general`, or \
                    `integer` for `real`)";
    let t: Vec<String> = line.split_whitespace().map(str::to_lowercase).collect();
    if t.first().map(String::as_str) != Some("%%matrixmarket") || t.len() != 5 {
        return Err(err(
            file,
            "line 1",
            format!("not a MatrixMarket header: {expected}"),
        ));
    }
    if t[1] != "matrix" {
        return Err(err(
            file,
            "line 1",
            format!("object `{}` is not a matrix; {expected}", t[1]),
        ));
    }
    if t[2] != "coordinate" {
        return Err(err(
            file,
            "line 1",
            format!(
                "format `{}` is not supported (sparse `coordinate` only); {expected}",
                t[2]
            ),
        ));
    }
    if t[3] != "real" && t[3] != "integer" {
        return Err(err(
            file,
            "line 1",
            format!(
                "field `{}` is not supported (a structural matrix is real); {expected}",
                t[3]
            ),
        ));
    }
    match t[4].as_str() {
        "symmetric" => Ok(Symmetry::Symmetric),
        "general" => Ok(Symmetry::General),
        other => Err(err(
            file,
            "line 1",
            format!("symmetry `{other}` is not supported; {expected}"),
        )),
    }
}

/// The size line: (rows, declared entries).
fn size_line(file: &Path, no: usize, line: &str) -> Result<(usize, usize), Error> {
    let at = format!("line {no}");
    let t: Vec<&str> = line.split_whitespace().collect();
    let num = |s: &str, what: &str| {
        s.parse::<u64>().map_err(|_| {
            err(
                file,
                &at,
                format!("size line `{line}`: {what} `{s}` is not a non-negative integer"),
            )
        })
    };
    if t.len() != 3 {
        return Err(err(
            file,
            &at,
            format!("size line `{line}`: expected `rows cols entries`"),
        ));
    }
    let (rows, cols, nnz) = (
        num(t[0], "rows")?,
        num(t[1], "cols")?,
        num(t[2], "entries")?,
    );
    if rows != cols {
        return Err(err(
            file,
            &at,
            format!("the matrix is {rows} × {cols}; K and M must be square"),
        ));
    }
    if rows == 0 {
        return Err(err(file, &at, "the matrix has no rows"));
    }
    let budget = crate::files::dof_budget();
    if rows > budget as u64 {
        return Err(err(
            file,
            &at,
            format!(
                "{rows} rows exceed the model-size budget of {budget} DOF (set {} to allow \
                 more)",
                crate::files::DOF_BUDGET_VAR
            ),
        ));
    }
    if nnz < rows {
        return Err(err(
            file,
            &at,
            format!("{rows} rows but only {nnz} entries: every row needs at least its diagonal"),
        ));
    }
    let nnz = usize::try_from(nnz).map_err(|_| err(file, &at, "too many entries"))?;
    Ok((rows as usize, nnz))
}

/// One entry line: (row, col, value), 0-based.
fn entry(file: &Path, no: usize, line: &str, n: usize) -> Result<Triplet, Error> {
    let at = format!("line {no}");
    let t: Vec<&str> = line.split_whitespace().collect();
    if t.len() != 3 {
        return Err(err(
            file,
            &at,
            format!("`{line}`: expected `row col value`"),
        ));
    }
    let index = |s: &str| -> Result<usize, Error> {
        match s.parse::<u64>() {
            Ok(i) if i >= 1 && i <= n as u64 => Ok(i as usize - 1),
            _ => Err(err(
                file,
                &at,
                format!("`{line}`: index `{s}` is not in 1..={n} (indices are 1-based)"),
            )),
        }
    };
    let (i, j) = (index(t[0])?, index(t[1])?);
    let v: f64 = t[2]
        .parse()
        .map_err(|_| err(file, &at, format!("`{line}`: `{}` is not a number", t[2])))?;
    if !v.is_finite() {
        return Err(err(file, &at, format!("`{line}`: not a finite number")));
    }
    Ok((i, j, v))
}

/// Reads `path` under the rules of the module docs; returns the size and the full list of
/// entries (both triangles), sorted by column, then row.
pub fn read(path: &Path, duplicates: Duplicates) -> Result<(usize, Vec<Triplet>), Error> {
    let reader = std::io::BufReader::new(crate::files::BoundedReader::open(path)?);
    let mut lines = reader.lines().enumerate();
    let mut next = || -> Result<Option<(usize, String)>, Error> {
        match lines.next() {
            None => Ok(None),
            Some((k, Ok(l))) => Ok(Some((k + 1, l))),
            Some((k, Err(e))) => Err(err(path, format!("line {}", k + 1), format!("{e}"))),
        }
    };
    let Some((_, first)) = next()? else {
        return Err(err(path, "line 1", "empty file"));
    };
    let symmetry = header(path, &first)?;
    let data = |l: &str| !l.trim().is_empty() && !l.trim_start().starts_with('%');
    let (n, declared) = loop {
        match next()? {
            None => {
                return Err(err(
                    path,
                    "size line",
                    "missing (the file ends after its header)",
                ))
            }
            Some((no, l)) if data(&l) => break size_line(path, no, &l)?,
            Some(_) => {}
        }
    };
    // (row, col, value, line), stored triangle only; grows with what the file holds.
    let mut stored: Vec<(usize, usize, f64, usize)> = Vec::new();
    while let Some((no, l)) = next()? {
        if !data(&l) {
            continue;
        }
        if stored.len() == declared {
            return Err(err(
                path,
                format!("line {no}"),
                format!("more entries than the {declared} the size line declares"),
            ));
        }
        let (i, j, v) = entry(path, no, &l, n)?;
        stored.push((i, j, v, no));
    }
    if stored.len() < declared {
        return Err(err(
            path,
            "size line",
            format!(
                "declares {declared} entries but the file holds {}",
                stored.len()
            ),
        ));
    }
    let entries = merge_duplicates(path, stored, symmetry, duplicates)?;
    let mut out = Vec::with_capacity(2 * entries.len());
    for &(i, j, v) in &entries {
        out.push((i, j, v));
        if symmetry == Symmetry::Symmetric && i != j {
            out.push((j, i, v));
        }
    }
    out.sort_unstable_by_key(|&(i, j, _)| (j, i));
    if symmetry == Symmetry::General {
        check_symmetric(path, &out)?;
    }
    Ok((n, out))
}

/// Sorts the stored entries and rejects (or sums) entries given twice; in a `symmetric` file an
/// entry and its mirror image are the same entry (an error whatever `duplicates` says).
fn merge_duplicates(
    path: &Path,
    mut stored: Vec<(usize, usize, f64, usize)>,
    symmetry: Symmetry,
    duplicates: Duplicates,
) -> Result<Vec<Triplet>, Error> {
    let key = |i: usize, j: usize| match symmetry {
        Symmetry::Symmetric => (i.max(j), i.min(j)),
        Symmetry::General => (i, j),
    };
    stored.sort_unstable_by_key(|&(i, j, _, no)| (key(i, j).1, key(i, j).0, no));
    let mut out: Vec<Triplet> = Vec::with_capacity(stored.len());
    let mut last: Option<(usize, usize, usize)> = None;
    for (i, j, v, no) in stored {
        let (ki, kj) = key(i, j);
        match last {
            Some((li, lj, lno)) if key(li, lj) == (ki, kj) => {
                if (li, lj) != (i, j) {
                    return Err(err(
                        path,
                        format!("line {no}"),
                        format!(
                            "entry ({}, {}) is the mirror image of line {lno}: a `symmetric` \
                             file stores one triangle only (storing both counts every \
                             off-diagonal twice)",
                            i + 1,
                            j + 1
                        ),
                    ));
                }
                if duplicates == Duplicates::Reject {
                    return Err(err(
                        path,
                        format!("line {no}"),
                        format!(
                            "entry ({}, {}) is a duplicate of line {lno} (set the map's \
                             \"duplicates\": \"sum\" to add duplicates up)",
                            i + 1,
                            j + 1
                        ),
                    ));
                }
                out.last_mut().expect("an entry before").2 += v;
            }
            _ => {
                out.push((i, j, v));
                last = Some((i, j, no));
            }
        }
    }
    Ok(out)
}

/// Symmetry of a `general` file: |a_ij − a_ji| ≤ 1e-12 max|a| (`entries` sorted by column, then
/// row).
fn check_symmetric(path: &Path, entries: &[Triplet]) -> Result<(), Error> {
    let max = entries.iter().fold(0.0f64, |m, e| m.max(e.2.abs()));
    let tol = SYMMETRY_TOLERANCE * max;
    let find = |i: usize, j: usize| {
        entries
            .binary_search_by_key(&(j, i), |&(r, c, _)| (c, r))
            .map(|k| entries[k].2)
            .unwrap_or(0.0)
    };
    for &(i, j, v) in entries {
        if i != j {
            let t = find(j, i);
            if (v - t).abs() > tol {
                return Err(err(
                    path,
                    format!("entry ({}, {})", i + 1, j + 1),
                    format!(
                        "the matrix is not symmetric: a({0}, {1}) = {v:e} but a({1}, {0}) = {t:e}",
                        i + 1,
                        j + 1
                    ),
                ));
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read_text(text: &str, dup: Duplicates) -> Result<(usize, Vec<Triplet>), String> {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.mtx");
        std::fs::write(&p, text).unwrap();
        read(&p, dup).map_err(|e| e.to_string())
    }

    const H: &str = "%%MatrixMarket matrix coordinate real symmetric\n";

    #[test]
    fn reads_the_lower_triangle_and_mirrors_it() {
        let (n, e) = read_text(
            &format!("{H}% c\n2 2 3\n1 1 4\n2 1 -1\n2 2 4\n"),
            Duplicates::Reject,
        )
        .unwrap();
        assert_eq!(n, 2);
        assert_eq!(
            e,
            vec![(0, 0, 4.0), (1, 0, -1.0), (0, 1, -1.0), (1, 1, 4.0)]
        );
    }

    #[test]
    fn refuses_what_is_not_exactly_declared() {
        let r = |t: &str| read_text(&format!("{H}{t}"), Duplicates::Reject).unwrap_err();
        assert!(r("2 2 2\n1 1 4\n2 1 -1\n2 2 4\n").contains("more entries than the 2"));
        assert!(
            r("2 2 4\n1 1 4\n2 1 -1\n2 2 4\n").contains("declares 4 entries but the file holds 3")
        );
        assert!(r("2 2 4\n1 1 4\n2 1 -1\n1 2 -1\n2 2 4\n").contains("mirror image of line 4"));
        assert!(read_text(
            &format!("{H}2 2 3\n1 1 4\n1 2 -1\n2 2 4\n"),
            Duplicates::Reject
        )
        .is_ok());
        assert!(r("2 2 3\n1 1 4\n1 1 4\n2 2 4\n").contains("entry (1, 1) is a duplicate of line"));
        assert!(r("2 2 3\n1 1 4\n3 1 -1\n2 2 4\n").contains("not in 1..=2"));
        assert!(r("2 2 3\n1 1 4\n0 1 -1\n2 2 4\n").contains("1-based"));
        assert!(r("2 2 3\n1 1 nan\n2 1 -1\n2 2 4\n").contains("not a finite"));
        assert!(r("18446744073709551615 18446744073709551615 3\n").contains("budget"));
        assert!(r("1000000000000 1000000000000 3\n").contains("budget"));
        assert!(r("5 5 3\n1 1 4\n2 1 -1\n2 2 4\n").contains("every row needs"));
        assert!(r("2 3 3\n").contains("square"));
        let s = read_text(
            "%%MatrixMarket matrix array real general\n2 2\n",
            Duplicates::Reject,
        )
        .unwrap_err();
        assert!(s.contains("`array` is not supported"), "{s}");
    }

    #[test]
    fn sums_duplicates_only_on_request() {
        let t = format!("{H}2 2 4\n1 1 3\n1 1 1\n2 1 -1\n2 2 4\n");
        let (_, e) = read_text(&t, Duplicates::Sum).unwrap();
        assert_eq!(e[0], (0, 0, 4.0));
    }

    #[test]
    fn general_files_must_be_symmetric() {
        let g = "%%MatrixMarket matrix coordinate real general\n";
        assert!(read_text(
            &format!("{g}2 2 4\n1 1 4\n2 1 -1\n1 2 -1\n2 2 4\n"),
            Duplicates::Reject
        )
        .is_ok());
        let e = read_text(
            &format!("{g}2 2 4\n1 1 4\n2 1 -1\n1 2 -2\n2 2 4\n"),
            Duplicates::Reject,
        )
        .unwrap_err();
        assert!(e.contains("not symmetric"), "{e}");
    }
}
