//! `kiln study`: its measurements are what they claim (errors recomputed independently against
//! the reference, lookup errors as `verify` gives them), and its files follow their schema.
//! Timings are never asserted.

use kiln::integrate::reference::{ReferenceSettings, reference_albedo};
use kiln::study::estimators::{Estimator, estimate};
use kiln::study::{StudySettings, lookup_csv, run, runs_csv};
use kiln::table::axis::MuMapping;
use kiln::{Masking, Model, Ndf};

fn model() -> Model {
    Model {
        ndf: Ndf::Ggx,
        masking: Masking::HeightCorrelated,
    }
}

fn tiny() -> StudySettings {
    StudySettings {
        model: model(),
        size: 4,
        samples: vec![
            (Estimator::CosineRandom, vec![64, 256]),
            (Estimator::VndfSobol, vec![256]),
        ],
        tolerances: vec![1e-4],
        lookup_sizes: vec![4],
        lookup_mappings: vec![MuMapping::Linear, MuMapping::Adaptive],
        seed: 5,
    }
}

#[test]
fn study_errors_are_recomputed_against_the_reference() {
    let settings = tiny();
    let done = std::sync::atomic::AtomicU64::new(0);
    let report = run(&settings, &|n| {
        done.fetch_add(n, std::sync::atomic::Ordering::Relaxed);
    });
    // Progress adds up to the announced work.
    assert_eq!(
        done.load(std::sync::atomic::Ordering::Relaxed),
        settings.work()
    );
    assert_eq!(report.runs.len(), 4);
    let spec = settings.table_spec();
    for r in &report.runs {
        let estimator = Estimator::ALL
            .into_iter()
            .find(|e| e.name() == r.method)
            .unwrap();
        let tolerance = r.tolerance.unwrap_or(0.0);
        let diffs: Vec<f64> = (0..spec.len())
            .map(|k| {
                let (alpha, mu) = spec.texel_coordinates(k);
                let mu = mu.unwrap();
                let (value, _) = estimate(
                    estimator,
                    model(),
                    alpha,
                    mu,
                    r.samples,
                    tolerance,
                    settings.seed,
                );
                let truth =
                    reference_albedo(model(), alpha, mu, &ReferenceSettings::default()).value;
                (value - truth).abs()
            })
            .collect();
        let max = diffs.iter().copied().fold(0.0, f64::max);
        let rms = (diffs.iter().map(|d| d * d).sum::<f64>() / diffs.len() as f64).sqrt();
        if estimator == Estimator::Quadrature {
            // Its `samples` is the mean evaluation count; the estimates do not depend on it.
            assert!(r.samples > 0);
        }
        assert_eq!(r.max_error, max, "{r:?}");
        assert!((r.rms_error - rms).abs() <= 1e-15 * rms.max(1.0), "{r:?}");
        assert!(r.seconds > 0.0);
    }
    // The Pareto front is a subset of the runs, time-ordered with falling error.
    let front: Vec<_> = report.pareto.iter().map(|&k| &report.runs[k]).collect();
    assert!(!front.is_empty());
    for pair in front.windows(2) {
        assert!(pair[0].seconds <= pair[1].seconds && pair[0].max_error > pair[1].max_error);
    }
    // One summary per method, each with the three targets.
    assert_eq!(report.summary.len(), 3);
    assert!(report.summary.iter().all(|s| s.reaches.len() == 3));
    // Each method's convergence exponent, recomputed here from its runs as the least-squares
    // slope of ln(max error) on ln(samples); none for a method with one run.
    for summary in &report.summary {
        let points: Vec<(f64, f64)> = report
            .runs
            .iter()
            .filter(|r| r.method == summary.method && r.tolerance.is_none())
            .map(|r| ((r.samples as f64).ln(), r.max_error.ln()))
            .collect();
        match points.as_slice() {
            [(x0, y0), (x1, y1)] => {
                let p = -(y1 - y0) / (x1 - x0);
                let got = summary.convergence_exponent.unwrap();
                assert!(
                    (got - p).abs() < 1e-12,
                    "{}: {got} against {p}",
                    summary.method
                );
            }
            [_] | [] => assert_eq!(summary.convergence_exponent, None, "{}", summary.method),
            other => panic!("{} runs of {}", other.len(), summary.method),
        }
    }
    // The adaptive axis beats the linear one at this size, as verify measures.
    assert_eq!(report.lookup.len(), 2);
    assert!(report.lookup[1].max_error < report.lookup[0].max_error);
}

