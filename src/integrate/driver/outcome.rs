//! What a run returns: its status, curves, energy check, trajectory and timings.

use serde::{Serialize, Serializer};

use crate::error::{CallbackOutcome, Error};
use crate::integrate::mechanical::{EnergySample, MechanicalOde};
use crate::integrate::problem::OdeStats;
use crate::integrate::sundials::CvodeFlag;
use crate::system::SecondOrderSystem;

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
    /// Pairs in contact (a non-zero normal force).
    pub closed_pairs: Vec<usize>,
}

impl Curves {
    pub(super) fn push(&mut self, s: &EnergySample) {
        self.t.push(s.t);
        self.contact_force_norm.push(s.contact_force_norm);
        self.friction_force_norm.push(s.friction_force_norm);
        self.master_uy.push(s.master[1]);
        self.kinetic.push(s.kinetic);
        self.strain.push(s.strain);
        self.pair.push(s.pair);
        self.external_work.push(s.external_work);
        self.dissipated.push(s.dissipated);
        self.closed_pairs.push(s.closed_pairs);
    }

    /// The energy balance `E_kin + E_strain + E_pair + D − W` at each output minus its value at
    /// the first output, N·mm: zero for an exact solution. A run from rest starts with every
    /// energy zero; a run from an initial state ([`TransientOptions::start`](super::TransientOptions::start)) with its stored
    /// energy, which the balance then conserves.
    pub fn balance(&self) -> Vec<f64> {
        let at = |i: usize| {
            self.kinetic[i] + self.strain[i] + self.pair[i] + self.dissipated[i]
                - self.external_work[i]
        };
        let b0 = if self.t.is_empty() { 0.0 } else { at(0) };
        (0..self.t.len()).map(|i| at(i) - b0).collect()
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
    /// energy states W and D ([`TransientOptions::energy_resolution`](super::TransientOptions::energy_resolution)); residuals below it are
    /// not counted against the run (a short run whose energies are at the tolerance's level).
    pub resolution: f64,
    /// `max_residual <= tolerance · energy_scale + resolution`.
    pub ok: bool,
}

impl Curves {
    /// The run's [`EnergyCheck`]; `resolution` (N·mm) is the run's
    /// [`TransientOptions::energy_resolution`](super::TransientOptions::energy_resolution).
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

/// The states of a run at its output times ([`TransientOptions::record`](super::TransientOptions::record)), each block stored
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
    /// An empty trajectory with room for `outputs` outputs of the sizes of `q` and of the
    /// problem's forces and slip memory.
    pub(super) fn with_capacity<S: SecondOrderSystem>(
        outputs: usize,
        q: &[f64],
        ode: &MechanicalOde<S>,
    ) -> Trajectory {
        Trajectory {
            q: Vec::with_capacity(outputs * q.len()),
            p: Vec::with_capacity(outputs * ode.pair_forces().len()),
            s: Vec::with_capacity(outputs * ode.slip_memory().len()),
        }
    }

    /// Appends one output: `q` and the forces and slip memory of the problem's last sample.
    pub(super) fn push<S: SecondOrderSystem>(&mut self, q: &[f64], ode: &MechanicalOde<S>) {
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
    /// Events: [`MAX_STALLED_ROOTS`](super::MAX_STALLED_ROOTS) roots in a row without progress in time at `t` (s).
    Chatter {
        /// Time reached, s.
        t: f64,
    },
    /// Stopped at `t` (s) because the run crawls: its statistics show it cannot finish in
    /// reasonable time ([`Stall`](super::Stall): chattering events or a collapsing step).
    Stalled {
        /// Time reached, s.
        t: f64,
        /// What the statistics showed.
        reason: super::Stall,
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
    /// `callback` for a failure without a CVODE flag name, `budget`, `chatter`, `stalled` or
    /// `error`.
    pub fn name(&self) -> &str {
        match self {
            RunStatus::Finished => "ok",
            RunStatus::Budget { .. } => "budget",
            RunStatus::Chatter { .. } => "chatter",
            RunStatus::Stalled { .. } => "stalled",
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
    pub(super) fn of_error(e: &Error, t: f64, budget: bool) -> RunStatus {
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

/// The result of [`integrate`](super::integrate): status, statistics, timings and the curves up to the time
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
    /// [`TransientOptions::record`](super::TransientOptions::record).
    #[serde(skip)]
    pub trajectory: Option<Trajectory>,
    /// Wall time per kind of callback, with [`TransientOptions::profile`](super::TransientOptions::profile).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub profile: Option<Profile>,
    /// The error that ended a run that did not finish.
    #[serde(skip)]
    pub failure: Option<Error>,
}

/// Where a run's wall time went ([`TransientOptions::profile`](super::TransientOptions::profile)): the problem's callbacks, timed
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
