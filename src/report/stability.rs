//! The stability map's outputs ([`crate::studies::stability`]): `stability.json` (every cell, the
//! options and the references), `stability.md` (a markdown table) and three heat maps (SVG + PNG)
//! — rows model × iteration × max order, columns k_n × friction × events — coloured by status, by
//! log10 of the wall time and by log10 of the error, the failure flag (and, on the status map,
//! the time reached, s) written in failed cells.

use std::path::{Path, PathBuf};
use std::time::Instant;

use crate::error::Error;
use crate::integrate::RunStatus;
use crate::model::Model;
use crate::report::heatmap::{sequential, HeatCell, HeatMap};
use crate::studies::stability::{
    on_off, run_sweep_model, IterKind, ModelKind, Sweep, SweepOptions,
};

/// The status with `CV_` stripped (short enough for a heat-map cell).
fn short_status(s: &RunStatus) -> &str {
    let name = s.name();
    name.strip_prefix("CV_").unwrap_or(name)
}

fn status_color(s: &RunStatus) -> [u8; 3] {
    match s {
        RunStatus::Finished => [120, 190, 120],
        RunStatus::Budget { .. } => [245, 170, 60],
        RunStatus::Chatter { .. } => [140, 90, 60],
        RunStatus::Stalled { .. } => [200, 110, 170],
        RunStatus::Failed { flag, .. } => match flag.name.as_str() {
            "CV_TOO_MUCH_WORK" => [215, 80, 70],
            "CV_CONV_FAILURE" => [150, 90, 190],
            "CV_ERR_FAILURE" => [70, 110, 200],
            _ => [110, 110, 110],
        },
        RunStatus::Error => [110, 110, 110],
    }
}

/// The markdown table of every cell.
pub(crate) fn markdown_table(sweep: &Sweep) -> String {
    let mut s = String::new();
    s.push_str(&format!(
        "# Stability map: {} (rtol {:e}, atol {:e}, window {} s ROM / {} s full, budget {} s/cell)\n\n",
        sweep.case,
        sweep.options.rtol,
        sweep.options.atol,
        sweep.options.end_time,
        sweep.options.full_end_time,
        sweep.options.budget_s
    ));
    s.push_str("| model | dim | iteration | max order | k_n (N/mm) | friction | events | status | t reached (s) | steps | RHS evals | nonlin iters | nonlin fails | err-test fails | events found | wall (s) | error | error vs full |\n");
    s.push_str("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    let opt = |e: Option<f64>| e.map_or("–".into(), |e| format!("{e:.2e}"));
    for c in &sweep.cells {
        let o = &c.outcome;
        s.push_str(&format!(
            "| {} | {} | {} | {} | {:.0e} | {} | {} | {} | {:.4e} | {} | {} | {} | {} | {} | {} | {:.3} | {} | {} |\n",
            c.model.name(),
            c.dim,
            c.iteration.name(),
            c.max_order,
            c.normal_stiffness,
            on_off(c.friction),
            on_off(c.events),
            o.status.name(),
            o.t_reached,
            o.stats.steps,
            o.stats.rhs_evals,
            o.stats.nonlinear_iterations,
            o.stats.nonlinear_conv_failures,
            o.stats.error_test_failures,
            o.events_found,
            o.wall_s,
            opt(c.error),
            opt(c.error_vs_full)
        ));
    }
    s.push_str(
        "\nReferences (Newton, max order 5, events off, tolerances ÷ reference_factor):\n\n",
    );
    s.push_str("| model | k_n (N/mm) | friction | status | t reached (s) | steps | wall (s) | error vs full |\n|---|---|---|---|---|---|---|---|\n");
    for r in &sweep.references {
        s.push_str(&format!(
            "| {} | {:.0e} | {} | {} | {:.4e} | {} | {:.3} | {} |\n",
            r.model.name(),
            r.normal_stiffness,
            on_off(r.friction),
            r.outcome.status,
            r.outcome.t_reached,
            r.outcome.stats.steps,
            r.outcome.wall_s,
            opt(r.error_vs_full)
        ));
    }
    s
}

/// What a heat map colours.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MapKind {
    /// Status (categorical).
    Status,
    /// log10 of the wall time.
    Wall,
    /// log10 of the error against the reference.
    Error,
}

