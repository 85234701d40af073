//! The main job's report (`jointrom run --quick`): every chart and table is written, the numbers
//! are consistent with each other and with the paper's qualitative claims on this window.

use jointrom::report::main_job::run_report;
use jointrom::studies::main_job::ReportOptions;

use crate::common;

#[test]
fn quick_report_on_the_friction_bar() {
    let model = common::model("friction_bar");
    let dir = common::tmp_dir("report_quick");
    let opts = ReportOptions {
        quick: true,
        progress: false,
        stability_dir: common::repo_path("results/stability"),
        ..ReportOptions::default()
    };
    let mut extra = serde_json::Map::new();
    extra.insert("marker".into(), serde_json::json!(42));
    let rep = run_report(&model, &dir, &opts, extra).unwrap();

    check_outputs(&dir);
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("results.json")).unwrap()).unwrap();
    assert_eq!(json["marker"], 42, "extra fields reach results.json");
    assert_eq!(json["g_chosen"].as_u64(), Some(rep.g_chosen as u64));

    // The a-priori g is the smallest with w(g) ≥ threshold.
    let g = rep.g_chosen;
    assert!(g >= 1 && rep.w[g - 1] >= rep.threshold);
    assert!(g == 1 || rep.w[g - 2] < rep.threshold);

    // The full run is the reference and finished; the full run with functional iteration is
    // recorded whatever its fate.
    let full = &rep.runs[0];
    assert_eq!((full.model.as_str(), full.status.name()), ("full", "ok"));
    assert_eq!(full.size, model.dofs());
    assert!(rep
        .runs
        .iter()
        .any(|r| r.model == "full" && r.iteration == "functional"));
    let run = |m: &str, g: usize, it: &str| {
        rep.runs
            .iter()
            .find(|r| r.model == m && r.g == Some(g) && r.iteration == it)
            .unwrap_or_else(|| panic!("no {m} g = {g} {it} run"))
    };
    // g = 0 misses the joint (the paper's point), all joint DOF reproduce it (within the
    // integration tolerance), and the TVD ROMs sit in between.
    let g0 = run("tvd", 0, "newton");
    let all = run("alldof", model.joint.pairs(), "newton");
    let chosen = run("tvd", g, "newton");
    let e0 = g0.error_fc.unwrap();
    let eall = all.error_fc.unwrap();
    let ech = chosen.error_fc.unwrap();
    assert!(e0 > 1.0, "g = 0 error {e0}");
    assert!(eall < 1e-2, "all joint DOF error {eall}");
    assert!(ech < e0 && ech > eall, "chosen g error {ech}");
    assert!(all.error_uy.unwrap() < 1e-4);
    // Functional and Newton iteration solve the same ROM: same curves within the tolerances.
    let fun = run("tvd", g, "functional");
    if fun.status.name() == "ok" {
        let d = jointrom::rom::compare::relative_l2(
            &fun.curves.t,
            &fun.curves.contact_force_norm,
            &chosen.curves.t,
            &chosen.curves.contact_force_norm,
        )
        .unwrap();
        assert!(d < 1e-2, "functional vs Newton ‖f_c‖ differ by {d}");
    }
    // Speed-ups are CPU ratios; the Pareto front is non-empty and not dominated.
    for r in rep.runs.iter().filter(|r| r.speedup.is_some()) {
        let s = r.speedup.unwrap();
        assert!((s * r.cpu_s - full.cpu_s).abs() <= 1e-9 * full.cpu_s.max(1.0));
    }
    let front: Vec<_> = rep.runs.iter().filter(|r| r.pareto).collect();
    assert!(!front.is_empty());
    for p in &front {
        let (c, e) = (p.cpu_s, p.error_fc.unwrap());
        assert!(
            !rep.runs
                .iter()
                .any(|r| r.status.name() == "ok"
                    && r.error_fc.is_some_and(|er| r.cpu_s < c && er < e))
        );
    }
    // Every reduced run carries its own error estimate; where the true error is well above the
    // integration floor (> 1e-2) the estimate is within a factor 2 of it. The headline model is
    // the tolerance-chosen one and meets its tolerance against the full run.
    for r in rep
        .runs
        .iter()
        .filter(|r| r.model != "full" && r.status.finished())
    {
        let est = r
            .estimate
            .as_ref()
            .and_then(|e| e.total.contact_force)
            .unwrap_or_else(|| {
                panic!(
                    "{} g = {:?}: no estimate ({:?})",
                    r.model, r.g, r.estimate_note
                )
            });
        let truth = r.error_fc.unwrap();
        if truth > 1e-2 {
            let eff = est / truth;
            assert!(
                (0.5..=2.0).contains(&eff),
                "{} g = {:?}: estimate {est}, true {truth}",
                r.model,
                r.g
            );
        }
    }
    // The short backbone of mode 1: its smallest amplitude sticks (the linearised frequency,
    // no dissipation), its largest slips (softer, damped).
    let b = rep.backbone.as_ref().expect("a backbone");
    let m = &b.modes[0];
    let (small, large) = (
        &m.ring_downs[0].cycles[0],
        &m.ring_downs.last().unwrap().cycles[0],
    );
    assert!(
        (small.frequency_hz / m.linear_frequency_hz - 1.0).abs() < 1e-3,
        "{small:?} vs {}",
        m.linear_frequency_hz
    );
    assert!(small.damping_ratio.abs() < 1e-6, "{small:?}");
    assert!(
        large.frequency_hz < small.frequency_hz && large.damping_ratio > 1e-4,
        "{large:?}"
    );
    let h = &rep.runs[rep.headline.expect("a headline model")];
    assert_eq!(h.model, "adaptive");
    assert!(
        h.error_fc.unwrap() <= rep.headline_tolerance,
        "headline error {:?}",
        h.error_fc
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// The quick report's files: every chart as PNG and SVG, the study charts, the stored stability
/// map, the texts, the inlined HTML page and the off-scale legend.
fn check_outputs(dir: &std::path::Path) {
    for f in [
        "report.md",
        "results.json",
        "report.html",
        "fc_t.png",
        "fc_t.svg",
        "fc_err_t.png",
        "fr_t.png",
        "fr_err_t.png",
        "uy_t.png",
        "speed_accuracy.png",
        "speed_accuracy.svg",
        "study/fc_error.png",
        "study/w.png",
        "stability_status.png",
        "backbone_frequency.png",
        "backbone_damping.png",
    ] {
        let p = dir.join(f);
        let len = std::fs::metadata(&p)
            .unwrap_or_else(|e| panic!("{} missing: {e}", p.display()))
            .len();
        assert!(
            len > 1000,
            "{} is suspiciously small ({len} bytes)",
            p.display()
        );
    }
    let md = std::fs::read_to_string(dir.join("report.md")).unwrap();
    for needle in [
        "speed_accuracy.png",
        "fc_t.png",
        "study/w.png",
        "stability_status.png",
        "backbone_damping.png",
    ] {
        assert!(md.contains(needle), "report.md does not show {needle}");
    }
    // The error charts are shown, and the HTML page carries every image of the markdown inline
    // (no link back to the folder).
    assert!(
        md.contains("fc_err_t.png"),
        "report.md does not show the error chart"
    );
    let html = std::fs::read_to_string(dir.join("report.html")).unwrap();
    let images = md.matches("![").count();
    assert_eq!(
        html.matches("src=\"data:image/png;base64,").count(),
        images,
        "report.html does not inline all {images} images"
    );
    assert!(!html.contains("src=\"fc_t.png\""));
    // g = 0's contact force dwarfs the others: it is drawn off scale, its peak in the legend.
    let svg = std::fs::read_to_string(dir.join("fc_t.svg")).unwrap();
    assert!(
        svg.contains("TVD g = 0 — off scale, peak"),
        "g = 0 not drawn off scale"
    );
}

/// A run's own `curves.csv` (units in its column names) is a reference for `--reference`: read
/// back, it compares with the run at zero error, the dissipated energy included.
#[test]
fn a_runs_curves_csv_is_a_reference() {
    let t: Vec<f64> = (0..5).map(|k| 1e-4 * k as f64).collect();
    let ramp = |s: f64| t.iter().map(|&x| s * x).collect::<Vec<f64>>();
    let run = jointrom::integrate::Curves {
        contact_force_norm: ramp(1e3),
        friction_force_norm: ramp(2.5e2),
        master_uy: ramp(-1.0),
        kinetic: ramp(0.0),
        strain: ramp(0.0),
        pair: ramp(0.0),
        external_work: ramp(0.0),
        dissipated: ramp(10.0),
        closed_pairs: vec![0; t.len()],
        t: t.clone(),
    };
    let csv = jointrom::report::curves::curves_csv(&run).unwrap();
    assert!(csv.starts_with("t_s,contact_force_norm_N"), "{csv}");
    let reference = jointrom::rom::JointCurves::parse_csv(&csv, "curves.csv").unwrap();
    assert_eq!(reference.t.len(), t.len());
    let e = reference.errors(&run);
    assert!(e.contact_force.unwrap() < 1e-9, "{e:?}");
    assert!(
        e.friction_force.unwrap() < 1e-9 && e.master_uy.unwrap() < 1e-9,
        "{e:?}"
    );
    assert!(e.dissipated.unwrap() < 1e-9, "{e:?}");
}
