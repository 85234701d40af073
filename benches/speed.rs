//! Speed of the reduced models against the full FE model, with where each run's time
//! goes: `cargo bench --bench speed`.
//!
//! Per built-in scene (friction on, the paper's tolerances, the case's window), all in this
//! process: the full FE run and the reduced runs — TVD g = 12, the a-priori TVD, all joint DOF,
//! the tolerance-chosen model (TOL 1e-2) — each with the active-set refresh of the Newton
//! iteration (the default) and without it. Printed per run: r, wall time, steps, convergence
//! failures, setups + refreshes, the time per component (right-hand sides, Newton setups,
//! Newton solves, the rest = CVODE's own work and the outputs; [`jointrom::integrate::Profile`])
//! and per step, the speed-up against the full run *with the same settings*, and the true
//! relative L2 errors of ‖f_c‖(t), ‖f_R‖(t), u_y(t) against the stored full reference
//! (`cases/reference/<scene>_full_friction_on.json`, made without refresh). Criterion then
//! times the tolerance-chosen model's run over 0.02 s (10 samples).
//!
//! The tolerance-chosen model runs at the integration tolerances it chose
//! ([`jointrom::rom::tolerance::integration_looseness`]); beside it, the honest equal-accuracy
//! comparison: the full model at 10×, 100× and 1000× the paper's rtol and atol, its errors
//! against the stored reference, and the ratio of the loosest full run that still meets 1 % in
//! ‖f_c‖(t) to the tolerance-chosen model's run.
//! Measured figures: docs/performance/speed.md.

use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion};
use jointrom::integrate::{run, Run, TransientOptions};
use jointrom::reduction::{build_basis, BasisKind, BasisOptions};
use jointrom::rom::tolerance::{tolerance_model, ToleranceOptions};
use jointrom::system::{FullSystem, ReducedSystem, Scene};
use jointrom::Model;

/// Relative L2 difference `‖a − b‖ / ‖b‖` over the common samples.
fn rel_l2(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    let num: f64 = (0..n).map(|i| (a[i] - b[i]).powi(2)).sum();
    let den: f64 = (0..n).map(|i| b[i].powi(2)).sum();
    (num / den).sqrt()
}

/// The stored full reference curves: ‖f_c‖, ‖f_R‖, u_y.
fn reference(scene: &str) -> [Vec<f64>; 3] {
    let path = format!(
        "{}/cases/reference/{scene}_full_friction_on.json",
        env!("CARGO_MANIFEST_DIR")
    );
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let v: serde_json::Value = serde_json::from_str(&text).expect("reference JSON");
    let curve = |k: &str| -> Vec<f64> {
        v[k].as_array()
            .unwrap_or_else(|| panic!("{path}: no `{k}`"))
            .iter()
            .map(|x| x.as_f64().expect("number"))
            .collect()
    };
    [
        curve("contact_force_norm"),
        curve("friction_force_norm"),
        curve("master_uy"),
    ]
}

fn options(refresh: bool) -> TransientOptions {
    let mut o = TransientOptions {
        profile: true,
        ..TransientOptions::default()
    };
    if !refresh {
        o.problem.refresh = None;
    }
    o
}

fn row(name: &str, r: usize, run: &Run, full_wall: f64, reference: &[Vec<f64>; 3]) {
    let s = &run.stats;
    let p = run.profile.clone().unwrap_or_default();
    let c = &run.curves;
    let us = |x: f64| 1e6 * x / s.steps.max(1) as f64;
    println!(
        "{name:<26} {r:>4} {:>7.3} {:>6} {:>4} {:>5}+{:<4} {:>5.1} {:>5.1} {:>5.1} {:>5.1} {:>6.1} {:>6.1}x  {:.1e} {:.1e} {:.1e}",
        run.wall_s,
        s.steps,
        s.nonlinear_conv_failures,
        s.linear_setups,
        s.newton_refreshes,
        us(p.rhs_s),
        us(p.setup_s),
        us(p.solve_s),
        us(p.other_s),
        us(run.wall_s),
        full_wall / run.wall_s,
        rel_l2(&c.contact_force_norm, &reference[0]),
        rel_l2(&c.friction_force_norm, &reference[1]),
        rel_l2(&c.master_uy, &reference[2]),
    );
}

