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

use super::estimate::Estimate;
use super::sobol::{OwenSobol, mix_seed};
pub use crate::model::masking::reflection_loss;
use crate::model::ndf::{BeckmannVisibleNormals, VisibleSlopeX};
use crate::model::special::{FRAC_1_SQRT_PI, erfc};

use crate::model::{
    Beckmann, Ggx, Masking, MicrofacetDistribution, Model, Ndf, SMOOTH_ALPHA, Vec3,
    albedo_is_exactly_one, smooth_point,
};

/// The unit-roughness slopes the Beckmann sum samples inside the lost circle reach at most this
/// far from 0; the share beyond, under `exp(-27^2) = 1e-317` (below f64's smallest normal
/// number), counts as lost.
const SLOPE_REACH: f64 = 27.0;

/// How a QMC estimate is run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub struct QmcSettings {
    /// Integrand evaluations per estimate, a power of two, split evenly over the scrambles.
    pub samples: u64,
    /// Independent scrambles `R` (at least 2, a power of two), for the standard error.
    pub scrambles: u32,
    /// The base seed; every estimate derives its scrambles from it and its own coordinates.
    pub seed: u64,
}

impl QmcSettings {
    /// 2^19 evaluations in 8 scrambles: a standard error below 1e-6 at mid-range points of GGX
    /// `E` (measured: at most 3.4e-7 for mu and alpha in {0.3, 0.5, 0.7}; 2^18 gives up to 1.1e-6).
    pub const DEFAULT_SAMPLES: u64 = 1 << 19;
    /// Eight scrambles: the standard error then has 7 degrees of freedom.
    pub const DEFAULT_SCRAMBLES: u32 = 8;

    /// How many times a directional estimate's evaluations an average over `mu` (`E_avg`)
    /// takes by default: it integrates over `mu` as well, and its tables are 1-D and cheap.
    pub const AVERAGE_FACTOR: u64 = 16;

    /// The default evaluations of an average for `samples` per directional estimate
    /// ([`QmcSettings::AVERAGE_FACTOR`] times, saturating).
    #[must_use]
    pub fn average_samples_for(samples: u64) -> u64 {
        samples.saturating_mul(Self::AVERAGE_FACTOR)
    }

    /// The most points one scramble takes (its Sobol index is 32 bits).
    pub const MAX_POINTS_PER_SCRAMBLE: u64 = 1 << 32;

    /// The sample counts these scrambles allow: powers of two from one point per scramble to
    /// [`QmcSettings::MAX_POINTS_PER_SCRAMBLE`] per scramble.
    #[must_use]
    pub fn sample_range(&self) -> (u64, u64) {
        let min = u64::from(self.scrambles.max(1));
        (min, min.saturating_mul(Self::MAX_POINTS_PER_SCRAMBLE))
    }

    /// Checks the settings, saying what is wrong and what is allowed; messages start with the
    /// flag (`--scrambles`, `--samples`): callers naming another flag replace `--samples`.
    pub fn validate(&self) -> Result<(), String> {
        if self.scrambles < 2 || !self.scrambles.is_power_of_two() || self.scrambles > 1024 {
            return Err(format!(
                "--scrambles must be a power of two from 2 to 1024 (got {})",
                self.scrambles
            ));
        }
        let (min, max) = self.sample_range();
        if !self.samples.is_power_of_two() || self.samples < min || self.samples > max {
            return Err(format!(
                "--samples must be a power of two from {min} to 2^{} (one to 2^32 points for each \
                 of the {} scrambles; got {})",
                max.trailing_zeros(),
                self.scrambles,
                self.samples
            ));
        }
        Ok(())
    }

    /// `log2` of the points per scramble.
    fn log2_per_scramble(&self) -> u32 {
        self.samples.trailing_zeros() - self.scrambles.trailing_zeros()
    }
}

impl Default for QmcSettings {
    fn default() -> Self {
        Self {
            samples: Self::DEFAULT_SAMPLES,
            scrambles: Self::DEFAULT_SCRAMBLES,
            seed: 0,
        }
    }
}

/// Tags that keep the scrambles of different quantities apart.
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

/// `sqrt(1 - mu^2)` computed as `sqrt((1 - mu)(1 + mu))`, accurate near `mu = 1`.
pub(crate) fn sin_from_cos(mu: f64) -> f64 {
    ((1.0 - mu) * (1.0 + mu)).max(0.0).sqrt()
}

