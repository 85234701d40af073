//! The static convergence study (`jointrom::studies::convergence`) and the chart helpers (`jointrom::report::chart`).

#![allow(clippy::needless_range_loop)]

use std::path::PathBuf;

use faer::Mat;
use jointrom::joint::statics::ContactOptions;
use jointrom::joint::NORMAL;
use jointrom::linalg::cholesky::SparseCholesky;
use jointrom::model::contact_static_full;
use jointrom::reduction::{build_basis, craig_bampton, final_basis, BasisKind, BasisOptions};
use jointrom::report::chart::{LineChart, Reference, Series};
use jointrom::report::convergence::write_charts;
use jointrom::rom::statics::{
    reduced_contact_static, reduced_contact_static_damped, reduced_contact_static_restarting,
};
use jointrom::studies::convergence::{basis_static, run_study, within, StudyOptions};
use jointrom::system::ReducedSystem;
use jointrom::{Interface, Model};

use crate::common;

fn tmp(name: &str) -> PathBuf {
    common::tmp_dir(&format!("study_{name}"))
}

/// The study's reduced pipeline (final_basis → ReducedSystem → reduced contact solve) is exact
/// when the basis holds the whole joint space: Φ_S spans K⁻¹ f (master load) and K⁻¹ B_nᵀ spans
/// every contact force, so the full solution lies in span Φ and the Galerkin solution of the
/// convex contact energy is it.
#[test]
fn reduced_statics_exact_with_the_whole_joint_space() {
    for case in ["friction_bar", "multilayer_sheet"] {
        let model = common::model(case);
        let n = model.dofs();
        let w = model.joint.pairs();
        let cb = craig_bampton(&model, 10).unwrap();
        let mut f = Mat::<f64>::zeros(n, w);
        for z in 0..w {
            for (c, v) in model.joint.row(3 * z + NORMAL) {
                f[(c, z)] = v;
            }
        }
        SparseCholesky::new(&model.stiffness)
            .unwrap()
            .solve_in_place(&mut f);
        let (phi, dropped) = final_basis(&[cb.as_ref(), f.as_ref()], &model.mass, 1e-8).unwrap();
        assert_eq!(dropped, 0, "{case}");
        let rm = ReducedSystem::new(&model, phi).unwrap();
        let opts = ContactOptions::default();
        let full = contact_static_full(&model, model.master_load(), &opts).unwrap();
        let red = reduced_contact_static(&model, &rm, 1.0, &opts).unwrap();
        let rel = (full.state.contact_force_norm - red.state.contact_force_norm).abs()
            / full.state.contact_force_norm;
        println!(
            "{case}: full {} reduced {} rel {rel:e}",
            full.state.contact_force_norm, red.state.contact_force_norm
        );
        assert!(rel < 1e-6, "{case}: relative error {rel:e}");
        assert_eq!(red.state.active, full.state.active, "{case}");
        // Translations (mm) and rotations (rad) each relative to their own size.
        for range in [0..3, 3..6] {
            let scale = range
                .clone()
                .fold(0.0f64, |a, k| a.max(full.master_displacement[k].abs()));
            for k in range {
                let d = (red.master_displacement[k] - full.master_displacement[k]).abs();
                assert!(
                    d <= 1e-5 * scale,
                    "{case}: master DOF {k}: {} vs {}",
                    red.master_displacement[k],
                    full.master_displacement[k]
                );
            }
        }
    }
}

/// Fixed-interface modes `skip + 1 ..= skip + count` by the sparse solver as the `modes` series
/// builds them (n × count, zero on the master DOF).
fn sparse_fixed_interface_modes(
    model: &Model,
    skip: usize,
    count: usize,
) -> Result<Mat<f64>, jointrom::Error> {
    let modes = model.modes(skip + count, Interface::Fixed)?;
    let m = modes.shapes.nrows();
    Ok(Mat::from_fn(model.dofs(), count, |r, c| {
        if r < m {
            modes.shapes[(r, skip + c)]
        } else {
            0.0
        }
    }))
}