fn scene_table(name: &str) {
    let model = Model::from_case_name(name).expect("built-in case");
    let scene = Scene::of(&model);
    let reference = reference(name);
    let tvd = |g: Option<usize>| {
        let opts = BasisOptions {
            g,
            ..BasisOptions::default()
        };
        let b = build_basis(&model, BasisKind::Tvd, &opts).expect("TVD basis");
        ReducedSystem::new(&model, b.phi).expect("ROM")
    };
    let alldof = build_basis(&model, BasisKind::AllDof, &BasisOptions::default())
        .map(|b| ReducedSystem::new(&model, b.phi).expect("ROM"))
        .expect("all-DOF basis");
    let tol = tolerance_model(&model, &ToleranceOptions::new(1e-2)).expect("tolerance model");
    let (tol_rtol, tol_atol) = (tol.transient.ode.rtol, tol.transient.ode.atol);
    let roms = [
        ("TVD g = 12", tvd(Some(12))),
        ("TVD a-priori w(g)", tvd(None)),
        ("all joint DOF", alldof),
        ("TOL 1e-2 (paper tol.)", tol.rom.clone()),
    ];
    println!(
        "\n{name}: µs per step: RHS, setup, solve, other (CVODE, outputs), total; errors vs stored full run\n\
         {:<26} {:>4} {:>7} {:>6} {:>4} {:>10} {:>5} {:>5} {:>5} {:>5} {:>6} {:>7}  fc      fR      uy",
        "model", "r", "wall s", "steps", "ncf", "setup+ref", "rhs", "setup", "solve", "other", "step", "speedup"
    );
    for refresh in [true, false] {
        let tag = if refresh { "" } else { " (no refresh)" };
        let full = run(
            FullSystem::new(&model).expect("full"),
            &scene,
            &options(refresh),
        )
        .expect("full run");
        row(
            &format!("full FE{tag}"),
            model.dofs(),
            &full,
            full.wall_s,
            &reference,
        );
        for (label, rom) in &roms {
            let r = run(rom.clone(), &scene, &options(refresh)).expect("ROM run");
            row(
                &format!("{label}{tag}"),
                rom.dim(),
                &r,
                full.wall_s,
                &reference,
            );
        }
        let mut own = options(refresh);
        own.ode.rtol = tol_rtol;
        own.ode.atol = tol_atol;
        let chosen = run(tol.rom.clone(), &scene, &own).expect("ROM run");
        row(
            &format!("TOL 1e-2, rtol {tol_rtol:.0e}{tag}"),
            tol.rom.dim(),
            &chosen,
            full.wall_s,
            &reference,
        );
        if refresh {
            equal_accuracy(&model, &scene, &reference, &full, &chosen);
        }
    }
}

/// The full model at looser tolerances against the stored reference: the loosest that still
/// meets 1 % in ‖f_c‖(t), and its wall time against the tolerance-chosen model's run.
fn equal_accuracy(
    model: &Model,
    scene: &Scene,
    reference: &[Vec<f64>; 3],
    full: &Run,
    chosen: &Run,
) {
    let mut loosest: Option<(f64, f64)> = None;
    for factor in [10.0, 100.0, 1000.0] {
        let mut o = options(true);
        o.ode.rtol *= factor;
        o.ode.atol *= factor;
        let Ok(r) = run(FullSystem::new(model).expect("full"), scene, &o) else {
            println!("full FE ×{factor:<5} failed");
            continue;
        };
        row(
            &format!("full FE, rtol {:.0e}", o.ode.rtol),
            model.dofs(),
            &r,
            full.wall_s,
            reference,
        );
        if rel_l2(&r.curves.contact_force_norm, &reference[0]) <= 1e-2 {
            loosest = Some((factor, r.wall_s));
        }
    }
    match loosest {
        Some((factor, wall)) => println!(
            "equal accuracy: the loosest full run within 1 % (×{factor} the paper's tolerances) \
             takes {wall:.3} s: {:.0}× the TOL 1e-2 model's {:.3} s (paper-tolerance full run: \
             {:.0}×)",
            wall / chosen.wall_s,
            chosen.wall_s,
            full.wall_s / chosen.wall_s
        ),
        None => println!(
            "equal accuracy: no looser full run within 1 %; paper-tolerance full run {:.0}× the \
             TOL 1e-2 model",
            full.wall_s / chosen.wall_s
        ),
    }
}

fn speed(c: &mut Criterion) {
    for name in ["friction_bar", "multilayer_sheet"] {
        scene_table(name);
    }
    let mut group = c.benchmark_group("speed");
    group.sample_size(10);
    group.warm_up_time(Duration::from_millis(500));
    group.measurement_time(Duration::from_secs(5));
    for name in ["friction_bar", "multilayer_sheet"] {
        let model = Model::from_case_name(name).expect("built-in case");
        let scene = Scene::of(&model);
        let tol = tolerance_model(&model, &ToleranceOptions::new(1e-2)).expect("tolerance model");
        let rom = tol.rom;
        let opts = TransientOptions {
            end_time: Some(0.02),
            ..tol.transient
        };
        group.bench_function(format!("{name}_tol_1e-2_run_0.02s"), |b| {
            b.iter(|| run(rom.clone(), &scene, &opts).expect("ROM run"))
        });
    }
    group.finish();
}

criterion_group!(benches, speed);
criterion_main!(benches);
