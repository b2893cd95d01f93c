//! Table axes: where each texel's value was computed, and how a lookup finds it.
//!
//! An axis of `N` samples maps an index `i` to a texture coordinate `t_i` in [0, 1] by its grid
//! convention, then `t` to the physical coordinate (`mu` or roughness) by its mapping:
//!
//! - grid `centers` (the default): `t_i = (i + 0.5) / N`, the centre of texel `i` when the table is
//!   a texture over [0, 1] sampled with bilinear filtering and clamp-to-edge (what a GPU does);
//!   the axis ends `t = 0` and `t = 1` lie half a texel outside the first and last sample;
//! - grid `nodes`: `t_i = i / (N - 1)`, the first and last samples sit exactly on the axis ends
//!   (Cycles, appleseed); a GPU lookup must then remap `t' = (t (N - 1) + 0.5) / N`.
//!
//! Mappings from `t` to the physical coordinate:
//!
//! - `mu`, `linear`: `mu = t`; `sqrt`: `mu = t^2`, i.e. the texture coordinate is `sqrt(mu)`
//!   (Unity HDRP), which puts more samples near grazing; `adaptive` (kiln's default): the texture
//!   coordinate depends on the roughness too, `t = (mu (1 + c alpha) / (mu + c alpha))^p` with
//!   `c = 4`, `p = 0.4` ([`MuMapping::Adaptive`]);
//! - roughness `r` (perceptual): `r = t`, `alpha = r^2`; roughness `alpha`: `alpha = t`;
//! - index of refraction `eta` in `[1, eta_max]` (the dielectric tables): `linear`,
//!   `eta = 1 + t (eta_max - 1)` (Unreal's glass table, over [1, 3]); `cycles`, linear in
//!   `z = sqrt((eta - 1) / (eta + 1))` (the fourth root of the normal-incidence reflectance `F0`),
//!   `z = t z_max`, `eta = (1 + z^2) / (1 - z^2)`: Cycles' glass tables. `z` puts more samples
//!   near `eta = 1`, where the critical angle of light arriving from inside opens as
//!   `sqrt(2 (eta - 1))` and the inside tables change fastest. The axis always lists `eta >= 1`;
//!   a table of light arriving from inside is computed at the relative index `1 / eta`.
//!
//! Why `adaptive`: at small `alpha`, `E` has a boundary layer at `mu ~ alpha` (`docs/physics.md`,
//! "Hard cases"): `E(mu, alpha)` is, to `O(alpha^2)`, a function of `x = mu / alpha` alone that
//! dips to 0.89 at `x ~ 1` (height-correlated GGX) whatever `alpha` is. No axis that ignores
//! `alpha` can follow the dip as `alpha -> 0`; in `t` above, `x = c s / (1 + c alpha - s)` with
//! `s = t^(1/p)`, so the dip stays at the same `t` for every small `alpha` and a bilinear lookup
//! resolves it everywhere. The constants were chosen by measured lookup error at 32 x 32 (c in
//! 1..5, p in 0.33..1; see the README). At `alpha = 0` the mapping gives `t = 1` for every
//! `mu > 0` (the mirror's `E = 1`) and `t = 0` at `mu = 0`; the row at `alpha = 0` holds the
//! boundary layer's limit `alpha -> 0+`, computed at [`LAYER_LIMIT_ALPHA`].

use crate::model::RoughnessConvention;
use serde::{Deserialize, Serialize};

/// Where the samples of an axis sit.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum Grid {
    /// `t_i = (i + 0.5) / N`: texel centres.
    Centers,
    /// `t_i = i / (N - 1)`: nodes on the axis ends.
    Nodes,
}

impl Grid {
    /// The name used on the command line and in files.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Grid::Centers => "centers",
            Grid::Nodes => "nodes",
        }
    }

    /// The texture coordinate `t_i` of sample `i` of `n`.
    #[must_use]
    pub fn coordinate(self, i: usize, n: usize) -> f64 {
        match self {
            Grid::Centers => (i as f64 + 0.5) / n as f64,
            Grid::Nodes if n == 1 => 0.0,
            Grid::Nodes => i as f64 / (n - 1) as f64,
        }
    }

    /// The formula of [`Grid::coordinate`], for metadata.
    #[must_use]
    pub fn formula(self) -> &'static str {
        match self {
            Grid::Centers => "t_i = (i + 0.5) / N",
            Grid::Nodes => "t_i = i / (N - 1)",
        }
    }
}

/// The constants of [`MuMapping::Adaptive`], at home with the change of variable they define.
pub use crate::integrate::grazing::{ADAPTIVE_POWER, ADAPTIVE_SCALE};

/// The `alpha` at which a row at `alpha = 0` of an [`MuMapping::Adaptive`] table is computed:
/// that row holds the limit `alpha -> 0+` at fixed `t`, which `E` approaches as `O(alpha^2)`, so
/// the difference at 1e-7 is about 1e-14 (equal to [`crate::model::SMOOTH_ALPHA`]).
pub const LAYER_LIMIT_ALPHA: f64 = crate::model::SMOOTH_ALPHA;

