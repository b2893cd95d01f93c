//! The directional albedo of anisotropic GGX, `E(mu, phi; alpha_x, alpha_y)` (`F = 1`,
//! height-correlated Smith masking), and its Fourier coefficients in the view's azimuth.
//!
//! # The reference
//!
//! `E(o) = ∫ D(m) (o.m) G2(o, i) / mu dω_m` over the normals whose reflection `i = 2 (o.m) m - o`
//! stays above the horizon, with `G2 = 1 / (1 + Lambda(o) + Lambda(i))` (Heitz 2014, eq. 99),
//! written `(o.m) / (A(o) + mu Lambda(i))` with the projected area `A(o) = mu (1 + Lambda(o))`.
//! Normals are taken by azimuth `phi_m` in `[0, 2 pi]` (outer) and by `x = ln(tan(theta_m) /
//! alpha_m)` (inner), where `alpha_m` is the isotropic roughness whose `D` has the anisotropic
//! one's shape along `phi_m` ([`AnisotropicGgx::normal_alpha_along`]): the peak has the same
//! width in `x` at every azimuth, as in the isotropic reference (`crate::integrate::reference`).
//! In those variables `D dω_m = alpha_m^2 e^(2x) sqrt(1 + t^2) / (pi alpha_x alpha_y (1 +
//! e^(2x))^2) dx dphi_m` (`t = tan(theta_m)`). For a fixed `phi_m` the reflection crosses the
//! horizon at `tan(theta*) = (R + c) / mu = mu / (R - c)`, `c = sin(theta_o) cos(phi_m -
//! phi_o)`, `R = sqrt(mu^2 + c^2)` (the isotropic reference's `theta*`, in the form without
//! cancellation for either sign of `c`): the `x` integral ends there, where the integrand goes
//! to 0 continuously, so both levels integrate smooth functions. The outer level breaks where
//! `cos(phi_m - phi_o)` is 0 or ±1, at the axes, and where `alpha_m` turns from one axis's
//! roughness to the other's (`tan phi_m = alpha_y / alpha_x`).
//!
//! The error estimate adds the outer integral's to the integral of the inner ones, as the
//! isotropic reference does.
//!
//! # The azimuth
//!
//! `D` is symmetric under `x -> -x` and `y -> -y`, so `E(phi)` is even and of period `pi`:
//! `E(phi) = c_0 + c_2 cos 2 phi + c_4 cos 4 phi + ...`, with `c_0` the azimuthal average and
//! `c_{2k} = (4 / pi) ∫_0^{pi/2} E(phi) cos(2 k phi) dphi` for `k > 0`
//! ([`reference_anisotropic_fourier`]).

use super::estimate::Estimate;
use super::qmc::{QmcSettings, replicates, sum_over_block};
use super::reference::{ReferenceSettings, ReferenceValue};
use crate::model::{AnisotropicGgx, Vec3};
use crate::numerics::gauss_kronrod::integrate_pieces;
use std::f64::consts::{FRAC_PI_2, PI};

/// The lowest `x = ln(tan(theta_m) / alpha_m)` integrated: below it the distribution holds less
/// than `exp(-54)` of its mass (as in the isotropic reference).
const X_MIN: f64 = -27.0;
/// The highest `x`: GGX's tail beyond it carries less than `exp(-44)`.
const X_MAX: f64 = 44.0;

/// Checks an anisotropic view and roughness: `mu` in [0, 1], both roughness values finite and
/// in (0, 1000].
pub fn check_anisotropic(ndf: AnisotropicGgx, mu: f64) -> crate::Result<()> {
    for (name, alpha) in [("alpha_x", ndf.alpha_x), ("alpha_y", ndf.alpha_y)] {
        if !(alpha > 0.0 && alpha <= 1000.0) {
            return Err(crate::Error::InvalidInput(format!(
                "{name} = {alpha} is outside (0, 1000]: anisotropic GGX needs a positive \
                 roughness on each axis (a mirror along one axis is the limit alpha -> 0, \
                 give 1e-4)"
            )));
        }
    }
    if !(0.0..=1.0).contains(&mu) {
        return Err(crate::Error::InvalidInput(format!(
            "mu = {mu} is outside [0, 1]"
        )));
    }
    Ok(())
}

