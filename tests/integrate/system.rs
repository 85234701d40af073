//! The second-order systems (`jointrom::system`) and the mechanical ODE (`jointrom::integrate::mechanical`):
//! right-hand side against a direct computation, the structured Newton solve against
//! `I − γJ` by differences, and a Φ = I reduced system against the full one.

use faer::Mat;
use jointrom::integrate::problem::OdeOptions;
use jointrom::integrate::problem::OdeProblem;
use jointrom::integrate::{run, MechanicalOde, ProblemOptions, TransientOptions};
use jointrom::joint::law::{PairLaw, PairState};
use jointrom::system::{FullSystem, ReducedSystem, Scene, SecondOrderSystem};
use jointrom::Model;
use rand::rngs::StdRng;

use crate::common::{self, inf_norm};

fn opts(friction: bool) -> ProblemOptions {
    ProblemOptions {
        friction,
        events: true,
        ..ProblemOptions::default()
    }
}

/// A state with q random (mm scale `qs`), v random, and slip memory s = u_t − e where e = 0
/// (all closed pairs stick) or, for `slip`, |e| = 2c on closed pairs (they slide).
fn state<S: SecondOrderSystem>(
    ode: &MechanicalOde<S>,
    rng: &mut StdRng,
    qs: f64,
    slip: bool,
    t_load: f64,
) -> Vec<f64> {
    let _ = t_load;
    let n = ode.coords();
    let w = ode.system().pairs();
    let mut y = vec![0.0; ode.dim()];
    for v in &mut y[..n] {
        *v = qs * common::uniform(rng);
    }
    for v in &mut y[n..2 * n] {
        *v = common::uniform(rng);
    }
    let mut u = vec![0.0; 3 * w];
    ode.system().joint_apply_into(&y[..n], &mut u);
    if ode.law().friction {
        let law = *ode.law();
        for k in 0..w {
            let c = law.mu * law.k_n * (-u[3 * k]).max(0.0) / law.k_t;
            let (e1, e2) = if slip && c > 0.0 {
                let th = std::f64::consts::PI * common::uniform(rng);
                (2.0 * c * th.cos(), 2.0 * c * th.sin())
            } else {
                (0.0, 0.0)
            };
            // states are s / slip_scale
            y[2 * n + 2 * k] = (u[3 * k + 1] - e1) / ode.slip_scale();
            y[2 * n + 2 * k + 1] = (u[3 * k + 2] - e2) / ode.slip_scale();
        }
    }
    let wi = ode.work_index();
    y[wi] = 0.3;
    y[wi + 1] = 0.1;
    y
}

fn pair_states<S: SecondOrderSystem>(ode: &MechanicalOde<S>, y: &[f64]) -> Vec<PairState> {
    let n = ode.coords();
    let w = ode.system().pairs();
    let mut u = vec![0.0; 3 * w];
    ode.system().joint_apply_into(&y[..n], &mut u);
    (0..w)
        .map(|k| {
            let s = if ode.law().friction {
                let ss = ode.slip_scale();
                [ss * y[2 * n + 2 * k], ss * y[2 * n + 2 * k + 1]]
            } else {
                [0.0; 2]
            };
            ode.law()
                .eval([u[3 * k], u[3 * k + 1], u[3 * k + 2]], s)
                .state
        })
        .collect()
}

/// `(I − γJ) z` by a central difference of F along z with step ε.
fn newton_matvec<S: SecondOrderSystem>(
    ode: &mut MechanicalOde<S>,
    t: f64,
    y: &[f64],
    z: &[f64],
    gamma: f64,
    eps: f64,
) -> Vec<f64> {
    let d = ode.dim();
    let yp: Vec<f64> = (0..d).map(|i| y[i] + eps * z[i]).collect();
    let ym: Vec<f64> = (0..d).map(|i| y[i] - eps * z[i]).collect();
    let mut fp = vec![0.0; d];
    let mut fm = vec![0.0; d];
    ode.rhs(t, &yp, &mut fp).unwrap();
    ode.rhs(t, &ym, &mut fm).unwrap();
    (0..d)
        .map(|i| z[i] - gamma * (fp[i] - fm[i]) / (2.0 * eps))
        .collect()
}

