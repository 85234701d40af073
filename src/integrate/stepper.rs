//! Stepping a run from outside, for co-simulation (an FMU, [`crate::report::fmu`]): the
//! integrator is created once, then advanced from communication point to communication point
//! while the caller changes the master load between calls.
//!
//! ## The problem
//!
//! The same mechanical ODE as every run ([`MechanicalOde`], from rest, the same CVODE setup:
//! pass [`crate::integrate::TransientOptions::default`]'s `ode` and `problem` to get the
//! `transient` command's), with the load of the system replaced by
//!
//! ```text
//! f(t) = λ · f_system(t) + F_ext,      F_ext = Φ_mᵀ [Fx, Fy, Fz, Mx, My, Mz]   (reduced)
//! ```
//!
//! ([`MechanicalOde::set_load`]): λ scales the model's own load history, `F_ext` is a master
//! load held constant over each communication step (a zero-order hold: FMI 2.0 co-simulation
//! without input interpolation).
//!
//! ## Restarts
//!
//! [`Stepper::advance`] integrates with CVODE's `CV_NORMAL` task and no stop time, exactly as
//! the driver loop does ([`crate::integrate::integrate`]): CVODE takes its own steps, possibly
//! past the communication point, and interpolates the state there. While the load is unchanged
//! this is the same sequence of CVODE calls as a run with outputs at the communication points,
//! so a stepped run with the default load reproduces `jointrom transient` **bit for bit** (a
//! stop time at every communication point would shorten steps and change the results at the
//! level of the integration error). When [`Stepper::set_load`] changes the load, the history
//! CVODE built past the communication point used the old load and is useless; the next
//! [`Stepper::advance`] therefore re-initialises CVODE at the communication point with the
//! interpolated state (`CVodeReInit`: order 1, history discarded — the right-hand side jumps
//! there) and the new load applies from that point on, as the hold requires. A caller whose
//! inputs change at every step thus pays one restart per step; a caller with constant inputs
//! pays nothing.
//!
//! Events (if on) are handled as in the driver loop: a re-initialisation at every root, and a
//! chattering switch ends the step with [`Error::Chatter`].
//!
//! Step budget: [`OdeOptions::max_steps`] applies to each [`Stepper::advance`] (a co-simulation
//! runs for as long as its importer wants; a run's budget of 10⁶ steps would end it after ~20 s
//! of the friction bar's simulated time).
//!
//! Allocation: none in the callbacks; one copy of the state per [`Stepper::advance`] into a
//! buffer allocated once, and one vector per load change.

use super::driver::{non_finite, RootGuard};
use super::mechanical::{EnergySample, MechanicalOde, ProblemOptions};
use super::problem::{OdeOptions, OdeProblem, OdeStats};
use super::sundials::Integrator;
use crate::case::ContactSpec;
use crate::error::{Error, IntegrationError};
use crate::system::SecondOrderSystem;

/// A mechanical run advanced from outside (see the module docs).
pub struct Stepper<S: SecondOrderSystem> {
    cv: Integrator<MechanicalOde<S>>,
    roots: RootGuard,
    /// The load changed since CVODE's history was built: re-initialise before the next step.
    restart: bool,
    /// Re-initialisations done for load changes.
    restarts: u64,
    /// Internal steps allowed per [`Stepper::advance`] ([`OdeOptions::max_steps`]).
    steps_per_advance: u64,
    /// The outputs at the current time.
    last: EnergySample,
    /// The state at the current time (a buffer for sampling).
    y: Vec<f64>,
}

impl<S: SecondOrderSystem> Stepper<S> {
    /// A run of `system` with the contact law `contact` from rest at `t0` (s), with the
    /// system's own load until [`Stepper::set_load`].
    ///
    /// # Errors
    /// [`Error::Integration`] for a non-finite `t0` or a bad option (naming it), errors of the
    /// integrator's setup ([`Error::Sundials`] naming the C function).
    pub fn new(
        system: S,
        t0: f64,
        contact: &ContactSpec,
        ode: &OdeOptions,
        problem: &ProblemOptions,
    ) -> Result<Stepper<S>, Error> {
        if !t0.is_finite() {
            return Err(IntegrationError::StartTime { t0 }.into());
        }
        let mut mech = MechanicalOde::new(system, contact, problem)?;
        let y = mech.initial_state();
        let last = mech.sample(t0, &y);
        let cv = Integrator::new(mech, t0, &y, ode)?;
        Ok(Stepper {
            cv,
            roots: RootGuard::new(),
            restart: false,
            restarts: 0,
            steps_per_advance: ode.max_steps as u64,
            last,
            y,
        })
    }

