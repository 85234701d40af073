//! Bit-identical results for any number of threads: the exported reduced models,
//! the tolerance-chosen model and the transient curves of both built-in scenes, run with
//! `RAYON_NUM_THREADS=1` and `=2`.

use std::path::Path;
use std::process::Command;

use serde_json::Value;

use crate::common::tmp_dir;

/// Runs the binary with `threads` rayon threads; its stdout (asserting success).
fn with_threads(threads: usize, args: &[&str]) -> Vec<u8> {
    let out = Command::new(env!("CARGO_BIN_EXE_jointrom"))
        .args(args)
        .env("RAYON_NUM_THREADS", threads.to_string())
        .output()
        .expect("run jointrom");
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out.stdout
}

fn export(threads: usize, case: &str, extra: &[&str], dir: &Path) -> Vec<u8> {
    let file = dir.join(format!("{case}-{threads}.json"));
    let mut args = vec!["export", case, "--out", file.to_str().unwrap()];
    args.extend_from_slice(extra);
    with_threads(threads, &args);
    std::fs::read(&file).unwrap()
}

/// The curves of a transient run (timings differ from run to run; the numbers may not).
fn curves(threads: usize, case: &str, extra: &[&str]) -> Value {
    let mut args = vec!["transient", case, "--json", "--end-time", "0.005"];
    args.extend_from_slice(extra);
    let doc: Value = serde_json::from_slice(&with_threads(threads, &args)).unwrap();
    serde_json::json!({
        "curves": doc["curves"],
        "stats": doc["stats"],
        "error_estimate": doc["error_estimate"],
        "basis_size": doc["basis_size"],
    })
}

#[test]
fn exports_are_bit_identical_for_one_and_two_threads() {
    let dir = tmp_dir("threads-export");
    for case in ["friction_bar", "multilayer_sheet"] {
        for extra in [&["--g", "12"][..], &["--basis", "alldof"][..]] {
            let one = export(1, case, extra, &dir);
            let two = export(2, case, extra, &dir);
            assert!(
                one == two,
                "{case} {extra:?}: exports differ between 1 and 2 threads"
            );
        }
    }
}

#[test]
fn tolerance_model_and_curves_are_bit_identical_for_one_and_two_threads() {
    let dir = tmp_dir("threads-tolerance");
    let one = export(1, "friction_bar", &["--tolerance", "1e-2"], &dir);
    let two = export(2, "friction_bar", &["--tolerance", "1e-2"], &dir);
    assert!(one == two, "tolerance-chosen exports differ");
    for case in ["friction_bar", "multilayer_sheet"] {
        for extra in [&["--g", "12"][..], &["--model", "full"][..]] {
            assert_eq!(
                curves(1, case, extra),
                curves(2, case, extra),
                "{case} {extra:?}: curves differ between 1 and 2 threads"
            );
        }
    }
}
