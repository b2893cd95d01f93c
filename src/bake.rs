//! Baking: from options to table specs, and from a spec to a table, texels in parallel.
//!
//! Each texel is one value of the spec's integral at the texel's point by the method the options
//! chose ([`crate::integrate::value`]: the deterministic reference, or a QMC estimate summed in a
//! fixed order inside one thread), a pure function of the spec and the texel's coordinates; a
//! fitted table then moves its texels for the lookup ([`crate::table::lookup_fit`]). Rayon spreads
//! texels over cores and collects them in index order, so a table is byte-identical for any thread
//! count.

use crate::cache::{Cache, CacheKey};
use crate::error::{Error, Result};
use crate::integrate::reference::ReferenceSettings;
use crate::integrate::value::Point;
use crate::integrate::{Estimate, QmcSettings};
use crate::model::dielectric::TransmissionConvention;
use crate::model::{Masking, Model, Ndf, RoughnessConvention};
use crate::table::axis::{Axis, Grid, IorBound, IorMapping, MuMapping, RoughnessSpacing};
use crate::table::{Method, Quantity, Table, TableSpec, Texels};
use crate::verify::{MAX_AVERAGE_ENTRIES_CHECKED, spread_indices};
use rayon::prelude::*;

/// What `kiln bake` bakes: for each model, an `E` table and an `E_avg` table.
///
/// The default is GGX with height-correlated masking, to a max error of 1e-7 (the deterministic
/// quadrature, checked against the reference on a sample of texels).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BakeOptions {
    pub ndfs: Vec<Ndf>,
    pub maskings: Vec<Masking>,
    /// The tables baked per model: `E` and `E_avg` by default; the split-sum channels
    /// `E_scale` and `E_bias` on request.
    pub quantities: Vec<Quantity>,
    /// Samples per axis: `E` is `size x size`, `E_avg` has `size` entries.
    pub size: usize,
    /// QMC evaluations per `E` texel (a power of two).
    pub samples: u64,
    /// QMC evaluations per `E_avg` entry (a power of two); `E_avg` integrates over `mu` as well,
    /// and 32 entries are cheap, so the default is [`QmcSettings::AVERAGE_FACTOR`] times `samples`.
    pub average_samples: u64,
    /// Independent scrambles per estimate (for the standard error).
    pub scrambles: u32,
    pub seed: u64,
    pub roughness_convention: RoughnessConvention,
    /// How the roughness samples are spaced along the convention's value (linear only with a
    /// table over the IOR: [`BakeOptions::validate`]); `None`: the spacing of each table's `mu`
    /// axis ([`BakeOptions::roughness_spacing_for`]).
    #[serde(default)]
    pub roughness_spacing: Option<RoughnessSpacing>,
    /// The `mu` axis of every table; `None`: kiln's axis for each quantity
    /// ([`BakeOptions::mu_mapping_for`]).
    #[serde(default)]
    pub mu_mapping: Option<MuMapping>,
    pub grid: Grid,
    /// Samples on the index-of-refraction axis of the dielectric tables and `F_avg` (their
    /// roughness and `mu` axes have `size` samples).
    pub ior_size: usize,
    /// How the IOR axis is spaced ([`IorMapping`]).
    pub ior_mapping: IorMapping,
    /// The IOR axis runs over `[1, ior_max]`.
    pub ior_max: f64,
    /// The Fresnel model of the `E_F` tables (a grey one; required with [`Quantity::EF`]).
    pub fresnel: Option<crate::model::Fresnel>,
    /// How the dielectric tables count a refraction that ends on the incident side
    /// ([`TransmissionConvention`]; the other tables ignore it).
    #[serde(default)]
    pub transmission: TransmissionConvention,
    /// Measure each table's node error against the deterministic reference after baking (only
    /// meaningful for [`Method::Qmc`]).
    pub check_against_reference: bool,
    /// How to compute the values.
    pub method: Method,
    /// Bake to this max error (the default, [`BakeOptions::DEFAULT_MAX_ERROR`]): kiln picks the
    /// method and its sample count or tolerance ([`BakeOptions::resolved`]), overriding
    /// `method`, `samples`, `average_samples` and `check_against_reference`, then confirms the
    /// result against the reference on a sample of texels. `None` bakes with `method` as given.
    pub max_error: Option<f64>,
    /// Point samples or texels fitted for the bilinear lookup ([`crate::table::lookup_fit`]);
    /// `None`: those of each table's `mu` axis ([`BakeOptions::texels_for`]: fitted on the
    /// balanced axis, `E`'s default; point samples over the IOR).
    #[serde(default)]
    pub texels: Option<Texels>,
}

