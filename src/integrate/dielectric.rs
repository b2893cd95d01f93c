//! The energy albedo of a rough dielectric interface, reflection plus transmission
//! ([`crate::model::dielectric`] for the model and its convention), by QMC and by the
//! deterministic reference.
//!
//! `E_eta(mu) = R + T`: the fraction of the power arriving along a direction with
//! `cos(theta) = mu` that a single scattering event at the interface of relative index `eta`
//! (`n_other / n_view`) sends on, by reflection or by refraction. `E_avg,eta = 2 ∫ E_eta(mu) mu dmu`.
//!
//! QMC: visible-normal sampling as for `E` ([`super::albedo`](mod@super::albedo)), each sample scoring both branches
//! (no Russian roulette between them, so no variance from the choice); `1 - E` is accumulated.
//!
//! Reference: the parametrisation of [`super::reference`] (`phi in [0, pi]`, `x = ln(tan(theta_m)
//! / alpha)`), integrating `[R, T, 1 - E]` together. Each `x` integral is split where the integrand
//! has a kink: the peak (`x = 0`), the reflected direction's horizon (closed form), the critical
//! angle of total internal reflection (`o.m = sqrt(1 - eta^2)` for `eta < 1`, closed form: `o.m =
//! rho cos(theta - delta)` along the `phi` slice), the refracted direction's horizon (found by
//! bisection between sign changes on a scan uniform in `theta_m`) and the edge of visibility.
//! Geometric ladders of breaks close in on the two horizons, whose masking layers are ~`alpha`
//! wide (as `E`'s horizon ladder). The piece below the peak is integrated from `x = -infinity` in
//! `s = t / (alpha + t)`, as in `E`'s reference; above, `x` is cut where GGX's tail holds a
//! hundredth of the tolerance (`super::reference::x_range`).
//!
//! The averages integrate over the microfacet normal first ([`super::dielectric_average`]);
//! [`nested_dielectric_average_albedo_with`], an integral over `mu` of the reference above, is
//! the other order, kept as an independent check.
//!
//! Limits: `alpha = 0` with `mu > 0` is the smooth interface, `R = F(mu)`, `T = 1 - F(mu)`,
//! `E = 1` exactly. Unlike `E`, `E_eta(0)` is not 1 in general (for `eta < 1` refracted directions
//! of a grazing view go up and are lost), so `mu = 0` is integrated like any other point. Between
//! 0 and
//! [`SMOOTH_ALPHA`] the interface is evaluated at `SMOOTH_ALPHA` (the boundary layer `mu ~ alpha`
//! then lies below `mu = 1e-6`; the similarity [`crate::model::smooth_point`] uses for `E` does not
//! hold once `F` depends on `mu`).

use super::albedo::{GgxView, Levels, TAG_DIELECTRIC, TAG_DIELECTRIC_AVG, levels_sum, model_key};
use super::beckmann_albedo::BeckmannView;
use super::dielectric_average::average;
pub use super::dielectric_reference::DielectricReference;
use super::estimate::Estimate;
use super::gauss_kronrod::{KRONROD_NODES, integrate_pieces, integrate_pieces_batch};
use super::qmc::{QmcSettings, replicates, sum_over_block};
use super::reference::{ReferenceSettings, ladder, phi_breaks, s_of_x, t_of_s, x_range};
use crate::model::dielectric::{
    TransmissionConvention, refract, scattering_with, scatterings_at_cos,
};
use crate::model::vector::sin_from_cos;
use crate::model::{
    Beckmann, Ggx, Masking, MicrofacetDistribution, Model, Ndf, SMOOTH_ALPHA, Vec3,
};
use crate::numerics::bisection::bisect;
use crate::numerics::elementary::exp_lane;
use std::f64::consts::PI;

fn check(alpha: f64, mu: f64, eta: f64) {
    assert!((0.0..=1.0).contains(&mu) && alpha >= 0.0 && alpha.is_finite());
    assert!(
        eta > 0.0 && eta.is_finite(),
        "eta must be positive (got {eta})"
    );
}

/// `E_eta(mu)` by QMC for the model at `alpha` (slope-space), `eta = n_other / n_view`.
///
/// # Panics
/// If the settings are invalid or an argument is out of range; callers validate input first.
#[must_use]
pub fn dielectric_albedo(
    model: Model,
    alpha: f64,
    mu: f64,
    eta: f64,
    settings: &QmcSettings,
) -> Estimate {
    dielectric_albedo_with(
        model,
        alpha,
        mu,
        eta,
        TransmissionConvention::SingleScattering,
        settings,
    )
}

