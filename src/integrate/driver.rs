//! The one driver loop: a [`SecondOrderSystem`] with its joint law integrated from rest by
//! CVODE, sampled every `output_step`, optionally under a wall-clock deadline, with an observer
//! of the coordinates at every output. Every caller — the `transient` command, the stability
//! map, the main job's report, sweeps, POD training — runs through [`integrate`] and gets a typed
//! [`RunStatus`].
//!
//! With events on, each located root (a gap or a stick/slip switch changing sign) restarts the
//! integrator there (`CVodeReInit`: order 1, history discarded — the right-hand side is only
//! piecewise smooth across a switch); [`MAX_STALLED_ROOTS`] roots in a row without progress in
//! time end the run as [`RunStatus::Chatter`].

use std::time::{Duration, Instant};

use serde::{Serialize, Serializer};

use super::mechanical::{EnergySample, MechanicalOde, ProblemOptions, DEFAULT_MAX_ORDER};
use super::problem::{CallbackError, OdeOptions, OdeProblem, OdeStats, Stop};
use super::sundials::{Cvode, CvodeFlag};
use crate::error::{CallbackOutcome, Error};
use crate::system::{Scene, SecondOrderSystem};

/// Options of [`integrate`]. Defaults: the integrator's defaults ([`OdeOptions::default`]: BDF,
/// Newton with the structured solve, rtol 1e-8, atol 1e-6 — the paper's Table 1) except the
/// maximum order [`DEFAULT_MAX_ORDER`] = 2, velocity tolerance
/// [`super::mechanical::DEFAULT_VELOCITY_SCALE`] × atol, friction on, events off, τ = 1e-6 s,
/// outputs every 1e-4 s, the scene's end time, no wall-clock budget.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TransientOptions {
    /// Integrator options.
    pub ode: OdeOptions,
    /// Friction, events, τ.
    pub problem: ProblemOptions,
    /// Spacing of the output times, s (> 0).
    pub output_step: f64,
    /// End of the run, s (`None`: the scene's `end_time`).
    pub end_time: Option<f64>,
    /// Wall-clock budget of the integration, s (`None`: unlimited), checked in every
    /// right-hand side; running out ends the run as [`RunStatus::Budget`].
    #[serde(skip)]
    pub budget_s: Option<f64>,
    /// Keep the coordinates, pair forces and slip memory at every output in
    /// [`Run::trajectory`] (for the a-posteriori error estimate of a reduced run,
    /// [`crate::reduction::estimate`]); `false` by default.
    #[serde(skip)]
    pub record: bool,
    /// Time every callback ([`Run::profile`]): costs two clock reads per callback; `false` by
    /// default.
    #[serde(skip)]
    pub profile: bool,
}

impl Default for TransientOptions {
    fn default() -> Self {
        TransientOptions {
            ode: OdeOptions {
                max_order: DEFAULT_MAX_ORDER,
                ..OdeOptions::default()
            },
            problem: ProblemOptions::default(),
            output_step: 1e-4,
            end_time: None,
            budget_s: None,
            record: false,
            profile: false,
        }
    }
}

impl TransientOptions {
    /// The absolute resolution of a run's energy balance, N·mm: 10 × the absolute tolerance
    /// CVODE holds the energy states W and D to (`atol` × [`ProblemOptions::energy_scale`],
    /// 1e-9 N·mm by default). A run whose energies are themselves at this level (the first
    /// millisecond of a ramp: 1e-7 N·mm) cannot balance better than it, relative to anything.
    pub fn energy_resolution(&self) -> f64 {
        10.0 * self.ode.atol * self.problem.energy_scale
    }
}

/// Output curves of a run, one entry per output time.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Curves {
    /// Output times, s.
    pub t: Vec<f64>,
    /// ‖f_c‖, N.
    pub contact_force_norm: Vec<f64>,
    /// ‖f_R‖, N.
    pub friction_force_norm: Vec<f64>,
    /// Master node u_y, mm.
    pub master_uy: Vec<f64>,
    /// Kinetic energy, N·mm.
    pub kinetic: Vec<f64>,
    /// Strain energy, N·mm.
    pub strain: Vec<f64>,
    /// Pair (penalty and stick) energy, N·mm.
    pub pair: Vec<f64>,
    /// External work, N·mm.
    pub external_work: Vec<f64>,
    /// Dissipated energy, N·mm.
    pub dissipated: Vec<f64>,
}

