//! `jointrom sweep`: variants of one shared reduced model, run in parallel, give the same curves
//! as run one by one and as a direct run of the case; the variant file is validated.

use jointrom::integrate as transient;
use jointrom::reduction::{build_basis, BasisKind, BasisOptions};
use jointrom::studies::sweep::{read_variants, run_sweep, Variant};
use jointrom::system::{ReducedSystem, Scene};

use crate::common;

fn variant(name: &str, mu: Option<f64>, scale: Option<f64>) -> Variant {
    Variant {
        name: name.into(),
        load_scale: scale,
        friction_coefficient: mu,
        normal_stiffness: None,
        stick_stiffness: None,
    }
}

#[test]
fn parallel_equals_sequential_and_the_case_variant_equals_a_direct_run() {
    let model = common::model("friction_bar");
    let b = build_basis(&model, BasisKind::Tvd, &BasisOptions::default()).unwrap();
    let rom = ReducedSystem::new(&model, b.phi).unwrap();
    let opts = common::until(0.01);
    let vs = vec![
        variant("case", None, None),
        variant("mu 0", Some(0.0), None),
        variant("mu 0.5", Some(0.5), None),
        variant("half load", None, Some(0.5)),
    ];
    let par = run_sweep(&model, &rom, &vs, &opts, true).unwrap();
    let seq = run_sweep(&model, &rom, &vs, &opts, false).unwrap();
    for (p, s) in par.runs.iter().zip(&seq.runs) {
        assert_eq!(p.status, "ok");
        assert_eq!(p.curves, s.curves, "{}", p.variant.name);
    }
    let direct = transient::run(rom.clone(), &Scene::of(&model), &opts).unwrap();
    assert_eq!(par.runs[0].curves, direct.curves);
    // μ = 0: no friction force; μ = 0.5 rubs harder than the case's 0.25.
    let last = |v: &[f64]| *v.last().unwrap();
    assert_eq!(last(&par.runs[1].curves.friction_force_norm), 0.0);
    assert!(
        last(&par.runs[2].curves.friction_force_norm)
            > last(&par.runs[0].curves.friction_force_norm)
    );
    // Half the load: about half the tip displacement (contact is nearly linear here).
    let r = last(&par.runs[3].curves.master_uy) / last(&par.runs[0].curves.master_uy);
    assert!((r - 0.5).abs() < 0.05, "uy ratio {r}");
    assert!(par.sum_wall_s > 0.0 && par.wall_s > 0.0);
}

#[test]
fn bad_variant_files_name_the_field() {
    for (name, text, field) in [
        (
            "unknown",
            r#"{"variants": [{"name": "a", "mu": 0.1}]}"#,
            "variants[0]",
        ),
        (
            "negative",
            r#"{"variants": [{"name": "a", "friction_coefficient": -0.1}]}"#,
            "variants[0].friction_coefficient",
        ),
        (
            "kn",
            r#"{"variants": [{"name": "a"}, {"name": "b", "normal_stiffness": 0}]}"#,
            "variants[1].normal_stiffness",
        ),
        ("empty", r#"{"variants": []}"#, "variants"),
    ] {
        let path = common::tmp_path(&format!("sweep_{name}.json"));
        std::fs::write(&path, text).unwrap();
        let e = read_variants(&path).unwrap_err().to_string();
        assert!(
            e.contains(&path.display().to_string()) && e.contains(field),
            "{name}: {e}"
        );
        let _ = std::fs::remove_file(&path);
    }
    let ok = read_variants(&common::repo_path("cases/sweeps/friction_bar_mu.json")).unwrap();
    assert_eq!(ok.len(), 6);
}