/// [`dielectric_albedo`] in the given convention ([`TransmissionConvention`]).
///
/// # Panics
/// As [`dielectric_albedo`].
#[must_use]
pub fn dielectric_albedo_with(
    model: Model,
    alpha: f64,
    mu: f64,
    eta: f64,
    convention: TransmissionConvention,
    settings: &QmcSettings,
) -> Estimate {
    check(alpha, mu, eta);
    if (alpha == 0.0 && mu > 0.0) || convention.smooth_at(eta) {
        return Estimate::exact(0.0);
    }
    let alpha = alpha.max(SMOOTH_ALPHA);
    let key = [
        TAG_DIELECTRIC,
        model_key(model),
        alpha.to_bits(),
        mu.to_bits(),
        eta.to_bits(),
    ];
    let masking = model.masking;
    match model.ndf {
        Ndf::Ggx => {
            let ndf = Ggx { alpha };
            let o = Vec3::from_mu(mu);
            let lambda_o = ndf.lambda(o);
            let levels = dielectric_levels(alpha, mu);
            replicates(settings, &key, |seq, log2_n| {
                levels_sum(seq, log2_n, &levels, |u0, t| {
                    let m = ndf.visible_normal_on_cap(o, u0, t);
                    scattering_with(ndf, masking, o, lambda_o, m, eta, convention).loss
                })
            })
        }
        Ndf::Beckmann => {
            let ndf = Beckmann { alpha };
            let view = BeckmannView::with_ladder(alpha, mu, BECKMANN_FLOOR);
            replicates(settings, &key, |seq, log2_n| {
                view.sum(seq, log2_n, |m| {
                    scattering_with(ndf, masking, view.o, view.lambda_o, m, eta, convention).loss
                })
            })
        }
    }
}

/// The visible x-slope share down to which a Beckmann view's ladder runs
/// ([`BeckmannView::with_ladder`]): the slopes below it hold at most this share of any loss,
/// and each level of the ladder gets its own points down to there.
const BECKMANN_FLOOR: f64 = 1e-16;

/// The strata of a GGX view's cap coordinate for the dielectric: the reflection's
/// ([`GgxView::levels`]: its tail, the rungs around its horizon crossing and the body's) with a
/// ladder of quarters toward the rim merged in, down to `alpha^2 / 100` (at most `1e-3`), where
/// a normal's tilt reaches `tan(theta_m) ~ 10` (`t ~ alpha^2 / tan^2` in the body). The
/// refraction's rare events lie at other tilts than the reflection's: at alpha = 1e-3, mu =
/// 0.7, eta = 1.5, plain visible-normal sampling put `1 - E` at `8.28e-8` with a standard error
/// of `4.2e-13`, the reference `2.92e-7`; at mu = 0, eta = 1/3 (total internal reflection
/// everywhere but the rim's normals facing the view) every scramble of 2^13 points gave 0.
fn dielectric_levels(alpha: f64, mu: f64) -> Levels {
    GgxView::new(alpha, mu, sin_from_cos(mu))
        .levels()
        .with_rim_ladder((alpha * alpha * 1e-2).min(1e-3))
}

/// `E_avg,eta = 2 ∫ E_eta(mu) mu dmu` by QMC, with `s = mu^2` as a third dimension.
///
/// # Panics
/// As [`dielectric_albedo`].
#[must_use]
pub fn dielectric_average_albedo(
    model: Model,
    alpha: f64,
    eta: f64,
    settings: &QmcSettings,
) -> Estimate {
    dielectric_average_albedo_with(
        model,
        alpha,
        eta,
        TransmissionConvention::SingleScattering,
        settings,
    )
}

/// [`dielectric_average_albedo`] in the given convention ([`TransmissionConvention`]).
///
/// # Panics
/// As [`dielectric_albedo`].
#[must_use]
pub fn dielectric_average_albedo_with(
    model: Model,
    alpha: f64,
    eta: f64,
    convention: TransmissionConvention,
    settings: &QmcSettings,
) -> Estimate {
    check(alpha, 0.5, eta);
    if alpha == 0.0 || convention.smooth_at(eta) {
        return Estimate::exact(0.0);
    }
    let alpha = alpha.max(SMOOTH_ALPHA);
    let key = [
        TAG_DIELECTRIC_AVG,
        model_key(model),
        alpha.to_bits(),
        eta.to_bits(),
    ];
    fn kernel<N: MicrofacetDistribution>(
        ndf: N,
        masking: Masking,
        eta: f64,
        convention: TransmissionConvention,
        settings: &QmcSettings,
        key: &[u64],
    ) -> Estimate {
        replicates(settings, key, |seq, log2_n| {
            sum_over_block(
                seq,
                log2_n,
                #[inline(always)]
                |[u0, u1, s]: [f64; 3]| {
                    let o = Vec3::new((1.0 - s).sqrt(), 0.0, s.sqrt());
                    let m = ndf.sample_visible_normal(o, [u0, u1]);
                    let lambda_o = ndf.lambda(o);
                    scattering_with(ndf, masking, o, lambda_o, m, eta, convention).loss
                },
            )
        })
    }
    let masking = model.masking;
    match model.ndf {
        Ndf::Ggx => kernel(Ggx { alpha }, masking, eta, convention, settings, &key),
        Ndf::Beckmann => kernel(Beckmann { alpha }, masking, eta, convention, settings, &key),
    }
}

/// `E_eta(mu)` with its parts, by quadrature (see the module docs).
#[must_use]
pub fn reference_dielectric_albedo(
    model: Model,
    alpha: f64,
    mu: f64,
    eta: f64,
    settings: &ReferenceSettings,
) -> DielectricReference {
    reference_dielectric_albedo_with(
        model,
        alpha,
        mu,
        eta,
        TransmissionConvention::SingleScattering,
        settings,
    )
}

