//! The deterministic sheen albedo `E_sheen(mu_o, alpha) = ∫ D(h) V(o, i) mu_i dω_i` of the
//! Charlie/Ashikhmin cloth lobe ([`crate::model::sheen`]), the blue channel of Filament's and
//! Godot's DFG tables.
//!
//! The integral is taken over half vectors, where the distribution's sharp factor lives: with
//! `c = cos(theta_h)` and `dω_i = 4 (o.h) dω_h = 4 (o.h) dc dphi` (the reflection Jacobian,
//! Walter et al. 2007, eq. 14),
//! `E = 2 ∫_0^1 dc D(c) ∫_0^{phi_max(c)} dphi V(o, i) mu_i 4 (o.h)`,
//! with `o = (s_o, 0, mu_o)`, `o.h = s_o s_h cos(phi) + mu_o c`, `mu_i = 2 (o.h) c - mu_o`, and
//! `phi_max` where `mu_i` reaches 0. In the plane of incidence the reflected direction's polar
//! angle is `2 theta_h -+ theta_o`, so the support starts at `theta_h = (theta_o + pi/2) / 2`
//! and covers every `phi` below `theta_h = (pi/2 - theta_o) / 2`: both are break points of the
//! outer integral, as is the distribution's width `1 / sqrt(k)`, `k = 1 / (2 alpha)`, past the
//! support's start. Both integrals are adaptive Gauss-Kronrod ([`super::gauss_kronrod`]); the
//! inner one evaluates a rule's nodes at once (`inner_values`, compiled for AVX2 where the CPU
//! has it), and its error estimates are carried through the outer integral into the stated error.

use super::gauss_kronrod::{KRONROD_NODES, Quadrature, integrate_pieces, integrate_pieces_batch};
use crate::model::sheen::{ashikhmin_v, charlie_d, charlie_weight};
use crate::model::vector::sin_from_cos;
use crate::numerics::elementary::sin_cos_lane;
use std::f64::consts::{FRAC_PI_2, PI};

/// `E_sheen(mu_o, alpha)` to the absolute `tolerance`, for `alpha > 0`, `mu_o` in `(0, 1]`:
/// the value, its error estimate and whether the tolerance was met.
#[must_use]
pub fn sheen_albedo(alpha: f64, mu_o: f64, tolerance: f64) -> Quadrature<1> {
    let mu_o = mu_o.clamp(0.0, 1.0);
    let s_o = sin_from_cos(mu_o);
    let theta_o = mu_o.acos();
    let c_start = ((theta_o + FRAC_PI_2) / 2.0).cos();
    let c_full = ((FRAC_PI_2 - theta_o) / 2.0).cos();
    let width = (2.0 * alpha).sqrt();
    let mut breaks = vec![c_start, c_full, 1.0];
    for m in [0.25, 1.0, 3.0, 8.0] {
        breaks.push((c_start + m * width).min(1.0));
    }
    breaks.sort_by(f64::total_cmp);
    breaks.dedup();
    // The inner integrals' error estimates reach the stated error weighted by `2 D(c)`, whose
    // integral over `c` is `weight`: each inner integral gets `INNER_SHARE` of the tolerance
    // divided by it, the outer integral the rest, so the stated error stays within `tolerance`.
    let inner_tolerance = INNER_SHARE * tolerance / charlie_weight(alpha);
    let mut inner_evaluations = 0;
    let mut inner_converged = true;
    let mut outer = |c: f64| -> [f64; 2] {
        let d = charlie_d(c, alpha);
        if d == 0.0 {
            return [0.0; 2];
        }
        let s_h = sin_from_cos(c);
        // mu_i > 0  <=>  cos(phi) > (mu_o / (2 c) - mu_o c) / (s_o s_h).
        let numerator = mu_o / (2.0 * c) - mu_o * c;
        let denominator = s_o * s_h;
        let phi_max = if denominator > 0.0 {
            (numerator / denominator).clamp(-1.0, 1.0).acos()
        } else if numerator < 0.0 {
            PI
        } else {
            0.0
        };
        if phi_max == 0.0 {
            return [0.0; 2];
        }
        let slice = Slice {
            mu_o,
            a: s_o * s_h,
            c,
        };
        let inner = integrate_pieces_batch(
            &mut |nodes: &[f64; KRONROD_NODES], values: &mut [[f64; 1]; KRONROD_NODES]| {
                *values = slice.values_at(nodes);
            },
            &[0.0, phi_max],
            inner_tolerance,
            64,
        );
        inner_evaluations += inner.evaluations;
        inner_converged &= inner.converged;
        [2.0 * d * inner.value[0], 2.0 * d * inner.error]
    };
    let outer = integrate_pieces(&mut outer, &breaks, (1.0 - INNER_SHARE) * tolerance, 400);
    // The inner integrals' estimates, weighted as their values are, add to the outer one's;
    // an inner integral that ran out of budget makes the whole unconverged.
    Quadrature {
        value: [outer.value[0]],
        error: outer.error + outer.value[1],
        evaluations: outer.evaluations + inner_evaluations,
        converged: outer.converged && inner_converged,
    }
}

