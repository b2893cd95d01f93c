//! Anisotropic GGX's albedo (`kiln eval --alpha-x --alpha-y [--phi]`) against an integrator
//! written here from scratch: over the incident directions (kiln integrates over microfacet
//! normals), with `D` and Smith's `Lambda` from Heitz 2014 (eqs. 85 and 86) typed anew; the
//! azimuthal average by the trapezoid rule over a period (spectrally accurate for a smooth
//! periodic function); the values the issue measured; a physical identity (`E(mu = 1)` cannot
//! depend on the azimuth); and the refusals.

use crate::command;
use crate::common;

use std::f64::consts::PI;

/// `E(mu, phi)` of anisotropic GGX (height-correlated, `F = 1`) by composite Gauss-Legendre over
/// the incident direction `(mu_i, phi_i)`: `E = ∫ D(h) G2(o, i) / (4 mu) dmu_i dphi_i`.
fn independent_e(alpha_x: f64, alpha_y: f64, mu: f64, phi: f64) -> f64 {
    let lambda = |v: [f64; 3]| {
        let a = ((alpha_x * v[0]).powi(2) + (alpha_y * v[1]).powi(2)) / (v[2] * v[2]);
        ((1.0 + a).sqrt() - 1.0) / 2.0
    };
    let d = |h: [f64; 3]| {
        let q = (h[0] / alpha_x).powi(2) + (h[1] / alpha_y).powi(2) + h[2] * h[2];
        1.0 / (PI * alpha_x * alpha_y * q * q)
    };
    let so = (1.0 - mu * mu).sqrt();
    let o = [so * phi.cos(), so * phi.sin(), mu];
    let lambda_o = lambda(o);
    let rule = common::gauss_legendre(8);
    let (mu_panels, phi_panels) = (240, 480);
    let mut total = 0.0;
    for p in 0..mu_panels {
        let (a, b) = (
            p as f64 / mu_panels as f64,
            (p + 1) as f64 / mu_panels as f64,
        );
        for &(x, w) in &rule {
            let mu_i = 0.5 * (a + b) + 0.5 * (b - a) * x;
            let w_mu = 0.5 * (b - a) * w;
            let si = (1.0 - mu_i * mu_i).sqrt();
            let mut ring = 0.0;
            for q in 0..phi_panels {
                let width = 2.0 * PI / phi_panels as f64;
                let start = q as f64 * width;
                for &(y, v) in &rule {
                    let phi_i = start + 0.5 * width * (1.0 + y);
                    let i = [si * phi_i.cos(), si * phi_i.sin(), mu_i];
                    let h = [o[0] + i[0], o[1] + i[1], o[2] + i[2]];
                    let n = (h[0] * h[0] + h[1] * h[1] + h[2] * h[2]).sqrt();
                    let h = [h[0] / n, h[1] / n, h[2] / n];
                    let g2 = 1.0 / (1.0 + lambda_o + lambda(i));
                    ring += 0.5 * width * v * d(h) * g2;
                }
            }
            total += w_mu * ring;
        }
    }
    total / (4.0 * mu)
}

/// `kiln eval ... --json`'s `value` and `std_error`.
fn kiln_e(args: &[&str]) -> (f64, f64) {
    let output = command::kiln(args);
    assert!(
        output.status.success(),
        "{args:?}: {}",
        command::stderr(&output)
    );
    let json: serde_json::Value = serde_json::from_slice(&output.stdout).expect("one JSON object");
    assert_eq!(json["converged"], true, "{json}");
    (
        json["value"].as_f64().unwrap(),
        json["std_error"].as_f64().unwrap(),
    )
}

/// kiln's isotropic reference `E` at the lobe's geometric mean, `alpha = 0.3`, `mu =
/// 0.9`: what Cycles reads for `alpha = (0.9, 0.1)`.
fn geometric_mean_reading() -> f64 {
    kiln_e(&[
        "eval",
        "--alpha",
        "0.3",
        "--mu",
        "0.9",
        "--method",
        "reference",
        "--json",
    ])
    .0
}

