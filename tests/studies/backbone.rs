//! Backbones (`jointrom::studies::backbone`): the ring-down and extraction against closed forms
//! on a single-DOF Jenkins element (a spring in parallel with a stick spring and Coulomb slider,
//! pressed by a constant normal preload), a linear oscillator (friction off), homogeneity
//! without preload, and the friction bar's reduced model under its static load.

use std::f64::consts::PI;

use jointrom::case::ContactSpec;
use jointrom::integrate::TransientOptions;
use jointrom::rom::ModelSpec;
use jointrom::studies::backbone::{
    self, ring_down, BackboneOptions, Equilibrium, LinearMode, RingDown,
};
use jointrom::system::{Scene, SecondOrderSystem};
use jointrom::{Error, Model};

/// Two DOF: x (tangential, mass `m`, spring `k`) and y (normal, mass `m_y`, spring `k_y`), one
/// pair whose gap is y and whose tangential slip t1 is x. The master is (x, y).
#[derive(Clone)]
struct Jenkins {
    m: f64,
    k: f64,
    m_y: f64,
    k_y: f64,
    /// The Newton matrix's inverse, 2×2 row-major.
    inv: [f64; 4],
}

/// `B` (3 × 2): normal = y, t1 = x, t2 = 0.
const B: [[f64; 2]; 3] = [[0.0, 1.0], [1.0, 0.0], [0.0, 0.0]];

impl SecondOrderSystem for Jenkins {
    fn dim(&self) -> usize {
        2
    }
    fn pairs(&self) -> usize {
        1
    }
    fn mul_k_into(&self, q: &[f64], out: &mut [f64]) {
        out[0] = self.k * q[0];
        out[1] = self.k_y * q[1];
    }
    fn mul_m_into(&self, x: &[f64], out: &mut [f64]) {
        out[0] = self.m * x[0];
        out[1] = self.m_y * x[1];
    }
    fn solve_m_in_place(&mut self, x: &mut [f64]) {
        x[0] /= self.m;
        x[1] /= self.m_y;
    }
    fn load_into(&self, _t: f64, out: &mut [f64]) {
        out.iter_mut().for_each(|v| *v = 0.0);
    }
    fn master_load_into(&self, f: &[f64; 6], out: &mut [f64]) {
        out[0] = f[0];
        out[1] = f[1];
    }
    fn joint_apply_into(&self, q: &[f64], out: &mut [f64]) {
        for (o, row) in out.iter_mut().zip(B) {
            *o = row[0] * q[0] + row[1] * q[1];
        }
    }
    fn joint_transpose_add(&self, p: &[f64], out: &mut [f64]) {
        for (pi, row) in p.iter().zip(B) {
            out[0] += row[0] * pi;
            out[1] += row[1] * pi;
        }
    }
    fn newton_factor(&mut self, gamma: f64, kc: &[f64]) -> Result<(), Error> {
        let g2 = gamma * gamma;
        let mut a = [self.m + g2 * self.k, 0.0, 0.0, self.m_y + g2 * self.k_y];
        for i in 0..2 {
            for j in 0..2 {
                let mut s = 0.0;
                for r in 0..3 {
                    for c in 0..3 {
                        s += B[r][i] * kc[3 * r + c] * B[c][j];
                    }
                }
                a[2 * i + j] += g2 * s;
            }
        }
        let det = a[0] * a[3] - a[1] * a[2];
        self.inv = [a[3] / det, -a[1] / det, -a[2] / det, a[0] / det];
        Ok(())
    }
    fn newton_solve_in_place(&mut self, x: &mut [f64]) {
        let (x0, x1) = (x[0], x[1]);
        x[0] = self.inv[0] * x0 + self.inv[1] * x1;
        x[1] = self.inv[2] * x0 + self.inv[3] * x1;
    }
    fn master_displacement(&self, q: &[f64]) -> [f64; 6] {
        [q[0], q[1], 0.0, 0.0, 0.0, 0.0]
    }
}

/// The element's parameters: m = 1e-3 t, k = 2e4 N/mm in parallel with the Jenkins element
/// k_t = 1e4 N/mm, μ = 0.25; the normal DOF (1e-3 t, k_y = k_n = 1e4 N/mm) pressed by 80 N,
/// so |p_n| = 40 N, F_s = μ|p_n| = 10 N and the stick radius c = F_s / k_t = 1e-3 mm.
const M: f64 = 1e-3;
const K: f64 = 2e4;
const K_T: f64 = 1e4;
const MU: f64 = 0.25;
const K_N: f64 = 1e4;
const PRESS: f64 = 80.0;

