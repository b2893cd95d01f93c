//! `kiln bake`.

use crate::args::{SEE_CONVENTIONS, parse_samples, parse_size};
use crate::fresnel_args::FresnelArgs;
use clap::Args;
use kiln::format::replace::Replace;
use kiln::format::{self, Format, Precision};
use kiln::{
    BakeOptions, Grid, IorMapping, Masking, Method, MuMapping, Ndf, QmcSettings, Quantity,
    RoughnessConvention, RoughnessSpacing,
};
use std::path::PathBuf;
use std::time::Instant;

/// Bake E(mu, roughness) and E_avg(roughness) tables and write them to a directory.
#[derive(Args, Debug)]
#[command(
    long_about = "Bake E(mu, roughness) and E_avg(roughness) tables (and on request split-sum, \
                  dielectric and F_avg(eta) tables: see --quantity) and write them as EXR, \
                  raw binary, Rust source, JSON and PNG. By default to a max error of 1e-7: \
                  kiln picks the cheapest method that meets --max-error (the deterministic \
                  quadrature below 1e-3, quasi-Monte Carlo with visible-normal sampling and \
                  Owen-scrambled Sobol points above) and checks a sample of texels against its \
                  reference. --method qmc --samples N bakes by QMC with a standard error per \
                  texel from independent scrambles. The metadata of every file states the model, \
                  axes, grid, method, error and the command that reproduces it. Output is \
                  byte-identical for any thread count.",
    after_help = SEE_CONVENTIONS,
    // What a scene file or a preset sets for itself: given with --scene or --preset, an error.
    group(clap::ArgGroup::new("table_spec").multiple(true).args([
        "ndf", "masking", "quantity", "size", "samples", "avg_samples", "scrambles", "seed",
        "format", "precision", "roughness_axis", "roughness_spacing", "mu_axis", "grid",
        "ior_size", "ior_axis", "ior_max", "transmission", "method", "no_reference_check",
        "fresnel", "f0", "f90", "ior", "eta", "k",
    ])),
    // A method named (or its samples): with --max-error, which picks the method, an error.
    group(clap::ArgGroup::new("explicit_method").multiple(true).args([
        "method", "samples", "avg_samples", "no_reference_check",
    ]))
)]
pub struct BakeArgs {
    /// Normal distributions to bake, comma-separated: ggx,beckmann for both (Beckmann's
    /// sampling is about 20 times slower than GGX's).
    #[arg(long, value_enum, value_delimiter = ',', default_value = "ggx")]
    ndf: Vec<Ndf>,
    /// Smith G2 forms to bake, comma-separated.
    #[arg(
        long,
        value_enum,
        value_delimiter = ',',
        default_value = "height-correlated"
    )]
    masking: Vec<Masking>,
    /// Tables to bake per model, comma-separated: e (E), e-avg (E_avg), and the split-sum
    /// channels e-scale (integral of (1 - Fc) f mu_i) and e-bias (integral of Fc f mu_i),
    /// Fc = (1 - o.h)^5: Schlick's E_F = F0 * E_scale + F90 * E_bias. The multiscatter layout
    /// of Filament and Godot is e-bias with e. Dielectric (glass) tables over (eta, roughness,
    /// mu): e-dielectric and e-dielectric-inside (energy albedo R + T for light arriving from
    /// outside, relative index eta, and from inside, 1 / eta), e-avg-dielectric and
    /// e-avg-dielectric-inside over (eta, roughness), and f-avg, the exact dielectric F_avg(eta).
    /// e-f: the Fresnel-weighted albedo E_F = integral of F(o.h) f mu_i for the model the
    /// Fresnel flags name (one channel: one value per parameter). f-ms-norm: the
    /// lookup-consistent normalisation of the Kulla-Conty lobe, (1 - average of the E lookup)
    /// / r, derived from e [default: e,e-avg,f-ms-norm, or e-f when a Fresnel flag is given].
    #[arg(long, value_enum, value_delimiter = ',')]
    quantity: Option<Vec<Quantity>>,
    #[command(flatten)]
    fresnel: FresnelArgs,
    /// Samples per axis: E is SIZE x SIZE, E_avg has SIZE entries. 2 to 4096.
    #[arg(long, default_value_t = BakeOptions::DEFAULT_SIZE, value_parser = parse_size, allow_negative_numbers = true)]
    size: usize,
    /// Samples on the IOR axis of the dielectric tables and f-avg (their roughness and mu
    /// axes have --size samples; Cycles' glass tables are 16 x 16 x 16). 2 to 4096
    /// [default: 16]. Only with a table over the IOR.
    #[arg(long, value_parser = parse_size, allow_negative_numbers = true)]
    ior_size: Option<usize>,
    /// Layout of the tables over the IOR, on [1, --ior-max]. glass: kiln's glass layout for the
    /// dielectric tables, whose IOR and mu coordinates follow the layers near eta = 1 (the IOR
    /// coordinate tied to roughness, the mu coordinate to roughness and the IOR; the eta = 1
    /// slice holds the limit eta -> 1+); f-avg keeps cycles. The
    /// product grids: cycles (linear in sqrt((eta - 1) / (eta + 1)), Cycles' glass tables; their
    /// names get -ior-cycles) or linear, with --mu-axis. The axis lists eta >= 1; inside tables
    /// are computed at 1 / eta [default: glass].
    #[arg(long, value_enum)]
    ior_axis: Option<IorMapping>,
    /// The top of the IOR axis, above 1 (Unreal's glass table goes to 3; diamond is 2.42)
    /// [default: 3].
    #[arg(long, allow_negative_numbers = true)]
    ior_max: Option<f64>,
    /// How the dielectric tables count a refraction that ends on the incident side of the
    /// surface: single-scattering (lost, as the BSDF evaluates it; kiln's default) or cycles
    /// (kept, and an index within 1e-4 of 1 smooth, as Cycles' sampler computed Blender's glass
    /// tables). Recorded in the tables' metadata and names.
    #[arg(
        long,
        value_enum,
        default_value = "single-scattering",
        hide_possible_values = true
    )]
    transmission: kiln::model::dielectric::TransmissionConvention,
    /// QMC samples per E texel, a power of two from --scrambles to 2^32 x --scrambles (split
    /// over the scrambles); implies --method qmc [default: 2^19].
    #[arg(long, value_parser = parse_samples, allow_negative_numbers = true)]
    samples: Option<u64>,
    /// QMC samples per E_avg entry, a power of two in the same range; implies --method qmc
    /// [default: 16 x --samples, at most 2^32 x --scrambles].
    #[arg(long, value_parser = parse_samples, allow_negative_numbers = true)]
    avg_samples: Option<u64>,
    /// QMC: independent scrambles per estimate, for the standard error: a power of two, 2 to
    /// 1024 [default: 8].
    #[arg(long, allow_negative_numbers = true)]
    scrambles: Option<u32>,
    /// QMC: base seed of the scrambles [default: 0].
    #[arg(long)]
    seed: Option<u64>,
    /// What the texels are: lookup-fit (chosen so that the bilinear lookup, the way a GPU
    /// samples the file, is closest to the quantity everywhere: about half the lookup error,
    /// nodes off by as much; the metadata's lookup_fit says what the fit measured) or nodes
    /// (each the quantity at its node, exact to --max-error: for a renderer that reads nodes,
    /// or its own interpolation). The glass tables (over the IOR) are fitted only when asked,
    /// at about ten times the bake's cost (E_avg_dielectric's 16 x 16 lookup 1.21e-3 -> 5.8e-4).
    /// With --preset, the engine's tables in its layout. See docs/accuracy.md [default:
    /// lookup-fit on the balanced mu axis (E, E_avg, f_ms_norm) up to --size 128, nodes on the
    /// others, beyond and over the IOR; named -nodes or -lookup-fit where it differs].
    #[arg(long, value_enum)]
    texels: Option<kiln::table::Texels>,
    /// Output directory, created if missing.
    /// [default: tables, or the scene's output.dir]
    #[arg(long)]
    out: Option<PathBuf>,
    /// Bake what a scene file's materials need (see `kiln plan`), reusing unchanged tables from
    /// the cache in OUT/.kiln-cache; the scene's [output] sets formats, precision and max_error.
    #[arg(long, conflicts_with_all = ["table_spec", "max_error", "texels"])]
    scene: Option<PathBuf>,
    /// Bake an engine's table in that engine's own layout, to drop in for its file: cycles
    /// (shader.tables: table_ggx_E, table_ggx_Eavg and the four glass arrays, in Cycles'
    /// transmission convention, to 1e-5 unless --max-error is given), bevy (dfg.ktx2, RG16F
    /// scale/bias, 64 x 64, zstd), three (DFGLUTData.js as three ships it, 16 x 16 transposed half bits),
    /// enterprise-pbr (GGX_E.exr and GGX_E_avg.exr, half channel Y), filament (dfg.inc, 128 x
    /// 128 RGB16F half bits, cloth in B), godot (dfg_lut.dds, RGBA16F, rows at 1 - r,
    /// Schlick-GGX), unity-hdrp (preIntegratedFGD_GGXDisneyDiffuse.exr, 64 x 64, sqrt(NoV)
    /// nodes, Disney diffuse in B), unreal (ShadingEnergyGGXSpec.exr, 32 x 32, R = E, G = E*Fc)
    /// or games202 (GGX_E_LUT.png and GGX_Eavg_LUT.png for the GAMES202 Kulla-Conty homework,
    /// 128 x 128 8-bit grey, rounded); with kiln's JSON sidecars of the tables it holds. --max-error and --out apply.
    #[arg(
        long,
        value_enum,
        hide_possible_values = true,
        conflicts_with_all = ["scene", "table_spec"]
    )]
    preset: Option<kiln::preset::Preset>,
    /// With --preset cycles: copy the arrays kiln does not compute (table_sheen_ltc, an LTC
    /// fit) from this shader.tables (Blender's own, say) into the one written, so that it
    /// replaces Blender's whole. Without it the file says that Blender's must be kept.
    #[arg(long, requires = "preset", value_name = "FILE")]
    carry_over: Option<PathBuf>,
    /// Output formats, comma-separated.
    #[arg(
        long,
        value_enum,
        value_delimiter = ',',
        default_value = "exr,bin,rs,json,png"
    )]
    format: Vec<Format>,
    /// Storage precision of the value and 1 - value channels in EXR, binary, KTX2 and DDS files
    /// (std_error stays f32, and so does f_ms_norm, whose smallest values would be f16
    /// subnormals; JSON is always f64, Rust, C and shader code always f32).
    #[arg(long, value_enum, default_value = "f32")]
    precision: Precision,
    /// Roughness axis: perceptual r (alpha = r^2) or alpha.
    #[arg(long, value_enum, default_value = "r")]
    roughness_axis: RoughnessConvention,
    /// Spacing of the roughness samples along --roughness-axis: linear (the texture coordinate
    /// is r, or alpha) or balanced (t = 0.6 P(r) + 0.4 r^2 (3 - 2 r), P(r) about r^1.37: more
    /// rows where E bends fastest, r ~ 0.5, fewer near the mirror; laid out with --mu-axis
    /// balanced for --texels lookup-fit). The tables over the IOR keep the linear spacing
    /// [default: balanced with --mu-axis balanced, otherwise linear].
    #[arg(long, value_enum, hide_possible_values = true)]
    roughness_spacing: Option<RoughnessSpacing>,
    /// Spacing of the mu axis: balanced (kiln's layout for E, E_avg and f_ms_norm, with
    /// balanced rows and texels fitted for the lookup: the grazing layer, and more texels near
    /// mu = 1 at moderate roughness, so that the fitted lookup's largest error is about even
    /// over the domain; 2.1e-4 at 32 x 32, against 6.5e-4 for the adaptive axis' point samples;
    /// see docs/accuracy.md), adaptive (follows the grazing layer mu ~ alpha; lookup coordinate
    /// t = (mu (1 + 4 alpha) / (mu + 4 alpha))^0.4; the glass tables' product grid), split-sum (kiln's layout for the quantities that vary with mu on a
    /// mirror, e-scale, e-bias and e-f: the grazing layer, and texels for Fc(mu) on the mirror
    /// row; t = 0.6 A(mu; 0.3, 0.5) + 0.4 A(mu; 4 alpha, 0.4), A(y; k, p) = (y (1 + k) / (y +
    /// k))^p), linear (mu = t) or sqrt (mu = t^2). See "Conventions" below. [default: kiln's
    /// axis for each quantity: balanced for e, e-avg and f-ms-norm, split-sum for e-scale, e-bias
    /// and e-f; the glass tables lay out mu themselves].
    #[arg(long, value_enum, hide_possible_values = true)]
    mu_axis: Option<MuMapping>,
    /// Where samples sit: nodes i/(N - 1) on the axis ends (lookups must remap, see below) or
    /// texel centres (i + 0.5)/N.
    #[arg(long, value_enum, default_value = "nodes")]
    grid: Grid,
    /// Compute the values by this method instead of to a max error: quasi-Monte Carlo (with a
    /// standard error per texel, --samples) or the deterministic reference quadrature at its
    /// full accuracy (error at most 1e-10).
    #[arg(long, value_enum)]
    method: Option<Method>,
    /// With --method qmc (or --samples): skip measuring each table's node error against the
    /// deterministic reference after baking; the metadata then states only the standard
    /// errors. An error with any other method.
    #[arg(long)]
    no_reference_check: bool,
    /// Bake to this max error (1e-10 to 0.5) [default: 1e-7 unless --method or --samples is
    /// given]: kiln picks the cheapest method that meets it (QMC from 1e-3 up, the quadrature
    /// below, by what `kiln study` measured), records the choice, checks a sample of texels
    /// against the reference, and fails rather than write a table that misses it.
    #[arg(
        long,
        value_parser = crate::args::parse_error_bound,
        allow_negative_numbers = true,
        conflicts_with = "explicit_method"
    )]
    max_error: Option<f64>,
    /// Replace tables of the same name in --out that another bake made to a different spec
    /// (another size, method or accuracy), and remove their files in formats this bake does
    /// not write, so that the folder holds one consistent set. Without it such a bake stops
    /// before writing anything. (Tables of other layouts have other names: `-mu-linear`,
    /// `-centers`, `-alpha`; a preset's sidecars start with the preset's name.)
    #[arg(long)]
    force: bool,
    /// Compute only shard I of N (0 to N - 1) into --out/kiln-shard-I-of-N.json; `kiln merge`
    /// writes the tables. auto: Slurm's SLURM_ARRAY_TASK_ID/_COUNT, or Kubernetes'
    /// JOB_COMPLETION_INDEX with KILN_SHARD_COUNT.
    #[arg(long, value_name = "I/N|auto", conflicts_with_all = ["scene", "preset"])]
    shard: Option<String>,
    /// Print one JSON object instead of the summary: each table (id, quantity, shape,
    /// max_std_error, node_errors, lookup_fit), the files written, the folder and the seconds.
    /// For kiln's own tables (not with --scene, --preset or --shard).
    #[arg(long, conflicts_with_all = ["scene", "preset", "shard"])]
    json: bool,
    /// No progress bar and no summary.
    #[arg(long, short)]
    quiet: bool,
}

