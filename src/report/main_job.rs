//! The main job's report, `jointrom run` (steps 4–6 of [`crate::studies::main_job`]): the
//! study's charts, ‖f_c‖(t), ‖f_R‖(t), master u_y(t) and speed against accuracy, the first joint
//! modes (VTU and a picture), the stored stability map, `report.md` and `results.json`.

use std::path::{Path, PathBuf};
use std::time::Instant;

use crate::error::Error;
use crate::model::Model;
use crate::reduction::BasisOptions;
use crate::report::chart::{LegendPosition, LineChart, Reference, Series};
use crate::studies::convergence as study;
use crate::studies::main_job::{run_main_job, Progress, Report, ReportOptions, RunRecord};

/// Runs the main job on `model` and writes the report into `dir` (created if missing);
/// `extra` fields are added to `results.json`. No progress is reported (see
/// [`run_report_observed`]).
///
/// # Errors
/// Building the model's bases or the full reference run failing, charts or files that cannot be
/// written. Reduced runs that fail are recorded with their status, not errors.
pub fn run_report(
    model: &Model,
    dir: &Path,
    opts: &ReportOptions,
    extra: serde_json::Map<String, serde_json::Value>,
) -> Result<Report, Error> {
    run_report_observed(model, dir, opts, extra, &mut |_| {})
}

/// [`run_report`], reporting its progress to `observer` when [`ReportOptions::progress`] is set.
///
/// # Errors
/// As [`run_report`].
pub fn run_report_observed(
    model: &Model,
    dir: &Path,
    opts: &ReportOptions,
    extra: serde_json::Map<String, serde_json::Value>,
    observer: &mut dyn FnMut(&Progress),
) -> Result<Report, Error> {
    let t_all = Instant::now();
    crate::files::create_dir(dir)?;
    let mut report = run_main_job(model, opts, extra, observer)?;
    write_report(model, dir, opts, &mut report, t_all)?;
    Ok(report)
}

/// Writes the report of a finished main job into `dir`: the charts, the joint modes, the stored
/// stability map, `results.json` and `report.md`; adds the files written to `report.files` and
/// sets `report.total_s` from `t_all` (the job's start).
///
/// # Errors
/// Charts or files that cannot be written.
pub fn write_report(
    model: &Model,
    dir: &Path,
    opts: &ReportOptions,
    report: &mut Report,
    t_all: Instant,
) -> Result<(), Error> {
    let case = report.case.clone();
    // The static study's charts.
    let study_dir = dir.join("study");
    crate::files::create_dir(&study_dir)?;
    for f in crate::report::convergence::write_charts(&report.study, &study_dir)? {
        report.files.push(relative(dir, &f));
    }
    // 4. Charts.
    for f in time_charts(report, dir)? {
        report.files.push(relative(dir, &f));
    }
    for f in speed_chart(report, dir)? {
        report.files.push(relative(dir, &f));
    }
    if let Some(c) = hysteresis_chart(report) {
        for f in c.write(&dir.join("hysteresis"))? {
            report.files.push(relative(dir, &f));
        }
    }
    // Joint modes: VTU for ParaView and the picture of the first four.
    let shape_dir = dir.join("shapes");
    let sh = crate::report::shapes::shapes(model, BasisOptions::default().nu, 12)?;
    for f in crate::report::shapes::write_shapes(model, &sh, &shape_dir)? {
        report.files.push(relative(dir, &f));
    }
    // The backbone's charts.
    if let Some(b) = &report.backbone {
        for f in crate::report::backbone::charts(b, dir, "backbone")? {
            report.files.push(relative(dir, &f));
        }
    }
    // 5. The stored stability map.
    let stab = opts.stability_dir.join(&case);
    let mut stability_files = Vec::new();
    for name in ["stability_status", "stability_error", "stability_wall"] {
        for ext in ["png", "svg"] {
            let src = stab.join(format!("{name}.{ext}"));
            if src.is_file() {
                let dst = dir.join(format!("{name}.{ext}"));
                crate::files::write_atomic_with(&dst, |tmp| std::fs::copy(&src, tmp).map(|_| ()))?;
                stability_files.push(relative(dir, &dst));
            }
        }
    }
    report.files.extend(stability_files.iter().cloned());
    report.total_s = t_all.elapsed().as_secs_f64();

    // 6. Files.
    let json = dir.join("results.json");
    write(
        &json,
        &serde_json::to_string_pretty(report).expect("the report serialises"),
    )?;
    let md = dir.join("report.md");
    let text = markdown(report, &stab, !stability_files.is_empty());
    write(&md, &text)?;
    // The same report as one self-contained page (images inlined).
    let page = crate::report::html::render(&text, dir, &format!("jointrom report: {case}"))?;
    write(&dir.join("report.html"), &page)?;
    report.files.push("results.json".into());
    report.files.push("report.md".into());
    report.files.push("report.html".into());
    Ok(())
}

