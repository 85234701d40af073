//! Whole-model tests on the two paper scenes: DOF counts, constraint elimination, rigid-body
//! modes of the free structure, eigen-solver agreement, statics, and the CLI's JSON contract.

use faer::Side;
use jointrom::assembly::assemble_structure;
use jointrom::case::Case;
use jointrom::linalg::eigen::dense_modes;
use jointrom::mesh::Mesh;
use jointrom::Interface;

use crate::common::{self, jointrom_err, jointrom_json};

#[test]
fn paper_dof_counts() {
    let fb = common::model("friction_bar");
    assert_eq!(fb.dofs(), 906);
    // The paper's 648 joint DOF and 54 pairs less the pairs inside the area welds' nuggets
    // (one per weld and interface: the node pairs at the weld centres), which are welded.
    assert_eq!(fb.joint_dofs(), 624);
    assert_eq!(fb.pair_count(), 52);
    let ml = common::model("multilayer_sheet");
    assert_eq!(ml.dofs(), 834);
    assert_eq!(ml.joint_dofs(), 774);
    assert_eq!(ml.pair_count(), 86);
}

#[test]
fn free_structure_has_exactly_six_rigid_body_modes() {
    for name in Case::BUILTIN {
        let case = Case::load(name).unwrap();
        let mut mesh = Mesh::from_case(&case).unwrap();
        mesh.clamped.clear();
        let s = assemble_structure(&mesh).unwrap();
        let k = s.stiffness.to_dense();
        let eig = k.self_adjoint_eigenvalues(Side::Lower).unwrap();
        let largest = eig[eig.len() - 1];
        let zero = eig.iter().filter(|&&l| l.abs() <= 1e-10 * largest).count();
        assert_eq!(zero, 6, "{name}: smallest eigenvalues {:?}", &eig[..8]);
        assert!(eig[6] > 1e-10 * largest, "{name}: {:?}", &eig[..8]);
    }
}

#[test]
fn clamp_and_rigid_tie_are_exact() {
    let model = common::model("friction_bar");
    let load = model.master_load();
    let sol = model.static_linear(&[load]).unwrap().remove(0);
    let u = model.dof_map.expand(&sol.displacement);
    for &c in &model.mesh().unwrap().clamped {
        assert!(u[6 * c..6 * c + 6].iter().all(|&v| v == 0.0));
    }
    let m = model.mesh().unwrap().tie.master;
    let xm = model.mesh().unwrap().nodes[m];
    let (um, th) = (&u[6 * m..6 * m + 3], &u[6 * m + 3..6 * m + 6]);
    for &s in &model.mesh().unwrap().tie.slaves {
        let r: Vec<f64> = (0..3)
            .map(|k| model.mesh().unwrap().nodes[s][k] - xm[k])
            .collect();
        let rigid = [
            um[0] + th[1] * r[2] - th[2] * r[1],
            um[1] + th[2] * r[0] - th[0] * r[2],
            um[2] + th[0] * r[1] - th[1] * r[0],
        ];
        for k in 0..3 {
            assert!((u[6 * s + k] - rigid[k]).abs() <= 1e-12 * um[1].abs());
            assert_eq!(u[6 * s + 3 + k], th[k]);
        }
    }
    // Equilibrium: the work of the load equals the strain energy (Clapeyron), 2U = fᵀu.
    let mut ku = vec![0.0; model.dofs()];
    model.stiffness.mul_vec(&sol.displacement, &mut ku);
    let two_u: f64 = ku.iter().zip(&sol.displacement).map(|(a, b)| a * b).sum();
    let work: f64 = (0..6).map(|k| load[k] * sol.master_displacement[k]).sum();
    assert!(
        (two_u - work).abs() <= 1e-6 * work.abs(),
        "2U = {two_u}, work = {work}"
    );
    // The load pushes the tip down and twists it negatively about x.
    assert!(sol.master_displacement[1] < 0.0 && sol.master_displacement[3] < 0.0);
}

#[test]
fn lanczos_and_dense_agree_on_both_scenes_and_interfaces() {
    for name in Case::BUILTIN {
        let model = common::model(name);
        for iface in [Interface::Fixed, Interface::Free] {
            let lanczos = model.modes(20, iface).unwrap();
            let (k, m) = match iface {
                Interface::Free => (model.stiffness.clone(), model.mass.clone()),
                Interface::Fixed => {
                    let n = model.dofs() - 6;
                    (model.stiffness.leading(n), model.mass.leading(n))
                }
            };
            let dense = dense_modes(&k, &m, 20).unwrap();
            for i in 0..20 {
                let (a, b) = (lanczos.frequencies_hz[i], dense.frequencies_hz[i]);
                assert!(
                    (a - b).abs() <= 1e-7 * b,
                    "{name} {iface:?} mode {i}: {a} vs {b}"
                );
            }
            // Φᵀ M Φ = I.
            let n = k.n;
            let mut mphi = vec![0.0; n];
            for i in 0..20 {
                m.mul_vec(lanczos.shapes.col_as_slice(i), &mut mphi);
                for j in 0..20 {
                    let v: f64 = lanczos
                        .shapes
                        .col_as_slice(j)
                        .iter()
                        .zip(&mphi)
                        .map(|(x, y)| x * y)
                        .sum();
                    let e = if i == j { 1.0 } else { 0.0 };
                    assert!((v - e).abs() < 1e-8, "{name}: phi_{j}' M phi_{i} = {v}");
                }
            }
            // Fixed-interface frequencies lie above the free ones (interlacing, Rayleigh).
            if iface == Interface::Fixed {
                let free = model.modes(20, Interface::Free).unwrap();
                for i in 0..20 {
                    assert!(lanczos.frequencies_hz[i] >= free.frequencies_hz[i] * (1.0 - 1e-9));
                }
            }
        }
    }
}

