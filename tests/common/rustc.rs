//! Compiling and running generated Rust with the rustc that builds the tests.

/// Compiles the Rust program `source` with rustc (`name.rs` in `dir`, edition 2021, optimised),
/// runs it, and returns the numbers it prints, one per line. Panics, with rustc's message, if it
/// does not compile.
pub fn compile_and_run(dir: &std::path::Path, name: &str, source: &str) -> Vec<f64> {
    let file = dir.join(format!("{name}.rs"));
    std::fs::write(&file, source).unwrap();
    let program = dir.join(name);
    let rustc = std::env::var("RUSTC").unwrap_or_else(|_| "rustc".into());
    let compiled = std::process::Command::new(rustc)
        .args(["--edition", "2021", "-O", "-A", "warnings", "-o"])
        .arg(&program)
        .arg(&file)
        .output()
        .expect("rustc runs");
    assert!(
        compiled.status.success(),
        "the generated Rust does not compile:\n{}",
        String::from_utf8_lossy(&compiled.stderr)
    );
    let output = std::process::Command::new(&program).output().unwrap();
    assert!(output.status.success());
    String::from_utf8(output.stdout)
        .unwrap()
        .lines()
        .map(|l| l.parse().unwrap())
        .collect()
}
