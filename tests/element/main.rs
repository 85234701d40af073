//! Elements (`jointrom::element`): Shell4, Beam2 and the area Weld against invariants and closed-form theory.

#[path = "../common/mod.rs"]
mod common;

mod beam2;
mod shell4;
mod weld;
