//! Contact points inside the joint's faces (`jointrom::model::sampling`): their areas are the
//! pairs' tributary areas redistributed, the points at the nodes are the per-area pairs
//! themselves, and penetration fields the interpolations represent give the per-area pressure
//! on every mesh.

use jointrom::case::{Case, ContactSampling, GapInterpolation};
use jointrom::joint::statics::ContactOptions;
use jointrom::model::contact_static_full;
use jointrom::model::per_area::joints_overlap;
use jointrom::model::sampling::SamplingPoints;
use jointrom::Model;

use crate::common::{self, repo_path};

const KAPPA: f64 = 160.0;
const GAPS: [GapInterpolation; 2] = [GapInterpolation::Hermite, GapInterpolation::Bilinear];

fn per_area(mut case: Case, sampling: Option<ContactSampling>) -> Case {
    case.contact.normal_stiffness = f64::NAN;
    case.contact.stick_stiffness = f64::NAN;
    case.contact.normal_stiffness_per_area = Some(KAPPA);
    case.contact.stick_stiffness_per_area = Some(KAPPA);
    case.contact.sampling = sampling;
    case
}

fn points(m: usize, gap: GapInterpolation) -> Option<ContactSampling> {
    Some(ContactSampling {
        points_per_edge: m,
        gap,
    })
}

fn scale_case(name: &str) -> Case {
    Case::from_file(&repo_path(&format!("cases/scale/{name}.json"))).unwrap()
}

/// The points' areas add up to the pairs' tributary areas (the overlap less the shares of the
/// fused and held corners) for any m, and every point has area.
#[test]
fn point_areas_sum_to_the_pairs_areas() {
    let cases = [
        common::builtin_case("friction_bar"),
        common::builtin_case("multilayer_sheet"),
        scale_case("friction_bar_x2"),
    ];
    for case in cases {
        let nodal = Model::from_case(per_area(case.clone(), None)).unwrap();
        let want: f64 = nodal.pair_areas.as_ref().unwrap().iter().sum();
        let overlap = joints_overlap(&case);
        assert!(want < overlap, "{}: no fused share", nodal.name);
        for m in [1, 2, 3] {
            let model = Model::from_case(per_area(case.clone(), points(m, GAPS[0]))).unwrap();
            let areas = model.pair_areas.as_ref().unwrap();
            let sum: f64 = areas.iter().sum();
            assert!(
                (sum - want).abs() <= 1e-9 * want,
                "{} m {m}: Σ A_p {sum} vs Σ A_i {want} mm²",
                model.name
            );
            assert!(areas.iter().all(|&a| a > 0.0));
            assert_eq!(model.pairs.len(), areas.len());
            assert_eq!(model.joint.pairs(), areas.len());
            assert!(
                areas.len() > nodal.pair_count() * (m * m) / 2,
                "{} m {m}: {} points for {} pairs",
                model.name,
                areas.len(),
                nodal.pair_count()
            );
        }
    }
}

/// Points at the nodes are the per-area node pairs: the same rows of B, areas, weights, law and
/// contact statics, bit for bit.
#[test]
fn points_at_the_nodes_are_the_per_area_pairs() {
    for name in ["friction_bar", "multilayer_sheet"] {
        let pairs = Model::from_case(per_area(common::builtin_case(name), None)).unwrap();
        for gap in GAPS {
            let mut nodes = pairs.clone();
            nodes
                .apply_contact_sampling([KAPPA, KAPPA], SamplingPoints::Nodes, gap, "test")
                .unwrap();
            assert_eq!(nodes.joint.rows(), pairs.joint.rows());
            for r in 0..pairs.joint.rows() {
                let a: Vec<_> = pairs.joint.row(r).collect();
                let b: Vec<_> = nodes.joint.row(r).collect();
                assert_eq!(a, b, "{name}: row {r}");
            }
            assert_eq!(nodes.pair_areas, pairs.pair_areas, "{name}");
            assert_eq!(nodes.pair_weights, pairs.pair_weights, "{name}");
            assert_eq!(nodes.contact, pairs.contact, "{name}");
            let load = pairs.master_load();
            let opts = ContactOptions::default();
            let (a, b) = (
                contact_static_full(&pairs, load, &opts).unwrap(),
                contact_static_full(&nodes, load, &opts).unwrap(),
            );
            assert_eq!(a, b, "{name}");
        }
    }
}

/// Displaces the upper sheet's joint nodes by `u_y = −δ (1 + a x + b x²)` with the Kirchhoff
/// rotation `θ_z = ∂u_y/∂x` (the lower sheet stays): the gap field `g(x)`.
fn tilt_upper(model: &Model, delta: f64, a: f64, b: f64) -> Vec<f64> {
    let mesh = model.mesh().unwrap();
    let mut q = vec![0.0; model.dofs()];
    for p in &mesh.pairs {
        let x = mesh.nodes[p.upper][0];
        let dep = &model.dof_map.nodes[p.upper];
        q[dep[1].as_free().unwrap()] = -delta * (1.0 + a * x + b * x * x);
        q[dep[5].as_free().unwrap()] = -delta * (a + 2.0 * b * x);
    }
    q
}

/// The x of the centre of the (single) joint's overlap rectangle, mm.
fn overlap_centre_x(case: &Case) -> f64 {
    let j = &case.joints[0];
    let sheet = |n: &str| case.sheets.iter().find(|s| s.name == n).unwrap();
    let (a, b) = (sheet(&j.lower), sheet(&j.upper));
    0.5 * (a.x[0].max(b.x[0]) + a.x[1].min(b.x[1]))
}

