//! A rough dielectric interface: microfacet reflection plus transmission.
//!
//! Source: Walter, Marschner, Li and Torrance 2007, "Microfacet Models for Refraction through Rough
//! Surfaces" (EGSR): the BTDF (eq. 21), the refraction Jacobian (eq. 17), the Fresnel term
//! (eq. 22, [`super::fresnel::dielectric`]); Heitz 2014, "Understanding the Masking-Shadowing
//! Function in Microfacet-Based BRDFs", for visible-normal sampling. The masking forms are the
//! same as for reflection ([`Masking`]): `G2 = 1 / (1 + Lambda(o) + Lambda(i))` or
//! `G1(o) G1(i)`, which is what pbrt-v4, Cycles and Mitsuba evaluate for transmission too (Heitz
//! 2014 gives a Beta-function form for height-correlated transmission; no renderer kiln serves
//! uses it, and a table is only right for the BSDF the renderer evaluates).
//!
//! ## Convention: energy albedo (the sample weight), not radiance albedo
//!
//! `eta = n_other / n_view` is the relative index of the medium across the interface from the view
//! direction `o`. Light arriving along `o` is reflected with probability `F(o.m)` at a visible
//! microfacet `m` and refracted otherwise. Drawing `m` from the visible normals of `o` (density
//! `G1(o) (o.m)+ D(m) / mu_o`), the fraction of the incident *power* that leaves is the mean of
//!
//! - reflection: `F(o.m) G2(o, i_r) / G1(o)` when `i_r = reflect(o, m)` is above the surface,
//! - transmission: `(1 - F(o.m)) G2(o, i_t) / G1(o)` when `i_t = refract(o, m)` is below it
//!   (a refracted direction that ends on the incident side is rejected: it counts as lost),
//!
//! because Walter's Jacobian `dω_i / dω_m` cancels the BTDF's `(o.m + eta i.m)^2` denominator.
//! kiln's dielectric tables hold this *energy albedo*, the quantity a path tracer's throughput
//! multiplies by (the sample weight, Cycles and pbrt-v4's importance mode): with a smooth
//! surface it is `R + T = F + (1 - F) = 1`, so `1 - E` is the energy that single scattering loses
//! and `1 / E` is Turquin's compensation factor.
//!
//! The *radiance* albedo `∫ f(o, i) |mu_i| dω_i` of Walter's radiance BTDF differs by the solid
//! angle compression of refraction: its transmitted part is `T / eta^2`, so it is `R + T / eta^2`
//! (below 1 for `eta > 1` even when smooth, above 1 possible for `eta < 1`). Renderers that carry
//! radiance with that factor (pbrt-v4's radiance mode) must scale kiln's transmission by
//! `1 / eta^2`; the library returns `R` and `T` separately ([`Scattering`]) for that reason.
//!
//! Reciprocity in this convention: Walter's BTDF obeys `f(o, i) / n_i^2 = f(i, o) / n_o^2`, so the
//! hemispherical averages of the transmitted energy from either side satisfy
//! `T_avg(eta) = eta^2 T_avg(1 / eta)` (with a smooth surface: `1 - F_avg(eta) = eta^2 (1 -
//! F_avg(1 / eta))`, the Fresnel reciprocity of `docs/physics.md`).

use super::masking::Masking;
use super::ndf::MicrofacetDistribution;
use super::vector::Vec3;

/// What one visible microfacet normal contributes to the energy albedo of a dielectric
/// interface: `reflection + transmission + loss = 1`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scattering {
    /// `F G2(o, i_r) / G1(o)`, or 0 when the reflected direction is below the surface.
    pub reflection: f64,
    /// `(1 - F) G2(o, i_t) / G1(o)`, or 0 under total internal reflection or when the refracted
    /// direction is above the surface.
    pub transmission: f64,
    /// The rest, computed without cancellation ([`Masking::loss`]).
    pub loss: f64,
}

