//! The competitor reduction bases of the paper's Section 5: Joint Interface Modes (5.3), all
//! joint DOF kept (5.1) and POD of transient snapshots (5.2), against independent computations,
//! plus the TVD convergence of the reduced contact statics.

// Index loops mirror the matrix formulas, as in the library.
#![allow(clippy::needless_range_loop)]

use std::time::Instant;

use faer::{Mat, MatRef};
use jointrom::case::Case;
use jointrom::error::ReductionError;
use jointrom::joint::statics::{ContactOptions, ContactState};
use jointrom::linalg::cholesky::SparseCholesky;
use jointrom::linalg::SymCsc;
use jointrom::model::contact_static_full;
use jointrom::reduction::{
    alldof_vectors, build_basis, jim_dofs, joint_interface_modes, snapshot_basis, snapshot_pod,
    BasisKind, BasisOptions, JimSet,
};
use jointrom::system::ReducedSystem;
use jointrom::{Error, Model};

use crate::common::{self, col, mul, norm};

/// `Xᵀ A X` for sparse symmetric A.
fn gram(a: &SymCsc, x: MatRef<'_, f64>) -> Mat<f64> {
    let ax: Vec<Vec<f64>> = (0..x.ncols()).map(|c| mul(a, &col(x, c))).collect();
    Mat::from_fn(x.ncols(), x.ncols(), |i, j| {
        (0..x.nrows()).map(|r| x[(r, i)] * ax[j][r]).sum()
    })
}

/// Frobenius norm of `G − I`.
fn dev_from_identity(g: &Mat<f64>) -> f64 {
    let mut s = 0.0;
    for i in 0..g.nrows() {
        for j in 0..g.ncols() {
            let e = if i == j { 1.0 } else { 0.0 };
            s += (g[(i, j)] - e).powi(2);
        }
    }
    s.sqrt()
}

/// The principal submatrix of `a` on the sorted index list `idx`.
fn submatrix(a: &SymCsc, idx: &[usize]) -> SymCsc {
    let mut pos = vec![usize::MAX; a.n];
    for (k, &i) in idx.iter().enumerate() {
        pos[i] = k;
    }
    let mut col_ptr = vec![0];
    let mut row_idx = Vec::new();
    let mut values = Vec::new();
    for &j in idx {
        for p in a.col_ptr[j]..a.col_ptr[j + 1] {
            let r = pos[a.row_idx[p]];
            if r != usize::MAX {
                row_idx.push(r);
                values.push(a.values[p]);
            }
        }
        col_ptr.push(row_idx.len());
    }
    SymCsc {
        n: idx.len(),
        col_ptr,
        row_idx,
        values,
    }
}

/// Reduced frictionless contact statics on a basis Φ under `load`: the state and the master
/// displacement.
fn try_reduced_contact(
    model: &Model,
    phi: Mat<f64>,
    load: [f64; 6],
) -> Result<(ContactState, [f64; 6]), Error> {
    let red = ReducedSystem::new(model, phi)?;
    let (eta, state) = common::reduced_contact(&red, load, model.contact.normal_stiffness)?;
    let um = std::array::from_fn(|d| {
        (0..red.dim())
            .map(|c| red.phi_master[(d, c)] * eta[c])
            .sum()
    });
    Ok((state, um))
}

fn reduced_contact(model: &Model, phi: Mat<f64>, load: [f64; 6]) -> (ContactState, [f64; 6]) {
    try_reduced_contact(model, phi, load).unwrap()
}

fn scaled(load: [f64; 6], s: f64) -> [f64; 6] {
    load.map(|v| v * s)
}

fn rel_master(a: &[f64; 6], b: &[f64; 6]) -> f64 {
    let d: Vec<f64> = a.iter().zip(b).map(|(x, y)| x - y).collect();
    norm(&d) / norm(b)
}

