//! The exported reduced model (`jointrom export`, schema `jointrom-rom` v1): re-integrated by
//! jointrom's own engine it gives the same curves as the model it came from, and a damaged file
//! is rejected naming the file and the field.

use std::path::PathBuf;

use jointrom::integrate as transient;
use jointrom::reduction::{build_basis, BasisKind, BasisOptions};
use jointrom::rom::file::{BasisInfo, RomFile};
use jointrom::system::{ReducedSystem, Scene};

use crate::common::{self, jointrom_json, jointrom_ok};

fn tmp(name: &str) -> PathBuf {
    common::tmp_path(&format!("export_{name}.json"))
}

#[test]
fn exported_rom_reintegrates_to_identical_curves() {
    let model = common::model("friction_bar");
    let b = build_basis(&model, BasisKind::Tvd, &BasisOptions::default()).unwrap();
    let info = BasisInfo {
        kind: "tvd".into(),
        g: b.g,
        nu: 10,
        threshold: 0.999,
        w: b.w.clone(),
        tolerance: None,
    };
    let rom = ReducedSystem::new(&model, b.phi).unwrap();
    let file = RomFile::new(&model, &rom, info).unwrap();
    let path = tmp("roundtrip");
    file.write(&path).unwrap();
    let back = RomFile::read(&path).unwrap();
    assert_eq!(back, file, "the JSON round trip is exact");
    let r = rom.dim();
    assert_eq!(back.dimension, r);
    assert_eq!(back.joint_operator.len(), 3 * model.joint.pairs());
    assert_eq!(back.master_rows, back.reduced_loads);
    // M̃ = I (M-orthonormal basis).
    for i in 0..r {
        for j in 0..r {
            let id = if i == j { 1.0 } else { 0.0 };
            assert!((back.mass[i][j] - id).abs() < 1e-12);
        }
    }
    let direct = transient::run(rom.clone(), &Scene::of(&model), &common::until(5e-3)).unwrap();
    let again =
        transient::run(back.system().unwrap(), &back.scene(), &common::until(5e-3)).unwrap();
    assert_eq!(direct.curves, again.curves, "identical curves");
    assert_eq!(direct.stats.steps, again.stats.steps);
    assert!(direct.curves.contact_force_norm.last().unwrap() > &0.0);
    let _ = std::fs::remove_file(&path);
}

/// Spoils one field of a good file.
type Damage = dyn Fn(&mut serde_json::Value);

#[test]
fn damaged_files_are_rejected_naming_the_field() {
    let model = common::model("friction_bar");
    let b = build_basis(
        &model,
        BasisKind::Tvd,
        &BasisOptions {
            g: Some(2),
            ..BasisOptions::default()
        },
    )
    .unwrap();
    let info = BasisInfo {
        kind: "tvd".into(),
        g: 2,
        nu: 10,
        threshold: 0.999,
        w: Vec::new(),
        tolerance: None,
    };
    let rom = ReducedSystem::new(&model, b.phi).unwrap();
    let good: serde_json::Value =
        serde_json::to_value(RomFile::new(&model, &rom, info).unwrap()).unwrap();
    let cases: Vec<(&str, Box<Damage>, &str)> = vec![
        (
            "unknown",
            Box::new(|v| v["colour"] = "red".into()),
            "colour",
        ),
        (
            "schema",
            Box::new(|v| v["schema"] = "other".into()),
            "schema",
        ),
        ("version", Box::new(|v| v["version"] = 2.into()), "version"),
        (
            "rows",
            Box::new(|v| {
                v["stiffness"].as_array_mut().unwrap().pop();
            }),
            "stiffness",
        ),
        (
            "cols",
            Box::new(|v| {
                v["joint_operator"][4].as_array_mut().unwrap().pop();
            }),
            "joint_operator[4]",
        ),
        (
            "kn",
            Box::new(|v| v["contact"]["normal_stiffness"] = (-1.0).into()),
            "contact.normal_stiffness",
        ),
        (
            "size",
            Box::new(|v| v["coordinate_size"][0] = 0.0.into()),
            "coordinate_size[0]",
        ),
    ];
    for (name, damage, field) in cases {
        let mut v = good.clone();
        damage(&mut v);
        let path = tmp(name);
        std::fs::write(&path, serde_json::to_string(&v).unwrap()).unwrap();
        let e = RomFile::read(&path).unwrap_err().to_string();
        assert!(
            e.contains(&path.display().to_string()) && e.contains(field),
            "{name}: {e}"
        );
        let _ = std::fs::remove_file(&path);
    }
}

#[test]
fn cli_export_then_transient_from_the_file_matches_the_direct_run() {
    let path = tmp("cli");
    jointrom_ok([
        "export",
        "friction_bar",
        "--g",
        "5",
        "--out",
        path.to_str().unwrap(),
    ]);
    let run = |model: &str| {
        let mut args = vec![
            "transient",
            "friction_bar",
            "--model",
            model,
            "--end-time",
            "3e-3",
            "--json",
        ];
        if model == "tvd" {
            args.extend(["--g", "5"]);
        }
        let v = jointrom_json(args);
        v["curves"].clone()
    };
    let from_file = run(&format!("file:{}", path.display()));
    let direct = run("tvd");
    assert_eq!(from_file, direct);
    let _ = std::fs::remove_file(&path);
}

