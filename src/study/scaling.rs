//! `kiln study --scaling`: how a bake's cost and its errors grow with the table's size. For each
//! case (`E`, `E_avg`, the split-sum pair, a dielectric table) kiln bakes tables of increasing
//! size to one max error, the whole bake timed on the wall clock (its confirmation against the
//! reference included), and measures each table's node error (the bake's own confirmation) and
//! its lookup error at a fixed set of points, the same for every size, against the reference
//! computed once per case. A least-squares line through `ln(seconds)` against `ln(texels)` over
//! the largest sizes gives the exponent: 1 when the cost is per texel, so that doubling the size
//! costs 4x for a 2-D table and 8x for a 3-D one.
//!
//! Timings are measurements of this machine at this moment, reported, never asserted.

use crate::bake::BakeOptions;
use crate::integrate::reference::ReferenceSettings;
use crate::integrate::value::Point;
use crate::model::Model;
use crate::table::axis::{IorMapping, MuMapping};
use crate::table::{Quantity, Table};
use rayon::prelude::*;
use serde::Serialize;
use std::time::Instant;

/// One family of tables the study grows.
#[derive(Clone, Debug, PartialEq)]
pub struct Case {
    /// `E`, `E_avg`, `split-sum`, `E_dielectric`.
    pub name: String,
    /// The tables baked together.
    pub quantities: Vec<Quantity>,
    /// The sizes (samples per axis, every axis; the IOR axis too).
    pub sizes: Vec<usize>,
    /// The `mu` axis (kiln's adaptive one, or linear for the split-sum pair, which varies with
    /// `mu` on a mirror).
    pub mu_mapping: MuMapping,
}

/// What to run.
#[derive(Clone, Debug, PartialEq)]
pub struct ScalingSettings {
    pub model: Model,
    /// The max error every table is baked to.
    pub max_error: f64,
    pub cases: Vec<Case>,
    /// Fixed lookup points per axis (their number is this to the power of the table's
    /// dimension).
    pub lookup_points_per_axis: usize,
}

impl ScalingSettings {
    /// The full study (a few minutes on 2 cores): `E`, `E_avg` and the split-sum pair at 16 to
    /// 256 per axis, `E_dielectric` at 8 to 32 per axis (32^3 texels), all to 1e-6.
    #[must_use]
    pub fn full(model: Model) -> Self {
        let sizes = vec![16, 32, 64, 128, 256];
        Self::with(model, 1e-6, &sizes, &[8, 12, 16, 24, 32], 32)
    }

    /// A quick look (seconds): sizes 8 to 32 (4 to 8 for the dielectric table), to 1e-5.
    #[must_use]
    pub fn quick(model: Model) -> Self {
        Self::with(model, 1e-5, &[8, 16, 32], &[4, 6, 8], 16)
    }

    fn with(
        model: Model,
        max_error: f64,
        sizes: &[usize],
        dielectric_sizes: &[usize],
        lookup_points_per_axis: usize,
    ) -> Self {
        let case = |name: &str, quantities: Vec<Quantity>, sizes: &[usize]| Case {
            name: name.to_string(),
            mu_mapping: if quantities.iter().any(|q| q.varies_on_a_mirror()) {
                MuMapping::Linear
            } else {
                MuMapping::Adaptive
            },
            quantities,
            sizes: sizes.to_vec(),
        };
        Self {
            model,
            max_error,
            cases: vec![
                case("E", vec![Quantity::E], sizes),
                case("E_avg", vec![Quantity::EAvg], sizes),
                case("split-sum", vec![Quantity::EScale, Quantity::EBias], sizes),
                case(
                    "E_dielectric",
                    vec![Quantity::EDielectric],
                    dielectric_sizes,
                ),
            ],
            lookup_points_per_axis,
        }
    }

    /// The bake of `case` at `size`.
    #[must_use]
    pub fn options(&self, case: &Case, size: usize) -> BakeOptions {
        BakeOptions {
            ndfs: vec![self.model.ndf],
            maskings: vec![self.model.masking],
            quantities: case.quantities.clone(),
            size,
            ior_size: size,
            mu_mapping: Some(case.mu_mapping),
            max_error: Some(self.max_error),
            // The study measures point samples on linear rows, whatever the mu axis.
            roughness_spacing: Some(crate::table::axis::RoughnessSpacing::Linear),
            texels: Some(crate::table::Texels::Nodes),
            ..BakeOptions::default()
        }
    }

    /// Progress units: one per bake.
    #[must_use]
    pub fn work(&self) -> u64 {
        self.cases.iter().map(|c| c.sizes.len() as u64).sum()
    }
}