#[test]
fn jim_and_alldof_build_for_both_scenes_m_orthonormal() {
    for name in Case::BUILTIN {
        let model = common::model(name);
        let w = model.joint.pairs();
        for (kind, g) in [
            (BasisKind::Jim, Some(20)),
            (BasisKind::Jim, None),
            (BasisKind::AllDof, None),
        ] {
            let opts = BasisOptions {
                g,
                ..Default::default()
            };
            let t = Instant::now();
            let b = build_basis(&model, kind, &opts).unwrap();
            let ms = t.elapsed().as_secs_f64() * 1e3;
            let dev = dev_from_identity(&gram(&model.mass, b.phi.as_ref()));
            eprintln!(
                "{name} {} g={:?}: r = {}, g = {}, dropped = {}, ‖ΦᵀMΦ − I‖_F = {dev:.2e}, {ms:.1} ms",
                kind.name(),
                g,
                b.phi.ncols(),
                b.g,
                b.dropped
            );
            assert!(dev <= 1e-10, "{name} {}: ‖ΦᵀMΦ − I‖ = {dev:e}", kind.name());
            // The modal rotation: ΦᵀKΦ = diag(eigenvalues), ascending.
            let kt = gram(&model.stiffness, b.phi.as_ref());
            let r = b.phi.ncols();
            assert_eq!(b.eigenvalues.len(), r);
            assert!(b.eigenvalues.windows(2).all(|w| w[0] <= w[1]));
            let lmax = b.eigenvalues[r - 1];
            for i in 0..r {
                let d = (kt[(i, i)] - b.eigenvalues[i]).abs();
                assert!(d <= 1e-10 * lmax, "{name}: K̃[{i},{i}] − ω² = {d:e}");
                for j in 0..i {
                    let off = kt[(i, j)].abs();
                    assert!(off <= 1e-9 * lmax, "{name}: K̃[{i},{j}] = {off:e}");
                }
            }
            assert_eq!(b.phi.nrows(), model.dofs());
            assert_eq!(
                b.phi.ncols() + b.dropped,
                16 + b.g,
                "{name} {}",
                kind.name()
            );
            match (kind, g) {
                (BasisKind::AllDof, _) => {
                    assert_eq!(b.g, w);
                    assert!(b.w.is_empty());
                }
                (BasisKind::Jim, Some(g)) => {
                    assert_eq!(b.g, g);
                    assert!(b.w.is_empty());
                }
                _ => {
                    // g chosen by the TVD's w(g) threshold, exactly as for Tvd.
                    let tvd =
                        build_basis(&model, BasisKind::Tvd, &BasisOptions::default()).unwrap();
                    assert_eq!(b.g, tvd.g, "{name}");
                    assert!(b.g > 0);
                    assert_eq!(b.w, tvd.w);
                }
            }
            // Nothing dropped by the M-orthonormalization: the competitor vectors are independent.
            assert_eq!(b.dropped, 0, "{name} {}", kind.name());
        }
    }
}

