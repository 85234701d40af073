//! Basis benchmarks: the whole TVD basis of each built-in case
//! (`build_basis(.., BasisKind::Tvd, ..)`: 16 Craig–Bampton vectors → 512 TVD → K-weighted POD →
//! M-orthonormal Φ) and its pieces separately. Target: ≤ 50 ms for the friction bar.

use criterion::{criterion_group, criterion_main, Criterion};
use jointrom::case::Case;
use jointrom::reduction::{
    build_basis, craig_bampton, final_basis, pod, trial_vector_derivatives, BasisKind,
    BasisOptions, TvdOptions, DEFAULT_DROP_TOL, DEFAULT_THRESHOLD,
};
use jointrom::Model;

fn basis(c: &mut Criterion) {
    for name in Case::BUILTIN {
        let model = Model::from_case_name(name).expect("built-in case assembles");
        let opts = BasisOptions::default();
        let cb = craig_bampton(&model, opts.nu).expect("Craig–Bampton");
        let tvd =
            trial_vector_derivatives(&model, cb.as_ref(), &TvdOptions::default()).expect("TVD");
        let p = pod(tvd.vectors.as_ref(), Some(&model.stiffness)).expect("POD");
        let g = p.choose_g(DEFAULT_THRESHOLD);
        let jm = p.leading(g).to_owned();

        let mut group = c.benchmark_group(format!("basis/{name}"));
        group.sample_size(10);
        group.bench_function("build_basis_tvd", |b| {
            b.iter(|| build_basis(&model, BasisKind::Tvd, &opts).expect("basis"))
        });
        group.bench_function("craig_bampton", |b| {
            b.iter(|| craig_bampton(&model, opts.nu).expect("Craig–Bampton"))
        });
        group.bench_function("tvd", |b| {
            b.iter(|| {
                trial_vector_derivatives(&model, cb.as_ref(), &TvdOptions::default()).expect("TVD")
            })
        });
        group.bench_function("tvd_inertia", |b| {
            let o = TvdOptions {
                inertia: true,
                ..TvdOptions::default()
            };
            b.iter(|| trial_vector_derivatives(&model, cb.as_ref(), &o).expect("TVD"))
        });
        group.bench_function("pod_weighted", |b| {
            b.iter(|| pod(tvd.vectors.as_ref(), Some(&model.stiffness)).expect("POD"))
        });
        group.bench_function("pod_plain", |b| {
            b.iter(|| pod(tvd.vectors.as_ref(), None).expect("POD"))
        });
        group.bench_function("final_basis", |b| {
            b.iter(|| {
                final_basis(&[cb.as_ref(), jm.as_ref()], &model.mass, DEFAULT_DROP_TOL)
                    .expect("final basis")
            })
        });
        group.finish();
    }
}

criterion_group!(benches, basis);
criterion_main!(benches);
