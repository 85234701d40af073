//! Backbones: the amplitude-dependent frequency and damping ratio of a jointed structure's
//! modes, from free decays (ring-downs) of the reduced or the full FE model.
//!
//! For each mode k and amplitude A the model starts from its preloaded equilibrium displaced by
//! A times the mode's shape, at rest, with the equilibrium's slip memory ([`linear`]), and rings
//! down under the constant preload with friction on — no other force. The modal coordinate
//! `a(t) = ψᵀM(q − q_eq) / ψᵀMψ` (mm; an M-orthogonal projection, which filters the other
//! linearised modes out of the motion), the master's motion along the mode's master direction
//! and the dissipated energy are sampled 64 times per linearised period, and each cycle's
//! frequency, amplitude and equivalent viscous damping ratio are extracted from them
//! ([`extract`]).
//!
//! ## Tolerances follow the amplitude
//!
//! With no preload, zero initial gaps, penalty contact and a Coulomb limit μ|p_n|, every force
//! scales with the displacement and so does the viscoplastic slip law; the free decay of a
//! scaled shape is the same motion scaled and the backbone is flat. For the computed decay to
//! keep that property the integrator's absolute tolerances must scale too: a ring-down of
//! amplitude A runs with `atol = rel_atol · A` (mm) and the active-set refresh margin scaled by
//! A/(1 mm). Under a preload the stick radius `μ|p_n|/k_t` is fixed and small amplitudes stick:
//! the tolerance then only resolves the motion better than it needs.
//!
//! Two of a transient's tolerances are stated for a load history, not for a vibration about a
//! preloaded equilibrium, and would set a ring-down's step instead of its motion:
//!
//! - **The energy states.** W and D are integrated states in the error test. Under a constant
//!   preload f the external work oscillates with the vibration, `W = f·ψ_master A` in amplitude
//!   — linear in A, where the vibration's energy `E = ½ m_k ω_k² A²` is quadratic. With the
//!   transient's energy unit scaled like the displacements (a tolerance ∝ A²) W was held to
//!   1e-10 of itself, and it alone set the step of a ring-down where the joint sticks (a
//!   linear oscillation: 1 100 steps per period). A ring-down's energy unit is therefore
//!   `|f·ψ_master| + ½ m_k ω_k² A` per mm of amplitude (`ring_down_energy_unit`): both
//!   energies resolved to `atol` relative to the work and energy of the vibration itself.
//! - **The velocities.** A transient's velocities are held to `atol · 1e3 1/s`, so every mode
//!   above 160 Hz is resolved in velocity, i.e. in displacement to `atol · 1e3/ω`. A slipping
//!   joint excites the model's stiff local modes (the pairs' attachment columns reach 10⁶ rad/s)
//!   at every stick–slip switch, and resolving them to that tighter bound took 10⁵–10⁶ steps per
//!   ring-down. A ring-down about a preloaded equilibrium holds every mode below
//!   [`RING_DOWN_VELOCITY_SCALE`] = 1e6 1/s by its displacement alone (a larger scale changes
//!   neither the steps nor the damping). BDF2 then damps the local modes above the step's
//!   reach numerically, energy the balance misses: under a preload a few 1e-9 of the run's
//!   energy. Without a preload the joint opens and closes every cycle, the impacts put much of
//!   the energy into those modes, and the balance missed 38 % (7 % with the transient's
//!   scale): there the transient's velocity scale is kept.
//!
//! The damping ratio of a slipping joint converges slowly with the tolerance: the stick–slip
//! switches excite the joint's high-frequency dynamics, whose resolution adds dissipation
//! (about +1 % per decade of atol between 1e-6 and 1e-8 on the friction bar, up to +5 % per
//! decade in a gross slip of the multilayer sheet, where a model with the full model's stiff
//! local modes converges more slowly than a reduced one; the validation docs compare models at
//! one tolerance, and at a tighter one where the reference has not converged). The ring-downs
//! therefore default to an absolute tolerance a decade below the transient's
//! ([`DEFAULT_ATOL`]).
//!
//! ## Where a backbone stops meaning something
//!
//! Each decay is checked: its energy balance ([`crate::integrate::Curves::energy_check`]: a miss
//! names `--amplitudes`), whether the joint's contact force vanished at some output (the joint
//! opened fully: the equilibrium's contact state, and with it mode k, no longer describes the
//! motion), and whether the decay gave a cycle at all. Modes that couple (close linearised
//! frequencies, or a slipping joint transferring energy into another mode) show as a modal
//! coordinate that stops decaying like one mode: the extracted frequency then drifts from cycle
//! to cycle. Both are reported, not hidden.

