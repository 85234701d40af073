//! Stored reference curves (full-FE runs kept under `cases/reference/`) and the relative L2
//! errors of a run against them: `jointrom transient CASE --reference PATH`.
//!
//! A reference holds, at its output times `t` (s), ‖f_c‖ and ‖f_R‖ (N) and the master node's
//! u_y (mm). The error of a run's curve `a` against the reference curve `r` is
//!
//! ```text
//! e = sqrt( Σ_k (a(t_k) − r(t_k))² / Σ_k r(t_k)² )
//! ```
//!
//! over the output times `t_k` the run and the reference share (matched to 1e-6 of the smaller
//! output spacing, [`relative_l2`]): a run over a shorter span is compared over its span, a run
//! with a coarser output step at its own outputs.
//!
//! Two file formats: CSV with a header naming the columns `t`, `contact_force_norm`,
//! `friction_force_norm`, `master_uy` and optionally `dissipated`, each also with the unit a
//! run's own `curves.csv` appends (`t_s`, `contact_force_norm_N`, `friction_force_norm_N`,
//! `master_uy_mm`, `dissipated_Nmm`; other columns ignored, so a run's `curves.csv` is a
//! reference), and the compact JSON of `cases/reference/compact.py` (arrays of those names).

use std::path::Path;

use serde::Serialize;

use crate::error::{Error, ReferenceProblem, RomError};
use crate::integrate::Curves;

/// The four curves every comparison of runs is about — ‖f_c‖(t), ‖f_R‖(t) and the master's
/// u_y(t) at the output times — of a run (`From<Curves>`) or of a stored reference
/// ([`JointCurves::read`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct JointCurves {
    /// Output times, s (strictly increasing).
    pub t: Vec<f64>,
    /// ‖f_c‖, N.
    pub contact_force_norm: Vec<f64>,
    /// ‖f_R‖, N.
    pub friction_force_norm: Vec<f64>,
    /// Master u_y, mm.
    pub master_uy: Vec<f64>,
    /// The joint's dissipated energy D, N·mm (empty: a reference made before it was stored).
    pub dissipated: Vec<f64>,
}

/// The relative L2 errors of a run against a reference (module docs); `None` where the
/// reference curve is zero over the compared times (e.g. ‖f_R‖ with friction off).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ReferenceErrors {
    /// ‖f_c‖(t).
    pub contact_force: Option<f64>,
    /// ‖f_R‖(t).
    pub friction_force: Option<f64>,
    /// Master u_y(t).
    pub master_uy: Option<f64>,
    /// The dissipated energy D(t) (`None`: not in the reference, or zero).
    pub dissipated: Option<f64>,
    /// D at the last compared time: `|D(T) − D_ref(T)| / |D_ref(T)|`.
    pub dissipated_end: Option<f64>,
    /// Output times compared (shared by the run and the reference).
    pub compared_outputs: usize,
    /// Last compared time, s.
    pub compared_until: f64,
}

const COLUMNS: [&str; 4] = [
    "t",
    "contact_force_norm",
    "friction_force_norm",
    "master_uy",
];

/// The units a run's own `curves.csv` appends to [`COLUMNS`] (`t_s`, `contact_force_norm_N`, …:
/// [`crate::report::curves::CURVE_COLUMNS`]).
const COLUMN_UNITS: [&str; 4] = ["s", "N", "N", "mm"];

/// The position of the CSV column `name`, or of `name_unit` as a run's `curves.csv` names it.
fn column_position(header: &csv::StringRecord, name: &str, unit: &str) -> Option<usize> {
    header.iter().position(|h| {
        h == name
            || h.strip_prefix(name)
                .and_then(|rest| rest.strip_prefix('_'))
                .is_some_and(|u| u == unit)
    })
}

impl From<Curves> for JointCurves {
    /// The four compared curves of a run, taken from it.
    fn from(c: Curves) -> JointCurves {
        JointCurves {
            t: c.t,
            contact_force_norm: c.contact_force_norm,
            friction_force_norm: c.friction_force_norm,
            master_uy: c.master_uy,
            dissipated: c.dissipated,
        }
    }
}

/// Stored reference curves are [`JointCurves`].
pub type ReferenceCurves = JointCurves;

impl JointCurves {
    /// The relative L2 errors of these curves against `reference` (module docs).
    pub fn errors_against(&self, reference: &JointCurves) -> ReferenceErrors {
        reference.errors_of(
            &self.t,
            [
                &self.contact_force_norm,
                &self.friction_force_norm,
                &self.master_uy,
                &self.dissipated,
            ],
        )
    }

