//! kiln's `mu` axis for the quantities that vary with `mu` on a mirror (the split-sum channels
//! `E_scale` and `E_bias`, the Fresnel-weighted `E_F`): the adaptive coordinate, which follows
//! the grazing layer `mu ~ alpha` ([`crate::integrate::grazing`]) but maps every `mu > 0` to 1
//! at `alpha = 0`, blended with a fixed warp of `mu` that keeps texels for Schlick's
//! `Fc(mu) = (1 - mu)^5` (or the Fresnel factor) on the mirror row and between the rows near it:
//!
//! `t = w A(mu; k, p) + (1 - w) A(mu; 4 alpha, 0.4)`, `A(y; k, p) = (y (1 + k) / (y + k))^p`
//! ([`super::glass_layout::saturation`]), with `w = 0.6`, `k = 0.3`, `p = 0.5`.
//!
//! `t` increases with `mu` at every `alpha` (both parts do), so `mu` at a node is found by
//! bisection; a renderer only ever computes `t` from `mu` (a few operations more than the
//! adaptive axis). The constants were chosen by measured lookup error of point-sampled 32 x 32
//! GGX height-correlated tables (`kiln verify --density 4`, the largest of `E_scale` and `E_bias`,
//! 2026-12-05) over `w` in {0.4, 0.5, 0.6}, `k` in {0.1, 0.3, 1}, `p` in {0.5, 0.7}: 8.3e-3 at the
//! chosen ones, 9.2e-3 to 4.0e-2 elsewhere, against 1.01e-1 on the linear `mu` axis and
//! 9.6e-2 on the sqrt one (where the near-mirror grazing layer of `E_bias` falls between texels).

use super::glass_layout::{INVERSION_STEPS, saturation};
use crate::numerics::bisection::bisect;

/// The constants of the split-sum `mu` axis (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SplitSumLayout {
    /// `w`, the share of the coordinate given to the fixed warp.
    pub share: f64,
    /// `k` of the fixed warp `A(mu; k, p)`.
    pub scale: f64,
    /// `p` of the fixed warp.
    pub power: f64,
}

impl SplitSumLayout {
    /// kiln's split-sum layout.
    pub const KILN: SplitSumLayout = SplitSumLayout {
        share: 0.6,
        scale: 0.3,
        power: 0.5,
    };

    /// The texture coordinate of `mu` at roughness `alpha` (module docs).
    #[must_use]
    pub fn mu_coordinate(&self, mu: f64, alpha: f64) -> f64 {
        self.share * saturation(mu, self.scale, self.power)
            + (1.0 - self.share) * crate::integrate::grazing::t_of_mu(mu, alpha)
    }

    /// `mu` at coordinate `t` (the inverse of [`SplitSumLayout::mu_coordinate`]; at `alpha = 0`,
    /// where the coordinate jumps from 0 to `1 - w` at `mu = 0+`, every `t` up to that jump gives
    /// `mu = 0`).
    #[must_use]
    pub fn mu_at(&self, t: f64, alpha: f64) -> f64 {
        if t <= 0.0 {
            return 0.0;
        }
        if t >= 1.0 {
            return 1.0;
        }
        bisect(0.0, 1.0, INVERSION_STEPS, |mu| {
            self.mu_coordinate(mu, alpha) < t
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The coordinate runs from 0 at `mu = 0` to 1 at `mu = 1` and increases in between at
    /// every roughness, and the inverse gives `mu` back (a wrong branch or constant in either
    /// would not).
    #[test]
    fn the_coordinate_is_monotone_and_its_inverse_gives_mu_back() {
        let l = SplitSumLayout::KILN;
        for alpha in [1e-7, 1e-3, 0.05, 0.3, 1.0] {
            assert_eq!(l.mu_coordinate(0.0, alpha), 0.0);
            assert!((l.mu_coordinate(1.0, alpha) - 1.0).abs() < 1e-15);
            let mut previous = 0.0;
            for j in 1..=1000 {
                let mu = f64::from(j) / 1000.0;
                let t = l.mu_coordinate(mu, alpha);
                assert!(t > previous, "alpha {alpha}, mu {mu}");
                previous = t;
                let back = l.mu_at(t, alpha);
                assert!((back - mu).abs() <= 1e-12 * mu.max(1e-3), "{back} vs {mu}");
            }
        }
        // On the mirror the fixed warp alone resolves mu: Fc's texels are where w A is.
        let t = l.mu_coordinate(0.5, 0.0);
        let want = 0.6 * (0.5f64 * 1.3 / 0.8).sqrt() + 0.4;
        assert!((t - want).abs() < 1e-15, "{t} vs {want}");
    }
}
