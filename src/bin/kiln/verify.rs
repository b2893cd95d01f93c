//! `kiln verify`.

use crate::args::{SEE_CONVENTIONS, parse_error_bound, parse_number};
use crate::fresnel_args::FresnelArgs;
use clap::Args;
use kiln::format::Precision;
use kiln::integrate::reference::ReferenceSettings;
use kiln::verify::furnace::furnace;
use kiln::verify::input::{AxisName, Encoding, Layout, read_external, read_kiln};
use kiln::verify::{Against, AuditSettings, Point, Progress, audit};
use kiln::{Axis, Grid, Masking, Model, MuMapping, Ndf, Quantity, RoughnessConvention, Table};
use std::path::{Path, PathBuf};

mod anisotropy;
mod fit;

/// Audit a table (or a texture-free fit, --fit) against the deterministic reference (or another table).
#[derive(Args, Debug, Clone)]
#[command(
    long_about = "Audit a table, kiln's or an engine's. Reports the error of the stored values at \
                  the coordinates the table says it was computed at (node_max_error, \
                  node_rms_error) and of its bilinear lookup, with its own grid convention, on a \
                  dense set of points between the nodes including the axis ends \
                  (lookup_max_error, lookup_rms_error, lookup_p99_error), each with the worst \
                  point. Every file kiln writes carries its layout (JSON, EXR, KTX2, C and Rust \
                  in themselves; binary and DDS through the JSON sidecar beside them); for any \
                  other table give it with --shape, --order, --grid, --roughness-axis, \
                  --mu-axis, --clamp-min and the model flags, and for an engine's own file name \
                  its layout with --preset. --max-error X --quiet makes it a build gate.",
    after_help = SEE_CONVENTIONS
)]
pub struct VerifyArgs {
    /// The table to audit: a kiln output, a text file of numbers (whitespace or commas, '#'
    /// comments), raw little-endian floats (--dtype) or an EXR channel (--channel). Not with
    /// --fit, which audits a formula instead of a file of numbers.
    #[arg(required_unless_present_any = ["fit", "anisotropy_convention"])]
    file: Option<PathBuf>,
    /// Audit how an engine compensates an anisotropic GGX lobe with its isotropic E table,
    /// read at one roughness: kulla-conty (Filament, Unreal: the arithmetic mean of alpha_x
    /// and alpha_y; alias arithmetic-mean), disney (Cycles, Enterprise PBR: the geometric mean;
    /// alias geometric-mean), gltf (KHR_materials_anisotropy: the bitangent's roughness; alias
    /// minimum), openpbr (the root mean square; alias rms). Compares the isotropic reference
    /// with the anisotropic lobe's over r, anisotropy, mu and the view's azimuth, and reports
    /// the maximum error and where (--plot: a map per anisotropy).
    #[arg(long, value_enum, hide_possible_values = true, conflicts_with_all = ["file", "fit", "furnace", "preset", "shape",
        "channel", "dtype", "order", "grid", "roughness_axis", "mu_axis", "roughness_spacing",
        "texels", "quantity", "average", "clamp_min", "density", "only", "form", "against"])]
    anisotropy_convention: Option<kiln::model::AnisotropyConvention>,
    /// Audit a texture-free fit instead of a table: karis (UE4 mobile EnvBRDFApprox), materialx
    /// (mx_ggx_dir_albedo_analytic), unreal (UE5's analytic GGXEnergyLookup), or a formula
    /// file (TOML: name = "...", optional define = ["k = max(r, 1e-3)", ...], and formulas
    /// E, E_scale and/or E_bias in mu, r and alpha = r^2; see docs/fits.md). Reports each
    /// quantity's maximum error over mu and r in [0, 1] against the reference for the model
    /// of --ndf and --masking (default GGX height-correlated), and where it is.
    #[arg(long, value_name = "NAME|FILE.toml", conflicts_with_all = ["file", "furnace",
        "preset", "shape", "channel", "dtype", "order", "grid", "roughness_axis", "mu_axis",
        "roughness_spacing", "texels", "quantity", "average", "clamp_min", "density", "only",
        "form", "against"])]
    fit: Option<String>,
    /// With --fit: points per axis of the (sqrt(mu), r) grid the fit is compared on, the ends
    /// included; a finer grid then surrounds each quantity's worst point.
    #[arg(long, default_value_t = 129, requires = "fit",
        value_parser = clap::value_parser!(u32).range(2..=1025))]
    points: u32,
    /// What to compare with: 'reference' (the deterministic quadrature) or another table's file.
    #[arg(long, default_value = "reference")]
    against: String,
    /// White furnace test instead of an audit: does energy compensation with FILE's E table
    /// give back exactly what single scattering loses? kulla-conty: the lobe f_ms normalised
    /// by the f_ms_norm table (else E_avg) found beside FILE or given with --average,
    /// E + albedo(f_ms) - 1 over a fine roughness and mu ladder; turquin: single scattering
    /// scaled by 1 / E_lookup, E_true / E_lookup - 1 at the lookup audit's points (against the
    /// reference: seconds). --max-error applies to the worst over the forms checked.
    #[arg(long, conflicts_with = "against")]
    furnace: bool,
    /// With --furnace: the compensation forms to check, comma-separated [default: both].
    #[arg(long, value_enum, value_delimiter = ',', requires = "furnace")]
    form: Option<Vec<kiln::verify::furnace::Form>>,
    /// Draw where the table is wrong into this .svg or .png file: the node and the lookup error
    /// over the table's axes (heat maps on a log colour scale, or error against roughness for
    /// E_avg; for a table with an IOR axis, the slice of the worst point), the worst point
    /// ringed. With --furnace: the deviation of each form over (mu, r) instead. With --preset
    /// and several tables, one file per table, its quantity added to the name (plot-E_bias.svg).
    #[arg(long)]
    plot: Option<PathBuf>,
    /// The E_avg table for --furnace (default: beside FILE).
    #[arg(long, requires = "furnace")]
    average: Option<PathBuf>,
    /// Print one JSON object instead of text (one per table with --preset).
    #[arg(long)]
    json: bool,
    /// FILE is an engine's own table in that engine's layout (cycles: shader.tables with
    /// table_ggx_E, table_ggx_Eavg and the glass arrays, those in Cycles' convention; bevy:
    /// dfg.ktx2, zstd or not; three: the DFG LUT's Uint16Array; enterprise-pbr: GGX_E.exr or
    /// GGX_E_avg.exr; filament: dfg.inc, RGB or RG half bits; godot: dfg_lut.dds; unity-hdrp and unreal: their EXR; games202:
    /// GGX_E_LUT.png or GGX_Eavg_LUT.png, told apart by their rows): audit each of its tables
    /// against the reference for the model the engine evaluates (GGX, height-correlated; Godot
    /// and GAMES202: separable Schlick-GGX), with what half-float or 8-bit storage alone costs
    /// beside the measured error; a blue channel (Filament's and Godot's cloth, HDRP's
    /// Disney diffuse) is compared with kiln's values at its texels (node errors only).
    #[arg(long, value_enum, conflicts_with_all = ["furnace", "shape", "channel", "dtype",
        "order", "grid", "roughness_axis", "mu_axis", "roughness_spacing", "texels", "ndf",
        "masking", "quantity"])]
    preset: Option<kiln::preset::Preset>,
    /// With --preset: audit only these of the file's tables, comma-separated (e,e-avg of a
    /// Cycles shader.tables skips its four glass arrays, whose audit takes most of a minute).
    #[arg(long, value_enum, value_delimiter = ',', requires = "preset")]
    only: Option<Vec<Quantity>>,
    /// Exit with status 1 when node_max_error exceeds this (lookup_max_error for a table of
    /// texels fitted for the lookup, `kiln bake --texels lookup-fit`).
    #[arg(long, value_parser = parse_error_bound, allow_negative_numbers = true)]
    max_error: Option<f64>,
    /// Lookup points per texel along each axis.
    #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u32).range(1..=64))]
    density: u32,
    /// The smallest coordinate the table was actually computed at, on both axes [default: 0;
    /// 1e-4 for a Cycles file not written by kiln, as Blender computes its tables there].
    #[arg(long, value_parser = parse_clamp, allow_negative_numbers = true)]
    clamp_min: Option<f64>,
    /// External tables: raw little-endian floats of this type (otherwise text is expected).
    #[arg(long, value_enum)]
    dtype: Option<Precision>,
    /// External tables: read this channel of an EXR file.
    #[arg(long, conflicts_with = "dtype")]
    channel: Option<String>,
    /// External tables: sizes, slowest-varying axis first: 32x32 for E, 32 for E_avg (one size
    /// means an E_avg table unless --quantity says otherwise).
    #[arg(long, value_parser = parse_shape)]
    shape: Option<Shape>,
    /// External tables: the axes, slowest-varying first [default: r,mu for E; r for E_avg].
    #[arg(long, value_enum, value_delimiter = ',')]
    order: Option<Vec<AxisName>>,
    /// External tables: where samples sit [default: centers, as GPU textures are sampled].
    #[arg(long, value_enum)]
    grid: Option<Grid>,
    /// External tables: the roughness axis, r (alpha = r^2) or alpha [default: r].
    #[arg(long, value_enum)]
    roughness_axis: Option<RoughnessConvention>,
    /// External tables: the mu axis spacing [default: linear, as engines' tables are].
    #[arg(long, value_enum)]
    mu_axis: Option<MuMapping>,
    /// External tables: the rows, linear or balanced [default: balanced with --mu-axis balanced].
    #[arg(long, value_enum, hide_possible_values = true)]
    roughness_spacing: Option<kiln::RoughnessSpacing>,
    /// External tables: nodes, or lookup-fit to judge the lookup (as kiln's fitted tables).
    #[arg(long, value_enum, hide_possible_values = true)]
    texels: Option<kiln::table::Texels>,
    /// External tables: the normal distribution [default: ggx].
    #[arg(long, value_enum)]
    ndf: Option<Ndf>,
    /// External tables: the Smith G2 form [default: height-correlated].
    #[arg(long, value_enum)]
    masking: Option<Masking>,
    /// External tables: what the numbers are (e-f: the Fresnel-weighted albedo of the model
    /// the Fresnel flags name) [default: e-avg for a one-size --shape, else e].
    #[arg(long, value_enum)]
    quantity: Option<Quantity>,
    #[command(flatten)]
    fresnel: FresnelArgs,
    /// Print nothing but errors: the exit status says whether the table passed --max-error
    /// (0 passed, 1 failed, 2 could not be read), and a failing check prints one line on
    /// stderr. For build gates. Not with --json, which prints the report.
    #[arg(long, short, conflicts_with = "json")]
    quiet: bool,
}

