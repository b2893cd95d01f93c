//! The `kiln` command: errors for bad input, the eval JSON interface, outputs that round-trip,
//! and byte-identical results for any thread count.

#![cfg(feature = "cli")]

use crate::f16_oracle;

use kiln::format::{binary, exr, json::Sidecar};
use std::path::Path;
use std::process::{Command, Output};

use crate::command;
use command::kiln;

fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

fn files_in(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .map(|entries| {
            entries
                .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
                .collect()
        })
        .unwrap_or_default();
    names.sort();
    names
}

/// A small, fast bake into `dir`.
fn small_bake(dir: &Path, extra: &[&str]) -> Output {
    let out = dir.to_str().unwrap();
    let mut args = vec![
        "bake",
        "--size",
        "4",
        "--samples",
        "1024",
        "--avg-samples",
        "4096",
        "--out",
        out,
    ];
    args.extend_from_slice(extra);
    kiln(&args)
}

#[test]
fn bad_input_gets_one_line_exit_status_2_and_no_files() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let out = out.to_str().unwrap();
    let cases: &[(&[&str], &str)] = &[
        (&["bake", "--size", "0", "--out", out], "size"),
        (&["bake", "--size", "-3", "--out", out], "size"),
        (&["bake", "--size", "nan", "--out", out], "size"),
        (&["bake", "--samples", "1000", "--out", out], "power of two"),
        (&["bake", "--samples", "0", "--out", out], "power of two"),
        (&["bake", "--ndf", "phong", "--out", out], "phong"),
        (&["bake", "--masking", "v-cavity", "--out", out], "v-cavity"),
        (&["bake", "--format", "tiff", "--out", out], "tiff"),
        (&["bake", "--scrambles", "3", "--out", out], "scrambles"),
        (&["bake", "--max-error", "1e-12", "--out", out], "max-error"),
        (&["bake", "--max-error", "-1", "--out", out], "positive"),
        (
            &[
                "bake",
                "--max-error",
                "1e-4",
                "--samples",
                "1024",
                "--out",
                out,
            ],
            "--samples",
        ),
        (&["eval", "--alpha", "0.5", "--mu", "1.5"], "[0, 1]"),
        (&["eval", "--alpha", "0.5", "--mu", "-0.1"], "[0, 1]"),
        (&["eval", "--alpha", "0.5", "--mu", "nan"], "mu"),
        (&["eval", "--alpha", "-1", "--mu", "0.5"], "roughness"),
        (
            &["eval", "--alpha", "0.5", "--mu", "0.5", "--samples", "-4"],
            "power of two",
        ),
        (&["eval", "--roughness", "inf", "--mu", "0.5"], "finite"),
        (&["eval", "--alpha", "0.5"], "--mu"),
        (&["eval", "--mu", "0.5"], "--alpha"),
        (
            &[
                "eval",
                "--alpha",
                "0.5",
                "--roughness",
                "0.5",
                "--mu",
                "0.5",
            ],
            "--roughness",
        ),
    ];
    for (args, mentions) in cases {
        let output = kiln(args);
        let message = stderr(&output);
        assert_eq!(output.status.code(), Some(2), "{args:?}: {message}");
        // One line saying what is wrong; then at most clap's usage line and tips.
        let mut lines = message.trim_end().lines();
        assert!(
            lines.next().is_some_and(|line| line.starts_with("kiln: ")),
            "{args:?}: {message}"
        );
        assert!(
            lines.all(|line| line.starts_with("  Usage: ") || line.starts_with("  tip: ")),
            "{args:?}: more than one line of message: {message}"
        );
        assert!(
            message.contains(mentions),
            "{args:?}: '{message}' does not mention {mentions}"
        );
        assert!(output.stdout.is_empty(), "{args:?}");
    }
    assert!(
        !Path::new(out).exists(),
        "a failed run created the output directory"
    );
}

#[test]
fn an_unwritable_output_directory_fails_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    // A regular file where the directory should be.
    let blocker = dir.path().join("not-a-directory");
    std::fs::write(&blocker, b"x").unwrap();
    let output = small_bake(&blocker, &[]);
    assert_eq!(output.status.code(), Some(2), "{}", stderr(&output));
    assert!(stderr(&output).contains("not-a-directory"));
    assert_eq!(std::fs::read(&blocker).unwrap(), b"x");
    assert_eq!(files_in(dir.path()), ["not-a-directory"]);
}

