//! Files in and out, under one set of rules:
//!
//! - **reads are bounded by what is there**: only regular files are read (a folder, a device such
//!   as `/dev/zero` or a pipe is refused by name), and never more than [`input_budget`] bytes
//!   (1 GiB unless `JOINTROM_MAX_INPUT_BYTES` says otherwise), so a hostile input cannot make
//!   jointrom read until memory runs out;
//! - **writes are atomic**: every output file is written to a temporary file in the same folder
//!   and renamed over its name when complete ([`write_atomic`], [`write_atomic_with`]), so a
//!   reader never sees a half-written file, two runs into one folder leave whole files, and a
//!   failed write leaves nothing; a symbolic link is followed (the file it points to is
//!   replaced, the link kept), a device or pipe (`--out /dev/null`) is written in place, never
//!   replaced, and new files get the usual permissions (0666 less the umask);
//! - **names are contained**: a model or variant name becomes a file or folder name only through
//!   [`safe_name`] (no `/`, no `..`, no absolute path, no control characters) and is printed only
//!   through [`printable`] (control characters escaped);
//! - **a failed command leaves nothing half-done**: a program that calls [`journal_start`]
//!   has every file and folder this module creates recorded, and [`journal_rollback`] removes
//!   them again (files it replaced keep their new, complete content); the `jointrom` binary
//!   rolls back whenever a command fails;
//! - **messages say what happened**: [`Error::Io`] (reading) and [`Error::Write`] (creating,
//!   writing, renaming) carry the file and the OS error, and their text names the kind — no such
//!   file, a folder where a file was expected, a parent that is not a folder, a symbolic-link
//!   loop, a name too long, permission denied.

use std::io::{Read, Write};
use std::path::{Path, PathBuf};

use crate::Error;

/// Default bound on any one input file, bytes (1 GiB): the largest matrix file a 10⁶-DOF shell
/// model writes is a few hundred MB.
pub const DEFAULT_INPUT_BUDGET: u64 = 1 << 30;

/// The environment variable that overrides [`DEFAULT_INPUT_BUDGET`] (bytes, a positive integer).
pub const INPUT_BUDGET_VAR: &str = "JOINTROM_MAX_INPUT_BYTES";

/// The largest input file jointrom reads, bytes: `JOINTROM_MAX_INPUT_BYTES` if set to a positive
/// integer, else [`DEFAULT_INPUT_BUDGET`].
pub fn input_budget() -> u64 {
    env_budget(INPUT_BUDGET_VAR, DEFAULT_INPUT_BUDGET)
}

/// The positive integer in the environment variable `var`, else `default`.
fn env_budget<T: std::str::FromStr + PartialOrd + Default>(var: &str, default: T) -> T {
    std::env::var(var)
        .ok()
        .and_then(|v| v.trim().parse::<T>().ok())
        .filter(|v| *v > T::default())
        .unwrap_or(default)
}

/// Default bound on the size of a model, DOF (6 per node of a case's mesh, or rows of a
/// user's matrices): 2·10⁶. Building a case's model takes about 4 GB per 10⁶ DOF today (181 000
/// nodes: 4.1 GB for `info`), so this keeps a model inside a 24 GB machine; the check comes
/// before anything is allocated, and `JOINTROM_MAX_DOF` raises it.
pub const DEFAULT_DOF_BUDGET: usize = 2_000_000;

/// The environment variable that overrides [`DEFAULT_DOF_BUDGET`] (a positive integer).
pub const DOF_BUDGET_VAR: &str = "JOINTROM_MAX_DOF";

/// The largest model jointrom builds, DOF: `JOINTROM_MAX_DOF` if set to a positive integer,
/// else [`DEFAULT_DOF_BUDGET`].
pub fn dof_budget() -> usize {
    env_budget(DOF_BUDGET_VAR, DEFAULT_DOF_BUDGET)
}