fn reference(alpha_x: f64, alpha_y: f64, mu: f64, phi: Option<f64>) -> (f64, f64) {
    let (ax, ay, mu) = (alpha_x.to_string(), alpha_y.to_string(), mu.to_string());
    let mut args = vec![
        "eval",
        "--alpha-x",
        &ax,
        "--alpha-y",
        &ay,
        "--mu",
        &mu,
        "--method",
        "reference",
        "--json",
    ];
    let phi = phi.map(|p| p.to_string());
    if let Some(phi) = &phi {
        args.extend(["--phi", phi]);
    }
    kiln_e(&args)
}

/// kiln's reference within 1e-7 of the independent integrator, at one azimuth, from a near-mirror
/// axis (`alpha_y = 0.05`) to `alpha_x = 1.5`, from grazing (`mu = 0.05`) to normal.
#[test]
fn the_albedo_at_an_azimuth_matches_an_independent_integrator() {
    for (ax, ay, mu, phi) in [
        (0.9, 0.1, 0.9, 0.0),
        (0.9, 0.1, 0.9, PI / 2.0),
        (0.5, 0.05, 0.3, 0.7),
        (0.2, 0.6, 0.05, 2.5),
        (1.5, 0.3, 0.6, -1.0),
    ] {
        let (value, error) = reference(ax, ay, mu, Some(phi));
        let expected = independent_e(ax, ay, mu, phi);
        assert!(
            (value - expected).abs() < 1e-7,
            "alpha ({ax}, {ay}), mu {mu}, phi {phi}: kiln {value} vs {expected}"
        );
        assert!(error < 1e-9, "{error}");
    }
}

/// The measurement (its own integrator): `E = 0.594` along x and `0.578` along y at
/// `alpha = (0.9, 0.1)`, `mu = 0.9`, where the geometric mean's isotropic `E` is 0.868 (kiln
/// 0.867498: the third digit within a unit).
#[test]
fn the_published_values_are_met() {
    let (along_x, _) = reference(0.9, 0.1, 0.9, Some(0.0));
    let (along_y, _) = reference(0.9, 0.1, 0.9, Some(PI / 2.0));
    assert!((along_x - 0.594).abs() < 5e-4, "{along_x}");
    assert!((along_y - 0.578).abs() < 5e-4, "{along_y}");
    let isotropic = geometric_mean_reading();
    assert!((isotropic - 0.868).abs() < 1e-3, "{isotropic}");
}

/// The azimuthal average (no `--phi`) is the mean of `E` over a period, taken here by the
/// trapezoid rule on 12 azimuths of `[0, pi)` (`E` has period `pi`), each by the independent
/// integrator; and the QMC estimate of it agrees within its standard error.
#[test]
fn the_azimuthal_average_is_the_mean_over_a_period() {
    let (ax, ay, mu) = (0.9, 0.1, 0.6);
    let n = 12;
    let mean = (0..n)
        .map(|k| independent_e(ax, ay, mu, PI * k as f64 / n as f64))
        .sum::<f64>()
        / n as f64;
    let (value, _) = reference(ax, ay, mu, None);
    assert!((value - mean).abs() < 1e-7, "kiln {value} vs {mean}");
    let (qmc, std_error) = kiln_e(&[
        "eval",
        "--alpha-x",
        "0.9",
        "--alpha-y",
        "0.1",
        "--mu",
        "0.6",
        "--json",
    ]);
    assert!(
        (qmc - mean).abs() < 5.0 * std_error,
        "{qmc} ± {std_error} vs {mean}"
    );
}

/// At normal incidence the view has no azimuth: every `phi` gives the same `E`, which the
/// integrand reaches by different normals at each `phi` (the outer breaks move with it).
#[test]
fn at_normal_incidence_the_azimuth_does_not_matter() {
    let (first, _) = reference(0.7, 0.15, 1.0, Some(0.0));
    for phi in [0.3, 1.2, 2.9] {
        let (value, _) = reference(0.7, 0.15, 1.0, Some(phi));
        assert!(
            (value - first).abs() < 1e-10,
            "phi {phi}: {value} vs {first}"
        );
    }
}

