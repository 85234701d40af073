//! The card reader: NASTRAN bulk data text → [`Card`]s, one per card with its fields, the file
//! and the line it starts on.
//!
//! # Formats
//!
//! - **Small field** (fixed): columns 1–8 hold the card name (or a continuation marker), then
//!   eight data fields of 8 columns (9–72); columns 73–80 (the continuation marker) and beyond
//!   are ignored.
//! - **Large field** (fixed): the name ends with `*` (`GRID*`); four data fields of 16 columns
//!   (9–72) per line; a continuation line starts with `*`.
//! - **Free field**: a line with a comma; fields separated by commas, the first is the name (or
//!   a continuation marker); eight data fields per line (four when the name ends with `*`);
//!   more than nine fields after the name on one line is an error.
//! - Tabs are expanded to the next multiple of 8 columns; `$` starts a comment to the end of the
//!   line; card names are case-insensitive.
//!
//! A line continues the card above when it starts with `+`, `*` or `,`, or when its first eight
//! columns are blank. Continuation markers are not matched against the line before (NASTRAN's
//! old explicit form); every continuation belongs to the card above it. Each physical line
//! contributes eight fields (four for a large-field line) to the card's flat field list, blank
//! fields padded, so field `k` of a card is the same field whatever the format.
//!
//! # Sections and INCLUDE
//!
//! A deck with a `BEGIN BULK` line has executive and case control above it: the case control's
//! `SPC`, `DLOAD` and `TSTEP` set selections are kept (as [`CaseControl`]), the rest of the
//! control lines are ignored. Without `BEGIN BULK` the whole file is bulk data. `ENDDATA` ends
//! the deck. `INCLUDE 'file'` (quoted or not, on one line) reads another file in place, its path
//! relative to the including file's folder; includes nest at most [`MAX_INCLUDE_DEPTH`] deep and
//! a file including itself (directly or not) is an error.
//!
//! # Bounds
//!
//! Every file is read through [`crate::files::read_bytes`] (regular files only, under the input
//! budget), and the bytes of all included files together count against the same budget, so
//! memory stays proportional to the input. Text that is not UTF-8 is read with replacement
//! characters (decks are ASCII; comments are not always).

use std::path::{Path, PathBuf};

use crate::error::Error;

/// How deep `INCLUDE` statements nest at most.
pub const MAX_INCLUDE_DEPTH: usize = 16;

/// Where a card starts: the file (index into [`Cards::files`]) and 1-based line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Position {
    /// Index into [`Cards::files`].
    pub file: usize,
    /// Line number, from 1.
    pub line: usize,
}

/// One bulk data card.
#[derive(Clone, Debug, PartialEq)]
pub struct Card {
    /// The card name in upper case, without the large-field `*`.
    pub name: String,
    /// Data fields 1, 2, ... (field 1 is the first after the name), trimmed; blank fields are
    /// empty strings.
    pub fields: Vec<String>,
    /// Where the card starts.
    pub at: Position,
}

/// Set selections of the case control section (`None`: not given).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CaseControl {
    /// `SPC = n`.
    pub spc: Option<i64>,
    /// `DLOAD = n`.
    pub dload: Option<i64>,
    /// `TSTEP = n` (selects a `TSTEP` or `TSTEPNL` card).
    pub tstep: Option<i64>,
    /// The line of the first `SUBCASE` after the first, if the deck has several.
    pub extra_subcase: Option<Position>,
}

/// A read deck: its files, cards and case control.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Cards {
    /// The files read, the main deck first.
    pub files: Vec<PathBuf>,
    /// The bulk data cards in reading order (includes in place).
    pub cards: Vec<Card>,
    /// The case control's set selections.
    pub control: CaseControl,
}

impl Cards {
    /// `file:line` of a position.
    pub fn locate(&self, at: Position) -> String {
        format!("{}:{}", self.files[at.file].display(), at.line)
    }

    /// The error for a card: `file:line: NAME: reason`.
    pub fn error(&self, card: &Card, reason: impl Into<String>) -> Error {
        self.error_at(at_name(card), card.at, reason)
    }

    /// The error at a position: `file:line: what: reason`.
    pub(crate) fn error_at(&self, what: String, at: Position, reason: impl Into<String>) -> Error {
        Error::Deck {
            file: self.files[at.file].clone(),
            line: at.line,
            card: what,
            reason: reason.into(),
        }
    }
}

fn at_name(card: &Card) -> String {
    match card.fields.first() {
        Some(id) if !id.is_empty() => format!("{} {}", card.name, id),
        _ => card.name.clone(),
    }
}

/// Which section a line is in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Section {
    Executive,
    CaseControl,
    Bulk,
    Done,
}