impl BakeArgs {
    fn replace(&self) -> Replace {
        if self.force {
            Replace::Force
        } else {
            Replace::Refuse
        }
    }
}

pub fn run(args: BakeArgs) -> kiln::Result<()> {
    if let Some(path) = &args.scene {
        return bake_scene(path, args.out.as_deref(), args.quiet, args.replace());
    }
    if let Some(preset) = args.preset {
        return bake_preset(preset, &args);
    }
    let out = args.out.clone().unwrap_or_else(|| PathBuf::from("tables"));
    check_method_flags(&args)?;
    check_ior_flags(&args)?;
    let replace = args.replace();
    // Naming a method or a sample count asks for that method; otherwise a max error decides.
    let explicit_method =
        args.method.is_some() || args.samples.is_some() || args.avg_samples.is_some();
    let scrambles = args.scrambles.unwrap_or(QmcSettings::DEFAULT_SCRAMBLES);
    let max_error = match args.max_error {
        Some(x) => Some(x),
        None if explicit_method => None,
        None => Some(BakeOptions::DEFAULT_MAX_ERROR),
    };
    let samples = args.samples.unwrap_or(QmcSettings::DEFAULT_SAMPLES);
    let options = BakeOptions {
        ndfs: args.ndf,
        maskings: args.masking,
        quantities: args.quantity.clone().unwrap_or_else(|| {
            if args.fresnel.given() {
                vec![Quantity::EF]
            } else {
                BakeOptions::DEFAULT_QUANTITIES.to_vec()
            }
        }),
        fresnel: if args.fresnel.given() {
            Some(args.fresnel.model()?)
        } else {
            None
        },
        size: args.size,
        samples,
        average_samples: args.avg_samples.unwrap_or_else(|| {
            let (_, most) = QmcSettings {
                samples,
                scrambles,
                seed: 0,
            }
            .sample_range();
            QmcSettings::average_samples_for(samples).min(most)
        }),
        scrambles,
        seed: args.seed.unwrap_or(0),
        roughness_convention: args.roughness_axis,
        roughness_spacing: args.roughness_spacing,
        mu_mapping: args.mu_axis,
        grid: args.grid,
        ior_size: args.ior_size.unwrap_or(BakeOptions::DEFAULT_IOR_SIZE),
        ior_mapping: args.ior_axis.unwrap_or(IorMapping::Glass),
        ior_max: args.ior_max.unwrap_or(BakeOptions::DEFAULT_IOR_MAX),
        transmission: args.transmission,
        check_against_reference: !args.no_reference_check,
        method: args.method.unwrap_or(Method::Qmc),
        max_error,
        texels: args.texels,
    };
    options.validate()?;
    let mut formats = args.format;
    formats.sort();
    formats.dedup();
    // Fail on an unusable output directory now, not after minutes of integration.
    format::check_output_dir(&out)?;
    if let Some(shard) = &args.shard {
        let shard = match shard.as_str() {
            "auto" => {
                kiln::shard::ShardIndex::from_environment(&|name| std::env::var(name).ok(), None)
            }
            text => kiln::shard::ShardIndex::parse(text),
        }?;
        let bake = kiln::shard::ShardedBake {
            options,
            formats,
            precision: args.precision,
        };
        return bake_shard(&bake, shard, &out, args.quiet);
    }
    // A folder of tables this bake may not replace: refused now, not after the integration.
    format::replace::precheck(&out, &options.resolved().specs(), &formats, replace)?;
    crate::announce_cost(options.estimated_core_seconds(), args.quiet);

    let bar = crate::progress_bar(args.quiet, options.total_samples(), "integrating");
    let start = Instant::now();
    let tables = options.bake(&|samples| bar.inc(samples))?;
    bar.finish_and_clear();
    let seconds = start.elapsed().as_secs_f64();
    let written = format::write_tables(&out, &tables, &formats, args.precision, replace)?;
    if args.json {
        let object = crate::report::tables_written_json(&tables, &written, &out, Some(seconds));
        println!("{object}");
    } else if !args.quiet {
        for table in &tables {
            let shape: Vec<String> = table.spec.shape().iter().map(|n| n.to_string()).collect();
            let measured = match (table.lookup_fit, table.node_errors) {
                (Some(fit), _) => format!(
                    ", fitted: lookup max error {:.1e} (point samples' {:.1e}) at {} points, \
                     texels moved up to {:.1e}",
                    fit.lookup_max_error, fit.node_lookup_max_error, fit.points, fit.max_correction
                ),
                (None, Some(e)) => format!(
                    ", max error vs reference {:.1e} ({} texels)",
                    e.max, e.texels
                ),
                (None, None) => String::new(),
            };
            println!(
                "{:<44} {:>9} max std error {:.1e}{measured}",
                table.spec.id(),
                shape.join("x"),
                table.max_std_error()
            );
        }
        println!(
            "baked {} in {seconds:.1} s; wrote {} to {}",
            kiln::error::count(tables.len(), "table"),
            kiln::error::count(written.len(), "file"),
            out.display()
        );
    }
    Ok(())
}