    /// The current time, s.
    pub fn t(&self) -> f64 {
        self.cv.t()
    }

    /// The outputs at the current time (force norms, master displacement, energies).
    pub fn sample(&self) -> &EnergySample {
        &self.last
    }

    /// The state `y = [q, v, s, W, D]` at the current time (see [`MechanicalOde`]).
    pub fn state(&self) -> &[f64] {
        self.cv.y()
    }

    /// The load from now on: the system's own load history times `scale` (dimensionless) plus
    /// the master-node load `master = [Fx, Fy, Fz (N), Mx, My, Mz (N·mm)]`, held constant. A
    /// change from the load in force makes the next [`Stepper::advance`] restart CVODE at the
    /// current time (module docs); setting the same load again changes nothing.
    ///
    /// # Errors
    /// [`IntegrationError::LoadScale`] or [`IntegrationError::LoadComponent`] naming the value
    /// if one is not finite (the load in force is kept).
    pub fn set_load(&mut self, scale: f64, master: [f64; 6]) -> Result<(), Error> {
        let (old_scale, old_master) = self.cv.problem().load();
        // Bit patterns: −0.0 and 0.0 are the same load; a NaN is refused below.
        if scale == old_scale && master == old_master {
            return Ok(());
        }
        self.cv.problem_mut().set_load(scale, master)?;
        self.restart = true;
        Ok(())
    }

    /// The load in force: `(scale, master load)` as given to [`Stepper::set_load`].
    pub fn load(&self) -> (f64, [f64; 6]) {
        self.cv.problem().load()
    }

    /// Integrates to `t_next` (s, after the current time) and returns the outputs there.
    ///
    /// # Errors
    /// [`Error::Integration`] for a `t_next` that is not finite or not after the current time, or
    /// an output that is not finite at `t_next` (an overflow); integrator failures
    /// ([`Error::Sundials`] with the flag and the time reached — `CV_TOO_MUCH_WORK` after
    /// [`OdeOptions::max_steps`] internal steps in this advance —, [`Error::Callback`],
    /// [`Error::Chatter`]). After an error the time and state are the last ones CVODE reached
    /// and the outputs those of the last successful step.
    pub fn advance(&mut self, t_next: f64) -> Result<&EnergySample, Error> {
        let t = self.cv.t();
        if !(t_next.is_finite() && t_next > t) {
            return Err(IntegrationError::StepEnd { t, t_next }.into());
        }
        if self.restart {
            self.y.copy_from_slice(self.cv.y());
            self.cv.reinit(t, &self.y)?;
            self.restart = false;
            self.restarts += 1;
        }
        let budget = self.cv.stats().steps.saturating_add(self.steps_per_advance);
        self.cv.set_max_steps(budget);
        self.roots.advance_to(&mut self.cv, t_next)?;
        let t = self.cv.t();
        self.y.copy_from_slice(self.cv.y());
        let s = self.cv.problem_mut().sample(t, &self.y);
        if let Some(what) = non_finite(&s) {
            return Err(IntegrationError::OutputNotFinite { what, t }.into());
        }
        self.last = s;
        Ok(&self.last)
    }

    /// Integrator statistics since the start (steps, Newton iterations, ...), with the
    /// problem's active-set refreshes.
    pub fn stats(&self) -> OdeStats {
        let mut stats = self.cv.stats();
        stats.newton_refreshes = self.cv.problem().refreshes();
        stats.newton_low_rank = self.cv.problem().low_rank_refreshes();
        stats.newton_refresh_pairs = self.cv.problem().refresh_pairs();
        self.cv.problem().add_screen_stats(&mut stats);
        stats
    }

    /// Re-initialisations: `(for load changes, at events)`.
    pub fn restarts(&self) -> (u64, u64) {
        (self.restarts, self.roots.events)
    }

    /// The problem's dimension (length of [`Stepper::state`]).
    pub fn dim(&self) -> usize {
        self.cv.problem().dim()
    }
}
