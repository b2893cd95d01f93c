//! The Beckmann half of the QMC albedo estimators ([`mod@super::albedo`]): how a Beckmann view's
//! points are placed, by strata of its visible x-slope down to the rare slopes whose reflection
//! leaves the hemisphere, or by its reflected directions, or inside the lost circle.

use super::qmc::{MIN_LEVEL_LOG2, Stratum, points_per_level, sum_over_block};
use super::sobol::OwenSobol;
use crate::model::masking::reflection_loss;
use crate::model::ndf::{BeckmannVisibleNormals, VisibleSlopeX};
use crate::model::special::{FRAC_1_SQRT_PI, erfc};
use crate::model::vector::sin_from_cos;
use crate::model::{Beckmann, Masking, MicrofacetDistribution, Vec3};
use crate::numerics::elementary::cos_sin_pi;

/// The unit-roughness slopes the Beckmann sum samples inside the lost circle reach at most this
/// far from 0; the share beyond, under `exp(-27^2) = 1e-317` (below f64's smallest normal
/// number), counts as lost.
const SLOPE_REACH: f64 = 27.0;

/// Below this share the lost slopes cannot matter (their loss is at most the share) and a
/// ladder down to them would only thin out the points elsewhere: at normal incidence on
/// Beckmann alpha = 0.1 (lost share `~1e-45`) its levels left the y-slope's tail to 2^13 points
/// each, and the Schlick-weighted albedo, which grows as the tilt's tenth power, came out 1 %
/// low (6 standard errors).
const NEGLIGIBLE_SHARE: f64 = 1e-20;
/// A Beckmann view is grazing, for the ladder of its height-correlated layer, when the stretched
/// view's `cot(theta) = mu / (alpha so)` is below this (`mu` under a tenth of `alpha`): above
/// it the layer is not rare, and the levels would only thin out the body's points (at alpha =
/// 0.64, mu = 0.49 and 2^13 samples the node error rose from 2e-4 to 1.9e-3).
const GRAZING_COT: f64 = 0.1;
/// Grazing views take the ladder only below this roughness: above it the masking layer's loss
/// is spread over the body of the visible normals (the reflection's `Lambda` matters wherever it
/// leaves within `alpha` of the horizon), and the [`LostCircle`] resolves it better (measured at
/// 2^16 samples, `mu` from 1e-4 to 0.06: at alpha 0.2 the ladder's standard error is 1.2 to 2.8
/// times below the circle's, at 0.3 mixed, from 0.4 the circle's is 2 to 50 times below).
const GRAZING_LADDER_MAX_ALPHA: f64 = 0.25;
/// A view is sampled by its reflected directions ([`BeckmannSampling::Reflection`]) when the
/// lost circle's far end `(1 + so) / (mu alpha)` (the slope of the normal that reflects the view
/// to the horizon on the far side) lies within this many unit-roughness slopes of 0: then the
/// circle's boundary cuts through the body of the visible normals, and the density of the
/// reflected directions varies by at most `exp(2.65^2) ~ 1100` over the hemisphere (measured at
/// 2^16 samples: at alpha 0.7, mu 1 the standard error fell 6.7x, at alpha 1.5, mu 0.99 18x; at
/// a far end of 3 to 4 the circle was the better by up to 2x).
const REFLECTION_MAX_FAR_END: f64 = 2.65;
/// Each level of the ladder holds this fraction of the share above it.
const LADDER_RATIO: f64 = 1.0 / 16.0;
/// At most this many tail levels (the deepest then reaches a share of `0.5 / 16^14 ~ 7e-18`; the
/// last level runs to 0, so nothing is left out, only sampled more thinly).
const MAX_LADDER_LEVELS: usize = 15;

