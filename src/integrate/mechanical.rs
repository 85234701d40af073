//! The transient mechanical problem as a first-order ODE ([`crate::integrate::problem::OdeProblem`]) for any
//! [`SecondOrderSystem`], full or reduced.
//!
//! ## State
//!
//! ```text
//! y = [q (n), v (n), s (2w, friction on only), W, D]
//! q' = v
//! M v' = f(t) − K q − Bᵀ p(B q, s)                 (paper eq. 6 / eq. 7)
//! s' = ṡ(B q, s)                                   (viscoplastic slip memory, crate::joint::law)
//! W' = f(t) · v                                    (external work, N·mm)
//! D' = Σ_pairs p_t · ṡ                             (dissipated energy, N·mm)
//! ```
//!
//! The `s`, `W`, `D` states are stored in units of [`ProblemOptions::slip_scale`] (mm) and
//! [`ProblemOptions::energy_scale`] (N·mm), 1e-3 by default, so that the integrator's scalar
//! absolute tolerance (1e-6) means 1e-9 mm of slip: the stick radius `μ|p_n|/k_t` is ~1e-6 mm
//! for a pair force of 0.04 N, and with s in mm the slip memory would be resolved to no digit.
//!
//! With friction off the state has no `s` block (the tangential forces are zero and there is no
//! memory to carry) and `D' = 0`. `W` and `D` are integrated by the integrator itself (so they
//! are as accurate as the motion, independent of the output spacing); they do not feed back into
//! the motion. The energy balance
//! `E_kin + E_strain + E_pair − W + D = 0` (from rest, [`EnergySample::balance`]) then closes up
//! to the integration error and the viscoplastic lag of [`crate::joint::law`].
//!
//! ## The Newton solve
//!
//! CVODE's Newton matrix is `I − γJ`. With `P_u = ∂p/∂(Bq)`, `P_s = ∂p/∂s = −[0; T]`
//! (`T = ∂p_t/∂u_t`), `D_s = ∂ṡ/∂u_t = −∂ṡ/∂s`, `φ_g = ∂ṡ/∂g`, the system
//! `(I − γJ) [a; b; c; z_W; z_D] = [r_q; r_v; r_s; r_W; r_D]` reads
//!
//! ```text
//! a − γ b = r_q
//! M b + γ K a + γ Bᵀ (P_u B a + P_s c) = M r_v
//! (I + γ D_s) c = r_s + γ D_s B_t a + γ φ_g B_n a          (per pair, 2×2)
//! ```
//!
//! Eliminating `b = (a − r_q)/γ` and `c` gives (the `φ_g` term drops out: `T φ_g = 0`)
//!
//! ```text
//! (M + γ² (K + Bᵀ K_c B)) a = M r_q + γ M r_v + γ² Bᵀ [0; T (I + γ D_s)⁻¹ r_s]
//! K_c per pair = [[∂p_n/∂g, 0], [0, T (I + γ D_s)⁻¹]]
//! ```
//!
//! `T (I + γD_s)⁻¹` is symmetric for every branch (stick: `k_t I`, open: 0, slip:
//! `μ|p_n|/|e| / (1 + γρ/τ) · (I − n nᵀ)`, `ρ = (|e| − c)/|e|`). The only term dropped is the
//! non-symmetric `∂p_t/∂g = −μ k_n n` of sliding pairs (the friction force follows the normal
//! force), so that the matrix stays symmetric positive definite for a Cholesky factorization:
//! the solve is exact when no pair slides, otherwise a modified Newton direction that CVODE's
//! iteration corrects. `z_W = r_W + γ f(t)·b` and `z_D = r_D + γ ∇D'·[a; c]` are exact.

