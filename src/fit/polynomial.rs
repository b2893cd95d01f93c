//! Texture-free fits of `E(mu, r)` found by kiln (`kiln fit`): polynomials in
//! kiln's own coordinates, fitted in the maximum norm, whose maximum error the fit audit
//! ([`crate::verify::fit`]) states.
//!
//! The coordinates are those of kiln's adaptive table axis ([`crate::integrate::grazing`]):
//! `t = (mu (1 + c alpha) / (mu + c alpha))^p` with `c = 4`, `p = 0.4` and `alpha = r^2`, in
//! which the grazing boundary layer of `E` at `mu ~ alpha` stays at the same `t` for every
//! small `alpha`. `E` is a smooth function of `(t, r)`, where it is not of `(mu, r)` (the layer's
//! dip of 0.11 keeps its depth as its width goes to 0). A fit is
//! `sum_{i <= n_t, j <= n_r} a_ij u^i v^j` with `u = 2 t - 1`, `v = 2 r - 1` in [-1, 1]
//! (power basis on the centred interval: its coefficients stay small, so an f32 evaluation
//! adds little).
//!
//! The coefficients are found by Lawson's iteratively reweighted least squares
//! ([`crate::numerics::minimax`], the pure minimax) in the Chebyshev basis, over a dense grid in
//! `(t, r)` and the grazing probes of every row, against the reference; then converted to the
//! power basis. The maximum error the fit states is not the fit's own: it is the audit's of the
//! formula file written (the same text a shader pastes), [`crate::verify::fit::audit_fit`].

use crate::integrate::reference::ReferenceSettings;
use crate::integrate::value::{Integral, Point};
use crate::model::Model;
use crate::numerics::minimax::{Lawson, dot, lawson};
use rayon::prelude::*;

/// The shape of a polynomial fit: degrees in `t` (absent for `E_avg`) and in `r`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Degrees {
    pub t: usize,
    pub r: usize,
}

impl Degrees {
    /// The number of coefficients.
    #[must_use]
    pub fn coefficients(self) -> usize {
        (self.t + 1) * (self.r + 1)
    }
}

/// A fitted polynomial: `coefficients[i * (r + 1) + j]` multiplies `u^i v^j`.
#[derive(Clone, Debug, PartialEq)]
pub struct PolynomialFit {
    pub model: Model,
    pub degrees: Degrees,
    pub coefficients: Vec<f64>,
    /// The largest error over the fit's own points (the audit's figure is the one to state).
    pub fit_max_error: f64,
}

/// `t` of kiln's adaptive axis at `(mu, alpha)`.
#[must_use]
pub fn adaptive_t(mu: f64, alpha: f64) -> f64 {
    crate::integrate::grazing::t_of_mu(mu, alpha)
}

/// Chebyshev polynomials `T_0..=T_n` at `x`.
pub(crate) fn chebyshev(x: f64, n: usize) -> Vec<f64> {
    let mut t = vec![1.0; n + 1];
    if n >= 1 {
        t[1] = x;
    }
    for k in 2..=n {
        t[k] = 2.0 * x * t[k - 1] - t[k - 2];
    }
    t
}

/// The power-basis coefficients of `T_0..=T_n` (row `k`: `T_k = sum_i m[k][i] x^i`).
pub(crate) fn chebyshev_to_power(n: usize) -> Vec<Vec<f64>> {
    let mut m = vec![vec![0.0; n + 1]; n + 1];
    m[0][0] = 1.0;
    if n >= 1 {
        m[1][1] = 1.0;
    }
    for k in 2..=n {
        for i in 0..=n {
            let shifted = if i > 0 { 2.0 * m[k - 1][i - 1] } else { 0.0 };
            m[k][i] = shifted - m[k - 2][i];
        }
    }
    m
}

impl PolynomialFit {
    /// The value at `mu` and the perceptual roughness `r`, as the emitted code computes it.
    #[must_use]
    pub fn value(&self, mu: f64, r: f64) -> f64 {
        let u = 2.0 * adaptive_t(mu, r * r) - 1.0;
        self.value_at(u, 2.0 * r - 1.0)
    }

    /// The polynomial at `(u, v)` by Horner's rule, `u` outermost.
    fn value_at(&self, u: f64, v: f64) -> f64 {
        let nr = self.degrees.r + 1;
        let mut outer = 0.0;
        for i in (0..=self.degrees.t).rev() {
            let mut inner = 0.0;
            for j in (0..nr).rev() {
                inner = inner * v + self.coefficients[i * nr + j];
            }
            outer = outer * u + inner;
        }
        outer
    }
}

/// The fit's points in `(t, r)`: a `(n + 1) x (n + 1)` grid, and on every row the grazing
/// probes (`mu` from 0 to 1, [`crate::table::axis::grazing_probes`]) mapped to `t`.
fn fit_points(n: usize) -> Vec<(f64, f64)> {
    let mut points = Vec::new();
    for r in (0..=n).map(|j| j as f64 / n as f64) {
        for i in 0..=n {
            points.push((i as f64 / n as f64, r));
        }
        for mu in crate::table::axis::grazing_probes() {
            points.push((adaptive_t(mu, r * r), r));
        }
    }
    points
}

/// Fits `E` of `model` with the given degrees. `progress` hears of each reference evaluation.
#[must_use]
pub fn fit(model: Model, degrees: Degrees, progress: &(dyn Fn() + Sync)) -> PolynomialFit {
    let truth = truth_points(model, progress);
    fit_to(model, degrees, &truth)
}