/// The Guyan condensation computed independently: `T = [I; −K_oo⁻¹ K_oJ]` by a factorization of
/// `K_oo` (not `K_ii`), `K* = Tᵀ K_ii T`, `M* = Tᵀ M_ii T`. Every JIM restricted to the joint DOF,
/// `v = φ_J`, must satisfy `K* v = λ M* v`, and `φ = T v` on the other DOF.
fn check_condensed_eigenproblem(model: &Model, set: JimSet, count: usize) -> Vec<f64> {
    let n = model.dofs();
    let m = n - 6;
    let jd = jim_dofs(model, set).unwrap();
    let mut is_j = vec![false; m];
    jd.iter().for_each(|&d| is_j[d] = true);
    let others: Vec<usize> = (0..m).filter(|&d| !is_j[d]).collect();
    let kii = model.stiffness.leading(m);
    let mii = model.mass.leading(m);
    let koo = SparseCholesky::new(&submatrix(&kii, &others)).unwrap();
    let p = jd.len();
    // −K_oJ columns.
    let mut rhs = Mat::<f64>::zeros(others.len(), p);
    for (c, &j) in jd.iter().enumerate() {
        for (r, &o) in others.iter().enumerate() {
            rhs[(r, c)] = -kii.get(o, j);
        }
    }
    koo.solve_in_place(&mut rhs);
    let mut t = Mat::<f64>::zeros(m, p);
    for c in 0..p {
        t[(jd[c], c)] = 1.0;
        for (r, &o) in others.iter().enumerate() {
            t[(o, c)] = rhs[(r, c)];
        }
    }
    let ks = gram(&kii, t.as_ref());
    let ms = gram(&mii, t.as_ref());
    let ks_norm = (0..p)
        .map(|i| (0..p).map(|j| ks[(i, j)].abs()).sum::<f64>())
        .fold(0.0, f64::max);
    let jim = joint_interface_modes(model, count, set).unwrap();
    assert_eq!(jim.vectors.ncols(), count);
    let mut worst = 0.0f64;
    for c in 0..count {
        let lam = jim.eigenvalues[c];
        let phi = col(jim.vectors.as_ref(), c);
        assert!(phi[m..].iter().all(|&v| v == 0.0), "master DOF not fixed");
        let v: Vec<f64> = jd.iter().map(|&d| phi[d]).collect();
        let vn = v.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        let mut res = 0.0f64;
        for i in 0..p {
            let r: f64 = (0..p).map(|j| (ks[(i, j)] - lam * ms[(i, j)]) * v[j]).sum();
            res = res.max(r.abs());
        }
        let rel = res / (ks_norm * vn);
        worst = worst.max(rel);
        // Measured ≤ 1e-11 with point welds, up to 1e-7 with area welds (the in-plane set's
        // condensed problem is worse conditioned): still 9 orders below the eigenvalues.
        assert!(rel < 1e-6, "{set:?} JIM {c}: eigen residual {rel:e}");
        // Expansion by the condensation: φ = T v on all interior DOF.
        let tv: Vec<f64> = (0..m)
            .map(|r| (0..p).map(|j| t[(r, j)] * v[j]).sum())
            .collect();
        let d: Vec<f64> = (0..m).map(|r| tv[r] - phi[r]).collect();
        let e = norm(&d) / norm(&phi[..m]);
        assert!(e < 1e-8, "{set:?} JIM {c}: φ ≠ T φ_J, relative {e:e}");
        // M-normalized, K-Rayleigh quotient λ.
        let mphi = mul(&model.mass, &phi);
        let kphi = mul(&model.stiffness, &phi);
        let pm: f64 = phi.iter().zip(&mphi).map(|(a, b)| a * b).sum();
        let pk: f64 = phi.iter().zip(&kphi).map(|(a, b)| a * b).sum();
        assert!((pm - 1.0).abs() < 1e-10, "φᵀMφ = {pm}");
        assert!((pk - lam).abs() < 1e-8 * lam, "φᵀKφ = {pk}, λ = {lam}");
    }
    assert!(
        jim.eigenvalues.windows(2).all(|w| w[0] <= w[1]),
        "not ascending"
    );
    eprintln!(
        "{} {set:?}: |J| = {p}, worst eigen residual {worst:.2e}, f_1 = {:.1} Hz, f_{count} = {:.1} Hz",
        model.name,
        jim.eigenvalues[0].sqrt() / (2.0 * std::f64::consts::PI),
        jim.eigenvalues[count - 1].sqrt() / (2.0 * std::f64::consts::PI)
    );
    jim.eigenvalues
}

#[test]
fn jim_vectors_satisfy_the_condensed_eigenproblem() {
    for name in Case::BUILTIN {
        let model = common::model(name);
        let count = 30;
        let ln = check_condensed_eigenproblem(&model, JimSet::Normal, count);
        let lt = check_condensed_eigenproblem(&model, JimSet::InPlane, count);
        // Both = the two sets merged by eigenvalue.
        let both = joint_interface_modes(&model, count, JimSet::Both).unwrap();
        let mut merged: Vec<(f64, JimSet)> = ln
            .iter()
            .map(|&l| (l, JimSet::Normal))
            .chain(lt.iter().map(|&l| (l, JimSet::InPlane)))
            .collect();
        merged.sort_by(|a, b| a.0.total_cmp(&b.0));
        for c in 0..count {
            assert!((both.eigenvalues[c] - merged[c].0).abs() <= 1e-10 * merged[c].0);
            assert_eq!(both.sets[c], merged[c].1, "{name}: Both column {c}");
        }
        let normals = both.sets.iter().filter(|&&s| s == JimSet::Normal).count();
        eprintln!(
            "{name}: Both, first {count}: {normals} normal, {} in-plane",
            count - normals
        );
        assert!(
            normals > 0 && normals < count,
            "{name}: Both does not mix the sets"
        );
    }
}