/// `kiln bake ... --shard I/N`: integrates the shard and writes its file.
fn bake_shard(
    bake: &kiln::shard::ShardedBake,
    shard: kiln::shard::ShardIndex,
    out: &std::path::Path,
    quiet: bool,
) -> kiln::Result<()> {
    crate::announce_cost(
        bake.options.estimated_core_seconds() / shard.count as f64,
        quiet,
    );
    let bar = crate::progress_bar(
        quiet,
        bake.options.integration_samples() / shard.count as u64,
        "integrating",
    );
    let start = Instant::now();
    let file = kiln::shard::bake_shard(bake, shard, &|samples| bar.inc(samples))?;
    bar.finish_and_clear();
    let bytes = serde_json::to_vec(&file).map_err(|e| kiln::Error::InvalidInput(e.to_string()))?;
    let written = format::write_files(out, &[(shard.file_name(), bytes)])?;
    if !quiet {
        let texels: usize = file.tables.iter().map(|t| t.range.1 - t.range.0).sum();
        println!(
            "shard {} of {}: {texels} texels of {} tables in {:.1} s; wrote {}",
            shard.index,
            shard.count,
            file.tables.len(),
            start.elapsed().as_secs_f64(),
            written[0].display()
        );
    }
    Ok(())
}

/// The IOR axis' flags are errors for a bake without a table over the IOR, which would ignore
/// them (and record nothing of them).
fn check_ior_flags(args: &BakeArgs) -> kiln::Result<()> {
    let given = crate::args::given(&[
        ("--ior-size", args.ior_size.is_some()),
        ("--ior-axis", args.ior_axis.is_some()),
        ("--ior-max", args.ior_max.is_some()),
    ]);
    let over_ior = args
        .quantity
        .as_ref()
        .is_some_and(|qs| qs.iter().any(|q| q.has_ior()));
    if given.is_empty() || over_ior {
        return Ok(());
    }
    Err(kiln::Error::InvalidInput(format!(
        "{} {} the IOR axis, which none of the tables baked has: add a glass table \
         (--quantity e-dielectric, e-dielectric-inside, e-avg-dielectric, \
         e-avg-dielectric-inside or f-avg), or drop {}",
        given.join(", "),
        if given.len() == 1 { "sets" } else { "set" },
        if given.len() == 1 { "it" } else { "them" }
    )))
}

