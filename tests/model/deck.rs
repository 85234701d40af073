//! NASTRAN decks (`jointrom::case::nastran`): the built-in scenes written as a pre-processor
//! writes them (`cases/nastran/*.bdf`, by `scripts/case_to_bdf.py`) give the same model as the
//! case files — DOF, pairs, fixed-interface frequencies and contact statics — and the reader's
//! formats, warnings and refusals.

use std::path::{Path, PathBuf};

use jointrom::case::nastran::{cards, deck};
use jointrom::case::{RampShape, RampSpec};
use jointrom::joint::statics::ContactOptions;
use jointrom::model::contact_static_full;
use jointrom::{Error, Interface, Model};

use crate::common::{self, repo_path};

fn deck_model(name: &str) -> Model {
    let path = repo_path(&format!("cases/nastran/{name}.bdf"));
    Model::from_case_name(path.to_str().unwrap()).unwrap()
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(1e-300)
}

/// A deck and the built-in case agree: same DOF, same pairs (by node position), first ten
/// fixed-interface frequencies and the contact statics under the case's load and its negative
/// within 0.1 % (measured: ~1e-11).
fn same_as_case(name: &str, fused: usize) {
    // `--deck-local-mesh off`: a deck's CWELD is the area weld on the sheets' own shells, the
    // case with `"local_mesh": "off"`.
    let path = repo_path(&format!("cases/nastran/{name}.bdf"));
    let d = Model::from_deck_with(&path, jointrom::case::LocalMesh::Off).unwrap();
    let c = common::rbe3_model(name);
    assert_eq!(d.dofs(), c.dofs(), "{name}: DOF");
    assert_eq!(d.pair_count(), c.pair_count(), "{name}: pairs");
    let key = |m: &Model| {
        let mut v: Vec<[i64; 6]> = m
            .pairs
            .iter()
            .map(|p| {
                let (a, b) = (m.geometry.nodes[p.lower], m.geometry.nodes[p.upper]);
                [a[0], a[1], a[2], b[0], b[1], b[2]].map(|x| (x * 1e6).round() as i64)
            })
            .collect();
        v.sort_unstable();
        v
    };
    assert_eq!(key(&d), key(&c), "{name}: the same node pairs");
    for (p, q) in d.pairs.iter().zip(&c.pairs) {
        assert_eq!(p.directions(), q.directions(), "{name}: pair frames");
    }
    let (fd, fc) = (
        d.modes(10, Interface::Fixed).unwrap().frequencies_hz,
        c.modes(10, Interface::Fixed).unwrap().frequencies_hz,
    );
    for (k, (a, b)) in fd.iter().zip(&fc).enumerate() {
        println!("{name}: mode {}: deck {a:.6} Hz, case {b:.6} Hz", k + 1);
        assert!(rel(*a, *b) < 1e-3, "{name}: mode {}: {a} vs {b} Hz", k + 1);
    }
    assert_eq!(d.master_load(), c.master_load(), "{name}: master load");
    let opts = ContactOptions::default();
    for sign in [1.0, -1.0] {
        let load = c.master_load().map(|v| sign * v);
        let (sd, sc) = (
            contact_static_full(&d, load, &opts).unwrap(),
            contact_static_full(&c, load, &opts).unwrap(),
        );
        let (nd, nc) = (sd.state.contact_force_norm, sc.state.contact_force_norm);
        println!("{name}: load ×{sign}: |f_c| deck {nd:.9e} N, case {nc:.9e} N");
        assert!(rel(nd, nc) < 1e-3, "{name}: |f_c| {nd} vs {nc}");
        assert_eq!(sd.state.pairs_in_contact, sc.state.pairs_in_contact);
        let (ud, uc) = (sd.master_displacement, sc.master_displacement);
        for k in [1, 3] {
            assert!(
                rel(ud[k], uc[k]) < 1e-3,
                "{name}: master dof {k}: {} vs {}",
                ud[k],
                uc[k]
            );
        }
    }
    assert_eq!(d.end_time, c.end_time, "{name}: end time from TSTEP");
    for t in [0.0, 0.3, 0.5, 0.9, 1.0, 1.5, 4.0].map(|f| f * c.end_time / 4.0) {
        let (a, b) = (d.load.ramp.factor(t), c.load.ramp.factor(t));
        assert!((a - b).abs() < 1e-4, "{name}: ramp at {t} s: {a} vs {b}");
    }
    let fused_warning = d
        .warnings
        .iter()
        .find(|w| w.contains("inside an area weld's nugget"))
        .expect("a warning for the fused CGAPs");
    assert_eq!(
        fused_warning.matches("700").count(),
        fused,
        "{fused_warning}"
    );
    assert!(
        d.warnings.iter().any(|w| w.contains("EIGRL ×1, PARAM ×1")),
        "{:?}",
        d.warnings
    );
}

