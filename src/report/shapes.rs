//! Seeing the shapes (the paper's Figs. 3–6, 14, 20): the Craig–Bampton trial vectors, the trial
//! vector derivatives (Algorithm 2, eq. 16) and the joint modes Φ̃_T (the K-weighted POD of the
//! TVD, eqs. 24–25) as VTU files for ParaView ([`crate::report::vtu`]), and the first joint modes as a
//! PNG/SVG picture for the report.
//!
//! The picture shows what a joint mode does in the joint: one panel per mode, every joint pair
//! at its (x, z) position, coloured by its normal gap `g_k = b_k φ` (paper eq. 9's B_n rows)
//! relative to the mode's largest |g|: blue closes the joint (g < 0, penetration that the
//! contact stiffness resists), red opens it, white leaves it unchanged.

use std::path::{Path, PathBuf};

use faer::{Mat, MatRef};
use plotters::prelude::*;

use crate::error::{Error, ReportError};
use crate::joint::NORMAL;
use crate::model::Model;
use crate::reduction::{craig_bampton, pod_tvd, trial_vector_derivatives, TvdOptions};
use crate::report::chart::{chart_error, ensure_font, FAMILY};

/// The shapes of a case's TVD basis.
pub struct Shapes {
    /// Craig–Bampton `[Φ_S Φ_V]` (n × (6 + ν)).
    pub craig_bampton: Mat<f64>,
    /// The first TVD columns (K-normalized), n × count.
    pub tvd: Mat<f64>,
    /// The first joint modes (K-orthonormal POMs of the weighted POD), n × count.
    pub joint_modes: Mat<f64>,
    /// Their POD eigenvalues λ (energy), descending.
    pub lambda: Vec<f64>,
}

/// Computes the shapes: ν fixed-interface modes, the TVD and their weighted POD; keeps the first
/// `count` TVD and joint modes.
pub fn shapes(model: &Model, nu: usize, count: usize) -> Result<Shapes, Error> {
    let cb = craig_bampton(model, nu)?;
    let tvd = trial_vector_derivatives(model, cb.as_ref(), &TvdOptions::default())?;
    let pod = pod_tvd(model, &tvd, true)?;
    let k = count.min(tvd.vectors.ncols());
    let tvd_first = tvd.vectors.as_ref().subcols(0, k).to_owned();
    let jm = pod.leading(count).to_owned();
    let lambda = pod.lambda.iter().take(jm.ncols()).copied().collect();
    Ok(Shapes {
        craig_bampton: cb,
        tvd: tvd_first,
        joint_modes: jm,
        lambda,
    })
}

/// Writes `craig_bampton.vtu`, `tvd.vtu`, `joint_modes.vtu` and the picture of the first (up
/// to) four joint modes (`joint_modes.png`, `.svg`) into `dir`; returns the paths.
pub fn write_shapes(model: &Model, s: &Shapes, dir: &Path) -> Result<Vec<PathBuf>, Error> {
    crate::files::create_dir(dir)?;
    let mut files = Vec::new();
    for (name, m) in [
        ("craig_bampton", &s.craig_bampton),
        ("tvd", &s.tvd),
        ("joint_mode", &s.joint_modes),
    ] {
        let file = dir.join(format!(
            "{}.vtu",
            if name == "joint_mode" {
                "joint_modes"
            } else {
                name
            }
        ));
        crate::report::vtu::write_shapes(model, name, m.as_ref(), &file)?;
        files.push(file);
    }
    let k = s.joint_modes.ncols().min(4);
    if k > 0 {
        files.extend(render_joint_modes(
            model,
            s.joint_modes.as_ref().subcols(0, k),
            &dir.join("joint_modes"),
        )?);
    }
    Ok(files)
}

/// Blue (−1) – white (0) – red (+1).
fn diverging(v: f64) -> RGBColor {
    let v = v.clamp(-1.0, 1.0);
    let f = |a: f64| (255.0 * a).round() as u8;
    if v < 0.0 {
        let a = 1.0 + v; // 0 at −1
        RGBColor(f(0.15 + 0.85 * a), f(0.3 + 0.7 * a), 255)
    } else {
        let a = 1.0 - v;
        RGBColor(255, f(0.2 + 0.8 * a), f(0.15 + 0.85 * a))
    }
}