fn system() -> Jenkins {
    Jenkins {
        m: M,
        k: K,
        m_y: M,
        k_y: K_N,
        inv: [0.0; 4],
    }
}

fn scene() -> Scene {
    Scene {
        contact: ContactSpec::per_pair(K_N, MU, K_T),
        end_time: 1.0,
    }
}

/// The friction force limit F_s (N) and the stick radius c (mm) at the preload.
fn slider() -> (f64, f64) {
    let p_n = K_N * PRESS / (K_N + K_N);
    (MU * p_n, MU * p_n / K_T)
}

/// The equilibrium under the normal preload `press` (N) and the tangential mode `shape`
/// (x, y) at the linearised frequency `f_lin` (Hz).
fn setup(press: f64, shape: [f64; 2], f_lin: f64) -> (Equilibrium, LinearMode) {
    let sys = system();
    let y = -press / (K_N + K_N);
    let eq = Equilibrium::at(&sys, vec![0.0, y], [0.0, -press, 0.0, 0.0, 0.0, 0.0]);
    let mass_shape = vec![M * shape[0], M * shape[1]];
    let mode = LinearMode {
        number: 1,
        frequency_hz: f_lin,
        modal_mass: shape[0] * mass_shape[0] + shape[1] * mass_shape[1],
        master: [shape[0], shape[1], 0.0, 0.0, 0.0, 0.0],
        mass_shape,
        shape: shape.to_vec(),
    };
    (eq, mode)
}

fn options(amplitudes: &[f64], friction: bool) -> BackboneOptions {
    let mut transient = TransientOptions::default();
    transient.problem.friction = friction;
    // The extraction is checked against closed forms to 1e-4 in frequency: at a tolerance where
    // BDF2's phase error (1.4e-4 on this oscillator at the default atol 1e-6) is below that.
    transient.ode.atol = 1e-7;
    BackboneOptions {
        modes: vec![1],
        amplitudes: amplitudes.to_vec(),
        preload: 1.0,
        cycles: 3,
        transient,
    }
}

fn decay(press: f64, shape: [f64; 2], f_lin: f64, a: f64, friction: bool) -> RingDown {
    let (eq, mode) = setup(press, shape, f_lin);
    let r = ring_down(
        || Ok(system()),
        &scene(),
        &eq,
        &mode,
        a,
        &options(&[a], friction),
    )
    .unwrap();
    assert!(r.status.finished() && r.energy_ok, "{r:?}");
    assert!(r.cycles.len() >= 5, "{} cycles", r.cycles.len());
    r
}

/// The first-harmonic (in-phase) stiffness of the steady Masing loop of a Jenkins element
/// (k_t, F_s) at amplitude `a` (mm): `(1/πa) ∫₀^{2π} f(θ) cos θ dθ` with x = a cos θ and the loop's
/// branches `f = max(F_s − k_t (a − x), −F_s)` descending, `min(−F_s + k_t (x + a), F_s)`
/// ascending, by the midpoint rule on 20 000 points.
fn masing_first_harmonic(a: f64, f_s: f64) -> f64 {
    let n = 20_000;
    let h = 2.0 * PI / n as f64;
    let mut s = 0.0;
    for i in 0..n {
        let th = (i as f64 + 0.5) * h;
        let x = a * th.cos();
        let f = if th < PI {
            (f_s - K_T * (a - x)).max(-f_s)
        } else {
            (-f_s + K_T * (x + a)).min(f_s)
        };
        s += f * th.cos() * h;
    }
    s / (PI * a)
}

#[test]
fn jenkins_element_below_the_stick_radius_is_the_linearised_oscillator() {
    let (_, c) = slider();
    let f_lin = ((K + K_T) / M).sqrt() / (2.0 * PI);
    let r = decay(PRESS, [1.0, 0.0], f_lin, 0.5 * c, true);
    for x in &r.cycles {
        assert!(
            (x.frequency_hz / f_lin - 1.0).abs() < 1e-4,
            "{x:?} vs {f_lin}"
        );
        assert!(x.damping_ratio.abs() < 1e-6, "{x:?}");
        assert!((x.modal_amplitude / (0.5 * c) - 1.0).abs() < 1e-4, "{x:?}");
    }
}

