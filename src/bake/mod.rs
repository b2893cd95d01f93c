//! Baking: from options to table specs, and from a spec to a table, texels in parallel.
//!
//! Each texel is one value of the spec's integral at the texel's point by the method the options
//! chose ([`crate::integrate::value`]: the deterministic reference, or a QMC estimate summed in a
//! fixed order inside one thread), a pure function of the spec and the texel's coordinates; a
//! fitted table then moves its texels for the lookup ([`crate::table::lookup_fit`]). Rayon spreads
//! texels over cores and collects them in index order, so a table is byte-identical for any thread
//! count.

mod confirm;
mod cost;
mod validate;

pub use confirm::{confirmation_sample, confirmation_settings};
use cost::lookup_fit_settings;
pub use cost::{
    estimated_core_seconds, lookup_fit_bytes, lookup_fit_core_seconds, lookup_fit_evaluations,
};

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

    /// The smallest `--max-error` accepted (the reference itself is good to 1e-10).
    pub const MIN_MAX_ERROR: f64 = 1e-10;

    /// The smallest `max_error` baked by QMC ([`BakeOptions::resolved`]): below it the
    /// quadrature is cheaper at every accuracy (`kiln study`).
    pub const QMC_MIN_MAX_ERROR: f64 = 1e-3;

    /// Whether a bake to `max_error` runs the deterministic quadrature ([`BakeOptions::resolved`]):
    /// below [`BakeOptions::QMC_MIN_MAX_ERROR`], and for any bound when it bakes `glass` tables
    /// (over the IOR).
    #[must_use]
    pub fn max_error_takes_quadrature(max_error: f64, glass: bool) -> bool {
        max_error < Self::QMC_MIN_MAX_ERROR || glass
    }

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
        if !Self::max_error_takes_quadrature(max_error, self.bakes_glass()) {
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
            .unwrap_or_else(|| MuMapping::kiln_default(quantity, self.over_ior(quantity)))
    }

    /// The material's index of refraction of `quantity`'s table when it is a glass albedo
    /// at one IOR: a dielectric Fresnel model named beside a glass quantity (`--ior 1.5`), a 2-D
    /// table at that index (`TableSpec::fixed_ior`); `None` otherwise.
    #[must_use]
    pub fn fixed_ior_for(&self, quantity: Quantity) -> Option<f64> {
        match self.fresnel {
            Some(crate::model::Fresnel::Dielectric { eta }) if quantity.is_dielectric() => {
                Some(eta)
            }
            _ => None,
        }
    }

    /// Whether `quantity`'s table has an IOR axis: `F_avg` and the glass albedos but those at
    /// one IOR ([`BakeOptions::fixed_ior_for`]).
    #[must_use]
    pub fn over_ior(&self, quantity: Quantity) -> bool {
        quantity.has_ior() && self.fixed_ior_for(quantity).is_none()
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
        if self.over_ior(quantity) {
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
        let max_error = self
            .max_error
            .filter(|&x| Self::max_error_takes_quadrature(x, self.bakes_glass()))?;
        Some((-max_error.log10() - 1e-9).ceil() as u32)
    }

    /// Whether a dielectric table is among the quantities: [`BakeOptions::resolved`] bakes
    /// those by the quadrature at every `max_error`, since QMC at the sample count of the
    /// reflection tables' rule missed the bound from inside (measured node error 2.0e-3 at
    /// `--max-error 1e-3`, 1.1e-2 at 1e-2 in Cycles' convention; issue 40).
    fn bakes_glass(&self) -> bool {
        Self::any_glass(&self.quantities)
    }

    /// Whether `quantities` hold a glass table (over the IOR; `F_avg`, a 1-D integral, is not
    /// one), which a bake to a max error computes by the quadrature.
    #[must_use]
    pub fn any_glass(quantities: &[Quantity]) -> bool {
        quantities.iter().any(|q| q.is_dielectric())
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
                            transmission: if quantity.is_glass_albedo() {
                                self.transmission
                            } else {
                                TransmissionConvention::SingleScattering
                            },
                            model,
                            quantity,
                            ior: self.over_ior(quantity).then_some(
                                // Cycles' axis for F_avg and the coats' reflection,
                                // which kiln's glass layout (of R + T) does not fit.
                                if glass_layout
                                    && (quantity == Quantity::FAvg || quantity.is_reflection_only())
                                {
                                    f_avg_ior
                                } else {
                                    ior
                                },
                            ),
                            fresnel: self.fresnel.filter(|_| {
                                quantity == Quantity::EF || self.fixed_ior_for(quantity).is_some()
                            }),
                            roughness: quantity.has_roughness().then(|| roughness(quantity)),
                            mu: quantity.has_mu().then_some(
                                if glass_layout
                                    && self.over_ior(quantity)
                                    && quantity.is_glass_albedo()
                                {
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
        if quantities.iter().any(|&q| self.over_ior(q)) {
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
    let channels = [
        estimates.iter().map(|e| e.value).collect(),
        estimates.iter().map(|e| e.one_minus_value).collect(),
        estimates.iter().map(|e| e.std_error).collect(),
    ];
    Table::unmeasured(spec, channels, command)
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