pub mod basis;
pub mod extract;
pub mod linear;

use std::time::Instant;

use serde::Serialize;

use crate::error::{Error, FlagError, RomError, StudyError};
use crate::integrate::{integrate, InitialState, RunStatus, TransientOptions};
use crate::model::Model;
use crate::rom::{build_rom, ModelSpec};
use crate::system::{FullSystem, Scene, SecondOrderSystem};

pub use basis::{backbone_model, BackboneModel};
pub use extract::{cycles, Cycle, Samples};
pub use linear::{
    full_equilibrium, full_modes, reduced_equilibrium, reduced_modes, Equilibrium, LinearMode,
};

/// Outputs per linearised period of a ring-down.
pub const SAMPLES_PER_PERIOD: usize = 64;

/// The amplitude the tolerances are stated at, mm (`rel_atol` = atol at 1 mm).
const REFERENCE_AMPLITUDE: f64 = 1.0;

/// The ring-downs' default absolute tolerance at 1 mm of amplitude, mm: a decade below the
/// transient's, because a slipping joint's damping ratio converges slowly with the tolerance
/// (module docs): at 1e-6 the full model's ζ in the multilayer sheet's gross slip is still 4.9 %
/// from its 1e-7 value, at 1e-7 1.8 % from its 1e-8 value, so 1e-7 resolves ζ to a few per cent
/// at about twice the steps.
pub const DEFAULT_ATOL: f64 = 1e-7;

/// What a backbone computes.
#[derive(Clone, Debug)]
pub struct BackboneOptions {
    /// Mode numbers (1 = lowest).
    pub modes: Vec<usize>,
    /// Amplitudes A of the initial modal displacement, mm of the largest nodal translation
    /// (finite, > 0).
    pub amplitudes: Vec<f64>,
    /// Preload factor S on the case's master load (0: none).
    pub preload: f64,
    /// Cycles of each ring-down (≥ 1): the decay runs in chunks of 1.5 × (cycles + ½)
    /// linearised periods until it has them ([`MAX_CHUNKS`] at most).
    pub cycles: usize,
    /// The run's options: integrator, friction, τ, wall-clock budget (end time, output step,
    /// start and load are set per ring-down; `ode.atol` is taken relative to 1 mm of
    /// amplitude, see the module docs).
    pub transient: TransientOptions,
}

impl BackboneOptions {
    /// The checked options.
    ///
    /// # Errors
    /// No mode or a mode 0, no amplitude or one not finite and positive, a non-finite preload,
    /// no cycle — each naming its flag.
    pub fn check(&self) -> Result<(), Error> {
        if self.modes.is_empty() || self.modes.contains(&0) {
            return Err(FlagError::Value {
                flag: "modes",
                value: format!("{:?}", self.modes),
                need: "give mode numbers from 1 (the lowest), e.g. 1,2,3",
            }
            .into());
        }
        if self.amplitudes.is_empty() {
            return Err(FlagError::Value {
                flag: "amplitudes",
                value: "(none)".into(),
                need: "give one or more amplitudes in mm, or --range A_MIN A_MAX N",
            }
            .into());
        }
        for &a in &self.amplitudes {
            crate::integrate::positive_flag("amplitudes", a)?;
        }
        if !self.preload.is_finite() {
            return Err(FlagError::NotFinite {
                flag: "preload",
                value: self.preload,
            }
            .into());
        }
        if self.cycles == 0 {
            return Err(FlagError::AtLeast {
                flag: "cycles",
                min: 1,
            }
            .into());
        }
        Ok(())
    }
}

