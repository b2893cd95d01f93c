//! A report gated by `--max-error`: the flags of the audits that can fail, and how they print
//! their verdict.

use crate::args::parse_error_bound;
use clap::Args;

/// The flags of an audit's verdict: its bound, JSON, or nothing but a failure.
#[derive(Args, Debug, Clone)]
pub struct GateArgs {
    /// Exit with status 1 when the report's worst figure (the largest error or deviation its
    /// verdict line names) exceeds this.
    #[arg(long, value_parser = parse_error_bound, allow_negative_numbers = true)]
    pub max_error: Option<f64>,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
    /// Print nothing but errors: the exit status says whether the report passed --max-error
    /// (0 passed, 1 failed, 2 could not be made), and a failing check prints one line on
    /// stderr. Not with --json.
    #[arg(long, short, conflicts_with = "json")]
    pub quiet: bool,
}

impl GateArgs {
    /// How a report with its own `max_error` field names the bound in JSON (`bound_field`).
    pub fn gate<'a>(&self, bound_field: &'a str) -> Gate<'a> {
        Gate {
            json: self.json,
            quiet: self.quiet,
            bound: self.max_error,
            bound_field,
        }
    }
}

/// How a gated report is printed.
pub struct Gate<'a> {
    /// Print one JSON object: the report with the bound (under `bound_field`) and `passed`.
    pub json: bool,
    /// Print nothing but a failure, on stderr.
    pub quiet: bool,
    pub bound: Option<f64>,
    /// The JSON field of the bound (the report may have a `max_error` of its own).
    pub bound_field: &'a str,
}

impl Gate<'_> {
    /// Prints `report` (JSON), or its `text` and the verdict line, or with `quiet` only a
    /// failure naming `subject`; `worst` is the figure the bound gates, `what` its name ("max
    /// error"). Returns whether it passed.
    pub fn print(
        &self,
        report: &impl serde::Serialize,
        text: impl FnOnce() -> String,
        worst: f64,
        what: &str,
        subject: &str,
    ) -> bool {
        let passed = self.bound.is_none_or(|bound| worst <= bound);
        if self.json {
            let mut object = serde_json::to_value(report).expect("a report serialises");
            if let Some(bound) = self.bound {
                object[self.bound_field] = bound.into();
                object["passed"] = passed.into();
            }
            println!("{object}");
        } else if self.quiet {
            if let (false, Some(bound)) = (passed, self.bound) {
                eprintln!("kiln: {subject}: {what} {worst:.2e} exceeds --max-error {bound:e}");
            }
        } else {
            print!("{}", text());
            if let Some(bound) = self.bound {
                println!(
                    "{}: {what} {worst:.2e} {} --max-error {bound:e}",
                    if passed { "PASSED" } else { "FAILED" },
                    if passed { "within" } else { "exceeds" }
                );
            }
        }
        passed
    }
}
