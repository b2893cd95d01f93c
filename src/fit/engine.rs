//! The texture-free fits engines ship for the directional albedo, written from their published
//! formulas (kiln's own code, the coefficients as published), each in its source's roughness
//! convention: what `kiln verify-fit` audits.
//!
//! Every fit here is of GGX's split-sum terms: `E_scale` and `E_bias` (Karis 2013; their sum is
//! `E` for `F = 1`), or `E` and `E_bias` (Unreal 5).

use crate::integrate::quantity::Quantity;

/// A published fit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum EngineFit {
    /// Karis 2014, "Physically Based Shading on Mobile" (Unreal Engine blog), `EnvBRDFApprox`:
    /// a fit of UE4's split-sum LUT in the perceptual roughness `r` and `mu = N.V`.
    Karis,
    /// MaterialX `mx_ggx_dir_albedo_analytic` (`libraries/pbrlib/genglsl/lib/
    /// mx_microfacet_specular.glsl`, Apache-2.0): a rational fit in `mu` and `alpha`.
    #[cfg_attr(feature = "cli", value(name = "materialx"))]
    MaterialX,
    /// Unreal Engine 5 `GGXEnergyLookup` with `USE_ENERGY_CONSERVATION == 2`
    /// (`Engine/Shaders/Private/ShadingEnergyConservation.ush`): `E` and its Fresnel part in
    /// the perceptual roughness `r` and `mu`.
    Unreal,
}

impl EngineFit {
    pub const ALL: [EngineFit; 3] = [EngineFit::Karis, EngineFit::MaterialX, EngineFit::Unreal];

    /// The name on the command line.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            EngineFit::Karis => "karis",
            EngineFit::MaterialX => "materialx",
            EngineFit::Unreal => "unreal",
        }
    }

    /// Where the formula is published.
    #[must_use]
    pub fn source(self) -> &'static str {
        match self {
            EngineFit::Karis => {
                "Karis 2014, \"Physically Based Shading on Mobile\", EnvBRDFApprox \
                 (https://www.unrealengine.com/blog/physically-based-shading-on-mobile)"
            }
            EngineFit::MaterialX => {
                "MaterialX mx_ggx_dir_albedo_analytic, libraries/pbrlib/genglsl/lib/\
                 mx_microfacet_specular.glsl (a rational quadratic fit in mu and alpha)"
            }
            EngineFit::Unreal => {
                "Unreal Engine 5 GGXEnergyLookup, USE_ENERGY_CONSERVATION == 2, \
                 Engine/Shaders/Private/ShadingEnergyConservation.ush"
            }
        }
    }

    /// The quantities the fit gives (its split-sum pair and their sum `E`).
    #[must_use]
    pub fn quantities(self) -> [Quantity; 3] {
        [Quantity::E, Quantity::EScale, Quantity::EBias]
    }

    /// `(E_scale, E_bias)` at `mu` and the perceptual roughness `r` (`alpha = r^2`).
    #[must_use]
    pub fn split_sum(self, mu: f64, r: f64) -> (f64, f64) {
        match self {
            EngineFit::Karis => karis(mu, r),
            EngineFit::MaterialX => materialx(mu, r * r),
            EngineFit::Unreal => {
                let (e, e_bias) = unreal(mu, r);
                (e - e_bias, e_bias)
            }
        }
    }

    /// The fit's value of `quantity` (one of [`EngineFit::quantities`]) at `mu` and `r`.
    #[must_use]
    pub fn value(self, quantity: Quantity, mu: f64, r: f64) -> f64 {
        let (scale, bias) = self.split_sum(mu, r);
        match quantity {
            Quantity::EScale => scale,
            Quantity::EBias => bias,
            _ => scale + bias,
        }
    }
}

/// Karis' `EnvBRDFApprox`: with `c0 = (-1, -0.0275, -0.572, 0.022)`, `c1 = (1, 0.0425, 1.04,
/// -0.04)`, `q = r c0 + c1`, `a = min(q.x^2, 2^(-9.28 mu)) q.x + q.y`, the pair is
/// `(-1.04 a + q.z, 1.04 a + q.w)`.
fn karis(mu: f64, r: f64) -> (f64, f64) {
    let q = [
        1.0 - r,
        0.0425 - 0.0275 * r,
        1.04 - 0.572 * r,
        0.022 * r - 0.04,
    ];
    let a = (q[0] * q[0]).min((-9.28 * mu).exp2()) * q[0] + q[1];
    (-1.04 * a + q[2], 1.04 * a + q[3])
}

