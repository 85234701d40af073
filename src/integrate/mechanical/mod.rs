//! The transient mechanical problem as a first-order ODE ([`crate::integrate::problem::OdeProblem`]) for any
//! [`SecondOrderSystem`], full or reduced.
//!
//! ## State
//!
//! ```text
//! y = [q (n), v (n), s (2w, friction on only; or e = u_t − s, *The slip memory as elastic stretch*), W, D]
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
//! `E_kin + E_strain + E_pair − W + D = 0` (from rest, [`EnergySample::balance`]; from an initial
//! state, its value there) then closes up to the integration error and the viscoplastic lag of
//! [`crate::joint::law`].
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
//! iteration corrects. `z_W = r_W + γ f(t)·b` and `z_D = r_D + γ ∇D'·[a; c]` are exact
//! (`newton`).
//!
//! The corrections `c` read `B a` through `D_s`, `φ_g` and `∂d/∂(g, u_t)` only: on an open pair
//! `D_s = I/τ` and the rest vanish, on a stuck one all of them vanish, and only a sliding pair
//! needs its normal row. Where the system offers products of selected rows
//! ([`SecondOrderSystem::joint_apply_rows_into`], the reduced model's dense `BΦ`, whose
//! products stream the matrix and cost what they read) the solve forms the tangential rows of
//! every pair and the normal rows of the sliding ones, and an output sample the normal rows and
//! the closed pairs' tangential rows (an open pair's force and stored energy read its gap
//! alone) — the values the whole product gives those entries, bit for bit. The right-hand
//! side needs every row: an open pair's memory follows its tangential displacement.
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
//! and refactors at once with the current γ: a Newton iteration that follows the active set
//! (`refresh`). The margin keeps pairs hovering at round-off around a switch (gaps of a mostly
//! closed interface) from refactoring for nothing. Both the full and the reduced models use it.
//!
//! A refresh re-linearizes the pairs whose branch differs from the stored one (at the
//! iterate; pairs on the same branch are left as linearized) and first asks the system to
//! update its factor by their blocks alone at the factored γ
//! ([`SecondOrderSystem::newton_update`]): the full model does that exactly by a low-rank
//! (capacitance) correction, without refactoring ([`crate::system::FullSystem`]), the reduced
//! model by a rank update of its dense Cholesky factor when that costs less than a
//! factorization ([`crate::system::ReducedSystem`]). If the system declines (a change of too
//! high a rank, a full correction, a downdate that would lose definiteness), every pair is
//! re-linearized and the matrix refactored at the current γ — a better Newton matrix than the
//! update at the factored γ, which is why an update is only taken where it is cheaper. The pairs on a branch with a constant tangent (open, stick) are then exactly as a
//! full re-linearization would leave them; the sliding ones keep the tangent of their last
//! linearization.
//!
//! ## Pair screening
//!
//! A reduced model's joint kinematics `B Φ q` are dense: 3w·r operations per product, several
//! products per step (right-hand sides, the refresh check, the Newton solve), for every pair of
//! the interface — although at any time only a few are in contact. With
//! [`ProblemOptions::screen`] (opt-in) a step evaluates only a *tracked set* T of pairs and
//! proves every other pair open. At a Newton setup (between steps, so that a step sees one
//! right-hand side) the set is built from the gaps, their rates and accelerations at
//! `(t_ref, q_ref, v_ref)` (three products of the normal rows over all pairs): pair z joins if
//! the least gap of its quadratic prediction over the horizon `H = 60 γ` (≈ 40 steps) is not
//! positive, and leaves if that of `2H` is positive; the set is rebuilt at the first setup
//! after `H/2`. Every right-hand side proves the untracked pairs open by
//!
//! ```text
//! g_z(q) = g_ref + ġ_ref τ + B_{n,z} Δ ≥ g_ref + ġ_ref τ − ‖B_{n,z}‖ ‖Δ‖ ,
//! Δ = q − q_ref − v_ref τ ,  τ = t − t_ref
//! ```
//!
//! (Cauchy–Schwarz on the normal row; `‖Δ‖` costs r operations, the test one per pair), checks
//! the pairs whose bound is not positive exactly (one row product each), and lets a pair found
//! closed join at once (a *late entry*): no contact is ever missed; the prediction only sets
//! the cost. The tracked pairs' products, law, `Bᵀp`, Newton blocks and refresh check run over
//! T alone.
//!
//! **The slip memory of untracked pairs.** An open pair's memory relaxes to its tangential
//! displacement with time constant τ ([`crate::joint::law`]): it carries no information but
//! "no elastic stretch" when the pair closes. A pair that leaves T keeps the memory rate it
//! had (from the setup's right-hand side), held constant — its Jacobian rows are zero, and the
//! state's derivative is continuous. When it joins again its memory becomes
//! `s = slip_scale · state + offset` with the offset chosen so that `s = u_t − τ ṡ_frozen`:
//! the open-pair law then returns the same rate, so the derivative is again continuous and
//! CVODE's history stays valid; the elastic stretch starts at `τ ṡ_frozen` (≈ 1e-5 mm at
//! 10 mm/s), the size of the lag the law already has.
//!
//! **Why it is not the default.** A thin lap joint is pressed nearly shut: its open pairs' gaps
//! are 1e-4–1e-3 of the structure's motion in coordinate space, so within a few steps the bound
//! `‖B_{n,z}‖ ‖Δ‖` exceeds most gaps and half the untracked pairs need their exact product,
//! and the set changes (late entries, joins and leaves at builds) cost error-test failures —
//! fewer since the untracked pairs' memory left the error test (previous section), but on a
//! joint of few pairs still more than the products it saves. It pays where the products of
//! thousands of pairs are most of a step (docs/performance/speed.md, *Pair screening*).
//! The full model does not screen (its sparse `B q` costs a few entries per pair); screening
//! is off with events on (the root functions need every pair). Curves with and without
//! screening agree to the integration tolerance (`tests/integrate/screen.rs`).
//!
//! ## The slip memory as elastic stretch
//!
//! With [`ProblemOptions::stretch`] (opt-in, reduced models, events off) the memory states hold
//! the elastic stretch `e = u_t − s` (mm, in units of `slip_scale`) instead of the slip `s`.
//! It is a change of variables, not of the law ([`crate::joint::law`] sees `s = u_t − e`):
//!
//! ```text
//! ė = B_t v − ṡ(g, e)          (open pairs: ṡ = e/τ, so e relaxes to τ u̇_t)
//! ```
//!
//! The Newton solve eliminates the same way. With `c` the correction of `e`, `∂p_t/∂e = T`,
//! `∂ė/∂v = B_t` and `γ b = a − r_q`:
//!
//! ```text
//! (I + γ D_s) c = r_e + B_t a − B_t r_q − γ φ_g B_n a
//! (M + γ² (K + Bᵀ K_c B)) a = M r_q + γ M r_v − γ² B_tᵀ T (I + γ D_s)⁻¹ (r_e − B_t r_q)
//! z_D = r_D + γ (∂d/∂e · c + ∂d/∂g B_n a)
//! ```
//!
//! with the same `K_c` as above (the `φ_g` term drops out again), so the factorization is
//! shared; a solve needs one more joint product, `B_t r_q`, and a right-hand side `B_t v`.
//!
//! **Why it exists.** An open pair's `s` follows its tangential displacement `u_t` — the
//! structure's motion — and the error test holds it to the slip memory's tolerance
//! (1e-9 mm at atol 1e-6); its `e` stays near `τ u̇_t` and varies little. With screening, a
//! pair that leaves the tracked set keeps the rate of its state, and one that joins gets the
//! offset that makes the law's rate equal to it, as with `s`: `e = τ (u̇_t − ė_frozen)`. The
//! frozen rate of `e` is `τ ü_t`, small, where that of `s` was `u̇_t`: set changes disturb
//! the integrated state far less, and the screened run takes fewer steps than with `s`.
//!
//! **Why it is not the default.** The same fact cuts the other way: the `s` states of the open
//! pairs are a tight, implicit control on the tangential motion of the whole interface, and
//! without it the error test at the same rtol is looser — the steps saved are bought with
//! accuracy (docs/performance/speed.md, *Pair screening*), and the tolerance model's
//! integration check then tightens rtol and takes more steps than with `s`.
//! Curves with and without it agree to the integration tolerance
//! (`tests/integrate/screen.rs`).
//!
//! ## What sets the step size
//!
//! Every model takes about the steps of its Craig–Bampton motion at BDF order 2: the accuracy
//! of the resolved motion sets the floor, so no condensation of joint directions can take a
//! reduced model below it, and fewer steps would need the base's own stiff modes out of the
//! integrated state. Orders above 2 are ruled out by the undamped high modes (next sections);
//! the friction relaxation's −1/τ eigenvalues are damped by BDF2 (A-stable) and do not limit
//! `h`; Newton convergence failures at pair switches, each cutting `h` by 4, are what the
//! active-set refresh removes.
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
//! ## The error test of the open pairs' slip memory
//!
//! An open pair (`g ≥ 0`, stick radius 0) has `ṡ = (u_t − s)/τ`: its memory is slaved to its
//! tangential displacement. A BDF step `s_{n+1} = a_s + γ ṡ_{n+1}` (`a_s` the history's
//! combination, `γ = h β_0`) gives, with `a_s = a_u − a_e` the same combination of `u_t` and
//! of the elastic part `e = u_t − s`,
//!
//! ```text
//! e_{n+1} = τγ/(τ + γ) · [ (u_{t,n+1} − a_u)/γ + a_e/γ ]  ≈  τ u̇_t^BDF + (τ/γ) a_e
//! ```
//!
//! — `τ` times the formula's derivative of `u_t`, plus the history's stretch damped by
//! `τ/γ` (~1e-2 at the reduced models' steps). What the pair carries into its closing is
//! therefore fixed by the implicit equation and by the coordinates, whose own error test
//! bounds the velocity error δu̇_t: `|δe| ≲ τ |δu̇_t|` (1e-8 mm at the 1 % model's velocity
//! tolerance). The memory's local error estimate (predictor against corrector) measures
//! instead how well the history extrapolates `u_t` itself, held to the slip tolerance
//! `atol · L · slip_scale` — 1000× tighter than the field's `atol · L`: a control of the open
//! interface's tangential motion that the field test already gives at its own level.
//!
//! So a reduced model's step with [`ProblemOptions::open_slip_test`] off (the default) gives
//! the memory states of the pairs open by more than the refresh margin zero error weight
//! ([`OdeProblem::adjust_error_weights`], CVODE's `CVodeWFtolerances`); every other weight is
//! CVODE's own `1/(rtol |y_i| + atol_i)`, bit for bit, and a closed pair's memory — its
//! elastic stretch and the friction force — is tested as before. The gaps are those of the
//! last right-hand side (the accepted step's last Newton iterate, within the Newton
//! tolerance of the step's state; no product of its own). Pairs within the margin of the
//! switch keep their test: they hover at round-off around `g = 0` under the load ramp's start,
//! and switching their weights on and off with every sign change made that phase take ~1.8×
//! the steps. The Newton matrix treats an open pair's memory exactly (`D_s = I/τ`), so the
//! Newton convergence test, which uses the same weights, loses nothing either. With screening
//! the pairs outside the tracked set get zero weight as well: every right-hand side proves them
//! open (their gaps of the last one are not computed), and their memory runs at its frozen
//! rate, so the set's changes — a pair leaving or joining it — no longer reach the error test
//! through those states. The full model keeps every state in its test (its bits are
//! unchanged); so do the stretch states, whose memory states are not the slip of every pair.
//!
//! ## Running
//!
//! [`crate::integrate::driver`] drives a [`MechanicalOde`] with [`crate::integrate::Cvode`]
//! from rest to the scene's end time, sampling [`EnergySample`]s into
//! [`crate::integrate::Curves`] every `output_step` (1e-4 s by
//! default). With events on, every located root (a gap or a stick/slip switch changing sign)
//! re-initialises the integrator (order 1, history discarded); 1000 roots in a row without
//! progress in time end the run with an error (a chattering switch).
//!
//! ## Step size of the full model: defaults
//!
//! Two causes of tiny steps of the full FE model under CVODE's defaults, both legitimately
//! removable:
//!
//! 1. **BDF orders 3–5 on an undamped structure.** The FE model has modes up to ~10⁶–10⁷ rad/s
//!    (shell membrane/drilling, the penalty springs on nodal masses of ~1e-7 t) that the motion
//!    does not excite. BDF3–5 are not A-stable: their stability regions miss a sector around the
//!    imaginary axis, and on an undamped mode `hω` must stay small or the mode grows; CVODE's error
//!    test then keeps `h` near 1e-8 s while the order climbs. Stability-limit detection
//!    (`CVodeSetStabLimDet`) does not cure it. BDF2 is A-stable and damps the unresolved
//!    modes numerically (the ROM has none of them: its highest mode is the truncation's):
//!    **max order 2** ([`DEFAULT_MAX_ORDER`]). With friction on the order never rises above 2
//!    anyway (the −1/τ eigenvalues of open and sliding pairs).
//! 2. **The velocity tolerance.** With one number for both (vs = 1 1/s, velocity atol 1e-6 mm/s)
//!    every mode above 0.16 Hz is held to atol/ω in displacement — 1e-12 mm for a 10⁶ rad/s mode.
//!    vs = ω_ref makes the displacement tolerance rule modes below ω_ref and the velocity
//!    tolerance modes above it (see [`DEFAULT_VELOCITY_SCALE`]): **vs = 1e3 1/s** (ω_ref ≈ 160 Hz,
//!    between the friction bar's first two fixed-interface modes, 87 and 217 Hz).
//!
//! The same settings apply to the full and the reduced models (tolerances in mm of the physical
//! field, [`OdeProblem::atol_scale`]).

