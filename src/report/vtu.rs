//! VTU (ParaView's XML UnstructuredGrid, ASCII) output of displacement shapes and fields.
//!
//! A shape is a vector `q` of the model's independent DOF (a mode, a TVD, a joint mode, the
//! state of a transient at one time). It is expanded to all nodes with the DOF map, `u = T q`
//! ([`crate::assembly::DofMap::expand`]: clamped DOF are zero, RBE2 slaves follow their master
//! rigidly, `u_s = u_m + θ_m × (x_s − x_m)`), and written per node as two point arrays,
//! `<name>_u` (u_x, u_y, u_z in mm) and `<name>_rot` (θ_x, θ_y, θ_z in rad). Cells: `Shell4` as
//! `VTK_QUAD` (9), `Beam2` as `VTK_LINE` (3), with the cell data `sheet` (−1 for beams; the map's
//! `group` for a user's model) and `thickness` (mm; the beam diameter for beams). A user's model
//! ([`crate::model::matrices`]) shows the cells its map lists; a node component without a matrix row is
//! drawn as zero. In ParaView, "Warp By Vector" on `<name>_u`
//! shows the deformed shape.
//!
//! [`write_shapes`] puts several shapes in one file (one array pair each); [`write_series`]
//! writes one file per time plus a `.pvd` collection that ParaView plays as an animation.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use faer::MatRef;

use crate::error::{Error, ReportError};
use crate::model::{CellNodes, Model};

/// VTK cell type of a 4-node quadrilateral.
const VTK_QUAD: u8 = 9;
/// VTK cell type of a 2-node line.
const VTK_LINE: u8 = 3;

