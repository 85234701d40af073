//! Loading cases from files and by name: `Case::from_file`, `Case::load`, and the errors that
//! name the file.

use std::path::PathBuf;

use jointrom::case::Case;
use jointrom::Error;

use crate::common;

/// A scratch file under Cargo's per-target temporary directory.
fn scratch(name: &str, text: &str) -> PathBuf {
    let path = common::tmp_path(&format!("case_files_{name}"));
    std::fs::write(&path, text).expect("write scratch case");
    path
}

#[test]
fn a_missing_file_is_an_io_error_naming_it() {
    let path = common::tmp_path("no_such_dir/no_such_case.json");
    match Case::from_file(&path) {
        Err(err @ Error::Io { .. }) => {
            let Error::Io { file, source } = &err else {
                unreachable!()
            };
            assert_eq!(file, &path);
            assert_eq!(source.kind(), std::io::ErrorKind::NotFound);
            assert!(err.to_string().contains("no_such_case.json"), "{err}");
        }
        other => panic!("expected Error::Io, got {other:?}"),
    }
}

#[test]
fn a_file_loads_and_is_labelled_by_its_path() {
    let path = scratch("friction_bar.json", &common::case_text("friction_bar"));
    let label = path.display().to_string();
    let from_file = Case::from_file(&path).expect("valid file");
    assert_eq!(from_file.source, label);
    let loaded = Case::load(&label).expect("load by path");
    assert_eq!(loaded.source, label);
    let builtin = common::builtin_case("friction_bar");
    assert_eq!(
        Case {
            source: builtin.source.clone(),
            ..loaded
        },
        builtin
    );
}

#[test]
fn errors_in_a_file_name_the_file() {
    let text =
        common::case_text("friction_bar").replace("\"thickness\": 0.5", "\"thickness\": -0.5");
    let path = scratch("bad_thickness.json", &text);
    match Case::load(&path.display().to_string()) {
        Err(Error::Case { file, path: at, .. }) => {
            assert_eq!(file, path.display().to_string());
            assert_eq!(at, "sheets[0].thickness");
        }
        other => panic!("expected Error::Case, got {other:?}"),
    }
}

#[test]
fn load_falls_back_to_builtin_names() {
    for name in Case::BUILTIN {
        let case = Case::load(name).expect("builtin by name");
        assert_eq!(case.source, format!("builtin:{name}"));
    }
}

#[test]
fn load_of_an_unknown_name_lists_the_builtins() {
    match Case::load("friction_baar") {
        Err(err @ Error::Io { .. }) => {
            let message = err.to_string();
            assert!(message.contains("friction_baar"), "{message}");
            for name in Case::BUILTIN {
                assert!(message.contains(name), "{message}");
            }
        }
        other => panic!("expected Error::Io, got {other:?}"),
    }
}

#[test]
fn schema_errors_keep_serde_as_the_source() {
    use std::error::Error as _;
    let text = include_str!("../../cases/friction_bar.json").replacen('{', "{\"colour\": 1,", 1);
    let err = Case::from_json_str(&text, "colour.json").unwrap_err();
    assert!(matches!(err, Error::Case { .. }), "{err}");
    let source = err.source().expect("serde's error as the source");
    assert!(
        source.downcast_ref::<Box<serde_json::Error>>().is_some(),
        "{source}"
    );
    assert!(source.to_string().contains("colour"), "{source}");
}
