//! NASTRAN bulk data in: the subset a spot-welded sheet model with contact needs, read from a
//! deck as a pre-processor writes it (`jointrom info|modes|static|basis|transient|run|export
//! DECK.bdf`).
//!
//! Reading is two steps: [`cards`] turns the text (small, large and free field, continuations,
//! `INCLUDE`, case control) into cards with their file and line; [`deck`] types each supported
//! card and checks its fields. The mesh is built from the typed [`Deck`] by
//! `crate::mesh::Mesh::from_deck`, which resolves the references between cards.
//!
//! # Supported cards and how they map
//!
//! | card | read as | refused (error naming the line) |
//! |---|---|---|
//! | `GRID` | a node, mm; PS = 123456 clamps it | CP/CD ≠ 0, partial PS, SEID |
//! | `CQUAD4` | a `Shell4` | ZOFFS ≠ 0, corner thicknesses |
//! | `PSHELL` | its thickness and MAT1 | MID2 ≠ MID1 or blank, 12I/T³ ≠ 1, TS/T ≠ 5/6, NSM |
//! | `MAT1` | E, ν (two of E, G, NU), ρ | thermal expansion, GE ≠ 0; several different MAT1 in use |
//! | `CWELD` + `PWELD` | an area weld of diameter D (`PARTPAT`, `ELPAT`, `ELEMID`: the nugget sampled on the two sheets); `ALIGN`: a point weld (`Beam2`) between GA and GB | GRIDID, MCID, GA/GB with patches, PWELD TYPE other than SPOT |
//! | `CBAR`/`CBEAM` + `PBARL`/`PBEAML` `ROD` | a circular `Beam2` (diameter 2·DIM1) | other sections, PBAR/PBEAM, pin flags, offsets |
//! | `RBE2` (one) | the rigid tie; GN is the master node that carries the load | CM ≠ 123456, a second RBE2 |
//! | `SPC1`/`SPC`/`SPCADD` | clamps (all six components) | partial components, enforced values |
//! | `CONM2` | a point mass and inertia at a grid | CID ≠ 0, offsets |
//! | `FORCE`/`MOMENT`/`DAREA` | the master load (at GN only) | CID ≠ 0, a load on another grid |
//! | `TLOAD1` + `TABLED1` (`DLOAD`) | the load's time function (linear, NASTRAN's extrapolation) | DELAY cards, TYPE ≠ LOAD, US0/VS0, LOG axes, several tables |
//! | `TSTEP`/`TSTEPNL` | the end time Σ Nᵢ·DTᵢ | |
//! | `CGAP` + `PGAP` | a joint pair: normal GA → GB, KA → k_n, KT → k_t (default MU1·KA), MU1 → μ | U0 ≠ 0, F0 ≠ 0, KB > 1e-6·KA, MU2 ≠ MU1, CID, different PGAP laws |
//! | `PARAM` | `WTMASS` (the factor on every mass) | `LGDISP` ≥ 0, `G`, `W3`, `W4` |
//!
//! Cards that carry no mechanics jointrom models ([`deck::IGNORED`]: `PARAM`, `EIGRL`, unused
//! coordinate systems, ...) and unknown cards are listed in a warning; cards that change the
//! mechanics and are not modelled ([`deck::REFUSED`]: `CTRIA3`, `MATS1`, `PCOMP`, `MPC`,
//! `PLOAD4`, ...) are an error naming the line.
//!
//! # Reading, bounded
//!
//! No input panics the reader; its memory is proportional to the input: the text is read under
//! the input budget (all included files together), every card is parsed field by field with
//! errors naming the file, line, card and field, and the model's size is checked against the
//! DOF budget before anything is allocated for it. `fuzz/` drives [`deck::read`] with
//! libFuzzer (`scripts/fuzz.sh deck`).

pub mod cards;
pub mod deck;

pub use deck::Deck;

/// Whether a model argument names a NASTRAN deck: by extension (`.bdf`, `.dat`, `.nas`, `.blk`,
/// `.bulk`, any case) or, for an existing file with another extension that is not JSON, by
/// content (its first card-like line is `SOL`, `CEND`, `BEGIN BULK`, `INCLUDE` or a bulk card
/// name followed by a field).
pub fn is_deck(arg: &str) -> bool {
    let path = std::path::Path::new(arg);
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase());
    match ext.as_deref() {
        Some("bdf" | "dat" | "nas" | "blk" | "bulk") => true,
        Some("json") => false,
        _ => path.is_file() && looks_like_deck(path),
    }
}

fn looks_like_deck(path: &std::path::Path) -> bool {
    use std::io::Read;
    let Ok(file) = std::fs::File::open(path) else {
        return false;
    };
    let mut head = Vec::new();
    if file.take(4096).read_to_end(&mut head).is_err() {
        return false;
    }
    let text = String::from_utf8_lossy(&head);
    let Some(first) = text
        .lines()
        .map(|l| l.split('$').next().unwrap_or("").trim())
        .find(|l| !l.is_empty())
    else {
        return false;
    };
    let upper = first.to_ascii_uppercase();
    let word: String = upper
        .chars()
        .take_while(|c| c.is_ascii_alphanumeric() || *c == '*')
        .collect();
    matches!(
        word.trim_end_matches('*'),
        "SOL"
            | "CEND"
            | "BEGIN"
            | "INCLUDE"
            | "ID"
            | "TIME"
            | "GRID"
            | "CQUAD4"
            | "PSHELL"
            | "MAT1"
            | "CGAP"
            | "CWELD"
            | "RBE2"
            | "SPC1"
    )
}
