//! Directional albedo `E(mu)` and its cosine-weighted average `E_avg` by quasi-Monte Carlo:
//! visible-normal (VNDF) importance sampling driven by Owen-scrambled Sobol points.
//!
//! With `m` drawn from the visible normals of `o` and `i = reflect(o, m)`, the F = 1 albedo
//! `E(mu_o) = ∫ f(o, i) mu_i dω_i` is the mean of `w = G2(o, i) / G1(o)` when `i` is above the
//! horizon and 0 below (Heitz & d'Eon 2014, eq. 10; `docs/physics.md`, "Estimating E"). kiln accumulates
//! `1 - w` (see [`Masking::loss`]), so `1 - E` keeps its relative precision near `E = 1`.
//!
//! `E_avg = 2 ∫_0^1 E(mu) mu dmu = ∫_0^1 E(sqrt(s)) ds` is integrated in its own right, with `s =
//! mu^2` as a third QMC dimension, not summed from a coarse table.
//!
//! Each estimate runs `R` independent scrambles of `N / R` points and reports the spread between
//! them as its standard error ([`Estimate::from_replicates`]). Sums run in a fixed order inside one
//! thread, so an estimate is a pure function of its inputs.
//!
//! Near a mirror, and at grazing views, the loss lives in a sliver of the sample space that points
//! placed in proportion to its measure never reach, and every scramble then agrees on a loss that
//! is too small. Each scramble is therefore stratified, every stratum with its own points and
//! weighted by its measure (unbiased for any split): GGX's spherical-cap coordinate by
//! [`GgxView::levels`], Beckmann's visible x-slope by `beckmann_strata`; rough surfaces keep (at
//! most) two equal halves. `cargo run --release --example hard_grid` scores the result on the
//! hardest points against the reference.

use super::beckmann_albedo::BeckmannView;
use super::estimate::Estimate;
pub use super::qmc::QmcSettings;
use super::qmc::{
    MIN_LEVEL_LOG2, Stratum, points_per_level, replicates, stratified_sum, sum_over_block,
};
use super::sobol::OwenSobol;
pub use crate::model::masking::reflection_loss;
use crate::model::vector::sin_from_cos;
pub use crate::numerics::elementary::cos_sin_pi;

use crate::model::{
    Beckmann, Ggx, Masking, MicrofacetDistribution, Model, Ndf, SMOOTH_ALPHA, Vec3,
    albedo_is_exactly_one, smooth_point,
};

const TAG_E: u64 = 0x45;
const TAG_E_AVG: u64 = 0x4541;
const TAG_WEIGHTED: u64 = 0x4548;
pub(crate) const TAG_DIELECTRIC: u64 = 0x4544;
pub(crate) const TAG_DIELECTRIC_AVG: u64 = 0x454441;

/// `E(mu)` for the model at `alpha` (slope-space roughness), `mu = cos(theta_o)` in [0, 1].
///
/// Exact limits are returned without sampling: `alpha = 0` with `mu > 0` (a mirror, `E = 1`)
/// and, for height-correlated masking, `mu = 0` (`E(0) = 1`, `docs/physics.md`). Below
/// [`SMOOTH_ALPHA`] the estimate is taken at the similar point ([`smooth_point`]).
///
/// # Panics
/// If the settings are invalid ([`QmcSettings::validate`]) or `mu`/`alpha` are out of range;
/// callers validate user input first.
#[must_use]
pub fn albedo(model: Model, alpha: f64, mu: f64, settings: &QmcSettings) -> Estimate {
    assert!((0.0..=1.0).contains(&mu) && alpha >= 0.0 && alpha.is_finite());
    if albedo_is_exactly_one(model, alpha, mu) {
        return Estimate::exact(0.0);
    }
    let (alpha, mu) = smooth_point(alpha, mu);
    let key = [TAG_E, model_key(model), alpha.to_bits(), mu.to_bits()];
    // Everything that depends on the view only is set up once, outside the scrambles.
    match (model.ndf, model.masking) {
        (Ndf::Ggx, Masking::HeightCorrelated) => {
            let view = GgxView::new(alpha, mu, sin_from_cos(mu));
            let levels = view.levels();
            replicates(settings, &key, |seq, log2_n| {
                levels_sum(
                    seq,
                    log2_n,
                    &levels,
                    #[inline(always)]
                    |u0, t| ggx_loss::<true>(&view, u0, t),
                )
            })
        }
        (Ndf::Ggx, Masking::Separable) => {
            let view = GgxView::new(alpha, mu, sin_from_cos(mu));
            let levels = view.levels();
            replicates(settings, &key, |seq, log2_n| {
                levels_sum(
                    seq,
                    log2_n,
                    &levels,
                    #[inline(always)]
                    |u0, t| ggx_loss::<false>(&view, u0, t),
                )
            })
        }
        (Ndf::Ggx, masking) => {
            // Schlick-GGX: the generic loss on the GGX cap, stratified like the Smith forms.
            let ndf = Ggx { alpha };
            let o = Vec3::from_mu(mu);
            let lambda_o = ndf.lambda(o);
            let levels = GgxView::new(alpha, mu, sin_from_cos(mu)).levels();
            replicates(settings, &key, |seq, log2_n| {
                levels_sum(seq, log2_n, &levels, |u0, t| {
                    let m = ndf.visible_normal_on_cap(o, u0, t);
                    reflection_loss(ndf, masking, o, lambda_o, m)
                })
            })
        }
        (Ndf::Beckmann, masking) => {
            let view = BeckmannView::new(alpha, mu);
            replicates(settings, &key, |seq, log2_n| {
                view.sum(seq, log2_n, |m| view.loss(masking, m))
            })
        }
    }
}