/// The study's fixed-interface modes (skip/count columns) agree with `Model::modes`
/// (frequencies to 1e-8, same subspace) and are M-orthonormal.
#[test]
fn dense_modes_match_lanczos() {
    let model = common::model("friction_bar");
    let lanczos = model.modes(12, Interface::Fixed).unwrap();
    let dense = sparse_fixed_interface_modes(&model, 0, 12).unwrap();
    let n = model.dofs();
    let mut mx = vec![0.0; n];
    let mut kx = vec![0.0; n];
    for c in 0..12 {
        let x: Vec<f64> = dense.col(c).iter().copied().collect();
        model.mass.mul_vec(&x, &mut mx);
        model.stiffness.mul_vec(&x, &mut kx);
        let xm: f64 = x.iter().zip(&mx).map(|(a, b)| a * b).sum();
        let xk: f64 = x.iter().zip(&kx).map(|(a, b)| a * b).sum();
        assert!((xm - 1.0).abs() < 1e-9, "mode {c}: xᵀMx = {xm}");
        let f = xk.sqrt() / (2.0 * std::f64::consts::PI);
        let fl = lanczos.frequencies_hz[c];
        assert!(
            (f - fl).abs() < 1e-8 * fl,
            "mode {c}: dense {f} Hz, Lanczos {fl} Hz"
        );
        for d in 0..c {
            let y: Vec<f64> = dense.col(d).iter().copied().collect();
            let o: f64 = y.iter().zip(&mx).map(|(a, b)| a * b).sum();
            assert!(o.abs() < 1e-9, "modes {d}, {c}: yᵀMx = {o}");
        }
        for m in model.master_dofs() {
            assert_eq!(dense[(m, c)], 0.0);
        }
    }
    // `skip` returns the later modes: mode 13 of a skip-12 call is the 13th overall.
    let later = sparse_fixed_interface_modes(&model, 12, 1).unwrap();
    let all = sparse_fixed_interface_modes(&model, 0, 13).unwrap();
    let dot: f64 = (0..n).map(|r| later[(r, 0)] * all[(r, 12)]).sum::<f64>();
    let nrm: f64 = (0..n).map(|r| later[(r, 0)].powi(2)).sum::<f64>();
    assert!((dot.abs() / nrm - 1.0).abs() < 1e-8);
}

#[test]
fn within_first_and_stays() {
    let g = [0, 1, 2, 3, 4];
    let w = within(&g, &[1.0, 1e-3, 0.5, 1e-3, 1e-5], 1e-2);
    assert_eq!((w.first, w.stays), (Some(1), Some(3)));
    let w = within(&g, &[1.0, 1.0, 1.0, 1.0, 1.0], 1e-2);
    assert_eq!((w.first, w.stays), (None, None));
    let w = within(&g, &[0.0; 5], 1e-2);
    assert_eq!((w.first, w.stays), (Some(0), Some(0)));
    let w = within(&g, &[1e-3, 1e-3, 1e-3, 1e-3, f64::NAN], 1e-2);
    assert_eq!((w.first, w.stays), (Some(0), None));
}

