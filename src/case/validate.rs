//! Validation helpers shared by the case file and the matrix map: an error context that names the
//! file and JSON path, and the checks of the material, contact law, load and end time.

use std::collections::HashMap;

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
            source: None,
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
    check_stiffnesses(c, ctx)?;
    let mu = c.friction_coefficient;
    if !(mu.is_finite() && mu >= 0.0) {
        return Err(ctx.err(
            "contact.friction_coefficient",
            format!("must be finite and ≥ 0, got {mu}"),
        ));
    }
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
    load.ramp
        .check("load.ramp")
        .map_err(|(path, reason)| ctx.err(path, reason))?;
    ctx.positive("end_time", end_time, " s")
}

/// The penalty stiffnesses of a contact block as a file gives them: each of the normal and the
/// stick stiffness either per pair (N/mm) or per area (N/mm³), not both, positive and finite,
/// and both given the same way.
fn check_stiffnesses(c: &ContactSpec, ctx: &Ctx) -> Result<(), Error> {
    let mut ways = [false; 2];
    for (i, (name, per_pair, per_area)) in [
        (
            "normal_stiffness",
            c.normal_stiffness,
            c.normal_stiffness_per_area,
        ),
        (
            "stick_stiffness",
            c.stick_stiffness,
            c.stick_stiffness_per_area,
        ),
    ]
    .into_iter()
    .enumerate()
    {
        let pair_path = format!("contact.{name}");
        let area_path = format!("contact.{name}_per_area");
        match (per_pair.is_nan(), per_area) {
            (false, Some(_)) => {
                return Err(ctx.err(
                    area_path,
                    format!(
                        "`{name}` (per pair, N/mm) and `{name}_per_area` (per area, N/mm³) are                          given together: give one of them"
                    ),
                ))
            }
            (true, None) => {
                return Err(ctx.err(
                    pair_path,
                    format!(
                        "missing: give `{name}` (per pair, N/mm) or `{name}_per_area` (per                          area, N/mm³)"
                    ),
                ))
            }
            (false, None) => ctx.positive(&pair_path, per_pair, " N/mm")?,
            (true, Some(k)) => {
                ctx.positive(&area_path, k, " N/mm³")?;
                ways[i] = true;
            }
        }
    }
    if let Some(sampling) = &c.sampling {
        let m = sampling.points_per_edge;
        if !ways[0] {
            return Err(ctx.err(
                "contact.sampling",
                "contact points inside the faces need the stiffnesses per area \
                 (`normal_stiffness_per_area`, `stick_stiffness_per_area`, N/mm³): a point's \
                 spring is κ times its share of the joint area",
            ));
        }
        if !(1..=super::MAX_POINTS_PER_EDGE).contains(&m) {
            return Err(ctx.err(
                "contact.sampling.points_per_edge",
                format!(
                    "must lie in 1..={} (points per face edge; a face gets m × m), got {m}",
                    super::MAX_POINTS_PER_EDGE
                ),
            ));
        }
    }
    if ways[0] != ways[1] {
        return Err(ctx.err(
            "contact.stick_stiffness_per_area",
            "give both stiffnesses per area (`normal_stiffness_per_area` and \
             `stick_stiffness_per_area`, N/mm³) or both per pair (N/mm): a pair's stick and \
             normal springs share its tributary area",
        ));
    }
    Ok(())
}

/// The longest element side a sheet may have, mm (1 km): sizes and coordinates derived from a
/// sheet's extent stay far from overflow, and a larger side is a unit mistake.
pub const MAX_ELEMENT_SIDE: f64 = 1e6;

