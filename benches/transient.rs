//! Transient benchmarks: the friction bar with friction, at the paper's Table 1
//! tolerances (rtol 1e-8, atol 1e-6 mm) with the transient defaults (BDF max order 2, velocity
//! atol 1e3 1/s × atol, events off, see `jointrom::integrate::mechanical`):
//!
//! - ROM with the w(g)-chosen TVD basis, functional iteration and Newton (structured solve);
//! - full FE model, functional iteration and Newton (structured sparse solve).
//!
//! Each configuration is first run once over its *report window* and its wall and CPU time and
//! solver statistics are printed: ROM 0.2 s (the case's end time), full Newton 0.2 s, full
//! functional 5e-4 s — its steps are bounded by the stiffest membrane mode (~1e-8 s), so 0.2 s
//! would take hours; the printout extrapolates. Override with `JOINTROM_BENCH_ROM_END`,
//! `JOINTROM_BENCH_FULL_END`, `JOINTROM_BENCH_FULL_FUNCTIONAL_END`. Criterion then times a shorter
//! window (ROM 0.02 s, full 1e-4 s) with 10 samples. Target for the ROM with friction: ≤ 0.3 s
//! wall for 0.2 s. Measured figures: docs/validation/transient.md.

use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion};
use jointrom::integrate::problem::{Iteration, NewtonLinear, OdeOptions};
use jointrom::integrate::{run, ProblemOptions, Run, TransientOptions};
use jointrom::reduction::{build_basis, BasisKind, BasisOptions};
use jointrom::system::{FullSystem, ReducedSystem, Scene};
use jointrom::Model;

fn options(iteration: Iteration, end: f64) -> TransientOptions {
    let d = TransientOptions::default();
    TransientOptions {
        ode: OdeOptions { iteration, ..d.ode },
        problem: ProblemOptions {
            friction: true,
            events: false,
            ..d.problem
        },
        end_time: Some(end),
        ..d
    }
}

fn report(name: &str, end: f64, r: &Run) {
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
    let rom = ReducedSystem::new(&model, basis.phi).expect("reduced model");
    let scene = Scene::of(&model);
    let rom_end = env_or("JOINTROM_BENCH_ROM_END", 0.2);
    let full_end = env_or("JOINTROM_BENCH_FULL_END", 0.2);
    let full_functional_end = env_or("JOINTROM_BENCH_FULL_FUNCTIONAL_END", 5e-4);
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
        let sys = || rom.clone();
        match run(sys(), &scene, &options(it, rom_end)) {
            Ok(r) => report(&format!("rom {name} (report window)"), rom_end, &r),
            Err(e) => println!("rom {name} (report window): failed: {e}"),
        }
        group.bench_function(format!("rom_{name}_0.02s"), |b| {
            b.iter(|| run(sys(), &scene, &options(it, 0.02)).expect("ROM run"))
        });
    }
    for (name, it) in iterations {
        let sys = || FullSystem::new(&model).expect("full system");
        let end = if name == "functional" {
            full_functional_end
        } else {
            full_end
        };
        match run(sys(), &scene, &options(it, end)) {
            Ok(r) => {
                report(&format!("full {name} (report window)"), end, &r);
                if end < rom_end {
                    println!(
                        "full {name}: {rom_end} s would take ~{:.0} s wall at this rate",
                        r.wall_s * rom_end / end
                    );
                }
            }
            Err(e) => println!("full {name} (report window): failed: {e}"),
        }
        group.bench_function(format!("full_{name}_1e-4s"), |b| {
            b.iter(|| run(sys(), &scene, &options(it, 1e-4)).expect("full run"))
        });
    }
    group.finish();
}

criterion_group!(benches, transient);
criterion_main!(benches);