    /// Reads a reference file: JSON if its name ends in `.json`, else CSV (module docs).
    ///
    /// # Errors
    /// [`RomError::Reference`] naming the file (and the line of a CSV) for a missing column, a
    /// value that is not a finite number, curves of different lengths, fewer than two outputs
    /// or times that do not increase.
    pub fn read(path: &Path) -> Result<JointCurves, Error> {
        let text = crate::files::read_text(path)?;
        let what = path.display().to_string();
        if path.extension().is_some_and(|e| e == "json") {
            JointCurves::parse_json(&text, &what)
        } else {
            JointCurves::parse_csv(&text, &what)
        }
    }

    /// Parses the CSV form; `what` names the source in errors.
    pub fn parse_csv(text: &str, what: &str) -> Result<JointCurves, Error> {
        let bad = |problem: ReferenceProblem| -> Error {
            RomError::Reference {
                file: what.to_string(),
                problem,
            }
            .into()
        };
        let mut r = csv::ReaderBuilder::new()
            .trim(csv::Trim::All)
            .from_reader(text.as_bytes());
        let header = r
            .headers()
            .map_err(|e| bad(ReferenceProblem::Csv(e)))?
            .clone();
        let mut index = [0usize; 4];
        for ((slot, name), unit) in index.iter_mut().zip(COLUMNS).zip(COLUMN_UNITS) {
            *slot = column_position(&header, name, unit)
                .ok_or_else(|| bad(ReferenceProblem::NoColumn { name }))?;
        }
        let mut cols: [Vec<f64>; 4] = Default::default();
        for (row, rec) in r.records().enumerate() {
            let rec = rec.map_err(|e| bad(ReferenceProblem::Csv(e)))?;
            for (col, &i) in cols.iter_mut().zip(&index) {
                let cell = rec.get(i).unwrap_or("");
                let v = cell
                    .parse::<f64>()
                    .ok()
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| {
                        bad(ReferenceProblem::NotFinite {
                            line: row + 2,
                            cell: crate::files::printable(cell).to_string(),
                        })
                    })?;
                col.push(v);
            }
        }
        let [t, fc, fr, uy] = cols;
        JointCurves::checked(t, fc, fr, uy, what)
            .map(|c| c.with_dissipated(optional_csv_column(text, "dissipated", "Nmm")))
    }

    /// Parses the compact JSON form (`cases/reference/compact.py`): the curves at the top level,
    /// or under `curves` as `jointrom transient --json` writes them.
    pub fn parse_json(text: &str, what: &str) -> Result<JointCurves, Error> {
        let bad = |problem: ReferenceProblem| -> Error {
            RomError::Reference {
                file: what.to_string(),
                problem,
            }
            .into()
        };
        let mut v: serde_json::Value =
            serde_json::from_str(text).map_err(|e| bad(ReferenceProblem::Json(e)))?;
        if v.get("t").is_none() && v.get("curves").is_some_and(|c| c.get("t").is_some()) {
            v = v["curves"].take();
        }
        let arr = |name: &'static str| -> Result<Vec<f64>, Error> {
            v[name]
                .as_array()
                .ok_or_else(|| bad(ReferenceProblem::NoArray { name }))?
                .iter()
                .map(|x| {
                    x.as_f64()
                        .filter(|x| x.is_finite())
                        .ok_or_else(|| bad(ReferenceProblem::NotNumber { name }))
                })
                .collect()
        };
        let dissipated = if v.get("dissipated").is_some() {
            arr("dissipated")?
        } else {
            Vec::new()
        };
        JointCurves::checked(
            arr(COLUMNS[0])?,
            arr(COLUMNS[1])?,
            arr(COLUMNS[2])?,
            arr(COLUMNS[3])?,
            what,
        )
        .and_then(|c| {
            if dissipated.is_empty() || dissipated.len() == c.t.len() {
                Ok(c.with_dissipated(dissipated))
            } else {
                Err(bad(ReferenceProblem::Lengths))
            }
        })
    }

    /// These curves with the dissipated energy `d` (empty or one value per output).
    fn with_dissipated(mut self, d: Vec<f64>) -> JointCurves {
        self.dissipated = if d.len() == self.t.len() {
            d
        } else {
            Vec::new()
        };
        self
    }

    fn checked(
        t: Vec<f64>,
        contact_force_norm: Vec<f64>,
        friction_force_norm: Vec<f64>,
        master_uy: Vec<f64>,
        what: &str,
    ) -> Result<JointCurves, Error> {
        let bad = |problem: ReferenceProblem| -> Error {
            RomError::Reference {
                file: what.to_string(),
                problem,
            }
            .into()
        };
        let n = t.len();
        if [&contact_force_norm, &friction_force_norm, &master_uy]
            .iter()
            .any(|c| c.len() != n)
        {
            return Err(bad(ReferenceProblem::Lengths));
        }
        if n < 2 {
            return Err(bad(ReferenceProblem::TooFew { outputs: n }));
        }
        if let Some(i) = t.windows(2).position(|w| w[1] <= w[0]) {
            return Err(bad(ReferenceProblem::NotIncreasing {
                output: i + 1,
                t: t[i + 1],
                previous: t[i],
            }));
        }
        Ok(JointCurves {
            t,
            contact_force_norm,
            friction_force_norm,
            master_uy,
            dissipated: Vec::new(),
        })
    }

    /// The errors of a run's curves against the reference (module docs).
    pub fn errors(&self, c: &Curves) -> ReferenceErrors {
        self.errors_of(
            &c.t,
            [
                &c.contact_force_norm,
                &c.friction_force_norm,
                &c.master_uy,
                &c.dissipated,
            ],
        )
    }

    /// The errors of the curves `[fc, fr, uy, D]` at times `t` against these (D may be empty).
    fn errors_of(&self, t: &[f64], [fc, fr, uy, d]: [&[f64]; 4]) -> ReferenceErrors {
        let l2 = |a: &[f64], r: &[f64]| relative_l2(t, a, &self.t, r);
        let (count, until) = self.shared_times(t);
        let with_d = !d.is_empty() && d.len() == t.len() && !self.dissipated.is_empty();
        ReferenceErrors {
            contact_force: l2(fc, &self.contact_force_norm),
            friction_force: l2(fr, &self.friction_force_norm),
            master_uy: l2(uy, &self.master_uy),
            dissipated: with_d.then(|| l2(d, &self.dissipated)).flatten(),
            dissipated_end: with_d
                .then(|| relative_at(t, d, &self.t, &self.dissipated, until))
                .flatten(),
            compared_outputs: count,
            compared_until: until,
        }
    }

    /// How many of `t` the reference has too (the matching of [`relative_l2`]), and the last.
    fn shared_times(&self, t: &[f64]) -> (usize, f64) {
        let spacing = |t: &[f64]| {
            t.windows(2)
                .map(|w| w[1] - w[0])
                .filter(|d| *d > 0.0)
                .fold(f64::INFINITY, f64::min)
        };
        let tol = 1e-6 * spacing(t).min(spacing(&self.t));
        let (mut count, mut last) = (0, f64::NAN);
        let mut j = 0;
        for &x in t {
            while j < self.t.len() && self.t[j] < x - tol {
                j += 1;
            }
            if j < self.t.len() && (self.t[j] - x).abs() <= tol {
                count += 1;
                last = x;
            }
        }
        (count, last)
    }
}

