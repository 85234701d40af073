//! Matrix maps: the fuzzed map next to a small model's valid K.mtx and M.mtx (copied from
//! $JOINTROM_FUZZ_MATRICES, set by scripts/fuzz.sh).
#![no_main]
use libfuzzer_sys::fuzz_target;
use std::sync::OnceLock;

fn dir() -> &'static tempfile::TempDir {
    static D: OnceLock<tempfile::TempDir> = OnceLock::new();
    D.get_or_init(|| {
        let d = tempfile::tempdir().unwrap();
        let src = std::env::var("JOINTROM_FUZZ_MATRICES").expect("JOINTROM_FUZZ_MATRICES");
        for f in ["K.mtx", "M.mtx"] {
            std::fs::copy(std::path::Path::new(&src).join(f), d.path().join(f)).unwrap();
        }
        d
    })
}

fuzz_target!(|data: &[u8]| {
    let map = dir().path().join("model.json");
    std::fs::write(&map, data).unwrap();
    let _ = jointrom::model::matrices::load(&map);
});
