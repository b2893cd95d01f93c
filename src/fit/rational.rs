//! Rational texture-free fits of `E(mu, r)` (`kiln fit --degrees PT,PR/QT,QR`):
//! `E = 1 - t^2 P(u, s) / Q(u, s)`, fitted in the maximum norm, whose maximum error the fit
//! audit ([`crate::verify::fit`]) states.
//!
//! The coordinates are those of kiln's adaptive axis with other constants:
//! `t = (mu (1 + alpha) / (mu + alpha))^0.3` (`c = 1`, `p = 0.3` in
//! [`crate::integrate::grazing`]'s form, so the grazing layer at `mu ~ alpha` keeps its `t` at
//! every small roughness), `u = 2 t - 1`, and `s = 2 r^3.2 - 1` (`r^3.2 = alpha^1.6`). The factor
//! `t^2` builds in what the height-correlated albedo does at grazing: `E(0) = 1` at every
//! roughness (docs/physics.md), `1 - E` vanishing there about linearly in `mu` (measured on the
//! reference). The constants were chosen by the
//! measured maximum error of the fits at 12 and 31 coefficients (docs/fits.md).
//!
//! `P` and `Q` are tensor-product polynomials, found in the Chebyshev basis by differential
//! correction (Cheney and Loeb, "Two new algorithms for rational approximation", Numer. Math. 3
//! (1961) 72-75; convergence to the best approximation on a finite set: Barrodale, Powell and
//! Roberts, SIAM J. Numer. Anal. 9 (1972) 493-504): given the current maximum `delta` and
//! denominator `Q_k`, a linear program ([`crate::numerics::simplex`]) minimises `z` subject to
//! `|E Q - N| - delta Q <= z Q_k` at every point (`N = Q - t^2 P`), `Q >= 1e-3` and the `Q`
//! coefficients in [-1, 1]; it stops when `z` no longer falls below 0. Both are then written in
//! the power basis of `(u, s)`, scaled so that `Q`'s constant term is 1: the fit has
//! `|P| + |Q| - 1` coefficients.

use super::polynomial::{Degrees, chebyshev, chebyshev_to_power};
use crate::model::Model;
use crate::numerics::simplex::{LpError, minimize_from};

/// `p` of the fit's `t`.
pub const T_POWER: f64 = 0.3;
/// The power of `r` in the fit's roughness coordinate.
pub const R_POWER: f64 = 3.2;
/// The lower bound of the denominator at the fit's points (its coefficients are in [-1, 1]).
const DENOMINATOR_FLOOR: f64 = 1e-3;
/// Points added to a step's program per round of column generation.
const ADDED_PER_ROUND: usize = 500;
/// Differential-correction steps at most (each a linear program).
const MAX_STEPS: usize = 40;

/// The estimated time of [`fit_to`] for `shape`, in seconds (its linear programs run on one
/// thread): `44 s (n / 33)^4.5` for `n` unknowns (the coefficients and `z`), fitted to whole
/// `kiln fit --degrees` runs on a 2-core AMD EPYC, one each (2026-12-07: 2,2/2,2 in 4.1 s,
/// 3,3/3,3 in 44 s of CPU, 4,4/4,4 in 261 s). The cost grows with the programs' size and the
/// steps they take, so the figure is a rough one: 6,6/6,6 about 2 hours, 12,12/12,12 about 3
/// weeks.
#[must_use]
pub fn estimated_seconds(shape: RationalShape) -> f64 {
    let unknowns = (shape.coefficients() + 2) as f64;
    44.0 * (unknowns / 33.0).powf(4.5)
}

/// The shape of a rational fit: the degrees of `P` and of `Q`, and whether `P` is additive.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RationalShape {
    pub numerator: Degrees,
    pub denominator: Degrees,
    /// `P(u, s) = A(u) + B(s)`, without the cross terms `u^i s^j` (`i, j >= 1`): `T + R + 1`
    /// coefficients instead of `(T + 1) (R + 1)` (`--degrees T+R/QT,QR`). At 12 coefficients
    /// `P = A(u) + B(s)` of degrees 2 and 1 over the full `Q` of degrees 2, 2 is 9.2e-3 off
    /// where the tensor shape 1,1/2,2 is 1.01e-2 off (docs/fits.md).
    pub additive: bool,
}