#[test]
fn jenkins_element_dissipates_masings_loop_and_softens_like_its_first_harmonic() {
    let (f_s, c) = slider();
    let f_lin = ((K + K_T) / M).sqrt() / (2.0 * PI);
    let mut last_f = f_lin;
    for ratio in [2.0, 5.0, 20.0] {
        let r = decay(PRESS, [1.0, 0.0], f_lin, ratio * c, true);
        for x in &r.cycles {
            let a = x.modal_amplitude;
            // Masing: a cycle between turning points ±a dissipates 4 F_s (a − c).
            let masing = 4.0 * f_s * (a - c);
            assert!(
                (x.dissipated / masing - 1.0).abs() < 0.02,
                "A/c = {ratio}: ΔD {} vs Masing {masing}",
                x.dissipated
            );
            let k_eq = K + masing_first_harmonic(a, f_s);
            let f_hb = (k_eq / M).sqrt() / (2.0 * PI);
            assert!(
                (x.frequency_hz / f_hb - 1.0).abs() < 0.01,
                "A/c = {ratio}: f {} vs first harmonic {f_hb}",
                x.frequency_hz
            );
            // ζ = ΔD / (2π k_eq a²) with the loop's own stiffness. (The secant stiffness
            // k + F_s/a, the cruder closed form, is off by up to ~1 % here: a cycle of a fast
            // decay averages over a shrinking loop.)
            let zeta = masing / (2.0 * PI * k_eq * a * a);
            assert!(
                (x.damping_ratio / zeta - 1.0).abs() < 0.03,
                "A/c = {ratio}: ζ {} vs {zeta}",
                x.damping_ratio
            );
        }
        let f0 = r.cycles[0].frequency_hz;
        assert!(f0 < last_f, "softening: {f0} after {last_f}");
        last_f = f0;
    }
}

#[test]
fn linear_oscillator_has_constant_frequency_and_no_damping() {
    let f_lin = (K / M).sqrt() / (2.0 * PI);
    for a in [1e-4, 1.0, 1e3] {
        let r = decay(PRESS, [1.0, 0.0], f_lin, a, false);
        for x in &r.cycles {
            assert!(
                (x.frequency_hz / f_lin - 1.0).abs() < 1e-4,
                "A = {a}: {x:?}"
            );
            assert!(x.damping_ratio.abs() < 1e-9, "A = {a}: {x:?}");
        }
    }
}

#[test]
fn without_preload_the_backbone_is_flat() {
    // The shape moves the normal DOF too: the joint opens and closes every cycle, and its
    // friction limit follows the vibration's own pressure — nonlinear, but homogeneous.
    let f_glued = ((K + K_T) / M).sqrt() / (2.0 * PI);
    let runs: Vec<RingDown> = [1e-3, 1.0, 1e3]
        .iter()
        .map(|&a| decay(0.0, [1.0, 0.5], f_glued, a, true))
        .collect();
    let base = &runs[0].cycles[0];
    assert!(base.damping_ratio > 1e-3, "the decay dissipates: {base:?}");
    for r in &runs[1..] {
        let x = &r.cycles[0];
        assert!(
            (x.frequency_hz / base.frequency_hz - 1.0).abs() < 1e-4,
            "A = {}: {} vs {}",
            r.amplitude,
            x.frequency_hz,
            base.frequency_hz
        );
        assert!(
            (x.damping_ratio / base.damping_ratio - 1.0).abs() < 1e-3,
            "A = {}: ζ {} vs {}",
            r.amplitude,
            x.damping_ratio,
            base.damping_ratio
        );
    }
}

#[test]
fn friction_bar_reduced_model_under_its_static_load_sticks_at_small_amplitudes() {
    let model = Model::from_case_name("friction_bar").unwrap();
    let spec = ModelSpec::Basis {
        kind: jointrom::reduction::BasisKind::Tvd,
        g: None,
        nu: 10,
    };
    let mut opts = options(&[1e-6, 1e-3], true);
    opts.modes = vec![1];
    opts.cycles = 1;
    let b = backbone::compute(&model, &spec, &opts).unwrap();
    let m = &b.modes[0];
    let small = &m.ring_downs[0].cycles[0];
    assert!(
        (small.frequency_hz / m.linear_frequency_hz - 1.0).abs() < 1e-3,
        "{small:?} vs {}",
        m.linear_frequency_hz
    );
    assert!(small.damping_ratio.abs() < 1e-6, "{small:?}");
    let large = &m.ring_downs[1].cycles[0];
    assert!(large.frequency_hz < 0.995 * small.frequency_hz, "{large:?}");
    assert!(large.damping_ratio > 1e-4, "{large:?}");
}

/// The friction bar and its a-priori TVD basis (ν = 10), which the backbone's model enriches.
fn friction_bar_tvd_basis() -> (Model, faer::Mat<f64>) {
    let model = Model::from_case_name("friction_bar").unwrap();
    let opts = jointrom::reduction::BasisOptions {
        nu: 10,
        ..Default::default()
    };
    let phi = jointrom::reduction::build_basis(&model, jointrom::reduction::BasisKind::Tvd, &opts)
        .unwrap()
        .phi;
    (model, phi)
}

