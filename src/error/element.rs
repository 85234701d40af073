//! Why an element (or its material) could not be built.

use crate::linalg::LinalgError;

/// An element that could not be built: degenerate geometry, a bad material, a weld whose nugget
/// does not fit the sheets. Shown after `element: `.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ElementError {
    /// The material's constants are out of range (E > 0, −1 < ν < 0.5, ρ > 0).
    #[error(
        "invalid material: E = {youngs_modulus} N/mm², nu = {poisson_ratio}, rho = {density} \
         t/mm³ (need E > 0, -1 < nu < 0.5, rho > 0)"
    )]
    Material {
        /// E (N/mm²).
        youngs_modulus: f64,
        /// ν.
        poisson_ratio: f64,
        /// ρ (t/mm³).
        density: f64,
    },
    /// A Shell4 thickness (mm) that is not positive and finite.
    #[error("Shell4 thickness must be positive and finite, got {thickness} mm")]
    Shell4Thickness { thickness: f64 },
    /// A Shell4 with a NaN or infinite node coordinate (the four nodes, mm).
    #[error("Shell4 node coordinates are not finite: {nodes:?}")]
    Shell4NotFinite { nodes: [[f64; 3]; 4] },
    /// A Shell4 of zero area (the four nodes, mm).
    #[error("Shell4 is degenerate (zero area): {nodes:?}")]
    Shell4Degenerate { nodes: [[f64; 3]; 4] },
    /// A warped Shell4: `node` lies `offset` mm off the element plane.
    #[error(
        "Shell4 is warped: node {node:?} lies {offset:.3e} mm off the element plane (flat \
         elements only)"
    )]
    Shell4Warped { node: [f64; 3], offset: f64 },
    /// A Shell4 whose edge midpoints give no in-plane direction (the four nodes, mm).
    #[error("Shell4 has no usable edge direction: {nodes:?}")]
    Shell4NoEdge { nodes: [[f64; 3]; 4] },
    /// A Shell4 that is not convex or whose nodes are not in cyclic order (mm).
    #[error("Shell4 is not convex or its nodes are not in cyclic order: {nodes:?}")]
    Shell4NotConvex { nodes: [[f64; 3]; 4] },
    /// A Beam2 from `a` to `b` (mm) whose length is zero, negative or not finite.
    #[error(
        "Beam2: length |b - a| = {length} mm between a = {a:?} and b = {b:?} (need a finite \
         length > 0)"
    )]
    Beam2Length {
        length: f64,
        a: [f64; 3],
        b: [f64; 3],
    },
    /// A Beam2 from `a` to `b` (mm) whose diameter (mm) is zero, negative or not finite.
    #[error(
        "Beam2: diameter = {diameter} mm between a = {a:?} and b = {b:?} (need a finite \
         diameter > 0)"
    )]
    Beam2Diameter {
        diameter: f64,
        a: [f64; 3],
        b: [f64; 3],
    },
    /// A Beam2 from `a` to `b` (mm) with an invalid material (`source`).
    #[error("Beam2 between a = {a:?} and b = {b:?}: {source}")]
    Beam2Material {
        a: [f64; 3],
        b: [f64; 3],
        #[source]
        source: Box<ElementError>,
    },
    /// A Beam2 (`length`, `diameter` in mm, from `a` to `b`) whose stiffness or mass overflows.
    #[error(
        "Beam2: L = {length} mm, d = {diameter} mm between a = {a:?} and b = {b:?} give a \
         stiffness or mass that is not representable in f64"
    )]
    Beam2NotRepresentable {
        length: f64,
        diameter: f64,
        a: [f64; 3],
        b: [f64; 3],
    },
    /// Weld `index` (at `centre` (x, z), mm) cannot be fitted to its layer on sheet `sheet`.
    #[error(
        "welds[{index}] at (x, z) = ({}, {}) mm on sheet {sheet}: {problem}",
        centre[0],
        centre[1]
    )]
    WeldLayer {
        index: usize,
        centre: [f64; 2],
        sheet: usize,
        problem: WeldLayerProblem,
    },
    /// Weld `index` failed: `source` (a connector beam, its nugget, its neighbourhood).
    #[error("welds[{index}]: {source}")]
    InWeld {
        index: usize,
        #[source]
        source: Box<ElementError>,
    },
    /// A weld's nugget is sampled differently on the sheets `lower` and `upper`.
    #[error("the nugget is not sampled alike on sheets {lower} and {upper}")]
    NuggetSampling { lower: usize, upper: usize },
    /// A shell under a weld's nugget is degenerate (its isoparametric map has no inverse at a
    /// sampling point), so the bonded slab cannot be integrated on it.
    #[error("the shell of sheet {sheet} at (x, z) = ({x}, {z}) mm under the nugget is degenerate")]
    DegenerateNuggetShell { sheet: usize, x: f64, z: f64 },
    /// A weld's re-meshed neighbourhood has an internal stiffness that does not factor.
    #[error("the re-meshed neighbourhood's internal stiffness: linear algebra: {source}")]
    NeighbourhoodStiffness {
        #[source]
        source: LinalgError,
    },
}

/// Why a weld's nugget cannot be fitted rigidly to one sheet.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WeldLayerProblem {
    /// Fewer than three points of the nugget lie inside the sheet.
    TooFewPoints,
    /// The nugget's points on the sheet are collinear.
    Collinear,
}

impl std::fmt::Display for WeldLayerProblem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            WeldLayerProblem::TooFewPoints => {
                "fewer than three points of the nugget lie inside the sheets"
            }
            WeldLayerProblem::Collinear => "the nugget's points are collinear: no rigid fit",
        })
    }
}
