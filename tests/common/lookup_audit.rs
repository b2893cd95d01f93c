//! A table's lookup error as `kiln verify` measures it.

/// The largest error of `table`'s bilinear lookup against the deterministic reference at the
/// audit's points (`kiln::verify::lookup_coordinates`, mu = 0 and the grazing probes included).
pub fn lookup_max_error(table: &kiln::Table) -> f64 {
    kiln::verify::audit(
        table,
        &kiln::verify::Against::Reference(kiln::integrate::reference::ReferenceSettings::default()),
        &kiln::verify::AuditSettings::default(),
        &|_| {},
    )
    .lookup_max_error
}
