//! The `kiln` command: parses, calls the library, prints. No maths here.

mod anisotropic;
mod args;
mod bake;
mod compensation;
mod eval;
mod external;
mod fit;
mod fresnel_args;
mod furnace;
mod gate;
mod legacy;
mod merge;
mod plan;
mod plot;
mod report;
mod study;
mod verify;
mod verify_anisotropy;
mod verify_fit;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// Bakes the lookup tables energy-conserving microfacet materials need (Kulla-Conty E, E_avg).
#[derive(Parser, Debug)]
#[command(
    name = "kiln",
    version,
    about,
    arg_required_else_help = true,
    after_help = "Start with `kiln bake` (the default tables into tables/), `kiln bake --preset \
                  NAME` (an engine's own file) or `kiln verify FILE`; `kiln help COMMAND` \
                  explains each. `kiln --help` adds the conventions every table follows.",
    after_long_help = args::CONVENTIONS
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

// The variants carry no doc comments: a variant's would replace its command's `about` and
// `long_about` (each `*Args` struct's doc comment and long description).
#[derive(Subcommand, Debug)]
enum Command {
    Bake(bake::BakeArgs),
    Eval(eval::EvalArgs),
    Plan(plan::PlanArgs),
    Verify(verify::VerifyArgs),
    Furnace(furnace::FurnaceArgs),
    VerifyFit(verify_fit::VerifyFitArgs),
    VerifyAnisotropy(verify_anisotropy::VerifyAnisotropyArgs),
    Study(study::StudyArgs),
    Merge(merge::MergeArgs),
    Fit(fit::FitArgs),
    Compensation(compensation::CompensationArgs),
    Anisotropic(anisotropic::AnisotropicArgs),
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

/// A spinner with the time spent, for work whose progress cannot be counted (one QMC
/// estimate); hidden if `quiet`.
pub fn spinner(quiet: bool, what: &str) -> indicatif::ProgressBar {
    if quiet {
        return indicatif::ProgressBar::hidden();
    }
    let bar = indicatif::ProgressBar::new_spinner();
    bar.set_style(
        indicatif::ProgressStyle::with_template(&format!("{{spinner}} {what} {{elapsed}}"))
            .expect("valid template"),
    );
    bar.enable_steady_tick(std::time::Duration::from_millis(200));
    bar
}

/// A `.toml` file given where no positional argument is taken (`kiln bake scene.toml`).
fn stray_scene_file(e: &clap::Error) -> Option<String> {
    use clap::error::{ContextKind, ContextValue};
    if e.kind() != clap::error::ErrorKind::UnknownArgument {
        return None;
    }
    match e.get(ContextKind::InvalidArg) {
        Some(ContextValue::String(arg)) if arg.ends_with(".toml") && !arg.starts_with('-') => {
            Some(arg.clone())
        }
        _ => None,
    }
}

/// A point's flag (`--roughness`, `--mu`, `--alpha`, `--eta`) given to `kiln bake`, which takes
/// none: the user wants `kiln eval`.
fn point_flag_on_bake(e: &clap::Error, args: &[std::ffi::OsString]) -> Option<String> {
    use clap::error::{ContextKind, ContextValue};
    if e.kind() != clap::error::ErrorKind::UnknownArgument
        || args.get(1).and_then(|a| a.to_str()) != Some("bake")
    {
        return None;
    }
    match e.get(ContextKind::InvalidArg) {
        Some(ContextValue::String(arg)) => {
            let flag = arg.split('=').next().unwrap_or(arg);
            ["--roughness", "--mu", "--alpha", "--eta"]
                .contains(&flag)
                .then(|| flag.to_string())
        }
        _ => None,
    }
}

/// A conflict with a group of flags (`--scene` with the flags a scene sets itself), said with
/// the flags given rather than clap's list of the whole group.
fn conflict_as_given(e: &clap::Error, args: &[std::ffi::OsString]) -> Option<String> {
    use clap::error::{ContextKind, ContextValue};
    if e.kind() != clap::error::ErrorKind::ArgumentConflict {
        return None;
    }
    let Some(ContextValue::String(invalid)) = e.get(ContextKind::InvalidArg) else {
        return None;
    };
    let prior = match e.get(ContextKind::PriorArg)? {
        ContextValue::Strings(all) => all.clone(),
        ContextValue::String(one) => vec![one.clone()],
        _ => return None,
    };
    let given = |shown: &String| {
        let flag = shown.split([' ', '=']).next().unwrap_or(shown);
        args.iter().filter_map(|a| a.to_str()).any(|a| {
            a == flag
                || a.strip_prefix(flag)
                    .is_some_and(|rest| rest.starts_with('='))
        })
    };
    let named: Vec<String> = prior
        .iter()
        .filter(|p| given(p))
        .map(|p| format!("'{p}'"))
        .collect();
    (named.len() < prior.len() && !named.is_empty()).then(|| {
        format!(
            "the argument '{invalid}' cannot be used with {}",
            named.join(", ")
        )
    })
}

/// `0.4 s`, `12 s`, `3.5 min`, `1.2 h`.
pub fn human_seconds(seconds: f64) -> String {
    if seconds < 10.0 {
        format!("{seconds:.1} s")
    } else if seconds < 120.0 {
        format!("{seconds:.0} s")
    } else if seconds < 7200.0 {
        format!("{:.1} min", seconds / 60.0)
    } else {
        format!("{:.1} h", seconds / 3600.0)
    }
}

/// Says on stderr, before a bake of more than a few seconds starts, how long it should take
/// (on any stderr: a log or CI output needs it as much as a terminal); nothing with `quiet`.
pub fn announce_cost(core_seconds: f64, quiet: bool) {
    announce_seconds(core_seconds / rayon::current_num_threads() as f64, quiet);
}

/// [`announce_cost`] of work estimated in seconds of wall time (some of it on one thread).
pub fn announce_seconds(seconds: f64, quiet: bool) {
    let threads = rayon::current_num_threads();
    if !quiet && seconds > 5.0 {
        eprintln!(
            "kiln: estimated {} on {threads} threads (a rough figure; interrupting writes \
             nothing)",
            human_seconds(seconds)
        );
    }
}

fn main() -> ExitCode {
    // A reader that stops reading (`kiln verify ... | head`) ends kiln quietly, as it ends any
    // Unix tool: the default SIGPIPE action, which Rust's runtime replaces with "ignore" (and
    // println! would then panic on the broken pipe).
    #[cfg(unix)]
    // SAFETY: setting a signal's disposition to SIG_DFL at start-up, before any thread exists,
    // installs no handler and touches no memory.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    let (args, note) = legacy::rewrite(std::env::args_os().collect());
    let quiet = args.iter().any(|a| a == "-q" || a == "--quiet");
    if let (Some(note), false) = (note, quiet) {
        eprintln!("kiln: {note}");
    }
    let cli = match Cli::try_parse_from(&args) {
        Ok(cli) => cli,
        Err(e) => {
            use clap::error::ErrorKind;
            if matches!(
                e.kind(),
                ErrorKind::DisplayHelp
                    | ErrorKind::DisplayVersion
                    | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
            ) {
                e.exit();
            }
            // One line: what was wrong, and the allowed values (clap's first paragraph, joined),
            // then clap's tips ("a similar argument exists") and the usage line.
            let rendered = e.render().to_string();
            let lines: Vec<&str> = rendered.lines().map(str::trim).collect();
            let message: Vec<&str> = lines
                .iter()
                .copied()
                .take_while(|line| !line.is_empty())
                .collect();
            let said = conflict_as_given(&e, &args)
                .unwrap_or_else(|| message.join(" ").trim_start_matches("error: ").to_string());
            eprintln!("kiln: {said}");
            let point = point_flag_on_bake(&e, &args);
            for line in &lines[message.len()..] {
                // clap's look-alike (`--roughness-axis` for `--roughness`) is not what someone
                // who names a point wants: the tip below replaces it.
                if point.is_some() && (line.starts_with("tip:") || line.starts_with("Usage:")) {
                    continue;
                }
                if line.starts_with("tip:") || line.starts_with("Usage:") {
                    eprintln!("  {line}");
                }
            }
            if let Some(flag) = point {
                eprintln!(
                    "  tip: kiln bake writes whole tables; to compute one point, use kiln eval \
                     {flag} ... (e.g. kiln eval --mu 0.5 --roughness 0.5); to choose the table's \
                     axes, see kiln bake --help (--size, --roughness-axis, --mu-axis)"
                );
            }
            if let Some(scene) = stray_scene_file(&e) {
                eprintln!("  tip: name a scene file with --scene {scene}");
            }
            return ExitCode::from(2);
        }
    };
    let result = match cli.command {
        Command::Bake(args) => bake::run(args).map(|()| true),
        Command::Eval(args) => eval::run(args).map(|()| true),
        Command::Plan(args) => plan::run(args).map(|()| true),
        Command::Verify(args) => verify::run(args),
        Command::Furnace(args) => furnace::run(args),
        Command::VerifyFit(args) => verify_fit::run(args),
        Command::VerifyAnisotropy(args) => verify_anisotropy::run(args),
        Command::Study(args) => study::run(args).map(|()| true),
        Command::Merge(args) => merge::run(args).map(|()| true),
        Command::Fit(args) => fit::run(args).map(|()| true),
        Command::Compensation(args) => compensation::run(args).map(|()| true),
        Command::Anisotropic(args) => anisotropic::run(args),
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
