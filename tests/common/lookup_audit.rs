//! A table's lookup error as `kiln verify` measures it.

/// The largest error of `table`'s bilinear lookup against the deterministic reference at the
/// audit's points (`kiln::verify::lookup_coordinates`, mu = 0 and the grazing probes included).
pub fn lookup_max_error(table: &kiln::Table) -> f64 {
    lookup_max_error_to(
        table,
        kiln::integrate::reference::ReferenceSettings::default().tolerance,
    )
}

/// [`lookup_max_error`] with the reference at `tolerance`.
pub fn lookup_max_error_to(table: &kiln::Table, tolerance: f64) -> f64 {
    let settings = kiln::integrate::reference::ReferenceSettings {
        tolerance,
        ..kiln::integrate::reference::ReferenceSettings::default()
    };
    kiln::verify::audit(
        table,
        &kiln::verify::Against::Reference(settings),
        &kiln::verify::AuditSettings::default(),
        &|_| {},
    )
    .lookup_max_error
}
