//! The estimators `kiln study` compares, each as plain scalar code: the textbook ones kiln does
//! not bake with, and kiln's own.
//!
//! All estimate `E(mu_o) = ∫ f(o, i) mu_i dω_i` with `f = D(h) G2(o, i) / (4 mu_i mu_o)`, `F = 1`
//! (`docs/physics.md`, "Microfacet BRDF" and "Estimating E"), from `n` points:
//!
//! - uniform hemisphere sampling, pdf `1 / (2 pi)`: weight `2 pi f mu_i`;
//! - cosine-weighted hemisphere sampling, pdf `mu_i / pi`: weight `pi f`;
//! - NDF sampling, pdf `D(m) cos(theta_m)` (GGX `tan^2 = alpha^2 u / (1 - u)`, Beckmann
//!   `tan^2 = -alpha^2 ln(1 - u)`): weight `G2 (o.m) / (mu_o cos(theta_m))` when `i` is above the
//!   horizon;
//! - visible-normal (VNDF) sampling, pdf `G1(o) (o.m)+ D(m) / mu_o`: weight `G2 / G1(o)`.
//!
//! The first two and "VNDF, random" use independent pseudo-random points (SplitMix64, Steele et al.
//! 2014), seeded per texel; "NDF, Sobol" uses one Owen-scrambled Sobol sequence; "VNDF, Sobol" is
//! [`crate::integrate::albedo`](mod@crate::integrate::albedo) itself (kiln's default, two scrambles).
//! `G2 / mu_o` is evaluated as `1 / (projected_area(mu_o) + mu_o Lambda(i))` (height-correlated)
//! or `G1(i) / projected_area(mu_o)` (separable), finite at `mu_o = 0`.

use crate::integrate::QmcSettings;
use crate::integrate::albedo::{albedo, reflection_loss};
use crate::integrate::reference::{ReferenceSettings, reference_albedo};
use crate::integrate::sobol::{OwenSobol, mix_seed};
use crate::model::{
    Beckmann, Ggx, Masking, MicrofacetDistribution, Model, Ndf, Vec3, albedo_is_exactly_one,
};
use serde::Serialize;
use std::f64::consts::PI;

/// One way to compute `E`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Estimator {
    /// Plain Monte Carlo, uniform hemisphere directions, pseudo-random points.
    UniformRandom,
    /// Plain Monte Carlo, cosine-weighted hemisphere directions, pseudo-random points.
    CosineRandom,
    /// Importance sampling of `D(m) cos(theta_m)`, Owen-scrambled Sobol points.
    NdfSobol,
    /// Visible-normal sampling, pseudo-random points.
    VndfRandom,
    /// Visible-normal sampling, Owen-scrambled Sobol points: kiln's default.
    VndfSobol,
    /// The deterministic reference quadrature at a given tolerance.
    Quadrature,
}

impl Estimator {
    /// Every estimator, in the order the study reports them.
    pub const ALL: [Estimator; 6] = [
        Estimator::UniformRandom,
        Estimator::CosineRandom,
        Estimator::NdfSobol,
        Estimator::VndfRandom,
        Estimator::VndfSobol,
        Estimator::Quadrature,
    ];

    /// The name in files and plots.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Estimator::UniformRandom => "uniform-random",
            Estimator::CosineRandom => "cosine-random",
            Estimator::NdfSobol => "ndf-sobol",
            Estimator::VndfRandom => "vndf-random",
            Estimator::VndfSobol => "vndf-sobol",
            Estimator::Quadrature => "quadrature",
        }
    }

    /// A line for legends.
    #[must_use]
    pub fn describe(self) -> &'static str {
        match self {
            Estimator::UniformRandom => "uniform hemisphere, random",
            Estimator::CosineRandom => "cosine hemisphere, random",
            Estimator::NdfSobol => "NDF sampling, Sobol",
            Estimator::VndfRandom => "VNDF sampling, random",
            Estimator::VndfSobol => "VNDF sampling, Sobol (kiln)",
            Estimator::Quadrature => "adaptive quadrature (reference)",
        }
    }
}

/// SplitMix64 (Steele, Lea and Flood 2014): a fast, well-mixed 64-bit generator; the top 53 bits
/// make a uniform double in [0, 1).
#[derive(Clone, Debug)]
pub struct SplitMix64(u64);

