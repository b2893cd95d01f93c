//! `kiln furnace`: the white furnace test of a table's energy compensation, Kulla-Conty's lobe
//! with its normalisation and Turquin's 1 / E scaling ([`kiln::verify::furnace`]).

use crate::args::SEE_CONVENTIONS;
use crate::external::ExternalLayout;
use crate::report::{
    FileGate, json_report, plot_kind_of, print_verdict, quiet_verdict, write_plot,
};
use clap::Args;
use kiln::verify::AuditSettings;
use kiln::verify::furnace::{
    Form, FormReport, forms_for, furnace, normalisation_beside, turquin, turquin_core_seconds,
};
use kiln::{Axis, Table};
use std::path::{Path, PathBuf};

/// White furnace test: does energy compensation with a table give back what single scattering loses?
#[derive(Args, Debug, Clone)]
#[command(
    long_about = "White furnace test of an E table (or a glass table): does energy compensation \
                  with it give back exactly what single scattering loses? kulla-conty: the lobe \
                  f_ms normalised by the f_ms_norm table (else E_avg) found beside FILE or given \
                  with --average, E + albedo(f_ms) - 1 over a fine roughness and mu ladder; \
                  turquin: single scattering scaled by 1 / E_lookup, E_true / E_lookup - 1 at the \
                  points of kiln verify's lookup audit (against the reference: seconds). \
                  --max-error applies to the worst over the forms checked. Was `kiln verify \
                  --furnace`, which still works in this release.",
    after_help = SEE_CONVENTIONS
)]
pub struct FurnaceArgs {
    /// The E table (NAME-E.EXT as kiln names it, or any table with its layout given) or glass
    /// table (E_dielectric, from either side).
    file: PathBuf,
    /// The compensation forms to check, comma-separated [default: both; turquin for glass].
    #[arg(long, value_enum, value_delimiter = ',')]
    form: Option<Vec<Form>>,
    /// The f_ms_norm or E_avg table of the Kulla-Conty form [default: beside FILE].
    #[arg(long)]
    average: Option<PathBuf>,
    /// Lookup points per texel along each axis (Turquin's form: the points of kiln verify's
    /// lookup audit; Kulla-Conty's: the roughness ladder).
    #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u32).range(1..=64))]
    density: u32,
    /// The smallest coordinate the table was actually computed at, on both axes (Turquin's
    /// form compares the truth there) [default: 0].
    #[arg(long, value_parser = crate::args::parse_clamp, allow_negative_numbers = true)]
    clamp_min: Option<f64>,
    /// Draw the deviation of each form over (mu, r) into this .svg or .png file (a glass table:
    /// over mu and eta, the worst over roughness), the worst point ringed.
    #[arg(long)]
    plot: Option<PathBuf>,
    #[command(flatten)]
    layout: ExternalLayout,
    #[command(flatten)]
    gate: crate::gate::GateArgs,
}

impl FurnaceArgs {
    fn file(&self) -> &Path {
        &self.file
    }

    fn gate(&self) -> FileGate<'_> {
        FileGate {
            file: &self.file,
            max_error: self.gate.max_error,
        }
    }

    fn audit_settings(&self) -> AuditSettings {
        AuditSettings {
            clamp_min: self.clamp_min.unwrap_or(0.0),
            density: self.density as usize,
            storage: None,
        }
    }
}

