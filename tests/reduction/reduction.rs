//! Basis construction of Witteveen & Pichler (2014), Algorithm 2: Craig–Bampton, trial vector
//! derivatives, POD and the final M-orthonormal basis, on the two built-in cases.

// Index loops mirror the matrix formulas, as in the library.
#![allow(clippy::needless_range_loop)]

use std::time::Instant;

use faer::{Mat, MatRef};
use jointrom::case::Case;
use jointrom::joint::statics::ContactOptions;
use jointrom::joint::NORMAL;
use jointrom::linalg::cholesky::SparseCholesky;
use jointrom::linalg::SymCsc;
use jointrom::model::contact_static_full;
use jointrom::model::Interface;
use jointrom::reduction::{
    active_pairs, build_basis, craig_bampton, craig_bampton_with, displacement_scales, final_basis,
    pod, pod_tvd, trial_vector_derivatives, BasisKind, BasisOptions, FixedInterface, TvdOptions,
    DEFAULT_THRESHOLD,
};
use jointrom::system::ReducedSystem;

use crate::common::{self, col, dot, inf_norm, mul};

/// `Xᵀ A Y` for sparse symmetric A.
fn gram(a: &SymCsc, x: MatRef<'_, f64>, y: MatRef<'_, f64>) -> Mat<f64> {
    let ay: Vec<Vec<f64>> = (0..y.ncols()).map(|c| mul(a, &col(y, c))).collect();
    Mat::from_fn(x.ncols(), y.ncols(), |i, j| dot(&col(x, i), &ay[j]))
}

fn max_dev_from_identity(g: &Mat<f64>) -> f64 {
    let mut d = 0.0f64;
    for i in 0..g.nrows() {
        for j in 0..g.ncols() {
            let e = if i == j { 1.0 } else { 0.0 };
            d = d.max((g[(i, j)] - e).abs());
        }
    }
    d
}

/// One fixed-interface factorization serves Craig–Bampton (as ν grows) and the estimate's
/// truncated modes: the shared path gives the bits of each use factoring on its own.
#[test]
fn shared_fixed_interface_gives_the_same_bits() {
    let model = common::model("friction_bar");
    let fixed = FixedInterface::new(&model).unwrap();
    for nu in [10, 20] {
        let own = craig_bampton(&model, nu).unwrap();
        let shared = craig_bampton_with(&model, nu, &fixed).unwrap();
        assert!(own == shared, "Craig–Bampton ν = {nu}");
    }
    let own = model.modes(40, Interface::Fixed).unwrap();
    let shared = fixed.modes(40).unwrap();
    assert!(own.shapes == shared.shapes, "fixed-interface mode shapes");
    assert_eq!(own.eigenvalues, shared.eigenvalues);
}

#[test]
fn craig_bampton_constraint_modes_and_k_orthogonality() {
    for name in Case::BUILTIN {
        let model = common::model(name);
        let n = model.dofs();
        let master = model.master_dofs();
        let nu = 10;
        let phi = craig_bampton(&model, nu).unwrap();
        assert_eq!((phi.nrows(), phi.ncols()), (n, 6 + nu));
        // Unit master displacement of each constraint mode; Φ_V zero on the master.
        for c in 0..6 + nu {
            for (d, &dof) in master.iter().enumerate() {
                let expect = if c < 6 && c == d { 1.0 } else { 0.0 };
                assert_eq!(phi[(dof, c)], expect, "{name}: column {c}, master DOF {d}");
            }
        }
        // K Φ_S vanishes on the interior (backward error of the interior solve).
        let knorm = model.stiffness.inf_norm();
        for c in 0..6 {
            let x = col(phi.as_ref(), c);
            let kx = mul(&model.stiffness, &x);
            let interior = inf_norm(&kx[..n - 6]);
            let be = interior / (knorm * inf_norm(&x));
            assert!(
                be < 1e-12,
                "{name}: constraint mode {c}: interior residual {be:e}"
            );
        }
        // Φ_Sᵀ K Φ_V = 0, relative to the energies.
        let g = gram(&model.stiffness, phi.as_ref(), phi.as_ref());
        for s in 0..6 {
            for v in 6..6 + nu {
                let rel = g[(s, v)].abs() / (g[(s, s)] * g[(v, v)]).sqrt();
                // Exact in theory (K Φ_S is zero on the interior, Φ_V on the master); in floating
                // point limited by K's conditioning (stiff short welds), so 1e-8, while the
                // interior residual above is held to a backward error of 1e-12.
                assert!(rel < 1e-8, "{name}: Φ_S[{s}]ᵀKΦ_V[{v}] relative {rel:e}");
            }
        }
        // The M-orthonormal basis of CB alone needs no dropped direction.
        let (q, dropped) = final_basis(&[phi.as_ref()], &model.mass, 1e-8).unwrap();
        assert_eq!(dropped, 0, "{name}");
        assert_eq!(q.ncols(), 6 + nu);
        let dev = max_dev_from_identity(&gram(&model.mass, q.as_ref(), q.as_ref()));
        assert!(dev < 1e-10, "{name}: ΦᵀMΦ − I = {dev:e}");
    }
}

