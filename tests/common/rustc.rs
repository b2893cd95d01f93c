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

/// The generated Rust lookup of the 2-D `table`, written as `{id}.rs` in `dir`, compiled and run
/// in f32 at `points` (`mu`, roughness): what it returns at each.
#[allow(dead_code)] // not every test that includes this file runs a lookup
pub fn generated_lookups(
    dir: &std::path::Path,
    table: &kiln::Table,
    points: &[(f64, f64)],
) -> Vec<f64> {
    use std::fmt::Write as _;
    let id = table.spec.id();
    let rust = std::fs::read_to_string(dir.join(format!("{id}.rs"))).unwrap();
    let constant = kiln::format::rust::const_prefix(table);
    let mut source = format!("{rust}\nfn main() {{\n");
    for &(mu, r) in points {
        let _ = writeln!(
            source,
            "    println!(\"{{}}\", {}_lookup(&{constant}, {mu:?}_f32, {r:?}_f32));",
            constant.to_lowercase()
        );
    }
    source += "}\n";
    // A crate name is an identifier: `-ior-1.5` loses its dot.
    let crate_name = format!("{id}_lookup").replace('.', "_");
    let values = compile_and_run(dir, &crate_name, &source);
    assert_eq!(values.len(), points.len());
    values
}
