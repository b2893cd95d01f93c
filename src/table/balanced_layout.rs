//! kiln's balanced layout of the tables over `(roughness, mu)` (issue 39): texture coordinates
//! placed so that the bilinear lookup of texels fitted for it ([`super::lookup_fit`]) has about
//! the same largest error everywhere, rather than the adaptive axis' (which resolves the
//! grazing layer `mu ~ alpha` and leaves the rest to chance).
//!
//! What the measured error of a fitted 32 x 32 `E` says about kiln's adaptive layout
//! (`examples/lookup_axes.rs`, GGX height-correlated, 281,220 reference points): its worst
//! texels are between `mu = 0.85` and 1 at `r ~ 0.45`, where `E` bends fastest in roughness
//! (`d^2 E / dr^2 ~ -4` at `mu = 1`, `r` 0.5 to 0.6, the knee where single-scattering loss sets
//! in), while it spends a fifth of its `mu` texels below `mu = 0.01` at `r = 0.45`, where the
//! lookup is 5 times better than its maximum. The balanced layout:
//!
//! - **`mu`:** `t = (g(u + eps) - g(eps)) / (g(1 + eps) - g(eps))`, `g(x) = x^p`, of the
//!   adaptive axis' Möbius coordinate `u = mu (1 + k) / (mu + k)`, with a scale that grows with
//!   roughness, `k = c alpha (1 + e alpha)` (so `mu` near 1 keeps more texels at moderate
//!   roughness) and an offset `eps = (z / 32) (32 / N)^w exp(-y alpha)` that makes `t` linear in
//!   `mu` right at grazing, over about a texel (so that the first texel is not spent on
//!   `mu < 1e-4`). To `O(alpha)` the coordinate is still a function of `mu / alpha` at small
//!   `alpha`, so the grazing layer keeps its texels at every roughness, and the row
//!   `alpha = 0` holds the layer's limit as on the adaptive axis.
//! - **roughness:** `t_r = (1 - m) P(r) + m r^2 (3 - 2 r)` (`r = sqrt(alpha)`, perceptual), `P`
//!   the power `r^q` turned into a multiple of `alpha` below `r ~ d`
//!   ([`BalancedLayout::roughness_coordinate`]): more rows through the knee, fewer near the
//!   mirror, where `E` depends on `mu / alpha` alone.
//!
//! Both coordinates increase with their variable and reach 0 and 1 at the axis ends; a lookup
//! computes them in closed form, a bake inverts them (the `mu` coordinate in closed form, the
//! roughness by bisection). The constants were chosen by the measured maximum error of the
//! fitted 31-, 32- and 33-texel `E` tables, with the 16-, 64- and 128-texel ones no worse than
//! on the adaptive layout (`examples/lookup_axes.rs` measures any candidate).

use crate::numerics::bisection::bisect;

/// The constants of a balanced layout (module docs); [`BalancedLayout::KILN`] is kiln's, the
/// one the `balanced` mappings use.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BalancedLayout {
    /// `c`: the grazing layer's scale `k = c alpha (1 + e alpha)` in units of `alpha`.
    pub scale: f64,
    /// `e`: how the scale grows with roughness.
    pub scale_growth: f64,
    /// `p`: the power that spreads `mu`'s texels toward grazing.
    pub power: f64,
    /// `z`: the grazing offset `eps` at 32 samples and `alpha = 0`, times 32.
    pub offset: f64,
    /// `w`: how the offset shrinks with the size, `(32 / N)^w`.
    pub offset_size_power: f64,
    /// `y`: how the offset fades with roughness, `exp(-y alpha)`.
    pub offset_decay: f64,
    /// `q`: the roughness coordinate's power of `r`.
    pub roughness_power: f64,
    /// `m`: the share of the smoothstep `r^2 (3 - 2 r)` in the roughness coordinate.
    pub roughness_knee: f64,
    /// `d`: below `r ~ d` the power of `r` turns into a multiple of `alpha = r^2` (see
    /// [`BalancedLayout::roughness_coordinate`]).
    pub roughness_offset: f64,
}

