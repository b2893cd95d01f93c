//! Half-float storage without silent loss: values beyond f16's range are clamped, never turned
//! into infinity or zero, and the metadata counts them.
//!
//! f16 has 11 significant bits: a rounding error of at most `2^-11` (4.9e-4) relative for
//! normal values, down to `2^-14` (6.1e-5). Below that, subnormals keep a fixed spacing of `2^-24` (6.0e-8), so their
//! relative precision falls; below half that spacing a value would round to zero. `1 - E` is
//! stored beside `E` for this reason (`docs/physics.md`, "Hard cases"): `E(1, alpha = 0.01)` rounds
//! to exactly 1 as an f16, while `1 - E` keeps 0.05 % relative precision down to 6.1e-5.

use half::f16;
use serde::{Deserialize, Serialize};

/// The largest finite f16, 65504.
pub const MAX: f64 = 65504.0;
/// The smallest positive normal f16, `2^-14`.
pub const MIN_NORMAL: f64 = 6.103_515_625e-5;
/// The smallest positive subnormal f16, `2^-24`.
pub const MIN_SUBNORMAL: f64 = 5.960_464_477_539_063e-8;

/// What storing one value as f16 did.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// Stored to f16's full relative precision (or exactly zero).
    Exact,
    /// Stored as a subnormal: absolute spacing 6e-8, reduced relative precision.
    Subnormal,
    /// Beyond f16's range (above 65504 in magnitude, or so small that it would round to zero):
    /// clamped to the largest finite or the smallest subnormal value of the same sign.
    Clamped,
}

/// `v` as an f16, clamped into f16's finite non-zero range if it would overflow or underflow.
/// Rounded once, directly from f64, to nearest with ties to even (IEEE 754, so the same on
/// every CPU): rounding through f32 first rounded twice, and a value within f32's half step of
/// an f16 tie landed on the tie and went to the even side, one f16 step from the nearest
/// (1.4477539513 stored as 1.447265625, not 1.4482421875; tests/f16_rounding.rs). NaN stays
/// NaN.
#[must_use]
pub fn encode(v: f64) -> (f16, Outcome) {
    let magnitude = v.abs();
    if v == 0.0 || v.is_nan() {
        return (f16::from_f32(v as f32), Outcome::Exact);
    }
    if magnitude > MAX {
        return (f16::from_f64(MAX.copysign(v)), Outcome::Clamped);
    }
    let h = nearest(v);
    if h.to_f32() == 0.0 {
        return (f16::from_f64(MIN_SUBNORMAL.copysign(v)), Outcome::Clamped);
    }
    let outcome = if f64::from(h.to_f32()).abs() < MIN_NORMAL {
        Outcome::Subnormal
    } else {
        Outcome::Exact
    };
    (h, outcome)
}

/// The f16 nearest to `v` (finite, at most [`MAX`] in magnitude), ties to even: `half`'s
/// conversions go through f32 (and F16C's through f32 in hardware), which rounds twice; the
/// result is within one f16 step of the nearest, so the nearest of it and its two neighbours
/// (distances exact in f64, the values being close) is the correctly rounded one.
fn nearest(v: f64) -> f16 {
    let first = f16::from_f32(v as f32);
    let bits = first.to_bits();
    let mut best = (first, (first.to_f64() - v).abs());
    for neighbour in [bits.wrapping_sub(1), bits.wrapping_add(1)] {
        let candidate = f16::from_bits(neighbour);
        // Stay finite and on the same side of zero (0x0000 - 1 and 0x8000 - 1 are NaNs).
        if !candidate.is_finite()
            || (candidate.is_sign_negative() != first.is_sign_negative()
                && candidate.to_f64() != 0.0)
        {
            continue;
        }
        let distance = (candidate.to_f64() - v).abs();
        if distance < best.1 || (distance == best.1 && neighbour & 1 == 0) {
            best = (candidate, distance);
        }
    }
    best.0
}