/// How the `mu` axis is spaced.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum MuMapping {
    /// `mu = t`.
    Linear,
    /// `mu = t^2` (texture coordinate `sqrt(mu)`).
    Sqrt,
    /// `t = (mu (1 + c alpha) / (mu + c alpha))^p`, `c = 4`, `p = 0.4`: follows the grazing
    /// boundary layer `mu ~ alpha` at every roughness (see the module docs); kiln's default
    /// for the tables it bakes.
    Adaptive,
    /// kiln's glass layout (`table::glass_layout`): `t = w A(mu; kappa, 0.35) + (1 - w)
    /// A(mu; 4 alpha, 0.4)`, the adaptive coordinate with a share `w = 0.3 / (1 + (eta - 1) /
    /// alpha^2)` given to the layer of width `kappa = (eta - 1) / (alpha + sqrt(eta - 1))` that
    /// opens near grazing as `eta -> 1+`; depends on roughness and on the IOR, so only on a table
    /// over the IOR, chosen by `--ior-axis glass`.
    #[cfg_attr(feature = "cli", value(skip))]
    Glass,
    /// kiln's balanced layout (`table::balanced_layout`): `t = ((u + eps)^0.4 - eps^0.4) / ((1 +
    /// eps)^0.4 - eps^0.4)` of `u = mu (1 + k) / (mu + k)`, `k = 3 alpha (1 + 7 alpha)`,
    /// `eps = (1.25 / 32) (32 / N)^1.5 exp(-3 alpha)`: the adaptive axis' grazing layer, with
    /// more texels near `mu = 1` at moderate roughness and fewer at `mu < 1e-4`, for the lookup
    /// of fitted texels (`--texels lookup-fit`).
    Balanced,
    /// kiln's layout of a glass table at one IOR (`table::one_ior_layout`): kiln's balanced
    /// coordinate with shares given to the eta layer near grazing (an index close to 1) and, from
    /// inside, to the critical angle `mu_c = sqrt(1 - eta^2)`; depends on roughness and on the
    /// table's relative index `eta`, so only on a glass table at one IOR, which it is kiln's
    /// layout of.
    #[cfg_attr(feature = "cli", value(skip))]
    OneIor,
    /// kiln's split-sum layout (`table::split_sum_layout`), for the quantities that vary with
    /// `mu` on a mirror (`e-scale`, `e-bias`, `e-f`): `t = 0.6 A(mu; 0.3, 0.5) + 0.4 A(mu; 4
    /// alpha, 0.4)` with `A(y; k, p) = (y (1 + k) / (y + k))^p`: the adaptive axis' grazing
    /// layer, and texels for `Fc(mu)` on the mirror row (which the adaptive axis maps to `t = 1`).
    SplitSum,
}

