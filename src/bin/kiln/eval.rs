//! `kiln eval`.

mod anisotropic;
mod walk;

use crate::args::{SEE_CONVENTIONS, parse_alpha, parse_mu, parse_roughness, parse_samples};
use crate::fresnel_args::FresnelArgs;
use clap::{Args, ValueEnum};
use kiln::integrate::reference::{ReferenceSettings, reference_albedo, reference_average_albedo};
use kiln::{Fresnel, Masking, Model, Ndf, QmcSettings, Quantity, RoughnessConvention};
use std::time::Instant;

/// How to evaluate: the methods a table is baked by (`kiln bake` picks one per table from
/// --max-error; `eval` does not pick).
pub use kiln::table::Method;

/// What `kiln eval` evaluates.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum EvalQuantity {
    /// Directional albedo E(mu) (needs --mu and a roughness).
    E,
    /// Average albedo E_avg (needs a roughness).
    EAvg,
    /// Average Fresnel reflectance F_avg = 2 * integral of F(mu) mu dmu for the --fresnel model
    /// (per channel; no roughness).
    FAvg,
    /// Energy albedo R + T of a rough dielectric interface at relative index --ior (light
    /// arriving from the side --ior is relative to; give 1/eta for inside), with --mu; the
    /// reference also reports R, T and the radiance albedo R + T / eta^2.
    EDielectric,
    /// Its average 2 * integral of E mu dmu.
    EAvgDielectric,
    /// e_k(mu): the energy (F = 1) that leaves a GGX microsurface after exactly --order k
    /// scattering events, by the microsurface random walk (e_1 is E; the orders sum to 1).
    EOrder,
    /// The directional albedo of the whole GGX microsurface, every order, with the Fresnel
    /// model (--f0/--f90, or --eta/--k) applied at every bounce, by the random walk: the truth
    /// energy compensation stands for.
    EMultiple,
    /// The albedo of the single-scattering BRDF with the Fresnel model plus --compensation
    /// (kulla-conty or turquin), from the reference's E, E_avg, E_F and F_avg: compare with
    /// e-multiple.
    ECompensated,
}

