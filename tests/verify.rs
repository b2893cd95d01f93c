//! `kiln verify`: kiln's own tables, external tables in every format and layout, bad input, the
//! `--max-error` gate (engines' real files: `tests/engine_files.rs`).

#![cfg(feature = "cli")]

use kiln::integrate::reference::{ReferenceSettings, reference_albedo};
use kiln::verify::{Against, AuditSettings, audit};
use kiln::{BakeOptions, Masking, Model, Ndf, RoughnessConvention};
use serde_json::Value;
use std::path::Path;

use crate::command;
use command::{json_of, kiln, number, succeeded};

/// Runs `kiln verify ... --json` and returns its exit status and report.
fn verify(args: &[&str]) -> (Option<i32>, Value) {
    json_of("verify", args)
}

fn bake(dir: &Path, extra: &[&str]) {
    let mut args = vec![
        "bake",
        "--size",
        "6",
        "--samples",
        "65536",
        "--avg-samples",
        "16384",
        "--no-reference-check",
        "--format",
        "exr,bin,json",
        "-q",
        "--out",
        dir.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    let output = kiln(&args);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
}

/// One channel of a kiln sidecar, in f64.
fn sidecar_values(path: &Path, channel: &str) -> Vec<f64> {
    let sidecar: Value = serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap();
    sidecar["data"][channel]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect()
}

/// Where QMC is not dominated by rare events (alpha >= 0.06 here), every node's error against the
/// reference is within five of its standard errors (plus the reference's own 1e-10).
#[test]
fn node_errors_of_a_kiln_table_are_consistent_with_its_standard_errors() {
    let options = BakeOptions {
        size: 8,
        samples: 1 << 16,
        average_samples: 1 << 16,
        roughness_convention: RoughnessConvention::Alpha,
        check_against_reference: false,
        max_error: None,
        // Point samples: each texel is its QMC estimate.
        texels: Some(kiln::table::Texels::Nodes),
        ..BakeOptions::default()
    };
    let tables = options.bake(&|_| {}).unwrap();
    let e = &tables[0];
    let report = audit(
        e,
        &Against::Reference(ReferenceSettings::default()),
        &AuditSettings::default(),
        &|_| {},
    );
    let mut largest_ratio: f64 = 0.0;
    for k in 0..e.spec.len() {
        let (alpha, mu) = e.spec.texel_coordinates(k);
        let r = reference_albedo(
            e.spec.model,
            alpha,
            mu.unwrap(),
            &ReferenceSettings::default(),
        );
        let error = (e.value[k] - r.value).abs();
        assert!(
            error <= 5.0 * e.std_error[k] + 1e-10,
            "texel {k}: error {error:.2e}, std error {:.2e}",
            e.std_error[k]
        );
        largest_ratio = largest_ratio.max(error / e.std_error[k]);
    }
    assert!(report.node_max_error <= 5.0 * e.max_std_error());
    // A sanity check of the other side: errors are not all far below their standard errors.
    assert!(largest_ratio > 0.5, "{largest_ratio}");
}

#[test]
fn every_input_format_and_layout_gives_the_same_audit() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // The adaptive axis on linear rows, which an external table's flags can describe.
    bake(d, &["--mu-axis", "adaptive"]);
    // Audits a file of `d` read as an external table in the bake's layout, with `extra` flags.
    let external = |name: &str, extra: &[&str]| {
        let path = d.join(name);
        let mut args = vec![
            path.to_str().unwrap(),
            "--shape",
            "6x6",
            "--grid",
            "nodes",
            "--mu-axis",
            "adaptive",
        ];
        args.extend_from_slice(extra);
        verify(&args).1
    };
    let (status, from_json) = verify(&[d
        .join("ggx-height-correlated-E-mu-adaptive.json")
        .to_str()
        .unwrap()]);
    assert_eq!(status, Some(0));
    let node = number(&from_json, "node_max_error");
    let lookup = number(&from_json, "lookup_max_error");
    assert_eq!(from_json["nodes"], 36);
    // A 13 x 13 ladder, and 27 grazing probes on each of its 13 roughness rungs.
    assert_eq!(from_json["lookup_points"], 13 * (13 + 27));

    // kiln's EXR and binary hold f32: the same audit to within f32 rounding.
    let (_, from_exr) = verify(&[d
        .join("ggx-height-correlated-E-mu-adaptive.exr")
        .to_str()
        .unwrap()]);
    let (_, from_bin) = verify(&[d
        .join("ggx-height-correlated-E-mu-adaptive.bin")
        .to_str()
        .unwrap()]);
    for report in [&from_exr, &from_bin] {
        assert!(
            (number(report, "node_max_error") - node).abs() < 1e-7,
            "{report}"
        );
        assert!(
            (number(report, "lookup_max_error") - lookup).abs() < 1e-7,
            "{report}"
        );
    }

    // External text, roughness-major and whitespace-separated: identical to the sidecar.
    let values = sidecar_values(&d.join("ggx-height-correlated-E-mu-adaptive.json"), "E");
    let text: Vec<String> = values.iter().map(|v| format!("{v:?}")).collect();
    std::fs::write(
        d.join("r-major.txt"),
        format!("# kiln E, r rows\n{}\n", text.join(" ")),
    )
    .unwrap();
    let from_text = external("r-major.txt", &[]);
    assert_eq!(number(&from_text, "node_max_error"), node);
    assert_eq!(number(&from_text, "lookup_max_error"), lookup);

    // Transposed (mu-major), comma-separated, with --order mu,r: identical again.
    let transposed: Vec<String> = (0..36)
        .map(|k| format!("{:?}", values[(k % 6) * 6 + k / 6]))
        .collect();
    std::fs::write(d.join("mu-major.csv"), transposed.join(",")).unwrap();
    let from_csv = external("mu-major.csv", &["--order", "mu,r"]);
    assert_eq!(number(&from_csv, "node_max_error"), node);
    assert_eq!(number(&from_csv, "lookup_max_error"), lookup);

    // Raw f32 equals kiln's f32 files; raw f16 is within half-float rounding (2^-11 below 1).
    let f32_bytes: Vec<u8> = values
        .iter()
        .flat_map(|&v| (v as f32).to_le_bytes())
        .collect();
    std::fs::write(d.join("e.f32"), f32_bytes).unwrap();
    let raw32 = external("e.f32", &["--dtype", "f32"]);
    assert_eq!(
        number(&raw32, "node_max_error"),
        number(&from_exr, "node_max_error")
    );
    let f16_bytes: Vec<u8> = values
        .iter()
        .flat_map(|&v| half::f16::from_f32(v as f32).to_le_bytes())
        .collect();
    std::fs::write(d.join("e.f16"), f16_bytes).unwrap();
    let raw16 = external("e.f16", &["--dtype", "f16"]);
    assert!(
        (number(&raw16, "node_max_error") - node).abs() <= 2f64.powi(-11),
        "{raw16}"
    );

    // One EXR channel, read as an external table.
    let channel = external(
        "ggx-height-correlated-E-mu-adaptive.exr",
        &["--channel", "E"],
    );
    assert_eq!(
        number(&channel, "node_max_error"),
        number(&from_exr, "node_max_error")
    );
}

