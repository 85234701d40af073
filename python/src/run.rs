//! A transient run's result as Python sees it (`RunResult`), and the transient options from
//! the keyword arguments of `Model.transient`, `Rom.transient` and `Model.reduce`, checked as
//! the CLI checks its flags (the messages name the flags).

use jointrom::integrate::{RunChoices, RunHook, TransientOptions};
use jointrom::rom::ModelRun;
use jointrom::studies::stability::IterKind;
use jointrom::Error;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use serde_json::json;

use crate::convert;

/// The keyword arguments of a transient run (the CLI's `transient` flags of the same names).
pub struct RunArgs {
    pub end_time: Option<f64>,
    pub output_step: f64,
    pub friction: bool,
    pub events: bool,
    pub rtol: Option<f64>,
    pub atol: Option<f64>,
    pub iteration: String,
    pub max_order: Option<usize>,
    pub max_wall: f64,
}

impl RunArgs {
    /// The transient options, as `jointrom transient` makes them from its flags.
    pub fn options(&self, hook: Option<RunHook>) -> Result<TransientOptions, Error> {
        let mut o = RunChoices {
            iteration: IterKind::parse(&self.iteration)?.iteration(),
            friction: self.friction,
            events: self.events,
            rtol: self.rtol,
            atol: self.atol,
            max_order: self.max_order,
            end_time: self.end_time,
            output_step: self.output_step,
            max_wall: self.max_wall,
        }
        .options()?;
        o.hook = hook;
        Ok(o)
    }

    /// Whether rtol or atol were given (else a tolerance model's own are used).
    pub fn tolerances_given(&self) -> bool {
        self.rtol.is_some() || self.atol.is_some()
    }
}

/// The result of a transient run: curves as numpy arrays (output times `t` in s, `‖f_c‖` and
/// `‖f_R‖` in N, the master's `u_y` in mm, energies in N·mm), the solver statistics and the
/// error estimate as dicts, as in `jointrom transient --json`.
#[pyclass(module = "jointrom", name = "RunResult", frozen)]
pub struct RunResult {
    /// The model's name: `full`, the basis kind, `adaptive` or `file:PATH`.
    #[pyo3(get)]
    model: String,
    /// The case's name.
    #[pyo3(get)]
    case: String,
    /// The model's size: DOF of the full model, r of a reduced one.
    #[pyo3(get)]
    basis_size: usize,
    /// Added vectors g (pairs of the tolerance model); None for the full model.
    #[pyo3(get)]
    g: Option<usize>,
    #[pyo3(get)]
    t: Py<PyAny>,
    #[pyo3(get)]
    contact_force_norm: Py<PyAny>,
    #[pyo3(get)]
    friction_force_norm: Py<PyAny>,
    #[pyo3(get)]
    master_uy: Py<PyAny>,
    #[pyo3(get)]
    kinetic: Py<PyAny>,
    #[pyo3(get)]
    strain: Py<PyAny>,
    #[pyo3(get)]
    pair: Py<PyAny>,
    #[pyo3(get)]
    external_work: Py<PyAny>,
    #[pyo3(get)]
    dissipated: Py<PyAny>,
    /// CVODE's statistics (the JSON's `stats`).
    #[pyo3(get)]
    stats: Py<PyAny>,
    /// The estimated relative L2 errors (the JSON's `error_estimate`): a dict, `{"unavailable":
    /// why}`, or None for the full model.
    #[pyo3(get)]
    error_estimate: Py<PyAny>,
    /// The energy balance check (the JSON's `energy_check`).
    #[pyo3(get)]
    energy_check: Py<PyAny>,
    /// The options of the run (the JSON's `options`).
    #[pyo3(get)]
    options: Py<PyAny>,
    /// The tolerance model's choice (the JSON's `tolerance`), or None.
    #[pyo3(get)]
    tolerance: Py<PyAny>,
    /// Wall and CPU time of the integration, s.
    #[pyo3(get)]
    wall_s: f64,
    #[pyo3(get)]
    cpu_s: f64,
    /// Wall time of building the reduced model, s (None for the full model or a file).
    #[pyo3(get)]
    offline_s: Option<f64>,
    /// Located events (roots).
    #[pyo3(get)]
    events: u64,
    /// Wall time of the whole call inside jointrom, s: the run, its error estimate and
    /// integration check (the rest of a call's time is the Python binding's).
    #[pyo3(get)]
    total_s: f64,
}

impl RunResult {
    /// The result of `o`, a run of the model named `model` of case `case` with `opts` that
    /// took `total_s` inside jointrom; the curves are moved into numpy arrays.
    pub fn new(
        py: Python<'_>,
        case: String,
        model: String,
        (mut o, total_s): (ModelRun, f64),
        opts: &TransientOptions,
    ) -> PyResult<RunResult> {
        let c = std::mem::take(&mut o.run.curves);
        let check = c.energy_check(opts.energy_resolution());
        let estimate = match &o.estimate {
            None => serde_json::Value::Null,
            Some(Ok(e)) => serde_json::to_value(e).unwrap_or(serde_json::Value::Null),
            Some(Err(why)) => json!({ "unavailable": why }),
        };
        Ok(RunResult {
            model,
            case,
            basis_size: o.basis_size,
            g: o.g,
            t: convert::vector(py, c.t),
            contact_force_norm: convert::vector(py, c.contact_force_norm),
            friction_force_norm: convert::vector(py, c.friction_force_norm),
            master_uy: convert::vector(py, c.master_uy),
            kinetic: convert::vector(py, c.kinetic),
            strain: convert::vector(py, c.strain),
            pair: convert::vector(py, c.pair),
            external_work: convert::vector(py, c.external_work),
            dissipated: convert::vector(py, c.dissipated),
            stats: convert::serialized(py, &o.run.stats)?,
            error_estimate: convert::json(py, &estimate)?,
            energy_check: convert::serialized(py, &check)?,
            options: convert::serialized(py, opts)?,
            tolerance: convert::serialized(py, &o.tolerance)?,
            wall_s: o.run.wall_s,
            cpu_s: o.run.cpu_s,
            offline_s: o.offline_s,
            events: o.run.events,
            total_s,
        })
    }
}

#[pymethods]
impl RunResult {
    /// The curves as a dict of arrays (the JSON's `curves`).
    fn curves<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (k, v) in [
            ("t", &self.t),
            ("contact_force_norm", &self.contact_force_norm),
            ("friction_force_norm", &self.friction_force_norm),
            ("master_uy", &self.master_uy),
            ("kinetic", &self.kinetic),
            ("strain", &self.strain),
            ("pair", &self.pair),
            ("external_work", &self.external_work),
            ("dissipated", &self.dissipated),
        ] {
            d.set_item(k, v.clone_ref(py))?;
        }
        Ok(d)
    }

    fn __repr__(&self, py: Python<'_>) -> String {
        let n = self.t.bind(py).len().unwrap_or(0);
        format!(
            "RunResult(case={:?}, model={:?}, basis_size={}, outputs={n}, wall_s={:.4})",
            self.case, self.model, self.basis_size, self.wall_s
        )
    }
}

impl RunResult {
    /// Sets the build time of the reduced model that ran.
    pub fn set_offline(&mut self, offline_s: Option<f64>) {
        self.offline_s = offline_s;
    }
}

/// `f()` and its wall time, s.
pub fn timed<T>(f: impl FnOnce() -> Result<T, Error>) -> Result<(T, f64), Error> {
    let t0 = std::time::Instant::now();
    f().map(|v| (v, t0.elapsed().as_secs_f64()))
}