#[test]
fn active_pairs_zero_rule() {
    let opts = TvdOptions::default();
    let off = TvdOptions {
        zero_gap_active: false,
        ..opts
    };
    // All gaps exactly zero: all active for both signs, or none.
    let z = [0.0; 4];
    assert_eq!(active_pairs(&z, 1.0, 1.0, &opts), vec![true; 4]);
    assert_eq!(active_pairs(&z, 1.0, -1.0, &opts), vec![true; 4]);
    assert_eq!(active_pairs(&z, 1.0, 1.0, &off), vec![false; 4]);
    // Gaps at round-off of the vector's displacement scale count as zero.
    let g = [1.0, -2.0, 1e-12, -1e-12];
    assert_eq!(
        active_pairs(&g, 3.0, 1.0, &opts),
        vec![false, true, true, true]
    );
    assert_eq!(
        active_pairs(&g, 3.0, -1.0, &opts),
        vec![true, false, true, true]
    );
    assert_eq!(
        active_pairs(&g, 3.0, 1.0, &off),
        vec![false, true, false, false]
    );
    // A vector that opens no gap (all gaps round-off, e.g. an in-plane constraint mode) has
    // every gap zero, whatever the signs of its round-off: the rule, not the noise, decides.
    let r = [3e-14, -5e-14, 1e-15, -2e-13];
    assert_eq!(active_pairs(&r, 1.0, 1.0, &opts), vec![true; 4]);
    assert_eq!(active_pairs(&r, 1.0, -1.0, &opts), vec![true; 4]);
    assert_eq!(active_pairs(&r, 1.0, 1.0, &off), vec![false; 4]);
    assert_eq!(active_pairs(&r, 1.0, -1.0, &off), vec![false; 4]);
    // The reference is the displacement scale, not an absolute one: tiny vectors with tiny
    // displacements are judged like any other.
    let t = [1e-12, -1e-12];
    assert_eq!(active_pairs(&t, 1e-12, 1.0, &off), vec![false, true]);
}

