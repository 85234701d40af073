//! The distributed offline stage (design in `docs/distributed.md`): the
//! Craig–Bampton eigen solve and the TVD's multi-right-hand-side solve handed to PETSc/SLEPc
//! (+ MUMPS) over MPI, and the results compared with the native path.
//!
//! # What crosses the boundary
//! [`prepare`] writes a job folder in PETSc's binary format ([`crate::model::petsc`]) and a
//! manifest `job.json` (schema [`SCHEMA`]):
//!
//! | file | what | units |
//! |---|---|---|
//! | `Kii.petsc` | `K_ii`, the stiffness with the six master DOF removed (fixed interface), n_i × n_i AIJ | N/mm, N·mm/rad |
//! | `Mii.petsc` | `M_ii`, the mass likewise | t, t·mm² |
//! | `K.petsc` | `K`, the whole stiffness (master free, the case's clamps), n × n AIJ | N/mm |
//! | `R.petsc` | the TVD right-hand sides `B_uᵀ Q` (n × p, dense; [`super::tvd::static_right_hand_sides`]) | N per unit of the base |
//!
//! The PETSc program (`distributed/jointrom_slepc.c`) returns `modes.petsc` (ν vectors of
//! length n_i), `Z.petsc` (n × p) and `result.json` (eigenvalues ω² in (rad/s)² printed with 17
//! digits, SLEPc's residuals, the wall time of each stage); [`compare`] reads them.
//!
//! # The two problems
//! 1. Fixed-interface modes `K_ii φ = ω² M_ii φ`, the ν lowest: natively faer's Krylov–Schur on
//!    `L⁻¹ M_ii L⁻ᵀ` (`K_ii = L Lᵀ`, [`crate::linalg::eigen`]); on SLEPc Krylov–Schur with
//!    shift-and-invert at target σ = 0, i.e. on `K_ii⁻¹ M_ii` in the `M_ii` inner product — the
//!    same spectral transformation, `μ = 1/ω²`.
//! 2. The static TVD flexibility `K Z = R` (eqs. 16/18 through the joint flexibility columns,
//!    [`super::tvd`] "Compressed flexibility"): natively one sparse Cholesky of K and p solves
//!    with one double-double refinement step; on PETSc one MUMPS Cholesky and `KSPMatSolve`.
//!
//! # The measures ([`Comparison`])
//! - frequencies `f = √ω² / 2π`: `max_i |f_i^P − f_i^N| / f_i^N` (target ≤ 1e-8);
//! - the span of the modes: with both sets `M_ii`-orthonormal (`Φ_Nᵀ M Φ_N = I`, the SLEPc set
//!   normalized here and its deviation `max |Φ_Pᵀ M Φ_P − I|` reported), the sine of the largest
//!   principal angle between the subspaces in the M inner product,
//!   `sin θ_max = ‖(I − Φ_N Φ_Nᵀ M) Φ_P‖_M = √λ_max(Wᵀ M W)` with `W = Φ_P − Φ_N (Φ_Nᵀ M Φ_P)`
//!   (formed directly, not as `1 − cos²`, which would cancel);
//! - each SLEPc pair's normwise backward error on jointrom's own matrices,
//!   `‖K φ − ω² M φ‖∞ / ((‖K‖∞ + ω² ‖M‖∞) ‖φ‖∞)` (the native solver accepts ≤ 1e-10);
//! - the solve: `‖Z_P − Z_N‖_F / ‖Z_N‖_F` and the backward error of each side,
//!   `max_c ‖r_c − K z_c‖∞ / (‖K‖∞ ‖z_c‖∞ + ‖r_c‖∞)` with the residual in double-double.

use std::path::{Path, PathBuf};
use std::time::Instant;

use faer::{Mat, MatRef};
use serde::{Deserialize, Serialize};