/// One bake of one case at one size.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ScalingRun {
    pub case: String,
    /// Samples per axis.
    pub size: usize,
    /// Texels of all the case's tables together.
    pub texels: usize,
    /// Wall time of the bake, all cores (the confirmation against the reference included).
    pub seconds: f64,
    /// The largest node error the bake's confirmation measured, over the case's tables.
    pub node_max_error: f64,
    /// The largest error of the tables' lookup at the case's fixed points.
    pub lookup_max_error: f64,
    pub lookup_rms_error: f64,
}

/// The fitted growth of one case's cost.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ScalingFit {
    pub case: String,
    /// The slope of `ln(seconds)` against `ln(texels)` over [`FITTED_SIZES`] largest sizes.
    pub exponent: f64,
    /// The sizes the line was fitted over.
    pub sizes: Vec<usize>,
}

/// Everything the scaling study measured.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ScalingReport {
    pub kiln_version: String,
    /// Threads rayon used.
    pub threads: usize,
    pub ndf: String,
    pub masking: String,
    pub max_error: f64,
    /// The fixed lookup points: this many per axis.
    pub lookup_points_per_axis: usize,
    pub runs: Vec<ScalingRun>,
    pub fits: Vec<ScalingFit>,
}

/// The exponent is fitted over this many of a case's largest sizes (the smallest bakes are
/// dominated by their fixed costs).
pub const FITTED_SIZES: usize = 3;

/// The least-squares slope of `ln(y)` against `ln(x)`; NaN for fewer than two points.
#[must_use]
pub fn log_log_slope(points: &[(f64, f64)]) -> f64 {
    let n = points.len() as f64;
    if points.len() < 2 {
        return f64::NAN;
    }
    let logs: Vec<(f64, f64)> = points.iter().map(|&(x, y)| (x.ln(), y.ln())).collect();
    let mean_x = logs.iter().map(|p| p.0).sum::<f64>() / n;
    let mean_y = logs.iter().map(|p| p.1).sum::<f64>() / n;
    let sxy: f64 = logs.iter().map(|p| (p.0 - mean_x) * (p.1 - mean_y)).sum();
    let sxx: f64 = logs.iter().map(|p| (p.0 - mean_x) * (p.0 - mean_x)).sum();
    sxy / sxx
}

/// The fixed lookup points of a table of `quantity`: `k` per axis at `(j + 0.37) / k` of each
/// axis' physical range (roughness `r`, `mu`, and for the dielectric tables `eta` from 1 to the
/// axis' top along Cycles' IOR mapping, whatever the layout studied), off every node of the sizes studied.
fn lookup_points(quantity: Quantity, k: usize) -> Vec<Point> {
    let t = |j: usize| (j as f64 + 0.37) / k as f64;
    let etas: Vec<Option<f64>> = if quantity.has_ior() {
        let options = BakeOptions::default();
        (0..k)
            .map(|j| Some(IorMapping::Cycles.eta(t(j), options.ior_max, 1.0)))
            .collect()
    } else {
        vec![None]
    };
    let mus: Vec<Option<f64>> = if quantity.has_mu() {
        (0..k).map(|j| Some(t(j))).collect()
    } else {
        vec![None]
    };
    let mut points = Vec::new();
    for &eta in &etas {
        for j in 0..k {
            let r = t(j);
            for &mu in &mus {
                points.push(Point {
                    alpha: r * r,
                    mu,
                    eta,
                });
            }
        }
    }
    points
}