/// The value a reader of the f16 file gets back for `v` ([`encode`], widened).
#[must_use]
pub fn stored(v: f64) -> f64 {
    f64::from(encode(v).0.to_f32())
}

/// How many values of a channel [`encode`] clamped or stored as subnormals.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Counts {
    /// Values beyond f16's range, clamped (never stored as infinity or zero).
    pub clamped: usize,
    /// Values stored as subnormals (below 6.1e-5), with absolute spacing 6e-8.
    pub subnormal: usize,
}

/// [`Counts`] for storing `values` as f16.
#[must_use]
pub fn counts(values: &[f64]) -> Counts {
    let mut counts = Counts::default();
    for &v in values {
        match encode(v).1 {
            Outcome::Exact => {}
            Outcome::Subnormal => counts.subnormal += 1,
            Outcome::Clamped => counts.clamped += 1,
        }
    }
    counts
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overflow_and_underflow_are_clamped_not_infinite_or_zero() {
        assert_eq!(encode(1e6), (f16::MAX, Outcome::Clamped));
        assert_eq!(encode(-1e6), (f16::MIN, Outcome::Clamped));
        let (tiny, outcome) = encode(1e-9);
        assert_eq!(outcome, Outcome::Clamped);
        assert_eq!(f64::from(tiny.to_f32()), MIN_SUBNORMAL);
        assert_eq!(encode(0.0), (f16::ZERO, Outcome::Exact));
        assert_eq!(encode(1e-6).1, Outcome::Subnormal);
        assert_eq!(encode(0.5), (f16::from_f32(0.5), Outcome::Exact));
        assert!(encode(f64::NAN).0.is_nan());
        assert_eq!(
            counts(&[1e-9, 1e-6, 0.5, 0.0, 7e4]),
            Counts {
                clamped: 2,
                subnormal: 1
            }
        );
    }

    /// The edges of each outcome, from the half crate's constants: f16's largest value is
    /// stored as itself, not clamped; its smallest normal is normal; its smallest subnormal is a
    /// subnormal; a value that rounds to zero is clamped with its sign.
    #[test]
    fn outcomes_at_the_edges_of_the_range() {
        assert_eq!(encode(f64::from(f16::MAX)), (f16::MAX, Outcome::Exact));
        assert_eq!(encode(-f64::from(f16::MAX)), (f16::MIN, Outcome::Exact));
        let normal = f64::from(f16::MIN_POSITIVE);
        assert_eq!(normal, MIN_NORMAL);
        assert_eq!(encode(normal), (f16::MIN_POSITIVE, Outcome::Exact));
        let subnormal = f64::from(f16::MIN_POSITIVE_SUBNORMAL);
        assert_eq!(subnormal, MIN_SUBNORMAL);
        assert_eq!(
            encode(subnormal),
            (f16::MIN_POSITIVE_SUBNORMAL, Outcome::Subnormal)
        );
        assert_eq!(encode(0.99 * normal).1, Outcome::Subnormal);
        let (negative, outcome) = encode(-1e-9);
        assert_eq!(outcome, Outcome::Clamped);
        assert_eq!(f64::from(negative.to_f32()), -MIN_SUBNORMAL);
        assert_eq!(
            counts(&[7e4, -7e4, 1e-9, 1e-6, 3e-7, 0.5]),
            Counts {
                clamped: 3,
                subnormal: 2
            }
        );
    }

    #[test]
    fn normal_range_keeps_relative_precision() {
        // 0.1 % relative accuracy down to 1e-4 (kiln's promise for one_minus_E): rounding to
        // 11 significant bits errs by at most 2^-11 relative throughout f16's normal range.
        let mut v = 1e-4;
        while v < 1.0 {
            let back = stored(v);
            assert!(((back - v) / v).abs() <= 2f64.powi(-11), "{v}");
            v *= 1.013;
        }
    }
}