#[test]
fn too_many_modes_is_an_error_not_a_panic() {
    let model = common::model("multilayer_sheet");
    let err = model.modes(5000, Interface::Fixed).unwrap_err();
    assert!(err.to_string().contains("5000"), "{err}");
    assert!(model.modes(0, Interface::Free).is_err());
}

/// With contact points inside the faces `info` counts the points, and says they are points:
/// 2 × 2 per joint face of the friction bar (34 faces).
#[test]
fn info_counts_contact_points() {
    let v = jointrom_json([
        "info",
        "friction_bar",
        "--contact-per-area",
        "160,160",
        "--contact-sampling",
        "2",
        "--json",
    ]);
    assert_eq!(v["contact_points"], v["joint_pairs"]);
    assert_eq!(v["contact_points"], 136);
}

#[test]
fn cli_json_contract() {
    let v = jointrom_json(["info", "friction_bar", "--json"]);
    assert_eq!(v["dofs"], 906);
    assert_eq!(v["joint_pairs"], 52);
    assert!(
        v["contact_points"].is_null(),
        "node pairs: {}",
        v["contact_points"]
    );
    assert_eq!(v["joint_dofs"], 624);
    assert_eq!(v["nodes"], 157);
    assert_eq!(v["elements"], 102);
    assert_eq!(v["area_welds"], 2);
    assert_eq!(v["beams"], 0);

    let v = jointrom_json([
        "modes",
        "multilayer_sheet",
        "--count",
        "5",
        "--interface",
        "free",
        "--json",
    ]);
    let f = v["frequencies_hz"].as_array().unwrap();
    assert_eq!(f.len(), 5);
    assert!(f.windows(2).all(|w| w[0].as_f64() <= w[1].as_f64()));

    let v = jointrom_json(["static", "friction_bar", "--linear", "--json"]);
    let u = v["master_displacement"].as_array().unwrap();
    assert_eq!(u.len(), 6);
    let v2 = jointrom_json([
        "static",
        "friction_bar",
        "--linear",
        "--scale",
        "-2",
        "--json",
    ]);
    let uy = u[1].as_f64().unwrap();
    let uy2 = v2["master_displacement"][1].as_f64().unwrap();
    assert!((uy2 + 2.0 * uy).abs() <= 1e-9 * uy.abs(), "{uy} {uy2}");

    // With contact (the default): the joint stiffens the bar, some but not all pairs close.
    let v3 = jointrom_json(["static", "friction_bar", "--json"]);
    assert!(v3["contact_force_norm"].as_f64().unwrap() > 0.0);
    let n = v3["pairs_in_contact"].as_u64().unwrap();
    assert!(n > 0 && n < 52, "{n}");
    let uy3 = v3["master_displacement"][1].as_f64().unwrap();
    assert!(
        uy3 < 0.0 && uy3.abs() < uy.abs(),
        "contact must stiffen: {uy3} vs {uy}"
    );
}

#[test]
fn cli_errors_name_the_problem() {
    let err = jointrom_err(["info", "no_such_case"]);
    assert!(err.contains("no_such_case"), "{err}");
    let err = jointrom_err(["static", "friction_bar", "--scale", "nan"]);
    assert!(err.contains("--scale"), "{err}");
    let dir = common::tmp_dir("model_cli_errors");
    let bad = dir.join("bad.json");
    std::fs::write(&bad, "{\"name\": 3}").unwrap();
    let err = jointrom_err(["info", bad.to_str().unwrap()]);
    assert!(err.contains("bad.json"), "{err}");
}

#[test]
fn factorization_errors_keep_faer_as_the_source() {
    use std::error::Error as _;
    // diag(1, −1): not positive definite.
    let a = jointrom::linalg::SymCsc {
        n: 2,
        col_ptr: vec![0, 1, 2],
        row_idx: vec![0, 1],
        values: vec![1.0, -1.0],
    };
    let err = match jointrom::linalg::SparseCholesky::new(&a) {
        Err(e) => jointrom::Error::from(e),
        Ok(_) => panic!("an indefinite matrix was factored"),
    };
    assert!(matches!(err, jointrom::Error::LinearAlgebra(_)), "{err}");
    assert!(err.to_string().contains("not positive definite"), "{err}");
    let source = err.source().expect("the linear-algebra error");
    assert!(
        source.source().is_some(),
        "faer's error as the source of {source}"
    );
}
