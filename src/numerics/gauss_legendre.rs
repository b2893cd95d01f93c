//! Gauss-Legendre rules: `n` nodes integrate polynomials of degree `2n - 1` exactly.
//!
//! The nodes are the roots of the Legendre polynomial `P_n`, found by Newton's method from the
//! asymptotic first guess `cos(pi (k - 1/4) / (n + 1/2))`, with `P_n` and `P_n'` from the
//! three-term recurrence `k P_k = (2k - 1) x P_{k-1} - (k - 1) P_{k-2}` and
//! `(x^2 - 1) P_n' = n (x P_n - P_{n-1})`; the weights are `2 / ((1 - x^2) P_n'(x)^2)`
//! (Abramowitz and Stegun, "Handbook of Mathematical Functions", 22.7.10, 22.8.5 and 25.4.29).

/// The `n`-point rule on `[-1, 1]`: `(node, weight)` pairs, nodes in decreasing order.
///
/// # Panics
/// If `n` is 0.
#[must_use]
pub fn rule(n: usize) -> Vec<(f64, f64)> {
    assert!(n > 0, "a Gauss-Legendre rule needs at least one node");
    (0..n)
        .map(|k| {
            let mut x = (std::f64::consts::PI * (k as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut derivative = 1.0;
            for _ in 0..100 {
                let (p, p_previous) = legendre(n, x);
                derivative = n as f64 * (x * p - p_previous) / (x * x - 1.0);
                let step = p / derivative;
                x -= step;
                if step.abs() <= 1e-16 {
                    break;
                }
            }
            let (p, p_previous) = legendre(n, x);
            derivative = if n == 1 {
                1.0
            } else {
                let d = n as f64 * (x * p - p_previous) / (x * x - 1.0);
                if d.is_finite() { d } else { derivative }
            };
            (x, 2.0 / ((1.0 - x * x) * derivative * derivative))
        })
        .collect()
}

/// `(P_n(x), P_{n-1}(x))` by the recurrence.
fn legendre(n: usize, x: f64) -> (f64, f64) {
    let (mut previous, mut current) = (1.0, x);
    if n == 0 {
        return (1.0, 0.0);
    }
    for k in 2..=n {
        let next = ((2 * k - 1) as f64 * x * current - (k - 1) as f64 * previous) / k as f64;
        previous = current;
        current = next;
    }
    (current, previous)
}

/// `∫_a^b f` by the rule (from [`rule`]) mapped onto `[a, b]`, for vector integrands.
pub fn integrate<const N: usize>(
    rule: &[(f64, f64)],
    f: &mut impl FnMut(f64) -> [f64; N],
    a: f64,
    b: f64,
) -> [f64; N] {
    let (centre, half) = (0.5 * (a + b), 0.5 * (b - a));
    let mut total = [0.0; N];
    for &(x, w) in rule {
        let value = f(centre + half * x);
        for (t, v) in total.iter_mut().zip(value) {
            *t += half * w * v;
        }
    }
    total
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rules_integrate_polynomials_of_degree_2n_minus_1_exactly() {
        for n in [1usize, 2, 3, 7, 12, 20, 32] {
            let r = rule(n);
            assert_eq!(r.len(), n);
            assert!(
                (r.iter().map(|p| p.1).sum::<f64>() - 2.0).abs() < 1e-14,
                "{n}"
            );
            for degree in 0..2 * n as i32 {
                let exact =
                    [(1.0f64.powi(degree + 1) - (-1.0f64).powi(degree + 1))
                        / f64::from(degree + 1)];
                let got = integrate(&r, &mut |x: f64| [x.powi(degree)], -1.0, 1.0);
                assert!((got[0] - exact[0]).abs() < 1e-13, "n {n} degree {degree}");
            }
            // Degree 2n is not exact: the rule is exactly as strong as claimed (its error on
            // x^2n shrinks like 4^-n, so look where it is well above rounding).
            if n <= 12 {
                let got = integrate(&r, &mut |x: f64| [x.powi(2 * n as i32)], -1.0, 1.0);
                assert!((got[0] - 2.0 / (2 * n + 1) as f64).abs() > 1e-10, "n {n}");
            }
        }
    }

    #[test]
    fn mapped_onto_an_interval() {
        let r = rule(10);
        let got = integrate(&r, &mut |x: f64| [x.exp(), 1.0], 1.0, 3.0);
        assert!((got[0] - (3f64.exp() - 1f64.exp())).abs() < 1e-12);
        assert!((got[1] - 2.0).abs() < 1e-14);
    }
}
