//! The whole hard grid (`kiln::study::hard_grid`): QMC `E` and Schlick-weighted albedo against
//! the reference at every point, scored in QMC standard errors; prints the worst points per
//! sample count and the worst score overall.
//!
//! Usage: `cargo run --release --example hard_grid -- [LOG2_SAMPLES...]` (default: 16 20);
//! `KILN_SCRAMBLES` and `KILN_SEED` change the scrambles (default 8) and the seed (default 0).
use kiln::study::hard_grid::{check, points};
use rayon::prelude::*;

fn main() {
    let logs: Vec<u32> = std::env::args()
        .skip(1)
        .map(|a| a.parse().expect("LOG2_SAMPLES: an integer"))
        .collect();
    let logs = if logs.is_empty() { vec![16, 20] } else { logs };
    let grid = points();
    let scrambles: u32 =
        std::env::var("KILN_SCRAMBLES").map_or(8, |s| s.parse().expect("KILN_SCRAMBLES"));
    let seed: u64 = std::env::var("KILN_SEED").map_or(0, |s| s.parse().expect("KILN_SEED"));
    let mut worst_overall: f64 = 0.0;
    for log2 in logs {
        let start = std::time::Instant::now();
        let mut checks: Vec<_> = grid
            .par_iter()
            .map(|&p| check(p, 1 << log2, scrambles, seed))
            .collect();
        checks.sort_by(|a, b| b.z.total_cmp(&a.z));
        let over = checks.iter().filter(|c| c.z > 5.0 || c.z.is_nan()).count();
        println!(
            "2^{log2} samples in {scrambles} scrambles, seed {seed}: {} points, {over} beyond 5 \
             standard errors, {:.1} s",
            checks.len(),
            start.elapsed().as_secs_f64()
        );
        println!(
            "  z        ndf       masking             F0    alpha   mu       1-E qmc        std error  1-E reference"
        );
        for c in checks.iter().take(8) {
            let p = c.point;
            println!(
                "  {:<8.3} {:<9} {:<19} {:<5} {:<7} {:<8} {:<14.6e} {:<10.2e} {:.6e}",
                c.z,
                p.model.ndf.to_string(),
                p.model.masking.to_string(),
                p.f0.map_or("1".to_string(), |f| f.to_string()),
                p.alpha,
                p.mu,
                c.qmc_one_minus,
                c.std_error,
                c.reference_one_minus
            );
        }
        worst_overall = worst_overall.max(checks[0].z);
        if checks[0].z.is_nan() {
            worst_overall = f64::NAN;
        }
    }
    println!("worst z: {worst_overall:.3}");
}
