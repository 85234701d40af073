//! The stepping API for co-simulation (`jointrom::integrate::Stepper`): with the system's own
//! load it makes the driver loop's CVODE calls (identical curves), a load change restarts CVODE
//! once, and the load hook's `(1, 0)` is the system's own load exactly.

use jointrom::integrate::{run, Stepper, TransientOptions};
use jointrom::reduction::{build_basis, BasisKind, BasisOptions};
use jointrom::system::{ReducedSystem, Scene};

use crate::common;

/// A small TVD model of the friction bar (g = 4).
fn rom() -> (ReducedSystem, Scene) {
    let model = common::model("friction_bar");
    let opts = BasisOptions {
        g: Some(4),
        ..BasisOptions::default()
    };
    let b = build_basis(&model, BasisKind::Tvd, &opts).unwrap();
    (
        ReducedSystem::new(&model, b.phi).unwrap(),
        Scene::of(&model),
    )
}

#[test]
fn stepping_with_the_own_load_reproduces_the_driver_loop() {
    let (sys, scene) = rom();
    let end = 5e-3;
    let opts = common::until(end);
    let reference = run(sys.clone(), &scene, &opts).unwrap();
    let d = TransientOptions::default();
    let mut st = Stepper::new(sys, 0.0, &scene.contact, &d.ode, &d.problem).unwrap();
    assert_eq!(st.sample().master, [0.0; 6], "from rest");
    // The same load set again is no change.
    st.set_load(1.0, [0.0; 6]).unwrap();
    let mut uy = vec![st.sample().master[1]];
    let mut fc = vec![st.sample().contact_force_norm];
    for k in 1..reference.curves.t.len() {
        let s = st.advance(k as f64 * opts.output_step).unwrap();
        uy.push(s.master[1]);
        fc.push(s.contact_force_norm);
    }
    assert_eq!(uy, reference.curves.master_uy, "bit for bit");
    assert_eq!(fc, reference.curves.contact_force_norm);
    assert_eq!(st.stats().steps, reference.stats.steps);
    assert_eq!(st.restarts(), (0, 0));
    assert!(fc.last().unwrap() > &0.0);
}

#[test]
fn a_load_change_restarts_once_and_bad_values_are_refused() {
    let (sys, scene) = rom();
    let d = TransientOptions::default();
    let mut st = Stepper::new(sys, 0.0, &scene.contact, &d.ode, &d.problem).unwrap();
    st.advance(1e-3).unwrap();
    let before = st.sample().master[1];
    // A held downward force at the master node on top of the own load.
    st.set_load(1.0, [0.0, -0.5, 0.0, 0.0, 0.0, 0.0]).unwrap();
    st.set_load(1.0, [0.0, -0.5, 0.0, 0.0, 0.0, 0.0]).unwrap();
    assert_eq!(st.load(), (1.0, [0.0, -0.5, 0.0, 0.0, 0.0, 0.0]));
    for k in 2..=4 {
        st.advance(k as f64 * 1e-3).unwrap();
    }
    assert_eq!(st.restarts().0, 1, "one restart for one change");
    assert!(st.sample().master[1] < before, "pushed down");
    let e = st.set_load(f64::NAN, [0.0; 6]).unwrap_err().to_string();
    assert!(e.contains("load scale"), "{e}");
    let e = st.set_load(1.0, [0.0, 0.0, 0.0, f64::INFINITY, 0.0, 0.0]);
    assert!(e.unwrap_err().to_string().contains("Mx"));
    assert_eq!(st.load(), (1.0, [0.0, -0.5, 0.0, 0.0, 0.0, 0.0]), "kept");
    let t = st.t();
    for bad in [t, t - 1e-3, f64::NAN] {
        let e = st.advance(bad).unwrap_err().to_string();
        assert!(e.contains("after the current time"), "{e}");
    }
    assert!(Stepper::new(rom().0, f64::NAN, &scene.contact, &d.ode, &d.problem).is_err());
}

#[test]
fn the_step_budget_applies_to_each_advance() {
    // A co-simulation runs for as long as its importer wants: OdeOptions::max_steps bounds one
    // advance, not the whole run as in the driver loop.
    let (sys, scene) = rom();
    let end = 5e-3;
    let steps = run(sys.clone(), &scene, &common::until(end))
        .unwrap()
        .stats
        .steps;
    let mut opts = common::until(end);
    opts.ode.max_steps = (steps / 3) as usize;
    let e = run(sys.clone(), &scene, &opts).unwrap_err().to_string();
    assert!(e.contains("CV_TOO_MUCH_WORK"), "{e}");
    let mut st = Stepper::new(sys.clone(), 0.0, &scene.contact, &opts.ode, &opts.problem).unwrap();
    for k in 1..=50 {
        st.advance(k as f64 * end / 50.0).unwrap();
    }
    assert!(st.stats().steps > steps / 3, "{} steps", st.stats().steps);
    let mut one = Stepper::new(sys, 0.0, &scene.contact, &opts.ode, &opts.problem).unwrap();
    let e = one.advance(end).unwrap_err().to_string();
    assert!(e.contains("CV_TOO_MUCH_WORK"), "{e}");
}
