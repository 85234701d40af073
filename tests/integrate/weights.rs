//! The error weights of a reduced model's step (`ProblemOptions::open_slip_test`): the slip
//! memory of a pair open at the step's start is slaved to the pair's tangential motion (it
//! relaxes to `u_t` with τ = 1e-6 s), so a reduced model gives its states zero weight by
//! default (`--open-slip-test on` tests them); every other weight is the integrator's own
//! `1 / (rtol |y_i| + atol_i)`, bit for bit. The curves must stay those of the run that tests
//! every state, to the integration tolerance, and the full model must keep its test (and its
//! bits).

use jointrom::integrate::problem::OdeProblem;
use jointrom::integrate::{run, MechanicalOde, ProblemOptions, TransientOptions};
use jointrom::reduction::{build_basis, BasisKind, BasisOptions};
use jointrom::system::{FullSystem, ReducedSystem, Scene, SecondOrderSystem};

use crate::common;

/// The friction bar's TVD model.
fn friction_bar_rom() -> (jointrom::model::Model, ReducedSystem) {
    let path = common::repo_path("cases/friction_bar.json");
    let model = common::model(path.to_str().expect("path"));
    let basis = build_basis(&model, BasisKind::Tvd, &BasisOptions::default()).expect("basis");
    let rom = ReducedSystem::new(&model, basis.phi).expect("ROM");
    (model, rom)
}

#[test]
fn open_pairs_memory_gets_zero_weight_and_every_other_weight_is_kept() {
    let (model, rom) = friction_bar_rom();
    let (n, w) = (rom.dim(), rom.pairs());
    assert!(
        !ProblemOptions::default().open_slip_test,
        "the open pairs' memory is out of the test by default"
    );
    let opts = ProblemOptions {
        open_slip_test: false,
        ..ProblemOptions::default()
    };
    let margin = opts.refresh.expect("refresh on by default");
    let mut ode = MechanicalOde::new(rom.clone(), &model.contact, &opts).expect("problem");
    assert!(
        ode.adjusts_error_weights(),
        "a reduced model adjusts its weights"
    );
    // A state whose coordinates open some pairs and close others.
    let mut y = vec![0.0; ode.dim()];
    for (j, x) in y[..n].iter_mut().enumerate() {
        *x = 1e-3 * ((j as f64 * 0.7).sin() + 0.3 * (j as f64 * 1.9).cos());
    }
    for (j, x) in y[n..].iter_mut().enumerate() {
        *x = 0.5 * (j as f64 * 0.37).cos();
    }
    let gaps: Vec<f64> = (0..w).map(|k| rom.joint_pair(&y[..n], k)[0]).collect();
    let open = gaps.iter().filter(|&&g| g > margin).count();
    assert!(
        open > 0 && open < w,
        "the test state opens {open} of {w} pairs: it must open some and close others"
    );
    let mut scale = vec![0.0; ode.dim()];
    assert!(ode.atol_scale(&mut scale));
    let (rtol, atol) = (1e-7, 1e-5);
    let given: Vec<f64> = y
        .iter()
        .zip(&scale)
        .map(|(yi, si)| 1.0 / (rtol * yi.abs() + atol * si))
        .collect();
    // Before any right-hand side the weights read the gaps at `y`; after one, those of its
    // state (here the same `y`): both must give the same weights.
    let mut before = given.clone();
    ode.adjust_error_weights(&y, &mut before).expect("weights");
    let mut ydot = vec![0.0; ode.dim()];
    ode.rhs(0.0, &y, &mut ydot).expect("rhs");
    let mut ewt = given.clone();
    ode.adjust_error_weights(&y, &mut ewt).expect("weights");
    assert_eq!(
        before, ewt,
        "weights from the gaps at y and at the last right-hand side"
    );
    for (i, (&a, &b)) in ewt.iter().zip(&given).enumerate() {
        let pair = i.checked_sub(2 * n).map(|s| s / 2).filter(|&k| k < w);
        match pair {
            Some(k) if gaps[k] > margin => {
                assert_eq!(a, 0.0, "state {i}: open pair {k}'s memory has weight {a}")
            }
            _ => assert_eq!(
                a.to_bits(),
                b.to_bits(),
                "state {i}: weight {a} changed from {b}"
            ),
        }
    }
    // Tested when asked, and always by the full model.
    let tested = ProblemOptions {
        open_slip_test: true,
        ..opts
    };
    let ode = MechanicalOde::new(rom, &model.contact, &tested).expect("problem");
    assert!(!ode.adjusts_error_weights());
    let full = MechanicalOde::new(
        FullSystem::new(&model).expect("full"),
        &model.contact,
        &opts,
    )
    .expect("full problem");
    assert!(
        !full.adjusts_error_weights(),
        "the full model tests every state"
    );
}

#[test]
fn untested_open_memory_keeps_the_curves() {
    // The built-in friction bar over its first 50 ms: the load ramp, pairs closing, sticking
    // and starting to slide, most of the interface open.
    let (model, rom) = friction_bar_rom();
    let scene = Scene::of(&model);
    let untested = common::until(0.05);
    let mut tested: TransientOptions = untested.clone();
    tested.problem.open_slip_test = true;
    let a = run(rom.clone(), &scene, &untested).expect("run without the open memory's test");
    let b = run(rom, &scene, &tested).expect("run testing every state");
    let diff = common::curve_differences(&a, &b);
    println!(
        "open memory untested vs tested: {diff:?}; steps {} vs {}",
        a.stats.steps, b.stats.steps
    );
    assert_ne!(
        a.curves.master_uy, b.curves.master_uy,
        "the weights changed nothing: the path is not taken"
    );
    for (what, e) in diff {
        assert!(
            e < 2e-3,
            "{what}(t) moved by {e:.2e} with the open memory untested"
        );
    }
}

#[test]
fn full_model_keeps_its_bits() {
    // The option is the reduced models' alone: the full model's run is the same bit for bit.
    let path = common::repo_path("cases/friction_bar.json");
    let model = common::model(path.to_str().expect("path"));
    let scene = Scene::of(&model);
    let default = common::until(0.003);
    let mut tested: TransientOptions = default.clone();
    tested.problem.open_slip_test = true;
    let full = || FullSystem::new(&model).expect("full");
    let a = run(full(), &scene, &default).expect("default run");
    let b = run(full(), &scene, &tested).expect("tested run");
    assert_eq!(a.stats.steps, b.stats.steps);
    assert_eq!(a.curves.contact_force_norm, b.curves.contact_force_norm);
    assert_eq!(a.curves.master_uy, b.curves.master_uy);
}
