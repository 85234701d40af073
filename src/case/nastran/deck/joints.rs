//! Welds, weld beams and contact gaps: CWELD, PWELD, CBAR/CBEAM, PBARL/PBEAML, CGAP, PGAP.

use super::fields::parse_real;
use super::{
    BeamCard, Deck, Fields, GapCard, Location, PgapCard, PweldCard, RodCard, WeldAttach, WeldCard,
};
use crate::error::Error;

impl Deck {
    pub(super) fn cweld(&mut self, f: &Fields) -> Result<(), Error> {
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

    pub(super) fn pweld(&mut self, f: &Fields) -> Result<(), Error> {
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

    pub(super) fn beam(&mut self, f: &Fields) -> Result<(), Error> {
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

    pub(super) fn rod(&mut self, f: &Fields) -> Result<(), Error> {
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

    pub(super) fn cgap(&mut self, f: &Fields) -> Result<(), Error> {
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

    pub(super) fn pgap(&mut self, f: &Fields) -> Result<(), Error> {
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
