//! kiln's layout of a glass table at one IOR (issue 61): the `mu` coordinate of the energy albedo
//! `R + T` of a rough dielectric at one relative index `eta`, over (roughness, `mu`), for the
//! bilinear lookup of fitted texels.
//!
//! Two features a lookup must follow:
//!
//! - **The grazing layer**: from outside `E(0) = 1` at every roughness, and `1 - E` rises like a
//!   power of `mu` below `mu ~ 1e-3` (at `eta = 1.5`, `alpha = 0.75`: 1.8e-3 at `mu = 1e-4`,
//!   1.2e-2 at `1e-3`), more steeply than `E`'s, and ever more so as `eta -> 1`. The base is
//!   kiln's balanced coordinate `B(mu)` (`table::balanced_layout`, the one `E` is fitted on) with
//!   its offset `eps` a tenth of `E`'s ([`OneIorLayout::offset_factor`]), which keeps texels
//!   down to `mu ~ 1e-4`.
//! - **The critical angle**, from inside (`eta < 1`): total internal reflection begins at
//!   `mu_c = sqrt(1 - eta^2)`, and the albedo bends there over a width about `alpha` (sharply on
//!   a near-mirror). A share `w_c` of the coordinate is a smooth step centred there,
//!   `C(mu) = (atan((mu - mu_c) / s) - atan(-mu_c / s)) / (atan((1 - mu_c) / s) - atan(-mu_c /
//!   s))`, `s = c_c alpha + s_0`.
//!
//! - **Normal incidence at high roughness**, from inside: there `E` is about 0.44 at `r = 1`
//!   and curved in `mu` (`E'' ~ 3`), and the lookup's relative error peaked (1.2e-3 at 1.5). A
//!   share `w_t alpha^2` is a step `T(mu)` toward `mu = 1`, as `C` with its centre at 1 and width
//!   `s_t`.
//!
//! `t = w_c C(mu) + w_t alpha^2 T(mu) + (1 - w_c - w_t alpha^2) B(mu)` (`w_c = w_t = 0` from
//! outside). Every part rises from 0 at `mu = 0` to 1 at `mu = 1`, so `t` does; a lookup computes
//! it in closed form, a bake inverts it by bisection. The constants were chosen by the Turquin furnace of fitted 32 x 32 tables
//! (`kiln bake --quantity e-dielectric,e-dielectric-inside --ior X`, then `kiln furnace`),
//! measured 2026-12-08 against the balanced axis itself: from outside at 1.05 1.0e-3 (balanced
//! 8.1e-3), at 1.5 9.0e-4 (8.8e-4); from inside at 1.2 9.2e-4 (2.1e-3), at 1.5 8.4e-4
//! (2.1e-3), at 3 8.1e-4 (2.5e-3). The step at normal incidence took 1.5 from 1.2e-3 to 8.4e-4
//! and cost the indices next to 1 (1.05: 4.6e-3 to 6.3e-3; 1.1: 1.8e-3 to 2.0e-3; at
//! `w_t = 0.3`, 3.3e-3 at 1.1). An eta layer as kiln's glass layout has over the IOR
//! (`table::glass_layout`) made the grazing views worse at one IOR (1.9e-3 from outside at 1.5;
//! 3.4e-3 at 1.05 beside the smaller offset).

use super::balanced_layout::BalancedLayout;
use crate::numerics::bisection::bisect;

/// The constants of the one-IOR layout (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OneIorLayout {
    /// `w_c`: the critical angle's share, from inside.
    pub critical_share: f64,
    /// `c_c`: the critical step's width per unit `alpha`.
    pub critical_scale: f64,
    /// `s_0`: the critical step's width on a mirror.
    pub critical_floor: f64,
    /// `w_t`: from inside, the share of a step at normal incidence, `w_t alpha^2` of the
    /// coordinate (`alpha` up to 1).
    pub top_share: f64,
    /// `s_t`: the width of the step at normal incidence.
    pub top_width: f64,
    /// The balanced coordinate's offset `eps` as a multiple of `E`'s
    /// ([`BalancedLayout::KILN`]): below 1, more texels at the most grazing views.
    pub offset_factor: f64,
}

