//! `jointrom info`: model summary.

use clap::Args;
use serde_json::{json, Value};

use jointrom::{Error, Model};

use crate::common::print_json;

#[derive(Args)]
pub struct InfoArgs {
    /// Case file, matrix map (`jointrom-matrices` JSON) or built-in name (friction_bar, multilayer_sheet).
    case: String,
    /// One JSON document on stdout.
    #[arg(long)]
    json: bool,
}

pub fn run(a: InfoArgs) -> Result<(), Error> {
    let model = crate::common::load_model(&a.case)?;
    let v = info_json(&model);
    if a.json {
        print_json(&v);
    } else {
        println!(
            "case            {}",
            jointrom::files::printable(&model.name)
        );
        println!("DOF             {}", model.dofs());
        println!("joint pairs     {}", model.pair_count());
        println!("joint DOF       {}", model.joint_dofs());
        println!("nodes           {}", model.geometry.nodes.len());
        println!(
            "elements        {} ({} Shell4, {} Beam2, {} Weld)",
            v["elements"],
            cell_count(&model, true),
            cell_count(&model, false),
            area_welds(&model)
        );
    }
    Ok(())
}

/// The `info --json` document (also part of `run`'s results.json).
pub fn info_json(model: &Model) -> Value {
    json!({
        "case": model.name,
        "dofs": model.dofs(),
        "joint_pairs": model.pair_count(),
        "joint_dofs": model.joint_dofs(),
        "origin": match model.origin {
            jointrom::model::Origin::Case { .. } => "case",
            jointrom::model::Origin::Matrices { .. } => "matrices",
        },
        "nodes": model.geometry.nodes.len(),
        "elements": model.geometry.cells.len() + area_welds(model),
        "shells": cell_count(model, true),
        "beams": cell_count(model, false),
        "area_welds": area_welds(model),
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

/// Number of area welds (a generated case's `Weld` elements; none for a user's matrices).
fn area_welds(model: &Model) -> usize {
    model.mesh().map_or(0, |m| m.welds.len())
}

/// Number of 4-node (`quads`) or 2-node display cells.
fn cell_count(model: &Model, quads: bool) -> usize {
    use jointrom::model::CellNodes;
    model
        .geometry
        .cells
        .iter()
        .filter(|c| matches!(c.nodes, CellNodes::Quad4(_)) == quads)
        .count()
}