/// [`reference_dielectric_albedo`] in the given convention ([`TransmissionConvention`]).
#[must_use]
pub fn reference_dielectric_albedo_with(
    model: Model,
    alpha: f64,
    mu: f64,
    eta: f64,
    convention: TransmissionConvention,
    settings: &ReferenceSettings,
) -> DielectricReference {
    check(alpha, mu, eta);
    if (alpha == 0.0 && mu > 0.0) || convention.smooth_at(eta) {
        return DielectricReference::exact(mu, eta);
    }
    let alpha = alpha.max(SMOOTH_ALPHA);
    match model.ndf {
        Ndf::Ggx => quadrature(Ggx { alpha }, model.masking, mu, eta, convention, settings),
        Ndf::Beckmann => quadrature(
            Beckmann { alpha },
            model.masking,
            mu,
            eta,
            convention,
            settings,
        ),
    }
}

/// `E_avg,eta = 2 ∫ E_eta(mu) mu dmu` with its parts, by quadrature over the microfacet normal
/// first ([`super::dielectric_average`]); [`nested_dielectric_average_albedo_with`] computes the
/// same in the other order.
#[must_use]
pub fn reference_dielectric_average_albedo(
    model: Model,
    alpha: f64,
    eta: f64,
    settings: &ReferenceSettings,
) -> DielectricReference {
    reference_dielectric_average_albedo_with(
        model,
        alpha,
        eta,
        TransmissionConvention::SingleScattering,
        settings,
    )
}

/// The tolerance of one dielectric average evaluated on its own (`kiln eval --quantity
/// e-avg-dielectric --method reference`): a triple integral, asked for 1e-9 rather than the
/// reference's default 1e-10 (at r = 0.5, eta = 1.5 it states 3.0e-10 in 0.19 s whole process,
/// 2026-12-07).
pub const AVERAGE_POINT_TOLERANCE: f64 = 1e-9;

/// [`reference_dielectric_average_albedo`] in the given convention ([`TransmissionConvention`]).
#[must_use]
pub fn reference_dielectric_average_albedo_with(
    model: Model,
    alpha: f64,
    eta: f64,
    convention: TransmissionConvention,
    settings: &ReferenceSettings,
) -> DielectricReference {
    if let Some(smooth) = smooth_average(alpha, eta, convention) {
        return smooth;
    }
    let alpha = alpha.max(SMOOTH_ALPHA);
    let masking = model.masking;
    match model.ndf {
        Ndf::Ggx => average(Ggx { alpha }, masking, eta, convention, settings),
        Ndf::Beckmann => average(Beckmann { alpha }, masking, eta, convention, settings),
    }
}

/// The arguments checked, and where the interface is smooth (`alpha = 0`, or an index the
/// convention takes as matched) its averages: `R_avg = F_avg(eta)`, `T_avg = 1 - F_avg(eta)`.
fn smooth_average(
    alpha: f64,
    eta: f64,
    convention: TransmissionConvention,
) -> Option<DielectricReference> {
    check(alpha, 0.5, eta);
    (alpha == 0.0 || convention.smooth_at(eta)).then(|| {
        let f_avg = crate::model::Fresnel::Dielectric { eta }.average_report();
        DielectricReference {
            reflection: f_avg.value[0],
            transmission: 1.0 - f_avg.value[0],
            one_minus_value: 0.0,
            error: f_avg.error,
            evaluations: f_avg.evaluations,
            converged: true,
        }
    })
}

/// [`reference_dielectric_average_albedo_with`] in the other order, an independent check of it
/// (tests): an integral over `mu` of [`reference_dielectric_albedo_with`], at a quarter of the
/// tolerance (their errors add up under a weight `2 mu` that integrates to 1), broken at `alpha
/// / 16, alpha / 4, alpha, 4 alpha` (the grazing layer) and, for `eta < 1`, at the critical
/// angle's `mu_c = sqrt(1 - eta^2)`, `mu_c +- alpha / 4, alpha, 4 alpha` (the roughness smooths
/// the critical angle over a width ~alpha) and `mu = eta`. Five to fifteen times the
/// evaluations.
#[must_use]
pub fn nested_dielectric_average_albedo_with(
    model: Model,
    alpha: f64,
    eta: f64,
    convention: TransmissionConvention,
    settings: &ReferenceSettings,
) -> DielectricReference {
    if let Some(smooth) = smooth_average(alpha, eta, convention) {
        return smooth;
    }
    let mut breaks = vec![0.0, 1.0];
    for b in [alpha / 16.0, alpha / 4.0, alpha, 4.0 * alpha] {
        breaks.push(b);
    }
    if eta < 1.0 {
        // The critical angle, smoothed over a width ~alpha: a ladder on either side.
        let critical = ((1.0 - eta) * (1.0 + eta)).sqrt();
        breaks.push(critical);
        // Below mu = eta the critical angle's curve reaches the horizon (see `quadrature`):
        // a kink in E(mu) (GGX alpha 1, eta 1/3: 2.1x understated at 1e-6 without it).
        breaks.push(eta);
        for b in [alpha / 4.0, alpha, 4.0 * alpha] {
            breaks.extend([critical - b, critical + b]);
        }
    }
    breaks.retain(|&b| (0.0..=1.0).contains(&b));
    breaks.sort_by(f64::total_cmp);
    let inner = ReferenceSettings {
        tolerance: settings.tolerance / 4.0,
        ..*settings
    };
    let mut evaluations = 0;
    let mut converged = true;
    let mut integrand = |mu: f64| {
        let r = reference_dielectric_albedo_with(model, alpha, mu, eta, convention, &inner);
        evaluations += r.evaluations;
        converged &= r.converged;
        let w = 2.0 * mu;
        [
            w * r.reflection,
            w * r.transmission,
            w * r.one_minus_value,
            w * r.error,
        ]
    };
    let outer = integrate_pieces(
        &mut integrand,
        &breaks,
        settings.tolerance / 2.0,
        settings.max_intervals,
    );
    DielectricReference::from_outer(&outer, 1.0, evaluations, converged)
}