/// `n` amplitudes spaced logarithmically from `lo` to `hi` (mm).
///
/// # Errors
/// Bounds not finite and positive, `hi < lo`, `n` = 0 — naming `--range`.
pub fn log_range(lo: f64, hi: f64, n: usize) -> Result<Vec<f64>, Error> {
    crate::integrate::positive_flag("range", lo)?;
    crate::integrate::positive_flag("range", hi)?;
    if hi < lo || n == 0 || (n == 1 && hi != lo) {
        return Err(FlagError::Value {
            flag: "range",
            value: format!("{lo} {hi} {n}"),
            need: "A_MIN ≤ A_MAX (mm) and N ≥ 1 points (N = 1 needs A_MIN = A_MAX)",
        }
        .into());
    }
    Ok((0..n)
        .map(|i| {
            if n == 1 {
                lo
            } else {
                lo * (hi / lo).powf(i as f64 / (n - 1) as f64)
            }
        })
        .collect())
}

/// One ring-down: its amplitude, how it ran and its cycles.
#[derive(Clone, Debug, Serialize)]
pub struct RingDown {
    /// The initial amplitude A, mm.
    pub amplitude: f64,
    /// How the run ended.
    pub status: RunStatus,
    /// Simulated span, s.
    pub end_time: f64,
    /// Integrator steps.
    pub steps: u64,
    /// CPU time of the integration, s.
    pub cpu_s: f64,
    /// Wall time of the integration, s.
    pub wall_s: f64,
    /// Energy-balance residual relative to the run's energy scale, and whether it passed.
    pub energy_residual_ratio: f64,
    pub energy_ok: bool,
    /// The joint's contact force vanished at some output (the joint opened fully).
    pub joint_opened: bool,
    /// Energy dissipated over the run, N·mm.
    pub dissipated: f64,
    /// The extracted cycles.
    pub cycles: Vec<Cycle>,
}

impl RingDown {
    /// The first cycle (the one starting at the initial amplitude), if any.
    pub fn first(&self) -> Option<&Cycle> {
        self.cycles.first()
    }

    /// What a reader must know about one ring-down of mode `k` (module docs, *Where a backbone
    /// stops meaning something*).
    pub fn warnings(&self, k: usize, cycles: usize) -> Vec<String> {
        let r = self;
        let a = r.amplitude;
        let mut w = Vec::new();
        if !r.status.finished() {
            w.push(format!(
                "mode {k}, --amplitudes {a}: the ring-down stopped at t = {:.4e} s ({})",
                r.end_time, r.status
            ));
        }
        if !r.energy_ok {
            w.push(format!(
                "mode {k}, --amplitudes {a}: the energy balance misses by {:.2} % of the run's \
                 energy (> {} %): its frequency and damping cannot be trusted; use a smaller amplitude",
                100.0 * r.energy_residual_ratio,
                100.0 * crate::integrate::driver::ENERGY_BALANCE_TOLERANCE
            ));
        }
        if r.joint_opened {
            w.push(format!(
                "mode {k}, --amplitudes {a}: the joint opened fully during the decay: beyond the \
                 amplitudes where mode {k} of the preloaded joint describes the motion"
            ));
        }
        if r.cycles.is_empty() {
            w.push(format!(
                "mode {k}, --amplitudes {a}: the decay is too short to extract a frequency (no full \
                 cycle in {:.4e} s; --cycles {cycles})",
                r.end_time
            ));
        }
        w
    }
}