#[test]
fn eval_json_is_one_object_with_the_agreed_fields() {
    let output = kiln(&[
        "eval",
        "--ndf",
        "ggx",
        "--alpha",
        "1",
        "--mu",
        "1",
        "--samples",
        "65536",
        "--json",
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    let text = String::from_utf8(output.stdout).unwrap();
    assert_eq!(text.trim_end().lines().count(), 1);
    let object: serde_json::Value = serde_json::from_str(&text).unwrap();
    for field in ["value", "std_error", "method", "samples", "seconds"] {
        assert!(object.get(field).is_some(), "missing {field} in {text}");
    }
    assert_eq!(object["samples"], 65536);
    let value = object["value"].as_f64().unwrap();
    let std_error = object["std_error"].as_f64().unwrap();
    let exact = 1.0 - std::f64::consts::LN_2;
    assert!(
        (value - exact).abs() <= 5.0 * std_error,
        "{value} ± {std_error} vs {exact}"
    );

    // --roughness is perceptual: r = 0.5 is alpha = 0.25.
    let by_r = kiln(&[
        "eval",
        "--roughness",
        "0.5",
        "--mu",
        "0.3",
        "--json",
        "--samples",
        "1024",
    ]);
    let by_alpha = kiln(&[
        "eval",
        "--alpha",
        "0.25",
        "--mu",
        "0.3",
        "--json",
        "--samples",
        "1024",
    ]);
    let value = |o: &Output| {
        serde_json::from_slice::<serde_json::Value>(&o.stdout).unwrap()["value"].clone()
    };
    assert_eq!(value(&by_r), value(&by_alpha));

    let avg = kiln(&[
        "eval",
        "--alpha",
        "1",
        "--quantity",
        "e-avg",
        "--json",
        "--samples",
        "65536",
    ]);
    let object: serde_json::Value = serde_json::from_slice(&avg.stdout).unwrap();
    assert_eq!(object["quantity"], "E_avg");
    // Within five of its own standard errors of the published value (known to 5e-9), not a
    // fixed 1e-4 that is a hundred of them.
    let (value, std_error) = (
        object["value"].as_f64().unwrap(),
        object["std_error"].as_f64().unwrap(),
    );
    assert!(std_error > 0.0 && std_error < 1e-4, "{object}");
    assert!(
        (value - 0.409_137_09).abs() <= 5.0 * std_error + 5e-9,
        "{value} ± {std_error:e}"
    );
}

/// `kiln eval --quantity f-avg`: the check values through the JSON interface, every
/// Fresnel model, and bad Fresnel flags named with status 2.
#[test]
fn eval_f_avg_json_and_fresnel_flags() {
    let json = |args: &[&str]| -> serde_json::Value {
        let mut all = vec!["eval", "--quantity", "f-avg", "--json"];
        all.extend_from_slice(args);
        let output = kiln(&all);
        assert!(output.status.success(), "{args:?}: {}", stderr(&output));
        let text = String::from_utf8(output.stdout).unwrap();
        assert_eq!(text.trim_end().lines().count(), 1);
        serde_json::from_str(&text).unwrap()
    };
    let glass = json(&["--fresnel", "dielectric", "--ior", "1.5"]);
    for field in ["value", "std_error", "method", "samples", "seconds"] {
        assert!(glass.get(field).is_some(), "missing {field} in {glass}");
    }
    assert_eq!(glass["quantity"], "F_avg");
    assert!((glass["value"].as_f64().unwrap() - 0.091_777_959_3).abs() < 1e-9);
    // --ior alone means dielectric; light leaving glass.
    let inside = json(&["--ior", "0.6666666666666666"]);
    assert!((inside["value"].as_f64().unwrap() - 0.596_345_759_7).abs() < 1e-9);
    // --f0 alone means Schlick: (20 F0 + 1) / 21, per channel.
    let schlick = json(&["--f0", "0.04,0.5,1"]);
    assert_eq!(schlick["method"], "closed-form");
    let rgb: Vec<f64> = schlick["value"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    for (got, f0) in rgb.iter().zip([0.04, 0.5, 1.0]) {
        assert!((got - (20.0 * f0 + 1.0) / 21.0).abs() < 1e-15);
    }
    let metal = json(&[
        "--fresnel",
        "conductor",
        "--eta",
        "0.18,0.42,1.37",
        "--k",
        "3.42,2.35,1.77",
    ]);
    assert_eq!(metal["value_rgb"].as_array().unwrap().len(), 3);
    assert_eq!(json(&["--fresnel", "none"])["value"], 1.0);

    // E_F at one point: QMC within its standard error of the reference; RGB gives three values.
    let e_f = |method: &str, f0: &str| -> serde_json::Value {
        let output = kiln(&[
            "eval", "--alpha", "0.25", "--mu", "0.5", "--f0", f0, "--method", method, "--json",
        ]);
        assert!(output.status.success(), "{}", stderr(&output));
        serde_json::from_slice(&output.stdout).unwrap()
    };
    let (qmc, reference) = (e_f("qmc", "0.04"), e_f("reference", "0.04"));
    assert_eq!(qmc["quantity"], "E_F");
    let difference = (qmc["value"].as_f64().unwrap() - reference["value"].as_f64().unwrap()).abs();
    assert!(
        difference <= 5.0 * qmc["std_error"].as_f64().unwrap() + 1e-10,
        "{qmc} {reference}"
    );
    let rgb = e_f("reference", "0.04,0.5,0.9");
    let values = rgb["value"].as_array().unwrap();
    assert_eq!(values[0], reference["value"]);
    assert!(values[0].as_f64() < values[1].as_f64() && values[1].as_f64() < values[2].as_f64());

    for (args, needle) in [
        (&["--fresnel", "dielectric"][..], "needs --ior"),
        (&["--fresnel", "conductor", "--eta", "1"][..], "needs --k"),
        (
            &["--ior", "-1"][..],
            "ior must be between 0.01 and 100 (got -1)",
        ),
        (&["--f0", "1.2"][..], "f0 must be in [0, 1]"),
        (&["--f0", "0.1,0.2"][..], "three comma-separated"),
        (
            &["--fresnel", "dielectric", "--ior", "1.5", "--k", "2"][..],
            "--k does not apply",
        ),
        (&["--ior", "1.5", "--mu", "0.5"][..], "drop --mu"),
    ] {
        let mut all = vec!["eval", "--quantity", "f-avg"];
        all.extend_from_slice(args);
        let output = kiln(&all);
        assert_eq!(output.status.code(), Some(2), "{args:?}");
        assert!(
            stderr(&output).contains(needle),
            "{args:?}: {}",
            stderr(&output)
        );
        assert!(output.stdout.is_empty());
    }
}

/// `kiln plan`: one model, both NDFs, duplicates merged, no materials; a bad scene file
/// gets its line and column, status 2.
#[test]
fn plan_lists_each_needed_table_once() {
    let dir = tempfile::tempdir().unwrap();
    let plan = |name: &str, text: &str| -> (Output, serde_json::Value) {
        let path = dir.path().join(name);
        std::fs::write(&path, text).unwrap();
        let output = kiln(&["plan", path.to_str().unwrap(), "--json"]);
        let json = serde_json::from_slice(&output.stdout).unwrap_or(serde_json::Value::Null);
        (output, json)
    };
    let material = |name: &str, ndf: &str, extra: &str| {
        format!("[[material]]\nname = \"{name}\"\nndf = \"{ndf}\"\nroughness = 0.4\n{extra}\n")
    };
    let ids = |json: &serde_json::Value| -> Vec<String> {
        json["tables"]
            .as_array()
            .unwrap()
            .iter()
            .map(|t| format!("{}-{}-{}", t["ndf"], t["masking"], t["quantity"]).replace('"', ""))
            .collect()
    };
    let (_, one) = plan("one.toml", &material("steel", "ggx", ""));
    assert_eq!(
        ids(&one),
        [
            "ggx-height-correlated-E",
            "ggx-height-correlated-E_avg",
            "ggx-height-correlated-f_ms_norm"
        ]
    );
    assert_eq!(one["materials"][0]["name"], "steel");
    let (_, both) = plan(
        "both.toml",
        &(material("steel", "ggx", "") + &material("wood", "beckmann", "masking = \"separable\"")),
    );
    assert_eq!(
        ids(&both),
        [
            "ggx-height-correlated-E",
            "ggx-height-correlated-E_avg",
            "ggx-height-correlated-f_ms_norm",
            "beckmann-separable-E",
            "beckmann-separable-E_avg",
            "beckmann-separable-f_ms_norm"
        ]
    );
    let (_, twins) = plan(
        "twins.toml",
        &(material("a", "ggx", "fresnel = { schlick = { f0 = 0.04 } }")
            + &material("b", "ggx", "fresnel = { dielectric = { ior = 1.5 } }")),
    );
    assert_eq!(twins["tables"].as_array().unwrap().len(), 3);
    assert_eq!(
        twins["tables"][0]["materials"],
        serde_json::json!(["a", "b"])
    );
    let f_avg = twins["materials"][1]["f_avg"][0].as_f64().unwrap();
    assert!((f_avg - 0.091_777_959_3).abs() < 1e-9);
    let (_, empty) = plan("empty.toml", "");
    assert!(empty["tables"].as_array().unwrap().is_empty());
    assert!(empty["materials"].as_array().unwrap().is_empty());

    let (bad, _) = plan("bad.toml", &material("a", "ggx", "colour = 1"));
    assert_eq!(bad.status.code(), Some(2));
    let message = stderr(&bad);
    assert!(
        message.contains("line 5") && message.contains("colour"),
        "{message}"
    );
    let (bad, _) = plan(
        "rough.toml",
        &material("a", "ggx", "").replace("0.4", "-0.1"),
    );
    assert_eq!(bad.status.code(), Some(2));
    assert!(stderr(&bad).contains("roughness -0.1"), "{}", stderr(&bad));
}

/// A scene's `output.dir` is relative to the scene file, whatever the working directory, and
/// the bake writes each material's values: `F_avg` (Schlick's closed form `(20 F0 + F90) / 21`),
/// `E_avg` at its roughness (against the reference quadrature, within the table's lookup
/// error) and the colour multiplier `F_avg^2 E_avg / (1 - F_avg (1 - E_avg))`.
#[test]
fn scene_output_is_beside_the_scene_with_its_materials_values() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("scene.toml");
    std::fs::write(
        &scene,
        "[output]\ndir = \"baked\"\nformats = [\"json\"]\nmax_error = 1e-5\n\n\
         [[material]]\nname = \"plastic\"\nndf = \"ggx\"\nroughness = 0.5\n\
         fresnel = { schlick = { f0 = 0.04 } }\n",
    )
    .unwrap();
    let elsewhere = tempfile::tempdir().unwrap();
    let output = Command::new(env!("CARGO_BIN_EXE_kiln"))
        .args(["bake", "--scene", scene.to_str().unwrap(), "-q"])
        .current_dir(elsewhere.path())
        .output()
        .unwrap();
    assert!(output.status.success(), "{}", stderr(&output));
    assert!(files_in(elsewhere.path()).is_empty());
    let text = std::fs::read(dir.path().join("baked/materials.json")).unwrap();
    let document: serde_json::Value = serde_json::from_slice(&text).unwrap();
    let plastic = &document["materials"][0];
    assert_eq!(plastic["name"], "plastic");
    assert_eq!(plastic["e_avg_table"], "ggx-height-correlated-E_avg");
    let f_avg = plastic["f_avg"][0].as_f64().unwrap();
    assert!(
        (f_avg - (20.0 * 0.04 + 1.0) / 21.0).abs() < 1e-12,
        "{plastic}"
    );
    let e_avg = plastic["e_avg"].as_f64().unwrap();
    // GGX height-correlated E_avg at alpha = 0.25 (r = 0.5), by the reference quadrature.
    let reference = kiln(&[
        "eval",
        "--quantity",
        "e-avg",
        "--roughness",
        "0.5",
        "--method",
        "reference",
        "--json",
    ]);
    let reference: serde_json::Value = serde_json::from_slice(&reference.stdout).unwrap();
    let truth = reference["value"].as_f64().unwrap();
    assert!((e_avg - truth).abs() < 1e-3, "{e_avg} vs {truth}");
    let colour = plastic["colour_multiplier"][1].as_f64().unwrap();
    let expected = f_avg * f_avg * truth / (1.0 - f_avg * (1.0 - truth));
    assert!((colour - expected).abs() < 1e-4, "{colour} vs {expected}");
}

/// `kiln bake --scene`: says what it baked, then that it reused everything.
#[test]
fn scene_bake_reports_reuse() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("scene.toml");
    std::fs::write(
        &scene,
        "[output]\nformats = [\"json\"]\nmax_error = 1e-4\n\n[[material]]\nname = \"a\"\n\
         ndf = \"ggx\"\nroughness = 0.3\n",
    )
    .unwrap();
    let out = dir.path().join("out");
    let bake = || {
        let output = kiln(&[
            "bake",
            "--scene",
            scene.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(output.status.success(), "{}", stderr(&output));
        String::from_utf8(output.stdout).unwrap()
    };
    let first = bake();
    assert!(first.contains("reused from the cache: none"), "{first}");
    assert!(first.contains("baked: ggx-height-correlated-E, ggx-height-correlated-E_avg"));
    let second = bake();
    assert!(second.contains("baked: none"), "{second}");
    assert_eq!(
        files_in(&out),
        [
            ".kiln-cache",
            "ggx-height-correlated-E.json",
            "ggx-height-correlated-E_avg.json",
            "ggx-height-correlated-f_ms_norm.json",
            "materials.json"
        ]
    );
    // A scene flag with a table flag is a usage error.
    let output = kiln(&["bake", "--scene", scene.to_str().unwrap(), "--size", "8"]);
    assert_eq!(output.status.code(), Some(2));
}

#[test]
fn outputs_agree_with_each_other_and_round_trip() {
    let dir = tempfile::tempdir().unwrap();
    for precision in ["f32", "f16"] {
        let out = dir.path().join(precision);
        let output = small_bake(
            &out,
            &[
                "--precision",
                precision,
                "--ndf",
                "ggx,beckmann",
                "--masking",
                "separable",
            ],
        );
        assert!(output.status.success(), "{}", stderr(&output));
        for id in [
            "ggx-separable-E",
            "ggx-separable-E_avg",
            "beckmann-separable-E",
            "beckmann-separable-E_avg",
        ] {
            let read = |ext: &str| std::fs::read(out.join(format!("{id}.{ext}"))).unwrap();
            let sidecar: Sidecar = serde_json::from_slice(&read("json")).unwrap();
            let q = &sidecar.metadata.quantity;
            let reference = &sidecar.data[q.as_str()];
            let one_minus = &sidecar.data[&format!("one_minus_{q}")];
            let std_error = &sidecar.data["std_error"];
            // What a value becomes in storage: f32, or f16 rounded to nearest even (the tests'
            // own rounding, tests/common/f16_oracle.rs), with kiln's documented rule that a
            // non-zero value is never flushed to zero but kept as the smallest subnormal.
            let stored = |v: f64| match precision {
                "f32" => f64::from(v as f32),
                _ => f16_oracle::oracle(v),
            };
            // f16: nothing non-zero is stored as zero, and the metadata counts what was clamped
            // (recounted here independently: values that plain rounding would flush to zero).
            if precision == "f16" {
                let storage = sidecar.metadata.f16_storage.as_ref().expect("f16 counts");
                for (name, values) in [
                    (q.clone(), reference),
                    (format!("one_minus_{q}"), one_minus),
                ] {
                    let flushed = values
                        .iter()
                        .filter(|&&v| v != 0.0 && f16_oracle::round_nearest_even(v) == 0.0)
                        .count();
                    assert_eq!(storage[&name].clamped, flushed, "{id} {name}");
                    assert!(
                        values.iter().all(|&v| v == 0.0 || stored(v) != 0.0),
                        "{id} {name}"
                    );
                }
            } else {
                assert!(sidecar.metadata.f16_storage.is_none());
            }

            let image = exr::decode(&read("exr")).unwrap();
            let channel = |name: &str| &image.channels.iter().find(|(n, _)| n == name).unwrap().1;
            assert_eq!(image.width * image.height, reference.len());
            assert!(
                reference
                    .iter()
                    .map(|&v| stored(v))
                    .eq(channel(q).iter().copied()),
                "{id} exr {q}"
            );
            assert!(
                one_minus
                    .iter()
                    .map(|&v| stored(v))
                    .eq(channel(&format!("one_minus_{q}")).iter().copied())
            );
            // std_error stays f32 whatever the precision.
            assert!(
                std_error
                    .iter()
                    .map(|&v| f64::from(v as f32))
                    .eq(channel("std_error").iter().copied())
            );
            let header: kiln::format::metadata::Metadata =
                serde_json::from_str(image.metadata.as_deref().unwrap()).unwrap();
            assert_eq!(header, sidecar.metadata);

            let bin = binary::decode(&read("bin")).unwrap();
            assert_eq!(bin.shape, sidecar.metadata.shape);
            assert_eq!(bin.channels[0].0, *q);
            assert!(
                reference
                    .iter()
                    .map(|&v| stored(v))
                    .eq(bin.channels[0].1.iter().copied()),
                "{id} bin"
            );
            assert!(
                std_error
                    .iter()
                    .map(|&v| f64::from(v as f32))
                    .eq(bin.channels[2].1.iter().copied())
            );

            assert_eq!(
                sidecar.files.get("exr").map(String::as_str),
                Some(format!("{id}.exr").as_str())
            );
            assert_eq!(sidecar.metadata.precision, precision);
            assert!(sidecar.metadata.command.contains("--masking separable"));
        }
    }
}

#[test]
fn results_are_byte_identical_for_any_thread_count_and_run() {
    let dir = tempfile::tempdir().unwrap();
    let run = |name: &str, threads: Option<&str>| {
        let out = dir.path().join(name);
        let mut command = Command::new(env!("CARGO_BIN_EXE_kiln"));
        command.args([
            "bake",
            "--size",
            "6",
            "--samples",
            "2048",
            "--avg-samples",
            "8192",
            "--ndf",
            "ggx,beckmann",
            "-q",
        ]);
        command.arg("--out").arg(&out);
        match threads {
            Some(n) => command.env("RAYON_NUM_THREADS", n),
            None => command.env_remove("RAYON_NUM_THREADS"),
        };
        let output = command.output().unwrap();
        assert!(output.status.success(), "{}", stderr(&output));
        out
    };
    let one = run("one", Some("1"));
    let three = run("three", Some("3"));
    let default = run("default", None);
    let again = run("again", None);
    let names = files_in(&one);
    assert_eq!(names.len(), 26);
    for other in [&three, &default, &again] {
        assert_eq!(files_in(other), names);
        for name in &names {
            assert!(
                std::fs::read(one.join(name)).unwrap() == std::fs::read(other.join(name)).unwrap(),
                "{name} differs"
            );
        }
    }
}

#[test]
fn generated_rust_compiles_for_every_layout() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("tables");
    let out_arg = out.to_str().unwrap();
    let output = kiln(&[
        "bake",
        "--format",
        "rs",
        "--roughness-axis",
        "alpha",
        "--mu-axis",
        "sqrt",
        "--grid",
        "nodes",
        "--size",
        "5",
        "--samples",
        "256",
        "--avg-samples",
        "256",
        "--out",
        out_arg,
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    // One crate that includes both files, so that their constant names must not clash either.
    let lib = dir.path().join("lib.rs");
    std::fs::write(
        &lib,
        "#![deny(warnings)]\ninclude!(\"tables/ggx-height-correlated-E-alpha-mu-sqrt.rs\");\ninclude!(\"tables/ggx-height-correlated-E_avg-alpha-rows-linear.rs\");\n\
         pub fn corner() -> f32 { GGX_HEIGHT_CORRELATED_E_ALPHA_MU_SQRT[4][0] + GGX_HEIGHT_CORRELATED_E_AVG_ALPHA_ROWS_LINEAR[0] + GGX_HEIGHT_CORRELATED_E_ALPHA_MU_SQRT_MU[4] }\n",
    )
    .unwrap();
    let rustc = std::env::var("RUSTC").unwrap_or_else(|_| "rustc".into());
    let compiled = Command::new(rustc)
        .args([
            "--edition",
            "2024",
            "--crate-type",
            "lib",
            "--crate-name",
            "tables",
            "-o",
        ])
        .arg(dir.path().join("libtables.rlib"))
        .arg(&lib)
        .output()
        .unwrap();
    assert!(
        compiled.status.success(),
        "{}",
        String::from_utf8_lossy(&compiled.stderr)
    );
}

#[test]
fn help_explains_the_conventions() {
    // Once, in `kiln --help`; each subcommand's help points there.
    let output = kiln(&["--help"]);
    let text = String::from_utf8(output.stdout).unwrap();
    for command in ["bake", "verify", "eval"] {
        let help = String::from_utf8(kiln(&[command, "--help"]).stdout).unwrap();
        assert!(help.contains("kiln --help"), "{command} --help");
        assert!(
            !help.contains("Conventions:\n"),
            "{command} --help repeats them"
        );
    }
    for phrase in [
        "alpha = r^2",
        "(i + 0.5) / N",
        "i / (N - 1)",
        "cos(theta)",
        "one_minus_E",
    ] {
        assert!(
            text.contains(phrase),
            "kiln --help does not explain {phrase}"
        );
    }
}

#[test]
fn reference_method_bakes_tables_within_1e_10_that_qmc_agrees_with() {
    let dir = tempfile::tempdir().unwrap();
    let reference = dir.path().join("reference");
    let output = kiln(&[
        "bake",
        "--method",
        "reference",
        "--size",
        "4",
        "--format",
        "json",
        "-q",
        "--out",
        reference.to_str().unwrap(),
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    let qmc = dir.path().join("qmc");
    let output = kiln(&[
        "bake",
        "--size",
        "4",
        "--samples",
        "65536",
        "--format",
        "json",
        "-q",
        "--no-reference-check",
        "--out",
        qmc.to_str().unwrap(),
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    for id in ["ggx-height-correlated-E", "ggx-height-correlated-E_avg"] {
        let read = |dir: &Path| -> Sidecar {
            serde_json::from_slice(&std::fs::read(dir.join(format!("{id}.json"))).unwrap()).unwrap()
        };
        let (r, q) = (read(&reference), read(&qmc));
        assert!(r.metadata.estimator.contains("quadrature"));
        assert!(r.metadata.command.contains("--method reference"));
        assert!(
            r.metadata.max_std_error <= 1e-10,
            "{}",
            r.metadata.max_std_error
        );
        let symbol = &r.metadata.quantity;
        // Row 0 (r = 1/8, alpha = 0.016) is left out: there QMC misses the rare events that carry
        // the loss and its standard error understates its error (README, "Known limits").
        let per_row = if symbol == "E" { 4 } else { 1 };
        for k in per_row..r.data[symbol.as_str()].len() {
            let (exact, estimate) = (r.data[symbol.as_str()][k], q.data[symbol.as_str()][k]);
            let se = q.data["std_error"][k];
            // 1e-12 covers texels where QMC's estimate is exact to rounding (a std error of 0).
            assert!(
                (exact - estimate).abs() <= 5.0 * se + 1e-12,
                "{id}[{k}]: {exact} vs {estimate} ± {se}"
            );
        }
    }
}

/// `kiln study --scaling --quick`: its four files, the CSV rows the JSON's runs, one fit per
/// case in the plot's legend, a PNG. Its timings are not asserted.
#[test]
fn study_scaling_writes_consistent_files() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("scaling");
    let output = kiln(&[
        "study",
        "--scaling",
        "--quick",
        "-q",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    assert_eq!(
        files_in(&out),
        ["scaling.csv", "scaling.json", "scaling.png", "scaling.svg"]
    );
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("scaling.json")).unwrap()).unwrap();
    let runs = json["runs"].as_array().unwrap();
    let csv = std::fs::read_to_string(out.join("scaling.csv")).unwrap();
    assert_eq!(csv.lines().count(), runs.len() + 1);
    for (line, run) in csv.lines().skip(1).zip(runs) {
        assert!(line.starts_with(&format!(
            "{},{},{},",
            run["case"].as_str().unwrap(),
            run["size"],
            run["texels"]
        )));
    }
    let svg = std::fs::read_to_string(out.join("scaling.svg")).unwrap();
    let fits = json["fits"].as_array().unwrap();
    assert_eq!(fits.len(), 4);
    for fit in fits {
        let case = fit["case"].as_str().unwrap();
        assert!(svg.contains(&format!("{case} (time ~ texels^")), "{case}");
    }
    let png = std::fs::read(out.join("scaling.png")).unwrap();
    assert!(png.starts_with(b"\x89PNG"));
    let text = String::from_utf8(output.stdout).unwrap();
    assert!(text.contains("time ~ texels^"), "{text}");
}

/// `kiln study --quick`: every file, consistent with each other (CSV rows are the JSON's runs),
/// plots that are an SVG with the legend's entries and a PNG of the stated size, and a summary
/// line per method. Its timings are not asserted.
#[test]
fn study_quick_writes_consistent_files_and_a_summary() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("study");
    let output = kiln(&["study", "--quick", "-q", "--out", out.to_str().unwrap()]);
    assert!(output.status.success(), "{}", stderr(&output));
    assert_eq!(
        files_in(&out),
        [
            "lookup.csv",
            "lookup.png",
            "lookup.svg",
            "study.csv",
            "study.json",
            "study.png",
            "study.svg"
        ]
    );
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("study.json")).unwrap()).unwrap();
    let runs = json["runs"].as_array().unwrap();
    let csv = std::fs::read_to_string(out.join("study.csv")).unwrap();
    assert_eq!(csv.lines().count(), runs.len() + 1);
    for (line, run) in csv.lines().skip(1).zip(runs) {
        assert!(line.starts_with(&format!(
            "{},{},",
            run["method"].as_str().unwrap(),
            run["samples"]
        )));
    }
    let methods: std::collections::BTreeSet<&str> =
        runs.iter().map(|r| r["method"].as_str().unwrap()).collect();
    assert_eq!(methods.len(), 6, "every method, even in --quick");
    assert!(json["cores"].as_u64().unwrap() >= 1 && json["kiln_version"].is_string());
    let svg = std::fs::read_to_string(out.join("study.svg")).unwrap();
    assert!(
        svg.starts_with("<svg")
            && svg.contains("Pareto front")
            && svg.contains("VNDF sampling, Sobol")
    );
    let png = std::fs::read(out.join("study.png")).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    assert_eq!(u32::from_be_bytes(png[16..20].try_into().unwrap()), 1100);
    let stdout = String::from_utf8_lossy(&output.stdout);
    for method in &methods {
        assert!(stdout.lines().any(|l| l.starts_with(method)), "{stdout}");
    }
    assert!(
        stdout.contains("to 1e-6") || stdout.contains("did not reach 1e-6"),
        "{stdout}"
    );
}

/// `kiln bake --f0 0.04` writes an `E_F` table for that model; `kiln verify --quantity e-f
/// --f0 0.04` audits the same numbers as an external table, and refuses without the model.
#[test]
fn fresnel_flags_on_bake_and_verify() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    let baked = kiln(&[
        "bake",
        "--f0",
        "0.04",
        "--mu-axis",
        "linear",
        "--size",
        "4",
        "--max-error",
        "1e-6",
        "--format",
        "json",
        "--out",
        out,
        "-q",
    ]);
    assert!(baked.status.success(), "{}", stderr(&baked));
    let sidecar: Sidecar = serde_json::from_slice(
        &std::fs::read(
            dir.path()
                .join("ggx-height-correlated-E_F-schlick-0.04-1-mu-linear.json"),
        )
        .unwrap(),
    )
    .unwrap();
    assert_eq!(sidecar.metadata.quantity, "E_F");
    assert!(
        sidecar.metadata.fresnel.contains("schlick"),
        "{}",
        sidecar.metadata.fresnel
    );
    let text: Vec<String> = sidecar.data["E_F"]
        .iter()
        .map(|v| format!("{v:e}"))
        .collect();
    let external = dir.path().join("theirs.txt");
    std::fs::write(&external, text.join("\n")).unwrap();
    let layout = [
        "--shape",
        "4x4",
        "--order",
        "r,mu",
        "--grid",
        "nodes",
        "--mu-axis",
        "linear",
        "--quantity",
        "e-f",
        "--density",
        "1",
        "--json",
    ];
    let mut args = vec!["verify", external.to_str().unwrap()];
    args.extend(layout);
    args.extend(["--f0", "0.04"]);
    let audited = kiln(&args);
    assert!(audited.status.success(), "{}", stderr(&audited));
    let report: serde_json::Value = serde_json::from_slice(&audited.stdout).unwrap();
    let node_max = report["node_max_error"].as_f64().unwrap();
    assert!(node_max <= 1e-6, "{report}");
    // The same numbers read as a different model's E_F are far off.
    args.truncate(args.len() - 2);
    args.extend(["--f0", "0.5"]);
    let wrong = kiln(&args);
    let report: serde_json::Value = serde_json::from_slice(&wrong.stdout).unwrap();
    assert!(report["node_max_error"].as_f64().unwrap() > 0.1, "{report}");
    // Without the model: one line, status 2.
    args.truncate(args.len() - 2);
    let refused = kiln(&args);
    assert_eq!(refused.status.code(), Some(2));
    assert!(
        stderr(&refused).contains("needs the Fresnel model"),
        "{}",
        stderr(&refused)
    );
}

/// `kiln bake --preset three` writes the engine's file and kiln's sidecars; `kiln verify
/// --preset three` audits that file as the engine would read it (one JSON object per table).
#[test]
fn presets_bake_and_verify() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    let baked = kiln(&["bake", "--preset", "three", "--out", out, "-q"]);
    assert!(baked.status.success(), "{}", stderr(&baked));
    assert_eq!(
        files_in(dir.path()),
        [
            "DFGLUTData.js",
            "three-ggx-height-correlated-E_bias.json",
            "three-ggx-height-correlated-E_scale.json"
        ]
    );
    let file = dir.path().join("DFGLUTData.js");
    let audited = kiln(&[
        "verify",
        "--preset",
        "three",
        file.to_str().unwrap(),
        "--json",
        "--density",
        "1",
    ]);
    assert!(audited.status.success(), "{}", stderr(&audited));
    let reports: Vec<serde_json::Value> = String::from_utf8(audited.stdout)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(reports.len(), 2);
    for report in &reports {
        // Half floats: at most half a spacing (2^-12 below 1) off the reference.
        let node_max = report["node_max_error"].as_f64().unwrap();
        assert!(node_max <= 2f64.powi(-12) + 1e-7, "{report}");
    }
    assert_eq!(reports[0]["quantity"], "E_scale");
    // A preset takes no table flags.
    let refused = kiln(&["bake", "--preset", "bevy", "--size", "8", "--out", out]);
    assert_eq!(refused.status.code(), Some(2));
}

/// The sidecar of Enterprise PBR's `f_ms_norm` describes the file beside it: both are derived
/// from the half-float `E` the engine file holds (the sidecar held the normalisation of the f64
/// `E`, off by the f16 rounding of `E`, up to 2e-4 relative).
#[test]
fn a_preset_sidecar_holds_the_values_of_the_engine_file_beside_it() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    let baked = kiln(&["bake", "--preset", "enterprise-pbr", "--out", out, "-q"]);
    assert!(baked.status.success(), "{}", stderr(&baked));
    let preset = kiln::preset::Preset::EnterprisePbr;
    let name = kiln::preset::ENTERPRISE_NORMALISATION_FILE;
    let bytes = std::fs::read(dir.path().join(name)).unwrap();
    let engine = preset.read_tables(&bytes, name).unwrap().remove(0);
    let sidecar = files_in(dir.path())
        .into_iter()
        .find(|f| f.contains("f_ms_norm") && f.ends_with(".json"))
        .expect("a sidecar of f_ms_norm");
    let described = kiln::verify::input::read_kiln(&dir.path().join(sidecar))
        .unwrap()
        .unwrap();
    assert_eq!(described.value.len(), engine.value.len());
    for (k, (s, e)) in described.value.iter().zip(&engine.value).enumerate() {
        // The file stores f32.
        assert_eq!(
            f64::from(*s as f32),
            *e,
            "entry {k}: sidecar {s:e}, file {e:e}"
        );
    }
}

/// `kiln eval --quantity e-dielectric --ior ETA`: the energy albedo in the usual JSON object,
/// with the reference's reflected and transmitted parts and the radiance albedo beside it.
#[test]
fn eval_dielectric_reports_both_conventions() {
    let output = kiln(&[
        "eval",
        "--quantity",
        "e-dielectric",
        "--ior",
        "1.5",
        "--alpha",
        "0.5",
        "--mu",
        "0.5",
        "--method",
        "reference",
        "--json",
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    let json: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    let get = |k: &str| json[k].as_f64().unwrap_or_else(|| panic!("{k} in {json}"));
    let (r, t) = (get("reflection"), get("transmission"));
    assert!((get("value") - (r + t)).abs() < 1e-15);
    assert!((get("radiance_albedo") - (r + t / 2.25)).abs() < 1e-15);
    assert!((get("value") + get("one_minus_value") - 1.0).abs() < 1e-10);
    assert_eq!(json["quantity"], "E_dielectric");
    // QMC agrees within its standard error (4 of them).
    let output = kiln(&[
        "eval",
        "--quantity",
        "e-dielectric",
        "--ior",
        "1.5",
        "--alpha",
        "0.5",
        "--mu",
        "0.5",
        "--json",
    ]);
    let qmc: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    let gap = (qmc["value"].as_f64().unwrap() - get("value")).abs();
    assert!(gap < 4.0 * qmc["std_error"].as_f64().unwrap(), "{qmc}");
    // Without the index: one line, status 2.
    let refused = kiln(&[
        "eval",
        "--quantity",
        "e-dielectric",
        "--alpha",
        "0.5",
        "--mu",
        "0.5",
    ]);
    assert_eq!(refused.status.code(), Some(2));
    assert!(stderr(&refused).contains("--ior"), "{}", stderr(&refused));
}

/// The dielectric tables, the GPU containers (zstd included) and the generated code are
/// byte-identical for any thread count too.
#[test]
fn dielectric_and_container_outputs_are_byte_identical_for_any_thread_count() {
    let dir = tempfile::tempdir().unwrap();
    let run = |name: &str, threads: &str| {
        let out = dir.path().join(name);
        for args in [
            vec![
                "bake",
                "--quantity",
                "e-dielectric,e-avg-dielectric-inside,f-avg",
                "--size",
                "3",
                "--ior-size",
                "2",
                "--max-error",
                "1e-4",
                "--format",
                "exr,bin,json,ktx2,dds,h,wgsl,glsl,hlsl",
                "--precision",
                "f16",
                "-q",
            ],
            vec!["bake", "--preset", "bevy", "--max-error", "1e-3", "-q"],
        ] {
            let output = Command::new(env!("CARGO_BIN_EXE_kiln"))
                .args(&args)
                .arg("--out")
                .arg(&out)
                .env("RAYON_NUM_THREADS", threads)
                .output()
                .unwrap();
            assert!(output.status.success(), "{}", stderr(&output));
        }
        out
    };
    let one = run("one", "1");
    let two = run("two", "2");
    let names = files_in(&one);
    // Three tables in nine formats, and the preset's dfg.ktx2 with its two sidecars.
    assert_eq!(names.len(), 3 * 9 + 3, "{names:?}");
    assert_eq!(files_in(&two), names);
    for name in &names {
        assert!(
            std::fs::read(one.join(name)).unwrap() == std::fs::read(two.join(name)).unwrap(),
            "{name} differs"
        );
    }
}

/// Issue 64, defect 1: `--texels lookup-fit` with `F_avg` (alone, beside `E`, in a shard) bakes
/// instead of panicking (exit 101 at `roughness_axis`): `F_avg`, a closed form over the IOR
/// alone, is point samples, and the others are fitted.
#[test]
fn f_avg_with_fitted_texels_bakes() {
    for extra in [
        &["--quantity", "f-avg"][..],
        &["--quantity", "f-avg,e"][..],
        &["--quantity", "f-avg,e", "--shard", "1/2"][..],
    ] {
        let dir = tempfile::tempdir().unwrap();
        let output = Command::new(env!("CARGO_BIN_EXE_kiln"))
            .args([
                "bake",
                "--texels",
                "lookup-fit",
                "--size",
                "6",
                "-q",
                "--out",
            ])
            .arg(dir.path())
            .args(extra)
            .output()
            .unwrap();
        assert!(
            output.status.success(),
            "{extra:?}: exit {:?}: {}",
            output.status.code(),
            String::from_utf8_lossy(&output.stderr)
        );
    }
}
