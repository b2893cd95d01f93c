//! `kiln verify-fit`: the audit of texture-free fits finds their worst points (closed forms,
//! a hidden spike, random points), reproduces the figures measured for the engines' fits, and
//! its command says what is wrong with bad input.

use kiln::Quantity;
use kiln::fit::engine::EngineFit;
use kiln::fit::{Fit, FormulaFit};
use kiln::integrate::reference::ReferenceSettings;
use kiln::integrate::value::{Integral, Point};
use kiln::verify::fit::{FitAuditSettings, FitReport, audit_fit};
use std::path::Path;

use crate::cxx;
use crate::rng;
use rng::Rng;

/// A number in [0, 1).
fn uniform(rng: &mut Rng) -> f64 {
    (rng.next() >> 11) as f64 / (1u64 << 53) as f64
}

#[allow(dead_code, clippy::all)]
mod emitted {
    include!("data/fits/ggx_height_correlated_e_fit_t3_r2.rs");
    include!("data/fits/ggx_height_correlated_e_fit_p3_3_q3_3.rs");
    include!("data/fits/ggx_height_correlated_e_fit_p2_plus_1_q2_2.rs");
}

/// An emitted fit in f32.
type F32Fit = fn(f32, f32) -> f32;

/// The fits whose files are committed in tests/data/fits, with the emitted Rust function.
const COMMITTED: [(&str, F32Fit); 3] = [
    (
        "ggx_height_correlated_e_fit_t3_r2",
        emitted::ggx_height_correlated_e_fit_t3_r2,
    ),
    (
        "ggx_height_correlated_e_fit_p3_3_q3_3",
        emitted::ggx_height_correlated_e_fit_p3_3_q3_3,
    ),
    (
        "ggx_height_correlated_e_fit_p2_plus_1_q2_2",
        emitted::ggx_height_correlated_e_fit_p2_plus_1_q2_2,
    ),
];

fn audit(fit: &Fit) -> FitReport {
    audit_fit(fit, &FitAuditSettings::default(), &|| {})
}

fn formula(text: &str) -> Fit {
    Fit::Formula(FormulaFit::parse(text).expect("the formula file parses"))
}

fn quantity(report: &FitReport, q: Quantity) -> &kiln::verify::fit::FitQuantityReport {
    report
        .quantities
        .iter()
        .find(|r| r.quantity == q)
        .unwrap_or_else(|| panic!("{} audits {q:?}", report.fit))
}

/// The truth the audit compares with, at one point (`E_scale = E - E_bias`).
fn truth(q: Quantity, mu: f64, r: f64) -> f64 {
    let value = |quantity| {
        Integral {
            quantity,
            ..Integral::albedo(FitAuditSettings::default().model)
        }
        .reference(
            Point {
                alpha: r * r,
                mu: Some(mu),
                eta: None,
            },
            &ReferenceSettings {
                tolerance: 1e-8,
                ..Default::default()
            },
        )
        .value
    };
    match q {
        Quantity::EScale => value(Quantity::E) - value(Quantity::EBias),
        other => value(other),
    }
}

/// `E = 0` is off by exactly 1 where `E` is 1, the most it can be: on the mirror
/// (`E(mu, r = 0) = 1`) and at grazing (height-correlated `E(0, alpha) = 1`, docs/physics.md).
#[test]
fn a_zero_fit_is_off_by_one_at_the_mirror() {
    let report = audit(&formula("name = \"zero\"\nE = \"0\""));
    let e = quantity(&report, Quantity::E);
    assert!((e.max_error - 1.0).abs() < 1e-9, "max {}", e.max_error);
    assert!(e.worst.r == 0.0 || e.worst.mu == 0.0, "{:?}", e.worst);
    assert_eq!(e.worst.fit, 0.0);
    assert_eq!(e.non_finite_points, 0);
    // The whole table is on record: its mean error is the mean of E, well inside (0, 1).
    assert!(e.mean_error > 0.5 && e.mean_error < 1.0, "{}", e.mean_error);
}

