//! The deterministic reference: `E`, `1 - E` and `E_avg` by nested adaptive Gauss-Kronrod
//! quadrature, with an error estimate beside each value.
//!
//! Parametrisation (`docs/physics.md`, "A deterministic reference"): microfacet normals `m` by azimuth
//! `phi in [0, pi]` (the integrand is symmetric under `phi -> -phi`; the result is doubled) and
//! `x = ln(tan(theta_m) / alpha)`, in which the normal distribution's peak has the same width at
//! every `alpha`. For a fixed `phi` the reflected direction `i = 2 (o.m) m - o` crosses the horizon
//! at `theta*(phi) = (pi - atan2(mu, sqrt(1 - mu^2) cos(phi))) / 2`, and `m` stops being visible at
//! `o.m = 0`. The `x` integral is split at both, so that each piece is smooth:
//!
//! - piece A (`i` above the horizon): `E` gathers `D(m) (o.m) G2(o, i) / mu`, and `1 - E` gathers
//!   `D(m) (o.m) / (mu (1 + Lambda(o))) * loss`, with `loss = 1 - G2 / G1(o)` computed without
//!   cancellation ([`Masking::loss`]);
//! - piece B (`m` visible, `i` below the horizon): only `1 - E` gathers, with `loss = 1`.
//!
//! The tails are integrated in the logistic of `x`, `s = t / (alpha + t)` (`t = tan(theta_m)`,
//! `dx = ds / (s (1 - s))`), which maps the whole line onto `[0, 1]` with nothing cut off: below
//! the peak (`x < 0`, where the integrand goes as `e^(2x)`, i.e. `s^2`) and over piece B (the bare
//! distribution, whose GGX tail goes as `e^(-x)`, i.e. `1 - s`), both polynomial in `s`. Piece A
//! above the peak stays in `x`: there the masking loss has its layer at the horizon curve, which
//! `s` would squeeze into the last thousandth of the range at a grazing view. Where `s` is used the
//! integrand needs no exponential, and a table costs 35 to 45 % fewer evaluations than with `x`
//! throughout (cut to a range the tolerance needs).
//!
//! `1 - E` so becomes an integral of its own (by the visible-normal normalisation
//! `∫ (o.m)+ D dω = mu (1 + Lambda(o))`), never `1 - E` subtracted. `G1(o) / mu` is evaluated as
//! `1 / projected_area(mu)`, which stays finite at `mu = 0`.
//!
//! `E_avg = ∫_0^1 2 mu E(mu) dmu` integrates the inner result over `mu`, with breaks at
//! `alpha / 16, alpha / 4, alpha, 4 alpha` where `E` has its grazing boundary layer.
//!
//! The integrand is evaluated a whole 15-point rule at a time
//! ([`integrate_pieces_batch`]), in stages over arrays of lanes with selects for branches, and
//! compiled a second time for AVX2 (picked at run time; both builds give the same bits). The
//! normals and their density per unit of the variable come in closed form from the
//! distribution ([`MicrofacetDistribution::polar_lanes_in_s`], one division and one root), `x`'s
//! exponential from [`exp_lane`], `Lambda(i)` from the reflected direction's components, and
//! each masking's `G2` and loss share a division (numerics version 7; a test holds every lane
//! to the textbook integrand within 1e-12).
//!
//! Error estimates are Gauss-Kronrod's `|K15 - G7|`, summed over intervals and propagated through
//! the nesting (the outer integral adds the integral of the inner estimates). They are pessimistic
//! for these smooth pieces: the tests compare against closed forms to far below the estimate.
//!
//! Where it gives up: each adaptive level has an interval budget ([`ReferenceSettings`]). When a
//! budget runs out the best value is returned with `converged: false` and its error estimate; the
//! caller decides. Outside `alpha` in [1e-3, 2] and `mu` in [1e-6, 1], where the 1e-10 target is
//! tested, the method still runs and reports its own estimate. Below [`SMOOTH_ALPHA`] it works at
//! the similar point ([`smooth_point`]), and `alpha = 0` with `mu > 0` returns the mirror's
//! exact `E = 1`.

use super::gauss_kronrod::{KRONROD_NODES, Quadrature, integrate_pieces, integrate_pieces_batch};
use crate::model::{
    Beckmann, Ggx, Masking, MicrofacetDistribution, Model, Ndf, SMOOTH_ALPHA, Vec3,
    albedo_is_exactly_one, smooth_point,
};
use crate::numerics::elementary::exp_lane;
use serde::Serialize;
use std::f64::consts::PI;

/// Tolerances and budgets of the reference.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReferenceSettings {
    /// The absolute error the result aims for.
    pub tolerance: f64,
    /// Interval budget of each adaptive integral (per level of the nesting).
    pub max_intervals: usize,
}

impl Default for ReferenceSettings {
    /// Aims at 1e-11 so that the result is within 1e-10 with room to spare.
    fn default() -> Self {
        Self {
            tolerance: 1e-11,
            max_intervals: 200,
        }
    }
}

/// A reference value: `E` and `1 - E`, each integrated directly, and the error estimate.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ReferenceValue {
    pub value: f64,
    pub one_minus_value: f64,
    /// The quadrature's error estimate (absolute), for either.
    pub error: f64,
    /// Integrand evaluations spent.
    pub evaluations: u64,
    /// Whether every adaptive integral met its tolerance within its budget.
    pub converged: bool,
}

