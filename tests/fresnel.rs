//! Fresnel-weighted albedo `E_F(mu) = ∫ F(o.h) f mu_i dω_i`: QMC against the reference at
//! ordinary and grazing points, and the identities that tie the weighted integrals to `E`.

use crate::common;

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

/// `kiln bake --quantity e-scale,e-bias,e`: the split-sum channels meet the requested max error,
/// add up to `E` at every node, survive every output format, and refuse the adaptive mu axis.
#[test]
fn split_sum_tables_bake_verify_and_round_trip() {
    use kiln::format::replace::Replace;
    use kiln::format::{Format, Precision, write_tables};
    use kiln::verify::input::read_kiln;
    use kiln::{BakeOptions, MuMapping, Quantity};
    let options = BakeOptions {
        size: 8,
        quantities: vec![Quantity::EScale, Quantity::EBias, Quantity::E],
        mu_mapping: Some(MuMapping::Linear),
        max_error: Some(1e-6),
        ..BakeOptions::default()
    };
    let tables = options.bake(&|_| {}).unwrap();
    assert_eq!(tables.len(), 3);
    let (scale, bias, e) = (&tables[0], &tables[1], &tables[2]);
    assert_eq!(scale.spec.quantity, Quantity::EScale);
    // Each channel against the tests' own quadrature (tests/common), where it holds to 1e-9:
    // scale weights the BRDF by 1 - (1 - c)^5, bias by (1 - c)^5 (a wrong D, G2, Jacobian or
    // weight in kiln's integrals moves them; the sum scale + bias = E below would not see it).
    let weights: [&dyn Fn(f64) -> f64; 3] = [
        &|c: f64| 1.0 - (1.0 - c).powi(5),
        &|c: f64| (1.0 - c).powi(5),
        &|_| 1.0,
    ];
    for (table, weight) in tables.iter().zip(weights) {
        for k in 0..table.spec.len() {
            let (alpha, mu) = table.spec.texel_coordinates(k);
            let mu = mu.unwrap();
            if mu >= 0.02 && alpha >= 0.05 {
                let independent = common::reference_weighted_e(table.spec.model, alpha, mu, weight);
                assert!(
                    (table.value[k] - independent).abs() <= 1e-6 + 1e-9,
                    "{} texel {k}: {} vs {independent}",
                    table.spec.id(),
                    table.value[k]
                );
            }
        }
    }
    for k in 0..e.spec.len() {
        assert!(
            (scale.value[k] + bias.value[k] - e.value[k]).abs() <= 2e-6,
            "texel {k}"
        );
    }
    // Every format writes them; kiln's readers give back the f32 values and the quantity.
    let dir = tempfile::tempdir().unwrap();
    write_tables(
        dir.path(),
        &tables,
        &Format::ALL,
        Precision::F32,
        Replace::Refuse,
    )
    .unwrap();
    for name in ["E_scale", "E_bias"] {
        let original = if name == "E_scale" { scale } else { bias };
        // The linear mu axis is in the name (not kiln's default layout).
        let id = format!("ggx-height-correlated-{name}-mu-linear");
        assert_eq!(original.spec.id(), id);
        for extension in ["json", "exr", "bin"] {
            let path = dir.path().join(format!("{id}.{extension}"));
            let back = read_kiln(&path).unwrap().expect("a kiln file");
            assert_eq!(back.spec.quantity.symbol(), name, "{extension}");
            for k in 0..original.spec.len() {
                assert!(
                    (back.value[k] - original.value[k]).abs() <= 1e-7,
                    "{name}.{extension}"
                );
            }
        }
        let rust = std::fs::read_to_string(dir.path().join(format!("{id}.rs"))).unwrap();
        assert!(rust.contains(&format!(
            "GGX_HEIGHT_CORRELATED_{}_MU_LINEAR",
            name.to_uppercase()
        )));
    }
    let metadata = kiln::format::metadata::Metadata::new(bias, "f32");
    assert!(metadata.description.contains("Fc = (1 - o.h)^5"));

    // The adaptive mu axis cannot hold a split-sum channel at roughness 0; kiln names its own.
    let adaptive = BakeOptions {
        mu_mapping: Some(MuMapping::Adaptive),
        ..options
    };
    let error = adaptive.validate().unwrap_err().to_string();
    assert!(error.contains("--mu-axis split-sum"), "{error}");
}

/// A QMC split-sum bake agrees with the reference within its standard errors where QMC is not
/// dominated by rare events (alpha >= 0.04 here; at alpha -> 0 and mu = 0 the loss sits in GGX's
/// far tail, as for `E`: README, Known limits).
#[test]
fn split_sum_qmc_tables_match_the_reference() {
    use kiln::{BakeOptions, MuMapping, Quantity};
    let options = BakeOptions {
        size: 6,
        quantities: vec![Quantity::EBias],
        mu_mapping: Some(MuMapping::Linear),
        samples: 1 << 14,
        max_error: None,
        ..BakeOptions::default()
    };
    let table = &options.bake(&|_| {}).unwrap()[0];
    let settings = ReferenceSettings::default();
    for k in 0..table.spec.len() {
        let (alpha, mu) = table.spec.texel_coordinates(k);
        if alpha < 0.04 {
            continue;
        }
        let truth = table.spec.integral().reference(
            kiln::integrate::value::Point {
                alpha,
                mu,
                eta: None,
            },
            &settings,
        );
        assert!(
            (table.value[k] - truth.value).abs() <= 5.0 * table.std_error[k] + 1e-9,
            "texel {k} (alpha {alpha}, mu {mu:?}): {} ± {:.1e} vs {}",
            table.value[k],
            table.std_error[k],
            truth.value
        );
    }
}

