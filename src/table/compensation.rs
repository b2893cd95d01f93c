//! kiln's compensation as textures (issue 60): the four coefficients of the multiple-scattering
//! albedo `M(mu, F0)` ([`KilnCompensation`]) at every texel of an `E` table's layout, fitted to
//! the microsurface walk, and their cosine-weighted averages `M_avg` over the roughness axis.
//!
//! A renderer reads it as it reads `E`: one bilinear lookup of an RGBA texture at `(mu, r)`
//! gives the coefficients `c_j` (the basis is linear in them, so a lookup of the coefficients is
//! the lookup of `M` at every `F0`), `M(mu, F0) = Σ_j c_j B_j(F0)`; with the averages'
//! lookup at `r`, the lobe `M(mu_o, F0) M(mu_i, F0) / (pi M_avg(F0))` per channel adds exactly
//! `M(mu_o, F0)` to the single-scattering albedo, since `M_avg = 2 ∫ M(mu) mu dmu` is taken of
//! the table's own lookup (as [`super::normalisation`] takes `f_ms_norm` of `E`'s). The lobe is
//! symmetric in `mu_o` and `mu_i`, so reciprocal.
//!
//! Each texel is fitted at the point the layout computes `E` at ([`TableSpec::texel_point`]) to
//! walks seeded from the table's seed and the texel's index, so that the table is the same bytes
//! for any thread count, and independent of an audit's walks (seed 0) unless asked to be.

use super::{Table, TableSpec};
use crate::integrate::compensation::KilnCompensation;
use crate::integrate::reference::ReferenceSettings;
use crate::integrate::walk::{WalkError, WalkSettings};
use crate::model::Model;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// The `F0` values at which a texel's standard error is read: the walk's albedo's standard
/// error, largest over these.
const ERROR_F0S: [f64; 5] = [0.02, 0.25, 0.5, 0.75, 0.9];

/// Intervals of the composite Simpson rule over `mu` in [0, 1] that averages a row's lookup:
/// the lookup is piecewise smooth between the texture's points (at most 64 a row in kiln's
/// layouts), and 4096 intervals put the rule's error below 1e-8 of `M_avg`.
const AVERAGE_INTERVALS: usize = 4096;

/// kiln's compensation at every texel of a layout.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CompensationTable {
    /// The `E` layout the coefficients are stored in (its axes, grid and coordinate mappings:
    /// the lookup is `E`'s).
    pub spec: TableSpec,
    /// The `E_avg` layout the averages are stored in (the same roughness axis).
    pub average_spec: TableSpec,
    /// Coefficient `j` of every texel (row-major, roughness slowest), for `j` in 0..4.
    pub coefficients: [Vec<f64>; 4],
    /// Per texel, the walk's standard error of the albedo it was fitted to, largest over `F0`
    /// in `ERROR_F0S`.
    pub std_error: Vec<f64>,
    /// Coefficient `j` of `M_avg` at every roughness of the averages' axis.
    pub average: [Vec<f64>; 4],
    /// The walks each texel was fitted to.
    pub walks: u64,
    /// The base seed of the walks (each texel's is this plus its index).
    pub seed: u64,
}

impl CompensationTable {
    /// The estimated cost of [`CompensationTable::bake`] of `texels` texels with `walks` walks
    /// each, in seconds of one core: about 0.05 s a texel per 2^16 walks, the fit's references
    /// included (the 32 x 32 table: 25.2 s at 2^16, 49.5 s at 2^17 on two cores, one run each,
    /// 2026-12-07).
    #[must_use]
    pub fn bake_core_seconds(texels: u64, walks: u64) -> f64 {
        texels as f64 * 0.05 * walks as f64 / f64::from(1 << 16)
    }