/// Runs the study; `progress` hears of each bake done.
///
/// # Errors
/// If a case's bake is not valid options (checked for every case and size before any work).
pub fn run(
    settings: &ScalingSettings,
    progress: &(dyn Fn(u64) + Sync),
) -> crate::error::Result<ScalingReport> {
    for case in &settings.cases {
        if case.sizes.is_empty() {
            return Err(crate::error::Error::InvalidInput(format!(
                "scaling case {} has no sizes",
                case.name
            )));
        }
        for &size in &case.sizes {
            settings.options(case, size).validate()?;
        }
    }
    let truth_settings = ReferenceSettings {
        tolerance: settings.max_error / 100.0,
        ..ReferenceSettings::default()
    };
    let mut runs = Vec::new();
    for case in &settings.cases {
        // The truth at the fixed points, once per case: (quantity, points, values).
        let mut truths: Vec<(Quantity, Vec<Point>, Vec<f64>)> = Vec::new();
        // The truth does not depend on the size: the specs of the smallest bake name it.
        for spec in settings.options(case, case.sizes[0]).resolved().specs() {
            let quantity = spec.quantity;
            let integral = spec.integral();
            // The relative index (1 / eta for light from inside), as the lookup takes it too.
            let points: Vec<Point> = lookup_points(quantity, settings.lookup_points_per_axis)
                .into_iter()
                .map(|at| Point {
                    eta: at.eta.map(|eta| spec.relative_eta(eta)),
                    ..at
                })
                .collect();
            let values = points
                .par_iter()
                .map(|&at| integral.reference(at, &truth_settings).value)
                .collect();
            truths.push((quantity, points, values));
        }
        for &size in &case.sizes {
            let options = settings.options(case, size);
            let start = Instant::now();
            let tables = options.bake(&|_| {})?;
            let seconds = start.elapsed().as_secs_f64();
            let (mut max, mut sum2, mut count) = (0.0f64, 0.0, 0usize);
            for (quantity, points, values) in &truths {
                let table = find(&tables, *quantity);
                let convention = table.spec.roughness_convention();
                for (at, truth) in points.iter().zip(values) {
                    let looked = table.lookup_eta(
                        at.mu.unwrap_or(1.0),
                        convention.from_alpha(at.alpha),
                        at.eta.unwrap_or(1.0),
                    );
                    let error = (looked - truth).abs();
                    max = max.max(error);
                    sum2 += error * error;
                    count += 1;
                }
            }
            runs.push(ScalingRun {
                case: case.name.clone(),
                size,
                texels: tables.iter().map(|t| t.spec.len()).sum(),
                seconds,
                node_max_error: tables
                    .iter()
                    .filter_map(|t| t.node_errors.map(|e| e.max))
                    .fold(0.0, f64::max),
                lookup_max_error: max,
                lookup_rms_error: (sum2 / count.max(1) as f64).sqrt(),
            });
            progress(1);
        }
    }
    let fits = settings
        .cases
        .iter()
        .map(|case| {
            let mine: Vec<&ScalingRun> = runs.iter().filter(|r| r.case == case.name).collect();
            let fitted = &mine[mine.len().saturating_sub(FITTED_SIZES)..];
            ScalingFit {
                case: case.name.clone(),
                exponent: log_log_slope(
                    &fitted
                        .iter()
                        .map(|r| (r.texels as f64, r.seconds))
                        .collect::<Vec<_>>(),
                ),
                sizes: fitted.iter().map(|r| r.size).collect(),
            }
        })
        .collect();
    Ok(ScalingReport {
        kiln_version: crate::format::metadata::KILN_VERSION.to_string(),
        threads: rayon::current_num_threads(),
        ndf: settings.model.ndf.name().to_string(),
        masking: settings.model.masking.name().to_string(),
        max_error: settings.max_error,
        lookup_points_per_axis: settings.lookup_points_per_axis,
        runs,
        fits,
    })
}

fn find(tables: &[Table], quantity: Quantity) -> &Table {
    tables
        .iter()
        .find(|t| t.spec.quantity == quantity)
        .expect("the bake made the case's tables")
}

/// `scaling.csv`: `case,size,texels,seconds,node_max_error,lookup_max_error,lookup_rms_error`.
#[must_use]
pub fn scaling_csv(report: &ScalingReport) -> String {
    let mut out =
        String::from("case,size,texels,seconds,node_max_error,lookup_max_error,lookup_rms_error\n");
    for r in &report.runs {
        out.push_str(&format!(
            "{},{},{},{:.6},{:.6e},{:.6e},{:.6e}\n",
            r.case,
            r.size,
            r.texels,
            r.seconds,
            r.node_max_error,
            r.lookup_max_error,
            r.lookup_rms_error
        ));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_slope_of_a_power_law_is_its_exponent() {
        let points: Vec<(f64, f64)> = [16.0, 64.0, 256.0, 1024.0]
            .iter()
            .map(|&x: &f64| (x, 3.0 * x.powf(1.5)))
            .collect();
        assert!((log_log_slope(&points) - 1.5).abs() < 1e-12);
        assert!(log_log_slope(&points[..1]).is_nan());
    }

    #[test]
    fn lookup_points_cover_each_axis_off_the_nodes() {
        let points = lookup_points(Quantity::EDielectric, 4);
        assert_eq!(points.len(), 64);
        assert!(
            points
                .iter()
                .all(|p| p.eta.unwrap() > 1.0 && p.mu.unwrap() < 1.0)
        );
        assert_eq!(lookup_points(Quantity::EAvg, 4).len(), 4);
        assert_eq!(lookup_points(Quantity::E, 4).len(), 16);
    }
}
