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
