//! The one driver loop: a [`SecondOrderSystem`] with its joint law integrated from rest (or
//! from a given [`InitialState`], under a constant load: a free decay) by CVODE, sampled every `output_step`, optionally under a wall-clock deadline, with an observer
//! of the coordinates at every output. Every caller — the `transient` command, the stability
//! map, the main job's report, sweeps, POD training — runs through [`integrate`] and gets a typed
//! [`RunStatus`].
//!
//! With events on, each located root (a gap or a stick/slip switch changing sign) restarts the
//! integrator there (`CVodeReInit`: order 1, history discarded — the right-hand side is only
//! piecewise smooth across a switch); [`MAX_STALLED_ROOTS`] roots in a row without progress in
//! time end the run as [`RunStatus::Chatter`].
//!
//! A run's options are in `options`, what it returns (status, curves, timings) in `outcome`.

use std::time::{Duration, Instant};

use super::mechanical::MechanicalOde;
use super::problem::{CallbackError, OdeProblem, OdeStats, Stop};
use super::sundials::Integrator;
use crate::error::Error;
use crate::system::{Scene, SecondOrderSystem};

mod options;
mod outcome;
mod stall;

pub use options::{
    dirk_table_flag, positive_flag, InitialState, RunChoices, RunHook, TransientOptions,
};
pub use outcome::{
    Curves, EnergyCheck, Profile, Run, RunStatus, Trajectory, ENERGY_BALANCE_TOLERANCE,
};
pub use stall::Stall;

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
        return Err(crate::error::IntegrationError::TooManyOutputs {
            end,
            output_step,
            outputs: n,
            max: MAX_OUTPUTS,
        }
        .into());
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
/// [`crate::error::IntegrationError`] for a non-positive or non-finite `output_step`/`end_time`
/// or `tau`; any integrator error ([`Error::Sundials`] with the flag and time reached, callback
/// errors, a chattering switch).
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
    hook: Option<RunHook>,
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
        if self.hook.as_ref().is_some_and(|h| !(h.0)(t)) {
            self.exceeded = true;
            return Err(CallbackError::Fatal("stopped by the caller".into()));
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
    fn adjusts_error_weights(&self) -> bool {
        self.inner.adjusts_error_weights()
    }
    fn adjust_error_weights(&mut self, y: &[f64], ewt: &mut [f64]) -> Result<(), CallbackError> {
        self.inner.adjust_error_weights(y, ewt)
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
    cv: Integrator<Deadline<MechanicalOde<S>>>,
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
            return Err(crate::error::IntegrationError::NotPositive {
                what: "end_time",
                value: end,
            }
            .into());
        }
        if !(opts.output_step.is_finite() && opts.output_step > 0.0) {
            return Err(crate::error::IntegrationError::NotPositive {
                what: "output_step",
                value: opts.output_step,
            }
            .into());
        }
        let outputs = output_count(end, opts.output_step)?;
        if let Some(b) = opts.budget_s {
            if !(b.is_finite() && b > 0.0) {
                return Err(crate::error::IntegrationError::NotPositive {
                    what: "the wall-clock budget",
                    value: b,
                }
                .into());
            }
        }
        let mut ode = MechanicalOde::new(system, &scene.contact, &opts.problem)?;
        if let Some(f) = opts.constant_load {
            ode.set_load(0.0, f)?;
        }
        let dim = ode.coords();
        let y0 = match &opts.start {
            Some(s) => ode.state_from(s)?,
            None => ode.initial_state(),
        };
        let mut curves = Curves::default();
        curves.push(&ode.sample(0.0, &y0));
        let trajectory = opts.record.then(|| {
            // Room for every output at once: no regrowth (and copy) of the largest arrays.
            let mut tr = Trajectory::with_capacity(outputs + 1, &y0[..dim], &ode);
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
            hook: opts.hook.clone(),
        };
        let cv = Integrator::new(problem, 0.0, &y0, &opts.ode)?;
        Ok(Driver {
            cv,
            dim,
            end,
            output_step: opts.output_step,
            curves,
            trajectory,
            y0,
            roots: RootGuard::watched(stall::StallWatch::new(
                0.0,
                opts.ode.method.order(opts.ode.max_order),
                opts.problem.velocity_scale,
            )),
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
            if let Some(e) = self.roots.watch_output(t, &self.cv.stats()) {
                failure = Some(e);
                break;
            }
            let y = self.cv.y().to_vec();
            let s = self.cv.problem_mut().inner.sample(t, &y);
            self.curves.push(&s);
            if let Some(what) = non_finite(&s) {
                failure = Some(crate::error::IntegrationError::OutputNotFinite { what, t }.into());
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
        let stalled = self.roots.watch.as_ref().and_then(|w| w.stalled);
        let status = match (&failure, stalled) {
            (Some(_), Some(reason)) => RunStatus::Stalled {
                t: t_reached,
                reason,
            },
            (failure, _) => match failure {
                None => RunStatus::Finished,
                Some(Error::Chatter { .. }) => RunStatus::Chatter { t: t_reached },
                Some(e) => RunStatus::of_error(e, t_reached, self.cv.problem().exceeded),
            },
        };
        let mut stats = self.cv.stats();
        stats.newton_refreshes = self.cv.problem().inner.refreshes();
        stats.newton_low_rank = self.cv.problem().inner.low_rank_refreshes();
        stats.newton_refresh_pairs = self.cv.problem().inner.refresh_pairs();
        self.cv.problem().inner.add_screen_stats(&mut stats);
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

/// The error of a run stopped at `t` (s) because it crawls.
fn stalled_error(t: f64, reason: &str) -> Error {
    crate::error::IntegrationError::Stalled {
        t,
        reason: reason.to_string(),
    }
    .into()
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
    /// The driver's watch for runs that crawl (none in a co-simulation).
    watch: Option<stall::StallWatch>,
}

impl RootGuard {
    pub(super) fn new() -> RootGuard {
        RootGuard {
            events: 0,
            last_root_t: f64::NEG_INFINITY,
            stalled: 0,
            watch: None,
        }
    }

    /// A guard that also stops a run that crawls ([`Stall`]).
    fn watched(watch: stall::StallWatch) -> RootGuard {
        RootGuard {
            watch: Some(watch),
            ..RootGuard::new()
        }
    }

    /// At an output at `t`: the error that stops a run that crawls, if it does.
    fn watch_output(&mut self, t: f64, stats: &OdeStats) -> Option<Error> {
        let events = self.events;
        let reason = self.watch.as_mut()?.at_output(t, stats, events)?;
        Some(stalled_error(t, &reason))
    }

    /// Integrates `cv` to `tout`, re-initialising at every root.
    pub(super) fn advance_to<P: OdeProblem>(
        &mut self,
        cv: &mut Integrator<P>,
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
                    if let Some(w) = &mut self.watch {
                        if let Some(reason) = w.at_root(t, &cv.stats(), self.events) {
                            return Err(stalled_error(t, &reason));
                        }
                    }
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

    /// Curves from rest (t = 0, every energy zero: the balance is counted from there) to one
    /// output point with the given energies (N·mm).
    fn one(kinetic: f64, strain: f64, work: f64) -> Curves {
        Curves {
            t: vec![0.0, 0.1],
            contact_force_norm: vec![0.0; 2],
            friction_force_norm: vec![0.0; 2],
            master_uy: vec![0.0; 2],
            kinetic: vec![0.0, kinetic],
            strain: vec![0.0, strain],
            pair: vec![0.0; 2],
            external_work: vec![0.0, work],
            dissipated: vec![0.0; 2],
            closed_pairs: vec![0; 2],
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