/// A weighted directional albedo `E_h(mu) = ∫ f(o, i) h(o.m) mu_i dω_i` with `F = 1` inside `f`
/// and the weight `h` of the cosine between the view and the microfacet normal `m` (the half
/// vector) in `[0, 1]`: a Fresnel reflectance `F(o.m)`, or Schlick's `Fc = (1 - o.m)^5` and
/// `1 - Fc` for the split-sum tables. The estimate is `1 - w h` averaged over visible normals
/// (`w = G2 / G1(o)`, 0 below the horizon), so `one_minus_value` is `1 - E_h` estimated directly.
/// Visible normals on GGX's cap ([`Ggx::visible_normal_on_cap`]) or from Beckmann's slopes,
/// stratified as for `E`; not the specialised GGX kernel.
///
/// # Panics
/// As [`albedo`].
#[must_use]
pub fn weighted_albedo(
    model: Model,
    alpha: f64,
    mu: f64,
    h: impl Fn(f64) -> f64 + Copy,
    settings: &QmcSettings,
) -> Estimate {
    assert!((0.0..=1.0).contains(&mu) && alpha >= 0.0 && alpha.is_finite());
    if alpha == 0.0 && mu > 0.0 {
        // A mirror: m = n, so o.m = mu and w = 1.
        return Estimate::exact(1.0 - h(mu));
    }
    if alpha < SMOOTH_ALPHA {
        // As the reference below SMOOTH_ALPHA (`reference::weighted_below_smooth`): E's
        // similarity does not hold for a weight of o.h = mu + O(alpha), so E_h = h(mu) E, and
        // the product's deviation at SMOOTH_ALPHA joins the standard error.
        let e = albedo(model, alpha, mu, settings);
        let weight = h(mu);
        let one_minus_value = 1.0 - weight * e.value;
        let (deviation, _) = if alpha == 0.0 {
            (0.0, 0)
        } else {
            super::reference::weighted_product_deviation(
                model,
                mu,
                h,
                &super::reference::ReferenceSettings::default(),
            )
        };
        return Estimate {
            value: 1.0 - one_minus_value,
            one_minus_value,
            std_error: (weight * e.std_error).hypot(deviation),
            samples: e.samples,
        };
    }
    let key = [
        TAG_WEIGHTED,
        model_key(model),
        alpha.to_bits(),
        mu.to_bits(),
    ];
    match model.ndf {
        Ndf::Ggx => {
            // Visible normals on the GGX cap, stratified like `E` (see [`GgxView::strata`]).
            let ndf = Ggx { alpha };
            let masking = model.masking;
            let o = Vec3::from_mu(mu);
            let lambda_o = ndf.lambda(o);
            let levels = GgxView::new(alpha, mu, sin_from_cos(mu)).levels();
            replicates(settings, &key, |seq, log2_n| {
                levels_sum(seq, log2_n, &levels, |u0, t| {
                    let m = ndf.visible_normal_on_cap(o, u0, t);
                    let w = 1.0 - reflection_loss(ndf, masking, o, lambda_o, m);
                    1.0 - w * h(o.dot(m).clamp(0.0, 1.0))
                })
            })
        }
        Ndf::Beckmann => {
            let view = BeckmannView::new(alpha, mu);
            replicates(settings, &key, |seq, log2_n| {
                view.sum(seq, log2_n, |m| {
                    let w = 1.0 - view.loss(model.masking, m);
                    1.0 - w * h(view.o.dot(m).clamp(0.0, 1.0))
                })
            })
        }
    }
}

