//! `kiln study`: what accuracy costs. Every estimator of [`estimators`] fills the same `E` table
//! at increasing sample counts (the quadrature at decreasing tolerances), timed on the wall clock
//! with every core, and its max and RMS error at the table's nodes is measured against the
//! deterministic reference; and reference-filled tables of increasing size, for each mu axis
//! mapping, are audited for their lookup error as `kiln verify` measures it.
//!
//! Timings are measurements of this machine at this moment, reported, never asserted.

pub mod estimators;
pub mod hard_grid;
pub mod scaling;
pub mod yardstick;

use crate::bake::{BakeOptions, bake_table};
use crate::integrate::reference::{ReferenceSettings, reference_albedo};
use crate::model::Model;
use crate::table::axis::{Grid, MuMapping};
use crate::table::{Method, Quantity, TableSpec};
use crate::verify::{Against, AuditSettings, Progress, audit, audit_points};
use estimators::{Estimator, estimate};
use rayon::prelude::*;
use serde::Serialize;
use std::time::Instant;

/// What to run.
#[derive(Clone, Debug)]
pub struct StudySettings {
    pub model: Model,
    /// The `E` table the estimators fill: `size x size`, kiln's default axes.
    pub size: usize,
    /// Sample counts per sampling estimator.
    pub samples: Vec<(Estimator, Vec<u64>)>,
    /// Tolerances of the quadrature.
    pub tolerances: Vec<f64>,
    /// Table sizes of the lookup study.
    pub lookup_sizes: Vec<usize>,
    /// Mappings of the lookup study.
    pub lookup_mappings: Vec<MuMapping>,
    pub seed: u64,
}

fn powers_of_two(from: u32, to: u32) -> Vec<u64> {
    (from..=to).map(|k| 1u64 << k).collect()
}

impl StudySettings {
    /// The full study: a 32 x 32 table, up to 2^20 samples per texel for kiln's estimator and
    /// 2^18 for the others, tolerances 1e-2 to 1e-10 (the reference it is measured against is
    /// the same quadrature at 1e-11), lookup tables of 8 to 128.
    #[must_use]
    pub fn full(model: Model) -> Self {
        Self::with(model, 32, 18, 20, 10, &[8, 16, 32, 64, 128])
    }

    /// A quick look (under a minute on 2 cores): a 16 x 16 table, up to 2^14 samples (2^16 for
    /// kiln's estimator), tolerances down to 1e-8, lookup tables of 8 to 32.
    #[must_use]
    pub fn quick(model: Model) -> Self {
        Self::with(model, 16, 14, 16, 8, &[8, 16, 32])
    }

    fn with(
        model: Model,
        size: usize,
        top: u32,
        kiln_top: u32,
        digits: i32,
        lookup_sizes: &[usize],
    ) -> Self {
        let samples = Estimator::ALL
            .iter()
            .filter(|&&e| e != Estimator::Quadrature)
            .map(|&e| {
                let top = if e == Estimator::VndfSobol {
                    kiln_top
                } else {
                    top
                };
                (e, powers_of_two(2, top))
            })
            .collect();
        Self {
            model,
            size,
            samples,
            tolerances: (2..=digits).map(|d| 10f64.powi(-d)).collect(),
            lookup_sizes: lookup_sizes.to_vec(),
            lookup_mappings: vec![MuMapping::Linear, MuMapping::Sqrt, MuMapping::Adaptive],
            seed: 0,
        }
    }

    /// The `E` table the estimators fill (kiln's default axes at `size`).
    #[must_use]
    pub fn table_spec(&self) -> TableSpec {
        e_spec(self.model, self.size, MuMapping::Adaptive, Method::Qmc)
    }

    /// Progress units: one per texel estimated, per reference value, per audited point.
    #[must_use]
    pub fn work(&self) -> u64 {
        let texels = (self.size * self.size) as u64;
        let runs: usize =
            self.samples.iter().map(|(_, s)| s.len()).sum::<usize>() + self.tolerances.len();
        let lookup: u64 = self
            .lookup_mappings
            .iter()
            .flat_map(|&mapping| self.lookup_sizes.iter().map(move |&n| (mapping, n)))
            .map(|(mapping, n)| {
                let spec = lookup_spec(self.model, n, mapping);
                spec.len() as u64 + audit_points(&spec, &AuditSettings::default())
            })
            .sum();
        texels * (runs as u64 + 1) + lookup
    }
}