/// How far (in `x`) the ladders toward the two horizons reach.
const LADDER_REACH: f64 = 8.0;

/// Lanes of one batch of the integrand: a rule's [`KRONROD_NODES`] padded to a multiple of the
/// SIMD width.
const LANES: usize = 16;

/// The variable of one piece of the `x` integral at one azimuth (see [`quadrature`]).
#[derive(Clone, Copy)]
enum Variable {
    /// `x` itself: `t = alpha e^x`.
    X,
    /// `s = t / (alpha + t)`, from `x = -infinity`.
    Logistic,
    /// `x = edge + s^2`, beside a critical angle at the piece's start.
    SquareFrom(f64),
    /// `x = edge - s^2`, beside a critical angle at the piece's end.
    SquareTo(f64),
}

/// What the integrand needs of the view and the interface at every normal.
struct DielectricView<N> {
    ndf: N,
    masking: Masking,
    o: Vec3,
    /// `Lambda(o)`.
    lambda_o: f64,
    /// `G1(o) / mu`.
    inverse_area: f64,
    eta: f64,
    convention: TransmissionConvention,
}

impl<N: MicrofacetDistribution> DielectricView<N> {
    /// `[R, T, 1 - E]` per unit of the piece's variable at one rule's nodes, at azimuth `phi`:
    /// the visible density `D (o.m) G1(o) / mu` per unit `x` and `phi` (`dω_m = sin^2 cos dx
    /// dphi`) times what the normal scatters ([`scatterings_at_cos`]), times `dx/dv`.
    #[inline(always)]
    fn values_at(
        &self,
        nodes: &[f64; KRONROD_NODES],
        variable: Variable,
        cos_phi: f64,
        sin_phi: f64,
        values: &mut [[f64; 3]; KRONROD_NODES],
    ) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports AVX2, checked on the line above.
            let lanes = unsafe { dielectric_values_avx2(self, nodes, variable, cos_phi, sin_phi) };
            values.copy_from_slice(&lanes[..KRONROD_NODES]);
            return;
        }
        let lanes = dielectric_values(self, nodes, variable, cos_phi, sin_phi);
        values.copy_from_slice(&lanes[..KRONROD_NODES]);
    }
}

/// [`dielectric_values`] compiled for AVX2: bit-identical (the same IEEE operations in the same
/// order per lane), several lanes at a time, the nodes' `exp` included.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn dielectric_values_avx2<N: MicrofacetDistribution>(
    view: &DielectricView<N>,
    nodes: &[f64; KRONROD_NODES],
    variable: Variable,
    cos_phi: f64,
    sin_phi: f64,
) -> [[f64; 3]; LANES] {
    dielectric_values(view, nodes, variable, cos_phi, sin_phi)
}

/// [`DielectricView::values_at`] in lanes: `t = tan(theta_m)` and `dx/dv` at each node of the
/// piece's variable, [`dielectric_lanes`] there, and the factor `dx/ds = +-2 s` of the square
/// maps applied to the result.
#[inline(always)]
fn dielectric_values<N: MicrofacetDistribution>(
    view: &DielectricView<N>,
    nodes: &[f64; KRONROD_NODES],
    variable: Variable,
    cos_phi: f64,
    sin_phi: f64,
) -> [[f64; 3]; LANES] {
    let alpha = view.ndf.alpha();
    let mut t = [0.0; LANES];
    let mut jacobian = [1.0; LANES];
    let mut factor = [1.0; LANES];
    let padded: [f64; LANES] = std::array::from_fn(|k| nodes[k % KRONROD_NODES]);
    // One loop per variable, so that each vectorises (a `match` inside the loop kept the
    // `exp` scalar).
    match variable {
        Variable::X => {
            for (t, &v) in t.iter_mut().zip(&padded) {
                *t = alpha * exp_lane(v);
            }
        }
        Variable::Logistic => {
            for k in 0..LANES {
                (t[k], jacobian[k]) = t_of_s(padded[k], alpha);
            }
        }
        Variable::SquareFrom(edge) | Variable::SquareTo(edge) => {
            let sign = if matches!(variable, Variable::SquareFrom(_)) {
                1.0
            } else {
                -1.0
            };
            for k in 0..LANES {
                let v = padded[k];
                t[k] = alpha * exp_lane(edge + sign * (v * v));
                factor[k] = 2.0 * v;
            }
        }
    }
    let mut lanes = dielectric_lanes(view, &t, &jacobian, cos_phi, sin_phi);
    for (lane, factor) in lanes.iter_mut().zip(factor) {
        *lane = lane.map(|v| factor * v);
    }
    lanes
}