fn write(path: &Path, text: &str) -> Result<(), Error> {
    crate::files::write_atomic(path, text)
}

fn relative(dir: &Path, f: &Path) -> String {
    f.strip_prefix(dir).unwrap_or(f).display().to_string()
}

/// Selects one output curve of a run.
type Curve = fn(&RunRecord) -> &[f64];

/// ‖f_c‖(t), ‖f_R‖(t), u_y(t): full against TVD with g = 0, the paper's sizes and the a-priori g.
fn time_charts(rep: &Report, dir: &Path) -> Result<Vec<PathBuf>, Error> {
    let mut shown: Vec<&RunRecord> = vec![&rep.runs[0]];
    let mut wanted: Vec<usize> = vec![0];
    wanted.extend(rep.paper_anchors.iter().map(|a| a.g).filter(|&g| g > 0));
    if rep.paper_anchors.is_empty() {
        wanted.extend([10, 25]);
    }
    wanted.push(rep.g_chosen);
    wanted.sort_unstable();
    wanted.dedup();
    for g in wanted {
        if let Some(r) = rep.runs.iter().find(|r| {
            r.model == "tvd" && r.g == Some(g) && r.iteration == "newton" && !r.curves.t.is_empty()
        }) {
            shown.push(r);
        }
    }
    if let Some(h) = rep.headline.and_then(|i| rep.runs.get(i)) {
        shown.push(h);
    }
    let mut files = Vec::new();
    let quantities: [(&str, &str, &str, &str, Curve); 4] = [
        (
            "fc",
            "contact force norm ‖f_c‖",
            "‖f_c‖ (N)",
            "N",
            |r| &r.curves.contact_force_norm,
        ),
        (
            "fr",
            "friction force norm ‖f_R‖",
            "‖f_R‖ (N)",
            "N",
            |r| &r.curves.friction_force_norm,
        ),
        ("uy", "master displacement u_y", "u_y (mm)", "mm", |r| {
            &r.curves.master_uy
        }),
        (
            "dissipated",
            "dissipated energy D of the joint",
            "D (N·mm)",
            "N·mm",
            |r| &r.curves.dissipated,
        ),
    ];
    for (stem, what, axis, unit, get) in quantities {
        files.extend(
            history_chart(rep, &shown, what, axis, unit, get)
                .write(&dir.join(format!("{stem}_t")))?,
        );
        if let Some(c) = error_chart(rep, &shown, what, get) {
            files.extend(c.write(&dir.join(format!("{stem}_err_t")))?);
        }
    }
    Ok(files)
}

/// The joint's hysteresis at the pair that dissipates most: tangential force against relative
/// tangential displacement, full run and headline model.
fn hysteresis_chart(rep: &Report) -> Option<LineChart> {
    let h = rep.hysteresis.as_ref()?;
    let mut c = LineChart::new(
        format!(
            "{}: hysteresis of pair {} (dissipates most: {:.3e} N·mm in the full run)",
            rep.case, h.pair, h.dissipated
        ),
        "relative tangential displacement (mm)",
        "tangential force (N)",
    );
    c.legend = LegendPosition::UpperRight;
    let headline = rep.headline.and_then(|i| rep.runs.get(i));
    for (label, pts) in [
        (format!("full FE ({} DOF)", rep.dofs), &h.full),
        (
            headline.map_or("headline model".into(), |r| run_label(rep, r)),
            &h.reduced,
        ),
    ] {
        let mut s = Series::new(label, pts.clone());
        s.markers = false;
        c.series.push(s);
    }
    Some(c)
}