/// `|a(t) − r(t)| / |r(t)|` at the time `t` of both curves (matched as in [`relative_l2`];
/// `None` where either has no output there or the reference is zero).
fn relative_at(t_a: &[f64], a: &[f64], t_ref: &[f64], reference: &[f64], t: f64) -> Option<f64> {
    let near = |ts: &[f64]| {
        let i = ts.partition_point(|&x| x < t);
        [i.checked_sub(1), Some(i)]
            .into_iter()
            .flatten()
            .filter(|&i| i < ts.len())
            .min_by(|&i, &j| (ts[i] - t).abs().total_cmp(&(ts[j] - t).abs()))
    };
    let (i, j) = (near(t_a)?, near(t_ref)?);
    let gap = (t_a[i] - t).abs().max((t_ref[j] - t).abs());
    (reference[j] != 0.0 && gap <= 1e-9 * t.abs().max(1e-12))
        .then(|| (a[i] - reference[j]).abs() / reference[j].abs())
}

/// An optional CSV column of `text` by name, or `name_unit` (empty if absent or not all finite
/// numbers).
fn optional_csv_column(text: &str, name: &str, unit: &str) -> Vec<f64> {
    let mut r = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .from_reader(text.as_bytes());
    let Some(i) = r
        .headers()
        .ok()
        .and_then(|h| column_position(h, name, unit))
    else {
        return Vec::new();
    };
    let values: Option<Vec<f64>> = r
        .records()
        .map(|rec| {
            rec.ok()?
                .get(i)?
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
        })
        .collect();
    values.unwrap_or_default()
}

