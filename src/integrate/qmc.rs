//! The quasi-Monte Carlo machinery under kiln's estimators: how an estimate is run
//! ([`QmcSettings`]), its independent scrambles (`replicates`), the deterministic SIMD sum over
//! one scramble's points (`sum_over_block`) and its stratified forms ([`Stratum`],
//! `stratified_sum`). The estimators themselves are in [`mod@super::albedo`] and its
//! neighbours.

use super::estimate::Estimate;
use super::sobol::{OwenSobol, mix_seed};

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
    /// flag (`--scrambles`, `--samples`).
    pub fn validate(&self) -> crate::Result<()> {
        self.validate_as("--samples")
    }

    /// [`QmcSettings::validate`], the sample count named as `samples_flag` (`--avg-samples`).
    pub fn validate_as(&self, samples_flag: &str) -> crate::Result<()> {
        if self.scrambles < 2 || !self.scrambles.is_power_of_two() || self.scrambles > 1024 {
            return Err(crate::Error::InvalidInput(format!(
                "--scrambles must be a power of two from 2 to 1024 (got {})",
                self.scrambles
            )));
        }
        let (min, max) = self.sample_range();
        if !self.samples.is_power_of_two() || self.samples < min || self.samples > max {
            return Err(crate::Error::InvalidInput(format!(
                "{samples_flag} must be a power of two from {min} to 2^{} (one to 2^32 points for each \
                 of the {} scrambles; got {})",
                max.trailing_zeros(),
                self.scrambles,
                self.samples
            )));
        }
        Ok(())
    }

    /// `log2` of the points per scramble.
    pub(crate) fn log2_per_scramble(&self) -> u32 {
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
pub(crate) fn sum_over_block_portable<const D: usize>(
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

/// The share of the points below which a stratum is not worth its own: a ladder whose levels
/// would get fewer than `2^MIN_LEVEL_LOG2` points per scramble falls back to the coarse split
/// (at such counts no rare event is resolved anyway, and the levels' spread would only make the
/// standard error noisier).
pub(crate) const MIN_LEVEL_LOG2: u32 = 4;
/// `log2` of the points level `k` of `levels` gets when `2^log2_n` points are shared as equally
/// as powers of two allow: with `2^c` the next power of two from `levels`, each level gets
/// `2^(log2_n - c)` and the last `2^c - levels` levels twice that, so that the shares add up to
/// `2^log2_n` exactly (at least one point each when `2^log2_n < levels`).
pub(crate) fn points_per_level(log2_n: u32, levels: usize, k: usize) -> u32 {
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