impl MuMapping {
    /// The name used on the command line and in files.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            MuMapping::Linear => "linear",
            MuMapping::Sqrt => "sqrt",
            MuMapping::Adaptive => "adaptive",
            MuMapping::Glass => "glass",
            MuMapping::Balanced => "balanced",
            MuMapping::SplitSum => "split-sum",
            MuMapping::OneIor => "one-ior",
        }
    }

    /// The tag of a table on this axis where it is not kiln's axis for the quantity
    /// ([`crate::table::TableSpec::id`]): `mu-` and the name.
    #[must_use]
    pub fn tag(self) -> &'static str {
        match self {
            MuMapping::Linear => "mu-linear",
            MuMapping::Sqrt => "mu-sqrt",
            MuMapping::Adaptive => "mu-adaptive",
            MuMapping::Glass => "mu-glass",
            MuMapping::Balanced => "mu-balanced",
            MuMapping::SplitSum => "mu-split-sum",
            MuMapping::OneIor => "mu-one-ior",
        }
    }

    /// kiln's `mu` axis for `quantity` (the layout a bake gives it when no `--mu-axis` is
    /// named, and the one its file name leaves untagged):
    /// - [`MuMapping::SplitSum`] for the quantities that vary with `mu` on a mirror (the split-sum
    ///   channels and `E_F`: the grazing-layer axes map every `mu > 0` to `t = 1` there);
    /// - [`MuMapping::Adaptive`] for the tables over the IOR (`over_ior`; kiln's glass layout
    ///   replaces it with [`MuMapping::Glass`]; Cycles' product grid keeps it);
    /// - [`MuMapping::Balanced`] for `E` and what derives from it (`E_avg`, `f_ms_norm`), whose
    ///   texels are fitted for the lookup on it ([`crate::table::Texels::paired_with`]), and
    ///   for the glass albedos at one IOR ([`crate::table::TableSpec::fixed_ior`]), fitted as
    ///   `E` is.
    #[must_use]
    pub fn kiln_default(quantity: crate::integrate::quantity::Quantity, over_ior: bool) -> Self {
        if quantity.varies_on_a_mirror() {
            MuMapping::SplitSum
        } else if quantity.is_glass_albedo() && quantity.has_mu() && !over_ior {
            MuMapping::OneIor
        } else if over_ior {
            MuMapping::Adaptive
        } else {
            MuMapping::Balanced
        }
    }

    /// Whether the texture coordinate depends on `alpha` as well as `mu`.
    #[must_use]
    pub fn depends_on_roughness(self) -> bool {
        matches!(
            self,
            MuMapping::Adaptive
                | MuMapping::Glass
                | MuMapping::Balanced
                | MuMapping::SplitSum
                | MuMapping::OneIor
        )
    }

    /// Whether the axis keeps `mu` apart on a mirror row (`alpha = 0`), where the split-sum
    /// and Fresnel-weighted quantities still vary with `mu`: every axis but those that follow
    /// only the grazing layer (`adaptive`, `balanced`, `glass` map every `mu > 0` to `t = 1`
    /// there).
    #[must_use]
    pub fn resolves_mu_on_a_mirror(self) -> bool {
        matches!(
            self,
            MuMapping::Linear | MuMapping::Sqrt | MuMapping::SplitSum
        )
    }

    /// Whether the texture coordinate depends on the index of refraction (only on a table over
    /// the IOR).
    #[must_use]
    pub fn depends_on_ior(self) -> bool {
        self == MuMapping::Glass
    }

    /// `mu` at texture coordinate `t` on the row of slope-space roughness `alpha`, on an axis
    /// of `size` samples (only `balanced` depends on it; a `glass` axis at `eta = 1`: see
    /// [`MuMapping::mu_at`]).
    #[must_use]
    pub fn mu(self, t: f64, alpha: f64, size: usize) -> f64 {
        self.mu_at(t, alpha, 1.0, size)
    }

    /// `mu` at texture coordinate `t` at roughness `alpha` and axis index `eta_up >= 1`, on an
    /// axis of `size` samples.
    #[must_use]
    pub fn mu_at(self, t: f64, alpha: f64, eta_up: f64, size: usize) -> f64 {
        match self {
            MuMapping::Linear => t,
            MuMapping::Sqrt => t * t,
            MuMapping::Adaptive => crate::integrate::grazing::mu_of_t(t, alpha),
            MuMapping::Glass => super::glass_layout::GlassLayout::KILN.mu_at(t, alpha, eta_up),
            MuMapping::Balanced => {
                super::balanced_layout::BalancedLayout::KILN.mu_at(t, alpha, size)
            }
            MuMapping::SplitSum => super::split_sum_layout::SplitSumLayout::KILN.mu_at(t, alpha),
            MuMapping::OneIor => {
                super::one_ior_layout::OneIorLayout::KILN.mu_at(t, alpha, eta_up, size)
            }
        }
    }

    /// The texture coordinate of `mu` at roughness `alpha` on an axis of `size` samples (the
    /// inverse of [`MuMapping::mu`]). For `adaptive` and `balanced`, `mu = 0` gives 0 whatever
    /// `alpha`, and `alpha = 0` gives 1 for `mu > 0`.
    #[must_use]
    pub fn coordinate(self, mu: f64, alpha: f64, size: usize) -> f64 {
        self.coordinate_at(mu, alpha, 1.0, size)
    }

    /// The texture coordinate of `mu` at roughness `alpha` and axis index `eta_up >= 1` on an
    /// axis of `size` samples (the inverse of [`MuMapping::mu_at`]).
    #[must_use]
    pub fn coordinate_at(self, mu: f64, alpha: f64, eta_up: f64, size: usize) -> f64 {
        match self {
            MuMapping::Linear => mu,
            MuMapping::Sqrt => mu.sqrt(),
            MuMapping::Adaptive => crate::integrate::grazing::t_of_mu(mu, alpha),
            MuMapping::Glass => {
                super::glass_layout::GlassLayout::KILN.mu_coordinate(mu, alpha, eta_up)
            }
            MuMapping::Balanced => {
                super::balanced_layout::BalancedLayout::KILN.mu_coordinate(mu, alpha, size)
            }
            MuMapping::SplitSum => {
                super::split_sum_layout::SplitSumLayout::KILN.mu_coordinate(mu, alpha)
            }
            MuMapping::OneIor => {
                super::one_ior_layout::OneIorLayout::KILN.mu_coordinate(mu, alpha, eta_up, size)
            }
        }
    }

    /// The formula, for metadata.
    #[must_use]
    pub fn formula(self) -> String {
        match self {
            MuMapping::Linear => "mu = t".to_string(),
            MuMapping::Sqrt => "mu = t^2 (lookup coordinate t = sqrt(mu))".to_string(),
            MuMapping::Adaptive => {
                "lookup coordinate t = (mu (1 + 4 alpha) / (mu + 4 alpha))^0.4 (t = 0 at mu = 0; \
                 t = 1 at alpha = 0, mu > 0); mu = s k / (1 + k - s) with s = t^2.5, k = 4 alpha; \
                 the row at alpha = 0 holds the limit alpha -> 0+ (computed at alpha = 1e-7)"
                    .to_string()
            }
            MuMapping::Glass => {
                "lookup coordinate t = w A(mu; kappa, 0.35) + (1 - w) A(mu; 4 alpha, 0.4) with \
                 A(y; k, p) = (y (1 + k) / (y + k))^p (1 at k = 0, y > 0; 0 at y = 0), \
                 kappa = (eta - 1) / (alpha + sqrt(eta - 1)), w = 0.3 / (1 + (eta - 1) / \
                 (1 alpha^2)), eta >= 1 the IOR axis' index (1 / the relative index of light from \
                 inside); mu at t by bisection; the row at alpha = 0 holds the limit alpha -> 0+ \
                 (computed at alpha = 1e-3); on the slice eta = 1 the texels above the eta layer \
                 (t > 0.3) are the albedo at eta = 1"
                    .to_string()
            }
            MuMapping::Balanced => {
                let l = super::balanced_layout::BalancedLayout::KILN;
                format!(
                    "lookup coordinate t = {} (t = 0 at mu = 0; t = 1 at alpha = 0, mu > 0); mu = \
                     u k / (1 + k - u) with u = (t ((1 + eps)^{p} - eps^{p}) + eps^{p})^(1/{p}) - \
                     eps; the row at alpha = 0 holds the limit alpha -> 0+ (computed at alpha = \
                     1e-7)",
                    balanced_formula(l),
                    p = l.power,
                )
            }
            MuMapping::SplitSum => {
                let l = super::split_sum_layout::SplitSumLayout::KILN;
                format!(
                    "lookup coordinate t = {w} A(mu; {k}, {p}) + {v} A(mu; 4 alpha, 0.4) with \
                     A(y; k, p) = (y (1 + k) / (y + k))^p (0 at y = 0; 1 at k = 0, y > 0); mu at \
                     t by bisection; the row at alpha = 0 holds the limit alpha -> 0+ (computed \
                     at alpha = 1e-7)",
                    w = l.share,
                    k = l.scale,
                    p = l.power,
                    v = 1.0 - l.share,
                )
            }
            MuMapping::OneIor => {
                let l = super::one_ior_layout::OneIorLayout::KILN;
                let b = l.base();
                format!(
                    "lookup coordinate t = w_c C(mu) + w_t T(mu) + (1 - w_c - w_t) B(mu), eta the table's relative \
                     index (its IOR from outside, 1 / IOR from inside); B the balanced \
                     coordinate with a tenth of its offset: B = {}; from inside (eta < 1) w_c = \
                     {wc} and C(mu) = (atan((mu - mu_c) / s) - atan(-mu_c / s)) / (atan((1 - \
                     mu_c) / s) - atan(-mu_c / s)), mu_c = sqrt(1 - eta^2), s = {cc} alpha + \
                     {s0}, and a share w_t = {wt} min(alpha, 1)^2 more of the coordinate is T(mu) \
                     = (atan((mu - 1) / {st}) - atan(-1 / {st})) / -atan(-1 / {st}) (t = w_c \
                     C + w_t T + (1 - w_c - w_t) B); from outside w_c = w_t = 0; mu at t by \
                     bisection; the row at alpha = 0 holds the limit alpha -> 0+ (computed at \
                     alpha = 1e-7)",
                    balanced_formula(b),
                    wt = l.top_share,
                    st = l.top_width,
                    wc = l.critical_share,
                    cc = l.critical_scale,
                    s0 = l.critical_floor,
                )
            }
        }
    }
}