fn e_spec(model: Model, size: usize, mapping: MuMapping, method: Method) -> TableSpec {
    let options = BakeOptions {
        size,
        mu_mapping: Some(mapping),
        grid: Grid::Nodes,
        method,
        max_error: None,
        roughness_spacing: Some(crate::table::axis::RoughnessSpacing::Linear),
        texels: Some(crate::table::Texels::Nodes),
        ..BakeOptions::default()
    };
    let mut spec = options.specs().remove(0);
    spec.model = model;
    debug_assert_eq!(spec.quantity, Quantity::E);
    spec
}

/// A table of the lookup study: filled by the reference quadrature at 1e-10.
fn lookup_spec(model: Model, size: usize, mapping: MuMapping) -> TableSpec {
    TableSpec {
        reference_digits: Some(10),
        ..e_spec(model, size, mapping, Method::Reference)
    }
}

/// One estimator at one setting.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Run {
    pub method: String,
    /// Points per texel; for the quadrature, its mean integrand evaluations per texel.
    pub samples: u64,
    /// The quadrature's tolerance.
    pub tolerance: Option<f64>,
    /// Wall time to fill the table, all cores.
    pub seconds: f64,
    /// Against the reference at the table's nodes.
    pub max_error: f64,
    pub rms_error: f64,
}

/// How soon a method reaches an accuracy.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Reach {
    pub max_error: f64,
    /// The shortest measured time at which the method's max error was at most `max_error`.
    pub seconds: Option<f64>,
    pub samples: Option<u64>,
}

/// Per method: when it reaches 1e-4, 1e-6 and 1e-8, and how fast its error falls.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Summary {
    pub method: String,
    pub reaches: Vec<Reach>,
    /// The measured convergence exponent `p` of `max error ~ N^-p` over the method's runs
    /// ([`convergence_exponent`]); `None` with fewer than two sample counts.
    pub convergence_exponent: Option<f64>,
}

/// The least-squares slope of `ln(max error)` against `ln(samples)` over the sampling runs of
/// `runs` (not the quadrature's, whose evaluations follow its tolerance, not a power law) with a
/// positive, finite error, negated: `p` in `max error ~ N^-p` (plain Monte Carlo 0.5, QMC
/// towards 1). `None` with fewer than two distinct sample counts.
#[must_use]
pub fn convergence_exponent(runs: &[&Run]) -> Option<f64> {
    let points: Vec<(f64, f64)> = runs
        .iter()
        .filter(|r| r.tolerance.is_none())
        .filter(|r| r.samples > 0 && r.max_error > 0.0 && r.max_error.is_finite())
        .map(|r| ((r.samples as f64).ln(), r.max_error.ln()))
        .collect();
    let n = points.len() as f64;
    let mean_x = points.iter().map(|p| p.0).sum::<f64>() / n;
    let mean_y = points.iter().map(|p| p.1).sum::<f64>() / n;
    let sxx: f64 = points.iter().map(|p| (p.0 - mean_x).powi(2)).sum();
    if points.len() < 2 || sxx <= 0.0 {
        return None;
    }
    let sxy: f64 = points.iter().map(|p| (p.0 - mean_x) * (p.1 - mean_y)).sum();
    Some(-sxy / sxx)
}

/// The lookup error of one reference-filled table.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LookupRun {
    pub mapping: String,
    pub grid: String,
    pub size: usize,
    pub max_error: f64,
    pub rms_error: f64,
    pub p99_error: f64,
}

/// Everything a study measured.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StudyReport {
    pub kiln_version: String,
    /// Threads rayon used.
    pub threads: usize,
    /// Logical CPUs of the machine.
    pub cores: usize,
    pub ndf: String,
    pub masking: String,
    /// The `E` table: `size x size`, and its axes.
    pub size: usize,
    pub table: String,
    pub runs: Vec<Run>,
    /// Indices into `runs` of the Pareto front (no other run is both faster and more accurate),
    /// fastest first.
    pub pareto: Vec<usize>,
    pub summary: Vec<Summary>,
    pub lookup: Vec<LookupRun>,
}

/// The targets of [`Summary`].
pub const TARGETS: [f64; 3] = [1e-4, 1e-6, 1e-8];

/// Indices of the runs no other run beats on both time and max error, fastest first.
#[must_use]
pub fn pareto_front(runs: &[Run]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..runs.len()).collect();
    order.sort_by(|&a, &b| {
        runs[a]
            .seconds
            .total_cmp(&runs[b].seconds)
            .then(runs[a].max_error.total_cmp(&runs[b].max_error))
    });
    let mut front = Vec::new();
    let mut best = f64::INFINITY;
    for k in order {
        if runs[k].max_error < best {
            best = runs[k].max_error;
            front.push(k);
        }
    }
    front
}