/// `[R, T, 1 - E]` per unit `x` and `phi` at `t_k = tan(theta_m)`, times `jacobian_k`; nothing
/// where a node rounds onto an end of its range (`s = 0`, where the integrand vanishes) or the
/// normal faces away from the view.
#[inline(always)]
fn dielectric_lanes<N: MicrofacetDistribution>(
    view: &DielectricView<N>,
    t: &[f64; LANES],
    jacobian: &[f64; LANES],
    cos_phi: f64,
    sin_phi: f64,
) -> [[f64; 3]; LANES] {
    let o = view.o;
    let mut m = [Vec3::new(0.0, 0.0, 1.0); LANES];
    let mut om = [0.0; LANES];
    let mut density = [0.0; LANES];
    let mut counts = [false; LANES];
    for k in 0..LANES {
        let t = t[k];
        let cos_t = 1.0 / (1.0 + t * t).sqrt();
        let sin_t = t * cos_t;
        m[k] = Vec3::new(sin_t * cos_phi, sin_t * sin_phi, cos_t);
        om[k] = o.dot(m[k]);
        // dω_m = sin^2 cos dx dphi in these variables; G1(o) (o.m) D / mu is the visible density.
        density[k] = view.ndf.d_from_tan2(t * t)
            * sin_t
            * sin_t
            * m[k].z
            * om[k]
            * view.inverse_area
            * jacobian[k];
        counts[k] = t > 0.0 && t < f64::INFINITY && om[k] > 0.0;
    }
    let scattering = scatterings_at_cos(
        view.ndf,
        view.masking,
        &[o; LANES],
        &[view.lambda_o; LANES],
        &m,
        &om,
        view.eta,
        view.convention,
    );
    let mut values = [[0.0; 3]; LANES];
    for k in 0..LANES {
        let s = scattering[k];
        values[k] = if counts[k] {
            [
                density[k] * s.reflection,
                density[k] * s.transmission,
                density[k] * s.loss,
            ]
        } else {
            [0.0; 3]
        };
    }
    values
}

/// The azimuths in `(0, pi)` where an end of a slice's refracting range `o.m > c` (`c` the
/// critical angle's cosine; `o.m = rho cos(theta - delta)` along the slice, so the ends are
/// `theta = delta +- acos(c / rho)`) crosses the reflected direction's horizon `theta* = (pi -
/// atan2(mu, so cos phi)) / 2`, where the inner integral is broken with a ladder of rungs: the
/// critical angle's square root then moves through the masking layer, a kink in `phi` that a
/// piece stepping over it does not see (GGX r 0.45, mu 0.7, eta 2/3: 1.8e-8 off where 3.5e-9
/// was stated, at tolerance 1e-8). A scan of 128 steps, then bisection.
fn critical_crossings(mu: f64, so: f64, c: f64) -> Vec<f64> {
    const SCAN: usize = 128;
    // The signed gaps of both ends from the horizon at `phi`, where the slice refracts.
    let gaps = |phi: f64| -> Option<[f64; 2]> {
        let cos_phi = phi.cos();
        let rho = (mu * mu + so * so * cos_phi * cos_phi).sqrt();
        if rho <= c {
            return None;
        }
        let delta = (so * cos_phi).atan2(mu);
        let spread = (c / rho).acos();
        let theta_star = 0.5 * (PI - mu.atan2(so * cos_phi));
        Some([delta - spread - theta_star, delta + spread - theta_star])
    };
    let mut crossings = Vec::new();
    let mut previous: Option<(f64, [f64; 2])> = None;
    for k in 0..=SCAN {
        let phi = PI * k as f64 / SCAN as f64;
        let here = gaps(phi);
        if let (Some((phi0, g0)), Some(g1)) = (previous, here) {
            for j in 0..2 {
                if (g0[j] < 0.0) != (g1[j] < 0.0) {
                    crossings.push(bisect(phi0, phi, 50, |mid| {
                        gaps(mid).is_some_and(|g| (g[j] < 0.0) == (g0[j] < 0.0))
                    }));
                }
            }
        }
        previous = here.map(|g| (phi, g));
    }
    crossings
}