/// The balanced coordinate of `layout` as a formula: `((u + eps)^p - eps^p) / ((1 + eps)^p -
/// eps^p)` with its constants (`table::balanced_layout`).
fn balanced_formula(l: super::balanced_layout::BalancedLayout) -> String {
    format!(
        "((u + eps)^{p} - eps^{p}) / ((1 + eps)^{p} - eps^{p}) with u = mu (1 + k) / (mu + k), k = \
         {c} alpha (1 + {e} alpha), eps = ({z} / 32) (32 / N)^{w} exp(-{y} alpha), N the axis \
         size",
        p = l.power,
        c = l.scale,
        e = l.scale_growth,
        z = l.offset,
        w = l.offset_size_power,
        y = l.offset_decay,
    )
}

/// How the samples of a roughness axis are spaced along its convention's value (`r` or
/// `alpha`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum RoughnessSpacing {
    /// The texture coordinate is the value itself: `r = t` (or `alpha = t`).
    #[default]
    Linear,
    /// kiln's balanced layout (`table::balanced_layout`): `t = 0.6 P(r) + 0.4 r^2 (3 - 2 r)`
    /// of perceptual `r = sqrt(alpha)`, `P(r)` the normalised `r^1.37`, proportional to `alpha`
    /// below `r ~ 0.02`: more rows through the knee `r ~ 0.5` where `E` bends fastest, fewer
    /// near the mirror.
    Balanced,
}

impl RoughnessSpacing {
    /// The name used on the command line and in files.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            RoughnessSpacing::Linear => "linear",
            RoughnessSpacing::Balanced => "balanced",
        }
    }

    /// The tag of rows spaced so where they are not those of the table's `mu` axis
    /// ([`crate::table::TableSpec::id`]).
    #[must_use]
    pub fn tag(self) -> &'static str {
        match self {
            RoughnessSpacing::Linear => "rows-linear",
            RoughnessSpacing::Balanced => "rows-balanced",
        }
    }

    /// The spacing laid out with the `mu` axis `mapping`: balanced rows with the balanced axis,
    /// linear otherwise (the command line's default).
    #[must_use]
    pub fn paired_with(mapping: MuMapping) -> Self {
        match mapping {
            MuMapping::Balanced | MuMapping::OneIor => RoughnessSpacing::Balanced,
            _ => RoughnessSpacing::Linear,
        }
    }

    /// Whether this is the linear spacing (which files written before the balanced layout
    /// imply, and do not name).
    #[must_use]
    pub fn is_linear(&self) -> bool {
        *self == RoughnessSpacing::Linear
    }

    /// The texture coordinate of the roughness `value` given in `convention`.
    #[must_use]
    pub fn coordinate(self, value: f64, convention: RoughnessConvention) -> f64 {
        match self {
            RoughnessSpacing::Linear => value,
            RoughnessSpacing::Balanced => super::balanced_layout::BalancedLayout::KILN
                .roughness_coordinate(convention.to_alpha(value.max(0.0)).sqrt()),
        }
    }

    /// The roughness value in `convention` at texture coordinate `t` (the inverse of
    /// [`RoughnessSpacing::coordinate`]).
    #[must_use]
    pub fn value_at(self, t: f64, convention: RoughnessConvention) -> f64 {
        match self {
            RoughnessSpacing::Linear => t,
            RoughnessSpacing::Balanced => {
                let r = super::balanced_layout::BalancedLayout::KILN.roughness_at(t);
                convention.from_alpha(r * r)
            }
        }
    }
}

