//! Anisotropic GGX: roughness `alpha_x` along the tangent (x) and `alpha_y` along the bitangent
//! (y), and the conventions by which engines turn a roughness and an anisotropy into the two.
//!
//! Sources: Heitz 2014, "Understanding the Masking-Shadowing Function in Microfacet-Based BRDFs",
//! section 5.3 (`D`, eq. 85) and section 5.4 (Smith's `Lambda` of an anisotropic distribution
//! is the isotropic one at the direction's projected roughness `alpha_phi = sqrt(alpha_x^2
//! cos^2 phi + alpha_y^2 sin^2 phi)`); Dupuy & Benyoub 2023 for the visible normals (each axis
//! stretched by its own roughness). The conventions are cited where they are defined
//! ([`AnisotropyConvention`]).

use super::ndf::visible_normal_on_stretched_cap;
use super::vector::Vec3;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Anisotropic GGX of slope-space roughness `alpha_x` along x and `alpha_y` along y. With
/// `alpha_x = alpha_y = alpha` it is [`super::Ggx`] at `alpha`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AnisotropicGgx {
    pub alpha_x: f64,
    pub alpha_y: f64,
}

impl AnisotropicGgx {
    /// `D(m) = 1 / (pi alpha_x alpha_y (m_x^2 / alpha_x^2 + m_y^2 / alpha_y^2 + m_z^2)^2)` for a
    /// unit normal with `m_z > 0` (Heitz 2014, eq. 85 multiplied through by `cos^4`).
    #[must_use]
    pub fn d(&self, m: Vec3) -> f64 {
        let (ax, ay) = (self.alpha_x, self.alpha_y);
        let q = (m.x / ax) * (m.x / ax) + (m.y / ay) * (m.y / ay) + m.z * m.z;
        1.0 / (PI * ax * ay * q * q)
    }

    /// `alpha_x^2 v_x^2 + alpha_y^2 v_y^2`: the squared projected roughness times `sin^2(theta)`.
    #[must_use]
    #[inline(always)]
    pub fn stretched_xy2(&self, v: Vec3) -> f64 {
        let (x, y) = (self.alpha_x * v.x, self.alpha_y * v.y);
        x * x + y * y
    }

    /// Smith's `Lambda(v) = (sqrt(1 + a) - 1) / 2`, `a = (alpha_x^2 v_x^2 + alpha_y^2 v_y^2) /
    /// v_z^2` (Heitz 2014, eqs. 72 and 86), as `a / (2 (1 + sqrt(1 + a)))` (no cancellation when
    /// `a` is small); infinite on the horizon.
    #[must_use]
    #[inline(always)]
    pub fn lambda(&self, v: Vec3) -> f64 {
        let a = self.stretched_xy2(v) / (v.z * v.z);
        if a.is_infinite() {
            return f64::INFINITY;
        }
        a / (2.0 * (1.0 + (1.0 + a).sqrt()))
    }

    /// The projected area `v_z (1 + Lambda(v)) = (v_z + sqrt(v_z^2 + alpha_x^2 v_x^2 +
    /// alpha_y^2 v_y^2)) / 2` of a unit direction with `v_z >= 0` (Heitz 2014, eq. 11): finite
    /// on the horizon.
    #[must_use]
    #[inline(always)]
    pub fn projected_area(&self, v: Vec3) -> f64 {
        0.5 * (v.z + (v.z * v.z + self.stretched_xy2(v)).sqrt())
    }

    /// A normal from the distribution of normals visible from `o` (density `G1(o) (o.m)+ D(m) /
    /// o_z`), `u` a point of the unit square (Dupuy & Benyoub 2023).
    #[must_use]
    #[inline(always)]
    pub fn sample_visible_normal(&self, o: Vec3, u: [f64; 2]) -> Vec3 {
        visible_normal_on_stretched_cap(self.alpha_x, self.alpha_y, o, u[0], 1.0 - u[1])
    }

    /// The roughness `alpha_phi` of the isotropic GGX whose `D` has the same shape as this one's
    /// along azimuth `phi` of the normal: `1 / alpha_phi^2 = cos^2 phi / alpha_x^2 + sin^2 phi /
    /// alpha_y^2`, so that `D(theta, phi) = D_iso(theta; alpha_phi) alpha_phi^2 / (alpha_x
    /// alpha_y)`.
    #[must_use]
    pub fn normal_alpha_along(&self, cos_phi: f64, sin_phi: f64) -> f64 {
        let (cx, sy) = (cos_phi / self.alpha_x, sin_phi / self.alpha_y);
        1.0 / (cx * cx + sy * sy).sqrt()
    }
}

