//! The random numbers of one walk: the first vertices from an Owen-scrambled Sobol point, the
//! rest from a counter-seeded generator, so that every walk's numbers depend only on (seed,
//! scramble, walk index) and never on which thread runs it.

use crate::integrate::sobol::{DIMENSIONS, OwenSobol, mix_seed};

/// The numbers one walk draws, in order.
pub struct WalkRandom<'a> {
    sobol: Option<&'a OwenSobol>,
    index: u32,
    dim: usize,
    state: u64,
    key: u64,
}

impl<'a> WalkRandom<'a> {
    /// Walk `index` of the scramble `sobol` (whose seed also keys the generator's stream); with
    /// `None`, every number from the generator.
    #[must_use]
    pub fn new(sobol: Option<&'a OwenSobol>, stream_seed: u64, index: u32) -> Self {
        let key = mix_seed(&[stream_seed, u64::from(index)]);
        Self {
            sobol,
            index,
            dim: 0,
            state: key,
            key,
        }
    }

    /// A number uniform in (0, 1) for a purpose beside the walk (`tag` names it), from the
    /// walk's key: it neither reads nor advances the walk's own numbers.
    #[must_use]
    pub fn side_uniform(&self, tag: u64) -> f64 {
        let z = mix_seed(&[self.key, tag]);
        ((z >> 11) as f64 + 0.5) * (1.0 / 9_007_199_254_740_992.0)
    }

    /// The next number, uniform in (0, 1): the Sobol point's coordinates first (the first two
    /// vertices: a depth and a normal each), then SplitMix64 (Steele, Lea and Flood 2014).
    #[inline]
    pub fn uniform(&mut self) -> f64 {
        if let Some(sobol) = self.sobol
            && self.dim < DIMENSIONS
        {
            let u = sobol.sample(self.index, self.dim);
            self.dim += 1;
            return u;
        }
        self.state = self.state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
        // 53 bits, and half a step: (k + 1/2) 2^-53, never 0 or 1.
        ((z >> 11) as f64 + 0.5) * (1.0 / 9_007_199_254_740_992.0)
    }
}
