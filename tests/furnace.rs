//! The white furnace test: of an `E` / `E_avg` pair through the Kulla-Conty lobe
//! ([`kiln::verify::furnace`]), and the command that runs it, `kiln furnace` (both forms, the
//! normalisation found beside the table, glass, the picture, the gate).

use crate::command::{json_of, kiln, number, succeeded};
use kiln::verify::furnace::furnace;
use kiln::verify::input::read_kiln;
use serde_json::Value;
use std::path::Path;

fn committed(name: &str) -> kiln::Table {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("tables/{name}.json"));
    read_kiln(&path).unwrap().unwrap()
}

/// `1 - Ē`, the average of the `E` lookup, checked against an independent rule: midpoints in
/// the texture coordinate `t` (where the lookup is piecewise linear), 2^12 cells, weights
/// `mu(t_1)^2 - mu(t_0)^2`. And the deviation is `(1 - E(mu)) ((1 - Ē) / (1 - E_avg) - 1)`.
#[test]
fn furnace_integrates_the_lookup_and_reports_the_identity() {
    let e = committed("ggx-height-correlated-E");
    let avg = committed("ggx-height-correlated-E_avg");
    let report = furnace(&e, &avg, 2).unwrap();
    assert_eq!(report.normalisation, "E_avg");
    let Some(kiln::table::axis::Axis::Mu { mapping, size, .. }) = e.spec.mu else {
        unreachable!()
    };
    for row in report.rows.iter().filter(|row| row.roughness >= 0.1) {
        let cells = 1 << 12;
        let mut integral = 0.0;
        for k in 0..cells {
            let (t0, t1) = (k as f64 / cells as f64, (k + 1) as f64 / cells as f64);
            let (mu0, mu1) = (
                mapping.mu(t0, row.alpha, size),
                mapping.mu(t1, row.alpha, size),
            );
            let mid = mapping.mu((t0 + t1) / 2.0, row.alpha, size);
            integral += e.lookup_one_minus(mid, row.roughness) * (mu1 * mu1 - mu0 * mu0);
        }
        let relative = (integral / row.one_minus_e_avg_of_e - 1.0).abs();
        assert!(
            relative < 1e-4,
            "r {}: {integral} vs {}",
            row.roughness,
            row.one_minus_e_avg_of_e
        );
        let ratio = row.one_minus_e_avg_of_e / row.one_minus_e_avg;
        let expected = e.lookup_one_minus(row.worst_mu, row.roughness) * (ratio - 1.0);
        assert!((row.deviation - expected).abs() <= 1e-15);
        assert!((row.relative_mismatch - (ratio - 1.0)).abs() <= 1e-15);
    }
}

/// With the exact `E_avg`, the lobe restores energy within 1e-3 from r = 0.25 up only. Below,
/// `1 - E_avg` is under 1.3e-2 and its relative mismatch with the lookup's average is
/// multiplied by `1 - E` of up to 0.11 in the grazing layer (docs/verify.md gives the figures):
/// why kiln ships `f_ms_norm`. At r = 0 (a mirror) there is no loss and no lobe.
#[test]
fn the_exact_average_restores_energy_from_r_one_quarter_only() {
    let e = committed("ggx-height-correlated-E");
    let avg = committed("ggx-height-correlated-E_avg");
    let report = furnace(&e, &avg, 2).unwrap();
    for row in &report.rows {
        assert!(row.deviation.is_finite());
        if row.roughness >= 0.25 {
            assert!(row.deviation.abs() <= 1e-3, "{row:?}");
        }
    }
    // 0.086 on the default fitted balanced table, 0.128 on the adaptive axis' point samples.
    assert!(report.max_deviation > 0.05, "{:?}", report.worst);
    assert!(report.worst.roughness < 0.05, "{:?}", report.worst);
    // The r = 0 row of E holds the limit alpha -> 0+; at mu = 1 that is the mirror, which
    // loses nothing.
    assert_eq!(report.rows[0].deviation, 0.0, "{:?}", report.rows[0]);
}