/// The strata of a Beckmann view's visible x-slope, as shares `w` of the slopes above (see
/// [`crate::model::ndf::VisibleSlopeX::upper_share`]): `[1/2, 1]` (the body, half the points), then a ladder of
/// levels each holding a sixteenth of the share above it, down past the share `w_lost` of the
/// slopes whose reflection leaves the hemisphere, then the rest down to 0. At a grazing view of a
/// smooth surface (`mu = 10 alpha`) that share is `~1e-11`: the Gaussian tail's sliver that plain
/// visible-normal sampling never reaches, and where all of `1 - E` lives. Each level then holds its
/// part of the loss in at least a sixteenth of its measure. When the losses are not rare (the
/// lost slopes' share above 1/64) or negligible (below [`NEGLIGIBLE_SHARE`]), one stratum: plain sampling, except at grazing views (the
/// stretched view's `cot(theta) = mu / (alpha so)` below [`GRAZING_COT`]), whose ladder runs down to the slopes
/// within 1 % of their end.
fn beckmann_strata(visible: &BeckmannVisibleNormals, alpha: f64, mu: f64) -> Vec<Stratum> {
    let so = sin_from_cos(mu);
    let lost_slope = (1.0 - so) / (mu * alpha);
    let slopes = visible.slope_x();
    // The stretched view's cot(theta): the visible x-slopes end there.
    let b = mu / (alpha * so);
    let lost_share = if lost_slope.is_finite() {
        slopes.upper_share(lost_slope)
    } else {
        1.0
    };
    let lost = if (NEGLIGIBLE_SHARE..1.0 / 64.0).contains(&lost_share) {
        // The levels above the lost share take in the masking layer below the lost slopes.
        slopes.upper_share(lost_slope)
    } else if b < GRAZING_COT && mu > 0.0 {
        // A grazing view: the reflection's height `mu_i` falls with the distance of the slope
        // from its end `b`, and the height-correlated loss `~mu / (mu + mu_i)` gathers equally
        // from every decade of it, down to `mu_i ~ mu / 100`: rungs down to that slope's share.
        slopes.upper_share(0.99 * b)
    } else {
        return vec![Stratum {
            start: 0.0,
            weight: 1.0,
        }];
    };
    ladder_down_to(lost)
}

/// The ladder of [`beckmann_strata`] over the visible x-slope's share: `[1/2, 1]`, then levels
/// each holding [`LADDER_RATIO`] of the share above, until one starts below `lost` (at most
/// [`MAX_LADDER_LEVELS`]), then the rest down to 0.
fn ladder_down_to(lost: f64) -> Vec<Stratum> {
    let mut strata = vec![Stratum {
        start: 0.5,
        weight: 0.5,
    }];
    let mut top: f64 = 0.5;
    while top >= lost && strata.len() < MAX_LADDER_LEVELS {
        let bottom = top * LADDER_RATIO;
        strata.push(Stratum {
            start: bottom,
            weight: top - bottom,
        });
        top = bottom;
    }
    strata.push(Stratum {
        start: 0.0,
        weight: top,
    });
    strata
}

/// Strata of the visible x-slope's share for rare events in either tail: the body `[1/4, 3/4]`
/// (half the points), then on each side levels each holding [`LADDER_RATIO`] of the share
/// beyond, down to the share `floor` in the upper tail (normals tilted away from the view) and
/// to `max(floor, 1e-12)` in the lower (tilted toward it: the share is `1 - w` there, and `w`
/// near 1 keeps fewer digits), then the rest of each tail.
fn two_sided_ladder(floor: f64) -> Vec<Stratum> {
    let mut strata = vec![Stratum {
        start: 0.25,
        weight: 0.5,
    }];
    for (side_floor, upper) in [(floor, true), (floor.max(1e-12), false)] {
        let mut top: f64 = 0.25;
        while top >= side_floor {
            let bottom = top * LADDER_RATIO;
            let start = if upper { bottom } else { 1.0 - top };
            strata.push(Stratum {
                start,
                weight: top - bottom,
            });
            top = bottom;
        }
        strata.push(Stratum {
            start: if upper { 0.0 } else { 1.0 - top },
            weight: top,
        });
    }
    strata
}

/// What the Beckmann sums need of one view `o = (so, 0, mu)`, set up once per estimate: the
/// visible-normal sampler and how the points are placed ([`BeckmannSampling`]).
pub(crate) struct BeckmannView {
    ndf: Beckmann,
    pub(crate) o: Vec3,
    pub(crate) lambda_o: f64,
    visible: BeckmannVisibleNormals,
    sampling: BeckmannSampling,
}

/// How a Beckmann view's sum places its points.
enum BeckmannSampling {
    /// Inside the slopes whose reflection stays above the horizon ([`LostCircle`]): every view
    /// but the grazing ones of smooth surfaces and the near-normal ones of rough surfaces.
    Circle(LostCircle),
    /// By the reflected direction, uniform over the hemisphere ([`BeckmannView::reflection_sum`]):
    /// views whose lost circle ends within [`REFLECTION_MAX_FAR_END`] slopes of 0.
    Reflection,
    /// By the strata of [`beckmann_strata`] over the visible x-slope's share: grazing views (the
    /// stretched view's `cot(theta)` below [`GRAZING_COT`]) at roughness below
    /// [`GRAZING_LADDER_MAX_ALPHA`], whose masking layer they resolve.
    Ladder(Vec<Stratum>),
}