/// A deck of a built-in scene gets the case's weld model (`local_mesh` `auto`: the re-meshed
/// neighbourhood where the deck's regular shells do not resolve the nugget; a weld through
/// three sheets written as two CWELDs is one weld): the first ten fixed-interface frequencies
/// and the contact statics (‖f_c‖, master displacement, pair forces) equal the case file's to
/// 1e-6 (measured: ~1e-12).
#[test]
fn decks_get_the_case_weld_model() {
    for name in ["friction_bar", "multilayer_sheet"] {
        let (d, c) = (deck_model(name), common::model(name));
        assert_eq!(d.dofs(), c.dofs(), "{name}: DOF");
        let resolved = |m: &Model| {
            m.mesh()
                .unwrap()
                .welds
                .iter()
                .filter(|w| w.patch.is_some())
                .count()
        };
        assert_eq!(resolved(&d), resolved(&c), "{name}: re-meshed welds");
        assert!(resolved(&d) > 0, "{name}");
        let (fd, fc) = (
            d.modes(10, Interface::Fixed).unwrap().frequencies_hz,
            c.modes(10, Interface::Fixed).unwrap().frequencies_hz,
        );
        for (k, (a, b)) in fd.iter().zip(&fc).enumerate() {
            println!("{name}: mode {}: deck {a:.9} Hz, case {b:.9} Hz", k + 1);
            assert!(rel(*a, *b) < 1e-6, "{name}: mode {}: {a} vs {b} Hz", k + 1);
        }
        let opts = ContactOptions::default();
        let load = c.master_load();
        let (sd, sc) = (
            contact_static_full(&d, load, &opts).unwrap(),
            contact_static_full(&c, load, &opts).unwrap(),
        );
        let (nd, nc) = (sd.state.contact_force_norm, sc.state.contact_force_norm);
        println!("{name}: |f_c| deck {nd:.12e} N, case {nc:.12e} N");
        assert!(rel(nd, nc) < 1e-6, "{name}: |f_c| {nd} vs {nc}");
        assert_eq!(sd.state.pairs_in_contact, sc.state.pairs_in_contact);
        for k in 0..6 {
            let (a, b) = (sd.master_displacement[k], sc.master_displacement[k]);
            assert!(
                (a - b).abs() <= 1e-6 * b.abs().max(1e-6),
                "{name}: master dof {k}: {a} vs {b}"
            );
        }
    }
}

#[test]
fn friction_bar_deck_equals_the_case() {
    same_as_case("friction_bar", 2);
}

#[test]
fn multilayer_deck_equals_the_case() {
    same_as_case("multilayer_sheet", 6);
}