/// `E_avg = 2 ∫ E(mu) mu dmu` for the model at `alpha`, integrated directly (see the module docs).
///
/// # Panics
/// As [`albedo`].
#[must_use]
pub fn average_albedo(model: Model, alpha: f64, settings: &QmcSettings) -> Estimate {
    assert!(alpha >= 0.0 && alpha.is_finite());
    if alpha < SMOOTH_ALPHA {
        return Estimate::exact(0.0);
    }
    let key = [TAG_E_AVG, model_key(model), alpha.to_bits()];
    replicates(settings, &key, |seq, log2_n| {
        match (model.ndf, model.masking) {
            (Ndf::Ggx, Masking::HeightCorrelated) => ggx_average_sum::<true>(seq, log2_n, alpha),
            (Ndf::Ggx, Masking::Separable) => ggx_average_sum::<false>(seq, log2_n, alpha),
            (Ndf::Ggx, masking) => {
                let ndf = Ggx { alpha };
                let loss = move |s: f64, u0: f64, pick: fn(&GgxView) -> Stratum, u1: f64| {
                    let so = (1.0 - s).sqrt();
                    let mu = s.sqrt();
                    let stratum = pick(&GgxView::new(alpha, mu, so));
                    let o = Vec3::new(so, 0.0, mu);
                    let m = ndf.visible_normal_on_cap(o, u0, stratum.t(u1));
                    stratum.weight * reflection_loss(ndf, masking, o, ndf.lambda(o), m)
                };
                stratified_sum(
                    seq,
                    log2_n,
                    #[inline(always)]
                    |[u0, u1, s]| loss(s, u0, |v| v.strata().0, u1),
                    #[inline(always)]
                    |[u0, u1, s]| loss(s, u0, |v| v.strata().1, u1),
                )
            }
            (Ndf::Beckmann, masking) => generic_average(Beckmann { alpha }, masking, seq, log2_n),
        }
    })
}

/// The summed loss of one scramble of GGX's `E_avg` with a Smith masking (`s = mu^2` the third
/// dimension), each view's cap split into tail and body ([`GgxView::strata`]).
#[inline(always)]
fn ggx_average_sum<const HEIGHT_CORRELATED: bool>(seq: &OwenSobol, log2_n: u32, alpha: f64) -> f64 {
    stratified_sum(
        seq,
        log2_n,
        #[inline(always)]
        |[u0, u1, s]| {
            let view = GgxView::from_mu2(alpha, s);
            let (body, _) = view.strata();
            body.weight * ggx_loss::<HEIGHT_CORRELATED>(&view, u0, body.t(u1))
        },
        #[inline(always)]
        |[u0, u1, s]| {
            let view = GgxView::from_mu2(alpha, s);
            let (_, tail) = view.strata();
            tail.weight * ggx_loss::<HEIGHT_CORRELATED>(&view, u0, tail.t(u1))
        },
    )
}

/// The summed loss of one scramble of `E_avg` for any distribution and masking, with
/// `s = mu^2` as the third dimension (the readable form; GGX's Smith forms have the
/// specialised kernel).
fn generic_average<N: MicrofacetDistribution>(
    ndf: N,
    masking: Masking,
    seq: &OwenSobol,
    log2_n: u32,
) -> f64 {
    sum_over_block(
        seq,
        log2_n,
        #[inline(always)]
        |[u0, u1, s]| {
            let o = Vec3::new((1.0 - s).sqrt(), 0.0, s.sqrt());
            generic_loss(ndf, masking, o, ndf.lambda(o), [u0, u1])
        },
    )
}

pub(crate) fn model_key(model: Model) -> u64 {
    (model.ndf as u64) << 8 | model.masking as u64
}

/// The loss `1 - w` of one visible-normal sample, for any distribution (the readable form; GGX
/// has a faster specialised twin, [`ggx_loss`]).
#[inline]
#[must_use]
pub fn generic_loss<N: MicrofacetDistribution>(
    ndf: N,
    masking: Masking,
    o: Vec3,
    lambda_o: f64,
    u: [f64; 2],
) -> f64 {
    reflection_loss(ndf, masking, o, lambda_o, ndf.sample_visible_normal(o, u))
}

