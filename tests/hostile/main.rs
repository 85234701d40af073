//! Hostile and careless input (issue 16): a corpus of bad case files, matrix maps and
//! MatrixMarket files, reduced-model files, sweep variants, flags and output paths, each run
//! through the `jointrom` binary. Every entry must end the way the corpus says — a clear error
//! (non-zero exit, a message naming the file, field, line or flag), a warning on a run that
//! finishes, or a contained success — and never in a panic, a signal, a hang or a silent exit 0.
//!
//! The README's table of bad-input classes is printed from this corpus:
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
    let failures = runner::run_all(&cases);
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

/// Prints the README's table: class, input, what jointrom answers (a substring of its message).
#[test]
#[ignore = "prints the README table"]
fn print_table() {
    println!("| # | input kind | bad input | answer (exit, message contains) |");
    println!("|---|---|---|---|");
    for (i, c) in corpus().iter().enumerate() {
        let answer = match &c.expect {
            Expect::Fails(m) => format!("error: `{}`", m.replace('|', "\\|")),
            Expect::Warns(m) => format!("exit 0, warning: `{}`", m.replace('|', "\\|")),
            Expect::Contained(m) => format!("exit 0, contained: {m}"),
        };
        println!(
            "| {} | {} | {} | {} |",
            i + 1,
            c.kind,
            c.what.replace('|', "\\|"),
            answer
        );
    }
}