/// The backbone of one mode.
#[derive(Clone, Debug, Serialize)]
pub struct ModeBackbone {
    /// Mode number k.
    pub mode: usize,
    /// The linearised model's frequency, Hz.
    pub linear_frequency_hz: f64,
    /// With `--tolerance`: the full model's linearised frequency, Hz (the reference of
    /// `linear_frequency_hz`, which the enrichment makes equal to it up to rounding).
    pub full_linear_frequency_hz: Option<f64>,
    /// The master's displacement in the (1 mm) shape `[ux, uy, uz (mm), rx, ry, rz (rad)]`.
    pub shape_master: [f64; 6],
    /// `ψᵀMψ` of the 1 mm shape, t.
    pub modal_mass: f64,
    /// One ring-down per amplitude, in the order given.
    pub ring_downs: Vec<RingDown>,
}

/// A computed backbone.
#[derive(Clone, Debug, Serialize)]
pub struct Backbone {
    /// The model's name (`full`, a basis kind, `adaptive`).
    pub model: String,
    /// Its size: DOF of the full model, r of a reduced one.
    pub model_size: usize,
    /// With `--tolerance`: r of the tolerance model before the backbone's enrichment
    /// ([`basis`]), and the pairs whose attachment modes the enrichment added.
    pub tolerance_model_size: Option<usize>,
    pub attachment_pairs: Option<usize>,
    /// The preload factor S and its master load `[Fx, Fy, Fz (N), Mx, My, Mz (N·mm)]`.
    pub preload: f64,
    pub preload_load: [f64; 6],
    /// Closed pairs at the equilibrium (of all pairs).
    pub closed_pairs: usize,
    pub pairs: usize,
    /// The master's equilibrium displacement `[ux, uy, uz (mm), rx, ry, rz (rad)]`.
    pub equilibrium_master: [f64; 6],
    /// Friction on.
    pub friction: bool,
    /// Wall time of building the model, the equilibrium and the modes, s.
    pub setup_s: f64,
    /// CPU and wall time of all ring-downs, s.
    pub ring_down_cpu_s: f64,
    pub ring_down_wall_s: f64,
    /// The modes.
    pub modes: Vec<ModeBackbone>,
    /// What a reader must know (energy checks missed, joints opened, decays without cycles).
    pub warnings: Vec<String>,
}

/// Velocity tolerance per displacement tolerance of a ring-down, 1/s (module docs).
pub const RING_DOWN_VELOCITY_SCALE: f64 = 1e6;

/// The unit of a ring-down's energy states W and D, N·mm per mm of amplitude (module docs):
/// the preload's work per mm along the shape plus the vibration's energy per mm of amplitude,
/// `|f·ψ_master| + ½ m_k ω_k² A`, so that the energies are resolved to `atol` (at 1 mm)
/// relative to `|f·ψ| A + ½ m_k ω_k² A²`.
fn ring_down_energy_unit(eq: &Equilibrium, mode: &LinearMode, a: f64) -> f64 {
    let work: f64 = eq.load.iter().zip(&mode.master).map(|(f, m)| f * m).sum();
    let omega = 2.0 * std::f64::consts::PI * mode.frequency_hz;
    work.abs() * REFERENCE_AMPLITUDE + 0.5 * mode.modal_mass * omega * omega * a
}

/// The transient options of one ring-down of `mode` at amplitude `a` from `eq`.
fn ring_down_options(
    base: &TransientOptions,
    eq: &Equilibrium,
    mode: &LinearMode,
    a: f64,
    cycles: usize,
) -> TransientOptions {
    let period = 1.0 / mode.frequency_hz;
    let rel = a / REFERENCE_AMPLITUDE;
    let mut o = base.clone();
    o.ode.atol = base.ode.atol * rel;
    o.problem.energy_scale = ring_down_energy_unit(eq, mode, a);
    if eq.load.iter().any(|&f| f != 0.0) {
        o.problem.velocity_scale = RING_DOWN_VELOCITY_SCALE;
    }
    o.problem.refresh = base.problem.refresh.map(|m| m * rel);
    o.end_time = Some(1.5 * (cycles as f64 + 0.5) * period);
    o.output_step = period / SAMPLES_PER_PERIOD as f64;
    o.start = Some(InitialState {
        q: eq
            .q
            .iter()
            .zip(&mode.shape)
            .map(|(q, s)| q + a * s)
            .collect(),
        v: vec![0.0; eq.q.len()],
        slip: eq.slip.clone(),
    });
    o.constant_load = Some(eq.load);
    o
}

