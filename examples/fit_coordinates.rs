//! Which coordinates suit a polynomial fit of E: `cargo run --release --example fit_coordinates`
//! prints the minimax error of fits of several sizes in t = (mu (1 + c alpha) / (mu + c
//! alpha))^p and r, for several (c, p) (kiln fit uses kiln's table axis, c = 4, p = 0.4).
use kiln::fit::polynomial::{Degrees, fit_to};
use kiln::integrate::reference::ReferenceSettings;
use kiln::integrate::value::{Integral, Point};
use kiln::{Masking, Model, Ndf};
use rayon::prelude::*;

fn main() {
    let model = Model {
        ndf: Ndf::Ggx,
        masking: Masking::HeightCorrelated,
    };
    let integral = Integral::albedo(model);
    let settings = ReferenceSettings {
        tolerance: 1e-8,
        ..ReferenceSettings::default()
    };
    let args: Vec<f64> = std::env::args()
        .skip(1)
        .map(|a| a.parse().unwrap())
        .collect();
    for pair in args.chunks(2) {
        let (c, p) = (pair[0], pair[1]);
        let n = 96;
        let mut pts = Vec::new();
        for j in 0..=n {
            let r = j as f64 / n as f64;
            let alpha = if r == 0.0 { 1e-7 } else { r * r };
            let k = c * alpha;
            let t_of = |mu: f64| {
                if mu <= 0.0 {
                    0.0
                } else {
                    (mu * (1.0 + k) / (mu + k)).min(1.0).powf(p)
                }
            };
            let mu_of = |t: f64| {
                let s = t.powf(1.0 / p);
                if s >= 1.0 {
                    1.0
                } else {
                    (s * k / (1.0 + k - s)).min(1.0)
                }
            };
            for i in 0..=n {
                let t = i as f64 / n as f64;
                pts.push((t, r, mu_of(t), alpha));
            }
            for mu in kiln::table::axis::grazing_probes() {
                pts.push((t_of(mu), r, mu, alpha));
            }
        }
        let truth: Vec<((f64, f64), f64)> = pts
            .par_iter()
            .map(|&(t, r, mu, alpha)| {
                (
                    (t, r),
                    integral
                        .reference(
                            Point {
                                alpha,
                                mu: Some(mu),
                                eta: None,
                            },
                            &settings,
                        )
                        .value,
                )
            })
            .collect();
        print!("c {c} p {p}:");
        for (dt, dr) in [(3, 2), (2, 3), (4, 3), (5, 4), (7, 3), (7, 4), (4, 7)] {
            let f = fit_to(model, Degrees { t: dt, r: dr }, &truth);
            print!("  {}: {:.2e}", (dt + 1) * (dr + 1), f.fit_max_error);
        }
        println!();
    }
}
