//! Special functions in f64: `erf`/`erfc` (from `libm`, correctly handled tails), `erf_inv`, and
//! Beckmann's Smith `Lambda` as a function of `a`, for lanes, from Cody's rational approximations.

use crate::numerics::elementary::exp_lane;

/// `1 / sqrt(pi)`.
pub const FRAC_1_SQRT_PI: f64 = 0.564_189_583_547_756_3;

/// The error function.
#[must_use]
pub fn erf(x: f64) -> f64 {
    libm::erf(x)
}

/// The complementary error function `1 - erf(x)`, accurate in relative terms for large `x`.
#[must_use]
pub fn erfc(x: f64) -> f64 {
    libm::erfc(x)
}

/// The inverse error function written in terms of a uniform variate: returns `y` with
/// `erf(y) = 2 u - 1`, i.e. a normal deviate of variance 1/2 for `u` uniform in (0, 1).
///
/// Taking `u` rather than `2u - 1` keeps full precision in both tails: the solve runs on
/// `erfc(-y) = 2u` below the median and on `erfc(y) = 2 (1 - u)` above it.
///
/// Method: the starting guess is M. Giles' single-precision approximation of `erfinv`
/// ("Approximating the erfinv function", GPU Computing Gems, 2011), or the leading asymptotic
/// term beyond its range, refined by Halley steps on the `erfc` form (one, usually), or by Newton
/// steps on its logarithm below `u = 1e-250`. `u <= 0` gives `-inf`,
/// `u >= 1` gives `+inf`.
#[must_use]
pub fn erf_inv_uniform(u: f64) -> f64 {
    if u <= 0.0 {
        return f64::NEG_INFINITY;
    }
    if u >= 1.0 {
        return f64::INFINITY;
    }
    // Work on the lower half by symmetry: y(u) = -y(1 - u). `1 - u` is exact for u >= 0.5.
    let (tail, sign) = if u < 0.5 { (u, -1.0) } else { (1.0 - u, 1.0) };
    let mut y = erf_inv_guess(tail);
    let target = 2.0 * tail;
    if target > 1e-250 {
        // Halley on g(y) = erfc(y) - 2 tail, g' = -2/sqrt(pi) exp(-y^2), g'' = -2 y g': the step is
        // (g/g') / (1 + y g/g'). From Giles' guess (relative error ~1e-7) one step leaves ~1e-20;
        // a second runs only if the first was larger than 1e-5.
        for _ in 0..4 {
            let newton = (erfc(y) - target) / (-2.0 * FRAC_1_SQRT_PI * (-y * y).exp());
            let step = newton / (1.0 + y * newton);
            y -= step;
            if step.abs() <= 1e-5 * (1.0 + y.abs()) {
                break;
            }
        }
    } else {
        // Far out in the tail: Newton on ln erfc(y) - ln(2 tail), whose steps stay well scaled.
        let log_target = target.ln();
        for _ in 0..8 {
            let c = erfc(y);
            let step = (c.ln() - log_target) / (-2.0 * FRAC_1_SQRT_PI * (-y * y).exp() / c);
            y -= step;
            if step.abs() <= 1e-15 * y.abs() {
                break;
            }
        }
    }
    sign * y
}

/// The starting guess of [`erf_inv_uniform`] for `tail = min(u, 1 - u)` in `(0, 1/2]`: `|y|`
/// to about single precision by M. Giles' approximation of `erfinv` ("Approximating the erfinv
/// function", GPU Computing Gems, 2011) where `w = -ln(4 tail (1 - tail)) < 16`, and beyond it
/// (`tail < 3e-8`) the leading asymptotic term of `erfc`, good to about 1e-3.
fn erf_inv_guess(tail: f64) -> f64 {
    // Giles: w = -ln(1 - x^2) with x = 2u - 1, and 1 - x^2 = 4 u (1 - u).
    let w = -(4.0 * tail * (1.0 - tail)).ln();
    let x = 1.0 - 2.0 * tail; // |2u - 1|
    if w >= 16.0 {
        // Beyond Giles' range (tail < 3e-8): erfc(y) ~ exp(-y^2) / (y sqrt(pi)) = 2 tail gives
        // y^2 ~ L - ln(sqrt(pi L)) with L = -ln(2 tail).
        let l = -(2.0 * tail).ln();
        (l - (std::f64::consts::PI * l).sqrt().ln()).sqrt()
    } else if w < 5.0 {
        x * {
            let w = w - 2.5;
            let mut p = 2.810_226_36e-08;
            p = 3.432_739_39e-07 + p * w;
            p = -3.523_387_7e-06 + p * w;
            p = -4.391_506_54e-06 + p * w;
            p = 0.000_218_580_87 + p * w;
            p = -0.001_253_725_03 + p * w;
            p = -0.004_177_681_64 + p * w;
            p = 0.246_640_727 + p * w;
            1.501_409_41 + p * w
        }
    } else {
        x * {
            let w = w.sqrt() - 3.0;
            let mut p = -0.000_200_214_257;
            p = 0.000_100_950_558 + p * w;
            p = 0.001_349_343_22 + p * w;
            p = -0.003_673_428_44 + p * w;
            p = 0.005_739_507_73 + p * w;
            p = -0.007_622_461_3 + p * w;
            p = 0.009_438_870_47 + p * w;
            p = 1.001_674_06 + p * w;
            2.832_976_82 + p * w
        }
    }
}

