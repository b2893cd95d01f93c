//! The change of variable that follows the grazing boundary layer of `E` at `mu ~ alpha`
//! (`docs/physics.md`, "Hard cases"): `t = (mu (1 + c alpha) / (mu + c alpha))^p` with
//! `c` = [`ADAPTIVE_SCALE`], `p` = [`ADAPTIVE_POWER`]. To `O(alpha^2)`, `E(mu, alpha)` is a
//! function of `x = mu / alpha` alone; in `t`, `x = c s / (1 + c alpha - s)` with `s = t^(1/p)`,
//! so the layer sits at the same `t` for every small `alpha`. The `E_avg` rule integrates in
//! `t` ([`super::average_quadrature`]) and kiln's default `mu` axis is laid out in it
//! ([`crate::table::axis::MuMapping::Adaptive`]; the constants were chosen there, by measured
//! lookup error at 32 x 32).

/// The scale `c`: the boundary layer's `mu ~ alpha` maps near `t = (1 / (1 + c))^p`, about the
/// middle of `[0, 1]`.
pub const ADAPTIVE_SCALE: f64 = 4.0;
/// The power `p`: below 1 it spreads the samples near `mu = 0`.
pub const ADAPTIVE_POWER: f64 = 0.4;

/// `mu` at `t` for slope-space roughness `alpha`: 1 at `t = 1`; at `alpha = 0` the layer has no
/// width and every `t < 1` gives 0.
#[must_use]
pub fn mu_of_t(t: f64, alpha: f64) -> f64 {
    // s (mu + k) = mu (1 + k)  =>  mu = s k / (1 + k - s), with k = c alpha.
    let s = t.powf(1.0 / ADAPTIVE_POWER);
    let k = ADAPTIVE_SCALE * alpha;
    if s >= 1.0 {
        1.0
    } else {
        (s * k / (1.0 + k - s)).min(1.0)
    }
}

/// `t` at `mu` for `alpha` (the inverse of [`mu_of_t`]): 0 at `mu = 0` whatever `alpha`, 1 for
/// every `mu > 0` when `alpha = 0`.
#[must_use]
pub fn t_of_mu(mu: f64, alpha: f64) -> f64 {
    if mu <= 0.0 {
        return 0.0;
    }
    let k = ADAPTIVE_SCALE * alpha;
    (mu * (1.0 + k) / (mu + k)).min(1.0).powf(ADAPTIVE_POWER)
}
