//! Microfacet normal distributions: GGX (Trowbridge-Reitz) and Beckmann, isotropic.
//!
//! Each distribution is a small type whose methods carry the formulas' book names (`d`, `lambda`,
//! `g1`, `sample_visible_normal`), in the manner of pbrt-v4's `TrowbridgeReitzDistribution`.
//! Roughness is always `alpha` here (the slope-space width); the perceptual `r` with
//! `alpha = r^2` is converted at the edges (see `crate::Roughness`).
//!
//! Sources: Walter et al. 2007, "Microfacet Models for Refraction through Rough Surfaces" (D and
//! Lambda of both distributions); Heitz 2014, "Understanding the Masking-Shadowing Function in
//! Microfacet-Based BRDFs" (Smith Lambda, G1, G2); `docs/physics.md` for the stable forms.

pub use super::beckmann_sampling::{
    BeckmannVisibleNormals, VisibleSlopeX, beckmann_visible_slope_x,
};
use super::special::{FRAC_1_SQRT_PI, beckmann_lambda_of_a};
use super::vector::Vec3;
use crate::numerics::elementary::exp_lane;
use std::f64::consts::PI;

/// A microfacet normal distribution of fixed `alpha`, with its Smith masking and its visible-normal
/// sampling. Directions are unit vectors in the shading frame (normal `+z`).
pub trait MicrofacetDistribution: Copy + Send + Sync {
    /// The slope-space roughness `alpha` (not the perceptual `r`).
    fn alpha(&self) -> f64;

    /// The normal distribution `D(m)` given `cos_theta_m = m.z > 0`, normalised so that
    /// `∫ D(m) cos(theta_m) dω_m = 1`.
    fn d(&self, cos_theta_m: f64) -> f64;

    /// Smith's `Lambda` for a direction with the given `tan^2(theta)` (`+inf` on the horizon).
    fn lambda_from_tan2(&self, tan2_theta: f64) -> f64;

    /// [`MicrofacetDistribution::lambda_from_tan2`] at several directions at once, the same
    /// value for each, in a loop that vectorises where the distribution's form allows.
    #[inline(always)]
    fn lambdas_from_tan2<const L: usize>(&self, tan2_theta: &[f64; L]) -> [f64; L] {
        tan2_theta.map(|tan2| self.lambda_from_tan2(tan2))
    }

    /// Smith's `Lambda` of unit directions given `x^2 + y^2` and `z > 0` (infinite at `z = 0`;
    /// what it gives below the horizon is not meant to be used), at several at once. The
    /// default divides for `tan^2 = (x^2 + y^2) / z^2` and calls
    /// [`MicrofacetDistribution::lambdas_from_tan2`].
    #[inline(always)]
    fn lambdas_of_directions<const L: usize>(&self, xy2: &[f64; L], z: &[f64; L]) -> [f64; L] {
        let mut tan2 = [0.0; L];
        for k in 0..L {
            tan2[k] = xy2[k] / (z[k] * z[k]);
        }
        self.lambdas_from_tan2(&tan2)
    }

    /// The normals at nodes of the reference quadrature's logistic variable
    /// `s = t / (alpha + t)`, `t = tan(theta_m)` (`crate::integrate::reference`): their polar
    /// angle and the density of normals per unit `s` and azimuth, `D(m) sin^2 cos dx/ds` with
    /// `x = ln(t / alpha)`, `dx/ds = 1 / (s (1 - s))` (`dω_m = sin^2 cos dx dphi`), in closed
    /// forms with few divisions, in a loop that vectorises. The density is finite at both ends
    /// of `s` (0 at `s = 0`) and never NaN.
    fn polar_lanes_in_s<const L: usize>(&self, s: &[f64; L]) -> Polar<L>;

    /// As [`MicrofacetDistribution::polar_lanes_in_s`] at nodes of `x = ln(t / alpha)` itself,
    /// given `e^x` at each (`dx/dx = 1`; `e^x` up to `1e60`).
    fn polar_lanes_in_x<const L: usize>(&self, exp_x: &[f64; L]) -> Polar<L>;

    /// Smith's `Lambda(v)`, with `tan^2(theta)` taken from the components of `v`.
    #[inline(always)]
    fn lambda(&self, v: Vec3) -> f64 {
        self.lambda_from_tan2(v.tan2_theta())
    }

    /// `D(m)` given `tan^2(theta_m)`, with `cos^4 = 1 / (1 + tan^2)^2`: no cancellation near the
    /// normal, where `1 - cos^2` would lose the digits that a small `alpha` needs.
    fn d_from_tan2(&self, tan2_theta_m: f64) -> f64;

    /// The projected area of the microsurface seen from a direction with `cos(theta) = mu`,
    /// `mu (1 + Lambda) = ∫ (v.m)+ D(m) dω_m` (Heitz 2014, eq. 11), in a form that stays exact as
    /// `mu -> 0` (where `mu` goes to 0 and `Lambda` to infinity).
    fn projected_area(&self, mu: f64) -> f64;

    /// Smith masking `G1(v) = 1 / (1 + Lambda(v))` (Heitz 2014, eq. 43).
    fn g1(&self, v: Vec3) -> f64 {
        1.0 / (1.0 + self.lambda(v))
    }

    /// Samples a microfacet normal from the distribution of normals visible from `o`, density
    /// `G1(o) max(0, o.m) D(m) / o.z` (Heitz 2014, eq. 2). `u` is a point of the unit square.
    fn sample_visible_normal(&self, o: Vec3, u: [f64; 2]) -> Vec3;
}