impl Default for BakeOptions {
    fn default() -> Self {
        Self {
            ndfs: vec![Ndf::Ggx],
            maskings: vec![Masking::HeightCorrelated],
            quantities: Self::DEFAULT_QUANTITIES.to_vec(),
            size: Self::DEFAULT_SIZE,
            samples: QmcSettings::DEFAULT_SAMPLES,
            average_samples: QmcSettings::average_samples_for(QmcSettings::DEFAULT_SAMPLES),
            scrambles: QmcSettings::DEFAULT_SCRAMBLES,
            seed: 0,
            roughness_convention: RoughnessConvention::Perceptual,
            roughness_spacing: None,
            mu_mapping: None,
            grid: Grid::Nodes,
            ior_size: Self::DEFAULT_IOR_SIZE,
            ior_mapping: IorMapping::Glass,
            ior_max: Self::DEFAULT_IOR_MAX,
            fresnel: None,
            transmission: TransmissionConvention::SingleScattering,
            check_against_reference: true,
            method: Method::Qmc,
            max_error: Some(Self::DEFAULT_MAX_ERROR),
            texels: None,
        }
    }
}

impl BakeOptions {
    /// The default bake's max error: the deterministic quadrature at tolerance 1e-7 (half a
    /// second for the default pair on 2 cores), far below what a 32 x 32 bilinear lookup
    /// resolves, so the stored values are never the weak link.
    pub const DEFAULT_MAX_ERROR: f64 = 1e-7;