/// Runs the scrambles and combines their means of `1 - w`.
pub(crate) fn replicates(
    settings: &QmcSettings,
    key: &[u64],
    mut sum_loss: impl FnMut(&OwenSobol, u32) -> f64,
) -> Estimate {
    settings.validate().expect("invalid QMC settings");
    let log2_n = settings.log2_per_scramble();
    let n = (1u64 << log2_n) as f64;
    let mut seed_words = Vec::with_capacity(key.len() + 2);
    seed_words.push(settings.seed);
    seed_words.extend_from_slice(key);
    seed_words.push(0);
    let means: Vec<f64> = (0..settings.scrambles)
        .map(|r| {
            *seed_words.last_mut().expect("non-empty") = u64::from(r);
            let seq = OwenSobol::new(mix_seed(&seed_words));
            sum_loss(&seq, log2_n) / n
        })
        .collect();
    Estimate::from_replicates(&means, settings.samples)
}

/// Points processed per batch: the unit-square coordinates of a batch are produced first, then the
/// integrand runs over them in a loop the compiler can vectorise, then the batch is summed.
const BATCH: usize = 256;

/// Sums `loss` over the `2^log2_n` points of one scrambled sequence (dimensions `0..D`), with the
/// widest SIMD the CPU offers: on x86-64 with AVX2, the same code compiled for AVX2. The result
/// is bit-identical either way: the loop does the same IEEE operations in the same order (Rust
/// never fuses a multiply and an add on its own), only more lanes at a time.
///
/// Every `loss` closure passed here is marked `#[inline(always)]`: without it the inliner may
/// leave the closure as a call inside the AVX2 loop, which then stops vectorising (measured: the
/// GGX `E_avg` kernel ran 3x slower once an unrelated module was added to the crate).
#[inline(always)]
pub(crate) fn sum_over_block<const D: usize>(
    seq: &OwenSobol,
    log2_n: u32,
    loss: impl Fn([f64; D]) -> f64,
) -> f64 {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU supports AVX2, checked on the line above.
        return unsafe { sum_over_block_avx2(seq, log2_n, loss) };
    }
    sum_over_block_portable(seq, log2_n, loss)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn sum_over_block_avx2<const D: usize>(
    seq: &OwenSobol,
    log2_n: u32,
    loss: impl Fn([f64; D]) -> f64,
) -> f64 {
    sum_over_block_portable(seq, log2_n, loss)
}

