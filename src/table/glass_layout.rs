//! kiln's own glass layout (issue 38): texture coordinates for the dielectric tables over
//! `(eta, roughness, mu)` that follow the layers a product grid cannot, so that a renderer's
//! trilinear lookup stays close to the energy albedo `R + T` near `eta = 1`.
//!
//! What the layout follows (measured with `examples/glass_layout.rs`, `docs/physics.md`
//! "Glass near eta = 1"):
//!
//! - **The eta layer in `mu`.** For light from outside, `E(0) = 1` for every `eta > 1`, while
//!   the limit `eta -> 1+` at fixed `mu > 0` is `(1 + Lambda(mu)) / (1 + 2 Lambda(mu))` (0.533 at
//!   `alpha = 1`, `mu = 1/15`): `E` falls from 1 to that curve over a layer of width about
//!   `(eta - 1) / alpha` in `mu` (`sqrt(eta - 1)` on a mirror). The `mu` coordinate gives that
//!   layer a share `w` of `t` while it stands apart from the masking layer,
//!   `w = w_0 / (1 + (eta - 1) / (d alpha^2))`:
//!   `t = w A(mu; kappa, p_e) + (1 - w) A(mu; 4 alpha, 0.4)`, with
//!   `A(mu; k, p) = (mu (1 + k) / (mu + k))^p` (kiln's adaptive axis is `A(mu; 4 alpha, 0.4)`,
//!   [`crate::integrate::grazing`]) and `kappa = c_e (eta - 1) / (alpha + s sqrt(eta - 1))`.
//! - **The regime change at `eta - 1 ~ alpha^2`**, where that layer merges with the masking
//!   layer `mu ~ alpha`: the IOR coordinate is tied to `alpha^2`,
//!   `z = b A(x; c_z alpha^2, q) + (1 - b) x^q` with `x = u(eta) / u(eta_max)`,
//!   `u(eta) = (eta - 1) / (eta + 1)` (`x^(1/2)` is Cycles' `z`, the fourth root of `F0`, scaled).
//!   At every roughness a share of the IOR texels lies below `eta - 1 ~ alpha^2`.
//! - **`eta = 1` itself** is a discontinuity of a renderer's convention (an exactly index-matched
//!   interface is passed straight through), not of the albedo tabulated: the `z = 0` slice holds
//!   the one-sided limit `eta -> 1+` at fixed texture coordinates. Above the eta layer
//!   (`t > w`) that limit is the albedo at `eta = 1` itself (the layer's part of `t` saturates);
//!   inside it, the layer's profile, computed at `eta - 1 =` [`LIMIT_ETA_OFFSET`] `alpha^2` (its
//!   reciprocal for light from inside) and at `alpha >=` [`LAYER_ROW_LIMIT_ALPHA`]. The row
//!   `alpha = 0` holds the limit `alpha -> 0+`, computed at [`ROW_LIMIT_ALPHA`].
//!   [`crate::table::TableSpec::texel_point`] says where each texel is computed.
//!
//! Both coordinates are increasing in their variable and reach 0 and 1 at the axis ends; a
//! lookup computes them in closed form from `(mu, alpha, eta)`, a bake inverts them by
//! bisection. The constants were chosen by measured furnace error at 16^3
//! (`examples/glass_layout.rs` measures any candidate: `-- 16 out w=0.2 d=0 pe=0.5 b=0.5`, the
//! first one, 9.4e-2 next to `eta = 1` and 4.6e-3 above 1.5 on its audit points; kiln's,
//! `-- 16 out`, 6.9e-2 and 3.2e-3).

use crate::numerics::bisection::bisect;

