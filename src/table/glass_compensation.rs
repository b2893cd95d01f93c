//! kiln's compensation for glass at one index of refraction (issue 60): two scale factors per
//! texel and side, for the reflection and the transmission lobes of the single-scattering BSDF,
//! so that a renderer's rough dielectric sends on as much energy each way as the dielectric
//! microsurface walk ([`crate::integrate::walk::dielectric`]) does.
//!
//! Turquin's compensation divides the whole BSDF by its energy albedo `E = R + T` (kiln's
//! `e-dielectric` tables): no energy is lost, but the light single scattering misses is split
//! as single scattering splits it, and the walk splits it otherwise (from inside a glass at
//! `r = 1`, normal incidence, the walk reflects 0.406 of the light, Turquin 0.062:
//! `docs/multiple-scattering.md`). kiln's scales the two lobes apart: `k_R = R_walk / R` and
//! `k_T = T_walk / T`, with `R` and `T` the single-scattering BSDF's reflected and transmitted
//! energy (kiln's dielectric reference, the BSDF pbrt-v4, Cycles and Mitsuba evaluate) and
//! `R_walk`, `T_walk` what the walk sends each way after any number of scatterings. A renderer
//! multiplies its reflection lobe by `k_R(mu_o)` and its transmission lobe by `k_T(mu_o)`, read
//! at the view's side: the albedo is then `R_walk + T_walk = 1` and its split the walk's, at
//! every texel. Like Turquin's, the scaling is not reciprocal (it depends on the view alone).
//!
//! The factors are stored over kiln's `E` layout `(roughness, mu)` for light from outside
//! (relative index `eta`, the material's) and from inside (`1 / eta`), each texel at the point
//! the layout computes `E` at ([`TableSpec::texel_point`]), its walks seeded from the table's
//! seed and the texel's index (the same bytes on any number of threads).

use super::{Table, TableSpec};
use crate::integrate::dielectric::reference_dielectric_albedo;
use crate::integrate::reference::ReferenceSettings;
use crate::integrate::walk::{View, WalkError, WalkSettings, walk_dielectric};
use crate::model::Model;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// The sides a glass table holds: light from outside (relative index `eta`) and from inside
/// (`1 / eta`).
pub const SIDES: [&str; 2] = ["outside", "inside"];

/// Below this single-scattering energy a lobe's scale is 1: nothing goes that way to scale (an
/// index-matched interface reflects nothing).
const NOTHING: f64 = 1e-12;

/// kiln's glass compensation at one index over a layout.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GlassCompensationTable {
    /// The `E` layout the factors are stored in (the lookup is `E`'s).
    pub spec: TableSpec,
    /// The material's relative index `n_inside / n_outside`.
    pub eta: f64,
    /// `k_R` per texel for light from outside and from inside.
    pub reflection: [Vec<f64>; 2],
    /// `k_T` per texel for light from outside and from inside.
    pub transmission: [Vec<f64>; 2],
    /// Per texel, the walk's standard error of the reflected energy, largest over the sides.
    pub std_error: Vec<f64>,
    /// The walks at each texel and side.
    pub walks: u64,
    /// The base seed of the walks (each texel's is this plus its index).
    pub seed: u64,
}

impl GlassCompensationTable {
    /// The estimated cost of baking `texels` texels with `walks` walks each, in seconds of one
    /// core: two sides a texel, about a second per 2^20 walks each, and the references (the
    /// 32 x 32 table at 2^15: 48 s on two cores, 2026-12-07).
    #[must_use]
    pub fn bake_core_seconds(texels: u64, walks: u64) -> f64 {
        texels as f64 * 2.0 * (0.01 + 1.1 * walks as f64 / f64::from(1 << 20))
    }

