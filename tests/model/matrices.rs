//! Users' own models (`jointrom::model::matrices`): the friction bar exported as MatrixMarket K, M plus
//! the JSON map and read back gives bit-identical matrices, bases, statics and transients; rows
//! in another order with SPC'd rows left in give the same model; the report runs on it; damaged
//! maps and matrices are rejected naming the file and the field.

use std::path::{Path, PathBuf};

use jointrom::integrate as transient;
use jointrom::joint::statics::ContactOptions;
use jointrom::model::contact_static_full;
use jointrom::reduction::{build_basis, BasisKind, BasisOptions};
use jointrom::system::{FullSystem, ReducedSystem, Scene};
use jointrom::Model;
use serde_json::Value;

use crate::common::{self, jointrom_err, jointrom_ok};

fn tmp_dir(name: &str) -> PathBuf {
    common::tmp_dir(&format!("matrices_{name}"))
}

fn exported(name: &str) -> (Model, PathBuf) {
    let model = common::model("friction_bar");
    let dir = tmp_dir(name);
    let files = jointrom::model::matrices::write(&model, &dir).unwrap();
    assert_eq!(files.len(), 3);
    (model, dir)
}

fn load(path: &Path) -> Model {
    common::model(path.to_str().unwrap())
}

fn assert_same_model(a: &Model, b: &Model) {
    assert_eq!(a.name, b.name);
    assert_eq!(a.dofs(), b.dofs());
    assert_eq!(a.master_dofs(), b.master_dofs());
    for (x, y, what) in [(&a.stiffness, &b.stiffness, "K"), (&a.mass, &b.mass, "M")] {
        assert_eq!(x.col_ptr, y.col_ptr, "{what} pattern");
        assert_eq!(x.row_idx, y.row_idx, "{what} pattern");
        let bits = |v: &[f64]| v.iter().map(|f| f.to_bits()).collect::<Vec<_>>();
        assert_eq!(
            bits(&x.values),
            bits(&y.values),
            "{what} values, bit for bit"
        );
    }
    assert_eq!(a.pairs, b.pairs);
    assert_eq!(a.joint.rows(), b.joint.rows());
    for r in 0..a.joint.rows() {
        let ra: Vec<_> = a.joint.row(r).collect();
        let rb: Vec<_> = b.joint.row(r).collect();
        assert_eq!(ra, rb, "joint row {r}");
    }
    assert_eq!(a.load, b.load);
    assert_eq!(a.contact, b.contact);
    assert_eq!(a.end_time, b.end_time);
    assert_eq!(a.geometry.nodes, b.geometry.nodes);
    assert_eq!(a.geometry.cells, b.geometry.cells);
    assert_eq!(a.geometry.followers, b.geometry.followers);
    // Display expansion (clamped zero, followers rigid) is the same for any q.
    let q: Vec<f64> = (0..a.dofs())
        .map(|i| ((i * 37 % 101) as f64) * 1e-3)
        .collect();
    assert_eq!(a.dof_map.expand(&q), b.dof_map.expand(&q));
}