fn parse_clamp(text: &str) -> Result<f64, String> {
    let value = parse_number(text)?;
    if (0.0..1.0).contains(&value) {
        Ok(value)
    } else {
        Err(format!("clamp-min must be in [0, 1) (got {text})"))
    }
}

/// Table sizes, slowest-varying axis first.
#[derive(Clone, Debug)]
struct Shape(Vec<usize>);

fn parse_shape(text: &str) -> Result<Shape, String> {
    let sizes: Result<Vec<usize>, _> = text
        .split(['x', 'X'])
        .map(|s| s.trim().parse::<usize>())
        .collect();
    match sizes {
        Ok(sizes)
            if (1..=2).contains(&sizes.len())
                && sizes.iter().all(|&n| (2..=65536).contains(&n)) =>
        {
            Ok(Shape(sizes))
        }
        _ => Err(format!(
            "shape must be like 32x32 or 32, each size 2 to 65536 (got {text})"
        )),
    }
}

impl VerifyArgs {
    /// The file audited (clap requires it unless --fit is given, which never asks for it).
    pub fn file(&self) -> &Path {
        self.file.as_deref().unwrap_or(Path::new("-"))
    }

    /// The external-layout flags given on the command line: a kiln file carries its own layout,
    /// so these are errors with one.
    fn layout_flags_given(&self) -> Vec<&'static str> {
        crate::args::given(&[
            ("--shape", self.shape.is_some()),
            ("--order", self.order.is_some()),
            ("--grid", self.grid.is_some()),
            ("--roughness-axis", self.roughness_axis.is_some()),
            ("--mu-axis", self.mu_axis.is_some()),
            ("--roughness-spacing", self.roughness_spacing.is_some()),
            ("--texels", self.texels.is_some()),
            ("--ndf", self.ndf.is_some()),
            ("--masking", self.masking.is_some()),
            ("--quantity", self.quantity.is_some()),
            ("the Fresnel flags", self.fresnel.given()),
        ])
    }

    /// The quantity of an external table: `--quantity`, else `E_avg` for a one-size shape and
    /// `E` otherwise.
    /// The audit's settings from the flags: `--clamp-min` (0 unless given), `--density`.
    fn audit_settings(&self, storage: Option<kiln::verify::Storage>) -> AuditSettings {
        AuditSettings {
            clamp_min: self.clamp_min.unwrap_or(0.0),
            density: self.density as usize,
            storage,
        }
    }

    fn quantity(&self, shape: &[usize]) -> Quantity {
        self.quantity.unwrap_or(if shape.len() == 1 {
            Quantity::EAvg
        } else {
            Quantity::E
        })
    }

    fn layout(&self, path: &Path) -> kiln::Result<Layout> {
        // kiln's pictures and lookup code are not tables: say which file is.
        let extension = path.extension().and_then(|e| e.to_str()).unwrap_or("");
        let what = match extension {
            "png" => Some("an 8-bit heat map (a picture of the table)"),
            "wgsl" | "glsl" | "hlsl" => Some("shader code that samples the table's texture"),
            _ => None,
        };
        if let (Some(what), None) = (what, &self.shape) {
            let sidecar = path.with_extension("json");
            let stem = path.with_extension("");
            return Err(kiln::Error::InvalidInput(if sidecar.is_file() {
                format!(
                    "{} is {what}, not the table's numbers, which kiln does not read back: \
                     verify the table itself, {} (or its .exr, .bin, .ktx2, .rs or .h)",
                    path.display(),
                    sidecar.display()
                )
            } else {
                format!(
                    "{} is {what} if kiln wrote it, not a table kiln reads: verify the table \
                     it was made from ({}.json, .exr, ...); an engine's PNG table is read with \
                     --preset games202",
                    path.display(),
                    stem.display()
                )
            }));
        }
        let Shape(shape) = self.shape.clone().ok_or_else(|| {
            kiln::Error::InvalidInput(format!(
                "{} is not a kiln table (no kiln metadata in it or a sidecar beside it): give \
                 its layout, at least --shape (e.g. --shape 32x32 --order mu,r for an E table, \
                 --shape 32 for E_avg), or --preset NAME for an engine's file",
                path.display()
            ))
        })?;
        let quantity = self.quantity(&shape);
        let order = self.order.clone().unwrap_or(if quantity.has_mu() {
            vec![AxisName::R, AxisName::Mu]
        } else {
            vec![AxisName::R]
        });
        let fresnel = match (quantity, self.fresnel.given()) {
            (Quantity::EF, true) => {
                let model = self.fresnel.model()?;
                if !model.is_grey() {
                    return Err(kiln::Error::InvalidInput(
                        "--quantity e-f audits one channel: give one value per Fresnel \
                         parameter (that channel's)"
                            .into(),
                    ));
                }
                Some(model)
            }
            (Quantity::EF, false) => {
                return Err(kiln::Error::InvalidInput(
                    "--quantity e-f needs the Fresnel model the table was computed for, e.g. \
                     --f0 0.04 or --ior 1.5"
                        .into(),
                ));
            }
            (_, true) => {
                return Err(kiln::Error::InvalidInput(format!(
                    "the Fresnel flags apply to --quantity e-f only (a {} table is for F = 1)",
                    quantity.symbol()
                )));
            }
            (_, false) => None,
        };
        let mu_mapping = self.mu_axis.unwrap_or(MuMapping::Linear);
        Ok(Layout {
            model: Model {
                ndf: self.ndf.unwrap_or(Ndf::Ggx),
                masking: self.masking.unwrap_or(Masking::HeightCorrelated),
            },
            quantity,
            fresnel,
            shape,
            order,
            grid: self.grid.unwrap_or(Grid::Centers),
            roughness: self
                .roughness_axis
                .unwrap_or(RoughnessConvention::Perceptual),
            mu_mapping,
            roughness_spacing: self
                .roughness_spacing
                .unwrap_or_else(|| kiln::RoughnessSpacing::paired_with(mu_mapping)),
            texels: self.texels.unwrap_or_default(),
        })
    }

    fn load(&self, path: &Path) -> kiln::Result<Table> {
        if self.channel.is_none()
            && self.dtype.is_none()
            && let Some(table) = read_kiln(path)?
        {
            let given = self.layout_flags_given();
            if !given.is_empty() {
                return Err(kiln::Error::InvalidInput(format!(
                    "{} is a kiln table and carries its own layout ({} {}, {}); {} describe \
                     external tables and would be ignored: drop {}",
                    path.display(),
                    table.spec.model,
                    table.spec.quantity.symbol(),
                    table
                        .spec
                        .shape()
                        .iter()
                        .map(ToString::to_string)
                        .collect::<Vec<_>>()
                        .join("x"),
                    given.join(", "),
                    if given.len() == 1 { "it" } else { "them" }
                )));
            }
            return Ok(table);
        }
        let is_exr = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("exr"));
        if is_exr && self.channel.is_none() {
            return Err(kiln::Error::InvalidInput(format!(
                "{} is an EXR without kiln's metadata: name the channel to read with --channel \
                 and give the layout (--shape, --order, ...)",
                path.display()
            )));
        }
        let encoding = match (&self.channel, self.dtype) {
            (Some(name), _) => Encoding::ExrChannel(name.clone()),
            (None, Some(dtype)) => Encoding::Raw(dtype),
            (None, None) => Encoding::Text,
        };
        read_external(path, &encoding, &self.layout(path)?)
    }
}

