//! What a bake costs before it runs: seconds of one core per table (integration and lookup fit),
//! the samples its progress counts, and the lookup fit's evaluations and memory.

use super::*;

impl BakeOptions {
    /// The estimated cost of the bake in seconds of one core ([`estimated_core_seconds`] of
    /// each table it makes).
    #[must_use]
    pub fn estimated_core_seconds(&self) -> f64 {
        self.resolved()
            .specs()
            .iter()
            .map(estimated_core_seconds)
            .sum()
    }

    /// The work [`BakeOptions::bake`] will report to its progress callback, for a progress
    /// bar: each texel's integrand samples ([`BakeOptions::integration_samples`]), and for
    /// fitted texels each reference evaluation of the fit counted as one texel's samples.
    #[must_use]
    pub fn total_samples(&self) -> u64 {
        self.resolved()
            .specs()
            .iter()
            .map(|s| (integrated_texels(s) + lookup_fit_evaluations(s)) * s.qmc.samples)
            .sum()
    }

    /// The integrand samples of the texels alone (what a shard reports: the lookup fit runs
    /// where the shards are merged).
    #[must_use]
    pub fn integration_samples(&self) -> u64 {
        self.resolved()
            .specs()
            .iter()
            .map(|s| integrated_texels(s) * s.qmc.samples)
            .sum()
    }
}

/// The texels of `spec` that a bake integrates (none of `f_ms_norm`, derived from a lookup).
pub(super) fn integrated_texels(spec: &TableSpec) -> u64 {
    if spec.quantity == Quantity::FMsNorm {
        0
    } else {
        spec.len() as u64
    }
}

/// The settings of [`fit_texels`] for a table of `spec`.
pub(super) fn lookup_fit_settings(spec: &TableSpec) -> crate::table::lookup_fit::LookupFitSettings {
    if spec.ior.is_some() {
        return crate::table::lookup_fit::LookupFitSettings::over_ior();
    }
    let cells = spec.shape().into_iter().max().unwrap_or(1);
    crate::table::lookup_fit::LookupFitSettings::for_cells(cells)
}

/// The reference evaluations [`fit_texels`] makes for a table of `spec`: 0 for point samples.
/// Counted, not built.
#[must_use]
pub fn lookup_fit_evaluations(spec: &TableSpec) -> u64 {
    if spec.texels != Texels::LookupFit {
        return 0;
    }
    crate::table::lookup_fit::planned_evaluations(
        spec,
        &lookup_fit_settings(spec),
        audit_count(spec),
    ) as u64
}

/// `kiln verify`'s default audit points for `spec`, which a lookup fit adds to its own.
pub(super) fn audit_count(spec: &TableSpec) -> usize {
    let audit =
        crate::verify::lookup_coordinate_count(spec, &crate::verify::AuditSettings::default());
    usize::try_from(audit).unwrap_or(usize::MAX)
}

/// The memory [`fit_texels`] holds for a table of `spec`, in bytes: 0 for point samples
/// ([`crate::table::lookup_fit::memory_bytes`]).
#[must_use]
pub fn lookup_fit_bytes(spec: &TableSpec) -> u64 {
    if spec.texels != Texels::LookupFit {
        return 0;
    }
    crate::table::lookup_fit::memory_bytes(spec, &lookup_fit_settings(spec), audit_count(spec))
}

/// The estimated cost of baking `spec`, in seconds of one core (divide by the threads): for
/// `kiln plan` and for `kiln bake` to say how long it will take before it starts.
///
/// Per texel, measured as whole-process wall time of `kiln bake --quantity Q` on a 2-core AMD
/// EPYC (AVX2), times 2, at the default max error 1e-7 (32 x 32 tables, the dielectric ones
/// 16 x 16 x 16 and 16 x 16; numerics version 8, one run each, 2026-12-02), given here for 8
/// digits: GGX `E` 0.3 ms, Beckmann `E` 0.6 ms, GGX `E_avg` 4 ms, Beckmann `E_avg` 25 ms, the
/// split-sum and Fresnel-weighted channels 0.15 ms, dielectric `E` 1.1 ms (outside) and 3.2 ms
/// (inside), their averages 37 ms and 49 ms, `F_avg` nothing to speak of.
/// The quadrature's cost grows about linearly with the digits asked for, so the figure is
/// scaled by `digits / 8`. QMC costs its samples at the measured kernel rates (GGX 75 M/s per
/// core for `E`, 50 M/s for `E_avg`; Beckmann 3.5 and 1.7 M/s; 20 M/s for the rest). An
/// estimate to within a factor of two or three: enough to tell seconds from minutes.
#[must_use]
pub fn estimated_core_seconds(spec: &TableSpec) -> f64 {
    integration_core_seconds(spec) + lookup_fit_core_seconds(spec)
}

/// The cost of a lookup fit ([`fit_texels`]; 0 for point samples), in seconds of one core: its
/// reference evaluations at the fit's tolerance ([`crate::table::lookup_fit::LookupFitSettings`]),
/// each at 0.45 of a texel's figure of
/// [`crate::integrate::cost::reference_seconds`] (the fit's points are between the texels, where the
/// integrands are tamer; measured on 32 x 32 and 64 x 64 `E` bakes, 3.4 s and 5.3 s whole
/// process on 2 cores, 2026-12-04; a glass albedo's at 1.3 of it: the two 32 x 32 tables at
/// one IOR, 1.5, fitted in 15.6 s of a 17.7 s bake on 2 cores, 2026-12-08, where the figure at
/// 0.45 said 6.4 s), and its Lawson iterations, each a banded Cholesky solve of
/// about `texels x (band + 1)^2` multiply-adds at 1.2 ns (fitted to a 128 x 128 bake, 26 s).
#[must_use]
pub fn lookup_fit_core_seconds(spec: &TableSpec) -> f64 {
    let evaluations = lookup_fit_evaluations(spec);
    if evaluations == 0 {
        return 0.0;
    }
    let band = crate::table::lookup_fit::band(spec) as f64;
    let settings = lookup_fit_settings(spec);
    let solve = settings.iterations as f64 * spec.len() as f64 * band * band * 1.2e-9;
    let digits = (-settings.tolerance.log10()).round().max(1.0) as u32;
    let share = if spec.quantity.is_dielectric() {
        1.3
    } else {
        0.45
    };
    share
        * evaluations as f64
        * crate::integrate::cost::reference_seconds(spec.quantity, spec.model, digits)
        + solve
}

/// [`estimated_core_seconds`] of the texels' integration alone.
fn integration_core_seconds(spec: &TableSpec) -> f64 {
    let texels = spec.len() as f64;
    match spec.method {
        Method::Qmc => {
            texels
                * crate::integrate::cost::qmc_seconds_per_point(
                    spec.quantity,
                    spec.model,
                    spec.qmc.samples,
                )
        }
        Method::Reference => {
            let digits = spec.reference_digits.unwrap_or(10);
            texels * crate::integrate::cost::reference_seconds(spec.quantity, spec.model, digits)
        }
    }
}
