//! The edges of the domain (`docs/physics.md`, "Hard cases"): property-based tests over `mu` in
//! [0, 1] and `alpha` in [0, 4], with their exact edges drawn often, for every distribution and
//! masking form; and a table of hard points checked against the deterministic reference.

use kiln::integrate::albedo::{QmcSettings, albedo, average_albedo};
use kiln::integrate::reference::{ReferenceSettings, reference_albedo};
use kiln::model::{Beckmann, Ggx, Masking, MicrofacetDistribution, Model, Ndf, SMOOTH_ALPHA, Vec3};
use proptest::prelude::*;

fn models() -> Vec<Model> {
    let mut models = Vec::new();
    for ndf in Ndf::ALL {
        for masking in [Masking::HeightCorrelated, Masking::Separable] {
            models.push(Model { ndf, masking });
        }
    }
    models
}

/// `alpha` in [0, 4]: the exact edges, log-uniform down to 1e-12, and uniform.
fn alpha() -> impl Strategy<Value = f64> {
    prop_oneof![
        prop_oneof![
            Just(0.0),
            Just(1e-9),
            Just(1e-4),
            Just(SMOOTH_ALPHA),
            Just(1.0),
            Just(4.0)
        ],
        (-12.0f64..0.6).prop_map(|e| 10f64.powf(e).min(4.0)),
        0.0f64..=4.0,
    ]
}

/// `mu` in [0, 1]: the exact edges, log-uniform down to 1e-12, and uniform.
fn mu() -> impl Strategy<Value = f64> {
    prop_oneof![
        prop_oneof![Just(0.0), Just(1e-12), Just(1e-6), Just(1.0)],
        (-12.0f64..0.0).prop_map(|e| 10f64.powf(e)),
        0.0f64..=1.0,
    ]
}

fn small_qmc() -> QmcSettings {
    QmcSettings {
        samples: 1 << 11,
        scrambles: 2,
        seed: 3,
    }
}

/// Reference settings for properties (a looser tolerance than the default, for speed).
fn quick_reference() -> ReferenceSettings {
    ReferenceSettings {
        tolerance: 1e-9,
        max_intervals: 200,
    }
}