/// Chunks a ring-down may take before it gives up on finding its cycles: the decay runs in
/// chunks of 1.5 × (cycles + ½) linearised periods, each continuing from the last one's state,
/// until `cycles` cycles are found — a softened mode takes longer than its linearisation says.
pub const MAX_CHUNKS: usize = 8;

/// One ring-down (module docs) of the systems `make` builds (one per chunk).
pub fn ring_down<S: SecondOrderSystem>(
    mut make: impl FnMut() -> Result<S, Error>,
    scene: &Scene,
    eq: &Equilibrium,
    mode: &LinearMode,
    amplitude: f64,
    opts: &BackboneOptions,
) -> Result<RingDown, Error> {
    let mut o = ring_down_options(&opts.transient, eq, mode, amplitude, opts.cycles);
    let chunk = o.end_time.unwrap_or(scene.end_time);
    let first = make()?;
    if let Some(start) = &mut o.start {
        start.slip = admissible_slip(&first, &scene.contact, &start.q, &eq.slip);
    }
    let master = master_functional(&first, &mode.master);
    let n = first.dim();
    let mut sys = Some(first);
    let mut samples = Samples::default();
    let preload = eq.load.iter().any(|&v| v != 0.0);
    let mut out = RingDown {
        amplitude,
        status: RunStatus::Finished,
        end_time: 0.0,
        steps: 0,
        cpu_s: 0.0,
        wall_s: 0.0,
        energy_residual_ratio: 0.0,
        energy_ok: true,
        joint_opened: false,
        dissipated: 0.0,
        cycles: Vec::new(),
    };
    let want = 2 * opts.cycles - 1;
    for _ in 0..MAX_CHUNKS {
        let system = match sys.take() {
            Some(s) => s,
            None => make()?,
        };
        let (t0, d0) = (out.end_time, out.dissipated);
        let skip = usize::from(!samples.t.is_empty());
        let mut k = 0usize;
        let run = integrate(system, scene, &o, |t, q| {
            k += 1;
            if k <= skip {
                return;
            }
            let dq = |w: &[f64]| -> f64 {
                q.iter()
                    .zip(&eq.q)
                    .zip(w)
                    .map(|((q, e), w)| (q - e) * w)
                    .sum()
            };
            samples.t.push(t0 + t);
            samples.modal.push(dq(&mode.mass_shape) / mode.modal_mass);
            if let Some(g) = &master {
                samples.master.push(dq(g));
            }
        });
        samples
            .dissipated
            .extend(run.curves.dissipated.iter().skip(skip).map(|d| d0 + d));
        let check = run.curves.energy_check(o.energy_resolution());
        out.status = run.status.clone();
        out.end_time = t0 + run.t_reached;
        out.steps += run.stats.steps;
        out.cpu_s += run.cpu_s;
        out.wall_s += run.wall_s;
        out.energy_residual_ratio = out.energy_residual_ratio.max(check.residual_ratio);
        out.energy_ok &= check.ok;
        out.joint_opened |= preload && run.curves.contact_force_norm.contains(&0.0);
        out.dissipated = d0 + run.curves.dissipated.last().copied().unwrap_or(0.0);
        let m = samples.dissipated.len().min(samples.t.len());
        samples.t.truncate(m);
        samples.modal.truncate(m);
        samples.dissipated.truncate(m);
        if master.is_some() {
            samples.master.truncate(m);
        }
        out.cycles = cycles(&samples, 1.0 / mode.frequency_hz, mode.modal_mass);
        if !run.status.finished() || out.cycles.len() >= want {
            break;
        }
        // Continue from where the chunk ended: its state, its slip memory (in mm).
        let y = &run.final_state;
        let slip_scale = o.problem.slip_scale;
        let ns = if o.problem.friction { eq.slip.len() } else { 0 };
        o.start = Some(InitialState {
            q: y[..n].to_vec(),
            v: y[n..2 * n].to_vec(),
            slip: y[2 * n..2 * n + ns]
                .iter()
                .map(|s| s * slip_scale)
                .collect(),
        });
        o.end_time = Some(chunk);
    }
    out.cycles.truncate(want);
    Ok(out)
}