/// What the GGX kernel needs of the view: `o = (so, 0, mu)` and its stretched direction.
#[derive(Clone, Copy, Debug)]
pub struct GgxView {
    alpha: f64,
    alpha2: f64,
    mu: f64,
    so: f64,
    /// The stretched view `normalize(alpha so, 0, mu)`.
    vx: f64,
    vz: f64,
    /// `1 - vz`, computed without cancellation as `vx^2 / (1 + vz)`.
    one_minus_vz: f64,
    /// `1 + Lambda(o)`.
    one_plus_lambda_o: f64,
    /// [`ggx_tail_bound`] for this view.
    tail_bound: f64,
    /// The share of the cap coordinate given to the tail stratum ([`GgxView::strata`]).
    tail_share: f64,
}

/// Below this cap coordinate's bound from [`ggx_tail_bound`], times this margin, is the tail
/// stratum: the bound is exact only at one azimuth, and the margin also takes in the normals whose
/// reflection grazes the horizon, where the masking loss climbs to 1.
const TAIL_MARGIN: f64 = 4.0;
/// The tail stratum never takes more than half the cap: at grazing views the "tail" is
/// everywhere, and equal halves sample it as well as no split would.
const MAX_TAIL_SHARE: f64 = 0.5;

/// The cap coordinate `t` (see [`Ggx::visible_normal_on_cap`]) above which no GGX visible normal
/// reflects the view `o = (so, 0, mu)` below the horizon, for any azimuth; `vx`, `vz` is the
/// stretched view.
///
/// A reflection leaves the hemisphere only if the normal is tilted by more than
/// `theta* = (pi/2 - theta_o) / 2` (tilted away from `o` in its plane; any other azimuth needs
/// more), `tan(theta*) = mu / (1 + so)`. On the cap the unnormalised half vector is
/// `h = (s cos phi + vx, s sin phi, t (1 + vz))` with `s^2 = (1 + vz)(1 - t)(1 - vz + t (1 + vz))
/// <= vx^2 + t (1 + vz)^2`, and the normal's tilt is `tan(theta_m) = alpha |h_xy| / h_z <=
/// alpha (2 vx + (1 + vz) sqrt(t)) / (t (1 + vz))`. That bound falls to `tan(theta*)` at
/// `sqrt(t) = (b + sqrt(b^2 + 4 a)) / 2` with `a = 2 alpha vx / ((1 + vz) tan(theta*))` and
/// `b = alpha / tan(theta*)`. Infinite at `mu = 0`, where every tilt can leave.
#[must_use]
pub fn ggx_tail_bound(alpha: f64, mu: f64, so: f64, vx: f64, vz: f64) -> f64 {
    let tan_star = mu / (1.0 + so);
    let a = 2.0 * alpha * vx / ((1.0 + vz) * tan_star);
    let b = alpha / tan_star;
    let root = 0.5 * (b + (b * b + 4.0 * a).sqrt());
    root * root
}

/// The cap coordinate below which a GGX visible normal can tilt away from the view at all: the
/// half vector's x-component `s cos(phi) + vx` can be negative only where the cap's radius `s`
/// exceeds `vx`, `t < 2 vz / (1 + vz)`. At grazing views (`vz ~ mu / alpha`) this rim is a sliver
/// holding the normals that reflect the view out of the hemisphere, or along it, where the
/// height-correlated masking loss `Li / (1 + Lo + Li)` with a huge `Lo` is not small.
#[must_use]
pub fn ggx_rim(vz: f64) -> f64 {
    2.0 * vz / (1.0 + vz)
}

impl GgxView {
    /// From `mu` and `so = sqrt(1 - mu^2)`.
    #[inline(always)]
    #[must_use]
    pub fn new(alpha: f64, mu: f64, so: f64) -> Self {
        let stretched = (alpha * alpha * so * so + mu * mu).sqrt();
        let lambda_o = Ggx { alpha }.lambda(Vec3::new(so, 0.0, mu));
        let vx = alpha * so / stretched;
        let vz = mu / stretched;
        let tail_bound = ggx_tail_bound(alpha, mu, so, vx, vz);
        let tail_share = (TAIL_MARGIN * tail_bound.min(ggx_rim(vz))).min(MAX_TAIL_SHARE);
        Self {
            alpha,
            alpha2: alpha * alpha,
            mu,
            so,
            vx,
            vz,
            one_minus_vz: vx * vx / (1.0 + vz),
            one_plus_lambda_o: 1.0 + lambda_o,
            tail_bound,
            tail_share,
        }
    }