/// Cody's first interval, `|x| <= 0.46875`: `erf(x) = x A(x^2) / B(x^2)`, the numerator's
/// coefficients from the highest degree's partner down as Cody lists them (`A[4]` leads).
/// W. J. Cody, "Rational Chebyshev approximations for the error function", Math. Comp. 23
/// (1969) 631-637, as tabulated in his SPECFUN routine CALERF (1990), each the double nearest
/// the published 18 digits.
const CODY_A: [f64; 5] = [
    3.1611237438705655,
    113.86415415105016,
    377.485237685302,
    3209.3775891384694,
    0.18577770618460315,
];
const CODY_B: [f64; 4] = [
    23.601290952344122,
    244.02463793444417,
    1282.6165260773723,
    2844.236833439171,
];
/// Cody's second interval, `0.46875 < x <= 4`: `exp(x^2) erfc(x) = C(x) / D(x)` (same source).
const CODY_C: [f64; 9] = [
    0.5641884969886701,
    8.883149794388377,
    66.11919063714163,
    298.6351381974001,
    881.952221241769,
    1712.0476126340707,
    2051.0783778260716,
    1230.3393547979972,
    2.1531153547440383e-8,
];
const CODY_D: [f64; 8] = [
    15.744926110709835,
    117.6939508913125,
    537.1811018620099,
    1621.3895745666903,
    3290.7992357334597,
    4362.619090143247,
    3439.3676741437216,
    1230.3393548037495,
];
/// Cody's third interval, `x > 4`: `x exp(x^2) erfc(x) = 1 / sqrt(pi) - z P(z) / Q(z)` with
/// `z = 1 / x^2` (same source).
const CODY_P: [f64; 6] = [
    0.30532663496123236,
    0.36034489994980445,
    0.12578172611122926,
    0.016083785148742275,
    6.587491615298378e-4,
    0.016315387137302097,
];
const CODY_Q: [f64; 5] = [
    2.568520192289822,
    1.8729528499234604,
    0.5279051029514285,
    0.06051834131244132,
    0.0023352049762686918,
];

/// Where Cody's first interval ends and his third begins.
const CODY_FIRST_TO: f64 = 0.468_75;
const CODY_THIRD_FROM: f64 = 4.0;

/// The numerator and denominator of one of Cody's rationals at `x`, in his order of
/// evaluation: `num = p[n] x`, `den = x`, then `num = (num + p[i]) x`, `den = (den + q[i]) x`
/// for `i < n - 1`, and `p[n - 1]`, `q[n - 1]` added last (`q` has `n` entries, `p` one more;
/// the denominator's leading coefficient is 1).
#[inline(always)]
fn cody_rational<const P: usize, const Q: usize>(x: f64, p: &[f64; P], q: &[f64; Q]) -> (f64, f64) {
    let n = Q;
    let mut num = p[n] * x;
    let mut den = x;
    for i in 0..n - 1 {
        num = (num + p[i]) * x;
        den = (den + q[i]) * x;
    }
    (num + p[n - 1], den + q[n - 1])
}