/// How an engine turns its roughness `alpha` (slope space, after its own `r^2`) and its
/// anisotropy `a` into `alpha_x` (tangent) and `alpha_y` (bitangent), and which single
/// roughness it reads its isotropic tables at.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum AnisotropyConvention {
    /// Kulla & Conty 2017 (Imageworks): alpha_x = alpha (1 + a), alpha_y = alpha (1 - a), a in
    /// [0, 0.99]. Filament, Unreal; their isotropic table read at alpha, the arithmetic mean.
    #[cfg_attr(feature = "cli", value(alias = "arithmetic-mean"))]
    KullaConty,
    /// Burley 2012 (Disney): alpha_x = alpha / s, alpha_y = alpha s, s = sqrt(1 - 0.9 a), a in
    /// [0, 1]. Cycles, Enterprise PBR; read at alpha, the geometric mean.
    #[cfg_attr(feature = "cli", value(alias = "geometric-mean"))]
    Disney,
    /// glTF KHR_materials_anisotropy: alpha_x = alpha + (1 - alpha) a^2, alpha_y = alpha, a in
    /// [0, 1]; read at alpha, the bitangent's (the smaller) roughness.
    #[cfg_attr(feature = "cli", value(alias = "minimum"))]
    Gltf,
    /// OpenPBR 1.0 (specular_roughness_anisotropy): alpha_x = alpha sqrt(2 / (1 + (1 -
    /// a)^2)), alpha_y = (1 - a) alpha_x, a in [0, 0.99]; read at alpha, the root mean square.
    #[cfg_attr(feature = "cli", value(alias = "rms"))]
    Openpbr,
}

impl AnisotropyConvention {
    /// Every convention, in a fixed order.
    pub const ALL: [AnisotropyConvention; 4] = [
        AnisotropyConvention::KullaConty,
        AnisotropyConvention::Disney,
        AnisotropyConvention::Gltf,
        AnisotropyConvention::Openpbr,
    ];

    /// The name used on the command line and in files.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            AnisotropyConvention::KullaConty => "kulla-conty",
            AnisotropyConvention::Disney => "disney",
            AnisotropyConvention::Gltf => "gltf",
            AnisotropyConvention::Openpbr => "openpbr",
        }
    }

    /// The largest anisotropy the convention takes: Kulla-Conty's `alpha_y` vanishes at 1.
    #[must_use]
    pub fn max_anisotropy(self) -> f64 {
        match self {
            AnisotropyConvention::KullaConty | AnisotropyConvention::Openpbr => 0.99,
            AnisotropyConvention::Disney | AnisotropyConvention::Gltf => 1.0,
        }
    }

    /// [`AnisotropyConvention::alphas`] after checking `a` against the convention's range
    /// (`[0, max_anisotropy]`).
    pub fn checked_alphas(self, alpha: f64, a: f64) -> crate::Result<(f64, f64)> {
        self.check_anisotropy(a)?;
        Ok(self.alphas(alpha, a))
    }

    /// Checks an anisotropy against the convention's range, `[0, max_anisotropy]`.
    pub fn check_anisotropy(self, a: f64) -> crate::Result<()> {
        let max = self.max_anisotropy();
        if !(0.0..=max).contains(&a) {
            return Err(crate::Error::InvalidInput(format!(
                "anisotropy {a} is outside [0, {max}] for the {self} convention (swap the \
                 tangent and bitangent for the other direction)"
            )));
        }
        Ok(())
    }

    /// `(alpha_x, alpha_y)` for roughness `alpha` and anisotropy `a` (see each convention).
    #[must_use]
    pub fn alphas(self, alpha: f64, a: f64) -> (f64, f64) {
        match self {
            AnisotropyConvention::KullaConty => (alpha * (1.0 + a), alpha * (1.0 - a)),
            AnisotropyConvention::Disney => {
                let aspect = (1.0 - 0.9 * a).sqrt();
                (alpha / aspect, alpha * aspect)
            }
            AnisotropyConvention::Gltf => (alpha + (1.0 - alpha) * a * a, alpha),
            AnisotropyConvention::Openpbr => {
                let b = 1.0 - a;
                let alpha_x = alpha * (2.0 / (1.0 + b * b)).sqrt();
                (alpha_x, b * alpha_x)
            }
        }
    }

    /// The coordinate of anisotropy `a` on a table's axis ending at `max` (both in `[0, max]`
    /// of the convention): uniform in the logarithm of the aspect ratio `alpha_x / alpha_y` where
    /// it depends on `a` alone (Kulla-Conty `atanh(a)`, Disney `-ln(1 - 0.9 a)`, OpenPBR `-ln(1 -
    /// a)`, each over its value at `max`), and `(a / max)^2` for glTF's, whose `alpha_x - alpha_y`
    /// grows as `a^2`. Linear in `a` itself, the bitangent's roughness `alpha (1 - a)` halves
    /// within the last interval of 16 samples at `a = 0.95`, and lookups there were 3.5e-3 off
    /// (measured while designing, 2026-12-07).
    #[must_use]
    pub fn anisotropy_coordinate(self, a: f64, max: f64) -> f64 {
        if max <= 0.0 {
            return 0.0;
        }
        let f = |a: f64| match self {
            AnisotropyConvention::KullaConty => a.atanh(),
            AnisotropyConvention::Disney => -(-0.9 * a).ln_1p(),
            AnisotropyConvention::Openpbr => -(-a).ln_1p(),
            AnisotropyConvention::Gltf => a * a,
        };
        (f(a.clamp(0.0, max)) / f(max)).clamp(0.0, 1.0)
    }

    /// The anisotropy at coordinate `w` of an axis ending at `max` (the inverse of
    /// [`AnisotropyConvention::anisotropy_coordinate`]).
    #[must_use]
    pub fn anisotropy_at(self, w: f64, max: f64) -> f64 {
        let w = w.clamp(0.0, 1.0);
        match self {
            AnisotropyConvention::KullaConty => (w * max.atanh()).tanh(),
            AnisotropyConvention::Disney => -(w * (-0.9 * max).ln_1p()).exp_m1() / 0.9,
            AnisotropyConvention::Openpbr => -(w * (-max).ln_1p()).exp_m1(),
            AnisotropyConvention::Gltf => max * w.sqrt(),
        }
        .min(max)
    }

    /// The average by which the convention's engines read an isotropic table.
    #[must_use]
    pub fn reading(self) -> IsotropicReading {
        match self {
            AnisotropyConvention::KullaConty => IsotropicReading::ArithmeticMean,
            AnisotropyConvention::Disney => IsotropicReading::GeometricMean,
            AnisotropyConvention::Gltf => IsotropicReading::Minimum,
            AnisotropyConvention::Openpbr => IsotropicReading::Rms,
        }
    }
}

