//! Elements (`jointrom::element`): Shell4 and Beam2 against invariants and closed-form theory.

#[path = "../common/mod.rs"]
mod common;

mod beam2;
mod shell4;