/// The lowest `x = ln(tan(theta_m) / alpha)` ever integrated: below it both distributions hold
/// less than `exp(-2 * 27)` of their mass. The tolerance narrows the range further.
const X_MIN: f64 = -27.0;
/// The highest `x`: GGX's tail carries `~exp(-x)` beyond it, below 1e-19.
const X_MAX: f64 = 44.0;

/// `E(mu)` by quadrature (see the module docs). `alpha` is the slope-space roughness.
#[must_use]
pub fn reference_albedo(
    model: Model,
    alpha: f64,
    mu: f64,
    settings: &ReferenceSettings,
) -> ReferenceValue {
    assert!((0.0..=1.0).contains(&mu) && alpha >= 0.0 && alpha.is_finite());
    if albedo_is_exactly_one(model, alpha, mu) {
        return MIRROR;
    }
    let (alpha, mu) = smooth_point(alpha, mu);
    finish(quadrature_for(model, alpha, mu, settings))
}

/// A mirror (`alpha = 0`) reflects everything: `E = 1` exactly.
pub(crate) const MIRROR: ReferenceValue = ReferenceValue {
    value: 1.0,
    one_minus_value: 0.0,
    error: 0.0,
    evaluations: 0,
    converged: true,
};

/// `[E, 1 - E]` for the model's distribution at `alpha`.
fn quadrature_for(
    model: Model,
    alpha: f64,
    mu: f64,
    settings: &ReferenceSettings,
) -> Quadrature<2> {
    weighted_quadrature_for(model, alpha, mu, |_| 1.0, Channels::WithLoss, settings)
}

/// `[E_h, 1 - E]` for the model's distribution at `alpha` (see [`reference_weighted_albedo`]),
/// or `[E_h, 0]` with [`Channels::WeightedOnly`].
fn weighted_quadrature_for(
    model: Model,
    alpha: f64,
    mu: f64,
    h: impl Fn(f64) -> f64 + Copy,
    channels: Channels,
    settings: &ReferenceSettings,
) -> Quadrature<2> {
    let masking = model.masking;
    match model.ndf {
        Ndf::Ggx => channels_quadrature(Ggx { alpha }, masking, mu, h, channels, settings),
        Ndf::Beckmann => {
            channels_quadrature(Beckmann { alpha }, masking, mu, h, channels, settings)
        }
    }
}

/// [`albedo_quadrature`] with the channels compiled in (a run-time test inside the integrand
/// cost `E` 4 %).
fn channels_quadrature<N: MicrofacetDistribution>(
    ndf: N,
    masking: Masking,
    mu: f64,
    h: impl Fn(f64) -> f64 + Copy,
    channels: Channels,
    settings: &ReferenceSettings,
) -> Quadrature<2> {
    match channels {
        Channels::WithLoss => albedo_quadrature::<_, true>(ndf, masking, mu, h, settings),
        Channels::WeightedOnly => albedo_quadrature::<_, false>(ndf, masking, mu, h, settings),
    }
}

/// Which integrals a quadrature of the albedo takes: both `E_h` and the loss `1 - E`, or `E_h`
/// alone, so that neither the loss's own piece (the reflection below the horizon, where `E_h`
/// gathers nothing) nor its error estimate costs evaluations that no result uses.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Channels {
    WithLoss,
    WeightedOnly,
}

/// The weighted albedo `E_h(mu) = ∫ f(o, i) h(o.m) mu_i dω_i` (`F = 1` inside `f`, `m` the half
/// vector; see [`crate::integrate::albedo::weighted_albedo`]) by the same quadrature as `E`, with
/// `h` applied to the `E` integrand. `one_minus_value` is `1 - E_h` by subtraction (the weighted
/// integrand has no loss form); `error` is the estimate for the weighted integral, which alone
/// steers the quadrature (no loss integral is taken: numerics version 8).
#[must_use]
pub fn reference_weighted_albedo(
    model: Model,
    alpha: f64,
    mu: f64,
    h: impl Fn(f64) -> f64 + Copy,
    settings: &ReferenceSettings,
) -> ReferenceValue {
    assert!((0.0..=1.0).contains(&mu) && alpha >= 0.0 && alpha.is_finite());
    if alpha == 0.0 && mu > 0.0 {
        let value = h(mu);
        return ReferenceValue {
            value,
            one_minus_value: 1.0 - value,
            ..MIRROR
        };
    }
    if alpha < SMOOTH_ALPHA {
        return weighted_below_smooth(model, alpha, mu, h, settings);
    }
    let q = weighted_quadrature_for(model, alpha, mu, h, Channels::WeightedOnly, settings);
    // A raw value outside [0, 1] is the quadrature's error showing: kept within the range, with
    // the stated error widened to cover the distance (never clamped silently).
    let value = q.value[0].clamp(0.0, 1.0);
    ReferenceValue {
        value,
        one_minus_value: 1.0 - value,
        error: q.error + (q.value[0] - value).abs(),
        evaluations: q.evaluations,
        converged: q.converged,
    }
}

