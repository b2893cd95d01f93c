//! kiln's table of anisotropic GGX's albedo `E(mu, phi; r, a)` in an engine's convention
//! (issue 61), for Kulla-Conty's lobe and Turquin's scaling of an anisotropic lobe.
//!
//! # Why four axes
//!
//! An anisotropic lobe's albedo depends on the view's azimuth `phi` (from the tangent) as well
//! as on `mu`: at `alpha = (0.9, 0.1)` by up to 0.25 near grazing
//! (`kiln verify-anisotropy`), far beyond what one roughness can follow. Its
//! Fourier series in `phi` decays slowly there (`c_2 = 0.054`, `c_4 = -0.033`, `c_6 = 0.022` at
//! `mu = 0.02`), so the table samples the azimuth itself.
//!
//! # The axes (all node-centred: the first and last samples sit on the ends)
//!
//! - `a`: the anisotropy in the convention's terms, its samples uniform in
//!   [`AnisotropyConvention::anisotropy_coordinate`] (the logarithm of the aspect ratio) from 0
//!   to the table's largest.
//! - `r`: perceptual roughness `r_j = j / (N_r - 1)`, `alpha = r^2`, `(alpha_x, alpha_y)` from
//!   the convention ([`AnisotropyConvention::alphas`]). The row `r = 0` holds the smooth
//!   surface's limit profile, computed at [`SMOOTH_R`] (as `E` depends on `mu / alpha` alone
//!   there, as in the isotropic tables).
//! - `v`: the view's azimuth as a coordinate of its projected roughness `alpha_phi =
//!   sqrt(alpha_x^2 cos^2 phi + alpha_y^2 sin^2 phi)` (Heitz 2014, eq. 86): `v = ln(alpha_x /
//!   alpha_phi) / ln(alpha_x / alpha_y)`, 0 along the tangent, 1 along the bitangent; at
//!   `alpha_x = alpha_y`, its limit `sin^2 phi`. Measured against the plain azimuth at 17
//!   samples, linear lookups are 5 to 20 times closer in `v` at the strongest anisotropy.
//! - `t`: the view's cosine through kiln's adaptive mapping
//!   ([`crate::integrate::grazing::t_of_mu`]) at the view's own roughness `alpha_phi`, whose
//!   grazing layer `mu ~ alpha_phi` it follows.
//!
//! Values are stored `t` fastest, then `v`, `r`, `a`. A renderer computes `(t, v, r, a)` from
//! its lobe and view and interpolates linearly in each ([`AnisotropicTable::lookup`]).
//! `E_avg(r, a)` (over `mu` and `phi`, for Kulla-Conty's normalisation) is stored beside it.

use crate::integrate::anisotropic::reference_anisotropic_albedo;
use crate::integrate::grazing::{mu_of_t, t_of_mu};
use crate::integrate::reference::ReferenceSettings;
use crate::model::{AnisotropicGgx, AnisotropyConvention};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// The perceptual roughness at which the row `r = 0` is computed: `alpha = 1e-6`, where `E`'s
/// dependence on anything but `mu / alpha_phi` is below 1e-11.
pub const SMOOTH_R: f64 = 1e-3;

/// The number of samples on each axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct AnisotropicSizes {
    pub mu: usize,
    pub azimuth: usize,
    pub roughness: usize,
    pub anisotropy: usize,
}

impl AnisotropicSizes {
    /// kiln's default: 32 view cosines, 16 azimuths, 32 roughness values, 16 anisotropies.
    pub const DEFAULT: Self = Self {
        mu: 32,
        azimuth: 16,
        roughness: 32,
        anisotropy: 16,
    };

    /// The number of texels.
    #[must_use]
    pub fn len(&self) -> usize {
        self.mu * self.azimuth * self.roughness * self.anisotropy
    }

    /// The estimated cost of baking a table of these sizes at the default tolerance, in seconds
    /// of one core: 3e-4 a texel (the 32 x 16 x 32 x 16 table in 40 s on two cores, 2026-12-07).
    #[must_use]
    pub fn core_seconds(&self) -> f64 {
        self.len() as f64 * 3.0e-4
    }

