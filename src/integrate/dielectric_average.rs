//! The hemispherical average of a rough dielectric's energy albedo, `E_avg,eta = 2 ∫ E_eta(mu) mu
//! dmu`, by a quadrature over the microfacet normal first: a sixth of the evaluations of the
//! nested one (an integral over `mu` of [`super::dielectric`]'s integrals over the visible
//! normals; 28 M against 167 M over 16 points at 1e-7, GGX, alpha 0.01 to 1, eta 1/3 to 1.5),
//! which stays as an independent check of it.
//!
//! Swapping the order (the view `o` and the normal `m` both range over their hemispheres):
//!
//! `X_avg = (1 / pi) ∫ dω_o ∫ dω_m D(m) (o.m)+ G1(o) s_X(o, m) = (1 / pi) ∫ dω_m D(m) K_X(m)`,
//!
//! with `s_X` the reflected, transmitted or lost fraction at one visible normal
//! (`scattering_at_cos`, Walter et al. 2007 with Smith masking; `docs/physics.md`) and
//! `K_X(m) = ∫ (o.m)+ G1(o) s_X(o, m) dω_o` over the views above the surface. `K` depends only
//! on `theta_m` (isotropy). In the normal's frame, with `o.m = cos(theta_h)` and `phi_h` the
//! view's azimuth about `m` (`phi_h = 0` tilted toward the macro normal):
//!
//! - the Fresnel factor depends on `theta_h` alone, so the critical angle `sin(theta_h) = eta`
//!   is a line of the grid;
//! - `o.z = A - B cos(phi_h)`, the reflected direction's `z = A + B cos(phi_h)` and the
//!   refracted one's `(B cos(phi_h) - eta cos(theta_t) cos(theta_m)) / eta`, with `A =
//!   cos(theta_h) cos(theta_m)`, `B = sin(theta_h) sin(theta_m)`: every horizon the masking
//!   turns on is a closed-form `phi_h`.
//!
//! So `X_avg = 4 ∫ dx D sin^2(theta_m) cos(theta_m) ∫_0^{pi/2} dtheta_h sin cos(theta_h) ∫_0^pi
//! dphi_h G1(o) s_X`, with `x = ln(tan(theta_m) / alpha)` integrated in `s = t / (alpha + t)`
//! ([`super::reference`]), where the whole line is `[0, 1]`. Each level is adaptive
//! Gauss-Kronrod; its stated error adds its own estimate and the integral of the levels' below,
//! as the nested reference does. With `s_R + s_T + s_L = 1` the three parts add up to 1 (`(1 /
//! pi) ∫ mu_o dω_o`), which the tests check along with agreement with the nested reference.

use super::dielectric_reference::DielectricReference;
use super::gauss_kronrod::{KRONROD_NODES, integrate_pieces, integrate_pieces_batch};
use super::reference::{ReferenceSettings, ladder, s_of_x, t_of_s};
use crate::model::dielectric::{TransmissionConvention, scatterings_at_cos};
use crate::model::{Masking, MicrofacetDistribution, Vec3};
use crate::numerics::bisection::bisect;
use crate::numerics::elementary::sin_cos_lane;
use std::f64::consts::{FRAC_PI_2, PI};

/// How a piece of a level is mapped onto its share `[k, k + 1]` of the rule's variable: plainly,
/// or with `u^2` at an end where the integrand goes as a square root of the distance (the
/// critical angle, where a horizon enters the slice), which makes it smooth there.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Ends {
    Plain,
    SquareRootAtStart,
    SquareRootAtEnd,
    SquareRootAtBoth,
}

/// A piece `[a, b]` of a level and how its ends behave.
#[derive(Clone, Copy, Debug)]
struct Piece {
    a: f64,
    b: f64,
    ends: Ends,
}