/// Sums `loss` over the `2^log2_n` points of one scrambled sequence (dimensions `0..D`), in a
/// fixed order: eight interleaved partial sums per batch, batches added in turn.
#[inline(always)]
fn sum_over_block_portable<const D: usize>(
    seq: &OwenSobol,
    log2_n: u32,
    loss: impl Fn([f64; D]) -> f64,
) -> f64 {
    let mut block = seq.block::<D>(log2_n);
    let mut raw = [[0u32; BATCH]; D];
    let mut unit = [[0f64; BATCH]; D];
    let mut losses = [0f64; BATCH];
    let mut total = 0.0;
    while block.remaining() > 0 {
        let len = (block.remaining() as usize).min(BATCH);
        {
            let mut slices: [&mut [u32]; D] = {
                let mut it = raw.iter_mut();
                std::array::from_fn(|_| &mut it.next().expect("D rows")[..len])
            };
            block.fill_reversed(&mut slices);
        }
        for d in 0..D {
            for k in 0..len {
                unit[d][k] = seq.to_unit(seq.scramble_reversed(raw[d][k], d), d);
            }
        }
        for k in 0..len {
            losses[k] = loss(std::array::from_fn(|d| unit[d][k]));
        }
        let mut lanes = [0f64; 8];
        for chunk in losses[..len].chunks(8) {
            for (lane, &x) in lanes.iter_mut().zip(chunk) {
                *lane += x;
            }
        }
        total += ((lanes[0] + lanes[1]) + (lanes[2] + lanes[3]))
            + ((lanes[4] + lanes[5]) + (lanes[6] + lanes[7]));
    }
    total
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

/// One stratum of the cap coordinate: `t = start + width u` for `u` uniform in [0, 1), whose
/// samples carry the stratum's measure `weight = width` (see `stratified_sum`).
#[derive(Clone, Copy, Debug)]
pub struct Stratum {
    pub start: f64,
    pub weight: f64,
}

impl Stratum {
    /// The cap coordinate of the stratum's point `u`.
    #[inline(always)]
    #[must_use]
    pub fn t(&self, u: f64) -> f64 {
        self.start + self.weight * u
    }
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

/// `log2` of the points level `k` of `levels` gets when `2^log2_n` points are shared as equally
/// as powers of two allow: with `2^c` the next power of two from `levels`, each level gets
/// `2^(log2_n - c)` and the last `2^c - levels` levels twice that, so that the shares add up to
/// `2^log2_n` exactly (at least one point each when `2^log2_n < levels`).
fn points_per_level(log2_n: u32, levels: usize, k: usize) -> u32 {
    let c = (levels as u32).next_power_of_two().trailing_zeros();
    let doubled = (1usize << c) - levels;
    let base = log2_n.saturating_sub(c);
    if k >= levels - doubled && log2_n >= c {
        base + 1
    } else {
        base
    }
}

/// A stratified sum over one scramble: half the `2^log2_n` points of `seq` go through `body` and
/// half, from an independent stream of the same scramble, through `tail` (one point each when
/// `log2_n = 0`). Each closure weights its loss by its stratum's measure, so the two means add up
/// to the integral; the result is scaled to a sum over `2^log2_n` points, as
/// [`sum_over_block`] returns. Unbiased for any split, deterministic like [`sum_over_block`].
#[inline(always)]
pub(crate) fn stratified_sum<const D: usize>(
    seq: &OwenSobol,
    log2_n: u32,
    body: impl Fn([f64; D]) -> f64,
    tail: impl Fn([f64; D]) -> f64,
) -> f64 {
    let half = log2_n.saturating_sub(1);
    let scale = (1u64 << log2_n) as f64 / (1u64 << half) as f64;
    let body = sum_over_block(seq, half, body);
    let tail = sum_over_block(&seq.stream(1), half, tail);
    (body + tail) * scale
}

/// The share of the points below which a stratum is not worth its own: a ladder whose levels
/// would get fewer than `2^MIN_LEVEL_LOG2` points per scramble falls back to the coarse split
/// (at such counts no rare event is resolved anyway, and the levels' spread would only make the
/// standard error noisier).
const MIN_LEVEL_LOG2: u32 = 4;
/// Below this share the lost slopes cannot matter (their loss is at most the share) and a
/// ladder down to them would only thin out the points elsewhere: at normal incidence on
/// Beckmann alpha = 0.1 (lost share `~1e-45`) its levels left the y-slope's tail to 2^13 points
/// each, and the Schlick-weighted albedo, which grows as the tilt's tenth power, came out 1 %
/// low (6 standard errors).
const NEGLIGIBLE_SHARE: f64 = 1e-20;
/// A Beckmann view is grazing, for the ladder of its height-correlated layer, when the stretched
/// view's `cot(theta) = mu / (alpha so)` is below this (`mu` under a tenth of `alpha`): above
/// it the layer is not rare, and the levels would only thin out the body's points (at alpha =
/// 0.64, mu = 0.49 and 2^13 samples the node error rose from 2e-4 to 1.9e-3).
const GRAZING_COT: f64 = 0.1;
/// Grazing views take the ladder only below this roughness: above it the masking layer's loss
/// is spread over the body of the visible normals (the reflection's `Lambda` matters wherever it
/// leaves within `alpha` of the horizon), and the [`LostCircle`] resolves it better (measured at
/// 2^16 samples, `mu` from 1e-4 to 0.06: at alpha 0.2 the ladder's standard error is 1.2 to 2.8
/// times below the circle's, at 0.3 mixed, from 0.4 the circle's is 2 to 50 times below).
const GRAZING_LADDER_MAX_ALPHA: f64 = 0.25;
/// A view is sampled by its reflected directions ([`BeckmannSampling::Reflection`]) when the
/// lost circle's far end `(1 + so) / (mu alpha)` (the slope of the normal that reflects the view
/// to the horizon on the far side) lies within this many unit-roughness slopes of 0: then the
/// circle's boundary cuts through the body of the visible normals, and the density of the
/// reflected directions varies by at most `exp(2.65^2) ~ 1100` over the hemisphere (measured at
/// 2^16 samples: at alpha 0.7, mu 1 the standard error fell 6.7x, at alpha 1.5, mu 0.99 18x; at
/// a far end of 3 to 4 the circle was the better by up to 2x).
const REFLECTION_MAX_FAR_END: f64 = 2.65;
/// Each level of the ladder holds this fraction of the share above it.
const LADDER_RATIO: f64 = 1.0 / 16.0;
/// At most this many tail levels (the deepest then reaches a share of `0.5 / 16^14 ~ 7e-18`; the
/// last level runs to 0, so nothing is left out, only sampled more thinly).
const MAX_LADDER_LEVELS: usize = 15;

/// The strata of a Beckmann view's visible x-slope, as shares `w` of the slopes above (see
/// [`crate::model::ndf::VisibleSlopeX::upper_share`]): `[1/2, 1]` (the body, half the points), then a ladder of
/// levels each holding a sixteenth of the share above it, down past the share `w_lost` of the
/// slopes whose reflection leaves the hemisphere, then the rest down to 0. At a grazing view of a
/// smooth surface (`mu = 10 alpha`) that share is `~1e-11`: the Gaussian tail's sliver that plain
/// visible-normal sampling never reaches, and where all of `1 - E` lives. Each level then holds its
/// part of the loss in at least a sixteenth of its measure. When the losses are not rare (the
/// lost slopes' share above 1/64) or negligible (below [`NEGLIGIBLE_SHARE`]), one stratum: plain sampling, except at grazing views (the
/// stretched view's `cot(theta) = mu / (alpha so)` below [`GRAZING_COT`]), whose ladder runs down to the slopes
/// within 1 % of their end.
fn beckmann_strata(visible: &BeckmannVisibleNormals, alpha: f64, mu: f64) -> Vec<Stratum> {
    let so = sin_from_cos(mu);
    let lost_slope = (1.0 - so) / (mu * alpha);
    let slopes = visible.slope_x();
    // The stretched view's cot(theta): the visible x-slopes end there.
    let b = mu / (alpha * so);
    let lost_share = if lost_slope.is_finite() {
        slopes.upper_share(lost_slope)
    } else {
        1.0
    };
    let lost = if (NEGLIGIBLE_SHARE..1.0 / 64.0).contains(&lost_share) {
        // The levels above the lost share take in the masking layer below the lost slopes.
        slopes.upper_share(lost_slope)
    } else if b < GRAZING_COT && mu > 0.0 {
        // A grazing view: the reflection's height `mu_i` falls with the distance of the slope
        // from its end `b`, and the height-correlated loss `~mu / (mu + mu_i)` gathers equally
        // from every decade of it, down to `mu_i ~ mu / 100`: rungs down to that slope's share.
        slopes.upper_share(0.99 * b)
    } else {
        return vec![Stratum {
            start: 0.0,
            weight: 1.0,
        }];
    };
    ladder_down_to(lost)
}

/// The ladder of [`beckmann_strata`] over the visible x-slope's share: `[1/2, 1]`, then levels
/// each holding [`LADDER_RATIO`] of the share above, until one starts below `lost` (at most
/// [`MAX_LADDER_LEVELS`]), then the rest down to 0.
fn ladder_down_to(lost: f64) -> Vec<Stratum> {
    let mut strata = vec![Stratum {
        start: 0.5,
        weight: 0.5,
    }];
    let mut top: f64 = 0.5;
    while top >= lost && strata.len() < MAX_LADDER_LEVELS {
        let bottom = top * LADDER_RATIO;
        strata.push(Stratum {
            start: bottom,
            weight: top - bottom,
        });
        top = bottom;
    }
    strata.push(Stratum {
        start: 0.0,
        weight: top,
    });
    strata
}

/// Strata of the visible x-slope's share for rare events in either tail: the body `[1/4, 3/4]`
/// (half the points), then on each side levels each holding [`LADDER_RATIO`] of the share
/// beyond, down to the share `floor` in the upper tail (normals tilted away from the view) and
/// to `max(floor, 1e-12)` in the lower (tilted toward it: the share is `1 - w` there, and `w`
/// near 1 keeps fewer digits), then the rest of each tail.
fn two_sided_ladder(floor: f64) -> Vec<Stratum> {
    let mut strata = vec![Stratum {
        start: 0.25,
        weight: 0.5,
    }];
    for (side_floor, upper) in [(floor, true), (floor.max(1e-12), false)] {
        let mut top: f64 = 0.25;
        while top >= side_floor {
            let bottom = top * LADDER_RATIO;
            let start = if upper { bottom } else { 1.0 - top };
            strata.push(Stratum {
                start,
                weight: top - bottom,
            });
            top = bottom;
        }
        strata.push(Stratum {
            start: if upper { 0.0 } else { 1.0 - top },
            weight: top,
        });
    }
    strata
}

/// What the Beckmann sums need of one view `o = (so, 0, mu)`, set up once per estimate: the
/// visible-normal sampler and how the points are placed ([`BeckmannSampling`]).
pub(crate) struct BeckmannView {
    ndf: Beckmann,
    pub(crate) o: Vec3,
    pub(crate) lambda_o: f64,
    visible: BeckmannVisibleNormals,
    sampling: BeckmannSampling,
}

/// How a Beckmann view's sum places its points.
enum BeckmannSampling {
    /// Inside the slopes whose reflection stays above the horizon ([`LostCircle`]): every view
    /// but the grazing ones of smooth surfaces and the near-normal ones of rough surfaces.
    Circle(LostCircle),
    /// By the reflected direction, uniform over the hemisphere ([`BeckmannView::reflection_sum`]):
    /// views whose lost circle ends within [`REFLECTION_MAX_FAR_END`] slopes of 0.
    Reflection,
    /// By the strata of [`beckmann_strata`] over the visible x-slope's share: grazing views (the
    /// stretched view's `cot(theta)` below [`GRAZING_COT`]) at roughness below
    /// [`GRAZING_LADDER_MAX_ALPHA`], whose masking layer they resolve.
    Ladder(Vec<Stratum>),
}

/// The visible normals of a Beckmann view `o = (so, 0, mu)` whose mirror reflection stays above
/// the horizon, in unit-roughness slopes `(x, y)` (the view's frame, as
/// [`BeckmannVisibleNormals::normal_from_slopes`]): a disc. With slopes `alpha (x, y)`, the
/// normal `m ∝ (-alpha x, -alpha y, 1)` reflects `o` to `i_z = 2 (o.m) m_z - mu`, which is
/// positive iff `(x - c)^2 + y^2 < r^2` with centre `c = -so / (mu alpha)` and radius
/// `r = 1 / (mu alpha)` (expand `2 (mu - alpha x so) > mu (1 + alpha^2 (x^2 + y^2))`). Outside
/// it the loss is 1 exactly, so the sum takes the share outside in closed form
/// ([`VisibleSlopeX::upper_share`]) and samples the inside only: x in `[c - r, c + r]` from a
/// logistic proxy of the visible x-slopes ([`LostCircle::x_slope`]), and for each x the folded
/// y-slope (the view's mirror symmetry) within `|y| < y*(x) = sqrt((right - x)(x - left))` from
/// a half-logistic proxy ([`LostCircle::y_slope`]), each weighted by the true density over the
/// proxy's, with the share beyond `y*` added as `erfc(y*)` (conditional Monte Carlo). The
/// integrand is then smooth inside; the x map goes through the smoothstep `3 v^2 - 2 v^3`,
/// whose zero derivative at both ends undoes the square roots of `y*` at the disc's ends.
#[derive(Clone, Copy, Debug)]
struct LostCircle {
    /// `c - r` and `c + r`.
    left: f64,
    right: f64,
    /// The x-slopes sampled: `[start, start + span]`, the disc's x range within
    /// [`SLOPE_REACH`] of 0.
    start: f64,
    span: f64,
    /// The visible slopes' share outside `[start, start + span]`, all counted as lost.
    lost: f64,
    /// The logistic proxy of the x-slopes' density: its centre, scale, and its CDF at `start`
    /// (`p_start`, and `1 - p_start` as `q_start`) and over the range (`p_span`).
    centre: f64,
    scale: f64,
    p_start: f64,
    q_start: f64,
    p_span: f64,
}

/// The logistic CDF `1 / (1 + exp(-z))`.
fn logistic(z: f64) -> f64 {
    1.0 / (1.0 + (-z).exp())
}

impl LostCircle {
    fn new(slopes: &VisibleSlopeX, alpha: f64, mu: f64) -> Self {
        let so = sin_from_cos(mu);
        // c - r, and c + r as (1 - so) / (mu alpha): no cancellation at near-normal views.
        let (left, right) = (-(so + 1.0) / (mu * alpha), (1.0 - so) / (mu * alpha));
        let start = left.max(-SLOPE_REACH);
        let end = right.min(SLOPE_REACH).max(start);
        // The mode of (b - x) exp(-x^2), the root of 2 x^2 - 2 b x - 1 in the stable form (0 at
        // normal incidence), and a scale near the Gaussian's (standard deviation 0.71 = 0.39 pi /
        // sqrt 3), a little wider for the tilt.
        let b = slopes.end();
        let centre = if b.is_finite() {
            -1.0 / (b + (b * b + 2.0).sqrt())
        } else {
            0.0
        };
        let scale = 0.45;
        let p_start = logistic((start - centre) / scale);
        let q_start = logistic((centre - start) / scale);
        let p_end = logistic((end - centre) / scale);
        Self {
            left,
            right,
            start,
            span: end - start,
            lost: slopes.upper_share(end) + (1.0 - slopes.upper_share(start)),
            centre,
            scale,
            p_start,
            q_start,
            p_span: (p_end - p_start).max(0.0),
        }
    }

    /// The x-slope for the variate `v` in [0, 1] and its density per unit of `v`, `dx/dv`:
    /// `x = centre + scale ln(p / (1 - p))` (the logistic proxy's inverse CDF, which puts the
    /// points where the visible slopes are) with `p` from `p_start` over `p_span` through the
    /// smoothstep `3 v^2 - 2 v^3` (whose zero derivative at both ends undoes the disc ends' square
    /// roots). `1 - p` is carried on its own, so the tails keep their digits.
    #[inline(always)]
    fn x_slope(&self, v: f64) -> (f64, f64) {
        let step = v * v * (3.0 - 2.0 * v);
        let p = self.p_start + self.p_span * step;
        let q = self.q_start - self.p_span * step;
        if !(p > 0.0 && q > 0.0) {
            return (self.start, 0.0);
        }
        let x = (self.centre + self.scale * (p / q).ln()).clamp(self.start, self.start + self.span);
        (x, self.scale / (p * q) * self.p_span * 6.0 * v * (1.0 - v))
    }

    /// The y-slope `|y|` in `[0, reach]` for the variate `v` in [0, 1] and `dy/dv`: the inverse
    /// CDF of the half-logistic proxy `tanh(y / 2 s)` (scale `s` as for x) restricted to the
    /// range, `y = 2 s atanh(v tanh(reach / 2 s))`, smooth up to `reach` and `reach v` when the
    /// reach is short.
    #[inline(always)]
    fn y_slope(&self, reach: f64, v: f64) -> (f64, f64) {
        let two_s = (2.0 * self.scale).max(reach);
        let top = (reach / two_s).tanh();
        let p = v * top;
        let y = (two_s * p.atanh()).min(reach);
        (y, two_s * top / ((1.0 - p) * (1.0 + p)))
    }
}

impl BeckmannView {
    fn new(alpha: f64, mu: f64) -> Self {
        let ndf = Beckmann { alpha };
        let o = Vec3::from_mu(mu);
        let untabulated = BeckmannVisibleNormals::new(ndf.alpha, o);
        // The stretched view's cot(theta): the visible x-slopes end there.
        let grazing = mu <= 0.0
            || (untabulated.slope_x().end() < GRAZING_COT && alpha < GRAZING_LADDER_MAX_ALPHA);
        let far_end = (1.0 + sin_from_cos(mu)) / (mu * alpha);
        let (visible, sampling) = if grazing {
            // The ladder solves for slopes at every point: start it from a table.
            let visible = BeckmannVisibleNormals::tabulated(ndf.alpha, o);
            let strata = beckmann_strata(&visible, alpha, mu);
            (visible, BeckmannSampling::Ladder(strata))
        } else if far_end < REFLECTION_MAX_FAR_END {
            (untabulated, BeckmannSampling::Reflection)
        } else {
            let circle = LostCircle::new(untabulated.slope_x(), alpha, mu);
            (untabulated, BeckmannSampling::Circle(circle))
        };
        Self {
            ndf,
            o,
            lambda_o: ndf.lambda(o),
            visible,
            sampling,
        }
    }

    /// A view whose sum runs by a ladder on both tails of the visible x-slopes
    /// ([`two_sided_ladder`]) whatever the view: for integrands whose rare events are not the
    /// reflection's alone (the dielectric's refraction and total internal reflection,
    /// [`crate::integrate::dielectric`]), which the [`LostCircle`] does not know.
    pub(crate) fn with_ladder(alpha: f64, mu: f64, floor: f64) -> Self {
        let ndf = Beckmann { alpha };
        let o = Vec3::from_mu(mu);
        Self {
            ndf,
            o,
            lambda_o: ndf.lambda(o),
            visible: BeckmannVisibleNormals::tabulated(ndf.alpha, o),
            sampling: BeckmannSampling::Ladder(two_sided_ladder(floor)),
        }
    }

    /// [`BeckmannView::sum`] inside the [`LostCircle`], the share outside in closed form.
    fn circle_sum(
        &self,
        circle: &LostCircle,
        seq: &OwenSobol,
        log2_n: u32,
        integrand: impl Fn(Vec3) -> f64,
    ) -> f64 {
        let slopes = self.visible.slope_x();
        let (left, right) = (circle.left, circle.right);
        let inside = sum_over_block(seq, log2_n, |[v0, v1]: [f64; 2]| {
            let (x, jacobian) = circle.x_slope(v0);
            let jacobian = jacobian * slopes.density(x);
            let reach = ((right - x).max(0.0) * (x - left).max(0.0))
                .sqrt()
                .min(SLOPE_REACH);
            // |y| on [0, reach] from the half-logistic proxy, weighted by its density
            // 2 exp(-y^2) / sqrt(pi) per unit of v1.
            let (y, dy) = circle.y_slope(reach, v1);
            let density = 2.0 * FRAC_1_SQRT_PI * (-y * y).exp();
            let m = self.visible.normal_from_slopes(x, y);
            jacobian * (erfc(reach) + dy * density * integrand(m))
        });
        circle.lost * (1u64 << log2_n) as f64 + inside
    }

    /// [`BeckmannView::sum`] over the reflected directions `i`, uniform over the half of the
    /// upper hemisphere with `i_y >= 0` (the view's mirror symmetry): `i_z = v0`, azimuth
    /// `pi v1`. The reflected directions of the visible normals have the density
    /// `p(i) = G1(o) D(h) / (4 mu)` with `h = (o + i) / |o + i|` (the visible normals' density
    /// `G1(o) max(0, o.h) D(h) / mu` (Heitz 2014, eq. 2) times the reflection's Jacobian
    /// `1 / (4 o.h)`, Walter et al. 2007, eq. 14), so `1 - E = 1 - ∫ p(i) (1 - loss(h)) di`
    /// over the upper hemisphere, the rest (reflections below the horizon) lost. Each point
    /// gives `1 - 2 pi p(i) (1 - integrand(h))`. No boundary lies inside the square: the
    /// integrand is smooth wherever `D` is broad over the hemisphere.
    fn reflection_sum(&self, seq: &OwenSobol, log2_n: u32, integrand: impl Fn(Vec3) -> f64) -> f64 {
        let o = self.o;
        let ndf = self.ndf;
        // 2 pi G1(o) / (4 mu): the weight of D(h) per uniform point.
        let scale = 2.0 * std::f64::consts::PI / (4.0 * o.z * (1.0 + self.lambda_o));
        sum_over_block(seq, log2_n, |[v0, v1]: [f64; 2]| {
            let (cos_phi, sin_phi) = cos_sin_pi(v1);
            let iz = v0;
            let ir = ((1.0 - iz) * (1.0 + iz)).max(0.0).sqrt();
            let h = Vec3::new(o.x + ir * cos_phi, o.y + ir * sin_phi, o.z + iz).normalize();
            1.0 - scale * ndf.d(h.z) * (1.0 - integrand(h))
        })
    }

    /// The loss `1 - w` of the visible normal `m` ([`reflection_loss`]).
    fn loss(&self, masking: Masking, m: Vec3) -> f64 {
        reflection_loss(self.ndf, masking, self.o, self.lambda_o, m)
    }

    /// The sum of `integrand(m)` over the visible normals of one scramble, returned as a sum over
    /// `2^log2_n` points as [`sum_over_block`] does; `integrand` must be 1 wherever the
    /// reflection leaves the hemisphere (a loss). By [`BeckmannSampling`].
    pub(crate) fn sum(&self, seq: &OwenSobol, log2_n: u32, integrand: impl Fn(Vec3) -> f64) -> f64 {
        match &self.sampling {
            BeckmannSampling::Circle(circle) => self.circle_sum(circle, seq, log2_n, integrand),
            BeckmannSampling::Reflection => self.reflection_sum(seq, log2_n, integrand),
            BeckmannSampling::Ladder(strata) => self.ladder_sum(strata, seq, log2_n, integrand),
        }
    }

    /// [`BeckmannView::sum`] by the ladder's strata: the first stratum (the body) gets half the
    /// points, the others share the other half ([`points_per_level`]), each level from its own
    /// stream of the scramble; with fewer than `2^MIN_LEVEL_LOG2` points per level, plain
    /// sampling. Each level draws the x-slope whose upper share is uniform within it
    /// ([`crate::model::ndf::VisibleSlopeX::sample_upper`]); the level means, weighted by their
    /// measure, add up to the integral.
    fn ladder_sum(
        &self,
        strata: &[Stratum],
        seq: &OwenSobol,
        log2_n: u32,
        integrand: impl Fn(Vec3) -> f64,
    ) -> f64 {
        let slopes = self.visible.slope_x();
        let at = |slope_x: f64, u1: f64| integrand(self.visible.normal_from_slope_x(slope_x, u1));
        let tail_levels = strata.len().saturating_sub(1);
        let body_log2 = log2_n.saturating_sub(1);
        if strata.len() == 1 || points_per_level(body_log2, tail_levels, 0) < MIN_LEVEL_LOG2 {
            return sum_over_block(seq, log2_n, |[u0, u1]: [f64; 2]| at(slopes.sample(u0), u1));
        }
        let mut mean = 0.0;
        for (k, stratum) in strata.iter().enumerate() {
            let (stream, log2) = if k == 0 {
                (*seq, body_log2)
            } else {
                (
                    seq.stream(k as u64),
                    points_per_level(body_log2, tail_levels, k - 1),
                )
            };
            let sum = sum_over_block(&stream, log2, |[v0, u1]: [f64; 2]| {
                // A share of exactly 0 or 1 (a level's end, or 1 - tiny rounded up) is an
                // infinite slope: the nearest shares that are not.
                let share = stratum
                    .t(v0)
                    .clamp(f64::MIN_POSITIVE, 1.0 - f64::EPSILON / 2.0);
                at(slopes.sample_upper(share), u1)
            });
            mean += stratum.weight * (sum / (1u64 << log2) as f64);
        }
        mean * (1u64 << log2_n) as f64
    }
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

/// `(cos(pi u), sin(pi u))` for `u` in [0, 1], by Taylor polynomials of `sin` and `cos` on
/// `[-pi/2, pi/2]` (through degree 21 and 22: truncation below 3e-16), using
/// `cos(pi u) = -sin(pi t)` and `sin(pi u) = cos(pi t)` with `t = u - 1/2`.
#[inline(always)]
#[must_use]
pub fn cos_sin_pi(u: f64) -> (f64, f64) {
    const SIN: [f64; 11] = [
        1.0,
        -0.166_666_666_666_666_66,
        0.008_333_333_333_333_333,
        -0.000_198_412_698_412_698_4,
        2.755_731_922_398_589_3e-6,
        -2.505_210_838_544_172e-8,
        1.605_904_383_682_161_3e-10,
        -7.647_163_731_819_816e-13,
        2.811_457_254_345_520_6e-15,
        -8.220_635_246_624_33e-18,
        1.957_294_106_339_126_3e-20,
    ];
    const COS: [f64; 12] = [
        1.0,
        -0.5,
        0.041_666_666_666_666_664,
        -0.001_388_888_888_888_889,
        2.480_158_730_158_73e-5,
        -2.755_731_922_398_589e-7,
        2.087_675_698_786_81e-9,
        -1.147_074_559_772_972_5e-11,
        4.779_477_332_387_385e-14,
        -1.561_920_696_858_622_5e-16,
        4.110_317_623_312_165e-19,
        -8.896_791_392_450_574e-22,
    ];
    let y = std::f64::consts::PI * (u - 0.5);
    let y2 = y * y;
    let mut s = SIN[10];
    for &c in SIN[..10].iter().rev() {
        s = s * y2 + c;
    }
    let mut c = COS[11];
    for &k in COS[..11].iter().rev() {
        c = c * y2 + k;
    }
    (-y * s, c)
}

#[cfg(test)]
mod tests {
    use super::*;

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