/// A roughness and an anisotropy through a convention give the lobe of the convention's
/// formula: `--roughness 0.5 --anisotropy 0.5` in Kulla-Conty's is `alpha = (0.375, 0.125)`.
#[test]
fn an_anisotropy_is_read_through_its_convention() {
    let (by_convention, _) = kiln_e(&[
        "eval",
        "--roughness",
        "0.5",
        "--anisotropy",
        "0.5",
        "--mu",
        "0.4",
        "--phi",
        "0.5",
        "--method",
        "reference",
        "--json",
    ]);
    let (by_alphas, _) = reference(0.375, 0.125, 0.4, Some(0.5));
    assert_eq!(by_convention, by_alphas);
}

/// Out-of-range values are refused with their range, and the anisotropic flags with what they
/// do not go with.
#[test]
fn bad_anisotropic_input_is_refused_with_the_range() {
    command::refused(
        &[
            "eval",
            "--roughness",
            "0.5",
            "--anisotropy",
            "1.2",
            "--mu",
            "0.3",
        ],
        &["anisotropy 1.2", "[0, 0.99]", "kulla-conty"],
    );
    command::refused(
        &["eval", "--alpha-x", "0.5", "--alpha-y", "0", "--mu", "0.3"],
        &["alpha_y = 0", "(0, 1000]"],
    );
    command::refused(
        &[
            "eval",
            "--alpha-x",
            "0.5",
            "--alpha-y",
            "0.2",
            "--mu",
            "0.3",
            "--phi",
            "7",
        ],
        &["phi = 7", "[-2 pi, 2 pi]"],
    );
    command::refused(
        &["eval", "--alpha", "0.5", "--mu", "0.3", "--phi", "1"],
        &["--phi", "--alpha-x"],
    );
    command::refused(
        &[
            "eval",
            "--alpha-x",
            "0.5",
            "--alpha-y",
            "0.2",
            "--quantity",
            "e-avg",
        ],
        &["--quantity e-avg"],
    );
}

/// The audit of an engine's reading at the lobe: Disney's convention at `alpha = 0.3`
/// and `a = 8 / 9 / 0.9` (`aspect = 1/3`) is `alpha = (0.9, 0.1)`, read at the geometric mean
/// 0.3. The audit's truth is the independent integrator's, its read value kiln's isotropic `E`,
/// and the worst error is along y (0.29; 0.27 along x).
#[test]
fn the_audit_compares_the_lobe_with_the_isotropic_value_the_engine_reads() {
    use kiln::model::AnisotropyConvention;
    use kiln::verify::anisotropy::{AnisotropyGrid, audit_anisotropy};
    let grid = AnisotropyGrid {
        roughness: vec![0.3f64.sqrt()],
        anisotropy: vec![8.0 / 9.0 / 0.9],
        mu: vec![0.9],
        phi: vec![0.0, PI / 2.0],
    };
    let audit = audit_anisotropy(AnisotropyConvention::Disney, &grid).unwrap();
    assert_eq!(audit.points, 2);
    let isotropic = geometric_mean_reading();
    for p in &audit.compared {
        assert!(
            (p.alpha_x - 0.9).abs() < 1e-12 && (p.alpha_y - 0.1).abs() < 1e-12,
            "{p:?}"
        );
        let truth = independent_e(0.9, 0.1, 0.9, p.phi);
        assert!((p.truth - truth).abs() < 1e-7, "{p:?} vs {truth}");
        assert!((p.read - isotropic).abs() < 1e-9, "{p:?}");
    }
    assert!(
        (audit.max_error - (isotropic - 0.578_363_4)).abs() < 1e-6,
        "{audit:?}"
    );
    assert_eq!(audit.worst.phi, PI / 2.0);
    assert!((audit.max_azimuthal_spread - (0.594_323_5 - 0.578_363_4)).abs() < 1e-6);
}

