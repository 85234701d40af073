//! A run's output curves as CSV (`transient --out DIR` writes `DIR/curves.csv`): one row per
//! output time, units in the column names.

use crate::error::{Error, ReportError};
use crate::integrate::Curves;

/// The column names, with units.
pub const CURVE_COLUMNS: [&str; 9] = [
    "t_s",
    "contact_force_norm_N",
    "friction_force_norm_N",
    "master_uy_mm",
    "kinetic_Nmm",
    "strain_Nmm",
    "pair_Nmm",
    "external_work_Nmm",
    "dissipated_Nmm",
];

/// The curves as CSV text: a header of [`CURVE_COLUMNS`], then t with 9 significant digits and
/// every other value with 11.
pub fn curves_csv(c: &Curves) -> Result<String, Error> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let fail = |e: csv::Error| ReportError::Curves {
        source: Box::new(e),
    };
    w.write_record(CURVE_COLUMNS).map_err(fail)?;
    for i in 0..c.t.len() {
        let values = [
            c.contact_force_norm[i],
            c.friction_force_norm[i],
            c.master_uy[i],
            c.kinetic[i],
            c.strain[i],
            c.pair[i],
            c.external_work[i],
            c.dissipated[i],
        ];
        let mut row = vec![format!("{:.8e}", c.t[i])];
        row.extend(values.iter().map(|v| format!("{v:.10e}")));
        w.write_record(&row).map_err(fail)?;
    }
    let bytes = w.into_inner().map_err(|e| ReportError::Curves {
        source: Box::new(e.into_error()),
    })?;
    Ok(String::from_utf8(bytes).map_err(|e| ReportError::Curves {
        source: Box::new(e),
    })?)
}