//!
//! ## Active-set refresh
//!
//! CVODE's Newton iteration is a *modified* Newton: the matrix above is factored at a setup
//! (every ~20 steps, on a γ change of > 30 % or after a failure) and reused. Smooth changes of
//! the tangent are harmless, but a pair that closes, opens, sticks or slips between setups makes
//! the stored matrix miss (or keep) a penalty `k_n` or stick stiffness `k_t` — the iteration then
//! converges slowly or not at all, CVODE counts a convergence failure, cuts `h` by 4 and
//! re-factors. With [`ProblemOptions::refresh`] the problem checks each iterate's branches
//! (one `B q` product and a comparison per pair) and, when a pair has crossed its switch by
//! more than the margin (gap beyond 0, or `|e| − c` beyond 0 for stick/slip, in mm), re-linearizes
//! and refactors at once with the current γ: a Newton iteration that follows the active set.
//! Measured on the 0.2 s runs with friction (steps; wall in s; refreshes in brackets; this
//! machine's timings vary by ±20 %):
//!
//! | scene, model | off | margin 1e-6 mm | **1e-8 mm** | 0 |
//! |---|---|---|---|---|
//! | friction bar, full FE | 22 276; 8.2 | 10 804; 5.8 (242) | **8 234; 4.0 (274)** | 7 832; 4.7 (304) |
//! | friction bar, all joint DOF | 20 014; 0.37 | 9 918; 0.23 | **8 343; 0.20 (399)** | 7 823; 0.18 |
//! | friction bar, TOL 1e-2 (r = 24) | 19 297; 0.18 | 13 160; 0.14 | **11 289; 0.086 (349)** | 12 772; 0.13 |
//! | multilayer, full FE | 12 646; 5.8 | 12 660; 5.5 (34) | **10 212; 4.9 (686)** | 11 786; 5.9 (1 683) |
//! | multilayer, all joint DOF | 13 727; 0.42 | 13 040; 0.50 | **11 938; 0.48 (651)** | 12 104; 0.58 (1 832) |
//!
//! Convergence failures drop from 232 → 47 (friction bar, full) and 330 → 44 (all joint DOF);
//! on the friction bar the step count falls 2.4–2.7×, on the multilayer sheet (whose pairs are
//! mostly closed, with many gaps hovering at round-off around 0 — margin 0 refactors 1 683 times
//! for no fewer steps) by ~15 %. The curves move by integration-level amounts (friction bar full
//! FE against the stored run without refresh: ‖f_c‖ 3.0e-4, u_y 3.8e-5, ‖f_R‖ 6.3e-3 — the stick–slip
//! history's sensitivity, see `cases/reference/SOURCE.md`). Both the full and the reduced models
//! use it: the baseline gets faster too.
//!
//! A refresh re-linearizes the pairs whose branch differs from the stored one (at the
//! iterate; pairs on the same branch are left as linearized) and first asks the system to
//! update its factor by their blocks alone at the factored γ
//! ([`SecondOrderSystem::newton_update`]): the full model does that exactly by a low-rank
//! (capacitance) correction, without refactoring ([`crate::system::FullSystem`]). If the system
//! declines (the reduced model, whose dense refactorization is cheap, or a full correction),
//! every pair is re-linearized and the matrix refactored at the current γ, as before. (Measured
//! and not kept for the reduced model: rank-≤ 3 Cholesky updates per switched pair at the
//! factored γ (faer's rank-r update) took the multilayer's TOL 1e-2 ROM from 11 798 to 12 883
//! steps and 170 to 192 ms, the friction bar's unchanged — its refactorization re-linearizes
//! every pair at the current γ, a better Newton matrix than the update's.) The pairs
//! on a branch with a constant tangent (open, stick) are then exactly as a full
//! re-linearization would leave them; the sliding ones keep the tangent of their last
//! linearization — on the refined friction bars the step counts stay within their run-to-run
//! scatter (README, *Full FE reference at scale*).
//!
//! ## What sets the step size (measured, friction bar, 0.2 s with friction, paper tolerances)
//!
//! | suspect | how measured | finding |
//! |---|---|---|
//! | accuracy of the resolved motion (BDF2) | steps vs model, friction off | Craig–Bampton only 9 881, modes g = 12 13 003, all joint DOF 20 237, full FE 30 835: BDF2 at rtol 1e-8 needs `(2/9)(hω)³ ≲ 1e-8`, h ≈ 7e-6 s for the 87 Hz mode alone — ~10⁴ steps is the floor of order 2 |
//! | BDF order 3–5 | `--max-order 3…5`, CB only | 250 000–300 000 steps: the undamped constraint modes (axial ~7.6 kHz) sit in BDF3–5's unstable band near the imaginary axis |
//! | joint-local high frequencies | ROM in its modal coordinates, error test off (atol × 1e6) for the 49 of 68 modes above 2e4 rad/s | 20 162 → 16 502 steps only: the high modes are not what the error test resolves |
//! | error test over slip / energy states | `CVodeGetEstLocalErrors` × weights at the outputs; their atol × 1e6 | they carry 80–98 % of the sampled WRMS error, yet excluding them saves 12 % (19 749 → 17 395): displacements and velocities bind next |
//! | Newton convergence failures at pair switches | CVODE's counters; active-set refresh | 232–330 failures per run, each cutting h by 4: the refresh (below) removes ~85 % of them and **60 % of the steps** |
//! | step-size policy | `CVodeSetEtaFixedStepBounds` (`--step-growth` 1.01–1.3 vs CVODE's 1.5) | friction bar −25 … −35 % steps but erratic (±20 % run to run), multilayer ±5 %: kept at CVODE's default |
//! | the WRMS norm's length | r = 24 ROM (154 states) vs full (1 918 states) | the mean over fewer, busier components held the ROM ~√(1918/154) = 3.5× tighter than the full model for the same field error; at 3.5× looser rtol/atol the TOL 1e-2 ROM took 5 937 instead of 11 289 steps with the same true errors (‖f_c‖ 5.7e-4 vs 6.3e-4). Now the reduced model's error test is the full model's on the field (next section): 11 289 → 8 163–9 325 steps |
//! | the joint directions at all (step floor) | the Craig–Bampton base alone (r = 16, no joint coordinate), field error test (below) | friction bar 8 688 steps (friction off) / 9 846 (on), multilayer 10 758 / 12 468; the full model 8 414 / 8 309 and – / 12 391, the TOL 1e-2 ROM – / 8 688 and – / 11 798: every model takes the steps of the Craig–Bampton motion at order 2, so no condensation of joint directions (quasi-static or otherwise) can take a reduced model below them |
//! | order 3–5 on that base | `--max-order 3`, `5`, Craig–Bampton base alone | friction off 139 950 / 48 721 steps, on 240 086 / 227 885: the undamped high modes of the base itself (constraint modes) forbid orders above 2 — fewer steps than the order-2 floor need the base's own stiff modes out of the integrated state (an index-1 DAE whose algebraic part carries the non-smooth contact law; not built) |
//! | friction relaxation τ = 1e-6 s | friction off vs on | ≈ the same steps (17 924 vs 19 749): the −1/τ eigenvalues are damped by BDF2 (A-stable) and do not limit h |
//!
//! ## The error test of a reduced model
//!
//! CVODE accepts a step when the WRMS norm of its local error estimate is at most 1:
//! `‖e‖ = √( (1/N) Σᵢ (eᵢ / wᵢ)² )`, `wᵢ = rtol |yᵢ| + atolᵢ`, over the N states. The full
//! model's N = 2n + 2w_s + 2 states are the nodal displacements and velocities, the slip memory
//! and the two energies. A reduced model's state `(q, v, s, W, D)` stands for the full state
//! `(Φq, Φv, s, W, D)`, and its error for `(Φe_q, Φe_v, e_s, …)`. Its error test is made the
//! full model's test of that field (atol-dominated: displacements of tens of mm against
//! rtol 1e-8 and atol 1e-6 are): with columns `Φ_j` nearly orthogonal in the Euclidean sense,
//! `Σᵢ (Φe_q)ᵢ² ≈ Σ_j ‖Φ_j‖² e_{q,j}²`, so
//!
//! ```text
//! (1/N_full) [ Σ_j (‖Φ_j‖ e_{q,j} / atol)² + … + Σ_k (e_{s,k} / atol_s)² ]
//!   = (1/N_red) [ Σ_j (e_{q,j} / (atol · L / ‖Φ_j‖))² + … + Σ_k (e_{s,k} / (atol_s · L))² ],
//! L = √(N_full / N_red),
//! ```
//!
//! which is what [`OdeProblem::atol_scale`] gives the reduced model: coordinate j's absolute
//! tolerance `atol · L / ‖Φ_j‖₂` (velocities × `velocity_scale`) and the slip memory's
//! `atol · L` ([`SecondOrderSystem::coordinate_size_into`], [`SecondOrderSystem::field_dofs`];
//! L = 1 and ‖Φ_j‖ = 1 for the full model, whose test is unchanged). The energies W and D keep
//! their own `atol · energy_scale`: they are the energy balance's check, not part of the motion.
//! Exact for Euclidean-orthogonal columns (tested: `tests/integrate/system.rs`,
//! `reduced_error_test_is_the_full_models_on_the_field`); jointrom's M-orthonormal columns are
//! near it.
//!
//! Before, a reduced coordinate's tolerance was `atol / max|Φ_j|` and the slip memory's `atol`:
//! the mean over the reduced model's few states, most of them slip memory, held it ~L ≈ 3.5×
//! (friction bar, r = 24) tighter than the full model on the same field, and the tolerance-chosen
//! model took more steps than the full model (11 289 vs 8 234). Measured (`cargo bench --bench
//! speed`, true errors against the stored full runs unchanged within their scatter): friction
//! bar TOL 1e-2 ROM 11 289 → 9 325 steps (‖f_c‖ 6.3e-4 → 6.1e-4), TVD g = 12 12 842 → 9 715, all
//! joint DOF 8 343 → 8 349; multilayer TOL 1e-2 12 478 → 12 153 (‖f_c‖ 5.2e-3 both). Scaling the
//! coordinates alone and not the slip memory saves nothing (12 806 steps): the slip states bind.
//! The reduced models now take about the full model's steps (8 309, 12 391): what is left of the
//! speed-up is the cost per step.
//!
//! ## Running
//!
//! [`crate::integrate::driver`] drives a [`MechanicalOde`] with [`crate::integrate::sundials::Cvode`]
//! from rest to the scene's end time, sampling [`EnergySample`]s into
//! [`crate::integrate::Curves`] every `output_step` (1e-4 s by
//! default). With events on, every located root (a gap or a stick/slip switch changing sign)
//! re-initialises the integrator (order 1, history discarded); 1000 roots in a row without
//! progress in time end the run with an error (a chattering switch).
//!
//! Measured step counts, Newton iterations and energy balances of these runs are in
//! `docs/validation/transient.md` (section `integrate::mechanical`).
//!
//! ## Step size of the full model: defaults
//!
//! The full FE model (friction bar, 906 DOF) took ~1e5 steps of ~1e-8 s per millisecond with
//! CVODE's defaults (the measured table of max order × velocity tolerance × friction is in
//! `docs/validation/transient.md`).
//!
//! Two causes, both legitimately removable:
//!
//! 1. **BDF orders 3–5 on an undamped structure.** The FE model has modes up to ~10⁶–10⁷ rad/s
//!    (shell membrane/drilling, the penalty springs on nodal masses of ~1e-7 t) that the motion
//!    does not excite. BDF3–5 are not A-stable: their stability regions miss a sector around the
//!    imaginary axis, and on an undamped mode `hω` must stay small or the mode grows; CVODE's error
//!    test then keeps `h` near 1e-8 s while the order climbs (15 081 steps, and 307 986 when a
//!    looser velocity tolerance lets it climb further). Stability-limit detection
//!    (`CVodeSetStabLimDet`) does not cure it (22 937). BDF2 is A-stable and damps the unresolved
//!    modes numerically (the ROM has none of them: its highest mode is the truncation's):
//!    **max order 2** ([`DEFAULT_MAX_ORDER`]), 10× fewer steps. With friction on the order never
//!    rose above 2 anyway (the −1/τ eigenvalues of open and sliding pairs).
//! 2. **The velocity tolerance.** With one number for both (vs = 1 1/s, velocity atol 1e-6 mm/s)
//!    every mode above 0.16 Hz is held to atol/ω in displacement — 1e-12 mm for a 10⁶ rad/s mode
//!    — and even BDF2 needs 25 000 steps. vs = ω_ref makes the displacement tolerance rule modes
//!    below ω_ref and the velocity tolerance modes above it (see [`DEFAULT_VELOCITY_SCALE`]):
//!    **vs = 1e3 1/s** (ω_ref ≈ 160 Hz, between the friction bar's first two fixed-interface
//!    modes, 87 and 217 Hz); 1e4 saves nothing more (more Newton failures).
//!
//! Newton is not the bottleneck: 1.1–1.6 iterations per step, and the convergence failures
//! (contact pairs opening/closing within a step) cost ~10 % of the steps. With these defaults the
//! full friction bar runs 0.2 s in 28 000–38 000 steps (~20 s CPU) and the TVD ROM (r = 28) in
//! 7 000–11 000 steps; the same settings apply to both (tolerances in mm of the physical field,
//! [`OdeProblem::atol_scale`]). Accuracy: see `cases/reference/SOURCE.md` (default vs 100×
//! tighter tolerances).

