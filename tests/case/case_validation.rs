//! Case validation: each rule is broken once, by editing the friction bar, and the error must be
//! an `Error::Case` naming the file, the JSON path and the problem in plain words.

use jointrom::case::Case;
use jointrom::mesh::Mesh;
use jointrom::Error;
use serde_json::{json, Value};

use crate::common;

const FILE: &str = "edited_friction_bar.json";

/// Parses and validates a case as every command does: the fields when the file is read, the
/// geometry when its mesh is generated.
fn validated(text: &str, file: &str) -> Result<Case, Error> {
    let case = Case::from_json_str(text, file)?;
    Mesh::from_case(&case)?;
    Ok(case)
}

fn friction_bar() -> Value {
    serde_json::from_str(&common::case_text("friction_bar")).expect("builtin is JSON")
}

/// Parses `text` and checks the error's file, path and that the reason contains `word`
/// (case-insensitive).
fn expect_text_err(text: &str, path: &str, word: &str) {
    match validated(text, FILE) {
        Err(Error::Case {
            file,
            path: got,
            reason,
            ..
        }) => {
            assert_eq!(file, FILE);
            assert_eq!(got, path, "wrong path; reason: {reason}");
            assert!(
                reason.to_lowercase().contains(&word.to_lowercase()),
                "reason at `{path}` lacks `{word}`: {reason}"
            );
        }
        Err(other) => panic!("expected Error::Case at `{path}`, got {other}"),
        Ok(_) => panic!("expected Error::Case at `{path}`, but the case was accepted"),
    }
}

fn expect_err(case: &Value, path: &str, word: &str) {
    expect_text_err(&case.to_string(), path, word);
}

/// Applies `edit` to the friction bar and expects an error.
fn edited(edit: impl FnOnce(&mut Value), path: &str, word: &str) {
    let mut case = friction_bar();
    edit(&mut case);
    expect_err(&case, path, word);
}

/// `build_mesh` on a case edited in code (for values JSON cannot hold).
fn expect_mesh_err(edit: impl FnOnce(&mut Case), path: &str, word: &str) {
    let mut case = common::builtin_case("friction_bar");
    edit(&mut case);
    match Mesh::from_case(&case) {
        Err(Error::Case {
            file,
            path: got,
            reason,
            ..
        }) => {
            assert_eq!(file, "builtin:friction_bar");
            assert_eq!(got, path, "wrong path; reason: {reason}");
            assert!(reason.contains(word), "reason lacks `{word}`: {reason}");
        }
        other => panic!("expected Error::Case at `{path}`, got {other:?}"),
    }
}

fn push(v: &mut Value, item: Value) {
    v.as_array_mut().expect("array").push(item);
}

fn remove(v: &mut Value, key: &str) {
    v.as_object_mut().expect("object").remove(key).expect(key);
}

#[test]
fn the_unedited_friction_bar_is_accepted() {
    validated(&friction_bar().to_string(), FILE).expect("valid");
}

#[test]
fn unknown_fields() {
    edited(
        |c| c["sheets"][0]["colour"] = json!("red"),
        "sheets[0].colour",
        "unknown field",
    );
    edited(|c| c["solver"] = json!("cvode"), "solver", "unknown field");
    edited(
        |c| c["load"]["master"]["fw"] = json!(1.0),
        "load.master.fw",
        "unknown field",
    );
}

#[test]
fn missing_fields() {
    edited(
        |c| remove(&mut c["sheets"][1], "thickness"),
        "sheets[1].thickness",
        "missing",
    );
    edited(|c| remove(c, "end_time"), "end_time", "missing");
    edited(
        |c| remove(&mut c["rigid_tie"], "master"),
        "rigid_tie.master",
        "missing",
    );
    // Optional parts may be missing.
    let mut case = friction_bar();
    remove(&mut case, "description");
    case["load"]["master"] = json!({});
    let case = validated(&case.to_string(), FILE).expect("optional fields");
    assert_eq!(case.description, None);
    assert_eq!(case.master_load(), [0.0; 6]);
}

