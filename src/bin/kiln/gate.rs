//! A report gated by `--max-error`: how the audits that can fail print their verdict.

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
