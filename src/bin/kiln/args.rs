//! Argument parsers shared by the subcommands: each rejects bad input with a message naming the
//! value and the allowed range (clap prints it on one line; the process exits with status 2).

use kiln::BakeOptions;

/// The conventions every table follows, printed after `--help`.
pub const CONVENTIONS: &str = "\
Conventions:
  mu         cos(theta) of the view direction, in [0, 1] (0 = grazing, 1 = normal incidence).
  roughness  either perceptual r with alpha = r^2 (Burley, Filament, Cycles; the default axis)
             or alpha itself (the slope-space width; Mitsuba). Every file says which.
  grid       'nodes' (bake's default): t = i / (N - 1), the first and last samples on the axis
             ends, so lookups interpolate all the way to mu = 0 and 1 and r = 0 and 1; a GPU
             lookup must remap t' = (t (N - 1) + 0.5) / N before sampling. 'centers': sample i
             sits at texel centre t = (i + 0.5) / N, sampled at raw t by a GPU, but the outer
             half texel on each side is clamped (errors up to 1e-2 at 32 x 32).
  mu axis    'adaptive' (bake's default): look up at t = (mu (1 + 4 alpha) / (mu + 4 alpha))^0.4
             (t = 0 at mu = 0, t = 1 at alpha = 0 and mu > 0). It keeps the grazing boundary
             layer mu ~ alpha at the same t for every roughness: 6.5e-4 max lookup error at
             32 x 32 against 1e-1 for 'linear' and 'sqrt'. The row alpha = 0 holds the limit
             alpha -> 0+ (computed at alpha = 1e-7). 'linear': mu = t. 'sqrt': mu = t^2 (look up
             at t = sqrt(mu)).
  layout     row-major, roughness rows (slow), mu columns (fast); as an image x = mu, y = roughness.
  E          directional albedo of the single-scattering BRDF with F = 1; E_avg = 2 ∫ E(mu) mu dmu.
             one_minus_E is stored beside E, estimated directly: use it when E is near 1,
             especially in half floats.";

/// A finite number.
pub fn parse_number(text: &str) -> Result<f64, String> {
    let value: f64 = text
        .trim()
        .parse()
        .map_err(|_| format!("'{text}' is not a number"))?;
    if value.is_finite() {
        Ok(value)
    } else {
        Err(format!("{text} is not a finite number"))
    }
}

/// `mu = cos(theta)` in [0, 1].
pub fn parse_mu(text: &str) -> Result<f64, String> {
    let mu = parse_number(text)?;
    if (0.0..=1.0).contains(&mu) {
        Ok(mu)
    } else {
        Err(format!(
            "mu is cos(theta) and must be in [0, 1] (got {text})"
        ))
    }
}

/// A roughness (`r` or `alpha`) in [0, 1000].
pub fn parse_roughness(text: &str) -> Result<f64, String> {
    let value = parse_number(text)?;
    if (0.0..=1e3).contains(&value) {
        Ok(value)
    } else {
        Err(format!("roughness must be in [0, 1000] (got {text})"))
    }
}

/// A table size per axis.
pub fn parse_size(text: &str) -> Result<usize, String> {
    let size: i64 = text
        .trim()
        .parse()
        .map_err(|_| format!("'{text}' is not a whole number"))?;
    if (2..=BakeOptions::MAX_SIZE as i64).contains(&size) {
        Ok(size as usize)
    } else {
        Err(format!(
            "size must be between 2 and {} (got {text})",
            BakeOptions::MAX_SIZE
        ))
    }
}

/// A QMC sample count: a power of two.
pub fn parse_samples(text: &str) -> Result<u64, String> {
    let n: i128 = text
        .trim()
        .parse()
        .map_err(|_| format!("'{text}' is not a whole number"))?;
    if (2..=1 << 42).contains(&n) && (n as u64).is_power_of_two() {
        Ok(n as u64)
    } else {
        Err(format!(
            "samples must be a power of two between 2 and 2^42 (got {text})"
        ))
    }
}

/// A positive, finite error bound.
pub fn parse_error_bound(text: &str) -> Result<f64, String> {
    let value = parse_number(text)?;
    if value > 0.0 {
        Ok(value)
    } else {
        Err(format!("an error bound must be positive (got {text})"))
    }
}
