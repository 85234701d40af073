//! MatrixMarket files through the strict reader.
#![no_main]
use libfuzzer_sys::fuzz_target;
use std::io::Write;

fuzz_target!(|data: &[u8]| {
    let mut f = tempfile::NamedTempFile::new().unwrap();
    f.write_all(data).unwrap();
    for dup in [
        jointrom::model::mtx::Duplicates::Reject,
        jointrom::model::mtx::Duplicates::Sum,
    ] {
        let _ = jointrom::model::mtx::read(f.path(), dup);
    }
});
