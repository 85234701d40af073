//! Transient runs against the stored full-FE reference curves of `cases/reference/` (see its
//! SOURCE.md for the commands, tolerances and the convergence study).
//!
//! - A short window of the full model is re-run and compared with the stored curve: it checks
//!   that the engine still produces the reference (a regression test), at a tolerance above the
//!   reference's own integration error (the default-vs-100×-tighter difference over that window).
//! - Reduced models (TVD basis, K-weighted POD) are compared with the stored full-FE curves over
//!   the whole 0.2 s: g = 0 (Craig–Bampton only) misses the contact force by a factor of ~40, the
//!   w(g)-chosen g (w ≥ 0.999, g = 19) by ~30 % in ‖f_c‖ (the static study finds the same gap,
//!   see `jointrom::studies::convergence`), and the largest POD basis (all 51 POD modes) meets
//!   the 2 % target.

use jointrom::integrate::{run, Curves, TransientOptions};
use jointrom::reduction::{build_basis, BasisKind, BasisOptions};
use jointrom::rom::compare::ReferenceCurves;
use jointrom::system::{FullSystem, ReducedSystem, Scene};
use jointrom::Model;

use crate::common::{self, rel_l2};

struct Reference {
    t: Vec<f64>,
    contact_force_norm: Vec<f64>,
    friction_force_norm: Vec<f64>,
    master_uy: Vec<f64>,
}

fn reference(name: &str) -> Reference {
    let (path, v) = common::reference_json(name);
    let arr = |k: &str| -> Vec<f64> {
        v[k].as_array()
            .unwrap_or_else(|| panic!("{}: no array {k}", path.display()))
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect()
    };
    Reference {
        t: arr("t"),
        contact_force_norm: arr("contact_force_norm"),
        friction_force_norm: arr("friction_force_norm"),
        master_uy: arr("master_uy"),
    }
}

/// (‖f_c‖, master uy, ‖f_R‖) relative L2 differences of a run against a reference over the
/// run's outputs (same output times).
fn errors(c: &Curves, r: &Reference) -> (f64, f64, f64) {
    let n = c.t.len().min(r.t.len());
    for i in 0..n {
        assert!(
            (c.t[i] - r.t[i]).abs() < 1e-9,
            "output times differ at {i}: {} vs {}",
            c.t[i],
            r.t[i]
        );
    }
    let fr = if r.friction_force_norm[..n].iter().any(|&x| x != 0.0) {
        rel_l2(&c.friction_force_norm, &r.friction_force_norm, n)
    } else {
        0.0
    };
    (
        rel_l2(&c.contact_force_norm, &r.contact_force_norm, n),
        rel_l2(&c.master_uy, &r.master_uy, n),
        fr,
    )
}

fn options(friction: bool, end: Option<f64>) -> TransientOptions {
    let mut o = TransientOptions {
        end_time: end,
        ..TransientOptions::default()
    };
    o.problem.friction = friction;
    o
}

fn rom_errors(friction: bool, g: Option<usize>, r: &Reference) -> (usize, f64, f64, f64) {
    let model = common::model("friction_bar");
    let basis = build_basis(
        &model,
        BasisKind::Tvd,
        &BasisOptions {
            g,
            ..Default::default()
        },
    )
    .unwrap();
    let g_used = basis.g;
    let rom = ReducedSystem::new(&model, basis.phi).unwrap();
    let res = run(rom.clone(), &Scene::of(&model), &options(friction, None)).unwrap();
    assert_eq!(
        res.curves.t.len(),
        r.t.len(),
        "the ROM covers the reference window"
    );
    let (fc, uy, fr) = errors(&res.curves, r);
    eprintln!(
        "friction {friction}, g = {g_used} (r = {}): ‖f_c‖ {fc:.4}, uy {uy:.2e}, ‖f_R‖ {fr:.4}; {} steps, {:.2} s",
        rom.dim(),
        res.stats.steps,
        res.wall_s
    );
    (g_used, fc, uy, fr)
}

/// The full model over the first 0.01 s reproduces the stored curves with the settings they were
/// made with (the `transient` defaults, active-set refresh on; re-made 2026-11-26 with the
/// welds' re-meshed neighbourhoods); the default-vs-tight difference of the reference over this
/// window bounds the tolerance.
#[test]
fn full_model_short_window_reproduces_the_stored_reference() {
    let model = common::model("friction_bar");
    for (friction, name) in [
        (false, "friction_bar_full_friction_off"),
        (true, "friction_bar_full_friction_on"),
    ] {
        let r = reference(name);
        let sys = FullSystem::new(&model).unwrap();
        let opts = options(friction, Some(0.01));
        let res = run(sys, &Scene::of(&model), &opts).unwrap();
        assert_eq!(res.curves.t.len(), 101);
        let (fc, uy, fr) = errors(&res.curves, &r);
        eprintln!(
            "{name}: ‖f_c‖ {fc:.2e}, uy {uy:.2e}, ‖f_R‖ {fr:.2e}; {} steps, {:.2} s",
            res.stats.steps, res.wall_s
        );
        assert!(
            fc < 1e-3 && uy < 1e-4 && fr < 1e-3,
            "{name}: {fc} {uy} {fr}"
        );
    }
}

