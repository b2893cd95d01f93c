//! The confirmation of a baked table: finite values, the node error measured against the
//! reference at a sample of texels ([`confirmation_sample`]) and a table that misses its
//! `--max-error` refused; the same steps for a table merged from shards.

use super::*;

impl BakeOptions {
    /// Finishes a table whose texels were all integrated (in one process, or merged from
    /// shards, [`crate::shard`]): checks every value is finite, records the requested max
    /// error, measures the node error against the reference as the options ask (`options` is
    /// [`BakeOptions::resolved`]) and refuses a table that misses its bound. The same steps
    /// whatever computed the texels, so a merged bake is byte-identical to an unsharded one.
    ///
    /// # Errors
    /// A non-finite texel, a NaN check or a measured error beyond `--max-error`.
    pub fn confirm(
        &self,
        options: &BakeOptions,
        table: Table,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<Table> {
        let terms = self
            .check_plan(options, &table.spec)
            .map(|(indices, settings)| {
                crate::verify::node_error_terms(
                    &table.spec,
                    &indices,
                    &|k| (table.value[k], table.one_minus_value[k]),
                    &settings,
                )
            });
        self.confirm_with(table, terms.as_deref(), progress)
    }

    /// The check against the reference a table gets ([`BakeOptions::confirm`]): the texels and
    /// the reference settings, or `None` for none. `options` is [`BakeOptions::resolved`].
    #[must_use]
    pub fn check_plan(
        &self,
        options: &BakeOptions,
        spec: &TableSpec,
    ) -> Option<(Vec<usize>, ReferenceSettings)> {
        if let Some(bound) = self.max_error {
            Some((
                confirmation_sample(spec),
                confirmation_settings(bound, spec),
            ))
        } else if options.check_against_reference && options.method == Method::Qmc {
            Some((
                crate::verify::node_error_indices(spec),
                ReferenceSettings::default(),
            ))
        } else {
            None
        }
    }

    /// [`BakeOptions::confirm`] with the check's terms already measured
    /// ([`crate::verify::node_error_terms`] at [`BakeOptions::check_plan`]'s texels, in order):
    /// a sharded bake measures them where the texels were computed.
    ///
    /// # Errors
    /// As [`BakeOptions::confirm`].
    pub fn confirm_with(
        &self,
        mut table: Table,
        terms: Option<&[(f64, bool)]>,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<Table> {
        table.check_computed()?;
        table.requested_max_error = self.max_error;
        table.node_errors = terms.map(crate::verify::summarise_node_errors);
        if let Some(measured) = table.node_errors
            && measured.max.is_nan()
        {
            return Err(Error::InvalidInput(format!(
                "{}: the check against the reference gave no number (NaN) at one of its {} \
                 texels; nothing was written: please report it",
                table.spec.id(),
                measured.texels
            )));
        }
        if let (Some(bound), Some(measured)) = (self.max_error, table.node_errors)
            && measured.max > bound
        {
            return Err(Error::InvalidInput(format!(
                "{}: the measured node error {:.2e} exceeds --max-error {bound:e}; kiln's \
                 choice ({}) fell short: please report it, and use --method reference",
                table.spec.id(),
                measured.max,
                table.spec.method.describe()
            )));
        }
        if table.spec.texels == Texels::LookupFit {
            fit_texels(&mut table, progress);
            // The fit moved every texel by what the reference said at its points: the same
            // checks again, so that a value the fit could not make (not a number) is refused
            // by name before anything is written.
            table.check_computed()?;
        }
        Ok(table)
    }
}

/// The texels a bake at a requested max error checks against the reference: for `E`, the first
/// and last column of every row (grazing `mu = 0` and normal incidence, where the quadrature
/// works hardest) and a diagonal lattice, every texel with `(row + column) % 8 == 0`, in between
/// (about a sixth of a 32 x 32 table); for `E_avg`, five entries evenly spread, ends included.
#[must_use]
pub fn confirmation_sample(spec: &TableSpec) -> Vec<usize> {
    match spec.mu {
        Some(mu) => {
            let columns = mu.size();
            (0..spec.len())
                .filter(|&k| {
                    let (row, column) = (k / columns, k % columns);
                    column == 0 || column + 1 == columns || (row + column) % 8 == 0
                })
                .collect()
        }
        None => spread_indices(spec.len(), MAX_AVERAGE_ENTRIES_CHECKED),
    }
}

/// The reference a bake at `max_error` confirms `spec` against: tolerance `max_error / 100`
/// (so the check's own error is negligible), and for a quadrature-baked table also ten times
/// tighter than the bake's own tolerance, so the check never repeats the bake's computation.
#[must_use]
pub fn confirmation_settings(max_error: f64, spec: &TableSpec) -> ReferenceSettings {
    let mut tolerance = max_error / 100.0;
    if spec.method == Method::Reference {
        tolerance = tolerance.min(spec.reference_settings().tolerance / 10.0);
    }
    ReferenceSettings {
        tolerance,
        ..ReferenceSettings::default()
    }
}
