//! The whole hard grid (`kiln::study::hard_grid`): QMC `E` and Schlick-weighted albedo against
//! the reference at every point, scored in QMC standard errors; prints the worst points per
//! sample count and the worst score overall.
//!
//! Usage: `cargo run --release --example hard_grid -- [--dielectric] [LOG2_SAMPLES...]`
//! (default: 16 20); `--dielectric` runs the dielectric grid (`R + T` over `eta`) instead.
//! `KILN_SCRAMBLES` and `KILN_SEED` change the scrambles (default 8) and the seed (default 0).
use kiln::study::hard_grid::{
    DielectricPoint, HardCheck, HardPoint, check, check_dielectric, dielectric_points, points,
};
use rayon::prelude::*;

fn main() {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let dielectric = args.iter().any(|a| a == "--dielectric");
    args.retain(|a| a != "--dielectric");
    let logs: Vec<u32> = args
        .iter()
        .map(|a| a.parse().expect("LOG2_SAMPLES: an integer"))
        .collect();
    let logs = if logs.is_empty() { vec![16, 20] } else { logs };
    if dielectric {
        run_grid(
            "dielectric, ",
            &dielectric_points(),
            check_dielectric,
            "ndf       alpha   mu       eta       ",
            |p: &DielectricPoint| {
                format!(
                    "{:<9} {:<7} {:<8} {:<10.6}",
                    p.model.ndf.to_string(),
                    p.alpha,
                    p.mu,
                    p.eta
                )
            },
            &logs,
        );
    } else {
        run_grid(
            "",
            &points(),
            check,
            "ndf       masking             F0    alpha   mu      ",
            |p: &HardPoint| {
                format!(
                    "{:<9} {:<19} {:<5} {:<7} {:<8}",
                    p.model.ndf.to_string(),
                    p.model.masking.to_string(),
                    p.f0.map_or("1".to_string(), |f| f.to_string()),
                    p.alpha,
                    p.mu
                )
            },
            &logs,
        );
    }
}

/// One grid at each sample count: the eight worst points (columns `point_columns`, each
/// point's cells by `describe`) and the worst score overall.
fn run_grid<P: Copy + Send + Sync>(
    title: &str,
    grid: &[P],
    check: fn(P, u64, u32, u64) -> HardCheck<P>,
    point_columns: &str,
    describe: impl Fn(&P) -> String,
    logs: &[u32],
) {
    let scrambles: u32 =
        std::env::var("KILN_SCRAMBLES").map_or(8, |s| s.parse().expect("KILN_SCRAMBLES"));
    let seed: u64 = std::env::var("KILN_SEED").map_or(0, |s| s.parse().expect("KILN_SEED"));
    let mut worst_overall: f64 = 0.0;
    for &log2 in logs {
        let start = std::time::Instant::now();
        let mut checks: Vec<_> = grid
            .par_iter()
            .map(|&p| check(p, 1 << log2, scrambles, seed))
            .collect();
        checks.sort_by(|a, b| b.z.total_cmp(&a.z));
        let over = checks.iter().filter(|c| c.z > 5.0 || c.z.is_nan()).count();
        println!(
            "{title}2^{log2} samples in {scrambles} scrambles, seed {seed}: {} points, {over} \
             beyond 5 standard errors, {:.1} s",
            checks.len(),
            start.elapsed().as_secs_f64()
        );
        println!("  z        {point_columns} 1-E qmc        std error  1-E reference");
        for c in checks.iter().take(8) {
            println!(
                "  {:<8.3} {} {:<14.6e} {:<10.2e} {:.6e}",
                c.z,
                describe(&c.point),
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