/// A uniform and a linearly varying penetration give every point the pressure κ·g at its
/// position and the resultant κ∫|g| dA on every mesh, for either gap; a quadratic one (a bent
/// sheet) is represented exactly by the Hermite gap only.
#[test]
fn penetration_fields_give_the_per_area_pressure_at_the_points() {
    let delta = 1e-3;
    let cases = [
        common::builtin_case("friction_bar"),
        scale_case("friction_bar_x2"),
    ];
    for case in cases {
        let mut case = case;
        case.welds.clear();
        let overlap = joints_overlap(&case);
        for (m, gap) in [(1, GAPS[0]), (2, GAPS[0]), (3, GAPS[1])] {
            let model = Model::from_case(per_area(case.clone(), points(m, gap))).unwrap();
            let x_span = {
                let xs = model.point_positions.as_ref().unwrap().iter().map(|p| p[0]);
                let (lo, hi) = xs.fold((f64::MAX, f64::MIN), |(l, h), x| (l.min(x), h.max(x)));
                (lo, hi)
            };
            let a = -0.5 / x_span.1;
            for b in [0.0, 0.2 / (x_span.1 * x_span.1)] {
                let q = tilt_upper(&model, delta, a, b);
                let mut gaps = vec![0.0; model.pair_count()];
                model.joint.gaps(&q, &mut gaps);
                let forces: Vec<f64> = gaps
                    .iter()
                    .map(|g| model.contact.normal_stiffness * g.min(0.0))
                    .collect();
                let meas = model.contact_measures(&forces, &gaps);
                let areas = model.pair_areas.as_ref().unwrap();
                let mut worst = 0.0f64;
                for (i, &p) in forces.iter().enumerate() {
                    let x = model.pair_position(i)[0];
                    let want = KAPPA * delta * (1.0 + a * x + b * x * x);
                    let got = (model.pair_weight(i) * p).abs() / areas[i];
                    worst = worst.max((got - want).abs() / want);
                }
                // The Hermite gap is exact for both (a rigid tilt and a constant curvature
                // leave DKMQ's edge increments zero); the bilinear one for the tilt only.
                if b == 0.0 || gap == GapInterpolation::Hermite {
                    assert!(
                        worst < 1e-9,
                        "{} m {m} {gap:?} b {b}: {worst:e}",
                        model.name
                    );
                } else {
                    assert!(worst > 1e-5, "{} m {m} {gap:?}: {worst:e}", model.name);
                }
                if b == 0.0 {
                    assert!((meas.contact_area.unwrap() - overlap).abs() <= 1e-9 * overlap);
                    let resultant: f64 = forces
                        .iter()
                        .enumerate()
                        .map(|(i, p)| (model.pair_weight(i) * p).abs())
                        .sum();
                    // κ δ ∫(1 + a x) dA over the overlap rectangle (its centroid's x).
                    let mean_x = overlap_centre_x(&case);
                    let want = KAPPA * delta * overlap * (1.0 + a * mean_x);
                    assert!(
                        (resultant - want).abs() <= 1e-9 * want,
                        "{}: resultant {resultant} vs {want} N",
                        model.name
                    );
                }
            }
        }
    }
}

/// The contact statics of a sampled model are in equilibrium with the point springs `κ A_p`
/// on the unweighted point gaps.
#[test]
fn sampled_statics_are_the_point_springs() {
    let case = per_area(common::builtin_case("friction_bar"), points(2, GAPS[0]));
    let model = Model::from_case(case).unwrap();
    let load = model.master_load();
    let sol = contact_static_full(&model, load, &ContactOptions::default()).unwrap();
    let u = &sol.displacement;
    let mut r = vec![0.0; model.dofs()];
    model.stiffness.mul_vec(u, &mut r);
    let master = model.master_dofs();
    for k in 0..6 {
        r[master[k]] -= load[k];
    }
    let mut kin = vec![0.0; model.joint.rows()];
    model.joint.apply(u, &mut kin);
    let areas = model.pair_areas.as_ref().unwrap();
    let mut p = vec![0.0; model.joint.rows()];
    let mut closed = 0;
    for (i, a) in areas.iter().enumerate() {
        // Weighted rows: b_i = w_i b̂_i, g_i = w_i ĝ_i; the force on the structure
        // κ A_i ĝ_i b̂_iᵀ = κ Ā g_i b_iᵀ.
        let w = model.pair_weight(i);
        p[3 * i] = KAPPA * a * (kin[3 * i] / w).min(0.0) / w;
        closed += usize::from(kin[3 * i] < 0.0);
    }
    assert!(closed > model.pair_count() / 20, "{closed} points closed");
    model.joint.apply_transpose_add(&p, &mut r);
    let scale = load.iter().map(|v| v.abs()).fold(0.0, f64::max);
    let res = r.iter().map(|v| v.abs()).fold(0.0, f64::max);
    assert!(res <= 1e-8 * scale, "residual {res:e} of {scale}");
}

/// A matrix map holds node pairs only: exporting a model with contact points is refused by
/// name, and the same model without them exports.
#[test]
fn export_refuses_contact_points() {
    let dir = std::env::temp_dir().join(format!("jointrom-sampling-export-{}", std::process::id()));
    let case = per_area(common::builtin_case("friction_bar"), points(2, GAPS[0]));
    let model = Model::from_case(case).unwrap();
    let err = jointrom::model::matrices::write(&model, &dir)
        .unwrap_err()
        .to_string();
    assert!(err.contains("contact.sampling"), "{err}");
    assert!(!dir.join("model.json").exists());
    let plain = Model::from_case(per_area(common::builtin_case("friction_bar"), None)).unwrap();
    assert!(jointrom::model::matrices::write(&plain, &dir).is_ok());
    let _ = std::fs::remove_dir_all(&dir);
}
