//! The two built-in cases (Witteveen & Pichler 2014, Sections 4.1 and 4.2): they load, and their
//! meshes have the counts, coordinates, numbering and joint pairs the paper's models have.

use std::collections::BTreeSet;

use jointrom::case::Case;
use jointrom::mesh::{Material, Mesh};

use crate::common;

fn builtin(name: &str) -> (Case, Mesh) {
    let case = common::builtin_case(name);
    let mesh = Mesh::from_case(&case).expect("built-in mesh");
    (case, mesh)
}

/// DOF left after eliminating the clamped nodes and the tie slaves (6 per node).
fn independent_dofs(mesh: &Mesh) -> usize {
    6 * (mesh.nodes.len() - mesh.clamped.len() - mesh.tie.slaves.len())
}

/// Distinct nodes that are in some joint pair.
fn pair_nodes(mesh: &Mesh) -> BTreeSet<usize> {
    mesh.pairs.iter().flat_map(|p| [p.lower, p.upper]).collect()
}

fn assert_node(mesh: &Mesh, index: usize, expected: [f64; 3]) {
    let got = mesh.nodes[index];
    for a in 0..3 {
        assert!(
            (got[a] - expected[a]).abs() < 1e-9,
            "node {index}: got {got:?}, expected {expected:?}"
        );
    }
}

#[test]
fn every_builtin_loads_and_unknown_names_are_none() {
    for name in Case::BUILTIN {
        let (case, _) = builtin(name);
        assert_eq!(case.name, *name);
        assert_eq!(case.source, format!("builtin:{name}"));
    }
    assert!(Case::builtin("no_such_case").is_none());
}

#[test]
fn friction_bar_counts_match_the_paper() {
    let (_, mesh) = builtin("friction_bar");
    assert_eq!(mesh.nodes.len(), 156 + 1);
    assert_eq!(mesh.shells.len(), 100);
    assert_eq!(mesh.beams.len(), 0);
    assert_eq!(mesh.welds.len(), 2);
    assert_eq!(mesh.clamped.len(), 3);
    assert_eq!(mesh.tie.slaves.len(), 3);
    // The paper's 54 pairs less the two inside the nuggets (welded, not in contact).
    assert_eq!(mesh.pairs.len(), 52);
    assert_eq!(independent_dofs(&mesh), 906);
    let joint = pair_nodes(&mesh);
    assert_eq!(joint.len(), 104);
    assert_eq!(6 * joint.len(), 624);
}

#[test]
fn friction_bar_numbering_and_coordinates() {
    let (case, mesh) = builtin("friction_bar");
    assert_eq!(mesh.sheets.len(), 2);
    assert_eq!(mesh.sheets[0].name, "A");
    assert_eq!(mesh.sheets[0].first_node, 0);
    assert_eq!(mesh.sheets[0].elements, [25, 2]);
    assert_eq!(mesh.sheets[1].name, "B");
    assert_eq!(mesh.sheets[1].first_node, 78);
    // Node (i, k) of a sheet is first_node + i·(nz + 1) + k.
    assert_node(&mesh, 0, [0.0, 0.0, 0.0]);
    assert_node(&mesh, 1, [0.0, 0.0, 12.5]);
    assert_node(&mesh, 3, [5.0, 0.0, 0.0]);
    assert_node(&mesh, 77, [125.0, 0.0, 25.0]);
    assert_node(&mesh, 78, [40.0, 0.5, 0.0]);
    assert_node(&mesh, 91, [60.0, 0.5, 12.5]);
    assert_node(&mesh, 155, [165.0, 0.5, 25.0]);
    assert_node(&mesh, 156, [165.0, 0.5, 12.5]);
    assert_eq!(mesh.tie.master, 156);
    assert_eq!(mesh.clamped, vec![0, 1, 2]);
    assert_eq!(mesh.tie.slaves, vec![153, 154, 155]);
    // Area welds at (60, 12.5) and (105, 12.5) through A and B: full nuggets (the sampling
    // weights sum to the disc's area); the node pairs at their centres, A (12, 1) – B (4, 1) and
    // A (21, 1) – B (13, 1), are welded and not joint pairs.
    let centres: Vec<[f64; 2]> = mesh.welds.iter().map(|w| w.centre).collect();
    assert_eq!(centres, vec![[60.0, 12.5], [105.0, 12.5]]);
    for w in &mesh.welds {
        assert_eq!(w.diameter, 5.0);
        let sheets: Vec<usize> = w.layers.iter().map(|l| l.sheet).collect();
        assert_eq!(sheets, vec![0, 1]);
        for l in &w.layers {
            let area: f64 = l.points.iter().map(|p| p.weight).sum();
            assert!((area - std::f64::consts::PI * 6.25).abs() < 1e-9, "{area}");
        }
    }
    for (l, u) in [(37, 91), (64, 118)] {
        assert!(!mesh.pairs.iter().any(|p| p.lower == l || p.upper == u));
    }
    // The first shell of A, counter-clockwise in (x, z).
    assert_eq!(mesh.shells[0].nodes, [0, 3, 4, 1]);
    assert_eq!(mesh.shells[0].thickness, 0.5);
    assert_eq!(mesh.shells[0].sheet, 0);
    assert_eq!(mesh.shells[50].sheet, 1);
    assert_eq!(mesh.shells[50].nodes, [78, 81, 82, 79]);
    // The first pair of the joint: A (8, 0) under B (0, 0), both at (x, z) = (40, 0).
    assert_eq!((mesh.pairs[0].lower, mesh.pairs[0].upper), (24, 78));
    assert_eq!(
        mesh.material,
        Material {
            youngs_modulus: case.material.youngs_modulus,
            poisson_ratio: case.material.poisson_ratio,
            density: case.material.density,
        }
    );
    assert_eq!(mesh.material, jointrom::element::Material::STEEL);
}