fn describe(point: &Point, convention: &str) -> String {
    let mut at = match point.mu {
        Some(mu) => format!("mu = {mu:.6}, "),
        None => String::new(),
    };
    if let Some(eta) = point.eta {
        at += &format!("eta = {eta:.6}, ");
    }
    if convention == "none" {
        // F_avg: no roughness axis.
        return format!(
            "eta = {:.6}: table {:.7}, reference {:.7}",
            point.eta.unwrap_or(1.0),
            point.table,
            point.reference
        );
    }
    format!(
        "{at}{convention} = {:.6} (alpha {:.3e}): table {:.7}, reference {:.7}",
        point.roughness, point.alpha, point.table, point.reference
    )
}

/// The file beside a kiln `E` table's file (`NAME.EXT`, named as kiln names it) holding its
/// normalisation: `f_ms_norm` if it is there, else `E_avg`.
fn sibling_normalisation(path: &Path, table: &Table) -> kiln::Result<PathBuf> {
    let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or("");
    let extension = path.extension().and_then(|e| e.to_str()).unwrap_or("");
    if stem != table.spec.id() {
        return Err(kiln::Error::InvalidInput(format!(
            "{} is not named as kiln names its E table ({}.{extension}): give its f_ms_norm or \
             E_avg table with --average",
            path.display(),
            table.spec.id()
        )));
    }
    let norm = kiln::table::normalisation::spec_for(&table.spec).id();
    let average = kiln::TableSpec {
        quantity: Quantity::EAvg,
        mu: None,
        ..table.spec.clone()
    }
    .id();
    let candidates = [norm, average].map(|id| path.with_file_name(format!("{id}.{extension}")));
    candidates
        .iter()
        .find(|candidate| candidate.is_file())
        .cloned()
        .ok_or_else(|| {
            kiln::Error::InvalidInput(format!(
                "found neither {} nor {} beside {}: give the normalisation with --average",
                candidates[0].display(),
                candidates[1].display(),
                path.display()
            ))
        })
}