/// A spike of height 10 and width 0.003, narrower than the grid's step (1/128) and between its
/// nodes, is found by the refinement: the stated maximum is within 10% of the peak, at the peak.
#[test]
fn a_spike_between_the_nodes_is_found() {
    let report = audit(&formula(
        "name = \"spike\"\n\
         E = \"10 * exp(-((sqrt(mu) - 0.5003)^2 + (r - 0.3001)^2) / 1e-5)\"",
    ));
    let e = quantity(&report, Quantity::E);
    assert!(e.max_error > 9.0, "max {} at {:?}", e.max_error, e.worst);
    assert!((e.worst.mu.sqrt() - 0.5003).abs() < 2e-4, "{:?}", e.worst);
    assert!((e.worst.r - 0.3001).abs() < 2e-4, "{:?}", e.worst);
}

/// A fit that is NaN somewhere states no maximum (NaN) and counts the points.
#[test]
fn a_fit_that_is_nan_somewhere_has_no_maximum() {
    let report = audit(&formula("name = \"log\"\nE = \"1 + log(mu - 0.5) * 0\""));
    let e = quantity(&report, Quantity::E);
    assert!(e.max_error.is_nan());
    assert!(e.non_finite_points > 100, "{}", e.non_finite_points);
}

/// The engines' fits: the figures measured for them when the work was filed (against
/// height-correlated GGX), and no random point worse than the stated maximum.
#[test]
fn engine_fits_have_the_measured_maxima_and_no_point_beats_them() {
    let mut rng = Rng(39);
    let random: Vec<(f64, f64)> = (0..1500)
        .map(|_| (uniform(&mut rng), uniform(&mut rng)))
        .collect();
    for engine in EngineFit::ALL {
        let fit = Fit::Engine(engine);
        let report = audit(&fit);
        let e = quantity(&report, Quantity::E);
        let (mu, r) = (e.worst.mu, e.worst.r);
        match engine {
            // Filed as 0.43; the audit finds 0.55 at the grazing rough corner.
            EngineFit::Karis => assert!(e.max_error > 0.43, "{}", e.max_error),
            // Filed as "about 0.10 near alpha 0.0025 at grazing": grazing and smooth.
            EngineFit::MaterialX => {
                assert!(e.max_error > 0.10, "{}", e.max_error);
                assert!(mu < 0.01 && r * r < 0.01, "{:?}", e.worst);
            }
            // Filed as 0.059 (at sampled points); the maximum is at least that, and near it.
            EngineFit::Unreal => {
                assert!((0.059..0.07).contains(&e.max_error), "{}", e.max_error);
            }
        }
        for q in &report.quantities {
            // The stated worst point is what the reference says there.
            let at = truth(q.quantity, q.worst.mu, q.worst.r);
            assert!((q.worst.reference - at).abs() < 1e-6, "{q:?}");
            let beaten = random.iter().find_map(|&(mu, r)| {
                let error = (fit.value(q.quantity, mu, r) - truth(q.quantity, mu, r)).abs();
                (error > q.max_error + 1e-7).then_some((mu, r, error))
            });
            assert!(
                beaten.is_none(),
                "{} {:?}: stated {:.4e}, random point {beaten:?}",
                report.fit,
                q.quantity,
                q.max_error
            );
        }
    }
}

/// MaterialX's fit was filed as 0.035 off for alpha >= 0.025. A 97 x 97 grid in (sqrt(mu),
/// alpha) over that part of the domain finds more: 0.0565 at alpha = 0.025, mu = 0.024 (the
/// grazing band at its smoothest roughness), so the filed figure was a sample of the maximum.
#[test]
fn materialx_is_near_its_filed_error_away_from_the_mirror() {
    let fit = Fit::Engine(EngineFit::MaterialX);
    let n = 97;
    let mut worst: f64 = 0.0;
    for j in 0..n {
        let alpha = 0.025 + (1.0 - 0.025) * j as f64 / (n - 1) as f64;
        for i in 0..n {
            let t = i as f64 / (n - 1) as f64;
            let (mu, r) = (t * t, alpha.sqrt());
            worst = worst.max((fit.value(Quantity::E, mu, r) - truth(Quantity::E, mu, r)).abs());
        }
    }
    assert!((0.050..0.065).contains(&worst), "{worst}");
}

