//! Argument parsers shared by the subcommands: each rejects bad input with a message naming the
//! value and the allowed range (clap prints it on one line; the process exits with status 2).

use kiln::BakeOptions;

/// Where a subcommand's help sends the reader for the conventions (printed once, by `kiln
/// --help`, rather than after every subcommand's help).
pub const SEE_CONVENTIONS: &str =
    "Conventions (mu, roughness r or alpha, nodes or centres, the mu axes, layout): kiln --help";

/// The conventions every table follows, printed after `kiln --help`.
pub const CONVENTIONS: &str = "\
Conventions:
  mu         cos(theta) of the view direction, in [0, 1] (0 = grazing, 1 = normal incidence).
  roughness  either perceptual r with alpha = r^2 (Burley, Filament, Cycles; the default axis)
             or alpha itself (the slope-space width; Mitsuba). Every file says which.
  grid       'nodes' (bake's default): t = i / (N - 1), the first and last samples on the axis
             ends, so lookups interpolate all the way to mu = 0 and 1 and r = 0 and 1; a GPU
             lookup must remap t' = (t (N - 1) + 0.5) / N before sampling. 'centers': sample i
             sits at texel centre t = (i + 0.5) / N, sampled at raw t by a GPU, but the outer
             half texel on each side is clamped: at 32 x 32 the lookup error reaches 2.5e-2
             there (E, adaptive mu axis; 1.4e-2 for E_avg), against 6.5e-4 on nodes.
  mu axis    kiln's axis for each quantity unless --mu-axis names one. 'balanced' (E, E_avg,
             f_ms_norm; with balanced rows): the grazing boundary layer mu ~ alpha at the same t
             for every roughness, and more texels near mu = 1 at moderate roughness (the
             metadata and the generated lookups give its formula). 'split-sum' (e-scale,
             e-bias, e-f, which vary with mu on a mirror). 'adaptive': t = (mu (1 + 4 alpha) /
             (mu + 4 alpha))^0.4 (t = 0 at mu = 0, t = 1 at alpha = 0 and mu > 0): 6.5e-4 max
             lookup error at 32 x 32 against 1e-1 for 'linear' (mu = t) and 'sqrt' (mu = t^2).
             The row alpha = 0 holds the limit alpha -> 0+ (computed at alpha = 1e-7).
  texels     'lookup-fit' (bake's default on the balanced axis): chosen so that the bilinear
             lookup is closest to the truth everywhere (2.1e-4 at 32 x 32 for E), the nodes off
             by about as much; 'nodes': each texel the quantity at its node.
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

/// A finite number in `[lo, hi]`; the message says what the number is (`what`).
fn parse_in(text: &str, lo: f64, hi: f64, what: &str) -> Result<f64, String> {
    let value = parse_number(text)?;
    if (lo..=hi).contains(&value) {
        Ok(value)
    } else {
        Err(format!("{what} must be in [{lo}, {hi}] (got {text})"))
    }
}

/// `mu = cos(theta)` in [0, 1].
pub fn parse_mu(text: &str) -> Result<f64, String> {
    parse_in(text, 0.0, 1.0, "mu is cos(theta) and")
}

/// A perceptual roughness `r` in [0, 1].
pub fn parse_roughness(text: &str) -> Result<f64, String> {
    // The range of every table and scene; rougher surfaces by --alpha (alpha = r^2 > 1).
    parse_in(text, 0.0, 1.0, "perceptual roughness r").map_err(|e| {
        format!("{e} (tables and scenes span r in [0, 1]; for alpha above 1 give --alpha)")
    })
}

/// A slope-space roughness `alpha` in [0, 1000].
pub fn parse_alpha(text: &str) -> Result<f64, String> {
    parse_in(text, 0.0, 1e3, "alpha (slope-space roughness)")
}

/// The names of the flags given, from `(name, given)` pairs: for errors that list them.
pub fn given<'a>(flags: &[(&'a str, bool)]) -> Vec<&'a str> {
    flags
        .iter()
        .filter_map(|&(flag, given)| given.then_some(flag))
        .collect()
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

/// A QMC sample count: a power of two. Its range depends on `--scrambles`
/// (`QmcSettings::validate` checks it and names the flag).
pub fn parse_samples(text: &str) -> Result<u64, String> {
    let trimmed = text.trim();
    // `65536` or `2^16`.
    let n: i128 = match trimmed.split_once('^') {
        Some(("2", power)) => match power.trim().parse::<u32>() {
            Ok(k) if k <= 62 => 1 << k,
            _ => return Err(format!("'{text}' is not a power of two up to 2^62")),
        },
        _ => trimmed
            .parse()
            .map_err(|_| format!("'{text}' is not a whole number (or 2^k)"))?,
    };
    if (1..=1 << 62).contains(&n) && (n as u64).is_power_of_two() {
        Ok(n as u64)
    } else {
        Err(format!(
            "must be a power of two (e.g. 65536 = 2^16), from --scrambles to 2^32 times \
             --scrambles (got {text})"
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

/// `--clamp-min`: the smallest coordinate a table was computed at, in [0, 1).
pub fn parse_clamp(text: &str) -> Result<f64, String> {
    let value = parse_number(text)?;
    if (0.0..1.0).contains(&value) {
        Ok(value)
    } else {
        Err(format!("clamp-min must be in [0, 1) (got {text})"))
    }
}
