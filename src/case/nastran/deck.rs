//! From cards to a typed deck: each supported card's fields read and checked (type, sign,
//! range, unsupported options), ids unique per kind, the others sorted into ignored (a warning)
//! and refused (an error naming the line). References between cards are resolved later, when
//! the mesh is built (`crate::mesh`'s deck builder).

use std::collections::{BTreeMap, BTreeSet};

use super::cards::{Card, Cards, Position};
use crate::error::Error;

/// Cards that carry no mechanics jointrom models (solver controls, coordinate systems used by
/// nothing, plot elements): read past, listed in a warning.
pub const IGNORED: &[&str] = &[
    "EIGRL", "EIGR", "NLPARM", "NLPCI", "CORD2R", "CORD2C", "CORD2S", "CORD1R", "CORD1C", "CORD1S",
    "PLOTEL", "SWLDPRM", "DTI", "MDLPRM", "ECHOON", "ECHOOFF",
];

/// Cards that change the mechanics in ways jointrom does not model: an error naming the line.
pub const REFUSED: &[(&str, &str)] = &[
    (
        "CTRIA3",
        "jointrom's shell is the 4-node Shell4: mesh the sheets with CQUAD4 only",
    ),
    (
        "CTRIA6",
        "jointrom's shell is the 4-node Shell4: mesh the sheets with CQUAD4 only",
    ),
    (
        "CTRIAR",
        "jointrom's shell is the 4-node Shell4: mesh the sheets with CQUAD4 only",
    ),
    (
        "CQUAD8",
        "jointrom's shell is the 4-node Shell4 (no mid-side nodes)",
    ),
    ("CQUADR", "jointrom's shell is the 4-node Shell4 (CQUAD4)"),
    ("CQUAD", "jointrom's shell is the 4-node Shell4 (CQUAD4)"),
    ("CSHEAR", "shear panels are not modelled"),
    (
        "CHEXA",
        "solid elements are not modelled (sheets are Shell4)",
    ),
    (
        "CPENTA",
        "solid elements are not modelled (sheets are Shell4)",
    ),
    (
        "CTETRA",
        "solid elements are not modelled (sheets are Shell4)",
    ),
    (
        "CPYRAM",
        "solid elements are not modelled (sheets are Shell4)",
    ),
    (
        "MAT2",
        "anisotropic shell materials are not modelled (MAT1 only)",
    ),
    ("MAT8", "orthotropic materials are not modelled (MAT1 only)"),
    ("MAT9", "anisotropic materials are not modelled (MAT1 only)"),
    (
        "MATS1",
        "material nonlinearity is not modelled (linear elastic MAT1)",
    ),
    ("MATT1", "temperature-dependent materials are not modelled"),
    ("PCOMP", "laminates are not modelled (PSHELL with MAT1)"),
    ("PCOMPG", "laminates are not modelled (PSHELL with MAT1)"),
    ("CELAS1", "scalar springs are not modelled"),
    ("CELAS2", "scalar springs are not modelled"),
    ("CELAS3", "scalar springs are not modelled"),
    ("CELAS4", "scalar springs are not modelled"),
    ("CBUSH", "bushings are not modelled"),
    ("CBUSH1D", "bushings are not modelled"),
    ("CDAMP1", "dampers are not modelled (the model is undamped)"),
    ("CDAMP2", "dampers are not modelled (the model is undamped)"),
    ("CDAMP3", "dampers are not modelled (the model is undamped)"),
    ("CDAMP4", "dampers are not modelled (the model is undamped)"),
    ("CVISC", "dampers are not modelled (the model is undamped)"),
    (
        "CROD",
        "rods are not modelled (beams: CBAR/CBEAM with a PBARL/PBEAML ROD)",
    ),
    (
        "CONROD",
        "rods are not modelled (beams: CBAR/CBEAM with a PBARL/PBEAML ROD)",
    ),
    ("CTUBE", "tubes are not modelled"),
    ("CFAST", "fasteners are not modelled (spot welds: CWELD)"),
    ("CSEAM", "seam welds are not modelled (spot welds: CWELD)"),
    (
        "MPC",
        "multipoint constraints are not modelled (rigid tie: one RBE2)",
    ),
    (
        "MPCADD",
        "multipoint constraints are not modelled (rigid tie: one RBE2)",
    ),
    (
        "RBE3",
        "interpolation elements are not modelled (rigid tie: one RBE2)",
    ),
    ("RBAR", "rigid bars are not modelled (rigid tie: one RBE2)"),
    ("RBAR1", "rigid bars are not modelled (rigid tie: one RBE2)"),
    (
        "RBE1",
        "rigid elements other than one RBE2 are not modelled",
    ),
    ("RROD", "rigid rods are not modelled"),
    ("RSPLINE", "rigid splines are not modelled"),
    (
        "CONM1",
        "general mass matrices are not modelled (CONM2 only)",
    ),
    ("CMASS1", "scalar masses are not modelled (CONM2 only)"),
    ("CMASS2", "scalar masses are not modelled (CONM2 only)"),
    ("CMASS3", "scalar masses are not modelled (CONM2 only)"),
    ("CMASS4", "scalar masses are not modelled (CONM2 only)"),
    ("NSM", "non-structural mass is not modelled"),
    ("NSM1", "non-structural mass is not modelled"),
    ("NSML", "non-structural mass is not modelled"),
    ("NSML1", "non-structural mass is not modelled"),
    (
        "GRAV",
        "gravity loads are not modelled (loads: FORCE/MOMENT at the RBE2 grid)",
    ),
    (
        "PLOAD",
        "pressure loads are not modelled (loads: FORCE/MOMENT at the RBE2 grid)",
    ),
    (
        "PLOAD1",
        "beam loads are not modelled (loads: FORCE/MOMENT at the RBE2 grid)",
    ),
    (
        "PLOAD2",
        "pressure loads are not modelled (loads: FORCE/MOMENT at the RBE2 grid)",
    ),
    (
        "PLOAD4",
        "pressure loads are not modelled (loads: FORCE/MOMENT at the RBE2 grid)",
    ),
    (
        "LOAD",
        "static load combinations are not read (TLOAD1 → FORCE/MOMENT or DAREA)",
    ),
    ("TLOAD2", "only TLOAD1 with a TABLED1 is read"),
    ("RLOAD1", "frequency-response loads are not modelled"),
    ("RLOAD2", "frequency-response loads are not modelled"),
    ("SPCD", "enforced displacements are not modelled"),
    ("TEMP", "thermal loads are not modelled"),
    ("TEMPD", "thermal loads are not modelled"),
    ("DEFORM", "enforced deformations are not modelled"),
    (
        "SUPORT",
        "free-free models are not modelled (clamp with SPC1 123456)",
    ),
    (
        "SUPORT1",
        "free-free models are not modelled (clamp with SPC1 123456)",
    ),
    ("CGAPG", "only node-to-node gaps (CGAP) are modelled"),
    (
        "BCTABLE",
        "surface contact is not modelled (node-to-node CGAP pairs)",
    ),
    (
        "BSURF",
        "surface contact is not modelled (node-to-node CGAP pairs)",
    ),
    (
        "BCPROP",
        "surface contact is not modelled (node-to-node CGAP pairs)",
    ),
    (
        "BCONP",
        "surface contact is not modelled (node-to-node CGAP pairs)",
    ),
    (
        "BLSEG",
        "surface contact is not modelled (node-to-node CGAP pairs)",
    ),
    (
        "DELAY",
        "DELAY cards are not read (give TLOAD1's delay as a real number)",
    ),
    ("TABLED2", "only TABLED1 is read"),
    ("TABLED3", "only TABLED1 is read"),
    ("TABLED4", "only TABLED1 is read"),
];

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