#[test]
fn csv_files_follow_their_schema() {
    let report = run(&tiny(), &|_| {});
    let csv = runs_csv(&report);
    let mut lines = csv.lines();
    assert_eq!(
        lines.next(),
        Some("method,samples,seconds,max_error,rms_error")
    );
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), report.runs.len());
    for (row, run) in rows.iter().zip(&report.runs) {
        assert_eq!(row.len(), 5);
        assert_eq!(row[0], run.method);
        assert_eq!(row[1].parse::<u64>().unwrap(), run.samples);
        let seconds: f64 = row[2].parse().unwrap();
        assert!((seconds - run.seconds).abs() <= 1e-6);
        let max: f64 = row[3].parse().unwrap();
        assert!((max - run.max_error).abs() <= 1e-6 * run.max_error);
        let _: f64 = row[4].parse().unwrap();
    }
    let lookup = lookup_csv(&report);
    let mut lines = lookup.lines();
    assert_eq!(
        lines.next(),
        Some("mapping,grid,size,max_error,rms_error,p99_error")
    );
    assert_eq!(lines.count(), report.lookup.len());
}

/// `kiln study --scaling`'s measurements: the lookup error it reports is the one this test
/// computes on its own (the same fixed points, kiln's reference by its direct entry point), a
/// larger table's lookup is closer to the truth, every bake met its max error at the nodes,
/// and the CSV holds the runs.
#[test]
fn scaling_study_measures_what_it_reports() {
    use kiln::integrate::reference::reference_albedo;
    use kiln::study::scaling::{Case, ScalingSettings, run, scaling_csv};
    use kiln::{BakeOptions, Quantity};
    let settings = ScalingSettings {
        model: model(),
        max_error: 1e-4,
        cases: vec![
            Case {
                name: "E".into(),
                quantities: vec![Quantity::E],
                sizes: vec![4, 8],
                mu_mapping: MuMapping::Adaptive,
            },
            Case {
                name: "E_dielectric".into(),
                quantities: vec![Quantity::EDielectric],
                sizes: vec![3],
                mu_mapping: MuMapping::Adaptive,
            },
        ],
        lookup_points_per_axis: 5,
    };
    let done = std::sync::atomic::AtomicU64::new(0);
    let report = run(&settings, &|n| {
        done.fetch_add(n, std::sync::atomic::Ordering::Relaxed);
    })
    .unwrap();
    assert_eq!(done.into_inner(), settings.work());
    assert_eq!(report.runs.len(), 3);
    assert_eq!(
        report.runs.iter().map(|r| r.texels).collect::<Vec<_>>(),
        [16, 64, 27]
    );
    for r in &report.runs {
        assert!(r.node_max_error <= 1e-4 && r.seconds > 0.0, "{r:?}");
    }
    // The E lookup error at size 4, recomputed: the table as the study bakes it, looked up at
    // (j + 0.37) / 5 of r and mu, against the reference.
    let table = BakeOptions {
        quantities: vec![Quantity::E],
        size: 4,
        ior_size: 4,
        max_error: Some(1e-4),
        // The study's layout: the adaptive axis' point samples on linear rows.
        mu_mapping: Some(MuMapping::Adaptive),
        ..BakeOptions::default()
    }
    .bake(&|_| {})
    .unwrap()
    .remove(0);
    let mut max = 0.0f64;
    for i in 0..5 {
        for j in 0..5 {
            let (r, mu) = ((i as f64 + 0.37) / 5.0, (j as f64 + 0.37) / 5.0);
            let settings = ReferenceSettings {
                tolerance: 1e-9,
                ..ReferenceSettings::default()
            };
            let truth = reference_albedo(model(), r * r, mu, &settings).value;
            max = max.max((table.lookup(mu, r) - truth).abs());
        }
    }
    let reported = report.runs[0].lookup_max_error;
    assert!((reported - max).abs() <= 1e-7, "{reported:e} vs {max:e}");
    assert!(report.runs[1].lookup_max_error < reported);
    // One fit per case, over its sizes.
    assert_eq!(report.fits.len(), 2);
    assert_eq!(report.fits[0].sizes, [4, 8]);
    assert!(report.fits[0].exponent.is_finite() && report.fits[1].exponent.is_nan());
    let csv = scaling_csv(&report);
    let mut lines = csv.lines();
    assert_eq!(
        lines.next(),
        Some("case,size,texels,seconds,node_max_error,lookup_max_error,lookup_rms_error")
    );
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 3);
    assert_eq!(
        (rows[2][0], rows[2][1], rows[2][2]),
        ("E_dielectric", "3", "27")
    );
}
