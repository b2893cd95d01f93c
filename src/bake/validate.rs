//! The checks of a bake's options: each value in its range, and the whole bake (its tables'
//! texels, memory and time) within kiln's bounds, before anything is allocated.

use super::*;

impl BakeOptions {
    /// Checks every option, naming the bad value and the allowed range.
    pub fn validate(&self) -> Result<()> {
        if !(2..=Self::MAX_SIZE).contains(&self.size) {
            return Err(Error::InvalidInput(format!(
                "size must be between 2 and {} (got {})",
                Self::MAX_SIZE,
                self.size
            )));
        }
        if !(2..=Self::MAX_SIZE).contains(&self.ior_size) {
            return Err(Error::InvalidInput(format!(
                "ior-size must be between 2 and {} (got {})",
                Self::MAX_SIZE,
                self.ior_size
            )));
        }
        if !(self.ior_max > 1.0 && self.ior_max <= MAX_IOR) {
            return Err(Error::InvalidInput(format!(
                "ior-max must be above 1 and at most 100 (got {}): the IOR axis runs over \
                 [1, ior-max], and inside tables use 1 / eta",
                crate::error::shown(self.ior_max)
            )));
        }
        if let Some(q) = self.quantities().into_iter().find(|&q| {
            self.over_ior(q) && self.roughness_spacing_for(q) == RoughnessSpacing::Balanced
        }) {
            return Err(Error::InvalidInput(format!(
                "--roughness-spacing balanced (the default with --mu-axis balanced) lays out the \
                 tables over roughness and mu; {} is over the IOR too, whose rows stay linear: \
                 bake it in a separate command, or give --roughness-spacing linear",
                q.symbol()
            )));
        }
        if !self.transmission.is_default() && !self.quantities().iter().any(|q| q.is_glass_albedo())
        {
            return Err(Error::InvalidInput(format!(
                "transmission {} applies to the dielectric tables only (e-dielectric, \
                 e-dielectric-inside, e-avg-dielectric, e-avg-dielectric-inside): add one with \
                 --quantity, or drop --transmission",
                self.transmission.name()
            )));
        }
        if let Some(x) = self.max_error
            && !(Self::MIN_MAX_ERROR..=0.5).contains(&x)
        {
            return Err(Error::InvalidInput(format!(
                "max-error must be between {:e} and 0.5 (got {})",
                Self::MIN_MAX_ERROR,
                crate::error::shown(x)
            )));
        }
        if self.ior_mapping == IorMapping::Glass
            && let Some(q) = self.quantities.iter().find(|&&q| {
                self.over_ior(q)
                    && q.is_glass_albedo()
                    && q.has_mu()
                    && self.mu_mapping_for(q) != MuMapping::Adaptive
            })
        {
            let mapping = self.mu_mapping_for(*q);
            return Err(Error::InvalidInput(format!(
                "--quantity {} with --mu-axis {}: kiln's glass layout (--ior-axis glass, the \
                 default) lays out mu itself, tied to roughness and the IOR; for a {} mu axis \
                 use the product grid, --ior-axis cycles or linear",
                q.cli_name(),
                mapping.name(),
                mapping.name()
            )));
        }
        if let Some(q) = self
            .quantities
            .iter()
            .find(|&&q| q.varies_on_a_mirror() && !self.mu_mapping_for(q).resolves_mu_on_a_mirror())
        {
            return Err(Error::InvalidInput(format!(
                "--quantity {} needs --mu-axis split-sum (kiln's layout for it), linear or sqrt: \
                 the {} mu axis follows E's grazing layer and maps every mu > 0 to t = 1 at \
                 roughness 0, where {} still varies with mu",
                q.cli_name(),
                self.mu_mapping_for(*q).name(),
                if *q == Quantity::EF {
                    "E_F = F(mu)"
                } else {
                    "a split-sum channel, Fc(mu) = (1 - mu)^5 or 1 - Fc(mu),"
                }
            )));
        }
        let one_ior = self.quantities.iter().find_map(|&q| self.fixed_ior_for(q));
        if let Some(ior) = one_ior {
            crate::table::check::check_fixed_ior(ior)?;
        }
        match (self.quantities.contains(&Quantity::EF), self.fresnel) {
            (true, None) => {
                return Err(Error::InvalidInput(
                    "--quantity e-f needs a Fresnel model: --fresnel with its parameters, e.g. \
                     --f0 0.04 or --ior 1.5"
                        .into(),
                ));
            }
            (true, Some(fresnel)) if !fresnel.is_grey() => {
                return Err(Error::InvalidInput(
                    "--quantity e-f bakes one channel: give one value per parameter (a coloured \
                     model differs per channel; bake one table per channel with that channel's \
                     values)"
                        .into(),
                ));
            }
            (false, Some(_)) if one_ior.is_some() => {}
            (false, Some(_)) => {
                return Err(Error::InvalidInput(
                    "a Fresnel model applies to the Fresnel-weighted table (add --quantity e-f) \
                     and, as --ior, to the glass tables at one IOR (--quantity e-dielectric and \
                     the others); the other tables are for F = 1"
                        .into(),
                ));
            }
            (true, Some(fresnel)) => fresnel.validate()?,
            (false, None) => {}
        }
        for model in self.models() {
            model.validate()?;
        }
        if self.quantities.contains(&Quantity::FMsNorm) && !self.quantities.contains(&Quantity::E) {
            return Err(Error::InvalidInput(
                "--quantity f-ms-norm is derived from the E table's lookup: bake e with it \
                 (--quantity e,f-ms-norm)"
                    .into(),
            ));
        }
        if self.ndfs.is_empty() || self.maskings.is_empty() || self.quantities.is_empty() {
            return Err(Error::InvalidInput(
                "name at least one ndf, one masking and one quantity".into(),
            ));
        }
        for (flag, samples) in [
            ("--samples", self.samples),
            ("--avg-samples", self.average_samples),
        ] {
            QmcSettings {
                samples,
                scrambles: self.scrambles,
                seed: self.seed,
            }
            .validate_as(flag)?;
        }
        self.check_bounds()
    }