use crate::case::ContactSpec;
use crate::error::Error;
use crate::integrate::problem::{CallbackError, OdeProblem};
use crate::joint::law::{evaluate_pairs, PairLaw, PairState, DEFAULT_TAU};
use crate::system::SecondOrderSystem;

/// Default [`ProblemOptions::velocity_scale`], 1/s: velocities are held to `atol · ω_ref` with
/// ω_ref = 1e3 rad/s (160 Hz, between the friction bar's 1st and 2nd fixed-interface modes,
/// 87 and 217 Hz). A mode of circular frequency ω and displacement error ε has a velocity error
/// ω ε, so modes below ω_ref are controlled by the displacement tolerance (ε ≤ atol) and modes
/// above by the velocity tolerance (ε ≤ atol · ω_ref/ω, tighter). With ω_ref = 1 rad/s (one
/// number for both, the paper's Table 1 read literally) every mode above 0.16 Hz — all of them —
/// is held to atol/ω in displacement, 10⁻¹¹ mm for a 1 MHz shell mode: see the module docs.
pub const DEFAULT_VELOCITY_SCALE: f64 = 1e3;

/// Default maximum BDF order of [`crate::integrate::TransientOptions`]: 2 (see the module docs — BDF orders 3–5
/// are not A-stable, and the undamped FE model's high-frequency modes on the imaginary axis
/// then force steps of ~1e-8 s).
pub const DEFAULT_MAX_ORDER: usize = 2;

