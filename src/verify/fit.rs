//! The audit of a texture-free fit ([`crate::fit::Fit`]): the fit's values against the
//! deterministic reference over the whole domain, `mu` in [0, 1] (0 included) and the
//! perceptual roughness `r` in [0, 1] (0 included), reporting each quantity's maximum error
//! and where it is, with an error map (`kiln verify-fit`).
//!
//! The points: `mu = t^2` and `r` on an `n x n` product grid in `(t, r)` (dense where the
//! grazing layer and the near-mirror are), then around each quantity's worst point finer grids
//! over the two cells either side of it, four rounds each a quarter the span of the last, so
//! that the stated maximum is the peak found, not a grid's sample of it.

use super::error_map::{ErrorMap, MAX_MAP_CELLS};
use crate::fit::Fit;
use crate::integrate::quantity::Quantity;
use crate::integrate::reference::ReferenceSettings;
use crate::integrate::value::{Integral, Point};
use crate::model::{Masking, Model, Ndf};
use rayon::prelude::*;
use serde::Serialize;

/// How to audit a fit ([`Default`]: against GGX height-correlated, 129 x 129 points, the
/// reference at 1e-7).
#[derive(Clone, Copy, Debug)]
pub struct FitAuditSettings {
    /// The model the fit approximates.
    pub model: Model,
    /// Grid points per axis (the ends included).
    pub points: usize,
    /// The reference's tolerance (its error estimate is reported beside each maximum).
    pub tolerance: f64,
}

impl Default for FitAuditSettings {
    fn default() -> Self {
        Self {
            model: Model {
                ndf: Ndf::Ggx,
                masking: Masking::HeightCorrelated,
            },
            points: 129,
            tolerance: 1e-7,
        }
    }
}

/// Refinement points per axis around a worst point.
const REFINE_POINTS: usize = 17;

/// Rounds of refinement, each over a span a quarter of the last's.
const ZOOM_ROUNDS: usize = 4;

/// One compared point.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct FitPoint {
    pub mu: f64,
    /// Perceptual roughness; `alpha = r^2`.
    pub r: f64,
    pub alpha: f64,
    pub fit: f64,
    pub reference: f64,
    /// `|fit - reference|`, NaN if the fit is NaN there.
    pub error: f64,
}

/// What the audit found for one quantity.
#[derive(Clone, Debug, Serialize)]
pub struct FitQuantityReport {
    pub quantity: Quantity,
    /// The largest error found (NaN if the fit is NaN anywhere).
    pub max_error: f64,
    /// Where it is.
    pub worst: FitPoint,
    /// Over the product grid.
    pub rms_error: f64,
    pub mean_error: f64,
    /// Points where the fit is NaN or infinite.
    pub non_finite_points: usize,
    /// The largest reference error estimate among the points compared.
    pub reference_error: f64,
    #[serde(skip)]
    pub map: ErrorMap,
}

/// The audit of one fit.
#[derive(Clone, Debug, Serialize)]
pub struct FitReport {
    pub fit: String,
    pub source: String,
    pub model: String,
    /// Product-grid points per axis, and all points compared (the refinements included).
    pub grid_points: usize,
    pub points_compared: usize,
    pub reference_tolerance: f64,
    pub quantities: Vec<FitQuantityReport>,
}

/// The product grid's `(mu, r)`, `mu = t^2`, row-major from `r = 0`.
fn grid(n: usize) -> Vec<(f64, f64)> {
    let at = |k: usize| k as f64 / (n - 1) as f64;
    (0..n)
        .flat_map(|j| (0..n).map(move |i| (at(i) * at(i), at(j))))
        .collect()
}

/// The reference values at `points` of each quantity the fit gives: `E` and `E_bias` are
/// integrated, `E_scale = E - E_bias`.
fn references(
    quantities: &[Quantity],
    points: &[(f64, f64)],
    settings: &FitAuditSettings,
    progress: &(dyn Fn() + Sync),
) -> Vec<Vec<(f64, f64)>> {
    let reference = ReferenceSettings {
        tolerance: settings.tolerance,
        ..ReferenceSettings::default()
    };
    let needs_bias = quantities.iter().any(|q| *q != Quantity::E);
    let needs_e = quantities.iter().any(|q| *q != Quantity::EBias);
    let at = |quantity: Quantity, mu: f64, r: f64| {
        let integral = Integral {
            quantity,
            ..Integral::albedo(settings.model)
        };
        let point = Point {
            alpha: r * r,
            mu: Some(mu),
            eta: None,
        };
        let v = integral.reference(point, &reference);
        (v.value, v.error)
    };
    let values: Vec<((f64, f64), (f64, f64))> = points
        .par_iter()
        .map(|&(mu, r)| {
            let e = if needs_e {
                at(Quantity::E, mu, r)
            } else {
                (f64::NAN, 0.0)
            };
            let bias = if needs_bias {
                at(Quantity::EBias, mu, r)
            } else {
                (f64::NAN, 0.0)
            };
            progress();
            (e, bias)
        })
        .collect();
    quantities
        .iter()
        .map(|q| {
            values
                .iter()
                .map(|&(e, bias)| match q {
                    Quantity::EBias => bias,
                    Quantity::EScale => (e.0 - bias.0, e.1 + bias.1),
                    _ => e,
                })
                .collect()
        })
        .collect()
}