impl Curves {
    fn push(&mut self, s: &EnergySample) {
        self.t.push(s.t);
        self.contact_force_norm.push(s.contact_force_norm);
        self.friction_force_norm.push(s.friction_force_norm);
        self.master_uy.push(s.master[1]);
        self.kinetic.push(s.kinetic);
        self.strain.push(s.strain);
        self.pair.push(s.pair);
        self.external_work.push(s.external_work);
        self.dissipated.push(s.dissipated);
    }

    /// The energy balance `E_kin + E_strain + E_pair + D − W` at each output, N·mm.
    pub fn balance(&self) -> Vec<f64> {
        (0..self.t.len())
            .map(|i| {
                self.kinetic[i] + self.strain[i] + self.pair[i] + self.dissipated[i]
                    - self.external_work[i]
            })
            .collect()
    }
}

/// The largest energy-balance residual a run may have, relative to its energy scale
/// ([`Curves::energy_check`]): clean runs measure 2e-7–2e-5 (friction bar full FE and TVD,
/// Newton and functional; multilayer), a run with k_n = 1e15 N/mm 0.57 (functional) and 1.0
/// (Newton), so a miss by 1 % is a run whose numbers cannot be trusted.
pub const ENERGY_BALANCE_TOLERANCE: f64 = 1e-2;

/// The energy balance of a run in one number: `max_t |E_kin + E_strain + E_pair + D − W|`
/// against the run's energy scale `max_t max(|W|, E_kin + E_strain + E_pair + D)`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct EnergyCheck {
    /// Largest |balance| over the outputs, N·mm (= mJ).
    pub max_residual: f64,
    /// The run's energy scale, N·mm.
    pub energy_scale: f64,
    /// `max_residual / energy_scale` (0 for a run without energy).
    pub residual_ratio: f64,
    /// [`ENERGY_BALANCE_TOLERANCE`].
    pub tolerance: f64,
    /// The absolute resolution of the balance, N·mm: what the integrator resolves of the
    /// energy states W and D ([`TransientOptions::energy_resolution`]); residuals below it are
    /// not counted against the run (a short run whose energies are at the tolerance's level).
    pub resolution: f64,
    /// `max_residual <= tolerance · energy_scale + resolution`.
    pub ok: bool,
}

impl Curves {
    /// The run's [`EnergyCheck`]; `resolution` (N·mm) is the run's
    /// [`TransientOptions::energy_resolution`].
    pub fn energy_check(&self, resolution: f64) -> EnergyCheck {
        let mut max_residual = 0.0f64;
        let mut energy_scale = 0.0f64;
        for (i, b) in self.balance().into_iter().enumerate() {
            let stored = self.kinetic[i] + self.strain[i] + self.pair[i] + self.dissipated[i];
            energy_scale = energy_scale.max(self.external_work[i].abs()).max(stored);
            // NaN (a run gone wrong) counts as the largest residual.
            max_residual = if b.is_nan() {
                f64::INFINITY
            } else {
                max_residual.max(b.abs())
            };
        }
        let residual_ratio = if energy_scale > 0.0 {
            max_residual / energy_scale
        } else if max_residual > 0.0 {
            f64::INFINITY
        } else {
            0.0
        };
        EnergyCheck {
            max_residual,
            energy_scale,
            residual_ratio,
            tolerance: ENERGY_BALANCE_TOLERANCE,
            resolution,
            ok: max_residual <= ENERGY_BALANCE_TOLERANCE * energy_scale + resolution,
        }
    }
}

/// The states of a run at its output times ([`TransientOptions::record`]), each block stored
/// output after output.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Trajectory {
    /// Coordinates per output (n or r values each): mm, rad or generalized coordinates.
    pub q: Vec<f64>,
    /// Pair forces per output (3w each: normal, t1, t2 per pair), N.
    pub p: Vec<f64>,
    /// Slip memory per output (2w each with friction, else none), mm.
    pub s: Vec<f64>,
}

