//! Samples per second of kiln's QMC estimators (VNDF sampling with Owen-scrambled Sobol points).
//!
//! Run with `cargo bench --bench estimators`; criterion reports throughput in elements (integrand
//! evaluations) per second, single-threaded.

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use kiln::{Masking, Model, Ndf, QmcSettings, albedo, average_albedo};
use std::hint::black_box;

fn estimators(c: &mut Criterion) {
    let samples = 1u64 << 16;
    let settings = QmcSettings {
        samples,
        ..QmcSettings::default()
    };
    let mut group = c.benchmark_group("vndf");
    group.throughput(Throughput::Elements(samples));
    for ndf in Ndf::ALL {
        for masking in Masking::ALL {
            let model = Model { ndf, masking };
            let name = format!("{ndf}-{masking}");
            group.bench_with_input(BenchmarkId::new("E", &name), &model, |b, &model| {
                b.iter(|| albedo(model, black_box(0.25), black_box(0.5), &settings))
            });
            group.bench_with_input(BenchmarkId::new("E_avg", &name), &model, |b, &model| {
                b.iter(|| average_albedo(model, black_box(0.25), &settings))
            });
        }
    }
    group.finish();
}

criterion_group!(benches, estimators);
criterion_main!(benches);