/// The legend text of a run in the time charts.
fn run_label(rep: &Report, r: &RunRecord) -> String {
    if r.model == "full" {
        format!("full FE ({} DOF)", r.size)
    } else if let Some((tol, _)) = r.tolerance {
        format!("adaptive, TOL {tol:.0e} (r = {})", r.size)
    } else if r.g == Some(rep.g_chosen) {
        format!("TVD g = {} (a priori, w ≥ {})", rep.g_chosen, rep.threshold)
    } else {
        format!("TVD g = {}", r.g.unwrap_or(0))
    }
}

/// How far beyond the full run's range a series may reach before it is drawn off scale: a
/// series that dwarfs the others (g = 0's 55 N against 2.5 N) would flatten the curves that
/// matter into the axis.
const OFF_SCALE: f64 = 3.0;

/// One quantity's history, full FE against the reduced models. The y range is the full run's
/// (and every series within [`OFF_SCALE`] of it); a series beyond is cut at the frame and its
/// legend gives its peak.
fn history_chart(
    rep: &Report,
    shown: &[&RunRecord],
    what: &str,
    axis: &str,
    unit: &str,
    get: Curve,
) -> LineChart {
    let mut c = LineChart::new(
        format!("{}: {what}, full FE vs reduced models", rep.case),
        "t (s)",
        axis,
    );
    c.legend = LegendPosition::UpperRight;
    let extent = |r: &RunRecord| {
        get(r)
            .iter()
            .filter(|v| v.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
                (lo.min(v), hi.max(v))
            })
    };
    let (flo, fhi) = extent(shown[0]);
    let span = (fhi - flo)
        .max(fhi.abs().max(flo.abs()) * 1e-6)
        .max(f64::MIN_POSITIVE);
    let in_scale =
        |(lo, hi): (f64, f64)| lo >= flo - OFF_SCALE * span && hi <= fhi + OFF_SCALE * span;
    let mut range = (flo, fhi);
    let mut off = false;
    for r in shown {
        let e = extent(r);
        if e.0 > e.1 {
            continue;
        }
        if in_scale(e) {
            range = (range.0.min(e.0), range.1.max(e.1));
        } else {
            off = true;
        }
    }
    for r in shown {
        let e = extent(r);
        let mut text = run_label(rep, r);
        if off && e.0 <= e.1 && !in_scale(e) {
            let peak = if e.1.abs() >= e.0.abs() { e.1 } else { e.0 };
            text = format!("{text} — off scale, peak {peak:.3} {unit}");
        }
        let mut s = Series::new(
            text,
            r.curves
                .t
                .iter()
                .copied()
                .zip(get(r).iter().copied())
                .collect(),
        );
        s.markers = false;
        c.series.push(s);
    }
    if off {
        let pad = 0.08 * (range.1 - range.0).max(span);
        c.y_range = Some((range.0 - pad, range.1 + pad));
    }
    c
}

/// The reduced models' error over time, `|q_ROM(t) − q_full(t)| / max_t |q_full|`, on a log
/// axis: where the histories lie on top of each other this is what tells them apart. `None`
/// without a full run to compare with.
fn error_chart(rep: &Report, shown: &[&RunRecord], what: &str, get: Curve) -> Option<LineChart> {
    let full = shown.first().filter(|r| r.model == "full")?;
    let reference = get(full);
    let scale = reference.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if !(scale > 0.0 && scale.is_finite()) {
        return None;
    }
    let mut c = LineChart::new(
        format!("{}: error of {what} against full FE", rep.case),
        "t (s)",
        "|ROM − full| / max |full| (log)",
    );
    c.y_log = true;
    c.legend = LegendPosition::LowerRight;
    for (k, r) in shown.iter().enumerate().skip(1) {
        // The runs share the output times; a run that stopped early is compared where it ran.
        let pts: Vec<(f64, f64)> = r
            .curves
            .t
            .iter()
            .zip(get(r))
            .zip(reference)
            .map(|((&t, &q), &q0)| (t, (q - q0).abs() / scale))
            .collect();
        let mut s = Series::new(run_label(rep, r), pts);
        s.markers = false;
        // The colour the run has in the history chart.
        s.color = Some(k);
        c.series.push(s);
    }
    // Errors at round-off level (or exactly zero) are not drawn on the log axis.
    let drawable = c.series.iter().any(|s| s.points.iter().any(|p| p.1 > 0.0));
    drawable.then_some(c)
}

