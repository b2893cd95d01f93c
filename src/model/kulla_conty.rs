//! The Kulla-Conty multiple-scattering lobe, from the tables' `1 - E` and `1 - E_avg`.
//!
//! Kulla and Conty 2017, "Revisiting Physically Based Shading at Imageworks" (SIGGRAPH course
//! notes), `docs/physics.md` "Kulla-Conty quantities":
//! `f_ms(o, i) = (1 - E(mu_o)) (1 - E(mu_i)) / (pi (1 - E_avg))`. Its albedo,
//! `∫ f_ms mu_i dω_i = (1 - E(mu_o)) 2 ∫ (1 - E(mu_i)) mu_i dmu_i / (1 - E_avg)`, is exactly
//! `1 - E(mu_o)`: the energy single scattering loses (`kiln furnace` checks it on tables).
//!
//! Precision: pass `1 - E` and `1 - E_avg` as kiln stores them (estimated directly), never
//! `1.0 - E`: at `alpha = 1e-3` (GGX), `1 - E_avg` is 7.4e-6, which `1.0 - E_avg` in f32 gets
//! wrong by 8 %, and in f16 not at all. As `alpha -> 0`, `1 - E_avg` goes to zero like
//! `2 alpha^2 (0.25 + ln(1 / alpha) / 2)` while `1 - E` stays near 0.11 in the grazing layer
//! `mu ~ alpha`: `f_ms` concentrates at grazing angles with bounded albedo. Where `1 - E_avg` is
//! 0 (a mirror; kiln stores exactly 0 at `alpha = 0`) or below f64's normal range, there is no
//! loss to restore and `f_ms` is 0.

//!
//! Which `1 - E_avg` to pass: the one that matches the `E` the renderer looks up. The exact
//! `E_avg` closes the furnace only for the exact `E`; with a table's bilinear lookup of `E`, the
//! lobe must be normalised by the average of that lookup, `1 - Ē`, or it adds or removes energy
//! in proportion to the mismatch. For kiln's default 32 x 32 GGX table the mismatch of the exact
//! `E_avg` reaches +119 % at r = 1/31 (`1 - E_avg` 8.0e-6 against the lookup's 1.74e-5), an
//! energy error of 0.128 at grazing views; with kiln's `f_ms_norm` table
//! ([`crate::table::normalisation`], `normalisation_lookup`) the error stays below 4.1e-6 at
//! every roughness and `mu` (`kiln furnace tables/ggx-height-correlated-E.json`, 1402
//! roughness values, quarter-texel and finer). So: `f_ms_norm` for the lobe's denominator, the
//! `E_avg` table for the colour term [`fresnel_colour`] (where the physical average belongs)
//! and for anything else that wants the true average.

use std::f64::consts::PI;

/// `1 / (pi (1 - E_avg))`, the lobe's normalisation: 0 where `1 - E_avg` is 0 or subnormal.
#[must_use]
pub fn normalisation(one_minus_e_avg: f64) -> f64 {
    if one_minus_e_avg >= f64::MIN_POSITIVE {
        1.0 / (PI * one_minus_e_avg)
    } else {
        0.0
    }
}

/// `f_ms(o, i) = (1 - E(mu_o)) (1 - E(mu_i)) / (pi (1 - E_avg))` (see the module docs).
#[must_use]
pub fn multiple_scattering(one_minus_e_o: f64, one_minus_e_i: f64, one_minus_e_avg: f64) -> f64 {
    one_minus_e_o * one_minus_e_i * normalisation(one_minus_e_avg)
}

