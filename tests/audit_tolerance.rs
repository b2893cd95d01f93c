//! The audit measures each group of points at a reference tolerance tied to the errors it
//! reports (issue 19): its figures must be those of a fixed fine reference, whatever tolerance
//! it settled at, and the tolerance it states must be the one the figures call for.

use kiln::integrate::reference::{ReferenceSettings, reference_albedo};
use kiln::verify::{
    Against, AuditSettings, REFERENCE_FRACTION, SCOUT_TOLERANCE, audit, lookup_coordinates,
};
use kiln::{BakeOptions, Quantity, Table};

/// An 8 x 8 `E` table whose nodes are the reference at 1e-13 moved by a known pattern of
/// errors around `size`, so that its node errors are known independently of the audit.
fn table_with_node_errors(size: f64) -> (Table, Vec<f64>) {
    let mut table = BakeOptions {
        quantities: vec![Quantity::E],
        size: 8,
        max_error: Some(1e-4),
        ..BakeOptions::default()
    }
    .bake(&|_| {})
    .unwrap()
    .remove(0);
    let fine = ReferenceSettings {
        tolerance: 1e-13,
        ..ReferenceSettings::default()
    };
    let mut errors = Vec::new();
    for k in 0..table.spec.len() {
        let (alpha, mu) = table.spec.texel_coordinates(k);
        let truth = reference_albedo(table.spec.model, alpha, mu.unwrap(), &fine).value;
        // Signs and sizes that vary from texel to texel, between 0.5 and 1.5 times `size`.
        let error = size * (0.5 + ((k * 37) % 11) as f64 / 10.0);
        let signed = if k % 3 == 0 { -error } else { error };
        table.value[k] = truth + signed;
        table.one_minus_value[k] = 1.0 - table.value[k];
        errors.push(error);
    }
    (table, errors)
}

fn rms(errors: &[f64]) -> f64 {
    (errors.iter().map(|e| e * e).sum::<f64>() / errors.len() as f64).sqrt()
}

/// Node errors of 1e-8: a scout at 1e-6 alone would blur them (its reference is only good to
/// ~1e-8), so the audit must refine, and its node figures must be those known by construction.
#[test]
fn small_node_errors_are_measured_at_a_tolerance_fine_enough_for_them() {
    let (table, errors) = table_with_node_errors(1e-8);
    let report = audit(
        &table,
        &Against::Reference(ReferenceSettings::default()),
        &AuditSettings::default(),
        &|_| {},
    );
    let (max, rms) = (errors.iter().copied().fold(0.0, f64::max), rms(&errors));
    assert!(
        (report.node_max_error - max).abs() < 1e-3 * max,
        "{} vs {max}",
        report.node_max_error
    );
    assert!(
        (report.node_rms_error - rms).abs() < 1e-3 * rms,
        "{} vs {rms}",
        report.node_rms_error
    );
    // The tolerance the figures call for, within a factor of two, and stated.
    let called_for = REFERENCE_FRACTION * rms;
    let t = report.node_reference_tolerance;
    assert!(t <= 2.0 * called_for && t >= 0.5 * called_for, "{t:e}");
}

/// Lookups with bilinear errors ~1e-4: the audit measures them at the tolerance their figures
/// call for, coarser than its scout's, and its lookup figures agree with a fixed reference at
/// 1e-11 over the same points.
#[test]
fn large_lookup_errors_are_measured_coarsely_and_still_right() {
    let (table, _) = table_with_node_errors(1e-9);
    let settings = AuditSettings::default();
    let report = audit(
        &table,
        &Against::Reference(ReferenceSettings::default()),
        &settings,
        &|_| {},
    );
    let smallest = report
        .lookup_max_error
        .min(report.lookup_rms_error)
        .min(report.lookup_p99_error);
    let (t, called_for) = (
        report.lookup_reference_tolerance,
        REFERENCE_FRACTION * smallest,
    );
    assert!(t > SCOUT_TOLERANCE, "{t:e}");
    assert!(t <= 2.0 * called_for && t >= 0.5 * called_for, "{t:e}");
    let fine = ReferenceSettings::default();
    let convention = table.spec.roughness_convention();
    let errors: Vec<f64> = lookup_coordinates(&table.spec, &settings)
        .iter()
        .map(|at| {
            let mu = at.mu.unwrap();
            let truth = reference_albedo(table.spec.model, at.alpha, mu, &fine).value;
            (table.lookup(mu, convention.from_alpha(at.alpha)) - truth).abs()
        })
        .collect();
    let (max, rms) = (errors.iter().copied().fold(0.0, f64::max), rms(&errors));
    assert!(max > 1e-4, "{max}");
    assert!(
        (report.lookup_max_error - max).abs() < 1e-4 * max,
        "{} vs {max}",
        report.lookup_max_error
    );
    assert!(
        (report.lookup_rms_error - rms).abs() < 1e-4 * rms,
        "{} vs {rms}",
        report.lookup_rms_error
    );
}
