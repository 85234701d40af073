//! The FMU's error paths: bad arguments, calls in the wrong state, a failing integrator and
//! damaged resources give `fmi2Error` (or NULL from `fmi2Instantiate`) with a message through
//! the logger — never a crash — and instances are freed whatever state they are in.

use jointrom::report::fmu::{guid, vr};

use crate::common;
use crate::cosim::{fixture, jointrom, resources_uri, started, END, STEP};
use crate::host::{Fmu, Instance, ERROR, OK};

/// Asserts that the instance's log holds an error message containing `what`.
fn logged(inst: &Instance, what: &str) {
    let log = inst.take_log();
    assert!(
        log.iter()
            .any(|m| m.starts_with("3 [logStatusError]") && m.contains(what)),
        "expected an error about `{what}`, log: {log:?}"
    );
}

#[test]
fn bad_steps_and_inputs_are_errors_and_reset_recovers() {
    let f = fixture();
    let fmu = Fmu::load(&f.binary);
    assert_eq!(fmu.null_component_calls(), ERROR);

    let inst = started(&fmu, f, &[]);
    assert_eq!(inst.do_step(0.0, -STEP), ERROR);
    logged(
        &inst,
        "communicationStepSize must be finite and positive, got -0.0001",
    );
    // The instance is now in the error state: no more steps, values still readable.
    assert_eq!(inst.do_step(0.0, STEP), ERROR);
    logged(&inst, "not allowed in state Error");
    assert_eq!(inst.get_real(&[vr::MASTER_UY]), (OK, vec![0.0]));
    // Reset brings it back.
    assert_eq!(inst.reset(), OK);
    assert_eq!(inst.setup(None, 0.0, None), OK);
    assert_eq!(inst.enter(), OK);
    assert_eq!(inst.exit(), OK);
    assert_eq!(inst.do_step(0.0, STEP), OK);

    for (t, h, what) in [
        (0.0, 0.0, "communicationStepSize"),
        (STEP, f64::NAN, "communicationStepSize"),
        (0.5, STEP, "is not the FMU's time"),
        (f64::NAN, STEP, "is not the FMU's time"),
    ] {
        let inst = started(&fmu, f, &[]);
        assert_eq!(inst.do_step(0.0, STEP), OK);
        assert_eq!(inst.do_step(t, h), ERROR, "doStep({t}, {h})");
        logged(&inst, what);
    }
    // Past the stop time given to fmi2SetupExperiment.
    let inst = started(&fmu, f, &[]);
    assert_eq!(inst.do_step(0.0, 2.0 * END), ERROR);
    logged(&inst, "past the stopTime");

    let inst = started(&fmu, f, &[]);
    assert_eq!(inst.set_real(&[vr::MASTER_FY], &[f64::NAN]), ERROR);
    logged(&inst, "master_fy = NaN is not finite");
    let inst = started(&fmu, f, &[]);
    assert_eq!(inst.set_real(&[vr::LOAD_SCALE], &[f64::INFINITY]), ERROR);
    logged(&inst, "load_scale = inf is not finite");
}

#[test]
fn calls_in_the_wrong_state_and_unknown_variables_are_errors() {
    let f = fixture();
    let fmu = Fmu::load(&f.binary);
    let uri = resources_uri(&f.dir);
    let fresh = || Instance::new(&fmu, &f.guid, &uri, true).unwrap();

    let inst = fresh();
    assert_eq!(inst.do_step(0.0, STEP), ERROR);
    logged(&inst, "fmi2DoStep is not allowed in state Instantiated");
    let inst = fresh();
    assert_eq!(inst.get_real(&[vr::MASTER_UY]).0, ERROR);
    logged(&inst, "fmi2GetReal is not allowed in state Instantiated");
    let inst = fresh();
    assert_eq!(inst.exit(), ERROR);
    logged(&inst, "fmi2ExitInitializationMode is not allowed");

    // Fixed parameters only before initialization; outputs never; bad values of parameters.
    let inst = started(&fmu, f, &[]);
    assert_eq!(inst.set_real(&[vr::MU], &[0.1]), ERROR);
    logged(&inst, "mu is a fixed parameter");
    for (r, v, what) in [
        (vr::MASTER_UY, 1.0, "master_uy is an output"),
        (vr::K_N, 0.0, "k_n must be > 0 N/mm"),
        (vr::MU, -0.1, "mu must be >= 0"),
        (99, 1.0, "no Real variable has value reference 99"),
    ] {
        let inst = fresh();
        assert_eq!(inst.set_real(&[r], &[v]), ERROR);
        logged(&inst, what);
    }
    // Setting a value that is refused changes nothing else of the call.
    let inst = fresh();
    assert_eq!(
        inst.set_real(&[vr::MU, vr::K_T], &[0.5, -1.0]),
        ERROR,
        "all or nothing"
    );
    assert_eq!(inst.reset(), OK);
    assert_eq!(inst.enter(), OK);
    let mu0 = inst.get_real(&[vr::MU]).1[0];
    assert!((mu0 - 0.25).abs() < 1e-15, "mu back to the ROM's: {mu0}");

    let inst = started(&fmu, f, &[]);
    assert_eq!(inst.get_fmu_state(), ERROR);
    logged(&inst, "canGetAndSetFMUstate");
    let inst = started(&fmu, f, &[]);
    assert_eq!(inst.terminate(), OK);
    assert_eq!(inst.do_step(0.0, STEP), ERROR);
    logged(&inst, "not allowed in state Terminated");
}