/// The slip memory of a ring-down's initial state: the equilibrium's `slip`, except where the
/// displaced state `q` would stretch a pair's stick spring beyond its cone (`|u_t − s| > c =
/// μ|p_n|/k_t`; an open pair has c = 0) — there the memory is returned to the cone,
/// `s = u_t − c e/|e|`, the state a monotonic loading from the equilibrium to `q` leaves
/// (Masing's virgin curve). Without this the law would dissipate the excess stretch within τ
/// at the start, energy the structure never stored.
fn admissible_slip<S: SecondOrderSystem>(
    sys: &S,
    contact: &crate::case::ContactSpec,
    q: &[f64],
    slip: &[f64],
) -> Vec<f64> {
    let w = sys.pairs();
    let mut u = vec![0.0; 3 * w];
    sys.joint_apply_into(q, &mut u);
    let mut out = slip.to_vec();
    for k in 0..w.min(slip.len() / 2) {
        let g = u[3 * k];
        let c = contact.friction_coefficient * contact.normal_stiffness * (-g).max(0.0)
            / contact.stick_stiffness;
        let e = [u[3 * k + 1] - slip[2 * k], u[3 * k + 2] - slip[2 * k + 1]];
        let norm = e[0].hypot(e[1]);
        if norm > c {
            out[2 * k] = u[3 * k + 1] - c * e[0] / norm;
            out[2 * k + 1] = u[3 * k + 2] - c * e[1] / norm;
        }
    }
    out
}

/// The linear functional `g` with `gᵀ q` = the master's translation along the unit direction of
/// the shape's master translation `shape_master[..3]`, or `None` when the shape does not move
/// the master (a translation below 1e-6 mm per mm of amplitude). The master displacement is
/// linear in q, so g is probed with unit vectors (O(1) each for the full model, O(r) for a
/// reduced one).
fn master_functional<S: SecondOrderSystem>(sys: &S, shape_master: &[f64; 6]) -> Option<Vec<f64>> {
    let m = shape_master;
    let norm = (m[0] * m[0] + m[1] * m[1] + m[2] * m[2]).sqrt();
    if norm <= 1e-6 {
        return None;
    }
    let dir = [m[0] / norm, m[1] / norm, m[2] / norm];
    let n = sys.dim();
    let mut e = vec![0.0; n];
    let mut g = vec![0.0; n];
    for j in 0..n {
        e[j] = 1.0;
        let d = sys.master_displacement(&e);
        g[j] = dir[0] * d[0] + dir[1] * d[1] + dir[2] * d[2];
        e[j] = 0.0;
    }
    Some(g)
}