/// The same cards in small, large and free field, with comments, tabs and continuations.
#[test]
fn formats_give_the_same_cards() {
    let dir = common::tmp_dir("deck_formats");
    let line = |fields: &[&str]| -> String {
        fields.iter().map(|f| format!("{f:<8}")).collect::<String>() + "\n"
    };
    let small = [
        "$ small field\n".to_string(),
        line(&["GRID", "17", "0", "1.25", "-2.5", "3.0"]),
        line(&["CQUAD4", "1", "2", "17", "18", "19", "20"]),
        line(&["PGAP", "1", "", "", "1.+4", "", "2.5+3", ".25"]),
        line(&["TABLED1", "30", "LINEAR", "LINEAR"]),
        line(&["+", "0.0", "0.0", "0.05", "1.0", "ENDT"]),
    ]
    .concat();
    let small = small.as_str();
    let large = "GRID*                 17               0            1.25            -2.5\n*                    3.0\nCQUAD4*                1               2              17              18\n*                     19              20\nPGAP*                  1                                        10000.0\n*                                2500.          0.25\nTABLED1*              30          LINEAR          LINEAR\n*\n*                    0.0             0.0            0.05             1.0\n*                   ENDT\n";
    let free = "GRID,17,0,1.25,-2.5,3.0 $ a comment\ncquad4,1,2,17,18,19,20\nPGAP,1,,,1.E4,,2.5E3,0.25\nTABLED1,30,LINEAR,LINEAR\n,0.0,0.0,0.05,1.0,ENDT\n";
    let tabs = "GRID\t17\t0\t1.25\t-2.5\t3.0\nCQUAD4\t1\t2\t17\t18\t19\t20\nPGAP\t1\t\t\t1.+4\t\t2.5+3\t.25\nTABLED1\t30\tLINEAR\tLINEAR\n\t0.0\t0.0\t0.05\t1.0\tENDT\n";
    let mut decks = Vec::new();
    for (name, text) in [
        ("small", small),
        ("large", large),
        ("free", free),
        ("tabs", tabs),
    ] {
        let path = dir.join(format!("{name}.bdf"));
        std::fs::write(&path, text).unwrap();
        let d = deck::read(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
        decks.push((name, d));
    }
    let (_, first) = &decks[0];
    assert_eq!(first.grids[&17].xyz, [1.25, -2.5, 3.0]);
    assert_eq!(first.pgaps[&1].normal_stiffness, 1e4);
    assert_eq!(first.pgaps[&1].stick_stiffness, 2500.0);
    assert_eq!(first.tables[&30].points, vec![[0.0, 0.0], [0.05, 1.0]]);
    for (name, d) in &decks[1..] {
        assert_eq!(d.grids[&17].xyz, first.grids[&17].xyz, "{name}");
        assert_eq!(d.quads[0].grids, first.quads[0].grids, "{name}");
        assert_eq!(d.pgaps[&1].normal_stiffness, 1e4, "{name}");
        assert_eq!(d.pgaps[&1].stick_stiffness, 2500.0, "{name}");
        assert_eq!(d.pgaps[&1].friction_coefficient, 0.25, "{name}");
        assert_eq!(d.tables[&30].points, first.tables[&30].points, "{name}");
    }
}

/// Writes `text` as a deck beside the friction bar's mesh include and loads it.
fn load_variant(name: &str, edit: impl Fn(String) -> String) -> Result<Model, Error> {
    let dir = common::tmp_dir(&format!("deck_{name}"));
    let src = repo_path("cases/nastran");
    for f in ["friction_bar.bdf", "friction_bar_mesh.bdf"] {
        std::fs::copy(src.join(f), dir.join(f)).unwrap();
    }
    let main = dir.join("friction_bar.bdf");
    let text = std::fs::read_to_string(&main).unwrap();
    let edited = edit(text.clone());
    assert_ne!(edited, text, "{name}: the edit matched nothing in the deck");
    std::fs::write(&main, edited).unwrap();
    Model::from_case_name(main.to_str().unwrap())
}

fn fails(name: &str, edit: impl Fn(String) -> String, expect: &[&str]) {
    let e = load_variant(name, edit)
        .map(|_| ())
        .unwrap_err()
        .to_string();
    println!("{name}: {e}");
    for want in expect {
        assert!(e.contains(want), "{name}: `{e}` lacks `{want}`");
    }
}

fn before_enddata(card: &str) -> impl Fn(String) -> String + '_ {
    move |t| t.replace("ENDDATA", &format!("{card}\nENDDATA"))
}