/// How an index-of-refraction axis is spaced (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum IorMapping {
    /// `eta = 1 + t (eta_max - 1)`.
    Linear,
    /// Linear in `z = sqrt((eta - 1) / (eta + 1))` (Cycles' glass tables); `F_avg`'s axis.
    Cycles,
    /// Blender's own glass tables (`shader.tables`): `z = t` clamped to `[1e-4, 0.99]` at the
    /// nodes, so the axis runs from `eta = 1 + 2e-8` to `eta = 99.5` whatever `eta_max`, and
    /// the lookup reads `t = z` unclamped (`microfacet_ggx_glass_E`).
    Blender,
    /// kiln's glass layout for the dielectric albedos (the default): IOR and
    /// mu coordinates that follow the layers near `eta = 1`, the slice `eta = 1` holding the
    /// limit `eta -> 1+`; `z = 0.35 A(x; 0.3 alpha^2, 1/2) + 0.65 x^(1/2)`, `x = u(eta) /
    /// u(eta_max)`, `u = (eta - 1) / (eta + 1)`, `A(y; k, p) = (y (1 + k) / (y + k))^p`.
    Glass,
}

/// The ends of [`IorMapping::Blender`]'s `z` (`ior_parameterization` in Cycles'
/// `precompute.cpp`: `z = clamp(k / 15, 1e-4, 0.99)`).
pub const BLENDER_Z_RANGE: (f64, f64) = (1e-4, 0.99);

impl IorMapping {
    /// The name used on the command line and in files.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            IorMapping::Linear => "linear",
            IorMapping::Cycles => "cycles",
            IorMapping::Blender => "blender",
            IorMapping::Glass => "glass",
        }
    }

    /// Whether the coordinate depends on roughness as well as `eta`.
    #[must_use]
    pub fn depends_on_roughness(self) -> bool {
        self == IorMapping::Glass
    }

    fn z(eta: f64) -> f64 {
        ((eta - 1.0) / (eta + 1.0)).max(0.0).sqrt()
    }

    /// `eta` at texture coordinate `t` on an axis up to `max`, at slope-space roughness `alpha`
    /// (only the `glass` mapping depends on it).
    #[must_use]
    pub fn eta(self, t: f64, max: f64, alpha: f64) -> f64 {
        match self {
            IorMapping::Glass => super::glass_layout::GlassLayout::KILN.ior_at(t, max, alpha),
            IorMapping::Linear => 1.0 + t * (max - 1.0),
            IorMapping::Cycles => {
                let z = t * Self::z(max);
                (1.0 + z * z) / (1.0 - z * z)
            }
            IorMapping::Blender => {
                let z = t.clamp(BLENDER_Z_RANGE.0, BLENDER_Z_RANGE.1);
                (1.0 + z * z) / (1.0 - z * z)
            }
        }
    }

    /// The texture coordinate of `eta` (the inverse of [`IorMapping::eta`]); an `eta < 1` is
    /// looked up at `1 / eta`, as the axis lists indices from 1 up; at roughness `alpha` (only the
    /// `glass` mapping depends on it).
    #[must_use]
    pub fn coordinate(self, eta: f64, max: f64, alpha: f64) -> f64 {
        let eta = if eta < 1.0 { 1.0 / eta } else { eta };
        match self {
            IorMapping::Glass => {
                super::glass_layout::GlassLayout::KILN.ior_coordinate(eta, max, alpha)
            }
            IorMapping::Linear => (eta - 1.0) / (max - 1.0),
            IorMapping::Cycles => Self::z(eta) / Self::z(max),
            IorMapping::Blender => Self::z(eta),
        }
    }

    /// The formula, for metadata.
    #[must_use]
    pub fn formula(self) -> &'static str {
        match self {
            IorMapping::Linear => "eta = 1 + t (eta_max - 1)",
            IorMapping::Cycles => {
                "z = t z_max with z = sqrt((eta - 1) / (eta + 1)), z_max = z(eta_max); \
                 eta = (1 + z^2) / (1 - z^2)"
            }
            IorMapping::Blender => {
                "z = clamp(t, 1e-4, 0.99), eta = (1 + z^2) / (1 - z^2) (Blender's glass tables; \
                 a lookup reads t = sqrt((eta - 1) / (eta + 1)))"
            }
            IorMapping::Glass => {
                "lookup coordinate t = 0.35 A(x; 0.3 alpha^2, 0.5) + 0.65 x^0.5 with x = u(eta) / \
                 u(eta_max), u(eta) = (eta - 1) / (eta + 1), A(y; k, p) = (y (1 + k) / (y + k))^p \
                 (1 at k = 0, y > 0; 0 at y = 0); eta at t by bisection; the slice t = 0 holds the \
                 one-sided limit eta -> 1+ at fixed coordinates (computed at eta - 1 = 1e-4 \
                 alpha^2; a renderer passes an exactly index-matched interface straight through)"
            }
        }
    }
}

/// An index of refraction as an axis bound: an f64 that compares and hashes by its bits, so that
/// axes stay `Eq` and `Hash`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(transparent)]
pub struct IorBound(pub f64);

