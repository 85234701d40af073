//! `Rom`: a reduced model built from a `Model` (`Model.reduce`) or read from a reduced-model
//! file (`jointrom.load_rom`): its basis Φ and reduced matrices as numpy arrays, its transient
//! run with the error estimate, the file and the FMU.

use std::path::PathBuf;
use std::sync::Arc;

use jointrom::integrate::{ProblemOptions, TransientOptions};
use jointrom::rom::file::{BasisInfo, RomFile};
use jointrom::rom::{BuiltRom, ModelRun};
use jointrom::system::{ReducedSystem, Scene};
use pyo3::prelude::*;

use crate::convert;
use crate::errors::{input, IntoPy};
use crate::model::PyModel;
use crate::run::{RunArgs, RunResult};
use crate::worker;

/// A reduced model.
#[pyclass(module = "jointrom", name = "Rom", frozen)]
pub struct Rom {
    /// The model it reduces (None for a file read without one).
    model: Option<Arc<jointrom::Model>>,
    system: ReducedSystem,
    info: BasisInfo,
    /// The file it was read from, with its path.
    file: Option<(RomFile, PathBuf)>,
    /// The tolerance model's integration tolerances (rtol, atol).
    chosen: Option<(f64, f64)>,
    offline_s: Option<f64>,
}

impl Rom {
    /// The reduced model `built` of `model`.
    pub fn built(model: Arc<jointrom::Model>, built: BuiltRom) -> Rom {
        let chosen = built
            .tolerance
            .as_ref()
            .map(|t| (t.transient.ode.rtol, t.transient.ode.atol));
        Rom {
            model: Some(model),
            system: built.rom,
            info: built.info,
            file: None,
            chosen,
            offline_s: Some(built.offline_s),
        }
    }

    /// The file of this reduced model (as `jointrom export` writes it).
    fn rom_file(&self) -> Result<RomFile, jointrom::Error> {
        match (&self.file, &self.model) {
            (Some((f, _)), _) => Ok(f.clone()),
            (None, Some(model)) => RomFile::new(model, &self.system, self.info.clone()),
            (None, None) => Err(jointrom::error::RomError::Detached.into()),
        }
    }

    /// The model's name in results: the basis kind, `adaptive`, or `file:PATH`.
    fn name(&self) -> String {
        match &self.file {
            Some((_, path)) => format!("file:{}", path.display()),
            None => self.info.kind.clone(),
        }
    }

    /// A run of this reduced model with `opts` (its error estimate where it has its basis Φ and
    /// model).
    fn run(&self, opts: &TransientOptions) -> Result<ModelRun, jointrom::Error> {
        match (&self.model, &self.system.phi, &self.file) {
            (Some(model), Some(_), _) => {
                jointrom::rom::run_rom(model, self.system.clone(), self.info.g, opts, None)
            }
            (_, _, Some((f, _))) => {
                let opts = TransientOptions {
                    problem: ProblemOptions {
                        tau: f.friction_relaxation_time,
                        ..opts.problem
                    },
                    ..opts.clone()
                };
                let run = jointrom::integrate::run(self.system.clone(), &f.scene(), &opts)?;
                Ok(ModelRun {
                    run,
                    basis_size: f.dimension,
                    g: Some(f.basis.g),
                    training: None,
                    frames: Vec::new(),
                    offline_s: None,
                    tolerance: None,
                    estimate: Some(Err("an exported reduced model carries no basis Φ to \
                                        correct its joint forces with"
                        .into())),
                })
            }
            (Some(model), None, None) => {
                jointrom::integrate::run(self.system.clone(), &Scene::of(model), opts).map(|run| {
                    ModelRun {
                        run,
                        basis_size: self.system.dim(),
                        g: Some(self.info.g),
                        training: None,
                        frames: Vec::new(),
                        offline_s: None,
                        tolerance: None,
                        estimate: None,
                    }
                })
            }
            (None, _, None) => Err(jointrom::error::RomError::Detached.into()),
        }
    }

    /// The end time of a run with `opts`, s.
    fn end_time(&self, opts: &TransientOptions) -> f64 {
        opts.end_time.unwrap_or(match (&self.file, &self.model) {
            (Some((f, _)), _) => f.end_time,
            (None, Some(m)) => m.end_time,
            (None, None) => f64::NAN,
        })
    }
}

/// A reduced model written by `Rom.save` or `jointrom export` (str or os.PathLike). With
/// `model`, checks that the file was exported from it (the CLI's `--model file:PATH` check).
#[pyfunction]
#[pyo3(signature = (path, model = None))]
pub fn load_rom(py: Python<'_>, path: PathBuf, model: Option<&PyModel>) -> PyResult<Rom> {
    let model = model.map(|m| m.checked().cloned()).transpose()?;
    let (file, system) = worker::run(py, None, f64::NAN, |_| {
        let f = RomFile::read(&path)?;
        if let Some(m) = &model {
            f.check_source(m, &path)?;
        }
        let system = f.system()?;
        Ok((f, system))
    })?;
    Ok(Rom {
        model,
        system,
        info: file.basis.clone(),
        file: Some((file, path)),
        chosen: None,
        offline_s: None,
    })
}

