//! One right-hand-side evaluation of the mechanical ODE (`MechanicalOde::rhs`, friction on) for
//! the friction bar's ROM (a-priori g) and full FE model, at the state reached after 0.02 s of
//! the transient (pairs open, sticking and slipping). Prints the time per call with the flop
//! count it implies.
//!
//! Flops per ROM call (r coordinates, w pairs): `BΦ q` and `(BΦ)ᵀ p` 2·(3w·r) each, `K̃ q`
//! 2r² (dense), M̃ = I (no solve), the pair law ~60 per pair: `4·3w·r + 2r² + 60w`.
//! Full model: `K q` 2·nnz(K) (both triangles stored), the B products ~4 per joint-row entry, the
//! mass solve with the sparse Cholesky factor ~4·nnz(L) — reported as the K and B part only (the
//! factor's fill is faer's business), so the implied rate is a lower bound.

use std::hint::black_box;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion};
use jointrom::integrate::problem::OdeProblem;
use jointrom::integrate::{run, MechanicalOde, ProblemOptions, TransientOptions};
use jointrom::reduction::{build_basis, BasisKind, BasisOptions};
use jointrom::system::{FullSystem, ReducedSystem, Scene, SecondOrderSystem};
use jointrom::Model;

/// Mean time of `f` over a calibrated number of calls, ns.
fn time_ns(mut f: impl FnMut()) -> f64 {
    let mut n = 1u64;
    loop {
        let t = std::time::Instant::now();
        for _ in 0..n {
            f();
        }
        let e = t.elapsed();
        if e > Duration::from_millis(300) {
            return e.as_nanos() as f64 / n as f64;
        }
        n *= 4;
    }
}

fn state_after<S: SecondOrderSystem>(sys: S, scene: &Scene) -> Vec<f64> {
    let opts = TransientOptions {
        end_time: Some(0.02),
        ..TransientOptions::default()
    };
    run(sys, scene, &opts).expect("0.02 s run").final_state
}

fn rhs(c: &mut Criterion) {
    let model = Model::from_case_name("friction_bar").expect("friction bar");
    let basis = build_basis(&model, BasisKind::Tvd, &BasisOptions::default()).expect("basis");
    let rom = ReducedSystem::new(&model, basis.phi).expect("ROM");
    let scene = Scene::of(&model);
    let (r, w) = (rom.dim(), model.joint.pairs());
    let po = ProblemOptions::default();

    let y = state_after(rom.clone(), &scene);
    let mut ode = MechanicalOde::new(rom.clone(), &scene.contact, &po).expect("ode");
    let mut ydot = vec![0.0; y.len()];
    let ns = time_ns(|| {
        ode.rhs(0.02, black_box(&y), &mut ydot).expect("rhs");
    });
    let flops = (4 * 3 * w * r + 2 * r * r + 60 * w) as f64;
    println!(
        "ROM RHS (r = {r}, w = {w}, state {}): {ns:.0} ns, ~{flops:.0} flops → {:.2} GFlop/s",
        y.len(),
        flops / ns
    );

    let yf = state_after(FullSystem::new(&model).expect("full"), &scene);
    let mut full = MechanicalOde::new(FullSystem::new(&model).expect("full"), &scene.contact, &po)
        .expect("ode");
    let mut yfdot = vec![0.0; yf.len()];
    let nsf = time_ns(|| {
        full.rhs(0.02, black_box(&yf), &mut yfdot).expect("rhs");
    });
    let nnz_k = model.stiffness.values.len();
    let joint_entries: usize = (0..3 * w).map(|row| model.joint.row(row).count()).sum();
    let flops_f = (2 * nnz_k + 4 * joint_entries + 60 * w) as f64;
    println!(
        "full RHS (n = {}, nnz(K) = {nnz_k}): {nsf:.0} ns, ≥ {flops_f:.0} flops (K, B, pair law; \
         plus the mass solve) → ≥ {:.2} GFlop/s",
        model.dofs(),
        flops_f / nsf
    );

    let mut group = c.benchmark_group("rhs");
    group.bench_function("rom_friction_bar", |b| {
        b.iter(|| ode.rhs(0.02, black_box(&y), &mut ydot).expect("rhs"))
    });
    group.bench_function("full_friction_bar", |b| {
        b.iter(|| full.rhs(0.02, black_box(&yf), &mut yfdot).expect("rhs"))
    });
    group.finish();
}

criterion_group!(benches, rhs);
criterion_main!(benches);
