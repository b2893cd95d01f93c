//! Generated code holds only what kiln generated (issue 41). `--carry-over` copied C from the
//! file it was given into Cycles' `shader.tables` (text before `table_sheen_ltc` on its line,
//! and between the array's `}` and `};`), and wrote the file's path unescaped into a `/* */`
//! comment, so that a program including the output ran `system()` or declared variables of the
//! attacker's. Now the carried array is parsed into numbers and re-emitted, and any text from
//! outside kiln (a path, a recorded command) is escaped for comments of every language.
//!
//! The check is independent of kiln's escaping: each generated file's comments are removed by
//! this file's own reader of each language's comment rules (C's backslash-newline splice,
//! Rust's and WGSL's nesting block comments), and where a C++ compiler is present by its
//! preprocessor too; what is left, the code a compiler sees, must not hold the attacker's text.

#![cfg(feature = "cli")]

use std::path::{Path, PathBuf};

use kiln::format::{Format, Precision};
use kiln::preset::Preset;
use kiln::{Quantity, Table, TableSpec};

use crate::command;
use crate::cxx;
use command::kiln;

/// Texts that try to leave a comment in each way a language allows, each carrying the word
/// `injected`.
const HOSTILE: [&str; 6] = [
    "evil*/int injected_a;/*",
    "x\nint injected_b;",
    "x\r\nint injected_c;",
    "trailing backslash \\\nint injected_d;",
    "trigraph ??/\nint injected_e;",
    "nested /* /* */ */ int injected_f; /*",
];

/// How a language's comments work.
#[derive(Clone, Copy)]
struct Comments {
    /// Block comments nest (Rust, WGSL).
    nesting: bool,
    /// A backslash before a newline continues a line comment (C, C++, HLSL, GLSL).
    splice: bool,
}

const C_LIKE: Comments = Comments {
    nesting: false,
    splice: true,
};
const NESTING: Comments = Comments {
    nesting: true,
    splice: false,
};
const JS: Comments = Comments {
    nesting: false,
    splice: false,
};