/// `E_h` below [`SMOOTH_ALPHA`], where `E`'s similarity ([`smooth_point`]) does not hold for a
/// weight of `o.h`: every visible normal lies within `O(alpha)` of the normal there, so
/// `o.h = mu + O(alpha)` and `E_h = h(mu) E + O(alpha |h'|)`, with `E` from the similarity. The
/// error adds what that product misses at `SMOOTH_ALPHA` itself ([`weighted_product_deviation`]),
/// which bounds it at every smaller `alpha` (it shrinks with `alpha`). Without this, a weight
/// of `mu` was evaluated at the similar point's `mu * SMOOTH_ALPHA / alpha`: `E_bias(0.1476)`
/// was 0.100 at `alpha = 4e-8` and 0 at 1e-8 instead of `(1 - mu)^5 = 0.450`.
fn weighted_below_smooth(
    model: Model,
    alpha: f64,
    mu: f64,
    h: impl Fn(f64) -> f64 + Copy,
    settings: &ReferenceSettings,
) -> ReferenceValue {
    let e = reference_albedo(model, alpha, mu, settings);
    let value = (h(mu) * e.value).clamp(0.0, 1.0);
    // At alpha = 0 (here with mu = 0: the grazing mirror) the product is the exact limit.
    let deviation = if alpha == 0.0 {
        (0.0, 0)
    } else {
        weighted_product_deviation(model, mu, h, settings)
    };
    ReferenceValue {
        value,
        one_minus_value: 1.0 - value,
        error: e.error + deviation.0,
        evaluations: e.evaluations + deviation.1,
        converged: e.converged,
    }
}

/// `|E_h(mu, SMOOTH_ALPHA) - h(mu) E(mu, SMOOTH_ALPHA)|` plus both quadratures' error
/// estimates, and the evaluations spent: how far the product `h(mu) E` is from `E_h` at the
/// smallest roughness integrated directly (see [`weighted_below_smooth`]).
pub(crate) fn weighted_product_deviation(
    model: Model,
    mu: f64,
    h: impl Fn(f64) -> f64 + Copy,
    settings: &ReferenceSettings,
) -> (f64, u64) {
    let q = weighted_quadrature_for(model, SMOOTH_ALPHA, mu, h, Channels::WeightedOnly, settings);
    let e = reference_albedo(model, SMOOTH_ALPHA, mu, settings);
    (
        (q.value[0] - h(mu) * e.value).abs() + q.error + e.error,
        q.evaluations + e.evaluations,
    )
}

/// `E_avg = 2 ∫ E(mu) mu dmu` by nested quadrature.
#[must_use]
pub fn reference_average_albedo(
    model: Model,
    alpha: f64,
    settings: &ReferenceSettings,
) -> ReferenceValue {
    assert!(alpha >= 0.0 && alpha.is_finite());
    if alpha < SMOOTH_ALPHA {
        return MIRROR;
    }
    // The inner E(mu) integrals get a tenth of the budget each: their errors add up under the
    // outer integral, whose weight 2 mu integrates to 1.
    let inner = ReferenceSettings {
        tolerance: settings.tolerance / 10.0,
        ..*settings
    };
    let mut evaluations = 0;
    let mut converged = true;
    let mut integrand = |mu: f64| {
        let q = quadrature_for(model, alpha, mu, &inner);
        evaluations += q.evaluations;
        converged &= q.converged;
        let w = 2.0 * mu;
        [w * q.value[0], w * q.value[1], w * q.error]
    };
    let mut breaks = vec![0.0];
    for b in [alpha / 16.0, alpha / 4.0, alpha, 4.0 * alpha] {
        if b < 1.0 {
            breaks.push(b);
        }
    }
    breaks.push(1.0);
    let outer = integrate_pieces(
        &mut integrand,
        &breaks,
        settings.tolerance / 2.0,
        settings.max_intervals,
    );
    finish(Quadrature {
        value: [outer.value[0], outer.value[1]],
        error: outer.error + outer.value[2],
        evaluations: evaluations + outer.evaluations,
        converged: converged && outer.converged,
    })
}

/// The reference value of a quadrature of `[E, 1 - E]`: a raw value outside [0, 1] (the
/// quadrature's own error, near a mirror or at grazing) is brought into the range and the
/// stated error widened by the distance, so that the statement still covers the truth.
fn finish(q: Quadrature<2>) -> ReferenceValue {
    let (value, one_minus_value) = (q.value[0].clamp(0.0, 1.0), q.value[1].clamp(0.0, 1.0));
    let moved = (q.value[0] - value)
        .abs()
        .max((q.value[1] - one_minus_value).abs());
    ReferenceValue {
        value,
        one_minus_value,
        error: q.error + moved,
        evaluations: q.evaluations,
        converged: q.converged,
    }
}

