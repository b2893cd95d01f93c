//! `kiln fit`: a texture-free polynomial or rational fit of `E` with its audited maximum error
//! ([`kiln::fit::polynomial`], [`kiln::fit::rational`], [`kiln::fit::emit`]).

use clap::Args;
use kiln::fit::emit::{FitFormat, FitText, MadeFit, emit};
use kiln::fit::polynomial::{Degrees, fit_to, truth_points};
use kiln::fit::rational::{RationalShape, coordinates_of};
use kiln::verify::fit::{FitAuditSettings, audit_emitted};
use kiln::{Masking, Model, Ndf};
use std::path::PathBuf;

/// Fit E(mu, r) without a texture, with its audited maximum error, as shader code
///
/// A polynomial in kiln's adaptive coordinates (t = (mu (1 + 4 alpha) / (mu + 4 alpha))^0.4
/// and r, alpha = r^2), or a rational 1 - t^2 P / Q in coordinates of the same kind (t = (mu
/// (1 + alpha) / (mu + alpha))^0.3 and r^3.2), chosen in the maximum norm against kiln's
/// reference, written as a formula file and as WGSL, GLSL, HLSL, Rust and C functions. The
/// maximum error printed and written beside each fit is the audit's (`kiln verify-fit` of the
/// formula file written), over mu in [0, 1] and r in [0, 1], both ends included. `--sweep`
/// prints what each size costs instead. See docs/fits.md.
#[derive(Args, Debug)]
pub struct FitArgs {
    /// The fit's shape. T,R: a polynomial of degree T in t and R in r, (T + 1) (R + 1)
    /// coefficients. PT,PR/QT,QR: the rational 1 - t^2 P / Q, P of degrees PT, PR and Q of
    /// degrees QT, QR (in t and r^3.2), (PT + 1) (PR + 1) + (QT + 1) (QR + 1) - 1
    /// coefficients; 3,3/3,3 is 31 coefficients within 1e-3. PT+PR/QT,QR: P additive, A(t) +
    /// B(r) without cross terms, PT + PR + 1 coefficients; 2+1/2,2 is 12 coefficients within
    /// 1e-2. Each degree 1 to 12 (R, PR, QR from 0).
    #[arg(long, default_value = "5,4", value_parser = parse_shape)]
    degrees: Shape,
    /// Print the maximum error of fits of several sizes, polynomial (12 to 64 coefficients)
    /// and rational (7 to 31), instead of writing one.
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

/// What `--degrees` asks for.
#[derive(Clone, Copy, Debug)]
pub enum Shape {
    Polynomial(Degrees),
    Rational(RationalShape),
}

fn parse_shape(text: &str) -> Result<Shape, String> {
    let bad = || {
        format!(
            "'{text}': give the degrees in t and r as T,R (a polynomial, 5,4) or as \
             PT,PR/QT,QR (the rational 1 - t^2 P / Q, 3,3/3,3; PT+PR/QT,QR for an additive P \
             without cross terms, 2+1/2,2), each 1 to 12 in t and 0 to 12 in r (1 to 12 for a \
             polynomial)"
        )
    };
    let degrees = |part: &str, lowest_r: usize| {
        let (t, r) = part.split_once(',').or_else(|| part.split_once('+'))?;
        let parse = |s: &str, lowest: usize| {
            s.trim()
                .parse::<usize>()
                .ok()
                .filter(|d| (lowest..=12).contains(d))
        };
        Some(Degrees {
            t: parse(t, 1)?,
            r: parse(r, lowest_r)?,
        })
    };
    match text.split_once('/') {
        None if text.contains('+') => Err(bad()),
        None => degrees(text, 1).map(Shape::Polynomial).ok_or_else(bad),
        Some((p, q)) if !q.contains('+') => Ok(Shape::Rational(RationalShape {
            numerator: degrees(p, 0).ok_or_else(bad)?,
            denominator: degrees(q, 0).ok_or_else(bad)?,
            additive: p.contains('+'),
        })),
        Some(_) => Err(bad()),
    }
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

/// The rational shape of P's and Q's degrees, P additive or not.
const fn rational(p: (usize, usize), q: (usize, usize), additive: bool) -> RationalShape {
    RationalShape {
        numerator: Degrees { t: p.0, r: p.1 },
        denominator: Degrees { t: q.0, r: q.1 },
        additive,
    }
}

/// The rational shapes `--sweep` tries.
const RATIONAL_SWEEP: [RationalShape; 6] = [
    rational((1, 1), (1, 1), false),
    rational((1, 1), (2, 2), false),
    rational((2, 1), (2, 2), true),
    rational((2, 2), (2, 2), false),
    rational((3, 3), (2, 2), false),
    rational((3, 3), (3, 3), false),
];

/// A fit and its audit: the formula file's text and the audited maximum.
struct Audited {
    fit: MadeFit,
    max_error: f64,
    worst: (f64, f64),
}

/// Makes the fit of `shape` against `truth` (the polynomial fit's points).
fn make(
    model: Model,
    shape: Shape,
    truth: &[((f64, f64), f64)],
    quiet: bool,
) -> kiln::Result<MadeFit> {
    Ok(match shape {
        Shape::Polynomial(degrees) => MadeFit::Polynomial(fit_to(model, degrees, truth)),
        Shape::Rational(shape) => {
            let bar = crate::progress_bar(quiet, 0, "rational fit steps");
            let fit =
                kiln::fit::rational::fit_to(model, shape, &coordinates_of(truth), &|| bar.inc(1));
            bar.finish_and_clear();
            MadeFit::Rational(fit.map_err(|e| {
                kiln::Error::InvalidInput(format!(
                    "the rational fit's linear program failed ({e}); a smaller shape may \
                     succeed, and this is worth reporting"
                ))
            })?)
        }
    })
}

fn audited(fit: MadeFit, model: Model) -> Audited {
    let settings = FitAuditSettings {
        model,
        ..FitAuditSettings::default()
    };
    let report = audit_emitted(&fit, &settings, &|| {});
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
    model.validate()?;
    // A bad --plot or --out is refused before the reference is computed.
    let svg = crate::report::plot_kind_of(args.plot.as_deref())?;
    let out = args.out.clone().unwrap_or_else(|| PathBuf::from("fits"));
    if !args.sweep {
        kiln::format::check_output_dir(&out)?;
    }
    let quiet = args.quiet || args.json;
    let shapes: Vec<Shape> = if args.sweep {
        SWEEP
            .iter()
            .map(|&(t, r)| Shape::Polynomial(Degrees { t, r }))
            .chain(RATIONAL_SWEEP.iter().copied().map(Shape::Rational))
            .collect()
    } else {
        vec![args.degrees]
    };
    let rationals: Vec<RationalShape> = shapes
        .iter()
        .filter_map(|s| match s {
            Shape::Rational(shape) => Some(*shape),
            Shape::Polynomial(_) => None,
        })
        .collect();
    let polynomials = shapes.len() - rationals.len();
    let threads = rayon::current_num_threads() as f64;
    crate::announce_seconds(
        kiln::verify::fit::fits_seconds(model, polynomials, &rationals, threads),
        quiet,
    );
    let bar = crate::progress_bar(
        quiet,
        kiln::fit::polynomial::truth_point_count() as u64,
        "reference",
    );
    let truth = truth_points(model, &|| bar.inc(1));
    bar.finish_and_clear();
    if args.sweep {
        let mut fits = Vec::new();
        for shape in shapes {
            let a = audited(make(model, shape, &truth, quiet)?, model);
            if !quiet {
                let kind = match a.fit {
                    MadeFit::Polynomial(_) => "polynomial",
                    MadeFit::Rational(_) => "rational",
                };
                println!(
                    "{:>3} coefficients ({kind} {}): max error {:.2e} at mu = {:.6}, r = {:.6}",
                    a.fit.coefficients(),
                    a.fit.degrees_text(),
                    a.max_error,
                    a.worst.0,
                    a.worst.1
                );
            }
            fits.push(a);
        }
        if let (Some(svg), Some(path)) = (svg, &args.plot) {
            let points = |rational: bool| -> Vec<(usize, f64)> {
                fits.iter()
                    .filter(|a| matches!(a.fit, MadeFit::Rational(_)) == rational)
                    .map(|a| (a.fit.coefficients(), a.max_error))
                    .collect()
            };
            crate::report::write_plot(
                path,
                svg,
                crate::plot::fit_sweep_plot(&model.to_string(), &points(false), &points(true)),
            )?;
        }
        if args.json {
            let rows: Vec<serde_json::Value> = fits
                .iter()
                .map(|a| {
                    serde_json::json!({
                        "degrees": a.fit.degrees_text(),
                        "coefficients": a.fit.coefficients(),
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
    let a = audited(make(model, args.degrees, &truth, quiet)?, model);
    let command = format!(
        "kiln fit --ndf {} --masking {} --degrees {}",
        model.ndf,
        model.masking,
        a.fit.degrees_text()
    );
    let text = a.fit.description(a.max_error, &command);
    let mut formats = args.format.unwrap_or_else(|| FitFormat::ALL.to_vec());
    formats.sort();
    formats.dedup();
    let name = a.fit.function_name();
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
                "degrees": a.fit.degrees_text(),
                "coefficients": coefficients_json(&a.fit),
                "max_error": a.max_error,
                "worst": {"mu": a.worst.0, "r": a.worst.1},
                "files": written,
            })
        );
    } else if !args.quiet {
        println!(
            "{name}: {} coefficients, max error {:.2e} at mu = {:.6}, r = {:.6} (the audit of \
             {}/{name}.toml)",
            a.fit.coefficients(),
            a.max_error,
            a.worst.0,
            a.worst.1,
            out.display()
        );
        println!("wrote {} files to {}", written.len(), out.display());
    }
    Ok(())
}

/// The fit's coefficients in `--json`: the polynomial's list, or the rational's `P` and `Q`.
fn coefficients_json(fit: &MadeFit) -> serde_json::Value {
    match fit {
        MadeFit::Polynomial(fit) => serde_json::json!(fit.coefficients),
        MadeFit::Rational(fit) => {
            serde_json::json!({"numerator": fit.numerator, "denominator": fit.denominator})
        }
    }
}