/// kiln's default table read as an external one: `--mu-axis balanced` brings the balanced rows
/// kiln lays out with it, and `--texels lookup-fit` has it judged by its lookup, as its sidecar
/// is. The same audit as the file's own, within f32 rounding; with linear rows named instead,
/// the lookups are far off; without `--texels` the nodes (off by 2.3e-4 by design) judge it.
#[test]
fn an_external_table_in_kilns_default_layout_audits_as_its_file_does() {
    let json = Path::new(env!("CARGO_MANIFEST_DIR")).join("tables/ggx-height-correlated-E.json");
    let (_, own) = verify(&[json.to_str().unwrap()]);
    let dir = tempfile::tempdir().unwrap();
    let raw = dir.path().join("e.f32");
    let bytes: Vec<u8> = sidecar_values(&json, "E")
        .iter()
        .flat_map(|&v| (v as f32).to_le_bytes())
        .collect();
    std::fs::write(&raw, bytes).unwrap();
    let external = |extra: &[&str]| {
        let mut args = vec![
            raw.to_str().unwrap(),
            "--shape",
            "32x32",
            "--grid",
            "nodes",
            "--mu-axis",
            "balanced",
            "--dtype",
            "f32",
            "--max-error",
            "2.2e-4",
        ];
        args.extend_from_slice(extra);
        verify(&args)
    };
    let (status, fitted) = external(&["--texels", "lookup-fit"]);
    let lookup = number(&own, "lookup_max_error");
    assert!(lookup < 2.2e-4, "{own}");
    assert_eq!(status, Some(0), "{fitted}");
    assert!(
        (number(&fitted, "lookup_max_error") - lookup).abs() < 1e-6,
        "{fitted} vs {own}"
    );
    let (status, nodes) = external(&[]);
    assert_eq!(status, Some(1), "{nodes}");
    assert!(number(&nodes, "node_max_error") > 2.2e-4, "{nodes}");
    let (_, wrong) = external(&["--texels", "lookup-fit", "--roughness-spacing", "linear"]);
    assert!(
        number(&wrong, "lookup_max_error") > 10.0 * lookup,
        "{wrong}"
    );
}

