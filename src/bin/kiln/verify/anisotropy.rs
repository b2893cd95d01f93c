//! `kiln verify --anisotropy-convention`: how far an engine's isotropic `E` table, read at its
//! single roughness, is from its anisotropic lobe's albedo ([`kiln::verify::anisotropy`]).

use super::{VerifyArgs, plot_kind, write_plot};
use kiln::model::AnisotropyConvention;
use kiln::verify::anisotropy::{
    AnisotropyAudit, AnisotropyGrid, AnisotropyPoint, anisotropy_maps, audit_anisotropy,
};

/// Seconds of one core per compared point at the audit's tolerance (both references), measured
/// over the standard grid: about 5 ms (`kiln verify --anisotropy-convention kulla-conty`,
/// 2026-12-07).
const SECONDS_PER_POINT: f64 = 5e-3;

pub fn run(args: &VerifyArgs, convention: AnisotropyConvention) -> kiln::Result<bool> {
    if args.fresnel.given() || args.ndf.is_some() || args.masking.is_some() {
        return Err(kiln::Error::InvalidInput(
            "--anisotropy-convention audits GGX with height-correlated masking and F = 1 (the \
             lobe engines make anisotropic): drop --ndf, --masking and the Fresnel flags"
                .into(),
        ));
    }
    let svg = plot_kind(args)?;
    let grid = AnisotropyGrid::standard(convention);
    let points = grid.roughness.len() * grid.anisotropy.len() * grid.mu.len() * grid.phi.len();
    let quiet = args.quiet || args.json;
    crate::announce_cost(points as f64 * SECONDS_PER_POINT, quiet);
    let spinner = crate::spinner(quiet, "verifying");
    let audit = audit_anisotropy(convention, &grid).map_err(kiln::Error::InvalidInput)?;
    spinner.finish_and_clear();
    if let (Some(svg), Some(path)) = (svg, &args.plot) {
        let title = format!(
            "{convention} convention, isotropic E read at the {}: |E_read - E|, worst over phi",
            audit.reading.describe()
        );
        let maps = anisotropy_maps(&audit, &grid);
        write_plot(path, svg, crate::plot::error_map_plot(&title, &maps))?;
    }
    let gate = crate::gate::Gate {
        json: args.json,
        quiet: args.quiet,
        bound: args.max_error,
        bound_field: "max_error_bound",
    };
    let subject = format!("--anisotropy-convention {convention}");
    let passed = gate.print(
        &audit,
        || text(&audit, &grid),
        audit.max_error,
        "max error",
        &subject,
    );
    Ok(passed)
}

/// One point, as the report names it.
fn point(p: &AnisotropyPoint) -> String {
    format!(
        "r = {:.3}, a = {}, mu = {:.4}, phi = {:.4} (alpha_x {:.4}, alpha_y {:.4}, read at {:.4}): \
         E {:.4}, read {:.4}",
        p.roughness, p.anisotropy, p.mu, p.phi, p.alpha_x, p.alpha_y, p.alpha_read, p.truth, p.read
    )
}

fn text(audit: &AnisotropyAudit, grid: &AnisotropyGrid) -> String {
    let mut out = format!(
        "{} convention: isotropic E read at the {} of alpha_x and alpha_y, against the \
         anisotropic lobe's E (both references to {:e}) at {} points: r {} to {}, mu {} to {}, \
         phi 0 to pi/2\n  max |error| {:.3e} at {}\n",
        audit.convention,
        audit.reading.describe(),
        audit.truth_tolerance,
        audit.points,
        grid.roughness[0],
        grid.roughness[grid.roughness.len() - 1],
        grid.mu[0],
        grid.mu[grid.mu.len() - 1],
        audit.max_error,
        point(&audit.worst)
    );
    for row in &audit.by_anisotropy {
        out += &format!(
            "  a = {:<5} max |error| {:.3e} at {}\n",
            row.anisotropy,
            row.max_error,
            point(&row.worst)
        );
    }
    out += &format!(
        "  E changes with the view's azimuth by up to {:.3} at one (r, a, mu): no single \
         roughness follows it\n",
        audit.max_azimuthal_spread
    );
    out
}
