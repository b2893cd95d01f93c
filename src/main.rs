//! The `kiln` command: parses, calls the library, prints. No maths here.

use clap::{Args, Parser, Subcommand, ValueEnum};
use kiln::format::{self, Format, Precision};
use kiln::{BakeOptions, Grid, Masking, Model, MuMapping, Ndf, QmcSettings, RoughnessConvention};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

const CONVENTIONS: &str = "\
Conventions:
  mu         cos(theta) of the view direction, in [0, 1] (0 = grazing, 1 = normal incidence).
  roughness  either perceptual r with alpha = r^2 (Burley, Filament, Cycles; the default axis)
             or alpha itself (the slope-space width; Mitsuba). Every file says which.
  grid       'centers': sample i sits at texel centre t = (i + 0.5) / N, right for a GPU texture
             sampled with bilinear filtering and clamp-to-edge. 'nodes': t = i / (N - 1), the
             first and last samples on the axis ends (Cycles); a GPU lookup must remap
             t' = (t (N - 1) + 0.5) / N.
  mu axis    'linear': mu = t. 'sqrt': mu = t^2 (look up at t = sqrt(mu)), denser near grazing.
  layout     row-major, roughness rows (slow), mu columns (fast); as an image x = mu, y = roughness.
  E          directional albedo of the single-scattering BRDF with F = 1; E_avg = 2 ∫ E(mu) mu dmu.
             one_minus_E is stored beside E, estimated directly: use it when E is near 1,
             especially in half floats.";

/// Bakes the lookup tables energy-conserving microfacet materials need (Kulla-Conty E, E_avg).
#[derive(Parser, Debug)]
#[command(name = "kiln", version, about, after_help = CONVENTIONS)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Bake E(mu, roughness) and E_avg(roughness) tables and write them to a directory.
    #[command(
        long_about = "Bake E(mu, roughness) and E_avg(roughness) tables by quasi-Monte Carlo \
                      (visible-normal sampling, Owen-scrambled Sobol points) and write them as \
                      EXR, raw binary, Rust source, JSON and PNG. Each texel carries its standard \
                      error, measured from independent scrambles; the metadata of every file \
                      states the model, axes, grid, samples, seed, error and the command that \
                      reproduces it. Output is byte-identical for any thread count.",
        after_help = CONVENTIONS
    )]
    Bake(BakeArgs),
    /// Evaluate E or E_avg at one point.
    #[command(
        long_about = "Evaluate E(mu) or E_avg at one roughness, with its standard error. With \
                      --json, print exactly one JSON object with the fields value, \
                      one_minus_value, std_error, method, samples, seconds and the inputs.",
        after_help = CONVENTIONS
    )]
    Eval(EvalArgs),
}

#[derive(Args, Debug)]
struct BakeArgs {
    /// Normal distributions to bake, comma-separated: ggx,beckmann for both (Beckmann's
    /// sampling is about 20 times slower than GGX's).
    #[arg(long, value_enum, value_delimiter = ',', default_value = "ggx")]
    ndf: Vec<NdfArg>,
    /// Smith G2 forms to bake, comma-separated.
    #[arg(
        long,
        value_enum,
        value_delimiter = ',',
        default_value = "height-correlated"
    )]
    masking: Vec<MaskingArg>,
    /// Samples per axis: E is SIZE x SIZE, E_avg has SIZE entries. 2 to 4096.
    #[arg(long, default_value_t = BakeOptions::DEFAULT_SIZE, value_parser = parse_size, allow_negative_numbers = true)]
    size: usize,
    /// QMC samples per E texel, a power of two (split over the scrambles).
    #[arg(long, default_value_t = QmcSettings::DEFAULT_SAMPLES, value_parser = parse_samples, allow_negative_numbers = true)]
    samples: u64,
    /// QMC samples per E_avg entry, a power of two [default: 16 x --samples].
    #[arg(long, value_parser = parse_samples, allow_negative_numbers = true)]
    avg_samples: Option<u64>,
    /// Independent scrambles per estimate, for the standard error: a power of two, 2 to 1024.
    #[arg(long, default_value_t = QmcSettings::DEFAULT_SCRAMBLES, allow_negative_numbers = true)]
    scrambles: u32,
    /// Base seed of the scrambles.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Output directory, created if missing.
    #[arg(long, default_value = "tables")]
    out: PathBuf,
    /// Output formats, comma-separated.
    #[arg(
        long,
        value_enum,
        value_delimiter = ',',
        default_value = "exr,bin,rs,json,png"
    )]
    format: Vec<FormatArg>,
    /// Storage precision of the value channels in EXR and binary files (std_error stays f32).
    #[arg(long, value_enum, default_value = "f32")]
    precision: PrecisionArg,
    #[command(flatten)]
    axes: AxisArgs,
    /// No progress bar and no summary.
    #[arg(long, short)]
    quiet: bool,
}

