//! The BRDF kiln tabulates: normal distributions, Smith masking, roughness conventions.
//!
//! The reflection BRDF (`docs/physics.md`) is `f(o, i) = F(o.h) D(h) G2(o, i) / (4 |n.i| |n.o|)`;
//! the tables here are for `F = 1`.

pub mod anisotropic_ggx;
pub mod beckmann_sampling;
pub mod dielectric;
pub mod disney_diffuse;
pub mod fresnel;
pub mod kulla_conty;
pub mod masking;
pub mod ndf;
pub mod sheen;
pub mod special;
pub mod vector;

use serde::{Deserialize, Serialize};

pub use anisotropic_ggx::{AnisotropicGgx, AnisotropyConvention, IsotropicReading};
pub use fresnel::Fresnel;
pub use masking::Masking;
pub use ndf::{Beckmann, Ggx, MicrofacetDistribution, Polar};
pub use vector::Vec3;

/// Below this slope-space roughness kiln treats the surface as smooth: `E` comes from the
/// grazing boundary layer's similarity, `E(mu, alpha) = E(mu SMOOTH_ALPHA / alpha, SMOOTH_ALPHA)`
/// ([`smooth_point`]), and `E_avg` is the mirror's 1.
///
/// Why: as `alpha -> 0`, `E` depends on `mu / alpha` alone up to `O(alpha^2)` (`docs/physics.md`,
/// "Hard cases": `E(mu = alpha) ~ 0.89` at every small `alpha`), so the rescaled point is exact
/// to about `1e-14` here; below ~1e-12 the reference quadrature stops resolving `mu ~ alpha`
/// in f64 (the view sits within `1e-12` rad of the horizon) and plain sampling would follow it.
/// `1 - E_avg` below this roughness is under `2 alpha^2 (0.25 + ln(1 / alpha) / 2) ~ 2e-13`.
/// `E` stays continuous into `alpha = 0`: it tends to 1 at every fixed `mu > 0` (the mirror),
/// and at `mu = 0` to the layer's limit (1 height-correlated, 0.936 separable GGX), which is
/// what kiln returns at `alpha = 0` itself.
pub const SMOOTH_ALPHA: f64 = 1e-7;

/// The point `(alpha, mu)` at which kiln evaluates `E(mu, alpha)`: itself from
/// [`SMOOTH_ALPHA`] up, the similar point at `SMOOTH_ALPHA` below it (see there); at
/// `alpha = 0`, `mu > 0` maps to `mu = 1` (the mirror) and `mu = 0` stays 0 (the layer's limit).
#[must_use]
pub fn smooth_point(alpha: f64, mu: f64) -> (f64, f64) {
    if alpha >= SMOOTH_ALPHA {
        (alpha, mu)
    } else if mu == 0.0 {
        (SMOOTH_ALPHA, 0.0)
    } else if alpha < f64::MIN_POSITIVE {
        // A subnormal alpha: SMOOTH_ALPHA / alpha overflows below 5.6e-316 (and then every
        // mu went to the mirror's 1: issue 64, defect 8); the ratio mu / alpha does not, and
        // overflows only where the view is a mirror's anyway.
        (SMOOTH_ALPHA, ((mu / alpha) * SMOOTH_ALPHA).min(1.0))
    } else {
        (SMOOTH_ALPHA, (mu * (SMOOTH_ALPHA / alpha)).min(1.0))
    }
}

/// Whether `E(mu, alpha) = 1` exactly, with nothing to integrate: a mirror (`alpha = 0`,
/// `mu > 0`), and the height-correlated grazing limit `E(0) = 1` (`docs/physics.md`: `G2 / G1(o) =
/// (1 + Lambda(o)) / (1 + Lambda(o) + Lambda(i)) -> 1` as `Lambda(o) -> infinity`). Every
/// estimator returns these without sampling.
#[must_use]
pub fn albedo_is_exactly_one(model: Model, alpha: f64, mu: f64) -> bool {
    (alpha == 0.0 && mu > 0.0) || (mu == 0.0 && model.masking == Masking::HeightCorrelated)
}

/// Which normal distribution a table is computed for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum Ndf {
    Ggx,
    Beckmann,
}

impl Ndf {
    /// Every distribution, in a fixed order.
    pub const ALL: [Ndf; 2] = [Ndf::Ggx, Ndf::Beckmann];

