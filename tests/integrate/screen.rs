//! Pair screening of reduced models (`ProblemOptions::screen`) and the slip memory as elastic
//! stretch (`ProblemOptions::stretch`): the screened run evaluates a tracked subset of the pairs
//! and proves the others open, and the stretch states are a change of variables of the same
//! law, so their curves must be those of the run that evaluates every pair with the slip
//! states, to the integration tolerance — on a mesh fine enough that most pairs are far from
//! contact at any time.

use jointrom::integrate::{run, ProblemOptions, Run, TransientOptions};
use jointrom::reduction::{build_basis, BasisKind, BasisOptions};
use jointrom::system::{ReducedSystem, Scene, SecondOrderSystem};

use crate::common::{self, rel_l2};

/// The model of `case` and its TVD reduced model.
fn tvd_model(case: &str) -> (jointrom::model::Model, ReducedSystem) {
    let path = common::repo_path(case);
    let model = common::model(path.to_str().expect("path"));
    let basis = build_basis(&model, BasisKind::Tvd, &BasisOptions::default()).expect("basis");
    let rom = ReducedSystem::new(&model, basis.phi).expect("ROM");
    (model, rom)
}

/// The TVD model of `case` over `[0, end]` run with `change` applied to the default problem
/// options, and with the defaults; and its number of pairs.
fn runs(case: &str, end: f64, change: impl Fn(&mut ProblemOptions)) -> (Run, Run, usize) {
    let (model, rom) = tvd_model(case);
    let pairs = rom.pairs();
    let scene = Scene::of(&model);
    let off = common::until(end);
    assert!(!off.problem.screen, "screening is off by default");
    assert!(
        !off.problem.stretch,
        "the stretch states are off by default"
    );
    let mut on: TransientOptions = off.clone();
    change(&mut on.problem);
    let a = run(rom.clone(), &scene, &on).expect("changed run");
    let b = run(rom, &scene, &off).expect("default run");
    (a, b, pairs)
}

#[test]
fn screened_reduced_run_keeps_the_curves_and_evaluates_fewer_pairs() {
    // The friction bar refined 2× (173 pairs) over its first 20 ms: contact builds up under
    // the ramped load while most of the interface stays open.
    let (on, off, pairs) = runs("cases/scale/friction_bar_x2.json", 0.02, |p| {
        p.screen = true
    });
    assert_eq!(on.curves.t.len(), off.curves.t.len(), "output count");
    let n = on.curves.t.len();
    let fc = rel_l2(
        &on.curves.contact_force_norm,
        &off.curves.contact_force_norm,
        n,
    );
    let fr = rel_l2(
        &on.curves.friction_force_norm,
        &off.curves.friction_force_norm,
        n,
    );
    let uy = rel_l2(&on.curves.master_uy, &off.curves.master_uy, n);
    let d = rel_l2(&on.curves.dissipated, &off.curves.dissipated, n);
    let s = &on.stats;
    let mean = s.screen_tracked_sum as f64 / s.screen_builds.max(1) as f64;
    println!(
        "screened vs every pair: |f_c| {fc:.2e}, |f_R| {fr:.2e}, u_y {uy:.2e}, D {d:.2e}; \
         steps {} vs {}; builds {}, tracked mean {mean:.1} max {} of {pairs}, violations {}, \
         entries {}, exits {}, exact checks {} (right-hand sides {})",
        s.steps,
        off.stats.steps,
        s.screen_builds,
        s.screen_tracked_max,
        s.screen_violations,
        s.screen_entries,
        s.screen_exits,
        s.screen_exact_checks,
        s.rhs_evals
    );
    assert!(s.screen_builds > 0, "the screened run never built its set");
    assert_eq!(off.stats.screen_builds, 0, "screening while off");
    assert!(
        mean < 0.5 * pairs as f64,
        "the screen tracked {mean:.0} of {pairs} pairs on average"
    );
    for (what, e) in [("|f_c|", fc), ("|f_R|", fr), ("u_y", uy), ("D", d)] {
        assert!(e < 2e-3, "{what}(t) moved by {e:.2e} with screening");
    }
}

#[test]
fn stretch_states_keep_the_curves() {
    // The same law in other variables: the built-in friction bar over its first 50 ms (the
    // load ramp: closing, sticking and the onset of sliding) with every pair, and the ×2 bar
    // over 20 ms with screening.
    for (case, end, screen) in [
        ("cases/friction_bar.json", 0.05, false),
        ("cases/scale/friction_bar_x2.json", 0.02, true),
    ] {
        let (on, off, _) = runs(case, end, |p| {
            p.stretch = true;
            p.screen = screen;
        });
        let diff = common::curve_differences(&on, &off);
        println!(
            "{case}: stretch{} vs slip states: {diff:?}; steps {} vs {}",
            if screen { " + screening" } else { "" },
            on.stats.steps,
            off.stats.steps
        );
        for (what, e) in diff {
            assert!(
                e < 2e-3,
                "{case}: {what}(t) moved by {e:.2e} with the stretch states"
            );
        }
    }
}

#[test]
fn screened_run_leaves_the_untracked_memory_out_of_the_error_test() {
    // The same screened run with the open pairs' memory tested (`--open-slip-test on`) and
    // untested (the default, which with screening also frees the pairs outside the tracked
    // set): the same curves to the integration tolerance, by a different path.
    let (model, rom) = tvd_model("cases/scale/friction_bar_x2.json");
    let scene = Scene::of(&model);
    let mut opts = common::until(0.02);
    opts.problem.screen = true;
    assert!(
        !opts.problem.open_slip_test,
        "the open memory is untested by default"
    );
    let untested = run(rom.clone(), &scene, &opts).expect("screened run");
    opts.problem.open_slip_test = true;
    let tested = run(rom, &scene, &opts).expect("screened run testing every state");
    assert_ne!(
        untested.curves.master_uy, tested.curves.master_uy,
        "the weights changed nothing: the path is not taken"
    );
    let diffs = common::curve_differences(&untested, &tested);
    println!(
        "screened, untracked memory untested vs tested: {diffs:?}; steps {} vs {}, error-test \
         failures {} vs {}",
        untested.stats.steps,
        tested.stats.steps,
        untested.stats.error_test_failures,
        tested.stats.error_test_failures
    );
    for (what, e) in diffs {
        assert!(e < 2e-3, "{what}(t) moved by {e:.2e}");
    }
}
