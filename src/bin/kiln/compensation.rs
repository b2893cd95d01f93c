//! `kiln compensation`: Kulla-Conty's and Turquin's energy compensation measured against the
//! microsurface walk (`kiln::verify::compensation`; glass: `kiln::verify::glass_compensation`).

use crate::args::{SEE_CONVENTIONS, parse_samples};
use clap::Args;
use kiln::integrate::compensation::Compensation;
use kiln::integrate::walk::WalkSettings;
use kiln::verify::compensation::{CompensationAudit, CompensationGrid, audit_compensations};
use kiln::{Masking, Model, Ndf, RoughnessConvention};

/// Measure energy compensations against the microsurface random walk.
#[derive(Args, Debug)]
#[command(
    long_about = "Measure how far the albedo of single scattering plus an energy compensation \
                  (Kulla-Conty's lobe with its colour term, Turquin's scaling, kiln's own fitted \
                  to walks of another seed) is from the albedo \
                  of every order of scattering on the microsurface, by the random walk (GGX, or \
                  Beckmann with --ndf; height-correlated; Schlick's Fresnel at every bounce). Prints, per \
                  compensation, the largest deviation of each sign with its 95 % confidence \
                  half-width and where it is, and the RMS over the grid; --json prints every \
                  point. The compensations are computed from kiln's reference (E, E_avg, E_F, \
                  F_avg), not from a table: what is measured is the model's error. --ior \
                  walks glass instead (a rough dielectric interface: where the light goes, \
                  reflected or transmitted, against Turquin's split); --lobe measures where \
                  the added light goes; --bake writes kiln's own compensation for engines.",
    after_help = SEE_CONVENTIONS,
    // The audit's grid and report: with --bake, which writes a table instead, an error.
    group(clap::ArgGroup::new("audit").multiple(true).args([
        "compensation", "roughness", "mu", "f0", "f90", "json",
    ])),
    // A conductor's Fresnel and its compensations: with --ior (glass), an error.
    group(clap::ArgGroup::new("conductor").multiple(true).args(["compensation", "f0", "f90"]))
)]
pub struct CompensationArgs {
    /// The compensations to measure [default: all three; with --lobe kulla-conty and turquin,
    /// since at F = 1 kiln's lobe is Kulla-Conty's].
    #[arg(long, value_enum, value_delimiter = ',')]
    compensation: Vec<Compensation>,
    /// Perceptual roughness values r (alpha = r^2), comma-separated, in [0, 1] [default:
    /// 0.25,0.5,0.75,1; with --lobe 0.5,0.75,1: below r = 0.5 the walk's lobe needs far more
    /// walks for a useful confidence, docs/multiple-scattering.md].
    #[arg(long, value_delimiter = ',', value_parser = crate::args::parse_roughness, allow_negative_numbers = true)]
    roughness: Vec<f64>,
    /// View cosines mu, comma-separated, in [0, 1].
    #[arg(long, value_delimiter = ',', default_value = "0.05,0.1,0.2,0.35,0.5,0.7,0.85,1", value_parser = crate::args::parse_mu, allow_negative_numbers = true)]
    mu: Vec<f64>,
    /// Schlick's F0 values, comma-separated, in [0, 1] [default: 0.02,0.04,0.1,0.25,0.5,0.75,
    /// 0.9,1; with --lobe 1, the white furnace].
    #[arg(long, value_delimiter = ',', value_parser = crate::args::parse_number, allow_negative_numbers = true)]
    f0: Vec<f64>,
    /// Schlick's F90, in [0, 1].
    #[arg(long, default_value_t = 1.0, value_parser = crate::args::parse_number, allow_negative_numbers = true)]
    f90: f64,
    /// Walks per view, a power of two (every F0 shares them) [default: 2^20; with --bake, per
    /// texel, 2^17: a standard error of at most 1e-4 at every texel of 32 x 32].
    #[arg(long, value_parser = parse_samples, allow_negative_numbers = true)]
    walks: Option<u64>,
    /// Bake kiln's compensation into this folder instead: its four coefficients at every texel
    /// of the E layout of --size (fitted to walks seeded from --seed and the texel) and their
    /// averages over mu, as one JSON file (NDF-MASKING-kiln-compensation.json).
    #[arg(long, value_name = "DIR", conflicts_with_all = ["table", "audit"])]
    bake: Option<std::path::PathBuf>,
    /// With --bake: the files to write, comma-separated [default: all; with --ior json,exr]:
    /// json (the checked document every audit reads), exr, ktx2 and dds (the coefficients as an
    /// RGBA 32-bit float texture over the E layout: channels c0 to c3, x = mu, row 0 at r = 0;
    /// for glass kR_outside, kT_outside, kR_inside, kT_inside),
    /// wgsl, glsl and hlsl (the texture's lookup, M(mu, F0) and the lobe), rs (the coefficients
    /// as arrays with the same functions in f32), h (a C/C++ header: the texture's texels and
    /// M_avg's as arrays, the basis, albedo and lobe functions).
    #[arg(long, value_enum, value_delimiter = ',', requires = "bake")]
    format: Vec<CompensationFormat>,
    /// With --bake: the E layout's size (size x size texels, kiln's default layout).
    #[arg(long, default_value_t = 32, requires = "bake", value_parser = crate::args::parse_size)]
    size: usize,
    /// Measure kiln's compensation as this baked table's lookup (what a renderer reads) instead
    /// of fitting it at each view.
    #[arg(long, value_name = "FILE")]
    table: Option<std::path::PathBuf>,
    /// Measure the lobes instead of the albedo: the lobe each compensation adds (with Schlick's
    /// --f0 at every bounce, F90 = 1; at F0 = 1 kiln's is Kulla-Conty's) against the walk's
    /// lobe of the second and later orders, by next-event estimation, from each view (--mu) to
    /// each exit (--exit), averaged over the azimuth and at each --azimuth. kiln's lobe needs
    /// its baked --table (for M_avg).
    #[arg(long, conflicts_with_all = ["f90", "bake"])]
    lobe: bool,
    /// With --lobe: exit cosines, comma-separated, in (0, 1] [default: the --mu values].
    #[arg(long, value_delimiter = ',', requires = "lobe", value_parser = crate::args::parse_mu, allow_negative_numbers = true)]
    exit: Vec<f64>,
    /// With --lobe: exit azimuths in degrees from the view's plane, comma-separated, in
    /// [0, 180] (0: back towards the light's side, 180: the mirror direction's side).
    #[arg(long, value_delimiter = ',', requires = "lobe", default_value = "0,45,90,135,180", value_parser = crate::args::parse_number, allow_negative_numbers = true)]
    azimuth: Vec<f64>,
    /// With --lobe: also draw the lobes in the plane of incidence, one panel per roughness and
    /// view (at most 12, at the first --f0), into this SVG or PNG file.
    #[arg(long, value_name = "FILE", requires = "lobe")]
    plot: Option<std::path::PathBuf>,
    /// Measure glass instead: a rough dielectric interface at these relative indices
    /// n_inside / n_outside, comma-separated, in [0.01, 100] (1.5: glass seen from air; 0.667:
    /// the same glass seen from inside). Prints where the light goes, reflected or
    /// transmitted, by the dielectric walk (every order; no energy is lost), beside the
    /// renderer's single-scattering BSDF and Turquin's compensation (the BSDF divided by its
    /// energy albedo R + T, kiln's e-dielectric table: Cycles' glass albedo scaling), and kiln's
    /// glass compensation with --table. With --bake: bake kiln's glass compensation at this one
    /// index (scale factors for the BSDF's reflection and transmission lobes, from outside and
    /// from inside).
    #[arg(long, value_delimiter = ',', value_parser = crate::args::parse_number, allow_negative_numbers = true, conflicts_with_all = ["lobe", "conductor"])]
    ior: Vec<f64>,
    /// The normal distribution of the microsurface (its masking is the walk's own,
    /// height-correlated).
    #[arg(long, value_enum, default_value = "ggx")]
    ndf: Ndf,
    /// Base seed of the walks' scrambles.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Print one JSON object (every point and the summaries) instead of text.
    #[arg(long)]
    json: bool,
    /// No progress on stderr.
    #[arg(long, short)]
    quiet: bool,
}