    /// Whether the table holds nothing (never, once checked).
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Every axis 2 to 256 samples.
    pub fn check(&self) -> crate::Result<()> {
        for (axis, n) in [
            ("mu", self.mu),
            ("azimuth", self.azimuth),
            ("roughness", self.roughness),
            ("anisotropy", self.anisotropy),
        ] {
            if !(2..=256).contains(&n) {
                return Err(crate::Error::InvalidInput(format!(
                    "the {axis} axis has {n} samples; give 2 to 256"
                )));
            }
        }
        Ok(())
    }
}

/// The view's azimuth coordinate `v` of `phi` on a lobe (module docs).
#[must_use]
pub fn azimuth_coordinate(alpha_x: f64, alpha_y: f64, phi: f64) -> f64 {
    let (s, c) = phi.sin_cos();
    let (s2, c2) = (s * s, c * c);
    let ratio = alpha_x / alpha_y;
    if (ratio - 1.0).abs() < 1e-9 {
        return s2;
    }
    let alpha_phi = (alpha_x * alpha_x * c2 + alpha_y * alpha_y * s2).sqrt();
    ((alpha_x / alpha_phi).ln() / ratio.ln()).clamp(0.0, 1.0)
}

/// The azimuth in `[0, pi/2]` at coordinate `v` (the inverse of [`azimuth_coordinate`]) and the
/// view's projected roughness there, `alpha_x^(1 - v) alpha_y^v`.
#[must_use]
pub fn azimuth_at(alpha_x: f64, alpha_y: f64, v: f64) -> (f64, f64) {
    let ratio = alpha_x / alpha_y;
    if (ratio - 1.0).abs() < 1e-9 {
        return (v.sqrt().asin(), alpha_x);
    }
    let alpha_phi = alpha_x * (alpha_y / alpha_x).powf(v);
    let s2 = (alpha_x * alpha_x - alpha_phi * alpha_phi) / (alpha_x * alpha_x - alpha_y * alpha_y);
    (s2.clamp(0.0, 1.0).sqrt().asin(), alpha_phi)
}

/// The view's projected roughness `alpha_phi` at azimuth `phi` (Heitz 2014, eq. 86).
#[must_use]
pub fn projected_roughness(alpha_x: f64, alpha_y: f64, phi: f64) -> f64 {
    let (s, c) = phi.sin_cos();
    ((alpha_x * c).powi(2) + (alpha_y * s).powi(2)).sqrt()
}

/// The white furnace of a table measured between its samples
/// (`crate::verify::anisotropic_table`), as its file states it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MeasuredFurnace {
    /// Points between the samples, drawn uniformly in `r`, `a`, `mu` and the azimuth.
    pub points: usize,
    pub max_lookup_error: f64,
    /// `max |E / E_lookup - 1|`.
    pub max_turquin: f64,
    /// `max |E + Kulla-Conty's added energy - 1|`.
    pub max_kulla_conty: f64,
}

/// kiln's anisotropic albedo table (module docs).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AnisotropicTable {
    pub convention: AnisotropyConvention,
    /// The largest anisotropy (the last sample of the `a` axis).
    pub max_anisotropy: f64,
    pub sizes: AnisotropicSizes,
    /// `E` per texel, `t` fastest, then `v`, `r`, `a`.
    pub values: Vec<f64>,
    /// The largest of the reference's error estimates over the texels.
    pub max_error: f64,
    /// `E_avg(r, a)`, `r` fastest: the average of the lookup over `mu` and the azimuth.
    pub average: Vec<f64>,
    /// The reference's tolerance.
    pub tolerance: f64,
}

