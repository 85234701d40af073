//! `jointrom info`: model summary.

use clap::Args;
use jointrom::Error;

use crate::common::print_json;
use crate::summary::{area_welds, cell_count, info_json};

#[derive(Args)]
pub struct InfoArgs {
    /// Case file, NASTRAN deck (.bdf), matrix map (`jointrom-matrices` JSON) or built-in name (friction_bar, multilayer_sheet).
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
        match &model.point_positions {
            Some(points) => println!(
                "contact points  {} (inside the joint's faces)",
                points.len()
            ),
            None => println!("joint pairs     {}", model.pair_count()),
        }
        println!("joint DOF       {}", model.joint_dofs());
        println!("nodes           {}", model.geometry.nodes.len());
        println!(
            "elements        {} ({} Shell4, {} Beam2, {} Weld; {} with a re-meshed neighbourhood, \
             {} bonded on the sheets' shells)",
            v["elements"],
            cell_count(&model, true),
            cell_count(&model, false),
            area_welds(&model),
            v["resolved_welds"],
            v["bonded_welds"]
        );
    }
    Ok(())
}
