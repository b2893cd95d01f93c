//! `kiln eval`.

use crate::args::{CONVENTIONS, parse_mu, parse_roughness, parse_samples};
use clap::{Args, ValueEnum};
use kiln::integrate::reference::{ReferenceSettings, reference_albedo, reference_average_albedo};
use kiln::{Masking, Model, Ndf, QmcSettings, Quantity, RoughnessConvention};
use std::time::Instant;

/// How to evaluate.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Method {
    /// Quasi-Monte Carlo (VNDF sampling, Owen-scrambled Sobol), as `kiln bake` uses.
    Qmc,
    /// The deterministic reference: nested adaptive Gauss-Kronrod quadrature, error <= 1e-10.
    Reference,
}

/// Evaluate E or E_avg at one point.
#[derive(Args, Debug)]
#[command(
    long_about = "Evaluate E(mu) or E_avg at one roughness, by QMC (with its standard error) or by \
                  the deterministic reference quadrature (with its error estimate). With --json, \
                  print exactly one JSON object with the fields value, one_minus_value, std_error, \
                  method, samples, seconds and the inputs; for the reference, std_error is the \
                  quadrature's error estimate and samples its integrand evaluations.",
    after_help = CONVENTIONS
)]
pub struct EvalArgs {
    /// Normal distribution.
    #[arg(long, value_enum, default_value = "ggx")]
    ndf: Ndf,
    /// Smith G2 form.
    #[arg(long, value_enum, default_value = "height-correlated")]
    masking: Masking,
    /// Slope-space roughness alpha, >= 0 (give this or --roughness).
    #[arg(long, value_parser = parse_roughness, required_unless_present = "roughness", conflicts_with = "roughness", allow_negative_numbers = true)]
    alpha: Option<f64>,
    /// Perceptual roughness r >= 0, alpha = r^2 (give this or --alpha).
    #[arg(long, value_parser = parse_roughness, allow_negative_numbers = true)]
    roughness: Option<f64>,
    /// cos(theta) of the view direction, in [0, 1]; required for --quantity e.
    #[arg(long, value_parser = parse_mu, allow_negative_numbers = true)]
    mu: Option<f64>,
    /// What to evaluate.
    #[arg(long, value_enum, default_value = "e")]
    quantity: Quantity,
    /// How to evaluate it.
    #[arg(long, value_enum, default_value = "qmc")]
    method: Method,
    /// QMC samples, a power of two (split over the scrambles) [default: 2^19 for e, 2^23 for
    /// e-avg, as `kiln bake` uses].
    #[arg(long, value_parser = parse_samples, allow_negative_numbers = true)]
    samples: Option<u64>,
    /// Independent scrambles, for the standard error: a power of two, 2 to 1024.
    #[arg(long, default_value_t = QmcSettings::DEFAULT_SCRAMBLES, allow_negative_numbers = true)]
    scrambles: u32,
    /// Base seed of the scrambles.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
}

pub fn run(args: EvalArgs) -> kiln::Result<()> {
    let model = Model {
        ndf: args.ndf,
        masking: args.masking,
    };
    let alpha = match (args.alpha, args.roughness) {
        (Some(alpha), _) => alpha,
        (None, Some(r)) => RoughnessConvention::Perceptual.to_alpha(r),
        (None, None) => unreachable!("clap requires one of them"),
    };
    let mu = match (args.quantity, args.mu) {
        (Quantity::E, None) => {
            return Err(kiln::Error::InvalidInput(
                "--quantity e needs --mu (cos(theta) in [0, 1])".into(),
            ));
        }
        (Quantity::E, Some(mu)) => Some(mu),
        (Quantity::EAvg, _) => None,
    };
    let start = Instant::now();
    // (value, one_minus_value, error, samples or evaluations, converged)
    let (value, one_minus_value, error, samples, converged) = match args.method {
        Method::Qmc => {
            let samples = args.samples.unwrap_or(match args.quantity {
                Quantity::E => QmcSettings::DEFAULT_SAMPLES,
                Quantity::EAvg => 16 * QmcSettings::DEFAULT_SAMPLES,
            });
            let settings = QmcSettings {
                samples,
                scrambles: args.scrambles,
                seed: args.seed,
            };
            settings.validate().map_err(kiln::Error::InvalidInput)?;
            let e = match mu {
                Some(mu) => kiln::albedo(model, alpha, mu, &settings),
                None => kiln::average_albedo(model, alpha, &settings),
            };
            (e.value, e.one_minus_value, e.std_error, e.samples, true)
        }
        Method::Reference => {
            if args.samples.is_some() {
                return Err(kiln::Error::InvalidInput(
                    "--samples sets the QMC sample count; the reference quadrature (--method \
                     reference) chooses its own evaluations"
                        .into(),
                ));
            }
            let settings = ReferenceSettings::default();
            let r = match mu {
                Some(mu) => reference_albedo(model, alpha, mu, &settings),
                None => reference_average_albedo(model, alpha, &settings),
            };
            (
                r.value,
                r.one_minus_value,
                r.error,
                r.evaluations,
                r.converged,
            )
        }
    };
    let seconds = start.elapsed().as_secs_f64();
    let method = match args.method {
        Method::Qmc => "qmc",
        Method::Reference => "reference",
    };
    let symbol = args.quantity.symbol();
    if args.json {
        let mut object = serde_json::json!({
            "quantity": symbol,
            "ndf": model.ndf.name(),
            "masking": model.masking.name(),
            "alpha": alpha,
            "roughness": args.roughness,
            "mu": mu,
            "value": value,
            "one_minus_value": one_minus_value,
            "std_error": error,
            "method": method,
            "samples": samples,
            "seconds": seconds,
            "converged": converged,
            "kiln_version": kiln::format::metadata::KILN_VERSION,
        });
        if args.method == Method::Qmc {
            object["estimator"] = "vndf-sobol-owen".into();
            object["scrambles"] = args.scrambles.into();
            object["seed"] = args.seed.into();
        }
        println!("{object}");
    } else {
        let at = mu.map(|mu| format!("mu = {mu}, ")).unwrap_or_default();
        let what = match args.method {
            Method::Qmc => format!("{samples} samples"),
            Method::Reference => format!("reference quadrature, {samples} evaluations"),
        };
        println!(
            "{symbol}({at}alpha = {alpha}) = {value:.12} ± {error:.1e} (1 - {symbol} = \
             {one_minus_value:.6e}; {}, {what}, {seconds:.3} s)",
            model.ndf
        );
        if !converged {
            eprintln!(
                "kiln: warning: the quadrature did not reach its tolerance; the error estimate is what it reached"
            );
        }
    }
    Ok(())
}
