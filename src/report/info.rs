//! The `info --json` document of a model: its size, origin, mass, load and mesh counts (the
//! CLI's `jointrom info --json`, `run`'s results.json and the Python package's `Model.info`).

use serde_json::{json, Value};

use crate::mesh::OwnShellNugget;
use crate::model::Model;

/// The `info --json` document (also part of `run`'s results.json).
pub fn info_json(model: &Model) -> Value {
    json!({
        "case": model.name,
        "dofs": model.dofs(),
        // With contact points inside the faces (`contact.sampling`), the contact entities the
        // law acts on are the points: `joint_pairs` counts them, `contact_points` says so.
        "joint_pairs": model.pair_count(),
        "contact_points": model.point_positions.as_ref().map(Vec::len),
        "joint_dofs": model.joint_dofs(),
        "origin": match model.origin {
            crate::model::Origin::Case { .. } => "case",
            crate::model::Origin::Matrices { .. } => "matrices",
            crate::model::Origin::Deck { .. } => "deck",
        },
        "structural_mass": structural_mass(model),
        "master_load": model.master_load(),
        "end_time": model.end_time,
        "point_masses": model.mesh().map_or(0, |m| m.masses.len()),
        "warnings": model.warnings,
        "nodes": model.geometry.nodes.len(),
        "elements": model.geometry.cells.len() + area_welds(model),
        "shells": cell_count(model, true),
        "beams": cell_count(model, false),
        "area_welds": area_welds(model),
        // Area welds whose neighbourhood is re-meshed and condensed (`local_mesh`).
        "resolved_welds": model
            .mesh()
            .map_or(0, |m| m.welds.iter().filter(|w| w.patch.is_some()).count()),
        // Area welds bonded over the disc on the sheets' own shells (`local_mesh` auto on shells
        // that resolve the nugget).
        "bonded_welds": model.mesh().map_or(0, |m| {
            m.welds
                .iter()
                .filter(|w| w.patch.is_none() && w.own_shells == OwnShellNugget::BondedSlab)
                .count()
        }),
        "clamped_nodes": model
            .dof_map
            .nodes
            .iter()
            .filter(|d| d.iter().all(|c| c.terms().next().is_none()))
            .count(),
        "tied_nodes": model.geometry.followers.len(),
        "stiffness_nonzeros": model.stiffness.values.len(),
    })
}

/// The mass of the mesh's shells, beams and point masses (t): Σ ρ t A + Σ ρ π d²/4 L + Σ m,
/// for a cross-check against a pre-processor's mass; `null` for a user's matrices.
fn structural_mass(model: &Model) -> Option<f64> {
    let mesh = model.mesh()?;
    let rho = mesh.material.density;
    let x = &mesh.nodes;
    let sub = |a: usize, b: usize| [0, 1, 2].map(|k| x[b][k] - x[a][k]);
    let shells: f64 = mesh
        .shells
        .iter()
        .map(|s| {
            let (d1, d2) = (sub(s.nodes[0], s.nodes[2]), sub(s.nodes[1], s.nodes[3]));
            let c = [
                d1[1] * d2[2] - d1[2] * d2[1],
                d1[2] * d2[0] - d1[0] * d2[2],
                d1[0] * d2[1] - d1[1] * d2[0],
            ];
            rho * s.thickness * 0.5 * (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt()
        })
        .sum();
    let beams: f64 = mesh
        .beams
        .iter()
        .map(|b| {
            let d = sub(b.nodes[0], b.nodes[1]);
            let length = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            rho * std::f64::consts::FRAC_PI_4 * b.diameter * b.diameter * length
        })
        .sum();
    let points: f64 = mesh.masses.iter().map(|m| m.mass).sum();
    Some(shells + beams + points)
}

/// Number of area welds (a generated case's `Weld` elements; none for a user's matrices).
pub fn area_welds(model: &Model) -> usize {
    model.mesh().map_or(0, |m| m.welds.len())
}

/// Number of 4-node (`quads`) or 2-node display cells.
pub fn cell_count(model: &Model, quads: bool) -> usize {
    use crate::model::CellNodes;
    model
        .geometry
        .cells
        .iter()
        .filter(|c| matches!(c.nodes, CellNodes::Quad4(_)) == quads)
        .count()
}