/// `kiln verify-anisotropy` refuses what it does not audit: it takes no model flags and no
/// table.
#[test]
fn the_anisotropy_audit_refuses_other_models() {
    command::refused(
        &["verify-anisotropy", "rms", "--ndf", "beckmann"],
        &["--ndf"],
    );
    command::refused(
        &["verify-anisotropy", "rms", "tables/ggx_E.exr"],
        &["tables/ggx_E.exr"],
    );
}

/// `kiln anisotropic --bake` of a small table writes a document that `--table` reads back and
/// runs the furnace of; a lookup between samples within the furnace's measure of the truth at
/// the independent integrator's point; a file whose values were tampered with is refused by
/// name before any lookup.
#[test]
fn an_anisotropic_table_bakes_reads_back_and_refuses_tampering() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    let baked = command::kiln(&[
        "anisotropic",
        "--bake",
        out,
        "--size",
        "12,5,6,3",
        "--points",
        "64",
        "-q",
    ]);
    assert!(baked.status.success(), "{}", command::stderr(&baked));
    let json = dir.path().join("ggx-anisotropic-kulla-conty-E.json");
    let bin = std::fs::read(dir.path().join("ggx-anisotropic-kulla-conty-E.bin")).unwrap();
    assert_eq!(bin.len(), 12 * 5 * 6 * 3 * 4);
    let table = kiln::format::anisotropic::decode(&std::fs::read(&json).unwrap(), "t").unwrap();
    // The f32 file holds the document's values in its order.
    let first = f32::from_le_bytes(bin[4..8].try_into().unwrap());
    assert_eq!(first, table.values[1] as f32);
    // A lookup at a sample of the table is the independent integrator's value there.
    let (a, r, ndf) = kiln::table::anisotropic::AnisotropicTable::lobe(
        table.convention,
        table.max_anisotropy,
        &table.sizes,
        2,
        4,
    );
    let (phi, alpha_phi) = kiln::table::anisotropic::azimuth_at(ndf.alpha_x, ndf.alpha_y, 0.5);
    let mu = kiln::integrate::grazing::mu_of_t(7.0 / 11.0, alpha_phi);
    let truth = independent_e(ndf.alpha_x, ndf.alpha_y, mu, phi);
    let read = table.lookup(mu, phi, r, a);
    assert!((read - truth).abs() < 1e-4, "{read} vs {truth}");
    let checked = command::kiln(&[
        "anisotropic",
        "--table",
        json.to_str().unwrap(),
        "--points",
        "32",
        "--json",
    ]);
    assert!(checked.status.success(), "{}", command::stderr(&checked));
    let report: serde_json::Value = serde_json::from_slice(&checked.stdout).unwrap();
    assert_eq!(report["points"], 32);
    assert!(report["max_lookup_error"].as_f64().unwrap() > 0.0);
    // Tampered: a value above 1.
    let text = std::fs::read_to_string(&json).unwrap();
    let tampered = text.replacen("\"values\":[", "\"values\":[1.5,", 1);
    let bad = dir.path().join("bad.json");
    std::fs::write(&bad, tampered).unwrap();
    command::refused(
        &["anisotropic", "--table", bad.to_str().unwrap()],
        &["bad.json", "values"],
    );
}

/// `kiln anisotropic` refuses a bad tolerance, furnace roughness, anisotropy or size before any
/// work and before making its folder.
#[test]
fn an_anisotropic_bake_refuses_bad_settings_before_it_starts() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("new");
    let o = out.to_str().unwrap();
    for (flags, words) in [
        (
            &["--tolerance", "1"][..],
            &["tolerance 1e0", "[1e-10, 1e-2]"][..],
        ),
        (&["--min-roughness", "2"], &["min roughness 2", "[0, 1)"]),
        (&["--max-anisotropy", "1"], &["anisotropy 1", "[0, 0.99]"]),
        (&["--size", "32,16,32"], &["four sample counts"]),
        (&["--size", "32,1,32,16"], &["azimuth axis has 1 samples"]),
    ] {
        let mut args = vec!["anisotropic", "--bake", o];
        args.extend_from_slice(flags);
        let message = command::refused(&args, words);
        assert!(!message.contains("estimated"), "{message}");
        assert!(!out.exists(), "{flags:?} left {o}");
    }
}