#[derive(Args, Debug)]
struct AxisArgs {
    /// Roughness axis: perceptual r (alpha = r^2) or alpha.
    #[arg(long, value_enum, default_value = "r")]
    roughness_axis: RoughnessArg,
    /// Spacing of the mu axis: linear (mu = t) or sqrt (mu = t^2).
    #[arg(long, value_enum, default_value = "linear")]
    mu_axis: MuAxisArg,
    /// Where samples sit: texel centres (i + 0.5)/N or nodes i/(N - 1).
    #[arg(long, value_enum, default_value = "centers")]
    grid: GridArg,
}

#[derive(Args, Debug)]
struct EvalArgs {
    /// Normal distribution.
    #[arg(long, value_enum, default_value = "ggx")]
    ndf: NdfArg,
    /// Smith G2 form.
    #[arg(long, value_enum, default_value = "height-correlated")]
    masking: MaskingArg,
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
    quantity: QuantityArg,
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

#[derive(Clone, Copy, Debug, ValueEnum)]
enum NdfArg {
    Ggx,
    Beckmann,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
enum MaskingArg {
    HeightCorrelated,
    Separable,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
enum FormatArg {
    Exr,
    Bin,
    Rs,
    Json,
    Png,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
enum PrecisionArg {
    F32,
    F16,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
enum RoughnessArg {
    /// Perceptual roughness, alpha = r^2.
    R,
    /// Slope-space roughness.
    Alpha,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
enum MuAxisArg {
    Linear,
    Sqrt,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
enum GridArg {
    Centers,
    Nodes,
}

#[derive(Clone, Copy, Debug, ValueEnum, PartialEq)]
enum QuantityArg {
    /// Directional albedo E(mu).
    E,
    /// Average albedo E_avg.
    EAvg,
}

impl From<NdfArg> for Ndf {
    fn from(a: NdfArg) -> Self {
        match a {
            NdfArg::Ggx => Ndf::Ggx,
            NdfArg::Beckmann => Ndf::Beckmann,
        }
    }
}

impl From<MaskingArg> for Masking {
    fn from(a: MaskingArg) -> Self {
        match a {
            MaskingArg::HeightCorrelated => Masking::HeightCorrelated,
            MaskingArg::Separable => Masking::Separable,
        }
    }
}

fn parse_number(text: &str) -> Result<f64, String> {
    let value: f64 = text
        .trim()
        .parse()
        .map_err(|_| format!("'{text}' is not a number"))?;
    if value.is_finite() {
        Ok(value)
    } else {
        Err(format!("{text} is not a finite number"))
    }
}

fn parse_mu(text: &str) -> Result<f64, String> {
    let mu = parse_number(text)?;
    if (0.0..=1.0).contains(&mu) {
        Ok(mu)
    } else {
        Err(format!(
            "mu is cos(theta) and must be in [0, 1] (got {text})"
        ))
    }
}

fn parse_roughness(text: &str) -> Result<f64, String> {
    let value = parse_number(text)?;
    if (0.0..=1e3).contains(&value) {
        Ok(value)
    } else {
        Err(format!("roughness must be in [0, 1000] (got {text})"))
    }
}

fn parse_size(text: &str) -> Result<usize, String> {
    let size: i64 = text
        .trim()
        .parse()
        .map_err(|_| format!("'{text}' is not a whole number"))?;
    if (2..=BakeOptions::MAX_SIZE as i64).contains(&size) {
        Ok(size as usize)
    } else {
        Err(format!(
            "size must be between 2 and {} (got {text})",
            BakeOptions::MAX_SIZE
        ))
    }
}

fn parse_samples(text: &str) -> Result<u64, String> {
    let n: i128 = text
        .trim()
        .parse()
        .map_err(|_| format!("'{text}' is not a whole number"))?;
    if (2..=1 << 42).contains(&n) && (n as u64).is_power_of_two() {
        Ok(n as u64)
    } else {
        Err(format!(
            "samples must be a power of two between 2 and 2^42 (got {text})"
        ))
    }
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
        Command::Bake(args) => bake(args),
        Command::Eval(args) => eval(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("kiln: {e}");
            // Bad input and unusable output directories are the caller's to fix: status 2.
            let usage = e.is_usage() || matches!(e, kiln::Error::Io { .. });
            ExitCode::from(if usage { 2 } else { 1 })
        }
    }
}

fn bake(args: BakeArgs) -> kiln::Result<()> {
    let options = BakeOptions {
        ndfs: args.ndf.iter().map(|&n| n.into()).collect(),
        maskings: args.masking.iter().map(|&m| m.into()).collect(),
        size: args.size,
        samples: args.samples,
        average_samples: args.avg_samples.unwrap_or(16 * args.samples),
        scrambles: args.scrambles,
        seed: args.seed,
        roughness_convention: match args.axes.roughness_axis {
            RoughnessArg::R => RoughnessConvention::Perceptual,
            RoughnessArg::Alpha => RoughnessConvention::Alpha,
        },
        mu_mapping: match args.axes.mu_axis {
            MuAxisArg::Linear => MuMapping::Linear,
            MuAxisArg::Sqrt => MuMapping::Sqrt,
        },
        grid: match args.axes.grid {
            GridArg::Centers => Grid::Centers,
            GridArg::Nodes => Grid::Nodes,
        },
    };
    options.validate()?;
    let formats: Vec<Format> = {
        let mut f: Vec<Format> = args
            .format
            .iter()
            .map(|f| match f {
                FormatArg::Exr => Format::Exr,
                FormatArg::Bin => Format::Bin,
                FormatArg::Rs => Format::Rs,
                FormatArg::Json => Format::Json,
                FormatArg::Png => Format::Png,
            })
            .collect();
        f.sort();
        f.dedup();
        f
    };
    let precision = match args.precision {
        PrecisionArg::F32 => Precision::F32,
        PrecisionArg::F16 => Precision::F16,
    };
    // Fail on an unusable output directory now, not after minutes of integration.
    format::check_output_dir(&args.out)?;

    let bar = if args.quiet {
        indicatif::ProgressBar::hidden()
    } else {
        let bar = indicatif::ProgressBar::new(options.total_samples());
        bar.set_style(
            indicatif::ProgressStyle::with_template(
                "{spinner} integrating [{bar:40}] {percent:>3}% {msg} eta {eta}",
            )
            .expect("valid template")
            .progress_chars("=> "),
        );
        bar
    };
    let start = Instant::now();
    let tables = options.bake(&|samples| bar.inc(samples))?;
    bar.finish_and_clear();
    let seconds = start.elapsed().as_secs_f64();
    let written = format::write_tables(&args.out, &tables, &formats, precision)?;
    if !args.quiet {
        for table in &tables {
            println!(
                "{:<32} {:>9} max std error {:.1e}",
                table.spec.id(),
                table
                    .spec
                    .shape()
                    .iter()
                    .map(|n| n.to_string())
                    .collect::<Vec<_>>()
                    .join("x"),
                table.max_std_error()
            );
        }
        println!(
            "baked {} tables in {seconds:.1} s; wrote {} files to {}",
            tables.len(),
            written.len(),
            args.out.display()
        );
    }
    Ok(())
}

fn eval(args: EvalArgs) -> kiln::Result<()> {
    let model = Model {
        ndf: args.ndf.into(),
        masking: args.masking.into(),
    };
    let alpha = match (args.alpha, args.roughness) {
        (Some(alpha), _) => alpha,
        (None, Some(r)) => RoughnessConvention::Perceptual.to_alpha(r),
        (None, None) => unreachable!("clap requires one of them"),
    };
    let samples = args.samples.unwrap_or(match args.quantity {
        QuantityArg::E => QmcSettings::DEFAULT_SAMPLES,
        QuantityArg::EAvg => 16 * QmcSettings::DEFAULT_SAMPLES,
    });
    let settings = QmcSettings {
        samples,
        scrambles: args.scrambles,
        seed: args.seed,
    };
    settings.validate().map_err(kiln::Error::InvalidInput)?;
    let start = Instant::now();
    let estimate = match args.quantity {
        QuantityArg::E => {
            let mu = args.mu.ok_or_else(|| {
                kiln::Error::InvalidInput("--quantity e needs --mu (cos(theta) in [0, 1])".into())
            })?;
            kiln::albedo(model, alpha, mu, &settings)
        }
        QuantityArg::EAvg => kiln::average_albedo(model, alpha, &settings),
    };
    let seconds = start.elapsed().as_secs_f64();
    let quantity = match args.quantity {
        QuantityArg::E => "E",
        QuantityArg::EAvg => "E_avg",
    };
    if args.json {
        let object = serde_json::json!({
            "quantity": quantity,
            "ndf": model.ndf.name(),
            "masking": model.masking.name(),
            "alpha": alpha,
            "roughness": args.roughness,
            "mu": if args.quantity == QuantityArg::E { args.mu } else { None },
            "value": estimate.value,
            "one_minus_value": estimate.one_minus_value,
            "std_error": estimate.std_error,
            "method": "qmc",
            "estimator": "vndf-sobol-owen",
            "samples": estimate.samples,
            "scrambles": args.scrambles,
            "seed": args.seed,
            "seconds": seconds,
            "kiln_version": kiln::format::metadata::KILN_VERSION,
        });
        println!("{object}");
    } else {
        let at = match args.mu {
            Some(mu) if args.quantity == QuantityArg::E => format!("mu = {mu}, "),
            _ => String::new(),
        };
        println!(
            "{quantity}({at}alpha = {alpha}) = {:.10} ± {:.1e} (1 - {quantity} = {:.6e}; {} {} samples in {seconds:.3} s)",
            estimate.value,
            estimate.std_error,
            estimate.one_minus_value,
            model.ndf,
            estimate.samples
        );
    }
    Ok(())
}