/// `text` with its comments removed by `rules` (each comment becomes one space). String
/// literals are not special: kiln's generated code holds none that could contain a comment
/// marker, and treating one as code only makes this stricter.
fn code_only(text: &str, rules: Comments) -> String {
    let b = text.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut k = 0;
    while k < b.len() {
        if b[k..].starts_with(b"//") {
            // To the end of the line, which a backslash before the newline (C) continues; a
            // lone CR does not end it.
            k += 2;
            while k < b.len() && b[k] != b'\n' {
                if rules.splice && b[k] == b'\\' && b.get(k + 1) == Some(&b'\n') {
                    k += 1;
                }
                k += 1;
            }
            out.push(b' ');
        } else if b[k..].starts_with(b"/*") {
            let mut depth = 1;
            k += 2;
            while k < b.len() && depth > 0 {
                if b[k..].starts_with(b"*/") {
                    depth -= 1;
                    k += 2;
                } else if rules.nesting && b[k..].starts_with(b"/*") {
                    depth += 1;
                    k += 2;
                } else {
                    k += 1;
                }
            }
            out.push(b' ');
        } else {
            out.push(b[k]);
            k += 1;
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// The comment rules of a generated file, by its name.
fn rules_of(name: &str) -> Option<Comments> {
    let ext = name.rsplit('.').next()?;
    match ext {
        "h" | "hlsl" | "glsl" | "tables" | "inc" | "cpp" => Some(C_LIKE),
        "rs" | "wgsl" => Some(NESTING),
        "js" => Some(JS),
        _ => None,
    }
}

/// What each generated source file of `files` leaves to a compiler holds no `injected`; and
/// that each was seen.
fn free_of_injections(files: &[(String, Vec<u8>)], context: &str) -> usize {
    let mut sources = 0;
    for (name, bytes) in files {
        let Some(rules) = rules_of(name) else {
            continue;
        };
        sources += 1;
        let text = String::from_utf8_lossy(bytes);
        let code = code_only(&text, rules);
        assert!(
            !code.contains("injected"),
            "{context}: {name} lets text out of a comment:\n{}",
            code.lines()
                .filter(|l| l.contains("injected"))
                .collect::<Vec<_>>()
                .join("\n")
        );
        // Also the raw text never holds a line that starts with the attacker's code.
        assert!(
            !text
                .lines()
                .any(|l| l.trim_start().starts_with("int injected")),
            "{context}: {name}"
        );
    }
    sources
}

/// A table of `spec` with plausible values and the recorded command `command`.
fn table(spec: TableSpec, command: &str) -> Table {
    let n = spec.len();
    let value: Vec<f64> = (0..n).map(|k| 0.5 + 0.25 * (k as f64 / n as f64)).collect();
    Table {
        one_minus_value: value.iter().map(|v| 1.0 - v).collect(),
        std_error: vec![0.0; n],
        value,
        spec,
        command: command.into(),
        node_errors: None,
        requested_max_error: None,
        lookup_fit: None,
    }
}

/// Every kiln format and every preset's files, with a table whose recorded command (text a
/// cache entry or a file read back can carry) tries each way out of a comment: what the
/// compilers see holds none of it.
#[test]
fn no_recorded_text_leaves_a_comment_in_any_generator() {
    let formats = [
        Format::Rs,
        Format::H,
        Format::Wgsl,
        Format::Glsl,
        Format::Hlsl,
    ];
    for hostile in HOSTILE {
        let specs = kiln::BakeOptions {
            quantities: vec![Quantity::E, Quantity::EAvg],
            size: 4,
            ..kiln::BakeOptions::default()
        }
        .specs();
        let tables: Vec<Table> = specs.into_iter().map(|s| table(s, hostile)).collect();
        let files = kiln::format::encode_all(&tables, &formats, Precision::F32).unwrap();
        assert_eq!(free_of_injections(&files, hostile), 10);
        for preset in Preset::ALL {
            let tables: Vec<Table> = preset
                .bakes(None)
                .iter()
                .flat_map(|o| o.resolved().specs())
                .filter(|s| s.quantity != Quantity::FMsNorm)
                .map(|s| table(s, hostile))
                .collect();
            let files = preset
                .files_with_sidecars(&tables, None, None)
                .unwrap_or_else(|e| panic!("{}: {e}", preset.name()));
            free_of_injections(&files, &format!("{} {hostile:?}", preset.name()));
        }
    }
}

fn blender_shader_tables() -> String {
    std::fs::read_to_string(
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/engines/cycles/shader.tables"),
    )
    .unwrap()
}

/// Runs the C++ preprocessor on `file` (comments removed, as the compiler sees it), if there
/// is one.
fn preprocessed(file: &Path) -> Option<String> {
    let compiler = cxx::compiler_or_skip("the C++ preprocessor's reading of the emitted code")?;
    let out = std::process::Command::new(compiler)
        .args([
            "-x",
            "c++",
            "-E",
            "-P",
            "-DCCL_NAMESPACE_BEGIN=",
            "-DCCL_NAMESPACE_END=",
        ])
        .arg(file)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    Some(String::from_utf8(out.stdout).unwrap())
}

/// The three injections, through `kiln bake --preset cycles --carry-over`: code on the
/// line before `table_sheen_ltc`, code between the array's `}` and `};`, and a directory whose
/// name closes the header's comment and opens another. The file kiln writes declares Blender's
/// arrays and nothing else, and its LTC numbers are Blender's.
#[test]
fn carried_over_code_and_paths_never_reach_the_output() {
    let blender = blender_shader_tables();
    let at = blender.find("static const float table_sheen_ltc[").unwrap();
    let end = at + blender[at..].find("};").unwrap();
    let poisoned = format!(
        "{}int injected_a = system(\"touch PWNED\"); {}}} int injected_b = 1; struct S {{ {}",
        &blender[..at],
        &blender[at..end],
        &blender[end..]
    );
    let dir = tempfile::tempdir().unwrap();
    let evil = dir.path().join("evil*").join("int injected_c;").join("*");
    std::fs::create_dir_all(&evil).unwrap();
    let carried = evil.join("shader.tables");
    std::fs::write(&carried, &poisoned).unwrap();
    let out = dir.path().join("out");
    let run = kiln(&[
        "bake",
        "--preset",
        "cycles",
        // The quadrature (QMC's inside glass misses 1e-3 and 1e-2 by 13 %: issue 40).
        "--max-error",
        "1e-4",
        "-q",
        "--carry-over",
        carried.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let written = out.join("shader.tables");
    let text = std::fs::read_to_string(&written).unwrap();
    let files = [("shader.tables".to_string(), text.clone().into_bytes())];
    assert_eq!(free_of_injections(&files, "carry-over"), 1);
    assert!(!text.contains("system("), "{}", &text[..2000]);
    // The path is in the header, escaped.
    assert!(text.contains("evil%2A/int injected_c;/%2A/shader.tables"));
    // The LTC numbers are Blender's, read by this file's own parser.
    let numbers = |t: &str| -> Vec<u32> {
        let at = t.find("table_sheen_ltc[3072] = {").unwrap() + 25;
        t[at..at + t[at..].find('}').unwrap()]
            .split(',')
            .map(|s| s.trim().trim_end_matches('f'))
            .filter(|s| !s.is_empty())
            .map(|s| s.parse::<f32>().unwrap().to_bits())
            .collect()
    };
    assert_eq!(numbers(&text), numbers(&blender));
    if let Some(code) = preprocessed(&written) {
        assert!(
            !code.contains("injected"),
            "the compiler sees injected code"
        );
        assert!(!code.contains("system"), "the compiler sees system()");
        let declared = code.matches("static const float ").count();
        assert_eq!(declared, blender.matches("static const float ").count());
    }
}

/// A carried array with anything but numbers between its braces is refused, not copied.
#[test]
fn a_carried_array_that_is_not_numbers_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    for body in [
        "1.0f, system(\"x\"), 2.0f",
        "1.0f, 2.0f /* c */",
        "1.0f, 0x10",
        "1.0f, 1e99f",
        "1.0f, nan",
    ] {
        let file = dir.path().join("bad.tables");
        std::fs::write(
            &file,
            format!("static const float table_sheen_ltc[3] = {{ {body} }};"),
        )
        .unwrap();
        let run = kiln(&[
            "bake",
            "--preset",
            "cycles",
            "--carry-over",
            file.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]);
        let message = String::from_utf8_lossy(&run.stderr);
        assert_eq!(run.status.code(), Some(2), "{body}: {message}");
        assert!(message.contains("not an array of numbers"), "{message}");
        assert!(!out.exists());
    }
}

/// A scene's material names reach only `materials.json` (JSON, escaped), never generated code:
/// a name that tries to close a comment and a string, baked into every code format.
#[test]
fn a_hostile_material_name_stays_out_of_generated_code() {
    let dir = tempfile::tempdir().unwrap();
    let name = "evil*/ int injected_g; /* \\\" `x` ??/";
    let scene = format!(
        "[output]\nformats = [\"rs\", \"h\", \"wgsl\", \"glsl\", \"hlsl\", \"json\"]\n\
         max_error = 1e-3\n\n[[material]]\nname = {}\nndf = \"ggx\"\nroughness = 0.5\n",
        serde_json::to_string(name).unwrap()
    );
    let path = dir.path().join("scene.toml");
    std::fs::write(&path, scene).unwrap();
    let out = dir.path().join("out");
    let run = kiln(&[
        "bake",
        "--scene",
        path.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "-q",
    ]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let files: Vec<(String, Vec<u8>)> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_file())
        .map(|p| {
            (
                p.file_name().unwrap().to_string_lossy().into_owned(),
                std::fs::read(&p).unwrap(),
            )
        })
        .collect();
    assert!(free_of_injections(&files, "scene") >= 5);
    for (file, bytes) in &files {
        if rules_of(file).is_some() {
            assert!(
                !String::from_utf8_lossy(bytes).contains("evil"),
                "{file} holds the material's name"
            );
        }
    }
    let materials: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("materials.json")).unwrap()).unwrap();
    assert_eq!(materials["materials"][0]["name"], name);
}