/// Default [`ProblemOptions::refresh`] margin, mm: 1e-2 × the default absolute tolerance — the
/// size of correction CVODE's Newton test still accepts (its coefficient 0.1 on a local-error
/// weight of ~0.1 atol); a pair that crosses its switch by less is absorbed by the modified
/// Newton iteration. Measured grid (0, 1e-8, 1e-6 mm, off): module docs, *Active-set refresh*.
pub const DEFAULT_REFRESH_MARGIN: f64 = 1e-8;

/// Options of the mechanical problem.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct ProblemOptions {
    /// Friction (tangential forces and slip memory) on.
    pub friction: bool,
    /// Root functions: gaps (w) and, with friction, stick/slip switches (w).
    pub events: bool,
    /// Relaxation time τ of the slip memory, s.
    pub tau: f64,
    /// Unit of the slip-memory states, mm (state = s / slip_scale). The integrator's absolute
    /// tolerance applies to the states, and the stick radius `μ|p_n|/k_t` is only ~1e-6 mm at
    /// p_n = 0.04 N: with atol 1e-6 on s in mm the slip memory (and the dissipation) would be
    /// resolved to no digit. Default 1e-3 (atol 1e-6 ↔ 1e-9 mm).
    pub slip_scale: f64,
    /// Unit of the energy states W and D, N·mm (default 1e-3: atol 1e-6 ↔ 1e-9 N·mm).
    pub energy_scale: f64,
    /// Velocity tolerance per displacement tolerance, 1/s: a velocity's absolute tolerance is
    /// `atol · velocity_scale` (mm/s) while a displacement's is `atol` (mm). 1 applies the one
    /// number of the paper's Table 1 to both.
    pub velocity_scale: f64,
    /// Active-set refresh margin, mm (`None`: off): inside a Newton iteration, re-linearize and
    /// refactor the Newton matrix when a pair at the current iterate is on another branch than
    /// at the last linearization by more than this — a gap beyond 0, or an elastic slip beyond
    /// the stick radius, by more than the margin (for the slip, the margin times
    /// `slip_scale`, i.e. the same in units of the states' tolerances). See the module docs,
    /// *Active-set refresh*. Default `Some(1e-8)` ([`DEFAULT_REFRESH_MARGIN`]).
    pub refresh: Option<f64>,
}

impl Default for ProblemOptions {
    fn default() -> Self {
        ProblemOptions {
            friction: true,
            events: false,
            tau: DEFAULT_TAU,
            slip_scale: 1e-3,
            energy_scale: 1e-3,
            velocity_scale: DEFAULT_VELOCITY_SCALE,
            refresh: Some(DEFAULT_REFRESH_MARGIN),
        }
    }
}

/// One pair's linearization kept between Newton setup and solves.
#[derive(Clone, Copy, Debug, Default)]
struct PairLin {
    /// `(I + γ D_s)⁻¹`.
    inv: [[f64; 2]; 2],
    /// `D_s = ∂ṡ/∂u_t`.
    sdot_u: [[f64; 2]; 2],
    /// `φ_g = ∂ṡ/∂g`.
    sdot_g: [f64; 2],
    /// `T (I + γ D_s)⁻¹` (symmetric).
    t_eff: [[f64; 2]; 2],
    /// `T = ∂p_t/∂u_t`.
    pt_u: [[f64; 2]; 2],
    /// `∂p_n/∂g`.
    pn_g: f64,
    /// `∂d/∂u_t`, `∂d/∂g`.
    diss_u: [f64; 2],
    diss_g: f64,
}

/// The mechanical ODE of a second-order system with joint pairs.
pub struct MechanicalOde<S: SecondOrderSystem> {
    sys: S,
    law: PairLaw,
    events: bool,
    n: usize,
    w: usize,
    /// Work buffers (no allocation in callbacks).
    u: Vec<f64>,
    p: Vec<f64>,
    srate: Vec<f64>,
    f: Vec<f64>,
    tmp: Vec<f64>,
    tmp2: Vec<f64>,
    kc: Vec<f64>,
    lin: Vec<PairLin>,
    lin_gamma: f64,
    have_lin: bool,
    /// Sliding pairs at the last Newton setup.
    slipping_at_setup: usize,
    /// Each pair's branch at the last linearization.
    branch: Vec<PairState>,
    refresh: Option<f64>,
    /// Re-linearizations inside Newton iterations (active-set refreshes).
    refreshes: u64,
    /// Of those, the ones done by a low-rank update of the factor.
    low_rank_refreshes: u64,
    /// Pairs that had switched branch at a refresh, summed over the refreshes.
    refresh_pairs: u64,
    /// The pairs on another branch than linearized at a refresh (scratch, capacity w).
    changed: Vec<usize>,
    /// The last right-hand side's `q`, slip states and joint kinematics `B q`: CVODE's Newton
    /// iteration evaluates the right-hand side at the iterate it then solves at, so the
    /// refresh check reuses the product when the iterate is the same.
    rhs_q: Vec<f64>,
    rhs_s: Vec<f64>,
    rhs_u: Vec<f64>,
    /// Slip memory in mm (the states times `s_scale`).
    s_phys: Vec<f64>,
    s_scale: f64,
    e_scale: f64,
    v_scale: f64,
    /// The co-simulation's load ([`MechanicalOde::set_load`]); `None`: the system's own load.
    load_hook: Option<LoadHook>,
}

/// A load other than the system's own ([`MechanicalOde::set_load`]):
/// `f(t) = scale · f_system(t) + F_master`, with `F_master` the (generalized) forces of a
/// master-node load held constant until the next change.
#[derive(Clone, Debug, PartialEq)]
struct LoadHook {
    /// Factor on the system's own load history (dimensionless).
    scale: f64,
    /// The added master-node load `[Fx, Fy, Fz (N), Mx, My, Mz (N·mm)]`.
    master: [f64; 6],
    /// Its (generalized) forces ([`SecondOrderSystem::master_load_into`]), computed once per
    /// change so that the right-hand side does not allocate.
    forces: Vec<f64>,
}

