//! Reduction bases (`jointrom::reduction`): Craig–Bampton, TVD, POD, final basis, the competitors
//! (JIM, alldof, snapshot POD), the `basis`/`static --basis`/`study` CLI and the reduced-model file.

#[path = "../common/mod.rs"]
mod common;

mod cli_basis;
mod competitors;
mod export;
mod reduction;
mod roundoff;
mod threads;
mod tolerance;
