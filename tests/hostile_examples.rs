//! The hostile inputs and faults found by fuzzing kiln (issue 22), each as the command a user
//! or an attacker would run: every one failed (wrote NaN, passed a NaN audit, panicked,
//! exhausted memory, echoed raw bytes) before, and must end with a clear error (exit 2) now.

#![cfg(feature = "cli")]

use std::path::Path;
use std::process::{Command, Stdio};

use crate::command;
use command::kiln;

fn stderr(output: &std::process::Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

/// Exit 2 with a message on stderr naming `needle`, no panic.
fn refused(output: &std::process::Output, needle: &str) {
    let message = stderr(output);
    assert_eq!(output.status.code(), Some(2), "{message}");
    assert!(!message.contains("panicked"), "{message}");
    assert!(message.contains(needle), "wanted '{needle}' in: {message}");
}

fn bake_small(dir: &Path, formats: &str) {
    let out = kiln(
        &[
            "bake",
            "--quantity",
            "e",
            "--size",
            "6",
            "--max-error",
            "1e-3",
            "--format",
            formats,
            "-q",
            "--out",
        ]
        .iter()
        .copied()
        .chain([dir.to_str().unwrap()])
        .collect::<Vec<_>>(),
    );
    assert!(out.status.success(), "{}", stderr(&out));
}

/// An IOR beyond what f64 can square gave all-NaN tables, exit 0, `node_max_error: 0`; a
/// conductor eta of 1e-200 gave "File name too long".
#[test]
fn inputs_outside_the_physical_domain_are_refused_up_front() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("nb");
    let o = out.to_str().unwrap();
    refused(
        &kiln(&[
            "bake",
            "--ior",
            "1e155",
            "--mu-axis",
            "linear",
            "--size",
            "4",
            "--format",
            "json",
            "--out",
            o,
        ]),
        "ior must be between 0.01 and 100 (got 1e155)",
    );
    refused(
        &kiln(&[
            "bake",
            "--quantity",
            "e-f",
            "--eta",
            "1e-200",
            "--k",
            "1",
            "--mu-axis",
            "linear",
            "--out",
            o,
        ]),
        "eta must be between 0.01 and 100 (got 1e-200)",
    );
    refused(
        &kiln(&[
            "bake",
            "--quantity",
            "e-f",
            "--eta",
            "1e308",
            "--k",
            "1",
            "--mu-axis",
            "linear",
            "--out",
            o,
        ]),
        "eta must be between",
    );
    assert!(!out.exists() || std::fs::read_dir(&out).unwrap().next().is_none());
    // A scene is held to the same bounds by plan as by bake.
    let scene = dir.path().join("s.toml");
    std::fs::write(
        &scene,
        "[[material]]\nname = \"x\"\nndf = \"ggx\"\nroughness = 0.5\nfresnel = { dielectric = \
         { ior = 1e155 } }\n",
    )
    .unwrap();
    refused(
        &kiln(&["plan", scene.to_str().unwrap()]),
        "ior must be between",
    );
}