/// `(I − γJ) z` assembled from the block Jacobian (system operators and the pair law's exact
/// derivatives, `∂p_t/∂g` included): no elimination, unlike the structured solve under test.
fn newton_matvec_exact<S: SecondOrderSystem>(
    ode: &mut MechanicalOde<S>,
    t: f64,
    y: &[f64],
    z: &[f64],
    gamma: f64,
    with_pt_g: bool,
) -> Vec<f64> {
    let n = ode.coords();
    let w = ode.system().pairs();
    let law = *ode.law();
    let fr = law.friction;
    let ns = if fr { 2 * w } else { 0 };
    // Work in physical units (s in mm, W and D in N·mm): D = diag(1, slip_scale, energy_scale)
    // maps states to physical values, and the state operator is D⁻¹ (I − γJ_phys) D.
    let d = ode.dim();
    let unit: Vec<f64> = (0..d)
        .map(|i| {
            if i < 2 * n {
                1.0
            } else if i < 2 * n + ns {
                ode.slip_scale()
            } else {
                ode.energy_scale()
            }
        })
        .collect();
    let y: Vec<f64> = y.iter().zip(&unit).map(|(a, b)| a * b).collect();
    let z: Vec<f64> = z.iter().zip(&unit).map(|(a, b)| a * b).collect();
    let mut u = vec![0.0; 3 * w];
    let mut bz = vec![0.0; 3 * w];
    ode.system().joint_apply_into(&y[..n], &mut u);
    ode.system().joint_apply_into(&z[..n], &mut bz);
    let mut dp = vec![0.0; 3 * w];
    let mut jz = vec![0.0; ode.dim()];
    let mut dd = 0.0;
    for k in 0..w {
        let sk = if fr {
            [y[2 * n + 2 * k], y[2 * n + 2 * k + 1]]
        } else {
            [0.0; 2]
        };
        let zs = if fr {
            [z[2 * n + 2 * k], z[2 * n + 2 * k + 1]]
        } else {
            [0.0; 2]
        };
        let mut tg = law.tangent([u[3 * k], u[3 * k + 1], u[3 * k + 2]], sk);
        if !with_pt_g {
            tg.pt_g = [0.0; 2];
        }
        let de = [bz[3 * k + 1] - zs[0], bz[3 * k + 2] - zs[1]];
        let dg = bz[3 * k];
        dp[3 * k] = tg.pn_g * dg;
        for i in 0..2 {
            dp[3 * k + 1 + i] = tg.pt_u[i][0] * de[0] + tg.pt_u[i][1] * de[1] + tg.pt_g[i] * dg;
            if fr {
                jz[2 * n + 2 * k + i] =
                    tg.sdot_u[i][0] * de[0] + tg.sdot_u[i][1] * de[1] + tg.sdot_g[i] * dg;
            }
        }
        dd += tg.diss_u[0] * de[0] + tg.diss_u[1] * de[1] + tg.diss_g * dg;
    }
    let mut acc = vec![0.0; n];
    ode.system().mul_k_into(&z[..n], &mut acc);
    ode.system().joint_transpose_add(&dp, &mut acc);
    let mut f = vec![0.0; n];
    ode.system().load_into(t, &mut f);
    jz[..n].copy_from_slice(&z[n..2 * n]);
    // J_v z = −M⁻¹ (K z_q + Bᵀ dp): checked as M (z_v − r_v) form by the caller via `mass_times`.
    for (o, a) in jz[n..2 * n].iter_mut().zip(&acc) {
        *o = -a;
    }
    let wi = ode.work_index();
    jz[wi] = f.iter().zip(&z[n..2 * n]).map(|(a, b)| a * b).sum();
    jz[wi + 1] = dd;
    // (I − γJ) z with the v rows left multiplied by M: M z_v − γ (−K z_q − Bᵀ dp).
    let mut mzv = vec![0.0; n];
    ode.system().mul_m_into(&z[n..2 * n], &mut mzv);
    let mut out: Vec<f64> = z.iter().zip(&jz).map(|(a, b)| a - gamma * b).collect();
    for i in 0..n {
        out[n + i] = mzv[i] - gamma * jz[n + i];
    }
    // Size of the largest term entering each row (for a backward error).
    let mut scale: Vec<f64> = z
        .iter()
        .zip(&jz)
        .map(|(a, b)| a.abs().max((gamma * b).abs()))
        .collect();
    for i in 0..n {
        scale[n + i] = mzv[i].abs().max((gamma * jz[n + i]).abs());
    }
    for i in 2 * n..d {
        out[i] /= unit[i];
        scale[i] /= unit[i];
    }
    out.extend(scale);
    out
}