fn run_furnace(args: &VerifyArgs, table: &Table) -> kiln::Result<bool> {
    use kiln::verify::furnace::{Form, FormReport, turquin};
    let glass = matches!(
        table.spec.quantity,
        Quantity::EDielectric | Quantity::EDielectricInside
    );
    if !glass && table.spec.quantity != Quantity::E {
        return Err(kiln::Error::InvalidInput(format!(
            "--furnace tests an E table with its normalisation: {} holds {}; give the E file \
             (NAME-E.EXT), whose f_ms_norm or E_avg is found beside it or given with --average",
            args.file().display(),
            table.spec.quantity.symbol()
        )));
    }
    if glass
        && args
            .form
            .as_deref()
            .is_some_and(|f| f.contains(&Form::KullaConty))
    {
        return Err(kiln::Error::InvalidInput(format!(
            "{} is a glass table: kiln checks Turquin's 1 / E compensation of it (--form \
             turquin); the Kulla-Conty lobe of glass is not in this version",
            args.file().display()
        )));
    }
    let forms = args.form.clone().unwrap_or_else(|| {
        if glass {
            vec![Form::Turquin]
        } else {
            vec![Form::KullaConty, Form::Turquin]
        }
    });
    let plot_kind = plot_kind(args)?;
    let normalisation = match forms.contains(&Form::KullaConty) {
        true => {
            let average_path = match &args.average {
                Some(path) => path.clone(),
                None => sibling_normalisation(args.file(), table)?,
            };
            let average = args.load(&average_path)?;
            Some((average_path, average))
        }
        false => None,
    };
    let kulla_conty = match &normalisation {
        Some((path, average)) => Some((
            path.clone(),
            furnace(table, average, args.density as usize)?,
        )),
        None => None,
    };
    let turquin_report = match forms.contains(&Form::Turquin) {
        true => {
            let settings = args.audit_settings(None);
            let points = kiln::verify::lookup_coordinate_count(&table.spec, &settings);
            // The furnace's truth is the reference at 1e-9 (TURQUIN_TRUTH_TOLERANCE); a glass
            // table's points cost four times what the bake's figures say (measured at 1e-10:
            // the 16 x 16 x 16 E_dielectric's 65340 points took 137 s on 2 threads, 2026-12-03,
            // 4.2 ms each).
            let glass = if table.spec.ior.is_some() { 4.0 } else { 1.0 };
            crate::announce_cost(
                points as f64 * glass * kiln::bake::reference_seconds_per_point(&table.spec, 9),
                args.quiet || args.json,
            );
            let bar = crate::progress_bar(args.quiet || args.json, points, "turquin");
            let report = turquin(table, &settings, &|| bar.inc(1))?;
            bar.finish_and_clear();
            Some(report)
        }
        false => None,
    };
    let form_reports: Vec<FormReport> = kulla_conty
        .iter()
        .map(|(_, report)| FormReport::of_kulla_conty(report))
        .chain(turquin_report)
        .collect();
    if let (Some(path), Some(svg), Some(Axis::Ior { max, .. })) =
        (&args.plot, plot_kind, table.spec.ior)
    {
        // A glass table: the furnace's own points, binned over mu and eta (worst over
        // roughness), with its worst point ringed.
        let report = form_reports.iter().find(|f| f.form == Form::Turquin);
        let maps: Vec<_> = report.and_then(|r| r.map.clone()).into_iter().collect();
        let marks = vec![report.map(|r| {
            let (x, y) = kiln::verify::furnace::glass_map_position(
                r.worst_mu,
                r.worst_eta.unwrap_or(1.0),
                max.0,
            );
            crate::plot::FurnaceMark {
                x,
                y,
                mu: r.worst_mu,
                roughness: r.worst_roughness,
                eta: r.worst_eta,
                deviation: r.deviation,
            }
        })];
        let title = format!(
            "{}: Turquin furnace deviation, worst over roughness (blue: lost, red: added)",
            table.spec.id()
        );
        write_plot(path, svg, crate::plot::furnace_plot(&title, &maps, &marks))?;
    } else if let (Some(path), Some(svg)) = (&args.plot, plot_kind) {
        let maps = kiln::verify::furnace::furnace_maps(
            table,
            normalisation.as_ref().map(|(_, t)| t),
            &forms,
            64,
            64,
        )?;
        // The command's worst point of each form, ringed on its map and stated in its caption.
        let convention = table.spec.roughness_convention();
        let marks: Vec<Option<crate::plot::FurnaceMark>> = maps
            .iter()
            .map(|map| {
                let report = form_reports.iter().find(|f| f.form == map.form)?;
                let kiln::Axis::Mu { mapping, size, .. } = table.spec.mu? else {
                    return None;
                };
                let alpha = convention.to_alpha(report.worst_roughness);
                Some(crate::plot::FurnaceMark {
                    x: mapping.coordinate(report.worst_mu, alpha, size),
                    y: report.worst_roughness,
                    mu: report.worst_mu,
                    roughness: report.worst_roughness,
                    eta: None,
                    deviation: report.deviation,
                })
            })
            .collect();
        let title = format!(
            "{}: white furnace deviation (blue: energy lost, red: added)",
            table.spec.id()
        );
        write_plot(path, svg, crate::plot::furnace_plot(&title, &maps, &marks))?;
    }
    let max_deviation = kiln::stats::max_or_nan(form_reports.iter().map(|f| f.max_deviation));
    let passed = args.max_error.is_none_or(|bound| max_deviation <= bound);
    if args.json {
        let mut object = match &kulla_conty {
            Some((path, report)) => {
                let mut object = json_report(report, args, passed);
                object["average"] = path.display().to_string().into();
                object
            }
            None => json_report(&serde_json::json!({}), args, passed),
        };
        object["max_deviation"] = max_deviation.into();
        object["forms"] = serde_json::to_value(&form_reports).expect("reports serialise");
        println!("{object}");
        return Ok(passed);
    }
    if args.quiet {
        quiet_verdict(args, passed, "furnace max deviation", max_deviation);
        return Ok(passed);
    }
    if let Some((path, report)) = &kulla_conty {
        print_kulla_conty(args, table, path, report);
    }
    if let Some(t) = form_reports.iter().find(|f| f.form == Form::Turquin) {
        println!(
            "{}: white furnace test of Turquin's 1 / E scaling: max |E_true / E_lookup - 1| = \
             {:.2e} at mu = {:.3e}, {} = {:.4}{} (the lookup audit's points against the reference)",
            args.file().display(),
            t.max_deviation,
            t.worst_mu,
            table.spec.roughness_convention().name(),
            t.worst_roughness,
            t.worst_eta
                .map(|eta| format!(", eta = {eta:.4}"))
                .unwrap_or_default()
        );
        if !t.eta_bands.is_empty() {
            println!("         eta (or 1 / eta)     max |dev|      at eta       at r      at mu");
            for band in &t.eta_bands {
                println!(
                    "    {:>6.3} - {:<10}  {:>12.2e}  {:>10.5}  {:>9.4}  {:>9.3e}",
                    band.lower,
                    if band.upper.is_finite() {
                        format!("{:.3}", band.upper)
                    } else {
                        "max".to_string()
                    },
                    band.max_deviation,
                    band.worst_eta,
                    band.worst_roughness,
                    band.worst_mu
                );
            }
        }
    }
    print_verdict(args.max_error, passed, "max deviation", max_deviation);
    Ok(passed)
}

