//! Beckmann's QMC standard error over GGX's at the same point, sample count and seed (8
//! scrambles): `cargo run --release --example beckmann_vs_ggx -- [LOG2_SAMPLES]` (default 16);
//! `ALPHAS` and `MUS` (comma-separated) replace the grid.
use kiln::{Masking, Model, Ndf, QmcSettings, albedo};
fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let log2: u32 = args.first().map_or(16, |a| a.parse().unwrap());
    let alphas: Vec<f64> = std::env::var("ALPHAS")
        .map_or(vec![0.3, 0.5, 0.7, 1.0, 1.5, 2.0], |s| {
            s.split(",").map(|x| x.parse().unwrap()).collect()
        });
    let mus: Vec<f64> = std::env::var("MUS").map_or(vec![0.05, 0.2, 0.5, 0.7, 0.9, 1.0], |s| {
        s.split(",").map(|x| x.parse().unwrap()).collect()
    });
    for ndf_m in [Masking::HeightCorrelated] {
        println!("2^{log2}: ratio beckmann/ggx std error (beckmann se)");
        for &alpha in &alphas {
            let mut line = format!("alpha {alpha:<4}");
            for &mu in &mus {
                let s = QmcSettings {
                    samples: 1 << log2,
                    scrambles: 8,
                    seed: 0,
                };
                let b = albedo(
                    Model {
                        ndf: Ndf::Beckmann,
                        masking: ndf_m,
                    },
                    alpha,
                    mu,
                    &s,
                );
                let g = albedo(
                    Model {
                        ndf: Ndf::Ggx,
                        masking: ndf_m,
                    },
                    alpha,
                    mu,
                    &s,
                );
                line += &format!(
                    "  mu {mu}: {:.2} ({:.1e})",
                    b.std_error / g.std_error,
                    b.std_error
                );
            }
            println!("{line}");
        }
    }
}