    /// The name used on the command line and in files.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Ndf::Ggx => "ggx",
            Ndf::Beckmann => "beckmann",
        }
    }
}

impl std::fmt::Display for Ndf {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// The BRDF model a table belongs to: distribution and masking form (`F = 1` for now).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Model {
    pub ndf: Ndf,
    pub masking: Masking,
}

/// `ggx height-correlated`: the distribution and the masking form, as tables and messages name
/// a model.
impl std::fmt::Display for Model {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} {}", self.ndf.name(), self.masking.name())
    }
}

impl Model {
    /// Checks the combination: Schlick-GGX masking approximates GGX's Smith `G1` and is
    /// defined with GGX only.
    pub fn validate(&self) -> crate::Result<()> {
        if self.masking == Masking::SchlickGgx && self.ndf != Ndf::Ggx {
            return Err(crate::Error::InvalidInput(format!(
                "masking schlick-ggx approximates GGX's masking and goes with --ndf ggx only \
                 (got {})",
                self.ndf
            )));
        }
        Ok(())
    }
}

/// How a roughness number is to be read.
///
/// Perceptual roughness `r` maps to `alpha = r^2` (Burley 2012, Karis 2013; Filament, Cycles,
/// Imageworks). `Alpha` takes the slope-space width directly (Mitsuba). pbrt-v4's
/// `alpha = sqrt(r)` is not offered: convert to `alpha` first.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum RoughnessConvention {
    /// Perceptual roughness `r`, `alpha = r^2`.
    #[serde(rename = "r")]
    #[cfg_attr(feature = "cli", value(name = "r"))]
    Perceptual,
    /// `alpha` itself.
    Alpha,
}

impl RoughnessConvention {
    /// The name used on the command line and in files: `r` or `alpha`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            RoughnessConvention::Perceptual => "r",
            RoughnessConvention::Alpha => "alpha",
        }
    }

    /// The `alpha` a roughness value in this convention stands for.
    #[must_use]
    pub fn to_alpha(self, value: f64) -> f64 {
        match self {
            RoughnessConvention::Perceptual => value * value,
            RoughnessConvention::Alpha => value,
        }
    }

    /// The roughness value in this convention that stands for `alpha` (the inverse of
    /// [`RoughnessConvention::to_alpha`]).
    #[must_use]
    pub fn from_alpha(self, alpha: f64) -> f64 {
        match self {
            RoughnessConvention::Perceptual => alpha.sqrt(),
            RoughnessConvention::Alpha => alpha,
        }
    }

    /// A sentence for metadata and generated docs.
    #[must_use]
    pub fn describe(self) -> &'static str {
        match self {
            RoughnessConvention::Perceptual => "perceptual roughness r, alpha = r^2",
            RoughnessConvention::Alpha => "alpha (slope-space roughness) directly",
        }
    }
}

impl std::fmt::Display for RoughnessConvention {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn model(ndf: Ndf, masking: Masking) -> Model {
        Model { ndf, masking }
    }

    /// Below `SMOOTH_ALPHA` a point moves along `mu / alpha = const` to `alpha = 1e-7`, capped
    /// at the mirror's `mu = 1`; from it up, nothing moves.
    #[test]
    fn a_smooth_point_keeps_mu_over_alpha() {
        assert_eq!(smooth_point(1e-7, 0.3), (1e-7, 0.3));
        assert_eq!(smooth_point(0.5, 1e-9), (0.5, 1e-9));
        assert_eq!(smooth_point(1e-9, 0.0), (1e-7, 0.0));
        let (alpha, mu) = smooth_point(1e-9, 2e-11);
        assert_eq!(alpha, 1e-7);
        assert!((mu / 2e-9 - 1.0).abs() < 1e-15, "{mu}");
        assert_eq!(smooth_point(1e-9, 0.5), (1e-7, 1.0));
        assert_eq!(smooth_point(0.0, 0.3), (1e-7, 1.0));
        assert_eq!(smooth_point(0.0, 0.0), (1e-7, 0.0));
        // Subnormal alpha (issue 64, defect 8: from 1e-316 down every mu went to the mirror).
        for a in [1e-316, 5e-324] {
            assert_eq!(smooth_point(a, a), (1e-7, 1e-7), "{a}");
            assert_eq!(smooth_point(a, 0.5), (1e-7, 1.0), "{a}");
        }
    }