/// Halvings of the inversion: `mu` to about 1e-18, below f64's resolution of `mu` near 1.
const INVERSION_STEPS: u32 = 60;

impl OneIorLayout {
    /// kiln's one-IOR layout. Measured beside it (module docs' bakes, one run each): offsets of
    /// 0.05 and 0.2 times `E`'s (1.2e-3 and 2.1e-3 from outside at 1.05; 0.01: 2.4e-3); from
    /// inside a share of 0.3 with a step half as wide (1.1e-3 at 1.5, 6.2e-3 at 1.05 against
    /// 4.6e-3).
    pub const KILN: OneIorLayout = OneIorLayout {
        critical_share: 0.2,
        critical_scale: 1.0,
        critical_floor: 0.01,
        offset_factor: 0.1,
        top_share: 0.15,
        top_width: 0.3,
    };

    /// The base coordinate `B`: kiln's balanced one with its offset scaled.
    #[must_use]
    pub fn base(&self) -> BalancedLayout {
        BalancedLayout {
            offset: BalancedLayout::KILN.offset * self.offset_factor,
            ..BalancedLayout::KILN
        }
    }

    /// The critical angle's share at relative index `eta`: `w_c` from inside (`eta < 1`), 0
    /// from outside.
    #[must_use]
    pub fn critical_share_at(&self, eta: f64) -> f64 {
        if eta < 1.0 { self.critical_share } else { 0.0 }
    }

    /// The cosine of the critical angle at relative index `eta < 1`, `sqrt(1 - eta^2)`.
    #[must_use]
    pub fn critical_mu(eta: f64) -> f64 {
        (1.0 - eta * eta).max(0.0).sqrt()
    }

    /// The critical step's width `s = c_c alpha + s_0`.
    #[must_use]
    pub fn critical_width(&self, alpha: f64) -> f64 {
        self.critical_scale * alpha + self.critical_floor
    }

    /// The critical step `C(mu)` at `(alpha, eta)`, `eta < 1` (module docs).
    #[must_use]
    pub fn critical_step(&self, mu: f64, alpha: f64, eta: f64) -> f64 {
        let centre = Self::critical_mu(eta);
        let width = self.critical_width(alpha);
        let at = |x: f64| ((x - centre) / width).atan();
        let (low, high) = (at(0.0), at(1.0));
        ((at(mu.clamp(0.0, 1.0)) - low) / (high - low)).clamp(0.0, 1.0)
    }

    /// The step at normal incidence's factor `w_t` at relative index `eta`: `w_t` from inside,
    /// 0 from outside (its share at `alpha` is this times `min(alpha, 1)^2`).
    #[must_use]
    pub fn top_share_for(&self, eta: f64) -> f64 {
        if eta < 1.0 { self.top_share } else { 0.0 }
    }

    /// The share of the step at normal incidence at `alpha`, from inside: `w_t min(alpha, 1)^2`.
    #[must_use]
    pub fn top_share_at(&self, alpha: f64) -> f64 {
        self.top_share * alpha.min(1.0).powi(2)
    }

    /// The step at normal incidence `T(mu) = (atan((mu - 1) / s_t) - atan(-1 / s_t)) /
    /// (-atan(-1 / s_t))` (module docs).
    #[must_use]
    pub fn top_step(&self, mu: f64) -> f64 {
        let at = |x: f64| ((x - 1.0) / self.top_width).atan();
        ((at(mu.clamp(0.0, 1.0)) - at(0.0)) / (at(1.0) - at(0.0))).clamp(0.0, 1.0)
    }

    /// The coordinate `t` of `mu` at roughness `alpha` and relative index `eta` on an axis of
    /// `size` samples: 0 at `mu = 0`, 1 at `mu = 1`.
    #[must_use]
    pub fn mu_coordinate(&self, mu: f64, alpha: f64, eta: f64, size: usize) -> f64 {
        let w_c = self.critical_share_at(eta);
        let base = self.base().mu_coordinate(mu, alpha, size);
        if w_c > 0.0 {
            let w_t = self.top_share_at(alpha);
            ((1.0 - w_c - w_t) * base
                + w_c * self.critical_step(mu, alpha, eta)
                + w_t * self.top_step(mu))
            .clamp(0.0, 1.0)
        } else {
            base
        }
    }