/// The goal of the lookup-consistent normalisation: with `f_ms_norm` the lobe closes the
/// furnace within 1e-3 at every roughness of the ladder (quarter texels, 400 steps below
/// r = 0.1, the midpoints of f_ms_norm's nodes) and every mu, 0 included.
#[test]
fn the_lookup_consistent_normalisation_closes_the_furnace() {
    let e = committed("ggx-height-correlated-E");
    let norm = committed("ggx-height-correlated-f_ms_norm");
    let report = furnace(&e, &norm, 4).unwrap();
    assert_eq!(report.normalisation, "f_ms_norm");
    assert!(report.rows.len() > 1000);
    assert!(report.max_deviation <= 1e-3, "{:?}", report.worst);
    for band in &report.bands {
        assert!(band.max_deviation <= 1e-3, "{band:?}");
    }
}

/// The same, in half floats: the files of an f16 bake (f_ms_norm derived from the E values as
/// stored) read back and tested as a renderer would sample them.
#[test]
fn the_normalisation_closes_the_furnace_in_half_floats() {
    use kiln::format::replace::Replace;
    use kiln::format::{Format, Precision, write_tables};
    let tables = kiln::BakeOptions::default().bake(&|_| {}).unwrap();
    let dir = tempfile::tempdir().unwrap();
    write_tables(
        dir.path(),
        &tables,
        &[Format::Exr],
        Precision::F16,
        Replace::Refuse,
    )
    .unwrap();
    let read = |name: &str| {
        read_kiln(&dir.path().join(format!("{name}.exr")))
            .unwrap()
            .unwrap()
    };
    let e = read("ggx-height-correlated-E");
    let norm = read("ggx-height-correlated-f_ms_norm");
    let report = furnace(&e, &norm, 4).unwrap();
    // f_ms_norm stays f32 in an f16 bake (its smallest values would be f16 subnormals): the
    // lobe closes as in f32 (4.1e-6; 2.6e-4 when f_ms_norm was rounded to f16), and the
    // table is within 1e-4 relative of its f16 E table's lookup average.
    assert!(report.max_deviation <= 2e-5, "{:?}", report.worst);
    let audit = kiln::verify::furnace::audit_normalisation(&e, &norm).unwrap();
    assert!(
        audit.lookup_max_relative_error <= 1e-4,
        "{}",
        audit.lookup_max_relative_error
    );
}

/// The lobe's albedo integrated independently: `E(mu_o) + ∫ f_ms mu_i dω_i`, with `E` the
/// table's lookup, `f_ms` normalised by `f_ms_norm`'s lookup, and the integral over `mu_i` by a
/// midpoint rule over geometrically spaced `mu` (not the furnace's Gauss-Kronrod split at the
/// lookup's nodes), must be 1 within 1e-3 at low and high roughness, between nodes, at grazing
/// and normal views.
#[test]
fn the_lobe_restores_the_lost_energy_by_an_independent_integral() {
    use kiln::table::normalisation::normalisation_lookup;
    let e = committed("ggx-height-correlated-E");
    let norm = committed("ggx-height-correlated-f_ms_norm");
    for r in [3e-4, 1e-3, 4.1e-3, 0.01, 0.02, 0.033, 0.05, 0.1, 0.3, 0.77] {
        let alpha = r * r;
        let one_minus_e_avg = normalisation_lookup(&norm, r);
        // mu from 1e-14 to 1 in 2^17 geometric cells (below 1e-14 the weight mu dmu is nil).
        let cells = 1 << 17;
        let mu_at = |k: usize| 10f64.powf(-14.0 + 14.0 * k as f64 / cells as f64);
        let mut average = 0.0;
        for k in 0..cells {
            let (mu0, mu1) = (mu_at(k), mu_at(k + 1));
            average += e.lookup_one_minus((mu0 + mu1) / 2.0, r) * (mu1 * mu1 - mu0 * mu0);
        }
        for mu_o in [0.0, 1e-6, alpha, 0.05, 0.5, 1.0] {
            let loss = e.lookup_one_minus(mu_o, r);
            // ∫ f_ms mu_i dω_i = 2 pi ∫ loss_o loss_i mu_i dmu_i / (pi (1 - E_avg)).
            let lobe = loss * average / one_minus_e_avg;
            let deviation = lobe - loss;
            assert!(deviation.abs() <= 1e-3, "r {r}, mu {mu_o}: {deviation:e}");
        }
    }
}

