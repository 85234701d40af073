//! `jointrom static`: static response to the case's master load (full or reduced).

use clap::Args;
use serde_json::{json, Value};

use jointrom::error::{FlagError, RomError};
use jointrom::joint::statics as contact;
use jointrom::reduction::{BasisKind, BasisOptions, JointFlexibility};
use jointrom::rom::spec::unsupported;
use jointrom::rom::statics::scaled_load;
use jointrom::rom::tolerance::static_tolerance_model;
use jointrom::rom::{ModelFlags, ModelSpec};
use jointrom::studies::convergence as study;
use jointrom::{Error, Model};

use crate::common::{print_json, print_master_displacement};
use crate::summary::{static_json, with_warnings};

#[derive(Args)]
pub struct StaticArgs {
    /// Case file, matrix map (`jointrom-matrices` JSON) or built-in name.
    case: String,
    /// Linear analysis without contact (the joint may interpenetrate); default: full FE
    /// model with frictionless penalty contact in the joint pairs.
    #[arg(long)]
    linear: bool,
    /// Factor on the case's load (e.g. -1 reverses it).
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    scale: f64,
    /// The model (default: full). A reduced basis solves the reduced contact statics exactly;
    /// --tolerance TOL solves the smallest Craig–Bampton + pair-attachment-mode model (the pairs
    /// in contact, largest force first) whose ‖f_c‖ is within TOL of the full model's (the full
    /// model's ‖f_c‖ from the exact pair-space solution).
    #[command(flatten)]
    model: ModelFlags,
    /// One JSON document on stdout.
    #[arg(long)]
    json: bool,
}

pub fn run(a: StaticArgs) -> Result<(), Error> {
    let scale = a.scale;
    if !scale.is_finite() {
        return Err(FlagError::NotFinite {
            flag: "scale",
            value: scale,
        }
        .into());
    }
    let spec = a.model.spec(ModelSpec::Full)?;
    if a.linear && spec.is_reduced() {
        return Err(RomError::LinearReduced.into());
    }
    let model = crate::common::load_model(&a.case)?;
    match spec {
        ModelSpec::Full => {}
        ModelSpec::Tolerance { tolerance, nu, on } => {
            // Statics has one controlled quantity, ‖f_c‖.
            let fc =
                jointrom::reduction::Quantities::of(&[jointrom::reduction::Quantity::ContactForce]);
            if on.is_some_and(|q| q != fc) {
                return Err(RomError::ToleranceOnStatic.into());
            }
            return tolerance_static(&model, tolerance, nu, scale, a.json);
        }
        ModelSpec::Basis { kind, g, nu } => {
            return reduced_static(&model, kind, g, nu, scale, a.json)
        }
        other => {
            return Err(unsupported(
                "static",
                &other,
                "full, a reduced basis or --tolerance TOL",
            ))
        }
    }
    let (v, state) = if a.linear {
        (static_json(&model, scale)?, None)
    } else {
        let (v, st) = contact_json(&model, scale)?;
        (v, Some(st))
    };
    if a.json {
        print_json(&with_warnings(&model, v));
        return Ok(());
    }
    let kind = if a.linear {
        "linear"
    } else {
        "with contact (frictionless)"
    };
    println!(
        "{} — static {kind}, load × {scale}:",
        jointrom::files::printable(&model.name)
    );
    let u = &v["master_displacement"];
    print_master_displacement(|k| u[k].as_f64().unwrap_or(f64::NAN));
    if !a.linear {
        println!(
            "  ‖f_c‖ = {:.6} N, {} of {} pairs in contact",
            v["contact_force_norm"].as_f64().unwrap_or(f64::NAN),
            v["pairs_in_contact"],
            model.pair_count()
        );
    }
    if let Some(st) = &state {
        print_measures(&model, st);
    }
    Ok(())
}

fn contact_json(model: &Model, scale: f64) -> Result<(Value, contact::ContactState), Error> {
    let load = model.master_load().map(|v| v * scale);
    let sol =
        jointrom::model::contact_static_full(model, load, &contact::ContactOptions::default())?;
    let mut v = json!({
        "case": model.name,
        "linear": false,
        "load": load,
        "master_displacement": sol.master_displacement,
        "iterations": sol.state.iterations,
    });
    add_pair_forces(&mut v, model, &sol.state);
    Ok((v, sol.state))
}