/// Checks a view's azimuth: radians from the tangent, in `[-2 pi, 2 pi]`.
pub fn check_azimuth(phi: f64) -> crate::Result<()> {
    if (-2.0 * PI..=2.0 * PI).contains(&phi) {
        Ok(())
    } else {
        Err(crate::Error::InvalidInput(format!(
            "the view's azimuth phi = {phi} is outside [-2 pi, 2 pi] (radians from the tangent)"
        )))
    }
}

/// The unit view with `cos(theta) = mu` at azimuth `phi` (radians from the x axis).
#[must_use]
pub fn view(mu: f64, phi: f64) -> Vec3 {
    let so = ((1.0 - mu) * (1.0 + mu)).max(0.0).sqrt();
    let (sin, cos) = phi.sin_cos();
    Vec3::new(so * cos, so * sin, mu)
}

/// `E(mu, phi)` by the reference quadrature (module docs). At `mu = 0` it is the grazing limit
/// 1 exactly (`G2 / G1(o) -> 1` as `Lambda(o) -> infinity`, whatever the roughness).
///
/// # Panics
/// On a roughness or `mu` that [`check_anisotropic`] refuses.
#[must_use]
pub fn reference_anisotropic_albedo(
    ndf: AnisotropicGgx,
    mu: f64,
    phi: f64,
    settings: &ReferenceSettings,
) -> ReferenceValue {
    if let Err(message) = check_anisotropic(ndf, mu) {
        panic!("{message}");
    }
    if mu == 0.0 {
        return super::reference::MIRROR;
    }
    albedo_at(
        ndf,
        view(mu, phi),
        settings.tolerance,
        settings.max_intervals,
    )
}

/// `E(o)`, `o` a unit view with `o.z > 0`.
fn albedo_at(ndf: AnisotropicGgx, o: Vec3, tolerance: f64, max_intervals: usize) -> ReferenceValue {
    let mu = o.z;
    let area = ndf.projected_area(o);
    let so = (o.x * o.x + o.y * o.y).sqrt();
    let phi_o = o.y.atan2(o.x).rem_euclid(2.0 * PI);
    let inner_tolerance = tolerance / (4.0 * PI);
    let mut evaluations = 0u64;
    let mut converged = true;
    let mut outer = |phi_m: f64| -> [f64; 2] {
        let (sin_m, cos_m) = phi_m.sin_cos();
        let c = so * (phi_m - phi_o).cos();
        let r = mu.hypot(c);
        let tan_star = if c >= 0.0 { (r + c) / mu } else { mu / (r - c) };
        let alpha_m = ndf.normal_alpha_along(cos_m, sin_m);
        let x_star = (tan_star / alpha_m).ln().min(X_MAX);
        if x_star <= X_MIN {
            return [0.0, 0.0];
        }
        let mut breaks: smallvec::SmallVec<[f64; 6]> = smallvec::smallvec![X_MIN];
        breaks.extend([-4.0, 0.0, 4.0].into_iter().filter(|&b| b < x_star));
        breaks.push(x_star);
        let scale = alpha_m * alpha_m / (PI * ndf.alpha_x * ndf.alpha_y);
        let mut inner = |x: f64| -> [f64; 1] {
            let e = x.exp();
            let e2 = e * e;
            let t = alpha_m * e;
            let root = (1.0 + t * t).sqrt();
            let (sin_t, cos_t) = (t / root, 1.0 / root);
            let m = Vec3::new(sin_t * cos_m, sin_t * sin_m, cos_t);
            let density = scale * e2 * root / ((1.0 + e2) * (1.0 + e2));
            let om = o.dot(m);
            let i = o.reflect(m);
            if i.z <= 0.0 || om <= 0.0 {
                return [0.0];
            }
            [density * om / (area + mu * ndf.lambda(i))]
        };
        let q = integrate_pieces(&mut inner, &breaks, inner_tolerance, max_intervals);
        evaluations += q.evaluations;
        converged &= q.converged;
        [q.value[0], q.error]
    };
    let mut breaks: Vec<f64> = vec![0.0, FRAC_PI_2, PI, 1.5 * PI, 2.0 * PI];
    for k in 0..4 {
        breaks.push((phi_o + k as f64 * FRAC_PI_2).rem_euclid(2.0 * PI));
    }
    // Where `alpha_m` turns from the tangent's roughness to the bitangent's (`tan phi_m =
    // alpha_y / alpha_x`): at a strong anisotropy the normals' density changes within that
    // angle of the axis, and a 15-point rule across it misjudged its own error (3e-3 off at
    // tolerance 1e-3 before these breaks, `kiln anisotropic` while designing, 2026-12-07).
    let turn = ndf.alpha_y.atan2(ndf.alpha_x);
    breaks.extend([turn, PI - turn, PI + turn, 2.0 * PI - turn]);
    breaks.sort_by(f64::total_cmp);
    breaks.dedup_by(|a, b| (*a - *b).abs() < 1e-12);
    let q = integrate_pieces(&mut outer, &breaks, tolerance / 2.0, max_intervals);
    evaluations += q.evaluations;
    let value = q.value[0];
    let clamped = value.clamp(0.0, 1.0);
    ReferenceValue {
        value: clamped,
        one_minus_value: 1.0 - clamped,
        error: q.error + q.value[1] + (value - clamped).abs(),
        evaluations,
        converged: converged && q.converged,
    }
}