#[test]
fn layout_flags_match_the_tables_they_describe() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    bake(
        d,
        &[
            "--grid",
            "nodes",
            "--mu-axis",
            "sqrt",
            "--roughness-axis",
            "alpha",
            "--masking",
            "separable",
        ],
    );
    // Not kiln's default layout: the axes are in the names.
    let json = d.join("ggx-separable-E-alpha-mu-sqrt.json");
    let (_, own) = verify(&[json.to_str().unwrap()]);
    let text: Vec<String> = sidecar_values(&json, "E")
        .iter()
        .map(|v| format!("{v:?}"))
        .collect();
    std::fs::write(d.join("e.txt"), text.join("\n")).unwrap();
    let flags = [
        "--shape",
        "6x6",
        "--grid",
        "nodes",
        "--mu-axis",
        "sqrt",
        "--roughness-axis",
        "alpha",
        "--masking",
        "separable",
    ];
    let mut args = vec![d.join("e.txt").to_str().unwrap().to_string()];
    args.extend(flags.iter().map(|s| s.to_string()));
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let (_, external) = verify(&args);
    for field in [
        "node_max_error",
        "node_rms_error",
        "lookup_max_error",
        "lookup_p99_error",
    ] {
        assert_eq!(number(&external, field), number(&own, field), "{field}");
    }
    // A wrong flag is visible: the same numbers read as height-correlated are far off.
    let mut wrong = args.clone();
    wrong.truncate(wrong.len() - 2);
    let (_, misread) = verify(&wrong);
    assert!(number(&misread, "node_max_error") > 100.0 * number(&own, "node_max_error"));
    // So are the numbers read as Beckmann's.
    let mut beckmann = args.clone();
    beckmann.extend(["--ndf", "beckmann"]);
    let (_, misread) = verify(&beckmann);
    assert!(number(&misread, "node_max_error") > 100.0 * number(&own, "node_max_error"));

    // An E_avg table, external text of one size (the quantity inferred), against kiln's own
    // reading of it.
    let avg = d.join("ggx-separable-E_avg-alpha-rows-linear.json");
    let (_, own) = verify(&[avg.to_str().unwrap()]);
    let numbers: Vec<String> = sidecar_values(&avg, "E_avg")
        .iter()
        .map(|v| format!("{v:?}"))
        .collect();
    std::fs::write(d.join("avg.txt"), numbers.join(" ")).unwrap();
    let (_, external) = verify(&[
        d.join("avg.txt").to_str().unwrap(),
        "--shape",
        "6",
        "--grid",
        "nodes",
        "--roughness-axis",
        "alpha",
        "--masking",
        "separable",
    ]);
    assert_eq!(own["quantity"], "E_avg");
    for field in ["node_max_error", "lookup_max_error", "lookup_p99_error"] {
        assert_eq!(number(&external, field), number(&own, field), "{field}");
    }
}

