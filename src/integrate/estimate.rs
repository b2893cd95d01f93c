//! Combining independent replicates into an estimate with a standard error.

use serde::Serialize;

/// An estimate of an albedo-like quantity `E` in [0, 1], carried as `1 - E` (the energy lost),
/// which keeps its relative precision when `E` is close to 1.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Estimate {
    /// `E`.
    pub value: f64,
    /// `1 - E`, estimated directly (not by subtracting a rounded `E` from 1).
    pub one_minus_value: f64,
    /// The standard error of either.
    pub std_error: f64,
    /// Integrand evaluations spent.
    pub samples: u64,
}

impl Estimate {
    /// An exactly known value (a limit the integrator does not need to sample).
    #[must_use]
    pub fn exact(one_minus_value: f64) -> Self {
        Self {
            value: 1.0 - one_minus_value,
            one_minus_value,
            std_error: 0.0,
            samples: 0,
        }
    }

    /// The mean of `R >= 2` independent replicate means of `1 - E`, with the standard error
    /// `sqrt(Σ (I_r - Ī)^2 / (R (R - 1)))` (docs/physics.md): the spread between independent scrambles,
    /// never the spread inside one sequence, which QMC makes meaningless.
    #[must_use]
    pub fn from_replicates(one_minus_means: &[f64], samples: u64) -> Self {
        assert!(
            one_minus_means.len() >= 2,
            "need at least two replicates for an error estimate"
        );
        let (mean, std_error) = mean_and_std_error(one_minus_means);
        // A mean outside [0, 1] (possible only for an estimator with negative or > 1 weights)
        // is brought into the range, and the standard error widened by the distance: never a
        // clamp that hides a bias.
        let one_minus_value = mean.clamp(0.0, 1.0);
        Self {
            value: 1.0 - one_minus_value,
            one_minus_value,
            std_error: std_error + (mean - one_minus_value).abs(),
            samples,
        }
    }
}

/// The mean of `R >= 2` independent replicate means and its standard error,
/// `sqrt(Σ (I_r - Ī)^2 / (R (R - 1)))`.
#[must_use]
pub fn mean_and_std_error(means: &[f64]) -> (f64, f64) {
    let r = means.len() as f64;
    let mean = means.iter().sum::<f64>() / r;
    let var = means.iter().map(|&x| (x - mean) * (x - mean)).sum::<f64>();
    (mean, (var / (r * (r - 1.0))).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn replicate_statistics() {
        let e = Estimate::from_replicates(&[0.1, 0.2, 0.3, 0.4], 64);
        assert!((e.one_minus_value - 0.25).abs() < 1e-15);
        assert!((e.value - 0.75).abs() < 1e-15);
        // Sample variance 1/60 * 5 ... : Σ (x - 0.25)^2 = 0.05, / (4 * 3) -> sqrt(0.05 / 12).
        assert!((e.std_error - (0.05f64 / 12.0).sqrt()).abs() < 1e-15);
    }

    #[test]
    fn a_mean_outside_the_range_widens_the_error() {
        let e = Estimate::from_replicates(&[-2e-6, -1e-6, -3e-6, -2e-6], 64);
        assert_eq!(e.one_minus_value, 0.0);
        assert!(e.std_error >= 2e-6, "{e:?}");
    }
}
