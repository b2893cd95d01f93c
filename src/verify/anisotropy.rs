//! How far an engine's isotropic `E` table is from an anisotropic lobe's albedo when the engine
//! reads it at one roughness (`kiln verify-anisotropy`).
//!
//! Every engine compensates an anisotropic GGX lobe with its isotropic `E(mu, alpha)` read at a
//! single `alpha` ([`IsotropicReading`]). The audit takes the engine's own parameters over a grid
//! (perceptual roughness `r`, `alpha = r^2`, and anisotropy `a`, turned into `(alpha_x,
//! alpha_y)` by its [`AnisotropyConvention`]), and at each view `(mu, phi)` compares the
//! isotropic reference `E(mu, alpha_read)` with the anisotropic reference `E(mu, phi; alpha_x,
//! alpha_y)` (`crate::integrate::anisotropic`). Both are quadratures with error estimates far
//! below the errors reported (the tolerance is [`TRUTH_TOLERANCE`]).

use super::ErrorMap;
use crate::integrate::anisotropic::reference_anisotropic_albedo;
use crate::integrate::reference::{ReferenceSettings, reference_albedo};
use crate::model::{
    AnisotropicGgx, AnisotropyConvention, IsotropicReading, Masking, Model, Ndf,
    RoughnessConvention,
};
use rayon::prelude::*;
use serde::Serialize;
use std::f64::consts::FRAC_PI_2;

/// The reference's tolerance on both sides of the comparison: errors of 1e-3 and more are
/// reported to three digits with room to spare.
pub const TRUTH_TOLERANCE: f64 = 1e-9;

/// The grid an audit runs over.
#[derive(Clone, Debug, PartialEq)]
pub struct AnisotropyGrid {
    /// Perceptual roughness values (`alpha = r^2`).
    pub roughness: Vec<f64>,
    /// Anisotropy values, each within the convention's range.
    pub anisotropy: Vec<f64>,
    /// View cosines.
    pub mu: Vec<f64>,
    /// View azimuths in radians from the tangent, in `[0, pi/2]` (`E` is even and of period
    /// `pi` in the azimuth, so this quarter holds every value).
    pub phi: Vec<f64>,
}

impl AnisotropyGrid {
    /// The points of the grid: roughness x anisotropy x `mu` x azimuth.
    #[must_use]
    pub fn points(&self) -> usize {
        self.roughness.len() * self.anisotropy.len() * self.mu.len() * self.phi.len()
    }

    /// The estimated cost of [`audit_anisotropy`] over this grid, in seconds of one core: about
    /// 5 ms a point at the audit's tolerance, both references (measured over the standard grid,
    /// `kiln verify-anisotropy kulla-conty`, 2026-12-07).
    #[must_use]
    pub fn audit_core_seconds(&self) -> f64 {
        self.points() as f64 * 5e-3
    }

    /// The default grid: `r` from 0.1 to 1 in 16 steps, `a` = 0.25, 0.5, 0.75, 0.95, 16 view
    /// cosines from 0.02 to 1 (denser at grazing: `mu = 0.02 + 0.98 t^2`), 5 azimuths from 0 to
    /// `pi/2`.
    #[must_use]
    pub fn standard(convention: AnisotropyConvention) -> Self {
        let max = convention.max_anisotropy();
        let steps = |n: usize, f: &dyn Fn(f64) -> f64| {
            (0..n)
                .map(|k| f(k as f64 / (n - 1) as f64))
                .collect::<Vec<_>>()
        };
        Self {
            roughness: steps(16, &|t| 0.1 + 0.9 * t),
            anisotropy: [0.25, 0.5, 0.75, 0.95]
                .into_iter()
                .map(|a: f64| a.min(max))
                .collect(),
            mu: steps(16, &|t| 0.02 + 0.98 * t * t),
            phi: steps(5, &|t| FRAC_PI_2 * t),
        }
    }
}