/// The visible normals of a Beckmann view `o = (so, 0, mu)` whose mirror reflection stays above
/// the horizon, in unit-roughness slopes `(x, y)` (the view's frame, as
/// [`BeckmannVisibleNormals::normal_from_slopes`]): a disc. With slopes `alpha (x, y)`, the
/// normal `m ∝ (-alpha x, -alpha y, 1)` reflects `o` to `i_z = 2 (o.m) m_z - mu`, which is
/// positive iff `(x - c)^2 + y^2 < r^2` with centre `c = -so / (mu alpha)` and radius
/// `r = 1 / (mu alpha)` (expand `2 (mu - alpha x so) > mu (1 + alpha^2 (x^2 + y^2))`). Outside
/// it the loss is 1 exactly, so the sum takes the share outside in closed form
/// ([`VisibleSlopeX::upper_share`]) and samples the inside only: x in `[c - r, c + r]` from a
/// logistic proxy of the visible x-slopes ([`LostCircle::x_slope`]), and for each x the folded
/// y-slope (the view's mirror symmetry) within `|y| < y*(x) = sqrt((right - x)(x - left))` from
/// a half-logistic proxy ([`LostCircle::y_slope`]), each weighted by the true density over the
/// proxy's, with the share beyond `y*` added as `erfc(y*)` (conditional Monte Carlo). The
/// integrand is then smooth inside; the x map goes through the smoothstep `3 v^2 - 2 v^3`,
/// whose zero derivative at both ends undoes the square roots of `y*` at the disc's ends.
#[derive(Clone, Copy, Debug)]
struct LostCircle {
    /// `c - r` and `c + r`.
    left: f64,
    right: f64,
    /// The x-slopes sampled: `[start, start + span]`, the disc's x range within
    /// [`SLOPE_REACH`] of 0.
    start: f64,
    span: f64,
    /// The visible slopes' share outside `[start, start + span]`, all counted as lost.
    lost: f64,
    /// The logistic proxy of the x-slopes' density: its centre, scale, and its CDF at `start`
    /// (`p_start`, and `1 - p_start` as `q_start`) and over the range (`p_span`).
    centre: f64,
    scale: f64,
    p_start: f64,
    q_start: f64,
    p_span: f64,
}

/// The logistic CDF `1 / (1 + exp(-z))`.
fn logistic(z: f64) -> f64 {
    1.0 / (1.0 + (-z).exp())
}

impl LostCircle {
    fn new(slopes: &VisibleSlopeX, alpha: f64, mu: f64) -> Self {
        let so = sin_from_cos(mu);
        // c - r, and c + r as (1 - so) / (mu alpha): no cancellation at near-normal views.
        let (left, right) = (-(so + 1.0) / (mu * alpha), (1.0 - so) / (mu * alpha));
        let start = left.max(-SLOPE_REACH);
        let end = right.min(SLOPE_REACH).max(start);
        // The mode of (b - x) exp(-x^2), the root of 2 x^2 - 2 b x - 1 in the stable form (0 at
        // normal incidence), and a scale near the Gaussian's (standard deviation 0.71 = 0.39 pi /
        // sqrt 3), a little wider for the tilt.
        let b = slopes.end();
        let centre = if b.is_finite() {
            -1.0 / (b + (b * b + 2.0).sqrt())
        } else {
            0.0
        };
        let scale = 0.45;
        let p_start = logistic((start - centre) / scale);
        let q_start = logistic((centre - start) / scale);
        let p_end = logistic((end - centre) / scale);
        Self {
            left,
            right,
            start,
            span: end - start,
            lost: slopes.upper_share(end) + (1.0 - slopes.upper_share(start)),
            centre,
            scale,
            p_start,
            q_start,
            p_span: (p_end - p_start).max(0.0),
        }
    }

    /// The x-slope for the variate `v` in [0, 1] and its density per unit of `v`, `dx/dv`:
    /// `x = centre + scale ln(p / (1 - p))` (the logistic proxy's inverse CDF, which puts the
    /// points where the visible slopes are) with `p` from `p_start` over `p_span` through the
    /// smoothstep `3 v^2 - 2 v^3` (whose zero derivative at both ends undoes the disc ends' square
    /// roots). `1 - p` is carried on its own, so the tails keep their digits.
    #[inline(always)]
    fn x_slope(&self, v: f64) -> (f64, f64) {
        let step = v * v * (3.0 - 2.0 * v);
        let p = self.p_start + self.p_span * step;
        let q = self.q_start - self.p_span * step;
        if !(p > 0.0 && q > 0.0) {
            return (self.start, 0.0);
        }
        let x = (self.centre + self.scale * (p / q).ln()).clamp(self.start, self.start + self.span);
        (x, self.scale / (p * q) * self.p_span * 6.0 * v * (1.0 - v))
    }