    /// From `s = mu^2` in (0, 1], as the `E_avg` integral draws it.
    #[inline(always)]
    #[must_use]
    pub fn from_mu2(alpha: f64, s: f64) -> Self {
        Self::new(alpha, s.sqrt(), (1.0 - s).sqrt())
    }

    /// The strata of the cap coordinate for a sum that resolves GGX's heavy tail at every scale.
    ///
    /// When the tail is not a sliver (its share capped at a half: rough surfaces at views that
    /// are not grazing), the two halves of [`GgxView::strata`]. Otherwise, from the rim up:
    ///
    /// - `[0, delta)`, the tail; where `delta` comes from [`ggx_tail_bound`] (not from the rim of
    ///   a grazing view, [`ggx_rim`]), cut around `c`, the cap coordinate of [`ggx_tail_bound`] (at
    ///   `mu = 1` exactly where the reflection crosses the horizon, elsewhere near it), at
    ///   `c (1 -+ 4^-k)`, `k = 1..K`, `4^-K` down to a quarter of the layer's relative width
    ///   `alpha / sin(2 theta*)`. Just above `c` the reflection
    ///   grazes the horizon and the masking loss climbs to 1 within a tilt of `~alpha / 2`: a
    ///   layer of relative width `~2 alpha`, which at `alpha = 1e-4`, `mu = 1` holds `1.3e-12` of
    ///   `1 - E = 1.00013e-8` in a sliver of `5e-5` of the tail.
    /// - `[delta, 1)`, the body, cut at `delta 4^k`: a normal's tilt goes as `tan^2 ~ alpha^2 / t`
    ///   here, so each rung holds one range of tilts, and whatever grows with the tilt (the
    ///   masking loss, a Schlick weight `(1 - o.m)^5`) is sampled at every scale rather than left
    ///   to the few points that land near `delta` (at `alpha = 1e-3`, `mu = 1`, `F0 = 0.04`, one
    ///   point in 4096 moved the estimate by `3e-9`, 20000 of its stated errors). At a grazing
    ///   view the height-correlated loss `~mu / (mu + mu_i)` gathers equally from every decade
    ///   of the reflection's height `mu_i`, which the rungs sample alike.
    #[must_use]
    pub fn levels(&self) -> Levels {
        let delta = self.tail_share;
        let crossing = self.tail_bound;
        let centre = delta / TAIL_MARGIN;
        if delta >= MAX_TAIL_SHARE {
            return Levels::from_edges(&[0.0, delta, 1.0], delta);
        }
        if delta <= 0.0 || delta.is_nan() {
            // A view on the horizon (`mu = 0`, no rim): one stratum.
            return Levels::from_edges(&[0.0, 1.0], 0.5);
        }
        let mut edges = vec![0.0];
        if crossing <= centre {
            // The layer's relative width in t: a tilt of alpha / 2 at the horizon angle theta*,
            // alpha / sin(2 theta*) relative to tan(theta_m) ~ 1 / t.
            let tan_star = self.mu / (1.0 + self.so);
            let layer = self.alpha * (1.0 + tan_star * tan_star) / (2.0 * tan_star);
            let mut ratios = Vec::new();
            let mut r: f64 = 0.25;
            while r >= layer / 4.0 && ratios.len() < MAX_CROSSING_RUNGS {
                ratios.push(r);
                r *= 0.25;
            }
            edges.extend(ratios.iter().map(|r| centre * (1.0 - r)));
            edges.push(centre);
            edges.extend(ratios.iter().rev().map(|r| centre * (1.0 + r)));
        }
        let mut rung = delta;
        while rung < 0.25 && edges.len() < MAX_GGX_LEVELS {
            edges.push(rung);
            rung *= 4.0;
        }
        edges.push(1.0);
        Levels::from_edges(&edges, delta)
    }

    /// The body and the tail of the cap: `t` in `[delta, 1)` and `[0, delta)`, with `delta` the
    /// share below which GGX's heavy tail reflects the view out of the hemisphere
    /// ([`ggx_tail_bound`] with a margin, at most half). At `alpha = 1e-3`, `mu = 1` that tail is
    /// a sliver of `~1e-6` of the cap carrying all of `1 - E`; sampled in proportion to its
    /// measure, `2^16` points per scramble never reach it and every scramble agrees on a loss
    /// that is too small. Given half the points, it is resolved like the body.
    #[inline(always)]
    #[must_use]
    pub fn strata(&self) -> (Stratum, Stratum) {
        let delta = self.tail_share;
        (
            Stratum {
                start: delta,
                weight: 1.0 - delta,
            },
            Stratum {
                start: 0.0,
                weight: delta,
            },
        )
    }
}