/// CPU time against the ‖f_c‖ error, one scatter series per (basis kind, iteration), the Pareto
/// front, the full run's CPU time and the paper's ratios as vertical lines.
fn speed_chart(rep: &Report, dir: &Path) -> Result<Vec<PathBuf>, Error> {
    let mut c = LineChart::new(
        format!(
            "{}: speed against accuracy ({} s window)",
            rep.case, rep.end_time
        ),
        "integration CPU time (s)",
        "relative L2 error of ‖f_c‖(t) vs full FE",
    );
    c.x_log = true;
    c.y_log = true;
    c.legend = LegendPosition::LowerLeft;
    c.size = (1100, 700);
    let mut groups: Vec<(String, String)> = Vec::new();
    for r in rep.runs.iter().skip(1) {
        let key = (r.model.clone(), r.iteration.clone());
        if !groups.contains(&key) {
            groups.push(key);
        }
    }
    for (model, it) in &groups {
        let pts: Vec<(f64, f64)> = rep
            .runs
            .iter()
            .filter(|r| &r.model == model && &r.iteration == it)
            .filter_map(|r| r.error_fc.map(|e| (r.cpu_s, e.max(study::ERROR_FLOOR))))
            .collect();
        if !pts.is_empty() {
            c.series
                .push(Series::scatter(format!("{model} ({it})"), pts));
        }
    }
    let mut front: Vec<(f64, f64)> = rep
        .runs
        .iter()
        .filter(|r| r.pareto)
        .filter_map(|r| r.error_fc.map(|e| (r.cpu_s, e.max(study::ERROR_FLOOR))))
        .collect();
    front.sort_by(|a, b| a.0.total_cmp(&b.0));
    if !front.is_empty() {
        let mut s = Series::new("Pareto front", front);
        s.markers = false;
        c.series.push(s);
    }
    let full_cpu = rep.runs[0].cpu_s;
    if full_cpu.is_finite() && full_cpu > 0.0 {
        c.x_references.push(Reference {
            label: format!("full FE, Newton: {full_cpu:.2} s"),
            value: full_cpu,
            color: None,
        });
        for a in &rep.paper_anchors {
            c.x_references.push(Reference {
                label: format!("paper: g = {} at {} % of full", a.g, a.cpu_percent),
                value: full_cpu * a.cpu_percent / 100.0,
                color: Some([150, 150, 150]),
            });
        }
    }
    c.references.push(Reference {
        label: "2 % (accuracy target)".into(),
        value: 0.02,
        color: Some([200, 0, 0]),
    });
    if c.series.is_empty() {
        return Ok(Vec::new());
    }
    Ok(c.write(&dir.join("speed_accuracy"))?.to_vec())
}

fn fmt_opt(v: Option<f64>, prec: usize) -> String {
    v.map_or("–".into(), |x| format!("{x:.prec$e}"))
}

