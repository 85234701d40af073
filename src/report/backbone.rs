//! A backbone's outputs ([`crate::studies::backbone`]): a CSV of every extracted cycle, charts of
//! frequency (relative to the linearised model's) and damping ratio against the modal amplitude
//! on a log axis, and a markdown table of the first cycle of each ring-down.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::error::Error;
use crate::report::chart::{LineChart, Reference, Series};
use crate::studies::backbone::Backbone;

/// The CSV of every cycle: `mode, amplitude_mm, cycle, t_start_s, t_end_s,
/// modal_amplitude_mm, master_amplitude_mm, frequency_hz, frequency_ratio, damping_ratio,
/// dissipated_nmm` (`frequency_ratio` = frequency / the linearised model's; an empty
/// master amplitude where the mode does not move the master).
pub fn csv(b: &Backbone) -> String {
    let mut s = String::from(
        "mode,amplitude_mm,cycle,t_start_s,t_end_s,modal_amplitude_mm,master_amplitude_mm,\
         frequency_hz,frequency_ratio,damping_ratio,dissipated_nmm\n",
    );
    for m in &b.modes {
        for r in &m.ring_downs {
            for c in &r.cycles {
                let master = c
                    .master_amplitude
                    .map(|v| format!("{v:e}"))
                    .unwrap_or_default();
                let _ = writeln!(
                    s,
                    "{},{:e},{},{:e},{:e},{:e},{},{:e},{:e},{:e},{:e}",
                    m.mode,
                    r.amplitude,
                    c.cycle,
                    c.t_start,
                    c.t_end,
                    c.modal_amplitude,
                    master,
                    c.frequency_hz,
                    c.frequency_hz / m.linear_frequency_hz,
                    c.damping_ratio,
                    c.dissipated
                );
            }
        }
    }
    s
}

/// Every cycle of mode `m` as (modal amplitude, value).
fn points(
    b: &Backbone,
    value: impl Fn(f64, &crate::studies::backbone::Cycle) -> f64,
) -> Vec<Series> {
    b.modes
        .iter()
        .map(|m| {
            let mut p: Vec<(f64, f64)> = m
                .ring_downs
                .iter()
                .flat_map(|r| r.cycles.iter())
                .map(|c| (c.modal_amplitude, value(m.linear_frequency_hz, c)))
                .filter(|(x, y)| x.is_finite() && *x > 0.0 && y.is_finite())
                .collect();
            p.sort_by(|a, b| a.0.total_cmp(&b.0));
            Series::new(
                format!("mode {} ({:.1} Hz)", m.mode, m.linear_frequency_hz),
                p,
            )
        })
        .collect()
}

/// Writes `STEM_frequency.{svg,png}` and `STEM_damping.{svg,png}` into `dir` (nothing when no
/// cycle was extracted); returns the paths written.
pub fn charts(b: &Backbone, dir: &Path, stem: &str) -> Result<Vec<PathBuf>, Error> {
    let title = format!("{} model, preload {}", b.model, b.preload);
    let mut f = LineChart::new(
        format!("Backbone: frequency / linearised frequency — {title}"),
        "modal amplitude (largest nodal translation), mm",
        "f / f_linearised",
    );
    f.x_log = true;
    f.series = points(b, |f0, c| c.frequency_hz / f0);
    f.references.push(Reference::new("linearised", 1.0));
    let mut d = LineChart::new(
        format!("Backbone: damping ratio — {title}"),
        "modal amplitude (largest nodal translation), mm",
        "equivalent viscous damping ratio ζ",
    );
    d.x_log = true;
    d.series = points(b, |_, c| c.damping_ratio);
    let mut out = Vec::new();
    // A backbone without a single extracted cycle (every decay too short or failed, said in
    // its warnings) has nothing to draw.
    if f.series.iter().all(|s| s.points.is_empty()) {
        return Ok(out);
    }
    out.extend(f.write(&dir.join(format!("{stem}_frequency")))?);
    out.extend(d.write(&dir.join(format!("{stem}_damping")))?);
    Ok(out)
}

/// A markdown table of the first cycle of each ring-down (mode, amplitude, frequency and its
/// ratio to the linearised one, damping ratio, CPU time), with the warnings.
pub fn markdown(b: &Backbone) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "Model `{}` (size {}), preload S = {} (master load {:?}), {} of {} pairs closed at the \
         equilibrium, friction {}; ring-downs {:.2} s CPU in all.\n",
        b.model,
        b.model_size,
        b.preload,
        b.preload_load,
        b.closed_pairs,
        b.pairs,
        if b.friction { "on" } else { "off" },
        b.ring_down_cpu_s
    );
    if let (Some(r0), Some(w)) = (b.tolerance_model_size, b.attachment_pairs) {
        let _ = writeln!(
            s,
            "The tolerance model (r = {r0}) enriched for the backbone: the full model's \
             equilibrium, linearised modes (stuck and slipped) and the attachment modes of its \
             {w} pairs. Full model's linearisation: {}.\n",
            b.modes
                .iter()
                .filter_map(|m| m
                    .full_linear_frequency_hz
                    .map(|f| format!("mode {} {f:.3} Hz", m.mode)))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    s.push_str(
        "| mode | f_lin (Hz) | A (mm) | Ā first cycle (mm) | f (Hz) | f / f_lin | ζ | CPU (s) |\n\
         |---:|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    for m in &b.modes {
        for r in &m.ring_downs {
            match r.first() {
                Some(c) => {
                    let _ = writeln!(
                        s,
                        "| {} | {:.3} | {:.3e} | {:.3e} | {:.4} | {:.5} | {:.3e} | {:.3} |",
                        m.mode,
                        m.linear_frequency_hz,
                        r.amplitude,
                        c.modal_amplitude,
                        c.frequency_hz,
                        c.frequency_hz / m.linear_frequency_hz,
                        c.damping_ratio,
                        r.cpu_s
                    );
                }
                None => {
                    let _ = writeln!(
                        s,
                        "| {} | {:.3} | {:.3e} | — | — | — | — | {:.3} |",
                        m.mode, m.linear_frequency_hz, r.amplitude, r.cpu_s
                    );
                }
            }
        }
    }
    for w in &b.warnings {
        let _ = writeln!(s, "\n- warning: {w}");
    }
    s
}