/// `[E_h, 1 - E]` with the error estimate, for one distribution (`[E_h, 0]` and the estimate of
/// `E_h` alone without `WITH_LOSS`, [`Channels::WeightedOnly`]).
fn albedo_quadrature<N: MicrofacetDistribution, const WITH_LOSS: bool>(
    ndf: N,
    masking: Masking,
    mu: f64,
    h: impl Fn(f64) -> f64 + Copy,
    settings: &ReferenceSettings,
) -> Quadrature<2> {
    let alpha = ndf.alpha();
    let so = ((1.0 - mu) * (1.0 + mu)).max(0.0).sqrt();
    let o = Vec3::new(so, 0.0, mu);
    let lambda_o = ndf.lambda_from_tan2(if mu == 0.0 {
        f64::INFINITY
    } else {
        (so / mu) * (so / mu)
    });
    // G1(o) / mu, finite at mu = 0.
    let inverse_area = 1.0 / ndf.projected_area(mu);
    // The inner variables (module docs): `x = ln(t / alpha)`, `t = tan(theta_m)`, above the
    // peak in piece A; its logistic `s = t / (alpha + t)` ([`t_of_s`]) below the peak and in
    // piece B.
    let s_of_tan = |tan: f64| {
        if tan.is_finite() {
            tan / (alpha + tan)
        } else {
            1.0
        }
    };
    // Piece A's variable: `u = s` for `x < 0`, `u = 1/2 + x` beyond; `(t, dx/du)` at `u`.
    let u_of_x = |x: f64| if x < 0.0 { s_of_x(x) } else { 0.5 + x };

    let view = View {
        ndf,
        masking,
        mu,
        o,
        lambda_o,
        inverse_area,
    };

    let inner_tolerance = settings.tolerance / (4.0 * PI);
    let mut evaluations = 0;
    let mut all_converged = true;
    let mut over_phi = |phi: f64| -> [f64; 3] {
        let (sin_phi, cos_phi) = phi.sin_cos();
        // Horizon curve of the reflected direction, and the edge of visibility.
        let theta_star = 0.5 * (PI - mu.atan2(so * cos_phi));
        let tan_star = theta_star.tan();
        let s_visible = if cos_phi < 0.0 && so > 0.0 {
            s_of_tan(mu / (so * -cos_phi))
        } else {
            1.0
        };
        let mut above = |nodes: &[f64; KRONROD_NODES], values: &mut [[f64; 2]; KRONROD_NODES]| {
            view.values_at(
                Batch {
                    nodes,
                    piece: Piece::A,
                    cos_phi,
                    sin_phi,
                },
                h,
                values,
            );
            if !WITH_LOSS {
                for value in values.iter_mut() {
                    value[1] = 0.0;
                }
            }
        };
        let x_star = (tan_star / alpha).ln();
        // In place: a small vector moved into an iterator and collected again is a copy of
        // its whole inline buffer (6 % of a bake's time in `memmove` before).
        let mut breaks = horizon_breaks(
            f64::NEG_INFINITY,
            0.0_f64.min(x_star),
            x_star,
            alpha,
            theta_star,
        );
        for x in &mut breaks {
            *x = u_of_x(*x);
        }
        let s_star = s_of_tan(tan_star);
        let a =
            integrate_pieces_batch(&mut above, &breaks, inner_tolerance, settings.max_intervals);
        let mut below = |nodes: &[f64; KRONROD_NODES], values: &mut [[f64; 2]; KRONROD_NODES]| {
            view.values_at(
                Batch {
                    nodes,
                    piece: Piece::B,
                    cos_phi,
                    sin_phi,
                },
                h,
                values,
            );
        };
        let below_breaks: &[f64] = if WITH_LOSS {
            &[s_star, s_visible.max(s_star)]
        } else {
            &[]
        };
        let b = integrate_pieces_batch(
            &mut below,
            below_breaks,
            inner_tolerance,
            settings.max_intervals,
        );
        evaluations += a.evaluations + b.evaluations;
        all_converged &= a.converged && b.converged;
        [a.value[0], a.value[1] + b.value[1], a.error + b.error]
    };
    // The azimuth breaks ([`phi_breaks`]) give the grazing layer near phi = pi / 2 its own
    // intervals.
    let outer = integrate_pieces(
        &mut over_phi,
        &phi_breaks(mu, so),
        settings.tolerance / 4.0,
        settings.max_intervals,
    );
    Quadrature {
        value: [2.0 * outer.value[0], 2.0 * outer.value[1]],
        error: 2.0 * (outer.error + outer.value[2]),
        evaluations: evaluations + outer.evaluations,
        converged: all_converged && outer.converged,
    }
}

/// Lanes of one batch of the integrand: a rule's [`KRONROD_NODES`] padded to a multiple of the
/// SIMD width (four `f64` with AVX2).
const LANES: usize = 16;

/// What the integrand needs of the view `o = (so, 0, mu)` at every normal.
struct View<N> {
    ndf: N,
    masking: Masking,
    mu: f64,
    o: Vec3,
    /// `Lambda(o)`.
    lambda_o: f64,
    /// `G1(o) / mu = 1 / (mu (1 + Lambda(o)))`.
    inverse_area: f64,
}

/// The two pieces of the `x` integral at one azimuth (module docs), each with its variable.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Piece {
    /// The reflection above the horizon: `u = s` below the peak (`u < 1/2`), `u = 1/2 + x`
    /// beyond.
    A,
    /// The reflection below the horizon, the normal still visible: `s` throughout.
    B,
}

/// One rule's nodes in a piece's variable, at one azimuth.
#[derive(Clone, Copy)]
struct Batch<'a> {
    nodes: &'a [f64; KRONROD_NODES],
    piece: Piece,
    cos_phi: f64,
    sin_phi: f64,
}

impl<N: MicrofacetDistribution> View<N> {
    /// `[E part, 1 - E part]` per unit of the piece's variable at one rule's nodes, at azimuth
    /// `phi`: in piece A `D (o.m) G2 / mu h(o.m)` and `D (o.m) / (mu (1 + Lambda(o))) loss`; in
    /// piece B (and wherever the reflection falls below the horizon) `[0, D (o.m) / (mu (1 +
    /// Lambda(o)))]`, every visible normal losing all it reflects.
    #[inline(always)]
    fn values_at(
        &self,
        batch: Batch,
        h: impl Fn(f64) -> f64 + Copy,
        values: &mut [[f64; 2]; KRONROD_NODES],
    ) {
        self.values_with(batch, h, values, true);
    }

