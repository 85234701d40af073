//! [`Integrator`]: the integrator a run's [`OdeOptions::method`] chooses — CVODE ([`Cvode`]:
//! BDF, Adams) or ARKODE's ARKStep ([`Arkode`]: a DIRK table) — behind one interface, so the
//! driver loop and the stepper make the same calls whichever integrates.

use super::{Arkode, Cvode};
use crate::error::Error;
use crate::integrate::problem::{Method, OdeOptions, OdeProblem, OdeStats, Stop};

/// CVODE or ARKStep, as [`OdeOptions::method`] says.
pub enum Integrator<P: OdeProblem> {
    /// BDF or Adams.
    Cvode(Cvode<P>),
    /// A DIRK method.
    Arkode(Arkode<P>),
}

impl<P: OdeProblem> Integrator<P> {
    /// [`Arkode::new`] for [`Method::Dirk`], else [`Cvode::new`].
    ///
    /// # Errors
    /// Those of the constructor called.
    pub fn new(problem: P, t0: f64, y0: &[f64], opts: &OdeOptions) -> Result<Self, Error> {
        Ok(match opts.method {
            Method::Dirk(_) => Integrator::Arkode(Arkode::new(problem, t0, y0, opts)?),
            Method::Bdf | Method::Adams => Integrator::Cvode(Cvode::new(problem, t0, y0, opts)?),
        })
    }

    /// [`Cvode::solve_to`] / [`Arkode::solve_to`].
    ///
    /// # Errors
    /// Those of the integrator.
    pub fn solve_to(&mut self, tout: f64) -> Result<Stop, Error> {
        match self {
            Integrator::Cvode(c) => c.solve_to(tout),
            Integrator::Arkode(a) => a.solve_to(tout),
        }
    }

    /// [`Cvode::reinit`] / [`Arkode::reinit`].
    ///
    /// # Errors
    /// Those of the integrator.
    pub fn reinit(&mut self, t: f64, y: &[f64]) -> Result<(), Error> {
        match self {
            Integrator::Cvode(c) => c.reinit(t, y),
            Integrator::Arkode(a) => a.reinit(t, y),
        }
    }

    /// Current time, s.
    pub fn t(&self) -> f64 {
        match self {
            Integrator::Cvode(c) => c.t(),
            Integrator::Arkode(a) => a.t(),
        }
    }

    /// Current state.
    pub fn y(&self) -> &[f64] {
        match self {
            Integrator::Cvode(c) => c.y(),
            Integrator::Arkode(a) => a.y(),
        }
    }

    /// Statistics, cumulative since creation.
    pub fn stats(&self) -> OdeStats {
        match self {
            Integrator::Cvode(c) => c.stats(),
            Integrator::Arkode(a) => a.stats(),
        }
    }

    /// The run's step budget ([`Cvode::set_max_steps`]).
    pub fn set_max_steps(&mut self, total: u64) {
        match self {
            Integrator::Cvode(c) => c.set_max_steps(total),
            Integrator::Arkode(a) => a.set_max_steps(total),
        }
    }

    /// The problem.
    pub fn problem(&self) -> &P {
        match self {
            Integrator::Cvode(c) => c.problem(),
            Integrator::Arkode(a) => a.problem(),
        }
    }

    /// The problem, writable.
    pub fn problem_mut(&mut self) -> &mut P {
        match self {
            Integrator::Cvode(c) => c.problem_mut(),
            Integrator::Arkode(a) => a.problem_mut(),
        }
    }
}