/// The backbone's model (a basis enriched with the full model's equilibrium, linearised modes and
/// the joint's attachment modes) linearises like the full model about the preloaded
/// equilibrium, with the same closed pairs; the a-priori TVD basis it is built on does not.
#[test]
fn friction_bar_backbone_model_linearises_like_the_full_model() {
    use jointrom::studies::backbone::{
        backbone_model, full_equilibrium, full_modes, reduced_equilibrium, reduced_modes,
    };
    let (model, phi) = friction_bar_tvd_basis();
    let full_eq = full_equilibrium(&model, 1.0).unwrap();
    let full: Vec<f64> = full_modes(&model, &full_eq, 3, true)
        .unwrap()
        .iter()
        .map(|m| m.frequency_hz)
        .collect();
    let plain = jointrom::system::ReducedSystem::new(&model, phi.clone()).unwrap();
    let plain_eq = reduced_equilibrium(&model, &plain, 1.0).unwrap();
    let plain_f = reduced_modes(&model, &plain, &plain_eq, 3, true).unwrap()[0].frequency_hz;
    assert!(plain_f > 1.01 * full[0], "{plain_f} vs {}", full[0]);
    let b = backbone_model(&model, &phi, 1.0, 3, true).unwrap();
    assert_eq!(b.full_frequencies_hz, full);
    assert!(b.rom.dim() > phi.ncols());
    let eq = reduced_equilibrium(&model, &b.rom, 1.0).unwrap();
    assert_eq!(eq.closed, full_eq.closed);
    let modes = reduced_modes(&model, &b.rom, &eq, 3, true).unwrap();
    for (m, f) in modes.iter().zip(&full) {
        assert!(
            (m.frequency_hz / f - 1.0).abs() < 1e-6,
            "mode {}: {} vs {f}",
            m.number,
            m.frequency_hz
        );
    }
}

/// A slipping ring-down of the backbone's model (the a-priori TVD basis enriched, its Newton
/// matrix factored in the eigenbasis as diagonal plus the joint's low-rank term) against the
/// full FE model's: the friction bar's mode 1 at 3.162e-4 mm under its static load, where the
/// least pressed closed pairs slip (full model: ζ = 6.7e-3), both at the default tolerances.
/// The backbone's targets: frequency within 0.5 %, damping ratio within 5 %.
#[test]
fn friction_bar_backbone_model_rings_down_like_the_full_model_where_the_joint_slips() {
    use jointrom::studies::backbone::{
        backbone_model, full_equilibrium, full_modes, reduced_equilibrium, reduced_modes,
    };
    use jointrom::system::FullSystem;
    let (model, phi) = friction_bar_tvd_basis();
    let b = backbone_model(&model, &phi, 1.0, 1, true).unwrap();
    assert!(
        b.rom.modal_newton(),
        "the backbone's model is in its eigenbasis"
    );
    let a = 3.162e-4;
    let mut bb = options(&[a], true);
    bb.cycles = 1;
    bb.transient.ode.atol = TransientOptions::default().ode.atol;
    let scene = Scene::of(&model);
    let eq = reduced_equilibrium(&model, &b.rom, 1.0).unwrap();
    let mode = &reduced_modes(&model, &b.rom, &eq, 1, true).unwrap()[0];
    let reduced = ring_down(|| Ok(b.rom.clone()), &scene, &eq, mode, a, &bb).unwrap();
    let full_eq = full_equilibrium(&model, 1.0).unwrap();
    let full_mode = &full_modes(&model, &full_eq, 1, true).unwrap()[0];
    let full = ring_down(
        || FullSystem::new(&model),
        &scene,
        &full_eq,
        full_mode,
        a,
        &bb,
    )
    .unwrap();
    let (r, f) = (reduced.first().unwrap(), full.first().unwrap());
    assert!(
        f.damping_ratio > 1e-3,
        "the full model's joint slips: {f:?}"
    );
    assert!(
        (r.frequency_hz / f.frequency_hz - 1.0).abs() < 5e-3,
        "{r:?} vs {f:?}"
    );
    assert!(
        (r.damping_ratio / f.damping_ratio - 1.0).abs() < 0.05,
        "ζ {} vs the full model's {}",
        r.damping_ratio,
        f.damping_ratio
    );
}

