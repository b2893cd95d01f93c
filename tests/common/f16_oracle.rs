//! An f16 rounding written from IEEE 754's definition, not through the `half` crate (which
//! rounds through f32, twice): round to nearest, ties to even, directly from f64, with f16's 11
//! significant bits and its subnormal spacing `2^-24`, and kiln's clamps (docs/accuracy.md:
//! above 65504 to 65504, and what would round to zero to `2^-24`). The tests' oracle of what an
//! f16 file holds.

/// The largest finite f16.
pub const MAX: f64 = 65504.0;
/// The smallest positive subnormal f16, `2^-24`.
pub const MIN_SUBNORMAL: f64 = 5.960_464_477_539_063e-8;

/// `v` rounded to the nearest f16, ties to even, without clamps (0 below half the smallest
/// subnormal; above `MAX` the value rounded as if the exponent went on).
pub fn round_nearest_even(v: f64) -> f64 {
    if v == 0.0 || !v.is_finite() {
        return v;
    }
    let magnitude = v.abs();
    // The spacing of f16 values at this magnitude: 2^(e - 10) for 2^e <= |v| < 2^(e + 1),
    // 2^-24 below 2^-14.
    let mut exponent = magnitude.log2().floor();
    if 2f64.powf(exponent) > magnitude {
        exponent -= 1.0;
    } else if 2f64.powf(exponent + 1.0) <= magnitude {
        exponent += 1.0;
    }
    let spacing = 2f64.powf(exponent.max(-14.0) - 10.0);
    let q = magnitude / spacing; // exact: a power-of-two scaling
    let floor = q.floor();
    let rest = q - floor;
    let rounded = if rest > 0.5 || (rest == 0.5 && floor % 2.0 == 1.0) {
        floor + 1.0
    } else {
        floor
    };
    (rounded * spacing).copysign(v)
}

/// `v` as an f16 file holds it: rounded to nearest even, with kiln's clamps.
pub fn oracle(v: f64) -> f64 {
    if v == 0.0 || v.is_nan() {
        return v;
    }
    if v.abs() > MAX {
        return MAX.copysign(v);
    }
    let rounded = round_nearest_even(v);
    if rounded.abs() > MAX {
        MAX.copysign(v)
    } else if rounded == 0.0 {
        MIN_SUBNORMAL.copysign(v)
    } else {
        rounded
    }
}