impl AnisotropicTable {
    /// `(anisotropy, r, alpha_x, alpha_y)` of the lobe at samples `(l, j)`; the row `r = 0` is
    /// computed at [`SMOOTH_R`].
    #[must_use]
    pub fn lobe(
        convention: AnisotropyConvention,
        max_anisotropy: f64,
        sizes: &AnisotropicSizes,
        l: usize,
        j: usize,
    ) -> (f64, f64, AnisotropicGgx) {
        let w = l as f64 / (sizes.anisotropy - 1) as f64;
        let a = convention.anisotropy_at(w, max_anisotropy);
        let r = (j as f64 / (sizes.roughness - 1) as f64).max(SMOOTH_R);
        let (alpha_x, alpha_y) = convention.alphas(r * r, a);
        (a, r, AnisotropicGgx { alpha_x, alpha_y })
    }

    /// Computes every texel by the reference quadrature at `tolerance`
    /// ([`reference_anisotropic_albedo`]; its estimates are pessimistic: at 1e-3 the largest
    /// error measured against 1e-11 at 192 points of `r`, `a`, `mu` and `phi` was 1.9e-5, while
    /// designing, 2026-12-07), and each `E_avg` as the average
    /// of the table's own lookup over `mu` and the azimuth ([`slice_average`]), so that
    /// Kulla-Conty's lobe normalised by it adds back exactly `1 - E_lookup`. The same bytes on
    /// any number of threads. `progress` hears the number of `(r, a)` rows done.
    ///
    /// # Errors
    /// Sizes or an anisotropy the convention refuses, or a tolerance outside `[1e-10, 1e-2]`.
    pub fn bake(
        convention: AnisotropyConvention,
        max_anisotropy: f64,
        sizes: AnisotropicSizes,
        tolerance: f64,
        progress: &(dyn Fn(u64) + Sync),
    ) -> crate::Result<Self> {
        sizes.check()?;
        convention.check_anisotropy(max_anisotropy)?;
        check_tolerance(tolerance)?;
        let settings = ReferenceSettings {
            tolerance,
            ..ReferenceSettings::default()
        };
        let done = std::sync::atomic::AtomicU64::new(0);
        let rows: Vec<(Vec<(f64, f64)>, f64)> = (0..sizes.anisotropy * sizes.roughness)
            .into_par_iter()
            .map(|row| {
                let (l, j) = (row / sizes.roughness, row % sizes.roughness);
                let (_, _, ndf) = Self::lobe(convention, max_anisotropy, &sizes, l, j);
                let mut texels = Vec::with_capacity(sizes.mu * sizes.azimuth);
                for k in 0..sizes.azimuth {
                    let v = k as f64 / (sizes.azimuth - 1) as f64;
                    let (phi, alpha_phi) = azimuth_at(ndf.alpha_x, ndf.alpha_y, v);
                    for i in 0..sizes.mu {
                        let t = i as f64 / (sizes.mu - 1) as f64;
                        let mu = mu_of_t(t, alpha_phi).clamp(0.0, 1.0);
                        let e = reference_anisotropic_albedo(ndf, mu, phi, &settings);
                        texels.push((e.value, e.error));
                    }
                }
                let values: Vec<f64> = texels.iter().map(|p| p.0).collect();
                let average = slice_average(&values, ndf, &sizes);
                progress(done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1);
                (texels, average)
            })
            .collect();
        let values = rows
            .iter()
            .flat_map(|(t, _)| t.iter().map(|p| p.0))
            .collect();
        let max_error =
            crate::stats::max_or_nan(rows.iter().flat_map(|(t, _)| t.iter().map(|p| p.1)));
        let average = rows.iter().map(|(_, a)| *a).collect();
        Ok(Self {
            convention,
            max_anisotropy,
            sizes,
            values,
            max_error,
            average,
            tolerance,
        })
    }

    /// The texture coordinates `(t, v, r, a / max)` of a lookup, each clamped to `[0, 1]`.
    #[must_use]
    pub fn coordinates(&self, mu: f64, phi: f64, r: f64, a: f64) -> [f64; 4] {
        let (alpha_x, alpha_y) = self.convention.alphas(r.max(SMOOTH_R).powi(2), a);
        let v = azimuth_coordinate(alpha_x, alpha_y, phi);
        let t = t_of_mu(mu, projected_roughness(alpha_x, alpha_y, phi));
        [
            t,
            v,
            r,
            self.convention
                .anisotropy_coordinate(a, self.max_anisotropy),
        ]
        .map(|c| c.clamp(0.0, 1.0))
    }