/// The files `kiln compensation --bake` writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
enum CompensationFormat {
    Json,
    Exr,
    Ktx2,
    Dds,
    Wgsl,
    Glsl,
    Hlsl,
    Rs,
    H,
}

impl CompensationFormat {
    /// Every format, in the default order.
    const ALL: [CompensationFormat; 9] = [
        CompensationFormat::Json,
        CompensationFormat::Exr,
        CompensationFormat::Ktx2,
        CompensationFormat::Dds,
        CompensationFormat::Wgsl,
        CompensationFormat::Glsl,
        CompensationFormat::Hlsl,
        CompensationFormat::Rs,
        CompensationFormat::H,
    ];
}

impl CompensationArgs {
    /// The model walked: `--ndf` with the walk's own masking (height-correlated).
    fn model(&self) -> Model {
        Model {
            ndf: self.ndf,
            masking: Masking::HeightCorrelated,
        }
    }

    /// The walks' settings: `--walks` (or `default_walks`) and `--seed`, checked.
    fn walk_settings(&self, default_walks: u64) -> kiln::Result<WalkSettings> {
        let settings = WalkSettings {
            walks: self.walks.unwrap_or(default_walks),
            seed: self.seed,
            ..WalkSettings::default()
        };
        settings.validate()?;
        Ok(settings)
    }

