//! `exp` and `sin`/`cos` written so that a loop over lanes of them vectorises: no calls, no
//! branches (the range reduction by arithmetic and bit operations, the polynomial by Horner's
//! rule), within a few ulp of the library's functions over the ranges stated. The integrands
//! that run a quadrature rule's nodes in SIMD lanes ([`crate::integrate::reference`],
//! [`crate::integrate::dielectric`], [`crate::integrate::dielectric_average`]) call these where a
//! library call per lane would not vectorise.
//!
//! Method (Cody and Waite, "Software Manual for the Elementary Functions", Prentice-Hall 1980;
//! Muller, "Elementary Functions: Algorithms and Implementation", 3rd ed., Birkhäuser 2016,
//! chapter 11): subtract the nearest multiple `k` of `ln 2` (of `pi / 2`), the constant split in
//! two or three parts whose leading parts have enough trailing zero bits that their products
//! with `k` are exact; evaluate the Taylor polynomial of the reduced argument, of a degree whose
//! truncation error is below half an ulp on the reduced range; scale by `2^k` through the
//! exponent bits (pick `sin` or `cos` and the sign by `k mod 4`). The nearest integer comes from
//! adding and subtracting `1.5 * 2^52`, which rounds to an integer in f64 arithmetic (Muller,
//! section 11.1), and leaves `k` in the low mantissa bits for the exponent.

/// `1.5 * 2^52`: adding it to `|y| < 2^51` and subtracting it again rounds `y` to the nearest
/// integer, and the sum holds that integer in its low mantissa bits.
const ROUNDER: f64 = 6_755_399_441_055_744.0;

/// `ln 2` in two parts (bit patterns, so that no decimal rounding enters): the leading part
/// has its last 11 mantissa bits zero, so `k ln2_hi` is exact for `|k| < 2^11` (fdlibm's
/// `e_exp.c` split).
const LN2_HI: f64 = f64::from_bits(0x3fe6_2e42_fee0_0000);
const LN2_LO: f64 = f64::from_bits(0x3dea_39ef_3579_3c76);

/// The range [`exp_lane`] serves: above it `2^k` would overflow the exponent field.
pub const EXP_MAX: f64 = 709.0;
/// Below it the result would be subnormal: [`exp_lane`] returns 0 there.
pub const EXP_MIN: f64 = -708.0;

/// `e^x` for `x` in `[EXP_MIN, EXP_MAX]`, within 2 ulp of the library's `exp` (tested on a
/// million points); 0 below `EXP_MIN` (where the true value is below `3.3e-308`), `e^709` above
/// `EXP_MAX`, 0 for NaN (callers pass finite arguments; the lanes they drop may hold anything).
/// Branch-free: a loop of it over an array vectorises.
#[inline(always)]
#[must_use]
pub fn exp_lane(x: f64) -> f64 {
    let clamped = x.clamp(EXP_MIN, EXP_MAX);
    let shifted = clamped * std::f64::consts::LOG2_E + ROUNDER;
    let k = shifted - ROUNDER;
    let r = (clamped - k * LN2_HI) - k * LN2_LO;
    // `|r| <= ln 2 / 2`: Taylor to degree 13, truncation below `0.35^14 / 14! = 4e-18`.
    let mut p = 1.0 / 6_227_020_800.0;
    p = p * r + 1.0 / 479_001_600.0;
    p = p * r + 1.0 / 39_916_800.0;
    p = p * r + 1.0 / 3_628_800.0;
    p = p * r + 1.0 / 362_880.0;
    p = p * r + 1.0 / 40_320.0;
    p = p * r + 1.0 / 5_040.0;
    p = p * r + 1.0 / 720.0;
    p = p * r + 1.0 / 120.0;
    p = p * r + 1.0 / 24.0;
    p = p * r + 1.0 / 6.0;
    p = p * r + 0.5;
    p = p * r + 1.0;
    p = p * r + 1.0;
    // `2^k` from the low bits of `shifted`, where the rounding left `k` (module docs).
    let scale = f64::from_bits(shifted.to_bits().wrapping_add(1023) << 52);
    let value = p * scale;
    if x >= EXP_MIN { value } else { 0.0 }
}

/// `pi / 2` in three parts (bit patterns), the first two of 33 significant bits each, so that
/// their products with `k` are exact for `|k| < 2^20`, the third the rest (fdlibm's
/// `e_rem_pio2.c`: `pio2_1`, `pio2_2`, `pio2_2t`).
const PIO2_1: f64 = f64::from_bits(0x3ff9_21fb_5440_0000);
const PIO2_2: f64 = f64::from_bits(0x3dd0_b461_1a60_0000);
const PIO2_3: f64 = f64::from_bits(0x3ba3_198a_2e03_7073);

/// The range [`sin_cos_lane`] serves: `|x| <= SIN_COS_MAX`.
pub const SIN_COS_MAX: f64 = 1024.0;