    /// Walks every texel of `spec` (an `E` layout of `model`) from both sides of an interface of
    /// relative index `eta` with `settings` (the seed of texel `k` is `settings.seed + k`).
    /// `progress` hears the number of texels done.
    ///
    /// # Errors
    /// A model, index or setting the walk refuses ([`WalkError`]).
    pub fn bake(
        model: Model,
        spec: TableSpec,
        eta: f64,
        settings: &WalkSettings,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<Self, WalkError> {
        settings.validate()?;
        crate::integrate::walk::check_eta(eta)?;
        let reference = ReferenceSettings::default();
        let done = std::sync::atomic::AtomicU64::new(0);
        // Per texel: [k_R, k_T] per side, and the standard error.
        let texels: Vec<([[f64; 2]; 2], f64)> = (0..spec.len())
            .into_par_iter()
            .map(|k| {
                let (alpha, mu, _) = spec.texel_point(k);
                let mu = mu.expect("an E layout has a mu axis");
                let walks = WalkSettings {
                    seed: settings.seed.wrapping_add(k as u64),
                    ..*settings
                };
                let mut scales = [[1.0; 2]; 2];
                let mut std_error: f64 = 0.0;
                for (side, relative) in [eta, 1.0 / eta].into_iter().enumerate() {
                    let walk =
                        walk_dielectric(model, alpha, View::Mu(mu), relative, &walks, &|_| {})?;
                    let single =
                        reference_dielectric_albedo(model, alpha, mu, relative, &reference);
                    let parts = [single.reflection, single.transmission];
                    for lobe in 0..2 {
                        if parts[lobe] > NOTHING {
                            scales[side][lobe] = walk.all[lobe].value / parts[lobe];
                        }
                    }
                    std_error = std_error.max(walk.all[0].std_error);
                }
                progress(done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1);
                Ok((scales, std_error))
            })
            .collect::<Result<_, WalkError>>()?;
        let channel =
            |side: usize, lobe: usize| texels.iter().map(|(s, _)| s[side][lobe]).collect();
        Ok(Self {
            spec,
            eta,
            reflection: [channel(0, 0), channel(1, 0)],
            transmission: [channel(0, 1), channel(1, 1)],
            std_error: texels.iter().map(|(_, e)| *e).collect(),
            walks: settings.walks,
            seed: settings.seed,
        })
    }

    /// `[k_R, k_T]` a renderer's bilinear lookup reads at `(mu, roughness)` (roughness in the
    /// layout's convention), clamp-to-edge, for a view from inside or outside.
    #[must_use]
    pub fn lookup(&self, mu: f64, roughness: f64, inside: bool) -> [f64; 2] {
        let layout = Table::layout_of(self.spec.clone());
        let side = usize::from(inside);
        [
            layout.lookup_channel(&self.reflection[side], mu, roughness),
            layout.lookup_channel(&self.transmission[side], mu, roughness),
        ]
    }

    /// The largest standard error over the texels.
    #[must_use]
    pub fn max_std_error(&self) -> f64 {
        crate::stats::max_or_nan(self.std_error.iter().copied())
    }

    /// Checks a table read from a file before anything looks it up: `spec` an `E` layout
    /// ([`TableSpec::check`]) without an IOR axis, `eta` in `[0.01, 100]`, every channel as long
    /// as the layout, every factor finite and not negative, every standard error too.
    ///
    /// # Errors
    /// A sentence naming what does not fit.
    pub fn check(&self) -> crate::Result<()> {
        use crate::integrate::quantity::Quantity;
        self.spec
            .check()
            .map_err(|e| crate::Error::Malformed(format!("spec: {e}")))?;
        if self.spec.quantity != Quantity::E || self.spec.ior.is_some() {
            return Err(crate::Error::Malformed(
                "spec is not an E layout over (roughness, mu)".into(),
            ));
        }
        crate::integrate::walk::check_eta(self.eta).map_err(|_| {
            crate::Error::Malformed(format!(
                "eta {} is out of range [0.01, 100]",
                crate::error::shown(self.eta)
            ))
        })?;
        let n = self.spec.len();
        let channels = [
            ("reflection (outside)", &self.reflection[0]),
            ("reflection (inside)", &self.reflection[1]),
            ("transmission (outside)", &self.transmission[0]),
            ("transmission (inside)", &self.transmission[1]),
            ("std_error", &self.std_error),
        ];
        for (what, values) in channels {
            if values.len() != n {
                return Err(crate::Error::Malformed(format!(
                    "{what} holds {} numbers for {n} texels",
                    values.len()
                )));
            }
            if let Some(k) = values.iter().position(|v| !(*v >= 0.0 && v.is_finite())) {
                return Err(crate::Error::Malformed(format!(
                    "{what} at texel {k} is not a finite number >= 0"
                )));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{Masking, Ndf};
    use crate::table::axis::MuMapping;
    use crate::table::{Grid, test_e_spec};

    /// A 3 x 3 table at 2^10 walks a texel and side.
    fn small(seed: u64) -> GlassCompensationTable {
        let model = Model {
            ndf: Ndf::Ggx,
            masking: Masking::HeightCorrelated,
        };
        let settings = WalkSettings {
            walks: 1 << 10,
            seed,
            ..WalkSettings::default()
        };
        let spec = test_e_spec(3, 3, Grid::Nodes, MuMapping::Linear);
        GlassCompensationTable::bake(model, spec, 1.5, &settings, &|_| {}).expect("bakes")
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
        assert_ne!(one.reflection, on(1, 4).reflection);
    }

    /// A table read from a file is checked before it is looked up: a channel of the wrong
    /// length, a negative or infinite factor, an index out of range and a layout that is not
    /// E's are each refused by name.
    #[test]
    fn a_damaged_table_is_refused_by_name() {
        let table = small(1);
        table.check().expect("a baked table passes");
        let mut short = table.clone();
        short.transmission[1].pop();
        assert!(
            short
                .check()
                .unwrap_err()
                .to_string()
                .contains("transmission (inside) holds 8")
        );
        let mut negative = table.clone();
        negative.reflection[0][4] = -0.5;
        assert!(
            negative
                .check()
                .unwrap_err()
                .to_string()
                .contains("reflection (outside) at texel 4")
        );
        let mut infinite = table.clone();
        infinite.std_error[2] = f64::INFINITY;
        assert!(
            infinite
                .check()
                .unwrap_err()
                .to_string()
                .contains("std_error at texel 2")
        );
        let mut eta = table.clone();
        eta.eta = 0.0;
        assert!(
            eta.check()
                .unwrap_err()
                .to_string()
                .contains("eta 0 is out of range")
        );
        let mut average = table.clone();
        average.spec.quantity = crate::integrate::quantity::Quantity::EAvg;
        assert!(average.check().is_err());
    }
}
