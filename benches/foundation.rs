//! Foundation benchmarks: assembly (case → mesh → K, M) and the 30 lowest fixed-interface
//! modes, for both built-in cases. Target: ≤ 50 ms for the friction bar.

use criterion::{criterion_group, criterion_main, Criterion};
use jointrom::case::Case;
use jointrom::{Interface, Model};

fn foundation(c: &mut Criterion) {
    for name in Case::BUILTIN {
        let case = Case::load(name).expect("built-in case loads");
        let model = Model::from_case(case.clone()).expect("built-in case assembles");
        let mut group = c.benchmark_group(*name);
        group.sample_size(20);
        group.bench_function("assembly", |b| {
            b.iter(|| Model::from_case(case.clone()).expect("assembles"))
        });
        group.bench_function("modes30_fixed", |b| {
            b.iter(|| model.modes(30, Interface::Fixed).expect("modes"))
        });
        group.bench_function("assembly+modes30_fixed", |b| {
            b.iter(|| {
                let m = Model::from_case(case.clone()).expect("assembles");
                m.modes(30, Interface::Fixed).expect("modes")
            })
        });
        group.finish();
    }
}

criterion_group!(benches, foundation);
criterion_main!(benches);