/// Solves `(I − γJ) z = r` with the problem's solver and returns the relative residuals
/// `‖(I − γJ) z − r‖∞ / ‖r‖∞`, (1) with the exact block operator (v rows times M), (2) with
/// `(I − γJ) z` by differences with a step that keeps every pair on
/// its branch (the law is piecewise affine off the sliding branch, so the difference is exact to
/// round-off there).
fn newton_residual<S: SecondOrderSystem>(
    ode: &mut MechanicalOde<S>,
    t: f64,
    y: &[f64],
    gamma: f64,
    rng: &mut StdRng,
    with_pt_g: bool,
) -> (f64, f64, f64) {
    let d = ode.dim();
    let r: Vec<f64> = (0..d).map(|_| common::uniform(rng)).collect();
    let mut fy = vec![0.0; d];
    ode.rhs(t, y, &mut fy).unwrap();
    assert!(ode.newton_setup(t, y, &fy, false, gamma).unwrap());
    let mut z = vec![0.0; d];
    ode.newton_solve(t, y, &r, &mut z, gamma).unwrap();
    let base = pair_states(ode, y);
    let mut eps = 1e-2 * inf_norm(y) / inf_norm(&z);
    loop {
        let yp: Vec<f64> = (0..d).map(|i| y[i] + eps * z[i]).collect();
        let ym: Vec<f64> = (0..d).map(|i| y[i] - eps * z[i]).collect();
        if pair_states(ode, &yp) == base && pair_states(ode, &ym) == base {
            break;
        }
        eps *= 0.25;
        assert!(eps > 1e-30, "no step keeps the pairs on their branches");
    }
    // Exact block operator (v rows multiplied by M, so no M-solve enters the check).
    let mut ez = newton_matvec_exact(ode, t, y, &z, gamma, with_pt_g);
    let terms = ez.split_off(d);
    let mut mrv = vec![0.0; ode.coords()];
    ode.system()
        .mul_m_into(&r[ode.coords()..2 * ode.coords()], &mut mrv);
    let mut rr = r.clone();
    rr[ode.coords()..2 * ode.coords()].copy_from_slice(&mrv);
    let eres: Vec<f64> = ez.iter().zip(&rr).map(|(a, b)| a - b).collect();
    let exact_rel = inf_norm(&eres) / inf_norm(&rr);
    let backward = inf_norm(&eres) / (inf_norm(&terms) + inf_norm(&rr));
    println!("  block operator: residual/‖r‖ {exact_rel:.2e}, backward error {backward:.2e}");
    let az = newton_matvec(ode, t, y, &z, gamma, eps);
    let res: Vec<f64> = az.iter().zip(&r).map(|(a, b)| a - b).collect();
    (exact_rel, backward, inf_norm(&res) / inf_norm(&r))
}

/// The pair forces, computed independently of `jointrom::joint::law` (the law written out).
fn pair_forces_direct(law: &PairLaw, u: &[f64], s: &[f64]) -> Vec<f64> {
    let w = u.len() / 3;
    let mut p = vec![0.0; 3 * w];
    for k in 0..w {
        let g = u[3 * k];
        if g >= 0.0 {
            continue;
        }
        let pn = law.k_n * g;
        p[3 * k] = pn;
        if law.friction {
            let e = [u[3 * k + 1] - s[2 * k], u[3 * k + 2] - s[2 * k + 1]];
            let trial = [law.k_t * e[0], law.k_t * e[1]];
            let norm = (trial[0] * trial[0] + trial[1] * trial[1]).sqrt();
            let cap = law.mu * pn.abs();
            let scale = if norm <= cap { 1.0 } else { cap / norm };
            p[3 * k + 1] = scale * trial[0];
            p[3 * k + 2] = scale * trial[1];
        }
    }
    p
}