/// Whose dielectric albedo a table holds: single scattering as a BSDF evaluates it (kiln's), or
/// what Cycles' sampler made of it when it computed Blender's glass tables
/// (`table_ggx_glass_*` in `shader.tables`), which a table that replaces Blender's must match.
/// They differ in two places:
///
/// - a refracted direction that ends on the incident side of the macrosurface: single
///   scattering cannot send light through the interface and back to the side it came from, and
///   the BSDF's evaluation gives it nothing, so kiln counts it as lost; Cycles' sampler (its
///   hemisphere check commented out) kept it with the weight of any refraction,
///   `(1 - F) G2(o, i_t) / G1(o)` (`Lambda` of `|cos|`). Blender's `glass_inv_E` differs from
///   kiln's by up to 0.61 there (grazing views from inside, high roughness);
/// - an index within 1e-4 of 1 (`|eta - 1| < 1e-4`, Cycles' first IOR node): Cycles treats the
///   interface as smooth, `E = F + (1 - F) = 1`, where a rough index-matched interface loses
///   `1 - G2 / G1` (0.3 at `r = 1`, `mu = 0.4`).
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "kebab-case")]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum TransmissionConvention {
    /// Single scattering as the BSDF evaluates it (kiln's default).
    #[default]
    SingleScattering,
    /// Cycles' sampler, as it computed Blender's glass tables.
    Cycles,
}

impl TransmissionConvention {
    /// The name on the command line, in files and in table names.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            TransmissionConvention::SingleScattering => "single-scattering",
            TransmissionConvention::Cycles => "cycles",
        }
    }

    /// Whether it is kiln's default (single scattering), which files leave out.
    #[must_use]
    pub fn is_default(&self) -> bool {
        *self == TransmissionConvention::SingleScattering
    }

    /// A sentence for metadata.
    #[must_use]
    pub fn describe(self) -> &'static str {
        match self {
            TransmissionConvention::SingleScattering => {
                "single scattering: a refraction that ends on the incident side of the surface \
                 is lost, as the BSDF evaluates it"
            }
            TransmissionConvention::Cycles => {
                "Cycles' sampler (bsdf_microfacet_sample): a refraction that ends on the \
                 incident side of the surface is kept, and an index within 1e-4 of 1 is smooth \
                 (E = 1), as Blender computed its glass tables"
            }
        }
    }

    /// Whether a refraction that ends on the incident side is kept.
    #[must_use]
    pub fn keeps_refraction_above(self) -> bool {
        self == TransmissionConvention::Cycles
    }

    /// Whether the interface is treated as smooth at this relative index whatever the
    /// roughness (Cycles: `|eta - 1| < 1e-4`).
    #[must_use]
    pub fn smooth_at(self, eta: f64) -> bool {
        self == TransmissionConvention::Cycles && (eta - 1.0).abs() < CYCLES_SINGULAR_ETA
    }
}

/// Cycles treats an interface within this of index 1 as smooth (`bsdf_microfacet_sample`).
pub const CYCLES_SINGULAR_ETA: f64 = 1e-4;

/// Refracts the unit view direction `o` through the unit microfacet normal `m` with
/// `c = o.m > 0`, into the medium of relative index `eta = n_other / n_view` (Walter 2007,
/// eq. 40): `i_t = -o / eta + (c / eta - cos_t) m`, `cos_t = sqrt(1 - (1 - c^2) / eta^2)`, so
/// that `i_t.m = -cos_t`. `None` under total internal reflection.
#[must_use]
#[inline]
pub fn refract(o: Vec3, m: Vec3, c: f64, eta: f64) -> Option<Vec3> {
    if eta == 1.0 {
        // Index-matched: straight through, exactly (the general formula leaves rounding noise
        // of 1e-16 in `c - cos_t`, which decides the side of a grazing direction).
        return Some(o * -1.0);
    }
    let sin2_t = (1.0 - c) * (1.0 + c) / (eta * eta);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = ((1.0 - sin2_t).max(0.0)).sqrt();
    Some(m * (c / eta - cos_t) - o * (1.0 / eta))
}

/// The contributions of the visible microfacet normal `m` for the view `o` (see the module
/// docs); `lambda_o = Lambda(o)`, single scattering ([`TransmissionConvention`]).
#[must_use]
#[inline]
pub fn scattering<N: MicrofacetDistribution>(
    ndf: N,
    masking: Masking,
    o: Vec3,
    lambda_o: f64,
    m: Vec3,
    eta: f64,
) -> Scattering {
    scattering_with(
        ndf,
        masking,
        o,
        lambda_o,
        m,
        eta,
        TransmissionConvention::SingleScattering,
    )
}