impl Eq for IorBound {}

impl std::hash::Hash for IorBound {
    fn hash<H: std::hash::Hasher>(&self, state: &mut H) {
        self.0.to_bits().hash(state);
    }
}

/// One axis of a table.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(tag = "quantity", rename_all = "kebab-case")]
pub enum Axis {
    /// `mu = cos(theta_o)` of the view direction.
    Mu {
        size: usize,
        mapping: MuMapping,
        grid: Grid,
    },
    /// Roughness, in the given convention (`r` with `alpha = r^2`, or `alpha`), spaced along
    /// it by `spacing`.
    Roughness {
        size: usize,
        convention: RoughnessConvention,
        grid: Grid,
        #[serde(default, skip_serializing_if = "RoughnessSpacing::is_linear")]
        spacing: RoughnessSpacing,
    },
    /// The index of refraction `eta` in `[1, max]` (listed from 1 up whichever side the light
    /// arrives from).
    Ior {
        size: usize,
        mapping: IorMapping,
        max: IorBound,
        grid: Grid,
    },
}

impl Axis {
    /// The number of samples along the axis.
    #[must_use]
    pub fn size(&self) -> usize {
        match *self {
            Axis::Mu { size, .. } | Axis::Roughness { size, .. } | Axis::Ior { size, .. } => size,
        }
    }

    /// The grid convention.
    #[must_use]
    pub fn grid(&self) -> Grid {
        match *self {
            Axis::Mu { grid, .. } | Axis::Roughness { grid, .. } | Axis::Ior { grid, .. } => grid,
        }
    }

    /// The axis name: `mu`, `r`, `alpha` or `eta`.
    #[must_use]
    pub fn name(&self) -> &'static str {
        match *self {
            Axis::Mu { .. } => "mu",
            Axis::Ior { .. } => "eta",
            Axis::Roughness { convention, .. } => convention.name(),
        }
    }

    /// The texture coordinate `t_i` of sample `i`.
    #[must_use]
    pub fn coordinate(&self, i: usize) -> f64 {
        self.grid().coordinate(i, self.size())
    }

    /// The physical coordinate (`mu`, `r`, `alpha` or `eta`, as [`Axis::name`] says) of sample
    /// `i`, on the row of roughness `alpha` (the `adaptive` and `glass` mappings depend on it)
    /// and, for a `mu` axis, at the IOR axis' index `eta_up >= 1` (only `glass` depends on it).
    #[must_use]
    pub fn value_at(&self, i: usize, alpha: f64, eta_up: f64) -> f64 {
        match *self {
            Axis::Mu { mapping, size, .. } => {
                mapping.mu_at(self.coordinate(i), alpha, eta_up, size)
            }
            Axis::Roughness {
                convention,
                spacing,
                ..
            } => spacing.value_at(self.coordinate(i), convention),
            Axis::Ior { mapping, max, .. } => mapping.eta(self.coordinate(i), max.0, alpha),
        }
    }

    /// Whether the physical coordinate of a sample depends on the row (roughness or IOR).
    #[must_use]
    pub fn depends_on_row(&self) -> bool {
        match *self {
            Axis::Mu { mapping, .. } => mapping.depends_on_roughness(),
            Axis::Ior { mapping, .. } => mapping.depends_on_roughness(),
            Axis::Roughness { .. } => false,
        }
    }

    /// What metadata lists for sample `i`: the physical coordinate, or for an axis whose
    /// physical coordinate depends on the row (the `adaptive` and `glass` mappings) the texture
    /// coordinate.
    #[must_use]
    pub fn listed_value(&self, i: usize) -> f64 {
        if self.depends_on_row() {
            self.coordinate(i)
        } else {
            self.value_at(i, 1.0, 1.0)
        }
    }

    /// [`Axis::listed_value`] of every sample.
    #[must_use]
    pub fn listed_values(&self) -> Vec<f64> {
        (0..self.size()).map(|i| self.listed_value(i)).collect()
    }

    /// `alpha` at sample `i` of a roughness axis. Panics on a `mu` axis.
    #[must_use]
    pub fn alpha(&self, i: usize) -> f64 {
        match *self {
            Axis::Roughness { .. } => self.alpha_at_coordinate(self.coordinate(i)),
            Axis::Mu { .. } | Axis::Ior { .. } => panic!("alpha asked of a {} axis", self.name()),
        }
    }

    /// `alpha` at texture coordinate `t` of a roughness axis. Panics on another axis.
    #[must_use]
    pub fn alpha_at_coordinate(&self, t: f64) -> f64 {
        match *self {
            Axis::Roughness {
                convention,
                spacing,
                ..
            } => convention.to_alpha(spacing.value_at(t, convention)),
            Axis::Mu { .. } | Axis::Ior { .. } => panic!("alpha asked of a {} axis", self.name()),
        }
    }

    /// The roughness value (in the axis' convention) at texture coordinate `t` of a roughness
    /// axis. Panics on another axis.
    #[must_use]
    pub fn roughness_at_coordinate(&self, t: f64) -> f64 {
        match *self {
            Axis::Roughness {
                convention,
                spacing,
                ..
            } => spacing.value_at(t, convention),
            Axis::Mu { .. } | Axis::Ior { .. } => {
                panic!("roughness asked of a {} axis", self.name())
            }
        }
    }

    /// The formula from index to value, for metadata and generated docs.
    #[must_use]
    pub fn formula(&self) -> String {
        match *self {
            Axis::Mu { mapping, grid, .. } => format!("{}, {}", grid.formula(), mapping.formula()),
            Axis::Roughness {
                convention,
                grid,
                spacing,
                ..
            } => match (convention, spacing) {
                (RoughnessConvention::Perceptual, RoughnessSpacing::Linear) => {
                    format!("{}, r = t_i, alpha = r^2", grid.formula())
                }
                (RoughnessConvention::Alpha, RoughnessSpacing::Linear) => {
                    format!("{}, alpha = t_i", grid.formula())
                }
                (_, RoughnessSpacing::Balanced) => {
                    let l = super::balanced_layout::BalancedLayout::KILN;
                    format!(
                        "{}, t_i = {} P(r) + {} r^2 (3 - 2 r), P(r) = ((r^2 + d^2)^({} / 2) - \
                         d^{}) / ((1 + d^2)^({} / 2) - d^{}), d = {} (r at t_i by bisection), \
                         alpha = r^2",
                        grid.formula(),
                        1.0 - l.roughness_knee,
                        l.roughness_knee,
                        l.roughness_power,
                        l.roughness_power,
                        l.roughness_power,
                        l.roughness_power,
                        l.roughness_offset
                    )
                }
            },
            Axis::Ior {
                mapping, grid, max, ..
            } => format!(
                "{}, {}, eta_max = {}",
                grid.formula(),
                mapping.formula(),
                max.0
            ),
        }
    }

    /// The continuous sample position (in units of samples, clamped to `[0, N - 1]`) of the
    /// physical coordinate `x` on the row of roughness `alpha` (and, for a `glass` mu axis, at
    /// the IOR axis' index `eta_up >= 1`): what a bilinear lookup of this axis interpolates at.
    #[must_use]
    pub fn position(&self, x: f64, alpha: f64, eta_up: f64) -> f64 {
        let t = match *self {
            Axis::Mu { mapping, size, .. } => mapping.coordinate_at(x, alpha, eta_up, size),
            Axis::Roughness {
                convention,
                spacing,
                ..
            } => spacing.coordinate(x, convention),
            Axis::Ior { mapping, max, .. } => mapping.coordinate(x, max.0, alpha),
        };
        let n = self.size() as f64;
        let p = match self.grid() {
            Grid::Centers => t * n - 0.5,
            Grid::Nodes => t * (n - 1.0),
        };
        p.clamp(0.0, n - 1.0)
    }
}