    /// Fits the coefficients at every texel of `spec` (an `E` layout of `model`) to walks with
    /// `settings` (the seed of texel `k` is `settings.seed + k`), and averages each roughness of
    /// `average_spec` (an `E_avg` layout over the same roughness axis) through the lookup.
    /// `progress` hears the number of texels done.
    ///
    /// # Errors
    /// A model or setting the walk refuses ([`WalkError`]).
    pub fn bake(
        model: Model,
        spec: TableSpec,
        average_spec: TableSpec,
        settings: &WalkSettings,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<Self, WalkError> {
        settings.validate()?;
        let reference = ReferenceSettings::default();
        let done = std::sync::atomic::AtomicU64::new(0);
        let texels: Vec<(KilnCompensation, f64)> = (0..spec.len())
            .into_par_iter()
            .map(|k| {
                let (alpha, mu, _) = spec.texel_point(k);
                let mu = mu.expect("an E layout has a mu axis");
                let walks = WalkSettings {
                    seed: settings.seed.wrapping_add(k as u64),
                    ..*settings
                };
                let (fit, polynomial) =
                    KilnCompensation::fitted(model, alpha, mu, &walks, &reference)?;
                let std_error = ERROR_F0S
                    .iter()
                    .map(|&f0| polynomial.albedo(f0).std_error)
                    .fold(0.0, f64::max);
                progress(done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1);
                Ok((fit, std_error))
            })
            .collect::<Result<_, WalkError>>()?;
        let coefficients =
            std::array::from_fn(|j| texels.iter().map(|(c, _)| c.coefficients[j]).collect());
        let mut table = Self {
            spec,
            average_spec,
            coefficients,
            std_error: texels.iter().map(|(_, e)| *e).collect(),
            average: std::array::from_fn(|_| Vec::new()),
            walks: settings.walks,
            seed: settings.seed,
        };
        table.average = table.averages_of_lookup();
        Ok(table)
    }

    /// `M_avg`'s coefficients at every roughness of the averages' axis: `2 ∫ c_j(mu) mu dmu` of
    /// the coefficients' lookup, by the composite Simpson rule.
    fn averages_of_lookup(&self) -> [Vec<f64>; 4] {
        let h = 1.0 / AVERAGE_INTERVALS as f64;
        let roughnesses: Vec<f64> = (0..self.average_spec.len())
            .map(|k| {
                let (alpha, _, _) = self.average_spec.texel_point(k);
                self.spec.roughness_convention().from_alpha(alpha)
            })
            .collect();
        let layout = self.layout();
        std::array::from_fn(|j| {
            roughnesses
                .iter()
                .map(|&r| {
                    let f = |i: usize| {
                        let mu = i as f64 * h;
                        mu * layout.lookup_channel(&self.coefficients[j], mu, r)
                    };
                    let inner: f64 = (1..AVERAGE_INTERVALS)
                        .map(|i| if i % 2 == 1 { 4.0 * f(i) } else { 2.0 * f(i) })
                        .sum();
                    2.0 * h / 3.0 * (f(0) + inner + f(AVERAGE_INTERVALS))
                })
                .collect()
        })
    }

    /// The layout as a table whose channels are looked up (its own values unused).
    fn layout(&self) -> Table {
        Table::layout_of(self.spec.clone())
    }

    /// The coefficients a renderer's bilinear lookup reads at `(mu, roughness)` (roughness in
    /// the layout's convention), clamp-to-edge: kiln's compensation there.
    #[must_use]
    pub fn lookup(&self, mu: f64, roughness: f64) -> KilnCompensation {
        let layout = self.layout();
        KilnCompensation {
            coefficients: std::array::from_fn(|j| {
                layout.lookup_channel(&self.coefficients[j], mu, roughness)
            }),
        }
    }

    /// `M_avg`'s coefficients a renderer's lookup reads at `roughness`.
    #[must_use]
    pub fn lookup_average(&self, roughness: f64) -> KilnCompensation {
        let layout = Table::layout_of(self.average_spec.clone());
        KilnCompensation {
            coefficients: std::array::from_fn(|j| {
                layout.lookup_channel(&self.average[j], 0.5, roughness)
            }),
        }
    }

    /// The largest standard error over the texels.
    #[must_use]
    pub fn max_std_error(&self) -> f64 {
        crate::stats::max_or_nan(self.std_error.iter().copied())
    }
}

impl CompensationTable {
    /// Checks a table read from a file before anything looks it up: `spec` an `E` layout and
    /// `average_spec` an `E_avg` layout ([`TableSpec::check`]) of the same model over the same
    /// roughness axis, without an IOR axis; every channel as long as its layout; every number
    /// finite, every standard error not negative.
    ///
    /// # Errors
    /// A sentence naming what does not fit.
    pub fn check(&self) -> crate::Result<()> {
        use crate::integrate::quantity::Quantity;
        self.spec
            .check()
            .map_err(|e| crate::Error::Malformed(format!("spec: {e}")))?;
        self.average_spec
            .check()
            .map_err(|e| crate::Error::Malformed(format!("average_spec: {e}")))?;
        if self.spec.quantity != Quantity::E || self.spec.ior.is_some() {
            return Err(crate::Error::Malformed(
                "spec is not an E layout over (roughness, mu)".into(),
            ));
        }
        if self.average_spec.quantity != Quantity::EAvg || self.average_spec.ior.is_some() {
            return Err(crate::Error::Malformed(
                "average_spec is not an E_avg layout over roughness".into(),
            ));
        }
        if self.average_spec.roughness != self.spec.roughness
            || self.average_spec.model != self.spec.model
        {
            return Err(crate::Error::Malformed(
                "the averages' layout is not over the table's roughness axis".into(),
            ));
        }
        let lengths = |what: &str, channels: &[Vec<f64>], n: usize| match channels
            .iter()
            .position(|c| c.len() != n)
        {
            Some(j) => Err(crate::Error::Malformed(format!(
                "{what} {j} holds {} numbers for {n} texels",
                channels[j].len()
            ))),
            None => Ok(()),
        };
        lengths("coefficient", &self.coefficients, self.spec.len())?;
        lengths(
            "std_error",
            std::slice::from_ref(&self.std_error),
            self.spec.len(),
        )?;
        lengths(
            "average coefficient",
            &self.average,
            self.average_spec.len(),
        )?;
        let finite = |what: &str, channels: &[Vec<f64>]| {
            for (j, channel) in channels.iter().enumerate() {
                if let Some(k) = channel.iter().position(|v| !v.is_finite()) {
                    return Err(crate::Error::Malformed(format!(
                        "{what} {j} at texel {k} is not a finite number"
                    )));
                }
            }
            Ok(())
        };
        finite("coefficient", &self.coefficients)?;
        finite("average coefficient", &self.average)?;
        if let Some(k) = self
            .std_error
            .iter()
            .position(|e| !(*e >= 0.0 && e.is_finite()))
        {
            return Err(crate::Error::Malformed(format!(
                "std_error at texel {k} is not a finite number >= 0"
            )));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::quantity::Quantity;
    use crate::model::{Masking, Ndf};
    use crate::table::axis::MuMapping;
    use crate::table::{Grid, test_e_spec};

    fn ggx() -> Model {
        Model {
            ndf: Ndf::Ggx,
            masking: Masking::HeightCorrelated,
        }
    }

    /// A 4 x 4 table at 2^12 walks a texel.
    fn small(seed: u64) -> CompensationTable {
        let spec = test_e_spec(4, 4, Grid::Nodes, MuMapping::Linear);
        let average_spec = TableSpec {
            quantity: Quantity::EAvg,
            mu: None,
            ..spec.clone()
        };
        let settings = WalkSettings {
            walks: 1 << 12,
            seed,
            ..WalkSettings::default()
        };
        CompensationTable::bake(ggx(), spec, average_spec, &settings, &|_| {}).expect("bakes")
    }

    /// The averages are what makes the lobe add exactly `M(mu_o)`: `2 ∫ M mu dmu` of the
    /// table's own lookup. Checked row by row against adaptive Gauss-Kronrod quadrature of
    /// the lookup (an independent rule, which finds the lookup's kinks by itself).
    #[test]
    fn the_averages_are_the_cosine_weighted_means_of_the_lookup() {
        let table = small(7);
        let layout = Table::layout_of(table.spec.clone());
        for row in 0..table.average_spec.len() {
            let (alpha, _, _) = table.average_spec.texel_point(row);
            let r = table.spec.roughness_convention().from_alpha(alpha);
            let integral = crate::numerics::gauss_kronrod::integrate(
                |mu| {
                    std::array::from_fn::<f64, 4, _>(|j| {
                        2.0 * mu * layout.lookup_channel(&table.coefficients[j], mu, r)
                    })
                },
                0.0,
                1.0,
                1e-12,
                10_000,
            );
            for j in 0..4 {
                let (ours, theirs) = (table.average[j][row], integral.value[j]);
                assert!(
                    (ours - theirs).abs() <= 1e-8 * theirs.abs().max(1e-3),
                    "row {row} coefficient {j}: {ours} against {theirs}"
                );
            }
            // And the lookup of the averages at the row's roughness is that row.
            let looked_up = table.lookup_average(r);
            for j in 0..4 {
                assert!((looked_up.coefficients[j] - table.average[j][row]).abs() < 1e-12);
            }
        }
    }

    /// The same seed gives the same table on any number of threads; another seed other walks.
    #[test]
    fn a_seed_gives_the_same_table_on_any_number_of_threads() {
        let on = |threads: usize, seed: u64| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("pool")
                .install(|| small(seed))
        };
        let one = on(1, 3);
        assert_eq!(one, on(3, 3));
        assert_ne!(one.coefficients, on(1, 4).coefficients);
    }

    /// A table read from a file is checked before it is looked up: a channel of the wrong
    /// length, a number that is not finite, a negative standard error and a layout that is not
    /// E's are each refused by name.
    #[test]
    fn a_damaged_table_is_refused_by_name() {
        let table = small(1);
        table.check().expect("a baked table passes");
        let mut short = table.clone();
        short.coefficients[2].pop();
        assert!(
            short
                .check()
                .unwrap_err()
                .to_string()
                .contains("coefficient 2 holds 15")
        );
        let mut nan = table.clone();
        nan.average[1][0] = f64::NAN;
        assert!(
            nan.check()
                .unwrap_err()
                .to_string()
                .contains("average coefficient 1 at texel 0")
        );
        let mut negative = table.clone();
        negative.std_error[5] = -1.0;
        assert!(
            negative
                .check()
                .unwrap_err()
                .to_string()
                .contains("std_error at texel 5")
        );
        let mut swapped = table.clone();
        std::mem::swap(&mut swapped.spec, &mut swapped.average_spec);
        assert!(swapped.check().is_err());
    }
}
