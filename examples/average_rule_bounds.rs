//! Rechecks the measured bounds of the fixed `E_avg` rules
//! (`kiln::integrate::average_quadrature::RULE_BOUNDS`) on a finer roughness ladder than they
//! were measured on: every rule against the composite adaptive rule at tolerance 1e-12, both
//! distributions, both Smith forms, `r` from 0.005 to 1 in steps of 0.005, three rungs below,
//! and every 1/1200 from 0.33 to 0.38 (around `alpha = 1/8`, where the tail part starts and the
//! worst cases sit). Prints, per distribution and order, the largest error as a fraction of the
//! bound and where it was. About ten minutes on 2 cores.
//!
//! Usage: `cargo run --release --example average_rule_bounds`
use kiln::integrate::average_quadrature::{
    RULE_BOUNDS, quadrature_average_albedo, rule_average_albedo,
};
use kiln::integrate::reference::ReferenceSettings;
use kiln::{Masking, Model, Ndf};
use rayon::prelude::*;

fn main() {
    let settings = ReferenceSettings {
        tolerance: 1e-12,
        ..ReferenceSettings::default()
    };
    let mut rungs: Vec<f64> = (1..=200).map(|j| f64::from(j) / 200.0).collect();
    rungs.extend((0..=60).map(|j| 0.33 + 0.05 * f64::from(j) / 60.0));
    rungs.extend([0.01, 0.02, 0.03]);
    let mut cases = Vec::new();
    for ndf in Ndf::ALL {
        for masking in [Masking::HeightCorrelated, Masking::Separable] {
            for &r in &rungs {
                cases.push((Model { ndf, masking }, r));
            }
        }
    }
    // (fraction of the bound, ndf, order, masking, r) for every rule at every case.
    let fractions: Vec<(f64, Ndf, usize, Masking, f64)> = cases
        .par_iter()
        .flat_map_iter(|&(model, r)| {
            let alpha = r * r;
            let exact = quadrature_average_albedo(model, alpha, &settings);
            RULE_BOUNDS
                .iter()
                .filter(move |&&(ndf, _, _)| ndf == model.ndf)
                .map(move |&(ndf, order, bound)| {
                    let rule = rule_average_albedo(model, alpha, order, &settings);
                    let error = (rule.one_minus_value - exact.one_minus_value).abs();
                    (error / bound, ndf, order, model.masking, r)
                })
        })
        .collect();
    println!(
        "{} roughness cases, every rule against the composite rule at 1e-12",
        cases.len()
    );
    for &(ndf, order, bound) in &RULE_BOUNDS {
        let worst = fractions
            .iter()
            .filter(|f| f.1 == ndf && f.2 == order)
            .max_by(|a, b| a.0.total_cmp(&b.0))
            .expect("every rule was run");
        println!(
            "{ndf} order {order:2} bound {bound:.1e}: worst {:.3} of it ({}, r = {:.5})",
            worst.0, worst.3, worst.4
        );
    }
}