/// The seeds' tag of the anisotropic estimates (`E` at one azimuth and the azimuthal average).
const TAG_ANISOTROPIC: u64 = 0x4541_4e49;

/// `1 - G2(o, i) / G1(o)` for the visible normal `m`: `mu Lambda(i) / (A(o) + mu Lambda(i))`
/// when the reflection `i` is above the horizon, 1 when it is not (the energy lost, which QMC
/// averages over visible normals; `E` is one minus its mean).
#[inline(always)]
fn loss(ndf: AnisotropicGgx, o: Vec3, area: f64, m: Vec3) -> f64 {
    let i = o.reflect(m);
    if i.z <= 0.0 {
        return 1.0;
    }
    let shadowed = o.z * ndf.lambda(i);
    shadowed / (area + shadowed)
}

/// `E(mu, phi)` by QMC over visible normals (Owen-scrambled Sobol points, independent scrambles
/// for the standard error), or with `phi = None` its azimuthal average, the view's azimuth a
/// third dimension over `[0, pi/2]` (the symmetry of the module docs).
///
/// # Panics
/// On a roughness or `mu` that [`check_anisotropic`] refuses, or invalid settings.
#[must_use]
pub fn anisotropic_albedo(
    ndf: AnisotropicGgx,
    mu: f64,
    phi: Option<f64>,
    settings: &QmcSettings,
) -> Estimate {
    if let Err(message) = check_anisotropic(ndf, mu) {
        panic!("{message}");
    }
    if mu == 0.0 {
        return Estimate::exact(0.0);
    }
    let key = [
        TAG_ANISOTROPIC,
        ndf.alpha_x.to_bits(),
        ndf.alpha_y.to_bits(),
        mu.to_bits(),
        phi.map_or(u64::MAX, f64::to_bits),
    ];
    match phi {
        Some(phi) => {
            let o = view(mu, phi);
            let area = ndf.projected_area(o);
            replicates(settings, &key, |seq, log2_n| {
                sum_over_block::<2>(
                    seq,
                    log2_n,
                    #[inline(always)]
                    |u| loss(ndf, o, area, ndf.sample_visible_normal(o, u)),
                )
            })
        }
        None => replicates(settings, &key, |seq, log2_n| {
            sum_over_block::<3>(
                seq,
                log2_n,
                #[inline(always)]
                |u| {
                    let o = view(mu, FRAC_PI_2 * u[2]);
                    let area = ndf.projected_area(o);
                    loss(ndf, o, area, ndf.sample_visible_normal(o, [u[0], u[1]]))
                },
            )
        }),
    }
}