/// What a file-system error means, in words (used by [`Error::Io`] and [`Error::Write`]).
pub fn describe(e: &std::io::Error) -> String {
    use std::io::ErrorKind as K;
    if e.get_ref().is_some() {
        // A message jointrom wrote itself.
        return e.to_string();
    }
    // Linux's errno values for a link loop and an over-long name (their ErrorKinds are not
    // stable yet).
    match e.raw_os_error() {
        Some(40) if cfg!(target_os = "linux") => {
            return "too many levels of symbolic links (a link loop)".into()
        }
        Some(36) if cfg!(target_os = "linux") => return "name too long".into(),
        _ => {}
    }
    let kind = match e.kind() {
        K::NotFound => "no such file or folder",
        K::PermissionDenied => "permission denied",
        K::IsADirectory => "is a folder, not a file",
        K::NotADirectory => "a part of the path is not a folder",
        K::AlreadyExists => "already exists",
        K::InvalidFilename => "name too long or invalid",
        K::StorageFull => "no space left on the device",
        K::ReadOnlyFilesystem => "read-only file system",
        K::FileTooLarge => "file too large",
        K::InvalidData => "not valid UTF-8 text",
        K::UnexpectedEof => "ended early",
        _ => "",
    };
    if kind.is_empty() {
        e.to_string()
    } else {
        kind.to_string()
    }
}

fn read_err(path: &Path, source: std::io::Error) -> Error {
    Error::Io {
        file: path.to_path_buf(),
        source,
    }
}

/// An [`Error::Write`] for `path`: `action` is what failed (`write`, `create folder`, ...).
pub fn write_err(path: &Path, action: &'static str, source: std::io::Error) -> Error {
    Error::Write {
        file: path.to_path_buf(),
        action,
        source,
    }
}

/// Reads a whole input file as UTF-8 text, refusing what is not a regular file and anything
/// over [`input_budget`] bytes (checked while reading, not from the declared size alone).
pub fn read_text(path: &Path) -> Result<String, Error> {
    let bytes = read_bytes(path)?;
    String::from_utf8(bytes).map_err(|_| {
        read_err(
            path,
            std::io::Error::new(std::io::ErrorKind::InvalidData, "not UTF-8"),
        )
    })
}

/// Reads a whole input file as bytes under the rules of [`read_text`].
pub fn read_bytes(path: &Path) -> Result<Vec<u8>, Error> {
    let file = open_input(path)?;
    let budget = input_budget();
    let mut out = Vec::new();
    file.take(budget + 1)
        .read_to_end(&mut out)
        .map_err(|e| read_err(path, e))?;
    if out.len() as u64 > budget {
        return Err(too_large(path, budget));
    }
    Ok(out)
}

fn too_large(path: &Path, budget: u64) -> Error {
    read_err(
        path,
        std::io::Error::new(
            std::io::ErrorKind::FileTooLarge,
            format!(
                "larger than the input budget of {budget} bytes (set {INPUT_BUDGET_VAR} to \
                 read larger files)"
            ),
        ),
    )
}

/// Opens an input file for streaming: only a regular file (after following links) is opened;
/// the caller bounds what it reads by [`input_budget`] (see [`BoundedReader`]).
pub fn open_input(path: &Path) -> Result<std::fs::File, Error> {
    let meta = std::fs::metadata(path).map_err(|e| read_err(path, e))?;
    if meta.is_dir() {
        return Err(read_err(
            path,
            std::io::Error::new(std::io::ErrorKind::IsADirectory, "is a folder, not a file"),
        ));
    }
    if !meta.is_file() {
        return Err(read_err(
            path,
            std::io::Error::other(
                "not a regular file (a device, pipe or socket is not read as an input)",
            ),
        ));
    }
    let budget = input_budget();
    if meta.len() > budget {
        return Err(too_large(path, budget));
    }
    std::fs::File::open(path).map_err(|e| read_err(path, e))
}

/// A reader that fails with a clear error once more than [`input_budget`] bytes were read
/// (a file that grows while it is read cannot exceed the budget either).
pub struct BoundedReader {
    inner: std::io::Take<std::fs::File>,
    budget: u64,
    read: u64,
}

impl BoundedReader {
    /// Opens `path` as with [`open_input`].
    pub fn open(path: &Path) -> Result<Self, Error> {
        let budget = input_budget();
        Ok(BoundedReader {
            inner: open_input(path)?.take(budget + 1),
            budget,
            read: 0,
        })
    }
}

impl Read for BoundedReader {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.read += n as u64;
        if self.read > self.budget {
            return Err(std::io::Error::new(
                std::io::ErrorKind::FileTooLarge,
                format!("larger than the input budget of {} bytes", self.budget),
            ));
        }
        Ok(n)
    }
}

/// What this process created since [`journal_start`] (`None`: not recording).
static JOURNAL: std::sync::Mutex<Option<Vec<Created>>> = std::sync::Mutex::new(None);

enum Created {
    File(PathBuf),
    Dir(PathBuf),
}

fn record(c: Created) {
    if let Ok(mut j) = JOURNAL.lock() {
        if let Some(list) = j.as_mut() {
            list.push(c);
        }
    }
}