impl Trajectory {
    /// Appends one output: `q` and the forces and slip memory of the problem's last sample.
    fn push<S: SecondOrderSystem>(&mut self, q: &[f64], ode: &MechanicalOde<S>) {
        self.q.extend_from_slice(q);
        self.p.extend_from_slice(ode.pair_forces());
        self.s.extend_from_slice(ode.slip_memory());
    }
}

/// How a run ended. Serialized as its [`RunStatus::name`].
#[derive(Clone, Debug, PartialEq)]
pub enum RunStatus {
    /// The end time was reached.
    Finished,
    /// The wall-clock budget ran out at `t` (s).
    Budget {
        /// Time reached, s.
        t: f64,
    },
    /// Events: [`MAX_STALLED_ROOTS`] roots in a row without progress in time at `t` (s).
    Chatter {
        /// Time reached, s.
        t: f64,
    },
    /// A SUNDIALS call failed (`function` returned `flag`), or a problem callback failed and
    /// made CVODE return `flag` (`callback` names it) at `t` (s).
    Failed {
        /// The C function that failed (`CVode`, `CVodeReInit`, ...).
        function: &'static str,
        /// Its return flag.
        flag: CvodeFlag,
        /// The callback whose failure caused it, if any.
        callback: Option<&'static str>,
        /// Time reached, s.
        t: f64,
    },
    /// Anything else (the system or the integrator could not be set up, an invalid option).
    Error,
}

impl RunStatus {
    /// `ok`, the CVODE flag's name (`CV_TOO_MUCH_WORK`, `CV_CONV_FAILURE`, ...), `sundials` or
    /// `callback` for a failure without a CVODE flag name, `budget`, `chatter` or `error`.
    pub fn name(&self) -> &str {
        match self {
            RunStatus::Finished => "ok",
            RunStatus::Budget { .. } => "budget",
            RunStatus::Chatter { .. } => "chatter",
            RunStatus::Failed { flag, .. } if flag.name.starts_with("CV_") => &flag.name,
            RunStatus::Failed { callback: None, .. } => "sundials",
            RunStatus::Failed { .. } => "callback",
            RunStatus::Error => "error",
        }
    }

    /// Whether the run reached its end.
    pub fn finished(&self) -> bool {
        *self == RunStatus::Finished
    }

    /// The status of a run that failed with `e` at `t` (s); `budget`: the deadline had passed.
    fn of_error(e: &Error, t: f64, budget: bool) -> RunStatus {
        if budget {
            return RunStatus::Budget { t };
        }
        match e {
            Error::Sundials { function, flag, .. } => RunStatus::Failed {
                function,
                flag: flag.clone(),
                callback: None,
                t,
            },
            Error::Callback {
                callback,
                outcome: CallbackOutcome::Returned { flag, .. },
                ..
            } => RunStatus::Failed {
                function: "CVode",
                flag: flag.clone(),
                callback: Some(callback),
                t,
            },
            _ => RunStatus::Error,
        }
    }
}

impl std::fmt::Display for RunStatus {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl Serialize for RunStatus {
    fn serialize<Z: Serializer>(&self, s: Z) -> Result<Z::Ok, Z::Error> {
        s.serialize_str(self.name())
    }
}

/// The result of [`integrate`]: status, statistics, timings and the curves up to the time
/// reached.
#[derive(Debug, Serialize)]
pub struct Run {
    /// How the run ended.
    pub status: RunStatus,
    /// Time reached, s.
    pub t_reached: f64,
    /// Integrator statistics.
    pub stats: OdeStats,
    /// Wall-clock time of the integration (excluding the system's construction), s.
    pub wall_s: f64,
    /// CPU time of the integrating thread, s (NaN where unavailable).
    pub cpu_s: f64,
    /// Events located (and re-initialisations done) with events on.
    pub events: u64,
    /// Output curves (from t = 0 to the last output reached).
    pub curves: Curves,
    /// Final state `y` (q, v, s, W, D).
    pub final_state: Vec<f64>,
    /// The states at the output times (the times are `curves.t`), with
    /// [`TransientOptions::record`].
    #[serde(skip)]
    pub trajectory: Option<Trajectory>,
    /// Wall time per kind of callback, with [`TransientOptions::profile`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub profile: Option<Profile>,
    /// The error that ended a run that did not finish.
    #[serde(skip)]
    pub failure: Option<Error>,
}

/// Where a run's wall time went ([`TransientOptions::profile`]): the problem's callbacks, timed
/// one by one, and the rest — CVODE's own work (prediction, error test, step and order
/// selection, vector operations) and the output sampling.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Profile {
    /// Right-hand sides: calls and wall time, s.
    pub rhs_calls: u64,
    pub rhs_s: f64,
    /// Newton setups (linearization and factorization).
    pub setup_calls: u64,
    pub setup_s: f64,
    /// Newton solves (including the active-set refreshes they trigger).
    pub solve_calls: u64,
    pub solve_s: f64,
    /// The run's wall time minus the callbacks, s.
    pub other_s: f64,
}

