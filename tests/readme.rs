//! The documentation cannot drift from the behaviour: every `$ kiln ...` line in a fenced block of
//! `README.md` and `docs/*.md` is run (in order, per page, in a fresh temporary folder holding
//! copies of the repository's `tables/`, `tests/data/` and `examples/`) and must succeed; where
//! the page shows the output under the command, the run must print the same lines, every number
//! within one unit of the last digit the page prints.

#![cfg(feature = "cli")]

use std::path::Path;
use std::process::Command;

/// One documented command and the output the page shows for it.
struct Example {
    page: String,
    line: usize,
    command: String,
    output: Vec<String>,
}

fn examples(page: &Path) -> Vec<Example> {
    let text = std::fs::read_to_string(page).unwrap();
    let mut examples: Vec<Example> = Vec::new();
    let mut in_block = false;
    let mut open: Option<usize> = None;
    for (k, line) in text.lines().enumerate() {
        if line.starts_with("```") {
            in_block = !in_block;
            open = None;
            continue;
        }
        if !in_block {
            continue;
        }
        if let Some(command) = line.strip_prefix("$ ") {
            open = command.starts_with("kiln ").then(|| {
                examples.push(Example {
                    page: page.display().to_string(),
                    line: k + 1,
                    command: command.to_string(),
                    output: Vec::new(),
                });
                examples.len() - 1
            });
        } else if let Some(index) = open {
            examples[index].output.push(line.to_string());
        }
    }
    examples
}

/// The numbers of a line, and the line with each replaced by `#`.
fn numbers(line: &str) -> (Vec<String>, String) {
    let mut found = Vec::new();
    let mut skeleton = String::new();
    let chars: Vec<char> = line.chars().collect();
    let mut k = 0;
    while k < chars.len() {
        let starts_number = chars[k].is_ascii_digit()
            || (chars[k] == '-'
                && chars.get(k + 1).is_some_and(char::is_ascii_digit)
                && (k == 0 || !chars[k - 1].is_alphanumeric()));
        if !starts_number {
            skeleton.push(chars[k]);
            k += 1;
            continue;
        }
        let start = k;
        k += 1;
        while k < chars.len() && chars[k].is_ascii_digit() {
            k += 1;
        }
        if k + 1 < chars.len() && chars[k] == '.' && chars[k + 1].is_ascii_digit() {
            k += 1;
            while k < chars.len() && chars[k].is_ascii_digit() {
                k += 1;
            }
        }
        // An exponent: e-9, e5.
        if k < chars.len() && chars[k] == 'e' {
            let mut end = k + 1;
            if chars.get(end) == Some(&'-') {
                end += 1;
            }
            if chars.get(end).is_some_and(char::is_ascii_digit) {
                while end < chars.len() && chars[end].is_ascii_digit() {
                    end += 1;
                }
                k = end;
            }
        }
        found.push(chars[start..k].iter().collect());
        skeleton.push('#');
    }
    (found, skeleton)
}

/// One unit of the last digit `shown` prints: `1.29e-9` -> 1e-11, `0.9987730` -> 1e-7, `5980` -> 1.
fn last_digit(shown: &str) -> f64 {
    let (mantissa, exponent) = match shown.split_once('e') {
        Some((m, e)) => (m, e.parse::<i32>().unwrap()),
        None => (shown, 0),
    };
    let decimals = mantissa.split_once('.').map_or(0, |(_, d)| d.len()) as i32;
    10f64.powi(exponent - decimals)
}

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap() {
        let entry = entry.unwrap();
        let name = entry.file_name();
        if name == "target" {
            continue;
        }
        let path = entry.path();
        if path.is_dir() {
            copy_dir(&path, &to.join(&name));
        } else {
            std::fs::copy(&path, to.join(&name)).unwrap();
        }
    }
}