use crate::error::{Error, ReductionError};
use crate::files;
use crate::linalg::compensated::{solve_refined_steps, sym_mul_compensated};
use crate::linalg::sparse::sym_mul_mat;
use crate::linalg::symmetric_eigenvalues;
use crate::linalg::LinalgError;
use crate::linalg::{Modes, SparseCholesky, SymCsc};
use crate::model::petsc;
use crate::model::{Interface, Model};

use super::craig_bampton::craig_bampton;
use super::tvd::{static_right_hand_sides, TvdOptions};

/// The manifest's `schema` value.
pub const SCHEMA: &str = "jointrom-petsc-job";

/// The job manifest `job.json`: what each file of the folder is.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct JobManifest {
    /// Always [`SCHEMA`].
    pub schema: String,
    /// 1.
    pub version: u32,
    /// The model's name.
    pub case: String,
    /// n, the model's independent DOF.
    pub dofs: usize,
    /// n_i = n − 6, the interior DOF of the fixed-interface problem.
    pub interior_dofs: usize,
    /// ν, the fixed-interface modes asked for.
    pub nu: usize,
    /// p, the columns of `R.petsc`.
    pub rhs_columns: usize,
    /// File name → what it holds and its units.
    pub files: Vec<JobFile>,
}

/// One file of a job folder.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct JobFile {
    /// Name inside the folder.
    pub file: String,
    /// What it holds.
    pub what: String,
    /// Units of its values.
    pub units: String,
}

/// The native results a job is compared with, and their wall times (s).
#[derive(Clone, Debug)]
pub struct NativeReference {
    /// The ν lowest fixed-interface modes (`model.modes(ν, Fixed)`), M_ii-orthonormal.
    pub modes: Modes,
    /// The right-hand sides R (n × p), as written to `R.petsc`.
    pub rhs: Mat<f64>,
    /// `K⁻¹ R` by the TVD's own solve (one refinement step).
    pub solution: Mat<f64>,
    /// Backward error of [`Self::solution`] (module docs).
    pub solve_backward: f64,
    /// Seconds: eigen solve (factor + Krylov–Schur), K factor, refined solves, the
    /// Craig–Bampton base and TVD right-hand sides (not compared), writing the job.
    pub seconds: NativeSeconds,
}

/// Wall times of the native path, s.
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct NativeSeconds {
    /// `K_ii` factor and Krylov–Schur for ν modes.
    pub eigen: f64,
    /// Sparse Cholesky of K.
    pub factor: f64,
    /// The p refined solves.
    pub solve: f64,
    /// Craig–Bampton base and TVD right-hand sides (what the job needs; not compared).
    pub rhs: f64,
    /// Writing the job folder.
    pub export: f64,
}

fn job_files() -> Vec<JobFile> {
    let f = |file: &str, what: &str, units: &str| JobFile {
        file: file.into(),
        what: what.into(),
        units: units.into(),
    };
    vec![
        f(
            "Kii.petsc",
            "K_ii: stiffness without the six master DOF (fixed interface), AIJ",
            "N/mm, N·mm/rad",
        ),
        f(
            "Mii.petsc",
            "M_ii: mass without the six master DOF, AIJ",
            "t, t·mm²",
        ),
        f(
            "K.petsc",
            "K: whole stiffness (master free, the case's clamps), AIJ",
            "N/mm, N·mm/rad",
        ),
        f(
            "R.petsc",
            "TVD right-hand sides B_u^T Q (n x p), dense",
            "N per unit of the base",
        ),
    ]
}

