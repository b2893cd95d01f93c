//! Masking-shadowing `G2`: Smith's, in the two forms renderers use, and the separable
//! Schlick-GGX approximation engines evaluate.
//!
//! Sources: Heitz 2014, "Understanding the Masking-Shadowing Function in Microfacet-Based BRDFs",
//! eqs. 98 (separable) and 99 (height-correlated); `docs/physics.md`. Schlick-GGX: Schlick 1994's
//! `G1(v) = mu / (mu (1 - k) + k)` with Karis 2013's (UE4) `k = alpha / 2` for image-based
//! lighting, as Godot and the GAMES202 homework evaluate it (`docs/physics.md`, "Masking-shadowing").
//!
//! The estimators sample Smith's visible normals whatever the form, so every form is expressed
//! as the loss `1 - G2 / G1_Smith(o)` of a sample ([`Masking::loss_at`]).

use super::{MicrofacetDistribution, Vec3};
use serde::{Deserialize, Serialize};

/// Which Smith `G2` a table is computed for. Part of a table's identity: a table is only right for
/// the BRDF the renderer evaluates.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum Masking {
    /// `G2 = 1 / (1 + Lambda(o) + Lambda(i))` (pbrt, Cycles, Filament, Unity, Bevy). The default.
    HeightCorrelated,
    /// `G2 = G1(o) G1(i)`.
    Separable,
    /// `G2 = G1(o) G1(i)` with Schlick's `G1(v) = mu / (mu (1 - k) + k)`, `k = alpha / 2`
    /// (separable Schlick-GGX: UE4's image-based lighting, Godot, GAMES202). At `alpha = 1` it
    /// equals Smith's separable GGX exactly (`G1 = 2 mu / (1 + mu)` both).
    #[serde(rename = "schlick-ggx")]
    #[cfg_attr(feature = "cli", value(name = "schlick-ggx"))]
    SchlickGgx,
}

impl Masking {
    /// The two Smith forms, in a fixed order (the forms every property of `docs/physics.md` holds
    /// for; [`Masking::SchlickGgx`] is an approximation engines use).
    pub const ALL: [Masking; 2] = [Masking::HeightCorrelated, Masking::Separable];