/// Reads a deck and every file it includes (see the module docs).
pub fn read(path: &Path) -> Result<Cards, Error> {
    let text = read_file(path, 0)?;
    let mut reader = Reader {
        out: Cards {
            files: vec![path.to_path_buf()],
            ..Cards::default()
        },
        bytes: text.len() as u64,
        stack: vec![canonical(path)],
        section: if has_begin_bulk(&text) {
            Section::Executive
        } else {
            Section::Bulk
        },
        subcases: 0,
    };
    reader.text(&text, 0)?;
    Ok(reader.out)
}

/// Reads the text of a deck (or an included file) under the input budget.
fn read_file(path: &Path, used: u64) -> Result<String, Error> {
    let bytes = crate::files::read_bytes(path)?;
    let budget = crate::files::input_budget();
    if used + bytes.len() as u64 > budget {
        return Err(Error::Io {
            file: path.to_path_buf(),
            source: std::io::Error::new(
                std::io::ErrorKind::FileTooLarge,
                format!(
                    "the deck and its includes exceed the input budget of {budget} bytes ({})",
                    crate::files::INPUT_BUDGET_VAR
                ),
            ),
        });
    }
    Ok(String::from_utf8_lossy(&bytes).into_owned())
}

fn canonical(path: &Path) -> PathBuf {
    std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf())
}

fn has_begin_bulk(text: &str) -> bool {
    text.lines().any(|l| is_begin_bulk(strip_comment(l)))
}

fn is_begin_bulk(line: &str) -> bool {
    let upper = line.trim().to_ascii_uppercase();
    let mut words = upper.split_whitespace();
    words.next() == Some("BEGIN") && words.next().is_some_and(|w| w.starts_with("BULK"))
}

fn strip_comment(line: &str) -> &str {
    match line.find('$') {
        Some(i) => &line[..i],
        None => line,
    }
}

struct Reader {
    out: Cards,
    /// Bytes read so far (all files).
    bytes: u64,
    /// Canonical paths of the files being read (for cycles).
    stack: Vec<PathBuf>,
    section: Section,
    /// `SUBCASE` lines seen.
    subcases: usize,
}

impl Reader {
    fn text(&mut self, text: &str, file: usize) -> Result<(), Error> {
        for (i, raw) in text.split('\n').enumerate() {
            let at = Position { file, line: i + 1 };
            let line = strip_comment(raw.strip_suffix('\r').unwrap_or(raw));
            if line.trim().is_empty() {
                continue;
            }
            if let Some(target) = include_target(line) {
                self.include(target, at)?;
                continue;
            }
            match self.section {
                Section::Done => break,
                Section::Executive => {
                    if line.trim().to_ascii_uppercase().starts_with("CEND") {
                        self.section = Section::CaseControl;
                    } else if is_begin_bulk(line) {
                        self.section = Section::Bulk;
                    }
                }
                Section::CaseControl => {
                    if is_begin_bulk(line) {
                        self.section = Section::Bulk;
                    } else {
                        self.case_control(line, at)?;
                    }
                }
                Section::Bulk => self.bulk_line(line, at)?,
            }
        }
        Ok(())
    }

    fn include(&mut self, target: String, at: Position) -> Result<(), Error> {
        let here = &self.out.files[at.file];
        let path = match here.parent() {
            Some(dir) if Path::new(&target).is_relative() => dir.join(&target),
            _ => PathBuf::from(&target),
        };
        let what = "INCLUDE".to_string();
        if self.stack.len() > MAX_INCLUDE_DEPTH {
            return Err(self.out.error_at(
                what,
                at,
                format!("includes nest deeper than {MAX_INCLUDE_DEPTH} files"),
            ));
        }
        let canon = canonical(&path);
        if self.stack.contains(&canon) {
            return Err(self.out.error_at(
                what,
                at,
                format!("`{}` includes itself (directly or through others)", target),
            ));
        }
        let text = read_file(&path, self.bytes)?;
        self.bytes += text.len() as u64;
        self.out.files.push(path);
        let file = self.out.files.len() - 1;
        self.stack.push(canon);
        let result = self.text(&text, file);
        self.stack.pop();
        result
    }