/// The typed deck.
#[derive(Clone, Debug, Default)]
pub struct Deck {
    /// The cards as read (files, positions, case control).
    pub cards: Cards,
    /// GRIDs by id.
    pub grids: BTreeMap<i64, GridCard>,
    /// CQUAD4s in file order.
    pub quads: Vec<QuadCard>,
    /// PSHELLs by id.
    pub pshells: BTreeMap<i64, PshellCard>,
    /// MAT1s by id.
    pub materials: BTreeMap<i64, Mat1Card>,
    /// CWELDs in file order.
    pub welds: Vec<WeldCard>,
    /// PWELDs by id.
    pub pwelds: BTreeMap<i64, PweldCard>,
    /// CBAR/CBEAMs in file order.
    pub beams: Vec<BeamCard>,
    /// PBARL/PBEAML ROD sections by id.
    pub rods: BTreeMap<i64, RodCard>,
    /// CONM2s in file order.
    pub masses: Vec<MassCard>,
    /// RBE2s in file order.
    pub rbe2: Vec<Rbe2Card>,
    /// SPC1/SPC entries.
    pub spcs: Vec<SpcCard>,
    /// SPCADD: set id → member sets.
    pub spcadds: BTreeMap<i64, (Vec<i64>, Position)>,
    /// FORCE/MOMENT/DAREA entries.
    pub loads: Vec<LoadEntry>,
    /// TLOAD1s by set id.
    pub tloads: BTreeMap<i64, Tload1Card>,
    /// DLOADs by set id.
    pub dloads: BTreeMap<i64, DloadCard>,
    /// TABLED1s by id.
    pub tables: BTreeMap<i64, TableCard>,
    /// TSTEP/TSTEPNL by set id: the end time Σ Nᵢ·DTᵢ (s) and the card.
    pub tsteps: BTreeMap<i64, (f64, Position)>,
    /// CGAPs in file order.
    pub gaps: Vec<GapCard>,
    /// PGAPs by id.
    pub pgaps: BTreeMap<i64, PgapCard>,
    /// `PARAM,WTMASS`: the factor on every mass (density, CONM2), 1 by default.
    pub wtmass: f64,
    /// Warnings (ignored and unknown cards).
    pub warnings: Vec<String>,
}

/// Reads and types a deck (see the module docs of [`super`]).
pub fn read(path: &std::path::Path) -> Result<Deck, Error> {
    let cards = super::cards::read(path)?;
    interpret(cards)
}