/// Runs the native path on `model` (ν fixed-interface modes; the Craig–Bampton base, its TVD
/// right-hand sides and their solve with K) and writes the job folder `dir` for the PETSc
/// program (module docs).
pub fn prepare(model: &Model, nu: usize, dir: &Path) -> Result<NativeReference, Error> {
    let n = model.dofs();
    let mut seconds = NativeSeconds::default();
    let t = Instant::now();
    let modes = model.modes(nu, Interface::Fixed)?;
    seconds.eigen = t.elapsed().as_secs_f64();

    let t = Instant::now();
    let base = craig_bampton(model, nu)?;
    let rhs = static_right_hand_sides(model, base.as_ref(), &TvdOptions::default())?;
    drop(base);
    seconds.rhs = t.elapsed().as_secs_f64();
    if rhs.ncols() == 0 {
        return Err(ReductionError::NoTvdRhs {
            case: files::printable(&model.name).to_string(),
        }
        .into());
    }

    let t = Instant::now();
    let chol = SparseCholesky::new(&model.stiffness)?;
    seconds.factor = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let solution = solve_refined_steps(&model.stiffness, &chol, &rhs, 1);
    seconds.solve = t.elapsed().as_secs_f64();
    drop(chol);
    let solve_backward = solve_backward_error(&model.stiffness, rhs.as_ref(), solution.as_ref());

    let t = Instant::now();
    files::create_dir(dir)?;
    let m = n - 6;
    petsc::write_sym_aij(&dir.join("Kii.petsc"), &model.stiffness.leading(m))?;
    petsc::write_sym_aij(&dir.join("Mii.petsc"), &model.mass.leading(m))?;
    petsc::write_sym_aij(&dir.join("K.petsc"), &model.stiffness)?;
    petsc::write_dense(&dir.join("R.petsc"), rhs.as_ref())?;
    let manifest = JobManifest {
        schema: SCHEMA.into(),
        version: 1,
        case: model.name.clone(),
        dofs: n,
        interior_dofs: m,
        nu,
        rhs_columns: rhs.ncols(),
        files: job_files(),
    };
    let text = serde_json::to_string_pretty(&manifest)
        .map_err(|source| ReductionError::JobManifest { source })?;
    files::write_atomic(&dir.join("job.json"), text)?;
    seconds.export = t.elapsed().as_secs_f64();
    Ok(NativeReference {
        modes,
        rhs,
        solution,
        solve_backward,
        seconds,
    })
}

/// What the PETSc program reports in `result.json`.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PetscResult {
    /// MPI ranks.
    pub ranks: usize,
    /// n_i as loaded.
    pub interior_dofs: usize,
    /// n as loaded.
    pub dofs: usize,
    /// p as loaded.
    pub rhs_columns: usize,
    /// Eigenpairs SLEPc converged (≥ ν).
    pub converged: usize,
    /// Krylov–Schur restarts.
    pub iterations: usize,
    /// ω² of the ν lowest modes, (rad/s)².
    pub eigenvalues: Vec<f64>,
    /// SLEPc's relative residual of each pair.
    pub relative_errors: Vec<f64>,
    /// Wall time of each stage, s.
    pub seconds: PetscSeconds,
}

/// Wall times of the PETSc program's stages (MPI_Wtime on rank 0), s.
#[derive(Clone, Copy, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PetscSeconds {
    /// Loading K_ii and M_ii.
    pub load_eigen: f64,
    /// `EPSSolve` (MUMPS Cholesky of K_ii and Krylov–Schur).
    pub eigen: f64,
    /// Writing the modes.
    pub write_modes: f64,
    /// Loading K and R.
    pub load_solve: f64,
    /// MUMPS Cholesky of K (`KSPSetUp`).
    pub factor: f64,
    /// `KSPMatSolve` of all p columns.
    pub solve: f64,
    /// Writing Z.
    pub write_solution: f64,
    /// The whole program after initialization.
    pub total: f64,
}