/// The outer integral's breaks in the azimuth: [`phi_breaks`], and with a critical angle
/// (`critical_cos`, light leaving the denser medium) where its curve leaves the slice, a ladder
/// beyond it, where it crosses the horizon, and its crossings ([`critical_crossings`]).
fn outer_breaks(mu: f64, so: f64, critical_cos: Option<f64>) -> Vec<f64> {
    let mut breaks = phi_breaks(mu, so);
    if let Some(c) = critical_cos {
        // Where the critical angle's curve leaves the slice (rho(phi) = critical cos), the
        // inner integral has a kink in phi: break there.
        if c > mu && so > 0.0 {
            let cos_phi = ((c - mu) * (c + mu)).sqrt() / so;
            if cos_phi < 1.0 {
                breaks.extend([cos_phi.acos(), (-cos_phi).acos()]);
            }
            // Beyond it the slices reach past the critical angle, where the Fresnel factor
            // falls from 1 over a width ~c in o.m: a layer of the inner integral in phi,
            // ~c / so wide, at the end of a piece up to pi / 2 long, which the outer rule
            // stepped over at mu = 0 (GGX alpha 0.051, eta 0.99968: 2.4e-7 off where 4.0e-8
            // was stated, at tolerance 1e-7). A ladder in rho closes in on it, from c / 4 (one
            // started at c / 16 made `kiln verify --preset cycles` of the inside table 14 %
            // slower than without a ladder; this one 3 %).
            for rung in ladder(4.0 * c, 1.0) {
                let rho = c + rung;
                let cos_phi = ((rho - mu) * (rho + mu)).sqrt() / so;
                if cos_phi < 1.0 {
                    breaks.extend([cos_phi.acos(), (-cos_phi).acos()]);
                }
            }
        }
        // And where it crosses the horizon (theta_m = pi / 2 at rho sin(delta) = so cos(phi)
        // = critical cos): beyond, the slice refracts up to its visible edge. Without this break
        // the outer rule stepped over the kink (GGX alpha 0.327, mu 0.300, eta 1/3: 1.8e-7 off
        // where 4.8e-8 was stated, at tolerance 1e-7).
        if c < so {
            breaks.push((c / so).acos());
        }
        breaks.extend(critical_crossings(mu, so, c));
        breaks.sort_by(f64::total_cmp);
    }
    breaks
}

/// A slice's breaks in `x` made ready for its pieces: the critical angles added, those outside
/// `[x_min, x_visible]` dropped, sorted, a piece between two critical angles halved and one
/// ending at a critical angle from `x_min` given a break a unit before it.
fn finish_slice_breaks(
    mut breaks: Vec<f64>,
    critical: &[f64],
    x_min: f64,
    x_visible: f64,
) -> Vec<f64> {
    breaks.extend(critical);
    breaks.retain(|&b| b >= x_min && b <= x_visible);
    breaks.sort_by(f64::total_cmp);
    breaks.dedup();
    // A piece between the two critical angles has a square root at both ends: split it, so
    // that each half has one, which its substitution below makes smooth.
    if let [first, second] = critical[..]
        && breaks
            .windows(2)
            .any(|w| (w[0] == first && w[1] == second) || (w[0] == second && w[1] == first))
    {
        breaks.push(0.5 * (first + second));
        breaks.sort_by(f64::total_cmp);
    }
    // The piece from x_min is integrated from x = -infinity in s (below); when it ends at a
    // critical angle, a break a unit before it keeps the square-root piece finite.
    if let Some(&first) = breaks.get(1)
        && first <= 0.0
        && critical.contains(&first)
        && first - 1.0 > x_min
    {
        breaks.insert(1, first - 1.0);
    }
    breaks
}

/// Where the refracted direction crosses the horizon along a slice: the sign changes of its
/// `z` (`refracted_z`, `None` where the facet does not refract) between the points of `scan`,
/// found by bisection, each added to `breaks` with a ladder into its masking layer on both
/// sides.
fn refraction_horizon_breaks(
    scan: &[f64],
    refracted_z: &dyn Fn(f64) -> Option<f64>,
    alpha: f64,
    breaks: &mut Vec<f64>,
) {
    let mut previous: Option<(f64, f64)> = None;
    for &x in scan {
        let z = refracted_z(x);
        if let (Some((x0, z0)), Some(z1)) = (previous, z)
            && (z0 < 0.0) != (z1 < 0.0)
        {
            let root = bisect(x0, x, 40, |mid| {
                refracted_z(mid).is_some_and(|zm| (zm < 0.0) == (z0 < 0.0))
            });
            breaks.push(root);
            // The refracted direction grazes the horizon here: its masking layer, on both
            // sides.
            let layer = 2.0 * alpha / (2.0 * (alpha * root.exp()).atan()).sin();
            for rung in ladder(layer, LADDER_REACH) {
                breaks.extend([root - rung, root + rung]);
            }
        }
        previous = z.map(|z| (x, z));
    }
}

/// The facet tilts `theta_m` in `(0, pi/2)` at which a slice at `cos(phi)` meets the critical
/// angle (`o.m = critical_cos`, light leaving the denser medium), each with the side (+1 or -1)
/// on which the facet refracts: `o.m = rho cos(theta - delta)` along the slice.
fn critical_angles(mu: f64, so: f64, cos_phi: f64, critical_cos: Option<f64>) -> Vec<(f64, f64)> {
    let rho = (mu * mu + so * so * cos_phi * cos_phi).sqrt();
    let delta = (so * cos_phi).atan2(mu);
    let Some(c) = critical_cos.filter(|&c| c < rho) else {
        return Vec::new();
    };
    let spread = (c / rho).acos();
    [(delta - spread, 1.0), (delta + spread, -1.0)]
        .into_iter()
        .filter(|&(theta, _)| theta > 0.0 && theta < PI / 2.0)
        .collect()
}

