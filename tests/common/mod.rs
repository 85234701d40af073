//! Helpers shared by the integration-test binaries (`tests/<stage>/main.rs`): running the
//! `jointrom` binary, built-in models and case files, scratch paths, the stored reference
//! curves, small vector helpers and seeded random numbers.
//!
//! Every binary includes this module, and none uses all of it.
#![allow(dead_code)]

use std::ffi::OsStr;
use std::path::PathBuf;
use std::process::{Command, Output};

use jointrom::case::Case;
use jointrom::integrate::TransientOptions;
use jointrom::joint::statics::{contact_static_reduced, ContactOptions, ContactState};
use jointrom::joint::NORMAL;
use jointrom::linalg::SymCsc;
use jointrom::system::ReducedSystem;
use jointrom::{Error, Model};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use serde_json::Value;

// ---------------------------------------------------------------------------------------------
// The command-line binary

/// Runs the `jointrom` binary with `args`; its output, whatever the exit status.
pub fn jointrom<I, S>(args: I) -> Output
where
    I: IntoIterator<Item = S>,
    S: AsRef<OsStr>,
{
    Command::new(env!("CARGO_BIN_EXE_jointrom"))
        .args(args)
        .output()
        .expect("run the jointrom binary")
}

/// Runs the `jointrom` binary with `args`, asserting success; its standard output.
pub fn jointrom_ok<I, S>(args: I) -> Vec<u8>
where
    I: IntoIterator<Item = S>,
    S: AsRef<OsStr>,
{
    let args: Vec<S> = args.into_iter().collect();
    let out = jointrom(&args);
    assert!(
        out.status.success(),
        "jointrom {:?} failed: {}",
        args.iter().map(|a| a.as_ref()).collect::<Vec<_>>(),
        String::from_utf8_lossy(&out.stderr)
    );
    out.stdout
}

/// Runs the `jointrom` binary with `args`, asserting success; its standard output as one JSON
/// document.
pub fn jointrom_json<I, S>(args: I) -> Value
where
    I: IntoIterator<Item = S>,
    S: AsRef<OsStr>,
{
    serde_json::from_slice(&jointrom_ok(args)).expect("stdout is one JSON document")
}

/// Runs the `jointrom` binary with `args`, asserting failure; its standard error.
pub fn jointrom_err<I, S>(args: I) -> String
where
    I: IntoIterator<Item = S>,
    S: AsRef<OsStr>,
{
    let args: Vec<S> = args.into_iter().collect();
    let out = jointrom(&args);
    assert!(
        !out.status.success(),
        "jointrom {:?} should fail",
        args.iter().map(|a| a.as_ref()).collect::<Vec<_>>()
    );
    String::from_utf8_lossy(&out.stderr).into_owned()
}

// ---------------------------------------------------------------------------------------------
// Built-in cases and models, files of the repository

/// The built-in model `name` (or a case or matrix-map file path).
pub fn model(name: &str) -> Model {
    Model::from_case_name(name).unwrap_or_else(|e| panic!("model `{name}` does not load: {e}"))
}

/// The built-in model `name` with every weld a point weld (`"model": "point"`): the model before
/// the RBE3 weld, kept where a test needs a behaviour measured on it (an active-set cycle).
#[allow(dead_code)]
pub fn point_weld_model(name: &str) -> Model {
    let mut case = builtin_case(name);
    for w in &mut case.welds {
        w.model = jointrom::case::WeldModel::Point;
    }
    Model::from_case(case).unwrap()
}

/// The built-in case `name` with the welds' neighbourhoods not re-meshed (`"local_mesh":
/// "off"`: the RBE3 area weld on the sheets' own shells, the default before the re-meshed
/// neighbourhood) — what a NASTRAN deck's CWELD gives, and the model some tests' measured
/// premises were taken on.
#[allow(dead_code)]
pub fn rbe3_case(name: &str) -> Case {
    let mut case = builtin_case(name);
    for w in &mut case.welds {
        w.local_mesh = jointrom::case::LocalMesh::Off;
    }
    case
}

/// [`rbe3_case`]'s model.
#[allow(dead_code)]
pub fn rbe3_model(name: &str) -> Model {
    Model::from_case(rbe3_case(name)).unwrap()
}

/// The built-in case `name` with point welds written to a temporary file; its path.
#[allow(dead_code)]
pub fn point_weld_case_file(name: &str) -> String {
    let mut case: Value = serde_json::from_str(&case_text(name)).unwrap();
    for w in case["welds"].as_array_mut().unwrap() {
        w["model"] = Value::from("point");
    }
    let path = tmp_path(&format!("{name}_point_welds.json"));
    std::fs::write(&path, case.to_string()).unwrap();
    path.to_str().unwrap().to_string()
}

/// The built-in case `name`.
pub fn builtin_case(name: &str) -> Case {
    Case::builtin(name)
        .unwrap_or_else(|| panic!("`{name}` is not a built-in case"))
        .unwrap_or_else(|e| panic!("built-in `{name}` does not load: {e}"))
}

/// A path inside the repository (`rel` relative to its root).
pub fn repo_path(rel: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(rel)
}

