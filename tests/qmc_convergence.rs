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
    let points: Vec<(f64, f64)> = [0.1, 0.3, 1.0]
        .into_iter()
        .flat_map(|alpha| [0.2, 0.5, 1.0].map(|mu| (alpha, mu)))
        .collect();
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