impl BalancedLayout {
    /// kiln's balanced layout.
    pub const KILN: BalancedLayout = BalancedLayout {
        scale: 3.0,
        scale_growth: 7.0,
        power: 0.4,
        offset: 1.25,
        offset_size_power: 1.5,
        offset_decay: 3.0,
        roughness_power: 1.37,
        roughness_knee: 0.4,
        roughness_offset: 0.02,
    };

    /// The grazing layer's scale `k` at slope-space roughness `alpha`.
    #[must_use]
    pub fn scale_at(&self, alpha: f64) -> f64 {
        self.scale * alpha * (1.0 + self.scale_growth * alpha)
    }

    /// The grazing offset `eps` at `alpha` on an axis of `size` samples.
    #[must_use]
    pub fn offset_at(&self, alpha: f64, size: usize) -> f64 {
        let n = size.max(1) as f64;
        self.offset / 32.0
            * (32.0 / n).powf(self.offset_size_power)
            * (-self.offset_decay * alpha).exp()
    }

    /// The texture coordinate of `mu` at `alpha` on an axis of `size` samples: 0 at `mu = 0`,
    /// 1 at `mu = 1`, and at `alpha = 0` 1 for every `mu > 0` (the mirror).
    #[must_use]
    pub fn mu_coordinate(&self, mu: f64, alpha: f64, size: usize) -> f64 {
        if mu <= 0.0 {
            return 0.0;
        }
        let k = self.scale_at(alpha);
        let u = if k <= 0.0 {
            1.0
        } else {
            (mu * (1.0 + k) / (mu + k)).min(1.0)
        };
        let eps = self.offset_at(alpha, size);
        let (low, high) = (eps.powf(self.power), (1.0 + eps).powf(self.power));
        (((u + eps).powf(self.power) - low) / (high - low)).clamp(0.0, 1.0)
    }

    /// `mu` at texture coordinate `t` (the inverse of [`BalancedLayout::mu_coordinate`]; 0 for
    /// every `t < 1` at `alpha = 0`, where the row holds a limit, `TableSpec::texel_point`).
    #[must_use]
    pub fn mu_at(&self, t: f64, alpha: f64, size: usize) -> f64 {
        if t >= 1.0 {
            return 1.0;
        }
        if t <= 0.0 {
            return 0.0;
        }
        let eps = self.offset_at(alpha, size);
        let (low, high) = (eps.powf(self.power), (1.0 + eps).powf(self.power));
        let u = ((t * (high - low) + low).powf(1.0 / self.power) - eps).clamp(0.0, 1.0);
        let k = self.scale_at(alpha);
        (u * k / (1.0 + k - u)).clamp(0.0, 1.0)
    }

    /// The texture coordinate of perceptual roughness `r` in [0, 1]: `(1 - m) P(r) + m r^2 (3 -
    /// 2 r)` with `P(r) = ((r^2 + d^2)^(q/2) - d^q) / ((1 + d^2)^(q/2) - d^q)`, which is `r^q`
    /// (normalised) above `r ~ d` and proportional to `alpha = r^2` below: there a fitted
    /// table's `1 - Ē` grows like `alpha`, and so does the coordinate that `f_ms_norm` divides
    /// it by ([`crate::table::normalisation`]).
    #[must_use]
    pub fn roughness_coordinate(&self, r: f64) -> f64 {
        let r = r.clamp(0.0, 1.0);
        let p = self.roughness_power_terms();
        let power = ((r * r + p.offset_squared).powf(p.half_power) - p.low) / p.scale;
        let m = self.roughness_knee;
        (1.0 - m) * power + m * r * r * (3.0 - 2.0 * r)
    }

