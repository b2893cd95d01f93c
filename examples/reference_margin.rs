//! How far the dielectric reference's tolerance sits above its actual error, and what each
//! tolerance costs: GGX height-correlated `E_dielectric` on 1287 points (eta from 1/3 to 3, r
//! from 0.01 to 1, mu from 0 to 1, the grazing and near-index-matched ones included), at
//! tolerances 1e-3 to 1e-8, against the same reference at 1e-12. Prints, per tolerance, the mean
//! integrand evaluations per point and the largest actual error as a fraction of the tolerance
//! (what `kiln verify`'s `COARSEST_TOLERANCE` and `REFERENCE_FRACTION` rest on; docs/verify.md),
//! with the number of points whose stated error is below their actual one. `inside` runs a denser
//! grid of light from inside around the critical angle instead (693 points, eta 0.5 to 0.95, at
//! 1e-6 to 1e-8). Seconds on 2 cores; `WORST=1` lists the understated points.
//!
//! Usage: `cargo run --release --example reference_margin [-- inside]`
use kiln::integrate::dielectric::reference_dielectric_albedo;
use kiln::integrate::reference::ReferenceSettings;
use kiln::model::{Masking, Model, Ndf};
use rayon::prelude::*;

fn main() {
    let model = Model {
        ndf: Ndf::Ggx,
        masking: Masking::HeightCorrelated,
    };
    // With `inside`: a denser grid of light from inside around the critical angle.
    let inside = std::env::args().nth(1).as_deref() == Some("inside");
    let (etas, roughness, mus, tolerances): (Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>) = if inside {
        (
            vec![0.5, 0.6, 2.0 / 3.0, 0.7, 0.75, 0.8, 0.85, 0.9, 0.95],
            vec![0.03, 0.15, 0.25, 0.4, 0.55, 0.7, 0.9],
            vec![0.15, 0.3, 0.4, 0.45, 0.55, 0.6, 0.65, 0.75, 0.8, 0.85, 0.95],
            vec![1e-6, 1e-7, 1e-8],
        )
    } else {
        (
            vec![
                1.0 / 3.0,
                1.0 / 1.5,
                0.9,
                0.99,
                0.999,
                1.001,
                1.01,
                1.1,
                1.5,
                2.5,
                3.0,
            ],
            vec![0.01, 0.05, 0.1, 0.2, 0.3, 0.45, 0.6, 0.8, 1.0],
            vec![
                0.0, 1e-6, 1e-3, 0.01, 0.05, 0.1, 0.2, 0.35, 0.5, 0.7, 0.9, 0.99, 1.0,
            ],
            vec![1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8],
        )
    };
    let mut points = Vec::new();
    for &eta in &etas {
        for &r in &roughness {
            for &mu in &mus {
                points.push((eta, r, mu));
            }
        }
    }
    // `1 - E` and the evaluations at every point, at one tolerance.
    let at = |tolerance: f64| -> Vec<(f64, u64, f64)> {
        let settings = ReferenceSettings {
            tolerance,
            ..ReferenceSettings::default()
        };
        points
            .par_iter()
            .map(|&(eta, r, mu)| {
                let v = reference_dielectric_albedo(model, r * r, mu, eta, &settings);
                (v.one_minus_value, v.evaluations, v.error)
            })
            .collect()
    };
    let truth = at(1e-12);
    println!("{} points; against the reference at 1e-12", points.len());
    println!(
        "tolerance  evaluations/point  max actual error  (of the tolerance)  max actual / stated  \
         points understated"
    );
    for &tolerance in &tolerances {
        let values = at(tolerance);
        let mean = values.iter().map(|v| v.1).sum::<u64>() as f64 / values.len() as f64;
        let actual: Vec<f64> = values
            .iter()
            .zip(&truth)
            .map(|(v, t)| (v.0 - t.0).abs())
            .collect();
        let worst = actual.iter().copied().fold(0.0, f64::max);
        // The reference's stated error against its actual one (the truth's own estimate added).
        let ratios: Vec<f64> = actual
            .iter()
            .zip(values.iter().zip(&truth))
            .map(|(a, (v, t))| a / (v.2 + t.2).max(1e-300))
            .collect();
        let understated = ratios.iter().filter(|&&r| r > 1.0).count();
        if std::env::var_os("WORST").is_some() {
            for (k, r) in ratios.iter().enumerate() {
                if *r > 1.0 {
                    eprintln!(
                        "  {tolerance:e} at {:?}: actual {:.2e}, stated {:.2e}",
                        points[k], actual[k], values[k].2
                    );
                }
            }
        }
        println!(
            "{tolerance:9.0e}  {mean:17.0}  {worst:16.2e}  {:>18}  {:19.2}  {understated:18}",
            format!("1/{:.0}", tolerance / worst),
            ratios.iter().copied().fold(0.0, f64::max)
        );
    }
}