/// The text report of the Kulla-Conty form.
fn print_kulla_conty(
    args: &VerifyArgs,
    table: &Table,
    average_path: &Path,
    report: &kiln::verify::furnace::FurnaceReport,
) {
    let convention = table.spec.roughness_convention().name();
    println!(
        "{} with {} ({}): white furnace test of the Kulla-Conty lobe, {} roughness values",
        args.file().display(),
        average_path.display(),
        report.normalisation,
        report.rows.len()
    );
    let w = &report.worst;
    println!(
        "  max |E + albedo(f_ms) - 1| = {:.2e} at mu = {:.3e}, {convention} = {:.4} (alpha {:.3e}): \
         the lobe's 1 - E_avg is {:.4e}, the average of the E lookup {:.4e} (mismatch {:+.2e})",
        report.max_deviation,
        w.worst_mu,
        w.roughness,
        w.alpha,
        w.one_minus_e_avg,
        w.one_minus_e_avg_of_e,
        w.relative_mismatch
    );
    println!(
        "  {:>15} {:>13} {:>10} {:>10}",
        convention, "max |dev|", "at r", "at mu"
    );
    for band in &report.bands {
        println!(
            "  {:>6.2} - {:<6.2} {:>13.2e} {:>10.5} {:>10.3e}",
            band.from, band.to, band.max_deviation, band.worst_roughness, band.worst_mu
        );
    }
}

/// The `--max-error` line of the text report.
fn print_verdict(bound: Option<f64>, passed: bool, what: &str, value: f64) {
    if let Some(bound) = bound {
        let verdict = if passed { "passes" } else { "FAILS" };
        println!("  {verdict} --max-error {bound:e} ({what} {value:.2e})");
    }
}

/// With `--quiet`: one line on stderr when the check failed, nothing otherwise.
fn quiet_verdict(args: &VerifyArgs, passed: bool, what: &str, value: f64) {
    if let (false, Some(bound)) = (passed, args.max_error) {
        eprintln!(
            "kiln: {}: {what} {value:.2e} exceeds --max-error {bound:e}",
            args.file().display()
        );
    }
}

/// A report as one JSON object, with the file and the `--max-error` verdict.
fn json_report(
    report: &impl serde::Serialize,
    args: &VerifyArgs,
    passed: bool,
) -> serde_json::Value {
    let mut object = serde_json::to_value(report).expect("a report serialises");
    object["file"] = args.file().display().to_string().into();
    if let Some(bound) = args.max_error {
        object["max_error"] = bound.into();
        object["passed"] = passed.into();
    }
    object
}

