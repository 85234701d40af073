//! Nodes, shells and their properties, materials, point masses: GRID, CQUAD4, PSHELL, MAT1,
//! CONM2.

use super::fields::is_all_six;
use super::{Deck, Fields, GridCard, MassCard, Mat1Card, PshellCard, QuadCard};
use crate::error::Error;

impl Deck {
    pub(super) fn grid(&mut self, f: &Fields) -> Result<(), Error> {
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

    pub(super) fn quad(&mut self, f: &Fields) -> Result<(), Error> {
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

    pub(super) fn pshell(&mut self, f: &Fields) -> Result<(), Error> {
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

    pub(super) fn mat1(&mut self, f: &Fields) -> Result<(), Error> {
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

    pub(super) fn conm2(&mut self, f: &Fields) -> Result<(), Error> {
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
}
