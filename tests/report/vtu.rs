//! VTU output: counts and structure of the XML, the displacement written for a known vector
//! (including rigid RBE2 slaves and clamped zeros), the series collection, and the shapes
//! command's files.

use std::path::PathBuf;

use faer::Mat;
use jointrom::report::vtu;

use crate::common::{self, jointrom_ok};

fn tmp(name: &str) -> PathBuf {
    common::tmp_path(&format!("vtu_{name}"))
}

/// The numbers of the point array `name` (3 per node).
fn array(doc: &str, name: &str) -> Vec<f64> {
    let key = format!("Name=\"{name}\"");
    let start = doc.find(&key).unwrap_or_else(|| panic!("no array {name}"));
    let body = &doc[start..];
    let open = body.find('>').unwrap() + 1;
    let close = body.find("</DataArray>").unwrap();
    body[open..close]
        .split_whitespace()
        .map(|t| t.parse().unwrap())
        .collect()
}

#[test]
fn a_shape_is_written_with_its_expansion_and_the_mesh() {
    let model = common::model("friction_bar");
    let n = model.dofs();
    // The master's uy = 1 (all other DOF zero): a rigid motion of the tied end.
    let master = model.master_dofs();
    let mut q = Mat::<f64>::zeros(n, 2);
    q[(master[1], 0)] = 1.0;
    q[(master[3], 1)] = 0.01; // rotation about x
    let path = tmp("shape.vtu");
    vtu::write_shapes(&model, "test", q.as_ref(), &path).unwrap();
    let doc = std::fs::read_to_string(&path).unwrap();
    let nodes = model.mesh().unwrap().nodes.len();
    let cells = model.mesh().unwrap().shells.len() + model.mesh().unwrap().beams.len();
    assert!(doc.contains(&format!(
        "NumberOfPoints=\"{nodes}\" NumberOfCells=\"{cells}\""
    )));
    assert_eq!(
        doc.matches("<DataArray").count(),
        doc.matches("</DataArray>").count()
    );
    let offsets = array(&doc, "offsets");
    assert_eq!(offsets.len(), cells);
    assert_eq!(
        *offsets.last().unwrap() as usize,
        4 * model.mesh().unwrap().shells.len() + 2 * model.mesh().unwrap().beams.len()
    );
    let u = array(&doc, "test_01_u");
    assert_eq!(u.len(), 3 * nodes);
    // Tied nodes move rigidly with the master: uy = 1, ux = uz = 0; clamped nodes stay at rest.
    for &s in &model.mesh().unwrap().tie.slaves {
        assert!((u[3 * s + 1] - 1.0).abs() < 1e-12 && u[3 * s].abs() < 1e-12);
    }
    for &c in &model.mesh().unwrap().clamped {
        assert!(u[3 * c..3 * c + 3].iter().all(|v| *v == 0.0));
    }
    // A rotation θx of the master: slaves follow u = θ × (x_s − x_m), a rigid motion, so the
    // relative displacement of any two slaves is perpendicular to their distance.
    let u2 = array(&doc, "test_02_u");
    let r2 = array(&doc, "test_02_rot");
    let slaves = &model.mesh().unwrap().tie.slaves;
    for &s in slaves {
        assert!(
            (r2[3 * s] - 0.01).abs() < 1e-14,
            "slave rotation follows the master"
        );
    }
    for w in slaves.windows(2) {
        let (a, b) = (w[0], w[1]);
        let xa = model.mesh().unwrap().nodes[a];
        let xb = model.mesh().unwrap().nodes[b];
        let d: Vec<f64> = (0..3).map(|k| xb[k] - xa[k]).collect();
        let du: Vec<f64> = (0..3).map(|k| u2[3 * b + k] - u2[3 * a + k]).collect();
        let stretch: f64 = d.iter().zip(&du).map(|(x, y)| x * y).sum();
        assert!(
            stretch.abs() < 1e-12,
            "rigid: relative motion ⟂ the distance"
        );
    }
    let _ = std::fs::remove_file(&path);

    // Bad input is an error, not a file.
    let bad = Mat::<f64>::zeros(n + 1, 1);
    assert!(vtu::write_shapes(&model, "x", bad.as_ref(), &path).is_err());
    assert!(vtu::write_shapes(&model, "bad name", q.as_ref(), &path).is_err());
}

#[test]
fn a_series_has_one_file_per_time_and_a_collection() {
    let model = common::model("friction_bar");
    let n = model.dofs();
    let dir = tmp("series");
    let states = vec![vec![0.0; n], vec![1e-3; n]];
    let pvd = vtu::write_series(&model, "u", &[0.0, 1e-4], &states, &dir).unwrap();
    let text = std::fs::read_to_string(&pvd).unwrap();
    assert_eq!(text.matches("<DataSet").count(), 2);
    assert!(dir.join("u_0001.vtu").is_file());
    assert!(vtu::write_series(&model, "u", &[0.0], &states, &dir).is_err());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn shapes_command_writes_vtu_and_the_joint_mode_picture() {
    let dir = tmp("cli");
    jointrom_ok([
        "shapes",
        "friction_bar",
        "--count",
        "4",
        "--out",
        dir.to_str().unwrap(),
    ]);
    for f in [
        "craig_bampton.vtu",
        "tvd.vtu",
        "joint_modes.vtu",
        "joint_modes.png",
        "joint_modes.svg",
    ] {
        let p = dir.join("friction_bar").join(f);
        assert!(
            std::fs::metadata(&p)
                .map(|m| m.len() > 1000)
                .unwrap_or(false),
            "{f}"
        );
    }
    let doc = std::fs::read_to_string(dir.join("friction_bar/joint_modes.vtu")).unwrap();
    assert_eq!(
        doc.matches("Name=\"joint_mode_0").count(),
        8,
        "4 modes × (u, rot)"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