impl Run {
    /// The run if it finished, else the error that ended it.
    pub fn into_result(self) -> Result<Run, Error> {
        match self.failure {
            Some(e) => Err(e),
            None => Ok(self),
        }
    }

    /// A run that could not start: its system or options failed with `e`.
    pub fn failed(e: Error) -> Run {
        Run {
            status: RunStatus::of_error(&e, 0.0, false),
            t_reached: 0.0,
            stats: OdeStats::default(),
            wall_s: 0.0,
            cpu_s: 0.0,
            events: 0,
            curves: Curves::default(),
            final_state: Vec::new(),
            trajectory: None,
            profile: None,
            failure: Some(e),
        }
    }
}

/// The most output points a run keeps (`end_time / output_step`): 10⁶ samples of every curve
/// are ~100 MB with the energies; beyond that a typo (`--output-step 1e-300`, `--end-time
/// 1e308`) would run forever with growing memory.
pub const MAX_OUTPUTS: f64 = 1e6;

/// Wall-clock budget of one command-line integration unless `--max-wall` says otherwise, s
/// (an hour: the full FE friction bar's 0.2 s takes 3–7 s, the slowest stored stability cell
/// 20 s).
pub const DEFAULT_MAX_WALL_S: f64 = 3600.0;

/// The number of output intervals of a run over `[0, end]` every `output_step` (both s), or an
/// error past [`MAX_OUTPUTS`].
pub fn output_count(end: f64, output_step: f64) -> Result<usize, Error> {
    let n = (end / output_step - 1e-9).ceil().max(1.0);
    // NaN (0/0) fails the comparison too.
    if n.is_nan() || n > MAX_OUTPUTS {
        return Err(Error::Invalid(format!(
            "end time {end:e} s / output step {output_step:e} s = {n:e} output points, more than \
             the {MAX_OUTPUTS:e} a run keeps: raise --output-step or lower --end-time"
        )));
    }
    Ok(n as usize)
}

/// The first output quantity of `s` that is NaN or infinite, by name: an integrator can step
/// on with finite coordinates while a pair force overflows (k_n = 1e300 N/mm), and such a run
/// must not count as finished.
pub(super) fn non_finite(s: &super::mechanical::EnergySample) -> Option<&'static str> {
    let named = [
        ("contact force norm", s.contact_force_norm),
        ("friction force norm", s.friction_force_norm),
        ("kinetic energy", s.kinetic),
        ("strain energy", s.strain),
        ("pair energy", s.pair),
        ("external work", s.external_work),
        ("dissipated energy", s.dissipated),
    ];
    named
        .iter()
        .find(|(_, v)| !v.is_finite())
        .map(|(n, _)| *n)
        .or_else(|| {
            (0..6).find(|&k| !s.master[k].is_finite()).map(|k| {
                [
                    "master ux",
                    "master uy",
                    "master uz",
                    "master rx",
                    "master ry",
                    "master rz",
                ][k]
            })
        })
}

/// Roots in a row at the same time after which a run is [`RunStatus::Chatter`].
pub const MAX_STALLED_ROOTS: usize = 1000;