/// Microfacet normals at several nodes of a quadrature over `tan(theta_m)`: each one's
/// `sin(theta_m)`, `cos(theta_m)` and the density of normals per unit of the node's variable and
/// of azimuth ([`MicrofacetDistribution::polar_lanes_in_s`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Polar<const L: usize> {
    pub sin: [f64; L],
    pub cos: [f64; L],
    pub density: [f64; L],
}

impl<const L: usize> Default for Polar<L> {
    fn default() -> Self {
        Self {
            sin: [0.0; L],
            cos: [1.0; L],
            density: [0.0; L],
        }
    }
}

/// GGX / Trowbridge-Reitz.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ggx {
    pub alpha: f64,
}

impl MicrofacetDistribution for Ggx {
    fn alpha(&self) -> f64 {
        self.alpha
    }

    /// `D = alpha^2 / (pi (1 + (alpha^2 - 1) c^2)^2)` (Walter 2007, eq. 33, rewritten in `c`),
    /// with `1 + (alpha^2 - 1) c^2` summed as `(1 - c)(1 + c) + alpha^2 c^2`: the plain form
    /// cancels to 0 at `c = 1` once `alpha^2` is below f64's epsilon.
    fn d(&self, cos_theta_m: f64) -> f64 {
        let a2 = self.alpha * self.alpha;
        let c = cos_theta_m;
        let t = (1.0 - c) * (1.0 + c) + a2 * c * c;
        a2 / (PI * t * t)
    }

    /// `D = alpha^2 (1 + t^2)^2 / (pi (alpha^2 + t^2)^2)`, `t^2 = tan^2(theta_m)`.
    fn d_from_tan2(&self, tan2: f64) -> f64 {
        let a2 = self.alpha * self.alpha;
        let ratio = (1.0 + tan2) / (a2 + tan2);
        a2 * ratio * ratio / PI
    }

    /// `mu (1 + Lambda) = (mu + sqrt(mu^2 + alpha^2 (1 - mu^2))) / 2`; a mirror's is `mu`, also
    /// where `mu^2` underflows (`mu < 1e-154`, where the formula would give `mu / 2`).
    fn projected_area(&self, mu: f64) -> f64 {
        if self.alpha == 0.0 {
            return mu;
        }
        let so2 = (1.0 - mu) * (1.0 + mu);
        0.5 * (mu + (mu * mu + self.alpha * self.alpha * so2).sqrt())
    }

    /// `Lambda = (sqrt(1 + x) - 1) / 2` with `x = alpha^2 tan^2(theta)` (Heitz 2014, eq. 72),
    /// evaluated as `x / (2 (1 + sqrt(1 + x)))`, which does not cancel for small `x`.
    /// Always inlined: the vectorised `E_avg` kernel evaluates it per sample.
    #[inline(always)]
    fn lambda_from_tan2(&self, tan2_theta: f64) -> f64 {
        if self.alpha == 0.0 {
            return 0.0;
        }
        let x = self.alpha * self.alpha * tan2_theta;
        if x.is_infinite() {
            return f64::INFINITY;
        }
        x / (2.0 * (1.0 + (1.0 + x).sqrt()))
    }

    /// `Lambda = alpha^2 (x^2 + y^2) / (2 (z^2 + z sqrt(z^2 + alpha^2 (x^2 + y^2))))`:
    /// [`Ggx::lambda_from_tan2`]'s `x / (2 (1 + sqrt(1 + x)))` with `x = alpha^2 tan^2` multiplied
    /// through by `z^2`, one division instead of two; infinite at `z = 0`.
    #[inline(always)]
    fn lambdas_of_directions<const L: usize>(&self, xy2: &[f64; L], z: &[f64; L]) -> [f64; L] {
        let a2 = self.alpha * self.alpha;
        let mut lambdas = [0.0; L];
        for k in 0..L {
            let numerator = a2 * xy2[k];
            let z2 = z[k] * z[k];
            lambdas[k] = numerator / (2.0 * (z2 + z[k] * (z2 + numerator).sqrt()));
        }
        lambdas
    }

    /// GGX in `s` (`u = 1 - s`, `t = alpha s / u`): with `P = u^2 + alpha^2 s^2` and
    /// `Q = u^2 + s^2`, `1 + t^2 = P / u^2` and `alpha^2 + t^2 = alpha^2 Q / u^2`, so
    /// `cos = u / sqrt(P)`, `sin = alpha s / sqrt(P)`, `D = P^2 / (pi alpha^2 Q^2)` and the
    /// density `D sin^2 cos / (s u) = s sqrt(P) / (pi Q^2)`: one division and one square root,
    /// finite at both ends (the horizon's `alpha / pi` at `s = 1`, 0 at `s = 0`).
    #[inline(always)]
    fn polar_lanes_in_s<const L: usize>(&self, s: &[f64; L]) -> Polar<L> {
        let a2 = self.alpha * self.alpha;
        let mut polar = Polar::default();
        for (k, &s) in s.iter().enumerate() {
            let u = 1.0 - s;
            let p = u * u + a2 * s * s;
            let q = u * u + s * s;
            let root = p.sqrt();
            let inverse = 1.0 / (root * q * q);
            let w = inverse * q * q;
            polar.cos[k] = u * w;
            polar.sin[k] = self.alpha * s * w;
            polar.density[k] = s * p * inverse / PI;
        }
        polar
    }

    /// GGX in `x` (`t = alpha e^x`, `R = 1 + t^2`): `D = R^2 / (pi alpha^2 (1 + e^(2x))^2)` and
    /// `sin^2 cos = t^2 / R^(3/2)`, so the density is `sqrt(R) e^(2x) / (pi (1 + e^(2x))^2)`:
    /// one division and one square root.
    #[inline(always)]
    fn polar_lanes_in_x<const L: usize>(&self, exp_x: &[f64; L]) -> Polar<L> {
        let mut polar = Polar::default();
        for (k, &e) in exp_x.iter().enumerate() {
            let e2 = e * e;
            let t = self.alpha * e;
            let r = 1.0 + t * t;
            let root = r.sqrt();
            let square = (1.0 + e2) * (1.0 + e2);
            let inverse = 1.0 / (root * square);
            let cos = inverse * square;
            polar.cos[k] = cos;
            polar.sin[k] = t * cos;
            polar.density[k] = r * e2 * inverse / PI;
        }
        polar
    }

