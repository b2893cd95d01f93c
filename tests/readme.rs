//! The documentation cannot drift from the behaviour: every `$ kiln ...` line in a fenced block of
//! `README.md` and `docs/*.md` is run (in order, per page, in a fresh temporary folder holding
//! copies of the repository's `tables/`, `tests/data/` and `examples/`) and must succeed; where
//! the page shows the output under the command, the run must print the same lines, every number
//! within one unit of the last digit the page prints; a picture a command draws into `docs/`
//! must be the committed one.
//!
//! A block the page marks `<!-- long: ... -->` on the line before it (a command of a minute or
//! more) runs in its own test, ignored by the README's test command and run by `.ci/run`
//! (`cargo test --release -- --ignored`).

#![cfg(feature = "cli")]

use std::path::Path;
use std::process::Command;

/// One documented command and the output the page shows for it.
struct Example {
    page: String,
    line: usize,
    command: String,
    output: Vec<String>,
    /// In a block marked `<!-- long: ... -->`.
    long: bool,
}

fn examples(page: &Path) -> Vec<Example> {
    let text = std::fs::read_to_string(page).unwrap();
    let mut examples: Vec<Example> = Vec::new();
    let mut in_block = false;
    let mut open: Option<usize> = None;
    let mut long = false;
    let mut previous = "";
    for (k, line) in text.lines().enumerate() {
        if line.starts_with("```") {
            in_block = !in_block;
            long = in_block && previous.starts_with("<!-- long");
            open = None;
            continue;
        }
        if !line.trim().is_empty() {
            previous = line;
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
                    long,
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

/// `README.md` and `docs/*.md`, in order.
fn pages() -> Vec<std::path::PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut docs: Vec<_> = std::fs::read_dir(root.join("docs"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    docs.sort();
    std::iter::once(root.join("README.md"))
        .chain(docs)
        .collect()
}

#[test]
fn every_documented_command_runs_and_prints_what_the_page_shows() {
    // The README's quick start alone has three.
    let ran = run_documented(false);
    assert!(ran >= 3, "only {ran} documented commands found");
}

#[test]
#[ignore = "long (about 110 s): .ci/run runs it with --ignored"]
fn every_long_documented_command_runs_and_prints_what_the_page_shows() {
    let ran = run_documented(true);
    assert!(ran >= 2, "only {ran} long documented commands found");
}

/// Runs the documented commands that are `long` (or not), page by page; returns how many.
fn run_documented(long: bool) -> usize {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let pages = pages();
    let mut ran = 0;
    for page in &pages {
        let examples: Vec<Example> = examples(page)
            .into_iter()
            .filter(|e| e.long == long)
            .collect();
        if examples.is_empty() {
            continue;
        }
        let dir = tempfile::tempdir().unwrap();
        for folder in ["tables", "tests/data", "examples"] {
            copy_dir(&root.join(folder), &dir.path().join(folder));
        }
        // A picture a page shows is drawn by a command on it into docs/: what the command draws
        // now must be the committed picture, byte for byte.
        std::fs::create_dir(dir.path().join("docs")).unwrap();
        for example in &examples {
            check(example, dir.path());
            ran += 1;
        }
        for drawn in std::fs::read_dir(dir.path().join("docs")).unwrap() {
            let drawn = drawn.unwrap().path();
            let name = drawn.file_name().unwrap();
            let committed = root.join("docs").join(name);
            assert!(
                std::fs::read(&committed).ok() == Some(std::fs::read(&drawn).unwrap()),
                "{}: docs/{} is not what its command draws now: run the command the page \
                 shows from the repository's root",
                page.display(),
                name.to_string_lossy()
            );
        }
    }
    ran
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
    for line in text
        .lines()
        .filter(|l| l.starts_with("| ") && l.contains("| `--ndf"))
    {
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

/// Whether `text` states a duration: a number, an optional space and `s`, `ms`, `min` or `h`,
/// standing alone (`0.18 s`, `2 min`; not `2^19 samples`, `1e-3`, `32 x 32`).
fn states_a_duration(text: &str) -> bool {
    let b = text.as_bytes();
    let mut k = 0;
    while k < b.len() {
        let alone = k == 0 || !(b[k - 1].is_ascii_alphanumeric() || b[k - 1] == b'.');
        if !(b[k].is_ascii_digit() && alone) {
            k += 1;
            continue;
        }
        let mut end = k;
        while end < b.len() && (b[end].is_ascii_digit() || b[end] == b'.') {
            end += 1;
        }
        let rest = &text[end..];
        let rest = rest.strip_prefix(' ').unwrap_or(rest);
        for unit in ["ms", "min", "s", "h"] {
            if let Some(after) = rest.strip_prefix(unit)
                && after
                    .chars()
                    .next()
                    .is_none_or(|c| !(c.is_alphanumeric() || c == '-' || c == '_'))
            {
                return true;
            }
        }
        k = end.max(k + 1);
    }
    false
}

/// Whether `text` dates a figure: a date (`2026-12-03`), a numerics version or a commit it was
/// measured at, or says the figure is an estimate or a bound rather than a measurement.
fn dates_it(text: &str) -> bool {
    let lower = text.to_lowercase();
    let b = lower.as_bytes();
    let date = (0..b.len().saturating_sub(9)).any(|k| {
        let d = |i: usize| b[k + i].is_ascii_digit();
        b[k..].starts_with(b"20")
            && d(2)
            && d(3)
            && b[k + 4] == b'-'
            && d(5)
            && d(6)
            && b[k + 7] == b'-'
            && d(8)
            && d(9)
    });
    let commit = lower.match_indices("commit ").any(|(at, m)| {
        lower[at + m.len()..]
            .chars()
            .take(7)
            .filter(char::is_ascii_hexdigit)
            .count()
            == 7
    });
    date || commit
        || lower
            .match_indices("numerics version ")
            .any(|(at, m)| lower[at + m.len()..].starts_with(|c: char| c.is_ascii_digit()))
        || lower
            .split(|c: char| !c.is_alphanumeric())
            .any(|w| ["estimated", "estimate", "timeout", "limit", "limits"].contains(&w))
}

/// Issue 42: figures of time went stale (a bake "0.80 s" that took 0.30, `study --quick` "22 s"
/// for 9.2). Every duration the pages state in prose (outside the fenced blocks, whose `$ kiln`
/// lines the test above runs) must say when it was measured: a date, a numerics version or a
/// commit, in its paragraph (a table: in its caption, one of the two paragraphs before it or
/// its section's first); or be an estimate or a bound.
#[test]
fn every_documented_timing_says_when_it_was_measured() {
    let pages = pages();
    let mut undated = Vec::new();
    let mut checked = 0;
    for page in &pages {
        let text = std::fs::read_to_string(page).unwrap();
        // Paragraphs outside fenced blocks, with the line each starts on; a heading ends one and
        // starts a section.
        let mut in_block = false;
        let mut paragraph: Vec<&str> = Vec::new();
        let mut start = 0;
        let mut section_first: Option<String> = None;
        let mut before: Vec<String> = Vec::new();
        let mut finish = |paragraph: &mut Vec<&str>,
                          start: usize,
                          section_first: &mut Option<String>,
                          before: &mut Vec<String>| {
            if paragraph.is_empty() {
                return;
            }
            let joined = paragraph.join(" ");
            // Inline code is commands and names, not figures.
            let prose: String = joined.split('`').step_by(2).collect::<Vec<_>>().join(" ");
            if states_a_duration(&prose) {
                checked += 1;
                // A table is dated by its caption (the paragraph before it, or its section's
                // first); prose must date its own figures.
                let table = joined.trim_start().starts_with('|');
                let context = table
                    && before
                        .iter()
                        .rev()
                        .take(2)
                        .chain(section_first.iter())
                        .any(|p| dates_it(p));
                if !dates_it(&joined) && !context {
                    undated.push(format!(
                        "{}:{}: {}",
                        page.display(),
                        start + 1,
                        &joined[..joined.len().min(120)]
                    ));
                }
            }
            if section_first.is_none() {
                *section_first = Some(joined.clone());
            }
            before.push(joined);
            paragraph.clear();
        };
        for (k, line) in text.lines().enumerate() {
            if line.starts_with("```") {
                in_block = !in_block;
                finish(&mut paragraph, start, &mut section_first, &mut before);
                continue;
            }
            if in_block {
                continue;
            }
            if line.trim().is_empty() || line.starts_with('#') {
                finish(&mut paragraph, start, &mut section_first, &mut before);
                if line.starts_with('#') {
                    section_first = None;
                    before.clear();
                }
                continue;
            }
            if paragraph.is_empty() {
                start = k;
            }
            paragraph.push(line);
        }
        finish(&mut paragraph, start, &mut section_first, &mut before);
    }
    assert!(
        checked > 20,
        "only {checked} paragraphs with durations found"
    );
    assert!(
        undated.is_empty(),
        "durations without a date, numerics version or commit:\n{}",
        undated.join("\n")
    );
}

#[test]
fn durations_and_dates_are_recognised() {
    for (text, duration) in [
        ("bakes in 0.18 s on 2 cores", true),
        ("took 2 min 21 s", true),
        ("3.5 ms each", true),
        ("2^19 samples, 1e-3, 32 x 32, 5 sigma, 0.5 sr", false),
        ("the 16 x 16 x 16 tables", false),
    ] {
        assert_eq!(states_a_duration(text), duration, "{text}");
    }
    for (text, dated) in [
        ("median of 5, 2026-12-03", true),
        ("numerics version 6", true),
        ("against commit 29b77f9", true),
        ("estimated 2.6 min", true),
        ("one run, time", false),
        ("every estimator", false),
        ("numerics version", false),
    ] {
        assert_eq!(dates_it(text), dated, "{text}");
    }
}
