//! Contact stiffness per area (`jointrom::model::per_area`, `jointrom::mesh::tributary`): the
//! tributary areas cover the joints, a uniform penetration gives the same pressure and
//! resultant on every mesh, and the weighted pair rows make the statics those of the springs
//! `κ·A_i`.

use jointrom::case::Case;
use jointrom::joint::statics::ContactOptions;
use jointrom::mesh::tributary::{corner_areas, tributary_areas};
use jointrom::model::contact_static_full;
use jointrom::model::per_area::joints_overlap;
use jointrom::Model;

use crate::common::{self, repo_path};

const KAPPA: f64 = 160.0;

fn per_area(mut case: Case) -> Case {
    case.contact.normal_stiffness = f64::NAN;
    case.contact.stick_stiffness = f64::NAN;
    case.contact.normal_stiffness_per_area = Some(KAPPA);
    case.contact.stick_stiffness_per_area = Some(KAPPA);
    case
}

fn scale_case(name: &str) -> Case {
    let path = repo_path(&format!("cases/scale/{name}.json"));
    Case::from_file(&path).unwrap()
}

/// Σ A_i + the shares of the pairs welds and supports take out = the joints' overlap, on the
/// built-in scenes and their refinements.
#[test]
fn tributary_areas_sum_to_the_overlap() {
    let cases = [
        common::builtin_case("friction_bar"),
        common::builtin_case("multilayer_sheet"),
        scale_case("friction_bar_x2"),
        scale_case("multilayer_sheet_x2"),
    ];
    for case in cases {
        let overlap = joints_overlap(&case);
        let model = Model::from_case(case).unwrap();
        let mesh = model.mesh().unwrap();
        let held: Vec<usize> = mesh
            .clamped
            .iter()
            .chain(&mesh.tie.slaves)
            .copied()
            .collect();
        let t = tributary_areas(
            &mesh.nodes,
            &mesh.shells,
            &mesh.pairs,
            &mesh.excluded,
            &held,
        )
        .unwrap();
        let sum: f64 = t.areas.iter().sum();
        assert!(
            (sum + t.excluded - overlap).abs() <= 1e-9 * overlap,
            "{}: Σ A_i {sum} + excluded {} vs overlap {overlap} mm²",
            model.name,
            t.excluded
        );
        assert!((t.total - overlap).abs() <= 1e-9 * overlap);
        assert!(t.areas.iter().all(|&a| a > 0.0));
        assert_eq!(model.pair_areas.as_deref(), Some(&t.areas[..]));
    }
}

/// `∫ N_a dA` of a face: a quarter of a rectangle each, and on a distorted face the corners'
/// shares add up to its area (shoelace) and follow the shape.
#[test]
fn corner_areas_are_the_shape_function_integrals() {
    let rect = corner_areas([
        [0.0, 0.0, 0.0],
        [5.0, 0.0, 0.0],
        [5.0, 0.0, 12.5],
        [0.0, 0.0, 12.5],
    ]);
    for a in rect {
        assert!((a - 62.5 / 4.0).abs() < 1e-12, "{rect:?}");
    }
    // A trapezoid in the x–z plane: area ½(4 + 2)·3 = 9 mm²; the long side's corners get more.
    let x = [
        [0.0, 0.0, 0.0],
        [4.0, 0.0, 0.0],
        [3.0, 0.0, 3.0],
        [1.0, 0.0, 3.0],
    ];
    let a = corner_areas(x);
    let sum: f64 = a.iter().sum();
    assert!((sum - 9.0).abs() < 1e-12, "{a:?}");
    assert!(a[0] > a[3] && a[1] > a[2], "{a:?}");
    // By hand: J = 3(3 − η)/4, ∫N_0 J = 2.5 mm², ∫N_3 J = 2 mm² (2×2 Gauss is exact here).
    assert!(
        (a[0] - 2.5).abs() < 1e-12 && (a[3] - 2.0).abs() < 1e-12,
        "{a:?}"
    );
}

/// A uniform penetration δ of the upper sheet gives the pressure κ·δ at every pair and the
/// resultant κ·δ·A_joint on every mesh (the friction bar without welds, ×1, ×2, ×4).
#[test]
fn uniform_penetration_gives_mesh_independent_pressure() {
    let delta = 1e-3;
    for name in ["friction_bar_x2", "friction_bar_x4"] {
        for case in [common::builtin_case("friction_bar"), scale_case(name)] {
            let mut case = per_area(case);
            case.welds.clear();
            let overlap = joints_overlap(&case);
            let model = Model::from_case(case).unwrap();
            let mut q = vec![0.0; model.dofs()];
            for p in &model.pairs {
                let dep = &model.dof_map.nodes[p.upper][1];
                let i = dep.as_free().expect("a free node");
                q[i] = -delta;
            }
            let mut gaps = vec![0.0; model.pair_count()];
            model.joint.gaps(&q, &mut gaps);
            let forces: Vec<f64> = gaps
                .iter()
                .map(|g| model.contact.normal_stiffness * g.min(0.0))
                .collect();
            let m = model.contact_measures(&forces, &gaps);
            let expect = KAPPA * delta * overlap;
            assert!(
                (m.contact_resultant - expect).abs() <= 1e-12 * expect,
                "{}: resultant {} vs {expect} N",
                model.name,
                m.contact_resultant
            );
            let pressure = KAPPA * delta;
            for (i, (&p, a)) in forces
                .iter()
                .zip(model.pair_areas.as_ref().unwrap())
                .enumerate()
            {
                let pi = (model.pair_weight(i) * p).abs() / a;
                assert!((pi - pressure).abs() <= 1e-12 * pressure, "pair {i}: {pi}");
            }
            assert!((m.contact_area.unwrap() - overlap).abs() <= 1e-9 * overlap);
            assert!((m.max_penetration.unwrap() - delta).abs() <= 1e-15);
        }
    }
}