    /// The most memory a bake may hold, in bytes: its tables' channels (three f64 a texel) and
    /// the estimates of the largest table while it is integrated.
    pub const MAX_BAKE_BYTES: u64 = 8 << 30;

    /// The longest bake kiln starts, in estimated seconds of one core
    /// ([`BakeOptions::estimated_core_seconds`]; about 116 core-days, a week on 16 cores):
    /// a plan beyond it is almost always a typo in a size or a sample count. Shard it, or ask
    /// for fewer texels or digits.
    pub const MAX_CORE_SECONDS: f64 = 1e7;

    /// Checks the product of the axes, not only each axis: every table within
    /// [`crate::table::MAX_TEXELS`] (what every reader accepts), the whole bake within
    /// [`BakeOptions::MAX_BAKE_BYTES`] of memory and [`BakeOptions::MAX_CORE_SECONDS`] of
    /// estimated time, before anything is allocated. Sharded bakes and merges run it too.
    fn check_bounds(&self) -> Result<()> {
        let specs = self.resolved().specs();
        let shape = |spec: &TableSpec| {
            spec.shape()
                .iter()
                .map(ToString::to_string)
                .collect::<Vec<_>>()
                .join(" x ")
        };
        let mut stored: u64 = 0;
        let mut largest: u64 = 0;
        let mut largest_fit: u64 = 0;
        for spec in &specs {
            let texels = spec
                .shape()
                .iter()
                .fold(1_u64, |n, &s| n.saturating_mul(s as u64));
            if texels > crate::table::MAX_TEXELS as u64 {
                return Err(Error::InvalidInput(format!(
                    "{}: {} = {texels} texels, more than the {} (2^26) a table may hold (every \
                     reader refuses more); nothing was written: lower the size{}",
                    spec.id(),
                    shape(spec),
                    crate::table::MAX_TEXELS,
                    if spec.ior.is_some() {
                        " or the ior-size"
                    } else {
                        ""
                    }
                )));
            }
            stored = stored.saturating_add(texels.saturating_mul(24));
            largest = largest.max(texels);
            let fit = lookup_fit_bytes(spec);
            if fit > Self::MAX_BAKE_BYTES {
                return Err(Error::InvalidInput(format!(
                    "{}: fitting the {} table's texels for its lookup (--texels lookup-fit) \
                     would hold {:.1} GiB (its normal equations: {texels} texels by a band of \
                     {}), more than the {} GiB kiln allows a bake; nothing was written: bake \
                     point samples (--texels points) at this size, or fit a smaller table",
                    spec.id(),
                    shape(spec),
                    fit as f64 / f64::from(1 << 30),
                    crate::table::lookup_fit::band(spec) + 1,
                    Self::MAX_BAKE_BYTES >> 30
                )));
            }
            largest_fit = largest_fit.max(fit);
        }
        let estimate = std::mem::size_of::<Estimate>() as u64;
        // The fit runs after the integration, table by table: its memory beside the tables.
        let bytes = stored
            .saturating_add(largest.saturating_mul(estimate))
            .max(stored.saturating_add(largest_fit));
        if bytes > Self::MAX_BAKE_BYTES {
            return Err(Error::InvalidInput(format!(
                "the bake's {} tables ({}) would hold {:.1} GiB, more than the {} GiB kiln \
                 allows a bake; nothing was written: bake fewer quantities or models at once, \
                 or lower the size",
                specs.len(),
                specs
                    .iter()
                    .map(|s| format!("{} {}", s.id(), shape(s)))
                    .collect::<Vec<_>>()
                    .join(", "),
                bytes as f64 / f64::from(1 << 30),
                Self::MAX_BAKE_BYTES >> 30
            )));
        }
        let seconds: f64 = specs.iter().map(estimated_core_seconds).sum();
        if seconds > Self::MAX_CORE_SECONDS {
            return Err(Error::InvalidInput(format!(
                "the bake would take an estimated {:.1e} core-seconds ({:.0} core-days), more \
                 than the {:.0e} kiln starts; nothing was written: ask for fewer samples, \
                 digits (a larger max-error) or texels",
                seconds,
                seconds / 86_400.0,
                Self::MAX_CORE_SECONDS
            )));
        }
        Ok(())
    }
}