/// Every sheet's own fields: a unique non-empty name, finite extents of positive length, a finite
/// y, a positive thickness, element counts ≥ 1, element sides of at most [`MAX_ELEMENT_SIDE`]
/// and a model within the DOF budget
/// ([`crate::files::dof_budget`]).
pub(crate) fn check_sheets(case: &Case, ctx: &Ctx) -> Result<(), Error> {
    if case.sheets.is_empty() {
        return Err(ctx.err("sheets", "no sheets: a case needs at least one"));
    }
    let mut names: HashMap<&str, usize> = HashMap::new();
    let mut first = 0usize;
    for (s, sheet) in case.sheets.iter().enumerate() {
        let p = format!("sheets[{s}]");
        if sheet.name.is_empty() {
            return Err(ctx.err(format!("{p}.name"), "empty sheet name"));
        }
        if let Some(prev) = names.insert(&sheet.name, s) {
            return Err(ctx.err(
                format!("{p}.name"),
                format!(
                    "duplicate sheet name `{}` (also sheets[{prev}])",
                    sheet.name
                ),
            ));
        }
        for (axis, span) in [("x", sheet.x), ("z", sheet.z)] {
            ctx.finite(&format!("{p}.{axis}[0]"), span[0], " mm")?;
            ctx.finite(&format!("{p}.{axis}[1]"), span[1], " mm")?;
            if span[1] <= span[0] {
                return Err(ctx.err(
                    format!("{p}.{axis}"),
                    format!(
                        "{axis}[1] must be greater than {axis}[0] (a positive length), got \
                         [{}, {}] mm",
                        span[0], span[1]
                    ),
                ));
            }
        }
        ctx.finite(&format!("{p}.y"), sheet.y, " mm")?;
        ctx.positive(&format!("{p}.thickness"), sheet.thickness, " mm")?;
        for (a, &n) in sheet.elements.iter().enumerate() {
            if n == 0 {
                return Err(ctx.err(
                    format!("{p}.elements[{a}]"),
                    "element count must be positive (at least 1)",
                ));
            }
        }
        let [nx, nz] = sheet.elements;
        for (a, (axis, span)) in [("x", sheet.x), ("z", sheet.z)].into_iter().enumerate() {
            let side = (span[1] - span[0]) / sheet.elements[a] as f64;
            if side.is_nan() || side > MAX_ELEMENT_SIDE {
                return Err(ctx.err(
                    format!("{p}.{axis}"),
                    format!(
                        "[{:e}, {:e}] mm in {} elements: an element side of {side:e} mm, over the \
                         {MAX_ELEMENT_SIDE:e} mm a sheet model admits (check the units: lengths \
                         are in mm)",
                        span[0], span[1], sheet.elements[a]
                    ),
                ));
            }
        }
        // Sheet nodes so far, plus the master node, 6 DOF each, within the model-size budget
        // (checked before anything is allocated).
        let budget = crate::files::dof_budget();
        let total = nx
            .checked_add(1)
            .zip(nz.checked_add(1))
            .and_then(|(a, b)| a.checked_mul(b))
            .and_then(|n| n.checked_add(first + 1));
        if total.is_none_or(|n| n > budget / 6) {
            return Err(ctx.err(
                format!("{p}.elements"),
                format!(
                    "{nx} × {nz} elements: the mesh would have more than {budget} DOF, the \
                     model-size budget (set {} to allow more; about 4 GB per 10⁶ DOF)",
                    crate::files::DOF_BUDGET_VAR
                ),
            ));
        }
        first += (nx + 1) * (nz + 1);
    }
    Ok(())
}

/// Two sheets whose plan views overlap may not cut into each other (mid-surfaces closer than
/// half their thicknesses), and two that touch must be joined by a `joints` entry or a weld:
/// sheets laid on top of each other with nothing between them pass through each other without
/// a force.
pub(crate) fn check_stacking(case: &Case, ctx: &Ctx) -> Result<(), Error> {
    // A joint naming an unknown sheet is reported by the joints' own check, more precisely.
    let known = |n: &str| case.sheets.iter().any(|s| s.name == n);
    if case
        .joints
        .iter()
        .any(|j| !known(&j.lower) || !known(&j.upper))
    {
        return Ok(());
    }
    let overlap = |a: [f64; 2], b: [f64; 2]| a[1].min(b[1]) - a[0].max(b[0]) > 0.0;
    for (j, b) in case.sheets.iter().enumerate() {
        for (i, a) in case.sheets.iter().enumerate().take(j) {
            if !(overlap(a.x, b.x) && overlap(a.z, b.z)) {
                continue;
            }
            let gap = (b.y - a.y).abs();
            let touch = 0.5 * (a.thickness + b.thickness);
            let joined = case.joints.iter().any(|jt| {
                (jt.lower == a.name && jt.upper == b.name)
                    || (jt.lower == b.name && jt.upper == a.name)
            });
            // A welded stack whose contact is deliberately not modelled (a linear, tied
            // model) is allowed; a stack held by nothing is not.
            let welded = case
                .welds
                .iter()
                .any(|w| w.sheets.contains(&a.name) && w.sheets.contains(&b.name));
            let names = format!("`{}` (sheets[{i}]) and `{}`", a.name, b.name);
            if gap < touch * (1.0 - 1e-9) {
                return Err(ctx.err(
                    format!("sheets[{j}].y"),
                    format!(
                        "{names} overlap in plan and their mid-surfaces are {gap} mm apart, \
                         less than half their thicknesses ({touch} mm): the sheets cut into \
                         each other"
                    ),
                ));
            }
            if gap <= touch * (1.0 + 1e-9) && !joined && !welded {
                return Err(ctx.err(
                    format!("sheets[{j}]"),
                    format!(
                        "{names} lie on top of each other without a joint between them: add \
                         {{\"lower\": ..., \"upper\": ...}} to `joints`, or move them apart"
                    ),
                ));
            }
        }
    }
    Ok(())
}
