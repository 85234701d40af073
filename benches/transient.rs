//! Transient benchmarks (issue 4): the friction bar with friction, at the paper's Table 1
//! tolerances (rtol 1e-8, atol 1e-6), BDF max order 5, events off:
//!
//! - ROM with the w(g)-chosen TVD basis, functional iteration and Newton (structured solve);
//! - full FE model, functional iteration and Newton (structured sparse solve).
//!
//! Each configuration is first run once over its *report window* (ROM: the case's 0.2 s, full
//! model: 5e-4 s; override with `JOINTROM_BENCH_ROM_END` / `JOINTROM_BENCH_FULL_END`) and its
//! wall time and solver statistics are printed; criterion then times a shorter window (ROM
//! 0.02 s, full 1e-4 s) with 10 samples. Target for the ROM with friction: ≤ 0.3 s wall for
//! 0.2 s.
//!
//! Measured (2 cores shared with other jobs: wall ≈ 2× CPU; ROM g = 12, r = 28):
//!
//! | configuration | window | wall | CPU | steps | RHS | nonlinear iters | last step |
//! |---|---|---|---|---|---|---|---|
//! | ROM functional | 0.2 s | 22.8 s | 11.5 s | 300 301 | 554 799 | 554 796 | 6.6e-7 s |
//! | ROM Newton | 0.2 s | 12.3 s | 6.2 s | 149 624 | 170 734 | 170 731 | 1.3e-6 s |
//! | full functional | 5e-4 s | 25.6 s | 12.9 s | 25 010 | 41 641 | 41 638 | 2.0e-8 s |
//! | full Newton | 5e-4 s | 44.3 s | 22.1 s | 32 415 | 34 597 | 34 594 | 9.3e-9 s |
//!
//! criterion (0.02 s ROM, 1e-4 s full): ROM functional 2.3 s, ROM Newton 2.2 s, full
//! functional 5.0 s, full Newton 0.26 s. The ROM with friction is ~20× (CPU) to ~40× (wall) off
//! the 0.3 s target: the steps (~1.3e-6 s) are bounded by accuracy — the tolerance on the
//! penalty oscillation of the closed pairs and on the slip memory (τ = 1e-6 s) — not by the cost
//! per step (~40 µs).

use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion};
use jointrom::ode::{Iteration, NewtonLinear, OdeOptions};
use jointrom::reduction::{build_basis, BasisKind, BasisOptions, ReducedModel};
use jointrom::system::{FullSystem, ReducedSystem};
use jointrom::transient::{run, ProblemOptions, TransientOptions, TransientResult};
use jointrom::Model;

fn options(iteration: Iteration, end: f64) -> TransientOptions {
    TransientOptions {
        ode: OdeOptions {
            iteration,
            ..OdeOptions::default()
        },
        problem: ProblemOptions {
            friction: true,
            events: false,
            ..ProblemOptions::default()
        },
        end_time: Some(end),
        ..TransientOptions::default()
    }
}

fn report(name: &str, end: f64, r: &TransientResult) {
    let s = &r.stats;
    println!(
        "{name}: {end} s in {:.3} s wall ({:.3} s CPU): {} steps, {} RHS evals, {} nonlinear \
         iterations, {} nonlinear failures, {} error-test failures, {} Newton setups, last \
         order {}, last step {:.2e} s",
        r.wall_s,
        r.cpu_s,
        s.steps,
        s.rhs_evals,
        s.nonlinear_iterations,
        s.nonlinear_conv_failures,
        s.error_test_failures,
        s.linear_setups,
        s.last_order,
        s.last_step
    );
}

fn env_or(key: &str, default: f64) -> f64 {
    std::env::var(key)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

fn transient(c: &mut Criterion) {
    let model = Model::from_case_name("friction_bar").expect("friction bar assembles");
    let basis = build_basis(&model, BasisKind::Tvd, &BasisOptions::default()).expect("basis");
    println!(
        "friction bar ROM: g = {}, r = {}",
        basis.g,
        basis.phi.ncols()
    );
    let rom = ReducedModel::new(&model, basis.phi).expect("reduced model");
    let rom_end = env_or("JOINTROM_BENCH_ROM_END", 0.2);
    let full_end = env_or("JOINTROM_BENCH_FULL_END", 5e-4);
    let iterations = [
        ("functional", Iteration::Functional { anderson: 0 }),
        (
            "newton",
            Iteration::Newton {
                linear: NewtonLinear::Problem,
            },
        ),
    ];
    let mut group = c.benchmark_group("friction_bar_transient");
    group.sample_size(10);
    group.warm_up_time(Duration::from_millis(500));
    group.measurement_time(Duration::from_secs(5));
    for (name, it) in iterations {
        let sys = || ReducedSystem::new(&model, &rom).expect("reduced system");
        match run(sys(), &options(it, rom_end)) {
            Ok(r) => report(&format!("rom {name} (report window)"), rom_end, &r),
            Err(e) => println!("rom {name} (report window): failed: {e}"),
        }
        group.bench_function(format!("rom_{name}_0.02s"), |b| {
            b.iter(|| run(sys(), &options(it, 0.02)).expect("ROM run"))
        });
    }
    for (name, it) in iterations {
        let sys = || FullSystem::new(&model).expect("full system");
        match run(sys(), &options(it, full_end)) {
            Ok(r) => report(&format!("full {name} (report window)"), full_end, &r),
            Err(e) => println!("full {name} (report window): failed: {e}"),
        }
        group.bench_function(format!("full_{name}_1e-4s"), |b| {
            b.iter(|| run(sys(), &options(it, 1e-4)).expect("full run"))
        });
    }
    group.finish();
}

criterion_group!(benches, transient);
criterion_main!(benches);