    /// The same operations as [`Ggx::lambda_from_tan2`] with the horizon's limit as a select,
    /// so that the loop vectorises.
    #[inline(always)]
    fn lambdas_from_tan2<const L: usize>(&self, tan2_theta: &[f64; L]) -> [f64; L] {
        let mut lambdas = [0.0; L];
        if self.alpha == 0.0 {
            return lambdas;
        }
        for (lambda, tan2) in lambdas.iter_mut().zip(tan2_theta) {
            let x = self.alpha * self.alpha * tan2;
            let finite = x / (2.0 * (1.0 + (1.0 + x).sqrt()));
            *lambda = if x.is_infinite() {
                f64::INFINITY
            } else {
                finite
            };
        }
        lambdas
    }

    /// Dupuy & Benyoub 2023, "Sampling Visible GGX Normals with Spherical Caps": stretch `o` to
    /// the unit-roughness configuration, sample the spherical cap below it uniformly, add the
    /// stretched view to obtain the (unnormalised) half vector, and unstretch.
    /// `u[1]` picks the cap's height: the cap coordinate `t = 1 - u[1]` of
    /// [`Ggx::visible_normal_on_cap`].
    fn sample_visible_normal(&self, o: Vec3, u: [f64; 2]) -> Vec3 {
        self.visible_normal_on_cap(o, u[0], 1.0 - u[1])
    }
}

impl Ggx {
    /// The visible normal at azimuth `phi = 2 pi u0` and cap coordinate `t` in [0, 1] of Dupuy &
    /// Benyoub's spherical cap (see [`MicrofacetDistribution::sample_visible_normal`]): the cap
    /// point's height is `z = t (1 + v_z) - v_z`, so `t` uniform is the visible-normal density and
    /// `t -> 0` is the cap's rim, where the half vector turns horizontal and the normals of GGX's
    /// heavy tail live. `z + v_z = t (1 + v_z)` and `1 - v_z = (v_x^2 + v_y^2) / (1 + v_z)` are
    /// computed without cancellation, so the tail keeps its precision when `t` is tiny.
    #[must_use]
    pub fn visible_normal_on_cap(&self, o: Vec3, u0: f64, t: f64) -> Vec3 {
        visible_normal_on_stretched_cap(self.alpha, self.alpha, o, u0, t)
    }
}

/// [`Ggx::visible_normal_on_cap`] for the anisotropic GGX of roughness `alpha_x` along x and
/// `alpha_y` along y (Dupuy & Benyoub 2023 stretch each axis by its own `alpha`): with
/// `alpha_x = alpha_y` the same operations, bit for bit.
#[must_use]
#[inline(always)]
pub(crate) fn visible_normal_on_stretched_cap(
    alpha_x: f64,
    alpha_y: f64,
    o: Vec3,
    u0: f64,
    t: f64,
) -> Vec3 {
    let v = Vec3::new(alpha_x * o.x, alpha_y * o.y, o.z).normalize();
    let phi = 2.0 * PI * u0;
    let hz = t * (1.0 + v.z);
    let one_minus_vz = (v.x * v.x + v.y * v.y) / (1.0 + v.z);
    let s = ((1.0 + v.z) * (1.0 - t) * (one_minus_vz + hz))
        .max(0.0)
        .sqrt();
    let (sin_phi, cos_phi) = phi.sin_cos();
    let h = Vec3::new(s * cos_phi + v.x, s * sin_phi + v.y, hz);
    Vec3::new(alpha_x * h.x, alpha_y * h.y, h.z).normalize()
}

/// Beckmann-Spizzichino.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Beckmann {
    pub alpha: f64,
}

impl MicrofacetDistribution for Beckmann {
    fn alpha(&self) -> f64 {
        self.alpha
    }

    /// `D = exp(-tan^2(theta_m) / alpha^2) / (pi alpha^2 c^4)` (Walter 2007, eq. 25).
    fn d(&self, cos_theta_m: f64) -> f64 {
        let a2 = self.alpha * self.alpha;
        let c2 = cos_theta_m * cos_theta_m;
        let tan2 = (1.0 - c2) / c2;
        (-tan2 / a2).exp() / (PI * a2 * c2 * c2)
    }

    /// `D = exp(-t^2 / alpha^2) (1 + t^2)^2 / (pi alpha^2)`, `t^2 = tan^2(theta_m)`.
    fn d_from_tan2(&self, tan2: f64) -> f64 {
        let a2 = self.alpha * self.alpha;
        (-tan2 / a2).exp() * (1.0 + tan2) * (1.0 + tan2) / (PI * a2)
    }

