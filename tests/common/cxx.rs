//! The C++ compiler the tests that compile kiln's generated C use, if the machine has one.

/// The first of `c++`, `g++` and `clang++` that runs.
pub fn compiler() -> Option<&'static str> {
    ["c++", "g++", "clang++"].into_iter().find(|c| {
        std::process::Command::new(c)
            .arg("--version")
            .output()
            .is_ok()
    })
}

/// The C++ compiler, or the skip reported for `test` (see `external.rs`).
#[allow(dead_code)] // not every test that includes this file compiles
pub fn compiler_or_skip(test: &str) -> Option<&'static str> {
    if let Some(compiler) = compiler() {
        return Some(compiler);
    }
    super::external::skipped(
        test,
        "a C++ compiler (c++, g++ or clang++)",
        "Debian: apt-get install g++",
    );
    None
}

/// Compiles `source` as C++17 with every literal in single precision (`name.cpp` in `dir`),
/// runs it, and returns the numbers it prints, one per line. Panics, with the compiler's
/// message, if it does not compile.
#[allow(dead_code)] // not every test that includes this file runs a program
pub fn compile_and_run(dir: &std::path::Path, name: &str, source: &str) -> Vec<f64> {
    let file = dir.join(format!("{name}.cpp"));
    std::fs::write(&file, source).unwrap();
    let program = dir.join(name);
    let compiler = compiler().expect("a C++ compiler (c++, g++ or clang++)");
    let compiled = std::process::Command::new(compiler)
        .args(["-std=c++17", "-O0", "-fsingle-precision-constant", "-o"])
        .arg(&program)
        .arg(&file)
        .output()
        .expect("the C++ compiler runs");
    assert!(
        compiled.status.success(),
        "{} does not compile as C++:\n{}",
        file.display(),
        String::from_utf8_lossy(&compiled.stderr)
    );
    let output = std::process::Command::new(&program).output().unwrap();
    assert!(output.status.success(), "{} failed", program.display());
    String::from_utf8(output.stdout)
        .unwrap()
        .lines()
        .map(|l| l.parse().unwrap())
        .collect()
}

/// A table's two channels (value, `1 - value`) as interleaved single-precision C++ literals, in
/// storage order: the texels of the tests' C++ stand-ins for a GPU texture.
#[allow(dead_code)] // not every test that includes this file samples a texture
pub fn texels_rg(table: &kiln::Table) -> String {
    let texels: Vec<String> = table
        .value
        .iter()
        .zip(&table.one_minus_value)
        .flat_map(|(v, w)| [format!("{:?}f", *v as f32), format!("{:?}f", *w as f32)])
        .collect();
    texels.join(", ")
}