/// Returns whether the table passed `--max-error` (always true without it).
pub fn run(args: VerifyArgs) -> kiln::Result<bool> {
    if let Some(fit) = &args.fit {
        return fit::run(&args, fit);
    }
    if let Some(convention) = args.anisotropy_convention {
        return anisotropy::run(&args, convention);
    }
    if let Some(preset) = args.preset {
        let bytes = kiln::format::read_file(args.file())?;
        // Name the file in what the layout's reader says.
        let in_file = |e: kiln::Error| match e {
            kiln::Error::InvalidInput(m) if !m.contains(&args.file().display().to_string()) => {
                kiln::Error::InvalidInput(format!("{}: {m}", args.file().display()))
            }
            other => other,
        };
        let mut tables = preset
            .read_tables(&bytes, &args.file().display().to_string())
            .map_err(in_file)?;
        if let Some(only) = &args.only {
            if let Some(missing) = only
                .iter()
                .find(|q| !tables.iter().any(|t| t.spec.quantity == **q))
            {
                let held: Vec<&str> = tables.iter().map(|t| t.spec.quantity.cli_name()).collect();
                return Err(kiln::Error::InvalidInput(format!(
                    "{}: --only names {}, but the file holds {} in the {} layout",
                    args.file().display(),
                    missing.cli_name(),
                    held.join(", "),
                    preset.name()
                )));
            }
            tables.retain(|t| only.contains(&t.spec.quantity));
        }
        let args = &VerifyArgs {
            clamp_min: args.clamp_min.or(Some(preset.computed_from(&bytes))),
            ..args.clone()
        };
        plot_kind(args)?;
        let several = tables.len() > 1;
        if let Some(path) = args.plot.as_ref().filter(|_| several && !args.quiet) {
            let names: Vec<String> = tables
                .iter()
                .map(|t| plot_for(path, t).display().to_string())
                .collect();
            eprintln!(
                "kiln: --plot: the file holds {} tables, so one picture each: {}",
                tables.len(),
                names.join(", ")
            );
        }
        // One estimate and one bar for the whole file.
        let quiet = args.quiet || args.json;
        let audited = |t: &&Table| t.spec.quantity != Quantity::FMsNorm;
        let settings = args.audit_settings(None);
        for table in tables.iter().filter(audited) {
            check_audit_size(args, table)?;
        }
        let seconds: f64 = tables
            .iter()
            .filter(audited)
            .map(|t| audit_core_seconds(t, &settings))
            .sum();
        crate::announce_cost(seconds, quiet);
        let bar = crate::progress_bar(quiet, (seconds * 1e6) as u64, "verifying");
        let mut passed = true;
        for table in &tables {
            let args = &VerifyArgs {
                plot: args
                    .plot
                    .as_ref()
                    .filter(|_| several)
                    .map(|path| plot_for(path, table))
                    .or_else(|| args.plot.clone()),
                ..args.clone()
            };
            passed &= if table.spec.quantity == Quantity::FMsNorm {
                let e_path = args.file().with_file_name(preset.file_name());
                let e_bytes = kiln::format::read_file(&e_path)?;
                let e = preset
                    .read_tables(&e_bytes, &e_path.display().to_string())?
                    .into_iter()
                    .find(|t| t.spec.quantity == Quantity::E)
                    .ok_or_else(|| {
                        kiln::Error::InvalidInput(format!("{}: no E table", e_path.display()))
                    })?;
                normalisation_audit(args, table, &e, &e_path)?
            } else {
                audit_one(args, table, preset.storage_of(&bytes), Some(&bar))?
            };
        }
        bar.finish_and_clear();
        if let Some(audit) = preset.audit_extra(&bytes).map_err(in_file)? {
            passed &= audit_extra(args, &audit);
        }
        return Ok(passed);
    }
    plot_kind(&args)?;
    let table = args.load(args.file())?;
    check_audit_size(&args, &table)?;
    if args.furnace {
        return run_furnace(&args, &table);
    }
    if table.spec.quantity == Quantity::FMsNorm && args.against == "reference" {
        return run_normalisation_audit(&args, &table);
    }
    audit_one(&args, &table, None, None)
}

/// [`kiln::verify::check_audit_size`] for `table` at the command's density, naming the file:
/// refused before any point is made.
fn check_audit_size(args: &VerifyArgs, table: &Table) -> kiln::Result<()> {
    kiln::verify::check_audit_size(&table.spec, &args.audit_settings(None)).map_err(|e| match e {
        kiln::Error::InvalidInput(m) => {
            kiln::Error::InvalidInput(format!("{}: {m}", kiln::error::escaped_path(args.file())))
        }
        other => other,
    })
}

/// Audits an `f_ms_norm` table against the average of its E table's lookup (the E table beside
/// it, named as kiln names it), and prints the report; whether it passed `--max-error`
/// (relative error of the lookup).
fn run_normalisation_audit(args: &VerifyArgs, table: &Table) -> kiln::Result<bool> {
    let source = table.spec.lookup_of.as_deref().ok_or_else(|| {
        kiln::Error::InvalidInput(format!(
            "{}: no lookup_of in its spec",
            args.file().display()
        ))
    })?;
    let extension = args
        .file()
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("json");
    let e_path = args
        .file()
        .with_file_name(format!("{}.{extension}", source.id()));
    if !e_path.is_file() {
        return Err(kiln::Error::InvalidInput(format!(
            "{} is the normalisation of an E table's lookup: its E table {} must be beside it",
            args.file().display(),
            e_path.display()
        )));
    }
    let e = args.load(&e_path)?;
    normalisation_audit(args, table, &e, &e_path)
}

