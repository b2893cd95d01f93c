//! `kiln study`.

use crate::plot;
use clap::Args;
use kiln::format;
use kiln::study::estimators::Estimator;
use kiln::study::{self, Reach, StudyReport, StudySettings, TARGETS};
use kiln::{Masking, Model, Ndf};
use std::path::PathBuf;

/// Measure what accuracy costs: every estimator's error against time, and lookup error against
/// table size.
#[derive(Args, Debug)]
#[command(
    long_about = "Measure what accuracy costs, on this machine. Every estimator (plain \
                  Monte Carlo with uniform and with cosine-weighted hemisphere directions, NDF \
                  sampling with Sobol points, visible-normal sampling with random and with Sobol \
                  points (kiln's default), and the deterministic quadrature at tolerances 1e-2 \
                  down) fills the same E table at increasing sample counts; each run's wall time \
                  (all cores) and its max and RMS error at the table's nodes against the \
                  reference go to DIR/study.csv and DIR/study.json, and error against time is \
                  plotted to DIR/study.svg and DIR/study.png with the Pareto front marked. Then \
                  reference-filled tables of increasing size, for each mu axis mapping, are \
                  audited as `kiln verify` does (DIR/lookup.csv, lookup.svg, lookup.png), so you \
                  can pick the smallest table that meets a target. Ends with the time each method \
                  needs to reach 1e-4, 1e-6 and 1e-8. The full run takes several minutes; \
                  --quick takes under one on 2 cores."
)]
pub struct StudyArgs {
    /// A quick look: a 16 x 16 table, up to 2^14 samples (2^16 for kiln's estimator),
    /// tolerances down to 1e-8, lookup tables up to 32 x 32.
    #[arg(long)]
    quick: bool,
    /// Directory for study.csv, study.json, study.svg, study.png and lookup.*.
    #[arg(long, default_value = "study")]
    out: PathBuf,
    /// Normal distribution.
    #[arg(long, value_enum, default_value = "ggx")]
    ndf: Ndf,
    /// Smith G2 form.
    #[arg(long, value_enum, default_value = "height-correlated")]
    masking: Masking,
    /// Instead: how cost grows with the work. E, E_avg and the split-sum pair baked at 16 to
    /// 256 per axis, a dielectric E table at 8 to 32 per axis (--quick: smaller), all to 1e-6
    /// (--quick: 1e-5); each bake's wall time, node error and lookup error at fixed points go
    /// to DIR/scaling.csv and scaling.json, time against texel count (log-log, with the fitted
    /// exponent) to scaling.svg and scaling.png. A few minutes on 2 cores.
    #[arg(long)]
    scaling: bool,
    /// No progress bar.
    #[arg(long, short)]
    quiet: bool,
}

/// `kiln study --scaling`.
fn run_scaling(args: &StudyArgs, model: Model) -> kiln::Result<()> {
    use kiln::study::scaling::{self, ScalingSettings};
    let settings = if args.quick {
        ScalingSettings::quick(model)
    } else {
        ScalingSettings::full(model)
    };
    format::check_output_dir(&args.out)?;
    let bar = crate::progress_bar(args.quiet, settings.work(), "baking");
    let report = scaling::run(&settings, &|units| bar.inc(units))?;
    bar.finish_and_clear();
    let (svg, png) = plot::scaling_plot(&report).map_err(|e| kiln::Error::Format {
        path: args.out.clone(),
        message: format!("plotting: {e}"),
    })?;
    let json = serde_json::to_string_pretty(&report).expect("a report serialises");
    let files = vec![
        (
            "scaling.csv".to_string(),
            scaling::scaling_csv(&report).into_bytes(),
        ),
        ("scaling.json".to_string(), json.into_bytes()),
        ("scaling.svg".to_string(), svg.into_bytes()),
        ("scaling.png".to_string(), png),
    ];
    let written = format::write_files(&args.out, &files)?;
    println!(
        "{} {}, every table to {:.0e}, {} threads",
        report.ndf, report.masking, report.max_error, report.threads
    );
    println!(
        "{:<14} {:>5} {:>8} {:>9} {:>10} {:>10}",
        "case", "size", "texels", "seconds", "node max", "lookup max"
    );
    for r in &report.runs {
        println!(
            "{:<14} {:>5} {:>8} {:>9.3} {:>10.2e} {:>10.2e}",
            r.case, r.size, r.texels, r.seconds, r.node_max_error, r.lookup_max_error
        );
    }
    for fit in &report.fits {
        println!(
            "{:<14} time ~ texels^{:.2} (sizes {:?})",
            fit.case, fit.exponent, fit.sizes
        );
    }
    if !args.quiet {
        for path in written {
            eprintln!("wrote {}", path.display());
        }
    }
    Ok(())
}

