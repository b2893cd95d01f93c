//! Baking kiln's compensation with the command line for a test, and reading its document back.

/// The stem of the compensation's files (`STEM.json`, `STEM.rs`, ...).
pub const STEM: &str = "ggx-height-correlated-kiln-compensation";

/// `kiln compensation --bake out --size SIZE --walks WALKS -q` with `extra` arguments (the
/// formats), asserting success; the table its JSON document holds.
pub fn bake(
    out: &std::path::Path,
    size: &str,
    walks: &str,
    extra: &[&str],
) -> kiln::table::compensation::CompensationTable {
    let baked = std::process::Command::new(env!("CARGO_BIN_EXE_kiln"))
        .args(["compensation", "--bake"])
        .arg(out)
        .args(["--size", size, "--walks", walks, "-q"])
        .args(extra)
        .output()
        .unwrap();
    assert!(
        baked.status.success(),
        "{}",
        String::from_utf8_lossy(&baked.stderr)
    );
    let bytes = std::fs::read(out.join(format!("{STEM}.json"))).unwrap();
    kiln::format::compensation::decode(&bytes, STEM).unwrap()
}