fn compare(fit: &Fit, quantity: Quantity, (mu, r): (f64, f64), reference: f64) -> FitPoint {
    let value = fit.value(quantity, mu, r);
    let error = if value.is_finite() {
        (value - reference).abs()
    } else {
        f64::NAN
    };
    FitPoint {
        mu,
        r,
        alpha: r * r,
        fit: value,
        reference,
        error,
    }
}

/// The number of reference evaluations [`audit_fit`] makes (for a progress bar): the grid and
/// the zoom rounds of each quantity.
#[must_use]
pub fn fit_audit_points(fit: &Fit, settings: &FitAuditSettings) -> u64 {
    (settings.points * settings.points
        + fit.quantities().len() * ZOOM_ROUNDS * REFINE_POINTS * REFINE_POINTS) as u64
}

/// The estimated cost of [`audit_fit`], in seconds of one core: each point costs the reference
/// of every quantity the fit gives, at the audit's tolerance.
#[must_use]
pub fn fit_audit_core_seconds(fit: &Fit, settings: &FitAuditSettings) -> f64 {
    let digits = (-settings.tolerance.log10()).round().max(1.0) as u32;
    let per_point: f64 = fit
        .quantities()
        .into_iter()
        .map(|q| crate::integrate::cost::reference_seconds(q, settings.model, digits))
        .sum();
    fit_audit_points(fit, settings) as f64 * per_point
}

/// The estimated wall time of `kiln fit` on `threads` threads, in seconds: the polynomial
/// fit's truth points (the reference to 1e-8, in parallel), then for each of `polynomials`
/// polynomial fits and each rational fit of `rationals` its audit over the default grid (the
/// reference to 1e-7, in parallel), and each rational fit's own solve
/// ([`crate::fit::rational::estimated_seconds`], one thread).
#[must_use]
pub fn fits_seconds(
    model: Model,
    polynomials: usize,
    rationals: &[crate::fit::rational::RationalShape],
    threads: f64,
) -> f64 {
    let e = |digits| crate::integrate::cost::reference_seconds(Quantity::E, model, digits);
    let truth = crate::fit::polynomial::truth_point_count() as f64 * e(8);
    let audit = FitAuditSettings::default().points.pow(2) as f64 * e(7) / threads;
    let solves: f64 = rationals
        .iter()
        .map(|&shape| crate::fit::rational::estimated_seconds(shape))
        .sum();
    truth / threads + (polynomials + rationals.len()) as f64 * audit + solves
}