/// `kiln fit`'s 12-coefficient polynomial (degrees 3 in t, 2 in r), 31-coefficient rational
/// (`1 - t^2 P / Q`, P and Q of degrees 3, 3) and 12-coefficient rational (P = A(u) + B(s) of
/// degrees 2 and 1, Q of degrees 2, 2): the maximum each audit states is never beaten at 10^5
/// random points and is not a loose bound either; the polynomial beats the engines' fits of E
/// (Unreal 5's is 0.0646 off), the rationals are within the goals of 1e-3 in 32 coefficients
/// and 1e-2 in 12, in f64 and in f32.
#[test]
#[ignore = "long (about 60 s): .ci/run runs it with --ignored"]
fn kiln_fits_state_a_maximum_no_random_point_beats() {
    use kiln::fit::emit::{FitText, MadeFit};
    use kiln::fit::polynomial::{Degrees, fit, truth_points};
    use kiln::fit::rational::{RationalShape, coordinates_of};
    let model = FitAuditSettings::default().model;
    let poly = fit(model, Degrees { t: 3, r: 2 }, &|| {});
    let shape = RationalShape {
        numerator: Degrees { t: 3, r: 3 },
        denominator: Degrees { t: 3, r: 3 },
        additive: false,
    };
    let points_truth = coordinates_of(&truth_points(model, &|| {}));
    let rational = kiln::fit::rational::fit_to(model, shape, &points_truth, &|| {}).unwrap();
    let small = RationalShape {
        numerator: Degrees { t: 2, r: 1 },
        denominator: Degrees { t: 2, r: 2 },
        additive: true,
    };
    assert_eq!(small.coefficients(), 12);
    let small = kiln::fit::rational::fit_to(model, small, &points_truth, &|| {}).unwrap();
    // (fit, the range its stated maximum falls in, its --degrees, its goal in f32)
    let fits = [
        (MadeFit::Polynomial(poly), 0.02..0.035, "3,2", f64::INFINITY),
        (MadeFit::Rational(rational), 5e-4..1e-3, "3,3/3,3", 1e-3),
        (MadeFit::Rational(small), 8e-3..1e-2, "2+1/2,2", 1e-2),
    ];
    let mut rng = Rng(1905);
    let points: Vec<(f64, f64)> = (0..100_000)
        .map(|_| (uniform(&mut rng), uniform(&mut rng)))
        .collect();
    use rayon::prelude::*;
    let reference: Vec<f64> = points
        .par_iter()
        .map(|&(mu, r)| truth(Quantity::E, mu, r))
        .collect();
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/fits");
    for ((made, range, degrees, goal), (name, emitted)) in fits.iter().zip(COMMITTED) {
        let report = kiln::verify::fit::audit_emitted(made, &FitAuditSettings::default(), &|| {});
        let stated = report.quantities[0].max_error;
        assert!(range.contains(&stated), "{name}: {stated}");
        let worst = points
            .par_iter()
            .zip(&reference)
            .map(|(&(mu, r), &e)| ((made.value(mu, r) - e).abs(), mu, r))
            .reduce(|| (0.0, 0.0, 0.0), |a, b| if a.0 >= b.0 { a } else { b });
        assert!(
            worst.0 <= stated + 1e-7,
            "{name}: stated {stated:.4e}, random {worst:?}"
        );
        assert!(
            worst.0 > 0.9 * stated,
            "{name}: stated {stated:.4e}, random {worst:?}"
        );
        // The committed files (`kiln fit --degrees D --out tests/data/fits`) are what kiln
        // writes now, and the Rust one, compiled here, computes the fit in f32.
        let command = format!("kiln fit --ndf ggx --masking height-correlated --degrees {degrees}");
        let text = made.description(stated, &command);
        assert_eq!(made.function_name(), name);
        for format in kiln::fit::emit::FitFormat::ALL {
            let file = format!("{name}.{}", format.extension());
            let committed = std::fs::read_to_string(dir.join(&file)).unwrap();
            assert!(
                committed == kiln::fit::emit::emit(made, format, &text),
                "tests/data/fits/{file} is not what kiln fit writes now: run `{command} --out \
                 tests/data/fits`"
            );
        }
        // In f32 the polynomial is its f64 value to 1e-5; the rational's small denominator
        // near (mu 0.8, r 0.05) costs more (7.0e-5 on a 401 x 401 grid, `cargo run --release
        // --example f32_check`), and in f32 it still keeps within the goal of 1e-3.
        let f32_error = points
            .par_iter()
            .zip(&reference)
            .map(|(&(mu, r), &e)| (f64::from(emitted(mu as f32, r as f32)) - e).abs())
            .reduce(|| 0.0, f64::max);
        for &(mu, r) in &points[..2000] {
            let f32_value = emitted(mu as f32, r as f32);
            let allowed = if degrees.contains('/') { 1e-4 } else { 1e-5 };
            assert!(
                (f64::from(f32_value) - made.value(mu, r)).abs() < allowed,
                "{name}: {mu} {r}"
            );
        }
        assert!(f32_error <= *goal, "{name} in f32: {f32_error:.4e}");
    }
}