/// Every field of the file that the run uses changes the run when it changes: a field that is
/// read, checked and then ignored would pass this loop unchanged.
#[test]
fn every_mechanical_field_of_the_file_changes_the_run() {
    let model = common::model("friction_bar");
    let b = build_basis(
        &model,
        BasisKind::Tvd,
        &BasisOptions {
            g: Some(6),
            ..BasisOptions::default()
        },
    )
    .unwrap();
    let info = BasisInfo {
        kind: "tvd".into(),
        g: b.g,
        nu: 10,
        threshold: 0.999,
        w: b.w.clone(),
        tolerance: None,
    };
    let rom = ReducedSystem::new(&model, b.phi).unwrap();
    let file = RomFile::new(&model, &rom, info).unwrap();
    let good = serde_json::to_value(&file).unwrap();
    let opts = common::until(4e-3);
    let curves = |v: &serde_json::Value| {
        let f: RomFile = serde_json::from_value(v.clone()).unwrap();
        let mut o = opts.clone();
        o.problem.tau = f.friction_relaxation_time;
        transient::run(f.system().unwrap(), &f.scene(), &o)
            .unwrap()
            .curves
    };
    let base = curves(&good);
    fn scale(x: &mut serde_json::Value, k: f64) {
        *x = (x.as_f64().unwrap() * k).into();
    }
    let changes: Vec<(&str, Box<Damage>)> = vec![
        (
            "stiffness",
            Box::new(|v| scale(&mut v["stiffness"][0][0], 1.01)),
        ),
        ("mass", Box::new(|v| scale(&mut v["mass"][1][1], 1.01))),
        (
            "joint_operator",
            Box::new(|v| {
                for row in v["joint_operator"].as_array_mut().unwrap() {
                    scale(&mut row[0], 1.05);
                }
            }),
        ),
        (
            "master_rows + reduced_loads",
            Box::new(|v| {
                scale(&mut v["master_rows"][1][0], 1.01);
                scale(&mut v["reduced_loads"][1][0], 1.01);
            }),
        ),
        (
            "master_load",
            Box::new(|v| scale(&mut v["master_load"]["fy"], 1.1)),
        ),
        (
            "contact.normal_stiffness",
            Box::new(|v| scale(&mut v["contact"]["normal_stiffness"], 2.0)),
        ),
        (
            "contact.stick_stiffness",
            Box::new(|v| scale(&mut v["contact"]["stick_stiffness"], 2.0)),
        ),
        (
            "contact.friction_coefficient",
            Box::new(|v| scale(&mut v["contact"]["friction_coefficient"], 0.5)),
        ),
        (
            "friction_relaxation_time",
            Box::new(|v| scale(&mut v["friction_relaxation_time"], 1000.0)),
        ),
        (
            "coordinate_size",
            Box::new(|v| {
                for s in v["coordinate_size"].as_array_mut().unwrap() {
                    scale(s, 100.0);
                }
            }),
        ),
        ("field_dofs", Box::new(|v| v["field_dofs"] = 40.into())),
        ("end_time", Box::new(|v| scale(&mut v["end_time"], 0.5))),
    ];
    for (field, change) in changes {
        let mut v = good.clone();
        change(&mut v);
        let mut o = opts.clone();
        if field == "end_time" {
            o.end_time = None;
        }
        let f: RomFile = serde_json::from_value(v).unwrap();
        o.problem.tau = f.friction_relaxation_time;
        let mut base_o = opts.clone();
        base_o.end_time = o.end_time;
        let reference = if field == "end_time" {
            transient::run(file.system().unwrap(), &file.scene(), &base_o)
                .unwrap()
                .curves
        } else {
            base.clone()
        };
        let got = transient::run(f.system().unwrap(), &f.scene(), &o)
            .unwrap()
            .curves;
        assert_ne!(got, reference, "changing `{field}` must change the run");
    }
}

/// A file run under another CASE is refused, naming the file's model: its output would carry
/// the other case's name.
#[test]
fn a_file_refuses_a_case_it_was_not_exported_from() {
    let path = tmp("source");
    jointrom_ok([
        "export",
        "friction_bar",
        "--g",
        "5",
        "--out",
        path.to_str().unwrap(),
    ]);
    let err = common::jointrom_err([
        "transient",
        "multilayer_sheet",
        "--model",
        &format!("file:{}", path.display()),
        "--end-time",
        "1e-3",
    ]);
    assert!(
        err.contains("exported from `friction_bar`"),
        "the error names the file's model: {err}"
    );
    let ok = jointrom_json([
        "transient",
        "friction_bar",
        "--model",
        &format!("file:{}", path.display()),
        "--end-time",
        "1e-3",
        "--json",
    ]);
    assert_eq!(ok["case"], "friction_bar");
    // The run takes the file's slip relaxation time τ.
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    v["friction_relaxation_time"] = (v["friction_relaxation_time"].as_f64().unwrap() * 1e3).into();
    let slow = tmp("source_tau");
    std::fs::write(&slow, serde_json::to_string(&v).unwrap()).unwrap();
    let other = jointrom_json([
        "transient",
        "friction_bar",
        "--model",
        &format!("file:{}", slow.display()),
        "--end-time",
        "1e-3",
        "--json",
    ]);
    assert_ne!(
        other["curves"], ok["curves"],
        "τ from the file changes the run"
    );
    let _ = std::fs::remove_file(&path);
    let _ = std::fs::remove_file(&slow);
}