/// The constants of a glass layout (module docs); [`GlassLayout::KILN`] is kiln's, the one
/// the `glass` mappings use. A value, so that candidates can be measured against it
/// (`examples/glass_layout.rs`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GlassLayout {
    /// `w`: the share of the `mu` coordinate given to the eta layer where `eta - 1 << alpha^2`.
    pub layer_share: f64,
    /// `d`: the eta layer's share falls as `w / (1 + (eta - 1) / (d alpha^2))`, so that where
    /// the eta layer has merged with the masking layer (`eta - 1 >> alpha^2`) the coordinate is
    /// kiln's adaptive one; 0 keeps the share `w` at every index.
    pub layer_share_decay: f64,
    /// `c_e`: the eta layer's width `kappa = c_e (eta - 1) / (alpha + s sqrt(eta - 1))`.
    pub layer_scale: f64,
    /// `s`: the weight of `sqrt(eta - 1)` in the eta layer's width (the mirror's Fresnel layer).
    pub layer_sqrt_weight: f64,
    /// `p_e`: the power that spreads the eta layer's texels toward `mu = 0`.
    pub layer_power: f64,
    /// `q`: the IOR coordinate's power of `x = u(eta) / u(eta_max)` (1/2: Cycles' `z`).
    pub ior_power: f64,
    /// `c_z`: where the IOR coordinate's roughness-tied part puts `eta - 1 ~ c_z alpha^2`.
    pub ior_scale: f64,
    /// `b`: the share of the IOR coordinate tied to roughness.
    pub ior_share: f64,
}

impl GlassLayout {
    /// kiln's glass layout.
    pub const KILN: GlassLayout = GlassLayout {
        layer_share: 0.3,
        layer_share_decay: 1.0,
        layer_scale: 1.0,
        layer_sqrt_weight: 1.0,
        layer_power: 0.35,
        ior_power: 0.5,
        ior_scale: 0.3,
        ior_share: 0.35,
    };

    /// The IOR coordinate `z` of `eta` (either side: `eta < 1` is read at `1 / eta`) on an axis
    /// up to `eta_max`, at slope-space roughness `alpha` (module docs).
    #[must_use]
    pub fn ior_coordinate(&self, eta: f64, eta_max: f64, alpha: f64) -> f64 {
        let x = (reflectance_root(eta) / reflectance_root(eta_max)).min(1.0);
        self.ior_coordinate_of_x(x, alpha)
    }

    fn ior_coordinate_of_x(&self, x: f64, alpha: f64) -> f64 {
        self.ior_share * saturation(x, self.ior_scale * alpha * alpha, self.ior_power)
            + (1.0 - self.ior_share) * x.powf(self.ior_power)
    }

    /// The index `eta >= 1` at IOR coordinate `z` at roughness `alpha` (the inverse of
    /// [`GlassLayout::ior_coordinate`]): 1 at `z = 0`, `eta_max` at `z = 1`.
    #[must_use]
    pub fn ior_at(&self, z: f64, eta_max: f64, alpha: f64) -> f64 {
        if z <= 0.0 {
            return 1.0;
        }
        if z >= 1.0 {
            return eta_max;
        }
        let x = bisect(0.0, 1.0, INVERSION_STEPS, |x| {
            self.ior_coordinate_of_x(x, alpha) < z
        });
        let u = x * reflectance_root(eta_max);
        (1.0 + u) / (1.0 - u)
    }

    /// The eta layer's width `kappa = c_e (eta - 1) / (alpha + s sqrt(eta - 1))` for the axis
    /// index `eta_up >= 1`.
    #[must_use]
    pub fn layer_width(&self, alpha: f64, eta_up: f64) -> f64 {
        let excess = (eta_up - 1.0).max(0.0);
        if excess == 0.0 {
            return 0.0;
        }
        self.layer_scale * excess / (alpha + self.layer_sqrt_weight * excess.sqrt())
    }

    /// The eta layer's share of the `mu` coordinate at `(alpha, eta_up)`:
    /// `w / (1 + (eta - 1) / (d alpha^2))`, or `w` where `d = 0`.
    #[must_use]
    pub fn layer_share_at(&self, alpha: f64, eta_up: f64) -> f64 {
        if self.layer_share_decay <= 0.0 {
            return self.layer_share;
        }
        let excess = (eta_up - 1.0).max(0.0);
        self.layer_share / (1.0 + excess / (self.layer_share_decay * alpha * alpha).max(1e-300))
    }