/// A mismatched pair is caught, with the sign of the energy error: an `E_avg` table whose
/// `1 - E_avg` is twice the truth makes the lobe return half the lost energy.
#[test]
fn a_mismatched_average_is_caught_with_its_sign() {
    let e = committed("ggx-height-correlated-E");
    let mut avg = committed("ggx-height-correlated-E_avg");
    for v in &mut avg.one_minus_value {
        *v *= 2.0;
    }
    let report = furnace(&e, &avg, 2).unwrap();
    let row = report.rows.iter().find(|row| row.roughness == 0.5).unwrap();
    assert!((row.relative_mismatch + 0.5).abs() < 1e-3, "{row:?}");
    assert!(row.deviation < -0.05, "{row:?}");
    // And the tables must be an E and an E_avg of one model.
    assert!(furnace(&avg, &e, 2).is_err());
}

// The command line: `kiln furnace`.

/// `kiln verify --json ARGS`: the exit status and the report.
fn verify(args: &[&str]) -> (Option<i32>, Value) {
    json_of("verify", args)
}

/// `kiln furnace --json ARGS`: the exit status and the report.
fn furnace_json(args: &[&str]) -> (Option<i32>, Value) {
    json_of("furnace", args)
}

/// `kiln furnace` finds the normalisation beside the E file (`f_ms_norm`, else `E_avg`; or takes
/// --average), reports JSON, and gates on --max-error; a file not named like a kiln E table
/// asks for --average.
#[test]
fn the_command_finds_the_average_and_gates() {
    let tables = Path::new(env!("CARGO_MANIFEST_DIR")).join("tables");
    let e = tables.join("ggx-height-correlated-E.json");
    let (status, report) = furnace_json(&[e.to_str().unwrap()]);
    assert_eq!(status, Some(0));
    assert!(
        report["average"]
            .as_str()
            .unwrap()
            .ends_with("ggx-height-correlated-f_ms_norm.json")
    );
    assert_eq!(report["normalisation"], "f_ms_norm");
    let max = number(&report, "max_deviation");
    // Both forms by default; the worst of them is max_deviation. Turquin's 1 / E scaling
    // leaves the lookup's relative error, E_true / E_lookup - 1: at least the audit's absolute
    // lookup error (E <= 1), at most that over the smallest E (0.3 at r = 1, mu = 1).
    let forms = report["forms"].as_array().unwrap();
    assert_eq!(forms.len(), 2);
    assert_eq!(forms[0]["form"], "kulla-conty");
    assert_eq!(forms[1]["form"], "turquin");
    let kulla_conty = number(&forms[0], "max_deviation");
    assert!(kulla_conty > 0.0 && kulla_conty < 1e-3, "{kulla_conty}");
    let turquin = number(&forms[1], "max_deviation");
    assert_eq!(max, kulla_conty.max(turquin));
    let (_, audit) = verify(&[e.to_str().unwrap()]);
    let lookup = number(&audit, "lookup_max_error");
    assert!(
        turquin >= lookup && turquin <= lookup / 0.3,
        "{turquin} vs {lookup}"
    );
    let (status, report) = furnace_json(&[
        e.to_str().unwrap(),
        "--form",
        "kulla-conty",
        "--max-error",
        "1e-9",
    ]);
    assert_eq!((status, &report["passed"]), (Some(1), &Value::Bool(false)));
    // The binary copies: the same test within f32 rounding.
    let bin = tables.join("ggx-height-correlated-E.bin");
    let norm = tables.join("ggx-height-correlated-f_ms_norm.bin");
    let (_, from_bin) = furnace_json(&[
        bin.to_str().unwrap(),
        "--form",
        "kulla-conty",
        "--average",
        norm.to_str().unwrap(),
    ]);
    assert!((number(&from_bin, "max_deviation") - kulla_conty).abs() < 0.05 * kulla_conty);
    // With the exact E_avg instead, the lookup's mismatch shows at low roughness.
    let avg = tables.join("ggx-height-correlated-E_avg.json");
    let (_, exact) = furnace_json(&[
        e.to_str().unwrap(),
        "--form",
        "kulla-conty",
        "--average",
        avg.to_str().unwrap(),
    ]);
    assert_eq!(exact["normalisation"], "E_avg");
    // (0.086 on the default fitted balanced table, 0.12 on the adaptive axis' point samples.)
    assert!(number(&exact, "max_deviation") > 0.05, "{exact}");
    let renamed = tempfile::tempdir().unwrap();
    let other = renamed.path().join("mine.json");
    std::fs::copy(&e, &other).unwrap();
    let output = kiln(&["furnace", other.to_str().unwrap()]);
    assert_eq!(output.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&output.stderr).contains("--average"));
}