/// The distributed results against the native ones (module docs, "The measures").
#[derive(Clone, Debug, Serialize)]
pub struct Comparison {
    /// MPI ranks of the PETSc run.
    pub ranks: usize,
    /// Native fixed-interface frequencies, Hz.
    pub frequencies_native_hz: Vec<f64>,
    /// SLEPc's, Hz.
    pub frequencies_petsc_hz: Vec<f64>,
    /// `max_i |f_i^P − f_i^N| / f_i^N`.
    pub frequency_rel_diff: f64,
    /// Sine of the largest M-principal angle between the two mode subspaces.
    pub span_sine: f64,
    /// `max |Φ_Pᵀ M Φ_P − I|` of SLEPc's modes as returned.
    pub m_orthonormality: f64,
    /// Largest backward error of SLEPc's pairs on jointrom's K_ii, M_ii.
    pub mode_backward: f64,
    /// `‖Z_P − Z_N‖_F / ‖Z_N‖_F`.
    pub solve_rel_diff: f64,
    /// Backward error of MUMPS's Z.
    pub solve_backward: f64,
    /// Backward error of the native Z.
    pub native_solve_backward: f64,
    /// What the PETSc program reported.
    pub petsc: PetscResult,
}

/// Reads what the PETSc program wrote to `out` and compares it with `native` (module docs).
pub fn compare(model: &Model, native: &NativeReference, out: &Path) -> Result<Comparison, Error> {
    let result_path = out.join("result.json");
    let text = files::read_text(&result_path)?;
    let petsc: PetscResult = serde_json::from_str(&text).map_err(|e| Error::Document {
        file: result_path.clone(),
        path: String::new(),
        reason: format!("not a jointrom_slepc result: {e}"),
        source: Some(Box::new(e)),
    })?;
    let n = model.dofs();
    let m = n - 6;
    let nu = native.modes.eigenvalues.len();
    let mismatch = |what: String| Error::Document {
        file: result_path.clone(),
        path: String::new(),
        reason: what,
        source: None,
    };
    if petsc.eigenvalues.len() != nu || petsc.interior_dofs != m || petsc.dofs != n {
        return Err(mismatch(format!(
            "{} eigenvalues on {} × {} DOF, expected {nu} on {m} × {n} (a result of another job?)",
            petsc.eigenvalues.len(),
            petsc.interior_dofs,
            petsc.dofs
        )));
    }
    let vecs_path = out.join("modes.petsc");
    let vecs = petsc::read_vecs(&vecs_path)?;
    if vecs.len() != nu || vecs.iter().any(|v| v.len() != m) {
        return Err(mismatch(format!(
            "{} holds {} vectors, expected {nu} of length {m}",
            vecs_path.display(),
            vecs.len()
        )));
    }
    let phi_p = Mat::from_fn(m, nu, |i, j| vecs[j][i]);
    drop(vecs);
    let k_ii = model.stiffness.leading(m);
    let m_ii = model.mass.leading(m);
    let (span_sine, m_orthonormality, phi_p) =
        span_measure(&m_ii, native.modes.shapes.as_ref(), phi_p)?;
    let mode_backward = pair_backward(&k_ii, &m_ii, &petsc.eigenvalues, phi_p.as_ref());

    let z_path = out.join("Z.petsc");
    let z = petsc::read_dense(&z_path)?;
    if z.shape() != native.solution.shape() {
        return Err(mismatch(format!(
            "{} is {} × {}, expected {} × {}",
            z_path.display(),
            z.nrows(),
            z.ncols(),
            native.solution.nrows(),
            native.solution.ncols()
        )));
    }
    let solve_rel_diff = (&z - &native.solution).norm_l2() / native.solution.norm_l2();
    let solve_backward = solve_backward_error(&model.stiffness, native.rhs.as_ref(), z.as_ref());
    let hz = |l: &f64| l.max(0.0).sqrt() / (2.0 * std::f64::consts::PI);
    let frequencies_petsc_hz: Vec<f64> = petsc.eigenvalues.iter().map(hz).collect();
    let frequency_rel_diff = frequencies_petsc_hz
        .iter()
        .zip(&native.modes.frequencies_hz)
        .map(|(p, n)| (p - n).abs() / n)
        .fold(0.0, f64::max);
    Ok(Comparison {
        ranks: petsc.ranks,
        frequencies_native_hz: native.modes.frequencies_hz.clone(),
        frequencies_petsc_hz,
        frequency_rel_diff,
        span_sine,
        m_orthonormality,
        mode_backward,
        solve_rel_diff,
        solve_backward,
        native_solve_backward: native.solve_backward,
        petsc,
    })
}

