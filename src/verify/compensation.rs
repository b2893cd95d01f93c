//! The audit of energy compensations against the microsurface walk: over a grid of roughness,
//! view and Schlick `F0`, the albedo Kulla-Conty's lobe and Turquin's scaling give
//! ([`crate::integrate::compensation`]) beside the albedo of every order of scattering on the
//! microsurface ([`crate::integrate::walk`], one set of walks per view for every `F0`).
//!
//! kiln's own compensation ([`Compensation::Kiln`]) is fitted at each view to walks of another
//! seed ([`KILN_FIT_SEED`]) than the audit's, so that it is measured against independent walks.
//!
//! Each figure is the relative deviation `compensated / walk - 1` with its 95 % confidence
//! half-width `1.96 (compensated / walk) (sigma_walk / walk)` (the compensations come from the
//! reference to 1e-10, so the walk's standard error is all the uncertainty there is).

use crate::integrate::compensation::{
    Compensation, KILN_FIT_SEED, KilnCompensation, SingleScattering,
};
use crate::integrate::reference::{ReferenceSettings, reference_average_albedo};
use crate::integrate::walk::{Measured, WalkError, WalkSettings, walk_schlick_polynomial};
use crate::model::{Fresnel, Model};
use crate::table::compensation::CompensationTable;
use serde::Serialize;

/// Where to measure.
#[derive(Clone, Debug, PartialEq)]
pub struct CompensationGrid {
    /// Slope-space roughness values (`alpha`).
    pub alphas: Vec<f64>,
    /// View cosines.
    pub mus: Vec<f64>,
    /// Schlick `F0` values, in `[0, 1]`.
    pub f0s: Vec<f64>,
    /// Schlick's `F90`, in `[0, 1]`.
    pub f90: f64,
}

/// One point of the audit.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CompensationPoint {
    pub alpha: f64,
    pub mu: f64,
    pub f0: f64,
    /// The walk's albedo (every order).
    pub walk: Measured,
    /// Single scattering alone, `E_F(mu)`.
    pub single: f64,
    /// Each compensation's albedo, in the order asked for.
    pub compensated: Vec<f64>,
}

impl CompensationPoint {
    /// `compensated / walk - 1` for compensation `k`, and its 95 % confidence half-width.
    #[must_use]
    pub fn deviation(&self, k: usize) -> (f64, f64) {
        let ratio = self.compensated[k] / self.walk.value;
        (
            ratio - 1.0,
            1.96 * ratio * self.walk.std_error / self.walk.value,
        )
    }
}

/// The largest deviation of one sign, where it is, and its confidence half-width.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Extreme {
    pub deviation: f64,
    pub confidence: f64,
    pub alpha: f64,
    pub mu: f64,
    pub f0: f64,
}

/// One compensation's figures over the grid.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CompensationSummary {
    pub compensation: Compensation,
    /// The most it gives too much (the largest `compensated / walk - 1`).
    pub highest: Extreme,
    /// The most it gives too little (the smallest).
    pub lowest: Extreme,
    /// The root mean square deviation over the grid's points.
    pub rms: f64,
}

/// The audit: every point, and a summary per compensation.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CompensationAudit {
    pub points: Vec<CompensationPoint>,
    pub summaries: Vec<CompensationSummary>,
    /// Walks per view.
    pub walks: u64,
    pub f90: f64,
}

/// Measures `compensations` against the walk over `grid` (GGX, height-correlated). kiln's is
/// `table`'s lookup where a table is given (what a renderer reads, its interpolation included),
/// else fitted at each view. `progress` hears the number of views done.
pub fn audit_compensations(
    model: Model,
    grid: &CompensationGrid,
    compensations: &[Compensation],
    settings: &WalkSettings,
    table: Option<&CompensationTable>,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<CompensationAudit, WalkError> {
    if let Some(&f0) = grid.f0s.iter().find(|f| !(0.0..=1.0).contains(*f)) {
        return Err(WalkError::F0(f0));
    }
    let reference = ReferenceSettings::default();
    let mut points = Vec::new();
    let mut done = 0;
    for &alpha in &grid.alphas {
        crate::integrate::walk::check_inputs(model, alpha, 0.5, 0)?;
        let e_avg = reference_average_albedo(model, alpha, &reference).value;
        for &mu in &grid.mus {
            let polynomial =
                walk_schlick_polynomial(model, alpha, mu, grid.f90, settings, &|_| {})?;
            let kiln = if compensations.contains(&Compensation::Kiln) {
                if grid.f90 != 1.0 {
                    return Err(WalkError::KilnFresnel(format!("F90 {}", grid.f90)));
                }
                match table {
                    Some(table) => {
                        let roughness = table.spec.roughness_convention().from_alpha(alpha);
                        Some(table.lookup(mu, roughness))
                    }
                    None => {
                        let fit_walks = WalkSettings {
                            seed: KILN_FIT_SEED,
                            ..*settings
                        };
                        Some(KilnCompensation::at(
                            model, alpha, mu, &fit_walks, &reference,
                        )?)
                    }
                }
            } else {
                None
            };
            for &f0 in &grid.f0s {
                let fresnel = Fresnel::Schlick {
                    f0: [f0; 3],
                    f90: [grid.f90; 3],
                };
                let single = SingleScattering {
                    kiln,
                    ..SingleScattering::at(model, alpha, mu, e_avg, &fresnel, &reference)
                };
                points.push(CompensationPoint {
                    alpha,
                    mu,
                    f0,
                    walk: polynomial.albedo(f0),
                    single: single.e_f[0],
                    compensated: compensations.iter().map(|c| c.albedo(&single)[0]).collect(),
                });
            }
            done += 1;
            progress(done);
        }
    }
    let summaries = compensations
        .iter()
        .enumerate()
        .map(|(k, &compensation)| summarise(&points, k, compensation))
        .collect();
    Ok(CompensationAudit {
        points,
        summaries,
        walks: settings.walks,
        f90: grid.f90,
    })
}

fn summarise(
    points: &[CompensationPoint],
    k: usize,
    compensation: Compensation,
) -> CompensationSummary {
    let extreme = |p: &CompensationPoint| {
        let (deviation, confidence) = p.deviation(k);
        Extreme {
            deviation,
            confidence,
            alpha: p.alpha,
            mu: p.mu,
            f0: p.f0,
        }
    };
    let all: Vec<Extreme> = points.iter().map(extreme).collect();
    let highest = *all
        .iter()
        .max_by(|a, b| a.deviation.total_cmp(&b.deviation))
        .expect("a grid has points");
    let lowest = *all
        .iter()
        .min_by(|a, b| a.deviation.total_cmp(&b.deviation))
        .expect("a grid has points");
    let rms =
        (all.iter().map(|e| e.deviation * e.deviation).sum::<f64>() / all.len() as f64).sqrt();
    CompensationSummary {
        compensation,
        highest,
        lowest,
        rms,
    }
}
