//! Test helpers: an independent deterministic quadrature of `E` and `E_avg` for checking the QMC
//! estimators (docs/physics.md, "A deterministic reference": microfacet-normal parametrisation
//! `x = ln(tan(theta_m) / alpha)`, mirror symmetry in phi, and a split at the horizon curve so
//! every piece is smooth). It shares only `D` and `Lambda` with the code under test, which have
//! their own identity tests.

use kiln::model::{Beckmann, Ggx, Masking, MicrofacetDistribution, Model, Ndf, Vec3};
use std::f64::consts::PI;

/// Gauss-Legendre nodes and weights on [-1, 1].
pub fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    let legendre = |x: f64| {
        let (mut p0, mut p1) = (1.0, x);
        for k in 2..=n {
            let k = k as f64;
            (p0, p1) = (p1, ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k);
        }
        let dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
        (p1, dp)
    };
    (0..n)
        .map(|i| {
            let mut x = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            for _ in 0..100 {
                let (p, dp) = legendre(x);
                let dx = p / dp;
                x -= dx;
                if dx.abs() < 1e-16 {
                    break;
                }
            }
            let (_, dp) = legendre(x);
            (x, 2.0 / ((1.0 - x * x) * dp * dp))
        })
        .collect()
}

/// `∫_a^b f` by composite Gauss-Legendre on `pieces` equal panels.
fn integrate(a: f64, b: f64, pieces: usize, rule: &[(f64, f64)], f: impl Fn(f64) -> f64) -> f64 {
    let h = (b - a) / pieces as f64;
    let mut sum = 0.0;
    for p in 0..pieces {
        let lo = a + h * p as f64;
        for &(t, w) in rule {
            sum += w * h / 2.0 * f(lo + h * (t + 1.0) / 2.0);
        }
    }
    sum
}

fn e_quadrature<N: MicrofacetDistribution>(
    ndf: N,
    masking: Masking,
    mu: f64,
    weight: &dyn Fn(f64) -> f64,
) -> f64 {
    let alpha = ndf.alpha();
    let o = Vec3::from_mu(mu);
    let lambda_o = ndf.lambda(o);
    let rule = gauss_legendre(24);
    // E = ∫ D(m) G2(o, i) (o.m) / mu_o dω_m over normals whose reflection is above the horizon.
    let inner = |phi: f64| {
        // Horizon curve (docs/physics.md): theta*(phi) = (pi - atan2(mu, sqrt(1 - mu^2) cos phi)) / 2.
        let theta_star = (PI - mu.atan2(o.x * phi.cos())) / 2.0;
        let x_star = (theta_star.tan() / alpha).ln();
        let (sin_p, cos_p) = phi.sin_cos();
        integrate(-30.0, x_star, 40, &rule, |x| {
            let tan = alpha * x.exp();
            let cos_t = 1.0 / (1.0 + tan * tan).sqrt();
            let sin_t = tan * cos_t;
            let m = Vec3::new(sin_t * cos_p, sin_t * sin_p, cos_t);
            let om = o.dot(m);
            let i = o.reflect(m);
            if om <= 0.0 || i.z <= 0.0 {
                return 0.0;
            }
            // dω_m = sin dtheta dphi, dtheta = cos^2 tan dx.
            let jacobian = sin_t * cos_t * cos_t * tan;
            ndf.d(cos_t) * masking.g2(lambda_o, ndf.lambda(i)) * om / mu * jacobian * weight(om)
        })
    };
    2.0 * integrate(0.0, PI, 16, &rule, inner)
}

/// `E(mu)` by deterministic quadrature, accurate to about 1e-9 for `mu >= 0.02` and
/// `alpha >= 0.05` (it reproduces docs/physics.md's eight-digit check values).
pub fn reference_e(model: Model, alpha: f64, mu: f64) -> f64 {
    reference_weighted_e(model, alpha, mu, &|_| 1.0)
}

/// `E` with the integrand weighted by `weight(o.m)` (a Fresnel factor at the facet's cosine, or
/// a split-sum weight), by the same quadrature and to the same accuracy as [`reference_e`].
pub fn reference_weighted_e(model: Model, alpha: f64, mu: f64, weight: &dyn Fn(f64) -> f64) -> f64 {
    match model.ndf {
        Ndf::Ggx => e_quadrature(Ggx { alpha }, model.masking, mu, weight),
        Ndf::Beckmann => e_quadrature(Beckmann { alpha }, model.masking, mu, weight),
    }
}

/// `E_avg = ∫_0^1 E(sqrt(s)) ds`, with `s = v^2` so that `ds = 2 v dv` smooths the grazing end;
/// for `alpha >= 0.3`, where `E` has no thin boundary layer in `mu`.
pub fn reference_e_avg(model: Model, alpha: f64) -> f64 {
    let rule = gauss_legendre(24);
    integrate(0.0, 1.0, 4, &rule, |v| {
        2.0 * v * reference_e(model, alpha, v)
    })
}