#[test]
fn bad_input_names_the_flag() {
    let model = Model::from_case_name("friction_bar").unwrap();
    let spec = ModelSpec::Basis {
        kind: jointrom::reduction::BasisKind::Tvd,
        g: None,
        nu: 10,
    };
    let err = |o: BackboneOptions| {
        backbone::compute(&model, &spec, &o)
            .unwrap_err()
            .to_string()
    };
    for a in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert!(err(options(&[a], true)).contains("--amplitudes"), "{a}");
    }
    let mut o = options(&[1e-6], true);
    o.modes = vec![0];
    assert!(err(o.clone()).contains("--modes"));
    o.modes = vec![500];
    let e = err(o);
    assert!(e.contains("--modes 500") && e.contains("only"), "{e}");
    assert!(backbone::log_range(1e-3, 1e-5, 3)
        .unwrap_err()
        .to_string()
        .contains("--range"));
    let r = backbone::log_range(1e-4, 1e-2, 3).unwrap();
    assert!((r[1] / 1e-3 - 1.0).abs() < 1e-12);
}

#[test]
fn an_initial_state_of_the_wrong_size_is_an_error_naming_its_block() {
    let (eq, _) = setup(PRESS, [1.0, 0.0], 100.0);
    let mut o = TransientOptions {
        end_time: Some(1e-3),
        constant_load: Some(eq.load),
        ..TransientOptions::default()
    };
    for (q, slip, what) in [
        (vec![0.0; 3], vec![0.0; 2], "q has 3 entries"),
        (vec![0.0; 2], vec![0.0; 1], "slip memory has 1 entries"),
        (vec![f64::NAN, 0.0], vec![0.0; 2], "q has 2 entries"),
    ] {
        o.start = Some(jointrom::integrate::InitialState {
            q,
            v: vec![0.0; 2],
            slip,
        });
        let e = jointrom::integrate::run(system(), &scene(), &o)
            .unwrap_err()
            .to_string();
        assert!(e.contains(what), "{e}");
    }
    // The right size runs, and the balance is counted from the start.
    o.start = Some(jointrom::integrate::InitialState {
        q: vec![1e-3, eq.q[1]],
        v: vec![0.0; 2],
        slip: eq.slip.clone(),
    });
    let r = jointrom::integrate::run(system(), &scene(), &o).unwrap();
    assert_eq!(r.curves.balance()[0], 0.0);
    assert!(r.curves.energy_check(o.energy_resolution()).ok);
}

#[test]
fn a_ring_down_whose_energy_balance_misses_is_named_with_its_amplitude() {
    // Friction off, integrated far too loosely: BDF2's numerical damping of the undamped
    // oscillator shows as a gap in the energy balance, which the ring-down reports and the
    // backbone's warning names with the amplitude's flag.
    let f_lin = (K / M).sqrt() / (2.0 * PI);
    let (eq, mode) = setup(PRESS, [1.0, 0.0], f_lin);
    let mut opts = options(&[1.0], false);
    opts.transient.ode.rtol = 1e-2;
    opts.transient.ode.atol = 1e-2;
    let r = ring_down(|| Ok(system()), &scene(), &eq, &mode, 1.0, &opts).unwrap();
    assert!(!r.energy_ok, "{r:?}");
    let w = r.warnings(1, opts.cycles).join("\n");
    assert!(
        w.contains("--amplitudes 1") && w.contains("energy balance"),
        "{w}"
    );
    // The same run at the tests' tolerance (`options`) balances and warns of nothing.
    let ok = decay(PRESS, [1.0, 0.0], f_lin, 1.0, false);
    assert!(ok.warnings(1, 3).is_empty(), "{:?}", ok.warnings(1, 3));
}

/// The command's ring-downs run a decade below the transient's absolute tolerance unless told
/// otherwise: the default is `--atol 1e-7` (the same steps), not the transient's 1e-6.
#[test]
fn backbone_command_defaults_to_a_decade_below_the_transients_atol() {
    let steps = |extra: &[&str]| {
        let mut args = vec![
            "backbone",
            "friction_bar",
            "--model",
            "tvd",
            "--modes",
            "1",
            "--amplitudes",
            "3.162e-4",
            "--cycles",
            "1",
            "--preload",
            "1",
            "--json",
        ];
        args.extend_from_slice(extra);
        let v = crate::common::jointrom_json(args);
        v["backbone"]["modes"][0]["ring_downs"][0]["steps"].clone()
    };
    let default = steps(&[]);
    assert!(default.as_u64().is_some_and(|s| s > 0), "{default}");
    assert_eq!(default, steps(&["--atol", "1e-7"]));
    assert_ne!(default, steps(&["--atol", "1e-6"]));
}
