//! Running the `kiln` binary from the CLI tests.

use std::process::{Command, Output};

/// Runs `kiln` with `args` and returns what it printed and its status.
pub fn kiln(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_kiln"))
        .args(args)
        .output()
        .expect("kiln runs")
}
