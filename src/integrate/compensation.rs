//! The albedo a renderer gets from the single-scattering BRDF plus an energy compensation, for
//! a Fresnel model: what the microsurface walk ([`crate::integrate::walk`]) measures them
//! against.
//!
//! Both forms are computed from kiln's deterministic reference (`E`, `E_avg` and the
//! Fresnel-weighted `E_F` to 1e-10, `F_avg` to 1e-14), not from a table's lookup: what is
//! measured is the compensation's model error (percents), not a table's interpolation (its
//! lookups are within 2.1e-4: `kiln verify`).

use crate::integrate::reference::{
    ReferenceSettings, reference_albedo, reference_average_albedo, reference_weighted_albedo,
};
use crate::model::Model;
use crate::model::fresnel::{Fresnel, Rgb};
use crate::model::kulla_conty::fresnel_colour;

/// An energy compensation of the single-scattering BRDF.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum Compensation {
    /// Kulla and Conty 2017: the added lobe `(1 - E(mu_o)) (1 - E(mu_i)) / (pi (1 - E_avg))`
    /// times `F_avg^2 E_avg / (1 - F_avg (1 - E_avg))` per channel (kiln's
    /// `model::kulla_conty`); its albedo is `E_F(mu) + colour (1 - E(mu))`.
    KullaConty,
    /// Turquin 2019, "Practical multiple scattering compensation for microfacet models"
    /// (Filament, Unreal 5, Bevy, three.js): the single-scattering BRDF scaled by
    /// `1 + F0 (1 / E(mu) - 1)`, `F0` the reflectance at normal incidence; its albedo is
    /// `E_F(mu) (1 + F0 (1 - E) / E)`.
    Turquin,
}

impl Compensation {
    /// The name on the command line and in reports.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Compensation::KullaConty => "kulla-conty",
            Compensation::Turquin => "turquin",
        }
    }
}

/// The directional albedo, per channel, of the single-scattering BRDF of `model` at `alpha`
/// with `fresnel` plus `compensation`, viewed at `mu` (see the module docs).
#[must_use]
pub fn compensated_albedo(
    model: Model,
    alpha: f64,
    mu: f64,
    fresnel: &Fresnel,
    compensation: Compensation,
    settings: &ReferenceSettings,
) -> Rgb {
    let e = reference_albedo(model, alpha, mu, settings);
    let single: Rgb = if fresnel.is_grey() {
        let f = *fresnel;
        let value =
            reference_weighted_albedo(model, alpha, mu, move |c| f.reflectance(c)[0], settings)
                .value;
        [value; 3]
    } else {
        std::array::from_fn(|j| {
            let f = *fresnel;
            reference_weighted_albedo(model, alpha, mu, move |c| f.reflectance(c)[j], settings)
                .value
        })
    };
    match compensation {
        Compensation::KullaConty => {
            let e_avg = reference_average_albedo(model, alpha, settings).value;
            let f_avg = fresnel.average();
            std::array::from_fn(|j| single[j] + fresnel_colour(f_avg[j], e_avg) * e.one_minus_value)
        }
        Compensation::Turquin => {
            let f0 = fresnel.reflectance(1.0);
            std::array::from_fn(|j| {
                if e.value > 0.0 {
                    single[j] * (1.0 + f0[j] * e.one_minus_value / e.value)
                } else {
                    0.0
                }
            })
        }
    }
}
