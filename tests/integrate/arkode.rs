//! The ARKStep DIRK integrator (`jointrom::integrate::Arkode`, chosen through `Integrator` by
//! `Method::Dirk`) against exact solutions: every table on an undamped oscillator with a stiff
//! undamped mode beside it, with the problem's Newton solver and with the dense one; options it
//! refuses; restarts; create/drop cycles with failures (the valgrind target).

use std::f64::consts::PI;

use jointrom::integrate::problem::{
    DirkTable, Iteration, Method, NewtonLinear, OdeOptions, OdeStats, Stop,
};
use jointrom::integrate::{Arkode, Integrator};

use super::cvode::{Fault, Faulty, Linear, OMEGA};

/// The stiff mode's ω, rad/s (100 kHz: h ω ≫ 1 at the steps the soft mode needs).
const OMEGA_STIFF: f64 = 2.0 * PI * 1e5;

/// Two uncoupled undamped oscillators y = [x1, v1, x2, v2], ω = [`OMEGA`], [`OMEGA_STIFF`].
fn two_modes() -> Linear {
    let (a, b) = (OMEGA * OMEGA, OMEGA_STIFF * OMEGA_STIFF);
    #[rustfmt::skip]
    let m = vec![
        0.0, 1.0, 0.0, 0.0,
        -a, 0.0, 0.0, 0.0,
        0.0, 0.0, 0.0, 1.0,
        0.0, 0.0, -b, 0.0,
    ];
    Linear::new(4, m)
}

fn dirk(table: DirkTable, linear: NewtonLinear) -> OdeOptions {
    OdeOptions {
        method: Method::Dirk(table),
        iteration: Iteration::Newton { linear },
        ..OdeOptions::default()
    }
}

/// Runs to t = 0.05 s (5 periods of the soft mode) from x1 = 1 (the stiff mode at rest, but
/// excited by round-off and the error of the steps) with outputs every 1e-3 s; the soft mode's
/// error max(|x1 − cos ωt|, |v1/ω + sin ωt|) at the end, the stiff mode's largest |x2|.
fn run(problem: Linear, opts: &OdeOptions) -> (f64, f64, OdeStats) {
    let mut int = Integrator::new(problem, 0.0, &[1.0, 0.0, 0.0, 0.0], opts).unwrap();
    let mut stiff: f64 = 0.0;
    for k in 1..=50 {
        let t = k as f64 * 1e-3;
        assert_eq!(int.solve_to(t).unwrap(), Stop::Reached(t));
        stiff = stiff.max(int.y()[2].abs());
    }
    let (t, y) = (int.t(), int.y());
    let err = (y[0] - (OMEGA * t).cos())
        .abs()
        .max((y[1] / OMEGA + (OMEGA * t).sin()).abs());
    (err, stiff, int.stats())
}

#[test]
fn every_table_matches_the_exact_soft_mode_beside_a_stiff_one() {
    let mut bad = Vec::new();
    for table in DirkTable::ALL {
        for linear in [NewtonLinear::Problem, NewtonLinear::DenseDq] {
            if linear == NewtonLinear::DenseDq && table.order() > 3 {
                continue;
            }
            let opts = dirk(table, linear);
            let (err, stiff, s) = run(two_modes(), &opts);
            println!(
                "{} {linear:?}: error {err:.2e}, stiff |x2| {stiff:.1e}, steps {}, rhs {}, \
                 newton {}, setups {}, err fails {}, conv fails {}",
                table.name(),
                s.steps,
                s.rhs_evals,
                s.nonlinear_iterations,
                s.linear_setups,
                s.error_test_failures,
                s.nonlinear_conv_failures
            );
            // A wrong γ, sign or stage time gives errors of order 1; the bound leaves room for
            // what the stages started from the last solution converge to with the higher
            // tables (measured up to 1.0e-3, ARK548L2SA_DIRK_8_4_5).
            if !(err < 2e-3 && stiff < 1e-6) {
                bad.push(format!(
                    "{} {linear:?}: error {err:e}, stiff {stiff:e}",
                    table.name()
                ));
            }
            assert_eq!(s.last_order, table.order() as i32);
            assert!(s.steps > 0 && s.rhs_evals >= s.steps);
        }
    }
    assert!(bad.is_empty(), "{bad:#?}");
}