fn reach_text(reach: &Reach) -> String {
    match (reach.seconds, reach.samples) {
        (Some(s), Some(n)) => format!("{s:.3} s (n={n})"),
        _ => "not reached".to_string(),
    }
}

/// The one-line comparison the README quotes: kiln's default against cosine-weighted MC at 1e-6.
fn headline(report: &StudyReport) -> String {
    let at = |method: Estimator| {
        report
            .summary
            .iter()
            .find(|s| s.method == method.name())
            .and_then(|s| s.reaches.iter().find(|r| r.max_error == 1e-6))
            .and_then(|r| r.seconds)
    };
    let most_samples = report
        .runs
        .iter()
        .filter(|r| r.method == Estimator::CosineRandom.name())
        .map(|r| r.samples)
        .max()
        .unwrap_or(0);
    match (at(Estimator::VndfSobol), at(Estimator::CosineRandom)) {
        (Some(kiln), Some(cosine)) => format!(
            "to 1e-6: vndf-sobol {kiln:.3} s, cosine-random {cosine:.3} s ({:.0}x faster)",
            cosine / kiln
        ),
        (Some(kiln), None) => format!(
            "to 1e-6: vndf-sobol {kiln:.3} s; cosine-random does not get there within {most_samples} samples per texel"
        ),
        (None, _) => "vndf-sobol did not reach 1e-6 at these sample counts".to_string(),
    }
}

pub fn run(args: StudyArgs) -> kiln::Result<()> {
    let model = Model {
        ndf: args.ndf,
        masking: args.masking,
    };
    if args.scaling {
        return run_scaling(&args, model);
    }
    let settings = if args.quick {
        StudySettings::quick(model)
    } else {
        StudySettings::full(model)
    };
    format::check_output_dir(&args.out)?;
    let bar = crate::progress_bar(args.quiet, settings.work(), "studying");
    let report = study::run(&settings, &|units| bar.inc(units));
    bar.finish_and_clear();

    let plot_error = |e: String| kiln::Error::Format {
        path: args.out.clone(),
        message: format!("plotting: {e}"),
    };
    let (cost_svg, cost_png) = plot::cost_plot(&report).map_err(plot_error)?;
    let (lookup_svg, lookup_png) = plot::lookup_plot(&report).map_err(plot_error)?;
    let json = serde_json::to_string_pretty(&report).expect("a report serialises");
    let files = vec![
        (
            "study.csv".to_string(),
            study::runs_csv(&report).into_bytes(),
        ),
        ("study.json".to_string(), json.into_bytes()),
        ("study.svg".to_string(), cost_svg.into_bytes()),
        ("study.png".to_string(), cost_png),
        (
            "lookup.csv".to_string(),
            study::lookup_csv(&report).into_bytes(),
        ),
        ("lookup.svg".to_string(), lookup_svg.into_bytes()),
        ("lookup.png".to_string(), lookup_png),
    ];
    let written = format::write_files(&args.out, &files)?;

    println!(
        "{} {} E, {} x {} table with kiln's default axes, {} threads",
        report.ndf, report.masking, report.size, report.size, report.threads
    );
    println!(
        "{:<16} {:>22} {:>22} {:>22} {:>12}",
        "time to max error",
        format!("{:.0e}", TARGETS[0]),
        format!("{:.0e}", TARGETS[1]),
        format!("{:.0e}", TARGETS[2]),
        "error ~"
    );
    for summary in &report.summary {
        let cells: Vec<String> = summary.reaches.iter().map(reach_text).collect();
        // The measured exponent of max error ~ N^-p over the method's runs.
        let rate = summary
            .convergence_exponent
            .map_or_else(|| "-".to_string(), |p| format!("N^-{p:.2}"));
        println!(
            "{:<16} {:>22} {:>22} {:>22} {:>12}",
            summary.method, cells[0], cells[1], cells[2], rate
        );
    }
    println!("{}", headline(&report));
    for run in &report.lookup {
        if run.size == 32 {
            println!(
                "lookup error at 32 x 32, mu axis {:<8}: max {:.2e}, rms {:.2e}",
                run.mapping, run.max_error, run.rms_error
            );
        }
    }
    if !args.quiet {
        for path in written {
            eprintln!("wrote {}", path.display());
        }
    }
    Ok(())
}