#[test]
fn tvd_count_residual_sign_flip_and_normalization() {
    let model = common::model("friction_bar");
    let n = model.dofs();
    let w = model.joint.pairs();
    let kn = model.contact.normal_stiffness;
    let base = craig_bampton(&model, 10).unwrap();
    let opts = TvdOptions::default();
    let tvd = trial_vector_derivatives(&model, base.as_ref(), &opts).unwrap();
    assert_eq!(tvd.total, 2 * 16 * 16);
    assert_eq!(tvd.total, 512);
    assert_eq!(
        tvd.nonzero() + tvd.zero_columns + tvd.negligible_columns,
        tvd.total
    );
    assert_eq!(tvd.index.len(), tvd.nonzero());
    // Active sets, recomputed here from the gaps and the largest translation of φ_j: they flip
    // with k where the gap is nonzero.
    let translations = model.translation_dofs();
    let mut flipped = 0;
    for j in 0..base.ncols() {
        let phi = col(base.as_ref(), j);
        let mut g = vec![0.0; w];
        model.joint.gaps(&phi, &mut g);
        let scale = translations
            .iter()
            .fold(0.0f64, |m, &d| m.max(phi[d].abs()));
        for z in 0..w {
            let zero = g[z].abs() <= opts.tol * scale;
            let neg = tvd.active[j][0][z];
            let pos = tvd.active[j][1][z];
            if zero {
                assert!(
                    neg && pos,
                    "j {j} pair {z}: zero gap must be active for both signs"
                );
            } else {
                assert_eq!(pos, g[z] < 0.0, "j {j} pair {z}, k = +1");
                assert_eq!(neg, !pos, "j {j} pair {z}: active set must flip with k");
                flipped += 1;
            }
        }
    }
    assert!(flipped > 0);
    // Residual: K (s φ_{i,k,j}) = Bₙᵀ(kₙ Bₙ φ_i) on the active pairs, built from B's rows here.
    let knorm = model.stiffness.inf_norm();
    let mut worst = 0.0f64;
    for (c, idx) in tvd.index.iter().enumerate() {
        let phi_i = col(base.as_ref(), idx.i);
        let act = &tvd.active[idx.j][if idx.k < 0 { 0 } else { 1 }];
        let mut f = vec![0.0; n];
        for z in (0..w).filter(|&z| act[z]) {
            let r = 3 * z + NORMAL;
            let bn: f64 = model.joint.row(r).map(|(d, v)| v * phi_i[d]).sum();
            for (d, v) in model.joint.row(r) {
                f[d] += kn * bn * v;
            }
        }
        let x: Vec<f64> = col(tvd.vectors.as_ref(), c)
            .iter()
            .map(|v| v * tvd.k_norms[c])
            .collect();
        let kx = mul(&model.stiffness, &x);
        let res: Vec<f64> = kx.iter().zip(&f).map(|(a, b)| a - b).collect();
        let be = inf_norm(&res) / (knorm * inf_norm(&x) + inf_norm(&f));
        worst = worst.max(be);
        // K-normalization.
        let xn = col(tvd.vectors.as_ref(), c);
        let e = dot(&xn, &mul(&model.stiffness, &xn));
        // φᵀKφ sums large cancelling terms (ill-conditioned K): 1e-8, not 1e-14.
        assert!((e - 1.0).abs() < 1e-8, "column {c}: φᵀKφ = {e}");
    }
    assert!(worst < 1e-12, "worst TVD backward error {worst:e}");
    println!(
        "friction_bar TVD: total {}, nonzero {}, zero {}, negligible {}, worst backward error {worst:.2e}",
        tvd.total,
        tvd.nonzero(),
        tvd.zero_columns,
        tvd.negligible_columns
    );
}

