//! Owen-scrambled Sobol points with random access, after Burley 2020, "Practical Hash-based Owen
//! Scrambling" (JCGT 9(4)).
//!
//! - The Sobol sequence in base 2 with Joe & Kuo's direction numbers (`new-joe-kuo-6.21201`,
//!   S. Joe and F. Y. Kuo, "Constructing Sobol sequences with better two-dimensional projections",
//!   SIAM J. Sci. Comput. 30, 2008) for the first [`DIMENSIONS`] dimensions, 32-bit: a sequence holds
//!   `2^32` points.
//! - Nested uniform (Owen) scrambling of each coordinate by Burley's hash, in the improved form of
//!   N. Vegdahl's `sobol_burley` (a Laine-Karras style hash on the bit-reversed value, where each
//!   bit may depend only on the bits above it in the original value).
//! - The index is shuffled by the same scramble (Burley section 4), which for the first `2^m`
//!   indices picks a random aligned block of `2^m` Sobol points and permutes it. Since the sum over
//!   a point set does not depend on its order, [`OwenSobol::block`] enumerates exactly the same set
//!   of points in Gray-code order, one XOR per point and dimension.
//! - Output in f64: the 32 scrambled bits, then 20 further bits that a full Owen scramble would
//!   randomise too (they depend on the prefix through a hash), then a final 1: every value lies in
//!   `[2^-53, 1 - 2^-53]`, never 0 or 1.

/// The number of dimensions with direction numbers.
pub const DIMENSIONS: usize = 6;

/// Joe-Kuo parameters `(s, a, m_1..m_s)` for dimensions 2.. (dimension 1 is van der Corput).
const JOE_KUO: [(u32, u32, [u32; 4]); DIMENSIONS - 1] = [
    (1, 0, [1, 0, 0, 0]),
    (2, 1, [1, 3, 0, 0]),
    (3, 1, [1, 3, 1, 0]),
    (3, 2, [1, 1, 1, 0]),
    (4, 1, [1, 1, 3, 3]),
];

/// `DIRECTIONS[d][k]` is the direction number XORed in when bit `k` of the index is set.
pub const DIRECTIONS: [[u32; 32]; DIMENSIONS] = directions();

/// [`DIRECTIONS`] with each number's bits reversed: XORing these yields the bit-reversed Sobol
/// coordinate, which is the form Burley's hash scrambles, saving one reversal per coordinate.
pub const DIRECTIONS_REVERSED: [[u32; 32]; DIMENSIONS] = reversed(directions());

const fn reversed(mut table: [[u32; 32]; DIMENSIONS]) -> [[u32; 32]; DIMENSIONS] {
    let mut d = 0;
    while d < DIMENSIONS {
        let mut k = 0;
        while k < 32 {
            table[d][k] = table[d][k].reverse_bits();
            k += 1;
        }
        d += 1;
    }
    table
}

const fn directions() -> [[u32; 32]; DIMENSIONS] {
    let mut out = [[0u32; 32]; DIMENSIONS];
    let mut k = 0;
    while k < 32 {
        out[0][k] = 1 << (31 - k);
        k += 1;
    }
    let mut d = 1;
    while d < DIMENSIONS {
        let (s, a, init) = JOE_KUO[d - 1];
        let s = s as usize;
        // m[k] for k = 1..=32 (index 0 unused).
        let mut m = [0u32; 33];
        let mut k = 1;
        while k <= 32 {
            if k <= s {
                m[k] = init[k - 1];
            } else {
                let mut v = m[k - s] ^ (m[k - s] << s);
                let mut j = 1;
                while j < s {
                    if (a >> (s - 1 - j)) & 1 == 1 {
                        v ^= m[k - j] << j;
                    }
                    j += 1;
                }
                m[k] = v;
            }
            out[d][k - 1] = m[k] << (32 - k);
            k += 1;
        }
        d += 1;
    }
    out
}

