//! The active-set refresh of the Newton iteration (`ProblemOptions::refresh`) against the
//! modified Newton iteration without it: the same curves to integration accuracy, fewer steps
//! and convergence failures, on the reduced and the full friction bar.

use jointrom::integrate::{run, Run, TransientOptions};
use jointrom::reduction::{build_basis, BasisKind, BasisOptions};
use jointrom::system::{FullSystem, ReducedSystem, Scene, SecondOrderSystem};

use crate::common::{self, rel_l2};

fn pair<S: SecondOrderSystem>(system: impl Fn() -> S, scene: &Scene, end: f64) -> (Run, Run) {
    let on = common::until(end);
    assert!(on.problem.refresh.is_some(), "refresh is on by default");
    let mut off: TransientOptions = on.clone();
    off.problem.refresh = None;
    let a = run(system(), scene, &on).expect("run with refresh");
    let b = run(system(), scene, &off).expect("run without refresh");
    (a, b)
}

fn compare(what: &str, on: &Run, off: &Run, fc_tol: f64) {
    let n = on.curves.t.len().min(off.curves.t.len());
    assert_eq!(
        on.curves.t.len(),
        off.curves.t.len(),
        "{what}: output count"
    );
    let fc = rel_l2(
        &on.curves.contact_force_norm,
        &off.curves.contact_force_norm,
        n,
    );
    let uy = rel_l2(&on.curves.master_uy, &off.curves.master_uy, n);
    let (s_on, s_off) = (&on.stats, &off.stats);
    println!(
        "{what}: |f_c| {fc:.2e}, u_y {uy:.2e}; steps {} vs {}, convergence failures {} vs {}, \
         refreshes {}",
        s_on.steps,
        s_off.steps,
        s_on.nonlinear_conv_failures,
        s_off.nonlinear_conv_failures,
        s_on.newton_refreshes
    );
    assert!(fc < fc_tol, "{what}: |f_c|(t) moved by {fc:.2e}");
    assert!(uy < 1e-4, "{what}: u_y(t) moved by {uy:.2e}");
    assert!(s_on.newton_refreshes > 0, "{what}: no refresh happened");
    assert_eq!(s_off.newton_refreshes, 0, "{what}: refreshes while off");
    assert!(
        s_on.steps < s_off.steps && s_on.nonlinear_conv_failures < s_off.nonlinear_conv_failures,
        "{what}: the refresh saved nothing"
    );
}

#[test]
fn refresh_keeps_the_reduced_curves_and_saves_steps() {
    let model = common::model("friction_bar");
    let basis = build_basis(&model, BasisKind::Tvd, &BasisOptions::default()).expect("basis");
    let rom = ReducedSystem::new(&model, basis.phi).expect("ROM");
    let (on, off) = pair(|| rom.clone(), &Scene::of(&model), 0.1);
    compare("ROM", &on, &off, 2e-3);
}

#[test]
fn refresh_keeps_the_full_curves_and_saves_steps() {
    let model = common::model("friction_bar");
    let full = || FullSystem::new(&model).expect("full");
    let (on, off) = pair(full, &Scene::of(&model), 0.03);
    compare("full", &on, &off, 2e-3);
}