impl SplitMix64 {
    #[must_use]
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }

    /// The next uniform number in [0, 1).
    pub fn next_f64(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
        (z >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}

/// `G2(o, i) / mu_o`, finite at `mu_o = 0` (see the module docs).
fn g2_over_mu<N: MicrofacetDistribution>(ndf: &N, masking: Masking, mu_o: f64, i: Vec3) -> f64 {
    let lambda_i = ndf.lambda(i);
    let area = ndf.projected_area(mu_o);
    match masking {
        Masking::HeightCorrelated => 1.0 / (area + mu_o * lambda_i),
        Masking::Separable => 1.0 / ((1.0 + lambda_i) * area),
        Masking::SchlickGgx => {
            let k = 0.5 * ndf.alpha();
            Masking::schlick_g1(i.z, ndf.alpha()) / (mu_o * (1.0 - k) + k)
        }
    }
}

/// `f(o, i) mu_i = D(h) G2 / (4 mu_o)` for `i` above the horizon.
fn brdf_cos<N: MicrofacetDistribution>(ndf: &N, masking: Masking, o: Vec3, i: Vec3) -> f64 {
    if i.z <= 0.0 {
        return 0.0;
    }
    let h = (o + i).normalize();
    ndf.d(h.z) * g2_over_mu(ndf, masking, o.z, i) / 4.0
}

/// A direction on the upper hemisphere from `cos(theta)` and `phi`.
fn direction(cos_theta: f64, phi: f64) -> Vec3 {
    let sin_theta = ((1.0 - cos_theta) * (1.0 + cos_theta)).max(0.0).sqrt();
    Vec3::new(sin_theta * phi.cos(), sin_theta * phi.sin(), cos_theta)
}

fn sum_generic<N: MicrofacetDistribution>(
    estimator: Estimator,
    ndf: N,
    kind: Ndf,
    masking: Masking,
    mu: f64,
    samples: u64,
    seed: u64,
) -> f64 {
    let o = Vec3::from_mu(mu);
    let mut random = SplitMix64::new(seed);
    let sobol = OwenSobol::new(seed);
    let lambda_o = ndf.lambda(o);
    let mut sum = 0.0;
    for k in 0..samples {
        sum += match estimator {
            Estimator::UniformRandom => {
                let i = direction(random.next_f64(), 2.0 * PI * random.next_f64());
                2.0 * PI * brdf_cos(&ndf, masking, o, i)
            }
            Estimator::CosineRandom => {
                let (u0, u1) = (random.next_f64(), random.next_f64());
                let i = direction((1.0 - u0).sqrt(), 2.0 * PI * u1);
                if i.z > 0.0 {
                    PI * brdf_cos(&ndf, masking, o, i) / i.z
                } else {
                    0.0
                }
            }
            Estimator::NdfSobol => {
                let index = k as u32;
                let (u0, u1) = (sobol.sample(index, 0), sobol.sample(index, 1));
                let tan2 = match kind {
                    Ndf::Ggx => ndf.alpha() * ndf.alpha() * u0 / (1.0 - u0),
                    Ndf::Beckmann => -ndf.alpha() * ndf.alpha() * (-u0).ln_1p(),
                };
                let cos_m = 1.0 / (1.0 + tan2).sqrt();
                let m = direction(cos_m, 2.0 * PI * u1);
                let i = o.reflect(m);
                let om = o.dot(m);
                if i.z > 0.0 && om > 0.0 && cos_m > 0.0 {
                    // G2 (o.m) / (mu_o cos(theta_m)).
                    g2_over_mu(&ndf, masking, mu, i) * om / cos_m
                } else {
                    0.0
                }
            }
            Estimator::VndfRandom => {
                let m = ndf.sample_visible_normal(o, [random.next_f64(), random.next_f64()]);
                1.0 - reflection_loss(ndf, masking, o, lambda_o, m)
            }
            Estimator::VndfSobol | Estimator::Quadrature => unreachable!("not sampled here"),
        };
    }
    sum / samples as f64
}

/// `E(mu)` for `model` at `alpha` by `estimator` with `samples` points (for
/// [`Estimator::Quadrature`], `samples` is ignored and `tolerance` sets the accuracy), seeded by
/// `seed`. Returns `E` and the integrand evaluations spent.
#[must_use]
pub fn estimate(
    estimator: Estimator,
    model: Model,
    alpha: f64,
    mu: f64,
    samples: u64,
    tolerance: f64,
    seed: u64,
) -> (f64, u64) {
    if albedo_is_exactly_one(model, alpha, mu) {
        return (1.0, 0);
    }
    let seed = mix_seed(&[seed, alpha.to_bits(), mu.to_bits()]);
    match estimator {
        Estimator::VndfSobol => {
            let settings = QmcSettings {
                samples,
                scrambles: 2,
                seed,
            };
            (albedo(model, alpha, mu, &settings).value, samples)
        }
        Estimator::Quadrature => {
            let settings = ReferenceSettings {
                tolerance,
                max_intervals: 200,
            };
            let r = reference_albedo(model, alpha, mu, &settings);
            (r.value, r.evaluations)
        }
        _ => {
            let value = match model.ndf {
                Ndf::Ggx => sum_generic(
                    estimator,
                    Ggx { alpha },
                    Ndf::Ggx,
                    model.masking,
                    mu,
                    samples,
                    seed,
                ),
                Ndf::Beckmann => sum_generic(
                    estimator,
                    Beckmann { alpha },
                    Ndf::Beckmann,
                    model.masking,
                    mu,
                    samples,
                    seed,
                ),
            };
            (value, samples)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every sampling estimator is unbiased: with many points it lands near the reference, and
    /// its error shrinks as the points grow (checked at a mid-range point where none is
    /// degenerate, for both distributions and maskings).
    #[test]
    fn every_estimator_converges_to_the_reference() {
        for ndf in Ndf::ALL {
            for masking in [Masking::HeightCorrelated, Masking::Separable] {
                let model = Model { ndf, masking };
                let (alpha, mu) = (0.5, 0.6);
                let truth = reference_albedo(model, alpha, mu, &ReferenceSettings::default()).value;
                for estimator in Estimator::ALL {
                    let (value, _) = estimate(estimator, model, alpha, mu, 1 << 16, 1e-10, 7);
                    // Plain MC at 2^16 points: standard deviation below 1e-2 here.
                    assert!(
                        (value - truth).abs() < 2e-2,
                        "{estimator:?} {model:?}: {value} vs {truth}"
                    );
                }
            }
        }
    }

    #[test]
    fn random_numbers_are_uniform_in_the_unit_interval() {
        let mut rng = SplitMix64::new(1);
        let n = 100_000;
        let (mut sum, mut below_quarter) = (0.0, 0);
        for _ in 0..n {
            let u = rng.next_f64();
            assert!((0.0..1.0).contains(&u));
            sum += u;
            below_quarter += usize::from(u < 0.25);
        }
        assert!((sum / n as f64 - 0.5).abs() < 5e-3);
        assert!((below_quarter as f64 / n as f64 - 0.25).abs() < 5e-3);
    }
}