/// `kiln furnace --plot` draws the deviation maps (SVG text names each form and its worst
/// deviation); a plot file that is neither .svg nor .png is refused before any work.
#[test]
fn furnace_plot_draws_each_form() {
    let tables = Path::new(env!("CARGO_MANIFEST_DIR")).join("tables");
    let e = tables.join("ggx-height-correlated-E.json");
    let dir = tempfile::tempdir().unwrap();
    let svg = dir.path().join("furnace.svg");
    succeeded(&[
        "furnace",
        e.to_str().unwrap(),
        "--form",
        "kulla-conty",
        "--plot",
        svg.to_str().unwrap(),
        "--quiet",
    ]);
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.starts_with("<svg") && text.contains("kulla-conty: max |deviation|"));
    // The picture states the command's own worst point (issue 42: the map's 64 x 64 grid alone
    // showed 4.3e-5 and a ring elsewhere, beside the command's 1.16e-4 at r 0.001), and its
    // colour bar says what the colours mean.
    let json = kiln(&[
        "furnace",
        e.to_str().unwrap(),
        "--form",
        "kulla-conty",
        "--json",
    ]);
    let report: serde_json::Value = serde_json::from_slice(&json.stdout).unwrap();
    let form = &report["forms"][0];
    let stated = format!(
        "max |deviation| {:.2e} at mu {:.2e}, r {:.4}",
        form["max_deviation"].as_f64().unwrap(),
        form["worst_mu"].as_f64().unwrap(),
        form["worst_roughness"].as_f64().unwrap()
    );
    assert!(text.contains(&stated), "the picture lacks '{stated}'");
    for label in ["deviation", "&lt; 1e-7", "+1e-1", "-1e-3"] {
        assert!(text.contains(label), "the colour bar lacks {label}");
    }
    let bad = dir.path().join("furnace.txt");
    crate::command::refused(
        &[
            "furnace",
            e.to_str().unwrap(),
            "--plot",
            bad.to_str().unwrap(),
        ],
        &[".svg or .png"],
    );
    assert!(!bad.exists());
}

/// The furnace of glass: Turquin's `1 / E` form on an `E_dielectric` table, its worst point
/// with its IOR; at least the audit's absolute lookup error (E <= 1 in the energy convention).
/// The Kulla-Conty lobe of glass is refused with a reason.
#[test]
fn glass_furnace_checks_turquins_form() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    let baked = kiln(&[
        "bake",
        "--quantity",
        "e-dielectric",
        "--size",
        "4",
        "--ior-size",
        "3",
        "--max-error",
        "1e-4",
        "--format",
        "json",
        "-q",
        "--out",
        out,
    ]);
    assert!(
        baked.status.success(),
        "{}",
        String::from_utf8_lossy(&baked.stderr)
    );
    let table = dir.path().join("ggx-height-correlated-E_dielectric.json");
    let table = table.to_str().unwrap();
    let (status, report) = furnace_json(&[table, "--density", "1"]);
    assert_eq!(status, Some(0), "{report}");
    let forms = report["forms"].as_array().unwrap();
    assert_eq!(forms.len(), 1);
    assert_eq!(forms[0]["form"], "turquin");
    let eta = number(&forms[0], "worst_eta");
    assert!((1.0..=3.0).contains(&eta), "{report}");
    let turquin = number(&forms[0], "max_deviation");
    let (_, audit) = verify(&[table, "--density", "1"]);
    assert!(
        turquin >= number(&audit, "lookup_max_error"),
        "{report} {audit}"
    );
    let output = kiln(&["furnace", table, "--form", "kulla-conty"]);
    assert_eq!(output.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&output.stderr).contains("glass"));
    // Its picture: over sqrt(mu) and the IOR, the command's worst point stated with its eta.
    let svg = dir.path().join("glass.svg");
    succeeded(&[
        "furnace",
        table,
        "--density",
        "1",
        "--plot",
        svg.to_str().unwrap(),
    ]);
    let text = std::fs::read_to_string(&svg).unwrap();
    let stated = format!(
        "max |deviation| {:.2e} at mu {}, eta {:.5}",
        turquin,
        {
            let mu = number(&forms[0], "worst_mu");
            if mu >= 1e-3 {
                format!("{mu:.4}")
            } else {
                format!("{mu:.2e}")
            }
        },
        eta
    );
    assert!(text.contains(&stated), "the picture lacks '{stated}'");
    assert!(text.contains("sqrt(mu)") && text.contains("eta or 1 / eta"));
}