impl RationalShape {
    /// The number of coefficients (`Q`'s constant term is 1).
    #[must_use]
    pub fn coefficients(self) -> usize {
        self.numerator_terms().len() + self.denominator.coefficients() - 1
    }

    /// The indices of `P`'s terms in its tensor layout (`i * (R + 1) + j` for `u^i s^j`): all of
    /// them, or those of an additive `P` (`i = 0` or `j = 0`).
    #[must_use]
    pub fn numerator_terms(self) -> Vec<usize> {
        let width = self.numerator.r + 1;
        (0..self.numerator.coefficients())
            .filter(|k| !self.additive || k / width == 0 || k % width == 0)
            .collect()
    }
}

/// A fitted rational: `numerator[i * (R + 1) + j]` multiplies `u^i s^j` in `P` (degrees
/// `(T, R)`), likewise `denominator` in `Q`, whose first coefficient is 1.
#[derive(Clone, Debug, PartialEq)]
pub struct RationalFit {
    pub model: Model,
    pub shape: RationalShape,
    pub numerator: Vec<f64>,
    pub denominator: Vec<f64>,
    /// The largest error over the fit's own points (the audit's figure is the one to state).
    pub fit_max_error: f64,
}

/// The fit's `t` of `mu` at roughness `alpha` (`c = 1`), as the emitted code computes it.
#[must_use]
pub fn rational_t(mu: f64, alpha: f64) -> f64 {
    (mu * (1.0 + alpha) / (mu + alpha).max(1e-30))
        .min(1.0)
        .powf(T_POWER)
}

/// The fit's roughness coordinate `r^3.2` in [0, 1].
#[must_use]
pub fn roughness_coordinate(r: f64) -> f64 {
    r.powf(R_POWER)
}

/// A tensor-product polynomial in the power basis at `(u, s)` by Horner's rule, `u` outermost.
fn horner(coefficients: &[f64], degrees: Degrees, u: f64, s: f64) -> f64 {
    let nr = degrees.r + 1;
    coefficients.chunks(nr).rev().fold(0.0, |outer, row| {
        outer * u + row.iter().rev().fold(0.0, |inner, &c| inner * s + c)
    })
}

impl RationalFit {
    /// The value at `mu` and the perceptual roughness `r`.
    #[must_use]
    pub fn value(&self, mu: f64, r: f64) -> f64 {
        let t = rational_t(mu, r * r);
        self.value_at(t, roughness_coordinate(r))
    }

    /// The value at the fit's coordinates `(t, r^3.2)`.
    #[must_use]
    pub fn value_at(&self, t: f64, w: f64) -> f64 {
        let (u, s) = (2.0 * t - 1.0, 2.0 * w - 1.0);
        let p = horner(&self.numerator, self.shape.numerator, u, s);
        let q = horner(&self.denominator, self.shape.denominator, u, s);
        1.0 - t * t * p / q
    }
}

/// The Chebyshev tensor basis `T_i(x) T_j(y)`, `j` fastest.
fn basis(degrees: Degrees, x: f64, y: f64) -> Vec<f64> {
    let (a, b) = (chebyshev(x, degrees.t), chebyshev(y, degrees.r));
    a.iter()
        .flat_map(|p| b.iter().map(move |q| p * q))
        .collect()
}

/// Chebyshev tensor coefficients to power-basis ones.
fn to_power(chebyshev_coefficients: &[f64], degrees: Degrees) -> Vec<f64> {
    let (nt, nr) = (degrees.t, degrees.r);
    let (mt, mr) = (chebyshev_to_power(nt), chebyshev_to_power(nr));
    let mut out = vec![0.0; degrees.coefficients()];
    for (p, row_t) in mt.iter().enumerate() {
        for (q, row_r) in mr.iter().enumerate() {
            let c = chebyshev_coefficients[p * (nr + 1) + q];
            for (i, a) in row_t.iter().enumerate() {
                for (j, b) in row_r.iter().enumerate() {
                    out[i * (nr + 1) + j] += c * a * b;
                }
            }
        }
    }
    out
}