#[test]
fn full_rhs_matches_a_direct_computation() {
    let model = common::model("friction_bar");
    let n = model.dofs();
    let mut rng = common::rng(0x9e37_79b9_7f4a_7c15);
    for (friction, slip) in [(false, false), (true, false), (true, true)] {
        let mut ode = MechanicalOde::new(
            FullSystem::new(&model).unwrap(),
            &model.contact,
            &opts(friction),
        )
        .unwrap();
        let y = state(&ode, &mut rng, 1e-3, slip, 0.0);
        let t = 0.02; // inside the load ramp
        let mut ydot = vec![0.0; ode.dim()];
        ode.rhs(t, &y, &mut ydot).unwrap();
        // Direct: r = f − K q − Bᵀp with the model's own matrices; M v' must equal r.
        let q = &y[..n];
        let mut u = vec![0.0; model.joint.rows()];
        model.joint.apply(q, &mut u);
        let s: Vec<f64> = y[2 * n..2 * n + if friction { 2 * model.joint.pairs() } else { 0 }]
            .iter()
            .map(|x| x * ode.slip_scale())
            .collect();
        let law = *ode.law();
        let p = pair_forces_direct(&law, &u, &s);
        let mut f = vec![0.0; n];
        let fm = model.load.master_at(t);
        for (d, &dof) in model.master_dofs().iter().enumerate() {
            f[dof] += fm[d];
        }
        let mut kq = vec![0.0; n];
        model.stiffness.mul_vec(q, &mut kq);
        let mut btp = vec![0.0; n];
        model.joint.apply_transpose_add(&p, &mut btp);
        let mut ma = vec![0.0; n];
        model.mass.mul_vec(&ydot[n..2 * n], &mut ma);
        let scale = inf_norm(&kq) + inf_norm(&btp) + inf_norm(&f);
        let err = (0..n)
            .map(|i| (ma[i] - (f[i] - kq[i] - btp[i])).abs())
            .fold(0.0, f64::max);
        println!(
            "friction {friction} slip {slip}: ‖M v' − (f − Kq − Bᵀp)‖∞ / scale = {:.2e}",
            err / scale
        );
        assert!(
            err <= 1e-8 * scale,
            "M v' residual {err:.3e} (scale {scale:.3e})"
        );
        assert_eq!(&ydot[..n], &y[n..2 * n], "q' = v");
        let closed = u.iter().step_by(3).filter(|&&g| g < 0.0).count();
        assert!(
            closed > 5 && closed < model.joint.pairs(),
            "{closed} closed pairs"
        );
        let wi = ode.work_index();
        let fv: f64 = f.iter().zip(&y[n..2 * n]).map(|(a, b)| a * b).sum();
        let es = ode.energy_scale();
        assert!((es * ydot[wi] - fv).abs() <= 1e-12 * fv.abs().max(1e-300));
        if friction {
            let mut diss = 0.0;
            for k in 0..model.joint.pairs() {
                let r = law.eval(
                    [u[3 * k], u[3 * k + 1], u[3 * k + 2]],
                    [s[2 * k], s[2 * k + 1]],
                );
                let ss = ode.slip_scale();
                for i in 0..2 {
                    let rate = ss * ydot[2 * n + 2 * k + i];
                    assert!((rate - r.s_rate[i]).abs() <= 1e-14 * r.s_rate[i].abs());
                }
                diss += r.dissipation;
            }
            assert!((es * ydot[wi + 1] - diss).abs() <= 1e-14 * diss);
            if slip {
                assert!(diss > 0.0);
            }
        } else {
            assert_eq!(ydot[wi + 1], 0.0);
        }
    }
}

fn reduced_model(model: &Model, r: usize) -> ReducedSystem {
    let basis = jointrom::reduction::build_basis(
        model,
        jointrom::reduction::BasisKind::Tvd,
        &jointrom::reduction::BasisOptions {
            g: Some(r.saturating_sub(16)),
            ..Default::default()
        },
    )
    .unwrap();
    ReducedSystem::new(model, basis.phi).unwrap()
}

#[test]
fn newton_solve_matches_i_minus_gamma_j() {
    let model = common::model("friction_bar");
    let rom = reduced_model(&model, 30);
    let mut rng = common::rng(0x2545_f491_4f6c_dd1d);
    for gamma in [1e-6, 1e-5, 1e-4] {
        for friction in [false, true] {
            // Reduced (dense) system; q scale: reduced coordinates of a ~1e-3 mm deflection.
            let mut ode = MechanicalOde::new(rom.clone(), &model.contact, &opts(friction)).unwrap();
            let y = state(&ode, &mut rng, 1e-3, false, 0.0);
            let (exact, backward, fd) = newton_residual(&mut ode, 0.02, &y, gamma, &mut rng, true);
            assert!(
                backward < 1e-12,
                "backward error {backward:.3e} of the Newton solve"
            );
            println!(
                "reduced, γ = {gamma:e}, friction {friction}, no sliding: residual {exact:.2e} \
                 (block operator), {fd:.2e} (differences)"
            );
            assert!(exact < 1e-8, "reduced Newton solve residual {exact:.3e}");
            assert!(
                fd < 1e-3,
                "reduced Newton solve residual by differences {fd:.3e}"
            );
            // Full (sparse) system.
            let mut ode = MechanicalOde::new(
                FullSystem::new(&model).unwrap(),
                &model.contact,
                &opts(friction),
            )
            .unwrap();
            let y = state(&ode, &mut rng, 1e-3, false, 0.0);
            let (exact, backward, fd) = newton_residual(&mut ode, 0.02, &y, gamma, &mut rng, true);
            assert!(
                backward < 1e-12,
                "backward error {backward:.3e} of the Newton solve"
            );
            println!(
                "full, γ = {gamma:e}, friction {friction}, no sliding: residual {exact:.2e} \
                 (block operator), {fd:.2e} (differences)"
            );
            assert!(exact < 1e-8, "full Newton solve residual {exact:.3e}");
            // (differences through the full model's M⁻¹ and K of norm ~1e10 lose ~all digits:
            // printed, not asserted)
        }
        // Sliding pairs: the dropped ∂p_t/∂g makes the solve approximate; measure it.
        let mut ode = MechanicalOde::new(rom.clone(), &model.contact, &opts(true)).unwrap();
        let y = state(&ode, &mut rng, 1e-3, true, 0.0);
        // Against the operator without ∂p_t/∂g (what the solver factors): exact.
        let (_, backward, _) = newton_residual(&mut ode, 0.02, &y, gamma, &mut rng, false);
        assert!(
            backward < 1e-12,
            "backward error {backward:.3e} without ∂p_t/∂g"
        );
        // Against the true operator: a modified-Newton direction.
        let (exact, backward, fd) = newton_residual(&mut ode, 0.02, &y, gamma, &mut rng, true);
        println!(
            "reduced, γ = {gamma:e}, {} sliding pairs: residual/‖r‖ {exact:.2e}, backward \
             {backward:.2e} (block operator), {fd:.2e} (differences)",
            ode.slipping_at_setup()
        );
        assert!(ode.slipping_at_setup() > 0);
        assert!(
            backward > 1e-10,
            "∂p_t/∂g is dropped, the solve cannot be exact"
        );
        // The solver as the approximate inverse in z ← z + P (r − A z) (what a modified Newton
        // iteration does): measure the contraction rate (M̃ = I here, so the block operator is
        // exactly I − γJ).
        let d = ode.dim();
        let r: Vec<f64> = (0..d).map(|_| common::uniform(&mut rng)).collect();
        let mut z = vec![0.0; d];
        let mut steps = Vec::new();
        for _ in 0..4 {
            let mut az = newton_matvec_exact(&mut ode, 0.02, &y, &z, gamma, true);
            az.truncate(d);
            let res: Vec<f64> = r.iter().zip(&az).map(|(a, b)| a - b).collect();
            let mut dz = vec![0.0; d];
            ode.newton_solve(0.02, &y, &res, &mut dz, gamma).unwrap();
            z.iter_mut().zip(&dz).for_each(|(a, b)| *a += b);
            steps.push(inf_norm(&dz) / inf_norm(&z));
        }
        let shown: Vec<String> = steps.iter().map(|x| format!("{x:.1e}")).collect();
        println!("  relative corrections of z ← z + P(r − (I − γJ) z): {shown:?}");
        assert!(
            steps[1] < 0.1 * steps[0] && steps[2] < 0.1 * steps[1].max(1e-14),
            "the approximate Newton solve contracts too slowly: {shown:?}"
        );
    }
}

