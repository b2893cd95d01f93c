//! A new user's first minutes (issue 16): a clone that tests itself, folders of tables that stay
//! consistent, flags that are never silently ignored, every file kiln writes readable by
//! `verify`, help and messages that teach, scenes, names and metadata that agree.

#![cfg(feature = "cli")]

use serde_json::Value;
use std::path::Path;
use std::process::Output;

#[path = "common/command.rs"]
mod command;
use command::{kiln, refused, stderr};

fn stdout(output: &Output) -> String {
    String::from_utf8_lossy(&output.stdout).into_owned()
}

fn files_in(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// A quick bake (8 x 8 unless `extra` sets the size; quadrature to 1e-5) into `dir`.
fn bake(dir: &Path, extra: &[&str]) -> Output {
    let mut args = vec![
        "bake",
        "--max-error",
        "1e-4",
        "-q",
        "--out",
        dir.to_str().unwrap(),
    ];
    if !extra.contains(&"--size") {
        args.extend(["--size", "8"]);
    }
    args.extend_from_slice(extra);
    kiln(&args)
}

/// Item 1: nothing in the repository reads or cites anything beside it.
#[test]
fn nothing_reaches_outside_the_repository() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut stack = vec![
        root.join("src"),
        root.join("tests"),
        root.join("examples"),
        root.join("benches"),
        root.join("docs"),
        root.join("scripts"),
        root.join(".ci"),
        root.join("README.md"),
        root.join("Cargo.toml"),
    ];
    let needle = ["..", "/shared"].concat();
    while let Some(path) = stack.pop() {
        if path.is_dir() {
            if path.ends_with("target") || path.ends_with("data") {
                continue;
            }
            stack.extend(std::fs::read_dir(&path).unwrap().map(|e| e.unwrap().path()));
        } else if let Ok(text) = std::fs::read_to_string(&path) {
            assert!(
                !text.contains(&needle),
                "{} reaches outside",
                path.display()
            );
        }
    }
}

/// Item 2: the repository root holds what a user expects, and no package archives.
#[test]
fn the_repository_root_holds_no_junk() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let expected = [
        ".ci",
        ".git",
        ".gitignore",
        "Cargo.lock",
        "Cargo.toml",
        "LICENSE-APACHE",
        "LICENSE-MIT",
        "README.md",
        "benches",
        "docs",
        "examples",
        "fuzz",
        "scripts",
        "src",
        "tables",
        "target",
        "tests",
    ];
    for name in files_in(root) {
        assert!(
            expected.contains(&name.as_str()),
            "unexpected {name} in the root"
        );
    }
    let ignore = std::fs::read_to_string(root.join(".gitignore")).unwrap();
    assert!(ignore.lines().any(|line| line == "*.whl"));
}