    /// `E` as a renderer reads it: linear in each of the four coordinates
    /// ([`AnisotropicTable::coordinates`]), clamped to the edges.
    #[must_use]
    pub fn lookup(&self, mu: f64, phi: f64, r: f64, a: f64) -> f64 {
        let c = self.coordinates(mu, phi, r, a);
        let s = &self.sizes;
        let sizes = [s.mu, s.azimuth, s.roughness, s.anisotropy];
        let mut base = [0usize; 4];
        let mut frac = [0.0; 4];
        for d in 0..4 {
            (base[d], frac[d]) = cell(c[d], sizes[d]);
        }
        let mut value = 0.0;
        for corner in 0..16usize {
            let mut weight = 1.0;
            let mut index = 0;
            let mut stride = 1;
            for d in 0..4 {
                let up = (corner >> d) & 1;
                weight *= if up == 1 { frac[d] } else { 1.0 - frac[d] };
                index += (base[d] + up) * stride;
                stride *= sizes[d];
            }
            if weight != 0.0 {
                value += weight * self.values[index];
            }
        }
        value
    }

    /// `E_avg` at `(r, a)`: `1 - E_avg = alpha^2 c(r, w)` with `c = (1 - E_avg) / alpha^2` read
    /// linearly in `r` and the anisotropy's coordinate `w` (`alpha = r^2`, the row `r = 0`
    /// standing at [`SMOOTH_R`]).
    ///
    /// Why: Kulla-Conty's lobe adds back exactly `1 - E_lookup` where `E_avg` is the average
    /// of the lookup itself, and between rows that average is not linear in `r`. Near the mirror
    /// the lookup's `mu` scales with `alpha` at a fixed `t` (the adaptive mapping is `mu ~ 4
    /// alpha_phi t^2.5 / (1 - t^2.5)` there), so the average of a row's values read at another
    /// roughness is `alpha^2` times a constant of the row, and the average of the interpolated
    /// lookup is `alpha^2` times the interpolated constants: this reading. Read linearly in
    /// `E_avg`, the ratio of `1 - A` to `1 - E_avg` was 0.75 at `r = 0.045` (32 roughness
    /// samples, a furnace 1.9e-2 off), read in `ln(1 - E_avg)` against `ln r` 1.06 (4.7e-3;
    /// both measured while designing, 2026-12-07).
    #[must_use]
    pub fn lookup_average(&self, r: f64, a: f64) -> f64 {
        let s = &self.sizes;
        let (j, fr) = cell(r, s.roughness);
        let (l, fa) = cell(
            self.convention
                .anisotropy_coordinate(a, self.max_anisotropy),
            s.anisotropy,
        );
        let alpha2 = |r: f64| r.max(SMOOTH_R).powi(4);
        let node_r = |j: usize| j as f64 / (s.roughness - 1) as f64;
        let at = |l: usize, j: usize| (1.0 - self.average[l * s.roughness + j]) / alpha2(node_r(j));
        let c = (1.0 - fa) * ((1.0 - fr) * at(l, j) + fr * at(l, j + 1))
            + fa * ((1.0 - fr) * at(l + 1, j) + fr * at(l + 1, j + 1));
        1.0 - alpha2(r) * c
    }

    /// The largest error estimate over the texels.
    #[must_use]
    pub fn max_node_error(&self) -> f64 {
        self.max_error
    }