#[test]
fn an_integrator_failure_is_an_error() {
    // A penalty of 1e300 N/mm overflows the pair forces at the first contact.
    let f = fixture();
    let fmu = Fmu::load(&f.binary);
    let inst = started(&fmu, f, &[(vr::K_N, 1e300), (vr::K_T, 1e300)]);
    let mut status = OK;
    let mut t = 0.0;
    while status == OK && t < END - 0.5 * STEP {
        status = inst.do_step(t, STEP);
        t += STEP;
    }
    assert_eq!(status, ERROR, "the run fails before {END} s");
    let log = inst.take_log();
    println!("k_n = 1e300 N/mm: {log:?}");
    assert!(log.iter().any(|m| m.contains("fmi2DoStep from")), "{log:?}");
    // Freed in the error state (drop).
}

/// A resources folder `name/resources` holding `text` as `rom.json` (none for `None`).
fn damaged_copy(name: &str, text: Option<&[u8]>) -> std::path::PathBuf {
    let dir = common::tmp_dir(name);
    std::fs::create_dir_all(dir.join("resources")).unwrap();
    if let Some(t) = text {
        std::fs::write(dir.join("resources/rom.json"), t).unwrap();
    }
    dir
}

#[test]
fn missing_or_damaged_resources_refuse_to_instantiate() {
    let f = fixture();
    let fmu = Fmu::load(&f.binary);
    let good = std::fs::read(f.dir.join("resources/rom.json")).unwrap();

    let missing = damaged_copy("fmu_missing", None);
    let e = Instance::new(&fmu, &f.guid, &resources_uri(&missing), true)
        .err()
        .unwrap();
    assert!(
        e.iter()
            .any(|m| m.contains("cannot read the reduced model")),
        "{e:?}"
    );

    // One digit changed: the GUID no longer matches.
    let mut edited = good.clone();
    let at = edited.iter().position(|b| b.is_ascii_digit()).unwrap();
    edited[at] = if edited[at] == b'9' {
        b'8'
    } else {
        edited[at] + 1
    };
    let dir = damaged_copy("fmu_edited", Some(&edited));
    let e = Instance::new(&fmu, &f.guid, &resources_uri(&dir), true)
        .err()
        .unwrap();
    assert!(
        e.iter().any(|m| m.contains("does not belong to this FMU")),
        "{e:?}"
    );

    // A damaged file with a matching GUID (as if packed so): the reader names the field.
    let cut = &good[..good.len() / 2];
    let dir = damaged_copy("fmu_cut", Some(cut));
    let e = Instance::new(&fmu, &guid(cut), &resources_uri(&dir), true)
        .err()
        .unwrap();
    assert!(e.iter().any(|m| m.contains("rom.json")), "{e:?}");
    let bad = String::from_utf8(good.clone()).unwrap().replacen(
        "\"normal_stiffness\": 10000.0",
        "\"normal_stiffness\": -1.0",
        1,
    );
    assert_ne!(bad.as_bytes(), &good[..]);
    let dir = damaged_copy("fmu_negative_kn", Some(bad.as_bytes()));
    let e = Instance::new(&fmu, &guid(bad.as_bytes()), &resources_uri(&dir), true)
        .err()
        .unwrap();
    assert!(
        e.iter().any(|m| m.contains("contact.normal_stiffness")),
        "{e:?}"
    );

    // Wrong kind, bad locations.
    let e = Instance::new(&fmu, &f.guid, &resources_uri(&f.dir), false)
        .err()
        .unwrap();
    assert!(e.iter().any(|m| m.contains("co-simulation only")), "{e:?}");
    let e = Instance::new(&fmu, &f.guid, "http://example.org/resources", true)
        .err()
        .unwrap();
    assert!(e.iter().any(|m| m.contains("not a file: URI")), "{e:?}");

    // Instances come and go.
    for _ in 0..3 {
        let a = started(&fmu, f, &[]);
        let b = started(&fmu, f, &[]);
        assert_eq!(a.do_step(0.0, STEP), OK);
        assert_eq!(b.do_step(0.0, STEP), OK);
    }
}

#[test]
fn export_names_a_missing_or_wrong_binary() {
    let f = fixture();
    let dir = common::tmp_dir("fmu_export_errors");
    let out = dir.join("x.fmu");
    let args = [
        "export",
        "friction_bar",
        "--g",
        "2",
        "--fmu",
        out.to_str().unwrap(),
    ];
    let missing = dir.join("no/libjointrom_fmu.so");
    let o = jointrom(&missing, &args);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.contains("JOINTROM_FMU_BINARY"),
        "{err}"
    );
    assert!(err.contains("is not a file"), "{err}");
    let not_elf = dir.join("fake.so");
    std::fs::write(&not_elf, "not a shared object").unwrap();
    let o = jointrom(&not_elf, &args);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.contains("not a 64-bit ELF"),
        "{err}"
    );
    assert!(!out.exists(), "no archive written");
    // Neither --out nor --fmu.
    let o = jointrom(&f.binary, &["export", "friction_bar", "--g", "2"]);
    assert!(!o.status.success());
}