    /// [`View::values_at`], compiled for AVX2 where the CPU has it if `allow_avx2` (the portable
    /// build otherwise, for the test that the two agree bit for bit).
    #[inline(always)]
    fn values_with(
        &self,
        batch: Batch,
        h: impl Fn(f64) -> f64 + Copy,
        values: &mut [[f64; 2]; KRONROD_NODES],
        allow_avx2: bool,
    ) {
        let (mu, alpha, lambda_o) = (self.mu, self.ndf.alpha(), self.lambda_o);
        let inverse_area = self.inverse_area;
        let area = 1.0 / inverse_area;
        // `(G2 / mu, loss)` from `i.z` and `Lambda(i)`, one masking form per loop.
        match self.masking {
            // G2 / mu = 1 / (mu (1 + Lo) + mu Li).
            Masking::HeightCorrelated => self.lanes(
                batch,
                h,
                values,
                allow_avx2,
                #[inline(always)]
                move |_iz, lambda_i| {
                    // One division for both: the loss `Li / (1 + Lo + Li)` is `mu Li G2 / mu`
                    // ([`Masking::loss`]'s limits as selects: 1 for a horizontal `i`, 0 for a
                    // view on the horizon).
                    let g2_over_mu = 1.0 / (area + mu * lambda_i);
                    let loss = if lambda_i == f64::INFINITY {
                        if lambda_o == f64::INFINITY { 0.0 } else { 1.0 }
                    } else {
                        mu * lambda_i * g2_over_mu
                    };
                    (g2_over_mu, loss)
                },
            ),
            Masking::Separable => self.lanes(
                batch,
                h,
                values,
                allow_avx2,
                #[inline(always)]
                move |_iz, lambda_i| {
                    // G1(i) = 1 / (1 + Li) once for both; the loss `1 - G1(i)` is `Li G1(i)`
                    // (1 for a horizontal `i`, [`Masking::loss`]).
                    let g1_i = 1.0 / (1.0 + lambda_i);
                    let loss = if lambda_i == f64::INFINITY {
                        1.0
                    } else {
                        lambda_i * g1_i
                    };
                    (inverse_area * g1_i, loss)
                },
            ),
            // G1_S(o) G1_S(i) / mu = G1_S(i) / (mu (1 - k) + k), k = alpha / 2.
            Masking::SchlickGgx => self.lanes(
                batch,
                h,
                values,
                allow_avx2,
                #[inline(always)]
                move |iz, lambda_i| {
                    (
                        Masking::schlick_g1(iz, alpha) / (mu * (1.0 - 0.5 * alpha) + 0.5 * alpha),
                        Masking::SchlickGgx.loss_at(alpha, mu, iz, lambda_o, lambda_i),
                    )
                },
            ),
        }
    }