/// Audits `table` (`f_ms_norm`) against the average of the lookup of `e` (read from
/// `e_path`), prints the report, and returns whether it passed `--max-error`.
fn normalisation_audit(
    args: &VerifyArgs,
    table: &Table,
    e: &Table,
    e_path: &std::path::Path,
) -> kiln::Result<bool> {
    let report = kiln::verify::furnace::audit_normalisation(e, table)?;
    let passed = args
        .max_error
        .is_none_or(|bound| report.lookup_max_relative_error <= bound);
    if args.json {
        println!("{}", json_report(&report, args, passed));
    } else if args.quiet {
        quiet_verdict(
            args,
            passed,
            "lookup relative error",
            report.lookup_max_relative_error,
        );
    } else {
        println!(
            "{}: f_ms_norm, {} entries, against the average of the lookup of {}",
            args.file().display(),
            report.nodes + 1,
            e_path.display()
        );
        println!(
            "  nodes   {:>6}: max relative error {:.2e}",
            report.nodes, report.node_max_relative_error
        );
        println!(
            "  lookups {:>6}: max relative error {:.2e} at {} = {:.6}",
            report.lookup_points,
            report.lookup_max_relative_error,
            table.spec.roughness_convention().name(),
            report.worst_roughness
        );
        print_verdict(
            args.max_error,
            passed,
            "lookup relative error",
            report.lookup_max_relative_error,
        );
    }
    Ok(passed)
}

/// Audits an engine file's channel that is not one of kiln's tables (Filament's and Godot's
/// cloth albedo, HDRP's Disney diffuse) at its texels against kiln's values there, and prints
/// the report; whether it passed `--max-error`.
fn audit_extra(args: &VerifyArgs, audit: &kiln::preset::ExtraAudit) -> bool {
    let passed = args.max_error.is_none_or(|bound| audit.max_error <= bound);
    if args.json {
        let mut object = serde_json::json!({
            "file": args.file().display().to_string(),
            "channel": audit.name,
            "texels": audit.texels,
            "node_max_error": audit.max_error,
            "node_rms_error": audit.rms_error,
            "worst_node": {"alpha": audit.worst_alpha, "mu": audit.worst_mu,
                           "table": audit.worst_table, "reference": audit.worst_reference},
            "reference_error_estimate": audit.reference_error,
        });
        if let Some(bound) = args.max_error {
            object["max_error"] = bound.into();
            object["passed"] = passed.into();
        }
        println!("{object}");
    } else if args.quiet {
        quiet_verdict(args, passed, "blue channel node max error", audit.max_error);
    } else {
        println!(
            "{}: blue channel, {} ({} texels, against kiln's values, error estimate {:.0e})",
            args.file().display(),
            audit.name,
            audit.texels,
            audit.reference_error
        );
        println!(
            "  nodes   {:>6}: max error {:.2e}, rms {:.2e}; worst at mu = {:.6}, r = {:.6} \
             (alpha {:.3e}): table {:.7}, reference {:.7}",
            audit.texels,
            audit.max_error,
            audit.rms_error,
            audit.worst_mu,
            audit.worst_alpha.sqrt(),
            audit.worst_alpha,
            audit.worst_table,
            audit.worst_reference
        );
        print_verdict(args.max_error, passed, "node max error", audit.max_error);
    }
    passed
}

/// `plot.svg` for one of several tables: `plot-QUANTITY.svg`.
fn plot_for(path: &Path, table: &Table) -> PathBuf {
    let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or("plot");
    let extension = path.extension().and_then(|e| e.to_str()).unwrap_or("svg");
    path.with_file_name(format!(
        "{stem}-{}.{extension}",
        table.spec.quantity.symbol()
    ))
}

/// Whether `--plot` asks for SVG (true) or PNG (false); `None` without it.
fn plot_kind(args: &VerifyArgs) -> kiln::Result<Option<bool>> {
    plot_kind_of(args.plot.as_deref())
}

/// Whether a `--plot` path asks for SVG (`Some(true)`) or PNG; an error for a folder that does
/// not exist or another extension.
pub(crate) fn plot_kind_of(plot: Option<&Path>) -> kiln::Result<Option<bool>> {
    // A picture goes into a folder that exists: a mistyped path is an error now, before the
    // audit, not a chain of new folders after it.
    if let Some(dir) = plot
        .and_then(Path::parent)
        .filter(|d| !d.as_os_str().is_empty() && !d.is_dir())
    {
        return Err(kiln::Error::InvalidInput(format!(
            "--plot {}: the folder {} does not exist; create it, or give a path in a folder \
             that does",
            plot.unwrap_or(dir).display(),
            dir.display()
        )));
    }
    match plot {
        Some(path) => match path.extension().and_then(|e| e.to_str()) {
            Some("svg") => Ok(Some(true)),
            Some("png") => Ok(Some(false)),
            _ => Err(kiln::Error::InvalidInput(format!(
                "--plot {}: give a .svg or .png file",
                path.display()
            ))),
        },
        None => Ok(None),
    }
}

/// Writes the error maps of an audit to `path` (SVG or PNG by its extension).
fn write_error_maps(path: &Path, table: &Table, report: &kiln::verify::Report) -> kiln::Result<()> {
    let svg = path.extension().and_then(|e| e.to_str()) == Some("svg");
    let maps = kiln::verify::error_maps(&table.spec, report);
    let title = format!(
        "{}: error against {} (ringed: the worst point)",
        table.spec.id(),
        report.against
    );
    write_plot(path, svg, crate::plot::error_map_plot(&title, &maps))
}

/// Writes a plot drawn as `(SVG text, PNG bytes)` to `path`, the SVG if `svg`.
pub(crate) fn write_plot(
    path: &Path,
    svg: bool,
    drawn: Result<(String, Vec<u8>), String>,
) -> kiln::Result<()> {
    let (text, png) = drawn.map_err(|message| kiln::Error::Format {
        path: path.to_path_buf(),
        message,
    })?;
    let bytes = if svg { text.into_bytes() } else { png };
    let dir = path.parent().filter(|p| !p.as_os_str().is_empty());
    let name = path
        .file_name()
        .and_then(|n| n.to_str())
        .unwrap_or("plot.svg");
    kiln::format::write_files(dir.unwrap_or(Path::new(".")), &[(name.to_string(), bytes)])?;
    Ok(())
}

/// The estimated cost of one reference value of `table`'s quantity at an audit's tolerance
/// (about 1e-6), in microseconds of one core: the unit of the command's progress bar.
fn point_micros(table: &Table) -> u64 {
    (kiln::bake::reference_seconds_per_point(&table.spec, 6) * 1e6).ceil() as u64
}

