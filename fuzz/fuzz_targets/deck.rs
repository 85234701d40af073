//! NASTRAN decks through the card reader, the typed deck and the mesh builder and assembly
//! (`Model::from_deck`; the model size is capped by JOINTROM_MAX_DOF in scripts/fuzz.sh).
#![no_main]
use libfuzzer_sys::fuzz_target;
use std::io::Write;

fuzz_target!(|data: &[u8]| {
    let mut f = tempfile::Builder::new().suffix(".bdf").tempfile().unwrap();
    f.write_all(data).unwrap();
    let _ = jointrom::Model::from_deck(f.path());
});