    /// The constants of `P(r) = ((r^2 + d^2)^(q/2) - d^q) / ((1 + d^2)^(q/2) - d^q)`, as the
    /// generated lookups write them.
    #[must_use]
    pub fn roughness_power_terms(&self) -> PowerTerms {
        let (q, d) = (self.roughness_power, self.roughness_offset);
        // (d^2)^(q/2) as P computes it, so that P(0) is exactly 0.
        let low = (d * d).powf(q / 2.0);
        PowerTerms {
            offset_squared: d * d,
            half_power: q / 2.0,
            low,
            scale: (1.0 + d * d).powf(q / 2.0) - low,
        }
    }

    /// Perceptual roughness `r` at texture coordinate `t` (the inverse of
    /// [`BalancedLayout::roughness_coordinate`], by bisection to f64).
    #[must_use]
    pub fn roughness_at(&self, t: f64) -> f64 {
        if t <= 0.0 {
            return 0.0;
        }
        if t >= 1.0 {
            return 1.0;
        }
        bisect(0.0, 1.0, 64, |r| self.roughness_coordinate(r) < t)
    }
}

/// `P(r) = ((r^2 + offset_squared)^half_power - low) / scale`
/// ([`BalancedLayout::roughness_power_terms`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PowerTerms {
    pub offset_squared: f64,
    pub half_power: f64,
    pub low: f64,
    pub scale: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    const L: BalancedLayout = BalancedLayout::KILN;

    /// The coordinates reach their ends, increase, and the inversions give back the point.
    #[test]
    fn coordinates_invert_and_increase() {
        for &alpha in &[0.0, 1e-7, 1e-3, 0.04, 0.25, 1.0] {
            for &size in &[8, 32, 128] {
                assert_eq!(L.mu_coordinate(0.0, alpha, size), 0.0);
                assert!((L.mu_coordinate(1.0, alpha, size) - 1.0).abs() < 1e-15);
                let mut last = 0.0;
                for k in 1..=200 {
                    let t = f64::from(k) / 200.0;
                    let mu = L.mu_at(t, alpha, size);
                    if alpha > 0.0 {
                        assert!(mu > last || t == 1.0, "mu {mu} at t {t}, alpha {alpha}");
                        let back = L.mu_coordinate(mu, alpha, size);
                        assert!((back - t).abs() < 1e-9, "t {t} -> mu {mu} -> {back}");
                    }
                    last = mu;
                }
            }
        }
        for k in 0..=100 {
            let r = f64::from(k) / 100.0;
            let t = L.roughness_coordinate(r);
            assert!((L.roughness_at(t) - r).abs() < 1e-12, "r {r}");
            if k > 0 {
                assert!(t > L.roughness_coordinate(r - 0.01));
            }
        }
        assert_eq!(L.roughness_coordinate(0.0), 0.0);
        assert!((L.roughness_coordinate(1.0) - 1.0).abs() < 1e-15);
    }

    /// A worked point: `r = 0.5` (`alpha = 0.25`), `mu = 0.5`, 32 samples, from the formulas.
    #[test]
    fn a_worked_point() {
        let (alpha, mu) = (0.25f64, 0.5f64);
        let k = 3.0 * alpha * (1.0 + 7.0 * alpha);
        let u = mu * (1.0 + k) / (mu + k);
        let eps = 1.25 / 32.0 * (-3.0 * alpha).exp();
        let t = ((u + eps).powf(0.4) - eps.powf(0.4)) / ((1.0 + eps).powf(0.4) - eps.powf(0.4));
        assert!((L.mu_coordinate(mu, alpha, 32) - t).abs() < 1e-15);
        let d2 = 0.02f64 * 0.02;
        let power = ((0.25 + d2).powf(0.685) - 0.02f64.powf(1.37))
            / ((1.0 + d2).powf(0.685) - 0.02f64.powf(1.37));
        let t_r = 0.6 * power + 0.4 * 0.25 * 2.0;
        assert!((L.roughness_coordinate(0.5) - t_r).abs() < 1e-15);
    }
}
