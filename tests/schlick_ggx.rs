//! The separable Schlick-GGX masking (`k = alpha / 2`) engines evaluate, as a model option:
//! its reference against closed forms and an independent integral, QMC against the reference,
//! and a bake.

use kiln::integrate::gauss_kronrod::integrate;
use kiln::integrate::reference::{ReferenceSettings, reference_albedo, reference_average_albedo};
use kiln::integrate::{QmcSettings, albedo, average_albedo};
use kiln::model::{Ggx, MicrofacetDistribution};
use kiln::{BakeOptions, Masking, Model, MuMapping, Ndf, Quantity};
use std::f64::consts::PI;

const SCHLICK: Model = Model {
    ndf: Ndf::Ggx,
    masking: Masking::SchlickGgx,
};

/// At `alpha = 1`, `k = 1/2` makes Schlick's `G1 = 2 mu / (1 + mu)`, Smith's GGX `G1` exactly:
/// the two separable models have the same albedo.
#[test]
fn equals_smith_separable_at_alpha_one() {
    let s = ReferenceSettings::default();
    let separable = Model {
        ndf: Ndf::Ggx,
        masking: Masking::Separable,
    };
    for mu in [0.0, 0.05, 0.5, 1.0] {
        let a = reference_albedo(SCHLICK, 1.0, mu, &s);
        let b = reference_albedo(separable, 1.0, mu, &s);
        assert!(
            (a.value - b.value).abs() < 1e-10,
            "{mu}: {} {}",
            a.value,
            b.value
        );
    }
    let a = reference_average_albedo(SCHLICK, 1.0, &s);
    assert!((a.value - 0.376_634_61).abs() < 1e-8, "{}", a.value);
}

/// At normal incidence the albedo is a 1-D integral over the normal's polar angle:
/// `E(1) = 2 pi ∫ D(theta) G1(1) G1(cos 2 theta) cos(theta) sin(theta) dtheta` over
/// `[0, pi / 4]` (the reflected direction leaves the hemisphere beyond), `G1(1) = 1`.
#[test]
fn matches_an_independent_integral_at_normal_incidence() {
    for alpha in [0.05, 0.3, 0.7] {
        let ndf = Ggx { alpha };
        let k = alpha / 2.0;
        let q = integrate(
            |theta: f64| {
                let mu_i = (2.0 * theta).cos();
                let g1 = mu_i / (mu_i * (1.0 - k) + k);
                [2.0 * PI * ndf.d(theta.cos()) * g1 * theta.cos() * theta.sin()]
            },
            0.0,
            PI / 4.0,
            1e-13,
            400,
        );
        let r = reference_albedo(SCHLICK, alpha, 1.0, &ReferenceSettings::default());
        assert!(
            (q.value[0] - r.value).abs() < 1e-9,
            "alpha {alpha}: {} vs {}",
            q.value[0],
            r.value
        );
    }
}

/// QMC within 4 standard errors of the reference, at ordinary and grazing points.
#[test]
fn qmc_agrees_with_the_reference() {
    let q = QmcSettings::default();
    let s = ReferenceSettings::default();
    for (alpha, mu) in [(0.5, 0.5), (0.1, 0.05), (0.3, 0.0), (0.8, 1.0)] {
        let truth = reference_albedo(SCHLICK, alpha, mu, &s);
        let e = albedo(SCHLICK, alpha, mu, &q);
        assert!(
            (e.value - truth.value).abs() < 4.0 * e.std_error + truth.error,
            "{alpha} {mu}: {} ± {:e} vs {}",
            e.value,
            e.std_error,
            truth.value
        );
    }
    let truth = reference_average_albedo(SCHLICK, 0.5, &s);
    let e = average_albedo(SCHLICK, 0.5, &q);
    assert!((e.value - truth.value).abs() < 4.0 * e.std_error + truth.error);
}

/// Baked like any other model (its own E_avg rule: the adaptive one), and refused with Beckmann.
#[test]
fn bakes_and_refuses_beckmann() {
    let options = BakeOptions {
        maskings: vec![Masking::SchlickGgx],
        size: 5,
        max_error: Some(1e-6),
        // Point samples, exact to the bound at every node.
        texels: Some(kiln::table::Texels::Nodes),
        ..BakeOptions::default()
    };
    let tables = options.bake(&|_| {}).unwrap();
    assert_eq!(tables[0].spec.id(), "ggx-schlick-ggx-E-nodes");
    for t in tables
        .iter()
        .filter(|t| t.spec.quantity != Quantity::FMsNorm)
    {
        assert!(t.node_errors.unwrap().max <= 1e-6);
    }
    // Its split-sum channels add up to its E (Godot imports this model's DFG table).
    let split = BakeOptions {
        quantities: vec![Quantity::EScale, Quantity::EBias, Quantity::E],
        mu_mapping: Some(MuMapping::Linear),
        ..options.clone()
    }
    .bake(&|_| {})
    .unwrap();
    for k in 0..split[0].spec.len() {
        let sum = split[0].value[k] + split[1].value[k];
        assert!((sum - split[2].value[k]).abs() <= 2e-6, "texel {k}: {sum}");
    }
    let error = BakeOptions {
        ndfs: vec![Ndf::Beckmann],
        ..options
    }
    .validate()
    .unwrap_err()
    .to_string();
    assert!(error.contains("--ndf ggx only"), "{error}");
}