impl std::fmt::Display for AnisotropyConvention {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// The single roughness at which an engine reads its isotropic `E` table for an anisotropic
/// lobe.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum IsotropicReading {
    /// `sqrt(alpha_x alpha_y)`: Cycles, Enterprise PBR, MaterialX.
    GeometricMean,
    /// `(alpha_x + alpha_y) / 2`: Filament, Bevy, Unreal.
    ArithmeticMean,
    /// `sqrt((alpha_x^2 + alpha_y^2) / 2)`: OpenPBR.
    Rms,
    /// `min(alpha_x, alpha_y)`: glTF's sample viewer (its base roughness).
    Minimum,
}

impl IsotropicReading {
    /// Every reading, in a fixed order.
    pub const ALL: [IsotropicReading; 4] = [
        IsotropicReading::GeometricMean,
        IsotropicReading::ArithmeticMean,
        IsotropicReading::Rms,
        IsotropicReading::Minimum,
    ];

    /// The name used on the command line and in files.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            IsotropicReading::GeometricMean => "geometric-mean",
            IsotropicReading::ArithmeticMean => "arithmetic-mean",
            IsotropicReading::Rms => "rms",
            IsotropicReading::Minimum => "minimum",
        }
    }

    /// The average in words: `geometric mean`, `arithmetic mean`, `root mean square`, `minimum`.
    #[must_use]
    pub fn describe(self) -> &'static str {
        match self {
            IsotropicReading::GeometricMean => "geometric mean",
            IsotropicReading::ArithmeticMean => "arithmetic mean",
            IsotropicReading::Rms => "root mean square",
            IsotropicReading::Minimum => "minimum",
        }
    }

    /// The isotropic `alpha` read for `(alpha_x, alpha_y)`.
    #[must_use]
    pub fn alpha(self, alpha_x: f64, alpha_y: f64) -> f64 {
        match self {
            IsotropicReading::GeometricMean => (alpha_x * alpha_y).sqrt(),
            IsotropicReading::ArithmeticMean => 0.5 * (alpha_x + alpha_y),
            IsotropicReading::Rms => (0.5 * (alpha_x * alpha_x + alpha_y * alpha_y)).sqrt(),
            IsotropicReading::Minimum => alpha_x.min(alpha_y),
        }
    }
}

impl std::fmt::Display for IsotropicReading {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{Ggx, MicrofacetDistribution};