/// The error test of a reduced model measures the physical field as the full model's does
/// (`jointrom::integrate::mechanical`, *The error test of a reduced model*): for a basis of
/// Euclidean-orthogonal columns, the WRMS norm of a reduced error `(e_q, e_v, e_s)` under the
/// reduced weights equals the full model's WRMS norm of `(Φ e_q, Φ e_v, e_s)` under its own
/// (atol-dominated: weights ∝ the atol scales); with Φ = I the scales are the full model's.
#[test]
fn reduced_error_test_is_the_full_models_on_the_field() {
    let model = common::model("friction_bar");
    let n = model.dofs();
    let (r, stride) = (12, 37);
    let phi = Mat::from_fn(n, r, |i, j| {
        if i == 5 + stride * j {
            0.5 + j as f64
        } else {
            0.0
        }
    });
    let full = MechanicalOde::new(
        FullSystem::new(&model).unwrap(),
        &model.contact,
        &opts(true),
    )
    .unwrap();
    let red = MechanicalOde::new(
        ReducedSystem::new(&model, phi.clone()).unwrap(),
        &model.contact,
        &opts(true),
    )
    .unwrap();
    let (mut wf, mut wr) = (vec![0.0; full.dim()], vec![0.0; red.dim()]);
    assert!(full.atol_scale(&mut wf) && red.atol_scale(&mut wr));
    let ns = red.dim() - 2 * r - 2;
    assert_eq!(full.dim() - 2 * n - 2, ns);
    let wrms = |e: &[f64], w: &[f64]| {
        (e.iter().zip(w).map(|(x, s)| (x / s).powi(2)).sum::<f64>() / e.len() as f64).sqrt()
    };
    let mut rng = common::rng(0x5eed_0e77_0f1e_1d00);
    for _ in 0..5 {
        let mut er: Vec<f64> = (0..red.dim()).map(|_| common::uniform(&mut rng)).collect();
        let d = er.len();
        er[d - 2..].fill(0.0);
        let mut ef = vec![0.0; full.dim()];
        for j in 0..r {
            for i in 0..n {
                ef[i] += phi[(i, j)] * er[j];
                ef[n + i] += phi[(i, j)] * er[r + j];
            }
        }
        ef[2 * n..2 * n + ns].copy_from_slice(&er[2 * r..2 * r + ns]);
        let (a, b) = (wrms(&er, &wr), wrms(&ef, &wf));
        assert!((a - b).abs() <= 1e-12 * b, "reduced {a} vs full {b}");
    }
    let id = MechanicalOde::new(
        ReducedSystem::new(&model, Mat::identity(n, n)).unwrap(),
        &model.contact,
        &opts(true),
    )
    .unwrap();
    let mut wi = vec![0.0; id.dim()];
    assert!(id.atol_scale(&mut wi));
    assert_eq!(wi, wf);
}

