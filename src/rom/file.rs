//! The reduced model as a product: a documented, versioned JSON file that other tools (system
//! simulation, an engineer's own scripts) read, and that jointrom re-integrates itself.
//!
//! ## Schema `jointrom-rom`, version 1
//!
//! Matrices are arrays of rows (row-major), numbers in SI-mm units (mm, N, t, s, rad). With r
//! the number of reduced coordinates q and w the number of joint pairs, the reduced equations
//! of motion (paper eq. 7) are
//!
//! ```text
//! M̃ q̈ + K̃ q = Σ_d f_d(t) φ_d − (BΦ)ᵀ p(BΦ q, s),     u_master = Φ_m q
//! ```
//!
//! | field | shape / type | meaning |
//! |---|---|---|
//! | `schema`, `version` | `"jointrom-rom"`, `1` | this format |
//! | `case`, `basis` | string, object | where it came from: basis kind, g, ν, w(g) threshold, w |
//! | `dimension` | r | reduced coordinates |
//! | `pairs` | w | joint node pairs |
//! | `mass` | r × r | `M̃ = ΦᵀMΦ` (t; the identity for jointrom's M-orthonormal bases) |
//! | `stiffness` | r × r | `K̃ = ΦᵀKΦ` (N/mm; diagonal ω² for the modal rotation) |
//! | `joint_operator` | 3w × r | `BΦ`: per pair the rows normal gap, slip t1 (x), slip t2 (z), mm per unit q |
//! | `master_rows` | 6 × r | `Φ_m`: rows of Φ at the master DOF ux, uy, uz (mm), rx, ry, rz (rad) |
//! | `reduced_loads` | 6 × r | `φ_d = Φᵀ e_d` for a unit master load along DOF d (= `master_rows`) |
//! | `master_load` | object | final master load `fx, fy, fz` (N), `mx, my, mz` (N·mm) |
//! | `load_ramp` | object | its time function (the case file's `load.ramp`) |
//! | `contact` | object | `normal_stiffness` k_n, `stick_stiffness` k_t (N/mm), `friction_coefficient` μ; a per-area model adds `normal_stiffness_per_area`, `stick_stiffness_per_area` (N/mm³; its k_n, k_t are those of a pair of mean area, the pairs' shares are in `BΦ`'s rows) |
//! | `friction_relaxation_time` | s | τ of jointrom's viscoplastic slip memory (see `crate::joint::law`) |
//! | `coordinate_size` | r | ‖Φ_j‖₂ per column over the full model's DOF (mm or rad per unit q): jointrom's tolerance scale (files without `field_dofs`: max |Φ_j|) |
//! | `field_dofs` | count | n, the full model's DOF: with `coordinate_size` the error test measures the physical field as the full model's does (`crate::integrate::mechanical`, *The error test of a reduced model*; absent in older files: r, and the test is the coordinates' own) |
//! | `end_time` | s | the case's simulated span |
//! | `source_digest` | string | SHA-256 (hex) of the source model's K and M (pattern and values), DOF count and pair count ([`model_digest`]); a run of the file under a CASE checks the CASE against it ([`RomFile::check_source`]; absent in older files: the name, DOF and pair counts are checked) |
//!
//! The pair law: gap `g = (BΦq)_normal`, normal force `p_n = k_n·min(g, 0)`; Coulomb friction
//! with elastic stick `k_t (u_t − s)` capped at `μ|p_n|` (see `crate::joint::law`).
//!
//! [`RomFile::read`] checks the schema, the version, every dimension and that every number is
//! finite, and the mechanics: r ≥ 1, w ≥ 1, M̃ symmetric positive definite, K̃ symmetric positive
//! semidefinite, a valid load ramp (a positive half-cosine duration or a table), positive k_n, k_t, τ and coordinate sizes, μ ≥ 0,
//! and `reduced_loads` equal to `master_rows` (read and checked: the two are the same
//! numbers, written twice for readers that want the load vectors by name), naming the file and
//! the field at fault; [`RomFile::system`] turns it into a
//! [`ReducedSystem`] that `crate::integrate::mechanical::run` integrates — the same curves as the model it
//! was exported from (bit for bit: JSON numbers round-trip exactly).