    /// Beckmann in `s` (`u = 1 - s`, `r = s / u = t / alpha`, `P = u^2 + alpha^2 s^2`):
    /// `cos = u / sqrt(P)`, `sin = alpha s / sqrt(P)` as for GGX, and the density
    /// `D sin^2 cos / (s u) = exp(-r^2) s sqrt(P) / (pi u^4)`, with the lane-wise `exp`
    /// ([`crate::numerics::elementary::exp_lane`]): two divisions and no library call. Nothing
    /// where `r^2` passes 700 (the density below `1e-300`) or `s` rounds to 1.
    #[inline(always)]
    fn polar_lanes_in_s<const L: usize>(&self, s: &[f64; L]) -> Polar<L> {
        let a2 = self.alpha * self.alpha;
        let mut polar = Polar::default();
        for (k, &s) in s.iter().enumerate() {
            let u = 1.0 - s;
            let inverse_u = 1.0 / u;
            let r = s * inverse_u;
            let p = u * u + a2 * s * s;
            let w = 1.0 / p.sqrt();
            let u4 = inverse_u * inverse_u * inverse_u * inverse_u;
            let density = exp_lane(-r * r) * s * p * w * u4 / PI;
            polar.cos[k] = u * w;
            polar.sin[k] = self.alpha * s * w;
            polar.density[k] = if u > 0.0 && r * r < 700.0 {
                density
            } else {
                0.0
            };
        }
        polar
    }

    /// Beckmann in `x` (`t = alpha e^x`): the density `exp(-e^(2x)) e^(2x) sqrt(1 + t^2) / pi`,
    /// with the lane-wise `exp`; nothing where `e^(2x)` passes 700.
    #[inline(always)]
    fn polar_lanes_in_x<const L: usize>(&self, exp_x: &[f64; L]) -> Polar<L> {
        let mut polar = Polar::default();
        for (k, &e) in exp_x.iter().enumerate() {
            let e2 = e * e;
            let t = self.alpha * e;
            let r = 1.0 + t * t;
            let cos = 1.0 / r.sqrt();
            let density = exp_lane(-e2) * e2 * r * cos / PI;
            polar.cos[k] = cos;
            polar.sin[k] = t * cos;
            polar.density[k] = if e2 < 700.0 { density } else { 0.0 };
        }
        polar
    }

    /// `mu (1 + Lambda) = mu (1 + erf(a)) / 2 + alpha sqrt(1 - mu^2) exp(-a^2) / (2 sqrt(pi))` with
    /// `a = mu / (alpha sqrt(1 - mu^2))`: the exact Lambda multiplied out, finite at `a = 0`.
    fn projected_area(&self, mu: f64) -> f64 {
        let so = ((1.0 - mu) * (1.0 + mu)).max(0.0).sqrt();
        if self.alpha == 0.0 || so == 0.0 {
            return mu;
        }
        let a = mu / (self.alpha * so);
        0.5 * mu * (1.0 + super::special::erf(a))
            + self.alpha * so * (-a * a).exp() * 0.5 * FRAC_1_SQRT_PI
    }

    /// Exact Smith Lambda, `a = 1 / (alpha tan(theta))` (Walter 2007, eq. 27 before the rational
    /// fit; `docs/physics.md`):
    ///
    /// `Lambda = (erf(a) - 1) / 2 + exp(-a^2) / (2 a sqrt(pi)) = (exp(-a^2) / (a sqrt(pi)) - erfc(a)) / 2`,
    ///
    /// by [`beckmann_lambda_of_a`] (Cody's rational `erfc`, written so that the two terms cancel
    /// as little as they can, and without them for `a > 4`), the same bits as
    /// [`Beckmann::lambdas_from_tan2`].
    fn lambda_from_tan2(&self, tan2_theta: f64) -> f64 {
        self.lambdas_from_tan2(&[tan2_theta])[0]
    }

    /// [`Beckmann::lambda_from_tan2`] in a loop that vectorises: `a = 1 / (alpha sqrt(tan^2))`,
    /// then [`beckmann_lambda_of_a`] (no library call). Nothing for a mirror, nothing at the
    /// normal, infinite on the horizon.
    #[inline(always)]
    fn lambdas_from_tan2<const L: usize>(&self, tan2_theta: &[f64; L]) -> [f64; L] {
        if self.alpha == 0.0 {
            return [0.0; L];
        }
        beckmann_lambda_of_a(&tan2_theta.map(|tan2| 1.0 / (self.alpha * tan2.sqrt())))
    }

    /// `a = z / (alpha sqrt(x^2 + y^2))`, one division, then [`beckmann_lambda_of_a`].
    #[inline(always)]
    fn lambdas_of_directions<const L: usize>(&self, xy2: &[f64; L], z: &[f64; L]) -> [f64; L] {
        if self.alpha == 0.0 {
            return [0.0; L];
        }
        let mut a = [0.0; L];
        for k in 0..L {
            a[k] = z[k] / (self.alpha * xy2[k].sqrt());
        }
        beckmann_lambda_of_a(&a)
    }

    /// Heitz & d'Eon 2014, "Importance Sampling Microfacet-Based BSDFs using the Distribution of
    /// Visible Normals": stretch `o`, sample the visible slopes of the unit-roughness Beckmann
    /// surface, rotate by `o`'s azimuth, unstretch, and turn the slope into a normal.
    ///
    /// The x-slope is drawn by inverting its CDF numerically (safeguarded Newton, as Jakob does for
    /// Mitsuba and pbrt-v3), which is continuous in `u`; the paper's fitted inversion has
    /// discontinuities that hurt QMC. See [`beckmann_visible_slope_x`].
    fn sample_visible_normal(&self, o: Vec3, u: [f64; 2]) -> Vec3 {
        BeckmannVisibleNormals::new(self.alpha, o).sample(u)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::special::erfc;

    /// Gauss-Legendre nodes and weights on [-1, 1] by Newton on the Legendre recurrence.
    fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
        (0..n)
            .map(|i| {
                let mut x = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
                loop {
                    let (mut p0, mut p1) = (1.0, x);
                    for k in 2..=n {
                        let k = k as f64;
                        (p0, p1) = (p1, ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k);
                    }
                    let dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
                    let dx = p1 / dp;
                    x -= dx;
                    if dx.abs() < 1e-15 {
                        let (mut p0, mut p1) = (1.0, x);
                        for k in 2..=n {
                            let k = k as f64;
                            (p0, p1) = (p1, ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k);
                        }
                        let dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
                        return (x, 2.0 / ((1.0 - x * x) * dp * dp));
                    }
                }
            })
            .collect()
    }

