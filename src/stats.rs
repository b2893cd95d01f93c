//! Summaries of many numbers that cannot hide a NaN.
//!
//! `iter.fold(0.0, f64::max)` drops NaN (`f64::max(0.0, NaN)` is 0), so a NaN texel would make
//! a table's maximum error look like 0 and pass every `--max-error` gate. Every maximum kiln
//! states or gates on goes through [`max_or_nan`].

/// The largest of `values`, NaN if any is NaN, 0 for none (errors and magnitudes are >= 0).
#[must_use]
pub fn max_or_nan(values: impl IntoIterator<Item = f64>) -> f64 {
    let mut max = 0.0_f64;
    for v in values {
        if v.is_nan() {
            return f64::NAN;
        }
        max = max.max(v);
    }
    max
}

#[cfg(test)]
mod tests {
    use super::max_or_nan;

    #[test]
    fn a_nan_anywhere_is_the_maximum() {
        assert!(max_or_nan([1e-3, f64::NAN, 2e-3]).is_nan());
        assert!(max_or_nan([f64::NAN]).is_nan());
        assert_eq!(max_or_nan([1e-3, 5e-3, 2e-3]), 5e-3);
        assert_eq!(max_or_nan([f64::INFINITY, 1.0]), f64::INFINITY);
        assert_eq!(max_or_nan(std::iter::empty()), 0.0);
    }
}