/// Friction off (the paper's Section 4.1.3 comparison): g = 0 fails, the w(g)-chosen g is ~40 %
/// off in ‖f_c‖ (the 2 % target is not met), all 51 POD modes meet it.
#[test]
fn rom_against_full_reference_friction_off() {
    let r = reference("friction_bar_full_friction_off");
    let (_, fc0, uy0, _) = rom_errors(false, Some(0), &r);
    // Measured 22.1 / 0.125 (DKMQ sheets, 2026-11-26; MITC4 with re-meshed weld
    // neighbourhoods 42.0 / 0.095, RBE3 area welds 21.4 / 0.152, point welds 32.7 / 0.385).
    assert!(fc0 > 5.0 && uy0 > 0.05, "g = 0: {fc0} {uy0}");
    let (g, fc, uy, _) = rom_errors(false, None, &r);
    eprintln!("friction off: g = 0 {fc0} {uy0}; chosen g = {g}: {fc} {uy}");
    assert!(g > 0 && g < 48);
    // Measured 0.389 / 3.6e-4 at the chosen g = 14 (DKMQ sheets, 2026-11-26; MITC4 with
    // re-meshed weld neighbourhoods g = 19, 0.302 / 1.5e-4; the RBE3 area welds chose g = 18
    // and were 0.044 / 3.1e-4 off, the point welds g = 12, 0.233 / 3.7e-3).
    assert!(fc < 0.5 && uy < 0.01, "chosen g = {g}: {fc} {uy}");
    let (_, fc48, uy48, _) = rom_errors(false, Some(51), &r);
    eprintln!("g = 51: {fc48} {uy48}");
    // Measured 0.0013 / 1.8e-5 with all 51 POD modes (DKMQ sheets; MITC4 with re-meshed weld
    // neighbourhoods 0.0013 / 2.6e-5, its g = 48 0.058 off; the RBE3 area welds' g = 48 was 0.0011 / 4.4e-6, the point
    // welds' 0.0133 / 1e-5).
    assert!(fc48 < 0.02 && uy48 < 1e-3, "g = 51: {fc48} {uy48}");
}

/// Friction on: the same picture for ‖f_c‖, uy and ‖f_R‖.
#[test]
fn rom_against_full_reference_friction_on() {
    let r = reference("friction_bar_full_friction_on");
    let (_, fc0, uy0, fr0) = rom_errors(true, Some(0), &r);
    assert!(
        fc0 > 5.0 && uy0 > 0.2 && fr0 > 5.0,
        "g = 0: {fc0} {uy0} {fr0}"
    );
    let (g, fc, uy, fr) = rom_errors(true, None, &r);
    // Measured 0.384 / 4.4e-3 / 0.384 at the chosen g = 14 (DKMQ sheets, 2026-11-26; MITC4
    // with re-meshed weld neighbourhoods g = 19, 0.304 / 3.8e-3 / 0.307; the RBE3 area welds
    // 0.220 / 4.4e-3 / 0.219): the a-priori rule gets the tip, not the forces.
    assert!(
        fc < 0.5 && uy < 0.01 && fr < 0.5,
        "chosen g = {g}: {fc} {uy} {fr}"
    );
}

/// End of the replayed piece of the x4 scale window, s (of its 4 ms).
const SCALE_PIECE_END: f64 = 1e-3;

/// The full model of the 10⁴-DOF scale window (`cases/scale/friction_bar_x4_window.json`) over
/// its first millisecond reproduces the stored reference of `cases/reference/scale/` (made by
/// the same defaults, see its SOURCE.md) with the exact low-rank refreshes of the Newton factor
/// in use. The piece has contact, friction and pairs switching; the tolerance is far above the
/// round-off differences between machines and below the integration error of the window.
#[test]
fn full_model_reproduces_the_scale_window_reference() {
    let case = common::repo_path("cases/scale/friction_bar_x4_window.json");
    let model = Model::from_case_name(case.to_str().unwrap()).unwrap();
    let r = ReferenceCurves::read(&common::repo_path(
        "cases/reference/scale/friction_bar_x4_window_full.csv",
    ))
    .unwrap();
    let opts = TransientOptions {
        end_time: Some(SCALE_PIECE_END),
        output_step: 1e-5,
        ..TransientOptions::default()
    };
    let res = run(FullSystem::new(&model).unwrap(), &Scene::of(&model), &opts).unwrap();
    let e = r.errors(&res.curves);
    let s = &res.stats;
    eprintln!(
        "x4 window to {SCALE_PIECE_END} s: {e:?}; {} steps, {} refreshes ({} low-rank), {:.2} s",
        s.steps, s.newton_refreshes, s.newton_low_rank, res.wall_s
    );
    assert_eq!(
        e.compared_outputs, 101,
        "the piece's outputs are in the reference"
    );
    let i =
        r.t.iter()
            .position(|&t| t >= SCALE_PIECE_END - 1e-12)
            .unwrap();
    assert!(
        r.contact_force_norm[i] > 0.0 && r.friction_force_norm[i] > 0.0,
        "the piece carries contact and friction"
    );
    assert!(s.newton_low_rank > 0, "the low-rank refresh is exercised");
    let (fc, fr, uy) = (
        e.contact_force.unwrap(),
        e.friction_force.unwrap(),
        e.master_uy.unwrap(),
    );
    assert!(fc < 1e-3 && fr < 1e-3 && uy < 1e-4, "{fc} {fr} {uy}");
}
