//! Stated errors that cannot be fooled (issue 18): a NaN is never a zero error, a quadrature
//! that ran out of budget is never stored as if it had converged, and a computed table that is
//! not finite is never written.

use kiln::verify::{Against, AuditSettings, audit, node_errors_at};
use kiln::{BakeOptions, Quantity, Table};

fn small_e_table() -> Table {
    BakeOptions {
        quantities: vec![Quantity::E],
        size: 4,
        max_error: Some(1e-4),
        // Point samples, exact to the bound at every node.
        texels: Some(kiln::table::Texels::Nodes),
        ..BakeOptions::default()
    }
    .bake(&|_| {})
    .unwrap()
    .remove(0)
}

/// `fold(0.0, f64::max)` turned a NaN texel into a node error of 0 that passed the bake's own
/// check; every maximum is now NaN when a texel is.
#[test]
fn a_nan_texel_is_never_a_zero_error() {
    let mut table = small_e_table();
    let indices: Vec<usize> = (0..table.spec.len()).collect();
    let settings = kiln::integrate::reference::ReferenceSettings::default();
    let clean = node_errors_at(&table, &indices, &settings);
    assert!(clean.max.is_finite() && clean.max < 1e-4);
    table.value[5] = f64::NAN;
    table.one_minus_value[5] = f64::NAN;
    table.std_error[6] = f64::NAN;
    let errors = node_errors_at(&table, &indices, &settings);
    assert!(errors.max.is_nan(), "node error {errors:?}");
    assert!(table.max_std_error().is_nan());
    // verify's audit reports NaN (and so fails any --max-error), nodes and lookups alike.
    let report = audit(
        &table,
        &Against::Reference(settings),
        &AuditSettings::default(),
        &|_| {},
    );
    assert!(report.node_max_error.is_nan() && report.lookup_max_error.is_nan());
    // And the bake's check refuses the table before anything is written.
    let message = table.check_computed().unwrap_err().to_string();
    assert!(
        message.contains("texel 5") && message.contains("NaN"),
        "{message}"
    );
}

/// A reference quadrature that ran out of its interval budget was stored with its error
/// estimate as if it had converged; [`estimate_texel`] now marks it with an infinite error (no
/// bound), and the bake refuses such a table by name. (kiln's quadratures converge on every
/// table it offers, even asked for 16 digits, so the mark is set by hand here.)
#[test]
fn an_unconverged_texel_is_refused_by_name() {
    let mut table = small_e_table();
    table.std_error[7] = f64::INFINITY;
    let message = table.check_computed().unwrap_err().to_string();
    assert!(
        message.contains("did not converge") && message.contains("texel 7"),
        "{message}"
    );
    table.std_error[7] = -1e-9;
    assert!(table.check_computed().is_err());
}

/// The confirmation's reference can run out of budget too: its error is then the difference
/// plus the reference's own estimate, and the count is recorded.
#[test]
fn an_unconverged_confirmation_widens_the_node_error() {
    let table = small_e_table();
    let indices: Vec<usize> = (0..table.spec.len()).collect();
    let starved = kiln::integrate::reference::ReferenceSettings {
        tolerance: 1e-15,
        max_intervals: 2,
    };
    let errors = node_errors_at(&table, &indices, &starved);
    assert!(errors.unconverged > 0, "{errors:?}");
    let full = node_errors_at(
        &table,
        &indices,
        &kiln::integrate::reference::ReferenceSettings::default(),
    );
    assert_eq!(full.unconverged, 0);
    assert!(errors.max >= full.max, "{errors:?} vs {full:?}");
}