/// [`scattering`] in the given convention (a refraction that ends on the incident side kept for
/// Cycles').
#[must_use]
#[inline]
pub fn scattering_with<N: MicrofacetDistribution>(
    ndf: N,
    masking: Masking,
    o: Vec3,
    lambda_o: f64,
    m: Vec3,
    eta: f64,
    convention: TransmissionConvention,
) -> Scattering {
    scattering_at_cos(ndf, masking, o, lambda_o, m, o.dot(m), eta, convention)
}

/// [`scattering_with`] given `c = o.m`, for a caller that knows it more exactly than the dot
/// product of the two vectors gives it: beside the critical angle `1 - F` grows as the square
/// root of the distance, and a last-bit change of `o.m` moved `F` by 4e-8 within 1e-13 of it.
#[must_use]
#[inline]
#[allow(clippy::too_many_arguments)]
pub fn scattering_at_cos<N: MicrofacetDistribution>(
    ndf: N,
    masking: Masking,
    o: Vec3,
    lambda_o: f64,
    m: Vec3,
    c: f64,
    eta: f64,
    convention: TransmissionConvention,
) -> Scattering {
    let [s] = scatterings_at_cos(ndf, masking, &[o], &[lambda_o], &[m], &[c], eta, convention);
    s
}

/// [`scattering_at_cos`] at `L` pairs of view and normal at once (`o[k]`, `lambda_o[k] =
/// Lambda(o[k])`, `m[k]`, `c[k] = o[k].m[k]`), in stages over arrays of lanes whose every branch
/// is a select, so that a caller's loop compiled for SIMD vectorises. The one home of the
/// formulas: the scalar form calls it with one lane.
#[must_use]
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub fn scatterings_at_cos<N: MicrofacetDistribution, const L: usize>(
    ndf: N,
    masking: Masking,
    o: &[Vec3; L],
    lambda_o: &[f64; L],
    m: &[Vec3; L],
    c: &[f64; L],
    eta: f64,
    convention: TransmissionConvention,
) -> [Scattering; L] {
    let alpha = ndf.alpha();
    let mut fresnel = [0.0; L];
    let mut reflected_z = [0.0; L];
    let mut reflected_tan2 = [0.0; L];
    let mut refracts = [false; L];
    let mut refracted_z = [0.0; L];
    let mut refracted_tan2 = [0.0; L];
    for k in 0..L {
        let c = c[k].clamp(0.0, 1.0);
        fresnel[k] = super::fresnel::dielectric(eta, c);
        let i = o[k].reflect(m[k]);
        reflected_z[k] = i.z;
        reflected_tan2[k] = i.tan2_theta();
        // [`refract`], its total internal reflection a flag.
        let sin2_t = (1.0 - c) * (1.0 + c) / (eta * eta);
        refracts[k] = sin2_t < 1.0;
        let cos_t = ((1.0 - sin2_t).max(0.0)).sqrt();
        let i_t = m[k] * (c / eta - cos_t) - o[k] * (1.0 / eta);
        refracted_z[k] = i_t.z;
        refracted_tan2[k] = i_t.tan2_theta();
    }
    let lambda_reflected = ndf.lambdas_from_tan2(&reflected_tan2);
    let lambda_refracted = ndf.lambdas_from_tan2(&refracted_tan2);
    let keeps_above = convention.keeps_refraction_above();
    let mut scattering = [Scattering {
        reflection: 0.0,
        transmission: 0.0,
        loss: 0.0,
    }; L];
    for k in 0..L {
        let mu_o = o[k].z;
        // [`crate::model::masking::reflection_loss`].
        let reflection_loss = if reflected_z[k] > 0.0 {
            masking.loss_at(
                alpha,
                mu_o,
                reflected_z[k],
                lambda_o[k],
                lambda_reflected[k],
            )
        } else {
            1.0
        };
        let transmission_loss = if eta == 1.0 {
            // Index-matched, i_t = -o: Lambda(i_t) = Lambda(o), and at a grazing view the loss
            // takes its limit along the view (1/2 height-correlated, 1 separable), not the value
            // at Lambda(o) = infinity with Lambda(i) finite that `Masking::loss` gives.
            masking.loss_index_matched(alpha, mu_o, lambda_o[k])
        } else if refracts[k] && (refracted_z[k] < 0.0 || (keeps_above && refracted_z[k] > 0.0)) {
            masking.loss_at(
                alpha,
                mu_o,
                refracted_z[k],
                lambda_o[k],
                lambda_refracted[k],
            )
        } else {
            1.0
        };
        let transmitted = 1.0 - fresnel[k];
        scattering[k] = Scattering {
            reflection: fresnel[k] * (1.0 - reflection_loss),
            transmission: transmitted * (1.0 - transmission_loss),
            loss: fresnel[k] * reflection_loss + transmitted * transmission_loss,
        };
    }
    scattering
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Ggx;

    #[test]
    fn refraction_obeys_snell_and_stays_unit() {
        let o = Vec3::new(0.6, 0.0, 0.8);
        let m = Vec3::new(0.1, 0.2, (1.0f64 - 0.05).sqrt());
        for eta in [1.0, 1.5, 1.0 / 1.5, 2.4] {
            let c = o.dot(m);
            let Some(t) = refract(o, m, c, eta) else {
                assert!(eta < 1.0 && (1.0 - c * c) / (eta * eta) >= 1.0);
                continue;
            };
            assert!((t.length_squared() - 1.0).abs() < 1e-14, "{eta}");
            let sin_i = (1.0 - c * c).sqrt();
            let cos_t = -t.dot(m);
            let sin_t = (1.0 - cos_t * cos_t).sqrt();
            assert!((sin_i - eta * sin_t).abs() < 1e-14, "{eta}");
            // Through the facet, not mirrored back off it: i_t.m = -cos_t < 0.
            assert!(cos_t > 0.0, "{eta}: {t:?}");
            // o, m and t lie in one plane.
            let normal = Vec3::new(
                o.y * m.z - o.z * m.y,
                o.z * m.x - o.x * m.z,
                o.x * m.y - o.y * m.x,
            );
            assert!(normal.dot(t).abs() < 1e-14, "{eta}");
        }
        // eta = 1: straight through.
        let t = refract(o, m, o.dot(m), 1.0).unwrap();
        assert!((t + o).length_squared() < 1e-28);
        // Beyond the critical angle.
        assert!(refract(o, Vec3::new(0.0, 0.0, 1.0), 0.8, 0.5).is_none());
    }

    #[test]
    fn contributions_add_up_to_one() {
        let ndf = Ggx { alpha: 0.4 };
        let o = Vec3::from_mu(0.3);
        let lambda_o = ndf.lambda(o);
        for masking in Masking::ALL {
            for eta in [1.0, 1.33, 1.0 / 1.33, 3.0] {
                for k in 0..50 {
                    let u = [(k as f64 + 0.5) / 50.0, ((k * 37) % 50) as f64 / 50.0];
                    let m = ndf.sample_visible_normal(o, u);
                    let s = scattering(ndf, masking, o, lambda_o, m, eta);
                    let sum = s.reflection + s.transmission + s.loss;
                    assert!((sum - 1.0).abs() < 1e-14, "{masking} {eta}: {s:?}");
                    assert!(s.reflection >= 0.0 && s.transmission >= 0.0 && s.loss >= 0.0);
                }
            }
        }
    }

    /// A view from inside (`eta = 1 / 1.5`) at `mu = 0.3` on a facet tilted 31 degrees
    /// towards it refracts upwards, to `z = 0.42`: single scattering loses that light, Cycles'
    /// convention keeps it with `(1 - F) G2(o, i_t) / G1(o)`, here worked from GGX's `Lambda`
    /// in closed form, `(sqrt(1 + alpha^2 tan^2) - 1) / 2`, and height-correlated masking.
    #[test]
    fn cycles_keeps_a_refraction_that_ends_above_and_single_scattering_loses_it() {
        let (alpha, eta) = (0.5, 1.0 / 1.5);
        let ndf = Ggx { alpha };
        let o = Vec3::from_mu(0.3);
        let t = 31f64.to_radians();
        let m = Vec3::new(t.sin(), 0.0, t.cos());
        let c = o.dot(m);
        let i_t = refract(o, m, c, eta).unwrap();
        assert!(i_t.z > 0.4, "{i_t:?}");
        let lambda = |v: Vec3| ((1.0 + alpha * alpha * v.tan2_theta()).sqrt() - 1.0) / 2.0;
        let transmitted = 1.0 - super::super::fresnel::dielectric(eta, c);
        let kept = transmitted * (1.0 + lambda(o)) / (1.0 + lambda(o) + lambda(i_t));
        let masking = Masking::HeightCorrelated;
        let lambda_o = lambda(o);
        let single = scattering_with(ndf, masking, o, lambda_o, m, eta, Default::default());
        let cycles = scattering_with(
            ndf,
            masking,
            o,
            lambda_o,
            m,
            eta,
            TransmissionConvention::Cycles,
        );
        assert_eq!(single.transmission, 0.0);
        assert!(
            (cycles.transmission - kept).abs() < 1e-14,
            "{cycles:?} vs {kept}"
        );
        assert!(kept > 0.2, "{kept}");
        assert_eq!(single.reflection, cycles.reflection);
        assert!((cycles.loss - (single.loss - kept)).abs() < 1e-14);
    }

    /// Names as serde writes them; only Cycles' convention keeps refractions above the surface
    /// and treats an index within 1e-4 of 1 as smooth.
    #[test]
    fn the_conventions_differ_where_their_docs_say() {
        use TransmissionConvention::{Cycles, SingleScattering};
        for convention in [SingleScattering, Cycles] {
            let name = serde_json::to_value(convention).unwrap();
            assert_eq!(name.as_str(), Some(convention.name()));
        }
        assert!(SingleScattering.is_default() && !Cycles.is_default());
        assert!(SingleScattering.describe().starts_with("single scattering"));
        assert!(Cycles.describe().starts_with("Cycles' sampler"));
        assert!(Cycles.keeps_refraction_above() && !SingleScattering.keeps_refraction_above());
        for eta in [1.0, 1.00005, 0.99995] {
            assert!(Cycles.smooth_at(eta), "{eta}");
            assert!(!SingleScattering.smooth_at(eta), "{eta}");
        }
        for eta in [1.0002, 0.9998, 1.5, 1.0 / 1.5] {
            assert!(!Cycles.smooth_at(eta), "{eta}");
        }
    }

    /// Every contribution against the formulas worked independently: the reflection
    /// `F G2(o, i_r) / G1(o)` about `m`, the refraction `(1 - F) G2(o, i_t) / G1(o)` with `i_t`
    /// from the scalar [`refract`] (Snell's law, tested above) when it goes below the surface,
    /// nothing under total internal reflection; GGX's `Lambda` in closed form and
    /// height-correlated masking, `G2 / G1(o) = (1 + Lambda(o)) / (1 + Lambda(o) + Lambda(i))`.
    #[test]
    fn each_contribution_is_the_masked_fresnel_share_of_its_direction() {
        let alpha = 0.4;
        let ndf = Ggx { alpha };
        let lambda = |v: Vec3| ((1.0 + alpha * alpha * v.tan2_theta()).sqrt() - 1.0) / 2.0;
        let kept = |o: Vec3, i: Vec3| (1.0 + lambda(o)) / (1.0 + lambda(o) + lambda(i));
        let (mut refractions, mut reflections_lost, mut total_internal) = (0, 0, 0);
        for mu in [0.15, 0.6, 0.97] {
            let o = Vec3::from_mu(mu);
            for eta in [1.5, 1.0 / 1.5, 2.4, 1.0 / 1.33, 1.0] {
                for k in 0..40 {
                    let u = [(k as f64 + 0.5) / 40.0, ((k * 17) % 40) as f64 / 40.0];
                    let m = ndf.sample_visible_normal(o, u);
                    let c = o.dot(m);
                    let f = super::super::fresnel::dielectric(eta, c);
                    let s = scattering(ndf, Masking::HeightCorrelated, o, lambda(o), m, eta);
                    let i_r = o.reflect(m);
                    let reflection = if i_r.z > 0.0 {
                        f * kept(o, i_r)
                    } else {
                        reflections_lost += 1;
                        0.0
                    };
                    let transmission = match refract(o, m, c, eta) {
                        Some(i_t) if i_t.z < 0.0 => {
                            refractions += 1;
                            (1.0 - f) * kept(o, i_t)
                        }
                        Some(_) => 0.0,
                        None => {
                            total_internal += 1;
                            assert_eq!(f, 1.0);
                            0.0
                        }
                    };
                    let at = format!("mu {mu}, eta {eta}, m {m:?}: {s:?}");
                    assert!((s.reflection - reflection).abs() < 1e-13, "{at}");
                    assert!((s.transmission - transmission).abs() < 1e-13, "{at}");
                }
            }
        }
        // The grid reaches every case.
        assert!(refractions > 300 && reflections_lost > 0 && total_internal > 0);
    }
}