#[test]
fn friction_bar_load_and_ramp() {
    let (case, _) = builtin("friction_bar");
    assert_eq!(case.master_load(), [0.0, -0.7, 0.0, -20.0, 0.0, 0.0]);
    assert_eq!(case.end_time, 0.2);
    let ramp = case.load.ramp.clone();
    assert_eq!(ramp.duration, Some(0.05));
    assert_eq!(ramp.factor(0.0), 0.0);
    assert!((ramp.factor(0.025) - 0.5).abs() < 1e-15);
    assert_eq!(ramp.factor(0.05), 1.0);
    assert_eq!(ramp.factor(0.1), 1.0);
    let half = case.load.master_at(0.025);
    assert!((half[1] + 0.35).abs() < 1e-15 && (half[3] + 10.0).abs() < 1e-12);
    let c = case.contact;
    assert_eq!(
        (
            c.normal_stiffness,
            c.friction_coefficient,
            c.stick_stiffness
        ),
        (1.0e4, 0.25, 1.0e4)
    );
}

#[test]
fn multilayer_sheet_counts_match_the_paper() {
    let (_, mesh) = builtin("multilayer_sheet");
    assert_eq!(mesh.nodes.len(), 150 + 1);
    assert_eq!(mesh.shells.len(), 72);
    assert_eq!(mesh.beams.len(), 0);
    assert_eq!(mesh.welds.len(), 3);
    assert_eq!(mesh.clamped.len(), 6);
    assert_eq!(mesh.tie.slaves.len(), 6);
    // The paper's 92 pairs less the six at the weld centres (three welds, two interfaces).
    assert_eq!(mesh.pairs.len(), 86);
    let joint = pair_nodes(&mesh);
    assert_eq!(joint.len(), 129);
    assert_eq!(6 * joint.len(), 774);
    assert_eq!(independent_dofs(&mesh), 834);
}

#[test]
fn multilayer_sheet_numbering_and_coordinates() {
    let (case, mesh) = builtin("multilayer_sheet");
    let firsts: Vec<usize> = mesh.sheets.iter().map(|s| s.first_node).collect();
    assert_eq!(firsts, vec![0, 50, 100]);
    assert_node(&mesh, 12, [33.75, 0.0, 0.0]);
    assert_node(&mesh, 75, [67.5, 0.5, 25.0]);
    assert_node(&mesh, 149, [135.0, 1.0, 25.0]);
    assert_node(&mesh, 150, [135.0, 0.5, 12.5]);
    assert_eq!(mesh.tie.master, 150);
    assert_eq!(mesh.clamped, vec![0, 1, 50, 51, 100, 101]);
    assert_eq!(mesh.tie.slaves, vec![48, 49, 98, 99, 148, 149]);
    // Three area welds through bottom, middle and top, each centred on a free edge (z = 0 or
    // 25): half of each nugget lies inside the sheets.
    assert_eq!(mesh.welds.len(), 3);
    for w in &mesh.welds {
        let sheets: Vec<usize> = w.layers.iter().map(|l| l.sheet).collect();
        assert_eq!(sheets, vec![0, 1, 2]);
        for l in &w.layers {
            let area: f64 = l.points.iter().map(|p| p.weight).sum();
            assert!(
                (area - 0.5 * std::f64::consts::PI * 6.25).abs() < 1e-9,
                "{area}"
            );
            assert!(l.points.iter().all(|p| p.xz[1] >= 0.0 && p.xz[1] <= 25.0));
        }
    }
    assert_eq!(case.master_load(), [0.0, -50.0, 0.0, -2500.0, 0.0, 0.0]);
    assert_eq!(case.load.ramp.duration, Some(0.005));
    assert_eq!(case.end_time, 0.05);
    // Interface by interface: bottom–middle first, then middle–top, 43 pairs each.
    let sheet_of = |n: usize| n / 50;
    for (q, p) in mesh.pairs.iter().enumerate() {
        let interface = q / 43;
        assert_eq!(
            (sheet_of(p.lower), sheet_of(p.upper)),
            (interface, interface + 1),
            "pair {q}"
        );
    }
}