    /// [`View::values_at`] with the masking's terms given, compiled for AVX2 where the CPU has
    /// it. The result is bit-identical either way: the same IEEE operations in the same order per
    /// lane (Rust never fuses a multiply and an add on its own), several lanes at a time.
    #[inline(always)]
    fn lanes(
        &self,
        batch: Batch,
        h: impl Fn(f64) -> f64 + Copy,
        values: &mut [[f64; 2]; KRONROD_NODES],
        allow_avx2: bool,
        masking_terms: impl Fn(f64, f64) -> (f64, f64) + Copy,
    ) {
        #[cfg(target_arch = "x86_64")]
        if allow_avx2 && std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports AVX2, checked on the line above.
            return unsafe { lanes_avx2(self, batch, h, values, masking_terms) };
        }
        lanes_portable(self, batch, h, values, masking_terms);
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn lanes_avx2<N: MicrofacetDistribution>(
    view: &View<N>,
    batch: Batch,
    h: impl Fn(f64) -> f64 + Copy,
    values: &mut [[f64; 2]; KRONROD_NODES],
    masking_terms: impl Fn(f64, f64) -> (f64, f64) + Copy,
) {
    lanes_portable(view, batch, h, values, masking_terms);
}

/// The loops over lanes of [`View::values_at`]: in stages over arrays of lanes, each a loop
/// simple enough to vectorise (no calls, no branch but selects). The rule's 15 nodes are padded
/// to [`LANES`] with a copy of the first, whose result is dropped.
#[inline(always)]
fn lanes_portable<N: MicrofacetDistribution>(
    view: &View<N>,
    batch: Batch,
    h: impl Fn(f64) -> f64 + Copy,
    values: &mut [[f64; 2]; KRONROD_NODES],
    masking_terms: impl Fn(f64, f64) -> (f64, f64) + Copy,
) {
    let Batch {
        nodes,
        piece,
        cos_phi,
        sin_phi,
    } = batch;
    // The normals and their density per unit of the piece's variable: piece A above the peak
    // in `x` (a rule's nodes all lie on one side of the peak, a break: the centre tells),
    // through the lane-wise `exp`; `s` elsewhere.
    let polar = if piece == Piece::A && nodes[0] >= 0.5 {
        let mut exp_x = [0.0; LANES];
        for k in 0..LANES {
            exp_x[k] = exp_lane((nodes[k % KRONROD_NODES] - 0.5).max(0.0));
        }
        view.ndf.polar_lanes_in_x(&exp_x)
    } else {
        let mut s = [0.0; LANES];
        for k in 0..LANES {
            s[k] = nodes[k % KRONROD_NODES];
        }
        view.ndf.polar_lanes_in_s(&s)
    };
    let mut om = [0.0; LANES];
    let mut weight = [0.0; LANES];
    let mut counts = [false; LANES];
    let mut iz = [0.0; LANES];
    let mut xy2_i = [0.0; LANES];
    for k in 0..LANES {
        // The normal, and `D(m) sin^2 cos (o.m) dx/dv` (`dω_m = sin^2 cos dx dphi`); nothing
        // where the normal faces away from the view (or where the node rounds onto an end of
        // its range, which the density makes 0).
        let sin_t = polar.sin[k];
        let m = Vec3::new(sin_t * cos_phi, sin_t * sin_phi, polar.cos[k]);
        om[k] = view.o.dot(m);
        weight[k] = polar.density[k] * om[k];
        counts[k] = om[k] > 0.0;
        let i = view.o.reflect(m);
        iz[k] = i.z;
        xy2_i[k] = i.x * i.x + i.y * i.y;
    }
    if piece == Piece::B {
        for k in 0..KRONROD_NODES {
            values[k] = [
                0.0,
                if counts[k] {
                    weight[k] * view.inverse_area
                } else {
                    0.0
                },
            ];
        }
        return;
    }
    let lambda_i = view.ndf.lambdas_of_directions(&xy2_i, &iz);
    let inverse_area = view.inverse_area;
    let mut out = [[0.0; 2]; LANES];
    for k in 0..LANES {
        let (g2_over_mu, loss) = masking_terms(iz[k], lambda_i[k]);
        let escapes = iz[k] <= 0.0;
        let e = if escapes {
            0.0
        } else {
            weight[k] * g2_over_mu * h(om[k].min(1.0))
        };
        let lost = if escapes {
            weight[k] * inverse_area
        } else {
            weight[k] * inverse_area * loss
        };
        out[k] = if counts[k] { [e, lost] } else { [0.0, 0.0] };
    }
    values.copy_from_slice(&out[..KRONROD_NODES]);
}

/// The `x = ln(tan(theta_m) / alpha)` range a tolerance needs. Below `x` the projected normals
/// hold about `exp(2 x)` of the mass (`tan^2 / alpha^2` near the peak's foot), above it GGX's tail
/// holds about `2 alpha exp(-x)` (Beckmann far less): cut where each is a hundredth of the
/// tolerance, within the hard limits. At loose tolerances this spares the adaptive rule most of
/// its splits (a 1e-6 table costs 40 % less); at 1e-11 the range is [-15, 30]. The dielectric
/// quadrature's range ([`super::dielectric`]); `E`'s own integrates its tails in `s` instead.
pub(crate) fn x_range(alpha: f64, tolerance: f64) -> (f64, f64) {
    let x_min = (0.5 * (tolerance * 0.01).ln()).max(X_MIN);
    let x_max = (100.0 * alpha.max(1.0) / tolerance).ln().min(X_MAX);
    (x_min, x_max)
}

/// The logistic of `x = ln(t / alpha)`: `s = t / (alpha + t)` (module docs).
pub(crate) fn s_of_x(x: f64) -> f64 {
    1.0 / (1.0 + (-x).exp())
}

/// `(t, dx/ds)` at `s = t / (alpha + t)`: `t = alpha s / (1 - s)`, `dx/ds = 1 / (s (1 - s))`.
pub(crate) fn t_of_s(s: f64, alpha: f64) -> (f64, f64) {
    (alpha * s / (1.0 - s), 1.0 / (s * (1.0 - s)))
}

/// A short list of breaks or rungs, inline (no allocation) up to the lengths the ladders reach
/// at `alpha = 1e-4`, where the inner integrals run once per azimuth node.
pub(crate) type Breaks = smallvec::SmallVec<[f64; 24]>;

/// Distances of a geometric ladder of breaks closing in on a masking layer of width `layer` (in
/// `x`): from a sixteenth of it, four times further each rung, below `limit`, so that every
/// scale between the layer and the piece has intervals of its own.
#[inline]
pub(crate) fn ladder(layer: f64, limit: f64) -> Breaks {
    let mut rungs = Breaks::new();
    let mut distance = layer.abs() / 16.0;
    while distance > 0.0 && distance < limit {
        rungs.push(distance);
        distance *= 4.0;
    }
    rungs
}

/// Breaks of piece A's `x` range `[x_min, x_star]`: the peak, then a geometric ladder closing in
/// on the horizon curve `x_star`. Just below it the reflected direction grazes the horizon and
/// the masking loss climbs from ~0 to 1 within an angle ~`alpha` of the horizon, a tilt of
/// `alpha / 2` of the normal, `~alpha / sin(2 theta*)` in `x`: at `alpha = 1e-4`, `mu = 1` a layer
/// of 1e-4 at the end of an interval of 9, which Gauss-Kronrod's nodes straddle and its error
/// estimate does not see (it carried `1.3e-12`, 10x the requested tolerance, of `1 - E = 1.00013e-8`,
/// while the estimate claimed under 1e-13). The ladder starts at a sixteenth of the layer and
/// grows 4x per break up to the peak, so every scale has intervals of its own.
#[inline]
pub(crate) fn horizon_breaks(
    x_min: f64,
    peak: f64,
    x_star: f64,
    alpha: f64,
    theta_star: f64,
) -> Breaks {
    let mut breaks = Breaks::new();
    breaks.extend([x_min, peak]);
    let layer = alpha / (2.0 * theta_star).sin().max(1e-300);
    let rungs = ladder(layer, x_star - peak);
    breaks.extend(rungs.iter().rev().map(|d| x_star - d));
    breaks.push(x_star);
    breaks
}

/// Breaks of the azimuth range `[0, pi]` for a view `(so, 0, mu)`. Near `phi = pi / 2` the
/// horizon curves and the edge of visibility swing across the whole `x` range within
/// `|cos(phi)| ~ mu / so` (the edge of visibility runs off to `theta = pi / 2` on one side; the
/// horizon curve drops from near `pi / 2` to near `mu / 2`). At grazing views that is a layer far
/// narrower than the first intervals, which an error estimate can miss: break the range at a
/// geometric ladder of distances from `pi / 2`, from `mu / so` up to 0.3, so every scale has
/// intervals of its own.
pub(crate) fn phi_breaks(mu: f64, so: f64) -> Vec<f64> {
    let mut breaks = vec![0.0, PI / 2.0, PI];
    if so > 0.0 && mu > 0.0 {
        let mut delta = mu / so;
        while delta < 0.3 {
            if delta > 1e-15 {
                breaks.push((-delta).acos());
                breaks.push(delta.acos());
            }
            delta *= 8.0;
        }
    }
    breaks.sort_by(f64::total_cmp);
    breaks
}

#[cfg(test)]
mod tests {
    use super::*;

