//! `E_avg` by a composite rule in variables where the integrand is smooth, for baking: about 90
//! `E` evaluations per entry where the nested adaptive reference spends hundreds, and checked
//! against it (tests, `kiln verify`).
//!
//! `E_avg = 2 ∫_0^1 E(mu) mu dmu` (`docs/physics.md`). In the adaptive table coordinate
//! `t = (mu (1 + c alpha) / (mu + c alpha))^p` ([`crate::table::axis::MuMapping::Adaptive`],
//! [`super::grazing`]) the grazing boundary
//! layer `mu ~ alpha` is smooth at every `alpha`, so the integral over `mu in [0, mu_c]`,
//! `mu_c = min(8 alpha, 1)`, is taken in `t`, with `2 mu dmu = 2 mu (dmu/dt) dt`,
//! `dmu/dt = k (1 + k) / (1 + k - s)^2 * s / (p t)`, `s = t^(1/p)`, `k = c alpha`. Beyond
//! `mu_c`, `1 - E` falls like `alpha^2 / mu^2` and the integrand is smooth in `v = ln mu`:
//! `2 mu dmu = 2 mu^2 dv`. Each part starts as [`PANELS`] panels of the 15-point Kronrod rule and
//! is bisected adaptively until its `|K15 - G7|` estimate meets a quarter of the tolerance (most
//! entries need no bisection; Beckmann at `alpha = 1`, whose `E(mu)` is less smooth near
//! `mu = 1`, does); `E` and `1 - E` come from [`reference_albedo`] at half the tolerance, which
//! the result's estimate adds, so that the error stated is within the tolerance.

use super::gauss_kronrod::integrate_pieces;
use super::gauss_legendre;
use super::grazing::{ADAPTIVE_POWER, ADAPTIVE_SCALE, mu_of_t, t_of_mu};
use super::reference::{MIRROR, ReferenceSettings, ReferenceValue, reference_albedo};
use crate::model::{Model, Ndf, SMOOTH_ALPHA};

/// Panels each part starts with.
pub const PANELS: usize = 3;

/// The two parts of `2 ∫_0^1 g(mu) mu dmu` in smooth variables (see the module docs): the head
/// `mu in [0, mu_c]` in the adaptive coordinate `t in [0, t_c]`, the tail `mu in [mu_c, 1]` in
/// `v = ln mu in [ln mu_c, 0]` (absent when `mu_c = 1`).
struct Split {
    alpha: f64,
    mu_c: f64,
    t_c: f64,
}

impl Split {
    fn new(alpha: f64) -> Self {
        let mu_c = (8.0 * alpha).min(1.0);
        Split {
            alpha,
            mu_c,
            t_c: t_of_mu(mu_c, alpha),
        }
    }

    /// `(mu, 2 mu dmu/dt)` at head coordinate `t`.
    fn head(&self, t: f64) -> (f64, f64) {
        let (p, k) = (ADAPTIVE_POWER, ADAPTIVE_SCALE * self.alpha);
        let s = t.powf(1.0 / p);
        let mu = mu_of_t(t, self.alpha);
        let dmu_dt = k * (1.0 + k) / (1.0 + k - s).powi(2) * s / (p * t);
        (mu, 2.0 * mu * dmu_dt)
    }

    /// `(mu, 2 mu dmu/dv)` at tail coordinate `v = ln mu`.
    fn tail(v: f64) -> (f64, f64) {
        let mu = v.exp();
        (mu, 2.0 * mu * mu)
    }

    fn has_tail(&self) -> bool {
        self.mu_c < 1.0
    }
}

/// The inner `E(mu)` evaluations of an `E_avg` rule, tallied.
struct Counted {
    evaluations: u64,
    converged: bool,
}

impl Default for Counted {
    fn default() -> Self {
        Self {
            evaluations: 0,
            converged: true,
        }
    }
}

impl Counted {
    /// `[E, 1 - E]` at `mu` by [`reference_albedo`], counted.
    fn albedo(&mut self, model: Model, alpha: f64, mu: f64, inner: &ReferenceSettings) -> [f64; 2] {
        let r = reference_albedo(model, alpha, mu, inner);
        self.evaluations += r.evaluations;
        self.converged &= r.converged;
        [r.value, r.one_minus_value]
    }
}