/// Beckmann's Smith `Lambda` as a function of `a = 1 / (alpha tan(theta))` (Walter 2007, eq. 27
/// before its rational fit), `Lambda = (exp(-a^2) / (a sqrt(pi)) - erfc(a)) / 2`, at several `a`
/// at once, branch-free so that the loop vectorises. `a = 0` gives `+inf`, `a = +inf` gives 0.
///
/// `erfc` comes from Cody's three rational approximations (see `CODY_A`), each written so that
/// the two terms of `Lambda` cancel as little as they can:
/// - `a <= 0.46875`: `(exp(-a^2) / (a sqrt(pi)) - 1 + a A(a^2) / B(a^2)) / 2`;
/// - `a <= 4`: `exp(-a^2) (1 / (a sqrt(pi)) - C(a) / D(a)) / 2`, which loses at most
///   `log10(2 a^2) < 1.6` digits to cancellation;
/// - `a > 4`: `exp(-a^2) z P(z) / Q(z) / (2 a)` with `z = 1 / a^2`, the asymptotic difference in
///   closed form: nothing cancels.
///
/// All three are evaluated and one is selected, with one division for the selected ratio. The
/// lane-wise `exp` ([`exp_lane`]) takes `-a^2` as rounded, so `Lambda`'s relative error grows
/// to `a^2` ulps where it is below `1e-200`; no sum of `Lambda`s sees that. Held to `mpmath`'s
/// values within `4e-15` relative from `a = 1e-8` to 26 (the tests).
#[inline(always)]
#[must_use]
pub fn beckmann_lambda_of_a<const L: usize>(a: &[f64; L]) -> [f64; L] {
    let mut lambdas = [0.0; L];
    for (lambda, &a) in lambdas.iter_mut().zip(a) {
        let inverse_a = 1.0 / a;
        let a2 = a * a;
        let z = inverse_a * inverse_a;
        let (first_num, first_den) = cody_rational(a2, &CODY_A, &CODY_B);
        let first_num = a * first_num;
        let (second_num, second_den) = cody_rational(a, &CODY_C, &CODY_D);
        let (third_num, third_den) = cody_rational(z, &CODY_P, &CODY_Q);
        let third_num = z * third_num;
        let first = a <= CODY_FIRST_TO;
        let third = a > CODY_THIRD_FROM;
        let (num, den) = if first {
            (first_num, first_den)
        } else if third {
            (third_num, third_den)
        } else {
            (second_num, second_den)
        };
        let ratio = num / den;
        let e = exp_lane(-a2);
        let leading = e * inverse_a * FRAC_1_SQRT_PI;
        let twice = if first {
            leading - 1.0 + ratio
        } else if third {
            e * ratio * inverse_a
        } else {
            leading - e * ratio
        };
        *lambda = 0.5 * twice;
    }
    lambdas
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn erf_inv_inverts_erf_across_the_range_and_in_the_tails() {
        for &u in &[
            1e-300,
            1e-100,
            1e-17,
            1e-9,
            1e-3,
            0.1,
            0.3,
            0.5,
            0.7,
            0.999,
            1.0 - 1e-12,
        ] {
            let y = erf_inv_uniform(u);
            // Check in the form that keeps precision: erfc(-y) = 2u.
            let back = erfc(-y) / 2.0;
            assert!(
                ((back - u) / u).abs() < 1e-13,
                "u = {u}: y = {y}, erfc(-y)/2 = {back}"
            );
        }
        // The median is +0, not -0 (the upper half takes it).
        assert_eq!(erf_inv_uniform(0.5).to_bits(), 0.0f64.to_bits());
        assert_eq!(erf_inv_uniform(0.0), f64::NEG_INFINITY);
        assert_eq!(erf_inv_uniform(1.0), f64::INFINITY);
    }

    /// Giles' guess is good to single precision over his range, so that one Halley step
    /// suffices (about 1e-7 relative, single precision), and the asymptotic guess beyond it
    /// to about 1e-3. Against the converged inverse, which the
    /// test above holds to `erfc`.
    #[test]
    fn the_starting_guess_is_as_good_as_its_sources_say() {
        let mut worst_giles: f64 = 0.0;
        // tail from 0.5 down to 3e-8, through both of Giles' branches (w = 5 at tail ~ 1.7e-3).
        for k in 0..=400 {
            let tail = 0.5 * 10f64.powf(-7.2 * f64::from(k) / 400.0);
            let y = -erf_inv_uniform(tail);
            if y == 0.0 {
                assert_eq!(erf_inv_guess(tail), 0.0);
                continue;
            }
            worst_giles = worst_giles.max((erf_inv_guess(tail) / y - 1.0).abs());
        }
        // 1.24e-7 measured.
        assert!(worst_giles < 2e-7, "{worst_giles:e}");
        let mut worst_asymptotic: f64 = 0.0;
        for tail in [2e-8, 1e-10, 1e-20, 1e-100, 1e-249, 1e-300] {
            let y = -erf_inv_uniform(tail);
            worst_asymptotic = worst_asymptotic.max((erf_inv_guess(tail) / y - 1.0).abs());
        }
        // 1.0e-3 measured.
        assert!(worst_asymptotic < 2e-3, "{worst_asymptotic:e}");
    }
}