/// Relative L2 difference of `a` against `reference` over the times of `a` that the reference
/// has too (matched to 1e-6 of the smaller spacing); `None` with fewer than 2 matched nonzero
/// points or a zero reference.
pub fn relative_l2(t_a: &[f64], a: &[f64], t_ref: &[f64], reference: &[f64]) -> Option<f64> {
    let spacing = |t: &[f64]| {
        t.windows(2)
            .map(|w| w[1] - w[0])
            .filter(|d| *d > 0.0)
            .fold(f64::INFINITY, f64::min)
    };
    let tol = 1e-6 * spacing(t_a).min(spacing(t_ref));
    if !tol.is_finite() {
        return None;
    }
    let (mut num, mut den, mut matched) = (0.0, 0.0, 0usize);
    let mut j = 0;
    for (i, &t) in t_a.iter().enumerate() {
        while j < t_ref.len() && t_ref[j] < t - tol {
            j += 1;
        }
        if j < t_ref.len() && (t_ref[j] - t).abs() <= tol {
            num += (a[i] - reference[j]).powi(2);
            den += reference[j].powi(2);
            if reference[j] != 0.0 {
                matched += 1;
            }
        }
    }
    (matched >= 2 && den > 0.0).then(|| (num / den).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn curves(t: &[f64], f: impl Fn(f64) -> f64) -> Curves {
        Curves {
            t: t.to_vec(),
            contact_force_norm: t.iter().map(|&x| f(x)).collect(),
            friction_force_norm: t.iter().map(|&x| 0.25 * f(x)).collect(),
            master_uy: t.iter().map(|&x| -x).collect(),
            ..Curves::default()
        }
    }

    const CSV: &str = "t,contact_force_norm,friction_force_norm,master_uy,extra\n\
                       0,0,0,0,9\n1e-4,1,0.25,-1e-4,9\n2e-4,2,0.5,-2e-4,9\n3e-4,3,0.75,-3e-4,9\n";

    #[test]
    fn csv_reference_errors() {
        let r = JointCurves::parse_csv(CSV, "test").unwrap();
        assert_eq!(r.t.len(), 4);
        let exact = curves(&r.t.clone(), |x| 1e4 * x);
        let e = r.errors(&exact);
        assert!(e.contact_force.unwrap() < 1e-12 && e.master_uy.unwrap() < 1e-12);
        assert_eq!(e.compared_outputs, 4);
        // 10 % more force, over the first three outputs only (a shorter run).
        let off = curves(&r.t[..3], |x| 1.1e4 * x);
        let e = r.errors(&off);
        assert!((e.contact_force.unwrap() - 0.1).abs() < 1e-12, "{e:?}");
        assert!((e.friction_force.unwrap() - 0.1).abs() < 1e-12);
        assert_eq!((e.compared_outputs, e.compared_until), (3, 2e-4));
    }

    #[test]
    fn dissipated_energy_is_compared_where_the_reference_has_it() {
        let json = r#"{"t":[0,1,2],"contact_force_norm":[0,1,1],"friction_force_norm":[0,1,1],
                       "master_uy":[0,1,1],"dissipated":[0,1,2]}"#;
        let r = JointCurves::parse_json(json, "f.json").unwrap();
        let mut run = curves(&r.t, |x| x.min(1.0));
        run.friction_force_norm = r.friction_force_norm.clone();
        run.dissipated = vec![0.0, 1.0, 2.2];
        let e = r.errors(&run);
        let l2 = (0.04f64 / 5.0).sqrt();
        assert!((e.dissipated.unwrap() - l2).abs() < 1e-12, "{e:?}");
        assert!((e.dissipated_end.unwrap() - 0.1).abs() < 1e-12, "{e:?}");
        let without = JointCurves::parse_csv(CSV, "f.csv").unwrap();
        assert_eq!(without.errors(&run).dissipated, None);
        // A `jointrom transient --json` document: the same curves under `curves`.
        let run_json = format!(r#"{{"case":"c","status":"ok","curves":{json}}}"#);
        let nested = JointCurves::parse_json(&run_json, "run.json").unwrap();
        assert_eq!((&nested.t, &nested.dissipated), (&r.t, &r.dissipated));
        let short = json.replace("[0,1,2]}", "[0,1]}");
        let e = JointCurves::parse_json(&short, "f.json").unwrap_err();
        assert!(e.to_string().contains("different lengths"), "{e}");
    }

    #[test]
    fn bad_references_are_refused_with_their_place() {
        let missing = "t,contact_force_norm,master_uy\n0,0,0\n1,1,1\n";
        let e = JointCurves::parse_csv(missing, "f.csv").unwrap_err();
        assert!(e.to_string().contains("friction_force_norm"), "{e}");
        let nan = CSV.replace("2e-4,2,", "2e-4,nan,");
        let e = JointCurves::parse_csv(&nan, "f.csv").unwrap_err();
        assert!(e.to_string().contains("line 4"), "{e}");
        let back = CSV.replace("3e-4,3", "1e-4,3");
        let e = JointCurves::parse_csv(&back, "f.csv").unwrap_err();
        assert!(e.to_string().contains("do not increase"), "{e}");
        let json =
            r#"{"t":[0,1],"contact_force_norm":[0,1],"friction_force_norm":[0],"master_uy":[0,1]}"#;
        let e = JointCurves::parse_json(json, "f.json").unwrap_err();
        assert!(e.to_string().contains("different lengths"), "{e}");
        let ok = json.replace(r#"[0],"#, r#"[0,0.5],"#);
        assert_eq!(
            JointCurves::parse_json(&ok, "f.json").unwrap().t,
            vec![0.0, 1.0]
        );
    }
}
