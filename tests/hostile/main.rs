//! Hostile and careless input: a corpus of bad case files, matrix maps and
//! MatrixMarket files, reduced-model files, sweep variants, flags and output paths, each run
//! through the `jointrom` binary. Every entry must end the way the corpus says — a clear error
//! (non-zero exit, a message naming the file, field, line or flag), a warning on a run that
//! finishes, or a contained success — and never in a panic, a signal, a hang or a silent exit 0.
//!
//! The table of bad-input classes (docs/validation/hostile-input.md) is printed from this corpus:
//! `cargo test --release --test hostile -- --ignored --nocapture print_table`.

#[path = "../common/mod.rs"]
mod common;

mod corpus;
mod runner;

use corpus::{corpus, Expect};

#[test]
fn every_hostile_input_gets_its_answer() {
    let cases = corpus();
    assert!(cases.len() >= 80, "the corpus has {} entries", cases.len());
    let (failures, _) = runner::run_all(&cases);
    assert!(
        failures.is_empty(),
        "{} of {} hostile inputs did not get their answer:\n{}",
        failures.len(),
        cases.len(),
        failures.join("\n")
    );
}

#[test]
fn corpus_ids_are_unique() {
    let cases = corpus();
    let mut ids: Vec<_> = cases.iter().map(|c| c.id).collect();
    ids.sort_unstable();
    let n = ids.len();
    ids.dedup();
    assert_eq!(ids.len(), n, "duplicate corpus ids");
}

/// Prints the bad-input table (docs/validation/hostile-input.md): input kind, bad input, and the answer jointrom gives (the line of
/// its message that the corpus checks).
#[test]
#[ignore = "prints the table of docs/validation/hostile-input.md"]
fn print_table() {
    let cases = corpus();
    let (failures, answers) = runner::run_all(&cases);
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    println!("| # | input kind | bad input | answer |");
    println!("|---|---|---|---|");
    for (i, (c, answer)) in cases.iter().zip(&answers).enumerate() {
        let mut answer = answer.trim_start_matches("jointrom: ").replace('|', "\\|");
        if answer.chars().count() > 240 {
            answer = answer.chars().take(237).collect::<String>() + "…";
        }
        let answer = match &c.expect {
            Expect::Warns(_) => format!("exit 0, {answer}"),
            _ => answer,
        };
        println!(
            "| {} | {} | {} | {} |",
            i + 1,
            c.kind,
            c.what.replace('|', "\\|"),
            answer.replace('`', "'")
        );
    }
}

/// Two runs writing into one folder at the same time (without the journal 14 of 30 rounds left files that
/// did not load): with atomic writes every round leaves whole files — the reduced model and the
/// exported matrices load, whichever run renamed last.
#[test]
fn concurrent_runs_into_one_folder_leave_whole_files() {
    use std::process::{Command, Stdio};
    let dir = common::tmp_dir("hostile_concurrent");
    let rom = dir.join("rom.json");
    let mats = dir.join("fb");
    let bin = env!("CARGO_BIN_EXE_jointrom");
    for round in 0..20 {
        let spawn = |args: &[&str]| {
            Command::new(bin)
                .args(args)
                .stdout(Stdio::null())
                .stderr(Stdio::piped())
                .spawn()
                .expect("spawn jointrom")
        };
        let g = if round % 2 == 0 { "4" } else { "6" };
        let children = [
            spawn(&[
                "export",
                "friction_bar",
                "--g",
                "4",
                "--out",
                rom.to_str().unwrap(),
            ]),
            spawn(&[
                "export",
                "friction_bar",
                "--g",
                g,
                "--out",
                rom.to_str().unwrap(),
            ]),
            spawn(&[
                "export-matrices",
                "friction_bar",
                "--out",
                mats.to_str().unwrap(),
            ]),
            spawn(&[
                "export-matrices",
                "friction_bar",
                "--out",
                mats.to_str().unwrap(),
            ]),
        ];
        for c in children {
            let out = c.wait_with_output().unwrap();
            assert!(
                out.status.success(),
                "round {round}: {}",
                String::from_utf8_lossy(&out.stderr)
            );
        }
        // Both files load: the ROM through a short run, the matrices through `info`.
        common::jointrom_ok([
            "transient",
            "friction_bar",
            "--model",
            &format!("file:{}", rom.display()),
            "--end-time",
            "0.001",
        ]);
        common::jointrom_ok(["info", mats.join("model.json").to_str().unwrap()]);
        let leftovers: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .chain(std::fs::read_dir(&mats).unwrap())
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.starts_with('.'))
            .collect();
        assert!(
            leftovers.is_empty(),
            "round {round}: temporary files left: {leftovers:?}"
        );
    }
}

/// A reader that closes the pipe early (`jointrom info X | head -0`) ends jointrom quietly with
/// SIGPIPE's status 141, not with a panic.
#[test]
fn a_closed_stdout_is_not_a_panic() {
    use std::process::{Command, Stdio};
    let case = common::repo_path("cases/scale/friction_bar_x4.json");
    let mut child = Command::new(env!("CARGO_BIN_EXE_jointrom"))
        .args(["info", case.to_str().unwrap()])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_eq!(out.status.code(), Some(141), "{stderr}");
}
