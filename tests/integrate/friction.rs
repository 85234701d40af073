//! The pair law of `jointrom::joint::law`: hysteresis loop against the exact Coulomb dissipation,
//! non-negative dissipation, no force when open, isotropy, derivatives against finite differences.

use jointrom::joint::law::{PairLaw, PairState, DEFAULT_TAU};

use crate::common;

fn law() -> PairLaw {
    PairLaw {
        k_n: 1e4,
        friction: true,
        mu: 0.25,
        k_t: 1e4,
        tau: DEFAULT_TAU,
    }
}

/// Integrates `ṡ` and the dissipation `∫ p_t·ṡ` and the work `∫ p_t·u̇_t` along a prescribed
/// path `u(t)` with classical RK4 at step `h` (≤ τ/4: the law's relaxation is resolved).
/// Returns (s, dissipation, work) after each of `cycles` periods.
fn integrate_path(
    law: &PairLaw,
    path: impl Fn(f64) -> ([f64; 3], [f64; 3]),
    period: f64,
    cycles: usize,
    steps_per_cycle: usize,
) -> Vec<([f64; 2], f64, f64)> {
    let h = period / steps_per_cycle as f64;
    let rate = |t: f64, s: [f64; 2]| -> [f64; 4] {
        let (u, du) = path(t);
        let r = law.eval(u, s);
        [
            r.s_rate[0],
            r.s_rate[1],
            r.dissipation,
            r.p[0] * du[0] + r.p[1] * du[1] + r.p[2] * du[2],
        ]
    };
    let mut y = [0.0f64; 4];
    let mut out = Vec::new();
    let mut t = 0.0;
    for _ in 0..cycles {
        for _ in 0..steps_per_cycle {
            let k1 = rate(t, [y[0], y[1]]);
            let k2 = rate(
                t + 0.5 * h,
                [y[0] + 0.5 * h * k1[0], y[1] + 0.5 * h * k1[1]],
            );
            let k3 = rate(
                t + 0.5 * h,
                [y[0] + 0.5 * h * k2[0], y[1] + 0.5 * h * k2[1]],
            );
            let k4 = rate(t + h, [y[0] + h * k3[0], y[1] + h * k3[1]]);
            for i in 0..4 {
                y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
            }
            assert!(
                k1[2] >= 0.0,
                "negative dissipation rate {} at t = {t}",
                k1[2]
            );
            t += h;
        }
        out.push(([y[0], y[1]], y[2], y[3]));
    }
    out
}

/// A pair at constant normal force p_n under u_t = A sin(ωt) along direction θ dissipates
/// 4 μ p_n (A − μ p_n / k_t) per cycle (the area of the exact Coulomb loop with elastic stick).
#[test]
fn cyclic_slip_dissipates_the_coulomb_loop_area() {
    let law = law();
    let pn = 1.0; // N
    let g = -pn / law.k_n;
    let c = law.mu * pn / law.k_t; // 2.5e-5 mm
    let freq = 200.0; // Hz
    let omega = 2.0 * std::f64::consts::PI * freq;
    let period = 1.0 / freq;
    let steps = (period / (law.tau / 4.0)).ceil() as usize;
    for (amp, theta) in [(10.0 * c, 0.0), (40.0 * c, 0.7), (3.0 * c, 2.0)] {
        let dir = [f64::cos(theta), f64::sin(theta)];
        let path = |t: f64| {
            let a = amp * (omega * t).sin();
            let da = amp * omega * (omega * t).cos();
            ([g, a * dir[0], a * dir[1]], [0.0, da * dir[0], da * dir[1]])
        };
        let res = integrate_path(&law, path, period, 3, steps);
        let expected = 4.0 * law.mu * pn * (amp - c);
        // Cycles 2 and 3 run on the steady loop (the first starts from the virgin state).
        for cyc in 1..3 {
            let diss = res[cyc].1 - res[cyc - 1].1;
            let work = res[cyc].2 - res[cyc - 1].2;
            let err = (diss - expected).abs() / expected;
            println!(
                "A = {amp:.3e} mm, θ = {theta}: cycle {} dissipation {diss:.6e} N·mm, \
                 work {work:.6e}, exact {expected:.6e}, rel. error {err:.2e}",
                cyc + 1
            );
            assert!(err < 1e-2, "dissipation error {err:.3e} ≥ 1 %");
            // Over a closed cycle the elastic energy returns: the work equals the dissipation.
            assert!(
                (work - diss).abs() < 1e-2 * expected,
                "work {work} vs dissipation {diss}"
            );
        }
    }
}