/// At most this many strata in a GGX view's [`Levels`].
const MAX_GGX_LEVELS: usize = 48;
/// At most this many rungs on each side of the horizon crossing ([`GgxView::levels`]).
const MAX_CROSSING_RUNGS: usize = 8;

/// The strata of one GGX view's cap coordinate, from the rim up, covering `[0, 1)`.
#[derive(Clone, Copy, Debug)]
pub struct Levels {
    strata: [Stratum; MAX_GGX_LEVELS],
    count: usize,
    /// The tail's share `delta`, for the coarse split `[0, delta), [delta, 1)`.
    tail_share: f64,
}

impl Levels {
    /// The strata, from the rim (`t = 0`) up.
    #[must_use]
    pub fn strata(&self) -> &[Stratum] {
        &self.strata[..self.count]
    }

    /// These levels with a geometric ladder toward the rim merged in: edges at `ratio^k`
    /// (`ratio` a quarter, or a sixteenth if the quarters would exceed [`MAX_GGX_LEVELS`]) down
    /// to `floor`, leaving out any within a factor 2 of one of these levels' own edges. Below
    /// `floor` the last level runs to the rim, so nothing is left out. For integrands whose rare
    /// events are not the reflection's alone (the dielectric's refraction and total internal
    /// reflection, [`crate::integrate::dielectric`]): each range of tilts near the rim gets its
    /// own points.
    #[must_use]
    pub(crate) fn with_rim_ladder(&self, floor: f64) -> Levels {
        let own: Vec<f64> = self.strata().iter().map(|s| s.start).collect();
        for ratio in [0.25, 1.0 / 16.0, 1.0 / 256.0] {
            let mut edges = own.clone();
            edges.push(1.0);
            let mut rung = ratio;
            while rung >= floor {
                if !own.iter().any(|&e| e > 0.5 * rung && e < 2.0 * rung) {
                    edges.push(rung);
                }
                rung *= ratio;
            }
            if edges.len() <= MAX_GGX_LEVELS + 1 {
                edges.sort_by(f64::total_cmp);
                return Levels::from_edges(&edges, self.tail_share);
            }
        }
        *self
    }

    fn from_edges(edges: &[f64], tail_share: f64) -> Self {
        let mut out = Levels {
            strata: [Stratum {
                start: 0.0,
                weight: 0.0,
            }; MAX_GGX_LEVELS],
            count: edges.len() - 1,
            tail_share,
        };
        for (k, pair) in edges.windows(2).enumerate() {
            out.strata[k] = Stratum {
                start: pair[0],
                weight: pair[1] - pair[0],
            };
        }
        out
    }
}

/// A stratified sum over one scramble for a GGX view's [`Levels`]: the strata share the points
/// as equally as powers of two allow ([`points_per_level`]), each from its own stream of the scramble; with fewer than
/// `2^MIN_LEVEL_LOG2` points per stratum, the coarse split into tail and body instead.
/// `loss(u0, t)` is the loss at azimuth variate `u0` and cap coordinate `t`; the strata's means,
/// weighted by their measure, add up to the integral, returned as a sum over `2^log2_n` points as
/// [`sum_over_block`] does. Unbiased for any strata; deterministic like [`sum_over_block`].
#[inline(always)]
pub(crate) fn levels_sum(
    seq: &OwenSobol,
    log2_n: u32,
    levels: &Levels,
    loss: impl Fn(f64, f64) -> f64 + Copy,
) -> f64 {
    let mut strata = levels.strata();
    let coarse;
    if points_per_level(log2_n, strata.len(), strata.len() - 1) < MIN_LEVEL_LOG2 && strata.len() > 2
    {
        coarse = Levels::from_edges(&[0.0, levels.tail_share, 1.0], levels.tail_share);
        strata = coarse.strata();
    }
    let mut mean = 0.0;
    for (k, stratum) in strata.iter().enumerate() {
        let stratum = *stratum;
        let stream = if k == 0 { *seq } else { seq.stream(k as u64) };
        let log2 = points_per_level(log2_n, strata.len(), k);
        mean += stratum.weight
            * sum_over_block(
                &stream,
                log2,
                #[inline(always)]
                |[u0, u1]: [f64; 2]| loss(u0, stratum.t(u1)),
            )
            / (1u64 << log2) as f64;
    }
    mean * (1u64 << log2_n) as f64
}