/// `(point, d point / d u)` at `u in [0, 1]` along `piece`.
fn map(piece: Piece, u: f64) -> (f64, f64) {
    let width = piece.b - piece.a;
    match piece.ends {
        Ends::Plain => (piece.a + width * u, width),
        Ends::SquareRootAtStart => (piece.a + width * u * u, 2.0 * width * u),
        Ends::SquareRootAtEnd => {
            let v = 1.0 - u;
            (piece.b - width * v * v, 2.0 * width * v)
        }
        Ends::SquareRootAtBoth => (
            piece.a + width * u * u * (3.0 - 2.0 * u),
            6.0 * width * u * (1.0 - u),
        ),
    }
}

/// Pieces between sorted, deduplicated `breaks`, with square-root ends at the points listed in
/// `singular`.
fn pieces(breaks: &[f64], singular: &[f64]) -> Vec<Piece> {
    breaks
        .windows(2)
        .filter(|w| w[1] > w[0])
        .map(|w| {
            let ends = match (singular.contains(&w[0]), singular.contains(&w[1])) {
                (false, false) => Ends::Plain,
                (true, false) => Ends::SquareRootAtStart,
                (false, true) => Ends::SquareRootAtEnd,
                (true, true) => Ends::SquareRootAtBoth,
            };
            Piece {
                a: w[0],
                b: w[1],
                ends,
            }
        })
        .collect()
}

/// The integral of `f` over `pieces` (at least one), each in its own variable `u` ([`map`]),
/// adaptively over all of them at once.
fn integrate_mapped(
    f: &mut impl FnMut(f64) -> [f64; 4],
    pieces: &[Piece],
    tolerance: f64,
    max_intervals: usize,
) -> super::gauss_kronrod::Quadrature<4> {
    let breaks: Vec<f64> = (0..=pieces.len()).map(|k| k as f64).collect();
    let mut mapped = |v: f64| {
        let k = (v.floor() as usize).min(pieces.len() - 1);
        let (point, jacobian) = map(pieces[k], v - k as f64);
        f(point).map(|value| value * jacobian)
    };
    integrate_pieces(&mut mapped, &breaks, tolerance, max_intervals)
}

/// Sorts, deduplicates and keeps the breaks within `[lo, hi]`.
fn tidy(breaks: &mut Vec<f64>, lo: f64, hi: f64) {
    breaks.retain(|&b| b >= lo && b <= hi);
    breaks.sort_by(f64::total_cmp);
    breaks.dedup();
}

/// Lanes of one batch of the inner integrand: a rule's [`KRONROD_NODES`] padded to a multiple
/// of the SIMD width.
const LANES: usize = 16;

/// One inner slice: the normal `m = (sin_m, 0, cos_m)` and the views at angle `theta_h` from it
/// (`cos_h = o.m`).
struct Slice<N> {
    ndf: N,
    masking: Masking,
    m: Vec3,
    sin_h: f64,
    cos_h: f64,
    eta: f64,
    convention: TransmissionConvention,
}

impl<N: MicrofacetDistribution> Slice<N> {
    /// [`slice_values`], compiled for AVX2 where the CPU has it.
    #[inline(always)]
    fn values_at(&self, nodes: &[f64; KRONROD_NODES]) -> [[f64; 4]; LANES] {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports AVX2, checked on the line above.
            return unsafe { slice_values_avx2(self, nodes) };
        }
        slice_values(self, nodes)
    }
}

/// [`slice_values`] compiled for AVX2: bit-identical (the same IEEE operations in the same
/// order per lane), several lanes at a time, the views' `sin` and `cos` included.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn slice_values_avx2<N: MicrofacetDistribution>(
    slice: &Slice<N>,
    nodes: &[f64; KRONROD_NODES],
) -> [[f64; 4]; LANES] {
    slice_values(slice, nodes)
}