/// CPU time of the calling thread, s (NaN where unavailable): a run's own cost even while
/// other runs share the process (rayon sweeps).
pub fn thread_cpu_s() -> f64 {
    cpu_time::ThreadTime::try_now()
        .map(|t| t.as_duration().as_secs_f64())
        .unwrap_or(f64::NAN)
}

/// Integrates `system` under `scene` from rest over `[0, end]` (end: `opts.end_time` or the
/// scene's) and samples the outputs every `opts.output_step`; `observe(t, q)` sees the
/// coordinates at t = 0 and at every output. Never fails as a whole: a setup or integration
/// failure, the budget running out or chattering events become the run's [`RunStatus`], with
/// the curves up to the time reached and the error in [`Run::failure`] ([`Run::into_result`]
/// turns it into a `Result`).
pub fn integrate<S: SecondOrderSystem>(
    system: S,
    scene: &Scene,
    opts: &TransientOptions,
    observe: impl FnMut(f64, &[f64]),
) -> Run {
    match Driver::new(system, scene, opts) {
        Ok(d) => d.run(observe),
        Err(e) => Run::failed(e),
    }
}

/// [`integrate`] without an observer, as a `Result`: the run if it finished, else its error.
///
/// # Errors
/// [`Error::Invalid`] for a non-positive or non-finite `output_step`/`end_time` or `tau`; any
/// integrator error ([`Error::Sundials`] with the flag and time reached, callback errors, a
/// chattering switch).
pub fn run<S: SecondOrderSystem>(
    system: S,
    scene: &Scene,
    opts: &TransientOptions,
) -> Result<Run, Error> {
    integrate(system, scene, opts, |_, _| {}).into_result()
}

/// A problem with an optional wall-clock deadline checked in every right-hand side.
struct Deadline<P> {
    inner: P,
    deadline: Option<Instant>,
    /// The budget behind `deadline`, s.
    budget_s: f64,
    exceeded: bool,
    profile: Option<Profile>,
}

/// `f()` timed into `slot` (calls, seconds) when profiling.
fn timed<T>(profile: bool, slot: (&mut u64, &mut f64), f: impl FnOnce() -> T) -> T {
    if !profile {
        return f();
    }
    let start = Instant::now();
    let out = f();
    *slot.0 += 1;
    *slot.1 += start.elapsed().as_secs_f64();
    out
}

impl<P: OdeProblem> OdeProblem for Deadline<P> {
    fn dim(&self) -> usize {
        self.inner.dim()
    }
    fn rhs(&mut self, t: f64, y: &[f64], ydot: &mut [f64]) -> Result<(), CallbackError> {
        if let Some(d) = self.deadline {
            if Instant::now() > d {
                self.exceeded = true;
                return Err(CallbackError::Fatal(format!(
                    "wall-clock budget of {} s exceeded (--max-wall)",
                    self.budget_s
                )));
            }
        }
        let mut p = self.profile.take();
        let on = p.is_some();
        let mut none = (0, 0.0);
        let slot = match &mut p {
            Some(p) => (&mut p.rhs_calls, &mut p.rhs_s),
            None => (&mut none.0, &mut none.1),
        };
        let out = timed(on, slot, || self.inner.rhs(t, y, ydot));
        self.profile = p;
        out
    }
    fn num_roots(&self) -> usize {
        self.inner.num_roots()
    }
    fn roots(&mut self, t: f64, y: &[f64], g: &mut [f64]) -> Result<(), CallbackError> {
        self.inner.roots(t, y, g)
    }
    fn atol_scale(&self, scale: &mut [f64]) -> bool {
        self.inner.atol_scale(scale)
    }
    fn has_newton_solver(&self) -> bool {
        self.inner.has_newton_solver()
    }
    fn newton_setup(
        &mut self,
        t: f64,
        y: &[f64],
        fy: &[f64],
        jok: bool,
        gamma: f64,
    ) -> Result<bool, CallbackError> {
        let mut p = self.profile.take();
        let on = p.is_some();
        let mut none = (0, 0.0);
        let slot = match &mut p {
            Some(p) => (&mut p.setup_calls, &mut p.setup_s),
            None => (&mut none.0, &mut none.1),
        };
        let out = timed(on, slot, || self.inner.newton_setup(t, y, fy, jok, gamma));
        self.profile = p;
        out
    }
    fn newton_solve(
        &mut self,
        t: f64,
        y: &[f64],
        r: &[f64],
        z: &mut [f64],
        gamma: f64,
    ) -> Result<(), CallbackError> {
        let mut p = self.profile.take();
        let on = p.is_some();
        let mut none = (0, 0.0);
        let slot = match &mut p {
            Some(p) => (&mut p.solve_calls, &mut p.solve_s),
            None => (&mut none.0, &mut none.1),
        };
        let out = timed(on, slot, || self.inner.newton_solve(t, y, r, z, gamma));
        self.profile = p;
        out
    }
}

