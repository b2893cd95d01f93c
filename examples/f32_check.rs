//! How far the committed fits' emitted Rust functions, evaluated in f32, are from their formula
//! files evaluated in f64, over a 401 x 401 grid in (mu, r):
//! `cargo run --release --example f32_check`.
#[allow(dead_code, clippy::all)]
mod emitted {
    include!("../tests/data/fits/ggx_height_correlated_e_fit_p3_3_q3_3.rs");
    include!("../tests/data/fits/ggx_height_correlated_e_fit_t3_r2.rs");
}

/// An emitted fit in f32.
type F32Fit = fn(f32, f32) -> f32;

fn main() {
    let fits: [(&str, F32Fit); 2] = [
        (
            "ggx_height_correlated_e_fit_t3_r2",
            emitted::ggx_height_correlated_e_fit_t3_r2,
        ),
        (
            "ggx_height_correlated_e_fit_p3_3_q3_3",
            emitted::ggx_height_correlated_e_fit_p3_3_q3_3,
        ),
    ];
    for (name, f32_fit) in fits {
        let path = format!("tests/data/fits/{name}.toml");
        let text = std::fs::read_to_string(&path).expect("run from the repository's root");
        let formula = kiln::fit::Fit::Formula(kiln::fit::FormulaFit::parse(&text).unwrap());
        let mut worst = (0.0_f64, 0.0, 0.0);
        for i in 0..=400 {
            for j in 0..=400 {
                let (mu, r) = (f64::from(i) / 400.0, f64::from(j) / 400.0);
                let d = (f64::from(f32_fit(mu as f32, r as f32))
                    - formula.value(kiln::Quantity::E, mu, r))
                .abs();
                if d > worst.0 {
                    worst = (d, mu, r);
                }
            }
        }
        println!(
            "{name}: f32 evaluation off the f64 formula by up to {:.2e} (at mu = {}, r = {})",
            worst.0, worst.1, worst.2
        );
    }
}