/// Flags that only QMC reads are errors with a method that does not read them, rather than
/// being ignored or switching the method: `--method reference`, or a `--max-error` (the
/// default 1e-7 included) below 1e-3, which kiln bakes by the quadrature.
fn check_method_flags(args: &BakeArgs) -> kiln::Result<()> {
    let qmc_chosen = args.method == Some(Method::Qmc)
        || (args.method.is_none() && (args.samples.is_some() || args.avg_samples.is_some()));
    if args.no_reference_check && !qmc_chosen {
        return Err(kiln::Error::InvalidInput(
            "--no-reference-check applies to QMC bakes only: add --method qmc (and --samples N) \
             to bake by QMC without the node check, or drop it (the default bake is checked \
             against the reference to --max-error)"
                .into(),
        ));
    }
    let explicit_method =
        args.method.is_some() || args.samples.is_some() || args.avg_samples.is_some();
    let max_error = args
        .max_error
        .or((!explicit_method).then_some(BakeOptions::DEFAULT_MAX_ERROR));
    let glass = args.quantity.as_deref().is_some_and(BakeOptions::any_glass);
    let by_quadrature = args.method == Some(Method::Reference)
        || (args.method.is_none()
            && max_error.is_some_and(|x| BakeOptions::max_error_takes_quadrature(x, glass)));
    if by_quadrature && args.method != Some(Method::Reference) {
        let qmc_only = crate::args::given(&[
            ("--scrambles", args.scrambles.is_some()),
            ("--seed", args.seed.is_some()),
        ]);
        if !qmc_only.is_empty() {
            return Err(kiln::Error::InvalidInput(format!(
                "{} {} QMC's sampling, but --max-error {} is baked by the deterministic \
                 quadrature, which has neither (kiln uses QMC from 1e-3 up, glass excepted): drop {}, or \
                 add --method qmc --samples N to bake by QMC",
                qmc_only.join(", "),
                if qmc_only.len() == 1 { "sets" } else { "set" },
                kiln::error::shown(max_error.unwrap_or(BakeOptions::DEFAULT_MAX_ERROR)),
                if qmc_only.len() == 1 { "it" } else { "them" }
            )));
        }
    }
    if args.method == Some(Method::Reference) {
        let qmc_only = crate::args::given(&[
            ("--samples", args.samples.is_some()),
            ("--avg-samples", args.avg_samples.is_some()),
            ("--scrambles", args.scrambles.is_some()),
            ("--seed", args.seed.is_some()),
        ]);
        if !qmc_only.is_empty() {
            return Err(kiln::Error::InvalidInput(format!(
                "{} {} QMC's sampling; --method reference is a deterministic quadrature that \
                 chooses its own evaluations: drop {} or use --method qmc",
                qmc_only.join(", "),
                if qmc_only.len() == 1 { "sets" } else { "set" },
                if qmc_only.len() == 1 { "it" } else { "them" }
            )));
        }
    }
    Ok(())
}