use std::path::Path;

use faer::Mat;
use serde::{Deserialize, Serialize};

use crate::case::{ContactSpec, MasterLoadSpec, RampSpec};
use crate::error::{Error, RomError};
use crate::joint::law::DEFAULT_TAU;
use crate::linalg::symmetric_eigenvalues;
use crate::model::Model;
use crate::system::{ErrorScale, ReducedSystem, Scene};

/// Schema name of the file.
pub const SCHEMA: &str = "jointrom-rom";
/// Schema version written (and the only one read).
pub const VERSION: u32 = 1;

/// Where the basis came from.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BasisInfo {
    /// Basis kind (`tvd`, `tvd-plain`, `modes`, `jim`, `alldof`, `adaptive`).
    pub kind: String,
    /// Added vectors g.
    pub g: usize,
    /// Fixed-interface modes ν.
    pub nu: usize,
    /// w(g) threshold of the a-priori choice (0 for `adaptive`).
    pub threshold: f64,
    /// POD energy ratios w(1), w(2), ... (empty for bases without POD).
    pub w: Vec<f64>,
    /// `adaptive`: the tolerance on the relative L2 error of ‖f_c‖(t) it was built for, the
    /// chosen pairs and the estimate of its run (absent for the other kinds and in older files).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tolerance: Option<ToleranceInfo>,
}

/// How an `adaptive` basis was chosen (`jointrom export --tolerance`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ToleranceInfo {
    /// The tolerance, relative L2 error of ‖f_c‖(t).
    pub tolerance: f64,
    /// Whether the estimate met it.
    pub met: bool,
    /// The pairs whose attachment modes the basis holds (indices of the joint pairs).
    pub pairs: Vec<usize>,
    /// The estimated relative L2 error of ‖f_c‖(t) of its transient with friction.
    pub error_estimate: Option<f64>,
}

/// The exported reduced model (see the module docs for every field).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RomFile {
    /// `"jointrom-rom"`.
    pub schema: String,
    /// 1.
    pub version: u32,
    /// Case name.
    pub case: String,
    /// Basis description.
    pub basis: BasisInfo,
    /// r.
    pub dimension: usize,
    /// w.
    pub pairs: usize,
    /// M̃ (r × r), t.
    pub mass: Vec<Vec<f64>>,
    /// K̃ (r × r), N/mm.
    pub stiffness: Vec<Vec<f64>>,
    /// BΦ (3w × r), mm per unit coordinate.
    pub joint_operator: Vec<Vec<f64>>,
    /// Φ at the master DOF (6 × r).
    pub master_rows: Vec<Vec<f64>>,
    /// Φᵀ e_d for unit master loads (6 × r).
    pub reduced_loads: Vec<Vec<f64>>,
    /// Final master load.
    pub master_load: MasterLoadSpec,
    /// Its time function.
    pub load_ramp: RampSpec,
    /// Pair law parameters.
    pub contact: ContactSpec,
    /// τ of the slip memory, s.
    pub friction_relaxation_time: f64,
    /// The error test's scale per column (r): ‖Φ_j‖₂, mm or rad per unit coordinate.
    pub coordinate_size: Vec<f64>,
    /// n, the DOF of the field the coordinates describe (absent in older files: r).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub field_dofs: Option<usize>,
    /// Simulated span, s.
    pub end_time: f64,
    /// SHA-256 of the source model's matrices ([`model_digest`]; absent in older files).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub source_digest: Option<String>,
}

