//! The static convergence study's charts ([`crate::studies::convergence`]): the error of ‖f_c‖
//! and ‖f_c‖ itself against g for every basis kind, and the POD energy ratios w(g).

use std::path::{Path, PathBuf};

use crate::error::Error;
use crate::report::chart::{series_color, LegendPosition, LineChart, Reference, Series};
use crate::studies::convergence::{Study, ERROR_FLOOR, WITHIN_TOLS};

/// Writes the study's charts into `dir` as SVG and PNG; returns the files written.
///
/// - `fc_error`: relative error of `‖f_c‖` against g, log axis (errors below [`ERROR_FLOOR`]
///   drawn at the floor; failed solves, NaN, leave a gap), with the 1e-2 and 1e-4 levels as
///   reference lines;
/// - `fc_norm`: `‖f_c‖` against g with the full-FE value (paper Figs. 7, 15, 19);
/// - `w`: the POD energy ratios w(g) with the threshold (paper Figs. 8, 16).
pub fn write_charts(study: &Study, dir: &Path) -> Result<Vec<PathBuf>, Error> {
    let mut files = Vec::new();
    let case = &study.case;

    let mut err = LineChart::new(
        format!(
            "{case}: static contact force convergence (ν = {})",
            study.nu
        ),
        "added vectors g",
        "relative error of ‖f_c‖",
    );
    err.y_log = true;
    err.legend = LegendPosition::LowerLeft;
    for s in &study.series {
        err.series.push(Series::new(
            s.label.clone(),
            s.g.iter()
                .zip(&s.relative_error)
                .map(|(&g, &e)| (g as f64, if e.is_nan() { e } else { e.max(ERROR_FLOOR) }))
                .collect(),
        ));
    }
    for tol in WITHIN_TOLS {
        err.references
            .push(Reference::new(format!("{tol:.0e}"), tol));
    }
    for t in &study.tvd_spans {
        // In the colour of the series it limits (alldof: the next free colour).
        let k = study
            .series
            .iter()
            .position(|s| s.name == t.name)
            .unwrap_or(study.series.len());
        let label = if t.name == "alldof" {
            format!(
                "alldof: CB + all pair constraint modes ({} columns)",
                t.basis_size
            )
        } else {
            format!("all {} TVD, no POD ({} columns)", t.name, t.basis_size)
        };
        err.references.push(Reference {
            label,
            value: t.relative_error.max(ERROR_FLOOR),
            color: Some(series_color(k)),
        });
    }
    files.extend(err.write(&dir.join("fc_error"))?);

    let mut norm = LineChart::new(
        format!("{case}: ‖f_c‖ of the reduced models (ν = {})", study.nu),
        "added vectors g",
        "‖f_c‖ (N)",
    );
    for s in &study.series {
        norm.series.push(Series::new(
            s.label.clone(),
            s.g.iter()
                .zip(&s.contact_force_norm)
                .map(|(&g, &f)| (g as f64, f))
                .collect(),
        ));
    }
    norm.references.push(Reference::new(
        format!("full FE, {:.6} N", study.full.contact_force_norm),
        study.full.contact_force_norm,
    ));
    files.extend(norm.write(&dir.join("fc_norm"))?);

    let mut w = LineChart::new(
        format!("{case}: POD energy ratio w(g) of the TVD (eq. 26)"),
        "POD modes g",
        "w(g)",
    );
    for e in &study.energy {
        w.series.push(Series::new(
            e.label.clone(),
            e.w.iter()
                .enumerate()
                .map(|(i, &v)| ((i + 1) as f64, v))
                .collect(),
        ));
    }
    w.legend = LegendPosition::LowerRight;
    w.references.push(Reference::new(
        format!("threshold {}", study.threshold),
        study.threshold,
    ));
    files.extend(w.write(&dir.join("w"))?);
    Ok(files)
}