/// Evaluate E or E_avg at one point, or F_avg.
#[derive(Args, Debug)]
#[command(
    long_about = "Evaluate E(mu) or E_avg at one roughness, by QMC (with its standard error) or by \
                  the deterministic reference quadrature (with its error estimate); or F_avg, the \
                  average Fresnel reflectance of a --fresnel model (Schlick's closed form, \
                  otherwise quadrature to 1e-14). With --json, print exactly one JSON object with \
                  the fields value, one_minus_value, std_error, method, samples, seconds and the \
                  inputs; for the reference, std_error is the quadrature's error estimate and \
                  samples its integrand evaluations. For F_avg, value is a number when the model \
                  is the same in every channel and [R, G, B] otherwise; value_rgb is always the \
                  three channels.",
    after_help = SEE_CONVENTIONS
)]
pub struct EvalArgs {
    /// Normal distribution.
    #[arg(long, value_enum, default_value = "ggx")]
    ndf: Ndf,
    /// Smith G2 form.
    #[arg(long, value_enum, default_value = "height-correlated")]
    masking: Masking,
    /// Slope-space roughness alpha, >= 0 (give this or --roughness).
    #[arg(long, value_parser = parse_alpha, conflicts_with = "roughness", allow_negative_numbers = true)]
    alpha: Option<f64>,
    /// Perceptual roughness r in [0, 1], alpha = r^2 (give this or --alpha, which goes to 1000).
    #[arg(long, value_parser = parse_roughness, allow_negative_numbers = true)]
    roughness: Option<f64>,
    /// cos(theta) of the view direction, in [0, 1]; required for --quantity e.
    #[arg(long, value_parser = parse_mu, allow_negative_numbers = true)]
    mu: Option<f64>,
    /// What to evaluate.
    #[arg(long, value_enum, default_value = "e")]
    quantity: EvalQuantity,
    #[command(flatten)]
    fresnel: FresnelArgs,
    #[command(flatten)]
    anisotropy: anisotropic::AnisotropyArgs,
    /// How to evaluate it. `kiln bake` picks its method from --max-error (the reference below
    /// 1e-3, as for its default tables); `eval` uses the one given here.
    #[arg(long, value_enum, default_value = "qmc")]
    method: Method,
    /// For --quantity e-dielectric|e-avg-dielectric: whose albedo. single-scattering: a
    /// refraction that ends on the incident side is lost (what the BSDF evaluates; kiln's
    /// tables); cycles: as Cycles' sampler computed Blender's glass tables (such a refraction
    /// kept, an index within 1e-4 of 1 treated as smooth).
    #[arg(long, value_enum, default_value = "single-scattering")]
    transmission: kiln::model::dielectric::TransmissionConvention,
    /// QMC samples, a power of two (split over the scrambles) [default: 2^19 for e, 2^23 for
    /// e-avg, as `kiln bake` uses].
    #[arg(long, value_parser = parse_samples, allow_negative_numbers = true)]
    samples: Option<u64>,
    /// Independent scrambles, for the standard error: a power of two, 2 to 1024 [default: 8
    /// for QMC, 16 for the walk].
    #[arg(long, allow_negative_numbers = true)]
    scrambles: Option<u32>,
    /// For --quantity e-order: which order k, 1 to 64.
    #[arg(long, allow_negative_numbers = true)]
    order: Option<u64>,
    /// For --quantity e-order|e-multiple: random walks, a power of two (split over the
    /// scrambles) [default: 2^22, a standard error of about 1e-4 at alpha = 1].
    #[arg(long, value_parser = parse_samples, allow_negative_numbers = true)]
    walks: Option<u64>,
    /// For --quantity e-compensated: the compensation whose albedo to compute.
    #[arg(long, value_enum)]
    compensation: Option<kiln::integrate::compensation::Compensation>,
    /// Print nothing on stderr (no estimate, no progress).
    #[arg(long, short)]
    quiet: bool,
    /// Base seed of the scrambles.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
}

pub fn run(args: EvalArgs) -> kiln::Result<()> {
    args.flags_of_their_quantities()?;
    if args.anisotropy.given() {
        return anisotropic::run(&args);
    }
    let fresnel = args.fresnel.model()?;
    if matches!(
        args.quantity,
        EvalQuantity::EOrder | EvalQuantity::EMultiple | EvalQuantity::ECompensated
    ) {
        return multiple_scattering(&args, fresnel);
    }
    let quantity = match args.quantity {
        EvalQuantity::EOrder | EvalQuantity::EMultiple | EvalQuantity::ECompensated => {
            unreachable!("handled above")
        }
        EvalQuantity::FAvg => return fresnel_average(&args, fresnel),
        EvalQuantity::E => Quantity::E,
        EvalQuantity::EAvg => Quantity::EAvg,
        EvalQuantity::EDielectric => Quantity::EDielectric,
        EvalQuantity::EAvgDielectric => Quantity::EAvgDielectric,
    };
    if args.fresnel.given() && quantity == Quantity::EAvg {
        return Err(kiln::Error::InvalidInput(
            "Fresnel-weighted E_avg is not in this version: --fresnel applies to --quantity e \
             (E_F) and f-avg"
                .into(),
        ));
    }
    let model = Model {
        ndf: args.ndf,
        masking: args.masking,
    };
    model.validate()?;
    let Some(alpha) = args.alpha_given()? else {
        return Err(kiln::Error::InvalidInput(format!(
            "--quantity {} needs --alpha A or --roughness R",
            quantity.cli_name()
        )));
    };
    let mu = match (quantity, args.mu) {
        (q, None) if q.has_mu() => {
            return Err(kiln::Error::InvalidInput(format!(
                "--quantity {} needs --mu (cos(theta) in [0, 1])",
                q.cli_name()
            )));
        }
        (q, Some(mu)) if q.has_mu() => Some(mu),
        (q, Some(mu)) => {
            return Err(kiln::Error::InvalidInput(format!(
                "--mu {mu} does not apply to --quantity {}: it is an average over mu (2 * \
                 integral of E(mu) mu dmu); drop --mu, or use --quantity {} for one mu",
                q.cli_name(),
                if q == Quantity::EAvg {
                    "e"
                } else {
                    "e-dielectric"
                }
            )));
        }
        (_, None) => None,
    };
    if quantity.has_ior() {
        let Fresnel::Dielectric { eta } = fresnel else {
            return Err(kiln::Error::InvalidInput(format!(
                "--quantity {} needs the relative index: --ior ETA (e.g. 1.5 for light arriving \
                 from air onto glass, 0.6667 for light arriving from inside)",
                quantity.cli_name()
            )));
        };
        return dielectric(&args, model, eta, alpha, mu);
    }
    if fresnel != Fresnel::None {
        let mu = mu.expect("E has a mu");
        return fresnel_weighted(&args, model, fresnel, alpha, mu);
    }
    let start = Instant::now();
    let evaluated = evaluate(&args, quantity, model, alpha, mu)?;
    print_value(
        &args,
        (quantity, model, alpha, mu),
        evaluated,
        start.elapsed().as_secs_f64(),
    );
    Ok(())
}

