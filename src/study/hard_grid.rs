//! The hard grid: QMC estimates of `E` and of the Schlick-weighted albedo at the points where
//! sampling is hardest (grazing and normal views, near-mirror and very rough surfaces), each
//! compared with the deterministic reference and scored in units of the QMC's own standard
//! error. A stated error is honest when no point scores far beyond a few units.
//!
//! The dielectric grid does the same for the energy albedo `R + T` of a rough dielectric
//! interface ([`crate::integrate::dielectric`]) over the relative index `eta`, from 1/3 to 3 and
//! at 1.001 and 1/1.001, where the interface nearly vanishes and total internal reflection sets
//! in at grazing normals.
//!
//! `cargo run --release --example hard_grid [-- --dielectric]` runs the whole grid and prints the
//! worst scores; `tests/hard_grid.rs` holds a fast subset of the first and the whole second at
//! 2^16 samples.

use crate::integrate::QmcSettings;
use crate::integrate::albedo::{albedo, weighted_albedo};
use crate::integrate::dielectric::{dielectric_albedo, reference_dielectric_albedo};
use crate::integrate::estimate::Estimate;
use crate::integrate::reference::{ReferenceSettings, reference_albedo, reference_weighted_albedo};
use crate::model::{Masking, Model, Ndf};
use serde::Serialize;

/// The grid's view cosines `mu`.
pub const MU: [f64; 7] = [0.0, 1e-6, 1e-4, 1e-3, 0.01, 0.5, 1.0];
/// The grid's slope-space roughnesses `alpha`.
pub const ALPHA: [f64; 6] = [1e-4, 1e-3, 1e-2, 0.1, 1.0, 2.0];
/// The weights: `None` is `F = 1` (`E` itself), `Some(f0)` Schlick's `F0 + (1 - F0)(1 - c)^5`.
pub const WEIGHTS: [Option<f64>; 3] = [None, Some(0.04), Some(0.5)];

/// One point of the grid.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct HardPoint {
    pub model: Model,
    pub alpha: f64,
    pub mu: f64,
    /// Schlick's `F0`, or `None` for `F = 1`.
    pub f0: Option<f64>,
}

/// Every point: both distributions, both Smith maskings, every weight, `alpha` and `mu`.
#[must_use]
pub fn points() -> Vec<HardPoint> {
    let mut out = Vec::new();
    for ndf in [Ndf::Ggx, Ndf::Beckmann] {
        for masking in Masking::ALL {
            for f0 in WEIGHTS {
                for alpha in ALPHA {
                    for mu in MU {
                        out.push(HardPoint {
                            model: Model { ndf, masking },
                            alpha,
                            mu,
                            f0,
                        });
                    }
                }
            }
        }
    }
    out
}

/// Schlick's reflectance at `F0` (`F90 = 1`) for the cosine `c` between view and half vector.
fn schlick(f0: f64) -> impl Fn(f64) -> f64 + Copy {
    move |c: f64| f0 + (1.0 - f0) * (1.0 - c).powi(5)
}

/// The dielectric grid's view cosines `mu`.
pub const DIELECTRIC_MU: [f64; 6] = [0.0, 0.05, 0.3, 0.7, 0.99, 1.0];
/// The dielectric grid's roughnesses `alpha`.
pub const DIELECTRIC_ALPHA: [f64; 6] = [1e-4, 1e-3, 1e-2, 0.1, 0.5, 1.0];
/// The dielectric grid's relative indices `eta = n_other / n_view`: inside and outside glass
/// and a dense medium, and either side of an interface that nearly vanishes.
pub const ETA: [f64; 6] = [1.0 / 3.0, 1.0 / 1.5, 1.0 / 1.001, 1.001, 1.5, 3.0];

/// One point of the dielectric grid.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct DielectricPoint {
    pub model: Model,
    pub alpha: f64,
    pub mu: f64,
    pub eta: f64,
}