/// The per-area contact statics are in equilibrium with the springs `κ·A_i` on the physical
/// (unweighted) gaps: `K u + Σ_i κ A_i min(g_i, 0) b_iᵀ = f`, with `b_i` the per-pair model's
/// rows.
#[test]
fn weighted_rows_are_the_springs_kappa_area() {
    for name in ["friction_bar", "multilayer_sheet"] {
        let plain = common::model(name);
        let model = Model::from_case(per_area(common::builtin_case(name))).unwrap();
        let load = model.master_load();
        let sol = contact_static_full(&model, load, &ContactOptions::default()).unwrap();
        let u = &sol.displacement;
        let mut r = vec![0.0; model.dofs()];
        model.stiffness.mul_vec(u, &mut r);
        let master = model.master_dofs();
        for k in 0..6 {
            r[master[k]] -= load[k];
        }
        let mut kin = vec![0.0; plain.joint.rows()];
        plain.joint.apply(u, &mut kin);
        let areas = model.pair_areas.as_ref().unwrap();
        let mut p = vec![0.0; plain.joint.rows()];
        let mut closed = 0;
        for (i, a) in areas.iter().enumerate() {
            p[3 * i] = KAPPA * a * kin[3 * i].min(0.0);
            closed += usize::from(kin[3 * i] < 0.0);
        }
        assert!(closed > 0, "{name}: no pair closed");
        plain.joint.apply_transpose_add(&p, &mut r);
        let scale = load.iter().map(|v| v.abs()).fold(0.0, f64::max);
        let res = r.iter().map(|v| v.abs()).fold(0.0, f64::max);
        assert!(res <= 1e-8 * scale, "{name}: residual {res:e} of {scale}");
    }
}

/// `--contact-per-area` on a deck takes the CQUAD4 faces at the CGAPs' nodes: the same areas
/// (by the pair's position) as the case file of the same mesh.
#[test]
fn deck_areas_equal_the_case_areas() {
    for name in ["friction_bar", "multilayer_sheet"] {
        let path = repo_path(&format!("cases/nastran/{name}.bdf"));
        let opts = jointrom::model::LoadOptions {
            contact_per_area: Some([KAPPA, KAPPA]),
            ..Default::default()
        };
        let deck = Model::from_case_name_with(path.to_str().unwrap(), &opts).unwrap();
        let case = Model::from_case(per_area(common::builtin_case(name))).unwrap();
        let key = |m: &Model| {
            let mut v: Vec<([i64; 3], f64)> = m
                .pairs
                .iter()
                .zip(m.pair_areas.as_ref().unwrap())
                .map(|(p, &a)| {
                    (
                        m.geometry.nodes[p.lower].map(|x| (x * 1e6).round() as i64),
                        a,
                    )
                })
                .collect();
            v.sort_by_key(|a| a.0);
            v
        };
        let (d, c) = (key(&deck), key(&case));
        assert_eq!(d.len(), c.len(), "{name}");
        for (a, b) in d.iter().zip(&c) {
            assert_eq!(a.0, b.0, "{name}");
            assert!(
                (a.1 - b.1).abs() <= 1e-9 * b.1,
                "{name} at {:?}: {} vs {}",
                a.0,
                a.1,
                b.1
            );
        }
        assert_eq!(deck.contact.normal_stiffness_per_area, Some(KAPPA));
        let rel = (deck.contact.normal_stiffness - case.contact.normal_stiffness).abs()
            / case.contact.normal_stiffness;
        assert!(rel < 1e-9, "{name}: k_n {rel:e}");
    }
}

/// The per-area value that gives the paper's mesh's largest pairs (interior pairs of the
/// friction bar, Δx Δz; the multilayer sheet's one element across has all its pairs on an edge,
/// Δx Δz / 2) the paper's k_n = 1e4 N/mm: κ = k_n / A.
#[test]
fn paper_equivalent_kappa() {
    for (name, cell) in [
        ("friction_bar", 5.0 * 12.5),
        ("multilayer_sheet", 5.625 * 25.0 / 2.0),
    ] {
        let mut case = common::builtin_case(name);
        let k = case.contact.normal_stiffness;
        case = per_area(case);
        case.contact.normal_stiffness_per_area = Some(k / cell);
        let model = Model::from_case(case).unwrap();
        let areas = model.pair_areas.as_ref().unwrap();
        let interior = areas.iter().fold(0.0f64, |m, &a| m.max(a));
        assert!((interior - cell).abs() < 1e-9 * cell, "{name}: {interior}");
        let i = areas.iter().position(|&a| a == interior).unwrap();
        let w = model.pair_weight(i);
        let k_i = model.contact.normal_stiffness * w * w;
        assert!((k_i - k).abs() < 1e-9 * k, "{name}: {k_i}");
    }
}
