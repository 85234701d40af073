//! `jointrom.load` and `Model`: a full FE model (a built-in name, a case file, a NASTRAN deck or
//! a matrix map), its info, modes, statics, K and M, its full transient, and `reduce`.

use std::ffi::CString;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::SystemTime;

use jointrom::joint::statics::ContactOptions;
use jointrom::linalg::SymCsc;
use jointrom::model::Origin;
use jointrom::reduction::BasisKind;
use jointrom::rom::{ModelFlags, ModelSpec, RunSettings};
use jointrom::Interface;
use numpy::{PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

use crate::convert;
use crate::errors::{input, IntoPy};
use crate::rom::Rom;
use crate::run::{RunArgs, RunResult};
use crate::worker;

/// A file the model was read from, with its size and time when read.
struct Stamp {
    path: PathBuf,
    len: u64,
    modified: Option<SystemTime>,
}

impl Stamp {
    fn of(path: &Path) -> Option<Stamp> {
        let m = std::fs::metadata(path).ok()?;
        Some(Stamp {
            path: path.to_path_buf(),
            len: m.len(),
            modified: m.modified().ok(),
        })
    }
}

/// A full FE model.
#[pyclass(module = "jointrom", name = "Model", frozen)]
pub struct PyModel {
    pub inner: Arc<jointrom::Model>,
    files: Vec<Stamp>,
}

/// The model `case` names: a built-in name (`friction_bar`, `multilayer_sheet`), a case file,
/// a NASTRAN deck or a matrix map (str or os.PathLike). Its warnings are issued as Python
/// warnings.
#[pyfunction]
pub fn load(py: Python<'_>, case: PathBuf) -> PyResult<PyModel> {
    let arg = case
        .to_str()
        .ok_or_else(|| input(format!("{}: not a UTF-8 path", case.display())))?
        .to_string();
    let model = worker::run(py, None, f64::NAN, |_| {
        jointrom::Model::from_case_name(&arg)
    })?;
    for w in &model.warnings {
        let text = CString::new(jointrom::files::printable(w)).unwrap_or_default();
        PyErr::warn(
            py,
            &py.get_type::<pyo3::exceptions::PyUserWarning>(),
            &text,
            1,
        )?;
    }
    let files = source_files(&model)
        .iter()
        .filter_map(|p| Stamp::of(p))
        .collect();
    Ok(PyModel {
        inner: Arc::new(model),
        files,
    })
}

/// The files a model was read from (none for a built-in case).
fn source_files(model: &jointrom::Model) -> Vec<PathBuf> {
    match &model.origin {
        Origin::Case { .. } if !model.source.starts_with("builtin:") => {
            vec![PathBuf::from(&model.source)]
        }
        Origin::Case { .. } => Vec::new(),
        Origin::Deck { deck, .. } => vec![deck.clone()],
        Origin::Matrices {
            map,
            stiffness,
            mass,
        } => vec![map.clone(), stiffness.clone(), mass.clone()],
    }
}

/// A symmetric sparse matrix (both triangles) as scipy.sparse's CSC matrix, or as the tuple
/// `(data, indices, indptr, shape)` without scipy.
fn sparse(py: Python<'_>, a: &SymCsc) -> PyResult<Py<PyAny>> {
    let data = convert::vector(py, a.values.clone());
    let idx: Vec<i64> = a.row_idx.iter().map(|&i| i as i64).collect();
    let ptr: Vec<i64> = a.col_ptr.iter().map(|&i| i as i64).collect();
    let indices = numpy::PyArray1::from_vec(py, idx).into_any();
    let indptr = numpy::PyArray1::from_vec(py, ptr).into_any();
    let shape = (a.n, a.n);
    match py.import("scipy.sparse") {
        Ok(sp) => Ok(sp
            .getattr("csc_matrix")?
            .call1(((data, indices, indptr), shape))?
            .unbind()),
        Err(_) => Ok(PyTuple::new(
            py,
            [
                data.into_bound(py),
                indices,
                indptr,
                shape.into_pyobject(py)?.into_any(),
            ],
        )?
        .into_any()
        .unbind()),
    }
}

/// A vector of `n` numbers from a list or a 1-D array; an error naming `what` for anything else.
pub fn vector_arg(v: &Bound<'_, PyAny>, what: &str, n: usize) -> PyResult<Vec<f64>> {
    let values: Vec<f64> = if let Ok(a) = v.cast::<PyArrayDyn<f64>>() {
        if a.ndim() != 1 {
            let dims: Vec<String> = a.shape().iter().map(|d| d.to_string()).collect();
            return Err(input(format!(
                "{what} must be a vector of {n} numbers, got an array of shape ({})",
                dims.join(", ")
            )));
        }
        a.to_vec()?
    } else {
        v.extract().map_err(|_| {
            PyTypeError::new_err(format!(
                "{what} must be a vector of {n} numbers (a list or a 1-D float array), got {}",
                v.get_type()
                    .name()
                    .map(|s| s.to_string())
                    .unwrap_or_default()
            ))
        })?
    };
    if values.len() != n {
        return Err(input(format!(
            "{what} must have {n} components, got {}",
            values.len()
        )));
    }
    Ok(values)
}

impl PyModel {
    /// The model, if none of its files changed since it was read.
    pub fn checked(&self) -> PyResult<&Arc<jointrom::Model>> {
        for s in &self.files {
            if Stamp::of(&s.path).is_none_or(|now| now.len != s.len || now.modified != s.modified) {
                return Err(input(format!(
                    "{}: changed since the model was loaded: load it again (jointrom.load)",
                    s.path.display()
                )));
            }
        }
        Ok(&self.inner)
    }
}

#[pymethods]
impl PyModel {
    /// The case's name.
    #[getter]
    fn name(&self) -> String {
        self.inner.name.clone()
    }

    /// Independent DOF.
    #[getter]
    fn dofs(&self) -> usize {
        self.inner.dofs()
    }

    /// Joint pairs.
    #[getter]
    fn pairs(&self) -> usize {
        self.inner.pair_count()
    }

    /// The `jointrom info --json` document as a dict.
    #[getter]
    fn info(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        convert::json(py, &jointrom::report::info::info_json(&self.inner))
    }

    /// The `count` lowest eigenfrequencies (Hz) with the master node clamped (`fixed`) or free.
    #[pyo3(signature = (count = 10, interface = "fixed"))]
    fn modes(&self, py: Python<'_>, count: usize, interface: &str) -> PyResult<Py<PyAny>> {
        let iface = match interface {
            "fixed" => Interface::Fixed,
            "free" => Interface::Free,
            other => {
                return Err(input(format!(
                    "--interface must be `fixed` or `free`, got `{other}`"
                )))
            }
        };
        let model = Arc::clone(self.checked()?);
        let modes = worker::run(py, None, f64::NAN, |_| model.modes(count, iface))?;
        Ok(convert::vector(py, modes.frequencies_hz))
    }

    /// The static response to `scale` × the case's master load (or `load`, six components
    /// `[Fx, Fy, Fz (N), Mx, My, Mz (N·mm)]`): with frictionless contact in the joint pairs,
    /// or `linear=True` without contact. A dict as `jointrom static --json`, with arrays.
    #[pyo3(signature = (scale = 1.0, load = None, linear = false))]
    fn r#static<'py>(
        &self,
        py: Python<'py>,
        scale: f64,
        load: Option<&Bound<'py, PyAny>>,
        linear: bool,
    ) -> PyResult<Bound<'py, PyDict>> {
        if !scale.is_finite() {
            return Err(input(format!("--scale must be finite, got {scale}")));
        }
        let model = Arc::clone(self.checked()?);
        let base = match load {
            Some(v) => {
                let v = vector_arg(v, "load", 6)?;
                std::array::from_fn(|k| v[k])
            }
            None => model.master_load(),
        };
        let load = base.map(|v| v * scale);
        let d = PyDict::new(py);
        d.set_item("case", &model.name)?;
        d.set_item("linear", linear)?;
        d.set_item("load", convert::vector(py, load.to_vec()))?;
        if linear {
            let mut sol = worker::run(py, None, f64::NAN, |_| model.static_linear(&[load]))?;
            let sol = sol.remove(0);
            d.set_item(
                "master_displacement",
                convert::vector(py, sol.master_displacement.to_vec()),
            )?;
            d.set_item("displacement", convert::vector(py, sol.displacement))?;
            return Ok(d);
        }
        let sol = worker::run(py, None, f64::NAN, |_| {
            jointrom::model::contact_static_full(&model, load, &ContactOptions::default())
        })?;
        let st = sol.state;
        let pair_forces: Vec<f64> = st
            .forces
            .iter()
            .zip(&model.pairs)
            .filter(|(p, _)| **p != 0.0)
            .flat_map(|(p, pair)| {
                let [x, y, z] = model.geometry.nodes[pair.lower];
                [x, y, z, *p]
            })
            .collect();
        let rows = pair_forces.len() / 4;
        let pair_forces = numpy::PyArray1::from_vec(py, pair_forces).reshape([rows, 4])?;
        d.set_item(
            "master_displacement",
            convert::vector(py, sol.master_displacement.to_vec()),
        )?;
        d.set_item("iterations", st.iterations)?;
        d.set_item("contact_force_norm", st.contact_force_norm)?;
        d.set_item(
            "contact_force_total",
            st.forces.iter().map(|p| p.abs()).sum::<f64>(),
        )?;
        d.set_item("pairs_in_contact", st.pairs_in_contact)?;
        d.set_item("pair_forces", pair_forces)?;
        d.set_item("forces", convert::vector(py, st.forces))?;
        d.set_item("gaps", convert::vector(py, st.gaps))?;
        d.set_item("displacement", convert::vector(py, sol.displacement))?;
        Ok(d)
    }

    /// The stiffness matrix K (N/mm) on the independent DOF.
    fn stiffness(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        sparse(py, &self.checked()?.stiffness)
    }

    /// The mass matrix M (t) on the independent DOF.
    fn mass(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        sparse(py, &self.checked()?.mass)
    }

    /// The full FE model's transient run from rest (`jointrom transient CASE --model full`).
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
        let args = RunArgs {
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
        let model = Arc::clone(self.checked()?);
        let opts = args.options(None).py_err()?;
        let end = opts.end_time.unwrap_or(model.end_time);
        let run = worker::run(py, progress, end, |hook| {
            let opts = args.options(Some(hook))?;
            crate::run::timed(|| {
                jointrom::rom::run_model(&model, &ModelSpec::Full, &opts, &RunSettings::default())
            })
        })?;
        RunResult::new(py, model.name.clone(), "full".into(), run, &opts)
    }

    /// A reduced model: `tolerance=TOL` builds the smallest one whose estimated errors of ‖f_c‖,
    /// ‖f_R‖, u_y and D (with friction) are at most TOL (its rounds are transient runs with the
    /// given options; its joint columns compressed where that pays, as the CLI's default
    /// `--compress-joint auto`); `basis=KIND`
    /// (tvd, tvd-plain, modes, jim, alldof) with `g` vectors (default: the a-priori rule) and
    /// `nu` fixed-interface modes builds that basis. Default: tvd.
    #[allow(clippy::too_many_arguments)]
    #[pyo3(signature = (*, tolerance = None, basis = None, g = None, nu = 10, end_time = None,
        output_step = 1e-4, friction = true, events = false, max_wall = 3600.0, progress = None))]
    fn reduce(
        &self,
        py: Python<'_>,
        tolerance: Option<f64>,
        basis: Option<&str>,
        g: Option<usize>,
        nu: usize,
        end_time: Option<f64>,
        output_step: f64,
        friction: bool,
        events: bool,
        max_wall: f64,
        progress: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Rom> {
        let kind = basis
            .map(BasisKind::from_name)
            .transpose()
            .map_err(jointrom::Error::from)
            .py_err()?;
        let flags = ModelFlags {
            model: None,
            basis: kind,
            g,
            nu,
            tolerance,
            tolerance_on: None,
        };
        let tvd = ModelSpec::Basis {
            kind: BasisKind::Tvd,
            g: None,
            nu,
        };
        let spec = flags.spec(tvd).py_err()?;
        let args = RunArgs {
            end_time,
            output_step,
            friction,
            events,
            rtol: None,
            atol: None,
            iteration: "newton".into(),
            max_order: None,
            max_wall,
        };
        let model = Arc::clone(self.checked()?);
        let opts = args.options(None).py_err()?;
        let end = opts.end_time.unwrap_or(model.end_time);
        let built = worker::run(py, progress, end, |hook| {
            let opts = args.options(Some(hook))?;
            jointrom::rom::build_rom(&model, &spec, &opts, "reduce")
        })?;
        Ok(Rom::built(model, built))
    }

    fn __repr__(&self) -> String {
        format!(
            "Model({:?}, dofs={}, pairs={})",
            self.inner.name,
            self.inner.dofs(),
            self.inner.pair_count()
        )
    }
}
