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

use super::estimate::Estimate;
use super::sobol::{OwenSobol, mix_seed};
use crate::model::ndf::BeckmannVisibleNormals;
use crate::model::{
    Beckmann, Ggx, Masking, MicrofacetDistribution, Model, Ndf, SMOOTH_ALPHA, Vec3,
    albedo_is_exactly_one, smooth_point,
};

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
    replicates(settings, &key, |seq, log2_n| {
        match (model.ndf, model.masking) {
            (Ndf::Ggx, Masking::HeightCorrelated) => {
                let view = GgxView::new(alpha, mu, sin_from_cos(mu));
                sum_over_block(
                    seq,
                    log2_n,
                    #[inline(always)]
                    |[u0, u1]| ggx_loss::<true>(&view, u0, u1),
                )
            }
            (Ndf::Ggx, Masking::Separable) => {
                let view = GgxView::new(alpha, mu, sin_from_cos(mu));
                sum_over_block(
                    seq,
                    log2_n,
                    #[inline(always)]
                    |[u0, u1]| ggx_loss::<false>(&view, u0, u1),
                )
            }
            (Ndf::Ggx, masking) => {
                // Schlick-GGX: the generic visible-normal sampler.
                let ndf = Ggx { alpha };
                let o = Vec3::from_mu(mu);
                let lambda_o = ndf.lambda(o);
                sum_over_block(
                    seq,
                    log2_n,
                    #[inline(always)]
                    |u| generic_loss(ndf, masking, o, lambda_o, u),
                )
            }
            (Ndf::Beckmann, masking) => {
                let ndf = Beckmann { alpha };
                let o = Vec3::from_mu(mu);
                let lambda_o = ndf.lambda(o);
                let visible = BeckmannVisibleNormals::tabulated(ndf, o);
                sum_over_block(
                    seq,
                    log2_n,
                    #[inline(always)]
                    |u| reflection_loss(ndf, masking, o, lambda_o, visible.sample(u)),
                )
            }
        }
    })
}

/// A weighted directional albedo `E_h(mu) = ∫ f(o, i) h(o.m) mu_i dω_i` with `F = 1` inside `f`
/// and the weight `h` of the cosine between the view and the microfacet normal `m` (the half
/// vector) in `[0, 1]`: a Fresnel reflectance `F(o.m)`, or Schlick's `Fc = (1 - o.m)^5` and
/// `1 - Fc` for the split-sum tables. The estimate is `1 - w h` averaged over visible normals
/// (`w = G2 / G1(o)`, 0 below the horizon), so `one_minus_value` is `1 - E_h` estimated directly.
/// Generic visible-normal sampling ([`MicrofacetDistribution::sample_visible_normal`]), not the
/// specialised GGX kernel.
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
    let (alpha, mu) = smooth_point(alpha, mu);
    let key = [
        TAG_WEIGHTED,
        model_key(model),
        alpha.to_bits(),
        mu.to_bits(),
    ];
    fn kernel<N: MicrofacetDistribution>(
        ndf: N,
        masking: Masking,
        mu: f64,
        h: impl Fn(f64) -> f64 + Copy,
        settings: &QmcSettings,
        key: &[u64],
    ) -> Estimate {
        let o = Vec3::from_mu(mu);
        let lambda_o = ndf.lambda(o);
        replicates(settings, key, |seq, log2_n| {
            sum_over_block(
                seq,
                log2_n,
                #[inline(always)]
                |u: [f64; 2]| {
                    let m = ndf.sample_visible_normal(o, u);
                    let w = 1.0 - reflection_loss(ndf, masking, o, lambda_o, m);
                    1.0 - w * h(o.dot(m).clamp(0.0, 1.0))
                },
            )
        })
    }
    match model.ndf {
        Ndf::Ggx => kernel(Ggx { alpha }, model.masking, mu, h, settings, &key),
        Ndf::Beckmann => kernel(Beckmann { alpha }, model.masking, mu, h, settings, &key),
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
            (Ndf::Ggx, Masking::HeightCorrelated) => sum_over_block(
                seq,
                log2_n,
                #[inline(always)]
                |[u0, u1, s]| ggx_loss::<true>(&GgxView::from_mu2(alpha, s), u0, u1),
            ),
            (Ndf::Ggx, Masking::Separable) => sum_over_block(
                seq,
                log2_n,
                #[inline(always)]
                |[u0, u1, s]| ggx_loss::<false>(&GgxView::from_mu2(alpha, s), u0, u1),
            ),
            (Ndf::Ggx, masking) => generic_average(Ggx { alpha }, masking, seq, log2_n),
            (Ndf::Beckmann, masking) => generic_average(Beckmann { alpha }, masking, seq, log2_n),
        }
    })
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

/// The loss `1 - w` for the microfacet normal `m`: reflect `o` about it; below the horizon all
/// is lost, above it [`Masking::loss`].
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
    /// `1 + Lambda(o)`.
    one_plus_lambda_o: f64,
}

impl GgxView {
    /// From `mu` and `so = sqrt(1 - mu^2)`.
    #[inline(always)]
    #[must_use]
    pub fn new(alpha: f64, mu: f64, so: f64) -> Self {
        let stretched = (alpha * alpha * so * so + mu * mu).sqrt();
        let lambda_o = Ggx { alpha }.lambda(Vec3::new(so, 0.0, mu));
        Self {
            alpha,
            alpha2: alpha * alpha,
            mu,
            so,
            vx: alpha * so / stretched,
            vz: mu / stretched,
            one_plus_lambda_o: 1.0 + lambda_o,
        }
    }

    /// From `s = mu^2` in (0, 1], as the `E_avg` integral draws it.
    #[inline(always)]
    #[must_use]
    pub fn from_mu2(alpha: f64, s: f64) -> Self {
        Self::new(alpha, s.sqrt(), (1.0 - s).sqrt())
    }
}

/// The loss `1 - w` of one GGX visible-normal sample, written out for speed and vectorisation.
///
/// The same computation as [`generic_loss`] with [`Ggx::sample_visible_normal`] (Dupuy & Benyoub
/// 2023), specialised to a view in the xz-plane and with the azimuth folded: the integrand is
/// symmetric under `y -> -y`, so `phi = pi u0` over `[0, pi]` replaces `2 pi u0`, and `sin(phi) >=
/// 0`. `cos` and `sin` of `pi u0` come from polynomials ([`cos_sin_pi`]), no library trigonometry.
/// `HEIGHT_CORRELATED` picks the masking form: `Li / (1 + Lo + Li)` or `Li / (1 + Li)`, with
/// `Li = x / (2 (1 + sqrt(1 + x)))` and `x = alpha^2 tan^2(theta_i)` (tan from components).
#[inline(always)]
#[must_use]
pub fn ggx_loss<const HEIGHT_CORRELATED: bool>(view: &GgxView, u0: f64, u1: f64) -> f64 {
    let (cos_phi, sin_phi) = cos_sin_pi(u0);
    // A uniform point of the spherical cap z in (-vz, 1].
    let z = (1.0 - u1) * (1.0 + view.vz) - view.vz;
    let s = ((1.0 - z) * (1.0 + z)).max(0.0).sqrt();
    // Half vector in the stretched space, then unstretched (unnormalised): m ∝ (mx, my, mz).
    let mx = view.alpha * (s * cos_phi + view.vx);
    let my = view.alpha * (s * sin_phi);
    let mz = z + view.vz;
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
                            Masking::HeightCorrelated => ggx_loss::<true>(&view, u0, u1),
                            Masking::Separable => ggx_loss::<false>(&view, u0, u1),
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