#[test]
fn identity_reduction_agrees_with_the_full_system() {
    let model = common::model("friction_bar");
    let n = model.dofs();
    let rom = ReducedSystem::new(&model, Mat::identity(n, n)).unwrap();
    let mut rng = common::rng(0xdead_beef_cafe_f00d);
    for (friction, slip) in [(false, false), (true, true)] {
        let mut full = MechanicalOde::new(
            FullSystem::new(&model).unwrap(),
            &model.contact,
            &opts(friction),
        )
        .unwrap();
        let mut red = MechanicalOde::new(rom.clone(), &model.contact, &opts(friction)).unwrap();
        assert_eq!(full.dim(), red.dim());
        let y = state(&full, &mut rng, 1e-3, slip, 0.0);
        let t = 0.03;
        let d = full.dim();
        let (mut a, mut b) = (vec![0.0; d], vec![0.0; d]);
        full.rhs(t, &y, &mut a).unwrap();
        red.rhs(t, &y, &mut b).unwrap();
        let diff: Vec<f64> = a.iter().zip(&b).map(|(x, y)| x - y).collect();
        let rel = inf_norm(&diff) / inf_norm(&a);
        println!("Φ = I: rhs relative difference {rel:.2e}");
        assert!(rel < 1e-8, "rhs differ by {rel:.3e}");
        let (sa, sb) = (full.sample(t, &y), red.sample(t, &y));
        for (x, z) in [
            (sa.contact_force_norm, sb.contact_force_norm),
            (sa.friction_force_norm, sb.friction_force_norm),
            (sa.kinetic, sb.kinetic),
            (sa.strain, sb.strain),
            (sa.pair, sb.pair),
            (sa.master[1], sb.master[1]),
        ] {
            assert!((x - z).abs() <= 1e-12 * x.abs().max(1e-300), "{x} vs {z}");
        }
        // Roots.
        let m = full.num_roots();
        assert_eq!(m, red.num_roots());
        let (mut ga, mut gb) = (vec![0.0; m], vec![0.0; m]);
        full.roots(t, &y, &mut ga).unwrap();
        red.roots(t, &y, &mut gb).unwrap();
        for (x, z) in ga.iter().zip(&gb) {
            assert!((x - z).abs() <= 1e-12 * inf_norm(&ga));
        }
        // Newton solves of the same matrix.
        let gamma = 1e-5;
        full.newton_setup(t, &y, &a, false, gamma).unwrap();
        red.newton_setup(t, &y, &b, false, gamma).unwrap();
        let r: Vec<f64> = (0..d).map(|_| common::uniform(&mut rng)).collect();
        let (mut za, mut zb) = (vec![0.0; d], vec![0.0; d]);
        full.newton_solve(t, &y, &r, &mut za, gamma).unwrap();
        red.newton_solve(t, &y, &r, &mut zb, gamma).unwrap();
        let diff: Vec<f64> = za.iter().zip(&zb).map(|(x, y)| x - y).collect();
        let rel = inf_norm(&diff) / inf_norm(&za);
        println!("Φ = I: Newton solve relative difference {rel:.2e}");
        assert!(rel < 1e-8, "Newton solves differ by {rel:.3e}");
    }
}