    /// `E(mu = a, alpha = a)` is the grazing layer's `0.892075...` for every small `a` down to
    /// the smallest subnormal, by the reference and by QMC: the similarity, not the mirror.
    #[test]
    fn subnormal_roughness_is_the_limit_it_stands_for() {
        use crate::integrate::reference::{ReferenceSettings, reference_albedo};
        let correlated = model(Ndf::Ggx, Masking::HeightCorrelated);
        let settings = ReferenceSettings::default();
        let layer = reference_albedo(correlated, 1e-6, 1e-6, &settings).value;
        assert!((layer - 0.892_075_491_49).abs() < 1e-9, "{layer}");
        for a in [1e-300, 1e-316, 5e-324] {
            let e = reference_albedo(correlated, a, a, &settings).value;
            assert!((e - layer).abs() < 1e-9, "alpha = mu = {a}: {e}");
            let qmc = crate::integrate::albedo(correlated, a, a, &Default::default());
            assert!(
                (qmc.value - layer).abs() < 1e-4,
                "alpha = mu = {a}: QMC {qmc:?}"
            );
        }
    }

    /// `E = 1` exactly: the mirror off the horizon for every masking, and the grazing limit of
    /// the height-correlated form only (separable GGX's is 0.936).
    #[test]
    fn the_albedo_is_exactly_one_only_for_the_mirror_and_the_correlated_grazing_limit() {
        let correlated = model(Ndf::Ggx, Masking::HeightCorrelated);
        let separable = model(Ndf::Ggx, Masking::Separable);
        assert!(albedo_is_exactly_one(correlated, 0.0, 0.5));
        assert!(albedo_is_exactly_one(separable, 0.0, 0.5));
        assert!(albedo_is_exactly_one(correlated, 0.3, 0.0));
        assert!(albedo_is_exactly_one(correlated, 0.0, 0.0));
        assert!(!albedo_is_exactly_one(separable, 0.3, 0.0));
        assert!(!albedo_is_exactly_one(separable, 0.0, 0.0));
        assert!(!albedo_is_exactly_one(correlated, 0.3, 0.5));
        assert!(!albedo_is_exactly_one(correlated, 1e-9, 0.5));
    }

    /// Names as serde writes and reads them, the roughness conventions both ways, and the one
    /// model combination refused.
    #[test]
    fn models_and_conventions_are_named_as_files_read_them() {
        let serde_name = |v: serde_json::Value| v.as_str().unwrap().to_string();
        for ndf in Ndf::ALL {
            assert_eq!(serde_name(serde_json::to_value(ndf).unwrap()), ndf.name());
            assert_eq!(ndf.to_string(), ndf.name());
        }
        assert_eq!(Ndf::ALL, [Ndf::Ggx, Ndf::Beckmann]);
        assert_eq!(
            model(Ndf::Beckmann, Masking::Separable).to_string(),
            "beckmann separable"
        );
        for convention in [RoughnessConvention::Perceptual, RoughnessConvention::Alpha] {
            let name = serde_name(serde_json::to_value(convention).unwrap());
            assert_eq!(name, convention.name());
            assert_eq!(convention.to_string(), name);
            assert_eq!(convention.from_alpha(convention.to_alpha(0.3)), 0.3);
        }
        assert_eq!(RoughnessConvention::Perceptual.to_alpha(0.5), 0.25);
        assert_eq!(RoughnessConvention::Perceptual.from_alpha(0.25), 0.5);
        assert_eq!(RoughnessConvention::Alpha.to_alpha(0.5), 0.5);
        assert_eq!(RoughnessConvention::Alpha.from_alpha(0.25), 0.25);
        assert!(
            RoughnessConvention::Perceptual
                .describe()
                .contains("alpha = r^2")
        );
        assert!(RoughnessConvention::Alpha.describe().starts_with("alpha"));
        let refused = model(Ndf::Beckmann, Masking::SchlickGgx).validate();
        assert!(
            refused
                .unwrap_err()
                .to_string()
                .contains("--ndf ggx only (got beckmann)")
        );
        assert!(model(Ndf::Ggx, Masking::SchlickGgx).validate().is_ok());
        assert!(model(Ndf::Beckmann, Masking::Separable).validate().is_ok());
    }
}