#[test]
fn pairs_coincide_are_free_ordered_and_distinct() {
    for name in Case::BUILTIN {
        let (case, mesh) = builtin(name);
        let fixed: BTreeSet<usize> = mesh
            .clamped
            .iter()
            .chain(&mesh.tie.slaves)
            .copied()
            .collect();
        let mut seen = BTreeSet::new();
        for (q, p) in mesh.pairs.iter().enumerate() {
            let (l, u) = (mesh.nodes[p.lower], mesh.nodes[p.upper]);
            assert!(
                (l[0] - u[0]).abs() < 1e-6 && (l[2] - u[2]).abs() < 1e-6,
                "{name}: pair {q} does not coincide in (x, z): {l:?} {u:?}"
            );
            assert!(u[1] > l[1], "{name}: pair {q}: upper not above lower");
            assert!(!fixed.contains(&p.lower) && !fixed.contains(&p.upper));
            assert!(seen.insert((p.lower, p.upper)), "{name}: pair {q} twice");
        }
        // Within an interface, sorted by (x, z) of the lower node.
        let mut start = 0;
        for joint in &case.joints {
            let lower = mesh.sheets.iter().position(|s| s.name == joint.lower);
            let lower = lower.expect("joint sheet");
            let len = mesh.pairs[start..]
                .iter()
                .take_while(|p| {
                    let g = &mesh.sheets[lower];
                    let n = (g.elements[0] + 1) * (g.elements[1] + 1);
                    (g.first_node..g.first_node + n).contains(&p.lower)
                })
                .count();
            let key = |p: &jointrom::mesh::JointPair| {
                let c = mesh.nodes[p.lower];
                (c[0], c[2])
            };
            for w in mesh.pairs[start..start + len].windows(2) {
                assert!(
                    key(&w[0]) < key(&w[1]),
                    "{name}: pairs not sorted by (x, z)"
                );
            }
            start += len;
        }
        assert_eq!(start, mesh.pairs.len());
    }
}

#[test]
fn shells_are_counter_clockwise_in_xz_and_on_their_sheet() {
    for name in Case::BUILTIN {
        let (case, mesh) = builtin(name);
        for (e, shell) in mesh.shells.iter().enumerate() {
            let p: Vec<[f64; 3]> = shell.nodes.iter().map(|&n| mesh.nodes[n]).collect();
            // Shoelace area in the (x, z) plane, x as abscissa and z as ordinate.
            let area: f64 = (0..4)
                .map(|a| {
                    let (p0, p1) = (p[a], p[(a + 1) % 4]);
                    p0[0] * p1[2] - p1[0] * p0[2]
                })
                .sum::<f64>()
                / 2.0;
            assert!(area > 0.0, "{name}: shell {e} is not counter-clockwise");
            let sheet = &case.sheets[shell.sheet];
            assert!(p.iter().all(|c| c[1] == sheet.y));
            assert_eq!(shell.thickness, sheet.thickness);
        }
    }
}

#[test]
fn a_case_survives_a_json_round_trip() {
    for name in Case::BUILTIN {
        let (case, mesh) = builtin(name);
        let text = serde_json::to_string_pretty(&case).expect("serialize");
        let again = Case::from_json_str(&text, "round-trip").expect("re-parse");
        assert_eq!(again.source, "round-trip");
        assert_eq!(
            Case {
                source: case.source.clone(),
                ..again.clone()
            },
            case
        );
        assert_eq!(Mesh::from_case(&again).expect("mesh"), mesh);
    }
}

#[test]
fn point_welds_keep_the_papers_beams_and_pairs() {
    let mut case = common::builtin_case("friction_bar");
    for w in &mut case.welds {
        w.model = jointrom::case::WeldModel::Point;
    }
    let mesh = Mesh::from_case(&case).unwrap();
    assert!(mesh.welds.is_empty());
    let beams: Vec<[usize; 2]> = mesh.beams.iter().map(|b| b.nodes).collect();
    assert_eq!(beams, vec![[37, 91], [64, 118]]);
    assert!(mesh.beams.iter().all(|b| b.diameter == 5.0));
    assert_eq!(mesh.pairs.len(), 54);
    assert_eq!(6 * pair_nodes(&mesh).len(), 648);
}