/// The share of [`sheen_albedo`]'s tolerance left to the inner integrals' errors. A quarter:
/// the inner integrals cost 97 % of the evaluations (most of them splits that the pessimistic
/// `|K15 - G7|` estimate asks for), and a quarter took the 128 x 128 plane of Filament and Godot
/// from 88 to 57 million evaluations (a tenth: 61 million; a fixed 1e-3 of the tolerance for
/// every `alpha`, as before: 88 million, and a stated error up to 1.001 times the tolerance).
const INNER_SHARE: f64 = 0.25;

/// One inner integral's fixed terms: the view `mu_o`, `a = sin(theta_o) sin(theta_h)` and
/// `c = cos(theta_h)`, so that `o.h = a cos(phi) + mu_o c`.
struct Slice {
    mu_o: f64,
    a: f64,
    c: f64,
}

impl Slice {
    /// [`inner_values`], compiled for AVX2 where the CPU has it.
    #[inline(always)]
    fn values_at(&self, nodes: &[f64; KRONROD_NODES]) -> [[f64; 1]; KRONROD_NODES] {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports AVX2, checked on the line above.
            return unsafe { inner_values_avx2(self, nodes) };
        }
        inner_values(self, nodes)
    }
}

/// [`inner_values`] compiled for AVX2: bit-identical (the same IEEE operations in the same order
/// per lane), several lanes at a time.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn inner_values_avx2(slice: &Slice, nodes: &[f64; KRONROD_NODES]) -> [[f64; 1]; KRONROD_NODES] {
    inner_values(slice, nodes)
}

/// The inner integrand `V(o, i) mu_i 4 (o.h)` at a rule's nodes `phi`, with the lane-wise
/// cosine ([`sin_cos_lane`]); nothing where `i` or `h` is below the horizon.
#[inline(always)]
fn inner_values(slice: &Slice, nodes: &[f64; KRONROD_NODES]) -> [[f64; 1]; KRONROD_NODES] {
    let Slice { mu_o, a, c } = *slice;
    let mut values = [[0.0]; KRONROD_NODES];
    for (value, &phi) in values.iter_mut().zip(nodes) {
        let (_, cos_phi) = sin_cos_lane(phi);
        let o_dot_h = a * cos_phi + mu_o * c;
        let mu_i = 2.0 * o_dot_h * c - mu_o;
        let v = ashikhmin_v(mu_o, mu_i) * mu_i * 4.0 * o_dot_h;
        value[0] = if mu_i <= 0.0 || o_dot_h <= 0.0 {
            0.0
        } else {
            v
        };
    }
    values
}