/// The `mu` of the grazing probes `verify` adds on every roughness of its ladder, whatever the
/// table's axis (and a lookup fit compares at, [`super::lookup_fit`]): exactly 0, 1e-12, and
/// 1e-6 to 1 in 24 log steps (the boundary layer `mu ~ alpha` that a coarse texture-space ladder
/// can step over).
#[must_use]
pub fn grazing_probes() -> Vec<f64> {
    let mut probes = vec![0.0, 1e-12];
    probes.extend((0..=24).map(|k| 10f64.powf(-6.0 + f64::from(k) / 4.0)));
    probes
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_conventions() {
        assert_eq!(Grid::Centers.coordinate(0, 32), 0.5 / 32.0);
        assert_eq!(Grid::Centers.coordinate(31, 32), 31.5 / 32.0);
        assert_eq!(Grid::Nodes.coordinate(0, 32), 0.0);
        assert_eq!(Grid::Nodes.coordinate(31, 32), 1.0);
        let mu = Axis::Mu {
            size: 4,
            mapping: MuMapping::Sqrt,
            grid: Grid::Nodes,
        };
        assert_eq!(mu.listed_values(), [0.0, 1.0 / 9.0, 4.0 / 9.0, 1.0]);
        // An adaptive axis lists its texture coordinates: its mu moves from row to row.
        let adaptive = Axis::Mu {
            size: 4,
            mapping: MuMapping::Adaptive,
            grid: Grid::Nodes,
        };
        assert_eq!(adaptive.listed_values(), [0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0]);
        let r = Axis::Roughness {
            size: 2,
            convention: RoughnessConvention::Perceptual,
            grid: Grid::Centers,
            spacing: crate::table::axis::RoughnessSpacing::Linear,
        };
        assert_eq!(r.listed_values(), [0.25, 0.75]);
        assert_eq!(r.alpha(1), 0.5625);
    }

    /// The names on the command line and in metadata are serde's, which files are read by;
    /// each formula names its own variables.
    #[test]
    fn conventions_are_named_as_files_read_them() {
        let serde_name = |v: serde_json::Value| v.as_str().unwrap().to_string();
        for grid in [Grid::Centers, Grid::Nodes] {
            assert_eq!(serde_name(serde_json::to_value(grid).unwrap()), grid.name());
        }
        for mapping in [MuMapping::Linear, MuMapping::Sqrt, MuMapping::Adaptive] {
            assert_eq!(
                serde_name(serde_json::to_value(mapping).unwrap()),
                mapping.name()
            );
            assert!(mapping.formula().contains("mu = "), "{}", mapping.formula());
        }
        for mapping in [IorMapping::Linear, IorMapping::Cycles, IorMapping::Blender] {
            assert_eq!(
                serde_name(serde_json::to_value(mapping).unwrap()),
                mapping.name()
            );
            assert!(
                mapping.formula().contains("eta = "),
                "{}",
                mapping.formula()
            );
        }
        assert!(Grid::Centers.formula().contains("(i + 0.5) / N"));
        assert!(Grid::Nodes.formula().contains("i / (N - 1)"));
        // A single node sits at the start of the axis.
        assert_eq!(Grid::Nodes.coordinate(0, 1), 0.0);
        let axes = [
            Axis::Mu {
                size: 2,
                mapping: MuMapping::Sqrt,
                grid: Grid::Nodes,
            },
            Axis::Roughness {
                size: 2,
                convention: RoughnessConvention::Perceptual,
                grid: Grid::Centers,
                spacing: crate::table::axis::RoughnessSpacing::Linear,
            },
            Axis::Roughness {
                size: 2,
                convention: RoughnessConvention::Alpha,
                grid: Grid::Nodes,
                spacing: crate::table::axis::RoughnessSpacing::Linear,
            },
            Axis::Ior {
                size: 2,
                mapping: IorMapping::Cycles,
                max: IorBound(3.0),
                grid: Grid::Nodes,
            },
        ];
        let names: Vec<_> = axes.iter().map(Axis::name).collect();
        assert_eq!(names, ["mu", "r", "alpha", "eta"]);
        let formulas: Vec<_> = axes.iter().map(Axis::formula).collect();
        assert!(formulas[0].starts_with("t_i = i / (N - 1), mu = t^2"));
        assert!(formulas[1].starts_with("t_i = (i + 0.5) / N, r = t_i, alpha = r^2"));
        assert!(formulas[2].starts_with("t_i = i / (N - 1), alpha = t_i"));
        assert!(formulas[3].ends_with("eta_max = 3"), "{}", formulas[3]);
    }

    #[test]
    fn ior_mappings_invert() {
        for mapping in [IorMapping::Linear, IorMapping::Cycles] {
            let axis = Axis::Ior {
                size: 16,
                mapping,
                max: IorBound(3.0),
                grid: Grid::Nodes,
            };
            assert_eq!(axis.value_at(0, 1.0, 1.0), 1.0);
            assert!((axis.value_at(15, 1.0, 1.0) - 3.0).abs() < 1e-14);
            for i in 0..16 {
                let eta = axis.value_at(i, 1.0, 1.0);
                assert!((axis.position(eta, 1.0, 1.0) - i as f64).abs() < 1e-9);
                // From inside: 1 / eta sits at the same place.
                assert!((axis.position(1.0 / eta, 1.0, 1.0) - i as f64).abs() < 1e-9);
            }
        }
        // Cycles' z: F0 = z^4.
        let eta = IorMapping::Cycles.eta(0.5, 1.5, 1.0);
        let z = 0.5 * (0.5f64 / 2.5).sqrt();
        assert!((((eta - 1.0) / (eta + 1.0)).powi(2) - z.powi(4)).abs() < 1e-15);
    }

    /// Blender's glass axis: `z = clamp(t, 1e-4, 0.99)`, `eta = (1 + z^2) / (1 - z^2)` whatever
    /// `eta_max` (`precompute.cpp`), worked by hand: `t = 0.5` is `eta = 1.25 / 0.75 = 5/3`,
    /// the ends are `1 + 2e-8` and `1.9801 / 0.0199`; the lookup reads `t = z` unclamped.
    #[test]
    fn blenders_ior_axis_is_its_clamped_z() {
        let blender = IorMapping::Blender;
        assert!((blender.eta(0.5, 3.0, 1.0) - 5.0 / 3.0).abs() < 1e-15);
        assert!((blender.eta(0.0, 3.0, 1.0) - (1.0 + 2e-8)).abs() < 1e-15);
        assert!((blender.eta(1.0, 3.0, 1.0) / (1.9801 / 0.0199) - 1.0).abs() < 1e-13);
        assert!((blender.coordinate(5.0 / 3.0, 3.0, 1.0) - 0.5).abs() < 1e-15);
        assert!((blender.coordinate(0.6, 3.0, 1.0) - 0.5).abs() < 1e-15);
        // Bounds compare and hash by their bits: two axes to different ends are two keys.
        let axis = |max: f64| Axis::Ior {
            size: 16,
            mapping: blender,
            max: IorBound(max),
            grid: Grid::Nodes,
        };
        let keys: std::collections::HashSet<Axis> = [axis(3.0), axis(2.0), axis(3.0)].into();
        assert_eq!(keys.len(), 2);
        let hash = |a: Axis| {
            use std::hash::{BuildHasher, BuildHasherDefault};
            BuildHasherDefault::<std::collections::hash_map::DefaultHasher>::default().hash_one(a)
        };
        assert_ne!(hash(axis(3.0)), hash(axis(2.0)));
    }

    #[test]
    fn position_inverts_value() {
        for grid in [Grid::Centers, Grid::Nodes] {
            for mapping in [MuMapping::Linear, MuMapping::Sqrt, MuMapping::Adaptive] {
                let axis = Axis::Mu {
                    size: 16,
                    mapping,
                    grid,
                };
                for alpha in [1e-7, 1e-3, 0.3, 1.0, 2.0] {
                    for i in 0..16 {
                        let p = axis.position(axis.value_at(i, alpha, 1.0), alpha, 1.0);
                        assert!((p - i as f64).abs() < 1e-9, "{mapping:?} {alpha} {i}: {p}");
                    }
                }
            }
        }
    }
}
