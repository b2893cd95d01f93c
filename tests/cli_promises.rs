//! The command line's promises to a new user, from their first minutes (issue 16) and first
//! hour (issue 42): a clone that tests itself and a repository root with nothing foreign in it;
//! folders of tables that stay consistent, and no empty folder after a refusal or an interrupt;
//! flags never silently ignored; every file kiln writes readable by `verify`; help and messages
//! that teach and point the right way; numbers read as written; long runs that say how long
//! first; scenes, names and metadata that agree; the layouts refusing what they cannot do.

#![cfg(feature = "cli")]

use serde_json::Value;
use std::path::Path;
use std::process::{Command, Output, Stdio};

use crate::command;
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
        "anisotropic",
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
        &["bake", "scene.toml"],
        &["tip: name a scene file with --scene scene.toml"],
    );
    // `kiln plan` takes the scene as its argument, and names a missing one.
    refused(&["plan", "scene.toml"], &["cannot read scene.toml"]);
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
        &["plan", scene.to_str().unwrap()],
        &["line 5", "schlick = { f0 = 0.04 }", "dielectric"],
    );
    // An empty scene warns.
    std::fs::write(&scene, "").unwrap();
    let output = kiln(&["plan", scene.to_str().unwrap()]);
    assert!(output.status.success());
    assert!(stderr(&output).contains("warning"), "{}", stderr(&output));
    // The furnace of an E_avg file asks for the E file.
    let tables = Path::new(env!("CARGO_MANIFEST_DIR")).join("tables");
    let average = tables.join("ggx-height-correlated-E_avg.json");
    refused(
        &["furnace", average.to_str().unwrap()],
        &["white furnace", "E file", "E_avg"],
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
    let output = kiln(&["plan", scene.to_str().unwrap(), "--json"]);
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
        "furnace",
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

fn ok(args: &[&str]) -> Output {
    let output = kiln(args);
    assert!(output.status.success(), "{args:?}: {}", stderr(&output));
    output
}

/// Item 2: `--seed` and `--scrambles` on a bake the quadrature makes (the default max error,
/// or any below 1e-3) changed the recorded spec and nothing else; the IOR flags without a
/// table over the IOR were ignored; `verify --json --quiet` printed the JSON anyway.
#[test]
fn flags_a_bake_would_ignore_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let o = out.to_str().unwrap();
    refused(
        &["bake", "--seed", "3", "--out", o],
        &["--seed", "--max-error 1e-7", "quadrature", "--method qmc"],
    );
    refused(
        &[
            "bake",
            "--max-error",
            "1e-5",
            "--scrambles",
            "4",
            "--out",
            o,
        ],
        &["--scrambles", "--max-error 1e-5"],
    );
    for flag in [
        ["--ior-size", "8"],
        ["--ior-max", "2"],
        ["--ior-axis", "linear"],
    ] {
        refused(
            &["bake", flag[0], flag[1], "--out", o],
            &[
                flag[0],
                "none of the tables baked",
                "--quantity e-dielectric",
            ],
        );
    }
    let table = Path::new(env!("CARGO_MANIFEST_DIR")).join("tables/ggx-height-correlated-E.json");
    refused(
        &["verify", table.to_str().unwrap(), "--json", "--quiet"],
        &["--quiet", "--json", "cannot be used with"],
    );
    assert!(!out.exists(), "a refusal created {}", out.display());
    // Where they apply, they are taken: QMC at 1e-2 reads the seed, a glass table the IOR size.
    ok(&[
        "bake",
        "--size",
        "4",
        "--max-error",
        "1e-2",
        "--seed",
        "3",
        "--format",
        "json",
        "-q",
        "--out",
        o,
    ]);
    ok(&[
        "bake",
        "--quantity",
        "f-avg",
        "--size",
        "4",
        "--ior-size",
        "5",
        "--format",
        "json",
        "-q",
        "--out",
        o,
    ]);
}

/// Item 2: a bake refused for replacing tables of another spec showed two descriptions that
/// read the same; it now names the field that differs, with both values.
#[test]
fn the_replacement_refusal_names_the_field_that_differs() {
    let dir = tempfile::tempdir().unwrap();
    let o = dir.path().to_str().unwrap();
    let bake = |seed: &str| {
        kiln(&[
            "bake",
            "--size",
            "4",
            "--max-error",
            "1e-2",
            "--seed",
            seed,
            "--format",
            "json",
            "-q",
            "--out",
            o,
        ])
    };
    assert!(bake("1").status.success());
    let refusal = bake("2");
    assert_eq!(refusal.status.code(), Some(2));
    let message = stderr(&refusal);
    assert!(
        message.contains("differing in qmc.seed (1 in the file, 2 here)"),
        "{message}"
    );
}