/// One compared point.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct AnisotropyPoint {
    /// Perceptual roughness and anisotropy, in the convention's terms.
    pub roughness: f64,
    pub anisotropy: f64,
    pub alpha_x: f64,
    pub alpha_y: f64,
    /// The single roughness the engine reads its isotropic table at.
    pub alpha_read: f64,
    pub mu: f64,
    pub phi: f64,
    /// The anisotropic lobe's `E` at this view.
    pub truth: f64,
    /// The isotropic `E` the engine reads.
    pub read: f64,
    /// `read - truth`: positive where the engine believes the lobe keeps more energy than it
    /// does (its compensation then adds too little).
    pub error: f64,
}

/// The worst point at one anisotropy.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct AnisotropyRow {
    pub anisotropy: f64,
    pub max_error: f64,
    pub worst: AnisotropyPoint,
}

/// What [`audit_anisotropy`] measured.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AnisotropyAudit {
    pub convention: AnisotropyConvention,
    pub reading: IsotropicReading,
    /// The largest `|read - truth|` over the grid.
    pub max_error: f64,
    pub worst: AnisotropyPoint,
    /// The worst point at each anisotropy of the grid.
    pub by_anisotropy: Vec<AnisotropyRow>,
    /// The largest spread `max_phi E - min_phi E` at one `(r, a, mu)`: what no single roughness,
    /// whatever the reading, can follow.
    pub max_azimuthal_spread: f64,
    pub points: usize,
    pub truth_tolerance: f64,
    /// Every point compared, anisotropy slowest, then `r`, `mu`, `phi`.
    #[serde(skip)]
    pub compared: Vec<AnisotropyPoint>,
}

/// Audits the convention's reading of an isotropic table over `grid` (module docs).
///
/// # Errors
/// An anisotropy outside the convention's range, a roughness outside (0, 1], a `mu` outside
/// (0, 1] or an azimuth outside `[0, pi/2]`, or an empty axis.
pub fn audit_anisotropy(
    convention: AnisotropyConvention,
    grid: &AnisotropyGrid,
) -> crate::Result<AnisotropyAudit> {
    let empty = [
        ("roughness", grid.roughness.is_empty()),
        ("anisotropy", grid.anisotropy.is_empty()),
        ("mu", grid.mu.is_empty()),
        ("phi", grid.phi.is_empty()),
    ];
    if let Some((axis, _)) = empty.iter().find(|(_, e)| *e) {
        return Err(crate::Error::InvalidInput(format!(
            "the audit's {axis} axis is empty"
        )));
    }
    for &r in &grid.roughness {
        if !(r > 0.0 && r <= 1.0) {
            return Err(crate::Error::InvalidInput(format!(
                "roughness {r} is outside (0, 1]"
            )));
        }
    }
    for &mu in &grid.mu {
        if !(mu > 0.0 && mu <= 1.0) {
            return Err(crate::Error::InvalidInput(format!(
                "mu = {mu} is outside (0, 1]"
            )));
        }
    }
    for &phi in &grid.phi {
        if !(0.0..=FRAC_PI_2).contains(&phi) {
            return Err(crate::Error::InvalidInput(format!(
                "phi = {phi} is outside [0, pi/2]"
            )));
        }
    }
    for &a in &grid.anisotropy {
        convention.check_anisotropy(a)?;
    }
    let reading = convention.reading();
    let settings = ReferenceSettings {
        tolerance: TRUTH_TOLERANCE,
        ..ReferenceSettings::default()
    };
    let model = Model {
        ndf: Ndf::Ggx,
        masking: Masking::HeightCorrelated,
    };
    let mut jobs = Vec::new();
    for &a in &grid.anisotropy {
        for &r in &grid.roughness {
            for &mu in &grid.mu {
                jobs.push((a, r, mu));
            }
        }
    }
    // One job per (a, r, mu): its azimuths share the isotropic value.
    let rows: Vec<(Vec<AnisotropyPoint>, f64)> = jobs
        .par_iter()
        .map(|&(a, r, mu)| {
            let alpha = RoughnessConvention::Perceptual.to_alpha(r);
            let (alpha_x, alpha_y) = convention.alphas(alpha, a);
            let alpha_read = reading.alpha(alpha_x, alpha_y);
            let read = reference_albedo(model, alpha_read, mu, &settings).value;
            let ndf = AnisotropicGgx { alpha_x, alpha_y };
            let points: Vec<AnisotropyPoint> = grid
                .phi
                .iter()
                .map(|&phi| {
                    let truth = reference_anisotropic_albedo(ndf, mu, phi, &settings).value;
                    AnisotropyPoint {
                        roughness: r,
                        anisotropy: a,
                        alpha_x,
                        alpha_y,
                        alpha_read,
                        mu,
                        phi,
                        truth,
                        read,
                        error: read - truth,
                    }
                })
                .collect();
            let (lo, hi) = points.iter().fold((f64::MAX, f64::MIN), |(lo, hi), p| {
                (lo.min(p.truth), hi.max(p.truth))
            });
            (points, hi - lo)
        })
        .collect();
    let max_azimuthal_spread = rows.iter().map(|r| r.1).fold(0.0, f64::max);
    let compared: Vec<AnisotropyPoint> = rows.into_iter().flat_map(|r| r.0).collect();
    let worst_of = |points: &mut dyn Iterator<Item = &AnisotropyPoint>| {
        *points
            .max_by(|x, y| x.error.abs().total_cmp(&y.error.abs()))
            .expect("a non-empty grid")
    };
    let worst = worst_of(&mut compared.iter());
    let by_anisotropy = grid
        .anisotropy
        .iter()
        .map(|&a| {
            let worst = worst_of(&mut compared.iter().filter(|p| p.anisotropy == a));
            AnisotropyRow {
                anisotropy: a,
                max_error: worst.error.abs(),
                worst,
            }
        })
        .collect();
    Ok(AnisotropyAudit {
        convention,
        reading,
        max_error: worst.error.abs(),
        worst,
        by_anisotropy,
        max_azimuthal_spread,
        points: compared.len(),
        truth_tolerance: TRUTH_TOLERANCE,
        compared,
    })
}

