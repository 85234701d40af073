//! Runs corpus entries through the binary, two at a time, each under a time limit.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

use crate::corpus::{Expect, Hostile};

/// Longest any one entry may take before it counts as a hang, s (the slowest honest entry runs
/// a few seconds).
const LIMIT: Duration = Duration::from_secs(60);

/// The base inputs every entry is derived from: the friction bar's case text, its exported
/// matrices and map, and an exported reduced model (g = 4).
pub struct Fixture {
    pub dir: PathBuf,
    pub case: String,
    pub map: String,
    pub k: String,
    pub m: String,
    pub rom: String,
    pub variants: String,
}

/// Made once per test process.
pub fn fixture() -> &'static Fixture {
    static F: OnceLock<Fixture> = OnceLock::new();
    F.get_or_init(|| {
        let dir = crate::common::tmp_path("hostile-fixture");
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let mats = dir.join("matrices");
        crate::common::jointrom_ok([
            "export-matrices",
            "friction_bar",
            "--out",
            mats.to_str().unwrap(),
        ]);
        let rom = dir.join("rom.json");
        crate::common::jointrom_ok([
            "export",
            "friction_bar",
            "--g",
            "4",
            "--out",
            rom.to_str().unwrap(),
        ]);
        let read = |p: &Path| std::fs::read_to_string(p).unwrap();
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        Fixture {
            case: read(&root.join("cases/friction_bar.json")),
            variants: read(&root.join("cases/sweeps/friction_bar_mu.json")),
            map: read(&mats.join("model.json")),
            k: read(&mats.join("K.mtx")),
            m: read(&mats.join("M.mtx")),
            rom: read(&rom),
            dir,
        }
    })
}

/// Runs every entry (two threads); the failures, one line each, and every entry's answer (in
/// corpus order; empty for a failure).
pub fn run_all(cases: &[Hostile]) -> (Vec<String>, Vec<String>) {
    let fx = fixture();
    let root = fx.dir.join("corpus");
    let _ = std::fs::remove_dir_all(&root);
    let next = std::sync::atomic::AtomicUsize::new(0);
    let failures = std::sync::Mutex::new(Vec::new());
    let answers = std::sync::Mutex::new(vec![String::new(); cases.len()]);
    std::thread::scope(|s| {
        for _ in 0..2 {
            s.spawn(|| loop {
                let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                let Some(c) = cases.get(i) else { break };
                match run_one(c, &root.join(c.id)) {
                    Ok(answer) => answers.lock().unwrap()[i] = answer,
                    Err(msg) => failures.lock().unwrap().push(format!("  {}: {msg}", c.id)),
                }
            });
        }
    });
    let mut f = failures.into_inner().unwrap();
    f.sort();
    (f, answers.into_inner().unwrap())
}

/// Runs one entry; its answer (the stderr line that carries the expected text, the folder
/// replaced by `…`) or what went wrong.
fn run_one(c: &Hostile, dir: &Path) -> Result<String, String> {
    std::fs::create_dir_all(dir).unwrap();
    for (name, bytes) in &c.files {
        let p = dir.join(name);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(&p, bytes).unwrap();
    }
    if let Some(setup) = &c.setup {
        setup(dir);
    }
    let args: Vec<String> = c
        .args
        .iter()
        .map(|a| a.replace("{d}", dir.to_str().unwrap()))
        .collect();
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_jointrom"));
    cmd.args(&args)
        .current_dir(dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    for (k, v) in &c.env {
        cmd.env(k, v);
    }
    let start = Instant::now();
    let mut child = cmd.spawn().map_err(|e| format!("spawn: {e}"))?;
    let (out, err) = drain(&mut child);
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        if start.elapsed() > LIMIT {
            let _ = child.kill();
            let _ = child.wait();
            return Err(format!("hang: killed after {} s", LIMIT.as_secs()));
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let stdout = String::from_utf8_lossy(&out.join().unwrap()).into_owned();
    let stderr = String::from_utf8_lossy(&err.join().unwrap()).into_owned();
    let Some(code) = status.code() else {
        return Err(format!("killed by a signal ({status}); stderr: {stderr}"));
    };
    if stderr.contains("panicked") || code == 101 {
        return Err(format!("panic: {stderr}"));
    }
    let line = stderr.lines().rev().find(|l| !l.is_empty()).unwrap_or("");
    match &c.expect {
        Expect::Fails(m) => {
            if code == 0 {
                return Err(format!("exit 0, expected an error containing `{m}`"));
            }
            if !stderr.contains(m) {
                return Err(format!("error does not contain `{m}`: {line}"));
            }
        }
        Expect::Warns(m) => {
            if code != 0 {
                return Err(format!("exit {code}, expected a warning `{m}`: {line}"));
            }
            if !stderr.contains(m) {
                return Err(format!("no warning containing `{m}` on stderr: {stderr}"));
            }
        }
        Expect::Contained(_) => {
            if code != 0 {
                return Err(format!("exit {code}: {line}"));
            }
        }
    }
    if let Some(check) = &c.check {
        check(dir, &stdout, &stderr)?;
    }
    let answer = match &c.expect {
        Expect::Fails(m) | Expect::Warns(m) => {
            // The error (or warning) line, and the line with the expected text if another.
            let first = stderr
                .lines()
                .find(|l| l.contains("error:") || l.contains("warning:"))
                .unwrap_or(line);
            match stderr.lines().find(|l| l.contains(m)) {
                Some(l) if l != first => {
                    let head: String = first.chars().take(120).collect();
                    format!(
                        "{head}… / {}",
                        l.trim().trim_start_matches("jointrom:").trim()
                    )
                }
                _ => first.to_string(),
            }
        }
        Expect::Contained(m) => format!("exit 0: {m}"),
    };
    Ok(answer.replace(dir.to_str().unwrap(), "…"))
}

type Drained = std::thread::JoinHandle<Vec<u8>>;

/// Reads the child's stdout and stderr on their own threads (a chatty child never blocks).
fn drain(child: &mut std::process::Child) -> (Drained, Drained) {
    use std::io::Read;
    let mut o = child.stdout.take().unwrap();
    let mut e = child.stderr.take().unwrap();
    let out = std::thread::spawn(move || {
        let mut v = Vec::new();
        let _ = o.read_to_end(&mut v);
        v
    });
    let err = std::thread::spawn(move || {
        let mut v = Vec::new();
        let _ = e.read_to_end(&mut v);
        v
    });
    (out, err)
}