/// The emitted C header compiles (as C++, twice included: `#pragma once`) and computes the
/// Rust function's values, when the machine has a compiler.
#[test]
fn the_emitted_c_header_computes_the_fit() {
    let Some(compiler) = cxx::compiler_or_skip("the_emitted_c_header_computes_the_fit") else {
        return;
    };
    for (name, rust) in COMMITTED {
        let dir = tempfile::tempdir().unwrap();
        let header =
            Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("tests/data/fits/{name}.h"));
        let points: Vec<(f32, f32)> = (0..50)
            .map(|k| ((k % 10) as f32 / 9.0, (k / 10) as f32 / 4.0))
            .collect();
        let calls: String = points
            .iter()
            .map(|(mu, r)| format!("    printf(\"%.9g\\n\", {name}({mu:?}f, {r:?}f));\n"))
            .collect();
        let source = format!(
            "#include <cstdio>\n#include \"{0}\"\n#include \"{0}\"\nint main() {{\n{calls}    \
             return 0;\n}}\n",
            header.display()
        );
        let main = dir.path().join("main.cpp");
        std::fs::write(&main, source).unwrap();
        let exe = dir.path().join("fit");
        let build = std::process::Command::new(compiler)
            .arg(&main)
            .arg("-o")
            .arg(&exe)
            .output()
            .unwrap();
        assert!(
            build.status.success(),
            "{}",
            String::from_utf8_lossy(&build.stderr)
        );
        let run = std::process::Command::new(&exe).output().unwrap();
        let printed = String::from_utf8(run.stdout).unwrap();
        for ((mu, r), line) in points.iter().zip(printed.lines()) {
            let c: f64 = line.parse().unwrap();
            let rust = rust(*mu, *r);
            assert!(
                (c - f64::from(rust)).abs() < 1e-6,
                "{name} {mu} {r}: C {c}, Rust {rust}"
            );
        }
        assert_eq!(printed.lines().count(), points.len());
    }
}

/// The emitted WGSL and GLSL parse and validate (naga), called from a fragment shader.
#[test]
fn emitted_shader_fits_validate() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/fits");
    let validate = |module: &naga::Module, source: &str| {
        naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::all(),
        )
        .validate(module)
        .unwrap_or_else(|e| panic!("{e:?}\n{source}"));
    };
    for (name, _) in COMMITTED {
        let wgsl = std::fs::read_to_string(dir.join(format!("{name}.wgsl"))).unwrap()
            + &format!(
                "\n@fragment\nfn main() -> @location(0) vec4<f32> {{\n    \
             return vec4<f32>({name}(0.5, 0.5), 0.0, 0.0, 1.0);\n}}\n"
            );
        let module = naga::front::wgsl::parse_str(&wgsl)
            .unwrap_or_else(|e| panic!("{}", e.emit_to_string(&wgsl)));
        validate(&module, &wgsl);
        let glsl = "#version 450\nlayout(location = 0) out vec4 colour;\n".to_string()
            + &std::fs::read_to_string(dir.join(format!("{name}.glsl"))).unwrap()
            + &format!(
                "\nvoid main() {{\n    colour = vec4({name}(0.5, 0.5), 0.0, 0.0, 1.0);\n}}\n"
            );
        let module = naga::front::glsl::Frontend::default()
            .parse(
                &naga::front::glsl::Options::from(naga::ShaderStage::Fragment),
                &glsl,
            )
            .unwrap_or_else(|e| panic!("{e:?}\n{glsl}"));
        validate(&module, &glsl);
    }
}

#[cfg(feature = "cli")]
use crate::command;

#[cfg(feature = "cli")]
mod command_line {
    use std::process::Output;

    use super::command::kiln;

    fn stderr(output: &Output) -> String {
        String::from_utf8_lossy(&output.stderr).into_owned()
    }