/// Types the cards of a read deck.
pub fn interpret(cards: Cards) -> Result<Deck, Error> {
    let mut deck = Deck {
        wtmass: 1.0,
        ..Deck::default()
    };
    let mut ignored: BTreeMap<String, usize> = BTreeMap::new();
    let mut unknown: BTreeMap<String, usize> = BTreeMap::new();
    for card in &cards.cards {
        let f = Fields {
            cards: &cards,
            card,
        };
        match card.name.as_str() {
            "GRID" => deck.grid(&f)?,
            "CQUAD4" => deck.quad(&f)?,
            "PSHELL" => deck.pshell(&f)?,
            "MAT1" => deck.mat1(&f)?,
            "CWELD" => deck.cweld(&f)?,
            "PWELD" => deck.pweld(&f)?,
            "CBAR" | "CBEAM" => deck.beam(&f)?,
            "PBARL" | "PBEAML" => deck.rod(&f)?,
            "PBAR" | "PBEAM" => {
                return Err(f.error(
                    "general beam sections are not read: give the weld or beam a circular \
                     section as PBARL/PBEAML with TYPE ROD",
                ))
            }
            "CONM2" => deck.conm2(&f)?,
            "RBE2" => deck.rbe2_card(&f)?,
            "SPC1" | "SPC" => deck.spc(&f)?,
            "SPCADD" => deck.spcadd(&f)?,
            "FORCE" | "MOMENT" => deck.force(&f)?,
            "DAREA" => deck.darea(&f)?,
            "TLOAD1" => deck.tload1(&f)?,
            "DLOAD" => deck.dload(&f)?,
            "TABLED1" => deck.tabled1(&f)?,
            "TSTEP" | "TSTEPNL" => deck.tstep(&f)?,
            "CGAP" => deck.cgap(&f)?,
            "PGAP" => deck.pgap(&f)?,
            "PARAM" => {
                if !deck.param(&f)? {
                    *ignored.entry("PARAM".into()).or_default() += 1;
                }
            }
            name => {
                if let Some((_, why)) = REFUSED.iter().find(|(n, _)| *n == name) {
                    return Err(f.error(format!("not supported: {why}")));
                }
                let list = if IGNORED.contains(&name) {
                    &mut ignored
                } else {
                    &mut unknown
                };
                *list.entry(crate::files::printable(name)).or_default() += 1;
            }
        }
    }
    deck.shared_ids(&cards)?;
    let list = |m: &BTreeMap<String, usize>| {
        m.iter()
            .map(|(n, c)| format!("{n} ×{c}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let file = cards.files[0].display().to_string();
    if !ignored.is_empty() {
        deck.warnings.push(format!(
            "{file}: ignored (no mechanics jointrom models): {}",
            list(&ignored)
        ));
    }
    if !unknown.is_empty() {
        deck.warnings.push(format!(
            "{file}: unknown cards, not read: {}",
            list(&unknown)
        ));
    }
    if let Some(at) = cards.control.extra_subcase {
        deck.warnings.push(format!(
            "{}: several subcases: jointrom reads the case control's first SPC, DLOAD and TSTEP",
            cards.locate(at)
        ));
    }
    deck.cards = cards;
    Ok(deck)
}

/// Field access with errors naming the card and the field.
pub(crate) struct Fields<'a> {
    pub(crate) cards: &'a Cards,
    pub(crate) card: &'a Card,
}

impl Fields<'_> {
    pub(crate) fn error(&self, reason: impl Into<String>) -> Error {
        self.cards.error(self.card, reason)
    }

    /// Data field `k` (1 = the first after the name), trimmed, "" when blank or absent.
    pub(crate) fn raw(&self, k: usize) -> &str {
        self.card.fields.get(k - 1).map_or("", |s| s.as_str())
    }

    fn bad(&self, name: &str, expected: &str, found: &str) -> Error {
        self.error(format!(
            "{name}: expected {expected}, found `{}`",
            crate::files::printable(found)
        ))
    }

    pub(crate) fn int_opt(&self, k: usize, name: &str) -> Result<Option<i64>, Error> {
        let s = self.raw(k);
        if s.is_empty() {
            return Ok(None);
        }
        let digits = s.strip_prefix(['+', '-']).unwrap_or(s);
        if digits.is_empty() || digits.len() > 15 || !digits.bytes().all(|b| b.is_ascii_digit()) {
            return Err(self.bad(name, "an integer", s));
        }
        s.parse::<i64>()
            .map(Some)
            .map_err(|_| self.bad(name, "an integer", s))
    }

    pub(crate) fn int(&self, k: usize, name: &str) -> Result<i64, Error> {
        self.int_opt(k, name)?
            .ok_or_else(|| self.error(format!("{name}: required, found a blank field")))
    }

    /// A positive id.
    pub(crate) fn id(&self, k: usize, name: &str) -> Result<i64, Error> {
        let v = self.int(k, name)?;
        if v <= 0 {
            return Err(self.error(format!("{name}: an id must be > 0, found {v}")));
        }
        Ok(v)
    }

    pub(crate) fn real_opt(&self, k: usize, name: &str) -> Result<Option<f64>, Error> {
        let s = self.raw(k);
        if s.is_empty() {
            return Ok(None);
        }
        parse_real(s)
            .map(Some)
            .ok_or_else(|| self.bad(name, "a finite real number", s))
    }

    pub(crate) fn real(&self, k: usize, name: &str) -> Result<f64, Error> {
        self.real_opt(k, name)?
            .ok_or_else(|| self.error(format!("{name}: required, found a blank field")))
    }

    fn real_or(&self, k: usize, name: &str, default: f64) -> Result<f64, Error> {
        Ok(self.real_opt(k, name)?.unwrap_or(default))
    }

    fn word(&self, k: usize) -> String {
        self.raw(k).to_ascii_uppercase()
    }

    /// Fields from `k` on must be blank (`what` names them in the error).
    fn blank_from(&self, k: usize, what: &str) -> Result<(), Error> {
        if let Some(j) = (k..=self.card.fields.len()).find(|&j| !self.raw(j).is_empty()) {
            return Err(self.error(format!(
                "{what}: unexpected `{}` in data field {j}",
                crate::files::printable(self.raw(j))
            )));
        }
        Ok(())
    }
}

/// A NASTRAN real: `1.5`, `-.5`, `1.E4`, `1.5D-3`, `7.85-9` (exponent without E), `2` (an
/// integer, read as a real). `None` for anything else, and for non-finite values.
pub fn parse_real(s: &str) -> Option<f64> {
    let upper = s.trim().to_ascii_uppercase().replace('D', "E");
    if upper.is_empty()
        || !upper
            .bytes()
            .all(|b| b.is_ascii_digit() || matches!(b, b'.' | b'+' | b'-' | b'E'))
    {
        return None;
    }
    let text = if upper.contains('E') {
        upper
    } else {
        // An exponent sign after the mantissa: 7.85-9 → 7.85E-9.
        match upper[1..].find(['+', '-']) {
            Some(i) => format!("{}E{}", &upper[..=i], &upper[i + 1..]),
            None => upper,
        }
    };
    let v: f64 = text.parse().ok()?;
    v.is_finite().then_some(v)
}

impl Deck {
    /// NASTRAN's id spaces: element ids are unique across all elements (CQUAD4, CWELD,
    /// CBAR/CBEAM, CGAP, CONM2, RBE2), property ids across all properties (PSHELL, PWELD,
    /// PBARL/PBEAML, PGAP).
    fn shared_ids(&self, cards: &Cards) -> Result<(), Error> {
        let elements = self
            .quads
            .iter()
            .map(|e| (e.id, "CQUAD4", e.at))
            .chain(self.welds.iter().map(|e| (e.id, "CWELD", e.at)))
            .chain(self.beams.iter().map(|e| (e.id, "CBAR/CBEAM", e.at)))
            .chain(self.gaps.iter().map(|e| (e.id, "CGAP", e.at)))
            .chain(self.masses.iter().map(|e| (e.id, "CONM2", e.at)))
            .chain(self.rbe2.iter().map(|e| (e.id, "RBE2", e.at)));
        let properties = self
            .pshells
            .iter()
            .map(|(&id, p)| (id, "PSHELL", p.at))
            .chain(self.pwelds.iter().map(|(&id, p)| (id, "PWELD", p.at)))
            .chain(self.rods.iter().map(|(&id, p)| (id, "PBARL/PBEAML", p.at)))
            .chain(self.pgaps.iter().map(|(&id, p)| (id, "PGAP", p.at)));
        for (space, ids) in [
            ("element", elements.collect::<Vec<_>>()),
            ("property", properties.collect::<Vec<_>>()),
        ] {
            let mut seen: BTreeMap<i64, (&str, Position)> = BTreeMap::new();
            for (id, card, at) in ids {
                if let Some((first, first_at)) = seen.insert(id, (card, at)) {
                    let (later, earlier) = if (at.file, at.line) > (first_at.file, first_at.line) {
                        ((card, at), (first, first_at))
                    } else {
                        ((first, first_at), (card, at))
                    };
                    return Err(cards.error_at(
                        format!("{} {id}", later.0),
                        later.1,
                        format!(
                            "{space} id {id} is also {} {id} at {}: NASTRAN's {space} ids are \
                             unique across kinds",
                            earlier.0,
                            cards.locate(earlier.1)
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    /// A `PARAM`: `WTMASS` is applied, parameters that change the mechanics jointrom models are
    /// refused (`LGDISP` ≥ 0: large displacements; `G`, `W3`, `W4`: damping); `true` when it
    /// was read, `false` when it is ignored.
    fn param(&mut self, f: &Fields) -> Result<bool, Error> {
        let name = f.word(1);
        match name.as_str() {
            "WTMASS" => {
                let w = f.real(2, "WTMASS")?;
                if w <= 0.0 {
                    return Err(f.error(format!("WTMASS must be > 0, found {w}")));
                }
                self.wtmass = w;
                Ok(true)
            }
            "LGDISP" if f.int_opt(2, "LGDISP")?.unwrap_or(-1) >= 0 => Err(f.error(
                "LGDISP ≥ 0 asks for large displacements: jointrom's structure is linear \
                 (the joints carry the nonlinearity)",
            )),
            "G" | "W3" | "W4" if f.real_opt(2, &name)?.unwrap_or(0.0) != 0.0 => Err(f.error(
                format!("{name}: structural damping is not modelled (the model is undamped)"),
            )),
            _ => Ok(false),
        }
    }

    fn unique<T>(
        f: &Fields,
        map: &mut BTreeMap<i64, T>,
        id: i64,
        value: T,
        at: fn(&T) -> Position,
    ) -> Result<(), Error> {
        if let Some(old) = map.get(&id) {
            return Err(f.error(format!(
                "id {id} is defined twice (first at {})",
                f.cards.locate(at(old))
            )));
        }
        map.insert(id, value);
        Ok(())
    }

    fn grid(&mut self, f: &Fields) -> Result<(), Error> {
        let id = f.id(1, "ID")?;
        for (k, name) in [(2, "CP"), (6, "CD")] {
            if f.int_opt(k, name)?.unwrap_or(0) != 0 {
                return Err(f.error(format!(
                    "{name}: coordinate systems other than the basic one (0) are not read"
                )));
            }
        }
        let xyz = [f.real(3, "X1")?, f.real(4, "X2")?, f.real(5, "X3")?];
        let ps = f.raw(7);
        let clamped = match ps {
            "" | "0" => false,
            _ if is_all_six(ps) => true,
            _ => {
                return Err(f.error(format!(
                    "PS: `{}`: jointrom constrains all six components of a grid (123456) or none",
                    crate::files::printable(ps)
                )))
            }
        };
        if f.int_opt(8, "SEID")?.unwrap_or(0) != 0 {
            return Err(f.error("SEID: superelements are not read"));
        }
        let at = f.card.at;
        Self::unique(
            f,
            &mut self.grids,
            id,
            GridCard {
                id,
                xyz,
                clamped,
                at,
            },
            |g| g.at,
        )
    }

    fn quad(&mut self, f: &Fields) -> Result<(), Error> {
        let (id, at) = (f.id(1, "EID")?, f.card.at);
        let pid = f.id(2, "PID")?;
        let grids = [
            f.id(3, "G1")?,
            f.id(4, "G2")?,
            f.id(5, "G3")?,
            f.id(6, "G4")?,
        ];
        if f.real_opt(8, "ZOFFS")?.unwrap_or(0.0) != 0.0 {
            return Err(f.error("ZOFFS: shell offsets are not modelled (mid-surface nodes)"));
        }
        for k in 11..=15 {
            if !f.raw(k).is_empty() {
                return Err(f.error(
                    "TFLAG, T1–T4: corner thicknesses are not read: the thickness is the PSHELL's",
                ));
            }
        }
        self.quads.push(QuadCard { id, pid, grids, at });
        Ok(())
    }

    fn pshell(&mut self, f: &Fields) -> Result<(), Error> {
        let id = f.id(1, "PID")?;
        let mid = f.id(2, "MID1")?;
        let thickness = f.real(3, "T")?;
        if thickness <= 0.0 {
            return Err(f.error(format!(
                "T: the thickness must be > 0, found {thickness} mm"
            )));
        }
        match f.int_opt(4, "MID2")? {
            Some(m) if m == mid => {}
            Some(m) => {
                return Err(f.error(format!(
                    "MID2 = {m} differs from MID1 = {mid}: jointrom's shells bend with the membrane's material"
                )))
            }
            None => {
                return Err(f.error(
                    "MID2 is blank: a membrane-only shell; jointrom's Shell4 bends (set MID2 = MID1)",
                ))
            }
        }
        if (f.real_or(5, "12I/T**3", 1.0)? - 1.0).abs() > 1e-9 {
            return Err(f.error("12I/T**3: only the solid section (1.0) is modelled"));
        }
        if let Some(m) = f.int_opt(6, "MID3")? {
            if m != mid {
                return Err(f.error(format!("MID3 = {m} differs from MID1 = {mid}")));
            }
        }
        if (f.real_or(7, "TS/T", 5.0 / 6.0)? - 5.0 / 6.0).abs() > 1e-3 {
            return Err(f.error("TS/T: only the shear factor 5/6 (0.833333) is modelled"));
        }
        if f.real_or(8, "NSM", 0.0)? != 0.0 {
            return Err(f.error("NSM: non-structural mass is not modelled"));
        }
        let at = f.card.at;
        Self::unique(
            f,
            &mut self.pshells,
            id,
            PshellCard { mid, thickness, at },
            |p| p.at,
        )
    }

    fn mat1(&mut self, f: &Fields) -> Result<(), Error> {
        let id = f.id(1, "MID")?;
        let (e, g, nu) = (
            f.real_opt(2, "E")?,
            f.real_opt(3, "G")?,
            f.real_opt(4, "NU")?,
        );
        let (e, nu) = match (e, g, nu) {
            (Some(e), None, Some(nu)) => (e, nu),
            (Some(e), Some(g), None) => (e, e / (2.0 * g) - 1.0),
            (None, Some(g), Some(nu)) => (2.0 * g * (1.0 + nu), nu),
            (Some(e), Some(g), Some(nu)) => {
                if (e / (2.0 * (1.0 + nu)) - g).abs() > 1e-3 * g.abs() {
                    return Err(f.error(format!(
                        "E = {e}, G = {g} and NU = {nu} disagree (G ≠ E/(2(1+NU))): an isotropic \
                         material needs two of them"
                    )));
                }
                (e, nu)
            }
            _ => return Err(f.error("give two of E, G, NU")),
        };
        let density = f.real_or(5, "RHO", 0.0)?;
        if !(e > 0.0 && nu > -1.0 && nu < 0.5 && density > 0.0) {
            return Err(f.error(format!(
                "E = {e} N/mm², NU = {nu}, RHO = {density} t/mm³: need E > 0, -1 < NU < 0.5 and \
                 RHO > 0 (a transient model needs mass)"
            )));
        }
        for (k, name) in [(6, "A"), (7, "TREF"), (8, "GE")] {
            if f.real_or(k, name, 0.0)? != 0.0 {
                let why = if name == "GE" {
                    "structural damping is not modelled (the model is undamped)"
                } else {
                    "thermal expansion is not modelled"
                };
                return Err(f.error(format!("{name}: {why}")));
            }
        }
        let at = f.card.at;
        Self::unique(
            f,
            &mut self.materials,
            id,
            Mat1Card {
                youngs_modulus: e,
                poisson_ratio: nu,
                density,
                at,
            },
            |m| m.at,
        )
    }

    fn cweld(&mut self, f: &Fields) -> Result<(), Error> {
        let (id, at) = (f.id(1, "EWID")?, f.card.at);
        let pid = f.id(2, "PWID")?;
        // ALIGN may stand in field 4 (GS blank) or, as some writers put it, in field 3.
        let (kind, shift) = if f.word(3) == "ALIGN" {
            ("ALIGN".to_string(), 0)
        } else {
            (f.word(4), 1)
        };
        if let Some(m) = f.int_opt(6 + shift, "MCID")? {
            if m != -1 {
                return Err(f.error("MCID: weld coordinate systems are not read"));
            }
        }
        if kind == "ALIGN" {
            let a = f.id(4 + shift, "GA")?;
            let b = f.id(5 + shift, "GB")?;
            self.welds.push(WeldCard {
                id,
                pid,
                attach: WeldAttach::Align { a, b },
                location: None,
                at,
            });
            return Ok(());
        }
        let (a, b) = (f.id(9, "PIDA/SHIDA")?, f.id(10, "PIDB/SHIDB")?);
        let attach = match kind.as_str() {
            "PARTPAT" => WeldAttach::Parts { a, b },
            "ELPAT" | "ELEMID" => WeldAttach::Elements { a, b },
            "GRIDID" => {
                return Err(f.error(
                    "TYPE GRIDID is not read: give the weld's location and its sheets \
                     (PARTPAT, ELPAT or ELEMID)",
                ))
            }
            other => {
                return Err(f.error(format!(
                    "TYPE `{}`: expected PARTPAT, ELPAT, ELEMID or ALIGN",
                    crate::files::printable(other)
                )))
            }
        };
        if !f.raw(5).is_empty() || !f.raw(6).is_empty() {
            return Err(f.error(
                "GA/GB: the weld's end points are placed by jointrom on the sheets' \
                 mid-surfaces; leave GA and GB blank",
            ));
        }
        let location = match f.int_opt(3, "GS")? {
            Some(gs) if gs > 0 => Location::Grid(gs),
            Some(gs) => return Err(f.error(format!("GS: a grid id must be > 0, found {gs}"))),
            None => {
                if f.raw(17).is_empty() && kind == "ELEMID" {
                    return Err(f.error("ELEMID needs GS (the weld's location grid)"));
                }
                Location::Point([f.real(17, "XS")?, f.real(18, "YS")?, f.real(19, "ZS")?])
            }
        };
        self.welds.push(WeldCard {
            id,
            pid,
            attach,
            location: Some(location),
            at,
        });
        Ok(())
    }

    fn pweld(&mut self, f: &Fields) -> Result<(), Error> {
        let id = f.id(1, "PID")?;
        let mid = f.id(2, "MID")?;
        let diameter = f.real(3, "D")?;
        if diameter <= 0.0 {
            return Err(f.error(format!(
                "D: the nugget diameter must be > 0, found {diameter} mm"
            )));
        }
        let ty = f.word(8);
        if !(ty.is_empty() || ty == "SPOT") {
            return Err(f.error(format!(
                "TYPE `{}`: only spot welds (blank or SPOT) are read",
                crate::files::printable(&ty)
            )));
        }
        let at = f.card.at;
        Self::unique(
            f,
            &mut self.pwelds,
            id,
            PweldCard { mid, diameter, at },
            |p| p.at,
        )
    }

    fn beam(&mut self, f: &Fields) -> Result<(), Error> {
        let (id, at) = (f.id(1, "EID")?, f.card.at);
        let pid = f.id(2, "PID")?;
        let grids = [f.id(3, "GA")?, f.id(4, "GB")?];
        // Fields 9–16 (pin flags, offsets) must be blank.
        for k in 9..=16 {
            let v = f.raw(k);
            if !(v.is_empty() || v == "0" || parse_real(v) == Some(0.0)) {
                return Err(f.error(
                    "pin flags and offsets (PA, PB, W1A–W3B) are not modelled: leave them blank",
                ));
            }
        }
        self.beams.push(BeamCard { id, pid, grids, at });
        Ok(())
    }

    fn rod(&mut self, f: &Fields) -> Result<(), Error> {
        let id = f.id(1, "PID")?;
        let mid = f.id(2, "MID")?;
        let ty = f.word(4);
        if ty != "ROD" {
            return Err(f.error(format!(
                "TYPE `{}`: only the solid circular section ROD is modelled",
                crate::files::printable(&ty)
            )));
        }
        let radius = f.real(9, "DIM1")?;
        if radius <= 0.0 {
            return Err(f.error(format!("DIM1: the radius must be > 0, found {radius} mm")));
        }
        let at = f.card.at;
        Self::unique(
            f,
            &mut self.rods,
            id,
            RodCard {
                mid,
                diameter: 2.0 * radius,
                at,
            },
            |r| r.at,
        )
    }

    fn conm2(&mut self, f: &Fields) -> Result<(), Error> {
        let (id, at) = (f.id(1, "EID")?, f.card.at);
        let grid = f.id(2, "G")?;
        if f.int_opt(3, "CID")?.unwrap_or(0) != 0 {
            return Err(f.error("CID: coordinate systems are not read (use CID 0)"));
        }
        let mass = f.real(4, "M")?;
        if mass < 0.0 {
            return Err(f.error(format!("M: a mass must be ≥ 0, found {mass} t")));
        }
        for (k, name) in [(5, "X1"), (6, "X2"), (7, "X3")] {
            if f.real_or(k, name, 0.0)? != 0.0 {
                return Err(f.error(format!("{name}: mass offsets are not modelled")));
            }
        }
        let mut inertia = [0.0; 6];
        for (i, name) in ["I11", "I21", "I22", "I31", "I32", "I33"]
            .iter()
            .enumerate()
        {
            inertia[i] = f.real_or(9 + i, name, 0.0)?;
        }
        if inertia[0] < 0.0 || inertia[2] < 0.0 || inertia[5] < 0.0 {
            return Err(f.error("I11, I22, I33 must be ≥ 0"));
        }
        self.masses.push(MassCard {
            id,
            grid,
            mass,
            inertia,
            at,
        });
        Ok(())
    }

    fn rbe2_card(&mut self, f: &Fields) -> Result<(), Error> {
        let (id, at) = (f.id(1, "EID")?, f.card.at);
        let master = f.id(2, "GN")?;
        if !is_all_six(f.raw(3)) {
            return Err(f.error(format!(
                "CM `{}`: jointrom's rigid tie couples all six components (123456)",
                crate::files::printable(f.raw(3))
            )));
        }
        let mut slaves = Vec::new();
        let n = f.card.fields.len();
        for k in 4..=n {
            let s = f.raw(k);
            if s.is_empty() {
                continue;
            }
            if s.contains('.') {
                // ALPHA (thermal expansion) may end the list.
                if parse_real(s).is_some_and(|a| a == 0.0) {
                    continue;
                }
                return Err(f.error("ALPHA: thermal expansion is not modelled"));
            }
            slaves.push(f.id(k, "GMi")?);
        }
        if slaves.is_empty() {
            return Err(f.error("no dependent grids"));
        }
        self.rbe2.push(Rbe2Card {
            id,
            master,
            slaves,
            at,
        });
        Ok(())
    }

    fn spc(&mut self, f: &Fields) -> Result<(), Error> {
        let sid = f.id(1, "SID")?;
        let mut grids = Vec::new();
        if f.card.name == "SPC" {
            // SPC SID G1 C1 D1 G2 C2 D2
            for (g, c, d) in [(2, 3, 4), (5, 6, 7)] {
                if f.raw(g).is_empty() {
                    continue;
                }
                let id = f.id(g, "G")?;
                grids.push((id, id));
                if !is_all_six(f.raw(c)) {
                    return Err(
                        f.error("C: jointrom constrains all six components of a grid (123456)")
                    );
                }
                if f.real_or(d, "D", 0.0)? != 0.0 {
                    return Err(f.error("D: enforced displacements are not modelled"));
                }
            }
        } else {
            if !is_all_six(f.raw(2)) {
                return Err(f.error(format!(
                    "C `{}`: jointrom constrains all six components of a grid (123456)",
                    crate::files::printable(f.raw(2))
                )));
            }
            let n = f.card.fields.len();
            let mut k = 3;
            while k <= n {
                if f.word(k) == "THRU" {
                    let (from, to) = (f.id(k - 1, "G")?, f.id(k + 1, "G")?);
                    if to < from {
                        return Err(f.error(format!("THRU: bad range {from} THRU {to}")));
                    }
                    grids.pop();
                    grids.push((from, to));
                    k += 2;
                    continue;
                }
                if !f.raw(k).is_empty() {
                    let id = f.id(k, "G")?;
                    grids.push((id, id));
                }
                k += 1;
            }
        }
        self.spcs.push(SpcCard {
            sid,
            grids,
            at: f.card.at,
        });
        Ok(())
    }

    fn spcadd(&mut self, f: &Fields) -> Result<(), Error> {
        let sid = f.id(1, "SID")?;
        let mut sets = Vec::new();
        for k in 2..=f.card.fields.len() {
            if !f.raw(k).is_empty() {
                sets.push(f.id(k, "Si")?);
            }
        }
        let at = f.card.at;
        Self::unique(f, &mut self.spcadds, sid, (sets, at), |s| s.1)
    }

    fn force(&mut self, f: &Fields) -> Result<(), Error> {
        let sid = f.id(1, "SID")?;
        let grid = f.id(2, "G")?;
        if f.int_opt(3, "CID")?.unwrap_or(0) != 0 {
            return Err(f.error("CID: coordinate systems are not read (use CID 0)"));
        }
        let scale = f.real(4, "F")?;
        let n = [
            f.real_or(5, "N1", 0.0)?,
            f.real_or(6, "N2", 0.0)?,
            f.real_or(7, "N3", 0.0)?,
        ];
        let offset = if f.card.name == "MOMENT" { 3 } else { 0 };
        let mut components = [0.0; 6];
        for a in 0..3 {
            components[offset + a] = scale * n[a];
        }
        self.loads.push(LoadEntry {
            sid,
            grid,
            components,
            at: f.card.at,
        });
        Ok(())
    }

    fn darea(&mut self, f: &Fields) -> Result<(), Error> {
        let sid = f.id(1, "SID")?;
        for (g, c, a) in [(2, 3, 4), (5, 6, 7)] {
            if f.raw(g).is_empty() {
                continue;
            }
            let grid = f.id(g, "P")?;
            let comp = f.raw(c);
            let value = f.real(a, "A")?;
            let mut components = [0.0; 6];
            let digits: Vec<u8> = comp.bytes().collect();
            if digits.is_empty() || !digits.iter().all(|d| (b'1'..=b'6').contains(d)) {
                return Err(f.bad("C", "component digits 1–6", comp));
            }
            for d in digits {
                components[(d - b'1') as usize] = value;
            }
            self.loads.push(LoadEntry {
                sid,
                grid,
                components,
                at: f.card.at,
            });
        }
        Ok(())
    }

    fn tload1(&mut self, f: &Fields) -> Result<(), Error> {
        let sid = f.id(1, "SID")?;
        let excite = f.id(2, "EXCITEID")?;
        let delay =
            match f.raw(3) {
                "" => 0.0,
                s if !s.contains(['.', 'E', 'e', 'D', 'd']) => return Err(f.error(
                    "DELAY: an integer refers to a DELAY card, which is not read; give the delay \
                     as a real number of seconds",
                )),
                _ => f.real(3, "DELAY")?,
            };
        let ty = f.word(4);
        if !(ty.is_empty() || ty == "0" || ty == "LOAD" || ty == "L" || ty == "LO") {
            return Err(f.error(format!(
                "TYPE `{}`: only applied loads (0 or LOAD) are modelled, not enforced motion",
                crate::files::printable(&ty)
            )));
        }
        let table = f.id(5, "TID")?;
        if f.real_or(6, "US0", 0.0)? != 0.0 || f.real_or(7, "VS0", 0.0)? != 0.0 {
            return Err(f.error("US0/VS0: enforced initial motion is not modelled"));
        }
        let at = f.card.at;
        Self::unique(
            f,
            &mut self.tloads,
            sid,
            Tload1Card {
                excite,
                delay,
                table,
                at,
            },
            |t| t.at,
        )
    }

    fn dload(&mut self, f: &Fields) -> Result<(), Error> {
        let sid = f.id(1, "SID")?;
        let scale = f.real(2, "S")?;
        let mut terms = Vec::new();
        let n = f.card.fields.len();
        let mut k = 3;
        while k < n {
            if !f.raw(k).is_empty() || !f.raw(k + 1).is_empty() {
                terms.push((f.real(k, "Si")?, f.id(k + 1, "Li")?));
            }
            k += 2;
        }
        if terms.is_empty() {
            return Err(f.error("no (Si, Li) terms"));
        }
        let at = f.card.at;
        Self::unique(
            f,
            &mut self.dloads,
            sid,
            DloadCard { scale, terms, at },
            |d| d.at,
        )
    }

    fn tabled1(&mut self, f: &Fields) -> Result<(), Error> {
        let id = f.id(1, "TID")?;
        for (k, name) in [(2, "XAXIS"), (3, "YAXIS")] {
            let w = f.word(k);
            if !(w.is_empty() || w == "LINEAR") {
                return Err(f.error(format!(
                    "{name} `{}`: only LINEAR axes are read",
                    crate::files::printable(&w)
                )));
            }
        }
        let flat = match f.word(4).as_str() {
            "" | "0" => false,
            "1" | "FLAT" => true,
            other => return Err(f.bad("FLAT/EXTRAP", "0, 1 or FLAT", other)),
        };
        let mut points = Vec::new();
        let n = f.card.fields.len();
        let mut k = 9;
        let mut ended = false;
        while k <= n {
            let (x, y) = (f.word(k), f.word(k + 1));
            if x == "ENDT" || (x.is_empty() && y == "ENDT") {
                ended = true;
                f.blank_from(k + 2, "after ENDT")?;
                break;
            }
            if x == "SKIP" || y == "SKIP" {
                k += 2;
                continue;
            }
            if x.is_empty() && y.is_empty() {
                k += 2;
                continue;
            }
            points.push([f.real(k, "x")?, f.real(k + 1, "y")?]);
            k += 2;
        }
        if !ended {
            return Err(f.error("the table does not end with ENDT"));
        }
        if points.len() < 2 {
            return Err(f.error("a table needs at least two points"));
        }
        let at = f.card.at;
        Self::unique(
            f,
            &mut self.tables,
            id,
            TableCard { points, flat, at },
            |t| t.at,
        )
    }

    fn tstep(&mut self, f: &Fields) -> Result<(), Error> {
        let sid = f.id(1, "SID")?;
        let mut end = 0.0;
        if f.card.name == "TSTEPNL" {
            let n = f.int(2, "NDT")?;
            let dt = f.real(3, "DT")?;
            if n <= 0 || dt <= 0.0 {
                return Err(f.error(format!("NDT = {n} and DT = {dt} s must be > 0")));
            }
            end = n as f64 * dt;
        } else {
            // TSTEP SID N1 DT1 NO1 / (blank) N2 DT2 NO2 / ...: one (N, DT, NO) per line.
            let lines = f.card.fields.len().div_ceil(8).max(1);
            for line in 0..lines {
                let base = 8 * line;
                if f.raw(base + 2).is_empty() && f.raw(base + 3).is_empty() {
                    continue;
                }
                let n = f.int(base + 2, "N")?;
                let dt = f.real(base + 3, "DT")?;
                if n <= 0 || dt <= 0.0 {
                    return Err(f.error(format!("N = {n} and DT = {dt} s must be > 0")));
                }
                end += n as f64 * dt;
            }
        }
        if !(end.is_finite() && end > 0.0) {
            return Err(f.error("no time steps"));
        }
        let at = f.card.at;
        Self::unique(f, &mut self.tsteps, sid, (end, at), |t| t.1)
    }

    fn cgap(&mut self, f: &Fields) -> Result<(), Error> {
        let (id, at) = (f.id(1, "EID")?, f.card.at);
        let pid = f.id(2, "PID")?;
        let grids = [f.id(3, "GA")?, f.id(4, "GB")?];
        if f.int_opt(8, "CID")?.is_some_and(|c| c != 0) {
            return Err(f.error(
                "CID: the gap direction is read from GA to GB; gap coordinate systems are not read",
            ));
        }
        self.gaps.push(GapCard { id, pid, grids, at });
        Ok(())
    }

    fn pgap(&mut self, f: &Fields) -> Result<(), Error> {
        let id = f.id(1, "PID")?;
        let u0 = f.real_or(2, "U0", 0.0)?;
        if u0 != 0.0 {
            return Err(f.error(format!(
                "U0 = {u0} mm: jointrom's pairs touch at rest (zero initial opening); an initial \
                 gap is not supported"
            )));
        }
        if f.real_or(3, "F0", 0.0)? != 0.0 {
            return Err(f.error("F0: a preload is not modelled"));
        }
        let ka = f.real(4, "KA")?;
        if ka <= 0.0 {
            return Err(f.error(format!(
                "KA: the closed stiffness must be > 0, found {ka} N/mm"
            )));
        }
        let kb = f.real_or(5, "KB", 1e-14 * ka)?;
        if !(0.0..=1e-6 * ka).contains(&kb) {
            return Err(f.error(format!(
                "KB = {kb} N/mm: an open gap carries no force in jointrom; KB must be ≤ 1e-6 KA"
            )));
        }
        let mu1 = f.real_or(7, "MU1", 0.0)?;
        if mu1 < 0.0 {
            return Err(f.error(format!(
                "MU1: the friction coefficient must be ≥ 0, found {mu1}"
            )));
        }
        let kt = f.real_or(6, "KT", mu1 * ka)?;
        if kt <= 0.0 {
            return Err(f.error(format!(
                "KT = {kt} N/mm: jointrom's stick stiffness must be > 0 (give KT, or MU1 > 0)"
            )));
        }
        if let Some(mu2) = f.real_opt(8, "MU2")? {
            if (mu2 - mu1).abs() > 1e-12 * mu1.abs().max(1.0) {
                return Err(f.error(format!(
                    "MU2 = {mu2} differs from MU1 = {mu1}: jointrom's Coulomb law has one coefficient"
                )));
            }
        }
        let at = f.card.at;
        Self::unique(
            f,
            &mut self.pgaps,
            id,
            PgapCard {
                normal_stiffness: ka,
                stick_stiffness: kt,
                friction_coefficient: mu1,
                at,
            },
            |p| p.at,
        )
    }
}

/// Whether a component field lists all six components (`123456` in any order).
fn is_all_six(s: &str) -> bool {
    let set: BTreeSet<u8> = s.bytes().collect();
    s.len() == 6 && set.len() == 6 && set.iter().all(|d| (b'1'..=b'6').contains(d))
}

#[cfg(test)]
mod tests {
    use super::parse_real;

    #[test]
    fn nastran_reals() {
        assert_eq!(parse_real("1.5"), Some(1.5));
        assert_eq!(parse_real("-.5"), Some(-0.5));
        assert_eq!(parse_real("1.E4"), Some(1e4));
        assert_eq!(parse_real("7.85-9"), Some(7.85e-9));
        assert_eq!(parse_real("2.1+5"), Some(2.1e5));
        assert_eq!(parse_real("1.5D-3"), Some(1.5e-3));
        assert_eq!(parse_real("-1.-3"), Some(-1e-3));
        assert_eq!(parse_real("3"), Some(3.0));
        assert_eq!(parse_real("nan"), None);
        assert_eq!(parse_real("inf"), None);
        assert_eq!(parse_real("1.e999"), None);
        assert_eq!(parse_real("1..2"), None);
        assert_eq!(parse_real("+"), None);
    }
}