#[test]
fn jim_bad_count_is_an_error() {
    let model = common::model("friction_bar");
    let nn = jim_dofs(&model, JimSet::Normal).unwrap().len();
    let err = joint_interface_modes(&model, nn + 1, JimSet::Normal).unwrap_err();
    assert!(
        matches!(
            err,
            Error::Reduction(ReductionError::JimCount { set: "normal", count, available })
                if count == nn + 1 && available == nn
        ) && err.to_string().contains("normal"),
        "{err}"
    );
    let err = joint_interface_modes(&model, 3 * nn + 1, JimSet::Both).unwrap_err();
    assert!(
        matches!(
            err,
            Error::Reduction(ReductionError::JimCount { set: "both", count, .. })
                if count == 3 * nn + 1
        ) && err.to_string().contains("both"),
        "{err}"
    );
    let opts = BasisOptions {
        g: Some(nn + 1),
        jim_set: JimSet::Normal,
        ..Default::default()
    };
    assert!(build_basis(&model, BasisKind::Jim, &opts).is_err());
    assert_eq!(
        joint_interface_modes(&model, 0, JimSet::Both)
            .unwrap()
            .vectors
            .ncols(),
        0
    );
}

#[test]
fn alldof_reproduces_the_full_contact_statics() {
    for name in Case::BUILTIN {
        let model = common::model(name);
        let n = model.dofs();
        let psi = alldof_vectors(&model).unwrap();
        assert_eq!(psi.ncols(), model.joint.pairs());
        // The span [Φ_S Φ_V ψ] as built (no orthonormalization) ...
        let cb = jointrom::reduction::craig_bampton(&model, 10).unwrap();
        let union = Mat::from_fn(n, 16 + psi.ncols(), |r, c| {
            if c < 16 {
                cb[(r, c)]
            } else {
                psi[(r, c - 16)]
            }
        });
        // ... the M-orthonormal, K-diagonal basis of build_basis ...
        let b = build_basis(&model, BasisKind::AllDof, &BasisOptions::default()).unwrap();
        // ... and the Gram–Schmidt basis without the modal rotation: the same span, but its
        // ill-conditioned K̃ costs accuracy in the multilayer's 1e-6-small gaps (measured 1.4e-7).
        let gs_opts = BasisOptions {
            modal: false,
            ..Default::default()
        };
        let gs = build_basis(&model, BasisKind::AllDof, &gs_opts).unwrap();
        for s in [1.0, -1.0] {
            let load = scaled(model.master_load(), s);
            let full = contact_static_full(&model, load, &ContactOptions::default()).unwrap();
            let fc = full.state.contact_force_norm;
            for (what, phi, tol_f) in [
                ("union", union.clone(), 1e-8),
                ("final", b.phi.clone(), 1e-8),
                ("gram-schmidt", gs.phi.clone(), 1e-6),
            ] {
                let (red, um) = reduced_contact(&model, phi, load);
                let ef = (red.contact_force_norm - fc).abs() / fc;
                let eu = rel_master(&um, &full.master_displacement);
                eprintln!(
                    "{name} scale {s:+} {what}: ‖f_c‖ full {fc:.9e} N, alldof {:.9e} N (rel {ef:.1e}), \
                     master rel {eu:.1e}, {} pairs in contact",
                    red.contact_force_norm, full.state.pairs_in_contact
                );
                assert_eq!(red.active, full.state.active, "{name} {s} {what}");
                assert!(
                    ef <= tol_f,
                    "{name} scale {s} {what}: ‖f_c‖ relative error {ef:e}"
                );
                assert!(
                    eu <= 1e-8,
                    "{name} scale {s} {what}: master displacement error {eu:e}"
                );
            }
        }
    }
}