    /// The `mu` coordinate `t` of `mu` at roughness `alpha` and axis index `eta_up >= 1`
    /// (module docs): 0 at `mu = 0`, 1 at `mu = 1`.
    #[must_use]
    pub fn mu_coordinate(&self, mu: f64, alpha: f64, eta_up: f64) -> f64 {
        let w = self.layer_share_at(alpha, eta_up);
        w * saturation(mu, self.layer_width(alpha, eta_up), self.layer_power)
            + (1.0 - w) * crate::integrate::grazing::t_of_mu(mu, alpha)
    }

    /// Where a texel of the `eta = 1` slice at `mu` coordinate `t_mu` on the row computed at
    /// `row_alpha` is computed, as `(alpha, eta_up)`: above the eta layer (`t_mu > w`) the layer's
    /// part of the coordinate saturates as `eta -> 1+`, so the limit is the albedo at `eta = 1`
    /// itself, on the row; inside the layer its profile, at [`limit_slice_eta`], on rows below
    /// [`LAYER_ROW_LIMIT_ALPHA`] at that `alpha` (the same `mu / alpha` and
    /// `(eta - 1) / alpha^2`).
    #[must_use]
    pub fn limit_slice_point(&self, t_mu: f64, row_alpha: f64) -> (f64, f64) {
        if t_mu > self.layer_share_at(row_alpha, 1.0) {
            (row_alpha, 1.0)
        } else {
            let alpha = row_alpha.max(LAYER_ROW_LIMIT_ALPHA);
            (alpha, limit_slice_eta(alpha))
        }
    }

    /// `mu` at coordinate `t` (the inverse of [`GlassLayout::mu_coordinate`]); where the
    /// coordinate is flat in `mu` (a mirror's layers have no width) the smallest such `mu`.
    #[must_use]
    pub fn mu_at(&self, t: f64, alpha: f64, eta_up: f64) -> f64 {
        if t <= 0.0 {
            return 0.0;
        }
        if t >= 1.0 {
            return 1.0;
        }
        bisect(0.0, 1.0, INVERSION_STEPS, |mu| {
            self.mu_coordinate(mu, alpha, eta_up) < t
        })
    }
}

/// The `eta = 1` slice is computed at `eta - 1 =` this times `alpha^2`: the albedo near
/// `eta = 1` is a function of `(eta - 1) / alpha^2` (and of `mu / kappa`), which it approaches
/// linearly (at `alpha = 1e-3`, `mu = 1e-3`, `E - E_limit` is 7e-6 at a ratio of 5e-5 and
/// 6.2e-4 at 5e-3), so the slice is within about 1.5e-5 of its limit. A smaller ratio puts the
/// slice's eta layer at `mu ~ 1e-5 alpha`, where the reference no longer converges in its
/// budget.
pub const LIMIT_ETA_OFFSET: f64 = 1e-4;

/// The `alpha` at which the row `alpha = 0` of a glass table is computed: its limit
/// `alpha -> 0+` at fixed texture coordinates. Larger than the adaptive axis' 1e-7
/// ([`super::axis::LAYER_LIMIT_ALPHA`]) because the IOR coordinate puts `eta - 1` near
/// `alpha^2` and its eta layer at `mu ~ (eta - 1) / alpha`, which the reference resolves down to
/// about `alpha = 1e-3` (the corrections to the limit are `O(alpha^2)` in `E`'s masking layer;
/// the albedo at `(mu / alpha, (eta - 1) / alpha^2)` fixed agrees to 1e-9 between
/// `alpha = 1e-3` and `1e-2`).
pub const ROW_LIMIT_ALPHA: f64 = 1e-3;