    /// The formats of `--format`, each once in the order given, or `default`.
    fn formats(&self, default: &[CompensationFormat]) -> Vec<CompensationFormat> {
        let mut formats: Vec<CompensationFormat> = Vec::new();
        for &format in &self.format {
            if !formats.contains(&format) {
                formats.push(format);
            }
        }
        if formats.is_empty() {
            default.to_vec()
        } else {
            formats
        }
    }

    /// The slope-space roughness of `--roughness` (or of `default`, perceptual).
    fn alphas(&self, default: &[f64]) -> Vec<f64> {
        let roughness = if self.roughness.is_empty() {
            default
        } else {
            &self.roughness
        };
        roughness
            .iter()
            .map(|&r| RoughnessConvention::Perceptual.to_alpha(r))
            .collect()
    }
}

/// `kiln compensation --bake DIR`.
fn bake(args: &CompensationArgs, out: &std::path::Path) -> kiln::Result<()> {
    use kiln::table::compensation::CompensationTable;
    let settings = args.walk_settings(1 << 17)?;
    kiln::format::check_output_dir(out)?;
    let options = kiln::BakeOptions {
        ndfs: vec![args.ndf],
        quantities: vec![kiln::Quantity::E, kiln::Quantity::EAvg],
        size: args.size,
        texels: Some(kiln::table::Texels::Nodes),
        ..kiln::BakeOptions::default()
    };
    options.validate()?;
    let mut specs = options.resolved().specs().into_iter();
    let (spec, average_spec) = (specs.next().expect("E"), specs.next().expect("E_avg"));
    let texels = spec.len() as u64;
    crate::announce_cost(
        CompensationTable::bake_core_seconds(texels, settings.walks),
        args.quiet,
    );
    let bar = crate::progress_bar(args.quiet, texels, "walking");
    let model = spec.model;
    let table = CompensationTable::bake(model, spec, average_spec, &settings, &|done| {
        bar.set_position(done)
    })?;
    bar.finish_and_clear();
    let command = format!(
        "kiln compensation --bake {} --size {} --walks {} --seed {}",
        out.display(),
        args.size,
        settings.walks,
        settings.seed
    );
    use kiln::format::Precision;
    use kiln::format::shader::{Language, encode_compensation};
    let stem = kiln::format::compensation::stem(&table).replace('_', "-");
    let mut files = Vec::new();
    // Each format once, in the order given (`--format json,h,json` writes two files).
    for format in args.formats(&CompensationFormat::ALL) {
        let texture = || kiln::format::compensation::texture(&table);
        let (extension, bytes) = match format {
            CompensationFormat::Json => {
                ("json", kiln::format::compensation::encode(&table, &command))
            }
            CompensationFormat::Exr => (
                "exr",
                kiln::format::exr::encode_texture(&texture(), &stem, Precision::F32)?,
            ),
            CompensationFormat::Ktx2 => (
                "ktx2",
                kiln::format::ktx2::encode(&texture(), Precision::F32)?,
            ),
            CompensationFormat::Dds => (
                "dds",
                kiln::format::dds::encode(&texture(), Precision::F32)?,
            ),
            CompensationFormat::Wgsl => (
                "wgsl",
                encode_compensation(&table, Language::Wgsl, &command).into_bytes(),
            ),
            CompensationFormat::Glsl => (
                "glsl",
                encode_compensation(&table, Language::Glsl, &command).into_bytes(),
            ),
            CompensationFormat::Hlsl => (
                "hlsl",
                encode_compensation(&table, Language::Hlsl, &command).into_bytes(),
            ),
            CompensationFormat::Rs => (
                "rs",
                kiln::format::rust::encode_compensation(&table, &command).into_bytes(),
            ),
            CompensationFormat::H => (
                "h",
                kiln::format::c_header::encode_compensation(&table, &command).into_bytes(),
            ),
        };
        files.push((format!("{stem}.{extension}"), bytes));
    }
    let what = format!("kiln's compensation at {0} x {0} texels", args.size);
    write_and_say(
        args,
        out,
        &files,
        &what,
        settings.walks,
        table.max_std_error(),
    )
}