/// `E_avg = ∫_0^1 2 mu E(mu) dmu` averaged over the view's azimuth, by QMC: `mu = sqrt(u)` (the
/// density `2 mu`), the azimuth uniform over `[0, pi/2]`, then a visible normal.
///
/// # Panics
/// On a roughness [`check_anisotropic`] refuses, or invalid settings.
#[must_use]
pub fn anisotropic_average_albedo(ndf: AnisotropicGgx, settings: &QmcSettings) -> Estimate {
    if let Err(message) = check_anisotropic(ndf, 1.0) {
        panic!("{message}");
    }
    let key = [
        TAG_ANISOTROPIC,
        ndf.alpha_x.to_bits(),
        ndf.alpha_y.to_bits(),
        u64::MAX,
        u64::MAX,
    ];
    replicates(settings, &key, |seq, log2_n| {
        sum_over_block::<4>(
            seq,
            log2_n,
            #[inline(always)]
            |u| {
                let o = view(u[3].sqrt(), FRAC_PI_2 * u[2]);
                if o.z <= 0.0 {
                    return 0.0;
                }
                let area = ndf.projected_area(o);
                loss(ndf, o, area, ndf.sample_visible_normal(o, [u[0], u[1]]))
            },
        )
    })
}

/// The azimuthal Fourier coefficients of `E(mu, phi)` (module docs), each with its error
/// estimate.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct FourierReference {
    /// `c_0, c_2, c_4, ...`: `coefficients[k]` multiplies `cos(2 k phi)`.
    pub coefficients: Vec<f64>,
    /// The error estimate of each (the outer quadrature's plus the integral of the inner ones).
    pub error: f64,
    pub evaluations: u64,
    pub converged: bool,
}