/// The text of the built-in case file `cases/{name}.json`.
pub fn case_text(name: &str) -> String {
    let path = repo_path(&format!("cases/{name}.json"));
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// A stored full-FE reference, `cases/reference/{name}.json`, as JSON.
pub fn reference_json(name: &str) -> (PathBuf, Value) {
    let path = repo_path(&format!("cases/reference/{name}.json"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let v = serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    (path, v)
}

/// The default transient options, run to `end_time` (s).
pub fn until(end_time: f64) -> TransientOptions {
    TransientOptions {
        end_time: Some(end_time),
        ..TransientOptions::default()
    }
}

// ---------------------------------------------------------------------------------------------
// Scratch files and folders

/// A scratch path `{name}` under Cargo's per-target temporary directory (nothing is created or
/// removed). Callers prefix `name` with their module's name, so binaries and modules do not clash.
pub fn tmp_path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name)
}

/// A fresh, empty scratch folder `{name}` under Cargo's per-target temporary directory.
pub fn tmp_dir(name: &str) -> PathBuf {
    let d = tmp_path(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap_or_else(|e| panic!("{}: {e}", d.display()));
    d
}

// ---------------------------------------------------------------------------------------------
// Vectors, curves

/// Euclidean norm.
pub fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// Dot product.
pub fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// Max norm.
pub fn inf_norm(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

/// Column `c` of `a`.
pub fn col(a: faer::MatRef<'_, f64>, c: usize) -> Vec<f64> {
    a.col(c).iter().copied().collect()
}

/// `A x` for sparse symmetric A.
pub fn mul(a: &SymCsc, x: &[f64]) -> Vec<f64> {
    let mut y = vec![0.0; a.n];
    a.mul_vec(x, &mut y);
    y
}

/// 3-vectors (node coordinates, directions).
pub mod v3 {
    pub type V3 = [f64; 3];

    pub fn dot(a: V3, b: V3) -> f64 {
        a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
    }

    pub fn cross(a: V3, b: V3) -> V3 {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    }

    pub fn norm(v: V3) -> f64 {
        dot(v, v).sqrt()
    }

    pub fn normalize(v: V3) -> V3 {
        let n = norm(v);
        v.map(|x| x / n)
    }

    pub fn scale(v: V3, s: f64) -> V3 {
        [v[0] * s, v[1] * s, v[2] * s]
    }

    pub fn add(a: V3, b: V3) -> V3 {
        [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
    }

    pub fn sub(a: V3, b: V3) -> V3 {
        [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
    }
}

/// Relative L2 difference over the first `n` samples: `‖a − b‖₂ / ‖b‖₂`.
pub fn rel_l2(a: &[f64], b: &[f64], n: usize) -> f64 {
    let num: f64 = (0..n).map(|i| (a[i] - b[i]).powi(2)).sum();
    let den: f64 = (0..n).map(|i| b[i].powi(2)).sum();
    (num / den).sqrt()
}

/// Relative L2 differences of ‖f_c‖, ‖f_R‖, u_y and D between two runs with the same outputs.
pub fn curve_differences(
    a: &jointrom::integrate::Run,
    b: &jointrom::integrate::Run,
) -> [(&'static str, f64); 4] {
    assert_eq!(a.curves.t.len(), b.curves.t.len(), "output count");
    let n = a.curves.t.len();
    let (x, y) = (&a.curves, &b.curves);
    [
        (
            "|f_c|",
            rel_l2(&x.contact_force_norm, &y.contact_force_norm, n),
        ),
        (
            "|f_R|",
            rel_l2(&x.friction_force_norm, &y.friction_force_norm, n),
        ),
        ("u_y", rel_l2(&x.master_uy, &y.master_uy, n)),
        ("D", rel_l2(&x.dissipated, &y.dissipated, n)),
    ]
}

// ---------------------------------------------------------------------------------------------
// Random numbers

/// A seeded generator: the same numbers on every run and machine.
pub fn rng(seed: u64) -> StdRng {
    StdRng::seed_from_u64(seed)
}

/// Uniform in [−1, 1).
pub fn uniform(rng: &mut StdRng) -> f64 {
    rng.random_range(-1.0..1.0)
}

/// Frictionless contact statics of a reduced system under the master load `load`
/// (`[Fx, Fy, Fz, Mx, My, Mz]`, N and N·mm) with penalty `k_n` (N/mm): the reduced coordinates
/// and the contact state.
pub fn reduced_contact(
    red: &ReducedSystem,
    load: [f64; 6],
    k_n: f64,
) -> Result<(Vec<f64>, ContactState), Error> {
    let r = red.dim();
    let w = red.b_phi().nrows() / 3;
    let b_n_phi = faer::Mat::from_fn(w, r, |i, j| red.b_phi()[(3 * i + NORMAL, j)]);
    let f_red: Vec<f64> = (0..r)
        .map(|c| (0..6).map(|d| red.phi_master[(d, c)] * load[d]).sum())
        .collect();
    contact_static_reduced(
        red.k().as_ref(),
        b_n_phi.as_ref(),
        &f_red,
        k_n,
        &ContactOptions::default(),
    )
}
