//! kiln's split-sum `mu` axis (`--mu-axis split-sum`, the default for `e-scale`, `e-bias` and
//! `e-f`; issue 39): the adaptive axis' grazing layer blended with a fixed warp that keeps
//! texels for `Fc(mu)` on the mirror row. Against the deterministic reference, its bilinear
//! lookup of the 32 x 32 split-sum channels is more than twice as close as the linear axis'
//! (the engines' layout), with point samples and with fitted texels, and its generated Rust
//! lookup, compiled by rustc and run in f32 at points no audit uses, computes the same
//! coordinates as the library.

use kiln::format::replace::Replace;
use kiln::format::{Format, Precision, write_tables};
use kiln::integrate::reference::ReferenceSettings;
use kiln::integrate::value::Point;
use kiln::table::{Quantity, Table, Texels};
use kiln::{BakeOptions, MuMapping};
use rayon::prelude::*;

use crate::lookup_audit;
use crate::rng;
use crate::rustc;

/// The 32 x 32 `E_scale` and `E_bias` tables on `mu_mapping`.
fn bake(mu_mapping: MuMapping, texels: Texels) -> Vec<Table> {
    BakeOptions {
        quantities: vec![Quantity::EScale, Quantity::EBias],
        mu_mapping: Some(mu_mapping),
        texels: Some(texels),
        ..BakeOptions::default()
    }
    .bake(&|_| {})
    .unwrap()
}

/// The lookup's largest error at the audit's points (mu = 0 and the grazing probes included),
/// measured 2026-12-05 at `--density 4`: point samples `E_scale` 6.6e-3 and `E_bias` 8.3e-3 on
/// the split-sum axis against 4.5e-2 and 1.0e-1 on the linear one; fitted 4.4e-3 and 5.6e-3.
#[test]
fn the_split_sum_axis_more_than_halves_the_lookup_error() {
    let linear = bake(MuMapping::Linear, Texels::Nodes);
    for texels in [Texels::Nodes, Texels::LookupFit] {
        let split_sum = bake(MuMapping::SplitSum, texels);
        for (ours, theirs) in split_sum.iter().zip(&linear) {
            let (ours_error, theirs_error) = (
                lookup_audit::lookup_max_error(ours),
                lookup_audit::lookup_max_error(theirs),
            );
            eprintln!(
                "{} ({texels:?}): split-sum {ours_error:.3e}, linear nodes {theirs_error:.3e}",
                ours.spec.id()
            );
            assert!(
                ours_error <= 0.5 * theirs_error && ours_error <= 1e-2,
                "{}: split-sum {ours_error:.3e} against linear {theirs_error:.3e}",
                ours.spec.id()
            );
        }
    }
}

/// The generated Rust lookups of the split-sum tables, compiled by rustc and run in f32 at 1600
/// pseudo-random points (`mu` half log-uniform down to 1e-6) and the edges, give the library's
/// lookup within 2e-5, and the truth within 1e-2.
#[test]
fn the_generated_lookup_computes_the_split_sum_coordinates() {
    let tables = bake(MuMapping::SplitSum, Texels::Nodes);
    let dir = tempfile::tempdir().unwrap();
    write_tables(
        dir.path(),
        &tables,
        &[Format::Rs],
        Precision::F32,
        Replace::Refuse,
    )
    .unwrap();
    let mut rng = rng::Rng(0x2545_f491_4f6c_dd1d);
    let mut next = || (rng.next() >> 11) as f64 / (1u64 << 53) as f64;
    let mut points: Vec<(f64, f64)> = (0..1600)
        .map(|k| {
            let (r, u) = (next(), next());
            (if k % 2 == 0 { u } else { 1e-6 * 1e6f64.powf(u) }, r)
        })
        .collect();
    for a in 0..=10 {
        let x = f64::from(a) / 10.0;
        points.extend([(0.0, x), (1.0, x), (x, 0.0), (x, 1.0)]);
    }
    for table in &tables {
        assert!(matches!(
            table.spec.mu,
            Some(kiln::Axis::Mu {
                mapping: MuMapping::SplitSum,
                ..
            })
        ));
        let generated = rustc::generated_lookups(dir.path(), table, &points);
        let integral = table.spec.integral();
        let settings = ReferenceSettings {
            tolerance: 1e-8,
            ..ReferenceSettings::default()
        };
        let worst = points
            .par_iter()
            .zip(&generated)
            .map(|(&(mu, r), &generated)| {
                // The inputs as the f32 lookup saw them.
                let (mu, r) = (f64::from(mu as f32), f64::from(r as f32));
                let library = table.lookup(mu, r);
                assert!(
                    (generated - library).abs() < 2e-5,
                    "{} at mu {mu}, r {r}: generated {generated}, library {library}",
                    table.spec.id()
                );
                let at = Point {
                    alpha: r * r,
                    mu: Some(mu),
                    eta: None,
                };
                (generated - integral.reference(at, &settings).value).abs()
            })
            .reduce(|| 0.0, f64::max);
        eprintln!("{}: largest error {worst:.3e}", table.spec.id());
        assert!(worst <= 1e-2, "{}: {worst:.3e}", table.spec.id());
    }
}