/// The views at a rule's nodes `phi_h` (around `m`, at angle `theta_h` from it), and
/// [`slice_lanes`] there.
#[inline(always)]
fn slice_values<N: MicrofacetDistribution>(
    slice: &Slice<N>,
    nodes: &[f64; KRONROD_NODES],
) -> [[f64; 4]; LANES] {
    let Vec3 {
        x: sin_m, z: cos_m, ..
    } = slice.m;
    let (sin_h, cos_h) = (slice.sin_h, slice.cos_h);
    let a = cos_h * cos_m;
    let b = sin_h * sin_m;
    // Padded first: an index `k % KRONROD_NODES` inside the loop kept `sin_cos_lane` scalar.
    let padded: [f64; LANES] = std::array::from_fn(|k| nodes[k % KRONROD_NODES]);
    let mut o = [slice.m; LANES];
    for (o, &phi) in o.iter_mut().zip(&padded) {
        let (sin_p, cos_p) = sin_cos_lane(phi);
        *o = Vec3::new(
            cos_h * sin_m + sin_h * cos_p * cos_m,
            sin_h * sin_p,
            a - b * cos_p,
        );
    }
    slice_lanes(slice, &o)
}

/// The inner integrand at the views `o[k]`: `G1(o) [R, T, 1 - E, 0]` of the slice's normal
/// ([`scatterings_at_cos`] with `o.m = cos_h` exactly), nothing for a view below the horizon.
#[inline(always)]
fn slice_lanes<N: MicrofacetDistribution>(
    slice: &Slice<N>,
    o: &[Vec3; LANES],
) -> [[f64; 4]; LANES] {
    let lambda_o = slice.ndf.lambdas_from_tan2(&o.map(Vec3::tan2_theta));
    let scattering = scatterings_at_cos(
        slice.ndf,
        slice.masking,
        o,
        &lambda_o,
        &[slice.m; LANES],
        &[slice.cos_h; LANES],
        slice.eta,
        slice.convention,
    );
    let mut values = [[0.0; 4]; LANES];
    for k in 0..LANES {
        let g1 = 1.0 / (1.0 + lambda_o[k]);
        let s = scattering[k];
        values[k] = if o[k].z <= 0.0 {
            [0.0; 4]
        } else {
            [g1 * s.reflection, g1 * s.transmission, g1 * s.loss, 0.0]
        };
    }
    values
}

/// The inner integral's breaks in `phi_h`, and the lowest `phi_h` integrated: the horizons of
/// the view (`o.z = 0` at `cos phi_h = a / b`, views at larger `phi_h` above), of the reflected
/// direction (at pi less that) and, where the slice `refracts`, of the refracted direction (at
/// `cos phi_h = eta cos(theta_t) cos(theta_m) / b`), each with a ladder into its masking layer.
/// `(a, b) = (cos theta_h cos theta_m, sin theta_h sin theta_m)`.
fn azimuth_breaks(
    (a, b, cos_m): (f64, f64, f64),
    (alpha, eta): (f64, f64),
    cos_theta_t: f64,
    refracts: bool,
    convention: TransmissionConvention,
) -> (Vec<f64>, f64) {
    // Horizons in phi_h: the view's (o.z = 0, views at larger phi_h are above), the
    // reflected direction's (at pi - that, reflections at smaller phi_h are above) and
    // the refracted one's (refractions at larger phi_h are below).
    let mut breaks = vec![0.0, PI];
    let mut lower = 0.0;
    let layer = |phi: f64, width: f64| -> f64 {
        let slope = b * phi.sin();
        width / slope.max((width * b).sqrt()).max(1e-300)
    };
    if a < b {
        let phi_o = (a / b).acos();
        lower = phi_o;
        let phi_r = PI - phi_o;
        breaks.extend([phi_o, phi_r]);
        let width = layer(phi_o, alpha);
        for rung in ladder(width, PI) {
            breaks.extend([phi_o + rung, phi_r - rung]);
        }
    }
    if refracts && b > 0.0 {
        let w_t = eta * cos_theta_t * cos_m / b;
        if w_t < 1.0 {
            let phi_t = w_t.acos();
            breaks.push(phi_t);
            let width = layer(phi_t, alpha * eta);
            // The transmission's masking layer is on the side where the refracted
            // direction is below the surface; in the convention that keeps refractions
            // above it too, on both.
            for rung in ladder(width, PI) {
                breaks.push(phi_t + rung);
                if convention.keeps_refraction_above() {
                    breaks.push(phi_t - rung);
                }
            }
        }
    }
    (breaks, lower)
}

