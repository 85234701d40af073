//! Case files: parse and validate; an accepted case is built into a model (mesh, elements,
//! assembly). Run with JOINTROM_MAX_DOF small (scripts/fuzz.sh sets 30000).
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        if let Ok(case) = jointrom::case::Case::from_json_str(text, "fuzz.json") {
            let _ = jointrom::Model::from_case(case);
        }
    }
});