/// Adds the contact state's `contact_force_norm`, `contact_force_total` (the resultant Σ|p|, N:
/// unlike the norm, comparable between meshes of one scene), `pairs_in_contact`, `pair_forces`
/// (`[x, y, z (mm) of the pair's lower node or contact point, p (N, compressive negative)]` per pair in contact),
/// the mesh-independent measures (`contact_resultant` N, `contact_area` mm², `peak_pressure`
/// N/mm², `max_penetration` mm, `max_penetration_per_thickness`; `crate::model::per_area`) and
/// the resolved `contact` law to the JSON object `v`.
fn add_pair_forces(v: &mut Value, model: &Model, st: &contact::ContactState) {
    let pair_forces: Vec<[f64; 4]> = st
        .forces
        .iter()
        .zip(&model.pairs)
        .enumerate()
        .filter(|(_, (p, _))| **p != 0.0)
        .map(|(i, (p, _))| {
            let [x, y, z] = model.pair_position(i);
            [x, y, z, model.pair_weight(i) * *p]
        })
        .collect();
    let m = model.contact_measures(&st.forces, &st.gaps);
    v["contact_force_norm"] = json!(st.contact_force_norm);
    v["contact_force_total"] = json!(m.contact_resultant);
    v["pairs_in_contact"] = json!(st.pairs_in_contact);
    v["pair_forces"] = json!(pair_forces);
    for (key, value) in [
        ("contact_resultant", Some(m.contact_resultant)),
        ("contact_area", m.contact_area),
        ("peak_pressure", m.peak_pressure),
        ("max_penetration", m.max_penetration),
        (
            "max_penetration_per_thickness",
            m.max_penetration_per_thickness,
        ),
    ] {
        v[key] = json!(value);
    }
    v["contact"] = json!(model.contact);
}

/// The text line of the mesh-independent contact measures.
fn print_measures(model: &Model, st: &contact::ContactState) {
    let m = model.contact_measures(&st.forces, &st.gaps);
    println!("  {}", m.describe(6));
}

fn tolerance_static(
    model: &Model,
    tol: f64,
    nu: usize,
    scale: f64,
    json: bool,
) -> Result<(), Error> {
    let t = static_tolerance_model(model, tol, nu, scale)?;
    let st = &t.solution.state;
    let mut v = json!({
        "case": model.name,
        "linear": false,
        "load": scaled_load(model, scale)?,
        "master_displacement": t.solution.master_displacement,
        "iterations": st.iterations,
        "basis": "adaptive",
        "g": t.pairs.len(),
        "basis_size": t.basis_size,
        "tolerance": tol,
        "pairs": t.pairs,
        "error_estimate": { "contact_force": t.error, "exact": true },
        "full_contact_force_norm": t.exact_norm,
        "offline_s": t.wall_s,
        "wall_s": t.wall_s,
    });
    add_pair_forces(&mut v, model, st);
    if json {
        print_json(&with_warnings(model, v));
        return Ok(());
    }
    println!(
        "{} — reduced static with contact (frictionless), adaptive basis for tolerance {tol:e} ({} pairs, {} columns), load × {scale}:",
        jointrom::files::printable(&model.name), t.pairs.len(), t.basis_size
    );
    print_master_displacement(|k| t.solution.master_displacement[k]);
    println!(
        "  ‖f_c‖ = {:.6} N (full {:.6} N, relative error {:.2e}), {} of {} pairs in contact; {:.1} ms",
        st.contact_force_norm,
        t.exact_norm,
        t.error,
        st.pairs_in_contact,
        model.pair_count(),
        t.wall_s * 1e3
    );
    Ok(())
}

fn reduced_static(
    model: &Model,
    kind: BasisKind,
    g: Option<usize>,
    nu: usize,
    scale: f64,
    json: bool,
) -> Result<(), Error> {
    let load = scaled_load(model, scale)?;
    let opts = BasisOptions {
        nu,
        g,
        ..BasisOptions::default()
    };
    let r = study::basis_static(model, kind, &opts, scale)?;
    let st = &r.solution.state;
    // The estimate of a reduced static is exact: the pair-space solution is the full model's.
    let exact: f64 = JointFlexibility::new(model)?
        .static_contact_forces(load)?
        .iter()
        .map(|p| p * p)
        .sum::<f64>()
        .sqrt();
    let error = if exact > 0.0 {
        (st.contact_force_norm - exact).abs() / exact
    } else {
        st.contact_force_norm
    };
    let mut v = json!({
        "case": model.name,
        "linear": false,
        "load": load,
        "master_displacement": r.solution.master_displacement,
        "iterations": st.iterations,
        "basis": r.basis,
        "g": r.g,
        "basis_size": r.basis_size,
        "restarted": r.restarted,
        "build_s": r.build_s,
        "offline_s": r.build_s,
        "solve_s": r.solve_s,
        "error_estimate": { "contact_force": error, "exact": true },
        "full_contact_force_norm": exact,
    });
    add_pair_forces(&mut v, model, st);
    if json {
        print_json(&with_warnings(model, v));
        return Ok(());
    }
    println!(
        "{} — reduced static with contact (frictionless), basis {} (g = {}, {} columns), load × {scale}:",
        jointrom::files::printable(&model.name), r.basis, r.g, r.basis_size
    );
    print_master_displacement(|k| r.solution.master_displacement[k]);
    println!(
        "  ‖f_c‖ = {:.6} N (full {exact:.6} N: relative error {error:.2e}, exact), {} of {} pairs in contact; basis {:.1} ms, solve {:.1} ms",
        st.contact_force_norm,
        st.pairs_in_contact,
        model.pair_count(),
        r.build_s * 1e3,
        r.solve_s * 1e3
    );
    Ok(())
}