/// Per method, the shortest time at which it reached each of [`TARGETS`].
#[must_use]
pub fn summarise(runs: &[Run]) -> Vec<Summary> {
    let mut methods: Vec<&str> = Vec::new();
    for run in runs {
        if !methods.contains(&run.method.as_str()) {
            methods.push(&run.method);
        }
    }
    methods
        .into_iter()
        .map(|method| Summary {
            method: method.to_string(),
            reaches: TARGETS
                .iter()
                .map(|&target| {
                    let best = runs
                        .iter()
                        .filter(|r| r.method == method && r.max_error <= target)
                        .min_by(|a, b| a.seconds.total_cmp(&b.seconds));
                    Reach {
                        max_error: target,
                        seconds: best.map(|r| r.seconds),
                        samples: best.map(|r| r.samples),
                    }
                })
                .collect(),
            convergence_exponent: convergence_exponent(
                &runs
                    .iter()
                    .filter(|r| r.method == method)
                    .collect::<Vec<_>>(),
            ),
        })
        .collect()
}

/// Max and RMS of `|value - truth|`.
#[must_use]
pub fn errors(values: &[f64], truth: &[f64]) -> (f64, f64) {
    let diffs: Vec<f64> = values
        .iter()
        .zip(truth)
        .map(|(v, t)| (v - t).abs())
        .collect();
    let max = crate::stats::max_or_nan(diffs.iter().copied());
    let rms = (diffs.iter().map(|d| d * d).sum::<f64>() / diffs.len() as f64).sqrt();
    (max, rms)
}

/// Runs the study. `progress` gets the units done (see [`StudySettings::work`]).
#[must_use]
pub fn run(settings: &StudySettings, progress: &(dyn Fn(u64) + Sync)) -> StudyReport {
    let spec = settings.table_spec();
    let texels: Vec<(f64, f64)> = (0..spec.len())
        .map(|k| {
            let (alpha, mu) = spec.texel_coordinates(k);
            (alpha, mu.expect("an E table"))
        })
        .collect();
    let truth: Vec<f64> = texels
        .par_iter()
        .map(|&(alpha, mu)| {
            progress(1);
            reference_albedo(settings.model, alpha, mu, &ReferenceSettings::default()).value
        })
        .collect();

    let fill = |estimator: Estimator, samples: u64, tolerance: f64| {
        let start = Instant::now();
        let values: Vec<(f64, u64)> = texels
            .par_iter()
            .map(|&(alpha, mu)| {
                let v = estimate(
                    estimator,
                    settings.model,
                    alpha,
                    mu,
                    samples,
                    tolerance,
                    settings.seed,
                );
                progress(1);
                v
            })
            .collect();
        let seconds = start.elapsed().as_secs_f64();
        let estimates: Vec<f64> = values.iter().map(|v| v.0).collect();
        let spent = values.iter().map(|v| v.1).sum::<u64>() / values.len() as u64;
        let (max_error, rms_error) = errors(&estimates, &truth);
        Run {
            method: estimator.name().to_string(),
            samples: spent,
            tolerance: (estimator == Estimator::Quadrature).then_some(tolerance),
            seconds,
            max_error,
            rms_error,
        }
    };
    let mut runs = Vec::new();
    for (estimator, counts) in &settings.samples {
        for &samples in counts {
            let mut r = fill(*estimator, samples, 0.0);
            r.samples = samples;
            runs.push(r);
        }
    }
    for &tolerance in &settings.tolerances {
        runs.push(fill(Estimator::Quadrature, 0, tolerance));
    }

    let mut lookup = Vec::new();
    let audit_reference = ReferenceSettings {
        tolerance: 1e-9,
        max_intervals: 200,
    };
    for &mapping in &settings.lookup_mappings {
        for &size in &settings.lookup_sizes {
            let spec = lookup_spec(settings.model, size, mapping);
            let table = bake_table(spec, String::new(), &|_| progress(1));
            let report = audit(
                &table,
                &Against::ReferenceAt(audit_reference),
                &AuditSettings::default(),
                &|step| {
                    if step == Progress::Compared {
                        progress(1);
                    }
                },
            );
            lookup.push(LookupRun {
                mapping: mapping.name().to_string(),
                grid: Grid::Nodes.name().to_string(),
                size,
                max_error: report.lookup_max_error,
                rms_error: report.lookup_rms_error,
                p99_error: report.lookup_p99_error,
            });
        }
    }

    StudyReport {
        kiln_version: crate::format::metadata::KILN_VERSION.to_string(),
        threads: rayon::current_num_threads(),
        cores: std::thread::available_parallelism().map_or(1, usize::from),
        ndf: settings.model.ndf.name().to_string(),
        masking: settings.model.masking.name().to_string(),
        size: settings.size,
        table: format!(
            "{n} x {n} E, kiln's default axes: r {}; mu {}",
            spec.roughness_axis().formula(),
            spec.mu.expect("an E table").formula(),
            n = settings.size
        ),
        pareto: pareto_front(&runs),
        summary: summarise(&runs),
        runs,
        lookup,
    }
}