/// The study on the friction bar: every series starts at plain Craig–Bampton (g = 0), the TVD
/// series improve by orders of magnitude, w(g) is a non-decreasing energy ratio, the study's
/// full value is the full solver's, and its charts are written.
#[test]
fn friction_bar_study() {
    let model = common::model("friction_bar");
    let opts = StudyOptions::default();
    let s = run_study(&model, &opts).unwrap();
    let full = contact_static_full(&model, model.master_load(), &opts.contact).unwrap();
    assert_eq!(s.full.contact_force_norm, full.state.contact_force_norm);
    let names: Vec<&str> = s.series.iter().map(|x| x.name.as_str()).collect();
    for want in ["tvd", "tvd-plain", "tvd-kt", "modes"] {
        assert!(names.contains(&want), "{names:?}");
    }
    // The TVD span itself holds the full solution (no POD truncation): measured 4.8e-8.
    let span = s.tvd_spans.iter().find(|t| t.name == "tvd").unwrap();
    assert!(
        span.relative_error < 1e-6,
        "all TVD: {:e}",
        span.relative_error
    );
    let e0 = s.series[0].relative_error[0];
    for x in &s.series {
        assert_eq!(x.g[0], 0);
        assert_eq!(x.basis_size[0], 16, "{}", x.name);
        assert_eq!(
            x.relative_error[0], e0,
            "{}: g = 0 is the same CB basis",
            x.name
        );
        assert_eq!(x.g.len(), x.available.min(opts.max_g) + 1, "{}", x.name);
        for (i, &g) in x.g.iter().enumerate() {
            assert_eq!(g, i);
            assert!(x.basis_size[i] <= 16 + g);
        }
    }
    let modes = s.series.iter().find(|x| x.name == "modes").unwrap();
    assert_eq!(modes.available, opts.max_g);
    assert!(modes.failures.len() < 10);
    // TVD + K-weighted POD: measured 3.3e1 at g = 0, 2.0e-2 with all 48 POMs (the POD keeps
    // λ > 1e-12 λ_max; the full solution is not in the kept TVD span, see the report).
    let tvd = s.series.iter().find(|x| x.name == "tvd").unwrap();
    let last = *tvd.relative_error.last().unwrap();
    assert!(
        last < 0.05 && last < e0 * 1e-2,
        "tvd: g=0 {e0:e}, last {last:e}"
    );
    for e in &s.energy {
        assert!(
            e.w.windows(2).all(|p| p[1] >= p[0]),
            "{}: w decreasing",
            e.name
        );
        assert!(e.w.iter().all(|&v| v > 0.0 && v <= 1.0));
        assert!(e.g_threshold >= 1 && e.w[e.g_threshold - 1] >= opts.threshold);
        if e.g_threshold >= 2 {
            assert!(e.w[e.g_threshold - 2] < opts.threshold);
        }
    }
    let dir = tmp("charts");
    let files = write_charts(&s, &dir).unwrap();
    assert_eq!(files.len(), 6);
    for f in files {
        let bytes = std::fs::read(&f).unwrap();
        assert!(
            bytes.len() > 1000,
            "{} has {} bytes",
            f.display(),
            bytes.len()
        );
        if f.extension().unwrap() == "png" {
            assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
        } else {
            assert!(String::from_utf8_lossy(&bytes).contains("<svg"));
        }
    }
}