proptest! {
    // A fixed seed keeps CI reproducible; set PROPTEST_CASES higher to explore more locally.
    #![proptest_config(ProptestConfig {
        cases: 96,
        rng_seed: proptest::test_runner::RngSeed::Fixed(0x6b69_6c6e),
        ..ProptestConfig::default()
    })]

    /// Both estimators finite; the reference's `E` and `1 - E` (integrated separately) in
    /// [0, 1] and summing to 1 within the 1e-10 it promises (its error estimate is not a strict
    /// bound: at a 1e-9 tolerance, Beckmann at alpha 1, mu 0.414 has the two 1.9e-9 apart with
    /// an estimate of 4.9e-10). QMC derives `E` from `1 - E` and clamps it to [0, 1], so its
    /// range and sum hold by construction and are not asserted; its value is checked against
    /// the reference at the hard points below.
    #[test]
    fn albedo_is_finite_and_bounded(alpha in alpha(), mu in mu()) {
        for model in models() {
            let q = albedo(model, alpha, mu, &small_qmc());
            let r = reference_albedo(model, alpha, mu, &ReferenceSettings::default());
            prop_assert!(
                q.value.is_finite() && q.one_minus_value.is_finite(),
                "qmc {model:?} alpha {alpha:e} mu {mu:e}: {} {}", q.value, q.one_minus_value
            );
            prop_assert!(
                r.value.is_finite() && (0.0..=1.0).contains(&r.value)
                    && (0.0..=1.0).contains(&r.one_minus_value),
                "reference {model:?} alpha {alpha:e} mu {mu:e}: {} {}", r.value, r.one_minus_value
            );
            let apart = 1e-10 + 2.0 * r.error;
            prop_assert!(
                (r.value + r.one_minus_value - 1.0).abs() <= apart + 2.0 * f64::EPSILON,
                "reference {model:?}: {} + {} - 1 = {:e} ({apart:e})",
                r.value, r.one_minus_value, r.value + r.one_minus_value - 1.0
            );
            prop_assert!(q.std_error.is_finite() && q.std_error >= 0.0);
            prop_assert!(r.error.is_finite() && r.error >= 0.0);
        }
    }

    /// `E_avg` by QMC: finite everywhere (its range is clamped, so not asserted).
    #[test]
    fn average_albedo_is_finite_and_bounded(alpha in alpha()) {
        for model in models() {
            let a = average_albedo(model, alpha, &small_qmc());
            prop_assert!(a.value.is_finite() && a.one_minus_value.is_finite());
            prop_assert!(a.std_error.is_finite());
        }
    }

    /// At normal incidence, rougher means darker: `E(1, alpha)` decreases with `alpha`.
    #[test]
    fn albedo_at_normal_incidence_decreases_with_roughness(a in alpha(), b in alpha()) {
        prop_assume!(a != b);
        let (low, high) = (a.min(b), a.max(b));
        for model in models() {
            let smooth = reference_albedo(model, low, 1.0, &quick_reference());
            let rough = reference_albedo(model, high, 1.0, &quick_reference());
            prop_assert!(
                smooth.value >= rough.value - (smooth.error + rough.error),
                "{model:?}: E(1, {low:e}) = {} < E(1, {high:e}) = {}", smooth.value, rough.value
            );
        }
    }

    /// Limits: height-correlated `E(0, alpha) = 1` exactly; separable `E(0, alpha) < 1`; and
    /// `E -> 1` as `alpha -> 0` at fixed `mu`, as `1 - E ~ alpha^2 (1 + 1 / (2 mu^2))` (GGX;
    /// Beckmann's tail is thinner), bounded here by twice that.
    #[test]
    fn albedo_limits(alpha in alpha(), mu in 1e-3f64..=1.0) {
        for model in models() {
            let grazing = reference_albedo(model, alpha, 0.0, &quick_reference());
            let sampled = albedo(model, alpha, 0.0, &small_qmc());
            match model.masking {
                Masking::HeightCorrelated => {
                    // mu = 0 itself is answered by a shortcut (albedo_is_exactly_one); the limit
                    // is checked through the integration: deep inside the grazing layer
                    // (mu = 1e-6 min(alpha, 1)), 1 - E is below 1e-4 at every alpha up to 4
                    // (5.1e-5 at alpha 4, GGX), where the layer's own scale (mu = alpha) loses
                    // about 0.108.
                    prop_assert_eq!(grazing.value, 1.0);
                    prop_assert_eq!(sampled.value, 1.0);
                    if alpha > 0.0 {
                        let deep = 1e-6 * alpha.min(1.0);
                        let limit = reference_albedo(model, alpha, deep, &quick_reference());
                        prop_assert!(
                            limit.one_minus_value <= 1e-4,
                            "{model:?} alpha {alpha:e}: 1 - E({deep:e}) = {:e}",
                            limit.one_minus_value
                        );
                    }
                }
                Masking::Separable => {
                    prop_assert!(grazing.value < 1.0 && sampled.value < 1.0, "{model:?} {alpha:e}");
                }
                Masking::SchlickGgx => unreachable!("models() holds the Smith forms"),
            }
            let smooth_alpha = alpha * 1e-3 * mu;
            let near_mirror = reference_albedo(model, smooth_alpha, mu, &quick_reference());
            let bound = 2.0 * smooth_alpha.powi(2) * (1.0 + 1.0 / (mu * mu)) + 1e-12;
            prop_assert!(
                near_mirror.one_minus_value <= bound,
                "{model:?} alpha {smooth_alpha:e} mu {mu}: 1 - E = {:e} > {bound:e}",
                near_mirror.one_minus_value
            );
        }
    }

    /// `E` is continuous through the smooth-surface threshold, where kiln switches from direct
    /// evaluation to the boundary layer's similarity.
    #[test]
    fn albedo_is_continuous_at_the_smooth_threshold(x in 0.0f64..1e3) {
        for model in models() {
            let below = SMOOTH_ALPHA * (1.0 - 1e-9);
            let above = SMOOTH_ALPHA * (1.0 + 1e-9);
            let e = |alpha: f64| reference_albedo(model, alpha, (x * alpha).min(1.0), &quick_reference());
            let (b, a) = (e(below), e(above));
            prop_assert!((b.value - a.value).abs() <= 1e-8 + b.error + a.error,
                "{model:?} x {x}: {} vs {}", b.value, a.value);
        }
    }

    /// Visible-normal samples: unit vectors facing the viewer, with a positive finite density
    /// `D(m) (o.m) / projected_area(mu)` (= `G1(o) (o.m)+ D(m) / mu`).
    #[test]
    fn visible_normals_are_unit_with_positive_density(
        alpha in (-9.0f64..0.6).prop_map(|e| 10f64.powf(e).min(4.0)),
        mu in mu(),
        u0 in 0.0f64..1.0,
        u1 in 0.0f64..1.0,
    ) {
        fn check<N: MicrofacetDistribution>(ndf: N, mu: f64, u: [f64; 2]) -> Result<(), TestCaseError> {
            let o = Vec3::from_mu(mu);
            let m = ndf.sample_visible_normal(o, u);
            prop_assert!((m.length_squared() - 1.0).abs() < 1e-12, "{m:?}");
            prop_assert!(m.z >= 0.0 && o.dot(m) >= 0.0, "{m:?} for {o:?}");
            let density = ndf.d(m.z) * o.dot(m) / ndf.projected_area(mu);
            prop_assert!(density.is_finite(), "{m:?}: {density}");
            // A sample on the visible hemisphere's rim (o.m = 0) has zero density; every other
            // sample a positive one.
            prop_assert!(density > 0.0 || o.dot(m) < 1e-12, "{m:?}: {density}");
            Ok(())
        }
        check(Ggx { alpha }, mu, [u0, u1])?;
        check(Beckmann { alpha }, mu, [u0, u1])?;
    }
}

/// Hard points against the deterministic reference: grazing views at a near-mirror and a rough
/// surface, and `alpha = 2`. The QMC estimate (kiln's default sample count) must agree within 5
/// standard errors plus the reference's own error estimate; the reference must converge.
#[test]
fn hard_points_agree_with_the_reference() {
    let settings = QmcSettings::default();
    let points = [
        (1e-3, 1e-4),
        (1.0, 1e-4),
        (2.0, 1e-4),
        (2.0, 0.5),
        (2.0, 1.0),
        (1e-3, 1e-3),
        (1e-4, 1e-12),
    ];
    for model in models() {
        for (alpha, mu) in points {
            let r = reference_albedo(model, alpha, mu, &ReferenceSettings::default());
            assert!(
                r.converged,
                "{model:?} alpha {alpha} mu {mu}: reference did not converge"
            );
            let q = albedo(model, alpha, mu, &settings);
            let error = (q.one_minus_value - r.one_minus_value).abs();
            assert!(
                error <= 5.0 * q.std_error + r.error + 1e-12,
                "{model:?} alpha {alpha} mu {mu}: qmc {} reference {} (se {:.1e})",
                q.value,
                r.value,
                q.std_error
            );
        }
    }
}
