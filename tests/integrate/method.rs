//! The integration method of a run (`OdeOptions::method`) through the driver loop: the DIRK
//! path (ARKODE's ARKStep) against the BDF path (CVODE) on the reduced friction bar.

use jointrom::integrate::problem::{DirkTable, Method};
use jointrom::integrate::run;
use jointrom::reduction::{build_basis, BasisKind, BasisOptions};
use jointrom::system::{ReducedSystem, Scene};

use crate::common::{self, rel_l2};

/// The DIRK path through the driver loop gives the BDF path's curves on the reduced friction
/// bar (TVD basis, friction on, 20 ms) within the integration tolerance.
#[test]
fn dirk_run_gives_the_bdf_curves_on_the_reduced_friction_bar() {
    let model = common::model("friction_bar");
    let basis = build_basis(&model, BasisKind::Tvd, &BasisOptions::default()).expect("basis");
    let rom = ReducedSystem::new(&model, basis.phi).expect("ROM");
    let scene = Scene::of(&model);
    let bdf = common::until(0.02);
    let b = run(rom.clone(), &scene, &bdf).expect("BDF run");
    for table in [DirkTable::Ark324Dirk, DirkTable::Esdirk324] {
        let mut o = bdf.clone();
        o.ode.method = Method::Dirk(table);
        let d = run(rom.clone(), &scene, &o).expect("DIRK run");
        let n = b.curves.t.len();
        assert_eq!(d.curves.t.len(), n);
        let c = (&d.curves, &b.curves);
        let fc = rel_l2(&c.0.contact_force_norm, &c.1.contact_force_norm, n);
        let fr = rel_l2(&c.0.friction_force_norm, &c.1.friction_force_norm, n);
        let uy = rel_l2(&c.0.master_uy, &c.1.master_uy, n);
        let dd = rel_l2(&c.0.dissipated, &c.1.dissipated, n);
        println!(
            "{}: |f_c| {fc:.1e}, |f_R| {fr:.1e}, u_y {uy:.1e}, D {dd:.1e}; steps {} (BDF {}), \
             rhs {} ({}), order {}",
            table.name(),
            d.stats.steps,
            b.stats.steps,
            d.stats.rhs_evals,
            b.stats.rhs_evals,
            d.stats.last_order
        );
        assert!(d.curves.energy_check(o.energy_resolution()).ok);
        assert!(fc < 2e-3 && fr < 2e-3, "{}: forces moved", table.name());
        assert!(uy < 1e-4 && dd < 1e-3, "{}: u_y / D moved", table.name());
        assert_eq!(d.stats.last_order, table.order() as i32);
    }
}