#[test]
fn wrong_types() {
    edited(
        |c| c["sheets"][0]["thickness"] = json!("thin"),
        "sheets[0].thickness",
        "invalid type",
    );
    edited(
        |c| c["sheets"][0]["elements"][0] = json!(-3),
        "sheets[0].elements[0]",
        "invalid value",
    );
    edited(
        |c| c["sheets"][0]["elements"] = json!([25]),
        "sheets[0].elements",
        "length",
    );
    edited(
        |c| c["welds"][1]["sheets"] = json!("A"),
        "welds[1].sheets",
        "invalid type",
    );
    edited(
        |c| c["load"]["ramp"]["shape"] = json!("linear"),
        "load.ramp.shape",
        "unknown variant",
    );
    // A name field given a number or null is valid JSON of the wrong type, not "invalid JSON".
    for v in [json!(1), json!(null), json!([true])] {
        edited(|c| c["contact"]["slip"] = v, "contact.slip", "invalid type");
    }
    edited(
        |c| c["load"]["ramp"]["shape"] = json!(2),
        "load.ramp.shape",
        "invalid type",
    );
}

#[test]
fn malformed_json() {
    let text = friction_bar().to_string();
    let cut = &text[..text.len() / 2];
    match validated(cut, FILE) {
        Err(Error::Case { file, reason, .. }) => {
            assert_eq!(file, FILE);
            assert!(
                reason.contains("invalid JSON") && reason.contains("line"),
                "{reason}"
            );
        }
        other => panic!("expected Error::Case, got {other:?}"),
    }
    expect_text_err(&format!("{text} {{}}"), "$", "trailing");
    expect_text_err("42", "$", "object");
    expect_text_err(" [\"friction_bar\"]", "$", "object");
}

#[test]
fn non_finite_numbers() {
    let text = friction_bar().to_string();
    let big = text.replacen("210000.0", "1e999", 1);
    assert_ne!(big, text);
    expect_text_err(&big, "material.youngs_modulus", "finite");
    let big = text.replacen("165.0,0.5,12.5", "165.0,-1e400,12.5", 1);
    assert_ne!(big, text);
    expect_text_err(&big, "rigid_tie.master[1]", "finite");
    // Values JSON cannot hold, set in code.
    expect_mesh_err(|c| c.sheets[1].y = f64::NAN, "sheets[1].y", "finite");
    expect_mesh_err(
        |c| c.sheets[0].x[1] = f64::INFINITY,
        "sheets[0].x[1]",
        "finite",
    );
    expect_mesh_err(|c| c.welds[0].z = f64::NAN, "welds[0].z", "finite");
    expect_mesh_err(|c| c.clamps[0].x = f64::NAN, "clamps[0].x", "finite");
    expect_mesh_err(
        |c| c.material.poisson_ratio = f64::NAN,
        "material.poisson_ratio",
        "(−1, 0.5)",
    );
    expect_mesh_err(
        |c| c.contact.friction_coefficient = f64::INFINITY,
        "contact.friction_coefficient",
        "finite",
    );
}

#[test]
fn thickness_must_be_positive() {
    edited(
        |c| c["sheets"][1]["thickness"] = json!(0.0),
        "sheets[1].thickness",
        "positive",
    );
    edited(
        |c| c["sheets"][0]["thickness"] = json!(-0.5),
        "sheets[0].thickness",
        "positive",
    );
}

#[test]
fn lengths_must_be_positive() {
    edited(
        |c| c["sheets"][0]["x"] = json!([125.0, 0.0]),
        "sheets[0].x",
        "greater",
    );
    edited(
        |c| c["sheets"][1]["z"] = json!([0.0, 0.0]),
        "sheets[1].z",
        "greater",
    );
}

#[test]
fn element_counts_must_be_positive_and_bounded() {
    edited(
        |c| c["sheets"][0]["elements"][1] = json!(0),
        "sheets[0].elements[1]",
        "positive",
    );
    edited(
        |c| c["sheets"][0]["elements"] = json!([100000, 100000]),
        "sheets[0].elements",
        "JOINTROM_MAX_DOF",
    );
    edited(
        |c| c["sheets"][0]["elements"] = json!([u64::MAX, 3]),
        "sheets[0].elements",
        "JOINTROM_MAX_DOF",
    );
}

#[test]
fn weld_diameter_must_be_positive() {
    edited(
        |c| c["welds"][1]["diameter"] = json!(0.0),
        "welds[1].diameter",
        "positive",
    );
}

#[test]
fn material_constants() {
    edited(
        |c| c["material"]["density"] = json!(0.0),
        "material.density",
        "positive",
    );
    edited(
        |c| c["material"]["youngs_modulus"] = json!(-1.0),
        "material.youngs_modulus",
        "positive",
    );
    for nu in [0.5, -1.0, 0.7, -3.0] {
        edited(
            |c| c["material"]["poisson_ratio"] = json!(nu),
            "material.poisson_ratio",
            "poisson",
        );
    }
}