    /// `mu` at coordinate `t` (the inverse of [`OneIorLayout::mu_coordinate`]).
    #[must_use]
    pub fn mu_at(&self, t: f64, alpha: f64, eta: f64, size: usize) -> f64 {
        if t <= 0.0 {
            return 0.0;
        }
        if t >= 1.0 {
            return 1.0;
        }
        if self.critical_share_at(eta) == 0.0 {
            return self.base().mu_at(t, alpha, size);
        }
        bisect(0.0, 1.0, INVERSION_STEPS, |mu| {
            self.mu_coordinate(mu, alpha, eta, size) < t
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The coordinate rises from 0 to 1 on both sides, the inversion gives `mu` back, and from
    /// inside the step puts more of `t` around the critical angle than the base alone: the
    /// slope there is `w_c / (s (atan((1 - mu_c) / s) - atan(-mu_c / s)))` above the base's
    /// share of it (beside the step at normal incidence's small share), worked at `eta = 1 /
    /// 1.5`, `alpha = 0.1` (`mu_c = sqrt(5) / 3`).
    #[test]
    fn the_coordinate_rises_inverts_and_gathers_at_the_critical_angle() {
        let l = OneIorLayout::KILN;
        for eta in [1.5, 1.0 / 1.5, 1.05, 1.0 / 3.0] {
            for alpha in [0.0, 1e-3, 0.1, 1.0] {
                assert_eq!(l.mu_coordinate(0.0, alpha, eta, 32), 0.0);
                assert!((l.mu_coordinate(1.0, alpha.max(1e-7), eta, 32) - 1.0).abs() < 1e-12);
                let mut last = 0.0;
                for k in 1..=200 {
                    let mu = f64::from(k) / 200.0;
                    let t = l.mu_coordinate(mu, alpha.max(1e-7), eta, 32);
                    assert!(t >= last, "{eta} {alpha} {mu}");
                    last = t;
                    // The inversion gives a mu of the same coordinate (near a mirror every
                    // mu > 0 maps close to t = 1, so mu itself is ill-conditioned there).
                    let back = l.mu_at(t, alpha.max(1e-7), eta, 32);
                    let again = l.mu_coordinate(back, alpha.max(1e-7), eta, 32);
                    assert!((again - t).abs() < 1e-12, "{eta} {alpha} {mu}: {back}");
                    if alpha >= 0.1 {
                        assert!((back - mu).abs() < 1e-9, "{eta} {alpha} {mu}: {back}");
                    }
                }
            }
        }
        let (eta, alpha) = (1.0 / 1.5, 0.1);
        let mu_c = 5f64.sqrt() / 3.0;
        assert!((OneIorLayout::critical_mu(eta) - mu_c).abs() < 1e-15);
        let h = 1e-6;
        let slope = |f: &dyn Fn(f64) -> f64| (f(mu_c + h) - f(mu_c - h)) / (2.0 * h);
        let whole = slope(&|mu| l.mu_coordinate(mu, alpha, eta, 32));
        let base = slope(&|mu| l.base().mu_coordinate(mu, alpha, 32));
        let s = 0.1 + 0.01;
        let step = 1.0 / (s * (((1.0 - mu_c) / s).atan() - (-mu_c / s).atan()));
        // The step at normal incidence, share 0.15 alpha^2, width 0.3.
        let w_t = 0.15 * alpha * alpha;
        let x = (mu_c - 1.0) / 0.3;
        let top = 1.0 / (0.3 * (1.0 + x * x) * (1.0 / 0.3f64).atan());
        assert!(
            (whole - ((0.8 - w_t) * base + 0.2 * step + w_t * top)).abs() < 1e-6 * whole,
            "{whole}"
        );
        assert!(whole > 1.5 * base, "{whole} {base}");
        // From outside the base alone: balanced with a tenth of the offset.
        let outside = l.mu_coordinate(0.3, alpha, 1.5, 32);
        assert_eq!(outside, l.base().mu_coordinate(0.3, alpha, 32));
    }
}