/// Starts recording every file and folder this module creates (and forgets an earlier record).
pub fn journal_start() {
    if let Ok(mut j) = JOURNAL.lock() {
        *j = Some(Vec::new());
    }
}

/// Stops recording and keeps what was created.
pub fn journal_commit() {
    if let Ok(mut j) = JOURNAL.lock() {
        *j = None;
    }
}

/// Stops recording and removes what was created since [`journal_start`], newest first (folders
/// only if empty then); returns how many files and folders were removed.
pub fn journal_rollback() -> usize {
    let list = match JOURNAL.lock() {
        Ok(mut j) => j.take().unwrap_or_default(),
        Err(_) => return 0,
    };
    let mut removed = 0;
    for c in list.iter().rev() {
        let ok = match c {
            Created::File(p) => std::fs::remove_file(p).is_ok(),
            Created::Dir(p) => std::fs::remove_dir(p).is_ok(),
        };
        removed += usize::from(ok);
    }
    removed
}

/// Creates `dir` and its parents ([`Error::Write`] with action `create folder` on failure, e.g.
/// when a part of the path is a file).
pub fn create_dir(dir: &Path) -> Result<(), Error> {
    if dir.exists() && !dir.is_dir() {
        return Err(write_err(
            dir,
            "create folder",
            std::io::Error::new(
                std::io::ErrorKind::AlreadyExists,
                "exists and is not a folder",
            ),
        ));
    }
    let missing: Vec<PathBuf> = dir
        .ancestors()
        .take_while(|a| !a.as_os_str().is_empty() && !a.exists())
        .map(Path::to_path_buf)
        .collect();
    std::fs::create_dir_all(dir).map_err(|e| write_err(dir, "create folder", e))?;
    for d in missing.into_iter().rev() {
        record(Created::Dir(d));
    }
    Ok(())
}

/// Writes `bytes` to `path` atomically: a temporary file in the same folder, flushed, then
/// renamed over `path`. On any failure nothing is left behind and `path` is unchanged.
pub fn write_atomic(path: &Path, bytes: impl AsRef<[u8]>) -> Result<(), Error> {
    write_atomic_with(path, |tmp| {
        let mut f = std::fs::File::create(tmp)?;
        f.write_all(bytes.as_ref())?;
        // Flushed to disk before the rename; a device or pipe written in place has nothing to
        // flush (and refuses the call).
        if f.metadata()?.is_file() {
            f.sync_data()?;
        }
        Ok::<(), std::io::Error>(())
    })
}

/// Writes `path` atomically through `fill`, which gets a temporary path in the same folder with
/// the same extension (so that writers that choose a format by extension, such as the chart
/// back-ends, work) and writes the whole file there; the file is renamed over `path` only if
/// `fill` succeeds, and removed otherwise.
pub fn write_atomic_with<E: Into<WriteFailure>>(
    path: &Path,
    fill: impl FnOnce(&Path) -> Result<(), E>,
) -> Result<(), Error> {
    let path = match output_target(path)? {
        Target::Replace(p) => p,
        Target::Stream => {
            // A device or a pipe (`--out /dev/null`, a FIFO) is written in place: there is
            // nothing to replace, and renaming over it would put a file where the device was.
            return fill(path).map_err(|e| match e.into() {
                WriteFailure::Io(source) => write_err(path, "write", source),
                WriteFailure::Error(err) => err,
            });
        }
    };
    let path = path.as_path();
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let suffix = path
        .extension()
        .map(|e| format!(".{}", e.to_string_lossy()))
        .unwrap_or_default();
    let mut builder = tempfile::Builder::new();
    // A normal new file's permissions (0666 less the umask), not the temporary file's 0600.
    #[cfg(unix)]
    builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666));
    let tmp = builder
        .prefix(&format!(".{name}."))
        .suffix(&suffix)
        .tempfile_in(&dir)
        .map_err(|e| write_err(path, "write", e))?
        .into_temp_path();
    if let Err(e) = fill(&tmp) {
        // `tmp` is removed when dropped.
        return Err(match e.into() {
            WriteFailure::Io(source) => write_err(path, "write", source),
            WriteFailure::Error(err) => err,
        });
    }
    let existed = path.exists();
    tmp.persist(path)
        .map_err(|e| write_err(path, "rename into place", e.error))?;
    if !existed {
        record(Created::File(path.to_path_buf()));
    }
    Ok(())
}