#[test]
fn contact_parameters() {
    edited(
        |c| c["contact"]["normal_stiffness"] = json!(0.0),
        "contact.normal_stiffness",
        "positive",
    );
    edited(
        |c| c["contact"]["stick_stiffness"] = json!(-1.0),
        "contact.stick_stiffness",
        "positive",
    );
    edited(
        |c| c["contact"]["friction_coefficient"] = json!(-0.1),
        "contact.friction_coefficient",
        "≥ 0",
    );
    // Frictionless contact is allowed.
    let mut case = friction_bar();
    case["contact"]["friction_coefficient"] = json!(0.0);
    validated(&case.to_string(), FILE).expect("mu = 0 is valid");
}

#[test]
fn times_must_be_positive() {
    edited(|c| c["end_time"] = json!(0.0), "end_time", "positive");
    edited(
        |c| c["load"]["ramp"]["duration"] = json!(-0.05),
        "load.ramp.duration",
        "positive",
    );
}

#[test]
fn master_must_be_finite() {
    expect_mesh_err(
        |c| c.rigid_tie.master[0] = f64::NAN,
        "rigid_tie.master[0]",
        "finite",
    );
    expect_mesh_err(
        |c| c.load.master.fy = f64::INFINITY,
        "load.master.fy",
        "finite",
    );
    expect_mesh_err(|c| c.load.master.mz = f64::NAN, "load.master.mz", "finite");
}

#[test]
fn sheet_names_must_be_unique_and_present() {
    edited(
        |c| c["sheets"][1]["name"] = json!("A"),
        "sheets[1].name",
        "duplicate",
    );
    edited(
        |c| c["sheets"][0]["name"] = json!(""),
        "sheets[0].name",
        "empty",
    );
    edited(|c| c["sheets"] = json!([]), "sheets", "no sheets");
}

#[test]
fn unknown_sheet_names() {
    edited(
        |c| c["clamps"][0]["sheets"][0] = json!("C"),
        "clamps[0].sheets[0]",
        "unknown sheet `C`",
    );
    edited(
        |c| c["rigid_tie"]["sheets"][0] = json!("b"),
        "rigid_tie.sheets[0]",
        "unknown sheet",
    );
    edited(
        |c| c["welds"][1]["sheets"][1] = json!("X"),
        "welds[1].sheets[1]",
        "unknown sheet",
    );
    edited(
        |c| c["joints"][0]["lower"] = json!("Z"),
        "joints[0].lower",
        "unknown sheet",
    );
    edited(
        |c| c["joints"][0]["upper"] = json!("Z"),
        "joints[0].upper",
        "unknown sheet",
    );
    edited(
        |c| c["clamps"][0]["sheets"] = json!(["A", "A"]),
        "clamps[0].sheets[1]",
        "twice",
    );
}

#[test]
fn clamp_and_tie_lines_must_be_node_lines() {
    edited(
        |c| c["clamps"][0]["x"] = json!(2.5),
        "clamps[0].x",
        "not a node line of sheet `A`",
    );
    edited(
        |c| c["clamps"][0]["x"] = json!(130.0),
        "clamps[0].x",
        "node line",
    );
    edited(
        |c| c["rigid_tie"]["x"] = json!(162.0),
        "rigid_tie.x",
        "node line",
    );
    // x = 130 is a node line of B but lies beyond A.
    edited(
        |c| c["clamps"][0] = json!({"x": 130.0, "sheets": ["B", "A"]}),
        "clamps[0].x",
        "sheet `A`",
    );
}

#[test]
fn the_structure_must_be_clamped() {
    edited(|c| c["clamps"] = json!([]), "clamps", "clamped");
    edited(
        |c| c["clamps"][0]["sheets"] = json!([]),
        "clamps[0].sheets",
        "no sheets",
    );
    edited(
        |c| c["rigid_tie"]["sheets"] = json!([]),
        "rigid_tie.sheets",
        "no sheets",
    );
}

#[test]
fn point_welds_must_sit_on_nodes() {
    let point = |c: &mut Value, w: usize| c["welds"][w]["model"] = json!("point");
    edited(
        |c| {
            point(c, 0);
            c["welds"][0]["x"] = json!(61.0);
        },
        "welds[0]",
        "not a node of sheet `A`",
    );
    // (20, 12.5) is a node of A only.
    edited(
        |c| {
            point(c, 1);
            c["welds"][1]["x"] = json!(20.0);
        },
        "welds[1]",
        "not a node of sheet `B`",
    );
    edited(
        |c| {
            point(c, 0);
            c["welds"][0]["z"] = json!(10.0);
        },
        "welds[0]",
        "not a node",
    );
    edited(
        |c| c["welds"][0]["model"] = json!("spot"),
        "welds[0].model",
        "unknown variant",
    );
}