    /// Checks a table read from a file: sizes, the anisotropy in the convention's range, every
    /// channel as long as the sizes say, every value in `[0, 1]`, the error estimate finite and
    /// not negative.
    ///
    /// # Errors
    /// A sentence naming what does not fit.
    pub fn check(&self) -> crate::Result<()> {
        self.sizes.check()?;
        self.convention.check_anisotropy(self.max_anisotropy)?;
        if !(self.max_error >= 0.0 && self.max_error.is_finite()) {
            return Err(crate::Error::Malformed(format!(
                "max_error {} is not a finite number >= 0",
                self.max_error
            )));
        }
        let n = self.sizes.len();
        let rows = self.sizes.roughness * self.sizes.anisotropy;
        for (what, values, len) in [
            ("values", &self.values, n),
            ("average", &self.average, rows),
        ] {
            if values.len() != len {
                return Err(crate::Error::Malformed(format!(
                    "{what} holds {} numbers for {len}",
                    values.len()
                )));
            }
            if let Some(k) = values.iter().position(|v| !(0.0..=1.0).contains(v)) {
                return Err(crate::Error::Malformed(format!(
                    "{what} at {k} is {}, outside [0, 1]",
                    values[k]
                )));
            }
        }
        Ok(())
    }
}

/// Checks a bake's reference tolerance: in `[1e-10, 1e-2]`.
pub fn check_tolerance(tolerance: f64) -> crate::Result<()> {
    if (1e-10..=1e-2).contains(&tolerance) {
        Ok(())
    } else {
        Err(crate::Error::InvalidInput(format!(
            "tolerance {tolerance:e} is outside [1e-10, 1e-2]"
        )))
    }
}

/// The cell of coordinate `c` (clamped to `[0, 1]`) on an axis of `n >= 2` node-centred samples:
/// the lower sample's index and the fraction of the way to the next.
fn cell(c: f64, n: usize) -> (usize, f64) {
    let x = c.clamp(0.0, 1.0) * (n - 1) as f64;
    let base = (x.floor() as usize).min(n - 2);
    (base, x - base as f64)
}

/// `E_avg = (2 / pi) ∫_0^{pi/2} ∫_0^1 2 mu E(mu, phi) dmu dphi` of a function `e(mu, phi)`
/// that is linear in the table's coordinates `t` and `v` between their samples (a lookup of the
/// lobe `(alpha_x, alpha_y)` on axes of `n_t` and `n_v` samples), by Gauss-Legendre rules on
/// the pieces between samples, where it is smooth: 8 azimuths between the azimuths of
/// consecutive `v` samples (the rule runs in `phi`: `phi(v)` has infinite slopes at the ends),
/// 4 points between the `mu` of consecutive `t` samples.
#[must_use]
pub fn hemisphere_average(
    e: impl Fn(f64, f64) -> f64,
    alpha_x: f64,
    alpha_y: f64,
    n_t: usize,
    n_v: usize,
) -> f64 {
    use crate::numerics::gauss_legendre::rule;
    let rule_phi = rule(8);
    let rule_t = rule(4);
    let phi_of = |k: usize| azimuth_at(alpha_x, alpha_y, k as f64 / (n_v - 1) as f64).0;
    let mut total = 0.0;
    for k in 0..n_v - 1 {
        let (phi_a, phi_b) = (phi_of(k), phi_of(k + 1));
        for &(x, w) in &rule_phi {
            let phi = 0.5 * (phi_a + phi_b) + 0.5 * (phi_b - phi_a) * x;
            let alpha_phi = projected_roughness(alpha_x, alpha_y, phi);
            let mut inner = 0.0;
            for i in 0..n_t - 1 {
                let (mu_a, mu_b) = (
                    mu_of_t(i as f64 / (n_t - 1) as f64, alpha_phi),
                    mu_of_t((i + 1) as f64 / (n_t - 1) as f64, alpha_phi),
                );
                for &(y, u) in &rule_t {
                    let mu = 0.5 * (mu_a + mu_b) + 0.5 * (mu_b - mu_a) * y;
                    inner += 0.5 * (mu_b - mu_a) * u * 2.0 * mu * e(mu, phi);
                }
            }
            total += 0.5 * (phi_b - phi_a) * w * inner;
        }
    }
    total * 2.0 / std::f64::consts::PI
}

