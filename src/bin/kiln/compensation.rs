//! `kiln compensation`: Kulla-Conty's and Turquin's energy compensation measured against the
//! microsurface walk (`kiln::verify::compensation`).

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
                  of every order of scattering on the microsurface, by the random walk (GGX, \
                  height-correlated, Schlick's Fresnel at every bounce). Prints, per \
                  compensation, the largest deviation of each sign with its 95 % confidence \
                  half-width and where it is, and the RMS over the grid; --json prints every \
                  point. The compensations are computed from kiln's reference (E, E_avg, E_F, \
                  F_avg), not from a table: what is measured is the model's error.",
    after_help = SEE_CONVENTIONS
)]
pub struct CompensationArgs {
    /// The compensations to measure [default: all three].
    #[arg(long, value_enum, value_delimiter = ',')]
    compensation: Vec<Compensation>,
    /// Perceptual roughness values r (alpha = r^2), comma-separated, in [0, 1].
    #[arg(long, value_delimiter = ',', default_value = "0.25,0.5,0.75,1", value_parser = crate::args::parse_roughness, allow_negative_numbers = true)]
    roughness: Vec<f64>,
    /// View cosines mu, comma-separated, in [0, 1].
    #[arg(long, value_delimiter = ',', default_value = "0.05,0.1,0.2,0.35,0.5,0.7,0.85,1", value_parser = crate::args::parse_mu, allow_negative_numbers = true)]
    mu: Vec<f64>,
    /// Schlick's F0 values, comma-separated, in [0, 1].
    #[arg(long, value_delimiter = ',', default_value = "0.02,0.04,0.1,0.25,0.5,0.75,0.9,1", value_parser = crate::args::parse_number, allow_negative_numbers = true)]
    f0: Vec<f64>,
    /// Schlick's F90, in [0, 1].
    #[arg(long, default_value_t = 1.0, value_parser = crate::args::parse_number, allow_negative_numbers = true)]
    f90: f64,
    /// Walks per view, a power of two (every F0 shares them).
    #[arg(long, default_value = "1048576", value_parser = parse_samples, allow_negative_numbers = true)]
    walks: u64,
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

pub fn run(args: CompensationArgs) -> kiln::Result<()> {
    let compensations = if args.compensation.is_empty() {
        Compensation::ALL.to_vec()
    } else {
        args.compensation.clone()
    };
    let grid = CompensationGrid {
        alphas: args
            .roughness
            .iter()
            .map(|&r| RoughnessConvention::Perceptual.to_alpha(r))
            .collect(),
        mus: args.mu.clone(),
        f0s: args.f0.clone(),
        f90: args.f90,
    };
    if !(0.0..=1.0).contains(&args.f90) {
        return Err(kiln::integrate::walk::WalkError::F90(args.f90).into());
    }
    let settings = WalkSettings {
        walks: args.walks,
        seed: args.seed,
        ..WalkSettings::default()
    };
    settings.validate()?;
    let model = Model {
        ndf: Ndf::Ggx,
        masking: Masking::HeightCorrelated,
    };
    let views = (grid.alphas.len() * grid.mus.len()) as u64;
    if !args.quiet {
        // About 0.5 s a view per 2^20 walks on two cores, walks and references (measured
        // 2026-12-07: 16 s for the default 32 views), twice that with kiln's own fit.
        let fits = if compensations.contains(&Compensation::Kiln) {
            2.0
        } else {
            1.0
        };
        let seconds = views as f64 * 0.5 * fits * args.walks as f64 / f64::from(1 << 20);
        if seconds > 5.0 {
            eprintln!(
                "kiln: {views} views of {} walks, about {} (fewer with --walks)",
                args.walks,
                crate::human_seconds(seconds)
            );
        }
    }
    let bar = crate::progress_bar(args.quiet, views, "walking");
    let audit = audit_compensations(model, &grid, &compensations, &settings, &|done| {
        bar.set_position(done)
    })?;
    bar.finish_and_clear();
    if args.json {
        println!(
            "{}",
            serde_json::to_string(&audit).expect("the audit serialises")
        );
    } else {
        print(&audit, &grid);
    }
    Ok(())
}

fn print(audit: &CompensationAudit, grid: &CompensationGrid) {
    println!(
        "against the microsurface walk (ggx height-correlated, Schlick F90 {}), {} walks a view, \
         {} points: {} roughness x {} mu x {} F0",
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