/// The colour multiplier of the additive `f_ms` lobe for a coloured Fresnel,
/// `F_avg^2 E_avg / (1 - F_avg (1 - E_avg))` per channel (Kulla and Conty 2017; `docs/physics.md`).
///
/// Why the square: a path that bounces `k + 1` times between microfacets keeps `F_avg^(k+1)`; with
/// a fraction `1 - E_avg` of the energy going on to another bounce each time, the total albedo
/// is the geometric series `F_avg E_avg / (1 - F_avg (1 - E_avg))`. The single-scattering lobe
/// already returns its first term, `F_avg E_avg` on average; the rest,
/// `F_avg^2 E_avg (1 - E_avg) / (1 - F_avg (1 - E_avg))`, is what `f_ms` must add, and `f_ms`
/// with `F = 1` returns `1 - E_avg` on average, hence this multiplier. Every path it stands for
/// has met Fresnel at least twice. The unsquared form (`F_avg E_avg / (...)`, a frequent slip)
/// credits those paths with one reflection only and adds energy for every `F_avg < 1`. At
/// `F_avg = 1` the multiplier is 1 (the white furnace).
#[must_use]
pub fn fresnel_colour(f_avg: f64, e_avg: f64) -> f64 {
    let denominator = 1.0 - f_avg * (1.0 - e_avg);
    if denominator > 0.0 {
        f_avg * f_avg * e_avg / denominator
    } else {
        // F_avg = 1 and E_avg = 0: nothing is ever reflected by one bounce; the limit along
        // F_avg = 1 is 1.
        1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The multiplier completes the geometric series: single scattering's `F_avg E_avg` plus
    /// `colour (1 - E_avg)` is the total `F_avg E_avg / (1 - F_avg (1 - E_avg))`; at `F_avg = 1`
    /// it is 1; it never exceeds `F_avg` (no energy gain from the lobe).
    #[test]
    fn fresnel_colour_completes_the_series() {
        for f in [0.0, 0.04, 0.3, 0.9, 1.0] {
            for e in [0.01, 0.4, 0.9, 1.0] {
                let colour = fresnel_colour(f, e);
                let total = f * e / (1.0 - f * (1.0 - e));
                assert!(
                    (f * e + colour * (1.0 - e) - total).abs() < 1e-15,
                    "{f} {e}"
                );
                assert!(colour <= f + 1e-15, "{f} {e}");
            }
            assert!((fresnel_colour(1.0, f.max(0.01)) - 1.0).abs() < 1e-15);
        }
        assert_eq!(fresnel_colour(1.0, 0.0), 1.0);
    }
    use crate::integrate::gauss_kronrod::integrate_pieces;
    use crate::integrate::reference::{
        ReferenceSettings, reference_albedo, reference_average_albedo,
    };
    use crate::model::{Masking, Model, Ndf};

    /// The lobe's albedo, `2 pi ∫ f_ms(mu_o, mu_i) mu_i dmu_i` (isotropic in azimuth), with the
    /// reference's `E` and `E_avg`, equals `1 - E(mu_o)`: the normalisation is right.
    #[test]
    fn lobe_restores_the_lost_energy() {
        let settings = ReferenceSettings {
            tolerance: 1e-10,
            max_intervals: 200,
        };
        let model = Model {
            ndf: Ndf::Ggx,
            masking: Masking::HeightCorrelated,
        };
        for alpha in [0.05, 0.5, 1.0] {
            let avg = reference_average_albedo(model, alpha, &settings).one_minus_value;
            let loss = |mu: f64| reference_albedo(model, alpha, mu, &settings).one_minus_value;
            for mu_o in [0.02, 0.5, 1.0] {
                let lost = loss(mu_o);
                let breaks =
                    [0.0, alpha / 16.0, alpha / 4.0, alpha, 4.0 * alpha, 1.0].map(|b| b.min(1.0));
                let albedo = integrate_pieces(
                    &mut |mu_i: f64| [2.0 * PI * multiple_scattering(lost, loss(mu_i), avg) * mu_i],
                    &breaks,
                    1e-9 * lost,
                    200,
                );
                // Both integrals are accurate to ~1e-10; the ratio to ~1e-8 relative.
                assert!(
                    (albedo.value[0] / lost - 1.0).abs() < 1e-6,
                    "alpha {alpha} mu {mu_o}: {} vs {lost}",
                    albedo.value[0]
                );
            }
        }
    }

    #[test]
    fn mirror_and_tiny_averages_give_a_finite_lobe() {
        assert_eq!(multiple_scattering(0.1, 0.1, 0.0), 0.0);
        assert_eq!(multiple_scattering(0.1, 0.1, 1e-310), 0.0);
        let tiny = multiple_scattering(0.11, 0.11, 1.7e-13);
        assert!(tiny.is_finite() && tiny > 0.0);
        assert_eq!(normalisation(1.0 / PI), 1.0);
    }
}