/// NaN written over the one-minus plane of a `.bin` audited clean, exit 0.
#[test]
fn verify_refuses_non_finite_or_inconsistent_channels() {
    let dir = tempfile::tempdir().unwrap();
    bake_small(dir.path(), "bin,json,exr");
    let bin = dir.path().join("ggx-height-correlated-E.bin");
    let bytes = std::fs::read(&bin).unwrap();
    let contents = kiln::format::binary::decode(&bytes).unwrap();
    assert_eq!(contents.channels[1].0, "one_minus_E");
    // The one-minus plane is the second; find it by its first value's bits.
    let first = (contents.channels[1].1[0] as f32).to_le_bytes();
    let at = bytes
        .windows(4)
        .enumerate()
        .filter(|(_, w)| *w == first)
        .map(|(k, _)| k)
        .find(|&k| {
            let v = f32::from_le_bytes(bytes[k + 4..k + 8].try_into().unwrap());
            v == contents.channels[1].1[1] as f32
        })
        .unwrap();
    let mut poisoned = bytes.clone();
    poisoned[at..at + 4].copy_from_slice(&f32::NAN.to_le_bytes());
    std::fs::write(&bin, &poisoned).unwrap();
    refused(
        &kiln(&["verify", bin.to_str().unwrap()]),
        "one_minus_E at texel 0 is NaN",
    );

    // An axis descriptor that is not the sidecar's.
    let mut swapped = bytes.clone();
    swapped[32..48].copy_from_slice(&bytes[48..64]);
    std::fs::write(&bin, &swapped).unwrap();
    refused(
        &kiln(&["verify", bin.to_str().unwrap()]),
        "axis descriptors",
    );

    // A binary beside the sidecar of another table (a bake killed between its renames).
    let other = tempfile::tempdir().unwrap();
    let out = kiln(&[
        "bake",
        "--quantity",
        "e",
        "--size",
        "6",
        "--max-error",
        "1e-3",
        "--ndf",
        "beckmann",
        "--format",
        "bin",
        "-q",
        "--out",
        other.path().to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    std::fs::copy(other.path().join("beckmann-height-correlated-E.bin"), &bin).unwrap();
    refused(
        &kiln(&["verify", bin.to_str().unwrap()]),
        "does not hold the values of its sidecar",
    );

    // A sidecar whose spec names F_avg (no IOR axis) and one whose axes are swapped panicked.
    let json = dir.path().join("ggx-height-correlated-E.json");
    let text = std::fs::read_to_string(&json).unwrap();
    let f_avg = text.replace("\"quantity\": \"E\"", "\"quantity\": \"F_avg\"");
    assert_ne!(f_avg, text);
    std::fs::write(&json, &f_avg).unwrap();
    let o = kiln(&["verify", json.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(!stderr(&o).contains("panicked"));
    let value: serde_json::Value = serde_json::from_str(&text).unwrap();
    let mut swapped = value.clone();
    let spec = &mut swapped["spec"];
    let (r, m) = (spec["roughness"].clone(), spec["mu"].clone());
    spec["roughness"] = m;
    spec["mu"] = r;
    std::fs::write(&json, serde_json::to_string(&swapped).unwrap()).unwrap();
    refused(&kiln(&["verify", json.to_str().unwrap()]), "axes swapped");
}

/// One half-float NaN in three.js' LUT audited as "max error NaN", exit 0.
#[test]
fn engine_files_with_nan_texels_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let source =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/engines/three/DFGLUTData-16.js");
    let text = std::fs::read_to_string(source).unwrap();
    let at = text.find("0x").unwrap();
    let poisoned = format!("{}0x7e00{}", &text[..at], &text[at + 6..]);
    let file = dir.path().join("DFGLUTData.js");
    std::fs::write(&file, poisoned).unwrap();
    refused(
        &kiln(&["verify", "--preset", "three", file.to_str().unwrap()]),
        "is NaN",
    );
    // A ] before the array's [ (found by cargo-fuzz: a string slice out of order panicked).
    let at = text.find("Uint16Array").unwrap() + "Uint16Array".len();
    std::fs::write(&file, format!("{}]{}", &text[..at], &text[at..])).unwrap();
    let o = kiln(&[
        "verify",
        "--preset",
        "three",
        file.to_str().unwrap(),
        "--quiet",
    ]);
    assert_ne!(o.status.code(), Some(101), "{}", stderr(&o));
    assert!(!stderr(&o).contains("panicked"), "{}", stderr(&o));
}

/// A Bevy KTX2 with a short level panicked; a 39 KB zstd KTX2 claiming a huge extent reached
/// 3 GB; a 405-byte EXR claiming 2^20 + 1 square aborted on a 4 TB allocation.
#[test]
fn headers_that_claim_too_much_are_refused_before_allocating() {
    let dir = tempfile::tempdir().unwrap();
    let bevy = std::fs::read(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/engines/bevy/dfg.ktx2"),
    )
    .unwrap();
    let short = dir.path().join("short.ktx2");
    std::fs::write(&short, &bevy[..bevy.len() - 100]).unwrap();
    let o = kiln(&["verify", "--preset", "bevy", short.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(!stderr(&o).contains("panicked"));
    // The same file claiming 65536 x 65536 texels (pixelWidth and pixelHeight at 20 and 24).
    let mut huge = bevy.clone();
    huge[20..24].copy_from_slice(&65536u32.to_le_bytes());
    huge[24..28].copy_from_slice(&65536u32.to_le_bytes());
    let huge_path = dir.path().join("huge.ktx2");
    std::fs::write(&huge_path, &huge).unwrap();
    let o = kiln(&["verify", "--preset", "bevy", huge_path.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("65536 x 65536"), "{}", stderr(&o));

    // An EXR whose data window claims (2^20 + 1)^2 pixels.
    bake_small(dir.path(), "exr");
    let exr = dir.path().join("ggx-height-correlated-E.exr");
    let mut bytes = std::fs::read(&exr).unwrap();
    let name = b"dataWindow\0box2i\0";
    let at = bytes.windows(name.len()).position(|w| w == name).unwrap() + name.len() + 4;
    let big = 1i32 << 20;
    bytes[at + 8..at + 12].copy_from_slice(&big.to_le_bytes());
    bytes[at + 12..at + 16].copy_from_slice(&big.to_le_bytes());
    std::fs::write(&exr, &bytes).unwrap();
    let o = kiln(&["verify", exr.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("1048577 x 1048577"), "{}", stderr(&o));
}

/// `kiln verify /dev/zero` and `kiln plan /dev/zero` read until memory ran out.
#[cfg(unix)]
#[test]
fn devices_are_not_read() {
    refused(&kiln(&["verify", "/dev/zero"]), "not a regular file");
    refused(&kiln(&["plan", "/dev/zero"]), "not a regular file");
}

/// `kiln verify … | head` panicked on the broken pipe (exit 101).
#[cfg(unix)]
#[test]
fn a_closed_pipe_ends_kiln_quietly() {
    let tables =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tables/ggx-height-correlated-E_avg.json");
    let mut child = Command::new(env!("CARGO_BIN_EXE_kiln"))
        .args(["verify", tables.to_str().unwrap()])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Close the reading end before kiln writes (it prints after its audit).
    drop(child.stdout.take());
    let output = child.wait_with_output().unwrap();
    let message = stderr(&output);
    assert!(!message.contains("panicked"), "{message}");
    assert_ne!(output.status.code(), Some(101));
}

/// Material names with NUL or a right-to-left override were accepted; errors echoed raw bytes
/// and newlines from the file.
#[test]
fn names_and_messages_hold_no_control_characters() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("s.toml");
    std::fs::write(
        &scene,
        "[[material]]\nname = \"steel\\u202egnp.exe\"\nndf = \"ggx\"\nroughness = 0.5\n",
    )
    .unwrap();
    let o = kiln(&["plan", scene.to_str().unwrap()]);
    refused(&o, "bidirectional");
    assert!(!stderr(&o).contains('\u{202e}'));
    std::fs::write(
        &scene,
        "[[material]]\nname = \"a\\u0000b\"\nndf = \"ggx\"\nroughness = 0.5\n",
    )
    .unwrap();
    let o = kiln(&["plan", scene.to_str().unwrap()]);
    refused(&o, "control characters");
    assert!(!stderr(&o).contains('\0'));
    // A text table with an escape sequence where a number should be.
    let table = dir.path().join("t.txt");
    std::fs::write(&table, "0.5 0.5\n\u{1b}[2J\u{1b}[31mrm 0.5\n0.5\n").unwrap();
    let o = kiln(&[
        "verify",
        table.to_str().unwrap(),
        "--shape",
        "2x2",
        "--order",
        "r,mu",
        "--grid",
        "nodes",
        "--mu-axis",
        "linear",
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(!stderr(&o).contains('\u{1b}'), "{}", stderr(&o));
    assert!(stderr(&o).contains("\\u{1b}"), "{}", stderr(&o));
}

/// Stale temporaries of an interrupted run were never cleaned (55 after one kill).
#[test]
fn stale_temporaries_are_removed_by_the_next_bake() {
    let dir = tempfile::tempdir().unwrap();
    let stale = dir.path().join(".ggx-height-correlated-E.json.aBc123.tmp");
    let fresh = dir.path().join(".ggx-height-correlated-E.exr.XyZ789.tmp");
    let unrelated = dir.path().join(".notes.tmp");
    for path in [&stale, &fresh, &unrelated] {
        std::fs::write(path, b"partial").unwrap();
    }
    let old = std::time::SystemTime::now() - std::time::Duration::from_secs(3600);
    for path in [&stale, &unrelated] {
        std::fs::File::options()
            .write(true)
            .open(path)
            .unwrap()
            .set_modified(old)
            .unwrap();
    }
    bake_small(dir.path(), "json");
    assert!(!stale.exists(), "a stale temporary of kiln's is removed");
    assert!(fresh.exists(), "a recent one may be a concurrent bake's");
    assert!(
        unrelated.exists(),
        "a file that is not kiln's is left alone"
    );
}