#[test]
fn unsupported_mechanics_are_errors_naming_the_line() {
    fails(
        "ctria3",
        before_enddata("CTRIA3,9,1,10001,10002,10004"),
        &["friction_bar.bdf:", "CTRIA3 9", "CQUAD4"],
    );
    fails(
        "mats1",
        before_enddata("MATS1,1,,PLASTIC,1000."),
        &["MATS1", "nonlinearity"],
    );
    fails(
        "u0",
        |t| t.replace("PGAP         201        ", "PGAP         201    0.01"),
        &["PGAP 201", "U0"],
    );
    fails(
        "second rbe2",
        before_enddata("RBE2,2,90001,123456,10004"),
        &["RBE2 2", "a second RBE2"],
    );
    fails(
        "partial spc",
        |t| t.replace("SPC1           1  123456", "SPC1           1     123"),
        &["SPC1 1", "all six"],
    );
    fails(
        "membrane shell",
        |t| t.replace("PSHELL,2,1,0.5,1,,1", "PSHELL,2,1,0.5"),
        &["PSHELL 2", "MID2"],
    );
    fails(
        "load elsewhere",
        before_enddata("FORCE,100,10005,0,1.,0.,1.,0."),
        &["load set 100", "grid 10005"],
    );
    fails(
        "no endt",
        |t| t.replace("ENDT", ""),
        &["TABLED1 30", "ENDT"],
    );
    fails(
        "bad real",
        |t| t.replace("MAT1,1,210000.0", "MAT1,1,2l0000.0"),
        &["MAT1 1", "E: expected a finite real number", "2l0000.0"],
    );
    fails(
        "nan",
        |t| t.replace("MAT1,1,210000.0", "MAT1,1,NaN"),
        &["MAT1 1", "E:"],
    );
    fails(
        "missing include",
        |t| t.replace("friction_bar_mesh.bdf", "nowhere.bdf"),
        &["nowhere.bdf", "cannot read"],
    );
    fails(
        "self include",
        |t| t.replace("friction_bar_mesh.bdf", "friction_bar.bdf"),
        &["INCLUDE", "includes itself"],
    );
    fails(
        "undefined grid",
        before_enddata("CGAP,79999,1,10004,99999"),
        &["CGAP", "grid 99999 is not defined"],
    );
    fails(
        "gap law",
        |t| {
            let t = t.replace("CGAP       70001     201", "CGAP       70001     202");
            before_enddata("PGAP,202,,,2.E4,,1.E4,0.25")(t)
        },
        &["CGAP 70002", "PGAP 201 differs from PGAP 202"],
    );
    fails(
        "no tstep",
        |t| t.replace("TSTEP   ", "$STEP   "),
        &["TSTEP"],
    );
    fails(
        "lgdisp",
        before_enddata("PARAM,LGDISP,1"),
        &["PARAM", "LGDISP", "large displacements"],
    );
    fails(
        "damping",
        before_enddata("PARAM,G,0.02"),
        &["PARAM", "damping"],
    );
}