/// The smallest `alpha` at which the eta layer's texels (`t <= w`) of the `eta = 1` slice are
/// computed (rows of smaller `alpha`, and `alpha = 0`, at this one, at the same `t`): there the
/// albedo is a function of `mu / alpha` and `(eta - 1) / alpha^2` alone (from inside, 0.0754526032 at `alpha` 1e-3 and 0.0754526236 at 1e-2, `mu = 2.5e-5
/// alpha`, `eta = 1 / (1 + 1e-4 alpha^2)`), and near `alpha = 1e-3` the reference exhausts its
/// budget on them.
pub const LAYER_ROW_LIMIT_ALPHA: f64 = 1e-2;

/// The index at which the `eta = 1` slice is computed at roughness `alpha`
/// (`1 + LIMIT_ETA_OFFSET alpha^2`).
#[must_use]
pub fn limit_slice_eta(alpha: f64) -> f64 {
    1.0 + LIMIT_ETA_OFFSET * alpha * alpha
}

/// Halvings of a coordinate's inversion: from `[0, 1]` to below 1e-30 absolute, so that a `mu`
/// or `x` as small as 1e-20 keeps ten digits.
pub(crate) const INVERSION_STEPS: u32 = 110;

/// `A(y; k, p) = (y (1 + k) / (y + k))^p` on `[0, 1]`: 0 at `y = 0`, 1 at `y = 1`, and 1 for
/// every `y > 0` when `k = 0`.
#[must_use]
pub fn saturation(y: f64, k: f64, p: f64) -> f64 {
    if y <= 0.0 {
        return 0.0;
    }
    if k <= 0.0 {
        return 1.0;
    }
    (y * (1.0 + k) / (y + k)).min(1.0).powf(p)
}

