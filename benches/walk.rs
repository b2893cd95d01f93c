//! Walks per second of the microsurface random walk ([`kiln::integrate::walk`]), on one thread,
//! for each estimator the walk offers: the escape as its expectation (kiln's) or drawn, and
//! Sobol numbers for the first vertices (kiln's) or pseudorandom ones; and the cost of the
//! lobe's next-event estimates. How the error falls with the work is
//! `examples/walk_estimators.rs`.
//!
//! Run with `cargo bench --bench walk`; criterion reports throughput in walks per second.

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use kiln::integrate::walk::lobe::LobeGrid;
use kiln::integrate::walk::{
    Escape, Numbers, WalkSettings, walk_albedo, walk_lobe, walk_schlick_polynomial,
};
use kiln::{Fresnel, Masking, Model, Ndf};
use std::hint::black_box;

const GGX: Model = Model {
    ndf: Ndf::Ggx,
    masking: Masking::HeightCorrelated,
};

fn walks(c: &mut Criterion) {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("a pool of one thread");
    let walks = 1u64 << 14;
    let mut group = c.benchmark_group("walk");
    group.throughput(Throughput::Elements(walks));
    for (name, escape, numbers) in [
        ("expected-sobol", Escape::Expected, Numbers::Sobol),
        (
            "expected-pseudorandom",
            Escape::Expected,
            Numbers::Pseudorandom,
        ),
        ("sampled-sobol", Escape::Sampled, Numbers::Sobol),
    ] {
        let settings = WalkSettings {
            walks,
            escape,
            numbers,
            ..WalkSettings::default()
        };
        for alpha in [0.25, 1.0] {
            // Every order with Schlick's F0 as a polynomial: what kiln's compensation bakes.
            group.bench_with_input(
                BenchmarkId::new(format!("schlick-polynomial-{name}"), alpha),
                &alpha,
                |b, &alpha| {
                    b.iter(|| {
                        pool.install(|| {
                            walk_schlick_polynomial(
                                GGX,
                                black_box(alpha),
                                0.5,
                                1.0,
                                &settings,
                                &|_| {},
                            )
                        })
                    })
                },
            );
        }
    }
    let settings = WalkSettings {
        walks,
        ..WalkSettings::default()
    };
    for alpha in [0.25, 1.0] {
        // The first three orders alone (the walk stops after the third vertex).
        group.bench_with_input(
            BenchmarkId::new("orders-1-3", alpha),
            &alpha,
            |b, &alpha| {
                b.iter(|| {
                    pool.install(|| {
                        walk_albedo(
                            GGX,
                            black_box(alpha),
                            0.5,
                            &Fresnel::None,
                            3,
                            &settings,
                            &|_| {},
                        )
                    })
                })
            },
        );
        // The lobe at 8 exits x (5 azimuths + 8 strata): kiln compensation --lobe's default.
        let grid = LobeGrid {
            mus: vec![0.05, 0.1, 0.2, 0.35, 0.5, 0.7, 0.85, 1.0],
            azimuths: (0..5)
                .map(|k| f64::from(k) * std::f64::consts::PI / 4.0)
                .collect(),
            strata: 8,
        };
        group.bench_with_input(BenchmarkId::new("lobe-104", alpha), &alpha, |b, &alpha| {
            b.iter(|| {
                pool.install(|| {
                    walk_lobe(
                        GGX,
                        black_box(alpha),
                        0.5,
                        &grid,
                        &Fresnel::None,
                        &settings,
                        &|_| {},
                    )
                })
            })
        });
    }
    group.finish();
}

criterion_group!(benches, walks);
criterion_main!(benches);