/// Every point of the dielectric grid: both distributions (height-correlated masking), every
/// `alpha`, `mu` and `eta`.
#[must_use]
pub fn dielectric_points() -> Vec<DielectricPoint> {
    let mut out = Vec::new();
    for ndf in [Ndf::Ggx, Ndf::Beckmann] {
        for alpha in DIELECTRIC_ALPHA {
            for mu in DIELECTRIC_MU {
                for eta in ETA {
                    out.push(DielectricPoint {
                        model: Model {
                            ndf,
                            masking: Masking::HeightCorrelated,
                        },
                        alpha,
                        mu,
                        eta,
                    });
                }
            }
        }
    }
    out
}

/// The QMC estimate at a point beside the reference, and the score.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct HardCheck<P = HardPoint> {
    pub point: P,
    pub samples: u64,
    /// `1 - value` by QMC and its stated standard error.
    pub qmc_one_minus: f64,
    pub std_error: f64,
    /// `1 - value` by the reference quadrature and its error estimate.
    pub reference_one_minus: f64,
    pub reference_error: f64,
    /// `|QMC - reference| / sqrt(std_error^2 + reference_error^2)`; 0 when both are exact and
    /// agree, infinite when both claim exactness and differ.
    pub z: f64,
}

/// The reference's tolerance: far below any QMC standard error the grid meets.
pub const REFERENCE_TOLERANCE: f64 = 1e-13;

/// Scores the QMC estimate at `point` with `samples` points in `scrambles` scrambles.
#[must_use]
pub fn check(point: HardPoint, samples: u64, scrambles: u32, seed: u64) -> HardCheck {
    let (settings, reference_settings) = grid_settings(samples, scrambles, seed);
    let HardPoint {
        model, alpha, mu, ..
    } = point;
    let (qmc, reference) = match point.f0 {
        None => (
            albedo(model, alpha, mu, &settings),
            reference_albedo(model, alpha, mu, &reference_settings),
        ),
        Some(f0) => (
            weighted_albedo(model, alpha, mu, schlick(f0), &settings),
            reference_weighted_albedo(model, alpha, mu, schlick(f0), &reference_settings),
        ),
    };
    score(
        point,
        samples,
        qmc,
        (reference.one_minus_value, reference.error),
    )
}

/// Scores the QMC estimate of `R + T` at `point` with `samples` points in `scrambles`
/// scrambles against the dielectric reference.
#[must_use]
pub fn check_dielectric(
    point: DielectricPoint,
    samples: u64,
    scrambles: u32,
    seed: u64,
) -> HardCheck<DielectricPoint> {
    let (settings, reference_settings) = grid_settings(samples, scrambles, seed);
    let DielectricPoint {
        model,
        alpha,
        mu,
        eta,
    } = point;
    let qmc = dielectric_albedo(model, alpha, mu, eta, &settings);
    let reference = reference_dielectric_albedo(model, alpha, mu, eta, &reference_settings);
    let (one_minus, error) = (reference.one_minus_value, reference.error);
    score(point, samples, qmc, (one_minus, error))
}

/// The QMC settings of one check and the reference's, shared by both grids.
fn grid_settings(samples: u64, scrambles: u32, seed: u64) -> (QmcSettings, ReferenceSettings) {
    (
        QmcSettings {
            samples,
            scrambles,
            seed,
        },
        ReferenceSettings {
            tolerance: REFERENCE_TOLERANCE,
            max_intervals: 400,
        },
    )
}

/// The check of `qmc` against the reference's `(1 - value, error estimate)`.
fn score<P>(
    point: P,
    samples: u64,
    qmc: Estimate,
    (reference_one_minus, reference_error): (f64, f64),
) -> HardCheck<P> {
    let difference = (qmc.one_minus_value - reference_one_minus).abs();
    let scale = qmc.std_error.hypot(reference_error);
    let z = if difference == 0.0 {
        0.0
    } else {
        difference / scale
    };
    HardCheck {
        point,
        samples,
        qmc_one_minus: qmc.one_minus_value,
        std_error: qmc.std_error,
        reference_one_minus,
        reference_error,
        z,
    }
}
