//! The `kiln` command: parses, calls the library, prints. No maths here.

mod args;
mod bake;
mod eval;
mod fresnel_args;
mod plan;
mod plot;
mod study;
mod verify;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// Bakes the lookup tables energy-conserving microfacet materials need (Kulla-Conty E, E_avg).
#[derive(Parser, Debug)]
#[command(name = "kiln", version, about, after_help = args::CONVENTIONS)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Bake E(mu, roughness) and E_avg(roughness) tables and write them to a directory.
    Bake(bake::BakeArgs),
    /// Evaluate E or E_avg at one point (QMC or the deterministic reference), or F_avg.
    Eval(eval::EvalArgs),
    /// Show the minimal set of tables a scene file's materials need.
    Plan(plan::PlanArgs),
    /// Audit a table (kiln's or an engine's) against the deterministic reference.
    Verify(verify::VerifyArgs),
    /// Measure what accuracy costs: error against time per estimator, lookup error against size.
    Study(study::StudyArgs),
}

/// A progress bar on stderr, drawn only when stderr is a terminal; hidden with `quiet`.
pub fn progress_bar(quiet: bool, total: u64, what: &str) -> indicatif::ProgressBar {
    if quiet {
        return indicatif::ProgressBar::hidden();
    }
    let bar = indicatif::ProgressBar::new(total);
    bar.set_style(
        indicatif::ProgressStyle::with_template(&format!(
            "{{spinner}} {what} [{{bar:40}}] {{percent:>3}}% eta {{eta}}"
        ))
        .expect("valid template")
        .progress_chars("=> "),
    );
    bar
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            use clap::error::ErrorKind;
            if matches!(e.kind(), ErrorKind::DisplayHelp | ErrorKind::DisplayVersion) {
                e.exit();
            }
            // One line: what was wrong, and the allowed values (clap's first paragraph, joined).
            let rendered = e.render().to_string();
            let message: Vec<&str> = rendered
                .lines()
                .map(str::trim)
                .take_while(|line| !line.is_empty())
                .collect();
            eprintln!("kiln: {}", message.join(" ").trim_start_matches("error: "));
            return ExitCode::from(2);
        }
    };
    let result = match cli.command {
        Command::Bake(args) => bake::run(args).map(|()| true),
        Command::Eval(args) => eval::run(args).map(|()| true),
        Command::Plan(args) => plan::run(args).map(|()| true),
        Command::Verify(args) => verify::run(args),
        Command::Study(args) => study::run(args).map(|()| true),
    };
    match result {
        Ok(true) => ExitCode::SUCCESS,
        // A check that ran and failed (verify --max-error).
        Ok(false) => ExitCode::from(1),
        Err(e) => {
            eprintln!("kiln: {e}");
            // Bad input and unusable output directories are the caller's to fix: status 2.
            let usage = e.is_usage() || matches!(e, kiln::Error::Io { .. });
            ExitCode::from(if usage { 2 } else { 1 })
        }
    }
}
