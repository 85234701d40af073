//! The rigid tie and the clamps: RBE2, SPC1/SPC, SPCADD.

use super::fields::{is_all_six, parse_real};
use super::{Deck, Fields, Rbe2Card, SpcCard};
use crate::error::Error;

impl Deck {
    pub(super) fn rbe2_card(&mut self, f: &Fields) -> Result<(), Error> {
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

    pub(super) fn spc(&mut self, f: &Fields) -> Result<(), Error> {
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

    pub(super) fn spcadd(&mut self, f: &Fields) -> Result<(), Error> {
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
}