/// Item 9: a refused or interrupted bake into a new folder left the folder behind, empty.
#[test]
fn refusals_and_interrupts_leave_no_empty_folders() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("new").join("deeper");
    let o = out.to_str().unwrap();
    // Refused after the folder check: a carried file that is not Blender's.
    let bad = dir.path().join("bad.tables");
    std::fs::write(&bad, "nothing").unwrap();
    refused(
        &[
            "bake",
            "--preset",
            "cycles",
            "--carry-over",
            bad.to_str().unwrap(),
            "--out",
            o,
        ],
        &["has no array table_sheen_ltc"],
    );
    assert!(!dir.path().join("new").exists());
    // Interrupted: a bake of minutes, killed once it has started integrating.
    let mut child = Command::new(env!("CARGO_BIN_EXE_kiln"))
        .args(["bake", "--size", "512", "--max-error", "1e-9", "--out", o])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(1500));
    assert!(
        child.try_wait().unwrap().is_none(),
        "the bake ended before it was interrupted"
    );
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(
        !dir.path().join("new").exists(),
        "an interrupted bake left {}",
        out.display()
    );
}

/// Item 9: a mistyped `--plot` path created folders up to the root; now it is refused before
/// the audit, and nothing is created.
#[test]
fn a_plot_path_in_a_missing_folder_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let table = Path::new(env!("CARGO_MANIFEST_DIR")).join("tables/ggx-height-correlated-E.json");
    let plot = dir.path().join("typo").join("maps").join("e.png");
    refused(
        &[
            "verify",
            table.to_str().unwrap(),
            "--plot",
            plot.to_str().unwrap(),
        ],
        &["--plot", "does not exist", "typo"],
    );
    assert!(!dir.path().join("typo").exists());
}

/// Item 7: messages that pointed the wrong way. Every subcommand's `--help` lost its long
/// description (the variants' doc comments replaced it), so the empty-scene warning's `kiln
/// plan --help` said nothing of scenes: it now shows the format, and that example is a scene
/// kiln reads. `bake --roughness` suggested `--roughness-axis`; a PNG given with `--shape` was
/// told to use `--dtype`; kiln's own `E.png` had "no sidecar" beside its sidecar.
#[test]
fn messages_point_the_right_way() {
    let help = String::from_utf8(kiln(&["plan", "--help"]).stdout).unwrap();
    let at = help
        .find("A scene file (TOML")
        .expect("the scene format in plan --help");
    let example: String = help[at..]
        .lines()
        .skip(1)
        .take_while(|l| !l.starts_with("Then"))
        .map(|l| l.strip_prefix("  ").unwrap_or(l))
        .filter(|l| !l.trim_start().starts_with('#'))
        .collect::<Vec<_>>()
        .join("\n");
    kiln::scene::Scene::parse(&example, "plan --help")
        .unwrap_or_else(|e| panic!("the help's scene does not parse: {e}\n{example}"));
    for (command, phrase) in [
        ("bake", "picks the cheapest method"),
        ("verify", "build gate"),
        ("plan", "minimal set of tables its"),
    ] {
        let text = String::from_utf8(kiln(&[command, "--help"]).stdout).unwrap();
        assert!(text.contains(phrase), "kiln {command} --help: {text}");
    }
    let message = refused(&["bake", "--roughness", "0.5"], &["kiln eval --roughness"]);
    assert!(!message.contains("--roughness-axis <"), "{message}");
    let tables = Path::new(env!("CARGO_MANIFEST_DIR")).join("tables");
    let png = tables.join("ggx-height-correlated-E.png");
    let png = png.to_str().unwrap();
    refused(
        &["verify", png],
        &["heat map", "ggx-height-correlated-E.json"],
    );
    let message = refused(&["verify", png, "--shape", "32x32"], &["a PNG image"]);
    assert!(!message.contains("use --dtype"), "{message}");
}