use crate::case::ContactSpec;
use crate::error::{Error, IntegrationError};
use crate::integrate::problem::{CallbackError, OdeProblem};
use crate::joint::law::{evaluate_listed_pairs, evaluate_pairs, PairLaw, PairState, DEFAULT_TAU};
use crate::system::{JointRows, SecondOrderSystem};

mod newton;
mod refresh;
mod screen;

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
    /// Pair screening (module docs, *Pair screening*): a system that offers it (the reduced
    /// model) evaluates only the pairs that may be in contact within the step; the others are
    /// proved open by a bound. Ignored with events on and by the full model. Off by default:
    /// on a joint of few pairs the set changes cost more steps than the pairs it skips save;
    /// it pays on interfaces of thousands of pairs (docs/performance/speed.md, *Pair
    /// screening*).
    pub screen: bool,
    /// The slip memory as elastic stretch (module docs, *The slip memory as elastic
    /// stretch*): the memory states of a system that offers screening (the reduced model) hold
    /// `e = u_t − s` (mm, in units of `slip_scale`) instead of `s`; the same law. Ignored with
    /// friction off, with events on and by the full model. Off by default: at equal
    /// tolerances it is less accurate than the slip form.
    pub stretch: bool,
    /// Keep the slip memory of open pairs in the reduced model's error test (module docs,
    /// *The error test of the open pairs' slip memory*). Off (the default): a reduced model's
    /// step gives the memory states of the pairs open by more than the refresh margin zero
    /// error weight, every other state the weights of the tolerances — fewer steps, the same
    /// curves to the integration tolerance (with screening, also those of the pairs outside
    /// the tracked set). On: every state is tested. The full model, and a reduced model with
    /// the stretch states, always test every state.
    pub open_slip_test: bool,
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
            screen: false,
            stretch: false,
            open_slip_test: false,
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
    /// Slip memory in mm (the states times `s_scale` plus `offset`; with `stretch`,
    /// `u_t − e` on the live pairs).
    s_phys: Vec<f64>,
    /// The memory states as elastic stretch `e = u_t − s` (module docs, *The slip memory as
    /// elastic stretch*); off: the states are the slip `s`.
    stretch: bool,
    /// With `stretch`: the elastic stretch in mm (the states times `s_scale` plus `offset`).
    e_phys: Vec<f64>,
    /// Joint kinematics of a second vector (`B v` in a right-hand side, `B r_q` in a Newton
    /// solve) on the live pairs (3w, scratch of `stretch`).
    ub: Vec<f64>,
    s_scale: f64,
    e_scale: f64,
    v_scale: f64,
    /// The co-simulation's load ([`MechanicalOde::set_load`]); `None`: the system's own load.
    load_hook: Option<LoadHook>,
    /// The pairs evaluated at a right-hand side, ascending: all of them, or the screen's
    /// tracked set.
    live: Vec<usize>,
    /// Pair screening, if on.
    screen: Option<screen::PairScreen>,
    /// The time of the load in `f` (NaN: none): a Newton solve at the time of the last
    /// right-hand side reuses it.
    f_time: f64,
    /// Rows of `B` a product needs beyond one kind of row for every pair (scratch, capacity
    /// 3w; [`SecondOrderSystem::joint_apply_rows_into`]) and that product's scratch (2w).
    rows: Vec<usize>,
    rows_scratch: Vec<f64>,
    /// Slip-memory offsets (2w with friction, mm): the memory (`s`, or `e` with `stretch`) is
    /// `slip_scale · state + offset`, zero unless a pair joined the screened set ([`screen`]).
    offset: Vec<f64>,
    /// The open pairs' memory states get zero error weight (module docs, *The error test of
    /// the open pairs' slip memory*).
    free_open_slip: bool,
    /// The gap (mm) beyond which a pair counts as open for the error weights: the refresh
    /// margin (the default's when the refresh is off).
    open_margin: f64,
    /// `B q` of the error weights' state (normal rows; 3w, scratch of `free_open_slip`).
    ewt_u: Vec<f64>,
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
            return Err(IntegrationError::NotPositive {
                what: "tau (slip relaxation time)",
                value: opts.tau,
            }
            .into());
        }
        for (name, v) in [
            ("slip_scale", opts.slip_scale),
            ("energy_scale", opts.energy_scale),
            ("velocity_scale", opts.velocity_scale),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(IntegrationError::ScaleNotPositive { name, value: v }.into());
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
        let screening = sys.joint_normal_row_norms().is_some() && !opts.events;
        let stretch = opts.stretch && opts.friction && screening;
        let free_open_slip = opts.friction
            && !opts.open_slip_test
            && sys.joint_normal_row_norms().is_some()
            && !stretch;
        let screen = if opts.screen && !opts.events {
            sys.joint_normal_row_norms()
                .map(|norms| screen::PairScreen::new(norms, n))
        } else {
            None
        };
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
            stretch,
            e_phys: vec![0.0; if stretch { 2 * w } else { 0 }],
            ub: vec![0.0; if stretch { 3 * w } else { 0 }],
            s_scale: opts.slip_scale,
            e_scale: opts.energy_scale,
            v_scale: opts.velocity_scale,
            load_hook: None,
            live: (0..w).collect(),
            screen,
            offset: vec![0.0; if opts.friction { 2 * w } else { 0 }],
            f_time: f64::NAN,
            rows: Vec::with_capacity(3 * w),
            rows_scratch: vec![0.0; 2 * w],
            free_open_slip,
            open_margin: opts.refresh.unwrap_or(DEFAULT_REFRESH_MARGIN),
            ewt_u: vec![0.0; if free_open_slip { 3 * w } else { 0 }],
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
    /// [`IntegrationError::LoadScale`] or [`IntegrationError::LoadComponent`] naming the
    /// component if `scale` or a load component is not finite.
    pub fn set_load(&mut self, scale: f64, master: [f64; 6]) -> Result<(), Error> {
        if !scale.is_finite() {
            return Err(IntegrationError::LoadScale { scale }.into());
        }
        const NAMES: [&str; 6] = ["Fx", "Fy", "Fz", "Mx", "My", "Mz"];
        if let Some(d) = master.iter().position(|v| !v.is_finite()) {
            return Err(IntegrationError::LoadComponent {
                component: NAMES[d],
                value: master[d],
            }
            .into());
        }
        self.f_time = f64::NAN;
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
        self.f_time = t;
    }

    /// `self.f = f(t)`, unless it already holds the load at `t` (a Newton solve at the time
    /// of the last right-hand side).
    fn load_at(&mut self, t: f64) {
        if self.f_time != t {
            self.total_load_into_f(t);
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

    /// Copies the slip memory of `y` into `s_phys` (mm). With `stretch` the states are the
    /// elastic stretch: it goes to `e_phys`, and the live pairs' slip `s = u_t − e` to `s_phys`
    /// from the kinematics in `u` (the caller's `B q` at the same `y`).
    fn load_slip(&mut self, y: &[f64]) {
        let i0 = 2 * self.n;
        let out = if self.stretch {
            &mut self.e_phys
        } else {
            &mut self.s_phys
        };
        for ((o, &x), &d) in out.iter_mut().zip(&y[i0..]).zip(&self.offset) {
            *o = self.s_scale * x + d;
        }
        if self.stretch {
            for &k in &self.live {
                for i in 0..2 {
                    self.s_phys[2 * k + i] = self.u[3 * k + 1 + i] - self.e_phys[2 * k + i];
                }
            }
        }
    }

    /// `u = B q` for [`MechanicalOde::sample`]: every row, or, where the system offers it
    /// and no screen is on, the normal rows and the tangential rows of the closed pairs only
    /// (an open pair's force and stored energy do not depend on them; same values).
    fn apply_for_sample(&mut self, q: &[f64]) {
        if self.rows_selectable() {
            let mut rows = std::mem::take(&mut self.rows);
            rows.clear();
            let done = self.sys.joint_apply_rows_into(
                q,
                Some(JointRows::Normal),
                &rows,
                &mut self.rows_scratch,
                &mut self.u,
            );
            if done {
                for k in 0..self.w {
                    if self.u[3 * k] < 0.0 {
                        rows.extend([3 * k + 1, 3 * k + 2]);
                    } else {
                        self.u[3 * k + 1] = 0.0;
                        self.u[3 * k + 2] = 0.0;
                    }
                }
                self.sys
                    .joint_apply_rows_into(q, None, &rows, &mut self.rows_scratch, &mut self.u);
            }
            self.rows = rows;
            if done {
                return;
            }
        }
        self.sys.joint_apply_into(q, &mut self.u);
    }

    /// Whether products of selected rows of `B` may stand in for the whole product: neither
    /// screening (its live set) nor the stretch states (their memory reads every row) is on.
    fn rows_selectable(&self) -> bool {
        self.screen.is_none() && !self.stretch
    }

    /// `u = B q` on the live pairs (all pairs without screening).
    fn apply_live(&mut self, q: &[f64]) {
        if self.screen.is_some() {
            self.sys.joint_apply_pairs_into(q, &self.live, &mut self.u);
        } else {
            self.sys.joint_apply_into(q, &mut self.u);
        }
    }

    /// `out += Bᵀ p` on the live pairs.
    fn transpose_add_live(&self, out: &mut [f64]) {
        if self.screen.is_some() {
            self.sys.joint_transpose_add_pairs(&self.p, &self.live, out);
        } else {
            self.sys.joint_transpose_add(&self.p, out);
        }
    }

    /// The pair forces `p` (3w: normal, t1, t2 per pair; N) of the last [`MechanicalOde::sample`].
    pub fn pair_forces(&self) -> &[f64] {
        &self.p
    }

    /// The slip memory `s` (2w with friction, else empty; mm) of the last
    /// [`MechanicalOde::sample`].
    pub(crate) fn slip_memory(&self) -> &[f64] {
        &self.s_phys
    }

    /// Pairs sliding at the last Newton setup.
    pub fn slipping_at_setup(&self) -> usize {
        self.slipping_at_setup
    }

    /// The initial state: at rest, undeformed, no slip, no work.
    pub(crate) fn initial_state(&self) -> Vec<f64> {
        vec![0.0; self.dim()]
    }

    /// The state `y` of an [`InitialState`](crate::integrate::InitialState): its
    /// coordinates, velocities and (with friction) slip memory, no work done yet.
    ///
    /// # Errors
    /// [`IntegrationError::InitialState`] naming the block of the wrong length or with a
    /// non-finite entry.
    pub(crate) fn state_from(
        &self,
        start: &crate::integrate::InitialState,
    ) -> Result<Vec<f64>, Error> {
        let ns = self.ns();
        let blocks: [(&'static str, &[f64], usize); 3] = [
            ("q", &start.q, self.n),
            ("v", &start.v, self.n),
            (
                "the slip memory",
                if ns > 0 { &start.slip } else { &[] },
                ns,
            ),
        ];
        let mut y = Vec::with_capacity(self.dim());
        for (what, x, need) in blocks {
            if x.len() != need || x.iter().any(|v| !v.is_finite()) {
                return Err(IntegrationError::InitialState {
                    what,
                    len: x.len(),
                    need,
                }
                .into());
            }
            y.extend_from_slice(x);
        }
        let s0 = 2 * self.n;
        if self.stretch {
            // The states hold e = u_t − s.
            for k in 0..self.w {
                let u = self.sys.joint_pair(&start.q, k);
                y[s0 + 2 * k] = u[1] - y[s0 + 2 * k];
                y[s0 + 2 * k + 1] = u[2] - y[s0 + 2 * k + 1];
            }
        }
        y[s0..].iter_mut().for_each(|s| *s /= self.s_scale);
        y.extend_from_slice(&[0.0, 0.0]);
        Ok(y)
    }

    /// Outputs at `(t, y)`: force norms, master displacement, energies.
    pub fn sample(&mut self, t: f64, y: &[f64]) -> EnergySample {
        let n = self.n;
        let (q, rest) = y.split_at(n);
        let (v, rest) = rest.split_at(n);
        let rest = &rest[self.ns()..];
        self.apply_for_sample(q);
        self.load_slip(y);
        if self.screen.is_some() && self.law.friction {
            // An untracked pair is open, its memory its tangential displacement.
            let mut live = self.live.iter().peekable();
            for k in 0..self.w {
                if live.peek() == Some(&&k) {
                    live.next();
                } else {
                    self.s_phys[2 * k] = self.u[3 * k + 1];
                    self.s_phys[2 * k + 1] = self.u[3 * k + 2];
                }
            }
        }
        let s = &self.s_phys;
        evaluate_pairs(&self.law, &self.u, s, &mut self.p, &mut self.srate);
        let mut fc = 0.0;
        let mut fr = 0.0;
        let mut pair = 0.0;
        let mut closed = 0;
        for k in 0..self.w {
            closed += usize::from(self.p[3 * k] != 0.0);
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
            closed_pairs: closed,
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
    /// Pairs in contact (a non-zero normal force: the gap closed).
    pub closed_pairs: usize,
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
        self.check_untracked(t, y);
        let (q, rest) = y.split_at(n);
        let v = &rest[..n];
        self.apply_live(q);
        self.load_slip(y);
        self.rhs_q.copy_from_slice(q);
        self.rhs_s.copy_from_slice(&y[2 * n..2 * n + ns]);
        self.rhs_u.copy_from_slice(&self.u);
        let tot = if self.screen.is_some() {
            evaluate_listed_pairs(
                &self.law,
                &self.live,
                &self.u,
                &self.s_phys,
                &mut self.p,
                &mut self.srate,
            )
        } else {
            evaluate_pairs(
                &self.law,
                &self.u,
                &self.s_phys,
                &mut self.p,
                &mut self.srate,
            )
        };
        self.total_load_into_f(t);
        self.sys.mul_k_into(q, &mut self.tmp);
        let mut tmp = std::mem::take(&mut self.tmp);
        self.transpose_add_live(&mut tmp);
        self.tmp = tmp;
        let (dq, drest) = ydot.split_at_mut(n);
        let (dv, drest) = drest.split_at_mut(n);
        dq.copy_from_slice(v);
        for ((o, fi), ki) in dv.iter_mut().zip(&self.f).zip(&self.tmp) {
            *o = fi - ki;
        }
        self.sys.solve_m_in_place(dv);
        let inv_s = 1.0 / self.s_scale;
        if self.stretch {
            // ė = u̇_t − ṡ on the live pairs; the others keep the rate they left the set with.
            if self.screen.is_some() {
                self.sys.joint_apply_pairs_into(v, &self.live, &mut self.ub);
            } else {
                self.sys.joint_apply_into(v, &mut self.ub);
            }
            match &self.screen {
                Some(sc) => sc.frozen_rates_into(&mut drest[..ns]),
                None => drest[..ns].fill(0.0),
            }
            for &k in &self.live {
                for i in 0..2 {
                    drest[2 * k + i] = inv_s * (self.ub[3 * k + 1 + i] - self.srate[2 * k + i]);
                }
            }
        } else if let Some(sc) = &self.screen {
            // Untracked pairs' memory keeps the rate it left the set with.
            sc.frozen_rates_into(&mut drest[..ns]);
            for &k in &self.live {
                for i in 2 * k..2 * k + ns.min(2) {
                    drest[i] = inv_s * self.srate[i];
                }
            }
        } else {
            for (o, &r) in drest[..ns].iter_mut().zip(&self.srate) {
                *o = inv_s * r;
            }
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

    fn adjusts_error_weights(&self) -> bool {
        self.free_open_slip
    }

    /// Zero weight for the memory states of the pairs open by more than the margin
    /// (`g > open_margin`) at the last right-hand side — the step just accepted, at its last
    /// Newton iterate — or at `y` before any, and with screening for those of the pairs
    /// outside the tracked set; every other weight as given (module docs, *The error test of
    /// the open pairs' slip memory*).
    fn adjust_error_weights(&mut self, y: &[f64], ewt: &mut [f64]) -> Result<(), CallbackError> {
        if !self.free_open_slip {
            return Ok(());
        }
        let after_rhs = self.rhs_q.first().is_some_and(|x| !x.is_nan());
        let u = if after_rhs {
            &self.rhs_u
        } else {
            let q = &y[..self.n];
            let done = self.sys.joint_apply_rows_into(
                q,
                Some(JointRows::Normal),
                &[],
                &mut self.rows_scratch,
                &mut self.ewt_u,
            );
            if !done {
                self.sys.joint_apply_into(q, &mut self.ewt_u);
            }
            &self.ewt_u
        };
        let slip = &mut ewt[2 * self.n..2 * self.n + 2 * self.w];
        let screen = self.screen.as_ref();
        for (k, (wk, uk)) in slip.chunks_exact_mut(2).zip(u.chunks_exact(3)).enumerate() {
            // An untracked pair is proven open at every right-hand side (its gap of the last
            // one was not computed) and its memory runs at its frozen rate.
            let untracked = screen.is_some_and(|sc| !sc.tracks(k));
            if untracked || uk[0] > self.open_margin {
                wk.fill(0.0);
            }
        }
        Ok(())
    }

    fn has_newton_solver(&self) -> bool {
        true
    }

    fn newton_setup(
        &mut self,
        t: f64,
        y: &[f64],
        fy: &[f64],
        jok: bool,
        gamma: f64,
    ) -> Result<bool, CallbackError> {
        self.setup_newton(t, y, fy, jok, gamma)
    }

    fn newton_solve(
        &mut self,
        t: f64,
        y: &[f64],
        r: &[f64],
        z: &mut [f64],
        gamma: f64,
    ) -> Result<(), CallbackError> {
        self.solve_newton(t, y, r, z, gamma)
    }
}
