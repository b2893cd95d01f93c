//! `kiln verify --fit`: the audit of a texture-free fit, an engine's or one given as a formula
//! file ([`kiln::verify::fit`]).

use super::{VerifyArgs, plot_kind, write_plot};
use kiln::fit::engine::EngineFit;
use kiln::fit::{Fit, FormulaFit};
use kiln::verify::fit::{FitAuditSettings, FitReport, audit_fit, fit_audit_points};
use kiln::{Masking, Model, Ndf};
use std::path::Path;

/// The fit `--fit` names: a built-in one, or a formula file.
fn fit_named(name: &str) -> kiln::Result<Fit> {
    if let Some(fit) = EngineFit::ALL.into_iter().find(|f| f.name() == name) {
        return Ok(Fit::Engine(fit));
    }
    let path = Path::new(name);
    if !path.exists() {
        let names: Vec<&str> = EngineFit::ALL.iter().map(|f| f.name()).collect();
        return Err(kiln::Error::InvalidInput(format!(
            "--fit {name}: neither a fit kiln knows ({}) nor a formula file",
            names.join(", ")
        )));
    }
    Ok(Fit::Formula(FormulaFit::read(path)?))
}

pub fn run(args: &VerifyArgs, name: &str) -> kiln::Result<bool> {
    if args.fresnel.given() {
        return Err(kiln::Error::InvalidInput(
            "--fit audits fits of E and its split-sum terms, which are for F = 1 (E_scale, \
             E_bias are Schlick's weights): drop the Fresnel flags"
                .into(),
        ));
    }
    let fit = fit_named(name)?;
    let model = Model {
        ndf: args.ndf.unwrap_or(Ndf::Ggx),
        masking: args.masking.unwrap_or(Masking::HeightCorrelated),
    };
    model.validate().map_err(kiln::Error::InvalidInput)?;
    let svg = plot_kind(args)?;
    let settings = FitAuditSettings {
        model,
        points: args.points as usize,
        ..FitAuditSettings::default()
    };
    let quiet = args.quiet || args.json;
    // Every point costs the reference of each quantity the fit gives, at the audit's tolerance.
    let digits = (-settings.tolerance.log10()).round().max(1.0) as u32;
    let per_point: f64 = fit
        .quantities()
        .into_iter()
        .map(|q| kiln::bake::reference_seconds(q, model, digits))
        .sum();
    let points = fit_audit_points(&fit, &settings);
    crate::announce_cost(points as f64 * per_point, quiet);
    let bar = crate::progress_bar(quiet, points, "verifying");
    let report = audit_fit(&fit, &settings, &|| bar.inc(1));
    bar.finish_and_clear();
    if let (Some(svg), Some(path)) = (svg, &args.plot) {
        let maps: Vec<_> = report.quantities.iter().map(|q| q.map.clone()).collect();
        let title = format!(
            "{}: |fit - reference| for {} (ringed: the worst point)",
            kiln::error::escaped(&report.fit),
            report.model
        );
        write_plot(path, svg, crate::plot::error_map_plot(&title, &maps))?;
    }
    let worst = kiln::stats::max_or_nan(report.quantities.iter().map(|q| q.max_error));
    let gate = crate::gate::Gate {
        json: args.json,
        quiet: args.quiet,
        bound: args.max_error,
        bound_field: "max_error",
    };
    let subject = format!("--fit {}", kiln::error::escaped(&report.fit));
    let passed = gate.print(&report, || text(&report), worst, "max error", &subject);
    Ok(passed)
}

/// The report as text: what was compared, then one line per quantity.
fn text(report: &FitReport) -> String {
    let mut out = format!(
        "{} ({})\nagainst the reference for {} (tolerance {:e}) at {} points: {} x {} over mu \
         = t^2 and r in [0, 1] (alpha = r^2), then around each worst point\n",
        kiln::error::escaped(&report.fit),
        kiln::error::escaped(&report.source),
        report.model,
        report.reference_tolerance,
        report.points_compared,
        report.grid_points,
        report.grid_points
    );
    for q in &report.quantities {
        let w = &q.worst;
        let nan = if q.non_finite_points > 0 {
            format!(" ({} points NaN or infinite)", q.non_finite_points)
        } else {
            String::new()
        };
        out += &format!(
            "  {:<8} max error {:.3e}{nan} at mu = {:.6}, r = {:.6} (alpha {:.3e}): fit {:.6}, \
             reference {:.6}; mean {:.2e}, RMS {:.2e}\n",
            q.quantity.symbol(),
            q.max_error,
            w.mu,
            w.r,
            w.alpha,
            w.fit,
            w.reference,
            q.mean_error,
            q.rms_error
        );
    }
    out
}