/// Dissipation is never negative, over random states and along a 2D (circular) path.
#[test]
fn dissipation_is_never_negative() {
    let law = law();
    let mut rng = common::rng(0x1234_5678_9abc_def0);
    let mut rnd = || common::uniform(&mut rng);
    for _ in 0..100_000 {
        let u = [1e-4 * rnd(), 1e-4 * rnd(), 1e-4 * rnd()];
        let s = [1e-4 * rnd(), 1e-4 * rnd()];
        let r = law.eval(u, s);
        assert!(
            r.dissipation >= 0.0,
            "d = {} at u = {u:?}, s = {s:?}",
            r.dissipation
        );
        let pt = r.p[1].hypot(r.p[2]);
        assert!(
            pt <= law.mu * r.p[0].abs() * (1.0 + 1e-12) + 1e-300,
            "|p_t| = {pt} exceeds μ|p_n| = {}",
            law.mu * r.p[0].abs()
        );
    }
    // Circular path with a varying normal force: RK4 checks d ≥ 0 at every step.
    let c = law.mu * 1.0 / law.k_t;
    let freq = 300.0;
    let w = 2.0 * std::f64::consts::PI * freq;
    let path = |t: f64| {
        let gn = -1e-4 * (1.0 + 0.5 * (3.0 * w * t).sin());
        let dg = -1e-4 * 0.5 * 3.0 * w * (3.0 * w * t).cos();
        let a = 5.0 * c;
        (
            [gn, a * (w * t).cos(), a * (w * t).sin()],
            [dg, -a * w * (w * t).sin(), a * w * (w * t).cos()],
        )
    };
    let res = integrate_path(&law, path, 1.0 / freq, 1, 20_000);
    assert!(res[0].1 > 0.0);
}

#[test]
fn no_force_when_open() {
    let law = law();
    for g in [0.0, 1e-9, 1e-3, 1.0] {
        for s in [[0.0, 0.0], [1e-3, -2e-3]] {
            let r = law.eval([g, 5e-4, -1e-4], s);
            assert_eq!(r.p, [0.0; 3], "g = {g}");
            assert_eq!(r.state, PairState::Open);
            assert_eq!(r.dissipation, 0.0);
            // the memory relaxes towards u_t
            assert!(r.s_rate[0] * (5e-4 - s[0]) >= 0.0);
        }
    }
    let closed = law.eval([-1e-6, 0.0, 0.0], [0.0; 2]);
    assert!((closed.p[0] + 1e-2).abs() < 1e-15, "p_n = {}", closed.p[0]);
    let frictionless = PairLaw {
        friction: false,
        ..law
    };
    let r = frictionless.eval([-1e-6, 1.0, 1.0], [0.0; 2]);
    assert_eq!([r.p[1], r.p[2]], [0.0, 0.0]);
}

/// Rotating the tangential path and memory by θ in the x–z plane rotates forces and rates.
#[test]
fn law_is_isotropic_in_the_tangent_plane() {
    let law = law();
    let cases = [
        ([-1e-5, 1e-8, 2e-8], [0.0, 0.0]),   // stick
        ([-1e-5, 3e-6, -1e-6], [1e-7, 0.0]), // slip
        ([2e-6, 3e-6, -1e-6], [1e-7, 0.0]),  // open
    ];
    for (u, s) in cases {
        let base = law.eval(u, s);
        for theta in [0.3f64, 1.9, -2.4] {
            let (c, sn) = (theta.cos(), theta.sin());
            let rot = |x: f64, z: f64| [c * x - sn * z, sn * x + c * z];
            let ur = rot(u[1], u[2]);
            let sr = rot(s[0], s[1]);
            let r = law.eval([u[0], ur[0], ur[1]], sr);
            let pe = rot(base.p[1], base.p[2]);
            let se = rot(base.s_rate[0], base.s_rate[1]);
            let scale = base.p[1].hypot(base.p[2]).max(1e-300);
            let sscale = base.s_rate[0].hypot(base.s_rate[1]).max(1e-300);
            assert_eq!(r.state, base.state);
            assert!((r.p[0] - base.p[0]).abs() <= 1e-14 * base.p[0].abs());
            for i in 0..2 {
                assert!(
                    (r.p[1 + i] - pe[i]).abs() <= 1e-12 * scale,
                    "θ {theta}: {r:?} vs {pe:?}"
                );
                assert!((r.s_rate[i] - se[i]).abs() <= 1e-9 * sscale);
            }
            assert!((r.dissipation - base.dissipation).abs() <= 1e-9 * base.dissipation.abs());
        }
    }
}