#[test]
fn area_welds_lie_anywhere_in_the_overlap_and_nowhere_else() {
    // Off the nodes: accepted, and the mesh keeps every coincident pair outside the nuggets.
    let mut case = friction_bar();
    case["welds"][0]["x"] = json!(61.3);
    case["welds"][0]["z"] = json!(10.1);
    let mesh = Mesh::from_case(&validated(&case.to_string(), FILE).unwrap()).unwrap();
    assert_eq!(mesh.welds.len(), 2);
    assert_eq!(mesh.pairs.len(), 52 + 1);
    // Outside sheet B (x < 40): outside the overlap.
    edited(
        |c| c["welds"][1]["x"] = json!(20.0),
        "welds[1]",
        "outside sheet `B`",
    );
    // Outside both sheets.
    edited(
        |c| c["welds"][0]["z"] = json!(-3.0),
        "welds[0]",
        "outside sheet `A`",
    );
    // An explicit joint point inside a nugget is welded, not a contact pair.
    edited(
        |c| c["joints"][0]["points"] = json!([[60.0, 12.5]]),
        "joints[0].points[0]",
        "inside the nugget of welds[0]",
    );
}

#[test]
fn weld_nuggets_fit_the_sheets_and_do_not_overlap() {
    // Wider than the 25 mm strip.
    edited(
        |c| c["welds"][0]["diameter"] = json!(30.0),
        "welds[0].diameter",
        "larger than the width of sheet `A`",
    );
    // Two welds 5 mm apart with 5 mm nuggets touch (allowed); 10 mm nuggets overlap.
    edited(
        |c| {
            c["welds"][1]["x"] = json!(65.0);
            c["welds"][1]["diameter"] = json!(10.0);
        },
        "welds[1]",
        "overlaps that of welds[0]",
    );
    let mut touching = friction_bar();
    touching["welds"][1]["x"] = json!(65.0);
    validated(&touching.to_string(), FILE).expect("touching nuggets are allowed");
}

#[test]
fn weld_sheets_must_rise_in_y() {
    edited(
        |c| c["welds"][0]["sheets"] = json!(["B", "A"]),
        "welds[0].sheets",
        "increasing y",
    );
    // Equal y is not increasing (the weld is checked before the joint's clearance).
    edited(
        |c| c["sheets"][1]["y"] = json!(0.0),
        "welds[0].sheets",
        "increasing y",
    );
    edited(
        |c| c["welds"][0]["sheets"] = json!(["A"]),
        "welds[0].sheets",
        "at least 2",
    );
}

#[test]
fn joints_need_zero_clearance() {
    edited(
        |c| c["sheets"][1]["y"] = json!(0.6),
        "joints[0]",
        "clearance",
    );
    edited(
        |c| c["sheets"][1]["y"] = json!(0.4999),
        "joints[0]",
        "clearance",
    );
    edited(
        |c| c["joints"][0] = json!({"lower": "B", "upper": "A"}),
        "joints[0]",
        "below",
    );
    // Within the tolerance 1e-9 of the scale the sheets touch.
    let mut case = friction_bar();
    case["sheets"][1]["y"] = json!(0.5 + 1e-12);
    validated(&case.to_string(), FILE).expect("touching within tolerance");
}

#[test]
fn joint_sheets_must_overlap() {
    edited(
        |c| {
            c["sheets"][1]["x"] = json!([130.0, 255.0]);
            c["welds"] = json!([]);
        },
        "joints[0]",
        "do not overlap",
    );
}

#[test]
fn overlapping_joint_sheets_must_coincide() {
    // B with twice the elements has nodes at x = 42.5, ... that A lacks.
    let mut case = friction_bar();
    case["sheets"][1]["elements"] = json!([50, 2]);
    expect_err(
        &case,
        "joints[0]",
        "overlapping sheets that do not coincide",
    );
    let reason = validated(&case.to_string(), FILE).unwrap_err().to_string();
    assert!(reason.contains("`A`") && reason.contains("`B`"), "{reason}");
    // Shifted across z by a quarter element: the area welds still fit (they need no node), the
    // joint does not.
    edited(
        |c| c["sheets"][1]["z"] = json!([3.125, 28.125]),
        "joints[0]",
        "do not coincide",
    );
    edited(
        |c| {
            c["sheets"][1]["z"] = json!([3.125, 28.125]);
            c["welds"] = json!([]);
        },
        "joints[0]",
        "do not coincide",
    );
}