    const HC: Masking = Masking::HeightCorrelated;

    #[test]
    fn closed_form_and_check_values() {
        let s = ReferenceSettings::default();
        let ggx = Model {
            ndf: Ndf::Ggx,
            masking: HC,
        };
        let r = reference_albedo(ggx, 1.0, 1.0, &s);
        assert!(
            (r.value - (1.0 - std::f64::consts::LN_2)).abs() < 1e-12,
            "{r:?}"
        );
        assert!(
            (r.one_minus_value - std::f64::consts::LN_2).abs() < 1e-12,
            "{r:?}"
        );
        assert!(r.converged && r.error < 1e-10);
        let r = reference_albedo(ggx, 0.5, 0.5, &s);
        assert!((r.value - 0.698_250_70).abs() < 5e-9, "{r:?}");
    }
}

#[cfg(test)]
mod bound_tests {
    use super::*;
    use crate::model::{Masking, Ndf};

    /// The stated error is a bound: at a tolerance of 1e-9, the difference from the same
    /// integral at 1e-14 is within the error the coarse result states, on a grid of both NDFs
    /// and maskings (Beckmann, alpha 1, mu 0.414 understated by 4x before the safety factor).
    #[test]
    fn the_stated_error_bounds_the_actual_error() {
        let coarse = ReferenceSettings {
            tolerance: 1e-9,
            ..ReferenceSettings::default()
        };
        let fine = ReferenceSettings {
            tolerance: 1e-14,
            max_intervals: 2000,
        };
        let mut worst: f64 = 0.0;
        for ndf in [Ndf::Ggx, Ndf::Beckmann] {
            for masking in [Masking::HeightCorrelated, Masking::Separable] {
                let model = Model { ndf, masking };
                for alpha in [0.01, 0.1, 0.3, 0.6, 1.0, 1.5] {
                    for mu in [0.0, 1e-3, 0.05, 0.2, 0.414, 0.7, 1.0] {
                        let c = reference_albedo(model, alpha, mu, &coarse);
                        let f = reference_albedo(model, alpha, mu, &fine);
                        let actual = (c.one_minus_value - f.one_minus_value).abs();
                        let ratio = actual / c.error.max(1e-300);
                        worst = worst.max(ratio);
                        assert!(
                            actual <= c.error + 1e-15,
                            "{model:?} alpha {alpha} mu {mu}: actual {actual:e} > stated {:e}",
                            c.error
                        );
                    }
                }
            }
        }
        assert!(worst > 0.0);
    }

    /// At `mu = 1` the azimuth drops out and `1 - E = alpha^2 / (1 + alpha^2) + ∫_0^1 alpha^2 /
    /// (alpha^2 + t)^2 L(t) dt` over `t = tan^2(theta_m)`, with `L = Lambda_i / (1 + Lambda_i)`
    /// for the reflection at `tan(theta_i) = 2 sqrt(t) / (1 - t)` (both maskings agree, since
    /// `Lambda(o) = 0`). Values from that 1-D integral in 40-digit arithmetic (mpmath `quad`,
    /// split at `alpha^2` and at `1 - 10 alpha ... 1 - alpha / 100`). The layer where the
    /// reflection grazes the horizon carries `1.3e-12` at `alpha = 1e-4`; before the reference
    /// split its `x` range there, it returned `1.000002e-8` with an error estimate under 1e-13.
    #[test]
    fn the_horizon_layer_at_normal_incidence() {
        let s = ReferenceSettings {
            tolerance: 1e-13,
            max_intervals: 400,
        };
        for masking in [Masking::HeightCorrelated, Masking::Separable] {
            let model = Model {
                ndf: Ndf::Ggx,
                masking,
            };
            for (alpha, truth) in [
                (1e-4, 1.000_133_582_140_07e-8),
                (1e-3, 1.001_351_303_056_96e-6),
            ] {
                let r = reference_albedo(model, alpha, 1.0, &s);
                let actual = (r.one_minus_value - truth).abs();
                assert!(
                    actual <= r.error && actual < 1e-14,
                    "{masking} alpha {alpha}: {r:?}, truth {truth:e}, off by {actual:e}"
                );
            }
        }
    }