#[pymethods]
impl Rom {
    /// The reduced dimension r.
    #[getter]
    fn dimension(&self) -> usize {
        self.system.dim()
    }

    /// The basis Φ (n × r) in physical DOF; None for a model read from a file.
    #[getter]
    fn phi(&self, py: Python<'_>) -> PyResult<Option<Py<PyAny>>> {
        self.system
            .phi
            .as_ref()
            .map(|p| convert::matrix(py, p))
            .transpose()
    }

    /// The reduced stiffness K̃ = Φᵀ K Φ (r × r), N/mm.
    #[getter]
    fn k(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        convert::matrix(py, self.system.k())
    }

    /// The reduced mass M̃ = Φᵀ M Φ (r × r), t.
    #[getter]
    fn m(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        convert::matrix(py, self.system.m())
    }

    /// The joint operator on the coordinates, BΦ (3 × pairs × r).
    #[getter]
    fn b_phi(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        convert::matrix(py, self.system.b_phi())
    }

    /// How it was made (the reduced-model file's `basis` record), as a dict, with `dimension`
    /// and `offline_s`.
    #[getter]
    fn info(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        let mut v = serde_json::to_value(&self.info).unwrap_or_default();
        v["dimension"] = self.system.dim().into();
        v["offline_s"] = self.offline_s.into();
        if let Some(m) = &self.model {
            v["case"] = m.name.clone().into();
        }
        convert::json(py, &v)
    }

    /// The reduced model's transient run from rest (`jointrom transient CASE --model KIND` or
    /// `--model file:PATH`), with its error estimate. A tolerance model runs with the
    /// integration tolerances it chose unless `rtol`/`atol` are given.
    #[allow(clippy::too_many_arguments)]
    #[pyo3(signature = (*, end_time = None, output_step = 1e-4, friction = true, events = false,
        rtol = None, atol = None, iteration = "newton", max_order = None, max_wall = 3600.0,
        progress = None))]
    fn transient(
        &self,
        py: Python<'_>,
        end_time: Option<f64>,
        output_step: f64,
        friction: bool,
        events: bool,
        rtol: Option<f64>,
        atol: Option<f64>,
        iteration: &str,
        max_order: Option<usize>,
        max_wall: f64,
        progress: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<RunResult> {
        let mut args = RunArgs {
            end_time,
            output_step,
            friction,
            events,
            rtol,
            atol,
            iteration: iteration.into(),
            max_order,
            max_wall,
        };
        if let (Some((r, a)), false) = (self.chosen, args.tolerances_given()) {
            (args.rtol, args.atol) = (Some(r), Some(a));
        }
        let opts = args.options(None).py_err()?;
        let end = self.end_time(&opts);
        let run = worker::run(py, progress, end, |hook| {
            let opts = args.options(Some(hook))?;
            crate::run::timed(|| self.run(&opts))
        })?;
        let case = match (&self.model, &self.file) {
            (Some(m), _) => m.name.clone(),
            (None, Some((f, _))) => f.case.clone(),
            (None, None) => String::new(),
        };
        let mut out = RunResult::new(py, case, self.name(), run, &opts)?;
        if self.file.is_none() {
            out.set_offline(self.offline_s);
        }
        Ok(out)
    }

    /// Writes the reduced model as a `jointrom-rom` JSON file (atomically).
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        let f = self.rom_file().py_err()?;
        worker::run(py, None, f64::NAN, |_| f.write(&path))
    }

    /// Writes the reduced model as an FMI 2.0 co-simulation FMU (atomically). `binary`: the FMU
    /// binary libjointrom_fmu.so (default: $JOINTROM_FMU_BINARY; `cargo build --release`
    /// builds it into target/release/).
    #[pyo3(signature = (path, binary = None))]
    fn export_fmu(&self, py: Python<'_>, path: PathBuf, binary: Option<PathBuf>) -> PyResult<()> {
        use jointrom::report::fmu::{BINARY_ENV, BINARY_FILE};
        let binary = match binary.or_else(|| std::env::var_os(BINARY_ENV).map(PathBuf::from)) {
            Some(b) if b.is_file() => b,
            Some(b) => {
                return Err(input(format!(
                    "{}: the FMU binary is not a file (build {BINARY_FILE} with `cargo build \
                     --release -p jointrom-fmu`)",
                    b.display()
                )))
            }
            None => {
                return Err(input(format!(
                    "export_fmu needs the FMU binary {BINARY_FILE}: pass binary=PATH or set \
                     {BINARY_ENV} (`cargo build --release -p jointrom-fmu` builds it into \
                     target/release/)"
                )))
            }
        };
        let f = self.rom_file().py_err()?;
        worker::run(py, None, f64::NAN, |_| {
            jointrom::report::fmu::write_fmu(&f, &binary, &path).map(|_| ())
        })
    }

    fn __repr__(&self) -> String {
        format!(
            "Rom({:?}, dimension={}, g={})",
            self.name(),
            self.system.dim(),
            self.info.g
        )
    }
}