/// PARAM,WTMASS scales every mass (ω ∝ 1/√m); a material in SI units draws a warning; a
/// degenerate CQUAD4 is named by its line.
#[test]
fn params_units_and_warped_shells() {
    let f = |m: &Model| m.modes(3, Interface::Fixed).unwrap().frequencies_hz;
    let base = f(&deck_model("friction_bar"));
    let light = load_variant("wtmass", before_enddata("PARAM,WTMASS,0.5")).unwrap();
    for (a, b) in f(&light).iter().zip(&base) {
        assert!(rel(*a, b * 2f64.sqrt()) < 1e-9, "{a} vs {b}·√2");
    }
    let si = load_variant("si", |t| {
        t.replace("MAT1,1,210000.0,,0.3,7.85-9", "MAT1,1,2.1+11,,0.3,7850.")
    })
    .unwrap();
    assert!(
        si.warnings.iter().any(|w| w.contains("mm, N, t, s")),
        "{:?}",
        si.warnings
    );
    let dir = common::tmp_dir("deck_warped");
    for f in ["friction_bar.bdf", "friction_bar_mesh.bdf"] {
        std::fs::copy(repo_path("cases/nastran").join(f), dir.join(f)).unwrap();
    }
    let mesh = dir.join("friction_bar_mesh.bdf");
    let text = std::fs::read_to_string(&mesh).unwrap();
    // Grid 10005 (5, 0, 12.5) moved onto grid 10001 (0, 0, 0): its shells degenerate.
    let warped = text.replacen(
        "GRID*              10005                             5.0             0.0\n*                   12.5",
        "GRID*              10005                             0.0             0.0\n*                    0.0",
        1,
    );
    assert_ne!(warped, text);
    std::fs::write(&mesh, warped).unwrap();
    let e = Model::from_case_name(dir.join("friction_bar.bdf").to_str().unwrap())
        .map(|_| ())
        .unwrap_err()
        .to_string();
    println!("warped: {e}");
    assert!(
        e.contains("friction_bar_mesh.bdf:") && e.contains("CQUAD4 1000"),
        "{e}"
    );
}

#[test]
fn unknown_cards_are_a_warning() {
    let m = load_variant("unknown", before_enddata("FOOBAR,1,2,3\nFOOBAR,4")).unwrap();
    assert!(
        m.warnings
            .iter()
            .any(|w| w.contains("unknown cards") && w.contains("FOOBAR ×2")),
        "{:?}",
        m.warnings
    );
    assert_eq!(m.dofs(), 906);
}

/// A weld moved off the nodes (the nugget sampled on the re-meshed neighbourhood) gives the
/// same model as the case with the weld moved alike; CONM2 adds its mass: the first frequency falls.
#[test]
fn welds_anywhere_and_point_masses() {
    let base = deck_model("friction_bar");
    let f0 = base.modes(5, Interface::Fixed).unwrap().frequencies_hz;
    let moved = load_variant("moved weld", |t| {
        t.replace(
            "GRID*              80001                            60.0             0.0\n*                   12.5",
            "GRID*              80001                            62.5             0.0\n*                   11.0",
        )
    })
    .unwrap();
    let f1 = moved.modes(5, Interface::Fixed).unwrap().frequencies_hz;
    let mut case = common::builtin_case("friction_bar");
    case.welds[0].x = 62.5;
    case.welds[0].z = 11.0;
    let f2 = Model::from_case(case)
        .unwrap()
        .modes(5, Interface::Fixed)
        .unwrap()
        .frequencies_hz;
    for k in 0..5 {
        println!(
            "mode {}: weld at (60, 12.5) {:.4} Hz; at (62.5, 11): deck {:.4}, case {:.4} Hz",
            k + 1,
            f0[k],
            f1[k],
            f2[k]
        );
        assert!(rel(f1[k], f2[k]) < 1e-9, "mode {}", k + 1);
    }
    assert!(f1[0] != f0[0]);
    let heavy = load_variant("conm2", before_enddata("CONM2,5,10040,0,1.E-5")).unwrap();
    let f3 = heavy.modes(1, Interface::Fixed).unwrap().frequencies_hz[0];
    println!(
        "CONM2 of 1e-5 t at grid 10040: f1 {:.4} → {f3:.4} Hz",
        f0[0]
    );
    assert!(f3 < 0.9 * f0[0]);
}