/// `R_avg`, `T_avg` and `(1 - E)_avg` with the stated error (see the module docs) for one
/// distribution.
pub(crate) fn average<N: MicrofacetDistribution>(
    ndf: N,
    masking: Masking,
    eta: f64,
    convention: TransmissionConvention,
    settings: &ReferenceSettings,
) -> DielectricReference {
    let alpha = ndf.alpha();
    let tolerance = settings.tolerance;
    let max_intervals = settings.max_intervals;
    let critical = (eta < 1.0).then(|| eta.asin());

    // The outer weight `4 D sin^2 cos dx/ds` at `s`, and where `theta_m` is.
    let outer_weight = |s: f64| -> Option<(f64, f64, f64)> {
        let (t, jacobian) = t_of_s(s, alpha);
        if !(t > 0.0 && t < f64::INFINITY) {
            return None;
        }
        let cos_m = 1.0 / (1.0 + t * t).sqrt();
        let sin_m = t * cos_m;
        let weight = 4.0 * ndf.d_from_tan2(t * t) * sin_m * sin_m * cos_m * jacobian;
        Some((weight, sin_m, cos_m))
    };
    let mut outer_breaks = vec![0.0, 0.5, 1.0];
    if let Some(c) = critical {
        // theta_m = pi / 2 - theta_c: the views' horizon enters the slice at the critical angle.
        outer_breaks.push(s_of_x(((FRAC_PI_2 - c).tan() / alpha).ln()));
    }
    if eta > 1.0 {
        // tan(theta_m) = sqrt(eta^2 - 1): where the refracted direction's horizon first enters
        // the slices (at theta_h = pi / 2, below), a kink of the middle integral. Without the
        // break the outer rule split toward it (GGX alpha 0.09, eta 1.5 at 1e-7: 1.44 M
        // evaluations, 0.45 M with it; the 16 x 16 outside average baked in 2.0 s, was 2.5 s).
        let tan_m = ((eta - 1.0) * (eta + 1.0)).sqrt();
        outer_breaks.push(s_of_x((tan_m / alpha).ln()));
    }
    tidy(&mut outer_breaks, 0.0, 1.0);
    // The tolerance is shared between the levels as in the nested reference: the outer rule
    // gets half; each middle integral `tolerance / (4 W)` (half its own rule's, half the inner
    // integrals', whose weight `sin cos` integrates to 1/2), which the outer weight, of
    // integral `W`, adds up to a quarter. The stated error adds every level's estimates
    // whatever they come to; this only aims them.
    let total_weight = integrate_pieces(
        &mut |s: f64| [outer_weight(s).map_or(0.0, |w| w.0)],
        &outer_breaks,
        1e-3,
        max_intervals,
    )
    .value[0]
        .max(1e-3);
    let middle_tolerance = tolerance / (4.0 * total_weight);
    let mut evaluations = 0u64;
    let mut converged = true;

    let mut over_theta_m = |s: f64| -> [f64; 4] {
        let Some((weight, sin_m, cos_m)) = outer_weight(s) else {
            return [0.0; 4];
        };
        let m = Vec3::new(sin_m, 0.0, cos_m);
        let theta_m = sin_m.atan2(cos_m);
        // Where the views' horizon enters the slice (A = B): theta_h = pi / 2 - theta_m.
        let entry = FRAC_PI_2 - theta_m;
        // Where the refracted direction's horizon enters (cos phi_h = 1): eta cos(theta_t)
        // cos(theta_m) = sin(theta_h) sin(theta_m), decreasing in theta_h; bisection.
        let cos_t = |theta_h: f64| {
            let s = theta_h.sin() / eta;
            ((1.0 - s) * (1.0 + s)).max(0.0).sqrt()
        };
        let g = |theta_h: f64| eta * cos_t(theta_h) * cos_m - theta_h.sin() * sin_m;
        let top = critical.unwrap_or(FRAC_PI_2);
        let refracted_entry = (g(top) < 0.0).then(|| bisect(0.0, top, 60, |t| g(t) > 0.0));
        let mut breaks = vec![0.0, FRAC_PI_2, entry];
        let mut singular = vec![entry];
        if let Some(c) = critical {
            breaks.push(c);
            singular.push(c);
        }
        if let Some(e) = refracted_entry {
            breaks.push(e);
            singular.push(e);
        }
        // (The views' masking layer, ~alpha wide in o.z, lies along theta_h = pi / 2 - theta_m
        // and reaches pi / 2; a ladder of breaks toward it doubled the evaluations and changed
        // no result on the test grids by more than the stated error: the rule finds it.)
        tidy(&mut breaks, 0.0, FRAC_PI_2);
        let middle_pieces = pieces(&breaks, &singular);

        let inner_tolerance = middle_tolerance;
        let mut over_theta_h = |theta_h: f64| -> [f64; 4] {
            let (sin_h, cos_h) = theta_h.sin_cos();
            let a = cos_h * cos_m;
            let b = sin_h * sin_m;
            let refracts = critical.is_none_or(|c| theta_h < c);
            let (mut breaks, lower) = azimuth_breaks(
                (a, b, cos_m),
                (alpha, eta),
                cos_t(theta_h),
                refracts,
                convention,
            );
            tidy(&mut breaks, lower, PI);
            if breaks.len() < 2 {
                return [0.0; 4];
            }
            let slice = Slice {
                ndf,
                masking,
                m,
                sin_h,
                cos_h,
                eta,
                convention,
            };
            let q = integrate_pieces_batch(
                &mut |nodes: &[f64; KRONROD_NODES], values: &mut [[f64; 4]; KRONROD_NODES]| {
                    values.copy_from_slice(&slice.values_at(nodes)[..KRONROD_NODES]);
                },
                &breaks,
                inner_tolerance,
                max_intervals,
            );
            evaluations += q.evaluations;
            converged &= q.converged;
            let w = sin_h * cos_h;
            [w * q.value[0], w * q.value[1], w * q.value[2], w * q.error]
        };
        let middle = integrate_mapped(
            &mut over_theta_h,
            &middle_pieces,
            middle_tolerance / 2.0,
            max_intervals,
        );
        converged &= middle.converged;
        [
            weight * middle.value[0],
            weight * middle.value[1],
            weight * middle.value[2],
            weight * (middle.error + middle.value[3]),
        ]
    };
    let outer = integrate_pieces(
        &mut over_theta_m,
        &outer_breaks,
        tolerance / 2.0,
        max_intervals,
    );
    DielectricReference::from_outer(&outer, 1.0, evaluations, converged)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The slice's lanes against [`crate::model::dielectric::scattering_at_cos`] one view at a
    /// time, bit for bit, and the AVX2 build against the portable one; views on both sides of
    /// the horizon, through total internal reflection.
    #[test]
    fn the_slice_lanes_give_the_scalar_integrand() {
        use crate::model::Ggx;
        use crate::model::dielectric::scattering_at_cos;
        let ndf = Ggx { alpha: 0.3 };
        let (sin_m, cos_m) = 0.7_f64.sin_cos();
        let m = Vec3::new(sin_m, 0.0, cos_m);
        for eta in [1.0 / 1.5, 1.5] {
            for cos_h in [0.1, 0.5] {
                let sin_h = (1.0_f64 - cos_h * cos_h).sqrt();
                let slice = Slice {
                    ndf,
                    masking: Masking::Separable,
                    m,
                    sin_h,
                    cos_h,
                    eta,
                    convention: TransmissionConvention::SingleScattering,
                };
                let nodes: [f64; KRONROD_NODES] = std::array::from_fn(|k| 0.2 * k as f64);
                let mut o = [m; LANES];
                for (k, o) in o.iter_mut().enumerate() {
                    let (sin_p, cos_p) = nodes[k % KRONROD_NODES].sin_cos();
                    *o = Vec3::new(
                        cos_h * sin_m + sin_h * cos_p * cos_m,
                        sin_h * sin_p,
                        cos_h * cos_m - sin_h * cos_p * sin_m,
                    );
                }
                let lanes = slice_lanes(&slice, &o);
                // From the nodes, with the lane-wise sin and cos: the same within rounding,
                // and the AVX2 build gives the portable build's bits.
                let from_nodes = slice_values(&slice, &nodes);
                for k in 0..LANES {
                    for c in 0..3 {
                        let (got, want) = (from_nodes[k][c], lanes[k][c]);
                        assert!((got - want).abs() <= 1e-13 * want.abs(), "{got} vs {want}");
                    }
                }
                #[cfg(target_arch = "x86_64")]
                if std::arch::is_x86_feature_detected!("avx2") {
                    // SAFETY: checked on the line above.
                    let simd = unsafe { slice_values_avx2(&slice, &nodes) };
                    assert_eq!(
                        simd.map(|v| v.map(f64::to_bits)),
                        from_nodes.map(|v| v.map(f64::to_bits))
                    );
                }
                assert!(o.iter().any(|o| o.z <= 0.0) && o.iter().any(|o| o.z > 0.0));
                for k in 0..LANES {
                    let want = if o[k].z <= 0.0 {
                        [0.0; 4]
                    } else {
                        let lambda_o = ndf.lambda(o[k]);
                        let g1 = 1.0 / (1.0 + lambda_o);
                        let s = scattering_at_cos(
                            ndf,
                            Masking::Separable,
                            o[k],
                            lambda_o,
                            m,
                            cos_h,
                            eta,
                            TransmissionConvention::SingleScattering,
                        );
                        [g1 * s.reflection, g1 * s.transmission, g1 * s.loss, 0.0]
                    };
                    assert_eq!(
                        lanes[k].map(f64::to_bits),
                        want.map(f64::to_bits),
                        "lane {k}"
                    );
                }
            }
        }
    }

    /// Each way of mapping a piece integrates polynomials and the square roots at its ends to
    /// their closed forms, within the rule's own estimate: a wrong point or Jacobian would not.
    #[test]
    fn every_mapping_integrates_to_the_closed_form() {
        let (a, b): (f64, f64) = (0.3, 1.7);
        let exact = [
            (b * b * b - a * a * a) / 3.0,
            2.0 / 3.0 * (b - a).powf(1.5),
            2.0 / 3.0 * (b - a).powf(1.5),
        ];
        for ends in [
            Ends::Plain,
            Ends::SquareRootAtStart,
            Ends::SquareRootAtEnd,
            Ends::SquareRootAtBoth,
        ] {
            let q = integrate_mapped(
                &mut |x: f64| [x * x, (x - a).max(0.0).sqrt(), (b - x).max(0.0).sqrt(), 0.0],
                &[Piece { a, b, ends }],
                1e-10,
                200,
            );
            for (k, want) in exact.into_iter().enumerate() {
                assert!(
                    (q.value[k] - want).abs() <= q.error + 1e-14,
                    "{ends:?} component {k}: {} against {want}, error {:e}",
                    q.value[k],
                    q.error
                );
            }
        }
        // Several pieces at once, each in its own share of the variable.
        let q = integrate_mapped(
            &mut |x: f64| [x, 0.0, 0.0, 0.0],
            &pieces(&[0.0, 0.5, 2.0], &[0.5]),
            1e-12,
            200,
        );
        assert!((q.value[0] - 2.0).abs() < 1e-12, "{}", q.value[0]);
    }
}