fn markdown(rep: &Report, stab: &Path, stability: bool) -> String {
    use std::fmt::Write;
    let mut s = String::new();
    let full = &rep.runs[0];
    let _ = writeln!(s, "# jointrom report: {}\n", rep.case);
    let _ = writeln!(
        s,
        "Command: `{}` — {} DOF, {} joint pairs, transient window {} s{}, whole job {:.1} s. \
         Every figure below was measured in this run on this machine.\n",
        rep.command_line.join(" "),
        rep.dofs,
        rep.pairs,
        rep.end_time,
        if rep.quick { " (quick)" } else { "" },
        rep.total_s
    );
    let _ = writeln!(s, "## Summary\n");
    let _ = writeln!(
        s,
        "A-priori size: g = {} joint modes (smallest g with w(g) ≥ {}, eq. 26). Full FE \
         reference: BDF + Newton, {} steps, {:.2} s CPU.\n",
        rep.g_chosen, rep.threshold, full.stats.steps, full.cpu_s
    );
    headline(&mut s, rep);
    runs_table(&mut s, rep);
    let _ = writeln!(
        s,
        "\nErrors are relative L2 over the output times (every 1e-4 s) against the full FE run; \
         `est.` is each reduced run's own error estimate (no full run needed: the quasi-static \
         joint correction, the truncated modes' dynamics and an integration check, see \
         `src/reduction/estimate.rs`), to be read against the true error beside it. \
         CPU is the integrating thread's CPU time; basis construction is \
         extra (`build_s` in `results.json`). A run that does not finish within its wall-clock \
         budget is recorded as `budget` with the time it reached.\n"
    );
    if !rep.paper_anchors.is_empty() {
        let _ = writeln!(s, "Paper (Sections 4.1.5, 4.2.4), CPU time of the reduced integration in % of the full FE model:");
        for a in &rep.paper_anchors {
            let ours = rep
                .runs
                .iter()
                .find(|r| r.model == "tvd" && r.g == Some(a.g) && r.iteration == "newton")
                .and_then(|r| r.cpu_percent);
            let _ = writeln!(
                s,
                "- g = {}: paper {} %, here {}",
                a.g,
                a.cpu_percent,
                ours.map_or("not run".into(), |p| format!("{p:.2} %"))
            );
        }
        let _ = writeln!(s);
    }
    let _ = writeln!(
        s,
        "## Transient: full FE against TVD reduced models (Figs. 9, 11, 12, 17, 18)\n"
    );
    let _ = writeln!(
        s,
        "Each quantity twice: its history (a model far off the full run's range is cut at the \
         frame, its legend gives its peak), and each reduced model's error against the full run \
         on a log scale, relative to the full run's peak.\n"
    );
    for (stem, what) in [
        ("fc", "contact force norm"),
        ("fr", "friction force norm"),
        ("uy", "master displacement"),
        ("dissipated", "dissipated energy D of the joint"),
    ] {
        let _ = writeln!(s, "![{what}]({stem}_t.png)\n");
        if rep.files.iter().any(|f| *f == format!("{stem}_err_t.png")) {
            let _ = writeln!(s, "![error of the {what}]({stem}_err_t.png)\n");
        }
    }
    let end = |r: &RunRecord| r.curves.dissipated.last().copied();
    if let (Some(full), Some(h)) = (
        rep.runs.first().and_then(end).filter(|&d| d > 0.0),
        rep.headline.and_then(|i| rep.runs.get(i)).and_then(end),
    ) {
        let _ = writeln!(
            s,
            "The joint's dissipated energy at the end of the run (`joint_dissipated_energy`, \
             mesh-independent): full FE {full:.6} N·mm, headline model {h:.6} N·mm ({:+.2} %).\n",
            100.0 * (h / full - 1.0)
        );
    }
    if rep.files.iter().any(|f| f == "hysteresis.png") {
        let _ = writeln!(
            s,
            "The joint's dissipated energy D(t) and the hysteresis of the pair that dissipates \
             most (tangential force against relative tangential displacement along its main \
             direction of friction), full FE against the headline model:\n\n\
             ![hysteresis](hysteresis.png)\n"
        );
    }
    let _ = writeln!(s, "## Speed against accuracy\n");
    let _ = writeln!(
        s,
        "One point per (basis, size, iteration); the line joins the Pareto front; vertical lines: \
         the full run's CPU time and the paper's CPU ratios applied to it.\n\n![speed against accuracy](speed_accuracy.png)\n"
    );
    let _ = writeln!(s, "## Joint modes (Figs. 3–6, 14)\n");
    let _ = writeln!(
        s,
        "The first joint modes Φ̃_T (K-weighted POD of the TVD) as the normal gap they give each \
         joint pair (blue closes, red opens; the sign of a mode is arbitrary). ParaView files of \
         the Craig–Bampton vectors, the first TVD and joint modes: `shapes/*.vtu`.\n\n\
         ![joint modes](shapes/joint_modes.png)\n"
    );
    backbone_section(&mut s, rep);
    study_section(&mut s, rep);
    stability_section(&mut s, rep, stab, stability);
    s
}