/// A digest of a model's mechanics: SHA-256 (hex) over its DOF and pair counts and the pattern
/// and values (bits) of K and M. Two models with the same digest have the same matrices, so a
/// reduced model exported from one is a reduced model of the other.
pub fn model_digest(model: &Model) -> String {
    use sha2::{Digest, Sha256};
    let mut h = Sha256::new();
    h.update((model.dofs() as u64).to_le_bytes());
    h.update((model.joint.pairs() as u64).to_le_bytes());
    for a in [&model.stiffness, &model.mass] {
        for &p in &a.col_ptr {
            h.update((p as u64).to_le_bytes());
        }
        for &i in &a.row_idx {
            h.update((i as u64).to_le_bytes());
        }
        for &v in &a.values {
            h.update(v.to_bits().to_le_bytes());
        }
    }
    h.finalize().iter().map(|b| format!("{b:02x}")).collect()
}

fn rows(a: &Mat<f64>) -> Vec<Vec<f64>> {
    (0..a.nrows())
        .map(|i| (0..a.ncols()).map(|j| a[(i, j)]).collect())
        .collect()
}

impl RomFile {
    /// The file of a reduced model of `model`.
    pub fn new(model: &Model, rom: &ReducedSystem, basis: BasisInfo) -> Result<RomFile, Error> {
        let r = rom.dim();
        let phi_master = &rom.phi_master;
        let scale = rom.error_scale.clone();
        Ok(RomFile {
            schema: SCHEMA.into(),
            version: VERSION,
            case: model.name.clone(),
            basis,
            dimension: r,
            pairs: model.joint.pairs(),
            mass: rows(rom.m()),
            stiffness: rows(rom.k()),
            joint_operator: rows(rom.b_phi()),
            master_rows: rows(phi_master),
            reduced_loads: rows(phi_master),
            master_load: model.load.master,
            load_ramp: model.load.ramp.clone(),
            contact: model.contact,
            friction_relaxation_time: DEFAULT_TAU,
            coordinate_size: scale.column,
            field_dofs: Some(scale.field_dofs),
            end_time: model.end_time,
            source_digest: Some(model_digest(model)),
        })
    }

    /// Checks that `model` is the model this file was exported from: the digest of its
    /// matrices where the file has one, else its name, DOF count and pair count. A run of the
    /// file labelled with another model's name would be mislabelled.
    ///
    /// # Errors
    /// [`RomError::SourceMismatch`] naming both models and what differs.
    pub fn check_source(&self, model: &Model, path: &Path) -> Result<(), Error> {
        let differs = match &self.source_digest {
            Some(d) if *d != model_digest(model) => Some("its K and M differ".to_string()),
            Some(_) => None,
            None if self.case != model.name => Some(format!("its name is `{}`", model.name)),
            None if self.field_dofs.is_some_and(|n| n != model.dofs()) => Some(format!(
                "it has {} DOF, the file's model {}",
                model.dofs(),
                self.field_dofs.unwrap_or(0)
            )),
            None if self.pairs != model.joint.pairs() => Some(format!(
                "it has {} joint pairs, the file's model {}",
                model.joint.pairs(),
                self.pairs
            )),
            None => None,
        };
        match differs {
            Some(differs) => Err(RomError::SourceMismatch {
                file: path.to_path_buf(),
                exported_from: crate::files::printable(&self.case).to_string(),
                differs,
            }
            .into()),
            None => Ok(()),
        }
    }

    /// Writes the file (pretty JSON).
    pub fn write(&self, path: &Path) -> Result<(), Error> {
        let text = serde_json::to_string_pretty(self).expect("the reduced model serialises");
        crate::files::write_atomic(path, text)
    }

    /// Reads and checks a file (errors name the file and the field).
    pub fn read(path: &Path) -> Result<RomFile, Error> {
        let text = crate::files::read_text(path)?;
        RomFile::parse(&text, path)
    }

