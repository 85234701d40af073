//! Where the joint's slips are taken (`"slip"` in the contact block): at the faces the pair
//! rows are objective — a rigid motion of the whole structure moves no pair — while the
//! paper's mid-surface node pairs read a rotation of stacked sheets as slip.

use jointrom::case::{Case, ContactSampling, GapInterpolation, SlipSurface};
use jointrom::Model;

use crate::common::repo_path;

/// The independent DOF of a rigid motion `u = a + θ × x` (every node's translation and
/// rotation; tied nodes follow the master, clamped ones are not in the pairs).
fn rigid_motion(model: &Model, a: [f64; 3], theta: [f64; 3]) -> Vec<f64> {
    let mut q = vec![0.0; model.dof_map.n];
    for (i, x) in model.geometry.nodes.iter().enumerate() {
        let u = [
            a[0] + theta[1] * x[2] - theta[2] * x[1],
            a[1] + theta[2] * x[0] - theta[0] * x[2],
            a[2] + theta[0] * x[1] - theta[1] * x[0],
        ];
        for (d, dep) in model.dof_map.nodes[i].iter().enumerate() {
            if let Some(j) = dep.as_free() {
                q[j] = if d < 3 { u[d] } else { theta[d - 3] };
            }
        }
    }
    q
}

/// The largest |row| of `B q` over the rows of one kind (0 normal, 1 and 2 tangential).
fn largest_rows(model: &Model, q: &[f64]) -> [f64; 3] {
    let mut out = vec![0.0; model.joint.rows()];
    model.joint.apply(q, &mut out);
    let mut m = [0.0f64; 3];
    for (r, v) in out.iter().enumerate() {
        m[r % 3] = m[r % 3].max(v.abs());
    }
    m
}

fn friction_bar(slip: SlipSurface, sampling: Option<ContactSampling>) -> Model {
    let mut case = Case::from_file(&repo_path("cases/friction_bar.json")).unwrap();
    case.contact.slip = slip;
    if sampling.is_some() {
        case.contact.normal_stiffness = f64::NAN;
        case.contact.stick_stiffness = f64::NAN;
        case.contact.normal_stiffness_per_area = Some(160.0);
        case.contact.stick_stiffness_per_area = Some(160.0);
        case.contact.sampling = sampling;
    }
    Model::from_case(case).unwrap()
}

/// A rigid rotation of the stack moves no pair at the faces; at the mid-surfaces its rotation
/// about z reads as a slip along x of `θ_z · (t_l + t_u)/2` (0.25 mm sheet offsets here).
#[test]
fn slips_at_the_faces_are_objective() {
    let theta = [0.02, -0.03, 0.05];
    let a = [0.1, -0.2, 0.3];
    for sampling in [
        None,
        Some(ContactSampling {
            points_per_edge: 2,
            gap: GapInterpolation::Hermite,
        }),
    ] {
        let faces = friction_bar(SlipSurface::Faces, sampling);
        let rows = largest_rows(&faces, &rigid_motion(&faces, a, theta));
        assert!(
            rows.iter().all(|&r| r < 1e-12),
            "rigid motion moved pairs at the faces: {rows:?}"
        );
        let mid = friction_bar(SlipSurface::MidSurface, sampling);
        let rows = largest_rows(&mid, &rigid_motion(&mid, a, theta));
        let scale = if sampling.is_some() {
            // Points carry √(A_p/Ā) row weights.
            rows[1] / (0.5 * theta[2])
        } else {
            1.0
        };
        assert!(rows[0] < 1e-12, "normal rows moved: {rows:?}");
        assert!(
            (rows[1] / scale - 0.5 * theta[2]).abs() < 1e-12 && rows[1] > 1e-3,
            "mid-surface slip along x {} against θ_z (t_l + t_u)/2 = {}",
            rows[1],
            0.5 * theta[2]
        );
        assert!(rows[2] > 1e-3, "mid-surface slip along z {}", rows[2]);
    }
}

/// The face offsets are the half thicknesses, and the default writes no `slip` field.
#[test]
fn face_offsets_are_half_thicknesses_and_the_default_is_unwritten() {
    let faces = friction_bar(SlipSurface::Faces, None);
    assert!(faces.pairs.iter().all(|p| p.face_offsets == [0.25, 0.25]));
    let mid = friction_bar(SlipSurface::MidSurface, None);
    assert!(mid.pairs.iter().all(|p| p.face_offsets == [0.0, 0.0]));
    let text = serde_json::to_string(&mid.contact).unwrap();
    assert!(!text.contains("slip"), "{text}");
    let text = serde_json::to_string(&faces.contact).unwrap();
    assert!(text.contains("\"slip\":\"faces\""), "{text}");
}

/// An unknown value names the field.
#[test]
fn an_unknown_slip_surface_is_an_error_naming_the_field() {
    let text = std::fs::read_to_string(repo_path("cases/friction_bar.json")).unwrap();
    let bad = text.replacen("\"contact\": {", "\"contact\": {\"slip\": \"top\", ", 1);
    let err = Case::from_json_str(&bad, "bad.json")
        .unwrap_err()
        .to_string();
    assert!(err.contains("slip") && err.contains("bad.json"), "{err}");
}
