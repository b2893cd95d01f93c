//! `kiln verify`: the audit of a table, kiln's or an engine's, against the reference or another
//! table ([`kiln::verify::audit`]).

use crate::args::{SEE_CONVENTIONS, parse_clamp, parse_error_bound};
use crate::external::ExternalLayout;
use crate::report::{
    FileGate, json_report, plot_kind_of, print_verdict, quiet_verdict, write_plot,
};
use clap::Args;
use kiln::integrate::reference::ReferenceSettings;
use kiln::verify::{Against, AuditSettings, Point, Progress, audit};
use kiln::{Quantity, Table};
use std::path::{Path, PathBuf};

/// Audit a table against the deterministic reference (or another table).
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
                  its layout with --preset. --max-error X --quiet makes it a build gate. The \
                  white furnace of a table is `kiln furnace`, the audit of a texture-free fit \
                  `kiln verify-fit`, and of an engine's anisotropy convention `kiln \
                  verify-anisotropy`.",
    after_help = SEE_CONVENTIONS
)]
pub struct VerifyArgs {
    /// The table to audit: a kiln output, a text file of numbers (whitespace or commas, '#'
    /// comments), raw little-endian floats (--dtype) or an EXR channel (--channel).
    file: PathBuf,
    /// What to compare with: 'reference' (the deterministic quadrature) or another table's file.
    #[arg(long, default_value = "reference")]
    against: String,
    /// Draw where the table is wrong into this .svg or .png file: the node and the lookup error
    /// over the table's axes (heat maps on a log colour scale, or error against roughness for
    /// E_avg; for a table with an IOR axis, the slice of the worst point), the worst point
    /// ringed. With --preset and several tables, one file per table, its quantity added to the
    /// name (plot-E_bias.svg).
    #[arg(long)]
    plot: Option<PathBuf>,
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
    #[arg(long, value_enum, conflicts_with = "external_layout")]
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
    #[command(flatten)]
    layout: ExternalLayout,
    /// Print nothing but errors: the exit status says whether the table passed --max-error
    /// (0 passed, 1 failed, 2 could not be read), and a failing check prints one line on
    /// stderr. For build gates. Not with --json, which prints the report.
    #[arg(long, short, conflicts_with = "json")]
    quiet: bool,
}

impl VerifyArgs {
    /// The file audited.
    pub fn file(&self) -> &Path {
        &self.file
    }

    /// The file and its bound, as the verdict names them.
    fn gate(&self) -> FileGate<'_> {
        FileGate {
            file: &self.file,
            max_error: self.max_error,
        }
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

/// Returns whether the table passed `--max-error` (always true without it).
pub fn run(args: VerifyArgs) -> kiln::Result<bool> {
    if let Some(preset) = args.preset {
        let bytes = kiln::format::read_file(args.file())?;
        // Name the file in what the layout's reader says.
        let in_file = |e: kiln::Error| e.in_file(args.file());
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
        plot_kind_of(args.plot.as_deref())?;
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
    plot_kind_of(args.plot.as_deref())?;
    let table = args.layout.load(args.file())?;
    check_audit_size(&args, &table)?;
    if table.spec.quantity == Quantity::FMsNorm && args.against == "reference" {
        return run_normalisation_audit(&args, &table);
    }
    audit_one(&args, &table, None, None)
}

/// [`kiln::verify::check_audit_size`] for `table` at the command's density, naming the file:
/// refused before any point is made.
fn check_audit_size(args: &VerifyArgs, table: &Table) -> kiln::Result<()> {
    kiln::verify::check_audit_size(&table.spec, &args.audit_settings(None))
        .map_err(|e| e.in_file(args.file()))
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
    let e = args.layout.load(&e_path)?;
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
        println!("{}", json_report(&report, &args.gate(), passed));
    } else if args.quiet {
        quiet_verdict(
            &args.gate(),
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
        quiet_verdict(
            &args.gate(),
            passed,
            "blue channel node max error",
            audit.max_error,
        );
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

/// The estimated cost of one reference value of `table`'s quantity at an audit's tolerance
/// (about 1e-6), in microseconds of one core: the unit of the command's progress bar.
fn point_micros(table: &Table) -> u64 {
    (kiln::integrate::cost::reference_seconds(table.spec.quantity, table.spec.model, 6) * 1e6)
        .ceil() as u64
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
        other = args.layout.load(Path::new(&args.against))?;
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
        let mut object = json_report(&report, &args.gate(), passed);
        if let Some(v) = &verdict {
            object["verdict"] = serde_json::to_value(v).expect("a verdict serialises");
        }
        println!("{object}");
    } else if args.quiet {
        quiet_verdict(&args.gate(), passed, gated, gated_error);
    } else {
        print_audit(args, table, &report, verdict.as_ref());
        print_verdict(args.max_error, passed, gated, gated_error);
    }
    Ok(passed)
}

/// The text report of one table's audit, up to its verdict line.
fn print_audit(
    args: &VerifyArgs,
    table: &Table,
    report: &kiln::verify::Report,
    verdict: Option<&kiln::verify::verdict::Verdict>,
) {
    let fitted = table.spec.texels == kiln::table::Texels::LookupFit;
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
    if let Some(v) = verdict {
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
}