/// `[R, T, 1 - E]` for one distribution (see the module docs).
fn quadrature<N: MicrofacetDistribution>(
    ndf: N,
    masking: Masking,
    mu: f64,
    eta: f64,
    convention: TransmissionConvention,
    settings: &ReferenceSettings,
) -> DielectricReference {
    let alpha = ndf.alpha();
    let so = sin_from_cos(mu);
    let o = Vec3::new(so, 0.0, mu);
    let lambda_o = ndf.lambda_from_tan2(if mu == 0.0 {
        f64::INFINITY
    } else {
        (so / mu) * (so / mu)
    });
    // G1(o) / mu, finite at mu = 0.
    let inverse_area = 1.0 / ndf.projected_area(mu);
    let (x_min, x_max) = x_range(alpha, settings.tolerance);
    let x_of_theta = |theta: f64| (theta.tan() / alpha).ln().clamp(x_min, x_max);
    let normal_at = |t: f64, cos_phi: f64, sin_phi: f64| {
        let cos_t = 1.0 / (1.0 + t * t).sqrt();
        let sin_t = t * cos_t;
        Vec3::new(sin_t * cos_phi, sin_t * sin_phi, cos_t)
    };
    let normal = |x: f64, cos_phi: f64, sin_phi: f64| {
        let t = alpha * x.exp();
        (normal_at(t, cos_phi, sin_phi), t)
    };
    let view = DielectricView {
        ndf,
        masking,
        o,
        lambda_o,
        inverse_area,
        eta,
        convention,
    };
    // The z of the refracted direction, where there is one.
    let refracted_z = |x: f64, cos_phi: f64, sin_phi: f64| -> Option<f64> {
        let (m, _) = normal(x, cos_phi, sin_phi);
        let om = o.dot(m);
        (om > 0.0)
            .then(|| refract(o, m, om, eta))
            .flatten()
            .map(|v| v.z)
    };
    let critical_cos = (eta < 1.0).then(|| ((1.0 - eta) * (1.0 + eta)).sqrt());

    let inner_tolerance = settings.tolerance / (4.0 * PI);
    let mut evaluations = 0;
    let mut all_converged = true;
    let mut over_phi = |phi: f64| -> [f64; 4] {
        let (sin_phi, cos_phi) = phi.sin_cos();
        // The reflected direction's horizon and the edge of visibility, as for E.
        let theta_star = 0.5 * (PI - mu.atan2(so * cos_phi));
        let x_visible = if cos_phi < 0.0 && so > 0.0 {
            x_of_theta((mu / (so * -cos_phi)).atan())
        } else {
            x_max
        };
        let x_star = x_of_theta(theta_star);
        let mut breaks = vec![x_min, x_visible, 0.0, x_star];
        let mut critical = Vec::new();
        // Sign changes of the refracted direction's z: a scan, then bisection. The scan is
        // uniform in theta_m (a scan uniform in x, over the range a tight tolerance needs,
        // stepped over pairs of sign changes near the peak: 6e-10 lost at 1e-12).
        const SCAN: usize = 32;
        let theta_visible = (x_visible.exp() * alpha).atan();
        let mut scan: Vec<f64> = (0..=SCAN)
            .map(|k| x_of_theta(theta_visible * k as f64 / SCAN as f64))
            .collect();
        // Refraction starts at a critical angle with the refracted direction in the facet's
        // plane, a few alpha from the horizon at a small tilt: its sign change can lie closer
        // to the critical angle than a scan step (eta 0.95, alpha 0.01, mu 0.3: 8e-8 lost at
        // 1e-6). Scan from just inside each critical angle too.
        for (theta, inward) in critical_angles(mu, so, cos_phi, critical_cos) {
            let x = x_of_theta(theta);
            critical.push(x);
            scan.push(x + inward * 1e-9);
        }
        scan.sort_by(f64::total_cmp);
        refraction_horizon_breaks(
            &scan,
            &|x| refracted_z(x, cos_phi, sin_phi),
            alpha,
            &mut breaks,
        );
        evaluations += scan.len() as u64 * 2;
        // The reflected direction's masking layer below its horizon curve (as in `E`'s
        // reference: a layer of width ~alpha / sin(2 theta*) in x, which a piece much wider
        // than it can step over unseen).
        for rung in ladder(alpha / (2.0 * theta_star).sin(), LADDER_REACH) {
            breaks.push(x_star - rung);
        }
        let breaks = finish_slice_breaks(breaks, &critical, x_min, x_visible);
        // Beside the critical angle 1 - F and the refracted direction go as sqrt(distance):
        // integrate those pieces in s with x = edge +- s^2, which makes them smooth.
        let pieces = breaks.len().saturating_sub(1).max(1) as f64;
        let mut total = [0.0; 4];
        for pair in breaks.windows(2) {
            let (a, b) = (pair[0], pair[1]);
            let (variable, lo, hi) = if a == x_min && b <= 0.0 && !critical.contains(&b) {
                // Below the peak, from x = -infinity: in `s = t / (alpha + t)`, where the
                // integrand (`~ e^(2x)` per unit x) is polynomial (as in `E`'s reference).
                (Variable::Logistic, 0.0, s_of_x(b))
            } else if critical.contains(&a) {
                (Variable::SquareFrom(a), 0.0, (b - a).sqrt())
            } else if critical.contains(&b) {
                (Variable::SquareTo(b), 0.0, (b - a).sqrt())
            } else {
                (Variable::X, a, b)
            };
            let q = integrate_pieces_batch(
                &mut |nodes: &[f64; KRONROD_NODES], values: &mut [[f64; 3]; KRONROD_NODES]| {
                    view.values_at(nodes, variable, cos_phi, sin_phi, values);
                },
                &[lo, hi],
                inner_tolerance / pieces,
                settings.max_intervals,
            );
            evaluations += q.evaluations;
            all_converged &= q.converged;
            for (sum, value) in total.iter_mut().zip(q.value) {
                *sum += value;
            }
            total[3] += q.error;
        }
        total
    };
    let breaks = outer_breaks(mu, so, critical_cos);
    let outer = integrate_pieces(
        &mut over_phi,
        &breaks,
        settings.tolerance / 4.0,
        settings.max_intervals,
    );
    // Doubled: the azimuths run over [0, pi] of the symmetric [-pi, pi].
    let mut reference = DielectricReference::from_outer(&outer, 2.0, evaluations, all_converged);
    // The stated error includes what the x range leaves out: the visible normals below `x_min`
    // and above `x_max` ([`x_range`]), each part's integrand at most 1 per unit of that mass
    // (`R + T + (1 - E) = 1` at every normal). Without it the statement fell short where the
    // cut carries transmission (GGX alpha 0.051, mu 6.6e-6, eta 0.9999997 from inside: 6.4e-10
    // off at tolerance 1e-7, 5.9e-10 stated).
    reference.error += (2.0 * x_min).exp() + 2.0 * alpha * (-x_max).exp();
    reference
}