/// The friction bar ROM (TVD basis, default options) for 0.02 s with Newton and friction: the
/// run completes and the energy balance `E_kin + E_strain + E_pair + D − W` closes.
#[test]
fn friction_bar_rom_runs_and_balances_energy() {
    let model = common::model("friction_bar");
    let basis = jointrom::reduction::build_basis(
        &model,
        jointrom::reduction::BasisKind::Tvd,
        &jointrom::reduction::BasisOptions::default(),
    )
    .unwrap();
    let rom = ReducedSystem::new(&model, basis.phi).unwrap();
    for (atol, tol) in [(1e-6, 1e-3), (1e-8, 2e-5)] {
        let opts = TransientOptions {
            ode: OdeOptions {
                atol,
                ..OdeOptions::default()
            },
            end_time: Some(0.02),
            ..TransientOptions::default()
        };
        let res = run(rom.clone(), &Scene::of(&model), &opts).unwrap();
        let c = &res.curves;
        assert_eq!(c.t.len(), 201);
        assert!((c.t[200] - 0.02).abs() < 1e-15);
        let w_max = c.external_work.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let balance = c.balance();
        let worst = balance.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let d_end = c.dissipated[200];
        println!(
            "ROM r = {}, atol {atol:e}: {} steps, {} rhs, {} Newton iterations, {} conv. failures, \
             {} error-test failures, {} setups; wall {:.3} s, cpu {:.2} s; uy(0.02) = {:.6} mm, \
             ‖f_c‖ = {:.4} N, ‖f_R‖ = {:.4} N, W = {:.6e}, D = {:.6e} N·mm, max |balance| = \
             {worst:.3e} N·mm ({:.2e} of max W)",
            rom.dim(),
            res.stats.steps,
            res.stats.rhs_evals,
            res.stats.nonlinear_iterations,
            res.stats.nonlinear_conv_failures,
            res.stats.error_test_failures,
            res.stats.linear_setups,
            res.wall_s,
            res.cpu_s,
            c.master_uy[200],
            c.contact_force_norm[200],
            c.friction_force_norm[200],
            c.external_work[200],
            d_end,
            worst / w_max
        );
        assert!(
            worst <= tol * w_max,
            "energy balance {worst:.3e} > {tol:e} · {w_max:.3e}"
        );
        // The structure is pushed down (fy < 0) and friction dissipates.
        assert!(c.master_uy[200] < -0.5);
        assert!(d_end > 0.0 && d_end < 0.05 * w_max);
        // D is a CVODE state held to atol × energy_scale (N·mm); BDF2 on variable steps may
        // dip it by less than that, never by the size of a dissipation of the wrong sign.
        let d_tol = atol * opts.problem.energy_scale;
        let dip = c
            .dissipated
            .windows(2)
            .map(|p| p[0] - p[1])
            .fold(0.0f64, f64::max);
        assert!(dip <= d_tol, "D decreases by {dip:.3e} N·mm > {d_tol:.1e}");
    }
}

/// Bad options are errors naming the field, not panics.
#[test]
fn bad_transient_options_are_errors() {
    let model = common::model("friction_bar");
    let rom = ReducedSystem::new(&model, Mat::identity(model.dofs(), 12)).unwrap();
    let bad = [
        (
            TransientOptions {
                output_step: 0.0,
                ..TransientOptions::default()
            },
            "output_step",
        ),
        (
            TransientOptions {
                end_time: Some(f64::NAN),
                ..TransientOptions::default()
            },
            "end_time",
        ),
        (
            TransientOptions {
                problem: ProblemOptions {
                    tau: -1.0,
                    ..ProblemOptions::default()
                },
                ..TransientOptions::default()
            },
            "tau",
        ),
        (
            TransientOptions {
                problem: ProblemOptions {
                    slip_scale: 0.0,
                    ..ProblemOptions::default()
                },
                ..TransientOptions::default()
            },
            "slip_scale",
        ),
    ];
    for (opts, field) in bad {
        let err = run(rom.clone(), &Scene::of(&model), &opts)
            .err()
            .unwrap_or_else(|| panic!("{field}: accepted"));
        assert!(err.to_string().contains(field), "{field}: {err}");
    }
}

/// A pair block of `K_c` as the mechanical problem builds it (normal entry, symmetric
/// tangential 2 × 2, no coupling), N/mm.
fn pair_block(kn: f64, t: [f64; 3]) -> [f64; 9] {
    [kn, 0.0, 0.0, 0.0, t[0], t[1], 0.0, t[1], t[2]]
}

#[test]
fn reduced_newton_update_equals_a_refactorization() {
    let model = common::model("friction_bar");
    let mut rom = reduced_model(&model, 60);
    let (r, w) = (rom.dim(), rom.pairs());
    let gamma = 2e-5;
    let mut kc = vec![0.0; 9 * w];
    for z in (0..w).step_by(3) {
        let block = pair_block(1e4, [1e4, 0.0, 1e4]);
        kc[9 * z..9 * z + 9].copy_from_slice(&block);
    }
    rom.newton_factor(gamma, &kc).unwrap();
    // Close a pair, open one, let one slide (a sliding pair's symmetric tangent) and one
    // whose tangent is diagonal change: up- and downdates of rank 1 and 2.
    let changed = [1, 3, 6, 9];
    kc[9..18].copy_from_slice(&pair_block(1e4, [1e4, 0.0, 1e4]));
    kc[27..36].fill(0.0);
    kc[54..63].copy_from_slice(&pair_block(1e4, [2.5e3, -1.2e3, 0.8e3]));
    kc[81..90].copy_from_slice(&pair_block(1e4, [0.0, 0.0, 1e4]));
    assert!(rom.newton_update(&kc, &changed), "the update was declined");
    let x0: Vec<f64> = (0..r).map(|i| ((i * 7 + 3) % 11) as f64 - 5.0).collect();
    let mut updated = x0.clone();
    rom.newton_solve_in_place(&mut updated);
    let mut fresh = reduced_model(&model, 60);
    fresh.newton_factor(gamma, &kc).unwrap();
    let mut refactored = x0;
    fresh.newton_solve_in_place(&mut refactored);
    let diff = updated
        .iter()
        .zip(&refactored)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    let scale = refactored.iter().map(|v| v.abs()).fold(0.0, f64::max);
    assert!(
        diff <= 1e-10 * scale,
        "updated and refactored solves differ by {diff:.2e} (scale {scale:.2e})"
    );
    // A block that couples the normal and tangential rows is left to a refactorization.
    let mut coupled = kc.clone();
    coupled[9 * 12 + 1] = 1.0;
    coupled[9 * 12 + 3] = 1.0;
    assert!(!rom.newton_update(&coupled, &[12]));
    // A change of higher rank than a factorization is worth (> r/6 columns) is declined.
    let mut many = kc.clone();
    // Each of these blocks changes by rank 3.
    let closing: Vec<usize> = (0..w).filter(|z| z % 3 == 1).take(r / 18 + 1).collect();
    for &z in &closing {
        many[9 * z..9 * z + 9].copy_from_slice(&pair_block(2e4, [2e4, 5e3, 3e4]));
    }
    assert!(!rom.newton_update(&many, &closing));
}