/// The estimated cost of auditing `table` (its nodes and its lookup points), in seconds of one
/// core, for [`crate::announce_cost`] and the progress bar.
fn audit_core_seconds(table: &Table, settings: &AuditSettings) -> f64 {
    let points = kiln::verify::audit_points(&table.spec, settings);
    points as f64 * point_micros(table) as f64 * 1e-6
}

/// Audits one table and prints the report; whether it passed `--max-error`. `storage`: how the
/// file stores its numbers, to show what that alone costs.
fn audit_one(
    args: &VerifyArgs,
    table: &Table,
    storage: Option<kiln::verify::Storage>,
    shared: Option<&indicatif::ProgressBar>,
) -> kiln::Result<bool> {
    let other;
    let against = if args.against == "reference" {
        Against::Reference(ReferenceSettings::default())
    } else {
        other = args.load(Path::new(&args.against))?;
        if other.spec.quantity != table.spec.quantity {
            return Err(kiln::Error::InvalidInput(format!(
                "{} holds {} but {} holds {}",
                args.file().display(),
                table.spec.quantity.symbol(),
                args.against,
                other.spec.quantity.symbol()
            )));
        }
        Against::Table(&other)
    };
    let settings = args.audit_settings(storage);
    let report = match shared {
        // The command's one bar, sized for every table up front: each point its estimated cost.
        Some(bar) => {
            let micros = point_micros(table);
            audit(table, &against, &settings, &|step| {
                if let Progress::Compared = step {
                    bar.inc(micros);
                }
            })
        }
        None => {
            crate::announce_cost(
                audit_core_seconds(table, &settings),
                args.quiet || args.json,
            );
            let bar = crate::progress_bar(args.quiet || args.json, 0, "verifying");
            let report = audit(table, &against, &settings, &|step| match step {
                Progress::Planned(points) => bar.inc_length(points),
                Progress::Compared => bar.inc(1),
            });
            bar.finish_and_clear();
            report
        }
    };
    if let Some(path) = &args.plot {
        write_error_maps(path, table, &report)?;
    }
    // Texels fitted for the lookup are judged by the lookup, what a renderer reads; their
    // nodes are off the truth by design.
    let fitted = table.spec.texels == kiln::table::Texels::LookupFit;
    let (gated, gated_error) = if fitted {
        ("lookup max error", report.lookup_max_error)
    } else {
        ("node max error", report.node_max_error)
    };
    let passed = args.max_error.is_none_or(|bound| gated_error <= bound);
    // For a file in fixed point (an 8-bit PNG): whether it is as good as that allows, and the
    // likely mistake where it is not.
    let verdict = storage.and_then(|s| kiln::verify::verdict::verdict(table, &report, &s));
    if args.json {
        let mut object = json_report(&report, args, passed);
        if let Some(v) = &verdict {
            object["verdict"] = serde_json::to_value(v).expect("a verdict serialises");
        }
        println!("{object}");
    } else if args.quiet {
        quiet_verdict(args, passed, gated, gated_error);
    } else {
        let shape: Vec<String> = report.shape.iter().map(|n| n.to_string()).collect();
        println!(
            "{}: {} {} {}, {} ({} grid, roughness axis {}{}{}) against {}",
            args.file().display(),
            report.ndf,
            report.masking,
            report.quantity,
            shape.join("x"),
            report.grid,
            report.roughness_axis,
            report
                .mu_axis
                .as_ref()
                .map(|m| format!(", mu axis {m}"))
                .unwrap_or_default(),
            if report.clamp_min > 0.0 {
                format!(", clamped to >= {}", report.clamp_min)
            } else {
                String::new()
            },
            report.against
        );
        println!(
            "  nodes   {:>6}: max error {:.2e}, rms {:.2e}; worst at {}",
            report.nodes,
            report.node_max_error,
            report.node_rms_error,
            describe(&report.worst_node, &report.roughness_axis)
        );
        println!(
            "  lookups {:>6}: max error {:.2e}, rms {:.2e}, p99 {:.2e}; worst at {}",
            report.lookup_points,
            report.lookup_max_error,
            report.lookup_rms_error,
            report.lookup_p99_error,
            describe(&report.worst_lookup, &report.roughness_axis)
        );
        if let Some(cost) = &report.storage_cost {
            println!(
                "  the true values in {} (the best this file can be): nodes max {:.2e}, rms {:.2e}; \
                 lookups max {:.2e}, rms {:.2e}",
                cost.storage,
                cost.node_max_error,
                cost.node_rms_error,
                cost.lookup_max_error,
                cost.lookup_rms_error
            );
        }
        if let Some(v) = &verdict {
            println!("  verdict: {}", v.sentence);
            if let Some(cost) = &report.storage_cost
                && cost.lookup_max_error >= 0.5 * report.lookup_max_error
                && report.lookup_max_error > 10.0 * cost.node_max_error
            {
                let at = &report.worst_lookup;
                println!(
                    "  the lookups' {:.2e} is the layout's own, not the file's: the true values \
                     stored in it give {:.2e}, where a bilinear lookup cannot follow the table \
                     between or beyond its texel centres (worst at {}r = {:.6})",
                    report.lookup_max_error,
                    cost.lookup_max_error,
                    at.mu
                        .map(|mu| format!("mu = {mu:.6}, "))
                        .unwrap_or_default(),
                    at.roughness
                );
            }
        }
        if report.node_reference_tolerance > 0.0 {
            println!(
                "  reference tolerance {:.0e} at the nodes, {:.0e} at the lookups (a hundredth of \
                 the smallest figure above, within [{:.0e}, {:.0e}])",
                report.node_reference_tolerance,
                report.lookup_reference_tolerance,
                ReferenceSettings::default().tolerance,
                kiln::verify::COARSEST_TOLERANCE
            );
        }
        if !report.reference_converged {
            println!(
                "  note: some reference values did not reach their tolerance (estimate {:.1e})",
                report.reference_error_estimate
            );
        }
        if fitted {
            println!(
                "  texels fitted for the lookup: the lookups are what a renderer reads, the nodes \
                 are off the truth by design"
            );
        }
        print_verdict(args.max_error, passed, gated, gated_error);
    }
    Ok(passed)
}