#[test]
fn tvd_zero_gap_rule_counts() {
    for name in Case::BUILTIN {
        let model = common::model(name);
        let base = craig_bampton(&model, 10).unwrap();
        let mut nonzero = [0usize; 2];
        for (a, zero_gap_active) in [true, false].into_iter().enumerate() {
            let opts = TvdOptions {
                zero_gap_active,
                ..TvdOptions::default()
            };
            let tvd = trial_vector_derivatives(&model, base.as_ref(), &opts).unwrap();
            // Gaps relative to the base vector's largest translation s_j (the rule's scale).
            let scales = displacement_scales(&model, base.as_ref());
            let bphi = model.joint.reduce(base.as_ref());
            let rel_gaps: Vec<Vec<f64>> = (0..base.ncols())
                .map(|j| {
                    (0..model.joint.pairs())
                        .map(|z| bphi[(3 * z + NORMAL, j)].abs() / scales[j])
                        .collect()
                })
                .collect();
            let all_zero: Vec<usize> = (0..base.ncols())
                .filter(|&j| rel_gaps[j].iter().all(|&r| r <= opts.tol))
                .collect();
            if zero_gap_active {
                let ratios: Vec<String> = rel_gaps
                    .iter()
                    .map(|g| format!("{:.1e}", g.iter().fold(0.0f64, |m, &r| m.max(r))))
                    .collect();
                println!(
                    "{name}: max|gap| / s_j per base vector: [{}]",
                    ratios.join(", ")
                );
                let zero: Vec<f64> = rel_gaps
                    .iter()
                    .flatten()
                    .copied()
                    .filter(|&r| r <= opts.tol)
                    .collect();
                let smallest_physical = rel_gaps
                    .iter()
                    .flatten()
                    .copied()
                    .filter(|&r| r > opts.tol)
                    .fold(f64::INFINITY, f64::min);
                println!(
                    "{name}: gaps counted as zero (|g| ≤ {:e} s_j): {} of {}, the largest {:.2e} s_j; smallest other gap {smallest_physical:.2e} s_j",
                    opts.tol,
                    zero.len(),
                    base.ncols() * model.joint.pairs(),
                    zero.iter().fold(0.0f64, |m, &r| m.max(r))
                );
                // The rule's threshold sits in an empty band, more than a decade from either
                // side (measured: 1.5e-11 … 1.6e-5 friction bar, 1.7e-11 … 1.1e-7 multilayer).
                assert!(zero.iter().all(|&r| r < 0.1 * opts.tol), "{name}");
                assert!(smallest_physical > 10.0 * opts.tol, "{name}");
            }
            println!(
                "{name}: zero_gap_active = {zero_gap_active}: total {}, nonzero {}, zero {}, negligible {}; base vectors with all gaps zero: {all_zero:?}",
                tvd.total,
                tvd.nonzero(),
                tvd.zero_columns,
                tvd.negligible_columns
            );
            assert_eq!(tvd.total, 512);
            nonzero[a] = tvd.nonzero();
            for weighted in [true, false] {
                let p = pod(tvd.vectors.as_ref(), weighted.then_some(&model.stiffness)).unwrap();
                println!(
                    "{name}: zero_gap_active = {zero_gap_active}, {}: rank {}, g(w ≥ {DEFAULT_THRESHOLD}) = {}",
                    if weighted { "K-weighted" } else { "plain" },
                    p.lambda.len(),
                    p.choose_g(DEFAULT_THRESHOLD)
                );
            }
        }
        // Treating zero gaps as inactive can only remove pairs, so never adds columns.
        assert!(nonzero[1] <= nonzero[0], "{name}: {nonzero:?}");
    }
}