/// The short backbone of mode 1 (`studies::main_job::report_backbone`).
fn backbone_section(s: &mut String, rep: &Report) {
    use std::fmt::Write;
    let _ = writeln!(
        s,
        "## Backbone of mode 1 (reduced model, under the static load)
"
    );
    match (&rep.backbone, &rep.backbone_error) {
        (Some(b), _) => {
            let _ = writeln!(
                s,
                "Free decays of the a-priori TVD model from its equilibrium under the case's \
                 load, displaced by mode 1 of the model linearised with its closed pairs stuck; \
                 frequency and equivalent viscous damping ratio per cycle (`jointrom backbone`, \
                 docs/guide/backbone.md).\n"
            );
            s.push_str(&crate::report::backbone::markdown(b));
            let _ = writeln!(
                s,
                "\n![backbone frequency](backbone_frequency.png)\n\n\
                 ![backbone damping](backbone_damping.png)\n"
            );
        }
        (None, Some(e)) => {
            let _ = writeln!(s, "Not computed: {e}\n");
        }
        (None, None) => {}
    }
}

/// The headline reduced model: the tolerance-chosen one, its true error against its estimate
/// and its speed, beside the paper's a-priori w(g) model.
fn headline(s: &mut String, rep: &Report) {
    use std::fmt::Write;
    let tol = rep.headline_tolerance;
    let Some(h) = rep.headline.and_then(|i| rep.runs.get(i)) else {
        let _ = writeln!(
            s,
            "**Headline reduced model** (tolerance {tol:.0e} on ‖f_c‖, ‖f_R‖, u_y and D): could not \
             be built or run — see the `adaptive` row below.\n"
        );
        return;
    };
    let est = |f: fn(&crate::reduction::CurveErrors) -> Option<f64>| {
        fmt_opt(h.estimate.as_ref().and_then(|e| f(&e.total)), 2)
    };
    let _ = writeln!(
        s,
        "**Headline reduced model** (tolerance {tol:.0e} on ‖f_c‖, ‖f_R‖, u_y and D): Craig–Bampton \
         + the attachment modes of {} pairs, r = {}; errors against the full run (estimated): \
         ‖f_c‖(t) {} ({}), ‖f_R‖(t) {} ({}), u_y {} ({}), D(t) {} ({}), D at the end {} ({}); \
         {:.2} s to build, {:.3} s CPU to run ({} of the full run's CPU).",
        h.g.unwrap_or(0),
        h.size,
        fmt_opt(h.error_fc, 2),
        est(|e| e.contact_force),
        fmt_opt(h.error_fr, 2),
        est(|e| e.friction_force),
        fmt_opt(h.error_uy, 2),
        est(|e| e.master_uy),
        fmt_opt(h.error_d, 2),
        est(|e| e.dissipated),
        fmt_opt(h.error_d_end, 2),
        est(|e| e.dissipated_end),
        h.build_s,
        h.cpu_s,
        h.cpu_percent.map_or("–".into(), |p| format!("{p:.2} %")),
    );
    if let Some(a) = rep
        .runs
        .iter()
        .find(|r| r.model == "tvd" && r.g == Some(rep.g_chosen) && r.iteration == "newton")
    {
        let _ = writeln!(
            s,
            "The paper's a-priori model (TVD, g = {}, w ≥ {}): ‖f_c‖(t) error {} (estimated {}).",
            rep.g_chosen,
            rep.threshold,
            fmt_opt(a.error_fc, 2),
            fmt_opt(a.estimate.as_ref().and_then(|e| e.total.contact_force), 2)
        );
    }
    let _ = writeln!(s);
}