/// The Newton factor of a reduced model in its eigenbasis (diagonal plus the joint's low-rank
/// term, by Woodbury) solves the same system as the dense factor of the same basis rotated
/// out of its eigenbasis (same span, `K̃` full): for a stuck pair, a sliding pair (a rank-two
/// symmetric tangent) and no pair at all.
#[test]
fn modal_newton_factor_solves_like_the_dense_one() {
    let model = common::model("friction_bar");
    let phi = jointrom::reduction::build_basis(
        &model,
        jointrom::reduction::BasisKind::Tvd,
        &jointrom::reduction::BasisOptions::default(),
    )
    .unwrap()
    .phi;
    let (phi, _) = jointrom::reduction::modal_rotation(&model, phi).unwrap();
    let r = phi.ncols();
    // An orthogonal Q (Householder reflection I − 2 v vᵀ / vᵀv): Φ Q is M-orthonormal with the
    // same span, and Φ Q z' = Φ z for z = Q z'.
    let mut rng = common::rng(0x9e37_79b9_7f4a_7c15);
    let v: Vec<f64> = (0..r).map(|_| common::uniform(&mut rng)).collect();
    let vv: f64 = v.iter().map(|x| x * x).sum();
    let q = Mat::from_fn(r, r, |i, j| {
        f64::from(u8::from(i == j)) - 2.0 * v[i] * v[j] / vv
    });
    let mut modal = ReducedSystem::new(&model, phi.clone()).unwrap();
    let mut dense = ReducedSystem::new(&model, &phi * &q).unwrap();
    assert!(modal.modal_newton(), "an eigenbasis takes the modal factor");
    assert!(!dense.modal_newton(), "a rotated basis is factored densely");
    let w = modal.pairs();
    let (k_n, k_t) = (
        model.contact.normal_stiffness,
        model.contact.stick_stiffness,
    );
    let mut kc = vec![0.0; 9 * w];
    kc[..9].copy_from_slice(&[k_n, 0.0, 0.0, 0.0, k_t, 0.0, 0.0, 0.0, k_t]);
    let (u, s) = ([0.2, 0.9, -0.4], [0.0, 0.3, 0.95]);
    for i in 0..3 {
        for j in 0..3 {
            kc[9 * (w / 2) + 3 * i + j] = k_n * u[i] * u[j] + 0.3 * k_t * s[i] * s[j];
        }
    }
    for (blocks, what) in [
        (kc, "a stuck and a sliding pair"),
        (vec![0.0; 9 * w], "none"),
    ] {
        for gamma in [1e-6, 1e-4] {
            let b: Vec<f64> = (0..r).map(|_| common::uniform(&mut rng)).collect();
            modal.newton_factor(gamma, &blocks).unwrap();
            let mut z = b.clone();
            modal.newton_solve_in_place(&mut z);
            // Qᵀ b = Q b (Q symmetric); z = Q z'.
            let qb: Vec<f64> = (0..r)
                .map(|i| (0..r).map(|j| q[(i, j)] * b[j]).sum())
                .collect();
            dense.newton_factor(gamma, &blocks).unwrap();
            let mut zq = qb;
            dense.newton_solve_in_place(&mut zq);
            let back: Vec<f64> = (0..r)
                .map(|i| (0..r).map(|j| q[(i, j)] * zq[j]).sum())
                .collect();
            let diff: Vec<f64> = z.iter().zip(&back).map(|(a, b)| a - b).collect();
            let rel = inf_norm(&diff) / inf_norm(&z);
            assert!(
                rel < 1e-9,
                "{what}, γ = {gamma:e}: relative difference {rel:.2e}"
            );
        }
    }
}
