//! Bisection of a bracketed change of side: the one root finder the integrators' breaks share
//! (critical angles, horizons and their crossings), where a fixed number of halvings is both
//! cheap and exact enough.

/// The midpoint of `[lo, hi]` after `steps` halvings, each keeping the half whose lower end
/// `at_lower_side` still accepts: `lo` moves to the midpoint when the predicate holds there,
/// `hi` otherwise. `at_lower_side(lo)` and `!at_lower_side(hi)` are the caller's bracket.
#[must_use]
pub fn bisect(mut lo: f64, mut hi: f64, steps: u32, at_lower_side: impl Fn(f64) -> bool) -> f64 {
    for _ in 0..steps {
        let mid = 0.5 * (lo + hi);
        if at_lower_side(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The root of `x^2 - 2` on `[1, 2]` to f64 after 60 halvings, and after 10 within the
    /// bracket's width over 2^11; the predicate's side decides which end moves.
    #[test]
    fn bisection_closes_on_the_change_of_side() {
        let root = bisect(1.0, 2.0, 60, |x| x * x < 2.0);
        assert!((root - 2f64.sqrt()).abs() < 1e-15, "{root}");
        let coarse = bisect(1.0, 2.0, 10, |x| x * x < 2.0);
        assert!((coarse - 2f64.sqrt()).abs() <= 0.5f64.powi(11), "{coarse}");
        // A decreasing function: the lower side is where it is still positive.
        let root = bisect(0.0, 3.0, 60, |x| x.cos() > 0.0);
        assert!((root - std::f64::consts::FRAC_PI_2).abs() < 1e-15, "{root}");
    }
}