    /// The default table size, 32 x 32.
    pub const DEFAULT_SIZE: usize = 32;
    /// The tables baked per model by default: `E`, `E_avg` and the lookup-consistent
    /// normalisation of the Kulla-Conty lobe (`f_ms_norm`, [`crate::table::normalisation`]).
    pub const DEFAULT_QUANTITIES: [Quantity; 3] = [Quantity::E, Quantity::EAvg, Quantity::FMsNorm];
    /// The largest table whose texels are fitted for the lookup unless `texels` says otherwise
    /// ([`BakeOptions::texels_for`]), per axis. The fit's cost grows with the texels times its
    /// points a cell (4.0 s at 64, 22 s at 128 on 2 cores, 2026-12-05) and beyond 128 it
    /// would cost more than any other part of the bake, while the point samples' lookup
    /// error is already 4.1e-5 at 128 and falls as `N^-2`.
    pub const LARGEST_FITTED_BY_DEFAULT: usize = 128;
    /// The largest size accepted per axis.
    pub const MAX_SIZE: usize = 4096;
    /// The default IOR axis size, 16 (Cycles' glass tables are 16 x 16 x 16).
    pub const DEFAULT_IOR_SIZE: usize = 16;
    /// The default top of the IOR axis, 3 (Unreal's glass table; diamond is 2.42).
    pub const DEFAULT_IOR_MAX: f64 = 3.0;

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
        if let Some(q) = self
            .quantities()
            .into_iter()
            .find(|&q| q.has_ior() && self.roughness_spacing_for(q) == RoughnessSpacing::Balanced)
        {
            return Err(Error::InvalidInput(format!(
                "--roughness-spacing balanced (the default with --mu-axis balanced) lays out the \
                 tables over roughness and mu; {} is over the IOR too, whose rows stay linear: \
                 bake it in a separate command, or give --roughness-spacing linear",
                q.symbol()
            )));
        }
        if !self.transmission.is_default()
            && !self
                .quantities()
                .iter()
                .any(|q| q.has_ior() && *q != Quantity::FAvg)
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
                q.has_ior() && q.has_mu() && self.mu_mapping_for(q) != MuMapping::Adaptive
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
            (false, Some(_)) => {
                return Err(Error::InvalidInput(
                    "a Fresnel model applies to the Fresnel-weighted table: add --quantity e-f \
                     (the other tables are for F = 1, or over the IOR for glass)"
                        .into(),
                ));
            }
            (true, Some(fresnel)) => fresnel.validate().map_err(Error::InvalidInput)?,
            (false, None) => {}
        }
        for model in self.models() {
            model.validate().map_err(Error::InvalidInput)?;
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
            .validate()
            .map_err(|e| Error::InvalidInput(e.replacen("--samples", flag, 1)))?;
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

    /// The smallest `--max-error` accepted (the reference itself is good to 1e-10).
    pub const MIN_MAX_ERROR: f64 = 1e-10;

    /// The options `bake` runs with: these, or for a `max_error` the cheapest method that meets
    /// it, by what `kiln study` measured (GGX, 32 x 32, kiln's axes; README "What accuracy
    /// costs"): from 1e-3 up (glass excepted, `BakeOptions::bakes_glass`), QMC with
    /// visible-normal sampling, whose max error over a table
    /// falls as about `N^-0.9`, at the smallest power of two `N >= (2 / max_error)^(1 / 0.9)`
    /// (twice the margin; 16 times that for `E_avg`); below 1e-3, where it is cheaper at every
    /// accuracy, the quadrature at tolerance `10^-d`, the largest power of ten at most
    /// `max_error`, with `E_avg` by the cheapest fixed rule whose measured bound is within half
    /// that tolerance, its `E` evaluations at the other half
    /// ([`crate::integrate::average_quadrature::average_albedo_to`]). The quadrature's stated
    /// error is a bound of its actual error (tested against itself at far tighter tolerances,
    /// and at the default table's every node by `kiln verify`: 2.5e-10 at tolerance 1e-7), so
    /// every texel is within the tolerance. Until numerics version 5 the tolerance was a tenth of that, and the tables
    /// came out 100 to 1000 times better than asked, at up to twice the cost; until version 6
    /// the tables over IOR kept that tenth, as their quadrature's stated error had been seen
    /// short by up to 3.7x where the critical angle meets the horizon (fixed in version 6).
    /// Either way the result is then checked against the reference on a sample of texels
    /// ([`confirmation_sample`]).
    #[must_use]
    pub fn resolved(&self) -> BakeOptions {
        let Some(max_error) = self.max_error else {
            return self.clone();
        };
        let mut options = self.clone();
        options.check_against_reference = true;
        if max_error >= 1e-3 && !self.bakes_glass() {
            let needed = (2.0 / max_error).powf(1.0 / 0.9).ceil() as u64;
            let samples = needed.next_power_of_two().max(64);
            options.method = Method::Qmc;
            options.samples = samples;
            options.average_samples = QmcSettings::average_samples_for(samples);
        } else {
            options.method = Method::Reference;
        }
        options
    }

    /// The `mu` axis of `quantity`'s table: the one named, or kiln's axis for it
    /// ([`MuMapping::kiln_default`]). `f_ms_norm` and `E_avg` follow `E`'s.
    #[must_use]
    pub fn mu_mapping_for(&self, quantity: Quantity) -> MuMapping {
        self.mu_mapping
            .unwrap_or_else(|| MuMapping::kiln_default(quantity))
    }

    /// The roughness spacing of `quantity`'s table: the one named, or the one that goes with
    /// its `mu` axis ([`RoughnessSpacing::paired_with`]).
    #[must_use]
    pub fn roughness_spacing_for(&self, quantity: Quantity) -> RoughnessSpacing {
        self.roughness_spacing
            .unwrap_or_else(|| RoughnessSpacing::paired_with(self.mu_mapping_for(quantity)))
    }

    /// The texels of `quantity`'s table: those named, or those that go with its `mu` axis
    /// ([`Texels::paired_with`]: fitted on the balanced axis) up to
    /// [`BakeOptions::LARGEST_FITTED_BY_DEFAULT`] texels a side, point samples beyond (named
    /// `-nodes`); point samples over the IOR unless named (a fit there costs about ten times
    /// the bake: 108 s for the four glass tables at 16^3, docs/verify.md). `F_avg`, a closed
    /// form over the IOR axis alone, is always point samples: there is no roughness to fit
    /// over (`--texels lookup-fit` with `f-avg` among other quantities fits the others).
    #[must_use]
    pub fn texels_for(&self, quantity: Quantity) -> Texels {
        if quantity == Quantity::FAvg {
            return Texels::Nodes;
        }
        if quantity.has_ior() {
            return self.texels.unwrap_or(Texels::Nodes);
        }
        self.texels.unwrap_or_else(|| {
            if self.size > Self::LARGEST_FITTED_BY_DEFAULT {
                Texels::Nodes
            } else {
                Texels::paired_with(self.mu_mapping_for(quantity))
            }
        })
    }

    /// With a `max_error` the quadrature bakes (below 1e-3, or any for glass): its tolerance
    /// `10^-digits` (see [`BakeOptions::resolved`]).
    #[must_use]
    pub fn reference_digits(&self) -> Option<u32> {
        let max_error = self.max_error.filter(|&x| x < 1e-3 || self.bakes_glass())?;
        Some((-max_error.log10() - 1e-9).ceil() as u32)
    }

    /// Whether a dielectric table is among the quantities: [`BakeOptions::resolved`] bakes
    /// those by the quadrature at every `max_error`, since QMC at the sample count of the
    /// reflection tables' rule missed the bound from inside (measured node error 2.0e-3 at
    /// `--max-error 1e-3`, 1.1e-2 at 1e-2 in Cycles' convention; issue 40).
    fn bakes_glass(&self) -> bool {
        self.quantities
            .iter()
            .any(|q| q.has_ior() && *q != Quantity::FAvg)
    }

    /// The models baked, in a fixed order.
    #[must_use]
    pub fn models(&self) -> Vec<Model> {
        let mut models = Vec::new();
        for &ndf in &self.ndfs {
            for &masking in &self.maskings {
                let model = Model { ndf, masking };
                if !models.contains(&model) {
                    models.push(model);
                }
            }
        }
        models
    }

    /// The tables to bake: each quantity for each model, in order (`F_avg`, the same for every
    /// model, once).
    #[must_use]
    pub fn specs(&self) -> Vec<TableSpec> {
        // kiln's glass layout is for the dielectric albedos; F_avg, which has no roughness,
        // keeps Cycles' axis.
        let glass_layout = self.ior_mapping == IorMapping::Glass;
        let f_avg_ior = Axis::Ior {
            size: self.ior_size,
            mapping: IorMapping::Cycles,
            max: IorBound(self.ior_max),
            grid: self.grid,
        };
        let glass_mu = Axis::Mu {
            size: self.size,
            mapping: MuMapping::Glass,
            grid: self.grid,
        };
        let ior = Axis::Ior {
            size: self.ior_size,
            mapping: self.ior_mapping,
            // Blender's axis ends where its clamp puts it, whatever ior_max.
            max: IorBound(match self.ior_mapping {
                IorMapping::Blender => IorMapping::Blender.eta(1.0, self.ior_max, 1.0),
                _ => self.ior_max,
            }),
            grid: self.grid,
        };
        let roughness = |quantity| Axis::Roughness {
            size: self.size,
            convention: self.roughness_convention,
            grid: self.grid,
            spacing: self.roughness_spacing_for(quantity),
        };
        let mu = |quantity| Axis::Mu {
            size: self.size,
            mapping: self.mu_mapping_for(quantity),
            grid: self.grid,
        };
        // A tolerance only means something to the quadrature.
        let reference_digits = self
            .reference_digits()
            .filter(|_| self.method == Method::Reference);
        let qmc = |samples| QmcSettings {
            samples,
            scrambles: self.scrambles,
            seed: self.seed,
        };
        let models = self.models();
        let first = models.first().copied();
        models
            .into_iter()
            .flat_map(|model| {
                self.quantities()
                    .into_iter()
                    .filter(move |&q| q != Quantity::FAvg || Some(model) == first)
                    .map(move |quantity| {
                        let spec = |quantity: Quantity| TableSpec {
                            reference_digits,
                            lookup_of: None,
                            refined_start: None,
                            texels: self.texels_for(quantity),
                            transmission: if quantity.has_ior() && quantity != Quantity::FAvg {
                                self.transmission
                            } else {
                                TransmissionConvention::SingleScattering
                            },
                            model,
                            quantity,
                            ior: quantity.has_ior().then_some(
                                if glass_layout && quantity == Quantity::FAvg {
                                    f_avg_ior
                                } else {
                                    ior
                                },
                            ),
                            fresnel: self.fresnel.filter(|_| quantity == Quantity::EF),
                            roughness: quantity.has_roughness().then(|| roughness(quantity)),
                            mu: quantity.has_mu().then_some(
                                if glass_layout && quantity.has_ior() {
                                    glass_mu
                                } else {
                                    mu(quantity)
                                },
                            ),
                            method: self.method,
                            qmc: qmc(if quantity.has_mu() {
                                self.samples
                            } else {
                                self.average_samples
                            }),
                        };
                        match quantity {
                            Quantity::FMsNorm => {
                                crate::table::normalisation::spec_for(&spec(Quantity::E))
                            }
                            _ => spec(quantity),
                        }
                    })
            })
            .collect()
    }

    /// The quantities baked per model, in the order given, each once, except that `f_ms_norm`
    /// comes last: it is derived from the `E` table.
    #[must_use]
    pub fn quantities(&self) -> Vec<Quantity> {
        let mut quantities: Vec<Quantity> = Vec::new();
        for &q in &self.quantities {
            if !quantities.contains(&q) {
                quantities.push(q);
            }
        }
        quantities.sort_by_key(|&q| q == Quantity::FMsNorm);
        quantities
    }

    /// ` --quantity ...` for a command line, empty for the default `e,e-avg,f-ms-norm`, with the IOR axis
    /// flags when a quantity has that axis.
    fn quantity_flag(&self) -> String {
        let quantities = self.quantities();
        if quantities == Self::DEFAULT_QUANTITIES {
            return String::new();
        }
        let names: Vec<&str> = quantities.iter().map(|q| q.cli_name()).collect();
        let mut flag = format!(" --quantity {}", names.join(","));
        if let Some(fresnel) = self.fresnel {
            flag += &format!(" {}", fresnel.flags());
        }
        if quantities.iter().any(|q| q.has_ior()) {
            flag += &format!(
                " --ior-size {} --ior-axis {} --ior-max {}",
                self.ior_size,
                self.ior_mapping.name(),
                self.ior_max
            );
        }
        flag
    }

    /// The `kiln bake` command that reproduces the tables of `model` with these options, with
    /// every setting spelled out but the layout flags not given (`--mu-axis`,
    /// `--roughness-spacing`, `--texels`: kiln's layout for each quantity, which each table's
    /// metadata states).
    #[must_use]
    pub fn command_for(&self, model: Model) -> String {
        let mut command = self.command_without_layout(model);
        // What is not named is kiln's layout for each quantity, which the metadata spells out.
        if let Some(mapping) = self.mu_mapping {
            command += &format!(" --mu-axis {}", mapping.name());
        }
        if let Some(spacing) = self.roughness_spacing {
            command += &format!(" --roughness-spacing {}", spacing.name());
        }
        if let Some(texels) = self.texels {
            command += &format!(" --texels {}", texels.name());
        }
        command
    }

    fn command_without_layout(&self, model: Model) -> String {
        if let Some(max_error) = self.max_error {
            return format!(
                "kiln bake --max-error {max_error:e}{} --ndf {} --masking {} --size {} --seed {} \
                 --roughness-axis {} --grid {}",
                self.quantity_flag(),
                model.ndf,
                model.masking,
                self.size,
                self.seed,
                self.roughness_convention,
                self.grid.name()
            );
        }
        if self.method == Method::Reference {
            return format!(
                "kiln bake --method reference{} --ndf {} --masking {} --size {} --roughness-axis {} \
                 --grid {}",
                self.quantity_flag(),
                model.ndf,
                model.masking,
                self.size,
                self.roughness_convention,
                self.grid.name()
            );
        }
        format!(
            "kiln bake{} --ndf {} --masking {} --size {} --samples {} --avg-samples {} \
             --scrambles {} --seed {} --roughness-axis {} --grid {}",
            self.quantity_flag(),
            model.ndf,
            model.masking,
            self.size,
            self.samples,
            self.average_samples,
            self.scrambles,
            self.seed,
            self.roughness_convention,
            self.grid.name()
        )
    }

    /// Bakes every table of [`BakeOptions::specs`]. `progress` is told how many integrand
    /// evaluations each finished texel spent (see [`BakeOptions::total_samples`]).
    ///
    /// Each table then has its node error measured against the deterministic reference
    /// ([`crate::verify::node_errors`]: every `E` texel, a few `E_avg` entries) and recorded in
    /// [`Table::node_errors`], unless `check_against_reference` is off.
    ///
    /// With a `max_error`, the options are [`BakeOptions::resolved`] first, every table's node
    /// error is measured (whatever the method) and a table whose measured error exceeds the
    /// bound is an error, not a file.
    pub fn bake(&self, progress: &(dyn Fn(u64) + Sync)) -> Result<Vec<Table>> {
        Ok(self.bake_cached(None, progress)?.tables)
    }

    /// As [`BakeOptions::bake`], taking each table from `cache` when it holds one with the same
    /// key ([`CacheKey`]: everything that changes the table's bytes) and storing each table baked.
    pub fn bake_cached(
        &self,
        cache: Option<&Cache>,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<BakeReport> {
        self.validate()?;
        let options = self.resolved();
        let mut report = BakeReport::default();
        for spec in options.specs() {
            let command = self.command_for(spec.model);
            let key = CacheKey::new(&spec, self.max_error, &command);
            match cache.map(|c| c.lookup(&key)) {
                Some(crate::cache::Lookup::Hit(table)) => {
                    report.reused.push(table.spec.id());
                    report.tables.push(*table);
                    continue;
                }
                Some(crate::cache::Lookup::Damaged(reason)) => {
                    report.repaired.push((spec.id(), reason));
                }
                Some(crate::cache::Lookup::Miss) | None => {}
            }
            if spec.quantity == Quantity::FMsNorm {
                // Derived from the lookup of the E table baked (or reused) just before it.
                let table =
                    crate::table::normalisation::derive_from(&spec, &report.tables, command)?;
                if let Some(cache) = cache {
                    cache.store(&key, &table)?;
                }
                report.baked.push(table.spec.id());
                report.tables.push(table);
                continue;
            }
            let table = bake_table(spec, command, progress);
            let table = self.confirm(&options, table, progress)?;
            if let Some(cache) = cache {
                cache.store(&key, &table)?;
            }
            report.baked.push(table.spec.id());
            report.tables.push(table);
        }
        Ok(report)
    }

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

/// What [`BakeOptions::bake_cached`] produced: the tables in spec order, and which were baked
/// (integrated) and which reused from the cache, by table id.
#[derive(Clone, Debug, Default)]
pub struct BakeReport {
    pub tables: Vec<Table>,
    pub baked: Vec<String>,
    pub reused: Vec<String>,
    /// Tables whose cache entry was damaged (and why): baked again, and the entry replaced.
    pub repaired: Vec<(String, String)>,
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

/// Fits a confirmed table's texels for its lookup ([`crate::table::lookup_fit`]), over its
/// own points and `kiln verify`'s audit points, and records what the fit measured. The node
/// errors then bound the stored texels' distance from the truth: the point samples' measured
/// error plus the largest correction (and the RMS is the corrections').
/// `progress` hears of each reference evaluation of the fit with the samples of one texel of
/// the bake (`spec.qmc.samples`, the unit of [`BakeOptions::total_samples`]).
pub fn fit_texels(table: &mut Table, progress: &(dyn Fn(u64) + Sync)) {
    let settings = lookup_fit_settings(&table.spec);
    let before = table.value.clone();
    // `kiln verify`'s own audit points are among the fit's: what it states, verify finds.
    let audit =
        crate::verify::lookup_coordinates(&table.spec, &crate::verify::AuditSettings::default());
    let samples = table.spec.qmc.samples;
    let report =
        crate::table::lookup_fit::fit_for_lookup(table, &settings, &audit, &|| progress(samples));
    let corrections = table
        .value
        .iter()
        .zip(&before)
        .map(|(a, b)| (a - b).powi(2));
    let rms = (corrections.sum::<f64>() / before.len().max(1) as f64).sqrt();
    if let Some(errors) = &mut table.node_errors {
        errors.max += report.max_correction;
        errors.rms = errors.rms.hypot(rms);
    }
    table.lookup_fit = Some(report);
}

/// The texels of `spec` that a bake integrates (none of `f_ms_norm`, derived from a lookup).
fn integrated_texels(spec: &TableSpec) -> u64 {
    if spec.quantity == Quantity::FMsNorm {
        0
    } else {
        spec.len() as u64
    }
}

/// The settings of [`fit_texels`] for a table of `spec`.
fn lookup_fit_settings(spec: &TableSpec) -> crate::table::lookup_fit::LookupFitSettings {
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
fn audit_count(spec: &TableSpec) -> usize {
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

/// Bakes one table, texels in parallel (deterministic for any thread count).
#[must_use]
pub fn bake_table(spec: TableSpec, command: String, progress: &(dyn Fn(u64) + Sync)) -> Table {
    let estimates: Vec<Estimate> = (0..spec.len())
        .into_par_iter()
        .map(|index| {
            let estimate = estimate_texel(&spec, index);
            progress(spec.qmc.samples);
            estimate
        })
        .collect();
    Table {
        value: estimates.iter().map(|e| e.value).collect(),
        one_minus_value: estimates.iter().map(|e| e.one_minus_value).collect(),
        std_error: estimates.iter().map(|e| e.std_error).collect(),
        spec,
        command,
        node_errors: None,
        requested_max_error: None,
        lookup_fit: None,
    }
}

/// The estimate of one texel (row-major index, slowest axis first): the spec's integral
/// ([`TableSpec::integral`]) at the texel's point by the spec's method
/// ([`crate::integrate::value`]), with [`Method::Reference`] at the spec's tolerance (`E_avg`
/// by a fixed rule whose measured error bound is within half of it where one is,
/// [`crate::integrate::average_quadrature::average_albedo_to`]).
#[must_use]
pub fn estimate_texel(spec: &TableSpec, index: usize) -> Estimate {
    let (alpha, mu, eta) = spec.texel_point(index);
    let at = Point { alpha, mu, eta };
    let integral = spec.integral();
    match spec.method {
        Method::Qmc => integral.qmc(at, &spec.qmc),
        Method::Reference => {
            let settings = spec.reference_settings();
            let mut r = integral.reference(at, &settings);
            // Where the glass layout's layers' limits (mu ~ 1e-4 alpha at alpha 1e-3,
            // eta - 1 ~ 1e-9) exhaust the budget at the bake's tolerance, the texel settles for
            // a hundred times it, converged: its stated error says so, and the bake's check
            // against --max-error measures the result.
            if !r.converged && spec.is_glass_layout() {
                let coarser = crate::integrate::reference::ReferenceSettings {
                    tolerance: settings.tolerance * 100.0,
                    ..settings
                };
                r = integral.reference(at, &coarser);
            }
            Estimate {
                value: r.value,
                one_minus_value: r.one_minus_value,
                // A quadrature that ran out of budget has no error bound: its texel says so
                // (infinite), and the bake refuses it (`Table::check_computed`).
                std_error: if r.converged { r.error } else { f64::INFINITY },
                samples: r.evaluations,
            }
        }
    }
}

/// The top of an IOR axis kiln accepts ([`crate::model::fresnel::MAX_INDEX`]).
pub const MAX_IOR: f64 = crate::model::fresnel::MAX_INDEX;

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
/// [`reference_seconds_per_point`] (the fit's points are between the texels, where the
/// integrands are tamer; measured on 32 x 32 and 64 x 64 `E` bakes, 3.4 s and 5.3 s whole
/// process on 2 cores, 2026-12-04), and its Lawson iterations, each a banded Cholesky solve of
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
    0.45 * evaluations as f64 * reference_seconds_per_point(spec, digits) + solve
}

/// [`estimated_core_seconds`] of the texels' integration alone.
fn integration_core_seconds(spec: &TableSpec) -> f64 {
    let texels = spec.len() as f64;
    match spec.method {
        Method::Qmc => texels * qmc_seconds_per_point(spec.quantity, spec.model, spec.qmc.samples),
        Method::Reference => {
            let digits = spec.reference_digits.unwrap_or(10);
            texels * reference_seconds_per_point(spec, digits)
        }
    }
}

/// The estimated cost of one QMC estimate of `quantity` for `model` with `samples` samples, in
/// seconds of one core, at the kernel rates measured for [`estimated_core_seconds`]: for `kiln
/// eval` to say how long a point will take.
#[must_use]
pub fn qmc_seconds_per_point(quantity: Quantity, model: crate::model::Model, samples: u64) -> f64 {
    let beckmann = model.ndf == crate::model::Ndf::Beckmann;
    let rate = match (quantity, beckmann) {
        (Quantity::E, false) => 75e6,
        (Quantity::EAvg, false) => 50e6,
        (Quantity::E, true) => 3.5e6,
        (Quantity::EAvg, true) => 1.7e6,
        _ => 20e6,
    };
    samples as f64 / rate
}

/// The estimated cost of one reference value of `spec`'s quantity and model at tolerance
/// `10^-digits`, in seconds of one core (the per-texel figures of [`estimated_core_seconds`]):
/// for `kiln verify` to say how long an audit will take.
#[must_use]
pub fn reference_seconds_per_point(spec: &TableSpec, digits: u32) -> f64 {
    reference_seconds(spec.quantity, spec.model, digits)
}

/// [`reference_seconds_per_point`] of `quantity` for `model`, without a table: for `kiln
/// verify --fit`.
#[must_use]
pub fn reference_seconds(quantity: Quantity, model: crate::model::Model, digits: u32) -> f64 {
    let beckmann = model.ndf == crate::model::Ndf::Beckmann;
    let per_texel = match (quantity, beckmann) {
        (Quantity::E, false) => 0.3e-3,
        (Quantity::E, true) => 0.6e-3,
        (Quantity::EAvg, false) => 4e-3,
        (Quantity::EAvg, true) => 25e-3,
        // kiln's glass layout at 1e-7, numerics version 13 (16^3 and 16^2 tables on 2 cores:
        // 1.4 s, 3.1 s, 2.5 s, 2.7 s), scaled to 8 digits.
        (Quantity::EDielectric, _) => 0.8e-3,
        (Quantity::EDielectricInside, _) => 1.7e-3,
        (Quantity::EAvgDielectric, _) => 22e-3,
        (Quantity::EAvgDielectricInside, _) => 24e-3,
        (Quantity::FAvg, _) => 1e-5,
        // Integrals of the E table's lookup, not of the BRDF.
        (Quantity::FMsNorm, _) => 0.15e-3,
        _ => 0.15e-3,
    };
    per_texel * f64::from(digits) / 8.0
}