    /// An estimate pushed out of [0, 1] by its own error is brought back with its error widened
    /// by the distance, not clamped silently.
    #[test]
    fn a_raw_value_outside_the_range_widens_the_error() {
        let r = finish(Quadrature {
            value: [1.0 + 3e-9, -3e-9],
            error: 1e-10,
            evaluations: 1,
            converged: true,
        });
        assert_eq!((r.value, r.one_minus_value), (1.0, 0.0));
        assert!(r.error >= 3e-9, "{r:?}");
    }
}

#[cfg(test)]
mod lane_tests {
    use super::*;

    /// The integrand per unit `x` and `phi`, written from the textbook forms: `D(m)` from
    /// `cos(theta_m)`, `G2` from both `Lambda`s, `dω_m = sin^2 cos dx dphi`, `m` from `theta_m`
    /// by `atan`. `[E part, 1 - E part]`, with `1 - E` as `D (o.m) (G1(o) - G2) / mu` where the
    /// reflection is above the horizon and `D (o.m) G1(o) / mu` where it is not.
    fn textbook<N: MicrofacetDistribution>(
        ndf: N,
        masking: Masking,
        mu: f64,
        t: f64,
        phi: f64,
    ) -> [f64; 2] {
        let theta = t.atan();
        let m = Vec3::new(
            theta.sin() * phi.cos(),
            theta.sin() * phi.sin(),
            theta.cos(),
        );
        let o = Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
        let om = o.dot(m);
        if om <= 0.0 {
            return [0.0, 0.0];
        }
        let per_x = ndf.d(m.z) * theta.sin().powi(2) * m.z * om / mu;
        let g1_o = ndf.g1(o);
        let i = m * (2.0 * om) - o;
        if i.z <= 0.0 {
            return [0.0, per_x * g1_o];
        }
        let g2 = match masking {
            Masking::SchlickGgx => {
                Masking::schlick_g1(mu, ndf.alpha()) * Masking::schlick_g1(i.z, ndf.alpha())
            }
            _ => masking.g2(ndf.lambda(o), ndf.lambda(i)),
        };
        [per_x * g2, per_x * (g1_o - g2)]
    }

    /// Every lane of one batch, in piece A's variable on both sides of the peak (`u < 1/2` in
    /// `s`, beyond in `x`) and in piece B's `s`, against the textbook integrand at the same
    /// normal divided by `dx/dv`; and the AVX2 build against the portable one, bit for bit.
    #[test]
    fn the_lanes_agree_with_the_textbook_integrand() {
        fn check<N: MicrofacetDistribution>(ndf: N) {
            let alpha = ndf.alpha();
            for masking in [
                Masking::HeightCorrelated,
                Masking::Separable,
                Masking::SchlickGgx,
            ] {
                for mu in [0.05_f64, 0.4, 0.9] {
                    let so = ((1.0 - mu) * (1.0 + mu)).sqrt();
                    let view = View {
                        ndf,
                        masking,
                        mu,
                        o: Vec3::new(so, 0.0, mu),
                        lambda_o: ndf.lambda_from_tan2((so / mu).powi(2)),
                        inverse_area: 1.0 / ndf.projected_area(mu),
                    };
                    for phi in [0.3, 1.5, 2.9] {
                        let (sin_phi, cos_phi) = f64::sin_cos(phi);
                        for (piece, a, b) in [
                            (Piece::A, 0.1, 0.5),
                            (Piece::A, 0.5, 2.5),
                            (Piece::B, 0.2, 0.97),
                        ] {
                            let nodes = crate::numerics::gauss_kronrod::tests::nodes_of(a, b);
                            let mut values = [[0.0; 2]; KRONROD_NODES];
                            view.values_at(
                                Batch {
                                    nodes: &nodes,
                                    piece,
                                    cos_phi,
                                    sin_phi,
                                },
                                |_| 1.0,
                                &mut values,
                            );
                            let mut portable = [[0.0; 2]; KRONROD_NODES];
                            let batch = Batch {
                                nodes: &nodes,
                                piece,
                                cos_phi,
                                sin_phi,
                            };
                            view.values_with(batch, |_| 1.0, &mut portable, false);
                            for (k, &v) in nodes.iter().enumerate() {
                                assert_eq!(
                                    values[k].map(f64::to_bits),
                                    portable[k].map(f64::to_bits),
                                    "AVX2 and portable builds differ"
                                );
                                let (t, dx_dv) = if piece == Piece::A && v >= 0.5 {
                                    (alpha * (v - 0.5).exp(), 1.0)
                                } else {
                                    t_of_s(v, alpha)
                                };
                                let mut want = textbook(ndf, masking, mu, t, phi);
                                if piece == Piece::B {
                                    // Every visible normal's reflection counted as lost.
                                    want = [0.0, want[0] + want[1]];
                                }
                                for c in 0..2 {
                                    let got = values[k][c] / dx_dv;
                                    assert!(
                                        (got - want[c]).abs() <= 1e-12 * want[c].abs().max(1e-3),
                                        "{masking} alpha {alpha} mu {mu} phi {phi} v {v}: \
                                         {got:e} vs {:e}",
                                        want[c]
                                    );
                                }
                            }
                        }
                    }
                }
            }
        }
        check(Ggx { alpha: 0.3 });
        check(Ggx { alpha: 1.2 });
        check(Beckmann { alpha: 0.5 });
    }
}