/// The first `count` azimuthal Fourier coefficients of `E(mu, phi)` by adaptive quadrature over
/// `phi` in `[0, pi/2]` of the reference `E` (module docs). `coefficients[0]` is the azimuthal
/// average.
///
/// # Panics
/// On a roughness or `mu` that [`check_anisotropic`] refuses, or `count` outside 1 to 4.
#[must_use]
pub fn reference_anisotropic_fourier(
    ndf: AnisotropicGgx,
    mu: f64,
    count: usize,
    settings: &ReferenceSettings,
) -> FourierReference {
    assert!((1..=4).contains(&count), "1 to 4 coefficients");
    if let Err(message) = check_anisotropic(ndf, mu) {
        panic!("{message}");
    }
    if mu == 0.0 {
        let mut coefficients = vec![0.0; count];
        coefficients[0] = 1.0;
        return FourierReference {
            coefficients,
            error: 0.0,
            evaluations: 0,
            converged: true,
        };
    }
    let mut evaluations = 0;
    let mut converged = true;
    // [E cos 0, E cos 2 phi, E cos 4 phi, E cos 6 phi, the inner error]
    let mut integrand = |phi: f64| -> [f64; 5] {
        let e = albedo_at(
            ndf,
            view(mu, phi),
            settings.tolerance / 4.0,
            settings.max_intervals,
        );
        evaluations += e.evaluations;
        converged &= e.converged;
        let mut out = [0.0; 5];
        for (k, slot) in out.iter_mut().take(count).enumerate() {
            *slot = e.value * (2.0 * k as f64 * phi).cos();
        }
        out[4] = e.error;
        out
    };
    let q = integrate_pieces(
        &mut integrand,
        &[0.0, FRAC_PI_2],
        settings.tolerance * FRAC_PI_2 / 4.0,
        settings.max_intervals,
    );
    evaluations += q.evaluations;
    let coefficients = (0..count)
        .map(|k| {
            let weight = if k == 0 { 2.0 / PI } else { 4.0 / PI };
            weight * q.value[k]
        })
        .collect();
    FourierReference {
        coefficients,
        error: 4.0 / PI * (q.error + q.value[4]),
        evaluations,
        converged: converged && q.converged,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::reference::reference_albedo;
    use crate::model::{Masking, Model, Ndf};

    /// QMC (visible normals) and the reference (quadrature over all normals) agree within a few
    /// standard errors, at one azimuth and on average.
    #[test]
    fn qmc_agrees_with_the_reference() {
        let ndf = AnisotropicGgx {
            alpha_x: 0.9,
            alpha_y: 0.1,
        };
        let settings = QmcSettings {
            samples: 1 << 18,
            scrambles: 16,
            ..QmcSettings::default()
        };
        let reference = ReferenceSettings {
            tolerance: 1e-9,
            ..ReferenceSettings::default()
        };
        for mu in [0.05, 0.5] {
            for phi in [0.0, 1.0] {
                let q = anisotropic_albedo(ndf, mu, Some(phi), &settings);
                let r = reference_anisotropic_albedo(ndf, mu, phi, &reference).value;
                assert!(
                    (q.value - r).abs() < 5.0 * q.std_error + 1e-6,
                    "{q:?} vs {r}"
                );
            }
            let q = anisotropic_albedo(ndf, mu, None, &settings);
            let r = reference_anisotropic_fourier(ndf, mu, 1, &reference).coefficients[0];
            assert!(
                (q.value - r).abs() < 5.0 * q.std_error + 1e-6,
                "{q:?} vs {r}"
            );
        }
    }

    /// The azimuth's range is `[-2 pi, 2 pi]`, its ends included, and `E` has period `pi` in it
    /// (`D` is symmetric under `x -> -x` and `y -> -y`).
    #[test]
    fn azimuths_of_a_whole_turn_either_way_are_accepted() {
        for phi in [-2.0 * PI, -6.2, 6.2, 2.0 * PI] {
            assert!(check_azimuth(phi).is_ok(), "{phi}");
        }
        for phi in [-6.3, 6.3, f64::NAN] {
            assert!(check_azimuth(phi).is_err(), "{phi}");
        }
        let ndf = AnisotropicGgx {
            alpha_x: 0.6,
            alpha_y: 0.2,
        };
        let settings = ReferenceSettings::default();
        let e = |phi| reference_anisotropic_albedo(ndf, 0.4, phi, &settings).value;
        assert!((e(6.0) - e(6.0 - 2.0 * PI)).abs() < 1e-10);
        assert!((e(2.5) - e(2.5 - PI)).abs() < 1e-10);
    }

    /// With equal axes the anisotropic reference is kiln's isotropic `E` (another
    /// parametrisation and another code), at every azimuth.
    #[test]
    fn equal_axes_give_the_isotropic_albedo() {
        let settings = ReferenceSettings::default();
        let model = Model {
            ndf: Ndf::Ggx,
            masking: Masking::HeightCorrelated,
        };
        for (alpha, mu) in [(0.05, 0.3), (0.3, 0.05), (0.7, 0.9), (1.0, 1.0), (0.5, 0.5)] {
            let iso = reference_albedo(model, alpha, mu, &settings).value;
            let ndf = AnisotropicGgx {
                alpha_x: alpha,
                alpha_y: alpha,
            };
            for phi in [0.0, 0.4, 2.0] {
                let e = reference_anisotropic_albedo(ndf, mu, phi, &settings);
                assert!(e.converged, "{e:?}");
                assert!(
                    (e.value - iso).abs() < 1e-10,
                    "alpha {alpha} mu {mu} phi {phi}: {} vs {iso}",
                    e.value
                );
            }
        }
    }
}