    /// `∫ f(m) dω_m` over the upper hemisphere in the variables `x = ln(tan(theta_m) / alpha)`
    /// over [-20, 40] (GGX decays only as `1 / tan` towards the horizon) and `phi`, which resolves
    /// the peak at every alpha.
    fn hemisphere_integral(alpha: f64, f: impl Fn(Vec3) -> f64) -> f64 {
        visible_integral(alpha, None, f)
    }

    /// As [`hemisphere_integral`], restricted to `o.m > 0` when `o` is given: `f` must be symmetric
    /// under `y -> -y`, and the phi range is cut exactly where `o.m` changes sign, so the
    /// integrand is smooth on each piece and Gauss-Legendre converges fast.
    fn visible_integral(alpha: f64, o: Option<Vec3>, f: impl Fn(Vec3) -> f64) -> f64 {
        let gl_x = gauss_legendre(300);
        let gl_phi = gauss_legendre(64);
        // The phi cut starts at tan(theta_m) = o.z / o.x: split the x range there too.
        let (x_lo, x_hi) = (-20.0, 40.0);
        let x_split = match o {
            Some(o) if o.x > 0.0 => ((o.z / o.x) / alpha).ln().clamp(x_lo, x_hi),
            _ => 0.0,
        };
        let mut sum = 0.0;
        let pieces = [(x_lo, x_split), (x_split, x_hi)];
        for &(t, wt) in &gl_x {
            for &(a, b) in &pieces {
                let x = a + (b - a) * (t + 1.0) / 2.0;
                let tan = alpha * x.exp();
                let theta = tan.atan();
                let (sin_t, cos_t) = theta.sin_cos();
                // dω = sin(theta) dtheta dphi, dtheta = tan / (1 + tan^2) dx.
                let jac = sin_t * tan / (1.0 + tan * tan) * (b - a) / 2.0;
                // o.m = o.x sin cos(phi) + o.z cos >= 0  <=>  cos(phi) >= -o.z cos / (o.x sin).
                let phi_max = match o {
                    None => PI,
                    Some(o) if o.x * sin_t <= o.z * cos_t => PI,
                    Some(o) => (-o.z * cos_t / (o.x * sin_t)).acos(),
                };
                for &(p, wp) in &gl_phi {
                    let phi = phi_max * (p + 1.0) / 2.0;
                    let m = Vec3::new(sin_t * phi.cos(), sin_t * phi.sin(), cos_t);
                    sum += wt * wp * phi_max * jac * f(m);
                }
            }
        }
        sum
    }

    #[test]
    fn d_is_normalised_for_both_distributions() {
        for &alpha in &[0.01, 0.1, 0.5, 1.0, 1.7] {
            let ggx = hemisphere_integral(alpha, |m| Ggx { alpha }.d(m.z) * m.z);
            let beckmann = hemisphere_integral(alpha, |m| Beckmann { alpha }.d(m.z) * m.z);
            assert!((ggx - 1.0).abs() < 1e-9, "GGX alpha {alpha}: {ggx}");
            assert!(
                (beckmann - 1.0).abs() < 1e-9,
                "Beckmann alpha {alpha}: {beckmann}"
            );
        }
    }

    /// docs/physics.md: `∫ (o.m)+ D(m) dω_m = mu_o (1 + Lambda(o))`, which holds for the exact Lambda.
    #[test]
    fn lambda_satisfies_the_projected_area_identity() {
        for &alpha in &[0.05, 0.3, 1.0, 1.6] {
            for &mu in &[0.02, 0.2, 0.5, 0.9] {
                let o = Vec3::from_mu(mu);
                let check = |name: &str, d: &dyn Fn(f64) -> f64, lambda: f64| {
                    let lhs = visible_integral(alpha, Some(o), |m| o.dot(m) * d(m.z));
                    let rhs = mu * (1.0 + lambda);
                    assert!(
                        (lhs - rhs).abs() < 1e-7 * rhs,
                        "{name} alpha {alpha} mu {mu}: {lhs} vs {rhs}"
                    );
                };
                let ggx = Ggx { alpha };
                let beckmann = Beckmann { alpha };
                check("GGX", &|c| ggx.d(c), ggx.lambda(o));
                check("Beckmann", &|c| beckmann.d(c), beckmann.lambda(o));
            }
        }
    }

    #[test]
    fn tan2_forms_and_projected_areas_agree_with_the_plain_forms() {
        for &alpha in &[1e-3, 0.2, 1.0, 2.5] {
            for &mu in &[1e-3, 0.3, 0.8, 1.0] {
                let o = Vec3::from_mu(mu);
                let check = |name: &str, area: f64, lambda: f64, d_tan: f64, d: f64| {
                    let plain = mu * (1.0 + lambda);
                    assert!(
                        (area - plain).abs() <= 1e-13 * plain,
                        "{name} {alpha} {mu}: {area} {plain}"
                    );
                    assert!(
                        (d_tan - d).abs() <= 1e-9 * d.max(1e-300),
                        "{name} D {alpha} {mu}: {d_tan} {d}"
                    );
                };
                let tan2 = (1.0 - mu * mu) / (mu * mu);
                let g = Ggx { alpha };
                check(
                    "GGX",
                    g.projected_area(mu),
                    g.lambda(o),
                    g.d_from_tan2(tan2),
                    g.d(mu),
                );
                let b = Beckmann { alpha };
                check(
                    "Beckmann",
                    b.projected_area(mu),
                    b.lambda(o),
                    b.d_from_tan2(tan2),
                    b.d(mu),
                );
            }
        }
        // At grazing the projected area is finite: the shadow of a rough surface.
        assert!((Ggx { alpha: 0.5 }.projected_area(0.0) - 0.25).abs() < 1e-16);
        let b = Beckmann { alpha: 0.5 }.projected_area(0.0);
        assert!((b - 0.25 * FRAC_1_SQRT_PI).abs() < 1e-16);
    }

