//! The BRDF kiln tabulates: normal distributions, Smith masking, roughness conventions.
//!
//! The reflection BRDF (`physics.md`) is `f(o, i) = F(o.h) D(h) G2(o, i) / (4 |n.i| |n.o|)`;
//! the tables here are for `F = 1`.

pub mod masking;
pub mod ndf;
pub mod special;
pub mod vector;

use serde::{Deserialize, Serialize};

pub use masking::Masking;
pub use ndf::{Beckmann, Ggx, MicrofacetDistribution};
pub use vector::Vec3;

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