/// Draws `modes` (n × k, k ≤ 4) as panels of the joint pairs' normal gaps (see the module docs)
/// to `<stem>.png` and `<stem>.svg`.
pub(crate) fn render_joint_modes(
    model: &Model,
    modes: MatRef<'_, f64>,
    stem: &Path,
) -> Result<Vec<PathBuf>, Error> {
    if modes.nrows() != model.dofs() {
        return Err(ReportError::Rows {
            what: "joint-mode picture: modes",
            rows: modes.nrows(),
            dofs: model.dofs(),
        }
        .into());
    }
    ensure_font()?;
    let w = model.joint.pairs();
    let pos: Vec<(f64, f64)> = model
        .pairs
        .iter()
        .enumerate()
        .map(|(i, p)| {
            // In the joint plane: (t1 · x, t2 · x); (x, z) for generated sheets.
            let x = model.pair_position(i);
            let dot = |t: [f64; 3]| t[0] * x[0] + t[1] * x[1] + t[2] * x[2];
            (dot(p.t1), dot(p.t2))
        })
        .collect();
    let mut gaps = vec![vec![0.0; w]; modes.ncols()];
    for (c, g) in gaps.iter_mut().enumerate() {
        for (k, gk) in g.iter_mut().enumerate() {
            *gk = model
                .joint
                .row(3 * k + NORMAL)
                .map(|(d, v)| v * modes[(d, c)])
                .sum();
        }
    }
    let png = stem.with_extension("png");
    let svg = stem.with_extension("svg");
    let size = (1000, 700);
    crate::files::write_atomic_with(&png, |tmp| {
        draw_panels(
            BitMapBackend::new(tmp, size).into_drawing_area(),
            &model.name,
            &pos,
            &gaps,
        )
        .map_err(|e| chart_error(&png, e))
    })?;
    crate::files::write_atomic_with(&svg, |tmp| {
        draw_panels(
            SVGBackend::new(tmp, size).into_drawing_area(),
            &model.name,
            &pos,
            &gaps,
        )
        .map_err(|e| chart_error(&svg, e))
    })?;
    Ok(vec![png, svg])
}

fn draw_panels<DB>(
    root: DrawingArea<DB, plotters::coord::Shift>,
    case: &str,
    pos: &[(f64, f64)],
    gaps: &[Vec<f64>],
) -> Result<(), String>
where
    DB: DrawingBackend,
    DB::ErrorType: 'static,
{
    let err = |e: &dyn std::fmt::Display| e.to_string();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let root = root
        .titled(
            &format!("{case}: first joint modes — normal gap of each joint pair (blue closes, red opens)"),
            (FAMILY, 20),
        )
        .map_err(|e| err(&e))?;
    let (x0, x1) = pos.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |a, p| {
        (a.0.min(p.0), a.1.max(p.0))
    });
    let (z0, z1) = pos.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |a, p| {
        (a.0.min(p.1), a.1.max(p.1))
    });
    if !(x0.is_finite() && z0.is_finite()) {
        return Err("no joint pairs to draw".into());
    }
    let pad = |a: f64, b: f64| {
        let m = 0.08 * (b - a).max(1.0);
        (a - m, b + m)
    };
    let (x0, x1) = pad(x0, x1);
    let (z0, z1) = pad(z0, z1);
    let panels = root.split_evenly((2, 2));
    for (c, (panel, g)) in panels.iter().zip(gaps).enumerate() {
        let gmax = g.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let mut chart = ChartBuilder::on(panel)
            .caption(
                format!("joint mode {} (max |g| = {gmax:.2e} mm)", c + 1),
                (FAMILY, 16),
            )
            .margin(10)
            .x_label_area_size(35)
            .y_label_area_size(50)
            .build_cartesian_2d(x0..x1, z0..z1)
            .map_err(|e| err(&e))?;
        chart
            .configure_mesh()
            .x_desc("along t1 (x for sheets), mm")
            .y_desc("along t2 (z), mm")
            .label_style((FAMILY, 12))
            .axis_desc_style((FAMILY, 13))
            .draw()
            .map_err(|e| err(&e))?;
        let scale = if gmax > 0.0 { 1.0 / gmax } else { 0.0 };
        chart
            .draw_series(
                pos.iter().zip(g).map(|(&p, &v)| {
                    Circle::new(p, 7, ShapeStyle::from(diverging(v * scale)).filled())
                }),
            )
            .map_err(|e| err(&e))?;
        chart
            .draw_series(
                pos.iter()
                    .map(|&p| Circle::new(p, 7, BLACK.stroke_width(1))),
            )
            .map_err(|e| err(&e))?;
    }
    root.present().map_err(|e| err(&e))?;
    Ok(())
}