#[cfg(test)]
mod lane_tests {
    use super::*;
    use crate::model::Ggx;

    /// Each lane against the scalar integrand written out (the normal at `t`, the visible
    /// density per unit `x` and `phi`, [`scattering_with`]), bit for bit; and the AVX2 build
    /// against the portable one. Both sides of the interface, both conventions, nodes through
    /// the critical angle and total internal reflection.
    #[test]
    fn the_lanes_give_the_scalar_integrand() {
        for eta in [1.0 / 1.5, 1.0, 1.5] {
            for convention in [
                TransmissionConvention::SingleScattering,
                TransmissionConvention::Cycles,
            ] {
                for mu in [0.1_f64, 0.6] {
                    let ndf = Ggx { alpha: 0.4 };
                    let so = (1.0 - mu * mu).sqrt();
                    let o = Vec3::new(so, 0.0, mu);
                    let view = DielectricView {
                        ndf,
                        masking: Masking::HeightCorrelated,
                        o,
                        lambda_o: ndf.lambda(o),
                        inverse_area: 1.0 / ndf.projected_area(mu),
                        eta,
                        convention,
                    };
                    let (sin_phi, cos_phi) = 2.0_f64.sin_cos();
                    let mut t = [0.0; LANES];
                    let jacobian = [1.5; LANES];
                    for (k, t) in t.iter_mut().enumerate() {
                        *t = 0.02 * 1.5_f64.powi(k as i32);
                    }
                    let lanes = dielectric_lanes(&view, &t, &jacobian, cos_phi, sin_phi);
                    #[cfg(target_arch = "x86_64")]
                    if std::arch::is_x86_feature_detected!("avx2") {
                        let nodes = crate::numerics::gauss_kronrod::tests::nodes_of(0.1, 0.9);
                        for variable in [
                            Variable::X,
                            Variable::Logistic,
                            Variable::SquareFrom(-1.0),
                            Variable::SquareTo(0.5),
                        ] {
                            // SAFETY: checked above.
                            let simd = unsafe {
                                dielectric_values_avx2(&view, &nodes, variable, cos_phi, sin_phi)
                            };
                            let portable =
                                dielectric_values(&view, &nodes, variable, cos_phi, sin_phi);
                            assert_eq!(
                                simd.map(|v| v.map(f64::to_bits)),
                                portable.map(|v| v.map(f64::to_bits))
                            );
                        }
                    }
                    for k in 0..LANES {
                        let cos_t = 1.0 / (1.0 + t[k] * t[k]).sqrt();
                        let m = Vec3::new(t[k] * cos_t * cos_phi, t[k] * cos_t * sin_phi, cos_t);
                        let om = o.dot(m);
                        let want = if om <= 0.0 {
                            [0.0; 3]
                        } else {
                            let sin_t = t[k] * m.z;
                            let density = ndf.d_from_tan2(t[k] * t[k])
                                * sin_t
                                * sin_t
                                * m.z
                                * om
                                * view.inverse_area
                                * jacobian[k];
                            let s = scattering_with(
                                ndf,
                                Masking::HeightCorrelated,
                                o,
                                view.lambda_o,
                                m,
                                eta,
                                convention,
                            );
                            [
                                density * s.reflection,
                                density * s.transmission,
                                density * s.loss,
                            ]
                        };
                        assert_eq!(
                            lanes[k].map(f64::to_bits),
                            want.map(f64::to_bits),
                            "eta {eta} mu {mu} t {}",
                            t[k]
                        );
                    }
                }
            }
        }
    }
}
