//! Running the `kiln` binary from the CLI tests.

use std::process::{Command, Output};

/// Runs `kiln` with `args` and returns what it printed and its status.
pub fn kiln(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_kiln"))
        .args(args)
        .output()
        .expect("kiln runs")
}

/// Starts `kiln` with `args` (and `env`), reads the first line it prints on stderr, then kills
/// it: for the warnings a long command gives before it starts.
#[allow(dead_code)] // not every test that includes this file starts long commands
pub fn first_stderr_line(args: &[&str], env: &[(&str, &str)]) -> String {
    use std::io::BufRead;
    let mut child = Command::new(env!("CARGO_BIN_EXE_kiln"))
        .args(args)
        .envs(env.iter().copied())
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("kiln starts");
    let mut line = String::new();
    std::io::BufReader::new(child.stderr.take().expect("piped"))
        .read_line(&mut line)
        .expect("stderr reads");
    child.kill().expect("kiln is killed");
    child.wait().expect("kiln is reaped");
    line
}
