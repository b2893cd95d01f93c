//! How closely a reciprocal lobe `f_ms = M(mu_o) M(mu_i) / (pi M_avg)` per channel, with the
//! multiple-scattering albedo `M(mu, r, F0) = walk - E_F` stored as a polynomial of low degree in
//! Schlick's `F0` (F90 = 1) per texel, could match the walk (issue 60's kiln compensation): for
//! each view the walk's exact `F0` polynomial is fitted by least squares, relative to the walk's
//! albedo, with Bernstein polynomials of degree 1 to 4 over `1 - POLE F0` for `F0` in [0.02, 1]
//! (the last coefficient pinned so that `F0 = 1` is the white furnace exactly), and the largest
//! relative error of the total albedo `E_F + M` is printed per degree. The lobe's albedo is
//! exactly `M(mu_o)` (its average normalises it), so this is the compensation's albedo error.
//!
//! `cargo run --release --example compensation_basis -- [LOG2_WALKS]` (default 18).

use kiln::integrate::reference::{ReferenceSettings, reference_weighted_albedo};
use kiln::integrate::walk::{WalkSettings, walk_schlick_polynomial};
use kiln::{Masking, Model, Ndf};

fn main() {
    let log2: u32 = std::env::args()
        .nth(1)
        .map_or(18, |a| a.parse().expect("LOG2_WALKS"));
    let model = Model {
        ndf: Ndf::Ggx,
        masking: Masking::HeightCorrelated,
    };
    let settings = WalkSettings {
        walks: 1 << log2,
        ..WalkSettings::default()
    };
    let reference = ReferenceSettings::default();
    let f0s: Vec<f64> = (0..=49).map(|k| 0.02 + 0.98 * k as f64 / 49.0).collect();
    let mut worst = [(0.0f64, 0.0, 0.0, 0.0); 5];
    for r in [0.1, 0.25, 0.4, 0.55, 0.7, 0.85, 1.0] {
        let alpha = r * r;
        for mu in [0.02, 0.05, 0.1, 0.2, 0.35, 0.5, 0.7, 0.85, 1.0] {
            let polynomial =
                walk_schlick_polynomial(model, alpha, mu, 1.0, &settings, &|_| {}).unwrap();
            let scale = reference_weighted_albedo(
                model,
                alpha,
                mu,
                |c| 1.0 - (1.0 - c).powi(5),
                &reference,
            )
            .value;
            let bias =
                reference_weighted_albedo(model, alpha, mu, |c| (1.0 - c).powi(5), &reference)
                    .value;
            let walk: Vec<f64> = f0s.iter().map(|&f| polynomial.albedo(f).value).collect();
            let single: Vec<f64> = f0s.iter().map(|&f| f * scale + bias).collect();
            for (degree, worst) in worst.iter_mut().enumerate().skip(1) {
                let fitted = fit(&f0s, &walk, &single, degree);
                for (k, &f0) in f0s.iter().enumerate() {
                    let error = (single[k] + fitted[k]) / walk[k] - 1.0;
                    if error.abs() > worst.0.abs() {
                        *worst = (error, r, mu, f0);
                    }
                }
            }
        }
    }
    println!("2^{log2} walks a view; r 0.1-1, mu 0.02-1, F0 0.02-1 (F90 = 1)");
    for (degree, (error, r, mu, f0)) in worst.iter().enumerate().skip(1) {
        println!(
            "degree {degree} ({} channels): max relative albedo error {:+.3}% at r = {r}, mu = {mu}, F0 = {f0:.2}",
            degree + 1,
            100.0 * error
        );
    }
}

/// The fixed pole of the basis: each Bernstein polynomial over `1 - POLE F0`, the shape of the
/// geometric series of bounces (`e_2 F^2 / (1 - q F)`, `q` the chance of one more bounce).
/// Measured at 2^16 walks, degree 3: 0.54 % at 0.2, 0.38 % at 0.25, 0.21 % at 0.3, 0.13 % at
/// 0.35, 0.22 % at 0.4, 0.58 % at 0.5 (1.1 % without a pole).
const POLE: f64 = 0.35;

/// `M = walk - single` fitted at the points `f0s` by Bernstein polynomials of `degree`, least
/// squares weighted by `1 / walk` (relative to the albedo); the fitted `M` at the points.
fn fit(f0s: &[f64], walk: &[f64], single: &[f64], degree: usize) -> Vec<f64> {
    let n = degree + 1;
    let basis = |f: f64| -> Vec<f64> {
        (0..n)
            .map(|j| {
                binomial(degree, j) * f.powi(j as i32) * (1.0 - f).powi((degree - j) as i32)
                    / (1.0 - POLE * f)
            })
            .collect()
    };
    // The last coefficient pinned so that the white furnace (F0 = 1, the last point) is exact:
    // only B_degree is non-zero at F0 = 1.
    let last = f0s.len() - 1;
    let pinned = (walk[last] - single[last]) * (1.0 - POLE * f0s[last]);
    let free = n - 1;
    let mut a = vec![vec![0.0; free]; free];
    let mut b = vec![0.0; free];
    for (k, &f) in f0s.iter().enumerate() {
        let w = 1.0 / (walk[k] * walk[k]);
        let row = basis(f);
        let target = walk[k] - single[k] - pinned * row[degree];
        for i in 0..free {
            b[i] += w * row[i] * target;
            for j in 0..free {
                a[i][j] += w * row[i] * row[j];
            }
        }
    }
    let mut c = solve(a, b);
    c.push(pinned);
    f0s.iter()
        .map(|&f| basis(f).iter().zip(&c).map(|(x, y)| x * y).sum())
        .collect()
}

fn binomial(n: usize, k: usize) -> f64 {
    (0..k).fold(1.0, |acc, i| acc * (n - i) as f64 / (i + 1) as f64)
}

/// Gaussian elimination with partial pivoting.
fn solve(mut a: Vec<Vec<f64>>, mut b: Vec<f64>) -> Vec<f64> {
    let n = b.len();
    for col in 0..n {
        let pivot = (col..n)
            .max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))
            .unwrap();
        a.swap(col, pivot);
        b.swap(col, pivot);
        let pivot_row = a[col].clone();
        for row in col + 1..n {
            let factor = a[row][col] / pivot_row[col];
            for (x, p) in a[row][col..].iter_mut().zip(&pivot_row[col..]) {
                *x -= factor * p;
            }
            b[row] -= factor * b[col];
        }
    }
    let mut x = vec![0.0; n];
    for row in (0..n).rev() {
        let sum: f64 = (row + 1..n).map(|k| a[row][k] * x[k]).sum();
        x[row] = (b[row] - sum) / a[row][row];
    }
    x
}
