//! `kiln verify-anisotropy`: how far an engine's isotropic `E` table, read at its
//! single roughness, is from its anisotropic lobe's albedo ([`kiln::verify::anisotropy`]).

use crate::report::{plot_kind_of, write_plot};
use clap::Args;
use kiln::model::AnisotropyConvention;
use kiln::verify::anisotropy::{
    AnisotropyAudit, AnisotropyGrid, AnisotropyPoint, anisotropy_maps, audit_anisotropy,
};

/// Audit how an engine compensates an anisotropic GGX lobe with its isotropic E table.
#[derive(Args, Debug, Clone)]
#[command(
    long_about = "Audit how an engine compensates an anisotropic GGX lobe (height-correlated \
                  masking, F = 1) with its isotropic E table, read at one roughness: compares \
                  the isotropic reference with the anisotropic lobe's over r, anisotropy, mu and \
                  the view's azimuth, and reports the maximum error and where (--plot: a map per \
                  anisotropy). kiln's own anisotropic table is `kiln anisotropic`. Was `kiln \
                  verify --anisotropy-convention`, which still works in this release."
)]
pub struct VerifyAnisotropyArgs {
    /// The engine's convention: kulla-conty (Filament, Unreal: the arithmetic mean of alpha_x
    /// and alpha_y; alias arithmetic-mean), disney (Cycles, Enterprise PBR: the geometric mean;
    /// alias geometric-mean), gltf (KHR_materials_anisotropy: the bitangent's roughness; alias
    /// minimum), openpbr (the root mean square; alias rms).
    #[arg(value_enum, hide_possible_values = true)]
    convention: AnisotropyConvention,
    /// Draw |E_read - E| over (mu, r), the worst over the azimuth, per anisotropy into this
    /// .svg or .png file.
    #[arg(long)]
    plot: Option<std::path::PathBuf>,
    #[command(flatten)]
    gate: crate::gate::GateArgs,
}

pub fn run(args: VerifyAnisotropyArgs) -> kiln::Result<bool> {
    let convention = args.convention;
    let args = &args;
    let svg = plot_kind_of(args.plot.as_deref())?;
    let grid = AnisotropyGrid::standard(convention);
    let quiet = args.gate.quiet || args.gate.json;
    crate::announce_cost(grid.audit_core_seconds(), quiet);
    let spinner = crate::spinner(quiet, "verifying");
    let audit = audit_anisotropy(convention, &grid)?;
    spinner.finish_and_clear();
    if let (Some(svg), Some(path)) = (svg, &args.plot) {
        let title = format!(
            "{convention} convention, isotropic E read at the {}: |E_read - E|, worst over phi",
            audit.reading.describe()
        );
        let maps = anisotropy_maps(&audit, &grid);
        write_plot(path, svg, crate::plot::error_map_plot(&title, &maps))?;
    }
    let gate = args.gate.gate("max_error_bound");
    let subject = format!("verify-anisotropy {convention}");
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