#[test]
fn joints_must_be_between_two_distinct_sheets_once() {
    edited(
        |c| c["joints"][0]["upper"] = json!("A"),
        "joints[0].upper",
        "same sheet",
    );
    edited(
        |c| c["joints"] = json!([{"lower": "A", "upper": "B"}, {"lower": "A", "upper": "B"}]),
        "joints[1]",
        "duplicate",
    );
}

#[test]
fn explicit_joint_points() {
    let mut case = friction_bar();
    case["joints"][0]["points"] = json!([[105.0, 0.0], [60.0, 25.0], [60.0, 0.0]]);
    let case = validated(&case.to_string(), FILE).expect("explicit points");
    let mesh = Mesh::from_case(&case).unwrap();
    let pairs: Vec<(usize, usize)> = mesh.pairs.iter().map(|p| (p.lower, p.upper)).collect();
    assert_eq!(
        pairs,
        vec![(36, 90), (38, 92), (63, 117)],
        "sorted by (x, z)"
    );

    // x = 10 is a node of A but outside B.
    edited(
        |c| c["joints"][0]["points"] = json!([[60.0, 0.0], [10.0, 12.5]]),
        "joints[0].points[1]",
        "not a node of sheet `B`",
    );
    edited(
        |c| c["joints"][0]["points"] = json!([[62.5, 12.5]]),
        "joints[0].points[0]",
        "not a node",
    );
    edited(
        |c| c["joints"][0]["points"] = json!([[60.0, 0.0], [60.0, 0.0]]),
        "joints[0].points[1]",
        "twice",
    );
    edited(
        |c| c["joints"][0]["points"] = json!([]),
        "joints[0].points",
        "empty",
    );
}

#[test]
fn explicit_joint_points_must_be_free() {
    // Clamp B at x = 40 as well: (40, 0) is then clamped on the upper side.
    edited(
        |c| {
            push(&mut c["clamps"], json!({"x": 40.0, "sheets": ["B"]}));
            c["joints"][0]["points"] = json!([[60.0, 0.0], [40.0, 0.0]]);
        },
        "joints[0].points[1]",
        "clamped (clamps[1])",
    );
    // Tie B at x = 125 (inside the overlap): (125, 25) is then tied.
    edited(
        |c| {
            c["rigid_tie"] = json!({"x": 125.0, "sheets": ["B"], "master": [125.0, 0.5, 12.5]});
            c["joints"][0]["points"] = json!([[125.0, 25.0]]);
        },
        "joints[0].points[0]",
        "tied",
    );
}

#[test]
fn implicit_pairs_skip_clamped_and_tied_nodes() {
    let mut case = friction_bar();
    push(&mut case["clamps"], json!({"x": 40.0, "sheets": ["B"]}));
    case["rigid_tie"] = json!({"x": 125.0, "sheets": ["A", "B"], "master": [125.0, 0.25, 12.5]});
    let mesh = Mesh::from_case(&validated(&case.to_string(), FILE).unwrap()).unwrap();
    assert_eq!(mesh.pairs.len(), 52 - 6);
    // A joint whose every pair is clamped or tied is an error.
    let mut case = friction_bar();
    case["sheets"][1]["x"] = json!([120.0, 245.0]);
    case["welds"] = json!([]);
    push(&mut case["clamps"], json!({"x": 120.0, "sheets": ["B"]}));
    case["rigid_tie"] = json!({"x": 125.0, "sheets": ["A", "B"], "master": [125.0, 0.25, 12.5]});
    expect_err(&case, "joints[0]", "no node pairs");
}

#[test]
fn no_node_may_be_both_clamped_and_tied() {
    edited(
        |c| c["rigid_tie"] = json!({"x": 0.0, "sheets": ["A"], "master": [0.0, 0.0, 12.5]}),
        "rigid_tie",
        "both clamped",
    );
}

#[test]
fn build_mesh_labels_errors_with_the_source() {
    let mut case = common::builtin_case("friction_bar");
    case.sheets[0].thickness = -1.0;
    let Err(err) = Mesh::from_case(&case) else {
        panic!("negative thickness accepted by build_mesh");
    };
    assert_eq!(
        err.to_string(),
        "builtin:friction_bar: at `sheets[0].thickness`: must be positive (finite and > 0), got -1 mm"
    );
}