/// `(sin x, cos x)` for `|x| <= SIN_COS_MAX`, each within 2 ulp of the library's (or within
/// `2e-16` absolute where it is near a zero; tested on a million points). Branch-free: a loop
/// of it over an array vectorises. Outside the range the result is meaningless (callers pass
/// azimuths and polar angles).
#[inline(always)]
#[must_use]
pub fn sin_cos_lane(x: f64) -> (f64, f64) {
    let shifted = x * std::f64::consts::FRAC_2_PI + ROUNDER;
    let k = shifted - ROUNDER;
    let r = ((x - k * PIO2_1) - k * PIO2_2) - k * PIO2_3;
    let r2 = r * r;
    // `|r| <= pi / 4`: `sin` to degree 17 and `cos` to degree 18, truncation below
    // `(pi / 4)^19 / 19! = 8e-20` and `(pi / 4)^20 / 20! = 3e-21`.
    let mut s = -1.0 / 355_687_428_096_000.0;
    s = s * r2 + 1.0 / 1_307_674_368_000.0;
    s = s * r2 - 1.0 / 6_227_020_800.0;
    s = s * r2 + 1.0 / 39_916_800.0;
    s = s * r2 - 1.0 / 362_880.0;
    s = s * r2 + 1.0 / 5_040.0;
    s = s * r2 - 1.0 / 120.0;
    s = s * r2 + 1.0 / 6.0;
    let sin_r = r - r * r2 * s;
    let mut c = -1.0 / 6_402_373_705_728_000.0;
    c = c * r2 + 1.0 / 20_922_789_888_000.0;
    c = c * r2 - 1.0 / 87_178_291_200.0;
    c = c * r2 + 1.0 / 479_001_600.0;
    c = c * r2 - 1.0 / 3_628_800.0;
    c = c * r2 + 1.0 / 40_320.0;
    c = c * r2 - 1.0 / 720.0;
    c = c * r2 + 1.0 / 24.0;
    let cos_r = 1.0 - 0.5 * r2 + r2 * r2 * c;
    // `x = k pi / 2 + r`: quadrant `k mod 4` picks and signs (two's complement low bits).
    let quadrant = shifted.to_bits() & 3;
    let swap = quadrant & 1 == 1;
    let (sin_q, cos_q) = if swap { (cos_r, sin_r) } else { (sin_r, cos_r) };
    let sin_sign = if quadrant & 2 == 2 { -1.0 } else { 1.0 };
    let cos_sign = if (quadrant + 1) & 2 == 2 { -1.0 } else { 1.0 };
    (sin_sign * sin_q, cos_sign * cos_q)
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

    /// Distance in units in the last place of `expected`.
    fn ulps(got: f64, expected: f64) -> f64 {
        if got == expected {
            return 0.0;
        }
        let ulp = f64::from_bits(expected.abs().to_bits() + 1) - expected.abs();
        (got - expected).abs() / ulp
    }

    /// Within 2 ulp of the library's `exp` on a million points of `[EXP_MIN, EXP_MAX]` and on a
    /// fine grid of `[0, 50]` (the quadrature's range), exact at 0, 0 below the range.
    #[test]
    fn exp_is_within_two_ulp_of_the_library() {
        let mut worst: f64 = 0.0;
        let n = 1_000_000;
        for j in 0..=n {
            let x = EXP_MIN + (EXP_MAX - EXP_MIN) * f64::from(j) / f64::from(n);
            worst = worst.max(ulps(exp_lane(x), x.exp()));
        }
        for j in 0..=500_000 {
            let x = 50.0 * f64::from(j) / 500_000.0;
            worst = worst.max(ulps(exp_lane(x), x.exp()));
            worst = worst.max(ulps(exp_lane(-x), (-x).exp()));
        }
        assert!(worst <= 2.0, "worst {worst} ulp");
        assert_eq!(exp_lane(0.0), 1.0);
        assert_eq!(exp_lane(-800.0), 0.0);
        assert_eq!(exp_lane(f64::NEG_INFINITY), 0.0);
        // The argument where the exponent's rounding turns (k from 0 to 1) and a large one.
        for x in [0.5 * std::f64::consts::LN_2, 1e-300, -1e-300, 700.0, -700.0] {
            assert!(ulps(exp_lane(x), x.exp()) <= 2.0, "{x}");
        }
    }

    /// Within 2 ulp of the library's `sin` and `cos` (or 2e-16 absolute near their zeros) on a
    /// million points of `[-SIN_COS_MAX, SIN_COS_MAX]` and on a fine grid of `[-2 pi, 2 pi]`, in
    /// every quadrant; exact at 0.
    #[test]
    fn sin_cos_are_within_two_ulp_of_the_library() {
        let check = |x: f64, worst: &mut f64| {
            let (s, c) = sin_cos_lane(x);
            for (got, expected) in [(s, x.sin()), (c, x.cos())] {
                let error = if expected.abs() < 0.25 {
                    (got - expected).abs() / 1e-16
                } else {
                    ulps(got, expected)
                };
                *worst = worst.max(error);
            }
        };
        let mut worst: f64 = 0.0;
        let n = 1_000_000;
        for j in 0..=n {
            check(
                SIN_COS_MAX * (2.0 * f64::from(j) / f64::from(n) - 1.0),
                &mut worst,
            );
        }
        for j in 0..=400_000 {
            check(
                4.0 * std::f64::consts::PI * (f64::from(j) / 400_000.0 - 0.5),
                &mut worst,
            );
        }
        assert!(worst <= 2.0, "worst {worst}");
        assert_eq!(sin_cos_lane(0.0), (0.0, 1.0));
        let (s, c) = sin_cos_lane(std::f64::consts::PI);
        assert!(s.abs() < 2e-16 && c == -1.0, "{s} {c}");
    }
}