/// The loss `1 - w` of one GGX visible normal at azimuth `pi u0` and cap coordinate `t`
/// ([`Ggx::visible_normal_on_cap`]), written out for speed and vectorisation.
///
/// The same computation as [`reflection_loss`] with [`Ggx::visible_normal_on_cap`] (Dupuy &
/// Benyoub 2023), specialised to a view in the xz-plane and with the azimuth folded: the integrand
/// is symmetric under `y -> -y`, so `phi = pi u0` over `[0, pi]` replaces `2 pi u0`, and
/// `sin(phi) >= 0`. `cos` and `sin` of `pi u0` come from polynomials ([`cos_sin_pi`]), no library
/// trigonometry. `HEIGHT_CORRELATED` picks the masking form: `Li / (1 + Lo + Li)` or
/// `Li / (1 + Li)`, with `Li = x / (2 (1 + sqrt(1 + x)))` and `x = alpha^2 tan^2(theta_i)` (tan
/// from components).
#[inline(always)]
#[must_use]
pub fn ggx_loss<const HEIGHT_CORRELATED: bool>(view: &GgxView, u0: f64, t: f64) -> f64 {
    let (cos_phi, sin_phi) = cos_sin_pi(u0);
    // A uniform point of the spherical cap z in (-vz, 1]: z + vz = t (1 + vz).
    let mz = t * (1.0 + view.vz);
    let s = ((1.0 + view.vz) * (1.0 - t) * (view.one_minus_vz + mz))
        .max(0.0)
        .sqrt();
    // Half vector in the stretched space, then unstretched (unnormalised): m ∝ (mx, my, mz).
    let mx = view.alpha * (s * cos_phi + view.vx);
    let my = view.alpha * (s * sin_phi);
    let n2 = mx * mx + my * my + mz * mz;
    // i = 2 (o.m) m - o with |m|^2 = n2.
    let k = 2.0 * (view.so * mx + view.mu * mz) / n2;
    let ix = k * mx - view.so;
    let iy = k * my;
    let iz = k * mz - view.mu;
    let x = view.alpha2 * (ix * ix + iy * iy) / (iz * iz);
    let root2 = 2.0 * (1.0 + (1.0 + x).sqrt());
    let loss = if HEIGHT_CORRELATED {
        x / (root2 * view.one_plus_lambda_o + x)
    } else {
        x / (root2 + x)
    };
    // Below the horizon (or so close that tan^2 overflows) the sample's energy is lost.
    if iz > 0.0 && x < f64::INFINITY {
        loss
    } else {
        1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::qmc::sum_over_block_portable;

    /// The levels' points add up to the sample count: none is dropped, none counted twice.
    #[test]
    fn the_levels_share_every_point() {
        for log2_n in 5..20 {
            for levels in (1..=48).filter(|&l| l <= 1 << log2_n) {
                let total: u64 = (0..levels)
                    .map(|k| 1u64 << points_per_level(log2_n, levels, k))
                    .sum();
                assert_eq!(total, 1 << log2_n, "2^{log2_n} over {levels} levels");
            }
        }
    }

    #[test]
    fn polynomial_cos_sin_match_the_library() {
        for k in 0..=10_000 {
            let u = k as f64 / 10_000.0;
            let (c, s) = cos_sin_pi(u);
            let phi = std::f64::consts::PI * u;
            assert!(
                (c - phi.cos()).abs() < 1e-15 && (s - phi.sin()).abs() < 1e-15,
                "u = {u}"
            );
        }
    }

    /// The specialised GGX kernel is the generic sampler and weight, with the azimuth folded.
    #[test]
    fn ggx_kernel_matches_the_generic_estimator_sample_by_sample() {
        let seq = OwenSobol::new(3);
        for &alpha in &[1e-3, 0.05, 0.4, 1.0, 2.0] {
            for &mu in &[0.0, 1e-6, 0.03, 0.5, 1.0] {
                let o = Vec3::from_mu(mu);
                let ndf = Ggx { alpha };
                let view = GgxView::new(alpha, mu, sin_from_cos(mu));
                for i in 0..500 {
                    let (u0, u1) = (seq.sample(i, 0), seq.sample(i, 1));
                    for masking in Masking::ALL {
                        let generic = generic_loss(ndf, masking, o, ndf.lambda(o), [u0 / 2.0, u1]);
                        let fast = match masking {
                            Masking::HeightCorrelated => ggx_loss::<true>(&view, u0, 1.0 - u1),
                            Masking::Separable => ggx_loss::<false>(&view, u0, 1.0 - u1),
                            Masking::SchlickGgx => unreachable!("ALL holds the Smith forms"),
                        };
                        // Both are a function of a direction computed two ways; near the
                        // horizon that direction is ill-conditioned, so compare loosely there.
                        let tol = if generic > 0.999 || mu < 1e-3 {
                            1e-6
                        } else {
                            1e-10
                        };
                        assert!(
                            (generic - fast).abs() <= tol,
                            "{masking} alpha {alpha} mu {mu} u ({u0}, {u1}): {generic} vs {fast}"
                        );
                    }
                }
            }
        }
    }

    fn hc(ndf: Ndf) -> Model {
        Model {
            ndf,
            masking: Masking::HeightCorrelated,
        }
    }

    /// The AVX2 build of the summation loop gives the same bits as the portable one.
    #[test]
    fn simd_and_portable_sums_are_bit_identical() {
        let seq = OwenSobol::new(11);
        let view = GgxView::new(0.3, 0.4, sin_from_cos(0.4));
        let kernel = |[u0, u1]: [f64; 2]| ggx_loss::<true>(&view, u0, u1);
        let portable = sum_over_block_portable(&seq, 12, kernel);
        assert_eq!(
            sum_over_block(&seq, 12, kernel).to_bits(),
            portable.to_bits()
        );
        let beckmann = |[u0, u1, s]: [f64; 3]| {
            let ndf = Beckmann { alpha: 0.3 };
            let o = Vec3::new((1.0 - s).sqrt(), 0.0, s.sqrt());
            generic_loss(ndf, Masking::Separable, o, ndf.lambda(o), [u0, u1])
        };
        let portable = sum_over_block_portable(&seq, 10, beckmann);
        assert_eq!(
            sum_over_block(&seq, 10, beckmann).to_bits(),
            portable.to_bits()
        );
    }

    #[test]
    fn closed_form_at_normal_incidence() {
        // GGX, mu = 1, alpha = 1: E = 1 - ln 2 (docs/physics.md).
        let e = albedo(hc(Ndf::Ggx), 1.0, 1.0, &QmcSettings::default());
        let exact = 1.0 - std::f64::consts::LN_2;
        assert!(e.std_error < 1e-5 && e.std_error > 0.0);
        assert!(
            (e.value - exact).abs() < 5.0 * e.std_error,
            "{e:?} vs {exact}"
        );
    }

    /// A mirror (`alpha = 0`) reflects about `m = n`, so the weighted albedo is the weight at
    /// `o.m = mu` itself: Schlick's `F0 + (1 - F0)(1 - mu)^5`, returned exactly without sampling.
    #[test]
    fn the_weighted_albedo_of_a_mirror_is_its_weight() {
        for ndf in Ndf::ALL {
            let (f0, mu) = (0.04, 0.6);
            let schlick = |c: f64| f0 + (1.0 - f0) * (1.0 - c).powi(5);
            let e = weighted_albedo(hc(ndf), 0.0, mu, schlick, &QmcSettings::default());
            let exact = 0.04 + 0.96 * 0.4f64.powi(5);
            assert!((e.value - exact).abs() < 1e-15, "{ndf}: {e:?}");
            assert!(
                (e.one_minus_value - (1.0 - exact)).abs() < 1e-15,
                "{ndf}: {e:?}"
            );
            assert_eq!((e.std_error, e.samples), (0.0, 0));
        }
    }

    #[test]
    fn estimates_are_reproducible_and_seed_dependent() {
        let s = QmcSettings {
            samples: 1 << 12,
            ..QmcSettings::default()
        };
        let a = albedo(hc(Ndf::Beckmann), 0.3, 0.4, &s);
        assert_eq!(a, albedo(hc(Ndf::Beckmann), 0.3, 0.4, &s));
        let b = albedo(hc(Ndf::Beckmann), 0.3, 0.4, &QmcSettings { seed: 1, ..s });
        assert_ne!(a.value, b.value);
    }

    #[test]
    fn settings_are_validated() {
        let ok = QmcSettings::default();
        assert!(ok.validate().is_ok());
        assert!(
            QmcSettings {
                samples: 1000,
                ..ok
            }
            .validate()
            .is_err()
        );
        assert!(QmcSettings { samples: 4, ..ok }.validate().is_err());
        assert!(QmcSettings { scrambles: 1, ..ok }.validate().is_err());
        assert!(QmcSettings { scrambles: 6, ..ok }.validate().is_err());
    }
}
