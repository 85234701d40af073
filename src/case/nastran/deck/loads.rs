//! The load and its time function, the end time: FORCE/MOMENT, DAREA, TLOAD1, DLOAD, TABLED1,
//! TSTEP/TSTEPNL.

use super::{Deck, DloadCard, Fields, LoadEntry, TableCard, Tload1Card};
use crate::error::Error;

impl Deck {
    pub(super) fn force(&mut self, f: &Fields) -> Result<(), Error> {
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

    pub(super) fn darea(&mut self, f: &Fields) -> Result<(), Error> {
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

    pub(super) fn tload1(&mut self, f: &Fields) -> Result<(), Error> {
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

    pub(super) fn dload(&mut self, f: &Fields) -> Result<(), Error> {
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

    pub(super) fn tabled1(&mut self, f: &Fields) -> Result<(), Error> {
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

    pub(super) fn tstep(&mut self, f: &Fields) -> Result<(), Error> {
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
}