    /// The name used on the command line and in files.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Masking::HeightCorrelated => "height-correlated",
            Masking::Separable => "separable",
            Masking::SchlickGgx => "schlick-ggx",
        }
    }

    /// Whether the form is Smith's (expressed through `Lambda` alone).
    #[must_use]
    pub fn is_smith(self) -> bool {
        self != Masking::SchlickGgx
    }

    /// Schlick's `G1(v) = mu / (mu (1 - k) + k)` with `k = alpha / 2`, for `|mu|`.
    #[must_use]
    pub fn schlick_g1(mu: f64, alpha: f64) -> f64 {
        let mu = mu.abs();
        let k = 0.5 * alpha;
        if mu == 0.0 && k == 0.0 {
            return 1.0; // the mirror's limit
        }
        mu / (mu * (1.0 - k) + k)
    }

    /// One minus the visible-normal estimator's weight `G2 / G1_Smith(o)` for a sample whose
    /// outgoing direction `i` is on the right side: [`Masking::loss`] for the Smith forms; for
    /// Schlick-GGX `1 - G1_S(o) G1_S(i) (1 + Lambda(o))` (which may be slightly negative where
    /// Schlick's `G1` exceeds Smith's). `mu_o`, `mu_i`: cosines of `o` and `i` (either sign).
    #[must_use]
    #[inline]
    pub fn loss_at(self, alpha: f64, mu_o: f64, mu_i: f64, lambda_o: f64, lambda_i: f64) -> f64 {
        match self {
            Masking::SchlickGgx => {
                let g2 = Self::schlick_g1(mu_o, alpha) * Self::schlick_g1(mu_i, alpha);
                if lambda_o.is_infinite() {
                    // mu_o = 0: G1_S(o) / G1_Smith(o) tends to a finite ratio; its limit as
                    // mu_o -> 0 is (1 / k) / (2 / alpha) = 1 for k = alpha / 2 (both ~ 2 mu /
                    // alpha), so the weight tends to G1_S(i).
                    return 1.0 - Self::schlick_g1(mu_i, alpha);
                }
                1.0 - g2 * (1.0 + lambda_o)
            }
            _ => self.loss(lambda_o, lambda_i),
        }
    }

    /// `G2(o, i)` from `Lambda(o)` and `Lambda(i)`.
    #[must_use]
    ///
    /// # Panics
    /// For [`Masking::SchlickGgx`], which is not a function of `Lambda` (see
    /// [`Masking::loss_at`]).
    pub fn g2(self, lambda_o: f64, lambda_i: f64) -> f64 {
        match self {
            Masking::HeightCorrelated => 1.0 / (1.0 + lambda_o + lambda_i),
            Masking::Separable => 1.0 / ((1.0 + lambda_o) * (1.0 + lambda_i)),
            Masking::SchlickGgx => panic!("Schlick-GGX's G2 needs the directions: loss_at"),
        }
    }

    /// One minus the visible-normal estimator's weight, `1 - G2 / G1(o)`, for a reflected direction
    /// above the horizon: the energy a single bounce loses for that sample, computed without
    /// cancellation so that `1 - E` keeps its relative precision when it is small.
    ///
    /// Height-correlated: `1 - (1 + Lo) / (1 + Lo + Li) = Li / (1 + Lo + Li)`;
    /// separable: `1 - G1(i) = Li / (1 + Li)`. Infinite `Lambda`s (directions on the horizon) give
    /// the limits: 1 when only `Li` is infinite, 0 whenever `Lo` is (a view on the horizon,
    /// where height-correlated `E = 1`).
    #[must_use]
    pub fn loss(self, lambda_o: f64, lambda_i: f64) -> f64 {
        if lambda_i == 0.0 {
            return 0.0;
        }
        match self {
            Masking::HeightCorrelated => {
                if lambda_o.is_infinite() {
                    0.0
                } else {
                    1.0 / (1.0 + (1.0 + lambda_o) / lambda_i)
                }
            }
            Masking::Separable => 1.0 / (1.0 + 1.0 / lambda_i),
            Masking::SchlickGgx => panic!("Schlick-GGX's loss needs the directions: loss_at"),
        }
    }
}

impl Masking {
    /// [`Masking::loss`] for a direction and its opposite, `Lambda(i) = Lambda(o)` (light passing
    /// straight through an index-matched interface): `L / (1 + 2 L)` height-correlated,
    /// `L / (1 + L)` separable, with their limits 1/2 and 1 as `L -> infinity` (a grazing view);
    /// Schlick-GGX through [`Masking::loss_at`] with `mu_i = mu_o`.
    #[must_use]
    pub fn loss_index_matched(self, alpha: f64, mu: f64, lambda: f64) -> f64 {
        match self {
            Masking::SchlickGgx => self.loss_at(alpha, mu, mu, lambda, lambda),
            _ if lambda == 0.0 => 0.0,
            Masking::HeightCorrelated => 1.0 / (2.0 + 1.0 / lambda),
            Masking::Separable => 1.0 / (1.0 + 1.0 / lambda),
        }
    }
}