#[test]
fn friction_bar_round_trip_is_identical() {
    let (case, dir) = exported("roundtrip");
    let back = load(&dir.join("model.json"));
    assert!(back.case().is_none(), "read from matrices, not a case");
    assert_same_model(&case, &back);

    // Contact statics of the full model.
    let opts = ContactOptions::default();
    let a = contact_static_full(&case, case.master_load(), &opts).unwrap();
    let b = contact_static_full(&back, back.master_load(), &opts).unwrap();
    assert_eq!(a.master_displacement, b.master_displacement);
    assert_eq!(a.state.contact_force_norm, b.state.contact_force_norm);
    assert!(a.state.pairs_in_contact > 0);

    // The a-priori TVD basis.
    let ba = build_basis(&case, BasisKind::Tvd, &BasisOptions::default()).unwrap();
    let bb = build_basis(&back, BasisKind::Tvd, &BasisOptions::default()).unwrap();
    assert_eq!(ba.g, bb.g);
    assert_eq!(ba.w, bb.w);
    assert_eq!(ba.phi, bb.phi, "basis bit for bit");

    // Reduced transient with friction, 0–0.02 s, and the full model, 0–2 ms.
    let ropts = common::until(0.02);
    let ra = transient::run(
        ReducedSystem::new(&case, ba.phi).unwrap(),
        &Scene::of(&case),
        &ropts,
    )
    .unwrap();
    let rb = transient::run(
        ReducedSystem::new(&back, bb.phi).unwrap(),
        &Scene::of(&back),
        &ropts,
    )
    .unwrap();
    assert_eq!(ra.curves, rb.curves, "ROM curves identical");
    assert_eq!(ra.stats.steps, rb.stats.steps);
    assert!(ra.curves.contact_force_norm.iter().any(|&f| f > 0.0));
    let fopts = common::until(2e-3);
    let fa = transient::run(FullSystem::new(&case).unwrap(), &Scene::of(&case), &fopts).unwrap();
    let fb = transient::run(FullSystem::new(&back).unwrap(), &Scene::of(&back), &fopts).unwrap();
    assert_eq!(fa.curves, fb.curves, "full-model curves identical");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Reads a MatrixMarket file's entries (1-based, as stored) and its size.
fn mtx_entries(path: &Path) -> (usize, Vec<(usize, usize, String)>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines().filter(|l| !l.starts_with('%'));
    let n: usize = lines
        .next()
        .unwrap()
        .split_whitespace()
        .next()
        .unwrap()
        .parse()
        .unwrap();
    let e = lines
        .map(|l| {
            let mut it = l.split_whitespace();
            let i: usize = it.next().unwrap().parse().unwrap();
            let j: usize = it.next().unwrap().parse().unwrap();
            (i, j, it.next().unwrap().to_string())
        })
        .collect();
    (n, e)
}

fn write_mtx(path: &Path, n: usize, entries: &[(usize, usize, String)], kind: &str) {
    let mut s = format!("%%MatrixMarket matrix coordinate real {kind}\n% test\n");
    s += &format!("{n} {n} {}\n", entries.len());
    for (i, j, v) in entries {
        s += &format!("{i} {j} {v}\n");
    }
    std::fs::write(path, s).unwrap();
}

#[test]
fn rows_in_another_order_with_spc_rows_give_the_same_model() {
    // Master rows first, an SPC'd row (coupled to row 1) inserted in the middle: the loader
    // drops it and moves the master last, restoring the original numbering exactly.
    let (case, dir) = exported("permuted");
    let map_text = std::fs::read_to_string(dir.join("model.json")).unwrap();
    let mut map: Value = serde_json::from_str(&map_text).unwrap();
    let n = case.dofs();
    let spc_at = n / 2; // new 1-based position of the SPC'd row
    let new_row = |old: usize| -> usize {
        // old 1-based; master rows n-5..=n → 1..=6; others shifted by 6, and by one more
        // after the SPC'd row.
        let r = if old > n - 6 { old - (n - 6) } else { old + 6 };
        if r >= spc_at {
            r + 1
        } else {
            r
        }
    };
    for (file, diag) in [("K.mtx", "1e9"), ("M.mtx", "1")] {
        let (size, entries) = mtx_entries(&dir.join(file));
        assert_eq!(size, n);
        let mut e: Vec<(usize, usize, String)> = entries
            .into_iter()
            .map(|(i, j, v)| {
                let (a, b) = (new_row(i), new_row(j));
                (a.max(b), a.min(b), v)
            })
            .collect();
        e.push((spc_at, spc_at, diag.to_string()));
        e.push((spc_at, new_row(1).min(spc_at), "-5.5".to_string()));
        write_mtx(&dir.join(format!("P{file}")), n + 1, &e, "symmetric");
    }
    for node in map["nodes"].as_array_mut().unwrap() {
        for r in node["rows"].as_array_mut().unwrap() {
            if let Some(old) = r.as_u64() {
                *r = (new_row(old as usize) as u64).into();
            }
        }
    }
    map["stiffness"] = "PK.mtx".into();
    map["mass"] = "PM.mtx".into();
    map["fixed_rows"] = serde_json::json!([spc_at]);
    let path = dir.join("permuted.json");
    std::fs::write(&path, serde_json::to_string(&map).unwrap()).unwrap();
    let back = load(&path);
    assert_same_model(&case, &back);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn cli_info_and_quick_report_on_a_matrix_model() {
    let dir = tmp_dir("cli");
    let out_arg = dir.to_str().unwrap();
    jointrom_ok([
        "export-matrices",
        "friction_bar",
        "--json",
        "--out",
        out_arg,
    ]);
    let map = dir.join("model.json");
    let map_arg = map.to_str().unwrap();
    let info = |arg: &str| -> Value {
        serde_json::from_slice(&jointrom_ok(["info", "--json", arg])).unwrap()
    };
    let a = info("friction_bar");
    let b = info(map_arg);
    assert_eq!(b["origin"], "matrices");
    assert_eq!(a["origin"], "case");
    for k in [
        "dofs",
        "joint_pairs",
        "joint_dofs",
        "nodes",
        "shells",
        "beams",
        "clamped_nodes",
        "tied_nodes",
        "stiffness_nonzeros",
    ] {
        assert_eq!(a[k], b[k], "info field {k}");
    }
    // The area welds are inside the exported K; the map's display cells do not list them.
    assert_eq!(b["area_welds"], 0);
    assert_eq!(
        a["elements"].as_u64().unwrap(),
        b["elements"].as_u64().unwrap() + a["area_welds"].as_u64().unwrap()
    );

    // The transient displacement field of a ROM run on the matrices, as a VTU series.
    let vtu = dir.join("vtu");
    let vtu_arg = vtu.to_str().unwrap();
    jointrom_ok([
        "transient",
        map_arg,
        "--end-time",
        "0.01",
        "--vtu-frames",
        "5",
        "--vtu",
        vtu_arg,
    ]);
    let pvd = std::fs::read_to_string(vtu.join("u.pvd")).unwrap();
    let frames = pvd.matches("<DataSet").count();
    assert!((5..=7).contains(&frames), "{frames} frames");
    let last = std::fs::read_to_string(vtu.join(format!("u_{:04}.vtu", frames - 1))).unwrap();
    assert!(last.contains(r#"Name="u_u""#));
    let err = jointrom_err(["transient", map_arg, "--vtu-frames", "0", "--vtu", vtu_arg]);
    assert!(err.contains("--vtu-frames"));

    // The main job's quick report on the matrices: same accuracy figures as on the case.
    let report = |arg: &str, sub: &str| -> Value {
        let out_dir = dir.join(sub);
        jointrom_ok([
            "run",
            arg,
            "--quick",
            "--json",
            "--out",
            out_dir.to_str().unwrap(),
        ]);
        let text = std::fs::read_to_string(out_dir.join("friction_bar/results.json")).unwrap();
        assert!(out_dir.join("friction_bar/speed_accuracy.png").is_file());
        serde_json::from_str(&text).unwrap()
    };
    let ra = report("friction_bar", "case");
    let rb = report(map_arg, "matrices");
    assert_eq!(ra["g_chosen"], rb["g_chosen"]);
    let errors = |r: &Value| -> Vec<(Value, Value, Value)> {
        r["runs"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| (x["model"].clone(), x["g"].clone(), x["error_fc"].clone()))
            .collect()
    };
    assert_eq!(errors(&ra), errors(&rb), "identical ‖f_c‖ errors per run");
    assert!(errors(&rb)
        .iter()
        .any(|e| e.2.as_f64().is_some_and(|v| v > 0.0)));
    let _ = std::fs::remove_dir_all(&dir);
}

/// Spoils a good map.
type Damage = dyn Fn(&mut Value, &Path);

fn node_with_rows(map: &Value) -> usize {
    map["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .position(|n| n["rows"][1].is_u64())
        .unwrap()
}

#[test]
fn bad_maps_and_matrices_name_the_file_and_field() {
    let (_, dir) = exported("bad");
    let good: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("model.json")).unwrap()).unwrap();
    // A 7-DOF general matrix with an asymmetric pair, and one with a zero diagonal.
    let tiny = |name: &str, entries: &[(usize, usize, &str)]| {
        let e: Vec<(usize, usize, String)> = entries
            .iter()
            .map(|&(i, j, v)| (i, j, v.to_string()))
            .collect();
        write_mtx(&dir.join(name), 7, &e, "general");
    };
    let diag: Vec<(usize, usize, &str)> = (1..=7).map(|i| (i, i, "1")).collect();
    let mut asym = diag.clone();
    asym.extend([(1, 2, "0.5"), (2, 1, "0.25")]);
    tiny("asym.mtx", &asym);
    tiny("diag7.mtx", &diag);
    tiny("zero.mtx", &diag[..6]);
    std::fs::write(
        dir.join("garbage.mtx"),
        "%%MatrixMarket matrix coordinate real general\n3 3\n",
    )
    .unwrap();
    let cases = damaged_inputs();
    for (name, damage, file, needle) in cases {
        let mut v = good.clone();
        damage(&mut v, &dir);
        let path = dir.join(format!("bad-{name}.json"));
        std::fs::write(&path, serde_json::to_string(&v).unwrap()).unwrap();
        let err = Model::from_case_name(path.to_str().unwrap())
            .err()
            .unwrap_or_else(|| panic!("{name}: accepted"))
            .to_string();
        let shown = if file == "model.json" {
            format!("bad-{name}.json")
        } else {
            file.to_string()
        };
        assert!(
            err.contains(&shown),
            "{name}: error does not name {shown}: {err}"
        );
        assert!(
            err.contains(needle),
            "{name}: error does not name `{needle}`: {err}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Replaces a map's matrices by the tiny 7-DOF files `k`, `m` and its nodes by two matching ones.
fn tiny_map(v: &mut Value, k: &str, m: &str) {
    v["stiffness"] = k.into();
    v["mass"] = m.into();
    v["nodes"] = serde_json::json!([
        {"id": 1, "xyz": [0.0, 0.0, 0.0], "rows": [1, 2, 3, 4, 5, 6]},
        {"id": 2, "xyz": [1.0, 0.0, 0.0], "rows": [7, null, null, null, null, null]}
    ]);
    v["master_node"] = 1.into();
    v["rigid_followers"] = serde_json::json!([]);
}

/// The damaged maps and matrices: (name, damage, file named in the error, field or reason in it).
fn damaged_inputs() -> Vec<(&'static str, Box<Damage>, &'static str, &'static str)> {
    vec![
        (
            "unknown",
            Box::new(|v, _| v["colour"] = "red".into()),
            "model.json",
            "colour",
        ),
        (
            "schema",
            Box::new(|v, _| v["version"] = 2.into()),
            "model.json",
            "version",
        ),
        (
            "kn",
            Box::new(|v, _| v["contact"]["normal_stiffness"] = (-1.0).into()),
            "model.json",
            "contact.normal_stiffness",
        ),
        (
            "row-range",
            Box::new(|v, _| {
                let i = node_with_rows(v);
                v["nodes"][i]["rows"][1] = 99_999_999.into();
            }),
            "model.json",
            "rows[1]",
        ),
        (
            "row-twice",
            Box::new(|v, _| {
                let i = node_with_rows(v);
                let r = v["nodes"][i]["rows"][0].clone();
                v["nodes"][i]["rows"][1] = r;
            }),
            "model.json",
            "rows[1]",
        ),
        (
            "node-id-twice",
            Box::new(|v, _| {
                let id = v["nodes"][0]["id"].clone();
                v["nodes"][1]["id"] = id;
            }),
            "model.json",
            "nodes[1].id",
        ),
        (
            "master-unknown",
            Box::new(|v, _| v["master_node"] = 0.into()),
            "model.json",
            "master_node",
        ),
        (
            "master-row",
            Box::new(|v, _| {
                let m = v["master_node"].clone();
                let nodes = v["nodes"].as_array_mut().unwrap();
                let node = nodes.iter_mut().find(|n| n["id"] == m).unwrap();
                node["rows"][5] = Value::Null;
            }),
            "model.json",
            "master_node",
        ),
        (
            "pair-node",
            Box::new(|v, _| v["pairs"][3]["lower"] = 0.into()),
            "model.json",
            "pairs[3].lower",
        ),
        (
            "pair-unit",
            Box::new(|v, _| v["pairs"][0]["normal"] = serde_json::json!([0.0, 2.0, 0.0])),
            "model.json",
            "pairs[0].normal",
        ),
        (
            "pair-orthogonal",
            Box::new(|v, _| v["pairs"][0]["t1"] = serde_json::json!([0.0, 1.0, 0.0])),
            "model.json",
            "pairs[0].t1",
        ),
        (
            "pair-frame-missing",
            Box::new(|v, _| {
                v["pairs"][0].as_object_mut().unwrap().remove("normal");
            }),
            "model.json",
            "pairs[0].normal",
        ),
        (
            "pair-no-row",
            Box::new(|v, _| {
                let lower = v["pairs"][0]["lower"].clone();
                let nodes = v["nodes"].as_array_mut().unwrap();
                let node = nodes.iter_mut().find(|n| n["id"] == lower).unwrap();
                node["rows"][1] = Value::Null;
            }),
            "model.json",
            "pairs[0].lower",
        ),
        (
            "cell",
            Box::new(|v, _| v["cells"][0]["nodes"] = serde_json::json!([1, 2, 3])),
            "model.json",
            "cells[0].nodes",
        ),
        (
            "missing-file",
            Box::new(|v, _| v["stiffness"] = "nope.mtx".into()),
            "nope.mtx",
            "cannot read",
        ),
        (
            "garbage",
            Box::new(|v, _| v["mass"] = "garbage.mtx".into()),
            "garbage.mtx",
            "MatrixMarket",
        ),
        (
            "size-mismatch",
            Box::new(|v, _| v["mass"] = "diag7.mtx".into()),
            "model.json",
            "mass",
        ),
        (
            "asymmetric",
            Box::new(|v, _| tiny_map(v, "asym.mtx", "diag7.mtx")),
            "asym.mtx",
            "entry (",
        ),
        (
            "zero-diagonal",
            Box::new(|v, _| tiny_map(v, "zero.mtx", "diag7.mtx")),
            "zero.mtx",
            "every row needs at least its diagonal",
        ),
    ]
}