/// `E` or `E_avg` at one point by `--method`: (value, 1 - value, error, samples or
/// evaluations, whether the quadrature converged).
fn evaluate(
    args: &EvalArgs,
    quantity: Quantity,
    model: Model,
    alpha: f64,
    mu: Option<f64>,
) -> kiln::Result<(f64, f64, f64, u64, bool)> {
    Ok(match args.method {
        Method::Qmc => {
            let samples = args.samples.unwrap_or(if quantity.has_mu() {
                QmcSettings::DEFAULT_SAMPLES
            } else {
                QmcSettings::average_samples_for(QmcSettings::DEFAULT_SAMPLES)
            });
            let settings = QmcSettings {
                samples,
                scrambles: args.scrambles.unwrap_or(QmcSettings::DEFAULT_SCRAMBLES),
                seed: args.seed,
            };
            settings.validate()?;
            let waiting = args.announce_qmc(quantity, model, samples);
            let e = match mu {
                Some(mu) => kiln::albedo(model, alpha, mu, &settings),
                None => kiln::average_albedo(model, alpha, &settings),
            };
            waiting.finish_and_clear();
            (e.value, e.one_minus_value, e.std_error, e.samples, true)
        }
        Method::Reference => {
            args.no_samples_for_reference()?;
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
    })
}

/// Prints one value of [`evaluate`] (JSON, or a line of text) with what it took.
fn print_value(
    args: &EvalArgs,
    (quantity, model, alpha, mu): (Quantity, Model, f64, Option<f64>),
    (value, one_minus_value, error, samples, converged): (f64, f64, f64, u64, bool),
    seconds: f64,
) {
    let method = args.method.name();
    let symbol = quantity.symbol();
    if args.json {
        let object = serde_json::json!({
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
        print_json(args, object);
    } else {
        let at = mu
            .map(|mu| format!("mu = {}, ", kiln::error::brief(mu)))
            .unwrap_or_default();
        let alpha = kiln::error::brief(alpha);
        let what = match args.method {
            Method::Qmc => format!("{samples} samples"),
            Method::Reference => format!("reference quadrature, {samples} evaluations"),
        };
        println!(
            "{symbol}({at}alpha = {alpha}) = {value:.12} ± {error:.1e} (1 - {symbol} = \
             {one_minus_value:.6e}; {}, {what}, {seconds:.3} s)",
            model
        );
        if !converged {
            eprintln!(
                "kiln: warning: the quadrature did not reach its tolerance; the error estimate is what it reached"
            );
        }
    }
}

/// `kiln eval --quantity f-avg`: `F_avg` per channel for the `--fresnel` model.
fn fresnel_average(args: &EvalArgs, fresnel: Fresnel) -> kiln::Result<()> {
    let irrelevant = crate::args::given(&[
        ("--alpha", args.alpha.is_some()),
        ("--roughness", args.roughness.is_some()),
        ("--mu", args.mu.is_some()),
        ("--samples", args.samples.is_some()),
    ]);
    if !irrelevant.is_empty() {
        return Err(kiln::Error::InvalidInput(format!(
            "F_avg depends on the Fresnel model only: drop {}",
            irrelevant.join(", ")
        )));
    }
    let start = Instant::now();
    let average = fresnel.average_report();
    let seconds = start.elapsed().as_secs_f64();
    let [r, g, b] = average.value;
    let uniform = r == g && g == b;
    if args.json {
        let object = serde_json::json!({
            "quantity": "F_avg",
            "fresnel": fresnel,
            "value": scalar_or_rgb(average.value),
            "value_rgb": [r, g, b],
            "one_minus_value": scalar_or_rgb(average.value.map(|v| 1.0 - v)),
            "std_error": average.error,
            "method": average.method,
            "samples": average.evaluations,
            "seconds": seconds,
            "converged": true,
            "kiln_version": kiln::format::metadata::KILN_VERSION,
        });
        println!("{object}");
    } else {
        let shown = if uniform {
            format!("{r:.10}")
        } else {
            format!("[{r:.10}, {g:.10}, {b:.10}]")
        };
        println!(
            "F_avg({}) = {shown} ± {:.1e} ({}, {} evaluations, {seconds:.3} s)",
            fresnel.name(),
            average.error,
            average.method,
            average.evaluations
        );
    }
    Ok(())
}

/// `kiln eval --quantity e` with a Fresnel model: `E_F(mu) = ∫ F(o.h) f mu_i dω_i` per channel
/// (channels with the same reflectance are computed once).
fn fresnel_weighted(
    args: &EvalArgs,
    model: Model,
    fresnel: Fresnel,
    alpha: f64,
    mu: f64,
) -> kiln::Result<()> {
    use kiln::integrate::albedo::weighted_albedo;
    use kiln::integrate::dielectric::reference_dielectric_albedo;
    use kiln::integrate::reference::reference_weighted_albedo;
    let start = Instant::now();
    let channel = |j: usize| move |c: f64| fresnel.reflectance(c)[j];
    // (value, error, samples, converged) per channel computed: one for a grey model.
    let mut channels: Vec<(f64, f64, u64, bool)> = Vec::new();
    for j in 0..if fresnel.is_grey() { 1 } else { 3 } {
        channels.push(match args.method {
            Method::Qmc => {
                let settings = QmcSettings {
                    samples: args.samples.unwrap_or(QmcSettings::DEFAULT_SAMPLES),
                    scrambles: args.scrambles.unwrap_or(QmcSettings::DEFAULT_SCRAMBLES),
                    seed: args.seed,
                };
                settings.validate()?;
                // Fresnel-weighted integrals run at the split-sum channels' rate.
                let waiting = args.announce_qmc(Quantity::EScale, model, settings.samples);
                let e = weighted_albedo(model, alpha, mu, channel(j), &settings);
                waiting.finish_and_clear();
                (e.value, e.std_error, e.samples, true)
            }
            Method::Reference => {
                args.no_samples_for_reference()?;
                if let Fresnel::Dielectric { eta } = fresnel {
                    // The dielectric quadrature splits at the critical angle, where F has a
                    // square-root kink that misleads the generic rule's error estimate.
                    let r = reference_dielectric_albedo(
                        model,
                        alpha,
                        mu,
                        eta,
                        &ReferenceSettings::default(),
                    );
                    channels.push((r.reflection, r.error, r.evaluations, r.converged));
                    continue;
                }
                let r = reference_weighted_albedo(
                    model,
                    alpha,
                    mu,
                    channel(j),
                    &ReferenceSettings::default(),
                );
                (r.value, r.error, r.evaluations, r.converged)
            }
        });
    }
    let seconds = start.elapsed().as_secs_f64();
    let values: [f64; 3] = std::array::from_fn(|j| channels[j.min(channels.len() - 1)].0);
    let error = kiln::stats::max_or_nan(channels.iter().map(|c| c.1));
    let samples: u64 = channels.iter().map(|c| c.2).sum();
    let converged = channels.iter().all(|c| c.3);
    let uniform = values[0] == values[1] && values[1] == values[2];
    let method = args.method.name();
    if args.json {
        let object = serde_json::json!({
            "quantity": "E_F",
            "ndf": model.ndf.name(),
            "masking": model.masking.name(),
            "fresnel": fresnel,
            "alpha": alpha,
            "roughness": args.roughness,
            "mu": mu,
            "value": scalar_or_rgb(values),
            "value_rgb": values,
            "one_minus_value": scalar_or_rgb(values.map(|v| 1.0 - v)),
            "std_error": error,
            "method": method,
            "samples": samples,
            "seconds": seconds,
            "converged": converged,
            "kiln_version": kiln::format::metadata::KILN_VERSION,
        });
        print_json(args, object);
    } else {
        let shown = if uniform {
            format!("{:.12}", values[0])
        } else {
            format!("[{:.10}, {:.10}, {:.10}]", values[0], values[1], values[2])
        };
        println!(
            "E_F(mu = {}, alpha = {}; {} Fresnel) = {shown} ± {error:.1e} ({}, {method}, \
             {samples} evaluations, {seconds:.3} s)",
            kiln::error::brief(mu),
            kiln::error::brief(alpha),
            fresnel.name(),
            model
        );
    }
    Ok(())
}

/// Prints an eval JSON object, with the QMC settings when QMC computed it.
/// `kiln eval --quantity e-dielectric|e-avg-dielectric --ior ETA`.
fn dielectric(
    args: &EvalArgs,
    model: Model,
    eta: f64,
    alpha: f64,
    mu: Option<f64>,
) -> kiln::Result<()> {
    use kiln::integrate::dielectric::{
        dielectric_albedo_with, dielectric_average_albedo_with, reference_dielectric_albedo_with,
        reference_dielectric_average_albedo_with,
    };
    let convention = args.transmission;
    let start = Instant::now();
    let (value, one_minus_value, error, samples, converged, parts) = match args.method {
        Method::Qmc => {
            let settings = QmcSettings {
                samples: args.samples.unwrap_or(if mu.is_some() {
                    QmcSettings::DEFAULT_SAMPLES
                } else {
                    QmcSettings::average_samples_for(QmcSettings::DEFAULT_SAMPLES)
                }),
                scrambles: args.scrambles.unwrap_or(QmcSettings::DEFAULT_SCRAMBLES),
                seed: args.seed,
            };
            settings.validate()?;
            let waiting = args.announce_qmc(Quantity::EDielectric, model, settings.samples);
            let e = match mu {
                Some(mu) => dielectric_albedo_with(model, alpha, mu, eta, convention, &settings),
                None => dielectric_average_albedo_with(model, alpha, eta, convention, &settings),
            };
            waiting.finish_and_clear();
            (
                e.value,
                e.one_minus_value,
                e.std_error,
                e.samples,
                true,
                None,
            )
        }
        Method::Reference => {
            args.no_samples_for_reference()?;
            let settings = ReferenceSettings::default();
            let r = match mu {
                Some(mu) => {
                    reference_dielectric_albedo_with(model, alpha, mu, eta, convention, &settings)
                }
                None => reference_dielectric_average_albedo_with(
                    model,
                    alpha,
                    eta,
                    convention,
                    &ReferenceSettings {
                        tolerance: kiln::integrate::dielectric::AVERAGE_POINT_TOLERANCE,
                        ..settings
                    },
                ),
            };
            let parts = (r.reflection, r.transmission, r.radiance_albedo(eta));
            (
                r.value(),
                r.one_minus_value,
                r.error,
                r.evaluations,
                r.converged,
                Some(parts),
            )
        }
    };
    let seconds = start.elapsed().as_secs_f64();
    let symbol = if mu.is_some() {
        "E_dielectric"
    } else {
        "E_avg_dielectric"
    };
    let method = args.method.name();
    if args.json {
        let mut object = serde_json::json!({
            "quantity": symbol,
            "ndf": model.ndf.name(),
            "masking": model.masking.name(),
            "eta": eta,
            "alpha": alpha,
            "roughness": args.roughness,
            "mu": mu,
            "value": value,
            "one_minus_value": one_minus_value,
            "convention": "energy albedo R + T (sample weight)",
            "transmission": convention,
            "std_error": error,
            "method": method,
            "samples": samples,
            "seconds": seconds,
            "converged": converged,
            "kiln_version": kiln::format::metadata::KILN_VERSION,
        });
        if let Some((reflection, transmission, radiance)) = parts {
            object["reflection"] = reflection.into();
            object["transmission"] = transmission.into();
            object["radiance_albedo"] = radiance.into();
        }
        print_json(args, object);
    } else {
        println!(
            "{symbol} = {value:.10} (1 - {symbol} = {one_minus_value:.4e}), {} {error:.2e}, \
             {model}, eta {eta}, alpha {alpha}{}",
            if args.method == Method::Qmc {
                "std error"
            } else {
                "error estimate"
            },
            mu.map(|m| format!(", mu {m}")).unwrap_or_default()
        );
        if let Some((reflection, transmission, radiance)) = parts {
            println!(
                "  reflection R = {reflection:.10}, transmission T = {transmission:.10}, \
                 radiance albedo R + T / eta^2 = {radiance:.10}"
            );
        }
    }
    Ok(())
}

fn print_json(args: &EvalArgs, mut object: serde_json::Value) {
    if args.method == Method::Qmc {
        object["estimator"] = "vndf-sobol-owen".into();
        object["scrambles"] = args
            .scrambles
            .unwrap_or(QmcSettings::DEFAULT_SCRAMBLES)
            .into();
        object["seed"] = args.seed.into();
    }
    println!("{object}");
}

/// A number when all three channels agree, `[R, G, B]` otherwise.
fn scalar_or_rgb(values: [f64; 3]) -> serde_json::Value {
    if values[0] == values[1] && values[1] == values[2] {
        values[0].into()
    } else {
        serde_json::json!(values)
    }
}

/// `kiln eval --quantity e-order|e-multiple|e-compensated`.
fn multiple_scattering(args: &EvalArgs, fresnel: Fresnel) -> kiln::Result<()> {
    let model = Model {
        ndf: args.ndf,
        masking: args.masking,
    };
    let (Some(alpha), Some(mu)) = (args.alpha_given()?, args.mu) else {
        return Err(kiln::Error::InvalidInput(format!(
            "--quantity {} needs --mu M and --alpha A (or --roughness R)",
            args.quantity
                .to_possible_value()
                .expect("no skipped variants")
                .get_name()
        )));
    };
    if args.method != Method::Qmc || args.samples.is_some() {
        return Err(kiln::Error::InvalidInput(
            "--method and --samples choose the single-scattering integrator: the walk has              --walks, --scrambles and --seed"
                .into(),
        ));
    }
    let view = walk::View {
        model,
        fresnel,
        alpha,
        mu,
    };
    match args.quantity {
        EvalQuantity::EOrder => {
            if fresnel != Fresnel::None {
                return Err(kiln::Error::InvalidInput(
                    "e_k is the energy of order k with F = 1: drop the Fresnel flags, or use \
                     --quantity e-multiple for the albedo with a Fresnel"
                        .into(),
                ));
            }
            let Some(order) = args.order else {
                return Err(kiln::Error::InvalidInput(
                    "--quantity e-order needs --order K (1 to 64)".into(),
                ));
            };
            walk::multiple_scattering(args, view, Some(order))
        }
        EvalQuantity::EMultiple => {
            if matches!(fresnel, Fresnel::Dielectric { .. }) {
                return Err(kiln::Error::InvalidInput(
                    "the walk is a conductor's (every bounce reflects): a dielectric \
                     interface, which also refracts, is not in this version; give Schlick's \
                     --f0 (and --f90) or a conductor's --eta and --k"
                        .into(),
                ));
            }
            walk::multiple_scattering(args, view, None)
        }
        EvalQuantity::ECompensated => {
            if matches!(fresnel, Fresnel::Dielectric { .. }) {
                return Err(kiln::Error::InvalidInput(
                    "e-compensated is a conductor's albedo: give Schlick's --f0 (and --f90) or \
                     a conductor's --eta and --k"
                        .into(),
                ));
            }
            walk::compensated(args, view)
        }
        _ => unreachable!("called for the walk's quantities"),
    }
}

impl EvalArgs {
    /// `--alpha`, or `--roughness` as alpha; none given is `None`.
    fn alpha_given(&self) -> kiln::Result<Option<f64>> {
        Ok(match (self.alpha, self.roughness) {
            (Some(alpha), _) => Some(alpha),
            (None, Some(r)) => Some(RoughnessConvention::Perceptual.to_alpha(r)),
            (None, None) => None,
        })
    }

    /// `--order`, `--walks` and `--compensation` belong to the walk's quantities.
    fn flags_of_their_quantities(&self) -> kiln::Result<()> {
        let misplaced = |flag: &str, wanted: &str| {
            Err(kiln::Error::InvalidInput(format!(
                "{flag} applies to --quantity {wanted} only"
            )))
        };
        if self.order.is_some() && self.quantity != EvalQuantity::EOrder {
            return misplaced("--order", "e-order");
        }
        if self.walks.is_some()
            && !matches!(
                self.quantity,
                EvalQuantity::EOrder | EvalQuantity::EMultiple
            )
        {
            return misplaced("--walks", "e-order or e-multiple");
        }
        if self.compensation.is_some() && self.quantity != EvalQuantity::ECompensated {
            return misplaced("--compensation", "e-compensated");
        }
        Ok(())
    }

    /// Announces a QMC estimate of `samples` samples that will take more than a few seconds
    /// ([`crate::announce_cost`], at [`kiln::integrate::cost::qmc_seconds_per_point`]'s kernel rates) and
    /// returns a spinner with the time spent, cleared when the estimate is in (hidden with
    /// --quiet or --json, or when the estimate is short).
    fn announce_qmc(
        &self,
        quantity: Quantity,
        model: kiln::Model,
        samples: u64,
    ) -> indicatif::ProgressBar {
        let quiet = self.quiet || self.json;
        let seconds = kiln::integrate::cost::qmc_seconds_per_point(quantity, model, samples);
        crate::announce_cost(seconds, quiet);
        let threads = rayon::current_num_threads() as f64;
        crate::spinner(quiet || seconds / threads <= 2.0, "integrating")
    }

    /// `--samples` is QMC's: an error with `--method reference`.
    fn no_samples_for_reference(&self) -> kiln::Result<()> {
        if self.samples.is_some() {
            return Err(kiln::Error::InvalidInput(
                "--samples sets the QMC sample count; the reference quadrature (--method \
                 reference) chooses its own evaluations"
                    .into(),
            ));
        }
        Ok(())
    }
}