#[test]
fn pod_optimality_and_orthonormality() {
    let model = common::model("friction_bar");
    let base = craig_bampton(&model, 10).unwrap();
    let tvd = trial_vector_derivatives(&model, base.as_ref(), &TvdOptions::default()).unwrap();
    let y = tvd.vectors.as_ref();
    let p = y.ncols();
    let k = &model.stiffness;

    let wp = pod(y, Some(k)).unwrap();
    // Trace of YᵀKY = p for K-normalized columns.
    let sum: f64 = wp.lambda.iter().sum();
    assert!(
        (sum - p as f64).abs() < 1e-8 * p as f64,
        "Σλ = {sum}, p = {p}"
    );
    // Rank bound without k_t: one direction per pair at most.
    assert!(
        wp.lambda.len() <= model.joint.pairs(),
        "rank {}",
        wp.lambda.len()
    );
    // w(p) = 1, nondecreasing, in [0, 1]; λ descending.
    assert_eq!(wp.w.len(), p);
    assert_eq!(*wp.w.last().unwrap(), 1.0);
    assert!(wp.w.windows(2).all(|a| a[1] >= a[0]));
    assert!(wp.w.iter().all(|&v| (0.0..=1.0).contains(&v)));
    assert!(wp.lambda.windows(2).all(|a| a[1] <= a[0]));
    assert_eq!(wp.dropped + wp.lambda.len(), p);
    // POMs are K-orthonormal.
    // POMs are K-orthonormal. u_i = Y û_i / sqrt(λ_i) amplifies the eigenvector and K-product
    // round-off by λ_max / λ_i, so entry (i, j) is held to 1e-8 · λ_max / sqrt(λ_i λ_j).
    let u = wp.poms.as_ref();
    let uku = gram(k, u, u);
    let lmax = wp.lambda[0];
    let mut worst = 0.0f64;
    for i in 0..u.ncols() {
        for j in 0..u.ncols() {
            let e = if i == j { 1.0 } else { 0.0 };
            let scaled = (uku[(i, j)] - e).abs() * (wp.lambda[i] * wp.lambda[j]).sqrt() / lmax;
            worst = worst.max(scaled);
        }
    }
    assert!(worst < 1e-8, "UᵀKU − I scaled by λ: {worst:e}");
    let lead = 25.min(u.ncols());
    let dev = max_dev_from_identity(&gram(k, u.subcols(0, lead), u.subcols(0, lead)));
    println!("K-weighted POD: first {lead} POMs: UᵀKU − I = {dev:.2e}; scaled worst {worst:.2e}");
    assert!(dev < 1e-8, "first {lead} POMs: UᵀKU − I = {dev:e}");
    // Captured energy of the first g POMs: Σ_j ‖P y_j‖²_K = ‖Uᵀ K Y‖²_F = λ_1 + … + λ_g.
    let uky = gram(k, u, y);
    for g in [1, 5, 25, wp.lambda.len()] {
        let g = g.min(wp.lambda.len());
        let captured: f64 = (0..g)
            .map(|i| (0..p).map(|j| uky[(i, j)].powi(2)).sum::<f64>())
            .sum();
        let lam: f64 = wp.lambda[..g].iter().sum();
        assert!(
            (captured - lam).abs() <= 1e-8 * lam,
            "g = {g}: captured {captured}, Σλ {lam}"
        );
        assert!((wp.w[g - 1] - lam / sum).abs() < 1e-12);
    }

    // Plain POD: Euclidean-orthonormal POMs, same properties of w.
    let pp = pod(y, None).unwrap();
    let u = pp.poms.as_ref();
    let utu = u.transpose() * u;
    let lmax = pp.lambda[0];
    let mut worst = 0.0f64;
    for i in 0..u.ncols() {
        for j in 0..u.ncols() {
            let e = if i == j { 1.0 } else { 0.0 };
            let scaled = (utu[(i, j)] - e).abs() * (pp.lambda[i] * pp.lambda[j]).sqrt() / lmax;
            worst = worst.max(scaled);
        }
    }
    assert!(worst < 1e-8, "UᵀU − I scaled by λ: {worst:e}");
    assert_eq!(*pp.w.last().unwrap(), 1.0);
    assert!(pp.w.windows(2).all(|a| a[1] >= a[0]));
    let uy = u.transpose() * y;
    let g = 10.min(pp.lambda.len());
    let captured: f64 = (0..g)
        .map(|i| (0..p).map(|j| uy[(i, j)].powi(2)).sum::<f64>())
        .sum();
    let lam: f64 = pp.lambda[..g].iter().sum();
    assert!((captured - lam).abs() <= 1e-8 * lam);
}

#[test]
fn energy_ratio_and_chosen_g_report() {
    for name in Case::BUILTIN {
        let model = common::model(name);
        let base = craig_bampton(&model, 10).unwrap();
        let tvd = trial_vector_derivatives(&model, base.as_ref(), &TvdOptions::default()).unwrap();
        for weighted in [true, false] {
            let weight = weighted.then_some(&model.stiffness);
            let p = pod(tvd.vectors.as_ref(), weight).unwrap();
            let g = p.choose_g(DEFAULT_THRESHOLD);
            let first: Vec<String> = p.w.iter().take(30).map(|v| format!("{v:.5}")).collect();
            println!(
                "{name} {}: rank {}, dropped λ {}, g(w ≥ {DEFAULT_THRESHOLD}) = {g}, g(0.95) = {}, g(0.9999) = {}\n  w(1..30) = [{}]",
                if weighted { "K-weighted" } else { "plain" },
                p.lambda.len(),
                p.dropped,
                p.choose_g(0.95),
                p.choose_g(0.9999),
                first.join(", ")
            );
            assert!(g >= 1 && g <= p.lambda.len());
            assert!(p.w[g - 1] >= DEFAULT_THRESHOLD);
            assert!(g == 1 || p.w[g - 2] < DEFAULT_THRESHOLD);
        }
    }
}