    #[test]
    fn bad_fits_get_a_clear_error_and_status_2() {
        let dir = tempfile::tempdir().unwrap();
        let unknown = kiln(&["verify-fit", "schlick"]);
        assert_eq!(unknown.status.code(), Some(2));
        assert!(
            stderr(&unknown).contains("neither a fit kiln knows (karis, materialx, unreal)"),
            "{}",
            stderr(&unknown)
        );
        let bad = dir.path().join("bad.toml");
        std::fs::write(&bad, "name = \"bad\"\nE = \"1 - mu *\"\n").unwrap();
        let out = kiln(&["verify-fit", bad.to_str().unwrap()]);
        assert_eq!(out.status.code(), Some(2));
        assert!(
            stderr(&out).contains("bad.toml: E: at character"),
            "{}",
            stderr(&out)
        );
        let fresnel = kiln(&["verify-fit", "karis", "--f0", "0.04"]);
        assert_eq!(fresnel.status.code(), Some(2));
        assert!(
            stderr(&fresnel).contains("unexpected argument '--f0'"),
            "{}",
            stderr(&fresnel)
        );
        let both = kiln(&["verify-fit", "karis", bad.to_str().unwrap()]);
        assert_eq!(both.status.code(), Some(2), "{}", stderr(&both));
        let few = kiln(&["verify-fit", "karis", "--points", "1"]);
        assert_eq!(few.status.code(), Some(2), "{}", stderr(&few));
    }

    #[test]
    fn kiln_fit_refuses_bad_degrees_and_writes_what_it_says() {
        for bad in [
            &["fit", "--degrees", "13,2"][..],
            &["fit", "--degrees", "3"],
            &["fit", "--sweep", "--degrees", "3,2"],
            &["fit", "--degrees", "3,0"],
            &["fit", "--degrees", "3,3/3"],
            &["fit", "--degrees", "0,3/3,3"],
            &["fit", "--degrees", "3,3/3,13"],
            // Only a rational's numerator can be additive.
            &["fit", "--degrees", "2+1"],
            &["fit", "--degrees", "2,2/2+1"],
            &["fit", "--degrees", "2+1+1/2,2"],
        ] {
            let out = kiln(bad);
            assert_eq!(out.status.code(), Some(2), "{bad:?}: {}", stderr(&out));
        }
        assert!(stderr(&kiln(&["fit", "--degrees", "3,3/3"])).contains("PT,PR/QT,QR"));
        let dir = tempfile::tempdir().unwrap();
        let out = kiln(&[
            "fit",
            "--degrees",
            "2,1",
            "--format",
            "toml,wgsl",
            "--out",
            dir.path().to_str().unwrap(),
            "--json",
        ]);
        assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(v["coefficients"].as_array().unwrap().len(), 6);
        let stated = v["max_error"].as_f64().unwrap();
        // The formula file written audits to the maximum stated.
        let toml = dir.path().join("ggx_height_correlated_e_fit_t2_r1.toml");
        let audit = kiln(&["verify-fit", toml.to_str().unwrap(), "--json"]);
        let a: serde_json::Value = serde_json::from_slice(&audit.stdout).unwrap();
        assert_eq!(a["quantities"][0]["max_error"].as_f64().unwrap(), stated);
        assert!(
            dir.path()
                .join("ggx_height_correlated_e_fit_t2_r1.wgsl")
                .exists()
        );
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2);

