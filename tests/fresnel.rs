//! Fresnel-weighted albedo `E_F(mu) = ∫ F(o.h) f mu_i dω_i`: QMC against the reference at
//! ordinary and grazing points, and the identities that tie the weighted integrals to `E`.

use kiln::integrate::albedo::weighted_albedo;
use kiln::integrate::reference::{ReferenceSettings, reference_albedo, reference_weighted_albedo};
use kiln::{Fresnel, Masking, Model, Ndf, QmcSettings};

fn models() -> Vec<Model> {
    let mut all = Vec::new();
    for ndf in Ndf::ALL {
        for masking in Masking::ALL {
            all.push(Model { ndf, masking });
        }
    }
    all
}

fn schlick(f0: f64) -> impl Fn(f64) -> f64 + Copy {
    move |c: f64| {
        Fresnel::Schlick {
            f0: [f0; 3],
            f90: [1.0; 3],
        }
        .reflectance(c)[0]
    }
}

/// QMC agrees with the reference within its standard error (four of them, plus the reference's
/// own estimate) for Schlick F0 = 0.04 and 0.5, at ordinary and grazing points, for both
/// distributions and both masking forms.
#[test]
fn qmc_agrees_with_the_reference() {
    let settings = QmcSettings {
        samples: 1 << 15,
        scrambles: 8,
        seed: 3,
    };
    let reference = ReferenceSettings::default();
    let mut worst: f64 = 0.0;
    for model in models() {
        for f0 in [0.04, 0.5] {
            for (alpha, mu) in [
                (0.25, 0.5),
                (0.6, 0.9),
                (0.1, 0.02),
                (0.5, 0.01),
                (1.0, 0.0),
            ] {
                let qmc = weighted_albedo(model, alpha, mu, schlick(f0), &settings);
                let truth = reference_weighted_albedo(model, alpha, mu, schlick(f0), &reference);
                assert!(truth.converged, "{model:?} {alpha} {mu}");
                let error = (qmc.value - truth.value).abs();
                assert!(
                    error <= 4.0 * qmc.std_error + truth.error + 1e-10,
                    "{model:?} F0 {f0} alpha {alpha} mu {mu}: {} ± {:.1e} vs {}",
                    qmc.value,
                    qmc.std_error,
                    truth.value
                );
                assert!((qmc.value + qmc.one_minus_value - 1.0).abs() < 1e-12);
                worst = worst.max(error / qmc.std_error.max(1e-300));
            }
        }
    }
    // The standard errors are not wildly pessimistic either.
    assert!(worst > 0.2, "{worst}");
}

/// With `h = 1` the weighted reference is `E`; Schlick's `E_F` is linear in `F0` and `F90`, so
/// the split-sum channels `scale = ∫ (1 - Fc) w` and `bias = ∫ Fc w` sum to `E` and give any
/// `E_F = F0 scale + F90 bias`; a dielectric's `E_F` lies below `E`.
#[test]
fn weighted_integrals_are_consistent_with_e() {
    let settings = ReferenceSettings::default();
    let fc = |c: f64| (1.0 - c).powi(5);
    for model in models() {
        for (alpha, mu) in [(0.3, 0.7), (0.05, 0.1), (0.8, 1.0)] {
            let e = reference_albedo(model, alpha, mu, &settings);
            let one = reference_weighted_albedo(model, alpha, mu, |_| 1.0, &settings);
            assert!((one.value - e.value).abs() < 1e-13, "{model:?}");
            let bias = reference_weighted_albedo(model, alpha, mu, fc, &settings);
            let scale = reference_weighted_albedo(model, alpha, mu, |c| 1.0 - fc(c), &settings);
            assert!(
                (scale.value + bias.value - e.value).abs() < 1e-10,
                "{model:?}"
            );
            let f0 = 0.04;
            let direct = reference_weighted_albedo(model, alpha, mu, schlick(f0), &settings);
            assert!((direct.value - (f0 * scale.value + bias.value)).abs() < 1e-10);
            let glass = Fresnel::Dielectric { eta: 1.5 };
            let e_f = reference_weighted_albedo(
                model,
                alpha,
                mu,
                move |c| glass.reflectance(c)[0],
                &settings,
            );
            assert!(e_f.value < e.value && e_f.value > 0.0, "{model:?}");
        }
    }
    // A mirror reflects with F(mu).
    let model = models()[0];
    let mirror = reference_weighted_albedo(model, 0.0, 0.6, schlick(0.04), &settings);
    assert_eq!(mirror.value, schlick(0.04)(0.6));
}
