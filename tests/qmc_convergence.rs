//! QMC that converges faster than Monte Carlo (issue 40): Beckmann's `E` estimator, whose
//! standard error fell as `N^-0.84` while the strata ladder gave its 0.47-measure level an
//! eighth of the points, now samples inside the lost circle with a smooth map and falls as
//! `N^-1.2` to `N^-1.6`. The exponent is the least-squares slope of `ln(std error)` on `ln N`
//! over 2^14 to 2^22 samples; plain Monte Carlo's is 0.5, so an exponent of 0.9 or more fails
//! for any estimator whose integrand lost its smoothness.

use kiln::{Masking, Model, Ndf, QmcSettings, albedo};
use rayon::prelude::*;

/// The least-squares slope of `ys` on `xs`.
fn slope(xs: &[f64], ys: &[f64]) -> f64 {
    let n = xs.len() as f64;
    let (mx, my) = (xs.iter().sum::<f64>() / n, ys.iter().sum::<f64>() / n);
    let sxy: f64 = xs.iter().zip(ys).map(|(x, y)| (x - mx) * (y - my)).sum();
    let sxx: f64 = xs.iter().map(|x| (x - mx) * (x - mx)).sum();
    sxy / sxx
}

#[test]
fn beckmann_qmc_standard_error_falls_at_least_as_n_to_the_minus_0_9() {
    let model = Model {
        ndf: Ndf::Beckmann,
        masking: Masking::HeightCorrelated,
    };
    // The lost circle, and the three other ways a view is sampled: the grazing ladder (alpha
    // 0.1, mu 0.005), the lost circle at a grazing view (1, 0.05) and the reflected directions
    // (0.7, 1 and 1.5, 0.95).
    let mut points: Vec<(f64, f64)> = [0.1, 0.3, 1.0]
        .into_iter()
        .flat_map(|alpha| [0.2, 0.5, 1.0].map(|mu| (alpha, mu)))
        .collect();
    points.extend([(0.1, 0.005), (1.0, 0.05), (0.7, 1.0), (1.5, 0.95)]);
    let logs = [14, 16, 18, 20, 22];
    let exponents: Vec<((f64, f64), f64)> = points
        .into_par_iter()
        .map(|(alpha, mu)| {
            let (xs, ys): (Vec<f64>, Vec<f64>) = logs
                .iter()
                .map(|&k| {
                    let settings = QmcSettings {
                        samples: 1 << k,
                        scrambles: 8,
                        seed: 0,
                    };
                    let estimate = albedo(model, alpha, mu, &settings);
                    assert!(estimate.std_error > 0.0, "alpha {alpha}, mu {mu}, 2^{k}");
                    (
                        f64::from(k) * std::f64::consts::LN_2,
                        estimate.std_error.ln(),
                    )
                })
                .unzip();
            ((alpha, mu), -slope(&xs, &ys))
        })
        .collect();
    for ((alpha, mu), exponent) in &exponents {
        eprintln!("Beckmann alpha {alpha}, mu {mu}: std error ~ N^-{exponent:.2}");
    }
    let slow: Vec<_> = exponents.iter().filter(|(_, e)| *e < 0.9).collect();
    assert!(slow.is_empty(), "converging slower than N^-0.9: {slow:?}");
}

/// Beckmann's standard error is within twice GGX's at the same point, sample count and seed,
/// over rough surfaces at every tilt (issue 40's goal; at lower roughness Beckmann's is the
/// smaller, 0.0 to 0.4 of GGX's at alpha 0.3). The exception is GGX's own: at alpha = 1 its
/// distribution is uniform over the hemisphere (`D = 1 / pi`), the cap point it samples is the
/// reflected direction itself, and its integrand depends on one coordinate only, so its error
/// there is 10 to 25 times below its own at alpha 0.7 or 1.5 (and Beckmann's 2.6 to 6 times
/// above it at mu 0.001 to 0.8; `docs/accuracy.md`): the grid steps over alpha in [0.95, 1.1].
#[test]
fn beckmann_qmc_standard_error_is_within_twice_ggx_s() {
    let points: Vec<(f64, f64)> = [0.3, 0.5, 0.7, 0.9, 1.25, 1.5, 2.0, 3.0]
        .into_iter()
        .flat_map(|alpha| [0.001, 0.05, 0.2, 0.5, 0.8, 0.95, 1.0].map(|mu| (alpha, mu)))
        .collect();
    let ratios: Vec<((f64, f64, u32), f64)> = points
        .into_par_iter()
        .flat_map_iter(|(alpha, mu)| {
            [16, 19].into_iter().map(move |k| {
                let settings = QmcSettings {
                    samples: 1 << k,
                    scrambles: 8,
                    seed: 0,
                };
                let error = |ndf| {
                    let model = Model {
                        ndf,
                        masking: Masking::HeightCorrelated,
                    };
                    albedo(model, alpha, mu, &settings).std_error
                };
                ((alpha, mu, k), error(Ndf::Beckmann) / error(Ndf::Ggx))
            })
        })
        .collect();
    let worst = ratios.iter().map(|(_, r)| *r).fold(0.0, f64::max);
    eprintln!("worst Beckmann / GGX standard error: {worst:.2}");
    let over: Vec<_> = ratios
        .iter()
        .filter(|(_, r)| r.is_nan() || *r > 2.0)
        .collect();
    assert!(
        over.is_empty(),
        "Beckmann's standard error over twice GGX's at (alpha, mu, log2 samples): {over:?}"
    );
}