#[test]
fn clamp_min_says_where_the_first_nodes_were_computed() {
    // A 3 x 3 node table computed Cycles' way: coordinates below 1e-4 moved up to 1e-4.
    let model = Model {
        ndf: Ndf::Ggx,
        masking: Masking::HeightCorrelated,
    };
    let s = ReferenceSettings::default();
    let axis = [0.0f64, 0.5, 1.0];
    let mut values = Vec::new();
    for &mu in &axis {
        for &r in &axis {
            let (mu, r) = (mu.max(1e-4), r.max(1e-4));
            values.push(format!(
                "{:?}",
                reference_albedo(model, r * r, mu, &s).value
            ));
        }
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("clamped.txt");
    std::fs::write(&path, values.join(" ")).unwrap();
    let p = path.to_str().unwrap();
    let layout = ["--shape", "3x3", "--order", "mu,r", "--grid", "nodes"];
    let (_, clamped) = verify(&[&[p, "--clamp-min", "1e-4"][..], &layout].concat());
    let (_, unclamped) = verify(&[&[p][..], &layout].concat());
    assert!(number(&clamped, "node_max_error") < 1e-9, "{clamped}");
    // Without the flag the mu = 0 row is compared with E(mu = 0) = 1, which it is not: the largest gap
    // is at r = 1, 1 - E(mu = 1e-4, alpha = 1).
    let gap = 1.0 - reference_albedo(model, 1.0, 1e-4, &s).value;
    assert!(
        (number(&unclamped, "node_max_error") - gap).abs() < 1e-9,
        "{unclamped} vs {gap}"
    );
}

#[test]
fn bad_tables_get_a_clear_error_and_status_2() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("short.txt"), "0.5 0.6 0.7").unwrap();
    std::fs::write(d.join("nan.txt"), "0.5 NaN 0.7 0.8").unwrap();
    std::fs::write(d.join("word.txt"), "0.5 half 0.7 0.8").unwrap();
    std::fs::write(d.join("odd.f32"), [0u8; 10]).unwrap();
    let cases: &[(&[&str], &str)] = &[
        (&["short.txt", "--shape", "2x2"], "holds 3 values"),
        (&["nan.txt", "--shape", "2x2"], "not a finite number"),
        (&["word.txt", "--shape", "2x2"], "'half' is not a number"),
        (
            &["odd.f32", "--shape", "2x2", "--dtype", "f32"],
            "whole number",
        ),
        (&["short.txt"], "--shape"),
        (
            &["short.txt", "--shape", "3", "--quantity", "e"],
            "--order names 2 axes",
        ),
        (&["short.txt", "--shape", "0x3"], "shape"),
        (&["missing.txt", "--shape", "2x2"], "missing.txt"),
        (
            &[
                "short.txt",
                "--shape",
                "3",
                "--quantity",
                "e-avg",
                "--max-error",
                "-1",
            ],
            "positive",
        ),
    ];
    for (args, mentions) in cases {
        let mut full = vec!["verify".to_string()];
        full.push(d.join(args[0]).to_string_lossy().into_owned());
        full.extend(args[1..].iter().map(|s| s.to_string()));
        let full: Vec<&str> = full.iter().map(String::as_str).collect();
        let output = kiln(&full);
        let message = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "{args:?}: {message}");
        assert_eq!(message.trim_end().lines().count(), 1, "{args:?}: {message}");
        assert!(
            message.contains(mentions),
            "{args:?}: '{message}' should mention {mentions}"
        );
    }
}