/// `kiln bake --preset NAME`.
fn bake_preset(preset: kiln::preset::Preset, args: &BakeArgs) -> kiln::Result<()> {
    let out = args.out.clone().unwrap_or_else(|| PathBuf::from("tables"));
    // The engine's tables, and its glass tables to their own default max error unless one is
    // named.
    let mut bakes = preset.bakes(args.max_error);
    // The engine's own tables (the first bake) get the texels asked for; glass tables, over
    // the IOR, stay point samples.
    if let Some(texels) = args.texels {
        bakes[0].texels = Some(texels);
        if texels != kiln::table::Texels::Nodes && bakes.len() > 1 && !args.quiet {
            eprintln!(
                "kiln: --texels {}: the {} glass tables (over the IOR) stay point samples",
                texels.name(),
                preset.name()
            );
        }
    }
    for options in &bakes {
        options.validate()?;
    }
    let carried = match &args.carry_over {
        Some(path) => {
            let bytes = format::read_file(path)?;
            let carried = preset.carried_from(&bytes, &path.display().to_string())?;
            if carried.is_none() {
                return Err(kiln::Error::InvalidInput(format!(
                    "--carry-over: the {} layout holds nothing kiln does not compute (only \
                     cycles carries arrays over: table_sheen_ltc)",
                    preset.name()
                )));
            }
            carried
        }
        None => None,
    };
    format::check_output_dir(&out)?;
    crate::announce_cost(
        bakes.iter().map(BakeOptions::estimated_core_seconds).sum(),
        args.quiet,
    );
    let total = bakes.iter().map(BakeOptions::total_samples).sum();
    let bar = crate::progress_bar(args.quiet, total, "integrating");
    let start = Instant::now();
    let mut tables = Vec::new();
    for options in &bakes {
        tables.extend(options.bake(&|samples| bar.inc(samples))?);
    }
    bar.finish_and_clear();
    // The engine's files and kiln's sidecars of the tables they hold, named after the preset
    // (the layout is the preset's), listing the engine's file(s) they describe.
    let extra = preset.extra_channel();
    let files = preset.files_with_sidecars(&tables, extra.as_ref(), carried.as_ref())?;
    let written = format::write_files(&out, &files)?;
    if !args.quiet {
        for table in &tables {
            if let Some(fit) = table.lookup_fit {
                println!(
                    "{:<32} fitted: lookup max error {:.1e} (point samples' {:.1e}), texels \
                     moved up to {:.1e}",
                    table.spec.id(),
                    fit.lookup_max_error,
                    fit.node_lookup_max_error,
                    fit.max_correction
                );
            } else if let Some(e) = table.node_errors {
                println!(
                    "{:<32} max error vs reference {:.1e} ({} texels)",
                    table.spec.id(),
                    e.max,
                    e.texels
                );
            }
        }
        if let Some(extra) = extra {
            println!(
                "blue channel: {}, error estimate {:.1e}",
                extra.name, extra.max_error
            );
        }
        let layout = preset.layout();
        if !layout.carried.is_empty() && carried.is_none() {
            println!(
                "note: {} is not made by kiln and is not in {}: Cycles needs it, so keep \
                 Blender's, or give --carry-over path/to/blender/shader.tables",
                layout.carried.join(", "),
                preset.file_name()
            );
        }
        println!(
            "{} layout: baked {} in {:.1} s; wrote {} ({}) to {}",
            preset.name(),
            kiln::error::count(tables.len(), "table"),
            start.elapsed().as_secs_f64(),
            preset.file_name(),
            kiln::error::count(written.len(), "file"),
            out.display()
        );
    }
    Ok(())
}