/// Item 9: `eval --roughness 1.5` was taken (a scene refuses it); counts of one were plural;
/// `1e-12` was echoed as `0.000000000001` and `alpha = r^2` with all its binary digits.
#[test]
fn numbers_and_counts_read_as_written() {
    refused(
        &["eval", "--roughness", "1.5", "--mu", "0.5"],
        &["[0, 1]", "--alpha"],
    );
    refused(
        &["bake", "--max-error", "1e-12", "--out", "never"],
        &["(got 1e-12)"],
    );
    let eval = ok(&[
        "eval",
        "--roughness",
        "0.1",
        "--mu",
        "0.5",
        "--method",
        "reference",
    ]);
    let text = String::from_utf8(eval.stdout).unwrap();
    assert!(text.contains("alpha = 0.01)"), "{text}");
    let dir = tempfile::tempdir().unwrap();
    let o = dir.path().to_str().unwrap();
    let bake = ok(&[
        "bake",
        "--quantity",
        "e-avg",
        "--size",
        "4",
        "--format",
        "json",
        "--out",
        o,
    ]);
    let text = String::from_utf8(bake.stdout).unwrap();
    assert!(text.contains("baked 1 table in"), "{text}");
    assert!(text.contains("wrote 1 file to"), "{text}");
    let scene = dir.path().join("one.toml");
    std::fs::write(
        &scene,
        "[[material]]\nname = \"m\"\nndf = \"ggx\"\nroughness = 0.5\nmultiple_scattering = \
         false\nimage_based_lighting = true\n",
    )
    .unwrap();
    let plan = ok(&["plan", scene.to_str().unwrap()]);
    let text = String::from_utf8(plan.stdout).unwrap();
    assert!(text.contains("1 material needs 2 tables"), "{text}");
}

