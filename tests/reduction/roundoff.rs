//! Round-off independence of the TVD basis: perturbing the model's K and M at the
//! level of their last digits must leave the active sets, the kept TVD columns, w(g), the
//! a-priori g and the reduced contact statics where they were.

use faer::Mat;
use jointrom::joint::statics::ContactOptions;
use jointrom::linalg::SymCsc;
use jointrom::reduction::{
    build_basis, craig_bampton, pod_tvd, trial_vector_derivatives, BasisKind, BasisOptions, Pod,
    Tvd, TvdOptions, DEFAULT_THRESHOLD,
};
use jointrom::rom::statics::reduced_contact_static_restarting;
use jointrom::system::ReducedSystem;
use jointrom::Model;

use crate::common;

/// A deterministic pseudo-random sign for the unordered index pair `{i, j}` (SplitMix64 of the
/// pair), so that a perturbation keeps a symmetric matrix symmetric.
fn sign(i: usize, j: usize, seed: u64) -> f64 {
    let (lo, hi) = (i.min(j) as u64, i.max(j) as u64);
    let mut z =
        seed ^ lo.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ hi.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    if z & 1 == 0 {
        1.0
    } else {
        -1.0
    }
}

/// `a` with every stored entry `a_ij` multiplied by `1 + rel · s_ij`, `s_ij = s_ji = ±1`.
fn perturbed(a: &SymCsc, rel: f64, seed: u64) -> SymCsc {
    let mut out = a.clone();
    for j in 0..a.n {
        for p in a.col_ptr[j]..a.col_ptr[j + 1] {
            out.values[p] *= 1.0 + rel * sign(a.row_idx[p], j, seed);
        }
    }
    out
}

/// The model with K and M perturbed at relative `rel`; the number of entries that changed.
fn perturbed_model(model: &Model, rel: f64) -> (Model, usize) {
    let mut out = model.clone();
    out.stiffness = perturbed(&model.stiffness, rel, 1);
    out.mass = perturbed(&model.mass, rel, 2);
    let changed = [(&model.stiffness, &out.stiffness), (&model.mass, &out.mass)]
        .iter()
        .map(|(a, b)| {
            a.values
                .iter()
                .zip(&b.values)
                .filter(|(x, y)| x != y)
                .count()
        })
        .sum();
    (out, changed)
}

/// The Craig–Bampton base (ν = 10), its TVD and their K-weighted POD.
fn tvd_and_pod(model: &Model) -> (Mat<f64>, Tvd, Pod) {
    let base = craig_bampton(model, 10).unwrap();
    let tvd = trial_vector_derivatives(model, base.as_ref(), &TvdOptions::default()).unwrap();
    let pod = pod_tvd(model, &tvd, true).unwrap();
    (base, tvd, pod)
}

/// `s_j = ±1` with `φ_j^b ≈ s_j φ_j^a`: an eigenvector's sign is not defined, and the eigen
/// solver's choice may flip with round-off (it does for some multilayer modes here). Flipping
/// φ_j swaps its `k = ±1` active sets and flips the sign of the TVD columns of φ_i = φ_j, none of
/// which changes the TVD space, its POD or a reduced result.
fn signs(a: &Mat<f64>, b: &Mat<f64>) -> Vec<i8> {
    (0..a.ncols())
        .map(|j| {
            let d: f64 = a
                .col(j)
                .iter()
                .zip(b.col(j).iter())
                .map(|(x, y)| x * y)
                .sum();
            if d < 0.0 {
                -1
            } else {
                1
            }
        })
        .collect()
}

/// The kept TVD columns `(i, k, j)` of `tvd` with `k` re-signed by `s_j`, sorted.
fn kept(tvd: &Tvd, s: &[i8]) -> Vec<(usize, i8, usize)> {
    let mut out: Vec<(usize, i8, usize)> =
        tvd.index.iter().map(|x| (x.i, x.k * s[x.j], x.j)).collect();
    out.sort_unstable();
    out
}

/// Reduced frictionless contact statics `‖f_c‖` (N) on the TVD basis with g joint modes.
fn reduced_fc(model: &Model, g: usize) -> f64 {
    let opts = BasisOptions {
        g: Some(g),
        ..BasisOptions::default()
    };
    let basis = build_basis(model, BasisKind::Tvd, &opts).unwrap();
    let rm = ReducedSystem::new(model, basis.phi).unwrap();
    // The product's path (the study's): the active-set Newton method, damped Newton where it
    // cycles on a coarse basis.
    reduced_contact_static_restarting(model, &rm, 1.0, &ContactOptions::default())
        .unwrap()
        .0
        .state
        .contact_force_norm
}

/// What moved between the model and its perturbed copy.
struct Moved {
    /// Base vectors whose sign the eigen solver flipped.
    flipped: Vec<usize>,
    /// `(j, k index, pairs)` of the active sets that changed (k re-signed by the flips).
    active: Vec<(usize, usize, usize)>,
    /// Whether the kept TVD columns `(i, ±k, j)` are the same.
    same_columns: bool,
    /// The a-priori g of both.
    g: (usize, usize),
    /// `max_g |Δw(g)|` (∞ when the POD sizes differ).
    dw: f64,
    /// `(g, ‖f_c‖, perturbed ‖f_c‖)` of the reduced statics.
    fc: Vec<(usize, f64, f64)>,
}