    /// Parses and checks the text of a file read from `path` (errors name `path` and the
    /// field), for readers that need the bytes too (an FMU checks them against its GUID).
    pub fn parse(text: &str, path: &Path) -> Result<RomFile, Error> {
        let bad = |field: &str, msg: String| Error::Document {
            file: path.to_path_buf(),
            path: field.to_string(),
            reason: msg,
            source: None,
        };
        let de = &mut serde_json::Deserializer::from_str(text);
        let f: RomFile = serde_path_to_error::deserialize(de).map_err(|e| Error::Document {
            file: path.to_path_buf(),
            path: e.path().to_string(),
            reason: e.inner().to_string(),
            source: Some(Box::new(e.into_inner())),
        })?;
        if f.schema != SCHEMA {
            return Err(bad(
                "schema",
                format!("expected \"{SCHEMA}\", got \"{}\"", f.schema),
            ));
        }
        if f.version != VERSION {
            return Err(bad(
                "version",
                format!("this jointrom reads version {VERSION}, got {}", f.version),
            ));
        }
        let (r, w) = (f.dimension, f.pairs);
        if r == 0 {
            return Err(bad("dimension", "must be at least 1".into()));
        }
        if w == 0 {
            return Err(bad("pairs", "must be at least 1 (a joint pair)".into()));
        }
        let check = |field: &str, m: &[Vec<f64>], nr: usize| -> Result<(), Error> {
            if m.len() != nr {
                return Err(bad(field, format!("expected {nr} rows, got {}", m.len())));
            }
            for (i, row) in m.iter().enumerate() {
                if row.len() != r {
                    return Err(bad(
                        &format!("{field}[{i}]"),
                        format!("expected {r} columns, got {}", row.len()),
                    ));
                }
                if let Some(j) = row.iter().position(|v| !v.is_finite()) {
                    return Err(bad(&format!("{field}[{i}][{j}]"), "not finite".into()));
                }
            }
            Ok(())
        };
        check("mass", &f.mass, r)?;
        check("stiffness", &f.stiffness, r)?;
        check("joint_operator", &f.joint_operator, 3 * w)?;
        check("master_rows", &f.master_rows, 6)?;
        check("reduced_loads", &f.reduced_loads, 6)?;
        if f.coordinate_size.len() != r {
            return Err(bad(
                "coordinate_size",
                format!("expected {r} entries, got {}", f.coordinate_size.len()),
            ));
        }
        let positive = |field: &str, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(bad(field, format!("must be finite and positive, got {v}")))
            }
        };
        positive("contact.normal_stiffness", f.contact.normal_stiffness)?;
        positive("contact.stick_stiffness", f.contact.stick_stiffness)?;
        positive("friction_relaxation_time", f.friction_relaxation_time)?;
        positive("end_time", f.end_time)?;
        if !(f.contact.friction_coefficient.is_finite() && f.contact.friction_coefficient >= 0.0) {
            return Err(bad(
                "contact.friction_coefficient",
                format!("must be ≥ 0, got {}", f.contact.friction_coefficient),
            ));
        }
        for (i, s) in f.coordinate_size.iter().enumerate() {
            positive(&format!("coordinate_size[{i}]"), *s)?;
        }
        if let Some(n) = f.field_dofs {
            if n < r {
                return Err(bad(
                    "field_dofs",
                    format!("{n} DOF cannot hold a reduced model of dimension {r}"),
                ));
            }
        }
        f.load_ramp
            .check("load_ramp")
            .map_err(|(field, reason)| bad(&field, reason))?;
        let m = &f.master_load;
        for (k, v) in [m.fx, m.fy, m.fz, m.mx, m.my, m.mz].into_iter().enumerate() {
            if !v.is_finite() {
                let key = ["fx", "fy", "fz", "mx", "my", "mz"][k];
                return Err(bad(
                    &format!("master_load.{key}"),
                    format!("not finite: {v}"),
                ));
            }
        }
        f.check_physics().map_err(|(field, msg)| bad(field, msg))?;
        Ok(f)
    }

    /// The mechanics a reduced model must have: M̃ symmetric positive definite, K̃ symmetric
    /// positive semidefinite (a negated or indefinite stiffness makes a run blow up to 10⁸⁷ mm
    /// instead of failing), `reduced_loads` equal to `master_rows` (a unit master load along
    /// DOF d enters as Φᵀe_d, which is row d of Φ at the master node; the file carries both so a
    /// reader need not know that, and jointrom uses `master_rows`). Symmetry within 1e-10 of
    /// the largest entry; semidefinite: no eigenvalue below −1e-10 × the largest.
    fn check_physics(&self) -> Result<(), (&'static str, String)> {
        let r = self.dimension;
        let mat = |m: &[Vec<f64>]| Mat::from_fn(r, r, |i, j| m[i][j]);
        let (m, k) = (mat(&self.mass), mat(&self.stiffness));
        for (field, a) in [("mass", &m), ("stiffness", &k)] {
            let max = (0..r)
                .flat_map(|i| (0..r).map(move |j| (i, j)))
                .fold(0.0f64, |acc, (i, j)| acc.max(a[(i, j)].abs()));
            for i in 0..r {
                for j in 0..i {
                    if (a[(i, j)] - a[(j, i)]).abs() > 1e-10 * max {
                        return Err((
                            field,
                            format!(
                                "not symmetric: [{i}][{j}] = {:e} but [{j}][{i}] = {:e}",
                                a[(i, j)],
                                a[(j, i)]
                            ),
                        ));
                    }
                }
            }
        }
        if m.llt(faer::Side::Lower).is_err() {
            return Err((
                "mass",
                "not positive definite (its Cholesky factorization fails)".into(),
            ));
        }
        let eig = symmetric_eigenvalues(k.as_ref(), "stiffness")
            .map_err(|e| ("stiffness", format!("eigenvalues failed: {e}")))?;
        let top = eig.iter().fold(0.0f64, |a, &l| a.max(l.abs()));
        if let Some(low) = eig.iter().copied().find(|&l| l < -1e-10 * top) {
            return Err((
                "stiffness",
                format!(
                    "not positive semidefinite: eigenvalue {low:e} N/mm (largest {top:e}); a \
                     stiffness must not push the structure away from rest"
                ),
            ));
        }
        for (d, (a, b)) in self.master_rows.iter().zip(&self.reduced_loads).enumerate() {
            let scale = a.iter().fold(0.0f64, |s, v| s.max(v.abs()));
            if let Some(j) = (0..r).find(|&j| (a[j] - b[j]).abs() > 1e-12 * scale.max(1e-300)) {
                return Err((
                    "reduced_loads",
                    format!(
                        "row {d} differs from master_rows[{d}] at column {j} ({:e} vs {:e}): \
                         the reduced load of a unit master load is Φᵀe_d, the master row itself",
                        b[j], a[j]
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The reduced system jointrom integrates.
    pub fn system(&self) -> Result<ReducedSystem, Error> {
        let mat = |m: &[Vec<f64>]| {
            let nc = m.first().map_or(self.dimension, Vec::len);
            Mat::from_fn(m.len(), nc, |i, j| m[i][j])
        };
        ReducedSystem::from_matrices(
            mat(&self.stiffness),
            mat(&self.mass),
            mat(&self.joint_operator),
            (
                mat(&self.master_rows),
                ErrorScale {
                    column: self.coordinate_size.clone(),
                    field_dofs: self.field_dofs.unwrap_or(self.dimension),
                },
            ),
            crate::case::LoadSpec {
                master: self.master_load,
                ramp: self.load_ramp.clone(),
            },
            None,
        )
    }

    /// The contact law and the span the reduced model was exported with.
    pub fn scene(&self) -> Scene {
        Scene {
            contact: self.contact,
            end_time: self.end_time,
        }
    }
}