/// `u(eta) = (eta - 1) / (eta + 1)`, `sqrt(F0)`; an `eta < 1` is read as `1 / eta`.
#[must_use]
pub fn reflectance_root(eta: f64) -> f64 {
    let eta = if eta < 1.0 { 1.0 / eta } else { eta };
    ((eta - 1.0) / (eta + 1.0)).max(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    const KILN: GlassLayout = GlassLayout::KILN;

    /// Both coordinates run from 0 to 1, increase, and their inversions give back the variable.
    #[test]
    fn the_coordinates_invert() {
        for alpha in [1e-7, 1e-3, 0.05, 0.3, 1.0] {
            for eta in [1.0 + 1e-9, 1.0005, 1.01, 1.2, 1.5, 2.2, 3.0] {
                let z = KILN.ior_coordinate(eta, 3.0, alpha);
                assert!((0.0..=1.0).contains(&z));
                let back = KILN.ior_at(z, 3.0, alpha);
                assert!(
                    ((back - 1.0) / (eta - 1.0) - 1.0).abs() < 1e-8,
                    "{alpha} {eta}: {back}"
                );
                // From inside, 1 / eta sits at the same coordinate.
                assert_eq!(KILN.ior_coordinate(1.0 / eta, 3.0, alpha), z);
                let mut last = -1.0;
                for k in 0..=64 {
                    let mu = if k == 0 {
                        0.0
                    } else {
                        10f64.powf(-8.0 * (1.0 - k as f64 / 64.0))
                    };
                    let t = KILN.mu_coordinate(mu, alpha, eta);
                    assert!(
                        t > last || (t == last && t == 1.0),
                        "{alpha} {eta} {mu}: {t}"
                    );
                    last = t;
                    let back = KILN.mu_at(t, alpha, eta);
                    assert!((back - mu).abs() <= 1e-9 * mu, "{alpha} {eta} {mu}: {back}");
                }
            }
        }
        assert_eq!(KILN.ior_coordinate(1.0, 3.0, 0.5), 0.0);
        assert!((KILN.ior_coordinate(3.0, 3.0, 0.5) - 1.0).abs() < 1e-15);
        assert_eq!(KILN.ior_at(0.0, 3.0, 0.5), 1.0);
        assert_eq!(KILN.ior_at(1.0, 3.0, 0.5), 3.0);
    }

    /// The eta layer keeps its share of the coordinate: at `mu = kappa` the layer's part is
    /// `w ((1 + kappa) / 2)^0.35`, worked for `eta = 1.01`, `alpha = 0.1`:
    /// `kappa = 0.01 / (0.1 + 0.1) = 0.05`, `w = 0.3 / (1 + 0.01 / 0.01) = 0.15`.
    #[test]
    fn the_eta_layer_sits_at_a_fixed_share_of_the_coordinate() {
        let kappa = KILN.layer_width(0.1, 1.01);
        assert!((kappa - 0.05).abs() < 1e-12, "{kappa}");
        let t = KILN.mu_coordinate(kappa, 0.1, 1.01);
        let masking = crate::integrate::grazing::t_of_mu(kappa, 0.1);
        let expected = 0.15 * (1.05f64 / 2.0).powf(0.35) + 0.85 * masking;
        assert!((t - expected).abs() < 1e-12, "{t} {expected}");
        // On a mirror the layer is the Fresnel layer sqrt(eta - 1).
        assert!((KILN.layer_width(0.0, 1.0004) - 0.02).abs() < 1e-12);
        // At eta = 1 it has no width: t jumps to w above mu = 0.
        assert!((KILN.mu_coordinate(1e-300, 0.5, 1.0) - 0.3).abs() < 1e-12);
        // Where the layer has merged with the masking layer its share fades.
        assert!((GlassLayout::KILN.layer_share_at(0.1, 1.1) - 0.3 / 11.0).abs() < 1e-15);
    }

    /// The IOR coordinate's tied share at `x = k = c_z alpha^2` (`alpha = 0.1`, `k = 0.003`),
    /// worked: `0.35 ((1 + k) / 2)^(1/2) + 0.65 k^(1/2)`.
    #[test]
    fn the_ior_coordinate_is_tied_to_alpha_squared() {
        let k: f64 = 0.3 * 0.01;
        let eta_max: f64 = 3.0;
        let u = k * reflectance_root(eta_max);
        let eta = (1.0 + u) / (1.0 - u);
        let z = KILN.ior_coordinate(eta, eta_max, 0.1);
        let expected = 0.35 * ((1.0 + k) / 2.0).sqrt() + 0.65 * k.sqrt();
        assert!((z - expected).abs() < 1e-12, "{z} {expected}");
    }

    /// The formulas files carry state the constants this module computes with.
    #[test]
    fn the_formulas_state_the_constants() {
        use crate::table::axis::{IorMapping, MuMapping};
        let mu_text = MuMapping::Glass.formula();
        let mu = mu_text.as_str();
        let ior = IorMapping::Glass.formula();
        let k = GlassLayout::KILN;
        for (text, constant) in [
            (mu, format!("t = w A(mu; kappa, {})", k.layer_power)),
            (
                mu,
                format!(
                    "w = {} / (1 + (eta - 1) / ({} alpha^2))",
                    k.layer_share, k.layer_share_decay
                ),
            ),
            (mu, format!("(t > {})", k.layer_share)),
            (mu, format!("computed at alpha = {ROW_LIMIT_ALPHA:e}")),
            (
                ior,
                format!(
                    "t = {} A(x; {} alpha^2, {}) + {} x^{}",
                    k.ior_share,
                    k.ior_scale,
                    k.ior_power,
                    1.0 - k.ior_share,
                    k.ior_power
                ),
            ),
            (ior, format!("eta - 1 = {LIMIT_ETA_OFFSET:e} alpha^2")),
        ] {
            assert!(text.contains(&constant), "{text} lacks {constant}");
        }
        assert_eq!((k.layer_scale, k.layer_sqrt_weight), (1.0, 1.0));
    }
}