/// The XML of one file: the mesh and, per shape, its two point arrays.
fn document(model: &Model, shapes: &[(String, Vec<f64>)]) -> String {
    let geo = &model.geometry;
    let nodes = geo.nodes.len();
    let cells = geo.cells.len();
    let mut s = String::new();
    let _ = writeln!(s, r#"<?xml version="1.0"?>"#);
    let _ = writeln!(
        s,
        r#"<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" header_type="UInt64">"#
    );
    let _ = writeln!(s, "<UnstructuredGrid>");
    let _ = writeln!(
        s,
        r#"<Piece NumberOfPoints="{nodes}" NumberOfCells="{cells}">"#
    );
    let _ = writeln!(s, "<Points>");
    let _ = writeln!(
        s,
        r#"<DataArray type="Float64" NumberOfComponents="3" format="ascii">"#
    );
    for p in &geo.nodes {
        let _ = writeln!(s, "{:e} {:e} {:e}", p[0], p[1], p[2]);
    }
    let _ = writeln!(s, "</DataArray>\n</Points>");
    let _ = writeln!(s, "<Cells>");
    let _ = writeln!(
        s,
        r#"<DataArray type="Int64" Name="connectivity" format="ascii">"#
    );
    for c in &geo.cells {
        let n = c.nodes.as_slice();
        for (k, i) in n.iter().enumerate() {
            let _ = write!(s, "{i}{}", if k + 1 < n.len() { " " } else { "\n" });
        }
    }
    let _ = writeln!(s, "</DataArray>");
    let _ = writeln!(
        s,
        r#"<DataArray type="Int64" Name="offsets" format="ascii">"#
    );
    let mut off = 0usize;
    for c in &geo.cells {
        off += c.nodes.as_slice().len();
        let _ = write!(s, "{off} ");
    }
    let _ = writeln!(s, "\n</DataArray>");
    let _ = writeln!(s, r#"<DataArray type="UInt8" Name="types" format="ascii">"#);
    for c in &geo.cells {
        let t = match c.nodes {
            CellNodes::Quad4(_) => VTK_QUAD,
            CellNodes::Line2(_) => VTK_LINE,
        };
        let _ = write!(s, "{t} ");
    }
    let _ = writeln!(s, "\n</DataArray>\n</Cells>");
    let _ = writeln!(s, "<CellData>");
    let _ = writeln!(s, r#"<DataArray type="Int32" Name="sheet" format="ascii">"#);
    for c in &geo.cells {
        let _ = write!(s, "{} ", c.group);
    }
    let _ = writeln!(s, "\n</DataArray>");
    let _ = writeln!(
        s,
        r#"<DataArray type="Float64" Name="thickness" format="ascii">"#
    );
    for c in &geo.cells {
        let _ = write!(s, "{:e} ", c.size);
    }
    let _ = writeln!(s, "\n</DataArray>\n</CellData>");
    let _ = writeln!(s, "<PointData>");
    for (name, u) in shapes {
        for (suffix, first) in [("u", 0usize), ("rot", 3)] {
            let _ = writeln!(
                s,
                r#"<DataArray type="Float64" Name="{name}_{suffix}" NumberOfComponents="3" format="ascii">"#
            );
            for i in 0..nodes {
                let b = 6 * i + first;
                let _ = writeln!(s, "{:e} {:e} {:e}", u[b], u[b + 1], u[b + 2]);
            }
            let _ = writeln!(s, "</DataArray>");
        }
    }
    let _ = writeln!(s, "</PointData>");
    let _ = writeln!(s, "</Piece>\n</UnstructuredGrid>\n</VTKFile>");
    s
}

/// Checks a shape name (letters, digits, `_`, `-`: it becomes an XML attribute and a file name).
fn check_name(name: &str) -> Result<(), Error> {
    if name.is_empty()
        || !name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
    {
        return Err(ReportError::VtuName {
            name: name.to_string(),
        }
        .into());
    }
    Ok(())
}

/// Expands the columns of `shapes` (independent DOF × k) and names them `<prefix>_01`, ...
fn expand_columns(
    model: &Model,
    prefix: &str,
    shapes: MatRef<'_, f64>,
) -> Result<Vec<(String, Vec<f64>)>, Error> {
    check_name(prefix)?;
    if shapes.nrows() != model.dofs() {
        return Err(ReportError::Rows {
            what: "VTU: shapes",
            rows: shapes.nrows(),
            dofs: model.dofs(),
        }
        .into());
    }
    (0..shapes.ncols())
        .map(|c| {
            let q: Vec<f64> = shapes.col(c).iter().copied().collect();
            if let Some(i) = q.iter().position(|v| !v.is_finite()) {
                return Err(ReportError::VtuNotFinite {
                    prefix: prefix.to_string(),
                    column: c,
                    dof: i,
                }
                .into());
            }
            Ok((format!("{prefix}_{:02}", c + 1), model.dof_map.expand(&q)))
        })
        .collect()
}

/// Writes the columns of `shapes` (model DOF × k) into one VTU file at `path`, named
/// `<prefix>_01`, `<prefix>_02`, ... (two point arrays each, see the module docs).
pub fn write_shapes(
    model: &Model,
    prefix: &str,
    shapes: MatRef<'_, f64>,
    path: &Path,
) -> Result<(), Error> {
    let fields = expand_columns(model, prefix, shapes)?;
    crate::files::write_atomic(path, document(model, &fields))
}

/// Writes a transient displacement field: `states[k]` (model DOF) at `times[k]` (s) as
/// `<dir>/<prefix>_NNNN.vtu` (array `<prefix>`) and the collection `<dir>/<prefix>.pvd`; returns
/// the `.pvd` path.
pub fn write_series(
    model: &Model,
    prefix: &str,
    times: &[f64],
    states: &[Vec<f64>],
    dir: &Path,
) -> Result<PathBuf, Error> {
    check_name(prefix)?;
    if times.len() != states.len() {
        return Err(ReportError::SeriesLength {
            times: times.len(),
            states: states.len(),
        }
        .into());
    }
    crate::files::create_dir(dir)?;
    let mut pvd = String::from(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"1.0\">\n<Collection>\n",
    );
    for (k, (t, q)) in times.iter().zip(states).enumerate() {
        if q.len() != model.dofs() {
            return Err(ReportError::SeriesState {
                state: k,
                len: q.len(),
                dofs: model.dofs(),
            }
            .into());
        }
        if !t.is_finite() || q.iter().any(|v| !v.is_finite()) {
            return Err(ReportError::SeriesNotFinite { state: k, t: *t }.into());
        }
        let name = format!("{prefix}_{k:04}.vtu");
        let file = dir.join(&name);
        let doc = document(model, &[(prefix.to_string(), model.dof_map.expand(q))]);
        crate::files::write_atomic(&file, doc)?;
        let _ = writeln!(
            pvd,
            "<DataSet timestep=\"{t:e}\" group=\"\" part=\"0\" file=\"{name}\"/>"
        );
    }
    pvd.push_str("</Collection>\n</VTKFile>\n");
    let path = dir.join(format!("{prefix}.pvd"));
    crate::files::write_atomic(&path, pvd)?;
    Ok(path)
}
