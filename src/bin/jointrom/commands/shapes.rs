//! `jointrom shapes`: Craig–Bampton vectors, TVD and joint modes as VTU and a picture.

use std::path::PathBuf;

use clap::Args;

use jointrom::report::shapes;
use jointrom::Error;

#[derive(Args)]
pub struct ShapesArgs {
    /// Case file, matrix map (`jointrom-matrices` JSON) or built-in name.
    case: String,
    /// Output folder.
    #[arg(long, default_value = "out")]
    out: PathBuf,
    /// TVD and joint modes written.
    #[arg(long, default_value_t = 12)]
    count: usize,
    /// Fixed-interface modes ν.
    #[arg(long, default_value_t = 10)]
    nu: usize,
}

pub fn run(a: ShapesArgs) -> Result<(), Error> {
    let model = crate::common::load_model(&a.case)?;
    let s = shapes::shapes(&model, a.nu, a.count)?;
    let dir = a.out.join(jointrom::files::safe_name(&model.name));
    for f in shapes::write_shapes(&model, &s, &dir)? {
        println!("{}", f.display());
    }
    Ok(())
}
