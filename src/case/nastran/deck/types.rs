//! The typed cards: one struct per supported card, with its file position.

use crate::case::nastran::cards::Position;

/// A grid point.
#[derive(Clone, Debug, PartialEq)]
pub struct GridCard {
    /// Grid id.
    pub id: i64,
    /// Position (x, y, z), mm, in the basic system.
    pub xyz: [f64; 3],
    /// Permanent single-point constraints (PS): 0 or 123456.
    pub clamped: bool,
    /// Where the card is.
    pub at: Position,
}

/// A `CQUAD4`.
#[derive(Clone, Debug, PartialEq)]
pub struct QuadCard {
    /// Element id.
    pub id: i64,
    /// PSHELL id.
    pub pid: i64,
    /// Grid ids G1–G4.
    pub grids: [i64; 4],
    /// Where the card is.
    pub at: Position,
}

/// A `PSHELL`.
#[derive(Clone, Debug, PartialEq)]
pub struct PshellCard {
    /// MAT1 id (MID1 = MID2, MID3 blank or equal).
    pub mid: i64,
    /// Thickness, mm.
    pub thickness: f64,
    /// Where the card is.
    pub at: Position,
}

/// A `MAT1`.
#[derive(Clone, Debug, PartialEq)]
pub struct Mat1Card {
    /// Young's modulus E, N/mm².
    pub youngs_modulus: f64,
    /// Poisson's ratio ν.
    pub poisson_ratio: f64,
    /// Density ρ, t/mm³.
    pub density: f64,
    /// Where the card is.
    pub at: Position,
}

/// Where a `CWELD` attaches.
#[derive(Clone, Debug, PartialEq)]
pub enum WeldAttach {
    /// `PARTPAT`: the shells of PSHELLs `a` and `b`.
    Parts {
        /// PIDA.
        a: i64,
        /// PIDB.
        b: i64,
    },
    /// `ELPAT` / `ELEMID`: the sheets of the shells `a` and `b` around them.
    Elements {
        /// SHIDA.
        a: i64,
        /// SHIDB.
        b: i64,
    },
    /// `ALIGN`: a point weld (beam) between grids `a` and `b`.
    Align {
        /// GA.
        a: i64,
        /// GB.
        b: i64,
    },
}

/// A `CWELD`.
#[derive(Clone, Debug, PartialEq)]
pub struct WeldCard {
    /// Element id.
    pub id: i64,
    /// PWELD id.
    pub pid: i64,
    /// The attachment.
    pub attach: WeldAttach,
    /// The weld's location: grid GS or (XS, YS, ZS) in mm; `None` for `ALIGN`.
    pub location: Option<Location>,
    /// Where the card is.
    pub at: Position,
}

/// A location given by a grid or by coordinates.
#[derive(Clone, Debug, PartialEq)]
pub enum Location {
    /// A grid id (not a structural node: only its position counts).
    Grid(i64),
    /// Coordinates, mm.
    Point([f64; 3]),
}

/// A `PWELD`.
#[derive(Clone, Debug, PartialEq)]
pub struct PweldCard {
    /// MAT1 id.
    pub mid: i64,
    /// Nugget diameter D, mm.
    pub diameter: f64,
    /// Where the card is.
    pub at: Position,
}

/// A `CBAR` or `CBEAM` (circular `ROD` sections only).
#[derive(Clone, Debug, PartialEq)]
pub struct BeamCard {
    /// Element id.
    pub id: i64,
    /// PBARL/PBEAML id.
    pub pid: i64,
    /// End grids GA, GB.
    pub grids: [i64; 2],
    /// Where the card is.
    pub at: Position,
}

/// A `PBARL`/`PBEAML` with a `ROD` section.
#[derive(Clone, Debug, PartialEq)]
pub struct RodCard {
    /// MAT1 id.
    pub mid: i64,
    /// Diameter, mm (2 × DIM1).
    pub diameter: f64,
    /// Where the card is.
    pub at: Position,
}

/// A `CONM2` at a grid (no offset, basic system).
#[derive(Clone, Debug, PartialEq)]
pub struct MassCard {
    /// Element id.
    pub id: i64,
    /// Grid id.
    pub grid: i64,
    /// Mass, t.
    pub mass: f64,
    /// Inertia `[I11, I21, I22, I31, I32, I33]`, t·mm².
    pub inertia: [f64; 6],
    /// Where the card is.
    pub at: Position,
}

/// An `RBE2` with all six components.
#[derive(Clone, Debug, PartialEq)]
pub struct Rbe2Card {
    /// Element id.
    pub id: i64,
    /// The independent grid GN (the master node).
    pub master: i64,
    /// The dependent grids.
    pub slaves: Vec<i64>,
    /// Where the card is.
    pub at: Position,
}

/// A `CGAP`.
#[derive(Clone, Debug, PartialEq)]
pub struct GapCard {
    /// Element id.
    pub id: i64,
    /// PGAP id.
    pub pid: i64,
    /// End grids GA, GB (the gap direction runs from GA to GB).
    pub grids: [i64; 2],
    /// Where the card is.
    pub at: Position,
}

/// A `PGAP` (zero initial opening and preload).
#[derive(Clone, Debug, PartialEq)]
pub struct PgapCard {
    /// KA: closed normal stiffness, N/mm.
    pub normal_stiffness: f64,
    /// KT: closed tangential (stick) stiffness, N/mm.
    pub stick_stiffness: f64,
    /// MU1: friction coefficient.
    pub friction_coefficient: f64,
    /// Where the card is.
    pub at: Position,
}

/// A load component set: `FORCE`/`MOMENT`/`DAREA` entries of one set id.
#[derive(Clone, Debug, PartialEq)]
pub struct LoadEntry {
    /// Set id.
    pub sid: i64,
    /// Grid id.
    pub grid: i64,
    /// `[Fx, Fy, Fz (N), Mx, My, Mz (N·mm)]` contributed.
    pub components: [f64; 6],
    /// Where the card is.
    pub at: Position,
}

/// A `TLOAD1` (TYPE 0 = LOAD).
#[derive(Clone, Debug, PartialEq)]
pub struct Tload1Card {
    /// EXCITEID: the FORCE/MOMENT/DAREA set.
    pub excite: i64,
    /// Delay τ, s.
    pub delay: f64,
    /// TABLED1 id.
    pub table: i64,
    /// Where the card is.
    pub at: Position,
}

/// A `DLOAD` combination: overall scale and (scale, TLOAD1 set) terms.
#[derive(Clone, Debug, PartialEq)]
pub struct DloadCard {
    /// Overall scale S.
    pub scale: f64,
    /// `(S_i, L_i)`.
    pub terms: Vec<(f64, i64)>,
    /// Where the card is.
    pub at: Position,
}

/// A `TABLED1` (linear axes).
#[derive(Clone, Debug, PartialEq)]
pub struct TableCard {
    /// Points `[x, y]`, SKIP pairs removed.
    pub points: Vec<[f64; 2]>,
    /// FLAT/EXTRAP = 1: end values held outside the table (else linear extrapolation).
    pub flat: bool,
    /// Where the card is.
    pub at: Position,
}

/// An `SPC1` or `SPC` (all six components, zero enforced value).
#[derive(Clone, Debug, PartialEq)]
pub struct SpcCard {
    /// Set id.
    pub sid: i64,
    /// Constrained grids as inclusive id ranges (`G1 THRU G2`; a single grid is `(g, g)`);
    /// ids in a range that no GRID defines are skipped, as NASTRAN does.
    pub grids: Vec<(i64, i64)>,
    /// Where the card is.
    pub at: Position,
}
