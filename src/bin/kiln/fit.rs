//! `kiln fit`: a texture-free polynomial fit of `E` with its audited maximum error
//! ([`kiln::fit::polynomial`], [`kiln::fit::emit`]).

use clap::Args;
use kiln::fit::emit::{FitFormat, description, emit, function_name};
use kiln::fit::polynomial::{Degrees, PolynomialFit, fit_to, truth_points};
use kiln::verify::fit::{FitAuditSettings, audit_polynomial};
use kiln::{Masking, Model, Ndf};
use std::path::PathBuf;

/// Fit E(mu, r) without a texture, with its audited maximum error, as shader code
///
/// A polynomial in kiln's adaptive coordinates (t = (mu (1 + 4
/// alpha) / (mu + 4 alpha))^0.4 and r, alpha = r^2) chosen in the maximum norm against kiln's
/// reference, written as a formula file and as WGSL, GLSL, HLSL, Rust and C functions. The
/// maximum error printed and written beside each fit is the audit's (`kiln verify --fit` of the
/// formula file written), over mu in [0, 1] and r in [0, 1], both ends included. `--sweep`
/// prints what each size costs instead. See docs/fits.md.
#[derive(Args, Debug)]
pub struct FitArgs {
    /// Degrees in t and in r, as T,R: (T + 1) (R + 1) coefficients, each 1 to 12.
    #[arg(long, default_value = "5,4", value_parser = parse_degrees)]
    degrees: Degrees,
    /// Print the maximum error of fits of several sizes (12 to 64 coefficients) instead of
    /// writing one.
    #[arg(long, conflicts_with_all = ["degrees", "out", "format"])]
    sweep: bool,
    /// With --sweep: draw the maximum error against the coefficient count into FILE.svg or
    /// FILE.png.
    #[arg(long, requires = "sweep", value_name = "FILE")]
    plot: Option<PathBuf>,
    /// Microfacet distribution [default: ggx].
    #[arg(long, value_enum)]
    ndf: Option<Ndf>,
    /// Masking-shadowing form [default: height-correlated].
    #[arg(long, value_enum)]
    masking: Option<Masking>,
    /// Output directory, created if missing [default: fits].
    #[arg(long)]
    out: Option<PathBuf>,
    /// Files to write, comma-separated [default: all: toml (the formula file), wgsl, glsl,
    /// hlsl, rs, h].
    #[arg(long, value_enum, value_delimiter = ',')]
    format: Option<Vec<FitFormat>>,
    /// One JSON object instead of text.
    #[arg(long, conflicts_with = "quiet")]
    json: bool,
    /// No progress bar and no summary.
    #[arg(long, short)]
    quiet: bool,
}

fn parse_degrees(text: &str) -> Result<Degrees, String> {
    let bad = || format!("'{text}': give the degrees in t and r as T,R, each 1 to 12 (5,4)");
    let (t, r) = text.split_once(',').ok_or_else(bad)?;
    let parse = |s: &str| {
        s.trim()
            .parse::<usize>()
            .ok()
            .filter(|d| (1..=12).contains(d))
    };
    Ok(Degrees {
        t: parse(t).ok_or_else(bad)?,
        r: parse(r).ok_or_else(bad)?,
    })
}

/// The shapes `--sweep` tries, by coefficient count.
const SWEEP: [(usize, usize); 9] = [
    (3, 2),
    (3, 3),
    (4, 3),
    (5, 3),
    (5, 4),
    (5, 5),
    (7, 4),
    (7, 5),
    (7, 7),
];

/// A fit and its audit: the formula file's text and the audited maximum.
struct Audited {
    fit: PolynomialFit,
    max_error: f64,
    worst: (f64, f64),
}

fn audited(fit: PolynomialFit, model: Model) -> Audited {
    let settings = FitAuditSettings {
        model,
        ..FitAuditSettings::default()
    };
    let report = audit_polynomial(&fit, &settings, &|| {});
    let e = &report.quantities[0];
    Audited {
        fit,
        max_error: e.max_error,
        worst: (e.worst.mu, e.worst.r),
    }
}

