//! Validation helpers shared by the case file and the matrix map: an error context that names the
//! file and JSON path, and the checks of the material, contact law, load and end time.

use super::{Case, ContactSpec, LoadSpec};
use crate::error::Error;

/// Where errors go: the file label.
pub(crate) struct Ctx<'a> {
    pub(crate) file: &'a str,
}

impl Ctx<'_> {
    pub(crate) fn err(&self, path: impl Into<String>, reason: impl Into<String>) -> Error {
        Error::Case {
            file: self.file.to_string(),
            path: path.into(),
            reason: reason.into(),
        }
    }

    pub(crate) fn finite(&self, path: &str, v: f64, unit: &str) -> Result<(), Error> {
        if v.is_finite() {
            Ok(())
        } else {
            Err(self.err(path, format!("must be a finite number, got {v}{unit}")))
        }
    }

    pub(crate) fn positive(&self, path: &str, v: f64, unit: &str) -> Result<(), Error> {
        if v.is_finite() && v > 0.0 {
            Ok(())
        } else {
            Err(self.err(
                path,
                format!("must be positive (finite and > 0), got {v}{unit}"),
            ))
        }
    }
}

/// E, ν, ρ.
pub(crate) fn check_material(case: &Case, ctx: &Ctx) -> Result<(), Error> {
    let m = &case.material;
    ctx.positive("material.youngs_modulus", m.youngs_modulus, " N/mm²")?;
    let nu = m.poisson_ratio;
    if !(nu > -1.0 && nu < 0.5) {
        return Err(ctx.err(
            "material.poisson_ratio",
            format!("Poisson's ratio must lie in (−1, 0.5), got {nu}"),
        ));
    }
    ctx.positive("material.density", m.density, " t/mm³")
}

/// The contact law, the load and the end time.
pub(crate) fn check_contact_and_load(case: &Case, ctx: &Ctx) -> Result<(), Error> {
    check_contact_load(&case.contact, &case.load, case.end_time, ctx.file)
}

/// Checks a contact law, a master load and an end time (fields `contact.*`, `load.*`,
/// `end_time` of a case file or a matrix map named `file`).
pub(crate) fn check_contact_load(
    c: &ContactSpec,
    load: &LoadSpec,
    end_time: f64,
    file: &str,
) -> Result<(), Error> {
    let ctx = &Ctx { file };
    ctx.positive("contact.normal_stiffness", c.normal_stiffness, " N/mm")?;
    let mu = c.friction_coefficient;
    if !(mu.is_finite() && mu >= 0.0) {
        return Err(ctx.err(
            "contact.friction_coefficient",
            format!("must be finite and ≥ 0, got {mu}"),
        ));
    }
    ctx.positive("contact.stick_stiffness", c.stick_stiffness, " N/mm")?;
    let m = &load.master;
    for (key, v, unit) in [
        ("fx", m.fx, " N"),
        ("fy", m.fy, " N"),
        ("fz", m.fz, " N"),
        ("mx", m.mx, " N·mm"),
        ("my", m.my, " N·mm"),
        ("mz", m.mz, " N·mm"),
    ] {
        ctx.finite(&format!("load.master.{key}"), v, unit)?;
    }
    ctx.positive("load.ramp.duration", load.ramp.duration, " s")?;
    ctx.positive("end_time", end_time, " s")
}