/// Item 3: tables of other layouts get other names; a bake refuses to replace a table of the
/// same name made to another spec (nothing written) unless --force, which leaves one
/// consistent set.
#[test]
fn tables_of_different_specs_never_overwrite_each_other_silently() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    assert!(bake(d, &[]).status.success());
    let sidecar = d.join("ggx-height-correlated-E.json");
    let before = std::fs::read(&sidecar).unwrap();
    // Another layout: its own names, the default table untouched.
    assert!(
        bake(d, &["--mu-axis", "linear", "--grid", "centers"])
            .status
            .success()
    );
    assert!(
        d.join("ggx-height-correlated-E-mu-linear-centers.json")
            .exists()
    );
    assert!(
        d.join("ggx-height-correlated-E_avg-rows-linear-centers.exr")
            .exists()
    );
    // An engine preset: the engine's file and its own sidecars.
    let output = kiln(&[
        "bake",
        "--preset",
        "unreal",
        "-q",
        "--out",
        d.to_str().unwrap(),
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    assert!(d.join("unreal-ggx-height-correlated-E.json").exists());
    assert_eq!(std::fs::read(&sidecar).unwrap(), before);
    // The same name at another size: refused, nothing written.
    let listing = files_in(d);
    let output = bake(d, &["--size", "6", "--format", "json"]);
    assert_eq!(output.status.code(), Some(2));
    let message = stderr(&output);
    for word in [
        "ggx-height-correlated-E.{exr,bin,rs,json,png}",
        "8x8",
        "6x6",
        "--force",
    ] {
        assert!(message.contains(word), "{message} lacks {word}");
    }
    assert_eq!(files_in(d), listing);
    assert_eq!(std::fs::read(&sidecar).unwrap(), before);
    // Forced: the JSON replaced, the other formats of that table removed.
    assert!(
        bake(d, &["--size", "6", "--format", "json", "--force"])
            .status
            .success()
    );
    assert_ne!(std::fs::read(&sidecar).unwrap(), before);
    for extension in ["exr", "bin", "rs", "png"] {
        assert!(
            !d.join(format!("ggx-height-correlated-E.{extension}"))
                .exists()
        );
    }
    assert!(
        d.join("ggx-height-correlated-E-mu-linear-centers.exr")
            .exists()
    );
    // The same spec again: replaced silently (byte-identical).
    assert!(
        bake(d, &["--size", "6", "--format", "json"])
            .status
            .success()
    );
}

/// Item 4: a flag that does not apply is an error saying why, never ignored or reinterpreted.
#[test]
fn flags_are_never_silently_ignored() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    refused(
        &["bake", "--no-reference-check", "--out", out],
        &["--no-reference-check", "--method qmc"],
    );
    refused(
        &[
            "bake",
            "--method",
            "reference",
            "--samples",
            "1024",
            "--out",
            out,
        ],
        &["--samples", "--method reference"],
    );
    refused(
        &["bake", "--method", "reference", "--seed", "3", "--out", out],
        &["--seed"],
    );
    refused(
        &[
            "eval",
            "--quantity",
            "e-avg",
            "--mu",
            "0.3",
            "--roughness",
            "0.5",
        ],
        &["--mu 0.3", "e-avg"],
    );
    let table = Path::new(env!("CARGO_MANIFEST_DIR")).join("tables/ggx-height-correlated-E.json");
    refused(
        &[
            "verify",
            table.to_str().unwrap(),
            "--ndf",
            "beckmann",
            "--shape",
            "16x16",
        ],
        &["--shape", "--ndf", "carries its own layout", "32x32"],
    );
    // One rule for sample counts, named by the flag given.
    refused(
        &["bake", "--samples", "2^36", "--out", out],
        &["--samples", "from 8 to 2^35"],
    );
    refused(
        &[
            "bake",
            "--scrambles",
            "2",
            "--samples",
            "2^34",
            "--out",
            out,
        ],
        &["--samples", "from 2 to 2^33"],
    );
    refused(
        &["bake", "--avg-samples", "3", "--out", out],
        &["--avg-samples", "power of two"],
    );
    refused(
        &["eval", "--samples", "4", "--mu", "0.5", "--alpha", "0.5"],
        &["--samples", "from 8 to 2^35"],
    );
    assert!(files_in(dir.path()).is_empty());
    // --samples alone means QMC (its help says so), and then the check may be skipped.
    let output = kiln(&[
        "bake",
        "--size",
        "4",
        "--samples",
        "2^10",
        "--no-reference-check",
        "--format",
        "json",
        "-q",
        "--out",
        out,
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
}

/// Item 5: `verify` reads every file kiln writes, from their own metadata or the sidecar, and
/// gets the same audit from each (within f32 and f16 rounding).
#[test]
fn verify_reads_every_format_kiln_writes() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let output = bake(d, &["--format", "json,exr,bin,rs,ktx2,dds,h"]);
    assert!(output.status.success(), "{}", stderr(&output));
    let audit = |file: &Path| -> Value {
        let output = kiln(&["verify", "--json", file.to_str().unwrap()]);
        assert_eq!(
            output.status.code(),
            Some(0),
            "{}: {}",
            file.display(),
            stderr(&output)
        );
        serde_json::from_slice(&output.stdout).unwrap()
    };
    for stem in ["ggx-height-correlated-E", "ggx-height-correlated-E_avg"] {
        let json = audit(&d.join(format!("{stem}.json")));
        let lookup = json["lookup_max_error"].as_f64().unwrap();
        let node = json["node_max_error"].as_f64().unwrap();
        // (E_avg's reference is slow to audit: two formats of it suffice.)
        let extensions: &[&str] = if stem.ends_with("E_avg") {
            &["ktx2", "rs"]
        } else {
            &["exr", "bin", "rs", "ktx2", "dds", "h"]
        };
        for extension in extensions {
            let report = audit(&d.join(format!("{stem}.{extension}")));
            assert_eq!(report["quantity"], json["quantity"], "{extension}");
            assert_eq!(report["shape"], json["shape"], "{extension}");
            // f32 storage: the errors move by f32 rounding only (6e-8 near 1).
            let other = report["node_max_error"].as_f64().unwrap();
            assert!((other - node).abs() < 1e-7, "{stem}.{extension}: {report}");
            let other = report["lookup_max_error"].as_f64().unwrap();
            assert!(
                (other - lookup).abs() < 1e-7,
                "{stem}.{extension}: {report}"
            );
        }
    }
    // Without the sidecar: C and Rust carry their metadata, DDS and binary cannot.
    std::fs::remove_file(d.join("ggx-height-correlated-E.json")).unwrap();
    for extension in ["h", "rs", "ktx2"] {
        audit(&d.join(format!("ggx-height-correlated-E.{extension}")));
    }
    let dds = d.join("ggx-height-correlated-E.dds");
    refused(&["verify", dds.to_str().unwrap()], &["sidecar", "DDS"]);
    // An external one-size table is an E_avg table.
    let values: Vec<String> = (0..8)
        .map(|k| format!("{}", 1.0 - 0.05 * f64::from(k)))
        .collect();
    let text = d.join("avg.txt");
    std::fs::write(&text, values.join("\n")).unwrap();
    let output = kiln(&["verify", "--json", text.to_str().unwrap(), "--shape", "8"]);
    assert!(output.status.success(), "{}", stderr(&output));
    let report: Value = serde_json::from_slice(&output.stdout).unwrap();
    assert_eq!(report["quantity"], "E_avg");
}

/// Item 6: help agrees with behaviour, and speaks the user's language.
#[test]
fn help_texts_are_true() {
    let help = |command: &str| stdout(&kiln(&[command, "--help"]));
    let bake = help("bake");
    assert!(
        bake.contains("[default: 2^19]"),
        "bake --help: samples default"
    );
    assert!(!bake.contains("2^16]"));
    assert!(bake.contains("KTX2 and DDS"), "bake --help: --precision");
    let verify = help("verify");
    assert!(verify.contains("[default: linear, as engines' tables are]"));
    assert!(!verify.contains("The default."), "verify --help: --mu-axis");
    assert!(!verify.contains("Store and use"), "verify --help: --dtype");
    for command in [
        "bake",
        "eval",
        "plan",
        "verify",
        "study",
        "merge",
        "compensation",
    ] {
        let text = help(command);
        assert!(!text.contains("[`"), "{command} --help shows rustdoc links");
        assert!(
            !text.contains("physics.md"),
            "{command} --help cites a file"
        );
        assert!(text.lines().count() < 200, "{command} --help is too long");
    }
}

/// Item 7: messages that teach.
#[test]
fn messages_teach() {
    // No arguments: the commands, on stderr, status 2.
    let output = kiln(&[]);
    assert_eq!(output.status.code(), Some(2));
    let all = format!("{}{}", stdout(&output), stderr(&output));
    for word in ["bake", "verify", "plan", "eval", "study"] {
        assert!(all.contains(word), "{all}");
    }
    refused(
        &["plan", "scene.toml"],
        &["tip: name a scene file with --scene scene.toml"],
    );
    refused(&["bake", "--scen", "x"], &["tip:", "--scene"]);
    refused(
        &["eval", "--alpha", "-1", "--mu", "0.5"],
        &["alpha", "[0, 1000]"],
    );
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // An engine's reader names the file and the layout.
    let bad = d.join("dfg.ktx2");
    std::fs::write(&bad, b"not a texture").unwrap();
    refused(
        &["verify", "--preset", "bevy", bad.to_str().unwrap()],
        &[bad.to_str().unwrap(), "bevy", "KTX2"],
    );
    // A scene's Fresnel model without its parameters: the forms it takes.
    let scene = d.join("scene.toml");
    std::fs::write(
        &scene,
        "[[material]]\nname = \"a\"\nndf = \"ggx\"\nroughness = 0.3\nfresnel = \"schlick\"\n",
    )
    .unwrap();
    refused(
        &["plan", "--scene", scene.to_str().unwrap()],
        &["line 5", "schlick = { f0 = 0.04 }", "dielectric"],
    );
    // An empty scene warns.
    std::fs::write(&scene, "").unwrap();
    let output = kiln(&["plan", "--scene", scene.to_str().unwrap()]);
    assert!(output.status.success());
    assert!(stderr(&output).contains("warning"), "{}", stderr(&output));
    // --furnace on an E_avg file asks for the E file.
    let tables = Path::new(env!("CARGO_MANIFEST_DIR")).join("tables");
    let average = tables.join("ggx-height-correlated-E_avg.json");
    refused(
        &["verify", "--furnace", average.to_str().unwrap()],
        &["--furnace", "E file", "E_avg"],
    );
    // A truncated kiln sidecar is damaged, not an external table without --shape.
    let text = std::fs::read(tables.join("ggx-height-correlated-E.json")).unwrap();
    let cut = d.join("cut.json");
    std::fs::write(&cut, &text[..text.len() / 2]).unwrap();
    let message = refused(&["verify", cut.to_str().unwrap()], &["damaged"]);
    assert!(!message.contains("--shape"), "{message}");
}

/// Item 8: a long bake says how long before it starts, on any stderr (here a pipe).
#[test]
fn a_long_bake_says_how_long_on_any_stderr() {
    let dir = tempfile::tempdir().unwrap();
    let line = command::first_stderr_line(
        &[
            "bake",
            "--size",
            "4096",
            "--out",
            dir.path().to_str().unwrap(),
        ],
        &[],
    );
    assert!(
        line.contains("estimated") && (line.contains(" h ") || line.contains(" min ")),
        "{line}"
    );
    // Interrupted: nothing written.
    assert!(files_in(dir.path()).is_empty());
    // `kiln plan` gives each table's estimate.
    let scene = dir.path().join("glass.toml");
    std::fs::write(
        &scene,
        "[[material]]\nname = \"glass\"\nndf = \"ggx\"\nroughness = 0.1\n\
         fresnel = { dielectric = { ior = 1.5 } }\ntransmission = true\n",
    )
    .unwrap();
    let output = kiln(&["plan", "--scene", scene.to_str().unwrap(), "--json"]);
    let plan: Value = serde_json::from_slice(&output.stdout).unwrap();
    let costs: Vec<f64> = plan["tables"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t["estimated_core_seconds"].as_f64().unwrap())
        .collect();
    assert_eq!(costs.len(), 7);
    // The fitted E (listed first: its fit's reference evaluations) and the four glass tables
    // are the expensive ones: seconds each, where E_avg and f_ms_norm take a fraction of one.
    let (reflection, glass) = costs.split_at(3);
    let cheap = reflection[1].max(reflection[2]);
    assert!(
        glass
            .iter()
            .chain(&reflection[..1])
            .all(|&c| c > 4.0 * cheap)
            && costs.iter().all(|&c| c > 0.0),
        "{costs:?}"
    );
}

/// Item 9: one name for each thing, and metadata that states only what holds.
#[test]
fn names_and_metadata_agree() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    assert!(bake(d, &["--format", "rs,h,json"]).status.success());
    let rust = std::fs::read_to_string(d.join("ggx-height-correlated-E.rs")).unwrap();
    let c = std::fs::read_to_string(d.join("ggx-height-correlated-E.h")).unwrap();
    assert!(rust.contains("pub const GGX_HEIGHT_CORRELATED_E_ONE_MINUS:"));
    assert!(c.contains("static const float GGX_HEIGHT_CORRELATED_E_ONE_MINUS["));
    // The quadrature has no scrambles.
    let sidecar: Value =
        serde_json::from_slice(&std::fs::read(d.join("ggx-height-correlated-E.json")).unwrap())
            .unwrap();
    assert!(
        sidecar.get("scrambles").is_none(),
        "{}",
        sidecar["estimator"]
    );
    // F_avg depends on no microfacet model.
    let output = kiln(&[
        "bake",
        "--quantity",
        "f-avg",
        "--format",
        "json",
        "-q",
        "--out",
        d.to_str().unwrap(),
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    let f_avg: Value =
        serde_json::from_slice(&std::fs::read(d.join("dielectric-F_avg.json")).unwrap()).unwrap();
    assert!(
        f_avg["ndf"].as_str().unwrap().starts_with("none"),
        "{}",
        f_avg["ndf"]
    );
    // A preset's sidecars name the engine file they describe.
    let web = d.join("web");
    let output = kiln(&[
        "bake",
        "--preset",
        "three",
        "-q",
        "--out",
        web.to_str().unwrap(),
    ]);
    assert!(output.status.success());
    let three: Value = serde_json::from_slice(
        &std::fs::read(web.join("three-ggx-height-correlated-E_scale.json")).unwrap(),
    )
    .unwrap();
    assert_eq!(three["files"]["three"], "DFGLUTData.js");
    // eval's text names the masking.
    let output = kiln(&[
        "eval",
        "--mu",
        "0.5",
        "--alpha",
        "0.5",
        "--masking",
        "separable",
    ]);
    assert!(
        stdout(&output).contains("ggx separable"),
        "{}",
        stdout(&output)
    );
}

/// Item 10: `verify --quiet` is a silent build gate.
#[test]
fn verify_quiet_is_a_build_gate() {
    let table = Path::new(env!("CARGO_MANIFEST_DIR")).join("tables/ggx-height-correlated-E.json");
    let table = table.to_str().unwrap();
    let output = kiln(&[
        "verify",
        table,
        "--quiet",
        "--max-error",
        // The fitted table is judged by its lookup (2.3e-4).
        "3e-4",
        "--density",
        "1",
    ]);
    assert_eq!(output.status.code(), Some(0));
    assert!(output.stdout.is_empty() && output.stderr.is_empty());
    let output = kiln(&[
        "verify",
        table,
        "--quiet",
        "--max-error",
        "1e-12",
        "--density",
        "1",
    ]);
    assert_eq!(output.status.code(), Some(1));
    assert!(output.stdout.is_empty());
    let message = stderr(&output);
    assert_eq!(message.lines().count(), 1, "{message}");
    assert!(message.contains("exceeds --max-error 1e-12"), "{message}");
}

/// kiln's glass layout (issue 38): a product-grid mu axis asked of it names the product grid;
/// the furnace picture of a table over the IOR is drawn (over mu and the IOR).
#[test]
fn the_glass_layout_refuses_what_it_cannot_do() {
    refused(
        &["bake", "--quantity", "e-dielectric", "--mu-axis", "linear"],
        &["--mu-axis linear", "glass layout", "--ior-axis cycles"],
    );
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    let baked = kiln(&[
        "bake",
        "--quantity",
        "e-dielectric",
        "--size",
        "3",
        "--ior-size",
        "2",
        "--max-error",
        "1e-3",
        "--format",
        "json",
        "--out",
        out,
        "-q",
    ]);
    assert!(baked.status.success(), "{}", stderr(&baked));
    let table = dir.path().join("ggx-height-correlated-E_dielectric.json");
    // Its furnace picture is drawn (over mu and the IOR; it was refused before issue 38's
    // picture), a PNG.
    let picture = dir.path().join("furnace.png");
    let drawn = kiln(&[
        "verify",
        "--furnace",
        table.to_str().unwrap(),
        "--plot",
        picture.to_str().unwrap(),
        "--density",
        "1",
    ]);
    assert!(drawn.status.success(), "{}", stderr(&drawn));
    let png = std::fs::read(&picture).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
}

/// kiln's balanced layout lays out the tables over roughness and mu: balanced rows with a
/// table over the IOR are refused by name (asked for, or the default of `--mu-axis balanced`),
/// and so is the balanced mu axis with a quantity that varies with `mu` on a mirror.
#[test]
fn the_balanced_layout_refuses_what_it_cannot_do() {
    refused(
        &[
            "bake",
            "--quantity",
            "e,e-dielectric",
            "--ior-axis",
            "cycles",
            "--roughness-spacing",
            "balanced",
        ],
        &[
            "--roughness-spacing balanced",
            "E_dielectric",
            "separate command",
        ],
    );
    refused(
        &[
            "bake",
            "--quantity",
            "e-dielectric",
            "--ior-axis",
            "cycles",
            "--mu-axis",
            "balanced",
        ],
        &[
            "default with --mu-axis balanced",
            "--roughness-spacing linear",
        ],
    );
    refused(
        &["bake", "--quantity", "e-scale", "--mu-axis", "balanced"],
        &[
            "--mu-axis split-sum (kiln's layout for it), linear or sqrt",
            "balanced mu axis",
        ],
    );
}