/// `(sin θ_max, max |Φ_Pᵀ M Φ_P − I|, Φ_P M-normalized)` for M-orthonormal `phi_n` (module
/// docs).
fn span_measure(
    m: &SymCsc,
    phi_n: MatRef<'_, f64>,
    mut phi_p: Mat<f64>,
) -> Result<(f64, f64, Mat<f64>), Error> {
    let nu = phi_p.ncols();
    let mp = sym_mul_mat(m, phi_p.as_ref());
    let gram = phi_p.transpose() * &mp;
    let mut dev = 0.0f64;
    for i in 0..nu {
        for j in 0..nu {
            let want = if i == j { 1.0 } else { 0.0 };
            dev = dev.max((gram[(i, j)] - want).abs());
        }
    }
    for j in 0..nu {
        let norm = gram[(j, j)].sqrt();
        if !(norm.is_finite() && norm > 0.0) {
            return Err(Error::LinearAlgebra(LinalgError::ModeNorm {
                what: format!("distributed: SLEPc mode {}", j + 1),
                norm,
            }));
        }
        phi_p.col_mut(j).iter_mut().for_each(|v| *v /= norm);
    }
    let mp = sym_mul_mat(m, phi_p.as_ref());
    let c = phi_n.transpose() * &mp;
    let w = &phi_p - phi_n * &c;
    let mw = sym_mul_mat(m, w.as_ref());
    let g = w.transpose() * &mw;
    let g = Mat::from_fn(nu, nu, |i, j| 0.5 * (g[(i, j)] + g[(j, i)]));
    let top = symmetric_eigenvalues(g.as_ref(), "distributed: span measure")
        .map_err(Error::LinearAlgebra)?
        .into_iter()
        .fold(0.0f64, f64::max);
    Ok((top.max(0.0).sqrt(), dev, phi_p))
}

/// The largest normwise backward error `‖K φ − λ M φ‖∞ / ((‖K‖∞ + λ ‖M‖∞) ‖φ‖∞)` of the pairs.
fn pair_backward(k: &SymCsc, m: &SymCsc, lambda: &[f64], phi: MatRef<'_, f64>) -> f64 {
    let (kn, mn) = (k.inf_norm(), m.inf_norm());
    let kp = sym_mul_mat(k, phi);
    let mp = sym_mul_mat(m, phi);
    let mut worst = 0.0f64;
    for (c, &l) in lambda.iter().enumerate() {
        let res = (0..phi.nrows())
            .map(|i| (kp[(i, c)] - l * mp[(i, c)]).abs())
            .fold(0.0, f64::max);
        let pn = phi.col(c).iter().fold(0.0f64, |a, v| a.max(v.abs()));
        worst = worst.max(res / ((kn + l * mn) * pn));
    }
    worst
}

/// `max_c ‖r_c − K z_c‖∞ / (‖K‖∞ ‖z_c‖∞ + ‖r_c‖∞)`, the residual in double-double.
fn solve_backward_error(k: &SymCsc, r: MatRef<'_, f64>, z: MatRef<'_, f64>) -> f64 {
    let res = sym_mul_compensated(k, z, -1.0, Some(r));
    let kn = k.inf_norm();
    let inf = |x: MatRef<'_, f64>, c: usize| x.col(c).iter().fold(0.0f64, |a, v| a.max(v.abs()));
    (0..z.ncols())
        .map(|c| inf(res.as_ref(), c) / (kn * inf(z, c) + inf(r, c)))
        .fold(0.0, f64::max)
}

/// The output folder of a run with `ranks` MPI ranks inside the job folder `dir`.
pub fn output_dir(dir: &Path, ranks: usize) -> PathBuf {
    dir.join(format!("ranks{ranks}"))
}