/// Where an output goes.
enum Target {
    /// A regular file, new or replaced by rename (a symbolic link's target, not the link).
    Replace(PathBuf),
    /// A device, pipe or socket, written in place.
    Stream,
}

/// Resolves what writing `path` means: a new or regular file is replaced atomically, a symbolic
/// link is followed (the file it points to is replaced and the link kept), a device or pipe is
/// written in place, and a folder is an error.
fn output_target(path: &Path) -> Result<Target, Error> {
    let meta = match std::fs::symlink_metadata(path) {
        Ok(m) => m,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Ok(Target::Replace(path.to_path_buf()))
        }
        Err(e) => return Err(write_err(path, "write", e)),
    };
    let kind = meta.file_type();
    if kind.is_symlink() {
        let real = std::fs::canonicalize(path)
            .map_err(|e| write_err(path, "write through the symbolic link", e))?;
        return output_target(&real);
    }
    if kind.is_dir() {
        return Err(write_err(
            path,
            "write",
            std::io::Error::from(std::io::ErrorKind::IsADirectory),
        ));
    }
    if kind.is_file() {
        Ok(Target::Replace(path.to_path_buf()))
    } else {
        Ok(Target::Stream)
    }
}

/// How a writer given to [`write_atomic_with`] failed: an OS error, or a jointrom error that
/// already names the file (e.g. a chart back-end's).
pub enum WriteFailure {
    /// An OS error while writing the temporary file.
    Io(std::io::Error),
    /// An error that already says what went wrong.
    Error(Error),
}

impl From<std::io::Error> for WriteFailure {
    fn from(e: std::io::Error) -> Self {
        WriteFailure::Io(e)
    }
}

impl From<Error> for WriteFailure {
    fn from(e: Error) -> Self {
        WriteFailure::Error(e)
    }
}

/// The longest file or folder name [`safe_name`] produces, bytes.
pub const MAX_NAME_LEN: usize = 96;

/// `name` as one safe path component: letters, digits, `-`, `_`, `.` and `+` are kept, every
/// other character (path separators, spaces, control characters, non-ASCII) becomes `_`, leading
/// dots are dropped (no `..`, no hidden files), the result is cut to [`MAX_NAME_LEN`] bytes, and
/// an empty result becomes `unnamed`. The same name always gives the same component.
pub fn safe_name(name: &str) -> String {
    let mut s: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.' | '+') {
                c
            } else {
                '_'
            }
        })
        .collect();
    let trimmed = s.trim_start_matches('.').len();
    s = s.split_off(s.len() - trimmed);
    s.truncate(MAX_NAME_LEN);
    if s.is_empty() {
        "unnamed".to_string()
    } else {
        s
    }
}

/// `text` fit for a terminal: control characters (escape sequences, carriage returns, bells)
/// are shown escaped (`\u{1b}`), everything else as is.
pub fn printable(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        if c.is_control() {
            out.extend(c.escape_default());
        } else {
            out.push(c);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_stay_one_component() {
        assert_eq!(safe_name("../../etc/passwd"), "_.._etc_passwd");
        assert_eq!(safe_name("/abs/path"), "_abs_path");
        assert_eq!(safe_name(".."), "unnamed");
        assert_eq!(safe_name("a\u{1b}[31mb"), "a__31mb");
        assert_eq!(safe_name("friction_bar"), "friction_bar");
        assert!(safe_name(&"x".repeat(1000)).len() <= MAX_NAME_LEN);
        assert_eq!(printable("a\u{1b}[2Jb\r"), "a\\u{1b}[2Jb\\r");
    }

    #[test]
    fn atomic_write_leaves_whole_files_only() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.json");
        write_atomic(&p, "{}").unwrap();
        assert_eq!(std::fs::read_to_string(&p).unwrap(), "{}");
        let r = write_atomic_with(&p, |_| Err(std::io::Error::other("disk on fire")));
        assert!(matches!(r, Err(Error::Write { .. })));
        assert_eq!(std::fs::read_to_string(&p).unwrap(), "{}");
        let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
        assert_eq!(left.len(), 1, "no temporary file left behind");
    }

    #[test]
    fn reads_refuse_folders_and_devices() {
        let dir = tempfile::tempdir().unwrap();
        let e = read_text(dir.path()).unwrap_err().to_string();
        assert!(e.contains("is a folder"), "{e}");
        let e = read_text(Path::new("/dev/zero")).unwrap_err().to_string();
        assert!(e.contains("not a regular file"), "{e}");
        let e = read_text(&dir.path().join("missing"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("no such file"), "{e}");
    }
}
