//! Samples per second of kiln's QMC estimators (VNDF sampling with Owen-scrambled Sobol points),
//! and of every estimator `kiln study` compares ([`kiln::study::estimators`]).
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
            // Near a mirror, where the sum stratifies GGX's tail and Beckmann's ladder.
            group.bench_with_input(
                BenchmarkId::new("E-near-mirror", &name),
                &model,
                |b, &model| b.iter(|| albedo(model, black_box(1e-3), black_box(0.5), &settings)),
            );
            group.bench_with_input(BenchmarkId::new("E_avg", &name), &model, |b, &model| {
                b.iter(|| average_albedo(model, black_box(0.25), &settings))
            });
        }
    }
    group.finish();
}

/// Every estimator of `kiln study`, GGX height-correlated at alpha 0.25, mu 0.5 (the quadrature's
/// elements are its integrand evaluations, at tolerance 1e-10).
fn study_estimators(c: &mut Criterion) {
    use kiln::study::estimators::{Estimator, estimate};
    let model = Model {
        ndf: Ndf::Ggx,
        masking: Masking::HeightCorrelated,
    };
    let samples = 1u64 << 14;
    let mut group = c.benchmark_group("study");
    for estimator in Estimator::ALL {
        let elements = match estimator {
            Estimator::Quadrature => estimate(estimator, model, 0.25, 0.5, 0, 1e-10, 0).1,
            _ => samples,
        };
        group.throughput(Throughput::Elements(elements));
        group.bench_function(estimator.name(), |b| {
            b.iter(|| {
                estimate(
                    estimator,
                    model,
                    black_box(0.25),
                    black_box(0.5),
                    samples,
                    1e-10,
                    0,
                )
            })
        });
    }
    group.finish();
}

criterion_group!(benches, estimators, study_estimators);
criterion_main!(benches);
