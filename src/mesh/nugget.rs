//! Sampling of an area weld's nugget disc on the welded sheets (the geometry half of
//! `crate::element::Weld`).
//!
//! The disc of radius R = d/2 around the weld centre is clipped to the rectangle common to all
//! welded sheets (a weld on a free edge keeps the half disc inside the sheets) and sampled by a
//! polar midpoint rule of equal-area cells: `m` annuli with radii `R·√(j/m)`, each cut into `s`
//! sectors; the point of a cell lies at radius `R·√((j + ½)/m)` and angle `2π(k + ½)/s` and
//! carries the cell's area `πR²/(m·s)`. A point is kept when it lies inside the clip rectangle, so
//! the kept weights sum to the clipped area within the rule's resolution. `s` is a multiple of
//! four, so no point lies on the axes through the centre and a weld centred on an edge keeps
//! exactly half of them.
//!
//! The rule follows the mesh so that the points always resolve the shells' shape functions:
//! with `h` the sheet's smaller element size, `m = max(`[`RINGS`]`, ⌈2R/h⌉)` and
//! `s = 4·max(`[`SECTORS`]`/4, ⌈πR/h⌉)`: point spacing at most h/2 along the rim.
//! Without that, a mesh finer than the point spacing would see the points as separate point
//! loads, and the weld would lose its mesh convergence again.
//!
//! Each point is located in the shell of its sheet that contains it and carries the bilinear
//! shape functions of that shell's nodes there: the sheet's displacement
//! at the point is `u(p) = Σ_a N_a(p) u_a` (likewise the rotations), whether or not a node lies
//! inside the disc — which makes the weld's footprint the nugget's and not the mesh's.

use super::{NuggetLayer, NuggetPoint};

/// Least number of annuli of the sampling rule.
pub(crate) const RINGS: usize = 6;
/// Least number of sectors per annulus (a multiple of four).
pub(crate) const SECTORS: usize = 24;

/// The shell containing a point and the bilinear shape functions of its nodes there.
pub(super) type Interpolation = ([usize; 4], [f64; 4]);

/// How a sheet is seen by the sampling: its index, mid-surface height (mm), smaller element size
/// (mm), and the shell and shape functions at a point (x, z) (mm).
pub(super) struct SheetView<'a> {
    pub(super) sheet: usize,
    pub(super) y: f64,
    pub(super) h: f64,
    pub(super) interpolation: &'a dyn Fn([f64; 2]) -> Interpolation,
}

/// Most sampling points of one nugget on one sheet: 10⁶ points are ~100 MB with their shape
/// functions, far beyond any mesh the DOF budget admits around one weld.
pub(super) const MAX_POINTS: f64 = 1e6;

/// The number of sampling points [`sample`] takes for a nugget of `diameter` on shells of
/// smaller side `h` (both mm), counted in floating point.
fn point_count(diameter: f64, h: f64) -> f64 {
    let radius = 0.5 * diameter;
    let rings = (RINGS as f64).max((2.0 * radius / h).ceil());
    let sectors = 4.0 * ((SECTORS / 4) as f64).max((std::f64::consts::PI * radius / h).ceil());
    rings * sectors
}

/// Refuses a nugget whose sampling would take more than [`MAX_POINTS`] points (a diameter
/// many orders above the element size), with the reason.
pub(super) fn check_points(diameter: f64, h: f64) -> Result<(), String> {
    let n = point_count(diameter, h);
    if n <= MAX_POINTS {
        Ok(())
    } else {
        Err(format!(
            "a {diameter} mm nugget on {h} mm shells would take {n:.3e} sampling points (at \
             most {MAX_POINTS:e}): the diameter is far larger than the elements"
        ))
    }
}

/// The sampling points of the disc (centre, diameter) kept by `inside` (the clip rectangle,
/// boundary included), on the sheet `view`.
pub(super) fn sample(
    centre: [f64; 2],
    diameter: f64,
    inside: &dyn Fn([f64; 2]) -> bool,
    view: &SheetView,
) -> NuggetLayer {
    let radius = 0.5 * diameter;
    let h = view.h;
    let rings = RINGS.max((2.0 * radius / h).ceil() as usize);
    let sectors = 4 * (SECTORS / 4).max((std::f64::consts::PI * radius / h).ceil() as usize);
    let weight = std::f64::consts::PI * radius * radius / (rings * sectors) as f64;
    let mut points = Vec::with_capacity(rings * sectors);
    for j in 0..rings {
        let r = radius * ((j as f64 + 0.5) / rings as f64).sqrt();
        for m in 0..sectors {
            let angle = std::f64::consts::TAU * (m as f64 + 0.5) / sectors as f64;
            let xz = [centre[0] + r * angle.cos(), centre[1] + r * angle.sin()];
            if !inside(xz) {
                continue;
            }
            let (nodes, shape) = (view.interpolation)(xz);
            points.push(NuggetPoint {
                xz,
                weight,
                nodes,
                shape,
            });
        }
    }
    NuggetLayer {
        sheet: view.sheet,
        y: view.y,
        points,
    }
}