    /// `Lambda(a) = (exp(-a^2) / (a sqrt(pi)) - erfc(a)) / 2` by `libm`'s `erfc` (fdlibm's
    /// approximations, independent of Cody's), switching to the asymptotic series of `erfc` for
    /// `a >= 6` where the two terms cancel: kiln's form before numerics version 8.
    fn beckmann_lambda_by_libm(a: f64) -> f64 {
        if a < 6.0 {
            return 0.5 * ((-a * a).exp() * FRAC_1_SQRT_PI / a - erfc(a));
        }
        let inv_2a2 = 0.5 / (a * a);
        let (mut term, mut sum, mut k) = (inv_2a2, 0.0_f64, 1.0);
        while term.abs() > 1e-17 * sum.abs() {
            sum += term;
            let next = term * -(2.0 * k + 1.0) * inv_2a2;
            if next.abs() >= term.abs() {
                break;
            }
            term = next;
            k += 1.0;
        }
        (-a * a).exp() * FRAC_1_SQRT_PI / (2.0 * a) * sum
    }

    /// Beckmann's `Lambda` by Cody's rationals against `mpmath` (50 digits) on both sides of
    /// Cody's interval ends (0.46875 and 4) and from `a = 1e-8` to 26, and against the `libm`
    /// form on a fine grid (where `Lambda` passes 1e-280); it is continuous across the ends.
    #[test]
    fn beckmann_lambda_matches_mpmath_and_an_independent_erfc() {
        // mpmath 1.3: (exp(-a^2) / (a sqrt(pi)) - erfc(a)) / 2 at 50 digits, each rounded to
        // the nearest double.
        let published = [
            (1e-8, 28209478.67738782),
            (1e-4, 2820.4479459482604),
            (0.01, 27.712300078290696),
            (0.1, 2.349110474981485),
            (0.3, 0.5236974710786996),
            (0.46875, 0.22939640955569746),
            (0.46876, 0.22938610391083716),
            (0.7, 0.08578447563675873),
            (1.0, 0.02512727083000611),
            (1.5, 0.002874288108260259),
            (2.0, 0.0002445056787378738),
            (3.0, 5.591724962696005e-07),
            (3.99, 2.4847570105502594e-10),
            (4.0, 2.2776771977658948e-10),
            (4.01, 2.087471594278031e-10),
            (5.0, 1.481342933684934e-14),
            (6.0, 1.4555347395581357e-19),
            (8.0, 4.318515368348727e-32),
            (12.0, 2.3385453759653967e-67),
            (20.0, 3.364037179547612e-179),
            (26.0, 2.09128909718775e-299),
        ];
        for &(a, want) in &published {
            let got = beckmann_lambda_of_a(&[a])[0];
            // Where `Lambda` is tiny the rounding of `-a^2` into `exp` costs up to `a^2 / 2` ulps.
            let allowed = 4e-15_f64.max(1.2e-16 * a * a);
            assert!(
                ((got - want) / want).abs() <= allowed,
                "a = {a}: {got} vs {want}"
            );
        }
        // Continuity across Cody's interval ends: a relative step of 1e-15 moves `Lambda` by
        // at most `(2 a^2 + 3) 1e-15` relative.
        for end in [0.468_75_f64, 4.0] {
            let below = beckmann_lambda_of_a(&[end * (1.0 - 1e-15)])[0];
            let above = beckmann_lambda_of_a(&[end * (1.0 + 1e-15)])[0];
            assert!(
                ((below - above) / above).abs() < 1e-13,
                "{end}: {below} vs {above}"
            );
        }
        // The libm form's own error: its two terms cancel by `2 a^2`, each carrying the `a^2`
        // ulps of `exp(-a * a)` (its series past 6 likewise).
        for i in 0..=20_000 {
            let a = 1e-6 * (26e6_f64).powf(f64::from(i) / 20_000.0);
            let got = beckmann_lambda_of_a(&[a])[0];
            let want = beckmann_lambda_by_libm(a);
            let allowed = 2.2e-16 * (2.0 * a * a + 3.0) * (a * a + 4.0);
            assert!(
                ((got - want) / want).abs() <= allowed,
                "a = {a}: {got} vs {want}"
            );
        }
        assert_eq!(
            beckmann_lambda_of_a(&[0.0, f64::INFINITY]),
            [f64::INFINITY, 0.0]
        );
    }

    /// The vectorised `Lambda` gives the scalar one's bits at every direction, the horizon and
    /// the normal included, and for a mirror.
    #[test]
    fn lambdas_at_once_are_the_lambdas_one_at_a_time() {
        let tan2 = [
            0.0,
            1e-300,
            1e-12,
            0.3,
            1.0,
            7.5,
            1e12,
            1e300,
            f64::INFINITY,
        ];
        for alpha in [0.0, 1e-4, 0.3, 1.0, 2.0] {
            let ggx = Ggx { alpha };
            let scalar = tan2.map(|t| ggx.lambda_from_tan2(t).to_bits());
            assert_eq!(
                ggx.lambdas_from_tan2(&tan2).map(f64::to_bits),
                scalar,
                "alpha {alpha}"
            );
            let beckmann = Beckmann { alpha };
            let scalar = tan2.map(|t| beckmann.lambda_from_tan2(t).to_bits());
            assert_eq!(beckmann.lambdas_from_tan2(&tan2).map(f64::to_bits), scalar);
        }
    }

