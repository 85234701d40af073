//! `jointrom export-matrices`: K and M as MatrixMarket files plus the JSON map.

use std::path::PathBuf;

use clap::Args;
use serde_json::json;

use jointrom::Error;

use crate::common::print_json;

#[derive(Args)]
pub struct ExportMatricesArgs {
    /// Case file, matrix map or built-in name.
    case: String,
    /// Output folder.
    #[arg(long)]
    out: PathBuf,
    /// One JSON document on stdout.
    #[arg(long)]
    json: bool,
}

pub fn run(a: ExportMatricesArgs) -> Result<(), Error> {
    let model = crate::common::load_model(&a.case)?;
    let files = jointrom::model::matrices::write(&model, &a.out)?;
    if a.json {
        print_json(&json!({
            "case": model.name,
            "dofs": model.dofs(),
            "joint_pairs": model.pair_count(),
            "files": files,
        }));
    } else {
        println!(
            "{}: {} DOF, {} joint pairs → {}",
            jointrom::files::printable(&model.name),
            model.dofs(),
            model.pair_count(),
            files
                .iter()
                .map(|f| f.display().to_string())
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    Ok(())
}