pub fn run(args: FitArgs) -> kiln::Result<()> {
    let model = Model {
        ndf: args.ndf.unwrap_or(Ndf::Ggx),
        masking: args.masking.unwrap_or(Masking::HeightCorrelated),
    };
    model.validate().map_err(kiln::Error::InvalidInput)?;
    // A bad --plot or --out is refused before the reference is computed.
    let svg = crate::verify::plot_kind_of(args.plot.as_deref())?;
    let out = args.out.clone().unwrap_or_else(|| PathBuf::from("fits"));
    if !args.sweep {
        kiln::format::check_output_dir(&out)?;
    }
    let quiet = args.quiet || args.json;
    let bar = crate::progress_bar(quiet, 0, "reference");
    let truth = truth_points(model, &|| bar.inc(1));
    bar.finish_and_clear();
    if args.sweep {
        let mut fits = Vec::new();
        for (t, r) in SWEEP {
            let a = audited(fit_to(model, Degrees { t, r }, &truth), model);
            if !quiet {
                println!(
                    "{:>3} coefficients (degrees {t}, {r}): max error {:.2e} at mu = {:.6}, r = {:.6}",
                    a.fit.degrees.coefficients(),
                    a.max_error,
                    a.worst.0,
                    a.worst.1
                );
            }
            fits.push(a);
        }
        if let (Some(svg), Some(path)) = (svg, &args.plot) {
            let points: Vec<(usize, f64)> = fits
                .iter()
                .map(|a| (a.fit.degrees.coefficients(), a.max_error))
                .collect();
            crate::verify::write_plot(
                path,
                svg,
                crate::plot::fit_sweep_plot(&model.to_string(), &points),
            )?;
        }
        if args.json {
            let rows: Vec<serde_json::Value> = fits
                .iter()
                .map(|a| {
                    serde_json::json!({
                        "degrees": [a.fit.degrees.t, a.fit.degrees.r],
                        "coefficients": a.fit.degrees.coefficients(),
                        "max_error": a.max_error,
                        "worst": {"mu": a.worst.0, "r": a.worst.1},
                    })
                })
                .collect();
            println!(
                "{}",
                serde_json::json!({"model": model.to_string(), "fits": rows})
            );
        }
        return Ok(());
    }
    let a = audited(fit_to(model, args.degrees, &truth), model);
    let command = format!(
        "kiln fit --ndf {} --masking {} --degrees {},{}",
        model.ndf, model.masking, args.degrees.t, args.degrees.r
    );
    let text = description(&a.fit, a.max_error, &command);
    let mut formats = args.format.unwrap_or_else(|| FitFormat::ALL.to_vec());
    formats.sort();
    formats.dedup();
    let name = function_name(&a.fit);
    let files: Vec<(String, Vec<u8>)> = formats
        .iter()
        .map(|&f| {
            (
                format!("{name}.{}", f.extension()),
                emit(&a.fit, f, &text).into_bytes(),
            )
        })
        .collect();
    let written = kiln::format::write_files(&out, &files)?;
    if args.json {
        println!(
            "{}",
            serde_json::json!({
                "name": name,
                "model": model.to_string(),
                "degrees": [a.fit.degrees.t, a.fit.degrees.r],
                "coefficients": a.fit.coefficients,
                "max_error": a.max_error,
                "worst": {"mu": a.worst.0, "r": a.worst.1},
                "files": written,
            })
        );
    } else if !args.quiet {
        println!(
            "{name}: {} coefficients, max error {:.2e} at mu = {:.6}, r = {:.6} (the audit of \
             {}/{name}.toml)",
            a.fit.degrees.coefficients(),
            a.max_error,
            a.worst.0,
            a.worst.1,
            out.display()
        );
        println!("wrote {} files to {}", written.len(), out.display());
    }
    Ok(())
}