/// The audit's errors as pictures' data: one map per anisotropy, `mu` across and `r` up, each
/// cell the largest `|error|` over the azimuths.
#[must_use]
pub fn anisotropy_maps(audit: &AnisotropyAudit, grid: &AnisotropyGrid) -> Vec<ErrorMap> {
    let (columns, rows) = (grid.mu.len(), grid.roughness.len());
    let per_row = columns * grid.phi.len();
    let per_map = rows * per_row;
    let ends = |v: &[f64]| (v[0], v[v.len() - 1]);
    let (mu_range, r_range) = (ends(&grid.mu), ends(&grid.roughness));
    audit
        .compared
        .chunks(per_map)
        .zip(&grid.anisotropy)
        .map(|(points, &a)| {
            let mut cells = vec![Some(0.0f64); rows * columns];
            let mut worst = (0.0, 0.0, -1.0);
            for (k, p) in points.iter().enumerate() {
                let (row, column) = (k / per_row, (k % per_row) / grid.phi.len());
                let cell = cells[row * columns + column].get_or_insert(0.0);
                *cell = cell.max(p.error.abs());
                if p.error.abs() > worst.2 {
                    let at = |i: usize, n: usize| (i as f64 + 0.5) / n as f64;
                    worst = (at(column, columns), at(row, rows), p.error.abs());
                }
            }
            ErrorMap {
                group: "read",
                columns,
                rows,
                cells,
                worst,
                eta: None,
                x_axis: format!(
                    "mu ({} to {}, denser at grazing), a = {a}",
                    mu_range.0, mu_range.1
                ),
                y_axis: format!("r ({} to {})", r_range.0, r_range.1),
            }
        })
        .collect()
}