/// How many points [`truth_points`] computes the reference at (97 x 97 and the grazing probes
/// on each of the 97 rows): what a cost estimate counts.
#[must_use]
pub fn truth_point_count() -> usize {
    fit_points(96).len()
}

/// The reference at the fit's points, `((t, r), value)`: computed once for every shape a
/// sweep tries.
#[must_use]
pub fn truth_points(model: Model, progress: &(dyn Fn() + Sync)) -> Vec<((f64, f64), f64)> {
    let integral = Integral::albedo(model);
    let settings = ReferenceSettings {
        tolerance: 1e-8,
        ..ReferenceSettings::default()
    };
    fit_points(96)
        .into_par_iter()
        .map(|(t, r)| {
            // At r = 0 the adaptive axis reaches only t = 0 and 1 (E = 1 at both); between
            // them the fit follows the layer's limit alpha -> 0+, as a table's row 0 holds it
            // (`TableSpec::point`), so that it stays continuous in r.
            let alpha = if r == 0.0 {
                crate::table::axis::LAYER_LIMIT_ALPHA
            } else {
                r * r
            };
            let mu = Some(crate::integrate::grazing::mu_of_t(t, alpha));
            let v = integral
                .reference(
                    Point {
                        alpha,
                        mu,
                        eta: None,
                    },
                    &settings,
                )
                .value;
            progress();
            ((t, r), v)
        })
        .collect()
}

/// [`fit`] against precomputed truth ([`truth_points`]).
#[must_use]
pub fn fit_to(model: Model, degrees: Degrees, truth: &[((f64, f64), f64)]) -> PolynomialFit {
    let (nt, nr) = (degrees.t, degrees.r);
    let k = degrees.coefficients();
    let rows: Vec<Vec<(usize, f64)>> = truth
        .iter()
        .map(|&((t, r), _)| {
            let (ct, cr) = (chebyshev(2.0 * t - 1.0, nt), chebyshev(2.0 * r - 1.0, nr));
            ct.iter()
                .flat_map(|a| cr.iter().map(move |b| a * b))
                .enumerate()
                .collect()
        })
        .collect();
    let b: Vec<f64> = truth.iter().map(|p| p.1).collect();
    let settings = Lawson {
        iterations: 100,
        weight_cap: f64::INFINITY,
        regularisation: 1e-13,
    };
    let chebyshev_coefficients = lawson(&rows, &b, k, &settings);
    let fit_max_error = rows
        .iter()
        .zip(&b)
        .map(|(row, bj)| (dot(row, &chebyshev_coefficients) - bj).abs())
        .fold(0.0_f64, f64::max);
    // Chebyshev coefficients c_pq of T_p(u) T_q(v) to power coefficients of u^i v^j.
    let (mt, mr) = (chebyshev_to_power(nt), chebyshev_to_power(nr));
    let mut coefficients = vec![0.0; k];
    for (p, row_t) in mt.iter().enumerate() {
        for (q, row_r) in mr.iter().enumerate() {
            let c = chebyshev_coefficients[p * (nr + 1) + q];
            for (i, a) in row_t.iter().enumerate() {
                for (j, b) in row_r.iter().enumerate() {
                    coefficients[i * (nr + 1) + j] += c * a * b;
                }
            }
        }
    }
    PolynomialFit {
        model,
        degrees,
        coefficients,
        fit_max_error,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The Chebyshev-to-power conversion against the closed forms `T_2 = 2x^2 - 1`,
    /// `T_3 = 4x^3 - 3x`, `T_4 = 8x^4 - 8x^2 + 1`.
    #[test]
    fn chebyshev_polynomials_in_the_power_basis() {
        let m = chebyshev_to_power(4);
        assert_eq!(m[2], [-1.0, 0.0, 2.0, 0.0, 0.0]);
        assert_eq!(m[3], [0.0, -3.0, 0.0, 4.0, 0.0]);
        assert_eq!(m[4], [1.0, 0.0, -8.0, 0.0, 8.0]);
        let x = 0.3_f64;
        let t = chebyshev(x, 4);
        assert!((t[4] - (8.0 * x.powi(4) - 8.0 * x * x + 1.0)).abs() < 1e-15);
    }

    /// A fit reproduces a polynomial it can represent (the truth `1 + t r^2` at degrees 1, 2):
    /// the power coefficients of `u = 2t - 1`, `v = 2r - 1` are found.
    #[test]
    fn a_representable_function_is_fitted_exactly() {
        let truth: Vec<((f64, f64), f64)> = (0..=10)
            .flat_map(|i| (0..=10).map(move |j| (i as f64 / 10.0, j as f64 / 10.0)))
            .map(|(t, r)| ((t, r), 1.0 + t * r * r))
            .collect();
        let model = Model {
            ndf: crate::model::Ndf::Ggx,
            masking: crate::model::Masking::HeightCorrelated,
        };
        let fit = fit_to(model, Degrees { t: 1, r: 2 }, &truth);
        assert!(fit.fit_max_error < 1e-12, "{}", fit.fit_max_error);
        for &((t, r), v) in &truth {
            assert!((fit.value_at(2.0 * t - 1.0, 2.0 * r - 1.0) - v).abs() < 1e-12);
        }
    }
}
