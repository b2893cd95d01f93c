//! `kiln verify-fit`: the audit of a texture-free fit, an engine's or one given as a formula
//! file ([`kiln::verify::fit`]).

use crate::report::{plot_kind_of, write_plot};
use clap::Args;
use kiln::fit::engine::EngineFit;
use kiln::fit::{Fit, FormulaFit};
use kiln::verify::fit::{
    FitAuditSettings, FitReport, audit_fit, fit_audit_core_seconds, fit_audit_points,
};
use kiln::{Masking, Model, Ndf};
use std::path::{Path, PathBuf};

/// Audit a texture-free fit of E against the reference.
#[derive(Args, Debug, Clone)]
#[command(
    long_about = "Audit a texture-free fit instead of a table: an engine's (karis: UE4 mobile \
                  EnvBRDFApprox; materialx: mx_ggx_dir_albedo_analytic; unreal: UE5's analytic \
                  GGXEnergyLookup) or a formula file (TOML: name = \"...\", optional define = \
                  [\"k = max(r, 1e-3)\", ...], and formulas E, E_scale and/or E_bias in mu, r and \
                  alpha = r^2; see docs/fits.md). Reports each quantity's maximum error over mu \
                  and r in [0, 1] against the reference for the model of --ndf and --masking \
                  (default GGX height-correlated), and where it is. Fits of E and its split-sum \
                  terms are for F = 1 (E_scale and E_bias are Schlick's weights). Was `kiln \
                  verify --fit`, which still works in this release."
)]
pub struct VerifyFitArgs {
    /// The fit: karis, materialx, unreal, or a formula file.
    #[arg(value_name = "NAME|FILE.toml")]
    fit: String,
    /// Points per axis of the (sqrt(mu), r) grid the fit is compared on, the ends included; a
    /// finer grid then surrounds each quantity's worst point.
    #[arg(long, default_value_t = 129, value_parser = clap::value_parser!(u32).range(2..=1025))]
    points: u32,
    /// The normal distribution [default: ggx].
    #[arg(long, value_enum)]
    ndf: Option<Ndf>,
    /// The Smith G2 form [default: height-correlated].
    #[arg(long, value_enum)]
    masking: Option<Masking>,
    /// Draw |fit - reference| over (mu, r) for each quantity into this .svg or .png file, the
    /// worst point ringed.
    #[arg(long)]
    plot: Option<PathBuf>,
    #[command(flatten)]
    gate: crate::gate::GateArgs,
}

/// The fit named: a built-in one, or a formula file.
fn fit_named(name: &str) -> kiln::Result<Fit> {
    if let Some(fit) = EngineFit::ALL.into_iter().find(|f| f.name() == name) {
        return Ok(Fit::Engine(fit));
    }
    let path = Path::new(name);
    if !path.exists() {
        let names: Vec<&str> = EngineFit::ALL.iter().map(|f| f.name()).collect();
        return Err(kiln::Error::InvalidInput(format!(
            "{name}: neither a fit kiln knows ({}) nor a formula file",
            names.join(", ")
        )));
    }
    Ok(Fit::Formula(FormulaFit::read(path)?))
}

pub fn run(args: VerifyFitArgs) -> kiln::Result<bool> {
    let args = &args;
    let fit = fit_named(&args.fit)?;
    let model = Model {
        ndf: args.ndf.unwrap_or(Ndf::Ggx),
        masking: args.masking.unwrap_or(Masking::HeightCorrelated),
    };
    model.validate()?;
    let svg = plot_kind_of(args.plot.as_deref())?;
    let settings = FitAuditSettings {
        model,
        points: args.points as usize,
        ..FitAuditSettings::default()
    };
    let quiet = args.gate.quiet || args.gate.json;
    crate::announce_cost(fit_audit_core_seconds(&fit, &settings), quiet);
    let points = fit_audit_points(&fit, &settings);
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
    let gate = args.gate.gate("max_error");
    let subject = kiln::error::escaped(&report.fit);
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