    /// One line of case control: `KEY = n` for SPC, DLOAD, TSTEP; SUBCASE counted.
    fn case_control(&mut self, line: &str, at: Position) -> Result<(), Error> {
        let upper = line.trim().to_ascii_uppercase();
        if upper.starts_with("SUBCASE") {
            self.subcases += 1;
            if self.subcases == 2 {
                self.out.control.extra_subcase = Some(at);
            }
            return Ok(());
        }
        let Some((key, value)) = upper.split_once('=') else {
            return Ok(());
        };
        let slot = match key.trim() {
            "SPC" => &mut self.out.control.spc,
            "DLOAD" => &mut self.out.control.dload,
            "TSTEP" | "TSTEPNL" => &mut self.out.control.tstep,
            _ => return Ok(()),
        };
        let value = value.trim();
        let id = value.parse::<i64>().map_err(|_| Error::Deck {
            file: self.out.files[at.file].clone(),
            line: at.line,
            card: key.trim().to_string(),
            reason: format!("case control: expected a set number, found `{value}`"),
        })?;
        *slot = Some(id);
        Ok(())
    }

    fn bulk_line(&mut self, line: &str, at: Position) -> Result<(), Error> {
        let trimmed = line.trim();
        if trimmed.to_ascii_uppercase().starts_with("ENDDATA") {
            self.section = Section::Done;
            return Ok(());
        }
        let expanded = expand_tabs(line);
        let first = expanded.chars().next().unwrap_or(' ');
        let continuation = matches!(first, '+' | '*' | ',')
            || (first == ' ' && expanded.chars().take(8).all(|c| c == ' '));
        let (head, data) = split_line(&expanded).map_err(|reason| Error::Deck {
            file: self.out.files[at.file].clone(),
            line: at.line,
            card: "line".into(),
            reason,
        })?;
        if continuation {
            let Some(card) = self.out.cards.last_mut() else {
                return Err(Error::Deck {
                    file: self.out.files[at.file].clone(),
                    line: at.line,
                    card: "continuation".into(),
                    reason: "a continuation line with no card above it".into(),
                });
            };
            card.fields.extend(data);
            return Ok(());
        }
        let name = head.trim_end_matches('*').trim().to_ascii_uppercase();
        if name.is_empty() || !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
            return Err(Error::Deck {
                file: self.out.files[at.file].clone(),
                line: at.line,
                card: crate::files::printable(&name),
                reason: "not a card name (letters and digits in columns 1–8)".into(),
            });
        }
        self.out.cards.push(Card {
            name,
            fields: data,
            at,
        });
        Ok(())
    }
}

/// The file named by an `INCLUDE` line, if it is one.
fn include_target(line: &str) -> Option<String> {
    let trimmed = line.trim_start();
    if !trimmed.get(..7)?.eq_ignore_ascii_case("INCLUDE") {
        return None;
    }
    let rest = &trimmed[7..];
    if !(rest.is_empty() || rest.starts_with(|c: char| c.is_ascii_whitespace() || c == '\'')) {
        return None;
    }
    let rest = rest.trim();
    let unquoted = rest.trim_matches(|c| c == '\'' || c == '"').trim();
    Some(unquoted.to_string())
}

/// Tabs expanded to the next multiple of 8 columns.
fn expand_tabs(line: &str) -> String {
    if !line.contains('\t') {
        return line.to_string();
    }
    let mut out = String::with_capacity(line.len() + 8);
    for c in line.chars() {
        if c == '\t' {
            let pad = 8 - out.chars().count() % 8;
            out.extend(std::iter::repeat_n(' ', pad));
        } else {
            out.push(c);
        }
    }
    out
}

/// Splits a line into its first field (name or continuation marker) and its data fields,
/// padded to 8 (small field, free field) or 4 (large field).
fn split_line(line: &str) -> Result<(String, Vec<String>), String> {
    if line.contains(',') {
        let mut parts = line.split(',');
        let head = parts.next().unwrap_or("").trim().to_string();
        let width = if head.starts_with('*') || head.ends_with('*') {
            4
        } else {
            8
        };
        let mut data: Vec<String> = parts.map(|f| f.trim().to_string()).collect();
        // A tenth field is the continuation marker.
        if data.len() == width + 1 {
            data.pop();
        }
        if data.len() > width {
            return Err(format!(
                "a free-field line holds at most {width} data fields after the name, found {}",
                data.len()
            ));
        }
        data.resize(width, String::new());
        return Ok((head, data));
    }
    let chars: Vec<char> = line.chars().collect();
    let column = |from: usize, to: usize| -> String {
        chars
            .get(from.min(chars.len())..to.min(chars.len()))
            .map(|s| s.iter().collect::<String>().trim().to_string())
            .unwrap_or_default()
    };
    let head = column(0, 8);
    let large = head.starts_with('*') || head.ends_with('*');
    let (width, size) = if large { (4, 16) } else { (8, 8) };
    let data = (0..width)
        .map(|k| column(8 + k * size, 8 + (k + 1) * size))
        .collect();
    Ok((head, data))
}