/// `kiln bake --f0 ... / --ior ...`: a Fresnel-weighted `E_F` table for that model. Schlick's
/// equals `F0 E_scale + F90 E_bias` from the split-sum tables (separate quadratures), the
/// dielectric's is confirmed against its reference, and the options that cannot make one fail.
#[test]
fn fresnel_weighted_tables_bake_for_the_model_named() {
    use kiln::{BakeOptions, MuMapping, Quantity};
    let base = BakeOptions {
        size: 6,
        mu_mapping: Some(MuMapping::Sqrt),
        max_error: Some(1e-6),
        ..BakeOptions::default()
    };
    let split = BakeOptions {
        quantities: vec![Quantity::EScale, Quantity::EBias],
        ..base.clone()
    }
    .bake(&|_| {})
    .unwrap();
    for (f0, f90) in [(0.04, 1.0), (0.5, 0.8)] {
        let fresnel = Fresnel::Schlick {
            f0: [f0; 3],
            f90: [f90; 3],
        };
        let table = &BakeOptions {
            quantities: vec![Quantity::EF],
            fresnel: Some(fresnel),
            ..base.clone()
        }
        .bake(&|_| {})
        .unwrap()[0];
        assert_eq!(table.spec.fresnel, Some(fresnel));
        assert_eq!(
            table.spec.id(),
            format!("ggx-height-correlated-E_F-schlick-{f0}-{f90}-mu-sqrt")
        );
        for k in 0..table.spec.len() {
            let (alpha, mu) = table.spec.texel_coordinates(k);
            let mu = mu.unwrap();
            if mu >= 0.02 && alpha >= 0.05 {
                let schlick = |c: f64| f0 + (f90 - f0) * (1.0 - c).powi(5);
                let independent =
                    common::reference_weighted_e(table.spec.model, alpha, mu, &schlick);
                assert!(
                    (table.value[k] - independent).abs() <= 1e-6 + 1e-9,
                    "texel {k}: {} vs {independent}",
                    table.value[k]
                );
            }
            let combined = f0 * split[0].value[k] + f90 * split[1].value[k];
            assert!(
                (table.value[k] - combined).abs() <= 3e-6,
                "texel {k}: {} vs {combined}",
                table.value[k]
            );
        }
    }
    let glass = &BakeOptions {
        quantities: vec![Quantity::EF],
        fresnel: Some(Fresnel::Dielectric { eta: 1.0 / 1.5 }),
        ..base.clone()
    }
    .bake(&|_| {})
    .unwrap()[0];
    // The dielectric seen from outside (eta = 1.5, a smooth Fresnel: the tests' quadrature holds
    // to 1e-9 there; inside, total internal reflection puts a kink in the integrand that it
    // resolves only to about 1e-4) against the tests' own quadrature.
    let outside = &BakeOptions {
        quantities: vec![Quantity::EF],
        fresnel: Some(Fresnel::Dielectric { eta: 1.5 }),
        ..base.clone()
    }
    .bake(&|_| {})
    .unwrap()[0];
    for k in 0..outside.spec.len() {
        let (alpha, mu) = outside.spec.texel_coordinates(k);
        let mu = mu.unwrap();
        if mu >= 0.02 && alpha >= 0.05 {
            let fresnel = |c: f64| kiln::model::fresnel::dielectric(1.5, c);
            let independent = common::reference_weighted_e(outside.spec.model, alpha, mu, &fresnel);
            assert!(
                (outside.value[k] - independent).abs() <= 1e-6 + 1e-9,
                "texel {k}: {} vs {independent}",
                outside.value[k]
            );
        }
    }
    // The mirror row: E_F = F(mu), exactly for mu > 0 (at mu = 0, the limit alpha -> 0 of a
    // grazing view, F = 1, to the max error).
    for k in 0..6 {
        let mu = glass.spec.texel_coordinates(k).1.unwrap();
        let f = kiln::model::fresnel::dielectric(1.0 / 1.5, mu);
        if mu > 0.0 {
            assert_eq!(glass.value[k], f);
        } else {
            assert!((glass.value[k] - f).abs() <= 1e-6);
        }
    }
    for (options, needle) in [
        (
            BakeOptions {
                quantities: vec![Quantity::EF],
                ..base.clone()
            },
            "needs a Fresnel model",
        ),
        (
            BakeOptions {
                fresnel: Some(Fresnel::Dielectric { eta: 1.5 }),
                ..base.clone()
            },
            "add --quantity e-f",
        ),
        (
            BakeOptions {
                quantities: vec![Quantity::EF],
                fresnel: Some(Fresnel::Conductor {
                    eta: [0.2, 0.9, 1.1],
                    k: [3.1; 3],
                }),
                ..base.clone()
            },
            "one table per channel",
        ),
        (
            BakeOptions {
                quantities: vec![Quantity::EF],
                fresnel: Some(Fresnel::Dielectric { eta: 1.5 }),
                mu_mapping: Some(MuMapping::Adaptive),
                ..base.clone()
            },
            "E_F = F(mu)",
        ),
    ] {
        let error = options.validate().unwrap_err().to_string();
        assert!(error.contains(needle), "{needle}: {error}");
    }
}