/// Truth points of [`super::polynomial::truth_points`] (in the adaptive axis' `(t, r)`) in this
/// fit's coordinates `(t, r^3.2)`. At `r = 0` the points hold the grazing layer's limit
/// `alpha -> 0+` ([`crate::table::axis::LAYER_LIMIT_ALPHA`]), as the polynomial fit's do.
#[must_use]
pub fn coordinates_of(truth: &[((f64, f64), f64)]) -> Vec<((f64, f64), f64)> {
    truth
        .iter()
        .map(|&((t, r), value)| {
            let alpha = if r == 0.0 {
                crate::table::axis::LAYER_LIMIT_ALPHA
            } else {
                r * r
            };
            let mu = crate::integrate::grazing::mu_of_t(t, alpha);
            ((rational_t(mu, alpha), roughness_coordinate(r)), value)
        })
        .collect()
}

/// Fits `1 - t^2 P / Q` of `shape` to `truth` given in the fit's coordinates
/// (`((t, r^3.2), value)`, [`coordinates_of`]) by differential correction (module docs).
/// `progress` hears of each step.
///
/// # Errors
/// When a step's linear program fails ([`LpError`]; a bug or numerical trouble, not a property
/// of the data).
pub fn fit_to(
    model: Model,
    shape: RationalShape,
    truth: &[((f64, f64), f64)],
    progress: &dyn Fn(),
) -> Result<RationalFit, LpError> {
    // P's unknowns are its terms' coefficients (all of the tensor, or an additive P's).
    let terms = shape.numerator_terms();
    let (np, nq) = (terms.len(), shape.denominator.coefficients());
    let unknowns = np + nq + 1;
    let rows: Vec<(Vec<f64>, Vec<f64>, f64)> = truth
        .iter()
        .map(|&((t, w), value)| {
            let (x, y) = (2.0 * t - 1.0, 2.0 * w - 1.0);
            let all = basis(shape.numerator, x, y);
            let p: Vec<f64> = terms.iter().map(|&k| t * t * all[k]).collect();
            (p, basis(shape.denominator, x, y), value)
        })
        .collect();
    // The fit's value and its denominator at a point, from Chebyshev coefficients `x = (p, q)`.
    let at = |x: &[f64], (p, q, _): &(Vec<f64>, Vec<f64>, f64)| {
        let d: f64 = q.iter().zip(&x[np..np + nq]).map(|(a, b)| a * b).sum();
        let n: f64 = p.iter().zip(&x[..np]).map(|(a, b)| a * b).sum();
        (1.0 - n / d, d)
    };
    let errors_of = |x: &[f64]| -> Vec<f64> {
        rows.iter()
            .map(|row| (at(x, row).0 - row.2).abs())
            .collect()
    };
    let largest = |errors: &[f64]| errors.iter().copied().fold(0.0_f64, f64::max);
    // Start from P = 0, Q = 1: E = 1.
    let mut x = vec![0.0; unknowns];
    x[np] = 1.0;
    let mut errors = errors_of(&x);
    let mut best = (largest(&errors), x.clone());
    let mut objective = vec![0.0; unknowns];
    objective[unknowns - 1] = 1.0;
    for _ in 0..MAX_STEPS {
        let delta = largest(&errors);
        let previous: Vec<f64> = rows.iter().map(|row| at(&x, row).1).collect();
        // A point's three constraints: |E Q - N| - delta Q <= z Q_k (E Q - N = (E - 1) Q +
        // t^2 P) and Q >= the floor.
        let add = |i: usize, g: &mut Vec<f64>, h: &mut Vec<f64>| {
            let (p, q, value) = &rows[i];
            for sign in [1.0, -1.0] {
                g.extend(p.iter().map(|b| sign * b));
                g.extend(q.iter().map(|b| (sign * (value - 1.0) - delta) * b));
                g.push(-previous[i]);
                h.push(0.0);
            }
            g.extend(std::iter::repeat_n(0.0, np));
            g.extend(q.iter().map(|b| -b));
            g.push(0.0);
            h.push(-DENOMINATOR_FLOOR);
        };
        // How far `y` is outside point i's constraints.
        let violation = |y: &[f64], i: usize| {
            let (p, q, value) = &rows[i];
            let n: f64 = p.iter().zip(&y[..np]).map(|(a, b)| a * b).sum();
            let d: f64 = q.iter().zip(&y[np..np + nq]).map(|(a, b)| a * b).sum();
            let z = y[unknowns - 1];
            let residual = n + (value - 1.0) * d;
            (residual.abs() - delta * d - z * previous[i]).max(DENOMINATOR_FLOOR - d)
        };
        let mut g = Vec::new();
        let mut h = Vec::new();
        for j in 0..nq {
            for sign in [1.0, -1.0] {
                let mut bound = vec![0.0; unknowns];
                bound[np + j] = sign;
                g.extend(bound);
                h.push(1.0);
            }
        }
        // Column generation (the points a step's program needs are few): start from the
        // points within half of the maximum and every 16th, then add the points the solution
        // violates, the worst first, until it violates none; the basis carries over, since a
        // point's constraints are columns of the dual.
        let mut active: Vec<bool> = errors
            .iter()
            .enumerate()
            .map(|(i, &e)| e >= 0.5 * delta || i % 16 == 0)
            .collect();
        for i in (0..rows.len()).filter(|&i| active[i]) {
            add(i, &mut g, &mut h);
        }
        let mut basis: Option<Vec<usize>> = None;
        let solution = loop {
            let solution = minimize_from(&objective, &g, &h, basis.as_deref())?;
            let mut violated: Vec<(f64, usize)> = (0..rows.len())
                .filter(|&i| !active[i])
                .map(|i| (violation(&solution.x, i), i))
                .filter(|&(v, _)| v > 1e-10)
                .collect();
            if violated.is_empty() {
                break solution;
            }
            violated.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
            let before = h.len();
            for &(_, i) in violated.iter().take(ADDED_PER_ROUND) {
                active[i] = true;
                add(i, &mut g, &mut h);
            }
            let grown = h.len() - before;
            basis = Some(
                solution
                    .basis
                    .iter()
                    .map(|&j| if j >= before { j + grown } else { j })
                    .collect(),
            );
        };
        progress();
        let next = solution.x;
        let z = next[unknowns - 1];
        errors = errors_of(&next);
        let error = largest(&errors);
        if error < best.0 {
            best = (error, next.clone());
        }
        if z > -1e-12 {
            break;
        }
        x = next;
    }
    let (fit_max_error, x) = best;
    // Back to the tensor layout, an additive P's cross terms 0 (in either basis: the Chebyshev
    // T_i(u) T_0(s) is a polynomial in u alone).
    let mut tensor = vec![0.0; shape.numerator.coefficients()];
    for (&k, &c) in terms.iter().zip(&x[..np]) {
        tensor[k] = c;
    }
    let numerator = to_power(&tensor, shape.numerator);
    let denominator = to_power(&x[np..np + nq], shape.denominator);
    let scale = denominator[0];
    Ok(RationalFit {
        model,
        shape,
        numerator: numerator.iter().map(|c| c / scale).collect(),
        denominator: denominator.iter().map(|c| c / scale).collect(),
        fit_max_error,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn model() -> Model {
        Model {
            ndf: crate::model::Ndf::Ggx,
            masking: crate::model::Masking::HeightCorrelated,
        }
    }

    /// A rational the form can represent, `1 - t^2 (0.3 + 0.2 u) / (1 + 0.4 s + 0.1 u s)`, is
    /// found from its values: coefficients and values to 1e-9.
    #[test]
    fn a_representable_rational_is_found() {
        let truth: Vec<((f64, f64), f64)> = (0..=20)
            .flat_map(|i| (0..=20).map(move |j| (i as f64 / 20.0, j as f64 / 20.0)))
            .map(|(t, w)| {
                let (u, s) = (2.0 * t - 1.0, 2.0 * w - 1.0);
                (
                    (t, w),
                    1.0 - t * t * (0.3 + 0.2 * u) / (1.0 + 0.4 * s + 0.1 * u * s),
                )
            })
            .collect();
        let shape = RationalShape {
            numerator: Degrees { t: 1, r: 1 },
            denominator: Degrees { t: 1, r: 1 },
            additive: false,
        };
        let fit = fit_to(model(), shape, &truth, &|| {}).unwrap();
        assert!(fit.fit_max_error < 1e-9, "{}", fit.fit_max_error);
        let expected_p = [0.3, 0.0, 0.2, 0.0];
        let expected_q = [1.0, 0.4, 0.0, 0.1];
        for (found, want) in fit.numerator.iter().zip(expected_p) {
            assert!((found - want).abs() < 1e-8, "{:?}", fit.numerator);
        }
        for (found, want) in fit.denominator.iter().zip(expected_q) {
            assert!((found - want).abs() < 1e-8, "{:?}", fit.denominator);
        }
        for &((t, w), v) in &truth {
            assert!((fit.value_at(t, w) - v).abs() < 1e-9);
        }
    }

    /// An additive `P` of degrees 2, 1 keeps `1, s, u, u^2` (tensor indices 0, 1, 2, 4): 12
    /// coefficients over `Q` of degrees 2, 2; its cross terms come back exactly 0, so the
    /// emitted code has 12 coefficients too.
    #[test]
    fn an_additive_numerator_has_no_cross_terms() {
        let shape = RationalShape {
            numerator: Degrees { t: 2, r: 1 },
            denominator: Degrees { t: 2, r: 2 },
            additive: true,
        };
        assert_eq!(shape.numerator_terms(), [0, 1, 2, 4]);
        assert_eq!(shape.coefficients(), 12);
        let tensor = RationalShape {
            additive: false,
            ..shape
        };
        assert_eq!(tensor.numerator_terms().len(), 6);
        // E = 1 - t^2 (0.2 + 0.1 u + 0.05 s) / (1 + 0.1 s): representable with no cross term.
        let truth: Vec<((f64, f64), f64)> = (0..=12)
            .flat_map(|i| (0..=12).map(move |j| (f64::from(i) / 12.0, f64::from(j) / 12.0)))
            .map(|(t, w)| {
                let (u, s) = (2.0 * t - 1.0, 2.0 * w - 1.0);
                (
                    (t, w),
                    1.0 - t * t * (0.2 + 0.1 * u + 0.05 * s) / (1.0 + 0.1 * s),
                )
            })
            .collect();
        let fit = fit_to(model(), shape, &truth, &|| {}).unwrap();
        assert!(fit.fit_max_error < 1e-9, "{}", fit.fit_max_error);
        for k in [3, 5] {
            assert_eq!(fit.numerator[k], 0.0, "cross term {k}");
        }
    }

    /// `1 - t^2 / (1 + t)` by `1 - c t^2` (`P` and `Q` of degree 0): the error is
    /// `t^2 |1 / (1 + t) - c|`, and the differential correction's maximum is the smallest a
    /// scan over `c` finds.
    #[test]
    fn a_constant_numerator_is_the_minimax_one() {
        let truth: Vec<((f64, f64), f64)> = (0..=400)
            .map(|i| i as f64 / 400.0)
            .map(|t| ((t, 0.5), 1.0 - t * t / (1.0 + t)))
            .collect();
        let shape = RationalShape {
            numerator: Degrees { t: 0, r: 0 },
            denominator: Degrees { t: 0, r: 0 },
            additive: false,
        };
        let fit = fit_to(model(), shape, &truth, &|| {}).unwrap();
        // Independent: scan c, for each the maximum over the points.
        let scan = (0..=20_000)
            .map(|k| 0.4 + 0.2 * k as f64 / 20_000.0)
            .map(|c| {
                truth
                    .iter()
                    .map(|&((t, _), _)| (t * t * (1.0 / (1.0 + t) - c)).abs())
                    .fold(0.0_f64, f64::max)
            })
            .fold(f64::INFINITY, f64::min);
        assert!(
            (fit.fit_max_error - scan).abs() < 1e-6,
            "{} {scan}",
            fit.fit_max_error
        );
    }
}
