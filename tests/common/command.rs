//! Running the `kiln` binary from the CLI tests.

use std::process::{Command, Output};

/// What `kiln` printed on stderr.
#[allow(dead_code)] // not every test that includes this file reads stderr
pub fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

/// Runs `kiln` and expects a usage error (exit 2, no panic) whose message names each of
/// `words`; the message.
#[allow(dead_code)] // not every test that includes this file expects refusals
pub fn refused(args: &[&str], words: &[&str]) -> String {
    let output = kiln(args);
    let message = stderr(&output);
    assert_eq!(output.status.code(), Some(2), "{args:?}: {message}");
    assert!(!message.contains("panicked"), "{message}");
    for word in words {
        assert!(
            message.contains(word),
            "{args:?}: '{message}' lacks '{word}'"
        );
    }
    message
}

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

/// `kiln COMMAND --json ARGS`: the exit status and the report (`Null` if none).
#[allow(dead_code)] // not every test that includes this file reads JSON
pub fn json_of(command: &str, args: &[&str]) -> (Option<i32>, serde_json::Value) {
    let mut all = vec![command, "--json"];
    all.extend_from_slice(args);
    let output = kiln(&all);
    let report = serde_json::from_slice(&output.stdout).unwrap_or(serde_json::Value::Null);
    assert!(
        report != serde_json::Value::Null || output.status.code() == Some(2),
        "{args:?}: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    (output.status.code(), report)
}

/// Runs kiln with `args` and asserts that it exits 0, showing its stderr if not.
#[allow(dead_code)] // not every test that includes this file runs a command to success
pub fn succeeded(args: &[&str]) {
    let output = kiln(args);
    assert_eq!(
        output.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
}

/// The number `field` of a JSON report.
#[allow(dead_code)] // not every test that includes this file reads reports
pub fn number(report: &serde_json::Value, field: &str) -> f64 {
    report[field]
        .as_f64()
        .unwrap_or_else(|| panic!("no {field} in {report}"))
}
