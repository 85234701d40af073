//! Reduced-model files: read, checked, turned into the reduced system.
#![no_main]
use libfuzzer_sys::fuzz_target;
use std::io::Write;

fuzz_target!(|data: &[u8]| {
    let mut f = tempfile::NamedTempFile::new().unwrap();
    f.write_all(data).unwrap();
    if let Ok(rom) = jointrom::rom::file::RomFile::read(f.path()) {
        let _ = rom.system();
    }
});
