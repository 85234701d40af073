//! Smoke fuzzing of every parser on stable Rust, run by `cargo test`: a seeded,
//! structure-aware mutator derives thousands of inputs from valid seeds — the built-in case
//! files, a small model's exported K.mtx/M.mtx/model.json, an exported reduced model, a sweep's
//! variants — and each parser must answer every one with `Ok` or an error, never a panic, and
//! within a time bound. The coverage-guided fuzzing with libFuzzer (`fuzz/`, `scripts/fuzz.sh`)
//! runs the same parsers for longer; its figures are in docs/validation/hostile-input.md.
//!
//! `JOINTROM_FUZZ_CASES=N` changes the number of inputs per parser (default 4000).

#[path = "../common/mod.rs"]
mod common;

mod mutate;

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use jointrom::case::Case;
use jointrom::Model;
use mutate::Mutator;

/// Inputs per parser.
fn cases() -> usize {
    std::env::var("JOINTROM_FUZZ_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(4000)
}

/// Longest one input may take (a hang or an allocation by a declared size shows up here).
const PER_INPUT: Duration = Duration::from_secs(5);

/// Runs `parse` on `n` mutants of `seeds`; panics (with the reproducer saved under
/// `target/tmp/fuzz-<name>-crash`) on the first input that panics or takes too long.
fn fuzz(name: &str, seeds: &[Vec<u8>], seed: u64, parse: impl Fn(&[u8]) -> bool) {
    // Mutated element counts may ask for big meshes; a small model-size budget keeps every
    // accepted one quick (the budget itself is what is being exercised).
    std::env::set_var("JOINTROM_MAX_DOF", "30000");
    let mut m = Mutator::new(seed);
    let (mut ok, mut err) = (0usize, 0usize);
    let start = Instant::now();
    for i in 0..cases() {
        let input = m.mutate(&seeds[i % seeds.len()]);
        let t0 = Instant::now();
        let r = catch_unwind(AssertUnwindSafe(|| parse(&input)));
        let dt = t0.elapsed();
        let save = || {
            let p = common::tmp_path(&format!("fuzz-{name}-crash"));
            std::fs::write(&p, &input).unwrap();
            p
        };
        match r {
            Ok(true) => ok += 1,
            Ok(false) => err += 1,
            Err(_) => panic!("{name}: input {i} panicked; saved as {}", save().display()),
        }
        assert!(
            dt < PER_INPUT,
            "{name}: input {i} took {dt:?}; saved as {}",
            save().display()
        );
    }
    println!(
        "{name}: {} inputs in {:.1} s ({ok} accepted, {err} rejected)",
        ok + err,
        start.elapsed().as_secs_f64()
    );
    assert!(err > 0, "{name}: the mutator never produced a bad input");
}

/// A scratch file for parsers that read paths.
fn scratch(name: &str) -> PathBuf {
    common::tmp_dir(&format!("fuzz-{name}"))
}

#[test]
fn case_files() {
    // The welds' neighbourhoods are not re-meshed (`"local_mesh": "off"`): a mutated number
    // would miss the condensation cache and take seconds per input; the re-meshed
    // neighbourhood's own bad input is in tests/hostile and tests/element/weld.rs.
    let seeds: Vec<Vec<u8>> = ["friction_bar", "multilayer_sheet"]
        .iter()
        .map(|n| {
            let mut case: serde_json::Value = serde_json::from_str(&common::case_text(n)).unwrap();
            for w in case["welds"].as_array_mut().unwrap() {
                w["local_mesh"] = serde_json::json!("off");
            }
            serde_json::to_string_pretty(&case).unwrap().into_bytes()
        })
        .collect();
    fuzz("case", &seeds, 1, |bytes| {
        let Ok(text) = std::str::from_utf8(bytes) else {
            return false;
        };
        match Case::from_json_str(text, "fuzz.json") {
            // Building the model (mesh, elements, assembly) from an accepted case must not
            // panic either; the mesh size is bounded by the validated element counts.
            Ok(case) => Model::from_case(case).is_ok(),
            Err(_) => false,
        }
    });
}

/// Sizes derived from case numbers: seeds whose sheet spans 1e308 or 1e12 mm, whose shells are
/// 1e-3 mm against a 5 mm nugget, or whose `local_mesh` is 1e-300 mm, with the automatic
/// neighbourhoods on. Every mutant's mesh is built (the grids, nuggets and neighbourhoods whose
/// sizes are checked before they are allocated); the condensation is not, to keep each input
/// quick.
#[test]
fn case_sizes() {
    let base: serde_json::Value = serde_json::from_str(&common::case_text("friction_bar")).unwrap();
    let variants: [(&str, serde_json::Value); 5] = [
        ("/sheets/0/x", serde_json::json!([0.0, 1e308])),
        ("/sheets/0/x", serde_json::json!([-1e308, 1e308])),
        ("/sheets/1/x", serde_json::json!([40.0, 1e12])),
        ("/sheets/0/elements", serde_json::json!([100000, 1])),
        ("/welds/0/diameter", serde_json::json!(24.0)),
    ];
    let mut seeds: Vec<Vec<u8>> = variants
        .iter()
        .map(|(ptr, v)| {
            let mut case = base.clone();
            *case.pointer_mut(ptr).unwrap() = v.clone();
            serde_json::to_string_pretty(&case).unwrap().into_bytes()
        })
        .collect();
    let mut tiny = base.clone();
    tiny["welds"][0]["local_mesh"] = serde_json::json!(1e-300);
    seeds.push(serde_json::to_string_pretty(&tiny).unwrap().into_bytes());
    // The seeds themselves: all but the wide nugget (accepted) are refused, none panics.
    let refused = seeds
        .iter()
        .filter(|s| {
            Case::from_json_str(std::str::from_utf8(s).unwrap(), "seed.json")
                .and_then(|case| jointrom::mesh::Mesh::from_case(&case))
                .is_err()
        })
        .count();
    assert_eq!(refused, seeds.len() - 1);
    fuzz("case-sizes", &seeds, 6, |bytes| {
        let Ok(text) = std::str::from_utf8(bytes) else {
            return false;
        };
        match Case::from_json_str(text, "fuzz.json") {
            Ok(case) => jointrom::mesh::Mesh::from_case(&case).is_ok(),
            Err(_) => false,
        }
    });
}

/// The friction bar on a coarse grid (6 × 2 shells a sheet, 20 mm apart, no welds).
fn shrink(case: &mut serde_json::Value) {
    case["sheets"][0]["x"] = serde_json::json!([0.0, 120.0]);
    case["sheets"][1]["x"] = serde_json::json!([40.0, 160.0]);
    case["sheets"][0]["elements"] = serde_json::json!([6, 2]);
    case["sheets"][1]["elements"] = serde_json::json!([6, 2]);
    case["rigid_tie"]["x"] = serde_json::json!(160.0);
    case["rigid_tie"]["master"] = serde_json::json!([160.0, 0.5, 12.5]);
    case["welds"] = serde_json::json!([]);
}

/// A small model's exported matrices and map (a coarse friction bar: a few hundred DOF).
fn small_matrices(dir: &Path) -> (Vec<u8>, Vec<u8>, Vec<u8>) {
    let mut case: serde_json::Value =
        serde_json::from_str(&common::case_text("friction_bar")).unwrap();
    shrink(&mut case);
    let case_file = dir.join("small.json");
    std::fs::write(&case_file, case.to_string()).unwrap();
    let out = dir.join("small");
    common::jointrom_ok([
        "export-matrices",
        case_file.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    let read = |f: &str| std::fs::read(out.join(f)).unwrap();
    (read("model.json"), read("K.mtx"), read("M.mtx"))
}

#[test]
fn matrix_maps_and_matrix_market_files() {
    let dir = scratch("matrices");
    let (map, k, m) = small_matrices(&dir);
    let work = dir.join("work");
    std::fs::create_dir_all(&work).unwrap();
    std::fs::write(work.join("M.mtx"), &m).unwrap();
    std::fs::write(work.join("K.mtx"), &k).unwrap();
    std::fs::write(work.join("model.json"), &map).unwrap();
    // Mutants of each file in turn, the other two left valid.
    for (file, seed) in [("model.json", &map), ("K.mtx", &k), ("M.mtx", &m)] {
        let target = work.join(file);
        fuzz(
            &format!("matrices:{file}"),
            std::slice::from_ref(seed),
            2,
            |bytes| {
                std::fs::write(&target, bytes).unwrap();
                jointrom::model::matrices::load(&work.join("model.json")).is_ok()
            },
        );
        std::fs::write(&target, seed).unwrap();
    }
}

#[test]
fn reduced_model_files() {
    let dir = scratch("rom");
    let rom = dir.join("rom.json");
    common::jointrom_ok([
        "export",
        "friction_bar",
        "--g",
        "2",
        "--out",
        rom.to_str().unwrap(),
    ]);
    let seed = std::fs::read(&rom).unwrap();
    let target = dir.join("mutant.json");
    fuzz("rom", &[seed], 3, |bytes| {
        std::fs::write(&target, bytes).unwrap();
        match jointrom::rom::file::RomFile::read(&target) {
            Ok(f) => f.system().is_ok(),
            Err(_) => false,
        }
    });
}

#[test]
fn sweep_variants() {
    let dir = scratch("variants");
    let seed = std::fs::read(common::repo_path("cases/sweeps/friction_bar_mu.json")).unwrap();
    let target = dir.join("variants.json");
    fuzz("variants", &[seed], 4, |bytes| {
        std::fs::write(&target, bytes).unwrap();
        jointrom::studies::sweep::read_variants(&target).is_ok()
    });
}

/// PETSc's binary format (`jointrom::model::petsc`, what the distributed path reads back): a
/// small symmetric AIJ matrix, a dense block in both of PETSc's layouts and two vectors; every
/// reader on every mutant.
#[test]
fn petsc_binary_files() {
    use jointrom::model::petsc;
    let dir = scratch("petsc");
    let n: usize = 8;
    let mut col_ptr = vec![0];
    let (mut row_idx, mut values) = (Vec::new(), Vec::new());
    for j in 0..n {
        for i in j.saturating_sub(1)..(j + 2).min(n) {
            row_idx.push(i);
            values.push(if i == j { 2.0 } else { -1.0 });
        }
        col_ptr.push(row_idx.len());
    }
    let a = jointrom::linalg::SymCsc {
        n,
        col_ptr,
        row_idx,
        values,
    };
    let x = faer::Mat::from_fn(5, 3, |i, j| i as f64 - 0.5 * j as f64);
    let (fa, fx, fv) = (dir.join("a"), dir.join("x"), dir.join("v"));
    petsc::write_sym_aij(&fa, &a).unwrap();
    petsc::write_dense(&fx, x.as_ref()).unwrap();
    petsc::write_vec(&fv, &[1.0, 2.0, 3.0]).unwrap();
    let mut vv = std::fs::read(&fv).unwrap();
    vv.extend_from_slice(&vv.clone());
    let seeds = vec![std::fs::read(&fa).unwrap(), std::fs::read(&fx).unwrap(), vv];
    let target = dir.join("mutant.petsc");
    fuzz("petsc", &seeds, 5, |bytes| {
        std::fs::write(&target, bytes).unwrap();
        let a = petsc::read_sym_aij(&target).is_ok();
        let d = petsc::read_dense(&target).is_ok();
        let v = petsc::read_vecs(&target).is_ok();
        a || d || v
    });
}
