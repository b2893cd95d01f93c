//! The build-script example (`examples/build-script`): an engine crate that bakes kiln's tables
//! in its `build.rs` with `default-features = false` and `include!`s the generated Rust. Built
//! here with the same cargo, offline (its dependencies are kiln's), in a target directory of its
//! own; its program's lookup must equal the library's.

use std::path::Path;
use std::process::Command;

#[test]
#[ignore = "long (about 140 s): .ci/run runs it with --ignored"]
fn build_script_example_bakes_and_includes_the_tables() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let manifest = root.join("examples/build-script/Cargo.toml");
    let target = root.join("target/build-script-example");
    let output = Command::new(env!("CARGO"))
        .args(["build", "--release", "--offline", "--manifest-path"])
        .arg(&manifest)
        .arg("--target-dir")
        .arg(&target)
        .output()
        .expect("cargo runs");
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let run = Command::new(target.join("release/kiln-build-script-example"))
        .output()
        .expect("the example runs");
    let text = String::from_utf8(run.stdout).unwrap();
    // "E(mu 0.5, r 0.5) = X, 1 - E = Y"
    let e: f64 = text
        .split("= ")
        .nth(1)
        .and_then(|s| s.split(',').next())
        .and_then(|s| s.trim().parse().ok())
        .unwrap_or_else(|| panic!("unexpected output: {text}"));
    let scene = kiln::scene::Scene::read(&root.join("examples/build-script/scene.toml")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let baked = scene
        .bake(dir.path(), &|_| {}, kiln::format::replace::Replace::Refuse)
        .unwrap();
    let table = &baked.report.tables[0];
    assert_eq!(table.spec.id(), "ggx-height-correlated-E");
    let expected = table.lookup(0.5, 0.5);
    // f32 storage and f32 arithmetic in the generated lookup.
    assert!((e - expected).abs() < 1e-6, "{e} vs {expected}");
    assert!(text.contains("E_avg entries: 32"), "{text}");
}