#[test]
fn tabled1_interpolates_and_extrapolates_like_nastran() {
    let ramp = RampSpec {
        shape: RampShape::Table,
        duration: None,
        points: vec![[0.0, 0.0], [1.0, 2.0], [1.0, 4.0], [2.0, 4.0]],
    };
    ramp.check("ramp").unwrap();
    assert_eq!(ramp.factor(0.5), 1.0);
    assert_eq!(ramp.factor(1.0), 3.0, "the mean at a jump");
    assert_eq!(ramp.factor(1.5), 4.0);
    assert_eq!(
        ramp.factor(-1.0),
        -2.0,
        "extrapolated through the first two points"
    );
    assert_eq!(ramp.factor(3.0), 4.0);
    let bad = RampSpec {
        points: vec![[0.0, 0.0], [1.0, 1.0], [0.5, 1.0]],
        ..ramp.clone()
    };
    assert!(bad
        .check("ramp")
        .unwrap_err()
        .1
        .contains("must not decrease"));
}

/// The reader never panics on truncated or garbled decks (a cheap stand-in for the fuzzer).
#[test]
fn truncations_never_panic() {
    let text = std::fs::read_to_string(repo_path("cases/nastran/friction_bar.bdf")).unwrap();
    let dir = common::tmp_dir("deck_truncated");
    std::fs::copy(
        repo_path("cases/nastran/friction_bar_mesh.bdf"),
        dir.join("friction_bar_mesh.bdf"),
    )
    .unwrap();
    let path: PathBuf = dir.join("cut.bdf");
    let mut errors = 0;
    for cut in (0..text.len()).step_by(37) {
        std::fs::write(&path, &text.as_bytes()[..cut]).unwrap();
        if Model::from_case_name(path.to_str().unwrap()).is_err() {
            errors += 1;
        }
    }
    assert!(errors > 0);
    let cards = cards::read(Path::new(&path)).unwrap();
    assert!(!cards.files.is_empty());
}

/// CWELD ELPAT (patches by element) gives the PARTPAT model; CWELD ALIGN and a CBAR with a
/// PBARL ROD between the weld-centre grids give the case's point weld (`"model": "point"`).
#[test]
fn weld_attachments_map_to_jointrom_welds() {
    let freq = |m: &Model| m.modes(10, Interface::Fixed).unwrap().frequencies_hz;
    let partpat = freq(&deck_model("friction_bar"));
    let elpat = load_variant("elpat", |t| {
        t.replace(
            "CWELD      60001     101   80001 PARTPAT\n+              1       2",
            "CWELD      60001     101   80001   ELPAT\n+         100026  200010",
        )
        .replace(
            "CWELD      60002     101   80002 PARTPAT\n+              1       2",
            "CWELD      60002     101   80002  ELEMID\n+         100044  200028",
        )
    })
    .unwrap();
    assert_eq!(freq(&elpat), partpat, "ELPAT/ELEMID = PARTPAT");
    let point = freq(&common::point_weld_model("friction_bar"));
    let align = |t: String| {
        t.replace(
            "CWELD      60001     101   80001 PARTPAT\n+              1       2",
            "CWELD,60001,101,,ALIGN,10038,20014",
        )
        .replace(
            "CWELD      60002     101   80002 PARTPAT\n+              1       2",
            "CWELD,60002,101,,ALIGN,10065,20041",
        )
    };
    let aligned = load_variant("align", align).unwrap();
    let bars = load_variant("cbar", |t| {
        align(t)
            .replace("CWELD,60001,101,,ALIGN,", "CBAR,60001,301,")
            .replace("CWELD,60002,101,,ALIGN,", "CBAR,60002,301,")
            .replace("ENDDATA", "PBARL,301,1,,ROD\n,2.5\nENDDATA")
    })
    .unwrap();
    for (k, p) in point.iter().enumerate() {
        let (a, b) = (freq(&aligned)[k], freq(&bars)[k]);
        println!(
            "mode {}: point weld {p:.6}, ALIGN {a:.6}, CBAR ROD {b:.6} Hz",
            k + 1
        );
        assert!(rel(a, *p) < 1e-9 && rel(b, *p) < 1e-9, "mode {}", k + 1);
    }
    // Welds without a nugget fuse no pairs: all 54 CGAPs are joint pairs.
    assert_eq!(aligned.pair_count(), 54);
}