/// Item 4: `verify --preset games202` gave a student no verdict. Four wrong files (rows not
/// flipped, alpha = r, truncation, noise) exited 0 without a word, a perfect file read 0.369
/// as its headline, and a 16-bit PNG was told its floor was 8 bits'. Each file here is kiln's
/// own table with one mistake made on purpose; the verdict must name it.
#[test]
fn a_games202_file_gets_a_verdict_that_names_its_mistake() {
    use kiln::preset::Preset;
    let dir = tempfile::tempdir().unwrap();
    let bake = |convention: Option<kiln::RoughnessConvention>| {
        let mut options = Preset::Games202.bakes(Some(1e-5)).remove(0);
        if let Some(c) = convention {
            options.quantities = vec![kiln::Quantity::E];
            options.roughness_convention = c;
        }
        options.bake(&|_| {}).unwrap()
    };
    let tables = bake(None);
    let truth = tables[0].clone();
    assert_eq!(truth.spec.quantity, kiln::Quantity::E);
    let average = tables[1].clone();
    let n = 128;
    let write = |name: &str, values: Vec<f64>| {
        let mut table = truth.clone();
        table.one_minus_value = values.iter().map(|v| 1.0 - v).collect();
        table.value = values;
        let files = Preset::Games202.files(&[table, average.clone()]).unwrap();
        let (_, bytes) = files.iter().find(|(f, _)| f == "GGX_E_LUT.png").unwrap();
        let folder = dir.path().join(name);
        std::fs::create_dir_all(&folder).unwrap();
        let path = folder.join("GGX_E_LUT.png");
        std::fs::write(&path, bytes).unwrap();
        path
    };
    // --density 1: the verdict reads the nodes; the lookups' default density is for audits.
    let audit = |path: &Path| {
        let out = ok(&[
            "verify",
            "--preset",
            "games202",
            path.to_str().unwrap(),
            "--density",
            "1",
        ]);
        String::from_utf8(out.stdout).unwrap()
    };
    let verdict = |path: &Path| {
        let text = audit(path);
        let found = text
            .lines()
            .find_map(|l| l.trim().strip_prefix("verdict: ").map(str::to_string))
            .unwrap_or_else(|| panic!("no verdict in\n{text}"));
        eprintln!("{}: {found}", path.display());
        found
    };
    let v = truth.value.clone();
    let perfect = write("perfect", v.clone());
    assert!(verdict(&perfect).starts_with("as good as 8-bit storage allows"));
    assert!(audit(&perfect).contains("is the layout's own"));
    // Rows in the other order.
    let flipped: Vec<f64> = (0..n * n).map(|k| v[(n - 1 - k / n) * n + k % n]).collect();
    assert!(verdict(&write("flipped", flipped)).starts_with("the roughness rows are flipped"));
    // alpha = r where the axis is perceptual.
    let alpha_is_r = bake(Some(kiln::RoughnessConvention::Alpha)).remove(0).value;
    assert!(verdict(&write("alpha", alpha_is_r)).starts_with("computed at alpha = r"));
    // floor(255 v) instead of round.
    let truncated: Vec<f64> = v.iter().map(|x| (x * 255.0).floor() / 255.0).collect();
    assert!(verdict(&write("truncated", truncated)).starts_with("truncated, not rounded"));
    // Noise of a few hundredths, as too few samples per texel give.
    let mut state = 0x2545_f491_u64;
    let noisy: Vec<f64> = v
        .iter()
        .map(|x| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let u = (state % 10_000) as f64 / 10_000.0 - 0.5;
            (x + 0.08 * u).clamp(0.0, 1.0)
        })
        .collect();
    assert!(verdict(&write("noisy", noisy)).starts_with("noisy"));
    // A 16-bit PNG of the true values: its floor is 16 bits' (7.6e-6), not 8 bits'.
    let folder = dir.path().join("sixteen");
    std::fs::create_dir_all(&folder).unwrap();
    let path = folder.join("GGX_E_LUT.png");
    let mut data = Vec::with_capacity(2 * n * n);
    for y in 0..n {
        // The homework's file has the roughest row on top.
        let i = n - 1 - y;
        for j in 0..n {
            let word = (v[i * n + j] * 65535.0).round() as u16;
            data.extend_from_slice(&word.to_be_bytes());
        }
    }
    let mut bytes = Vec::new();
    {
        let mut encoder = png::Encoder::new(&mut bytes, n as u32, n as u32);
        encoder.set_color(png::ColorType::Grayscale);
        encoder.set_depth(png::BitDepth::Sixteen);
        let mut writer = encoder.write_header().unwrap();
        writer.write_image_data(&data).unwrap();
    }
    std::fs::write(&path, bytes).unwrap();
    let text = audit(&path);
    assert!(text.contains("the true values in 16-bit"), "{text}");
    assert!(
        verdict(&path).starts_with("as good as 16-bit storage allows"),
        "{text}"
    );
    // Issue 64, defect 6: an 8-bit LUT saved as a 16-bit PNG (levels times 257) is the truth
    // rounded to 8 bits, not noise; so is a 4-bit PNG of the truth at 4 bits. The storage is
    // read from the data, not the header's bit depth alone.
    let grey_png = |name: &str, depth: png::BitDepth, data: Vec<u8>| {
        let folder = dir.path().join(name);
        std::fs::create_dir_all(&folder).unwrap();
        let path = folder.join("GGX_E_LUT.png");
        let mut bytes = Vec::new();
        {
            let mut encoder = png::Encoder::new(&mut bytes, n as u32, n as u32);
            encoder.set_color(png::ColorType::Grayscale);
            encoder.set_depth(depth);
            let mut writer = encoder.write_header().unwrap();
            writer.write_image_data(&data).unwrap();
        }
        std::fs::write(&path, bytes).unwrap();
        path
    };
    // Rows as the homework's file has them, roughest on top.
    let top_down = |k: usize| v[(n - 1 - k / n) * n + k % n];
    let widened: Vec<u8> = (0..n * n)
        .flat_map(|k| (u16::from((top_down(k) * 255.0).round() as u8) * 257).to_be_bytes())
        .collect();
    let path = grey_png("eight-as-sixteen", png::BitDepth::Sixteen, widened);
    let found = verdict(&path);
    assert!(
        found.starts_with("as good as 8-bit storage allows"),
        "{found}"
    );
    let nibbles: Vec<u8> = (0..n * n / 2)
        .map(|k| {
            let level = |k: usize| (top_down(k) * 15.0).round() as u8;
            level(2 * k) << 4 | level(2 * k + 1)
        })
        .collect();
    let path = grey_png("four", png::BitDepth::Four, nibbles);
    let found = verdict(&path);
    assert!(
        found.starts_with("as good as 4-bit storage allows"),
        "{found}"
    );
}