/// Returns whether the table passed `--max-error` (always true without it).
pub fn run(args: FurnaceArgs) -> kiln::Result<bool> {
    let table = args.layout.load(args.file())?;
    let in_file = |e: kiln::Error| e.in_file(args.file());
    let forms = forms_for(&table.spec, args.form.as_deref()).map_err(in_file)?;
    kiln::verify::check_audit_size(&table.spec, &args.audit_settings()).map_err(in_file)?;
    let args = &args;
    let table = &table;
    let plot_kind = plot_kind_of(args.plot.as_deref())?;
    let normalisation = match forms.contains(&Form::KullaConty) {
        true => {
            let average_path = match &args.average {
                Some(path) => path.clone(),
                None => normalisation_beside(args.file(), &table.spec)?,
            };
            let average = args.layout.load(&average_path)?;
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
            let settings = args.audit_settings();
            let points = kiln::verify::lookup_coordinate_count(&table.spec, &settings);
            crate::announce_cost(
                turquin_core_seconds(&table.spec, &settings),
                args.gate.quiet || args.gate.json,
            );
            let bar = crate::progress_bar(args.gate.quiet || args.gate.json, points, "turquin");
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
    if let (Some(path), Some(svg)) = (&args.plot, plot_kind) {
        draw(
            path,
            svg,
            table,
            normalisation.as_ref().map(|(_, t)| t),
            &forms,
            &form_reports,
        )?;
    }
    Ok(print_report(
        args,
        table,
        kulla_conty.as_ref(),
        &form_reports,
    ))
}

/// Prints the report (JSON, text, or with `--quiet` a failure only); whether it passed
/// `--max-error`.
fn print_report(
    args: &FurnaceArgs,
    table: &Table,
    kulla_conty: Option<&(PathBuf, kiln::verify::furnace::FurnaceReport)>,
    form_reports: &[FormReport],
) -> bool {
    let max_deviation = kiln::stats::max_or_nan(form_reports.iter().map(|f| f.max_deviation));
    let passed = args
        .gate
        .max_error
        .is_none_or(|bound| max_deviation <= bound);
    if args.gate.json {
        let mut object = match kulla_conty {
            Some((path, report)) => {
                let mut object = json_report(report, &args.gate(), passed);
                object["average"] = path.display().to_string().into();
                object
            }
            None => json_report(&serde_json::json!({}), &args.gate(), passed),
        };
        object["max_deviation"] = max_deviation.into();
        object["forms"] = serde_json::to_value(form_reports).expect("reports serialise");
        println!("{object}");
        return passed;
    }
    if args.gate.quiet {
        quiet_verdict(&args.gate(), passed, "furnace max deviation", max_deviation);
        return passed;
    }
    if let Some((path, report)) = kulla_conty {
        print_kulla_conty(args, table, path, report);
    }
    if let Some(t) = form_reports.iter().find(|f| f.form == Form::Turquin) {
        print_turquin(args, table, t);
    }
    print_verdict(args.gate.max_error, passed, "max deviation", max_deviation);
    passed
}

/// The text report of Turquin's form, with its IOR bands for a glass table.
fn print_turquin(args: &FurnaceArgs, table: &Table, t: &FormReport) {
    {
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
}

/// Draws the deviation maps of the forms checked, the worst point of each ringed: over (mu, r),
/// or for a glass table Turquin's points binned over mu and eta, the worst over roughness.
fn draw(
    path: &Path,
    svg: bool,
    table: &Table,
    normalisation: Option<&Table>,
    forms: &[Form],
    reports: &[FormReport],
) -> kiln::Result<()> {
    if let Some(Axis::Ior { max, .. }) = table.spec.ior {
        // A glass table: the furnace's own points, binned over mu and eta (worst over
        // roughness), with its worst point ringed.
        let report = reports.iter().find(|f| f.form == Form::Turquin);
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
        write_plot(path, svg, crate::plot::furnace_plot(&title, &maps, &marks))
    } else {
        let maps = kiln::verify::furnace::furnace_maps(table, normalisation, forms, 64, 64)?;
        // The command's worst point of each form, ringed on its map and stated in its caption.
        let convention = table.spec.roughness_convention();
        let marks: Vec<Option<crate::plot::FurnaceMark>> = maps
            .iter()
            .map(|map| {
                let report = reports.iter().find(|f| f.form == map.form)?;
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
        write_plot(path, svg, crate::plot::furnace_plot(&title, &maps, &marks))
    }
}

/// The text report of the Kulla-Conty form.
fn print_kulla_conty(
    args: &FurnaceArgs,
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
