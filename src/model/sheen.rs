//! The cloth (sheen) lobe Filament and Godot tabulate in the blue channel of their DFG tables:
//! the "Charlie" distribution with Ashikhmin's visibility, `F = 1`.
//!
//! - Charlie NDF (Estevez and Kulla 2017, "Production Friendly Microfacet Sheen BRDF", eq. 2):
//!   `D(h) = (2 + 1 / alpha) sin(theta_h)^(1 / alpha) / (2 pi)`, normalised so that
//!   `∫ D(h) cos(theta_h) dω_h = 1` (substitute `w = sin^2`: `(2 + 1/alpha) / (2 (k + 1)) = 1`
//!   with `k = 1 / (2 alpha)`). `alpha` is the slope-space roughness, perceptual roughness
//!   squared, as both engines pass it.
//! - Ashikhmin's visibility in Neubelt and Pettineo's form (2013, "Crafting a Next-Gen Material
//!   Pipeline for The Order: 1886"): `V(o, i) = 1 / (4 (mu_i + mu_o - mu_i mu_o))`, so the BRDF
//!   is `f = D(h) V(o, i)` (Filament's `DFV_Charlie_Uniform`, Godot's `integrate_dfg.glsl`).

/// The Charlie distribution `D(h)` at `cos(theta_h) = cos_h` for slope-space `alpha > 0`.
#[must_use]
pub fn charlie_d(cos_h: f64, alpha: f64) -> f64 {
    let sin2 = (1.0 - cos_h * cos_h).max(0.0);
    (2.0 + 1.0 / alpha) * sin2.powf(0.5 / alpha) / (2.0 * std::f64::consts::PI)
}

/// `∫_0^1 2 D(c) dc` of the Charlie distribution ([`charlie_d`]): the weight an error in an
/// integral over `c` of `D` times a bounded factor carries (the sheen albedo's inner integrals,
/// [`crate::integrate::sheen`]). With `k = 1 / (2 alpha)`,
/// `∫_0^1 (1 - c^2)^k dc = (sqrt(pi) / 2) Γ(k + 1) / Γ(k + 3/2)` (the Beta function
/// `B(1/2, k + 1) / 2`), so the integral is `(2 + 1/alpha) / pi` times that; about
/// `1 / sqrt(pi alpha)` for small `alpha`, where `D` peaks at `c = 0`.
#[must_use]
pub fn charlie_weight(alpha: f64) -> f64 {
    use std::f64::consts::PI;
    let k = 0.5 / alpha;
    let beta_half = 0.5 * PI.sqrt() * (libm::lgamma(k + 1.0) - libm::lgamma(k + 1.5)).exp();
    (2.0 + 1.0 / alpha) / PI * beta_half
}

/// Ashikhmin's visibility `1 / (4 (mu_i + mu_o - mu_i mu_o))` for cosines in `[0, 1]`, not both 0.
#[must_use]
#[inline]
pub fn ashikhmin_v(mu_o: f64, mu_i: f64) -> f64 {
    1.0 / (4.0 * (mu_i + mu_o - mu_i * mu_o))
}

/// The sheen albedo at normal incidence in closed form: with `mu_o = 1`, `mu_i = 2 c^2 - 1`
/// and `V = 1/4` for every `i`, and `w = 1 - c^2`,
/// `E(1) = (2 + 1/alpha) / 2 ∫_0^{1/2} w^k (1 - 2w) dw = 2^-(k+1) / (k + 2)`, `k = 1 / (2 alpha)`.
#[must_use]
pub fn sheen_albedo_at_normal(alpha: f64) -> f64 {
    let k = 0.5 / alpha;
    0.5f64.powf(k + 1.0) / (k + 2.0)
}