    /// The y-slope `|y|` in `[0, reach]` for the variate `v` in [0, 1] and `dy/dv`: the inverse
    /// CDF of the half-logistic proxy `tanh(y / 2 s)` (scale `s` as for x) restricted to the
    /// range, `y = 2 s atanh(v tanh(reach / 2 s))`, smooth up to `reach` and `reach v` when the
    /// reach is short.
    #[inline(always)]
    fn y_slope(&self, reach: f64, v: f64) -> (f64, f64) {
        let two_s = (2.0 * self.scale).max(reach);
        let top = (reach / two_s).tanh();
        let p = v * top;
        let y = (two_s * p.atanh()).min(reach);
        (y, two_s * top / ((1.0 - p) * (1.0 + p)))
    }
}

impl BeckmannView {
    pub(crate) fn new(alpha: f64, mu: f64) -> Self {
        let ndf = Beckmann { alpha };
        let o = Vec3::from_mu(mu);
        let untabulated = BeckmannVisibleNormals::new(ndf.alpha, o);
        // The stretched view's cot(theta): the visible x-slopes end there.
        let grazing = mu <= 0.0
            || (untabulated.slope_x().end() < GRAZING_COT && alpha < GRAZING_LADDER_MAX_ALPHA);
        let far_end = (1.0 + sin_from_cos(mu)) / (mu * alpha);
        let (visible, sampling) = if grazing {
            // The ladder solves for slopes at every point: start it from a table.
            let visible = BeckmannVisibleNormals::tabulated(ndf.alpha, o);
            let strata = beckmann_strata(&visible, alpha, mu);
            (visible, BeckmannSampling::Ladder(strata))
        } else if far_end < REFLECTION_MAX_FAR_END {
            (untabulated, BeckmannSampling::Reflection)
        } else {
            let circle = LostCircle::new(untabulated.slope_x(), alpha, mu);
            (untabulated, BeckmannSampling::Circle(circle))
        };
        Self {
            ndf,
            o,
            lambda_o: ndf.lambda(o),
            visible,
            sampling,
        }
    }

    /// A view whose sum runs by a ladder on both tails of the visible x-slopes
    /// ([`two_sided_ladder`]) whatever the view: for integrands whose rare events are not the
    /// reflection's alone (the dielectric's refraction and total internal reflection,
    /// [`crate::integrate::dielectric`]), which the [`LostCircle`] does not know.
    pub(crate) fn with_ladder(alpha: f64, mu: f64, floor: f64) -> Self {
        let ndf = Beckmann { alpha };
        let o = Vec3::from_mu(mu);
        Self {
            ndf,
            o,
            lambda_o: ndf.lambda(o),
            visible: BeckmannVisibleNormals::tabulated(ndf.alpha, o),
            sampling: BeckmannSampling::Ladder(two_sided_ladder(floor)),
        }
    }

    /// [`BeckmannView::sum`] inside the [`LostCircle`], the share outside in closed form.
    fn circle_sum(
        &self,
        circle: &LostCircle,
        seq: &OwenSobol,
        log2_n: u32,
        integrand: impl Fn(Vec3) -> f64,
    ) -> f64 {
        let slopes = self.visible.slope_x();
        let (left, right) = (circle.left, circle.right);
        let inside = sum_over_block(seq, log2_n, |[v0, v1]: [f64; 2]| {
            let (x, jacobian) = circle.x_slope(v0);
            let jacobian = jacobian * slopes.density(x);
            let reach = ((right - x).max(0.0) * (x - left).max(0.0))
                .sqrt()
                .min(SLOPE_REACH);
            // |y| on [0, reach] from the half-logistic proxy, weighted by its density
            // 2 exp(-y^2) / sqrt(pi) per unit of v1.
            let (y, dy) = circle.y_slope(reach, v1);
            let density = 2.0 * FRAC_1_SQRT_PI * (-y * y).exp();
            let m = self.visible.normal_from_slopes(x, y);
            jacobian * (erfc(reach) + dy * density * integrand(m))
        });
        circle.lost * (1u64 << log2_n) as f64 + inside
    }

