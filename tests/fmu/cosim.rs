//! The FMU of a small reduced model of the friction bar (TVD, g = 12, r = 28), exported by the
//! CLI, unpacked, and driven through its C interface as an importer would.
//!
//! The reference is `jointrom transient friction_bar --model file:ROM.json --end-time 0.02`: the
//! contract is a relative L2 difference of `master_uy` of at most 1e-3; the stepper's design
//! (no stop time, a restart only when inputs change) makes it agree to round-off, which is
//! checked as well.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;
use std::time::Instant;

use jointrom::report::fmu::{vr, BINARY_ENV, BINARY_FILE};
use serde_json::Value;

use crate::common::{self, norm};
use crate::host::{Fmu, Instance, CS_FUNCTIONS, OK};

/// Communication step and end of the runs, s (the transient's default output step).
pub const STEP: f64 = 1e-4;
pub const END: f64 = 0.02;

/// What every test shares: the binary, the unpacked FMU and the transient's curves.
pub struct Fixture {
    pub binary: PathBuf,
    /// The unpacked archive.
    pub dir: PathBuf,
    pub guid: String,
    /// `transient` curves: `t`, `master_uy`, `contact_force_norm`.
    t: Vec<f64>,
    uy: Vec<f64>,
    fc: Vec<f64>,
    /// The ROM's final master load `[fx, fy, fz, mx, my, mz]` and ramp duration (s).
    load: [f64; 6],
    ramp: f64,
}

/// The FMU binary: `$JOINTROM_FMU_BINARY`, else built by cargo (a no-op when `cargo test`
/// built the workspace) into the folder of the `jointrom` executable under test.
fn build_binary() -> PathBuf {
    if let Some(p) = std::env::var_os(BINARY_ENV) {
        return PathBuf::from(p);
    }
    let exe = PathBuf::from(env!("CARGO_BIN_EXE_jointrom"));
    let dir = exe.parent().unwrap().to_path_buf();
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let mut cmd = Command::new(cargo);
    cmd.current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(["build", "-p", "jointrom-fmu"]);
    if dir.file_name().is_some_and(|n| n == "release") {
        cmd.arg("--release");
    }
    let out = cmd.output().expect("run cargo build -p jointrom-fmu");
    assert!(
        out.status.success(),
        "cargo build -p jointrom-fmu failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let so = dir.join(BINARY_FILE);
    assert!(so.is_file(), "{} was not built", so.display());
    so
}

/// Runs `jointrom` with the FMU binary named by the environment.
pub fn jointrom(binary: &Path, args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_jointrom"))
        .env(BINARY_ENV, binary)
        .args(args)
        .output()
        .expect("run jointrom")
}

/// Unpacks the zip at `fmu` into `dir`; the names of its entries.
fn unpack(fmu: &Path, dir: &Path) -> Vec<String> {
    let file = std::fs::File::open(fmu).unwrap();
    let mut z = zip::ZipArchive::new(file).unwrap();
    let names: Vec<String> = z.file_names().map(str::to_string).collect();
    z.extract(dir).unwrap();
    names
}

pub fn fixture() -> &'static Fixture {
    static FIXTURE: OnceLock<Fixture> = OnceLock::new();
    FIXTURE.get_or_init(|| {
        let binary = build_binary();
        let work = common::tmp_dir("fmu_fixture");
        let rom = work.join("rom.json");
        let fmu = work.join("friction_bar.fmu");
        let (rom_s, fmu_s) = (rom.to_str().unwrap(), fmu.to_str().unwrap());
        let out = jointrom(
            &binary,
            &["export", "friction_bar", "--basis", "tvd", "--g", "12"]
                .into_iter()
                .chain(["--out", rom_s, "--fmu", fmu_s])
                .collect::<Vec<_>>(),
        );
        assert!(
            out.status.success(),
            "export failed: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let dir = work.join("unpacked");
        let names = unpack(&fmu, &dir);
        for entry in [
            "modelDescription.xml",
            "binaries/linux64/jointrom_friction_bar.so",
            "resources/rom.json",
        ] {
            assert!(names.iter().any(|n| n == entry), "{entry} in {names:?}");
        }
        let packed = std::fs::read(dir.join("resources/rom.json")).unwrap();
        assert_eq!(
            packed,
            std::fs::read(&rom).unwrap(),
            "rom.json = the --out file"
        );
        let xml = std::fs::read_to_string(dir.join("modelDescription.xml")).unwrap();
        let guid = xml
            .split("guid=\"")
            .nth(1)
            .unwrap()
            .split('"')
            .next()
            .unwrap();
        assert_eq!(guid, jointrom::report::fmu::guid(&packed));
        let doc = common::jointrom_json([
            "transient",
            "friction_bar",
            "--model",
            &format!("file:{rom_s}"),
            "--end-time",
            &END.to_string(),
            "--json",
        ]);
        let curve = |k: &str| -> Vec<f64> {
            doc["curves"][k]
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_f64().unwrap())
                .collect()
        };
        let rom_doc: Value = serde_json::from_slice(&packed).unwrap();
        let m = &rom_doc["master_load"];
        let load = ["fx", "fy", "fz", "mx", "my", "mz"].map(|k| m[k].as_f64().unwrap_or(0.0));
        Fixture {
            binary,
            guid: guid.to_string(),
            t: curve("t"),
            uy: curve("master_uy"),
            fc: curve("contact_force_norm"),
            load,
            ramp: rom_doc["load_ramp"]["duration"].as_f64().unwrap(),
            dir,
        }
    })
}