/// `kiln bake --scene FILE`.
fn bake_scene(
    path: &std::path::Path,
    out: Option<&std::path::Path>,
    quiet: bool,
    replace: Replace,
) -> kiln::Result<()> {
    let scene = kiln::scene::Scene::read(path)?;
    if scene.materials.is_empty() {
        eprintln!(
            "kiln: warning: {} names no materials: nothing to bake (add [[material]] entries)",
            path.display()
        );
    }
    let dir = out.map_or_else(|| scene.output_dir(), std::path::Path::to_path_buf);
    crate::announce_cost(
        scene
            .plan()
            .tables
            .iter()
            .map(|t| t.estimated_core_seconds)
            .sum(),
        quiet,
    );
    let total: u64 = scene
        .bake_options()
        .iter()
        .map(BakeOptions::total_samples)
        .sum();
    let bar = crate::progress_bar(quiet, total, "integrating");
    let start = Instant::now();
    let result = scene.bake(&dir, &|samples| bar.inc(samples), replace)?;
    bar.finish_and_clear();
    // A warning, quiet or not.
    for (id, reason) in &result.report.repaired {
        eprintln!(
            "kiln: warning: the cache entry of {id} was damaged ({reason}): baked it again and \
             replaced the entry"
        );
    }
    if !quiet {
        let list = |ids: &[String]| {
            if ids.is_empty() {
                "none".to_string()
            } else {
                ids.join(", ")
            }
        };
        println!("reused from the cache: {}", list(&result.report.reused));
        println!("baked: {}", list(&result.report.baked));
        println!(
            "{} in {:.1} s; wrote {} to {}",
            kiln::error::count(result.report.tables.len(), "table"),
            start.elapsed().as_secs_f64(),
            kiln::error::count(result.written.len(), "file"),
            dir.display()
        );
    }
    Ok(())
}