/// `E_avg` and `1 - E_avg` (see the module docs), with the rule's error estimate plus the inner
/// tolerance, and the `E` evaluations' integrand count.
#[must_use]
pub fn quadrature_average_albedo(
    model: Model,
    alpha: f64,
    settings: &ReferenceSettings,
) -> ReferenceValue {
    assert!(alpha >= 0.0 && alpha.is_finite());
    if alpha < SMOOTH_ALPHA {
        return MIRROR;
    }
    // The weights integrate to 1, so the inner errors add at most their tolerance: half the
    // tolerance for them, a quarter for each part's rule, so that the sum stated is within it.
    let inner = ReferenceSettings {
        tolerance: settings.tolerance / 2.0,
        ..*settings
    };
    let mut counted = Counted::default();
    let mut albedo = |mu: f64| counted.albedo(model, alpha, mu, &inner);
    let split = Split::new(alpha);
    let panels = |a: f64, b: f64| -> Vec<f64> {
        (0..=PANELS)
            .map(|j| a + (b - a) * j as f64 / PANELS as f64)
            .collect()
    };
    let budget = settings.max_intervals.max(4 * PANELS);
    let mut parts = vec![integrate_pieces(
        &mut |t| {
            let (mu, w) = split.head(t);
            albedo(mu).map(|g| w * g)
        },
        &panels(0.0, split.t_c),
        settings.tolerance / 4.0,
        budget,
    )];
    if split.has_tail() {
        parts.push(integrate_pieces(
            &mut |v| {
                let (mu, w) = Split::tail(v);
                albedo(mu).map(|g| w * g)
            },
            &panels(split.mu_c.ln(), 0.0),
            settings.tolerance / 4.0,
            budget,
        ));
    }
    ReferenceValue {
        value: parts.iter().map(|q| q.value[0]).sum(),
        one_minus_value: parts.iter().map(|q| q.value[1]).sum(),
        error: parts.iter().map(|q| q.error).sum::<f64>() + inner.tolerance,
        evaluations: counted.evaluations,
        converged: counted.converged && parts.iter().all(|q| q.converged),
    }
}

/// `E_avg` and `1 - E_avg` to `settings.tolerance` by the cheapest rule that states it: the
/// fixed Gauss-Legendre rule ([`rule_average_albedo`]) of the smallest order whose measured bound
/// ([`RULE_BOUNDS`]) is within half the tolerance, its `E` evaluations at the other half (so the
/// stated error, their sum, is within the tolerance), where a bound was measured for the model
/// (the Smith forms); otherwise the composite adaptive rule ([`quadrature_average_albedo`]). At
/// 1e-11 (what `kiln verify` asks at a table's nodes) the GGX rule spends 40 `E` evaluations
/// where the adaptive one spends about 100, each at a tolerance twice as tight.
#[must_use]
pub fn average_albedo_to(model: Model, alpha: f64, settings: &ReferenceSettings) -> ReferenceValue {
    let half = settings.tolerance / 2.0;
    match rule_order_for(model.ndf, half) {
        Some(order) if model.masking.is_smith() => {
            let inner = ReferenceSettings {
                tolerance: half,
                ..*settings
            };
            rule_average_albedo(model, alpha, order, &inner)
        }
        _ => quadrature_average_albedo(model, alpha, settings),
    }
}

/// The orders of the fixed Gauss-Legendre rule [`rule_average_albedo`] offers, with the largest
/// rule error measured for each, per distribution (`|rule - quadrature_average_albedo|` with
/// inner tolerance 1e-11, over 63 roughness rungs `r = j / 63` and both maskings; the test
/// `fixed_rules_stay_within_their_measured_bounds` rechecks a sample), rounded up by a factor of
/// two. Beckmann's `E(mu)` approaches 1 like `exp(-1 / (alpha^2 (1 - mu^2)))` near `mu = 1`:
/// smooth but not analytic, so its rules converge slowly and the adaptive rule serves the
/// tighter tolerances.
pub const RULE_BOUNDS: [(Ndf, usize, f64); 12] = [
    (Ndf::Ggx, 8, 6.3e-6),
    (Ndf::Ggx, 10, 4.4e-7),
    (Ndf::Ggx, 12, 1.9e-8),
    (Ndf::Ggx, 14, 1.1e-9),
    (Ndf::Ggx, 16, 5.1e-11),
    (Ndf::Ggx, 20, 1.5e-12),
    (Ndf::Beckmann, 8, 1.6e-4),
    (Ndf::Beckmann, 10, 2.9e-5),
    (Ndf::Beckmann, 12, 5.9e-6),
    (Ndf::Beckmann, 16, 1.1e-6),
    (Ndf::Beckmann, 20, 2.0e-7),
    (Ndf::Beckmann, 24, 2.8e-8),
];