    /// GGX's closed forms of the normals at the reference's nodes, in `s` and in `x`, against
    /// the textbook: `t` from the variable, `cos = 1 / sqrt(1 + t^2)`, `D` as Walter writes it
    /// with `cos^4 = 1 / (1 + t^2)^2` (the form in `cos` cancels near the normal), the density
    /// `D sin^2 cos dx/dv`; and Beckmann's alike. Within 1e-13 relative, from near 0 to the horizon; at the ends
    /// of `s` the limits (GGX's horizon density `alpha / pi`, nothing at `s = 0`).
    #[test]
    fn normals_at_the_nodes_are_the_textbook_normals() {
        let s = [1e-9, 0.01, 0.2, 0.4999, 0.5, 0.73, 0.97, 0.999_999];
        let x = [0.0, 1e-6, 0.3, 1.0, 2.5, 7.0, 20.0, 40.0];
        let close = |got: f64, want: f64| (got - want).abs() <= 1e-13 * want.abs().max(1e-300);
        for alpha in [1e-4, 0.05, 0.3, 1.0, 2.0] {
            let a2 = alpha * alpha;
            // Walter 2007, eqs. 33 and 25, `1 / cos^4 = (1 + t^2)^2`.
            let walter_ggx = |t: f64| {
                let c4 = 1.0 / ((1.0 + t * t) * (1.0 + t * t));
                1.0 / (PI * a2 * c4 * (1.0 + t * t / a2).powi(2))
            };
            let walter_beckmann = |t: f64| {
                let c4 = 1.0 / ((1.0 + t * t) * (1.0 + t * t));
                (-t * t / a2).exp() / (PI * a2 * c4)
            };
            let check = |what: &str, t: f64, jacobian: f64, d: f64, got: (f64, f64, f64)| {
                let cos = 1.0 / (1.0 + t * t).sqrt();
                let sin = t * cos;
                let density = d * sin * sin * cos * jacobian;
                assert!(
                    close(got.0, sin) && close(got.1, cos) && close(got.2, density),
                    "{what} alpha {alpha} t {t}: {got:?} vs {:?}",
                    (sin, cos, density)
                );
            };
            let ggx = Ggx { alpha };
            let beckmann = Beckmann { alpha };
            let (in_s, beckmann_s) = (ggx.polar_lanes_in_s(&s), beckmann.polar_lanes_in_s(&s));
            for (k, &v) in s.iter().enumerate() {
                let t = alpha * v / (1.0 - v);
                let jacobian = 1.0 / (v * (1.0 - v));
                let at = |p: &Polar<8>| (p.sin[k], p.cos[k], p.density[k]);
                check("GGX in s", t, jacobian, walter_ggx(t), at(&in_s));
                check(
                    "Beckmann in s",
                    t,
                    jacobian,
                    walter_beckmann(t),
                    at(&beckmann_s),
                );
            }
            let exp_x = x.map(f64::exp);
            let (in_x, beckmann_x) = (
                ggx.polar_lanes_in_x(&exp_x),
                beckmann.polar_lanes_in_x(&exp_x),
            );
            for (k, &e) in exp_x.iter().enumerate() {
                let t = alpha * e;
                let at = |p: &Polar<8>| (p.sin[k], p.cos[k], p.density[k]);
                check("GGX in x", t, 1.0, walter_ggx(t), at(&in_x));
                // Beckmann's tail underflows to nothing long before x = 40.
                if t < 20.0 * alpha.max(1.0) {
                    check("Beckmann in x", t, 1.0, walter_beckmann(t), at(&beckmann_x));
                }
            }
            let ends = ggx.polar_lanes_in_s(&[0.0, 1.0]);
            assert_eq!((ends.sin[0], ends.cos[0], ends.density[0]), (0.0, 1.0, 0.0));
            assert_eq!((ends.sin[1], ends.cos[1]), (1.0, 0.0));
            assert!(close(ends.density[1], alpha / PI), "{ends:?}");
            let ends = beckmann.polar_lanes_in_s(&[0.0, 1.0]);
            assert_eq!(
                ends.density, [0.0; 2],
                "nothing where t rounds to 0 or infinity"
            );
            assert_eq!((ends.sin[0], ends.cos[0]), (0.0, 1.0));
        }
    }

    /// GGX's `Lambda` from a direction's components agrees with the `tan^2` form within 1e-14
    /// relative, from the zenith to the horizon (infinite there), and Beckmann's default divides.
    #[test]
    fn lambdas_of_directions_are_lambdas_of_their_tangents() {
        let theta = [
            0.0,
            1e-8,
            0.2,
            0.9,
            1.3,
            1.5,
            std::f64::consts::FRAC_PI_2 - 1e-6,
            std::f64::consts::FRAC_PI_2,
        ];
        let xy2 = theta.map(|t: f64| t.sin() * t.sin());
        let z = theta.map(f64::cos);
        for alpha in [1e-4, 0.3, 1.0, 2.0] {
            let ggx = Ggx { alpha };
            let at_once = ggx.lambdas_of_directions(&xy2, &z);
            let beckmann = Beckmann { alpha }.lambdas_of_directions(&xy2, &z);
            for k in 0..theta.len() {
                let tan2 = xy2[k] / (z[k] * z[k]);
                let want = ggx.lambda_from_tan2(tan2);
                assert!(
                    (at_once[k] - want).abs() <= 1e-14 * want || at_once[k] == want,
                    "alpha {alpha} theta {}: {} vs {want}",
                    theta[k],
                    at_once[k]
                );
                let want = Beckmann { alpha }.lambda_from_tan2(tan2);
                assert!(
                    (beckmann[k] - want).abs() <= 1e-12 * want || beckmann[k] == want,
                    "Beckmann alpha {alpha} theta {}: {} vs {want}",
                    theta[k],
                    beckmann[k]
                );
            }
            assert_eq!(ggx.lambdas_of_directions(&[1.0], &[0.0]), [f64::INFINITY]);
        }
    }