/// Item 8: Blender's whole `shader.tables` took 157 s with a bar per table ("eta 14s" with two
/// minutes left) and no warning. Now the audit says its estimate for the whole file before it
/// starts (the measured time: 2 min 24 s on 2 cores, docs/engines.md).
#[test]
fn a_long_audit_says_how_long_for_the_whole_file_first() {
    let file =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/engines/cycles/shader.tables");
    let line = command::first_stderr_line(
        &["verify", "--preset", "cycles", file.to_str().unwrap()],
        &[("RAYON_NUM_THREADS", "2")],
    );
    // Within a factor of three of the measured 52 s (numerics version 13, 2026-12-05): "estimated
    // 89 s on 2 threads".
    let estimate = line
        .split("estimated ")
        .nth(1)
        .and_then(|rest| rest.split(" on ").next())
        .unwrap_or_else(|| panic!("no estimate: {line}"));
    let seconds: f64 = match estimate.split_once(' ') {
        Some((n, "s")) => n.parse().ok(),
        Some((n, "min")) => n.parse::<f64>().ok().map(|m| 60.0 * m),
        _ => None,
    }
    .unwrap_or_else(|| panic!("no estimate in seconds or minutes: {line}"));
    assert!((17.0..=156.0).contains(&seconds), "{line}");
}

/// Item 6: a wgpu user uploading the default `.ktx2` (RG32Float) with a linear sampler gets a
/// validation error unless the device has `float32-filterable`. The generated WGSL says so and
/// points at `--precision f16`, whose texture is RG16Float (checked in the file's own header).
#[test]
fn the_wgsl_says_which_texture_webgpu_filters() {
    let dir = tempfile::tempdir().unwrap();
    let o = dir.path().to_str().unwrap();
    ok(&[
        "bake",
        "--quantity",
        "e",
        "--size",
        "4",
        "--format",
        "wgsl,ktx2",
        "--precision",
        "f16",
        "-q",
        "--out",
        o,
    ]);
    let wgsl = std::fs::read_to_string(dir.path().join("ggx-height-correlated-E.wgsl")).unwrap();
    assert!(wgsl.contains("float32-filterable"), "{wgsl}");
    assert!(wgsl.contains("--precision f16"), "{wgsl}");
    // KTX2's vkFormat (bytes 12..16 of the header): 83 is VK_FORMAT_R16G16_SFLOAT.
    let ktx2 = std::fs::read(dir.path().join("ggx-height-correlated-E.ktx2")).unwrap();
    let format = u32::from_le_bytes(ktx2[12..16].try_into().unwrap());
    assert_eq!(format, 83);
}

/// A flag that a mode sets for itself (a scene's model, an audit's grid under `kiln
/// compensation --bake`) is refused by the flags given, not by clap's list of the whole group.
#[test]
fn a_conflict_names_the_flags_given() {
    let said = crate::command::refused(
        &["bake", "--scene", "scene.toml", "--ndf", "ggx", "--size=8"],
        &["'--scene <SCENE>' cannot be used with '--ndf <NDF>', '--size <SIZE>'"],
    );
    assert!(!said.contains("--masking"), "{said}");
    let said = crate::command::refused(
        &["compensation", "--bake", "out", "--f0", "0.5"],
        &["'--bake <DIR>' cannot be used with '--f0 <F0>'"],
    );
    assert!(!said.contains("--roughness"), "{said}");
    crate::command::refused(
        &["bake", "--max-error", "1e-3", "--samples", "64"],
        &["cannot be used with '--samples <SAMPLES>'"],
    );
}

/// `kiln bake --json` says what it wrote: every file it lists is in the folder and every file in
/// the folder is listed, each table's id names its files, and its stated node error is the one
/// its JSON sidecar records.
#[test]
fn bake_json_lists_what_it_wrote() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("t");
    let output = kiln(&[
        "bake",
        "--size",
        "8",
        "--quantity",
        "e,e-avg",
        "--texels",
        "nodes",
        "--out",
        out.to_str().unwrap(),
        "--json",
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    let report: Value = serde_json::from_slice(&output.stdout).unwrap();
    let listed: Vec<String> = report["files"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f.as_str().unwrap().to_string())
        .collect();
    let mut on_disk: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().path().display().to_string())
        .collect();
    on_disk.sort();
    let mut sorted = listed.clone();
    sorted.sort();
    assert_eq!(sorted, on_disk);
    let tables = report["tables"].as_array().unwrap();
    assert_eq!(tables.len(), 2);
    for table in tables {
        let id = table["id"].as_str().unwrap();
        let sidecar: Value =
            serde_json::from_slice(&std::fs::read(out.join(format!("{id}.json"))).unwrap())
                .unwrap();
        let recorded = &sidecar["node_max_error"];
        assert!(recorded.is_number(), "{id}: {sidecar}");
        assert_eq!(&table["node_errors"]["max"], recorded, "{id}");
    }
}