/// The `file:` URI of the unpacked resources folder `dir/resources`.
pub fn resources_uri(dir: &Path) -> String {
    format!("file://{}/resources/", dir.display())
}

/// `‖a − b‖ / ‖b‖` over the common length.
fn rel_l2(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    let d: Vec<f64> = (0..n).map(|i| a[i] - b[i]).collect();
    norm(&d) / norm(&b[..n])
}

/// An initialized instance of the packed binary with the given parameters `(vr, value)` set
/// before initialization.
pub fn started<'a>(fmu: &'a Fmu, f: &Fixture, params: &[(u32, f64)]) -> Instance<'a> {
    let inst = Instance::new(fmu, &f.guid, &resources_uri(&f.dir), true).unwrap();
    assert_eq!(inst.setup(None, 0.0, Some(END)), OK);
    for &(r, v) in params {
        assert_eq!(inst.set_real(&[r], &[v]), OK, "{:?}", inst.take_log());
    }
    assert_eq!(inst.enter(), OK);
    assert_eq!(inst.exit(), OK, "{:?}", inst.take_log());
    inst
}

/// Steps `inst` to [`END`] by [`STEP`], calling `before(k, t)` before each step; `master_uy`
/// and `contact_force_norm` at 0 and after every step.
fn run(inst: &Instance, mut before: impl FnMut(usize, f64)) -> (Vec<f64>, Vec<f64>) {
    let out = [vr::MASTER_UY, vr::CONTACT_FORCE_NORM];
    let (s, v) = inst.get_real(&out);
    assert_eq!(s, OK);
    let (mut uy, mut fc) = (vec![v[0]], vec![v[1]]);
    let n = (END / STEP).round() as usize;
    for k in 0..n {
        let t = k as f64 * STEP;
        before(k, t);
        assert_eq!(inst.do_step(t, STEP), OK, "step {k}: {:?}", inst.take_log());
        let (s, v) = inst.get_real(&out);
        assert_eq!(s, OK);
        uy.push(v[0]);
        fc.push(v[1]);
    }
    (uy, fc)
}

#[test]
fn fmu_reproduces_the_transient_of_its_reduced_model() {
    let f = fixture();
    // The binary inside the archive, as an importer loads it.
    let fmu = Fmu::load(&f.dir.join("binaries/linux64/jointrom_friction_bar.so"));
    assert_eq!(fmu.version(), "2.0");
    for name in CS_FUNCTIONS {
        assert!(fmu.exports(name), "{name} exported");
    }
    let inst = started(&fmu, f, &[]);
    let start = Instant::now();
    let (uy, fc) = run(&inst, |_, _| {});
    let wall = start.elapsed().as_secs_f64();
    let (s, t_end) = inst.last_successful_time();
    assert!(s == OK && (t_end - END).abs() < 1e-12, "{s} {t_end}");
    assert_eq!(inst.terminate(), OK);
    assert_eq!(
        uy.len(),
        f.uy.len(),
        "outputs at the transient's times {:?}",
        &f.t[..3]
    );
    let e_uy = rel_l2(&uy, &f.uy);
    let e_fc = rel_l2(&fc, &f.fc);
    println!(
        "FMU vs transient over {END} s, {} steps of {STEP} s: master_uy rel. L2 {e_uy:.3e}, \
         contact_force_norm {e_fc:.3e}; {wall:.3} s for the run",
        uy.len() - 1
    );
    assert!(e_uy <= 1e-3, "master_uy: {e_uy:e}");
    // The stepper makes the same CVODE calls as the transient's driver loop.
    assert!(e_uy <= 1e-12 && e_fc <= 1e-12, "{e_uy:e} {e_fc:e}");
    assert!(uy.iter().any(|&u| u.abs() > 1e-4), "the bar moves");
}

#[test]
fn inputs_drive_the_model_like_its_own_load() {
    // load_scale = 0 and the ROM's load fed as inputs, sampled at the middle of each step (a
    // zero-order hold of the ramp), with a restart of CVODE at every step: the same curve to
    // the hold's error.
    let f = fixture();
    let fmu = Fmu::load(&f.binary);
    let inst = started(&fmu, f, &[(vr::LOAD_SCALE, 0.0)]);
    let inputs: Vec<u32> = (vr::MASTER_FX..=vr::MASTER_MZ).collect();
    let (uy, _) = run(&inst, |_, t| {
        let mid = t + 0.5 * STEP;
        let ramp = 0.5 * (1.0 - (std::f64::consts::PI * (mid / f.ramp).min(1.0)).cos());
        let values = f.load.map(|v| v * ramp);
        assert_eq!(inst.set_real(&inputs, &values), OK);
    });
    let e = rel_l2(&uy, &f.uy);
    println!("inputs as a zero-order hold of the ROM's own load: master_uy rel. L2 {e:.3e}");
    assert!(e <= 1e-2, "{e:e}");
    // Twice the own load is not twice the response (contact and friction), but it is larger.
    let inst = started(&fmu, f, &[(vr::LOAD_SCALE, 2.0)]);
    let (uy2, _) = run(&inst, |_, _| {});
    assert!(
        norm(&uy2) > 1.5 * norm(&f.uy),
        "{} vs {}",
        norm(&uy2),
        norm(&f.uy)
    );
}