/// Options a DIRK method cannot take are refused with the field's name, before any C call;
/// table names parse with or without ARKODE's prefix, and nothing else parses.
#[test]
fn bad_options_are_named() {
    let y0 = [1.0, 0.0];
    let base = dirk(DirkTable::Sdirk534, NewtonLinear::Problem);
    let cases: Vec<(OdeOptions, &str)> = vec![
        (
            OdeOptions {
                iteration: Iteration::Functional { anderson: 0 },
                ..base.clone()
            },
            "iteration",
        ),
        (
            OdeOptions {
                stab_lim_det: true,
                ..base.clone()
            },
            "stab_lim_det",
        ),
        (
            OdeOptions {
                rtol: f64::NAN,
                ..base.clone()
            },
            "rtol",
        ),
        (
            OdeOptions {
                max_steps: 0,
                ..base.clone()
            },
            "max_steps",
        ),
        (
            OdeOptions {
                step_growth: 0.5,
                ..base.clone()
            },
            "step_growth",
        ),
        (
            OdeOptions {
                method: Method::Bdf,
                ..base.clone()
            },
            "method",
        ),
    ];
    for (opts, field) in cases {
        let e = Arkode::new(Linear::oscillator(), 0.0, &y0, &opts)
            .err()
            .unwrap();
        assert!(e.to_string().contains(field), "{field}: {e}");
    }
    // CVODE refuses a DIRK method by name.
    let e = jointrom::integrate::Cvode::new(Linear::oscillator(), 0.0, &y0, &base)
        .err()
        .unwrap();
    assert!(e.to_string().contains("method"), "{e}");
    assert_eq!(
        DirkTable::from_name("sdirk_5_3_4"),
        Some(DirkTable::Sdirk534)
    );
    assert_eq!(
        DirkTable::from_name("ARKODE_ARK436L2SA_DIRK_6_3_4"),
        Some(DirkTable::Ark436Dirk)
    );
    for t in DirkTable::ALL {
        assert_eq!(DirkTable::from_name(t.name()), Some(t));
        let short = t.name().trim_start_matches("ARKODE_");
        assert!(
            jointrom::integrate::problem::DIRK_TABLE_NAMES.contains(short),
            "{short} missing from the list of names"
        );
    }
    for bad in ["", "RK4", "ARKODE_", "SDIRK_2_1_2", "ARKODE_ERK_NONE"] {
        assert_eq!(DirkTable::from_name(bad), None, "{bad:?}");
        let e = jointrom::integrate::driver::dirk_table_flag("dirk-table", bad).unwrap_err();
        assert!(e.to_string().contains("--dirk-table"), "{e}");
    }
}

/// Restarts keep the statistics cumulative; a stop time is hit exactly.
#[test]
fn stop_time_and_reinit_keep_counting() {
    let opts = dirk(DirkTable::Kvaerno423, NewtonLinear::Problem);
    let mut a = Arkode::new(Linear::oscillator(), 0.0, &[1.0, 0.0], &opts).unwrap();
    a.set_stop_time(0.0123).unwrap();
    assert_eq!(a.solve_to(0.05).unwrap(), Stop::Reached(0.0123));
    assert!((a.y()[0] - (OMEGA * 0.0123).cos()).abs() < 1e-5);
    let before = a.stats();
    let (t, y) = (a.t(), a.y().to_vec());
    a.reinit(t, &y).unwrap();
    assert_eq!(a.stats().steps, before.steps);
    assert_eq!(a.solve_to(0.05).unwrap(), Stop::Reached(0.05));
    let after = a.stats();
    assert!(after.steps > before.steps);
    assert!((a.y()[0] - (OMEGA * 0.05).cos()).abs() < 1e-5);
    let p = a.into_problem();
    assert_eq!(p.rhs_calls, after.rhs_evals + after.rhs_evals_jac);
}

/// Create / integrate / drop cycles with both linear solvers and a failed construction (the
/// valgrind target: `scripts/valgrind.sh` runs the `arkode::` tests).
#[test]
fn create_drop_cycles() {
    let mut steps = 0;
    for cycle in 0..30 {
        for linear in [NewtonLinear::Problem, NewtonLinear::DenseDq] {
            let opts = dirk(DirkTable::ALL[cycle % DirkTable::ALL.len()], linear);
            let mut a = Arkode::new(Linear::oscillator(), 0.0, &[1.0, 0.0], &opts).unwrap();
            a.solve_to(1e-3).unwrap();
            steps += a.stats().steps;
            if cycle % 2 == 0 {
                assert!(a.into_problem().rhs_calls > 0);
            }
        }
        // Failures mid-run (a panic in the right-hand side, in the Newton solve), then drop.
        for fault in [Fault::PanicRhs, Fault::PanicNewtonSolve] {
            let opts = dirk(DirkTable::Kvaerno423, NewtonLinear::Problem);
            let mut a = Arkode::new(Faulty::new(fault), 0.0, &[1.0, 0.0], &opts).unwrap();
            let e = a.solve_to(0.01).unwrap_err();
            assert!(e.to_string().contains("panicked"), "{e}");
        }
        let bad = OdeOptions {
            max_steps: 0,
            ..dirk(DirkTable::Trbdf2, NewtonLinear::Problem)
        };
        assert!(Arkode::new(Linear::oscillator(), 0.0, &[1.0, 0.0], &bad).is_err());
    }
    assert!(steps > 0);
}