/// A sheen plane on texel centres: rows perceptual roughness `(i + 0.5) / n` (`alpha = r^2`),
/// columns `mu_o = (j + 0.5) / n`, row-major, each to the absolute `tolerance`; with the largest
/// error estimate and whether every texel met the tolerance. Texels are independent, so the
/// parallel loop gives the same bytes on any thread count.
#[must_use]
pub fn sheen_plane(n: usize, tolerance: f64) -> SheenPlane {
    use rayon::prelude::*;
    let texels: Vec<Quadrature<1>> = (0..n * n)
        .into_par_iter()
        .map(|k| {
            let r = ((k / n) as f64 + 0.5) / n as f64;
            let mu = ((k % n) as f64 + 0.5) / n as f64;
            sheen_albedo(r * r, mu, tolerance)
        })
        .collect();
    SheenPlane {
        max_error: crate::stats::max_or_nan(texels.iter().map(|q| q.error)),
        converged: texels.iter().all(|q| q.converged),
        value: texels.into_iter().map(|q| q.value[0]).collect(),
    }
}

/// The result of [`sheen_plane`].
#[derive(Clone, Debug, PartialEq)]
pub struct SheenPlane {
    /// `E_sheen` per texel, row-major (roughness rows, `mu` columns).
    pub value: Vec<f64>,
    /// The largest quadrature error estimate.
    pub max_error: f64,
    /// Whether every texel met the tolerance.
    pub converged: bool,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::sheen::sheen_albedo_at_normal;

    /// The inner lanes against the integrand written out one node at a time with the library's
    /// `cos` (within rounding), and the AVX2 build against the portable one bit for bit; nodes
    /// on both sides of the cut-off where `mu_i` reaches 0.
    #[test]
    fn the_inner_lanes_give_the_scalar_integrand() {
        let nodes: [f64; KRONROD_NODES] = std::array::from_fn(|k| 0.21 * k as f64);
        let mut zeros = 0;
        for (mu_o, theta_h) in [(0.3_f64, 0.9_f64), (0.05, 1.3), (0.9, 0.2)] {
            let (s_o, (s_h, c)) = (sin_from_cos(mu_o), theta_h.sin_cos());
            let slice = Slice {
                mu_o,
                a: s_o * s_h,
                c,
            };
            let lanes = inner_values(&slice, &nodes);
            for (k, &phi) in nodes.iter().enumerate() {
                let o_dot_h = s_o * s_h * phi.cos() + mu_o * c;
                let mu_i = 2.0 * o_dot_h * c - mu_o;
                let want = if mu_i <= 0.0 || o_dot_h <= 0.0 {
                    zeros += 1;
                    0.0
                } else {
                    mu_i * o_dot_h / (mu_i + mu_o - mu_i * mu_o)
                };
                let got = lanes[k][0];
                assert!(
                    (got - want).abs() <= 1e-14 * want.abs(),
                    "phi {phi}: {got} vs {want}"
                );
            }
            #[cfg(target_arch = "x86_64")]
            if std::arch::is_x86_feature_detected!("avx2") {
                // SAFETY: checked on the line above.
                let simd = unsafe { inner_values_avx2(&slice, &nodes) };
                assert_eq!(simd.map(|v| v[0].to_bits()), lanes.map(|v| v[0].to_bits()));
            }
        }
        assert!(zeros > 0 && zeros < 3 * KRONROD_NODES, "{zeros} zeros");
    }

