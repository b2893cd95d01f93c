//! Time to a table: kiln's bake to a max error of 1e-6 and 1e-10 (a 32 x 32 GGX `E` table and its
//! 32-entry `E_avg`), the Cycles-style yardstick on the same machine in the same run (2^16 VNDF
//! Sobol samples per texel, f32 evaluation, [`kiln::study::yardstick`]), and kiln's QMC throughput
//! on all cores.
//!
//! Run with `cargo bench --bench bake`. Before timing, each table's error is measured against the
//! deterministic reference at every node and printed; a kiln table that misses its bound stops
//! the benchmark. Times are wall times of the whole table on every core (rayon).

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use kiln::bake::confirmation_settings;
use kiln::integrate::reference::{ReferenceSettings, reference_albedo};
use kiln::study::yardstick::cycles_style_table;
use kiln::verify::node_errors_at;
use kiln::{BakeOptions, Masking, Model, Ndf, QmcSettings, Quantity, Table, bake_table};
use rayon::prelude::*;
use std::hint::black_box;

/// The `E` and `E_avg` tables `kiln bake --max-error X` produces, without its confirmation step
/// (`f_ms_norm`, which `kiln bake` derives from the `E` table, is left out).
fn bake_to(max_error: f64) -> Vec<Table> {
    let options = BakeOptions {
        max_error: Some(max_error),
        quantities: vec![Quantity::E, Quantity::EAvg],
        ..BakeOptions::default()
    }
    .resolved();
    options
        .specs()
        .into_iter()
        .map(|spec| bake_table(spec, String::new(), &|_| {}))
        .collect()
}

/// Max node error of every texel and every `E_avg` entry against the reference, at the
/// tolerance `kiln bake` confirms with (ten times tighter than the bake's own).
fn full_check(tables: &[Table], max_error: f64) -> f64 {
    tables
        .iter()
        .map(|t| {
            let all: Vec<usize> = (0..t.spec.len()).collect();
            node_errors_at(t, &all, &confirmation_settings(max_error, &t.spec)).max
        })
        .fold(0.0, f64::max)
}

fn kiln_bakes(c: &mut Criterion) {
    let mut group = c.benchmark_group("bake");
    group.sample_size(10);
    for max_error in [1e-6, 1e-10] {
        let measured = full_check(&bake_to(max_error), max_error);
        eprintln!("kiln --max-error {max_error:e}: max node error {measured:.2e} (E and E_avg)");
        assert!(measured <= max_error, "{measured} > {max_error}");
        group.bench_function(format!("kiln max-error {max_error:e}"), |b| {
            b.iter(|| bake_to(black_box(max_error)))
        });
    }
    group.bench_function("kiln max-error 1e-6 with confirmation", |b| {
        b.iter(|| {
            BakeOptions {
                max_error: Some(black_box(1e-6)),
                quantities: vec![Quantity::E, Quantity::EAvg],
                ..BakeOptions::default()
            }
            .bake(&|_| {})
            .unwrap()
        })
    });

    // The yardstick: Cycles' axes (linear, nodes, clamped to 1e-4).
    let size = 32;
    let samples = 1u32 << 16;
    let model = Model {
        ndf: Ndf::Ggx,
        masking: Masking::HeightCorrelated,
    };
    let yardstick = cycles_style_table(size, samples);
    let error = (0..size * size)
        .into_par_iter()
        .map(|k| {
            let (row, column) = (k / size, k % size);
            let r = row as f64 / (size - 1) as f64;
            let alpha = f64::from((r * r).max(1e-4) as f32);
            let mu = f64::from((column as f64 / (size - 1) as f64).max(1e-4) as f32);
            let truth = reference_albedo(model, alpha, mu, &ReferenceSettings::default()).value;
            (yardstick[k] - truth).abs()
        })
        .reduce(|| 0.0, f64::max);
    eprintln!("Cycles-style 2^16 samples per texel, f32: max node error {error:.2e}");
    group.throughput(Throughput::Elements(
        (size * size) as u64 * u64::from(samples),
    ));
    group.bench_function("cycles-style 2^16 f32", |b| {
        b.iter(|| cycles_style_table(black_box(size), samples))
    });

    // kiln's QMC kernel on every core: the same table size and sample count.
    let options = BakeOptions {
        samples: u64::from(samples),
        max_error: None,
        ..BakeOptions::default()
    };
    let spec = options.specs().remove(0);
    assert_eq!(
        spec.qmc,
        QmcSettings {
            samples: u64::from(samples),
            ..QmcSettings::default()
        }
    );
    group.bench_function("kiln qmc 2^16", |b| {
        b.iter(|| bake_table(black_box(spec.clone()), String::new(), &|_| {}))
    });
    group.finish();
}

criterion_group!(benches, kiln_bakes);
criterion_main!(benches);