/// The measured bound of the `order`-point rule for `ndf` ([`RULE_BOUNDS`]), if offered.
#[must_use]
pub fn rule_bound(ndf: Ndf, order: usize) -> Option<f64> {
    RULE_BOUNDS
        .iter()
        .find(|&&(n, o, _)| n == ndf && o == order)
        .map(|&(_, _, bound)| bound)
}

/// The smallest order in [`RULE_BOUNDS`] for `ndf` whose bound is at most `tolerance`; `None`
/// if none is (the adaptive rule then serves).
#[must_use]
pub fn rule_order_for(ndf: Ndf, tolerance: f64) -> Option<usize> {
    RULE_BOUNDS
        .iter()
        .find(|&&(n, _, bound)| n == ndf && bound <= tolerance)
        .map(|&(_, order, _)| order)
}

/// `E_avg` and `1 - E_avg` by a fixed `order`-point Gauss-Legendre rule on each part (head and
/// tail, see the module docs), each `E` from [`reference_albedo`] at `inner`'s tolerance: `2
/// order` evaluations of `E` where the adaptive rule spends about 90. No error estimate of its
/// own: the returned `error` is the inner tolerance plus the rule's measured bound
/// ([`RULE_BOUNDS`]), which is what a bake at a requested max error relies on before it checks
/// entries against the reference.
#[must_use]
pub fn rule_average_albedo(
    model: Model,
    alpha: f64,
    order: usize,
    inner: &ReferenceSettings,
) -> ReferenceValue {
    assert!(alpha >= 0.0 && alpha.is_finite());
    if alpha < SMOOTH_ALPHA {
        return MIRROR;
    }
    let rule = gauss_legendre::rule(order);
    let mut counted = Counted::default();
    let mut albedo = |mu: f64| counted.albedo(model, alpha, mu, inner);
    let split = Split::new(alpha);
    let mut total: [f64; 2] = gauss_legendre::integrate(
        &rule,
        &mut |t| {
            let (mu, w) = split.head(t);
            albedo(mu).map(|g| w * g)
        },
        0.0,
        split.t_c,
    );
    if split.has_tail() {
        let tail = gauss_legendre::integrate(
            &rule,
            &mut |v| {
                let (mu, w) = Split::tail(v);
                albedo(mu).map(|g| w * g)
            },
            split.mu_c.ln(),
            0.0,
        );
        total[0] += tail[0];
        total[1] += tail[1];
    }
    let bound = rule_bound(model.ndf, order).unwrap_or(f64::NAN);
    // `E_avg = 1 - (1 - E_avg)`: the weight `2 mu dmu` integrates to exactly 1, which a fixed rule
    // only approximates (its error on `∫ w E` is mostly its error on `∫ w`); `1 - E` is the
    // integrand the bounds were measured on.
    ReferenceValue {
        value: 1.0 - total[1],
        one_minus_value: total[1],
        error: inner.tolerance + bound,
        evaluations: counted.evaluations,
        converged: counted.converged,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::reference::reference_average_albedo;
    use crate::model::Masking;

    /// Within 1e-10 of the nested adaptive reference from alpha = 1e-3 (where `1 - E_avg` is
    /// 7.4e-6) to 2, both maskings, both distributions (Beckmann at alpha = 1 needs the
    /// adaptive bisection: three fixed panels miss by 6e-9).
    #[test]
    fn agrees_with_the_nested_reference() {
        let settings = ReferenceSettings::default();
        let mut cases = Vec::new();
        let (hc, sep) = (Masking::HeightCorrelated, Masking::Separable);
        for alpha in [1e-3, 0.01, 0.1, 0.125, 1.0, 2.0] {
            cases.push((
                Model {
                    ndf: Ndf::Ggx,
                    masking: hc,
                },
                alpha,
            ));
        }
        for (ndf, alpha) in [(Ndf::Ggx, 0.01), (Ndf::Ggx, 1.0), (Ndf::Beckmann, 0.2)] {
            cases.push((Model { ndf, masking: sep }, alpha));
        }
        cases.push((
            Model {
                ndf: Ndf::Beckmann,
                masking: hc,
            },
            1.0,
        ));
        for (model, alpha) in cases {
            let fast = quadrature_average_albedo(model, alpha, &settings);
            let nested = reference_average_albedo(model, alpha, &settings);
            let error = (fast.one_minus_value - nested.one_minus_value).abs();
            assert!(
                error <= 1e-10,
                "{model:?} alpha {alpha}: {} vs {} ({error:.1e})",
                fast.one_minus_value,
                nested.one_minus_value
            );
            assert!((fast.value - nested.value).abs() <= 1e-10);
            // The estimate is an upper bound of the actual difference here.
            assert!(fast.converged && fast.error >= error, "{fast:?}");
        }
    }

    /// The reference's `E_avg` at a tolerance ([`average_albedo_to`]) states an error within that
    /// tolerance and agrees with the nested adaptive reference within the two stated errors:
    /// by a fixed rule for the Smith forms (order 10 at 1e-6, 16 at 1e-9 and 20 at 1e-11 for
    /// GGX), by the composite rule for Schlick-GGX (no bound measured) and where no rule is good
    /// enough (Beckmann at 1e-11). Roughness on both sides of `alpha = 1/8`, where the tail part
    /// appears (the rules' worst case sits just below it).
    #[test]
    fn the_reference_average_meets_its_tolerance_by_the_cheapest_rule() {
        let nested_settings = ReferenceSettings::default();
        for (ndf, masking) in [
            (Ndf::Ggx, Masking::HeightCorrelated),
            (Ndf::Ggx, Masking::SchlickGgx),
            (Ndf::Beckmann, Masking::Separable),
        ] {
            let model = Model { ndf, masking };
            for alpha in [0.05, 0.124, 0.9] {
                let nested = reference_average_albedo(model, alpha, &nested_settings);
                for tolerance in [1e-6, 1e-9, 1e-11] {
                    let settings = ReferenceSettings {
                        tolerance,
                        ..nested_settings
                    };
                    let r = average_albedo_to(model, alpha, &settings);
                    let what = format!("{ndf} {masking} alpha {alpha} at {tolerance:e}: {r:?}");
                    assert!(r.converged && r.error <= tolerance, "{what}");
                    let difference = (r.one_minus_value - nested.one_minus_value).abs();
                    assert!(difference <= r.error + nested.error, "{what} vs {nested:?}");
                    assert!(
                        (r.value - nested.value).abs() <= r.error + nested.error,
                        "{what}"
                    );
                    // The fixed rule where one is offered: 2 parts (1 below alpha = 1/8) of
                    // `order` nodes, each an `E` at half the tolerance.
                    let rule = rule_order_for(ndf, tolerance / 2.0).filter(|_| masking.is_smith());
                    if let Some(order) = rule {
                        let inner = ReferenceSettings {
                            tolerance: tolerance / 2.0,
                            ..settings
                        };
                        assert_eq!(
                            r,
                            rule_average_albedo(model, alpha, order, &inner),
                            "{what}"
                        );
                    } else {
                        assert_eq!(
                            r,
                            quadrature_average_albedo(model, alpha, &settings),
                            "{what}"
                        );
                    }
                }
            }
        }
        assert_eq!(rule_order_for(Ndf::Ggx, 0.5e-11), Some(20));
        assert_eq!(rule_order_for(Ndf::Beckmann, 0.5e-11), None);
    }

    /// The fixed rules stay within their [`RULE_BOUNDS`] on a sample of rungs around where the
    /// measured worst cases sat (GGX: `r` near 0.35; Beckmann: rough), both maskings.
    #[test]
    fn fixed_rules_stay_within_their_measured_bounds() {
        use rayon::prelude::*;
        let settings = ReferenceSettings::default();
        let mut cases = Vec::new();
        for ndf in Ndf::ALL {
            for masking in Masking::ALL {
                for r in [0.05, 0.2, 0.35, 0.5, 0.8, 1.0] {
                    cases.push((Model { ndf, masking }, r * r));
                }
            }
        }
        cases.par_iter().for_each(|&(model, alpha)| {
            let exact = quadrature_average_albedo(model, alpha, &settings);
            for &(ndf, order, bound) in &RULE_BOUNDS {
                if ndf != model.ndf {
                    continue;
                }
                let fixed = rule_average_albedo(model, alpha, order, &settings);
                let error = (fixed.one_minus_value - exact.one_minus_value).abs();
                // The measured bound plus both inner tolerances.
                assert!(
                    error <= bound + 2.0 * settings.tolerance,
                    "{model:?} alpha {alpha} order {order}: {error:.2e} > {bound:.1e}"
                );
                assert!((fixed.value - exact.value).abs() <= bound + 2.0 * settings.tolerance);
                assert!(fixed.converged && fixed.evaluations > 0);
            }
        });
        assert_eq!(rule_order_for(Ndf::Ggx, 1e-7), Some(12));
        assert_eq!(rule_order_for(Ndf::Beckmann, 1e-10), None);
    }
}