impl<S: SecondOrderSystem> MechanicalOde<S> {
    /// Wraps a system with a contact law (k_n, μ, k_t).
    pub fn new(
        sys: S,
        contact: &ContactSpec,
        opts: &ProblemOptions,
    ) -> Result<MechanicalOde<S>, Error> {
        let c = contact;
        if !(opts.tau.is_finite() && opts.tau > 0.0) {
            return Err(Error::Invalid(format!(
                "tau (slip relaxation time) must be finite and positive, got {} s",
                opts.tau
            )));
        }
        for (name, v) in [
            ("slip_scale", opts.slip_scale),
            ("energy_scale", opts.energy_scale),
            ("velocity_scale", opts.velocity_scale),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::Invalid(format!(
                    "{name} must be finite and positive, got {v}"
                )));
            }
        }
        let law = PairLaw {
            k_n: c.normal_stiffness,
            friction: opts.friction,
            mu: c.friction_coefficient,
            k_t: c.stick_stiffness,
            tau: opts.tau,
        };
        let n = sys.dim();
        let w = sys.pairs();
        Ok(MechanicalOde {
            law,
            events: opts.events,
            n,
            w,
            u: vec![0.0; 3 * w],
            p: vec![0.0; 3 * w],
            srate: vec![0.0; 2 * w],
            f: vec![0.0; n],
            tmp: vec![0.0; n],
            tmp2: vec![0.0; n],
            kc: vec![0.0; 9 * w],
            lin: vec![PairLin::default(); w],
            lin_gamma: f64::NAN,
            have_lin: false,
            slipping_at_setup: 0,
            branch: vec![PairState::Open; w],
            refresh: opts.refresh,
            refreshes: 0,
            low_rank_refreshes: 0,
            refresh_pairs: 0,
            changed: Vec::with_capacity(w),
            rhs_q: vec![f64::NAN; n],
            rhs_s: vec![f64::NAN; if opts.friction { 2 * w } else { 0 }],
            rhs_u: vec![0.0; 3 * w],
            s_phys: vec![0.0; if opts.friction { 2 * w } else { 0 }],
            s_scale: opts.slip_scale,
            e_scale: opts.energy_scale,
            v_scale: opts.velocity_scale,
            load_hook: None,
            sys,
        })
    }

    /// Replaces the load by `scale · f_system(t) + F(master)`: the system's own load history
    /// times `scale` (dimensionless) plus the master-node load `master = [Fx, Fy, Fz (N), Mx,
    /// My, Mz (N·mm)]` held constant (a co-simulation's input between two communication
    /// points). `(1, 0)` restores the system's own load exactly (the same arithmetic as without
    /// a call). The right-hand side is not smooth across a change: restart the integrator
    /// after one ([`crate::integrate::Stepper`] does).
    ///
    /// # Errors
    /// [`Error::Invalid`] naming the component if `scale` or a load component is not finite.
    pub fn set_load(&mut self, scale: f64, master: [f64; 6]) -> Result<(), Error> {
        if !scale.is_finite() {
            return Err(Error::Invalid(format!(
                "the load scale must be finite, got {scale}"
            )));
        }
        const NAMES: [&str; 6] = ["Fx", "Fy", "Fz", "Mx", "My", "Mz"];
        if let Some(d) = master.iter().position(|v| !v.is_finite()) {
            return Err(Error::Invalid(format!(
                "the master load component {} must be finite, got {}",
                NAMES[d], master[d]
            )));
        }
        if scale == 1.0 && master.iter().all(|&v| v == 0.0) {
            self.load_hook = None;
            return Ok(());
        }
        let mut forces = vec![0.0; self.n];
        self.sys.master_load_into(&master, &mut forces);
        self.load_hook = Some(LoadHook {
            scale,
            master,
            forces,
        });
        Ok(())
    }

    /// The load set by [`MechanicalOde::set_load`]: `(scale, master load)`, `(1, 0)` for the
    /// system's own.
    pub fn load(&self) -> (f64, [f64; 6]) {
        match &self.load_hook {
            Some(h) => (h.scale, h.master),
            None => (1.0, [0.0; 6]),
        }
    }

    /// `self.f = f(t)`: the system's load, changed by the load hook if set.
    fn total_load_into_f(&mut self, t: f64) {
        self.sys.load_into(t, &mut self.f);
        if let Some(h) = &self.load_hook {
            for (fi, e) in self.f.iter_mut().zip(&h.forces) {
                *fi = h.scale * *fi + e;
            }
        }
    }

    /// The system.
    pub fn system(&self) -> &S {
        &self.sys
    }

    /// The pair law in use.
    pub fn law(&self) -> &PairLaw {
        &self.law
    }

    /// Number of structural coordinates n.
    pub fn coords(&self) -> usize {
        self.n
    }

    /// Number of slip-memory states (2w with friction, else 0).
    fn ns(&self) -> usize {
        if self.law.friction {
            2 * self.w
        } else {
            0
        }
    }

    /// Index of the external-work state W (D follows).
    pub fn work_index(&self) -> usize {
        2 * self.n + self.ns()
    }

    /// Unit of the slip-memory states, mm.
    pub fn slip_scale(&self) -> f64 {
        self.s_scale
    }

    /// Unit of the energy states, N·mm.
    pub fn energy_scale(&self) -> f64 {
        self.e_scale
    }

    /// Copies the slip memory of `y` into `s_phys` (mm).
    fn load_slip(&mut self, y: &[f64]) {
        let i0 = 2 * self.n;
        for (o, &x) in self.s_phys.iter_mut().zip(&y[i0..]) {
            *o = self.s_scale * x;
        }
    }

    /// The pair forces `p` (3w: normal, t1, t2 per pair; N) of the last [`MechanicalOde::sample`].
    pub fn pair_forces(&self) -> &[f64] {
        &self.p
    }

    /// The slip memory `s` (2w with friction, else empty; mm) of the last
    /// [`MechanicalOde::sample`].
    pub fn slip_memory(&self) -> &[f64] {
        &self.s_phys
    }

    /// Pairs sliding at the last Newton setup.
    pub fn slipping_at_setup(&self) -> usize {
        self.slipping_at_setup
    }

    /// The initial state: at rest, undeformed, no slip, no work.
    pub fn initial_state(&self) -> Vec<f64> {
        vec![0.0; self.dim()]
    }

    /// Outputs at `(t, y)`: force norms, master displacement, energies.
    pub fn sample(&mut self, t: f64, y: &[f64]) -> EnergySample {
        let n = self.n;
        self.load_slip(y);
        let (q, rest) = y.split_at(n);
        let (v, rest) = rest.split_at(n);
        let rest = &rest[self.ns()..];
        let s = &self.s_phys;
        self.sys.joint_apply_into(q, &mut self.u);
        evaluate_pairs(&self.law, &self.u, s, &mut self.p, &mut self.srate);
        let mut fc = 0.0;
        let mut fr = 0.0;
        let mut pair = 0.0;
        for k in 0..self.w {
            fc += self.p[3 * k].powi(2);
            fr += self.p[3 * k + 1].powi(2) + self.p[3 * k + 2].powi(2);
            let sk = if self.law.friction {
                [s[2 * k], s[2 * k + 1]]
            } else {
                [0.0; 2]
            };
            pair += self
                .law
                .stored_energy([self.u[3 * k], self.u[3 * k + 1], self.u[3 * k + 2]], sk);
        }
        self.sys.mul_m_into(v, &mut self.tmp);
        let kinetic = 0.5 * dot(v, &self.tmp);
        self.sys.mul_k_into(q, &mut self.tmp);
        let strain = 0.5 * dot(q, &self.tmp);
        EnergySample {
            t,
            contact_force_norm: fc.sqrt(),
            friction_force_norm: fr.sqrt(),
            master: self.sys.master_displacement(q),
            kinetic,
            strain,
            pair,
            external_work: self.e_scale * rest[0],
            dissipated: self.e_scale * rest[1],
        }
    }
}

