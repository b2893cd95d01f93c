//! The microsurface's height distribution, as the walk needs it: `C1(h)`, the fraction of the
//! surface below height `h`, and its inverse.
//!
//! Heitz, Hanika, d'Eon and Dachsbacher 2016 ("Multiple-Scattering Microfacet BSDFs with the
//! Smith Model", ACM TOG 35(4), sections 4-5) write the walk with heights: a ray travelling up
//! from `h` escapes with probability `C1(h)^Lambda(w)`, and every hit is drawn through `C1` and
//! its inverse. In `ln C1(h)` (minus the optical depth) the walk is the same for every height
//! distribution (Dupuy, Heitz and d'Eon 2016, "Additional Progress Towards the Unification of
//! Microfacet and Microflake Theories"); the distributions differ only in how many digits
//! `C1` keeps deep in the surface. kiln walks on exponential heights by default, whose
//! `ln C1(h) = h` is exact at every depth; uniform heights (the paper's) lose `C1`'s digits
//! below `1e-16` (`h + 1` rounds to 0) and Gaussian heights cost an `erfc` and its inverse a
//! step. Both stay as the check that nothing depends on the choice.

use crate::model::special::{erf_inv_uniform, erfc};
use std::f64::consts::SQRT_2;

/// A height distribution of the microsurface.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Heights {
    /// `C1(h) = e^h` for `h <= 0`: `ln C1` is the height itself, exact at every depth.
    #[default]
    Exponential,
    /// Uniform on `[-1, 1]`: `C1(h) = (h + 1) / 2` (Heitz et al. 2016's choice).
    Uniform,
    /// Standard normal: `C1(h) = erfc(-h / sqrt 2) / 2`.
    Gaussian,
}

impl Heights {
    /// Every distribution, in a fixed order.
    pub const ALL: [Heights; 3] = [Heights::Exponential, Heights::Uniform, Heights::Gaussian];

    /// The name used on the command line and in reports.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Heights::Exponential => "exponential",
            Heights::Uniform => "uniform",
            Heights::Gaussian => "gaussian",
        }
    }

    /// `ln C1(h)`, at most 0 (the top of the surface, `C1 = 1`).
    #[must_use]
    pub fn log_c1(self, h: f64) -> f64 {
        match self {
            Heights::Exponential => h.min(0.0),
            Heights::Uniform => (0.5 * (h + 1.0)).clamp(0.0, 1.0).ln(),
            Heights::Gaussian => (0.5 * erfc(-h / SQRT_2)).ln(),
        }
    }

    /// The height `h` with `ln C1(h) = log_c1` (`log_c1 <= 0`).
    #[must_use]
    pub fn height(self, log_c1: f64) -> f64 {
        match self {
            Heights::Exponential => log_c1,
            Heights::Uniform => 2.0 * log_c1.exp() - 1.0,
            // erf(y) = 2 C1 - 1 gives y, and Phi(sqrt 2 y) = C1.
            Heights::Gaussian => SQRT_2 * erf_inv_uniform(log_c1.exp()),
        }
    }
}

/// `ln C1` of the next hit of a ray travelling down from `log_c1` (0 at the top of the surface):
/// it always hits, with `ln C1' = ln C1 + ln(u) / (1 + Lambda(-w))` for a uniform `u`
/// (`lambda_down` is `Lambda` of the direction reversed, i.e. of `|w|`; Heitz, Hanika, d'Eon and
/// Dachsbacher 2016, section 4.1). Both walks step down by it.
#[must_use]
#[inline]
pub fn log_c1_of_hit_below(log_c1: f64, lambda_down: f64, u: f64) -> f64 {
    log_c1 + u.ln() / (1.0 + lambda_down)
}

/// `ln C1` of the next hit of a ray travelling up from `log_c1` with `Lambda(w) = lambda` that
/// did not escape (which it does with probability `escape = C1^Lambda`):
/// `C1' = C1 / (1 - u (1 - escape))^(1 / Lambda)` for a uniform `u` (section 4.2, conditioned on
/// no escape). Both walks step up by it.
#[must_use]
#[inline]
pub fn log_c1_of_hit_above(log_c1: f64, lambda: f64, escape: f64, u: f64) -> f64 {
    log_c1 - (-u * (1.0 - escape)).ln_1p() / lambda
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each distribution's inverse undoes its `C1` (a slip in one of the pair moves every hit).
    #[test]
    fn height_inverts_log_c1() {
        for heights in Heights::ALL {
            for log_c1 in [-1e-9, -0.01, -0.5, -2.0, -10.0] {
                let h = heights.height(log_c1);
                let back = heights.log_c1(h);
                assert!(
                    (back - log_c1).abs() <= 1e-9 * log_c1.abs().max(1.0),
                    "{heights:?}: {log_c1} -> {h} -> {back}"
                );
            }
        }
        // The published forms at one height each: uniform's median 0, Gaussian's Phi(1).
        assert!((Heights::Uniform.log_c1(0.0) - 0.5f64.ln()).abs() < 1e-15);
        assert!((Heights::Gaussian.log_c1(1.0) - 0.841_344_746_068_542_9f64.ln()).abs() < 1e-14);
    }
}