/// The exact derivatives of `tangent` against central differences in each branch.
#[test]
fn tangent_matches_finite_differences() {
    let law = law();
    let cases = [
        ([-1e-5, 1e-8, 2e-8], [0.0, 0.0]),   // stick
        ([-1e-5, 3e-6, -1e-6], [1e-7, 0.0]), // slip
        ([2e-6, 3e-6, -1e-6], [1e-7, 0.0]),  // open
    ];
    for (u, s) in cases {
        let t = law.tangent(u, s);
        let h = 1e-11;
        for j in 0..3 {
            let mut up = u;
            let mut um = u;
            up[j] += h;
            um[j] -= h;
            let (a, b) = (law.eval(up, s), law.eval(um, s));
            let dp: Vec<f64> = (0..3).map(|i| (a.p[i] - b.p[i]) / (2.0 * h)).collect();
            let ds: Vec<f64> = (0..2)
                .map(|i| (a.s_rate[i] - b.s_rate[i]) / (2.0 * h))
                .collect();
            let dd = (a.dissipation - b.dissipation) / (2.0 * h);
            let (ep, es, ed) = if j == 0 {
                (
                    [t.pn_g, t.pt_g[0], t.pt_g[1]],
                    [t.sdot_g[0], t.sdot_g[1]],
                    t.diss_g,
                )
            } else {
                (
                    [0.0, t.pt_u[0][j - 1], t.pt_u[1][j - 1]],
                    [t.sdot_u[0][j - 1], t.sdot_u[1][j - 1]],
                    t.diss_u[j - 1],
                )
            };
            let close = |x: f64, y: f64, scale: f64| (x - y).abs() <= 1e-5 * scale;
            for i in 0..3 {
                assert!(
                    close(dp[i], ep[i], law.k_n),
                    "∂p{i}/∂u{j}: fd {} vs {}",
                    dp[i],
                    ep[i]
                );
            }
            for i in 0..2 {
                assert!(
                    close(ds[i], es[i], 1.0 / law.tau),
                    "∂ṡ{i}/∂u{j}: fd {} vs {}",
                    ds[i],
                    es[i]
                );
            }
            assert!(
                close(dd, ed, law.k_n * 1e-5 / law.tau),
                "∂d/∂u{j}: fd {dd} vs {ed}"
            );
        }
    }
}

/// The stick/slip switch `μ|p_n| − k_t|e|` is positive exactly on sticking closed pairs, and
/// `evaluate_pairs` agrees with the pair-wise law.
#[test]
fn switch_function_and_slice_evaluation_agree_with_the_law() {
    use jointrom::joint::law::evaluate_pairs;
    let law = law();
    let u = [
        -1e-5, 1e-8, 2e-8, // stick
        -1e-5, 3e-6, -1e-6, // slip
        2e-6, 3e-6, -1e-6, // open
    ];
    let s = [0.0, 0.0, 1e-7, 0.0, 1e-7, 0.0];
    let mut p = [0.0; 9];
    let mut rate = [0.0; 6];
    let tot = evaluate_pairs(&law, &u, &s, &mut p, &mut rate);
    let states = [PairState::Stick, PairState::Slip, PairState::Open];
    let mut diss = 0.0;
    for k in 0..3 {
        let uk = [u[3 * k], u[3 * k + 1], u[3 * k + 2]];
        let sk = [s[2 * k], s[2 * k + 1]];
        let r = law.eval(uk, sk);
        assert_eq!(r.state, states[k]);
        assert_eq!(&p[3 * k..3 * k + 3], &r.p);
        assert_eq!(&rate[2 * k..2 * k + 2], &r.s_rate);
        diss += r.dissipation;
        let sw = law.switch(uk, sk);
        match r.state {
            PairState::Stick => assert!(sw > 0.0),
            _ => assert!(sw < 0.0),
        }
    }
    assert_eq!(tot.dissipation, diss);
    assert_eq!((tot.slipping, tot.closed), (1, 2));
    // Stored energy: penalty plus the capped elastic stick energy.
    let e = law.stored_energy([u[3], u[4], u[5]], [s[2], s[3]]);
    let c = law.mu * law.k_n * 1e-5 / law.k_t;
    let expected = 0.5 * law.k_n * 1e-10 + 0.5 * law.k_t * c * c;
    assert!((e - expected).abs() <= 1e-14 * expected);
}