#[test]
fn max_error_gates_a_build_and_tables_compare_with_each_other() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    bake(d, &[]);
    let json = d.join("ggx-height-correlated-E.json");
    let (status, report) = verify(&[json.to_str().unwrap(), "--max-error", "1e-12"]);
    assert_eq!(status, Some(1));
    assert_eq!(report["passed"], false);
    let (status, report) = verify(&[json.to_str().unwrap(), "--max-error", "0.01"]);
    assert_eq!(status, Some(0));
    assert_eq!(report["passed"], true);
    // Against its own f32 copy: only f32 rounding apart.
    let exr = d.join("ggx-height-correlated-E.exr");
    let (_, report) = verify(&[json.to_str().unwrap(), "--against", exr.to_str().unwrap()]);
    assert!(number(&report, "node_max_error") < 1e-7, "{report}");
    assert!(report["against"].as_str().unwrap().starts_with("table"));
}

/// `kiln verify --plot` draws the audit's error maps: an engine file audited with
/// `--preset` gives one picture per table (its quantity in the name), each naming its groups and
/// their worst error; a PNG is a PNG; a plot that is neither is refused before any work.
#[test]
fn plot_draws_where_a_table_is_wrong() {
    let three =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/engines/three/DFGLUTData-16.js");
    let dir = tempfile::tempdir().unwrap();
    let svg = dir.path().join("three.svg");
    succeeded(&[
        "verify",
        "--preset",
        "three",
        three.to_str().unwrap(),
        "--plot",
        svg.to_str().unwrap(),
        "--quiet",
        "--density",
        "1",
    ]);
    for quantity in ["E_scale", "E_bias"] {
        let text = std::fs::read_to_string(dir.path().join(format!("three-{quantity}.svg")))
            .unwrap_or_else(|e| panic!("{quantity}: {e}"));
        assert!(text.starts_with("<svg"), "{quantity}");
        assert!(text.contains("nodes: max") && text.contains("lookups: max"));
    }
    // three's scale is 1.42e-2 off at its worst node.
    let text = std::fs::read_to_string(dir.path().join("three-E_scale.svg")).unwrap();
    assert!(text.contains("nodes: max 1.42e-2"), "{text}");
    assert!(!svg.exists());
    let average =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tables/ggx-height-correlated-E_avg.json");
    let png = dir.path().join("average.png");
    let output = kiln(&[
        "verify",
        average.to_str().unwrap(),
        "--plot",
        png.to_str().unwrap(),
        "--quiet",
        "--against",
        average.to_str().unwrap(),
    ]);
    assert_eq!(output.status.code(), Some(0));
    assert!(std::fs::read(&png).unwrap().starts_with(b"\x89PNG"));
    let bad = dir.path().join("plot.jpg");
    command::refused(
        &[
            "verify",
            average.to_str().unwrap(),
            "--plot",
            bad.to_str().unwrap(),
        ],
        &[".svg or .png"],
    );
    assert!(!bad.exists());
}

/// The modes of the last release's `kiln verify` that are commands now still work for this
/// release: the same report as the new command's, and a note on stderr that names it (none
/// with --quiet).
#[test]
fn old_verify_modes_run_their_new_commands_with_a_note() {
    let e = Path::new(env!("CARGO_MANIFEST_DIR")).join("tables/ggx-height-correlated-E.json");
    let e = e.to_str().unwrap();
    let old = kiln(&["verify", "--furnace", e, "--form", "kulla-conty", "--json"]);
    let new = kiln(&["furnace", e, "--form", "kulla-conty", "--json"]);
    assert_eq!(old.status.code(), Some(0));
    assert_eq!(old.stdout, new.stdout);
    let note = String::from_utf8_lossy(&old.stderr);
    assert!(
        note.contains("`kiln verify --furnace` is now `kiln furnace`"),
        "{note}"
    );
    assert!(new.stderr.is_empty());
    let old = kiln(&["verify", "--fit=nonesuch", "-q"]);
    assert_eq!(old.status.code(), Some(2));
    let said = String::from_utf8_lossy(&old.stderr);
    assert!(
        said.contains("nonesuch: neither a fit kiln knows") && !said.contains("note"),
        "{said}"
    );
}