#[test]
fn chart_log_axis_and_errors() {
    let dir = tmp("chart_unit");
    let mut c = LineChart::new("log test", "x", "y");
    c.y_log = true;
    // A zero and a negative value cannot be drawn on a log axis: skipped, no panic.
    c.series.push(Series::new(
        "a",
        vec![
            (0.0, 1.0),
            (1.0, 1e-3),
            (2.0, 0.0),
            (3.0, -1.0),
            (4.0, 1e-9),
        ],
    ));
    c.references.push(Reference::new("ref", 1e-6));
    c.references.push(Reference {
        label: "coloured".into(),
        value: 1e-7,
        color: Some([200, 0, 0]),
    });
    let [svg, png] = c.write(&dir.join("log")).unwrap();
    assert!(std::fs::metadata(&svg).unwrap().len() > 500);
    assert!(std::fs::metadata(&png).unwrap().len() > 500);

    // Nothing drawable: an error naming the chart.
    let mut bad = LineChart::new("empty", "x", "y");
    bad.y_log = true;
    bad.series.push(Series::new("neg", vec![(0.0, -1.0)]));
    let e = bad.write_svg(&dir.join("bad.svg")).unwrap_err().to_string();
    assert!(
        e.contains("empty") && e.contains("no drawable point"),
        "{e}"
    );

    // An unwritable path is an error, not a panic.
    let e = c
        .write_png(&dir.join("no_such_dir/x.png"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("x.png"), "{e}");
}

/// Independent check of a reduced contact solution: the active set is self-consistent
/// (active ⇔ gap < 0) and η solves `(K̃ + k_n Σ_active b_iᵀ b_i) η = f̃` to round-off.
fn assert_equilibrium(model: &Model, rm: &ReducedSystem, scale: f64, eta: &[f64], what: &str) {
    let w = model.joint.pairs();
    let r = rm.dim();
    let k_n = model.contact.normal_stiffness;
    let load = rm.reduced_load();
    let b = |i: usize, j: usize| rm.b_phi()[(3 * i + NORMAL, j)];
    let gaps: Vec<f64> = (0..w)
        .map(|i| (0..r).map(|j| b(i, j) * eta[j]).sum())
        .collect();
    let mut res: Vec<f64> = (0..r)
        .map(|i| (0..r).map(|j| rm.k()[(i, j)] * eta[j]).sum::<f64>() - scale * load[i])
        .collect();
    for i in 0..w {
        if gaps[i] < 0.0 {
            for j in 0..r {
                res[j] += k_n * gaps[i] * b(i, j);
            }
        }
    }
    let fmax = load.iter().fold(0.0f64, |a, v| a.max(v.abs())) * scale.abs();
    let rmax = res.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    assert!(
        rmax <= 1e-8 * fmax,
        "{what}: residual {rmax:e} vs load {fmax:e}"
    );
}

/// The damped semismooth Newton solver agrees with the active-set one where that converges,
/// and solves the cases where the active-set one cycles (Craig–Bampton + 6 modes, load × −1,
/// on the point-weld friction bar), with a self-consistent active set and a zero residual.
#[test]
fn damped_reduced_contact() {
    let model = common::model("friction_bar");
    let opts = ContactOptions::default();
    let basis = |kind, g| {
        let b = build_basis(
            &model,
            kind,
            &BasisOptions {
                g: Some(g),
                ..BasisOptions::default()
            },
        )
        .unwrap();
        ReducedSystem::new(&model, b.phi).unwrap()
    };
    let rm = basis(BasisKind::Tvd, 20);
    let plain = reduced_contact_static(&model, &rm, 1.0, &opts).unwrap();
    let damped = reduced_contact_static_damped(&model, &rm, 1.0, &opts).unwrap();
    assert_eq!(plain.state.active, damped.state.active);
    let d = (plain.state.contact_force_norm - damped.state.contact_force_norm).abs();
    assert!(d <= 1e-9 * plain.state.contact_force_norm, "{d:e}");
    assert_equilibrium(&model, &rm, 1.0, &damped.eta, "tvd g=20 damped");

    // The cycling case, measured on the point-weld friction bar: Craig–Bampton + 6 modes,
    // load × −1 (3 modes until the sheets' DKMQ bending of 2026-11-26).
    let model = common::point_weld_model("friction_bar");
    let rm = ReducedSystem::new(
        &model,
        build_basis(
            &model,
            BasisKind::Modes,
            &BasisOptions {
                g: Some(6),
                ..BasisOptions::default()
            },
        )
        .unwrap()
        .phi,
    )
    .unwrap();
    assert!(
        reduced_contact_static(&model, &rm, -1.0, &opts).is_err(),
        "the active-set method was measured to cycle here; if it no longer does, pick another case"
    );
    let (sol, first) = reduced_contact_static_restarting(&model, &rm, -1.0, &opts).unwrap();
    assert!(first.is_some());
    assert!(sol.state.pairs_in_contact > 0);
    assert_equilibrium(&model, &rm, -1.0, &sol.eta, "modes g=6 × −1 damped");
    let st = basis_static(
        &model,
        BasisKind::Modes,
        &BasisOptions {
            g: Some(6),
            ..BasisOptions::default()
        },
        -1.0,
    )
    .unwrap();
    assert!(st.restarted);
    assert_eq!(
        st.solution.state.contact_force_norm,
        sol.state.contact_force_norm
    );
}
