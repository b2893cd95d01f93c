//! How the walk's error falls with the work, for each estimator it offers (issue 60's benchmark;
//! walks per second alone are `cargo bench --bench walk`): the escape tallied as its expectation
//! at every vertex (kiln's) or drawn (the analog walk), and Sobol numbers for the first two
//! vertices (kiln's) or pseudorandom ones throughout. For each, at walk counts 2^12 to 2^MAX,
//! the standard error (16 replicates) of `e_1`, `e_2`, `e_3` and of the albedo with Schlick's
//! `F0 = 0.5` (every order), the median wall time of 3 runs, and the efficiency
//! `1 / (sigma^2 t)` of the albedo (higher is better). GGX at `alpha = 1` and `0.25`, `mu = 0.5`.
//!
//! `cargo run --release --example walk_estimators -- [MAX_LOG2_WALKS]` (default 20).

use kiln::integrate::walk::{Escape, Numbers, WalkSettings, walk_albedo, walk_schlick_polynomial};
use kiln::{Fresnel, Masking, Model, Ndf};
use std::time::Instant;

const GGX: Model = Model {
    ndf: Ndf::Ggx,
    masking: Masking::HeightCorrelated,
};

fn main() {
    let max: u32 = std::env::args()
        .nth(1)
        .map_or(20, |a| a.parse().expect("MAX_LOG2_WALKS"));
    println!(
        "alpha  estimator               walks     se(e_1)   se(e_2)   se(e_3)   se(albedo F0 0.5)  seconds  efficiency"
    );
    for alpha in [1.0, 0.25] {
        for (name, escape, numbers) in [
            ("expected + sobol", Escape::Expected, Numbers::Sobol),
            (
                "expected + pseudorandom",
                Escape::Expected,
                Numbers::Pseudorandom,
            ),
            ("sampled + sobol", Escape::Sampled, Numbers::Sobol),
            (
                "sampled + pseudorandom",
                Escape::Sampled,
                Numbers::Pseudorandom,
            ),
        ] {
            for log2 in (12..=max).step_by(4) {
                let settings = WalkSettings {
                    walks: 1 << log2,
                    escape,
                    numbers,
                    ..WalkSettings::default()
                };
                let orders = walk_albedo(GGX, alpha, 0.5, &Fresnel::None, 3, &settings, &|_| {})
                    .expect("a walk");
                let mut times = Vec::new();
                let mut albedo = None;
                for _ in 0..3 {
                    let start = Instant::now();
                    let polynomial =
                        walk_schlick_polynomial(GGX, alpha, 0.5, 1.0, &settings, &|_| {})
                            .expect("a walk");
                    times.push(start.elapsed().as_secs_f64());
                    albedo = Some(polynomial.albedo(0.5));
                }
                times.sort_by(f64::total_cmp);
                let (t, a) = (times[1], albedo.expect("three runs"));
                println!(
                    "{alpha:<6} {name:<23} 2^{log2:<6} {:<9.2e} {:<9.2e} {:<9.2e} {:<18.2e} {:<8.3} {:.3e}",
                    orders.orders[0].std_error,
                    orders.orders[1].std_error,
                    orders.orders[2].std_error,
                    a.std_error,
                    t,
                    1.0 / (a.std_error * a.std_error * t)
                );
            }
        }
    }
}