#[test]
fn build_basis_and_reduced_model() {
    let model = common::model("friction_bar");
    let t0 = Instant::now();
    let basis = build_basis(&model, BasisKind::Tvd, &BasisOptions::default()).unwrap();
    let elapsed = t0.elapsed();
    println!(
        "friction_bar Tvd basis: r = {} (16 + g = {}), dropped {}, TVD {}/{} nonzero, built in {:.1} ms",
        basis.phi.ncols(),
        basis.g,
        basis.dropped,
        basis.tvd_nonzero,
        basis.tvd_total,
        elapsed.as_secs_f64() * 1e3
    );
    assert_eq!(basis.phi.ncols() + basis.dropped, 16 + basis.g);
    let rm = ReducedSystem::new(&model, basis.phi.clone()).unwrap();
    let r = rm.dim();
    let dev = max_dev_from_identity(rm.m());
    assert!(dev < 1e-10, "M̃ − I = {dev:e}");
    for i in 0..r {
        assert!(rm.k()[(i, i)] > 0.0);
        for j in 0..r {
            assert_eq!(rm.k()[(i, j)], rm.k()[(j, i)]);
        }
    }
    assert_eq!(
        (rm.b_phi().nrows(), rm.b_phi().ncols()),
        (model.joint.rows(), r)
    );
    let f = model.load.master.to_array();
    let mut full = vec![0.0; model.dofs()];
    for (d, &dof) in model.master_dofs().iter().enumerate() {
        full[dof] = f[d];
    }
    let load = rm.reduced_load();
    for c in 0..r {
        let expect = dot(&col(rm.phi.as_ref().unwrap().as_ref(), c), &full);
        assert!((load[c] - expect).abs() <= 1e-12 * expect.abs().max(1e-300));
    }

    for kind in [BasisKind::TvdPlain, BasisKind::Modes] {
        let t0 = Instant::now();
        let b = build_basis(&model, kind, &BasisOptions::default()).unwrap();
        println!(
            "friction_bar {kind:?} basis: r = {}, g = {}, dropped {}, built in {:.1} ms",
            b.phi.ncols(),
            b.g,
            b.dropped,
            t0.elapsed().as_secs_f64() * 1e3
        );
        let dev = max_dev_from_identity(&gram(&model.mass, b.phi.as_ref(), b.phi.as_ref()));
        assert!(dev < 1e-10, "{kind:?}: ΦᵀMΦ − I = {dev:e}");
        if kind == BasisKind::Modes {
            assert_eq!(b.phi.ncols(), 16 + b.g);
        }
    }
}

#[test]
fn tangential_stiffness_widens_the_tvd_space() {
    let model = common::model("friction_bar");
    let w = model.joint.pairs();
    let base = craig_bampton(&model, 10).unwrap();
    let normal = trial_vector_derivatives(&model, base.as_ref(), &TvdOptions::default()).unwrap();
    let opts = TvdOptions {
        tangential: true,
        ..TvdOptions::default()
    };
    let tang = trial_vector_derivatives(&model, base.as_ref(), &opts).unwrap();
    let pn = pod(normal.vectors.as_ref(), Some(&model.stiffness)).unwrap();
    let pt = pod(tang.vectors.as_ref(), Some(&model.stiffness)).unwrap();
    println!(
        "friction_bar rank of the TVD space: normal only {}, with k_t {} (pairs {w}); g(0.999) {} / {}",
        pn.lambda.len(),
        pt.lambda.len(),
        pn.choose_g(DEFAULT_THRESHOLD),
        pt.choose_g(DEFAULT_THRESHOLD)
    );
    assert!(pn.lambda.len() <= w);
    assert!(pt.lambda.len() <= 3 * w);
    assert!(pt.lambda.len() > pn.lambda.len());
}