#[test]
fn tvd_contact_force_converges_as_g_grows() {
    for name in Case::BUILTIN {
        let model = common::model(name);
        let load = model.master_load();
        let full = contact_static_full(&model, load, &ContactOptions::default()).unwrap();
        let fc = full.state.contact_force_norm;
        let mut errs = Vec::new();
        let gmax = model.joint.pairs();
        for g in [0, 5, 10, 20, 25, 40, gmax] {
            let mut row = format!("{name} g = {g:3}:");
            for kind in [
                BasisKind::Tvd,
                BasisKind::TvdPlain,
                BasisKind::Modes,
                BasisKind::Jim,
            ] {
                let opts = BasisOptions {
                    g: Some(g),
                    ..Default::default()
                };
                let b = match build_basis(&model, kind, &opts) {
                    Ok(b) => b,
                    Err(e) => {
                        // e.g. Modes: the eigensolver's accuracy check fails beyond ~50 modes.
                        assert!(kind != BasisKind::Tvd, "{name}: Tvd at g = {g}: {e}");
                        row += &format!(" {} (no basis: {e})", kind.name());
                        continue;
                    }
                };
                // Coarse reduced models can make the active-set Newton cycle (an error of the
                // contact solver, not of the basis): reported, asserted only for Tvd.
                match try_reduced_contact(&model, b.phi, load) {
                    Ok((red, _)) => {
                        let e = (red.contact_force_norm - fc).abs() / fc;
                        row += &format!(
                            " {}[{}] {:.5e} N ({e:.1e})",
                            kind.name(),
                            b.g,
                            red.contact_force_norm
                        );
                        if kind == BasisKind::Tvd {
                            errs.push((g, e));
                        }
                    }
                    Err(e) => {
                        assert!(e.to_string().contains("cycles"), "{e}");
                        row += &format!(" {} (cycled)", kind.name());
                        assert!(
                            kind != BasisKind::Tvd || g < 20,
                            "{name}: Tvd at g = {g} cycled"
                        );
                    }
                }
            }
            eprintln!("{row}");
        }
        eprintln!("{name}: full ‖f_c‖ = {fc:.6e} N");
        assert_eq!(errs[0].0, 0, "{name}: Craig–Bampton alone failed");
        let e0 = errs[0].1;
        let elast = errs.last().unwrap().1;
        assert!(
            e0 > 1e-2,
            "{name}: Craig–Bampton alone is already accurate ({e0:e})?"
        );
        eprintln!("{name}: TVD errors {errs:?}");
        // Measured (ν = 10, defaults): friction bar 33 at g = 0 → 2.0e-2 at g = 54 (48 POMs kept);
        // multilayer 34 → 1.6e-6 at g = 92. The friction bar's TVD space does not contain the
        // exact solution: two pairs are never active under any ±φ_j, and directions of pairs
        // with tiny gaps in every trial vector fall below the POD's 1e-12 λ_max cut (the pair
        // constraint modes of active pairs 16 and 37 lie 3e-3 outside the full TVD basis).
        let (bound, factor) = if *name == "friction_bar" {
            (5e-2, 2e-3)
        } else {
            (1e-5, 1e-6)
        };
        assert!(
            elast <= bound,
            "{name}: TVD at the largest g: error {elast:e} > {bound:e}"
        );
        assert!(
            elast <= factor * e0,
            "{name}: {elast:e} vs {e0:e} at g = 0: not {factor:e} smaller"
        );
        // The largest g is the best of the TVD bases measured (by a margin over g = 20).
        let e20 = errs.iter().find(|e| e.0 == 20).unwrap().1;
        assert!(
            elast < 0.2 * e20,
            "{name}: {elast:e} at g_max vs {e20:e} at g = 20"
        );
    }
}

