//! Smith masking-shadowing `G2`, in the two forms renderers use.
//!
//! Source: Heitz 2014, "Understanding the Masking-Shadowing Function in Microfacet-Based BRDFs",
//! eqs. 98 (separable) and 99 (height-correlated); `physics.md`.

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
}

impl Masking {
    /// Every form, in a fixed order.
    pub const ALL: [Masking; 2] = [Masking::HeightCorrelated, Masking::Separable];

    /// The name used on the command line and in files.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Masking::HeightCorrelated => "height-correlated",
            Masking::Separable => "separable",
        }
    }

    /// `G2(o, i)` from `Lambda(o)` and `Lambda(i)`.
    #[must_use]
    pub fn g2(self, lambda_o: f64, lambda_i: f64) -> f64 {
        match self {
            Masking::HeightCorrelated => 1.0 / (1.0 + lambda_o + lambda_i),
            Masking::Separable => 1.0 / ((1.0 + lambda_o) * (1.0 + lambda_i)),
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
        }
    }
}

impl Masking {
    /// [`Masking::loss`] for a direction and its opposite, `Lambda(i) = Lambda(o)` (light passing
    /// straight through an index-matched interface): `L / (1 + 2 L)` height-correlated,
    /// `L / (1 + L)` separable, with their limits 1/2 and 1 as `L -> infinity` (a grazing view).
    #[must_use]
    pub fn loss_index_matched(self, lambda: f64) -> f64 {
        if lambda == 0.0 {
            return 0.0;
        }
        match self {
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

#[cfg(test)]
mod tests {
    use super::*;

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
                assert!((m.loss_index_matched(l) - m.loss(l, l)).abs() < 1e-15);
            }
        }
        assert_eq!(
            Masking::HeightCorrelated.loss_index_matched(f64::INFINITY),
            0.5
        );
        assert_eq!(Masking::Separable.loss_index_matched(f64::INFINITY), 1.0);
    }
}