/// The state of one run between setup and the end.
struct Driver<S: SecondOrderSystem> {
    cv: Cvode<Deadline<MechanicalOde<S>>>,
    dim: usize,
    end: f64,
    output_step: f64,
    curves: Curves,
    trajectory: Option<Trajectory>,
    y0: Vec<f64>,
    roots: RootGuard,
}

impl<S: SecondOrderSystem> Driver<S> {
    fn new(system: S, scene: &Scene, opts: &TransientOptions) -> Result<Driver<S>, Error> {
        let end = opts.end_time.unwrap_or(scene.end_time);
        if !(end.is_finite() && end > 0.0) {
            return Err(Error::Invalid(format!(
                "end_time must be finite and positive, got {end} s"
            )));
        }
        if !(opts.output_step.is_finite() && opts.output_step > 0.0) {
            return Err(Error::Invalid(format!(
                "output_step must be finite and positive, got {} s",
                opts.output_step
            )));
        }
        output_count(end, opts.output_step)?;
        if let Some(b) = opts.budget_s {
            if !(b.is_finite() && b > 0.0) {
                return Err(Error::Invalid(format!(
                    "the wall-clock budget must be finite and positive, got {b} s"
                )));
            }
        }
        let mut ode = MechanicalOde::new(system, &scene.contact, &opts.problem)?;
        let dim = ode.coords();
        let y0 = ode.initial_state();
        let mut curves = Curves::default();
        curves.push(&ode.sample(0.0, &y0));
        let trajectory = opts.record.then(|| {
            let mut tr = Trajectory::default();
            tr.push(&y0[..dim], &ode);
            tr
        });
        let problem = Deadline {
            inner: ode,
            deadline: opts
                .budget_s
                .map(|b| Instant::now() + Duration::from_secs_f64(b)),
            budget_s: opts.budget_s.unwrap_or(f64::INFINITY),
            exceeded: false,
            profile: opts.profile.then(Profile::default),
        };
        let cv = Cvode::new(problem, 0.0, &y0, &opts.ode)?;
        Ok(Driver {
            cv,
            dim,
            end,
            output_step: opts.output_step,
            curves,
            trajectory,
            y0,
            roots: RootGuard::new(),
        })
    }

    fn run(mut self, mut observe: impl FnMut(f64, &[f64])) -> Run {
        observe(0.0, &self.y0[..self.dim]);
        let wall = Instant::now();
        let cpu0 = thread_cpu_s();
        let outputs = output_count(self.end, self.output_step).unwrap_or(1);
        let mut failure = None;
        for k in 1..=outputs {
            let tout = (k as f64 * self.output_step).min(self.end);
            if let Err(e) = self.roots.advance_to(&mut self.cv, tout) {
                failure = Some(e);
                break;
            }
            let t = self.cv.t();
            let y = self.cv.y().to_vec();
            let s = self.cv.problem_mut().inner.sample(t, &y);
            self.curves.push(&s);
            if let Some(what) = non_finite(&s) {
                failure = Some(Error::Invalid(format!(
                    "the run's {what} is not finite at t = {t} s (an overflow: check k_n, k_t \
                     and the load)"
                )));
                break;
            }
            if let Some(tr) = &mut self.trajectory {
                tr.push(&y[..self.dim], &self.cv.problem().inner);
            }
            observe(t, &y[..self.dim]);
        }
        let wall_s = wall.elapsed().as_secs_f64();
        let cpu_s = thread_cpu_s() - cpu0;
        let t_reached = self.cv.t();
        let status = match &failure {
            None => RunStatus::Finished,
            Some(Error::Chatter { .. }) => RunStatus::Chatter { t: t_reached },
            Some(e) => RunStatus::of_error(e, t_reached, self.cv.problem().exceeded),
        };
        let mut stats = self.cv.stats();
        stats.newton_refreshes = self.cv.problem().inner.refreshes();
        stats.newton_low_rank = self.cv.problem().inner.low_rank_refreshes();
        stats.newton_refresh_pairs = self.cv.problem().inner.refresh_pairs();
        let profile = self.cv.problem().profile.clone().map(|mut p| {
            p.other_s = wall_s - p.rhs_s - p.setup_s - p.solve_s;
            p
        });
        Run {
            status,
            t_reached,
            stats,
            wall_s,
            cpu_s,
            events: self.roots.events,
            curves: self.curves,
            final_state: self.cv.y().to_vec(),
            trajectory: self.trajectory,
            profile,
            failure,
        }
    }
}