#[test]
fn snapshot_pod_recovers_a_synthetic_span() {
    // The shapes and thresholds below were measured on the point-weld friction bar.
    let model = common::point_weld_model("friction_bar");
    let n = model.dofs();
    // Three known shapes outside the Craig–Bampton span: pair constraint modes.
    let psi = alldof_vectors(&model).unwrap();
    let known = Mat::from_fn(n, 3, |r, c| psi[(r, [3, 20, 41][c])] * 1e3);
    let z = 200;
    let mut rng = common::rng(0x2545_f491_4f6c_dd1d);
    let mut rnd = move || 0.5 * common::uniform(&mut rng); // in [-0.5, 0.5)
    let scale = (0..3)
        .map(|c| norm(&col(known.as_ref(), c)))
        .fold(0.0f64, f64::max);
    let noise = 1e-10 * scale;
    let y = Mat::from_fn(n, z, |r, t| {
        let tt = t as f64 * 0.01;
        let a = [
            (2.0 * std::f64::consts::PI * 3.0 * tt).sin(),
            0.5 * (2.0 * std::f64::consts::PI * 7.0 * tt).cos(),
            0.2 * tt,
        ];
        (0..3).map(|c| a[c] * known[(r, c)]).sum::<f64>() + noise * rnd()
    });
    for weight in [None, Some(&model.mass)] {
        let p = snapshot_pod(y.as_ref(), weight).unwrap();
        let w3 = p.w[2];
        eprintln!(
            "snapshot POD (weighted {}): λ_1..4 = {:.3e} {:.3e} {:.3e} {:.3e}, w(3) = 1 − {:.1e}",
            weight.is_some(),
            p.lambda[0],
            p.lambda[1],
            p.lambda[2],
            p.lambda.get(3).copied().unwrap_or(0.0),
            1.0 - w3
        );
        assert!(1.0 - w3 < 1e-12, "w(3) = {w3}");
        assert!(
            p.w[1] < 0.9999,
            "w(2) = {} — the third shape is not negligible",
            p.w[1]
        );
        // Largest principal angle between span(U_3) and span(known): σ_min of Q_uᵀ Q_k.
        let qu = p.leading(3).qr().compute_thin_Q();
        let qk = known.qr().compute_thin_Q();
        let c = qu.transpose() * &qk;
        let s = c.svd().unwrap();
        let smin = s.S().column_vector().iter().fold(1.0f64, |a, &v| a.min(v));
        let angle = smin.min(1.0).acos();
        eprintln!("  largest subspace angle {angle:.2e} rad");
        assert!(angle < 1e-6, "subspace angle {angle:e}");
    }
    // The builder: CB + 3 POMs contains the known shapes (M-projection residual).
    let opts = BasisOptions {
        g: Some(3),
        ..Default::default()
    };
    let b = snapshot_basis(&model, y.as_ref(), None, &opts).unwrap();
    assert_eq!((b.g, b.phi.ncols(), b.dropped), (3, 19, 0));
    let dev = dev_from_identity(&gram(&model.mass, b.phi.as_ref()));
    assert!(dev <= 1e-10, "‖ΦᵀMΦ − I‖ = {dev:e}");
    for c in 0..3 {
        let x = col(known.as_ref(), c);
        let mx = mul(&model.mass, &x);
        let coef: Vec<f64> = (0..b.phi.ncols())
            .map(|j| (0..n).map(|r| b.phi[(r, j)] * mx[r]).sum())
            .collect();
        let res: Vec<f64> = (0..n)
            .map(|r| {
                x[r] - (0..coef.len())
                    .map(|j| b.phi[(r, j)] * coef[j])
                    .sum::<f64>()
            })
            .collect();
        let e = norm(&res) / norm(&x);
        assert!(
            e < 1e-6,
            "known shape {c} outside the snapshot basis: {e:e}"
        );
    }
    // g chosen by the threshold: 3 (w(3) ≈ 1, w(2) < threshold).
    let auto = snapshot_basis(&model, y.as_ref(), None, &BasisOptions::default()).unwrap();
    assert_eq!(auto.g, 3);
    // Bad input.
    assert!(snapshot_basis(&model, y.as_ref().subrows(0, n - 1), None, &opts).is_err());
    let mut bad = y.clone();
    bad[(5, 7)] = f64::NAN;
    let err = snapshot_pod(bad.as_ref(), None).unwrap_err();
    assert!(err.to_string().contains("snapshot 7, DOF 5"), "{err}");
    assert!(snapshot_pod(Mat::<f64>::zeros(n, 0).as_ref(), None).is_err());
}

#[test]
fn basis_kind_names() {
    for k in BasisKind::ALL {
        assert_eq!(BasisKind::from_name(k.name()).unwrap(), k);
    }
    let names: Vec<&str> = BasisKind::ALL.iter().map(|k| k.name()).collect();
    assert_eq!(
        names,
        ["tvd", "tvd-plain", "tvd-secant", "modes", "jim", "alldof"]
    );
    let err = BasisKind::from_name("pod").unwrap_err();
    assert!(
        matches!(&err, ReductionError::UnknownBasis { name, .. } if name == "pod"),
        "{err:?}"
    );
    let msg = Error::from(err).to_string();
    assert!(msg.starts_with("invalid request: unknown basis"), "{msg}");
    for n in names {
        assert!(msg.contains(n), "{msg}");
    }
    assert!(msg.contains("`pod`"), "{msg}");
}