/// The heat map of a sweep: rows model × iteration × max order, columns k_n × friction ×
/// events, in the order of the options; a combination that was not run is blank.
pub(crate) fn heat_map(sweep: &Sweep, kind: MapKind) -> HeatMap {
    let o = &sweep.options;
    let mut rows = Vec::new();
    for &m in &o.models {
        for &it in &o.iterations {
            for &mo in &o.max_orders {
                rows.push((m, it, mo));
            }
        }
    }
    let mut cols = Vec::new();
    for &kn in &o.normal_stiffness {
        for &fr in &o.friction {
            for &ev in &o.events {
                cols.push((kn, fr, ev));
            }
        }
    }
    let find = |r: &(ModelKind, IterKind, usize), c: &(f64, bool, bool)| {
        sweep.cells.iter().find(|x| {
            x.model == r.0
                && x.iteration == r.1
                && x.max_order == r.2
                && x.normal_stiffness == c.0
                && x.friction == c.1
                && x.events == c.2
        })
    };
    let walls: Vec<f64> = sweep
        .cells
        .iter()
        .map(|c| c.outcome.wall_s.max(1e-4).log10())
        .collect();
    let (wlo, whi) = bounds(&walls);
    let errs: Vec<f64> = sweep
        .cells
        .iter()
        .filter_map(|c| c.error)
        .map(|e| e.max(1e-12).log10())
        .collect();
    let (elo, ehi) = bounds(&errs);
    let scaled = |v: f64, lo: f64, hi: f64| {
        if hi > lo {
            (v - lo) / (hi - lo)
        } else {
            0.5
        }
    };
    let cells: Vec<Vec<HeatCell>> = rows
        .iter()
        .map(|r| {
            cols.iter()
                .map(|c| match find(r, c) {
                    None => HeatCell {
                        color: [255, 255, 255],
                        text: String::new(),
                    },
                    Some(x) => {
                        let st = &x.outcome.status;
                        let failed_text = short_status(st).to_string();
                        match kind {
                            MapKind::Status => HeatCell {
                                color: status_color(st),
                                text: if x.outcome.ok() {
                                    "ok".into()
                                } else {
                                    format!("{failed_text} {:.1e}", x.outcome.t_reached)
                                },
                            },
                            MapKind::Wall => {
                                let v = x.outcome.wall_s.max(1e-4).log10();
                                HeatCell {
                                    color: sequential(scaled(v, wlo, whi)),
                                    text: if x.outcome.ok() {
                                        format!("{:.2} s", x.outcome.wall_s)
                                    } else {
                                        failed_text.clone()
                                    },
                                }
                            }
                            MapKind::Error => match x.error {
                                Some(e) => {
                                    let v = e.max(1e-12).log10();
                                    HeatCell {
                                        color: sequential(scaled(v, elo, ehi)),
                                        text: format!("{e:.1e}"),
                                    }
                                }
                                None => HeatCell {
                                    color: if x.outcome.ok() {
                                        [220, 220, 220]
                                    } else {
                                        status_color(st)
                                    },
                                    text: if x.outcome.ok() {
                                        "no ref".into()
                                    } else {
                                        failed_text
                                    },
                                },
                            },
                        }
                    }
                })
                .collect()
        })
        .collect();
    let legend: Vec<(String, [u8; 3])> = match kind {
        MapKind::Status => {
            let mut seen: Vec<(String, [u8; 3])> = Vec::new();
            for c in &sweep.cells {
                let s = &c.outcome.status;
                if !seen.iter().any(|(n, _)| n == s.name()) {
                    seen.push((s.name().to_string(), status_color(s)));
                }
            }
            seen
        }
        MapKind::Wall => ramp_legend(wlo, whi, "s"),
        MapKind::Error => ramp_legend(elo, ehi, ""),
    };
    let what = match kind {
        MapKind::Status => "status",
        MapKind::Wall => "wall time (colour: log10)",
        MapKind::Error => "relative L2 error of ‖f_c‖(t) vs reference (colour: log10)",
    };
    HeatMap {
        title: format!("{}: {what}", sweep.case),
        row_labels: rows
            .iter()
            .map(|(m, it, mo)| format!("{} {} order {mo}", m.name(), it.name()))
            .collect(),
        col_labels: cols
            .iter()
            .map(|(kn, fr, ev)| {
                vec![
                    format!("k_n {kn:.0e}"),
                    format!("friction {}", on_off(*fr)),
                    format!("events {}", on_off(*ev)),
                ]
            })
            .collect(),
        cells,
        legend,
        cell_size: (104, 30),
        row_label_width: 230,
    }
}

