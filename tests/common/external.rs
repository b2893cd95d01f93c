//! Tools outside Rust that some tests run: a C++ compiler (the generated HLSL, GLSL, WGSL and C
//! as C++), node (three.js' module), a Vulkan driver (the generated WGSL and GLSL on a device).
//! A test that needs one runs where it is, says on the terminal that it skipped where it is not
//! (past the test harness's capture, so that a passing run still shows it), and fails where the
//! run asks for everything: `CI=true`, as `.ci/run` runs after installing them. The README's
//! "Tests and what they need" lists them.

#![allow(dead_code)] // each test includes what it uses

use std::io::Write as _;

/// Whether this run must have every tool (`CI=true`).
pub fn everything_required() -> bool {
    std::env::var("CI").is_ok_and(|v| v == "true")
}

/// Reports that `test` cannot run without `tool` (`install` says how to get it): under
/// `CI=true` a failure, otherwise a line on the terminal, and the caller returns.
pub fn skipped(test: &str, tool: &str, install: &str) {
    let message = format!("{test}: SKIPPED, needs {tool} ({install})");
    assert!(
        !everything_required(),
        "{message}; CI=true asks for every test to run"
    );
    let _ = writeln!(std::io::stderr(), "kiln tests: {message}");
}

/// Whether `program` runs with `--version`.
pub fn runs(program: &str) -> bool {
    std::process::Command::new(program)
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success())
}

/// node, or the skip reported for `test`.
pub fn node_or_skip(test: &str) -> Option<&'static str> {
    if runs("node") {
        return Some("node");
    }
    skipped(test, "node", "Debian: apt-get install nodejs");
    None
}