/// The unscrambled Sobol coordinate of point `index` in dimension `dim`, as a 32-bit fraction.
#[must_use]
pub fn sobol(index: u32, dim: usize) -> u32 {
    let mut x = 0;
    let mut bits = index;
    let mut k = 0;
    while bits != 0 {
        if bits & 1 == 1 {
            x ^= DIRECTIONS[dim][k];
        }
        bits >>= 1;
        k += 1;
    }
    x
}

/// Burley's hash-based nested uniform scramble of a 32-bit fraction (most significant bit first):
/// bit `k` is flipped by a pseudo-random function of the bits above it and of `seed`.
#[inline]
#[must_use]
pub fn nested_uniform_scramble(x: u32, seed: u32) -> u32 {
    scramble_reversed(x.reverse_bits(), seed)
}

/// [`nested_uniform_scramble`] of the fraction whose bit-reversal is `reversed`: the Laine-Karras
/// style hash, in which each bit depends only on the bits below it, then the reversal back.
#[inline(always)]
#[must_use]
pub fn scramble_reversed(reversed: u32, seed: u32) -> u32 {
    let mut v = reversed;
    v ^= v.wrapping_mul(0x3d20_adea);
    v = v.wrapping_add(seed);
    v = v.wrapping_mul((seed >> 16) | 1);
    v ^= v.wrapping_mul(0x0552_6c56);
    v ^= v.wrapping_mul(0x53a2_2864);
    v.reverse_bits()
}

/// A 32-bit integer hash with good avalanche (C. Wellons' `lowbias32`).
#[inline]
#[must_use]
pub fn hash32(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^= x >> 16;
    x
}