/// Builds the TVD basis of `model` and of its copy with K and M perturbed at 1e-15, and measures
/// what moved (printed too, so a failing run shows every figure).
fn measure(name: &str, gs: &[usize]) -> Moved {
    let model = common::model(name);
    let (pert, changed) = perturbed_model(&model, 1e-15);
    assert!(changed > 0, "{name}: the perturbation changed nothing");
    let (ba, ta, pa) = tvd_and_pod(&model);
    let (bb, tb, pb) = tvd_and_pod(&pert);
    let s = signs(&ba, &bb);
    let flipped: Vec<usize> = (0..s.len()).filter(|&j| s[j] < 0).collect();
    let active: Vec<(usize, usize, usize)> = (0..ta.active.len())
        .flat_map(|j| (0..2).map(move |k| (j, k)))
        .map(|(j, k)| {
            let kb = if s[j] < 0 { 1 - k } else { k };
            let (a, b) = (&ta.active[j][k], &tb.active[j][kb]);
            (j, k, a.iter().zip(b).filter(|(x, y)| x != y).count())
        })
        .filter(|m| m.2 > 0)
        .collect();
    let same_columns = kept(&ta, &vec![1; s.len()]) == kept(&tb, &s)
        && (ta.zero_columns, ta.negligible_columns) == (tb.zero_columns, tb.negligible_columns);
    let g = (
        pa.choose_g(DEFAULT_THRESHOLD),
        pb.choose_g(DEFAULT_THRESHOLD),
    );
    let dw = if pa.w.len() == pb.w.len() {
        pa.w.iter()
            .zip(&pb.w)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()))
    } else {
        f64::INFINITY
    };
    println!(
        "{name}: {changed} entries of K, M perturbed; sign flipped: base vectors {flipped:?}; \
         active sets moved (j, k, pairs): {active:?}; TVD kept {} / {}, zero {} / {}, negligible \
         {} / {}; a-priori g {} / {}; max |Δw(g)| {dw:.1e}",
        ta.nonzero(),
        tb.nonzero(),
        ta.zero_columns,
        tb.zero_columns,
        ta.negligible_columns,
        tb.negligible_columns,
        g.0,
        g.1
    );
    let fc = gs
        .iter()
        .map(|&g| {
            let (fa, fb) = (reduced_fc(&model, g), reduced_fc(&pert, g));
            println!(
                "{name}: g = {g}: reduced ‖f_c‖ {fa:.12e} N, perturbed {fb:.12e} N, relative \
                 change {:.1e}",
                (fa - fb).abs() / fa
            );
            (g, fa, fb)
        })
        .collect();
    Moved {
        flipped,
        active,
        same_columns,
        g,
        dw,
        fc,
    }
}

/// K and M multiplied entrywise by `1 + 1e-15 s` (s = ±1, symmetric) must leave the TVD basis
/// where it was: the same active sets and kept columns (up to the sign of the eigenvectors),
/// the same a-priori g, w(g) and the reduced contact statics to the round-off of the base.
///
/// The multilayer sheet's in-plane constraint modes (ux, uz, ry) open no gap: their gaps are
/// round-off, ≤ 1e-13 of their displacement. Judged against the largest gap (a rule not kept),
/// their active sets were signs of round-off, and this perturbation flipped 35, 63 and 64 of
/// their 86 pairs (and one round-off pair of uy), moved the a-priori g from 21 to 20, w(g) by
/// 2.4e-2 and the reduced ‖f_c‖ by 2.5e-2, 2.9e-3 and 1.1e-1 at g = 12, 20, 40.
///
/// What still moves is the base itself: the constraint modes by ~1e-9 (K's conditioning: stiff
/// welds), the multilayer's vibration modes by up to 3.5e-8 (three pairs of modes 1.7e-4 …
/// 2.8e-4 apart; their residuals are at the round-off of `‖K‖ ‖φ‖`). Hence the measured
/// `|Δw| ≤ 2.4e-7` (multilayer) and `≤ 2.0e-10` (friction bar) and `‖f_c‖` within 4.4e-7; the
/// bounds are those with margin (‖f_c‖: the target's 1e-6).
#[test]
fn tvd_basis_ignores_round_off_of_k_and_m() {
    for (name, gs, w_bound) in [
        ("multilayer_sheet", &[12, 20, 40][..], 1e-6),
        ("friction_bar", &[6, 12, 30][..], 1e-9),
    ] {
        let m = measure(name, gs);
        assert!(
            m.active.is_empty(),
            "{name}: active sets moved, (j, k, pairs): {:?} (sign flips {:?})",
            m.active,
            m.flipped
        );
        assert!(m.same_columns, "{name}: the kept TVD columns moved");
        assert_eq!(m.g.0, m.g.1, "{name}: a-priori g");
        assert!(m.dw < w_bound, "{name}: w(g) moved by {:e}", m.dw);
        for (g, fa, fb) in m.fc {
            let rel = (fa - fb).abs() / fa;
            assert!(
                rel < 1e-6,
                "{name}: g = {g}: reduced ‖f_c‖ moved by {rel:e}"
            );
        }
    }
}