/// MaterialX's rational fit: numerators and denominators of `(E_scale, E_bias)` are the same
/// biquadratic-like polynomial in `x = mu`, `y = alpha` (terms 1, x, y, xy, x^2, y^2, x^2 y,
/// x y^2, x^2 y^2) with the published coefficients; MaterialX applies no clamp.
fn materialx(mu: f64, alpha: f64) -> (f64, f64) {
    // Rows: the coefficient of each term for (scale numerator, bias numerator, scale
    // denominator, bias denominator).
    const C: [[f64; 4]; 9] = [
        [0.10031, 0.93450, 1.0, 1.0],
        [-0.63301, -2.32352, -1.76427, 0.22797],
        [9.74995, 2.22823, 8.26501, 15.93688],
        [-2.02075, -3.74584, 11.54840, -55.82466],
        [29.38247, 1.42450, 28.99991, 13.07919],
        [-8.24713, -0.76829, -7.50867, 41.25882],
        [-26.51510, 1.43366, -36.16186, 54.86775],
        [19.98406, 0.29060, 15.85408, 300.10923],
        [-5.41717, 0.62933, 33.41550, -284.73288],
    ];
    let (x, y) = (mu, alpha);
    let terms = [
        1.0,
        x,
        y,
        x * y,
        x * x,
        y * y,
        x * x * y,
        x * y * y,
        x * x * y * y,
    ];
    let mut r = [0.0; 4];
    for (term, row) in terms.iter().zip(C) {
        for (acc, c) in r.iter_mut().zip(row) {
            *acc += c * term;
        }
    }
    (r[0] / r[2], r[1] / r[3])
}

/// Unreal 5's analytic energy terms: `E = 1 - saturate(r^(mu / r) (r mu + 0.0266916) /
/// (0.466495 + mu))` and its Fresnel part `E_bias = (1 - mu)^5 (2.36651 mu^(4.7703 r) +
/// 0.0387332)^r`, with `r` floored at 1e-3 as the engine's callers keep it off 0.
fn unreal(mu: f64, r: f64) -> (f64, f64) {
    let r = r.max(1e-3);
    let c = mu;
    let e = 1.0 - (r.powf(c / r) * ((r * c + 0.0266916) / (0.466495 + c))).clamp(0.0, 1.0);
    let e_bias = (1.0 - c).powi(5) * (2.36651 * c.powf(4.7703 * r) + 0.0387332).powf(r);
    (e, e_bias)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Values worked by hand from each published formula (Python, six significant digits or
    /// better), at points that exercise every branch: Karis' `min` on both sides, MaterialX's
    /// every term, Unreal's floor.
    #[test]
    fn each_fit_reproduces_its_source_by_hand() {
        // Karis, mu 0.5, r 0.5: q = (0.5, 0.02875, 0.754, -0.029); 2^-4.64 = 0.040107 < 0.25,
        // a = 0.040107 * 0.5 + 0.02875 = 0.0488036; (0.703244, 0.0217557).
        let (s, b) = EngineFit::Karis.split_sum(0.5, 0.5);
        assert!(
            (s - 0.703_244).abs() < 2e-6 && (b - 0.021_756).abs() < 2e-6,
            "{s} {b}"
        );
        // mu 1, r 0.9: q = (0.1, 0.01775, 0.5252, -0.0202); q.x^2 = 0.01 > 2^-9.28 = 0.0016086,
        // so a = 0.0016086 * 0.1 + 0.01775 = 0.0179109: (0.506573, -0.00157271).
        let (s, b) = EngineFit::Karis.split_sum(1.0, 0.9);
        assert!(
            (s - 0.506_573).abs() < 2e-6 && (b + 0.001_572_7).abs() < 2e-7,
            "{s} {b}"
        );
        // MaterialX, mu 0.5, alpha 0.25 (r 0.5): the four sums are 7.681535, 0.278193,
        // 9.165794 and 12.327293: (0.838065, 0.0225672).
        let (s, b) = EngineFit::MaterialX.split_sum(0.5, 0.5);
        assert!(
            (s - 0.838_065).abs() < 2e-6 && (b - 0.022_567_2).abs() < 2e-7,
            "{s} {b}"
        );
        // Unreal, mu 0.5, r 0.5: r^(mu/r) = 0.5; 0.5 (0.25 + 0.0266916) / 0.966495 = 0.143142;
        // E = 0.856858; E_bias = 0.03125 (2.36651 * 0.5^2.38515 + 0.0387332)^0.5 = 0.0219138.
        let e = EngineFit::Unreal.value(Quantity::E, 0.5, 0.5);
        let b = EngineFit::Unreal.value(Quantity::EBias, 0.5, 0.5);
        assert!(
            (e - 0.856_858).abs() < 2e-6 && (b - 0.021_913_8).abs() < 2e-7,
            "{e} {b}"
        );
        // At r = 0 the floor 1e-3 applies: r^(mu / r) underflows to 0 at mu 0.5, E = 1.
        assert_eq!(EngineFit::Unreal.value(Quantity::E, 0.5, 0.0), 1.0);
    }
}