/// Mixes a list of words into one 64-bit seed (SplitMix64's finaliser, chained).
#[must_use]
pub fn mix_seed(parts: &[u64]) -> u64 {
    let mut h: u64 = 0x9e37_79b9_7f4a_7c15;
    for &p in parts {
        h = h.wrapping_add(p).wrapping_add(0x9e37_79b9_7f4a_7c15);
        h = (h ^ (h >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        h = (h ^ (h >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        h ^= h >> 31;
    }
    h
}

/// Turns a scrambled 32-bit coordinate into an f64 in `[2^-53, 1 - 2^-53]`: 32 scrambled bits, 20
/// hashed deeper bits (keyed by `deep_seed`), and a final 1 bit.
#[inline]
#[must_use]
pub fn to_unit_f64(scrambled: u32, deep_seed: u32) -> f64 {
    let deep = hash32(scrambled ^ deep_seed) >> 12;
    // The 52 fraction bits `f` as the mantissa of `1 + f 2^-52`, minus 1 (exact), plus the final
    // half-ulp bit: `(2 f + 1) 2^-53` exactly, without a u64 -> f64 conversion (which AVX2 lacks
    // and the vectorised kernels would emulate).
    let fraction = (scrambled as u64) << 20 | deep as u64;
    (f64::from_bits(0x3ff0_0000_0000_0000 | fraction) - 1.0) + 1.0 / 9_007_199_254_740_992.0
}

/// One Owen-scrambled Sobol sequence: a seed fixing the index shuffle and each dimension's scramble.
#[derive(Clone, Copy, Debug)]
pub struct OwenSobol {
    seed: u64,
    shuffle_seed: u32,
    dim_seeds: [u32; DIMENSIONS],
    deep_seeds: [u32; DIMENSIONS],
}

impl OwenSobol {
    /// The sequence for a 64-bit seed; different seeds give independent scrambles.
    #[must_use]
    pub fn new(seed: u64) -> Self {
        let word = |tag: u64, dim: usize| mix_seed(&[seed, tag, dim as u64]) as u32;
        Self {
            seed,
            shuffle_seed: word(0, 0),
            dim_seeds: std::array::from_fn(|d| word(1, d)),
            deep_seeds: std::array::from_fn(|d| word(2, d)),
        }
    }

    /// An independent sequence derived from this one's seed: stream `k` of the same scramble
    /// (for a second stratum sampled beside the first).
    #[must_use]
    pub fn stream(&self, k: u64) -> Self {
        Self::new(mix_seed(&[self.seed, 0x5354_5245_414d, k]))
    }

    /// The scrambled 32-bit coordinate of point `index` in dimension `dim` (random access).
    #[must_use]
    pub fn sample_u32(&self, index: u32, dim: usize) -> u32 {
        let shuffled = nested_uniform_scramble(index, self.shuffle_seed);
        self.scramble(sobol(shuffled, dim), dim)
    }

    /// Point `index`'s coordinate in dimension `dim` as an f64 in (0, 1) (random access).
    #[must_use]
    pub fn sample(&self, index: u32, dim: usize) -> f64 {
        self.to_unit(self.sample_u32(index, dim), dim)
    }

    /// Scrambles an unscrambled Sobol coordinate of dimension `dim`.
    #[inline]
    #[must_use]
    pub fn scramble(&self, raw: u32, dim: usize) -> u32 {
        nested_uniform_scramble(raw, self.dim_seeds[dim])
    }

    /// Scrambles a bit-reversed Sobol coordinate (as [`SobolBlock::fill_reversed`] yields).
    #[inline(always)]
    #[must_use]
    pub fn scramble_reversed(&self, reversed: u32, dim: usize) -> u32 {
        scramble_reversed(reversed, self.dim_seeds[dim])
    }

    /// Turns a scrambled coordinate of dimension `dim` into an f64 (see [`to_unit_f64`]).
    #[inline]
    #[must_use]
    pub fn to_unit(&self, scrambled: u32, dim: usize) -> f64 {
        to_unit_f64(scrambled, self.deep_seeds[dim])
    }

    /// The first `2^log2_n` points of this sequence (the same set as `sample_u32(0..2^log2_n, _)`),
    /// enumerated in Gray-code order, unscrambled: apply [`OwenSobol::scramble`] to each value.
    #[must_use]
    pub fn block<const D: usize>(&self, log2_n: u32) -> SobolBlock<D> {
        assert!(log2_n <= 32 && D <= DIMENSIONS);
        let low_mask = if log2_n == 32 {
            u32::MAX
        } else {
            (1u32 << log2_n) - 1
        };
        let base = nested_uniform_scramble(0, self.shuffle_seed) & !low_mask;
        SobolBlock {
            current: std::array::from_fn(|d| sobol(base, d)),
            current_reversed: std::array::from_fn(|d| sobol(base, d).reverse_bits()),
            next: 0,
            count: 1u64 << log2_n,
        }
    }
}

/// Enumerates an aligned block of Sobol points in Gray-code order (see [`OwenSobol::block`]).
#[derive(Clone, Debug)]
pub struct SobolBlock<const D: usize> {
    current: [u32; D],
    current_reversed: [u32; D],
    next: u64,
    count: u64,
}

impl<const D: usize> SobolBlock<D> {
    /// How many points remain.
    #[must_use]
    pub fn remaining(&self) -> u64 {
        self.count - self.next
    }

    /// Moves to the next point (Gray-code order: one direction number XORed in per dimension),
    /// updating the plain or the bit-reversed coordinates: a block is read one way or the other.
    #[inline(always)]
    fn advance<const REVERSED: bool>(&mut self) {
        if self.next != 0 {
            let bit = self.next.trailing_zeros() as usize;
            for d in 0..D {
                if REVERSED {
                    self.current_reversed[d] ^= DIRECTIONS_REVERSED[d][bit];
                } else {
                    self.current[d] ^= DIRECTIONS[d][bit];
                }
            }
        }
        self.next += 1;
    }

    /// Writes the next `out[0].len()` points' raw coordinates, dimension by dimension.
    /// Panics if fewer points remain or the slices differ in length.
    pub fn fill(&mut self, out: &mut [&mut [u32]; D]) {
        self.fill_planes::<false>(out);
    }

    /// As [`SobolBlock::fill`], but writes each coordinate bit-reversed (for
    /// [`OwenSobol::scramble_reversed`]). Read a block with `fill_reversed` only, or with `fill`
    /// and the iterator only.
    pub fn fill_reversed(&mut self, out: &mut [&mut [u32]; D]) {
        self.fill_planes::<true>(out);
    }

    #[inline(always)]
    fn fill_planes<const REVERSED: bool>(&mut self, out: &mut [&mut [u32]; D]) {
        let n = out[0].len();
        assert!(n as u64 <= self.remaining());
        for k in 0..n {
            self.advance::<REVERSED>();
            let point = if REVERSED {
                &self.current_reversed
            } else {
                &self.current
            };
            for (plane, &coordinate) in out.iter_mut().zip(point) {
                plane[k] = coordinate;
            }
        }
    }
}

impl<const D: usize> Iterator for SobolBlock<D> {
    type Item = [u32; D];

    fn next(&mut self) -> Option<[u32; D]> {
        if self.next == self.count {
            return None;
        }
        self.advance::<false>();
        Some(self.current)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The mantissa construction gives exactly `(2 f + 1) 2^-53`, the value of the plain
    /// conversion, bit for bit, ends included.
    #[test]
    fn unit_conversion_is_exact() {
        let mut x = 0x1234_5678u32;
        let mut cases = vec![(0, 0), (u32::MAX, u32::MAX), (u32::MAX, 0), (0, u32::MAX)];
        for _ in 0..100_000 {
            x = hash32(x);
            cases.push((x, hash32(x ^ 0x9e37)));
        }
        for (scrambled, deep_seed) in cases {
            let deep = hash32(scrambled ^ deep_seed) >> 12;
            let bits = ((u64::from(scrambled) << 20 | u64::from(deep)) << 1) | 1;
            let plain = bits as f64 * (1.0 / 9_007_199_254_740_992.0);
            let got = to_unit_f64(scrambled, deep_seed);
            assert_eq!(
                got.to_bits(),
                plain.to_bits(),
                "{scrambled:#x} {deep_seed:#x}"
            );
            assert!(got > 0.0 && got < 1.0);
        }
    }

    /// The first eight points as published (Joe & Kuo's generator and SciPy's `qmc.Sobol`, which
    /// list points in Gray-code order: point `n` is `sobol(n ^ (n >> 1))`).
    #[test]
    fn first_points_match_the_published_sequence() {
        let published: [[f64; 8]; DIMENSIONS] = [
            [0.0, 0.5, 0.75, 0.25, 0.375, 0.875, 0.625, 0.125],
            [0.0, 0.5, 0.25, 0.75, 0.375, 0.875, 0.125, 0.625],
            [0.0, 0.5, 0.25, 0.75, 0.625, 0.125, 0.875, 0.375],
            [0.0, 0.5, 0.25, 0.75, 0.875, 0.375, 0.625, 0.125],
            [0.0, 0.5, 0.75, 0.25, 0.375, 0.875, 0.625, 0.125],
            [0.0, 0.5, 0.75, 0.25, 0.125, 0.625, 0.875, 0.375],
        ];
        for (dim, expected) in published.iter().enumerate() {
            let got: Vec<f64> = (0..8u32)
                .map(|n| sobol(n ^ (n >> 1), dim) as f64 / 4_294_967_296.0)
                .collect();
            assert_eq!(got, expected, "dimension {dim}");
        }
    }

    /// Counts, for the first `2^m` points of dimensions (a, b), how many land in each elementary
    /// interval of shape `2^-j x 2^-(m - t - j)`; a (t, m, 2)-net has exactly `2^t` in each.
    fn is_net(points: &[(u32, u32)], m: u32, t: u32) -> bool {
        (0..=m - t).all(|j| {
            let k = m - t - j;
            let mut counts = vec![0u32; 1 << (m - t)];
            for &(x, y) in points {
                let cx = if j == 0 { 0 } else { x >> (32 - j) };
                let cy = if k == 0 { 0 } else { y >> (32 - k) };
                counts[((cx << k) | cy) as usize] += 1;
            }
            counts.iter().all(|&c| c == 1 << t)
        })
    }

    #[test]
    fn scrambled_points_keep_the_net_property() {
        let seq = OwenSobol::new(42);
        for m in 1..=10 {
            let pts: Vec<(u32, u32)> = (0..1u32 << m)
                .map(|i| (seq.sample_u32(i, 0), seq.sample_u32(i, 1)))
                .collect();
            assert!(is_net(&pts, m, 0), "dims 0,1 are not a (0,{m},2)-net");
            // Every dimension alone is stratified: one point per interval of length 2^-m.
            for d in 0..DIMENSIONS {
                let mut cells: Vec<u32> = (0..1u32 << m)
                    .map(|i| seq.sample_u32(i, d) >> (32 - m))
                    .collect();
                cells.sort_unstable();
                assert!(
                    cells.iter().enumerate().all(|(k, &c)| c == k as u32),
                    "dim {d}, m {m}"
                );
            }
        }
    }

    #[test]
    fn block_enumerates_the_same_set_as_random_access() {
        let seq = OwenSobol::new(7);
        for m in [0, 1, 5, 12] {
            let mut random: Vec<[u32; 3]> = (0..1u32 << m)
                .map(|i| std::array::from_fn(|d| seq.sample_u32(i, d)))
                .collect();
            let mut block: Vec<[u32; 3]> = seq
                .block::<3>(m)
                .map(|raw| std::array::from_fn(|d| seq.scramble(raw[d], d)))
                .collect();
            random.sort_unstable();
            block.sort_unstable();
            assert_eq!(random, block, "m = {m}");
            // And `fill` agrees with the iterator.
            let mut bufs = [vec![0u32; 1 << m], vec![0u32; 1 << m], vec![0u32; 1 << m]];
            let [b0, b1, b2] = &mut bufs;
            seq.block::<3>(m).fill(&mut [b0, b1, b2]);
            let mut filled: Vec<[u32; 3]> = (0..1usize << m)
                .map(|k| std::array::from_fn(|d| seq.scramble(bufs[d][k], d)))
                .collect();
            filled.sort_unstable();
            assert_eq!(filled, block);
            // And so does the bit-reversed form.
            {
                let [b0, b1, b2] = &mut bufs;
                seq.block::<3>(m).fill_reversed(&mut [b0, b1, b2]);
            }
            let mut reversed: Vec<[u32; 3]> = (0..1usize << m)
                .map(|k| std::array::from_fn(|d| seq.scramble_reversed(bufs[d][k], d)))
                .collect();
            reversed.sort_unstable();
            assert_eq!(reversed, block);
        }
    }

    #[test]
    fn different_seeds_scramble_independently() {
        let (a, b) = (OwenSobol::new(1), OwenSobol::new(2));
        let same = (0..1000)
            .filter(|&i| a.sample_u32(i, 0) == b.sample_u32(i, 0))
            .count();
        assert!(same < 3);
        // Every scrambled coordinate is uniform: the mean of 2^16 points is 1/2 to O(2^-16).
        let mean: f64 = (0..1u32 << 16).map(|i| a.sample(i, 3)).sum::<f64>() / 65536.0;
        assert!((mean - 0.5).abs() < 1e-4, "{mean}");
    }

    #[test]
    fn unit_values_stay_strictly_inside_the_interval() {
        for (x, s) in [(0, 0), (u32::MAX, 0), (u32::MAX, u32::MAX), (0, u32::MAX)] {
            let v = to_unit_f64(x, s);
            assert!(v > 0.0 && v < 1.0, "{x} {s}: {v}");
        }
    }
}
