//! From cards to a typed deck: each supported card's fields read and checked (type, sign,
//! range, unsupported options), ids unique per kind, the others sorted into ignored (a warning)
//! and refused (an error naming the line). References between cards are resolved later, when
//! the mesh is built (`crate::mesh`'s deck builder).
//!
//! The typed cards are in `types` and the field reader in `fields`; each card family is
//! read in its own file: nodes, shells, materials and masses (`elements`), welds, beams and
//! gaps (`joints`), the rigid tie and clamps (`constraints`), loads and time steps
//! (`loads`). This file holds the card lists, the dispatch and the checks across cards.

use std::collections::BTreeMap;

use super::cards::{Cards, Position};
use crate::error::Error;

mod constraints;
mod elements;
mod fields;
mod joints;
mod loads;
mod types;

pub use fields::parse_real;
pub(crate) use fields::Fields;
pub use types::{
    BeamCard, DloadCard, GapCard, GridCard, LoadEntry, Location, MassCard, Mat1Card, PgapCard,
    PshellCard, PweldCard, QuadCard, Rbe2Card, RodCard, SpcCard, TableCard, Tload1Card, WeldAttach,
    WeldCard,
};

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
pub(crate) fn interpret(cards: Cards) -> Result<Deck, Error> {
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
}