/// Writes a bake's `files` into `out` (atomically, [`kiln::format::write_files`]) and, unless
/// `--quiet`, says `what` was written, with its walks and largest standard error.
fn write_and_say(
    args: &CompensationArgs,
    out: &std::path::Path,
    files: &[(String, Vec<u8>)],
    what: &str,
    walks: u64,
    max_std_error: f64,
) -> kiln::Result<()> {
    let written = kiln::format::write_files(out, files)?;
    if !args.quiet {
        println!(
            "{what}, {walks} walks each, largest standard error {max_std_error:.1e}: {}",
            written
                .iter()
                .map(|p| kiln::error::escaped_path(p))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    Ok(())
}

pub fn run(args: CompensationArgs) -> kiln::Result<()> {
    if let Some(out) = &args.bake {
        if !args.ior.is_empty() {
            return bake_glass(&args, out);
        }
        return bake(&args, out);
    }
    if args.lobe {
        return lobes(&args);
    }
    if !args.ior.is_empty() {
        return glass(&args);
    }
    let f0 = if args.f0.is_empty() {
        vec![0.02, 0.04, 0.1, 0.25, 0.5, 0.75, 0.9, 1.0]
    } else {
        args.f0.clone()
    };
    let table = read_table(args.table.as_deref(), args.model())?;
    let compensations = if args.compensation.is_empty() {
        Compensation::ALL.to_vec()
    } else {
        args.compensation.clone()
    };
    let grid = CompensationGrid {
        alphas: args.alphas(&[0.25, 0.5, 0.75, 1.0]),
        mus: args.mu.clone(),
        f0s: f0,
        f90: args.f90,
    };
    if !(0.0..=1.0).contains(&args.f90) {
        return Err(kiln::integrate::walk::WalkError::F90(args.f90).into());
    }
    let settings = args.walk_settings(1 << 20)?;
    let walks = settings.walks;
    let model = args.model();
    let views = (grid.alphas.len() * grid.mus.len()) as u64;
    if !args.quiet {
        let fits_kiln = compensations.contains(&Compensation::Kiln) && table.is_none();
        let seconds = kiln::verify::compensation::audit_seconds(views, walks, fits_kiln);
        if seconds > 5.0 {
            eprintln!(
                "kiln: {views} views of {} walks, about {} (fewer with --walks)",
                walks,
                crate::human_seconds(seconds)
            );
        }
    }
    let bar = crate::progress_bar(args.quiet, views, "walking");
    let audit = audit_compensations(
        model,
        &grid,
        &compensations,
        &settings,
        table.as_ref(),
        &|done| bar.set_position(done),
    )?;
    bar.finish_and_clear();
    if args.json {
        println!(
            "{}",
            serde_json::to_string(&audit).expect("the audit serialises")
        );
    } else {
        print(&audit, &grid, model);
    }
    Ok(())
}

fn print(audit: &CompensationAudit, grid: &CompensationGrid, model: Model) {
    println!(
        "against the microsurface walk ({model}, Schlick F90 {}), {} walks a view, {} points: {} \
         roughness x {} mu x {} F0",
        audit.f90,
        audit.walks,
        audit.points.len(),
        grid.alphas.len(),
        grid.mus.len(),
        grid.f0s.len()
    );
    for summary in &audit.summaries {
        let at = |e: &kiln::verify::compensation::Extreme| {
            format!(
                "{:+.2}% +- {:.2}% at r = {}, mu = {}, F0 = {}",
                100.0 * e.deviation,
                100.0 * e.confidence,
                kiln::error::brief(RoughnessConvention::Perceptual.from_alpha(e.alpha)),
                e.mu,
                e.f0
            )
        };
        println!(
            "  {:<12} too high {}; too low {}; rms {:.2}%",
            summary.compensation.name(),
            at(&summary.highest),
            at(&summary.lowest),
            100.0 * summary.rms
        );
    }
}

/// `kiln compensation --bake DIR --ior ETA`.
fn bake_glass(args: &CompensationArgs, out: &std::path::Path) -> kiln::Result<()> {
    use kiln::format::Precision;
    use kiln::format::glass_compensation as file;
    use kiln::table::glass_compensation::GlassCompensationTable;
    let &[eta] = &args.ior[..] else {
        return Err(kiln::Error::InvalidInput(format!(
            "--bake bakes glass at one index: give one --ior value, not {}",
            args.ior.len()
        )));
    };
    kiln::integrate::walk::check_eta(eta)?;
    let formats = args.formats(&[CompensationFormat::Json, CompensationFormat::Exr]);
    if let Some(other) = formats
        .iter()
        .find(|f| !matches!(f, CompensationFormat::Json | CompensationFormat::Exr))
    {
        return Err(kiln::Error::InvalidInput(format!(
            "--format {} is not written for glass yet: take json or exr",
            clap::ValueEnum::to_possible_value(other)
                .expect("a format has a name")
                .get_name()
        )));
    }
    let settings = args.walk_settings(1 << 15)?;
    kiln::format::check_output_dir(out)?;
    let options = kiln::BakeOptions {
        ndfs: vec![args.ndf],
        quantities: vec![kiln::Quantity::E],
        size: args.size,
        texels: Some(kiln::table::Texels::Nodes),
        ..kiln::BakeOptions::default()
    };
    options.validate()?;
    let spec = options.resolved().specs().remove(0);
    let texels = spec.len() as u64;
    crate::announce_cost(
        kiln::table::glass_compensation::GlassCompensationTable::bake_core_seconds(
            texels,
            settings.walks,
        ),
        args.quiet,
    );
    let bar = crate::progress_bar(args.quiet, texels, "walking");
    let table = GlassCompensationTable::bake(args.model(), spec, eta, &settings, &|done| {
        bar.set_position(done)
    })?;
    bar.finish_and_clear();
    let command = format!(
        "kiln compensation --bake {} --ior {eta} --size {} --walks {} --seed {}",
        out.display(),
        args.size,
        settings.walks,
        settings.seed
    );
    let stem = file::stem(&table);
    let mut files = Vec::new();
    for format in formats {
        let (extension, bytes) = match format {
            CompensationFormat::Exr => (
                "exr",
                kiln::format::exr::encode_texture(&file::texture(&table), &stem, Precision::F32)?,
            ),
            _ => ("json", file::encode(&table, &command)),
        };
        files.push((format!("{stem}.{extension}"), bytes));
    }
    let what = format!(
        "kiln's glass compensation at eta {eta}, {0} x {0} texels a side",
        args.size
    );
    write_and_say(
        args,
        out,
        &files,
        &what,
        settings.walks,
        table.max_std_error(),
    )
}

/// `kiln compensation --ior ETA`.
fn glass(args: &CompensationArgs) -> kiln::Result<()> {
    use kiln::verify::glass_compensation::{GlassGrid, SideSummary, audit_glass};
    let grid = GlassGrid {
        etas: args.ior.clone(),
        alphas: args.alphas(&[0.25, 0.5, 0.75, 1.0]),
        mus: args.mu.clone(),
    };
    for &eta in &grid.etas {
        kiln::integrate::walk::check_eta(eta)?;
    }
    let table = read_checked(
        args.table.as_deref(),
        args.model(),
        kiln::format::glass_compensation::decode,
        |t| t.spec.model,
    )?;
    if let Some(table) = &table
        && let Some(&eta) = grid.etas.iter().find(|&&e| {
            let near = |x: f64| (e / x - 1.0).abs() < 1e-3;
            !near(table.eta) && !near(1.0 / table.eta)
        })
    {
        return Err(kiln::Error::InvalidInput(format!(
            "--table holds kiln's glass compensation at eta {}: measure it at --ior {} \
                     (from outside) or {:.4} (from inside), within 0.1 %, not {}",
            table.eta,
            table.eta,
            1.0 / table.eta,
            kiln::error::shown(eta)
        )));
    }
    let settings = args.walk_settings(1 << 20)?;
    let views = (grid.etas.len() * grid.alphas.len() * grid.mus.len()) as u64;
    crate::announce_cost(
        kiln::verify::glass_compensation::audit_core_seconds(views, settings.walks),
        args.quiet,
    );
    let bar = crate::progress_bar(args.quiet, views, "walking");
    let audit = audit_glass(args.model(), &grid, &settings, table.as_ref(), &|done| {
        bar.set_position(done)
    })?;
    bar.finish_and_clear();
    if args.json {
        println!(
            "{}",
            serde_json::to_string(&audit).expect("the audit serialises")
        );
        return Ok(());
    }
    println!(
        "glass against the dielectric microsurface walk ({}, energy), {} walks a view, {} \
         roughness x {} mu at each index",
        args.model(),
        audit.walks,
        grid.alphas.len(),
        grid.mus.len()
    );
    let roughness =
        |alpha: f64| kiln::error::brief(RoughnessConvention::Perceptual.from_alpha(alpha));
    let line = |what: &str, side: &SideSummary, percent: bool| {
        let shown = |v: f64| {
            if percent {
                format!("{:+.2}%", 100.0 * v)
            } else {
                format!("{v:+.4}")
            }
        };
        let at = |e: &kiln::verify::glass_compensation::GlassExtreme| {
            format!(
                "{} +- {} at r = {}, mu = {}",
                shown(e.deviation),
                shown(e.confidence).trim_start_matches('+'),
                roughness(e.alpha),
                e.mu
            )
        };
        println!(
            "    {what:<30} highest {}; lowest {}; rms {}",
            at(&side.highest),
            at(&side.lowest),
            shown(side.rms).trim_start_matches('+')
        );
    };
    for summary in &audit.summaries {
        println!("  eta {}:", summary.eta);
        line("turquin R / walk R - 1", &summary.reflected, true);
        line("turquin T / walk T - 1", &summary.transmitted, true);
        line(
            "turquin R - walk R (energy)",
            &summary.reflected_energy,
            false,
        );
        line(
            "bsdf T_1 - walk T_1 (energy)",
            &summary.single_transmission,
            false,
        );
        if let Some([reflected, transmitted]) = &summary.kiln {
            line("kiln R / walk R - 1", reflected, true);
            line("kiln T / walk T - 1", transmitted, true);
        }
    }
    println!(
        "  r     mu     walk R    walk T    turquin R turquin T bsdf R_1  walk R_1  bsdf T_1  walk T_1"
    );
    for p in &audit.points {
        println!(
            "  {:<5} {:<6} {:.5}   {:.5}   {:.5}   {:.5}   {:.5}   {:.5}   {:.5}   {:.5}   (eta {})",
            roughness(p.alpha),
            p.mu,
            p.walk.all[0].value,
            p.walk.all[1].value,
            p.turquin[0],
            p.turquin[1],
            p.single[0],
            p.walk.single[0].value,
            p.single[1],
            p.walk.single[1].value,
            p.eta
        );
    }
    Ok(())
}

/// kiln's compensation table from `--table`, checked, if given.
fn read_table(
    path: Option<&std::path::Path>,
    model: Model,
) -> kiln::Result<Option<kiln::table::compensation::CompensationTable>> {
    read_checked(path, model, kiln::format::compensation::decode, |t| {
        t.spec.model
    })
}

/// A table of kiln's from `--table`, decoded by `decode` (which checks it) and refused unless
/// it was walked on `model` (`model_of` reads its own), if a path is given.
fn read_checked<T>(
    path: Option<&std::path::Path>,
    model: Model,
    decode: fn(&[u8], &str) -> kiln::Result<T>,
    model_of: fn(&T) -> Model,
) -> kiln::Result<Option<T>> {
    let Some(path) = path else {
        return Ok(None);
    };
    let bytes = kiln::format::read_file(path)?;
    let table = decode(&bytes, &kiln::error::escaped_path(path))?;
    if model_of(&table) != model {
        return Err(kiln::Error::InvalidInput(format!(
            "--table holds kiln's compensation for {}; the walk is {model} (--ndf)",
            model_of(&table)
        )));
    }
    Ok(Some(table))
}

/// `kiln compensation --lobe`.
fn lobes(args: &CompensationArgs) -> kiln::Result<()> {
    use kiln::verify::compensation::{LobeAuditGrid, audit_lobes};
    let table = read_table(args.table.as_deref(), args.model())?;
    // kiln's lobe needs its table's M_avg; at F = 1 it is Kulla-Conty's anyway.
    let compensations = if args.compensation.is_empty() {
        let mut all = vec![Compensation::KullaConty, Compensation::Turquin];
        if table.is_some() {
            all.push(Compensation::Kiln);
        }
        all
    } else {
        args.compensation.clone()
    };
    let grid = LobeAuditGrid {
        alphas: args.alphas(&[0.5, 0.75, 1.0]),
        views: args.mu.clone(),
        exits: if args.exit.is_empty() {
            args.mu.clone()
        } else {
            args.exit.clone()
        },
        azimuths: args.azimuth.iter().map(|d| d.to_radians()).collect(),
        f0s: if args.f0.is_empty() {
            vec![1.0]
        } else {
            args.f0.clone()
        },
    };
    let settings = args.walk_settings(1 << 20)?;
    let model = args.model();
    let svg = crate::report::plot_kind_of(args.plot.as_deref())?;
    let panels = grid.alphas.len() * grid.views.len();
    if svg.is_some() && panels > 12 {
        return Err(kiln::Error::InvalidInput(format!(
            "--plot draws one panel per roughness and view, at most 12: {} roughness x {} views \
             is {panels}; give fewer --roughness or --mu values",
            grid.alphas.len(),
            grid.views.len()
        )));
    }
    let views = (grid.alphas.len() * grid.views.len() * grid.f0s.len()) as u64
        * if svg.is_some() { 2 } else { 1 };
    if !args.quiet {
        let directions = grid.exits.len() * (grid.azimuths.len() + 8);
        let seconds =
            kiln::verify::compensation::lobe_audit_seconds(views, directions, settings.walks);
        if seconds > 5.0 {
            eprintln!(
                "kiln: {views} views of {} walks, about {} (fewer with --walks)",
                settings.walks,
                crate::human_seconds(seconds)
            );
        }
    }
    let bar = crate::progress_bar(args.quiet, views, "walking");
    let audit = audit_lobes(
        model,
        &grid,
        &compensations,
        table.as_ref(),
        &settings,
        &|done| bar.set_position(done),
    )?;
    if let (Some(path), Some(svg)) = (&args.plot, svg) {
        let lobe = (model, &compensations[..], table.as_ref());
        draw_lobes(path, svg, &grid, lobe, &settings, &bar)?;
    }
    bar.finish_and_clear();
    if args.json {
        println!(
            "{}",
            serde_json::to_string(&audit).expect("the audit serialises")
        );
        return Ok(());
    }
    print_lobe_audit(&audit, &grid, &compensations, model);
    Ok(())
}

/// Draws the lobe added by each compensation against the walk's, a panel per roughness and
/// view, at the grid's first F0.
fn draw_lobes(
    path: &std::path::Path,
    svg: bool,
    grid: &kiln::verify::compensation::LobeAuditGrid,
    (model, compensations, table): (
        Model,
        &[Compensation],
        Option<&kiln::table::compensation::CompensationTable>,
    ),
    settings: &kiln::integrate::walk::WalkSettings,
    bar: &indicatif::ProgressBar,
) -> kiln::Result<()> {
    let mut profiles = Vec::new();
    for &alpha in &grid.alphas {
        for &view in &grid.views {
            profiles.push(kiln::verify::compensation::lobe_profile(
                model,
                alpha,
                view,
                grid.f0s[0],
                compensations,
                table,
                settings,
            )?);
            bar.inc(1);
        }
    }
    let names: Vec<&str> = compensations.iter().map(|c| c.name()).collect();
    let fresnel = if grid.f0s[0] == 1.0 {
        "at F = 1".to_string()
    } else {
        format!("with Schlick F0 = {}", grid.f0s[0])
    };
    let title = format!(
        "The lobe added {fresnel} against the microsurface walk's (GGX, {} walks a view)",
        settings.walks
    );
    crate::report::write_plot(path, svg, crate::plot::lobe_plot(&title, &profiles, &names))
}

/// The text report of the lobe audit: the deviation's extremes per compensation and roughness.
fn print_lobe_audit(
    audit: &kiln::verify::compensation::LobeAudit,
    grid: &kiln::verify::compensation::LobeAuditGrid,
    compensations: &[Compensation],
    model: Model,
) {
    use kiln::verify::compensation::LobeExtreme;
    let white = grid.f0s == [1.0];
    let fresnel = if white {
        "at F = 1".to_string()
    } else {
        format!(
            "with Schlick F0 {} (F90 1)",
            grid.f0s
                .iter()
                .map(|f| f.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        )
    };
    println!(
        "the lobe added {fresnel} against the walk's orders 2 and later ({model}), \
         {} walks a view: {} roughness x {} views x {} exits, averaged over the azimuth and at \
         {} azimuths",
        audit.walks,
        grid.alphas.len(),
        grid.views.len(),
        grid.exits.len(),
        grid.azimuths.len()
    );
    let at = |e: &LobeExtreme| {
        format!(
            "{:+.1}% +- {:.1}% (view {}, exit {}{}{})",
            100.0 * e.deviation,
            100.0 * e.confidence,
            e.view,
            e.exit,
            e.azimuth
                .map(|p| format!(", {} deg", kiln::error::brief(p.to_degrees())))
                .unwrap_or_default(),
            if white {
                String::new()
            } else {
                format!(", F0 {}", e.f0)
            }
        )
    };
    let mut last = None;
    for summary in &audit.summaries {
        if last != Some(summary.compensation) {
            last = Some(summary.compensation);
            let same = if summary.compensation == Compensation::Kiln && white {
                " (at F = 1 kiln's lobe is Kulla-Conty's)"
            } else {
                ""
            };
            println!("  {}{same}", summary.compensation.name());
        }
        let mut rows = vec![("averaged", &summary.averaged)];
        if let Some(full) = &summary.full {
            rows.push(("in full", full));
        }
        for (what, f) in rows {
            println!(
                "    r = {:<5} {what:<9} {} to {}, rms {:.1}%, confidence up to +- {:.1}%",
                kiln::error::brief(RoughnessConvention::Perceptual.from_alpha(summary.alpha)),
                at(&f.lowest),
                at(&f.highest),
                100.0 * f.rms,
                100.0 * f.widest_confidence
            );
        }
    }
    if !compensations.contains(&Compensation::Kiln) {
        if white {
            println!("  kiln: at F = 1 its lobe is Kulla-Conty's (M(mu, 1) = 1 - E is pinned)");
        } else {
            println!(
                "  kiln: give its baked --table (kiln compensation --bake DIR) to measure its lobe"
            );
        }
    }
}