    /// With equal roughness on both axes every function is isotropic GGX's, and visible normals
    /// are the same bits.
    #[test]
    fn equal_axes_are_isotropic_ggx() {
        let alpha = 0.37;
        let aniso = AnisotropicGgx {
            alpha_x: alpha,
            alpha_y: alpha,
        };
        let ggx = Ggx { alpha };
        for (x, y, z) in [(0.3, 0.4, 0.866), (0.0, 0.6, 0.8), (0.9, -0.1, 0.42)] {
            let v = Vec3::new(x, y, z).normalize();
            assert!(
                (aniso.d(v) - ggx.d(v.z)).abs() < 1e-13 * ggx.d(v.z),
                "{v:?}"
            );
            assert!((aniso.lambda(v) - ggx.lambda(v)).abs() < 1e-15, "{v:?}");
            let area = ggx.projected_area(v.z);
            assert!((aniso.projected_area(v) - area).abs() < 1e-15, "{v:?}");
            for u in [[0.1, 0.2], [0.7, 0.95], [0.5, 0.0]] {
                assert_eq!(
                    aniso.sample_visible_normal(v, u),
                    ggx.sample_visible_normal(v, u)
                );
            }
        }
    }

    /// `D` is normalised (`∫ D cos dω = 1`) and the projected area is `∫ (v.m)+ D dω` (Heitz
    /// 2014, eq. 11), checked by a plain midpoint rule over the hemisphere in `(tan theta,
    /// phi)`, independent of the closed forms.
    #[test]
    fn d_is_normalised_and_lambda_is_its_projected_area() {
        let ndf = AnisotropicGgx {
            alpha_x: 0.6,
            alpha_y: 0.15,
        };
        let view = Vec3::new(0.5, 0.6, (1.0f64 - 0.61).sqrt());
        let (n_t, n_phi) = (4000, 400);
        let (mut norm, mut area) = (0.0, 0.0);
        // theta = atan(w), w = tan: dω = sin dtheta dphi; w from a map of [0, 1) (w = q / (1 - q)).
        for i in 0..n_t {
            let q = (i as f64 + 0.5) / n_t as f64;
            let w = q / (1.0 - q);
            let dw = 1.0 / ((1.0 - q) * (1.0 - q)) / n_t as f64;
            let theta = w.atan();
            let dtheta = dw / (1.0 + w * w);
            for j in 0..n_phi {
                let phi = 2.0 * PI * (j as f64 + 0.5) / n_phi as f64;
                let m = Vec3::new(
                    theta.sin() * phi.cos(),
                    theta.sin() * phi.sin(),
                    theta.cos(),
                );
                let weight = ndf.d(m) * theta.sin() * dtheta * 2.0 * PI / n_phi as f64;
                norm += weight * m.z;
                area += weight * view.dot(m).max(0.0);
            }
        }
        assert!((norm - 1.0).abs() < 2e-5, "{norm}");
        let expected = view.z * (1.0 + ndf.lambda(view));
        assert!((area - expected).abs() < 2e-5, "{area} vs {expected}");
        assert!((ndf.projected_area(view) - expected).abs() < 1e-15);
    }

    /// The conventions as their sources write them, worked by hand at `alpha = 0.25`,
    /// `a = 0.5`: Kulla-Conty 0.375, 0.125; Disney `aspect = sqrt(0.55)`; glTF `0.25 + 0.75 *
    /// 0.25 = 0.4375`; OpenPBR `0.25 sqrt(2 / 1.25) = 0.316227...`, half of it along y.
    #[test]
    fn conventions_give_the_roughness_their_sources_do() {
        let close = |(x, y): (f64, f64), (ex, ey): (f64, f64)| {
            assert!((x - ex).abs() < 1e-15 && (y - ey).abs() < 1e-15, "{x}, {y}");
        };
        close(
            AnisotropyConvention::KullaConty.alphas(0.25, 0.5),
            (0.375, 0.125),
        );
        let aspect = 0.55f64.sqrt();
        close(
            AnisotropyConvention::Disney.alphas(0.25, 0.5),
            (0.25 / aspect, 0.25 * aspect),
        );
        close(AnisotropyConvention::Gltf.alphas(0.25, 0.5), (0.4375, 0.25));
        close(
            AnisotropyConvention::Openpbr.alphas(0.25, 0.5),
            (0.316_227_766_016_837_94, 0.158_113_883_008_418_97),
        );
        // The anisotropy coordinate and its inverse.
        for convention in AnisotropyConvention::ALL {
            for w in [0.0, 0.3, 0.77, 1.0] {
                let a = convention.anisotropy_at(w, 0.9);
                let back = convention.anisotropy_coordinate(a, 0.9);
                assert!(
                    (back - w).abs() < 1e-12,
                    "{convention}: {w} -> {a} -> {back}"
                );
            }
        }
        // Each convention's reading gives back its alpha.
        for convention in AnisotropyConvention::ALL {
            let (x, y) = convention.alphas(0.25, 0.5);
            let read = convention.reading().alpha(x, y);
            assert!((read - 0.25).abs() < 1e-15, "{convention}: {read}");
            assert_eq!(convention.alphas(0.25, 0.0), (0.25, 0.25), "{convention}");
        }
    }
}