fn check(example: &Example, dir: &Path) {
    let args: Vec<&str> = example.command.split_whitespace().skip(1).collect();
    let output = Command::new(env!("CARGO_BIN_EXE_kiln"))
        .args(&args)
        .current_dir(dir)
        // The plan's estimates are per thread: fix the count the pages quote.
        .env("RAYON_NUM_THREADS", "2")
        .output()
        .unwrap();
    let place = format!("{}:{}: `{}`", example.page, example.line, example.command);
    assert!(
        output.status.success(),
        "{place} failed: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    if example.output.is_empty() {
        return;
    }
    let printed = String::from_utf8(output.stdout).unwrap();
    let printed: Vec<&str> = printed.lines().collect();
    assert_eq!(
        printed.len(),
        example.output.len(),
        "{place} printed\n{}",
        printed.join("\n")
    );
    for (shown, got) in example.output.iter().zip(&printed) {
        let (shown_numbers, shown_skeleton) = numbers(shown);
        let (got_numbers, got_skeleton) = numbers(got);
        assert_eq!(
            got_skeleton, shown_skeleton,
            "{place}: the page shows\n{shown}\nnow\n{got}"
        );
        for (a, b) in shown_numbers.iter().zip(&got_numbers) {
            let (x, y): (f64, f64) = (a.parse().unwrap(), b.parse().unwrap());
            assert!(
                (x - y).abs() <= 1.01 * last_digit(a),
                "{place}: the page shows {a}, kiln now prints {b}, in\n{got}"
            );
        }
    }
}

#[test]
fn every_documented_command_runs_and_prints_what_the_page_shows() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut pages = vec![root.join("README.md")];
    let mut docs: Vec<_> = std::fs::read_dir(root.join("docs"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    docs.sort();
    pages.extend(docs);
    let mut ran = 0;
    for page in &pages {
        let examples = examples(page);
        if examples.is_empty() {
            continue;
        }
        let dir = tempfile::tempdir().unwrap();
        for folder in ["tables", "tests/data", "examples"] {
            copy_dir(&root.join(folder), &dir.path().join(folder));
        }
        for example in &examples {
            check(example, dir.path());
            ran += 1;
        }
    }
    // The README's quick start alone has three.
    assert!(ran >= 3, "only {ran} documented commands found");
}

#[test]
fn numbers_are_read_with_their_printed_precision() {
    let (found, skeleton) = numbers("max error 1.29e-9, rms 7.21e-11; at mu = -0.5 of 32x32 f16");
    assert_eq!(found, ["1.29e-9", "7.21e-11", "-0.5", "32", "32", "16"]);
    assert_eq!(skeleton, "max error #, rms #; at mu = # of #x# f#");
    assert!((last_digit("1.29e-9") - 1e-11).abs() < 1e-25);
    assert!((last_digit("0.9987730") - 1e-7).abs() < 1e-20);
    assert_eq!(last_digit("5980"), 1.0);
}

/// The `kiln eval` table of docs/accuracy.md (issue 42: five of its seven rows had gone stale):
/// each row's ARGS, run with `--json`, give the row's value to its ten decimals and its
/// standard error to its last digit.
#[test]
fn the_documented_eval_table_is_what_kiln_eval_prints() {
    let page = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/accuracy.md");
    let text = std::fs::read_to_string(&page).unwrap();
    let mut rows = 0;
    for line in text.lines().filter(|l| l.starts_with("| ") && l.contains("| `--ndf")) {
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        let args: Vec<&str> = cells[2].trim_matches('`').split_whitespace().collect();
        let (value, std_error) = (cells[3], cells[4]);
        let mut command = vec!["eval"];
        command.extend(&args);
        command.push("--json");
        let output = Command::new(env!("CARGO_BIN_EXE_kiln"))
            .args(&command)
            .output()
            .unwrap();
        assert!(output.status.success(), "{line}");
        let json: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
        let got = json["value"].as_f64().unwrap();
        let got_error = json["std_error"].as_f64().unwrap();
        assert!(
            (got - value.parse::<f64>().unwrap()).abs() <= 1.01 * last_digit(value),
            "{line}: kiln eval now gives {got:.10}"
        );
        assert!(
            (got_error - std_error.parse::<f64>().unwrap()).abs() <= 1.01 * last_digit(std_error),
            "{line}: kiln eval now gives std error {got_error:.1e}"
        );
        rows += 1;
    }
    assert_eq!(rows, 7, "the table's rows were not found");
}