#[test]
fn final_basis_drops_dependent_directions_and_keeps_the_span() {
    let model = common::model("multilayer_sheet");
    let cb = craig_bampton(&model, 10).unwrap();
    let n = model.dofs();
    // Duplicates and a combination of earlier columns must be dropped.
    let extra = Mat::from_fn(n, 3, |r, c| match c {
        0 => cb[(r, 2)],
        1 => 3.0 * cb[(r, 7)],
        _ => cb[(r, 0)] - 2.0 * cb[(r, 12)],
    });
    let (q, dropped) = final_basis(&[cb.as_ref(), extra.as_ref()], &model.mass, 1e-8).unwrap();
    assert_eq!(dropped, 3);
    assert_eq!(q.ncols(), 16);
    let dev = max_dev_from_identity(&gram(&model.mass, q.as_ref(), q.as_ref()));
    assert!(dev < 1e-10, "ΦᵀMΦ − I = {dev:e}");
    // span(Φ) = span(CB): the M-orthogonal projection of each CB column reproduces it.
    let qmc = gram(&model.mass, q.as_ref(), cb.as_ref());
    for c in 0..cb.ncols() {
        let x = col(cb.as_ref(), c);
        let mut res = x.clone();
        for k in 0..q.ncols() {
            for r in 0..n {
                res[r] -= q[(r, k)] * qmc[(k, c)];
            }
        }
        let rel = inf_norm(&res) / inf_norm(&x);
        assert!(rel < 1e-9, "column {c}: projection residual {rel:e}");
    }
}