/// Audits `fit` against the reference for `settings.model` (see the module docs);
/// `progress` hears of each point compared.
///
/// # Panics
/// If `settings.points < 2`.
#[must_use]
pub fn audit_fit(
    fit: &Fit,
    settings: &FitAuditSettings,
    progress: &(dyn Fn() + Sync),
) -> FitReport {
    let n = settings.points;
    assert!(n >= 2, "a fit audit needs at least 2 points per axis");
    let points = grid(n);
    let truth = references(&fit.quantities(), &points, settings, progress);
    let step = 1.0 / (n - 1) as f64;
    let mut compared = points.len();
    let quantities = fit
        .quantities()
        .into_iter()
        .zip(truth)
        .map(|(quantity, truth)| {
            let found: Vec<FitPoint> = points
                .iter()
                .zip(&truth)
                .map(|(&p, &(reference, _))| compare(fit, quantity, p, reference))
                .collect();
            let worst_on_grid = *found
                .iter()
                .max_by(|a, b| a.error.total_cmp(&b.error))
                .expect("points");
            // Zoom in on the worst point: each round compares a 17 x 17 grid over two of the
            // previous round's cells either side of the worst so far (in (t, r)), so the last
            // round's spacing is the grid's over 4^ZOOM_ROUNDS.
            let mut refined: Vec<FitPoint> = Vec::new();
            let mut fine_errors: Vec<f64> = Vec::new();
            let mut best = worst_on_grid;
            let mut spacing = step;
            for _ in 0..ZOOM_ROUNDS {
                let (t0, r0) = (best.mu.sqrt(), best.r);
                let span = |c: f64, k: usize| {
                    let lo = (c - 2.0 * spacing).max(0.0);
                    let hi = (c + 2.0 * spacing).min(1.0);
                    lo + (hi - lo) * k as f64 / (REFINE_POINTS - 1) as f64
                };
                let fine: Vec<(f64, f64)> = (0..REFINE_POINTS)
                    .flat_map(|j| {
                        (0..REFINE_POINTS).map(move |i| {
                            let t = span(t0, i);
                            (t * t, span(r0, j))
                        })
                    })
                    .collect();
                let fine_truth = &references(&[quantity], &fine, settings, progress)[0];
                compared += fine.len();
                fine_errors.extend(fine_truth.iter().map(|t| t.1));
                let round: Vec<FitPoint> = fine
                    .iter()
                    .zip(fine_truth)
                    .map(|(&p, &(reference, _))| compare(fit, quantity, p, reference))
                    .collect();
                if let Some(p) = round.iter().max_by(|a, b| a.error.total_cmp(&b.error))
                    && p.error.total_cmp(&best.error).is_gt()
                {
                    best = *p;
                }
                refined.extend(round);
                spacing *= 4.0 / (REFINE_POINTS - 1) as f64;
            }
            let worst = *found
                .iter()
                .chain(&refined)
                .max_by(|a, b| a.error.total_cmp(&b.error))
                .expect("points");
            let errors = || found.iter().map(|p| p.error).filter(|e| e.is_finite());
            let count = errors().count().max(1) as f64;
            let non_finite_points = found
                .iter()
                .chain(&refined)
                .filter(|p| !p.error.is_finite())
                .count();
            FitQuantityReport {
                quantity,
                max_error: if non_finite_points > 0 {
                    f64::NAN
                } else {
                    worst.error
                },
                worst,
                rms_error: (errors().map(|e| e * e).sum::<f64>() / count).sqrt(),
                mean_error: errors().sum::<f64>() / count,
                non_finite_points,
                reference_error: crate::stats::max_or_nan(
                    truth.iter().map(|t| t.1).chain(fine_errors),
                ),
                map: error_map(quantity, &found, worst),
            }
        })
        .collect();
    FitReport {
        fit: fit.name().to_string(),
        source: fit.source().to_string(),
        model: settings.model.to_string(),
        grid_points: n,
        points_compared: compared,
        reference_tolerance: settings.tolerance,
        quantities,
    }
}

/// The grid's errors over `(sqrt(mu), r)` in at most [`MAX_MAP_CELLS`] cells per axis.
fn error_map(quantity: Quantity, found: &[FitPoint], worst: FitPoint) -> ErrorMap {
    let n = (found.len() as f64).sqrt().round() as usize;
    let cells_per_axis = n.min(MAX_MAP_CELLS);
    let mut cells: Vec<Option<f64>> = vec![None; cells_per_axis * cells_per_axis];
    let cell = |x: f64| ((x * cells_per_axis as f64) as usize).min(cells_per_axis - 1);
    for p in found {
        let k = cell(p.r) * cells_per_axis + cell(p.mu.sqrt());
        let e = if p.error.is_finite() {
            p.error
        } else {
            f64::NAN
        };
        cells[k] = Some(match cells[k] {
            Some(old) if old.is_nan() || e.is_nan() => f64::NAN,
            Some(old) => old.max(e),
            None => e,
        });
    }
    ErrorMap {
        group: quantity.symbol(),
        columns: cells_per_axis,
        rows: cells_per_axis,
        cells,
        worst: (worst.mu.sqrt(), worst.r, worst.error),
        eta: None,
        x_axis: "sqrt(mu)".to_string(),
        y_axis: "roughness r (alpha = r^2)".to_string(),
    }
}

/// Audits a fit kiln made ([`crate::fit::polynomial`], [`crate::fit::rational`]) as what it
/// writes: the formula file's text ([`crate::fit::emit`]) parsed back and audited by
/// [`audit_fit`], so that the maximum stated is that of the formula a user pastes.
///
/// # Panics
/// If kiln's own formula file does not parse (a bug).
#[must_use]
pub fn audit_emitted(
    fit: &impl crate::fit::emit::FitText,
    settings: &FitAuditSettings,
    progress: &(dyn Fn() + Sync),
) -> FitReport {
    let text = crate::fit::emit::emit(fit, crate::fit::emit::FitFormat::Toml, "");
    let formula = crate::fit::FormulaFit::parse(&text).expect("kiln's formula files parse");
    audit_fit(&Fit::Formula(formula), settings, progress)
}