        // A rational: P of degrees (1, 1) and Q of (1, 0), 4 + 2 - 1 coefficients, the
        // denominator's constant 1; its formula file audits to the maximum stated.
        let out = kiln(&[
            "fit",
            "--degrees",
            "1,1/1,0",
            "--format",
            "toml",
            "--out",
            dir.path().to_str().unwrap(),
            "--json",
        ]);
        assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let c = &v["coefficients"];
        assert_eq!(c["numerator"].as_array().unwrap().len(), 4);
        assert_eq!(c["denominator"].as_array().unwrap().len(), 2);
        assert_eq!(c["denominator"][0].as_f64(), Some(1.0));
        let toml = dir
            .path()
            .join("ggx_height_correlated_e_fit_p1_1_q1_0.toml");
        let audit = kiln(&["verify-fit", toml.to_str().unwrap(), "--json"]);
        let a: serde_json::Value = serde_json::from_slice(&audit.stdout).unwrap();
        assert_eq!(
            a["quantities"][0]["max_error"].as_f64().unwrap(),
            v["max_error"].as_f64().unwrap()
        );
    }

    /// `--max-error` gates a build on a fit, `--json` carries the figures and `--plot` draws them.
    #[test]
    fn a_fit_audit_gates_prints_and_plots() {
        let dir = tempfile::tempdir().unwrap();
        let plot = dir.path().join("unreal.svg");
        let out = kiln(&[
            "verify-fit",
            "unreal",
            "--points",
            "33",
            "--max-error",
            "0.2",
            "--plot",
            plot.to_str().unwrap(),
        ]);
        assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(text.contains("PASSED"), "{text}");
        assert!(text.contains("E_bias"), "{text}");
        let svg = std::fs::read_to_string(&plot).unwrap();
        assert!(
            svg.starts_with("<svg") || svg.starts_with("<?xml"),
            "{}",
            &svg[..40]
        );
        let fail = kiln(&[
            "verify-fit",
            "unreal",
            "--points",
            "33",
            "--max-error",
            "1e-3",
        ]);
        assert_eq!(fail.status.code(), Some(1), "{}", stderr(&fail));
        assert!(String::from_utf8_lossy(&fail.stdout).contains("FAILED"));
        let json = kiln(&[
            "verify-fit",
            "karis",
            "--points",
            "17",
            "--json",
            "--max-error",
            "0.1",
        ]);
        assert_eq!(json.status.code(), Some(1), "{}", stderr(&json));
        let v: serde_json::Value = serde_json::from_slice(&json.stdout).unwrap();
        assert_eq!(v["fit"], "karis");
        assert_eq!(v["passed"], false);
        assert_eq!(v["max_error"], 0.1);
        let e = &v["quantities"][0];
        assert_eq!(e["quantity"], "E");
        assert!(e["max_error"].as_f64().unwrap() > 0.43);
        assert!(e["worst"]["mu"].is_number() && e["worst"]["r"].is_number());
    }
}

/// Issue 64, defect 7: a formula file's text reaches the terminal escaped and bounded: `name`
/// and `source` with escape sequences and a bidi override, an unknown 4000-character name, a
/// `define` line holding ESC; and "at character N" counts characters after non-ASCII text.
#[cfg(feature = "cli")]
#[test]
fn formula_file_text_reaches_the_terminal_escaped_and_bounded() {
    let dir = tempfile::tempdir().unwrap();
    let run = |text: &str| {
        let file = dir.path().join("f.toml");
        std::fs::write(&file, text).unwrap();
        let output = std::process::Command::new(env!("CARGO_BIN_EXE_kiln"))
            .args(["verify-fit"])
            .arg(&file)
            .output()
            .unwrap();
        let all = format!(
            "{}{}",
            String::from_utf8_lossy(&output.stdout),
            String::from_utf8_lossy(&output.stderr)
        );
        assert!(
            !all.chars()
                .any(|c| c == '\u{1b}' || c == '\u{7}' || c == '\u{202e}'),
            "{all:?}"
        );
        (output.status.code(), all)
    };
    // A valid file whose name and source carry control text: audited, shown escaped.
    let (code, all) = run(
        "name = \"k\\u001b]0;owned\\u0007\"\nsource = \"s\\u202etxt\\u001b[2J\"\nE = \"1 - 0.5 * r\"\n",
    );
    assert_eq!(code, Some(0), "{all}");
    assert!(all.contains("k\\u{1b}]0;owned"), "{all}");
    // An unknown name of 4000 characters: quoted, at most 60 of them.
    let long = "x".repeat(4000);
    let (code, all) = run(&format!("name = \"k\"\nE = \"1 - {long}\"\n"));
    assert_eq!(code, Some(2), "{all}");
    assert!(
        all.len() < 600 && all.contains("unknown name 'xxx"),
        "{all}"
    );
    // A define line with ESC and no '='.
    let (code, all) = run("name = \"k\"\ndefine = [\"a\\u001b[2J\"]\nE = \"1\"\n");
    assert_eq!(code, Some(2), "{all}");
    assert!(all.contains("a\\u{1b}[2J"), "{all}");
    // Characters, not bytes: "1 +<no-break space>nu" fails at character 5, the n (bytes
    // would say 6: the space is two).
    let (code, all) = run("name = \"k\"\nE = \"1 +\\u00a0nu\"\n");
    assert_eq!(code, Some(2), "{all}");
    assert!(all.contains("at character 5"), "{all}");
}