    /// The Beta-function form of `∫ 2 D dc` against mpmath 1.3 (30 digits, `(2 + 1/alpha) /
    /// pi * sqrt(pi) / 2 * gamma(k + 1) / gamma(k + 3/2)`) and against the distribution
    /// integrated numerically (adaptive Gauss-Kronrod, split where its peak at `c = 0` ends),
    /// within 1e-9 (the difference of `lgamma`s near 3e5 at `alpha = 1.5e-5` keeps 4e-11); and
    /// the tolerance split it feeds: at the tolerance Filament's and Godot's planes use, the
    /// stated error is within it and covers the difference from a result 1e5 times tighter.
    #[test]
    fn the_inner_share_is_weighted_by_the_distribution() {
        for (alpha, mpmath) in [
            (1.5e-5_f64, 103.008_385_227_202_85),
            (1e-3, 12.631_423_130_208_645),
            (0.05, 1.892_582_742_008_043_2),
            (0.3, 0.965_277_713_516_110_2),
            (1.0, 0.75),
        ] {
            let width = (2.0 * alpha).sqrt();
            let breaks = [0.0, width, 4.0 * width, 16.0 * width, 1.0].map(|b: f64| b.min(1.0));
            let numeric = integrate_pieces(
                &mut |c: f64| [2.0 * charlie_d(c, alpha)],
                &breaks,
                1e-13,
                400,
            );
            let closed = charlie_weight(alpha);
            for want in [mpmath, numeric.value[0]] {
                assert!(
                    (closed - want).abs() <= 1e-9 * want,
                    "alpha {alpha}: {closed} vs {want}"
                );
            }
        }
        for (alpha, mu_o) in [(1.5e-5, 0.3), (0.01, 0.05), (0.25, 0.7), (1.0, 0.996)] {
            let q = sheen_albedo(alpha, mu_o, 1e-7);
            let tight = sheen_albedo(alpha, mu_o, 1e-12);
            assert!(q.converged && tight.converged, "alpha {alpha}, mu {mu_o}");
            assert!(q.error <= 1e-7, "alpha {alpha}, mu {mu_o}: {:e}", q.error);
            let off = (q.value[0] - tight.value[0]).abs();
            assert!(
                off <= q.error + tight.error,
                "alpha {alpha}, mu {mu_o}: off by {off:e}, stated {:e}",
                q.error
            );
        }
    }

    #[test]
    fn normal_incidence_matches_the_closed_form() {
        for alpha in [1e-4, 0.01, 0.1, 0.5, 1.0] {
            let q = sheen_albedo(alpha, 1.0, 1e-12);
            let exact = sheen_albedo_at_normal(alpha);
            assert!(q.converged, "alpha {alpha}");
            assert!(
                (q.value[0] - exact).abs() <= 1e-11 + 1e-10 * exact,
                "alpha {alpha}: {} vs {exact}",
                q.value[0]
            );
        }
    }

    /// An independent estimate over incident directions instead of half vectors: uniform
    /// hemisphere sampling of `i` (pdf `1 / (2 pi)`), jittered-stratified, with the standard
    /// error from independent replicates.
    fn sampled(alpha: f64, mu_o: f64) -> (f64, f64) {
        let o = crate::model::Vec3::from_mu(mu_o);
        let (n, replicates) = (128usize, 16usize);
        let mut state = 0x9e37_79b9_7f4a_7c15u64 ^ (alpha.to_bits() ^ mu_o.to_bits());
        let mut uniform = || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let means: Vec<f64> = (0..replicates)
            .map(|_| {
                let mut sum = 0.0;
                for a in 0..n {
                    for b in 0..n {
                        let mu_i = (a as f64 + uniform()) / n as f64;
                        let phi = 2.0 * PI * (b as f64 + uniform()) / n as f64;
                        let s_i = (1.0 - mu_i * mu_i).sqrt();
                        let (hx, hy, hz) =
                            (o.x + s_i * phi.cos(), o.y + s_i * phi.sin(), o.z + mu_i);
                        let cos_h = hz / (hx * hx + hy * hy + hz * hz).sqrt();
                        sum += charlie_d(cos_h, alpha) * ashikhmin_v(mu_o, mu_i) * mu_i * 2.0 * PI;
                    }
                }
                sum / (n * n) as f64
            })
            .collect();
        let mean = means.iter().sum::<f64>() / replicates as f64;
        let variance = means.iter().map(|m| (m - mean).powi(2)).sum::<f64>()
            / ((replicates - 1) * replicates) as f64;
        (mean, variance.sqrt())
    }

    #[test]
    fn oblique_views_match_an_independent_sampled_estimate() {
        for alpha in [0.1, 0.3, 1.0] {
            for mu_o in [0.05, 0.3, 0.7] {
                let q = sheen_albedo(alpha, mu_o, 1e-9);
                assert!(q.converged);
                let (mean, std_error) = sampled(alpha, mu_o);
                // Five standard errors: a false failure has odds below 1e-6 per point.
                assert!(
                    (q.value[0] - mean).abs() <= 5.0 * std_error + 1e-9,
                    "alpha {alpha}, mu {mu_o}: quadrature {} vs sampled {mean} +- {std_error}",
                    q.value[0]
                );
            }
        }
    }
}