/// The backbone of the model `spec` names on `model` (module docs): the full FE model or a
/// reduced one (a basis or `--tolerance`; its rounds run the case's own transient with
/// `opts.transient`).
///
/// # Errors
/// Bad options (naming their flags), a mode beyond the model's, a model that cannot be built,
/// an equilibrium or eigensolve that fails. A ring-down that fails or misses its energy check
/// is a warning in the result, not an error.
pub fn compute(model: &Model, spec: &ModelSpec, opts: &BackboneOptions) -> Result<Backbone, Error> {
    opts.check()?;
    let t0 = Instant::now();
    let count = opts.modes.iter().copied().max().unwrap_or(1);
    let friction = opts.transient.problem.friction;
    let scene = Scene::of(model);
    let mut enrichment = None;
    let (size, eq, modes, rom) = match spec {
        ModelSpec::Full => {
            check_modes(count, model.dofs(), "full")?;
            let eq = full_equilibrium(model, opts.preload)?;
            let modes = full_modes(model, &eq, count, friction)?;
            (model.dofs(), eq, modes, None)
        }
        _ => {
            // The reduced model is chosen on the case's own transient at the integrator's
            // default tolerances: `opts.transient.ode` holds the ring-downs' (stated at 1 mm of
            // amplitude), which must not change the model.
            let choose = TransientOptions {
                ode: TransientOptions::default().ode,
                ..opts.transient.clone()
            };
            let built = build_rom(model, spec, &choose, "backbone")?;
            let mut rom = built.rom;
            if let ModelSpec::Tolerance { .. } = spec {
                // The enrichment adds the modes asked for: any of the full model's will do.
                check_modes(count, model.dofs(), "full")?;
                let phi = rom.phi.as_ref().ok_or_else(|| RomError::Unsupported {
                    command: "backbone".into(),
                    model: "a tolerance model without its basis".into(),
                    takes: "--tolerance TOL with the basis kept",
                })?;
                let b = backbone_model(model, phi, opts.preload, count, friction)?;
                enrichment = Some((b.attachment_pairs, b.full_frequencies_hz, rom.dim()));
                rom = b.rom;
            }
            check_modes(count, rom.dim(), &spec.name())?;
            let eq = reduced_equilibrium(model, &rom, opts.preload)?;
            let modes = reduced_modes(model, &rom, &eq, count, friction)?;
            (rom.dim(), eq, modes, Some(rom))
        }
    };
    let setup_s = t0.elapsed().as_secs_f64();
    let mut out = Backbone {
        model: spec.name(),
        model_size: size,
        tolerance_model_size: enrichment.as_ref().map(|e| e.2),
        attachment_pairs: enrichment.as_ref().map(|e| e.0),
        preload: opts.preload,
        preload_load: eq.load,
        closed_pairs: eq.closed.iter().filter(|&&c| c).count(),
        pairs: eq.closed.len(),
        equilibrium_master: eq.master,
        friction,
        setup_s,
        ring_down_cpu_s: 0.0,
        ring_down_wall_s: 0.0,
        modes: Vec::new(),
        warnings: Vec::new(),
    };
    for &k in &opts.modes {
        let mode = &modes[k - 1];
        let mut ring_downs = Vec::with_capacity(opts.amplitudes.len());
        for &a in &opts.amplitudes {
            let r = match &rom {
                Some(rom) => ring_down(|| Ok(rom.clone()), &scene, &eq, mode, a, opts)?,
                None => ring_down(|| FullSystem::new(model), &scene, &eq, mode, a, opts)?,
            };
            out.ring_down_cpu_s += r.cpu_s;
            out.ring_down_wall_s += r.wall_s;
            out.warnings.extend(r.warnings(k, opts.cycles));
            ring_downs.push(r);
        }
        out.modes.push(ModeBackbone {
            mode: k,
            linear_frequency_hz: mode.frequency_hz,
            full_linear_frequency_hz: enrichment.as_ref().map(|e| e.1[k - 1]),
            shape_master: mode.master,
            modal_mass: mode.modal_mass,
            ring_downs,
        });
    }
    Ok(out)
}

/// An error unless `count` modes exist among `available`.
fn check_modes(count: usize, available: usize, model: &str) -> Result<(), Error> {
    if count > available {
        return Err(StudyError::ModeBeyond {
            mode: count,
            available,
            model: model.to_string(),
        }
        .into());
    }
    Ok(())
}
