//! Error-controlled reduction benchmarks: the tolerance-chosen model
//! (`jointrom::rom::tolerance`, TOL = 1e-2) against the full FE run, with friction, at the
//! paper's tolerances, on both built-in scenes.
//!
//! Each scene is first run five times over its whole window (0.2 s friction bar, 0.05 s
//! multilayer) in this process, the full model and the tolerance-chosen one: the medians of the
//! full run's wall time, the chosen model's offline (setup, enrichment rounds, the result's
//! basis) and online (its run) wall times and their ratio to the full run are printed — the
//! issue's target is offline + online ≤ 10 % of the full run — and the whole with the result's
//! own estimate (its quasi-static correction and the wait for the integration check, which runs
//! beside it). Criterion then times the whole tolerance build and run over a 0.02 s window with
//! 10 samples. Measured figures: docs/performance/tolerance-cost.md.

use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion};
use jointrom::integrate::{run, TransientOptions};
use jointrom::rom::tolerance::{tolerance_model, ToleranceOptions};
use jointrom::system::{FullSystem, Scene};
use jointrom::Model;

/// Runs per figure of the whole-window table (medians).
const REPEATS: usize = 5;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn tolerance(c: &mut Criterion) {
    let mut group = c.benchmark_group("tolerance");
    group.sample_size(10);
    group.warm_up_time(Duration::from_millis(500));
    group.measurement_time(Duration::from_secs(5));
    for name in ["friction_bar", "multilayer_sheet"] {
        let model = Model::from_case_name(name).expect("built-in case assembles");
        // Medians of REPEATS runs each (this machine's wall times scatter by ±20 % run to run).
        let full: Vec<f64> = (0..REPEATS)
            .map(|_| {
                run(
                    FullSystem::new(&model).expect("full system"),
                    &Scene::of(&model),
                    &TransientOptions::default(),
                )
                .expect("full run")
                .wall_s
            })
            .collect();
        let models: Vec<_> = (0..REPEATS)
            .map(|_| {
                tolerance_model(&model, &ToleranceOptions::new(1e-2)).expect("tolerance model")
            })
            .collect();
        let t = &models[0];
        let full = median(full);
        let offline = median(models.iter().map(|t| t.offline_s).collect());
        let online = median(models.iter().map(|t| t.run.wall_s).collect());
        let estimate = median(models.iter().map(|t| t.estimate_s).collect());
        let whole = median(
            models
                .iter()
                .map(|t| t.offline_s + t.run.wall_s + t.estimate_s)
                .collect(),
        );
        let pct = |s: f64| 100.0 * s / full;
        println!(
            "{name} (medians of {REPEATS}): full {full:.3} s wall; TOL 1e-2: r = {} ({} pairs, \
             nu = {}), offline {offline:.3} s + online {online:.3} s = {:.1} % of full ({} \
             steps); + its estimate {estimate:.3} s: whole {whole:.3} s = {:.1} %; estimate {:.2e}",
            t.rom.dim(),
            t.pairs.len(),
            t.nu,
            pct(offline + online),
            t.run.stats.steps,
            pct(whole),
            t.estimate.total.contact_force.unwrap_or(0.0)
        );
        let mut opts = ToleranceOptions::new(1e-2);
        opts.transient.end_time = Some(0.02);
        group.bench_function(format!("{name}_tol_1e-2_0.02s"), |b| {
            b.iter(|| tolerance_model(&model, &opts).expect("tolerance model"))
        });
    }
    group.finish();
}

criterion_group!(benches, tolerance);
criterion_main!(benches);