/// Outputs at one time.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct EnergySample {
    /// Time, s.
    pub t: f64,
    /// ‖f_c‖: Euclidean norm of all pair normal forces, N.
    pub contact_force_norm: f64,
    /// ‖f_R‖: Euclidean norm of all tangential (x, z) pair forces, N.
    pub friction_force_norm: f64,
    /// Master node `[ux, uy, uz (mm), rx, ry, rz (rad)]`.
    pub master: [f64; 6],
    /// `½ vᵀ M v`, N·mm.
    pub kinetic: f64,
    /// `½ qᵀ K q`, N·mm.
    pub strain: f64,
    /// Pair (penalty + elastic stick) energy, N·mm.
    pub pair: f64,
    /// `∫ f · v dt`, N·mm.
    pub external_work: f64,
    /// `∫ Σ p_t · ṡ dt`, N·mm.
    pub dissipated: f64,
}

impl EnergySample {
    /// `E_kin + E_strain + E_pair + D − W` (zero for an exact solution from rest), N·mm.
    pub fn balance(&self) -> f64 {
        self.kinetic + self.strain + self.pair + self.dissipated - self.external_work
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn mul2(a: &[[f64; 2]; 2], x: [f64; 2]) -> [f64; 2] {
    [
        a[0][0] * x[0] + a[0][1] * x[1],
        a[1][0] * x[0] + a[1][1] * x[1],
    ]
}

fn matmul2(a: &[[f64; 2]; 2], b: &[[f64; 2]; 2]) -> [[f64; 2]; 2] {
    let mut c = [[0.0; 2]; 2];
    for i in 0..2 {
        for j in 0..2 {
            c[i][j] = a[i][0] * b[0][j] + a[i][1] * b[1][j];
        }
    }
    c
}

impl<S: SecondOrderSystem> MechanicalOde<S> {
    /// The pair tangents at the kinematics in `u` and the slip memory in `s_phys` (loaded by
    /// the caller), with each pair's branch.
    fn linearize(&mut self) {
        let mut slipping = 0;
        for k in 0..self.w {
            let state = self.linearize_pair(k);
            if self.law.friction && state == PairState::Slip {
                slipping += 1;
            }
            self.branch[k] = state;
        }
        self.slipping_at_setup = slipping;
        self.have_lin = true;
    }

    /// Active-set refresh: if a pair's branch at the iterate `y` differs from the one of the
    /// stored linearization, re-linearizes there and refactors with `gamma`.
    fn refresh_if_switched(
        &mut self,
        y: &[f64],
        gamma: f64,
        margin: f64,
    ) -> Result<(), CallbackError> {
        let slip_margin = margin * self.s_scale;
        let (n, ns) = (self.n, self.ns());
        if y[..n] == self.rhs_q[..] && y[2 * n..2 * n + ns] == self.rhs_s[..] {
            self.u.copy_from_slice(&self.rhs_u);
        } else {
            self.sys.joint_apply_into(&y[..n], &mut self.u);
        }
        self.load_slip(y);
        // The pairs on another branch than linearized (`changed`); a refresh when one of them
        // is past its switch by more than the margin.
        self.changed.clear();
        let mut switched = false;
        for k in 0..self.w {
            let (uk, sk) = self.pair_kinematics(k);
            let (now, then) = (self.law.state(uk, sk), self.branch[k]);
            if now == then {
                continue;
            }
            self.changed.push(k);
            switched |= if (now == PairState::Open) != (then == PairState::Open) {
                uk[0].abs() > margin
            } else {
                self.law.cone_distance(uk, sk).abs() > slip_margin
            };
        }
        if !switched {
            return Ok(());
        }
        self.refreshes += 1;
        self.refresh_pairs += self.changed.len() as u64;
        if self.update_changed() {
            self.low_rank_refreshes += 1;
            return Ok(());
        }
        self.linearize();
        self.apply_gamma(gamma);
        self.sys
            .newton_factor(gamma, &self.kc)
            .map_err(|e| CallbackError::Recoverable(e.to_string()))
    }

    /// Pair k's kinematics `[g, u_t1, u_t2]` in `u` and slip memory in `s_phys` (zero with
    /// friction off), mm.
    /// Pair k's tangent at its kinematics into `lin[k]` (γ-dependent parts left to
    /// [`MechanicalOde::apply_gamma_pair`]); returns its branch there.
    fn linearize_pair(&mut self, k: usize) -> PairState {
        let (uk, sk) = self.pair_kinematics(k);
        let tg = self.law.tangent(uk, sk);
        self.lin[k] = PairLin {
            sdot_u: tg.sdot_u,
            sdot_g: tg.sdot_g,
            pt_u: tg.pt_u,
            pn_g: tg.pn_g,
            diss_u: tg.diss_u,
            diss_g: tg.diss_g,
            ..PairLin::default()
        };
        self.law.state(uk, sk)
    }

    fn pair_kinematics(&self, k: usize) -> ([f64; 3], [f64; 2]) {
        let uk = [self.u[3 * k], self.u[3 * k + 1], self.u[3 * k + 2]];
        let sk = if self.law.friction {
            [self.s_phys[2 * k], self.s_phys[2 * k + 1]]
        } else {
            [0.0; 2]
        };
        (uk, sk)
    }

    /// Re-linearizes the pairs in `changed` (those on another branch than linearized) at `u`,
    /// `s_phys` and the factored γ, and asks the system to change its factor by their blocks
    /// alone ([`SecondOrderSystem::newton_update`]). `false` if it did not: the caller then
    /// re-linearizes every pair and refactors at the current γ. The other pairs keep their
    /// linearization; the ones on a branch whose tangent is constant (open, stick) are then
    /// exactly as a full re-linearization would make them, the sliding ones as at the last
    /// linearization (as between setups).
    fn update_changed(&mut self) -> bool {
        for i in 0..self.changed.len() {
            let k = self.changed[i];
            let state = self.linearize_pair(k);
            let friction = self.law.friction;
            let slip = |s: PairState| usize::from(friction && s == PairState::Slip);
            self.slipping_at_setup = self.slipping_at_setup + slip(state) - slip(self.branch[k]);
            self.branch[k] = state;
            self.apply_gamma_pair(k, self.lin_gamma);
        }
        self.sys.newton_update(&self.kc, &self.changed)
    }

    /// Active-set refreshes so far ([`ProblemOptions::refresh`]).
    pub fn refreshes(&self) -> u64 {
        self.refreshes
    }

    /// Of the [`MechanicalOde::refreshes`], those done by a low-rank update of the factor
    /// ([`SecondOrderSystem::newton_update`]) instead of a refactorization.
    pub fn low_rank_refreshes(&self) -> u64 {
        self.low_rank_refreshes
    }

    /// Pairs that had switched branch at a refresh, summed over the refreshes.
    pub fn refresh_pairs(&self) -> u64 {
        self.refresh_pairs
    }

    /// Builds K_c and the per-pair data for γ from the stored linearization.
    fn apply_gamma(&mut self, gamma: f64) {
        for k in 0..self.w {
            self.apply_gamma_pair(k, gamma);
        }
        self.lin_gamma = gamma;
    }

    /// [`MechanicalOde::apply_gamma`] of pair k.
    fn apply_gamma_pair(&mut self, k: usize, gamma: f64) {
        let l = &mut self.lin[k];
        let a = [
            [1.0 + gamma * l.sdot_u[0][0], gamma * l.sdot_u[0][1]],
            [gamma * l.sdot_u[1][0], 1.0 + gamma * l.sdot_u[1][1]],
        ];
        let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
        l.inv = [
            [a[1][1] / det, -a[0][1] / det],
            [-a[1][0] / det, a[0][0] / det],
        ];
        let te = matmul2(&l.pt_u, &l.inv);
        let off = 0.5 * (te[0][1] + te[1][0]);
        l.t_eff = [[te[0][0], off], [off, te[1][1]]];
        let b = &mut self.kc[9 * k..9 * k + 9];
        b.fill(0.0);
        b[0] = l.pn_g;
        b[4] = l.t_eff[0][0];
        b[5] = l.t_eff[0][1];
        b[7] = l.t_eff[1][0];
        b[8] = l.t_eff[1][1];
    }
}

impl<S: SecondOrderSystem> OdeProblem for MechanicalOde<S> {
    fn dim(&self) -> usize {
        2 * self.n + self.ns() + 2
    }

    /// Displacements: `atol` in mm (or rad) of the physical field, i.e. `atol / size` for a
    /// coordinate whose unit moves the field by `size` (Euclidean norm); velocities:
    /// `velocity_scale` times that; slip memory and energies: their state units (`slip_scale`,
    /// `energy_scale`) — all times `√(N_field / N)`, the full model's state count over this
    /// one's (module docs, *The error test of a reduced model*; 1 for the full model).
    fn atol_scale(&self, scale: &mut [f64]) -> bool {
        let n = self.n;
        let field = (2 * self.sys.field_dofs() + self.ns() + 2) as f64;
        let length = (field / self.dim() as f64).sqrt();
        let (q, rest) = scale.split_at_mut(n);
        self.sys.coordinate_size_into(q);
        q.iter_mut().for_each(|x| *x = length / *x);
        let (v, rest) = rest.split_at_mut(n);
        for (vi, qi) in v.iter_mut().zip(q.iter()) {
            *vi = qi * self.v_scale;
        }
        let (slip, energies) = rest.split_at_mut(self.ns());
        slip.iter_mut().for_each(|x| *x = length);
        energies.iter_mut().for_each(|x| *x = 1.0);
        true
    }

    fn rhs(&mut self, t: f64, y: &[f64], ydot: &mut [f64]) -> Result<(), CallbackError> {
        let n = self.n;
        let ns = self.ns();
        self.load_slip(y);
        let (q, rest) = y.split_at(n);
        let v = &rest[..n];
        self.sys.joint_apply_into(q, &mut self.u);
        self.rhs_q.copy_from_slice(q);
        self.rhs_s.copy_from_slice(&y[2 * n..2 * n + ns]);
        self.rhs_u.copy_from_slice(&self.u);
        let tot = evaluate_pairs(
            &self.law,
            &self.u,
            &self.s_phys,
            &mut self.p,
            &mut self.srate,
        );
        self.total_load_into_f(t);
        self.sys.mul_k_into(q, &mut self.tmp);
        self.sys.joint_transpose_add(&self.p, &mut self.tmp);
        let (dq, drest) = ydot.split_at_mut(n);
        let (dv, drest) = drest.split_at_mut(n);
        dq.copy_from_slice(v);
        for ((o, fi), ki) in dv.iter_mut().zip(&self.f).zip(&self.tmp) {
            *o = fi - ki;
        }
        self.sys.solve_m_in_place(dv);
        let inv_s = 1.0 / self.s_scale;
        for (o, &r) in drest[..ns].iter_mut().zip(&self.srate) {
            *o = inv_s * r;
        }
        drest[ns] = dot(&self.f, v) / self.e_scale;
        drest[ns + 1] = tot.dissipation / self.e_scale;
        // Non-finite entries are caught by the CVODE trampoline (`check_finite`, naming the
        // entry), the only caller: not checked twice.
        Ok(())
    }

    fn num_roots(&self) -> usize {
        if !self.events {
            0
        } else if self.law.friction {
            2 * self.w
        } else {
            self.w
        }
    }

    fn roots(&mut self, _t: f64, y: &[f64], g: &mut [f64]) -> Result<(), CallbackError> {
        let n = self.n;
        self.sys.joint_apply_into(&y[..n], &mut self.u);
        for k in 0..self.w {
            g[k] = self.u[3 * k];
        }
        if self.law.friction {
            self.load_slip(y);
            let s = &self.s_phys;
            for k in 0..self.w {
                g[self.w + k] = self.law.switch(
                    [self.u[3 * k], self.u[3 * k + 1], self.u[3 * k + 2]],
                    [s[2 * k], s[2 * k + 1]],
                );
            }
        }
        Ok(())
    }

    fn has_newton_solver(&self) -> bool {
        true
    }

    fn newton_setup(
        &mut self,
        _t: f64,
        y: &[f64],
        _fy: &[f64],
        jok: bool,
        gamma: f64,
    ) -> Result<bool, CallbackError> {
        let n = self.n;
        let jcur = !(jok && self.have_lin);
        if jcur {
            self.sys.joint_apply_into(&y[..n], &mut self.u);
            self.load_slip(y);
            self.linearize();
        }
        self.apply_gamma(gamma);
        self.sys
            .newton_factor(gamma, &self.kc)
            .map_err(|e| CallbackError::Recoverable(e.to_string()))?;
        Ok(jcur)
    }

    fn newton_solve(
        &mut self,
        t: f64,
        y: &[f64],
        r: &[f64],
        z: &mut [f64],
        gamma: f64,
    ) -> Result<(), CallbackError> {
        if !self.have_lin {
            return Err(CallbackError::Fatal(
                "newton_solve called before newton_setup".into(),
            ));
        }
        if let Some(margin) = self.refresh {
            self.refresh_if_switched(y, gamma, margin)?;
        }
        // CVODE re-runs the setup only when γ has changed by more than ~30 %; between setups
        // the current γ is used in the elimination (so `a − γ b = r_q` holds exactly) with the
        // factorization and `(I + γ D_s)⁻¹` of the setup's γ.
        let g = gamma;
        let n = self.n;
        let ns = self.ns();
        let fr = self.law.friction;
        let (rq, rest) = r.split_at(n);
        let (rv, rest) = rest.split_at(n);
        let (rs, rest) = rest.split_at(ns);
        // Residuals and corrections of s, W, D in physical units (mm, N·mm) inside.
        let ss = self.s_scale;
        // rhs_a = M (r_q + γ r_v) + γ² Bᵀ [0; T_eff r_s]
        for ((o, a), b) in self.tmp2.iter_mut().zip(rq).zip(rv) {
            *o = a + g * b;
        }
        self.sys.mul_m_into(&self.tmp2, &mut self.tmp);
        if fr {
            for k in 0..self.w {
                let l = &self.lin[k];
                let x = mul2(&l.inv, [ss * rs[2 * k], ss * rs[2 * k + 1]]);
                let h = mul2(&l.pt_u, x);
                self.p[3 * k] = 0.0;
                self.p[3 * k + 1] = g * g * h[0];
                self.p[3 * k + 2] = g * g * h[1];
            }
            self.sys.joint_transpose_add(&self.p, &mut self.tmp);
        }
        let (za, zrest) = z.split_at_mut(n);
        za.copy_from_slice(&self.tmp);
        self.sys.newton_solve_in_place(za);
        let (zb, zrest) = zrest.split_at_mut(n);
        for ((b, a), q) in zb.iter_mut().zip(za.iter()).zip(rq) {
            *b = (a - q) / g;
        }
        let (zs, ze) = zrest.split_at_mut(ns);
        let mut zd = self.e_scale * rest[1];
        if fr {
            self.sys.joint_apply_into(za, &mut self.u);
            for k in 0..self.w {
                let l = &self.lin[k];
                let ba = [self.u[3 * k], self.u[3 * k + 1], self.u[3 * k + 2]];
                let du = mul2(&l.sdot_u, [ba[1], ba[2]]);
                let rhs = [
                    ss * rs[2 * k] + g * (du[0] + l.sdot_g[0] * ba[0]),
                    ss * rs[2 * k + 1] + g * (du[1] + l.sdot_g[1] * ba[0]),
                ];
                let c = mul2(&l.inv, rhs);
                zs[2 * k] = c[0] / ss;
                zs[2 * k + 1] = c[1] / ss;
                zd += g
                    * (l.diss_u[0] * (ba[1] - c[0])
                        + l.diss_u[1] * (ba[2] - c[1])
                        + l.diss_g * ba[0]);
            }
        }
        self.total_load_into_f(t);
        ze[0] = rest[0] + g * dot(&self.f, zb) / self.e_scale;
        ze[1] = zd / self.e_scale;
        // Checked by the CVODE trampoline, as the right-hand side.
        Ok(())
    }
}