/// `study.csv`: `method,samples,seconds,max_error,rms_error`, one row per run.
#[must_use]
pub fn runs_csv(report: &StudyReport) -> String {
    let mut out = String::from("method,samples,seconds,max_error,rms_error\n");
    for r in &report.runs {
        out.push_str(&format!(
            "{},{},{:.6},{:.6e},{:.6e}\n",
            r.method, r.samples, r.seconds, r.max_error, r.rms_error
        ));
    }
    out
}

/// `lookup.csv`: `mapping,grid,size,max_error,rms_error,p99_error`, one row per table.
#[must_use]
pub fn lookup_csv(report: &StudyReport) -> String {
    let mut out = String::from("mapping,grid,size,max_error,rms_error,p99_error\n");
    for r in &report.lookup {
        out.push_str(&format!(
            "{},{},{},{:.6e},{:.6e},{:.6e}\n",
            r.mapping, r.grid, r.size, r.max_error, r.rms_error, r.p99_error
        ));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run_at(method: &str, seconds: f64, max_error: f64) -> Run {
        Run {
            method: method.to_string(),
            samples: 1,
            tolerance: None,
            seconds,
            max_error,
            rms_error: max_error / 2.0,
        }
    }

    /// `max error = 3 N^-0.75` (a power law, exactly): the exponent 0.75; one sample count, or
    /// errors of 0, give none.
    #[test]
    fn the_convergence_exponent_is_the_power_law_s() {
        let runs: Vec<Run> = (4..=10)
            .map(|k| Run {
                samples: 1 << k,
                max_error: 3.0 * f64::from(1 << k).powf(-0.75),
                ..run_at("a", 1.0, 0.0)
            })
            .collect();
        let all: Vec<&Run> = runs.iter().collect();
        let p = convergence_exponent(&all).unwrap();
        assert!((p - 0.75).abs() < 1e-12, "{p}");
        // Plain Monte Carlo's N^-1/2 from two counts a factor 4 apart and errors a factor 2.
        let two = [
            Run {
                samples: 64,
                ..run_at("b", 1.0, 1e-2)
            },
            Run {
                samples: 256,
                ..run_at("b", 1.0, 5e-3)
            },
        ];
        let p = convergence_exponent(&two.iter().collect::<Vec<_>>()).unwrap();
        assert!((p - 0.5).abs() < 1e-12, "{p}");
        assert_eq!(convergence_exponent(&all[..1]), None);
        let zero = run_at("c", 1.0, 0.0);
        assert_eq!(convergence_exponent(&[&zero, &zero]), None);
        // The quadrature's runs (with a tolerance) are not a power law in their evaluations.
        let quadrature: Vec<Run> = runs
            .iter()
            .map(|r| Run {
                tolerance: Some(1e-6),
                ..r.clone()
            })
            .collect();
        assert_eq!(
            convergence_exponent(&quadrature.iter().collect::<Vec<_>>()),
            None
        );
        let summary = summarise(&runs);
        assert!((summary[0].convergence_exponent.unwrap() - 0.75).abs() < 1e-12);
    }

    #[test]
    fn pareto_front_keeps_only_undominated_runs() {
        let runs = vec![
            run_at("a", 1.0, 1e-3),
            run_at("b", 2.0, 1e-2), // dominated by a
            run_at("a", 3.0, 1e-5),
            run_at("c", 0.5, 1e-1),
            run_at("c", 3.0, 1e-4), // dominated by a at 3.0
        ];
        assert_eq!(pareto_front(&runs), vec![3, 0, 2]);
    }

    #[test]
    fn summary_takes_the_fastest_run_meeting_each_target() {
        let runs = vec![
            run_at("a", 1.0, 1e-3),
            run_at("a", 4.0, 5e-7),
            run_at("a", 2.0, 9e-5),
            run_at("b", 9.0, 1e-9),
        ];
        let summary = summarise(&runs);
        assert_eq!(summary[0].method, "a");
        let seconds: Vec<Option<f64>> = summary[0].reaches.iter().map(|r| r.seconds).collect();
        assert_eq!(seconds, [Some(2.0), Some(4.0), None]);
        assert_eq!(summary[1].reaches[2].seconds, Some(9.0));
    }
}