/// The K-weighted POD of the friction-bar TVD without squaring ([`pod_tvd`]) against an
/// independent computation: the flexibility columns `Z' = K⁻¹ B_nᵀ` solved here (sparse
/// Cholesky, one refinement step), `G' = B_n Z'`, its Cholesky `G' = L Lᵀ`, and the singular
/// values of the K-orthonormalized coefficients `Lᵀ C` (C: the pseudoforces formed here from
/// `k_n B_n φ_i` on the active pairs, K-normalized with G'). The eigenvalues agree to
/// 1e-14 λ_max, several lie below the old 1e-12 cut, and with all POD modes the reduced contact
/// force matches the full one to 1e-6 (the Gram route stalled at 2e-2).
#[test]
fn weighted_pod_of_tvd_resolves_small_eigenvalues() {
    let model = common::model("friction_bar");
    let base = craig_bampton(&model, 10).unwrap();
    let opts = TvdOptions::default();
    let tvd = trial_vector_derivatives(&model, base.as_ref(), &opts).unwrap();
    let t0 = Instant::now();
    let p = pod_tvd(&model, &tvd, true).unwrap();
    let t_new = t0.elapsed().as_secs_f64();
    let t0 = Instant::now();
    let gram = pod(tvd.vectors.as_ref(), Some(&model.stiffness)).unwrap();
    let t_old = t0.elapsed().as_secs_f64();
    println!(
        "weighted POD: pod_tvd {:.2} ms ({} modes), Gram route pod {:.2} ms ({} modes)",
        1e3 * t_new,
        p.lambda.len(),
        1e3 * t_old,
        gram.lambda.len()
    );
    let n = model.dofs();
    let w = model.joint.pairs();
    let kn = model.contact.normal_stiffness;
    // Z' and G'.
    let mut bt = Mat::<f64>::zeros(n, w);
    for z in 0..w {
        for (c, v) in model.joint.row(3 * z + NORMAL) {
            bt[(c, z)] += v;
        }
    }
    let chol = SparseCholesky::new(&model.stiffness).unwrap();
    let mut zf = bt.clone();
    chol.solve_in_place(&mut zf);
    for _ in 0..2 {
        let mut res = residual_dd(&model.stiffness, &bt, &zf);
        chol.solve_in_place(&mut res);
        zf += &res;
    }
    let bz = Mat::from_fn(w, w, |a, b| {
        model
            .joint
            .row(3 * a + NORMAL)
            .map(|(c, v)| v * zf[(c, b)])
            .sum::<f64>()
    });
    let g = Mat::from_fn(w, w, |a, b| 0.5 * (bz[(a, b)] + bz[(b, a)]));
    // C from the pseudoforces, K-normalized with G'.
    let bphi = model.joint.reduce(base.as_ref());
    let cols = tvd.index.len();
    let mut c = Mat::<f64>::zeros(w, cols);
    for (a, ix) in tvd.index.iter().enumerate() {
        let act = &tvd.active[ix.j][if ix.k < 0 { 0 } else { 1 }];
        for z in 0..w {
            if act[z] {
                c[(z, a)] = kn * bphi[(3 * z + NORMAL, ix.i)];
            }
        }
        let gc = &g * c.col(a);
        let e: f64 = c.col(a).iter().zip(gc.iter()).map(|(x, y)| x * y).sum();
        let s = e.sqrt();
        c.col_mut(a).iter_mut().for_each(|v| *v /= s);
    }
    let l = g.llt(faer::Side::Lower).unwrap();
    let a = l.L().transpose() * &c;
    let mut sv = a.singular_values().unwrap();
    sv.sort_by(|x, y| y.total_cmp(x));
    let reference: Vec<f64> = sv.iter().map(|s| s * s).collect();
    let lmax = reference[0];
    println!("friction bar weighted POD: {} kept", p.lambda.len());
    let (mut worst_abs, mut worst_rel) = (0.0f64, 0.0f64);
    for (i, r) in reference.iter().enumerate() {
        let got = p.lambda.get(i).copied().unwrap_or(0.0);
        println!(
            "  λ_{i:2}/λ_max: pod_tvd {:.6e}, reference {:.6e}",
            got / lmax,
            r / lmax
        );
        let d = (got - r).abs();
        worst_rel = worst_rel.max(d / r);
        assert!(
            d <= 1e-14 * lmax + 1e-10 * r,
            "λ_{i}: {got:e} vs {r:e} (Δ = {:e} λ_max)",
            d / lmax
        );
        if *r < 1e-6 * lmax {
            worst_abs = worst_abs.max(d / lmax);
        }
    }
    println!(
        "  worst |Δλ|/λ (all) = {worst_rel:.2e}, worst |Δλ|/λ_max (λ < 1e-6 λ_max) = {worst_abs:.2e}"
    );
    // The check must reach the small end of the spectrum (measured with the re-meshed weld
    // neighbourhoods: 4 below 1e-10 λ_max, the smallest 1.4e-13; the RBE3 welds had 3 below
    // 1e-12).
    let tiny = p.lambda.iter().filter(|&&l| l < 1e-10 * lmax).count();
    assert!(tiny >= 3, "only {tiny} eigenvalues below 1e-10 λ_max");
    // All POD modes: reduced contact force vs the full model.
    let b = build_basis(
        &model,
        BasisKind::Tvd,
        &BasisOptions {
            g: Some(p.lambda.len()),
            ..Default::default()
        },
    )
    .unwrap();
    let load = model.master_load();
    let full = contact_static_full(&model, load, &ContactOptions::default()).unwrap();
    let red = ReducedSystem::new(&model, b.phi).unwrap();
    let (_, state) = common::reduced_contact(&red, load, kn).unwrap();
    let fc = full.state.contact_force_norm;
    let err = (state.contact_force_norm - fc).abs() / fc;
    println!("  g = {}: ‖f_c‖ relative error {err:.2e}", p.lambda.len());
    assert!(err <= 1e-6, "reduced contact force error {err:e}");
}

/// `B − A X` (A symmetric, both triangles stored) with each entry accumulated in double-double
/// (TwoSum, FMA TwoProduct) and rounded once.
fn residual_dd(a: &SymCsc, b: &Mat<f64>, x: &Mat<f64>) -> Mat<f64> {
    let n = a.n;
    let mut out = Mat::<f64>::zeros(n, x.ncols());
    for c in 0..x.ncols() {
        let mut hi: Vec<f64> = (0..n).map(|i| b[(i, c)]).collect();
        let mut lo = vec![0.0; n];
        let mut add = |i: usize, av: f64, xv: f64| {
            let p = -av * xv;
            let pe = (-av).mul_add(xv, -p);
            let s = hi[i] + p;
            let z = s - hi[i];
            let se = (hi[i] - (s - z)) + (p - z);
            hi[i] = s;
            lo[i] += se + pe;
        };
        for j in 0..n {
            for k in a.col_ptr[j]..a.col_ptr[j + 1] {
                add(a.row_idx[k], a.values[k], x[(j, c)]);
            }
        }
        for i in 0..n {
            out[(i, c)] = hi[i] + lo[i];
        }
    }
    out
}