    #[test]
    fn lambda_limits() {
        assert_eq!(Ggx { alpha: 0.5 }.lambda_from_tan2(0.0), 0.0);
        assert_eq!(
            Ggx { alpha: 0.5 }.lambda_from_tan2(f64::INFINITY),
            f64::INFINITY
        );
        assert_eq!(Beckmann { alpha: 0.5 }.lambda_from_tan2(0.0), 0.0);
        assert_eq!(
            Beckmann { alpha: 0.5 }.lambda_from_tan2(f64::INFINITY),
            f64::INFINITY
        );
        assert_eq!(Ggx { alpha: 0.0 }.lambda_from_tan2(3.0), 0.0);
        // GGX: exact value at alpha tan = 1: (sqrt 2 - 1) / 2.
        let l = Ggx { alpha: 0.5 }.lambda_from_tan2(4.0);
        assert!((l - (2f64.sqrt() - 1.0) / 2.0).abs() < 1e-16);
    }

    /// The projected area `mu (1 + Lambda)` at its limits: a mirror's is `mu` at every `mu`, the
    /// horizon and the normal included (no `0 / 0`); at the horizon a rough surface keeps the
    /// area its facets show sideways, `alpha / 2` for GGX and `alpha / (2 sqrt(pi))` for
    /// Beckmann (`mu Lambda` as `mu -> 0`, from Heitz 2014 eqs. 72 and 77); at the normal, 1.
    #[test]
    fn projected_areas_at_the_limits() {
        for mu in [0.0, 1e-300, 0.3, 1.0] {
            assert_eq!(Ggx { alpha: 0.0 }.projected_area(mu), mu, "GGX {mu}");
            assert_eq!(
                Beckmann { alpha: 0.0 }.projected_area(mu),
                mu,
                "Beckmann {mu}"
            );
        }
        for alpha in [1e-3, 0.5, 2.0] {
            let ggx = Ggx { alpha }.projected_area(0.0);
            assert!((ggx - alpha / 2.0).abs() <= 1e-16 * alpha, "{alpha}: {ggx}");
            let beckmann = Beckmann { alpha }.projected_area(0.0);
            let expected = alpha * FRAC_1_SQRT_PI / 2.0;
            assert!(
                (beckmann - expected).abs() <= 1e-15 * alpha,
                "{alpha}: {beckmann}"
            );
            assert_eq!(Ggx { alpha }.projected_area(1.0), 1.0);
            assert_eq!(Beckmann { alpha }.projected_area(1.0), 1.0);
        }
    }

    /// The visible-normal samplers reproduce the visible-normal density: the mean of a test function
    /// over a fine sample grid matches its integral against `G1(o) (o.m)+ D(m) / mu_o`. The views
    /// lie in the xz plane and, turned about the normal by `psi`, out of it: an isotropic surface
    /// turns its visible normals with the view, so the samples turned back by `-psi` have the
    /// same mean (a sampler that mishandles the view's y component fails there).
    #[test]
    fn visible_normal_sampling_matches_its_density() {
        let n = 400;
        for &alpha in &[0.2, 0.8] {
            for &mu in &[0.1, 0.6, 0.999] {
                let o = Vec3::from_mu(mu);
                let test_fn = |m: Vec3| m.z * m.z + 0.3 * m.x + 0.1 * m.y * m.y;
                /// The mean of `f` over the visible normals sampled for the view `o` turned by
                /// `psi`, each turned back by `-psi`.
                fn mean<N: MicrofacetDistribution>(
                    ndf: N,
                    o: Vec3,
                    psi: f64,
                    n: usize,
                    f: impl Fn(Vec3) -> f64,
                ) -> f64 {
                    let turn = |v: Vec3, angle: f64| {
                        let (sin, cos) = angle.sin_cos();
                        Vec3::new(cos * v.x - sin * v.y, sin * v.x + cos * v.y, v.z)
                    };
                    let view = turn(o, psi);
                    let mut mean = 0.0;
                    for i in 0..n {
                        for j in 0..n {
                            let u = [(i as f64 + 0.5) / n as f64, (j as f64 + 0.5) / n as f64];
                            mean += f(turn(ndf.sample_visible_normal(view, u), -psi));
                        }
                    }
                    mean / (n * n) as f64
                }
                fn exact<N: MicrofacetDistribution>(
                    ndf: N,
                    o: Vec3,
                    f: impl Fn(Vec3) -> f64,
                ) -> f64 {
                    let g1 = ndf.g1(o);
                    visible_integral(ndf.alpha(), Some(o), |m| {
                        g1 * o.dot(m) * ndf.d(m.z) / o.z * f(m)
                    })
                }
                let ggx = exact(Ggx { alpha }, o, test_fn);
                let beckmann = exact(Beckmann { alpha }, o, test_fn);
                for psi in [0.0, 2.0] {
                    let got = mean(Ggx { alpha }, o, psi, n, test_fn);
                    assert!(
                        (got - ggx).abs() < 2e-4,
                        "GGX {alpha} {mu} turned {psi}: {got} vs {ggx}"
                    );
                    let got = mean(Beckmann { alpha }, o, psi, n, test_fn);
                    assert!(
                        (got - beckmann).abs() < 2e-4,
                        "Beckmann {alpha} {mu} turned {psi}: {got} vs {beckmann}"
                    );
                }
            }
        }
    }
}