    /// [`BeckmannView::sum`] over the reflected directions `i`, uniform over the half of the
    /// upper hemisphere with `i_y >= 0` (the view's mirror symmetry): `i_z = v0`, azimuth
    /// `pi v1`. The reflected directions of the visible normals have the density
    /// `p(i) = G1(o) D(h) / (4 mu)` with `h = (o + i) / |o + i|` (the visible normals' density
    /// `G1(o) max(0, o.h) D(h) / mu` (Heitz 2014, eq. 2) times the reflection's Jacobian
    /// `1 / (4 o.h)`, Walter et al. 2007, eq. 14), so `1 - E = 1 - ∫ p(i) (1 - loss(h)) di`
    /// over the upper hemisphere, the rest (reflections below the horizon) lost. Each point
    /// gives `1 - 2 pi p(i) (1 - integrand(h))`. No boundary lies inside the square: the
    /// integrand is smooth wherever `D` is broad over the hemisphere.
    fn reflection_sum(&self, seq: &OwenSobol, log2_n: u32, integrand: impl Fn(Vec3) -> f64) -> f64 {
        let o = self.o;
        let ndf = self.ndf;
        // 2 pi G1(o) / (4 mu): the weight of D(h) per uniform point.
        let scale = 2.0 * std::f64::consts::PI / (4.0 * o.z * (1.0 + self.lambda_o));
        sum_over_block(seq, log2_n, |[v0, v1]: [f64; 2]| {
            let (cos_phi, sin_phi) = cos_sin_pi(v1);
            let iz = v0;
            let ir = ((1.0 - iz) * (1.0 + iz)).max(0.0).sqrt();
            let h = Vec3::new(o.x + ir * cos_phi, o.y + ir * sin_phi, o.z + iz).normalize();
            1.0 - scale * ndf.d(h.z) * (1.0 - integrand(h))
        })
    }

    /// The loss `1 - w` of the visible normal `m` ([`reflection_loss`]).
    pub(crate) fn loss(&self, masking: Masking, m: Vec3) -> f64 {
        reflection_loss(self.ndf, masking, self.o, self.lambda_o, m)
    }

    /// The sum of `integrand(m)` over the visible normals of one scramble, returned as a sum over
    /// `2^log2_n` points as [`sum_over_block`] does; `integrand` must be 1 wherever the
    /// reflection leaves the hemisphere (a loss). By [`BeckmannSampling`].
    pub(crate) fn sum(&self, seq: &OwenSobol, log2_n: u32, integrand: impl Fn(Vec3) -> f64) -> f64 {
        match &self.sampling {
            BeckmannSampling::Circle(circle) => self.circle_sum(circle, seq, log2_n, integrand),
            BeckmannSampling::Reflection => self.reflection_sum(seq, log2_n, integrand),
            BeckmannSampling::Ladder(strata) => self.ladder_sum(strata, seq, log2_n, integrand),
        }
    }

    /// [`BeckmannView::sum`] by the ladder's strata: the first stratum (the body) gets half the
    /// points, the others share the other half ([`points_per_level`]), each level from its own
    /// stream of the scramble; with fewer than `2^MIN_LEVEL_LOG2` points per level, plain
    /// sampling. Each level draws the x-slope whose upper share is uniform within it
    /// ([`crate::model::ndf::VisibleSlopeX::sample_upper`]); the level means, weighted by their
    /// measure, add up to the integral.
    fn ladder_sum(
        &self,
        strata: &[Stratum],
        seq: &OwenSobol,
        log2_n: u32,
        integrand: impl Fn(Vec3) -> f64,
    ) -> f64 {
        let slopes = self.visible.slope_x();
        let at = |slope_x: f64, u1: f64| integrand(self.visible.normal_from_slope_x(slope_x, u1));
        let tail_levels = strata.len().saturating_sub(1);
        let body_log2 = log2_n.saturating_sub(1);
        if strata.len() == 1 || points_per_level(body_log2, tail_levels, 0) < MIN_LEVEL_LOG2 {
            return sum_over_block(seq, log2_n, |[u0, u1]: [f64; 2]| at(slopes.sample(u0), u1));
        }
        let mut mean = 0.0;
        for (k, stratum) in strata.iter().enumerate() {
            let (stream, log2) = if k == 0 {
                (*seq, body_log2)
            } else {
                (
                    seq.stream(k as u64),
                    points_per_level(body_log2, tail_levels, k - 1),
                )
            };
            let sum = sum_over_block(&stream, log2, |[v0, u1]: [f64; 2]| {
                // A share of exactly 0 or 1 (a level's end, or 1 - tiny rounded up) is an
                // infinite slope: the nearest shares that are not.
                let share = stratum
                    .t(v0)
                    .clamp(f64::MIN_POSITIVE, 1.0 - f64::EPSILON / 2.0);
                at(slopes.sample_upper(share), u1)
            });
            mean += stratum.weight * (sum / (1u64 << log2) as f64);
        }
        mean * (1u64 << log2_n) as f64
    }
}