/// The summary table: one row per run.
fn runs_table(s: &mut String, rep: &Report) {
    use std::fmt::Write;
    let _ = writeln!(
        s,
        "| model | g | size | iteration | status | err ‖f_c‖ | est. ‖f_c‖ | err u_y | est. u_y | err ‖f_R‖ | est. ‖f_R‖ | CPU s | % of full | speed-up | steps | RHS | Newton its | setups | Pareto |"
    );
    let _ = writeln!(
        s,
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
    );
    for r in &rep.runs {
        let est = r.estimate.as_ref().map(|e| e.total);
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {:.3} | {} | {} | {} | {} | {} | {} | {} |",
            match r.tolerance {
                Some((tol, met)) => format!(
                    "adaptive, TOL {tol:.0e}{}",
                    if met { "" } else { " (not met)" }
                ),
                None => r.model.clone(),
            },
            r.g.map_or("–".into(), |g| g.to_string()),
            r.size,
            r.iteration,
            if r.status.finished() {
                "ok".to_string()
            } else {
                format!("{} at t = {:.3e} s", r.status, r.t_reached)
            },
            fmt_opt(r.error_fc, 2),
            fmt_opt(est.and_then(|e| e.contact_force), 2),
            fmt_opt(r.error_uy, 2),
            fmt_opt(est.and_then(|e| e.master_uy), 2),
            fmt_opt(r.error_fr, 2),
            fmt_opt(est.and_then(|e| e.friction_force), 2),
            r.cpu_s,
            r.cpu_percent.map_or("–".into(), |p| format!("{p:.2}")),
            r.speedup.map_or("–".into(), |p| format!("{p:.0}×")),
            r.stats.steps,
            r.stats.rhs_evals,
            r.stats.nonlinear_iterations,
            r.stats.linear_setups,
            if r.pareto { "●" } else { "" }
        );
    }
}

/// The static convergence section.
fn study_section(s: &mut String, rep: &Report) {
    use std::fmt::Write;
    let _ = writeln!(
        s,
        "## Static convergence and w(g) (Figs. 7, 8, 15, 16, 19)\n"
    );
    let _ = writeln!(
        s,
        "Full FE: ‖f_c‖ = {:.9} N, {} pairs in contact.\n",
        rep.study.full.contact_force_norm, rep.study.full.pairs_in_contact
    );
    let _ = writeln!(
        s,
        "Mesh-independent measures of the full model's contact: {}.\n",
        rep.study.full.measures.describe(4)
    );
    let _ = writeln!(
        s,
        "| basis | error g = 0 | error at max g | first g within 1e-2 | first g within 1e-4 |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|");
    for x in &rep.study.series {
        let show = |o: Option<usize>| o.map_or("–".to_string(), |g| g.to_string());
        let _ = writeln!(
            s,
            "| {} | {:.2e} | {:.2e} | {} | {} |",
            x.label,
            x.relative_error.first().copied().unwrap_or(f64::NAN),
            x.relative_error.last().copied().unwrap_or(f64::NAN),
            show(x.within.first().and_then(|w| w.first)),
            show(x.within.get(1).and_then(|w| w.first)),
        );
    }
    let _ = writeln!(
        s,
        "\n![error](study/fc_error.png)\n\n![norm](study/fc_norm.png)\n\n![w(g)](study/w.png)\n"
    );
}

/// The stability-map section: the stored map if there is one.
fn stability_section(s: &mut String, rep: &Report, stab: &Path, stability: bool) {
    use std::fmt::Write;
    let _ = writeln!(s, "## Stability map\n");
    if stability {
        let _ = writeln!(
            s,
            "Stored map from `{}` (made by `jointrom stability {} --out {}`; see its \
             `stability.md` and SOURCE.md for the command and the failures explained).\n\n\
             ![status](stability_status.png)\n\n![error](stability_error.png)\n\n![wall](stability_wall.png)\n",
            stab.display(),
            rep.case,
            stab.parent().map_or(".".into(), |p| p.display().to_string())
        );
    } else {
        let _ = writeln!(
            s,
            "No stored map under `{}`: run `jointrom stability {}` (about 17 min on 2 cores).\n",
            stab.display(),
            rep.source
        );
    }
}