fn bounds(v: &[f64]) -> (f64, f64) {
    v.iter()
        .filter(|x| x.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
            (a.min(x), b.max(x))
        })
}

fn ramp_legend(lo: f64, hi: f64, unit: &str) -> Vec<(String, [u8; 3])> {
    if !(lo.is_finite() && hi.is_finite()) {
        return Vec::new();
    }
    (0..5)
        .map(|k| {
            let f = k as f64 / 4.0;
            let v = lo + f * (hi - lo);
            (format!("{:.1e} {unit}", 10f64.powf(v)), sequential(f))
        })
        .collect()
}

/// Writes `dir/stability.json`, `dir/stability.md` and the heat maps
/// `dir/stability_{status,wall,error}.{svg,png}`; returns the files written.
pub fn write_outputs(sweep: &Sweep, dir: &Path, charts: bool) -> Result<Vec<PathBuf>, Error> {
    crate::files::create_dir(dir)?;
    let write = |name: &str, text: String| -> Result<PathBuf, Error> {
        let p = dir.join(name);
        crate::files::write_atomic(&p, text)?;
        Ok(p)
    };
    let mut files = vec![
        write("stability.json", sweep_json(sweep).to_string())?,
        write("stability.md", markdown_table(sweep))?,
    ];
    if charts {
        for (kind, name) in [
            (MapKind::Status, "stability_status"),
            (MapKind::Wall, "stability_wall"),
            (MapKind::Error, "stability_error"),
        ] {
            files.extend(heat_map(sweep, kind).write(&dir.join(name))?);
        }
    }
    Ok(files)
}

/// The JSON document of a sweep (what `stability.json` holds): the options, models,
/// references and every cell, plus the ‖f_c‖ curves of the references.
pub(crate) fn sweep_json(sweep: &Sweep) -> serde_json::Value {
    let mut v = serde_json::to_value(sweep).unwrap_or(serde_json::Value::Null);
    if let Some(refs) = v.get_mut("references").and_then(|r| r.as_array_mut()) {
        for (j, r) in refs.iter_mut().zip(&sweep.references) {
            j["t"] = serde_json::json!(r.outcome.curves.t);
            j["contact_force_norm"] = serde_json::json!(r.outcome.curves.contact_force_norm);
        }
    }
    v
}

/// The stability study of a case (what `jointrom stability CASE` runs): loads the case, runs the
/// sweep of `opts`, writes `out/CASE/stability.{json,md}` and, with `charts`, the heat maps.
/// Returns a summary: the output folder, files, number of cells, failed cells by status, the
/// total wall time.
pub fn stability_study(
    case: &str,
    out: &Path,
    charts: bool,
    opts: &SweepOptions,
) -> Result<serde_json::Value, Error> {
    let t0 = Instant::now();
    let model = Model::from_case_name(case)?;
    let sweep = run_sweep_model(&model, t0.elapsed().as_secs_f64(), opts)?;
    let dir = out.join(crate::files::safe_name(&sweep.case));
    let files = write_outputs(&sweep, &dir, charts)?;
    let mut by_status = std::collections::BTreeMap::<String, usize>::new();
    for c in &sweep.cells {
        *by_status
            .entry(c.outcome.status.name().to_string())
            .or_default() += 1;
    }
    Ok(serde_json::json!({
        "dir": dir,
        "files": files,
        "cells": sweep.cells.len(),
        "status_counts": by_status,
        "wall_s": sweep.wall_s,
    }))
}