/// [`hemisphere_average`] of one `(r, a)` slice of the table (`values`: `t` fastest, then `v`),
/// read linearly in `t` and `v` as the lookup reads it.
#[must_use]
pub fn slice_average(values: &[f64], ndf: AnisotropicGgx, sizes: &AnisotropicSizes) -> f64 {
    let (n_t, n_v) = (sizes.mu, sizes.azimuth);
    let (alpha_x, alpha_y) = (ndf.alpha_x, ndf.alpha_y);
    let e = |mu: f64, phi: f64| {
        let (i, s) = cell(t_of_mu(mu, projected_roughness(alpha_x, alpha_y, phi)), n_t);
        let (k, f) = cell(azimuth_coordinate(alpha_x, alpha_y, phi), n_v);
        let at = |i: usize, k: usize| values[k * n_t + i];
        let row = |k: usize| (1.0 - s) * at(i, k) + s * at(i + 1, k);
        (1.0 - f) * row(k) + f * row(k + 1)
    };
    hemisphere_average(e, alpha_x, alpha_y, n_t, n_v)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::QmcSettings;
    use crate::integrate::anisotropic::anisotropic_average_albedo;
    use std::f64::consts::FRAC_PI_2;

    /// `v` is 0 along the tangent and 1 along the bitangent, [`azimuth_at`] inverts it, and it
    /// tends to `sin^2 phi` as the lobe turns isotropic (no jump at `alpha_x = alpha_y`).
    #[test]
    fn the_azimuth_coordinate_spans_the_quarter_and_inverts() {
        for (ax, ay) in [(0.9, 0.1), (0.05, 0.0025), (0.3, 0.3)] {
            assert_eq!(azimuth_coordinate(ax, ay, 0.0), 0.0);
            assert!((azimuth_coordinate(ax, ay, FRAC_PI_2) - 1.0).abs() < 1e-12);
            for v in [0.1, 0.5, 0.93] {
                let (phi, alpha_phi) = azimuth_at(ax, ay, v);
                assert!(
                    (azimuth_coordinate(ax, ay, phi) - v).abs() < 1e-9,
                    "{ax} {ay} {v}"
                );
                assert!((projected_roughness(ax, ay, phi) - alpha_phi).abs() < 1e-12);
            }
        }
        let phi = 0.7f64;
        let near = azimuth_coordinate(0.3 * (1.0 + 1e-7), 0.3, phi);
        assert!((near - phi.sin().powi(2)).abs() < 1e-6, "{near}");
    }

    /// A small table: its lookup at a sample is the sample; its `E_avg` (the average of its
    /// own lookup, [`slice_average`]) is what a second quadrature of the lookup gives
    /// (`crate::verify::anisotropic_table::lookup_average`), and within the lookup's error of
    /// the lobe's average estimated by QMC (an estimator of its own).
    #[test]
    fn a_table_reads_its_samples_and_averages_its_lookup() {
        let sizes = AnisotropicSizes {
            mu: 24,
            azimuth: 6,
            roughness: 4,
            anisotropy: 3,
        };
        let convention = AnisotropyConvention::KullaConty;
        let table = AnisotropicTable::bake(convention, 0.8, sizes, 1e-3, &|_| {}).unwrap();
        table.check().unwrap();
        for (l, j) in [(1, 2), (2, 3)] {
            let (a, r, ndf) = AnisotropicTable::lobe(convention, 0.8, &sizes, l, j);
            let (phi, alpha_phi) = azimuth_at(ndf.alpha_x, ndf.alpha_y, 0.4);
            let mu = mu_of_t(10.0 / 23.0, alpha_phi);
            let k = ((l * sizes.roughness + j) * sizes.azimuth + 2) * sizes.mu + 10;
            assert!((table.lookup(mu, phi, r, a) - table.values[k]).abs() < 1e-9);
            let stored = table.average[l * sizes.roughness + j];
            assert!((table.lookup_average(r, a) - stored).abs() < 1e-12);
            let again = crate::verify::anisotropic_table::lookup_average(&table, r, a);
            assert!((again - stored).abs() < 2e-4, "{again} vs {stored}");
            let qmc = anisotropic_average_albedo(
                ndf,
                &QmcSettings {
                    samples: 1 << 20,
                    ..QmcSettings::default()
                },
            );
            assert!((qmc.value - stored).abs() < 3e-3, "{qmc:?} vs {stored}");
        }
    }
}