/// Event handling shared by the driver loop and [`super::Stepper`]: integrates to an output time,
/// re-initialising at every root, and ends a chattering switch ([`MAX_STALLED_ROOTS`] roots in
/// a row without progress in time) with [`Error::Chatter`].
#[derive(Clone, Debug)]
pub(super) struct RootGuard {
    /// Events located (and re-initialisations done).
    pub(super) events: u64,
    last_root_t: f64,
    stalled: usize,
}

impl RootGuard {
    pub(super) fn new() -> RootGuard {
        RootGuard {
            events: 0,
            last_root_t: f64::NEG_INFINITY,
            stalled: 0,
        }
    }

    /// Integrates `cv` to `tout`, re-initialising at every root.
    pub(super) fn advance_to<P: OdeProblem>(
        &mut self,
        cv: &mut Cvode<P>,
        tout: f64,
    ) -> Result<(), Error> {
        loop {
            match cv.solve_to(tout)? {
                Stop::Reached(_) => return Ok(()),
                Stop::Root { t, .. } => {
                    self.events += 1;
                    // Guard against chattering: roots that make no progress in time.
                    if t - self.last_root_t <= 1e-13 * t.abs().max(1e-3) {
                        self.stalled += 1;
                        if self.stalled > MAX_STALLED_ROOTS {
                            return Err(Error::Chatter {
                                roots: MAX_STALLED_ROOTS,
                                time: t,
                            });
                        }
                    } else {
                        self.stalled = 0;
                    }
                    self.last_root_t = t;
                    let y = cv.y().to_vec();
                    cv.reinit(t, &y)?;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Curves of one output point with the given energies (N·mm).
    fn one(kinetic: f64, strain: f64, work: f64) -> Curves {
        Curves {
            t: vec![0.1],
            contact_force_norm: vec![0.0],
            friction_force_norm: vec![0.0],
            master_uy: vec![0.0],
            kinetic: vec![kinetic],
            strain: vec![strain],
            pair: vec![0.0],
            external_work: vec![work],
            dissipated: vec![0.0],
        }
    }

    #[test]
    fn energy_check_counts_relative_misses_beyond_the_resolution() {
        let res = TransientOptions::default().energy_resolution();
        assert!((res - 1e-8).abs() < 1e-20, "default resolution {res}");
        // Balanced to 1e-6 of the energy: ok.
        assert!(one(40.0, 60.0, 100.0 + 1e-4).energy_check(res).ok);
        // Off by 5 % of the energy: not ok, whatever the resolution.
        let c = one(40.0, 65.0, 100.0).energy_check(res);
        assert!(!c.ok && (c.residual_ratio - 5.0 / 105.0).abs() < 1e-12);
        // Energies at the integrator's own resolution: a 10 % miss of 1e-7 N·mm is 1e-8.
        let tiny = one(4e-8, 6e-8, 1.1e-7);
        assert!(tiny.energy_check(res).ok);
        assert!(!tiny.energy_check(0.0).ok);
        // NaN anywhere is a failed balance.
        assert!(!one(f64::NAN, 1.0, 1.0).energy_check(res).ok);
    }
}