impl std::fmt::Display for Masking {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// The loss `1 - w` for the microfacet normal `m`: reflect `o` about it; below the horizon all
/// is lost, above it [`Masking::loss_at`].
#[inline]
#[must_use]
pub fn reflection_loss<N: MicrofacetDistribution>(
    ndf: N,
    masking: Masking,
    o: Vec3,
    lambda_o: f64,
    m: Vec3,
) -> f64 {
    let i = o.reflect(m);
    if i.z > 0.0 {
        masking.loss_at(ndf.alpha(), o.z, i.z, lambda_o, ndf.lambda(i))
    } else {
        1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Schlick's `G1` at the horizon: 0 for any rough surface (`mu / (mu (1 - k) + k)` at
    /// `mu = 0`), 1 for a mirror at every `mu` including the horizon (its limit), and the closed
    /// form between.
    #[test]
    fn schlick_g1_at_the_horizon_and_on_a_mirror() {
        assert_eq!(Masking::schlick_g1(0.0, 0.5), 0.0);
        assert_eq!(Masking::schlick_g1(0.0, 0.0), 1.0);
        assert_eq!(Masking::schlick_g1(0.3, 0.0), 1.0);
        let (mu, k) = (0.3, 0.25);
        assert!((Masking::schlick_g1(-mu, 2.0 * k) - mu / (mu * (1.0 - k) + k)).abs() < 1e-16);
    }

    /// At `alpha = 1`, `k = 1/2`: Schlick's `G1 = mu / (mu / 2 + 1/2) = 2 mu / (1 + mu)`, Smith's
    /// GGX `G1 = 1 / (1 + (1 / mu - 1) / 2)`: the same; so the losses agree with separable.
    #[test]
    fn schlick_ggx_equals_smith_separable_at_alpha_one() {
        use crate::model::{Ggx, MicrofacetDistribution, Vec3};
        let ndf = Ggx { alpha: 1.0 };
        for mu_o in [0.05, 0.3, 0.9, 1.0] {
            for mu_i in [0.01, 0.4, 1.0] {
                let (lo, li) = (
                    ndf.lambda(Vec3::from_mu(mu_o)),
                    ndf.lambda(Vec3::from_mu(mu_i)),
                );
                let schlick = Masking::SchlickGgx.loss_at(1.0, mu_o, mu_i, lo, li);
                let smith = Masking::Separable.loss(lo, li);
                assert!(
                    (schlick - smith).abs() < 1e-14,
                    "{mu_o} {mu_i}: {schlick} {smith}"
                );
            }
        }
    }

    #[test]
    fn loss_is_one_minus_the_weight() {
        for &lo in &[0.0, 1e-9, 0.3, 4.0] {
            for &li in &[1e-12, 0.2, 7.0] {
                for m in Masking::ALL {
                    let g1o = 1.0 / (1.0 + lo);
                    let weight = m.g2(lo, li) / g1o;
                    assert!(
                        (m.loss(lo, li) - (1.0 - weight)).abs() < 1e-15,
                        "{m} {lo} {li}"
                    );
                    assert!((0.0..=1.0).contains(&m.loss(lo, li)));
                }
            }
        }
        assert_eq!(Masking::HeightCorrelated.loss(f64::INFINITY, 3.0), 0.0);
        assert_eq!(Masking::HeightCorrelated.loss(2.0, f64::INFINITY), 1.0);
        assert_eq!(Masking::Separable.loss(2.0, f64::INFINITY), 1.0);
        for m in Masking::ALL {
            for l in [0.0, 1e-9, 0.3, 4.0] {
                assert!((m.loss_index_matched(0.3, 0.5, l) - m.loss(l, l)).abs() < 1e-15);
            }
        }
        assert_eq!(
            Masking::HeightCorrelated.loss_index_matched(0.3, 0.0, f64::INFINITY),
            0.5
        );
        assert_eq!(
            Masking::Separable.loss_index_matched(0.3, 0.0, f64::INFINITY),
            1.0
        );
    }

    /// GGX's `Lambda` in closed form (Heitz 2014, eq. 72), written here apart from the model.
    fn ggx_lambda(alpha: f64, mu: f64) -> f64 {
        let tan2 = (1.0 - mu * mu) / (mu * mu);
        0.5 * (-1.0 + (1.0 + alpha * alpha * tan2).sqrt())
    }

    #[test]
    fn names_are_serdes_and_only_schlick_is_not_smith() {
        for m in [
            Masking::HeightCorrelated,
            Masking::Separable,
            Masking::SchlickGgx,
        ] {
            let serde_name = serde_json::to_string(&m).unwrap();
            assert_eq!(serde_name, format!("\"{}\"", m.name()));
            assert_eq!(m.to_string(), m.name());
            assert_eq!(m.is_smith(), m != Masking::SchlickGgx);
        }
    }

    /// Schlick-GGX's loss is `1 - G1_S(o) G1_S(i) / G1_Smith(o)`, worked from the closed forms;
    /// at a view on the horizon, its limit `1 - G1_S(i)`.
    #[test]
    fn schlick_ggx_loss_against_its_closed_form() {
        let g1_s = |mu: f64, alpha: f64| {
            let k = alpha / 2.0;
            mu / (mu * (1.0 - k) + k)
        };
        for alpha in [0.1, 0.5, 1.3] {
            for (mu_o, mu_i) in [(0.2, 0.7), (0.9, 0.05), (0.5, 0.5)] {
                let (lo, li) = (ggx_lambda(alpha, mu_o), ggx_lambda(alpha, mu_i));
                let smith_g1_o = 1.0 / (1.0 + lo);
                let expected = 1.0 - g1_s(mu_o, alpha) * g1_s(mu_i, alpha) / smith_g1_o;
                let loss = Masking::SchlickGgx.loss_at(alpha, mu_o, mu_i, lo, li);
                assert!((loss - expected).abs() < 1e-15, "{alpha} {mu_o} {mu_i}");
                // The Smith forms take no notice of the cosines.
                for m in Masking::ALL {
                    assert_eq!(m.loss_at(alpha, mu_o, mu_i, lo, li), m.loss(lo, li));
                }
            }
            let horizon = Masking::SchlickGgx.loss_at(alpha, 0.0, 0.3, f64::INFINITY, 0.1);
            assert!((horizon - (1.0 - g1_s(0.3, alpha))).abs() < 1e-15);
            let matched =
                Masking::SchlickGgx.loss_index_matched(alpha, 0.4, ggx_lambda(alpha, 0.4));
            let expected =
                1.0 - g1_s(0.4, alpha) * g1_s(0.4, alpha) * (1.0 + ggx_lambda(alpha, 0.4));
            assert!((matched - expected).abs() < 1e-15);
        }
        // Separable G2 and height-correlated G2 by their formulas.
        assert!((Masking::Separable.g2(0.5, 3.0) - 1.0 / (1.5 * 4.0)).abs() < 1e-16);
        assert!((Masking::HeightCorrelated.g2(0.5, 3.0) - 1.0 / 4.5).abs() < 1e-16);
    }

    #[test]
    #[should_panic(expected = "needs the directions")]
    fn schlick_ggx_has_no_g2_of_lambdas_alone() {
        let _ = Masking::SchlickGgx.g2(0.1, 0.2);
    }

    #[test]
    #[should_panic(expected = "needs the directions")]
    fn schlick_ggx_has_no_loss_of_lambdas_alone() {
        let _ = Masking::SchlickGgx.loss(0.1, 0.2);
    }

    /// Reflected about the normal, `o` stays above and loses what the masking says; reflected
    /// about a facet that sends it below the horizon, it is lost.
    #[test]
    fn reflection_loss_by_the_side_the_light_leaves_on() {
        use crate::model::{Ggx, Vec3};
        let alpha = 0.6;
        let ndf = Ggx { alpha };
        let mu = 0.5;
        let o = Vec3::from_mu(mu);
        let lo = ggx_lambda(alpha, mu);
        let up = Vec3 {
            x: 0.0,
            y: 0.0,
            z: 1.0,
        };
        // The mirror direction: Lambda(i) = Lambda(o), so the height-correlated loss is
        // L / (1 + 2 L).
        let loss = reflection_loss(ndf, Masking::HeightCorrelated, o, lo, up);
        assert!((loss - lo / (1.0 + 2.0 * lo)).abs() < 1e-14, "{loss}");
        let loss = reflection_loss(ndf, Masking::SchlickGgx, o, lo, up);
        let k = alpha / 2.0;
        let g1_s = mu / (mu * (1.0 - k) + k);
        assert!((loss - (1.0 - g1_s * g1_s * (1.0 + lo))).abs() < 1e-14);
        // A facet tilted 60 degrees away from o sends it straight down: all lost.
        let tilted = Vec3 {
            x: -(0.75f64.sqrt()),
            y: 0.0,
            z: 0.5,
        };
        assert!(o.reflect(tilted).z < 0.0);
        assert_eq!(reflection_loss(ndf, Masking::Separable, o, lo, tilted), 1.0);
    }
}
